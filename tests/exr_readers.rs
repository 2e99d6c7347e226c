//! `buffers.exr` as the tools of the field read it: OpenImageIO (its Python
//! module, and `oiiotool` running chapter 11's command) lists every channel and
//! gives each sample of a few known pixels; Blender's multilayer reader offers
//! every buffer as a pass of an Image node. Each compression reads back the
//! same samples.
//!
//! Needs Debian's `python3-openimageio`, `openimageio-tools` and `blender`
//! (`.ci/run` installs them). Without them the tests are skipped with a
//! message, or fail under CI (where `CI` is set).

mod common;

use std::path::{Path, PathBuf};

use exr::prelude::{ReadChannels, ReadLayers};
use std::process::Command;

use raystep::aov::Frame;
use raystep::io::output::{exr_bytes_as, exr_samples, ExrCompression, EXR_CHANNELS};
use raystep::stages::Stages;

/// The figure-1 scene, every stage on, small.
fn frame() -> Frame {
    common::render(&common::seed(60, 40), Stages::ALL)
}

/// Pixels to read back: the sky (a miss), the red sphere, the floor in shadow,
/// the floor lit.
fn known_pixels(frame: &Frame) -> Vec<(u32, u32)> {
    let find = |want: &dyn Fn(&raystep::aov::PixelRecord) -> bool| {
        let k = frame.pixels.iter().position(want).expect("such a pixel");
        (
            (k % frame.width as usize) as u32,
            (k / frame.width as usize) as u32,
        )
    };
    vec![
        (0, 0),
        find(&|p| p.is_hit() && p.object == 0 && p.shadow == 1.0),
        find(&|p| p.is_hit() && p.shadow == 0.0),
        find(&|p| p.is_hit() && p.object == 3 && p.shadow == 1.0),
    ]
}

/// The Python with OpenImageIO's module: Debian's (`/usr/bin/python3`, whatever
/// `python3` the PATH finds first) or the one on the PATH.
fn python_with_openimageio() -> Result<PathBuf, String> {
    for python in ["/usr/bin/python3", "python3"] {
        let ok = Command::new(python)
            .args(["-c", "import OpenImageIO"])
            .output()
            .is_ok_and(|o| o.status.success());
        if ok {
            return Ok(PathBuf::from(python));
        }
    }
    Err("Python's OpenImageIO module (apt-get install python3-openimageio)".into())
}

fn tool(name: &str, package: &str) -> Result<PathBuf, String> {
    let found = Command::new(name)
        .arg("--help")
        .output()
        .is_ok_and(|o| o.status.success() || !o.stdout.is_empty());
    match found {
        true => Ok(PathBuf::from(name)),
        false => Err(format!("{name} (apt-get install {package})")),
    }
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Check `x y channel value` lines printed by a reader against the frame's
/// samples, bit for bit.
fn check_samples(frame: &Frame, printed: &str, pixels: &[(u32, u32)], file: &str) {
    let mut seen = 0;
    for line in printed.lines() {
        let words: Vec<&str> = line.split(' ').collect();
        let [x, y, name, value] = words[..] else {
            panic!("{file}: unexpected line {line:?}");
        };
        let (x, y): (u32, u32) = (x.parse().unwrap(), y.parse().unwrap());
        let k = EXR_CHANNELS.iter().position(|(n, _)| *n == name);
        let k = k.unwrap_or_else(|| panic!("{file}: a channel raystep does not write: {name}"));
        let value: f64 = value.parse().unwrap();
        let expected = exr_samples(frame, y, x)[k];
        assert_eq!(value as f32, expected, "{file}: {name} at ({x}, {y})");
        assert_eq!(value, f64::from(expected), "{file}: {name} at ({x}, {y})");
        seen += 1;
    }
    assert_eq!(seen, pixels.len() * EXR_CHANNELS.len(), "{file}: {printed}");
}

#[test]
fn openimageio_lists_every_channel_and_reads_known_pixels_in_each_compression() {
    let Some(python) = common::required(python_with_openimageio(), "reading buffers.exr") else {
        return;
    };
    let frame = frame();
    let pixels = known_pixels(&frame);
    let dir = tempfile::tempdir().unwrap();
    let script = "import sys, OpenImageIO as oiio\n\
        buf = oiio.ImageBuf(sys.argv[1])\n\
        if buf.has_error: sys.exit(buf.geterror())\n\
        names = buf.spec().channelnames\n\
        print(' '.join(names))\n\
        for xy in sys.argv[2:]:\n\
        \x20   x, y = map(int, xy.split(','))\n\
        \x20   for name, value in zip(names, buf.getpixel(x, y)):\n\
        \x20       print(x, y, name, repr(value))\n";
    let at: Vec<String> = pixels.iter().map(|(x, y)| format!("{x},{y}")).collect();
    for compression in [
        ExrCompression::None,
        ExrCompression::Rle,
        ExrCompression::Zips,
        ExrCompression::Zip,
        ExrCompression::Piz,
    ] {
        let name = format!("{compression:?}.exr");
        let path = write(
            dir.path(),
            &name,
            &exr_bytes_as(&frame, compression).unwrap(),
        );
        let out = Command::new(&python)
            .args(["-c", script])
            .arg(&path)
            .args(&at)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let (names, samples) = stdout.split_once('\n').unwrap();
        // Every channel, as OpenImageIO lists them (R, G, B first, then by name).
        assert_eq!(
            names,
            "R G B Z N.X N.Y N.Z P.X P.Y P.Z ambient.R ambient.G ambient.B bounces.X \
             diffuse.R diffuse.G diffuse.B dir.X dir.Y dir.Z object.X rays.X shadow.X \
             specular.R specular.G specular.B",
            "{name}"
        );
        check_samples(&frame, samples, &pixels, &name);
    }
}

/// The command chapter 11 gives for one pixel's numbers, as the chapter has it.
fn chapter_command() -> String {
    let chapter = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("chapters/11-debugging.md"),
    )
    .unwrap();
    let line = chapter
        .lines()
        .find(|l| l.starts_with("oiiotool --info --dumpdata"))
        .expect("chapter 11 gives an oiiotool command that prints a pixel");
    line.to_string()
}

#[test]
fn the_chapter_oiiotool_command_prints_every_channel_of_the_pixel() {
    let command = chapter_command();
    let Some(oiiotool) = common::required(
        tool("oiiotool", "openimageio-tools"),
        "chapter 11's command",
    ) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let stages = common::raystep(dir.path(), &["stages", "-q"]);
    assert!(stages.status.success(), "{:?}", stages);
    let out = Command::new("sh")
        .args(["-c", &command])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let printed = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{command}: {out:?}");
    // `Pixel (74, 125): v v v …`, in the order `oiiotool --info -v` lists.
    let values: Vec<f64> = printed
        .trim()
        .strip_prefix("Pixel (74, 125):")
        .unwrap_or_else(|| panic!("{command} printed {printed:?}"))
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    let info = Command::new(&oiiotool)
        .args(["--info", "-v", "out/06-plane/buffers.exr"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let info = String::from_utf8_lossy(&info.stdout);
    let names: Vec<&str> = info
        .lines()
        .find_map(|l| l.trim().strip_prefix("channel list: "))
        .expect("the channel list")
        .split(", ")
        .collect();
    assert_eq!(values.len(), EXR_CHANNELS.len(), "{printed}");
    assert_eq!(names.len(), values.len(), "{info}");
    // The numbers `raystep explain --pixel 74,125` tells: depth 4.64808 and the
    // floor (object 3), in shadow, two rays.
    let scene = raystep::io::scene_file::seed();
    let frame = common::render(&scene, Stages::ALL);
    let samples = exr_samples(&frame, 125, 74);
    for (name, value) in names.iter().zip(&values) {
        let k = EXR_CHANNELS.iter().position(|(n, _)| n == name).unwrap();
        // Printed with 9 decimals.
        assert!(
            (value - f64::from(samples[k])).abs() <= 1e-9,
            "{name}: {value} for {}",
            samples[k]
        );
    }
    let z = names.iter().position(|n| *n == "Z").unwrap();
    assert!((values[z] - 4.64808).abs() < 1e-5, "{}", values[z]);
}

#[test]
fn blender_offers_every_buffer_as_a_pass() {
    let Some(blender) = common::required(tool("blender", "blender"), "Blender's reader") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let frame = frame();
    let exr = write(
        dir.path(),
        "buffers.exr",
        &exr_bytes_as(&frame, ExrCompression::None).unwrap(),
    );
    // The passes of a compositor Image node that shows the file.
    let script = write(
        dir.path(),
        "passes.py",
        b"import bpy, sys\n\
          image = bpy.data.images.load(sys.argv[sys.argv.index('--') + 1])\n\
          scene = bpy.context.scene\n\
          scene.use_nodes = True\n\
          node = scene.node_tree.nodes.new('CompositorNodeImage')\n\
          node.image = image\n\
          print('PASSES', ' '.join(o.name for o in node.outputs if o.enabled))\n",
    );
    let out = Command::new(blender)
        .args(["-b", "--factory-startup", "--python"])
        .arg(&script)
        .arg("--")
        .arg(&exr)
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{out:?}");
    assert!(!stdout.contains("unknown channel token"), "{stdout}");
    let passes = stdout
        .lines()
        .find_map(|l| l.strip_prefix("PASSES "))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert_eq!(
        passes,
        "Combined Alpha Depth N P ambient bounces diffuse dir object rays shadow specular"
    );
}

#[test]
fn every_compression_reads_back_the_samples_of_the_uncompressed_file() {
    let frame = frame();
    let read = |compression| {
        let bytes = exr_bytes_as(&frame, compression).unwrap();
        let image = exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(std::io::Cursor::new(bytes))
            .unwrap();
        let channels = image.layer_data.channel_data.list;
        let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
        let samples: Vec<Vec<u32>> = (channels.iter())
            .map(|c| c.sample_data.values_as_f32().map(f32::to_bits).collect())
            .collect();
        (names, samples)
    };
    let plain = read(ExrCompression::None);
    assert_eq!(plain.0.len(), EXR_CHANNELS.len());
    // The uncompressed file holds exactly the frame's samples.
    let (width, height) = (frame.width, frame.height);
    for (name, samples) in plain.0.iter().zip(&plain.1) {
        let k = EXR_CHANNELS.iter().position(|(n, _)| n == name).unwrap();
        for row in 0..height {
            for col in 0..width {
                let at = (row * width + col) as usize;
                assert_eq!(
                    samples[at],
                    exr_samples(&frame, row, col)[k].to_bits(),
                    "{name} at ({col}, {row})"
                );
            }
        }
    }
    for compression in [
        ExrCompression::Rle,
        ExrCompression::Zips,
        ExrCompression::Zip,
        ExrCompression::Piz,
    ] {
        assert!(read(compression) == plain, "{compression:?}");
    }
}
