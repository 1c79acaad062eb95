//! The numbers of the arithmetic (the ground floor): the [`Real`] trait every term and the
//! free link's mechanics compute in, for `f64` and for four f64 lanes, the number type of the
//! sweep's lanes ([`crate::dynamics::rod_lanes`]).
//!
//! `F64x4` is a plain `[f64; 4]` whose operations are written lane by lane with the same IEEE
//! operation as `f64` (no fused multiply-add: Rust never contracts `a * b + c`), so a lane's
//! arithmetic is bit for bit what the scalar path computes. The vector instructions come from
//! the compiler: the lanes' step is compiled twice, once for the baseline target and once
//! with AVX2 enabled (`#[target_feature]`), and the CPU picks one at run time ([`avx2`]).
//! The scalar path's lean step (the same step in one lane, `f64`) is dispatched the same
//! way: with AVX2's three-operand encodings it needs fewer register copies (a thesis-law
//! impact about 8 % faster, bit for bit the same). One wheel thus runs on any x86-64 (SSE2,
//! two lanes per instruction), uses 256-bit registers where the CPU has them, and builds
//! unchanged for arm64 (NEON, two lanes per instruction).
//!
//! `sin_cos` and `powf` are libm's, lane by lane, by default: so a lane's result is the
//! scalar path's bit for bit. With `GRANRS_FAST_LANES=1` the lanes call glibc's four-lane
//! versions instead where the CPU has AVX2 ([`vector_calls`], which says what that gains
//! and what it costs in agreement with the scalar path).
//!
//! Why no crate: `wide` picks its instructions when the crate is compiled
//! (`cfg(target_feature)`), so a baseline x86-64 wheel would never use AVX2; `pulp` does
//! dispatch at run time, but its vectors are values of an instruction-set token's
//! associated types, with no arithmetic operators, so the terms' generic arithmetic
//! (`a * b + c` over [`Real`]) could not run on them without wrapping every value with its
//! token. Neither has a vector `pow` or `sin_cos` either (glibc's are in [`vector_calls`]).

use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

pub mod vector_calls;

/// The number type of a term's arithmetic: `f64` for one scene; [`F64x4`] for
/// four scenes at once, one per SIMD lane (the sweep's lanes, `dynamics::rod_lanes`). Only
/// the operations the terms and the free link's mechanics use; a lane type does each lane
/// by lane with the same IEEE operation as `f64`, so that a lane's result is bit for bit the
/// scalar one.
pub trait Real:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Scenes per value: 1 for `f64`, 4 for the lanes' `F64x4`.
    const LANES: usize;
    /// The value `x` (in every lane).
    fn splat(x: f64) -> Self;
    /// `self^e` (libm's; in the lanes, glibc's four-lane call with `GRANRS_FAST_LANES=1`).
    fn powf(self, e: Self) -> Self;
    /// `1 / self`.
    fn recip(self) -> Self;
    /// `self * b + c` rounded once (a fused multiply-add: one instruction where the CPU
    /// has FMA and the code is compiled for it, else libm's `fma`, the same result).
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// The larger of the two (per lane).
    fn max(self, other: Self) -> Self;
    /// The smaller of the two (per lane).
    fn min(self, other: Self) -> Self;
    /// `a` where `self > 0`, else `b` (per lane: a blend, no branch).
    fn select_pos(self, a: Self, b: Self) -> Self;
    /// Whether it is zero (in every lane).
    fn all_zero(self) -> bool;
    /// Sine and cosine (libm's; in the lanes, glibc's four-lane calls with
    /// `GRANRS_FAST_LANES=1`).
    fn sin_cos(self) -> (Self, Self);
    /// Hyperbolic tangent (libm's, in each lane).
    fn tanh(self) -> Self;
    /// Lane `i`'s value (`f64`: itself).
    fn lane(self, i: usize) -> f64;
}

impl Real for f64 {
    const LANES: usize = 1;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn powf(self, e: Self) -> Self {
        f64::powf(self, e)
    }
    #[inline(always)]
    fn recip(self) -> Self {
        1.0 / self
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        f64::mul_add(self, b, c)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64::max(self, other)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        f64::min(self, other)
    }
    #[inline(always)]
    fn select_pos(self, a: Self, b: Self) -> Self {
        if self > 0.0 {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn all_zero(self) -> bool {
        self == 0.0
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        f64::sin_cos(self)
    }
    #[inline(always)]
    fn tanh(self) -> Self {
        f64::tanh(self)
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        debug_assert_eq!(i, 0, "one lane");
        self
    }
}

/// Number of lanes.
pub const LANES: usize = 4;

/// Four f64 lanes.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(32))]
pub struct F64x4(pub [f64; LANES]);

impl F64x4 {
    /// Lane by lane `f(a_i)`.
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        let a = self.0;
        F64x4([f(a[0]), f(a[1]), f(a[2]), f(a[3])])
    }

    /// Lane by lane `f(a_i, b_i)`.
    #[inline(always)]
    fn zip(self, b: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let (a, b) = (self.0, b.0);
        F64x4([f(a[0], b[0]), f(a[1], b[1]), f(a[2], b[2]), f(a[3], b[3])])
    }
}

macro_rules! binary {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F64x4 {
            type Output = F64x4;
            #[inline(always)]
            fn $method(self, b: F64x4) -> F64x4 {
                self.zip(b, |x, y| x $op y)
            }
        }
    };
}

binary!(Add, add, +);
binary!(Sub, sub, -);
binary!(Mul, mul, *);
binary!(Div, div, /);

impl Neg for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn neg(self) -> F64x4 {
        self.map(|x| -x)
    }
}

impl Real for F64x4 {
    const LANES: usize = LANES;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        F64x4([x; LANES])
    }
    #[inline(always)]
    fn powf(self, e: Self) -> Self {
        // glibc's four-lane call where switched on (within 4 ulp of libm's), else libm's.
        match vector_calls::pow(self.0, e.0) {
            Some(p) => F64x4(p),
            None => self.zip(e, f64::powf),
        }
    }
    #[inline(always)]
    fn recip(self) -> Self {
        self.map(|x| 1.0 / x)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        let (a, b, c) = (self.0, b.0, c.0);
        F64x4(std::array::from_fn(|i| a[i].mul_add(b[i], c[i])))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f64::abs)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.zip(other, f64::max)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.zip(other, f64::min)
    }
    #[inline(always)]
    fn select_pos(self, a: Self, b: Self) -> Self {
        let (s, a, b) = (self.0, a.0, b.0);
        let pick = |i: usize| if s[i] > 0.0 { a[i] } else { b[i] };
        F64x4([pick(0), pick(1), pick(2), pick(3)])
    }
    #[inline(always)]
    fn all_zero(self) -> bool {
        self.0.iter().all(|&x| x == 0.0)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        // glibc's four-lane calls where switched on (within 4 ulp of libm's), else libm's.
        if let Some((s, c)) = vector_calls::sin_cos(self.0) {
            return (F64x4(s), F64x4(c));
        }
        let r = self.0.map(f64::sin_cos);
        (F64x4(r.map(|x| x.0)), F64x4(r.map(|x| x.1)))
    }
    #[inline(always)]
    fn tanh(self) -> Self {
        self.map(f64::tanh)
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.0[i]
    }
}

/// Whether this CPU runs the lanes with AVX2 (256-bit) instructions: checked once at run
/// time, so the same build runs on CPUs without it.
#[inline]
pub fn avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_are_the_scalar_operations_bit_for_bit() {
        let a = F64x4([0.3, -1.7, 2.5e-3, 7.0]);
        let b = F64x4([1.1, 0.2, -3.0, 0.0]);
        let check = |v: F64x4, f: &dyn Fn(f64, f64) -> f64| {
            for i in 0..LANES {
                assert_eq!(v.0[i].to_bits(), f(a.0[i], b.0[i]).to_bits(), "lane {i}");
            }
        };
        check(a + b, &|x, y| x + y);
        check(a - b, &|x, y| x - y);
        check(a * b, &|x, y| x * y);
        check(a / b, &|x, y| x / y);
        check(-a, &|x, _| -x);
        if !vector_calls::active() {
            // Where glibc's four-lane calls are switched on, they are held to 4 ulp instead
            // (`vector_calls`'s test).
            check(a.abs().powf(b), &|x, y| x.abs().powf(y));
            check(a.sin_cos().0, &|x, _| x.sin_cos().0);
            check(a.sin_cos().1, &|x, _| x.sin_cos().1);
        }
        check(a.max(b), &|x, y| x.max(y));
        check(a.min(b), &|x, y| x.min(y));
        check(a.recip(), &|x, _| 1.0 / x);
        check(a.abs().sqrt(), &|x, _| x.abs().sqrt());
        check(a.tanh(), &|x, _| x.tanh());
        assert!(F64x4::splat(0.0).all_zero());
        assert!(!b.all_zero());
    }
}
