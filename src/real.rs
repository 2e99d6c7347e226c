//! Float32 or float64: the tracer is written once, for any [`Real`].
//!
//! `Real` is the few operations the tracer needs from a number, and
//! [`Vector`] the few it needs from a 3-vector; `f32` (with glam's `Vec3`) and
//! `f64` (with glam's `DVec3`) provide them. The types the tracer computes in (`Ray`,
//! the objects, the light, the hit, `Tracer`) take the precision as a parameter
//! that defaults to `f64`, so `Ray` means `Ray<f64>`; what is set up once (the
//! camera, the scene, the settings, the BVH) does not take it.
//!
//! The formulas without a branch (the normal, the step off a surface, the half
//! vector, the mirrored direction, the camera's grid) ask less: only the
//! arithmetic of [`Num`] and [`Vec3Num`]. Four numbers in SIMD lanes have that
//! arithmetic too, so the fast engine computes those formulas with the very
//! bodies the book shows: change one, and both engines change.

use std::fmt::Debug;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

use glam::DVec3;

/// The arithmetic of a formula without a branch: what one number and four
/// numbers side by side in SIMD lanes both have.
pub trait Num:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The number nearest to `x` (in every lane).
    fn of(x: f64) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// The larger of two (a NaN gives the other).
    fn max(self, other: Self) -> Self;
}

/// A 3-vector of [`Num`]s: the arithmetic of a formula without a branch.
pub trait Vec3Num:
    Copy + Add<Output = Self> + Sub<Output = Self> + Neg<Output = Self> + Mul<Self::Num, Output = Self>
{
    /// The number type of the components.
    type Num: Num;
    /// Dot product, `x·x' + y·y' + z·z'` added in that order.
    fn dot(self, other: Self) -> Self::Num;
    /// Squared length.
    fn length_squared(self) -> Self::Num;
    /// Euclidean length.
    fn length(self) -> Self::Num;
    /// The unit vector in the same direction, `v · (1 / ‖v‖)`.
    fn normalize(self) -> Self;
    /// The largest absolute value of a component.
    fn max_abs(self) -> Self::Num;
}

/// A floating-point number the tracer can compute in.
pub trait Real: Num + Debug + PartialOrd + Send + Sync + 'static {
    /// The 3-vector of this precision.
    type Vec3: Vector<Self>;
    /// The unit roundoff u: every basic operation is exact up to a factor (1 ± u).
    const UNIT_ROUNDOFF: Self;
    /// `f32` or `f64`.
    const NAME: &'static str;
    /// The same value in float64 (exact).
    fn to_f64(self) -> f64;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `self` to the power `e`.
    fn powf(self, e: Self) -> Self;
    /// The smaller of two.
    fn min(self, other: Self) -> Self;
    /// 1 with the sign of `self` (+1 for +0 and for −0).
    fn signum(self) -> Self;
    /// Neither infinite nor NaN.
    fn is_finite(self) -> bool;
}

/// A 3-vector of [`Real`]s: a point, a direction or a colour.
pub trait Vector<T: Num>:
    Vec3Num<Num = T> + Debug + PartialEq + Send + Sync + Mul<Self, Output = Self> + AddAssign
{
    /// (0, 0, 0).
    const ZERO: Self;
    /// The vector (x, y, z).
    fn new(x: T, y: T, z: T) -> Self;
    /// Distance between two points.
    fn distance(self, other: Self) -> T;
    /// Each component clamped to [0, 1]; a NaN stays NaN, so that a bug shows
    /// instead of turning black.
    fn clamp01(self) -> Self;
    /// The vector nearest to a float64 one.
    fn of(v: DVec3) -> Self;
    /// The same vector in float64 (exact).
    fn to_f64(self) -> DVec3;
}

macro_rules! real {
    ($t:ty, $v:ty, $name:literal) => {
        impl Num for $t {
            #[inline(always)]
            fn of(x: f64) -> $t {
                x as $t
            }
            #[inline(always)]
            fn sqrt(self) -> $t {
                <$t>::sqrt(self)
            }
            #[inline(always)]
            fn max(self, other: $t) -> $t {
                <$t>::max(self, other)
            }
        }

        impl Real for $t {
            type Vec3 = $v;
            const UNIT_ROUNDOFF: $t = <$t>::EPSILON / 2.0;
            const NAME: &'static str = $name;
            fn to_f64(self) -> f64 {
                self as f64
            }
            fn abs(self) -> $t {
                <$t>::abs(self)
            }
            fn powf(self, e: $t) -> $t {
                <$t>::powf(self, e)
            }
            fn min(self, other: $t) -> $t {
                <$t>::min(self, other)
            }
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
            fn signum(self) -> $t {
                if self >= 0.0 {
                    1.0
                } else {
                    -1.0
                }
            }
        }

        impl Vec3Num for $v {
            type Num = $t;
            #[inline(always)]
            fn dot(self, other: $v) -> $t {
                <$v>::dot(self, other)
            }
            #[inline(always)]
            fn length_squared(self) -> $t {
                <$v>::length_squared(self)
            }
            #[inline(always)]
            fn length(self) -> $t {
                <$v>::length(self)
            }
            #[inline(always)]
            fn normalize(self) -> $v {
                <$v>::normalize(self)
            }
            #[inline(always)]
            fn max_abs(self) -> $t {
                self.abs().max_element()
            }
        }

        impl Vector<$t> for $v {
            const ZERO: $v = <$v>::ZERO;
            fn new(x: $t, y: $t, z: $t) -> $v {
                <$v>::new(x, y, z)
            }
            fn distance(self, other: $v) -> $t {
                <$v>::distance(self, other)
            }
            fn clamp01(self) -> $v {
                let clip = |c: $t| if c.is_nan() { c } else { c.clamp(0.0, 1.0) };
                <$v>::new(clip(self.x), clip(self.y), clip(self.z))
            }
            fn of(v: DVec3) -> $v {
                <$v>::new(v.x as $t, v.y as $t, v.z as $t)
            }
            fn to_f64(self) -> DVec3 {
                DVec3::new(self.x as f64, self.y as f64, self.z as f64)
            }
        }
    };
}

real!(f32, glam::Vec3, "f32");
real!(f64, glam::DVec3, "f64");

/// Which [`Real`] a render computes in (`--precision`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Precision {
    /// float32: 24-bit significands, unit roundoff 6e-8.
    F32,
    /// float64: 53-bit significands, unit roundoff 1.1e-16 (the tutorial's, in Python).
    #[default]
    F64,
}

impl std::fmt::Display for Precision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        })
    }
}
