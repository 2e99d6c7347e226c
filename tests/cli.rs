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

fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(
        &bytes[..8],
        b"\x89PNG\r\n\x1a\n",
        "{} is a PNG",
        path.display()
    );
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    (be(16), be(20))
}

#[test]
fn no_arguments_renders_every_stage_of_the_built_in_scene_from_any_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = raystep(dir.path(), &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // Quiet on stderr when it is not a terminal: no progress bar, no warnings.
    assert_eq!(text(&out.stderr), "");
    let stdout = text(&out.stdout);
    assert!(stdout.contains("wrote 6 stages"), "{stdout}");
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
    let out = raystep(dir.path(), &args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("rays+intersection+blinn-phong+reflection+plane"));
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
    ] {
        assert!(stdout.contains(expected), "{expected:?} in\n{stdout}");
    }
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
    assert!(same.status.success());
    assert!(
        text(&same.stdout).contains("differ by more than 1/255: 0 pixels (0.00 %)"),
        "{}",
        text(&same.stdout)
    );

    let other = run(&["diff", "a/buffers.exr", "b/buffers.exr"]);
    assert!(other.status.success());
    assert!(!text(&other.stdout).contains("differ by more than 1/255: 0 pixels"));

    let sizes = run(&["diff", "a/buffers.exr", "small/buffers.exr"]);
    assert_eq!(sizes.status.code(), Some(2));
    assert!(text(&sizes.stderr).contains("60 × 40 but small/buffers.exr is 30 × 20"));

    let not_exr = run(&["diff", "a/buffers.exr", "a/beauty.png"]);
    assert_eq!(not_exr.status.code(), Some(2));
    assert!(text(&not_exr.stderr).contains("a/beauty.png: cannot read it as an EXR file"));
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
    let out = raystep(
        dir.path(),
        &["render", "big.toml", "--width", "40", "--height", "30"],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = raystep(dir.path(), &["check", "big.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("image.width = 20000"));
}

#[test]
fn bench_prints_one_json_object_with_the_promised_keys() {
    let dir = tempfile::tempdir().unwrap();
    let out = raystep(
        dir.path(),
        &[
            "bench", "--width", "64", "--height", "36", "--runs", "1", "--json",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
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
}

#[test]
fn generate_writes_a_scene_that_loads_and_refuses_a_count_of_zero() {
    let dir = tempfile::tempdir().unwrap();
    let out = raystep(
        dir.path(),
        &["generate", "spheres", "--count", "25", "--seed", "4"],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
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
fn chart_writes_its_csv_svg_and_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = raystep(
        dir.path(),
        &[
            "chart", "--width", "32", "--height", "18", "--runs", "1", "--out", "c",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let csv = std::fs::read_to_string(dir.path().join("c/chart.csv")).unwrap();
    assert_eq!(csv.lines().count(), 16, "a header and 15 settings: {csv}");
    assert_eq!(png_size(&dir.path().join("c/chart.png")), (960, 640));
    assert!(std::fs::read_to_string(dir.path().join("c/chart.svg"))
        .unwrap()
        .starts_with("<svg"));
}
