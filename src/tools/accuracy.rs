//! Where methods fail: every stress scene rendered with every precision,
//! intersection method and offset, and measured against a careful reference
//! (`raystep accuracy`).
//!
//! The reference works in float64 with the stable method on the very rays and the
//! very objects the method under test used (float32 numbers are converted to
//! float64 exactly), so it judges the arithmetic of the intersection and the
//! offset, not the rounding of the camera or of the scene's numbers: in float32,
//! the fake floor's radius 8999.3 is 8999.2998, and that sphere is the one judged.

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
        include_str!("../../scenes/stress/far-sphere.toml"),
    ),
    (
        "tiny-sphere",
        include_str!("../../scenes/stress/tiny-sphere.toml"),
    ),
    ("horizon", include_str!("../../scenes/stress/horizon.toml")),
    (
        "horizon-true",
        include_str!("../../scenes/stress/horizon-true.toml"),
    ),
    ("seed-x1", include_str!("../../scenes/stress/seed-x1.toml")),
    (
        "seed-x1000",
        include_str!("../../scenes/stress/seed-x1000.toml"),
    ),
    (
        "seed-x0.001",
        include_str!("../../scenes/stress/seed-x0.001.toml"),
    ),
    ("contact", include_str!("../../scenes/stress/contact.toml")),
    ("graze", include_str!("../../scenes/stress/graze.toml")),
    (
        "tiny-far",
        include_str!("../../scenes/stress/tiny-far.toml"),
    ),
    (
        "graze-row",
        include_str!("../../scenes/stress/graze-row.toml"),
    ),
    (
        "horizon-low-light",
        include_str!("../../scenes/stress/horizon-low-light.toml"),
    ),
    (
        "seed-moved-9e4",
        include_str!("../../scenes/stress/seed-moved-9e4.toml"),
    ),
    (
        "seed-moved-1e5",
        include_str!("../../scenes/stress/seed-moved-1e5.toml"),
    ),
    (
        "seed-x10000",
        include_str!("../../scenes/stress/seed-x10000.toml"),
    ),
    (
        "seed-x0.0001",
        include_str!("../../scenes/stress/seed-x0.0001.toml"),
    ),
    (
        "camera-far",
        include_str!("../../scenes/stress/camera-far.toml"),
    ),
    (
        "touching",
        include_str!("../../scenes/stress/touching.toml"),
    ),
    ("twins", include_str!("../../scenes/stress/twins.toml")),
    (
        "nested-mirror",
        include_str!("../../scenes/stress/nested-mirror.toml"),
    ),
    (
        "light-above",
        include_str!("../../scenes/stress/light-above.toml"),
    ),
    (
        "plane-far",
        include_str!("../../scenes/stress/plane-far.toml"),
    ),
];

/// A stress scene by name.
pub fn case(name: &str) -> Option<Scene> {
    let (_, text) = CASES.iter().find(|(n, _)| *n == name)?;
    Some(
        crate::io::scene_file::parse(text, &format!("scenes/stress/{name}.toml"))
            .expect("stress scenes are valid"),
    )
}

/// Pixels whose ray passes within this fraction of a sphere's radius of its
/// silhouette are not judged hit or miss: there the answer depends on the last
/// bit of the ray itself. In float32 the band is wider ([`silhouette_band`]).
pub const SILHOUETTE_BAND: f64 = 1e-9;

/// Unit roundoffs of `‖O‖ + ‖C‖ + r + t` in the silhouette band of the precision
/// under test: the ray's origin and direction, the centre and the radius it is
/// tested against are all rounded to numbers of that size, so float32 cannot
/// place a ray's closest approach to a sphere better than a few of those units.
pub const SILHOUETTE_UNITS: f64 = 8.0;

/// Hit points whose light direction is within this of the tangent plane
/// (|L·N| below it) are not judged lit or shadowed: the terminator. On a sphere
/// the band is wider where the `auto` step is a sizeable part of the radius
/// ([`terminator_band`]).
pub const TERMINATOR_BAND: f64 = 1e-3;

/// The width, in scene units, of the band around a sphere's silhouette in which a
/// ray is not judged, for a ray from `origin` computed with unit roundoff `u`:
/// [`SILHOUETTE_BAND`] of the radius in float64, and in float32 also
/// [`SILHOUETTE_UNITS`]` · u · (‖O‖ + ‖C‖ + r + t)` with `t` the distance to the
/// centre.
pub fn silhouette_band(u: f64, origin: Vec3, s: &Sphere) -> f64 {
    let relative = SILHOUETTE_BAND * s.radius;
    if u < f64::from(f32::EPSILON) / 4.0 {
        return relative;
    }
    let t = origin.distance(s.center);
    let sizes = origin.length() + s.center.length() + s.radius + t;
    relative.max(SILHOUETTE_UNITS * u * sizes)
}

/// Unit roundoffs of `r²` by which the stable test's `Δ/4 = r² − ‖h·d − m‖²`
/// may be off for a ray that grazes its own sphere: `m = C − O` (2u of `‖m‖²`),
/// `h·d − m` (2u), the sum of squares (γ_3) and `r²` (u), to first order.
pub const GRAZE_UNITS: f64 = 8.0;

/// The terminator band of a sphere of radius `radius` at a point whose `auto`
/// shadow ray starts `height` above the sphere (the step `h` of
/// [`crate::shade::shadow::sphere_step`] plus the point's own error, which the
/// judge measures), for a precision of unit roundoff `u`: the larger of
/// [`TERMINATOR_BAND`] and `√(2·height/r + 8u)`.
///
/// Why. A shadow ray from `height` above the sphere into its dark side at
/// `|L·N| = s` passes within `(r + height)·√(1 − s²)` of the centre: it misses
/// the sphere, and the dark-side point reads lit, when that is more than `r`,
/// that is when `s² < 2·height/r` (to first order). The test that decides it
/// computes `Δ/4` within [`GRAZE_UNITS`]`·u·r²`, so it may answer either way
/// for `s²` within `8u` of that. No offset that keeps origins outside does
/// better: `height` is at least what rounding can put the point off the sphere
/// by (a few `u·r`), so in float32 the band is about 1e-3 on every sphere
/// (`√(2·3.5u + 8u)` = 9.5e-4 at the very least, about 1.15e-3 on the fake
/// floor); in float64 it is [`TERMINATOR_BAND`] for any sphere within 1e9
/// radii of the origin. (The judge adds the angle by which rounding moved that
/// origin along the surface, seen from the centre, beside the point it judges.)
pub fn terminator_band(u: f64, radius: f64, height: f64) -> f64 {
    TERMINATOR_BAND.max((2.0 * height / radius + GRAZE_UNITS * u).sqrt())
}

/// What one configuration gets wrong on one scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Measure {
    /// The stress case.
    pub case: String,
    /// `f32` or `f64`.
    pub precision: String,
    /// `naive` or `stable`.
    pub method: String,
    /// `fixed:…`, `scene` or `auto`.
    pub offset: String,
    /// What the loader says of this scene in this precision: `ok`, `warned`
    /// (rendered, with a warning: float32 resolves its shadow edges only coarsely)
    /// or `refused` (measured anyway; `raystep render` refuses it in float32).
    pub limit: String,
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
    /// `false_hits` and `false_misses` judged with the narrow band of float64
    /// ([`SILHOUETTE_BAND`] of the radius) whatever the precision: in float32
    /// this counts the failures inside float32's own band too (the textbook
    /// quadratic's on `graze`).
    pub strict_false: (usize, usize),
    /// The largest distance of a first hit point from its surface, in scene units.
    pub max_surface_error: f64,
    /// The largest of each hit's distance from its surface divided by the unit
    /// roundoff times its surface's magnitude (dimensionless; it need not come from
    /// the same hit as `max_surface_error`).
    pub max_surface_error_ulps: f64,
    /// Fraction of first hits whose stepped-off origin is not outside the surface:
    /// the cause of acne, whichever way it shows.
    pub stuck: f64,
    /// Fraction of judged first hits whose shadow verdict differs from the
    /// reference's: the acne (or the light leaks) that shows.
    pub wrong_shadow: f64,
    /// Wrong shadow verdicts, counted (the numerator of `wrong_shadow`).
    pub wrong_shadows: usize,
    /// Wrong shadow verdicts where |L·N| is at least [`TERMINATOR_BAND`] (1e-3),
    /// whatever the terminator band of the precision at that point: in float32
    /// these include the dark-side points within the band the bound's own step
    /// makes ([`terminator_band`]), which `wrong_shadows` does not count.
    pub wrong_shadows_1e3: usize,
    /// The largest |L·N| at a wrong shadow verdict (0 if there is none): how far
    /// from the terminator the failures reach.
    pub worst_facing: f64,
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
    m.limit = match crate::io::scene_file::check_precision(scene, precision) {
        Err(_) => "refused",
        Ok(warnings) if !warnings.is_empty() => "warned",
        Ok(_) => "ok",
    }
    .to_string();
    m
}

/// Every stress case × precision × method × offset (fixed:0, the tutorial's
/// fixed:1e-5, scene, auto).
pub fn measure_all() -> Vec<Measure> {
    CASES
        .iter()
        .flat_map(|(name, _)| measure_case(name))
        .collect()
}

/// Every precision × method × offset on one stress case (none if it is unknown).
pub fn measure_case(name: &str) -> Vec<Measure> {
    let Some(scene) = case(name) else {
        return Vec::new();
    };
    let mut rows = Vec::new();
    for precision in [Precision::F32, Precision::F64] {
        for method in [Method::Naive, Method::Stable] {
            for offset in [
                Offset::Fixed(0.0),
                Offset::TUTORIAL,
                Offset::Scene,
                Offset::Auto,
            ] {
                rows.push(measure(name, &scene, precision, method, offset));
            }
        }
    }
    rows
}

fn measure_in<T: Real>(scene: &Scene, settings: &Settings) -> Measure {
    let tracer = Tracer::<T>::new(scene, settings);
    let reference: Vec<Object> = tracer.objects.iter().map(Object::exact).collect();
    let light = tracer.light.position.to_f64();
    let mut m = Measure {
        case: String::new(),
        precision: T::NAME.to_string(),
        method: settings.method.to_string(),
        offset: settings.offset.to_string(),
        limit: String::new(),
        pixels: (scene.width * scene.height) as usize,
        judged: 0,
        reference_hits: 0,
        false_hits: 0,
        false_misses: 0,
        strict_false: (0, 0),
        max_surface_error: 0.0,
        max_surface_error_ulps: 0.0,
        stuck: 0.0,
        wrong_shadow: 0.0,
        wrong_shadows: 0,
        wrong_shadows_1e3: 0,
        worst_facing: 0.0,
    };
    let u = T::UNIT_ROUNDOFF.to_f64();
    let (mut first_hits, mut stuck, mut shadow_judged, mut wrong) =
        (0usize, 0usize, 0usize, 0usize);
    for row in 0..scene.height {
        for col in 0..scene.width {
            let ray = tracer.camera.primary_ray::<T>(row, col);
            let exact_ray = Ray {
                origin: ray.origin.to_f64(),
                direction: ray.direction.to_f64(),
            };
            let traced = tracer.trace(ray, &mut ());
            let truth = reference_hit(&reference, &exact_ray, u);

            if let Some(strict) = reference_hit(&reference, &exact_ray, 0.0) {
                match (traced.first.map(|f| f.object), strict.hit) {
                    (Some(_), None) => m.strict_false.0 += 1,
                    (None, Some(_)) => m.strict_false.1 += 1,
                    (Some(a), Some(b)) if a != b => {
                        m.strict_false.0 += 1;
                        m.strict_false.1 += 1;
                    }
                    _ => {}
                }
            }
            if let Some(truth) = truth {
                match (traced.first.map(|f| f.object), truth.hit) {
                    (Some(_), None) => m.false_hits += 1,
                    (None, Some(_)) => m.false_misses += 1,
                    // The wrong object counts as both: a miss of the right one, a
                    // hit of the wrong one.
                    (Some(a), Some(b)) if a != b => {
                        m.false_hits += 1;
                        m.false_misses += 1;
                    }
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
            // (A plane through the origin has magnitude 0: its points' own size
            // stands in.)
            let size = exact_object.magnitude();
            let size = if size > 0.0 {
                size
            } else {
                point.to_f64().length()
            };
            let ulps = error / (T::UNIT_ROUNDOFF.to_f64() * size);
            m.max_surface_error_ulps = m.max_surface_error_ulps.max(ulps);
            // Is the stepped-off origin outside the surface?
            let shifted = step_off(point, T::Vec3::of(first.normal), object, settings.offset);
            // Outside means on the side the ray came from (for a plane: the face hit).
            let side = match exact_object.shape {
                Shape::Plane(pl) if pl.normal.dot(first.normal) < 0.0 => -1.0,
                _ => 1.0,
            };
            if side * surface_distance(exact_object, shifted.to_f64()) <= 0.0 {
                stuck += 1;
            }
            // Is the shadow verdict the reference's?
            let facing = first.normal;
            // Where the bound's own shadow ray starts, whatever the offset under
            // test: the terminator band is where that ray passes over its sphere.
            let bound_origin = match settings.offset {
                Offset::Auto => shifted,
                _ => step_off(point, T::Vec3::of(first.normal), object, Offset::Auto),
            }
            .to_f64();
            if let Some((lit, l_dot_n, band)) = reference_lit(
                &reference,
                first.object,
                point.to_f64(),
                facing,
                light,
                u,
                bound_origin,
            ) {
                if lit != first.lit {
                    m.wrong_shadows_1e3 += 1;
                }
                if l_dot_n.abs() >= band {
                    shadow_judged += 1;
                    if lit != first.lit {
                        wrong += 1;
                        m.worst_facing = m.worst_facing.max(l_dot_n.abs());
                    }
                }
            }
        }
    }
    m.stuck = stuck as f64 / first_hits.max(1) as f64;
    m.wrong_shadow = wrong as f64 / shadow_judged.max(1) as f64;
    m.wrong_shadows = wrong;
    m
}

/// The reference's answer for a primary ray: `None` if the ray is too close to a
/// silhouette to judge, otherwise the index of the first object hit (or none).
struct Truth {
    hit: Option<usize>,
}

fn reference_hit(objects: &[Object], ray: &Ray, u: f64) -> Option<Truth> {
    let mut nearest: Option<(f64, usize)> = None;
    for (i, o) in objects.iter().enumerate() {
        if let Some(t) = reference_distance(o, ray, u, 0.0)? {
            if nearest.is_none_or(|(n, _)| t < n) {
                nearest = Some((t, i));
            }
        }
    }
    Some(Truth {
        hit: nearest.map(|(_, i)| i),
    })
}

/// The reference's distance along `ray` to `object`: `Some(None)` for a miss,
/// `None` when the ray is too close to a sphere's silhouette to judge (the band
/// of [`silhouette_band`] for unit roundoff `u`, widened by `slack`, how far the
/// ray's origin may be from where the method under test put it), or so nearly
/// parallel to a plane that the sign of `⟨d, n⟩` is within rounding.
fn reference_distance(object: &Object, ray: &Ray, u: f64, slack: f64) -> Option<Option<f64>> {
    match object.shape {
        Shape::Sphere(s) => {
            let band = silhouette_band(u, ray.origin, &s) + slack;
            match exact_sphere(&s, ray, band) {
                Crossing::Ambiguous => None,
                Crossing::Miss => Some(None),
                Crossing::Hit(t) => Some(Some(t)),
            }
        }
        Shape::Plane(pl) => {
            let facing = ray.direction.dot(pl.normal);
            if facing.abs() <= 4.0 * u * ray.direction.length() * pl.normal.length() {
                return None;
            }
            Some(object.intersect(ray, Method::Stable))
        }
    }
}

/// Is `p` strictly outside the sphere of centre `c` and radius `r`? The sign of
/// ‖p − c‖² − r², decided in double-double arithmetic.
pub fn outside_exactly(p: Vec3, c: Vec3, r: f64) -> bool {
    use dd::Dd;
    let squares = (0..3).fold(Dd::ZERO, |acc, i| {
        let d = Dd::diff(p[i], c[i]);
        acc.add(d.mul(d))
    });
    squares.sub(Dd::product(r, r)).value() > 0.0
}

/// What the exact answer says of a ray and a sphere.
enum Crossing {
    /// Within the silhouette band: not judged.
    Ambiguous,
    /// Not hit by the tutorial's rule (no two crossings, or not both in front).
    Miss,
    /// Hit, at about this distance.
    Hit(f64),
}

/// The tutorial's hit rule decided by signs computed in double-double arithmetic
/// (about 106 bits), with the ray's direction as it is (not assumed of length 1):
/// with f = O − C and a = ‖d‖², two crossings iff Δ/4 = ⟨f, d⟩² − a·(‖f‖² − r²) > 0,
/// both in front iff ‖f‖ > r and ⟨f, d⟩ < 0. A ray whose closest approach is
/// within `band` of the radius (so `|Δ/4| ≈ 2r·|r − D|·a` within `2r·band·a`)
/// is not judged.
fn exact_sphere(s: &Sphere, ray: &Ray, band: f64) -> Crossing {
    use dd::Dd;
    let f: [Dd; 3] = [0, 1, 2].map(|i| Dd::diff(ray.origin[i], s.center[i]));
    let d = ray.direction.to_array();
    let fd = (0..3).fold(Dd::ZERO, |acc, i| acc.add(f[i].mul_f64(d[i])));
    let ff = (0..3).fold(Dd::ZERO, |acc, i| acc.add(f[i].mul(f[i])));
    let a = (0..3).fold(Dd::ZERO, |acc, i| acc.add(Dd::product(d[i], d[i])));
    let c = ff.sub(Dd::product(s.radius, s.radius));
    let quarter_delta = fd.mul(fd).sub(a.mul(c));
    if quarter_delta.value().abs() <= 2.0 * band * s.radius * a.value() {
        return Crossing::Ambiguous;
    }
    if quarter_delta.value() <= 0.0 || c.value() <= 0.0 || fd.value() >= 0.0 {
        return Crossing::Miss;
    }
    // The near root, (−⟨f, d⟩ − √(Δ/4)) / a, written without cancellation.
    let q = -fd.value() + quarter_delta.value().sqrt();
    Crossing::Hit(c.value() / q)
}

/// Double-double numbers: a value as the unevaluated sum of two float64s, about
/// 106 bits. Enough to decide the sign of the short expressions above.
mod dd {
    /// hi + lo, with |lo| at most half an ulp of hi.
    #[derive(Clone, Copy, Debug)]
    pub struct Dd(f64, f64);

    fn two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        let v = s - a;
        Dd(s, (a - (s - v)) + (b - v))
    }

    impl Dd {
        pub const ZERO: Dd = Dd(0.0, 0.0);

        /// a − b, exactly.
        pub fn diff(a: f64, b: f64) -> Dd {
            two_sum(a, -b)
        }

        /// a·b, exactly.
        pub fn product(a: f64, b: f64) -> Dd {
            let p = a * b;
            Dd(p, a.mul_add(b, -p))
        }

        pub fn add(self, o: Dd) -> Dd {
            let s = two_sum(self.0, o.0);
            two_sum(s.0, s.1 + self.1 + o.1)
        }

        pub fn sub(self, o: Dd) -> Dd {
            self.add(Dd(-o.0, -o.1))
        }

        pub fn mul(self, o: Dd) -> Dd {
            let p = Dd::product(self.0, o.0);
            two_sum(p.0, p.1 + self.0 * o.1 + self.1 * o.0)
        }

        pub fn mul_f64(self, x: f64) -> Dd {
            self.mul(Dd(x, 0.0))
        }

        pub fn value(self) -> f64 {
            self.0 + self.1
        }
    }
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
/// `facing` was seen, with `L·N` there and the terminator band at `p`
/// ([`terminator_band`], for the caller to judge by), or `None` where it is too
/// close to call: within [`TERMINATOR_BAND`] of the terminator, or with the
/// shadow ray grazing another sphere (its silhouette band, widened by the `auto`
/// step at `p`: the shadow ray starts that far from the point judged).
fn reference_lit(
    objects: &[Object],
    index: usize,
    p: Vec3,
    facing: Vec3,
    light: Vec3,
    u: f64,
    bound_origin: Vec3,
) -> Option<(bool, f64, f64)> {
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
    let band = match object.shape {
        Shape::Sphere(s) => {
            // The bound's origin, from the centre: its height above the sphere, and
            // how far rounding moved it along the surface from the point judged
            // (which turns the normal it sees by that over the radius).
            let from_centre = bound_origin - s.center;
            let height = (from_centre.length() - s.radius).abs();
            let aside = (from_centre - normal * from_centre.dot(normal)).length();
            terminator_band(u, s.radius, height) + aside / s.radius
        }
        Shape::Plane(_) => TERMINATOR_BAND,
    };
    if facing.abs() < TERMINATOR_BAND {
        return None;
    }
    // A sphere shadows its own far side; a plane lights both of its faces the same.
    if facing < 0.0 && matches!(object.shape, Shape::Sphere(_)) {
        return Some((false, facing, band));
    }
    // How far from the point judged the bound's shadow ray starts.
    let slack = on_surface.distance(bound_origin);
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
        if reference_distance(other, &ray, u, slack)?.is_some_and(|t| t < distance) {
            lit = false;
        }
    }
    Some((lit, facing, band))
}

/// The header line of `raystep accuracy`'s table.
pub fn table_header() -> String {
    format!(
        "{:<17} {:<4} {:<6} {:<10} {:>7} {:>7} {:>10} {:>9} {:>7} {:>7} {:>8} {:>6} {:>6} {}",
        "case",
        "prec",
        "method",
        "offset",
        "f.hits",
        "f.miss",
        "surf.err",
        "in u·size",
        "stuck%",
        "shadow%",
        "max|L·N|",
        "wrong",
        ">1e-3",
        "limit"
    )
}

/// One line of `raystep accuracy`'s table.
pub fn table_row(m: &Measure) -> String {
    format!(
        "{:<17} {:<4} {:<6} {:<10} {:>7} {:>7} {:>10.1e} {:>9.1} {:>7.2} {:>7.2} {:>8.1e} {:>6} {:>6} {}",
        m.case,
        m.precision,
        m.method,
        m.offset,
        m.false_hits,
        m.false_misses,
        m.max_surface_error,
        m.max_surface_error_ulps,
        100.0 * m.stuck,
        100.0 * m.wrong_shadow,
        m.worst_facing,
        m.wrong_shadows,
        m.wrong_shadows_1e3,
        m.limit
    )
}
