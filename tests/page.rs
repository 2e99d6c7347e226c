//! The page `raystep stages` writes (`OUT/index.html`), driven in a real headless
//! Chromium by `tests/browser/probe.mjs`: a cell of the grid is clicked, the real
//! mouse is moved over the large picture to a pixel, and every number the page
//! then shows must be the float32 that `buffers.exr` holds for that pixel.
//!
//! Needs Chromium (`apt-get install chromium`), Node.js and
//! `npm ci --prefix tests/browser`. Without them the test is skipped, or fails
//! under CI (where `CI` is set).

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

/// The browser window, in CSS pixels (one screen pixel each).
const VIEWPORT: (u32, u32) = (1400, 1000);

/// The fields of `pixels.js`, as the page shows them, and their EXR channels.
const FIELDS: [(&str, &str); 14] = [
    ("R", "R"),
    ("G", "G"),
    ("B", "B"),
    ("depth", "Z"),
    ("N.X", "N.X"),
    ("N.Y", "N.Y"),
    ("N.Z", "N.Z"),
    ("P.X", "P.X"),
    ("P.Y", "P.Y"),
    ("P.Z", "P.Z"),
    ("shadow", "shadow.X"),
    ("object", "object.X"),
    ("bounces", "bounces.X"),
    ("rays", "rays.X"),
];

fn manifest_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every channel of a `buffers.exr` file, by name.
struct Exr {
    width: usize,
    channels: HashMap<String, Vec<f32>>,
}

impl Exr {
    fn read(path: &Path) -> Exr {
        let image = exr::prelude::read_all_flat_layers_from_file(path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let layer = &image.layer_data[0];
        let channels = layer
            .channel_data
            .list
            .iter()
            .map(|c| {
                let values = c.sample_data.values_as_f32().collect();
                (c.name.to_string(), values)
            })
            .collect();
        Exr {
            width: layer.size.0,
            channels,
        }
    }

    fn at(&self, channel: &str, x: usize, y: usize) -> Option<f32> {
        self.channels.get(channel).map(|c| c[y * self.width + x])
    }

    /// The pixel in the middle (in reading order) of those that `keep`.
    fn middle_pixel(&self, keep: impl Fn(usize, usize) -> bool) -> (usize, usize) {
        let height = self.channels["R"].len() / self.width;
        let found: Vec<(usize, usize)> = (0..height)
            .flat_map(|y| (0..self.width).map(move |x| (x, y)))
            .filter(|&(x, y)| keep(x, y))
            .collect();
        assert!(!found.is_empty(), "no pixel of that kind");
        found[found.len() / 2]
    }
}

/// A number as the page writes it (JavaScript's `String(v)`), e.g. `Infinity`.
fn js_number(text: &str) -> f64 {
    text.parse()
        .unwrap_or_else(|e| panic!("{text:?} is not a number: {e}"))
}

#[test]
fn the_page_shows_the_exact_numbers_of_the_pixel_under_the_mouse() {
    let Some(chromium) = common::required(common::browser_tools(), "the browser test") else {
        return;
    };

    // The built-in scene, every stage, with the page.
    let out = tempfile::tempdir().unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args(["stages", "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    // The status lines are on stderr; stdout is for data.
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let index = out.path().join("index.html");
    assert!(
        stderr.contains(&format!("open {}", index.display())),
        "{stderr}"
    );
    let exr = |folder: &str| Exr::read(&out.path().join(folder).join("buffers.exr"));

    // Telling pixels: in the last stage the sky, the red sphere (object 0) lit,
    // the floor in shadow; a shadowed point of an earlier stage; a pixel of the
    // first stage, which computes no more than the colour.
    let plane = exr("06-plane");
    let sky = plane.middle_pixel(|x, y| plane.at("Z", x, y) == Some(f32::INFINITY));
    let red = plane.middle_pixel(|x, y| {
        plane.at("object.X", x, y) == Some(0.0) && plane.at("shadow.X", x, y) == Some(1.0)
    });
    let floor_in_shadow = plane.middle_pixel(|x, y| {
        plane.at("shadow.X", x, y) == Some(0.0) && plane.at("N.Y", x, y).unwrap() > 0.99
    });
    let shadow = exr("03-shadow");
    let shadowed = shadow.middle_pixel(|x, y| shadow.at("shadow.X", x, y) == Some(0.0));
    let probes = [
        ("01-rays", "direction", (150, 100)),
        ("03-shadow", "normal", shadowed),
        ("06-plane", "depth", sky),
        ("06-plane", "shadow", floor_in_shadow),
        ("06-plane", "beauty", red), // last: the screenshot shows it
    ];

    let screenshot = out.path().join("screenshot.png");
    let mut probe = Command::new("node");
    probe
        .arg(manifest_dir().join("tests/browser/probe.mjs"))
        .arg("--page")
        .arg(&index)
        .arg("--screenshot")
        .arg(&screenshot)
        .arg("--chromium")
        .arg(&chromium)
        .arg("--size")
        .arg(format!("{}x{}", VIEWPORT.0, VIEWPORT.1));
    for (stage, buffer, (x, y)) in probes {
        probe.arg(format!("{stage}:{buffer}:{x}:{y}"));
    }
    let result = probe.output().unwrap();
    assert!(
        result.status.success(),
        "probe.mjs failed:\n{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let report: Value = serde_json::from_slice(&result.stdout).unwrap_or_else(|e| {
        panic!("{e}: {}", String::from_utf8_lossy(&result.stdout));
    });

    // A clean page: no console errors or warnings, no script errors, no failed loads.
    for key in ["console", "pageErrors", "failedRequests"] {
        assert_eq!(report[key], serde_json::json!([]), "{key}");
    }

    // Every number the page shows, against buffers.exr.
    let shown = report["probes"].as_array().unwrap();
    assert_eq!(shown.len(), probes.len(), "a readout for every probe");
    for ((stage, buffer, (x, y)), shown) in probes.iter().zip(shown) {
        let at = format!("{stage} {buffer} ({x}, {y})");
        assert_eq!(shown["readout"]["stage"], *stage, "{at}");
        assert_eq!(shown["readout"]["x"], x.to_string(), "{at}");
        assert_eq!(shown["readout"]["y"], y.to_string(), "{at}");
        let exr = exr(stage);
        for (field, channel) in FIELDS {
            let cell = &shown["fields"][field];
            match exr.at(channel, *x, *y) {
                Some(expected) => {
                    assert_eq!(cell["computed"], "true", "{at} {field}");
                    let value = js_number(cell["value"].as_str().unwrap());
                    // Exactly: a float32 widened to a double, written and read back.
                    // (`==`, so 0 and −0 are the same: String(-0) is "0".)
                    assert!(
                        value == f64::from(expected),
                        "{at} {field}: the page shows {value}, buffers.exr holds {expected}"
                    );
                }
                // No channel: the stage does not compute it, and the page says so.
                None => {
                    assert_eq!(cell["computed"], "false", "{at} {field}");
                    assert_eq!(cell["text"], "—", "{at} {field}");
                }
            }
        }
    }
    let sky_shown = &report["probes"][2]["fields"];
    assert_eq!(sky_shown["depth"]["value"], "Infinity");
    assert_eq!(sky_shown["depth"]["text"], "∞ (miss)");
    assert_eq!(sky_shown["object"]["text"], "−1 (miss)");
    assert_eq!(
        report["probes"][3]["fields"]["shadow"]["text"],
        "0 (in shadow)"
    );

    // The screenshot: a PNG of the window's size, not one flat colour. A copy
    // stays in target/ for a person to look at.
    let bytes = std::fs::read(&screenshot).unwrap();
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    let picture = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .unwrap()
        .to_rgb8();
    assert_eq!(picture.dimensions(), VIEWPORT);
    let colours: std::collections::HashSet<[u8; 3]> = picture.pixels().map(|p| p.0).collect();
    assert!(colours.len() > 100, "{} colours", colours.len());
    let keep = manifest_dir().join("target");
    std::fs::create_dir_all(&keep).unwrap();
    std::fs::copy(&screenshot, keep.join("page-screenshot.png")).unwrap();
}
