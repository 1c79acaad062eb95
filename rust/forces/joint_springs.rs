//! `joint_springs`: the rotational spring-dampers of the body's joints.
//!
//! ```text
//! tau = -k (theta - theta_rest) - c dtheta/dt     at each spring-damper joint
//! ```
//!
//! with `theta` the joint's relative angle (child minus parent). The stiffness `k`
//! [N m/rad] and damping `c` [N m s/rad] are the joints' own (`knee = {k = 300.0, c = 5.0}`),
//! not this term's: listing it switches them on. Without it a spring-damper joint is free.
//!
//! - **Source:** granrs (the thesis's CAD model does not say what its joints were;
//!   `docs/bodies/leg.md`).
//! - **Parameters:** none.
//! - **Reads:** each spring-damper joint's angle and rate.
//! - **Switches:** none.
//! - **Energy:** the springs' energy is potential energy; the dampers' loss is `joint_loss`.

use super::{Acts, Class, ContactState, Medium, Rates, Term, TermInfo};

/// The joints' spring-dampers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointSprings;

impl Term for JointSprings {
    const INFO: TermInfo = TermInfo {
        name: "joint_springs",
        summary: "the joints' rotational spring-dampers (k, c on each joint)",
        equation: "tau = -k (theta - theta_rest) - c dtheta/dt  (each spring-damper joint)",
        source: "granrs (docs/bodies/leg.md, docs/bodies/linkage.md)",
        params: &[],
        acts: Acts::Body,
        class: Class::Static,
        velocity_dependent: true,
        reads: "each spring-damper joint's relative angle and rate",
        reads_area_speed: false,
        reads_frame: false,
        shapes: super::EVERY_SHAPE,
        switches: &[],
        columns: &[],
    };

    fn from_params(_values: &[f64]) -> Self {
        JointSprings
    }

    fn params(&self) -> Vec<f64> {
        Vec::new()
    }

    /// None at a contact: it acts through the mechanism, at the joints (a body term).
    fn rates(&self, _c: &ContactState<f64>, _m: &Medium<f64>) -> Rates {
        Rates::NONE
    }
}
