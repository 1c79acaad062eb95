//! The free link (thesis sec. 3.2.1): a round-ended rod dropped onto sand, tip first; a
//! linkage of one link whose root is its centre of mass, with one rod contact.

use nalgebra::Vector2;

use super::{check_rod_angle, Fields, Preset, Rod, Setting, Start};
use crate::bodies::{ContactShape, ContactSpec, LinkSpec, LinkageScene, RootKind, RootSpec};
use crate::error::{check_finite, Result};

/// The preset's registration.
pub const PRESET: Preset = Preset {
    name: "free_link",
    build,
    renames: &[],
    fields: &[
        "length", "diameter", "mass", "inertia", "q_deg", "v0", "depth0", "vx0", "omega0",
    ],
};

/// A free round-ended link dropped onto sand, tip first (MODEL.md, "Bodies").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeLink {
    /// The rod: length L, diameter d_c, mass m, inertia.
    pub rod: Rod,
    /// Initial angle from the vertical q [deg], |q| < 90.
    pub q_deg: f64,
    /// Initial motion: the tip's velocity is (vx0, -v0), its depth depth0.
    pub start: Start,
    /// Initial angular velocity dq/dt [rad/s].
    pub omega0: f64,
}

/// The thesis's free link at q = 0 and the Table 3.5 mean speed.
impl Default for FreeLink {
    fn default() -> Self {
        FreeLink {
            // The thesis's steel rod with round ends (sec. 3.2.1): L, d_c, m.
            rod: Rod {
                length: 0.190,
                diameter: 0.0127,
                mass: 0.184,
                inertia: None,
            },
            q_deg: 0.0,
            start: Start {
                v0: 2.214,
                depth0: 0.0,
                vx0: 0.0,
            },
            omega0: 0.0,
        }
    }
}

fn build(f: &dyn Fields) -> Result<LinkageScene> {
    let p = FreeLink {
        rod: Rod::read(f)?,
        q_deg: f.f64("q_deg")?,
        start: Start::read(f)?,
        omega0: f.f64_or("omega0", 0.0)?,
    };
    super::finish(f, 1, || p.check(), |setting| p.scene(setting))
}

impl FreeLink {
    /// Check every parameter; the error names the first bad one.
    pub fn check(&self) -> Result<()> {
        self.rod.check()?;
        check_rod_angle("q_deg", self.q_deg)?;
        check_finite("omega0", self.omega0)?;
        self.start.check()
    }

    /// The rod as a linkage in `setting`: the root is its centre of mass, the tip at x = 0,
    /// `depth0` below the surface, moving at (vx0, -v0) and turning at omega0.
    pub fn scene(&self, setting: Setting) -> LinkageScene {
        let q = self.q_deg.to_radians();
        let rod = &self.rod;
        let half = 0.5 * rod.length;
        // The tip's velocity is (vx0, -v0); the centre moves with it plus the spin.
        let normal = Vector2::new(q.cos(), -q.sin());
        let v_c = Vector2::new(self.start.vx0, -self.start.v0) + self.omega0 * half * normal;
        let link = LinkSpec {
            name: "rod".into(),
            mass: rod.mass,
            inertia: rod.inertia(),
            com: Vector2::zeros(),
            length: rod.length,
            q,
            omega: self.omega0,
        };
        let contact = ContactSpec {
            name: "rod".into(),
            link: "rod".into(),
            shape: ContactShape::Rod {
                tip: Vector2::new(-half, 0.0),
                length: rod.length,
                diameter: rod.diameter,
            },
        };
        let root = RootSpec {
            kind: RootKind::Free,
            link: "rod".into(),
            position: Vector2::new(half * q.sin(), half * q.cos() - self.start.depth0),
            velocity: v_c,
            mass: 0.0,
            rate: None,
        };
        setting.scene(vec![link], vec![], vec![contact], root)
    }
}
