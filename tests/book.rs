//! The book checks itself: its listings come from real code, its pictures are what
//! the code renders now, and every number it quotes is measured again here.

use std::path::{Path, PathBuf};

use raystep::tools::cli::render_command;
use raystep::tools::compare::{compare, Difference};
use raystep::tools::figures::{check_all, FIGURES};

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

/// The appendix that states the tutorial's rules, listed after the chapters.
const APPENDIX: &str = "tutorial-rules.md";

#[test]
fn every_chapter_file_is_in_the_summary_and_there_are_eleven_chapters() {
    let listed: Vec<String> = chapters().into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        listed.len(),
        13,
        "the introduction, eleven chapters and the appendix: {listed:?}"
    );
    assert_eq!(listed[0], "introduction.md", "{listed:?}");
    for (i, name) in listed[1..12].iter().enumerate() {
        assert!(
            name.starts_with(&format!("{:02}-", i + 1)),
            "chapter {} should be numbered {:02}: {listed:?}",
            i + 1,
            i + 1
        );
    }
    assert_eq!(listed[12], APPENDIX, "the appendix comes last: {listed:?}");
    // A suffix chapter: a plain link after the numbered list, not an item of it.
    let summary = std::fs::read_to_string(root().join("chapters/SUMMARY.md")).unwrap();
    let lines: Vec<&str> = summary.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.contains(&format!("]({APPENDIX})")))
        .unwrap();
    assert!(
        lines[at].starts_with('[') && at > 0 && lines[at - 1].trim().is_empty(),
        "SUMMARY.md should list {APPENDIX} as a suffix chapter, after a blank line"
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
            name == "introduction.md" || name == APPENDIX || from_src > 0,
            "{name} shows no code from src/"
        );
        for (path, anchor) in includes(&text) {
            let file = root().join("chapters").join(&path);
            let source = std::fs::read_to_string(&file)
                .unwrap_or_else(|e| panic!("{name}: {{{{#include {path}}}}}: {e}"));
            // mdBook's line ranges: `file:5:` is line 5 to the end.
            let lines_from = anchor
                .as_deref()
                .and_then(|a| a.strip_suffix(':'))
                .and_then(|n| n.parse::<usize>().ok());
            let included = match &anchor {
                None => source.clone(),
                Some(_) if lines_from.is_some() => source
                    .lines()
                    .skip(lines_from.unwrap() - 1)
                    .collect::<Vec<_>>()
                    .join("\n"),
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
    let problems = check_all(&root(), &root().join("chapters/img"), &render_command).unwrap();
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
    let step = "render --stage shadow --offset fixed:1e-5";
    let none = "render --stage shadow --offset fixed:0";
    let d = diff(step, none);
    assert_quotes(
        "04",
        &format!(
            "{} pixels differ by more than one 8-bit step ({:.2} % of the image)",
            d.over_one_step,
            100.0 * d.over_one_step as f64 / d.pixels as f64
        ),
    );
    let (with, without) = (
        render_command(step, &root()).unwrap(),
        render_command(none, &root()).unwrap(),
    );
    let shadowed = with.pixels.iter().filter(|p| p.shadow == 0.0).count();
    let turned = with
        .pixels
        .iter()
        .zip(&without.pixels)
        .filter(|(a, b)| a.shadow == 0.0 && b.shadow == 1.0)
        .count();
    assert_quotes(
        "04",
        &format!("{turned} of the {shadowed} pixels in\nshadow with the step"),
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
    // Chapter 6: two segments against six.
    let m = "render scenes/mirrors.toml --stage reflection --max-depth";
    let d = diff(&format!("{m} 2"), &format!("{m} 6"));
    assert_quotes(
        "06",
        &format!(
            "{} pixels differ by more than one 8-bit step",
            d.over_one_step
        ),
    );
    // Chapter 7: the fake plane against a true one, and where they differ.
    let (fake, width) = beauty("render scenes/seed.toml");
    let (real, _) = beauty("render scenes/true-plane.toml");
    let d = compare(&fake, &real, width);
    let differing_rows: Vec<usize> = fake
        .iter()
        .zip(&real)
        .enumerate()
        .filter(|(_, (a, b))| (0..3).any(|c| (a[c] - b[c]).abs() > 1.0 / 255.0))
        .map(|(i, _)| i / width)
        .collect();
    let near_horizon = differing_rows
        .iter()
        .filter(|r| (97..=108).contains(*r))
        .count();
    assert_quotes(
        "07",
        &format!("{} pixels differ by more than one 8-bit step (2.26 % of the picture), and {near_horizon} of\nthem lie in rows 97 to 108", d.over_one_step),
    );
    // Chapter 8: the viewer on a bounce, with the tutorial's rules; the whole
    // `raystep diff` report is quoted.
    let d = diff("render --tutorial", "render --tutorial --viewer ray-origin");
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
    // The tutorial's own count for the same change, as the appendix states it:
    // 2,660 pixels.
    assert_eq!(d.over_one_step, 2660);
    assert_quotes("tutorial-rules", "2,660 pixels by more than 1/255");
}

#[test]
fn every_accuracy_row_a_chapter_quotes_is_what_raystep_accuracy_prints_now() {
    let rows: Vec<String> = raystep::tools::accuracy::measure_all()
        .iter()
        .map(raystep::tools::accuracy::table_row)
        .collect();
    let header = raystep::tools::accuracy::table_header();
    let mut quoted = 0;
    for (name, text) in chapters() {
        for line in text.lines() {
            let first = line.split_whitespace().next().unwrap_or("");
            if raystep::tools::accuracy::CASES
                .iter()
                .any(|(case, _)| *case == first)
                && line.contains("  f")
            {
                assert!(
                    rows.iter().any(|r| r == line),
                    "{name} quotes a row `raystep accuracy` no longer prints:\n{line}"
                );
                quoted += 1;
            }
            if line.starts_with("case ") {
                assert_eq!(line, header, "{name}: the table header");
            }
        }
    }
    assert!(quoted >= 20, "{quoted} rows quoted");
}

#[test]
fn chapter_1_quotes_what_check_prints() {
    let scene = raystep::io::scene_file::load(&root().join("scenes/seed.toml")).unwrap();
    assert_quotes(
        "01",
        &raystep::tools::cli::describe(&scene, "scenes/seed.toml"),
    );
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
        "the last row of sky is row 101 across most of the width and row\n102 near the edges, against row 99",
    );
}

#[test]
fn the_book_builds_paths_from_its_own_folder() {
    let toml = std::fs::read_to_string(root().join("book/book.toml")).unwrap();
    assert!(toml.contains("src = \"../chapters\""));
    assert!(toml.contains("build-dir = \"../target/book\""));
    assert!(Path::new(&root().join("chapters/img")).is_dir());
}

#[test]
fn the_charts_shown_exist_and_their_numbers_are_the_csv_files() {
    let text = chapter("10");
    for chart in ["charts/chart.svg", "charts/scale.svg"] {
        assert!(
            text.contains(&format!("]({chart})")),
            "chapter 10 shows {chart}"
        );
        assert!(
            root().join("chapters").join(chart).is_file(),
            "{chart} exists"
        );
    }
    for command in [
        "raystep chart --runs 15 --out chapters/charts",
        "raystep chart --scale --runs 3 --out chapters/charts",
    ] {
        assert!(text.contains(command), "chapter 10 shows `{command}`");
    }
    // The errors the chapter quotes are the chart's.
    let csv = std::fs::read_to_string(root().join("chapters/charts/chart.csv")).unwrap();
    let rmse = |setting: &str| -> f64 {
        let row = csv
            .lines()
            .find(|l| l.starts_with(&format!("{setting},")))
            .unwrap();
        row.split(',').nth(2).unwrap().parse().unwrap()
    };
    assert!((rmse("default") - 2.1).abs() < 0.05 && (rmse("depth 1") - 18.0).abs() < 0.1);
    assert!(rmse("f32") > 2.0 * rmse("default") - 0.1);
    assert_eq!(rmse("naive"), rmse("default"));
    assert_eq!(rmse("accel off"), rmse("default"));
    assert_eq!(rmse("book engine"), rmse("default"));
    assert_eq!(rmse("early stop off"), rmse("default"));
}

#[test]
fn chapter_11_tells_the_story_explain_tells_now() {
    // The story is included from its insta snapshot (tests/explain.rs locks it);
    // check that the snapshot's text starts at the line the chapter includes from.
    let text = chapter("11");
    let include = "{{#include ../tests/snapshots/explain__floor-in-shadow.snap:5:}}";
    assert!(
        text.contains(include),
        "chapter 11 should include {include}"
    );
    let snap =
        std::fs::read_to_string(root().join("tests/snapshots/explain__floor-in-shadow.snap"))
            .unwrap();
    let fifth = snap.lines().nth(4).unwrap();
    assert!(fifth.starts_with("pixel x = 74, y = 125"), "{fifth}");
    assert!(text.contains("explain --pixel 74,125"));
    let scene = raystep::io::scene_file::seed();
    let settings = raystep::render::Settings::from(raystep::stages::Stages::ALL);
    let story = raystep::tools::explain::explain(&scene, &settings, 74, 125);
    assert!(snap.contains(story.to_string().trim_end()));
    // What the chapter reads off the story.
    for quoted in ["at t = 4.65", "12.17 away", "at 2.78", "1.7e-11"] {
        assert!(text.contains(quoted), "chapter 11 should say {quoted:?}");
    }
    assert!(story
        .to_string()
        .contains("object 0 at 2.78469 < 12.1712: in shadow"));
}
