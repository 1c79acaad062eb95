//! Batches from Python: `sweep` (run on the shared rayon pool with the GIL released, with
//! progress and Ctrl-C) and `validate_sweep` (Ctrl-C too).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::convert::{spec_from_dict, value_from_py};
use super::errors::to_pyerr;
use super::run::Compiled;
use crate::batch::{self, Listed, Source};
use crate::error::GranrsError;
use crate::spec::Value;

/// How long a sweep's calling thread waits for the batch by yielding its core before it
/// sleeps between progress reports (a one-scene sweep's core call 215-229 -> 202-205 us, and
/// no slower a 155-run sweep on two threads: `benches/bench_sweep.py --part fixed`).
const YIELD_WAIT: std::time::Duration = std::time::Duration::from_micros(200);

/// The batch a `sweep` call describes: its runs, and the output fields every run returns
/// (`outputs`: None keeps the scenes' own), checked (the typed error names the field).
fn source_from_py(
    py: Python<'_>,
    base: Option<Bound<'_, PyDict>>,
    axes: Option<Vec<(String, Bound<'_, PyAny>)>>,
    scenes: Option<Vec<Bound<'_, PyAny>>>,
    outputs: Option<Bound<'_, PyAny>>,
) -> PyResult<Source> {
    let mut src = source_of(base, axes, scenes)?;
    let err = |e: GranrsError| to_pyerr(py, e);
    if let Some(outputs) = outputs.filter(|o| !o.is_none()) {
        match value_from_py(&outputs) {
            Value::Names(names) => src.set_outputs(names).map_err(err)?,
            other => {
                return Err(err(GranrsError::WrongType {
                    field: "outputs".into(),
                    expected: "a list of names".into(),
                    got: other.kind(),
                }))
            }
        }
    }
    src.outputs().map_err(err)?;
    Ok(src)
}

/// The runs a `sweep` call describes.
fn source_of(
    base: Option<Bound<'_, PyDict>>,
    axes: Option<Vec<(String, Bound<'_, PyAny>)>>,
    scenes: Option<Vec<Bound<'_, PyAny>>>,
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
        // A compiled scene (`Scene._compiled()`) gives its spec and the scene built from it,
        // as they are; a dict is converted, and the batch builds it.
        (None, Some(scenes)) => Ok(Source::List(
            scenes
                .iter()
                .map(|s| match s.cast::<Compiled>() {
                    Ok(c) => Ok(Listed {
                        spec: Arc::clone(&c.get().spec),
                        built: Some(Arc::clone(&c.get().scene)),
                    }),
                    Err(_) => Ok(Listed::spec(spec_from_dict(s.cast::<PyDict>()?))),
                })
                .collect::<PyResult<_>>()?,
        )),
        _ => Err(PyValueError::new_err(
            "sweep() takes either base (with axes) or scenes",
        )),
    }
}

/// How often the calling thread of a sweep polls Python's signals (Ctrl-C): the batch's runs
/// see the cancellation within a few milliseconds more.
const SIGNALS_EVERY: std::time::Duration = std::time::Duration::from_millis(20);

/// How often a sweep reports its progress.
const PROGRESS_EVERY: std::time::Duration = std::time::Duration::from_millis(100);

/// Run `job` (given the flag that cancels it) on the shared pool while this thread waits
/// with the GIL released, polls Python's signals every [`SIGNALS_EVERY`] and reports
/// `progress(done)` about every [`PROGRESS_EVERY`]. Ctrl-C (or an exception in `progress`)
/// sets the flag, which the job's runs and validation watch, and is raised once the job has
/// stopped.
fn on_pool<R: Send>(
    py: Python<'_>,
    pool: &rayon::ThreadPool,
    done: &AtomicUsize,
    progress: Option<&Bound<'_, PyAny>>,
    job: impl FnOnce(&AtomicBool) -> R + Send,
) -> PyResult<R> {
    let cancel = AtomicBool::new(false);
    let finished = AtomicBool::new(false);
    let caller = std::thread::current();
    let mut out = None;
    let interrupted = pool.in_place_scope(|scope| {
        scope.spawn(|_| {
            // A panic is caught here, so that `finished` is always set.
            out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job(&cancel))).ok();
            finished.store(true, Ordering::Release);
            caller.unpark();
        });
        let mut interrupted: Option<PyErr> = None;
        let mut reported = usize::MAX;
        // A small sweep is over within a fraction of a millisecond: wait for it yielding the
        // core rather than asleep, whose wake-up added its latency to every small sweep.
        py.detach(|| {
            let t0 = std::time::Instant::now();
            while !finished.load(Ordering::Acquire) && t0.elapsed() < YIELD_WAIT {
                std::thread::yield_now();
            }
        });
        let mut last_report: Option<std::time::Instant> = None;
        loop {
            py.detach(|| {
                if !finished.load(Ordering::Acquire) {
                    std::thread::park_timeout(SIGNALS_EVERY);
                }
            });
            let now = done.load(Ordering::Relaxed);
            if let Some(cb) = progress {
                let due = last_report.is_none_or(|t| t.elapsed() >= PROGRESS_EVERY);
                if now != reported && (due || finished.load(Ordering::Acquire)) {
                    reported = now;
                    last_report = Some(std::time::Instant::now());
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
        // A cancelled job stops within milliseconds: wait for it without the GIL.
        py.detach(|| {
            while !finished.load(Ordering::Acquire) {
                std::thread::park_timeout(std::time::Duration::from_millis(5));
            }
        });
        interrupted
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    out.ok_or_else(|| PyRuntimeError::new_err("a sweep worker panicked"))
}

/// The shared pool and the threads of it a sweep asked for (0: all; more than the pool
/// has: all, see [`batch::workers`]).
fn pool_for(py: Python<'_>, threads: usize) -> PyResult<(Arc<rayon::ThreadPool>, usize)> {
    let pool = batch::pool().map_err(|e| to_pyerr(py, e))?;
    let workers = batch::workers(&pool, threads);
    Ok((pool, workers))
}

/// The most threads a sweep runs on: the machine's cores (the shared pool's size).
#[pyfunction]
pub(super) fn max_threads(py: Python<'_>) -> PyResult<usize> {
    Ok(pool_for(py, 0)?.1)
}

/// Whether a sweep's lanes call glibc's four-lane `sin`, `cos` and `pow`
/// (`GRANRS_FAST_LANES=1`, read once per process, on a CPU with AVX2 where libmvec is found):
/// then a lane's row is near `simulate`'s, not its bits.
#[pyfunction]
pub(super) fn fast_lanes() -> bool {
    crate::num::vector_calls::active()
}

/// Validate every run of a batch (as `sweep` describes it) without running any, on
/// `threads` threads (as `sweep`); raises the typed error of the first bad run, naming the
/// field and the run. Ctrl-C stops it (within milliseconds) and raises.
#[pyfunction]
#[pyo3(signature = (base=None, axes=None, scenes=None, threads=0, outputs=None))]
pub(super) fn validate_sweep<'py>(
    py: Python<'py>,
    base: Option<Bound<'py, PyDict>>,
    axes: Option<Vec<(String, Bound<'py, PyAny>)>>,
    scenes: Option<Vec<Bound<'py, PyAny>>>,
    threads: usize,
    outputs: Option<Bound<'py, PyAny>>,
) -> PyResult<usize> {
    let err = |e: GranrsError| to_pyerr(py, e);
    let src = source_from_py(py, base, axes, scenes, outputs)?;
    src.body().map_err(err)?;
    let n = src.len();
    let (pool, workers) = pool_for(py, threads)?;
    let done = AtomicUsize::new(0);
    on_pool(py, &pool, &done, None, |cancel| {
        batch::validate(&src, 0..n, workers, cancel)
    })?
    .map_err(err)?;
    Ok(n)
}

/// Run a batch: the Cartesian product of `axes` (a list of `(field, values)`) over the scene
/// dict `base`, or a list of scene dicts `scenes`; runs `start..stop` of it (default: all)
/// on `threads` threads of the shared pool (0, or more than the machine's cores: one per
/// core) with the GIL released.
///
/// Every run is validated before any starts. `progress(done)` is called about ten times a
/// second from the calling thread; Ctrl-C (or an exception in `progress`) cancels the batch,
/// the runs in flight and the validation included, within milliseconds, and raises. Returns
/// a dict: `columns` (names), `data` (a rows x columns float array, input order),
/// `failures` (list of (run, message)), `unresolved` (the runs with `unresolved_stops` > 0,
/// whatever the outputs), `body`.
///
/// `outputs` (a list of output field names, or None for the scenes' own) are the fields
/// every run computes and returns: the table's columns.
///
/// `lanes` (default true) runs the free-link scenes (under any terms) four at a time in
/// SIMD lanes (`batch::Path::Lanes`;
/// the same results bit for bit); false runs every scene alone on the scalar path.
#[pyfunction]
#[pyo3(signature = (base=None, axes=None, scenes=None, start=0, stop=None, threads=0, progress=None, lanes=true, outputs=None))]
#[allow(clippy::too_many_arguments)]
pub(super) fn sweep<'py>(
    py: Python<'py>,
    base: Option<Bound<'py, PyDict>>,
    axes: Option<Vec<(String, Bound<'py, PyAny>)>>,
    scenes: Option<Vec<Bound<'py, PyAny>>>,
    start: usize,
    stop: Option<usize>,
    threads: usize,
    progress: Option<Bound<'py, PyAny>>,
    lanes: bool,
    outputs: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let path = if lanes {
        batch::Path::Lanes
    } else {
        batch::Path::Scalar
    };
    let err = |e: GranrsError| to_pyerr(py, e);
    let src = source_from_py(py, base, axes, scenes, outputs)?;
    let n = src.len();
    let stop = stop.unwrap_or(n).min(n);
    let range = start.min(stop)..stop;
    let body = src.body().map_err(err)?;
    let (pool, workers) = pool_for(py, threads)?;
    let done = AtomicUsize::new(0);
    // One job on the shared pool validates every run, then runs them.
    let out = on_pool(py, &pool, &done, progress.as_ref(), |cancel| {
        batch::validate(&src, range.clone(), workers, cancel)
            .map(|()| batch::run(&src, range.clone(), workers, &done, cancel, path))
    })?
    .map_err(err)?;
    let rows = range.len();
    let width = out.columns.len();
    let d = PyDict::new(py);
    d.set_item("columns", out.columns)?;
    d.set_item("data", out.data.into_pyarray(py).reshape([rows, width])?)?;
    d.set_item("failures", out.failures)?;
    d.set_item("unresolved", out.unresolved)?;
    d.set_item("body", body)?;
    Ok(d)
}
