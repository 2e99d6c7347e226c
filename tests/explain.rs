//! `raystep explain`: its story ends where the render did, for every pixel, and a
//! few telling pixels of the figure-1 scene are locked as text snapshots (each read
//! through before it was accepted).

mod common;

use raystep::aov::{Frame, PixelRecord, NO_OBJECT};
use raystep::real::Precision;
use raystep::render::{render, Settings};
use raystep::scene::{Scene, Shape};
use raystep::shade::blinn_phong::Viewer;
use raystep::sphere::Method;
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
    agrees_everywhere(
        &scene,
        &Settings {
            viewer: Viewer::RayOrigin,
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

fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a - b).abs() <= tolerance * (1.0 + a.abs().max(b.abs()))
}

/// An early stop is told with the weight the path has left (the object's
/// reflection, from the scene file) and `reach[left]`, the most the segments left
/// could add, as the render's own tracer computes it.
#[test]
fn an_early_stop_names_the_weight_left_and_what_the_segments_left_could_add() {
    use raystep::tools::explain::num;
    let scene = common::scene(
        "[image]\nwidth = 20\nheight = 15\n[camera]\nposition = [0, 0, 1]\n\
         [light]\nposition = [5, 5, 5]\n[render]\nmax_depth = 3\n\
         [[sphere]]\ncenter = [0, 0, -1]\nradius = 0.7\nambient = [0.1, 0, 0]\n\
         diffuse = [0.7, 0, 0]\nreflection = 0.0001\n",
    );
    let settings = Settings::from(Stages::ALL);
    let frame = render(&scene, &settings, &|_| {});
    let story = explain(&scene, &settings, 10, 7);
    check(&story, frame.at(7, 10), &settings);
    assert_eq!(story.segments.len(), 1, "{story}");
    // Three segments allowed, one used: two left, each of which could add at most
    // reach[2] (weight 1) before the weight left scales it.
    let reach = raystep::render::Tracer::<f64>::new(&scene, &settings).reach;
    assert!(reach[2] > reach[1], "{reach:?}");
    let end = format!(
        "early stop after segment 0: the weight left, {}, times the most 2 more segments \
         can add, {}, is below half an 8-bit step",
        num(0.0001),
        num(reach[2])
    );
    assert_eq!(story.end, end);
    assert!(
        story.to_string().contains(&format!("end: {end}\n")),
        "{story}"
    );
}

/// A shadow ray that meets an object only beyond the light leaves the point lit:
/// a sphere at z = −3 (radius 1) lit by a light at z = −1, with a second sphere
/// behind the camera, at z = 3 (radius 0.5), on the shadow ray's line.
#[test]
fn a_blocker_beyond_the_light_leaves_the_point_lit() {
    use raystep::tools::explain::num;
    let scene = common::scene(
        "[image]\nwidth = 21\nheight = 21\n[camera]\nposition = [0, 0, 1]\n\
         [light]\nposition = [0, 0, -1]\n\
         [[sphere]]\ncenter = [0, 0, -3]\nradius = 1\n\
         [[sphere]]\ncenter = [0, 0, 3]\nradius = 0.5\n",
    );
    let settings = Settings::from(Stages::ALL);
    let frame = render(&scene, &settings, &|_| {});
    let story = explain(&scene, &settings, 10, 10);
    let record = frame.at(10, 10);
    assert_eq!(record.shadow, 1.0, "the render lights the point");
    check(&story, record, &settings);
    let hit = story.segments[0].hit.as_ref().expect("the near sphere");
    assert!(hit.lit && hit.shading.is_some(), "{story}");
    let shadow = hit.shadow.as_ref().expect("a shadow ray");
    // From (0, 0, −2) (about: the pixel is the centre one) to the light at z = −1,
    // and on to the far sphere's near side at z = 2.5.
    let (object, t) = shadow.blocker.expect("the sphere behind the camera");
    assert_eq!(object, 1);
    assert!((shadow.light_distance - 1.0).abs() < 1e-3, "{story}");
    assert!((t - 4.5).abs() < 1e-2, "{story}");
    let line = format!(
        "    → object 1 at {}, beyond the light ({}): lit\n",
        num(t),
        num(shadow.light_distance)
    );
    assert!(story.to_string().contains(&line), "{story}");
}

/// With the tutorial's fixed offset, a hit point is moved 1e-5 along its normal,
/// and the shadow ray and the reflection start from the moved point.
#[test]
fn the_moved_point_is_1e_5_along_the_normal_and_new_rays_start_there() {
    let scene = common::seed(300, 200);
    let settings = Settings::tutorial(Stages::ALL);
    let story = explain(&scene, &settings, 152, 81);
    let hit = story.segments[0].hit.as_ref().expect("the red sphere");
    for k in 0..3 {
        let moved = hit.point[k] + 1e-5 * hit.normal[k];
        assert!(close(hit.shifted[k], moved, 1e-12), "{story}");
    }
    assert!(close(hit.offset, 1e-5, 1e-9), "{}", hit.offset);
    let shadow = hit.shadow.as_ref().expect("a shadow ray");
    assert_eq!(shadow.ray.origin, hit.shifted);
    // The light, at (5, 5, 5), measured from the hit point.
    let to_light = [0, 1, 2].map(|k| 5.0 - hit.point[k]);
    let distance = to_light.iter().map(|c| c * c).sum::<f64>().sqrt();
    assert!(close(shadow.light_distance, distance, 1e-12), "{story}");
    let reflection = &story.segments[1];
    assert_eq!(reflection.ray.origin, hit.shifted);
}

/// With several samples per pixel the story gives their mean as the record keeps
/// it (in float32, exactly), the number of samples, and says so in words.
#[test]
fn with_several_samples_the_story_gives_their_mean_as_the_record_keeps_it() {
    use raystep::tools::explain::num;
    let scene = common::seed(60, 40);
    let settings = Settings {
        spp: 4,
        ..Settings::from(Stages::ALL)
    };
    let frame = render(&scene, &settings, &|_| {});
    let mut differ = 0;
    for (x, y) in [(28, 12), (30, 20), (45, 30), (10, 35), (0, 0)] {
        let story = explain(&scene, &settings, x, y);
        let record = frame.at(y, x);
        let samples = story.samples.as_ref().expect("four samples");
        assert_eq!(samples.spp, 4);
        assert_eq!(samples.colour, record.colour.map(f64::from), "{x},{y}");
        let text = story.to_string();
        let [r, g, b] = record.colour.map(|c| num(f64::from(c)));
        let line = format!("with 4 samples the pixel is their mean, ({r}, {g}, {b}); ");
        assert!(text.contains(&line), "{text}");
        assert!(story.rules.ends_with(", 4 samples per pixel"), "{text}");
        differ += usize::from(samples.colour != story.colour);
    }
    assert!(
        differ > 0,
        "a pixel whose mean is not its centre ray's colour"
    );
}

/// The float32 story tells float32 numbers: the screen point and the rays and
/// hits are float32 values, near the float64 story's.
#[test]
fn a_float32_story_tells_float32_numbers() {
    let scene = common::seed(60, 40);
    let f32_settings = Settings {
        precision: Precision::F32,
        ..Settings::from(Stages::ALL)
    };
    let is_f32 = |v: [f64; 3]| v.iter().all(|&c| f64::from(c as f32) == c);
    for (x, y) in [(28, 12), (31, 17), (10, 35), (0, 0)] {
        let story = explain(&scene, &f32_settings, x, y);
        let wide = explain(&scene, &Settings::from(Stages::ALL), x, y);
        let at = format!("pixel {x},{y}: {story}");
        assert!(is_f32(story.screen_point), "{at}");
        for k in 0..3 {
            assert!(
                close(story.screen_point[k], wide.screen_point[k], 1e-6),
                "{at}"
            );
        }
        assert!(is_f32(story.primary.direction), "{at}");
        for segment in &story.segments {
            assert!(
                is_f32(segment.ray.origin) && is_f32(segment.ray.direction),
                "{at}"
            );
            if let Some(hit) = &segment.hit {
                assert!(f64::from(hit.t as f32) == hit.t, "{at}");
                assert!(is_f32(hit.point) && is_f32(hit.normal), "{at}");
            }
        }
    }
}

/// With only the rays stage on, the colour is the primary ray's direction,
/// normalize(screen point − camera), each component mapped from [−1, 1] to
/// [0, 1]: nothing to clip.
#[test]
fn with_only_the_rays_stage_the_colour_is_the_direction_mapped() {
    use raystep::tools::explain::num;
    let scene = common::seed(60, 40);
    let settings = Settings::from(Stages::up_to(Stage::Rays));
    let frame = render(&scene, &settings, &|_| {});
    for (x, y) in [(0, 0), (30, 20), (59, 39)] {
        let story = explain(&scene, &settings, x, y);
        let p = story.screen_point;
        let towards = [p[0], p[1], p[2] - 1.0]; // the camera is at (0, 0, 1)
        let length = towards.iter().map(|c| c * c).sum::<f64>().sqrt();
        for (k, towards) in towards.into_iter().enumerate() {
            let mapped = (towards / length + 1.0) / 2.0;
            assert!(close(story.unclipped[k], mapped, 1e-9), "{story}");
            assert_eq!(story.unclipped[k], story.colour[k], "{story}");
        }
        assert_eq!(story.colour.map(|c| c as f32), frame.at(y, x).colour);
        let [r, g, b] = story.colour.map(num);
        let line = format!("colour: ({r}, {g}, {b}) → clipped to [0, 1]: ({r}, {g}, {b})");
        assert!(story.to_string().contains(&line), "{story}");
    }
}

/// A true plane's test names it as the scene file does and gives its one
/// crossing, `(point − origin)·N / (direction·N)`: ahead of a ray looking down at
/// it, behind one looking up.
#[test]
fn a_true_planes_test_names_it_and_gives_its_crossing() {
    let path = format!("{}/scenes/true-plane.toml", env!("CARGO_MANIFEST_DIR"));
    let mut scene = raystep::io::scene_file::load(path.as_ref()).unwrap();
    (scene.width, scene.height) = (60, 40);
    let settings = Settings::from(Stages::ALL);
    for (x, y, ahead) in [(30, 39, true), (30, 0, false)] {
        let story = explain(&scene, &settings, x, y);
        let plane = &story.segments[0].tests[3];
        assert_eq!(
            plane.what,
            "plane (the floor), through (0, -0.7, 0), normal (0, 1, 0)"
        );
        // The floor is y = −0.7 and the camera at y = 0.
        let crossing = -0.7 / story.primary.direction[1];
        assert_eq!(plane.roots.len(), 1, "{story}");
        assert!(close(plane.roots[0], crossing, 1e-12), "{story}");
        assert_eq!(crossing > 0.0, ahead);
        if ahead {
            assert_eq!(plane.t, Some(plane.roots[0]), "{story}");
        } else {
            assert_eq!(plane.verdict, "miss: the plane is behind the ray");
        }
    }
}

/// The naive method's discriminant is `Δ = b² − 4c` with `b = 2·d·(o − C)` and
/// `c = ‖o − C‖² − r²` (a unit direction), and its misses are told with `Δ`.
#[test]
fn the_naive_method_tells_delta_and_its_value() {
    let scene = common::seed(300, 200);
    let settings = Settings::tutorial(Stages::ALL);
    let story = explain(&scene, &settings, 152, 81);
    let spheres = [
        ([-0.2, 0.0, -1.0], 0.7),
        ([0.1, -0.3, 0.0], 0.1),
        ([-0.3, 0.0, 0.0], 0.15),
        ([0.0, -9000.0, 0.0], 8999.3),
    ];
    let ray = &story.segments[0].ray;
    let mut misses = 0;
    for (test, (centre, radius)) in story.segments[0].tests.iter().zip(spheres) {
        let f = [0, 1, 2].map(|k| ray.origin[k] - centre[k]);
        let b = 2.0 * (0..3).map(|k| ray.direction[k] * f[k]).sum::<f64>();
        let c = f.iter().map(|v| v * v).sum::<f64>() - radius * radius;
        let delta = b * b - 4.0 * c;
        let d = test.discriminant.expect("a sphere's discriminant");
        assert!((d - delta).abs() <= 1e-9 * b * b, "{d} {delta}: {story}");
        if delta < 0.0 {
            assert_eq!(test.verdict, "miss: Δ < 0, the ray passes beside it");
            misses += 1;
        }
    }
    assert!(misses > 0, "{story}");
}

/// Each hit tells the path's sum so far: the segments' light times their
/// weights, up to and with this segment's, which adds nothing in shadow.
#[test]
fn each_hit_tells_the_sum_so_far() {
    let scene = common::seed(60, 40);
    let settings = Settings::from(Stages::ALL);
    let mut reflections_in_shadow = 0;
    for y in 0..scene.height {
        for x in 0..scene.width {
            let story = explain(&scene, &settings, x, y);
            let mut sum = [0.0f64; 3];
            for segment in &story.segments {
                let Some(hit) = &segment.hit else { break };
                if let Some(light) = hit.illumination {
                    (0..3).for_each(|k| sum[k] += light[k] * segment.weight);
                } else if segment.index > 0 {
                    reflections_in_shadow += 1;
                }
                for (told, sum) in hit.sum.into_iter().zip(sum) {
                    assert!(close(told, sum, 1e-6), "{story}");
                }
            }
        }
    }
    assert!(reflections_in_shadow > 0);
}

/// A path that ends in shadow after reflections names the segment it ended at:
/// the render's count of reflections for that pixel.
#[test]
fn a_reflection_in_shadow_names_its_segment() {
    let scene = common::seed(60, 40);
    let settings = Settings::from(Stages::ALL);
    let frame = render(&scene, &settings, &|_| {});
    let mut told = 0;
    for y in 0..scene.height {
        for x in 0..scene.width {
            let story = explain(&scene, &settings, x, y);
            let record = frame.at(y, x);
            let last = story.segments.last().and_then(|s| s.hit.as_ref());
            if record.bounces == 0 || last.is_none_or(|h| h.lit) {
                continue;
            }
            let end = format!(
                "the point of segment {} does not see the light: the path ends there and adds \
                 nothing more (the tutorial's rule)",
                record.bounces
            );
            assert_eq!(story.end, end, "pixel {x},{y}");
            told += 1;
        }
    }
    assert!(told > 0);
}

/// A 3 × 3 picture whose middle ray, from the camera at z = 1 through the screen's
/// centre, runs exactly along −z: one sphere it only touches (centre 1 above the
/// ray, radius 1), one behind the camera (its roots −5 and −3), and a true plane
/// the ray runs parallel to. Every discriminant here is exact in float64.
const GRAZED: &str = r#"
[image]
width = 3
height = 3

[camera]
position = [0, 0, 1]

[light]
position = [5, 5, 5]

[[sphere]] # touched: f = o − C = (0, −1, 4), so f + (−f·d)·d = (0, −1, 0)
center = [0, 1, -3]
radius = 1
ambient = [0.1, 0, 0]
diffuse = [0.7, 0, 0]

[[sphere]] # behind the camera
center = [0, 0, 5]
radius = 1
ambient = [0, 0.1, 0]
diffuse = [0, 0.6, 0]

[[plane]]
point = [0, -0.7, 0]
normal = [0, 1, 0]
ambient = [0.1, 0.1, 0.1]
diffuse = [0.6, 0.6, 0.6]
"#;

/// Each way a ray can miss is told in its own words: a discriminant of exactly 0
/// (a ray that only touches the sphere: the tutorial asks Δ > 0), both roots
/// behind the ray, a plane the ray runs parallel to, and (from an infinite
/// input, which no scene file can hold) a discriminant that is not a number.
#[test]
fn each_kind_of_miss_is_told_as_what_it_is() {
    let mut scene = common::scene(GRAZED);
    let frame = render(&scene, &Settings::from(Stages::ALL), &|_| {});
    assert_eq!(
        frame.at(1, 1).object,
        NO_OBJECT,
        "the middle ray meets nothing"
    );
    // Δ/4 = r² − ‖f + h·d‖² = 1 − 1; Δ = b² − 4c = (−8)² − 4·(17 − 1).
    for (method, name) in [(Method::Stable, "Δ/4"), (Method::Naive, "Δ")] {
        let settings = Settings {
            method,
            ..Settings::from(Stages::ALL)
        };
        let story = explain(&scene, &settings, 1, 1);
        assert_eq!(story.primary.direction, [0.0, 0.0, -1.0]);
        assert!(story.segments[0].hit.is_none(), "{story}");
        assert_eq!(story.depth, None);
        let [tangent, behind, plane] = &story.segments[0].tests[..] else {
            panic!("three tests: {story}")
        };
        assert_eq!(tangent.discriminant, Some(0.0), "{story}");
        assert!(tangent.roots.is_empty() && tangent.t.is_none(), "{story}");
        assert_eq!(
            tangent.verdict,
            format!("miss: {name} = 0, the ray only touches it")
        );
        // From z = 1 along −z, the sphere around z = 5 of radius 1 is met at
        // t = −5 and t = −3.
        assert_eq!(behind.roots.len(), 2, "{story}");
        assert!(close(behind.roots[0], -5.0, 1e-12), "{story}");
        assert!(close(behind.roots[1], -3.0, 1e-12), "{story}");
        assert_eq!(
            behind.verdict,
            "miss: both roots negative, the sphere is behind the ray"
        );
        // d·N = 0: no crossing to give.
        assert_eq!(plane.discriminant, None);
        assert!(plane.roots.is_empty() && plane.t.is_none(), "{story}");
        assert_eq!(plane.verdict, "miss: the ray runs parallel to the plane");
        let text = story.to_string();
        assert!(
            text.contains(&format!("; discriminant {name} = 0\n")),
            "{story}"
        );
        assert!(
            text.contains(&format!("→ miss: {name} = 0, the ray only touches it")),
            "{story}"
        );
    }
    // A centre at infinity makes f·d = (−∞)·0, not a number: still a miss.
    let Shape::Sphere(s) = &mut scene.objects[0].shape else {
        panic!("the first object is a sphere")
    };
    s.center.y = f64::INFINITY;
    let story = explain(&scene, &Settings::from(Stages::ALL), 1, 1);
    let tangent = &story.segments[0].tests[0];
    assert!(tangent.discriminant.is_some_and(f64::is_nan), "{story}");
    assert_eq!(tangent.verdict, "miss: Δ/4 is not a number");
}

/// With `--viewer ray-origin`, Blinn-Phong's V at each hit points back along the
/// ray that found it, to that ray's origin: the camera for the primary ray, the
/// moved point of the last hit for a reflection (which is not the camera's
/// direction). The rules say so.
#[test]
fn with_the_ray_origin_as_viewer_v_points_back_to_each_rays_start() {
    let scene = common::seed(60, 40);
    let settings = Settings {
        viewer: Viewer::RayOrigin,
        ..Settings::from(Stages::ALL)
    };
    let unit = |v: [f64; 3]| {
        let n = v.iter().map(|c| c * c).sum::<f64>().sqrt();
        v.map(|c| c / n)
    };
    let (mut reflections, mut unlike_the_camera) = (0, 0);
    for y in 0..scene.height {
        for x in 0..scene.width {
            let story = explain(&scene, &settings, x, y);
            assert!(story.rules.contains("viewer ray origin"), "{}", story.rules);
            for segment in &story.segments {
                let Some(hit) = &segment.hit else { break };
                let Some(shading) = &hit.shading else {
                    continue;
                };
                let back = unit([0, 1, 2].map(|k| segment.ray.origin[k] - hit.point[k]));
                let to_camera = unit([0, 1, 2].map(|k| [0.0, 0.0, 1.0][k] - hit.point[k]));
                for (told, back) in shading.to_viewer.into_iter().zip(back) {
                    assert!(close(told, back, 1e-9), "{story}");
                }
                if segment.index > 0 {
                    reflections += 1;
                    let apart = (0..3).any(|k| !close(shading.to_viewer[k], to_camera[k], 1e-3));
                    unlike_the_camera += usize::from(apart);
                }
            }
        }
    }
    assert!(reflections > 0 && unlike_the_camera > 0);
}
