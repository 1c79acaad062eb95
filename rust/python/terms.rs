//! The force terms' registry for Python (`granrs.forces`): each term's description, a check
//! of one term's parameters, and `granrs.forces.Term` objects as specs of the core.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};

use crate::forces::{Acts, Class, TermSpec, TERMS};
use crate::spec::Value;

use super::errors::to_pyerr;

/// Every registered term's description, in the registry's order: name, summary, equation,
/// source, acts (`"contact"` or `"body"`), class, velocity_dependent, reads, shapes (the
/// contact shapes it is defined on: `"rod"`, `"box"`, `"arc"`), switches,
/// columns and params (each: name, unit, default, source, min, max, description, integer,
/// required).
#[pyfunction]
pub fn term_infos(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for t in TERMS {
        let d = PyDict::new(py);
        d.set_item("name", t.name)?;
        d.set_item("summary", t.summary)?;
        d.set_item("equation", t.equation)?;
        d.set_item("source", t.source)?;
        d.set_item(
            "acts",
            match t.acts {
                Acts::Contact => "contact",
                Acts::Body => "body",
            },
        )?;
        d.set_item(
            "class",
            match t.class {
                Class::Dynamic => "dynamic",
                Class::Static => "static",
            },
        )?;
        d.set_item("velocity_dependent", t.velocity_dependent)?;
        d.set_item("reads", t.reads)?;
        let shapes: Vec<&str> = t.shapes.iter().map(|s| s.name()).collect();
        d.set_item("shapes", shapes)?;
        let switches: Vec<&str> = t.switches.iter().map(|s| s.name()).collect();
        d.set_item("switches", switches)?;
        let columns: Vec<&str> = t.columns.iter().map(|(c, _)| *c).collect();
        d.set_item("columns", columns)?;
        let params = PyList::empty(py);
        for p in t.params {
            let pd = PyDict::new(py);
            pd.set_item("name", p.name)?;
            pd.set_item("unit", p.unit)?;
            pd.set_item("default", p.default)?;
            pd.set_item("source", p.source)?;
            pd.set_item("min", p.min)?;
            pd.set_item("max", p.max)?;
            pd.set_item("description", p.description)?;
            pd.set_item("integer", p.integer)?;
            pd.set_item("required", p.required())?;
            params.append(pd)?;
        }
        d.set_item("params", params)?;
        out.append(d)?;
    }
    Ok(out)
}

/// A pair of float arrays, returned to Python as a tuple.
type ArrayPair<'py> = (
    Bound<'py, numpy::PyArray1<f64>>,
    Bound<'py, numpy::PyArray1<f64>>,
);

/// The RFT coefficients (alpha_x, alpha_z) at the angles `beta` and `gamma` [rad] (equal
/// lengths), with the nine Fourier coefficients `coefficients` (order of
/// `forces::rft::GENERIC`): `granrs.forces.rft_alpha`.
#[pyfunction]
pub fn rft_alpha<'py>(
    py: Python<'py>,
    beta: numpy::PyReadonlyArray1<'py, f64>,
    gamma: numpy::PyReadonlyArray1<'py, f64>,
    coefficients: [f64; 9],
) -> PyResult<ArrayPair<'py>> {
    use numpy::IntoPyArray;
    let (b, g) = (beta.as_array(), gamma.as_array());
    if b.len() != g.len() {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "rft_alpha: beta and gamma must have the same length",
        ));
    }
    let (ax, az): (Vec<f64>, Vec<f64>) = b
        .iter()
        .zip(g.iter())
        .map(|(&b, &g)| crate::forces::rft::alpha_at(&coefficients, b, g))
        .unzip();
    Ok((ax.into_pyarray(py), az.into_pyarray(py)))
}

/// A term's parameters from a Python mapping: each a number or a sequence of numbers (one
/// per contact). A value that is neither is NaN here, which the check then names.
fn params_from_py<'py>(
    params: impl Iterator<Item = (Bound<'py, PyAny>, Bound<'py, PyAny>)>,
) -> Vec<(String, Vec<f64>)> {
    let one = |v: &Bound<'_, PyAny>| -> f64 {
        if v.is_instance_of::<pyo3::types::PyBool>() || is_numpy_bool(v) {
            return f64::NAN;
        }
        v.extract::<f64>().unwrap_or(f64::NAN)
    };
    params
        .map(|(k, v)| {
            let name = k.str().map(|s| s.to_string()).unwrap_or_default();
            let values = if let Ok(t) = v.cast::<PyTuple>() {
                t.iter().map(|x| one(&x)).collect()
            } else if let Ok(l) = v.cast::<PyList>() {
                l.iter().map(|x| one(&x)).collect()
            } else {
                vec![one(&v)]
            };
            (name, values)
        })
        .collect()
}

/// Check the term `name` with `params` (before any scene): the name, each parameter's name
/// and every value. Returns every parameter, defaults filled in, each a float or (given per
/// contact) a tuple. Errors name the term and parameter (`static_v.eta_v`).
#[pyfunction]
pub fn check_term<'py>(
    py: Python<'py>,
    name: &str,
    params: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let spec = TermSpec {
        name: name.to_string(),
        params: params_from_py(params.iter()),
    };
    let n = spec
        .params
        .iter()
        .map(|(_, v)| v.len())
        .max()
        .unwrap_or(1)
        .max(1);
    let per_contact_given = |k: &str| spec.params.iter().any(|(p, v)| p == k && v.len() != 1);
    // Lists of different lengths are checked against a scene's contacts later; here each
    // is checked against its own length.
    let mut checked = spec.clone();
    for (_, v) in checked.params.iter_mut() {
        if v.len() != 1 && v.len() != n {
            v.truncate(1);
        }
    }
    let (info, values) = checked.resolve(n).map_err(|e| to_pyerr(py, e))?;
    let out = PyDict::new(py);
    for (pi, p) in info.params.iter().enumerate() {
        if per_contact_given(p.name) {
            let given = &spec
                .params
                .iter()
                .rev()
                .find(|(k, _)| k == p.name)
                .unwrap()
                .1;
            out.set_item(p.name, PyTuple::new(py, given)?)?;
        } else {
            out.set_item(p.name, values[0][pi])?;
        }
    }
    Ok(out)
}

/// Whether `v` is numpy's boolean scalar (`np.True_`: `numpy.bool`, `numpy.bool_` before
/// numpy 2), which converts to a float as 1.0 but is refused wherever a bool is: a truth
/// value is never a number here.
pub(super) fn is_numpy_bool(v: &Bound<'_, PyAny>) -> bool {
    let ty = v.get_type();
    matches!(ty.name(), Ok(n) if n == "bool_" || n == "bool")
        && matches!(ty.module(), Ok(m) if m == "numpy")
}

/// `Scene.forces` (a sequence of `granrs.forces.Term`, each with `name` and `params`) as a
/// spec value; `None` where the items are not terms.
pub fn terms_from_py<'py>(
    items: impl ExactSizeIterator<Item = Bound<'py, PyAny>>,
) -> Option<Value> {
    let mut specs = Vec::with_capacity(items.len());
    for item in items {
        if item.cast::<PyString>().is_ok() {
            return None;
        }
        if let Ok(d) = item.cast::<PyDict>() {
            // A term as plain values (`Term.to_dict()`, a TOML table): "term" and its params.
            let name = d.get_item("term").ok()??;
            let name = name.cast::<PyString>().ok()?.to_str().ok()?.to_string();
            let pairs = d.iter().filter(|(k, _)| k.to_string() != "term");
            specs.push(TermSpec {
                name,
                params: params_from_py(pairs),
            });
            continue;
        }
        let py = item.py();
        let name = item.getattr(pyo3::intern!(py, "name")).ok()?;
        let name = name.cast::<PyString>().ok()?.to_str().ok()?.to_string();
        // Any mapping (a Term's params are read-only): its items as (key, value) pairs.
        let items = item
            .getattr(pyo3::intern!(py, "params"))
            .ok()?
            .call_method0(pyo3::intern!(py, "items"))
            .ok()?;
        let pairs: Vec<(Bound<'py, PyAny>, Bound<'py, PyAny>)> = items
            .try_iter()
            .ok()?
            .map(|kv| kv.ok()?.extract().ok())
            .collect::<Option<_>>()?;
        specs.push(TermSpec {
            name,
            params: params_from_py(pairs.into_iter()),
        });
    }
    Some(Value::Terms(specs))
}
