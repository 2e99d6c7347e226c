//! The command line's grammar: what each command accepts (clap's derives, the
//! limits `--help` prints) and how its arguments become a scene and settings.
//! [`cli`](super::cli) carries the commands out; the studio (`serve`) reads its
//! query keys with the same grammar.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

use crate::accel::Accel;
use crate::error::{to_stderr, Error};
use crate::io::output::{ExrCompression, PngEncoding};
use crate::io::scene_file::{self, Overrides};
use crate::real::Precision;
use crate::render::Settings;
use crate::scene::Scene;
use crate::shade::blinn_phong::Viewer;
use crate::shade::shadow::Offset;
use crate::sphere::Method;
use crate::stages::{Engine, Stage, Stages};

/// raystep: a ray tracer that teaches ray tracing one step at a time.
///
/// With no command, renders every stage of the built-in figure-1 scene into out/
/// (the same as raystep stages).
#[derive(Parser, Debug)]
#[command(name = "raystep", version, about, long_about, after_help = LIMITS)]
pub struct Cli {
    /// What to do (default: stages on the built-in scene).
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Print no status lines (what is being rendered, the files written, the
    /// progress bar) on standard error; errors and warnings still go there.
    #[arg(short, long, global = true)]
    pub quiet: bool,
}

/// The limits that keep a mistake from taking the machine down, as `--help` prints
/// them (the numbers are the constants of [`scene_file`], `samples`,
/// `tools::generate`, `io::generated` and `tools::cli`; a test in
/// `tests/hostile.rs` checks each).
pub const LIMITS: &str = "\
Limits (a value beyond them is refused with a message, exit code 2):
  image          1 to 16384 pixels a side, at most 7680 × 4320 in all: a render
                 takes about 64 bytes of memory per pixel (2.1 GB at the most)
  max_depth      1 to 64 segments per path (--max-depth, render.max_depth)
  --spp          a square number from 1 to 1024
  numbers        finite, at most 1e15 in magnitude; a radius at least 1e-12 and
                 1.9e-15 of the scene's size (1e-6 with --precision f32)
  scene files    at most 16 MiB
  generate       at most 1,000,000 spheres, listed up to 100,000 and above
                 written as a recipe ([generate] spheres = N, at most 1,000,000)
  chart --scale  a --max-count whose largest scene fits in 2.1 GB: about 750
                 bytes per sphere and 64 per pixel

Exit codes: 0 done, 1 diff found the images different, 2 a mistake in the input
or trouble, 130 interrupted (Ctrl-C: the files of the render before stay as they
were).";

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render every stage, rays to plane, each into DIR/NN-STAGE/ (01-rays, …, 06-plane) with its buffers.
    Stages(StagesArgs),
    /// Render one set of stages into DIR/: beauty, buffers as PNG, and buffers.exr.
    Render(RenderArgs),
    /// Tell the whole story of one pixel: the primary ray, every object's test,
    /// the nearest hit, the shadow ray, each Blinn-Phong term, each bounce, the colour.
    Explain(ExplainArgs),
    /// Check a scene file and print what it contains.
    Check(CheckArgs),
    /// Compare the beauty of two renders (their buffers.exr files), pixel by pixel.
    Diff(DiffArgs),
    /// Render the book's figures into chapters/img (run from the repository's root).
    Figures(FiguresArgs),
    /// Measure every stress scene × precision × intersection method × offset against
    /// a careful float64 reference: false hits and misses, hit points off the
    /// surface, stepped-off origins still inside it, wrong shadows.
    Accuracy(AccuracyArgs),
    /// Time a frame (render only) against the tutorial's program ported plainly,
    /// and with one thread against several: seconds per frame, rays and pixels per
    /// second, peak memory. Default: the built-in scene at 1920 × 1080, every stage.
    Bench(BenchArgs),
    /// Write a generated scene as TOML to standard output.
    Generate(GenerateArgs),
    /// Chart speed against accuracy for every setting that trades one for the other
    /// (or, with --scale, time against the number of spheres): a CSV, an SVG and a
    /// PNG. Default: the built-in scene at 960 × 540.
    Chart(ChartArgs),
    /// Serve a live page on 127.0.0.1 to switch stages, pick buffers and read any
    /// pixel's story, re-rendered on demand; the scene file is watched. Also an
    /// HTTP API (see the README). Runs until Ctrl-C.
    Serve(ServeArgs),
    /// Print a completion script for a shell to standard output, e.g.
    /// raystep completions bash > ~/.local/share/bash-completion/completions/raystep
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the manual page (roff) to standard output, e.g. raystep man | man -l -;
    /// with a command, that command's page (raystep-render(1): raystep man render)
    Man {
        /// The command whose page to print (default: raystep's own page, which
        /// lists the commands).
        #[arg(value_parser = COMMANDS)]
        command: Option<String>,
    },
}

/// The commands that have a manual page of their own (`raystep man COMMAND`;
/// `generate-spheres` is `raystep generate spheres`).
pub const COMMANDS: [&str; 14] = [
    "stages",
    "render",
    "explain",
    "check",
    "diff",
    "figures",
    "accuracy",
    "bench",
    "generate",
    "chart",
    "serve",
    "completions",
    "man",
    "generate-spheres",
];

/// Arguments of `raystep explain`.
#[derive(Args, Debug)]
pub struct ExplainArgs {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub frame: FrameArgs,
    /// The pixel: column and row from the top-left corner, e.g. 150,120.
    #[arg(long, value_parser = parse_pixel, allow_hyphen_values = true)]
    pub pixel: (u32, u32),
    /// Print one JSON object instead of the story in words (its depth is the
    /// first hit's distance, null on a miss).
    #[arg(long)]
    pub json: bool,
}

/// `X,Y` as two whole numbers.
fn parse_pixel(text: &str) -> Result<(u32, u32), String> {
    let usage = || format!("`{text}`: expected X,Y, two whole numbers such as 150,120");
    let (x, y) = text.split_once(',').ok_or_else(usage)?;
    let x = x.trim().parse().map_err(|_| usage())?;
    let y = y.trim().parse().map_err(|_| usage())?;
    Ok((x, y))
}

/// Arguments of `raystep chart`.
#[derive(Args, Debug)]
pub struct ChartArgs {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub scene: SceneArgs,
    /// Timed runs of each setting, after one warm-up run.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000), allow_negative_numbers = true)]
    pub runs: u32,
    /// Chart time against the number of spheres instead, on generated scenes at
    /// --width × --height (default 1920 × 1080).
    #[arg(long)]
    pub scale: bool,
    /// With --scale, the largest count (powers of ten and their triples up to it).
    #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u64).range(1..=10_000_000), requires = "scale", allow_negative_numbers = true)]
    pub max_count: u64,
    /// With --scale, also time the Embree program at PATH on each scene (built by
    /// benches/embree/run.sh build), drawn beside raystep's points.
    #[arg(long, value_name = "PATH", requires = "scale")]
    pub embree: Option<PathBuf>,
    /// Where the CSV and the charts go.
    #[arg(long, short = 'o', visible_alias = "output", default_value = "out")]
    pub out: PathBuf,
}

/// Arguments of `raystep generate`.
#[derive(Args, Debug)]
pub struct GenerateArgs {
    /// What to generate.
    #[command(subcommand)]
    pub what: Generated,
}

/// The scenes `raystep generate` can write.
#[derive(Subcommand, Debug)]
pub enum Generated {
    /// N spheres resting on the floor, at 1920 × 1080; the radius shrinks as 1/√N.
    Spheres {
        /// How many spheres, 1 to 1,000,000. Up to 100,000 the scene file lists
        /// them (a file of 100,000 is 16.7 MB, near the 16 MiB a scene file may be);
        /// above, it holds their recipe, the scene file's generate section.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000), allow_negative_numbers = true)]
        count: u32,
        /// The seed of the random numbers, 0 to 9223372036854775807 (TOML's largest
        /// integer): the same seed, the same scene.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(0..=i64::MAX as u64), allow_negative_numbers = true)]
        seed: u64,
        /// Write the recipe (the generate section: spheres = N, seed = S) at any
        /// count, not the list: a small file that loads in a fraction of the time.
        #[arg(long)]
        recipe: bool,
    },
}

/// Arguments of `raystep bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub frame: FrameArgs,
    /// Threads to render with [default: one per core].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024), allow_negative_numbers = true)]
    pub threads: Option<u32>,
    /// Timed runs of each measurement, after one warm-up run.
    #[arg(long, default_value_t = 7, value_parser = clap::value_parser!(u32).range(1..=1000), allow_negative_numbers = true)]
    pub runs: u32,
    /// Skip the yardstick (the tutorial's program ported plainly).
    #[arg(long)]
    pub no_yardstick: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `raystep accuracy`.
#[derive(Args, Debug)]
pub struct AccuracyArgs {
    /// Only this stress case (a name from scenes/stress/, e.g. far-sphere).
    #[arg(long)]
    pub case: Option<String>,
    /// Print one JSON array of objects instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// The scene to render and its size.
#[derive(Args, Debug, Default)]
pub struct SceneArgs {
    /// Scene file (TOML, at most 16 MiB; - reads it from standard input). Default:
    /// the built-in figure-1 scene (scenes/seed.toml).
    pub scene: Option<PathBuf>,
    /// Image width in pixels (overrides the scene's [image] width; 1 to 16384, and
    /// at most 7680 × 4320 pixels in all: about 64 bytes of memory each).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<{ scene_file::MAX_SIDE }>)]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene's [image] height; 1 to 16384, and
    /// at most 7680 × 4320 pixels in all).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<{ scene_file::MAX_SIDE }>)]
    pub height: Option<u32>,
}

/// The choices of method the book compares. Unset ones keep raystep's defaults, or
/// with `--tutorial` the tutorial's rules.
#[derive(Args, Debug, Default)]
pub struct RuleArgs {
    /// The tutorial's program exactly: --precision f64 --intersect naive
    /// --offset fixed:1e-5 --early-stop off (flags given beside it still apply).
    #[arg(long)]
    pub tutorial: bool,
    /// Compute in float32 or float64 [default: f64].
    #[arg(long, value_enum)]
    pub precision: Option<Precision>,
    /// How rays meet spheres: the tutorial's textbook quadratic (naive) or one that
    /// does not cancel (stable) [default: stable].
    #[arg(long, value_enum)]
    pub intersect: Option<Method>,
    /// How far shadow and reflected rays start from a hit point, along the normal:
    /// auto (a bound of the rounding error, right at every scale), scene (raystep's
    /// first automatic step, 8 u of the surface's size) or fixed:VALUE (the
    /// tutorial's is fixed:1e-5; fixed:0 shows shadow acne) [default: auto].
    #[arg(long, value_name = "auto|scene|fixed:VALUE")]
    pub offset: Option<Offset>,
    /// Who views the highlight on a reflection bounce: the camera (the tutorial's
    /// rule) or the ray's origin (the surface the light travels to).
    #[arg(long, value_enum, default_value_t = Viewer::Camera)]
    pub viewer: Viewer,
    /// Most segments per pixel path (overrides the scene's render.max_depth; 1 to 64).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<{ scene_file::MAX_DEPTH }>)]
    pub max_depth: Option<u32>,
    /// Samples per pixel, a square number from 1 to 1024: stratified over an n × n
    /// grid, jittered the same way on every run [default: 1, the tutorial's one ray
    /// per pixel].
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<{ scene_file::MAX_SPP }>)]
    pub spp: Option<u32>,
    /// End a reflection path once what is left of it cannot move a channel by half
    /// an 8-bit step [default: on; off with --tutorial].
    #[arg(long, value_enum, value_name = "on|off")]
    pub early_stop: Option<Switch>,
    /// How the nearest hit is searched for; never changes a pixel: off (the plain
    /// loop over every object), auto (a BVH from 24 spheres on; with --engine fast
    /// also tile masks for primary rays), bvh (a BVH whatever the number of
    /// spheres); never a BVH with --intersect naive [default: auto].
    #[arg(long, value_enum)]
    pub accel: Option<Accel>,
    /// Which tracer renders; never changes a pixel: book (the code the chapters
    /// show, one ray at a time) or fast (four rays at a time in SIMD lanes, with
    /// tile masks and a packet walk of the BVH) [default: book; fast for bench and
    /// chart].
    #[arg(long, value_enum)]
    pub engine: Option<Engine>,
    /// Where the processor has AVX, run the fast engine's packet loop compiled
    /// for it (four float64 lanes to a register instead of two); never changes a
    /// pixel [default: on].
    #[arg(long, value_enum, value_name = "on|off")]
    pub avx: Option<Switch>,
}

/// On or off.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Switch {
    /// On.
    On,
    /// Off.
    Off,
}

/// Arguments of `raystep stages`.
#[derive(Args, Debug, Default)]
pub struct StagesArgs {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub scene: SceneArgs,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub rules: RuleArgs,
    /// Output folder; each stage goes into a numbered folder inside it.
    #[arg(long, short = 'o', visible_alias = "output", default_value = "out")]
    pub out: PathBuf,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub files: FileArgs,
    /// `render`'s flags, which `stages` does not take (hidden): given, each is
    /// refused with the command that takes it, where clap would tip `-- --stage`.
    #[arg(long, hide = true, value_name = "STAGE")]
    pub stage: Option<String>,
    /// See `stage`.
    #[arg(long, hide = true, value_name = "STAGE")]
    pub without: Vec<String>,
    /// See `stage`.
    #[arg(long, hide = true)]
    pub json: bool,
}

impl StagesArgs {
    /// Refuse `render`'s flags, each with the command that takes it.
    pub fn refuse_render_flags(&self) -> Result<(), Error> {
        let flag = if self.stage.is_some() {
            "--stage"
        } else if !self.without.is_empty() {
            "--without"
        } else if self.json {
            "--json"
        } else {
            return Ok(());
        };
        Err(Error::Usage(format!(
            "stages renders every stage, each into its own folder, and takes no {flag}; \
             `raystep render {flag} …` renders one set of stages"
        )))
    }
}

/// How the files of a render are encoded (`render`, `stages`).
#[derive(Args, Debug, Default)]
pub struct FileArgs {
    /// How beauty.png and the Blinn-Phong terms' pictures store their linear
    /// values: as they are (the tutorial's; they look dark in a viewer), or
    /// through the sRGB transfer function, with an sRGB chunk. buffers.exr is
    /// always linear.
    #[arg(long, value_enum, value_name = "srgb|linear", default_value_t = PngEncoding::Linear)]
    pub png: PngEncoding,
    /// How buffers.exr is compressed: none (the fastest to write), rle, zips (deflate,
    /// a scan line per block), zip (deflate, 16 lines) or piz (wavelets); all
    /// lossless. The README has each one's size and time at 1920 × 1080.
    #[arg(long, value_enum, value_name = "none|rle|zips|zip|piz", default_value_t = ExrCompression::None)]
    pub exr_compression: ExrCompression,
}

/// One frame to render: the scene, the stages and the rules (`render`, `bench`).
#[derive(Args, Debug)]
pub struct FrameArgs {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub scene: SceneArgs,
    /// Turn on every stage up to and including this one.
    #[arg(long, value_enum, default_value = "plane")]
    pub stage: Stage,
    /// Turn one stage off again (repeatable), e.g. --stage plane --without shadow.
    #[arg(long, value_enum)]
    pub without: Vec<Stage>,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub rules: RuleArgs,
}

/// Arguments of `raystep render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub frame: FrameArgs,
    /// Output folder.
    #[arg(long, short = 'o', visible_alias = "output", default_value = "out")]
    pub out: PathBuf,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub files: FileArgs,
    /// Print one JSON object on standard output saying what was written: the
    /// files and their sizes, the buffers, the timings and the rays traced.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `raystep check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// Scene file (TOML) to check; - reads it from standard input.
    pub scene: PathBuf,
    /// Print one JSON object instead of the report in words (it lists every
    /// object).
    #[arg(long)]
    pub json: bool,
    /// List every object in words, not only the first 20 of each kind and a count
    /// of the rest.
    #[arg(long)]
    pub all: bool,
}

/// Arguments of `raystep diff`.
#[derive(Args, Debug)]
pub struct DiffArgs {
    /// The first render's buffers.exr.
    pub a: PathBuf,
    /// The second render's buffers.exr.
    pub b: PathBuf,
    /// The tolerance of one channel, as idiff's -fail: a pixel differs when some
    /// channel of its beauty (linear, 1 = white) differs by more than this. The
    /// default is one 8-bit step, 1/255.
    #[arg(long, default_value_t = 1.0 / 255.0, value_parser = parse_threshold, allow_negative_numbers = true)]
    pub threshold: f32,
    /// The percentage of pixels that may differ before the images count as
    /// different, as idiff's -failpercent (0 to 100).
    #[arg(long, default_value_t = 0.0, value_parser = parse_percent, allow_negative_numbers = true)]
    pub fail_percent: f64,
    /// Print one JSON object instead of the report in words.
    #[arg(long)]
    pub json: bool,
}

/// A count given on the command line: any whole number a `u32` holds (whether it
/// is in range, 1 to `MAX`, is checked with the scene, in the words of the
/// scene's own checks); anything else, a negative number or a fraction, is told
/// the range.
fn whole<const MAX: u32>(text: &str) -> Result<u32, String> {
    text.trim()
        .parse::<u32>()
        .map_err(|_| format!("expected a whole number from 1 to {MAX}"))
}

/// A channel tolerance: a finite number, 0 or more.
fn parse_threshold(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(t) if t.is_finite() && t >= 0.0 => Ok(t),
        _ => Err(format!(
            "`{text}`: expected a tolerance of one channel, a number 0 or more such as 0.004"
        )),
    }
}

/// A percentage from 0 to 100.
fn parse_percent(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(p) if (0.0..=100.0).contains(&p) => Ok(p),
        _ => Err(format!("`{text}`: expected a percentage from 0 to 100")),
    }
}

/// Arguments of `raystep serve`.
#[derive(Args, Debug)]
pub struct ServeArgs {
    /// Scene file (TOML) to serve; it is watched, and saving it re-renders the
    /// page. Default: the built-in figure-1 scene (scenes/seed.toml).
    pub scene: Option<PathBuf>,
    /// The port to listen on, on 127.0.0.1 only (0: any free port; the address
    /// printed says which).
    #[arg(long, default_value_t = 8123)]
    pub port: u16,
    /// Open the page in the default browser once the server listens.
    #[arg(long)]
    pub open: bool,
}

/// Arguments of `raystep figures`.
#[derive(Args, Debug)]
pub struct FiguresArgs {
    /// Where the images go.
    #[arg(
        long,
        short = 'o',
        visible_alias = "output",
        default_value = "chapters/img"
    )]
    pub out: PathBuf,
    /// Re-render and compare with the images in --out instead of writing them.
    #[arg(long)]
    pub check: bool,
}

impl StagesArgs {
    /// `raystep` with no command: every stage of the built-in scene into `out/`.
    pub fn default_out() -> StagesArgs {
        StagesArgs {
            scene: SceneArgs::default(),
            rules: RuleArgs::default(),
            out: PathBuf::from("out"),
            files: FileArgs::default(),
            stage: None,
            without: Vec::new(),
            json: false,
        }
    }
}

impl RuleArgs {
    /// The settings for `stages` under these rules, for `scene`, whose messages
    /// name it `name`. (`--max-depth` is the scene's: the loader puts it there,
    /// [`load_scene`].)
    pub fn apply(&self, scene: &Scene, name: &str, stages: Stages) -> Result<Settings, Error> {
        let base = if self.tutorial {
            Settings::tutorial(stages)
        } else {
            Settings::from(stages)
        };
        if let Some(spp) = self.spp {
            crate::io::scene_file::check_spp(spp).map_err(Error::Usage)?;
        }
        let precision = self.precision.unwrap_or(base.precision);
        let warnings = crate::io::scene_file::check_precision(scene, precision)
            .map_err(|e| Error::Usage(format!("{name}: --precision {precision}: {e}")))?;
        for warning in warnings {
            to_stderr(format_args!(
                "warning: {name}: --precision {precision}: {warning}"
            ));
        }
        let method = self.intersect.unwrap_or(base.method);
        if self.accel == Some(Accel::Bvh) && !Accel::Bvh.builds_bvh(0, method) {
            to_stderr(format_args!(
                "warning: --accel bvh: the textbook quadratic (--intersect naive{}) gets no \
                 BVH, since its false hits far outside a sphere (chapter 9) would fall \
                 outside the boxes; every object is tested, as with --accel off",
                if self.tutorial { ", by --tutorial" } else { "" }
            ));
        }
        Ok(Settings {
            stages,
            precision,
            method,
            offset: self.offset.unwrap_or(base.offset),
            viewer: self.viewer,
            accel: self.accel.unwrap_or(base.accel),
            spp: self.spp.unwrap_or(base.spp),
            early_stop: self.early_stop.map_or(base.early_stop, |s| s == Switch::On),
            engine: self.engine.unwrap_or(base.engine),
            avx: self.avx.map_or(base.avx, |s| s == Switch::On),
        })
    }
}

/// The scene and settings a `render` (or `bench`) command line asks for.
pub fn prepare(args: &FrameArgs) -> Result<(Scene, Settings), Error> {
    let stages = Stages::select(args.stage, &args.without).map_err(Error::Usage)?;
    let (scene, name) = load_scene(&args.scene, args.rules.max_depth)?;
    let settings = args.rules.apply(&scene, &name, stages)?;
    Ok((scene, settings))
}

impl SceneArgs {
    /// Render the built-in scene at `width × height` unless a scene or a size was
    /// given.
    pub fn default_size(&mut self, width: u32, height: u32) {
        if self.scene.is_none() && self.width.is_none() && self.height.is_none() {
            (self.width, self.height) = (Some(width), Some(height));
        }
    }
}

/// The name messages give the scene of `args`: its file, or the built-in one.
pub fn scene_name(args: &SceneArgs) -> String {
    match &args.scene {
        Some(path) => scene_file::display_name(path),
        None => scene_file::SEED_NAME.to_string(),
    }
}

/// Load the scene named by `args` (or the built-in one) and apply the size flags
/// and `max_depth` (`--max-depth`, which then replaces the file's
/// `render.max_depth` unchecked, as `--width` replaces `image.width`).
pub fn load_scene(args: &SceneArgs, max_depth: Option<u32>) -> Result<(Scene, String), Error> {
    let size = Overrides {
        width: args.width,
        height: args.height,
        max_depth,
    };
    let scene = match &args.scene {
        Some(path) => scene_file::load_sized(path, size)?,
        None => scene_file::parse_sized(scene_file::SEED_TOML, scene_file::SEED_NAME, size)?,
    };
    let name = scene_name(args);
    warn_if_unlikely(&scene, &name);
    Ok((scene, name))
}

/// `v` to four decimal places, without trailing zeros: 2, 0.5334, 133334.6667.
fn four_places(v: f64) -> String {
    format!("{}", (v * 1e4).round() / 1e4)
}

/// A `[screen]` whose shape is not the image's: valid (chapter 2's second
/// exercise makes one), but the pixels are not square and the picture comes out
/// stretched, which a reader should hear of. Shapes within 1 % of each other pass.
fn warn_if_stretched(scene: &Scene, name: &str) {
    let Some(screen) = scene.screen else {
        return;
    };
    let across = (screen.right - screen.left) / f64::from(scene.width);
    let up = (screen.top - screen.bottom) / f64::from(scene.height);
    if (up / across - 1.0).abs() > 0.01 {
        to_stderr(format_args!(
            "warning: {name}: the screen, {} × {}, is not the shape of the image, {} × {} \
             pixels: the pixels are not square, so the picture comes out stretched (a \
             [screen] of the image's shape, or none, keeps them square)",
            four_places(screen.right - screen.left),
            four_places(screen.top - screen.bottom),
            scene.width,
            scene.height
        ));
    }
}

/// What a valid scene may hold that was almost surely not meant, said as
/// warnings (every command that loads a scene says them): no objects, or
/// pixels that are not square.
pub fn warn_if_unlikely(scene: &Scene, name: &str) {
    warn_if_empty(scene, name);
    warn_if_stretched(scene, name);
}

/// A scene without objects is valid, but almost surely not what was meant.
fn warn_if_empty(scene: &Scene, name: &str) {
    if scene.objects.is_empty() {
        to_stderr(format_args!(
            "warning: {name}: the scene has no [[sphere]] and no [[plane]], so every ray \
             misses and the image is black"
        ));
    }
}

/// Refuse a `--pixel` outside the image of `scene`.
pub fn check_pixel(scene: &Scene, x: u32, y: u32) -> Result<(), Error> {
    if x >= scene.width || y >= scene.height {
        return Err(Error::Usage(format!(
            "--pixel {x},{y} is outside the {} × {} image: x runs from 0 to {} and y from 0 to {}",
            scene.width,
            scene.height,
            scene.width - 1,
            scene.height - 1
        )));
    }
    Ok(())
}
