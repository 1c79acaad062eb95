//! The Python module `granrs._granrs`: the only place that says `use pyo3`.
//!
//! Scenes arrive as plain dicts built by `granrs.Scene.to_dict()`, are converted to owned
//! Rust values and validated while the GIL is held, and run with the GIL released. Every
//! [`GranrsError`](crate::GranrsError) becomes an instance of the matching class of
//! `granrs.errors`, so that the Python and Rust layers share one exception tree.
//!
//! One file per part: `convert.rs` (Python values to spec values), `errors.rs` (the
//! exception conversion), `run.rs` (compile and run one scene), `sweep.rs` (batches),
//! `force.rs` (`resistance_force`), `mujoco.rs` (`SandGeoms`, for `granrs.mujoco`),
//! `space.rs` (bodies in space, for `granrs.space`) and `terms.rs` (the force terms'
//! registry). This file only registers them.

/// A dict of `key: value` pairs (each value converted with `IntoPyObject`), or the error of
/// the first that does not convert: the one way a core value becomes a Python dict here.
macro_rules! py_dict {
    ($py:expr, { $($k:literal: $v:expr),* $(,)? }) => {{
        let d = pyo3::types::PyDict::new($py);
        $(d.set_item($k, $v)?;)*
        d
    }};
}

mod convert;
mod errors;
mod force;
mod mujoco;
mod run;
mod space;
mod sweep;
mod terms;

use pyo3::prelude::*;

use crate::spec::{effects, RECORDS, SCENE_FIELDS};

#[pymodule]
fn _granrs(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run::compile, m)?)?;
    m.add_function(wrap_pyfunction!(run::compile_fields, m)?)?;
    m.add_function(wrap_pyfunction!(run::compiled_scene, m)?)?;
    m.add_function(wrap_pyfunction!(run::run_scene, m)?)?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(run::output_fields, m)?)?;
    m.add_class::<run::Compiled>()?;
    m.add_class::<run::RunOutcome>()?;
    m.add_function(wrap_pyfunction!(run::validate, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::validate_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::max_threads, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::fast_lanes, m)?)?;
    m.add_function(wrap_pyfunction!(force::resistance_force, m)?)?;
    m.add("FORCE_INPUTS", crate::evaluate::INPUTS.to_vec())?;
    m.add("FORCE_OUTPUTS", crate::evaluate::OUTPUTS.to_vec())?;
    m.add_class::<mujoco::SandGeoms>()?;
    m.add_class::<mujoco::MujocoCoupling>()?;
    m.add("SPACE_GEOM_OUTPUTS", crate::space::engine::OUTPUTS.to_vec())?;
    m.add("SPACE_REST_SPEED", crate::space::engine::REST_SPEED)?;
    m.add("GEOM_STATE", crate::evaluate::geoms::STATE.to_vec())?;
    m.add("GEOM_OUTPUTS", crate::evaluate::geoms::OUTPUTS.to_vec())?;
    m.add("EFFECTS", effects())?;
    m.add("PRESETS", crate::presets::names())?;
    m.add("RECORDS", RECORDS.to_vec())?;
    m.add("SCENE_FIELDS", SCENE_FIELDS.to_vec())?;
    m.add_function(wrap_pyfunction!(run::leg_segments, m)?)?;
    m.add_function(wrap_pyfunction!(terms::term_infos, m)?)?;
    m.add_function(wrap_pyfunction!(convert::scene_fields, m)?)?;
    m.add_function(wrap_pyfunction!(convert::element_fields, m)?)?;
    m.add_function(wrap_pyfunction!(convert::body_linkage, m)?)?;
    m.add("MAX_LINKS", crate::bodies::MAX_LINKS)?;
    m.add("MAX_CONTACTS", crate::dynamics::MAX_CONTACTS)?;
    m.add("MAX_CHORDS", crate::body::arc::MAX_CHORDS)?;
    m.add("DEFAULT_CHORDS", crate::body::arc::DEFAULT_CHORDS)?;
    m.add_function(wrap_pyfunction!(terms::check_term, m)?)?;
    m.add_function(wrap_pyfunction!(terms::rft_alpha, m)?)?;
    m.add("RFT_GENERIC", crate::forces::rft::GENERIC.to_vec())?;
    m.add(
        "RFT_COEFFICIENTS",
        crate::forces::rft::COEFFICIENT_NAMES.to_vec(),
    )?;
    m.add_class::<space::SpaceScene>()?;
    m.add_function(wrap_pyfunction!(space::space_scene, m)?)?;
    m.add_function(wrap_pyfunction!(space::space_run, m)?)?;
    m.add_function(wrap_pyfunction!(space::space_load, m)?)?;
    m.add_function(wrap_pyfunction!(space::xi_n, m)?)?;
    m.add_function(wrap_pyfunction!(space::rft3d_alpha, m)?)?;
    m.add(
        "RFT3D_COEFFICIENTS",
        crate::forces::rft3d::COEFFICIENTS
            .iter()
            .map(|row| row.to_vec())
            .collect::<Vec<_>>(),
    )?;
    m.add("SPACE_SUMMARY", space::summary_fields())?;
    m.add("SPACE_SERIES", space::series_columns())?;
    m.add(
        "SPACE_MAX_NODES",
        crate::space::shape::Quadrature::MAX_NODES,
    )?;
    m.add(
        "SPACE_DEFAULT_NODES",
        crate::space::shape::Quadrature::DEFAULT_NODES,
    )?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
