//! What a run is: the body, its contacts, the medium, the force terms (with their parameters), the
//! initial state, the time step, the end condition and the outputs wanted.
//!
//! Field names are those of the Python `granrs.Scene`, so that an error names the field the
//! user wrote. Angles are in degrees here (`*_deg`, the API edge) and radians inside the
//! engine.

use nalgebra::{SVector, Vector2};

use crate::body::rod::ApplyAt;
use crate::body::{Joint, Link, Mechanism, RodContact, SoleContact, SoleModel};
use crate::dynamics::{Contact, Model, Shape, SignModel};
use crate::error::{check_finite, check_range, GranrsError, Result};
use crate::forces::{Coefficients, ForceSet, Medium};
use crate::integrate::{solve, Method, Outcome, SolveOptions};

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

/// Validate the medium.
pub fn validate_medium(m: &Medium) -> Result<()> {
    check_range("rho_g", m.rho_g, 0.0, true)?;
    check_range("g", m.g, 0.0, false)?;
    Ok(())
}

/// Validate step, end time and sign model.
pub fn validate_options(o: &SolveOptions, sign_model: &SignModel) -> Result<()> {
    check_range("dt", o.dt, 0.0, true)?;
    check_range("t_end", o.t_end, 0.0, true)?;
    if o.t_end / o.dt > 1e9 {
        return Err(GranrsError::InvalidParameter {
            field: "dt".into(),
            value: o.dt,
            allowed: format!("at most 1e9 steps to t_end = {} s", o.t_end),
        });
    }
    if let SignModel::Smooth { eps } = sign_model {
        check_range("smooth_eps", *eps, 0.0, true)?;
    }
    if let Method::Dopri5 { rtol, atol } = o.method {
        check_range("rtol", rtol, 0.0, true)?;
        check_range("atol", atol, 0.0, true)?;
    }
    Ok(())
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

/// Check a joint's parameters; `field` names it.
fn validate_joint(field: &str, j: &Joint) -> Result<()> {
    if let Joint::Spring { k, c, rest } = j {
        check_range(&format!("{field}.k"), *k, 0.0, false)?;
        check_range(&format!("{field}.c"), *c, 0.0, false)?;
        check_finite(&format!("{field}.rest"), *rest)?;
    }
    Ok(())
}

/// Largest `h lambda` the fixed-step RK4 is given for a joint's fastest mode (its stability
/// limit is 2.78 on the negative real axis and 2.83 on the imaginary one).
const RK4_STABLE: f64 = 2.5;

/// Check that the fixed-step RK4 resolves every spring-damper joint at the initial posture:
/// for the joint's relative rate `a . qdot` (a = e_child - e_parent) the damper's rate is
/// `c a^T M^-1 a` and the spring's angular frequency `sqrt(k a^T M^-1 a)`; each times `dt`
/// must stay below [`RK4_STABLE`]. A stiffer joint is refused before any work starts, with the
/// largest value that would run (or use a smaller `dt`, or `method="dopri5"`).
fn validate_joint_stiffness<const N: usize>(
    model: &Model<N>,
    q0: &SVector<f64, N>,
    options: &SolveOptions,
    names: &[&str],
) -> Result<()> {
    if options.method != Method::Rk4 || !model.forces.joint_springs {
        return Ok(());
    }
    let pose = model.mechanism.pose(q0);
    let Some(chol) = model.mechanism.mass_matrix(&pose).cholesky() else {
        return Ok(());
    };
    for (i, link) in model.mechanism.links.iter().enumerate() {
        let (Some(p), Joint::Spring { k, c, .. }) = (link.parent, link.joint) else {
            continue;
        };
        let mut a = SVector::<f64, N>::zeros();
        a[2 + i] = 1.0;
        a[2 + p] = -1.0;
        let inv_inertia = a.dot(&chol.solve(&a));
        let name = names.get(i).copied().unwrap_or("joint");
        let dt = options.dt;
        if c * inv_inertia * dt > RK4_STABLE {
            return Err(GranrsError::InvalidParameter {
                field: format!("{name}.c"),
                value: c,
                allowed: format!(
                    "c <= {:.4e} N m s/rad at dt = {dt} s (the damper's rate c / I_eff, \
                     I_eff = {:.3e} kg m^2, must stay under {RK4_STABLE} / dt for RK4); use a \
                     smaller dt or method='dopri5'",
                    RK4_STABLE / (inv_inertia * dt),
                    1.0 / inv_inertia
                ),
            });
        }
        if (k * inv_inertia).sqrt() * dt > RK4_STABLE {
            return Err(GranrsError::InvalidParameter {
                field: format!("{name}.k"),
                value: k,
                allowed: format!(
                    "k <= {:.4e} N m/rad at dt = {dt} s (the spring's frequency \
                     sqrt(k / I_eff), I_eff = {:.3e} kg m^2, must stay under {RK4_STABLE} / dt \
                     for RK4); use a smaller dt or method='dopri5'",
                    (RK4_STABLE / dt).powi(2) / inv_inertia,
                    1.0 / inv_inertia
                ),
            });
        }
    }
    Ok(())
}

/// Check an angle from the vertical at which a rod's tip meets the sand first.
fn validate_rod_angle(field: &str, q_deg: f64) -> Result<()> {
    check_finite(field, q_deg)?;
    if q_deg.abs() >= 90.0 {
        return Err(GranrsError::InvalidParameter {
            field: field.into(),
            value: q_deg,
            allowed: format!("-90 < {field} < 90 (the tip must meet the sand first)"),
        });
    }
    Ok(())
}

/// Check the fields every body shares: medium, initial motion and numerics.
fn validate_common(
    medium: &Medium,
    v0: f64,
    depth0: f64,
    vx0: f64,
    options: &SolveOptions,
    sign_model: &SignModel,
) -> Result<()> {
    validate_medium(medium)?;
    check_range("v0", v0, 0.0, false)?;
    check_range("depth0", depth0, 0.0, false)?;
    check_finite("vx0", vx0)?;
    validate_options(options, sign_model)
}

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

/// Anthropometric data of the leg model.
///
/// Segment mass fractions, centre-of-mass positions and radii of gyration: Dempster (1955)
/// as tabulated in D. A. Winter, *Biomechanics and Motor Control of Human Movement*, 4th ed.,
/// Wiley 2009, Table 4.1. Segment lengths as fractions of the body height H: Winter's
/// Fig. 4.1 (after Drillis and Contini 1966): ankle 0.039 H, knee 0.285 H, hip (greater
/// trochanter) 0.530 H, shoulder (glenohumeral joint) 0.818 H above the floor.
pub mod leg_defaults {
    /// Body mass [kg] (thesis sec. 5.2.1: 75.35 +- 0.568 kg, five subjects).
    pub const BODY_MASS: f64 = 75.35;
    /// Body height [m] (thesis sec. 5.2.1: 1.78 +- 0.032 m).
    pub const HEIGHT: f64 = 1.78;
    /// Foot size f_s [m] (thesis sec. 5.3.2).
    pub const FOOT_LENGTH: f64 = 0.254;
    /// Shoe width w_s [m] (thesis sec. 5.3.2).
    pub const SHOE_WIDTH: f64 = 0.086;
    /// Tibia length l_l [m] (thesis sec. 5.3.2): the shank's length here.
    pub const TIBIA_LENGTH: f64 = 0.432;
    /// Sand bulk density [kg/m^3] (thesis sec. 5.3.2: fine sand).
    pub const RHO_G: f64 = 1600.0;
    /// Ankle height above the sole / H (Winter Fig. 4.1).
    pub const ANKLE_HEIGHT: f64 = 0.039;
    /// Thigh length / H: hip 0.530 H less knee 0.285 H (Winter Fig. 4.1).
    pub const THIGH_LENGTH: f64 = 0.245;
    /// Trunk length / H: shoulder 0.818 H less hip 0.530 H (Winter Fig. 4.1).
    pub const TRUNK_LENGTH: f64 = 0.288;
    /// Mass fractions of the body mass (Winter Table 4.1): foot, leg (shank), thigh, and
    /// half of head-arms-trunk (HAT 0.678, shared by the two legs).
    pub const MASS_FRACTION: [f64; 4] = [0.0145, 0.0465, 0.100, 0.678 / 2.0];
    /// Centre of mass from the segment's proximal end, fraction of its length (Winter
    /// Table 4.1): leg 0.433 (from the knee), thigh 0.433 (from the hip), HAT 0.626 (from
    /// the greater trochanter). The foot's is the middle of its box (granrs assumption).
    pub const COM_FROM_PROXIMAL: [f64; 3] = [0.433, 0.433, 0.626];
    /// Radius of gyration about the centre of mass, fraction of the segment length (Winter
    /// Table 4.1): leg 0.302, thigh 0.323, HAT 0.496. The foot is a uniform box (granrs
    /// assumption; its inertia barely matters).
    pub const GYRATION: [f64; 3] = [0.302, 0.323, 0.496];
    /// Posture at touchdown [deg] (granrs assumption, not from the thesis; drop-landing
    /// studies report knee flexion at initial contact of roughly 10-25 deg): knee flexion,
    /// hip flexion, trunk lean forward, sole pitch (toe up).
    pub const KNEE_DEG: f64 = 20.0;
    /// See `KNEE_DEG`.
    pub const HIP_DEG: f64 = 20.0;
    /// See `KNEE_DEG`.
    pub const TRUNK_DEG: f64 = 10.0;
    /// See `KNEE_DEG`.
    pub const FOOT_DEG: f64 = 0.0;
}

/// Mass [kg], length [m], centre of mass from the distal joint along the axis [m] and
/// moment of inertia about the centre of mass [kg m^2] of one segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Mass [kg].
    pub mass: f64,
    /// Length [m].
    pub length: f64,
    /// Centre of mass from the segment's lower (distal) joint, along its axis [m].
    pub com: f64,
    /// Moment of inertia about the centre of mass [kg m^2].
    pub inertia: f64,
}

/// A planar leg landing on its foot (MODEL.md, "Bodies"): foot, shank, thigh and half of
/// head-arms-trunk, with ankle, knee and hip joints, for one leg of a person landing on
/// both feet (so it carries half the body's mass above the feet).
///
/// Generalized coordinates `(x_ankle, y_ankle, q_foot, q_shank, q_thigh, q_trunk)`, angles
/// from the vertical; the foot's axis points from heel to toe (90 deg when flat), the
/// others from their lower joint up.
#[derive(Debug, Clone, PartialEq)]
pub struct LegScene {
    /// Body mass [kg].
    pub body_mass: f64,
    /// Body height [m].
    pub height: f64,
    /// Foot (sole) length f_s [m].
    pub foot_length: f64,
    /// Shoe width w_s [m].
    pub shoe_width: f64,
    /// Tibia length l_l [m]: the shank's length and the depth factor's reference length.
    pub tibia_length: f64,
    /// Height of the contact box above the sole [m]; `None`: the tibia length, so that the
    /// box is the sole's footprint carried up the leg and its immersed volume keeps
    /// growing as f_s w_s d past the ankle (as eq. 5.7 does for a flat landing). Set it to
    /// the ankle height (0.039 H) to let only the shoe displace sand.
    pub sole_height: Option<f64>,
    /// Ankle, knee and hip joints (a spring's rest angle is the initial posture's).
    pub joints: [Joint; 3],
    /// Knee flexion at touchdown [deg].
    pub knee_deg: f64,
    /// Hip flexion at touchdown [deg].
    pub hip_deg: f64,
    /// Trunk lean forward from the vertical at touchdown [deg].
    pub trunk_deg: f64,
    /// Sole pitch at touchdown, toe up [deg] (0: flat).
    pub foot_deg: f64,
    /// Reference area and volume of the sole.
    pub sole_model: SoleModel,
    /// The sand.
    pub medium: Medium,
    /// Initial downward speed [m/s].
    pub v0: f64,
    /// Initial depth of the sole's lowest point [m].
    pub depth0: f64,
    /// Initial horizontal velocity [m/s].
    pub vx0: f64,
    /// Point of application of the force: the middle of the sole (`Tip`) or E.
    pub apply_at: ApplyAt,
    /// Sign model of the static terms.
    pub sign_model: SignModel,
    /// The force terms that act, with their parameters per contact.
    pub forces: ForceSet,
    /// Step, end and recording.
    pub options: SolveOptions,
}

impl Default for LegScene {
    fn default() -> Self {
        LegScene {
            body_mass: leg_defaults::BODY_MASS,
            height: leg_defaults::HEIGHT,
            foot_length: leg_defaults::FOOT_LENGTH,
            shoe_width: leg_defaults::SHOE_WIDTH,
            tibia_length: leg_defaults::TIBIA_LENGTH,
            sole_height: None,
            joints: [Joint::Locked; 3],
            knee_deg: leg_defaults::KNEE_DEG,
            hip_deg: leg_defaults::HIP_DEG,
            trunk_deg: leg_defaults::TRUNK_DEG,
            foot_deg: leg_defaults::FOOT_DEG,
            sole_model: SoleModel::Box,
            medium: Medium {
                rho_g: leg_defaults::RHO_G,
                g: 9.81,
            },
            v0: 3.28,
            depth0: 0.0,
            vx0: 0.0,
            apply_at: ApplyAt::Tip,
            sign_model: SignModel::Modes,
            // Thesis sec. 5.3.2, v0 = 3.28 m/s.
            forces: ForceSet::thesis(&[Coefficients {
                eta_h: 10.0,
                eta_d: 13.0,
                eta_v: 195.0,
                lambda: 1.05,
            }]),
            options: SolveOptions::default(),
        }
    }
}

/// Names of the leg's joints, in order.
pub const LEG_JOINTS: [&str; 3] = ["ankle", "knee", "hip"];

impl LegScene {
    /// Check every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        check_range("body_mass", self.body_mass, 0.0, true)?;
        check_range("height", self.height, 0.0, true)?;
        check_range("foot_length", self.foot_length, 0.0, true)?;
        check_range("shoe_width", self.shoe_width, 0.0, true)?;
        check_range("tibia_length", self.tibia_length, 0.0, true)?;
        if let Some(h) = self.sole_height {
            check_range("sole_height", h, 0.0, true)?;
        }
        for (name, j) in LEG_JOINTS.iter().zip(&self.joints) {
            validate_joint(name, j)?;
        }
        for (field, v, lo, hi) in [
            ("knee_deg", self.knee_deg, 0.0, 150.0),
            ("hip_deg", self.hip_deg, -30.0, 150.0),
            ("trunk_deg", self.trunk_deg, -60.0, 60.0),
            ("foot_deg", self.foot_deg, -60.0, 60.0),
        ] {
            check_finite(field, v)?;
            if !(lo..=hi).contains(&v) {
                return Err(GranrsError::InvalidParameter {
                    field: field.into(),
                    value: v,
                    allowed: format!("{lo} <= {field} <= {hi}"),
                });
            }
        }
        if self.sole_model == SoleModel::Thesis {
            let q = self.angles()[1].to_degrees().abs();
            if !(1.0..=89.0).contains(&q) {
                return Err(GranrsError::InvalidParameter {
                    field: "sole_model".into(),
                    value: q,
                    allowed: "the thesis form (eqs. 5.5-5.7) divides by sin and cos of the \
                              shank angle; it needs 1 <= |shank angle| <= 89 deg (set by \
                              knee_deg, hip_deg and trunk_deg)"
                        .into(),
                });
            }
        }
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
            &["", "ankle", "knee", "hip"],
        )
    }

    /// Absolute angles from the vertical at touchdown [rad]: foot, shank, thigh, trunk.
    pub fn angles(&self) -> [f64; 4] {
        let trunk = self.trunk_deg.to_radians();
        let thigh = trunk - self.hip_deg.to_radians();
        let shank = thigh + self.knee_deg.to_radians();
        let foot = (90.0 - self.foot_deg).to_radians();
        [foot, shank, thigh, trunk]
    }

    /// Height of the contact box above the sole [m].
    pub fn sole_height(&self) -> f64 {
        self.sole_height.unwrap_or(self.tibia_length)
    }

    /// Height of the ankle above the sole [m]: 0.039 H (Winter Fig. 4.1).
    pub fn ankle_height(&self) -> f64 {
        leg_defaults::ANKLE_HEIGHT * self.height
    }

    /// The four segments, scaled to body mass and height: foot, shank, thigh, half trunk.
    pub fn segments(&self) -> [Segment; 4] {
        let m = self.body_mass;
        let fr = leg_defaults::MASS_FRACTION;
        let h = self.ankle_height();
        let foot_mass = fr[0] * m;
        let foot = Segment {
            mass: foot_mass,
            length: self.foot_length,
            com: 0.0,
            inertia: foot_mass * (self.foot_length.powi(2) + h * h) / 12.0,
        };
        let lengths = [
            self.tibia_length,
            leg_defaults::THIGH_LENGTH * self.height,
            leg_defaults::TRUNK_LENGTH * self.height,
        ];
        let mut out = [foot; 4];
        for i in 0..3 {
            let l = lengths[i];
            let mass = fr[i + 1] * m;
            let rg = leg_defaults::GYRATION[i] * l;
            // Shank and thigh: from the proximal (upper) end; the trunk from the hip, its
            // lower end.
            let com = if i < 2 {
                (1.0 - leg_defaults::COM_FROM_PROXIMAL[i]) * l
            } else {
                leg_defaults::COM_FROM_PROXIMAL[i] * l
            };
            out[i + 1] = Segment {
                mass,
                length: l,
                com,
                inertia: mass * rg * rg,
            };
        }
        out
    }

    /// The sole contact: the box on the sole under the ankle, centred on it (granrs
    /// assumption: the ankle above the middle of the sole).
    pub fn sole(&self) -> SoleContact {
        SoleContact {
            link: 0,
            angle_link: 1,
            heel: Vector2::new(-0.5 * self.foot_length, self.ankle_height()),
            length: self.foot_length,
            height: self.sole_height(),
            width: self.shoe_width,
            l_ref: self.tibia_length,
            model: self.sole_model,
        }
    }

    /// The leg as a mechanism rooted at the ankle.
    pub fn model(&self) -> Model<6> {
        let seg = self.segments();
        let a = self.angles();
        let h = self.ankle_height();
        let mut links = Vec::with_capacity(4);
        links.push(Link {
            mass: seg[0].mass,
            inertia: seg[0].inertia,
            com: Vector2::new(0.0, 0.5 * h),
            parent: None,
            joint_on_parent: Vector2::zeros(),
            joint: Joint::Free,
        });
        for i in 1..4 {
            let rest = a[i] - a[i - 1];
            let joint = match self.joints[i - 1] {
                Joint::Spring { k, c, .. } => Joint::Spring { k, c, rest },
                j => j,
            };
            links.push(Link {
                mass: seg[i].mass,
                inertia: seg[i].inertia,
                com: Vector2::new(seg[i].com, 0.0),
                parent: Some(i - 1),
                // The ankle is the foot's origin; knee and hip are the top of the segment
                // below.
                joint_on_parent: if i == 1 {
                    Vector2::zeros()
                } else {
                    Vector2::new(seg[i - 1].length, 0.0)
                },
                joint,
            });
        }
        Model {
            mechanism: Mechanism {
                links,
                root_mass: 0.0,
            },
            contacts: vec![Contact {
                shape: Shape::Sole(self.sole()),
            }],
            medium: self.medium,
            apply_at: self.apply_at,
            sign_model: self.sign_model,
            forces: self.forces.clone(),
        }
    }

    /// Initial state: the ankle above x = 0, the sole's lowest point `depth0` below the
    /// surface, every segment moving at (vx0, -v0) without rotation.
    pub fn initial_state(&self) -> (SVector<f64, 6>, SVector<f64, 6>) {
        let a = self.angles();
        let model = self.model();
        let mut q0 = SVector::<f64, 6>::new(0.0, 0.0, a[0], a[1], a[2], a[3]);
        let pose = model.mechanism.pose(&q0);
        let sole = self.sole();
        let lowest = sole
            .corners_local()
            .iter()
            .map(|r| model.mechanism.point(&pose, 0, *r).y)
            .fold(f64::INFINITY, f64::min);
        q0[1] = -lowest - self.depth0;
        let qd0 = SVector::<f64, 6>::new(self.vx0, -self.v0, 0.0, 0.0, 0.0, 0.0);
        (q0, qd0)
    }

    /// Validate and run.
    pub fn run(&self) -> Result<Outcome> {
        self.validate()?;
        let (q0, qd0) = self.initial_state();
        solve(&self.model(), q0, qd0, &self.options)
    }
}

/// Any of the body models.
#[derive(Debug, Clone, PartialEq)]
pub enum AnyScene {
    /// The free link.
    FreeLink(FreeLinkScene),
    /// The two-link chain.
    Chain(ChainScene),
    /// The leg.
    Leg(LegScene),
}

impl AnyScene {
    /// Check every field.
    pub fn validate(&self) -> Result<()> {
        match self {
            AnyScene::FreeLink(s) => s.validate(),
            AnyScene::Chain(s) => s.validate(),
            AnyScene::Leg(s) => s.validate(),
        }
    }

    /// Validate and run.
    pub fn run(&self) -> Result<Outcome> {
        match self {
            AnyScene::FreeLink(s) => s.run(),
            AnyScene::Chain(s) => s.run(),
            AnyScene::Leg(s) => s.run(),
        }
    }
}
