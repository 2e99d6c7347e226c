//! Where methods fail, and the defaults that do not: every stress case asserts the
//! failure of the tutorial's choices (measured, so that a test notices if it stops
//! failing) and the success of raystep's defaults (float64, stable, auto offset).

mod common;

use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use raystep::real::{Precision, Real};
use raystep::render::{render, Settings};
use raystep::scene::{Object, Shape};
use raystep::shade::shadow::{step_off, Offset};
use raystep::sphere::Method;
use raystep::stages::Stages;
use raystep::tools::accuracy::{case, measure, Measure, CASES};
use raystep::Vec3;

use Method::{Naive, Stable};
use Precision::{F32, F64};

fn run(name: &str, precision: Precision, method: Method, offset: Offset) -> Measure {
    measure(name, &case(name).unwrap(), precision, method, offset)
}

const TUTORIAL: Offset = Offset::TUTORIAL;
const AUTO: Offset = Offset::Auto;

/// The largest distance of a hit point from its surface that the defaults may
/// leave, in unit roundoffs of the surface's size (measured: at most 6.2).
const SURFACE_BOUND: f64 = 8.0;

/// The defaults get every case right: hit or miss as the reference says (outside
/// 1e-9 of a radius from a silhouette), hit points within [`SURFACE_BOUND`] unit
/// roundoffs of the surface's size, every stepped-off origin outside its surface,
/// every shadow verdict the reference's (away from the terminator).
#[test]
fn the_defaults_pass_every_stress_case() {
    assert_eq!(Settings::from(Stages::ALL).precision, F64);
    assert_eq!(Settings::from(Stages::ALL).method, Stable);
    assert_eq!(Settings::from(Stages::ALL).offset, AUTO);
    for (name, _) in CASES {
        let m = run(name, F64, Stable, AUTO);
        assert!(
            m.judged > m.pixels / 2,
            "{name}: judged {} of {}",
            m.judged,
            m.pixels
        );
        assert_eq!((m.false_hits, m.false_misses), (0, 0), "{name}");
        // (camera-far's primary rays travel 1e6 to a sphere of size 1: its hit
        // points are a few u of that distance off, millions of u of the sphere's
        // size, as for any method.)
        if *name != "camera-far" {
            assert!(m.max_surface_error_ulps <= SURFACE_BOUND, "{name}: {m:?}");
        }
        assert_eq!(m.stuck, 0.0, "{name}");
        assert_eq!(m.wrong_shadow, 0.0, "{name}");
    }
}

const SCENE: Offset = Offset::Scene;

/// float32 with the stable method and the `auto` offset: no false hit or miss
/// outside float32's silhouette band (8·u·(‖O‖ + ‖C‖ + r + t)), no origin stuck,
/// and no wrong shadow outside the terminator band on any case, those float32
/// warns about or refuses included. The band is 1e-3, or where it is wider the
/// one the bound's own step makes: √(2h/r + 8u), with h the height of that
/// step's origin above the sphere (`terminator_band`), which in float32 is
/// wider than 1e-3 on most spheres. But `auto` asks no shadow ray on a sphere's
/// own dark side (`own_shadow`: the sign of N·L), so on every case float32
/// renders without a warning not one shadow is wrong outside 1e-3 itself
/// (`wrong_shadows_1e3`).
#[test]
fn float32_with_the_bound_passes_every_case_within_its_bands() {
    let mut plain = 0;
    for (name, _) in CASES {
        let m = run(name, F32, Stable, AUTO);
        assert_eq!((m.false_hits, m.false_misses), (0, 0), "{name}: {m:?}");
        assert_eq!(m.stuck, 0.0, "{name}");
        assert_eq!(m.wrong_shadows, 0, "{name}: {m:?}");
        if m.limit == "ok" {
            assert_eq!(m.wrong_shadows_1e3, 0, "{name}: {m:?}");
            plain += 1;
        }
    }
    assert!(
        plain >= 12,
        "only {plain} cases render in float32 without a warning"
    );
    // The floor's dark side lit from near its horizon, where a shadow ray from the
    // step (3.8e-3 above the floor) would pass over its horizon up to
    // |L·N| = √(2h/r) ≈ 1e-3: the sign of N·L decides it.
    let floor = run("horizon-low-light", F32, Stable, AUTO);
    assert_eq!(floor.wrong_shadows_1e3, 0, "{floor:?}");
    // float64's band is 1e-3 itself: nothing between.
    let floor = run("horizon-low-light", F64, Stable, AUTO);
    assert_eq!(floor.wrong_shadows_1e3, 0, "{floor:?}");
}

/// The scene-sized offset (raystep's `auto` before the bound): its failures in
/// float32, measured, where the bound has none. On the tiny far sphere it steps
/// shadow rays 0.4 of a radius out, and the dark side reads lit up to
/// |L·N| = 0.7; on the fake floor lit from near its horizon, 8.6e-3 above the
/// floor against the bound's 3.8e-3, shadowed points read lit past the band
/// the bound's step makes (the case).
#[test]
fn the_scene_sized_offset_fails_in_float32_where_the_bound_does_not() {
    let tiny = run("tiny-far", F32, Stable, SCENE);
    assert!(tiny.wrong_shadow > 0.03, "{tiny:?}");
    assert!(tiny.worst_facing > 0.5, "{tiny:?}");
    assert_eq!(run("tiny-far", F32, Stable, AUTO).wrong_shadows, 0);
    // Measured: 3,840 (5,920 outside 1e-3), against 0 (0).
    let floor = run("horizon-low-light", F32, Stable, SCENE);
    assert!(floor.wrong_shadows > 1000, "{floor:?}");
    assert!(floor.worst_facing > 1.3e-3, "{floor:?}");
    let floor = run("horizon-low-light", F32, Stable, AUTO);
    assert_eq!(floor.wrong_shadows, 0, "{floor:?}");
    let mut failing = 0;
    for (name, _) in CASES {
        let scene = run(name, F32, Stable, SCENE);
        let auto = run(name, F32, Stable, AUTO);
        assert!(
            auto.wrong_shadows <= scene.wrong_shadows,
            "{name}: auto {auto:?}, scene {scene:?}"
        );
        failing += usize::from(scene.wrong_shadows > 0 && auto.wrong_shadows == 0);
    }
    // far-sphere, tiny-sphere, seed-x1, ×1000, ×1e4, ×0.001, ×1e-4, contact,
    // tiny-far, graze-row, horizon-low-light, the seed moved 9e4 and 1e5,
    // camera-far, touching, plane-far.
    assert!(failing >= 14, "{failing}");
}

/// The seed scene moved to (1e5, 1e5, 1e5), camera and light too: accepted,
/// rendered in float64 without an error, and the same picture as the seed at
/// ×1 (hit or miss and shadow in every pixel) but for pixels within the bands.
/// float32 is refused, with float64 named as the way out.
#[test]
fn float64_renders_the_seed_moved_1e5_away_as_it_renders_the_seed() {
    let moved = case("seed-moved-1e5").unwrap();
    let m = run("seed-moved-1e5", F64, Stable, AUTO);
    assert_eq!((m.false_hits, m.false_misses, m.wrong_shadows), (0, 0, 0));
    let error = raystep::io::scene_file::check_precision(&moved, F32).unwrap_err();
    assert!(error.contains("float64"), "{error}");
    assert!(raystep::io::scene_file::check_precision(&moved, F64).is_ok());
    let masks = |name: &str| {
        let frame = render(&case(name).unwrap(), &Settings::from(Stages::ALL), &|_| {});
        frame.pixels.iter().map(|p| p.shadow).collect::<Vec<f32>>()
    };
    let (one, far) = (masks("seed-x1"), masks("seed-moved-1e5"));
    assert!(!one.is_empty() && one.len() == far.len());
    let differ = one.iter().zip(&far).filter(|(a, b)| a != b).count();
    // Measured: the pixels whose rays pass within a few 1e-11 of a silhouette.
    assert!(differ <= 5, "{differ} of {} pixels differ", one.len());
}

/// float32 refuses, or warns, only when it is asked for.
#[test]
fn the_limits_depend_on_the_precision() {
    use raystep::io::scene_file::check_precision;
    for name in ["camera-far", "light-above", "seed-moved-1e5"] {
        let scene = case(name).unwrap();
        assert!(check_precision(&scene, F64).unwrap().is_empty(), "{name}");
        let error = check_precision(&scene, F32).unwrap_err();
        assert!(error.contains("float64"), "{name}: {error}");
    }
    for name in ["tiny-far", "far-sphere", "twins", "seed-moved-9e4"] {
        let warnings = check_precision(&case(name).unwrap(), F32).unwrap();
        assert!(!warnings.is_empty(), "{name}");
        assert!(
            warnings.iter().all(|w| w.contains("float64")),
            "{name}: {warnings:?}"
        );
    }
    for name in [
        "seed-x1",
        "seed-x10000",
        "seed-x0.0001",
        "horizon",
        "contact",
    ] {
        assert_eq!(
            check_precision(&case(name).unwrap(), F32),
            Ok(vec![]),
            "{name}"
        );
    }
}

#[test]
fn far_and_tiny_spheres_vanish_with_the_textbook_quadratic_in_float32() {
    for name in ["far-sphere", "tiny-sphere"] {
        let naive = run(name, F32, Naive, AUTO);
        assert_eq!(
            naive.false_misses, naive.reference_hits,
            "{name}: every pixel of the sphere is missed"
        );
        assert!(naive.false_misses > 5000, "{name}: {naive:?}");
        let stable = run(name, F32, Stable, AUTO);
        assert_eq!(
            (stable.false_hits, stable.false_misses),
            (0, 0),
            "{name}: {stable:?}"
        );
        // In float64 the textbook quadratic still sees the sphere, but its hit
        // points are thousands of times farther off the surface.
        let naive64 = run(name, F64, Naive, AUTO);
        let stable64 = run(name, F64, Stable, AUTO);
        assert_eq!(naive64.false_misses, 0, "{name}");
        assert!(
            naive64.max_surface_error > 1000.0 * stable64.max_surface_error,
            "{name}"
        );
    }
}

#[test]
fn grazing_rays_hit_where_they_miss_with_the_textbook_quadratic_in_float32() {
    // Every ray of this scene passes within float32's own silhouette band, so
    // the textbook quadratic's false hits are counted with float64's band.
    let naive = run("graze", F32, Naive, AUTO);
    assert!(naive.strict_false.0 > 1000, "{naive:?}");
    assert_eq!(naive.false_hits, 0, "{naive:?}");
    let stable = run("graze", F32, Stable, AUTO);
    assert_eq!(
        (stable.false_hits, stable.false_misses),
        (0, 0),
        "{stable:?}"
    );
}

#[test]
fn the_fixed_step_is_too_small_for_the_fake_floor_in_float32() {
    // Hit points on the fake floor land tens of times the tutorial's 1e-5 step off
    // its surface in float32 (a bias from rounding c = ‖f‖² − r², shared by every
    // ray from the camera); where the bias points inwards, origins stay inside.
    for name in ["horizon", "seed-x1"] {
        let tutorial = run(name, F32, Stable, TUTORIAL);
        assert!(
            tutorial.max_surface_error > 20.0 * 1e-5,
            "{name}: {tutorial:?}"
        );
    }
    assert!(run("horizon", F32, Stable, TUTORIAL).stuck > 0.001);
    assert_eq!(run("horizon", F32, Stable, AUTO).stuck, 0.0);
    // A true plane in the same view is computed from small numbers: a thousand times
    // closer in float32.
    let fake = run("horizon", F32, Stable, AUTO).max_surface_error;
    let real = run("horizon-true", F32, Stable, AUTO).max_surface_error;
    assert!(real * 1000.0 < fake, "true {real}, fake {fake}");
}

#[test]
fn a_true_plane_gets_classic_acne_without_a_step() {
    // A plane has no "both roots positive" rule to hide behind: a shadow ray from a
    // point just behind it meets it, and the lit side is speckled with shadow.
    for precision in [F32, F64] {
        let none = run("horizon-true", precision, Stable, Offset::Fixed(0.0));
        assert!(none.wrong_shadow > 0.01, "{none:?}");
        assert_eq!(
            run("horizon-true", precision, Stable, AUTO).wrong_shadow,
            0.0
        );
    }
}

#[test]
fn the_fixed_step_is_right_at_one_scale_only() {
    // ×1000 in float32: the step is far below the rounding error, origins stay inside.
    let big = run("seed-x1000", F32, Naive, TUTORIAL);
    assert!(big.stuck > 0.1, "{big:?}");
    // ×0.001, or a tiny sphere: the step is a sizeable part of the scene, and shadow
    // rays start beyond what should shadow them.
    for name in ["seed-x0.001", "tiny-sphere"] {
        let small = run(name, F64, Naive, TUTORIAL);
        assert!(small.wrong_shadow > 0.01, "{name}: {small:?}");
        assert_eq!(small.stuck, 0.0, "{name}");
    }
    // The auto offset is right at all three.
    for name in ["seed-x1", "seed-x1000", "seed-x0.001"] {
        assert_eq!(run(name, F64, Stable, AUTO).wrong_shadow, 0.0, "{name}");
    }
}

#[test]
fn without_a_step_origins_sit_inside_half_the_time() {
    for name in ["seed-x1", "contact", "far-sphere"] {
        let none = run(name, F64, Stable, Offset::Fixed(0.0));
        assert!(none.stuck > 0.3, "{name}: {none:?}");
        assert!(none.wrong_shadow > 0.01, "{name}: {none:?}");
    }
}

#[test]
fn the_same_shadow_mask_at_every_scale_with_the_defaults() {
    let mask = |name: &str, offset: Offset| {
        let settings = Settings {
            offset,
            ..Settings::from(Stages::ALL)
        };
        let frame = render(&case(name).unwrap(), &settings, &|_| {});
        frame.pixels.iter().map(|p| p.shadow).collect::<Vec<f32>>()
    };
    let differ = |a: &[f32], b: &[f32]| {
        assert_eq!(a.len(), b.len());
        a.iter().zip(b).filter(|(x, y)| x != y).count()
    };
    let one = mask("seed-x1", AUTO);
    // Every scaled copy of figure 1 the stress cases hold, ×1e-4 to ×1e4.
    let mut scales = 0;
    for (name, _) in CASES {
        if name.starts_with("seed-x") && *name != "seed-x1" {
            assert_eq!(differ(&one, &mask(name, AUTO)), 0, "{name}");
            scales += 1;
        }
    }
    assert_eq!(scales, 4, "×1e-4, ×1e-3, ×1e3 and ×1e4");
    // The tutorial's step changes the mask at ×0.001.
    let tutorial_one = mask("seed-x1", TUTORIAL);
    assert!(differ(&tutorial_one, &mask("seed-x0.001", TUTORIAL)) > 50);
}

/// The contact scene's two spheres, and a point on the large one at horizontal
/// distance `x` from the point under the small one's centre.
fn contact_probe(x: f64) -> (Vec<Object>, Vec3, Vec3) {
    let scene = case("contact").unwrap();
    let objects: Vec<Object> = scene.objects_in_play(Stages::ALL);
    let Shape::Sphere(big) = objects[0].shape else {
        panic!()
    };
    let normal = Vec3::new(x, (big.radius * big.radius - x * x).sqrt(), 0.0) / big.radius;
    (objects, big.center + normal * big.radius, normal)
}

#[test]
fn the_contact_shadow_is_whole_with_the_auto_offset_and_holed_with_the_fixed_step() {
    let scene = case("contact").unwrap();
    let light = scene.light.position;
    let shadowed = |x: f64, offset: Offset| {
        let (objects, p, n) = contact_probe(x);
        let shifted = step_off(p, n, &objects[0], offset);
        let to_light = (light - shifted).normalize();
        raystep::shade::shadow::in_shadow(&objects, shifted, to_light, light.distance(p), Stable)
    };
    // Under the small sphere (radius 0.002), up to 1.5e-3 from the contact point.
    let probes: Vec<f64> = (0..=30).map(|i| i as f64 * 5e-5).collect();
    assert!(
        probes.iter().all(|&x| shadowed(x, AUTO)),
        "auto: a hole in the contact shadow"
    );
    let holes = probes.iter().filter(|&&x| !shadowed(x, TUTORIAL)).count();
    // The gap is 1e-7 + about 300·x²: below the 1e-5 step for x < 1.8e-4.
    assert_eq!(
        holes, 4,
        "fixed:1e-5 lights the probes at x = 0, 5e-5, 1e-4, 1.5e-4"
    );
}

/// `pixels` is the image's size and `judged` the rays outside the silhouette
/// band. On `graze` every ray passes within a millionth of the sphere's
/// silhouette: inside float32's band (8·u·(‖O‖ + ‖C‖ + r + t) ≈ 4e-6), so float32
/// judges none of them, and outside float64's (1e-9 of the radius; neighbouring
/// rays are some 5e-8 apart there), so float64 judges them all.
#[test]
fn pixels_and_judged_count_the_image_and_the_rays_outside_the_band() {
    let scene = case("graze").unwrap();
    let pixels = (scene.width * scene.height) as usize;
    assert_eq!(pixels, 160 * 120);
    for method in [Naive, Stable] {
        let f32 = run("graze", F32, method, AUTO);
        assert_eq!((f32.pixels, f32.judged, f32.reference_hits), (pixels, 0, 0));
        let f64 = run("graze", F64, method, AUTO);
        assert_eq!((f64.pixels, f64.judged), (pixels, pixels), "{f64:?}");
        assert!(f64.reference_hits > 0 && f64.reference_hits < pixels);
    }
    for (name, _) in CASES {
        let scene = case(name).unwrap();
        let m = run(name, F64, Stable, AUTO);
        assert_eq!(m.pixels, (scene.width * scene.height) as usize, "{name}");
        assert!(
            m.reference_hits <= m.judged && m.judged <= m.pixels,
            "{m:?}"
        );
    }
}

/// far-sphere with a wall behind it: every primary ray hits something, so a pixel
/// where float32's textbook quadratic loses the sphere sees the wall instead,
/// the wrong object, which counts as a false hit (the wall) and a false miss
/// (the sphere), with either band.
#[test]
fn the_wrong_object_counts_as_a_false_hit_and_a_false_miss() {
    let toml = "[image]\nwidth = 160\nheight = 120\n[camera]\nposition = [0, 0, 1]\n\
                [screen]\nleft = -0.0003\nright = 0.0003\ntop = 0.000225\nbottom = -0.000225\n\
                [light]\nposition = [2000, 2000, -3000]\n\
                [[sphere]]\ncenter = [0, 0, -5000]\nradius = 1\n\
                [[plane]]\npoint = [0, 0, -6000]\nnormal = [0, 0, 1]\n";
    let scene = raystep::io::scene_file::parse(toml, "far-sphere-wall").unwrap();
    let naive = measure("far-sphere-wall", &scene, F32, Naive, AUTO);
    assert_eq!(
        naive.reference_hits, naive.judged,
        "every ray hits: {naive:?}"
    );
    assert!(naive.false_hits > 5000, "{naive:?}");
    assert_eq!(naive.false_hits, naive.false_misses, "{naive:?}");
    assert!(naive.strict_false.0 >= naive.false_hits, "{naive:?}");
    assert_eq!(naive.strict_false.0, naive.strict_false.1, "{naive:?}");
    let stable = measure("far-sphere-wall", &scene, F64, Stable, AUTO);
    assert_eq!(stable.reference_hits, stable.pixels, "{stable:?}");
    assert_eq!((stable.false_hits, stable.false_misses), (0, 0));
}

/// `raystep accuracy --json` reports each row's figures under their own names:
/// far-sphere's float32 textbook rows miss every pixel of the sphere (false
/// misses, no false hits), and every count is the library's.
#[test]
fn the_json_rows_carry_each_figure_under_its_own_name() {
    let dir = std::env::temp_dir();
    let out = common::raystep(&dir, &["accuracy", "--case", "far-sphere", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    let measured = raystep::tools::accuracy::measure_case("far-sphere");
    assert_eq!(rows.len(), measured.len());
    for (row, m) in rows.iter().zip(&measured) {
        assert_eq!(row["method"], m.method.as_str(), "{row}");
        assert_eq!(row["precision"], m.precision.as_str(), "{row}");
        assert_eq!(row["offset"], m.offset.as_str(), "{row}");
        for (field, value) in [
            ("pixels", m.pixels),
            ("judged", m.judged),
            ("reference_hits", m.reference_hits),
            ("false_hits", m.false_hits),
            ("false_misses", m.false_misses),
            ("wrong_shadows", m.wrong_shadows),
            ("wrong_shadows_1e3", m.wrong_shadows_1e3),
        ] {
            assert_eq!(row[field], value, "{field}: {row}");
        }
        assert_eq!(
            row["strict_false"],
            serde_json::json!([m.strict_false.0, m.strict_false.1])
        );
        if (row["precision"].as_str(), row["method"].as_str()) == (Some("f32"), Some("naive")) {
            assert_eq!(row["false_hits"], 0, "{row}");
            assert_eq!(row["false_misses"], row["reference_hits"], "{row}");
            assert!(row["false_misses"].as_u64().unwrap() > 5000, "{row}");
        }
    }
}

// ---- Property tests: random spheres and rays at scales from 1e-3 to 1e4 ----

/// The book's `step_off` with the `auto` offset, as the render moves a hit point.
fn auto_step<T: Real>(point: T::Vec3, normal: T::Vec3, surface: &Object<T>) -> T::Vec3 {
    step_off(point, normal, surface, AUTO)
}

fn scale() -> impl Strategy<Value = f64> {
    (-3.0f64..4.0).prop_map(|e| 10f64.powf(e))
}

fn unit() -> impl Strategy<Value = Vec3> {
    (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("RAYSTEP_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(2000)
    ))]

    #[test]
    fn a_stepped_off_origin_is_outside_its_sphere_at_any_scale(
        s in scale(), offset_far in 0.0f64..4.0, c in unit(), from in unit(), jitter in unit(),
        size in 0.001f64..1.0,
    ) {
        // A sphere of radius s·size up to s·1e4 from the origin, hit from outside.
        let center = c * s * 10f64.powf(offset_far);
        let radius = s * size;
        let dir = if from.length() < 1e-3 { Vec3::X } else { from.normalize() };
        let origin = center + dir * radius * (1.5 + 100.0 * jitter.x.abs());
        let aim = center + jitter * radius * 0.5; // |jitter| ≤ √3, so inside
        // In float64 the ray aimed inside always hits; in float32 the aim point
        // itself may round outside a small far sphere, so a miss is allowed there.
        let f64_result = common::sphere_recast::<f64>(center, radius, origin, aim, auto_step);
        prop_assert!(f64_result.is_some(), "f64: a ray aimed inside the sphere misses it");
        for (precision, result) in [("f64", f64_result), ("f32", common::sphere_recast::<f32>(center, radius, origin, aim, auto_step))] {
            if let Some((outside, into)) = result {
                prop_assert!(outside, "{precision}: stepped-off origin not outside");
                prop_assert!(into, "{precision}: a ray into the surface misses it");
            }
        }
    }

    #[test]
    fn a_ray_leaving_a_plane_never_meets_it_again_at_any_scale(
        s in scale(), far in 0.0f64..4.0, p in unit(), n in unit(), from in unit(), aim in unit(), out in unit(),
    ) {
        // A plane through a point up to s·1e4 from the origin, hit from a point on
        // one side, aimed at a point near its anchor.
        prop_assume!(n.length() > 0.1 && out.length() > 0.1);
        let normal = n.normalize();
        let point = p * s * 10f64.powf(far);
        let side = if from.dot(normal) >= 0.0 { 1.0 } else { -1.0 };
        let origin = point + normal * side * s * (0.1 + from.length()) + (from - normal * from.dot(normal)) * s;
        let target = point + (aim - normal * aim.dot(normal)) * s;
        // The origin is off the plane and the target on it: in float64 the ray
        // always hits (as for the sphere above, float32 may round the target off).
        let f64_result = common::plane_recast::<f64>(point, normal, origin, target, out, auto_step);
        prop_assert!(f64_result.is_some(), "f64: a ray aimed at the plane misses it");
        for (precision, result) in [
            ("f64", f64_result),
            ("f32", common::plane_recast::<f32>(point, normal, origin, target, out, auto_step)),
        ] {
            if let Some((misses, meets)) = result {
                prop_assert!(misses, "{precision}: a ray leaving the plane meets it again");
                prop_assert!(meets, "{precision}: a ray through the plane misses it");
            }
        }
    }

    #[test]
    fn no_nan_or_infinity_reaches_a_pixel(
        s in scale(), spheres in prop::collection::vec((unit(), 0.01f64..1.0), 1..4),
        camera in unit(), light in unit(), place in 0usize..4, light_inside in any::<bool>(),
        f32_precision in any::<bool>(), naive in any::<bool>(), offset in 0usize..3,
    ) {
        // Sphere k sits at (c·s) shifted by −s in z, with radius r·s.
        let centers: Vec<Vec3> = spheres.iter().map(|(c, _)| Vec3::new(c.x * s, c.y * s, c.z * s - s)).collect();
        let (c0, r0) = (centers[0], spheres[0].1 * s);
        // The camera: anywhere, at the centre of sphere 0, or inside it.
        let cam = match place {
            0 | 1 => camera * s * 3.0,
            2 => c0,
            _ => c0 + camera.normalize_or_zero() * r0 * 0.5,
        };
        let cam = if cam.z == 0.0 { Vec3::new(cam.x, cam.y, s) } else { cam };
        let light = if light_inside { c0 + light * r0 * 0.5 } else { light * s * 3.0 };
        let mut toml = String::new();
        // The loader refuses a camera or a light inside a sphere, so they are put
        // in place after it: the renderer must stay finite for a scene built in
        // code, too.
        toml += &format!("[image]\nwidth = 8\nheight = 6\n[camera]\nposition = [0, 0, {}]\n", 10.0 * s);
        toml += &format!("[light]\nposition = [0, {}, 0]\n", 10.0 * s);
        for (c, (_, r)) in centers.iter().zip(&spheres) {
            toml += &format!("[[sphere]]\ncenter = [{}, {}, {}]\nradius = {}\n", c.x, c.y, c.z, r * s);
        }
        toml += &format!("[[plane]]\npoint = [0, {}, 0]\nnormal = [0, 1, 0]\n", -s);
        let mut scene = raystep::io::scene_file::parse(&toml, "generated").unwrap();
        (scene.camera, scene.light.position) = (cam, light);
        let settings = Settings {
            precision: if f32_precision { F32 } else { F64 },
            method: if naive { Naive } else { Stable },
            offset: [AUTO, TUTORIAL, Offset::Fixed(0.0)][offset],
            ..Settings::from(Stages::ALL)
        };
        let frame = render(&scene, &settings, &|_| {});
        for p in &frame.pixels {
            check_pixel(p)?;
        }
        for (row, col) in [(0, 0), (frame.height - 1, frame.width - 1)] {
            let d = frame.direction(row, col);
            prop_assert!(d.iter().all(|c| c.is_finite()), "{:?}", d);
        }
    }
}

/// A pixel has no NaN or infinity anywhere, and its buffers agree on hit or miss.
fn check_pixel(p: &raystep::aov::PixelRecord) -> Result<(), TestCaseError> {
    prop_assert!(
        p.colour
            .iter()
            .all(|c| c.is_finite() && (0.0..=1.0).contains(c)),
        "{:?}",
        p
    );
    prop_assert!(p.normal.iter().all(|c| c.is_finite()), "{:?}", p);
    if p.shadow == -1.0 {
        prop_assert!(
            p.depth == f32::INFINITY && p.normal == [0.0; 3],
            "a miss: {:?}",
            p
        );
    } else {
        // (A distance below float32's smallest number is stored as 0.)
        prop_assert!(
            p.depth.is_finite() && p.depth >= 0.0,
            "a hit needs a finite depth: {:?}",
            p
        );
    }
    Ok(())
}

#[test]
fn tangent_rays_and_a_light_inside_a_sphere_give_finite_pixels() {
    // A pixel whose ray touches the sphere exactly (Δ = 0): the 3 × 3 image's middle
    // column looks at x = 0, and the sphere's left edge is at x = 0 on that plane.
    let toml = "[image]\nwidth = 3\nheight = 3\n[camera]\nposition = [0, 0, 1]\n\
                [light]\nposition = [5, 5, 5]\n[[sphere]]\ncenter = [1, 0, -2]\nradius = 1\n\
                [[plane]]\npoint = [0, -1, 0]\nnormal = [0, 1, 0]\n";
    let mut scene = raystep::io::scene_file::parse(toml, "tangent").unwrap();
    // At the sphere's centre: the loader refuses that, a scene built in code need not.
    scene.light.position = raystep::Vec3::new(1.0, 0.0, -2.0);
    for precision in [F32, F64] {
        for method in [Naive, Stable] {
            let settings = Settings {
                precision,
                method,
                ..Settings::from(Stages::ALL)
            };
            let frame = render(&scene, &settings, &|_| {});
            for p in &frame.pixels {
                check_pixel(p).unwrap();
            }
        }
    }
}

#[test]
fn a_too_small_height_above_a_plane_is_not_a_nan() {
    // A camera 1e-310 above a true plane: t overflows to infinity for nearly parallel
    // rays; the plane must count as missed, not give an infinite hit point.
    let toml = "[image]\nwidth = 8\nheight = 6\n[camera]\nposition = [0, 1e-310, 1]\n\
                [light]\nposition = [0, 5, 0]\n[[plane]]\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\n";
    let scene = raystep::io::scene_file::parse(toml, "low").unwrap();
    for precision in [F32, F64] {
        let settings = Settings {
            precision,
            ..Settings::from(Stages::ALL)
        };
        for p in &render(&scene, &settings, &|_| {}).pixels {
            check_pixel(p).unwrap();
        }
    }
}
