//! Renders with answers known in advance, in the style of pbrt's tests: analytic
//! depths, unit normals, a point behind an occluder, rays re-cast from a hit point,
//! `--without` equal to the stage before, and the same bytes on any thread count.

mod common;

use raystep::output::{exr_bytes, png_bytes};
use raystep::ray::Ray;
use raystep::render::Settings;
use raystep::render::Tracer;
use raystep::shade::reflection::reflect;
use raystep::shade::shadow::step_off;
use raystep::stages::{Stage, Stages};
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
            let traced = tracer.trace(ray);
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
fn the_exr_holds_the_exact_depth_of_a_pixel() {
    let frame = common::render(&common::scene(ONE_SPHERE), Stages::ALL);
    let dir = tempfile::tempdir().unwrap();
    raystep::output::write_frame(&frame, dir.path()).unwrap();
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
    assert_eq!(at("shadow", 2, 2), 1.0);
    assert_eq!(at("shadow", 0, 0), -1.0);
    assert!((at("R", 2, 2) - 0.85).abs() < 1e-6);
    assert_eq!(at("dir.Z", 2, 2), -1.0);
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

/// A floor sphere, an occluder above its top, the light above both.
fn occluder_scene(occluder_x: f64) -> raystep::scene::Scene {
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
        center = [{occluder_x}, 2, -2]
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
    let blocked = Tracer::<f64>::new(&occluder_scene(0.0), &Stages::ALL.into()).trace(down);
    let hit = blocked.first.unwrap();
    assert_eq!(hit.depth, 1.0);
    assert!(!hit.lit);
    assert_eq!(blocked.colour, Vec3::ZERO);

    // The same point with the occluder moved aside is lit.
    let open = Tracer::<f64>::new(&occluder_scene(3.0), &Stages::ALL.into()).trace(down);
    assert!(open.first.unwrap().lit);
    assert!(open.colour.max_element() > 0.5);

    // Without the shadow stage no shadow ray is cast: the point reads lit.
    let no_shadow = Stages::select(Stage::Plane, &[Stage::Shadow]).unwrap();
    assert!(
        Tracer::<f64>::new(&occluder_scene(0.0), &no_shadow.into())
            .trace(down)
            .first
            .unwrap()
            .lit
    );
}

#[test]
fn a_ray_recast_from_a_stepped_off_hit_point_does_not_hit_its_own_surface() {
    // With the tutorial's settings and with raystep's defaults: a ray that leaves
    // the surface (reflected, or towards a light in front of it) never meets it.
    let scene = common::seed(150, 100);
    for settings in [Settings::tutorial(Stages::ALL), Settings::from(Stages::ALL)] {
        let tracer = Tracer::<f64>::new(&scene, &settings);
        let mut checked = 0;
        for row in 0..scene.height {
            for col in 0..scene.width {
                let ray = tracer.camera.primary_ray::<f64>(row, col);
                let Some(hit) = tracer.trace(ray).first else {
                    continue;
                };
                let object = &tracer.objects[hit.object];
                let point = ray.at(hit.depth);
                let shifted = step_off(point, hit.normal, object, settings.offset);
                let to_light = (scene.light.position - shifted).normalize();
                let mut directions = vec![reflect::<f64>(ray.direction, hit.normal)];
                if to_light.dot(hit.normal) > 0.0 {
                    directions.push(to_light);
                }
                for direction in directions {
                    let again = object.intersect(
                        &Ray {
                            origin: shifted,
                            direction,
                        },
                        settings.method,
                    );
                    assert_eq!(
                        again, None,
                        "{settings:?}: pixel {row},{col} hits its own surface again"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 10_000, "{checked}");
    }
}

#[test]
fn turning_the_last_stage_off_gives_the_stage_before() {
    let scene = common::seed(60, 40);
    for pair in Stage::ALL.windows(2) {
        let (before, last) = (pair[0], pair[1]);
        let without = Stages::select(last, &[last]).unwrap();
        assert_eq!(without, Stages::up_to(before));
        assert_eq!(
            common::render(&scene, without),
            common::render(&scene, Stages::up_to(before)),
            "--stage {last} --without {last}"
        );
    }
}

#[test]
fn without_shadow_nothing_is_black_that_blinn_phong_lights() {
    // Blinn-Phong with the shadow stage off: every hit gets at least its ambient.
    let stages = Stages::select(Stage::Plane, &[Stage::Shadow]).unwrap();
    let frame = common::render(&common::seed(60, 40), stages);
    for p in frame.pixels.iter().filter(|p| p.is_hit()) {
        assert_eq!(p.shadow, 1.0);
        assert!(p.colour.iter().sum::<f32>() > 0.0);
    }
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
    for buffer in one.buffers() {
        assert_eq!(png_bytes(&one, buffer), png_bytes(&four, buffer));
    }
    assert_eq!(exr_bytes(&one).unwrap(), exr_bytes(&four).unwrap());
}
