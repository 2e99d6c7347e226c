//! The floor. The tutorial has no planes: its floor is a "fake plane", a sphere so
//! large (radius 8999.3) that the part the camera sees looks flat. raystep also
//! offers a true plane, a point and a normal, so the two can be compared.

use crate::ray::Ray;
use crate::real::{Real, Vec3Num};

/// The points `X` with `⟨X − P, n⟩ = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane<T: Real = f64> {
    /// Any point `P` of the plane.
    pub point: T::Vec3,
    /// The unit normal `n`.
    pub normal: T::Vec3,
}

// ANCHOR: intersect
impl<T: Real> Plane<T> {
    /// Distance along `ray` to the plane, if the ray crosses it in front of the
    /// origin: `t = ⟨P − O, n⟩ / ⟨d, n⟩`. A ray parallel to the plane misses, and
    /// so does one so nearly parallel that `t` overflows to infinity.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray<T>) -> Option<T> {
        let zero = T::of(0.0);
        let facing = ray.direction.dot(self.normal);
        if facing == zero {
            return None;
        }
        let t = (self.point - ray.origin).dot(self.normal) / facing;
        (t > zero && t.is_finite()).then_some(t)
    }

    /// The unit normal on the side the ray came from: a plane has two faces and
    /// both are lit the same way.
    #[inline]
    pub fn normal_towards(&self, ray: &Ray<T>) -> T::Vec3 {
        if ray.direction.dot(self.normal) > T::of(0.0) {
            -self.normal
        } else {
            self.normal
        }
    }
}
// ANCHOR_END: intersect

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;

    const FLOOR: Plane = Plane {
        point: Vec3::new(0.0, -1.0, 0.0),
        normal: Vec3::Y,
    };

    #[test]
    fn a_ray_looking_down_hits_at_the_height_over_the_cosine() {
        let ray = Ray::towards(Vec3::ZERO, Vec3::new(0.0, -1.0, -1.0));
        let t = FLOOR.intersect(&ray).unwrap();
        assert!((t - 2f64.sqrt()).abs() < 1e-15);
        assert_eq!(FLOOR.normal_towards(&ray), Vec3::Y);
    }

    #[test]
    fn parallel_and_receding_rays_miss() {
        assert_eq!(FLOOR.intersect(&Ray::towards(Vec3::ZERO, Vec3::X)), None);
        assert_eq!(FLOOR.intersect(&Ray::towards(Vec3::ZERO, Vec3::Y)), None);
    }

    #[test]
    fn seen_from_below_the_normal_faces_down() {
        let ray = Ray::towards(Vec3::new(0.0, -2.0, 0.0), Vec3::new(0.0, 0.0, 0.0));
        assert_eq!(FLOOR.intersect(&ray), Some(1.0));
        assert_eq!(FLOOR.normal_towards(&ray), -Vec3::Y);
    }
}
