//! Python values to the core's plain data: a scene dict, or a `granrs.Scene`'s own
//! attributes, to a [`SceneSpec`] of spec [`Value`]s (no checks beyond the type; the spec's
//! rules check the rest, with the GIL held).

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use super::terms;
use crate::bodies::LinkageScene;
use crate::error::GranrsError;
use crate::spec::{word, SceneSpec, Value};

/// Convert a Python value to a spec value (no checks beyond the type). The common types
/// (float, str, None) are tried first: this runs for every field of every scene.
pub(super) fn value_from_py(v: &Bound<'_, PyAny>) -> Value {
    if let Ok(f) = v.cast_exact::<PyFloat>() {
        return Value::Num(f.value());
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Value::Str(s.to_str().map(word).unwrap_or_default());
    }
    if v.is_none() {
        return Value::None;
    }
    if v.is_exact_instance_of::<PyInt>() {
        // As below for any other number; an int too large for a float is refused by type.
        return match v.extract::<f64>() {
            Ok(x) => Value::Num(x),
            Err(_) => Value::Other("int".into()),
        };
    }
    if v.is_instance_of::<PyBool>() {
        return Value::Bool(v.is_truthy().unwrap_or(false));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        return Value::Map(
            d.iter()
                .map(|(k, v)| {
                    (
                        k.str().map(|s| word(&s.to_string())).unwrap_or_default(),
                        value_from_py(&v),
                    )
                })
                .collect(),
        );
    }
    let items: Option<Vec<Bound<'_, PyAny>>> = match (v.cast::<PyTuple>(), v.cast::<PyList>()) {
        (Ok(t), _) => Some(t.iter().collect()),
        (_, Ok(l)) => Some(l.iter().collect()),
        _ => None,
    };
    if let Some(items) = items {
        // Names (`record`), force terms, or a list of values (a drive's table).
        if items.first().is_some_and(|x| x.cast::<PyString>().is_err()) {
            if let Some(terms) = terms::terms_from_py(items.iter().cloned()) {
                return terms;
            }
            return Value::List(items.iter().map(value_from_py).collect());
        }
        return names_from_py(items.into_iter());
    }
    if terms::is_numpy_bool(v) {
        return Value::Bool(v.is_truthy().unwrap_or(false));
    }
    let type_name = v
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default();
    // A `granrs.bodies.Linkage`: its plain form (a built-in body's name, or a mapping).
    if let Ok(inner) = v.getattr(pyo3::intern!(v.py(), "_core_value")) {
        return value_from_py(&inner);
    }
    match v.extract::<f64>() {
        Ok(x) => Value::Num(x),
        Err(_) => Value::Other(type_name),
    }
}

/// A list or tuple of names (`effects`, `record`) as a spec value.
fn names_from_py<'py>(items: impl ExactSizeIterator<Item = Bound<'py, PyAny>>) -> Value {
    let mut names = Vec::with_capacity(items.len());
    for item in items {
        match item.cast::<PyString>().ok().and_then(|s| s.to_str().ok()) {
            Some(s) => names.push(word(s)),
            None => return Value::Other("a list that is not all strings".into()),
        }
    }
    Value::Names(names)
}

/// A scene dict (from `granrs.Scene.to_dict()`) as a spec.
pub(super) fn spec_from_dict(d: &Bound<'_, PyDict>) -> SceneSpec {
    let mut pairs = Vec::with_capacity(d.len());
    for (k, v) in d.iter() {
        if let Ok(k) = k.cast::<PyString>() {
            if let Ok(k) = k.to_str() {
                pairs.push((k.to_owned(), value_from_py(&v)));
            }
        }
    }
    SceneSpec::from_pairs(pairs)
}

/// Convert a scene dict to an owned, validated scene (GIL held).
pub(super) fn scene_from_dict(d: &Bound<'_, PyDict>) -> Result<LinkageScene, GranrsError> {
    spec_from_dict(d).build()
}

/// The spec of a `granrs.Scene` read straight from its attributes: `fields` is the
/// instance's `__dict__`, `names` the fields its body uses (`scene._CORE_FIELDS`). The same
/// values as the dict `Scene._plain()` builds, without building it. Each names tuple's slots
/// are found once per thread (the tuples are module constants; see `SLOTS`).
pub(super) fn spec_from_fields(
    fields: &Bound<'_, PyDict>,
    names: &Bound<'_, PyTuple>,
) -> SceneSpec {
    SLOTS.with_borrow_mut(|cache| {
        let i = match cache.iter().position(|(t, _)| t.as_ptr() == names.as_ptr()) {
            Some(i) => i,
            None => {
                if cache.len() >= 8 {
                    cache.clear();
                }
                let slots = names
                    .iter()
                    .map(|n| {
                        let name = n.cast::<PyString>().ok()?;
                        SceneSpec::slot_of(name.to_str().ok()?)
                    })
                    .collect();
                cache.push((names.clone().unbind(), slots));
                cache.len() - 1
            }
        };
        let slots = &cache[i].1;
        let mut spec = SceneSpec::new();
        for (k, slot) in slots.iter().enumerate() {
            let Ok(name) = names.get_borrowed_item(k) else {
                continue;
            };
            let Ok(key) = name.cast::<PyString>() else {
                continue;
            };
            let Ok(Some(v)) = fields.get_item(key) else {
                continue;
            };
            match *slot {
                Some(slot) => spec.set_slot(slot, value_from_py(&v)),
                None => {
                    if let Ok(key_str) = key.to_str() {
                        spec.set(key_str, value_from_py(&v));
                    }
                }
            }
        }
        spec
    })
}

/// A names tuple (kept alive, so that its address names it) and the spec slot of each name.
type NamesSlots = (Py<PyTuple>, Vec<Option<usize>>);

thread_local! {
    /// Names tuples seen (a Scene's field names per body are a module constant) and the
    /// spec slot of each name, so that a scene's fields are read without matching names.
    static SLOTS: std::cell::RefCell<Vec<NamesSlots>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The table of a scene's fields ([`crate::spec::FIELDS`]): name, part, bodies, unit, note
/// and doc of each, for `granrs.scene`, the TOML notes and the docs.
#[pyfunction]
pub fn scene_fields(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for f in crate::spec::FIELDS.iter() {
        out.append(py_dict!(py, {
            "name": f.name, "part": f.part, "bodies": crate::presets::bodies_of(f.name), "unit": f.unit,
            "note": f.note, "doc": f.doc,
        }))?;
    }
    Ok(out)
}

/// The table of a linkage's element fields ([`crate::spec::ELEMENT_FIELDS`]): element,
/// name, unit, note and doc of each, for `granrs.bodies`, the TOML notes and the docs.
#[pyfunction]
pub fn element_fields(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for f in crate::spec::ELEMENT_FIELDS.iter() {
        out.append(py_dict!(py, {
            "element": f.element, "name": f.name, "unit": f.unit, "note": f.note, "doc": f.doc,
        }))?;
    }
    Ok(out)
}

/// A built-in body of a scene dict as a linkage's plain parts (`links`, `joints`,
/// `contacts`, `root`, with angles in degrees), or a linkage's own: what
/// `granrs.bodies.Linkage` holds; and `order`, the links' names in the engine's order (a
/// parent before its children: the order of the state's angles and of the results' links).
/// Only the body is read; `check` validates its structure and elements (not the rest of the
/// scene).
#[pyfunction]
#[pyo3(signature = (scene, check=false))]
pub fn body_linkage<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyDict>,
    check: bool,
) -> PyResult<Bound<'py, PyDict>> {
    use crate::bodies::{ContactShape, RootKind};
    let err = |e| super::errors::to_pyerr(py, e);
    let l = spec_from_dict(scene).body_scene().map_err(err)?;
    if check {
        l.validate_body().map_err(err)?;
    }
    let pair = |v: nalgebra::Vector2<f64>| (v.x, v.y);
    let links = PyList::empty(py);
    for k in &l.links {
        links.append(py_dict!(py, {
            "name": &k.name, "mass": k.mass, "inertia": k.inertia, "length": k.length,
            "com": pair(k.com), "q_deg": k.q.to_degrees(), "omega0": k.omega,
        }))?;
    }
    let joints = PyList::empty(py);
    for j in &l.joints {
        let d = py_dict!(py, {
            "name": &j.name, "parent": &j.parent, "child": &j.child, "at": pair(j.at),
        });
        let (kind, fields) = j.fields();
        d.set_item("kind", kind)?;
        for (k, value) in fields {
            // A driven joint's sinusoid is written only when it has one.
            let sinusoid = matches!(k, "amplitude_deg" | "frequency" | "phase_deg");
            if !sinusoid || j.joint.reads_clock() {
                d.set_item(k, value)?;
            }
        }
        if let Some(t) = &j.table {
            let rows: Vec<(f64, f64)> = t
                .times
                .iter()
                .zip(&t.angles)
                .map(|(&t, &a)| (t, a.to_degrees()))
                .collect();
            d.set_item("table", rows)?;
        }
        joints.append(d)?;
    }
    let contacts = PyList::empty(py);
    for c in &l.contacts {
        if let ContactShape::Box {
            thesis_angle_of: Some(_),
            ..
        } = c.shape
        {
            return Err(err(crate::error::GranrsError::InvalidScene {
                field: "sole_model".into(),
                message: "the thesis form of the sole (eqs. 5.5-5.7) reads the shank's \
                          angle; a linkage's box contact is the geometric box (sole_model \
                          = \"box\")"
                    .into(),
            }));
        }
        let (shape, fields) = c.shape.fields();
        let d = py_dict!(py, { "shape": shape, "at": pair(c.shape.at()) });
        for (k, value) in fields {
            if k == "chords" {
                d.set_item(k, value as usize)?;
            } else {
                d.set_item(k, value)?;
            }
        }
        d.set_item("name", &c.name)?;
        d.set_item("link", &c.link)?;
        contacts.append(d)?;
    }
    let kind = match l.root.kind {
        RootKind::Free => "free",
        RootKind::Pinned => "pinned",
        RootKind::Moving => "moving",
    };
    let root = py_dict!(py, {
        "kind": kind, "link": &l.root.link, "position": pair(l.root.position),
    });
    root.set_item("velocity", pair(l.root.velocity))?;
    root.set_item("mass", l.root.mass)?;
    if let Some(rate) = l.root.rate {
        root.set_item("rate", rate)?;
    }
    let out = PyDict::new(py);
    let order: Vec<&str> = l
        .order()
        .iter()
        .map(|&i| l.links[i].name.as_str())
        .collect();
    out.set_item("order", order)?;
    out.set_item("links", links)?;
    out.set_item("joints", joints)?;
    out.set_item("contacts", contacts)?;
    out.set_item("root", root)?;
    Ok(out)
}
