//! `raystep chart`: what each setting costs in time and buys in accuracy, in one
//! picture; and how the cost grows with the number of spheres.
//!
//! **Speed against accuracy.** Every setting that trades one for the other is
//! rendered on the same scene: precision, intersection method, offset, samples
//! per pixel, `max_depth`, early stop, acceleration. Accuracy is the beauty's error
//! against a reference render of the same scene made with every careful choice
//! (float64, the stable method, the automatic offset, 64 samples per pixel, 16
//! segments, no early stop): the root mean square error and the worst pixel, in
//! 8-bit levels. Speed is the median time per frame of the render alone, the runs
//! of all settings interleaved so that a noisy machine slows all of them alike.
//! A setting is on the Pareto frontier when no other setting is both faster and
//! more accurate.
//!
//! **Scale.** Generated scenes of N spheres ([`crate::tools::generate`]) at the chart's
//! size, rendered with `--accel auto` and with the plain loop (`--accel off`, up to
//! the count where it becomes too slow to wait for), and with `--embree PATH` by
//! the Embree program of `benches/embree` on the same scenes, beside them.

use std::path::Path;
use std::time::Instant;

use plotters::coord::combinators::{BindKeyPoints, WithKeyPoints};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::accel::Accel;
use crate::aov::Frame;
use crate::engine::render_into;
use crate::error::Error;
use crate::io::output::Pending;
use crate::real::Precision;
use crate::render::Settings;
use crate::scene::Scene;
use crate::shade::shadow::Offset;
use crate::sphere::Method;
use crate::stages::Engine;
use crate::stages::Stages;
use crate::tools::bench::{median, RowClock};

/// The font of the PNG charts, built in so that no system font is needed
/// (DejaVu Sans; its licence is in `assets/DejaVuSans-LICENSE.txt`).
const FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// One setting of the sweep, measured.
#[derive(Clone, Debug)]
pub struct Point {
    /// Short name, drawn beside the point.
    pub label: String,
    /// Median seconds per frame (render only).
    pub median_s: f64,
    /// Root mean square error of the beauty against the reference, 8-bit levels.
    pub rmse: f64,
    /// Largest error of any channel of any pixel, 8-bit levels.
    pub worst: f64,
    /// Is this raystep's default?
    pub default: bool,
    /// Is it on the Pareto frontier?
    pub frontier: bool,
}

/// A setting to measure: a label, the settings, and a `max_depth`.
struct Config {
    label: &'static str,
    settings: Settings,
    max_depth: u32,
}

/// The settings the chart compares: the default; the tutorial's program; and
/// changes from the default, most of one setting, a few of two (float32 with the
/// scene-sized step, four samples in float32, sixteen segments without the early
/// stop).
fn configs(max_depth: u32) -> Vec<Config> {
    // Speed is the fast engine's; the book's engine is one point of the chart.
    let default = Settings {
        engine: Engine::Fast,
        ..Settings::from(Stages::ALL)
    };
    let with = |label, change: &dyn Fn(&mut Settings)| {
        let mut settings = default;
        change(&mut settings);
        Config {
            label,
            settings,
            max_depth,
        }
    };
    let depth = |label, depth: u32, early_stop: bool| Config {
        label,
        settings: Settings {
            early_stop,
            ..default
        },
        max_depth: depth,
    };
    vec![
        with("default", &|_| {}),
        Config {
            label: "tutorial",
            settings: Settings {
                engine: Engine::Fast,
                ..Settings::tutorial(Stages::ALL)
            },
            max_depth,
        },
        with("f32", &|s| s.precision = Precision::F32),
        with("naive", &|s| s.method = Method::Naive),
        with("fixed:1e-5", &|s| s.offset = Offset::TUTORIAL),
        // The scene-sized step the bound replaced: what the bound costs.
        with("offset scene", &|s| s.offset = Offset::Scene),
        with("f32, offset scene", &|s| {
            s.precision = Precision::F32;
            s.offset = Offset::Scene;
        }),
        with("accel off", &|s| s.accel = Accel::Off),
        with("book engine", &|s| s.engine = Engine::Book),
        with("early stop off", &|s| s.early_stop = false),
        with("spp 4", &|s| s.spp = 4),
        with("spp 16", &|s| s.spp = 16),
        with("spp 4, f32", &|s| {
            s.spp = 4;
            s.precision = Precision::F32;
        }),
        depth("depth 1", 1, true),
        depth("depth 2", 2, true),
        depth("depth 16", 16, true),
        depth("depth 16, no early stop", 16, false),
    ]
}

/// The reference: every careful choice.
pub fn reference_settings() -> (Settings, u32) {
    let settings = Settings {
        precision: Precision::F64,
        method: Method::Stable,
        offset: Offset::Auto,
        spp: 64,
        early_stop: false,
        ..Settings::from(Stages::ALL)
    };
    (settings, 16)
}

/// Measure every setting on `scene`, `runs` timed runs each after a warm-up.
/// `progress(1)` is called after each render.
pub fn sweep(scene: &Scene, runs: usize, progress: &dyn Fn(u64)) -> Vec<Point> {
    let configs = configs(scene.max_depth);
    let (reference_settings, reference_depth) = reference_settings();
    let reference = render_at(scene, &reference_settings, reference_depth);
    progress(1);
    let mut frames: Vec<Frame> = configs
        .iter()
        .map(|c| Frame::blank(scene.camera(), c.settings.precision))
        .collect();
    let scenes: Vec<Scene> = configs
        .iter()
        .map(|c| Scene {
            max_depth: c.max_depth,
            ..scene.clone()
        })
        .collect();
    let mut times = vec![Vec::with_capacity(runs); configs.len()];
    for run in 0..=runs {
        for (i, c) in configs.iter().enumerate() {
            let start = Instant::now();
            render_into(&scenes[i], &c.settings, &mut frames[i], &|_| {});
            if run > 0 {
                times[i].push(start.elapsed().as_secs_f64());
            }
            progress(1);
        }
    }
    let mut points: Vec<Point> = configs
        .iter()
        .zip(frames)
        .zip(times)
        .map(|((c, frame), times)| {
            let (rmse, worst) = error(&frame, &reference);
            Point {
                label: c.label.to_string(),
                median_s: median(times),
                rmse,
                worst,
                default: c.label == "default",
                frontier: false,
            }
        })
        .collect();
    mark_frontier(&mut points);
    points
}

/// Render `scene` with `settings` and `max_depth`.
fn render_at(scene: &Scene, settings: &Settings, max_depth: u32) -> Frame {
    let scene = Scene {
        max_depth,
        ..scene.clone()
    };
    crate::render::render(&scene, settings, &|_| {})
}

/// Renders needed by [`sweep`] with `runs` runs: the reference, then a warm-up and
/// `runs` of each setting.
pub fn sweep_renders(runs: usize) -> u64 {
    1 + (configs(1).len() * (runs + 1)) as u64
}

/// The beauty's error against `reference`: (root mean square, worst), in 8-bit
/// levels (1 level = 1/255).
pub fn error(frame: &Frame, reference: &Frame) -> (f64, f64) {
    let mut sum = 0.0;
    let mut worst = 0.0f64;
    for (a, b) in frame.pixels.iter().zip(&reference.pixels) {
        for c in 0..3 {
            let d = f64::from(a.colour[c]) - f64::from(b.colour[c]);
            sum += d * d;
            worst = worst.max(d.abs());
        }
    }
    let n = (frame.pixels.len() * 3).max(1) as f64;
    ((sum / n).sqrt() * 255.0, worst * 255.0)
}

/// Mark the points that no other point beats on both time and error.
pub fn mark_frontier(points: &mut [Point]) {
    for i in 0..points.len() {
        let p = &points[i];
        let beaten = points.iter().any(|q| {
            q.median_s <= p.median_s
                && q.rmse <= p.rmse
                && (q.median_s < p.median_s || q.rmse < p.rmse)
        });
        points[i].frontier = !beaten;
    }
}

/// The points as CSV.
pub fn csv(points: &[Point]) -> String {
    csv_text(
        &[
            "setting",
            "median_ms",
            "rmse_levels",
            "worst_levels",
            "default",
            "frontier",
        ],
        points.iter().map(|p| {
            [
                p.label.clone(),
                format!("{:.3}", p.median_s * 1e3),
                format!("{:.4}", p.rmse),
                format!("{:.2}", p.worst),
                p.default.to_string(),
                p.frontier.to_string(),
            ]
        }),
    )
}

/// A header and rows as CSV, one record a line ending in `\n`, a field quoted
/// (its quotes doubled) only where it holds a comma, a quote or a line break, as
/// RFC 4180 has it ("spp 4, f32" is a label). Written by the `csv` crate.
fn csv_text<const N: usize>(header: &[&str; N], rows: impl Iterator<Item = [String; N]>) -> String {
    let mut writer = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    let fail = "writing CSV into memory cannot fail";
    writer.write_record(header).expect(fail);
    for row in rows {
        writer.write_record(&row).expect(fail);
    }
    let bytes = writer
        .into_inner()
        .expect("flushing CSV into memory cannot fail");
    String::from_utf8(bytes).expect("CSV of strings is UTF-8")
}

/// Who drew a point of the scale sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Series {
    /// raystep's fast engine with this `--accel`.
    Raystep(Accel),
    /// The Embree program of `benches/embree` on the same scene.
    Embree,
}

impl std::fmt::Display for Series {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Series::Raystep(accel) => accel.fmt(f),
            Series::Embree => f.write_str("embree"),
        }
    }
}

/// One measurement of the scale sweep.
#[derive(Clone, Debug)]
pub struct ScalePoint {
    /// Spheres in the scene.
    pub count: usize,
    /// How the nearest hit was searched for (or Embree).
    pub series: Series,
    /// Median seconds per frame (render only; raystep's includes its BVH build,
    /// Embree's does not).
    pub median_s: f64,
    /// Median seconds of the frame without building the tree: raystep's rows
    /// alone (as `raystep bench` times them, `trace_s`), Embree's frame.
    pub trace_s: f64,
    /// Seconds to build the BVH alone (0 without one).
    pub build_s: f64,
    /// Bytes of the BVH (raystep's; 0 without one, and for Embree).
    pub bvh_bytes: usize,
}

/// Render generated scenes of each count in `counts` at `width × height`, with
/// `--accel auto` and, up to `plain_up_to` spheres, `--accel off`; and, given
/// the path of the Embree program (`benches/embree/run.sh build`), with it too,
/// right after raystep's renders of the same scene, on as many threads.
pub fn scale(
    counts: &[usize],
    plain_up_to: usize,
    (width, height): (u32, u32),
    runs: usize,
    embree: Option<&Path>,
    progress: &dyn Fn(u64),
) -> Result<Vec<ScalePoint>, Error> {
    let mut points = Vec::new();
    for &count in counts {
        let mut scene = crate::tools::generate::scene(count, 1);
        (scene.width, scene.height) = (width, height);
        let objects: Vec<crate::scene::Object> = scene.objects_in_play(Stages::ALL);
        let start = Instant::now();
        let bvh = crate::bvh::Bvh::build(&objects);
        let build_s = start.elapsed().as_secs_f64();
        for accel in [Accel::Auto, Accel::Off] {
            if accel == Accel::Off && count > plain_up_to {
                continue;
            }
            let settings = Settings {
                accel,
                engine: Engine::Fast,
                ..Settings::from(Stages::ALL)
            };
            let mut frame = Frame::blank(scene.camera(), settings.precision);
            let mut times = Vec::new();
            let clock = RowClock::default();
            for run in 0..=runs {
                let start = Instant::now();
                render_into(&scene, &settings, &mut frame, &clock);
                if run > 0 {
                    times.push(start.elapsed().as_secs_f64());
                }
                progress(1);
            }
            let uses_bvh = accel.builds_bvh(count, settings.method);
            points.push(ScalePoint {
                count,
                series: Series::Raystep(accel),
                median_s: median(times),
                trace_s: median(clock.timed()),
                build_s: if uses_bvh { build_s } else { 0.0 },
                bvh_bytes: if uses_bvh { bvh.bytes() } else { 0 },
            });
        }
        if let Some(program) = embree {
            let (median_s, build_s) = run_embree(program, count, (width, height), runs)?;
            points.push(ScalePoint {
                count,
                series: Series::Embree,
                median_s,
                trace_s: median_s,
                build_s,
                bvh_bytes: 0,
            });
            progress(1);
        }
    }
    Ok(points)
}

/// Run the Embree program on the generated scene of `count` spheres (seed 1,
/// written to its standard input) at `width × height`, `runs` timed runs after
/// a warm-up, on rayon's number of threads: its median seconds per frame and its
/// build's seconds, from the CSV row it prints.
fn run_embree(
    program: &Path,
    count: usize,
    (width, height): (u32, u32),
    runs: usize,
) -> Result<(f64, f64), Error> {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let fail = |message: String| Error::Output {
        path: program.to_path_buf(),
        message,
    };
    let mut child = Command::new(program)
        .args([
            "--width",
            &width.to_string(),
            "--height",
            &height.to_string(),
        ])
        .args(["--runs", &runs.to_string()])
        .args(["--threads", &rayon::current_num_threads().to_string(), "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| fail(format!("cannot run the Embree program: {e}")))?;
    let text = crate::tools::generate::spheres_toml(count, 1);
    let mut stdin = child.stdin.take().expect("stdin is piped");
    let writer = std::thread::spawn(move || stdin.write_all(text.as_bytes()));
    let output = child
        .wait_with_output()
        .map_err(|e| fail(format!("the Embree program failed: {e}")))?;
    let _ = writer.join();
    if !output.status.success() {
        return Err(fail(format!(
            "the Embree program failed: {}",
            output.status
        )));
    }
    let stdout = String::from_utf8_lossy(&output.stdout);
    let mut lines = stdout.lines();
    let (header, row) = (lines.next().unwrap_or(""), lines.next().unwrap_or(""));
    let field = |name: &str| -> Option<f64> {
        let k = header.split(',').position(|h| h == name)?;
        row.split(',').nth(k)?.parse().ok()
    };
    match (field("median_ms"), field("build_ms")) {
        (Some(median), Some(build)) => Ok((median / 1e3, build / 1e3)),
        _ => Err(fail(format!("unexpected output: {stdout}"))),
    }
}

/// The scale points as CSV.
pub fn scale_csv(points: &[ScalePoint]) -> String {
    csv_text(
        &[
            "spheres",
            "accel",
            "median_ms",
            "bvh_build_ms",
            "bvh_bytes",
            "trace_ms",
        ],
        points.iter().map(|p| {
            [
                p.count.to_string(),
                p.series.to_string(),
                format!("{:.3}", p.median_s * 1e3),
                format!("{:.3}", p.build_s * 1e3),
                p.bvh_bytes.to_string(),
                format!("{:.3}", p.trace_s * 1e3),
            ]
        }),
    )
}

/// Make the built-in font the charts' "sans-serif" (once).
fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
            .unwrap_or_else(|_| panic!("the built-in font is a valid TrueType font"));
    });
}

/// Chart size in pixels.
const SIZE: (u32, u32) = (960, 640);

/// Something that draws a chart as SVG.
type DrawSvg<'a> = dyn for<'b> Fn(&DrawingArea<SVGBackend<'b>, Shift>) -> Result<(), String> + 'a;
/// Something that draws a chart into a bitmap.
type DrawBitmap<'a> =
    dyn for<'b> Fn(&DrawingArea<BitMapBackend<'b>, Shift>) -> Result<(), String> + 'a;

/// Write a chart as `stem.svg` and `stem.png` in `dir`, drawn by `draw`, into
/// `pending` (renamed into place when it is committed).
fn write_chart(
    pending: &mut Pending,
    dir: &Path,
    stem: &str,
    draw: &DrawSvg,
    draw_bitmap: &DrawBitmap,
) -> Result<Vec<std::path::PathBuf>, Error> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        draw(&root).map_err(|e| chart_error(dir, stem, e))?;
        root.present()
            .map_err(|e| chart_error(dir, stem, e.to_string()))?;
    }
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        draw_bitmap(&root).map_err(|e| chart_error(dir, stem, e))?;
        root.present()
            .map_err(|e| chart_error(dir, stem, e.to_string()))?;
    }
    let png = {
        use image::codecs::png::PngEncoder;
        use image::ImageEncoder;
        let mut bytes = Vec::new();
        PngEncoder::new(&mut bytes)
            .write_image(&rgb, SIZE.0, SIZE.1, image::ExtendedColorType::Rgb8)
            .expect("encoding a PNG into memory cannot fail");
        bytes
    };
    let files = [
        (dir.join(format!("{stem}.svg")), svg.into_bytes()),
        (dir.join(format!("{stem}.png")), png),
    ];
    for (path, bytes) in &files {
        pending.file(path, bytes)?;
    }
    Ok(files.into_iter().map(|(p, _)| p).collect())
}

fn chart_error(dir: &Path, stem: &str, message: String) -> Error {
    Error::Output {
        path: dir.join(stem),
        message: format!("cannot draw the chart: {message}"),
    }
}

/// A range that holds `values` on a log axis, with a margin.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    (lo / 1.6)..(hi * 1.6)
}

/// The labelled values of a log axis over `range`: 1, 2, …, 9 times each power of
/// ten where the axis spans less than two decades, else the powers of ten alone.
/// (Plotters' own choice gives each power of ten twice, as the last multiple of
/// one decade and the first of the next, and its label is drawn twice.)
fn log_ticks(range: &std::ops::Range<f64>) -> Vec<f64> {
    let (lo, hi) = (range.start, range.end);
    let multiples: &[f64] = if (hi / lo).log10() < 2.0 {
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    } else {
        &[1.0]
    };
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    (first..=last)
        .flat_map(|k| multiples.iter().map(move |m| m * 10f64.powi(k)))
        .filter(|v| (lo..=hi).contains(v))
        .collect()
}

/// A chart whose axes are both logarithmic, labelled at [`log_ticks`].
type LogLog<'a, DB> =
    ChartContext<'a, DB, Cartesian2d<WithKeyPoints<LogCoord<f64>>, WithKeyPoints<LogCoord<f64>>>>;

/// The axes of a chart on a white `root`: both logarithmic, over the ranges given,
/// named, with `y_decimals` decimals on the y labels.
fn log_log<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    (xs, x_desc): (std::ops::Range<f64>, &str),
    (ys, y_desc): (std::ops::Range<f64>, &str),
    y_decimals: usize,
) -> Result<LogLog<'a, DB>, String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(
            xs.clone().log_scale().with_key_points(log_ticks(&xs)),
            ys.clone().log_scale().with_key_points(log_ticks(&ys)),
        )
        .map_err(e)?;
    chart
        .configure_mesh()
        .light_line_style(TRANSPARENT)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.y_decimals$}"))
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(e)?;
    Ok(chart)
}

/// Draw the legend of the series labelled on `chart`, at `position`.
fn legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut LogLog<'a, DB>,
    position: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .label_font(("sans-serif", 14))
        .position(position)
        .draw()
        .map_err(|e| e.to_string())
}

/// Draw the speed-against-accuracy chart on `root`.
fn draw_sweep<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    points: &[Point],
    title: &str,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let floor = 1e-3;
    let mut chart = log_log(
        root,
        title,
        (
            log_range(points.iter().map(|p| p.median_s * 1e3)),
            "milliseconds per frame (median, render only)",
        ),
        (
            log_range(points.iter().map(|p| p.rmse.max(floor))),
            "error: RMSE against the reference (8-bit levels)",
        ),
        2,
    )?;
    let mut frontier: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.frontier)
        .map(|p| (p.median_s * 1e3, p.rmse.max(floor)))
        .collect();
    frontier.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart
        .draw_series(LineSeries::new(frontier, BLUE.stroke_width(2)))
        .map_err(e)?
        .label("Pareto frontier")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE.stroke_width(2)));
    let red = RGBColor(200, 30, 30);
    // Labels: beside their point, moved down a line while they would overlap a
    // label already placed (settings that give the same picture sit together).
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| points[a].rmse.total_cmp(&points[b].rmse).reverse());
    let mut placed: Vec<(i32, i32, i32)> = Vec::new();
    let mut elements = Vec::new();
    for i in order {
        let p = &points[i];
        let at = (p.median_s * 1e3, p.rmse.max(floor));
        let (px, py) = chart.backend_coord(&at);
        let label = p.label.clone();
        let width = 7 * label.chars().count() as i32;
        let mut dy = -14;
        while placed
            .iter()
            .any(|&(x, y, w)| (py + dy - y).abs() < 14 && px < x + w && x < px + width)
        {
            dy += 14;
        }
        placed.push((px, py + dy, width));
        let (colour, size) = if p.default { (red, 7) } else { (BLACK, 4) };
        elements.push(
            EmptyElement::at(at)
                + Circle::new((0, 0), size, colour.filled())
                + Text::new(
                    label,
                    (8, dy),
                    ("sans-serif", 13).into_font().color(&colour),
                ),
        );
    }
    chart.draw_series(elements).map_err(e)?;
    legend(&mut chart, SeriesLabelPosition::UpperRight)
}

/// Write the speed-against-accuracy chart as `stem.svg` and `stem.png`.
pub fn write_sweep(
    pending: &mut Pending,
    dir: &Path,
    stem: &str,
    points: &[Point],
    title: &str,
) -> Result<Vec<std::path::PathBuf>, Error> {
    write_chart(
        pending,
        dir,
        stem,
        &|root| draw_sweep(root, points, title),
        &|root| draw_sweep(root, points, title),
    )
}

/// Draw the time-against-spheres chart on `root`.
fn draw_scale<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    points: &[ScalePoint],
    title: &str,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let mut chart = log_log(
        root,
        title,
        (
            log_range(points.iter().map(|p| p.count as f64)),
            "spheres in the scene",
        ),
        (
            log_range(
                points
                    .iter()
                    .flat_map(|p| [p.median_s * 1e3, p.trace_s * 1e3]),
            ),
            "milliseconds per frame (median)",
        ),
        0,
    )?;
    let auto = format!(
        "raystep --accel auto (BVH from {} spheres): the rays alone",
        crate::accel::BVH_FROM
    );
    // raystep's whole frame, its tree's build and set-up included, dashed.
    let whole: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.series == Series::Raystep(Accel::Auto))
        .map(|p| (p.count as f64, p.median_s * 1e3))
        .collect();
    if !whole.is_empty() {
        let colour = RGBColor(120, 150, 255);
        chart
            .draw_series(DashedLineSeries::new(whole, 6, 4, colour.stroke_width(2)))
            .map_err(e)?
            .label("raystep --accel auto: the whole frame, the BVH's build included")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    for (series, colour, name) in [
        (Series::Raystep(Accel::Auto), BLUE, auto.as_str()),
        (
            Series::Raystep(Accel::Off),
            RGBColor(200, 30, 30),
            "raystep --accel off (plain loop)",
        ),
        (
            Series::Embree,
            RGBColor(20, 140, 60),
            "Embree 3, user-geometry spheres, 8-ray packets (its build not counted)",
        ),
    ] {
        let series: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.series == series)
            .map(|p| (p.count as f64, p.trace_s * 1e3))
            .collect();
        if series.is_empty() {
            continue;
        }
        chart
            .draw_series(LineSeries::new(series.clone(), colour.stroke_width(2)))
            .map_err(e)?
            .label(name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart
            .draw_series(
                series
                    .into_iter()
                    .map(|(x, y)| Circle::new((x, y), 4, colour.filled())),
            )
            .map_err(e)?;
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft)
}

/// Write the time-against-spheres chart as `stem.svg` and `stem.png`.
pub fn write_scale(
    pending: &mut Pending,
    dir: &Path,
    stem: &str,
    points: &[ScalePoint],
    title: &str,
) -> Result<Vec<std::path::PathBuf>, Error> {
    write_chart(
        pending,
        dir,
        stem,
        &|root| draw_scale(root, points, title),
        &|root| draw_scale(root, points, title),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_label_with_a_comma_stays_one_csv_field() {
        let text = csv(&[point("spp 4, f32", 10.0, 1.0), point("default", 5.0, 2.0)]);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[1], "\"spp 4, f32\",10.000,1.0000,1.00,false,false");
        assert_eq!(lines[2], "default,5.000,2.0000,2.00,false,false");
        let quoted = csv_text(&["a"], [["a \"b\"".to_string()]].into_iter());
        assert_eq!(quoted, "a\n\"a \"\"b\"\"\"\n");
    }

    #[test]
    fn a_log_axis_labels_each_value_once() {
        // Under two decades: every multiple of each power of ten inside the range.
        let ticks = log_ticks(&(6.0..300.0));
        let want = [
            6, 7, 8, 9, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 200, 300,
        ];
        assert_eq!(ticks.len(), want.len(), "{ticks:?}");
        for (t, w) in ticks.iter().zip(want) {
            assert!((t - f64::from(w)).abs() < 1e-9 * t, "{ticks:?}");
        }
        let small = log_ticks(&(0.39..25.0));
        assert_eq!(small.iter().filter(|&&t| (t - 1.0).abs() < 1e-9).count(), 1);
        assert_eq!(
            small.iter().filter(|&&t| (t - 10.0).abs() < 1e-9).count(),
            1
        );
        assert!(small.windows(2).all(|w| w[0] < w[1]), "{small:?}");
        // Two decades or more: the powers of ten alone.
        let wide = log_ticks(&(0.6..1.6e6));
        assert_eq!(wide, [1.0, 10.0, 100.0, 1e3, 1e4, 1e5, 1e6]);
    }

    fn point(label: &str, ms: f64, rmse: f64) -> Point {
        Point {
            label: label.into(),
            median_s: ms / 1e3,
            rmse,
            worst: rmse,
            default: false,
            frontier: false,
        }
    }

    #[test]
    fn the_frontier_keeps_the_points_nothing_beats_on_both_axes() {
        let mut points = vec![
            point("fast, rough", 1.0, 10.0),
            point("slow, fine", 10.0, 1.0),
            point("slow and rough", 10.0, 10.0),
            point("middle", 5.0, 5.0),
            point("beaten by middle", 6.0, 6.0),
        ];
        mark_frontier(&mut points);
        let on: Vec<&str> = points
            .iter()
            .filter(|p| p.frontier)
            .map(|p| p.label.as_str())
            .collect();
        assert_eq!(on, ["fast, rough", "slow, fine", "middle"]);
    }

    #[test]
    fn charts_draw_to_svg_and_png_without_system_fonts() {
        let folder = tempfile::tempdir().unwrap();
        let dir = folder.path();
        let mut points = vec![point("a", 1.0, 2.0), point("b", 2.0, 1.0)];
        points[0].default = true;
        mark_frontier(&mut points);
        let mut pending = Pending::new();
        let files = write_sweep(&mut pending, dir, "t", &points, "test").unwrap();
        pending.commit().unwrap();
        let svg = std::fs::read_to_string(&files[0]).unwrap();
        assert!(svg.contains("Pareto frontier") && svg.contains("milliseconds per frame"));
        // The two labels, each as its own line of text.
        assert!(svg.lines().any(|l| l.trim() == "a") && svg.lines().any(|l| l.trim() == "b"));
        let png = image::open(&files[1]).unwrap().to_rgb8();
        // Some pixels are not white: the axes, the points, the text.
        assert!(png.pixels().filter(|p| p.0 != [255, 255, 255]).count() > 1000);
    }

    /// Ties decide the frontier too: a point as accurate as another but slower, or
    /// as fast but less accurate, is beaten (the committed chart's `default` is off
    /// the frontier because `naive` has its error exactly, in less time).
    #[test]
    fn a_point_tied_on_one_axis_and_worse_on_the_other_is_off_the_frontier() {
        let mut points = vec![
            point("naive", 7.1, 2.1),
            point("default, as accurate and slower", 7.5, 2.1),
            point("as fast and rougher", 7.1, 3.0),
            point("slower and finer", 9.0, 1.0),
        ];
        mark_frontier(&mut points);
        let on: Vec<bool> = points.iter().map(|p| p.frontier).collect();
        assert_eq!(on, [true, false, false, true]);
    }

    /// The frontier weighs time against the root mean square error, the chart's y
    /// axis, not against the worst pixel: a point faster and lower in RMSE beats
    /// another whatever their worst pixels.
    #[test]
    fn the_frontier_weighs_the_rmse_not_the_worst_pixel() {
        let mut points = vec![
            point("fast, fine", 1.0, 1.0),
            point("slow, rough", 2.0, 2.0),
        ];
        points[0].worst = 100.0;
        points[1].worst = 1.0;
        mark_frontier(&mut points);
        assert!(points[0].frontier && !points[1].frontier, "{points:?}");
    }

    /// The error of one known difference: two pixels whose channels differ by
    /// (+1, +1, −5) and (+1, −5, +1) levels. Squares 1 + 1 + 25 twice, 54 over six
    /// channels, 9, whose root is 3 levels; the worst is the 5 levels below, in the
    /// blue channel of the first pixel and the green of the second.
    #[test]
    fn the_error_is_the_root_mean_square_over_every_channel_and_the_worst_difference() {
        let mut scene = crate::tools::generate::scene(1, 1);
        (scene.width, scene.height) = (2, 1);
        let mut reference = Frame::blank(scene.camera(), Precision::F64);
        let mut frame = reference.clone();
        let base = [0.5f32, 0.5, 0.5];
        let level = 1.0 / 255.0;
        for (i, diff) in [[1.0f32, 1.0, -5.0], [1.0, -5.0, 1.0]].iter().enumerate() {
            reference.pixels[i].colour = base;
            for c in 0..3 {
                frame.pixels[i].colour[c] = base[c] + diff[c] * level;
            }
        }
        let (rmse, worst) = error(&frame, &reference);
        assert!((rmse - 3.0).abs() < 1e-4, "rmse {rmse}");
        assert!((worst - 5.0).abs() < 1e-4, "worst {worst}");
        // The same frame against itself: no error at all.
        assert_eq!(error(&reference, &reference), (0.0, 0.0));
    }

    /// The CSV's header and one row as the committed `chapters/charts/chart.csv`
    /// has them: median in milliseconds, RMSE, then the worst pixel.
    #[test]
    fn the_chart_csv_has_the_documented_columns_in_order() {
        let mut p = point("default", 7.454, 2.1062);
        p.worst = 121.75;
        p.default = true;
        let text = csv(&[p]);
        assert_eq!(
            text,
            "setting,median_ms,rmse_levels,worst_levels,default,frontier\n\
             default,7.454,2.1062,121.75,true,false\n"
        );
    }

    /// The scale CSV's columns, as chapter 10 and the committed
    /// `chapters/charts/scale.csv` name them, each from its own field.
    #[test]
    fn the_scale_csv_has_the_documented_columns_in_order() {
        let points = [
            ScalePoint {
                count: 30,
                series: Series::Raystep(Accel::Auto),
                median_s: 0.051,
                trace_s: 0.050,
                build_s: 0.001,
                bvh_bytes: 1234,
            },
            ScalePoint {
                count: 30,
                series: Series::Embree,
                median_s: 0.0775,
                trace_s: 0.0775,
                build_s: 0.0075,
                bvh_bytes: 0,
            },
        ];
        assert_eq!(
            scale_csv(&points),
            "spheres,accel,median_ms,bvh_build_ms,bvh_bytes,trace_ms\n\
             30,auto,51.000,1.000,1234,50.000\n\
             30,embree,77.500,7.500,0,77.500\n"
        );
    }

    /// The renders of a sweep of two runs: the reference, then for each of the
    /// seventeen settings a warm-up and two timed runs, 1 + 17 × 3.
    /// And a sweep of one run, of a tiny scene, renders that many frames (the
    /// count sizes `chart`'s progress bar): 1 + 17 × 2.
    #[test]
    fn a_sweep_counts_the_reference_the_warm_ups_and_the_runs() {
        assert_eq!(sweep_renders(2), 52);
        let mut scene = crate::io::scene_file::seed();
        (scene.width, scene.height) = (4, 3);
        let ticks = std::cell::Cell::new(0u64);
        let points = sweep(&scene, 1, &|n| ticks.set(ticks.get() + n));
        assert_eq!(ticks.get(), sweep_renders(1));
        assert_eq!(sweep_renders(1), 35);
        assert_eq!(points.len(), 17);
    }

    /// An axis over 2 to 50 reaches a factor of 1.6 beyond both ends: 1.25 to 80.
    #[test]
    fn a_log_range_leaves_a_margin_on_both_sides() {
        let range = log_range([50.0, 2.0, 10.0].into_iter());
        assert!((range.start - 1.25).abs() < 1e-12, "{range:?}");
        assert!((range.end - 80.0).abs() < 1e-12, "{range:?}");
    }

    /// Exactly two decades is "two decades or more": the powers of ten alone.
    #[test]
    fn a_log_axis_of_exactly_two_decades_labels_the_powers_of_ten() {
        assert_eq!(log_ticks(&(1.0..100.0)), [1.0, 10.0, 100.0]);
    }

    /// `--scale` renders every count with `--accel auto`, the plain loop up to
    /// `plain_up_to` spheres included, and reports a tree (its bytes and build
    /// time) only for `auto` from `BVH_FROM` (24) spheres on.
    #[test]
    fn scale_runs_the_plain_loop_up_to_its_limit_and_counts_a_tree_only_where_one_is_built() {
        let from = crate::accel::BVH_FROM;
        let points = scale(&[from - 1, from, from + 1], from, (8, 6), 1, None, &|_| {}).unwrap();
        let rows: Vec<(usize, String, bool)> = points
            .iter()
            .map(|p| (p.count, p.series.to_string(), p.bvh_bytes > 0))
            .collect();
        let want = [
            (from - 1, "auto", false),
            (from - 1, "off", false),
            (from, "auto", true),
            (from, "off", false),
            (from + 1, "auto", true),
        ];
        let want: Vec<(usize, String, bool)> = want
            .iter()
            .map(|&(n, s, tree)| (n, s.to_string(), tree))
            .collect();
        assert_eq!(rows, want);
        for p in &points {
            assert_eq!(p.build_s > 0.0, p.bvh_bytes > 0, "{p:?}");
        }
    }

    /// A stand-in for the Embree program: it keeps its arguments and its standard
    /// input in `dir`, prints the header of `benches/embree/spheres.cpp` and one
    /// row (a build of 2.5 ms, a median of 40 ms), and exits with `code`.
    fn fake_embree(dir: &Path, code: i32) -> std::path::PathBuf {
        use std::os::unix::fs::PermissionsExt;
        let program = dir.join(format!("embree-{code}"));
        let script = format!(
            "#!/bin/sh\n\
             echo \"$@\" > '{args}'\n\
             cat > '{stdin}'\n\
             echo objects,width,height,threads,runs,geometry,build_ms,median_ms,min_ms,max_ms\n\
             echo 4,8,6,1,1,user,2.5,40,39,41\n\
             exit {code}\n",
            args = dir.join("args").display(),
            stdin = dir.join("stdin").display(),
        );
        std::fs::write(&program, script).unwrap();
        std::fs::set_permissions(&program, std::fs::Permissions::from_mode(0o755)).unwrap();
        program
    }

    /// With `--embree`, the program is run on the same scene (the generated one of
    /// seed 1, as `raystep generate spheres` writes it) at the chart's size, and its
    /// row is read by the names of its columns, milliseconds made seconds.
    #[test]
    fn scale_reads_the_embree_programs_row_by_its_column_names() {
        let folder = tempfile::tempdir().unwrap();
        let dir = folder.path();
        let program = fake_embree(dir, 0);
        let points = scale(&[4], 0, (8, 6), 1, Some(&program), &|_| {}).unwrap();
        let embree: Vec<&ScalePoint> = points
            .iter()
            .filter(|p| p.series == Series::Embree)
            .collect();
        assert_eq!(embree.len(), 1, "{points:?}");
        let p = embree[0];
        assert_eq!(p.count, 4);
        assert!((p.median_s - 0.040).abs() < 1e-12, "{p:?}");
        assert!((p.trace_s - 0.040).abs() < 1e-12, "{p:?}");
        assert!((p.build_s - 0.0025).abs() < 1e-12, "{p:?}");
        let args = std::fs::read_to_string(dir.join("args")).unwrap();
        assert!(
            args.starts_with("--width 8 --height 6 --runs 1 --threads "),
            "{args}"
        );
        let stdin = std::fs::read_to_string(dir.join("stdin")).unwrap();
        assert_eq!(stdin, crate::tools::generate::spheres_toml(4, 1));
        assert!(scale_csv(&points).contains("\n4,embree,40.000,2.500,0,40.000\n"));
        // A program that fails is an error, whatever it printed.
        let failing = fake_embree(dir, 1);
        let err = scale(&[4], 0, (8, 6), 1, Some(&failing), &|_| {}).unwrap_err();
        assert!(
            err.to_string().contains("the Embree program failed"),
            "{err}"
        );
    }

    /// The blue line joins the frontier's points alone, left to right: of four
    /// points three are on the frontier, so the SVG's blue lines are the frontier
    /// of three vertices and the legend's sample of two.
    #[test]
    fn the_frontier_line_joins_only_the_frontier_points_in_order_of_time() {
        let dir = tempfile::tempdir().unwrap();
        let mut points = vec![
            point("c", 3.0, 1.0),
            point("a", 1.0, 3.0),
            point("beaten", 4.0, 4.0),
            point("b", 2.0, 2.0),
        ];
        mark_frontier(&mut points);
        let mut pending = Pending::new();
        let files = write_sweep(&mut pending, dir.path(), "f", &points, "test").unwrap();
        pending.commit().unwrap();
        let svg = std::fs::read_to_string(&files[0]).unwrap();
        let mut lines: Vec<Vec<i64>> = svg
            .split("<polyline")
            .skip(1)
            .filter(|e| e.contains("stroke=\"#0000FF\""))
            .map(|e| {
                let points = e.split("points=\"").nth(1).unwrap();
                let points = &points[..points.find('"').unwrap()];
                points
                    .split_whitespace()
                    .map(|xy| xy.split(',').next().unwrap().parse().unwrap())
                    .collect()
            })
            .collect();
        lines.sort_by_key(Vec::len);
        assert_eq!(
            lines.iter().map(Vec::len).collect::<Vec<_>>(),
            [2, 3],
            "{lines:?}"
        );
        assert!(lines[1].windows(2).all(|w| w[0] < w[1]), "{lines:?}");
    }
}
