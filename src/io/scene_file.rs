//! Scene files: TOML in, a checked [`Scene`] out.
//!
//! A scene names only what differs from the tutorial's defaults; unknown keys are
//! errors, so a typo is never silently ignored. Every number is checked (finite,
//! in range) and every mistake is reported with the file, the key and what would be
//! valid.

use std::collections::HashMap;
use std::path::Path;

use serde::Deserialize;

use crate::camera::Screen;
use crate::error::Error;
use crate::plane::Plane;
use crate::real::Precision;
use crate::scene::{Light, Material, Object, Role, Scene, Shape};
use crate::shade::shadow::{pass_over, sphere_height};
use crate::sphere::Sphere;
use crate::Vec3;

/// The tutorial's figure-1 scene (`scenes/seed.toml`), built into the binary.
pub const SEED_TOML: &str = include_str!("../../scenes/seed.toml");

/// The name errors and summaries use for the built-in scene.
pub const SEED_NAME: &str = "scenes/seed.toml (built in)";

/// Largest accepted image side, in pixels.
pub const MAX_SIDE: u32 = 16384;

/// Largest accepted image, in pixels: 7680 × 4320 (8K). A render peaks at about
/// [`PEAK_BYTES_PER_PIXEL`], so this one needs about 2.1 GB of memory (and writes
/// about 3.5 GB of files for a stage with every buffer, most of it the
/// uncompressed `buffers.exr`: 104 bytes per pixel).
pub const MAX_PIXELS: u64 = 7680 * 4320;

/// Peak memory of a render and its files per pixel, rounded up from measurements:
/// `/usr/bin/time -f %M raystep render --width 7680 --height 4320` peaked at
/// 1.91 GB (58 bytes per pixel), and `raystep stages` at that size at 1.94 GB.
pub const PEAK_BYTES_PER_PIXEL: u64 = 64;

pub use crate::scene::MAX_MAGNITUDE;

/// Smallest accepted radius of a sphere.
pub const MIN_RADIUS: f64 = 1e-12;

/// Smallest radius of a sphere float32 resolves, as a fraction of the largest
/// coordinate of its center and of the camera: float32 rounds a coordinate by
/// 6e-8 of it (its unit roundoff u), so this is about 17u. A scene below it is
/// refused only when float32 is asked for ([`check_precision`]).
pub const MIN_RADIUS_RATIO: f64 = 1e-6;

/// The same limit in float64: the same 17 or so unit roundoffs, of float64's
/// unit roundoff (1.1e-16 instead of 6e-8), so 1.9e-15. The loader checks
/// scenes against it; float64 renders a scene at this limit as well as float32
/// renders one at [`MIN_RADIUS_RATIO`].
pub const MIN_RADIUS_RATIO_F64: f64 = MIN_RADIUS_RATIO * (f64::EPSILON / f32::EPSILON as f64);

/// How coarsely float32 may place a sphere's points before [`check_precision`]
/// warns, as the band a shadow ray from the `auto` step would pass over the
/// sphere in: the step `h` is a bound of the points' error, and such a ray passes
/// over its sphere for `|L·N|` below about `√(2h/r)`. (`auto` asks no ray on a
/// sphere's own dark side, but its points, normals and outline are as coarse.)
pub const F32_TERMINATOR_WARNING: f64 = 1e-2;

/// Largest accepted `max_depth`.
pub const MAX_DEPTH: u32 = 64;

/// Largest scene file read, in bytes.
pub const MAX_FILE_BYTES: u64 = 16 * 1024 * 1024;

/// What the command line says in place of the file: `--width` and `--height`
/// for `[image]`, `--max-depth` for `render.max_depth`. A key overridden is not
/// checked against its range in the file (its type still is), so a file may be
/// rendered smaller, or shallower, than it asks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Overrides {
    /// `--width`.
    pub width: Option<u32>,
    /// `--height`.
    pub height: Option<u32>,
    /// `--max-depth`.
    pub max_depth: Option<u32>,
}

/// The built-in figure-1 scene.
pub fn seed() -> Scene {
    parse(SEED_TOML, SEED_NAME).expect("the built-in scene is valid")
}

/// Read and check the scene file at `path`.
pub fn load(path: &Path) -> Result<Scene, Error> {
    load_sized(path, Overrides::default())
}

/// The name of the scene read from standard input (the path `-`) in messages.
pub const STDIN_NAME: &str = "<stdin>";

/// Whether `path` is `-`, the scene read from standard input.
pub fn is_stdin(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// The name of the scene at `path` in messages: the path, or [`STDIN_NAME`] for `-`.
pub fn display_name(path: &Path) -> String {
    if is_stdin(path) {
        STDIN_NAME.to_string()
    } else {
        path.display().to_string()
    }
}

/// Read and check the scene file at `path` (`-`: standard input), at the size
/// `size` asks for.
pub fn load_sized(path: &Path, size: Overrides) -> Result<Scene, Error> {
    let file = display_name(path);
    let fail = |message: String| Error::Scene {
        file: file.clone(),
        message,
    };
    let cannot = |e: std::io::Error| fail(format!("cannot read the scene file: {e}"));
    let reader: Box<dyn std::io::Read> = if is_stdin(path) {
        use std::io::IsTerminal;
        if std::io::stdin().is_terminal() {
            crate::error::to_stderr(format_args!(
                "reading the scene from standard input (end it with Ctrl-D)"
            ));
        }
        Box::new(std::io::stdin().lock())
    } else {
        let meta = std::fs::metadata(path).map_err(|e| {
            // The name the status line gives the built-in scene, tried outside
            // the repository.
            let seed = SEED_NAME.split(' ').next().map(Path::new);
            if e.kind() == std::io::ErrorKind::NotFound && Some(path) == seed {
                fail(format!(
                    "cannot read the scene file: {e}; the built-in scene needs no file: \
                     leave the scene out (`raystep render`)"
                ))
            } else {
                cannot(e)
            }
        })?;
        if meta.is_dir() {
            return Err(fail(
                "is a folder; give the path of a .toml scene file".into(),
            ));
        }
        Box::new(std::fs::File::open(path).map_err(cannot)?)
    };
    // Read at most one byte past the limit: a device such as /dev/zero (or a
    // pipe) has no length to check beforehand.
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(
        &mut std::io::Read::take(reader, MAX_FILE_BYTES + 1),
        &mut bytes,
    )
    .map_err(cannot)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(fail(format!(
            "is larger than {MAX_FILE_BYTES} bytes, the most a scene file may be"
        )));
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = valid.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = valid.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let column = String::from_utf8_lossy(&valid[line_start..])
            .chars()
            .count()
            + 1;
        fail(format!(
            "is not a text file (not UTF-8): line {line}, column {column} holds the byte \
             {:#04x}, which UTF-8 does not allow there; a scene file is TOML text: save it \
             as UTF-8",
            e.as_bytes()[valid.len()]
        ))
    })?;
    parse_sized(&text, &file, size)
}

/// Check the TOML text of a scene; `file` names it in error messages.
pub fn parse(text: &str, file: &str) -> Result<Scene, Error> {
    parse_sized(text, file, Overrides::default())
}

/// Check the TOML text of a scene at the size `size` asks for (the size decides the
/// default screen, so it is settled before anything is checked).
pub fn parse_sized(text: &str, file: &str, size: Overrides) -> Result<Scene, Error> {
    parse_text(text, file, size, true)
}

/// [`parse_sized`] for a text made from the file, not the file's own (the studio's
/// moved light or camera): a value out of range is named by table and key alone,
/// since a line and column of that text would point at nothing in the file.
pub fn parse_edited(text: &str, file: &str, size: Overrides) -> Result<Scene, Error> {
    parse_text(text, file, size, false)
}

/// [`parse_sized`], and whether a value out of range gets its place ([`located`]).
fn parse_text(text: &str, file: &str, size: Overrides, locate: bool) -> Result<Scene, Error> {
    let fail = |message: String| Error::Scene {
        file: file.to_string(),
        message,
    };
    // Editors on Windows may start a UTF-8 file with a byte-order mark.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if text
        .lines()
        .all(|l| l.trim().is_empty() || l.trim_start().starts_with('#'))
    {
        return Err(fail(format!(
            "is empty{}; a scene needs at least a camera and a light:\n{SMALLEST_SCENE}",
            if text.trim().is_empty() {
                ""
            } else {
                " (only comments)"
            }
        )));
    }
    let apart = if text.len() >= APART_FROM {
        read_apart(text, APART_PART)
    } else {
        None
    };
    let raw = match apart {
        Some(raw) => raw,
        None => toml::from_str::<SceneFile>(text).map_err(|e| fail(toml_error(&e, text)))?,
    };
    let overridden = size != Overrides::default();
    raw.check(size).map_err(|message| match () {
        _ if overridden && message.starts_with("--") => Error::Usage(message),
        _ if locate => fail(located(text, message)),
        _ => fail(message),
    })
}

/// A message of [`SceneFile::check`] with the line and column of the value it
/// names first ("`[[sphere]] number 2, radius: …`", "`light.ambient: …`",
/// "`screen: …`"), as a syntax error has them. Files of [`APART_FROM`] bytes or
/// more are not read again for it (their message names the table and key alone),
/// nor is a message that names no value of the file (a sphere of `[generate]`).
fn located(text: &str, message: String) -> String {
    use toml::de::DeValue;
    if text.len() >= APART_FROM {
        return message;
    }
    let Some(path) = named_value(&message) else {
        return message;
    };
    let Ok(document) = toml::de::DeTable::parse(text) else {
        return message;
    };
    fn key_of<'t, 'i>(
        table: &'t toml::de::DeTable<'i>,
        key: &str,
    ) -> Option<&'t toml::Spanned<DeValue<'i>>> {
        (table.iter().find(|(k, _)| k.get_ref() == key)).map(|(_, v)| v)
    }
    // The value reached so far (`None`: the document's top), and its place.
    let (mut here, mut span) = (None::<&DeValue>, None);
    for step in &path {
        let found = match (step, here) {
            (Step::Key(key), None) => key_of(document.get_ref(), key),
            (Step::Key(key), Some(DeValue::Table(t))) => key_of(t, key),
            (Step::Entry(n), Some(DeValue::Array(a))) => a.get(*n),
            _ => None,
        };
        let Some(found) = found else {
            break;
        };
        (here, span) = (Some(found.get_ref()), Some(found.span()));
    }
    match span {
        Some(span) => pointed(text, span, &message),
        // Not even the first step is in the file (a key made by a default).
        None => message,
    }
}

/// A step down a scene file's tables: a key, or the `n`-th entry (from 0) of an
/// array of tables.
enum Step {
    Key(String),
    Entry(usize),
}

/// The value a message of the loader names first, as steps from the file's top:
/// `[[sphere]] number 2, radius` is `sphere`, entry 1, `radius`;
/// `[[plane]] number 1, sphere, radius` goes one key deeper; `light.ambient` is
/// two keys; `screen:` one.
fn named_value(message: &str) -> Option<Vec<Step>> {
    let word = |s: &str| -> usize {
        s.find(|c: char| !(c.is_ascii_lowercase() || c == '_'))
            .unwrap_or(s.len())
    };
    for table in ["sphere", "plane"] {
        let Some(rest) = message.strip_prefix(&format!("[[{table}]] number ")) else {
            continue;
        };
        let digits = rest
            .find(|c: char| !c.is_ascii_digit())
            .unwrap_or(rest.len());
        let number: usize = rest[..digits].parse().ok()?;
        let mut path = vec![Step::Key(table.into()), Step::Entry(number.checked_sub(1)?)];
        let mut rest = &rest[digits..];
        // A fake plane's own checks call it "[[plane]] number N (a sphere)": the
        // numbers are in its `sphere = {…}`.
        if let Some(after) = rest.strip_prefix(" (a sphere)") {
            path.push(Step::Key("sphere".into()));
            rest = after;
        }
        while let Some(next) = rest.strip_prefix(", ") {
            let n = word(next);
            if n == 0 {
                break;
            }
            path.push(Step::Key(next[..n].into()));
            rest = &next[n..];
        }
        return Some(path);
    }
    let n = word(message);
    let table = &message[..n];
    match message[n..].strip_prefix('.') {
        Some(rest) if n > 0 && word(rest) > 0 => Some(vec![
            Step::Key(table.into()),
            Step::Key(rest[..word(rest)].into()),
        ]),
        None if n > 0 && message[n..].starts_with(':') => Some(vec![Step::Key(table.into())]),
        _ => None,
    }
}

/// Files from this many bytes on are read in parts ([`read_apart`]) where they
/// can be. (`raystep generate spheres --count 100000` writes 16.7 MB.)
const APART_FROM: usize = 1 << 20;

/// The `[[sphere]]` tables in one part of [`read_apart`].
const APART_PART: usize = 1000;

/// A file of many `[[sphere]]` tables, read in parts on every thread: the text
/// before the first line `[[sphere]]` as a whole scene file, then the rest cut
/// before every `part`-th such line, each part a TOML document of nothing but
/// `[[sphere]]` tables, their spheres appended in order. `None` (the file is
/// then read whole, which also gives any error its message and line) when a part
/// is not such a document, the head has a key `sphere` (even `sphere = []`, an
/// array that no `[[sphere]]` may extend), or the text has a multi-line
/// string, the one TOML value that could hold a line `[[sphere]]`.
///
/// The parts give what the whole gives: a table, array or inline table that ran
/// across a cut would leave the part before it unfinished, an error; a key of
/// the scene after the spheres is refused by a part, which knows only
/// `sphere`. What it saves: `toml` holds the tokens and events of all it reads
/// (531 MB for the 16.7 MB of 100,000 listed spheres, 0.8 s: `raystep check` of
/// such a file before commit 2edaad8, whose message has the figures).
fn read_apart(text: &str, part: usize) -> Option<SceneFile> {
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Spheres {
        sphere: Vec<SphereKeys>,
    }
    if text.contains("\"\"\"") || text.contains("'''") {
        return None;
    }
    let mut cuts = Vec::new();
    let (mut at, mut seen) = (0, 0usize);
    for line in text.split_inclusive('\n') {
        if line.trim_end() == "[[sphere]]" {
            if seen % part == 0 {
                cuts.push(at);
            }
            seen += 1;
        }
        at += line.len();
    }
    let first = *cuts.first()?;
    cuts.push(text.len());
    // The head must not have a key `sphere` of its own, not even `sphere = []`,
    // whose array a `[[sphere]]` cannot extend; read once, as a table, to see.
    let head = |text: &str| {
        let table = toml::from_str::<toml::Table>(text).ok()?;
        match table.contains_key("sphere") {
            true => None,
            false => table.try_into::<SceneFile>().ok(),
        }
    };
    let (head, parts) = rayon::join(
        || head(&text[..first]),
        || {
            use rayon::prelude::*;
            cuts.par_windows(2)
                .map(|w| toml::from_str::<Spheres>(&text[w[0]..w[1]]).ok())
                .collect::<Option<Vec<_>>>()
        },
    );
    let mut head = head?;
    head.sphere = parts?.into_iter().flat_map(|p| p.sphere).collect();
    Some(head)
}

/// The smallest scene raystep accepts, shown when a file lacks its camera or light.
const SMALLEST_SCENE: &str =
    "    [camera]\n    position = [0, 0, 1]\n    [light]\n    position = [5, 5, 5]";

/// Every section of a scene file and its keys, for "did you mean" and "belongs in".
const SECTIONS: [(&str, &[&str]); 8] = [
    ("[image]", &["width", "height"]),
    ("[camera]", &["position"]),
    ("[screen]", &["left", "right", "top", "bottom"]),
    ("[light]", &["position", "ambient", "diffuse", "specular"]),
    ("[render]", &["max_depth"]),
    (
        "[[sphere]]",
        &[
            "center",
            "radius",
            "ambient",
            "diffuse",
            "specular",
            "shininess",
            "reflection",
        ],
    ),
    (
        "[[plane]]",
        &[
            "sphere",
            "point",
            "normal",
            "ambient",
            "diffuse",
            "specular",
            "shininess",
            "reflection",
        ],
    ),
    ("[generate]", &["spheres", "seed"]),
];

/// A TOML or schema error as a message: where (line and column), what, a hint when
/// one is known, and the line itself with a mark under the place, cut to 80
/// characters around it (a file may be one huge line).
fn toml_error(e: &toml::de::Error, text: &str) -> String {
    let what = plain_types(e.message().trim_end());
    let with_hint = |what: String| match hint(&what) {
        Some(h) => cut_quoted(&format!("{what}; {h}")),
        None => cut_quoted(&what),
    };
    let Some(span) = e.span() else {
        if what.contains("recursion limit") {
            return deepest_nesting(text);
        }
        return with_hint(what);
    };
    let start = span.start.min(text.len());
    // A date or time where a number or list belongs: serde calls it a map.
    let value = &text[start..span.end.clamp(start, text.len())];
    let what = match what.strip_prefix("invalid type: map") {
        Some(rest) if looks_like_datetime(value) => format!("invalid type: a date or time{rest}"),
        _ => what,
    };
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
    let line = &text[line_start..line_end];
    let what = whole_number_range(&what, line);
    let what = brackets(&what, line).unwrap_or_else(|| with_hint(what));
    pointed(text, start..span.end, &what)
}

/// A whole number of the wrong kind (`width = 300.0`) told the range its key
/// accepts, not its type's: the image's sides 1 to [`MAX_SIDE`], `max_depth` 1
/// to [`MAX_DEPTH`] (the key read from the start of `line`).
fn whole_number_range(what: &str, line: &str) -> String {
    let key = line.split('=').next().unwrap_or("").trim();
    let range = match key {
        "width" | "height" => format!("from 1 to {MAX_SIDE}"),
        "max_depth" => format!("from 1 to {MAX_DEPTH}"),
        _ => return what.to_string(),
    };
    what.replace("from 0 to 4294967295", &range)
}

/// `what`, said of the text at `span` of `text`: "line L, column C: what", the
/// line (at most 80 characters of it) and a mark under the place.
fn pointed(text: &str, span: std::ops::Range<usize>, what: &str) -> String {
    let start = span.start.min(text.len());
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
    let line = text[..start].matches('\n').count() + 1;
    let chars: Vec<char> = text[line_start..line_end]
        .trim_end_matches('\r')
        .chars()
        .collect();
    let column = text[line_start..start].chars().count();
    let width = text[start..span.end.clamp(start, line_end)]
        .chars()
        .count()
        .max(1);
    // A window of at most 80 characters that shows the column.
    let from = column
        .saturating_sub(40)
        .min(chars.len().saturating_sub(80));
    let to = chars.len().min(from + 80);
    let shown: String = chars[from..to].iter().collect();
    let (dots_before, dots_after) = (
        if from > 0 { "…" } else { "" },
        if to < chars.len() { "…" } else { "" },
    );
    let gutter = " ".repeat(line.to_string().len());
    // Under a tab of the line, a tab, so that the mark stands under the place
    // whatever width a terminal gives a tab.
    let pad: String = dots_before
        .chars()
        .map(|_| ' ')
        .chain(
            chars[from..column.max(from)]
                .iter()
                .map(|&c| if c == '\t' { '\t' } else { ' ' }),
        )
        .collect();
    let marks = "^".repeat(width.min(to.saturating_sub(column)).max(1));
    format!(
        "line {line}, column {}: {what}\n{gutter} |\n{line} | {dots_before}{shown}{dots_after}\n{gutter} | {pad}{marks}",
        column + 1
    )
}

/// The message with every `quoted` or "quoted" token longer than 60 characters
/// cut to its first 40 and last 10 (a 10 MB key or string would otherwise be
/// quoted whole).
fn cut_quoted(message: &str) -> String {
    cut_between(&cut_between(message, '`'), '"')
}

/// [`cut_quoted`] for the tokens between two `quote`s.
fn cut_between(message: &str, quote: char) -> String {
    let mut out = String::with_capacity(message.len().min(4096));
    for (i, part) in message.split(quote).enumerate() {
        if i > 0 {
            out.push(quote);
        }
        let chars = part.chars().count();
        if i % 2 == 1 && chars > 60 {
            let head: String = part.chars().take(40).collect();
            let tail: String = part.chars().skip(chars - 10).collect();
            out.push_str(&format!("{head}…({} characters)…{tail}", chars - 50));
        } else {
            out.push_str(part);
        }
    }
    out
}

/// Does `value` (the text a TOML error points at) read as a TOML date or time,
/// such as `1979-05-27`, `07:32:00` or `1979-05-27T07:32:00Z`?
fn looks_like_datetime(value: &str) -> bool {
    let b = value.trim().as_bytes();
    let digits = |range: std::ops::Range<usize>| {
        b.get(range)
            .is_some_and(|d| d.iter().all(u8::is_ascii_digit))
    };
    (digits(0..4) && b.get(4) == Some(&b'-') && digits(5..7))
        || (digits(0..2) && b.get(2) == Some(&b':'))
}

/// The message for a file nested deeper than the TOML reader goes (a dotted key
/// of thousands of parts, say), which the reader gives with no place: the line
/// with the most levels, found by counting them.
fn deepest_nesting(text: &str) -> String {
    let levels = |line: &str| {
        let key = line.split('=').next().unwrap_or("");
        key.matches('.').count() + line.matches(['[', '{']).count()
    };
    let (number, deepest) = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, levels(l)))
        .max_by_key(|&(_, n)| n)
        .unwrap_or((1, 0));
    format!(
        "line {number}: nested too deeply for a scene file (about {deepest} levels of dotted keys, \
         tables or lists on that line); a scene's keys are at most two levels deep, as in \
         `[[sphere]]` then `radius = 0.5`"
    )
}

/// serde's names of types, in words a scene's author uses.
fn plain_types(message: &str) -> String {
    let message = match message.split_once("expected struct ") {
        // `expected struct CameraKeys`: the name is raystep's, not the file's.
        Some((before, _)) => format!("{before}expected a table"),
        None => message.to_string(),
    };
    message
        .replace(
            "expected u32",
            "expected a whole number from 0 to 4294967295",
        )
        .replace(
            "expected u64",
            "expected a whole number from 0 to 9223372036854775807",
        )
        .replace("expected f64", "expected a number")
        .replace("expected a sequence", "expected a list")
        .replace(
            " as i128, expected a number",
            ", beyond TOML's 64-bit integers: write it with an exponent (1e29) or a decimal \
             point, expected a number",
        )
        .replace(" as i128", "")
        .replace("`$__toml_private_datetime`", "a date or time")
        .replace("$__toml_private_datetime", "a date or time")
}

/// A table header with the wrong number of brackets (serde's own words for it,
/// "invalid type: map, expected a list", point nowhere near the fix).
fn brackets(message: &str, line: &str) -> Option<String> {
    let header = line.trim();
    let name = header.trim_matches(|c| c == '[' || c == ']' || c == ' ');
    if !message.starts_with("invalid type") || !header.starts_with('[') {
        None
    } else if header.starts_with("[[") {
        Some(format!(
            "`{header}` has two brackets, but a scene has one {name}: write `[{name}]`"
        ))
    } else {
        Some(format!(
            "`{header}` has one bracket, but there can be many of them: start each one with `[[{name}]]`"
        ))
    }
}

/// What to do about a TOML or schema error, when it is one of the usual ones.
fn hint(message: &str) -> Option<String> {
    if let Some(rest) = message.strip_prefix("unknown field `") {
        let (unknown, rest) = rest.split_once('`')?;
        let expected: Vec<&str> = rest.split('`').skip(1).step_by(2).collect();
        return unknown_key_hint(unknown, &expected);
    }
    if message.starts_with("missing field `camera`") || message.starts_with("missing field `light`")
    {
        return Some(format!(
            "every scene needs a camera and a light, at least:\n{SMALLEST_SCENE}"
        ));
    }
    if message.starts_with("duplicate key") {
        return Some("a key may be given once per section, and [image], [camera], [screen], [light], [render] and [generate] once per file (raystep has one camera and one point light)".into());
    }
    None
}

/// "did you mean" for a misspelt key, or where a key of another section belongs.
fn unknown_key_hint(unknown: &str, expected: &[&str]) -> Option<String> {
    let nearest = expected
        .iter()
        .map(|k| (strsim::damerau_levenshtein(unknown, k), *k))
        .min()
        .filter(|&(distance, k)| distance <= (k.chars().count() / 3).max(1));
    if let Some((_, key)) = nearest {
        return Some(format!("did you mean `{key}`?"));
    }
    let homes: Vec<&str> = SECTIONS
        .iter()
        .filter(|(_, keys)| keys.contains(&unknown))
        .map(|(section, _)| *section)
        .collect();
    if unknown == "sphere" && !homes.is_empty() {
        // A sphere of the scene is a section of its own; `sphere = {…}` is how a
        // [[plane]] entry names the tutorial's fake plane.
        return Some(
            "a sphere of the scene is a section of its own: start it with `[[sphere]]`, then \
             `center = [x, y, z]` and `radius = r` on lines of their own (`sphere = { … }` \
             belongs under [[plane]], where it makes the tutorial's fake plane)"
                .into(),
        );
    }
    (!homes.is_empty()).then(|| format!("`{unknown}` is a key of {}", homes.join(" and ")))
}

/// Refuse an image size that is zero or too large, naming where each side came
/// from (`image.width` or `--width`).
pub fn check_image_size(width: (u32, &str), height: (u32, &str)) -> Result<(), String> {
    for (value, source) in [width, height] {
        if value == 0 || value > MAX_SIDE {
            return Err(format!(
                "{source} = {value}: must be from 1 to {MAX_SIDE} pixels"
            ));
        }
    }
    let pixels = u64::from(width.0) * u64::from(height.0);
    if pixels > MAX_PIXELS {
        let gigabytes = (pixels * PEAK_BYTES_PER_PIXEL) as f64 / 1e9;
        return Err(format!(
            "{} = {} and {} = {} make {pixels} pixels; raystep renders at most {MAX_PIXELS} \
             (7680 × 4320), since a render needs about {PEAK_BYTES_PER_PIXEL} bytes per pixel \
             and this one would need {gigabytes:.1} GB",
            width.1, width.0, height.1, height.0
        ));
    }
    Ok(())
}

/// Refuse a `max_depth` outside 1 to [`MAX_DEPTH`], naming where it came from.
pub fn check_max_depth(max_depth: u32, source: &str) -> Result<(), String> {
    if (1..=MAX_DEPTH).contains(&max_depth) {
        Ok(())
    } else {
        Err(format!(
            "{source} = {max_depth}: must be from 1 to {MAX_DEPTH}"
        ))
    }
}

/// `--max-depth` on a scene already loaded, whose file's own `max_depth` passed
/// then: checked and set as [`Overrides::max_depth`] is when a file is read, without
/// reading it again (the studio asks this for the scene it serves).
pub fn override_max_depth(scene: &mut Scene, max_depth: Option<u32>) -> Result<(), Error> {
    if let Some(depth) = max_depth {
        check_max_depth(depth, "--max-depth").map_err(Error::Usage)?;
        scene.max_depth = depth;
    }
    Ok(())
}

pub use crate::samples::{check_spp, MAX_SPP};

/// Three numbers `[x, y, z]`: exactly three, so that a fourth is an error, not
/// silently dropped.
#[derive(Clone, Copy, Debug)]
struct Triple([f64; 3]);

impl<'de> Deserialize<'de> for Triple {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Triple, D::Error> {
        let numbers = Vec::<f64>::deserialize(d)?;
        <[f64; 3]>::try_from(numbers.as_slice())
            .map(Triple)
            .map_err(|_| {
                serde::de::Error::custom(format!(
                    "expected three numbers [x, y, z], found {}",
                    numbers.len()
                ))
            })
    }
}

// ANCHOR: schema
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    image: Option<ImageKeys>,
    camera: CameraKeys,
    screen: Option<ScreenKeys>,
    light: LightKeys,
    render: Option<RenderKeys>,
    #[serde(default)]
    sphere: Vec<SphereKeys>,
    #[serde(default)]
    plane: Vec<PlaneKeys>,
    generate: Option<GenerateKeys>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ImageKeys {
    width: Option<u32>,  // default 300
    height: Option<u32>, // default 200
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraKeys {
    position: Triple, // required
}

// ANCHOR_END: schema

// ANCHOR: schema_light
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScreenKeys {
    left: Option<f64>,   // default -1
    right: Option<f64>,  // default 1
    top: Option<f64>,    // default 1/ratio, ratio = width/height
    bottom: Option<f64>, // default -1/ratio
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightKeys {
    position: Triple,         // required
    ambient: Option<Triple>,  // default [1, 1, 1]
    diffuse: Option<Triple>,  // default [1, 1, 1]
    specular: Option<Triple>, // default [1, 1, 1]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderKeys {
    max_depth: Option<u32>, // default 3
}

// ANCHOR_END: schema_light

// ANCHOR: schema_objects
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereKeys {
    center: Triple,           // required
    radius: f64,              // required, > 0
    ambient: Option<Triple>,  // default [0.1, 0.1, 0.1]
    diffuse: Option<Triple>,  // default [0.6, 0.6, 0.6]
    specular: Option<Triple>, // default [1, 1, 1]
    shininess: Option<f64>,   // default 100
    reflection: Option<f64>,  // default 0.5
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlaneKeys {
    sphere: Option<SphereShape>, // the tutorial's fake plane ...
    point: Option<Triple>,       // ... or a true plane through `point`
    normal: Option<Triple>,      //     with this normal
    // The same material keys as a sphere:
    ambient: Option<Triple>,  // default [0.1, 0.1, 0.1]
    diffuse: Option<Triple>,  // default [0.6, 0.6, 0.6]
    specular: Option<Triple>, // default [1, 1, 1]
    shininess: Option<f64>,   // default 100
    reflection: Option<f64>,  // default 0.5
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereShape {
    center: Triple,
    radius: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GenerateKeys {
    spheres: u32,      // required: 1 to 1,000,000 spheres, made after the [[sphere]]s
    seed: Option<u64>, // default 1; as `raystep generate spheres --count N --seed S`
}
// ANCHOR_END: schema_objects

/// The material keys that `[[sphere]]` and `[[plane]]` share. (serde cannot both
/// flatten a shared struct and refuse unknown keys, so each section lists them.)
struct MaterialKeys {
    ambient: Option<Triple>,
    diffuse: Option<Triple>,
    specular: Option<Triple>,
    shininess: Option<f64>,
    reflection: Option<f64>,
}

/// Moves the material keys out of a `[[sphere]]` or `[[plane]]` entry.
macro_rules! material_keys {
    ($keys:expr) => {
        MaterialKeys {
            ambient: $keys.ambient,
            diffuse: $keys.diffuse,
            specular: $keys.specular,
            shininess: $keys.shininess,
            reflection: $keys.reflection,
        }
    };
}

impl SceneFile {
    fn check(self, overrides: Overrides) -> Result<Scene, String> {
        let image = self.image.unwrap_or(ImageKeys {
            width: None,
            height: None,
        });
        let width = match overrides.width {
            Some(w) => (w, "--width"),
            None => (image.width.unwrap_or(300), "image.width"),
        };
        let height = match overrides.height {
            Some(h) => (h, "--height"),
            None => (image.height.unwrap_or(200), "image.height"),
        };
        check_image_size(width, height)?;
        let (width, height) = (width.0, height.0);

        let camera = point(self.camera.position, &"camera.position")?;
        if camera.z == 0.0 {
            return Err(
                "camera.position: z = 0 puts the eye on the screen, which lies in the plane \
                 z = 0; move the camera off it, e.g. position = [0, 0, 1]"
                    .into(),
            );
        }

        let screen = match self.screen {
            None => None,
            Some(keys) => Some(keys.check(width, height)?),
        };
        // Near the screen's plane (but not on it) rays to the screen are too short
        // to have a direction in floating point.
        let edges = screen.unwrap_or(Screen::for_image(width, height));
        let size = view_size(camera, &edges);
        let nearest = least_length(size, MIN_RADIUS_RATIO_F64);
        if camera.z.abs() < nearest {
            return Err(format!(
                "camera.position: z = {} puts the eye too near the screen, which lies in the \
                 plane z = 0: it must be at least {} away ({} × {}, the \
                 largest coordinate of the screen's edges and the camera's x and y, and at \
                 least {MIN_RADIUS:e}), or rays to the screen have no direction; e.g. \
                 position = [0, 0, 1]",
                shown(camera.z),
                six_digits(nearest),
                six_digits(MIN_RADIUS_RATIO_F64),
                shown(size)
            ));
        }

        let light = Light {
            position: point(self.light.position, &"light.position")?,
            ambient: colour(self.light.ambient, Vec3::ONE, &"light.ambient")?,
            diffuse: colour(self.light.diffuse, Vec3::ONE, &"light.diffuse")?,
            specular: colour(self.light.specular, Vec3::ONE, &"light.specular")?,
        };

        let (max_depth, source) = match overrides.max_depth {
            Some(depth) => (depth, "--max-depth"),
            None => (
                self.render.and_then(|r| r.max_depth).unwrap_or(3),
                "render.max_depth",
            ),
        };
        check_max_depth(max_depth, source)?;

        let mut objects = Vec::new();
        for (i, keys) in self.sphere.into_iter().enumerate() {
            // Its place, written out only in a message (100,000 spheres would
            // otherwise make as many strings, and seven more each for its keys).
            let at = Lazy(|| format!("[[sphere]] number {}", i + 1));
            let shape = sphere(keys.center, keys.radius, &at)?;
            placed(&shape, &at, camera, light.position, MIN_RADIUS_RATIO_F64)?;
            objects.push(Object {
                shape: Shape::Sphere(shape),
                material: material_keys!(keys).check(&at)?,
                role: Role::Sphere,
            });
        }
        if let Some(keys) = self.generate {
            let most = crate::io::generated::MAX_GENERATED;
            let count = keys.spheres as usize;
            if !(1..=most).contains(&count) {
                return Err(format!(
                    "generate.spheres = {}: must be from 1 to {most}",
                    keys.spheres
                ));
            }
            let seed = keys.seed.unwrap_or(1);
            for (i, object) in generated_objects(count, seed).enumerate() {
                if let Shape::Sphere(shape) = &object.shape {
                    // Not in the file: named by the number explain and check give it too.
                    let id = objects.len();
                    let at = Lazy(|| {
                        format!(
                            "[generate] sphere number {} (object {id}, seed {seed})",
                            i + 1
                        )
                    });
                    placed(shape, &at, camera, light.position, MIN_RADIUS_RATIO_F64)?;
                }
                objects.push(object);
            }
        }
        for (i, keys) in self.plane.into_iter().enumerate() {
            let at = format!("[[plane]] number {}", i + 1);
            let shape = keys.shape(&at)?;
            match &shape {
                Shape::Sphere(s) => placed(
                    s,
                    &format!("{at} (a sphere)"),
                    camera,
                    light.position,
                    MIN_RADIUS_RATIO_F64,
                )?,
                Shape::Plane(plane) => {
                    lit_from_off(plane, &at, light.position, MIN_RADIUS_RATIO_F64)?
                }
            }
            objects.push(Object {
                shape,
                material: material_keys!(keys).check(&at)?,
                role: Role::Floor,
            });
        }

        Ok(Scene {
            width,
            height,
            camera,
            screen,
            light,
            max_depth,
            objects,
        })
    }
}

impl ScreenKeys {
    fn check(self, width: u32, height: u32) -> Result<Screen, String> {
        let d = Screen::for_image(width, height);
        let s = Screen {
            left: number(self.left.unwrap_or(d.left), &"screen.left")?,
            right: number(self.right.unwrap_or(d.right), &"screen.right")?,
            top: number(self.top.unwrap_or(d.top), &"screen.top")?,
            bottom: number(self.bottom.unwrap_or(d.bottom), &"screen.bottom")?,
        };
        if s.left >= s.right {
            return Err(format!(
                "screen: left ({}) must be less than right ({}); the screen would be empty or mirrored",
                s.left, s.right
            ));
        }
        if s.bottom >= s.top {
            return Err(format!(
                "screen: bottom ({}) must be less than top ({}); the screen would be empty or upside down",
                s.bottom, s.top
            ));
        }
        Ok(s)
    }
}

impl PlaneKeys {
    fn shape(&self, at: &str) -> Result<Shape, String> {
        match (&self.sphere, self.point, self.normal) {
            (Some(s), None, None) => Ok(Shape::Sphere(sphere(
                s.center,
                s.radius,
                &format!("{at}, sphere"),
            )?)),
            (None, Some(p), Some(n)) => {
                let normal = point(n, &format!("{at}, normal"))?;
                let largest = normal.abs().max_element();
                if largest == 0.0 || !normal.length_squared().is_finite() {
                    return Err(format!(
                        "{at}, normal: must be a non-zero vector of moderate size"
                    ));
                }
                // A normal so short that its squared length is subnormal or zero (say
                // [1e-162, 1e-161, 0]) has too few bits left in that square to be
                // normalised: its largest component is brought to 1 first.
                let normal = if normal.length_squared() < f64::MIN_POSITIVE {
                    normal / largest
                } else {
                    normal
                };
                let normal = normal.normalize();
                // Any point of the plane names it; keep the one nearest the origin,
                // so that the numbers the plane is computed from are no larger than
                // the plane's distance from the origin. (Adding +0 turns the −0 of
                // a zero component times a negative distance into 0, which every
                // message and `raystep check` then show as 0, not −0.)
                let anchor = point(p, &format!("{at}, point"))?;
                Ok(Shape::Plane(Plane {
                    point: normal * anchor.dot(normal) + Vec3::ZERO,
                    normal,
                }))
            }
            _ => Err(format!(
                "{at}: give either `sphere = {{ center = [x, y, z], radius = r }}` (the tutorial's \
                 fake plane) or both `point` and `normal` (a true plane), not both and not neither"
            )),
        }
    }
}

/// The spheres of `raystep generate spheres --count N --seed S` as the scene's
/// objects: their colours and mirror weights, and a sphere's defaults for the
/// keys the generated scene leaves out (what its listed `[[sphere]]` entries are
/// read into, and what a `[generate]` recipe makes).
pub fn generated_objects(count: usize, seed: u64) -> impl Iterator<Item = Object> {
    let defaults = MaterialKeys {
        ambient: None,
        diffuse: None,
        specular: None,
        shininess: None,
        reflection: None,
    }
    .check(&"a generated sphere")
    .expect("a sphere's default material is valid");
    crate::io::generated::spheres(count, seed)
        .into_iter()
        .map(move |b| Object {
            shape: Shape::Sphere(Sphere {
                center: Vec3::from(b.center),
                radius: b.radius,
            }),
            material: Material {
                ambient: Vec3::from(b.ambient),
                diffuse: Vec3::from(b.diffuse),
                specular: defaults.specular,
                shininess: defaults.shininess,
                reflection: b.reflection,
            },
            role: Role::Sphere,
        })
}

impl MaterialKeys {
    fn check(self, at: &dyn std::fmt::Display) -> Result<Material, String> {
        // Each key's place, written out only in a message.
        let key = |name: &'static str| Lazy(move || format!("{at}, {name}"));
        let shininess = number(self.shininess.unwrap_or(100.0), &key("shininess"))?;
        if shininess < 0.0 {
            return Err(format!(
                "{}: {} must be 0 or more",
                key("shininess"),
                shown(shininess)
            ));
        }
        let reflection = number(self.reflection.unwrap_or(0.5), &key("reflection"))?;
        if !(0.0..=1.0).contains(&reflection) {
            return Err(format!(
                "{}: {} must be from 0 (matte) to 1 (perfect mirror)",
                key("reflection"),
                shown(reflection)
            ));
        }
        Ok(Material {
            ambient: colour(self.ambient, Vec3::splat(0.1), &key("ambient"))?,
            diffuse: colour(self.diffuse, Vec3::splat(0.6), &key("diffuse"))?,
            specular: colour(self.specular, Vec3::ONE, &key("specular"))?,
            shininess,
            reflection,
        })
    }
}

fn number(value: f64, key: &dyn std::fmt::Display) -> Result<f64, String> {
    if !value.is_finite() {
        Err(format!("{key}: {value} is not a finite number"))
    } else if value.abs() > MAX_MAGNITUDE {
        Err(format!(
            "{key}: {} is larger than {MAX_MAGNITUDE:e} in magnitude, the most raystep accepts",
            shown(value)
        ))
    } else {
        Ok(value)
    }
}

fn point(value: Triple, key: &dyn std::fmt::Display) -> Result<Vec3, String> {
    for v in value.0 {
        number(v, key)?;
    }
    Ok(Vec3::from(value.0))
}

fn colour(
    value: Option<Triple>,
    default: Vec3,
    key: &dyn std::fmt::Display,
) -> Result<Vec3, String> {
    let Some(value) = value else {
        return Ok(default);
    };
    let c = point(value, key)?;
    if c.min_element() < 0.0 {
        return Err(format!(
            "{key}: {:?} has a negative component; colours are 0 or more",
            value.0
        ));
    }
    Ok(c)
}

/// The size of the numbers a primary ray is made from: the largest of the eye's
/// x and y and the screen's edges, in absolute value (the eye's z is what is
/// checked against it).
fn view_size(camera: Vec3, screen: &Screen) -> f64 {
    [
        camera.x,
        camera.y,
        screen.left,
        screen.right,
        screen.top,
        screen.bottom,
    ]
    .map(f64::abs)
    .into_iter()
    .fold(0.0, f64::max)
}

/// The least length (a radius, the camera's distance from the screen) that a
/// precision resolves among coordinates up to `size`: `ratio` of it
/// ([`MIN_RADIUS_RATIO`] in float32, [`MIN_RADIUS_RATIO_F64`] in float64), and at
/// least [`MIN_RADIUS`].
fn least_length(size: f64, ratio: f64) -> f64 {
    (ratio * size).max(MIN_RADIUS)
}

/// Text made only when it is shown: where a generated sphere is, named in a
/// message only if it is refused.
struct Lazy<F: Fn() -> String>(F);

impl<F: Fn() -> String> std::fmt::Display for Lazy<F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&(self.0)())
    }
}

/// Refuse a sphere too small for its place in the scene, and a camera or a light
/// inside (or on) it.
///
/// - Its radius must be at least [`MIN_RADIUS`], and at least `ratio` times the
///   largest coordinate of its center and of the camera (`ratio` is
///   [`MIN_RADIUS_RATIO`] for float32, [`MIN_RADIUS_RATIO_F64`] for float64):
///   below that, the precision's rounding of a hit point is a sizeable part of
///   the sphere, a hit point can land on the center, and its normal has no
///   direction.
/// - The tutorial's spheres are solid and shaded from outside: a camera inside
///   sees only the wall, lit as if from outside, and a light inside would leave
///   every other point in the sphere's shadow. "On" allows for rounding: within
///   `ratio` of the scene's size of the surface.
fn placed(
    s: &Sphere,
    at: &dyn std::fmt::Display,
    camera: Vec3,
    light: Vec3,
    ratio: f64,
) -> Result<(), String> {
    let size = s.center.abs().max_element().max(camera.abs().max_element());
    let smallest = least_length(size, ratio);
    if s.radius < smallest {
        let precision = if ratio == MIN_RADIUS_RATIO {
            "float32"
        } else {
            "float64"
        };
        return Err(format!(
            "{at}, radius: {} is smaller than {}, the least raystep accepts here in \
             {precision} ({} × {}, the largest coordinate of its center and of the \
             camera, and at least {MIN_RADIUS:e}): {precision} would round its hit points by \
             a sizeable part of its size; make it larger or scale the whole scene",
            shown(s.radius),
            six_digits(smallest),
            six_digits(ratio),
            shown(size)
        ));
    }
    let margin = ratio * size.max(s.radius);
    let inside = |p: Vec3| (p - s.center).length() <= s.radius + margin;
    let described = || {
        format!(
            "{at} (center {}, radius {})",
            vector(s.center),
            shown(s.radius)
        )
    };
    if inside(camera) {
        return Err(format!(
            "camera.position {} is inside {}: the camera would see only the \
             inside of that sphere's wall; move the camera or the sphere",
            vector(camera),
            described()
        ));
    }
    if inside(light) {
        return Err(format!(
            "light.position {} is inside {}: no light could leave it, so every \
             other point would be in shadow; move the light or the sphere",
            vector(light),
            described()
        ));
    }
    Ok(())
}

/// Refuse a light on a true plane (within `ratio` of the scene's size of it): the
/// plane would be lit edge-on, and a point of it could be the light itself, from
/// which no direction leads to the light.
fn lit_from_off(
    plane: &Plane,
    at: &dyn std::fmt::Display,
    light: Vec3,
    ratio: f64,
) -> Result<(), String> {
    let size = light
        .abs()
        .max_element()
        .max(plane.point.abs().max_element());
    if (light - plane.point).dot(plane.normal).abs() <= ratio * size {
        return Err(format!(
            "light.position {} lies on {at}: the plane would be lit edge-on, and the light \
             would be a point of it; move the light off the plane",
            vector(light)
        ));
    }
    Ok(())
}

/// Check a loaded scene (the loader checked it for float64) against what
/// `precision` resolves. In float64: nothing more. In float32: the loader's
/// limits again with [`MIN_RADIUS_RATIO`] (an error, naming float64 as the way
/// out), and warnings for what float32 renders but coarsely: a sphere whose
/// points it places coarsely ([`F32_TERMINATOR_WARNING`]), and spheres that
/// float32 makes one.
pub fn check_precision(scene: &Scene, precision: Precision) -> Result<Vec<String>, String> {
    if precision == Precision::F64 {
        return Ok(Vec::new());
    }
    let to_f64 = "; float64 (the default precision, --precision f64) renders it";
    let size = view_size(scene.camera, &scene.camera().screen);
    if scene.camera.z.abs() < least_length(size, MIN_RADIUS_RATIO) {
        return Err(format!(
            "camera.position: z = {} puts the eye too near the screen for float32 \
             (at least {MIN_RADIUS_RATIO:e} × {}){to_f64}",
            shown(scene.camera.z),
            shown(size)
        ));
    }
    let light = scene.light.position;
    let (mut coarse, mut twins) = (Told::default(), Told::default());
    // The largest |L·N| band of the coarse spheres.
    let mut coarsest = 0.0f64;
    // Each sphere as float32 rounds it (bits, -0 made +0, so that equal numbers
    // are equal keys), and the first object that rounds so.
    let mut rounded_to: HashMap<[u32; 4], usize> = HashMap::new();
    for (i, object) in scene.objects.iter().enumerate() {
        // Written out only in a message, as the loader does (100,000 spheres
        // would otherwise make as many strings).
        // Under the number explain, the studio and the `object` buffer give it.
        // And under its entry in the file, as the loader's messages name it.
        let entry = Lazy(|| format!("object {i} ({})", entry_of(scene, i)));
        let at = Lazy(|| format!("object {i} ({}, {})", entry_of(scene, i), describe(object)));
        match &object.shape {
            Shape::Sphere(s) => {
                // `placed` gives the centre and radius itself where it needs them.
                placed(s, &entry, scene.camera, light, MIN_RADIUS_RATIO)
                    .map_err(|e| format!("{e}{to_f64}"))?;
                // At the sphere's point farthest from the origin, where the step
                // is longest.
                let far = s.center + s.center.normalize_or(Vec3::X) * s.radius;
                let band = pass_over(F32_U, s.radius, far);
                if band > F32_TERMINATOR_WARNING {
                    coarsest = coarsest.max(band);
                    coarse.tell(|| {
                        let step = sphere_height(far, s.radius, F32_U);
                        format!(
                            "{at}: its centre is {:.1e} radii from the origin; float32 places \
                             its points to within {step:.1e} ({:.1e} of its radius), so its \
                             outline, its normals and the rays that leave it are that coarse (a \
                             shadow ray from there would pass over it up to |L·N| = {band:.2}); \
                             float64 (the default precision) renders it to 1e-3",
                            s.center.length() / s.radius,
                            step / s.radius,
                        )
                    });
                }
                let c = s.center.as_vec3();
                let key = [c.x, c.y, c.z, s.radius as f32].map(|v| (v + 0.0).to_bits());
                let first = *rounded_to.entry(key).or_insert(i);
                if first != i {
                    twins.tell(|| {
                        format!(
                            "{at} is object {first} in float32 (their centres and radii \
                             round to the same numbers), so the first of the two is drawn; \
                             float64 (the default precision) tells them apart"
                        )
                    });
                }
            }
            Shape::Plane(plane) => lit_from_off(plane, &at, light, MIN_RADIUS_RATIO)
                .map_err(|e| format!("{e}{to_f64}"))?,
        }
    }
    let mut warnings = coarse.told;
    if coarse.more > 0 {
        warnings.push(format!(
            "and {} more spheres that float32 places as coarsely (shadow rays passing over \
             them up to |L·N| = {:.2} in all); float64 (the default precision) renders them \
             to 1e-3",
            coarse.more, coarsest
        ));
    }
    warnings.extend(twins.told);
    if twins.more > 0 {
        warnings.push(format!(
            "and {} more spheres that float32 makes one with an earlier sphere, whose \
             centres and radii round to the same numbers; float64 (the default precision) \
             tells them apart",
            twins.more
        ));
    }
    Ok(warnings)
}

/// Warnings of one kind: the first [`TOLD`] in full, then how many more.
#[derive(Default)]
struct Told {
    told: Vec<String>,
    more: usize,
}

/// Warnings of one kind given in full; the rest are counted in one line (a
/// scene of 100,000 small spheres would otherwise print one for each).
const TOLD: usize = 5;

impl Told {
    fn tell(&mut self, message: impl FnOnce() -> String) {
        if self.told.len() < TOLD {
            self.told.push(message());
        } else {
            self.more += 1;
        }
    }
}

/// float32's unit roundoff.
const F32_U: f64 = f32::EPSILON as f64 / 2.0;

/// Object `i` of `scene` as the file holds it, as the loader's messages name it:
/// "`[[sphere]] number 2`" (counted from 1 among the entries of its table, where
/// the object's index counts from 0 over every object, spheres first).
fn entry_of(scene: &Scene, i: usize) -> String {
    let role = scene.objects[i].role;
    let n = scene.objects[..=i]
        .iter()
        .filter(|o| o.role == role)
        .count();
    let table = match role {
        Role::Sphere => "sphere",
        Role::Floor => "plane",
    };
    format!("[[{table}]] number {n}")
}

/// An object as messages name it.
fn describe(object: &Object) -> String {
    match &object.shape {
        Shape::Sphere(s) => format!(
            "a sphere, center {}, radius {}",
            vector(s.center),
            shown(s.radius)
        ),
        Shape::Plane(p) => format!("a plane through {}", vector(p.point)),
    }
}

/// A computed least value to six significant digits (`1.86266e-12`,
/// `0.100001`), not the seventeen that make it exact (`0.10000099999999999`):
/// rounded up, so that the number shown is itself accepted.
fn six_digits(v: f64) -> String {
    let nearest = format!("{v:.5e}");
    let mut rounded: f64 = nearest.parse().unwrap_or(v);
    if rounded < v {
        // One step up in the sixth digit.
        let (digits, exponent) = nearest.split_once('e').unwrap_or((&nearest, "0"));
        let up = digits.parse::<f64>().unwrap_or(0.0) + 1e-5;
        rounded = format!("{up:.5}e{exponent}").parse().unwrap_or(v);
    }
    shown(rounded)
}

/// `[x, y, z]` as a scene file writes it.
fn vector(v: Vec3) -> String {
    format!("[{}, {}, {}]", shown(v.x), shown(v.y), shown(v.z))
}

/// A number as a message shows it: `1e-300`, not three hundred zeros.
fn shown(v: f64) -> String {
    if v != 0.0 && !(1e-4..1e16).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

fn sphere(center: Triple, radius: f64, at: &dyn std::fmt::Display) -> Result<Sphere, String> {
    let radius = number(radius, &Lazy(|| format!("{at}, radius")))?;
    if radius <= 0.0 {
        return Err(format!(
            "{at}, radius: {} must be greater than 0",
            shown(radius)
        ));
    }
    Ok(Sphere {
        center: point(center, &Lazy(|| format!("{at}, center")))?,
        radius,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What the file gives read whole: its scene, or the message refusing it.
    fn whole(text: &str) -> Result<Scene, String> {
        let raw = toml::from_str::<SceneFile>(text).map_err(|e| toml_error(&e, text))?;
        raw.check(Overrides::default())
    }

    const HEAD: &str = "[image]\nwidth = 64\nheight = 48\n\n[camera]\nposition = [0, 0, 1]\n\n\
                        [light]\nposition = [5, 5, 5]\n\n[[plane]]\n\
                        sphere = { center = [0, -100, 0], radius = 99 }\n";

    /// Sphere `i` of a test file, its keys varied from one to the next.
    fn sphere_text(i: usize) -> String {
        let mut s = format!(
            "[[sphere]]\ncenter = [{}, {}, -{}]\nradius = 0.{}\n",
            (i % 13) as f64 * 0.25 - 1.5,
            (i % 7) as f64 * 0.1,
            3 + i % 5,
            1 + i % 9
        );
        if i.is_multiple_of(2) {
            s += &format!("ambient = [0.0{}, 0.1, 0.2]\n", i % 10);
        }
        if i.is_multiple_of(3) {
            s += "reflection = 0.25 # a comment\n";
        }
        s
    }

    /// A file of `count` spheres after [`HEAD`], in some of the ways TOML allows
    /// writing them: a spaced header, trailing blanks, line ends of Windows, a
    /// commented-out header, a table of inline keys.
    fn file(count: usize) -> String {
        let mut text = HEAD.to_string();
        for i in 0..count {
            let s = sphere_text(i);
            text += &match i % 6 {
                1 => s.replace("[[sphere]]", "[[ sphere ]]"),
                2 => s.replace("[[sphere]]\n", "[[sphere]]  \t\n"),
                3 => s.replace('\n', "\r\n"),
                4 => format!("# [[sphere]]\n{s}\n"),
                5 => s.replace("radius =", "\"radius\" ="),
                _ => s,
            };
        }
        text
    }

    #[test]
    fn a_file_read_in_parts_gives_what_it_gives_read_whole() {
        let text = file(60);
        let expected = whole(&text).expect("the test file is valid");
        assert_eq!(expected.objects.len(), 61);
        for part in [1, 2, 7, 59, 60, 1000] {
            let raw = read_apart(&text, part).expect("a file of spheres is read in parts");
            assert_eq!(
                raw.check(Overrides::default()).as_ref(),
                Ok(&expected),
                "{part}"
            );
        }
    }

    #[test]
    fn a_file_that_parts_could_misread_is_read_whole() {
        let spheres = file(12);
        let cases = [
            // The scene's own keys after the spheres: a part refuses them.
            (spheres.clone() + "[render]\nmax_depth = 2\n", true),
            (
                spheres.replace("[light]\nposition = [5, 5, 5]\n", "")
                    + "[light]\nposition = [5, 5, 5]\n",
                true,
            ),
            // Defined twice: read whole, TOML refuses it.
            (spheres.clone() + "[image]\nwidth = 8\n", false),
            // Spheres in the head already, as an array the `[[sphere]]`s cannot extend.
            (
                spheres.replace(
                    "[[plane]]",
                    "sphere = [{ center = [0, 0, -3], radius = 0.5 }]\n[[plane]]",
                ),
                false,
            ),
            // An array left open across a cut.
            (
                spheres.replacen("radius = 0.2\n", "radius = 0.2\nambient = [0.1,\n", 1),
                false,
            ),
            // A multi-line string, which might hold a line `[[sphere]]`.
            (
                spheres.replacen(
                    "radius = 0.2\n",
                    "radius = 0.2\nname = \"\"\"\n[[sphere]]\n\"\"\"\n",
                    1,
                ),
                false,
            ),
            // A mistake in a sphere: the message comes from the whole file.
            (
                spheres.replacen("radius = 0.4", "radius = \"big\"", 1),
                false,
            ),
            // No spheres at all.
            (HEAD.to_string(), true),
        ];
        for (text, valid) in cases {
            assert!(read_apart(&text, 2).is_none(), "{text}");
            assert_eq!(whole(&text).is_ok(), valid, "{text}");
        }
    }

    #[test]
    fn a_large_file_is_read_in_parts_and_a_mistake_in_it_named_at_its_line() {
        let mut text = file(14000);
        assert!(text.len() >= APART_FROM, "{} bytes", text.len());
        // Read in parts, as it is large and fit for them: what it gives whole.
        assert!(read_apart(&text, APART_PART).is_some());
        let scene = parse(&text, "big.toml").map_err(|e| e.to_string());
        assert_eq!(scene, whole(&text));
        let at = text.match_indices("[[sphere]]").nth(8000).unwrap().0;
        let line = text[..at].lines().count() + 3;
        text.insert_str(at, "[[sphere]]\ncenter = [0, 0, -3]\nradius = \"big\"\n");
        let Err(Error::Scene { message, .. }) = parse(&text, "big.toml") else {
            panic!("the mistake was missed");
        };
        assert!(
            message.starts_with(&format!("line {line}, column 10: invalid type")),
            "{message}"
        );
        assert_eq!(Err(message), whole(&text));
    }

    /// Pieces of TOML put into a file of spheres by the property below.
    const PIECES: [&str; 12] = [
        "[camera]\nposition = [0, 0, 2]\n",
        "[[sphere]]\n",
        "[[ sphere ]]\ncenter = [1, 1, -4]\nradius = 0.5\n",
        "center = [1,\n",
        "]\n",
        "radius = 2\n",
        "[sphere.x]\n",
        "sphere = []\n",
        "[[plane]]\npoint = [0, -1, 0]\nnormal = [0, 1, 0]\n",
        "s = '''\n",
        "[generate]\nspheres = 3\n",
        "# [[sphere]]\n",
    ];

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(
            std::env::var("RAYSTEP_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(2000)
        ))]

        /// Wherever pieces of TOML are put into a file of spheres, a file read
        /// in parts gives what it gives read whole: the same scene, or the
        /// same message from checking it (TOML's own are read whole).
        #[test]
        fn parts_never_disagree_with_the_whole(
            puts in proptest::collection::vec((0usize..1000, 0..PIECES.len()), 1..4),
            part in 1usize..5,
        ) {
            let mut lines: Vec<String> = file(10).lines().map(|l| format!("{l}\n")).collect();
            for (at, piece) in puts {
                let at = at % (lines.len() + 1);
                lines.insert(at, PIECES[piece].to_string());
            }
            let text = lines.concat();
            if let Some(raw) = read_apart(&text, part) {
                // The same scene, or the same message from checking it.
                proptest::prop_assert_eq!(raw.check(Overrides::default()), whole(&text), "{}", text);
            }
        }
    }

    /// A scene of many small spheres gets a few warnings in full and one line
    /// counting the rest, for each kind, not one warning per sphere; a twin is
    /// told which earlier sphere float32 makes it, as before.
    #[test]
    fn float32_warnings_are_counted_past_the_first_few() {
        let mut text = String::from(HEAD);
        // Twelve small spheres far from the origin for their size (2,000 radii).
        for i in 0..12 {
            text += &format!(
                "\n[[sphere]]\ncenter = [{}, 0, -10]\nradius = 0.005\n",
                f64::from(i) * 0.1 - 0.6
            );
        }
        // Object 13, then eight spheres that float32 rounds to it.
        text += "\n[[sphere]]\ncenter = [0, 0, -3]\nradius = 1\n";
        for i in 1..=8 {
            text += &format!(
                "\n[[sphere]]\ncenter = [0, 0, -3]\nradius = {}\n",
                1.0 + f64::from(i) * 1e-9
            );
        }
        let scene = whole(&text).unwrap();
        assert_eq!(check_precision(&scene, Precision::F64), Ok(vec![]));
        let warnings = check_precision(&scene, Precision::F32).unwrap();
        assert_eq!(warnings.len(), 2 * TOLD + 2, "{warnings:#?}");
        assert!(
            warnings.iter().all(|w| w.contains("float64")),
            "{warnings:#?}"
        );
        assert!(
            warnings[0].starts_with("object 0 ([[sphere]] number 1, a sphere"),
            "{}",
            warnings[0]
        );
        assert!(
            warnings[TOLD].starts_with("and 7 more spheres that float32 places"),
            "{}",
            warnings[TOLD]
        );
        for (k, w) in warnings[TOLD + 1..2 * TOLD + 1].iter().enumerate() {
            let number = 13 + k;
            assert!(
                w.starts_with(&format!("object {number} ("))
                    && w.contains("is object 12 in float32"),
                "{w}"
            );
        }
        assert!(
            warnings[2 * TOLD + 1].starts_with("and 3 more spheres that float32 makes one"),
            "{}",
            warnings[2 * TOLD + 1]
        );
    }

    #[test]
    fn a_value_out_of_range_is_found_in_the_file() {
        // The line and column of the value each kind of message names first.
        let message = |text: &str| match parse(text, "f.toml") {
            Err(Error::Scene { message, .. }) => message,
            other => panic!("{other:?}"),
        };
        let sphere = "\n[[sphere]]\ncenter = [0, 0, -3]\nradius = 1\n";
        let second = format!(
            "{HEAD}{sphere}{}",
            sphere.replace("radius = 1", "radius = -2")
        );
        let said = message(&second);
        assert!(
            said.starts_with("line 20, column 10: [[sphere]] number 2, radius: -2"),
            "{said}"
        );
        assert!(
            said.ends_with("\n20 | radius = -2\n   |          ^^"),
            "{said}"
        );
        // A key inside an inline table of a [[plane]].
        let said = message(&HEAD.replace("radius = 99", "radius = -99"));
        assert!(
            said.starts_with("line 12, column 44: [[plane]] number 1, sphere, radius"),
            "{said}"
        );
        // A table's own key, and a table as a whole.
        let said = message(&format!("{HEAD}{sphere}").replace("width = 64", "width = 0"));
        assert!(
            said.starts_with("line 2, column 9: image.width = 0"),
            "{said}"
        );
        let screen = "\n[screen]\nleft = 1\nright = 1\n";
        let said = message(&format!("{HEAD}{sphere}{screen}"));
        assert!(
            said.starts_with("line 18, column 1: screen: left (1)"),
            "{said}"
        );
        // What the file does not hold is named without a place: a sphere of
        // [generate] (the camera's position is the value the message names first).
        let inside = format!("{HEAD}{sphere}").replace("center = [0, 0, -3]", "center = [0, 0, 1]");
        let said = message(&inside);
        assert!(
            said.starts_with(
                "line 6, column 12: camera.position [0, 0, 1] is inside [[sphere]] number 1"
            ),
            "{said}"
        );
        assert_eq!(
            named_value("[generate] sphere number 3 (object 2, seed 1)").map(|p| p.len()),
            None
        );
        // A fake plane's own checks name its sphere "(a sphere)": the key is in it.
        let path = named_value("[[plane]] number 2 (a sphere), radius: 1e-300 is smaller");
        let keys: Vec<String> = (path.unwrap().iter())
            .map(|step| match step {
                Step::Key(k) => k.clone(),
                Step::Entry(n) => n.to_string(),
            })
            .collect();
        assert_eq!(keys, ["plane", "1", "sphere", "radius"]);
        // A file of a mebibyte or more is not read again to find the place.
        let big = format!(
            "{}{sphere}",
            HEAD.replace(
                "\n[camera]",
                &format!("\n{}\n[camera]", "#".repeat(APART_FROM))
            )
        );
        let said = message(&big.replace("radius = 1", "radius = -2"));
        assert!(
            said.starts_with("[[sphere]] number 1, radius: -2"),
            "{said}"
        );
    }

    #[test]
    fn a_least_value_is_shown_rounded_up_to_six_digits() {
        assert_eq!(six_digits(0.100001), "0.100001");
        assert_eq!(six_digits(0.10000099999999999), "0.100001");
        // Rounded to nearest, 0.1234564 would show as 0.123456, a radius that
        // the same message would refuse.
        assert_eq!(six_digits(0.1234564), "0.123457");
        for k in 1..2000 {
            let v = f64::from(k).sqrt() * 1.2345e-7 * f64::from(k);
            let shown: f64 = six_digits(v).parse().unwrap();
            assert!(
                shown >= v && shown <= v * (1.0 + 2e-5),
                "{v} shown as {shown}"
            );
        }
    }

    /// The smallest scene: a camera and a light, no objects.
    const SMALL: &str = "[camera]\nposition = [0, 0, 1]\n[light]\nposition = [5, 5, 5]\n";

    /// [`SMALL`] with `extra` after it, read whole.
    fn small(extra: &str) -> Result<Scene, String> {
        whole(&format!("{SMALL}{extra}"))
    }

    /// A sphere of radius 1 at [0, 0, -3] with the material keys `keys`.
    fn sphere_with(keys: &str) -> String {
        format!("[[sphere]]\ncenter = [0, 0, -3]\nradius = 1\n{keys}")
    }

    #[test]
    fn the_largest_image_and_max_depth_are_accepted_and_one_more_is_refused() {
        let eight_k = small("[image]\nwidth = 7680\nheight = 4320\n").unwrap();
        assert_eq!((eight_k.width, eight_k.height), (7680, 4320));
        assert_eq!(
            small("[image]\nwidth = 7680\nheight = 4321\n"),
            Err(
                "image.width = 7680 and image.height = 4321 make 33185280 pixels; raystep \
                 renders at most 33177600 (7680 × 4320), since a render needs about 64 bytes \
                 per pixel and this one would need 2.1 GB"
                    .into()
            )
        );
        assert_eq!(small("[render]\nmax_depth = 64\n").unwrap().max_depth, 64);
        assert_eq!(
            small("[render]\nmax_depth = 65\n"),
            Err("render.max_depth = 65: must be from 1 to 64".into())
        );
    }

    #[test]
    fn an_overridden_key_is_not_range_checked_in_the_file_but_still_typed() {
        let check = |extra: &str, overrides: Overrides| {
            let raw: SceneFile = toml::from_str(&format!("{SMALL}{extra}")).unwrap();
            raw.check(overrides)
        };
        let depth = Overrides {
            max_depth: Some(2),
            ..Overrides::default()
        };
        let deep = check("[render]\nmax_depth = 100\n", depth).unwrap();
        assert_eq!(deep.max_depth, 2);
        let wide = Overrides {
            width: Some(30),
            ..Overrides::default()
        };
        let scene = check("[image]\nwidth = 20000\nheight = 20\n", wide).unwrap();
        assert_eq!((scene.width, scene.height), (30, 20));
        // What is not overridden is checked as before.
        assert_eq!(
            check("[render]\nmax_depth = 100\n", wide),
            Err("render.max_depth = 100: must be from 1 to 64".into())
        );
        // The type is the file's to get right, overridden or not.
        assert!(
            toml::from_str::<SceneFile>(&format!("{SMALL}[render]\nmax_depth = \"deep\"\n"))
                .is_err()
        );
        assert!(parse_sized(
            &format!("{SMALL}[render]\nmax_depth = \"deep\"\n"),
            "t",
            depth
        )
        .is_err());
    }

    #[test]
    fn the_least_camera_distance_and_radius_are_accepted_and_less_is_refused() {
        // The default screen's edges are at most 1 from its centre, and 1.9e-15
        // of 1 is below 1e-12: the least distance from the screen is 1e-12.
        let camera = |z: &str| whole(&SMALL.replace("[0, 0, 1]", &format!("[0, 0, {z}]")));
        assert_eq!(camera("1e-12").unwrap().camera.z, 1e-12);
        assert_eq!(
            camera("-9.99e-13"),
            Err(
                "camera.position: z = -9.99e-13 puts the eye too near the screen, which lies \
                 in the plane z = 0: it must be at least 1e-12 away (1.86265e-15 × 1, the \
                 largest coordinate of the screen's edges and the camera's x and y, and at \
                 least 1e-12), or rays to the screen have no direction; e.g. position = \
                 [0, 0, 1]"
                    .into()
            )
        );
        // The same least length for a sphere's radius: 1e-12 is accepted.
        let radius = |r: &str| small(&format!("[[sphere]]\ncenter = [0, 0, -1]\nradius = {r}\n"));
        let Shape::Sphere(s) = radius("1e-12").unwrap().objects[0].shape else {
            panic!("a sphere");
        };
        assert_eq!(s.radius, 1e-12);
        assert_eq!(
            radius("9.99e-13"),
            Err(
                "[[sphere]] number 1, radius: 9.99e-13 is smaller than 1e-12, the least \
                 raystep accepts here in float64 (1.86265e-15 × 1, the largest coordinate of \
                 its center and of the camera, and at least 1e-12): float64 would round its \
                 hit points by a sizeable part of its size; make it larger or scale the whole \
                 scene"
                    .into()
            )
        );
    }

    #[test]
    fn float32_takes_a_camera_at_its_least_distance_and_refuses_one_nearer() {
        let camera = |z: &str| whole(&SMALL.replace("[0, 0, 1]", &format!("[0, 0, {z}]")));
        let at_least = camera("1e-6").unwrap();
        assert_eq!(check_precision(&at_least, Precision::F32), Ok(vec![]));
        assert_eq!(
            check_precision(&camera("9.99e-7").unwrap(), Precision::F32),
            Err(
                "camera.position: z = 9.99e-7 puts the eye too near the screen for float32 \
                 (at least 1e-6 × 1); float64 (the default precision, --precision f64) \
                 renders it"
                    .into()
            )
        );
    }

    #[test]
    fn a_material_at_the_ends_of_its_ranges_is_accepted_and_past_them_refused() {
        let scene = small(&sphere_with(
            "ambient = [0, 0, 0]\nshininess = 0\nreflection = 1\n",
        ))
        .unwrap();
        let m = &scene.objects[0].material;
        assert_eq!(
            (m.ambient, m.shininess, m.reflection),
            (Vec3::ZERO, 0.0, 1.0)
        );
        let matte = small(&sphere_with("reflection = 0\nshininess = 1e15\n")).unwrap();
        let m = &matte.objects[0].material;
        assert_eq!((m.reflection, m.shininess), (0.0, 1e15));
        assert_eq!(
            small(&sphere_with("reflection = 1.0000000000000002\n")),
            Err(
                "[[sphere]] number 1, reflection: 1.0000000000000002 must be from 0 (matte) \
                 to 1 (perfect mirror)"
                    .into()
            )
        );
        assert_eq!(
            small(&sphere_with("shininess = 1000000000000001.0\n")),
            Err(
                "[[sphere]] number 1, shininess: 1000000000000001 is larger than 1e15 \
                 in magnitude, the most raystep accepts"
                    .into()
            )
        );
    }

    #[test]
    fn a_light_on_a_sphere_within_the_band_is_refused_and_just_past_it_accepted() {
        // A sphere larger than the scene's coordinates (the camera's largest is
        // 0.75): the band is 1.9e-15 of its radius, 1.
        let edge = 1.0 + MIN_RADIUS_RATIO_F64;
        let light = |x: f64| {
            whole(&format!(
                "[camera]\nposition = [0.5, 0.5, 0.75]\n[light]\nposition = [{x:?}, 0, 0]\n\
                 [[sphere]]\ncenter = [0, 0, 0]\nradius = 1\n"
            ))
        };
        assert_eq!(
            light(edge),
            Err(format!(
                "light.position [{edge}, 0, 0] is inside [[sphere]] number 1 (center [0, 0, 0], \
                 radius 1): no light could leave it, so every other point would be in shadow; \
                 move the light or the sphere"
            ))
        );
        assert!(light(edge.next_up()).is_ok());
    }

    #[test]
    fn a_light_at_the_origin_on_a_plane_through_it_is_refused() {
        let text = SMALL.replace("[5, 5, 5]", "[0, 0, 0]")
            + "[[plane]]\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\n";
        assert_eq!(
            whole(&text),
            Err(
                "light.position [0, 0, 0] lies on [[plane]] number 1: the plane would be lit \
                 edge-on, and the light would be a point of it; move the light off the plane"
                    .into()
            )
        );
    }

    #[test]
    fn a_recipe_without_a_seed_is_seed_1() {
        let recipe = |seed: &str| small(&format!("[generate]\nspheres = 3\n{seed}"));
        let default = recipe("").unwrap();
        assert_eq!(default.objects.len(), 3);
        assert_eq!(Ok(&default), recipe("seed = 1\n").as_ref());
        assert_ne!(Ok(&default), recipe("seed = 0\n").as_ref());
    }

    #[test]
    fn a_key_is_suggested_up_to_a_third_of_its_length_in_edits() {
        let sphere = &SECTIONS[5].1;
        assert_eq!(SECTIONS[5].0, "[[sphere]]");
        // `reflection`: 10 letters, 3 edits; `position`: 8 letters, 2 edits.
        assert_eq!(
            unknown_key_hint("reflect", sphere).as_deref(),
            Some("did you mean `reflection`?")
        );
        assert_eq!(unknown_key_hint("shine", sphere), None);
        let light = &["position", "ambient", "diffuse", "specular"];
        assert_eq!(
            unknown_key_hint("positn", light).as_deref(),
            Some("did you mean `position`?")
        );
        assert_eq!(unknown_key_hint("posit", light), None);
    }

    /// Messages name an object by its index, counted from 0 over every object,
    /// spheres first (as `explain` and the `object` buffer do), and by its entry in
    /// the file, counted from 1 in its own table (as the loader's messages do): the
    /// seed scene's floor is object 3, `[[plane]] number 1`.
    #[test]
    fn an_object_is_named_by_its_entry_in_the_file() {
        let scene = whole(SEED_TOML).unwrap();
        let entries: Vec<String> = (0..scene.objects.len())
            .map(|i| entry_of(&scene, i))
            .collect();
        assert_eq!(
            entries,
            [
                "[[sphere]] number 1",
                "[[sphere]] number 2",
                "[[sphere]] number 3",
                "[[plane]] number 1"
            ]
        );
    }

    #[test]
    fn a_quoted_token_is_cut_from_61_characters_on() {
        let sixty = format!("unknown field `{}`", "k".repeat(60));
        assert_eq!(cut_quoted(&sixty), sixty);
        assert_eq!(
            cut_quoted(&format!("unknown field `{}`", "k".repeat(61))),
            format!(
                "unknown field `{}…(11 characters)…{}`",
                "k".repeat(40),
                "k".repeat(10)
            )
        );
    }

    #[test]
    fn float32_warns_of_a_sphere_a_thousand_radii_out_and_not_of_one_at_four_hundred() {
        // |L·N| up to √(2u(7 + 2·1001)) = 0.0155 and √(2u(7 + 2·401)) = 0.0098.
        let at = |z: &str| {
            small(&format!(
                "[[sphere]]\ncenter = [0, 0, -{z}]\nradius = 0.01\n"
            ))
            .unwrap()
        };
        let warnings = check_precision(&at("10"), Precision::F32).unwrap();
        assert_eq!(warnings.len(), 1, "{warnings:#?}");
        assert!(
            warnings[0].starts_with(
                "object 0 ([[sphere]] number 1, a sphere, center [0, 0, -10], radius 0.01): \
                 its centre is 1.0e3 \
                 radii from the origin"
            ) && warnings[0].contains("|L·N| = 0.02)"),
            "{}",
            warnings[0]
        );
        assert_eq!(check_precision(&at("4"), Precision::F32), Ok(vec![]));
    }

    #[test]
    fn the_deepest_line_is_counted_in_brackets_and_dots() {
        assert_eq!(
            deepest_nesting("[camera]\nposition = [0, 0, 1]\na.b = [[[[1]]]]\n"),
            "line 3: nested too deeply for a scene file (about 5 levels of dotted keys, \
             tables or lists on that line); a scene's keys are at most two levels deep, as in \
             `[[sphere]]` then `radius = 0.5`"
        );
    }

    #[test]
    fn a_long_line_is_shown_from_40_characters_before_the_place() {
        let text = format!("{}x = 1 #{}", " ".repeat(100), "c".repeat(200));
        assert_eq!(
            pointed(&text, 100..101, "here"),
            format!(
                "line 1, column 101: here\n  |\n1 | …{}x = 1 #{}…\n  | {}^",
                " ".repeat(40),
                "c".repeat(33),
                " ".repeat(41)
            )
        );
    }

    #[test]
    fn each_screen_edge_and_light_colour_is_named_in_its_message() {
        assert_eq!(
            small("[screen]\ntop = inf\n"),
            Err("screen.top: inf is not a finite number".into())
        );
        assert_eq!(
            whole(&SMALL.replace("[5, 5, 5]\n", "[5, 5, 5]\nspecular = [0, -1, 0]\n")),
            Err(
                "light.specular: [0.0, -1.0, 0.0] has a negative component; colours are 0 \
                 or more"
                    .into()
            )
        );
    }
}
