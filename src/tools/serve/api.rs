//! What the studio's HTTP API answers, apart from HTTP itself: the scene it
//! serves (and watches), and the query strings of `/api/render` and `/api/pixel`
//! turned into the command line's own arguments.
//!
//! A query is read as the flags of `raystep render` (or `explain`) without their
//! dashes: `stage=shadow&without=blinn-phong&width=300` becomes the words
//! `--stage=shadow --without=blinn-phong --width=300`, parsed by the command
//! line's own clap parser, so a mistake gets the message the command line gives.
//! A key with no value (`tutorial` or `tutorial=`) is a flag without one. The
//! scene is always the one served: no query names a file.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, SystemTime};

use clap::Parser;
use rayon::prelude::*;
use serde_json::{json, Value};

use crate::aov::{Buffer, Frame};
use crate::error::Error;
use crate::io::output::PngEncoding;
use crate::io::scene_file::{self, Overrides};
use crate::render::Settings;
use crate::scene::Scene;
use crate::stages::Stages;
use crate::tools::args::{check_pixel, Cli, Command, FrameArgs};

/// The longest query string taken, in bytes (a page's query is a few hundred).
pub const MAX_QUERY_BYTES: usize = 4096;

/// The most `key=value` pairs in one query.
pub const MAX_QUERY_PAIRS: usize = 64;

/// A request the API refuses: the HTTP status and the message (for a bad
/// option, the command line's own).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// 400 for a mistake in the query.
    pub status: u16,
    /// What is wrong, as the command line says it.
    pub message: String,
}

impl Refusal {
    fn bad(message: impl Into<String>) -> Refusal {
        Refusal {
            status: 400,
            message: message.into(),
        }
    }

    /// The body of the answer: `{"error": "..."}`.
    pub fn json(&self) -> String {
        json!({ "error": self.message }).to_string()
    }
}

impl From<Error> for Refusal {
    fn from(error: Error) -> Refusal {
        Refusal::bad(error.to_string())
    }
}

/// A clap error as the command line prints it (without its leading `error: `).
fn clap_message(error: &clap::Error) -> String {
    let text = error.to_string();
    let text = text.trim_end();
    text.strip_prefix("error: ").unwrap_or(text).to_string()
}

// ANCHOR: query_words
/// The words of the command line that `query` stands for (each `--key=value`, or
/// `--key`), and the values of the keys in `taken`, which the endpoint reads
/// itself (each at most once), in the order of `taken`.
pub fn query_words(
    query: &str,
    taken: &[&str],
) -> Result<(Vec<String>, Vec<Option<String>>), Refusal> {
    if query.len() > MAX_QUERY_BYTES {
        return Err(Refusal::bad(format!(
            "the query is {} bytes long; at most {MAX_QUERY_BYTES} are taken",
            query.len()
        )));
    }
    let mut words = Vec::new();
    let mut values: Vec<Option<String>> = vec![None; taken.len()];
    for (n, (key, value)) in form_urlencoded::parse(query.as_bytes()).enumerate() {
        if n >= MAX_QUERY_PAIRS {
            return Err(Refusal::bad(format!(
                "the query has more than {MAX_QUERY_PAIRS} keys"
            )));
        }
        if key.is_empty() && value.is_empty() {
            continue;
        }
        if let Some(i) = taken.iter().position(|t| *t == key) {
            if values[i].is_some() {
                return Err(Refusal::bad(format!("`{key}` is given more than once")));
            }
            values[i] = Some(value.into_owned());
            continue;
        }
        let well_formed = key.len() <= 32
            && key.starts_with(|c: char| c.is_ascii_lowercase())
            && key
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-');
        if !well_formed {
            return Err(Refusal::bad(format!(
                "`{key}` is not an option: the query's keys are the command line's flags \
                 without their dashes, e.g. stage=shadow&without=blinn-phong&width=300"
            )));
        }
        if ["help", "version", "out"].contains(&key.as_ref()) {
            return Err(Refusal::bad(format!(
                "`{key}` is not an option of the API: it renders into its answer, and writes \
                 and prints nothing"
            )));
        }
        words.push(if value.is_empty() {
            format!("--{key}")
        } else {
            format!("--{key}={value}")
        });
    }
    Ok((words, values))
}
// ANCHOR_END: query_words

/// Parse `raystep WORDS` with the command line's parser.
fn parse_command(words: Vec<String>) -> Result<Command, Refusal> {
    let cli = Cli::try_parse_from(std::iter::once("raystep".to_string()).chain(words))
        .map_err(|e| Refusal::bad(clap_message(&e)))?;
    cli.command
        .ok_or_else(|| Refusal::bad("no command".to_string()))
}

/// Where the served scene comes from.
#[derive(Clone, Debug)]
enum Source {
    BuiltIn,
    File(PathBuf),
}

/// A scene file as last seen on the disk: enough to notice a change.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Stamp {
    modified: Option<SystemTime>,
    len: u64,
    inode: u64,
}

fn stamp(path: &Path) -> Option<Stamp> {
    use std::os::unix::fs::MetadataExt;
    let m = std::fs::metadata(path).ok()?;
    Some(Stamp {
        modified: m.modified().ok(),
        len: m.len(),
        inode: m.ino(),
    })
}

/// What the studio serves, behind its lock.
struct Served {
    /// Grows by one on every reload, good or bad; 1 for the first load.
    version: u64,
    /// The text of the last scene that loaded.
    text: Arc<str>,
    /// The last scene that loaded, at its own size.
    scene: Arc<Scene>,
    /// Why the latest reload failed, if it did (the scene is then the last good).
    error: Option<String>,
    /// The file as last read, and its bytes then (good or not).
    stamp: Option<Stamp>,
    /// A change seen at the last look, read once the file stays as it is for
    /// one more look (an editor that truncates and then writes is not read in
    /// between).
    settling: Option<Option<Stamp>>,
    bytes: Option<Vec<u8>>,
    /// Scenes parsed at other sizes, for this version: (size, scene).
    sized: Vec<(Overrides, Arc<Scene>)>,
    /// The server is stopping: waiters leave.
    stopping: bool,
}

/// The scene being served: the built-in one, or a file watched for changes.
pub struct Studio {
    source: Source,
    name: String,
    served: Mutex<Served>,
    changed: Condvar,
}

/// How many scenes at other sizes are kept parsed.
const SIZED_KEPT: usize = 4;

/// The file's bytes as `scene_file::load` would read them (at most one byte past
/// its limit), or `None` if they cannot be read; their size and encoding are
/// checked by `Studio::text_of`.
fn read_bytes(path: &Path) -> Option<Vec<u8>> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .ok()?
        .take(scene_file::MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .ok()?;
    Some(bytes)
}

impl Studio {
    /// Serve the scene file at `path` (or the built-in scene): refused, with the
    /// command line's message, if it does not load now.
    pub fn open(path: Option<&Path>) -> Result<Studio, Error> {
        if path.is_some_and(scene_file::is_stdin) {
            return Err(Error::Usage(
                "serve watches its scene file and reloads it on every change, so it \
                 cannot take one from standard input (-): give the path of a file"
                    .into(),
            ));
        }
        let (source, name) = match path {
            None => (Source::BuiltIn, scene_file::SEED_NAME.to_string()),
            Some(p) => (Source::File(p.to_path_buf()), p.display().to_string()),
        };
        let (text, bytes, stamp) = match &source {
            Source::BuiltIn => (scene_file::SEED_TOML.to_string(), None, None),
            Source::File(p) => {
                let stamp = stamp(p);
                let bytes = read_bytes(p);
                let text = Studio::text_of(p, bytes.as_deref())?;
                (text, bytes, stamp)
            }
        };
        let scene = scene_file::parse(&text, &name)?;
        let served = Served {
            version: 1,
            text: text.into(),
            scene: Arc::new(scene),
            error: None,
            stamp,
            settling: None,
            bytes,
            sized: Vec::new(),
            stopping: false,
        };
        Ok(Studio {
            source,
            name,
            served: Mutex::new(served),
            changed: Condvar::new(),
        })
    }

    /// The text of a scene file read as `bytes`, or the command line's message
    /// for a file it cannot take (too large, not UTF-8, unreadable).
    fn text_of(path: &Path, bytes: Option<&[u8]>) -> Result<String, Error> {
        match bytes.map(std::str::from_utf8) {
            Some(Ok(text)) if text.len() as u64 <= scene_file::MAX_FILE_BYTES => {
                Ok(text.to_string())
            }
            // The command line's own reading says what is wrong.
            _ => match scene_file::load(path) {
                Err(e) => Err(e),
                Ok(_) => Err(Error::Scene {
                    file: path.display().to_string(),
                    message: "changed while it was read; it is read again".into(),
                }),
            },
        }
    }

    fn lock(&self) -> MutexGuard<'_, Served> {
        self.served.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The scene file's path, if it is not the built-in scene.
    pub fn path(&self) -> Option<&Path> {
        match &self.source {
            Source::BuiltIn => None,
            Source::File(p) => Some(p),
        }
    }

    /// The scene's name in messages: its path, or the built-in scene's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The version now, and the error of the latest reload if it failed.
    pub fn version(&self) -> (u64, Option<String>) {
        let served = self.lock();
        (served.version, served.error.clone())
    }

    /// Look at the scene file: if it changed before the last look and not since
    /// (and is not empty), and its bytes differ, load it again (keeping the last
    /// good scene if it no longer loads), count a new version and wake the
    /// waiters. Returns whether it reloaded.
    pub fn poll(&self) -> bool {
        let Source::File(path) = &self.source else {
            return false;
        };
        let now = stamp(path);
        {
            let mut served = self.lock();
            if now.is_some() && now == served.stamp {
                served.settling = None;
                return false;
            }
            // An empty file is one being written (truncated, its bytes not yet
            // there: on a busy machine that can outlast two looks); no scene is
            // empty, so wait for its bytes rather than report it broken.
            if now.as_ref().is_some_and(|s| s.len == 0) {
                served.settling = None;
                return false;
            }
            if served.settling.as_ref() != Some(&now) {
                served.settling = Some(now);
                return false;
            }
            served.settling = None;
        }
        let bytes = read_bytes(path);
        let mut served = self.lock();
        served.stamp = now;
        if bytes == served.bytes {
            return false;
        }
        served.bytes = bytes.clone();
        drop(served);
        let loaded = Studio::text_of(path, bytes.as_deref())
            .and_then(|text| scene_file::parse(&text, &self.name).map(|scene| (text, scene)));
        let mut served = self.lock();
        served.version += 1;
        match loaded {
            Ok((text, scene)) => {
                served.text = text.into();
                served.scene = Arc::new(scene);
                served.error = None;
                served.sized.clear();
            }
            Err(e) => served.error = Some(e.to_string()),
        }
        drop(served);
        self.changed.notify_all();
        true
    }

    /// Wait until the version differs from `seen`, the server stops, or
    /// `timeout` passes: the version then, its error, and whether it stops.
    pub fn wait_change(&self, seen: u64, timeout: Duration) -> (u64, Option<String>, bool) {
        let served = self.lock();
        let (served, _) = self
            .changed
            .wait_timeout_while(served, timeout, |s| s.version == seen && !s.stopping)
            .unwrap_or_else(|e| e.into_inner());
        (served.version, served.error.clone(), served.stopping)
    }

    /// Wake every waiter for good: the server stops.
    pub fn stop(&self) {
        self.lock().stopping = true;
        self.changed.notify_all();
    }

    /// The last good scene at the size `size` asks for, as the command line
    /// would load it (the size decides the default screen, so the text is parsed
    /// again at each size), and the version it belongs to.
    fn scene_at(&self, size: Overrides, edits: &Edits) -> Result<(Scene, u64), Error> {
        if !edits.is_empty() {
            let (text, version) = {
                let served = self.lock();
                (Arc::clone(&served.text), served.version)
            };
            let text = edits.apply(&text, &self.name)?;
            return Ok((scene_file::parse_edited(&text, &self.name, size)?, version));
        }
        let (text, version) = {
            let served = self.lock();
            if size == Overrides::default() {
                return Ok((Scene::clone(&served.scene), served.version));
            }
            if let Some((_, scene)) = served.sized.iter().find(|(s, _)| *s == size) {
                return Ok((Scene::clone(scene), served.version));
            }
            (Arc::clone(&served.text), served.version)
        };
        let scene = scene_file::parse_sized(&text, &self.name, size)?;
        let mut served = self.lock();
        if served.version == version && Arc::ptr_eq(&served.text, &text) {
            if served.sized.len() >= SIZED_KEPT {
                served.sized.remove(0);
            }
            served.sized.push((size, Arc::new(scene.clone())));
        }
        Ok((scene, version))
    }

    /// `prepare` of the command line on the served scene: the stages, the scene
    /// at its size, the rules; in that order, so that the first mistake found is
    /// the one the command line reports.
    fn prepare(&self, frame: &FrameArgs, edits: &Edits) -> Result<(Scene, Settings, u64), Error> {
        let stages = Stages::select(frame.stage, &frame.without).map_err(Error::Usage)?;
        let size = Overrides {
            width: frame.scene.width,
            height: frame.scene.height,
            max_depth: None,
        };
        let (mut scene, version) = self.scene_at(size, edits)?;
        // The served text's own max_depth passed when it loaded: a --max-depth
        // needs no parse of its own (100,000 listed spheres take about 0.3 s to
        // read: the README's `check` time).
        scene_file::override_max_depth(&mut scene, frame.rules.max_depth)?;
        let settings = frame.rules.apply(&scene, &self.name, stages)?;
        Ok((scene, settings, version))
    }

    /// `GET /api/render?QUERY`: what to render, or why not.
    pub fn render_job(&self, query: &str) -> Result<RenderJob, Refusal> {
        let (words, taken) = query_words(query, &["buffer", "view", "light", "camera"])?;
        let name = taken[0].clone().unwrap_or_else(|| "beauty".to_string());
        let view = taken[1].as_deref().map(view_name).transpose()?;
        let edits = Edits::read(&taken[2], &taken[3])?;
        let said = words.join("\u{1f}");
        let words = std::iter::once("render".to_string()).chain(words).collect();
        let Command::Render(args) = parse_command(words)? else {
            unreachable!("the words begin with `render`")
        };
        let (scene, settings, version) = self.prepare(&args.frame, &edits)?;
        // A render is a function of the scene's text and these: its beauty can
        // be looked up by them.
        let key = format!("{version}\u{1e}{said}\u{1e}{edits:?}");
        let Some(buffer) = Buffer::ALL.into_iter().find(|b| b.name() == name) else {
            let names: Vec<&str> = Buffer::ALL.iter().map(|b| b.name()).collect();
            return Err(Refusal::bad(format!(
                "buffer={name}: no such buffer; the buffers are {}",
                names.join(", ")
            )));
        };
        if !buffer.written(settings.stages) {
            return Err(Refusal::bad(format!(
                "buffer={name}: a render of {} has no {name} buffer; it has {}",
                settings.stages,
                buffers_of(settings.stages).join(", ")
            )));
        }
        Ok(RenderJob {
            scene,
            settings,
            buffer,
            png: args.files.png,
            version,
            view,
            key,
        })
    }

    /// `GET /api/diff?a=QUERY&b=QUERY`: the two renders (their beauty, as
    /// `buffers.exr` holds it) that `raystep diff` compares, or why not.
    pub fn diff_jobs(&self, query: &str) -> Result<DiffJobs, Refusal> {
        let (words, taken) = query_words(query, &["a", "b", "view"])?;
        if let Some(word) = words.first() {
            return Err(Refusal::bad(format!(
                "{word}: /api/diff takes a=QUERY&b=QUERY, the options of the two renders \
                 (each a query of /api/render, encoded), and view"
            )));
        }
        let (Some(a), Some(b)) = (&taken[0], &taken[1]) else {
            return Err(Refusal::bad(
                "give the two renders as a=QUERY&b=QUERY, each a query of /api/render (encoded)",
            ));
        };
        let view = taken[2].as_deref().map(view_name).transpose()?;
        let side = |name: &str, query: &str| {
            self.render_job(query).map_err(|r| Refusal {
                status: r.status,
                message: format!("{name}: {}", r.message),
            })
        };
        let (a, b) = (side("a", a)?, side("b", b)?);
        let size = |job: &RenderJob| (job.scene.width, job.scene.height);
        if size(&a) != size(&b) {
            let ((wa, ha), (wb, hb)) = (size(&a), size(&b));
            return Err(Refusal::bad(format!(
                "a is {wa} × {ha} but b is {wb} × {hb}: only renders of one size compare"
            )));
        }
        Ok(DiffJobs { a, b, view })
    }

    /// `GET /api/scene.toml?light=X,Y,Z&camera=X,Y,Z`: the scene's text with the
    /// page's changes, as a file to save.
    pub fn scene_toml(&self, query: &str) -> Result<String, Refusal> {
        let (words, taken) = query_words(query, &["light", "camera"])?;
        if let Some(word) = words.first() {
            return Err(Refusal::bad(format!(
                "{word}: /api/scene.toml takes only light=X,Y,Z and camera=X,Y,Z"
            )));
        }
        let edits = Edits::read(&taken[0], &taken[1])?;
        let text = Arc::clone(&self.lock().text);
        let text = edits.apply(&text, &self.name)?;
        // What is saved loads.
        scene_file::parse(&text, &self.name)?;
        Ok(text)
    }

    /// `GET /api/pixel?x=X&y=Y&QUERY`: exactly what `raystep explain --pixel X,Y
    /// QUERY --json` prints, or why not.
    pub fn pixel(&self, query: &str) -> Result<String, Refusal> {
        let (words, taken) = query_words(query, &["x", "y", "light", "camera"])?;
        let edits = Edits::read(&taken[2], &taken[3])?;
        let (Some(x), Some(y)) = (&taken[0], &taken[1]) else {
            return Err(Refusal::bad(
                "give the pixel as x=X&y=Y: column and row from the top-left corner",
            ));
        };
        let words = [
            "explain".to_string(),
            format!("--pixel={x},{y}"),
            "--json".into(),
        ]
        .into_iter()
        .chain(words)
        .collect();
        let Command::Explain(args) = parse_command(words)? else {
            unreachable!("the words begin with `explain`")
        };
        let (scene, settings, _) = self.prepare(&args.frame, &edits)?;
        let (x, y) = args.pixel;
        check_pixel(&scene, x, y)?;
        let story = crate::tools::explain::explain(&scene, &settings, x, y);
        Ok(crate::tools::json::json_text(&story, true) + "\n")
    }

    /// `GET /api/scene[?objects=none]`: the version, the error of the latest
    /// reload (or null), and the last good scene; with `objects=none`, without
    /// its list of objects (which the page does not read, and which is 24 MB
    /// of JSON for 100,000 spheres: README, "The studio").
    pub fn scene_json(&self, query: &str) -> Result<Value, Refusal> {
        let (words, taken) = query_words(query, &["objects"])?;
        let listed = match (words.first(), taken[0].as_deref()) {
            (None, None | Some("all")) => true,
            (None, Some("none")) => false,
            (Some(word), _) => {
                return Err(Refusal::bad(format!(
                    "{word}: /api/scene takes only objects=all or objects=none"
                )))
            }
            (None, Some(other)) => {
                return Err(Refusal::bad(format!(
                    "objects={other}: /api/scene takes objects=all or objects=none"
                )))
            }
        };
        let served = self.lock();
        Ok(json!({
            "version": served.version,
            "file": self.name,
            "error": served.error,
            "scene": crate::tools::json::scene_json(&served.scene, &self.name, listed),
        }))
    }
}

/// The names of the buffers a render of `stages` has.
pub fn buffers_of(stages: Stages) -> Vec<&'static str> {
    Buffer::ALL
        .into_iter()
        .filter(|b| b.written(stages))
        .map(Buffer::name)
        .collect()
}

/// A render the API was asked for, ready to run.
pub struct RenderJob {
    /// The scene at the size asked for.
    pub scene: Scene,
    /// The stages and rules.
    pub settings: Settings,
    /// The buffer whose PNG is the answer.
    pub buffer: Buffer,
    /// How `--png` stores its light.
    pub png: PngEncoding,
    /// The scene's version.
    pub version: u64,
    /// The view it draws (`view=NAME`): a newer render of the same view
    /// supersedes it.
    pub view: Option<String>,
    /// What the render depends on (the scene's version, the command line's
    /// words, the moves): two jobs with one key give the same frame.
    pub key: String,
}

impl RenderJob {
    /// Pixels in the image.
    pub fn pixels(&self) -> u64 {
        u64::from(self.scene.width) * u64::from(self.scene.height)
    }

    /// The frame, unless `cancel` is set before it is finished.
    pub fn frame(&self, cancel: &AtomicBool) -> Option<Frame> {
        crate::engine::render_cancellable(&self.scene, &self.settings, cancel, &|| {})
    }
}

/// The two renders of `/api/diff`.
pub struct DiffJobs {
    /// The first (A).
    pub a: RenderJob,
    /// The second (B).
    pub b: RenderJob,
    /// The view asking (`view=NAME`).
    pub view: Option<String>,
}

/// A frame's beauty, as `buffers.exr` holds it (its `R`, `G`, `B`).
pub fn beauty(frame: &Frame) -> Beauty {
    Beauty {
        width: frame.width,
        height: frame.height,
        pixels: frame.pixels.par_iter().map(|p| p.colour).collect(),
    }
}

/// The beauty of a render: what `raystep diff` compares.
#[derive(Clone, Debug, PartialEq)]
pub struct Beauty {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Linear RGB, row by row.
    pub pixels: Vec<[f32; 3]>,
}

/// What `raystep diff --json` reports of two renders' beauty (of one size), by
/// its own code ([`crate::tools::compare`], at its default threshold and fail
/// percent).
pub fn diff_json(a: &Beauty, b: &Beauty) -> Value {
    use crate::tools::compare::{compare, pixels_over};
    let (pa, pb) = (&a.pixels, &b.pixels);
    let d = compare(pa, pb, a.width as usize);
    let threshold = 1.0f32 / 255.0;
    let over = pixels_over(pa, pb, threshold);
    let percent = 100.0 * over as f64 / d.pixels.max(1) as f64;
    let largest = f64::from(d.largest);
    json!({
        "width": a.width,
        "height": a.height,
        "pixels": d.pixels,
        "threshold": threshold,
        "fail_percent": 0.0,
        "over_threshold": over,
        "over_threshold_percent": percent,
        "over_one_step": d.over_one_step,
        "largest": if largest.is_finite() { json!(largest) } else { Value::Null },
        "largest_at": { "row": d.largest_at.0, "column": d.largest_at.1 },
        "rmse": d.rmse,
        "clipped": [d.saturated.0, d.saturated.1],
        "non_finite": [d.non_finite.0, d.non_finite.1],
        "different": percent > 0.0,
    })
}

/// A view's name (`view=NAME`): 1 to 64 letters, digits, `-` or `_`.
fn view_name(name: &str) -> Result<String, Refusal> {
    let fine = (1..=64).contains(&name.len())
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    match fine {
        true => Ok(name.to_string()),
        false => Err(Refusal::bad(format!(
            "view={name}: a view's name is 1 to 64 letters, digits, - or _"
        ))),
    }
}

/// The page's changes to the scene: the light and the camera moved.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Edits {
    /// `[light] position`.
    pub light: Option<[f64; 3]>,
    /// `[camera] position`.
    pub camera: Option<[f64; 3]>,
}

impl Edits {
    /// The edits of `light=X,Y,Z` and `camera=X,Y,Z`.
    pub fn read(light: &Option<String>, camera: &Option<String>) -> Result<Edits, Refusal> {
        let point = |key: &str, text: &Option<String>| -> Result<Option<[f64; 3]>, Refusal> {
            let Some(text) = text else { return Ok(None) };
            let numbers: Vec<f64> = text
                .split(',')
                .map(|n| n.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .unwrap_or_default();
            match numbers[..] {
                [x, y, z] if numbers.iter().all(|n| n.is_finite() && n.abs() <= 1e6) => {
                    Ok(Some([x, y, z]))
                }
                _ => Err(Refusal::bad(format!(
                    "{key}={text}: give a point as three numbers X,Y,Z (each at most 1e6 \
                     in size)"
                ))),
            }
        };
        Ok(Edits {
            light: point("light", light)?,
            camera: point("camera", camera)?,
        })
    }

    /// Whether nothing is changed.
    pub fn is_empty(&self) -> bool {
        self == &Edits::default()
    }

    /// The scene's TOML `text` with the changes made: each position set in its
    /// table (made if the file has none). The file's own lines are kept, its
    /// comments too, with each `position = ...` line replaced (`Edits::in_place`);
    /// when that does not give exactly the values asked for (a position written
    /// over several lines, an inline table), the text is written again from its
    /// values, without the comments.
    pub fn apply(&self, text: &str, file: &str) -> Result<String, Error> {
        if self.is_empty() {
            return Ok(text.to_string());
        }
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut table: toml::Table = text.parse().map_err(|e: toml::de::Error| Error::Scene {
            file: file.to_string(),
            message: e.to_string(),
        })?;
        for (name, point) in [("light", self.light), ("camera", self.camera)] {
            let Some(point) = point else { continue };
            let section = table
                .entry(name)
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            let Some(section) = section.as_table_mut() else {
                return Err(Error::Scene {
                    file: file.to_string(),
                    message: format!("`{name}` is not a table"),
                });
            };
            let value = point.iter().map(|&c| toml::Value::Float(c)).collect();
            section.insert("position".into(), toml::Value::Array(value));
        }
        let kept = self.in_place(text);
        if kept.parse::<toml::Table>().ok().as_ref() == Some(&table) {
            return Ok(kept);
        }
        toml::to_string(&table).map_err(|e| Error::Scene {
            file: file.to_string(),
            message: e.to_string(),
        })
    }

    /// `text` with each moved position's line replaced, line by line: in the
    /// table's `position = ...` line (a comment after it kept), or as a new line
    /// under the table's header, or in a new table at the end. Not checked here:
    /// [`Edits::apply`] takes it only if it reads as the values asked for.
    fn in_place(&self, text: &str) -> String {
        // The name of the table a header line opens (`[light]` -> light); any
        // line starting with `[` ends the table before it.
        let header = |line: &str| -> Option<String> {
            let line = line.trim_start();
            let inner = line.strip_prefix('[')?.split(']').next()?;
            Some(inner.trim().to_string())
        };
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        for (name, point) in [("light", self.light), ("camera", self.camera)] {
            let Some([x, y, z]) = point else { continue };
            let value = format!("position = [{x:?}, {y:?}, {z:?}]");
            let Some(start) = lines
                .iter()
                .position(|l| header(l).as_deref() == Some(name))
            else {
                lines.extend([String::new(), format!("[{name}]"), value]);
                continue;
            };
            let end = lines[start + 1..]
                .iter()
                .position(|l| header(l).is_some())
                .map_or(lines.len(), |i| start + 1 + i);
            let is_position = |l: &String| {
                let l = l.trim_start();
                l.strip_prefix("position")
                    .is_some_and(|rest| rest.trim_start().starts_with('='))
            };
            match (start + 1..end).find(|&i| is_position(&lines[i])) {
                Some(i) => {
                    let comment = lines[i].find('#').map_or("", |c| &lines[i][c..]);
                    let comment = if comment.is_empty() {
                        String::new()
                    } else {
                        format!(" {comment}")
                    };
                    lines[i] = format!("{value}{comment}");
                }
                None => lines.insert(start + 1, value),
            }
        }
        lines.join("\n") + "\n"
    }
}

/// The answer of a [`RenderJob`].
pub struct Rendered {
    /// The PNG file's bytes.
    pub png: Vec<u8>,
    /// How long the render took.
    pub render_seconds: f64,
    /// How long the PNG took to encode.
    pub encode_seconds: f64,
}
