//! The Blinn-Phong reflection model: ambient + diffuse + specular.

use crate::real::{Num, Real, Vec3Num};
use crate::scene::{Light, Material};

/// Where the viewer of the highlight stands (`--viewer`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Viewer {
    /// The camera, on every bounce: the tutorial's rule.
    #[default]
    Camera,
    /// The origin of the ray that found the point: on a bounce, the surface it was
    /// reflected from, which is where that light travels to.
    RayOrigin,
}

// ANCHOR: terms_struct
/// The three terms of Blinn-Phong at one point, and the factors they come from
/// (what `raystep explain` prints and the `diffuse` and `specular` buffers hold).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Terms<T: Real = f64> {
    /// `ka·la`: light that reaches everything.
    pub ambient: T::Vec3,
    /// `kd·ld·(L·N)`.
    pub diffuse: T::Vec3,
    /// `ks·ls·(N·H)^(shininess/4)`.
    pub specular: T::Vec3,
    /// `L·N`, the cosine of the angle between the light and the normal.
    pub l_dot_n: T,
    /// `N·H`, clamped at 0: how close the half vector is to the normal.
    pub n_dot_h: T,
    /// `(N·H)^(shininess/4)`, the highlight's strength.
    pub highlight: T,
}

impl<T: Real> Terms<T> {
    /// ambient + diffuse + specular.
    #[inline]
    pub fn sum(&self) -> T::Vec3 {
        self.ambient + self.diffuse + self.specular
    }
}

// ANCHOR_END: terms_struct

// ANCHOR: terms
/// The terms of Blinn-Phong at a point.
///
/// `normal` is the surface normal N, `to_light` the unit vector L towards the light
/// and `to_viewer` the unit vector V towards the viewer (the camera, unless
/// `--viewer ray-origin`). With the half vector `H = normalize(L + V)`:
///
/// `ka·la + kd·ld·(L·N) + ks·ls·(N·H)^(shininess/4)`
///
/// As in the tutorial, `L·N` is not clamped: with the `auto` step and the `shadow`
/// stage on, a lit point of a sphere always faces the light, and with the
/// tutorial's fixed step a few points just past the terminator are lit with a
/// slightly negative `L·N` (chapter 8).
/// `N·H` is clamped at 0 before the power: a negative base with a fractional
/// exponent would give NaN, and on the tutorial's scene the clamp moves no value by
/// more than 2.2e-12 (chapter 8).
#[inline]
pub fn terms<T: Real>(
    material: &Material<T>,
    light: &Light<T>,
    normal: T::Vec3,
    to_light: T::Vec3,
    to_viewer: T::Vec3,
) -> Terms<T> {
    let (l_dot_n, n_dot_h) = factors(normal, to_light, to_viewer);
    let highlight = power(n_dot_h, material.shininess / T::of(4.0));
    Terms {
        ambient: material.ambient * light.ambient,
        diffuse: material.diffuse * light.diffuse * l_dot_n,
        specular: material.specular * light.specular * highlight,
        l_dot_n,
        n_dot_h,
        highlight,
    }
}

/// `L·N`, and `N·H` clamped at 0, with the half vector `H = normalize(L + V)`:
/// the geometry of Blinn-Phong. (For any [`Vec3Num`]: the fast engine computes it
/// four points at a time with this body.)
#[inline(always)]
pub fn factors<V: Vec3Num>(normal: V, to_light: V, to_viewer: V) -> (V::Num, V::Num) {
    let l_dot_n = to_light.dot(normal);
    let half = (to_light + to_viewer).normalize();
    let n_dot_h = normal.dot(half).max(V::Num::of(0.0));
    (l_dot_n, n_dot_h)
}
// ANCHOR_END: terms

/// `x` to the power `e`, `x ≥ 0`. A whole exponent up to 256 (the tutorial's
/// shininess 100 gives 25) is computed by repeated squaring, several times faster
/// than the general `powf` and within a few units in the last place of it.
#[inline]
pub fn power<T: Real>(x: T, e: T) -> T {
    match whole_exponent(e) {
        Some(n) => whole_power(x, n),
        None => x.powf(e),
    }
}

/// `x` to the whole power `n` by repeated squaring: `x^25 = x · x⁸ · x¹⁶`, one
/// factor `x^(2^k)` for each bit `k` of `n` that is set, lowest first. That is the
/// order Rust's `powi` multiplies in, so the result is `powi`'s to the bit. (For
/// any [`Num`]: the fast engine raises four lanes at once with this body.)
#[inline(always)]
pub fn whole_power<N: Num>(x: N, n: u32) -> N {
    let (mut result, mut square, mut bits) = (N::of(1.0), x, n);
    loop {
        if bits & 1 == 1 {
            result = result * square;
        }
        bits >>= 1;
        if bits == 0 {
            return result;
        }
        square = square * square;
    }
}

/// The exponent `e` as a whole number from 0 to 256, when [`power`] takes
/// [`whole_power`] for it.
#[inline]
pub fn whole_exponent<T: Real>(e: T) -> Option<u32> {
    let e = e.to_f64();
    // `as` saturates (a NaN or a negative number gives 0), so `n` is `e` exactly
    // when `e` is a whole number from 0 to 2³² − 1. (A conversion and a compare:
    // `fract` is a call into libm on a plain x86-64 build.)
    let n = e as u32;
    (f64::from(n) == e && n <= 256).then_some(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;

    #[test]
    fn whole_power_is_powi_to_the_bit() {
        let bases: [f64; 9] = [0.0, 1e-300, 0.1, 0.5, 0.731, 0.99999, 1.0, 1.5, 3.7];
        for n in 0..=256u32 {
            for &x in &bases {
                let expected = x.powi(n as i32);
                assert_eq!(whole_power(x, n).to_bits(), expected.to_bits(), "{x}^{n}");
                let x32 = x as f32;
                let expected32 = x32.powi(n as i32);
                assert_eq!(
                    whole_power(x32, n).to_bits(),
                    expected32.to_bits(),
                    "{x32}^{n}"
                );
            }
        }
    }

    const WHITE: Light = Light {
        position: Vec3::ZERO,
        ambient: Vec3::ONE,
        diffuse: Vec3::ONE,
        specular: Vec3::ONE,
    };

    fn material(ambient: f64, diffuse: f64, specular: f64) -> Material {
        Material {
            ambient: Vec3::splat(ambient),
            diffuse: Vec3::splat(diffuse),
            specular: Vec3::splat(specular),
            shininess: 100.0,
            reflection: 0.0,
        }
    }

    #[test]
    fn head_on_light_and_viewer_give_every_term_in_full() {
        let n = Vec3::Z;
        let c = terms(&material(0.1, 0.5, 0.25), &WHITE, n, n, n).sum();
        assert!((c - Vec3::splat(0.85)).abs().max_element() < 1e-15);
    }

    #[test]
    fn diffuse_follows_the_cosine_of_the_light_angle() {
        let n = Vec3::Z;
        let l = Vec3::new(0.6, 0.0, 0.8);
        // No specular, so only ambient + kd·(L·N) remains.
        let c = terms(&material(0.0, 1.0, 0.0), &WHITE, n, l, n).sum();
        assert!((c.x - 0.8).abs() < 1e-15);
    }

    #[test]
    fn a_half_vector_behind_the_surface_gives_no_highlight_and_no_nan() {
        let n = Vec3::Z;
        let c = terms(&material(0.0, 0.0, 1.0), &WHITE, n, -Vec3::X, -Vec3::Z).sum();
        assert_eq!(c, Vec3::ZERO);
    }
}
