//! Time integration, one file per piece (after diffrax and REBOUND): the loop itself
//! ([`solve`](mod@solve): step, detect, handle, observe), the step ([`stepper`]: RK4 and
//! Dopri5, dense output), where the steps end ([`control`]), the events ([`events`]), what
//! the run keeps of itself ([`observe`]) and what it returns ([`outcome`], with the one
//! table of output fields [`OUTCOME_FIELDS`]), and how a run is stopped from outside
//! ([`cancel`]).

pub mod cancel;
pub mod control;
pub mod drives;
pub mod events;
pub mod lane_step;
pub mod lanes;
pub mod observe;
pub mod options;
pub mod outcome;
pub mod solve;
pub mod stepper;

pub use drives::Drives;
pub use observe::{DIVERGENCE_FACTOR, RK4_STABILITY_LIMIT};
pub use options::{EndCondition, Record, SolveOptions};
pub use outcome::{
    ContactSummary, Field, FieldValue, Impulse, JointSummary, Needs, Outcome, OutcomeFields,
    Outputs, Series, Stats, Status, OUTCOME_FIELDS,
};
pub use solve::{solve, solve_driven, Run};
pub use stepper::{Method, RTOL_MIN};
