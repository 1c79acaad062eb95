//! `static_v`: the thesis's static vertical term, growing with the immersed volume and a
//! power of the depth.
//!
//! ```text
//! F_sv = - sgn(v_Ey) * eta_v * (d / L_ref)^lambda * g * rho_g * V        (along y)
//! ```
//!
//! with `V` the immersed volume (pi d_c^2 / 4 l for a rod, eq. 3.15), `d` the depth and
//! `L_ref` the body length (the rod's L; the tibia l_l for the leg).
//!
//! - **Source:** the thesis, eqs. 2.3-2.4, 3.3 and 3.15 (`docs/model.md`).
//! - **Parameters:** `eta_v` [-], the vertical static scaling constant, default 248.0; `lam`
//!   [-], the depth exponent lambda, default 0.106; both thesis Table 3.4 at q = 0.
//! - **Reads:** the medium's g and rho_g, the contact's depth, L_ref, V and the sign of v_Ey.
//! - **Switches:** the sign of v_Ey, with sticking ([`Switch::SlipY`]), as `static_h` in x.
//!   The factor d^lambda has an unbounded slope at d = 0 (entry and exit are located events
//!   of the engine, polished on the RK4 map).
//! - **Series:** `F_sv` (and `mode_y`, the held sign).

use super::{
    Acts, Class, ContactState, Medium, Param, Rates, Real, Switch, Term, TermForce, TermInfo,
};

/// The static vertical term F_sv.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticV {
    /// Vertical static scaling constant eta_v [-].
    pub eta_v: f64,
    /// Depth exponent lambda [-].
    pub lam: f64,
}

impl Term for StaticV {
    const INFO: TermInfo = TermInfo {
        name: "static_v",
        summary: "static vertical resistance, Coulomb-like in the sign of v_Ey",
        equation: "F_sv = -sgn(v_Ey) eta_v (d / L_ref)^lam g rho_g V  (along y)",
        source: "thesis eqs. 2.3-2.4, 3.3, 3.15 (docs/model.md)",
        params: &[
            Param {
                name: "eta_v",
                unit: "-",
                default: 248.0,
                source: "thesis Table 3.4, q = 0",
                min: 0.0,
                description: "vertical static scaling constant",
                integer: false,
                max: f64::INFINITY,
            },
            Param {
                name: "lam",
                unit: "-",
                default: 0.106,
                source: "thesis Table 3.4, q = 0",
                min: 0.0,
                description: "depth exponent lambda",
                integer: false,
                max: f64::INFINITY,
            },
        ],
        acts: Acts::Contact,
        class: Class::Static,
        velocity_dependent: false,
        reads: "g, rho_g; the contact's depth d, L_ref, immersed volume V and the sign of v_Ey",
        reads_area_speed: false,
        reads_frame: false,
        shapes: super::SOLID_SHAPES,
        switches: &[Switch::SlipY],
        columns: &[("F_sv", 1)],
    };

    fn from_params(values: &[f64]) -> Self {
        StaticV {
            eta_v: values[0],
            lam: values[1],
        }
    }

    fn params(&self) -> Vec<f64> {
        vec![self.eta_v, self.lam]
    }

    #[inline(always)]
    fn contact_force<F: Real>(&self, c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        self.force_with(&[F::splat(self.eta_v), F::splat(self.lam)], c, m)
    }

    #[inline(always)]
    fn force_with<F: Real>(&self, p: &[F], c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        let (eta_v, lam) = (p[0], p[1]);
        let zero = F::splat(0.0);
        let rg = m.g * m.rho_g;
        // d * (1 / L_ref): the division waits for L_ref alone, not for the depth.
        let depth_factor = (c.depth * c.l_ref.recip()).powf(lam);
        let bound = eta_v * depth_factor * rg * c.volume;
        TermForce {
            force: [zero, -c.sign[1] * bound],
            bound: [zero, bound],
            moment: F::splat(0.0),
        }
    }

    /// None that a step meets: its velocity enters only through a sign that the `modes`
    /// sign model holds through a step (the switch is a located event), and its depth law
    /// is located where it is not smooth (the entry). A secant F / d would be unbounded at
    /// the entry while the energy it stores is not (the thesis's runs are resolved there).
    fn rates(&self, _c: &ContactState<f64>, _m: &Medium<f64>) -> Rates {
        Rates::NONE
    }
}
