//! Reflection: the mirrored direction of a ray that meets a surface.

use crate::ray::Ray;
use crate::real::{Real, Vector};

// ANCHOR: reflect
/// The direction `d` mirrored about the unit normal `n`: `d − 2(d·n)n`.
#[inline]
pub fn reflect<T: Real>(direction: T::Vec3, normal: T::Vec3) -> T::Vec3 {
    direction - normal * (T::of(2.0) * direction.dot(normal))
}

/// The ray that continues the path: from the moved hit point `shifted`, along the
/// mirrored direction.
#[inline]
pub fn reflected_ray<T: Real>(shifted: T::Vec3, incoming: &Ray<T>, normal: T::Vec3) -> Ray<T> {
    Ray {
        origin: shifted,
        direction: reflect::<T>(incoming.direction, normal),
    }
}
// ANCHOR_END: reflect

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;

    #[test]
    fn a_ray_falling_at_45_degrees_leaves_at_45_degrees() {
        let d = Vec3::new(1.0, -1.0, 0.0).normalize();
        let r = reflect::<f64>(d, Vec3::Y);
        assert!((r - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-15);
    }

    #[test]
    fn reflection_keeps_the_length() {
        let d = Vec3::new(0.3, -0.5, 0.81).normalize();
        let n = Vec3::new(1.0, 2.0, -0.5).normalize();
        assert!((reflect::<f64>(d, n).length() - 1.0).abs() < 1e-15);
    }
}
