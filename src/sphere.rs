//! Ray-sphere intersection: the sphere equation, the quadratic and its discriminant.

use crate::ray::Ray;
use crate::Vec3;

/// The points `X` with `‖X − C‖² = r²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// The centre `C`.
    pub center: Vec3,
    /// The radius `r`, greater than 0.
    pub radius: f64,
}

// ANCHOR: intersect
impl Sphere {
    /// Distance along `ray` to where it enters the sphere, by the tutorial's rule.
    ///
    /// Putting `O + d·t` into the sphere equation gives `a·t² + b·t + c = 0` with
    /// `a = ‖d‖² = 1`, `b = 2⟨d, O − C⟩`, `c = ‖O − C‖² − r²` and the discriminant
    /// `Δ = b² − 4c`. Δ < 0: the ray misses; Δ = 0: it only touches the sphere,
    /// which does not count; Δ > 0: two crossings. The sphere counts as hit only
    /// when both roots are positive (it lies wholly in front of the origin), and the
    /// smaller root is the distance.
    pub fn intersect(&self, ray: &Ray) -> Option<f64> {
        let oc = ray.origin - self.center;
        let b = 2.0 * ray.direction.dot(oc);
        let c = oc.length_squared() - self.radius * self.radius;
        let delta = b * b - 4.0 * c;
        if delta > 0.0 {
            let root = delta.sqrt();
            let t1 = (-b + root) / 2.0;
            let t2 = (-b - root) / 2.0;
            if t1 > 0.0 && t2 > 0.0 {
                return Some(t1.min(t2));
            }
        }
        None
    }

    /// The outward unit normal at a point `p` on the surface.
    pub fn normal_at(&self, p: Vec3) -> Vec3 {
        (p - self.center).normalize()
    }
}
// ANCHOR_END: intersect

#[cfg(test)]
mod tests {
    use super::*;

    const UNIT: Sphere = Sphere {
        center: Vec3::new(0.0, 0.0, -5.0),
        radius: 1.0,
    };

    fn ray(origin: [f64; 3], direction: [f64; 3]) -> Ray {
        Ray {
            origin: Vec3::from(origin),
            direction: Vec3::from(direction).normalize(),
        }
    }

    #[test]
    fn a_ray_through_the_centre_hits_the_near_side() {
        assert_eq!(UNIT.intersect(&ray([0.0; 3], [0.0, 0.0, -1.0])), Some(4.0));
    }

    #[test]
    fn a_ray_that_passes_beside_misses() {
        assert_eq!(UNIT.intersect(&ray([0.0; 3], [0.0, 1.0, -1.0])), None);
    }

    #[test]
    fn a_tangent_ray_does_not_count() {
        // Δ = 0 exactly: the ray grazes the top of the sphere at y = 1.
        assert_eq!(
            UNIT.intersect(&ray([0.0, 1.0, 0.0], [0.0, 0.0, -1.0])),
            None
        );
    }

    #[test]
    fn a_sphere_behind_or_around_the_origin_is_not_hit() {
        // Behind: both roots negative.
        assert_eq!(UNIT.intersect(&ray([0.0; 3], [0.0, 0.0, 1.0])), None);
        // Around: one root negative, one positive (the tutorial's rule ignores it).
        assert_eq!(
            UNIT.intersect(&ray([0.0, 0.0, -5.0], [1.0, 0.0, 0.0])),
            None
        );
    }

    #[test]
    fn the_normal_is_unit_and_points_outwards() {
        let n = UNIT.normal_at(Vec3::new(0.0, 0.0, -4.0));
        assert_eq!(n, Vec3::new(0.0, 0.0, 1.0));
    }
}
