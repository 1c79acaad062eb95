//! The Python module `granrs._granrs`: the only place that says `use pyo3`.
//!
//! Scenes arrive as plain dicts built by `granrs.Scene.to_dict()`, are converted to owned
//! Rust values and validated while the GIL is held, and run with the GIL released. Every
//! [`GranrsError`] becomes an instance of the matching class of `granrs.errors`, so that the
//! Python and Rust layers share one exception tree.

use numpy::IntoPyArray;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::body::rod::ApplyAt;
use crate::body::{Joint, SoleModel};
use crate::dynamics::{Effects, SignModel};
use crate::error::GranrsError;
use crate::force::{Coefficients, Medium};
use crate::integrate::{EndCondition, Method, Outcome, Record, SolveOptions};
use crate::scene::{AnyScene, ChainScene, FreeLinkScene, LegScene, LEG_JOINTS};

/// Convert a core error to the matching `granrs.errors` exception.
fn to_pyerr(py: Python<'_>, err: GranrsError) -> PyErr {
    let (class, field) = match &err {
        GranrsError::InvalidParameter { field, .. } => {
            ("InvalidParameterError", Some(field.clone()))
        }
        GranrsError::WrongType { field, .. } => ("InvalidParameterError", Some(field.clone())),
        GranrsError::UnknownName { field, .. } => ("UnknownNameError", Some(field.clone())),
        GranrsError::InvalidScene { field, .. } => ("InvalidSceneError", Some(field.clone())),
        GranrsError::NonFinite { .. } => ("SimulationError", None),
    };
    let message = err.to_string();
    let make = || -> PyResult<PyErr> {
        let module = py.import("granrs.errors")?;
        let cls = module.getattr(class)?;
        let instance = match field {
            Some(f) => cls.call1((message.clone(), f))?,
            None => cls.call1((message.clone(),))?,
        };
        Ok(PyErr::from_value(instance))
    };
    make().unwrap_or_else(|_| PyRuntimeError::new_err(message.clone()))
}

fn bad_type(field: &str, what: &str) -> GranrsError {
    GranrsError::InvalidScene {
        field: field.to_string(),
        message: format!("expected {what}"),
    }
}

/// A required float field of the scene dict.
fn get_f64(d: &Bound<'_, PyDict>, field: &str) -> Result<f64, GranrsError> {
    let v = d
        .get_item(field)
        .map_err(|_| bad_type(field, "a number"))?
        .ok_or_else(|| GranrsError::InvalidScene {
            field: field.to_string(),
            message: "missing".into(),
        })?;
    let wrong = |got: String| GranrsError::WrongType {
        field: field.to_string(),
        expected: "a real number".into(),
        got,
    };
    if v.is_instance_of::<pyo3::types::PyBool>() {
        return Err(wrong("a bool".into()));
    }
    v.extract::<f64>()
        .map_err(|_| wrong(v.get_type().to_string()))
}

/// An optional float field (absent or None gives `None`).
fn get_opt_f64(d: &Bound<'_, PyDict>, field: &str) -> Result<Option<f64>, GranrsError> {
    match d.get_item(field).map_err(|_| bad_type(field, "a number"))? {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(_) => get_f64(d, field).map(Some),
    }
}

/// A required string field.
fn get_str(d: &Bound<'_, PyDict>, field: &str) -> Result<String, GranrsError> {
    d.get_item(field)
        .map_err(|_| bad_type(field, "a string"))?
        .ok_or_else(|| GranrsError::InvalidScene {
            field: field.to_string(),
            message: "missing".into(),
        })?
        .extract::<String>()
        .map_err(|_| bad_type(field, "a string"))
}

/// A list of strings (absent gives `None`).
fn get_names(d: &Bound<'_, PyDict>, field: &str) -> Result<Option<Vec<String>>, GranrsError> {
    match d
        .get_item(field)
        .map_err(|_| bad_type(field, "a list of names"))?
    {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => v
            .extract::<Vec<String>>()
            .map(Some)
            .map_err(|_| bad_type(field, "a list of names")),
    }
}

fn unknown(field: &str, value: &str, allowed: &[&str]) -> GranrsError {
    GranrsError::UnknownName {
        field: field.to_string(),
        value: value.to_string(),
        allowed: allowed.join(", "),
    }
}

/// Names of the effects a scene may list.
pub const EFFECTS: [&str; 4] = ["gravity", "drag", "static_h", "static_v"];
/// Names of the series a scene may record.
pub const RECORDS: [&str; 3] = ["state", "forces", "energy"];

fn parse_effects(names: Option<Vec<String>>) -> Result<Effects, GranrsError> {
    let Some(names) = names else {
        return Ok(Effects::default());
    };
    let mut e = Effects {
        gravity: false,
        drag: false,
        static_h: false,
        static_v: false,
    };
    for n in &names {
        match n.as_str() {
            "gravity" => e.gravity = true,
            "drag" => e.drag = true,
            "static_h" => e.static_h = true,
            "static_v" => e.static_v = true,
            other => return Err(unknown("effects", other, &EFFECTS)),
        }
    }
    Ok(e)
}

fn parse_record(names: Option<Vec<String>>, stride: Option<f64>) -> Result<Record, GranrsError> {
    let mut r = Record::default();
    for n in names.unwrap_or_default() {
        match n.as_str() {
            "state" => r.state = true,
            "forces" => r.forces = true,
            "energy" => r.energy = true,
            other => return Err(unknown("record", other, &RECORDS)),
        }
    }
    let stride = stride.unwrap_or(1.0);
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

/// An error about key `k` of the mapping `field`, renamed to the field `field.k`.
fn within(e: GranrsError, field: &str, k: &str) -> GranrsError {
    match e {
        GranrsError::InvalidScene { message, .. } => GranrsError::InvalidScene {
            field: format!("{field}.{k}"),
            message,
        },
        GranrsError::WrongType { expected, got, .. } => GranrsError::WrongType {
            field: format!("{field}.{k}"),
            expected,
            got,
        },
        other => other,
    }
}

/// A coefficients mapping (`eta_h`, `eta_d`, `eta_v`, `lam`) under `field`; absent or None
/// gives `None`.
fn get_coefficients(
    d: &Bound<'_, PyDict>,
    field: &str,
) -> Result<Option<Coefficients>, GranrsError> {
    let Some(c) = d
        .get_item(field)
        .map_err(|_| bad_type(field, "a mapping"))?
    else {
        return Ok(None);
    };
    if c.is_none() {
        return Ok(None);
    }
    let c = c
        .cast_into::<PyDict>()
        .map_err(|_| bad_type(field, "a mapping with eta_h, eta_d, eta_v, lam"))?;
    let get = |k: &str| get_f64(&c, k).map_err(|e| within(e, field, k));
    Ok(Some(Coefficients {
        eta_h: get("eta_h")?,
        eta_d: get("eta_d")?,
        eta_v: get("eta_v")?,
        lambda: get("lam")?,
    }))
}

/// A required coefficients mapping.
fn get_required_coefficients(
    d: &Bound<'_, PyDict>,
    field: &str,
) -> Result<Coefficients, GranrsError> {
    get_coefficients(d, field)?.ok_or_else(|| GranrsError::InvalidScene {
        field: field.into(),
        message: "missing".into(),
    })
}

/// A joint: `"free"`, `"locked"`, or a spring-damper `{"k": .., "c": ..}` (absent: free).
fn get_joint(d: &Bound<'_, PyDict>, field: &str) -> Result<Joint, GranrsError> {
    let Some(v) = d.get_item(field).map_err(|_| bad_type(field, "a joint"))? else {
        return Ok(Joint::Free);
    };
    if v.is_none() {
        return Ok(Joint::Free);
    }
    if let Ok(name) = v.extract::<String>() {
        return match name.as_str() {
            "free" => Ok(Joint::Free),
            "locked" => Ok(Joint::Locked),
            other => Err(unknown(
                field,
                other,
                &["free", "locked", "{k, c} spring-damper"],
            )),
        };
    }
    let spec = v.cast_into::<PyDict>().map_err(|_| {
        bad_type(
            field,
            "\"free\", \"locked\" or a spring-damper mapping {\"k\": N m/rad, \"c\": N m s/rad}",
        )
    })?;
    for key in spec.keys() {
        let key: String = key.extract().unwrap_or_default();
        if key != "k" && key != "c" {
            return Err(unknown(&format!("{field}.{key}"), &key, &["k", "c"]));
        }
    }
    let get = |k: &str| get_f64(&spec, k).map_err(|e| within(e, field, k));
    Ok(Joint::Spring {
        k: get("k")?,
        c: get("c")?,
        rest: 0.0,
    })
}

/// The fields every body shares.
struct Common {
    medium: Medium,
    apply_at: ApplyAt,
    sign_model: SignModel,
    effects: Effects,
    options: SolveOptions,
    v0: f64,
    depth0: f64,
    vx0: f64,
}

fn common_from_dict(d: &Bound<'_, PyDict>) -> Result<Common, GranrsError> {
    let apply_at = match get_str(d, "apply_at")?.as_str() {
        "tip" => ApplyAt::Tip,
        "centroid" => ApplyAt::Centroid,
        other => return Err(unknown("apply_at", other, &["tip", "centroid"])),
    };
    let sign_model = match get_str(d, "sign_model")?.as_str() {
        "modes" => SignModel::Modes,
        "raw" => SignModel::Raw,
        "smooth" => SignModel::Smooth {
            eps: get_f64(d, "smooth_eps")?,
        },
        other => return Err(unknown("sign_model", other, &["modes", "raw", "smooth"])),
    };
    let end = match get_str(d, "end")?.as_str() {
        "first_stop" => EndCondition::FirstStop,
        "all_stops" => EndCondition::AllStops,
        "time" => EndCondition::Time,
        other => return Err(unknown("end", other, &["first_stop", "all_stops", "time"])),
    };
    Ok(Common {
        medium: Medium {
            rho_g: get_f64(d, "rho_g")?,
            g: get_f64(d, "g")?,
        },
        apply_at,
        sign_model,
        effects: parse_effects(get_names(d, "effects")?)?,
        options: SolveOptions {
            dt: get_f64(d, "dt")?,
            method: match get_str(d, "method")?.as_str() {
                "rk4" => Method::Rk4,
                "dopri5" => Method::Dopri5 {
                    rtol: get_f64(d, "rtol")?,
                    atol: get_f64(d, "atol")?,
                },
                other => return Err(unknown("method", other, &["rk4", "dopri5"])),
            },
            t_end: get_f64(d, "t_end")?,
            end,
            record: parse_record(get_names(d, "record")?, get_opt_f64(d, "record_stride")?)?,
        },
        v0: get_f64(d, "v0")?,
        depth0: get_opt_f64(d, "depth0")?.unwrap_or(0.0),
        vx0: get_opt_f64(d, "vx0")?.unwrap_or(0.0),
    })
}

/// Build a free-link scene from the dict of `granrs.Scene.to_dict()`.
fn free_link_from_dict(d: &Bound<'_, PyDict>) -> Result<FreeLinkScene, GranrsError> {
    let c = common_from_dict(d)?;
    Ok(FreeLinkScene {
        length: get_f64(d, "length")?,
        diameter: get_f64(d, "diameter")?,
        mass: get_f64(d, "mass")?,
        inertia: get_opt_f64(d, "inertia")?,
        medium: c.medium,
        coefficients: get_required_coefficients(d, "coefficients")?,
        q_deg: get_f64(d, "q_deg")?,
        v0: c.v0,
        depth0: c.depth0,
        vx0: c.vx0,
        omega0: get_opt_f64(d, "omega0")?.unwrap_or(0.0),
        apply_at: c.apply_at,
        sign_model: c.sign_model,
        effects: c.effects,
        options: c.options,
    })
}

/// Build a chain scene: link 2's angle defaults to the mirror of link 1's, its
/// coefficients to link 1's.
fn chain_from_dict(d: &Bound<'_, PyDict>) -> Result<ChainScene, GranrsError> {
    let c = common_from_dict(d)?;
    let coefficients = get_required_coefficients(d, "coefficients")?;
    let q1 = get_f64(d, "q_deg")?;
    Ok(ChainScene {
        length: get_f64(d, "length")?,
        diameter: get_f64(d, "diameter")?,
        mass: get_f64(d, "mass")?,
        inertia: get_opt_f64(d, "inertia")?,
        pin_mass: get_opt_f64(d, "pin_mass")?.unwrap_or(0.0),
        joint: get_joint(d, "pin_joint")?,
        medium: c.medium,
        coefficients: [
            coefficients,
            get_coefficients(d, "coefficients2")?.unwrap_or(coefficients),
        ],
        q_deg: [q1, get_opt_f64(d, "q2_deg")?.unwrap_or(-q1)],
        v0: c.v0,
        depth0: c.depth0,
        vx0: c.vx0,
        omega0: get_opt_f64(d, "omega0")?.unwrap_or(0.0),
        apply_at: c.apply_at,
        sign_model: c.sign_model,
        effects: c.effects,
        options: c.options,
    })
}

/// Build a leg scene.
fn leg_from_dict(d: &Bound<'_, PyDict>) -> Result<LegScene, GranrsError> {
    let c = common_from_dict(d)?;
    let defaults = LegScene::default();
    let or = |field: &str, default: f64| -> Result<f64, GranrsError> {
        Ok(get_opt_f64(d, field)?.unwrap_or(default))
    };
    let sole_model = match d
        .get_item("sole_model")
        .map_err(|_| bad_type("sole_model", "a string"))?
    {
        Some(v) if !v.is_none() => match get_str(d, "sole_model")?.as_str() {
            "box" => SoleModel::Box,
            "thesis" => SoleModel::Thesis,
            other => return Err(unknown("sole_model", other, &["box", "thesis"])),
        },
        _ => SoleModel::Box,
    };
    let mut joints = [Joint::Locked; 3];
    for (j, name) in joints.iter_mut().zip(LEG_JOINTS) {
        if d.get_item(name)
            .ok()
            .flatten()
            .is_some_and(|v| !v.is_none())
        {
            *j = get_joint(d, name)?;
        }
    }
    Ok(LegScene {
        body_mass: or("body_mass", defaults.body_mass)?,
        height: or("height", defaults.height)?,
        foot_length: or("foot_length", defaults.foot_length)?,
        shoe_width: or("shoe_width", defaults.shoe_width)?,
        tibia_length: or("tibia_length", defaults.tibia_length)?,
        sole_height: get_opt_f64(d, "sole_height")?,
        joints,
        knee_deg: or("knee_deg", defaults.knee_deg)?,
        hip_deg: or("hip_deg", defaults.hip_deg)?,
        trunk_deg: or("trunk_deg", defaults.trunk_deg)?,
        foot_deg: or("foot_deg", defaults.foot_deg)?,
        sole_model,
        medium: c.medium,
        coefficients: get_required_coefficients(d, "coefficients")?,
        v0: c.v0,
        depth0: c.depth0,
        vx0: c.vx0,
        apply_at: c.apply_at,
        sign_model: c.sign_model,
        effects: c.effects,
        options: c.options,
    })
}

/// Convert a scene dict to an owned, validated scene (GIL held).
fn scene_from_dict(d: &Bound<'_, PyDict>) -> Result<AnyScene, GranrsError> {
    let scene = match get_str(d, "body")?.as_str() {
        "free_link" => AnyScene::FreeLink(free_link_from_dict(d)?),
        "chain" => AnyScene::Chain(chain_from_dict(d)?),
        "leg" => AnyScene::Leg(leg_from_dict(d)?),
        other => return Err(unknown("body", other, &["free_link", "chain", "leg"])),
    };
    scene.validate()?;
    Ok(scene)
}

/// Convert an outcome to a dict of Python values; series move into numpy without copying.
fn outcome_to_dict<'py>(py: Python<'py>, out: Outcome) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("status", out.status.name())?;
    d.set_item("t_final", out.t_final)?;
    let stats = PyDict::new(py);
    stats.set_item("steps", out.stats.steps)?;
    stats.set_item("rhs_evals", out.stats.rhs_evals)?;
    stats.set_item("root_evals", out.stats.root_evals)?;
    stats.set_item("events", out.stats.events)?;
    stats.set_item("rejected", out.stats.rejected)?;
    d.set_item("stats", stats)?;
    d.set_item("energy_start", out.energy_start)?;
    d.set_item("energy_end", out.energy_end)?;
    d.set_item("work_sand", out.work_sand)?;
    let contacts = PyList::empty(py);
    for c in &out.contacts {
        let cd = PyDict::new(py);
        cd.set_item("stopped", c.stopped)?;
        cd.set_item("t_s", c.t_s)?;
        cd.set_item("depth", c.depth)?;
        cd.set_item("dq", c.dq)?;
        cd.set_item("omega_end", c.omega_end)?;
        cd.set_item("F_d_max", c.f_d_max)?;
        cd.set_item("F_s_end", c.f_s_end)?;
        cd.set_item("F_r_end", c.f_r_end)?;
        cd.set_item("dKE", c.d_ke)?;
        cd.set_item("dPE", c.d_pe)?;
        cd.set_item("dE", c.d_e)?;
        cd.set_item("work_sand", c.work_sand)?;
        cd.set_item("x_tip_end", c.tip_end.x)?;
        cd.set_item("t_entry", c.t_entry)?;
        cd.set_item("link_dKE", c.link_d_ke)?;
        cd.set_item("link_dPE", c.link_d_pe)?;
        cd.set_item("link_dE", c.link_d_ke + c.link_d_pe)?;
        contacts.append(cd)?;
    }
    d.set_item("contacts", contacts)?;
    d.set_item("dissipated", out.dissipated)?;
    let joints = PyList::empty(py);
    for j in &out.joints {
        let jd = PyDict::new(py);
        jd.set_item("F_max", j.f_max)?;
        jd.set_item("torque_max", j.torque_max)?;
        joints.append(jd)?;
    }
    d.set_item("joints", joints)?;
    match out.series {
        None => d.set_item("series", py.None())?,
        Some(series) => {
            let s = PyDict::new(py);
            s.set_item("t", series.t.into_pyarray(py))?;
            for (name, col) in series.columns {
                s.set_item(name, col.into_pyarray(py))?;
            }
            d.set_item("series", s)?;
        }
    }
    Ok(d)
}

/// Run one scene (a dict from `granrs.Scene.to_dict()`) and return its results as a dict.
#[pyfunction]
fn simulate<'py>(py: Python<'py>, scene: &Bound<'py, PyDict>) -> PyResult<Bound<'py, PyDict>> {
    let scene = scene_from_dict(scene).map_err(|e| to_pyerr(py, e))?;
    let out = py.detach(|| scene.run()).map_err(|e| to_pyerr(py, e))?;
    outcome_to_dict(py, out)
}

/// Validate a scene dict without running it (raises the typed error, or returns None).
#[pyfunction]
fn validate(py: Python<'_>, scene: &Bound<'_, PyDict>) -> PyResult<()> {
    scene_from_dict(scene)
        .map(|_| ())
        .map_err(|e| to_pyerr(py, e))
}

/// The leg's segments for a scene dict (body "leg"): a list of dicts with name, mass [kg],
/// length [m], com (from the lower joint) [m] and inertia about the centre of mass [kg m^2].
#[pyfunction]
fn leg_segments<'py>(py: Python<'py>, scene: &Bound<'py, PyDict>) -> PyResult<Bound<'py, PyList>> {
    let leg = leg_from_dict(scene).map_err(|e| to_pyerr(py, e))?;
    leg.validate().map_err(|e| to_pyerr(py, e))?;
    let out = PyList::empty(py);
    for (name, s) in ["foot", "shank", "thigh", "half_trunk"]
        .iter()
        .zip(leg.segments())
    {
        let d = PyDict::new(py);
        d.set_item("name", name)?;
        d.set_item("mass", s.mass)?;
        d.set_item("length", s.length)?;
        d.set_item("com", s.com)?;
        d.set_item("inertia", s.inertia)?;
        out.append(d)?;
    }
    Ok(out)
}

#[pymodule]
fn _granrs(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add("EFFECTS", EFFECTS.to_vec())?;
    m.add("RECORDS", RECORDS.to_vec())?;
    m.add_function(wrap_pyfunction!(leg_segments, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
