//! A ray: a starting point and a unit direction, `ray(t) = O + d·t`.

use crate::Vec3;

/// A half-line that starts at `origin` and runs along the unit vector `direction`.
///
/// Because `direction` has length 1, the parameter `t` of [`Ray::at`] is also the
/// distance from the origin: the depth buffer stores it as it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts (`t = 0`).
    pub origin: Vec3,
    /// Unit vector the ray travels along.
    pub direction: Vec3,
}

// ANCHOR: ray
impl Ray {
    /// The ray that starts at `origin` and passes through `target`.
    pub fn towards(origin: Vec3, target: Vec3) -> Ray {
        Ray {
            origin,
            direction: (target - origin).normalize(),
        }
    }

    /// The point at distance `t` along the ray: `O + d·t`.
    pub fn at(&self, t: f64) -> Vec3 {
        self.origin + self.direction * t
    }
}
// ANCHOR_END: ray

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn towards_gives_a_unit_direction_and_at_walks_along_it() {
        let ray = Ray::towards(Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.0, 2.0, -7.0));
        assert_eq!(ray.direction, Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(ray.at(0.0), ray.origin);
        assert_eq!(ray.at(2.5), Vec3::new(1.0, 2.0, 0.5));
    }
}
