//! The lone rod's fast paths of `rft` and `rft_inertial` on x86-64: the same law as
//! [`Rft::law`] and [`RftInertial::law`], compiled with AVX2 (its three-operand encodings:
//! the same IEEE operations in the same order, so the same bits) and with the element count
//! known when compiled. The laws' physics is in the parent module; this one only picks where
//! it runs: `contact_force` of one scene on a rod asks [`Rft::lone_rod`] /
//! [`RftInertial::lone_rod`] first.

use super::{Rft, RftCoefficients, RftInertial};
use crate::forces::outline::rod_plates;
use crate::forces::outline::Plate;
use crate::forces::{Boundary, ContactState, Medium, Outline, Real};

/// Most elements per plate of a lone rod's fast paths ([`Rft::rod_avx2`],
/// [`RftInertial::rod_avx2`]); each count from 1 up has its own instance.
const ROD_FAST_ELEMENTS: usize = 8;

/// The boundary of one scene's rod and its (diameter, immersed length), where a fast path
/// applies: one scene, a rod outline, 1 to [`ROD_FAST_ELEMENTS`] elements per plate, and a
/// CPU with AVX2.
#[inline(always)]
fn lone_rod_of<'a, F: Real>(
    elements: usize,
    c: &ContactState<'a, F>,
) -> Option<(&'a Boundary<F>, (F, F))> {
    if F::LANES != 1 || !(1..=ROD_FAST_ELEMENTS).contains(&elements) || !crate::num::avx2() {
        return None;
    }
    let b = c.boundary?;
    let Outline::Rod { diameter, immersed } = b.outline else {
        return None;
    };
    Some((b, (diameter, immersed)))
}

impl Rft {
    /// A lone rod's force and moment by [`Rft::rod_avx2`], where it applies: one scene, a rod
    /// held nowhere, at most [`ROD_FAST_ELEMENTS`] elements per plate, a CPU with AVX2.
    #[inline(always)]
    pub(super) fn lone_rod<F: Real>(
        &self,
        co: &RftCoefficients<F>,
        c: &ContactState<F>,
    ) -> Option<([F; 2], F)> {
        let (b, rod) = lone_rod_of(self.elements, c)?;
        if !(b.held[0] + b.held[1]).all_zero() {
            return None;
        }
        // SAFETY: this CPU has AVX2 (`lone_rod_of` checked).
        Some(unsafe { self.rod_avx2(co, rod, b) })
    }

    /// [`Rft::integrate`] over a rod's two plates at `N` elements each (`self.elements`), its
    /// elements moving along their own velocities: the same arithmetic in the same order.
    #[inline(always)]
    fn integrate_rod<F: Real, const N: usize>(
        &self,
        co: &RftCoefficients<F>,
        (diameter, immersed): (F, F),
        b: &Boundary<F>,
    ) -> ([F; 2], F) {
        let plates = rod_plates(diameter, immersed, &b.frame);
        let mut sum = ([F::splat(0.0); 2], F::splat(0.0));
        self.add_plate::<F, N>(co, &plates[0], b, None, &mut sum);
        self.add_plate::<F, N>(co, &plates[1], b, None, &mut sum);
        sum
    }

    /// A lone rod's contact, held nowhere, at up to [`ROD_FAST_ELEMENTS`] elements per plate:
    /// the count known when compiled (one instance per count) and the whole compiled with
    /// AVX2 (its three-operand encodings; the same IEEE operations in the same order, so the
    /// same bits as [`Rft::law`]). A quarter less time than the plain loop at eight
    /// elements, half at two (docs/laws.md, "Cost"). Measured on the way: LLVM packs two
    /// elements to a 128-bit register here; compiled one count per function it packed four
    /// to a 256-bit one, and the shuffles of the x, y pairs made that a quarter slower. A
    /// change here is to be measured (`benches/bench_laws.py`).
    ///
    /// # Safety
    /// The CPU must have AVX2 ([`crate::num::avx2`]).
    #[target_feature(enable = "avx2")]
    #[inline(never)]
    pub(super) unsafe fn rod_avx2<F: Real>(
        &self,
        co: &RftCoefficients<F>,
        rod: (F, F),
        b: &Boundary<F>,
    ) -> ([F; 2], F) {
        match self.elements {
            1 => self.integrate_rod::<F, 1>(co, rod, b),
            2 => self.integrate_rod::<F, 2>(co, rod, b),
            3 => self.integrate_rod::<F, 3>(co, rod, b),
            4 => self.integrate_rod::<F, 4>(co, rod, b),
            5 => self.integrate_rod::<F, 5>(co, rod, b),
            6 => self.integrate_rod::<F, 6>(co, rod, b),
            7 => self.integrate_rod::<F, 7>(co, rod, b),
            // 8: `contact_force` sends only 1..=8 here. (A fallback arm to the plain loop, even
            // out of line, made the 8-element force 25 % slower: measured.)
            _ => self.integrate_rod::<F, 8>(co, rod, b),
        }
    }
}

impl RftInertial {
    /// A lone rod's force and moment by [`RftInertial::rod_avx2`], where it applies: one
    /// scene, a rod, at most [`ROD_FAST_ELEMENTS`] elements per plate, a CPU with AVX2.
    #[inline(always)]
    pub(super) fn lone_rod<F: Real>(
        &self,
        c: &ContactState<F>,
        m: &Medium<F>,
    ) -> Option<([F; 2], F)> {
        let (b, rod) = lone_rod_of(self.elements, c)?;
        let k = -(F::splat(self.lam) * m.rho_g);
        // SAFETY: this CPU has AVX2 (`lone_rod_of` checked).
        Some(unsafe { self.rod_avx2(k, rod, b) })
    }

    /// [`RftInertial::law`] on a lone rod at up to [`ROD_FAST_ELEMENTS`] elements per
    /// plate, the count known when compiled, compiled with AVX2 (the same operations in
    /// the same order: the same bits), as [`Rft`]'s (docs/laws.md, "Cost").
    ///
    /// # Safety
    /// The CPU must have AVX2 ([`crate::num::avx2`]).
    #[target_feature(enable = "avx2")]
    #[inline(never)]
    pub(super) unsafe fn rod_avx2<F: Real>(
        &self,
        k: F,
        (diameter, immersed): (F, F),
        b: &Boundary<F>,
    ) -> ([F; 2], F) {
        #[inline(always)]
        fn rod<F: Real, const N: usize>(
            t: &RftInertial,
            k: F,
            plates: &[Plate<F>; 2],
            b: &Boundary<F>,
        ) -> ([F; 2], F) {
            let mut sum = ([F::splat(0.0); 2], F::splat(0.0));
            t.add_plate::<F, N>(k, &plates[0], b, &mut sum);
            t.add_plate::<F, N>(k, &plates[1], b, &mut sum);
            sum
        }
        let plates = rod_plates(diameter, immersed, &b.frame);
        match self.elements {
            1 => rod::<F, 1>(self, k, &plates, b),
            2 => rod::<F, 2>(self, k, &plates, b),
            3 => rod::<F, 3>(self, k, &plates, b),
            4 => rod::<F, 4>(self, k, &plates, b),
            5 => rod::<F, 5>(self, k, &plates, b),
            6 => rod::<F, 6>(self, k, &plates, b),
            7 => rod::<F, 7>(self, k, &plates, b),
            // 8: `contact_force` sends only 1..=8 here (as `Rft::rod_avx2`).
            _ => rod::<F, 8>(self, k, &plates, b),
        }
    }
}
