//! Time integration: the fixed-step RK4, its cubic Hermite dense output, event location
//! and the solve loop.

pub mod dense;
pub mod rk4;
pub mod solve;

pub use solve::{
    solve, ContactSummary, EndCondition, JointSummary, Method, Outcome, Record, Series,
    SolveOptions, Stats, Status,
};
