//! The command line: parse the arguments, call the library, report what was written.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{CommandFactory, Parser};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::aov::Frame;
use crate::engine::{render, render_into};
use crate::error::Error;
use crate::io::output::Pending;
use crate::io::scene_file;
use crate::render::Settings;
use crate::scene::{Role, Scene, Shape};
use crate::stages::{Engine, Stage, Stages};
use crate::tools::args::{
    check_pixel, load_scene, prepare, scene_name, warn_if_unlikely, AccuracyArgs, BenchArgs,
    ChartArgs, CheckArgs, Cli, Command, DiffArgs, ExplainArgs, FiguresArgs, Generated, RenderArgs,
    StagesArgs,
};
use crate::tools::json::{json_text, scene_json};

/// Print a line on stdout, returning from the function with an error if it
/// cannot be written ([`say_line`]).
macro_rules! say {
    ($($arg:tt)*) => {
        say_line(format_args!($($arg)*))?
    };
}

/// Print a status line on standard error (what is being done, what was written),
/// unless `-q/--quiet` was given. Standard output is for what a command produces.
macro_rules! status {
    ($($arg:tt)*) => {
        status_line(format_args!($($arg)*))
    };
}

/// Set by `-q/--quiet`: no status lines and no progress bar.
static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

fn quiet() -> bool {
    QUIET.load(std::sync::atomic::Ordering::Relaxed)
}

/// Write a status line to standard error, unless quiet. A status line that
/// cannot be written is not an error: the work it reports on is done.
fn status_line(text: std::fmt::Arguments) {
    if !quiet() {
        crate::error::to_stderr(text);
    }
}

/// Print `value` (an object) as JSON on standard output, with `"schema": 1`.
fn say_json(value: serde_json::Value, pretty: bool) -> Result<(), Error> {
    say_line(format_args!("{}", json_text(&value, pretty)))
}

/// Write `text` and a newline to standard output. A closed pipe (`raystep ... |
/// head -1`) ends the output quietly, as the reader has stopped reading; any other
/// failure (a full disk, `> /dev/full`) is an error, so that a command whose
/// output was lost or cut never exits 0.
fn say_line(text: std::fmt::Arguments) -> Result<(), Error> {
    write_stdout(format!("{text}\n").as_bytes())
}

/// Start the threads renders run on (rayon's global pool: as many as the machine
/// has cores, or `RAYON_NUM_THREADS`).
fn start_threads() -> Result<(), Error> {
    rayon::ThreadPoolBuilder::new().build_global().map_err(|e| {
        let asked = std::env::var("RAYON_NUM_THREADS").map_or_else(
            |_| "one per core".to_string(),
            |n| format!("RAYON_NUM_THREADS={n}"),
        );
        Error::Usage(format!(
            "cannot start the threads to render with ({asked}): {e}; set RAYON_NUM_THREADS \
             to fewer, or allow the process more memory"
        ))
    })
}

/// Write `bytes` to standard output, by the rules of [`say_line`].
fn write_stdout(bytes: &[u8]) -> Result<(), Error> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Error::Output {
            path: "standard output".into(),
            message: e.to_string(),
        }),
        _ => Ok(()),
    }
}

/// Carry out a parsed command line.
pub fn run(cli: Cli) -> Result<(), Error> {
    execute(cli).map(|_| ())
}

/// The exit code of `raystep diff` for images that differ beyond the threshold
/// (as diff, cmp and idiff: 0 the same, 1 different, 2 trouble).
pub const DIFFERENT: u8 = 1;

/// Carry out a parsed command line and return the exit code of a command done:
/// 0, or [`DIFFERENT`] for a `diff` of images that differ.
pub fn execute(cli: Cli) -> Result<u8, Error> {
    QUIET.store(cli.quiet, std::sync::atomic::Ordering::Relaxed);
    // The commands that render start their threads first, so that a machine that
    // cannot give them (RAYON_NUM_THREADS=200 under a memory limit) gets a message
    // instead of a panic inside rayon. bench builds its own pools, with the same
    // care; check, diff, generate, completions and man need none.
    if !matches!(
        cli.command,
        Some(
            Command::Check(_)
                | Command::Diff(_)
                | Command::Generate(_)
                | Command::Bench(_)
                | Command::Completions { .. }
                | Command::Man { .. }
        )
    ) {
        start_threads()?;
    }
    if let Some(Command::Diff(args)) = &cli.command {
        return diff(args);
    }
    match cli.command {
        None => stages(StagesArgs::default_out()),
        Some(Command::Stages(args)) => stages(args),
        Some(Command::Render(args)) => render_one(args),
        Some(Command::Explain(args)) => explain(&args),
        Some(Command::Check(args)) => check(&args),
        Some(Command::Diff(_)) => unreachable!("diff returns its own exit code above"),
        Some(Command::Figures(args)) => figures(&args),
        Some(Command::Accuracy(args)) => accuracy(&args),
        Some(Command::Bench(args)) => bench(args),
        Some(Command::Chart(args)) => chart(args),
        Some(Command::Serve(args)) => crate::tools::serve::run(&args, quiet()),
        Some(Command::Generate(args)) => match args.what {
            Generated::Spheres {
                count,
                seed,
                recipe,
            } => {
                use crate::tools::generate::{recipe_toml, spheres_toml, MAX_LISTED};
                let count = count as usize;
                let text = if recipe || count > MAX_LISTED {
                    if !recipe {
                        status!(
                            "more than {MAX_LISTED} spheres: the scene holds their recipe, \
                             [generate] spheres = {count}, seed = {seed}, not their list"
                        );
                    }
                    recipe_toml(count, seed)
                } else {
                    spheres_toml(count, seed)
                };
                write_stdout(text.as_bytes())
            }
        },
        Some(Command::Completions { shell }) => {
            let mut text = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "raystep", &mut text);
            write_stdout(&text)
        }
        Some(Command::Man { command }) => {
            let text = man_page(command.as_deref()).map_err(|e| Error::Output {
                path: "the manual page".into(),
                message: e.to_string(),
            })?;
            write_stdout(&text)
        }
    }
    .map(|()| 0)
}

/// The manual page of raystep, or of `command` (`raystep-render(1)`, as raystep's
/// page lists it), in roff.
fn man_page(command: Option<&str>) -> std::io::Result<Vec<u8>> {
    // `raystep help` has no page: the pages are the help.
    let mut cli = Cli::command().disable_help_subcommand(true);
    cli.build();
    let page = match command {
        None => cli,
        // `generate-spheres`: `spheres` under `generate`.
        Some(name) => (name.split('-'))
            .try_fold(cli, |command, word| command.find_subcommand(word).cloned())
            .expect("COMMANDS names raystep's commands")
            // (clap keeps a name for as long as the program runs, and this one
            // ends once the page is printed.)
            .name(&*format!("raystep-{name}").leak())
            .version(env!("CARGO_PKG_VERSION")),
    };
    let limits = page.get_after_help().map(|text| text.to_string());
    let man = clap_mangen::Man::new(page.clone().after_help(None::<&str>));
    let mut sections = vec![
        render_with(|w| man.render_title(w))?,
        render_with(|w| man.render_name_section(w))?,
        render_with(|w| man.render_synopsis_section(w))?,
        render_with(|w| man.render_description_section(w))?,
        render_with(|w| man.render_options_section(w))?,
    ];
    if page.has_subcommands() {
        sections.push(render_with(|w| man.render_subcommands_section(w))?);
    }
    // The limits are a table: written without filling (`.nf`), where clap_mangen
    // would run its lines together.
    if let Some(limits) = limits {
        let mut roff = String::from(".SH \"LIMITS AND EXIT CODES\"\n.nf\n");
        for line in limits.lines() {
            let line = line.replace('\\', "\\e").replace('-', "\\-");
            let guard = if line.starts_with(['.', '\'']) {
                "\\&"
            } else {
                ""
            };
            roff += &format!("{guard}{line}\n");
        }
        sections.push(roff + ".fi\n");
    }
    sections.push(render_with(|w| man.render_version_section(w))?);
    // Each section rendered alone starts with the same two lines of set-up
    // (`.ie`, `.el`): kept once, at the top.
    let mut out = String::new();
    for (k, section) in sections.iter().enumerate() {
        for line in section.lines() {
            if k == 0 || !(line.starts_with(".ie ") || line.starts_with(".el ")) {
                out += line;
                out.push('\n');
            }
        }
    }
    Ok(out.into_bytes())
}

/// What `render` writes, as text.
fn render_with(
    render: impl FnOnce(&mut Vec<u8>) -> std::io::Result<()>,
) -> std::io::Result<String> {
    let mut bytes = Vec::new();
    render(&mut bytes)?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// The contact sheet `raystep stages` writes: a row per stage, a column per buffer.
pub const CONTACT_SHEET: &str = "contact-sheet.png";

fn stages(args: StagesArgs) -> Result<(), Error> {
    args.refuse_render_flags()?;
    let (scene, name) = load_scene(&args.scene, args.rules.max_depth)?;
    let base = args.rules.apply(&scene, &name, Stages::ALL)?;
    // Every file of every stage is renamed into place at the end, together: an
    // error or Ctrl-C on the way leaves the folder as it was.
    let mut pending = Pending::new()
        .with_png(args.files.png)
        .with_exr(args.files.exr_compression);
    pending.folder(&args.out)?;
    // The stage folders are raystep's own names: a link or a file at one is
    // refused now, before anything is rendered.
    for stage in Stage::ALL {
        let dir = args.out.join(stage.folder());
        crate::io::output::check_own_folder(&dir)?;
        let stages = Stages::up_to(stage);
        crate::io::output::check_final_names(&crate::io::output::frame_files(&dir, stages))?;
    }
    status!(
        "{name}: every stage at {} × {}, {} engine",
        scene.width,
        scene.height,
        base.engine
    );
    let bar = job_bar(u64::from(scene.height) * Stage::ALL.len() as u64);
    let start = Instant::now();
    let mut page = Vec::new(); // a row of index.html per stage
    let mut sheet = crate::io::contact::ContactSheet::new(crate::io::contact::THUMBNAIL_WIDTH)
        .with_png(args.files.png);
    // One frame for the six stages, each rendered over the last: a fresh frame
    // of 108 MB at 1920 × 1080 costs the kernel about 22 ms to map on two threads.
    let mut frame = Frame::blank(scene.camera(), base.precision);
    for stage in Stage::ALL {
        bar.set_message(format!("rendering {}", stage.folder()));
        let dir = args.out.join(stage.folder());
        let settings = Settings {
            stages: Stages::up_to(stage),
            ..base
        };
        let ((), seconds) = timed(|| render_into(&scene, &settings, &mut frame, &|n| bar.inc(n)));
        crate::error::check_interrupt()?;
        pending.folder(&dir)?;
        write(&mut pending, &frame, &dir, seconds, &bar)?;
        // The numbers behind the pictures, for the page (up to a size).
        if crate::io::page::has_numbers(scene.width, scene.height) {
            crate::io::page::write_pixels(&mut pending, &dir, &stage.folder(), &frame)?;
        } else {
            pending.remove_on_commit(&dir.join(crate::io::page::PIXELS_FILE));
        }
        let label = stage.label();
        sheet.add_row(&label, &frame);
        page.push(crate::io::page::PageStage {
            folder: stage.folder(),
            label,
            buffers: frame.buffers().map(|b| b.name().to_string()).collect(),
        });
    }
    drop(frame);
    bar.set_message("writing the page");
    let contact = args.out.join(CONTACT_SHEET);
    pending.file(&contact, &sheet.png())?;
    let index = crate::io::page::write_index(
        &mut pending,
        &args.out,
        &name,
        scene.width,
        scene.height,
        &page,
    )?;
    pending.commit()?;
    bar.finish_and_clear();
    status!(
        "wrote {} stages into {} in {:.2} s",
        Stage::ALL.len(),
        folder(&args.out),
        start.elapsed().as_secs_f64()
    );
    status!(
        "open {} to look through every stage and buffer ({} has them on one sheet)",
        index.display(),
        contact.display()
    );
    Ok(())
}

fn explain(args: &ExplainArgs) -> Result<(), Error> {
    let (scene, settings) = prepare(&args.frame)?;
    let (x, y) = args.pixel;
    check_pixel(&scene, x, y)?;
    if settings.engine == Engine::Fast {
        status!(
            "explain follows the book's tracer one ray at a time; --engine fast gives the \
             same bits, so this is its story too"
        );
    }
    let story = crate::tools::explain::explain(&scene, &settings, x, y);
    if args.json {
        say!("{}", json_text(&story, true));
    } else {
        say!(
            "{}: {} × {}",
            scene_name(&args.frame.scene),
            scene.width,
            scene.height
        );
        say!("{story}");
    }
    Ok(())
}

fn render_one(args: RenderArgs) -> Result<(), Error> {
    let start = Instant::now();
    let (scene, settings) = prepare(&args.frame)?;
    let mut pending = Pending::new()
        .with_png(args.files.png)
        .with_exr(args.files.exr_compression);
    pending.folder(&args.out)?;
    crate::io::output::check_final_names(&crate::io::output::frame_files(
        &args.out,
        settings.stages,
    ))?;
    let name = scene_name(&args.frame.scene);
    status!(
        "{name}: {} at {} × {}, {} engine",
        settings.stages,
        scene.width,
        scene.height,
        settings.engine
    );
    let bar = job_bar(u64::from(scene.height));
    bar.set_message("rendering");
    let (frame, seconds) = timed(|| render(&scene, &settings, &|n| bar.inc(n)));
    crate::error::check_interrupt()?;
    let (written, write_seconds) = write(&mut pending, &frame, &args.out, seconds, &bar)?;
    bar.finish_and_clear();
    pending.commit()?;
    if args.json {
        let files: Vec<serde_json::Value> = written
            .iter()
            .map(|path| {
                let bytes = std::fs::metadata(path).map(|m| m.len()).ok();
                serde_json::json!({ "path": path.display().to_string(), "bytes": bytes })
            })
            .collect();
        let buffers: Vec<&str> = frame.buffers().map(|b| b.name()).collect();
        say_json(
            serde_json::json!({
                "scene": name,
                "width": scene.width,
                "height": scene.height,
                "stages": settings.stages.to_string(),
                "engine": settings.engine.to_string(),
                "precision": settings.precision.to_string(),
                "spp": settings.spp,
                "out": args.out.display().to_string(),
                "files": files,
                "buffers": buffers,
                "seconds": {
                    "render": seconds,
                    "write": write_seconds,
                    "total": start.elapsed().as_secs_f64(),
                },
                "rays": {
                    "primary": frame.rays.primary,
                    "shadow": frame.rays.shadow,
                    "reflection": frame.rays.reflection,
                    "total": frame.rays.total(),
                },
                "peak_memory_bytes": crate::tools::bench::peak_memory_bytes(),
            }),
            true,
        )?;
    }
    Ok(())
}

/// Write the files of `frame` into `pending` (the bar's phase: writing files) and
/// say which, with the times; the paths written and the seconds it took.
fn write(
    pending: &mut Pending,
    frame: &Frame,
    dir: &Path,
    render_seconds: f64,
    bar: &ProgressBar,
) -> Result<(Vec<PathBuf>, f64), Error> {
    let phase = bar.message().replace("rendering", "writing files");
    bar.set_message(phase);
    let (written, write_seconds) = timed(|| pending.frame_counted(frame, dir, &|n| bar.inc(n)));
    let written = written?;
    let names: Vec<String> = written
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    bar.suspend(|| {
        status!(
            "  {:<28} {}   render {:.3} s, write {:.3} s",
            folder(dir),
            names.join(" "),
            render_seconds,
            write_seconds
        );
    });
    Ok((written, write_seconds))
}

fn bench(mut args: BenchArgs) -> Result<(), Error> {
    args.frame.scene.default_size(1920, 1080);
    // bench measures speed: the fast engine unless the book's is asked for.
    args.frame.rules.engine.get_or_insert(Engine::Fast);
    let (scene, settings) = prepare(&args.frame)?;
    let name = scene_name(&args.frame.scene);
    let threads = args
        .threads
        .map_or_else(rayon::current_num_threads, |t| t as usize);
    let options = crate::tools::bench::Options {
        runs: args.runs as usize,
        threads,
        yardstick: !args.no_yardstick,
    };
    status!("{name}: {}", settings.stages);
    let bar = counted_bar(u64::from(args.runs) + 1, "bench", "runs");
    let report = crate::tools::bench::bench(&scene, &settings, options, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    crate::error::check_interrupt()?;
    if args.json {
        say!("{}", json_text(&report, false));
    } else {
        say!("{}", report.text().trim_end());
    }
    Ok(())
}

fn chart(mut args: ChartArgs) -> Result<(), Error> {
    // --scale: the image size and the sphere counts charted (powers of ten and
    // their triples up to --max-count), refused before anything is made if the
    // largest scene would not fit in memory.
    let size = (
        args.scene.width.unwrap_or(1920),
        args.scene.height.unwrap_or(1080),
    );
    let counts: Vec<usize> = (0..8)
        .flat_map(|e| [10usize.pow(e), 3 * 10usize.pow(e)])
        .filter(|&n| n as u64 <= args.max_count)
        .collect();
    if args.scale {
        check_scale_memory(counts.last().copied().unwrap_or(1), size)?;
    }
    let mut pending = Pending::new();
    pending.folder(&args.out)?;
    let runs = args.runs as usize;
    if args.scale && args.scene.scene.is_some() {
        return Err(Error::Usage(
            "--scale charts generated scenes of N spheres; it takes no scene file".into(),
        ));
    }
    if args.scale {
        crate::io::scene_file::check_image_size((size.0, "--width"), (size.1, "--height"))
            .map_err(Error::Usage)?;
        let plain_up_to = 300;
        let renders: u64 = counts
            .iter()
            .map(|&n| if n <= plain_up_to { 2 } else { 1 } * (args.runs as u64 + 1))
            .sum::<u64>()
            + if args.embree.is_some() {
                counts.len() as u64
            } else {
                0
            };
        status!(
            "time against spheres at {} × {}: {} counts",
            size.0,
            size.1,
            counts.len()
        );
        let bar = counted_bar(renders, "scale", "renders");
        let embree = args.embree.as_deref();
        let points =
            crate::tools::chart::scale(&counts, plain_up_to, size, runs, embree, &|n| bar.inc(n))?;
        bar.finish_and_clear();
        crate::error::check_interrupt()?;
        let csv = crate::tools::chart::scale_csv(&points);
        pending.file(&args.out.join("scale.csv"), csv.as_bytes())?;
        let title = format!("Time against spheres, {} × {}, every stage", size.0, size.1);
        let files =
            crate::tools::chart::write_scale(&mut pending, &args.out, "scale", &points, &title)?;
        pending.commit()?;
        say!("{}", csv.trim_end());
        let csv = args.out.join("scale.csv");
        status!("wrote {}, {}", csv.display(), names(&files));
        return Ok(());
    }
    args.scene.default_size(960, 540);
    let (scene, name) = load_scene(&args.scene, None)?;
    status!(
        "{name}: speed against accuracy at {} × {}",
        scene.width,
        scene.height
    );
    let bar = counted_bar(crate::tools::chart::sweep_renders(runs), "chart", "renders");
    let points = crate::tools::chart::sweep(&scene, runs, &|n| bar.inc(n));
    bar.finish_and_clear();
    crate::error::check_interrupt()?;
    let csv = crate::tools::chart::csv(&points);
    pending.file(&args.out.join("chart.csv"), csv.as_bytes())?;
    let title = format!(
        "Speed against accuracy: {name}, {} × {}",
        scene.width, scene.height
    );
    let files =
        crate::tools::chart::write_sweep(&mut pending, &args.out, "chart", &points, &title)?;
    pending.commit()?;
    say!("{}", csv.trim_end());
    let csv = args.out.join("chart.csv");
    status!("wrote {}, {}", csv.display(), names(&files));
    Ok(())
}

/// A folder as status lines name it: with one `/` at the end, whether or not
/// it was given with one.
fn folder(dir: &Path) -> String {
    let shown = dir.display().to_string();
    match shown.ends_with('/') {
        true => shown,
        false => shown + "/",
    }
}

fn names(files: &[PathBuf]) -> String {
    files
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let value = f();
    (value, start.elapsed().as_secs_f64())
}

/// One bar on stderr for a whole job that renders `rows` rows in all (a frame's
/// height, or the six stages' heights): each row counts twice, once traced and
/// once written to every file, so the bar goes on through the writing. Its phase
/// is named in the message ("rendering", "writing files") and the bar shows the
/// share done; it ticks on its own, so that a long write does not look stalled.
fn job_bar(rows: u64) -> ProgressBar {
    // As wide as the longest phase, "writing files 02-intersection", so that the
    // bar stays where it is from phase to phase.
    let widest = Stage::ALL
        .iter()
        .map(|s| s.folder().len())
        .max()
        .unwrap_or(0);
    let label = format!("{{msg:<{}}}", "writing files ".len() + widest);
    let bar = styled_bar(2 * rows, &format!("{label} [{{bar:30}}] {{percent:>3}} %"));
    bar.enable_steady_tick(std::time::Duration::from_millis(250));
    bar
}

/// A bar on stderr counting `len` `unit`s after `label`, drawn only when stderr is
/// a terminal and not `--quiet`.
fn counted_bar(len: u64, label: &str, unit: &str) -> ProgressBar {
    styled_bar(len, &format!("{label} [{{bar:30}}] {{pos}}/{{len}} {unit}"))
}

/// A bar on stderr of `len` steps drawn as `shown` followed by the time spent and
/// the time left, only when stderr is a terminal and not `--quiet`. The time left
/// shows only once 5 % is done and half a second has passed: a first guess from
/// the first rows is far off.
fn styled_bar(len: u64, shown: &str) -> ProgressBar {
    let target = if quiet() {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    };
    let bar = ProgressBar::with_draw_target(Some(len), target);
    let template = format!("{shown}, {{elapsed}}{{left}}");
    let left = |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
        let done = state.fraction();
        if (0.05..1.0).contains(&done) && state.elapsed().as_secs_f64() >= 0.5 {
            let _ = write!(w, ", {:#} left", indicatif::HumanDuration(state.eta()));
        }
    };
    bar.set_style(
        ProgressStyle::with_template(&template)
            .expect("the template is valid")
            .with_key("left", left)
            .progress_chars("=> "),
    );
    bar
}

/// Bytes of memory `chart --scale` takes per sphere of its largest scene, at its
/// peak: the generated scene, the objects in play, the BVH and the records of the
/// frame beside them. Measured: `/usr/bin/time -f "%M KB" raystep chart --scale
/// --max-count 1000000 --runs 1 --width 64 --height 36` peaked at 754 MB, against
/// 81 MB for 100,000 spheres (about 750 bytes per sphere).
pub const SCALE_BYTES_PER_SPHERE: u64 = 750;

/// Refuse a `chart --scale` whose largest scene, of `spheres`, would need more
/// memory than raystep's largest render (the image limit's 2.1 GB), with the figure.
fn check_scale_memory(spheres: usize, (width, height): (u32, u32)) -> Result<(), Error> {
    use crate::io::scene_file::{MAX_PIXELS, PEAK_BYTES_PER_PIXEL};
    let budget = MAX_PIXELS * PEAK_BYTES_PER_PIXEL;
    let pixels = u64::from(width) * u64::from(height);
    let need = spheres as u64 * SCALE_BYTES_PER_SPHERE + pixels * PEAK_BYTES_PER_PIXEL;
    if need > budget {
        return Err(Error::Usage(format!(
            "--max-count: a chart up to {spheres} spheres at {width} × {height} would need \
             about {:.1} GB of memory (about {SCALE_BYTES_PER_SPHERE} bytes per sphere and \
             {PEAK_BYTES_PER_PIXEL} per pixel); raystep takes at most {:.1} GB, the memory \
             of its largest render: give a smaller --max-count",
            need as f64 / 1e9,
            budget as f64 / 1e9
        )));
    }
    Ok(())
}

fn diff(args: &DiffArgs) -> Result<u8, Error> {
    let (wa, ha, a) = crate::tools::compare::read_beauty(&args.a)?;
    let (wb, hb, b) = crate::tools::compare::read_beauty(&args.b)?;
    if (wa, ha) != (wb, hb) {
        return Err(Error::Usage(format!(
            "{} is {wa} × {ha} but {} is {wb} × {hb}: only renders of one size compare",
            args.a.display(),
            args.b.display()
        )));
    }
    let d = crate::tools::compare::compare(&a, &b, wa);
    let over = crate::tools::compare::pixels_over(&a, &b, args.threshold);
    let percent = 100.0 * over as f64 / d.pixels.max(1) as f64;
    let different = percent > args.fail_percent;
    let code = if different { DIFFERENT } else { 0 };
    if args.json {
        say_json(
            serde_json::json!({
                "a": args.a.display().to_string(),
                "b": args.b.display().to_string(),
                "width": wa,
                "height": ha,
                "pixels": d.pixels,
                "threshold": args.threshold,
                "fail_percent": args.fail_percent,
                "over_threshold": over,
                "over_threshold_percent": percent,
                "over_one_step": d.over_one_step,
                "largest": finite_or_null(f64::from(d.largest)),
                "largest_at": { "row": d.largest_at.0, "column": d.largest_at.1 },
                "rmse": d.rmse,
                "clipped": [d.saturated.0, d.saturated.1],
                "non_finite": [d.non_finite.0, d.non_finite.1],
                "different": different,
            }),
            true,
        )?;
        return Ok(code);
    }
    say!(
        "{} against {}: {wa} × {ha} pixels",
        args.a.display(),
        args.b.display()
    );
    say!(
        "  differ by more than 1/255: {} pixels ({:.2} %)",
        d.over_one_step,
        100.0 * d.over_one_step as f64 / d.pixels as f64
    );
    match d.largest > 0.0 {
        true => say!(
            "  largest difference:        {:.4} (row {}, column {})",
            d.largest,
            d.largest_at.0,
            d.largest_at.1
        ),
        // Where the largest of no differences lies would mean nothing.
        false => say!("  largest difference:        0 (the images are the same)"),
    }
    say!("  root mean square:          {:.6}", d.rmse);
    say!(
        "  clipped (a channel at 1):  {} and {} pixels",
        d.saturated.0,
        d.saturated.1
    );
    if d.non_finite != (0, 0) {
        say!(
            "  not finite (inf or NaN):   {} and {} pixels (a pixel finite in one file and \
             not in the other differs; the root mean square is over channels finite in both)",
            d.non_finite.0,
            d.non_finite.1
        );
    }
    say!(
        "  {}: {over} pixels ({percent:.2} %) differ by more than {:.6} (--threshold), {} \
         {:.2} % (--fail-percent)",
        if different { "different" } else { "the same" },
        args.threshold,
        if different { "more than" } else { "at most" },
        args.fail_percent
    );
    Ok(code)
}

/// `x` as a JSON number, or null where it is infinite or NaN (which JSON lacks).
fn finite_or_null(x: f64) -> serde_json::Value {
    if x.is_finite() {
        x.into()
    } else {
        serde_json::Value::Null
    }
}

fn accuracy(args: &AccuracyArgs) -> Result<(), Error> {
    use crate::tools::accuracy::{measure_all, CASES};
    if let Some(case) = &args.case {
        if !CASES.iter().any(|(n, _)| n == case) {
            let names: Vec<&str> = CASES.iter().map(|(n, _)| *n).collect();
            return Err(Error::Usage(format!(
                "--case {case}: no such stress case; the cases are {}",
                names.join(", ")
            )));
        }
    }
    let rows = match &args.case {
        Some(case) => crate::tools::accuracy::measure_case(case),
        None => measure_all(),
    };
    if args.json {
        // An array, as before: each row carries the schema.
        let rows: Vec<serde_json::Value> = rows
            .iter()
            .map(|row| serde_json::from_str(&json_text(row, false)).expect("valid JSON"))
            .collect();
        say!(
            "{}",
            serde_json::to_string_pretty(&rows).expect("plain data serialises")
        );
        return Ok(());
    }
    say!("{}", crate::tools::accuracy::table_header());
    for m in &rows {
        say!("{}", crate::tools::accuracy::table_row(m));
    }
    Ok(())
}

fn figures(args: &FiguresArgs) -> Result<(), Error> {
    let root = Path::new(".");
    // The figures' commands name the repository's scenes (scenes/seed.toml, ...).
    if !root.join("scenes").is_dir() || !root.join("chapters").is_dir() {
        return Err(Error::Usage(
            "figures renders the book's pictures from the repository's scenes/ into its \
             chapters/img/: run it in the root of a raystep checkout (no scenes/ and \
             chapters/ here)"
                .into(),
        ));
    }
    if args.check {
        let problems = crate::tools::figures::check_all(root, &args.out, &render_command)?;
        if problems.is_empty() {
            say!(
                "every figure in {} is what raystep renders now",
                args.out.display()
            );
            return Ok(());
        }
        return Err(Error::Usage(format!(
            "{} figure problems; run `raystep figures` to re-render:\n  {}",
            problems.len(),
            problems.join("\n  ")
        )));
    }
    let written = crate::tools::figures::write_all(root, &args.out, &render_command)?;
    status!("wrote {} figures into {}", written.len(), folder(&args.out));
    Ok(())
}

fn check(args: &CheckArgs) -> Result<(), Error> {
    let path = &args.scene;
    let name = scene_file::display_name(path);
    let scene = scene_file::load(path)?;
    warn_if_unlikely(&scene, &name);
    if args.json {
        return say_json(scene_json(&scene, &name, true), true);
    }
    let listed = (!args.all).then_some(LISTED);
    say!("{}", describe(&scene, &name, listed).trim_end());
    Ok(())
}

/// How many spheres (and planes) `raystep check` lists in words before it counts
/// the rest: a generated scene of a million would print two million lines.
pub const LISTED: usize = 20;

/// A readable summary of a checked scene, as `raystep check` prints it: every
/// object, or with `listed = Some(n)` the first `n` of each kind and a line that
/// counts the others. Objects are numbered from 0, spheres first, as
/// `explain`, the studio and the `object` buffer number them.
pub fn describe(scene: &Scene, name: &str, listed: Option<usize>) -> String {
    let mut out = format!("{name}: a valid scene\n");
    let cam = scene.camera();
    let s = cam.screen;
    let screen_source = if scene.screen.is_some() {
        "set by the scene"
    } else {
        "default, from the image's ratio"
    };
    out += &format!(
        "  image    {} × {} pixels, max_depth {}\n",
        scene.width, scene.height, scene.max_depth
    );
    out += &format!("  camera   at {}\n", scene.camera);
    out += &format!(
        "  screen   z = 0, left {}, right {}, top {:.4}, bottom {:.4} ({screen_source})\n",
        s.left, s.right, s.top, s.bottom
    );
    let l = &scene.light;
    out += &format!(
        "  light    at {}; ambient {}, diffuse {}, specular {}\n",
        l.position, l.ambient, l.diffuse, l.specular
    );
    // Each object under the number explain, the studio and the `object` buffer
    // give it: its index among the scene's objects, spheres first.
    for role in [Role::Sphere, Role::Floor] {
        let objects: Vec<_> = (scene.objects.iter().enumerate())
            .filter(|(_, o)| o.role == role)
            .collect();
        let heading = match role {
            Role::Sphere => "spheres:",
            Role::Floor => "planes: ",
        };
        let note = match role {
            Role::Floor if !objects.is_empty() => " (drawn from the plane stage on)",
            _ => "",
        };
        out += &format!("  {heading} {}{note}\n", objects.len());
        let shown = listed.unwrap_or(usize::MAX).min(objects.len());
        for &(id, o) in objects.iter().take(shown) {
            let shape = match o.shape {
                Shape::Sphere(sp) => format!("sphere at {}, radius {}", sp.center, sp.radius),
                Shape::Plane(p) => format!("true plane through {}, normal {}", p.point, p.normal),
            };
            let m = &o.material;
            out += &format!(
                "    object {id}: {shape}\n      ambient {}, diffuse {}, specular {}, shininess {}, reflection {}\n",
                m.ambient,
                m.diffuse,
                m.specular,
                m.shininess,
                m.reflection
            );
        }
        if shown < objects.len() {
            out += &format!(
                "    … and {} more (raystep check --all lists every one, --json too)\n",
                objects.len() - shown
            );
        }
    }
    out
}

/// The frame that `raystep ARGS` renders, for a `render` command; scene paths in
/// `args` are relative to `root`.
pub fn render_command(args: &str, root: &Path) -> Result<Frame, Error> {
    let words = std::iter::once("raystep").chain(args.split_whitespace());
    let cli =
        Cli::try_parse_from(words).map_err(|e| Error::Usage(format!("`raystep {args}`: {e}")))?;
    let Some(Command::Render(mut render)) = cli.command else {
        return Err(Error::Usage(format!(
            "`raystep {args}` is not a render command"
        )));
    };
    render.frame.scene.scene = render.frame.scene.scene.map(|p| root.join(p));
    let (scene, settings) = prepare(&render.frame)?;
    Ok(crate::render::render(&scene, &settings, &|_| {}))
}
