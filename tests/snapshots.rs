//! Every stage of the figure-1 scene, every buffer it writes, locked as PNG
//! snapshots (100 × 70). Each snapshot image was looked at before it was accepted;
//! a change to any pixel of any buffer fails here, and under `CI=true` insta does
//! not write new snapshots, it fails.

mod common;

use raystep::io::output::{exr_bytes, png_bytes};
use raystep::stages::{Stage, Stages};

/// Every stage of the seed scene, every buffer: (snapshot name, PNG bytes).
fn seed_stages() -> Vec<(String, Vec<u8>)> {
    let scene = common::seed(100, 70);
    let mut files = Vec::new();
    for stage in Stage::ALL {
        let frame = common::render(&scene, Stages::up_to(stage));
        for buffer in frame.buffers() {
            let name = format!("seed-{}-{}.png", stage.folder(), buffer.name());
            files.push((name, png_bytes(&frame, buffer)));
        }
    }
    files
}

/// The small scenes, each at the stage it was made to show: (snapshot name,
/// PNG bytes).
fn small_scenes() -> Vec<(String, Vec<u8>)> {
    let cases = [
        ("shadow", Stage::Shadow),
        ("highlights", Stage::BlinnPhong),
        ("mirrors", Stage::Reflection),
        ("true-plane", Stage::Plane),
    ];
    let mut files = Vec::new();
    for (name, stage) in cases {
        let path = format!("{}/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        let mut scene = raystep::io::scene_file::load(path.as_ref()).unwrap();
        scene.width = 100;
        scene.height = 70;
        let frame = common::render(&scene, Stages::up_to(stage));
        for buffer in frame.buffers().filter(|b| b.name() != "direction") {
            let file = format!("{name}-{}-{}.png", stage.folder(), buffer.name());
            files.push((file, png_bytes(&frame, buffer)));
        }
    }
    files
}

/// The EXR snapshot's name.
const FLOATS: &str = "seed-06-plane-buffers.exr";

#[test]
fn every_stage_and_buffer_of_the_seed_scene() {
    for (name, bytes) in seed_stages() {
        insta::assert_binary_snapshot!(name.as_str(), bytes);
    }
}

/// The raw floats too, not only their 8-bit pictures: the EXR of the last stage
/// holds every buffer (a depth scaled by a constant would not change depth.png).
#[test]
fn the_float_buffers_of_the_seed_scene() {
    let frame = common::render(&common::seed(100, 70), Stages::ALL);
    insta::assert_binary_snapshot!(FLOATS, exr_bytes(&frame).unwrap());
}

/// The small scenes, each at the stage it was made to show.
#[test]
fn each_small_scene_at_its_stage() {
    for (name, bytes) in small_scenes() {
        insta::assert_binary_snapshot!(name.as_str(), bytes);
    }
}

/// insta fails on a snapshot that differs, not on one no test asks for: a
/// buffer dropped from a stage would leave its snapshot behind and pass. So the
/// snapshots this file's tests make are exactly the files that hold them.
#[test]
fn every_snapshot_file_of_this_file_is_one_a_test_makes() {
    use std::collections::BTreeSet;
    let mut made: BTreeSet<String> = seed_stages()
        .into_iter()
        .chain(small_scenes())
        .map(|(name, _)| name)
        .collect();
    made.insert(FLOATS.to_string());
    // insta's files: `snapshots__NAME.snap`, the NAME's extension dropped, and
    // the bytes beside it in `snapshots__NAME.snap.EXTENSION`.
    let made: BTreeSet<String> = made
        .iter()
        .flat_map(|name| {
            let (stem, extension) = name.rsplit_once('.').unwrap();
            [
                format!("snapshots__{stem}.snap"),
                format!("snapshots__{stem}.snap.{extension}"),
            ]
        })
        .collect();
    let folder = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/snapshots");
    let on_disk: BTreeSet<String> = std::fs::read_dir(folder)
        .unwrap()
        .map(|entry| entry.unwrap().file_name().into_string().unwrap())
        .filter(|name| name.starts_with("snapshots__") && !name.ends_with(".new"))
        .collect();
    assert_eq!(
        on_disk.difference(&made).collect::<Vec<_>>(),
        Vec::<&String>::new(),
        "snapshot files no test makes"
    );
    assert_eq!(
        made.difference(&on_disk).collect::<Vec<_>>(),
        Vec::<&String>::new(),
        "snapshots with no file"
    );
}
