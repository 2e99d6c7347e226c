//! `raystep serve`, the studio: the built binary is started on a free port of
//! 127.0.0.1 and spoken to over plain TCP (loopback only), as a browser or a
//! script would. Each endpoint's answer is checked against the command line's
//! own output for the same options; then its safety (the Host header, paths
//! that try to leave the page, bad options), a load of 1,000 requests from 50
//! clients, Ctrl-C, and a fuzz of the query parser (in-process).

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use serde_json::Value;

/// A `raystep serve` process, killed when dropped.
struct Server {
    child: Child,
    port: u16,
}

impl Server {
    /// Start `raystep serve [scene] --port 0` and read the address it prints.
    fn start(scene: Option<&Path>) -> Server {
        Server::start_in(None, scene)
    }

    /// [`Server::start`] in the folder `dir` (a relative `scene` is in it).
    fn start_in(dir: Option<&Path>, scene: Option<&Path>) -> Server {
        Server::start_with(dir, scene, Stdio::null(), &[])
    }

    /// [`Server::start_in`], its standard error to `stderr`, with the options
    /// `extra` after `serve`.
    fn start_with(
        dir: Option<&Path>,
        scene: Option<&Path>,
        stderr: Stdio,
        extra: &[&str],
    ) -> Server {
        let mut command = Command::new(env!("CARGO_BIN_EXE_raystep"));
        if let Some(dir) = dir {
            command.current_dir(dir);
        }
        command.arg("serve").args(extra);
        if let Some(scene) = scene {
            command.arg(scene);
        }
        let mut child = command
            .args(["--port", "0"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(stderr)
            .spawn()
            .unwrap();
        let stdout = child.stdout.take().unwrap();
        let (sender, receiver) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut line = String::new();
            let _ = BufReader::new(stdout).read_line(&mut line);
            let _ = sender.send(line);
        });
        let line = receiver
            .recv_timeout(Duration::from_secs(30))
            .expect("raystep serve prints its address");
        let port = line
            .trim()
            .strip_prefix("http://127.0.0.1:")
            .and_then(|rest| rest.strip_suffix('/'))
            .and_then(|port| port.parse().ok())
            .unwrap_or_else(|| panic!("not an address: {line:?}"));
        Server { child, port }
    }

    /// `GET target` with the right Host header.
    fn get(&self, target: &str) -> Reply {
        get(self.port, target)
    }

    /// Send `request` as it is and read the whole answer.
    fn raw(&self, request: &str) -> Reply {
        exchange(self.port, request)
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// An HTTP answer.
#[derive(Debug)]
struct Reply {
    status: u16,
    headers: Vec<(String, String)>,
    body: Vec<u8>,
}

impl Reply {
    fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }

    fn json(&self) -> Value {
        serde_json::from_slice(&self.body).unwrap_or_else(|e| {
            panic!("{e}: {}", String::from_utf8_lossy(&self.body));
        })
    }

    /// The message of a refusal, `{"error": "..."}`.
    fn error(&self) -> String {
        self.json()["error"].as_str().unwrap().to_string()
    }
}

/// `GET target` from the server on `port`, with the right Host header (from
/// any thread: the port is all it needs).
fn get(port: u16, target: &str) -> Reply {
    get_with(port, target, "")
}

/// `GET target` as [`get`] sends it, with `extra` header lines (each ending in
/// `\r\n`).
fn get_with(port: u16, target: &str, extra: &str) -> Reply {
    exchange(
        port,
        &format!(
            "GET {target} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n{extra}Connection: close\r\n\r\n"
        ),
    )
}

/// Send `request` to 127.0.0.1:`port` and read the answer until the server
/// closes the connection (every request here says `Connection: close`).
fn exchange(port: u16, request: &str) -> Reply {
    let mut stream = TcpStream::connect(("127.0.0.1", port)).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    stream.write_all(request.as_bytes()).unwrap();
    let mut bytes = Vec::new();
    stream.read_to_end(&mut bytes).unwrap();
    parse_reply(&bytes)
}

/// Newer small renders of `view`, one every 50 ms until `running` has finished,
/// each sent from a thread of its own so that one the server has not answered yet
/// never holds the next back (one that came before the running render is
/// superseded by it, and its own render may then wait behind the running one's);
/// their statuses, in the order sent. Fails after two minutes or 1,000 requests.
fn supersede_until_finished<R>(
    port: u16,
    view: &str,
    running: &std::thread::JoinHandle<R>,
) -> Vec<u16> {
    let deadline = Instant::now() + Duration::from_secs(120);
    let target = format!("/api/render?view={view}&width=30&height=20");
    let mut newer = Vec::new();
    while !running.is_finished() {
        assert!(
            Instant::now() < deadline && newer.len() < 1000,
            "the render of view {view} is still running after {} newer requests",
            newer.len()
        );
        let target = target.clone();
        newer.push(std::thread::spawn(move || get(port, &target).status));
        std::thread::sleep(Duration::from_millis(50));
    }
    newer.into_iter().map(|t| t.join().unwrap()).collect()
}

fn parse_reply(bytes: &[u8]) -> Reply {
    let end = bytes
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .unwrap_or_else(|| panic!("no header end in {:?}", String::from_utf8_lossy(bytes)));
    let head = std::str::from_utf8(&bytes[..end]).unwrap();
    let mut lines = head.split("\r\n");
    let status_line = lines.next().unwrap();
    let status = status_line
        .split(' ')
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("status line {status_line:?}"));
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(n, v)| (n.trim().to_string(), v.trim().to_string()))
        .collect();
    let body = bytes[end + 4..].to_vec();
    let reply = Reply {
        status,
        headers,
        body,
    };
    if let Some(length) = reply
        .header("Content-Length")
        .filter(|_| !reply.body.is_empty())
    {
        assert_eq!(length.parse::<usize>().unwrap(), reply.body.len(), "length");
    }
    reply
}

fn raystep(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args(args)
        .output()
        .unwrap()
}

/// A folder with a copy of the built-in scene, as `scene.toml`.
fn scene_folder() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, raystep::io::scene_file::SEED_TOML).unwrap();
    (dir, scene)
}

/// Query strings and the same options as command-line words.
const CASES: [(&str, &[&str]); 6] = [
    ("width=60&height=40", &["--width", "60", "--height", "40"]),
    (
        "stage=shadow&width=60&height=40&buffer=depth",
        &["--stage", "shadow", "--width", "60", "--height", "40"],
    ),
    (
        "without=blinn-phong&precision=f32&width=61&height=37&buffer=normal",
        &[
            "--without",
            "blinn-phong",
            "--precision",
            "f32",
            "--width",
            "61",
            "--height",
            "37",
        ],
    ),
    (
        "stage=plane&without=shadow&without=reflection&width=50&height=30&buffer=object",
        &[
            "--stage",
            "plane",
            "--without",
            "shadow",
            "--without",
            "reflection",
            "--width",
            "50",
            "--height",
            "30",
        ],
    ),
    (
        "tutorial&spp=4&width=40&height=30&buffer=rays",
        &[
            "--tutorial",
            "--spp",
            "4",
            "--width",
            "40",
            "--height",
            "30",
        ],
    ),
    (
        "engine=fast&offset=fixed%3A0&max-depth=5&width=64&height=40&buffer=bounces",
        &[
            "--engine",
            "fast",
            "--offset",
            "fixed:0",
            "--max-depth",
            "5",
            "--width",
            "64",
            "--height",
            "40",
        ],
    ),
];

/// The buffer a case's query asks for.
fn buffer_of(query: &str) -> &str {
    query
        .split('&')
        .find_map(|p| p.strip_prefix("buffer="))
        .unwrap_or("beauty")
}

#[test]
fn render_answers_the_png_the_command_line_writes() {
    let (dir, scene) = scene_folder();
    let server = Server::start(Some(&scene));
    for (i, (query, flags)) in CASES.iter().enumerate() {
        let out = dir.path().join(format!("out{i}"));
        let mut args = vec!["render", scene.to_str().unwrap()];
        args.extend_from_slice(flags);
        args.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let cli = raystep(&args);
        assert!(
            cli.status.success(),
            "{}",
            String::from_utf8_lossy(&cli.stderr)
        );
        let reply = server.get(&format!("/api/render?{query}"));
        assert_eq!(
            reply.status,
            200,
            "{query}: {}",
            String::from_utf8_lossy(&reply.body)
        );
        assert_eq!(reply.header("Content-Type"), Some("image/png"));
        let file = out.join(format!("{}.png", buffer_of(query)));
        let expected = std::fs::read(&file).unwrap();
        assert!(
            reply.body == expected,
            "{query}: the answer ({} bytes) is not {} ({} bytes)",
            reply.body.len(),
            file.display(),
            expected.len()
        );
        assert_eq!(reply.header("X-Raystep-Scene-Version"), Some("1"));
    }
    // No options: the scene's own size, every stage, the beauty buffer.
    let reply = server.get("/api/render");
    assert_eq!(reply.status, 200);
    assert_eq!(reply.header("X-Raystep-Size"), Some("300x200"));
    assert_eq!(
        reply.header("X-Raystep-Buffers"),
        Some("beauty,direction,depth,normal,position,shadow,object,ambient,diffuse,specular,bounces,rays")
    );
}

#[test]
fn pixel_answers_what_explain_json_prints() {
    let (_dir, scene) = scene_folder();
    let server = Server::start(Some(&scene));
    for (query, flags) in CASES {
        for (x, y) in [(0, 0), (20, 17), (30, 25)] {
            let mut args = vec!["explain", scene.to_str().unwrap()];
            let pixel = format!("{x},{y}");
            args.extend_from_slice(&["--pixel", &pixel, "--json"]);
            args.extend_from_slice(flags);
            let cli = raystep(&args);
            assert!(
                cli.status.success(),
                "{}",
                String::from_utf8_lossy(&cli.stderr)
            );
            let options: Vec<&str> = query
                .split('&')
                .filter(|p| !p.starts_with("buffer="))
                .collect();
            let reply = server.get(&format!("/api/pixel?x={x}&y={y}&{}", options.join("&")));
            assert_eq!(
                reply.status,
                200,
                "{query}: {}",
                String::from_utf8_lossy(&reply.body)
            );
            assert_eq!(
                String::from_utf8_lossy(&reply.body),
                String::from_utf8_lossy(&cli.stdout),
                "{query} at ({x}, {y})"
            );
        }
    }
}

#[test]
fn the_scene_is_json_with_a_version_and_the_page_is_served() {
    let server = Server::start(None);
    let scene = server.get("/api/scene").json();
    assert_eq!(scene["version"], 1);
    assert_eq!(scene["error"], Value::Null);
    assert_eq!(scene["file"], "scenes/seed.toml (built in)");
    assert_eq!(scene["scene"]["width"], 300);
    assert_eq!(scene["scene"]["objects"].as_array().unwrap().len(), 4);
    assert_eq!(scene["scene"]["objects"][0]["radius"], 0.7);
    assert_eq!(scene["scene"]["object_count"], 4);
    assert_eq!(server.get("/api/scene?objects=all").json(), scene);
    // The scene as `raystep check --json` gives it, field for field, but for its
    // name (the file's) and the schema.
    let seed = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/seed.toml");
    let check = Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args(["check", seed, "--json"])
        .output()
        .unwrap();
    let mut checked: Value = serde_json::from_slice(&check.stdout).unwrap();
    let mut served = scene["scene"].clone();
    for fields in [&mut checked, &mut served] {
        let fields = fields.as_object_mut().unwrap();
        fields.remove("scene");
        fields.remove("schema");
    }
    assert_eq!(served, checked);
    // What the page asks for: all but the list of objects.
    let brief = server.get("/api/scene?objects=none").json();
    assert_eq!(brief["scene"].get("objects"), None, "{brief}");
    assert_eq!(brief["scene"]["object_count"], 4);
    let mut full = scene.clone();
    full["scene"].as_object_mut().unwrap().remove("objects");
    assert_eq!(brief, full);
    for bad in ["objects=some", "stage=shadow", "objects=none&objects=all"] {
        let reply = server.get(&format!("/api/scene?{bad}"));
        assert_eq!(reply.status, 400, "{bad}");
    }
    let page = server.get("/");
    assert_eq!(page.status, 200);
    assert!(String::from_utf8_lossy(&page.body).contains("raystep studio"));
    assert!(page.header("Content-Security-Policy").is_some());
    for (path, kind) in [
        ("/studio.js", "text/javascript"),
        ("/studio.css", "text/css"),
    ] {
        let reply = server.get(path);
        assert_eq!(reply.status, 200, "{path}");
        assert!(
            reply.header("Content-Type").unwrap().starts_with(kind),
            "{path}"
        );
    }
    // HEAD: the headers alone; other methods are refused.
    let host = format!("127.0.0.1:{}", server.port);
    let head = server.raw(&format!(
        "HEAD /api/scene HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
    ));
    assert_eq!(head.status, 200);
    assert!(head.body.is_empty());
    let post = server.raw(&format!(
        "POST /api/scene HTTP/1.1\r\nHost: {host}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
    ));
    assert_eq!(post.status, 405);
}

/// Run the command line, which must succeed.
fn raystep_ok(args: &[&str]) -> std::process::Output {
    let out = raystep(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn diff_answers_the_figures_raystep_diff_gives_for_the_two_renders() {
    let (dir, scene) = scene_folder();
    let server = Server::start(Some(&scene));
    let s = scene.to_str().unwrap();
    // A: every stage; B: without shadows, in float32.
    let (qa, qb) = (
        "width=60&height=40",
        "width=60&height=40&without=shadow&precision=f32",
    );
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let size = ["--width", "60", "--height", "40"];
    let mut args = vec!["render", s, "--out", a.to_str().unwrap()];
    args.extend_from_slice(&size);
    raystep_ok(&args);
    let mut args = vec!["render", s, "--out", b.to_str().unwrap()];
    args.extend_from_slice(&size);
    args.extend_from_slice(&["--without", "shadow", "--precision", "f32"]);
    raystep_ok(&args);
    let cli = raystep(&[
        "diff",
        a.join("buffers.exr").to_str().unwrap(),
        b.join("buffers.exr").to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(cli.status.code(), Some(1), "different");
    let cli: Value = serde_json::from_slice(&cli.stdout).unwrap();
    let encode_side = |q: &str| q.replace('=', "%3D").replace('&', "%26");
    let reply = server.get(&format!(
        "/api/diff?a={}&b={}",
        encode_side(qa),
        encode_side(qb)
    ));
    assert_eq!(
        reply.status,
        200,
        "{}",
        String::from_utf8_lossy(&reply.body)
    );
    let api = reply.json();
    for key in std::iter::once("schema").chain(common::DIFF_FIGURES) {
        assert_eq!(api[key], cli[key], "{key}");
    }
    assert!(api["over_one_step"].as_u64().unwrap() > 100);
    assert_eq!(api["a_version"], 1);
    // Both were rendered for it; their beauty is kept for the next.
    assert_eq!(reply.header("X-Raystep-Renders"), Some("2"));
    // A against itself: nothing differs, and nothing is rendered again.
    let same = server.get(&format!("/api/diff?a={0}&b={0}", encode_side(qa)));
    assert_eq!(same.header("X-Raystep-Renders"), Some("0"));
    let same = same.json();
    assert_eq!(same["over_one_step"], 0);
    assert_eq!(same["rmse"], 0.0);
    assert_eq!(same["different"], false);
    // A render the page asked for is kept too: its diff renders only the other.
    let qc = "width=60&height=40&stage=shadow";
    assert_eq!(
        server.get(&format!("/api/render?{qc}&buffer=depth")).status,
        200
    );
    let third = server.get(&format!(
        "/api/diff?a={}&b={}",
        encode_side(qc),
        encode_side("width=60&height=40&tutorial")
    ));
    assert_eq!(third.status, 200);
    assert_eq!(third.header("X-Raystep-Renders"), Some("1"));
    // Refusals: two sizes, a side missing, a bad option on one side (named).
    let sizes = server.get(&format!(
        "/api/diff?a={}&b=width%3D61%26height%3D40",
        encode_side(qa)
    ));
    assert_eq!(sizes.status, 400);
    assert_eq!(
        sizes.error(),
        "a is 60 × 40 but b is 61 × 40: only renders of one size compare"
    );
    let missing = server.get(&format!("/api/diff?a={}", encode_side(qa)));
    assert_eq!(missing.status, 400);
    assert!(missing.error().starts_with("give the two renders"));
    let bad = server.get(&format!("/api/diff?a={}&b=spp%3D3", encode_side(qa)));
    assert_eq!(bad.status, 400);
    assert!(bad.error().starts_with("b: "), "{}", bad.error());
    let stray = server.get("/api/diff?a=&b=&width=3");
    assert_eq!(stray.status, 400);
}

#[test]
fn the_light_and_the_camera_moved_render_and_save_as_the_scene_file_does() {
    let (dir, scene) = scene_folder();
    let server = Server::start(Some(&scene));
    let moved = "light=1.5,4,-2&camera=0.25,-0.1,1";
    let saved = server.get(&format!("/api/scene.toml?{moved}"));
    assert_eq!(
        saved.status,
        200,
        "{}",
        String::from_utf8_lossy(&saved.body)
    );
    assert!(saved
        .header("Content-Disposition")
        .unwrap()
        .starts_with("attachment; filename=\"scene-studio.toml\""));
    // The file's own lines, comments too, with the two positions replaced.
    let text = String::from_utf8(saved.body.clone()).unwrap();
    let seed = raystep::io::scene_file::SEED_TOML;
    let expected = seed
        .replace("position = [5, 5, 5]", "position = [1.5, 4.0, -2.0]")
        .replace("position = [0, 0, 1]", "position = [0.25, -0.1, 1.0]");
    assert_eq!(text, expected);
    // A scene without the tables gets them, at the end.
    let light_only = raystep::tools::serve::api::Edits {
        light: Some([1.0, 2.0, 3.0]),
        camera: None,
    };
    let bare = light_only
        .apply(
            "[[sphere]]\ncenter = [0, 0, -1]\nradius = 0.5\n",
            "bare.toml",
        )
        .unwrap();
    assert!(
        bare.ends_with("\n[light]\nposition = [1.0, 2.0, 3.0]\n"),
        "{bare}"
    );
    // A position written over several lines: the text is written again.
    let spread = light_only
        .apply(
            "[light]\nposition = [\n  5,\n  5,\n  5,\n]\n",
            "spread.toml",
        )
        .unwrap();
    let table: toml::Table = spread.parse().unwrap();
    assert_eq!(table["light"]["position"].as_array().unwrap().len(), 3);
    assert_eq!(table["light"]["position"][0].as_float(), Some(1.0));
    let path = dir.path().join("saved.toml");
    std::fs::write(&path, &saved.body).unwrap();
    let p = path.to_str().unwrap();
    // The saved file says what the page changed, and renders as the API did.
    let check = raystep_ok(&["check", p, "--json"]);
    let check: Value = serde_json::from_slice(&check.stdout).unwrap();
    let text = check.to_string();
    assert!(text.contains("1.5") && text.contains("0.25"), "{text}");
    let out = dir.path().join("out");
    raystep_ok(&[
        "render",
        p,
        "--width",
        "60",
        "--height",
        "40",
        "--out",
        out.to_str().unwrap(),
    ]);
    let reply = server.get(&format!("/api/render?{moved}&width=60&height=40"));
    assert_eq!(reply.status, 200);
    assert!(reply.body == std::fs::read(out.join("beauty.png")).unwrap());
    let unmoved = server.get("/api/render?width=60&height=40");
    assert!(reply.body != unmoved.body, "the move changes the picture");
    // The pixel's story too.
    let cli = raystep_ok(&[
        "explain", p, "--pixel", "30,20", "--json", "--width", "60", "--height", "40",
    ]);
    let story = server.get(&format!("/api/pixel?x=30&y=20&{moved}&width=60&height=40"));
    assert_eq!(
        String::from_utf8_lossy(&story.body),
        String::from_utf8_lossy(&cli.stdout)
    );
    // No change: the file's own text, as it is.
    let plain = server.get("/api/scene.toml");
    assert_eq!(plain.body, raystep::io::scene_file::SEED_TOML.as_bytes());
    for bad in [
        "light=1,2",
        "light=1,2,nan",
        "camera=a,b,c",
        "light=1e9,0,0",
        "width=3",
    ] {
        let reply = server.get(&format!("/api/scene.toml?{bad}"));
        assert_eq!(reply.status, 400, "{bad}");
        assert!(!reply.error().is_empty());
    }
    assert_eq!(server.get("/api/render?light=1,2").status, 400);
    // A light moved into a sphere: the message names the light and the sphere,
    // but no line of the file, whose text the move is not.
    let inside = server.get("/api/render?light=-0.2,0,-1");
    assert_eq!(inside.status, 400);
    let said = inside.error();
    assert!(
        said.contains("light.position [-0.2, 0, -1] is inside [[sphere]] number 1"),
        "{said}"
    );
    assert!(!said.contains("line "), "{said}");
}

/// Two renders at once each have threads of their own: a small render of one
/// view is answered while a large one of another view still runs. (In one
/// shared pool the small one waited for all the large one's rows.)
#[test]
fn a_small_render_is_not_held_up_by_a_large_one() {
    let server = Server::start(None);
    let port = server.port;
    let request = move |query: &str| get(port, &format!("/api/render?{query}"));
    // Half a minute in a debug build, were it not cancelled.
    let large = std::thread::spawn(move || request("view=a&width=1920&height=1080&spp=256"));
    std::thread::sleep(Duration::from_millis(500));
    let asked = Instant::now();
    let small = request("view=b&width=30&height=20");
    let took = asked.elapsed();
    assert_eq!(small.status, 200);
    // Milliseconds on threads of its own; behind the large one's rows, about
    // as long as the large render itself.
    assert!(
        took < Duration::from_secs(5),
        "the small render took {took:?}"
    );
    // Only now is the large one superseded: it was still rendering, so it is
    // cancelled (it would be 200 had it finished first).
    let statuses = supersede_until_finished(port, "a", &large);
    let large = large.join().unwrap();
    assert_eq!(
        large.status,
        409,
        "{}",
        String::from_utf8_lossy(&large.body)
    );
    for status in statuses {
        assert!([200, 409].contains(&status));
    }
}

#[test]
fn a_render_a_newer_request_of_its_view_supersedes_is_cancelled() {
    let server = Server::start(None);
    let port = server.port;
    // A render of minutes (1920 × 1080, 64 samples a pixel, in a debug build).
    let slow = std::thread::spawn(move || {
        let started = Instant::now();
        let reply = get(port, "/api/render?view=main&width=1920&height=1080&spp=64");
        (reply, started.elapsed())
    });
    // Newer renders of the same view until the slow one has answered: one of
    // them comes after it started and supersedes it. (Sent each from a thread of
    // its own: a loop that waited for one superseded by the slow render, its own
    // render behind the slow one's rows, sent nothing more, and the slow render
    // ran to its end; CI saw that once.)
    let statuses = supersede_until_finished(port, "main", &slow);
    let (reply, took) = slow.join().unwrap();
    assert_eq!(
        reply.status,
        409,
        "{}",
        String::from_utf8_lossy(&reply.body)
    );
    assert_eq!(
        reply.error(),
        "cancelled: a newer request of view main superseded this one"
    );
    eprintln!(
        "superseded after {took:?}, {} newer requests",
        statuses.len()
    );
    // Each newer one was answered with its frame or superseded in turn, and the
    // one claimed last had nothing after it: some frame came back. A request
    // after them all is superseded by nothing.
    assert!(
        statuses.iter().all(|s| [200, 409].contains(s)),
        "{statuses:?}"
    );
    assert!(statuses.contains(&200), "{statuses:?}");
    assert_eq!(
        server
            .get("/api/render?view=main&width=30&height=20")
            .status,
        200
    );
    // Other views, and requests without one, are left alone.
    assert_eq!(
        server
            .get("/api/render?view=other&width=30&height=20")
            .status,
        200
    );
    assert_eq!(server.get("/api/render?view=a%20b").status, 400);
}

/// The seam the server cancels through: once the flag is set no row starts, and
/// `render_cancellable` answers none; never cancelled, it gives the plain
/// render's frame, every row told.
#[test]
fn a_cancelled_render_stops_taking_rows() {
    use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
    for engine in [raystep::stages::Engine::Book, raystep::stages::Engine::Fast] {
        let scene = common::seed(64, 400);
        let mut settings: raystep::render::Settings = raystep::stages::Stages::ALL.into();
        settings.engine = engine;
        // Cancelled as soon as the first row is finished.
        let (rows, cancel) = (AtomicU64::new(0), AtomicBool::new(false));
        let after_one = || {
            rows.fetch_add(1, Ordering::SeqCst);
            cancel.store(true, Ordering::SeqCst);
        };
        let frame = raystep::engine::render_cancellable(&scene, &settings, &cancel, &after_one);
        assert!(frame.is_none(), "{engine:?}");
        // Each thread finishes at most the row it had started.
        let done = rows.load(Ordering::SeqCst);
        assert!(
            (1..=rayon::current_num_threads() as u64).contains(&done),
            "{engine:?}: {done} rows of 400 after the cancel"
        );
        let (rows, never) = (AtomicU64::new(0), AtomicBool::new(false));
        let count = || {
            rows.fetch_add(1, Ordering::SeqCst);
        };
        let whole = raystep::engine::render_cancellable(&scene, &settings, &never, &count)
            .expect("finished");
        assert_eq!(rows.load(Ordering::SeqCst), 400, "{engine:?}");
        let plain = raystep::engine::render(&scene, &settings, &|_| {});
        assert!(whole.pixels == plain.pixels, "{engine:?}");
    }
}

/// `render_cancellable` with the flag already set starts no row, with either
/// engine.
#[test]
fn a_render_cancelled_before_it_starts_traces_no_row() {
    use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
    for engine in [raystep::stages::Engine::Book, raystep::stages::Engine::Fast] {
        let scene = common::seed(64, 400);
        let mut settings: raystep::render::Settings = raystep::stages::Stages::ALL.into();
        settings.engine = engine;
        let (rows, cancelled) = (AtomicU64::new(0), AtomicBool::new(true));
        let count = || {
            rows.fetch_add(1, Ordering::SeqCst);
        };
        let frame = raystep::engine::render_cancellable(&scene, &settings, &cancelled, &count);
        assert!(frame.is_none(), "{engine:?}");
        assert_eq!(rows.load(Ordering::SeqCst), 0, "{engine:?}");
    }
}

/// The command line's message for `args`, as it prints it on stderr (without
/// `error: `), and its exit code, which must be 2.
fn cli_error(args: &[&str]) -> String {
    let out = raystep(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    let text = stderr.trim_end();
    text.strip_prefix("error: ").unwrap_or(text).to_string()
}

#[test]
fn a_bad_option_is_400_with_the_command_lines_message_and_the_server_keeps_serving() {
    let (dir, scene) = scene_folder();
    let server = Server::start(Some(&scene));
    let s = scene.to_str().unwrap();
    let out = dir.path().join("never");
    let o = out.to_str().unwrap();
    let cases: [(&str, Vec<&str>); 9] = [
        // clap's messages show the usage of what was given: no scene file here.
        (
            "precision=f16",
            vec!["render", "--precision", "f16", "--out", o],
        ),
        ("stage=nope", vec!["render", "--stage", "nope", "--out", o]),
        (
            "stage=shadow&without=plane",
            vec![
                "render",
                s,
                "--stage",
                "shadow",
                "--without",
                "plane",
                "--out",
                o,
            ],
        ),
        (
            "without=intersection",
            vec!["render", s, "--without", "intersection", "--out", o],
        ),
        ("width=0", vec!["render", s, "--width", "0", "--out", o]),
        (
            "width=9000&height=9000",
            vec![
                "render", s, "--width", "9000", "--height", "9000", "--out", o,
            ],
        ),
        ("spp=3", vec!["render", s, "--spp", "3", "--out", o]),
        (
            "max-depth=65",
            vec!["render", s, "--max-depth", "65", "--out", o],
        ),
        ("pixel=1,2", vec!["render", "--pixel", "1,2", "--out", o]),
    ];
    for (query, args) in cases {
        let reply = server.get(&format!("/api/render?{query}"));
        assert_eq!(reply.status, 400, "{query}");
        assert_eq!(reply.error(), cli_error(&args), "{query}");
        assert_eq!(
            server.get("/api/scene").status,
            200,
            "still up after {query}"
        );
    }
    // explain's own refusals.
    let explain = [
        (
            "x=300&y=0",
            vec!["explain", s, "--pixel", "300,0", "--json"],
        ),
        ("x=a&y=1", vec!["explain", "--pixel", "a,1", "--json"]),
        (
            "x=1&y=2&buffer=beauty",
            vec!["explain", "--pixel", "1,2", "--json", "--buffer", "beauty"],
        ),
    ];
    for (query, args) in explain {
        let reply = server.get(&format!("/api/pixel?{query}"));
        assert_eq!(reply.status, 400, "{query}");
        assert_eq!(reply.error(), cli_error(&args), "{query}");
    }
    // The API's own refusals.
    for (path, words) in [
        (
            "/api/render?stage=rays&buffer=depth",
            "a render of rays has no depth buffer",
        ),
        ("/api/render?buffer=colour", "buffer=colour: no such buffer"),
        (
            "/api/render?out=%2Ftmp%2Fx",
            "`out` is not an option of the API",
        ),
        ("/api/render?Stage=plane", "`Stage` is not an option"),
        ("/api/render?--stage=plane", "is not an option"),
        ("/api/pixel?x=1", "give the pixel as x=X&y=Y"),
        (
            "/api/render?buffer=depth&buffer=beauty",
            "`buffer` is given more than once",
        ),
    ] {
        let reply = server.get(path);
        assert_eq!(reply.status, 400, "{path}");
        assert!(reply.error().contains(words), "{path}: {}", reply.error());
    }
    assert!(!out.exists(), "nothing is written");
}

/// The address the server prints is a text it formats itself, so the tests that
/// connect to it would pass whatever it bound: here the other loopback addresses
/// must be refused. (On Linux every address of 127.0.0.0/8 is this machine, so a
/// server bound to 0.0.0.0, or to 127.0.0.2, would accept there.)
#[test]
fn the_studio_listens_on_127_0_0_1_only() {
    let server = Server::start(None);
    let port = server.port;
    assert_eq!(server.get("/api/scene").status, 200, "127.0.0.1 is served");
    for other in ["127.0.0.2", "127.1.2.3"] {
        assert!(
            TcpStream::connect_timeout(
                &format!("{other}:{port}").parse().unwrap(),
                Duration::from_secs(5)
            )
            .is_err(),
            "{other}:{port} accepts a connection: the studio must listen on 127.0.0.1 only"
        );
    }
}

#[test]
fn a_request_for_another_host_is_421() {
    let server = Server::start(None);
    let port = server.port;
    for host in [
        format!("evil.example:{port}"),
        format!("127.0.0.1:{}", port.wrapping_add(1)),
        "127.0.0.1".to_string(),
        format!("localhost.evil.example:{port}"),
        format!("[::1]:{port}"),
    ] {
        let reply = server.raw(&format!(
            "GET /api/scene HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
        ));
        assert_eq!(reply.status, 421, "{host}");
        assert!(reply.error().contains("Host"), "{host}");
    }
    // No Host at all, and two of them.
    let none = server.raw("GET /api/scene HTTP/1.0\r\n\r\n");
    assert_eq!(none.status, 421);
    let two = server.raw(&format!(
        "GET /api/scene HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nHost: evil.example\r\nConnection: close\r\n\r\n"
    ));
    assert_eq!(two.status, 421);
    // localhost is this server too; a request another site's page makes is not.
    let local = server.raw(&format!(
        "GET /api/scene HTTP/1.1\r\nHost: LocalHost:{port}\r\nConnection: close\r\n\r\n"
    ));
    assert_eq!(local.status, 200);
    let cross = get_with(
        port,
        "/api/render?width=8&height=8",
        "Sec-Fetch-Site: cross-site\r\n",
    );
    assert_eq!(cross.status, 403);
}

#[test]
fn paths_that_leave_the_page_are_404() {
    let server = Server::start(None);
    for target in [
        "/../Cargo.toml",
        "/%2e%2e/",
        "/%2e%2e/Cargo.toml",
        "/%2E%2E%2FCargo.toml",
        "/..%2fCargo.toml",
        "//etc/passwd",
        "/etc/passwd",
        "/api/../Cargo.toml",
        "/studio.js/../../Cargo.toml",
        "/assets/studio/studio.js",
        "/src/main.rs",
        "/api/render/../../Cargo.toml",
        "/%00",
        "http://127.0.0.1/../Cargo.toml",
    ] {
        let reply = server.get(target);
        assert_eq!(reply.status, 404, "{target}");
        let body = String::from_utf8_lossy(&reply.body);
        assert!(
            !body.contains("[package]") && !body.contains("root:"),
            "{target}: {body}"
        );
    }
}

/// Read what `stream` has sent into `seen`, if anything came before its read
/// timeout; fail if it closed.
fn read_some(stream: &mut TcpStream, seen: &mut Vec<u8>) {
    let mut chunk = [0; 4096];
    match stream.read(&mut chunk) {
        Ok(0) => panic!("the stream closed: {:?}", String::from_utf8_lossy(seen)),
        Ok(n) => seen.extend_from_slice(&chunk[..n]),
        Err(e)
            if matches!(
                e.kind(),
                std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
            ) => {}
        Err(e) => panic!("{e}"),
    }
}

/// Read from `stream` into `seen` until it holds `needle` after `from`, or fail
/// after `timeout`.
fn read_until(
    stream: &mut TcpStream,
    seen: &mut Vec<u8>,
    from: usize,
    needle: &str,
    timeout: Duration,
) {
    let deadline = Instant::now() + timeout;
    let found =
        |seen: &[u8]| String::from_utf8_lossy(&seen[from.min(seen.len())..]).contains(needle);
    while !found(seen) {
        assert!(
            Instant::now() < deadline,
            "no {needle:?} in {:?}",
            String::from_utf8_lossy(seen)
        );
        read_some(stream, seen);
    }
}

#[test]
fn saving_the_scene_reloads_it_with_an_event_and_a_broken_file_keeps_the_last_good_scene() {
    let (_dir, scene) = scene_folder();
    let server = Server::start(Some(&scene));
    let mut events = TcpStream::connect(("127.0.0.1", server.port)).unwrap();
    events
        .set_read_timeout(Some(Duration::from_millis(200)))
        .unwrap();
    write!(
        events,
        "GET /api/events HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n\r\n",
        server.port
    )
    .unwrap();
    let mut seen = Vec::new();
    let wait = Duration::from_secs(10);
    read_until(
        &mut events,
        &mut seen,
        0,
        ": connected at version 1\n\n",
        wait,
    );
    let head = String::from_utf8_lossy(&seen).to_string();
    assert!(head.starts_with("HTTP/1.1 200 OK\r\n"), "{head}");
    assert!(
        head.contains("Content-Type: text/event-stream\r\n"),
        "{head}"
    );
    let before = server.get("/api/render?width=60&height=40").body;

    // A change: an event within a second, a new version, a new picture.
    let text = raystep::io::scene_file::SEED_TOML;
    assert!(text.contains("radius = 0.7"));
    let saved = Instant::now();
    std::fs::write(&scene, text.replace("radius = 0.7", "radius = 0.5")).unwrap();
    let mark = seen.len();
    read_until(
        &mut events,
        &mut seen,
        mark,
        "data: {\"error\":null,\"version\":2}\n\n",
        wait,
    );
    assert!(
        saved.elapsed() < Duration::from_secs(2),
        "{:?}",
        saved.elapsed()
    );
    let json = server.get("/api/scene").json();
    assert_eq!(json["version"], 2);
    assert_eq!(json["scene"]["objects"][0]["radius"], 0.5);
    let after = server.get("/api/render?width=60&height=40");
    assert_eq!(after.header("X-Raystep-Scene-Version"), Some("2"));
    assert_ne!(after.body, before, "the picture follows the file");

    // A broken file: the event and /api/scene carry the command line's message,
    // and the last good scene is still rendered.
    let broken = text.replace("radius = 0.7", "radius = -1");
    std::fs::write(&scene, &broken).unwrap();
    let cli = cli_error(&["check", scene.to_str().unwrap()]);
    let mark = seen.len();
    read_until(&mut events, &mut seen, mark, "\"version\":3}\n\n", wait);
    let event = String::from_utf8_lossy(&seen[mark..]).to_string();
    let data: Value = serde_json::from_str(
        event
            .lines()
            .find_map(|l| l.strip_prefix("data: "))
            .unwrap(),
    )
    .unwrap();
    assert_eq!(data["error"], cli.as_str());
    let json = server.get("/api/scene").json();
    assert_eq!(json["version"], 3);
    assert_eq!(json["error"], cli.as_str());
    assert_eq!(json["scene"]["objects"][0]["radius"], 0.5);
    assert_eq!(
        server.get("/api/render?width=60&height=40").body,
        after.body
    );

    // Mended: version 4, no error.
    std::fs::write(&scene, text).unwrap();
    let mark = seen.len();
    read_until(
        &mut events,
        &mut seen,
        mark,
        "data: {\"error\":null,\"version\":4}\n\n",
        wait,
    );
    assert_eq!(server.get("/api/render?width=60&height=40").body, before);
}

#[test]
fn load_of_1000_requests_from_50_clients_is_answered_and_the_server_stays_up() {
    const CLIENTS: usize = 50;
    const EACH: usize = 20;
    let server = Server::start(None);
    let port = server.port;
    let started = Instant::now();
    let threads: Vec<_> = (0..CLIENTS)
        .map(|client| {
            std::thread::spawn(move || {
                let mut latencies = Vec::new();
                for i in 0..EACH {
                    let n = client * EACH + i;
                    let host = format!("127.0.0.1:{port}");
                    let get = |target: &str| {
                        format!("GET {target} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n")
                    };
                    let stages = ["rays", "intersection", "shadow", "blinn-phong", "reflection", "plane"];
                    let (request, expected): (String, &[u16]) = match n % 10 {
                        0..=3 => (
                            get(&format!("/api/render?stage={}&width=60&height=40", stages[n % 6])),
                            &[200],
                        ),
                        4 => (get(&format!("/api/pixel?x={}&y={}&width=60&height=40", n % 60, n % 40)), &[200]),
                        5 => (get("/api/scene"), &[200]),
                        6 => (get(&format!("/api/render?precision=f{n}&width=60&height=40")), &[400]),
                        7 => (
                            format!("GET /api/scene HTTP/1.1\r\nHost: evil.example:{port}\r\nConnection: close\r\n\r\n"),
                            &[421],
                        ),
                        8 => (get("/%2e%2e/%2e%2e/etc/passwd"), &[404]),
                        // Not HTTP at all: tiny_http answers 400 and closes.
                        _ => ("NONSENSE\r\n\r\n".to_string(), &[400]),
                    };
                    let start = Instant::now();
                    let reply = exchange(port, &request);
                    latencies.push((start.elapsed(), reply.status));
                    assert!(
                        expected.contains(&reply.status),
                        "request {n}: {} for {request:?}",
                        reply.status
                    );
                }
                latencies
            })
        })
        .collect();
    let mut latencies: Vec<(Duration, u16)> = Vec::new();
    for thread in threads {
        latencies.extend(thread.join().expect("every request is answered"));
    }
    let seconds = started.elapsed().as_secs_f64();
    assert_eq!(latencies.len(), CLIENTS * EACH);
    let mut statuses = std::collections::BTreeMap::new();
    for (_, status) in &latencies {
        *statuses.entry(*status).or_insert(0) += 1;
    }
    // 600 answered, 100 bad options and 100 not HTTP refused with 400, 100
    // foreign hosts with 421, 100 paths out of the page with 404.
    assert_eq!(
        statuses,
        [(200, 600), (400, 200), (404, 100), (421, 100)].into()
    );
    latencies.sort();
    eprintln!(
        "load: {} requests from {CLIENTS} clients in {seconds:.2} s: {:.0} requests/s, \
         median {:?}, max {:?}; statuses {statuses:?}",
        latencies.len(),
        latencies.len() as f64 / seconds,
        latencies[latencies.len() / 2].0,
        latencies.last().unwrap().0
    );
    // Still up, and still right.
    let scene = server.get("/api/scene");
    assert_eq!(scene.status, 200);
    assert_eq!(server.get("/api/render?width=60&height=40").status, 200);
}

/// Stop `server` as Ctrl-C does, and wait for it to end: its exit code.
fn interrupt(server: &mut Server) -> Option<i32> {
    let pid = server.child.id().to_string();
    let kill = Command::new("kill").args(["-INT", &pid]).status().unwrap();
    assert!(kill.success());
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Some(status) = server.child.try_wait().unwrap() {
            break status;
        }
        assert!(Instant::now() < deadline, "still running after Ctrl-C");
        std::thread::sleep(Duration::from_millis(20));
    };
    status.code()
}

#[test]
fn ctrl_c_stops_the_server_with_exit_code_130() {
    let log = tempfile::NamedTempFile::new().unwrap();
    let mut server = Server::start_with(None, None, log.reopen().unwrap().into(), &[]);
    assert_eq!(server.get("/api/scene").status, 200);
    assert_eq!(interrupt(&mut server), Some(130));
    assert!(
        TcpStream::connect(("127.0.0.1", server.port)).is_err(),
        "closed"
    );
    // It says it stopped, not what a render interrupted says (it wrote nothing).
    let said = std::fs::read_to_string(log.path()).unwrap();
    assert!(said.starts_with("serving scenes/seed.toml (built in) on http://127.0.0.1:"));
    assert!(
        said.ends_with("interrupted: the studio stopped (every answer under way was finished)\n"),
        "{said}"
    );
}

#[test]
fn quiet_leaves_out_the_serving_line() {
    // -q silences status lines, the studio's address on standard error among
    // them (standard output still gives it, for a script to read).
    let log = tempfile::NamedTempFile::new().unwrap();
    let mut server = Server::start_with(None, None, log.reopen().unwrap().into(), &["-q"]);
    assert_eq!(server.get("/api/scene").status, 200);
    assert_eq!(interrupt(&mut server), Some(130));
    let said = std::fs::read_to_string(log.path()).unwrap();
    assert_eq!(
        said,
        "error: interrupted: the studio stopped (every answer under way was finished)\n"
    );
}

#[test]
fn the_host_header_is_checked_exactly() {
    use raystep::tools::serve::host_allowed;
    assert!(host_allowed("127.0.0.1:8123", 8123));
    assert!(host_allowed("localhost:8123", 8123));
    assert!(host_allowed("LOCALHOST:8123", 8123));
    for host in [
        "127.0.0.1",
        "localhost",
        "127.0.0.1:81230",
        "127.0.0.1:8123.evil",
        "evil:8123",
        " 127.0.0.1:8123",
    ] {
        assert!(!host_allowed(host, 8123), "{host}");
    }
}

/// The API's answers are JSON, refusals too, and say so; nothing it answers is
/// kept by a cache (a scene file changes under the same URL), nor sniffed as
/// another type.
#[test]
fn api_answers_are_json_and_never_cached() {
    let server = Server::start(None);
    for (target, status) in [
        ("/api/scene", 200),
        ("/api/pixel?x=1&y=1&width=8&height=8", 200),
        ("/api/render?spp=3", 400),
        ("/api/nothing", 404),
    ] {
        let reply = server.get(target);
        assert_eq!(reply.status, status, "{target}");
        assert_eq!(
            reply.header("Content-Type"),
            Some("application/json; charset=utf-8"),
            "{target}"
        );
        assert_eq!(reply.header("Cache-Control"), Some("no-store"), "{target}");
        assert_eq!(
            reply.header("X-Content-Type-Options"),
            Some("nosniff"),
            "{target}"
        );
        reply.json();
    }
    let png = server.get("/api/render?width=8&height=8");
    assert_eq!(png.header("Cache-Control"), Some("no-store"));
}

/// The page is `/` and `/index.html` alike ("the page's three files"), and no
/// other site may show it in a frame (`X-Frame-Options: DENY`, as its policy's
/// `frame-ancestors 'none'`).
#[test]
fn the_page_is_also_index_html_and_is_never_framed() {
    let server = Server::start(None);
    let root = server.get("/");
    let index = server.get("/index.html");
    assert_eq!(index.status, 200);
    assert_eq!(index.body, root.body);
    assert_eq!(
        index.header("Content-Type"),
        Some("text/html; charset=utf-8")
    );
    for page in [&root, &index] {
        assert_eq!(page.header("X-Frame-Options"), Some("DENY"));
        assert!(page
            .header("Content-Security-Policy")
            .unwrap()
            .contains("frame-ancestors 'none'"));
    }
}

/// A 405 says which methods are answered: HTTP requires its `Allow` header
/// (RFC 9110, 15.5.6), and the README says GET and HEAD.
#[test]
fn a_refused_method_is_405_with_the_allowed_ones() {
    let server = Server::start(None);
    let port = server.port;
    for method in ["POST", "PUT", "DELETE", "OPTIONS"] {
        let reply = server.raw(&format!(
            "{method} /api/scene HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
        ));
        assert_eq!(reply.status, 405, "{method}");
        assert_eq!(reply.header("Allow"), Some("GET, HEAD"), "{method}");
        assert!(reply.error().contains("GET"), "{method}");
    }
}

/// `Sec-Fetch-Site`: the page's own requests (`same-origin`) and an address
/// typed in (`none`) are answered; a page of any other origin, even a sibling
/// subdomain (`same-site`), gets 403 (README, "Safety").
#[test]
fn only_the_page_itself_or_a_typed_address_passes_sec_fetch_site() {
    let server = Server::start(None);
    for (site, status) in [
        ("same-origin", 200),
        ("none", 200),
        ("same-site", 403),
        ("cross-site", 403),
    ] {
        let reply = get_with(
            server.port,
            "/api/scene",
            &format!("Sec-Fetch-Site: {site}\r\n"),
        );
        assert_eq!(reply.status, status, "{site}");
    }
}

/// The saved scene's name is the file's, with `-studio.toml`, when that name
/// is plain (letters, digits, `-`, `_`, `.`); any other name, a quote in it
/// say, which would end the header's quoted filename, gives `scene-studio.toml`.
#[test]
fn the_saved_scene_is_named_after_a_plainly_named_file_only() {
    let dir = tempfile::tempdir().unwrap();
    for (file, saved) in [
        ("my.scene_1-a.toml", "my.scene_1-a-studio.toml"),
        ("a\"b.toml", "scene-studio.toml"),
        ("two words.toml", "scene-studio.toml"),
    ] {
        let path = dir.path().join(file);
        std::fs::write(&path, raystep::io::scene_file::SEED_TOML).unwrap();
        let server = Server::start(Some(&path));
        let reply = server.get("/api/scene.toml?light=1,2,3");
        assert_eq!(reply.status, 200, "{file}");
        assert_eq!(
            reply.header("Content-Disposition"),
            Some(format!("attachment; filename=\"{saved}\"").as_str()),
            "{file}"
        );
        assert_eq!(
            reply.header("Content-Type"),
            Some("application/toml; charset=utf-8")
        );
    }
}

/// Open `/api/events` on `port` with `method`; the stream, and what it has
/// sent once `needle` is in it.
fn open_events(port: u16, method: &str, needle: &str) -> (TcpStream, Vec<u8>) {
    let mut stream = TcpStream::connect(("127.0.0.1", port)).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_millis(200)))
        .unwrap();
    write!(
        stream,
        "{method} /api/events HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut seen = Vec::new();
    read_until(&mut stream, &mut seen, 0, needle, Duration::from_secs(10));
    (stream, seen)
}

/// Read what `stream` sends for `time` (it must stay open).
fn read_for(stream: &mut TcpStream, seen: &mut Vec<u8>, time: Duration) {
    let deadline = Instant::now() + time;
    while Instant::now() < deadline {
        read_some(stream, seen);
    }
}

/// HEAD of the event stream is its head alone, closed at once when the client
/// asks (HTTP: a HEAD's answer has no body), and opens no stream: 40 of them in
/// a row, more than the 32 streams open at once, are each answered. Without
/// `Connection: close` the connection stays open for the next request, and the
/// head does not say it closes. A 33rd open stream gets 503 until one closes.
#[test]
fn event_streams_are_at_most_32_and_a_head_opens_none() {
    let server = Server::start(None);
    let port = server.port;
    for n in 0..40 {
        let (mut stream, mut seen) = open_events(port, "HEAD", "\r\n\r\n");
        let deadline = Instant::now() + Duration::from_secs(10);
        loop {
            let mut chunk = [0; 4096];
            match stream.read(&mut chunk) {
                Ok(0) => break,
                Ok(k) => seen.extend_from_slice(&chunk[..k]),
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                    ) =>
                {
                    assert!(Instant::now() < deadline, "HEAD {n}: not closed");
                }
                Err(e) => panic!("{e}"),
            }
        }
        let text = String::from_utf8_lossy(&seen);
        assert!(text.starts_with("HTTP/1.1 200 OK\r\n"), "HEAD {n}: {text}");
        assert!(text.ends_with("\r\n\r\n"), "HEAD {n}: a body: {text:?}");
    }
    let mut kept = TcpStream::connect(("127.0.0.1", port)).unwrap();
    kept.set_read_timeout(Some(Duration::from_millis(200)))
        .unwrap();
    let host = format!("Host: 127.0.0.1:{port}");
    write!(kept, "HEAD /api/events HTTP/1.1\r\n{host}\r\n\r\n").unwrap();
    let mut seen = Vec::new();
    read_until(&mut kept, &mut seen, 0, "\r\n\r\n", Duration::from_secs(10));
    let head = String::from_utf8_lossy(&seen).to_lowercase();
    assert!(head.starts_with("http/1.1 200 ok\r\n"), "{head}");
    assert!(!head.contains("connection: close"), "{head}");
    let mark = seen.len();
    write!(
        kept,
        "GET /api/scene HTTP/1.1\r\n{host}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    read_until(
        &mut kept,
        &mut seen,
        mark,
        "HTTP/1.1 200 OK\r\n",
        Duration::from_secs(10),
    );
    let open: Vec<_> = (0..32)
        .map(|_| open_events(port, "GET", ": connected at version 1\n\n"))
        .collect();
    // Read until its head alone: a stream let in never ends.
    let (_, head) = open_events(port, "GET", "\r\n\r\n");
    let head = String::from_utf8_lossy(&head).to_string();
    assert!(head.starts_with("HTTP/1.1 503 "), "a 33rd stream: {head}");
    assert_eq!(server.get("/api/scene").status, 200);
    drop(open);
}

/// An event is a reload: none when the stream opens (the comment says the
/// version then), one for a change, and no repeats of it.
#[test]
fn an_event_stream_tells_each_reload_once() {
    let (_dir, scene) = scene_folder();
    let server = Server::start(Some(&scene));
    let (mut events, mut seen) = open_events(server.port, "GET", ": connected at version 1\n\n");
    // Two looks of the watcher and more: nothing to tell.
    read_for(&mut events, &mut seen, Duration::from_millis(700));
    let text = String::from_utf8_lossy(&seen).to_string();
    assert!(!text.contains("data:"), "{text}");
    let mark = seen.len();
    let seed = raystep::io::scene_file::SEED_TOML;
    std::fs::write(&scene, seed.replace("radius = 0.7", "radius = 0.5")).unwrap();
    read_until(
        &mut events,
        &mut seen,
        mark,
        "data: {\"error\":null,\"version\":2}\n\n",
        Duration::from_secs(10),
    );
    read_for(&mut events, &mut seen, Duration::from_millis(700));
    let text = String::from_utf8_lossy(&seen[mark..]).to_string();
    assert_eq!(text.matches("data:").count(), 1, "{text}");
}

/// Wait (at most 10 s) until the served scene's version is `version`.
fn wait_for_version(server: &Server, version: u64) -> Value {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let json = server.get("/api/scene?objects=none").json();
        if json["version"] == version {
            return json;
        }
        assert!(Instant::now() < deadline, "still {json}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// A save that leaves the bytes as they were is no reload, nor is a file
/// emptied (one being written: no scene is empty); a change is.
#[test]
fn the_same_bytes_again_or_an_empty_file_is_no_new_version() {
    let (_dir, scene) = scene_folder();
    let server = Server::start(Some(&scene));
    let seed = raystep::io::scene_file::SEED_TOML;
    // The same bytes, a new modification time; then an empty file. Each is
    // given four looks of the watcher (every 250 ms, README).
    std::fs::write(&scene, seed).unwrap();
    std::thread::sleep(Duration::from_millis(1000));
    let json = server.get("/api/scene?objects=none").json();
    assert_eq!(
        (&json["version"], &json["error"]),
        (&1.into(), &Value::Null)
    );
    std::fs::write(&scene, "").unwrap();
    std::thread::sleep(Duration::from_millis(1000));
    let json = server.get("/api/scene?objects=none").json();
    assert_eq!(
        (&json["version"], &json["error"]),
        (&1.into(), &Value::Null)
    );
    // The watcher was looking: a change is version 2.
    std::fs::write(&scene, seed.replace("radius = 0.7", "radius = 0.5")).unwrap();
    let json = wait_for_version(&server, 2);
    assert_eq!(json["error"], Value::Null);
}

/// The beauty kept for a diff is kept by the scene's version too (README): after
/// a reload the diff renders again, and the versions it reports are the new one.
#[test]
fn a_diff_after_a_reload_renders_the_new_scene() {
    let (_dir, scene) = scene_folder();
    let server = Server::start(Some(&scene));
    let query = "width=60&height=40";
    assert_eq!(server.get(&format!("/api/render?{query}")).status, 200);
    let seed = raystep::io::scene_file::SEED_TOML;
    std::fs::write(&scene, seed.replace("radius = 0.7", "radius = 0.5")).unwrap();
    wait_for_version(&server, 2);
    // A against itself: one render of the new scene, none of the old one reused.
    let side = query.replace('=', "%3D").replace('&', "%26");
    let reply = server.get(&format!("/api/diff?a={side}&b={side}"));
    assert_eq!(reply.status, 200);
    assert_eq!(reply.header("X-Raystep-Renders"), Some("1"));
    let json = reply.json();
    assert_eq!(json["a_version"], 2);
    assert_eq!(json["b_version"], 2);
}

/// A diff compares renders of one size: a height differing alone is refused as
/// a width is.
#[test]
fn a_diff_of_two_heights_is_400() {
    let server = Server::start(None);
    let reply = server.get("/api/diff?a=width%3D60%26height%3D40&b=width%3D60%26height%3D41");
    assert_eq!(reply.status, 400);
    assert_eq!(
        reply.error(),
        "a is 60 × 40 but b is 60 × 41: only renders of one size compare"
    );
}

/// A query is at most 4 KiB (README): 4096 bytes are taken, 4097 are not; and at
/// most `MAX_QUERY_PAIRS` pairs (empty ones too) are.
#[test]
fn a_query_is_at_most_4_kib_and_64_pairs() {
    use raystep::tools::serve::api::MAX_QUERY_PAIRS;
    let server = Server::start(None);
    let pad = |bytes: usize| format!("objects=all{}", "&".repeat(bytes - 11));
    assert_eq!(server.get(&format!("/api/scene?{}", pad(4096))).status, 200);
    let long = server.get(&format!("/api/scene?{}", pad(4097)));
    assert_eq!(long.status, 400);
    assert!(long.error().contains("4097 bytes"), "{}", long.error());
    let pairs = |n: usize| vec!["="; n].join("&");
    let most = server.get(&format!("/api/scene?{}", pairs(MAX_QUERY_PAIRS)));
    assert_eq!(most.status, 200);
    let more = server.get(&format!("/api/scene?{}", pairs(MAX_QUERY_PAIRS + 1)));
    assert_eq!(more.status, 400);
    assert!(more.error().contains("more than"), "{}", more.error());
}

/// A view's name is 1 to 64 letters, digits, `-` or `_` (its message says so).
#[test]
fn a_views_name_is_1_to_64_characters() {
    let server = Server::start(None);
    let view = |n: usize| format!("/api/render?width=8&height=8&view={}", "v".repeat(n));
    assert_eq!(server.get(&view(1)).status, 200);
    assert_eq!(server.get(&view(64)).status, 200);
    for n in [0, 65] {
        let reply = server.get(&view(n));
        assert_eq!(reply.status, 400, "{n}");
        assert!(reply.error().contains("1 to 64"), "{n}: {}", reply.error());
    }
}

/// A moved point's numbers are each at most 1e6 in size, negative ones too.
#[test]
fn a_moved_point_is_at_most_1e6_each_way() {
    let server = Server::start(None);
    for (query, status) in [
        ("light=-1e6,5,5", 200),
        ("light=1e6,5,5", 200),
        ("light=-1000001,5,5", 400),
        ("camera=0,-1e7,1", 400),
        ("camera=0,0,-1e9", 400),
    ] {
        let reply = server.get(&format!("/api/scene.toml?{query}"));
        assert_eq!(reply.status, status, "{query}");
    }
}

/// The headers the page's drags read: the eye where the scene (or the move)
/// puts it, as `x,y,z`, and the screen as `left,right,top,bottom`, which for a
/// scene without one is the tutorial's, from the image's ratio: −1 to 1 across,
/// ±height/width up and down (README, "JSON output": `screen`).
#[test]
fn the_camera_and_screen_headers_are_in_their_documented_order() {
    let server = Server::start(None);
    let numbers = |reply: &Reply, name: &str| -> Vec<f64> {
        reply
            .header(name)
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect()
    };
    let plain = server.get("/api/render?width=30&height=20");
    assert_eq!(numbers(&plain, "X-Raystep-Camera"), [0.0, 0.0, 1.0]);
    assert_eq!(
        numbers(&plain, "X-Raystep-Screen"),
        [-1.0, 1.0, 20.0 / 30.0, -20.0 / 30.0]
    );
    let moved = server.get("/api/render?width=30&height=20&camera=0.25,-0.1,0.5");
    assert_eq!(numbers(&moved, "X-Raystep-Camera"), [0.25, -0.1, 0.5]);
}

/// Every answer is one block with its length (`Content-Length`, never chunked),
/// a large PNG too: more than tiny_http's own threshold for chunks (32 KiB).
#[test]
fn a_large_answer_comes_with_its_length() {
    let server = Server::start(None);
    for target in [
        "/api/render?width=600&height=400&buffer=normal",
        "/api/scene",
    ] {
        let reply = server.get(target);
        assert_eq!(reply.status, 200);
        assert_eq!(reply.header("Transfer-Encoding"), None, "{target}");
        assert_eq!(
            reply.header("Content-Length"),
            Some(reply.body.len().to_string().as_str()),
            "{target}"
        );
    }
    let png = server.get("/api/render?width=600&height=400&buffer=normal");
    assert!(png.body.len() > 32 * 1024, "{} bytes", png.body.len());
}

/// Keys of the query: the flags, a few others, and anything.
fn key() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "stage",
            "without",
            "width",
            "height",
            "precision",
            "intersect",
            "offset",
            "viewer",
            "max-depth",
            "spp",
            "early-stop",
            "accel",
            "engine",
            "avx",
            "tutorial",
            "buffer",
            "x",
            "y",
            "pixel",
            "json",
            "out",
            "help",
            "version",
            "scene",
            "view",
            "light",
            "camera",
            "a",
            "b",
            "",
        ])
        .prop_map(String::from),
        "[a-zA-Z0-9%+=._-]{0,12}",
        any::<String>(),
    ]
}

/// Values: the valid ones, numbers near the limits, and anything.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "",
            "plane",
            "shadow",
            "rays",
            "f32",
            "f64",
            "naive",
            "stable",
            "auto",
            "fixed:0",
            "fixed:1e-5",
            "fixed:-1",
            "fixed:nan",
            "on",
            "off",
            "book",
            "fast",
            "bvh",
            "beauty",
            "depth",
            "bounces",
            "4",
            "16",
            "1024",
            "1025",
            "0",
            "-1",
            "64",
            "65",
            "16384",
            "16385",
            "4294967296",
            "1e3",
            "%",
            "%zz",
            "%2e%2e",
            "..",
            "/etc/passwd",
            "main",
            "1,2,3",
            "1,2",
            "1e300,0,0",
            "width%3D9%26height%3D9",
        ])
        .prop_map(String::from),
        (0u32..100).prop_map(|n| n.to_string()),
        any::<String>(),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// Any query: an answer (200) or a refusal with a message (400), never a panic.
    #[test]
    fn any_query_is_answered_or_refused_with_a_message(
        pairs in prop::collection::vec((key(), value()), 0..8),
        raw in any::<bool>(),
    ) {
        static STUDIO: std::sync::OnceLock<raystep::tools::serve::api::Studio> = std::sync::OnceLock::new();
        let studio = STUDIO.get_or_init(|| raystep::tools::serve::api::Studio::open(None).unwrap());
        // Encoded as a browser would, or sent as it is (stray `%`, `&` and `=`).
        let query = if raw {
            pairs.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join("&")
        } else {
            encode(&pairs)
        };
        match studio.render_job(&query) {
            Ok(job) => {
                // Within the command line's limits.
                prop_assert!(job.pixels() <= raystep::io::scene_file::MAX_PIXELS);
                prop_assert!(job.settings.spp <= raystep::io::scene_file::MAX_SPP);
            }
            Err(refusal) => {
                prop_assert_eq!(refusal.status, 400);
                prop_assert!(!refusal.message.is_empty());
            }
        }
        // The page's other queries: a diff's two sides, a scene to save.
        match studio.diff_jobs(&query) {
            Ok(jobs) => {
                prop_assert!(jobs.a.pixels() <= raystep::io::scene_file::MAX_PIXELS);
                prop_assert_eq!(jobs.a.pixels(), jobs.b.pixels());
            }
            Err(refusal) => {
                prop_assert_eq!(refusal.status, 400);
                prop_assert!(!refusal.message.is_empty());
            }
        }
        if let Err(refusal) = studio.scene_toml(&query) {
            prop_assert_eq!(refusal.status, 400);
            prop_assert!(!refusal.message.is_empty());
        }
        match studio.pixel(&format!("x=1&y=1&{query}")) {
            Ok(json) => {
                let story: Value = serde_json::from_str(&json).unwrap();
                prop_assert_eq!(&story["x"], 1);
            }
            Err(refusal) => {
                prop_assert_eq!(refusal.status, 400);
                prop_assert!(!refusal.message.is_empty());
            }
        }
    }
}

/// `application/x-www-form-urlencoded`, as URLSearchParams writes it.
fn encode(pairs: &[(String, String)]) -> String {
    let escape = |s: &str| {
        s.bytes()
            .map(|b| match b {
                b'a'..=b'z' | b'A'..=b'Z' | b'0'..=b'9' | b'-' | b'.' | b'_' | b'*' => {
                    char::from(b).to_string()
                }
                b' ' => "+".to_string(),
                _ => format!("%{b:02X}"),
            })
            .collect::<String>()
    };
    pairs
        .iter()
        .map(|(k, v)| format!("{}={}", escape(k), escape(v)))
        .collect::<Vec<_>>()
        .join("&")
}

/// Where the browser test writes the book's screenshots when asked to make
/// them (`RAYSTEP_STUDIO_SHOTS=chapters/studio`), with their record.
const SHOTS_VARIABLE: &str = "RAYSTEP_STUDIO_SHOTS";

/// The command that makes the book's screenshots, as chapter 13 shows it.
pub const SHOTS_COMMAND: &str =
    "RAYSTEP_STUDIO_SHOTS=chapters/studio cargo test --test serve studio_page";

/// FNV-1a, 64 bits: the record's fingerprint of each screenshot's bytes.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The page in a real headless Chromium (`tests/browser/studio.mjs`): stages
/// switched, a refusal shown with the command line's reason, a buffer picked and
/// shown in false colour, a pixel's story read (exactly `explain --json`), zoom to
/// single pixels, A/B with `raystep diff`'s figures, the light dragged and the
/// scene saved as a file, and a saved scene followed. With
/// `RAYSTEP_STUDIO_SHOTS=DIR`, its screenshots are kept in DIR for the book,
/// with a record (`shots.json`) that tests/book.rs checks them against.
#[test]
fn the_studio_page_zooms_compares_drags_tells_a_pixels_story_and_follows_the_file() {
    let Some(chromium) = common::required(common::browser_tools(), "the browser test") else {
        return;
    };
    let (dir, scene) = scene_folder();
    let new_scene = dir.path().join("new.toml");
    let text = raystep::io::scene_file::SEED_TOML;
    std::fs::write(&new_scene, text.replace("radius = 0.7", "radius = 0.5")).unwrap();
    let broken_scene = dir.path().join("broken.toml");
    std::fs::write(&broken_scene, text.replace("radius = 0.7", "radius = -1")).unwrap();
    let broken_error = cli_error(&["check", broken_scene.to_str().unwrap()]);
    // Served by its name in its folder, as a reader would: the page shows it.
    let server = Server::start_in(Some(dir.path()), Some(Path::new("scene.toml")));
    const VIEWPORT: (u32, u32) = (1400, 900);
    let (x, y) = (150, 120);
    let screenshot = dir.path().join("studio.png");
    let book_shots = std::env::var_os(SHOTS_VARIABLE).map(|d| {
        let d = PathBuf::from(d);
        match d.is_absolute() {
            true => d,
            false => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(d),
        }
    });
    let shots = book_shots
        .clone()
        .unwrap_or_else(|| dir.path().join("shots"));
    let download = dir.path().join("saved.toml");
    // The story the page must tell, before the page changes the scene file.
    let pixel = format!("{x},{y}");
    let explain = Command::new(env!("CARGO_BIN_EXE_raystep"))
        .arg("explain")
        .arg(&scene)
        .args(["--pixel", &pixel, "--json", "--stage", "plane"])
        .output()
        .unwrap();
    // `raystep diff`'s figures for the A/B the page makes, of the scene as it is
    // then (the page saves a new one later).
    let s = scene.to_str().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    raystep_ok(&["render", s, "--out", a.to_str().unwrap()]);
    raystep_ok(&[
        "render",
        s,
        "--without",
        "shadow",
        "--out",
        b.to_str().unwrap(),
    ]);
    let cli = raystep(&[
        "diff",
        a.join("buffers.exr").to_str().unwrap(),
        b.join("buffers.exr").to_str().unwrap(),
        "--json",
    ]);
    let cli: Value = serde_json::from_slice(&cli.stdout).unwrap();
    let run = Command::new("node")
        .arg(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/browser/studio.mjs"))
        .arg("--url")
        .arg(format!("http://127.0.0.1:{}/", server.port))
        .arg("--screenshot")
        .arg(&screenshot)
        .arg("--scene")
        .arg(&scene)
        .arg("--new-scene")
        .arg(&new_scene)
        .arg("--broken-scene")
        .arg(&broken_scene)
        .arg("--shots")
        .arg(&shots)
        .arg("--download")
        .arg(&download)
        .arg("--chromium")
        .arg(&chromium)
        .arg("--size")
        .arg(format!("{}x{}", VIEWPORT.0, VIEWPORT.1))
        .arg("--pixel")
        .arg(format!("{x},{y}"))
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "studio.mjs failed:\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let report: Value = serde_json::from_slice(&run.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&run.stdout)));
    for key in ["pageErrors", "failedRequests"] {
        assert_eq!(report[key], serde_json::json!([]), "{key}");
    }
    // The one message in the console: Chromium's note of the refused render.
    let refused_load = "Failed to load resource: the server responded with a status of 400 \
                        (Bad Request)";
    assert_eq!(
        report["console"],
        serde_json::json!([{"type": "error", "text": refused_load}])
    );
    let queries: Vec<(&str, &str)> = report["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            (
                s["action"].as_str().unwrap(),
                s["query"].as_str().unwrap_or(""),
            )
        })
        .collect();
    let light = report["light"]["sent"].as_str().unwrap();
    let dragged = format!(
        "stage=plane&light={}&buffer=beauty",
        light.replace(',', "%2C")
    );
    let camera = report["camera"]["sent"].as_str().unwrap();
    let camera_dragged = format!(
        "stage=plane&light={}&camera={}&buffer=beauty",
        light.replace(',', "%2C"),
        camera.replace(',', "%2C")
    );
    assert_eq!(
        queries,
        [
            ("load", "stage=plane&buffer=beauty"),
            ("shadow off", "stage=plane&without=shadow&buffer=beauty"),
            ("shadow on", "stage=plane&buffer=beauty"),
            // Refused: the picture and its query stay those of the last render.
            ("rays off", "stage=plane&buffer=beauty"),
            ("rays on", "stage=plane&buffer=beauty"),
            ("depth", "stage=plane&buffer=depth"),
            ("beauty", "stage=plane&buffer=beauty"),
            ("B: shadow off", "stage=plane&without=shadow&buffer=beauty"),
            ("shadow on again", "stage=plane&buffer=beauty"),
            ("light dragged", dragged.as_str()),
            ("camera dragged", camera_dragged.as_str()),
            ("reset", "stage=plane&buffer=beauty"),
            ("depth again", "stage=plane&buffer=depth"),
            ("scene saved", "stage=plane&buffer=depth"),
        ]
    );
    // The refusal is the command line's.
    let refused = cli_error(&["render", s, "--stage", "plane", "--without", "rays"]);
    assert_eq!(report["refusal"], refused.as_str());
    // False colour: the grey pixels of the depth picture come out coloured.
    let grey = report["falseColour"]["before"].as_u64().unwrap();
    assert!(grey > 20_000, "{grey} grey pixels of 60000");
    assert!(report["falseColour"]["after"].as_u64().unwrap() < grey / 50);
    // The story is exactly `explain --json`, of the scene as it was then, with
    // the values of the buffers.
    let story = report["story"]["json"].as_str().unwrap();
    assert!(story == String::from_utf8_lossy(&explain.stdout), "{story}");
    assert!(report["storyText"].as_str().unwrap().contains("Segment 0"));
    let buffers = report["storyBuffers"].as_str().unwrap();
    for name in ["beauty", "depth", "normal", "object", "bounces", "rays"] {
        assert!(buffers.contains(name), "{name} in {buffers}");
    }
    // Zoomed in to 32 screen pixels a pixel, a click picks the next pixel.
    assert!(report["zoom"]["zoom"].as_f64().unwrap() >= 32.0);
    assert_eq!(report["zoom"]["x"], x + 1);
    // A/B: nothing differs between A and itself; with B without shadows, the
    // figures are `raystep diff`'s for the two renders.
    assert_eq!(report["ab"]["same"]["over_one_step"], 0);
    assert_eq!(report["ab"]["a"], "stage=plane");
    assert_eq!(report["ab"]["b"], "stage=plane&without=shadow");
    let figures = &report["ab"]["figures"];
    for key in ["over_one_step", "largest", "largest_at", "rmse", "pixels"] {
        assert_eq!(figures[key], cli[key], "{key}");
    }
    let words = report["ab"]["text"].as_str().unwrap();
    assert!(
        words.contains(&format!("{} of 60000 pixels", cli["over_one_step"])),
        "{words}"
    );
    // The light moved right only, and the file saved says where it is.
    let before = report["light"]["before"].as_str().unwrap();
    assert_eq!(before, "(5, 5, 5)");
    // The drags are exact (assets/studio/studio.js, `moveBy`), on the grid of the
    // picture: the built-in scene's 300 × 200 screen, its pixels' points `across`
    // and `down` apart (camera.rs's linspace), seen from the eye (0, 0, 1).
    let rule = &report["light"]["rule"];
    let numbers = |v: &Value| -> Vec<f64> {
        let list = v.as_array().unwrap_or_else(|| panic!("{v}"));
        list.iter().map(|x| x.as_f64().unwrap()).collect()
    };
    let screen = raystep::camera::Screen::for_image(300, 200);
    assert_eq!(
        numbers(&rule["screen"]),
        [screen.left, screen.right, screen.top, screen.bottom]
    );
    assert_eq!(numbers(&rule["eye"]), [0.0, 0.0, 1.0]);
    let across = (screen.right - screen.left) / 299.0;
    let down = (screen.top - screen.bottom) / 199.0;
    // Where a point is seen in the picture, in pixels (column, row): where the
    // line from the eye through it meets the screen, on the pixels' grid.
    let seen = |p: &[f64]| {
        let k = 1.0 / (1.0 - p[2]);
        let (x, y) = (p[0] * k, p[1] * k);
        ((x - screen.left) / across, (screen.top - y) / down)
    };
    let close = |a: f64, b: f64, tolerance: f64| (a - b).abs() <= tolerance;
    for m in rule["moved"].as_array().unwrap() {
        let (start, end) = (numbers(&m["start"]), numbers(&m["end"]));
        assert_eq!(end[2], start[2], "z is kept: {m}");
        if start[2] < 1.0 {
            // In front of the eye: its image follows the pointer, 30 right, 20 down.
            let (a, b) = (seen(&start), seen(&end));
            assert!(
                close(b.0 - a.0, 30.0, 1e-9) && close(b.1 - a.1, 20.0, 1e-9),
                "{m}: seen {a:?} then {b:?}"
            );
        } else {
            // Level with the eye: no image; the screen's steps.
            let step = [end[0] - start[0], end[1] - start[1]];
            assert!(
                close(step[0], 30.0 * across, 1e-12) && close(step[1], -20.0 * down, 1e-12),
                "{m}"
            );
        }
    }
    // The camera: as far as the pointer went over the screen, so the ray through
    // the pixel now under the pointer has the direction of the one under it before.
    let eye = numbers(&rule["camera"]);
    assert!(
        close(eye[0], 30.0 * across, 1e-12) && close(eye[1], -20.0 * down, 1e-12),
        "{eye:?}"
    );
    assert_eq!(eye[2], 1.0);
    // The light the test dragged 80 screen pixels right lies behind the eye
    // (z = 5): it moved by (1 − 5)/1 = 4 times the screen's steps, right only
    // (the page sends 4 decimals).
    let zoom = report["light"]["zoom"].as_f64().unwrap();
    let moved: Vec<f64> = light.split(',').map(|v| v.parse().unwrap()).collect();
    let expected = 5.0 + 80.0 / zoom * across * 4.0;
    assert!(
        close(moved[0], expected, 0.5e-4 + 1e-12) && moved[1] == 5.0 && moved[2] == 5.0,
        "{moved:?}, expected x {expected}"
    );
    // The camera dragged 40 screen pixels up: up by 40 rows of the screen.
    let zoom = report["camera"]["zoom"].as_f64().unwrap();
    let moved: Vec<f64> = camera.split(',').map(|v| v.parse().unwrap()).collect();
    let expected = 40.0 / zoom * down;
    assert!(
        moved[0] == 0.0 && close(moved[1], expected, 0.5e-4 + 1e-12) && moved[2] == 1.0,
        "{moved:?}, expected y {expected}"
    );
    let shown = report["camera"]["shown"].as_str().unwrap();
    assert_eq!(shown, format!("(0, {}, 1) moved", moved[1]));
    assert_eq!(report["saved"]["name"], "scene-studio.toml");
    let saved = download.to_str().unwrap();
    raystep_ok(&["check", saved]);
    let out = dir.path().join("saved");
    raystep_ok(&["render", saved, "--out", out.to_str().unwrap()]);
    // The scene file was the built-in scene when it was saved.
    let api = Server::start(None).get(&format!("/api/render?light={light}"));
    assert!(api.body == std::fs::read(out.join("beauty.png")).unwrap());
    // The broken file: the command line's message in the page (its file, line and
    // key; the page was given the file by the name `scene.toml`), the last good
    // picture kept; then the new file, version 3.
    let shown = report["broken"]["error"].as_str().unwrap();
    let message = broken_error.replace(broken_scene.to_str().unwrap(), "scene.toml");
    assert!(shown.contains(&message), "{shown:?} lacks {message:?}");
    assert!(
        shown.contains("the picture is of the last scene that loaded"),
        "{shown}"
    );
    assert_eq!(report["broken"]["state"], "ready");
    assert_eq!(report["version"], "3");

    // The screenshots: PNGs of the window's size, not one flat colour; a copy
    // stays in target/ for a person to look at.
    let mut record = Vec::new();
    let names = ["overview", "depth-false-colour", "zoom", "ab", "light"];
    let shot_paths: Vec<PathBuf> = names
        .iter()
        .map(|n| shots.join(format!("studio-{n}.png")))
        .chain([screenshot.clone()])
        .collect();
    for path in &shot_paths {
        let bytes = std::fs::read(path).unwrap();
        common::check_screenshot(&bytes, path, VIEWPORT, 101);
        record.push(serde_json::json!({
            "file": path.file_name().unwrap().to_str().unwrap(),
            "width": VIEWPORT.0,
            "height": VIEWPORT.1,
            "bytes": bytes.len(),
            "fnv1a64": format!("{:016x}", fnv1a(&bytes)),
        }));
    }
    record.pop(); // the last screenshot is not the book's
    let keep = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target");
    std::fs::create_dir_all(&keep).unwrap();
    std::fs::copy(&screenshot, keep.join("studio-screenshot.png")).unwrap();
    if let Some(book) = book_shots {
        let manifest = serde_json::json!({
            "made_by": SHOTS_COMMAND,
            "note": "screenshots of headless Chromium: not byte-stable from one run to the next, \
                     so tests/book.rs checks each file against this record, which the test \
                     writes with them",
            "shots": record,
        });
        std::fs::write(
            book.join("shots.json"),
            serde_json::to_string_pretty(&manifest).unwrap() + "\n",
        )
        .unwrap();
    }
}
