//! Shadows: is there anything between the hit point and the light?

use crate::ray::Ray;
use crate::real::{Num, Real, Vec3Num};
use crate::scene::{blocked, Object, Shape};
use crate::sphere::Method;

/// How far the tutorial moves a hit point along the normal before casting a new
/// ray from it.
pub const TUTORIAL_STEP: f64 = 1e-5;

/// The `scene` offset (raystep's `auto` before the bound below) steps out by this
/// many unit roundoffs of the size of the numbers the point is computed from: the
/// larger of the surface's size (the largest coordinate of its centre or anchor,
/// plus its radius) and the point's own largest coordinate (so that a floor
/// through the origin still steps out far from it). Kept to be
/// measured against (`--offset scene`): it is right at every scale, but for a
/// sphere far from the origin compared with its radius it is a sizeable part of
/// the radius (8·u·(max|Cᵢ| + r), with max|Cᵢ| the centre's largest coordinate,
/// is half the radius of a sphere of radius 1e-3 at 1000 in float32), and shadow
/// rays that start that far out pass over their own sphere near the terminator.
pub const SCENE_FACTOR: f64 = 8.0;

/// Unit roundoffs of the radius in the `auto` step over a sphere: the bound
/// derived at [`sphere_step`] is 6.5, to first order; the rest covers the terms
/// of second order and the rounding of the bound itself.
pub const RADIUS_UNITS: f64 = 7.0;

/// Unit roundoffs of the distance of the hit point from the origin in the `auto`
/// step over a sphere: the bound derived at [`sphere_step`] is 1, to first order.
pub const POINT_UNITS: f64 = 2.0;

/// Unit roundoffs of the distance from a plane's anchor (its point nearest the
/// origin) in the `auto` step over a plane: the bound derived at
/// [`plane_height`] is 8, to first order.
pub const ANCHOR_UNITS: f64 = 10.0;

/// Unit roundoffs of the projected point's distance from the origin in the
/// `auto` step over a plane: the bound derived at [`plane_height`] is 2, to
/// first order.
pub const ORIGIN_UNITS: f64 = 3.0;

/// How far a hit point is moved along the normal before a shadow or reflected ray
/// leaves it (`--offset`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Offset {
    /// A fixed distance, whatever the scene's scale: `fixed:1e-5` is the tutorial's.
    Fixed(f64),
    /// Put the point back on the surface, then step out by [`SCENE_FACTOR`] unit
    /// roundoffs of the larger of the surface's size and the point's largest
    /// coordinate (raystep's first automatic offset, kept for comparison).
    Scene,
    /// Move the point to a height above the surface that is a bound of the
    /// error of that move and of the next ray's test ([`sphere_step`],
    /// [`step_out`]): a few unit roundoffs of the radius and of the point's
    /// distance from the origin. On a sphere's own dark side no shadow ray is
    /// cast at all ([`own_shadow`]).
    #[default]
    Auto,
}

impl Offset {
    /// The tutorial's step, `fixed:1e-5`.
    pub const TUTORIAL: Offset = Offset::Fixed(TUTORIAL_STEP);
}

impl std::str::FromStr for Offset {
    type Err = String;

    /// `auto`, `scene`, or `fixed:VALUE` with VALUE from 0 to 1e15 (e.g. `fixed:1e-5`).
    fn from_str(text: &str) -> Result<Offset, String> {
        match text {
            "auto" => return Ok(Offset::Auto),
            "scene" => return Ok(Offset::Scene),
            _ => {}
        }
        let value = text.strip_prefix("fixed:").ok_or_else(|| {
            format!("`{text}`: expected auto, scene or fixed:VALUE, e.g. fixed:1e-5")
        })?;
        match value.parse::<f64>() {
            Ok(v) if (0.0..=crate::scene::MAX_MAGNITUDE).contains(&v) => Ok(Offset::Fixed(v)),
            _ => Err(format!(
                "`{value}`: the offset must be a number from 0 to {:e}",
                crate::scene::MAX_MAGNITUDE
            )),
        }
    }
}

impl std::fmt::Display for Offset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Offset::Fixed(v) if *v == 0.0 => f.write_str("fixed:0"),
            Offset::Fixed(v) => write!(f, "fixed:{v:e}"),
            Offset::Scene => f.write_str("scene"),
            Offset::Auto => f.write_str("auto"),
        }
    }
}

// ANCHOR: step_off
/// The hit point moved a little along the surface normal. A ray cast from the
/// exact hit point could find the same surface again at a tiny distance, because
/// the computed point lies a rounding error inside or outside it ("shadow acne").
#[inline(always)]
pub fn step_off<T: Real>(
    point: T::Vec3,
    normal: T::Vec3,
    surface: &Object<T>,
    offset: Offset,
) -> T::Vec3 {
    let u = T::UNIT_ROUNDOFF;
    match offset {
        Offset::Fixed(step) => point + normal * T::of(step),
        Offset::Auto => match &surface.shape {
            Shape::Sphere(s) => sphere_step(point, normal, s.center, s.radius, u),
            Shape::Plane(pl) => {
                let on_surface = surface.surface_point(point, normal);
                step_out(on_surface, normal, plane_height(on_surface, pl.point, u))
            }
        },
        Offset::Scene => {
            let on_surface = surface.surface_point(point, normal);
            step_out_by_scene(on_surface, normal, surface.magnitude(), u)
        }
    }
}

/// The `auto` step over a sphere of centre `center` and radius `radius`, from
/// the hit point `point` (P, as computed) along the unit `normal` (N, computed
/// from P): to the height `h = u·(7·r + 2·‖P‖)` above the sphere, with `u` the
/// unit roundoff, in one move, `P + N·((r − ‖P − C‖) + h)`.
///
/// Why. Every operation is exact up to a factor `1 + δ`, `|δ| ≤ u` (Higham's
/// model; `γ_n = n·u/(1 − n·u)` bounds `n` such factors). Follow the new
/// origin `O` through, measuring heights along the normal:
///
/// 1. `d = ‖P − C‖` as computed is within `3.5u·r` of P's true distance from
///    the centre (a difference, three squares summed, a square root), so
///    `r − d` puts P back on the sphere up to `3.5u·r`. (pbrt-v4 re-projects
///    its sphere hit points for the same reason: the hit point's error grew
///    with the root's, the projection's depends only on the numbers it is
///    computed from.)
/// 2. `N` is a unit vector up to `‖N‖ = 1 ± 4.5u` and points along P's radius
///    up to a few `u`; it multiplies only the short move `(r − d) + h`, a few
///    `u` of the distances, so its error counts `u²` (second order), as do the
///    roundings of the move's length and of `N·(…)`.
/// 3. The sum `P + N·(…)` is rounded: `u·‖O‖`, and `‖O‖ ≤ ‖P‖` to first order.
/// 4. The next ray's test must see the origin outside: it computes
///    `c = ‖C − O‖² − r²` and counts the sphere only if `c > 0`. Rounding of
///    `C − O`, of the sum of squares (`γ_3`) and of `r²` can turn a true `c > 0`
///    negative unless `‖C − O‖ > r·(1 + 3u)`: `3u·r` more.
///
/// So the origin is outside, as the next test sees it, once
/// `h > 6.5u·r + u·‖P‖` (to first order in `u`); the step rounds both up. It
/// needs nothing of the normal but the direction, and `‖P − C‖` is the length
/// the normal is computed from. (raystep first put the point back on the
/// sphere as `S = C + N·r` and then stepped out from `S`: that rounds twice
/// where this rounds once, and trusts `‖N‖ = 1` over the whole radius, which
/// cost `9.5u·r + 2u·‖S‖`.)
///
/// Nothing here is the size of the scene: a sphere far from the origin steps
/// out by `2u` of the point's distance (the spacing of the numbers there, which
/// no method can beat), not by a multiple of its largest coordinate, and `‖P‖`
/// is at most the ray's origin plus the distance it travelled, `‖O‖ + t`.
#[inline(always)]
pub fn sphere_step<V: Vec3Num>(point: V, normal: V, center: V, radius: V::Num, u: V::Num) -> V {
    let back_to_surface = radius - (point - center).length();
    point + normal * (back_to_surface + sphere_height(point, radius, u))
}

/// The height above a sphere of radius `radius` that [`sphere_step`] moves a
/// hit point `point` to: `h = u·(7·r + 2·‖P‖)`, at most `STEP_CAP`.
#[inline(always)]
pub fn sphere_height<V: Vec3Num>(point: V, radius: V::Num, u: V::Num) -> V::Num {
    let height = u * (V::Num::of(RADIUS_UNITS) * radius + V::Num::of(POINT_UNITS) * point.length());
    capped(height)
}

/// The `auto` step over a plane: from a point `on_surface` just put back on
/// the plane (`p − n·⟨p − A, n⟩`), out along the unit `normal` by `height`, a
/// bound of what rounding can do to it ([`plane_height`]).
/// (For any [`Vec3Num`]: the fast engine steps four points at once with this
/// body.)
#[inline(always)]
pub fn step_out<V: Vec3Num>(on_surface: V, normal: V, height: V::Num) -> V {
    on_surface + normal * capped(height)
}

/// The `auto` step's height at a point `on_surface` of a plane whose anchor
/// (its point nearest the origin) is `anchor`: `h = u·(10·‖S − A‖ + 3·‖S‖)`.
/// Followed as [`sphere_step`] follows a sphere's point, the projected point
/// needs `h > 8u·‖S − A‖ + 2u·‖S‖`: the dot product `⟨S − A, n⟩` is where its
/// error grows with the distance from the anchor, once when the point is
/// projected and once in the next test. `‖S‖` is at most the ray's origin plus
/// the distance it travelled, `‖O‖ + t`.
#[inline(always)]
pub fn plane_height<V: Vec3Num>(on_surface: V, anchor: V, u: V::Num) -> V::Num {
    let from_anchor = (on_surface - anchor).length();
    u * (V::Num::of(ANCHOR_UNITS) * from_anchor + V::Num::of(ORIGIN_UNITS) * on_surface.length())
}
// ANCHOR_END: step_off

/// The largest `auto` step: finite in float32 too, and beyond any step a scene
/// inside the limits (coordinates up to 1e15) can need. A point so far out that
/// the bound overflows (a plane met at t ~ 1e300) would step by ∞ and turn every
/// coordinate it touches into NaN.
pub const STEP_CAP: f64 = 1e38;

/// `height`, or [`STEP_CAP`] if it is larger (or ∞).
#[inline(always)]
fn capped<N: Num>(height: N) -> N {
    -(-height).max(-N::of(STEP_CAP))
}

/// How far round the terminator a shadow ray that starts the `auto` step `h` above
/// a sphere of radius `radius`, at its point `on_surface`, passes over it
/// ([`sphere_height`]): it enters the sphere at `|L·N| = s` only if
/// `(r + h)·√(1 − s²) ≤ r`, so for `s` below about `√(2h/r)` it clears it.
/// In float32 that is at least `√(14u)` = 9.1e-4. (This is the nominal step's
/// band, which the float32 warnings quote; the band `raystep accuracy` judges
/// with, `tools::accuracy::terminator_band`, takes the height the step's origin
/// actually has, the step plus the point's error, and adds the `8u` by which
/// the next test's `Δ/4` may be off.)
pub fn pass_over(u: f64, radius: f64, on_surface: crate::Vec3) -> f64 {
    (2.0 * sphere_height(on_surface, radius, u) / radius).sqrt()
}

/// The `scene` step: out along the unit `normal` by [`SCENE_FACTOR`] unit
/// roundoffs `u` of the larger of the surface's `magnitude` and the point's
/// largest coordinate. (For any [`Vec3Num`], as the fast engine computes it.)
#[inline(always)]
pub fn step_out_by_scene<V: Vec3Num>(on_surface: V, normal: V, magnitude: V::Num, u: V::Num) -> V {
    let scale = magnitude.max(on_surface.max_abs());
    let bound = V::Num::of(SCENE_FACTOR) * u * scale;
    on_surface + normal * bound
}

// ANCHOR: own_shadow
/// Is the point in its own sphere's shadow? A sphere hides the light from
/// every point of it where the light is below the horizon, `N·L < 0`, whatever
/// else lies on the way, so raystep's `auto` offset asks no shadow ray there.
/// The ray would say the same but near the terminator: started the step `h`
/// above the sphere, it passes over it for `|N·L|` up to about `√(2h/r)`
/// (chapter 9), where the sign of `N·L` errs only within a few unit roundoffs.
/// The tutorial's step (`fixed`) and the `scene` step keep asking the ray, as
/// the tutorial does; and a plane lights both of its faces.
#[inline(always)]
pub fn own_shadow<T: Real>(
    surface: &Object<T>,
    normal: T::Vec3,
    to_light: T::Vec3,
    offset: Offset,
) -> bool {
    offset == Offset::Auto
        && matches!(surface.shape, Shape::Sphere(_))
        && normal.dot(to_light) < T::of(0.0)
}
// ANCHOR_END: own_shadow

// ANCHOR: in_shadow
/// The tutorial's shadow test: cast a ray from the moved point `shifted` towards the
/// light (`to_light`, a unit vector). The point is in shadow if an object is hit
/// closer than the light, whose distance `light_distance` is measured from the
/// original hit point.
#[inline]
pub fn in_shadow<T: Real>(
    objects: &[Object<T>],
    shifted: T::Vec3,
    to_light: T::Vec3,
    light_distance: T,
    method: Method,
) -> bool {
    let shadow_ray = Ray {
        origin: shifted,
        direction: to_light,
    };
    blocked(objects, &shadow_ray, light_distance, method)
}
// ANCHOR_END: in_shadow

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sphere_shadows_its_own_dark_side_under_auto_only() {
        let ball = crate::bvh::test_ball(0.0, 0.0, 0.0, 1.0);
        let up = crate::Vec3::Y;
        let below = crate::Vec3::new(1.0, -1e-9, 0.0).normalize();
        let above = crate::Vec3::new(1.0, 1e-9, 0.0).normalize();
        assert!(own_shadow(&ball, up, below, Offset::Auto));
        assert!(!own_shadow(&ball, up, above, Offset::Auto));
        // The tutorial's step and the scene-sized one ask the shadow ray, as the
        // tutorial does.
        assert!(!own_shadow(&ball, up, below, Offset::TUTORIAL));
        assert!(!own_shadow(&ball, up, below, Offset::Scene));
        // A plane lights both of its faces.
        assert!(!own_shadow(&floor(), up, below, Offset::Auto));
    }

    /// A floor through the origin, facing up (its anchor is the origin, so its
    /// `magnitude` is 0).
    fn floor() -> Object {
        let mut floor = crate::bvh::test_ball(0.0, 0.0, 0.0, 1.0);
        floor.shape = Shape::Plane(crate::plane::Plane {
            point: crate::Vec3::ZERO,
            normal: crate::Vec3::Y,
        });
        floor
    }

    #[test]
    fn the_scene_step_grows_with_the_points_coordinates_where_the_surface_is_small() {
        // The floor's own numbers are all 0; the point's largest coordinate, 1e3,
        // sets the step: 8 unit roundoffs of it, ≈ 8.9e-13, straight up.
        let floor = floor();
        assert_eq!(floor.magnitude(), 0.0);
        let point = crate::Vec3::new(1e3, 0.0, -1e3);
        let moved = step_off(point, crate::Vec3::Y, &floor, Offset::Scene);
        let expected = SCENE_FACTOR * f64::UNIT_ROUNDOFF * 1e3;
        assert!((8.8e-13..9.0e-13).contains(&expected));
        assert_eq!(moved, crate::Vec3::new(1e3, expected, -1e3));
    }

    #[test]
    fn the_auto_step_over_a_plane_starts_from_the_point_put_back_on_it() {
        // In float32, far from the anchor: the bound `h` is ~9e-3 there. A point
        // computed 2h below the floor, or 2h above it, must first go back onto
        // the floor and then out by h: it ends at height h either way (within
        // the rounding of the sum), not at -h or 3h as a step from the point as
        // computed would.
        let floor = floor().cast::<f32>();
        type V = <f32 as Real>::Vec3;
        let on_floor = V::new(1e4, 0.0, 5e3);
        let u = f32::UNIT_ROUNDOFF;
        let h = plane_height(on_floor, V::ZERO, u);
        let size = on_floor.length();
        assert!((12.0 * u * size..14.0 * u * size).contains(&h));
        for side in [-2.0f32, 2.0] {
            let computed = on_floor + V::Y * (side * h);
            let moved = step_off(computed, V::Y, &floor, Offset::Auto);
            assert!(
                (moved.y - h).abs() <= 4.0 * u * size,
                "from {side}·h: height {} for h = {h}",
                moved.y
            );
            assert_eq!((moved.x, moved.z), (on_floor.x, on_floor.z));
        }
    }

    #[test]
    fn offsets_parse_and_print_back() {
        assert_eq!("fixed:1e-5".parse(), Ok(Offset::Fixed(1e-5)));
        assert_eq!("fixed:0".parse(), Ok(Offset::Fixed(0.0)));
        assert_eq!("auto".parse(), Ok(Offset::Auto));
        assert_eq!("scene".parse(), Ok(Offset::Scene));
        assert_eq!(Offset::Scene.to_string(), "scene");
        assert_eq!(Offset::TUTORIAL.to_string(), "fixed:1e-5");
        assert_eq!(Offset::default().to_string(), "auto");
        assert_eq!(Offset::Fixed(0.0).to_string(), "fixed:0");
        assert!("fixed:-1".parse::<Offset>().is_err());
        assert!("fixed:nan".parse::<Offset>().is_err());
        assert!("1e-5"
            .parse::<Offset>()
            .unwrap_err()
            .contains("expected auto, scene or fixed:VALUE"));
    }
}
