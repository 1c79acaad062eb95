//! A run's options: the step, the stepper, when it ends, what it records and which output
//! fields it returns. The ground floor of `integrate`: every other file of it reads these,
//! and they read only the stepper's [`Method`] and the set of output fields, [`Outputs`].

use super::outcome::Outputs;
use super::stepper::Method;

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
    /// Which output fields to compute and return (default: all).
    pub outputs: Outputs,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            dt: 1e-4,
            method: Method::Rk4,
            t_end: 1.0,
            end: EndCondition::FirstStop,
            record: Record::default(),
            outputs: Outputs::ALL,
        }
    }
}

/// What to record as time series. Nothing is stored for a field that is off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Record {
    /// Generalized coordinates and rates, and the work of the sand.
    pub state: bool,
    /// Per contact: tip position and velocity, depth, and the four force components.
    pub forces: bool,
    /// Kinetic and potential energy.
    pub energy: bool,
    /// Record every `stride`-th grid step (events are always recorded). 0 means 1.
    pub stride: usize,
}

impl Record {
    /// Whether anything is recorded.
    pub fn any(&self) -> bool {
        self.state || self.forces || self.energy
    }
}
