//! Renders with answers known in advance, in the style of pbrt's tests: analytic
//! depths, unit normals, each light colour in its own term, a float32 render's
//! depths, a point behind an occluder (and not behind an object past the light),
//! rays re-cast from a hit point, `--without` equal to the stage before, the
//! levels of `--spp`'s samples, the segment at which early stop ends a path
//! between two mirrors, a large scene's tree changing no pixel, and the same
//! bytes on any thread count.

mod common;

use raystep::io::output::{exr_bytes, png_bytes};
use raystep::ray::Ray;
use raystep::render::Settings;
use raystep::render::Tracer;
use raystep::shade::reflection::reflect;
use raystep::shade::shadow::{step_off, Offset};
use raystep::stages::{Stage, Stages};
use raystep::tools::accuracy::surface_distance;
use raystep::Vec3;

/// One sphere straight ahead of the camera, light at the camera.
const ONE_SPHERE: &str = r#"
[image]
width = 5
height = 5
[camera]
position = [0, 0, 1]
[light]
position = [0, 0, 1]
[[sphere]]
center = [0, 0, -3]
radius = 1
ambient = [0.1, 0.1, 0.1]
diffuse = [0.5, 0.5, 0.5]
specular = [0.25, 0.25, 0.25]
reflection = 0
"#;

#[test]
fn the_centre_pixel_sees_the_sphere_at_its_analytic_distance() {
    let scene = common::scene(ONE_SPHERE);
    let frame = common::render(&scene, Stages::ALL);
    // Camera at z = 1, sphere surface nearest to it at z = -2: distance 3.
    assert_eq!(frame.at(2, 2).depth, 3.0);
    // The corner pixels look past the sphere.
    assert_eq!(frame.at(0, 0).depth, f32::INFINITY);
    assert_eq!(frame.at(0, 0).shadow, -1.0);
    assert_eq!(frame.at(0, 0).normal, [0.0; 3]);
}

#[test]
fn every_depth_equals_the_geometric_distance_to_the_sphere() {
    // A second formula, not the quadratic: project the centre on the ray, then
    // step back by the half chord.
    let mut scene = common::scene(ONE_SPHERE);
    (scene.width, scene.height) = (41, 41);
    let tracer = Tracer::<f64>::new(&scene, &Stages::ALL.into());
    let (c, r) = (Vec3::new(0.0, 0.0, -3.0), 1.0);
    let mut hits = 0;
    for row in 0..41 {
        for col in 0..41 {
            let ray = tracer.camera.primary_ray::<f64>(row, col);
            let along = (c - ray.origin).dot(ray.direction);
            let miss2 = (c - ray.origin).length_squared() - along * along;
            let traced = tracer.trace(ray, &mut ());
            match traced.first {
                Some(hit) => {
                    hits += 1;
                    let expected = along - (r * r - miss2).sqrt();
                    assert!((hit.depth - expected).abs() < 1e-12, "{row},{col}");
                }
                None => assert!(miss2 >= r * r * (1.0 - 1e-12), "{row},{col}"),
            }
        }
    }
    // The sphere covers about 89 of the 41 × 41 pixels.
    assert!(hits > 80, "{hits}");
}

#[test]
fn lit_head_on_the_centre_pixel_is_ambient_plus_diffuse_plus_specular() {
    // L = V = N = +z at the centre: every Blinn-Phong factor is 1.
    let frame = common::render(&common::scene(ONE_SPHERE), Stages::ALL);
    let c = frame.at(2, 2).colour;
    for channel in c {
        assert!((channel - 0.85).abs() < 1e-6, "{c:?}");
    }
}

#[test]
fn each_term_takes_its_own_colour_of_the_light() {
    // The light's three colours told apart, one channel each: the ambient term
    // is red only, the diffuse green only, the specular blue only. Head on,
    // every factor is 1, so the pixel is (ka·la_r, kd·ld_g, ks·ls_b).
    let scene = ONE_SPHERE.replace(
        "[light]\nposition = [0, 0, 1]",
        "[light]\nposition = [0, 0, 1]\nambient = [1, 0, 0]\ndiffuse = [0, 1, 0]\nspecular = [0, 0, 1]",
    );
    assert_ne!(scene, ONE_SPHERE);
    let frame = common::render(&common::scene(&scene), Stages::ALL);
    let c = frame.at(2, 2).colour;
    let expected = [0.1, 0.5, 0.25];
    for k in 0..3 {
        assert!((c[k] - expected[k]).abs() < 1e-6, "{c:?}");
    }
}

#[test]
fn a_float32_render_is_traced_in_float32() {
    // `--precision f32` runs the book's tracer on float32 numbers: every hit's
    // depth is the float32 tracer's, and some are not the float64 tracer's.
    let scene = common::seed(60, 40);
    let settings = Settings {
        precision: raystep::real::Precision::F32,
        ..Settings::from(Stages::ALL)
    };
    let frame = raystep::render::render(&scene, &settings, &|_| {});
    let camera = scene.camera();
    let narrow = Tracer::<f32>::new(&scene, &settings);
    let wide = Tracer::<f64>::new(&scene, &Settings::from(Stages::ALL));
    let depth = |first: Option<raystep::aov::FirstHit>| first.map(|f| f.depth as f32);
    let (mut hits, mut apart) = (0, 0);
    for row in 0..40 {
        for col in 0..60 {
            let in_f32 = depth(narrow.trace(camera.primary_ray(row, col), &mut ()).first);
            let in_f64 = depth(wide.trace(camera.primary_ray(row, col), &mut ()).first);
            let record = frame.at(row, col);
            assert_eq!(in_f32.is_some(), record.is_hit(), "({row}, {col})");
            if let Some(d) = in_f32 {
                assert_eq!(d, record.depth, "({row}, {col})");
                hits += 1;
                apart += usize::from(in_f64 != Some(d));
            }
        }
    }
    assert!(hits > 1000, "{hits} hits");
    assert!(
        apart > hits / 10,
        "{apart} of {hits} depths differ in float64"
    );
}

#[test]
fn the_exr_holds_the_exact_depth_of_a_pixel() {
    let frame = common::render(&common::scene(ONE_SPHERE), Stages::ALL);
    let dir = tempfile::tempdir().unwrap();
    raystep::io::output::write_frame(&frame, dir.path()).unwrap();
    let image =
        exr::prelude::read_all_flat_layers_from_file(dir.path().join("buffers.exr")).unwrap();
    let layer = &image.layer_data[0];
    let channel = |name: &str| {
        layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap_or_else(|| panic!("no channel {name}"))
    };
    let at = |name: &str, row: usize, col: usize| {
        channel(name)
            .sample_data
            .value_by_flat_index(row * 5 + col)
            .to_f32()
    };
    assert_eq!(at("Z", 2, 2), 3.0);
    assert_eq!(at("Z", 0, 0), f32::INFINITY);
    assert_eq!(at("N.Z", 2, 2), 1.0);
    assert_eq!(at("shadow.X", 2, 2), 1.0);
    assert_eq!(at("shadow.X", 0, 0), -1.0);
    assert!((at("R", 2, 2) - 0.85).abs() < 1e-6);
    assert_eq!(at("dir.Z", 2, 2), -1.0);
    // P: from the camera at z = 1, 3 along −z, the sphere's front at z = −2; a
    // miss holds (0, 0, 0).
    let p = |row, col| ["P.X", "P.Y", "P.Z"].map(|c| at(c, row, col));
    assert_eq!(p(2, 2), [0.0, 0.0, -2.0]);
    assert_eq!(p(0, 0), [0.0; 3]);
}

#[test]
fn normals_are_unit_length_on_hits_and_zero_on_misses() {
    let frame = common::render(&common::seed(150, 100), Stages::ALL);
    let mut hits = 0;
    for p in &frame.pixels {
        let n = Vec3::from(p.normal.map(f64::from));
        if p.is_hit() {
            hits += 1;
            assert!((n.length() - 1.0).abs() < 1e-6, "{n}");
        } else {
            assert_eq!(n, Vec3::ZERO);
        }
    }
    assert!(hits > 0);
}

/// A floor sphere, an occluder above its top, the light above both: the floor
/// sphere's top at (0, 0, −2), the light 5 above it at (0, 5, −2), and an
/// occluder of radius 0.5 at (x, y, −2).
fn occluder_at(occluder_x: f64, occluder_y: f64) -> raystep::scene::Scene {
    common::scene(&format!(
        r#"
        [camera]
        position = [0, 0, 1]
        [light]
        position = [0, 5, -2]
        [[sphere]]
        center = [0, -1, -2]
        radius = 1
        [[sphere]]
        center = [{occluder_x}, {occluder_y}, -2]
        radius = 0.5
        "#
    ))
}

#[test]
fn a_point_behind_an_occluder_is_in_shadow_and_black() {
    // Look straight down at the top of the lower sphere, (0, 0, -2).
    let down: Ray = Ray {
        origin: Vec3::new(0.0, 1.0, -2.0),
        direction: -Vec3::Y,
    };
    let blocked =
        Tracer::<f64>::new(&occluder_at(0.0, 2.0), &Stages::ALL.into()).trace(down, &mut ());
    let hit = blocked.first.unwrap();
    assert_eq!(hit.depth, 1.0);
    assert!(!hit.lit);
    assert_eq!(blocked.colour, Vec3::ZERO);

    // The same point with the occluder moved aside is lit.
    let open = Tracer::<f64>::new(&occluder_at(3.0, 2.0), &Stages::ALL.into()).trace(down, &mut ());
    assert!(open.first.unwrap().lit);
    assert!(open.colour.max_element() > 0.5);

    // Along the whole way to the light and no farther: an occluder from 3.5 to
    // 4.5 above the point, of the light's 5, shadows it; one from 5.5 to 6.5,
    // past the light, does not.
    let lit_with = |y: f64| {
        Tracer::<f64>::new(&occluder_at(0.0, y), &Stages::ALL.into())
            .trace(down, &mut ())
            .first
            .unwrap()
            .lit
    };
    assert!(!lit_with(4.0), "an occluder near the light");
    assert!(lit_with(6.0), "an object beyond the light");

    // Without the shadow stage no shadow ray is cast: the point reads lit.
    let no_shadow = Stages::select(Stage::Plane, &[Stage::Shadow]).unwrap();
    assert!(
        Tracer::<f64>::new(&occluder_at(0.0, 2.0), &no_shadow.into())
            .trace(down, &mut ())
            .first
            .unwrap()
            .lit
    );
}

/// What re-casting from the stepped-off hit points of the seed scene finds.
#[derive(Debug, Default)]
struct Recast {
    /// First hits checked.
    checked: usize,
    /// Stepped-off origins not outside their surface.
    inside: usize,
    /// Reflected rays that meet their own surface again.
    rehit: usize,
    /// Shadow rays into a sphere's dark side (L·N < 0) that miss that sphere, and
    /// the largest |L·N| among them.
    dark_leaks: usize,
    worst_leak: f64,
}

fn recast(settings: Settings) -> Recast {
    let scene = common::seed(150, 100);
    let tracer = Tracer::<f64>::new(&scene, &settings);
    let mut r = Recast::default();
    for row in 0..scene.height {
        for col in 0..scene.width {
            let ray = tracer.camera.primary_ray::<f64>(row, col);
            let Some(hit) = tracer.trace(ray, &mut ()).first else {
                continue;
            };
            let object = &tracer.objects[hit.object];
            let point = ray.at(hit.depth);
            let shifted = step_off(point, hit.normal, object, settings.offset);
            let to_light = (scene.light.position - shifted).normalize();
            let cast = |direction| {
                object.intersect(
                    &Ray {
                        origin: shifted,
                        direction,
                    },
                    settings.method,
                )
            };
            r.checked += 1;
            r.inside += usize::from(surface_distance(object, shifted) <= 0.0);
            r.rehit += usize::from(cast(reflect(ray.direction, hit.normal)).is_some());
            let facing = to_light.dot(hit.normal);
            if facing < 0.0 && cast(to_light).is_none() {
                r.dark_leaks += 1;
                r.worst_leak = r.worst_leak.max(-facing);
            }
        }
    }
    r
}

#[test]
fn a_ray_recast_from_a_stepped_off_hit_point_leaves_its_surface_or_meets_it_as_it_should() {
    // raystep's defaults: every stepped-off origin is outside its surface, no
    // reflected ray meets its surface again, and every shadow ray into a sphere's
    // dark side is blocked by that sphere.
    let defaults = recast(Settings::from(Stages::ALL));
    assert!(defaults.checked > 5_000, "{defaults:?}");
    assert_eq!(
        (defaults.inside, defaults.rehit, defaults.dark_leaks),
        (0, 0, 0),
        "{defaults:?}"
    );

    // The tutorial's 1e-5 step: outside and no re-hit too, but just past the
    // terminator the step lifts the shadow ray over its own sphere. A ray starting h
    // above a sphere of radius r passes over it when it dips below the tangent plane
    // by less than √(2h/r): for the smallest sphere (r = 0.1), |L·N| < 0.014.
    let tutorial = recast(Settings::tutorial(Stages::ALL));
    assert_eq!((tutorial.inside, tutorial.rehit), (0, 0), "{tutorial:?}");
    let bound = (2.0 * 1e-5 / 0.1f64).sqrt();
    assert!(
        tutorial.dark_leaks > 0 && tutorial.worst_leak < bound,
        "{tutorial:?}"
    );

    // Without a step: about half the origins sit inside.
    let none = recast(Settings {
        offset: Offset::Fixed(0.0),
        ..Settings::from(Stages::ALL)
    });
    assert!(none.inside > none.checked / 4, "{none:?}");
}

#[test]
fn switched_off_stages_give_what_other_settings_give() {
    // No reflection stage is one segment per path. (The frames record different
    // stages, so their pixels are compared.)
    let seed = common::seed(60, 40);
    let mut one_segment = seed.clone();
    one_segment.max_depth = 1;
    let without_reflection = Stages::select(Stage::Plane, &[Stage::Reflection]).unwrap();
    assert_eq!(
        common::render(&seed, without_reflection).pixels,
        common::render(&one_segment, Stages::ALL).pixels
    );
    assert_ne!(
        common::render(&seed, without_reflection).pixels,
        common::render(&seed, Stages::ALL).pixels
    );

    // On a scene with no [[plane]], the plane stage changes nothing.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/shadow.toml");
    let no_planes = raystep::io::scene_file::load(path.as_ref()).unwrap();
    assert_eq!(
        common::render(&no_planes, Stages::up_to(Stage::Plane)).pixels,
        common::render(&no_planes, Stages::up_to(Stage::Reflection)).pixels
    );
    // On figure 1 it adds the floor.
    assert_ne!(
        common::render(&seed, Stages::up_to(Stage::Plane)).pixels,
        common::render(&seed, Stages::up_to(Stage::Reflection)).pixels
    );
}

#[test]
fn without_shadow_every_hit_is_plain_blinn_phong_even_where_it_is_negative() {
    // --stage blinn-phong --without shadow: no shadow ray, so every hit is lit and its
    // colour is clip(ambient + diffuse·(L·N) + specular), with L·N negative on the
    // far side of a sphere (so some hits are black).
    let scene = common::seed(120, 80);
    let stages = Stages::select(Stage::BlinnPhong, &[Stage::Shadow]).unwrap();
    let settings = Settings::from(stages);
    let tracer = Tracer::<f64>::new(&scene, &settings);
    let frame = common::render(&scene, stages);
    let mut black = 0;
    for row in 0..scene.height {
        for col in 0..scene.width {
            let p = frame.at(row, col);
            if !p.is_hit() {
                continue;
            }
            assert_eq!(p.shadow, 1.0);
            let ray = tracer.camera.primary_ray::<f64>(row, col);
            let hit = tracer.trace(ray, &mut ()).first.unwrap();
            let object = &tracer.objects[hit.object];
            let point = ray.at(hit.depth);
            let shifted = step_off(point, hit.normal, object, settings.offset);
            let to_light = (scene.light.position - shifted).normalize();
            let to_camera = (scene.camera - point).normalize();
            let expected = raystep::shade::blinn_phong::terms(
                &object.material,
                &scene.light,
                hit.normal,
                to_light,
                to_camera,
            )
            .sum()
            .clamp(Vec3::ZERO, Vec3::ONE);
            let got = Vec3::from(p.colour.map(f64::from));
            assert!(
                (got - expected).abs().max_element() < 1e-6,
                "{row},{col}: {got} vs {expected}"
            );
            black += usize::from(p.colour == [0.0; 3]);
        }
    }
    assert!(black > 0, "the far sides, where L·N < 0, clip to black");
}

/// `--spp N` colours a pixel with the mean of N stratified samples, while its
/// buffers keep the centre ray's first hit. In the intersection stage a hit is
/// the sphere's flat diffuse colour (0.5) and a miss black, so with N samples
/// every channel is k · 0.5 / N for the k samples that hit: the pixels the
/// silhouette crosses take the levels between, the others 0 or 0.5.
#[test]
fn several_samples_average_the_pixel_and_leave_its_buffers_as_one_sample_has_them() {
    let mut scene = common::scene(ONE_SPHERE);
    (scene.width, scene.height) = (21, 21);
    let render = |spp: u32| {
        let settings = Settings {
            spp,
            ..Settings::from(Stages::up_to(Stage::Intersection))
        };
        raystep::render::render(&scene, &settings, &|_| {})
    };
    let one = render(1);
    for spp in [1, 4, 9] {
        let frame = render(spp);
        let mut levels = std::collections::BTreeSet::new();
        for row in 0..21 {
            for col in 0..21 {
                let (p, q) = (frame.at(row, col), one.at(row, col));
                // The buffers are the centre ray's, whatever the sample count.
                let buffers = |r: &raystep::aov::PixelRecord| {
                    (r.depth, r.normal, r.shadow, r.object, r.bounces)
                };
                assert_eq!(buffers(p), buffers(q), "({row}, {col}) at {spp} spp");
                // The centre ray, then the samples (no shadow ray, no bounce).
                assert_eq!(p.rays, if spp > 1 { spp + 1 } else { 1 });
                let hits = f64::from(p.colour[0]) / 0.5 * f64::from(spp);
                let k = hits.round();
                assert!(
                    (hits - k).abs() < 1e-5 && (0.0..=f64::from(spp)).contains(&k),
                    "({row}, {col}) at {spp} spp: {:?}",
                    p.colour
                );
                assert!(p.colour.iter().all(|&c| c == p.colour[0]));
                levels.insert(k as u32);
            }
        }
        // Misses, full hits and levels between them: a render that traced the
        // centre ray alone would show only 0 and N.
        let between = levels.iter().filter(|&&k| k > 0 && k < spp).count();
        assert!(levels.contains(&0) && levels.contains(&spp), "{levels:?}");
        assert!(
            between >= usize::from(spp > 1) * 2,
            "at {spp} spp: {levels:?}"
        );
    }
}

/// A rule for ending a path: does it end after segment `s`, given `reach(k)`,
/// the most `k` segments of weight 1 can add?
type Ends<'a> = &'a dyn Fn(u32, &dyn Fn(u32) -> f64) -> bool;

/// Early stop ends a path once the most that its remaining segments could add
/// is under half an 8-bit step. Between two facing mirrors of reflection ρ the
/// centre ray bounces along the axis, every segment lit; the most that k
/// segments of weight 1 can add is B·(1 + ρ + … + ρᵏ⁻¹) with B = ka + kd + ks
/// (the light's colours are 1). The path ends after the first segment s whose
/// weight ρˢ⁺¹ times that for the segments left falls under the half step.
/// Returns that s for mirrors of `rho` and terms `terms` (ka, kd, ks) with
/// `segments` segments at most, after checking the render against it: the
/// centre pixel's bounces and rays, and its colour within an 8-bit level of
/// the whole path's. `variants` are rules a slip in the code would follow
/// (the bound computed otherwise); each must give another s, so that the
/// scene tells them from the rule.
fn early_stop_between_two_mirrors(
    rho: f64,
    terms: [f64; 3],
    segments: u32,
    variants: &[(&str, Ends)],
) -> u32 {
    let mirror = |z: i32| {
        format!(
            "[[sphere]]\ncenter = [0, 0, {z}]\nradius = 1\nreflection = {rho}\n\
             ambient = [{0}, {0}, {0}]\ndiffuse = [{1}, {1}, {1}]\nspecular = [{2}, {2}, {2}]\n",
            terms[0], terms[1], terms[2]
        )
    };
    let corridor = format!(
        "[image]\nwidth = 3\nheight = 3\n[camera]\nposition = [0, 0, 1]\n[render]\nmax_depth = {segments}\n\
         [light]\nposition = [0, 5, 1]\nambient = [1, 1, 1]\ndiffuse = [1, 1, 1]\nspecular = [1, 1, 1]\n{}{}",
        mirror(-3),
        mirror(5)
    );
    let scene = common::scene(&corridor);
    let most: f64 = terms.iter().sum();
    let reach = |k: u32| (0..k).map(|i| rho.powi(i as i32) * most).sum::<f64>();
    // The first s at which `ends(s, reach)` holds.
    let stop_with = |ends: Ends| (0..segments).find(|&s| ends(s, &reach)).unwrap();
    let stop = stop_with(&|s, reach| {
        rho.powi(s as i32 + 1) * reach(segments - s - 1) < raystep::render::HALF_STEP
    });
    for (what, variant) in variants {
        assert_ne!(
            stop_with(variant),
            stop,
            "{what} gives the rule's stop here"
        );
    }

    let render = |early_stop: bool| {
        let settings = Settings {
            early_stop,
            ..Settings::from(Stages::ALL)
        };
        *raystep::render::render(&scene, &settings, &|_| {}).at(1, 1)
    };
    let (stopped, whole) = (render(true), render(false));
    // Every segment hits a mirror head on and is lit: s + 1 segments, s
    // reflections, one shadow ray a segment, one primary ray.
    assert_eq!(stopped.depth, 3.0);
    assert_eq!(stopped.bounces, stop);
    assert_eq!(stopped.rays, 1 + stop + (stop + 1));
    assert_eq!(whole.bounces, segments - 1);
    assert_eq!(whole.rays, 1 + (segments - 1) + segments);
    // What the stop left out moves no channel by an 8-bit level.
    for k in 0..3 {
        assert!((stopped.colour[k] - whole.colour[k]).abs() < 1.0 / 255.0);
    }
    stop
}

/// With ρ = ½ and B = 1 over 10 segments the path ends at s = 8, one
/// reflection before the last, where counting one segment too many would give
/// s = 9.
#[test]
fn early_stop_ends_a_path_between_two_mirrors_at_the_segment_its_rule_gives() {
    let one_too_many = |s: u32, reach: &dyn Fn(u32) -> f64| {
        0.5f64.powi(s as i32 + 1) * reach(10 - s) < raystep::render::HALF_STEP
    };
    let stop = early_stop_between_two_mirrors(
        0.5,
        [0.25, 0.5, 0.25],
        10,
        &[("one segment too many", &one_too_many)],
    );
    assert_eq!(stop, 8);
}

/// With ρ = 0.2 and B = 0.1 + 0.5 + 0.4 = 1 over 12 segments, reach(k) =
/// 1.25·(1 − 0.2ᵏ): after segment 3 what is left is 0.2⁴·1.25 = 0.0020, just
/// over the half step 0.00196, and after segment 4 it is 0.0004, so the path
/// ends at s = 4. The scene tells the bound's parts apart: a half step a fifth
/// larger, or the specular term left out of B (0.6·1.25·0.0016 = 0.0012), would
/// stop it at 3; the segments left counted without ρ (B·k) at 5.
#[test]
fn early_stop_weighs_every_term_and_the_mirrors_reflection() {
    let (rho, segments) = (0.2f64, 12u32);
    let weight = |s: u32| rho.powi(s as i32 + 1);
    let left = |s: u32| segments - s - 1;
    let larger_step = |s: u32, reach: &dyn Fn(u32) -> f64| {
        weight(s) * reach(left(s)) < 1.2 * raystep::render::HALF_STEP
    };
    let no_specular = |s: u32, reach: &dyn Fn(u32) -> f64| {
        weight(s) * reach(left(s)) * 0.6 < raystep::render::HALF_STEP
    };
    let no_reflection = |s: u32, _: &dyn Fn(u32) -> f64| {
        weight(s) * f64::from(left(s)) < raystep::render::HALF_STEP
    };
    let stop = early_stop_between_two_mirrors(
        rho,
        [0.1, 0.5, 0.4],
        segments,
        &[
            ("a half step a fifth larger", &larger_step),
            ("B without ks", &no_specular),
            ("the segments left without ρ", &no_reflection),
        ],
    );
    assert_eq!(stop, 4);
}

/// The BVH only skips tests whose answer it knows: with it and without it the
/// records are the same, bit for bit, on a scene large enough that its tree is
/// built on several threads (20,000 spheres; the build goes parallel from 8,192),
/// in both precisions and with both engines.
#[test]
fn the_tree_of_a_large_scene_changes_no_pixel() {
    use raystep::accel::Accel;
    use raystep::real::Precision;
    use raystep::stages::Engine;
    let mut scene = raystep::tools::generate::scene(20_000, 7);
    (scene.width, scene.height) = (48, 27);
    for precision in [Precision::F64, Precision::F32] {
        let with = |accel, engine| Settings {
            accel,
            precision,
            engine,
            ..Settings::from(Stages::ALL)
        };
        let off = raystep::engine::render(&scene, &with(Accel::Off, Engine::Book), &|_| {});
        let hits = off.pixels.iter().filter(|p| p.is_hit()).count();
        assert!(
            hits > 48 * 27 / 2,
            "{hits} pixels see a sphere or the floor"
        );
        for engine in [Engine::Book, Engine::Fast] {
            let tree = raystep::engine::render(&scene, &with(Accel::Bvh, engine), &|_| {});
            assert_eq!(tree.engine, engine);
            assert_eq!(tree.pixels.len(), off.pixels.len());
            let apart = off.pixels.iter().zip(&tree.pixels).filter(|(a, b)| a != b);
            assert_eq!(apart.count(), 0, "{precision:?}, {engine:?}");
        }
    }
}

#[test]
fn a_partial_screen_follows_the_size_flags() {
    let text =
        "[camera]\nposition = [0, 0, 1]\n[light]\nposition = [5, 5, 5]\n[screen]\nleft = -1\n";
    let size = raystep::io::scene_file::Overrides {
        width: Some(100),
        height: Some(100),
        max_depth: None,
    };
    let scene = raystep::io::scene_file::parse_sized(text, "t", size).unwrap();
    let screen = scene.screen.unwrap();
    assert_eq!(
        (screen.left, screen.right, screen.top, screen.bottom),
        (-1.0, 1.0, 1.0, -1.0)
    );
}

#[test]
fn the_same_bytes_on_one_thread_and_on_four() {
    let scene = common::seed(120, 80);
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| common::render(&scene, Stages::ALL))
    };
    let (one, four) = (on(1), on(4));
    assert_eq!(one, four);
    // The files too, each encoded inside its own pool (the EXR encoder and the PNGs
    // run in parallel).
    let files = |threads: usize, frame: &raystep::aov::Frame| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut bytes: Vec<Vec<u8>> = frame.buffers().map(|b| png_bytes(frame, b)).collect();
            bytes.push(exr_bytes(frame).unwrap());
            bytes
        })
    };
    assert_eq!(files(1, &one), files(4, &four));
}

/// The files of a render are written in one pass, a window of scan lines at a
/// time (the EXR's blocks and every picture's rows, the PNGs streamed): each PNG
/// holds the picture `visualise` draws and the EXR the bytes `exr_bytes_as`
/// gives, in one-line blocks (no compression) and 16-line ones (ZIP), over
/// several windows (300 lines at 130 wide is two), and every file's bytes are the
/// same on one thread and on three. The rows written are told as each window is
/// done (the progress bar's second half): every row once, in more than one step.
#[test]
fn the_files_written_hold_the_pictures_and_the_exr_on_any_thread_count() {
    use raystep::io::output::{exr_bytes_as, visualise, ExrCompression, Pending};
    let frame = common::render(&common::seed(130, 300), Stages::ALL);
    for compression in [ExrCompression::None, ExrCompression::Zip] {
        let write = |threads: usize| {
            let dir = tempfile::tempdir().unwrap();
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut pending = Pending::new().with_exr(compression);
                pending.folder(dir.path()).unwrap();
                let told = std::sync::Mutex::new(Vec::new());
                let paths = pending
                    .frame_counted(&frame, dir.path(), &|n| told.lock().unwrap().push(n))
                    .unwrap();
                let told: Vec<u64> = told.into_inner().unwrap();
                assert_eq!(told.iter().sum::<u64>(), 300, "{told:?}");
                assert!(told.iter().filter(|&&n| n > 0).count() >= 2, "{told:?}");
                pending.commit().unwrap();
                paths
                    .iter()
                    .map(|p| (p.clone(), std::fs::read(p).unwrap()))
                    .collect::<Vec<_>>()
            })
        };
        let (one, three) = (write(1), write(3));
        let bytes = |files: &[(std::path::PathBuf, Vec<u8>)]| {
            files.iter().map(|(_, b)| b.clone()).collect::<Vec<_>>()
        };
        assert_eq!(bytes(&one), bytes(&three), "{compression:?}");
        let (exr, pngs) = one.split_last().unwrap();
        assert!(exr.0.ends_with("buffers.exr"));
        assert!(
            exr.1 == exr_bytes_as(&frame, compression).unwrap(),
            "{compression:?}: buffers.exr differs from exr_bytes_as"
        );
        assert_eq!(pngs.len(), frame.buffers().count());
        for ((path, png), buffer) in pngs.iter().zip(frame.buffers()) {
            assert!(path.ends_with(format!("{}.png", buffer.name())));
            let decoded = image::load_from_memory(png).unwrap().to_rgb8();
            assert_eq!(decoded.dimensions(), (130, 300));
            assert!(
                decoded.into_raw() == visualise(&frame, buffer),
                "{}: the file's pixels differ from visualise",
                buffer.name()
            );
        }
    }
}
