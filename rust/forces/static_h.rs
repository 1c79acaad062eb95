//! `static_h`: the thesis's static horizontal term, growing with the square of the depth.
//!
//! ```text
//! F_sh = - sgn(v_Ex) * eta_h * g * rho_g * w * d^2        (along x)
//! ```
//!
//! with `w` the contact's width (d_c for a rod, the sole length f_s for a foot, as in
//! eq. 5.3) and `d` its depth.
//!
//! - **Source:** the thesis, eqs. 2.2 and 3.2 (`docs/model.md`, "The resistance force").
//! - **Parameters:** `eta_h` [-], the horizontal static scaling constant; default 6.5, thesis
//!   Table 3.4 at q = 0.
//! - **Reads:** the medium's g and rho_g, the contact's width and depth, the sign of v_Ex.
//! - **Switches:** the sign of v_Ex, with sticking ([`Switch::SlipX`]): the term is
//!   Coulomb-like; in the `modes` sign model its sign is held through a step, the switch is
//!   located, and where both sides push back v_Ex is held at zero by a reaction bounded by
//!   the term's magnitude (Karnopp).
//! - **Series:** `F_sh` (and `mode_x`, the held sign).

use super::{
    Acts, Class, ContactState, Medium, Param, Rates, Real, Switch, Term, TermForce, TermInfo,
};

/// The static horizontal term F_sh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticH {
    /// Horizontal static scaling constant eta_h [-].
    pub eta_h: f64,
}

impl Term for StaticH {
    const INFO: TermInfo = TermInfo {
        name: "static_h",
        summary: "static horizontal resistance, Coulomb-like in the sign of v_Ex",
        equation: "F_sh = -sgn(v_Ex) eta_h g rho_g w d^2  (along x)",
        source: "thesis eqs. 2.2, 3.2 (docs/model.md)",
        params: &[Param {
            name: "eta_h",
            unit: "-",
            default: 6.5,
            source: "thesis Table 3.4, q = 0",
            min: 0.0,
            description: "horizontal static scaling constant",
            integer: false,
            max: f64::INFINITY,
        }],
        acts: Acts::Contact,
        class: Class::Static,
        velocity_dependent: false,
        reads: "g, rho_g; the contact's width w, depth d and the sign of v_Ex",
        reads_area_speed: false,
        reads_frame: false,
        shapes: super::SOLID_SHAPES,
        switches: &[Switch::SlipX],
        columns: &[("F_sh", 0)],
    };

    fn from_params(values: &[f64]) -> Self {
        StaticH { eta_h: values[0] }
    }

    fn params(&self) -> Vec<f64> {
        vec![self.eta_h]
    }

    #[inline(always)]
    fn contact_force<F: Real>(&self, c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        self.force_with(&[F::splat(self.eta_h)], c, m)
    }

    #[inline(always)]
    fn force_with<F: Real>(&self, p: &[F], c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        let zero = F::splat(0.0);
        let rg = m.g * m.rho_g;
        let bound = p[0] * rg * c.width * c.depth * c.depth;
        TermForce {
            force: [-c.sign[0] * bound, zero],
            bound: [bound, zero],
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
