//! Shadows: is there anything between the hit point and the light?

use crate::ray::Ray;
use crate::real::{Num, Real, Vec3Num};
use crate::scene::{blocked, Object};
use crate::sphere::Method;

/// How far the tutorial moves a hit point along the normal before casting a new
/// ray from it.
pub const TUTORIAL_STEP: f64 = 1e-5;

/// The `auto` offset steps out by this many unit roundoffs of the size of the
/// numbers the surface is computed from. It has to cover the error of the point put
/// back on the surface and the error of the next ray's first root, a few units
/// each. Measured with the property tests `a_stepped_off_origin_is_outside_its_sphere_at_any_scale`
/// and `a_ray_leaving_a_plane_never_meets_it_again_at_any_scale` (`tests/accuracy.rs`,
/// `RAYSTEP_PROPTEST_CASES=20000`, scales 1e-3 to 1e4): a factor of 1 fails in
/// float32, 2 fails in float64, 4 passes; 8 leaves a margin of 2. A larger factor
/// costs accuracy the other way: shadow rays start too far out and pass over their
/// own sphere at the terminator (in float32, a step about four times this one gave
/// 6.55 % wrong shadows on `scenes/stress/far-sphere.toml`, against 3.42 %).
pub const AUTO_FACTOR: f64 = 8.0;

/// How far a hit point is moved along the normal before a shadow or reflected ray
/// leaves it (`--offset`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Offset {
    /// A fixed distance, whatever the scene's scale: `fixed:1e-5` is the tutorial's.
    Fixed(f64),
    /// Put the point back on the surface, then step out by a bound of its rounding
    /// error, which grows with the size of the numbers involved: right at every scale.
    #[default]
    Auto,
}

impl Offset {
    /// The tutorial's step, `fixed:1e-5`.
    pub const TUTORIAL: Offset = Offset::Fixed(TUTORIAL_STEP);
}

impl std::str::FromStr for Offset {
    type Err = String;

    /// `auto`, or `fixed:VALUE` with VALUE from 0 to 1e15 (e.g. `fixed:1e-5`).
    fn from_str(text: &str) -> Result<Offset, String> {
        if text == "auto" {
            return Ok(Offset::Auto);
        }
        let value = text
            .strip_prefix("fixed:")
            .ok_or_else(|| format!("`{text}`: expected auto or fixed:VALUE, e.g. fixed:1e-5"))?;
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
            Offset::Auto => f.write_str("auto"),
        }
    }
}

// ANCHOR: step_off
/// The hit point moved a little along the surface normal. A ray cast from the
/// exact hit point could find the same surface again at a tiny distance, because
/// the computed point lies a rounding error inside or outside it ("shadow acne").
#[inline]
pub fn step_off<T: Real>(
    point: T::Vec3,
    normal: T::Vec3,
    surface: &Object<T>,
    offset: Offset,
) -> T::Vec3 {
    match offset {
        Offset::Fixed(step) => point + normal * T::of(step),
        Offset::Auto => {
            let on_surface = surface.surface_point(point, normal);
            step_out(on_surface, normal, surface.magnitude(), T::UNIT_ROUNDOFF)
        }
    }
}

/// The `auto` step: from a point computed to be on a surface whose numbers are of
/// size `magnitude`, out along the unit `normal` by `AUTO_FACTOR` unit roundoffs
/// `u` of the larger of that size and the point's. (For any [`Vec3Num`]: the fast
/// engine steps four points at once with this body.)
#[inline(always)]
pub fn step_out<V: Vec3Num>(on_surface: V, normal: V, magnitude: V::Num, u: V::Num) -> V {
    let scale = magnitude.max(on_surface.max_abs());
    let bound = V::Num::of(AUTO_FACTOR) * u * scale;
    on_surface + normal * bound
}
// ANCHOR_END: step_off

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
    fn offsets_parse_and_print_back() {
        assert_eq!("fixed:1e-5".parse(), Ok(Offset::Fixed(1e-5)));
        assert_eq!("fixed:0".parse(), Ok(Offset::Fixed(0.0)));
        assert_eq!("auto".parse(), Ok(Offset::Auto));
        assert_eq!(Offset::TUTORIAL.to_string(), "fixed:1e-5");
        assert_eq!(Offset::default().to_string(), "auto");
        assert_eq!(Offset::Fixed(0.0).to_string(), "fixed:0");
        assert!("fixed:-1".parse::<Offset>().is_err());
        assert!("fixed:nan".parse::<Offset>().is_err());
        assert!("1e-5"
            .parse::<Offset>()
            .unwrap_err()
            .contains("expected auto or fixed:VALUE"));
    }
}
