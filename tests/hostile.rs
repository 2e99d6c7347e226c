//! Hostile input: every mistake a user can type or write in a scene ends in one
//! clear message and exit code 2, never a panic, a hang, a NaN image or a lost
//! file; and an interrupted or killed render leaves the files of the render before
//! it as they were.
//!
//! The corpus is in `tests/hostile/`:
//!
//! - `scenes/*.toml`: one bad (or odd but valid) scene file each. Its first lines
//!   say what is wrong with it and what raystep must answer:
//!   `# expect-exit: 2` and one `# expect: TEXT` per text the message must hold.
//! - `commands.toml`: command lines, with the exit code and texts each must give.
//!
//! A case is added by adding a file or a `[[case]]`; nothing here needs to change.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use serde::Deserialize;

mod common;
use common::raystep;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hostile")
}

/// What a case expects: the exit code and the texts the output must hold.
#[derive(Debug, Deserialize)]
struct Expected {
    exit: i32,
    expect: Vec<String>,
}

/// The expectations written at the top of a scene file of the corpus.
fn expected_of(text: &str) -> Expected {
    let mut exit = None;
    let mut expect = Vec::new();
    for line in text.lines().map(|l| l.trim_end_matches('\r')) {
        if let Some(code) = line.strip_prefix("# expect-exit: ") {
            exit = Some(code.parse().expect("an exit code"));
        } else if let Some(words) = line.strip_prefix("# expect: ") {
            expect.push(words.to_string());
        }
    }
    Expected {
        exit: exit.expect("every corpus file says `# expect-exit: N`"),
        expect,
    }
}

/// Check one run against `expected`; `what` names the case in failures.
fn check_output(what: &str, out: &Output, expected: &Expected) {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let said = format!("{stderr}{stdout}");
    assert_eq!(
        out.status.code(),
        Some(expected.exit),
        "{what}: exit code; it said:\n{said}"
    );
    assert!(
        !said.contains("panicked") && !said.contains("RUST_BACKTRACE"),
        "{what}: a panic:\n{said}"
    );
    // Nothing a terminal would obey: a scene's control characters are quoted as
    // their pictures (␛ for ESC).
    assert!(
        !said.contains(|c: char| c.is_control() && c != '\n' && c != '\t'),
        "{what}: a control character reaches the terminal:\n{said:?}"
    );
    for words in &expected.expect {
        assert!(
            said.contains(words.as_str()),
            "{what}: {words:?} is not in:\n{said}"
        );
    }
    if expected.exit >= 2 {
        // One message, on stderr, and nothing on stdout (exit code 1 is diff's
        // "different", a report and no error).
        assert_eq!(
            stderr.matches("error:").count(),
            1,
            "{what}: one message:\n{stderr}"
        );
        assert_eq!(stdout, "", "{what}: stdout");
    }
}

/// Every path under `dir` (hidden ones too, folders included, and what is in
/// them), relative to `dir`, sorted.
fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut folders = vec![dir.to_path_buf()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path.clone());
            }
            found.push(path.strip_prefix(dir).unwrap().to_path_buf());
        }
    }
    found.sort();
    found
}

/// Every file under `dir`, with its bytes.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    walk(dir)
        .into_iter()
        .filter(|p| dir.join(p).is_file())
        .map(|p| {
            (
                p.display().to_string(),
                std::fs::read(dir.join(&p)).unwrap(),
            )
        })
        .collect()
}

/// Every name under `dir`, folders included.
fn names(dir: &Path) -> Vec<String> {
    walk(dir).iter().map(|p| p.display().to_string()).collect()
}

/// The scene files of the corpus, sorted by name.
fn scene_files() -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(corpus().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    paths
}

#[derive(Deserialize)]
struct Commands {
    case: Vec<CommandCase>,
}

#[derive(Deserialize)]
struct CommandCase {
    what: String,
    args: Vec<String>,
    #[serde(flatten)]
    expected: Expected,
}

fn command_cases() -> Vec<CommandCase> {
    let text = std::fs::read_to_string(corpus().join("commands.toml")).unwrap();
    toml::from_str::<Commands>(&text).unwrap().case
}

/// The smallest scene, with one sphere.
const OK_SCENE: &str = "[camera]\nposition = [0, 0, 1]\n[light]\nposition = [5, 5, 5]\n\
                        [[sphere]]\ncenter = [0, 0, -1]\nradius = 0.5\n";

/// Files the command cases name as `{fixtures}/…`, made once.
fn fixtures() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let at = |name: &str| dir.path().join(name);
        std::fs::write(at("binary.toml"), [0xff, 0xfe, 0x00, 0x12, 0x9c]).unwrap();
        // A scene saved as Latin-1: "café" in a comment on line 2.
        std::fs::write(
            at("latin1.toml"),
            b"[camera]\nposition = [0, 0, 1] # caf\xe9\n",
        )
        .unwrap();
        std::fs::write(at("empty.toml"), "").unwrap();
        // 100 MB that take no room: the file is sparse.
        let huge = std::fs::File::create(at("huge.toml")).unwrap();
        huge.set_len(100_000_000).unwrap();
        std::fs::write(at("bom.toml"), format!("\u{feff}{OK_SCENE}")).unwrap();
        let out = raystep(
            dir.path(),
            &["render", "--width", "40", "--height", "30", "--out", "good"],
        );
        assert!(out.status.success());
        let exr = std::fs::read(at("good/buffers.exr")).unwrap();
        std::fs::copy(at("good/buffers.exr"), at("good.exr")).unwrap();
        std::fs::copy(at("good/beauty.png"), at("beauty.png")).unwrap();
        std::fs::write(at("truncated.exr"), &exr[..exr.len() / 3]).unwrap();
        let mut noise = exr.clone();
        // From past the header (about 850 bytes with 26 channels): the offsets
        // and the pixels. Flipped channel names read as another file's channels.
        for i in (1000..noise.len()).step_by(97) {
            noise[i] ^= 0x5a;
        }
        std::fs::write(at("noise.exr"), noise).unwrap();
        // The header's dataWindow (a box2i: x min, y min, x max, y max) made huge.
        let mut huge_header = exr;
        let key = b"dataWindow\0box2i\0";
        let at_box = huge_header
            .windows(key.len())
            .position(|w| w == key)
            .expect("a dataWindow attribute")
            + key.len()
            + 4;
        for corner in [8, 12] {
            huge_header[at_box + corner..at_box + corner + 4]
                .copy_from_slice(&1_999_999i32.to_le_bytes());
        }
        std::fs::write(at("huge-header.exr"), huge_header).unwrap();
        // Flat grey, and the same with a NaN, an infinity and a -infinity.
        let grey = |x: usize, y: usize| match (x, y) {
            (3, 2) => (f32::NAN, 0.5, 0.5),
            (4, 2) => (f32::INFINITY, 0.5, 0.5),
            (5, 2) => (0.5, f32::NEG_INFINITY, 0.5),
            _ => (0.5, 0.5, 0.5),
        };
        exr::prelude::write_rgb_file(at("flat.exr"), 8, 4, |_, _| (0.5f32, 0.5f32, 0.5f32))
            .unwrap();
        exr::prelude::write_rgb_file(at("non-finite.exr"), 8, 4, grey).unwrap();
        // A real EXR file with a depth channel and no colour.
        {
            use exr::prelude::*;
            let depth = SpecificChannels::build()
                .with_channel("Z")
                .with_pixel_fn(|_| (1.0f32,));
            Image::from_channels((8, 4), depth)
                .write()
                .to_file(at("depth-only.exr"))
                .unwrap();
        }
        dir
    })
    .path()
}

#[test]
fn every_bad_scene_file_ends_in_its_message_and_writes_nothing() {
    let paths = scene_files();
    for path in &paths {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(path).unwrap();
        let expected = expected_of(&text);
        let dir = tempfile::tempdir().unwrap();
        let file = path.to_str().unwrap();
        // `check` and `render` load the same way and must say the same.
        for args in [&["check", file][..], &["render", file, "--out", "out"]] {
            let out = raystep(dir.path(), args);
            let what = format!("{name} ({})", args[0]);
            check_output(&what, &out, &expected);
            if expected.exit != 0 {
                assert!(
                    String::from_utf8_lossy(&out.stderr).contains(file),
                    "{what}: the message names the file"
                );
                assert_eq!(names(dir.path()), Vec::<String>::new(), "{what}: wrote");
            }
        }
        if expected.exit == 0 {
            // What is accepted renders to finite colours in [0, 1].
            let exr = dir.path().join("out/buffers.exr");
            let (_, _, pixels) = raystep::tools::compare::read_beauty(&exr).unwrap();
            assert!(
                pixels.iter().flatten().all(|c| (0.0..=1.0).contains(c)),
                "{name}: a colour outside [0, 1]"
            );
        }
    }
    assert!(paths.len() >= 132, "{} scene files", paths.len());
    let said = format!("`tests/hostile/`: {} scene files", paths.len());
    assert!(
        common::readme_words().contains(&said),
        "the README should say {said:?}"
    );
}

#[test]
fn every_bad_command_line_ends_in_its_message_and_writes_nothing() {
    let fixtures = fixtures().to_str().unwrap().to_string();
    let cases = command_cases();
    for case in &cases {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("ok.toml"), OK_SCENE).unwrap();
        std::fs::write(dir.path().join("notes.txt"), "not a folder").unwrap();
        let before = files(dir.path());
        let args: Vec<String> = case
            .args
            .iter()
            .map(|a| a.replace("{fixtures}", &fixtures))
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let start = Instant::now();
        let out = raystep(dir.path(), &args);
        check_output(&case.what, &out, &case.expected);
        if case.expected.exit != 0 {
            assert_eq!(files(dir.path()), before, "{}: wrote", case.what);
            // Refused before any work: a mistake is told at once.
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "{}: took {:?}",
                case.what,
                start.elapsed()
            );
        }
    }
    assert!(cases.len() >= 78, "{} command cases", cases.len());
    let said = format!("and {} command lines in `commands.toml`", cases.len());
    assert!(
        common::readme_words().contains(&said),
        "the README should say {said:?}"
    );
    // With the scene files: the 200 inputs of the corpus, at least.
    assert!(cases.len() + scene_files().len() >= 200);
}

/// The output folder of a case where the user cannot write. Root may write
/// anywhere, so as root (CI's user, often) raystep is run as the user `nobody`
/// (uid 65534) through util-linux's `setpriv`.
#[test]
fn a_folder_without_write_permission_is_refused_before_rendering() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    // `nobody` may enter the temporary folder (made 0700) but not write there.
    std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755)).unwrap();
    let locked = dir.path().join("locked");
    std::fs::create_dir(&locked).unwrap();
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
    let args = ["render", "--out", "locked"];
    let out = if std::fs::write(locked.join("probe"), "").is_ok() {
        std::fs::remove_file(locked.join("probe")).unwrap();
        let setpriv = Command::new("setpriv").arg("--version").output();
        let found = match setpriv {
            Ok(out) if out.status.success() => Ok(()),
            _ => Err("setpriv (util-linux), to run raystep as nobody".to_string()),
        };
        if common::required(found, "the permission test as root").is_none() {
            return;
        }
        // A copy of the binary beside the folder: `nobody` may not reach the
        // checkout (under /root, say).
        let binary = dir.path().join("raystep");
        std::fs::copy(env!("CARGO_BIN_EXE_raystep"), &binary).unwrap();
        (Command::new("setpriv"))
            .args(["--reuid=65534", "--regid=65534", "--clear-groups"])
            .arg(&binary)
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap()
    } else {
        raystep(dir.path(), &args)
    };
    check_output(
        "a read-only folder",
        &out,
        &Expected {
            exit: 2,
            expect: vec![
                "cannot write locked".into(),
                "cannot write files in the output folder".into(),
                "Permission denied".into(),
            ],
        },
    );
}

#[test]
fn raystep_writes_only_the_names_it_owns() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    // A user's own files beside the outputs, and names close to raystep's.
    let mine = [
        ("notes.txt", "my notes"),
        ("beauty.png.bak", "an old copy"),
        (".beauty.png.tmp", "another program's temporary"),
        ("01-rays/my-sketch.svg", "<svg/>"),
        // At the names of buffers a rays-only render does not write, in folders
        // that never held raystep's buffers.exr: the user's, not stale buffers.
        ("depth.png", "my own depth"),
        ("01-rays/normal.png", "my own normals"),
    ];
    std::fs::create_dir(out.join("01-rays")).unwrap();
    for (name, text) in mine {
        std::fs::write(out.join(name), text).unwrap();
    }
    for args in [
        &["stages", "--width", "40", "--height", "30"][..],
        &[
            "render", "--stage", "rays", "--width", "40", "--height", "30",
        ],
    ] {
        let run = raystep(dir.path(), args);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        for (name, text) in mine {
            assert_eq!(
                std::fs::read_to_string(out.join(name)).unwrap(),
                text,
                "{name}"
            );
        }
    }
    // What is there: the user's files and raystep's own names, nothing else.
    let owned: Vec<String> = names(&out)
        .into_iter()
        .filter(|n| !mine.iter().any(|(m, _)| m == n))
        .collect();
    for name in &owned {
        let file = name.rsplit('/').next().unwrap();
        let known = file.ends_with(".png")
            || ["buffers.exr", "pixels.js", "index.html"].contains(&file)
            || (name.matches('/').count() == 0 && name.starts_with("0"));
        assert!(known, "raystep wrote {name}");
        assert!(!file.ends_with(".tmp"), "a temporary file was left: {name}");
    }
}

/// A buffer's PNG is stale, and removed by a render that does not write it, only
/// when the earlier render's `buffers.exr` in that folder lists the buffer's
/// channels: with that file gone, or not an EXR, `depth.png` is left alone.
#[test]
fn only_the_buffers_the_earlier_exr_lists_are_removed_as_stale() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let mut all = vec!["render", "--width", "20", "--height", "10"];
        all.extend_from_slice(args);
        let out = raystep(dir.path(), &all);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let out = dir.path().join("out");
    run(&[]);
    let depth = std::fs::read(out.join("depth.png")).unwrap();
    for not_raysteps in [None, Some("not an EXR")] {
        match not_raysteps {
            None => std::fs::remove_file(out.join("buffers.exr")).unwrap(),
            Some(text) => std::fs::write(out.join("buffers.exr"), text).unwrap(),
        }
        run(&["--stage", "rays"]);
        assert_eq!(std::fs::read(out.join("depth.png")).unwrap(), depth);
        // The rays-only render's own EXR lists no depth: still left alone.
        run(&["--stage", "rays"]);
        assert_eq!(std::fs::read(out.join("depth.png")).unwrap(), depth);
    }
    // After a render of every buffer, its EXR lists them: a rays-only render
    // removes every PNG it does not write.
    run(&[]);
    run(&["--stage", "rays"]);
    let mut left: Vec<String> = names(&out);
    left.sort();
    assert_eq!(left, ["beauty.png", "buffers.exr", "direction.png"]);
}

/// A file name is quoted as a scene's text is: a name holding ESC (which a
/// terminal would take for the start of a command) is shown with ␛.
#[test]
fn a_file_name_with_control_characters_is_shown_not_obeyed() {
    let dir = tempfile::tempdir().unwrap();
    let name = "\u{1b}[31mred\u{7}.toml";
    std::fs::write(dir.path().join(name), "[camera]\nposition = [0, 0, 1]\n").unwrap();
    for args in [&["check", name][..], &["render", name, "--out", "out"]] {
        let out = raystep(dir.path(), args);
        let said = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{said}");
        assert!(said.contains("\u{241b}[31mred\u{2407}.toml"), "{said:?}");
        assert!(!said.contains(['\u{1b}', '\u{7}']), "{said:?}");
    }
}

/// Send `signal` (`-INT`, `-KILL`) to a process.
fn send(signal: &str, pid: u32) {
    let status = Command::new("kill")
        .args([signal, &pid.to_string()])
        .status()
        .unwrap();
    assert!(status.success(), "kill {signal} {pid}");
}

/// Wait until `child` catches SIGINT and SIGTERM, as the `SigCgt` mask of
/// `/proc/PID/status` shows once raystep has set its handlers: a signal sent
/// earlier would meet the default action and end the process at once, which is
/// not what these tests ask about. (Sleeping a while instead guessed how long a
/// start takes on a busy machine.) Returns early if the process has ended.
fn wait_for_handlers(child: &mut std::process::Child) {
    // Bits 1 and 14: signals 2 (SIGINT) and 15 (SIGTERM), counted from 1.
    let wanted = (1u64 << 1) | (1u64 << 14);
    let status = format!("/proc/{}/status", child.id());
    let deadline = Instant::now() + Duration::from_secs(60);
    while child.try_wait().unwrap().is_none() {
        let text = std::fs::read_to_string(&status).unwrap_or_default();
        let caught = text
            .lines()
            .find_map(|line| line.strip_prefix("SigCgt:"))
            .and_then(|hex| u64::from_str_radix(hex.trim(), 16).ok());
        if caught.is_some_and(|mask| mask & wanted == wanted) {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "no handler for SIGINT and SIGTERM after 60 s: {text:?}"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Run `args` in `dir` and send `signal` `delay` after its handlers are set (if
/// it is still running); returns its exit code (None: ended by the signal).
fn interrupted(dir: &Path, args: &[&str], signal: &str, delay: Duration) -> Option<i32> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args(args)
        .current_dir(dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    wait_for_handlers(&mut child);
    std::thread::sleep(delay);
    if child.try_wait().unwrap().is_none() {
        send(signal, child.id());
    }
    child.wait().unwrap().code()
}

/// The files of folder `out` made by `args` in a fresh folder, and how long it took.
fn made_by(args: &[&str]) -> (BTreeMap<String, Vec<u8>>, Duration) {
    let dir = tempfile::tempdir().unwrap();
    let start = Instant::now();
    let run = raystep(dir.path(), args);
    let took = start.elapsed();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    (files(&dir.path().join("out")), took)
}

/// The old render, then the new one interrupted (SIGINT) at several moments from
/// its start to its end: each time the folder holds the old files exactly (exit
/// 130), or, if the signal came after the new files were in place, the new ones
/// exactly (exit 0). Never a mixture, never a temporary file.
fn interrupting(old: &[&str], new: &[&str]) {
    let (old_files, _) = made_by(old);
    let (new_files, took) = made_by(new);
    let mut outcomes = BTreeMap::new();
    // `took` is one run's time, and on a shared machine the next runs may take a
    // third of it; a signal as soon as the handlers are in (tenth 0) still
    // lands while the render runs.
    for tenth in [0, 1, 3, 5, 7, 9, 12] {
        let dir = tempfile::tempdir().unwrap();
        assert!(raystep(dir.path(), old).status.success());
        let delay = took * tenth / 10;
        let code = interrupted(dir.path(), new, "-INT", delay);
        let now = files(&dir.path().join("out"));
        match code {
            Some(130) => assert!(
                now == old_files,
                "interrupted at {delay:?}: not the old files"
            ),
            Some(0) => assert!(now == new_files, "done at {delay:?}: not the new files"),
            other => panic!("exit {other:?} after SIGINT at {delay:?}"),
        }
        *outcomes.entry(code).or_insert(0) += 1;
    }
    // The early signals did interrupt (the test would prove nothing otherwise).
    assert!(
        outcomes.get(&Some(130)).is_some_and(|&n| n >= 2),
        "{outcomes:?}"
    );
}

#[test]
fn ctrl_c_during_a_render_leaves_the_previous_files_as_they_were() {
    interrupting(
        &[
            "render", "--stage", "shadow", "--width", "64", "--height", "48",
        ],
        &["render", "--width", "600", "--height", "400"],
    );
}

#[test]
fn ctrl_c_during_stages_leaves_every_stage_of_the_previous_run() {
    interrupting(
        &["stages", "--width", "64", "--height", "48"],
        &["stages", "--width", "200", "--height", "150"],
    );
}

#[test]
fn a_killed_render_leaves_whole_files_and_the_next_run_clears_its_temporaries() {
    let old: &[&str] = &[
        "render", "--stage", "shadow", "--width", "64", "--height", "48",
    ];
    let new: &[&str] = &["render", "--width", "600", "--height", "400"];
    let (old_files, _) = made_by(old);
    let (new_files, took) = made_by(new);
    let (mut left_temporaries, mut killed) = (0, 0);
    for tenth in [2, 5, 8, 9] {
        let dir = tempfile::tempdir().unwrap();
        assert!(raystep(dir.path(), old).status.success());
        let delay = took * tenth / 10;
        // No exit code: the kill landed before the render ended.
        killed += usize::from(interrupted(dir.path(), new, "-KILL", delay).is_none());
        let out = dir.path().join("out");
        // Every file is whole: the old one, or the new one.
        for (name, bytes) in files(&out) {
            let file = name.rsplit('/').next().unwrap();
            if file.starts_with('.') && file.ends_with(".raystep.tmp") {
                left_temporaries += 1;
                continue;
            }
            let whole =
                old_files.get(&name) == Some(&bytes) || new_files.get(&name) == Some(&bytes);
            assert!(
                whole,
                "killed at {delay:?}: {name} is neither the old nor the new file"
            );
        }
        // The next run into the folder removes what the killed one left, and what
        // a process long gone left (no process has a number this large).
        std::fs::write(out.join(".beauty.png.999999999.raystep.tmp"), "half").unwrap();
        assert!(raystep(dir.path(), old).status.success());
        assert_eq!(
            files(&out),
            old_files,
            "killed at {delay:?}, then run again"
        );
    }
    // Whether a kill landed while files were being written depends on the moment;
    // that at least one landed at all is what makes the test mean something (the
    // kill at two tenths of the time comes long before the end).
    assert!(killed > 0, "every render ended before its kill");
    eprintln!("{left_temporaries} temporary files were left by {killed} kills");
}

#[test]
fn counts_are_grouped_by_three_digits_as_the_help_writes_them() {
    let grouped = common::grouped;
    assert_eq!(
        [
            grouped(7),
            grouped(999),
            grouped(1000),
            grouped(100_000),
            grouped(1_000_000)
        ],
        ["7", "999", "1,000", "100,000", "1,000,000"]
    );
}

#[test]
fn help_states_every_limit_with_the_numbers_the_code_uses() {
    use raystep::io::scene_file::*;
    let help = raystep(Path::new("."), &["--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains(raystep::tools::args::LIMITS),
        "--help ends with the limits"
    );
    let (w, h) = (7680u64, 4320u64);
    assert_eq!(w * h, MAX_PIXELS);
    let gigabytes = format!("{:.1} GB", (MAX_PIXELS * PEAK_BYTES_PER_PIXEL) as f64 / 1e9);
    for stated in [
        format!("1 to {MAX_SIDE} pixels a side"),
        format!("{w} × {h} in all"),
        format!("about {PEAK_BYTES_PER_PIXEL} bytes of memory per pixel ({gigabytes} at the most)"),
        format!("1 to {MAX_DEPTH} segments"),
        format!("from 1 to {MAX_SPP}"),
        format!("at most {MAX_MAGNITUDE:e} in magnitude"),
        format!(
            "a radius at least {MIN_RADIUS:e} and\n                 {MIN_RADIUS_RATIO_F64:.1e} of the scene's size ({MIN_RADIUS_RATIO:e} with --precision f32)"
        ),
        format!("at most {} MiB", MAX_FILE_BYTES / (1024 * 1024)),
        format!(
            "fits in {gigabytes}: about {}\n                 bytes per sphere",
            raystep::tools::cli::SCALE_BYTES_PER_SPHERE
        ),
        format!(
            "at most {} spheres, listed up to {} and above",
            common::grouped(raystep::tools::generate::MAX_GENERATED),
            common::grouped(raystep::tools::generate::MAX_LISTED)
        ),
        format!(
            "spheres = N, at most {})",
            common::grouped(raystep::tools::generate::MAX_GENERATED)
        ),
    ] {
        assert!(
            raystep::tools::args::LIMITS.contains(&stated),
            "{stated:?} in the limits"
        );
    }
}

#[test]
fn chapter_1_quotes_the_message_raystep_gives() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let quoted = common::transcript(
        "01-scene.md",
        "raystep check tests/hostile/scenes/unknown-radus.toml",
    );
    let out = raystep(root, &["check", "tests/hostile/scenes/unknown-radus.toml"]);
    assert_eq!(quoted, String::from_utf8_lossy(&out.stderr));
}

#[test]
fn a_plane_normal_of_any_length_becomes_a_unit_vector() {
    // The squared length of the first is subnormal, of the second zero: both were
    // normalised badly (to length 1.011) or refused.
    for (name, expected) in [
        (
            "plane-subnormal-normal.toml",
            [0.09950371902099892, 0.9950371902099893, 0.0],
        ),
        ("plane-underflowing-normal.toml", [0.0, 1.0, 0.0]),
    ] {
        let path = corpus().join("scenes").join(name);
        let scene = raystep::io::scene_file::load(&path).unwrap();
        let raystep::scene::Shape::Plane(plane) = scene.objects.last().unwrap().shape else {
            panic!("{name}: the last object is the plane");
        };
        assert!(
            (plane.normal.length() - 1.0).abs() <= 1e-15,
            "{name}: {:?}",
            plane.normal
        );
        assert_eq!(plane.normal.to_array(), expected, "{name}");
    }
}

#[test]
fn output_that_cannot_be_written_is_an_error_and_a_closed_pipe_is_not() {
    use std::io::Read;
    use std::process::Stdio;
    let full = Path::new("/dev/full");
    let found = match full.exists() {
        true => Ok(()),
        false => Err("/dev/full".to_string()),
    };
    if common::required(found, "the full-device cases").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ok.toml"), OK_SCENE).unwrap();
    for args in [
        &["generate", "spheres", "--count", "100"][..],
        &["--help"],
        &["--version"],
        &["render", "--help"],
        &["check", "ok.toml"],
        &["explain", "ok.toml", "--pixel", "1,1", "--json"],
        &["explain", "ok.toml", "--pixel", "1,1"],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_raystep"))
            .args(args)
            .current_dir(dir.path())
            .stdout(std::fs::File::create(full).unwrap())
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?} into a full device: {said}"
        );
        assert!(
            said.contains("cannot write standard output: No space left on device"),
            "{args:?}: {said}"
        );
        // The render's report could not be given: its files are not committed.
        assert_eq!(
            names(dir.path()),
            vec!["ok.toml".to_string()],
            "{args:?} wrote"
        );
    }
    // render says nothing on stdout without --json: a full stdout is no trouble. With
    // --json, the report lost is an error (exit 2), though the files are written.
    for (json, code) in [(false, 0), (true, 2)] {
        let mut args = vec!["render", "ok.toml", "--width", "20", "--height", "10"];
        if json {
            args.push("--json");
        }
        let out = Command::new(env!("CARGO_BIN_EXE_raystep"))
            .args(&args)
            .current_dir(dir.path())
            .stdout(std::fs::File::create(full).unwrap())
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {said}");
        assert_eq!(
            json,
            said.contains("cannot write standard output: No space left on device"),
            "{args:?}: {said}"
        );
    }
    // A reader that stops early (`| head -1`) is no error: exit 0, nothing said.
    let mut child = Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args(["generate", "spheres", "--count", "100000"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 64];
    child.stdout.take().unwrap().read_exact(&mut first).unwrap();
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "a closed pipe");
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn threads_that_cannot_start_are_a_message_not_a_panic() {
    // No thread's stack fits in 400 MB of address space: with RUST_MIN_STACK at
    // 1 GB, the pool's first thread cannot start, and the pool says so. (With
    // 2 MB stacks the address space would run out some hundred threads in, and
    // then, now and then, inside a thread that had just started: std aborts the
    // process when a new thread cannot map its signal stack, which no program
    // can catch. That made this test fail now and then on a busy machine: one
    // CI run of several on 2026-12-06.)
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ok.toml"), OK_SCENE).unwrap();
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 400000 && exec '{}' render ok.toml --width 20 --height 10 --out out",
            env!("CARGO_BIN_EXE_raystep")
        ))
        .env("RAYON_NUM_THREADS", "1000")
        .env("RUST_MIN_STACK", "1000000000")
        .current_dir(dir.path())
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{said}");
    assert!(
        said.contains("cannot start the threads to render with (RAYON_NUM_THREADS=1000)"),
        "{said}"
    );
    assert!(!said.contains("panicked"), "{said}");
    assert_eq!(names(dir.path()), vec!["ok.toml".to_string()]);
    // With the memory to spare, the same 200 threads render.
    let out = Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args([
            "render", "ok.toml", "--width", "20", "--height", "10", "--out", "out",
        ])
        .env("RAYON_NUM_THREADS", "200")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A FIFO at `path`: a file that a reader waits on until someone writes it.
fn make_fifo(path: &Path) {
    let made = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(made.success(), "mkfifo {}", path.display());
}

#[test]
fn a_command_that_hangs_fails_its_test_instead_of_stalling_the_suite() {
    // Every test runs raystep through `common::raystep`, which kills a command
    // that outlives its limit and fails: here `check` of a FIFO nobody writes.
    let dir = tempfile::tempdir().unwrap();
    make_fifo(&dir.path().join("fifo.toml"));
    let started = Instant::now();
    let hung = std::panic::catch_unwind(|| {
        common::raystep_within(dir.path(), &["check", "fifo.toml"], Duration::from_secs(1))
    });
    let message = *hung
        .expect_err("a hang passed")
        .downcast::<String>()
        .unwrap();
    assert!(message.contains("still ran after 1s: killed"), "{message}");
    assert!(started.elapsed() < Duration::from_secs(10));
    // Within its limit the same command ends as `Command::output` would.
    std::fs::write(dir.path().join("ok.toml"), OK_SCENE).unwrap();
    let out = common::raystep(dir.path(), &["check", "ok.toml"]);
    assert!(out.status.success() && !out.stdout.is_empty());
}

#[test]
fn one_signal_ends_any_command_within_a_second_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ok.toml"), OK_SCENE).unwrap();
    make_fifo(&dir.path().join("fifo.toml"));
    let before = names(dir.path());
    // Reading a FIFO that nobody writes, a benchmark of many runs, a chart: work
    // that does not stop between rows (a chart's renders do, between its other
    // work), ended by the watchdog.
    for (args, signal) in [
        (&["check", "fifo.toml"][..], "-INT"),
        (&["render", "fifo.toml", "--out", "out"], "-TERM"),
        (&["diff", "fifo.toml", "fifo.toml"], "-INT"),
        (
            &[
                "bench", "--runs", "1000", "--width", "320", "--height", "180",
            ],
            "-TERM",
        ),
        (
            &[
                "chart", "--runs", "1000", "--width", "96", "--height", "54", "--out", "out/c",
            ],
            "-INT",
        ),
    ] {
        let said = tempfile::NamedTempFile::new().unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_raystep"))
            .args(args)
            .current_dir(dir.path())
            .stdout(std::process::Stdio::null())
            .stderr(said.reopen().unwrap())
            .spawn()
            .unwrap();
        // Its handlers set, then a moment to be at its work (any moment would
        // do: none of these commands looks at the flag).
        wait_for_handlers(&mut child);
        std::thread::sleep(Duration::from_millis(100));
        assert!(
            child.try_wait().unwrap().is_none(),
            "{args:?} ended by itself"
        );
        send(signal, child.id());
        let sent = Instant::now();
        let code = loop {
            if let Some(status) = child.try_wait().unwrap() {
                break status.code();
            }
            assert!(
                sent.elapsed() < Duration::from_secs(3),
                "{args:?} still runs 3 s after {signal}"
            );
            std::thread::sleep(Duration::from_millis(20));
        };
        assert_eq!(code, Some(130), "{args:?} after {signal}");
        let stderr = std::fs::read_to_string(said.path()).unwrap();
        // The watchdog's words, or the command's own if it stopped first (a
        // chart's renders stop between rows).
        let last = stderr.lines().last().unwrap_or_default();
        assert!(
            last == format!("error: {}", raystep::interrupt::WATCHDOG_MESSAGE)
                || last == format!("error: {}", raystep::error::Error::Interrupted),
            "{args:?} said {stderr:?}"
        );
        assert!(
            sent.elapsed() < Duration::from_millis(1500),
            "{args:?}: {:?}",
            sent.elapsed()
        );
        assert_eq!(names(dir.path()), before, "{args:?} left files");
    }
}

#[test]
fn links_planted_at_temporary_names_are_never_written_through() {
    use std::os::unix::fs::symlink;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ok.toml"), OK_SCENE).unwrap();
    let victim = dir.path().join("victim.txt");
    std::fs::write(&victim, "the user's file").unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    // Links at every name the old, predictable scheme would have used, for the
    // next few process ids, and at a dead process's name (which raystep removes
    // as abandoned: the link, not its target).
    let me = std::process::id();
    for pid in (me..me + 200).chain([4_000_000]) {
        for name in ["beauty.png", "buffers.exr", "depth.png", "probe"] {
            let _ = symlink(&victim, out.join(format!(".{name}.{pid}.raystep.tmp")));
        }
    }
    let run = raystep(
        dir.path(),
        &[
            "render", "ok.toml", "--width", "20", "--height", "10", "--out", "out",
        ],
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "the user's file");
    assert!(out.join("beauty.png").is_file());
    // No temporary of raystep's own (`.NAME.PID.NONCE.raystep.tmp`, a nonce of 16
    // hexadecimal digits) is left.
    let own: Vec<String> = names(&out)
        .into_iter()
        .filter(|n| {
            let stem = n.strip_suffix(".raystep.tmp").unwrap_or("");
            stem.rsplit_once('.').is_some_and(|(_, nonce)| {
                nonce.len() == 16 && u64::from_str_radix(nonce, 16).is_ok()
            })
        })
        .collect();
    assert!(own.is_empty(), "{own:?}");
}

/// Every file under `dir` (links as links) with its bytes, to see that nothing
/// changed.
fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut all = BTreeMap::new();
    for name in walk(dir) {
        let path = dir.join(&name);
        let name = name.display().to_string();
        let meta = std::fs::symlink_metadata(&path).unwrap();
        let bytes = if meta.file_type().is_symlink() {
            format!("-> {}", std::fs::read_link(&path).unwrap().display()).into_bytes()
        } else {
            std::fs::read(&path).unwrap_or_default()
        };
        all.insert(name, bytes);
    }
    all
}

#[test]
fn symbolic_links_are_never_written_or_deleted_through() {
    use std::os::unix::fs::symlink;
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    std::fs::write(root.join("ok.toml"), OK_SCENE).unwrap();
    let elsewhere = root.join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();
    std::fs::write(elsewhere.join("beauty.png"), "the user's picture").unwrap();
    std::fs::write(elsewhere.join("depth.png"), "the user's depth").unwrap();
    std::fs::write(root.join("victim.txt"), "the user's file").unwrap();
    // A stage folder that is a link to a folder outside: refused, before rendering.
    let out = root.join("out");
    std::fs::create_dir(&out).unwrap();
    symlink("../elsewhere", out.join("03-shadow")).unwrap();
    let before = snapshot(root);
    let run = raystep(
        root,
        &[
            "stages", "ok.toml", "--width", "20", "--height", "10", "--out", "out",
        ],
    );
    let said = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{said}");
    assert!(said.contains("03-shadow: it is a symbolic link"), "{said}");
    assert_eq!(snapshot(root), before, "a refused run changed something");
    // Links at raystep's own file names: the link itself is replaced (a written
    // buffer) or removed (a stale one: a buffer the earlier render's buffers.exr
    // lists), never the file it points to.
    let render = root.join("render");
    let earlier = raystep(
        root,
        &[
            "render", "ok.toml", "--width", "20", "--height", "10", "--out", "render",
        ],
    );
    assert!(earlier.status.success());
    std::fs::remove_file(render.join("beauty.png")).unwrap();
    std::fs::remove_file(render.join("depth.png")).unwrap();
    symlink("../victim.txt", render.join("beauty.png")).unwrap();
    symlink("../elsewhere/depth.png", render.join("depth.png")).unwrap();
    let run = raystep(
        root,
        &[
            "render", "ok.toml", "--stage", "rays", "--width", "20", "--height", "10", "--out",
            "render",
        ],
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(root.join("victim.txt")).unwrap(),
        "the user's file"
    );
    assert_eq!(
        std::fs::read_to_string(elsewhere.join("depth.png")).unwrap(),
        "the user's depth"
    );
    let beauty = std::fs::symlink_metadata(render.join("beauty.png")).unwrap();
    assert!(
        beauty.is_file(),
        "beauty.png is raystep's file now, not the link"
    );
    assert!(!render.join("depth.png").exists(), "the stale link is gone");
}

#[test]
fn a_commit_puts_every_file_in_place_or_none() {
    // A folder at one of the final names: refused before a single rename.
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    std::fs::write(root.join("ok.toml"), OK_SCENE).unwrap();
    let run = raystep(
        root,
        &[
            "render", "ok.toml", "--width", "20", "--height", "10", "--out", "out",
        ],
    );
    assert!(run.status.success());
    std::fs::remove_file(root.join("out/depth.png")).unwrap();
    std::fs::create_dir(root.join("out/depth.png")).unwrap();
    std::fs::write(root.join("out/depth.png/mine.txt"), "the user's").unwrap();
    let before = snapshot(root);
    let run = raystep(
        root,
        &[
            "render",
            "ok.toml",
            "--width",
            "20",
            "--height",
            "10",
            "--max-depth",
            "1",
            "--out",
            "out",
        ],
    );
    let said = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{said}");
    assert!(
        said.contains("depth.png: a folder stands at this name"),
        "{said}"
    );
    assert_eq!(
        snapshot(root),
        before,
        "the folder holds exactly the old files"
    );

    // A rename that fails half way (here: a temporary removed from under the
    // commit) is undone: the files renamed before it are the old ones again.
    use raystep::io::output::Pending;
    let out = root.join("mixed");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("a.txt"), "old a").unwrap();
    std::fs::write(out.join("stale.txt"), "old stale").unwrap();
    let mut pending = Pending::new();
    pending.folder(&out).unwrap();
    pending.file(&out.join("a.txt"), b"new a").unwrap();
    pending.file(&out.join("b.txt"), b"new b").unwrap();
    pending.remove_on_commit(&out.join("stale.txt"));
    for entry in std::fs::read_dir(&out).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if name.starts_with(".b.txt.") {
            std::fs::remove_file(out.join(name)).unwrap();
        }
    }
    let error = pending.commit().unwrap_err().to_string();
    assert!(
        error.contains("b.txt") && error.contains("nothing was changed"),
        "{error}"
    );
    assert_eq!(
        names(&out),
        vec!["a.txt".to_string(), "stale.txt".to_string()],
        "no temporary and no new file left"
    );
    assert_eq!(std::fs::read_to_string(out.join("a.txt")).unwrap(), "old a");
    assert_eq!(
        std::fs::read_to_string(out.join("stale.txt")).unwrap(),
        "old stale"
    );
}

#[test]
fn temporaries_are_removed_even_from_a_folder_moved_during_the_render() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    let mut child = Command::new(env!("CARGO_BIN_EXE_raystep"))
        .args([
            "stages", "--width", "960", "--height", "540", "--out", "out",
        ])
        .current_dir(root)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Move the folder away once the first stage is done (its status line says
    // so) and five are still to render, however fast the machine: the files of
    // every stage are put in place only at the end.
    let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut said = String::new();
    while !said.contains("out/01-rays/") {
        let read = std::io::BufRead::read_line(&mut stderr, &mut said).unwrap();
        assert!(read > 0, "no status line for the first stage: {said}");
    }
    std::fs::rename(root.join("out"), root.join("moved")).unwrap();
    std::io::Read::read_to_string(&mut stderr, &mut said).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(2), "{said}");
    // Which error depends on when the move lands: a stage's file that cannot be
    // made under the old path, or the check before anything is put in place.
    // Either way it is a write under `out/`, refused, with its reason.
    let error = said
        .lines()
        .find(|line| line.starts_with("error: "))
        .unwrap_or_else(|| panic!("no error line: {said}"));
    assert!(
        error.starts_with("error: cannot write out")
            && (error.contains("was moved or replaced while raystep rendered into it")
                || error.ends_with("No such file or directory (os error 2)")),
        "{said}"
    );
    // Nothing was put in place, at the old path or in the moved folder, and no
    // temporary is left in the moved one.
    assert!(!root.join("out").exists(), "something at the old path");
    let moved = root.join("moved");
    let files: Vec<PathBuf> = walk(&moved)
        .into_iter()
        .filter(|n| !moved.join(n).is_dir())
        .collect();
    assert!(
        files.is_empty(),
        "files left in the moved folder: {files:?}"
    );
}
