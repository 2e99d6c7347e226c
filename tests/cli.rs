//! The `raystep` binary as a user runs it: the default command, `render`, `check`,
//! `diff`, `bench`, `generate` and `chart`. Mistakes (a corpus of them, each with
//! the message it must end in) are in `tests/hostile.rs`.

use std::path::Path;
use std::process::Command;

mod common;
use common::raystep;

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Fails, showing all of `output`, unless it holds `wanted`.
#[track_caller]
fn says(output: &[u8], wanted: &str) {
    let output = text(output);
    assert!(output.contains(wanted), "no {wanted:?} in:\n{output}");
}

/// Run raystep in `dir` with `args`, which must succeed (else its stderr is
/// shown).
#[track_caller]
fn succeeds(dir: &Path, args: &[&str]) -> std::process::Output {
    let out = raystep(dir, args);
    assert!(out.status.success(), "{args:?}: {}", text(&out.stderr));
    out
}

/// Run raystep in `dir` with `args`, which must succeed, and read the JSON it
/// prints.
fn json_of(dir: &Path, args: &[&str]) -> serde_json::Value {
    let out = succeeds(dir, args);
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{args:?}: {e}"))
}

/// The bytes of the PNG file at `path` (its signature checked).
fn png_file(path: &Path) -> Vec<u8> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(
        &bytes[..8],
        b"\x89PNG\r\n\x1a\n",
        "{} is a PNG",
        path.display()
    );
    bytes
}

/// Write a `width` × `height` RGB EXR, `dir/name`, each pixel's colour given by
/// its (row, column).
fn write_exr(
    dir: &Path,
    name: &str,
    (width, height): (usize, usize),
    colour: impl Fn(usize, usize) -> (f32, f32, f32) + Sync,
) {
    exr::prelude::write_rgb_file(dir.join(name), width, height, |col, row| colour(row, col))
        .unwrap();
}

fn png_size(path: &Path) -> (u32, u32) {
    let bytes = png_file(path);
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    (be(16), be(20))
}

#[test]
fn each_stage_folder_holds_what_render_writes_for_that_stage_in_either_engine() {
    // `stages` renders its six stages one after another into one frame; each
    // folder's files must be those of `render --stage S` on a fresh one, byte for
    // byte, whatever the stage before left in the records.
    use raystep::stages::Stage;
    let dir = tempfile::tempdir().unwrap();
    for engine in ["book", "fast"] {
        let size = ["--width", "40", "--height", "30", "--engine", engine];
        let all = format!("all-{engine}");
        succeeds(
            dir.path(),
            &[&["stages", "-q", "-o", &all][..], &size].concat(),
        );
        for stage in Stage::ALL {
            let one = format!("{}-{engine}", stage.name());
            let render = ["render", "-q", "--stage", stage.name(), "-o", &one];
            succeeds(dir.path(), &[&render[..], &size].concat());
            let folder = dir.path().join(&all).join(stage.folder());
            let mut names: Vec<_> = std::fs::read_dir(dir.path().join(&one))
                .unwrap()
                .map(|e| e.unwrap().file_name())
                .collect();
            names.sort();
            assert!(names.len() >= 3, "{one}: {names:?}");
            for name in names {
                let read = |d: &Path| std::fs::read(d.join(&name)).unwrap();
                assert!(
                    read(&dir.path().join(&one)) == read(&folder),
                    "{engine}, {}: {name:?} differs",
                    stage.name()
                );
            }
        }
    }
}

#[test]
fn no_arguments_renders_every_stage_of_the_built_in_scene_from_any_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = succeeds(dir.path(), &[]);
    // Nothing on stdout, which is for data; the status lines on stderr, with no
    // progress bar (stderr is not a terminal) and no warnings.
    assert_eq!(text(&out.stdout), "");
    let stderr = text(&out.stderr);
    assert!(stderr.contains("wrote 6 stages"), "{stderr}");
    assert!(!stderr.contains("warning"), "{stderr}");
    for (folder, files) in [
        (
            "01-rays",
            &["beauty.png", "direction.png", "buffers.exr"][..],
        ),
        (
            "06-plane",
            &[
                "beauty.png",
                "direction.png",
                "depth.png",
                "normal.png",
                "shadow.png",
                "object.png",
                "ambient.png",
                "diffuse.png",
                "specular.png",
                "bounces.png",
                "rays.png",
                "buffers.exr",
            ][..],
        ),
    ] {
        for file in files {
            assert!(
                dir.path().join("out").join(folder).join(file).is_file(),
                "{folder}/{file}"
            );
        }
    }
    assert!(!dir.path().join("out/01-rays/depth.png").exists());
    assert_eq!(
        png_size(&dir.path().join("out/06-plane/beauty.png")),
        (300, 200)
    );
    let folders = std::fs::read_dir(dir.path().join("out"))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().path().is_dir())
        .count();
    assert_eq!(folders, 6);
    for file in ["index.html", "contact-sheet.png"] {
        assert!(dir.path().join("out").join(file).is_file(), "{file}");
    }
}

#[test]
fn render_writes_one_configuration_at_the_size_asked_and_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/seed.toml");
    let args = [
        "render",
        scene,
        "--stage",
        "plane",
        "--without",
        "shadow",
        "--width",
        "64",
        "--height",
        "48",
        "--out",
        "here",
    ];
    let out = succeeds(dir.path(), &args);
    assert_eq!(text(&out.stdout), "", "stdout is for data");
    says(
        &out.stderr,
        "rays+intersection+blinn-phong+reflection+plane",
    );
    let mut names: Vec<String> = std::fs::read_dir(dir.path().join("here"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "ambient.png",
            "beauty.png",
            "bounces.png",
            "buffers.exr",
            "depth.png",
            "diffuse.png",
            "direction.png",
            "normal.png",
            "object.png",
            "position.png",
            "rays.png",
            "shadow.png",
            "specular.png"
        ]
    );
    assert_eq!(png_size(&dir.path().join("here/depth.png")), (64, 48));

    // A later rays-only render into the same folder removes the buffers it does not
    // write, so the folder never mixes two renders.
    let out = raystep(
        dir.path(),
        &["render", scene, "--stage", "rays", "--out", "here"],
    );
    assert!(out.status.success());
    assert!(!dir.path().join("here/depth.png").exists());
    assert_eq!(png_size(&dir.path().join("here/beauty.png")), (300, 200));
}

#[test]
fn check_describes_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/seed.toml");
    let out = raystep(dir.path(), &["check", scene]);
    assert!(out.status.success());
    let stdout = text(&out.stdout);
    for expected in [
        "a valid scene",
        "300 × 200",
        "max_depth 3",
        "spheres: 3",
        "radius 8999.3",
        "planes:  1",
        // Numbered as explain, the studio and the object buffer number them:
        // from 0, spheres first, so the floor is object 3.
        "    object 0: sphere at [-0.2, 0, -1], radius 0.7\n",
        "    object 3: sphere at [0, -9000, 0], radius 8999.3\n",
    ] {
        assert!(stdout.contains(expected), "{expected:?} in\n{stdout}");
    }
    // A true plane through the point of it nearest the origin, with no −0 in it.
    let plane = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/true-plane.toml");
    let stdout = text(&raystep(dir.path(), &["check", plane]).stdout);
    assert!(
        stdout.contains("    object 3: true plane through [0, -0.7, 0], normal [0, 1, 0]\n"),
        "{stdout}"
    );
}

#[test]
fn chapter_one_shows_what_check_prints() {
    // The chapter's transcript of `raystep check scenes/seed.toml`, run from the
    // repository's root, is the command's output as it is now.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shown = common::transcript("01-scene.md", "raystep check scenes/seed.toml");
    let out = succeeds(root, &["check", "scenes/seed.toml"]);
    assert_eq!(shown, text(&out.stdout));
}

#[test]
fn check_counts_the_spheres_past_the_first_twenty() {
    // A generated scene of 30: the report in words lists 20 and counts 10; --all
    // and --json list all 30 (a scene of a million would otherwise print two
    // million lines).
    let dir = tempfile::tempdir().unwrap();
    let out = succeeds(
        dir.path(),
        &["generate", "spheres", "--count", "30", "--seed", "3"],
    );
    std::fs::write(dir.path().join("thirty.toml"), &out.stdout).unwrap();
    let listed = |stdout: &str| {
        stdout
            .lines()
            .filter(|l| l.starts_with("    object ") && l.contains(": sphere at"))
            .count()
    };
    let short = text(&raystep(dir.path(), &["check", "thirty.toml"]).stdout);
    assert!(short.contains("spheres: 30"), "{short}");
    assert!(short.contains("    object 19: sphere at"), "{short}");
    assert!(!short.contains("    object 20: sphere at"), "{short}");
    assert!(
        short.contains("… and 10 more (raystep check --all"),
        "{short}"
    );
    // The floor is the one plane, listed after the count of the spheres, under
    // its own number: object 30, after spheres 0 to 29.
    assert_eq!(listed(&short), 21, "{short}");
    assert!(
        short.contains("    object 30: sphere at [0, -9000, 0]"),
        "{short}"
    );
    let all = text(&raystep(dir.path(), &["check", "thirty.toml", "--all"]).stdout);
    assert_eq!(listed(&all), 31, "{all}");
    assert!(!all.contains("more (raystep check --all"), "{all}");
    let json = raystep(dir.path(), &["check", "thirty.toml", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(v["objects"].as_array().unwrap().len(), 31);
}

/// `check --json` of `scenes/seed.toml`, value for value against the file's own
/// numbers: the image, the camera, the default screen (x from -1 to 1, y ±200/300),
/// the counts, and the first, second and last objects with the defaults the file
/// leaves out (specular 1, shininess 100, reflection 0.5).
#[test]
fn check_json_states_the_seed_scenes_numbers() {
    use serde_json::json;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let v = json_of(root, &["check", "scenes/seed.toml", "--json"]);
    assert_eq!(v["scene"], "scenes/seed.toml", "the path as given");
    for (key, expected) in [
        ("width", json!(300)),
        ("height", json!(200)),
        ("max_depth", json!(3)),
        ("camera", json!([0.0, 0.0, 1.0])),
        ("spheres", json!(3)),
        ("planes", json!(1)),
        ("object_count", json!(4)),
    ] {
        assert_eq!(v[key], expected, "{key}");
    }
    let screen = &v["screen"];
    assert_eq!(screen["from_scene"], false, "{screen}");
    for (key, expected) in [("left", -1.0), ("right", 1.0), ("top", 2.0 / 3.0)] {
        let got = screen[key].as_f64().unwrap();
        assert!((got - expected).abs() < 1e-12, "{key}: {got}");
    }
    assert_eq!(
        screen["bottom"].as_f64(),
        Some(-screen["top"].as_f64().unwrap())
    );
    let red = &v["objects"][0];
    assert_eq!(red["entry"], "sphere", "{red}");
    assert_eq!(red["shape"], "sphere", "{red}");
    assert_eq!(red["center"], json!([-0.2, 0.0, -1.0]), "{red}");
    assert_eq!(red["radius"], 0.7, "{red}");
    let material = json!({
        "ambient": [0.1, 0.0, 0.0],
        "diffuse": [0.7, 0.0, 0.0],
        "specular": [1.0, 1.0, 1.0],
        "shininess": 100.0,
        "reflection": 0.5,
    });
    assert_eq!(red["material"], material, "{red}");
    assert_eq!(v["objects"][1]["radius"], 0.1, "the magenta sphere");
    // The floor is a [[plane]] entry made of a sphere.
    let floor = &v["objects"][3];
    assert_eq!(floor["entry"], "plane", "{floor}");
    assert_eq!(floor["shape"], "sphere", "{floor}");
    assert_eq!(floor["center"], json!([0.0, -9000.0, 0.0]), "{floor}");
    assert_eq!(floor["radius"], 8999.3, "{floor}");
}

/// `check --json` of a scene on stdin that sets what seed.toml leaves to the
/// defaults: the light's three colours (each different), a light off the
/// diagonal, a screen of its own, and a true plane.
#[test]
fn check_json_states_the_light_the_screen_and_a_true_plane() {
    use serde_json::json;
    let dir = tempfile::tempdir().unwrap();
    let scene = b"[camera]\nposition = [0, 0, 2]\n\
        [screen]\nleft = -0.5\nright = 0.5\ntop = 0.25\nbottom = -0.125\n\
        [light]\nposition = [1, 2, 3]\nambient = [0.1, 0.2, 0.3]\n\
        diffuse = [0.4, 0.5, 0.6]\nspecular = [0.7, 0.8, 0.9]\n\
        [[plane]]\npoint = [0, -1, 0]\nnormal = [0, 1, 0]\n";
    let out = raystep_with_input(dir.path(), &["check", "-", "--json"], scene);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["scene"], "<stdin>");
    let light = json!({
        "position": [1.0, 2.0, 3.0],
        "ambient": [0.1, 0.2, 0.3],
        "diffuse": [0.4, 0.5, 0.6],
        "specular": [0.7, 0.8, 0.9],
    });
    assert_eq!(v["light"], light);
    let screen = json!({
        "left": -0.5, "right": 0.5, "top": 0.25, "bottom": -0.125, "from_scene": true,
    });
    assert_eq!(v["screen"], screen);
    assert_eq!((&v["spheres"], &v["planes"]), (&json!(0), &json!(1)));
    let plane = &v["objects"][0];
    assert_eq!(plane["entry"], "plane", "{plane}");
    assert_eq!(plane["shape"], "plane", "{plane}");
    assert_eq!(plane["point"], json!([0.0, -1.0, 0.0]), "{plane}");
    assert_eq!(plane["normal"], json!([0.0, 1.0, 0.0]), "{plane}");
}

#[test]
fn help_and_version_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = raystep(dir.path(), &["--version"]);
    assert!(out.status.success());
    assert!(text(&out.stdout).starts_with("raystep "));
    for command in [
        &["--help"][..],
        &["render", "--help"],
        &["stages", "--help"],
        &["check", "--help"],
    ] {
        let out = raystep(dir.path(), command);
        assert!(out.status.success(), "{command:?}");
        assert!(text(&out.stdout).contains("Usage"), "{command:?}");
    }
    let out = raystep(dir.path(), &["render", "--help"]);
    let help = text(&out.stdout);
    for stage in [
        "rays",
        "intersection",
        "shadow",
        "blinn-phong",
        "reflection",
        "plane",
    ] {
        assert!(help.contains(stage), "{stage} in render --help");
    }
}

/// The smallest valid scene, with `extra` appended.
fn scene_with(extra: &str) -> String {
    format!("[camera]\nposition = [0, 0, 1]\n[light]\nposition = [5, 5, 5]\n{extra}")
}

#[test]
fn diff_compares_two_renders_and_refuses_two_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| raystep(dir.path(), args);
    assert!(
        run(&["render", "--width", "60", "--height", "40", "--out", "a"])
            .status
            .success()
    );
    assert!(run(&[
        "render",
        "--width",
        "60",
        "--height",
        "40",
        "--viewer",
        "ray-origin",
        "--out",
        "b"
    ])
    .status
    .success());
    assert!(
        run(&["render", "--width", "30", "--height", "20", "--out", "small"])
            .status
            .success()
    );

    let same = run(&["diff", "a/buffers.exr", "a/buffers.exr"]);
    assert_eq!(same.status.code(), Some(0), "the same: exit 0");
    says(&same.stdout, "differ by more than 1/255: 0 pixels (0.00 %)");
    // No place is named for the largest of no differences.
    says(
        &same.stdout,
        "largest difference:        0 (the images are the same)\n",
    );

    let other = run(&["diff", "a/buffers.exr", "b/buffers.exr"]);
    assert_eq!(
        other.status.code(),
        Some(1),
        "different: exit 1, as diff and cmp"
    );
    assert!(!text(&other.stdout).contains("differ by more than 1/255: 0 pixels"));
    says(&other.stdout, "largest difference:        0.");

    let sizes = run(&["diff", "a/buffers.exr", "small/buffers.exr"]);
    assert_eq!(sizes.status.code(), Some(2));
    says(&sizes.stderr, "60 × 40 but small/buffers.exr is 30 × 20");

    let not_exr = run(&["diff", "a/buffers.exr", "a/beauty.png"]);
    assert_eq!(not_exr.status.code(), Some(2));
    says(
        &not_exr.stderr,
        "a/beauty.png: cannot read it as an EXR file",
    );
}

#[test]
fn a_closed_stdout_is_not_a_crash() {
    // `raystep check scene | head -1`: the reader goes away after one line.
    use std::io::Read;
    use std::process::Stdio;
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/seed.toml");
    let mut child = Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args(["check", scene])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take()); // close the pipe before raystep writes
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    let status = child.wait().unwrap();
    assert!(status.success(), "{status:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn size_flags_override_a_size_the_file_gets_wrong() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("big.toml"),
        scene_with("[image]\nwidth = 20000\n"),
    )
    .unwrap();
    succeeds(
        dir.path(),
        &["render", "big.toml", "--width", "40", "--height", "30"],
    );
    let out = raystep(dir.path(), &["check", "big.toml"]);
    assert_eq!(out.status.code(), Some(2));
    says(&out.stderr, "image.width = 20000");
}

#[test]
fn max_depth_overrides_a_depth_the_file_gets_wrong_as_the_size_flags_do() {
    let dir = tempfile::tempdir().unwrap();
    let with_depth = |depth: u32| {
        scene_with(&format!(
            "[image]\nwidth = 8\nheight = 6\n[render]\nmax_depth = {depth}\n\
             [[sphere]]\ncenter = [0, 0, -1]\nradius = 0.7\n\
             ambient = [0.1, 0, 0]\ndiffuse = [0.7, 0, 0]\n\
             [[plane]]\npoint = [0, -0.7, 0]\nnormal = [0, 1, 0]\n\
             ambient = [0.1, 0.1, 0.1]\ndiffuse = [0.6, 0.6, 0.6]\n"
        ))
    };
    std::fs::write(dir.path().join("deep.toml"), with_depth(100)).unwrap();
    std::fs::write(dir.path().join("two.toml"), with_depth(2)).unwrap();
    for command in ["render", "stages"] {
        let out = raystep(
            dir.path(),
            &[command, "deep.toml", "--max-depth", "2", "-q"],
        );
        assert!(out.status.success(), "{command}: {}", text(&out.stderr));
    }
    // The flag's depth is the one rendered: the rays of a file that asks for 2.
    let rays = |args: &[&str]| {
        let args = [&["render", "--json", "-q", "--out", "o"], args].concat();
        json_of(dir.path(), &args)["rays"]["total"]
            .as_u64()
            .unwrap()
    };
    let two = rays(&["two.toml"]);
    assert_eq!(rays(&["deep.toml", "--max-depth", "2"]), two);
    assert!(rays(&["deep.toml", "--max-depth", "1"]) < two);
    // Without the flag the file's value is still checked, and named.
    let out = raystep(dir.path(), &["render", "deep.toml", "-q"]);
    assert_eq!(out.status.code(), Some(2));
    says(&out.stderr, "render.max_depth = 100: must be from 1 to 64");
}

#[test]
fn bench_prints_one_json_object_with_the_promised_keys() {
    let dir = tempfile::tempdir().unwrap();
    let json = json_of(
        dir.path(),
        &[
            "bench", "--width", "64", "--height", "36", "--runs", "1", "--json",
        ],
    );
    for key in [
        "median_s",
        "rays",
        "width",
        "height",
        "threads",
        "yardstick_ratio",
        "rays_shadow",
    ] {
        assert!(!json[key].is_null(), "{key} in {json}");
    }
    assert_eq!(
        (json["width"].as_u64(), json["height"].as_u64()),
        (Some(64), Some(36))
    );
    assert_eq!(json["rays_primary"].as_u64(), Some(64 * 36));
    // The rows alone are part of every frame, so their median is no longer than
    // the frame's, and the set-up (the rest) is what is left, never negative.
    let seconds = |key: &str| {
        json[key]
            .as_f64()
            .unwrap_or_else(|| panic!("{key} in {json}"))
    };
    assert!(seconds("trace_s") > 0.0);
    assert!(seconds("trace_s") <= seconds("median_s"), "{json}");
    assert!(seconds("setup_s") >= 0.0, "{json}");
    assert!(
        seconds("trace_rays_per_s") >= seconds("rays_per_s"),
        "{json}"
    );
}

/// `bench --json`'s `bvh_nodes` is `null` when the render uses no BVH: with
/// `--accel auto`, below 24 spheres (README.md: "a BVH from 24 spheres on").
#[test]
fn bench_reports_a_bvh_from_24_spheres_on() {
    let dir = tempfile::tempdir().unwrap();
    for (count, tree) in [("23", false), ("24", true)] {
        let out = succeeds(dir.path(), &["generate", "spheres", "--count", count]);
        let file = format!("{count}.toml");
        std::fs::write(dir.path().join(&file), &out.stdout).unwrap();
        let json = json_of(
            dir.path(),
            &[
                "bench",
                &file,
                "--width",
                "16",
                "--height",
                "9",
                "--runs",
                "1",
                "--no-yardstick",
                "--accel",
                "auto",
                "--json",
            ],
        );
        assert_eq!(!json["bvh_nodes"].is_null(), tree, "{count}: {json}");
    }
}

/// `bench --json`'s derived figures are the quotients README.md defines them by,
/// each of the very times it names (a ratio inverted, or taken against another
/// run's time, breaks one), `runs` is the count asked for, and the yardstick's rays
/// are the rays of the tutorial's own render of the same frame (chapter 10: it
/// traces the same rays), not the fast engine's.
#[test]
fn bench_json_derives_each_ratio_from_the_times_it_names() {
    let dir = tempfile::tempdir().unwrap();
    let json = |args: &[&str]| json_of(dir.path(), args);
    let bench = json(&[
        "bench",
        "--width",
        "20",
        "--height",
        "12",
        "--runs",
        "3",
        "--threads",
        "2",
        "--json",
    ]);
    let get = |key: &str| {
        bench[key]
            .as_f64()
            .unwrap_or_else(|| panic!("{key} in {bench}"))
    };
    assert_eq!(bench["runs"].as_u64(), Some(3), "{bench}");
    assert_eq!(bench["threads"].as_u64(), Some(2), "{bench}");
    // (field, numerator, denominator), as README.md and the report's fields say.
    for (key, over, under) in [
        ("thread_speedup", "one_thread_median_s", "median_s"),
        ("trace_thread_speedup", "one_thread_trace_s", "trace_s"),
        ("yardstick_ratio", "yardstick_median_s", "median_s"),
        (
            "other_yardstick_ratio",
            "yardstick_median_s",
            "other_median_s",
        ),
        ("rays_per_s", "rays", "median_s"),
        ("trace_rays_per_s", "rays", "trace_s"),
        (
            "yardstick_rays_per_s",
            "yardstick_rays",
            "yardstick_median_s",
        ),
    ] {
        let expected = get(over) / get(under);
        assert!(
            (get(key) - expected).abs() <= 1e-9 * expected.abs(),
            "{key} = {} is not {over} / {under} = {expected}: {bench}",
            get(key)
        );
    }
    let pixels = 20.0 * 12.0 / get("median_s");
    assert!(
        (get("pixels_per_s") - pixels).abs() <= 1e-9 * pixels,
        "{bench}"
    );
    // The tutorial's render of the same frame counts its rays pixel by pixel.
    let tutorial = json(&[
        "render",
        "--tutorial",
        "--width",
        "20",
        "--height",
        "12",
        "-o",
        "t",
        "--json",
    ]);
    assert_eq!(
        bench["yardstick_rays"], tutorial["rays"]["total"],
        "{bench} against {tutorial}"
    );
}

#[test]
fn generate_writes_a_scene_that_loads_and_refuses_a_count_of_zero() {
    let dir = tempfile::tempdir().unwrap();
    let out = succeeds(
        dir.path(),
        &["generate", "spheres", "--count", "25", "--seed", "4"],
    );
    let scene = raystep::io::scene_file::parse(&text(&out.stdout), "generated").unwrap();
    assert_eq!(scene.objects.len(), 26, "25 spheres and the floor");
    let again = raystep(
        dir.path(),
        &["generate", "spheres", "--count", "25", "--seed", "4"],
    );
    assert_eq!(out.stdout, again.stdout, "the same seed, the same bytes");
    let zero = raystep(dir.path(), &["generate", "spheres", "--count", "0"]);
    assert_eq!(zero.status.code(), Some(2));
}

#[test]
fn generate_writes_a_million_spheres_as_their_recipe_and_the_recipe_loads() {
    let dir = tempfile::tempdir().unwrap();
    let out = succeeds(
        dir.path(),
        &["generate", "spheres", "--count", "1000000", "--seed", "7"],
    );
    let file = text(&out.stdout);
    assert!(
        file.len() < 1000,
        "a recipe, not a list: {} bytes",
        file.len()
    );
    assert!(
        file.contains("[generate]\nspheres = 1000000\nseed = 7\n"),
        "{file}"
    );
    assert!(text(&out.stderr).contains("recipe"), "it says so on stderr");
    let scene = raystep::io::scene_file::parse(&file, "generated").unwrap();
    assert_eq!(
        scene.objects.len(),
        1_000_001,
        "a million spheres and the floor"
    );
    // Below the list's limit, --recipe asks for the recipe: the same scene as the list.
    let list = raystep(dir.path(), &["generate", "spheres", "--count", "40"]);
    let recipe = raystep(
        dir.path(),
        &["generate", "spheres", "--count", "40", "--recipe"],
    );
    assert!(text(&recipe.stderr).is_empty(), "{}", text(&recipe.stderr));
    says(&recipe.stdout, "[generate]\nspheres = 40\nseed = 1\n");
    assert_eq!(
        raystep::io::scene_file::parse(&text(&recipe.stdout), "recipe").unwrap(),
        raystep::io::scene_file::parse(&text(&list.stdout), "list").unwrap()
    );
}

#[test]
fn chart_writes_its_csv_svg_and_png_and_its_errors_rank_the_settings_as_chapter_10_says() {
    let dir = tempfile::tempdir().unwrap();
    succeeds(
        dir.path(),
        &[
            "chart", "--width", "32", "--height", "18", "--runs", "1", "--out", "c",
        ],
    );
    let csv = std::fs::read_to_string(dir.path().join("c/chart.csv")).unwrap();
    assert_eq!(csv.lines().count(), 18, "a header and 17 settings: {csv}");
    assert_eq!(png_size(&dir.path().join("c/chart.png")), (960, 640));
    assert!(std::fs::read_to_string(dir.path().join("c/chart.svg"))
        .unwrap()
        .starts_with("<svg"));
    // The numbers say what chapter 10 says of them: one row, `default`, is
    // raystep's default; more samples divide the error (16 below 4 below 1); a
    // `max_depth` of 1 misses reflections that 2 already has; float32 moves
    // pixels; acceleration, early stop and the book engine change none (the
    // default's error exactly); and no pixel's error is below the root mean
    // square of them all.
    let mut reader = csv::Reader::from_reader(csv.as_bytes());
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    let row = |setting: &str| {
        rows.iter()
            .find(|r| &r[0] == setting)
            .unwrap_or_else(|| panic!("no row {setting}: {csv}"))
    };
    let rmse = |setting: &str| -> f64 { row(setting)[2].parse().unwrap() };
    let defaults: Vec<&str> = rows
        .iter()
        .filter(|r| &r[4] == "true")
        .map(|r| &r[0])
        .collect();
    assert_eq!(defaults, ["default"], "{csv}");
    assert!(rmse("spp 16") < rmse("spp 4"), "{csv}");
    assert!(rmse("spp 4") < rmse("default"), "{csv}");
    assert!(rmse("depth 1") > rmse("depth 2"), "{csv}");
    assert_ne!(rmse("f32"), rmse("default"), "{csv}");
    for same in ["accel off", "early stop off", "book engine"] {
        assert_eq!(rmse(same), rmse("default"), "{same}: {csv}");
    }
    for r in &rows {
        let (rmse, worst): (f64, f64) = (r[2].parse().unwrap(), r[3].parse().unwrap());
        assert!(worst >= rmse, "{r:?}");
    }
}

/// Run raystep in `dir` with `input` on its standard input.
fn raystep_with_input(dir: &Path, args: &[&str], input: &[u8]) -> std::process::Output {
    use std::io::Write;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(input).unwrap();
    child.wait_with_output().unwrap()
}

#[test]
fn diff_exits_0_same_1_different_2_trouble_with_a_threshold() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| raystep(dir.path(), args);
    for (out, stage) in [("a", "plane"), ("b", "reflection")] {
        let made = run(&[
            "render", "-q", "--width", "40", "--height", "30", "--stage", stage, "-o", out,
        ]);
        assert!(made.status.success(), "{}", text(&made.stderr));
    }
    let code = |args: &[&str]| run(args).status.code();
    assert_eq!(code(&["diff", "a/buffers.exr", "a/buffers.exr"]), Some(0));
    assert_eq!(code(&["diff", "a/buffers.exr", "b/buffers.exr"]), Some(1));
    // A tolerance above any difference of colour: the same.
    assert_eq!(
        code(&["diff", "a/buffers.exr", "b/buffers.exr", "--threshold", "2"]),
        Some(0)
    );
    // As many pixels allowed to differ as do: the same; one fewer: different.
    let json = run(&["diff", "a/buffers.exr", "b/buffers.exr", "--json"]);
    assert_eq!(json.status.code(), Some(1));
    let report: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let over = report["over_threshold_percent"].as_f64().unwrap();
    assert!(over > 0.0, "{report}");
    let at = format!("{over}");
    assert_eq!(
        code(&[
            "diff",
            "a/buffers.exr",
            "b/buffers.exr",
            "--fail-percent",
            &at
        ]),
        Some(0)
    );
    // Trouble: a missing file, a bad threshold, a missing argument.
    assert_eq!(code(&["diff", "a/buffers.exr", "none.exr"]), Some(2));
    assert_eq!(
        code(&[
            "diff",
            "a/buffers.exr",
            "a/buffers.exr",
            "--threshold",
            "-1"
        ]),
        Some(2)
    );
    assert_eq!(code(&["diff", "a/buffers.exr"]), Some(2));
}

/// `diff` says where the largest difference lies as row, then column, in its
/// text and in `--json`: two 30 × 20 pictures (30 columns, 20 rows) that differ
/// in one pixel, row 5, column 17, by 0.5 in green, and by 0.1 in row 12,
/// column 3. A place given as (column, row) would be off the picture.
#[test]
fn diff_places_the_largest_difference_at_its_row_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let (width, height) = (30, 20);
    let write = |name: &str, changed: bool| {
        write_exr(dir.path(), name, (width, height), |row, col| {
            let green = match (changed, row, col) {
                (true, 5, 17) => 0.75,
                (true, 12, 3) => 0.35,
                _ => 0.25,
            };
            (0.5, green, 0.125)
        });
    };
    write("a.exr", false);
    write("b.exr", true);
    for (a, b) in [("a.exr", "b.exr"), ("b.exr", "a.exr")] {
        let json = raystep(dir.path(), &["diff", a, b, "--json"]);
        assert_eq!(json.status.code(), Some(1), "{}", text(&json.stderr));
        let report: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
        assert_eq!(report["width"], width, "{report}");
        assert_eq!(report["height"], height, "{report}");
        assert_eq!(report["largest"], 0.5, "{report}");
        assert_eq!(
            report["largest_at"],
            serde_json::json!({ "row": 5, "column": 17 }),
            "{report}"
        );
        assert_eq!(report["over_one_step"], 2, "{report}");
        let said = raystep(dir.path(), &["diff", a, b]);
        says(
            &said.stdout,
            "largest difference:        0.5000 (row 5, column 17)",
        );
    }
}

/// `over_threshold_percent` is a percentage of the pixels (README: "the same as
/// a percentage of `pixels`"), and `--fail-percent P` lets up to P percent
/// differ: two 30 × 20 pictures (600 pixels) that differ in 3 pixels by 0.5
/// differ in 0.5 % of them, different under `--fail-percent 0.4`, the same under
/// 0.5 (at most 0.5 %) and 0.6.
#[test]
fn diff_gives_the_share_of_differing_pixels_in_percent_and_fails_above_fail_percent() {
    let dir = tempfile::tempdir().unwrap();
    for (name, changed) in [("a.exr", false), ("b.exr", true)] {
        write_exr(dir.path(), name, (30, 20), |row, col| {
            let differs = changed && [(0, 0), (7, 11), (19, 29)].contains(&(row, col));
            (if differs { 0.75 } else { 0.25 }, 0.25, 0.25)
        });
    }
    let json = raystep(dir.path(), &["diff", "a.exr", "b.exr", "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(report["over_threshold"], 3, "{report}");
    let percent = report["over_threshold_percent"].as_f64().unwrap();
    assert!((percent - 0.5).abs() < 1e-9, "{report}");
    let said = raystep(dir.path(), &["diff", "a.exr", "b.exr"]);
    says(
        &said.stdout,
        "different: 3 pixels (0.50 %) differ by more than",
    );
    for (allowed, code) in [("0.4", 1), ("0.5", 0), ("0.6", 0)] {
        let out = raystep(
            dir.path(),
            &["diff", "a.exr", "b.exr", "--fail-percent", allowed],
        );
        assert_eq!(out.status.code(), Some(code), "--fail-percent {allowed}");
    }
}

/// `non_finite` counts the pixels with a channel infinite or NaN in `a`, then in
/// `b`, as `clipped` does: a has a NaN and an infinity in two pixels, b an
/// infinity in a third; swapping the files swaps the counts.
#[test]
fn diff_counts_the_pixels_not_finite_in_a_then_in_b() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, odd: &[((usize, usize), f32)]| {
        write_exr(dir.path(), name, (4, 3), |row, col| {
            let red = odd
                .iter()
                .find(|(at, _)| *at == (row, col))
                .map_or(0.5, |&(_, v)| v);
            (red, 0.5, 0.5)
        });
    };
    write("a.exr", &[((0, 1), f32::NAN), ((2, 3), f32::INFINITY)]);
    write("b.exr", &[((1, 0), f32::INFINITY)]);
    for (a, b, counts) in [("a.exr", "b.exr", [2, 1]), ("b.exr", "a.exr", [1, 2])] {
        let json = raystep(dir.path(), &["diff", a, b, "--json"]);
        let report: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
        assert_eq!(report["non_finite"], serde_json::json!(counts), "{report}");
        assert_eq!(report["over_threshold"], 3, "{report}");
        let said = raystep(dir.path(), &["diff", a, b]);
        assert!(
            text(&said.stdout).contains(&format!(
                "not finite (inf or NaN):   {} and {} pixels",
                counts[0], counts[1]
            )),
            "{}",
            text(&said.stdout)
        );
    }
}

/// README: `generate spheres` lists "up to 100,000" spheres one by one and
/// writes the recipe above: 100,000 are listed, with nothing said on stderr;
/// 100,001 are a recipe, and stderr says so (but not under `-q`).
#[test]
fn generate_lists_100000_spheres_and_writes_the_recipe_of_100001() {
    let dir = tempfile::tempdir().unwrap();
    let listed = raystep(dir.path(), &["generate", "spheres", "--count", "100000"]);
    assert_eq!(listed.status.code(), Some(0), "{}", text(&listed.stderr));
    assert!(listed.stderr.is_empty(), "{}", text(&listed.stderr));
    let file = text(&listed.stdout);
    assert_eq!(file.matches("[[sphere]]\n").count(), 100_000);
    assert!(!file.contains("[generate]"));
    let recipe = raystep(dir.path(), &["generate", "spheres", "--count", "100001"]);
    assert_eq!(recipe.status.code(), Some(0), "{}", text(&recipe.stderr));
    let file = text(&recipe.stdout);
    assert!(
        file.contains("[generate]\nspheres = 100001\nseed = 1\n") && !file.contains("[[sphere]]"),
        "{file}"
    );
    says(&recipe.stderr, "recipe");
    // `-q` silences that note too; the scene still goes to standard output.
    let quiet = raystep(
        dir.path(),
        &["-q", "generate", "spheres", "--count", "100001"],
    );
    assert_eq!(quiet.status.code(), Some(0), "{}", text(&quiet.stderr));
    assert_eq!(text(&quiet.stderr), "");
    assert_eq!(text(&quiet.stdout), file);
}

/// Issue 22's bound: a 1920 × 1080 render with every buffer (twelve pictures
/// and the EXR of 26 channels) peaks at or under 150 MB (10⁶ bytes), as
/// `render --json` reports it from `/proc` (125.8 MB with a release build on
/// 2026-12-06; the frame of records alone is 108 MB).
#[test]
fn a_1080p_render_with_every_buffer_peaks_at_or_under_150_mb() {
    let proc_status = std::path::Path::new("/proc/self/status")
        .is_file()
        .then_some(())
        .ok_or_else(|| "/proc/self/status (Linux)".to_string());
    if common::required(proc_status, "the peak memory test").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let report = json_of(
        dir.path(),
        &[
            "render", "--width", "1920", "--height", "1080", "-o", "o", "--json", "-q",
        ],
    );
    assert_eq!(report["files"].as_array().unwrap().len(), 13, "{report}");
    let peak = report["peak_memory_bytes"]
        .as_u64()
        .expect("a peak on Linux");
    let frame = 1920 * 1080 * raystep::aov::RECORD_BYTES as u64;
    assert!(
        peak > frame,
        "the frame alone is {frame} bytes; peak {peak}"
    );
    assert!(peak <= 150_000_000, "peak {peak} bytes, over 150 MB");
}

#[test]
fn json_outputs_carry_schema_1_and_the_documented_fields() {
    let dir = tempfile::tempdir().unwrap();
    let seed = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/seed.toml");
    let json = |args: &[&str]| -> serde_json::Value {
        let out = raystep(dir.path(), args);
        assert!(
            matches!(out.status.code(), Some(0 | 1)),
            "{args:?}: {}",
            text(&out.stderr)
        );
        serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{args:?}: {e}: {}", text(&out.stdout)))
    };
    let has = |value: &serde_json::Value, keys: &[&str]| {
        assert_eq!(value["schema"], 1, "{value}");
        for key in keys {
            assert!(value.get(key).is_some(), "{key} in {value}");
        }
    };

    let render = json(&[
        "render", "--width", "24", "--height", "16", "-o", "r", "--json",
    ]);
    has(
        &render,
        &[
            "scene",
            "width",
            "height",
            "stages",
            "engine",
            "precision",
            "spp",
            "out",
            "files",
            "buffers",
            "seconds",
            "rays",
            "peak_memory_bytes",
        ],
    );
    let files = render["files"].as_array().unwrap();
    assert_eq!(files.len(), 13, "twelve pictures and the EXR: {render}");
    for file in files {
        let path = dir.path().join(file["path"].as_str().unwrap());
        let bytes = std::fs::metadata(&path).unwrap().len();
        assert_eq!(file["bytes"].as_u64(), Some(bytes), "{}", path.display());
    }
    assert_eq!(render["buffers"].as_array().unwrap().len(), 12);
    for key in ["render", "write", "total"] {
        assert!(render["seconds"][key].as_f64().unwrap() >= 0.0, "{render}");
    }
    assert_eq!(render["rays"]["primary"].as_u64(), Some(24 * 16));
    // Each count is the one `bench` reports for the same frame (its engine
    // traces the same rays), and the total is their sum.
    let counted = json(&[
        "bench",
        "--width",
        "24",
        "--height",
        "16",
        "--runs",
        "1",
        "--no-yardstick",
        "--json",
    ]);
    let rays = &render["rays"];
    for (key, bench_key) in [
        ("primary", "rays_primary"),
        ("shadow", "rays_shadow"),
        ("reflection", "rays_reflection"),
        ("total", "rays"),
    ] {
        assert_eq!(
            rays[key], counted[bench_key],
            "{key}: {rays} against {counted}"
        );
    }
    let sum: u64 = ["primary", "shadow", "reflection"]
        .iter()
        .map(|k| rays[k].as_u64().unwrap())
        .sum();
    assert_eq!(rays["total"].as_u64(), Some(sum));
    assert!(
        rays["shadow"].as_u64() > rays["reflection"].as_u64(),
        "{rays}"
    );

    let check = json(&["check", seed, "--json"]);
    has(
        &check,
        &[
            "scene",
            "valid",
            "width",
            "height",
            "max_depth",
            "camera",
            "screen",
            "light",
            "spheres",
            "planes",
            "object_count",
            "objects",
        ],
    );
    assert_eq!(check["valid"], true);
    assert_eq!(
        check["objects"].as_array().unwrap().len() as u64,
        check["spheres"].as_u64().unwrap() + check["planes"].as_u64().unwrap()
    );

    let diff = json(&["diff", "r/buffers.exr", "r/buffers.exr", "--json"]);
    has(
        &diff,
        &[&["a", "b"][..], &common::DIFF_FIGURES[..]].concat(),
    );
    assert_eq!(diff["different"], false);
    assert_eq!(diff["pixels"].as_u64(), Some(24 * 16));
    // A picture differs from itself by more than 0 nowhere: threshold 0 too.
    let exact = json(&[
        "diff",
        "r/buffers.exr",
        "r/buffers.exr",
        "--threshold",
        "0",
        "--json",
    ]);
    assert_eq!(exact["over_threshold"].as_u64(), Some(0), "{exact}");
    assert_eq!(exact["different"], false);
    // `clipped` counts a's clipped pixels, then b's: the rays stage's colours,
    // (d + 1)/2 for a unit direction d, never reach 1.
    let rays_only = json(&[
        "render", "--width", "24", "--height", "16", "-o", "d", "--stage", "rays", "--json",
    ]);
    assert_eq!(rays_only["schema"], 1);
    let clipped = |a: &str, b: &str| {
        let diff = json(&["diff", a, b, "--json"]);
        let c = diff["clipped"].as_array().unwrap().clone();
        (c[0].as_u64().unwrap(), c[1].as_u64().unwrap())
    };
    let (lit, none) = clipped("r/buffers.exr", "d/buffers.exr");
    assert!(lit > 0 && none == 0, "clipped {lit}, {none}");
    assert_eq!(clipped("d/buffers.exr", "r/buffers.exr"), (0, lit));

    let explain = json(&["explain", "--pixel", "1,1", "--json"]);
    has(&explain, &["depth"]);
    let bench = json(&[
        "bench",
        "--width",
        "16",
        "--height",
        "9",
        "--runs",
        "1",
        "--no-yardstick",
        "--json",
    ]);
    has(&bench, &["median_s", "rays"]);
    let accuracy = json(&["accuracy", "--case", "far-sphere", "--json"]);
    let rows = accuracy.as_array().unwrap();
    // Two precisions × two intersection methods × four offsets.
    assert_eq!(rows.len(), 16, "{accuracy}");
    for row in rows {
        assert_eq!(row["schema"], 1, "{row}");
        assert_eq!(row["case"], "far-sphere", "{row}");
    }
}

#[test]
fn status_lines_go_to_stderr_and_quiet_silences_them() {
    let dir = tempfile::tempdir().unwrap();
    let size = ["--width", "24", "--height", "16"];
    for command in ["render", "stages"] {
        let mut args = vec![command];
        args.extend(size);
        let out = succeeds(dir.path(), &args);
        assert_eq!(text(&out.stdout), "", "{command}: stdout is for data");
        let stderr = text(&out.stderr);
        assert!(stderr.contains("24 × 16"), "{command}: {stderr}");
        assert!(stderr.contains("beauty.png"), "{command}: {stderr}");
        for quiet in ["-q", "--quiet"] {
            let mut args = vec![quiet, command];
            args.extend(size);
            let out = succeeds(dir.path(), &args);
            assert_eq!(text(&out.stdout), "", "{quiet} {command}");
            assert_eq!(text(&out.stderr), "", "{quiet} {command}");
        }
    }
    // --quiet is global: after the command too, and --json still prints.
    let out = raystep(
        dir.path(),
        &[
            "render", "--width", "8", "--height", "8", "--json", "--quiet",
        ],
    );
    assert_eq!(text(&out.stderr), "");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["width"], 8);
}

#[test]
fn completions_and_a_man_page() {
    let dir = tempfile::tempdir().unwrap();
    let bash = succeeds(dir.path(), &["completions", "bash"]);
    let script = text(&bash.stdout);
    assert!(script.contains("raystep"), "{script}");
    assert!(script.contains("complete"), "{script}");
    for shell in ["zsh", "fish", "elvish", "powershell"] {
        let out = raystep(dir.path(), &["completions", shell]);
        assert!(out.status.success(), "{shell}");
        assert!(text(&out.stdout).contains("raystep"), "{shell}");
    }
    assert_eq!(
        raystep(dir.path(), &["completions", "tcsh"]).status.code(),
        Some(2)
    );
    let man = succeeds(dir.path(), &["man"]);
    let page = text(&man.stdout);
    let first = page
        .lines()
        .find(|l| !l.starts_with(".ie") && !l.starts_with(".el"));
    assert!(first.unwrap().starts_with(".TH raystep 1"), "{page}");
    assert!(page.contains("render"), "{page}");
    // The limits and exit codes are a table, kept as written (no filling).
    let limits = page.split(".SH \"LIMITS AND EXIT CODES\"\n.nf\n").nth(1);
    let limits = limits
        .expect("a section of limits, not filled")
        .split(".fi\n")
        .next();
    assert!(limits.unwrap().contains("\nExit codes: 0 done"), "{page}");
    // Every page raystep's own page refers to is there: `raystep man COMMAND`.
    let listed: Vec<&str> = page
        .lines()
        .filter_map(|l| l.strip_prefix("raystep\\-")?.strip_suffix("(1)"))
        .collect();
    let mut listed: Vec<String> = listed.into_iter().map(String::from).collect();
    // And every page those pages refer to (generate's: generate-spheres).
    let mut k = 0;
    while k < listed.len() {
        let command = listed[k].clone();
        let page = text(&raystep(dir.path(), &["man", &command]).stdout);
        for line in page.lines() {
            let Some(name) = line
                .strip_prefix("raystep\\-")
                .and_then(|l| l.strip_suffix("(1)"))
            else {
                continue;
            };
            let name = name.replace("\\-", "-");
            if !listed.contains(&name) {
                listed.push(name);
            }
        }
        k += 1;
    }
    assert_eq!(listed, raystep::tools::args::COMMANDS, "{page}");
    for command in &listed {
        let command = command.as_str();
        let man = raystep(dir.path(), &["man", command]);
        assert!(man.status.success(), "{command}: {}", text(&man.stderr));
        let page = text(&man.stdout);
        assert!(
            page.contains(&format!(".TH raystep-{command} 1 ")),
            "{command}: {page}"
        );
        let words = command.replace('-', " ");
        assert!(page.contains(&format!("\\fBraystep {words}\\fR")), "{page}");
        // man shows a backtick as it is: the pages quote code without them.
        assert!(!page.contains('`'), "{command}: {page}");
    }
    assert_eq!(
        raystep(dir.path(), &["man", "nothing"]).status.code(),
        Some(2)
    );
}

#[test]
fn a_scene_on_stdin_and_output_aliases() {
    let dir = tempfile::tempdir().unwrap();
    let seed = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/seed.toml")).unwrap();
    let check = raystep_with_input(dir.path(), &["check", "-"], &seed);
    assert!(check.status.success(), "{}", text(&check.stderr));
    assert!(text(&check.stdout).starts_with("<stdin>: a valid scene"));
    // A pipe is not a terminal: no notice (a_scene_typed_at_a_terminal_... has it).
    assert_eq!(text(&check.stderr), "");
    let broken = raystep_with_input(dir.path(), &["check", "-"], b"[camera]\nposition = 3\n");
    assert_eq!(broken.status.code(), Some(2));
    assert!(
        text(&broken.stderr).starts_with("error: <stdin>: "),
        "{}",
        text(&broken.stderr)
    );
    for (flag, folder) in [("-o", "short"), ("--output", "long"), ("--out", "out")] {
        let args = [
            "render", "-", "--width", "12", "--height", "8", flag, folder,
        ];
        let out = raystep_with_input(dir.path(), &args, &seed);
        assert!(out.status.success(), "{flag}: {}", text(&out.stderr));
        assert!(text(&out.stderr).starts_with("<stdin>: "), "{flag}");
        assert_eq!(
            png_size(&dir.path().join(folder).join("beauty.png")),
            (12, 8)
        );
    }
    // serve follows its file, so it cannot take one from stdin: a message, exit 2.
    let serve = raystep_with_input(dir.path(), &["serve", "-", "--port", "0"], &seed);
    assert_eq!(serve.status.code(), Some(2));
    says(&serve.stderr, "cannot take one from standard input");
}

/// Where `script` (util-linux) runs a command at a terminal of its own.
fn terminal_runner() -> Result<(), String> {
    match Command::new("script").arg("--version").output() {
        Ok(out) if out.status.success() => Ok(()),
        _ => Err("script, which gives a command a terminal (apt-get install bsdutils)".into()),
    }
}

#[test]
fn a_scene_typed_at_a_terminal_is_announced_before_it_is_read() {
    use std::io::Write;
    use std::process::Stdio;
    if common::required(terminal_runner(), "the terminal test").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let seed = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/seed.toml")).unwrap();
    let command = format!("'{}' check -", env!("CARGO_BIN_EXE_raystep"));
    let mut child = Command::new("script")
        .args(["-qec", &command, "/dev/null"])
        .current_dir(dir.path())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The scene, then Ctrl-D at the start of a line: the end of what is typed.
    let mut typed = seed.clone();
    typed.push(4);
    child.stdin.take().unwrap().write_all(&typed).unwrap();
    let out = child.wait_with_output().unwrap();
    let said = text(&out.stdout);
    assert!(out.status.success(), "{said}{}", text(&out.stderr));
    let notice = said
        .find("reading the scene from standard input (end it with Ctrl-D)")
        .unwrap_or_else(|| panic!("no notice in:\n{said}"));
    let report = said
        .find("<stdin>: a valid scene")
        .unwrap_or_else(|| panic!("{said}"));
    assert!(notice < report, "{said}");
}

/// At a terminal, the job's one bar goes on through the writing (README: each
/// row counts twice, traced, then written): at 1280 × 720 the write phase of a
/// debug build takes most of a second, and the bar is drawn in it between 50 %
/// (every row traced) and 100 %. A release build writes that size in under the
/// bar's tick of 250 ms, so it renders 3840 × 2160 (about half a second of
/// writing).
#[test]
fn the_bar_at_a_terminal_counts_the_rows_written_too() {
    if common::required(terminal_runner(), "the terminal test").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let size = match cfg!(debug_assertions) {
        true => "--width 1280 --height 720",
        false => "--width 3840 --height 2160",
    };
    let command = format!(
        "'{}' render {size} --out out",
        env!("CARGO_BIN_EXE_raystep")
    );
    let out = Command::new("script")
        .args(["-qec", &command, "/dev/null"])
        .current_dir(dir.path())
        .stdin(std::process::Stdio::null())
        .output()
        .unwrap();
    let said = text(&out.stdout);
    assert!(out.status.success(), "{said}{}", text(&out.stderr));
    // Each drawing of the bar: its phase, then "] NN %".
    let shares = |phase: &str| -> Vec<u32> {
        said.split(phase)
            .skip(1)
            .filter_map(|rest| {
                let share = rest.split_once(']')?.1.split_once('%')?.0;
                share.trim().parse().ok()
            })
            .collect()
    };
    let (traced, written) = (shares("rendering"), shares("writing files"));
    assert!(traced.iter().all(|&p| p <= 50), "{traced:?}");
    assert!(written.iter().all(|&p| p >= 50), "{written:?}");
    assert!(
        written.iter().any(|&p| 50 < p && p < 100),
        "no drawing while the files were written: {written:?}\n{said}"
    );
    assert_eq!(written.iter().max(), Some(&100), "{written:?}");
}

#[test]
fn no_help_shows_rustdoc_syntax() {
    let dir = tempfile::tempdir().unwrap();
    let commands: &[&[&str]] = &[
        &[],
        &["stages"],
        &["render"],
        &["explain"],
        &["check"],
        &["diff"],
        &["figures"],
        &["accuracy"],
        &["bench"],
        &["generate"],
        &["generate", "spheres"],
        &["chart"],
        &["serve"],
        &["completions"],
        &["man"],
    ];
    for command in commands {
        for help in ["--help", "-h"] {
            let mut args = command.to_vec();
            args.push(help);
            let out = raystep(dir.path(), &args);
            assert!(out.status.success(), "{args:?}");
            let said = text(&out.stdout);
            assert!(said.contains("Usage"), "{args:?}");
            // Backticks too: a terminal shows them as they are, not as code.
            for rustdoc in ["`", "](", "crate::"] {
                assert!(
                    !said.contains(rustdoc),
                    "{args:?} shows {rustdoc:?}:\n{said}"
                );
            }
        }
    }
    // The number --accel's help states is the one the code uses.
    let help = text(&raystep(dir.path(), &["render", "--help"]).stdout);
    let from = format!("A BVH from {} spheres on", raystep::accel::BVH_FROM);
    assert!(help.contains(&from), "{help}");
}

#[test]
fn float32_messages_name_the_scene_and_the_object_as_explain_numbers_it() {
    // What --precision f32 refuses or warns about is named by its file, and by
    // the object's number in explain, the studio and the object buffer.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let render = |scene: &str| {
        let scene = root.join("scenes/stress").join(scene);
        let args = ["render", scene.to_str().unwrap(), "--precision", "f32"];
        // The scenes' screens are 3:2, so is the image: square pixels, no warning.
        let size = [
            "--width",
            "9",
            "--height",
            "6",
            "-q",
            "--out",
            out.to_str().unwrap(),
        ];
        let run = raystep(dir.path(), &[&args[..], &size[..]].concat());
        (
            run.status.code(),
            text(&run.stderr),
            scene.display().to_string(),
        )
    };
    let (code, said, scene) = render("seed-moved-1e5.toml");
    assert_eq!(code, Some(2), "{said}");
    assert!(
        said.starts_with(&format!(
            "error: {scene}: --precision f32: object 1 ([[sphere]] number 2), radius: 0.1 is \
             smaller than 0.100001, "
        )),
        "{said}"
    );
    let (code, said, scene) = render("twins.toml");
    assert_eq!(code, Some(0), "{said}");
    assert!(
        said.starts_with(&format!(
            "warning: {scene}: --precision f32: object 1 ([[sphere]] number 2, a sphere, \
             center [0, 0, -3], \
             radius 1.000000001) is object 0 in float32"
        )),
        "{said}"
    );
}

#[test]
fn chapter_one_shows_where_a_value_out_of_range_is() {
    // The chapter's example: the seed with its second sphere's radius made -0.1,
    // refused with the line and column of the value, as a syntax error is.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shown = common::transcript(
        "01-scene.md",
        "raystep check scenes/seed.toml    # with the second sphere's radius made -0.1",
    );
    let seed = std::fs::read_to_string(root.join("scenes/seed.toml")).unwrap();
    let changed = seed.replacen("\nradius = 0.1\n", "\nradius = -0.1\n", 1);
    assert_ne!(changed, seed);
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("scenes")).unwrap();
    std::fs::write(dir.path().join("scenes/seed.toml"), changed).unwrap();
    let out = raystep(dir.path(), &["check", "scenes/seed.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(shown, text(&out.stderr));
}

#[test]
fn status_lines_and_refusals_say_what_they_mean() {
    let dir = tempfile::tempdir().unwrap();
    // A folder given with a slash is named with one.
    let out = succeeds(
        dir.path(),
        &["render", "--width", "8", "--height", "6", "-o", "r1/"],
    );
    let said = text(&out.stderr);
    assert!(
        said.contains("\n  r1/ ") && !said.contains("r1//"),
        "{said}"
    );
    // bench keeps its status line on standard error with --json, and a ratio
    // below 1 reads as one ("0.5× as fast", not "0.5× faster").
    let out = succeeds(
        dir.path(),
        &[
            "bench", "--width", "8", "--height", "6", "--runs", "1", "--json",
        ],
    );
    assert!(
        text(&out.stderr).starts_with("scenes/seed.toml (built in): rays+"),
        "{}",
        text(&out.stderr)
    );
    serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap();
    let words = text(
        &raystep(
            dir.path(),
            &["bench", "--width", "8", "--height", "6", "--runs", "1"],
        )
        .stdout,
    );
    assert!(
        words.contains("threads are ") && words.contains("× as fast"),
        "{words}"
    );
    assert!(!words.contains("faster"), "{words}");
    // An option that means something only with another is refused without it.
    let out = raystep(dir.path(), &["chart", "--max-count", "10"]);
    assert_eq!(out.status.code(), Some(2));
    says(&out.stderr, "--scale");
}

#[test]
fn each_exr_compression_writes_the_scheme_openexr_names() {
    // OpenEXR's schemes, and the scan lines each packs into one block: none,
    // RLE and ZIPS one, ZIP 16, PIZ 32. Every lossless scheme reads back the
    // same samples, so only the file's header tells them apart.
    use exr::compression::Compression;
    let dir = tempfile::tempdir().unwrap();
    for (name, scheme, lines) in [
        ("none", Compression::Uncompressed, 1),
        ("rle", Compression::RLE, 1),
        ("zips", Compression::ZIP1, 1),
        ("zip", Compression::ZIP16, 16),
        ("piz", Compression::PIZ, 32),
    ] {
        let args = [
            "render",
            "--width",
            "24",
            "--height",
            "40",
            "--exr-compression",
            name,
            "-o",
            name,
            "-q",
        ];
        let out = raystep(dir.path(), &args);
        assert!(out.status.success(), "{name}: {}", text(&out.stderr));
        let path = dir.path().join(name).join("buffers.exr");
        let header = exr_header(&path);
        assert_eq!(header.compression, scheme, "--exr-compression {name}");
        assert_eq!(header.compression.scan_lines_per_block(), lines);
        assert_eq!(header.chunk_count, 40usize.div_ceil(lines), "{name}");
    }
}

/// The chunk types of a PNG file, in order (README: `--png srgb` writes an
/// `sRGB` chunk, `linear` none).
fn png_chunks(path: &Path) -> Vec<String> {
    common::png_chunks(&png_file(path))
}

/// The header of the EXR file at `path` (its one part).
fn exr_header(path: &Path) -> exr::meta::header::Header {
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    meta.headers.into_iter().next().unwrap()
}

/// README: without `--out`, `render` and `stages` write into `out/`; `--output
/// DIR` and `-o DIR` are aliases of `--out DIR`, on `stages` as on `render`.
#[test]
fn the_output_folder_is_out_unless_given_and_stages_takes_both_aliases() {
    let dir = tempfile::tempdir().unwrap();
    let size = ["--width", "12", "--height", "8", "-q"];
    succeeds(dir.path(), &[&["render"][..], &size].concat());
    assert_eq!(png_size(&dir.path().join("out/beauty.png")), (12, 8));
    succeeds(dir.path(), &[&["stages"][..], &size].concat());
    assert_eq!(
        png_size(&dir.path().join("out/06-plane/beauty.png")),
        (12, 8)
    );
    for (flag, folder) in [("-o", "short"), ("--output", "long")] {
        let out = raystep(dir.path(), &[&["stages", flag, folder][..], &size].concat());
        assert!(out.status.success(), "stages {flag}: {}", text(&out.stderr));
        let beauty = dir.path().join(folder).join("01-rays/beauty.png");
        assert_eq!(png_size(&beauty), (12, 8), "stages {flag}");
    }
}

/// The README's table of rules: raystep's defaults are f64, stable, auto, the
/// camera as the viewer, early stop on (and one sample per pixel); `--tutorial`
/// sets every option to the tutorial's (f64, naive, fixed:1e-5, camera, early
/// stop off); flags given beside it still apply. `explain --json` states the
/// rules in force (`rules`), so each of the five shows.
#[test]
fn tutorial_sets_all_five_rules_and_flags_beside_it_still_apply() {
    let dir = tempfile::tempdir().unwrap();
    let rules = |flags: &[&str]| -> String {
        let args = [&["explain", "--pixel", "150,100", "--json"][..], flags].concat();
        let story = json_of(dir.path(), &args);
        story["rules"].as_str().unwrap().to_string()
    };
    assert_eq!(
        rules(&[]),
        "precision f64, intersection stable, offset auto, viewer camera, early stop on, \
         1 sample per pixel"
    );
    assert_eq!(
        rules(&["--tutorial"]),
        "precision f64, intersection naive, offset fixed:1e-5, viewer camera, \
         early stop off, 1 sample per pixel"
    );
    assert_eq!(
        rules(&[
            "--tutorial",
            "--precision",
            "f32",
            "--intersect",
            "stable",
            "--offset",
            "scene",
            "--viewer",
            "ray-origin",
            "--early-stop",
            "on",
            "--spp",
            "4",
        ]),
        "precision f32, intersection stable, offset scene, viewer ray origin, \
         early stop on, 4 samples per pixel"
    );
    // `fixed:0` is a valid offset (README: it shows shadow acne).
    assert!(
        rules(&["--offset", "fixed:0"]).contains(", offset fixed:0, "),
        "fixed:0"
    );
}

/// `render --json` states what the flags asked for: by default every stage
/// (README: `--stage` defaults to `plane`, all of them), the book engine and one
/// sample per pixel; `--engine fast --spp 4 --max-depth 1` is the fast engine,
/// 4 samples per pixel and the centre ray that gives the buffers (chapter 10:
/// "one more path per pixel"), 5 primary rays a pixel, and no reflected ray at
/// all (a path of one segment).
#[test]
fn render_json_states_the_stages_engine_samples_and_depth_the_flags_ask_for() {
    let dir = tempfile::tempdir().unwrap();
    let json = |flags: &[&str]| {
        let render = ["render", "--width", "12", "--height", "8", "-q", "--json"];
        json_of(dir.path(), &[&render[..], flags].concat())
    };
    let plain = json(&[]);
    assert_eq!(
        plain["stages"], "rays+intersection+shadow+blinn-phong+reflection+plane",
        "{plain}"
    );
    assert_eq!(plain["engine"], "book", "{plain}");
    assert_eq!(plain["spp"], 1, "{plain}");
    assert_eq!(plain["rays"]["primary"], 12 * 8, "{plain}");
    assert!(plain["rays"]["reflection"].as_u64() > Some(0), "{plain}");
    let asked = json(&["--engine", "fast", "--spp", "4", "--max-depth", "1"]);
    assert_eq!(asked["engine"], "fast", "{asked}");
    assert_eq!(asked["spp"], 4, "{asked}");
    assert_eq!(asked["rays"]["primary"], (4 + 1) * 12 * 8, "{asked}");
    assert_eq!(asked["rays"]["reflection"], 0, "{asked}");
}

/// README: `--png` defaults to `linear` (a PNG with no colour chunk) and
/// `--exr-compression` to `none`; `--png srgb` adds an `sRGB` chunk, and both
/// flags work on `stages` as on `render`.
#[test]
fn png_and_exr_defaults_and_their_flags_on_render_and_stages() {
    use exr::compression::Compression;
    let dir = tempfile::tempdir().unwrap();
    let size = ["--width", "12", "--height", "8", "-q"];
    succeeds(
        dir.path(),
        &[&["render", "-o", "plain"][..], &size].concat(),
    );
    let plain = dir.path().join("plain");
    assert!(!png_chunks(&plain.join("beauty.png")).contains(&"sRGB".to_string()));
    assert_eq!(
        exr_header(&plain.join("buffers.exr")).compression,
        Compression::Uncompressed
    );
    succeeds(
        dir.path(),
        &[&["render", "-o", "srgb", "--png", "srgb"][..], &size].concat(),
    );
    let chunks = png_chunks(&dir.path().join("srgb/beauty.png"));
    assert!(chunks.contains(&"sRGB".to_string()), "{chunks:?}");

    let flags = ["--png", "srgb", "--exr-compression", "zip"];
    succeeds(
        dir.path(),
        &[&["stages", "-o", "st"][..], &flags, &size].concat(),
    );
    for stage in ["01-rays", "06-plane"] {
        let folder = dir.path().join("st").join(stage);
        let chunks = png_chunks(&folder.join("beauty.png"));
        assert!(chunks.contains(&"sRGB".to_string()), "{stage}: {chunks:?}");
        assert_eq!(
            exr_header(&folder.join("buffers.exr")).compression,
            Compression::ZIP16,
            "{stage}"
        );
    }
}

/// README: `completions SHELL` writes a script for that shell, in its own
/// syntax: bash's `complete -F`, zsh's `#compdef` line, fish's `complete -c`,
/// elvish's `arg-completer` and PowerShell's `Register-ArgumentCompleter`.
#[test]
fn completions_are_written_in_each_shells_own_syntax() {
    let dir = tempfile::tempdir().unwrap();
    for (shell, mark) in [
        ("bash", "complete -F _raystep"),
        ("zsh", "#compdef raystep"),
        ("fish", "complete -c raystep"),
        ("elvish", "edit:completion:arg-completer[raystep]"),
        (
            "powershell",
            "Register-ArgumentCompleter -Native -CommandName 'raystep'",
        ),
    ] {
        let out = raystep(dir.path(), &["completions", shell]);
        assert!(out.status.success(), "{shell}: {}", text(&out.stderr));
        let script = text(&out.stdout);
        assert!(script.contains(mark), "{shell}: {script}");
    }
}

/// README: `--engine fast` is the default of `bench` (it measures speed), and
/// `--engine book` still picks the book's engine there; `bench --json` names the
/// engine timed (`engine`) and the other one (`other_engine`).
#[test]
fn bench_times_the_fast_engine_unless_the_book_is_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let bench = |flags: &[&str]| {
        let bench = ["bench", "--width", "8", "--height", "6", "--runs", "1"];
        let quiet = ["--no-yardstick", "--json", "-q"];
        json_of(dir.path(), &[&bench[..], &quiet, flags].concat())
    };
    let default = bench(&[]);
    assert_eq!(default["engine"], "fast", "{default}");
    assert_eq!(default["other_engine"], "book", "{default}");
    let book = bench(&["--engine", "book"]);
    assert_eq!(book["engine"], "book", "{book}");
}
