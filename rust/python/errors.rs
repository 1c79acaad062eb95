//! The one exhaustive conversion of a core error ([`GranrsError`]) to the matching class of
//! `granrs.errors`, so that the Python and Rust layers share one exception tree (rooted at
//! `granrs.GranrsError`; the classes for bad input subclass `ValueError`).

use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;

use crate::error::GranrsError;

/// Convert a core error to the matching `granrs.errors` exception.
pub(crate) fn to_pyerr(py: Python<'_>, err: GranrsError) -> PyErr {
    let (class, field) = match &err {
        GranrsError::InvalidParameter { field, .. } => {
            ("InvalidParameterError", Some(field.clone()))
        }
        GranrsError::WrongType { field, .. } => ("InvalidParameterError", Some(field.clone())),
        GranrsError::UnknownName { field, .. } => ("UnknownNameError", Some(field.clone())),
        GranrsError::UnknownParameter { field, .. } => ("UnknownNameError", Some(field.clone())),
        GranrsError::InvalidScene { field, .. } => ("InvalidSceneError", Some(field.clone())),
        GranrsError::NonFinite { .. } => ("SimulationError", None),
        // A run stopped from outside: the binding raises what stopped it (Ctrl-C's
        // KeyboardInterrupt); this is the fallback.
        GranrsError::Cancelled => return PyKeyboardInterrupt::new_err(err.to_string()),
    };
    let message = err.to_string();
    let make = || -> PyResult<PyErr> {
        let module = py.import("granrs.errors")?;
        let cls = module.getattr(class)?;
        let instance = match field {
            Some(f) => cls.call1((message.clone(), f))?,
            None => cls.call1((message.clone(),))?,
        };
        Ok(PyErr::from_value(instance))
    };
    make().unwrap_or_else(|_| PyRuntimeError::new_err(message.clone()))
}
