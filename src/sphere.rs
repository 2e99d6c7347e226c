//! Ray-sphere intersection: the sphere equation, the quadratic and its
//! discriminant, computed two ways, side by side: the tutorial's textbook formula
//! and a careful one that keeps its accuracy where the textbook one loses it.

use crate::ray::Ray;
use crate::real::{Real, Vec3Num};

/// The points `X` with `‖X − C‖² = r²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere<T: Real = f64> {
    /// The centre `C`.
    pub center: T::Vec3,
    /// The radius `r`, greater than 0.
    pub radius: T,
}

/// How the quadratic is solved (`--intersect`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Method {
    /// The tutorial's: Δ = b² − 4c, roots (−b ± √Δ)/2.
    Naive,
    /// Ray Tracing Gems, chapter 7: Δ from the ray's closest approach to the centre,
    /// roots q and c/q (no subtraction of nearly equal numbers).
    #[default]
    Stable,
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Method::Naive => "naive",
            Method::Stable => "stable",
        })
    }
}

// ANCHOR: intersect
impl<T: Real> Sphere<T> {
    /// Distance along `ray` to where it enters the sphere, by the tutorial's rule:
    /// the sphere counts only when the ray crosses it twice (Δ > 0; a ray that only
    /// touches it does not count) and both crossings are in front of the origin. The
    /// smaller root is the distance.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray<T>, method: Method) -> Option<T> {
        // Both crossings can be in front only if the ray moves towards the centre.
        // When it does not, nothing is left to solve: this changes no answer, it
        // only skips the square root for spheres behind the ray.
        if ray.direction.dot(self.center - ray.origin) <= T::of(0.0) {
            return None;
        }
        let (near, far) = match method {
            Method::Naive => self.roots_naive(ray)?,
            Method::Stable => self.roots_stable(ray)?,
        };
        let zero = T::of(0.0);
        (near > zero && far > zero).then_some(near)
    }

    /// The outward unit normal at a point `p` on the surface.
    #[inline]
    pub fn normal_at(&self, p: T::Vec3) -> T::Vec3 {
        outward_normal(p, self.center)
    }
}

/// The unit vector from `center` to `p`: the outward normal of a sphere. (Written
/// for any [`Vec3Num`], so the fast engine computes it four at a time with this
/// body.)
#[inline(always)]
pub fn outward_normal<V: Vec3Num>(p: V, center: V) -> V {
    (p - center).normalize()
}
// ANCHOR_END: intersect

// ANCHOR: naive
impl<T: Real> Sphere<T> {
    /// The two roots of `t² + b·t + c = 0`, smaller first, if Δ > 0: the textbook
    /// way. `b = 2⟨d, O − C⟩`, `c = ‖O − C‖² − r²`, `Δ = b² − 4c`, `t = (−b ± √Δ)/2`.
    #[inline(always)]
    pub fn roots_naive(&self, ray: &Ray<T>) -> Option<(T, T)> {
        let (two, four) = (T::of(2.0), T::of(4.0));
        let oc = ray.origin - self.center;
        let b = two * ray.direction.dot(oc);
        let c = oc.length_squared() - self.radius * self.radius;
        let delta = b * b - four * c;
        // Δ > 0: two crossings (a NaN, from an infinite input, is a miss too).
        if delta > T::of(0.0) {
            let root = delta.sqrt();
            let t1 = (-b + root) / two;
            let t2 = (-b - root) / two;
            Some((t1.min(t2), t1.max(t2)))
        } else {
            None
        }
    }
}
// ANCHOR_END: naive

// ANCHOR: stable
impl<T: Real> Sphere<T> {
    /// The same two roots, computed so that no step subtracts nearly equal numbers.
    ///
    /// With `m = C − O` (from the origin to the centre) and `h = ⟨d, m⟩ = −b/2`
    /// (the distance along the ray to the point closest to the centre),
    /// the roots are `h ± √(Δ/4)`, and `Δ/4 = r² − ‖h·d − m‖²`: the radius squared
    /// minus the squared distance from the centre to that closest point. The
    /// textbook `b² − 4c` computes the same number as the difference of two large
    /// terms, which loses every digit when the sphere is small or far compared with
    /// `‖m‖`.
    ///
    /// `q = h + sign(h)·√(Δ/4)` adds two numbers of one sign; the other root is
    /// `c/q`, because the product of the roots is `c = ‖m‖² − r²`.
    #[inline(always)]
    pub fn roots_stable(&self, ray: &Ray<T>) -> Option<(T, T)> {
        let m = self.center - ray.origin;
        let h = ray.direction.dot(m);
        let closest = ray.direction * h - m;
        let r2 = self.radius * self.radius;
        let quarter_delta = r2 - closest.length_squared();
        if quarter_delta > T::of(0.0) {
            let q = h + h.signum() * quarter_delta.sqrt();
            let c = m.length_squared() - r2;
            let (t1, t2) = (c / q, q);
            // |q| = |h| + √(Δ/4) > 0, so c/q never divides by zero; the guard keeps
            // it so if that reasoning is ever broken. (A NaN passes it, and fails
            // the "both roots positive" test of `intersect` instead.)
            (q != T::of(0.0)).then(|| (t1.min(t2), t1.max(t2)))
        } else {
            None
        }
    }
}
// ANCHOR_END: stable

impl<T: Real> Sphere<T> {
    /// The textbook discriminant `Δ = b² − 4c` of [`Sphere::roots_naive`], as it
    /// computes it (for `raystep explain`).
    pub fn discriminant_naive(&self, ray: &Ray<T>) -> T {
        let oc = ray.origin - self.center;
        let b = T::of(2.0) * ray.direction.dot(oc);
        b * b - T::of(4.0) * (oc.length_squared() - self.radius * self.radius)
    }

    /// `Δ/4 = r² − ‖h·d − m‖²` of [`Sphere::roots_stable`], as it computes it.
    pub fn quarter_discriminant(&self, ray: &Ray<T>) -> T {
        let m = self.center - ray.origin;
        let h = ray.direction.dot(m);
        self.radius * self.radius - (ray.direction * h - m).length_squared()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;

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

    const METHODS: [Method; 2] = [Method::Naive, Method::Stable];

    #[test]
    fn a_ray_through_the_centre_hits_the_near_side() {
        for m in METHODS {
            assert_eq!(
                UNIT.intersect(&ray([0.0; 3], [0.0, 0.0, -1.0]), m),
                Some(4.0),
                "{m}"
            );
        }
    }

    #[test]
    fn a_ray_that_passes_beside_misses() {
        for m in METHODS {
            assert_eq!(
                UNIT.intersect(&ray([0.0; 3], [0.0, 1.0, -1.0]), m),
                None,
                "{m}"
            );
        }
    }

    #[test]
    fn a_tangent_ray_does_not_count() {
        // Δ = 0 exactly: the ray grazes the top of the sphere at y = 1.
        for m in METHODS {
            assert_eq!(
                UNIT.intersect(&ray([0.0, 1.0, 0.0], [0.0, 0.0, -1.0]), m),
                None,
                "{m}"
            );
        }
    }

    #[test]
    fn a_sphere_behind_or_around_the_origin_is_not_hit() {
        for m in METHODS {
            // Behind: both roots negative.
            assert_eq!(
                UNIT.intersect(&ray([0.0; 3], [0.0, 0.0, 1.0]), m),
                None,
                "{m}"
            );
            // Around: one root negative, one positive (the tutorial's rule ignores it).
            assert_eq!(
                UNIT.intersect(&ray([0.0, 0.0, -5.0], [1.0, 0.0, 0.0]), m),
                None,
                "{m}"
            );
        }
    }

    #[test]
    fn both_methods_give_both_roots() {
        let r = ray([0.0, 0.5, 0.0], [0.0, 0.0, -1.0]);
        let exact = (5.0 - 0.75f64.sqrt(), 5.0 + 0.75f64.sqrt());
        for m in METHODS {
            let (near, far) = match m {
                Method::Naive => UNIT.roots_naive(&r),
                Method::Stable => UNIT.roots_stable(&r),
            }
            .unwrap();
            assert!(
                (near - exact.0).abs() < 1e-14 && (far - exact.1).abs() < 1e-14,
                "{m}"
            );
        }
    }

    #[test]
    fn only_the_stable_method_sees_a_far_unit_sphere_in_float32() {
        // A unit sphere 10,000 away, a ray aimed 0.5 off its centre: a sure hit.
        let far: Sphere<f32> = Sphere {
            center: glam::Vec3::new(0.0, 0.0, -10_000.0),
            radius: 1.0,
        };
        let r: Ray<f32> = Ray::towards(glam::Vec3::ZERO, glam::Vec3::new(0.5, 0.0, -10_000.0));
        let t = far.intersect(&r, Method::Stable).expect("stable: hit");
        assert!((t - (10_000.0 - 0.75f32.sqrt())).abs() < 0.01, "{t}");
        // b² and 4c are both about 4e8; float32 keeps 7 digits, so their difference,
        // 4·(r² − 0.25) = 3, is lost in rounding.
        assert_eq!(far.intersect(&r, Method::Naive), None);
    }

    #[test]
    fn the_normal_is_unit_and_points_outwards() {
        let n = UNIT.normal_at(Vec3::new(0.0, 0.0, -4.0));
        assert_eq!(n, Vec3::new(0.0, 0.0, 1.0));
    }

    /// The tutorial's rule applied to the roots alone, without the shortcut.
    fn by_the_roots<T: Real>(s: &Sphere<T>, r: &Ray<T>, m: Method) -> Option<T> {
        let (near, far) = match m {
            Method::Naive => s.roots_naive(r)?,
            Method::Stable => s.roots_stable(r)?,
        };
        (near > T::of(0.0) && far > T::of(0.0)).then_some(near)
    }

    #[test]
    fn the_shortcut_for_spheres_behind_changes_no_answer() {
        // Origins inside, on, beside, in front of and behind the sphere; directions
        // towards, away from, across and grazing it; both precisions.
        let s32 = Sphere::<f32> {
            center: glam::Vec3::new(0.0, 0.0, -5.0),
            radius: 1.0,
        };
        let mut checked = 0;
        let mut skipped = 0;
        for (ox, oy, oz) in [
            (0.0, 0.0, 0.0),
            (0.0, 0.0, -5.0),
            (0.0, 1.0, -5.0),
            (0.3, -0.2, -4.5),
            (0.0, 0.0, -10.0),
            (2.0, 1.0, -5.0),
            (0.0, 0.0, -4.0),
            (1e3, -2e2, 7e2),
        ] {
            for i in 0..400 {
                let a = i as f64 * 0.157;
                let b = (i % 37) as f64 * 0.087 - 1.6;
                let d = [a.cos() * b.cos(), b.sin(), a.sin() * b.cos()];
                for m in METHODS {
                    let r = ray([ox, oy, oz], d);
                    let expected = by_the_roots(&UNIT, &r, m);
                    assert_eq!(UNIT.intersect(&r, m), expected, "{m} {r:?}");
                    let r32 = Ray::<f32> {
                        origin: glam::Vec3::new(ox as f32, oy as f32, oz as f32),
                        direction: glam::Vec3::from(d.map(|c| c as f32)).normalize(),
                    };
                    assert_eq!(s32.intersect(&r32, m), by_the_roots(&s32, &r32, m));
                    checked += 1;
                    let towards = r.direction.dot(UNIT.center - r.origin);
                    skipped += usize::from(towards <= 0.0 && m == Method::Stable);
                }
            }
        }
        // The comparison covered rays the shortcut answers and rays it does not.
        assert!(
            skipped > 1000 && skipped < checked / 2,
            "{skipped} of {checked}"
        );
    }
}
