//! Step-size control (diffrax's step-size controllers): RK4's constant step on the fixed
//! grid `t_n = n dt`, or Dopri5's adaptive step from its error estimate.
//!
//! The grid is computed by multiplication, so that round-off never adds a step past `t_end`;
//! after an event the step to the next grid point is shortened.

use super::options::SolveOptions;
use super::outcome::Stats;
use super::stepper::Method;
use crate::error::{GranrsError, Result};

/// Where the run's steps end.
#[derive(Debug, Clone, Copy)]
pub(super) struct Control {
    /// Dopri5's adaptive step (else RK4's grid).
    adaptive: bool,
    /// The grid's step, and Dopri5's first [s].
    dt: f64,
    /// Latest end time [s].
    t_end: f64,
    /// Whole steps taken: on the grid, the grid points passed.
    n: u64,
    /// Grid points up to `t_end`.
    n_grid: u64,
    /// The adaptive step's next size [s].
    h: f64,
}

impl Control {
    /// The control of a run with `options`.
    pub(super) fn new(options: &SolveOptions) -> Self {
        Control {
            adaptive: matches!(options.method, Method::Dopri5 { .. }),
            dt: options.dt,
            t_end: options.t_end,
            n: 0,
            n_grid: (options.t_end / options.dt).ceil() as u64,
            h: options.dt,
        }
    }

    /// Whether the step adapts (Dopri5), else the grid (RK4).
    #[inline]
    pub(super) fn adaptive(&self) -> bool {
        self.adaptive
    }

    /// Make the next adaptive step of size `h`.
    #[inline]
    pub(super) fn retry(&mut self, h: f64) {
        self.h = h;
    }

    /// Whether the run has reached `t_end` at `t`.
    #[inline]
    pub(super) fn finished(&self, t: f64) -> bool {
        if self.adaptive {
            t >= self.t_end
        } else {
            self.n >= self.n_grid
        }
    }

    /// The end of the next step from `t`: the next grid point, or `t` plus the adaptive
    /// step (without leaving a sliver before `t_end`).
    #[inline]
    pub(super) fn next(&self, t: f64) -> f64 {
        if self.adaptive {
            let target = t + self.h;
            if target >= self.t_end || self.t_end - target < 1e-3 * self.h {
                self.t_end
            } else {
                target
            }
        } else {
            ((self.n + 1) as f64 * self.dt).min(self.t_end)
        }
    }

    /// Whether the step of size `h` to the next grid point is empty (an event landed on the
    /// grid point); then the run passes that point.
    #[inline]
    pub(super) fn landed(&mut self, h: f64) -> bool {
        if !self.adaptive && h <= 1e-12 * self.dt {
            self.n += 1;
            true
        } else {
            false
        }
    }

    /// The factor of the next adaptive step's size after one of error norm `err`.
    #[inline]
    fn factor(err: f64) -> f64 {
        if err == 0.0 {
            5.0
        } else {
            (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
        }
    }

    /// The shortest adaptive step [s].
    #[inline]
    fn floor(&self) -> f64 {
        1e-14 * self.t_end.max(1.0)
    }

    /// Whether [`Control::judge`] would reject a step of size `h` with error norm `err` and
    /// find the next one too short (a step size underflow).
    #[inline]
    pub(super) fn would_underflow(&self, h: f64, err: f64) -> bool {
        let next = h * Self::factor(err).min(0.9);
        self.adaptive && (err.is_nan() || err > 1.0) && (next.is_nan() || next <= self.floor())
    }

    /// Judge a step of size `h` from `t` with error norm `err`: accept it (true; the next
    /// adaptive step's size is set) or reject it (false; to be tried again, shorter). The
    /// grid accepts every step. An adaptive step that shrinks to nothing is an error.
    #[inline]
    pub(super) fn judge(&mut self, h: f64, err: f64, t: f64, stats: &mut Stats) -> Result<bool> {
        if !self.adaptive {
            return Ok(true);
        }
        let factor = Self::factor(err);
        if err.is_nan() || err > 1.0 {
            stats.rejected += 1;
            self.h = h * factor.min(0.9);
            if self.h.is_nan() || self.h <= self.floor() {
                return Err(GranrsError::NonFinite {
                    t,
                    message: format!("step size underflow at t = {t} s (error norm {err})"),
                });
            }
            return Ok(false);
        }
        self.h = h * factor;
        Ok(true)
    }

    /// A whole step was taken; returns how many so far (the recording stride counts them).
    #[inline]
    pub(super) fn advance(&mut self) -> u64 {
        self.n += 1;
        self.n
    }
}
