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
use super::drives::Drives;
use super::events::{self, Events, Landing, Span};
use super::observe::{Observer, Record};
use super::outcome::{Outcome, Stats, Status};
use super::stepper::{deriv_of, full_step, partial_step, Method, State};
use crate::dynamics::{Eval, Model};
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
    solve_driven(model, q0, qd0, options, &Drives::default())
}

/// [`solve`] with table-driven joints: a step ends on each of the tables' times (up to
/// `t_end`), where the rates take the impulse of the new segments. The run records the
/// state before and after each impulse (both at that time).
pub fn solve_driven<const N: usize>(
    model: &Model<N>,
    q0: SVector<f64, N>,
    qd0: SVector<f64, N>,
    options: &SolveOptions,
    drives: &Drives,
) -> Result<Outcome> {
    let mut stats = Stats::default();
    let mut y = State {
        q: q0,
        qd: qd0,
        work: 0.0,
        dissipated: 0.0,
    };
    let mut modes = events::initial_modes(model, &y, options.dt, &mut stats);
    let mut obs = Observer::new(model, &y, &modes, options.record);
    let mut control = Control::new(options);
    let mut events = Events::new();
    let mut t = 0.0f64;
    // The evaluations at the step's start (`evals[cur]`) and end: an accepted step swaps
    // their roles instead of copying (an `Eval` holds every contact's findings).
    let mut evals = [model.eval(&y.q, &y.qd, &modes); 2];
    let mut cur = 0usize;
    stats.rhs_evals += 1;
    obs.record(model, t, &y, &evals[cur], &modes);
    // The next time of the drive tables.
    let mut next_time = 0usize;

    let status = loop {
        // A time of the drive tables: the impulse onto the new segments.
        if let Some(tb) = drives.time(next_time) {
            if tb - t <= 1e-12 * options.dt {
                next_time += 1;
                obs.record_new(model, t, &y, &evals[cur], &modes);
                for (link, impulse, energy) in
                    model.drive_impulse(&y.q, &mut y.qd, &drives.targets(tb))
                {
                    obs.impulse(link, t, impulse, energy);
                }
                stats.events += 1;
                events.after_impulse(model, &mut modes, &y, &mut stats);
                model.eval_into(&y.q, &y.qd, &modes, &mut evals[cur]);
                stats.rhs_evals += 1;
                obs.record(model, t, &y, &evals[cur], &modes);
                continue;
            }
        }
        if control.finished(t) {
            break if options.end == EndCondition::Time {
                Status::EndTime
            } else {
                Status::NotStopped
            };
        }

        // Step: to the next grid point, or to a time of the drive tables before it.
        let grid = control.next(t);
        let (t_next, clamped) = match drives.time(next_time) {
            Some(tb) if tb < grid => (tb, true),
            _ => (grid, false),
        };
        let h = t_next - t;
        if !clamped && control.landed(h) {
            events.next_step();
            continue;
        }
        let (e0, e1) = start_and_end(&mut evals, cur);
        let k1 = deriv_of(&y, e0);
        let sample = |q: &SVector<f64, N>, s: &_| obs.offer(q, s);
        let (y1, err) = full_step(
            model,
            options.method,
            &modes,
            &y,
            &k1,
            h,
            e1,
            &mut stats,
            sample,
        );
        if !control.judge(h, err, t, &mut stats)? {
            continue;
        }
        let e1: &Eval<N> = e1;
        if !y1.is_finite() || !e1.qdd.iter().all(|v| v.is_finite()) {
            return Err(GranrsError::NonFinite {
                t,
                message: format!("state became non-finite in the step from t = {t} s (h = {h} s)"),
            });
        }

        // Detect.
        let span = Span {
            y0: &y,
            k1: &k1,
            e0,
            y1: &y1,
            e1,
            h,
        };
        let mut earliest = events.detect(model, &modes, &span, &mut stats);
        if events.none() {
            // Accept the whole step.
            y = y1;
            cur = 1 - cur;
            // `evals[cur]` is the step's end: it tells when the projection has nothing to do.
            if model.sticking_may_drift(&evals[cur], &modes)
                && model.project_sticking(&y.q, &mut y.qd, &modes)
            {
                stats.rhs_evals += 1;
                model.eval_into(&y.q, &y.qd, &modes, &mut evals[cur]);
            }
            t = t_next;
            stats.steps += 1;
            obs.step_end(model, &y, &evals[cur], &modes);
            if !clamped {
                let n = control.advance();
                events.next_step();
                obs.record_step(n, model, t, &y, &evals[cur], &modes);
            }
            continue;
        }

        // Handle: step to the earliest event, exactly (a real step of the located length),
        // and change the modes there.
        if options.method == Method::Rk4 {
            earliest = events.polish(model, &modes, &span, earliest, &mut stats);
        }
        let h_star = earliest * h;
        let y_star = if earliest >= 1.0 {
            y1
        } else if h_star > 0.0 {
            let sample = |q: &SVector<f64, N>, s: &_| obs.offer(q, s);
            partial_step(
                model,
                options.method,
                &modes,
                &y,
                &k1,
                h_star,
                &mut stats,
                sample,
            )
        } else {
            y
        };
        let t_star = if earliest >= 1.0 { t_next } else { t + h_star };
        let e_star = model.eval(&y_star.q, &y_star.qd, &modes);
        stats.rhs_evals += 1;
        if h_star > 0.0 {
            stats.steps += 1;
            obs.step_end(model, &y_star, &e_star, &modes);
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
        let terminal = events.handle(
            model,
            &mut modes,
            earliest,
            &at,
            options.end,
            &mut obs,
            &mut stats,
        );
        y = y_star;
        t = t_star;

        // Observe.
        if terminal {
            obs.record(model, t, &y, &e_star, &modes);
            break Status::Stopped;
        }
        model.project_sticking(&y.q, &mut y.qd, &modes);
        model.eval_into(&y.q, &y.qd, &modes, &mut evals[cur]);
        stats.rhs_evals += 1;
        obs.record(model, t, &y, &evals[cur], &modes);
    };
    obs.finish(model, status, t, &y, &modes, stats, options)
}
