//! Reflection: the mirrored direction of a ray that meets a surface.

use crate::ray::Ray;
use crate::real::{Num, Real, Vec3Num};

// ANCHOR: reflect
/// The direction `d` mirrored about the unit normal `n`: `d − 2(d·n)n`. (Written
/// for any [`Vec3Num`]: one ray's vector, or four rays' in the fast engine.)
#[inline(always)]
pub fn reflect<V: Vec3Num>(direction: V, normal: V) -> V {
    direction - normal * (V::Num::of(2.0) * direction.dot(normal))
}

/// The ray that continues the path: from the moved hit point `shifted`, along the
/// mirrored direction.
#[inline]
pub fn reflected_ray<T: Real>(shifted: T::Vec3, incoming: &Ray<T>, normal: T::Vec3) -> Ray<T> {
    Ray {
        origin: shifted,
        direction: reflect(incoming.direction, normal),
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
        let r = reflect(d, Vec3::Y);
        assert!((r - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-15);
    }

    #[test]
    fn reflection_keeps_the_length() {
        let d = Vec3::new(0.3, -0.5, 0.81).normalize();
        let n = Vec3::new(1.0, 2.0, -0.5).normalize();
        assert!((reflect(d, n).length() - 1.0).abs() < 1e-15);
    }
}
