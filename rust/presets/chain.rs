//! The thesis's two-link chain (sec. 4.1): two rods pinned at their top ends, falling as one
//! body; each with its own contact and coefficients, the tips may reach the sand at
//! different times. A linkage rooted at the pin: link 1 hangs from the root, link 2 from
//! link 1's top end (the same point); each rod's axis points from its tip to the pin.

use nalgebra::Vector2;

use super::{check_joint, check_rod_angle, relaxed_at, Fields, Preset, Rod, Setting, Start};
use crate::bodies::{
    ContactShape, ContactSpec, JointSpec, LinkSpec, LinkageScene, RootKind, RootSpec,
};
use crate::body::Joint;
use crate::error::{check_finite, check_range, Result};

/// The preset's registration.
pub const PRESET: Preset = Preset {
    name: "chain",
    build,
    renames: &[("joints.pin", "pin_joint")],
    fields: &[
        "length",
        "diameter",
        "mass",
        "inertia",
        "pin_mass",
        "pin_joint",
        "q_deg",
        "q2_deg",
        "v0",
        "depth0",
        "vx0",
        "omega0",
    ],
};

/// Two rods pinned at their top ends (MODEL.md, "Bodies").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chain {
    /// Each link: length, diameter, mass, inertia.
    pub rod: Rod,
    /// Mass of the pin (a point mass at the joint) [kg].
    pub pin_mass: f64,
    /// The pin: free (the thesis), locked, or a spring-damper relaxed at the initial angle.
    pub joint: Joint,
    /// Initial angles of link 1 and link 2 from the vertical [deg].
    pub q_deg: [f64; 2],
    /// Initial motion: the whole chain at (vx0, -v0), the lower tip `depth0` deep.
    pub start: Start,
    /// Initial angular velocity of both links [rad/s].
    pub omega0: f64,
}

impl Default for Chain {
    fn default() -> Self {
        Chain {
            // L1 = L2 and d1 = d2 (thesis sec. 4.1); the mass is not in the thesis: a solid
            // steel cylinder (7850 kg/m^3) of the stated size, pi/4 d^2 L rho = 0.0341 kg.
            rod: Rod {
                length: 0.135,
                diameter: 0.0064,
                mass: 0.0341,
                inertia: None,
            },
            pin_mass: 0.0,
            joint: Joint::Free,
            q_deg: [-15.0, 15.0],
            start: Start {
                v0: 2.29,
                depth0: 0.0,
                vx0: 0.0,
            },
            omega0: 0.0,
        }
    }
}

/// Link 2's angle defaults to the mirror of link 1's.
fn build(f: &dyn Fields) -> Result<LinkageScene> {
    let q1 = f.f64("q_deg")?;
    let p = Chain {
        rod: Rod::read(f)?,
        pin_mass: f.f64_or("pin_mass", 0.0)?,
        joint: f.joint("pin_joint", Joint::Free)?,
        q_deg: [q1, f.opt_f64("q2_deg")?.unwrap_or(-q1)],
        start: Start::read(f)?,
        omega0: f.f64_or("omega0", 0.0)?,
    };
    super::finish(f, 2, || p.check(), |setting| p.scene(setting))
}

impl Chain {
    /// Check every parameter; the error names the first bad one.
    pub fn check(&self) -> Result<()> {
        self.rod.check()?;
        check_range("pin_mass", self.pin_mass, 0.0, false)?;
        check_joint("pin_joint", &self.joint)?;
        check_rod_angle("q_deg", self.q_deg[0])?;
        check_rod_angle("q2_deg", self.q_deg[1])?;
        check_finite("omega0", self.omega0)?;
        self.start.check()
    }

    /// The chain as a linkage in `setting`: the pin above x = 0, the lower tip `depth0`
    /// below the surface.
    pub fn scene(&self, setting: Setting) -> LinkageScene {
        let (q1, q2) = (self.q_deg[0].to_radians(), self.q_deg[1].to_radians());
        let r = &self.rod;
        let inertia = r.inertia();
        let link = |name: &str, q: f64| LinkSpec {
            name: name.into(),
            mass: r.mass,
            inertia,
            com: Vector2::new(-0.5 * r.length, 0.0),
            length: r.length,
            q,
            omega: self.omega0,
        };
        let rod = |name: &str| ContactSpec {
            name: name.into(),
            link: name.into(),
            shape: ContactShape::Rod {
                tip: Vector2::new(-r.length, 0.0),
                length: r.length,
                diameter: r.diameter,
            },
        };
        let pin = JointSpec {
            name: "pin".into(),
            parent: "link1".into(),
            child: "link2".into(),
            at: Vector2::zeros(),
            joint: relaxed_at(self.joint, q2 - q1),
            table: None,
        };
        let root = RootSpec {
            kind: RootKind::Free,
            link: "link1".into(),
            position: Vector2::new(0.0, r.length * q1.cos().max(q2.cos()) - self.start.depth0),
            velocity: Vector2::new(self.start.vx0, -self.start.v0),
            mass: self.pin_mass,
            rate: None,
        };
        setting.scene(
            vec![link("link1", q1), link("link2", q2)],
            vec![pin],
            vec![rod("link1"), rod("link2")],
            root,
        )
    }
}
