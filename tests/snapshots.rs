//! Every stage of the figure-1 scene, every buffer it writes, locked as PNG
//! snapshots (100 × 70). Each snapshot image was looked at before it was accepted;
//! a change to any pixel of any buffer fails here, and under `CI=true` insta does
//! not write new snapshots, it fails.

mod common;

use raystep::io::output::{exr_bytes, png_bytes};
use raystep::stages::{Stage, Stages};

#[test]
fn every_stage_and_buffer_of_the_seed_scene() {
    let scene = common::seed(100, 70);
    for stage in Stage::ALL {
        let frame = common::render(&scene, Stages::up_to(stage));
        for buffer in frame.buffers() {
            let name = format!("seed-{}-{}.png", stage.folder(), buffer.name());
            insta::assert_binary_snapshot!(name.as_str(), png_bytes(&frame, buffer));
        }
    }
}

/// The raw floats too, not only their 8-bit pictures: the EXR of the last stage
/// holds every buffer (a depth scaled by a constant would not change depth.png).
#[test]
fn the_float_buffers_of_the_seed_scene() {
    let frame = common::render(&common::seed(100, 70), Stages::ALL);
    insta::assert_binary_snapshot!("seed-06-plane-buffers.exr", exr_bytes(&frame).unwrap());
}

/// The small scenes, each at the stage it was made to show.
#[test]
fn each_small_scene_at_its_stage() {
    let cases = [
        ("shadow", Stage::Shadow),
        ("highlights", Stage::BlinnPhong),
        ("mirrors", Stage::Reflection),
        ("true-plane", Stage::Plane),
    ];
    for (name, stage) in cases {
        let path = format!("{}/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        let mut scene = raystep::io::scene_file::load(path.as_ref()).unwrap();
        scene.width = 100;
        scene.height = 70;
        let frame = common::render(&scene, Stages::up_to(stage));
        for buffer in frame.buffers().filter(|b| b.name() != "direction") {
            let file = format!("{name}-{}-{}.png", stage.folder(), buffer.name());
            insta::assert_binary_snapshot!(file.as_str(), png_bytes(&frame, buffer));
        }
    }
}
