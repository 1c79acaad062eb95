//! Python values to the core's plain data: a scene dict, or a `granrs.Scene`'s own
//! attributes, to a [`SceneSpec`] of spec [`Value`]s (no checks beyond the type; the spec's
//! rules check the rest, with the GIL held).

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use super::terms;
use crate::bodies::AnyScene;
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
    if let Ok(t) = v.cast::<PyTuple>() {
        if let Some(first) = t.iter().next() {
            if first.cast::<PyString>().is_err() {
                if let Some(terms) = terms::terms_from_py(t.iter()) {
                    return terms;
                }
            }
        }
        return names_from_py(t.iter());
    }
    if let Ok(l) = v.cast::<PyList>() {
        if let Some(first) = l.iter().next() {
            if first.cast::<PyString>().is_err() {
                if let Some(terms) = terms::terms_from_py(l.iter()) {
                    return terms;
                }
            }
        }
        return names_from_py(l.iter());
    }
    let type_name = v
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default();
    if type_name == "bool_" {
        return Value::Bool(v.is_truthy().unwrap_or(false));
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
pub(super) fn scene_from_dict(d: &Bound<'_, PyDict>) -> Result<AnyScene, GranrsError> {
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
        let d = PyDict::new(py);
        d.set_item("name", f.name)?;
        d.set_item("part", f.part)?;
        d.set_item("bodies", f.bodies.to_vec())?;
        d.set_item("unit", f.unit)?;
        d.set_item("note", f.note)?;
        d.set_item("doc", f.doc)?;
        out.append(d)?;
    }
    Ok(out)
}
