//! The thesis's bodies as presets: each is a function from a few parameters (the rod's
//! size, its angle and speed, the person's mass and height, ...) to a [`LinkageScene`] with
//! its initial state, so that every run, sweep, summary and record goes through the one
//! linkage path.
//!
//! A preset is one file here (its parameters with their sources, their checks, and the
//! linkage it builds) and one line in [`PRESETS`]. It reads its parameters through
//! [`Fields`] (a scene's named fields: [`crate::spec::SceneSpec`] implements it) and names
//! them in its errors as the user wrote them; an error the linkage's own checks raise about
//! one of its joints is renamed to the preset's field ([`Preset::renames`]).

use crate::bodies::LinkageScene;
use crate::body::rod::ApplyAt;
use crate::body::Joint;
use crate::dynamics::SignModel;
use crate::error::{check_finite, check_range, GranrsError, Result};
use crate::forces::{ForceSet, Medium};
use crate::integrate::SolveOptions;

pub mod chain;
pub mod free_link;
pub mod leg;
#[cfg(test)]
mod plate;
#[cfg(test)]
mod tests;

/// What a preset reads of a scene: its named fields, typed (the error names the field).
pub trait Fields {
    /// A required number.
    fn f64(&self, field: &str) -> Result<f64>;
    /// An optional number (absent or `None` gives `None`).
    fn opt_f64(&self, field: &str) -> Result<Option<f64>>;
    /// A number with a default when the field is absent.
    fn f64_or(&self, field: &str, default: f64) -> Result<f64>;
    /// A joint: `"free"`, `"locked"` or a spring-damper `{k, c}` (rest angle 0; the preset
    /// sets it); absent or `None` gives `default`.
    fn joint(&self, field: &str, default: Joint) -> Result<Joint>;
    /// One of `allowed`, or `default` when absent or `None`.
    fn choice<'a>(&'a self, field: &str, default: &'a str, allowed: &[&str]) -> Result<&'a str>;
    /// What every scene has besides its body, for a body with `n_contacts` contacts.
    fn setting(&self, n_contacts: usize) -> Result<Setting>;
}

/// What every scene has besides its body: the sand, how the terms act, the terms, and the
/// numerics.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    /// The sand.
    pub medium: Medium,
    /// Point of application of the contact terms.
    pub apply_at: ApplyAt,
    /// Sign model of the static terms.
    pub sign_model: SignModel,
    /// The force terms that act, with their parameters per contact.
    pub forces: ForceSet,
    /// Step, end and recording.
    pub options: SolveOptions,
}

impl Default for Setting {
    /// The thesis's sand and law (Table 3.4, q = 0 row) with the default numerics.
    fn default() -> Self {
        Setting {
            medium: Medium::default(),
            apply_at: ApplyAt::Tip,
            sign_model: SignModel::Modes,
            forces: ForceSet::thesis(&[crate::forces::Coefficients::TABLE_3_4_VERTICAL]),
            options: SolveOptions::default(),
        }
    }
}

/// A registered preset.
pub struct Preset {
    /// The name a scene's `body` field takes.
    pub name: &'static str,
    /// Read the preset's parameters from `fields`, check them, and build its linkage.
    pub build: fn(&dyn Fields) -> Result<LinkageScene>,
    /// Joint paths of the linkage (`joints.<name>`) and the scene field that sets each, so
    /// that an error of the linkage's checks names the field the user wrote.
    pub renames: &'static [(&'static str, &'static str)],
    /// The scene fields it reads besides every scene's ([`Fields::setting`]): the fields
    /// that apply to it (and to the other presets that read them) only.
    pub fields: &'static [&'static str],
}

/// Every preset, one line each.
pub static PRESETS: &[Preset] = &[
    free_link::PRESET,
    chain::PRESET,
    leg::PRESET,
    // The worked example of a new preset (docs/bodies), a fixture of the crate's tests.
    #[cfg(test)]
    plate::PRESET,
];

/// The preset named `name`.
pub fn preset(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name)
}

/// The presets' names.
pub fn names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.name).collect()
}

/// The presets that read the scene field `field` (empty: a field every body reads).
pub fn bodies_of(field: &str) -> Vec<&'static str> {
    PRESETS
        .iter()
        .filter(|p| p.fields.contains(&field))
        .map(|p| p.name)
        .collect()
}

impl Preset {
    /// `e` with a field of the linkage's (`joints.pin.k`) renamed to the preset's
    /// (`pin_joint.k`).
    pub fn rename(&self, e: GranrsError) -> GranrsError {
        e.map_field(|field| {
            for (from, to) in self.renames {
                if let Some(rest) = field.strip_prefix(from) {
                    if rest.is_empty() || rest.starts_with('.') {
                        return format!("{to}{rest}");
                    }
                }
            }
            field
        })
    }
}

/// The linkage `scene` builds in the setting of `f` (a body of `contacts` contacts), once
/// `check` has passed: every field's type first, then the preset's ranges.
fn finish(
    f: &dyn Fields,
    contacts: usize,
    check: impl FnOnce() -> Result<()>,
    scene: impl FnOnce(Setting) -> LinkageScene,
) -> Result<LinkageScene> {
    let setting = f.setting(contacts)?;
    check()?;
    Ok(scene(setting))
}

/// A spring-damper's parameters checked (`field.k`, `field.c`); other joints pass.
fn check_joint(field: &str, j: &Joint) -> Result<()> {
    if let Joint::Spring { k, c, .. } = j {
        check_range(&format!("{field}.k"), *k, 0.0, false)?;
        check_range(&format!("{field}.c"), *c, 0.0, false)?;
    }
    Ok(())
}

/// `joint` with a spring-damper's rest angle set to `rest` [rad].
fn relaxed_at(joint: Joint, rest: f64) -> Joint {
    match joint {
        Joint::Spring { k, c, .. } => Joint::Spring { k, c, rest },
        j => j,
    }
}

/// An angle from the vertical at which a rod's tip meets the sand first.
fn check_rod_angle(field: &str, q_deg: f64) -> Result<()> {
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

/// The initial motion every preset takes: downward speed, depth and horizontal speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    /// Initial downward speed [m/s].
    pub v0: f64,
    /// Initial depth of the lowest point [m].
    pub depth0: f64,
    /// Initial horizontal velocity [m/s].
    pub vx0: f64,
}

impl Start {
    /// Read `v0`, `depth0` (default 0) and `vx0` (default 0), and check them.
    fn read(f: &dyn Fields) -> Result<Start> {
        let s = Start {
            v0: f.f64("v0")?,
            depth0: f.f64_or("depth0", 0.0)?,
            vx0: f.f64_or("vx0", 0.0)?,
        };
        Ok(s)
    }

    /// Check the values.
    fn check(&self) -> Result<()> {
        check_range("v0", self.v0, 0.0, false)?;
        check_range("depth0", self.depth0, 0.0, false)?;
        check_finite("vx0", self.vx0)?;
        Ok(())
    }
}

/// A round rod's size and mass: the free link, each link of the chain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rod {
    /// Length [m].
    pub length: f64,
    /// Diameter [m].
    pub diameter: f64,
    /// Mass [kg].
    pub mass: f64,
    /// Moment of inertia about the centre of mass [kg m^2]; `None`: a solid cylinder,
    /// m (L^2/12 + d^2/16).
    pub inertia: Option<f64>,
}

impl Rod {
    /// Read `length`, `diameter`, `mass` and `inertia` (optional).
    fn read(f: &dyn Fields) -> Result<Rod> {
        Ok(Rod {
            length: f.f64("length")?,
            diameter: f.f64("diameter")?,
            mass: f.f64("mass")?,
            inertia: f.opt_f64("inertia")?,
        })
    }

    /// Check the values.
    fn check(&self) -> Result<()> {
        check_range("length", self.length, 0.0, true)?;
        check_range("diameter", self.diameter, 0.0, true)?;
        check_range("mass", self.mass, 0.0, true)?;
        if let Some(i) = self.inertia {
            check_range("inertia", i, 0.0, true)?;
        } else if !self.inertia().is_finite() {
            // A solid cylinder's inertia overflows: name the size that does it.
            let (field, value) = if !(self.length * self.length).is_finite() {
                ("length", self.length)
            } else if !(self.diameter * self.diameter).is_finite() {
                ("diameter", self.diameter)
            } else {
                ("mass", self.mass)
            };
            return Err(GranrsError::InvalidParameter {
                field: field.into(),
                value,
                allowed: "a size whose solid-cylinder inertia m (L^2/12 + d^2/16) is finite \
                          (or give inertia)"
                    .into(),
            });
        }
        Ok(())
    }

    /// Moment of inertia about the centre of mass [kg m^2].
    pub fn inertia(&self) -> f64 {
        let (l, d) = (self.length, self.diameter);
        self.inertia
            .unwrap_or(self.mass * (l * l / 12.0 + d * d / 16.0))
    }
}

impl Setting {
    /// The linkage of these parts in this setting.
    fn scene(
        self,
        links: Vec<crate::bodies::LinkSpec>,
        joints: Vec<crate::bodies::JointSpec>,
        contacts: Vec<crate::bodies::ContactSpec>,
        root: crate::bodies::RootSpec,
    ) -> LinkageScene {
        LinkageScene {
            links,
            joints,
            contacts,
            root,
            medium: self.medium,
            apply_at: self.apply_at,
            sign_model: self.sign_model,
            forces: self.forces,
            options: self.options,
        }
    }
}
