//! Where methods fail: every stress scene rendered with every precision,
//! intersection method and offset, and measured against a careful reference
//! (`raystep accuracy`).
//!
//! The reference works in float64 with the stable method on the very rays the
//! method under test traced (a float32 ray is converted exactly), so it judges the
//! arithmetic of the intersection and the offset, not the rounding of the camera.

use serde::Serialize;

use crate::ray::Ray;
use crate::real::{Precision, Real, Vector};
use crate::render::{Settings, Tracer};
use crate::scene::{Object, Scene, Shape};
use crate::shade::shadow::{step_off, Offset};
use crate::sphere::{Method, Sphere};
use crate::stages::Stages;
use crate::Vec3;

/// The stress scenes (`scenes/stress/`), built into the binary: (name, TOML).
pub const CASES: &[(&str, &str)] = &[
    (
        "far-sphere",
        include_str!("../scenes/stress/far-sphere.toml"),
    ),
    (
        "tiny-sphere",
        include_str!("../scenes/stress/tiny-sphere.toml"),
    ),
    ("horizon", include_str!("../scenes/stress/horizon.toml")),
    (
        "horizon-true",
        include_str!("../scenes/stress/horizon-true.toml"),
    ),
    ("seed-x1", include_str!("../scenes/stress/seed-x1.toml")),
    (
        "seed-x1000",
        include_str!("../scenes/stress/seed-x1000.toml"),
    ),
    (
        "seed-x0.001",
        include_str!("../scenes/stress/seed-x0.001.toml"),
    ),
    ("contact", include_str!("../scenes/stress/contact.toml")),
    ("graze", include_str!("../scenes/stress/graze.toml")),
];

/// A stress scene by name.
pub fn case(name: &str) -> Option<Scene> {
    let (_, text) = CASES.iter().find(|(n, _)| *n == name)?;
    Some(
        crate::scene_file::parse(text, &format!("scenes/stress/{name}.toml"))
            .expect("stress scenes are valid"),
    )
}

/// Pixels whose ray passes within this fraction of a sphere's radius of its
/// silhouette are not judged hit or miss: there the answer depends on the last
/// bit of the ray itself.
pub const SILHOUETTE_BAND: f64 = 1e-9;

/// Hit points whose light direction is within this of the tangent plane
/// (|L·N| below it) are not judged lit or shadowed: the terminator.
pub const TERMINATOR_BAND: f64 = 1e-3;

/// What one configuration gets wrong on one scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Measure {
    /// The stress case.
    pub case: String,
    /// `f32` or `f64`.
    pub precision: String,
    /// `naive` or `stable`.
    pub method: String,
    /// `fixed:…` or `auto`.
    pub offset: String,
    /// Pixels in the image.
    pub pixels: usize,
    /// Pixels judged for hit or miss (outside the silhouette band).
    pub judged: usize,
    /// Judged pixels that the reference sees hit something.
    pub reference_hits: usize,
    /// Pixels that hit something where the reference misses.
    pub false_hits: usize,
    /// Pixels that miss where the reference hits.
    pub false_misses: usize,
    /// The largest distance of a first hit point from its surface, in scene units.
    pub max_surface_error: f64,
    /// The same, in unit roundoffs of the surface's magnitude (dimensionless).
    pub max_surface_error_ulps: f64,
    /// Fraction of first hits whose stepped-off origin is not outside the surface:
    /// the cause of acne, whichever way it shows.
    pub stuck: f64,
    /// Fraction of judged first hits whose shadow verdict differs from the
    /// reference's: the acne (or the light leaks) that shows.
    pub wrong_shadow: f64,
}

/// Measure one configuration on one scene (every stage on).
pub fn measure(
    name: &str,
    scene: &Scene,
    precision: Precision,
    method: Method,
    offset: Offset,
) -> Measure {
    let settings = Settings {
        stages: Stages::ALL,
        precision,
        method,
        offset,
        ..Settings::from(Stages::ALL)
    };
    let mut m = match precision {
        Precision::F32 => measure_in::<f32>(scene, &settings),
        Precision::F64 => measure_in::<f64>(scene, &settings),
    };
    m.case = name.to_string();
    m
}

/// Every stress case × precision × method × offset (fixed:0, the tutorial's
/// fixed:1e-5, auto).
pub fn measure_all() -> Vec<Measure> {
    let mut rows = Vec::new();
    for (name, _) in CASES {
        let scene = case(name).expect("listed");
        for precision in [Precision::F32, Precision::F64] {
            for method in [Method::Naive, Method::Stable] {
                for offset in [Offset::Fixed(0.0), Offset::TUTORIAL, Offset::Auto] {
                    rows.push(measure(name, &scene, precision, method, offset));
                }
            }
        }
    }
    rows
}

fn measure_in<T: Real>(scene: &Scene, settings: &Settings) -> Measure {
    let tracer = Tracer::<T>::new(scene, settings);
    let reference: Vec<Object> = scene.objects_in_play(Stages::ALL);
    let light = scene.light.position;
    let mut m = Measure {
        case: String::new(),
        precision: T::NAME.to_string(),
        method: settings.method.to_string(),
        offset: settings.offset.to_string(),
        pixels: (scene.width * scene.height) as usize,
        judged: 0,
        reference_hits: 0,
        false_hits: 0,
        false_misses: 0,
        max_surface_error: 0.0,
        max_surface_error_ulps: 0.0,
        stuck: 0.0,
        wrong_shadow: 0.0,
    };
    let (mut first_hits, mut stuck, mut shadow_judged, mut wrong) =
        (0usize, 0usize, 0usize, 0usize);
    for row in 0..scene.height {
        for col in 0..scene.width {
            let ray = tracer.camera.primary_ray::<T>(row, col);
            let exact_ray = Ray {
                origin: ray.origin.to_f64(),
                direction: ray.direction.to_f64(),
            };
            let traced = tracer.trace(ray);
            let truth = reference_hit(&reference, &exact_ray);

            if let Some(truth) = truth {
                match (traced.first.is_some(), truth.hit.is_some()) {
                    (true, false) => m.false_hits += 1,
                    (false, true) => m.false_misses += 1,
                    _ => {}
                }
                m.judged += 1;
                m.reference_hits += usize::from(truth.hit.is_some());
            }

            let Some(first) = traced.first else { continue };
            first_hits += 1;
            // How far the computed hit point is from the surface it is on.
            let object = &tracer.objects[first.object];
            let point = ray.at(T::of(first.depth));
            let exact_object = &reference[first.object];
            let error = surface_distance(exact_object, point.to_f64()).abs();
            m.max_surface_error = m.max_surface_error.max(error);
            let ulps = error / (T::UNIT_ROUNDOFF.to_f64() * exact_object.magnitude());
            m.max_surface_error_ulps = m.max_surface_error_ulps.max(ulps);
            // Is the stepped-off origin outside the surface?
            let shifted = step_off(point, T::Vec3::of(first.normal), object, settings.offset);
            if surface_distance(exact_object, shifted.to_f64()) <= 0.0 {
                stuck += 1;
            }
            // Is the shadow verdict the reference's?
            let facing = first.normal;
            if let Some(lit) =
                reference_lit(&reference, first.object, point.to_f64(), facing, light)
            {
                shadow_judged += 1;
                if lit != first.lit {
                    wrong += 1;
                }
            }
        }
    }
    m.stuck = stuck as f64 / first_hits.max(1) as f64;
    m.wrong_shadow = wrong as f64 / shadow_judged.max(1) as f64;
    m
}

/// The reference's answer for a primary ray: `None` if the ray is too close to a
/// silhouette to judge, otherwise the index of the first object hit (or none).
struct Truth {
    hit: Option<usize>,
}

fn reference_hit(objects: &[Object], ray: &Ray) -> Option<Truth> {
    let mut nearest: Option<(f64, usize)> = None;
    for (i, o) in objects.iter().enumerate() {
        if let Shape::Sphere(s) = o.shape {
            if near_silhouette(&s, ray) {
                return None;
            }
        }
        if let Some(t) = o.intersect(ray, Method::Stable) {
            if nearest.is_none_or(|(n, _)| t < n) {
                nearest = Some((t, i));
            }
        }
    }
    Some(Truth {
        hit: nearest.map(|(_, i)| i),
    })
}

fn near_silhouette(s: &Sphere, ray: &Ray) -> bool {
    let f = ray.origin - s.center;
    let closest = f - ray.direction * ray.direction.dot(f);
    (closest.length() - s.radius).abs() <= SILHOUETTE_BAND * s.radius
}

/// Signed distance from `p` to the surface: positive outside (a sphere) or on the
/// side the normal points to (a plane).
pub fn surface_distance(object: &Object, p: Vec3) -> f64 {
    match object.shape {
        Shape::Sphere(s) => (p - s.center).length() - s.radius,
        Shape::Plane(pl) => (p - pl.point).dot(pl.normal),
    }
}

/// The reference's shadow verdict at (near) `p` on object `index`, whose face
/// `facing` was seen, or `None` where
/// it is too close to call: on the terminator, or with the shadow ray grazing
/// another sphere.
fn reference_lit(
    objects: &[Object],
    index: usize,
    p: Vec3,
    facing: Vec3,
    light: Vec3,
) -> Option<bool> {
    let object = &objects[index];
    let on_surface = object.project(p);
    let normal = match object.shape {
        Shape::Sphere(s) => s.normal_at(on_surface),
        // The face the primary ray saw.
        Shape::Plane(pl) if pl.normal.dot(facing) < 0.0 => -pl.normal,
        Shape::Plane(pl) => pl.normal,
    };
    let to_light = (light - on_surface).normalize();
    let facing = to_light.dot(normal);
    if facing.abs() < TERMINATOR_BAND {
        return None;
    }
    // A sphere shadows its own far side; a plane lights both of its faces the same.
    if facing < 0.0 && matches!(object.shape, Shape::Sphere(_)) {
        return Some(false);
    }
    let ray = Ray {
        origin: on_surface,
        direction: to_light,
    };
    let distance = light.distance(on_surface);
    let mut lit = true;
    for (i, other) in objects.iter().enumerate() {
        if i == index {
            continue;
        }
        if let Shape::Sphere(s) = other.shape {
            if near_silhouette(&s, &ray) {
                return None;
            }
        }
        if let Some(t) = other.intersect(&ray, Method::Stable) {
            if t < distance {
                lit = false;
            }
        }
    }
    Some(lit)
}

/// The header line of `raystep accuracy`'s table.
pub fn table_header() -> String {
    format!(
        "{:<12} {:<4} {:<6} {:<10} {:>7} {:>7} {:>10} {:>9} {:>7} {:>7}",
        "case",
        "prec",
        "method",
        "offset",
        "f.hits",
        "f.miss",
        "surf.err",
        "in u·size",
        "stuck%",
        "shadow%"
    )
}

/// One line of `raystep accuracy`'s table.
pub fn table_row(m: &Measure) -> String {
    format!(
        "{:<12} {:<4} {:<6} {:<10} {:>7} {:>7} {:>10.1e} {:>9.1} {:>7.2} {:>7.2}",
        m.case,
        m.precision,
        m.method,
        m.offset,
        m.false_hits,
        m.false_misses,
        m.max_surface_error,
        m.max_surface_error_ulps,
        100.0 * m.stuck,
        100.0 * m.wrong_shadow
    )
}
