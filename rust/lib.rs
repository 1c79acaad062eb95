//! granrs: rods, linkages and feet sinking into sand.
//!
//! The Rust core of the `granrs` Python package: the granular resistance force of the
//! thesis "Bipedal impact with granular matter" (dynamic drag plus static depth-dependent
//! terms, see [`forces`]), planar articulated bodies ([`body`]), and a fixed-step RK4 with
//! exact event handling ([`integrate`]). `shared/MODEL.md` fixes the frame and the reading of
//! the thesis used throughout.
//!
//! The Python bindings live in `python/` behind the `python` cargo feature, so that
//! `cargo test` needs no Python.

pub mod batch;
pub mod bodies;
pub mod body;
pub mod dynamics;
pub mod error;
pub mod evaluate;
pub mod fields;
pub mod forces;
pub mod integrate;
pub mod num;
pub mod presets;
pub mod space;
pub mod spec;

#[cfg(feature = "python")]
mod python;

pub use error::{GranrsError, Result};
