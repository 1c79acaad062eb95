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

use super::control::Control;
use super::events::{self, Events, Landing, Span};
use super::observe::{Observer, Record};
use super::outcome::{Outcome, Stats, Status};
use super::stepper::{deriv_of, full_step, partial_step, Deriv, Method, State};
use crate::dynamics::{Eval, Model, Modes};
use crate::error::{GranrsError, Result};

/// When a run ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndCondition {
    /// At the first stop of any contact (the thesis's end of the penetration phase).
    FirstStop,
    /// When every contact has stopped.
    AllStops,
    /// At `t_end`, whatever happens before.
    Time,
}

/// Options of one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// Step size of the fixed grid [s] (thesis: 10 kHz, 1e-4 s); the first step of Dopri5.
    pub dt: f64,
    /// The time stepper.
    pub method: Method,
    /// Latest end time [s].
    pub t_end: f64,
    /// When to end.
    pub end: EndCondition,
    /// What to record.
    pub record: Record,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            dt: 1e-4,
            method: Method::Rk4,
            t_end: 1.0,
            end: EndCondition::FirstStop,
            record: Record::default(),
        }
    }
}

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
    let mut run = Run::new(model, q0, qd0, options);
    while let Some(h) = run.next_step() {
        run.step(model, h)?;
    }
    run.finish(model)
}

/// One run between its steps: the loop's state, so that a caller can drive the steps. The
/// sweep's lanes ([`super::lanes`]) compute the stages of one step for several runs at once
/// and hand each run its step's end ([`Run::end_eval`], [`Run::after_step`]); everything
/// else (the events, the observer, the step-size control) is this run's own.
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
        let mut obs = Observer::new(model, &y, &modes, options.record);
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
        }
    }

    /// The size of the next step, or `None` when the run has ended ([`Run::finish`]).
    #[inline]
    pub fn next_step(&mut self) -> Option<f64> {
        if self.status.is_some() {
            return None;
        }
        loop {
            if self.control.finished(self.t) {
                self.status = Some(if self.options.end == EndCondition::Time {
                    Status::EndTime
                } else {
                    Status::NotStopped
                });
                return None;
            }
            let h = self.control.next(self.t) - self.t;
            if self.control.landed(h) {
                self.events.next_step();
                continue;
            }
            return Some(h);
        }
    }

    /// The state at the step's start, its derivative there (the first stage) and the modes
    /// held through the step.
    #[inline]
    pub fn start(&self) -> (&State<N>, Deriv<N>, &Modes) {
        (
            &self.y,
            deriv_of(&self.y, &self.evals[self.cur]),
            &self.modes,
        )
    }

    /// The slot of the step's end evaluation, for a caller that computes the step itself.
    #[inline]
    pub fn end_eval(&mut self) -> &mut Eval<N> {
        &mut self.evals[1 - self.cur]
    }

    /// Show the run one RK4 stage's coordinates and the drag's stiffness there (see
    /// [`super::stepper::step_sampling`]), for a caller that computes the step itself.
    #[inline]
    pub fn offer(&mut self, q: &SVector<f64, N>, stiff: &crate::dynamics::DragStiffness) {
        self.obs.offer(q, stiff);
    }

    /// Count `n` evaluations of the right-hand side made for this run by its caller.
    #[inline]
    pub fn count_evals(&mut self, n: usize) {
        self.stats.rhs_evals += n;
    }

    /// Take a whole step of size `h` (from [`Run::next_step`]) on the scalar path.
    #[inline]
    pub fn step(&mut self, model: &Model<N>, h: f64) -> Result<()> {
        let (e0, e1) = start_and_end(&mut self.evals, self.cur);
        let k1 = deriv_of(&self.y, e0);
        let obs = &mut self.obs;
        let sample = |q: &SVector<f64, N>, s: &_| obs.offer(q, s);
        let (y1, err) = full_step(
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
        self.after_step(model, h, &k1, y1, err)
    }

    /// The rest of a step of size `h` whose first stage is `k1`, whose end is `y1` (its
    /// evaluation in [`Run::end_eval`]) and whose error estimate is `err` (0 for RK4):
    /// the step-size control, the events (located, and the step cut there), the observer.
    #[inline]
    pub fn after_step(
        &mut self,
        model: &Model<N>,
        h: f64,
        k1: &Deriv<N>,
        y1: State<N>,
        err: f64,
    ) -> Result<()> {
        let options = &self.options;
        let stats = &mut self.stats;
        let obs = &mut self.obs;
        let modes = &mut self.modes;
        let events = &mut self.events;
        let control = &mut self.control;
        let (y, t, cur) = (&mut self.y, &mut self.t, &mut self.cur);
        let t_next = control.next(*t);
        if !control.judge(h, err, *t, stats)? {
            return Ok(());
        }
        let (e0, e1) = start_and_end(&mut self.evals, *cur);
        let e1: &Eval<N> = e1;
        if !y1.is_finite() || !e1.qdd.iter().all(|v| v.is_finite()) {
            let t = *t;
            return Err(GranrsError::NonFinite {
                t,
                message: format!("state became non-finite in the step from t = {t} s (h = {h} s)"),
            });
        }

        // Detect.
        let span = Span {
            y0: y,
            k1,
            e0,
            y1: &y1,
            e1,
            h,
        };
        let mut earliest = events.detect(model, modes, &span, stats);
        if events.none() {
            // Accept the whole step.
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
            let n = control.advance();
            events.next_step();
            stats.steps += 1;
            obs.step_end(model, y, &evals[*cur], modes);
            obs.record_step(n, model, *t, y, &evals[*cur], modes);
            return Ok(());
        }

        // Handle: step to the earliest event, exactly (a real step of the located length),
        // and change the modes there.
        if options.method == Method::Rk4 {
            earliest = events.polish(model, modes, &span, earliest, stats);
        }
        let h_star = earliest * h;
        let y_star = if earliest >= 1.0 {
            y1
        } else if h_star > 0.0 {
            let sample = |q: &SVector<f64, N>, s: &_| obs.offer(q, s);
            partial_step(model, options.method, modes, y, k1, h_star, stats, sample)
        } else {
            *y
        };
        let t_star = if earliest >= 1.0 { t_next } else { *t + h_star };
        let e_star = model.eval(&y_star.q, &y_star.qd, modes);
        stats.rhs_evals += 1;
        if h_star > 0.0 {
            stats.steps += 1;
            obs.step_end(model, &y_star, &e_star, modes);
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

    /// The outcome of a run that has ended ([`Run::next_step`] gave `None`).
    pub fn finish(self, model: &Model<N>) -> Result<Outcome> {
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
