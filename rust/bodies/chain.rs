//! The thesis's two-link chain (sec. 4.1): two rods pinned at their top ends.

use nalgebra::{SVector, Vector2};

use super::{validate_common, validate_joint, validate_joint_stiffness, validate_rod_angle};
use crate::body::rod::ApplyAt;
use crate::body::{Joint, Link, Mechanism, RodContact};
use crate::dynamics::{Contact, Model, Shape, SignModel};
use crate::error::{check_finite, check_range, Result};
use crate::forces::{Coefficients, ForceSet, Medium};
use crate::integrate::{solve, Outcome, SolveOptions};

/// The thesis's two-link chain (sec. 4.1) and the mass the thesis does not give.
pub mod chain_defaults {
    /// Link length L1 = L2 [m] (thesis sec. 4.1).
    pub const LENGTH: f64 = 0.135;
    /// Link diameter d1 = d2 [m] (thesis sec. 4.1).
    pub const DIAMETER: f64 = 0.0064;
    /// Link mass [kg]: not in the thesis; a solid steel cylinder (7850 kg/m^3) of the
    /// stated size, pi/4 d^2 L rho = 0.0341 kg (`shared/thesis/bodies.csv`).
    pub const MASS: f64 = 0.0341;
}

/// Two rods pinned at their top ends (MODEL.md, "Bodies"), falling as one body: each with
/// its own contact and coefficients; the tips may reach the sand at different times.
///
/// Generalized coordinates `(x_pin, y_pin, q1, q2)`; each rod's axis points from its tip to
/// the pin.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainScene {
    /// Length of each link [m].
    pub length: f64,
    /// Diameter of each link [m].
    pub diameter: f64,
    /// Mass of each link [kg].
    pub mass: f64,
    /// Moment of inertia of each link about its centre of mass [kg m^2]; `None`: a solid
    /// cylinder, m (L^2/12 + d^2/16).
    pub inertia: Option<f64>,
    /// Mass of the pin (a point mass at the joint) [kg].
    pub pin_mass: f64,
    /// The pin: free (the thesis's frictionless joint), locked, or a spring-damper whose
    /// rest angle is the initial angle between the links.
    pub joint: Joint,
    /// The sand.
    pub medium: Medium,
    /// Angles of link 1 and link 2 from the vertical [deg].
    pub q_deg: [f64; 2],
    /// Initial downward speed of the chain [m/s].
    pub v0: f64,
    /// Initial depth of the lower tip [m].
    pub depth0: f64,
    /// Initial horizontal velocity [m/s].
    pub vx0: f64,
    /// Initial angular velocity of both links [rad/s].
    pub omega0: f64,
    /// Point of application of the forces.
    pub apply_at: ApplyAt,
    /// Sign model of the static terms.
    pub sign_model: SignModel,
    /// The force terms that act, with their parameters per contact.
    pub forces: ForceSet,
    /// Step, end and recording.
    pub options: SolveOptions,
}

impl Default for ChainScene {
    fn default() -> Self {
        ChainScene {
            length: chain_defaults::LENGTH,
            diameter: chain_defaults::DIAMETER,
            mass: chain_defaults::MASS,
            inertia: None,
            pin_mass: 0.0,
            joint: Joint::Free,
            medium: Medium::default(),
            q_deg: [-15.0, 15.0],
            v0: 2.29,
            depth0: 0.0,
            vx0: 0.0,
            omega0: 0.0,
            apply_at: ApplyAt::Tip,
            sign_model: SignModel::Modes,
            forces: ForceSet::thesis(&[Coefficients::TABLE_3_4_VERTICAL; 2]),
            options: SolveOptions::default(),
        }
    }
}

impl ChainScene {
    /// Check every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        check_range("length", self.length, 0.0, true)?;
        check_range("diameter", self.diameter, 0.0, true)?;
        check_range("mass", self.mass, 0.0, true)?;
        if let Some(i) = self.inertia {
            check_range("inertia", i, 0.0, true)?;
        }
        check_range("pin_mass", self.pin_mass, 0.0, false)?;
        validate_joint("pin_joint", &self.joint)?;
        validate_rod_angle("q_deg", self.q_deg[0])?;
        validate_rod_angle("q2_deg", self.q_deg[1])?;
        check_finite("omega0", self.omega0)?;
        validate_common(
            &self.medium,
            self.v0,
            self.depth0,
            self.vx0,
            &self.options,
            &self.sign_model,
        )?;
        validate_joint_stiffness(
            &self.model(),
            &self.initial_state().0,
            &self.options,
            &["", "pin_joint"],
        )
    }

    /// Moment of inertia of each link about its centre of mass [kg m^2].
    pub fn inertia(&self) -> f64 {
        self.inertia.unwrap_or(
            self.mass * (self.length * self.length / 12.0 + self.diameter * self.diameter / 16.0),
        )
    }

    /// The chain as a mechanism rooted at the pin: link 1 hangs from the root, link 2 from
    /// link 1's top end (the same point).
    pub fn model(&self) -> Model<4> {
        let (q1, q2) = (self.q_deg[0].to_radians(), self.q_deg[1].to_radians());
        let joint = match self.joint {
            Joint::Spring { k, c, .. } => Joint::Spring {
                k,
                c,
                rest: q2 - q1,
            },
            j => j,
        };
        let link = |parent: Option<usize>| Link {
            mass: self.mass,
            inertia: self.inertia(),
            com: Vector2::new(-0.5 * self.length, 0.0),
            parent,
            joint_on_parent: Vector2::zeros(),
            joint,
        };
        let rod = |i: usize| Contact {
            shape: Shape::Rod(RodContact {
                link: i,
                tip: Vector2::new(-self.length, 0.0),
                length: self.length,
                diameter: self.diameter,
            }),
        };
        Model {
            mechanism: Mechanism {
                links: vec![link(None), link(Some(0))],
                root_mass: self.pin_mass,
                root_fixed: false,
                root_rate: None,
            },
            contacts: vec![rod(0), rod(1)],
            medium: self.medium,
            apply_at: self.apply_at,
            sign_model: self.sign_model,
            forces: self.forces.clone(),
        }
    }

    /// Initial state: the pin above x = 0, the lower tip `depth0` below the surface, the
    /// whole chain moving at (vx0, -v0) and turning at omega0.
    pub fn initial_state(&self) -> (SVector<f64, 4>, SVector<f64, 4>) {
        let (q1, q2) = (self.q_deg[0].to_radians(), self.q_deg[1].to_radians());
        let y_pin = self.length * q1.cos().max(q2.cos()) - self.depth0;
        let q0 = SVector::<f64, 4>::new(0.0, y_pin, q1, q2);
        let qd0 = SVector::<f64, 4>::new(self.vx0, -self.v0, self.omega0, self.omega0);
        (q0, qd0)
    }

    /// Validate and run.
    pub fn run(&self) -> Result<Outcome> {
        self.validate()?;
        let (q0, qd0) = self.initial_state();
        solve(&self.model(), q0, qd0, &self.options)
    }
}
