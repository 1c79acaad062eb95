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

use nalgebra::SVector;

use super::{Acts, Class, ContactState, Medium, Rates, Real, Term, TermForce, TermInfo};
use crate::body::{Joint, Link, Mechanism};

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

    /// None: a body term has no contact force.
    fn force_with<F: Real>(&self, _p: &[F], _c: &ContactState<F>, _m: &Medium<F>) -> TermForce<F> {
        TermForce::force([F::splat(0.0); 2])
    }

    /// None at a contact: it acts at the joints (a body term; [`Term::joint_rates`]).
    fn rates(&self, _c: &ContactState<f64>, _m: &Medium<f64>) -> Rates {
        Rates::NONE
    }

    /// Each spring-damper joint's torque on its child link, and its reaction on the parent.
    #[inline(always)]
    fn add_joint_torques<const N: usize>(
        &self,
        body: &Mechanism<N>,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        out: &mut SVector<f64, N>,
        torques: &mut [f64; N],
    ) -> f64 {
        let mut dissipated = 0.0;
        for (i, l) in body.links.iter().enumerate() {
            if let (Some(p), Joint::Spring { k, c, rest }) = (l.parent, l.joint) {
                let theta = q[2 + i] - q[2 + p];
                let rate = qd[2 + i] - qd[2 + p];
                let tau = -k * (theta - rest) - c * rate;
                out[2 + i] += tau;
                out[2 + p] -= tau;
                torques[i] = tau;
                dissipated += c * rate * rate;
            }
        }
        dissipated
    }

    /// The springs' elastic energy, `sum 1/2 k (theta - theta_rest)^2`.
    fn joint_energy<const N: usize>(&self, body: &Mechanism<N>, q: &SVector<f64, N>) -> f64 {
        body.links
            .iter()
            .enumerate()
            .map(|(i, l)| match (l.parent, l.joint) {
                (Some(p), Joint::Spring { k, rest, .. }) => {
                    let x = q[2 + i] - q[2 + p] - rest;
                    0.5 * k * x * x
                }
                _ => 0.0,
            })
            .sum()
    }

    /// A spring-damper joint's own k and c.
    fn joint_rates(&self, link: &Link) -> Option<(f64, f64)> {
        match link.joint {
            Joint::Spring { k, c, .. } => Some((k, c)),
            _ => None,
        }
    }
}
