//! A scene as data: named fields with plain values ([`SceneSpec`]), and the one set of rules
//! that turns them into a validated [`LinkageScene`] (a preset's, or the linkage given).
//!
//! Python dicts (`granrs.Scene.to_dict()`), TOML files (through Python) and sweep axes all
//! arrive as a `SceneSpec`, so that they share every check and every error message. A sweep
//! keeps one base spec and overrides a few fields per run ([`SceneSpec::set`]), which needs
//! neither Python nor the GIL.

use std::borrow::Cow;

use nalgebra::Vector2;

use crate::bodies::linkage::{JOINT_FIELDS, SHAPE_FIELDS};
use crate::bodies::{
    ContactShape, ContactSpec, JointSpec, LinkSpec, LinkageScene, RootKind, RootSpec,
};
use crate::body::rod::ApplyAt;
use crate::body::{DriveTable, Joint};
use crate::dynamics::SignModel;
use crate::error::{check_range, GranrsError, Result};
use crate::forces::{Coefficients, ForceSet, Medium, TermSpec};
use crate::integrate::{EndCondition, Method, Outputs, Record, SolveOptions};
use crate::presets::{self, Fields, Setting};

#[cfg(test)]
mod tests;
mod value;

use crate::fields::field_slot;
pub use crate::fields::{ElementField, FieldInfo, ELEMENT_FIELDS, FIELDS, SCENE_FIELDS};

#[cfg(test)]
pub(crate) use tests::free_link_spec;
pub use value::{word, Value};

/// Names of the series a scene may record.
pub const RECORDS: [&str; 3] = ["state", "forces", "energy"];

/// A scene as named fields. Fields that a body does not use are ignored.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneSpec {
    /// The fields of [`SCENE_FIELDS`], by slot.
    known: [Option<Value>; SCENE_FIELDS.len()],
    /// Any other field, sorted by name.
    others: Vec<(String, Value)>,
}

impl Default for SceneSpec {
    fn default() -> Self {
        SceneSpec {
            known: [const { None }; SCENE_FIELDS.len()],
            others: Vec::new(),
        }
    }
}

#[cold]
#[inline(never)]
fn missing(field: &str) -> GranrsError {
    GranrsError::InvalidScene {
        field: field.to_string(),
        message: "missing (a value is needed)".into(),
    }
}

#[cold]
#[inline(never)]
fn wrong(field: &str, expected: &str, got: &Value) -> GranrsError {
    GranrsError::WrongType {
        field: field.to_string(),
        expected: expected.to_string(),
        got: got.kind(),
    }
}

#[cold]
#[inline(never)]
fn unknown(field: &str, value: &str, allowed: &[&str]) -> GranrsError {
    GranrsError::UnknownName {
        field: field.to_string(),
        value: value.to_string(),
        allowed: allowed.join(", "),
    }
}

/// An error about key `k` of the mapping `field`, renamed to the field `field.k`.
#[cold]
#[inline(never)]
fn within(e: GranrsError, field: &str, k: &str) -> GranrsError {
    match e {
        GranrsError::InvalidScene { .. } | GranrsError::WrongType { .. } => {
            e.map_field(|_| format!("{field}.{k}"))
        }
        other => other,
    }
}

fn num(field: &str, v: Option<&Value>) -> Result<f64> {
    match v {
        None => Err(missing(field)),
        Some(Value::Num(x)) => Ok(*x),
        Some(other) => Err(wrong(field, "a real number", other)),
    }
}

fn map_get<'a>(entries: &'a [(Cow<'static, str>, Value)], k: &str) -> Option<&'a Value> {
    entries.iter().find(|(name, _)| name == k).map(|(_, v)| v)
}

impl SceneSpec {
    /// An empty spec.
    pub fn new() -> Self {
        Self::default()
    }

    /// A spec from (field, value) pairs; a later duplicate replaces an earlier one.
    pub fn from_pairs(pairs: Vec<(String, Value)>) -> Self {
        let mut spec = Self::new();
        for (name, value) in pairs {
            spec.set(&name, value);
        }
        spec
    }

    /// Set (or replace) a field.
    pub fn set(&mut self, field: &str, value: Value) {
        if let Some(slot) = field_slot(field) {
            self.known[slot] = Some(value);
            return;
        }
        match self
            .others
            .binary_search_by(|(name, _)| name.as_str().cmp(field))
        {
            Ok(i) => self.others[i].1 = value,
            Err(i) => self.others.insert(i, (field.to_string(), value)),
        }
    }

    /// The slot of a field of [`SCENE_FIELDS`], for [`SceneSpec::set_slot`].
    pub fn slot_of(field: &str) -> Option<usize> {
        field_slot(field)
    }

    /// Set the field of slot `slot` (see [`SceneSpec::slot_of`]).
    pub fn set_slot(&mut self, slot: usize, value: Value) {
        self.known[slot] = Some(value);
    }

    /// A field's value, if present.
    #[inline]
    pub fn get(&self, field: &str) -> Option<&Value> {
        match field_slot(field) {
            Some(slot) => self.known[slot].as_ref(),
            None => self
                .others
                .binary_search_by(|(name, _)| name.as_str().cmp(field))
                .ok()
                .map(|i| &self.others[i].1),
        }
    }

    /// Whether a field is present and not `None`.
    fn has(&self, field: &str) -> bool {
        !matches!(self.get(field), None | Some(Value::None))
    }

    /// A required number.
    pub fn f64(&self, field: &str) -> Result<f64> {
        num(field, self.get(field))
    }

    /// An optional number (absent or `None` gives `None`).
    pub fn opt_f64(&self, field: &str) -> Result<Option<f64>> {
        if self.has(field) {
            self.f64(field).map(Some)
        } else {
            Ok(None)
        }
    }

    /// A number with a default when the field is absent (a TOML file may leave it out);
    /// `None` is not a number and is refused, naming the field.
    fn f64_or(&self, field: &str, default: f64) -> Result<f64> {
        match self.get(field) {
            None => Ok(default),
            v => num(field, v),
        }
    }

    /// A required string.
    pub fn str(&self, field: &str) -> Result<&str> {
        match self.get(field) {
            None => Err(missing(field)),
            Some(Value::Str(s)) => Ok(s.as_ref()),
            Some(other) => Err(wrong(field, "a string", other)),
        }
    }

    /// A list of names (absent or `None` gives `None`).
    fn names(&self, field: &str) -> Result<Option<&[Cow<'static, str>]>> {
        match self.get(field) {
            None | Some(Value::None) => Ok(None),
            Some(Value::Names(n)) => Ok(Some(n)),
            Some(other) => Err(wrong(field, "a list of names", other)),
        }
    }

    /// The force terms of a body with `n_contacts` contacts: the `forces` list (absent: the
    /// thesis's law with each term's defaults, Table 3.4 at q = 0, as `granrs.Scene`'s).
    fn forces(&self, n_contacts: usize) -> Result<ForceSet> {
        match self.get("forces") {
            // (A body without contacts, a linkage swinging in the air, takes one row.)
            None | Some(Value::None) => Ok(ForceSet::thesis(&vec![
                Coefficients::TABLE_3_4_VERTICAL;
                n_contacts.max(1)
            ])),
            Some(Value::Terms(specs)) => ForceSet::build(specs, n_contacts),
            Some(Value::Names(n)) if n.is_empty() => ForceSet::build(&[], n_contacts),
            Some(other) => Err(wrong("forces", "a list of force terms", other)),
        }
    }

    /// A joint: `"free"`, `"locked"`, or a spring-damper `{"k": .., "c": ..}`; absent or
    /// `None` gives `default`.
    fn joint(&self, field: &str, default: Joint) -> Result<Joint> {
        match self.get(field) {
            None | Some(Value::None) => Ok(default),
            Some(Value::Str(name)) => match name.as_ref() {
                "free" => Ok(Joint::Free),
                "locked" => Ok(Joint::Locked),
                other => Err(unknown(
                    field,
                    other,
                    &["free", "locked", "{k, c} spring-damper"],
                )),
            },
            Some(Value::Map(entries)) => {
                for (k, _) in entries {
                    if k != "k" && k != "c" {
                        return Err(unknown(&format!("{field}.{k}"), k, &["k", "c"]));
                    }
                }
                let get = |k: &str| num(k, map_get(entries, k)).map_err(|e| within(e, field, k));
                Ok(Joint::Spring {
                    k: get("k")?,
                    c: get("c")?,
                    rest: 0.0,
                })
            }
            Some(other) => Err(wrong(
                field,
                "\"free\", \"locked\" or a spring-damper mapping {\"k\": N m/rad, \"c\": N m s/rad}",
                other,
            )),
        }
    }

    fn record(&self) -> Result<Record> {
        let mut r = Record::default();
        for n in self.names("record")?.unwrap_or_default() {
            let seen = match n.as_ref() {
                "state" => std::mem::replace(&mut r.state, true),
                "forces" => std::mem::replace(&mut r.forces, true),
                "energy" => std::mem::replace(&mut r.energy, true),
                other => return Err(unknown("record", other, &RECORDS)),
            };
            if seen {
                return Err(GranrsError::InvalidScene {
                    field: "record".into(),
                    message: format!("lists {n:?} twice (each series once)"),
                });
            }
        }
        let stride = self.f64_or("record_stride", 1.0)?;
        if !(stride.is_finite() && stride >= 1.0 && stride.fract() == 0.0 && stride < 1e12) {
            return Err(GranrsError::InvalidParameter {
                field: "record_stride".into(),
                value: stride,
                allowed: "a whole number >= 1".into(),
            });
        }
        r.stride = stride as usize;
        Ok(r)
    }

    /// The output fields a run returns: the names listed in `outputs` (absent or `None`:
    /// every field).
    pub fn outputs(&self) -> Result<Outputs> {
        match self.names("outputs")? {
            None => Ok(Outputs::ALL),
            Some(names) => Outputs::from_names(names),
        }
    }

    /// The fields every body shares but its forces.
    fn common_numerics(&self) -> Result<Common> {
        // The fields that one sign model or one method reads are checked whichever is
        // chosen: a scene holding a bad one is refused, not kept until it is switched on.
        for name in ["smooth_eps", "rtol", "atol"] {
            if let Some(x) = self.opt_f64(name)? {
                check_range(name, x, 0.0, true)?;
            }
        }
        // Read by granrs.simulate and granrs.sweep (the step's check), not by the run: checked
        // here with every field.
        match self.get("step_check") {
            None | Some(Value::Bool(_)) => {}
            Some(other) => return Err(wrong("step_check", "true or false", other)),
        }
        let apply_at = match self.str("apply_at")? {
            "tip" => ApplyAt::Tip,
            "centroid" => ApplyAt::Centroid,
            other => return Err(unknown("apply_at", other, &["tip", "centroid"])),
        };
        let sign_model = match self.str("sign_model")? {
            "modes" => SignModel::Modes,
            "raw" => SignModel::Raw,
            "smooth" => SignModel::Smooth {
                eps: self.f64("smooth_eps")?,
            },
            other => return Err(unknown("sign_model", other, &["modes", "raw", "smooth"])),
        };
        let end = match self.str("end")? {
            "first_stop" => EndCondition::FirstStop,
            "all_stops" => EndCondition::AllStops,
            "time" => EndCondition::Time,
            other => return Err(unknown("end", other, &["first_stop", "all_stops", "time"])),
        };
        let method = match self.str("method")? {
            "rk4" => Method::Rk4,
            "dopri5" => Method::Dopri5 {
                rtol: self.f64("rtol")?,
                atol: self.f64("atol")?,
            },
            other => return Err(unknown("method", other, &["rk4", "dopri5"])),
        };
        Ok(Common {
            medium: Medium {
                rho_g: self.f64("rho_g")?,
                g: self.f64("g")?,
            },
            apply_at,
            sign_model,
            options: SolveOptions {
                dt: self.f64("dt")?,
                method,
                t_end: self.f64("t_end")?,
                end,
                record: self.record()?,
                outputs: self.outputs()?,
            },
        })
    }

    /// The body named by the `body` field (`"linkage"` for a linkage's mapping, else a
    /// preset's name).
    pub fn body(&self) -> Result<&str> {
        if let Some(Value::Map(_)) = self.get("body") {
            return Ok("linkage");
        }
        let body = self.str("body")?;
        match presets::preset(body) {
            Some(p) => Ok(p.name),
            None => Err(unknown("body", body, &presets::names())),
        }
    }

    /// Build the scene (a preset's linkage, or the linkage given) and validate every field;
    /// the error names the first bad one, as the user wrote it.
    pub fn build(&self) -> Result<LinkageScene> {
        let scene = self.body_scene()?;
        match self.body()? {
            "linkage" => scene.validate()?,
            name => {
                if let Some(preset) = presets::preset(name) {
                    scene.validate().map_err(|e| preset.rename(e))?;
                }
            }
        }
        Ok(scene)
    }

    /// Build the scene, checking what building needs (types, names, and a preset's own
    /// parameters); [`Self::build`] validates the rest.
    pub fn body_scene(&self) -> Result<LinkageScene> {
        match self.body()? {
            "linkage" => self.linkage(),
            name => match presets::preset(name) {
                Some(preset) => (preset.build)(self),
                None => Err(unknown("body", name, &presets::names())),
            },
        }
    }
}

impl Fields for SceneSpec {
    fn f64(&self, field: &str) -> Result<f64> {
        SceneSpec::f64(self, field)
    }

    fn opt_f64(&self, field: &str) -> Result<Option<f64>> {
        SceneSpec::opt_f64(self, field)
    }

    fn f64_or(&self, field: &str, default: f64) -> Result<f64> {
        SceneSpec::f64_or(self, field, default)
    }

    fn joint(&self, field: &str, default: Joint) -> Result<Joint> {
        SceneSpec::joint(self, field, default)
    }

    fn choice<'a>(&'a self, field: &str, default: &'a str, allowed: &[&str]) -> Result<&'a str> {
        if !self.has(field) {
            return Ok(default);
        }
        let v = self.str(field)?;
        if allowed.contains(&v) {
            Ok(v)
        } else {
            Err(unknown(field, v, allowed))
        }
    }

    fn setting(&self, n_contacts: usize) -> Result<Setting> {
        let c = self.common_numerics()?;
        Ok(Setting {
            medium: c.medium,
            apply_at: c.apply_at,
            sign_model: c.sign_model,
            forces: self.forces(n_contacts)?,
            options: c.options,
        })
    }
}

/// The entries of one element of a linkage (`body.links[i]`, ...), each key checked
/// against [`ELEMENT_FIELDS`].
struct Element<'a> {
    /// `links.<name>` (or `links[i]` before the name is known).
    path: String,
    entries: &'a [(Cow<'static, str>, Value)],
}

impl<'a> Element<'a> {
    fn new(kind: &str, plural: &str, i: usize, v: &'a Value) -> Result<(Element<'a>, String)> {
        let at = format!("{plural}[{i}]");
        let Value::Map(entries) = v else {
            return Err(wrong(&at, &format!("a {kind} (a mapping)"), v));
        };
        let allowed: Vec<&str> = ELEMENT_FIELDS
            .iter()
            .filter(|f| f.element == kind)
            .map(|f| f.name)
            .collect();
        for (k, _) in entries.iter() {
            if !allowed.contains(&k.as_ref()) {
                return Err(unknown(&format!("{at}.{k}"), k, &allowed));
            }
        }
        let name = match map_get(entries, "name") {
            None | Some(Value::None) => String::new(),
            Some(Value::Str(s)) => s.to_string(),
            Some(other) => return Err(wrong(&format!("{at}.name"), "a string", other)),
        };
        let path = if name.is_empty() {
            at
        } else {
            format!("{plural}.{name}")
        };
        Ok((Element { path, entries }, name))
    }

    /// Refuse a key that the element's kind (`kind`, a key of `keys`) does not read, where
    /// `keys` lists the keys only some kinds read (the other keys every kind reads): a rod
    /// contact given a `radius` is an error, not a value silently left unused. An unknown
    /// kind passes (its own check names it).
    fn only_for(&self, what: &str, keys: &[(&str, &[&str])], kind: &str) -> Result<()> {
        let Some((_, own)) = keys.iter().find(|(k, _)| *k == kind) else {
            return Ok(());
        };
        for (k, v) in self.entries {
            let k = k.as_ref();
            let some_kind_reads = keys.iter().any(|(_, ks)| ks.contains(&k));
            if some_kind_reads && !own.contains(&k) && !matches!(v, Value::None) {
                return Err(GranrsError::InvalidScene {
                    field: self.field(k),
                    message: format!(
                        "{what} takes no {k} (it reads {}); leave it out",
                        if own.is_empty() {
                            "none of its kind's parameters".to_string()
                        } else {
                            own.join(", ")
                        }
                    ),
                });
            }
        }
        Ok(())
    }

    fn field(&self, k: &str) -> String {
        format!("{}.{k}", self.path)
    }

    fn get(&self, k: &str) -> Option<&'a Value> {
        match map_get(self.entries, k) {
            None | Some(Value::None) => None,
            v => v,
        }
    }

    fn num(&self, k: &str) -> Result<f64> {
        num(&self.field(k), self.get(k))
    }

    fn num_or(&self, k: &str, default: f64) -> Result<f64> {
        match self.get(k) {
            None => Ok(default),
            v => num(&self.field(k), v),
        }
    }

    fn str(&self, k: &str) -> Result<&'a str> {
        match self.get(k) {
            None => Err(missing(&self.field(k))),
            Some(Value::Str(s)) => Ok(s.as_ref()),
            Some(other) => Err(wrong(&self.field(k), "a string", other)),
        }
    }

    fn point_or(&self, k: &str, default: Vector2<f64>) -> Result<Vector2<f64>> {
        match self.get(k) {
            None => Ok(default),
            Some(Value::List(xs)) if xs.len() == 2 => {
                let a = num(&format!("{}[0]", self.field(k)), Some(&xs[0]))?;
                let b = num(&format!("{}[1]", self.field(k)), Some(&xs[1]))?;
                Ok(Vector2::new(a, b))
            }
            Some(other) => Err(wrong(&self.field(k), "a pair of numbers", other)),
        }
    }
}

/// A driven joint's table, `[(time [s], angle [deg]), ...]`, with its angles in radians
/// (its values are checked by the linkage).
fn drive_table(field: &str, v: &Value) -> Result<DriveTable> {
    let rows: &[Value] = match v {
        Value::List(rows) => rows,
        Value::Names(n) if n.is_empty() => &[],
        other => {
            return Err(wrong(
                field,
                "a list of (time [s], angle [deg]) pairs",
                other,
            ))
        }
    };
    let mut table = DriveTable {
        times: Vec::with_capacity(rows.len()),
        angles: Vec::with_capacity(rows.len()),
    };
    for (i, row) in rows.iter().enumerate() {
        let pair = match row {
            Value::List(p) if p.len() == 2 => p,
            other => {
                return Err(wrong(
                    field,
                    &format!("a list of (time [s], angle [deg]) pairs (row {i} is not one)"),
                    other,
                ))
            }
        };
        let entry = |k: usize| match &pair[k] {
            Value::Num(x) => Ok(*x),
            other => Err(wrong(
                field,
                &format!("numbers (time [s], angle [deg]) in each row (row {i})"),
                other,
            )),
        };
        table.times.push(entry(0)?);
        table.angles.push(entry(1)?.to_radians());
    }
    Ok(table)
}

/// The elements of one list of a linkage (`links`, `joints`, `contacts`).
fn elements<'a>(entries: &'a [(Cow<'static, str>, Value)], k: &str) -> Result<&'a [Value]> {
    match map_get(entries, k) {
        None | Some(Value::None) => Ok(&[]),
        Some(Value::List(items)) => Ok(items),
        Some(Value::Names(n)) if n.is_empty() => Ok(&[]),
        Some(other) => Err(wrong(k, "a list of mappings", other)),
    }
}

impl SceneSpec {
    /// A user-defined linkage: the `body` mapping (`links`, `joints`, `contacts`, `root`)
    /// and the fields every body shares.
    fn linkage(&self) -> Result<LinkageScene> {
        let Some(Value::Map(body)) = self.get("body") else {
            return Err(missing("body"));
        };
        for (k, _) in body.iter() {
            if !["links", "joints", "contacts", "root"].contains(&k.as_ref()) {
                return Err(unknown(
                    &format!("body.{k}"),
                    k,
                    &["links", "joints", "contacts", "root"],
                ));
            }
        }
        let mut links = Vec::new();
        for (i, v) in elements(body, "links")?.iter().enumerate() {
            let (e, name) = Element::new("link", "links", i, v)?;
            links.push(LinkSpec {
                name,
                mass: e.num("mass")?,
                inertia: e.num("inertia")?,
                com: e.point_or("com", Vector2::zeros())?,
                length: e.num("length")?,
                q: e.num_or("q_deg", 0.0)?.to_radians(),
                omega: e.num_or("omega0", 0.0)?,
            });
        }
        let mut joints = Vec::new();
        for (i, v) in elements(body, "joints")?.iter().enumerate() {
            let (e, name) = Element::new("joint", "joints", i, v)?;
            let kind = match e.get("kind") {
                None => "free",
                Some(_) => e.str("kind")?,
            };
            e.only_for(&format!("a joint of kind {kind:?}"), JOINT_FIELDS, kind)?;
            let parent = e.str("parent")?.to_string();
            let child = e.str("child")?.to_string();
            let table = match e.get("table") {
                None => None,
                Some(v) => {
                    let field = e.field("table");
                    let clash = ["rate", "amplitude_deg", "frequency", "phase_deg"]
                        .into_iter()
                        .find(|k| e.get(k).is_some());
                    if kind != "driven" || clash.is_some() {
                        return Err(GranrsError::InvalidScene {
                            field,
                            message: match clash {
                                Some(k) => format!(
                                    "a table drives the joint alone: leave out {k} (or the table)"
                                ),
                                None => format!(
                                    "a table drives a joint of kind \"driven\", not {kind:?}"
                                ),
                            },
                        });
                    }
                    Some(drive_table(&field, v)?)
                }
            };
            let joint = match kind {
                "free" => Joint::Free,
                "locked" => Joint::Locked,
                "spring" => {
                    let rest = match e.get("rest_deg") {
                        Some(_) => e.num("rest_deg")?.to_radians(),
                        None => {
                            // The initial relative angle.
                            let q =
                                |n: &str| links.iter().find(|l| l.name == n).map_or(0.0, |l| l.q);
                            q(&child) - q(&parent)
                        }
                    };
                    Joint::Spring {
                        k: e.num("k")?,
                        c: e.num("c")?,
                        rest,
                    }
                }
                "driven" if table.is_some() => Joint::Table,
                "driven" => {
                    let amplitude = e.num_or("amplitude_deg", 0.0)?;
                    let frequency = if amplitude != 0.0 {
                        e.num("frequency")?
                    } else {
                        e.num_or("frequency", 0.0)?
                    };
                    Joint::Driven {
                        rate: e.num_or("rate", 0.0)?,
                        amplitude: amplitude.to_radians(),
                        omega: std::f64::consts::TAU * frequency,
                        phase: e.num_or("phase_deg", 0.0)?.to_radians(),
                    }
                }
                other => {
                    return Err(unknown(
                        &e.field("kind"),
                        other,
                        &["free", "locked", "spring", "driven"],
                    ))
                }
            };
            joints.push(JointSpec {
                name,
                parent,
                child,
                at: e.point_or("at", Vector2::zeros())?,
                joint,
                table,
            });
        }
        let mut contacts = Vec::new();
        for (i, v) in elements(body, "contacts")?.iter().enumerate() {
            let (e, name) = Element::new("contact", "contacts", i, v)?;
            let at = e.point_or("at", Vector2::zeros())?;
            let shape_name = e.str("shape")?;
            let shapes: Vec<&str> = SHAPE_FIELDS.iter().map(|(k, _)| *k).collect();
            if !shapes.contains(&shape_name) {
                return Err(unknown(&e.field("shape"), shape_name, &shapes));
            }
            e.only_for(
                &format!("a contact of shape {shape_name:?}"),
                SHAPE_FIELDS,
                shape_name,
            )?;
            let length = if shape_name == "arc" {
                0.0
            } else {
                e.num("length")?
            };
            let shape = match shape_name {
                "arc" => ContactShape::Arc {
                    centre: at,
                    radius: e.num("radius")?,
                    start: e.num("start_deg")?.to_radians(),
                    end: e.num("end_deg")?.to_radians(),
                    width: e.num("width")?,
                    chords: e.num_or("chords", crate::body::arc::DEFAULT_CHORDS as f64)?,
                },
                "rod" => ContactShape::Rod {
                    tip: at,
                    length,
                    diameter: e.num("diameter")?,
                },
                "box" => ContactShape::Box {
                    corner: at,
                    length,
                    height: e.num("height")?,
                    width: e.num("width")?,
                    l_ref: e.num_or("l_ref", length)?,
                    thesis_angle_of: None,
                },
                other => return Err(unknown(&e.field("shape"), other, &shapes)),
            };
            contacts.push(ContactSpec {
                name,
                link: e.str("link")?.to_string(),
                shape,
            });
        }
        let root = match map_get(body, "root") {
            None | Some(Value::None) => RootSpec {
                kind: RootKind::Free,
                link: links.first().map(|l| l.name.clone()).unwrap_or_default(),
                position: Vector2::zeros(),
                velocity: Vector2::zeros(),
                mass: 0.0,
                rate: None,
            },
            Some(v @ Value::Map(entries)) => {
                let e = Element {
                    path: "root".into(),
                    entries,
                };
                for (k, _) in entries.iter() {
                    if !ELEMENT_FIELDS
                        .iter()
                        .any(|f| f.element == "root" && f.name == k)
                    {
                        let allowed: Vec<&str> = ELEMENT_FIELDS
                            .iter()
                            .filter(|f| f.element == "root")
                            .map(|f| f.name)
                            .collect();
                        return Err(unknown(&format!("root.{k}"), k, &allowed));
                    }
                }
                let _ = v;
                let kind = match e.get("kind") {
                    None => RootKind::Free,
                    Some(_) => match e.str("kind")? {
                        "free" => RootKind::Free,
                        "pinned" => RootKind::Pinned,
                        "moving" => RootKind::Moving,
                        other => {
                            return Err(unknown("root.kind", other, &["free", "pinned", "moving"]))
                        }
                    },
                };
                RootSpec {
                    kind,
                    link: match e.get("link") {
                        None => links.first().map(|l| l.name.clone()).unwrap_or_default(),
                        Some(_) => e.str("link")?.to_string(),
                    },
                    position: e.point_or("position", Vector2::zeros())?,
                    velocity: e.point_or("velocity", Vector2::zeros())?,
                    mass: e.num_or("mass", 0.0)?,
                    rate: match e.get("rate") {
                        None => None,
                        Some(_) => Some(e.num("rate")?),
                    },
                }
            }
            Some(other) => return Err(wrong("root", "a mapping", other)),
        };
        let c = self.setting(contacts.len())?;
        Ok(LinkageScene {
            links,
            joints,
            contacts,
            root,
            medium: c.medium,
            apply_at: c.apply_at,
            sign_model: c.sign_model,
            forces: c.forces,
            options: c.options,
        })
    }
}

/// The names of the terms of the thesis's law ([`ForceSet::thesis`]), which a law of
/// `effects` selects from.
pub fn effects() -> Vec<&'static str> {
    ForceSet::thesis(&[Coefficients::TABLE_3_4_VERTICAL]).names
}

/// The thesis's law with coefficients (eta_h, eta_d, eta_v, lambda) per contact, its terms
/// limited to `names` (every term when `None`).
pub fn thesis_law(
    names: Option<&[Cow<'static, str>]>,
    per_contact: &[Coefficients],
) -> Result<ForceSet> {
    let all = ForceSet::thesis(per_contact).specs();
    let Some(names) = names else {
        return ForceSet::build(&all, per_contact.len());
    };
    let effects = effects();
    for n in names {
        if !effects.contains(&n.as_ref()) {
            return Err(unknown("effects", n, &effects));
        }
    }
    let listed: Vec<TermSpec> = all
        .into_iter()
        .filter(|t| names.iter().any(|n| n == &t.name))
        .collect();
    ForceSet::build(&listed, per_contact.len())
}

/// The fields every body shares but its forces.
struct Common {
    medium: Medium,
    apply_at: ApplyAt,
    sign_model: SignModel,
    options: SolveOptions,
}
