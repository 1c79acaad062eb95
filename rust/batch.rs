//! Many runs at once: a Cartesian product of field values over a base scene, or a list of
//! scenes, run on the process's one rayon pool ([`pool`], one thread per core) and
//! summarized into one table (one row per run, in input order).
//!
//! Every scene of the batch is built and validated before the first run starts, so a bad
//! value stops the batch with an error naming the run and the field, and nothing has run. A
//! run that fails (a non-finite state) does not stop the batch: its row has status
//! [`STATUS_FAILED`] and its message is kept. Progress is an atomic counter and
//! cancellation an atomic flag, so a caller (Python's Ctrl-C) can watch and stop the
//! batch, its validation included, from another thread: the runs in flight stop within a
//! few milliseconds ([`crate::integrate::cancel`]).

use std::borrow::Cow;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use crate::bodies::LinkageScene;
use crate::error::{GranrsError, Result};
use crate::integrate::cancel::Watch;
use crate::integrate::lanes::{run_lanes, LaneIsa, LaneScene};
use crate::integrate::{Outcome, Outputs, Status};
use crate::spec::{SceneSpec, Value};

/// Status codes of the `status` column ([`Status::code`]).
pub const STATUS_STOPPED: f64 = Status::Stopped.code();
/// `t_end` reached with the end condition `time`.
pub const STATUS_END_TIME: f64 = Status::EndTime.code();
/// `t_end` reached before the stop.
pub const STATUS_NOT_STOPPED: f64 = Status::NotStopped.code();
/// The run failed (its message is in [`BatchOut::failures`]).
pub const STATUS_FAILED: f64 = 3.0;
/// The run was not started (the batch was cancelled).
pub const STATUS_CANCELLED: f64 = 4.0;

/// Contacts and reported joints of a scene: each contact (at least one column set, NaN for
/// a body without contacts), and each link's joint where there are several links (a single
/// link hangs from nothing but its root).
pub fn body_shape(scene: &LinkageScene) -> (usize, usize) {
    let links = scene.links.len();
    (
        scene.contacts.len().max(1),
        if links > 1 { links } else { 0 },
    )
}

/// The summary columns of a body of `shape` ([`body_shape`]) whose runs return `outputs`,
/// in row order: the run's fields of [`crate::integrate::OUTCOME_FIELDS`] in `outputs`
/// (`status` first, always), then each contact's (prefixed `c{i}.`) and each reported
/// joint's (`joint{j}.`).
pub fn columns((nc, nj): (usize, usize), outputs: Outputs) -> Vec<String> {
    let mut out: Vec<String> = outputs.run().map(|f| f.name.to_string()).collect();
    for i in 0..nc {
        out.extend(outputs.contact().map(|f| format!("c{i}.{}", f.name)));
    }
    for j in 0..nj {
        out.extend(outputs.joint().map(|f| format!("joint{j}.{}", f.name)));
    }
    out
}

/// Write one outcome into its row (`row.len() == columns(shape, out.outputs).len()`).
pub fn summarize(out: &Outcome, row: &mut [f64]) {
    let fields = out.outputs;
    let mut cells = row.iter_mut();
    for (f, cell) in fields.run().zip(&mut cells) {
        *cell = (f.read)(out).as_f64();
    }
    for c in &out.contacts {
        for (f, cell) in fields.contact().zip(&mut cells) {
            *cell = (f.read)(c).as_f64();
        }
    }
    // The row has room for the body's reported joints (none for a free link).
    for j in &out.joints {
        for (f, cell) in fields.joint().zip(&mut cells) {
            *cell = (f.read)(j).as_f64();
        }
    }
}

/// What a batch runs.
// A spec holds a slot for every scene field (about 1.4 kB); a batch has one Source, built
// once, so the size of its variants does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum Source {
    /// The Cartesian product of `axes` over `base` (the last axis varies fastest, as in
    /// `itertools.product`).
    Product {
        /// The scene every run starts from.
        base: SceneSpec,
        /// Field name and its values, per axis.
        axes: Vec<(String, Vec<Value>)>,
    },
    /// One scene per run (shared: a `granrs.Scene` converts its spec once and keeps it).
    List(Vec<Listed>),
}

/// A run of a list batch: its spec, and the scene built and validated from it where the
/// caller has that already (a compiled `granrs.Scene`), so that the batch neither validates
/// nor builds it again.
#[derive(Debug, Clone)]
pub struct Listed {
    /// The scene's spec.
    pub spec: Arc<SceneSpec>,
    /// The scene built from `spec` and validated.
    pub built: Option<Arc<LinkageScene>>,
}

impl Listed {
    /// A spec still to be built (and validated) by the batch.
    pub fn spec(spec: SceneSpec) -> Self {
        Listed {
            spec: Arc::new(spec),
            built: None,
        }
    }
}

impl Source {
    /// Number of runs.
    pub fn len(&self) -> usize {
        match self {
            Source::Product { axes, .. } => axes.iter().map(|(_, v)| v.len()).product(),
            Source::List(specs) => specs.len(),
        }
    }

    /// Whether there is nothing to run.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The spec of run `i`.
    pub fn spec(&self, i: usize) -> Cow<'_, SceneSpec> {
        match self {
            Source::List(runs) => Cow::Borrowed(runs[i].spec.as_ref()),
            Source::Product { base, axes } => {
                let mut spec = base.clone();
                let mut rest = i;
                for (field, values) in axes.iter().rev() {
                    let n = values.len();
                    spec.set(field, values[rest % n].clone());
                    rest /= n;
                }
                Cow::Owned(spec)
            }
        }
    }

    /// The scene of run `i`, built and validated (or as the caller built it).
    pub fn scene(&self, i: usize) -> Result<Cow<'_, LinkageScene>> {
        match self {
            Source::List(runs) => match &runs[i].built {
                Some(scene) => Ok(Cow::Borrowed(scene.as_ref())),
                None => runs[i].spec.build().map(Cow::Owned),
            },
            Source::Product { .. } => self.spec(i).build().map(Cow::Owned),
        }
    }

    /// The shape of the batch's body ([`body_shape`]): that of the first of its first runs
    /// that builds (a body's shape does not depend on the fields a sweep varies), or one
    /// contact where none does (every run then fails).
    pub fn shape(&self) -> (usize, usize) {
        (0..self.len().min(16))
            .find_map(|i| self.scene(i).ok().map(|s| body_shape(&s)))
            .unwrap_or((1, 0))
    }

    /// The output fields of the batch's runs, its columns ([`columns`]): the base scene's
    /// `outputs`, or the listed scenes', which must all be the same; a product may not vary
    /// them (an error names the field `outputs`).
    pub fn outputs(&self) -> Result<Outputs> {
        let one_set = |message: String| GranrsError::InvalidScene {
            field: "outputs".into(),
            message,
        };
        match self {
            Source::Product { base, axes } => {
                if axes.iter().any(|(f, _)| f == "outputs") {
                    return Err(one_set(
                        "a sweep returns one set of columns: give outputs once, not as an axis"
                            .into(),
                    ));
                }
                base.outputs()
            }
            Source::List(runs) => {
                let Some(first) = runs.first() else {
                    return Ok(Outputs::ALL);
                };
                let outputs = first.spec.outputs()?;
                for (i, s) in runs.iter().enumerate().skip(1) {
                    if s.spec.outputs().map_err(|e| in_run(i, e))? != outputs {
                        return Err(one_set(format!(
                            "a sweep returns one set of columns: run {i} asks for other \
                             outputs than run 0 (give the sweep outputs=... for all)"
                        )));
                    }
                }
                Ok(outputs)
            }
        }
    }

    /// Every run returns `outputs` (a sweep's `outputs=`): the base scene's field, or each
    /// listed scene's (its spec, and the scene built from it, whose options take them; no
    /// scene is built again).
    pub fn set_outputs(&mut self, names: Vec<std::borrow::Cow<'static, str>>) -> Result<()> {
        let outputs = Outputs::from_names(&names)?;
        match self {
            Source::Product { base, .. } => base.set("outputs", Value::Names(names)),
            Source::List(runs) => {
                for run in runs.iter_mut() {
                    let mut spec = (*run.spec).clone();
                    spec.set("outputs", Value::Names(names.clone()));
                    run.spec = Arc::new(spec);
                    if let Some(built) = &run.built {
                        let mut scene = (**built).clone();
                        scene.options.outputs = outputs;
                        run.built = Some(Arc::new(scene));
                    }
                }
            }
        }
        Ok(())
    }

    /// The one body of the batch (every run must share it).
    pub fn body(&self) -> Result<String> {
        let body_of = |spec: &SceneSpec| spec.body().map(|b| b.to_string());
        match self {
            Source::Product { base, axes } => {
                if axes.iter().any(|(f, _)| f == "body") {
                    return Err(GranrsError::InvalidScene {
                        field: "body".into(),
                        message: "a sweep runs one body; sweep each body separately".into(),
                    });
                }
                body_of(base)
            }
            Source::List(runs) => {
                let Some(first) = runs.first() else {
                    return Ok("free_link".into());
                };
                let body = body_of(&first.spec)?;
                for (i, s) in runs.iter().enumerate() {
                    let b = body_of(&s.spec).map_err(|e| in_run(i, e))?;
                    if b != body {
                        return Err(GranrsError::InvalidScene {
                            field: "body".into(),
                            message: format!(
                                "a sweep runs one body: run 0 is {body:?}, run {i} is {b:?}"
                            ),
                        });
                    }
                }
                Ok(body)
            }
        }
    }
}

/// Prefix an error's message with the run it came from (the field stays the same).
pub fn in_run(i: usize, e: GranrsError) -> GranrsError {
    match e {
        GranrsError::InvalidParameter {
            field,
            value,
            allowed,
        } => GranrsError::InvalidParameter {
            field,
            value,
            allowed: format!("{allowed}; in run {i}"),
        },
        GranrsError::WrongType {
            field,
            expected,
            got,
        } => GranrsError::WrongType {
            field,
            expected,
            got: format!("{got} (run {i})"),
        },
        GranrsError::UnknownName {
            field,
            value,
            allowed,
        } => GranrsError::UnknownName {
            field,
            value,
            allowed: format!("{allowed}; in run {i}"),
        },
        GranrsError::InvalidScene { field, message } => GranrsError::InvalidScene {
            field,
            message: format!("{message} (run {i})"),
        },
        other => other,
    }
}

/// The machine's cores (what the process may run on: its CPU affinity and cgroup quota):
/// the size of the one pool ([`pool`]), so the most threads a batch runs on.
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The one rayon pool of the process, of [`cores`] threads, started on first use and kept:
/// every batch runs on it, whatever its thread count ([`workers`]), so a process never holds
/// more of granrs' threads than cores, and a sweep neither starts nor stops threads.
///
/// The pool carries the id of the process that started it. A forked child (multiprocessing's
/// fork, a forking Dask worker) inherits it but not its threads, so it starts its own and
/// forgets the parent's: never drops it, as dropping would wake threads that do not exist in
/// the child.
pub fn pool() -> Result<Arc<rayon::ThreadPool>> {
    static POOL: Mutex<Option<(u32, Arc<rayon::ThreadPool>)>> = Mutex::new(None);
    let pid = std::process::id();
    let mut kept = POOL.lock().unwrap_or_else(|p| p.into_inner());
    match kept.take() {
        Some((owner, pool)) if owner == pid => {
            *kept = Some((owner, Arc::clone(&pool)));
            return Ok(pool);
        }
        Some((_, inherited)) => std::mem::forget(inherited),
        None => {}
    }
    let started = rayon::ThreadPoolBuilder::new()
        .num_threads(cores())
        .thread_name(|i| format!("granrs-{i}"))
        .build()
        .map_err(|e| GranrsError::InvalidScene {
            field: "threads".into(),
            message: format!("cannot start a thread pool: {e}"),
        })?;
    let started = Arc::new(started);
    *kept = Some((pid, Arc::clone(&started)));
    Ok(started)
}

/// The threads of `pool` a batch asked for `threads` runs on: all of them for 0, at most
/// all of them (a larger count is capped; the Python layer says so).
pub fn workers(pool: &rayon::ThreadPool, threads: usize) -> usize {
    let all = pool.current_num_threads();
    if threads == 0 {
        all
    } else {
        threads.min(all)
    }
}

/// Run `work` on the first `workers` threads of the current rayon pool (call inside
/// `pool.install` or a job of the pool), each with a [`Watch`] on `cancel` over its runs;
/// the rest of the pool's threads stay idle.
fn on_workers(workers: usize, cancel: &AtomicBool, work: impl Fn() + Sync) {
    rayon::broadcast(|ctx| {
        if ctx.index() < workers {
            Watch::new(cancel).over(&work);
        }
    });
}

/// Build and validate every run in `range` on `workers` threads (the current pool's, see
/// [`on_workers`]); the error of the first bad run, in input order, names it. Setting
/// `cancel` stops the validation ([`GranrsError::Cancelled`]).
pub fn validate(
    src: &Source,
    range: std::ops::Range<usize>,
    workers: usize,
    cancel: &AtomicBool,
) -> Result<()> {
    // Runs are handed out in input order, so once run `i` is found bad every earlier run
    // has been handed out: no later one needs building.
    let next = AtomicUsize::new(range.start);
    let first_bad = AtomicUsize::new(usize::MAX);
    let bad = Mutex::new(Vec::new());
    on_workers(workers, cancel, || loop {
        let i = next.fetch_add(1, Ordering::Relaxed);
        if i >= range.end || i > first_bad.load(Ordering::Relaxed) || cancel.load(Ordering::Relaxed)
        {
            return;
        }
        if let Err(e) = src.scene(i) {
            first_bad.fetch_min(i, Ordering::Relaxed);
            bad.lock().unwrap_or_else(|p| p.into_inner()).push((i, e));
        }
    });
    if cancel.load(Ordering::Relaxed) {
        return Err(GranrsError::Cancelled);
    }
    let bad = bad.into_inner().unwrap_or_else(|p| p.into_inner());
    match bad.into_iter().min_by_key(|(i, _)| *i) {
        None => Ok(()),
        Some((i, e)) => Err(in_run(i, e)),
    }
}

/// The table of a batch.
#[derive(Debug, Clone, PartialEq)]
pub struct BatchOut {
    /// Column names.
    pub columns: Vec<String>,
    /// Row-major values, `rows x columns.len()`.
    pub data: Vec<f64>,
    /// Runs that failed, by index within the batch, with their messages.
    pub failures: Vec<(usize, String)>,
    /// Runs with a contact whose result the step did not resolve (`unresolved_stops` > 0,
    /// which every run computes whatever its outputs: see `Needs::ALWAYS`), by index within
    /// the batch, in order: what the sweep's step-size warning reads when its columns do
    /// not hold `unresolved_stops`.
    pub unresolved: Vec<usize>,
    /// Whether the batch was cancelled before every run finished.
    pub cancelled: bool,
}

/// How a batch runs its scenes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Path {
    /// Free-link scenes (under any terms) four at a time in SIMD lanes (`integrate::lanes`, with AVX2 where the
    /// CPU has it), every other scene alone. The default; the results are the scalar path's
    /// bit for bit.
    Lanes,
    /// Every scene alone, on the scalar path (for tests and benchmarks).
    Scalar,
}

/// The rows of a batch's table, shared by the threads that fill them: each row is written
/// by the one lane that was handed its scene (an atomic counter hands out each once).
struct Rows {
    ptr: *mut f64,
    width: usize,
    len: usize,
}

// SAFETY: the threads write disjoint rows (`Rows::row`'s contract); the table outlives them.
unsafe impl Sync for Rows {}

impl Rows {
    fn new(data: &mut [f64], width: usize) -> Self {
        Rows {
            ptr: data.as_mut_ptr(),
            width,
            len: data.len() / width.max(1),
        }
    }

    /// Row `j`.
    ///
    /// # Safety
    /// No other reference to row `j` may be alive while the returned one is.
    #[allow(clippy::mut_from_ref)]
    unsafe fn row(&self, j: usize) -> &mut [f64] {
        assert!(j < self.len, "row {j} of {}", self.len);
        // SAFETY: in bounds (above); exclusive by the caller's contract.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(j * self.width), self.width) }
    }
}

/// Run every scene in `range` on `workers` threads of the current rayon pool (call inside
/// `pool.install` or a job of the pool; see [`on_workers`]). `done` counts finished runs;
/// setting `cancel` stops the batch: the runs in flight stop within a few milliseconds
/// ([`crate::integrate::cancel`]) and every run not finished gets status
/// [`STATUS_CANCELLED`]. Validate first: a run whose scene does not build is recorded as
/// failed. `path` chooses the lanes or the scalar path.
pub fn run(
    src: &Source,
    range: std::ops::Range<usize>,
    workers: usize,
    done: &AtomicUsize,
    cancel: &AtomicBool,
    path: Path,
) -> BatchOut {
    let shape = src.shape();
    // (`sweep` checks the outputs before it runs anything.)
    let columns = columns(shape, src.outputs().unwrap_or_default());
    let width = columns.len();
    let start = range.start;
    let mut data = vec![f64::NAN; range.len() * width];
    let failures = Mutex::new(Vec::new());
    let unresolved = Mutex::new(Vec::new());
    // A run's row, and whether the step resolved its contacts.
    let summarize = |i: usize, out: &Outcome, row: &mut [f64]| {
        summarize(out, row);
        if out.stats.unresolved_stops > 0 {
            unresolved.lock().unwrap_or_else(|p| p.into_inner()).push(i);
        }
    };
    let fail = |i: usize, row: &mut [f64], e: GranrsError| {
        if let GranrsError::Cancelled = e {
            row.fill(f64::NAN);
            row[0] = STATUS_CANCELLED;
            return;
        }
        row[0] = STATUS_FAILED;
        failures
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .push((i, e.to_string()));
    };
    let n = range.len();
    let rows = Rows::new(&mut data, width);
    // The lanes take one-link bodies (every scene of a batch has its body's shape); a body
    // of several links runs on the scalar path.
    if path == Path::Lanes && shape.1 == 0 {
        let isa = LaneIsa::detect();
        // Every thread runs its own four lanes and takes the batch's next scene whenever a
        // lane frees: no thread waits on another's tail, and no lane idles until the batch
        // runs out (with fixed chunks, each chunk's last steps ran with idle lanes).
        let next_scene = AtomicUsize::new(0);
        on_workers(workers, cancel, || {
            let next = || -> Option<LaneScene<usize>> {
                loop {
                    let j = next_scene.fetch_add(1, Ordering::Relaxed);
                    if j >= n {
                        return None;
                    }
                    // SAFETY: `next_scene` hands each scene to one lane of one thread once.
                    let row = unsafe { rows.row(j) };
                    if cancel.load(Ordering::Relaxed) {
                        row[0] = STATUS_CANCELLED;
                        continue;
                    }
                    match src.scene(start + j) {
                        // A one-link body without a clock (no joint, so no table) goes to
                        // the lanes, which take it where they cover its model
                        // ([`run_lanes`]).
                        Ok(scene) if scene.size() == 1 => {
                            let (q0, qd0) = scene.initial_state::<3>();
                            return Some((j, scene.model::<3>(), q0, qd0, scene.options));
                        }
                        // Built, so validated ([`Source::scene`]).
                        Ok(scene) => match scene.run_validated() {
                            Ok(out) => summarize(start + j, &out, row),
                            Err(e) => fail(start + j, row, e),
                        },
                        Err(e) => fail(start + j, row, e),
                    }
                    done.fetch_add(1, Ordering::Relaxed);
                }
            };
            let finished = |j: usize, out: Result<Outcome>| {
                // SAFETY: scene `j`'s row, written by the lane that ran it alone.
                let row = unsafe { rows.row(j) };
                match out {
                    Ok(out) => summarize(start + j, &out, row),
                    Err(e) => fail(start + j, row, e),
                }
                done.fetch_add(1, Ordering::Relaxed);
            };
            run_lanes(isa, next, finished);
        });
    } else {
        let next_run = AtomicUsize::new(0);
        on_workers(workers, cancel, || loop {
            let j = next_run.fetch_add(1, Ordering::Relaxed);
            if j >= n {
                return;
            }
            // SAFETY: `next_run` hands each row to one thread once.
            let row = unsafe { rows.row(j) };
            if cancel.load(Ordering::Relaxed) {
                row[0] = STATUS_CANCELLED;
                continue;
            }
            // Built, so validated ([`Source::scene`]).
            match src.scene(start + j).and_then(|s| s.run_validated()) {
                Ok(out) => summarize(start + j, &out, row),
                Err(e) => fail(start + j, row, e),
            }
            done.fetch_add(1, Ordering::Relaxed);
        });
    }
    let mut failures = failures.into_inner().unwrap_or_else(|p| p.into_inner());
    failures.sort_by_key(|(i, _)| *i);
    let mut unresolved = unresolved.into_inner().unwrap_or_else(|p| p.into_inner());
    unresolved.sort_unstable();
    BatchOut {
        columns,
        data,
        failures,
        unresolved,
        cancelled: cancel.load(Ordering::Relaxed),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::Value;

    fn base() -> SceneSpec {
        crate::spec::free_link_spec()
    }

    /// Numbers as the values of a sweep axis.
    fn num(v: &[f64]) -> Vec<Value> {
        v.iter().map(|&x| Value::Num(x)).collect()
    }

    /// Words as the values of a sweep axis.
    fn word(v: &[&'static str]) -> Vec<Value> {
        v.iter()
            .map(|&x| Value::Str(std::borrow::Cow::Borrowed(x)))
            .collect()
    }

    fn product() -> Source {
        Source::Product {
            base: base(),
            axes: vec![
                (
                    "q_deg".into(),
                    vec![Value::Num(0.0), Value::Num(30.0), Value::Num(-60.0)],
                ),
                ("v0".into(), vec![Value::Num(1.0), Value::Num(3.0)]),
            ],
        }
    }

    #[test]
    fn product_order_is_last_axis_fastest() {
        let src = product();
        assert_eq!(src.len(), 6);
        let s = src.spec(3);
        assert_eq!(s.f64("q_deg").unwrap(), 30.0);
        assert_eq!(s.f64("v0").unwrap(), 3.0);
        let s = src.spec(4);
        assert_eq!(s.f64("q_deg").unwrap(), -60.0);
        assert_eq!(s.f64("v0").unwrap(), 1.0);
    }

    #[test]
    fn parallel_rows_equal_single_runs_in_order() {
        let src = product();
        let done = AtomicUsize::new(0);
        let cancel = AtomicBool::new(false);
        let out = pool()
            .unwrap()
            .install(|| run(&src, 0..src.len(), 2, &done, &cancel, Path::Lanes));
        assert_eq!(done.load(Ordering::Relaxed), 6);
        let width = out.columns.len();
        let depth = out.columns.iter().position(|c| c == "c0.depth").unwrap();
        for i in 0..6 {
            let alone = src.spec(i).build().unwrap().run().unwrap();
            let mut row = vec![0.0; width];
            summarize(&alone, &mut row);
            assert_eq!(
                out.data[i * width..(i + 1) * width]
                    .iter()
                    .map(|x| x.to_bits())
                    .collect::<Vec<_>>(),
                row.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                "run {i}"
            );
            assert!(row[depth] > 0.0);
        }
    }

    /// The rows of a batch on `path`, as bits.
    fn rows_bits(src: &Source, path: Path) -> Vec<u64> {
        let done = AtomicUsize::new(0);
        let cancel = AtomicBool::new(false);
        let out = pool()
            .unwrap()
            .install(|| run(src, 0..src.len(), 2, &done, &cancel, path));
        assert_eq!(done.load(Ordering::Relaxed), src.len());
        assert!(out.failures.is_empty(), "{:?}", out.failures);
        out.data.iter().map(|x| x.to_bits()).collect()
    }

    /// The lanes give the scalar path's rows bit for bit: scenes that end at different
    /// times (angles from -85 to 89 deg, speeds from 0.05 to 5 m/s, spins), that stick,
    /// slide and spin, that start in the sand, that end at `t_end` or at every stop, at
    /// the tip and at the centroid, under every sign model.
    #[test]
    fn lanes_rows_are_the_scalar_rows_bitwise() {
        let src = Source::Product {
            base: base(),
            axes: vec![
                ("apply_at".into(), word(&["tip", "centroid"])),
                ("sign_model".into(), word(&["modes", "raw", "smooth"])),
                (
                    "q_deg".into(),
                    num(&[-85.0, -30.0, 0.0, 5.0, 45.0, 75.0, 89.0]),
                ),
                ("v0".into(), num(&[0.05, 1.12, 2.214, 5.0])),
                ("omega0".into(), num(&[0.0, -7.0, 20.0])),
            ],
        };
        assert_eq!(rows_bits(&src, Path::Lanes), rows_bits(&src, Path::Scalar));
        let src = Source::Product {
            base: base(),
            axes: vec![
                ("end".into(), word(&["all_stops", "time"])),
                ("t_end".into(), num(&[0.004, 0.05])),
                ("depth0".into(), num(&[0.0, 0.03])),
                ("q_deg".into(), num(&[0.0, 15.0, 60.0])),
                ("vx0".into(), num(&[-1.0, 0.0, 0.4])),
            ],
        };
        assert_eq!(rows_bits(&src, Path::Lanes), rows_bits(&src, Path::Scalar));
    }

    /// The free link's lean steps (the lanes' arithmetic in `f64`, `Run::step`) give the
    /// outcome of the general rigid-rod path (`full_step` through `Model::eval`) bit for bit,
    /// under every sign model: every field of the outcome, summaries and counts.
    #[test]
    fn lean_steps_are_the_general_path_bitwise() {
        let src = Source::Product {
            base: base(),
            axes: vec![
                ("sign_model".into(), word(&["modes", "raw", "smooth"])),
                ("apply_at".into(), word(&["tip", "centroid"])),
                ("end".into(), word(&["first_stop", "all_stops"])),
                ("depth0".into(), num(&[0.0, 0.03])),
                (
                    "q_deg".into(),
                    num(&[-85.0, -30.0, 0.0, 5.0, 45.0, 75.0, 89.0]),
                ),
                ("v0".into(), num(&[0.05, 1.12, 2.214, 5.0])),
                ("omega0".into(), num(&[0.0, -7.0, 20.0])),
            ],
        };
        let mut lean_steps = 0;
        for i in 0..src.len() {
            let Ok(s) = src.spec(i).build() else {
                panic!("run {i} does not build");
            };
            let lean = crate::dynamics::rod_lanes::lean_equals_general(&s, &format!("run {i}"));
            lean_steps += lean.stats.steps;
        }
        assert!(lean_steps > 100_000, "{lean_steps} steps");
    }

    /// A batch whose runs ask for some outputs has those columns only (`status` first), and
    /// their values are the full batch's bit for bit, on the lanes and the scalar path,
    /// under the thesis's terms and under frame laws (whose runs the lanes then accept
    /// plain steps of: nothing reads the terms' own stiffness).
    #[test]
    fn fewer_outputs_are_the_full_rows_columns_bitwise() {
        use crate::forces::TermSpec;
        let names: Vec<std::borrow::Cow<'static, str>> =
            vec!["depth".into(), "t_s".into(), "F_d_max".into()];
        for forces in [
            None,
            Some(vec![
                TermSpec::new("gravity", &[]),
                TermSpec::new("rft", &[("zeta", 1e6)]),
            ]),
            Some(vec![
                TermSpec::new("gravity", &[]),
                TermSpec::new("poncelet", &[("c", 0.8), ("k", 150.0)]),
            ]),
        ] {
            let mut full = base();
            if let Some(terms) = forces {
                full.set("forces", Value::Terms(terms));
            }
            let axes = vec![
                ("q_deg".into(), num(&[-60.0, 0.0, 5.0, 45.0, 85.0])),
                ("v0".into(), num(&[0.5, 2.214, 4.0])),
                ("vx0".into(), num(&[0.0, 0.4])),
            ];
            let full = Source::Product { base: full, axes };
            let mut lean = full.clone();
            lean.set_outputs(names.clone()).unwrap();
            let all = columns(full.shape(), Outputs::ALL);
            let some = columns(lean.shape(), lean.outputs().unwrap());
            assert_eq!(some, ["status", "c0.t_s", "c0.depth", "c0.F_d_max"]);
            let want = rows_bits(&full, Path::Scalar);
            for path in [Path::Lanes, Path::Scalar] {
                let got = rows_bits(&lean, path);
                for (r, row) in got.chunks(some.len()).enumerate() {
                    for (c, name) in some.iter().enumerate() {
                        let k = all.iter().position(|a| a == name).unwrap();
                        assert_eq!(row[c], want[r * all.len() + k], "{path:?} run {r} {name}");
                    }
                }
            }
        }
    }

    /// What a run's outputs leave out is not computed: the parts of the observation only
    /// those fields need are left at their start (NaN or 0), while the steps' error
    /// estimate, which every run computes (`Needs::ALWAYS`), is there.
    #[test]
    fn fields_left_out_are_not_computed() {
        let mut spec = base();
        spec.set("outputs", Value::Names(vec!["depth".into(), "t_s".into()]));
        let lean = spec.build().unwrap().run().unwrap();
        let full = base().build().unwrap().run().unwrap();
        let (c, f) = (&lean.contacts[0], &full.contacts[0]);
        assert_eq!(
            (c.depth.to_bits(), c.t_s.to_bits()),
            (f.depth.to_bits(), f.t_s.to_bits())
        );
        assert!(lean.h_lambda.is_nan() && full.h_lambda > 0.0);
        assert!(c.f_d_max == 0.0 && f.f_d_max > 0.0);
        assert!(c.d_ke.is_nan() && c.link_d_ke.is_nan() && f.d_ke.is_finite());
        assert_eq!(lean.stats, full.stats);
        assert!(lean.step_error.is_finite());
        assert_eq!(lean.step_error.to_bits(), full.step_error.to_bits());
    }

    #[test]
    fn validation_names_the_first_bad_run() {
        let src = Source::Product {
            base: base(),
            axes: vec![(
                "mass".into(),
                vec![Value::Num(1.0), Value::Num(-1.0), Value::Num(f64::NAN)],
            )],
        };
        match validate(&src, 0..3, 2, &AtomicBool::new(false)) {
            Err(GranrsError::InvalidParameter { field, allowed, .. }) => {
                assert_eq!(field, "mass");
                assert!(allowed.ends_with("in run 1"), "{allowed}");
            }
            other => panic!("{other:?}"),
        }
    }

    /// A batch of runs that each take minutes, cancelled from another thread: every run,
    /// in flight or not, stops within milliseconds with status cancelled (no failure), on
    /// both paths. Before, a cancelled batch waited for its runs in flight.
    #[test]
    fn cancelling_a_batch_stops_the_runs_in_flight() {
        for path in [Path::Lanes, Path::Scalar] {
            let mut long = base();
            long.set("end", Value::Str(std::borrow::Cow::Borrowed("time")));
            long.set("t_end", Value::Num(1e3));
            long.set("dt", Value::Num(1e-5));
            let src = Source::Product {
                base: long,
                axes: vec![("v0".into(), num(&[1.0, 2.0, 3.0, 4.0, 5.0]))],
            };
            let done = AtomicUsize::new(0);
            let cancel = AtomicBool::new(false);
            let t0 = std::time::Instant::now();
            let out = std::thread::scope(|s| {
                s.spawn(|| {
                    std::thread::sleep(std::time::Duration::from_millis(100));
                    cancel.store(true, Ordering::Relaxed);
                });
                pool()
                    .unwrap()
                    .install(|| run(&src, 0..src.len(), 2, &done, &cancel, path))
            });
            let took = t0.elapsed();
            assert!(took.as_secs_f64() < 2.0, "{path:?}: stopped after {took:?}");
            assert!(out.cancelled);
            assert!(out.failures.is_empty(), "{:?}", out.failures);
            assert!(out
                .data
                .chunks(out.columns.len())
                .all(|r| r[0] == STATUS_CANCELLED));
        }
    }

    /// Validation stops when cancelled, with [`GranrsError::Cancelled`].
    #[test]
    fn a_cancelled_validation_stops() {
        let src = product();
        let cancel = AtomicBool::new(true);
        let out = pool()
            .unwrap()
            .install(|| validate(&src, 0..src.len(), 2, &cancel));
        assert!(matches!(out, Err(GranrsError::Cancelled)), "{out:?}");
    }

    /// The one pool has a thread per core; a batch asks for at most that many.
    #[test]
    fn the_pool_is_one_thread_per_core_and_shared() {
        let pool = pool().unwrap();
        assert_eq!(pool.current_num_threads(), cores());
        assert!(Arc::ptr_eq(&pool, &super::pool().unwrap()));
        assert_eq!(workers(&pool, 0), cores());
        assert_eq!(workers(&pool, 1), 1);
        assert_eq!(workers(&pool, 1000), cores());
    }

    #[test]
    fn a_cancelled_batch_marks_what_it_did_not_run() {
        let src = product();
        let done = AtomicUsize::new(0);
        let cancel = AtomicBool::new(true);
        let out = run(&src, 0..src.len(), 2, &done, &cancel, Path::Lanes);
        assert!(out.cancelled);
        assert_eq!(done.load(Ordering::Relaxed), 0);
        assert!(out
            .data
            .chunks(out.columns.len())
            .all(|r| r[0] == STATUS_CANCELLED));
    }
}
