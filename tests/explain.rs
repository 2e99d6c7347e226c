//! `raystep explain`: its story ends where the render did, for every pixel, and a
//! few telling pixels of the figure-1 scene are locked as text snapshots (each read
//! through before it was accepted).

mod common;

use raystep::aov::{Frame, PixelRecord, NO_OBJECT};
use raystep::real::Precision;
use raystep::render::{render, Settings};
use raystep::scene::Scene;
use raystep::stages::{Stage, Stages};
use raystep::tools::explain::{explain, Explanation};

/// Check that the story of every pixel gives the numbers the render stored.
fn agrees_everywhere(scene: &Scene, settings: &Settings) {
    let frame: Frame = render(scene, settings, &|_| {});
    for y in 0..scene.height {
        for x in 0..scene.width {
            let story = explain(scene, settings, x, y);
            let record = frame.at(y, x);
            check(&story, record, settings);
            // The position buffer, which the record does not hold.
            let position = story.position.map(|p| p.map(|c| c as f32));
            let expected = record.is_hit().then(|| frame.position(y, x));
            let at = format!("pixel {x},{y} under {settings:?}");
            if settings.stages.intersection {
                assert_eq!(position, expected, "{at}");
            }
        }
    }
}

fn check(story: &Explanation, record: &PixelRecord, settings: &Settings) {
    let at = format!("pixel {},{} under {settings:?}", story.x, story.y);
    let f32s = |v: [f64; 3]| v.map(|c| c as f32);
    match &story.samples {
        None => {
            assert_eq!(f32s(story.colour), record.colour, "{at}");
            assert_eq!(
                story.rays.iter().sum::<u64>(),
                u64::from(record.rays),
                "{at}"
            );
        }
        Some(samples) => {
            assert_eq!(f32s(samples.colour), record.colour, "{at}");
            assert_eq!(samples.rays, u64::from(record.rays), "{at}");
        }
    }
    if !settings.stages.intersection {
        return;
    }
    // The story's own numbers add up: each segment's light times its weight
    // makes the sum (computed in the render's precision, hence the tolerance),
    // and the sum clipped is the colour.
    let mut sum = [0.0f64; 3];
    for segment in &story.segments {
        if let Some(light) = segment.hit.as_ref().and_then(|h| h.illumination) {
            (0..3).for_each(|k| sum[k] += light[k] * segment.weight);
        }
    }
    for k in 0..3 {
        let unclipped = story.unclipped[k];
        assert!(
            (sum[k] - unclipped).abs() <= 1e-5 * (1.0 + unclipped.abs()),
            "{at}: the segments add up to {sum:?}, the story says {:?}",
            story.unclipped
        );
        assert_eq!(unclipped.clamp(0.0, 1.0), story.colour[k], "{at}");
    }
    assert_eq!(story.rays[2], u64::from(record.bounces), "{at}");
    assert_eq!(
        story.depth.map(|d| d as f32),
        record.is_hit().then_some(record.depth),
        "{at}"
    );
    let first = story.segments[0].hit.as_ref();
    match first {
        None => assert_eq!(record.object, NO_OBJECT, "{at}"),
        Some(hit) => {
            assert_eq!(hit.object as u32, record.object, "{at}");
            assert_eq!(f32s(hit.normal), record.normal, "{at}");
            assert_eq!(if hit.lit { 1.0 } else { 0.0 }, record.shadow, "{at}");
            let (diffuse, specular) = hit
                .shading
                .as_ref()
                .map_or((0.0, 0.0), |s| (s.l_dot_n as f32, s.highlight as f32));
            assert_eq!(
                (diffuse, specular),
                (record.diffuse, record.specular),
                "{at}"
            );
        }
    }
}

#[test]
fn the_story_of_every_pixel_ends_where_the_render_did() {
    let scene = common::seed(60, 40);
    for stage in Stage::ALL {
        agrees_everywhere(&scene, &Settings::from(Stages::up_to(stage)));
    }
    agrees_everywhere(&scene, &Settings::tutorial(Stages::ALL));
    agrees_everywhere(
        &scene,
        &Settings {
            precision: Precision::F32,
            ..Settings::from(Stages::ALL)
        },
    );
    agrees_everywhere(
        &scene,
        &Settings {
            spp: 4,
            ..Settings::from(Stages::ALL)
        },
    );
    let without_shadow = Stages::select(Stage::Plane, &[Stage::Shadow]).unwrap();
    agrees_everywhere(&scene, &Settings::from(without_shadow));
    for name in ["mirrors", "true-plane", "highlights"] {
        let path = format!("{}/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        let mut scene = raystep::io::scene_file::load(path.as_ref()).unwrap();
        (scene.width, scene.height) = (50, 35);
        agrees_everywhere(&scene, &Settings::from(Stages::ALL));
    }
}

/// The first pixel, in reading order, of the 300 × 200 figure-1 render whose
/// record satisfies `wanted`.
fn first_pixel(frame: &Frame, wanted: impl Fn(&PixelRecord) -> bool) -> (u32, u32) {
    let i = frame.pixels.iter().position(wanted).expect("such a pixel");
    (
        (i % frame.width as usize) as u32,
        (i / frame.width as usize) as u32,
    )
}

#[test]
fn telling_pixels_of_the_seed_scene() {
    let scene = common::seed(300, 200);
    let settings = Settings::from(Stages::ALL);
    let frame = render(&scene, &settings, &|_| {});
    let brightest_highlight = frame
        .pixels
        .iter()
        .filter(|p| p.object == 0)
        .map(|p| p.specular)
        .fold(0.0, f32::max);
    // The first pixel whose path runs through all max_depth segments, the last
    // one hitting something: the path ends because it may not go further.
    let deepest = frame
        .pixels
        .iter()
        .enumerate()
        .filter(|(_, p)| p.bounces + 1 == scene.max_depth)
        .map(|(i, _)| ((i % 300) as u32, (i / 300) as u32))
        .find(|&(x, y)| {
            let story = explain(&scene, &settings, x, y);
            story
                .segments
                .last()
                .unwrap()
                .hit
                .as_ref()
                .is_some_and(|h| h.lit)
        })
        .expect("a path to max_depth");
    let pixels = [
        ("sky", (0, 0)),
        (
            "red-sphere-highlight",
            first_pixel(&frame, |p| {
                p.object == 0 && p.specular == brightest_highlight
            }),
        ),
        (
            "floor-in-shadow",
            first_pixel(&frame, |p| p.object == 3 && p.shadow == 0.0),
        ),
        ("path-to-max-depth", deepest),
        // A sphere's own dark side: in shadow with the primary ray alone.
        (
            "sphere-dark-side",
            first_pixel(&frame, |p| p.object != 3 && p.shadow == 0.0 && p.rays == 1),
        ),
    ];
    for (name, (x, y)) in pixels {
        let story = explain(&scene, &settings, x, y);
        check(&story, frame.at(y, x), &settings);
        insta::assert_snapshot!(name, story.to_string());
    }
}

fn raystep(args: &[&str]) -> std::process::Output {
    common::raystep(std::path::Path::new("."), args)
}

#[test]
fn json_has_the_depth_or_null_and_the_cli_checks_the_pixel() {
    let json = |pixel: &str| {
        let out = raystep(&["explain", "--pixel", pixel, "--json"]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let sky = json("0,0");
    assert!(sky["depth"].is_null(), "{sky}");
    assert!(sky["position"].is_null(), "{sky}");
    let sphere = json("150,60");
    let depth = sphere["depth"].as_f64().unwrap();
    assert_eq!(sphere["segments"][0]["hit"]["t"].as_f64(), Some(depth));
    assert!((1.0..2.0).contains(&depth), "{depth}");
    // P is the hit's point, within float32's rounding.
    let point = &sphere["segments"][0]["hit"]["point"];
    for k in 0..3 {
        let (p, q) = (
            sphere["position"][k].as_f64().unwrap(),
            point[k].as_f64().unwrap(),
        );
        assert!((p - q).abs() <= 1e-6 * (1.0 + q.abs()), "{p} {q}");
    }

    for (pixel, message) in [
        ("300,10", "outside the 300 × 200 image"),
        ("10", "expected X,Y"),
        ("-1,3", "expected X,Y"),
        ("a,b", "expected X,Y"),
    ] {
        let out = raystep(&["explain", &format!("--pixel={pixel}")]);
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(message), "{pixel}: {stderr}");
    }
    // --stage works as for render: before the shadow stage no shadow ray is told.
    let out = raystep(&["explain", "--pixel", "150,60", "--stage", "intersection"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("shadow: stage off"), "{text}");
}

#[test]
fn explain_with_the_fast_engine_says_it_tells_the_book_tracers_story() {
    let book = raystep(&["explain", "--pixel", "150,60"]);
    let fast = raystep(&["explain", "--pixel", "150,60", "--engine", "fast"]);
    assert!(book.status.success() && fast.status.success());
    // The same story on stdout (the fast engine gives the book's bits) ...
    assert_eq!(book.stdout, fast.stdout);
    // ... and a note on stderr that it is the book's tracer that is told,
    // which -q silences as every status line.
    let note = "explain follows the book's tracer";
    assert!(!String::from_utf8_lossy(&book.stderr).contains(note));
    assert!(String::from_utf8_lossy(&fast.stderr).contains(note));
    let quiet = raystep(&["explain", "--pixel", "150,60", "--engine", "fast", "-q"]);
    assert!(quiet.status.success());
    assert_eq!(quiet.stdout, book.stdout);
    assert!(!String::from_utf8_lossy(&quiet.stderr).contains(note));
}

/// In a scene of more than `LISTED` objects the story lists the objects a ray
/// hits and counts the misses by their reason, so that every object is still
/// accounted for; a small scene's story lists every test.
#[test]
fn a_story_among_many_spheres_counts_the_misses() {
    use raystep::tools::explain::LISTED;
    let settings = Settings::from(Stages::ALL);
    let many = raystep::tools::generate::scene(200, 7);
    let small: Scene = common::seed(200, 140);
    for (scene, pixels) in [
        (&many, [(40, 60), (10, 10), (80, 50)]),
        (&small, [(74, 125), (10, 10), (50, 40)]),
    ] {
        let objects = scene.objects_in_play::<f64>(settings.stages).len();
        for (x, y) in pixels {
            let (x, y) = (x * scene.width / 100, y * scene.height / 140);
            let story = explain(scene, &settings, x, y);
            assert!(!story.segments.is_empty());
            for segment in &story.segments {
                let counted: usize = segment.unlisted.iter().map(|u| u.count).sum();
                assert_eq!(segment.tests.len() + counted, objects, "pixel {x},{y}");
                if objects > LISTED {
                    assert!(counted > 0);
                    assert!(
                        segment.tests.iter().all(|t| t.t.is_some()),
                        "{:?}",
                        segment.tests
                    );
                    assert!(segment
                        .unlisted
                        .iter()
                        .all(|u| u.verdict.starts_with("miss: ")));
                    let text = story.to_string();
                    for u in &segment.unlisted {
                        let objects = if u.count == 1 { "object" } else { "objects" };
                        let line = format!("  {} other {objects}\n    → {}\n", u.count, u.verdict);
                        assert!(text.contains(&line), "{text}");
                    }
                } else {
                    assert!(segment.unlisted.is_empty());
                }
            }
        }
    }
}
