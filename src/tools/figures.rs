//! The book's pictures. Every render in `chapters/img/` is listed here as the
//! `raystep render` command a reader would type, and `raystep figures` runs those
//! very commands, so the command printed beside a picture is the one that made it.
//! The diagrams (SVG) are drawn by [`crate::tools::diagrams`] from the crate's own
//! geometry. `raystep figures --check` re-renders and redraws them all and compares
//! the bytes.

use std::path::{Path, PathBuf};

use crate::aov::{Buffer, Frame};
use crate::error::Error;
use crate::io::output::{png_bytes_as, PngEncoding};

/// What renders a figure: the frame of `raystep ARGS` with scene paths relative to
/// `ROOT` (the command line's [`render_command`](crate::tools::cli::render_command),
/// which parses ARGS as `raystep` does).
pub type Renderer<'a> = &'a dyn Fn(&str, &Path) -> Result<Frame, Error>;

/// One picture of the book: `raystep ARGS`, keeping some of its buffers.
#[derive(Clone, Copy, Debug)]
pub struct Figure {
    /// The path under `chapters/img/`, without `-buffer.png`, e.g. `ch04/acne`.
    pub name: &'static str,
    /// The arguments after `raystep`: always a `render` command.
    pub args: &'static str,
    /// The buffers kept, each written as `NAME-BUFFER.png`.
    pub buffers: &'static [Buffer],
}

use Buffer::{Ambient, Beauty, Bounces, Depth, Diffuse, Normal, Object, Rays, Shadow, Specular};

/// Every figure of the book, by chapter.
#[rustfmt::skip]
pub const FIGURES: &[Figure] = &[
    fig("ch01/seed", "render scenes/seed.toml", &[Beauty]),
    fig("ch02/rays", "render scenes/seed.toml --stage rays", &[Beauty]),
    fig("ch02/narrow", "render scenes/narrow.toml --stage rays", &[Beauty]),
    fig("ch02/narrow-plane", "render scenes/narrow.toml", &[Beauty]),
    fig("ch03/intersection", "render scenes/seed.toml --stage intersection", &[Beauty, Depth, Normal, Shadow]),
    fig("ch04/shadow", "render scenes/seed.toml --stage shadow --offset fixed:1e-5", &[Beauty, Shadow]),
    fig("ch04/acne", "render scenes/seed.toml --stage shadow --offset fixed:0", &[Beauty, Shadow]),
    fig("ch04/blocker", "render scenes/shadow.toml --stage shadow", &[Beauty, Shadow]),
    fig("ch05/blinn-phong", "render scenes/seed.toml --stage blinn-phong", &[Beauty]),
    fig("ch05/no-shadow", "render scenes/seed.toml --stage blinn-phong --without shadow", &[Beauty]),
    fig("ch05/highlights", "render scenes/highlights.toml --stage blinn-phong", &[Beauty]),
    fig("ch06/reflection", "render scenes/seed.toml --stage reflection", &[Beauty]),
    fig("ch06/mirrors-1", "render scenes/mirrors.toml --stage reflection --max-depth 1", &[Beauty]),
    fig("ch06/mirrors-2", "render scenes/mirrors.toml --stage reflection --max-depth 2", &[Beauty]),
    fig("ch06/mirrors-6", "render scenes/mirrors.toml --stage reflection --max-depth 6", &[Beauty]),
    fig("ch07/fake", "render scenes/seed.toml --stage plane", &[Beauty, Depth, Normal, Shadow]),
    fig("ch07/true", "render scenes/true-plane.toml --stage plane", &[Beauty, Depth, Normal, Shadow]),
    fig("ch08/camera", "render --tutorial --out out/camera", &[Beauty]),
    fig("ch08/ray-origin", "render --tutorial --viewer ray-origin --out out/ray-origin", &[Beauty]),
    fig("ch08/srgb", "render scenes/seed.toml --png srgb --out out/srgb", &[Beauty]),
    fig("ch09/far-naive", "render scenes/stress/far-sphere.toml --precision f32 --intersect naive", &[Beauty]),
    fig("ch09/far-stable", "render scenes/stress/far-sphere.toml --precision f32", &[Beauty]),
    fig("ch09/graze-naive", "render scenes/stress/graze.toml --precision f32 --intersect naive", &[Beauty]),
    fig("ch09/graze-stable", "render scenes/stress/graze.toml --precision f32", &[Beauty]),
    fig("ch09/x1000-tutorial", "render scenes/stress/seed-x1000.toml --precision f32 --tutorial", &[Shadow]),
    fig("ch09/x1000-auto", "render scenes/stress/seed-x1000.toml --precision f32", &[Shadow]),
    fig("ch09/tiny-tutorial", "render scenes/stress/tiny-sphere.toml --tutorial", &[Beauty, Shadow]),
    fig("ch09/tiny-auto", "render scenes/stress/tiny-sphere.toml", &[Beauty, Shadow]),
    fig("ch09/x0001-tutorial", "render scenes/stress/seed-x0.001.toml --tutorial", &[Shadow]),
    fig("ch09/x0001-auto", "render scenes/stress/seed-x0.001.toml", &[Shadow]),
    fig("ch09/plane-no-step", "render scenes/stress/horizon-true.toml --offset fixed:0", &[Beauty, Shadow]),
    fig("ch09/plane-auto", "render scenes/stress/horizon-true.toml", &[Beauty, Shadow]),
    fig("ch09/tiny-far-scene", "render scenes/stress/tiny-far.toml --precision f32 --offset scene", &[Beauty, Shadow]),
    fig("ch09/tiny-far-auto", "render scenes/stress/tiny-far.toml --precision f32", &[Beauty, Shadow]),
    fig("ch11/seed", "render scenes/seed.toml", &[Beauty, Object, Shadow, Ambient, Diffuse, Specular, Bounces, Rays]),
];

/// The contact sheet of chapter 11 and the README, under `chapters/img/`: what
/// `raystep stages` writes as `out/contact-sheet.png` for the built-in scene.
pub const CONTACT_SHEET: &str = "ch11/contact-sheet.png";

/// [`CONTACT_SHEET`]'s bytes: every stage of the built-in scene, as `raystep
/// stages` renders them.
pub fn contact_sheet() -> Vec<u8> {
    let scene = crate::io::scene_file::seed();
    let mut sheet = crate::io::contact::ContactSheet::new(crate::io::contact::THUMBNAIL_WIDTH);
    for stage in crate::stages::Stage::ALL {
        let settings = crate::render::Settings::from(crate::stages::Stages::up_to(stage));
        sheet.add_row(
            &stage.label(),
            &crate::render::render(&scene, &settings, &|_| {}),
        );
    }
    sheet.png()
}

/// Every file `raystep figures` writes under `chapters/img/`: (file, bytes, what
/// makes it).
fn every_file(root: &Path, run: Renderer) -> Result<Vec<(String, Vec<u8>, String)>, Error> {
    let mut files = Vec::new();
    for figure in FIGURES {
        for (file, bytes) in figure.render(root, run)? {
            files.push((file, bytes, format!("raystep {}", figure.args)));
        }
    }
    files.push((
        CONTACT_SHEET.to_string(),
        contact_sheet(),
        "raystep stages".to_string(),
    ));
    for diagram in crate::tools::diagrams::DIAGRAMS {
        files.push((
            diagram.file(),
            diagram.svg(root)?.into_bytes(),
            format!("the diagram {} of src/tools/diagrams.rs", diagram.name),
        ));
    }
    Ok(files)
}

const fn fig(name: &'static str, args: &'static str, buffers: &'static [Buffer]) -> Figure {
    Figure {
        name,
        args,
        buffers,
    }
}

impl Figure {
    /// The file of one of its buffers, relative to `chapters/img/`.
    pub fn file(&self, buffer: Buffer) -> String {
        format!("{}-{}.png", self.name, buffer.name())
    }

    /// Render the figure; scene paths in `args` are relative to `root`. Returns each
    /// kept buffer's file name and PNG bytes.
    pub fn render(&self, root: &Path, run: Renderer) -> Result<Vec<(String, Vec<u8>)>, Error> {
        let frame = run(self.args, root)?;
        Ok(self
            .buffers
            .iter()
            .map(|&b| (self.file(b), png_bytes_as(&frame, b, self.png())))
            .collect())
    }

    /// The `--png` of its command (linear without one).
    pub fn png(&self) -> PngEncoding {
        let words: Vec<&str> = self.args.split_whitespace().collect();
        words
            .windows(2)
            .find(|w| w[0] == "--png")
            .and_then(|w| clap::ValueEnum::from_str(w[1], false).ok())
            .unwrap_or_default()
    }
}

/// Render every figure and draw every diagram into `out` (normally
/// `chapters/img`); scenes are read relative to `root`. Returns the files written.
pub fn write_all(root: &Path, out: &Path, run: Renderer) -> Result<Vec<PathBuf>, Error> {
    let mut written = Vec::new();
    for (file, bytes, _) in every_file(root, run)? {
        let path = out.join(file);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| Error::Output {
                path: dir.to_path_buf(),
                message: e.to_string(),
            })?;
        }
        crate::io::output::write_atomically(&path, &bytes)?;
        written.push(path);
    }
    Ok(written)
}

/// Re-render every figure and redraw every diagram, and compare with the files in
/// `out`: the problems found (a missing file, different bytes, a PNG or SVG in
/// `out` that nothing makes).
pub fn check_all(root: &Path, out: &Path, run: Renderer) -> Result<Vec<String>, Error> {
    let mut problems = Vec::new();
    let mut expected = Vec::new();
    for (file, bytes, command) in every_file(root, run)? {
        let path = out.join(&file);
        match std::fs::read(&path) {
            Err(_) => problems.push(format!("{file}: missing ({command})")),
            Ok(found) if found != bytes => {
                problems.push(format!("{file}: differs from what `{command}` renders now"))
            }
            Ok(_) => {}
        }
        expected.push(path);
    }
    for path in image_files(out) {
        if !expected.contains(&path) {
            problems.push(format!(
                "{}: no figure or diagram makes this image",
                path.display()
            ));
        }
    }
    Ok(problems)
}

/// The PNG and SVG files under `dir`, at any depth.
fn image_files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return found;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            found.extend(image_files(&path));
        } else if path.extension().is_some_and(|e| e == "png" || e == "svg") {
            found.push(path);
        }
    }
    found
}
