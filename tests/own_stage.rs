//! Chapter 12's worked example, built and run: ambient occlusion as a seventh
//! stage, `occlusion`, written on the crate's public API.
//!
//! A real stage changes `Tracer::trace` in `src/render.rs`. Until it is ready to go
//! there, it lives here: [`trace`] is a copy of that loop with the stage's lines
//! and a switch for them. The tests check what the chapter says: with the switch
//! off the copy gives the book's bits for every pixel; with it on the picture only
//! darkens, only where a neighbour is within reach, by the numbers the chapter
//! quotes.
//!
//! `RAYSTEP_OWN_STAGE_PNG=1 cargo test --test own_stage` also writes the pictures
//! (`own-stage-off.png`, `own-stage-on.png`, `own-stage-buffer.png`) into the
//! system's temporary folder, to look at.

mod common;

use std::f64::consts::TAU;

use raystep::aov::{Buffer, FirstHit, Frame, PixelRecord};
use raystep::io::output::png_bytes;
use raystep::ray::Ray;
use raystep::real::Precision;
use raystep::render::{Settings, Traced, Tracer, HALF_STEP};
use raystep::scene::{Object, Scene, Shape};
use raystep::shade::blinn_phong::{self, Viewer};
use raystep::shade::{reflection, shadow};
use raystep::stages::{Stage, Stages};
use raystep::tools::compare::compare;
use raystep::Vec3;

// ANCHOR: occlusion
/// How far a probe looks for a neighbour, in scene units.
const RADIUS: f64 = 0.5;
/// How many probes leave each point.
const PROBES: u32 = 8;

/// The share of the probes from `shifted` that meet an object closer than
/// [`RADIUS`]: 0 in the open, 1 where every probe is blocked.
fn occlusion(tracer: &Tracer, shifted: Vec3, normal: Vec3) -> f64 {
    occlusion_with(tracer, shifted, normal, PROBES)
}

/// [`occlusion`] with `probes` probes.
fn occlusion_with(tracer: &Tracer, shifted: Vec3, normal: Vec3, probes: u32) -> f64 {
    // Two unit vectors at right angles to the normal and to each other.
    let helper = if normal.x.abs() < 0.9 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let across = normal.cross(helper).normalize();
    let along = normal.cross(across);
    let mut blocked = 0;
    for i in 0..probes {
        // Evenly spaced round the normal, each 45° away from it.
        let turn = TAU * f64::from(i) / f64::from(probes);
        let sideways = across * turn.cos() + along * turn.sin();
        let probe = (normal + sideways).normalize();
        // Chapter 4's question: is anything along this ray, closer than this?
        if tracer.in_shadow(shifted, probe, RADIUS) {
            blocked += 1;
        }
    }
    f64::from(blocked) / f64::from(probes)
}
// ANCHOR_END: occlusion

/// What the copy of the loop gives for one pixel.
struct Path {
    /// The colour and first hit, as `Tracer::trace` returns them.
    traced: Traced,
    /// The new buffer: the first hit's occlusion; −1 on a miss, 0 where none was
    /// computed (the stage off, or the point in shadow).
    occlusion: f64,
    /// Each point whose ambient term the stage dimmed: the point, the object it
    /// is on, and its occlusion, in the order of the path.
    dimmed: Vec<(Vec3, usize, f64)>,
    /// The probes the stage cast.
    probes: u32,
}

/// `Tracer::trace` of `src/render.rs`, line for line but for the observer, with
/// the `occlusion` stage's lines switched on by `occlusion_on`.
fn trace(tracer: &Tracer, primary: Ray, occlusion_on: bool) -> Path {
    let segments = if tracer.stages.reflection {
        tracer.max_depth
    } else {
        1
    };
    let mut colour = Vec3::ZERO;
    let mut weight = 1.0;
    let mut ray = primary;
    let mut first = None;
    let (mut first_occlusion, mut dimmed, mut probes) = (-1.0, Vec::new(), 0);
    for segment in 0..segments {
        let Some(hit) = tracer.nearest_hit(&ray) else {
            break;
        };
        let object = &tracer.objects[hit.object];
        let point = ray.at(hit.t);
        let normal = object.normal_at(point, &ray);
        let shifted = shadow::step_off(point, normal, object, tracer.offset);
        let to_light = (tracer.light.position - shifted).normalize();
        let lit = if !tracer.stages.shadow {
            true
        } else if shadow::own_shadow(object, normal, to_light, tracer.offset) {
            false
        } else {
            let light_distance = tracer.light.position.distance(point);
            !tracer.in_shadow(shifted, to_light, light_distance)
        };
        // ANCHOR: shading
        let mut occluded = 0.0;
        let terms = (lit && tracer.stages.blinn_phong).then(|| {
            let viewer = match tracer.viewer {
                Viewer::Camera => tracer.camera.position,
                Viewer::RayOrigin => ray.origin,
            };
            let to_viewer = (viewer - point).normalize();
            let mut terms =
                blinn_phong::terms(&object.material, &tracer.light, normal, to_light, to_viewer);
            // The new stage: keep the share of ambient light the probes let in.
            if occlusion_on {
                occluded = occlusion(tracer, shifted, normal);
                terms.ambient *= 1.0 - occluded;
            }
            terms
        });
        // ANCHOR_END: shading
        if terms.is_some() && occlusion_on {
            probes += PROBES;
        }
        if occluded > 0.0 {
            dimmed.push((point, hit.object, occluded));
        }
        if segment == 0 {
            first_occlusion = occluded;
            first = Some(FirstHit {
                depth: hit.t,
                normal,
                lit,
                object: hit.object,
                diffuse: terms.map_or(0.0, |t| t.l_dot_n),
                specular: terms.map_or(0.0, |t| t.highlight),
            });
        }
        if !lit {
            break;
        }
        let illumination = terms.map_or(object.material.diffuse, |t| t.sum());
        colour += illumination * weight;
        weight *= object.material.reflection;
        ray = reflection::reflected_ray(shifted, &ray, normal);
        let left = (segments - segment - 1) as usize;
        if tracer
            .reach
            .get(left)
            .is_some_and(|r| weight * r < HALF_STEP)
        {
            break;
        }
    }
    Path {
        traced: Traced {
            colour: colour.clamp(Vec3::ZERO, Vec3::ONE),
            first,
        },
        occlusion: first_occlusion,
        dimmed,
        probes,
    }
}

/// Every pixel of `scene` under `settings`, row by row, traced by the copy.
fn render(scene: &Scene, settings: &Settings, occlusion_on: bool) -> Vec<Path> {
    let tracer = Tracer::<f64>::new(scene, settings);
    let camera = tracer.camera;
    (0..camera.height)
        .flat_map(|row| (0..camera.width).map(move |col| (row, col)))
        .map(|(row, col)| trace(&tracer, camera.primary_ray(row, col), occlusion_on))
        .collect()
}

/// The figure-1 scene at its size, 300 × 200, traced by the copy with every
/// stage of the book on, without and with the new stage.
fn seed_off_and_on() -> (Vec<Path>, Vec<Path>) {
    let (scene, settings) = (common::seed(300, 200), Settings::from(Stages::ALL));
    (
        render(&scene, &settings, false),
        render(&scene, &settings, true),
    )
}

/// The beauty buffer of `paths`, as a frame stores it (float32).
fn beauty(paths: &[Path]) -> Vec<[f32; 3]> {
    paths
        .iter()
        .map(|p| p.traced.colour.as_vec3().to_array())
        .collect()
}

/// The distance from `p` to the surface of `object`.
fn distance_to(object: &Object, p: Vec3) -> f64 {
    match object.shape {
        Shape::Sphere(s) => p.distance(s.center) - s.radius,
        Shape::Plane(q) => (p - q.point).dot(q.normal).abs(),
    }
}

/// The distance from `p` to the nearest object of `scene` other than `own`.
fn neighbour_distance(scene: &Scene, own: usize, p: Vec3) -> f64 {
    let objects = scene.objects.iter().enumerate();
    objects
        .filter(|&(i, _)| i != own)
        .map(|(_, o)| distance_to(o, p))
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn with_the_stage_off_the_copy_gives_the_books_bits() {
    let scene = common::seed(300, 200);
    for stage in Stage::ALL.into_iter().filter(|&s| s >= Stage::Intersection) {
        let stages = Stages::up_to(stage);
        for settings in [Settings::from(stages), Settings::tutorial(stages)] {
            let tracer = Tracer::<f64>::new(&scene, &settings);
            let paths = render(&scene, &settings, false);
            for (i, path) in paths.iter().enumerate() {
                let (row, col) = (i as u32 / 300, i as u32 % 300);
                let book = tracer.pixel(row, col, &mut ());
                assert_eq!(path.traced, book, "{stage}: pixel ({row}, {col})");
                assert_eq!((path.probes, path.dimmed.len()), (0, 0));
            }
        }
    }
    // The default render, as `raystep render` makes it: the same picture.
    let frame = common::render(&scene, Stages::ALL);
    let book: Vec<[f32; 3]> = frame.pixels.iter().map(|p| p.colour).collect();
    assert_eq!(beauty(&seed_off_and_on().0), book);
}

// ANCHOR: only_darkens
#[test]
fn occlusion_only_darkens_and_only_near_a_neighbour() {
    let scene = common::seed(300, 200);
    let (off, on) = seed_off_and_on();
    for (i, (off, on)) in off.iter().zip(&on).enumerate() {
        // No channel of any pixel gets brighter.
        let (before, after) = (off.traced.colour, on.traced.colour);
        assert!(after.cmple(before).all(), "pixel {i} got brighter");
        // A path the stage did not dim keeps its bits.
        if on.dimmed.is_empty() {
            assert_eq!(on.traced, off.traced, "pixel {i}");
        }
        // Every point it dimmed has another object within reach.
        for &(point, object, _) in &on.dimmed {
            let gap = neighbour_distance(&scene, object, point);
            assert!(gap < RADIUS, "pixel {i}: dimmed {gap} from the nearest");
        }
    }
}
// ANCHOR_END: only_darkens

#[test]
fn the_occlusion_buffer_is_minus_one_on_a_miss_and_zero_in_shadow() {
    let (_, on) = seed_off_and_on();
    for path in &on {
        match path.traced.first {
            None => assert_eq!(path.occlusion, -1.0),
            Some(hit) if !hit.lit => assert_eq!(path.occlusion, 0.0),
            Some(_) => assert!((0.0..=1.0).contains(&path.occlusion)),
        }
    }
}

/// Where the red sphere stands on the floor.
const CONTACT: Vec3 = Vec3::new(-0.2, -0.7, -1.0);

/// Does chapter 12 (`chapter`, its words) say `text`? The counts it quotes are
/// measured here, not written into the tests: a change to the render that moves
/// one fails until the chapter says the new number.
fn says(chapter: &str, text: &str) {
    assert!(chapter.contains(text), "chapter 12 should say {text:?}");
}

#[test]
fn the_numbers_chapter_12_quotes() {
    let (off, on) = seed_off_and_on();
    let lit = |p: &&Path| p.traced.first.is_some_and(|f| f.lit);
    let lit_hits = on.iter().filter(lit).count();
    let touched = on.iter().filter(|p| p.occlusion > 0.0).count();
    let buried: Vec<usize> = (0..on.len()).filter(|&i| on[i].occlusion == 1.0).collect();
    let d = compare(&beauty(&off), &beauty(&on), 300);
    let probes: u64 = on.iter().map(|p| u64::from(p.probes)).sum();
    let rays = common::render(&common::seed(300, 200), Stages::ALL).rays;
    let (g, chapter) = (
        common::grouped,
        common::chapter_words("12-your-own-stage.md"),
    );
    says(&chapter, &format!(
        "Of the {} pixels whose first hit is lit, {} have at least one probe blocked there; {} are buried",
        g(lit_hits),
        g(touched),
        buried.len()
    ));
    says(&chapter, &format!(
        "{} pixels ({:.2} %) change by more than one 8-bit step, and the largest change is by {:.4}, at row {}, column {}",
        g(d.over_one_step),
        100.0 * d.over_one_step as f64 / on.len() as f64,
        d.largest,
        d.largest_at.0,
        d.largest_at.1
    ));
    says(
        &chapter,
        &format!(
            "it cast {} probes, against {} rays for the whole default render",
            g(probes as usize),
            g(rays.total() as usize)
        ),
    );
    assert!(probes > 2 * rays.total(), "the rays more than triple");
    // Every buried point lies within 0.3 of where the red sphere meets the floor.
    let camera = common::seed(300, 200).camera();
    for &i in &buried {
        let ray = camera.primary_ray::<f64>(i as u32 / 300, i as u32 % 300);
        let point = ray.at(on[i].traced.first.unwrap().depth);
        assert!(point.distance(CONTACT) < 0.3, "{point}");
    }
    // The largest change: the red sphere's underside, 6 of 8 probes blocked, and
    // the floor it reflects, 5 of 8 blocked, at half weight.
    let largest = &on[150 * 300 + 149];
    let dimmed: Vec<(usize, f64)> = largest.dimmed.iter().map(|d| (d.1, d.2)).collect();
    assert_eq!(dimmed, [(0, 0.75), (3, 0.625)]);
    // The floor (object 3) is the only neighbour within reach of the first point.
    let scene = common::seed(300, 200);
    let (first, _, _) = largest.dimmed[0];
    let objects = scene.objects.iter().enumerate().skip(1);
    let near: Vec<usize> = objects
        .filter(|(_, o)| distance_to(o, first) < RADIUS)
        .map(|(i, _)| i)
        .collect();
    assert_eq!(near, [3]);
    assert!((f64::from(d.largest) - (0.75 * 0.1 + 0.5 * 0.625 * 0.1)).abs() < 1e-6);

    // The words of the chapter, whatever the line breaks.
    let text = common::chapter_words("12-your-own-stage.md");
    let percent = 100.0 * d.over_one_step as f64 / d.pixels as f64;
    for quoted in [
        format!(
            "Of the {} pixels whose first hit is lit, {} have",
            common::grouped(lit_hits),
            common::grouped(touched)
        ),
        format!("{} are buried: all eight", buried.len()),
        format!(
            "{} pixels ({percent:.2} %) change",
            common::grouped(d.over_one_step)
        ),
        format!("by {:.4}, at row 150, column 149", d.largest),
        format!(
            "{} probes, against {} rays",
            common::grouped(probes as usize),
            common::grouped(rays.total() as usize)
        ),
    ] {
        assert!(text.contains(&quoted), "chapter 12 should say {quoted:?}");
    }
    show(&off, &on);
}

/// With `RAYSTEP_OWN_STAGE_PNG` set, write the pictures without and with the
/// stage, and the new buffer (white in the open, black where every probe is
/// blocked, dark blue on a miss), into the system's temporary folder.
fn show(off: &[Path], on: &[Path]) {
    if std::env::var_os("RAYSTEP_OWN_STAGE_PNG").is_none() {
        return;
    }
    let buffer: Vec<[f32; 3]> = on
        .iter()
        .map(|p| match p.occlusion {
            o if o < 0.0 => [0.0, 0.0, 0.5],
            o => [1.0 - o as f32; 3],
        })
        .collect();
    for (name, colours) in [("off", beauty(off)), ("on", beauty(on)), ("buffer", buffer)] {
        let mut frame = Frame::blank(common::seed(300, 200).camera(), Precision::F64);
        for (record, &colour) in frame.pixels.iter_mut().zip(&colours) {
            *record = PixelRecord::missed(colour, 0, 0);
        }
        let path = std::env::temp_dir().join(format!("own-stage-{name}.png"));
        std::fs::write(&path, png_bytes(&frame, Buffer::Beauty)).unwrap();
        eprintln!("wrote {}", path.display());
    }
}

#[test]
fn exercise_3_more_probes_give_finer_levels_for_four_times_the_probes() {
    // The occlusion of every lit first hit of the seed scene, with 8 probes and 32.
    let scene = common::seed(300, 200);
    let tracer = Tracer::<f64>::new(&scene, &Settings::from(Stages::ALL));
    let (mut eight, mut many) = (Vec::new(), Vec::new());
    for row in 0..scene.height {
        for col in 0..scene.width {
            let ray = tracer.camera.primary_ray::<f64>(row, col);
            let Some(hit) = tracer.nearest_hit(&ray) else {
                continue;
            };
            let object = &tracer.objects[hit.object];
            let point = ray.at(hit.t);
            let normal = object.normal_at(point, &ray);
            let shifted = shadow::step_off(point, normal, object, tracer.offset);
            let to_light = (tracer.light.position - shifted).normalize();
            let distance = tracer.light.position.distance(point);
            if tracer.in_shadow(shifted, to_light, distance) {
                continue;
            }
            eight.push(occlusion_with(&tracer, shifted, normal, 8));
            many.push(occlusion_with(&tracer, shifted, normal, 32));
        }
    }
    let levels = |values: &[f64]| {
        let mut seen: Vec<u64> = values.iter().map(|v| v.to_bits()).collect();
        seen.sort_unstable();
        seen.dedup();
        seen.len()
    };
    let mean = |values: &[f64]| values.iter().sum::<f64>() / values.len() as f64;
    let (l8, l32) = (levels(&eight), levels(&many));
    let (m8, m32) = (mean(&eight), mean(&many));
    let occluded = |values: &[f64]| values.iter().filter(|&&v| v > 0.0).count();
    println!(
        "{} lit first hits: levels {l8} and {l32}; mean {m8:.4} and {m32:.4}; \
         occluded {} and {}",
        eight.len(),
        occluded(&eight),
        occluded(&many)
    );
    // n probes give the fractions k/n, k = 0 to n: every one occurs, with
    // eight probes and with 32.
    assert_eq!((l8, l32), (8 + 1, 32 + 1));
    // More probes find more blockers, not fewer.
    assert!(occluded(&many) > occluded(&eight));
    // What the exercise says, measured here: the lit first hits, the levels,
    // the points with a blocker, and the mean.
    let (g, chapter) = (
        common::grouped,
        common::chapter_words("12-your-own-stage.md"),
    );
    says(
        &chapter,
        &format!("Over the {} lit first hits", g(eight.len())),
    );
    says(
        &chapter,
        &format!("takes {l32} different values instead of {l8}"),
    );
    says(
        &chapter,
        &format!(
            "{} points instead of {} see at least one blocker",
            g(occluded(&many)),
            g(occluded(&eight))
        ),
    );
    says(&chapter, &format!("barely moves ({m8:.3})"));
    assert_eq!(format!("{m8:.3}"), format!("{m32:.3}"), "{m8} {m32}");
}
