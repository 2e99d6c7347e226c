//! Fuzzing the scene loader and the renderer: whatever text arrives, raystep
//! either refuses it with a message or renders sound pixels; it never panics.
//!
//! Two properties, run by proptest:
//!
//! - `a_mutated_scene_file_is_refused_with_a_message_or_renders_sound_pixels`
//!   starts from every valid scene file of the repository (the built-in scene,
//!   `scenes/*.toml` and `scenes/stress/*.toml`) and damages it with one to four
//!   random mutations: a character deleted, inserted or replaced (control and
//!   non-ASCII characters too); a line deleted, duplicated or swapped with
//!   another; a number replaced by a hostile one (`nan`, `inf`, `5e-324`, `1e16`,
//!   `"x"`, `[1,2]`, …) or multiplied by a power of ten; a key misspelt; a
//!   `[[sphere]]` or `[[plane]]` block copied (up to 66 times, past the BVH's
//!   threshold of 24 spheres and the tile masks' and packets' 64 objects); a table header
//!   dropped. It is parsed at a small size, or at the file's own.
//! - `random_scenes_at_extreme_scales_render_sound_pixels` writes valid scenes as
//!   TOML text at a scale of 10^k, k from −6 to 12: a camera, a light, one to
//!   eight spheres, sometimes a screen, a fake or a true plane, random materials.
//!   The loader may refuse some of them (a camera or a light inside a sphere),
//!   but at least half must be accepted, or the property would test nothing.
//!
//! The loader must not panic, and when it refuses a file its message must say
//! something and name the file. A scene it accepts is rendered under raystep's
//! defaults, the `rays` stage alone, the tutorial's settings, float32, 4 samples
//! per pixel (with each engine), and one random combination of stages, precision,
//! methods, offset, viewer, acceleration, samples, engine and AVX build; in
//! float32, a scene `check_precision` refuses there (as `raystep render
//! --precision f32` does; the refusal must say something) must render without a
//! panic and alike in every engine, its pixels' soundness unchecked. Every
//! pixel must be sound: its colour a finite number in [0, 1], its normal and
//! Blinn-Phong factors finite, and either a hit (depth finite and ≥ 0, shadow 0
//! or 1) or a miss (depth +∞, shadow −1). With acceleration on or the fast
//! engine, every record must equal the book engine's plain loop (`--accel off
//! --engine book`).
//! `the_faults_fuzzing_found_stay_fixed` keeps the six faults these properties
//! found as cases of their own.
//!
//! Bounds: images of at most 20 × 12 pixels (a file's own size is capped at
//! 32 × 32); 500 mutated files and 200 random scenes, under a second in a debug
//! build. `RAYSTEP_FUZZ_CASES=N` runs N cases of each property instead, e.g.
//! `RAYSTEP_FUZZ_CASES=5000 cargo test --release --test fuzz`, and
//! `PROPTEST_RNG_SEED=S` repeats a run. Each test prints how many cases passed
//! and how many scenes were rendered or refused (`-- --nocapture`). A failure is
//! shrunk and reported with the scene's TOML text, the size and the settings.

mod common;

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::LazyLock;

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use raystep::accel::Accel;
use raystep::aov::{PixelRecord, NO_OBJECT};
use raystep::engine::render;
use raystep::io::scene_file::{check_precision, parse_sized, Overrides, MAX_MAGNITUDE, SEED_TOML};
use raystep::real::Precision;
use raystep::render::Settings;
use raystep::scene::Scene;
use raystep::shade::blinn_phong::Viewer;
use raystep::shade::shadow::Offset;
use raystep::sphere::Method;
use raystep::stages::{Engine, Stage, Stages};

/// The name every fuzzed scene is parsed under: errors must name it.
const FILE: &str = "fuzz.toml";

/// Cases of each property: `RAYSTEP_FUZZ_CASES`, or `default`.
fn cases(default: u32) -> u32 {
    std::env::var("RAYSTEP_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A runner of `cases` cases. Failures are reported with their TOML text rather
/// than saved to a regressions file, after at most two minutes of shrinking (a
/// change that breaks a property on many scenes could otherwise shrink for more
/// than ten, rendering each smaller scene, before the test reports it).
fn runner(cases: u32) -> TestRunner {
    TestRunner::new(Config {
        cases,
        failure_persistence: None,
        max_shrink_time: 120_000,
        ..Config::default()
    })
}

/// What a property's cases came to before the first failure, if any: the scenes
/// the loader accepted (and that rendered soundly) and those it refused. The
/// cases that shrink a failure are not counted.
#[derive(Default)]
struct Tally {
    accepted: Cell<u32>,
    refused: Cell<u32>,
    failed: Cell<bool>,
}

impl Tally {
    /// Count the outcome of one case, [`load_and_render`]'s, and pass it on.
    fn count(&self, outcome: Result<bool, TestCaseError>) -> Result<(), TestCaseError> {
        if !self.failed.get() {
            match &outcome {
                Ok(true) => self.accepted.set(self.accepted.get() + 1),
                Ok(false) => self.refused.set(self.refused.get() + 1),
                Err(_) => self.failed.set(true),
            }
        }
        outcome.map(|_| ())
    }

    /// E.g. `mutated files: 200 cases passed (31 rendered, 169 refused)`.
    fn summary(&self, what: &str) -> String {
        let (accepted, refused) = (self.accepted.get(), self.refused.get());
        let then = if self.failed.get() {
            ", then one failed"
        } else {
            ""
        };
        format!(
            "{what}: {} cases passed ({accepted} rendered, {refused} refused){then}",
            accepted + refused
        )
    }
}

// ---------------------------------------------------------------------------
// What every render must give
// ---------------------------------------------------------------------------

/// The settings every accepted scene is rendered under, named for the report,
/// followed by `random`.
fn settings_to_try(random: Settings) -> [(&'static str, Settings); 7] {
    let defaults = Settings::from(Stages::ALL);
    [
        ("defaults", defaults),
        ("stage rays", Settings::from(Stages::up_to(Stage::Rays))),
        ("tutorial", Settings::tutorial(Stages::ALL)),
        (
            "float32",
            Settings {
                precision: Precision::F32,
                ..defaults
            },
        ),
        ("spp 4", Settings { spp: 4, ..defaults }),
        (
            "fast engine, spp 4",
            Settings {
                spp: 4,
                engine: Engine::Fast,
                ..defaults
            },
        ),
        ("random", random),
    ]
}

/// Any valid combination of stages, precision, methods and sample count.
fn any_settings() -> impl Strategy<Value = Settings> {
    (
        prop::sample::select(Stage::ALL.to_vec()),
        prop::collection::vec(prop::sample::select(Stage::ALL.to_vec()), 0..=2),
        any::<bool>(),
        prop::sample::select(vec![Method::Naive, Method::Stable]),
        prop::sample::select(vec![Offset::Auto, Offset::TUTORIAL, Offset::Fixed(0.0)]),
        prop::sample::select(vec![Viewer::Camera, Viewer::RayOrigin]),
        prop::sample::select(vec![Accel::Off, Accel::Auto, Accel::Bvh]),
        prop::sample::select(vec![1u32, 4, 9]),
        any::<bool>(),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(
            |(last, without, f32, method, offset, viewer, accel, spp, early_stop, fast, avx)| {
                // `--stage last --without ...`, or all up to `last` if that set is refused.
                let stages = Stages::select(last, &without).unwrap_or(Stages::up_to(last));
                Settings {
                    precision: if f32 { Precision::F32 } else { Precision::F64 },
                    method,
                    offset,
                    viewer,
                    accel,
                    spp,
                    early_stop,
                    engine: if fast { Engine::Fast } else { Engine::Book },
                    avx,
                    ..Settings::from(stages)
                }
            },
        )
}

/// What is wrong with a pixel, if anything.
fn unsound(p: &PixelRecord) -> Option<&'static str> {
    // `contains` is false for a NaN.
    if !p.colour.iter().all(|c| (0.0..=1.0).contains(c)) {
        return Some("colour not a finite number in [0, 1]");
    }
    if !p.normal.iter().all(|n| n.is_finite()) {
        return Some("normal not finite");
    }
    if !p.diffuse.is_finite() || !p.specular.is_finite() {
        return Some("Blinn-Phong factor (diffuse or specular) not finite");
    }
    if p.object == NO_OBJECT {
        if p.depth != f32::INFINITY {
            return Some("a miss whose depth is not +inf");
        }
        if p.shadow != -1.0 {
            return Some("a miss whose shadow is not -1");
        }
    } else {
        if !(p.depth.is_finite() && p.depth >= 0.0) {
            return Some("a hit whose depth is not finite and >= 0");
        }
        if p.shadow != 0.0 && p.shadow != 1.0 {
            return Some("a hit whose shadow is neither 0 nor 1");
        }
    }
    None
}

/// Render `scene` under each of `settings` and check every pixel. The error names
/// the settings, the first bad pixel and its record. A scene float32 cannot
/// resolve is refused in float32, as `raystep render --precision f32` refuses it,
/// with a message; the library still renders it, without a panic and with the
/// same records from every engine, but its pixels are not promised to be sound,
/// unless `strict` (the seeds, which render soundly in float32 all the same).
fn renders_soundly(
    scene: &Scene,
    settings: &[(&str, Settings)],
    strict: bool,
) -> Result<(), String> {
    for (name, s) in settings {
        let refused = check_precision(scene, s.precision).err();
        if refused.as_ref().is_some_and(|m| m.trim().is_empty()) {
            return Err(format!(
                "{name}: refused in {} without a message",
                s.precision
            ));
        }
        let frame = no_panic(&format!("render ({name}: {s:?})"), || {
            render(scene, s, &|_| {})
        })?;
        let width = scene.width as usize;
        if frame.pixels.len() != width * scene.height as usize {
            return Err(format!("{name}: {} pixels", frame.pixels.len()));
        }
        let promised = strict || refused.is_none();
        for (i, p) in frame.pixels.iter().enumerate().filter(|_| promised) {
            if let Some(why) = unsound(p) {
                let (row, col) = (i / width, i % width);
                return Err(format!(
                    "{name} ({s:?}): pixel (row {row}, col {col}) of {width} × {}: {why}: {p:?}",
                    scene.height
                ));
            }
        }
        // Acceleration skips only tests that cannot succeed, and the fast engine
        // computes the same numbers four at a time: the book's engine with its plain
        // loop over every object must give the very same records.
        if s.accel != Accel::Off || s.engine == Engine::Fast {
            let plain = render(
                scene,
                &Settings {
                    accel: Accel::Off,
                    engine: Engine::Book,
                    ..*s
                },
                &|_| {},
            );
            let same = |i: usize| {
                common::record_bits(&frame.pixels[i]) == common::record_bits(&plain.pixels[i])
            };
            if let Some(i) = (0..frame.pixels.len()).find(|&i| !same(i)) {
                return Err(format!(
                    "{name} ({s:?}): pixel (row {}, col {}) differs with --accel off --engine book: {:?} against {:?}",
                    i / width,
                    i % width,
                    frame.pixels[i],
                    plain.pixels[i]
                ));
            }
        }
    }
    Ok(())
}

/// Run `f`, turning a panic into an error that names `what`.
fn no_panic<R>(what: &str, f: impl FnOnce() -> R) -> Result<R, String> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|payload| {
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("(no message)");
        format!("{what} panicked: {message}")
    })
}

/// Load `text` as [`FILE`] at `size` and, if it is accepted, render it under
/// `settings`. Returns whether it was accepted; a failure carries the whole story.
fn load_and_render(
    text: &str,
    size: Overrides,
    settings: &[(&str, Settings)],
) -> Result<bool, TestCaseError> {
    let fail = |what: String| {
        TestCaseError::fail(format!(
            "{what}\n--- {FILE}, size {size:?} ---\n{text}\n--- end of {FILE} ---"
        ))
    };
    match no_panic("parse_sized", || parse_sized(text, FILE, size)).map_err(fail)? {
        Err(e) => {
            let message = e.to_string();
            if message.trim().is_empty() || !message.contains(FILE) {
                return Err(fail(format!(
                    "refused with a message that is empty or does not name {FILE}: {message:?}"
                )));
            }
            Ok(false)
        }
        Ok(mut scene) => {
            // A file's own size may be up to 8K: keep the render small.
            scene.width = scene.width.min(32);
            scene.height = scene.height.min(32);
            renders_soundly(&scene, settings, false).map_err(fail)?;
            Ok(true)
        }
    }
}

// ---------------------------------------------------------------------------
// Property 1: mutated scene files
// ---------------------------------------------------------------------------

/// Every valid scene file of the repository, as (name, text): the built-in scene,
/// then `scenes/*.toml` and `scenes/stress/*.toml`, sorted by path.
static SEEDS: LazyLock<Vec<(String, String)>> = LazyLock::new(|| {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut paths = Vec::new();
    for folder in ["scenes", "scenes/stress"] {
        for entry in std::fs::read_dir(root.join(folder)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                paths.push(path);
            }
        }
    }
    paths.sort();
    let mut seeds = vec![("built-in seed".to_string(), SEED_TOML.to_string())];
    for path in paths {
        let name = path.strip_prefix(root).unwrap().display().to_string();
        seeds.push((name, std::fs::read_to_string(&path).unwrap()));
    }
    seeds
});

/// Numbers a mutation puts in place of one in the file: non-finite, signed zeros,
/// subnormals, values around [`MAX_MAGNITUDE`], integers too large for `u32` or
/// for TOML, and values of the wrong type.
const HOSTILE: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "0",
    "-0.0",
    "1e-300",
    "5e-324",
    "1e-45",
    "1e-9",
    "1e14",
    "9.9e14",
    "1e15",
    "1.0000000000000002e15",
    "1e16",
    "1e300",
    "-1",
    "4294967296",
    "99999999999999999999",
    "\"x\"",
    "[]",
    "[1,2]",
    "true",
];

/// A misspelling of a key.
#[derive(Clone, Copy, Debug)]
enum Typo {
    DropLetter,
    DoubleLetter,
    SwapLetters,
    Capitalise,
    Plural,
}

/// One change to a scene file. An [`Index`] picks among what the file has (its
/// characters, lines, numbers, keys or table headers) when the change is made.
#[derive(Clone, Debug)]
enum Mutation {
    DeleteChar(Index),
    InsertChar(Index, char),
    ReplaceChar(Index, char),
    DeleteLine(Index),
    DuplicateLine(Index),
    SwapLines(Index, Index),
    ReplaceNumber(Index, &'static str),
    /// Multiply a number by 10^k, and by −1 if asked: a scene at another scale,
    /// or turned inside out, that the loader may well accept.
    RescaleNumber(Index, i32, bool),
    MisspellKey(Index, Typo, Index),
    /// Copy an array-of-tables block (`[[sphere]]`, `[[plane]]`) this many times.
    CopyBlock(Index, usize),
    DropHeader(Index),
}

/// A character to insert: any of U+0000 to U+00FF (control characters, ASCII,
/// Latin-1), a few troublemakers (byte-order mark, line separator, right-to-left
/// override, replacement character, a crab), or any character at all.
fn odd_char() -> impl Strategy<Value = char> {
    prop_oneof![
        any::<u8>().prop_map(char::from),
        prop::sample::select(vec!['\u{feff}', '\u{2028}', '\u{202e}', '\u{fffd}', '🦀']),
        any::<char>(),
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let typo = prop::sample::select(vec![
        Typo::DropLetter,
        Typo::DoubleLetter,
        Typo::SwapLetters,
        Typo::Capitalise,
        Typo::Plural,
    ]);
    let copies = prop_oneof![4 => 1..=3usize, 1 => 10..=13usize, 1 => 62..=66usize];
    prop_oneof![
        1 => any::<Index>().prop_map(Mutation::DeleteChar),
        1 => (any::<Index>(), odd_char()).prop_map(|(i, c)| Mutation::InsertChar(i, c)),
        1 => (any::<Index>(), odd_char()).prop_map(|(i, c)| Mutation::ReplaceChar(i, c)),
        1 => any::<Index>().prop_map(Mutation::DeleteLine),
        1 => any::<Index>().prop_map(Mutation::DuplicateLine),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        4 => (any::<Index>(), prop::sample::select(HOSTILE))
            .prop_map(|(i, n)| Mutation::ReplaceNumber(i, n)),
        4 => (any::<Index>(), -20..=20i32, prop::bool::weighted(0.2))
            .prop_map(|(i, k, negate)| Mutation::RescaleNumber(i, k, negate)),
        2 => (any::<Index>(), typo, any::<Index>())
            .prop_map(|(i, t, at)| Mutation::MisspellKey(i, t, at)),
        2 => (any::<Index>(), copies).prop_map(|(i, n)| Mutation::CopyBlock(i, n)),
        1 => any::<Index>().prop_map(Mutation::DropHeader),
    ]
}

/// The byte ranges of the tokens of `text` that `is_token` accepts, outside
/// comments. `is_token(line, start, end)` is asked of every maximal run of
/// characters that can make a number or a key (`[A-Za-z0-9_.+-]`).
fn tokens(text: &str, is_token: impl Fn(&str, usize, usize) -> bool) -> Vec<(usize, usize)> {
    let word = |b: u8| b.is_ascii_alphanumeric() || b"_.+-".contains(&b);
    let mut found = Vec::new();
    let mut line_start = 0;
    for line in text.split_inclusive('\n') {
        let code = &line[..line.find('#').unwrap_or(line.len())];
        let bytes = code.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            if !word(bytes[i]) {
                i += 1;
                continue;
            }
            let start = i;
            while i < bytes.len() && word(bytes[i]) {
                i += 1;
            }
            if is_token(code, start, i) {
                found.push((line_start + start, line_start + i));
            }
        }
        line_start += line.len();
    }
    found
}

/// The numbers of `text`: runs that start with a digit, or a sign or point and a digit.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    tokens(text, |line, start, end| {
        let token = line[start..end].trim_start_matches(['+', '-', '.']);
        token.starts_with(|c: char| c.is_ascii_digit())
    })
}

/// The keys of `text`: names followed by `=`, and table names followed by `]`.
fn keys(text: &str) -> Vec<(usize, usize)> {
    tokens(text, |line, start, end| {
        let name = &line[start..end];
        let next = line[end..].trim_start();
        name.starts_with(|c: char| c.is_ascii_alphabetic())
            && (next.starts_with('=') && !next.starts_with("==") || next.starts_with(']'))
    })
}

/// `key` misspelt by `typo`, at the letter `at` picks.
fn misspell(key: &str, typo: Typo, at: &Index) -> String {
    let mut letters: Vec<char> = key.chars().collect();
    let i = at.index(letters.len());
    match typo {
        Typo::DropLetter => {
            letters.remove(i);
        }
        Typo::DoubleLetter => letters.insert(i, letters[i]),
        Typo::SwapLetters if letters.len() > 1 => {
            let first = i.min(letters.len() - 2);
            letters.swap(first, first + 1);
        }
        Typo::SwapLetters => letters.push('x'),
        Typo::Capitalise => letters[0] = letters[0].to_ascii_uppercase(),
        Typo::Plural => letters.push('s'),
    }
    letters.into_iter().collect()
}

/// The item `i` picks from `items`, if there is any.
fn pick<T: Copy>(items: &[T], i: &Index) -> Option<T> {
    (!items.is_empty()).then(|| items[i.index(items.len())])
}

/// `text` with the character `i` picks replaced by `new` (empty to delete it).
fn replace_char(text: &str, i: &Index, new: &str) -> String {
    let chars: Vec<(usize, char)> = text.char_indices().collect();
    let Some((at, c)) = pick(&chars, i) else {
        return text.to_string();
    };
    let mut text = text.to_string();
    text.replace_range(at..at + c.len_utf8(), new);
    text
}

/// `text` with `c` inserted at the character boundary `i` picks (the end too).
fn insert_char(text: &str, i: &Index, c: char) -> String {
    let mut boundaries: Vec<usize> = text.char_indices().map(|(at, _)| at).collect();
    boundaries.push(text.len());
    let mut text = text.to_string();
    text.insert(boundaries[i.index(boundaries.len())], c);
    text
}

/// `text` with the token `i` picks among `tokens` replaced by what `change` makes
/// of it; unchanged if there is no token or `change` gives `None`.
fn replace_token(
    text: &str,
    tokens: &[(usize, usize)],
    i: &Index,
    change: impl FnOnce(&str) -> Option<String>,
) -> String {
    let mut text = text.to_string();
    if let Some((start, end)) = pick(tokens, i) {
        if let Some(new) = change(&text[start..end]) {
            text.replace_range(start..end, &new);
        }
    }
    text
}

/// `text` with its lines edited by `edit`. Each line keeps its newline (the last
/// one gains it if missing), so lines can be moved and copied.
fn edit_lines(text: &str, edit: impl FnOnce(&mut Vec<String>)) -> String {
    let mut lines: Vec<String> = text
        .split_inclusive('\n')
        .map(|l| l.strip_suffix('\n').unwrap_or(l).to_string() + "\n")
        .collect();
    if !lines.is_empty() {
        edit(&mut lines);
    }
    lines.concat()
}

/// The numbers of the lines that are table headers: `[name]`, or only the
/// array-of-tables headers `[[name]]` if `arrays`.
fn headers(lines: &[String], arrays: bool) -> Vec<usize> {
    let opening = if arrays { "[[" } else { "[" };
    (0..lines.len())
        .filter(|&n| lines[n].trim_start().starts_with(opening))
        .collect()
}

/// `text` with `mutation` made; a mutation that finds nothing to change (no
/// number in an empty file, say) leaves it as it is.
fn mutate(text: &str, mutation: &Mutation) -> String {
    match mutation {
        Mutation::DeleteChar(i) => replace_char(text, i, ""),
        Mutation::ReplaceChar(i, c) => replace_char(text, i, &c.to_string()),
        Mutation::InsertChar(i, c) => insert_char(text, i, *c),
        Mutation::DeleteLine(i) => edit_lines(text, |lines| {
            lines.remove(i.index(lines.len()));
        }),
        Mutation::DuplicateLine(i) => edit_lines(text, |lines| {
            let at = i.index(lines.len());
            lines.insert(at, lines[at].clone());
        }),
        Mutation::SwapLines(a, b) => edit_lines(text, |lines| {
            let n = lines.len();
            lines.swap(a.index(n), b.index(n));
        }),
        Mutation::ReplaceNumber(i, hostile) => {
            replace_token(text, &numbers(text), i, |_| Some(hostile.to_string()))
        }
        Mutation::RescaleNumber(i, k, negate) => replace_token(text, &numbers(text), i, |number| {
            let x: f64 = number.parse().ok()?;
            let sign = if *negate { -1.0 } else { 1.0 };
            Some(format!("{:e}", sign * x * 10f64.powi(*k)))
        }),
        Mutation::MisspellKey(i, typo, at) => {
            replace_token(text, &keys(text), i, |key| Some(misspell(key, *typo, at)))
        }
        Mutation::CopyBlock(i, copies) => edit_lines(text, |lines| {
            let Some(start) = pick(&headers(lines, true), i) else {
                return;
            };
            let end = (start + 1..lines.len())
                .find(|&n| lines[n].trim_start().starts_with('['))
                .unwrap_or(lines.len());
            let block = lines[start..end].to_vec();
            for _ in 0..*copies {
                lines.splice(end..end, block.iter().cloned());
            }
        }),
        Mutation::DropHeader(i) => edit_lines(text, |lines| {
            if let Some(header) = pick(&headers(lines, false), i) {
                lines.remove(header);
            }
        }),
    }
}

/// A size to parse at: both sides overridden, the width only, the file's own, or
/// the file's own with `--max-depth`.
fn any_size() -> impl Strategy<Value = Overrides> {
    prop_oneof![
        6 => (1..=20u32, 1..=12u32).prop_map(|(w, h)| Overrides {
            width: Some(w),
            height: Some(h),
            max_depth: None,
        }),
        1 => (1..=20u32).prop_map(|w| Overrides {
            width: Some(w),
            height: None,
            max_depth: None,
        }),
        2 => Just(Overrides::default()),
        1 => (1..=64u32).prop_map(|d| Overrides {
            max_depth: Some(d),
            ..Overrides::default()
        }),
    ]
}

#[test]
fn a_mutated_scene_file_is_refused_with_a_message_or_renders_sound_pixels() {
    // Every seed is valid and renders soundly before it is mutated.
    let small = Overrides {
        width: Some(12),
        height: Some(8),
        max_depth: None,
    };
    for (name, text) in SEEDS.iter() {
        let scene = parse_sized(text, name, small).unwrap_or_else(|e| panic!("{e}"));
        let settings = settings_to_try(Settings::from(Stages::ALL));
        renders_soundly(&scene, &settings, true).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    let seeds = SEEDS.len();

    let strategy = (
        any::<Index>(),
        prop::collection::vec(mutation(), 1..=4),
        any_size(),
        any_settings(),
    );
    let tally = Tally::default();
    let n = cases(500);
    let result = runner(n).run(&strategy, |(seed, mutations, size, random)| {
        let (_, original) = &SEEDS[seed.index(seeds)];
        let text = mutations
            .iter()
            .fold(original.clone(), |t, m| mutate(&t, m));
        tally.count(load_and_render(&text, size, &settings_to_try(random)))
    });
    eprintln!("{}", tally.summary("mutated scene files"));
    if let Err(e) = result {
        panic!("{e}");
    }
    // About one damaged file in five still loads (104 of 500 in one run): the
    // renderer's half of the property is tested only if some do. A tenth is more
    // than five standard deviations below that at 500 cases; with fewer than 200
    // (`RAYSTEP_FUZZ_CASES`) chance alone could miss it, so it is not asked.
    if n >= 200 {
        let accepted = tally.accepted.get();
        assert!(
            accepted >= n / 10,
            "only {accepted} of {n} mutated files were accepted and rendered"
        );
    }
}

// ---------------------------------------------------------------------------
// Property 2: random valid scenes at extreme scales
// ---------------------------------------------------------------------------

/// The surface of a generated object.
#[derive(Clone, Debug)]
struct Surface {
    ambient: [f64; 3],
    diffuse: [f64; 3],
    specular: Option<[f64; 3]>,
    shininess: f64,
    reflection: f64,
}

/// A generated sphere, in units of the scene's scale.
#[derive(Clone, Debug)]
struct Ball {
    center: [f64; 3],
    radius: f64,
    surface: Surface,
}

/// A generated floor, in units of the scene's scale.
#[derive(Clone, Debug)]
enum Floor {
    None,
    /// The tutorial's fake plane: a sphere of radius `radius`, its top `gap` below
    /// the lower of the camera and the light.
    Fake {
        radius: f64,
        gap: f64,
        surface: Surface,
    },
    /// A true plane `gap` below the lower of the camera and the light; its normal
    /// is not scaled but may be of any length.
    True {
        gap: f64,
        normal: [f64; 3],
        surface: Surface,
    },
}

/// A generated scene: every position and length is in units of 10^`exponent`.
#[derive(Clone, Debug)]
struct RandomScene {
    exponent: i32,
    camera: [f64; 3],
    /// Half the width and half the height of the screen, if the scene sets one.
    screen: Option<(f64, f64)>,
    light: [f64; 3],
    light_colour: Option<[f64; 3]>,
    max_depth: Option<u32>,
    spheres: Vec<Ball>,
    floor: Floor,
}

/// A number as TOML reads it back exactly (`{:e}`: `1e-6`, `-2.5e12`).
fn toml_number(x: f64) -> String {
    assert!(x.is_finite() && x.abs() < MAX_MAGNITUDE, "{x} out of range");
    format!("{x:e}")
}

fn toml_triple(v: [f64; 3]) -> String {
    format!(
        "[{}, {}, {}]",
        toml_number(v[0]),
        toml_number(v[1]),
        toml_number(v[2])
    )
}

impl Surface {
    fn toml(&self) -> String {
        let mut keys = format!(
            "ambient = {}\ndiffuse = {}\nshininess = {}\nreflection = {}\n",
            toml_triple(self.ambient),
            toml_triple(self.diffuse),
            toml_number(self.shininess),
            toml_number(self.reflection),
        );
        if let Some(specular) = self.specular {
            keys += &format!("specular = {}\n", toml_triple(specular));
        }
        keys
    }
}

impl RandomScene {
    fn toml(&self) -> String {
        let s = 10f64.powi(self.exponent);
        let scaled = |v: [f64; 3]| v.map(|x| x * s);
        let mut text = format!(
            "# scale 1e{}\n[camera]\nposition = {}\n\n[light]\nposition = {}\n",
            self.exponent,
            toml_triple(scaled(self.camera)),
            toml_triple(scaled(self.light)),
        );
        if let Some(c) = self.light_colour {
            text += &format!(
                "ambient = {0}\ndiffuse = {0}\nspecular = {0}\n",
                toml_triple(c)
            );
        }
        if let Some((half_width, half_height)) = self.screen {
            text += &format!(
                "\n[screen]\nleft = {}\nright = {}\ntop = {}\nbottom = {}\n",
                toml_number(-half_width * s),
                toml_number(half_width * s),
                toml_number(half_height * s),
                toml_number(-half_height * s),
            );
        }
        if let Some(max_depth) = self.max_depth {
            text += &format!("\n[render]\nmax_depth = {max_depth}\n");
        }
        for ball in &self.spheres {
            text += &format!(
                "\n[[sphere]]\ncenter = {}\nradius = {}\n{}",
                toml_triple(scaled(ball.center)),
                toml_number(ball.radius * s),
                ball.surface.toml()
            );
        }
        // The floor lies below the lower of the camera and the light.
        let low = self.camera[1].min(self.light[1]);
        match &self.floor {
            Floor::None => {}
            Floor::Fake {
                radius,
                gap,
                surface,
            } => {
                // Keep the centre (radius plus the height of its top) below the
                // loader's largest magnitude.
                let radius = (radius * s).min(MAX_MAGNITUDE / 8.0);
                let center = [0.0, (low - gap) * s - radius, -3.0 * s];
                text += &format!(
                    "\n[[plane]]\nsphere = {{ center = {}, radius = {} }}\n{}",
                    toml_triple(center),
                    toml_number(radius),
                    surface.toml()
                );
            }
            Floor::True {
                gap,
                normal,
                surface,
            } => {
                text += &format!(
                    "\n[[plane]]\npoint = {}\nnormal = {}\n{}",
                    toml_triple([0.0, (low - gap) * s, 0.0]),
                    toml_triple(*normal),
                    surface.toml()
                );
            }
        }
        text
    }
}

fn colour(most: f64) -> impl Strategy<Value = [f64; 3]> {
    [0.0..=most, 0.0..=most, 0.0..=most]
}

fn surface() -> impl Strategy<Value = Surface> {
    (
        colour(1.0),
        colour(1.0),
        prop::option::of(colour(1.0)),
        prop_oneof![Just(0.0), (0.0..=4.0f64).prop_map(|e| 10f64.powf(e))],
        prop_oneof![Just(0.0), Just(1.0), 0.0..=1.0f64],
    )
        .prop_map(
            |(ambient, diffuse, specular, shininess, reflection)| Surface {
                ambient,
                diffuse,
                specular,
                shininess,
                reflection,
            },
        )
}

fn ball() -> impl Strategy<Value = Ball> {
    (
        [-3.0..=3.0f64, -2.0..=2.0, -8.0..=0.5],
        -4.0..=0.7f64,
        surface(),
    )
        .prop_map(|(center, size, surface)| Ball {
            center,
            radius: 10f64.powf(size),
            surface,
        })
}

fn floor() -> impl Strategy<Value = Floor> {
    prop_oneof![
        Just(Floor::None),
        (1.0..=4.0f64, 0.05..=2.0f64, surface()).prop_map(|(size, gap, surface)| Floor::Fake {
            radius: 10f64.powf(size),
            gap,
            surface,
        }),
        (
            0.05..=2.0f64,
            [-1.0..=1.0f64, 0.2..=1.0, -1.0..=1.0],
            -3..=3i32,
            surface()
        )
            .prop_map(|(gap, normal, length, surface)| Floor::True {
                gap,
                normal: normal.map(|n| n * 10f64.powi(length)),
                surface,
            }),
    ]
}

fn random_scene() -> impl Strategy<Value = RandomScene> {
    (
        -6..=12i32,
        [-1.0..=1.0f64, -1.0..=1.0, 0.2..=4.0],
        prop::option::weighted(0.75, (0.01..=2.0f64, 0.01..=2.0f64)),
        [-10.0..=10.0f64, -1.0..=10.0, -10.0..=10.0],
        prop::option::of(colour(2.0)),
        prop::option::of(1..=8u32),
        prop::collection::vec(ball(), 1..=8),
        floor(),
    )
        .prop_map(
            |(exponent, camera, screen, light, light_colour, max_depth, spheres, floor)| {
                RandomScene {
                    exponent,
                    camera,
                    screen,
                    light,
                    light_colour,
                    max_depth,
                    spheres,
                    floor,
                }
            },
        )
}

#[test]
fn random_scenes_at_extreme_scales_render_sound_pixels() {
    let tally = Tally::default();
    let strategy = (random_scene(), 1..=20u32, 1..=12u32, any_settings());
    let result = runner(cases(200)).run(&strategy, |(scene, width, height, random)| {
        let size = Overrides {
            width: Some(width),
            height: Some(height),
            max_depth: None,
        };
        tally.count(load_and_render(
            &scene.toml(),
            size,
            &settings_to_try(random),
        ))
    });
    eprintln!("{}", tally.summary("random scenes"));
    if let Err(e) = result {
        panic!("{e}");
    }
    // Valid scenes, refused only where a check goes beyond validity (a camera
    // inside a sphere): at least half must be rendered.
    let (accepted, refused) = (tally.accepted.get(), tally.refused.get());
    assert!(
        accepted >= refused,
        "the loader refused {refused} of {} valid scenes",
        accepted + refused
    );
}

// ---------------------------------------------------------------------------
// What fuzzing found, kept as cases of their own
// ---------------------------------------------------------------------------

/// The five faults these properties found (and that are fixed), each checked
/// directly: refused with its reason, or rendered soundly (acceleration included).
#[test]
fn the_faults_fuzzing_found_stay_fixed() {
    let scene = |rest: &str| {
        format!("[camera]\nposition = [0, 0, 1]\n[light]\nposition = [5, 5, 5]\n{rest}")
    };
    // Odd: the middle row's rays are exactly level with the plane of A.
    let size = Overrides {
        width: Some(15),
        height: Some(15),
        max_depth: None,
    };
    let offset_0 = Settings {
        offset: Offset::Fixed(0.0),
        ..Settings::from(Stages::ALL)
    };
    let all = settings_to_try(offset_0);
    // A: a plane met almost edge-on, at t ≈ 1.4e300, beyond float32: a hit, not +∞.
    let edge_on = scene("[[plane]]\npoint = [0, -1, 0]\nnormal = [1e-300, 1, 0]\n");
    assert_eq!(
        load_and_render(&edge_on, size, &all).map_err(|e| e.to_string()),
        Ok(true)
    );
    // B and C: the camera 1e-300 from the screen's plane, where rays have no
    // direction (B: NaN at the `rays` stage; C: tile masks that dropped a sphere).
    let refused = |text: &str, words: &str| {
        let message = parse_sized(text, FILE, size)
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(message.contains(words), "{words:?} not in {message}");
    };
    let near_screen = "[camera]\nposition = [0, 0, 1e-300]\n[light]\nposition = [0, 5, 0]\n\
                       [[sphere]]\ncenter = [-0.5, 0, 0]\nradius = 0.25\n";
    refused(near_screen, "puts the eye too near the screen");
    // D: the light on a true plane, where `--offset fixed:0` met the light itself.
    let light_on_plane = "[camera]\nposition = [0, 0, 1]\n[light]\nposition = [0, 0, -1]\n\
                          [[plane]]\npoint = [0, 0, -1]\nnormal = [0, 0, 1]\n";
    refused(light_on_plane, "lies on [[plane]] number 1");
    // E: a screen 1e-300 high, whose tiles' pyramids have no height: the tile
    // masks dropped a sphere that jittered samples (spp 4) meet.
    let flat_screen = "[camera]\nposition = [0, 0, 1]\n[screen]\nleft = -0.0003\nright = 0.0003\n\
                       top = 1e-300\nbottom = 0\n[light]\nposition = [2000, 2000, -3000]\n\
                       [[sphere]]\ncenter = [0, 0, -5000]\nradius = 1\n";
    let two = Overrides {
        width: Some(2),
        height: Some(2),
        max_depth: None,
    };
    assert_eq!(
        load_and_render(flat_screen, two, &all).map_err(|e| e.to_string()),
        Ok(true)
    );
    // Just off the plane, the same scene renders soundly.
    let light_off_plane =
        light_on_plane.replace("position = [0, 0, -1]", "position = [0, 0, -0.5]");
    assert_eq!(
        load_and_render(&light_off_plane, size, &all).map_err(|e| e.to_string()),
        Ok(true)
    );
    // F: a mirror of radius 0.5 at 1.5e8 (a mutated scenes/mirrors.toml): float32
    // spaces its numbers 16 apart there, the hit point lands off the sphere and its
    // normal is NaN. float32 refuses the scene, as the command line does; float64
    // renders it soundly (`load_and_render` checks float32 pixels only where accepted).
    let far_mirror = scene("[[sphere]]\ncenter = [0, 0, -1.5e8]\nradius = 0.5\nreflection = 0.9\n");
    let parsed = parse_sized(&far_mirror, FILE, size).unwrap();
    let message = check_precision(&parsed, Precision::F32).unwrap_err();
    assert!(
        message.contains("the least raystep accepts here in float32"),
        "{message}"
    );
    assert_eq!(check_precision(&parsed, Precision::F64), Ok(Vec::new()));
    assert_eq!(
        load_and_render(&far_mirror, size, &all).map_err(|e| e.to_string()),
        Ok(true)
    );
}
