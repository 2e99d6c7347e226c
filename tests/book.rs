//! The book checks itself: its listings come from real code, its pictures are what
//! the code renders now, and every number it quotes is measured again here, or,
//! for the timings of chapters 9 and 10, which depend on the machine, read from
//! the CSV files `raystep chart` wrote beside the charts it shows.

mod common;

use std::collections::BTreeSet;
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

/// The numbered chapters.
const CHAPTERS: usize = 13;

/// Everything SUMMARY.md lists after the numbered chapters, in order: suffix
/// chapters that show no code of their own.
const APPENDICES: &[&str] = &[APPENDIX, ANSWERS, "notes/speed-log.md"];

/// The appendix that answers the exercises, a section for each chapter that has
/// some.
const ANSWERS: &str = "answers.md";

/// The top-level items (`1. `, `2. `, …) of the numbered lists in `section`.
fn numbered_items(section: &str) -> usize {
    let item = |l: &&str| {
        let digits = l.len() - l.trim_start_matches(|c: char| c.is_ascii_digit()).len();
        digits > 0 && l[digits..].starts_with(". ")
    };
    section.lines().filter(item).count()
}

#[test]
fn the_answers_appendix_answers_every_exercise_of_every_chapter() {
    let answers = chapters()
        .into_iter()
        .find(|(name, _)| name == ANSWERS)
        .expect("SUMMARY.md lists the answers")
        .1;
    // The appendix's sections, each from its `## ` heading to the next.
    let sections: Vec<&str> = answers.split("\n## ").skip(1).collect();
    let mut answered = 0;
    for (name, text) in chapters() {
        let Some((_, exercises)) = text.split_once("\n## Exercises\n") else {
            continue;
        };
        let exercises = numbered_items(exercises.split("\n## ").next().unwrap());
        // A section that links to the chapter's exercises, an answer for each.
        let link = format!("]({name}#exercises)");
        let section = sections
            .iter()
            .find(|s| s.contains(&link))
            .unwrap_or_else(|| panic!("{ANSWERS} has no section linking {link}"));
        assert_eq!(
            numbered_items(section),
            exercises,
            "{ANSWERS} should answer each of the {exercises} exercises of {name}"
        );
        answered += 1;
    }
    assert!(answered >= 9, "{answered} chapters with exercises");
}

#[test]
fn every_chapter_file_is_in_the_summary_and_there_are_thirteen_chapters() {
    let listed: Vec<String> = chapters().into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        listed.len(),
        1 + CHAPTERS + APPENDICES.len(),
        "the introduction, {CHAPTERS} chapters and the appendices: {listed:?}"
    );
    assert_eq!(listed[0], "introduction.md", "{listed:?}");
    for (i, name) in listed[1..=CHAPTERS].iter().enumerate() {
        assert!(
            name.starts_with(&format!("{:02}-", i + 1)),
            "chapter {} should be numbered {:02}: {listed:?}",
            i + 1,
            i + 1
        );
    }
    assert_eq!(
        listed[1 + CHAPTERS..],
        *APPENDICES,
        "the appendices come last: {listed:?}"
    );
    // Suffix chapters: plain links after the numbered list, not items of it.
    let summary = std::fs::read_to_string(root().join("chapters/SUMMARY.md")).unwrap();
    let lines: Vec<&str> = summary.lines().collect();
    let first = lines
        .iter()
        .position(|l| l.contains(&format!("]({APPENDIX})")))
        .unwrap();
    assert!(
        first > 0 && lines[first - 1].trim().is_empty(),
        "SUMMARY.md should list {APPENDIX} as a suffix chapter, after a blank line"
    );
    for appendix in APPENDICES {
        let line = lines.iter().find(|l| l.contains(&format!("]({appendix})")));
        assert!(
            line.is_some_and(|l| l.starts_with('[')),
            "SUMMARY.md should list {appendix} as a suffix chapter"
        );
    }
    for dir in ["", "notes"] {
        for entry in std::fs::read_dir(root().join("chapters").join(dir)).unwrap() {
            let name = entry.unwrap().file_name().to_string_lossy().into_owned();
            let name = if dir.is_empty() {
                name
            } else {
                format!("{dir}/{name}")
            };
            if name.ends_with(".md") && name != "SUMMARY.md" {
                assert!(listed.contains(&name), "{name} is not in SUMMARY.md");
            }
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
            name == "introduction.md" || APPENDICES.contains(&name.as_str()) || from_src > 0,
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
                // From src/, or from a test's Rust file, which `cargo test` builds.
                let compiled = line.contains("{{#include ../src/")
                    || (line.contains("{{#include ../tests/") && line.contains(".rs:"));
                assert!(
                    line.trim().is_empty() || compiled,
                    "{name}: a Rust block holds code that is not included from src/ \
                     or tests/ (include it, or mark the block `ignore`): {line}"
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
    // Chapters 4 and 9, and the README: the defaults against the tutorial's step
    // alone, and against every tutorial setting (the same pixels: the step is
    // what changes them).
    let defaults = "render";
    for (other, prefix, words) in [
        (
            "render --offset fixed:1e-5",
            "04",
            "the two pictures differ in",
        ),
        (
            "render --tutorial",
            "09",
            "the defaults differ from `--tutorial` in",
        ),
    ] {
        let d = diff(defaults, other);
        let quoted = format!("{words} {} pixels", d.over_one_step);
        let text = common::words(&chapter(prefix));
        assert!(
            text.contains(&quoted),
            "chapter {prefix} should say {quoted:?}"
        );
        if prefix == "09" {
            let readme = common::readme_words();
            let quoted = format!(
                "the defaults change {} of the 60,000 pixels by more than one 8-bit step",
                d.over_one_step
            );
            assert!(readme.contains(&quoted), "the README should say {quoted:?}");
        }
    }
    // Chapter 4's account of those pixels: in some the shadow mask differs; the
    // rest are lit in both pictures, and there the reflected rays take another
    // path (the `rays` buffer differs). Objects 0 and 3 of the seed scene are
    // the red sphere and the floor.
    let auto = render_command(defaults, &root()).unwrap();
    let fixed = render_command("render --offset fixed:1e-5", &root()).unwrap();
    let tutorial = render_command("render --tutorial", &root()).unwrap();
    // Where `other`'s colour differs from the defaults' by more than one 8-bit
    // step, the pixels `compare` counts in `over_one_step`.
    let places = |other: &raystep::aov::Frame| -> Vec<usize> {
        (auto.pixels.iter().zip(&other.pixels).enumerate())
            .filter(|(_, (a, b))| (0..3).any(|c| (a.colour[c] - b.colour[c]).abs() > 1.0 / 255.0))
            .map(|(i, _)| i)
            .collect()
    };
    let differing = places(&fixed);
    let colours = |frame: &raystep::aov::Frame| -> Vec<[f32; 3]> {
        frame.pixels.iter().map(|p| p.colour).collect()
    };
    let width = auto.width as usize;
    assert_eq!(
        differing.len(),
        compare(&colours(&auto), &colours(&fixed), width).over_one_step
    );
    let (masked, lit): (Vec<usize>, Vec<usize>) = differing
        .iter()
        .partition(|&&i| auto.pixels[i].shadow != fixed.pixels[i].shadow);
    for (a, b) in lit.iter().map(|&i| (&auto.pixels[i], &fixed.pixels[i])) {
        assert_eq!((a.shadow, b.shadow), (1.0, 1.0), "{a:?} {b:?}");
        assert_ne!(a.rays, b.rays, "{a:?} {b:?}");
    }
    let on = |object: u32| {
        lit.iter()
            .filter(|&&i| auto.pixels[i].object == object)
            .count()
    };
    assert_eq!(on(0) + on(3), lit.len());
    let quoted = format!(
        "In {} of them, along the edges of the dark sides, the shadow mask differs; the \
         other {}, {} on the floor and {} on the red sphere, are lit in both",
        masked.len(),
        lit.len(),
        on(3),
        on(0)
    );
    assert!(
        common::words(&chapter("04")).contains(&quoted),
        "chapter 4 should say {quoted:?}"
    );
    // Chapter 9: `--tutorial` changes the same pixels as its step alone.
    assert_eq!(places(&tutorial), differing);
    let quoted = format!(
        "{} along the edges of the dark sides, which the 1e-5 step wrongly lit, and {} lit \
         in both whose reflected rays take another path (the same {} pixels as",
        masked.len(),
        lit.len(),
        differing.len()
    );
    assert!(
        common::words(&chapter("09")).contains(&quoted),
        "chapter 9 should say {quoted:?}"
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
        &format!(
            "{} pixels differ by more than one 8-bit step ({:.2} % of the picture), and {near_horizon} of\nthem lie in rows 97 to 108",
            d.over_one_step,
            100.0 * d.over_one_step as f64 / d.pixels as f64
        ),
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

/// The appendix's float32 floor point that the tutorial's step leaves inside the
/// floor: `raystep explain --tutorial --precision f32 --pixel 147,108`, whose
/// third segment finds one of the floor's roots negative.
#[test]
fn the_appendix_shows_a_float32_floor_point_the_step_leaves_inside() {
    let scene = raystep::io::scene_file::seed();
    let settings = raystep::render::Settings {
        precision: raystep::real::Precision::F32,
        ..raystep::render::Settings::tutorial(raystep::stages::Stages::ALL)
    };
    let story = raystep::tools::explain::explain(&scene, &settings, 147, 108).to_string();
    let third = story.split("segment 2:").nth(1).expect("a third segment");
    let mut lines = third.lines().skip_while(|l| !l.contains("(the floor)"));
    let floor = lines.next().expect("the floor's test");
    let verdict = lines.next().unwrap();
    let roots = floor.split("roots ").nth(1).unwrap().replace('-', "−");
    let (near, far) = roots.split_once(", ").unwrap();
    assert!(near.starts_with('−') && !far.starts_with('−'), "{floor}");
    let inside = "one root negative, the ray starts inside the sphere";
    assert!(verdict.contains(inside), "{verdict}");
    let words = common::words(&chapter("tutorial-rules"));
    for quoted in [
        "explain --tutorial --precision f32 --pixel 147,108".to_string(),
        format!("the floor's roots {near} and {far}, \"{inside}\""),
    ] {
        assert!(
            words.contains(&quoted),
            "the appendix should say {quoted:?}"
        );
    }
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
    let described = raystep::tools::cli::describe(
        &scene,
        "scenes/seed.toml",
        Some(raystep::tools::cli::LISTED),
    );
    // Figure 1's four spheres, its light and its camera, a line each at least.
    assert!(described.lines().count() > 5, "{described}");
    assert_quotes("01", &described);
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
        "raystep chart --scale --runs 7 --out chapters/charts",
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
    assert_quotes(
        "10",
        &format!("about {:.1}\n  levels of error", rmse("default")),
    );
    assert_quotes("10", &format!("({:.0}\n  levels)", rmse("depth 1")));
    assert!(rmse("f32") > 1.4 * rmse("default"));
    assert_eq!(rmse("naive"), rmse("default"));
    assert_eq!(rmse("accel off"), rmse("default"));
    assert_eq!(rmse("book engine"), rmse("default"));
    assert_eq!(rmse("early stop off"), rmse("default"));
}

/// A column of `chapters/charts/chart.csv` for one setting: 1 the median time in
/// ms, 2 the error in 8-bit levels.
fn chart_value(setting: &str, column: usize) -> f64 {
    let csv = std::fs::read_to_string(root().join("chapters/charts/chart.csv")).unwrap();
    // A label with a comma is quoted ("f32, offset scene"): split from the right.
    let row = csv
        .lines()
        .find(|l| {
            l.starts_with(&format!("{setting},")) || l.starts_with(&format!("\"{setting}\","))
        })
        .unwrap_or_else(|| panic!("chart.csv has no row {setting}"));
    let fields: Vec<&str> = row.rsplitn(6, ',').collect();
    fields[5 - column].parse().unwrap()
}

#[test]
fn chapter_10_quotes_the_charts_csv_files() {
    let text = chapter("10");
    // The scale chart: 10 against 100,000 spheres with the BVH, and the tree of a
    // million.
    let csv = std::fs::read_to_string(root().join("chapters/charts/scale.csv")).unwrap();
    let row = |spheres: &str| -> Vec<f64> {
        let line = csv
            .lines()
            .find(|l| l.starts_with(&format!("{spheres},auto,")))
            .unwrap_or_else(|| panic!("scale.csv has no row {spheres},auto"));
        line.split(',')
            .skip(2)
            .map(|v| v.parse().unwrap())
            .collect()
    };
    let (ten, many, million) = (row("10"), row("100000"), row("1000000"));
    let quoted = format!(
        "10 spheres take {:.0} ms a frame and 100,000 take {:.0} ms, {:.1} times as long",
        ten[0],
        many[0],
        many[0] / ten[0]
    );
    assert!(text.contains(&quoted), "chapter 10 should say {quoted:?}");
    for quoted in [
        format!("tree of a million spheres is {:.0} MB", million[2] / 1e6),
        format!(
            "building it takes {:.0} ms, a third of that frame",
            million[1]
        ),
    ] {
        assert!(text.contains(&quoted), "chapter 10 should say {quoted:?}");
    }
    let third = million[1] / million[0];
    assert!((0.28..0.4).contains(&third), "a third: {third}");
    // The rays alone (the last column) are part of every frame.
    assert!(ten[3] <= ten[0] && many[3] <= many[0] && million[3] <= million[0]);
    // "a little more than the number of paths a pixel traces (N + 1)".
    let ms = |setting| chart_value(setting, 1);
    for (setting, n) in [("spp 4", 4.0), ("spp 16", 16.0)] {
        let times = ms(setting) / ms("default");
        assert!(
            times > n + 1.0 && times < 1.5 * (n + 1.0),
            "{setting}: {times}"
        );
    }
    // "saves two fifths of the rays" between two facing mirrors (exercise 3).
    assert!(text.contains("it saves two fifths of the rays"));
}

#[test]
fn chapter_9_quotes_the_timings_of_the_chart() {
    let ms = |setting| chart_value(setting, 1);
    let (default, f32, tutorial, naive) = (ms("default"), ms("f32"), ms("tutorial"), ms("naive"));
    let saves = |t: f64| (100.0 * (1.0 - t / default)).round();
    assert_quotes(
        "09",
        &format!(
            "float32 saves {} % of a frame ({f32:.1} ms against {default:.1} ms)",
            saves(f32)
        ),
    );
    assert_quotes(
        "09",
        &format!("the fixed step) {} %\n({tutorial:.1} ms)", saves(tutorial)),
    );
    assert_quotes(
        "09",
        &format!("gives {naive:.1} ms against {default:.1} ms"),
    );
    // What the bound's step costs against the scene-sized one it replaced
    // (issue 24): the same picture on figure 1, at about the same time.
    let (scene, f32_scene) = (ms("offset scene"), ms("f32, offset scene"));
    assert_quotes(
        "09",
        &format!("`offset scene` takes {scene:.1} ms against the default's {default:.1} ms"),
    );
    assert_quotes(
        "09",
        &format!("`f32, offset scene` {f32_scene:.1} ms against float32's {f32:.1} ms"),
    );
    assert_eq!(chart_value("offset scene", 2), chart_value("default", 2));
    // "costs nothing measurable": within a tenth either way in the committed chart.
    assert!((naive / default - 1.0).abs() < 0.1);
    // "at most a quarter of a frame": neither saving is larger.
    assert!(f32.min(tutorial) >= default * 3.0 / 4.0);
    // "half as large again", and more than double with the scene-sized step.
    let error = |setting| chart_value(setting, 2);
    assert!((error("f32") / error("default") - 1.5).abs() < 0.05);
    assert!(error("f32, offset scene") > 2.0 * error("default"));
    assert_quotes(
        "09",
        &format!(
            "{:.1}\nlevels against {:.1}",
            error("f32"),
            error("default")
        ),
    );
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
    for quoted in ["at t = 4.65", "12.17 away", "at 2.78", "8.8e-12"] {
        assert!(text.contains(quoted), "chapter 11 should say {quoted:?}");
    }
    assert!(story
        .to_string()
        .contains("object 0 at 2.78469 < 12.1712: in shadow"));
}

#[test]
fn every_diagram_is_shown_with_a_caption_in_its_chapter_and_is_committed_as_drawn() {
    use raystep::tools::diagrams::DIAGRAMS;
    assert!(DIAGRAMS.len() >= 7, "{} diagrams", DIAGRAMS.len());
    for diagram in DIAGRAMS {
        let file = diagram.file();
        let prefix = &diagram.name[2..4]; // "ch02/camera" -> "02"
        let text = chapter(prefix);
        // Shown by its own chapter, with alt text and a caption under it.
        let reference = format!("](img/{file})");
        let at = text
            .find(&reference)
            .unwrap_or_else(|| panic!("chapter {prefix} does not show img/{file}"));
        assert!(images(&text).contains(&format!("img/{file}")));
        let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
        let alt = &text[line_start..at];
        assert!(
            alt.starts_with("![") && alt.len() > 40,
            "chapter {prefix}: img/{file} needs alt text that says what it shows"
        );
        let after = &text[at + reference.len()..];
        let caption = after.trim_start_matches('\n').lines().next().unwrap_or("");
        assert!(
            caption.starts_with('*'),
            "chapter {prefix}: img/{file} needs a caption in italics under it"
        );
        // Committed, and what the code draws now.
        let path = root().join("chapters/img").join(&file);
        let committed = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e}; run `raystep figures`", path.display()));
        assert_eq!(
            committed,
            diagram.svg(&root()).unwrap(),
            "{file} differs from what src/tools/diagrams.rs draws now; run `raystep figures`"
        );
    }
}

/// The rows of the Markdown tables in `text` whose first cell is a path in
/// backticks: (path, the items in backticks of the second cell).
fn file_rows(text: &str) -> Vec<(String, Vec<String>)> {
    let mut rows = Vec::new();
    for line in text.lines() {
        let Some(rest) = line.strip_prefix("| `") else {
            continue;
        };
        let cells: Vec<&str> = rest.split(" | ").collect();
        let path = cells[0].trim_end_matches('`');
        let items = cells.get(1).map_or(Vec::new(), |cell| {
            cell.split('`')
                .skip(1)
                .step_by(2)
                .map(String::from)
                .collect()
        });
        rows.push((path.to_string(), items));
    }
    rows
}

/// The `.rs` files under `dir`, as paths from the repository's root.
fn rust_files(dir: &Path, found: &mut Vec<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, found);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let relative = path.strip_prefix(root()).unwrap();
            found.push(relative.to_string_lossy().replace('\\', "/"));
        }
    }
}

#[test]
fn chapter_12_names_every_file_that_names_the_stages() {
    use raystep::stages::Stage;
    let text = chapter("12");
    let rows = file_rows(&text);
    assert!(rows.len() >= 20, "chapter 12's tables: {rows:?}");
    // Each file named exists and holds what the chapter quotes from it.
    for (path, items) in &rows {
        let source = std::fs::read_to_string(root().join(path))
            .unwrap_or_else(|e| panic!("chapter 12 names {path}: {e}"));
        assert!(!items.is_empty(), "chapter 12 quotes nothing from {path}");
        for item in items {
            assert!(
                source.contains(item.as_str()),
                "chapter 12 says {path} holds `{item}`"
            );
        }
    }
    // Every file of src/ that names a stage, the list of stages or a stage's
    // switch is in a table.
    let mut patterns = vec![
        "Stage::ALL".to_string(),
        "Stages::ALL".into(),
        "Stages::up_to".into(),
        "Stages::select".into(),
    ];
    for stage in Stage::ALL {
        patterns.push(format!("Stage::{stage:?}"));
        patterns.push(format!("stages.{}", stage.name().replace('-', "_")));
    }
    let mut files = Vec::new();
    rust_files(&root().join("src"), &mut files);
    let mut naming = 0;
    for file in files {
        let source = std::fs::read_to_string(root().join(&file)).unwrap();
        if let Some(pattern) = patterns.iter().find(|p| source.contains(p.as_str())) {
            naming += 1;
            assert!(
                rows.iter().any(|(path, _)| *path == file),
                "{file} holds `{pattern}`: chapter 12's table should name it"
            );
        }
    }
    assert!(naming >= 10, "{naming} files of src/ name the stages");
}

/// Chapter 12's exercise 2, done: `chapters/answers/occlusion-stage.patch` makes
/// the stage real as the chapter's table says, and the chapter lists the tests
/// that failed with it. Every file the patch changes is named in the chapter, and
/// the patch must still apply to the code of today: when it stops applying, the
/// list may be stale. Make the stage again on the new code (`git apply -3` does
/// most of it), run the tests as the chapter says, correct its list, and commit
/// the new patch.
#[test]
fn chapter_12_exercise_2s_answer_applies_to_the_code_of_today() {
    let patch = "chapters/answers/occlusion-stage.patch";
    let text = std::fs::read_to_string(root().join(patch)).unwrap();
    let chapter = chapter("12");
    assert!(chapter.contains(patch), "chapter 12 names {patch}");
    let changed: Vec<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix("+++ b/"))
        .collect();
    assert!(changed.len() >= 15, "{changed:?}");
    for file in &changed {
        assert!(
            chapter.contains(&format!("`{file}`")),
            "the answer changes {file}, which chapter 12 does not name"
        );
    }
    let git = std::process::Command::new("git")
        .args(["apply", "--check", patch])
        .current_dir(root())
        .output()
        .map_err(|e| format!("git ({e})"));
    let Some(git) = common::required(git, "applying chapter 12's answer") else {
        return;
    };
    assert!(
        git.status.success(),
        "{patch} no longer applies, so chapter 12's list of failing tests may be \
         stale: {}",
        String::from_utf8_lossy(&git.stderr)
    );
}

/// The tests an answer's edit makes fail, as `.ci/answers` measured them
/// (`chapters/answers/NAME.failures`, one `PROGRAM: TEST` a line).
fn failures_of(answer: &str) -> Vec<(String, String)> {
    let path = root().join(format!("chapters/answers/{answer}.failures"));
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|line| {
            let (program, test) = line.split_once(": ").unwrap_or_else(|| panic!("{line}"));
            (program.to_string(), test.to_string())
        })
        .collect()
}

/// The words the answers count test programs in.
fn in_words(n: usize) -> &'static str {
    const WORDS: [&str; 13] = [
        "no", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten",
        "eleven", "twelve",
    ];
    WORDS[n]
}

/// Every edit of the book's code that an exercise asks for is a patch in
/// `chapters/answers/`, with the list of the tests it makes fail beside it,
/// which `.ci/answers` checks by applying the patch to a copy and running the
/// tests. Here: the answers' words give that list's counts, and chapter 12's
/// table names exactly its tests.
#[test]
fn the_answers_count_and_name_the_tests_their_edits_make_fail() {
    let flat = |text: &str| text.split_whitespace().collect::<Vec<_>>().join(" ");
    let programs = |failures: &[(String, String)]| {
        let mut names: Vec<&String> = failures.iter().map(|(p, _)| p).collect();
        names.sort();
        names.dedup();
        names.len()
    };
    let answers = flat(&std::fs::read_to_string(root().join("chapters/answers.md")).unwrap());
    for answer in ["chapter-03-far-root", "chapter-08-ambient-in-shadow"] {
        let failures = failures_of(answer);
        let said = format!(
            "The tests that fail ({}, in {} test programs)",
            failures.len(),
            in_words(programs(&failures))
        );
        assert!(
            answers.contains(&said),
            "answers.md should say \"{said}\" ({answer})"
        );
    }
    let failures = failures_of("occlusion-stage");
    let twelve = flat(&chapter("12"));
    let said = format!(
        "{} tests failed, in {} test programs",
        failures.len(),
        programs(&failures)
    );
    assert!(twelve.contains(&said), "chapter 12 should say \"{said}\"");
    // The table of the tests that fail: | `FILE` | `fn TEST`, `fn TEST` | why |.
    // A unit test of a file under src/ runs in the crate's own test program,
    // named by its module path.
    let text = chapter("12");
    let table = text
        .split_once("| file | test | why |")
        .expect("chapter 12's table of failing tests")
        .1;
    let mut named = Vec::new();
    for row in table.lines().skip(2).take_while(|l| l.starts_with('|')) {
        let cells: Vec<&str> = row.split(" | ").collect();
        let file = cells[0].trim_start_matches("| ").trim_matches('`');
        for test in cells[1].split(", ").filter_map(|t| t.strip_prefix("`fn ")) {
            let test = test.trim_end_matches('`');
            let program = if file.starts_with("src/") {
                "src/lib.rs"
            } else {
                file
            };
            named.push((program.to_string(), test.to_string()));
        }
    }
    let mut measured: Vec<(String, String)> = failures
        .iter()
        .map(|(program, test)| {
            let name = test.rsplit("::").next().unwrap();
            (program.clone(), name.to_string())
        })
        .collect();
    named.sort();
    measured.sort();
    assert_eq!(
        named, measured,
        "chapter 12's table against occlusion-stage.failures"
    );
    // Every patch has its list.
    for entry in std::fs::read_dir(root().join("chapters/answers")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "patch") {
            let stem = path.file_stem().unwrap().to_str().unwrap();
            assert!(!failures_of(stem).is_empty(), "{stem}");
        }
    }
}

#[test]
fn no_table_row_shows_more_than_two_pictures() {
    // At the book's width of about 750 px, three pictures in a row shrink below
    // the 300 × 200 they are rendered at, and the differences the text points at
    // can no longer be seen.
    for (name, text) in chapters() {
        for line in text.lines().filter(|l| l.starts_with('|')) {
            let pictures = line.matches("](img/").count();
            assert!(
                pictures <= 2,
                "{name}: {pictures} pictures in one row: {line}"
            );
        }
    }
}

/// FNV-1a, 64 bits, as tests/serve.rs records each screenshot's bytes.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Chapter 13's screenshots come from Chromium, so they cannot be made again
/// byte for byte: each one shown must be one the browser test wrote with its
/// record (`shots.json`: size and fingerprint of each file), made by the command
/// the chapter shows.
#[test]
fn the_studio_screenshots_are_those_the_browser_test_recorded() {
    let folder = root().join("chapters/studio");
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(folder.join("shots.json")).unwrap()).unwrap();
    let command = record["made_by"].as_str().unwrap();
    assert!(command.contains("cargo test --test serve studio_page"));
    let text = chapter("13");
    assert!(text.contains(command), "chapter 13 shows `{command}`");
    let shots = record["shots"].as_array().unwrap();
    // Kept out of img/, whose every file `raystep figures` makes.
    let shown: Vec<String> = text
        .match_indices("](studio/")
        .map(|(i, _)| {
            let start = i + 2;
            text[start..start + text[start..].find(')').unwrap()].to_string()
        })
        .collect();
    assert!(shown.len() >= 4, "{shown:?}");
    for image in &shown {
        let file = image.trim_start_matches("studio/");
        let entry = shots
            .iter()
            .find(|s| s["file"] == file)
            .unwrap_or_else(|| panic!("{image} is not one the browser test recorded"));
        let bytes = std::fs::read(folder.join(file)).unwrap();
        assert_eq!(entry["bytes"], bytes.len(), "{file}: run `{command}`");
        assert_eq!(
            entry["fnv1a64"],
            format!("{:016x}", fnv1a(&bytes)),
            "{file} is not the file the test wrote: run `{command}`"
        );
        let size = image::image_dimensions(folder.join(file)).unwrap();
        assert_eq!(
            (entry["width"].clone(), entry["height"].clone()),
            (size.0.into(), size.1.into())
        );
    }
}

/// Every image under `dir`, as paths relative to it.
fn images_under(dir: &Path) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut folders = vec![dir.to_path_buf()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap().flatten() {
            let path = entry.path();
            if path.is_dir() {
                folders.push(path);
            } else if path.extension().is_some_and(|e| e == "png" || e == "svg") {
                let relative = path.strip_prefix(dir).unwrap();
                found.insert(relative.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    found
}

/// `raystep figures` writes the files the book links, by the names committed in
/// chapters/img/ (whatever the renderer, here one of thumbnails), and `--check`
/// finds nothing to say of what it wrote, but reports a figure whose bytes
/// differ at the same length, a missing one, and an image nothing makes.
#[test]
fn figures_writes_the_committed_names_and_check_reports_each_kind_of_problem() {
    use raystep::tools::figures::write_all;
    let small =
        |args: &str, root: &Path| render_command(&format!("{args} --width 8 --height 6"), root);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("img");
    let written = write_all(&root(), &out, &small).unwrap();
    assert_eq!(written.len(), images_under(&out).len(), "each file once");
    // Every image in chapters/img/ is one `raystep figures` makes: the same
    // names, no more, no fewer.
    assert_eq!(
        images_under(&out),
        images_under(&root().join("chapters/img"))
    );
    assert_eq!(
        check_all(&root(), &out, &small).unwrap(),
        Vec::<String>::new()
    );

    // One byte changed, the length kept: the last byte of a PNG (its IEND CRC).
    let changed = out.join("ch04/acne-shadow.png");
    let mut bytes = std::fs::read(&changed).unwrap();
    *bytes.last_mut().unwrap() ^= 1;
    std::fs::write(&changed, bytes).unwrap();
    std::fs::remove_file(out.join("ch01/seed-beauty.png")).unwrap();
    std::fs::write(out.join("ch01/stray.png"), b"not a figure").unwrap();
    let problems = check_all(&root(), &out, &small).unwrap();
    assert_eq!(problems.len(), 3, "{problems:#?}");
    assert!(
        problems[0].starts_with("ch01/seed-beauty.png: missing")
            && problems[1].starts_with("ch04/acne-shadow.png: differs")
            && problems[2].contains("stray.png: no figure or diagram makes this image"),
        "{problems:#?}"
    );
}

/// A figure is encoded as its command's `--png` says: sRGB for the one command
/// that asks for it, linear for every other; and the files `raystep figures`
/// writes are so (an `sRGB` chunk in each colour picture of that figure, in no
/// other file).
#[test]
fn each_figure_is_encoded_as_its_command_says() {
    use raystep::io::output::PngEncoding;
    use raystep::tools::figures::write_all;
    for figure in FIGURES {
        let expected = if figure.args.contains("--png srgb") {
            PngEncoding::Srgb
        } else {
            PngEncoding::Linear
        };
        assert_eq!(figure.png(), expected, "{}", figure.name);
    }
    assert!(FIGURES.iter().any(|f| f.png() == PngEncoding::Srgb));
    let small =
        |args: &str, root: &Path| render_command(&format!("{args} --width 8 --height 6"), root);
    let dir = tempfile::tempdir().unwrap();
    write_all(&root(), dir.path(), &small).unwrap();
    let mut srgb = 0;
    for figure in FIGURES {
        for &buffer in figure.buffers {
            let file = format!("{}-{}.png", figure.name, buffer.name());
            let bytes = std::fs::read(dir.path().join(&file)).unwrap();
            let tagged = common::png_chunks(&bytes).iter().any(|c| c == "sRGB");
            let asked = figure.args.contains("--png srgb") && PngEncoding::applies_to(buffer);
            assert_eq!(tagged, asked, "{file}");
            srgb += usize::from(tagged);
        }
    }
    assert!(srgb > 0, "no figure file is sRGB");
}
