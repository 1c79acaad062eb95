//! `gravity`: the weight of every link.
//!
//! ```text
//! F_i = m_i g (0, -1)   at each link's centre of mass
//! ```
//!
//! - **Source:** granrs's model, `docs/model.md`, "Frame, units and the impact" (g = 9.81 m/s^2, as in the thesis).
//! - **Parameters:** none; g is the medium's (`Scene.g`), which also scales the static
//!   terms whether or not this term acts.
//! - **Reads:** each link's mass and centre of mass.
//! - **Switches:** none.
//! - **Energy:** with this term the potential energy is gravity's, m g y; without it the
//!   body has none from gravity (a free link with nothing acting keeps E = KE).

use super::{Acts, Class, ContactState, Medium, Rates, Real, Term, TermForce, TermInfo};

/// Gravity on the body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gravity;

impl Term for Gravity {
    const INFO: TermInfo = TermInfo {
        name: "gravity",
        summary: "the weight of every link, at its centre of mass",
        equation: "F_i = -m_i g y_hat  (each link i)",
        source: "granrs's model, docs/model.md (frame, units and the impact)",
        params: &[],
        acts: Acts::Body,
        class: Class::Static,
        velocity_dependent: false,
        reads: "each link's mass and centre of mass; g of the medium",
        reads_area_speed: false,
        reads_frame: false,
        shapes: super::ANY_SHAPE,
        switches: &[],
        columns: &[],
    };

    fn from_params(_values: &[f64]) -> Self {
        Gravity
    }

    fn params(&self) -> Vec<f64> {
        Vec::new()
    }

    /// None: a body term has no contact force.
    fn force_with<F: Real>(&self, _p: &[F], _c: &ContactState<F>, _m: &Medium<F>) -> TermForce<F> {
        TermForce::force([F::splat(0.0); 2])
    }

    /// None at a contact: a constant force on each link.
    fn rates(&self, _c: &ContactState<f64>, _m: &Medium<f64>) -> Rates {
        Rates::NONE
    }

    /// The medium's g, downward, on every mass.
    fn field(&self) -> f64 {
        1.0
    }
}
