//! The book checks itself: its listings come from real code, its pictures are what
//! the code renders now, and every number it quotes is measured again here.

use std::path::{Path, PathBuf};

use raystep::compare::{compare, Difference};
use raystep::figures::{check_all, render_command, FIGURES};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every chapter, as listed in SUMMARY.md: (file name, text).
fn chapters() -> Vec<(String, String)> {
    let dir = root().join("chapters");
    let summary = std::fs::read_to_string(dir.join("SUMMARY.md")).unwrap();
    let mut found = Vec::new();
    for line in summary.lines() {
        if let Some(start) = line.find("](") {
            let name = &line[start + 2..line[start..].find(')').unwrap() + start];
            let text = std::fs::read_to_string(dir.join(name))
                .unwrap_or_else(|e| panic!("SUMMARY.md lists {name}: {e}"));
            found.push((name.to_string(), text));
        }
    }
    found
}

fn chapter(prefix: &str) -> String {
    chapters()
        .into_iter()
        .find(|(name, _)| name.starts_with(prefix))
        .unwrap_or_else(|| panic!("no chapter {prefix}"))
        .1
}

/// The `{{#include …}}` directives of a text: (path, optional anchor).
fn includes(text: &str) -> Vec<(String, Option<String>)> {
    let mut found = Vec::new();
    let mut rest = text;
    while let Some(start) = rest.find("{{#include ") {
        let end = rest[start..].find("}}").unwrap() + start;
        let target = rest[start + "{{#include ".len()..end].trim();
        let (path, anchor) = match target.split_once(':') {
            Some((p, a)) => (p.to_string(), Some(a.to_string())),
            None => (target.to_string(), None),
        };
        found.push((path, anchor));
        rest = &rest[end..];
    }
    found
}

#[test]
fn every_chapter_file_is_in_the_summary_and_there_are_eight_chapters() {
    let listed: Vec<String> = chapters().into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        listed.len(),
        9,
        "the introduction and eight chapters: {listed:?}"
    );
    for entry in std::fs::read_dir(root().join("chapters")).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if name.ends_with(".md") && name != "SUMMARY.md" {
            assert!(listed.contains(&name), "{name} is not in SUMMARY.md");
        }
    }
}

#[test]
fn every_include_names_a_file_and_anchor_with_text() {
    for (name, text) in chapters() {
        let from_src = includes(&text)
            .iter()
            .filter(|(p, _)| p.starts_with("../src/"))
            .count();
        assert!(
            name == "introduction.md" || from_src > 0,
            "{name} shows no code from src/"
        );
        for (path, anchor) in includes(&text) {
            let file = root().join("chapters").join(&path);
            let source = std::fs::read_to_string(&file)
                .unwrap_or_else(|e| panic!("{name}: {{{{#include {path}}}}}: {e}"));
            let included = match &anchor {
                None => source.clone(),
                Some(anchor) => {
                    let start = format!("ANCHOR: {anchor}");
                    let end = format!("ANCHOR_END: {anchor}");
                    let lines: Vec<&str> = source.lines().collect();
                    let from = lines.iter().position(|l| l.trim_end().ends_with(&start));
                    let to = lines.iter().position(|l| l.trim_end().ends_with(&end));
                    let (Some(from), Some(to)) = (from, to) else {
                        panic!(
                            "{name}: {path} has no anchor `{anchor}` (both ANCHOR and ANCHOR_END)"
                        );
                    };
                    lines[from + 1..to]
                        .iter()
                        .filter(|l| !l.contains("ANCHOR"))
                        .copied()
                        .collect::<Vec<_>>()
                        .join("\n")
                }
            };
            assert!(
                included.trim().len() > 20,
                "{name}: {path}:{anchor:?} includes almost nothing"
            );
        }
    }
}

#[test]
fn rust_blocks_are_included_from_the_compiled_source() {
    for (name, text) in chapters() {
        let mut in_rust = false;
        for line in text.lines() {
            let fence = line.trim_start().starts_with("```");
            if fence && !in_rust && line.trim_start().starts_with("```rust") {
                let marked = line.contains("ignore") || line.contains("compile_fail");
                in_rust = !marked;
            } else if fence && in_rust {
                in_rust = false;
            } else if in_rust {
                assert!(
                    line.trim().is_empty() || line.contains("{{#include ../src/"),
                    "{name}: a Rust block holds code that is not included from src/ \
                     (include it, or mark the block `ignore`): {line}"
                );
            }
        }
    }
}

/// Image paths a chapter shows: `![...](img/...)`.
fn images(text: &str) -> Vec<String> {
    text.match_indices("](img/")
        .map(|(i, _)| {
            let start = i + 2;
            text[start..start + text[start..].find(')').unwrap()].to_string()
        })
        .collect()
}

#[test]
fn every_image_shown_exists_and_every_image_is_shown() {
    let mut shown = Vec::new();
    for (name, text) in chapters() {
        for image in images(&text) {
            assert!(
                root().join("chapters").join(&image).is_file(),
                "{name} shows {image}, which does not exist"
            );
            shown.push(image);
        }
    }
    for figure in FIGURES {
        for &buffer in figure.buffers {
            let file = format!("img/{}", figure.file(buffer));
            assert!(
                shown.contains(&file),
                "{file} is made but no chapter shows it"
            );
        }
    }
}

#[test]
fn every_figure_shows_the_command_that_made_it() {
    for figure in FIGURES {
        let prefix = &figure.name[2..4]; // "ch04/acne" -> "04"
        let text = chapter(prefix);
        let command = format!("raystep {}", figure.args);
        assert!(
            text.contains(&command),
            "chapter {prefix} shows {} without `{command}`",
            figure.name
        );
    }
}

#[test]
fn the_committed_figures_are_what_the_code_renders_now() {
    let problems = check_all(&root(), &root().join("chapters/img")).unwrap();
    assert!(
        problems.is_empty(),
        "run `cargo run --release -- figures` and look at the images:\n{}",
        problems.join("\n")
    );
}

fn beauty(args: &str) -> (Vec<[f32; 3]>, usize) {
    let frame = render_command(args, &root()).unwrap();
    (
        frame.pixels.iter().map(|p| p.colour).collect(),
        frame.width as usize,
    )
}

fn diff(a: &str, b: &str) -> Difference {
    let ((a, width), (b, _)) = (beauty(a), beauty(b));
    compare(&a, &b, width)
}

fn assert_quotes(prefix: &str, quoted: &str) {
    assert!(
        chapter(prefix).contains(quoted),
        "chapter {prefix} should say {quoted:?}"
    );
}

#[test]
fn the_numbers_the_chapters_quote_are_measured_again() {
    // Chapter 4: acne without the step.
    let d = diff(
        "render --stage shadow",
        "render --stage shadow --offset fixed:0",
    );
    assert_quotes(
        "04",
        &format!(
            "{} pixels differ by more than one 8-bit step",
            d.over_one_step
        ),
    );
    // Chapter 5: Blinn-Phong with and without the shadow stage.
    let d = diff(
        "render --stage blinn-phong",
        "render --stage blinn-phong --without shadow",
    );
    assert_quotes(
        "05",
        &format!(
            "{} pixels differ by more than one 8-bit step",
            d.over_one_step
        ),
    );
    // Chapter 7: the fake plane against a true one.
    let d = diff("render scenes/seed.toml", "render scenes/true-plane.toml");
    assert_quotes(
        "07",
        &format!(
            "{} pixels differ by more than one 8-bit step",
            d.over_one_step
        ),
    );
    // Chapter 8: the viewer on a bounce; the whole `raystep diff` report is quoted.
    let d = diff("render", "render --viewer ray-origin");
    let report = format!(
        "  differ by more than 1/255: {} pixels ({:.2} %)\n  largest difference:        {:.4} (row {}, column {})\n  root mean square:          {:.6}\n  clipped (a channel at 1):  {} and {} pixels",
        d.over_one_step,
        100.0 * d.over_one_step as f64 / d.pixels as f64,
        d.largest,
        d.largest_at.0,
        d.largest_at.1,
        d.rmse,
        d.saturated.0,
        d.saturated.1
    );
    assert_quotes("08", &report);
    assert_quotes(
        "08",
        &format!(
            "{} of the 60,000 pixels have a channel clipped",
            d.saturated.0
        ),
    );
    // The tutorial's own count for the same change (TUTORIAL.md): 2,660 pixels.
    assert_eq!(d.over_one_step, 2660);
}

#[test]
fn chapter_1_quotes_what_check_prints() {
    let scene = raystep::scene_file::load(&root().join("scenes/seed.toml")).unwrap();
    assert_quotes("01", &raystep::cli::describe(&scene, "scenes/seed.toml"));
}

#[test]
fn chapter_2_quotes_the_top_left_pixel() {
    let frame = render_command("render scenes/seed.toml --stage rays", &root()).unwrap();
    let rgb: Vec<u8> = frame
        .at(0, 0)
        .colour
        .iter()
        .map(|c| (c * 255.0).round() as u8)
        .collect();
    assert_quotes(
        "02",
        &format!("({}, {}, {}) in 8 bits", rgb[0], rgb[1], rgb[2]),
    );
}

#[test]
fn chapter_7_quotes_where_the_horizons_are() {
    // The topmost row whose primary ray hits the floor, in a column clear of spheres.
    let top_floor_row = |args: &str, col: u32| {
        let frame = render_command(args, &root()).unwrap();
        (0..frame.height)
            .find(|&row| frame.at(row, col).is_hit())
            .unwrap()
    };
    let rows = |args: &str| [0, 75, 225, 299].map(|col| top_floor_row(args, col) - 1);
    let fake = rows("render scenes/seed.toml");
    let real = rows("render scenes/true-plane.toml");
    assert_eq!(real, [99; 4], "the true plane's horizon");
    assert_eq!(
        fake,
        [102, 101, 101, 102],
        "the fake plane's horizon, lower at the edges"
    );
    assert_quotes(
        "07",
        "rows 101\nand 102 of the 300 × 200 picture, against row 99",
    );
}

#[test]
fn the_book_builds_paths_from_its_own_folder() {
    let toml = std::fs::read_to_string(root().join("book/book.toml")).unwrap();
    assert!(toml.contains("src = \"../chapters\""));
    assert!(toml.contains("build-dir = \"../target/book\""));
    assert!(Path::new(&root().join("chapters/img")).is_dir());
}
