//! `--png srgb|linear`: the sRGB transfer function of IEC 61966-2-1, and what
//! `raystep render --png srgb` writes against the linear EXR of the same render.

use std::path::Path;

mod common;
use common::raystep;
use raystep::io::output::srgb_encode;

/// A value in [0, 1] to 8 bits, rounded to the nearest level.
fn byte(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[test]
fn the_srgb_transfer_function_gives_the_known_answers() {
    assert_eq!(srgb_encode(0.0), 0.0);
    assert_eq!(byte(srgb_encode(0.0)), 0);
    assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
    assert_eq!(byte(srgb_encode(1.0)), 255);
    // 0.5 is 0.735 357 encoded: 187.52, level 188 (128 when written linear).
    assert!(
        (srgb_encode(0.5) - 0.735_357).abs() < 1e-5,
        "{}",
        srgb_encode(0.5)
    );
    assert_eq!(byte(srgb_encode(0.5)), 188);
    assert_eq!(byte(0.5), 128);
    // At the boundary 0.003 130 8 the straight line gives 12.92 × 0.003 130 8 =
    // 0.040 450; the power law just above it agrees to 3e-5 (the standard's
    // constants are rounded), and both are level 10.
    let at = srgb_encode(0.003_130_8);
    assert!((at - 0.040_449_936).abs() < 1e-7, "{at}");
    let above = srgb_encode(0.003_130_9);
    assert!(above > at && (above - at).abs() < 3e-5, "{at} {above}");
    assert_eq!(byte(at), 10);
    assert_eq!(byte(above), 10);
    // Below the boundary it is the straight line, and it rises everywhere.
    assert!((srgb_encode(0.001) - 0.01292).abs() < 1e-8);
    let mut last = -1.0;
    for k in 0..=1000 {
        let v = srgb_encode(k as f32 / 1000.0);
        assert!(v > last, "{k}");
        last = v;
    }
}

use common::png_chunks as chunks;

fn rgb(path: &Path) -> Vec<u8> {
    image::open(path).unwrap().to_rgb8().into_raw()
}

#[test]
fn png_srgb_writes_a_brighter_beauty_png_that_is_the_transfer_of_the_exr() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let out = raystep(dir.path(), args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let small = ["--width", "60", "--height", "40", "--stage", "plane"];
    run(&[&["render", "--out", "linear"][..], &small].concat());
    run(&[
        &["render", "--png", "linear", "--out", "default"][..],
        &small,
    ]
    .concat());
    run(&[&["render", "--png", "srgb", "--out", "srgb"][..], &small].concat());
    let (linear, srgb) = (dir.path().join("linear"), dir.path().join("srgb"));

    // Linear is the default, and its PNGs carry no colour chunk, as before.
    let linear_png = std::fs::read(linear.join("beauty.png")).unwrap();
    assert_eq!(
        linear_png,
        std::fs::read(dir.path().join("default/beauty.png")).unwrap()
    );
    assert_eq!(chunks(&linear_png), ["IHDR", "IDAT", "IEND"]);
    let srgb_png = std::fs::read(srgb.join("beauty.png")).unwrap();
    assert_eq!(chunks(&srgb_png), ["IHDR", "sRGB", "IDAT", "IEND"]);

    // The EXR is linear either way: the same bytes.
    let exr = std::fs::read(srgb.join("buffers.exr")).unwrap();
    assert_eq!(exr, std::fs::read(linear.join("buffers.exr")).unwrap());

    // Every byte of the sRGB picture is the transfer of the EXR's value.
    let image = exr::prelude::read_all_flat_layers_from_file(srgb.join("buffers.exr")).unwrap();
    let layer = &image.layer_data[0];
    let channel = |name: &str| {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name);
        c.unwrap_or_else(|| panic!("no channel {name}"))
    };
    let (r, g, b) = (channel("R"), channel("G"), channel("B"));
    let (linear_rgb, srgb_rgb) = (
        rgb(&linear.join("beauty.png")),
        rgb(&srgb.join("beauty.png")),
    );
    assert_eq!(srgb_rgb.len(), 60 * 40 * 3);
    let (mut brighter, mut darker) = (0, 0);
    for i in 0..60 * 40 {
        for (c, channel) in [r, g, b].into_iter().enumerate() {
            let value = channel.sample_data.value_by_flat_index(i).to_f32();
            let (l, s) = (linear_rgb[i * 3 + c], srgb_rgb[i * 3 + c]);
            assert_eq!(
                s,
                byte(srgb_encode(value)),
                "pixel {i} channel {c}: {value}"
            );
            assert_eq!(l, byte(value), "pixel {i} channel {c}: {value}");
            brighter += usize::from(s > l);
            darker += usize::from(s < l);
        }
    }
    assert_eq!(darker, 0);
    assert!(brighter > 60 * 40, "{brighter} channels brighter");

    // The pictures that hold no light are the same; the terms are encoded too.
    for name in [
        "depth",
        "normal",
        "shadow",
        "object",
        "bounces",
        "rays",
        "direction",
        "position",
    ] {
        let file = format!("{name}.png");
        assert_eq!(
            std::fs::read(linear.join(&file)).unwrap(),
            std::fs::read(srgb.join(&file)).unwrap(),
            "{file}"
        );
    }
    // The terms go through the curve as the beauty does: it lies above the
    // identity on (0, 1), so no byte is darker and the lit values come out
    // brighter.
    for name in ["ambient", "diffuse", "specular"] {
        let file = format!("{name}.png");
        let bytes = std::fs::read(srgb.join(&file)).unwrap();
        assert!(chunks(&bytes).contains(&"sRGB".to_string()), "{file}");
        let (l, s) = (rgb(&linear.join(&file)), rgb(&srgb.join(&file)));
        assert!(l.iter().zip(&s).all(|(l, s)| s >= l), "{file}");
        let brighter = l.iter().zip(&s).filter(|(l, s)| s > l).count();
        assert!(brighter > 100, "{file}: {brighter} channels brighter");
    }
}
