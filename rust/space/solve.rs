//! A free rigid body in space, driven by the sand's terms and gravity: its state, Euler's
//! equations, the classical RK4 on the fixed grid `t_n = n dt`, and the events.
//!
//! The state is the centre of mass `c` and its velocity `v` (world frame), the orientation
//! as a unit quaternion `q` (body to world; renormalised after every step, so it stays
//! unit to round-off) and the angular velocity `w` in the body frame:
//!
//! ```text
//! dc/dt = v          m dv/dt = F_sand + F_gravity
//! dq/dt = q (0, w) / 2      I dw/dt = M_sand,body - w x I w     (Euler's equations)
//! ```
//!
//! Events, located inside the step on the step map itself (RK4 from the step's start over a
//! shorter step, by Illinois) and restarted from there:
//! - **entry**: the lowest point reaches the surface (the sand's force starts there);
//! - **stop**: the lowest point's vertical velocity turns >= 0 after moving down, in the
//!   sand. The run ends there (`Status::Stopped`), as a planar run does: 3D-RFT, like the
//!   planar law, gives no force at zero speed, so what holds a body at rest is not the
//!   law's to say; granrs reports the stop and the load at it, and does not integrate a
//!   resting body (which would then creep or chatter under any speed-independent law).
//!
//! `h_lambda` is the step times the fastest rate the sand gives the body's centre: the
//! spring rate `sqrt(K / m)` with `K = 2 |F_rft3d| / d` (exact for a force growing as the
//! depth squared, an upper bound for one growing more slowly) and the damping rate
//! `2 (|F_inertial| + c rho_g A |v|^2) / (m |v|)` of the forces that grow as the velocity
//! squared (poncelet's depth term `k d` does not grow with the speed: it has no rate along
//! the motion); the Python layer warns above RK4's stability limit.

use std::f64::consts::PI;

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::load::{Load, Sand};
use crate::error::{GranrsError, Result};
use crate::integrate::cancel;
use crate::integrate::events::locate;

type V3 = Vector3<f64>;

/// A rigid body's mass properties.
#[derive(Debug, Clone, PartialEq)]
pub struct Inertia {
    /// Mass [kg].
    pub mass: f64,
    /// Inertia tensor about the centre of mass, body frame [kg m^2].
    pub tensor: Matrix3<f64>,
    /// Its inverse.
    pub inverse: Matrix3<f64>,
}

impl Inertia {
    /// Mass properties, checked: a positive, finite mass; a symmetric, positive definite,
    /// finite tensor (its fields named `{field}.mass` and `{field}.inertia`).
    pub fn new(field: &str, mass: f64, tensor: Matrix3<f64>) -> Result<Inertia> {
        if !(mass.is_finite() && mass > 0.0 && mass < 1e12) {
            return Err(GranrsError::InvalidParameter {
                field: format!("{field}.mass"),
                value: mass,
                allowed: "finite, > 0, < 1e12 (mass [kg])".into(),
            });
        }
        let bad = |message: String| GranrsError::InvalidScene {
            field: format!("{field}.inertia"),
            message,
        };
        if tensor.iter().any(|x| !x.is_finite()) {
            return Err(bad("every entry must be finite [kg m^2]".into()));
        }
        let scale = tensor.abs().max();
        if (tensor - tensor.transpose()).abs().max() > 1e-12 * scale {
            return Err(bad("the inertia tensor must be symmetric".into()));
        }
        let eig = tensor.symmetric_eigenvalues();
        let (lo, hi) = (eig.min(), eig.max());
        if !(lo > 1e-12 * hi && hi > 0.0) {
            return Err(bad(format!(
                "the inertia tensor must be positive definite (its eigenvalues are {:.3e}, {:.3e}, \
                 {:.3e} kg m^2)",
                eig[0], eig[1], eig[2]
            )));
        }
        // The triangle inequality of a real body's principal moments.
        let mut e: Vec<f64> = eig.iter().copied().collect();
        e.sort_by(f64::total_cmp);
        if e[0] + e[1] < e[2] * (1.0 - 1e-9) {
            return Err(bad(format!(
                "no rigid body has these principal moments ({:.3e} + {:.3e} < {:.3e} kg m^2)",
                e[0], e[1], e[2]
            )));
        }
        let inverse = tensor
            .try_inverse()
            .ok_or_else(|| bad("the inertia tensor is singular".into()))?;
        Ok(Inertia {
            mass,
            tensor,
            inverse,
        })
    }
}

/// The body's state (see the module's doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    /// Centre of mass, world [m].
    pub c: V3,
    /// Orientation, body to world (unit between steps).
    pub q: Quaternion<f64>,
    /// Velocity of the centre, world [m/s].
    pub v: V3,
    /// Angular velocity, body frame [rad/s].
    pub w: V3,
}

#[derive(Debug, Clone, Copy)]
struct Deriv {
    c: V3,
    q: Quaternion<f64>,
    v: V3,
    w: V3,
}

impl State {
    fn add(&self, h: f64, d: &Deriv) -> State {
        State {
            c: self.c + h * d.c,
            q: self.q + d.q * h,
            v: self.v + h * d.v,
            w: self.w + h * d.w,
        }
    }

    /// The orientation as a unit quaternion.
    pub fn rotation(&self) -> UnitQuaternion<f64> {
        UnitQuaternion::new_normalize(self.q)
    }

    /// The angular velocity in the world frame [rad/s].
    pub fn omega(&self) -> V3 {
        self.rotation() * self.w
    }

    fn is_finite(&self) -> bool {
        self.c
            .iter()
            .chain(self.v.iter())
            .chain(self.w.iter())
            .all(|x| x.is_finite())
            && self.q.coords.iter().all(|x| x.is_finite())
    }
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// The lowest point stopped moving down in the sand.
    Stopped,
    /// `t_end` came first.
    NotStopped,
}

impl Status {
    /// Its name, as Python shows it.
    pub fn name(self) -> &'static str {
        match self {
            Status::Stopped => "stopped",
            Status::NotStopped => "not_stopped",
        }
    }
}

/// What a run asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// The step [s].
    pub dt: f64,
    /// The end time [s].
    pub t_end: f64,
    /// Whether the run ends at the stop (else it runs on to `t_end`, through the stop).
    pub end_at_stop: bool,
    /// Whether to record the series (every step and event).
    pub record: bool,
}

/// One recorded instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time [s].
    pub t: f64,
    /// The state.
    pub state: State,
    /// The sand's load.
    pub load: Load,
    /// The lowest point's depth (negative above the surface) [m].
    pub depth: f64,
    /// The mechanical energy [J].
    pub energy: f64,
}

/// What a run gives.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// How it ended.
    pub status: Status,
    /// The time it ended [s].
    pub t_end: f64,
    /// The time of the stop [s] (NaN: none).
    pub t_s: f64,
    /// The time the lowest point entered the sand [s] (NaN: never; 0: it started in).
    pub t_entry: f64,
    /// The end state.
    pub end: State,
    /// The sand's load at the end.
    pub load_end: Load,
    /// The lowest point's depth at the end [m].
    pub depth: f64,
    /// The deepest the lowest point went [m].
    pub max_depth: f64,
    /// The largest magnitude of the sand's force [N].
    pub force_max: f64,
    /// The mechanical energy at the start and at the end [J] (kinetic, and potential
    /// m g z where gravity acts).
    pub energy_start: f64,
    /// See `energy_start`.
    pub energy_end: f64,
    /// The largest step times the sand's fastest rate (see the module's doc).
    pub h_lambda: f64,
    /// Steps taken (the event restarts included).
    pub steps: usize,
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
    /// Events handled (entries and the stop).
    pub events: usize,
    /// The largest number of surface elements in an evaluation.
    pub max_elements: usize,
    /// The recorded series (empty unless asked for).
    pub series: Vec<Sample>,
}

/// A free rigid body in the sand.
#[derive(Debug, Clone)]
pub struct Body {
    /// Its mass properties.
    pub inertia: Inertia,
    /// The sand (its shape, the terms, the medium, the surface, the rule).
    pub sand: Sand,
    /// The fastest rate of the sand seen at any evaluation of the run so far [1/s]
    /// (every stage, so that a step that goes in and out of stiff sand is seen).
    pub fastest_rate: f64,
}

impl Body {
    /// The derivative at `y`, and the sand's load there. `held`: the step started with the
    /// lowest point moving down in the sand, and holds that direction: where a stage finds
    /// it moving up (past the stop, which the step will locate), the law reads the velocity
    /// field with the lowest point's vertical velocity mirrored (continuous through zero),
    /// so that the step's stages see the force of the motion it started with, as the
    /// planar engine holds its signs through a step.
    fn deriv(&mut self, y: &State, held: bool) -> (Deriv, Load) {
        let r = y.rotation();
        let omega = r * y.w;
        let mut v_law = y.v;
        if held {
            let (_, vz) = self.lowest(y);
            if vz > 0.0 {
                v_law.z -= 2.0 * vz;
            }
        }
        let load = self.sand.load(&y.c, &r, &v_law, &omega);
        if load.elements > 0 {
            let rate = self.rate(y, &load);
            self.fastest_rate = self.fastest_rate.max(rate);
        }
        let mut f = load.force;
        if self.sand.terms.field != 0.0 {
            f.z -= self.inertia.mass * (self.sand.terms.field * self.sand.medium.g);
        }
        let i = &self.inertia.tensor;
        let m_body = r.inverse() * load.moment;
        let wdot = self.inertia.inverse * (m_body - y.w.cross(&(i * y.w)));
        let d = Deriv {
            c: y.v,
            q: y.q * Quaternion::from_imag(y.w) * 0.5,
            v: f / self.inertia.mass,
            w: wdot,
        };
        (d, load)
    }

    /// The mechanical energy at `y` [J].
    pub fn energy(&self, y: &State) -> f64 {
        let m = self.inertia.mass;
        let ke = 0.5 * m * y.v.norm_squared() + 0.5 * y.w.dot(&(self.inertia.tensor * y.w));
        let pe = m * (self.sand.terms.field * self.sand.medium.g) * y.c.z;
        ke + pe
    }

    /// The lowest point's height above the surface [m] and its vertical velocity [m/s].
    pub fn lowest(&self, y: &State) -> (f64, f64) {
        let r = y.rotation();
        let p = self.sand.shape.lowest_point(&y.c, &r);
        let v = y.v + (r * y.w).cross(&(p - y.c));
        (p.z - self.sand.surface, v.z)
    }

    /// One RK4 step of `h` from `y` (its first stage given), the orientation renormalised.
    fn rk4(&mut self, y: &State, k1: &Deriv, h: f64, held: bool, evals: &mut usize) -> State {
        let (k2, _) = self.deriv(&y.add(0.5 * h, k1), held);
        let (k3, _) = self.deriv(&y.add(0.5 * h, &k2), held);
        let (k4, _) = self.deriv(&y.add(h, &k3), held);
        *evals += 3;
        let mut out = State {
            c: y.c + h / 6.0 * (k1.c + 2.0 * k2.c + 2.0 * k3.c + k4.c),
            q: y.q + (k1.q + k2.q * 2.0 + k3.q * 2.0 + k4.q) * (h / 6.0),
            v: y.v + h / 6.0 * (k1.v + 2.0 * k2.v + 2.0 * k3.v + k4.v),
            w: y.w + h / 6.0 * (k1.w + 2.0 * k2.w + 2.0 * k3.w + k4.w),
        };
        out.q = out.q.normalize();
        out
    }

    /// Run from `y0` at t = 0.
    pub fn run(&mut self, y0: State, opts: &Options) -> Result<Outcome> {
        let dt = opts.dt;
        let n_steps = (opts.t_end / dt - 1e-9).ceil().max(1.0) as u64;
        let mut y = State {
            q: y0.q.normalize(),
            ..y0
        };
        let mut t = 0.0;
        let mut evals = 0usize;
        let (mut steps, mut events) = (0usize, 0usize);
        let (k, load0) = self.deriv(&y, false);
        let mut k1 = k;
        let mut load = load0;
        evals += 1;
        let energy_start = self.energy(&y);
        let (h0, _) = self.lowest(&y);
        let mut t_entry = if h0 < 0.0 { 0.0 } else { f64::NAN };
        let mut max_depth = (-h0).max(0.0);
        let mut force_max = load.force.norm();
        let mut h_lambda = 0.0f64;
        let mut max_elements = load.elements;
        let mut t_s = f64::NAN;
        let mut status = Status::NotStopped;
        let mut series = Vec::new();
        let sample = |body: &Body, t: f64, y: &State, load: &Load| Sample {
            t,
            state: *y,
            load: *load,
            depth: -body.lowest(y).0,
            energy: body.energy(y),
        };
        if opts.record {
            series.push(sample(self, t, &y, &load));
        }
        let mut look_in = cancel::FIRST_LOOK;
        let mut n = 0u64;
        while n < n_steps {
            look_in -= 1;
            if look_in == 0 {
                let (stop, next) = cancel::look();
                if stop {
                    return Err(GranrsError::Cancelled);
                }
                look_in = next.max(1);
            }
            let t_next = if n + 1 == n_steps {
                opts.t_end
            } else {
                (n + 1) as f64 * dt
            };
            let h = t_next - t;
            let (z0, vz0) = self.lowest(&y);
            let held = z0 < 0.0 && vz0 < 0.0 && t_s.is_nan();
            let mut y1 = self.rk4(&y, &k1, h, held, &mut evals);
            steps += 1;
            if !y1.is_finite() {
                return Err(GranrsError::NonFinite {
                    t: t_next,
                    message: "the body's state became non-finite (is dt too large for the \
                              sand's stiffness? see h_lambda)"
                        .into(),
                });
            }
            let (z1, vz1) = self.lowest(&y1);
            let mut t1 = t_next;
            let mut stopped = false;
            if z0 >= 0.0 && z1 < 0.0 {
                // Entry: locate z = 0 on the step map.
                let (theta, e) = if z0 == 0.0 {
                    (0.0, 0)
                } else {
                    let y_ = y;
                    let k_ = k1;
                    locate(
                        |th| {
                            let yt = self.rk4(&y_, &k_, th * h, held, &mut evals);
                            self.lowest(&yt).0
                        },
                        z0,
                        z1,
                        1e-13,
                    )
                };
                let _ = e;
                if theta > 0.0 && theta < 1.0 {
                    y1 = self.rk4(&y, &k1, theta * h, held, &mut evals);
                    t1 = t + theta * h;
                }
                if t_entry.is_nan() {
                    // On the surface at the step's start (theta = 0): it enters there.
                    t_entry = if theta == 0.0 { t } else { t1 };
                }
                events += 1;
            } else if z1 < 0.0 && vz0 < 0.0 && vz1 >= 0.0 && t_s.is_nan() {
                // The stop: vz = 0 after moving down, in the sand.
                let theta = if vz1 == 0.0 {
                    1.0
                } else {
                    let y_ = y;
                    let k_ = k1;
                    locate(
                        |th| {
                            let yt = self.rk4(&y_, &k_, th * h, held, &mut evals);
                            -self.lowest(&yt).1
                        },
                        -vz0,
                        -vz1,
                        1e-13,
                    )
                    .0
                };
                if theta < 1.0 {
                    y1 = self.rk4(&y, &k1, theta * h, held, &mut evals);
                    t1 = t + theta * h;
                }
                t_s = t1;
                events += 1;
                stopped = true;
            }
            y = y1;
            t = t1;
            let (k, l) = self.deriv(&y, false);
            evals += 1;
            k1 = k;
            load = l;
            let depth = -self.lowest(&y).0;
            max_depth = max_depth.max(depth);
            force_max = force_max.max(load.force.norm());
            max_elements = max_elements.max(load.elements);
            h_lambda = h_lambda.max(dt * self.fastest_rate);
            if opts.record {
                series.push(sample(self, t, &y, &load));
            }
            if stopped && opts.end_at_stop {
                status = Status::Stopped;
                break;
            }
            if t >= t_next {
                n += 1;
            }
            if stopped {
                status = Status::Stopped;
            }
        }
        let depth = -self.lowest(&y).0;
        // The load at the end with its areas (a run does not compute them on the way).
        let reported = self.sand.report_areas;
        self.sand.report_areas = true;
        let (_, load) = self.deriv(&y, false);
        self.sand.report_areas = reported;
        Ok(Outcome {
            status,
            t_end: t,
            t_s,
            t_entry,
            end: y,
            load_end: load,
            depth,
            max_depth,
            force_max,
            energy_start,
            energy_end: self.energy(&y),
            h_lambda,
            steps,
            rhs_evals: evals,
            events,
            max_elements,
            series,
        })
    }

    /// The sand's fastest rate at the centre [1/s] (see the module's doc).
    fn rate(&self, y: &State, load: &Load) -> f64 {
        let m = self.inertia.mass;
        let depth = -self.lowest(y).0;
        let spring = if depth > 0.0 {
            (2.0 * load.rft3d.norm() / depth / m).sqrt()
        } else {
            0.0
        };
        let speed = y.v.norm();
        // The velocity-squared forces' rate, 2 |F| / (m |v|): the inertial term's, and
        // poncelet's drag c rho_g A |v|^2 (its depth term k d, which does not grow with
        // the speed, has no rate along the motion).
        let quadratic = self.sand.terms.poncelet.map_or(0.0, |p| {
            p.c * self.sand.medium.rho_g * load.projected_area * speed * speed
        });
        let damping = if speed > 0.0 {
            2.0 * (load.inertial.norm() + quadratic) / (m * speed)
        } else {
            0.0
        };
        spring.max(damping)
    }
}

/// The angle between two orientations [rad] (for the tests and the summaries).
pub fn angle_between(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> f64 {
    let d = a.inverse() * b;
    let a = d.angle();
    if a > PI {
        2.0 * PI - a
    } else {
        a
    }
}
