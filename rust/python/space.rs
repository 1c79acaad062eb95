//! Bodies in space from Python (`granrs.space`): a scene dict is converted and checked into
//! a [`SpaceScene`] (every field, before any work), run with the GIL released, and its
//! outcome returned as a dict whose names come from `space::outputs`.

use numpy::IntoPyArray;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyList, PyTuple};

use super::errors::to_pyerr;
use super::run::watched;
use crate::error::GranrsError;
use crate::forces::{Medium, TermSpec};
use crate::space::load::load_with_error;
use crate::space::outputs::{SERIES, SUMMARY};
use crate::space::shape::{Quadrature, Shape};
use crate::space::{state_of, MassSpec, Scene3};

type Res<T> = std::result::Result<T, GranrsError>;

fn wrong(field: &str, expected: &str, got: &Bound<'_, PyAny>) -> GranrsError {
    GranrsError::WrongType {
        field: field.into(),
        expected: expected.into(),
        got: got
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_else(|_| "?".into()),
    }
}

fn is_bool(v: &Bound<'_, PyAny>) -> bool {
    v.is_instance_of::<PyBool>() || super::terms::is_numpy_bool(v)
}

fn number(v: &Bound<'_, PyAny>, field: &str) -> Res<f64> {
    if is_bool(v) {
        return Err(wrong(field, "a number", v));
    }
    v.extract::<f64>().map_err(|_| wrong(field, "a number", v))
}

fn item<'py>(d: &Bound<'py, PyDict>, key: &str, field: &str) -> Res<Bound<'py, PyAny>> {
    d.get_item(key)
        .ok()
        .flatten()
        .ok_or_else(|| GranrsError::InvalidScene {
            field: field.into(),
            message: "missing".into(),
        })
}

fn numbers<const N: usize>(v: &Bound<'_, PyAny>, field: &str) -> Res<[f64; N]> {
    // The common case first: a tuple of N floats (NumPy's float64 is one: a subclass of
    // float, never a bool), as `space.load`'s state at every call, without the general
    // path's per-item checks.
    if let Ok(t) = v.cast::<PyTuple>() {
        if t.len() == N {
            let mut out = [0.0; N];
            let mut floats = true;
            for (o, x) in out.iter_mut().zip(t.iter()) {
                match x.cast::<PyFloat>() {
                    Ok(f) => *o = f.value(),
                    Err(_) => {
                        floats = false;
                        break;
                    }
                }
            }
            if floats {
                return Ok(out);
            }
        }
    }
    let what = || format!("a sequence of {N} numbers");
    if v.is_instance_of::<pyo3::types::PyString>() {
        return Err(wrong(field, &what(), v));
    }
    let items: Vec<Bound<'_, PyAny>> = v
        .try_iter()
        .map_err(|_| wrong(field, &what(), v))?
        .take(N + 1)
        .collect::<PyResult<_>>()
        .map_err(|_| wrong(field, &what(), v))?;
    if items.len() != N {
        return Err(GranrsError::InvalidScene {
            field: field.into(),
            message: format!(
                "{}, got {}{}",
                what(),
                items.len().min(N),
                if items.len() > N { " or more" } else { "" }
            ),
        });
    }
    let mut out = [0.0; N];
    for (k, x) in items.iter().enumerate() {
        out[k] = number(x, &format!("{field}[{k}]"))?;
    }
    Ok(out)
}

fn rows<const N: usize>(v: &Bound<'_, PyAny>, field: &str, most: usize) -> Res<Vec<[f64; N]>> {
    let mut out = Vec::new();
    for (i, row) in v
        .try_iter()
        .map_err(|_| wrong(field, "a sequence of rows", v))?
        .enumerate()
    {
        if i >= most {
            return Err(GranrsError::InvalidScene {
                field: field.into(),
                message: format!("more than {most} rows"),
            });
        }
        let row = row.map_err(|_| wrong(field, "a sequence of rows", v))?;
        out.push(numbers::<N>(&row, &format!("{field}[{i}]"))?);
    }
    Ok(out)
}

fn shape_of(d: &Bound<'_, PyAny>) -> Res<Shape> {
    shape_at(d, "body.shape")
}

/// A shape from its dict, errors naming `field` (`body.shape`, or a MuJoCo geom).
pub(super) fn shape_at(d: &Bound<'_, PyAny>, field: &str) -> Res<Shape> {
    let d = d.cast::<PyDict>().map_err(|_| wrong(field, "a shape", d))?;
    let kind: String = item(d, "kind", &format!("{field}.kind"))?
        .extract()
        .map_err(|_| wrong(&format!("{field}.kind"), "a string", d))?;
    let num = |k: &str| -> Res<f64> {
        number(
            &item(d, k, &format!("{field}.{k}"))?,
            &format!("{field}.{k}"),
        )
    };
    match kind.as_str() {
        "sphere" => Shape::sphere(field, num("radius")?),
        "capsule" => Shape::capsule(field, num("radius")?, num("length")?),
        "cylinder" => Shape::cylinder(field, num("radius")?, num("length")?),
        "cuboid" => Shape::cuboid(
            field,
            numbers::<3>(
                &item(d, "size", &format!("{field}.size"))?,
                &format!("{field}.size"),
            )?,
        ),
        "mesh" => {
            let v = rows::<3>(
                &item(d, "vertices", &format!("{field}.vertices"))?,
                &format!("{field}.vertices"),
                3_000_000,
            )?;
            let t = rows::<3>(
                &item(d, "triangles", &format!("{field}.triangles"))?,
                &format!("{field}.triangles"),
                1_000_001,
            )?;
            let mut tri = Vec::with_capacity(t.len());
            for (i, r) in t.iter().enumerate() {
                let mut idx = [0i64; 3];
                for k in 0..3 {
                    if r[k].fract() != 0.0 || !r[k].is_finite() {
                        return Err(GranrsError::InvalidParameter {
                            field: format!("{field}.triangles[{i}][{k}]"),
                            value: r[k],
                            allowed: "a vertex index (an integer)".into(),
                        });
                    }
                    idx[k] = r[k] as i64;
                }
                tri.push(idx);
            }
            Shape::mesh(field, &v, &tri)
        }
        other => Err(GranrsError::UnknownName {
            field: format!("{field}.kind"),
            value: other.into(),
            allowed: "sphere, capsule, cylinder, cuboid, mesh".into(),
        }),
    }
}

fn mass_of(d: &Bound<'_, PyDict>) -> Res<MassSpec> {
    let get = |k: &str| d.get_item(k).ok().flatten().filter(|v| !v.is_none());
    match (get("density"), get("mass"), get("inertia")) {
        (Some(rho), None, None) => Ok(MassSpec::Density(number(&rho, "body.density")?)),
        (None, Some(m), None) => Ok(MassSpec::Mass(number(&m, "body.mass")?)),
        (None, Some(m), Some(i)) => {
            let r = rows::<3>(&i, "body.inertia", 3)?;
            if r.len() != 3 {
                return Err(GranrsError::InvalidScene {
                    field: "body.inertia".into(),
                    message: "a 3 x 3 tensor [kg m^2]".into(),
                });
            }
            Ok(MassSpec::Given(
                number(&m, "body.mass")?,
                [r[0], r[1], r[2]],
            ))
        }
        (None, None, Some(_)) => Err(GranrsError::InvalidScene {
            field: "body.inertia".into(),
            message: "an inertia needs its mass".into(),
        }),
        (None, None, None) => Err(GranrsError::InvalidScene {
            field: "body.density".into(),
            message: "give the body's density, or its mass (and optionally its inertia)".into(),
        }),
        _ => Err(GranrsError::InvalidScene {
            field: "body.density".into(),
            message: "give the density or the mass, not both".into(),
        }),
    }
}

pub(super) fn forces_of(v: &Bound<'_, PyAny>) -> Res<Vec<TermSpec>> {
    let mut out = Vec::new();
    for (i, t) in v
        .try_iter()
        .map_err(|_| wrong("forces", "a list of terms", v))?
        .enumerate()
    {
        let t = t.map_err(|_| wrong("forces", "a list of terms", v))?;
        let field = format!("forces[{i}]");
        let (name, params): (String, Bound<'_, PyDict>) = t
            .extract()
            .map_err(|_| wrong(&field, "a (name, params) pair", &t))?;
        let mut p = Vec::new();
        for (k, x) in params.iter() {
            let k: String = k
                .extract()
                .map_err(|_| wrong(&field, "parameter names", &params))?;
            let pf = format!("{field}.{name}.{k}");
            if x.cast::<PyTuple>().is_ok() || x.cast::<PyList>().is_ok() {
                return Err(GranrsError::InvalidScene {
                    field: pf,
                    message: "one value (a body in space is one contact)".into(),
                });
            }
            p.push((k, vec![number(&x, &pf)?]));
        }
        out.push(TermSpec { name, params: p });
    }
    Ok(out)
}

fn scene_of(d: &Bound<'_, PyDict>) -> Res<Scene3> {
    let body = item(d, "body", "body")?;
    let body = body
        .cast::<PyDict>()
        .map_err(|_| wrong("body", "a body", &body))?;
    let shape = shape_of(&item(body, "shape", "body.shape")?)?;
    let mass = mass_of(body)?;
    let v3 = |k: &str| numbers::<3>(&item(d, k, k)?, k);
    let num = |k: &str| number(&item(d, k, k)?, k);
    let end: String = item(d, "end", "end")?
        .extract()
        .map_err(|_| GranrsError::WrongType {
            field: "end".into(),
            expected: "\"stop\" or \"t_end\"".into(),
            got: "?".into(),
        })?;
    let end_at_stop = match end.as_str() {
        "stop" => true,
        "t_end" => false,
        other => {
            return Err(GranrsError::UnknownName {
                field: "end".into(),
                value: other.into(),
                allowed: "stop, t_end".into(),
            })
        }
    };
    let record = item(d, "record", "record")?;
    if !is_bool(&record) {
        return Err(wrong("record", "True or False", &record));
    }
    let nodes = num("quadrature")?;
    if nodes.fract() != 0.0 || !(1.0..=Quadrature::MAX_NODES as f64).contains(&nodes) {
        return Err(GranrsError::InvalidParameter {
            field: "quadrature".into(),
            value: nodes,
            allowed: format!(
                "an integer in 1..={} (nodes per panel)",
                Quadrature::MAX_NODES
            ),
        });
    }
    Ok(Scene3 {
        shape,
        mass,
        position: v3("position")?,
        orientation: numbers::<4>(&item(d, "orientation", "orientation")?, "orientation")?,
        velocity: v3("velocity")?,
        omega: v3("omega")?,
        forces: forces_of(&item(d, "forces", "forces")?)?,
        medium: Medium {
            rho_g: num("rho_g")?,
            g: num("g")?,
        },
        surface: num("surface")?,
        dt: num("dt")?,
        t_end: num("t_end")?,
        end_at_stop,
        record: record.is_truthy().unwrap_or(false),
        nodes: nodes as usize,
    })
}

/// A scene of a body in space, converted and checked, with its body built once (for
/// `space_load`'s evaluations).
#[pyclass(frozen, module = "granrs._granrs")]
pub(super) struct SpaceScene {
    scene: Scene3,
    body: std::sync::Mutex<crate::space::solve::Body>,
}

#[pymethods]
impl SpaceScene {
    /// The body's mass [kg] and inertia tensor about its centre of mass, body frame
    /// [kg m^2], and its volume [m^3].
    fn mass_properties(&self, py: Python<'_>) -> PyResult<(f64, Vec<Vec<f64>>, f64)> {
        let (body, _, _) = self.scene.build().map_err(|e| to_pyerr(py, e))?;
        let t = body.inertia.tensor;
        Ok((
            body.inertia.mass,
            (0..3)
                .map(|i| (0..3).map(|j| t[(i, j)]).collect())
                .collect(),
            self.scene.shape.volume(),
        ))
    }

    /// A mesh's vertices in the body frame (its centre of mass the origin) [m], or None for
    /// another shape.
    fn body_vertices(&self) -> Option<Vec<(f64, f64, f64)>> {
        match &self.scene.shape {
            Shape::Mesh(m) => Some(m.vertices.iter().map(|v| (v.x, v.y, v.z)).collect()),
            _ => None,
        }
    }

    /// The lowest point's offset from the centre of mass at the initial orientation [m]
    /// (world axes).
    fn lowest_offset(&self) -> (f64, f64, f64) {
        let q = self.scene.orientation;
        let r = nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
            q[0], q[1], q[2], q[3],
        ));
        let p = self
            .scene
            .shape
            .lowest_point(&nalgebra::Vector3::zeros(), &r);
        (p.x, p.y, p.z)
    }
}

/// Convert and check a scene dict of `granrs.space.Scene` (the typed error of its first bad
/// field, before any work).
#[pyfunction]
pub(super) fn space_scene(py: Python<'_>, scene: &Bound<'_, PyDict>) -> PyResult<SpaceScene> {
    let scene = scene_of(scene).map_err(|e| to_pyerr(py, e))?;
    let (mut body, _, _) = scene.build().map_err(|e| to_pyerr(py, e))?;
    body.sand.report_areas = true;
    Ok(SpaceScene {
        scene,
        body: std::sync::Mutex::new(body),
    })
}

/// Run a checked scene with the GIL released: a dict with `status`, `summary` (the fields of
/// `SPACE_SUMMARY`), `series` (the columns of `SPACE_SERIES`, or None) and `run_seconds`.
#[pyfunction]
pub(super) fn space_run<'py>(
    py: Python<'py>,
    scene: &Bound<'py, SpaceScene>,
) -> PyResult<Bound<'py, PyDict>> {
    let (mut body, y0, opts) = scene.get().scene.build().map_err(|e| to_pyerr(py, e))?;
    let (out, seconds) = watched(py, move || body.run(y0, &opts))?;
    let out = out.map_err(|e| to_pyerr(py, e))?;
    let summary = PyDict::new(py);
    for f in SUMMARY {
        summary.set_item(f.name, (f.read)(&out))?;
    }
    let series = if out.series.is_empty() {
        py.None().into_bound(py)
    } else {
        let s = PyDict::new(py);
        for c in SERIES {
            let col: Vec<f64> = out.series.iter().map(c.read).collect();
            s.set_item(c.name, col.into_pyarray(py))?;
        }
        s.into_any()
    };
    let q = out.end.rotation();
    Ok(py_dict!(py, {
        "status": out.status.name(),
        "summary": summary,
        "series": series,
        "orientation_end": (q.w, q.i, q.j, q.k),
        "run_seconds": seconds,
    }))
}

/// The sand's load on the scene's body at a pose and motion, as the fields of
/// `granrs.space.Load` (a dict that becomes its instance's own): `force` and `moment`
/// (about the centre of mass) [N, N m], `terms` (each listed sand term's share, in the
/// order rft3d, rft3d_inertial, poncelet), the wetted and projected areas, the element
/// count and, with `error`, the quadrature's error estimate (the change when its nodes are
/// doubled) of the force and the moment (NaN without). Its keys are interned: built at
/// every call without a new string.
#[pyfunction]
#[pyo3(signature = (scene, position, orientation, velocity, omega, error=true))]
pub(super) fn space_load<'py>(
    py: Python<'py>,
    scene: &Bound<'py, SpaceScene>,
    position: &Bound<'py, PyAny>,
    orientation: &Bound<'py, PyAny>,
    velocity: &Bound<'py, PyAny>,
    omega: &Bound<'py, PyAny>,
    error: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let scene = scene.get();
    let state = (|| -> Res<crate::space::solve::State> {
        state_of(
            numbers::<3>(position, "position")?,
            numbers::<4>(orientation, "orientation")?,
            numbers::<3>(velocity, "velocity")?,
            numbers::<3>(omega, "omega")?,
        )
    })()
    .map_err(|e| to_pyerr(py, e))?;
    let r = state.rotation();
    let w = r * state.w;
    let (load, ef, em, listed) = py.detach(|| {
        let mut body = scene.body.lock().unwrap_or_else(|p| p.into_inner());
        let t = &body.sand.terms;
        let listed = [
            t.rft3d.is_some(),
            t.inertial.is_some(),
            t.poncelet.is_some(),
        ];
        let (load, ef, em) = if error {
            load_with_error(&mut body.sand, &state.c, &r, &state.v, &w)
        } else {
            (
                body.sand.load(&state.c, &r, &state.v, &w),
                f64::NAN,
                f64::NAN,
            )
        };
        (load, ef, em, listed)
    });
    let v3 = |v: nalgebra::Vector3<f64>| (v.x, v.y, v.z);
    let terms = PyDict::new(py);
    let shares = [
        (intern!(py, "rft3d"), load.rft3d),
        (intern!(py, "rft3d_inertial"), load.inertial),
        (intern!(py, "poncelet"), load.poncelet),
    ];
    for ((name, share), on) in shares.into_iter().zip(listed) {
        if on {
            terms.set_item(name, v3(share))?;
        }
    }
    let d = PyDict::new(py);
    d.set_item(intern!(py, "force"), v3(load.force))?;
    d.set_item(intern!(py, "moment"), v3(load.moment))?;
    d.set_item(intern!(py, "terms"), terms)?;
    d.set_item(intern!(py, "wetted_area"), load.wetted_area)?;
    d.set_item(intern!(py, "projected_area"), load.projected_area)?;
    d.set_item(intern!(py, "elements"), load.elements)?;
    d.set_item(intern!(py, "force_error"), ef)?;
    d.set_item(intern!(py, "moment_error"), em)?;
    Ok(d)
}

/// Each summary field of a run in space: (name, unit, description).
pub(super) fn summary_fields() -> Vec<(&'static str, &'static str, &'static str)> {
    SUMMARY
        .iter()
        .map(|f| (f.name, f.unit, f.description))
        .collect()
}

/// Each series column of a run in space: (name, unit, description).
pub(super) fn series_columns() -> Vec<(&'static str, &'static str, &'static str)> {
    SERIES
        .iter()
        .map(|f| (f.name, f.unit, f.description))
        .collect()
}

/// 3D-RFT's material scale xi_n [N/m^3] from the medium's critical-state density rho_c
/// [kg/m^3] and internal friction mu [-] (`forces::rft3d::xi_n`).
#[pyfunction]
pub(super) fn xi_n(rho_c: f64, mu: f64) -> f64 {
    crate::forces::rft3d::xi_n(rho_c, mu)
}

/// The generic 3D-RFT stress (dimensionless) on an element with outward unit normal `n`
/// moving with velocity `v` (zero on trailing elements).
#[pyfunction]
pub(super) fn rft3d_alpha(n: [f64; 3], v: [f64; 3], grazing: bool) -> (f64, f64, f64) {
    let law = crate::forces::rft3d::Rft3d {
        zeta: 1.0,
        mu_surf: f64::INFINITY,
        grazing,
    }
    .lanes::<f64>();
    let a = crate::forces::rft3d::stress(&law, n, v);
    (a[0], a[1], a[2])
}
