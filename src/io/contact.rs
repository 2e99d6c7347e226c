//! The contact sheet of `raystep stages`: one PNG with a row per stage and a
//! column per buffer, so that the whole progression is one picture.
//!
//! Each cell is the buffer's 8-bit picture (the same as its PNG file,
//! [`crate::io::output::visualise`]) scaled down to a thumbnail; a buffer the frame does
//! not hold is an empty cell marked "not written". Layout, in pixels:
//!
//! ```text
//! MARGIN
//!   [label column]  GAP  beauty  GAP  depth  GAP  normal  GAP  shadow   header row (HEADER_H)
//!                   GAP
//!   1 rays          GAP  thumb   GAP  empty  GAP  empty   GAP  empty    a row per frame
//!                   GAP
//!   2 intersection  GAP  thumb   GAP  thumb  GAP  thumb   GAP  thumb
//!   ...                                                                   MARGIN
//! ```
//!
//! Every cell is as wide as the widest thumbnail (and never narrower than its
//! column's name); a row is as high as its thumbnails (and never lower than a line
//! of text). Drawing is deterministic: the same frames give the same bytes.

use image::imageops::{self, FilterType};
use image::RgbImage;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;

use crate::aov::{Buffer, Frame};

/// The buffers a contact sheet shows, one column each.
pub const COLUMNS: [Buffer; 4] = [
    Buffer::Beauty,
    Buffer::Depth,
    Buffer::Normal,
    Buffer::Shadow,
];

/// Space around the whole sheet.
const MARGIN: u32 = 8;
/// Space between cells (and between the header or labels and the cells).
const GAP: u32 = 4;
/// Height of the header row of column names.
const HEADER_H: u32 = 26;
/// The lowest a row may be: one line of label text.
const LINE_H: u32 = 22;
/// Space kept beside a text, in its cell or column.
const PAD: u32 = 8;
/// Font size of the column names and row labels.
const TEXT_SIZE: f64 = 18.0;
/// Font size of the "not written" note.
const NOTE_SIZE: f64 = 14.0;
/// The note of an empty cell.
const NOTE: &str = "not written";

/// The sheet's background.
const BACKGROUND: [u8; 3] = [40, 40, 40];
/// An empty cell (a buffer the frame does not hold).
const EMPTY: [u8; 3] = [58, 58, 58];
/// Column names and row labels.
const TEXT: RGBColor = RGBColor(215, 215, 215);
/// The note of an empty cell.
const NOTE_COLOUR: RGBColor = RGBColor(160, 160, 160);

/// One row: its label, and a thumbnail per column (`None`: not written).
#[derive(Clone, Debug)]
struct Row {
    label: String,
    cells: [Option<RgbImage>; COLUMNS.len()],
}

/// The widest a thumbnail of `raystep stages`' sheet is (the built-in scene's 300
/// pixels fit).
pub const THUMBNAIL_WIDTH: u32 = 320;

/// A grid of thumbnails: a row per frame added, a column per buffer of [`COLUMNS`].
#[derive(Clone, Debug)]
pub struct ContactSheet {
    max_width: u32,
    rows: Vec<Row>,
    /// How the colour pictures are encoded (`--png`), as in their own files.
    png: crate::io::output::PngEncoding,
}

/// Where everything goes, in pixels.
#[derive(Clone, Debug, PartialEq)]
struct Layout {
    /// Width of the label column.
    label_w: u32,
    /// Width of every cell.
    cell_w: u32,
    /// Height of each row.
    row_h: Vec<u32>,
    /// The whole sheet.
    width: u32,
    height: u32,
}

impl Layout {
    /// Left edge of column `c`'s cells.
    fn cell_x(&self, c: usize) -> u32 {
        MARGIN + self.label_w + GAP + c as u32 * (self.cell_w + GAP)
    }

    /// Top edge of row `r`.
    fn row_y(&self, r: usize) -> u32 {
        MARGIN + HEADER_H + GAP + self.row_h[..r].iter().map(|h| h + GAP).sum::<u32>()
    }
}

impl ContactSheet {
    /// An empty sheet whose thumbnails are at most `max_width` pixels wide (frames are
    /// scaled down keeping their aspect; never up).
    pub fn new(max_width: u32) -> ContactSheet {
        ContactSheet {
            max_width: max_width.max(1),
            rows: Vec::new(),
            png: crate::io::output::PngEncoding::Linear,
        }
    }

    /// The same, its colour pictures encoded as `png` says, as their PNG files are.
    pub fn with_png(mut self, png: crate::io::output::PngEncoding) -> ContactSheet {
        self.png = png;
        self
    }

    /// Add a row labelled `label` (e.g. "1 rays") from `frame`: for each column, the
    /// buffer's 8-bit picture scaled to the thumbnail size, or an empty cell when the
    /// frame does not hold that buffer. Only the thumbnails are kept.
    pub fn add_row(&mut self, label: &str, frame: &Frame) {
        use rayon::iter::{IntoParallelRefIterator, ParallelIterator};
        let (width, height) = thumbnail_size(frame.width, frame.height, self.max_width);
        // The columns' pictures drawn and shrunk in parallel (a full-size picture
        // at a time on each thread).
        let cells: Vec<Option<RgbImage>> = COLUMNS
            .par_iter()
            .map(|&buffer| {
                if !frame.buffers().any(|b| b == buffer) {
                    return None;
                }
                let picture = RgbImage::from_raw(
                    frame.width,
                    frame.height,
                    crate::io::output::visualise_as(frame, buffer, self.png),
                )
                .expect("visualise gives 3 bytes per pixel");
                Some(if (width, height) == (frame.width, frame.height) {
                    picture
                } else {
                    imageops::resize(&picture, width, height, FilterType::Triangle)
                })
            })
            .collect();
        self.rows.push(Row {
            label: label.to_string(),
            cells: cells.try_into().expect("a cell per column"),
        });
    }

    /// The sheet as PNG bytes: a header row with the column names, a label column on
    /// the left, a thin gap between cells, on a neutral dark-grey background, text in
    /// light grey.
    pub fn png(&self) -> Vec<u8> {
        use image::codecs::png::PngEncoder;
        use image::ImageEncoder;
        let layout = self.layout();
        let rgb = self.draw(&layout);
        let mut bytes = Vec::new();
        PngEncoder::new(&mut bytes)
            .write_image(
                &rgb,
                layout.width,
                layout.height,
                image::ExtendedColorType::Rgb8,
            )
            .expect("encoding a PNG into memory cannot fail");
        bytes
    }

    fn layout(&self) -> Layout {
        let thumbnails = || self.rows.iter().flat_map(|r| r.cells.iter().flatten());
        let label_w = self
            .rows
            .iter()
            .map(|r| text_width(&r.label, TEXT_SIZE) + PAD)
            .max()
            .unwrap_or(0);
        let cell_w = thumbnails()
            .map(RgbImage::width)
            .chain(COLUMNS.map(|b| text_width(b.name(), TEXT_SIZE) + PAD))
            .chain([text_width(NOTE, NOTE_SIZE) + PAD])
            .max()
            .unwrap_or(0);
        let row_h: Vec<u32> = self
            .rows
            .iter()
            .map(|r| {
                r.cells
                    .iter()
                    .flatten()
                    .map(RgbImage::height)
                    .fold(LINE_H, u32::max)
            })
            .collect();
        let width = 2 * MARGIN + label_w + COLUMNS.len() as u32 * (GAP + cell_w);
        let height = 2 * MARGIN + HEADER_H + row_h.iter().map(|h| GAP + h).sum::<u32>();
        Layout {
            label_w,
            cell_w,
            row_h,
            width,
            height,
        }
    }

    /// The sheet as RGB bytes, row-major.
    fn draw(&self, layout: &Layout) -> Vec<u8> {
        let (w, h) = (layout.width, layout.height);
        let mut rgb = BACKGROUND.repeat(w as usize * h as usize);
        let mut fill =
            |x: u32, y: u32, width: u32, height: u32, pixel: &dyn Fn(u32, u32) -> [u8; 3]| {
                for dy in 0..height {
                    let start = ((y + dy) as usize * w as usize + x as usize) * 3;
                    for dx in 0..width {
                        let at = start + dx as usize * 3;
                        rgb[at..at + 3].copy_from_slice(&pixel(dx, dy));
                    }
                }
            };
        // The thumbnails, centred in their cells.
        let mut notes = Vec::new();
        for (r, row) in self.rows.iter().enumerate() {
            let (y, row_h) = (layout.row_y(r), layout.row_h[r]);
            for (c, cell) in row.cells.iter().enumerate() {
                let x = layout.cell_x(c);
                match cell {
                    Some(t) => fill(
                        x + (layout.cell_w - t.width()) / 2,
                        y + (row_h - t.height()) / 2,
                        t.width(),
                        t.height(),
                        &|dx, dy| t.get_pixel(dx, dy).0,
                    ),
                    None => {
                        fill(x, y, layout.cell_w, row_h, &|_, _| EMPTY);
                        notes.push((x + layout.cell_w / 2, y + row_h / 2));
                    }
                }
            }
        }
        // The text, over them.
        register_font();
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
            let style = |size, colour: &RGBColor, h| {
                ("sans-serif", size)
                    .into_font()
                    .color(colour)
                    .pos(Pos::new(h, VPos::Center))
            };
            let text = |s: &str, style: &TextStyle, (x, y): (u32, u32)| {
                root.draw_text(s, style, (x as i32, y as i32))
                    .expect("the built-in font draws into memory");
            };
            let header = style(TEXT_SIZE, &TEXT, HPos::Center);
            for (c, buffer) in COLUMNS.iter().enumerate() {
                let x = layout.cell_x(c) + layout.cell_w / 2;
                text(buffer.name(), &header, (x, MARGIN + HEADER_H / 2));
            }
            let label = style(TEXT_SIZE, &TEXT, HPos::Left);
            for (r, row) in self.rows.iter().enumerate() {
                let y = layout.row_y(r) + layout.row_h[r] / 2;
                text(&row.label, &label, (MARGIN, y));
            }
            let note = style(NOTE_SIZE, &NOTE_COLOUR, HPos::Center);
            for at in notes {
                text(NOTE, &note, at);
            }
            root.present()
                .expect("drawing into a buffer in memory cannot fail");
        }
        rgb
    }
}

/// The size of the thumbnail of a `width × height` frame at most `max_width` wide:
/// scaled down keeping the aspect (rounded, at least 1 pixel), never up.
fn thumbnail_size(width: u32, height: u32, max_width: u32) -> (u32, u32) {
    if width <= max_width {
        return (width, height);
    }
    let scaled =
        (u64::from(height) * u64::from(max_width) + u64::from(width) / 2) / u64::from(width);
    (max_width, (scaled as u32).max(1))
}

/// The width in pixels of `text` at `size` in the sheet's font.
fn text_width(text: &str, size: f64) -> u32 {
    register_font();
    ("sans-serif", size)
        .into_font()
        .box_size(text)
        .expect("the built-in font is registered")
        .0
}

/// Make the built-in DejaVu Sans the "sans-serif" of plotters (once), as
/// [`crate::tools::chart`] does for its charts: the same name and the same font, so
/// whichever registers first, both draw alike.
fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../../assets/DejaVuSans.ttf"),
        )
        .unwrap_or_else(|_| panic!("the built-in font is a valid TrueType font"));
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::scene_file::{parse_sized, Overrides, SEED_NAME, SEED_TOML};
    use crate::render::{render, Settings};
    use crate::stages::{Stage, Stages};

    /// The seed scene at `width × height`, every stage, into a sheet of thumbnails
    /// at most `max_width` wide; and the frame of the last stage.
    fn sheet(width: u32, height: u32, max_width: u32) -> (ContactSheet, Frame) {
        let size = Overrides {
            width: Some(width),
            height: Some(height),
            max_depth: None,
        };
        let scene = parse_sized(SEED_TOML, SEED_NAME, size).unwrap();
        let mut sheet = ContactSheet::new(max_width);
        let mut last = None;
        for stage in Stage::ALL {
            let frame = render(&scene, &Settings::from(Stages::up_to(stage)), &|_| {});
            sheet.add_row(&format!("{} {}", stage.number(), stage.name()), &frame);
            last = Some(frame);
        }
        (sheet, last.unwrap())
    }

    fn decode(png: &[u8]) -> RgbImage {
        image::load_from_memory_with_format(png, image::ImageFormat::Png)
            .unwrap()
            .to_rgb8()
    }

    #[test]
    fn thumbnails_are_scaled_down_keeping_the_aspect_never_up() {
        assert_eq!(thumbnail_size(300, 200, 150), (150, 100));
        assert_eq!(thumbnail_size(300, 200, 100), (100, 67));
        assert_eq!(thumbnail_size(300, 200, 300), (300, 200));
        assert_eq!(thumbnail_size(300, 200, 1000), (300, 200));
        assert_eq!(thumbnail_size(1000, 1, 10), (10, 1));
    }

    #[test]
    fn the_sheet_has_a_row_per_stage_and_a_cell_per_buffer_where_the_layout_puts_them() {
        let (sheet, last) = sheet(120, 80, 90);
        let png = decode(&sheet.png());
        // The layout: thumbnails of 90 × 60; labels and column names measured.
        let (tw, th) = (90, 60);
        let label_w = Stage::ALL
            .iter()
            .map(|s| text_width(&format!("{} {}", s.number(), s.name()), TEXT_SIZE) + PAD)
            .max()
            .unwrap();
        assert!(label_w > 60 && label_w < 140, "label column {label_w} px");
        assert!(COLUMNS
            .iter()
            .all(|b| text_width(b.name(), TEXT_SIZE) + PAD <= tw));
        assert!(text_width(NOTE, NOTE_SIZE) + PAD <= tw);
        let width = MARGIN + label_w + 4 * (GAP + tw) + MARGIN;
        let height = MARGIN + HEADER_H + 6 * (GAP + th) + MARGIN;
        assert_eq!(png.dimensions(), (width, height));
        // Every written cell holds its thumbnail, pixel for pixel; its centre pixel
        // is the thumbnail's.
        for (r, row) in sheet.rows.iter().enumerate() {
            let y = MARGIN + HEADER_H + GAP + r as u32 * (GAP + th);
            for (c, cell) in row.cells.iter().enumerate() {
                let x = MARGIN + label_w + GAP + c as u32 * (GAP + tw);
                let Some(thumb) = cell else { continue };
                assert_eq!(thumb.dimensions(), (tw, th));
                assert_eq!(
                    png.get_pixel(x + tw / 2, y + th / 2),
                    thumb.get_pixel(tw / 2, th / 2)
                );
                for (dx, dy, p) in thumb.enumerate_pixels() {
                    assert_eq!(png.get_pixel(x + dx, y + dy), p, "row {r} column {c}");
                }
            }
        }
        // The thumbnails are the buffers' pictures, scaled: the plane stage's, again.
        for (c, &buffer) in COLUMNS.iter().enumerate() {
            let full = RgbImage::from_raw(120, 80, crate::io::output::visualise(&last, buffer));
            let expected = imageops::resize(&full.unwrap(), tw, th, FilterType::Triangle);
            assert_eq!(sheet.rows[5].cells[c].as_ref(), Some(&expected));
        }
        // Between and around the cells: the background.
        let x_gap = MARGIN + label_w + GAP + tw;
        assert_eq!(png.get_pixel(x_gap, height / 2).0, BACKGROUND);
        assert_eq!(png.get_pixel(width - 1, height - 1).0, BACKGROUND);
        assert_eq!(png.get_pixel(0, 0).0, BACKGROUND);
    }

    #[test]
    fn a_buffer_the_stage_does_not_write_is_an_empty_cell_with_a_note() {
        let (sheet, _) = sheet(120, 80, 90);
        let png = decode(&sheet.png());
        let layout = sheet.layout();
        // Row 1 `rays`: beauty only.
        let rays = &sheet.rows[0];
        assert!(rays.cells[0].is_some());
        assert!(rays.cells[1..].iter().all(Option::is_none));
        // Row 2 `intersection` on: all four.
        assert!(sheet.rows[1].cells.iter().all(Option::is_some));
        let (x, y) = (layout.cell_x(1), layout.row_y(0));
        let cell: Vec<[u8; 3]> = (0..layout.row_h[0])
            .flat_map(|dy| (0..layout.cell_w).map(move |dx| (dx, dy)))
            .map(|(dx, dy)| png.get_pixel(x + dx, y + dy).0)
            .collect();
        // The empty-cell grey, with grey text on it: the note.
        assert_eq!(png.get_pixel(x + 1, y + 1).0, EMPTY);
        assert!(cell.iter().all(|p| p[0] == p[1] && p[1] == p[2]));
        let empty = cell.iter().filter(|&&p| p == EMPTY).count();
        assert!(empty > cell.len() / 2 && empty < cell.len(), "{empty}");
    }

    #[test]
    fn the_sheet_is_the_same_bytes_every_time() {
        let (a, _) = sheet(60, 40, 50);
        let (b, _) = sheet(60, 40, 50);
        assert_eq!(a.png(), b.png());
    }

    #[test]
    fn an_empty_sheet_is_its_header() {
        let png = decode(&ContactSheet::new(100).png());
        let layout = ContactSheet::new(100).layout();
        assert_eq!(png.dimensions(), (layout.width, 2 * MARGIN + HEADER_H));
    }

    /// The height is scaled as the width is, to the nearest pixel: 300 × 100 at 200
    /// wide is 66.7 high, so 67.
    #[test]
    fn a_thumbnails_height_rounds_to_the_nearest_pixel() {
        assert_eq!(thumbnail_size(300, 100, 200), (200, 67));
        assert_eq!(thumbnail_size(300, 100, 210), (210, 70));
    }

    /// The ink of the text in the rectangle `x0..x1` × `y0..y1`: the columns of its
    /// leftmost and rightmost pixels that are not `ground`, if any.
    fn ink(
        png: &RgbImage,
        (x0, x1): (u32, u32),
        (y0, y1): (u32, u32),
        ground: [u8; 3],
    ) -> Option<(u32, u32)> {
        let xs: Vec<u32> = (x0..x1)
            .filter(|&x| (y0..y1).any(|y| png.get_pixel(x, y).0 != ground))
            .collect();
        Some((*xs.first()?, *xs.last()?))
    }

    /// `text` drawn alone in the sheet's header style, centred at (`x`, `y`) of a
    /// `w × h` picture of the background: what a column's name looks like by itself.
    fn header_text_alone(text: &str, (w, h): (u32, u32), (x, y): (u32, u32)) -> RgbImage {
        register_font();
        let mut rgb = BACKGROUND.repeat(w as usize * h as usize);
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
            let style = ("sans-serif", TEXT_SIZE)
                .into_font()
                .color(&TEXT)
                .pos(Pos::new(HPos::Center, VPos::Center));
            root.draw_text(text, &style, (x as i32, y as i32)).unwrap();
            root.present().unwrap();
        }
        RgbImage::from_raw(w, h, rgb).unwrap()
    }

    /// README's columns, in its order: beauty, depth, normal, shadow; each name
    /// drawn over its own cells. The header strip over column `c` is compared,
    /// pixel for pixel, with each of the four names drawn alone at the same place:
    /// it must be exactly its own name and none of the others (names of nearly one
    /// width, "beauty" 53 px and "normal" 54, swapped, are caught).
    #[test]
    fn the_columns_are_beauty_depth_normal_shadow_each_named_over_its_cells() {
        let names = ["beauty", "depth", "normal", "shadow"];
        assert_eq!(COLUMNS.map(|b| b.name()), names);
        let (sheet, _) = sheet(120, 80, 90);
        let png = decode(&sheet.png());
        let layout = sheet.layout();
        let strip = (layout.cell_w, MARGIN + HEADER_H);
        for (c, name) in names.iter().enumerate() {
            let x = layout.cell_x(c);
            let drawn = imageops::crop_imm(&png, x, 0, strip.0, strip.1).to_image();
            let matching: Vec<&str> = names
                .iter()
                .copied()
                .filter(|other| {
                    let alone =
                        header_text_alone(other, strip, (strip.0 / 2, MARGIN + HEADER_H / 2));
                    alone == drawn
                })
                .collect();
            assert_eq!(matching, [*name], "the name over column {c}");
        }
    }

    /// Thumbnails lower than a line of text (16 × 8): each row is still a line high
    /// (LINE_H, 22 px: the sheet 8 + 26 + 6 × (4 + 22) + 8 = 198 high), each
    /// thumbnail in the middle of its cell (as wide as the "not written" note), and
    /// each column's name within its cell.
    #[test]
    fn small_thumbnails_sit_centred_in_rows_a_line_of_text_high() {
        let (sheet, last) = sheet(16, 8, 90);
        let png = decode(&sheet.png());
        assert_eq!(png.height(), 198);
        let layout = sheet.layout();
        let beauty =
            RgbImage::from_raw(16, 8, crate::io::output::visualise(&last, Buffer::Beauty)).unwrap();
        let (x, y) = (layout.cell_x(0), layout.row_y(5));
        let (dx, dy) = ((layout.cell_w - 16) / 2, (22 - 8) / 2);
        assert!(dx > 20, "the cell is {} wide", layout.cell_w);
        for (px, py, p) in beauty.enumerate_pixels() {
            assert_eq!(png.get_pixel(x + dx + px, y + dy + py), p, "({px}, {py})");
        }
        assert_eq!(png.get_pixel(x, y + 11).0, BACKGROUND);
        assert_eq!(png.get_pixel(x + layout.cell_w - 1, y + 11).0, BACKGROUND);
        // The names: no ink in the gaps between the cells of the header.
        for c in 0..COLUMNS.len() {
            let gap = (layout.cell_x(c) - GAP, layout.cell_x(c));
            assert_eq!(
                ink(&png, gap, (MARGIN, MARGIN + HEADER_H), BACKGROUND),
                None,
                "before column {c}"
            );
        }
    }

    /// Each row's label is drawn beside its own row, from the left margin, and
    /// the label column is the longest label's ink and PAD (within 2 pixels): an
    /// empty label above a long one leaves its row's label bare.
    #[test]
    fn each_label_is_beside_its_own_row_and_the_column_fits_the_longest() {
        let mut scene = crate::io::scene_file::seed();
        (scene.width, scene.height) = (40, 30);
        let frame = render(&scene, &Settings::from(Stages::up_to(Stage::Rays)), &|_| {});
        let mut sheet = ContactSheet::new(90);
        sheet.add_row("", &frame);
        sheet.add_row("WWWWWWWW", &frame);
        let png = decode(&sheet.png());
        let layout = sheet.layout();
        let label = |r: usize| {
            let y = layout.row_y(r);
            ink(
                &png,
                (0, layout.cell_x(0)),
                (y, y + layout.row_h[r]),
                BACKGROUND,
            )
        };
        assert_eq!(label(0), None, "the empty label's row has text");
        let (left, right) = label(1).expect("the long label's row has no text");
        assert!(left.abs_diff(MARGIN) <= 2, "the label starts at {left}");
        let drawn = right - left + 1;
        assert!(
            (layout.label_w - PAD).abs_diff(drawn) <= 2,
            "{drawn} px drawn, the column {} wide",
            layout.label_w
        );
    }

    /// With `--png srgb` the sheet shows the colour picture as its PNG file has it
    /// (README: "as their files do"), not the linear bytes: a 60 × 40 frame is
    /// shown unscaled, so the cell is the file's picture byte for byte.
    #[test]
    fn the_colour_thumbnail_is_encoded_as_its_png_file_is() {
        let mut scene = crate::io::scene_file::seed();
        (scene.width, scene.height) = (60, 40);
        let frame = render(
            &scene,
            &Settings::from(Stages::up_to(Stage::Plane)),
            &|_| {},
        );
        let srgb = crate::io::output::PngEncoding::Srgb;
        let mut sheet = ContactSheet::new(90).with_png(srgb);
        sheet.add_row("6 plane", &frame);
        let file = crate::io::output::visualise_as(&frame, Buffer::Beauty, srgb);
        assert_ne!(file, crate::io::output::visualise(&frame, Buffer::Beauty));
        let cell = sheet.rows[0].cells[0].as_ref().unwrap();
        assert_eq!(cell.as_raw(), &file);
    }

    /// The seed scene at its own size, for looking at:
    /// `cargo test --lib contact -- --ignored` writes /tmp/contact-sheet.png.
    #[test]
    #[ignore]
    fn write_the_seed_sheet_for_a_look() {
        let (sheet, _) = sheet(300, 200, 300);
        std::fs::write("/tmp/contact-sheet.png", sheet.png()).unwrap();
    }
}
