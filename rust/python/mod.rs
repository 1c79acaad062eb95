//! The Python module `granrs._granrs`: the only place that says `use pyo3`.
//!
//! Scenes arrive as plain dicts built by `granrs.Scene.to_dict()`, are converted to owned
//! Rust values and validated while the GIL is held, and run with the GIL released. Every
//! [`GranrsError`] becomes an instance of the matching class of `granrs.errors`, so that the
//! Python and Rust layers share one exception tree.

mod terms;

use std::borrow::Cow;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::batch::{self, Source};
use crate::bodies::AnyScene;
use crate::error::GranrsError;
use crate::integrate::{FieldValue, Outcome, OUTCOME_FIELDS};
use crate::spec::{word, SceneSpec, Value, COEFFICIENTS_SLOTS, EFFECTS, RECORDS, SCENE_FIELDS};

/// Convert a core error to the matching `granrs.errors` exception.
pub(crate) fn to_pyerr(py: Python<'_>, err: GranrsError) -> PyErr {
    let (class, field) = match &err {
        GranrsError::InvalidParameter { field, .. } => {
            ("InvalidParameterError", Some(field.clone()))
        }
        GranrsError::WrongType { field, .. } => ("InvalidParameterError", Some(field.clone())),
        GranrsError::UnknownName { field, .. } => ("UnknownNameError", Some(field.clone())),
        GranrsError::UnknownParameter { field, .. } => ("UnknownNameError", Some(field.clone())),
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

/// Convert a Python value to a spec value (no checks beyond the type). The common types
/// (float, str, None) are tried first: this runs for every field of every scene.
fn value_from_py(v: &Bound<'_, PyAny>) -> Value {
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
fn spec_from_dict(d: &Bound<'_, PyDict>) -> SceneSpec {
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
fn scene_from_dict(d: &Bound<'_, PyDict>) -> Result<AnyScene, GranrsError> {
    spec_from_dict(d).build()
}

/// A field's value as a Python value: a float, an int, a bool, or a status's name.
fn field_to_py(py: Python<'_>, v: FieldValue) -> PyResult<Bound<'_, PyAny>> {
    Ok(match v {
        FieldValue::Real(x) => x.into_pyobject(py)?.into_any(),
        FieldValue::Count(n) => n.into_pyobject(py)?.into_any(),
        FieldValue::Flag(b) => b.into_pyobject(py)?.to_owned().into_any(),
        FieldValue::Status(s) => s.name().into_pyobject(py)?.into_any(),
    })
}

/// Convert an outcome to a dict of Python values, its summaries read from the one table of
/// output fields ([`OUTCOME_FIELDS`]); series move into numpy without copying.
fn outcome_to_dict<'py>(py: Python<'py>, out: Outcome) -> PyResult<Bound<'py, PyDict>> {
    let fields = &OUTCOME_FIELDS;
    let d = PyDict::new(py);
    d.set_item("status", out.status.name())?;
    d.set_item("t_final", out.t_final)?;
    // The work counters; and the run-level entries of Result.summary (the counters first),
    // merged there with contact 0's in one update.
    let stats = PyDict::new(py);
    for f in fields.run {
        if let v @ FieldValue::Count(_) = (f.read)(&out) {
            stats.set_item(f.name, field_to_py(py, v)?)?;
        }
    }
    let run = stats.copy()?;
    for f in fields.run {
        match (f.read)(&out) {
            FieldValue::Count(_) => {}
            v => run.set_item(f.name, field_to_py(py, v)?)?,
        }
    }
    d.set_item("run", run)?;
    d.set_item("stats", stats)?;
    d.set_item("energy_start", out.energy_start)?;
    d.set_item("energy_end", out.energy_end)?;
    d.set_item("work_sand", out.work_sand)?;
    d.set_item("terms", PyTuple::new(py, &out.terms)?)?;
    // Each contact's summary; whether it stopped goes in a list of its own.
    let contacts = PyList::empty(py);
    let stopped = PyList::empty(py);
    for c in &out.contacts {
        stopped.append(c.stopped)?;
        let cd = PyDict::new(py);
        for f in fields.contact.iter().filter(|f| f.name != "stopped") {
            cd.set_item(f.name, field_to_py(py, (f.read)(c))?)?;
        }
        contacts.append(cd)?;
    }
    d.set_item("contacts", contacts)?;
    d.set_item("stopped", stopped)?;
    d.set_item("dissipated", out.dissipated)?;
    let joints = PyList::empty(py);
    for j in &out.joints {
        let jd = PyDict::new(py);
        for f in fields.joint {
            jd.set_item(f.name, field_to_py(py, (f.read)(j))?)?;
        }
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

/// A scene converted and validated once (`compile`), to run many times without parsing.
#[pyclass(frozen, module = "granrs._granrs")]
struct Compiled {
    scene: AnyScene,
}

/// Convert and validate a scene dict once; `run` it as often as wanted.
#[pyfunction]
fn compile(py: Python<'_>, scene: &Bound<'_, PyDict>) -> PyResult<Compiled> {
    let scene = scene_from_dict(scene).map_err(|e| to_pyerr(py, e))?;
    Ok(Compiled { scene })
}

/// A coefficients field read from a `granrs.Scene`: a `granrs.Coefficients` becomes the
/// mapping its `as_dict()` gives (the same four keys in the same order); anything else
/// converts as in a scene dict.
fn coefficients_from_py(v: &Bound<'_, PyAny>) -> Value {
    if v.is_none() || v.is_instance_of::<PyDict>() {
        return value_from_py(v);
    }
    let mut entries = Vec::with_capacity(4);
    for (key, name) in [
        (pyo3::intern!(v.py(), "eta_h"), "eta_h"),
        (pyo3::intern!(v.py(), "eta_d"), "eta_d"),
        (pyo3::intern!(v.py(), "eta_v"), "eta_v"),
        (pyo3::intern!(v.py(), "lam"), "lam"),
    ] {
        match v.getattr(key) {
            Ok(x) => entries.push((Cow::Borrowed(name), value_from_py(&x))),
            Err(_) => return value_from_py(v),
        }
    }
    Value::Map(entries)
}

/// The spec of a `granrs.Scene` read straight from its attributes: `fields` is the
/// instance's `__dict__`, `names` the fields its body uses (`scene._CORE_FIELDS`). The same
/// values as the dict `Scene._plain()` builds, without building it. Each names tuple's slots
/// are found once per thread (the tuples are module constants; see `SLOTS`).
fn spec_from_fields(fields: &Bound<'_, PyDict>, names: &Bound<'_, PyTuple>) -> SceneSpec {
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
                Some(slot) if COEFFICIENTS_SLOTS.contains(&slot) => {
                    spec.set_slot(slot, coefficients_from_py(&v))
                }
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

/// [`compile`] for a `granrs.Scene`, from its `__dict__` and its body's field names (see
/// [`spec_from_fields`]): the same validation and errors, without the scene dict.
#[pyfunction]
fn compile_fields(
    py: Python<'_>,
    fields: &Bound<'_, PyDict>,
    names: &Bound<'_, PyTuple>,
) -> PyResult<Compiled> {
    let scene = spec_from_fields(fields, names)
        .build()
        .map_err(|e| to_pyerr(py, e))?;
    Ok(Compiled { scene })
}

/// The compiled scene of a `granrs.Scene` from its `__dict__` (`fields`): the one cached
/// there (`_compiled_cache`; the scene is frozen), or else compiled from the fields its body
/// uses (`core_fields[body]`, see [`compile_fields`]) and cached. `Scene._compiled()`.
#[pyfunction]
fn compiled_scene<'py>(
    py: Python<'py>,
    fields: &Bound<'py, PyDict>,
    core_fields: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyAny>> {
    let cache = pyo3::intern!(py, "_compiled_cache");
    if let Some(compiled) = fields.get_item(cache)? {
        return Ok(compiled);
    }
    let body = fields.get_item(pyo3::intern!(py, "body"))?;
    let names = match &body {
        Some(body) => core_fields.get_item(body)?,
        None => None,
    };
    let Some(names) = names else {
        // Not a body (a Scene refuses one already): the spec names the field.
        let mut spec = SceneSpec::new();
        if let Some(body) = &body {
            spec.set("body", value_from_py(body));
        }
        return Err(to_pyerr(py, spec.body().err().unwrap_or_else(missing_body)));
    };
    let compiled = Bound::new(py, compile_fields(py, fields, names.cast::<PyTuple>()?)?)?;
    fields.set_item(cache, &compiled)?;
    Ok(compiled.into_any())
}

/// The error of a scene without a body.
fn missing_body() -> GranrsError {
    GranrsError::InvalidScene {
        field: "body".into(),
        message: "missing (a value is needed)".into(),
    }
}

/// The outcome of one run, kept in Rust until Python asks for it: the headline numbers are
/// getters, the rest comes as a dict from `to_dict` (built on first request by `Result`).
#[pyclass(frozen, module = "granrs._granrs")]
struct RunOutcome {
    /// Why the run ended.
    #[pyo3(get)]
    status: &'static str,
    /// Contact 0's stopping time [s] (NaN without a stop).
    #[pyo3(get)]
    t_s: f64,
    /// Contact 0's depth at its stop [m].
    #[pyo3(get)]
    depth: f64,
    /// Wall time of the run alone [s] (for measuring a call's overhead; not a result).
    #[pyo3(get)]
    run_seconds: f64,
    /// Largest dt * lambda of the drag (see `Outcome::h_lambda`).
    #[pyo3(get)]
    h_lambda: f64,
    /// Steps the sign modes chattered through (see `Stats::unresolved`).
    #[pyo3(get)]
    unresolved: usize,
    /// The rest, moved out (series included, without a copy) by the one `to_dict` call.
    out: Mutex<Option<Outcome>>,
}

#[pymethods]
impl RunOutcome {
    /// Everything, as a dict (once: `Result` keeps it).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = self
            .out
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .take()
            .ok_or_else(|| PyRuntimeError::new_err("RunOutcome.to_dict() was already called"))?;
        let d = outcome_to_dict(py, out)?;
        d.set_item("run_seconds", self.run_seconds)?;
        Ok(d)
    }
}

/// Run a compiled scene; its outcome stays in Rust until asked for.
#[pyfunction]
fn run(py: Python<'_>, compiled: &Bound<'_, Compiled>) -> PyResult<RunOutcome> {
    let scene = &compiled.get().scene;
    let (out, seconds) = py.detach(|| {
        let t0 = std::time::Instant::now();
        let out = scene.run();
        (out, t0.elapsed().as_secs_f64())
    });
    let out = out.map_err(|e| to_pyerr(py, e))?;
    let first = out.contacts.first();
    Ok(RunOutcome {
        status: out.status.name(),
        t_s: first.map_or(f64::NAN, |c| c.t_s),
        depth: first.map_or(f64::NAN, |c| c.depth),
        run_seconds: seconds,
        h_lambda: out.h_lambda,
        unresolved: out.stats.unresolved,
        out: Mutex::new(Some(out)),
    })
}

/// Run a `granrs.Scene` from its `__dict__`: [`compiled_scene`] then [`run`] in one call
/// (the body of `granrs.simulate`).
#[pyfunction]
fn run_scene(
    py: Python<'_>,
    fields: &Bound<'_, PyDict>,
    core_fields: &Bound<'_, PyDict>,
) -> PyResult<RunOutcome> {
    let compiled = compiled_scene(py, fields, core_fields)?;
    run(py, compiled.cast::<Compiled>()?)
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
    let leg = spec_from_dict(scene).leg().map_err(|e| to_pyerr(py, e))?;
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

/// The batch a `sweep` call describes.
fn source_from_py(
    base: Option<Bound<'_, PyDict>>,
    axes: Option<Vec<(String, Bound<'_, PyAny>)>>,
    scenes: Option<Vec<Bound<'_, PyDict>>>,
) -> PyResult<Source> {
    match (base, scenes) {
        (Some(base), None) => {
            let mut converted = Vec::new();
            for (field, values) in axes.unwrap_or_default() {
                let values: Vec<Value> = values
                    .try_iter()?
                    .map(|v| v.map(|v| value_from_py(&v)))
                    .collect::<PyResult<_>>()?;
                converted.push((field, values));
            }
            Ok(Source::Product {
                base: spec_from_dict(&base),
                axes: converted,
            })
        }
        (None, Some(scenes)) => Ok(Source::List(scenes.iter().map(spec_from_dict).collect())),
        _ => Err(PyValueError::new_err(
            "sweep() takes either base (with axes) or scenes",
        )),
    }
}

/// Validate every run of a batch (as `sweep` describes it) without running any; raises the
/// typed error of the first bad run, naming the field and the run.
#[pyfunction]
#[pyo3(signature = (base=None, axes=None, scenes=None, threads=0))]
fn validate_sweep<'py>(
    py: Python<'py>,
    base: Option<Bound<'py, PyDict>>,
    axes: Option<Vec<(String, Bound<'py, PyAny>)>>,
    scenes: Option<Vec<Bound<'py, PyDict>>>,
    threads: usize,
) -> PyResult<usize> {
    let err = |e: GranrsError| to_pyerr(py, e);
    let src = source_from_py(base, axes, scenes)?;
    src.body().map_err(err)?;
    let pool = batch::pool(threads).map_err(err)?;
    let n = src.len();
    py.detach(|| pool.install(|| batch::validate(&src, 0..n)))
        .map_err(err)?;
    Ok(n)
}

/// Run a batch: the Cartesian product of `axes` (a list of `(field, values)`) over the scene
/// dict `base`, or a list of scene dicts `scenes`; runs `start..stop` of it (default: all)
/// on `threads` threads (0: one per core) with the GIL released.
///
/// Every run is validated before any starts. `progress(done)` is called about ten times a
/// second from the calling thread; Ctrl-C (or an exception in `progress`) cancels the batch
/// after the runs in flight and raises. Returns a dict: `columns` (names), `data` (a
/// rows x columns float array, input order), `failures` (list of (run, message)), `body`.
#[pyfunction]
#[pyo3(signature = (base=None, axes=None, scenes=None, start=0, stop=None, threads=0, progress=None))]
#[allow(clippy::too_many_arguments)]
fn sweep<'py>(
    py: Python<'py>,
    base: Option<Bound<'py, PyDict>>,
    axes: Option<Vec<(String, Bound<'py, PyAny>)>>,
    scenes: Option<Vec<Bound<'py, PyDict>>>,
    start: usize,
    stop: Option<usize>,
    threads: usize,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let err = |e: GranrsError| to_pyerr(py, e);
    let src = source_from_py(base, axes, scenes)?;
    let n = src.len();
    let stop = stop.unwrap_or(n).min(n);
    let range = start.min(stop)..stop;
    let body = src.body().map_err(err)?;
    let pool = batch::pool(threads).map_err(err)?;
    py.detach(|| pool.install(|| batch::validate(&src, range.clone())))
        .map_err(err)?;
    let done = AtomicUsize::new(0);
    let cancel = AtomicBool::new(false);
    let finished = AtomicBool::new(false);
    let caller = std::thread::current();
    let (out, interrupted) = std::thread::scope(|s| {
        let worker = s.spawn(|| {
            let out = pool.install(|| batch::run(&src, range.clone(), &body, &done, &cancel));
            finished.store(true, Ordering::Release);
            caller.unpark();
            out
        });
        let mut interrupted: Option<PyErr> = None;
        let mut reported = usize::MAX;
        loop {
            py.detach(|| {
                if !finished.load(Ordering::Acquire) {
                    std::thread::park_timeout(std::time::Duration::from_millis(100));
                }
            });
            let now = done.load(Ordering::Relaxed);
            if let Some(cb) = &progress {
                if now != reported {
                    reported = now;
                    if let Err(e) = cb.call1((now,)) {
                        interrupted.get_or_insert(e);
                    }
                }
            }
            if let Err(e) = py.check_signals() {
                interrupted.get_or_insert(e);
            }
            if interrupted.is_some() {
                cancel.store(true, Ordering::Relaxed);
            }
            if finished.load(Ordering::Acquire) || interrupted.is_some() {
                break;
            }
        }
        let out = py.detach(|| worker.join());
        (out, interrupted)
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    let out = out.map_err(|_| PyRuntimeError::new_err("a sweep worker panicked"))?;
    let rows = range.len();
    let width = out.columns.len();
    let d = PyDict::new(py);
    d.set_item("columns", out.columns)?;
    d.set_item("data", out.data.into_pyarray(py).reshape([rows, width])?)?;
    d.set_item("failures", out.failures)?;
    d.set_item("body", body)?;
    Ok(d)
}

/// Evaluate the rod resistance force over many states (see `rust/evaluate.rs`): `inputs`
/// are nine equal-length float arrays in the order of `INPUTS`; returns an `n x 10` array
/// in the order of `OUTPUTS`. Every value is checked before any is evaluated.
#[pyfunction]
#[pyo3(signature = (inputs, length, diameter, rho_g, g, effects, sign_model, smooth_eps))]
#[allow(clippy::too_many_arguments)]
fn resistance_force<'py>(
    py: Python<'py>,
    inputs: Vec<numpy::PyReadonlyArray1<'py, f64>>,
    length: f64,
    diameter: f64,
    rho_g: f64,
    g: f64,
    effects: Vec<String>,
    sign_model: &str,
    smooth_eps: f64,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    use crate::error::check_range;
    use crate::evaluate::{evaluate, RodSetup, Sign, INPUTS, OUTPUTS};
    let err = |e: GranrsError| to_pyerr(py, e);
    if inputs.len() != INPUTS.len() {
        return Err(PyValueError::new_err(format!(
            "resistance_force takes {} arrays ({})",
            INPUTS.len(),
            INPUTS.join(", ")
        )));
    }
    let slices: Vec<&[f64]> = inputs
        .iter()
        .map(|a| a.as_slice())
        .collect::<Result<_, _>>()
        .map_err(|_| PyValueError::new_err("resistance_force needs contiguous arrays"))?;
    // Each input has n values or one (a scalar, broadcast here without copying).
    let n = slices.iter().map(|s| s.len()).max().unwrap_or(0);
    if slices.iter().any(|s| s.len() != n && s.len() != 1) {
        return Err(PyValueError::new_err(
            "resistance_force arrays must have the same length or length 1",
        ));
    }
    check_range("length", length, 0.0, true).map_err(err)?;
    check_range("diameter", diameter, 0.0, true).map_err(err)?;
    check_range("rho_g", rho_g, 0.0, true).map_err(err)?;
    check_range("g", g, 0.0, false).map_err(err)?;
    let names: Vec<Cow<'static, str>> = effects.into_iter().map(Cow::Owned).collect();
    // The terms' parameters come with each state; these are placeholders.
    let forces = crate::spec::thesis_law(
        Some(&names),
        &[crate::forces::Coefficients::TABLE_3_4_VERTICAL],
    )
    .map_err(err)?;
    let sign = match sign_model {
        "raw" => Sign::Raw,
        "smooth" => Sign::Smooth(check_range("smooth_eps", smooth_eps, 0.0, true).map_err(err)?),
        other => {
            return Err(err(GranrsError::UnknownName {
                field: "sign_model".into(),
                value: other.into(),
                allowed: "raw, smooth (the held signs of \"modes\" need a time history)".into(),
            }))
        }
    };
    // Check every value before evaluating any.
    let checked = py.detach(|| -> Result<(), GranrsError> {
        for (k, (name, s)) in INPUTS.iter().zip(&slices).enumerate() {
            for (i, &x) in s.iter().enumerate() {
                let ok = match k {
                    1 => x.is_finite() && x.abs() < 90.0,
                    5..=8 => x.is_finite() && x >= 0.0,
                    _ => x.is_finite(),
                };
                if !ok {
                    let allowed = match k {
                        1 => "finite, -90 < q_deg < 90",
                        5..=8 => "finite, >= 0",
                        _ => "finite",
                    };
                    return Err(GranrsError::InvalidParameter {
                        field: name.to_string(),
                        value: x,
                        allowed: format!("{allowed}; at index {i}"),
                    });
                }
            }
        }
        Ok(())
    });
    checked.map_err(err)?;
    let setup = RodSetup {
        length,
        diameter,
        medium: crate::forces::Medium { rho_g, g },
        forces,
        sign,
    };
    let width = OUTPUTS.len();
    let out = py.detach(|| {
        use rayon::prelude::*;
        const CHUNK: usize = 4096;
        let mut out = vec![0.0; n * width];
        let run = |c: usize, rows: &mut [f64]| {
            for (j, row) in rows.chunks_exact_mut(width).enumerate() {
                let i = c * CHUNK + j;
                let input = std::array::from_fn(|k| {
                    let s = slices[k];
                    if s.len() == 1 {
                        s[0]
                    } else {
                        s[i]
                    }
                });
                evaluate(&setup, input, row);
            }
        };
        if n <= 4 * CHUNK {
            // Small calls (a simulator's contacts at one step): no thread hand-off.
            out.chunks_mut(CHUNK * width)
                .enumerate()
                .for_each(|(c, rows)| run(c, rows));
        } else {
            out.par_chunks_mut(CHUNK * width)
                .enumerate()
                .for_each(|(c, rows)| run(c, rows));
        }
        out
    });
    out.into_pyarray(py).reshape([n, width])
}

#[pymodule]
fn _granrs(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(compile, m)?)?;
    m.add_function(wrap_pyfunction!(compile_fields, m)?)?;
    m.add_function(wrap_pyfunction!(compiled_scene, m)?)?;
    m.add_function(wrap_pyfunction!(run_scene, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_class::<Compiled>()?;
    m.add_class::<RunOutcome>()?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(validate_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(resistance_force, m)?)?;
    m.add("FORCE_INPUTS", crate::evaluate::INPUTS.to_vec())?;
    m.add("FORCE_OUTPUTS", crate::evaluate::OUTPUTS.to_vec())?;
    m.add("EFFECTS", EFFECTS.to_vec())?;
    m.add("RECORDS", RECORDS.to_vec())?;
    m.add("SCENE_FIELDS", SCENE_FIELDS.to_vec())?;
    m.add_function(wrap_pyfunction!(leg_segments, m)?)?;
    m.add_function(wrap_pyfunction!(terms::term_infos, m)?)?;
    m.add_function(wrap_pyfunction!(terms::check_term, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
