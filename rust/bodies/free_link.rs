//! The free link (thesis sec. 3.2.1): a round-ended rod dropped onto sand, tip first.

use nalgebra::{SVector, Vector2};

use super::{validate_common, validate_rod_angle};
use crate::body::rod::ApplyAt;
use crate::body::{Joint, Link, Mechanism, RodContact};
use crate::dynamics::{Contact, Model, Shape, SignModel};
use crate::error::{check_finite, check_range, Result};
use crate::forces::{Coefficients, ForceSet, Medium};
use crate::integrate::{solve, Outcome, SolveOptions};

/// The thesis's free link (sec. 3.2.1): a steel rod with round ends.
pub mod free_link_defaults {
    /// Length L [m] (thesis sec. 3.2.1).
    pub const LENGTH: f64 = 0.190;
    /// Diameter d_c [m] (thesis sec. 3.2.1).
    pub const DIAMETER: f64 = 0.0127;
    /// Mass m [kg] (thesis sec. 3.2.1).
    pub const MASS: f64 = 0.184;
}

/// A free round-ended link dropped onto sand, tip first (MODEL.md, "Bodies").
#[derive(Debug, Clone, PartialEq)]
pub struct FreeLinkScene {
    /// Rod length L [m].
    pub length: f64,
    /// Rod diameter d_c [m].
    pub diameter: f64,
    /// Mass m [kg].
    pub mass: f64,
    /// Moment of inertia about the centre of mass [kg m^2]; `None`: a solid cylinder,
    /// m (L^2/12 + d_c^2/16).
    pub inertia: Option<f64>,
    /// The sand.
    pub medium: Medium,
    /// Initial angle from the vertical q [deg], |q| < 90.
    pub q_deg: f64,
    /// Initial downward speed of the rod v0 [m/s] (velocity (vx0, -v0)).
    pub v0: f64,
    /// Initial depth of the tip [m] (0: the tip starts at the surface, as in the thesis).
    pub depth0: f64,
    /// Initial horizontal velocity [m/s].
    pub vx0: f64,
    /// Initial angular velocity dq/dt [rad/s].
    pub omega0: f64,
    /// Point of application of the force.
    pub apply_at: ApplyAt,
    /// Sign model of the static terms.
    pub sign_model: SignModel,
    /// The force terms that act, with their parameters per contact.
    pub forces: ForceSet,
    /// Step, end and recording.
    pub options: SolveOptions,
}

impl Default for FreeLinkScene {
    fn default() -> Self {
        FreeLinkScene {
            length: free_link_defaults::LENGTH,
            diameter: free_link_defaults::DIAMETER,
            mass: free_link_defaults::MASS,
            inertia: None,
            medium: Medium::default(),
            q_deg: 0.0,
            v0: 2.214,
            depth0: 0.0,
            vx0: 0.0,
            omega0: 0.0,
            apply_at: ApplyAt::Tip,
            sign_model: SignModel::Modes,
            forces: ForceSet::thesis(&[Coefficients::TABLE_3_4_VERTICAL]),
            options: SolveOptions::default(),
        }
    }
}

impl FreeLinkScene {
    /// Check every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        check_range("length", self.length, 0.0, true)?;
        check_range("diameter", self.diameter, 0.0, true)?;
        check_range("mass", self.mass, 0.0, true)?;
        if let Some(i) = self.inertia {
            check_range("inertia", i, 0.0, true)?;
        }
        validate_rod_angle("q_deg", self.q_deg)?;
        check_finite("omega0", self.omega0)?;
        validate_common(
            &self.medium,
            self.v0,
            self.depth0,
            self.vx0,
            &self.options,
            &self.sign_model,
        )
    }

    /// Moment of inertia about the centre of mass [kg m^2].
    pub fn inertia(&self) -> f64 {
        self.inertia.unwrap_or(
            self.mass * (self.length * self.length / 12.0 + self.diameter * self.diameter / 16.0),
        )
    }

    /// The free link as a one-link mechanism whose root is its centre of mass.
    pub fn model(&self) -> Model<3> {
        let link = Link {
            mass: self.mass,
            inertia: self.inertia(),
            com: Vector2::zeros(),
            parent: None,
            joint_on_parent: Vector2::zeros(),
            joint: Joint::Free,
        };
        Model {
            mechanism: Mechanism {
                links: vec![link],
                root_mass: 0.0,
                root_fixed: false,
                root_rate: None,
            },
            contacts: vec![Contact {
                shape: Shape::Rod(RodContact {
                    link: 0,
                    tip: Vector2::new(-0.5 * self.length, 0.0),
                    length: self.length,
                    diameter: self.diameter,
                }),
            }],
            medium: self.medium,
            apply_at: self.apply_at,
            sign_model: self.sign_model,
            forces: self.forces.clone(),
        }
    }

    /// Initial generalized coordinates and rates: tip at x = 0, `depth0` below the surface.
    pub fn initial_state(&self) -> (SVector<f64, 3>, SVector<f64, 3>) {
        let q = self.q_deg.to_radians();
        let half = 0.5 * self.length;
        let q0 = SVector::<f64, 3>::new(half * q.sin(), half * q.cos() - self.depth0, q);
        // The tip's velocity is (vx0, -v0); the centre moves with it plus the spin.
        let normal = Vector2::new(q.cos(), -q.sin());
        let v_c = Vector2::new(self.vx0, -self.v0) + self.omega0 * half * normal;
        let qd0 = SVector::<f64, 3>::new(v_c.x, v_c.y, self.omega0);
        (q0, qd0)
    }

    /// Validate and run.
    pub fn run(&self) -> Result<Outcome> {
        self.validate()?;
        let (q0, qd0) = self.initial_state();
        solve(&self.model(), q0, qd0, &self.options)
    }
}
