//! `SandGeoms`: the force and moment on N rod geoms of another engine (`granrs.mujoco.Sand`)
//! in one call, through the free link's right-hand side (see `rust/evaluate.rs`, `geoms`).

use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyReadwriteArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};

use super::errors::to_pyerr;
use super::terms::terms_from_py;
use crate::body::rod::ApplyAt;
use crate::dynamics::SignModel;
use crate::error::GranrsError;
use crate::evaluate::geoms::{
    self, Coupling, EngineOut, EnginePlace, EngineState, GeomShape, Work, MAX_COUPLED, STATE,
};
use crate::forces::{ForceSet, Medium};
use crate::space::engine as space_engine;
use crate::space::load::{Sand, Terms3};
use crate::space::shape::{Quadrature, Shape};
use crate::spec::Value;

/// N geoms (rods and sole boxes) under a list of contact terms in one sand, checked once;
/// `evaluate` takes every geom's state and writes every geom's force, moment and findings.
#[pyclass(module = "granrs._granrs", frozen)]
pub struct SandGeoms {
    inner: geoms::SandGeoms,
    names: Vec<String>,
}

#[pymethods]
impl SandGeoms {
    /// `names` and `shapes` per geom (`("rod", [d_c, L])` or `("sole", [length, height,
    /// width, l_ref])`); `forces` a sequence of `granrs.forces.Term` (contact terms only);
    /// the sand's `rho_g` and `g`; `apply_at` ("tip": a rod's tip, a sole's middle; or
    /// "centroid"); `sign_model` ("raw" or "smooth", with `smooth_eps` in m/s). Every error
    /// names the geom, term or parameter.
    #[new]
    #[pyo3(signature = (names, shapes, forces, rho_g, g, apply_at="tip", sign_model="raw", smooth_eps=1e-3))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        names: Vec<String>,
        shapes: Vec<(String, Vec<f64>)>,
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
        let mut kinds = Vec::with_capacity(shapes.len());
        for (i, (kind, size)) in shapes.iter().enumerate() {
            kinds.push(match (kind.as_str(), size.as_slice()) {
                ("rod", &[diameter, length]) => GeomShape::Rod { diameter, length },
                ("sole", &[length, height, width, l_ref]) => GeomShape::Sole {
                    length,
                    height,
                    width,
                    l_ref,
                },
                _ => {
                    return Err(err(GranrsError::UnknownName {
                        field: format!("shapes[{i}]"),
                        value: kind.clone(),
                        allowed: "(\"rod\", [d_c, L]), (\"sole\", [length, height, width, l_ref])"
                            .into(),
                    }))
                }
            });
        }
        let inner = geoms::SandGeoms::new(
            &names,
            &kinds,
            &set,
            Medium { rho_g, g },
            apply_at,
            sign_model,
        )
        .map_err(err)?;
        Ok(SandGeoms { inner, names })
    }

    /// Number of geoms.
    fn __len__(&self) -> usize {
        self.inner.len()
    }

    /// Every geom's force, moment and findings: `states` is `n x 7` in the order of
    /// `GEOM_STATE`, `out` an `n x 18` float array written in the order of `GEOM_OUTPUTS`.
    /// A non-finite state, an axis that is not a unit vector, or a rod's axis pointing down
    /// from its tip is an error naming the geom, before any is evaluated.
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
            self.inner
                .check_state(i, &self.names[i], &row)
                .map_err(|e| to_pyerr(py, e))?;
            rows.push(row);
        }
        for (i, (row, o)) in rows.iter().zip(out.chunks_exact_mut(width)).enumerate() {
            self.inner.evaluate(i, row, o);
        }
        Ok(())
    }
}

/// The arrays a coupling reads and writes at every step, bound once per `mjData` (MuJoCo
/// allocates them once, so their views stay valid while held): reading them then costs no
/// conversion per step. Both couplings bind the same arrays, in this order (`cvel` only for
/// the planar one): `geom_xpos`, `geom_xmat`, `cvel`, `subtree_com`, `cdof`, `qvel`, `qacc`,
/// `qfrc_applied`, `qfrc_passive` of the `mjData`, and the caller's buffers: the dense mass
/// matrix it fills, `outputs` per geom, the `applied` force and moment per geom,
/// `h_lambda`, the generalized force, and `before` and `after`, the bookkeeping of
/// `qfrc_applied`.
struct Arrays {
    geom_xpos: Py<PyArray2<f64>>,
    geom_xmat: Py<PyArray2<f64>>,
    cvel: Option<Py<PyArray2<f64>>>,
    subtree_com: Py<PyArray2<f64>>,
    cdof: Py<PyArray2<f64>>,
    qvel: Py<PyArray1<f64>>,
    qacc: Py<PyArray1<f64>>,
    qfrc_applied: Py<PyArray1<f64>>,
    qfrc_passive: Py<PyArray1<f64>>,
    mass: Py<PyArray2<f64>>,
    outputs: Py<PyArray2<f64>>,
    applied: Py<PyArray2<f64>>,
    h_lambda: Py<PyArray1<f64>>,
    generalized: Py<PyArray1<f64>>,
    before: Py<PyArray1<f64>>,
    after: Py<PyArray1<f64>>,
}

/// What a coupling's arrays must hold: `n` geoms on a model of `nv` dofs whose geoms and
/// bodies reach `max_geom` and `max_body`, `width` outputs and an `applied` row of `wrench`
/// values per geom, and whether the planar `cvel` is bound.
struct Sizes {
    n: usize,
    nv: usize,
    max_geom: usize,
    max_body: usize,
    width: usize,
    wrench: usize,
    cvel: bool,
}

impl Sizes {
    /// The sizes for geoms at `places` (each geom's index and the highest body it reads:
    /// its own or its tree's root), on a model of `nv` dofs.
    fn of(
        places: impl Iterator<Item = (usize, usize)>,
        nv: usize,
        width: usize,
        wrench: usize,
        cvel: bool,
    ) -> Sizes {
        let (mut n, mut max_geom, mut max_body) = (0, 0, 0);
        for (geom, body) in places {
            n += 1;
            max_geom = max_geom.max(geom + 1);
            max_body = max_body.max(body + 1);
        }
        Sizes {
            n,
            nv,
            max_geom,
            max_body,
            width,
            wrench,
            cvel,
        }
    }
}

/// One coupling's views of its bound arrays for one step.
struct Views<'a> {
    state: EngineState<'a>,
    outputs: &'a mut [f64],
    applied: &'a mut [f64],
    h_lambda: &'a mut [f64],
    generalized: &'a mut [f64],
    /// `qfrc_passive` (the callback) or `qfrc_applied`.
    target: &'a mut [f64],
    before: &'a mut [f64],
    after: &'a mut [f64],
}

impl Arrays {
    /// The arrays of `a` (in the order of [`Arrays`]), each checked for its shape once; an
    /// error names `class` and the array.
    fn bind(class: &str, z: &Sizes, a: &Bound<'_, PyTuple>) -> PyResult<Arrays> {
        let want = if z.cvel { 16 } else { 15 };
        if a.len() != want {
            return Err(PyValueError::new_err(format!(
                "{class}.bind: {want} arrays, got {}",
                a.len()
            )));
        }
        let items: Vec<_> = a.iter().collect();
        let two = |k: usize, name: &str, rows: usize, cols: usize, exact: bool| {
            let arr = items[k]
                .cast::<PyArray2<f64>>()
                .map_err(|_| PyValueError::new_err(format!("{class}.bind: {name}")))?;
            bind2(arr, class, name, rows, cols, exact)
        };
        let one = |k: usize, name: &str, len: usize| {
            let arr = items[k]
                .cast::<PyArray1<f64>>()
                .map_err(|_| PyValueError::new_err(format!("{class}.bind: {name}")))?;
            bind1(arr, class, name, len)
        };
        // The arrays after `cvel` sit one place later where it is bound.
        let at = |k: usize| k + usize::from(z.cvel);
        let cvel = match z.cvel {
            true => Some(two(2, "cvel", z.max_body, 6, false)?),
            false => None,
        };
        Ok(Arrays {
            geom_xpos: two(0, "geom_xpos", z.max_geom, 3, false)?,
            geom_xmat: two(1, "geom_xmat", z.max_geom, 9, false)?,
            cvel,
            subtree_com: two(at(2), "subtree_com", z.max_body, 3, false)?,
            cdof: two(at(3), "cdof", z.nv, 6, true)?,
            qvel: one(at(4), "qvel", z.nv)?,
            qacc: one(at(5), "qacc", z.nv)?,
            qfrc_applied: one(at(6), "qfrc_applied", z.nv)?,
            qfrc_passive: one(at(7), "qfrc_passive", z.nv)?,
            mass: two(at(8), "mass", z.nv, z.nv, true)?,
            outputs: two(at(9), "outputs", z.n, z.width, true)?,
            applied: two(at(10), "applied", z.n, z.wrench, true)?,
            h_lambda: one(at(11), "h_lambda", z.n)?,
            generalized: one(at(12), "generalized", z.nv)?,
            before: one(at(13), "before", z.nv)?,
            after: one(at(14), "after", z.nv)?,
        })
    }

    /// The bound arrays (`bound`: `None` before `class`'s `bind`, an error) as slices, with
    /// `qfrc_passive` (`passive`) or `qfrc_applied` as the target of the generalized force.
    ///
    /// # Safety
    /// Each array was checked contiguous with its shape at `bind`; MuJoCo never reallocates
    /// an mjData's arrays, the buffers are the `Sand`'s own, and no two slices alias
    /// (distinct arrays). The caller holds the mjData while the views live, and nothing
    /// else reads or writes these arrays meanwhile.
    unsafe fn views<'a>(
        bound: &'a Option<Arrays>,
        class: &str,
        py: Python<'a>,
        passive: bool,
    ) -> PyResult<Views<'a>> {
        let Some(a) = bound else {
            return Err(PyValueError::new_err(format!("{class}.step before bind")));
        };
        Ok(a.views_of(py, passive))
    }

    /// [`Arrays::views`] of bound arrays.
    unsafe fn views_of<'a>(&'a self, py: Python<'a>, passive: bool) -> Views<'a> {
        Views {
            state: EngineState {
                geom_xpos: ro(py, &self.geom_xpos),
                geom_xmat: ro(py, &self.geom_xmat),
                cvel: self.cvel.as_ref().map_or(&[], |c| ro(py, c)),
                subtree_com: ro(py, &self.subtree_com),
                cdof: ro(py, &self.cdof),
                mass: ro(py, &self.mass),
                qvel: ro(py, &self.qvel),
                qacc: ro(py, &self.qacc),
            },
            outputs: rw(py, &self.outputs),
            applied: rw(py, &self.applied),
            h_lambda: rw(py, &self.h_lambda),
            generalized: rw(py, &self.generalized),
            target: if passive {
                rw(py, &self.qfrc_passive)
            } else {
                rw(py, &self.qfrc_applied)
            },
            before: rw(py, &self.before),
            after: rw(py, &self.after),
        }
    }
}

impl Views<'_> {
    /// One evaluation: `f` reads the state and writes the engine's outputs, then the
    /// generalized force goes into MuJoCo's ([`Views::deliver`]).
    fn run<R>(
        &mut self,
        passive: bool,
        fresh: bool,
        f: impl FnOnce(&EngineState<'_>, EngineOut<'_>) -> R,
    ) -> R {
        let out = EngineOut {
            outputs: &mut *self.outputs,
            applied: &mut *self.applied,
            h_lambda: &mut *self.h_lambda,
            generalized: &mut *self.generalized,
        };
        let r = f(&self.state, out);
        self.deliver(passive, fresh);
        r
    }

    /// Put the generalized force into MuJoCo's: added to `qfrc_passive` (`passive`, the
    /// callback), or into `qfrc_applied` keeping the user's entries ([`keep_user_entries`]).
    fn deliver(&mut self, passive: bool, fresh: bool) {
        if passive {
            let gen = &*self.generalized;
            self.target.iter_mut().zip(gen).for_each(|(t, g)| *t += g);
        } else {
            keep_user_entries(
                self.target,
                self.before,
                self.after,
                self.generalized,
                fresh,
            );
        }
    }
}

/// The sand's engine under a MuJoCo model: rods and soles in the plane ([`Coupling`]), or
/// shapes in space ([`space_engine::SpaceCoupling`]).
enum Engine {
    Planar(Box<Coupling>),
    Space(Box<space_engine::SpaceCoupling>),
}

/// The sand placed on the bodies of a MuJoCo model (`granrs.mujoco.Sand`): one call per
/// evaluation reads the model's arrays, evaluates every geom and puts the generalized force
/// into MuJoCo's. Made by [`MujocoCoupling::planar`] ([`SandGeoms`], rod and sole geoms) or
/// [`MujocoCoupling::space`] (geoms as shapes in space under the terms in space, see
/// `crate::space::engine`).
#[pyclass(module = "granrs._granrs", unsendable)]
pub struct MujocoCoupling {
    engine: Engine,
    bound: Option<Arrays>,
}

#[pymethods]
impl MujocoCoupling {
    /// `rods` on MuJoCo's geoms `geom` (bodies `body`, tree roots `root`, tip `reach` from
    /// the centre, moved by the dofs `dofs`) of a model with `nv` dofs; the sand's surface
    /// height and patch in x; `stick` for the static terms as reactions;
    /// `implicit_damping` the dof damping the engine's step takes implicitly (nv);
    /// `rest_speed` the creep speed of a geom the static reactions hold.
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    fn planar(
        py: Python<'_>,
        rods: PyRef<'_, SandGeoms>,
        geom: Vec<usize>,
        body: Vec<usize>,
        root: Vec<usize>,
        reach: Vec<f64>,
        dofs: Vec<Vec<usize>>,
        nv: usize,
        surface: f64,
        patch: (f64, f64),
        stick: bool,
        implicit_damping: Vec<f64>,
        rest_speed: f64,
    ) -> PyResult<Self> {
        let n = rods.inner.len();
        crate::error::check_range("rest_speed", rest_speed, 0.0, true)
            .map_err(|e| to_pyerr(py, e))?;
        if [geom.len(), body.len(), root.len(), reach.len(), dofs.len()]
            .iter()
            .any(|&l| l != n)
            || dofs.iter().flatten().any(|&j| j >= nv)
            || implicit_damping.len() != nv
        {
            return Err(PyValueError::new_err("one place per geom, dofs below nv"));
        }
        if n > MAX_COUPLED {
            return Err(PyValueError::new_err(format!(
                "at most {MAX_COUPLED} geoms"
            )));
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
        Ok(MujocoCoupling {
            engine: Engine::Planar(Box::new(Coupling {
                rods: rods.inner.clone(),
                places,
                nv,
                surface,
                patch,
                stick,
                previous: vec![0.0; nv],
                implicit_damping,
                work: Work::new(n, nv),
                held: vec![None; n],
                held_wrench: vec![None; n],
                rest_speed,
            })),
            bound: None,
        })
    }

    /// `names` and `shapes` per geom (a `granrs.space` shape's dict), `forces` the terms
    /// in space (`(name, params)` pairs; no `gravity`: the engine applies it), the sand's
    /// `rho_g`, `surface`, `patch` (x_min, x_max, y_min, y_max) and `rest_speed`, the
    /// surface rule's `quadrature` nodes; each geom's place (`geom`, `body`, `root`,
    /// `dofs`) in a model of `nv` dofs, and the dof damping its integrator takes
    /// implicitly. Every error names the geom, term or parameter.
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    fn space(
        py: Python<'_>,
        names: Vec<String>,
        shapes: &Bound<'_, PyList>,
        forces: &Bound<'_, PyAny>,
        rho_g: f64,
        surface: f64,
        patch: [f64; 4],
        rest_speed: f64,
        quadrature: usize,
        geom: Vec<usize>,
        body: Vec<usize>,
        root: Vec<usize>,
        dofs: Vec<Vec<usize>>,
        nv: usize,
        implicit_damping: Vec<f64>,
    ) -> PyResult<Self> {
        let err = |e: GranrsError| to_pyerr(py, e);
        let n = names.len();
        if [shapes.len(), geom.len(), body.len(), root.len(), dofs.len()]
            .iter()
            .any(|&l| l != n)
            || dofs.iter().flatten().any(|&j| j >= nv)
            || implicit_damping.len() != nv
        {
            return Err(PyValueError::new_err(
                "one shape and place per geom, dofs below nv",
            ));
        }
        crate::error::check_range("rho_g", rho_g, 0.0, true).map_err(err)?;
        crate::error::check_finite("surface", surface).map_err(err)?;
        crate::error::check_range("rest_speed", rest_speed, 0.0, true).map_err(err)?;
        if !(1..=Quadrature::MAX_NODES).contains(&quadrature) {
            return Err(err(GranrsError::InvalidParameter {
                field: "quadrature".into(),
                value: quadrature as f64,
                allowed: format!("an integer in 1..={}", Quadrature::MAX_NODES),
            }));
        }
        let specs = super::space::forces_of(forces).map_err(err)?;
        let mut geoms = Vec::with_capacity(n);
        for i in 0..n {
            let field = format!("geoms[{i}]");
            let shape = super::space::shape_at(&shapes.get_item(i)?, &field).map_err(err)?;
            let terms = Terms3::from_specs(&specs, &shape).map_err(err)?;
            if terms.field != 0.0 {
                return Err(err(GranrsError::InvalidScene {
                    field: "forces.gravity".into(),
                    message: "MuJoCo applies the model's own gravity; list only the sand's \
                              terms (rft3d, rft3d_inertial, poncelet)"
                        .into(),
                }));
            }
            if !terms.any_sand() {
                return Err(err(GranrsError::InvalidScene {
                    field: "forces".into(),
                    message: "no term of the sand in space (rft3d, rft3d_inertial, poncelet)"
                        .into(),
                }));
            }
            let centre = match &shape {
                Shape::Mesh(m) => -m.offset,
                _ => nalgebra::Vector3::zeros(),
            };
            let sand = Sand::new(
                shape,
                terms,
                Medium { rho_g, g: 9.81 },
                surface,
                Quadrature::new(quadrature),
            );
            geoms.push(space_engine::SpaceGeom {
                sand,
                centre,
                place: space_engine::Place {
                    geom: geom[i],
                    body: body[i],
                    root: root[i],
                    dofs: dofs[i].clone(),
                },
            });
        }
        Ok(MujocoCoupling {
            engine: Engine::Space(Box::new(space_engine::SpaceCoupling {
                geoms,
                nv,
                patch,
                rest_speed,
                implicit_damping,
                previous: vec![0.0; nv],
                held: vec![None; n],
                solved: vec![None; n],
                rates: vec![None; n],
                cut: vec![0; n],
            })),
            bound: None,
        })
    }

    /// Bind the arrays of one `mjData` and the caller's buffers, in the order of
    /// [`Arrays`] (`cvel` only in the plane; `outputs` per geom in GEOM_OUTPUTS or
    /// SPACE_GEOM_OUTPUTS order; `applied` per geom, force and moment n x 3 in the plane, the
    /// wrench n x 6 in space), each checked for its shape once.
    #[pyo3(signature = (*arrays))]
    fn bind(&mut self, arrays: &Bound<'_, PyTuple>) -> PyResult<()> {
        let (class, sizes) = match &self.engine {
            Engine::Planar(c) => {
                let places = c.places.iter().map(|p| (p.geom, p.body.max(p.root)));
                let width = crate::evaluate::geoms::OUTPUTS.len();
                ("planar", Sizes::of(places, c.nv, width, 3, true))
            }
            Engine::Space(c) => {
                let places = c
                    .geoms
                    .iter()
                    .map(|g| (g.place.geom, g.place.body.max(g.place.root)));
                let width = space_engine::OUTPUTS.len();
                ("space", Sizes::of(places, c.nv, width, 6, false))
            }
        };
        let class = format!("MujocoCoupling.{class}");
        self.bound = Some(Arrays::bind(&class, &sizes, arrays)?);
        Ok(())
    }

    /// One evaluation at the bound arrays (the mass matrix filled by the caller): writes
    /// each geom's outputs, applied force and moment (wrench) and `h_lambda`, and the
    /// generalized force, and puts it into MuJoCo's: with `passive`, added to
    /// `qfrc_passive` (the callback); else into `qfrc_applied`, where an entry still equal
    /// to `after` (what the last step left there) is restored to `before` (what it held
    /// before), any other entry is the user's, the new contribution is added and `before`
    /// and `after` kept (`fresh`: no last step, every entry is the user's); `hold`: a later
    /// stage of RK4's step, which keeps the static reactions of its first. In space the GIL
    /// is released and the step is implicit. Returns the largest `h_lambda`, its geom, the
    /// Newton iterations, the solve's relative residual, whether it converged and whether
    /// the step fell back to sticking or sliding (in the plane: 0, 0.0, true, false).
    fn step(
        &mut self,
        py: Python<'_>,
        timestep: f64,
        passive: bool,
        fresh: bool,
        hold: bool,
    ) -> PyResult<(f64, usize, usize, f64, bool, bool)> {
        // SAFETY: as `Arrays::views`; the caller holds the mjData while this call runs (a
        // `Sand` method), and nothing of granrs's touches these arrays from another thread.
        unsafe {
            let mut v = Arrays::views(&self.bound, "MujocoCoupling", py, passive)?;
            match &mut self.engine {
                Engine::Planar(c) => {
                    v.run(passive, fresh, |state, out| {
                        c.step(state, timestep, hold, out)
                    });
                    let (mut k, mut top) = (0, 0.0);
                    for (i, &x) in v.h_lambda.iter().enumerate() {
                        if x > top {
                            (k, top) = (i, x);
                        }
                    }
                    Ok((top, k, 0, 0.0, true, false))
                }
                Engine::Space(c) => {
                    let r = py.detach(|| {
                        v.run(passive, fresh, |state, out| {
                            c.step(state, timestep, hold, out)
                        })
                    });
                    Ok((
                        r.h_lambda,
                        r.geom,
                        r.iterations,
                        r.residual,
                        r.converged,
                        r.fallback,
                    ))
                }
            }
        }
    }
}

/// A 2-d array checked for one `bind` of `class`: `cols` columns and `rows` rows (at least,
/// unless `exact`), C-contiguous.
fn bind2(
    a: &Bound2<'_>,
    class: &str,
    name: &str,
    rows: usize,
    cols: usize,
    exact: bool,
) -> PyResult<Py<PyArray2<f64>>> {
    let [r, k] = [a.shape()[0], a.shape()[1]];
    let ok = k == cols && if exact { r == rows } else { r >= rows };
    if ok && a.is_c_contiguous() {
        Ok(a.clone().unbind())
    } else {
        Err(PyValueError::new_err(format!("{class}.bind: {name}")))
    }
}

/// A 1-d array of `len` checked for one `bind` of `class`, C-contiguous.
fn bind1(a: &Bound1<'_>, class: &str, name: &str, len: usize) -> PyResult<Py<PyArray1<f64>>> {
    if a.len() == len && a.is_c_contiguous() {
        Ok(a.clone().unbind())
    } else {
        Err(PyValueError::new_err(format!("{class}.bind: {name}")))
    }
}

/// Put the generalized force `gen` into `qfrc_applied` (`target`): an entry still equal to
/// `after` (what the last step left there) is restored to `before` (what it held before),
/// any other entry is the user's (every entry, when `fresh`); the new contribution is added
/// and `before` and `after` kept.
fn keep_user_entries(
    target: &mut [f64],
    before: &mut [f64],
    after: &mut [f64],
    gen: &[f64],
    fresh: bool,
) {
    for j in 0..target.len() {
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

/// A bound array's data, read-only.
///
/// # Safety
/// As [`PyArrayMethods::as_slice`]: nothing may write the array while the slice lives.
unsafe fn ro<'a, D: numpy::ndarray::Dimension>(
    py: Python<'a>,
    a: &'a Py<numpy::PyArray<f64, D>>,
) -> &'a [f64] {
    a.bind(py).as_slice().expect("contiguous, checked at bind")
}

/// A bound array's data, writable.
///
/// # Safety
/// As [`PyArrayMethods::as_slice_mut`]: nothing else may read or write the array while the
/// slice lives.
#[allow(clippy::mut_from_ref)]
unsafe fn rw<'a, D: numpy::ndarray::Dimension>(
    py: Python<'a>,
    a: &'a Py<numpy::PyArray<f64, D>>,
) -> &'a mut [f64] {
    a.bind(py)
        .as_slice_mut()
        .expect("contiguous, checked at bind")
}

type Bound1<'py> = Bound<'py, PyArray1<f64>>;
type Bound2<'py> = Bound<'py, PyArray2<f64>>;
