//! A contact's boundary below the surface, as the terms that integrate over it read it
//! (`rft`, `rft_inertial`, `poncelet`).
//!
//! - **A rod** is two plates (Li, Zhang & Goldman 2013 lump a plate's two faces into one
//!   set of coefficients, so a thin body counts once):
//!   - the shaft, on the rod's axis from the tip T along the immersed length l;
//!   - the tip end, of length d_c across the axis at T, from its deeper corner (mirror
//!     images walk their elements alike).
//!
//!   Both are d_c wide out of the plane; the top end never counts.
//! - **A box** (a sole) is three plates: its bottom (heel to toe) and its back and front
//!   faces (from the heel and the toe up to the top), w_s wide out of the plane.
//! - **An arc** is its chords (`body::arc`), each a plate, as many as the contact says (at
//!   most [`MAX_CHORDS`](crate::body::arc::MAX_CHORDS)): they are made one by one as the
//!   terms walk the outline (one turn about the centre each), in a loop of their own, so a
//!   rod's or a box's fixed plates pay nothing for them ([`Outline::for_each_plate`]).
//!
//! A plate is cut into equal elements. Each element is clipped at the surface y = 0: only
//! its immersed part counts, and the depth z = -y varies linearly along it, so the
//! integrals below are exact for any element count while the element's direction of motion
//! is one (a translating plate).

use super::{Frame, Outline, Real};

/// Most plates of a rod's or a box's outline (an arc's chords are made as they are walked).
pub const MAX_PLATES: usize = 3;

/// One plate: from `a` to `b` [m] (world coordinates), `width` [m] out of the plane, with
/// its direction and length. A rod's plates take theirs from its frame (the axis is a unit
/// vector already); others from their ends ([`Plate::between`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plate<F> {
    /// One end [m].
    pub a: [F; 2],
    /// The other end [m].
    pub b: [F; 2],
    /// The unit vector from `a` to `b` (zeros for a plate of no length).
    pub u: [F; 2],
    /// Its length [m].
    pub length: F,
    /// Width out of the plane [m].
    pub width: F,
}

/// The immersed part of a plate, cut into `n` equal elements.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elements<F> {
    /// The immersed part's first end [m].
    pub start: [F; 2],
    /// From one element's middle to the next [m].
    pub step: [F; 2],
    /// One element's length [m].
    pub length: F,
    /// The plate's width out of the plane [m].
    pub width: F,
}

impl<F: Real> Elements<F> {
    /// The middle of element `k` [m] (its depth is the element's mean depth: the depth is
    /// linear along a plate).
    #[inline(always)]
    pub fn mid(&self, k: usize) -> [F; 2] {
        let t = F::splat(k as f64 + 0.5);
        [
            self.start[0] + t * self.step[0],
            self.start[1] + t * self.step[1],
        ]
    }
}

impl<F: Real> Outline<F> {
    /// Call `f` on each boundary plate at the pose `frame`, in order: a rod's or a box's
    /// from [`Outline::fixed_plates`], an arc's chords made one by one (one turn about its
    /// centre each). Two loops, so that a rod's or a box's stays the plain loop over its
    /// array that it was before arcs.
    #[inline(always)]
    pub fn for_each_plate(&self, frame: &Frame<F>, mut f: impl FnMut(&Plate<F>)) {
        if let Outline::Arc {
            centre,
            first,
            turn,
            chords,
            width,
        } = *self
        {
            let [c, s] = turn;
            let mut r = [first[0] - centre[0], first[1] - centre[1]];
            for _ in 0..chords {
                let q = [c * r[0] - s * r[1], s * r[0] + c * r[1]];
                f(&Plate::between(
                    [centre[0] + r[0], centre[1] + r[1]],
                    [centre[0] + q[0], centre[1] + q[1]],
                    width,
                ));
                r = q;
            }
            return;
        }
        let (plates, n) = self.fixed_plates(frame);
        for p in &plates[..n] {
            f(p);
        }
    }

    /// A rod's or a box's boundary plates (the first `n` of the array) at the pose `frame`;
    /// none for an arc (its chords: [`Outline::for_each_plate`]).
    #[inline(always)]
    pub fn fixed_plates(&self, frame: &Frame<F>) -> ([Plate<F>; MAX_PLATES], usize) {
        let zero = F::splat(0.0);
        let none = Plate {
            a: [zero; 2],
            b: [zero; 2],
            u: [zero; 2],
            length: zero,
            width: zero,
        };
        let mut out = [none; MAX_PLATES];
        match *self {
            Outline::Rod { diameter, immersed } => {
                [out[0], out[1]] = rod_plates(diameter, immersed, frame);
                (out, 2)
            }
            Outline::Box { corners, width } => {
                let [heel, toe, toe_top, heel_top] = corners;
                out[0] = Plate::between(heel, toe, width);
                out[1] = Plate::between(heel, heel_top, width);
                out[2] = Plate::between(toe, toe_top, width);
                (out, 3)
            }
            Outline::Arc { .. } => (out, 0),
        }
    }
}

/// A rod's two plates at the pose `frame`: its shaft from the tip T along the axis over the
/// immersed length, and its tip end across the axis at T from its deeper corner, both
/// `diameter` wide.
#[inline(always)]
pub fn rod_plates<F: Real>(diameter: F, immersed: F, frame: &Frame<F>) -> [Plate<F>; 2] {
    let t = frame.origin;
    let e = frame.axis;
    let half = F::splat(0.5) * diameter;
    // The tip end runs from its deeper corner: the normal to the axis, (-e_y, e_x), turned
    // to point up the slope with the sign of e_x (the sign of 1 / e_x, so that a level
    // end takes the sign of a zero e_x too). A rod and its mirror image (x -> -x) then walk
    // their elements in the same order and their forces are each other's mirror image bit
    // for bit; a normal fixed to the axis's left would walk the mirror's from the other end.
    let one = F::splat(1.0);
    let side = e[0].recip().select_pos(one, -one);
    let n = [-(side * e[1]), side * e[0]];
    // Directions and lengths from the frame: no square root (the one division is the side's).
    [
        Plate {
            a: t,
            b: [t[0] + immersed * e[0], t[1] + immersed * e[1]],
            u: e,
            length: immersed,
            width: diameter,
        },
        Plate {
            a: [t[0] - half * n[0], t[1] - half * n[1]],
            b: [t[0] + half * n[0], t[1] + half * n[1]],
            u: n,
            length: diameter,
            width: diameter,
        },
    ]
}

impl<F: Real> Plate<F> {
    /// The plate from `a` to `b`, its direction and length from its ends (one square root
    /// and one division).
    #[inline(always)]
    pub fn between(a: [F; 2], b: [F; 2], width: F) -> Self {
        let d = [b[0] - a[0], b[1] - a[1]];
        let length = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let inv = length.select_pos(length.recip(), F::splat(0.0));
        Plate {
            a,
            b,
            u: [d[0] * inv, d[1] * inv],
            length,
            width,
        }
    }

    /// Its part below the surface y = 0 (a plate of no length when none is), clipped once:
    /// the depth is linear along it, so the elements of the immersed part integrate `|z| dA`
    /// exactly for any count. A level plate counts whole from the moment it reaches the
    /// surface (the right limit at its entry, which the engine locates).
    #[inline(always)]
    pub fn immersed(&self) -> Plate<F> {
        let zero = F::splat(0.0);
        let one = F::splat(1.0);
        let (za, zb) = (-self.a[1], -self.b[1]);
        let dz = za - zb;
        // Where the plate meets the surface, as a fraction from `a` (level: no crossing).
        let cut = dz.abs().select_pos(za * dz.recip(), zero);
        let tiny = F::splat(f64::MIN_POSITIVE);
        let a_in = za + tiny;
        let b_in = zb + tiny;
        // Immersed from t0 to t1 (both ends in: 0..1; one in: up to the cut; none: 0..0).
        let t0 = a_in.select_pos(zero, b_in.select_pos(cut, zero));
        let t1 = b_in.select_pos(one, a_in.select_pos(cut, zero));
        let d = [self.b[0] - self.a[0], self.b[1] - self.a[1]];
        Plate {
            a: [self.a[0] + t0 * d[0], self.a[1] + t0 * d[1]],
            b: [self.a[0] + t1 * d[0], self.a[1] + t1 * d[1]],
            u: self.u,
            length: (t1 - t0) * self.length,
            width: self.width,
        }
    }

    /// Its immersed part cut into `n` equal elements.
    #[inline(always)]
    pub fn elements(&self, n: usize) -> Elements<F> {
        let part = self.immersed();
        let inv_n = F::splat(1.0 / n as f64);
        let step = [
            (part.b[0] - part.a[0]) * inv_n,
            (part.b[1] - part.a[1]) * inv_n,
        ];
        Elements {
            start: part.a,
            step,
            length: part.length * inv_n,
            width: self.width,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plate(a: [f64; 2], b: [f64; 2]) -> Plate<f64> {
        Plate::between(a, b, 2.0)
    }

    /// int |z| dA over the elements (midpoint rule).
    fn depth_area(p: &Plate<f64>, n: usize) -> f64 {
        let e = p.elements(n);
        (0..n).map(|k| -e.mid(k)[1] * e.length * e.width).sum()
    }

    #[test]
    fn clipped_elements_integrate_the_depth_exactly() {
        // A plate from 0.3 m above the surface to 0.6 m below it, at 45 degrees: the
        // immersed part is 0.6 sqrt(2) long with depths 0..0.6, so int |z| dA =
        // width * length * 0.3 = 2 * 0.6 sqrt(2) * 0.3, at every element count, either way.
        let exact = 2.0 * 0.6 * 2f64.sqrt() * 0.3;
        for p in [
            plate([0.0, 0.3], [0.9, -0.6]),
            plate([0.9, -0.6], [0.0, 0.3]),
        ] {
            for n in [1, 2, 3, 7, 64] {
                let sum = depth_area(&p, n);
                assert!((sum - exact).abs() < 1e-14, "{n}: {sum} vs {exact}");
                let e = p.elements(n);
                assert!((e.length * n as f64 - 0.6 * 2f64.sqrt()).abs() < 1e-14);
            }
        }
        // Wholly out of the sand: nothing.
        let out = plate([0.0, 0.1], [1.0, 0.2]);
        assert_eq!(out.elements(3).length, 0.0);
        assert_eq!(depth_area(&out, 3), 0.0);
    }

    /// A rod's plates and its mirror image's (x -> -x) are each other's mirror image bit for
    /// bit, ends and direction, so that the terms walk their elements in the same order:
    /// the tip end runs from its deeper corner, the axis's x a zero of either sign too.
    #[test]
    fn a_rods_plates_mirror_its_mirror_images() {
        let m = |p: [f64; 2]| [-p[0], p[1]];
        for (ex, ey) in [
            (0.6, 0.8),
            (-0.6, 0.8),
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.3, -0.9),
        ] {
            let frame = Frame {
                origin: [0.25, -0.05],
                v: [0.0; 2],
                omega: 0.0,
                axis: [ex, ey],
            };
            let image = Frame {
                origin: m(frame.origin),
                axis: m(frame.axis),
                ..frame
            };
            let plates = rod_plates(0.0127, 0.1, &frame);
            let mirrored = rod_plates(0.0127, 0.1, &image);
            for (p, q) in plates.iter().zip(&mirrored) {
                for (a, b) in [(p.a, q.a), (p.b, q.b), (p.u, q.u)] {
                    assert_eq!(m(a).map(f64::to_bits), b.map(f64::to_bits), "{ex} {ey}");
                }
            }
            // The tip end from its deeper corner (level: either end, as the mirror's).
            assert!(plates[1].a[1] <= plates[1].b[1], "{ex} {ey}");
        }
    }

    #[test]
    fn a_level_plate_counts_whole_from_the_surface_down() {
        let under = plate([0.0, -0.2], [1.0, -0.2]).elements(4);
        assert!((under.length - 0.25).abs() < 1e-15);
        let at = plate([0.0, 0.0], [1.0, 0.0]).elements(1);
        assert_eq!(at.length, 1.0);
        assert_eq!(plate([0.0, 0.2], [1.0, 0.2]).elements(1).length, 0.0);
    }
}
