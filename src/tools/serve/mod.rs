//! `raystep serve`: the studio, a page on 127.0.0.1 that re-renders on demand,
//! and the HTTP API it uses ([`api`]).
//!
//! HTTP is [tiny_http]'s: a thread per connection that parses requests, and a
//! few threads here that answer them. Renders are CPU work on rayon's pools, so
//! nothing is gained from an async runtime; tiny_http and its four small
//! dependencies build in seconds. Each of the [`RENDERS_AT_ONCE`] renders runs
//! on a rayon pool of its own: in one shared pool a render that came second
//! waited for the first one's rows (a 30 × 20 preview behind a 1080p render
//! took the whole 1.5 s of the large one: curl against `raystep serve` before
//! commit e7af856, whose message has the figures), since a pool's threads finish the
//! work they have split before they take new work from outside.
//!
//! Safety, since a server is an attack surface:
//! - it listens on 127.0.0.1 only;
//! - a request whose `Host` is not `127.0.0.1:PORT` or `localhost:PORT` is
//!   refused with 421 (a page elsewhere cannot reach it through DNS rebinding),
//!   and so, with 403, is one a browser marks as sent by a page of another
//!   origin (`Sec-Fetch-Site` other than `same-origin` or `none`);
//! - the only paths are the page's own files, compiled into the binary, and the
//!   API: nothing is ever read from the disk for a path, so `/../`, encoded dots
//!   and absolute paths are 404, and no symbolic link is followed;
//! - a query is at most [`api::MAX_QUERY_BYTES`], an image and its samples are
//!   bounded by the command line's limits, and at most [`RENDERS_AT_ONCE`]
//!   renders (and [`MAX_PIXELS`] pixels) are in flight: others wait in line, up
//!   to [`QUEUE_WAIT`], then get 503.

pub mod api;

use std::collections::{HashMap, VecDeque};
use std::io::Write;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use tiny_http::{Header, Method, Request, Response, Server};

use crate::error::Error;
use crate::io::scene_file::MAX_PIXELS;
use crate::tools::args::ServeArgs;
use api::{Refusal, Studio};

/// Renders at once; more wait in line.
pub const RENDERS_AT_ONCE: usize = 2;

// The gate keeps one bit a render pool in a `u32`.
const _: () = assert!(RENDERS_AT_ONCE <= 32);

/// How long a render waits for its turn before the answer is 503.
pub const QUEUE_WAIT: Duration = Duration::from_secs(30);

/// Threads that answer requests (each render holds one while it runs).
const WORKERS: usize = 8;

/// Event streams (`/api/events`) open at once; more get 503.
const MAX_STREAMS: usize = 32;

/// How often the scene file is looked at.
const WATCH_EVERY: Duration = Duration::from_millis(250);

/// How often an idle event stream sends a comment, to notice a closed one.
const KEEP_ALIVE: Duration = Duration::from_secs(15);

const PAGE_HTML: &str = include_str!("../../../assets/studio/index.html");
const PAGE_CSS: &str = include_str!("../../../assets/studio/studio.css");
const PAGE_JS: &str = include_str!("../../../assets/studio/studio.js");

/// The page's policy: its own files, its own API, nothing inline, no frames.
const PAGE_POLICY: &str = "default-src 'none'; script-src 'self'; style-src 'self'; \
     img-src 'self' blob: data:; connect-src 'self'; base-uri 'none'; form-action 'none'; \
     frame-ancestors 'none'";

/// Carry out `raystep serve`: listen, print the address, answer until Ctrl-C;
/// `quiet` (`-q`) leaves out the status line on standard error.
pub fn run(args: &ServeArgs, quiet: bool) -> Result<(), Error> {
    let studio = Arc::new(Studio::open(args.scene.as_deref())?);
    let address = SocketAddr::from(([127, 0, 0, 1], args.port));
    let server = Server::http(address).map_err(|e| {
        Error::Usage(format!(
            "cannot listen on {address}: {e}; give another --port, or --port 0 for any free one"
        ))
    })?;
    let port = server.server_addr().to_ip().map_or(args.port, |a| a.port());
    let url = format!("http://127.0.0.1:{port}/");
    {
        let mut out = std::io::stdout().lock();
        writeln!(out, "{url}")
            .and_then(|()| out.flush())
            .map_err(|e| Error::Output {
                path: "standard output".into(),
                message: e.to_string(),
            })?;
    }
    if !quiet {
        crate::error::to_stderr(format_args!(
            "serving {} on {url} (127.0.0.1 only); Ctrl-C to stop",
            studio.name()
        ));
    }
    if args.open {
        open_browser(&url);
    }
    let shared = Arc::new(Shared {
        studio,
        port,
        gate: Gate::default(),
        views: Views::default(),
        beauties: Beauties::default(),
        streams: Arc::new(AtomicUsize::new(0)),
        stopping: AtomicBool::new(false),
    });
    let server = Arc::new(server);
    let mut threads = Vec::new();
    for _ in 0..WORKERS {
        let (server, shared) = (Arc::clone(&server), Arc::clone(&shared));
        threads.push(std::thread::spawn(move || {
            while !shared.stopping.load(Ordering::Relaxed) {
                match server.recv_timeout(Duration::from_millis(100)) {
                    Ok(Some(request)) => answer(&shared, request),
                    Ok(None) => {}
                    Err(_) => break,
                }
            }
        }));
    }
    let watcher = {
        let shared = Arc::clone(&shared);
        std::thread::spawn(move || {
            while !shared.stopping.load(Ordering::Relaxed) {
                std::thread::sleep(WATCH_EVERY);
                shared.studio.poll();
            }
        })
    };
    while !crate::interrupt::requested() {
        std::thread::sleep(Duration::from_millis(50));
    }
    // Closing: no new requests, event streams told to end, answers under way
    // finished (a render stops at its next row and answers 503).
    shared.stopping.store(true, Ordering::Relaxed);
    shared.studio.stop();
    server.unblock();
    for thread in threads {
        let _ = thread.join();
    }
    let _ = watcher.join();
    drop(server);
    Err(Error::Stopped(
        "the studio stopped (every answer under way was finished)",
    ))
}

/// Start the system's browser on `url`, or say how to open it by hand.
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else {
        "xdg-open"
    };
    let started = std::process::Command::new(opener)
        .arg(url)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
    if let Err(e) = started {
        crate::error::to_stderr(format_args!(
            "warning: cannot start a browser with {opener} ({e}); open {url} by hand"
        ));
    }
}

/// What the threads share.
struct Shared {
    studio: Arc<Studio>,
    port: u16,
    gate: Gate,
    views: Views,
    beauties: Beauties,
    streams: Arc<AtomicUsize>,
    stopping: AtomicBool,
}

/// The renders in flight: which of the pools they hold (a bit each), and their
/// pixels; and a rayon pool for each render at once.
struct Gate {
    running: Mutex<(u32, u64)>,
    freed: Condvar,
    pools: Vec<rayon::ThreadPool>,
}

impl Default for Gate {
    /// The pools have as many threads as rayon's global pool (the processors,
    /// or `RAYON_NUM_THREADS`): a render alone runs as fast as on the command
    /// line, and two share the processors.
    fn default() -> Gate {
        let pools = (0..RENDERS_AT_ONCE)
            .map(|k| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(rayon::current_num_threads())
                    .thread_name(move |i| format!("render-{k}-{i}"))
                    .build()
                    .expect("the system gives threads for the render pools")
            })
            .collect();
        Gate {
            running: Mutex::new((0, 0)),
            freed: Condvar::new(),
            pools,
        }
    }
}

/// The renders under way (or waiting) of each view (`view=NAME`): a newer
/// request of a view cancels the one before it.
#[derive(Default)]
struct Views {
    current: Mutex<HashMap<String, Arc<AtomicBool>>>,
}

/// A request's claim on its view: its cancel flag, let go when dropped.
struct Claim<'a> {
    views: &'a Views,
    view: Option<String>,
    cancel: Arc<AtomicBool>,
}

// ANCHOR: supersede
impl Views {
    /// Claim `view` for a new request, cancelling the one that had it. No view:
    /// a flag nobody else sets.
    fn claim(&self, view: Option<&str>) -> Claim<'_> {
        let cancel = Arc::new(AtomicBool::new(false));
        if let Some(view) = view {
            let mut current = self.current.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(older) = current.insert(view.to_string(), Arc::clone(&cancel)) {
                older.store(true, Ordering::SeqCst);
            }
        }
        Claim {
            views: self,
            view: view.map(str::to_string),
            cancel,
        }
    }
}

impl Drop for Claim<'_> {
    fn drop(&mut self) {
        let Some(view) = &self.view else { return };
        let mut current = self.views.current.lock().unwrap_or_else(|e| e.into_inner());
        if current
            .get(view)
            .is_some_and(|c| Arc::ptr_eq(c, &self.cancel))
        {
            current.remove(view);
        }
    }
}
// ANCHOR_END: supersede

/// A render's place among those in flight, given back when dropped: its pool
/// and its pixels.
struct Turn<'a> {
    gate: &'a Gate,
    slot: usize,
    pixels: u64,
}

impl Turn<'_> {
    /// Run `work` on this turn's pool.
    fn run<R: Send>(&self, work: impl FnOnce() -> R + Send) -> R {
        self.gate.pools[self.slot].install(work)
    }
}

impl Gate {
    /// Wait for a turn to render `pixels`, until `deadline` or an interrupt.
    /// A render superseded meanwhile (`cancel` set) leaves the line at once.
    fn enter(&self, pixels: u64, deadline: Instant, cancel: &AtomicBool) -> Option<Turn<'_>> {
        let mut running = self.running.lock().unwrap_or_else(|e| e.into_inner());
        loop {
            if cancel.load(Ordering::SeqCst) {
                return None;
            }
            let (held, busy) = *running;
            let count = held.count_ones() as usize;
            // A render alone may always run: its size is within the limits.
            if count == 0 || (count < RENDERS_AT_ONCE && busy + pixels <= MAX_PIXELS) {
                let slot = (!held).trailing_zeros() as usize;
                *running = (held | 1 << slot, busy + pixels);
                return Some(Turn {
                    gate: self,
                    slot,
                    pixels,
                });
            }
            let now = Instant::now();
            if now >= deadline || crate::interrupt::requested() {
                return None;
            }
            let wait = (deadline - now).min(Duration::from_millis(100));
            running = self
                .freed
                .wait_timeout(running, wait)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
    }
}

impl Drop for Turn<'_> {
    fn drop(&mut self) {
        let mut running = self.gate.running.lock().unwrap_or_else(|e| e.into_inner());
        running.0 &= !(1 << self.slot);
        running.1 -= self.pixels;
        drop(running);
        self.gate.freed.notify_all();
    }
}

fn header(name: &str, value: &str) -> Header {
    Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("raystep's headers are ASCII")
}

/// Send `body` with `status`, as one block with its length (never chunked).
fn send(request: Request, status: u16, kind: &str, body: Vec<u8>, extra: &[(&str, String)]) {
    let mut response = Response::from_data(body)
        .with_status_code(status)
        .with_chunked_threshold(usize::MAX)
        .with_header(header("Content-Type", kind))
        .with_header(header("Cache-Control", "no-store"))
        .with_header(header("X-Content-Type-Options", "nosniff"))
        .with_header(header("Referrer-Policy", "no-referrer"));
    for (name, value) in extra {
        response.add_header(header(name, value));
    }
    // A client that went away is no concern of the server's.
    let _ = request.respond(response);
}

const JSON: &str = "application/json; charset=utf-8";

fn refuse(request: Request, refusal: &Refusal) {
    send(
        request,
        refusal.status,
        JSON,
        refusal.json().into_bytes(),
        &[],
    );
}

fn error(request: Request, status: u16, message: &str) {
    refuse(
        request,
        &Refusal {
            status,
            message: message.to_string(),
        },
    );
}

/// Whether `host` (a `Host` header) names this server: `127.0.0.1:PORT` or
/// `localhost:PORT`.
pub fn host_allowed(host: &str, port: u16) -> bool {
    let host = host.to_ascii_lowercase();
    host == format!("127.0.0.1:{port}") || host == format!("localhost:{port}")
}

/// Answer one request.
fn answer(shared: &Shared, request: Request) {
    let headers = |name: &'static str| -> Vec<String> {
        request
            .headers()
            .iter()
            .filter(|h| h.field.equiv(name))
            .map(|h| h.value.as_str().to_string())
            .collect()
    };
    let hosts = headers("Host");
    if hosts.len() != 1 || !host_allowed(&hosts[0], shared.port) {
        let port = shared.port;
        return error(
            request,
            421,
            &format!(
                "this server answers only requests for 127.0.0.1:{port} or localhost:{port} \
                 (the Host header)"
            ),
        );
    }
    if headers("Sec-Fetch-Site")
        .iter()
        .any(|site| !matches!(site.as_str(), "same-origin" | "none"))
    {
        return error(
            request,
            403,
            "this server answers only its own page, not pages of other origins",
        );
    }
    if !matches!(request.method(), Method::Get | Method::Head) {
        let allow = [("Allow", "GET, HEAD".to_string())];
        let body = Refusal {
            status: 405,
            message: "only GET (and HEAD) are answered".into(),
        }
        .json();
        return send(request, 405, JSON, body.into_bytes(), &allow);
    }
    let url = request.url().to_string();
    let (path, query) = url.split_once('?').unwrap_or((&url, ""));
    let studio = &shared.studio;
    match path {
        "/" | "/index.html" => send(
            request,
            200,
            "text/html; charset=utf-8",
            PAGE_HTML.into(),
            &[
                ("Content-Security-Policy", PAGE_POLICY.to_string()),
                ("X-Frame-Options", "DENY".to_string()),
            ],
        ),
        "/studio.css" => send(
            request,
            200,
            "text/css; charset=utf-8",
            PAGE_CSS.into(),
            &[],
        ),
        "/studio.js" => send(
            request,
            200,
            "text/javascript; charset=utf-8",
            PAGE_JS.into(),
            &[],
        ),
        "/api/scene" => match studio.scene_json(query) {
            Ok(json) => send(request, 200, JSON, json.to_string().into_bytes(), &[]),
            Err(refusal) => refuse(request, &refusal),
        },
        "/api/pixel" => match studio.pixel(query) {
            Ok(json) => send(request, 200, JSON, json.into_bytes(), &[]),
            Err(refusal) => refuse(request, &refusal),
        },
        "/api/render" => render(shared, request, query),
        "/api/diff" => diff(shared, request, query),
        "/api/scene.toml" => match studio.scene_toml(query) {
            Ok(text) => {
                let name = studio
                    .path()
                    .and_then(|p| p.file_stem())
                    .and_then(|s| s.to_str())
                    .filter(|s| {
                        s.chars()
                            .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
                    })
                    .unwrap_or("scene");
                let disposition = format!("attachment; filename=\"{name}-studio.toml\"");
                send(
                    request,
                    200,
                    "application/toml; charset=utf-8",
                    text.into_bytes(),
                    &[("Content-Disposition", disposition)],
                )
            }
            Err(refusal) => refuse(request, &refusal),
        },
        "/api/events" => events(shared, request),
        _ => error(
            request,
            404,
            "no such page: the studio has /, /api/scene, /api/scene.toml, /api/render, \
             /api/pixel, /api/diff and /api/events",
        ),
    }
}

/// Why a render gave no frame.
enum NoFrame {
    /// It waited its whole [`QUEUE_WAIT`] in line.
    Busy,
    /// A newer request of its view superseded it.
    Superseded,
    /// The server is stopping.
    Stopping,
}

/// Say why a render gave no frame.
fn no_frame(request: Request, why: NoFrame, view: Option<&str>) {
    match why {
        NoFrame::Busy => {
            let retry = [("Retry-After", "1".to_string())];
            let body = Refusal {
                status: 503,
                message: format!(
                    "busy: {RENDERS_AT_ONCE} renders at once, and this one waited {} s; \
                     try again",
                    QUEUE_WAIT.as_secs()
                ),
            }
            .json();
            send(request, 503, JSON, body.into_bytes(), &retry)
        }
        NoFrame::Superseded => error(
            request,
            409,
            &format!(
                "cancelled: a newer request of view {} superseded this one",
                view.unwrap_or("?")
            ),
        ),
        NoFrame::Stopping => error(request, 503, "the server is stopping"),
    }
}

/// Wait for a turn and render `job`'s frame, unless `cancel` is set first.
fn frame_of(
    shared: &Shared,
    job: &api::RenderJob,
    cancel: &AtomicBool,
) -> Result<(crate::aov::Frame, f64), NoFrame> {
    let turn = shared
        .gate
        .enter(job.pixels(), Instant::now() + QUEUE_WAIT, cancel);
    let why = || match () {
        () if crate::interrupt::requested() => NoFrame::Stopping,
        () if cancel.load(Ordering::SeqCst) => NoFrame::Superseded,
        () => NoFrame::Busy,
    };
    let Some(turn) = turn else { return Err(why()) };
    let start = Instant::now();
    let frame = turn.run(|| job.frame(cancel));
    let seconds = start.elapsed().as_secs_f64();
    drop(turn);
    match frame {
        Some(frame) if !crate::interrupt::requested() => Ok((frame, seconds)),
        _ => Err(why()),
    }
}

/// `GET /api/diff?a=QUERY&b=QUERY`: `raystep diff`'s figures for the beauty of
/// the two renders, as JSON.
fn diff(shared: &Shared, request: Request, query: &str) {
    let jobs = match shared.studio.diff_jobs(query) {
        Ok(jobs) => jobs,
        Err(refusal) => return refuse(request, &refusal),
    };
    let claim = shared.views.claim(jobs.view.as_deref());
    let mut renders = 0;
    let mut beauty_of = |job: &api::RenderJob| match shared.beauties.get(&job.key) {
        Some(beauty) => Ok(beauty),
        None => frame_of(shared, job, &claim.cancel).map(|(frame, _)| {
            renders += 1;
            shared.beauties.put(&job.key, api::beauty(&frame))
        }),
    };
    let beauties = beauty_of(&jobs.a).and_then(|a| beauty_of(&jobs.b).map(|b| (a, b)));
    match beauties {
        Ok((a, b)) => {
            let mut figures = api::diff_json(&a, &b);
            figures["a_version"] = jobs.a.version.into();
            figures["b_version"] = jobs.b.version.into();
            let body = crate::tools::json::json_text(&figures, true) + "\n";
            let extra = [("X-Raystep-Renders", renders.to_string())];
            send(request, 200, JSON, body.into_bytes(), &extra)
        }
        Err(why) => no_frame(request, why, jobs.view.as_deref()),
    }
}

/// Pixels of beauty kept for `/api/diff` (12 bytes each: about 100 MB).
const BEAUTY_PIXELS: u64 = 4 * 1920 * 1080;

/// The beauty of the latest renders, by their [`api::RenderJob::key`]: the page
/// renders A and B before it asks for their difference, which then needs no
/// render of its own.
#[derive(Default)]
struct Beauties {
    kept: Mutex<VecDeque<(String, Arc<api::Beauty>)>>,
}

impl Beauties {
    fn get(&self, key: &str) -> Option<Arc<api::Beauty>> {
        let kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        kept.iter()
            .find(|(k, _)| k == key)
            .map(|(_, b)| Arc::clone(b))
    }

    /// Keep `beauty` under `key` (the oldest leave to stay within
    /// [`BEAUTY_PIXELS`]), and give it back.
    fn put(&self, key: &str, beauty: api::Beauty) -> Arc<api::Beauty> {
        let beauty = Arc::new(beauty);
        let size = |b: &api::Beauty| b.pixels.len() as u64;
        if size(&beauty) > BEAUTY_PIXELS {
            return beauty;
        }
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        kept.retain(|(k, _)| k != key);
        kept.push_back((key.to_string(), Arc::clone(&beauty)));
        while kept.iter().map(|(_, b)| size(b)).sum::<u64>() > BEAUTY_PIXELS {
            kept.pop_front();
        }
        beauty
    }
}

/// `GET /api/render`: the PNG, or why not.
fn render(shared: &Shared, request: Request, query: &str) {
    let job = match shared.studio.render_job(query) {
        Ok(job) => job,
        Err(refusal) => return refuse(request, &refusal),
    };
    let claim = shared.views.claim(job.view.as_deref());
    let (frame, render_seconds) = match frame_of(shared, &job, &claim.cancel) {
        Ok(done) => done,
        Err(why) => return no_frame(request, why, job.view.as_deref()),
    };
    drop(claim);
    // Kept for a diff, unless too large to keep (then not even copied).
    if job.pixels() <= BEAUTY_PIXELS {
        shared.beauties.put(&job.key, api::beauty(&frame));
    }
    let encoding = Instant::now();
    let png = crate::io::output::png_bytes_as(&frame, job.buffer, job.png);
    let done = api::Rendered {
        png,
        render_seconds,
        encode_seconds: encoding.elapsed().as_secs_f64(),
    };
    let extra = [
        (
            "X-Raystep-Render-Seconds",
            format!("{:.6}", done.render_seconds),
        ),
        (
            "X-Raystep-Encode-Seconds",
            format!("{:.6}", done.encode_seconds),
        ),
        ("X-Raystep-Scene-Version", job.version.to_string()),
        (
            "X-Raystep-Buffers",
            api::buffers_of(job.settings.stages).join(","),
        ),
        (
            "X-Raystep-Size",
            format!("{}x{}", job.scene.width, job.scene.height),
        ),
        // The screen and the eye this render looked through, for the page's
        // drags (each number as Rust prints it: read back, the same f64).
        ("X-Raystep-Screen", {
            let s = job.scene.camera().screen;
            format!("{},{},{},{}", s.left, s.right, s.top, s.bottom)
        }),
        ("X-Raystep-Camera", {
            let [x, y, z] = job.scene.camera.to_array();
            format!("{x},{y},{z}")
        }),
    ];
    send(request, 200, "image/png", done.png, &extra);
}

/// `GET /api/events`: server-sent events, one each time the scene file is
/// reloaded, `data: {"version": N, "error": null or "..."}`, each on a thread of
/// its own. The stream stays open until the client leaves or the server stops.
///
/// tiny_http's responses are buffered (chunks of 8 KiB), which would hold
/// events back, so this answer is written straight to the connection: a
/// status line and headers, then each event, flushed as it happens.
fn events(shared: &Shared, request: Request) {
    // HEAD asks for the head alone: it is answered as any other request, so the
    // connection stays open or closes as the client asked, and opens no stream.
    // (Written by hand, as a stream's head is, it left the socket open under a
    // head saying `Connection: close`.)
    if *request.method() == Method::Head {
        return send(request, 200, "text/event-stream", Vec::new(), &[]);
    }
    let streams = Arc::clone(&shared.streams);
    if streams.fetch_add(1, Ordering::SeqCst) >= MAX_STREAMS {
        streams.fetch_sub(1, Ordering::SeqCst);
        return error(request, 503, "too many event streams are open");
    }
    let studio = Arc::clone(&shared.studio);
    let mut writer = request.into_writer();
    std::thread::spawn(move || {
        let (version, _) = studio.version();
        let head = "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\n\
                    Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n\
                    Connection: close\r\n\r\n";
        let opened = writer
            .write_all(head.as_bytes())
            .and_then(|()| write!(writer, "retry: 1000\n: connected at version {version}\n\n"))
            .and_then(|()| writer.flush());
        if opened.is_ok() {
            stream_events(&studio, writer, version);
        }
        streams.fetch_sub(1, Ordering::SeqCst);
    });
}

/// Write an event for each new version until the server stops or the client
/// goes away.
fn stream_events(studio: &Studio, mut writer: Box<dyn Write + Send>, mut seen: u64) {
    loop {
        let (version, error, stopping) = studio.wait_change(seen, KEEP_ALIVE);
        if stopping {
            return;
        }
        let sent = if version == seen {
            writer.write_all(b": still here\n\n")
        } else {
            seen = version;
            let data = serde_json::json!({ "version": version, "error": error });
            write!(writer, "data: {data}\n\n")
        };
        if sent.and_then(|()| writer.flush()).is_err() {
            return;
        }
    }
}
