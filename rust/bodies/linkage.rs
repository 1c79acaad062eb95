//! A user-defined planar linkage: links, revolute joints, contacts of several shapes and a
//! root that is free, pinned or moved at a constant velocity (`granrs.bodies.Linkage`).
//!
//! Every element has a name, and every error names the element (`links.shank.mass`,
//! `joints.knee.parent`, ...). The linkage is checked in full before any work: unknown or
//! duplicate names, links no joint connects to the root link, joint cycles, non-positive
//! masses and inertias, too many links or contacts, contacts on unknown links and driven
//! joints with non-finite trajectories are refused.
//!
//! The engine is the general one ([`Model`] over a [`Mechanism`] of `N = 2 + links`
//! generalized coordinates), compiled for 1 to [`MAX_LINKS`] links; a single link whose
//! root is its centre of mass with one rod contact (the free link) takes the closed-form
//! fast path as before.

use nalgebra::{SVector, Vector2};

use super::{validate_joint_stiffness, validate_options};
use crate::body::arc::MAX_CHORDS;
use crate::body::rod::ApplyAt;
use crate::body::{
    ArcContact, DriveTable, Joint, Link, Mechanism, RodContact, SoleContact, SoleModel,
};
use crate::dynamics::{Contact, Model, Shape, SignModel, MAX_CONTACTS, MAX_LOCKED};
use crate::error::{check_finite, check_range, GranrsError, Result};
use crate::forces::{ContactKind, ForceSet, Medium};
use crate::integrate::{solve_driven, Drives, Outcome, SolveOptions};

/// How far [rad] a table's angle at t = 0 may be from its joint's initial relative angle
/// (the degrees' round-off); the child's initial angle is then set from the table.
const TABLE_START_TOL: f64 = 1e-9;

/// Most links a linkage may have (the engine is compiled for 1 to `MAX_LINKS` links).
pub const MAX_LINKS: usize = 6;

/// One rigid link of a linkage.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkSpec {
    /// Its name (unique in the linkage).
    pub name: String,
    /// Mass [kg], > 0.
    pub mass: f64,
    /// Moment of inertia about the centre of mass [kg m^2], > 0.
    pub inertia: f64,
    /// Centre of mass in the link's local (s, n) coordinates, from its joint [m].
    pub com: Vector2<f64>,
    /// Length [m] (drawing and reports), > 0.
    pub length: f64,
    /// Initial angle of the link's axis from the vertical [rad].
    pub q: f64,
    /// Initial angular velocity [rad/s] (a link behind a locked or driven joint takes its
    /// parent's plus the joint's rate instead).
    pub omega: f64,
}

/// A revolute joint between two links.
#[derive(Debug, Clone, PartialEq)]
pub struct JointSpec {
    /// Its name (unique in the linkage).
    pub name: String,
    /// The parent link's name.
    pub parent: String,
    /// The child link's name (its local origin is at the joint).
    pub child: String,
    /// Where the joint is on the parent, local (s, n) coordinates [m].
    pub at: Vector2<f64>,
    /// Free, locked, a spring-damper (rest angle in rad) or driven at a constant rate.
    pub joint: Joint,
    /// A [`Joint::Table`]'s table (angles in rad); `None` for every other joint.
    pub table: Option<DriveTable>,
}

/// Each joint kind's keys beyond `name`, `parent`, `child`, `at` and `kind`, as a user
/// writes them: the one list that the scene file's keys, the linkage's checks and the
/// joint's dict read (a driven joint's `table` is not a number; [`JointSpec::fields`]).
pub const JOINT_FIELDS: &[(&str, &[&str])] = &[
    ("free", &[]),
    ("locked", &[]),
    ("spring", &["k", "c", "rest_deg"]),
    (
        "driven",
        &["rate", "amplitude_deg", "frequency", "phase_deg", "table"],
    ),
];

impl JointSpec {
    /// Its kind and its numbers as a user writes them (angles in degrees, the frequency in
    /// Hz), named by [`JOINT_FIELDS`]; a table-driven joint has none.
    pub fn fields(&self) -> (&'static str, impl Iterator<Item = (&'static str, f64)>) {
        let (i, values) = match self.joint {
            Joint::Free => (0, vec![]),
            Joint::Locked => (1, vec![]),
            Joint::Spring { k, c, rest } => (2, vec![k, c, rest.to_degrees()]),
            Joint::Driven {
                rate,
                amplitude,
                omega,
                phase,
            } => (
                3,
                vec![
                    rate,
                    amplitude.to_degrees(),
                    omega / std::f64::consts::TAU,
                    phase.to_degrees(),
                ],
            ),
            Joint::Table => (3, vec![]),
        };
        let (kind, keys) = JOINT_FIELDS[i];
        (kind, keys.iter().copied().zip(values))
    }
}

/// A contact's shape and where it sits on its link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactShape {
    /// A round rod from `tip` along the link's +s axis.
    Rod {
        /// The tip, local (s, n) [m].
        tip: Vector2<f64>,
        /// Length [m].
        length: f64,
        /// Diameter [m].
        diameter: f64,
    },
    /// A box (a sole, a plate) with one corner at `corner`, `length` along +s and `height`
    /// towards -n, `width` out of the plane.
    Box {
        /// The corner on the sole (the heel), local (s, n) [m].
        corner: Vector2<f64>,
        /// Length along +s [m].
        length: f64,
        /// Height towards -n [m].
        height: f64,
        /// Width out of the plane [m].
        width: f64,
        /// Reference length of the depth factor [m].
        l_ref: f64,
        /// `Some(i)`: the thesis's form of the sole (eqs. 5.5-5.7, `body::sole`), whose
        /// reference area and volume read the angle of link `i` (the leg's shank); `None`:
        /// the geometric box.
        thesis_angle_of: Option<usize>,
    },
    /// A thin circular arc (`body::arc`): centre, radius, from `start` over `span` (angles
    /// from +s towards +n), `width` out of the plane, cut into `chords` chords.
    Arc {
        /// The centre, local (s, n) [m].
        centre: Vector2<f64>,
        /// Radius [m].
        radius: f64,
        /// The first end's angle [rad].
        start: f64,
        /// The last end's angle [rad] (start < end <= start + 2 pi).
        end: f64,
        /// Width out of the plane [m].
        width: f64,
        /// The chords (1..=MAX_CHORDS; a non-integer is refused).
        chords: f64,
    },
}

/// Each contact shape's name and the numbers it reads beyond `name`, `link` and `at`, as a
/// user writes them (angles in degrees): the one list that the scene file's keys, the
/// linkage's checks and the contact's dict read.
pub const SHAPE_FIELDS: &[(&str, &[&str])] = &[
    ("rod", &["length", "diameter"]),
    ("box", &["length", "height", "width", "l_ref"]),
    (
        "arc",
        &["radius", "start_deg", "end_deg", "width", "chords"],
    ),
];

impl ContactShape {
    /// Its kind, as a term's list of shapes names it.
    pub fn kind(&self) -> ContactKind {
        match self {
            ContactShape::Rod { .. } => ContactKind::Rod,
            ContactShape::Box { .. } => ContactKind::Box,
            ContactShape::Arc { .. } => ContactKind::Arc,
        }
    }

    /// Its place on its link, local (s, n) [m]: a rod's tip, a box's corner, an arc's centre.
    pub fn at(&self) -> Vector2<f64> {
        match *self {
            ContactShape::Rod { tip, .. } => tip,
            ContactShape::Box { corner, .. } => corner,
            ContactShape::Arc { centre, .. } => centre,
        }
    }

    /// Its name and its numbers as a user writes them, named by [`SHAPE_FIELDS`].
    pub fn fields(&self) -> (&'static str, impl Iterator<Item = (&'static str, f64)>) {
        let (i, values) = match *self {
            ContactShape::Rod {
                length, diameter, ..
            } => (0, vec![length, diameter]),
            ContactShape::Box {
                length,
                height,
                width,
                l_ref,
                ..
            } => (1, vec![length, height, width, l_ref]),
            ContactShape::Arc {
                radius,
                start,
                end,
                width,
                chords,
                ..
            } => (
                2,
                vec![radius, start.to_degrees(), end.to_degrees(), width, chords],
            ),
        };
        let (name, keys) = SHAPE_FIELDS[i];
        debug_assert_eq!(keys.len(), values.len());
        (name, keys.iter().copied().zip(values))
    }
}

/// A contact of a linkage.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSpec {
    /// Its name.
    pub name: String,
    /// The link it is fixed on.
    pub link: String,
    /// Its shape.
    pub shape: ContactShape,
}

/// How the root moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RootKind {
    /// A floating base: the root point moves freely, from its initial velocity.
    Free,
    /// Fixed in space.
    Pinned,
    /// Moved at its (constant) velocity.
    Moving,
}

/// The root: the point the root link hangs from.
#[derive(Debug, Clone, PartialEq)]
pub struct RootSpec {
    /// Free, pinned or moving.
    pub kind: RootKind,
    /// The root link (its local origin is the root point).
    pub link: String,
    /// Initial position [m].
    pub position: Vector2<f64>,
    /// Initial velocity (a moving root's constant one) [m/s].
    pub velocity: Vector2<f64>,
    /// A point mass at the root [kg].
    pub mass: f64,
    /// The root link's angle driven at this constant rate [rad/s], or `None`: free.
    pub rate: Option<f64>,
}

/// A linkage in sand: the body, the medium, the force terms, the numerics.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkageScene {
    /// The links.
    pub links: Vec<LinkSpec>,
    /// The joints.
    pub joints: Vec<JointSpec>,
    /// The contacts.
    pub contacts: Vec<ContactSpec>,
    /// The root.
    pub root: RootSpec,
    /// The sand.
    pub medium: Medium,
    /// Point of application of the forces.
    pub apply_at: ApplyAt,
    /// Sign model of the static terms.
    pub sign_model: SignModel,
    /// The force terms that act, with their parameters per contact.
    pub forces: ForceSet,
    /// Step, end and recording.
    pub options: SolveOptions,
}

#[cold]
fn bad(field: String, message: String) -> GranrsError {
    GranrsError::InvalidScene { field, message }
}

/// Every element of a list (`links`, `joints`) has a name, and no two the same.
fn check_names<'a>(list: &str, what: &str, names: impl Iterator<Item = &'a str>) -> Result<()> {
    let names: Vec<&str> = names.collect();
    for (i, name) in names.iter().enumerate() {
        if name.is_empty() {
            return Err(bad(
                format!("{list}[{i}].name"),
                format!("a {what} needs a name"),
            ));
        }
        if names[..i].contains(name) {
            return Err(bad(
                format!("{list}.{name}.name"),
                format!("two {list} are named {name:?}"),
            ));
        }
    }
    Ok(())
}

fn check_point(field: &str, p: Vector2<f64>) -> Result<()> {
    check_finite(&format!("{field}[0]"), p.x)?;
    check_finite(&format!("{field}[1]"), p.y)?;
    Ok(())
}

/// Run `$body` with `const $n: usize` set to `2 + $links` (1 to [`MAX_LINKS`] links).
macro_rules! with_size {
    ($links:expr, $n:ident => $body:expr) => {
        with_size!(@sizes $links, $n, $body, 1 3, 2 4, 3 5, 4 6, 5 7, 6 8)
    };
    (@sizes $links:expr, $n:ident, $body:expr, $($l:literal $size:literal),*) => {
        match $links {
            $($l => {
                const $n: usize = $size;
                $body
            })*
            n => unreachable!("{n} links passed validation"),
        }
    };
}

impl LinkageScene {
    /// Check the structure and every element; the error names the first bad one.
    pub fn validate_body(&self) -> Result<()> {
        let n = self.links.len();
        if n == 0 || n > MAX_LINKS {
            return Err(GranrsError::InvalidParameter {
                field: "links".into(),
                value: n as f64,
                allowed: format!("1 to {MAX_LINKS} links"),
            });
        }
        if self.contacts.len() > MAX_CONTACTS {
            return Err(GranrsError::InvalidParameter {
                field: "contacts".into(),
                value: self.contacts.len() as f64,
                allowed: format!("at most {MAX_CONTACTS} contacts"),
            });
        }
        check_names("links", "link", self.links.iter().map(|l| l.name.as_str()))?;
        for l in &self.links {
            let f = |k: &str| format!("links.{}.{k}", l.name);
            check_range(&f("mass"), l.mass, 0.0, true)?;
            check_range(&f("inertia"), l.inertia, 0.0, true)?;
            check_range(&f("length"), l.length, 0.0, true)?;
            check_point(&f("com"), l.com)?;
            check_finite(&f("q_deg"), l.q)?;
            check_finite(&f("omega0"), l.omega)?;
        }
        let r = &self.root;
        if self.link_index(&r.link).is_none() {
            return Err(self.unknown_link("root.link", &r.link));
        }
        check_range("root.mass", r.mass, 0.0, false)?;
        check_point("root.position", r.position)?;
        check_point("root.velocity", r.velocity)?;
        if let Some(rate) = r.rate {
            if !rate.is_finite() {
                return Err(GranrsError::InvalidParameter {
                    field: "root.rate".into(),
                    value: rate,
                    allowed: "a finite rate [rad/s] of the root link's angle".into(),
                });
            }
        }
        if r.kind == RootKind::Pinned && r.velocity != Vector2::zeros() {
            return Err(bad(
                "root.velocity".into(),
                "a pinned root does not move: leave the velocity out (or kind = \"moving\")".into(),
            ));
        }
        let mut locked = 0;
        check_names(
            "joints",
            "joint",
            self.joints.iter().map(|j| j.name.as_str()),
        )?;
        for (i, j) in self.joints.iter().enumerate() {
            let f = |k: &str| format!("joints.{}.{k}", j.name);
            for (k, name) in [("parent", &j.parent), ("child", &j.child)] {
                if self.link_index(name).is_none() {
                    return Err(self.unknown_link(&f(k), name));
                }
            }
            if j.parent == j.child {
                return Err(bad(
                    f("child"),
                    "a joint connects two different links".into(),
                ));
            }
            if j.child == r.link {
                return Err(bad(
                    f("child"),
                    format!(
                        "{:?} is the root link: it hangs from the root, not from a joint \
                         (a joint cycle)",
                        j.child
                    ),
                ));
            }
            if let Some(o) = self.joints[..i].iter().find(|o| o.child == j.child) {
                return Err(bad(
                    f("child"),
                    format!(
                        "link {:?} already hangs from joint {:?}: each link has one parent \
                         (a joint cycle)",
                        j.child, o.name
                    ),
                ));
            }
            check_point(&f("at"), j.at)?;
            for (k, value) in j.fields().1 {
                if matches!(k, "k" | "c") {
                    check_range(&f(k), value, 0.0, false)?;
                } else {
                    check_finite(&f(k), value)?;
                }
            }
            match j.joint {
                Joint::Driven { amplitude, .. } => {
                    if amplitude != 0.0 && n >= MAX_LINKS {
                        return Err(GranrsError::InvalidParameter {
                            field: "links".into(),
                            value: n as f64,
                            allowed: format!(
                                "at most {} links with a sinusoidal drive (its clock takes a \
                                 coordinate)",
                                MAX_LINKS - 1
                            ),
                        });
                    }
                    locked += 1;
                }
                Joint::Table => {
                    self.validate_table(j)?;
                    locked += 1;
                }
                Joint::Locked => locked += 1,
                Joint::Free | Joint::Spring { .. } => {}
            }
            if j.table.is_some() && j.joint != Joint::Table {
                return Err(bad(
                    f("table"),
                    "a table drives a joint of kind \"driven\" alone (without rate or a \
                     sinusoid)"
                        .into(),
                ));
            }
        }
        if locked > MAX_LOCKED {
            return Err(GranrsError::InvalidParameter {
                field: "joints".into(),
                value: locked as f64,
                allowed: format!("at most {MAX_LOCKED} locked or driven joints"),
            });
        }
        // Every link reaches the root link through its parents (with one parent each and
        // none for the root link, a walk that does not end there is a cycle or a gap).
        for l in &self.links {
            let mut at = l.name.as_str();
            let mut steps = 0;
            while at != r.link {
                match self.joints.iter().find(|j| j.child == at) {
                    Some(j) if steps <= n => {
                        at = j.parent.as_str();
                        steps += 1;
                    }
                    Some(_) => {
                        return Err(bad(
                            format!("links.{}", l.name),
                            "its joints form a cycle that does not reach the root link".into(),
                        ))
                    }
                    None => {
                        return Err(bad(
                            format!("links.{}", l.name),
                            format!(
                                "not connected: no joint leads from it to the root link {:?}",
                                r.link
                            ),
                        ))
                    }
                }
            }
        }
        for (i, c) in self.contacts.iter().enumerate() {
            let name = if c.name.is_empty() {
                format!("{i}")
            } else {
                c.name.clone()
            };
            let f = |k: &str| format!("contacts.{name}.{k}");
            if self.link_index(&c.link).is_none() {
                return Err(self.unknown_link(&f("link"), &c.link));
            }
            if let ContactShape::Box {
                thesis_angle_of: Some(i),
                ..
            } = c.shape
            {
                if i >= self.links.len() {
                    return Err(bad(
                        f("thesis_angle_of"),
                        "names no link of this linkage".into(),
                    ));
                }
            }
            check_point(&f("at"), c.shape.at())?;
            for (k, value) in c.shape.fields().1 {
                match k {
                    "start_deg" | "end_deg" => {
                        check_finite(&f(k), value)?;
                    }
                    "chords" => {
                        if !(value >= 1.0 && value <= MAX_CHORDS as f64 && value.fract() == 0.0) {
                            return Err(GranrsError::InvalidParameter {
                                field: f(k),
                                value,
                                allowed: format!("a whole number from 1 to {MAX_CHORDS}"),
                            });
                        }
                    }
                    _ => {
                        check_range(&f(k), value, 0.0, true)?;
                    }
                }
            }
            if let ContactShape::Arc { start, end, .. } = c.shape {
                let span = end - start;
                if !(span > 0.0 && span <= std::f64::consts::TAU * (1.0 + 1e-12)) {
                    return Err(GranrsError::InvalidParameter {
                        field: f("end_deg"),
                        value: end.to_degrees(),
                        allowed: format!(
                            "start_deg < end_deg <= start_deg + 360 (start_deg = {})",
                            start.to_degrees()
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Check a table-driven joint's table: at least two points, finite, the times strictly
    /// increasing, and its angle at t = 0 the joint's initial relative angle.
    fn validate_table(&self, j: &JointSpec) -> Result<()> {
        let field = format!("joints.{}.table", j.name);
        let Some(d) = &j.table else {
            return Err(bad(
                field,
                "a joint driven along a table needs its table of (time, angle_deg) pairs".into(),
            ));
        };
        let param = |value: f64, allowed: String| GranrsError::InvalidParameter {
            field: field.clone(),
            value,
            allowed,
        };
        if d.times.len() < 2 || d.times.len() != d.angles.len() {
            return Err(param(
                d.times.len() as f64,
                "at least 2 (time [s], angle [deg]) points".into(),
            ));
        }
        for (i, (&t, &a)) in d.times.iter().zip(&d.angles).enumerate() {
            if !t.is_finite() {
                return Err(param(t, format!("a finite time [s] (row {i})")));
            }
            if !a.is_finite() {
                return Err(param(
                    a.to_degrees(),
                    format!("a finite angle [deg] (row {i})"),
                ));
            }
            if i > 0 && t <= d.times[i - 1] {
                return Err(param(
                    t,
                    format!(
                        "times strictly increasing: row {i}'s time after row {}'s ({} s)",
                        i - 1,
                        d.times[i - 1]
                    ),
                ));
            }
        }
        let q = |name: &str| self.link_index(name).map_or(0.0, |i| self.links[i].q);
        let initial = q(&j.child) - q(&j.parent);
        let at_zero = d.angle(0.0);
        if (initial - at_zero).abs() > TABLE_START_TOL {
            return Err(bad(
                field,
                format!(
                    "the table's angle at t = 0 ({:.9} deg) must be the joint's initial \
                     relative angle, links.{}.q_deg - links.{}.q_deg ({:.9} deg)",
                    at_zero.to_degrees(),
                    j.child,
                    j.parent,
                    initial.to_degrees()
                ),
            ));
        }
        Ok(())
    }

    /// Check every field (the body, the medium, the numerics and the joints' stiffness at
    /// this step); the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        self.validate_body()?;
        self.validate_terms_on_shapes()?;
        super::validate_medium(&self.medium)?;
        validate_options(&self.options, &self.sign_model)?;
        let order = self.order();
        let names: Vec<String> = order
            .iter()
            .map(|&i| {
                self.joints
                    .iter()
                    .find(|j| j.child == self.links[i].name)
                    .map(|j| format!("joints.{}", j.name))
                    .unwrap_or_default()
            })
            .collect();
        let names: Vec<&str> = names.iter().map(|s| s.as_str()).collect();
        with_size!(self.size(), N => {
            let model = self.model::<N>();
            validate_joint_stiffness(&model, &self.initial_state::<N>().0, &self.options, &names)
        })
    }

    /// Refuse a contact term that is not defined on a contact's shape (the term's
    /// [`TermInfo::shapes`](crate::forces::TermInfo::shapes)), naming the term and the
    /// contact, with the terms that act on that shape.
    pub fn validate_terms_on_shapes(&self) -> Result<()> {
        for (i, c) in self.contacts.iter().enumerate() {
            let kind = c.shape.kind();
            let Some(info) = self
                .forces
                .contact_info
                .iter()
                .find(|t| !t.shapes.contains(&kind))
            else {
                continue;
            };
            let name = if c.name.is_empty() {
                format!("{i}")
            } else {
                c.name.clone()
            };
            let fine: Vec<&str> = crate::forces::TERMS
                .iter()
                .filter(|t| t.acts == crate::forces::Acts::Contact && t.shapes.contains(&kind))
                .map(|t| t.name)
                .collect();
            let shape = kind.name();
            let a = if shape.starts_with('a') { "an" } else { "a" };
            return Err(bad(
                format!("forces.{}", info.name),
                format!(
                    "the term {:?} is not defined on {a} {shape} contact, and contacts.{name} \
                     is one; the terms that act on {a} {shape}: {}",
                    info.name,
                    fine.join(", ")
                ),
            ));
        }
        Ok(())
    }

    /// Whether a joint reads the time (a sinusoidal drive): the mechanism then has a clock
    /// coordinate after the links' ([`Mechanism::clock`]).
    pub fn has_clock(&self) -> bool {
        self.joints.iter().any(|j| j.joint.reads_clock())
    }

    /// The generalized coordinates beyond the root's: a link's angle each, and the clock.
    pub fn size(&self) -> usize {
        self.links.len() + usize::from(self.has_clock())
    }

    fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    #[cold]
    fn unknown_link(&self, field: &str, name: &str) -> GranrsError {
        let names: Vec<&str> = self.links.iter().map(|l| l.name.as_str()).collect();
        GranrsError::UnknownName {
            field: field.into(),
            value: name.into(),
            allowed: format!("a link of this linkage: {}", names.join(", ")),
        }
    }

    /// The links in the engine's order (a parent before its children): the root link, then
    /// breadth first through the joints in their order. Needs a valid body.
    pub fn order(&self) -> Vec<usize> {
        let mut order = vec![self.link_index(&self.root.link).unwrap_or(0)];
        let mut k = 0;
        while k < order.len() {
            let parent = &self.links[order[k]].name;
            for j in self.joints.iter().filter(|j| &j.parent == parent) {
                if let Some(c) = self.link_index(&j.child) {
                    if !order.contains(&c) {
                        order.push(c);
                    }
                }
            }
            k += 1;
        }
        order
    }

    /// The linkage as a model of `N = 2 + links` coordinates (a valid body).
    pub fn model<const N: usize>(&self) -> Model<N> {
        let order = self.order();
        let slot = |name: &str| {
            let i = self.link_index(name).unwrap_or(0);
            order.iter().position(|&o| o == i).unwrap_or(0)
        };
        let links = order
            .iter()
            .map(|&i| {
                let l = &self.links[i];
                let joint = self.joints.iter().find(|j| j.child == l.name);
                Link {
                    mass: l.mass,
                    inertia: l.inertia,
                    com: l.com,
                    parent: joint.map(|j| slot(&j.parent)),
                    joint_on_parent: joint.map_or(Vector2::zeros(), |j| j.at),
                    joint: joint.map_or(Joint::Free, |j| j.joint),
                }
            })
            .collect();
        let contacts = self
            .contacts
            .iter()
            .map(|c| {
                let link = slot(&c.link);
                Contact {
                    shape: match c.shape {
                        ContactShape::Rod {
                            tip,
                            length,
                            diameter,
                        } => Shape::Rod(RodContact {
                            link,
                            tip,
                            length,
                            diameter,
                        }),
                        ContactShape::Box {
                            corner,
                            length,
                            height,
                            width,
                            l_ref,
                            thesis_angle_of,
                        } => Shape::Sole(SoleContact {
                            link,
                            angle_link: thesis_angle_of.map_or(link, |i| slot(&self.links[i].name)),
                            heel: corner,
                            length,
                            height,
                            width,
                            l_ref,
                            model: if thesis_angle_of.is_some() {
                                SoleModel::Thesis
                            } else {
                                SoleModel::Box
                            },
                        }),
                        ContactShape::Arc {
                            centre,
                            radius,
                            start,
                            end,
                            width,
                            chords,
                        } => Shape::Arc(ArcContact {
                            link,
                            centre,
                            radius,
                            start,
                            span: end - start,
                            width,
                            chords: chords as usize,
                        }),
                    },
                }
            })
            .collect();
        Model {
            mechanism: Mechanism {
                links,
                root_mass: self.root.mass,
                root_fixed: self.root.kind != RootKind::Free,
                root_rate: self.root.rate,
            },
            contacts,
            medium: self.medium,
            apply_at: self.apply_at,
            sign_model: self.sign_model,
            forces: self.forces.clone(),
        }
    }

    /// Initial coordinates and rates in the engine's order: the root's position and
    /// velocity (zero for a pinned root), each link's angle and rate (behind a locked or
    /// driven joint, the parent's rate plus the joint's).
    pub fn initial_state<const N: usize>(&self) -> (SVector<f64, N>, SVector<f64, N>) {
        let order = self.order();
        let mut q = SVector::<f64, N>::zeros();
        let mut qd = SVector::<f64, N>::zeros();
        q[0] = self.root.position.x;
        q[1] = self.root.position.y;
        if self.root.kind != RootKind::Pinned {
            qd[0] = self.root.velocity.x;
            qd[1] = self.root.velocity.y;
        }
        for (k, &i) in order.iter().enumerate() {
            let l = &self.links[i];
            q[2 + k] = l.q;
            qd[2 + k] = l.omega;
            if k == 0 {
                if let Some(rate) = self.root.rate {
                    qd[2] = rate;
                }
            }
            if let Some(j) = self.joints.iter().find(|j| j.child == l.name) {
                let p = self.link_index(&j.parent).unwrap_or(0);
                let pk = order.iter().position(|&o| o == p).unwrap_or(0);
                match j.joint {
                    Joint::Locked => qd[2 + k] = qd[2 + pk],
                    Joint::Driven {
                        rate,
                        amplitude,
                        omega,
                        phase,
                    } => qd[2 + k] = qd[2 + pk] + rate + amplitude * omega * phase.cos(),
                    // The angle from the table (which agrees with the links' to
                    // TABLE_START_TOL), the rate its segment's at t = 0.
                    Joint::Table => {
                        if let Some(d) = &j.table {
                            q[2 + k] = q[2 + pk] + d.angle(0.0);
                            qd[2 + k] = qd[2 + pk] + d.slope(0.0);
                        }
                    }
                    _ => {}
                }
            }
        }
        if self.has_clock() {
            // The clock: q = t = 0, qdot = 1.
            qd[N - 1] = 1.0;
        }
        (q, qd)
    }

    /// Validate and run.
    pub fn run(&self) -> Result<Outcome> {
        self.validate()?;
        self.run_validated()
    }

    /// [`LinkageScene::run`] of a scene already validated ([`LinkageScene::validate`], as
    /// [`crate::spec::SceneSpec::build`] does): a compiled scene run many times is not
    /// validated again on every run.
    pub fn run_validated(&self) -> Result<Outcome> {
        with_size!(self.size(), N => {
            let (q0, qd0) = self.initial_state::<N>();
            solve_driven(&self.model::<N>(), q0, qd0, &self.options, self.drives())
        })
    }

    /// The table-driven joints, each with the link it carries in the engine's order.
    pub fn drives(&self) -> Drives {
        let order = self.order();
        Drives::new(
            self.joints
                .iter()
                .filter_map(|j| {
                    let d = j.table.clone()?;
                    let i = self.link_index(&j.child)?;
                    Some((order.iter().position(|&o| o == i)?, d))
                })
                .collect(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::free_link::FreeLink;
    use crate::presets::Setting;

    fn pendulum(joint: Joint) -> LinkageScene {
        let link = |name: &str, q: f64| LinkSpec {
            name: name.into(),
            mass: 1.0,
            inertia: 0.0075,
            com: Vector2::new(0.15, 0.0),
            length: 0.3,
            q,
            omega: 0.0,
        };
        let base = FreeLink::default().scene(Setting::default());
        LinkageScene {
            links: vec![link("a", 2.0), link("b", 2.5)],
            joints: vec![JointSpec {
                name: "j".into(),
                parent: "a".into(),
                child: "b".into(),
                at: Vector2::new(0.3, 0.0),
                joint,
                table: None,
            }],
            contacts: vec![],
            root: RootSpec {
                kind: RootKind::Pinned,
                link: "a".into(),
                position: Vector2::new(0.0, 1.0),
                velocity: Vector2::zeros(),
                mass: 0.0,
                rate: None,
            },
            ..base
        }
    }

    #[test]
    fn a_validated_scene_runs_as_run_does() {
        // `run_validated` (a compiled scene's run) is `run` without the validation: the same
        // outcome, and an invalid scene is refused by `run` (and by `SceneSpec::build`).
        let free = FreeLink::default().scene(Setting::default());
        assert_eq!(free.run_validated().unwrap(), free.run().unwrap());
        let s = pendulum(Joint::Free);
        assert_eq!(s.run_validated().unwrap(), s.run().unwrap());
        let mut bad = pendulum(Joint::Free);
        bad.joints[0].parent = "c".into();
        assert!(bad.run().is_err());
    }

    #[test]
    fn structure_errors_name_the_element() {
        let mut s = pendulum(Joint::Free);
        s.joints[0].parent = "c".into();
        let e = s.validate().unwrap_err();
        assert!(
            matches!(e, GranrsError::UnknownName { ref field, .. } if field == "joints.j.parent")
        );
        let mut s = pendulum(Joint::Free);
        s.joints.clear();
        let e = s.validate().unwrap_err();
        assert!(matches!(e, GranrsError::InvalidScene { ref field, .. } if field == "links.b"));
        let s = pendulum(Joint::driven(f64::NAN));
        let e = s.validate().unwrap_err();
        assert!(
            matches!(e, GranrsError::InvalidParameter { ref field, .. } if field == "joints.j.rate")
        );
    }

    #[test]
    fn a_pinned_root_stays_put_and_a_locked_pendulum_swings_as_one() {
        let mut s = pendulum(Joint::Locked);
        s.options.t_end = 0.2;
        s.options.end = crate::integrate::EndCondition::Time;
        let model = s.model::<4>();
        let (q0, qd0) = s.initial_state::<4>();
        let e = model.eval(&q0, &qd0, &Default::default());
        assert_eq!((e.qdd[0], e.qdd[1]), (0.0, 0.0));
        assert!((e.qdd[2] - e.qdd[3]).abs() < 1e-12 * e.qdd[2].abs());
        assert!(e.qdd[2].abs() > 1.0);
    }
}
