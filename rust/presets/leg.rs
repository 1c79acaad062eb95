//! The leg (thesis ch. 5): foot, shank, thigh and half trunk landing on the sole, for one
//! leg of a person landing on both feet (so it carries half the body's mass above the
//! feet). A linkage rooted at the ankle, angles from the vertical: the foot's axis points
//! from heel to toe (90 deg when flat), the others from their lower joint up.

use nalgebra::Vector2;

use super::{check_joint, relaxed_at, Fields, Preset, Setting, Start};
use crate::bodies::{
    ContactShape, ContactSpec, JointSpec, LinkSpec, LinkageScene, RootKind, RootSpec,
};
use crate::body::{Joint, SoleModel};
use crate::dynamics::Shape;
use crate::error::{check_finite, check_range, GranrsError, Result};

/// The preset's registration.
pub const PRESET: Preset = Preset {
    name: "leg",
    build,
    renames: &[
        ("joints.ankle", "ankle"),
        ("joints.knee", "knee"),
        ("joints.hip", "hip"),
    ],
    fields: &[
        "body_mass",
        "height",
        "foot_length",
        "shoe_width",
        "tibia_length",
        "sole_height",
        "ankle",
        "knee",
        "hip",
        "knee_deg",
        "hip_deg",
        "trunk_deg",
        "foot_deg",
        "sole_model",
        "v0",
        "depth0",
        "vx0",
    ],
};

/// Names of the leg's joints, in order (each a scene field).
pub const JOINTS: [&str; 3] = ["ankle", "knee", "hip"];

/// Names of the leg's links, from the foot up.
pub const LINKS: [&str; 4] = ["foot", "shank", "thigh", "trunk"];

/// Anthropometric data of the leg model.
///
/// Segment mass fractions, centre-of-mass positions and radii of gyration: Dempster (1955)
/// as tabulated in D. A. Winter, *Biomechanics and Motor Control of Human Movement*, 4th ed.,
/// Wiley 2009, Table 4.1. Segment lengths as fractions of the body height H: Winter's
/// Fig. 4.1 (after Drillis and Contini 1966): ankle 0.039 H, knee 0.285 H, hip (greater
/// trochanter) 0.530 H, shoulder (glenohumeral joint) 0.818 H above the floor.
pub mod defaults {
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

/// A planar leg landing on its foot (MODEL.md, "Bodies").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leg {
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
    /// Initial motion: every segment at (vx0, -v0) without rotation, the sole's lowest
    /// point `depth0` deep.
    pub start: Start,
}

impl Default for Leg {
    fn default() -> Self {
        Leg {
            body_mass: defaults::BODY_MASS,
            height: defaults::HEIGHT,
            foot_length: defaults::FOOT_LENGTH,
            shoe_width: defaults::SHOE_WIDTH,
            tibia_length: defaults::TIBIA_LENGTH,
            sole_height: None,
            joints: [Joint::Locked; 3],
            knee_deg: defaults::KNEE_DEG,
            hip_deg: defaults::HIP_DEG,
            trunk_deg: defaults::TRUNK_DEG,
            foot_deg: defaults::FOOT_DEG,
            sole_model: SoleModel::Box,
            start: Start {
                v0: 3.28,
                depth0: 0.0,
                vx0: 0.0,
            },
        }
    }
}

fn build(f: &dyn Fields) -> Result<LinkageScene> {
    let leg = Leg::read(f)?;
    let setting = f.setting(1)?;
    Ok(leg.scene(setting))
}

impl Leg {
    /// Read the leg's fields (those left out take the defaults) and check them.
    pub fn read(f: &dyn Fields) -> Result<Leg> {
        let d = Leg::default();
        let sole_model = match f.choice("sole_model", "box", &["box", "thesis"])? {
            "thesis" => SoleModel::Thesis,
            _ => SoleModel::Box,
        };
        let mut joints = [Joint::Locked; 3];
        for (j, name) in joints.iter_mut().zip(JOINTS) {
            *j = f.joint(name, Joint::Locked)?;
        }
        let leg = Leg {
            body_mass: f.f64_or("body_mass", d.body_mass)?,
            height: f.f64_or("height", d.height)?,
            foot_length: f.f64_or("foot_length", d.foot_length)?,
            shoe_width: f.f64_or("shoe_width", d.shoe_width)?,
            tibia_length: f.f64_or("tibia_length", d.tibia_length)?,
            sole_height: f.opt_f64("sole_height")?,
            joints,
            knee_deg: f.f64_or("knee_deg", d.knee_deg)?,
            hip_deg: f.f64_or("hip_deg", d.hip_deg)?,
            trunk_deg: f.f64_or("trunk_deg", d.trunk_deg)?,
            foot_deg: f.f64_or("foot_deg", d.foot_deg)?,
            sole_model,
            start: Start::read(f)?,
        };
        leg.check()?;
        Ok(leg)
    }

    /// Check every parameter; the error names the first bad one.
    pub fn check(&self) -> Result<()> {
        check_range("body_mass", self.body_mass, 0.0, true)?;
        check_range("height", self.height, 0.0, true)?;
        check_range("foot_length", self.foot_length, 0.0, true)?;
        check_range("shoe_width", self.shoe_width, 0.0, true)?;
        check_range("tibia_length", self.tibia_length, 0.0, true)?;
        if let Some(h) = self.sole_height {
            check_range("sole_height", h, 0.0, true)?;
        }
        for (name, j) in JOINTS.iter().zip(&self.joints) {
            check_joint(name, j)?;
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
        self.start.check()?;
        // Sizes so large that a segment's derived length, mass or inertia overflows are
        // refused naming the largest of them (the one that overflows it); so small that one
        // underflows to zero, naming the smallest.
        let segments = self.segments();
        let overflows = segments.iter().any(|s| {
            [s.mass, s.length, s.com, s.inertia]
                .iter()
                .any(|x| !x.is_finite())
        });
        let underflows = segments
            .iter()
            .any(|s| [s.mass, s.length, s.inertia].iter().any(|x| *x <= 0.0));
        if overflows || underflows {
            let sizes = [
                ("body_mass", self.body_mass),
                ("height", self.height),
                ("foot_length", self.foot_length),
                ("tibia_length", self.tibia_length),
            ];
            let (field, value) = sizes.into_iter().fold(sizes[0], |a, b| {
                if (overflows && b.1 > a.1) || (!overflows && b.1 < a.1) {
                    b
                } else {
                    a
                }
            });
            return Err(GranrsError::InvalidParameter {
                field: field.into(),
                value,
                allowed: "a size whose segments' lengths, masses and inertias are finite and \
                          positive"
                    .into(),
            });
        }
        Ok(())
    }

    /// Absolute angles from the vertical at touchdown [rad]: foot, shank, thigh, trunk.
    pub fn angles(&self) -> [f64; 4] {
        let trunk = self.trunk_deg.to_radians();
        let thigh = trunk - self.hip_deg.to_radians();
        let shank = thigh + self.knee_deg.to_radians();
        let foot = (90.0 - self.foot_deg).to_radians();
        [foot, shank, thigh, trunk]
    }

    /// Height of the ankle above the sole [m]: 0.039 H (Winter Fig. 4.1).
    pub fn ankle_height(&self) -> f64 {
        defaults::ANKLE_HEIGHT * self.height
    }

    /// The four segments, scaled to body mass and height: foot, shank, thigh, half trunk.
    pub fn segments(&self) -> [Segment; 4] {
        let m = self.body_mass;
        let fr = defaults::MASS_FRACTION;
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
            defaults::THIGH_LENGTH * self.height,
            defaults::TRUNK_LENGTH * self.height,
        ];
        let mut out = [foot; 4];
        for i in 0..3 {
            let l = lengths[i];
            let mass = fr[i + 1] * m;
            let rg = defaults::GYRATION[i] * l;
            // Shank and thigh: from the proximal (upper) end; the trunk from the hip, its
            // lower end.
            let com = if i < 2 {
                (1.0 - defaults::COM_FROM_PROXIMAL[i]) * l
            } else {
                defaults::COM_FROM_PROXIMAL[i] * l
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

    /// The leg as a linkage in `setting`: the ankle above x = 0, the sole's lowest point
    /// `depth0` below the surface. The sole contact is the box on the sole under the ankle,
    /// centred on it (granrs assumption: the ankle above the middle of the sole).
    pub fn scene(&self, setting: Setting) -> LinkageScene {
        let seg = self.segments();
        let a = self.angles();
        let h = self.ankle_height();
        let links = (0..4)
            .map(|i| LinkSpec {
                name: LINKS[i].into(),
                mass: seg[i].mass,
                inertia: seg[i].inertia,
                com: if i == 0 {
                    Vector2::new(0.0, 0.5 * h)
                } else {
                    Vector2::new(seg[i].com, 0.0)
                },
                length: seg[i].length,
                q: a[i],
                omega: 0.0,
            })
            .collect();
        let joints = (1..4)
            .map(|i| JointSpec {
                name: JOINTS[i - 1].into(),
                parent: LINKS[i - 1].into(),
                child: LINKS[i].into(),
                // The ankle is the foot's origin; knee and hip are the top of the segment
                // below.
                at: if i == 1 {
                    Vector2::zeros()
                } else {
                    Vector2::new(seg[i - 1].length, 0.0)
                },
                joint: relaxed_at(self.joints[i - 1], a[i] - a[i - 1]),
                table: None,
            })
            .collect();
        let sole = ContactSpec {
            name: "sole".into(),
            link: "foot".into(),
            shape: ContactShape::Box {
                corner: Vector2::new(-0.5 * self.foot_length, h),
                length: self.foot_length,
                height: self.sole_height.unwrap_or(self.tibia_length),
                width: self.shoe_width,
                l_ref: self.tibia_length,
                // The thesis's form reads the shank's angle (link 1).
                thesis_angle_of: (self.sole_model == SoleModel::Thesis).then_some(1),
            },
        };
        let root = RootSpec {
            kind: RootKind::Free,
            link: "foot".into(),
            position: Vector2::zeros(),
            velocity: Vector2::new(self.start.vx0, -self.start.v0),
            mass: 0.0,
            rate: None,
        };
        let mut scene = setting.scene(links, joints, vec![sole], root);
        // Lift the ankle so that the sole's lowest corner is `depth0` deep.
        let model = scene.model::<6>();
        let (q0, _) = scene.initial_state::<6>();
        let pose = model.mechanism.pose(&q0);
        let lowest = match &model.contacts[0].shape {
            Shape::Sole(s) => s
                .corners_local()
                .iter()
                .map(|r| model.mechanism.point(&pose, 0, *r).y)
                .fold(f64::INFINITY, f64::min),
            _ => 0.0,
        };
        scene.root.position.y = -lowest - self.start.depth0;
        scene
    }
}
