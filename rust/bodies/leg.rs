//! The leg (thesis ch. 5): foot, shank, thigh and half trunk landing on the sole.

use nalgebra::{SVector, Vector2};

use super::{validate_common, validate_joint, validate_joint_stiffness};
use crate::body::rod::ApplyAt;
use crate::body::{Joint, Link, Mechanism, SoleContact, SoleModel};
use crate::dynamics::{Contact, Model, Shape, SignModel};
use crate::error::{check_finite, check_range, GranrsError, Result};
use crate::forces::{Coefficients, ForceSet, Medium};
use crate::integrate::{solve, Outcome, SolveOptions};

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
                root_fixed: false,
                root_rate: None,
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
