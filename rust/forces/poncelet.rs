//! `poncelet`: the Poncelet / Katsuragi-Durian impact law, at the immersed centroid.
//!
//! ```text
//! F = - c rho_g A |v| v - k d v / |v|
//! ```
//!
//! with `v` the velocity of the immersed centroid E, `d` the contact's depth (a rod's tip
//! depth) and `A` the immersed part's cross-section normal to v:
//!
//! ```text
//! rod: A = (pi d_c^2 / 4) |e . v^| + d_c l |e x v^|     (e: the rod's axis, l: immersed)
//! box: A = w_s (b |u x v^| + h |u . v^|)                 (u: heel to toe; b, h: immersed
//!                                                          bottom and deepest face)
//! ```
//!
//! so pi d_c^2 / 4 for a rod moving along its axis and d_c l broadside. It acts at E, not at
//! the tip: E is where the engine holds a velocity at zero when a contact sticks, so the
//! set-valued k d term rests where its velocity does. At the tip, a rod pivoting about its
//! tip has v_T near zero while E still moves, and the term's direction then flips from stage
//! to stage (measured: the energy of a rotating drop rose by 8e-8 J in a step). For a body
//! moving along its axis (the impact experiments) E and T move alike. The drag is on from
//! the moment the tip enters (c rho_g A v0^2 is finite at d = 0: the entry is a located
//! event). In Katsuragi & Durian's form, m dv/dt = m g - (m / d1) v^2 - k z while the body
//! sinks: m / d1 = c rho_g A.
//!
//! - **Source:** Katsuragi & Durian, "Unified force law for granular impact cratering",
//!   Nature Physics 3 (2007) 420, eq. 1; Clark & Behringer, EPL 101 (2013) 64001 (the same
//!   law as an energy-depth relation).
//! - **Parameters:** `c` [-], the inertial drag coefficient; `k` [N/m], the depth-friction
//!   coefficient. Both required: they are fitted per body and medium (K&D report d1 and k
//!   for a steel sphere in glass beads, not for a rod).
//! - **Reads:** the medium's rho_g; the contact's depth, E and v_E, its axis and outline,
//!   and the held signs of v_E (sticking).
//! - **Switches:** the sign of v_Ey with sticking ([`Switch::SlipY`]): the k d term opposes
//!   the motion like the thesis's static terms. It is set-valued at rest, |F| <= k d along
//!   a held axis (y by its own stick, x by another term's), so a body whose weight is below
//!   k d sticks; it is not a spring and never pushes a resting body back out. Moving, its
//!   direction is v's (continuous while v is not zero; through a step the mode's held sign
//!   of v_Ey holds the motion, `dynamics::held_shift`).
//! - **Series:** `F_px`, `F_py`.

use super::{
    Acts, Boundary, Class, ContactState, Medium, Outline, Param, Rates, Real, Switch, Term,
    TermForce, TermInfo,
};

/// The Poncelet / Katsuragi-Durian law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Poncelet {
    /// Inertial drag coefficient c [-].
    pub c: f64,
    /// Depth-friction coefficient k [N/m].
    pub k: f64,
}

impl Poncelet {
    /// A |v| [m^3/s]: the immersed cross-section normal to v, times |v|.
    #[inline(always)]
    fn area_speed<F: Real>(b: &Boundary<F>, v: [F; 2]) -> F {
        let e = b.frame.axis;
        let along = (e[0] * v[0] + e[1] * v[1]).abs();
        let across = (e[0] * v[1] - e[1] * v[0]).abs();
        match b.outline {
            Outline::Rod { diameter, immersed } => {
                F::splat(std::f64::consts::FRAC_PI_4) * diameter * diameter * along
                    + diameter * immersed * across
            }
            Outline::Box { width, .. } => {
                let (plates, _) = b.outline.fixed_plates(&b.frame);
                let immersed = |i: usize| plates[i].immersed().length;
                let bottom = immersed(0);
                let face = immersed(1).max(immersed(2));
                width * (bottom * across + face * along)
            }
            // Refused on an arc before any work (`ForceSet::check_shapes`): a thin arc's
            // cross-section normal to v is not the law's.
            Outline::Arc { .. } => F::splat(0.0),
        }
    }
}

impl Term for Poncelet {
    const INFO: TermInfo = TermInfo {
        name: "poncelet",
        summary: "Poncelet / Katsuragi-Durian impact law at the reference point",
        equation: "F = -c rho_g A |v| v - k d v/|v|  at E (v: E's velocity; d: the depth; A: \
                   immersed cross-section normal to v)",
        source: "Katsuragi & Durian, Nature Physics 3 (2007) 420, eq. 1",
        params: &[
            Param {
                name: "c",
                unit: "-",
                default: f64::NAN,
                source: "none: fitted per body and medium (m / d1 = c rho_g A; granrs.media)",
                min: 0.0,
                description: "inertial drag coefficient",
                integer: false,
                max: f64::INFINITY,
            },
            Param {
                name: "k",
                unit: "N/m",
                default: f64::NAN,
                source: "none: fitted per body and medium (granrs.media)",
                min: 0.0,
                description: "depth-friction coefficient",
                integer: false,
                max: f64::INFINITY,
            },
        ],
        acts: Acts::Contact,
        class: Class::Static,
        velocity_dependent: true,
        reads: "rho_g; the contact's depth d, v_E and E, its axis and immersed outline; the \
                held signs of v_E (sticking)",
        reads_area_speed: false,
        reads_frame: true,
        shapes: super::SOLID_AND_SPACE_SHAPES,
        switches: &[Switch::SlipY],
        columns: &[("F_px", 0), ("F_py", 1)],
    };

    fn from_params(values: &[f64]) -> Self {
        Poncelet {
            c: values[0],
            k: values[1],
        }
    }

    fn params(&self) -> Vec<f64> {
        vec![self.c, self.k]
    }

    #[inline(never)]
    fn contact_force<F: Real>(&self, c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        self.force_with(&[F::splat(self.c), F::splat(self.k)], c, m)
    }

    /// With `p = [c, k]`; inlined where it is called: the SIMD lanes
    /// ([`crate::dynamics::rod_lanes`]) compile it into their AVX2 step.
    #[inline(always)]
    fn force_with<F: Real>(&self, p: &[F], c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        let (c_d, k_d) = (p[0], p[1]);
        let zero = F::splat(0.0);
        let Some(b) = c.boundary else {
            return TermForce::force([zero; 2]);
        };
        let friction = k_d * c.depth;
        let one = F::splat(1.0);
        let v = b.v_centroid;
        let speed = (v[0] * v[0] + v[1] * v[1]).sqrt();
        let inv = speed.select_pos(speed.recip(), zero);
        let drag = -(c_d * m.rho_g * Self::area_speed(b, v));
        let k = drag - friction * inv;
        // Along an axis held at zero the reaction stands in, up to k d.
        let [held_x, held_y] = b.held;
        let force = [(one - held_x) * k * v[0], (one - held_y) * k * v[1]];
        let bound = [held_x * friction, held_y * friction];
        // It acts at E: its moment about P.
        let r = [b.centroid[0] - b.apply[0], b.centroid[1] - b.apply[1]];
        TermForce {
            force,
            bound,
            moment: r[0] * force[1] - r[1] * force[0],
        }
    }

    /// The drag `c rho_g A |v| v` as a quadratic drag (`2 c rho_g A |v|`); in depth, the
    /// friction's `k`. The friction's direction also turns with v (`k d / |v|` across the
    /// motion), which is not counted: as E comes to rest it grows as 1 / |v|, so that at
    /// the step ends before any stop it reads about 1 / dt whether or not the step resolves
    /// the motion (measured on an `rft` rod, whose elements turn alike: `h_lambda` 28 at
    /// dt = 1e-4 and 25 to 161 at 1e-6, where the run is converged). Along an axis held at zero
    /// nothing moves and no term acts.
    fn rates(&self, c: &ContactState<f64>, m: &Medium<f64>) -> Rates {
        let Some(b) = c.boundary else {
            return Rates::NONE;
        };
        let [hx, hy] = b.held;
        let v = [(1.0 - hx) * b.v_centroid[0], (1.0 - hy) * b.v_centroid[1]];
        let speed = v[0].hypot(v[1]);
        if speed == 0.0 {
            return Rates::NONE;
        }
        // |F_drag| / |v| = c rho_g A |v|: at most twice that along the motion.
        let drag = self.c * m.rho_g * Self::area_speed(b, v);
        Rates {
            damping: 2.0 * drag,
            spring: self.k,
        }
    }
}
