//! The page `raystep stages` writes beside its pictures: `index.html`, a grid of
//! every stage × buffer in which a picture can be chosen, seen large, and read pixel
//! by pixel; and in each stage's folder `pixels.js`, the numbers it reads.
//!
//! The page works when opened from the disk, with no server: browsers refuse
//! `fetch()` of a local file but run a local `<script src>`. So the numbers are a
//! JavaScript file that hands them to the page:
//!
//! ```text
//! raystepPixels.load("06-plane", {"width": W, "height": H, "fields": ["R", …], "data": "<base64>"});
//! ```
//!
//! `data` is base64 of little-endian float32s, pixel after pixel, the top row
//! first, one float per field ([`FIELDS`]). The page's HTML, CSS and JavaScript are
//! `assets/page/` (plain files, no build step), copied into `index.html`.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::aov::{Buffer, Frame, NO_OBJECT};
use crate::error::Error;
use crate::io::output::Pending;

/// The page's file, in the folder of `raystep stages`.
pub const INDEX_FILE: &str = "index.html";

/// The numbers of a stage, in the stage's folder.
pub const PIXELS_FILE: &str = "pixels.js";

/// The largest render whose numbers [`PIXELS_FILE`] holds: 1920 × 1080. Its
/// file takes 75 bytes per pixel (14 float32s in base64: 155 MB at this size,
/// per stage); above it the
/// page still shows the pictures, and says where to read the numbers instead.
pub const NUMBERS_UP_TO: u64 = 1920 * 1080;

/// Whether a render of `width` × `height` gets a [`PIXELS_FILE`].
pub fn has_numbers(width: u32, height: u32) -> bool {
    u64::from(width) * u64::from(height) <= NUMBERS_UP_TO
}

/// The floats of each pixel in [`PIXELS_FILE`], in order.
pub const FIELDS: [&str; 14] = [
    "R", "G", "B", "depth", "N.X", "N.Y", "N.Z", "P.X", "P.Y", "P.Z", "shadow", "object",
    "bounces", "rays",
];

const TEMPLATE: &str = include_str!("../../assets/page/index.html");
const STYLE: &str = include_str!("../../assets/page/page.css");
const SCRIPT: &str = include_str!("../../assets/page/page.js");

/// One row of the page's grid: a stage, and the buffers (PNG names without
/// `.png`) it wrote.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct PageStage {
    /// The stage's folder, e.g. `06-plane`.
    pub folder: String,
    /// What the row is called, e.g. `plane`.
    pub label: String,
    /// The buffers the stage wrote, e.g. `beauty`, `direction`.
    pub buffers: Vec<String>,
}

/// The floats of pixel (`row`, `col`), in the order of [`FIELDS`]. On a miss:
/// depth `+∞`, normal and position `(0, 0, 0)`, shadow `−1`, object `−1` (as in
/// `buffers.exr`).
fn pixel_fields(frame: &Frame, row: u32, col: u32) -> [f32; 14] {
    let p = frame.at(row, col);
    let [r, g, b] = p.colour;
    let [px, py, pz] = frame.position(row, col);
    let [nx, ny, nz] = p.normal;
    let object = if p.object == NO_OBJECT {
        -1.0
    } else {
        p.object as f32
    };
    let (bounces, rays) = (p.bounces as f32, p.rays as f32);
    [
        r, g, b, p.depth, nx, ny, nz, px, py, pz, p.shadow, object, bounces, rays,
    ]
}

/// The contents of `folder/pixels.js` for `frame`: every field of every pixel.
pub fn pixels_js(folder: &str, frame: &Frame) -> String {
    let folder = serde_json::to_string(folder).expect("a string is valid JSON");
    let fields = serde_json::to_string(&FIELDS).expect("strings are valid JSON");
    let floats = frame.pixels.len() * FIELDS.len();
    let mut js = String::with_capacity((floats * 4).div_ceil(3) * 4 + 300);
    js.push_str("// The numbers of every pixel, for index.html. Written by raystep stages.\n");
    js.push_str(&format!(
        "raystepPixels.load({folder}, {{\"width\": {}, \"height\": {}, \"fields\": {fields}, \"data\": \"",
        frame.width, frame.height
    ));
    // Three pixels are 168 bytes, a multiple of 3: encoded 3 × 256 pixels at a
    // time, the base64 is the same as the whole at once, without holding all the
    // bytes.
    const GROUP: usize = 256 * 3 * FIELDS.len() * 4;
    let mut group = Vec::with_capacity(GROUP);
    for row in 0..frame.height {
        for col in 0..frame.width {
            for v in pixel_fields(frame, row, col) {
                group.extend_from_slice(&v.to_le_bytes());
            }
            if group.len() == GROUP {
                base64_into(&mut js, &group);
                group.clear();
            }
        }
    }
    base64_into(&mut js, &group);
    js.push_str("\"});\n");
    js
}

/// Append the base64 of `bytes` to `out` (RFC 4648, with `=` padding), by the
/// `base64` crate.
fn base64_into(out: &mut String, bytes: &[u8]) {
    use base64::Engine as _;
    base64::engine::general_purpose::STANDARD.encode_string(bytes, out);
}

/// The page: `scene_name` at `width` × `height`, a row per stage.
pub fn index_html(scene_name: &str, width: u32, height: u32, stages: &[PageStage]) -> String {
    let manifest = serde_json::json!({
        "scene": scene_name,
        "width": width,
        "height": height,
        "buffers": columns(stages),
        "stages": stages,
        "numbers": has_numbers(width, height),
        "numbersUpTo": NUMBERS_UP_TO,
    });
    // `<` written as `\u003c` (the same string to JavaScript) so that no text in
    // the manifest, say a scene named `</script>`, can end the <script> element.
    let manifest = serde_json::to_string(&manifest)
        .expect("the manifest is valid JSON")
        .replace('<', "\\u003c");
    // The manifest last: nothing in it is taken for a placeholder.
    TEMPLATE
        .replace("{{page.css}}", STYLE.trim_end())
        .replace("{{page.js}}", SCRIPT.trim_end())
        .replace("{{manifest}}", &manifest)
}

/// The grid's columns: every buffer some stage wrote, in the order of
/// [`Buffer::ALL`] (then any other name, in the order met).
fn columns(stages: &[PageStage]) -> Vec<String> {
    let written: Vec<&String> = stages.iter().flat_map(|s| &s.buffers).collect();
    let mut columns: Vec<String> = Buffer::ALL
        .iter()
        .map(|b| b.name().to_string())
        .filter(|name| written.contains(&name))
        .collect();
    for name in written {
        if !columns.contains(name) {
            columns.push(name.clone());
        }
    }
    columns
}

/// Write `dir/pixels.js` for the frame of the stage in `folder`, into `pending`.
pub fn write_pixels(
    pending: &mut Pending,
    dir: &Path,
    folder: &str,
    frame: &Frame,
) -> Result<(), Error> {
    pending.file(&dir.join(PIXELS_FILE), pixels_js(folder, frame).as_bytes())
}

/// Write `out/index.html` into `pending`; returns its path.
pub fn write_index(
    pending: &mut Pending,
    out: &Path,
    scene_name: &str,
    width: u32,
    height: u32,
    stages: &[PageStage],
) -> Result<PathBuf, Error> {
    let path = out.join(INDEX_FILE);
    pending.file(
        &path,
        index_html(scene_name, width, height, stages).as_bytes(),
    )?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stages::{Stage, Stages};

    fn base64(bytes: &[u8]) -> String {
        let mut out = String::new();
        base64_into(&mut out, bytes);
        out
    }

    #[test]
    fn base64_matches_the_rfc_4648_test_vectors() {
        let vectors = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (text, encoded) in vectors {
            assert_eq!(base64(text.as_bytes()), encoded, "{text:?}");
        }
        assert_eq!(base64(&[0xfb, 0xff, 0xbf]), "+/+/");
    }

    fn frame(width: u32, height: u32, last: Stage) -> Frame {
        let mut scene = crate::io::scene_file::seed();
        scene.width = width;
        scene.height = height;
        crate::render::render(&scene, &Stages::up_to(last).into(), &|_| {})
    }

    #[test]
    fn pixels_js_holds_every_field_of_every_pixel_top_row_first() {
        // 7 × 5: 35 pixels, not a multiple of the groups of three.
        let frame = frame(7, 5, Stage::Plane);
        let js = pixels_js("06-plane", &frame);
        let prefix = "raystepPixels.load(\"06-plane\", {\"width\": 7, \"height\": 5, \"fields\": \
            [\"R\",\"G\",\"B\",\"depth\",\"N.X\",\"N.Y\",\"N.Z\",\"P.X\",\"P.Y\",\"P.Z\",\"shadow\",\"object\",\"bounces\",\"rays\"], \
            \"data\": \"";
        let start = js.find(prefix).expect("the call") + prefix.len();
        let end = js.rfind("\"});").expect("the end of the call");
        let bytes: Vec<u8> = (0..frame.height)
            .flat_map(|row| (0..frame.width).map(move |col| (row, col)))
            .flat_map(|(row, col)| pixel_fields(&frame, row, col))
            .flat_map(f32::to_le_bytes)
            .collect();
        assert_eq!(bytes.len(), 35 * 14 * 4);
        assert_eq!(&js[start..end], base64(&bytes));
    }

    #[test]
    fn a_miss_reads_infinite_depth_zero_normal_and_minus_one() {
        let frame = frame(7, 5, Stage::Plane);
        assert!(!frame.at(0, 0).is_hit(), "the top-left corner sees the sky");
        let [.., depth, nx, ny, nz, px, py, pz, shadow, object, _, _] = pixel_fields(&frame, 0, 0);
        assert_eq!((depth, [nx, ny, nz]), (f32::INFINITY, [0.0; 3]));
        assert_eq!([px, py, pz], [0.0; 3]);
        assert_eq!((shadow, object), (-1.0, -1.0));
    }

    fn stage(folder: &str, buffers: &[&str]) -> PageStage {
        PageStage {
            folder: folder.into(),
            label: folder.into(),
            buffers: buffers.iter().map(|b| b.to_string()).collect(),
        }
    }

    #[test]
    fn the_columns_are_every_buffer_written_in_file_order() {
        let stages = [
            stage("01-rays", &["beauty", "direction"]),
            stage("02-intersection", &["shadow", "extra", "beauty", "depth"]),
        ];
        assert_eq!(
            columns(&stages),
            ["beauty", "direction", "depth", "shadow", "extra"]
        );
    }

    #[test]
    fn the_page_holds_the_manifest_and_no_placeholder() {
        let stages = [stage("01-rays", &["beauty", "direction"])];
        let html = index_html("a</script><b>", 30, 20, &stages);
        assert!(!html.contains("{{"), "a placeholder left");
        assert!(
            !html.contains("a</script>"),
            "the scene name ends the script"
        );
        let start = html.find("const MANIFEST = ").unwrap() + "const MANIFEST = ".len();
        let end = start + html[start..].find(";\n").unwrap();
        let manifest: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
        assert_eq!(manifest["scene"], "a</script><b>");
        assert_eq!(manifest["width"], 30);
        assert_eq!(
            manifest["buffers"],
            serde_json::json!(["beauty", "direction"])
        );
        assert_eq!(manifest["stages"][0]["folder"], "01-rays");
        assert!(html.contains("image-rendering: pixelated"), "the CSS is in");
        assert!(html.contains("window.raystepPixels"), "the script is in");
        assert_eq!(manifest["numbers"], true);
        // Past 1920 × 1080 the page has no numbers, and says so.
        let big = index_html("big", 1921, 1080, &stages);
        assert!(
            big.contains(r#""numbers":false"#),
            "no numbers at 1921 × 1080"
        );
        assert!(has_numbers(1920, 1080) && !has_numbers(1080, 1921));
    }
}
