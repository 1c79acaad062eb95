//! `RodGeoms`: the force and moment on N rod geoms of another engine (`granrs.mujoco.Sand`)
//! in one call, through the free link's right-hand side (see `rust/evaluate.rs`, `geoms`).

use numpy::{PyReadonlyArray2, PyReadwriteArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyList;

use super::errors::to_pyerr;
use super::terms::terms_from_py;
use crate::body::rod::ApplyAt;
use crate::dynamics::SignModel;
use crate::error::GranrsError;
use crate::evaluate::geoms::{self, STATE};
use crate::forces::{ForceSet, Medium};
use crate::spec::Value;

/// N rod geoms under a list of contact terms in one sand, checked once; `evaluate` takes
/// every geom's state and writes every geom's force, moment and findings.
#[pyclass(module = "granrs._granrs", frozen)]
pub struct RodGeoms {
    inner: geoms::RodGeoms,
    names: Vec<String>,
}

#[pymethods]
impl RodGeoms {
    /// `names`, `diameter` and `length` per geom; `forces` a sequence of
    /// `granrs.forces.Term` (contact terms only); the sand's `rho_g` and `g`; `apply_at`
    /// ("tip" or "centroid"); `sign_model` ("raw" or "smooth", with `smooth_eps` in m/s).
    /// Every error names the geom, term or parameter.
    #[new]
    #[pyo3(signature = (names, diameter, length, forces, rho_g, g, apply_at="tip", sign_model="raw", smooth_eps=1e-3))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        names: Vec<String>,
        diameter: Vec<f64>,
        length: Vec<f64>,
        forces: &Bound<'_, PyList>,
        rho_g: f64,
        g: f64,
        apply_at: &str,
        sign_model: &str,
        smooth_eps: f64,
    ) -> PyResult<Self> {
        let err = |e: GranrsError| to_pyerr(py, e);
        let specs = match terms_from_py(forces.iter()) {
            Some(Value::Terms(specs)) => specs,
            _ if forces.is_empty() => Vec::new(),
            _ => {
                return Err(err(GranrsError::WrongType {
                    field: "forces".into(),
                    expected: "a list of granrs.forces terms".into(),
                    got: "something else".into(),
                }))
            }
        };
        let set = ForceSet::build(&specs, names.len()).map_err(err)?;
        let apply_at = match apply_at {
            "tip" => ApplyAt::Tip,
            "centroid" => ApplyAt::Centroid,
            other => {
                return Err(err(GranrsError::UnknownName {
                    field: "apply_at".into(),
                    value: other.into(),
                    allowed: "tip, centroid".into(),
                }))
            }
        };
        let sign_model = match sign_model {
            "raw" => SignModel::Raw,
            "smooth" => SignModel::Smooth { eps: smooth_eps },
            other => {
                return Err(err(GranrsError::UnknownName {
                    field: "sign_model".into(),
                    value: other.into(),
                    allowed: "raw, smooth".into(),
                }))
            }
        };
        let inner = geoms::RodGeoms::new(
            &names,
            &diameter,
            &length,
            &set,
            Medium { rho_g, g },
            apply_at,
            sign_model,
        )
        .map_err(err)?;
        Ok(RodGeoms { inner, names })
    }

    /// Number of geoms.
    fn __len__(&self) -> usize {
        self.inner.len()
    }

    /// Every geom's force, moment and findings: `states` is `n x 7` in the order of
    /// `ROD_GEOM_STATE`, `out` an `n x 16` float array written in the order of
    /// `ROD_GEOM_OUTPUTS`. A non-finite state or an axis that is not a unit vector pointing
    /// up from the tip is an error naming the geom, before any is evaluated.
    fn evaluate(
        &self,
        py: Python<'_>,
        states: PyReadonlyArray2<'_, f64>,
        mut out: PyReadwriteArray2<'_, f64>,
    ) -> PyResult<()> {
        let n = self.inner.len();
        let width = geoms::OUTPUTS.len();
        if states.shape() != [n, STATE.len()] || out.shape() != [n, width] {
            return Err(PyValueError::new_err(format!(
                "evaluate takes states of shape ({n}, {}) and out of shape ({n}, {width})",
                STATE.len()
            )));
        }
        let states = states
            .as_slice()
            .map_err(|_| PyValueError::new_err("evaluate needs C-contiguous arrays"))?;
        let out = out
            .as_slice_mut()
            .map_err(|_| PyValueError::new_err("evaluate needs C-contiguous arrays"))?;
        let mut rows = Vec::with_capacity(n);
        for (i, s) in states.chunks_exact(STATE.len()).enumerate() {
            let row: [f64; 7] = s.try_into().expect("seven columns");
            geoms::RodGeoms::check_state(&self.names[i], &row).map_err(|e| to_pyerr(py, e))?;
            rows.push(row);
        }
        for (i, (row, o)) in rows.iter().zip(out.chunks_exact_mut(width)).enumerate() {
            self.inner.evaluate(i, row, o);
        }
        Ok(())
    }
}
