//! The solve loop (REBOUND's `reb_simulation_step`): step, detect, handle, observe.
//!
//! Each piece is a file beside this one: the step ([`super::stepper`]: RK4 or Dopri5, its
//! end, error and dense output), where the steps end ([`super::control`]: RK4's fixed grid
//! `t_n = n dt` or Dopri5's adaptive step), the events ([`super::events`]: every
//! discontinuity of the force law, surface entry and exit, a sign switch, the end of a
//! stick, and every stop, located inside the step and restarted from exactly there), and
//! what the run keeps of itself ([`super::observe`]: summaries, series, `h_lambda`). An
//! event is an outcome, reported in [`Status`]; only a non-finite state is an error.

use nalgebra::SVector;

use super::cancel;
use super::control::Control;
use super::drives::Drives;
use super::events::{self, Events, Landing, Span};
use super::lane_step::{LaneContact, LaneEnd, LaneIsa, LaneStart};
use super::observe::Observer;
use super::options::{EndCondition, SolveOptions};
use super::outcome::{Outcome, Stats, Status};
use super::stepper::{deriv_of, full_step, partial_step, Deriv, Method, State};
use crate::dynamics::rod_lanes::{pivot_ok, RodEval, RodModes, RodParams};
use crate::dynamics::{Eval, Model, Modes};
use crate::error::{GranrsError, Result};

/// The evaluations at a step's start (`evals[cur]`) and the slot for its end.
#[inline]
fn start_and_end<const N: usize>(evals: &mut [Eval<N>; 2], cur: usize) -> (&Eval<N>, &mut Eval<N>) {
    let (head, tail) = evals.split_at_mut(1);
    if cur == 0 {
        (&head[0], &mut tail[0])
    } else {
        (&tail[0], &mut head[0])
    }
}

/// Run `model` from `y0` at `t = 0` with `options`.
pub fn solve<const N: usize>(
    model: &Model<N>,
    q0: SVector<f64, N>,
    qd0: SVector<f64, N>,
    options: &SolveOptions,
) -> Result<Outcome> {
    solve_driven(model, q0, qd0, options, Drives::default())
}

/// [`solve`] with table-driven joints: a step ends on each of the tables' times (up to
/// `t_end`), where the rates take the impulse of the new segments. The run records the
/// state before and after each impulse (both at that time).
pub fn solve_driven<const N: usize>(
    model: &Model<N>,
    q0: SVector<f64, N>,
    qd0: SVector<f64, N>,
    options: &SolveOptions,
    drives: Drives,
) -> Result<Outcome> {
    let mut run = Run::new(model, q0, qd0, options).with_drives(drives);
    while let Some(h) = run.next_step(model) {
        run.step(model, h)?;
    }
    run.finish(model)
}

/// One run between its steps: the loop's state, so that a caller can drive the steps. The
/// sweep's lanes ([`super::lanes`]) take each run's step start ([`Run::lane_start`]),
/// compute the stages of one step for several runs at once and hand each run its step's end
/// ([`Run::lane_step_done`]); everything else (the events, the observer, the step-size
/// control) is this run's own. A run's lean parameters come from the model it was started
/// with: every later call must pass that model.
pub struct Run<const N: usize> {
    options: SolveOptions,
    stats: Stats,
    y: State<N>,
    modes: Modes,
    obs: Observer<N>,
    control: Control,
    events: Events,
    t: f64,
    /// The evaluations at the step's start (`evals[cur]`) and end: an accepted step swaps
    /// their roles instead of copying (an `Eval` holds every contact's findings).
    evals: [Eval<N>; 2],
    cur: usize,
    /// How the run ended, once it has.
    status: Option<Status>,
    /// The table-driven joints (none for most runs).
    drives: Drives,
    /// The next of the drives' times.
    next_time: usize,
    /// The end of the step [`Run::next_step`] gave, and whether a time of the drives (not
    /// the grid) cut it there.
    t_next: f64,
    clamped: bool,
    /// The free link on RK4 ([`RodParams::of`]):
    /// its steps are the lanes' arithmetic in one lane ([`super::lanes::lane_step`] in
    /// `f64`), which reads only what a stage needs; `None` for every other run. Boxed: held
    /// in place its law (the term list) made the run's frame a kilobyte larger, and the
    /// steps of a lone run about 9 % slower (measured through `granrs.simulate`).
    lean: Option<Box<RodParams<f64>>>,
    /// How this CPU runs a lean step: compiled with AVX2 where it has it (one binary for
    /// every x86-64; the same IEEE operations, so the same bits).
    isa: LaneIsa,
    /// Whether the lanes accepted this run's last step ([`Run::accept_plain`]) and keep its
    /// end's evaluation: the run must [`Run::resume`] it before it steps itself.
    in_lanes: bool,
    /// Steps until the run next looks at its thread's watch ([`cancel::look`]).
    look_in: u32,
    /// Whether the watch stopped the run ([`Run::finish`] then gives
    /// [`GranrsError::Cancelled`]).
    cancelled: bool,
}

impl<const N: usize> Run<N> {
    /// Start `model` from `(q0, qd0)` at `t = 0` with `options`.
    pub fn new(
        model: &Model<N>,
        q0: SVector<f64, N>,
        qd0: SVector<f64, N>,
        options: &SolveOptions,
    ) -> Self {
        let mut stats = Stats::default();
        let y = State {
            q: q0,
            qd: qd0,
            work: 0.0,
            dissipated: 0.0,
        };
        let modes = events::initial_modes(model, &y, options.dt, &mut stats);
        let mut obs = Observer::new(model, &y, &modes, options);
        let control = Control::new(options);
        let events = Events::new();
        let t = 0.0f64;
        let evals = [model.eval(&y.q, &y.qd, &modes); 2];
        stats.rhs_evals += 1;
        obs.record(model, t, &y, &evals[0], &modes);
        Run {
            options: *options,
            stats,
            y,
            modes,
            obs,
            control,
            events,
            t,
            evals,
            cur: 0,
            status: None,
            drives: Drives::default(),
            next_time: 0,
            t_next: 0.0,
            clamped: false,
            lean: match options.method {
                Method::Rk4 => RodParams::of(model).map(Box::new),
                Method::Dopri5 { .. } => None,
            },
            isa: LaneIsa::detect(),
            in_lanes: false,
            look_in: cancel::FIRST_LOOK,
            cancelled: false,
        }
    }

    /// The same run with every step on the general path ([`super::stepper::full_step`]):
    /// the reference the lean steps are held to, bit for bit (tests).
    pub fn general(mut self) -> Self {
        self.lean = None;
        self
    }

    /// The same run with table-driven joints.
    pub fn with_drives(mut self, drives: Drives) -> Self {
        self.drives = drives;
        self
    }

    /// The size of the next step, or `None` when the run has ended ([`Run::finish`]).
    #[inline(always)]
    pub fn next_step(&mut self, model: &Model<N>) -> Option<f64> {
        if self.status.is_some() {
            return None;
        }
        // Now and then, whether whoever started the run wants it stopped: one decrement a
        // step.
        self.look_in -= 1;
        if self.look_in == 0 && self.look() {
            return None;
        }
        loop {
            // A time of the drive tables: the impulse onto the new segments.
            if let Some(tb) = self.drives.time(self.next_time) {
                if tb - self.t <= 1e-12 * self.options.dt {
                    self.drive_impulse(model);
                    continue;
                }
            }
            if self.control.finished(self.t) {
                self.status = Some(if self.options.end == EndCondition::Time {
                    Status::EndTime
                } else {
                    Status::NotStopped
                });
                return None;
            }
            // Step: to the next grid point, or to a time of the drive tables before it.
            let grid = self.control.next(self.t);
            let (t_next, clamped) = match self.drives.time(self.next_time) {
                Some(tb) if tb < grid => (tb, true),
                _ => (grid, false),
            };
            let h = t_next - self.t;
            if !clamped && self.control.landed(h) {
                self.events.next_step();
                continue;
            }
            self.t_next = t_next;
            self.clamped = clamped;
            return Some(h);
        }
    }

    /// Look at the thread's watch ([`cancel::look`]): whether the run is to stop (then it
    /// has ended, cancelled), and when to look next.
    #[cold]
    #[inline(never)]
    fn look(&mut self) -> bool {
        let (stop, next) = cancel::look();
        self.look_in = next.max(1);
        if stop {
            self.cancelled = true;
            self.status = Some(Status::NotStopped);
        }
        stop
    }

    /// At a time of the drive tables: the rates take the impulse onto the new segments.
    #[cold]
    fn drive_impulse(&mut self, model: &Model<N>) {
        let tb = self.drives.time(self.next_time).unwrap_or(self.t);
        self.next_time += 1;
        let (t, y, modes) = (self.t, &mut self.y, &mut self.modes);
        let e = &mut self.evals[self.cur];
        self.obs.record_new(model, t, y, e, modes);
        for (link, impulse, energy) in
            model.drive_impulse(&y.q, &mut y.qd, &self.drives.targets(tb))
        {
            self.obs.impulse(link, t, impulse, energy);
        }
        self.stats.events += 1;
        self.events.after_impulse(model, modes, y, &mut self.stats);
        model.eval_into(&y.q, &y.qd, modes, e);
        self.stats.rhs_evals += 1;
        self.obs.record(model, t, y, e, modes);
    }

    /// Take a whole step of size `h` (from [`Run::next_step`]) on the scalar path.
    #[inline(always)]
    pub fn step(&mut self, model: &Model<N>, h: f64) -> Result<()> {
        if let Some(p) = &self.lean {
            if let Some((start, m, k1)) = self.lane_start(h) {
                let end = self.isa.step(&**p, &m, &start);
                if let Some(done) = self.lane_step_done(model, h, &k1, &end) {
                    return done;
                }
            }
        }
        self.step_general(model, h)
    }

    /// [`Run::step`] on the general path ([`super::stepper::full_step`]): a step the lean
    /// path does not cover (two sticking rows, a sticking pivot that is not clear).
    #[inline(always)]
    pub fn step_general(&mut self, model: &Model<N>, h: f64) -> Result<()> {
        debug_assert!(!self.in_lanes, "resume the run first");
        let (e0, e1) = start_and_end(&mut self.evals, self.cur);
        let k1 = deriv_of(&self.y, e0);
        let obs = &mut self.obs;
        let sample = |q: &SVector<f64, N>, s: &_| obs.offer(|| *q, s);
        let (y1, err, k4) = full_step(
            model,
            self.options.method,
            &self.modes,
            &self.y,
            &k1,
            h,
            e1,
            &mut self.stats,
            sample,
        );
        self.after_step(model, h, &k1, y1, err, k4.as_ref())
    }

    /// The start of a step of size `h` in one lane ([`super::lanes::lane_step`]): the state
    /// and first stage, the modes held through it, and the first stage as a [`Deriv`] (for
    /// [`Run::lane_step_done`]); `None` when the lanes do not cover this run or its modes.
    #[inline(always)]
    pub fn lane_start(&self, h: f64) -> Option<(LaneStart<f64>, RodModes<f64>, Deriv<N>)> {
        debug_assert!(!self.in_lanes, "resume the run first");
        let m = RodModes::of(&self.modes[0], self.lean.as_ref()?)?;
        let (y, k1) = (&self.y, deriv_of(&self.y, &self.evals[self.cur]));
        let start = LaneStart {
            q: [y.q[0], y.q[1], y.q[2]],
            qd: [y.qd[0], y.qd[1], y.qd[2]],
            work: y.work,
            dissipated: y.dissipated,
            qdd1: [k1.qd[0], k1.qd[1], k1.qd[2]],
            power1: k1.work,
            joint_power1: k1.dissipated,
            h,
        };
        Some((start, m, k1))
    }

    /// A step of size `h` whose first stage is `k1` taken in the lanes (`end`, this run's
    /// lane): the observer is shown its stages, its end evaluation takes the end slot, and
    /// [`Run::after_step`] does the rest. `None` (nothing done) when a sticking pivot was not
    /// clear: the scalar path must take the step.
    #[inline(always)]
    pub fn lane_step_done(
        &mut self,
        model: &Model<N>,
        h: f64,
        k1: &Deriv<N>,
        end: &LaneEnd<f64>,
    ) -> Option<Result<()>> {
        if !end.pivots_ok() {
            return None;
        }
        if self.obs.wants_stiffness() {
            for k in 0..3 {
                let (q, stiff) = end.stage::<N>(k);
                self.obs.offer(|| q, &stiff);
            }
        }
        end.eval.write(&mut self.evals[1 - self.cur]);
        self.stats.rhs_evals += 4;
        Some(self.after_step(model, h, k1, end.state(), 0.0, Some(&end.k4())))
    }

    /// The rest of a step of size `h` whose first stage is `k1`, whose end is `y1` (its
    /// evaluation in the end slot, `evals[1 - cur]`) and whose error estimate is `err` (0 for RK4):
    /// the step-size control, the events (located, and the step cut there), the observer.
    /// `k4` is RK4's fourth stage (for the step's error estimate; `None` for Dopri5).
    #[inline(always)]
    pub fn after_step(
        &mut self,
        model: &Model<N>,
        h: f64,
        k1: &Deriv<N>,
        y1: State<N>,
        err: f64,
        k4: Option<&Deriv<N>>,
    ) -> Result<()> {
        debug_assert!(!self.in_lanes, "resume the run first");
        let options = &self.options;
        let stats = &mut self.stats;
        let obs = &mut self.obs;
        let modes = &mut self.modes;
        let events = &mut self.events;
        let control = &mut self.control;
        let (y, t, cur) = (&mut self.y, &mut self.t, &mut self.cur);
        let (t_next, clamped) = (self.t_next, self.clamped);
        let (e0, e1) = start_and_end(&mut self.evals, *cur);
        let e1: &Eval<N> = e1;
        let finite = y1.is_finite() && e1.qdd.iter().all(|v| v.is_finite());
        let span = Span {
            y0: y,
            k1,
            e0,
            y1: &y1,
            e1,
            h,
        };
        // An adaptive step that fails its error test however short it gets, across an event:
        // the force law may jump there (a sole's drag at the surface), which no step across it
        // resolves. Rather than give up, step to the event, located on this step of the
        // shortest size the control allows, and handle it there.
        let mut to_event = None;
        if control.adaptive() && finite && control.would_underflow(h, err) {
            let earliest = events.detect(model, modes, &span, stats);
            if !events.none() && earliest < 1.0 {
                stats.rejected += 1;
                let h_star = earliest * h;
                let y_star = if h_star > 0.0 {
                    let sample = |q: &SVector<f64, N>, s: &_| obs.offer(|| *q, s);
                    // Dopri5 only (the adaptive step): no RK4 error estimate.
                    partial_step(model, options.method, modes, y, k1, h_star, stats, sample).0
                } else {
                    *y
                };
                // The next step starts at the shortest size again.
                control.retry(h);
                to_event = Some((earliest, y_star));
            }
        }
        let (mut earliest, y_to_event) = match to_event {
            Some((earliest, y_star)) => (earliest, Some(y_star)),
            None => {
                if !control.judge(h, err, *t, stats)? {
                    return Ok(());
                }
                if !finite {
                    let t = *t;
                    return Err(GranrsError::NonFinite {
                        t,
                        message: format!(
                            "state became non-finite in the step from t = {t} s (h = {h} s)"
                        ),
                    });
                }
                // Detect.
                (events.detect(model, modes, &span, stats), None)
            }
        };
        if events.none() {
            // Accept the whole step.
            if let Some(k4) = k4 {
                obs.step_error(h, k4, &deriv_of(&y1, e1));
            }
            *y = y1;
            *cur = 1 - *cur;
            let evals = &mut self.evals;
            // `evals[cur]` is the step's end: it tells when the projection has nothing to do.
            if model.sticking_may_drift(&evals[*cur], modes)
                && model.project_sticking(&y.q, &mut y.qd, modes)
            {
                stats.rhs_evals += 1;
                model.eval_into(&y.q, &y.qd, modes, &mut evals[*cur]);
            }
            *t = t_next;
            stats.steps += 1;
            obs.step_end(model, y, &evals[*cur], modes);
            obs.sample_rates(model, y, modes);
            if !clamped {
                let n = control.advance();
                events.next_step();
                obs.record_step(n, model, *t, y, &evals[*cur], modes);
            }
            return Ok(());
        }

        // Handle: step to the earliest event, exactly (a real step of the located length),
        // and change the modes there.
        if options.method == Method::Rk4 {
            earliest = events.polish(model, modes, &span, earliest, stats);
        }
        let h_star = earliest * h;
        // The step to the event.
        let y_star = if let Some(y_star) = y_to_event {
            y_star
        } else if earliest >= 1.0 {
            y1
        } else if h_star > 0.0 {
            let sample = |q: &SVector<f64, N>, s: &_| obs.offer(|| *q, s);
            partial_step(model, options.method, modes, y, k1, h_star, stats, sample).0
        } else {
            *y
        };
        let t_star = if earliest >= 1.0 { t_next } else { *t + h_star };
        let e_star = model.eval(&y_star.q, &y_star.qd, modes);
        stats.rhs_evals += 1;
        if let (Some(k4), true) = (k4, h_star > 0.0) {
            // The whole step's estimate, not one read at the event (see `cut_step_error`).
            obs.cut_step_error(h, h_star.min(h), k4, &deriv_of(&y1, e1));
        }
        if h_star > 0.0 {
            stats.steps += 1;
            obs.step_end(model, &y_star, &e_star, modes);
            obs.sample_rates(model, &y_star, modes);
        }
        // An event at the very start of the step is judged at the step's end.
        let probe = if h_star <= 1e-12 * options.dt {
            y1
        } else {
            y_star
        };
        let at = Landing {
            t: t_star,
            y: &y_star,
            e: &e_star,
            probe: &probe,
            lookahead: &y1,
            t_lookahead: t_next,
        };
        let terminal = events.handle(model, modes, earliest, &at, options.end, obs, stats);
        *y = y_star;
        *t = t_star;

        // Observe.
        if terminal {
            obs.record(model, *t, y, &e_star, modes);
            self.status = Some(Status::Stopped);
            return Ok(());
        }
        model.project_sticking(&y.q, &mut y.qd, modes);
        model.eval_into(&y.q, &y.qd, modes, &mut self.evals[*cur]);
        stats.rhs_evals += 1;
        obs.record(model, *t, y, &self.evals[*cur], modes);
        Ok(())
    }

    /// Whether the lanes may accept this run's plain steps themselves ([`Run::accept_plain`]):
    /// a lean run, not ended, with no drive time ahead, no component held by a stick (whose
    /// projection an accepted step would need) and a step end that the observer reads only
    /// for the drag.
    #[inline]
    pub fn may_stay_in_lanes(&self, model: &Model<N>) -> bool {
        self.lean.is_some()
            && self.status.is_none()
            && self.drives.time(self.next_time).is_none()
            && !model.any_stuck(&self.modes)
            && self.obs.drag_only()
    }

    /// Accept the step (of the size [`Run::next_step`] gave) taken in lane `i` of `end` if it
    /// meets nothing, as [`Run::lane_step_done`] and [`Run::after_step`] would: every pivot
    /// clear, the end finite, no switching function crossed; then the observer is shown its
    /// stages and its end, and the run moves to the end. The end's evaluation stays in the
    /// lanes: the run must [`Run::resume`] it before it steps itself. Returns false, with
    /// nothing done, for any other step. Only for a run that
    /// [`Run::may_stay_in_lanes`].
    #[inline(always)]
    pub fn accept_plain(
        &mut self,
        model: &Model<N>,
        end: &LaneEnd<crate::num::F64x4>,
        i: usize,
    ) -> bool {
        debug_assert!(self.may_stay_in_lanes(model) && !self.clamped);
        // By reference, as `RodEval::lane`.
        let lane = |x: &crate::num::F64x4| x.0[i];
        if !(end.stages.iter().all(|st| pivot_ok(lane(&st.pivot)))
            && pivot_ok(lane(&end.eval.pivot)))
        {
            return false;
        }
        let y1 = State {
            q: SVector::from_fn(|k, _| lane(&end.q[k])),
            qd: SVector::from_fn(|k, _| lane(&end.qd[k])),
            work: lane(&end.work),
            dissipated: lane(&end.dissipated),
        };
        if !y1.is_finite() || !end.eval.qdd.iter().all(|a| lane(a).is_finite()) {
            return false;
        }
        if !self
            .events
            .plain(&self.modes, &LaneContact::new(&end.eval, i))
        {
            return false;
        }
        if self.obs.wants_stiffness() {
            for st in &end.stages {
                let (q, stiff) = st.seen_in_lane::<N>(i);
                self.obs.offer(q, &stiff);
            }
        }
        if self.obs.wants_step_error() {
            let k4 = Deriv {
                q: SVector::from_fn(|k, _| lane(&end.qd4[k])),
                qd: SVector::from_fn(|k, _| lane(&end.qdd4[k])),
                work: 0.0,
                dissipated: 0.0,
            };
            let k5 = Deriv {
                q: y1.qd,
                qd: SVector::from_fn(|k, _| lane(&end.eval.qdd[k])),
                work: 0.0,
                dissipated: 0.0,
            };
            self.obs.step_error(self.t_next - self.t, &k4, &k5);
        }
        self.stats.rhs_evals += 4;
        self.y = y1;
        self.t = self.t_next;
        self.stats.steps += 1;
        if !self.modes[0].stopped {
            let (_, stiff) = end.last.seen_in_lane::<N>(i);
            self.obs.drag_at(&self.y.q, &stiff);
        }
        self.control.advance();
        self.events.next_step();
        self.in_lanes = true;
        true
    }

    /// Take back a run whose last steps the lanes accepted ([`Run::accept_plain`]): `end` is
    /// the evaluation at its state, that of the last step's end.
    #[inline]
    pub fn resume(&mut self, end: &RodEval<f64>) {
        if self.in_lanes {
            end.write(&mut self.evals[self.cur]);
            self.in_lanes = false;
        }
    }

    /// The first stage of the next step: the derivative at the run's state.
    #[inline]
    pub fn first_stage(&self) -> Deriv<N> {
        debug_assert!(!self.in_lanes, "resume the run first");
        deriv_of(&self.y, &self.evals[self.cur])
    }

    /// Whether the lanes hold this run's last evaluation ([`Run::resume`]).
    #[inline]
    pub fn in_lanes(&self) -> bool {
        self.in_lanes
    }

    /// The outcome of a run that has ended ([`Run::next_step`] gave `None`), or
    /// [`GranrsError::Cancelled`] for a run its watch stopped.
    pub fn finish(self, model: &Model<N>) -> Result<Outcome> {
        debug_assert!(!self.in_lanes, "resume the run first");
        if self.cancelled {
            return Err(GranrsError::Cancelled);
        }
        let status = self.status.unwrap_or(Status::NotStopped);
        self.obs.finish(
            model,
            status,
            self.t,
            &self.y,
            &self.modes,
            self.stats,
            &self.options,
        )
    }
}
