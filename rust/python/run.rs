//! Compiling and running one scene: `compile`, `compile_fields`, `compiled_scene`, `run`,
//! `run_scene` (the body of `granrs.simulate`), `validate` and `leg_segments`; the outcome
//! stays in Rust ([`RunOutcome`]) until Python asks for its dict, whose summaries are read
//! from the one table of output fields.

use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

use numpy::IntoPyArray;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use super::convert::{scene_from_dict, spec_from_dict, spec_from_fields, value_from_py};
use super::errors::to_pyerr;
use crate::bodies::LinkageScene;
use crate::error::GranrsError;
use crate::integrate::cancel::Watch;
use crate::integrate::{FieldValue, Outcome, Outputs, OUTCOME_FIELDS};
use crate::spec::SceneSpec;

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
/// output fields ([`OUTCOME_FIELDS`]), those the run computed (its `outputs`); series move
/// into numpy without copying.
fn outcome_to_dict<'py>(py: Python<'py>, out: Outcome) -> PyResult<Bound<'py, PyDict>> {
    let fields = out.outputs;
    let d = PyDict::new(py);
    d.set_item("status", out.status.name())?;
    d.set_item("t_final", out.t_final)?;
    // The work counters; and the run-level entries of Result.summary (the counters first),
    // merged there with contact 0's in one update.
    let stats = PyDict::new(py);
    for f in fields.run() {
        if let v @ FieldValue::Count(_) = (f.read)(&out) {
            stats.set_item(f.name, field_to_py(py, v)?)?;
        }
    }
    let run = stats.copy()?;
    for f in fields.run() {
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
    // Each contact's summary; whether it stopped, its t_s and its depth (every run's,
    // whatever its outputs) go in lists of their own.
    let contacts = PyList::empty(py);
    let stopped = PyList::empty(py);
    let t_s = PyList::empty(py);
    let depth = PyList::empty(py);
    for c in &out.contacts {
        stopped.append(c.stopped)?;
        t_s.append(c.t_s)?;
        depth.append(c.depth)?;
        let cd = PyDict::new(py);
        for f in fields.contact().filter(|f| f.name != "stopped") {
            cd.set_item(f.name, field_to_py(py, (f.read)(c))?)?;
        }
        contacts.append(cd)?;
    }
    d.set_item("contacts", contacts)?;
    d.set_item("stopped", stopped)?;
    d.set_item("t_s", t_s)?;
    d.set_item("depth", depth)?;
    d.set_item("dissipated", out.dissipated)?;
    let joints = PyList::empty(py);
    for j in &out.joints {
        let jd = PyDict::new(py);
        for f in fields.joint() {
            jd.set_item(f.name, field_to_py(py, (f.read)(j))?)?;
        }
        joints.append(jd)?;
    }
    d.set_item("joints", joints)?;
    // The table-driven joints' impulses: (link in the engine's order, t [s], impulse
    // [N m s], energy [J]), in time order.
    let impulses = PyList::empty(py);
    for i in &out.impulses {
        impulses.append((i.link, i.t, i.impulse, i.energy))?;
    }
    d.set_item("impulses", impulses)?;
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

/// The output fields a scene's `outputs` may list ([`OUTCOME_FIELDS`], by [`Outputs::names`]):
/// name, part (`run`, `contact` or `joint`), unit, and what the run computes for it beyond
/// its steps (empty: nothing), for `granrs.OUTPUTS`, `granrs.result.SUMMARY_UNITS` and the
/// docs.
#[pyfunction]
pub(super) fn output_fields(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let fields = &OUTCOME_FIELDS;
    let out = PyList::empty(py);
    let add = |part: &str, name: &str, unit: &str, needs: crate::integrate::Needs| {
        out.append(py_dict!(py, {
            "name": name, "part": part, "unit": unit, "computes": needs.names().join(", "),
        }))
    };
    for f in fields.run {
        add("run", f.name, f.unit, f.needs)?;
    }
    for f in fields.contact {
        add("contact", f.name, f.unit, f.needs)?;
    }
    for f in fields.joint {
        add("joint", f.name, f.unit, f.needs)?;
    }
    debug_assert_eq!(out.len(), Outputs::names().len());
    Ok(out)
}

/// A scene converted and validated once (`compile`), to run many times without parsing: its
/// spec (what a sweep over a list of scenes reads, shared) and the scene built from it.
#[pyclass(frozen, module = "granrs._granrs")]
pub(super) struct Compiled {
    pub(super) spec: Arc<SceneSpec>,
    pub(super) scene: Arc<LinkageScene>,
}

impl Compiled {
    /// Build `spec` (the typed error of its first bad field).
    fn of(py: Python<'_>, spec: SceneSpec) -> PyResult<Self> {
        let scene = spec.build().map_err(|e| to_pyerr(py, e))?;
        Ok(Compiled {
            spec: Arc::new(spec),
            scene: Arc::new(scene),
        })
    }
}

/// Convert and validate a scene dict once; `run` it as often as wanted.
#[pyfunction]
pub(super) fn compile(py: Python<'_>, scene: &Bound<'_, PyDict>) -> PyResult<Compiled> {
    Compiled::of(py, spec_from_dict(scene))
}

/// [`compile`] for a `granrs.Scene`, from its `__dict__` and its body's field names (see
/// [`spec_from_fields`]): the same validation and errors, without the scene dict.
#[pyfunction]
pub(super) fn compile_fields(
    py: Python<'_>,
    fields: &Bound<'_, PyDict>,
    names: &Bound<'_, PyTuple>,
) -> PyResult<Compiled> {
    Compiled::of(py, spec_from_fields(fields, names))
}

/// The compiled scene of a `granrs.Scene` from its `__dict__` (`fields`): the one cached
/// there (`_compiled_cache`; the scene is frozen), or else compiled from the fields its body
/// uses (`core_fields[body]`, see [`compile_fields`]) and cached. `Scene._compiled()`.
#[pyfunction]
pub(super) fn compiled_scene<'py>(
    py: Python<'py>,
    fields: &Bound<'py, PyDict>,
    core_fields: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyAny>> {
    let cache = pyo3::intern!(py, "_compiled_cache");
    if let Some(compiled) = fields.get_item(cache)? {
        return Ok(compiled);
    }
    let body = fields.get_item(pyo3::intern!(py, "body"))?;
    // A body is a name, or a `granrs.bodies.Linkage` whose `name` is a built-in body's or
    // "linkage".
    let names = match &body {
        Some(body) if body.is_instance_of::<pyo3::types::PyString>() => {
            core_fields.get_item(body)?
        }
        Some(body) => match body.getattr(pyo3::intern!(py, "name")) {
            Ok(name) => core_fields.get_item(name)?,
            Err(_) => None,
        },
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
pub(super) struct RunOutcome {
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
    /// Stops the step did not resolve (see `Stats::unresolved_stops`).
    #[pyo3(get)]
    unresolved_stops: usize,
    /// The steps' estimate of the largest relative error of t_s or depth (see
    /// `Outcome::step_error`).
    #[pyo3(get)]
    step_error: f64,
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

/// Whether this thread is Python's main thread, the one that runs its signal handlers
/// (asked of `threading` once per thread).
fn on_main_thread(py: Python<'_>) -> bool {
    thread_local! {
        static MAIN: std::cell::Cell<Option<bool>> = const { std::cell::Cell::new(None) };
    }
    MAIN.with(|main| match main.get() {
        Some(answer) => answer,
        None => {
            let ask = || -> PyResult<bool> {
                let threading = py.import("threading")?;
                let current = threading.call_method0("current_thread")?;
                Ok(current.is(&threading.call_method0("main_thread")?))
            };
            let answer = ask().unwrap_or(false);
            main.set(Some(answer));
            answer
        }
    })
}

/// Run `work` with the GIL released, and give its value and the seconds it took. On
/// Python's main thread the work polls the signals about every 20 ms
/// ([`crate::integrate::cancel`]: the GIL is taken back for the poll only), so that Ctrl-C
/// stops it and raises `KeyboardInterrupt` (or what a signal handler raised).
pub(super) fn watched<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<(T, f64)> {
    let main = on_main_thread(py);
    let (out, seconds, raised) = py.detach(|| {
        let t0 = std::time::Instant::now();
        let raised: std::cell::RefCell<Option<PyErr>> = std::cell::RefCell::new(None);
        let cancel = AtomicBool::new(false);
        let out = if main {
            let poll = || match Python::attach(|py| py.check_signals()) {
                Ok(()) => false,
                Err(e) => {
                    *raised.borrow_mut() = Some(e);
                    true
                }
            };
            Watch::polling(&cancel, &poll).over(work)
        } else {
            work()
        };
        (out, t0.elapsed().as_secs_f64(), raised.into_inner())
    });
    if let Some(e) = raised {
        return Err(e);
    }
    Ok((out, seconds))
}

/// Run a compiled scene with the GIL released; its outcome stays in Rust until asked for.
///
/// On Python's main thread the run polls the signals about every 20 ms
/// ([`crate::integrate::cancel`]: the GIL is taken back for the poll only), so that Ctrl-C
/// stops it and raises `KeyboardInterrupt` (or what a signal handler raised).
#[pyfunction]
pub(super) fn run(py: Python<'_>, compiled: &Bound<'_, Compiled>) -> PyResult<RunOutcome> {
    // Validated when it was compiled (`SceneSpec::build`); the scene is immutable.
    let scene = &compiled.get().scene;
    let (out, seconds) = watched(py, || scene.run_validated())?;
    let out = out.map_err(|e| to_pyerr(py, e))?;
    let first = out.contacts.first();
    Ok(RunOutcome {
        status: out.status.name(),
        t_s: first.map_or(f64::NAN, |c| c.t_s),
        depth: first.map_or(f64::NAN, |c| c.depth),
        run_seconds: seconds,
        h_lambda: out.h_lambda,
        unresolved: out.stats.unresolved,
        unresolved_stops: out.stats.unresolved_stops,
        step_error: out.step_error,
        out: Mutex::new(Some(out)),
    })
}

/// Run a `granrs.Scene` from its `__dict__`: [`compiled_scene`] then [`run`] in one call
/// (the body of `granrs.simulate`).
#[pyfunction]
pub(super) fn run_scene(
    py: Python<'_>,
    fields: &Bound<'_, PyDict>,
    core_fields: &Bound<'_, PyDict>,
) -> PyResult<RunOutcome> {
    let compiled = compiled_scene(py, fields, core_fields)?;
    run(py, compiled.cast::<Compiled>()?)
}

/// Validate a scene dict without running it (raises the typed error, or returns None).
#[pyfunction]
pub(super) fn validate(py: Python<'_>, scene: &Bound<'_, PyDict>) -> PyResult<()> {
    scene_from_dict(scene)
        .map(|_| ())
        .map_err(|e| to_pyerr(py, e))
}

/// The leg's segments for a scene dict (body "leg"): a list of dicts with name, mass [kg],
/// length [m], com (from the lower joint) [m] and inertia about the centre of mass [kg m^2].
#[pyfunction]
pub(super) fn leg_segments<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyList>> {
    let leg =
        crate::presets::leg::Leg::read(&spec_from_dict(scene)).map_err(|e| to_pyerr(py, e))?;
    let out = PyList::empty(py);
    for (name, s) in ["foot", "shank", "thigh", "half_trunk"]
        .iter()
        .zip(leg.segments())
    {
        out.append(py_dict!(py, {
            "name": name, "mass": s.mass, "length": s.length, "com": s.com,
            "inertia": s.inertia,
        }))?;
    }
    Ok(out)
}
