//! The worked example of a new preset (docs/bodies), a fixture of the crate's own tests: a
//! flat plate (a box contact) dropped level onto sand. A preset is this one file and its
//! line in [`super::PRESETS`]; it reads fields the scene table already has.

use nalgebra::Vector2;

use super::{Fields, Preset, Start};
use crate::bodies::{ContactShape, ContactSpec, LinkSpec, LinkageScene, RootKind, RootSpec};
use crate::error::{check_range, Result};

/// The preset's registration.
pub const PRESET: Preset = Preset {
    name: "plate",
    build,
    renames: &[],
    fields: &["length", "mass", "v0", "depth0", "vx0"],
};

fn build(f: &dyn Fields) -> Result<LinkageScene> {
    let (length, mass) = (f.f64("length")?, f.f64("mass")?);
    let start = Start::read(f)?;
    let setting = f.setting(1)?;
    check_range("length", length, 0.0, true)?;
    check_range("mass", mass, 0.0, true)?;
    start.check()?;
    // A 1 cm thick, 5 cm wide plate, its centre of mass the root, lying level (its axis
    // horizontal), its lower face `depth0` deep.
    let link = LinkSpec {
        name: "plate".into(),
        mass,
        inertia: mass * length * length / 12.0,
        com: Vector2::zeros(),
        length,
        q: std::f64::consts::FRAC_PI_2,
        omega: 0.0,
    };
    let contact = ContactSpec {
        name: "plate".into(),
        link: "plate".into(),
        shape: ContactShape::Box {
            corner: Vector2::new(-0.5 * length, 0.005),
            length,
            height: 0.01,
            width: 0.05,
            l_ref: length,
            thesis_angle_of: None,
        },
    };
    let root = RootSpec {
        kind: RootKind::Free,
        link: "plate".into(),
        position: Vector2::new(0.0, 0.005 - start.depth0),
        velocity: Vector2::new(start.vx0, -start.v0),
        mass: 0.0,
        rate: None,
    };
    Ok(setting.scene(vec![link], vec![], vec![contact], root))
}
