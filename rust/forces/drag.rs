//! `drag`: the dynamic term of the thesis's law, quadratic in the speed of the immersed part.
//!
//! ```text
//! F_d = - eta_d * rho_g * A_r * |v_E| * v_E
//! ```
//!
//! with `A_r |v_E| = d_c * l * |e x v_E|` for a rod (the reference area of eqs. 3.13-3.14
//! written without the atan of eq. 3.14, which breaks at v_Ey = 0: smooth at v_E = 0, no
//! division), and for a sole box the immersed part's area projected normal to v_E, times
//! |v_E| (`docs/model.md`, "What is immersed").
//!
//! - **Source:** "Bipedal impact with granular matter" (the thesis),
//!   eqs. 2.1 and 3.1, with the geometry of eqs. 3.13-3.14.
//! - **Parameters:** `eta_d` [-], the dynamic scaling constant; default 15.2, thesis Table 3.4
//!   at q = 0 (the vertical rod).
//! - **Reads:** the medium's rho_g, the contact's A_r |v_E| and v_E.
//! - **Switches:** the sign of e x v_E ([`Switch::Cross`]): |e x v_E| has a kink where v_E
//!   is parallel to the axis; in the `modes` sign model its sign is held through a step and
//!   the crossing is a located event.
//! - **Series:** `F_dx`, `F_dy`.

use super::{
    Acts, Class, ContactState, Medium, Param, Rates, Real, Switch, Term, TermForce, TermInfo,
};

/// The dynamic drag F_d.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drag {
    /// Dynamic scaling constant eta_d [-].
    pub eta_d: f64,
}

impl Term for Drag {
    const INFO: TermInfo = TermInfo {
        name: "drag",
        summary: "dynamic drag, quadratic in the speed of the immersed centroid E",
        equation: "F_d = -eta_d rho_g A_r |v_E| v_E,  A_r |v_E| = d_c l |e x v_E| (rod)",
        source: "thesis eqs. 2.1, 3.1, 3.13-3.14 (docs/model.md)",
        params: &[Param {
            name: "eta_d",
            unit: "-",
            default: 15.2,
            source: "thesis Table 3.4, q = 0",
            min: 0.0,
            description: "dynamic scaling constant",
            integer: false,
            max: f64::INFINITY,
        }],
        acts: Acts::Contact,
        class: Class::Dynamic,
        velocity_dependent: true,
        reads: "rho_g; the contact's A_r |v_E| and v_E",
        reads_area_speed: true,
        reads_frame: false,
        shapes: super::SOLID_SHAPES,
        switches: &[Switch::Cross],
        columns: &[("F_dx", 0), ("F_dy", 1)],
    };

    fn from_params(values: &[f64]) -> Self {
        Drag { eta_d: values[0] }
    }

    fn params(&self) -> Vec<f64> {
        vec![self.eta_d]
    }

    #[inline(always)]
    fn contact_force<F: Real>(&self, c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        self.force_with(&[F::splat(self.eta_d)], c, m)
    }

    #[inline(always)]
    fn force_with<F: Real>(&self, p: &[F], c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        let k = -(p[0] * m.rho_g * c.area_speed);
        TermForce::force([k * c.v[0], k * c.v[1]])
    }

    /// With `k = eta_d rho_g A_r |v_E|` (so `|F| = k |v_E|`): `dF/dv = -k (I + v^ v^T)` for
    /// a point moving freely, at most `2 k`; in depth, `A_r` grows with the immersed length
    /// (`|F| / d`).
    fn rates(&self, c: &ContactState<f64>, m: &Medium<f64>) -> Rates {
        let k = self.eta_d * m.rho_g * c.area_speed.abs();
        let speed = c.v[0].hypot(c.v[1]);
        Rates {
            damping: 2.0 * k,
            spring: if c.depth > 0.0 {
                k * speed / c.depth
            } else {
                0.0
            },
        }
    }
}
