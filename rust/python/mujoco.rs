//! `RodGeoms`: the force and moment on N rod geoms of another engine (`granrs.mujoco.Sand`)
//! in one call, through the free link's right-hand side (see `rust/evaluate.rs`, `geoms`).

use numpy::{
    PyReadonlyArray1, PyReadonlyArray2, PyReadwriteArray1, PyReadwriteArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyList;

use super::errors::to_pyerr;
use super::terms::terms_from_py;
use crate::body::rod::ApplyAt;
use crate::dynamics::SignModel;
use crate::error::GranrsError;
use crate::evaluate::geoms::{self, Coupling, EngineOut, EnginePlace, EngineState, STATE};
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

/// [`RodGeoms`] placed on the bodies of a MuJoCo model: one call per evaluation reads the
/// model's arrays, evaluates every geom and returns the generalized force (see
/// `granrs.mujoco.Sand`).
#[pyclass(module = "granrs._granrs")]
pub struct GeomCoupling {
    inner: Coupling,
}

#[pymethods]
impl GeomCoupling {
    /// `rods` on MuJoCo's geoms `geom` (bodies `body`, tree roots `root`, tip `reach` from
    /// the centre, moved by the dofs `dofs`) of a model with `nv` dofs; the sand's surface
    /// height and patch in x; `stick` for the static terms as reactions; `at_centroid`
    /// where the force acts; `implicit_damping` the dof damping the engine's step takes
    /// implicitly (nv).
    #[new]
    #[allow(clippy::too_many_arguments)]
    fn new(
        rods: PyRef<'_, RodGeoms>,
        geom: Vec<usize>,
        body: Vec<usize>,
        root: Vec<usize>,
        reach: Vec<f64>,
        dofs: Vec<Vec<usize>>,
        nv: usize,
        surface: f64,
        patch: (f64, f64),
        stick: bool,
        at_centroid: bool,
        implicit_damping: Vec<f64>,
    ) -> PyResult<Self> {
        let n = rods.inner.len();
        if [geom.len(), body.len(), root.len(), reach.len(), dofs.len()]
            .iter()
            .any(|&l| l != n)
            || dofs.iter().flatten().any(|&j| j >= nv)
            || implicit_damping.len() != nv
        {
            return Err(PyValueError::new_err("one place per geom, dofs below nv"));
        }
        let places = (0..n)
            .map(|i| EnginePlace {
                geom: geom[i],
                body: body[i],
                root: root[i],
                reach: reach[i],
                dofs: dofs[i].clone(),
            })
            .collect();
        Ok(GeomCoupling {
            inner: Coupling {
                rods: rods.inner.clone(),
                places,
                nv,
                surface,
                patch,
                stick,
                at_centroid,
                previous: vec![0.0; nv],
                implicit_damping,
            },
        })
    }

    /// One evaluation at MuJoCo's arrays (`geom_xpos`, `geom_xmat`, `cvel`, `subtree_com`,
    /// `cdof`, the dense mass matrix, `qvel`, `qacc`): writes each geom's `outputs`
    /// (ROD_GEOM_OUTPUTS), `applied` force and moment, `h_lambda`, and the generalized
    /// force `generalized` (nv), and puts it into `target` (nv): added to it without
    /// `kept` (the passive callback's `qfrc_passive`); with `kept = (before, after)` (the
    /// user's `qfrc_applied` without and with the last contribution), an entry still equal
    /// to `after` is restored to `before` and any other is the user's, then the new
    /// contribution is added and `before` and `after` updated (`fresh`: no last step).
    /// Returns the largest `h_lambda` and its geom.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (geom_xpos, geom_xmat, cvel, subtree_com, cdof, mass, qvel, qacc, timestep, outputs, applied, h_lambda, generalized, target, kept=None, fresh=false))]
    fn step(
        &mut self,
        geom_xpos: PyReadonlyArray2<'_, f64>,
        geom_xmat: PyReadonlyArray2<'_, f64>,
        cvel: PyReadonlyArray2<'_, f64>,
        subtree_com: PyReadonlyArray2<'_, f64>,
        cdof: PyReadonlyArray2<'_, f64>,
        mass: PyReadonlyArray2<'_, f64>,
        qvel: PyReadonlyArray1<'_, f64>,
        qacc: PyReadonlyArray1<'_, f64>,
        timestep: f64,
        mut outputs: PyReadwriteArray2<'_, f64>,
        mut applied: PyReadwriteArray2<'_, f64>,
        mut h_lambda: PyReadwriteArray1<'_, f64>,
        mut generalized: PyReadwriteArray1<'_, f64>,
        mut target: PyReadwriteArray1<'_, f64>,
        kept: Option<(PyReadwriteArray1<'_, f64>, PyReadwriteArray1<'_, f64>)>,
        fresh: bool,
    ) -> PyResult<(f64, usize)> {
        let c = &self.inner;
        let (n, nv) = (c.places.len(), c.nv);
        let bad = |what: &str| PyValueError::new_err(format!("GeomCoupling.step: {what}"));
        fn slice<'a>(
            a: &'a PyReadonlyArray2<'_, f64>,
            cols: usize,
            rows: usize,
        ) -> Option<&'a [f64]> {
            let ok = a.shape()[1] == cols && a.shape()[0] >= rows;
            a.as_slice().ok().filter(move |_| ok)
        }
        let max_geom = c.places.iter().map(|p| p.geom + 1).max().unwrap_or(0);
        let max_body = c
            .places
            .iter()
            .map(|p| p.body.max(p.root) + 1)
            .max()
            .unwrap_or(0);
        let state = EngineState {
            geom_xpos: slice(&geom_xpos, 3, max_geom).ok_or_else(|| bad("geom_xpos"))?,
            geom_xmat: slice(&geom_xmat, 9, max_geom).ok_or_else(|| bad("geom_xmat"))?,
            cvel: slice(&cvel, 6, max_body).ok_or_else(|| bad("cvel"))?,
            subtree_com: slice(&subtree_com, 3, max_body).ok_or_else(|| bad("subtree_com"))?,
            cdof: slice(&cdof, 6, nv).ok_or_else(|| bad("cdof"))?,
            mass: slice(&mass, nv, nv).ok_or_else(|| bad("mass"))?,
            qvel: qvel
                .as_slice()
                .ok()
                .filter(|s| s.len() == nv)
                .ok_or_else(|| bad("qvel"))?,
            qacc: qacc
                .as_slice()
                .ok()
                .filter(|s| s.len() == nv)
                .ok_or_else(|| bad("qacc"))?,
        };
        let width = crate::evaluate::geoms::OUTPUTS.len();
        let out = EngineOut {
            outputs: outputs
                .as_slice_mut()
                .ok()
                .filter(|s| s.len() == n * width)
                .ok_or_else(|| bad("outputs"))?,
            applied: applied
                .as_slice_mut()
                .ok()
                .filter(|s| s.len() == n * 3)
                .ok_or_else(|| bad("applied"))?,
            h_lambda: h_lambda
                .as_slice_mut()
                .ok()
                .filter(|s| s.len() == n)
                .ok_or_else(|| bad("h_lambda"))?,
            generalized: generalized
                .as_slice_mut()
                .ok()
                .filter(|s| s.len() == nv)
                .ok_or_else(|| bad("generalized"))?,
        };
        self.inner.step(&state, timestep, out);
        let gen = generalized.as_slice().map_err(|_| bad("generalized"))?;
        let target = target
            .as_slice_mut()
            .ok()
            .filter(|s| s.len() == nv)
            .ok_or_else(|| bad("target"))?;
        match kept {
            None => target.iter_mut().zip(gen).for_each(|(t, g)| *t += g),
            Some((mut before, mut after)) => {
                let before = before
                    .as_slice_mut()
                    .ok()
                    .filter(|s| s.len() == nv)
                    .ok_or_else(|| bad("before"))?;
                let after = after
                    .as_slice_mut()
                    .ok()
                    .filter(|s| s.len() == nv)
                    .ok_or_else(|| bad("after"))?;
                for j in 0..nv {
                    let user = if !fresh && target[j] == after[j] {
                        before[j]
                    } else {
                        target[j]
                    };
                    before[j] = user;
                    target[j] = user + gen[j];
                    after[j] = target[j];
                }
            }
        }
        let worst = h_lambda.as_slice().map_err(|_| bad("h_lambda"))?;
        let (mut k, mut top) = (0, 0.0);
        for (i, &x) in worst.iter().enumerate() {
            if x > top {
                (k, top) = (i, x);
            }
        }
        Ok((top, k))
    }
}
