//! `resistance_force`: the rod resistance force over many states at once, from numpy
//! arrays (see `rust/evaluate.rs`).

use std::borrow::Cow;

use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use super::errors::to_pyerr;
use crate::error::GranrsError;

/// Evaluate the rod resistance force over many states (see `rust/evaluate.rs`): `inputs`
/// are nine equal-length float arrays in the order of `INPUTS`; returns an `n x 10` array
/// in the order of `OUTPUTS`. Every value is checked before any is evaluated.
#[pyfunction]
#[pyo3(signature = (inputs, length, diameter, rho_g, g, effects, sign_model, smooth_eps))]
#[allow(clippy::too_many_arguments)]
pub(super) fn resistance_force<'py>(
    py: Python<'py>,
    inputs: Vec<numpy::PyReadonlyArray1<'py, f64>>,
    length: f64,
    diameter: f64,
    rho_g: f64,
    g: f64,
    effects: Vec<String>,
    sign_model: &str,
    smooth_eps: f64,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    use crate::error::check_range;
    use crate::evaluate::{evaluate, RodSetup, Sign, INPUTS, OUTPUTS};
    let err = |e: GranrsError| to_pyerr(py, e);
    if inputs.len() != INPUTS.len() {
        return Err(PyValueError::new_err(format!(
            "resistance_force takes {} arrays ({})",
            INPUTS.len(),
            INPUTS.join(", ")
        )));
    }
    let slices: Vec<&[f64]> = inputs
        .iter()
        .map(|a| a.as_slice())
        .collect::<Result<_, _>>()
        .map_err(|_| PyValueError::new_err("resistance_force needs contiguous arrays"))?;
    // Each input has n values or one (a scalar, broadcast here without copying).
    let n = slices.iter().map(|s| s.len()).max().unwrap_or(0);
    if slices.iter().any(|s| s.len() != n && s.len() != 1) {
        return Err(PyValueError::new_err(
            "resistance_force arrays must have the same length or length 1",
        ));
    }
    check_range("length", length, 0.0, true).map_err(err)?;
    check_range("diameter", diameter, 0.0, true).map_err(err)?;
    check_range("rho_g", rho_g, 0.0, true).map_err(err)?;
    check_range("g", g, 0.0, false).map_err(err)?;
    let names: Vec<Cow<'static, str>> = effects.into_iter().map(Cow::Owned).collect();
    // The terms' parameters come with each state; these are placeholders.
    let forces = crate::spec::thesis_law(
        Some(&names),
        &[crate::forces::Coefficients::TABLE_3_4_VERTICAL],
    )
    .map_err(err)?;
    let sign = match sign_model {
        "raw" => Sign::Raw,
        "smooth" => Sign::Smooth(check_range("smooth_eps", smooth_eps, 0.0, true).map_err(err)?),
        other => {
            return Err(err(GranrsError::UnknownName {
                field: "sign_model".into(),
                value: other.into(),
                allowed: "raw, smooth (the held signs of \"modes\" need a time history)".into(),
            }))
        }
    };
    // Check every value before evaluating any.
    let checked = py.detach(|| -> Result<(), GranrsError> {
        for (k, (name, s)) in INPUTS.iter().zip(&slices).enumerate() {
            for (i, &x) in s.iter().enumerate() {
                let ok = match k {
                    1 => x.is_finite() && x.abs() < 90.0,
                    5..=8 => x.is_finite() && x >= 0.0,
                    _ => x.is_finite(),
                };
                if !ok {
                    let allowed = match k {
                        1 => "finite, -90 < q_deg < 90",
                        5..=8 => "finite, >= 0",
                        _ => "finite",
                    };
                    return Err(GranrsError::InvalidParameter {
                        field: name.to_string(),
                        value: x,
                        allowed: format!("{allowed}; at index {i}"),
                    });
                }
            }
        }
        Ok(())
    });
    checked.map_err(err)?;
    let setup = RodSetup {
        length,
        diameter,
        medium: crate::forces::Medium { rho_g, g },
        forces,
        sign,
    };
    let width = OUTPUTS.len();
    const CHUNK: usize = 4096;
    // Large calls run on the process's one pool (`batch::pool`), as sweeps do.
    let pool = if n > 4 * CHUNK {
        Some(crate::batch::pool().map_err(err)?)
    } else {
        None
    };
    let out = py.detach(|| {
        use rayon::prelude::*;
        let mut out = vec![0.0; n * width];
        let run = |c: usize, rows: &mut [f64]| {
            for (j, row) in rows.chunks_exact_mut(width).enumerate() {
                let i = c * CHUNK + j;
                let input = std::array::from_fn(|k| {
                    let s = slices[k];
                    if s.len() == 1 {
                        s[0]
                    } else {
                        s[i]
                    }
                });
                evaluate(&setup, input, row);
            }
        };
        match pool {
            // Small calls (a simulator's contacts at one step): no thread hand-off.
            None => out
                .chunks_mut(CHUNK * width)
                .enumerate()
                .for_each(|(c, rows)| run(c, rows)),
            Some(pool) => pool.install(|| {
                out.par_chunks_mut(CHUNK * width)
                    .enumerate()
                    .for_each(|(c, rows)| run(c, rows))
            }),
        }
        out
    });
    out.into_pyarray(py).reshape([n, width])
}
