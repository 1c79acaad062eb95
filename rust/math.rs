//! `sin_cos` written here, without branches on its main range, so that the sweep's lanes
//! ([`crate::simd::F64x4`]) compute four in vector instructions (libm has no vector
//! version), and the free link's scalar path calls the same function, so that a lane's
//! results stay the scalar path's bit for bit.
//!
//! Range reduction plus a truncated series; every coefficient is 1/n!, rounded once to f64,
//! and pi/2 was split here from pi computed to 78 digits (Machin's formula,
//! `pi = 16 atan(1/5) - 4 atan(1/239)`):
//! `x = k pi/2 + r`, `|r| <= pi/4`, with pi/2 in three parts (33, 33 and 53 bits: Cody &
//! Waite, "Software Manual for the Elementary Functions", 1980), so that `k * PIO2_1` and
//! `k * PIO2_2` are exact for `|k| < 2^20`; then the Taylor series of sin to r^15 and of cos
//! to r^16 (the first omitted terms are below 2^-53 of the result on `|r| <= pi/4`:
//! `(pi/4)^16 / 17! = 6e-17`), and cos's last step written as in fdlibm's `__kernel_cos`
//! (`w = 1 - z/2`, then `(1 - w) - z/2` recovers the rounding of w); the quadrant `k mod 4`
//! picks and signs the two. For `|x| > 1e5` it is libm's.
//!
//! Measured against glibc (the tests): within 1 ulp for `|x| <= 100`, 2 ulp up to 1e5.
//! Cost (criterion `math` group of `benches/free_link.rs`): about libm's for one call, and
//! four lanes in one AVX2 evaluation.
//!
//! A `pow` written the same way (ln as a sum of two doubles, Dekker's product, exp by
//! Taylor series) was within 1 ulp of glibc but 4x its time for one call (39 against 9.6
//! ns per call): the scalar path would have lost more than the lanes gain, so `pow` is
//! libm's, lane by lane.

/// pi/2 = PIO2_1 + PIO2_2 + PIO2_3 (+ 2^-122): 33, 33 and 53 significant bits.
const PIO2_1: f64 = 1.5707963267341256;
const PIO2_2: f64 = 6.077100506303966e-11;
const PIO2_3: f64 = 2.0222662487959506e-21;
/// 2 / pi.
const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI;
use crate::forces::Real;
use crate::simd::{F64x4, LANES};

/// 1.5 * 2^52: adding it rounds to an integer, whose value the low bits then hold.
const MAGIC: f64 = 6755399441055744.0;
/// 2^-27: below it, sin x rounds to x and cos x to 1.
const TINY: f64 = 7.450580596923828e-9;
/// Largest |x| of `sin_cos`'s own range (`|k| < 2^20` with room).
pub const SIN_COS_LIMIT: f64 = 1e5;

/// What the functions here need of a number type beyond [`Real`]: its bits as integers,
/// for `f64` and, lane by lane, for [`F64x4`] (each operation is one lane-wise map, which
/// the compiler turns into one vector instruction).
pub trait Lane: Real {
    /// The bits, as integers (u64 per lane).
    type U: Copy;
    /// The bits.
    fn bits(self) -> Self::U;
    /// The number with these bits.
    fn from_bits(u: Self::U) -> Self;
    /// `f(u)` in each lane.
    fn umap(u: Self::U, f: impl Fn(u64) -> u64) -> Self::U;
    /// `a` where bit `bit` of `u` is set, else `b`.
    fn select_bit(u: Self::U, bit: u64, a: Self, b: Self) -> Self;
}

impl Lane for f64 {
    type U = u64;
    #[inline(always)]
    fn bits(self) -> u64 {
        self.to_bits()
    }
    #[inline(always)]
    fn from_bits(u: u64) -> f64 {
        f64::from_bits(u)
    }
    #[inline(always)]
    fn umap(u: u64, f: impl Fn(u64) -> u64) -> u64 {
        f(u)
    }
    #[inline(always)]
    fn select_bit(u: u64, bit: u64, a: f64, b: f64) -> f64 {
        if u & bit != 0 {
            a
        } else {
            b
        }
    }
}

impl Lane for F64x4 {
    type U = [u64; LANES];
    #[inline(always)]
    fn bits(self) -> [u64; LANES] {
        let a = self.0;
        [
            a[0].to_bits(),
            a[1].to_bits(),
            a[2].to_bits(),
            a[3].to_bits(),
        ]
    }
    #[inline(always)]
    fn from_bits(u: [u64; LANES]) -> F64x4 {
        F64x4([
            f64::from_bits(u[0]),
            f64::from_bits(u[1]),
            f64::from_bits(u[2]),
            f64::from_bits(u[3]),
        ])
    }
    #[inline(always)]
    fn umap(u: [u64; LANES], f: impl Fn(u64) -> u64) -> [u64; LANES] {
        [f(u[0]), f(u[1]), f(u[2]), f(u[3])]
    }
    #[inline(always)]
    fn select_bit(u: [u64; LANES], bit: u64, a: F64x4, b: F64x4) -> F64x4 {
        let (a, b) = (a.0, b.0);
        let one = |i: usize| if u[i] & bit != 0 { a[i] } else { b[i] };
        F64x4([one(0), one(1), one(2), one(3)])
    }
}

/// `x` rounded to the nearest integer (|x| < 2^51), as a number and as the integer's bits
/// in the low bits of `x + MAGIC`'s.
#[inline(always)]
fn round_int<L: Lane>(x: L) -> (L, L::U) {
    let magic = L::splat(MAGIC);
    let shifted = x + magic;
    (shifted - magic, shifted.bits())
}

/// `c[0] + c[1] x + ... + c[6] x^6`, given `x^2` and `x^4` (Estrin's scheme).
#[inline(always)]
fn estrin7<L: Lane>(x: L, x2: L, x4: L, c: &[f64; 7]) -> L {
    let k = |i: usize| L::splat(c[i]);
    let p01 = k(0) + k(1) * x;
    let p23 = k(2) + k(3) * x;
    let p45 = k(4) + k(5) * x;
    (p01 + x2 * p23) + x4 * (p45 + x2 * k(6))
}

/// `sin_cos` on its own range (`|x| <= SIN_COS_LIMIT`), without branches.
#[inline(always)]
pub fn sin_cos_core<L: Lane>(x: L) -> (L, L) {
    let c = L::splat;
    let (k, n) = round_int(x * c(TWO_OVER_PI));
    let r = ((x - k * c(PIO2_1)) - k * c(PIO2_2)) - k * c(PIO2_3);
    let z = r * r;
    // sin r = r + r z P(z), P = -1/3! + z/5! - ... - z^6/15!; cos r = 1 - z/2 + z^2 Q(z),
    // Q = 1/4! - z/6! + ... + z^6/16!. Each by Estrin's scheme (pairs, then z^2 and z^4):
    // a short chain of dependent operations, since the free link's evaluation waits for
    // it (Horner's 7 steps measured 11 % slower per impact than libm).
    let z2 = z * z;
    let z4 = z2 * z2;
    let p = estrin7(
        z,
        z2,
        z4,
        &[
            -1.0 / 6.0,
            1.0 / 120.0,
            -1.0 / 5040.0,
            1.0 / 362880.0,
            -1.0 / 39916800.0,
            1.0 / 6227020800.0,
            -1.0 / 1307674368000.0,
        ],
    );
    let s = r + r * (z * p);
    let q = estrin7(
        z,
        z2,
        z4,
        &[
            1.0 / 24.0,
            -1.0 / 720.0,
            1.0 / 40320.0,
            -1.0 / 3628800.0,
            1.0 / 479001600.0,
            -1.0 / 87178291200.0,
            1.0 / 20922789888000.0,
        ],
    );
    let hz = c(0.5) * z;
    let one = c(1.0);
    let w = one - hz;
    let co = w + (((one - w) - hz) + z2 * q);
    // Quadrant n mod 4 (the low bits of n's, MAGIC's low bits being 0):
    // (sin, cos) = (s, c), (c, -s), (-s, -c), (-c, s).
    let sin = L::select_bit(n, 1, co, s);
    let cos = L::select_bit(n, 1, s, co);
    let sin = L::select_bit(n, 2, -sin, sin);
    let n1 = L::umap(n, |u| u.wrapping_add(1));
    let cos = L::select_bit(n1, 2, -cos, cos);
    (sin, cos)
}

/// `(sin x, cos x)`.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() < TINY {
        // What the series gives there (z/2 is below half an ulp of 1; -0 comes out +0),
        // without waiting for it: a vertical rod evaluates sin_cos(0) at every stage.
        (x + 0.0, 1.0)
    } else if x.abs() <= SIN_COS_LIMIT {
        sin_cos_core(x)
    } else {
        x.sin_cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place between two finite f64 of one sign.
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        (a.to_bits() as i64).abs_diff(b.to_bits() as i64)
    }

    /// Largest ulp distance from glibc over a deterministic spread of arguments.
    fn worst(n: usize, arg: impl Fn(f64) -> f64, f: impl Fn(f64) -> (f64, f64)) -> u64 {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut worst = 0;
        for _ in 0..n {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let u = (seed >> 11) as f64 / (1u64 << 53) as f64;
            let (mine, libm) = f(arg(u));
            worst = worst.max(ulps(mine, libm));
        }
        worst
    }

    #[test]
    fn sin_cos_is_within_one_ulp_of_libm() {
        for (lo, hi) in [(-0.8, 0.8), (-7.0, 7.0), (-100.0, 100.0)] {
            let arg = |u: f64| lo + (hi - lo) * u;
            let s = worst(200_000, arg, |x| (sin_cos(x).0, x.sin()));
            let c = worst(200_000, arg, |x| (sin_cos(x).1, x.cos()));
            assert!(s <= 1 && c <= 1, "[{lo}, {hi}]: sin {s} ulp, cos {c} ulp");
        }
        // Far out, the reduction's third part runs out of bits: 2 ulp.
        let arg = |u: f64| -1e5 + 2e5 * u;
        assert!(worst(200_000, arg, |x| (sin_cos(x).0, x.sin())) <= 2);
        // The quadrants' signs and exact points.
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        for k in -8..8 {
            let x = k as f64 * std::f64::consts::FRAC_PI_2 + 0.3;
            let (s, c) = sin_cos(x);
            assert!(
                (s - x.sin()).abs() < 1e-15 && (c - x.cos()).abs() < 1e-15,
                "{x}"
            );
        }
        assert_eq!(sin_cos(1e6).0.to_bits(), 1e6f64.sin().to_bits());
        // The shortcut below 2^-27 is the series' own result, bit for bit.
        for x in [0.0, -0.0, 1e-300, 3e-9, -7.4e-9, TINY * 0.999_999] {
            let (s, c) = sin_cos_core(x);
            assert_eq!(
                (s.to_bits(), c.to_bits()),
                ((x + 0.0).to_bits(), 1f64.to_bits())
            );
            let fast = sin_cos(x);
            assert_eq!(
                (fast.0.to_bits(), fast.1.to_bits()),
                (s.to_bits(), c.to_bits())
            );
        }
    }
}
