//! The page `raystep stages` writes beside its pictures: `index.html`, a grid of
//! every stage × buffer in which a picture can be chosen, seen large, and read pixel
//! by pixel; and in each stage's folder `pixels.js`, the numbers it reads.
//!
//! The page works when opened from the disk, with no server: browsers refuse
//! `fetch()` of a local file but run a local `<script src>`. So the numbers are a
//! JavaScript file that hands them to the page:
//!
//! ```text
//! raystepPixels.load("06-plane", {"width": W, "height": H, "fields": [{"name": "R", "data": "<base64>"}, …]});
//! ```
//!
//! One entry per field ([`FIELDS`]) that the stage computed (the page shows "—"
//! for the others, so their numbers are not written). Each field's `data` holds its
//! float32 of every pixel, the top row first, exactly (the page shows the values
//! `buffers.exr` holds), packed as [`pack_field`] says: neighbouring pixels have
//! nearly the same bits, and zlib finds that once the bits are differences, laid
//! out byte by byte. The built-in scene's six stages at 1920 × 1080 take 3.3 to 7.5
//! bytes per pixel each, where the 14 float32s in base64 took 74.7 (README, "Limits",
//! has the command). The page's HTML, CSS and JavaScript are `assets/page/` (plain
//! files, no build step), copied into `index.html`.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::aov::{Buffer, Frame, PixelRecord, NO_OBJECT};
use crate::error::Error;
use crate::io::output::Pending;

/// The page's file, in the folder of `raystep stages`.
pub const INDEX_FILE: &str = "index.html";

/// The numbers of a stage, in the stage's folder.
pub const PIXELS_FILE: &str = "pixels.js";

/// The largest render whose numbers [`PIXELS_FILE`] holds: 1920 × 1080, where
/// the built-in scene's six stages' files take 57 MB together. Above it the
/// page still shows the pictures, and points to `raystep serve`, which tells
/// any pixel of any size.
pub const NUMBERS_UP_TO: u64 = 1920 * 1080;

/// Whether a render of `width` × `height` gets a [`PIXELS_FILE`].
pub fn has_numbers(width: u32, height: u32) -> bool {
    u64::from(width) * u64::from(height) <= NUMBERS_UP_TO
}

/// The fields of each pixel the page shows, in order, and the buffer whose
/// stage computes each: a stage that does not write the buffer gets no numbers
/// for the field.
pub const FIELDS: [(&str, Buffer); 14] = [
    ("R", Buffer::Beauty),
    ("G", Buffer::Beauty),
    ("B", Buffer::Beauty),
    ("depth", Buffer::Depth),
    ("N.X", Buffer::Normal),
    ("N.Y", Buffer::Normal),
    ("N.Z", Buffer::Normal),
    ("P.X", Buffer::Position),
    ("P.Y", Buffer::Position),
    ("P.Z", Buffer::Position),
    ("shadow", Buffer::Shadow),
    ("object", Buffer::Object),
    ("bounces", Buffer::Bounces),
    ("rays", Buffer::Rays),
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
#[cfg(test)]
fn pixel_fields(frame: &Frame, row: u32, col: u32) -> [f32; 14] {
    let mut fields = record_fields(frame.at(row, col));
    fields[7..10].copy_from_slice(&frame.position(row, col));
    fields
}

/// [`pixel_fields`] but the position, which needs the primary ray (left 0 here).
fn record_fields(p: &PixelRecord) -> [f32; 14] {
    let [r, g, b] = p.colour;
    let [nx, ny, nz] = p.normal;
    let object = if p.object == NO_OBJECT {
        -1.0
    } else {
        p.object as f32
    };
    let (bounces, rays) = (p.bounces as f32, p.rays as f32);
    [
        r, g, b, p.depth, nx, ny, nz, 0.0, 0.0, 0.0, p.shadow, object, bounces, rays,
    ]
}

/// The contents of `folder/pixels.js` for `frame`: every field the stage
/// computed, of every pixel, each packed by [`pack_field`] (the fields in
/// parallel: the same bytes whatever the number of threads).
pub fn pixels_js(folder: &str, frame: &Frame) -> String {
    use rayon::prelude::*;
    // Each field is packed straight from the records, and the text is put
    // together field by field, each dropped once copied: at 1920 × 1080 a
    // field's float32s are 8 MB, and `raystep stages` keeps its peak memory
    // near the frame's own. A field the record holds as it is gets a loop of
    // its own that reads only that number (through `record_fields`, which
    // makes all fourteen, the fields took a sixth longer). The positions' primary
    // rays are computed once for their three fields, 24 MB at that size,
    // dropped before the text is put together: each field computing them anew
    // took three times as long as a field read from the records.
    let (n, pixels) = (frame.pixels.len(), &frame.pixels);
    let positions = match frame.has(Buffer::Position) {
        true => positions(frame),
        false => Vec::new(),
    };
    let fields: Vec<(&str, String)> = FIELDS
        .par_iter()
        .enumerate()
        .filter(|(_, (_, buffer))| frame.has(*buffer))
        .map(|(i, (name, _))| {
            let data = match i {
                0..=2 => pack_with(n, |k| pixels[k].colour[i]),
                3 => pack_with(n, |k| pixels[k].depth),
                4..=6 => pack_with(n, |k| pixels[k].normal[i - 4]),
                7..=9 => pack_with(n, |k| positions[k][i - 7]),
                10 => pack_with(n, |k| pixels[k].shadow),
                _ => pack_with(n, |k| record_fields(&pixels[k])[i]),
            };
            (*name, data)
        })
        .collect();
    drop(positions);
    let packed: usize = fields
        .iter()
        .map(|(name, data)| name.len() + data.len() + 32)
        .sum();
    let mut js = String::with_capacity(packed + 256);
    js.push_str("// The numbers of every pixel, for index.html. Written by raystep stages.\n");
    let folder = serde_json::to_string(folder).expect("a string is valid JSON");
    js.push_str(&format!(
        "raystepPixels.load({folder}, {{\"width\": {}, \"height\": {}, \"fields\": [",
        frame.width, frame.height
    ));
    for (i, (name, data)) in fields.into_iter().enumerate() {
        js.push_str(if i == 0 { "\n" } else { ",\n" });
        js.push_str(&format!("{{\"name\": \"{name}\", \"data\": \""));
        js.push_str(&data);
        js.push_str("\"}");
    }
    js.push_str("\n]});\n");
    js
}

/// [`Frame::position`] of every pixel, in reading order (the rows in
/// parallel, each row's primary rays computed by [`Frame::ray_buffers_row`]).
fn positions(frame: &Frame) -> Vec<[f32; 3]> {
    use rayon::prelude::*;
    let width = frame.width as usize;
    let mut positions = vec![[0.0; 3]; frame.pixels.len()];
    (positions.par_chunks_mut(width).enumerate()).for_each_init(Vec::new, |rays, (row, out)| {
        rays.clear();
        frame.ray_buffers_row(row as u32, 0..width as u32, rays);
        for (position, (_, ray_position)) in out.iter_mut().zip(rays.iter()) {
            *position = *ray_position;
        }
    });
    positions
}

// ANCHOR: pack_field
/// One field's float32s (one per pixel, in reading order) as the page reads
/// them, exactly, in few bytes:
///
/// 1. each value's 32 bits less the bits of the value before it (wrapping; the
///    first less 0): neighbours are alike, so the differences are small
///    numbers, and a flat area (the sky, a field the stage leaves constant) is
///    zeros;
/// 2. the differences' lowest bytes first (every pixel's), then their second
///    bytes, third, and highest: runs of like bytes (the high bytes of small
///    differences are 0 or 255);
/// 3. compressed with zlib (RFC 1950, what a browser's
///    `DecompressionStream("deflate")` reads), then written in base64.
///
/// The page undoes the three in reverse (`assets/page/page.js`, `unpack`).
pub fn pack_field(values: &[f32]) -> String {
    pack_with(values.len(), |i| values[i])
}

/// [`pack_field`] of the `n` values `value(0)`, `value(1)`, …
fn pack_with(n: usize, value: impl Fn(usize) -> f32) -> String {
    let mut planes = vec![0u8; 4 * n];
    let mut before = 0u32;
    for i in 0..n {
        let bits = value(i).to_bits();
        let difference = bits.wrapping_sub(before).to_le_bytes();
        before = bits;
        for (plane, byte) in difference.into_iter().enumerate() {
            planes[plane * n + i] = byte;
        }
    }
    let zlib = miniz_oxide::deflate::compress_to_vec_zlib(&planes, ZLIB_LEVEL);
    drop(planes);
    let mut out = String::with_capacity(zlib.len().div_ceil(3) * 4);
    base64_into(&mut out, &zlib);
    out
}
// ANCHOR_END: pack_field

/// miniz's level (0 to 10) for [`pack_field`]: 1, the fastest. On the built-in
/// scene's last stage at 1920 × 1080, level 6 (zlib's default) writes a fifth
/// less (5.9 bytes per pixel instead of 7.5) in 6.7 times the time (1.9 s
/// instead of 0.28 s on one thread), which made `raystep stages` at that size
/// take half as long again.
const ZLIB_LEVEL: u8 = 1;

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

    /// What the page's `unpack` does: base64, zlib, the bytes of each difference
    /// from the four planes, added to the bits before.
    fn unpack(data: &str, count: usize) -> Vec<f32> {
        use base64::Engine as _;
        let zlib = base64::engine::general_purpose::STANDARD
            .decode(data)
            .expect("base64");
        let planes = miniz_oxide::inflate::decompress_to_vec_zlib(&zlib).expect("zlib");
        assert_eq!(planes.len(), 4 * count);
        let mut before = 0u32;
        (0..count)
            .map(|i| {
                let difference = u32::from_le_bytes([0, 1, 2, 3].map(|k| planes[k * count + i]));
                before = before.wrapping_add(difference);
                f32::from_bits(before)
            })
            .collect()
    }

    /// The call `pixels_js` writes: its folder, and its object.
    fn call(js: &str) -> (String, serde_json::Value) {
        let (comment, call) = js.split_once('\n').expect("a comment line");
        assert!(comment.starts_with("// "), "{comment}");
        let args = call
            .strip_prefix("raystepPixels.load(")
            .and_then(|c| c.strip_suffix(");\n"))
            .expect("one call");
        let args: serde_json::Value = serde_json::from_str(&format!("[{args}]")).expect("JSON");
        (args[0].as_str().unwrap().to_string(), args[1].clone())
    }

    #[test]
    fn pixels_js_holds_every_field_the_stage_computed_of_every_pixel_exactly() {
        // 7 × 5: 35 pixels, and the last stage computes every field.
        let plane = frame(7, 5, Stage::Plane);
        let (folder, info) = call(&pixels_js("06-plane", &plane));
        assert_eq!(folder, "06-plane");
        assert_eq!(
            (info["width"].as_u64(), info["height"].as_u64()),
            (Some(7), Some(5))
        );
        let fields = info["fields"].as_array().unwrap();
        let names: Vec<&str> = fields.iter().map(|f| f["name"].as_str().unwrap()).collect();
        assert_eq!(names, FIELDS.map(|(name, _)| name));
        for (i, field) in fields.iter().enumerate() {
            let values = unpack(field["data"].as_str().unwrap(), 35);
            for (n, v) in values.iter().enumerate() {
                let (row, col) = (n as u32 / 7, n as u32 % 7);
                let expected = pixel_fields(&plane, row, col)[i];
                // The same bits: -0 stays -0, +∞ stays +∞.
                assert_eq!(
                    v.to_bits(),
                    expected.to_bits(),
                    "{} at ({col}, {row})",
                    names[i]
                );
            }
        }
        // The first stage writes the picture and the rays' directions: only the
        // colour's fields, whose values the page shows.
        let rays = frame(7, 5, Stage::Rays);
        let (_, info) = call(&pixels_js("01-rays", &rays));
        let names: Vec<&str> = info["fields"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["name"].as_str().unwrap())
            .collect();
        assert_eq!(names, ["R", "G", "B"]);
    }

    #[test]
    fn a_flat_field_packs_to_almost_nothing_and_any_bits_come_back() {
        // The sky's depth at 1920 × 1080: 8 MB of float32s.
        let sky = vec![f32::INFINITY; 1920 * 1080];
        let packed = pack_field(&sky);
        // Under 0.05 bytes a pixel (miniz's fastest level: 50,688 bytes).
        assert!(packed.len() < 1920 * 1080 / 20, "{} bytes", packed.len());
        assert_eq!(unpack(&packed, sky.len()), sky);
        // Differences that wrap around, signs, zeros, the extremes.
        let odd = [
            0.0,
            -0.0,
            f32::MAX,
            -f32::MAX,
            f32::MIN_POSITIVE,
            1.0,
            -1.0,
            f32::NEG_INFINITY,
            0.1,
        ];
        let back = unpack(&pack_field(&odd), odd.len());
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back), bits(&odd));
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

    /// Each number of a pixel's record is the field of its name, in the order of
    /// [`FIELDS`] (R, G, B, depth, N.X, N.Y, N.Z, P.X, P.Y, P.Z, shadow, object,
    /// bounces, rays): a record whose numbers all differ, and its fields written out
    /// by hand (the position left 0, filled in from the primary ray).
    #[test]
    fn each_number_of_a_record_is_the_field_of_its_name() {
        let record = PixelRecord {
            colour: [0.1, 0.2, 0.3],
            depth: 4.0,
            normal: [0.5, 0.6, 0.7],
            shadow: 1.0,
            object: 9,
            diffuse: 0.25,
            specular: 0.125,
            bounces: 2,
            rays: 5,
        };
        assert_eq!(
            record_fields(&record),
            [0.1, 0.2, 0.3, 4.0, 0.5, 0.6, 0.7, 0.0, 0.0, 0.0, 1.0, 9.0, 2.0, 5.0]
        );
    }

    /// The manifest states the render's size as asked (30 wide, 20 high: the page
    /// draws its canvas and reads its pixels by them) and the largest render with
    /// numbers, 1920 × 1080 = 2,073,600 pixels.
    #[test]
    fn the_manifest_states_the_size_and_the_largest_render_with_numbers() {
        let html = index_html("s", 30, 20, &[stage("01-rays", &["beauty"])]);
        let start = html.find("const MANIFEST = ").unwrap() + "const MANIFEST = ".len();
        let end = start + html[start..].find(";\n").unwrap();
        let manifest: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
        assert_eq!(
            (&manifest["width"], &manifest["height"]),
            (&30.into(), &20.into())
        );
        assert_eq!(manifest["numbersUpTo"], 2_073_600);
    }
}
