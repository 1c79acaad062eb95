//! Bodies in space: a free rigid body of any shape (sphere, capsule, cylinder, cuboid,
//! closed triangle mesh) falling into sand under the terms that act in three dimensions
//! (`rft3d`, `rft3d_inertial`, `poncelet`, `gravity`).
//!
//! The frame is granrs's planar one extended: x right, y into the page, z up; the sand's
//! surface is the plane `z = surface` (0 unless a scene says otherwise), depth is measured
//! down from it. A planar scene's (x, y) is this frame's (x, z).
//!
//! - [`shape`]: the shapes, their mass properties, and the exact cut of their surface
//!   below the sand into quadrature elements ([`quad`]: the rules and the cuts);
//! - [`load`]: the terms over the elements (the force and the moment);
//! - [`solve`]: the rigid body, RK4 and the events;
//! - [`Scene3`]: what a run is, checked field by field before any work.

pub mod engine;
pub mod load;
pub mod outputs;
pub mod quad;
pub mod shape;
pub mod solve;

use nalgebra::{Matrix3, Quaternion, Vector3};

use crate::error::{GranrsError, Result};
use crate::forces::{Medium, TermSpec};
use load::{Sand, Terms3};
use shape::{Quadrature, Shape};
use solve::{Body, Inertia, Options, State};

/// How a body's mass is given.
#[derive(Debug, Clone, PartialEq)]
pub enum MassSpec {
    /// A uniform density [kg/m^3]: the mass and the inertia follow from the shape.
    Density(f64),
    /// A mass [kg], uniform over the shape (the inertia follows from the shape).
    Mass(f64),
    /// A mass [kg] and an inertia tensor about the centre of mass, body frame [kg m^2].
    Given(f64, [[f64; 3]; 3]),
}

/// A run of a body in space, as a user gives it (every field checked by [`Scene3::build`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Scene3 {
    /// The body's shape.
    pub shape: Shape,
    /// Its mass.
    pub mass: MassSpec,
    /// The centre of mass at t = 0 [m].
    pub position: [f64; 3],
    /// The orientation at t = 0, a unit quaternion (w, x, y, z), body to world.
    pub orientation: [f64; 4],
    /// The centre's velocity at t = 0 [m/s].
    pub velocity: [f64; 3],
    /// The angular velocity at t = 0, world frame [rad/s].
    pub omega: [f64; 3],
    /// The terms that act.
    pub forces: Vec<TermSpec>,
    /// The medium.
    pub medium: Medium,
    /// The sand's surface z [m].
    pub surface: f64,
    /// The step [s].
    pub dt: f64,
    /// The end time [s].
    pub t_end: f64,
    /// Whether the run ends at the stop.
    pub end_at_stop: bool,
    /// Whether to record the series.
    pub record: bool,
    /// Gauss-Legendre nodes per panel of a curved surface.
    pub nodes: usize,
}

/// Whether `v` is finite and in `[lo, hi]`.
#[inline]
fn within(v: f64, lo: f64, hi: f64) -> bool {
    v.is_finite() && v >= lo && v <= hi
}

fn finite(field: &str, v: f64, lo: f64, hi: f64, what: &str) -> Result<f64> {
    if within(v, lo, hi) {
        Ok(v)
    } else {
        Err(GranrsError::InvalidParameter {
            field: field.into(),
            value: v,
            allowed: format!("finite, in [{lo:e}, {hi:e}] ({what})"),
        })
    }
}

/// [`finite`] on each entry `field[k]` of `v` (an entry's name is written out only for its
/// error: a state is checked at every call of `space.load`).
fn each_finite<const N: usize>(
    field: &str,
    v: [f64; N],
    lo: f64,
    hi: f64,
    what: &str,
) -> Result<[f64; N]> {
    for (k, x) in v.iter().enumerate() {
        if !within(*x, lo, hi) {
            finite(&format!("{field}[{k}]"), *x, lo, hi, what)?;
        }
    }
    Ok(v)
}

fn vector(field: &str, v: [f64; 3], bound: f64, what: &str) -> Result<Vector3<f64>> {
    Ok(Vector3::from(each_finite(field, v, -bound, bound, what)?))
}

impl Scene3 {
    /// The checked scene: the body, its state at t = 0 and the run's options. Every field
    /// is checked before any work; an error names the first bad one.
    pub fn build(&self) -> Result<(Body, State, Options)> {
        let state = self.state()?;
        let rho_g = finite(
            "rho_g",
            self.medium.rho_g,
            0.0,
            1e5,
            "bulk density [kg/m^3]",
        )?;
        let g = finite("g", self.medium.g, 0.0, 1e4, "gravity [m/s^2]")?;
        let surface = finite(
            "surface",
            self.surface,
            -1e6,
            1e6,
            "the sand's surface z [m]",
        )?;
        let dt = finite("dt", self.dt, 1e-9, 1.0, "the step [s]")?;
        let t_end = finite("t_end", self.t_end, 0.0, 1e6, "[s]")?;
        if t_end <= 0.0 || t_end / dt > 1e9 {
            return Err(GranrsError::InvalidParameter {
                field: "t_end".into(),
                value: t_end,
                allowed: format!("> 0 and at most 1e9 steps of dt (<= {:.3e} s)", 1e9 * dt),
            });
        }
        if self.nodes < 1 || self.nodes > Quadrature::MAX_NODES {
            return Err(GranrsError::InvalidParameter {
                field: "quadrature".into(),
                value: self.nodes as f64,
                allowed: format!(
                    "an integer in 1..={} (nodes per panel)",
                    Quadrature::MAX_NODES
                ),
            });
        }
        let terms = Terms3::from_specs(&self.forces, &self.shape)?;
        let volume = self.shape.volume();
        let unit = self.shape.unit_inertia();
        let inertia = match &self.mass {
            MassSpec::Density(rho) => {
                let rho = finite("body.density", *rho, 1e-6, 1e6, "[kg/m^3]")?;
                let mass = rho * volume;
                if !(1e-12..=1e12).contains(&mass) {
                    return Err(GranrsError::InvalidParameter {
                        field: "body.density".into(),
                        value: rho,
                        allowed: format!(
                            "a density that gives the shape of {volume:.3e} m^3 a mass in \
                             [1e-12, 1e12] kg (this one gives {mass:.3e} kg)"
                        ),
                    });
                }
                Inertia::new("body", mass, unit * rho)?
            }
            MassSpec::Mass(m) => {
                let m = finite("body.mass", *m, 1e-12, 1e12, "[kg]")?;
                Inertia::new("body", m, unit * (m / volume))?
            }
            MassSpec::Given(m, t) => {
                let m = finite("body.mass", *m, 1e-12, 1e12, "[kg]")?;
                Inertia::new("body", m, Matrix3::from_fn(|i, j| t[i][j]))?
            }
        };
        let sand = Sand::new(
            self.shape.clone(),
            terms,
            Medium { rho_g, g },
            surface,
            Quadrature::new(self.nodes),
        );
        let opts = Options {
            dt,
            t_end,
            end_at_stop: self.end_at_stop,
            record: self.record,
        };
        Ok((
            Body {
                inertia,
                sand,
                fastest_rate: 0.0,
            },
            state,
            opts,
        ))
    }
}

impl Scene3 {
    /// The body's state at t = 0 from the scene's `position`, `orientation`, `velocity` and
    /// `omega`, each checked (an error names the first bad one).
    pub fn state(&self) -> Result<State> {
        state_of(self.position, self.orientation, self.velocity, self.omega)
    }
}

/// A body's state from its `position` [m], `orientation` (a unit quaternion w, x, y, z),
/// `velocity` [m/s] and `omega` (world frame) [rad/s], each checked and named as a scene's
/// field.
pub fn state_of(
    position: [f64; 3],
    orientation: [f64; 4],
    velocity: [f64; 3],
    omega: [f64; 3],
) -> Result<State> {
    // Wide enough for the default placement (the surface plus a size) of any shape.
    let c = vector("position", position, 1e7, "[m]")?;
    let q = each_finite(
        "orientation",
        orientation,
        -2.0,
        2.0,
        "a unit quaternion (w, x, y, z)",
    )?;
    let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if (norm - 1.0).abs() > 1e-6 {
        return Err(GranrsError::InvalidScene {
            field: "orientation".into(),
            message: format!(
                "a unit quaternion (w, x, y, z) is needed; this one has norm {norm:.9} \
                 (normalise it first)"
            ),
        });
    }
    let v = vector("velocity", velocity, 1e4, "[m/s]")?;
    let w = vector("omega", omega, 1e5, "[rad/s]")?;
    let qn = Quaternion::new(q[0], q[1], q[2], q[3]).normalize();
    let rot = nalgebra::UnitQuaternion::new_unchecked(qn);
    Ok(State {
        c,
        q: qn,
        v,
        w: rot.inverse() * w,
    })
}

#[cfg(test)]
mod tests;
