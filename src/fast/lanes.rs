//! Four numbers at once: the SIMD lanes the [packet tracer](crate::fast::packet)
//! computes in.
//!
//! [`Lanes`] is to four rays what [`Real`] is to one: the few operations the
//! packet tracer needs, for float64 ([`F64x4`], a plain array of four that the
//! compiler turns into two SSE2 registers or one AVX register, whichever the code
//! is compiled for) and float32 (wide's `f32x4`, one SSE register). [`V3`] is a
//! 3-vector whose components are lanes: four vectors side by side.
//!
//! Every operation here is the IEEE one, rounded once, exactly as the scalar
//! operation is, and every formula of [`V3`] adds and multiplies in the order glam
//! does. So each lane computes, bit for bit, what the scalar tracer computes for
//! its ray. (That rules out fused multiply-add, which rounds once where the scalar
//! code rounds twice.)
//!
//! A comparison gives a *mask*: a value of the same type whose lanes have every
//! bit set (true) or none (false). [`Lanes::bits`] turns it into a 4-bit number for
//! the control flow, [`Lanes::select`] picks lane by lane.

use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use crate::real::{Num, Real, Vec3Num, Vector};

/// A [`Real`] that the fast engine can put four to a SIMD register: the lane
/// type of its precision. (The book's number trait knows nothing of lanes.)
pub trait Laned: Real {
    /// Four numbers of this precision in SIMD lanes.
    type Lanes: Lanes<Self>;
}

impl Laned for f32 {
    type Lanes = wide::f32x4;
}

impl Laned for f64 {
    type Lanes = F64x4;
}

/// The number of lanes: rays traced together.
pub const WIDTH: usize = 4;

/// The bits of every lane.
pub const ALL: u32 = (1 << WIDTH) - 1;

/// `[f(0), f(1), f(2), f(3)]`: `std::array::from_fn` for the lanes, written
/// out so that it is always inlined (the packet tracer's AVX build compiles only
/// what is inlined into it for AVX).
#[inline(always)]
pub fn each<R>(mut f: impl FnMut(usize) -> R) -> [R; WIDTH] {
    [f(0), f(1), f(2), f(3)]
}

/// Four numbers of float64 (the limits of a packet's search, whatever its
/// precision).
pub type F64s = <f64 as Laned>::Lanes;

/// Four numbers of float32 (the BVH's box tests).
pub type F32s = <f32 as Laned>::Lanes;

/// The lanes `l` in precision `L`: exact into a wider precision, rounded to
/// nearest into a narrower one.
#[inline(always)]
pub fn convert<T: Laned, L: Laned>(l: T::Lanes) -> L::Lanes {
    let l = l.to_array();
    L::Lanes::from_array(each(|i| L::of(l[i].to_f64())))
}

/// Four numbers of precision `T` computed together.
pub trait Lanes<T: Real>:
    Num + Debug + Send + Sync + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// The same number in every lane.
    fn splat(x: T) -> Self;
    /// Lane `i` from `a[i]`.
    fn from_array(a: [T; WIDTH]) -> Self;
    /// The lanes as an array.
    fn to_array(self) -> [T; WIDTH];
    /// The smaller of two, lane by lane (as [`Real::min`]: a NaN gives the other).
    fn min(self, other: Self) -> Self;
    /// The smaller of two, lane by lane, where neither is a NaN (a lane with a NaN
    /// may come out as either): one instruction, where [`Lanes::min`] takes four.
    fn fast_min(self, other: Self) -> Self;
    /// The larger of two, lane by lane, where neither is a NaN (see
    /// [`Lanes::fast_min`]).
    fn fast_max(self, other: Self) -> Self;
    /// Absolute value of each lane.
    fn abs(self) -> Self;
    /// Mask of `self > other`.
    fn gt(self, other: Self) -> Self;
    /// Mask of `self < other`.
    fn lt(self, other: Self) -> Self;
    /// Mask of `self >= other`.
    fn ge(self, other: Self) -> Self;
    /// Mask of `self != other` (true for a NaN).
    fn ne(self, other: Self) -> Self;
    /// Where the mask `self` is true, `yes`; elsewhere `no`.
    fn select(self, yes: Self, no: Self) -> Self;
    /// Bit `i` set where lane `i` of the mask `self` is true.
    fn bits(self) -> u32;
    /// The mask whose lane `i` is true where bit `i` of `bits` is set.
    fn mask(bits: u32) -> Self;
}

macro_rules! lanes {
    ($t:ty, $w:ty, $bits:ty) => {
        impl Num for $w {
            #[inline(always)]
            fn of(x: f64) -> Self {
                <$w>::splat(x as $t)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$w>::sqrt(self)
            }
            #[inline(always)]
            fn max(self, other: Self) -> Self {
                <$w>::max(self, other)
            }
        }

        impl Lanes<$t> for $w {
            #[inline(always)]
            fn splat(x: $t) -> Self {
                <$w>::splat(x)
            }
            #[inline(always)]
            fn from_array(a: [$t; WIDTH]) -> Self {
                <$w>::new(a)
            }
            #[inline(always)]
            fn to_array(self) -> [$t; WIDTH] {
                <$w>::to_array(self)
            }
            #[inline(always)]
            fn min(self, other: Self) -> Self {
                <$w>::min(self, other)
            }
            #[inline(always)]
            fn fast_min(self, other: Self) -> Self {
                <$w>::fast_min(self, other)
            }
            #[inline(always)]
            fn fast_max(self, other: Self) -> Self {
                <$w>::fast_max(self, other)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                <$w>::abs(self)
            }
            #[inline(always)]
            fn gt(self, other: Self) -> Self {
                self.simd_gt(other)
            }
            #[inline(always)]
            fn lt(self, other: Self) -> Self {
                self.simd_lt(other)
            }
            #[inline(always)]
            fn ge(self, other: Self) -> Self {
                self.simd_ge(other)
            }
            #[inline(always)]
            fn ne(self, other: Self) -> Self {
                self.simd_ne(other)
            }
            #[inline(always)]
            fn select(self, yes: Self, no: Self) -> Self {
                <$w>::select(self, yes, no)
            }
            #[inline(always)]
            fn bits(self) -> u32 {
                self.to_bitmask()
            }
            #[inline(always)]
            fn mask(bits: u32) -> Self {
                let lane =
                    |i: usize| <$t>::from_bits(if bits >> i & 1 == 1 { <$bits>::MAX } else { 0 });
                <$w>::new([lane(0), lane(1), lane(2), lane(3)])
            }
        }
    };
}

lanes!(f32, wide::f32x4, u32);

/// Four float64 numbers as a plain array, each operation written lane by lane.
///
/// The compiler turns each of these loops into SIMD instructions as wide as the
/// function it lands in is compiled for: two SSE2 registers of two lanes on a plain
/// x86-64 build, one AVX register of four inside
/// [`Fast::packet_row`](crate::fast::Fast::packet_row) on a processor that
/// has AVX (chosen when the program runs), NEON pairs on ARM. The results are the
/// same in every case: each lane is the IEEE operation, rounded once.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F64x4(pub [f64; WIDTH]);

impl F64x4 {
    /// `f` of each lane.
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> F64x4 {
        F64x4(each(|i| f(self.0[i])))
    }

    /// `f` of each pair of lanes.
    #[inline(always)]
    fn zip(self, o: F64x4, f: impl Fn(f64, f64) -> f64) -> F64x4 {
        let (a, b) = (self.0, o.0);
        F64x4(each(|i| f(a[i], b[i])))
    }

    /// `f` of each pair of lanes' bits.
    #[inline(always)]
    fn zip_bits(self, o: F64x4, f: impl Fn(u64, u64) -> u64) -> F64x4 {
        self.zip(o, |a, b| f64::from_bits(f(a.to_bits(), b.to_bits())))
    }

    /// The mask of `test` on each pair of lanes. (Written as a negated 0 or 1,
    /// which the compiler makes one comparison instruction; an `if` would not be.)
    #[inline(always)]
    fn test(self, o: F64x4, test: impl Fn(f64, f64) -> bool) -> F64x4 {
        self.zip(o, |a, b| {
            f64::from_bits(u64::from(test(a, b)).wrapping_neg())
        })
    }
}

/// The mask of every 4-bit number, for [`Lanes::mask`]: one load.
static F64_MASKS: [F64x4; 16] = {
    let mut masks = [F64x4([0.0; WIDTH]); 16];
    let mut bits = 0;
    while bits < 16 {
        let mut i = 0;
        while i < WIDTH {
            if bits >> i & 1 == 1 {
                masks[bits].0[i] = f64::from_bits(u64::MAX);
            }
            i += 1;
        }
        bits += 1;
    }
    masks
};

macro_rules! f64x4_operator {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F64x4 {
            type Output = F64x4;
            #[inline(always)]
            fn $method(self, o: F64x4) -> F64x4 {
                self.zip(o, |a, b| a $op b)
            }
        }
    };
}

f64x4_operator!(Add, add, +);
f64x4_operator!(Sub, sub, -);
f64x4_operator!(Mul, mul, *);
f64x4_operator!(Div, div, /);

impl Neg for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn neg(self) -> F64x4 {
        self.map(|a| -a)
    }
}

impl BitAnd for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn bitand(self, o: F64x4) -> F64x4 {
        self.zip_bits(o, |a, b| a & b)
    }
}

impl BitOr for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn bitor(self, o: F64x4) -> F64x4 {
        self.zip_bits(o, |a, b| a | b)
    }
}

impl Not for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn not(self) -> F64x4 {
        self.map(|a| f64::from_bits(!a.to_bits()))
    }
}

impl Num for F64x4 {
    #[inline(always)]
    fn of(x: f64) -> Self {
        F64x4([x; WIDTH])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        self.zip(o, |a, b| {
            let max = if a > b { a } else { b };
            if b.is_nan() {
                a
            } else {
                max
            }
        })
    }
}

impl Lanes<f64> for F64x4 {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        F64x4([x; WIDTH])
    }
    #[inline(always)]
    fn from_array(a: [f64; WIDTH]) -> Self {
        F64x4(a)
    }
    #[inline(always)]
    fn to_array(self) -> [f64; WIDTH] {
        self.0
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        // The processor's minimum (`a < b ? a : b`), and the other where `o` is a
        // NaN: Rust's `f64::min` for every NaN.
        self.zip(o, |a, b| {
            let min = if a < b { a } else { b };
            if b.is_nan() {
                a
            } else {
                min
            }
        })
    }
    #[inline(always)]
    fn fast_min(self, o: Self) -> Self {
        self.zip(o, |a, b| if a < b { a } else { b })
    }
    #[inline(always)]
    fn fast_max(self, o: Self) -> Self {
        self.zip(o, |a, b| if a > b { a } else { b })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f64::abs)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Self {
        self.test(o, |a, b| a > b)
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Self {
        self.test(o, |a, b| a < b)
    }
    #[inline(always)]
    fn ge(self, o: Self) -> Self {
        self.test(o, |a, b| a >= b)
    }
    #[inline(always)]
    fn ne(self, o: Self) -> Self {
        self.test(o, |a, b| a != b)
    }
    #[inline(always)]
    fn select(self, yes: Self, no: Self) -> Self {
        (self & yes) | (!self & no)
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        // A mask's lanes are all ones (a NaN) or all zeros (+0), so "is lane i a
        // NaN" is its bit: one comparison and one `vmovmskpd` in the AVX build.
        // Gathered as sign bits (shifts and ors), the compiler made some twenty
        // instructions of a comparison and-ed with another mask.
        let nan = |i: usize| u32::from(self.0[i].is_nan());
        nan(0) | nan(1) << 1 | nan(2) << 2 | nan(3) << 3
    }
    #[inline(always)]
    fn mask(bits: u32) -> Self {
        F64_MASKS[(bits & ALL) as usize]
    }
}

/// A 3-vector of lanes of precision `T`: lane `i` of `x`, `y` and `z` is vector `i`.
#[derive(Clone, Copy, Debug)]
pub struct V3<T: Laned> {
    /// The x components.
    pub x: T::Lanes,
    /// The y components.
    pub y: T::Lanes,
    /// The z components.
    pub z: T::Lanes,
}

impl<T: Laned> V3<T> {
    /// The vector of lanes from its three components.
    #[inline(always)]
    pub fn new(x: T::Lanes, y: T::Lanes, z: T::Lanes) -> V3<T> {
        V3 { x, y, z }
    }

    /// The same vector `v` in every lane.
    #[inline(always)]
    pub fn splat(v: T::Vec3) -> V3<T> {
        let [x, y, z] = components::<T>(v);
        V3::new(T::Lanes::splat(x), T::Lanes::splat(y), T::Lanes::splat(z))
    }

    /// The vectors in precision `L` ([`convert`] of each coordinate).
    #[inline(always)]
    pub fn convert<L: Laned>(&self) -> V3<L> {
        V3::new(
            convert::<T, L>(self.x),
            convert::<T, L>(self.y),
            convert::<T, L>(self.z),
        )
    }

    /// Vector `i` in lane `i`.
    #[inline(always)]
    pub fn from_vectors(v: [T::Vec3; WIDTH]) -> V3<T> {
        let c = each(|i| components::<T>(v[i]));
        V3::new(
            T::Lanes::from_array(each(|i| c[i][0])),
            T::Lanes::from_array(each(|i| c[i][1])),
            T::Lanes::from_array(each(|i| c[i][2])),
        )
    }

    /// The vector in lane `i`, for each lane.
    #[inline(always)]
    pub fn to_vectors(self) -> [T::Vec3; WIDTH] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        each(|i| T::Vec3::new(x[i], y[i], z[i]))
    }

    /// Dot product, lane by lane: `x·x' + y·y' + z·z'`, added in that order.
    #[inline(always)]
    pub fn dot(self, o: V3<T>) -> T::Lanes {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Squared length.
    #[inline(always)]
    pub fn length_squared(self) -> T::Lanes {
        self.dot(self)
    }

    /// Euclidean length.
    #[inline(always)]
    pub fn length(self) -> T::Lanes {
        self.dot(self).sqrt()
    }

    /// The unit vector in the same direction: `v · (1 / ‖v‖)`, as glam computes it.
    #[inline(always)]
    pub fn normalize(self) -> V3<T> {
        let recip = T::Lanes::splat(T::of(1.0)) / self.length();
        self.scale(recip)
    }

    /// The largest absolute value of a component, as glam's `abs().max_element()`.
    #[inline(always)]
    pub fn max_abs(self) -> T::Lanes {
        let max = |a: T::Lanes, b: T::Lanes| a.gt(b).select(a, b);
        max(self.x.abs(), max(self.y.abs(), self.z.abs()))
    }

    /// Where the mask `m` is true, `yes`; elsewhere `no`.
    #[inline(always)]
    pub fn select(m: T::Lanes, yes: V3<T>, no: V3<T>) -> V3<T> {
        V3::new(
            m.select(yes.x, no.x),
            m.select(yes.y, no.y),
            m.select(yes.z, no.z),
        )
    }
}

/// The three components of a vector (exactly: through float64 and back).
#[inline(always)]
pub fn components<T: Laned>(v: T::Vec3) -> [T; 3] {
    let d = v.to_f64();
    [T::of(d.x), T::of(d.y), T::of(d.z)]
}

impl<T: Laned> Add for V3<T> {
    type Output = V3<T>;
    #[inline(always)]
    fn add(self, o: V3<T>) -> V3<T> {
        V3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<T: Laned> Sub for V3<T> {
    type Output = V3<T>;
    #[inline(always)]
    fn sub(self, o: V3<T>) -> V3<T> {
        V3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl<T: Laned> Neg for V3<T> {
    type Output = V3<T>;
    #[inline(always)]
    fn neg(self) -> V3<T> {
        V3::new(-self.x, -self.y, -self.z)
    }
}

/// Each component times the lane's number.
impl<T: Laned> Mul<T::Lanes> for V3<T> {
    type Output = V3<T>;
    #[inline(always)]
    fn mul(self, s: T::Lanes) -> V3<T> {
        V3::new(self.x * s, self.y * s, self.z * s)
    }
}

impl<T: Laned> V3<T> {
    /// `self * s`, by name.
    #[inline(always)]
    pub fn scale(self, s: T::Lanes) -> V3<T> {
        self * s
    }
}

/// The arithmetic of the book's formulas without a branch, four vectors at once.
impl<T: Laned> Vec3Num for V3<T> {
    type Num = T::Lanes;
    #[inline(always)]
    fn dot(self, o: V3<T>) -> T::Lanes {
        V3::dot(self, o)
    }
    #[inline(always)]
    fn length_squared(self) -> T::Lanes {
        V3::length_squared(self)
    }
    #[inline(always)]
    fn length(self) -> T::Lanes {
        V3::length(self)
    }
    #[inline(always)]
    fn normalize(self) -> V3<T> {
        V3::normalize(self)
    }
    #[inline(always)]
    fn max_abs(self) -> T::Lanes {
        V3::max_abs(self)
    }
}

/// `x` to the whole power `n[i]` in lane `i`, by the repeated squaring of
/// [`crate::shade::blinn_phong::whole_power`] (Rust's `powi`: multiply the result
/// by `x^(2^k)` for each set bit `k` of `n`, lowest first), so that each lane
/// rounds as the book's engine does.
#[inline(always)]
pub fn powi<T: Laned>(x: T::Lanes, n: [u32; WIDTH]) -> T::Lanes {
    let one = T::Lanes::splat(T::of(1.0));
    if n.iter().all(|&k| k == n[0]) {
        // One exponent for every lane (all four hit the same object): the book's
        // body, no masks.
        return crate::shade::blinn_phong::whole_power(x, n[0]);
    }
    let mut result = one;
    let mut square = x;
    let mut n = n;
    loop {
        let odd = n.iter().enumerate().fold(0, |m, (i, &k)| m | (k & 1) << i);
        if odd != 0 {
            result = T::Lanes::mask(odd).select(result * square, result);
        }
        n = each(|i| n[i] >> 1);
        if n == [0; WIDTH] {
            return result;
        }
        square = square * square;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;

    #[test]
    fn masks_and_bits_agree() {
        for bits in 0..=ALL {
            assert_eq!(<F64x4 as Lanes<f64>>::mask(bits).bits(), bits);
            assert_eq!(<wide::f32x4 as Lanes<f32>>::mask(bits).bits(), bits);
        }
        let a = F64x4::from_array([1.0, 2.0, f64::NAN, 4.0]);
        let b = <F64x4 as Lanes<f64>>::splat(2.0);
        assert_eq!(Lanes::<f64>::gt(a, b).bits(), 0b1000);
        assert_eq!(Lanes::<f64>::ne(a, b).bits(), 0b1101);
    }

    #[test]
    fn min_and_max_treat_a_nan_as_rusts_do() {
        let a = F64x4::from_array([f64::NAN, 1.0, 3.0, f64::NAN]);
        let b = F64x4::from_array([2.0, f64::NAN, 1.0, f64::NAN]);
        let (lo, hi) = (
            Lanes::<f64>::min(a, b).to_array(),
            <F64x4 as Num>::max(a, b).to_array(),
        );
        let (a, b) = (a.to_array(), b.to_array());
        for i in 0..3 {
            assert_eq!(lo[i], a[i].min(b[i]), "lane {i}");
            assert_eq!(hi[i], a[i].max(b[i]), "lane {i}");
        }
        assert!(lo[3].is_nan() && hi[3].is_nan());
    }

    #[test]
    fn vector_formulas_round_as_glams_do() {
        // Awkward numbers, so that another order of operations would round
        // differently somewhere among them.
        let vs: [Vec3; 4] = [
            Vec3::new(0.1, -0.7, 1e-3),
            Vec3::new(1e8, 3.3, -2.2e-9),
            Vec3::new(-0.333, 0.333, 0.334),
            Vec3::new(7.0, 1e-300, -1e300),
        ];
        let lanes: V3<f64> = V3::from_vectors(vs);
        let other = V3::from_vectors([vs[3], vs[0], vs[1], vs[2]]);
        let (n, d, m) = (
            lanes.normalize().to_vectors(),
            lanes.dot(other).to_array(),
            lanes.max_abs().to_array(),
        );
        for i in 0..4 {
            let o = [vs[3], vs[0], vs[1], vs[2]][i];
            assert_eq!(n[i], vs[i].normalize(), "normalize, lane {i}");
            assert_eq!(d[i].to_bits(), vs[i].dot(o).to_bits(), "dot, lane {i}");
            assert_eq!(m[i], vs[i].abs().max_element(), "max_abs, lane {i}");
        }
    }

    #[test]
    fn powi_rounds_as_rusts_powi_does() {
        let xs = [0.999_123_456_789, 0.5, 0.87, 1.000_000_1];
        for n in 0..=256u32 {
            // Four exponents, and one exponent in every lane.
            for ns in [[n, (n * 7) % 257, 25, 256 - n], [n; 4]] {
                let got = powi::<f64>(F64x4(xs), ns).to_array();
                let got32 = powi::<f32>(wide::f32x4::new(xs.map(|x| x as f32)), ns).to_array();
                for i in 0..4 {
                    let x = std::hint::black_box(xs[i]);
                    let k = std::hint::black_box(ns[i] as i32);
                    assert_eq!(got[i].to_bits(), x.powi(k).to_bits(), "{x}^{k}");
                    let x32 = x as f32;
                    assert_eq!(got32[i].to_bits(), x32.powi(k).to_bits(), "{x}^{k} f32");
                }
            }
        }
    }
}
