//! Shadows: is there anything between the hit point and the light?

use crate::ray::Ray;
use crate::scene::{blocked, Object};
use crate::Vec3;

/// How far the tutorial moves a hit point along the normal before casting a new
/// ray from it.
pub const TUTORIAL_STEP: f64 = 1e-5;

/// How far a hit point is moved along the normal before a shadow or reflected ray
/// leaves it (`--offset`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Offset {
    /// A fixed distance, whatever the scene's scale: `fixed:1e-5` is the tutorial's.
    Fixed(f64),
}

impl Default for Offset {
    fn default() -> Offset {
        Offset::Fixed(TUTORIAL_STEP)
    }
}

impl std::str::FromStr for Offset {
    type Err = String;

    /// `fixed:VALUE`, with VALUE a finite number, 0 or more (e.g. `fixed:1e-5`).
    fn from_str(text: &str) -> Result<Offset, String> {
        let value = text
            .strip_prefix("fixed:")
            .ok_or_else(|| format!("`{text}`: expected fixed:VALUE, e.g. fixed:1e-5"))?;
        match value.parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => Ok(Offset::Fixed(v)),
            _ => Err(format!(
                "`{value}`: the offset must be a finite number, 0 or more"
            )),
        }
    }
}

impl std::fmt::Display for Offset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Offset::Fixed(v) => write!(f, "fixed:{v:e}"),
        }
    }
}

// ANCHOR: step_off
/// The hit point moved a little along the surface normal. A ray cast from the
/// exact hit point could find the same surface again at a tiny distance, because
/// the computed point lies a rounding error inside or outside it ("shadow acne").
pub fn step_off(point: Vec3, normal: Vec3, offset: Offset) -> Vec3 {
    match offset {
        Offset::Fixed(step) => point + normal * step,
    }
}
// ANCHOR_END: step_off

// ANCHOR: in_shadow
/// The tutorial's shadow test: cast a ray from the moved point `shifted` towards the
/// light (`to_light`, a unit vector). The point is in shadow if an object is hit
/// closer than the light, whose distance `light_distance` is measured from the
/// original hit point.
pub fn in_shadow(objects: &[Object], shifted: Vec3, to_light: Vec3, light_distance: f64) -> bool {
    let shadow_ray = Ray {
        origin: shifted,
        direction: to_light,
    };
    blocked(objects, &shadow_ray, light_distance)
}
// ANCHOR_END: in_shadow

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_parse_and_print_back() {
        assert_eq!("fixed:1e-5".parse(), Ok(Offset::Fixed(1e-5)));
        assert_eq!("fixed:0".parse(), Ok(Offset::Fixed(0.0)));
        assert_eq!(Offset::default().to_string(), "fixed:1e-5");
        assert!("fixed:-1".parse::<Offset>().is_err());
        assert!("fixed:nan".parse::<Offset>().is_err());
        assert!("1e-5"
            .parse::<Offset>()
            .unwrap_err()
            .contains("expected fixed:VALUE"));
    }
}
