//! The command line: parse the arguments, call the library, report what was written.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::aov::Frame;
use crate::error::Error;
use crate::render::render;
use crate::scene::{Role, Scene, Shape};
use crate::scene_file::{self, check_image_size};
use crate::stages::{Stage, Stages};

/// raystep: a ray tracer that teaches ray tracing one step at a time.
///
/// With no command, renders every stage of the built-in figure-1 scene into `out/`
/// (the same as `raystep stages`).
#[derive(Parser, Debug)]
#[command(name = "raystep", version, about, long_about)]
pub struct Cli {
    /// What to do (default: `stages` on the built-in scene).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render every stage, rays to plane, each into DIR/<NN>-<stage>/ with its buffers.
    Stages(StagesArgs),
    /// Render one set of stages into DIR/: beauty, buffers as PNG, and buffers.exr.
    Render(RenderArgs),
    /// Check a scene file and print what it contains.
    Check(CheckArgs),
}

/// The scene to render and its size.
#[derive(Args, Debug, Default)]
pub struct SceneArgs {
    /// Scene file (TOML). Default: the built-in figure-1 scene (scenes/seed.toml).
    pub scene: Option<PathBuf>,
    /// Image width in pixels (overrides the scene's [image] width; 1 to 16384).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene's [image] height; 1 to 16384).
    #[arg(long)]
    pub height: Option<u32>,
}

/// Arguments of `raystep stages`.
#[derive(Args, Debug, Default)]
pub struct StagesArgs {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub scene: SceneArgs,
    /// Output folder; each stage goes into a numbered folder inside it.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
}

/// Arguments of `raystep render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub scene: SceneArgs,
    /// Turn on every stage up to and including this one.
    #[arg(long, value_enum, default_value = "plane")]
    pub stage: Stage,
    /// Turn one stage off again (repeatable), e.g. --stage plane --without shadow.
    #[arg(long, value_enum)]
    pub without: Vec<Stage>,
    /// Output folder.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
}

/// Arguments of `raystep check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// Scene file (TOML) to check.
    pub scene: PathBuf,
}

/// Carry out a parsed command line.
pub fn run(cli: Cli) -> Result<(), Error> {
    match cli.command {
        None => stages(StagesArgs::default_out()),
        Some(Command::Stages(args)) => stages(args),
        Some(Command::Render(args)) => render_one(args),
        Some(Command::Check(args)) => check(&args.scene),
    }
}

impl StagesArgs {
    fn default_out() -> StagesArgs {
        StagesArgs {
            scene: SceneArgs::default(),
            out: PathBuf::from("out"),
        }
    }
}

/// Load the scene named by `args` (or the built-in one) and apply the size flags.
pub fn load_scene(args: &SceneArgs) -> Result<(Scene, String), Error> {
    let (mut scene, name) = match &args.scene {
        Some(path) => (scene_file::load(path)?, path.display().to_string()),
        None => (scene_file::seed(), scene_file::SEED_NAME.to_string()),
    };
    scene.width = args.width.unwrap_or(scene.width);
    scene.height = args.height.unwrap_or(scene.height);
    check_image_size(scene.width, scene.height, "--").map_err(Error::Usage)?;
    Ok((scene, name))
}

fn stages(args: StagesArgs) -> Result<(), Error> {
    let (scene, name) = load_scene(&args.scene)?;
    ensure_folder(&args.out)?;
    println!("{name}: every stage at {} × {}", scene.width, scene.height);
    let bar = progress_bar(u64::from(scene.height) * Stage::ALL.len() as u64);
    let start = Instant::now();
    for stage in Stage::ALL {
        bar.set_message(stage.folder());
        let dir = args.out.join(stage.folder());
        let (frame, seconds) = timed(|| render(&scene, Stages::up_to(stage), &|n| bar.inc(n)));
        write(&frame, &dir, seconds, &bar)?;
    }
    bar.finish_and_clear();
    println!(
        "wrote {} stages into {}/ in {:.2} s",
        Stage::ALL.len(),
        args.out.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn render_one(args: RenderArgs) -> Result<(), Error> {
    let stages = Stages::select(args.stage, &args.without).map_err(Error::Usage)?;
    let (scene, name) = load_scene(&args.scene)?;
    ensure_folder(&args.out)?;
    println!("{name}: {stages} at {} × {}", scene.width, scene.height);
    let bar = progress_bar(u64::from(scene.height));
    let (frame, seconds) = timed(|| render(&scene, stages, &|n| bar.inc(n)));
    bar.finish_and_clear();
    write(&frame, &args.out, seconds, &bar)
}

fn write(frame: &Frame, dir: &Path, render_seconds: f64, bar: &ProgressBar) -> Result<(), Error> {
    let (written, write_seconds) = timed(|| crate::output::write_frame(frame, dir));
    let names: Vec<String> = written?
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    bar.suspend(|| {
        println!(
            "  {:<28} {}   render {:.3} s, write {:.3} s",
            format!("{}/", dir.display()),
            names.join(" "),
            render_seconds,
            write_seconds
        )
    });
    Ok(())
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let value = f();
    (value, start.elapsed().as_secs_f64())
}

/// A bar on stderr, drawn only when stderr is a terminal.
fn progress_bar(rows: u64) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(rows), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{msg:>16} [{bar:30}] {pos}/{len} rows, {eta} left")
            .expect("the template is valid")
            .progress_chars("=> "),
    );
    bar
}

fn ensure_folder(dir: &Path) -> Result<(), Error> {
    if dir.exists() && !dir.is_dir() {
        return Err(Error::Output {
            path: dir.to_path_buf(),
            message: "it is a file, not a folder; give --out a folder".into(),
        });
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::Output {
        path: dir.to_path_buf(),
        message: format!("cannot create the output folder: {e}"),
    })
}

fn check(path: &Path) -> Result<(), Error> {
    let scene = scene_file::load(path)?;
    print!("{}", describe(&scene, &path.display().to_string()));
    Ok(())
}

/// A readable summary of a checked scene, as `raystep check` prints it.
pub fn describe(scene: &Scene, name: &str) -> String {
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
    for role in [Role::Sphere, Role::Floor] {
        let objects: Vec<_> = scene.objects.iter().filter(|o| o.role == role).collect();
        let heading = match role {
            Role::Sphere => "spheres",
            Role::Floor => "planes (drawn from the plane stage on)",
        };
        out += &format!("  {} {heading}\n", objects.len());
        for (i, o) in objects.iter().enumerate() {
            let shape = match o.shape {
                Shape::Sphere(sp) => format!("sphere at {}, radius {}", sp.center, sp.radius),
                Shape::Plane(p) => format!("true plane through {}, normal {}", p.point, p.normal),
            };
            let m = &o.material;
            out += &format!(
                "    {}. {shape}\n       ambient {}, diffuse {}, specular {}, shininess {}, reflection {}\n",
                i + 1,
                m.ambient,
                m.diffuse,
                m.specular,
                m.shininess,
                m.reflection
            );
        }
    }
    out
}
