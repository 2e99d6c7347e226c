//! Helpers shared by the integration tests.
#![allow(dead_code)]

use raystep::aov::Frame;
use raystep::scene::Scene;
use raystep::stages::Stages;

/// The built-in figure-1 scene at `width` × `height`.
pub fn seed(width: u32, height: u32) -> Scene {
    let mut scene = raystep::io::scene_file::seed();
    scene.width = width;
    scene.height = height;
    scene
}

/// Render with raystep's default settings (the book engine), without progress
/// reporting.
pub fn render(scene: &Scene, stages: Stages) -> Frame {
    raystep::render::render(scene, &stages.into(), &|_| {})
}

/// A scene from TOML text, which must be valid.
pub fn scene(toml: &str) -> Scene {
    raystep::io::scene_file::parse(toml, "test scene").unwrap_or_else(|e| panic!("{e}"))
}

/// Read a PFM file: (width, height, RGB triples with the top row first).
pub fn read_pfm(bytes: &[u8]) -> (usize, usize, Vec<[f32; 3]>) {
    let mut fields = Vec::new();
    let mut pos = 0;
    while fields.len() < 4 {
        while bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        fields.push(std::str::from_utf8(&bytes[start..pos]).unwrap().to_string());
    }
    pos += 1; // the single whitespace byte after the scale
    assert_eq!(fields[0], "PF", "a colour PFM");
    let (w, h): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    let scale: f32 = fields[3].parse().unwrap();
    assert!(scale < 0.0, "little-endian PFM");
    let floats: Vec<f32> = bytes[pos..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(floats.len(), w * h * 3);
    let mut rows: Vec<[f32; 3]> = Vec::with_capacity(w * h);
    for row in (0..h).rev() {
        for col in 0..w {
            let i = (row * w + col) * 3;
            rows.push([floats[i], floats[i + 1], floats[i + 2]]);
        }
    }
    (w, h, rows)
}

/// Run the `raystep` binary with `args` in the folder `dir`.
pub fn raystep(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the binary runs")
}

/// Chromium and Node.js with playwright-core, as the browser tests drive them
/// (`tests/browser/`), or what is missing.
pub fn browser_tools() -> Result<std::path::PathBuf, String> {
    use std::path::PathBuf;
    let chromium = std::env::var_os("CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    let mut missing = Vec::new();
    if !chromium.is_file() {
        missing.push(format!(
            "Chromium at {} (apt-get install chromium, or set CHROMIUM to its path)",
            chromium.display()
        ));
    }
    let node = std::process::Command::new("node").arg("--version").output();
    if !node.is_ok_and(|o| o.status.success()) {
        missing.push("Node.js (apt-get install nodejs npm)".to_string());
    }
    let playwright = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/browser/node_modules/playwright-core");
    if !playwright.is_dir() {
        missing.push("playwright-core (npm ci --prefix tests/browser)".to_string());
    }
    if missing.is_empty() {
        Ok(chromium)
    } else {
        Err(missing.join("; "))
    }
}

/// The tools a test needs, or `None` when it is to be skipped: with a message
/// locally, and a failure under CI, where they are installed.
pub fn required<T>(tools: Result<T, String>, what: &str) -> Option<T> {
    match tools {
        Ok(tools) => Some(tools),
        Err(missing) if std::env::var_os("CI").is_some() => panic!("{what} needs: {missing}"),
        Err(missing) => {
            eprintln!("skipped: {what} needs: {missing}");
            None
        }
    }
}
