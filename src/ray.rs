//! A ray: a starting point and a unit direction, `ray(t) = O + d·t`.

use crate::real::{Real, Vec3Num};

/// A half-line that starts at `origin` and runs along the unit vector `direction`,
/// computed in precision `T` (float64 unless said otherwise).
///
/// Because `direction` has length 1, the parameter `t` of [`Ray::at`] is also the
/// distance from the origin: the depth buffer stores it as it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray<T: Real = f64> {
    /// Where the ray starts (`t = 0`).
    pub origin: T::Vec3,
    /// Unit vector the ray travels along.
    pub direction: T::Vec3,
}

// ANCHOR: ray
impl<T: Real> Ray<T> {
    /// The ray from `origin` along the unit vector `direction`.
    #[inline]
    pub fn new(origin: T::Vec3, direction: T::Vec3) -> Ray<T> {
        Ray { origin, direction }
    }

    /// The ray that starts at `origin` and passes through `target`.
    #[inline]
    pub fn towards(origin: T::Vec3, target: T::Vec3) -> Ray<T> {
        Ray {
            origin,
            direction: (target - origin).normalize(),
        }
    }

    /// The point at distance `t` along the ray: `O + d·t`.
    #[inline]
    pub fn at(&self, t: T) -> T::Vec3 {
        self.origin + self.direction * t
    }
}
// ANCHOR_END: ray

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;

    #[test]
    fn towards_gives_a_unit_direction_and_at_walks_along_it() {
        let ray: Ray = Ray::towards(Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.0, 2.0, -7.0));
        assert_eq!(ray.direction, Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(ray.at(0.0), ray.origin);
        assert_eq!(ray.at(2.5), Vec3::new(1.0, 2.0, 0.5));
    }
}
