//! Helpers shared by the integration tests.
#![allow(dead_code)]

use raystep::aov::{Frame, PixelRecord};
use raystep::scene::Scene;
use raystep::stages::Stages;

/// The figures `raystep diff --json` prints (besides the two files' names and
/// `schema`), which the studio's `/api/diff` gives too.
pub const DIFF_FIGURES: [&str; 14] = [
    "width",
    "height",
    "pixels",
    "threshold",
    "fail_percent",
    "over_threshold",
    "over_threshold_percent",
    "over_one_step",
    "largest",
    "largest_at",
    "rmse",
    "clipped",
    "non_finite",
    "different",
];

/// The built-in figure-1 scene at `width` × `height`.
pub fn seed(width: u32, height: u32) -> Scene {
    let mut scene = raystep::io::scene_file::seed();
    scene.width = width;
    scene.height = height;
    scene
}

/// Render with raystep's default settings (the book engine), without progress
/// reporting.
pub fn render(scene: &Scene, stages: Stages) -> Frame {
    raystep::render::render(scene, &stages.into(), &|_| {})
}

/// A scene from TOML text, which must be valid.
pub fn scene(toml: &str) -> Scene {
    raystep::io::scene_file::parse(toml, "test scene").unwrap_or_else(|e| panic!("{e}"))
}

/// Read a PFM file: (width, height, RGB triples with the top row first).
pub fn read_pfm(bytes: &[u8]) -> (usize, usize, Vec<[f32; 3]>) {
    let mut fields = Vec::new();
    let mut pos = 0;
    while fields.len() < 4 {
        while bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        fields.push(std::str::from_utf8(&bytes[start..pos]).unwrap().to_string());
    }
    pos += 1; // the single whitespace byte after the scale
    assert_eq!(fields[0], "PF", "a colour PFM");
    let (w, h): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    let scale: f32 = fields[3].parse().unwrap();
    assert!(scale < 0.0, "little-endian PFM");
    let floats: Vec<f32> = bytes[pos..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(floats.len(), w * h * 3);
    let mut rows: Vec<[f32; 3]> = Vec::with_capacity(w * h);
    for row in (0..h).rev() {
        for col in 0..w {
            let i = (row * w + col) * 3;
            rows.push([floats[i], floats[i + 1], floats[i + 2]]);
        }
    }
    (w, h, rows)
}

/// The longest a test lets one `raystep` command run (the longest run of a
/// test's commands takes a few seconds; a debug build on a loaded machine ten
/// times as long).
pub const RUN_LIMIT: std::time::Duration = std::time::Duration::from_secs(180);

/// Run the `raystep` binary with `args` in the folder `dir`, as
/// `Command::output` does (no standard input, both outputs read whole), but a
/// command still running after [`RUN_LIMIT`] is killed and fails the test: a
/// hang is a failure, not a suite that never ends.
pub fn raystep(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    raystep_within(dir, args, RUN_LIMIT)
}

/// [`raystep`] with a limit of its own.
pub fn raystep_within(
    dir: &std::path::Path,
    args: &[&str],
    limit: std::time::Duration,
) -> std::process::Output {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    // Each output read on a thread of its own, so that neither pipe fills.
    fn read_all(mut pipe: impl Read + Send + 'static) -> std::thread::JoinHandle<Vec<u8>> {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            pipe.read_to_end(&mut bytes).expect("the output reads");
            bytes
        })
    }
    let stdout = read_all(child.stdout.take().unwrap());
    let stderr = read_all(child.stderr.take().unwrap());
    let started = std::time::Instant::now();
    let mut pause = std::time::Duration::from_millis(1);
    let status = loop {
        if let Some(status) = child.try_wait().expect("the binary is waited for") {
            break status;
        }
        if started.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            panic!("raystep {args:?} still ran after {limit:?}: killed");
        }
        std::thread::sleep(pause);
        pause = (pause * 2).min(std::time::Duration::from_millis(20));
    };
    std::process::Output {
        status,
        stdout: stdout.join().unwrap(),
        stderr: stderr.join().unwrap(),
    }
}

/// The text of chapter `file` (in `chapters/`).
pub fn chapter(file: &str) -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(root.join("chapters").join(file))
        .unwrap_or_else(|e| panic!("chapters/{file}: {e}"))
}

/// The words of `text` joined by single spaces: a quote found in it however
/// its lines wrap it.
pub fn words(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Chapter `file`'s [`words`].
pub fn chapter_words(file: &str) -> String {
    words(&chapter(file))
}

/// The README's [`words`].
pub fn readme_words() -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    words(&std::fs::read_to_string(root.join("README.md")).expect("README.md"))
}

/// What chapter `file` (in `chapters/`) shows after the line `$ COMMAND`, up to
/// the end of its code block: the transcript a test holds to the command.
pub fn transcript(file: &str, command: &str) -> String {
    let chapter = chapter(file);
    let line = format!("$ {command}\n");
    let after = chapter
        .split(&line)
        .nth(1)
        .unwrap_or_else(|| panic!("{file} shows `{line}`"));
    after[..after.find("```").unwrap()].to_string()
}

/// `n` with a comma between each group of three digits, as the book and the
/// help write counts.
pub fn grouped(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, digit) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(digit);
    }
    out
}

/// Chromium and Node.js with playwright-core, as the browser tests drive them
/// (`tests/browser/`), or what is missing.
pub fn browser_tools() -> Result<std::path::PathBuf, String> {
    use std::path::PathBuf;
    let chromium = std::env::var_os("CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    let mut missing = Vec::new();
    if !chromium.is_file() {
        missing.push(format!(
            "Chromium at {} (apt-get install chromium, or set CHROMIUM to its path)",
            chromium.display()
        ));
    }
    let node = std::process::Command::new("node").arg("--version").output();
    if !node.is_ok_and(|o| o.status.success()) {
        missing.push("Node.js (apt-get install nodejs npm)".to_string());
    }
    let playwright = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/browser/node_modules/playwright-core");
    if !playwright.is_dir() {
        missing.push("playwright-core (npm ci --prefix tests/browser)".to_string());
    }
    if missing.is_empty() {
        Ok(chromium)
    } else {
        Err(missing.join("; "))
    }
}

/// The tools a test needs, or `None` when it is to be skipped: with a message
/// locally, and a failure under CI, where they are installed.
pub fn required<T>(tools: Result<T, String>, what: &str) -> Option<T> {
    match tools {
        Ok(tools) => Some(tools),
        Err(missing) if std::env::var_os("CI").is_some() => panic!("{what} needs: {missing}"),
        Err(missing) => {
            eprintln!("skipped: {what} needs: {missing}");
            None
        }
    }
}

/// The material of the property tests' surfaces (it plays no part).
pub fn grey() -> raystep::scene::Material {
    raystep::scene::Material {
        ambient: raystep::Vec3::splat(0.1),
        diffuse: raystep::Vec3::splat(0.6),
        specular: raystep::Vec3::ONE,
        shininess: 100.0,
        reflection: 0.5,
    }
}

/// A sphere, and a ray from outside it aimed near its centre, in `T`. After a hit,
/// with the point moved off the surface by `step` (the book's `step_off`, or a
/// variant an exercise tries): is the stepped-off origin strictly outside (checked
/// exactly), and does a ray from it into the surface meet it, as a shadow ray into
/// a dark side must?
pub fn sphere_recast<T: raystep::real::Real>(
    center: raystep::Vec3,
    radius: f64,
    origin: raystep::Vec3,
    aim: raystep::Vec3,
    step: impl Fn(T::Vec3, T::Vec3, &raystep::scene::Object<T>) -> T::Vec3,
) -> Option<(bool, bool)> {
    use raystep::real::Vector;
    use raystep::scene::{Object, Role, Shape};
    use raystep::sphere::Method::Stable;
    let sphere = Object::<f64> {
        shape: Shape::Sphere(raystep::sphere::Sphere { center, radius }),
        material: grey(),
        role: Role::Sphere,
    };
    let object = sphere.cast::<T>();
    let Shape::Sphere(s) = object.shape else {
        unreachable!()
    };
    let ray = raystep::ray::Ray::<T>::towards(T::Vec3::of(origin), T::Vec3::of(aim));
    let point = ray.at(s.intersect(&ray, Stable)?);
    let normal = s.normal_at(point);
    let shifted = step(point, normal, &object);
    let (c, r) = (s.center.to_f64(), s.radius.to_f64());
    let outside = raystep::tools::accuracy::outside_exactly(shifted.to_f64(), c, r);
    let into = raystep::ray::Ray::new(shifted, -normal);
    Some((outside, s.intersect(&into, Stable).is_some()))
}

/// A plane, and a ray that hits it, in `T`. After the hit, with the point moved
/// off by `step`: does a ray from the stepped-off origin leaving the face (any
/// direction with d·n > 0, made from `out`) miss the plane, and one going through
/// it (d·n < 0) meet it? (A plane, unlike a sphere under the tutorial's rule, can
/// be met again by a ray that starts just behind it.)
pub fn plane_recast<T: raystep::real::Real>(
    point: raystep::Vec3,
    normal: raystep::Vec3,
    origin: raystep::Vec3,
    aim: raystep::Vec3,
    out: raystep::Vec3,
    step: impl Fn(T::Vec3, T::Vec3, &raystep::scene::Object<T>) -> T::Vec3,
) -> Option<(bool, bool)> {
    use raystep::real::Vector;
    use raystep::scene::{Object, Role, Shape};
    let plane = Object::<f64> {
        shape: Shape::Plane(raystep::plane::Plane { point, normal }),
        material: grey(),
        role: Role::Floor,
    };
    let object = plane.cast::<T>();
    let Shape::Plane(pl) = object.shape else {
        unreachable!()
    };
    let ray = raystep::ray::Ray::<T>::towards(T::Vec3::of(origin), T::Vec3::of(aim));
    let hit = ray.at(pl.intersect(&ray)?);
    let face = pl.normal_towards(&ray);
    let shifted = step(hit, face, &object);
    // A direction leaving the face, and its mirror through it.
    let n = face.to_f64();
    let leave = (out - n * out.dot(n) + n * (0.05 + out.dot(n).abs())).normalize();
    let through = leave - n * (2.0 * leave.dot(n));
    let ray_from = |d: raystep::Vec3| raystep::ray::Ray::new(shifted, T::Vec3::of(d));
    let misses = pl.intersect(&ray_from(leave)).is_none();
    let meets = pl.intersect(&ray_from(through)).is_some();
    Some((misses, meets))
}

/// Check that a browser's screenshot `bytes` (read from `path`) is a PNG of the
/// window's `size` and not one flat colour: at least `least_colours` colours.
pub fn check_screenshot(
    bytes: &[u8],
    path: &std::path::Path,
    size: (u32, u32),
    least_colours: usize,
) {
    let picture = image::load_from_memory_with_format(bytes, image::ImageFormat::Png)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8();
    assert_eq!(picture.dimensions(), size, "{}", path.display());
    let colours: std::collections::HashSet<[u8; 3]> = picture.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() >= least_colours,
        "{}: {} colours",
        path.display(),
        colours.len()
    );
}

/// Every bit of a record, a word a field, so that even a zero of the other sign or
/// a NaN (which `==` never finds equal) compares as the bits it is.
pub fn record_bits(p: &PixelRecord) -> [u32; 13] {
    let f = |x: f32| x.to_bits();
    [
        f(p.colour[0]),
        f(p.colour[1]),
        f(p.colour[2]),
        f(p.depth),
        f(p.normal[0]),
        f(p.normal[1]),
        f(p.normal[2]),
        f(p.shadow),
        p.object,
        f(p.diffuse),
        f(p.specular),
        p.bounces,
        p.rays,
    ]
}

/// The chunk types of a PNG file's bytes, in order.
pub fn png_chunks(bytes: &[u8]) -> Vec<String> {
    let mut found = Vec::new();
    let mut at = 8;
    while at + 8 <= bytes.len() {
        let length = u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        found.push(String::from_utf8_lossy(&bytes[at + 4..at + 8]).into_owned());
        at += 12 + length; // length, type, data, CRC
    }
    found
}
