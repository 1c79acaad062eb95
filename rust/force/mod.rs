//! Granular resistance-force laws. One file per law; each starts with its source.

pub mod resistance;

pub use resistance::{Coefficients, ForceComponents, Medium, RodContactState};
