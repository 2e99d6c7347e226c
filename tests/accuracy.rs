//! Where methods fail, and the defaults that do not: every stress case asserts the
//! failure of the tutorial's choices (measured, so that a test notices if it stops
//! failing) and the success of raystep's defaults (float64, stable, auto offset).

mod common;

use proptest::prelude::*;
use raystep::accuracy::{case, measure, surface_distance, Measure, CASES};
use raystep::ray::Ray;
use raystep::real::{Precision, Real, Vector};
use raystep::render::{render, Settings};
use raystep::scene::{Material, Object, Role, Shape};
use raystep::shade::shadow::{step_off, Offset, AUTO_FACTOR};
use raystep::sphere::{Method, Sphere};
use raystep::stages::Stages;
use raystep::Vec3;

use Method::{Naive, Stable};
use Precision::{F32, F64};

fn run(name: &str, precision: Precision, method: Method, offset: Offset) -> Measure {
    measure(name, &case(name).unwrap(), precision, method, offset)
}

const TUTORIAL: Offset = Offset::TUTORIAL;
const AUTO: Offset = Offset::Auto;

/// The defaults get every case right: hit or miss as the reference says (outside
/// 1e-9 of a radius from a silhouette), hit points within 16 unit roundoffs of the
/// surface's size, every stepped-off origin outside its surface, every shadow
/// verdict the reference's (away from the terminator).
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
        assert!(m.max_surface_error_ulps <= AUTO_FACTOR, "{name}: {m:?}");
        assert_eq!(m.stuck, 0.0, "{name}");
        assert_eq!(m.wrong_shadow, 0.0, "{name}");
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
    let naive = run("graze", F32, Naive, AUTO);
    assert!(naive.false_hits > 1000, "{naive:?}");
    let stable = run("graze", F32, Stable, AUTO);
    assert_eq!(
        (stable.false_hits, stable.false_misses),
        (0, 0),
        "{stable:?}"
    );
}

#[test]
fn the_fixed_step_is_too_small_for_the_fake_floor_in_float32() {
    // Hit points on the fake floor land far more than 1e-5 off its surface in
    // float32, so the tutorial's step leaves origins inside it.
    for name in ["horizon", "seed-x1"] {
        let f32_tutorial = run(name, F32, Stable, TUTORIAL);
        assert!(
            f32_tutorial.max_surface_error > 1e-4,
            "{name}: {f32_tutorial:?}"
        );
        assert!(f32_tutorial.stuck > 0.001, "{name}: {f32_tutorial:?}");
        assert_eq!(run(name, F32, Stable, AUTO).stuck, 0.0, "{name}");
    }
    // A true plane in the same view is computed from small numbers: 5,000 times
    // closer in float32.
    let fake = run("horizon", F32, Stable, AUTO).max_surface_error;
    let real = run("horizon-true", F32, Stable, AUTO).max_surface_error;
    assert!(real * 1000.0 < fake, "true {real}, fake {fake}");
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
    let differ = |a: &[f32], b: &[f32]| a.iter().zip(b).filter(|(x, y)| x != y).count();
    let one = mask("seed-x1", AUTO);
    assert_eq!(differ(&one, &mask("seed-x1000", AUTO)), 0, "×1000");
    assert_eq!(differ(&one, &mask("seed-x0.001", AUTO)), 0, "×0.001");
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

// ---- Property tests: random spheres and rays at scales from 1e-3 to 1e4 ----

/// Exact sign of ‖p − c‖² − r², for float64 inputs, in double-double arithmetic.
fn outside_exactly(p: Vec3, c: Vec3, r: f64) -> bool {
    fn two_diff(a: f64, b: f64) -> (f64, f64) {
        let s = a - b;
        let bb = a - s;
        (s, (a - (s + bb)) + (bb - b))
    }
    fn square(hi: f64, lo: f64) -> (f64, f64) {
        let p = hi * hi;
        let e = hi.mul_add(hi, -p);
        (p, e + 2.0 * hi * lo + lo * lo)
    }
    fn add(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
        let s = a.0 + b.0;
        let v = s - a.0;
        let e = (a.0 - (s - v)) + (b.0 - v);
        (s, e + a.1 + b.1)
    }
    let mut sum = (0.0, 0.0);
    for i in 0..3 {
        let (hi, lo) = two_diff(p[i], c[i]);
        sum = add(sum, square(hi, lo));
    }
    let r2 = (r * r, r.mul_add(r, -(r * r)));
    let diff = add(sum, (-r2.0, -r2.1));
    diff.0 + diff.1 > 0.0
}

fn material() -> Material {
    Material {
        ambient: Vec3::splat(0.1),
        diffuse: Vec3::splat(0.6),
        specular: Vec3::ONE,
        shininess: 100.0,
        reflection: 0.5,
    }
}

/// A sphere at scale `s`, a ray from outside it aimed near its centre, in `T`.
/// Returns the stepped-off origin after a hit, checked outside, or None on a miss.
fn recast_check<T: Real>(
    center: Vec3,
    radius: f64,
    origin: Vec3,
    aim: Vec3,
) -> Option<(bool, bool, bool)> {
    let sphere = Object::<f64> {
        shape: Shape::Sphere(Sphere { center, radius }),
        material: material(),
        role: Role::Sphere,
    };
    let object = sphere.cast::<T>();
    let Shape::Sphere(s) = object.shape else {
        unreachable!()
    };
    let ray: Ray<T> = Ray::towards(T::Vec3::of(origin), T::Vec3::of(aim));
    let t = s.intersect(&ray, Stable)?;
    let point = ray.at(t);
    let normal = s.normal_at(point);
    let shifted = step_off(point, normal, &object, AUTO);
    let exact_center = s.center.to_f64();
    let outside = outside_exactly(shifted.to_f64(), exact_center, s.radius.to_f64());
    // Away from the surface: never the same sphere again. Into it: always.
    let away = s
        .intersect(
            &Ray {
                origin: shifted,
                direction: normal,
            },
            Stable,
        )
        .is_none();
    let into = s
        .intersect(
            &Ray {
                origin: shifted,
                direction: -normal,
            },
            Stable,
        )
        .is_some();
    Some((outside, away, into))
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
    fn a_recast_ray_never_meets_its_own_surface_at_any_scale(
        s in scale(), offset_far in 0.0f64..4.0, c in unit(), from in unit(), jitter in unit(),
        size in 0.001f64..1.0,
    ) {
        // A sphere of radius s·size somewhere within s·1e4·offset_far of the origin.
        let center = c * s * 10f64.powf(offset_far);
        let radius = s * size;
        let dir = if from.length() < 1e-3 { Vec3::X } else { from.normalize() };
        let origin = center + dir * radius * (1.5 + 100.0 * jitter.x.abs());
        let aim = center + jitter * radius * 0.9;
        for (precision, result) in [
            ("f64", recast_check::<f64>(center, radius, origin, aim)),
            ("f32", recast_check::<f32>(center, radius, origin, aim)),
        ] {
            if let Some((outside, away, into)) = result {
                prop_assert!(outside, "{precision}: stepped-off origin not outside");
                prop_assert!(away, "{precision}: a ray leaving the surface hits it again");
                prop_assert!(into, "{precision}: a ray into the surface misses it");
            }
        }
    }

    #[test]
    fn no_nan_or_infinity_reaches_a_pixel(
        s in scale(), spheres in prop::collection::vec((unit(), 0.01f64..1.0), 1..4),
        camera in unit(), light in unit(), inside in any::<bool>(), f32_precision in any::<bool>(),
    ) {
        // Tangent rays, a camera at a centre or inside a sphere, a light inside one.
        let mut toml = String::new();
        let cam = if inside { spheres[0].0 * s } else { camera * s * 3.0 };
        let cam_z = if cam.z == 0.0 { s } else { cam.z };
        toml += &format!("[image]\nwidth = 8\nheight = 6\n[camera]\nposition = [{}, {}, {}]\n", cam.x, cam.y, cam_z);
        toml += &format!("[light]\nposition = [{}, {}, {}]\n", light.x * s, light.y * s, light.z * s);
        for (c, r) in &spheres {
            toml += &format!("[[sphere]]\ncenter = [{}, {}, {}]\nradius = {}\n", c.x * s, c.y * s, c.z * s - s, r * s);
        }
        toml += &format!("[[plane]]\npoint = [0, {}, 0]\nnormal = [0, 1, 0]\n", -s);
        let scene = raystep::scene_file::parse(&toml, "generated").unwrap();
        let settings = Settings {
            precision: if f32_precision { F32 } else { F64 },
            ..Settings::from(Stages::ALL)
        };
        let frame = render(&scene, &settings, &|_| {});
        for p in &frame.pixels {
            prop_assert!(p.colour.iter().all(|c| c.is_finite() && (0.0..=1.0).contains(c)), "{:?}", p);
            prop_assert!(!p.depth.is_nan() && p.depth > 0.0, "{:?}", p);
            prop_assert!(p.normal.iter().all(|c| c.is_finite()), "{:?}", p);
            prop_assert!(p.direction.iter().all(|c| c.is_finite()), "{:?}", p);
        }
        let _ = surface_distance;
    }
}
