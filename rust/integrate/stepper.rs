//! The steppers (diffrax's `AbstractSolver.step`): one step of the classical fourth-order
//! Runge-Kutta method or of the adaptive Dormand-Prince 5(4) pair on the body's state, its
//! end, its error estimate (Dopri5), and its dense output (the cubic Hermite interpolant
//! through both ends and their derivatives, free with RK4: the end derivative is the next
//! step's first stage).
//!
//! The state is the generalized coordinates, their rates, and the work done by the sand
//! on the body (integrated alongside, so that the energy balance can be checked against an
//! independent quadrature). The modes are held fixed through a step.

use nalgebra::SVector;

use super::outcome::Stats;
use crate::dynamics::{DragStiffness, Eval, Model, Modes};

/// The smallest relative tolerance of Dopri5: 100 times f64's epsilon (2.2e-14), the floor
/// of MATLAB's ode45 and SciPy's RK45. Below it a step's own round-off is a fair part of
/// what the tolerance allows, and the step-size control chases it down to nothing.
pub const RTOL_MIN: f64 = 100.0 * f64::EPSILON;

/// The time stepper.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Classical RK4 on the fixed grid `n dt` (default; the thesis ran at 10 kHz).
    Rk4,
    /// Adaptive Dormand-Prince 5(4): tolerances instead of a step; `dt` is the first step.
    Dopri5 {
        /// Relative tolerance (at least [`RTOL_MIN`]).
        rtol: f64,
        /// Absolute tolerance [SI units of each coordinate].
        atol: f64,
    },
}

/// The integrated state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State<const N: usize> {
    /// Generalized coordinates [m, m, rad...].
    pub q: SVector<f64, N>,
    /// Their rates [m/s, m/s, rad/s...].
    pub qd: SVector<f64, N>,
    /// Work done by the sand on the body since the start [J] (non-positive at E).
    pub work: f64,
    /// Energy dissipated by the joints' dampers since the start [J] (non-negative).
    pub dissipated: f64,
}

/// The time derivative of a [`State`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Deriv<const N: usize> {
    /// dq/dt.
    pub q: SVector<f64, N>,
    /// d(qd)/dt.
    pub qd: SVector<f64, N>,
    /// Power of the sand's forces [W].
    pub work: f64,
    /// Power dissipated by the joints [W].
    pub dissipated: f64,
}

impl<const N: usize> State<N> {
    /// `self + h * d`, component by component (nalgebra's scalar-vector product measured
    /// about 130 instructions per RK4 step more than the plain loop).
    #[inline]
    pub fn add(&self, h: f64, d: &Deriv<N>) -> State<N> {
        State {
            q: SVector::from_fn(|i, _| self.q[i] + h * d.q[i]),
            qd: SVector::from_fn(|i, _| self.qd[i] + h * d.qd[i]),
            work: self.work + h * d.work,
            dissipated: self.dissipated + h * d.dissipated,
        }
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.q.iter().all(|v| v.is_finite())
            && self.qd.iter().all(|v| v.is_finite())
            && self.work.is_finite()
            && self.dissipated.is_finite()
    }
}

/// Derivative of the state from an evaluation.
#[inline]
pub fn deriv_of<const N: usize>(y: &State<N>, e: &Eval<N>) -> Deriv<N> {
    Deriv {
        q: y.qd,
        qd: e.qdd,
        work: e.power,
        dissipated: e.joint_power,
    }
}

/// One RK4 step of size `h` from `y`, whose derivative `k1` is already known.
/// Costs three evaluations.
#[inline]
pub fn step<const N: usize>(
    model: &Model<N>,
    modes: &Modes,
    y: &State<N>,
    k1: &Deriv<N>,
    h: f64,
) -> State<N> {
    step_sampling(model, modes, y, k1, h, |_, _| {}).0
}

/// [`step`], showing `sample` each stage's coordinates and the drag's stiffest contact
/// there: a step that does not resolve the contact meets, at its stages, a stiffness its
/// ends do not show. Returns the end and the fourth stage `k4`, whose difference from the
/// derivative at the end is the step's error estimate ([`companion`]).
#[inline]
pub fn step_sampling<const N: usize>(
    model: &Model<N>,
    modes: &Modes,
    y: &State<N>,
    k1: &Deriv<N>,
    h: f64,
    mut sample: impl FnMut(&SVector<f64, N>, &DragStiffness),
) -> (State<N>, Deriv<N>) {
    let mut f = |s: &State<N>| {
        let (qdd, power, joint_power, stiff) = model.rates_sampled(&s.q, &s.qd, modes);
        sample(&s.q, &stiff);
        Deriv {
            q: s.qd,
            qd: qdd,
            work: power,
            dissipated: joint_power,
        }
    };
    let y2 = y.add(0.5 * h, k1);
    let k2 = f(&y2);
    let y3 = y.add(0.5 * h, &k2);
    let k3 = f(&y3);
    let y4 = y.add(h, &k3);
    let k4 = f(&y4);
    let s6 = h / 6.0;
    // Component by component, in the same order of operations as the vector form.
    let y1 = State {
        q: SVector::from_fn(|i, _| {
            y.q[i] + s6 * (k1.q[i] + 2.0 * k2.q[i] + 2.0 * k3.q[i] + k4.q[i])
        }),
        qd: SVector::from_fn(|i, _| {
            y.qd[i] + s6 * (k1.qd[i] + 2.0 * k2.qd[i] + 2.0 * k3.qd[i] + k4.qd[i])
        }),
        work: y.work + (h / 6.0) * (k1.work + 2.0 * k2.work + 2.0 * k3.work + k4.work),
        dissipated: y.dissipated
            + (h / 6.0)
                * (k1.dissipated + 2.0 * k2.dissipated + 2.0 * k3.dissipated + k4.dissipated),
    };
    (y1, k4)
}

/// The error estimate of an RK4 step of size `h` whose fourth stage is `k4` and whose end's
/// derivative is `k5` (the next step's first stage, evaluated anyway): `h / 6 (k4 - k5)`,
/// per coordinate and rate. It is the difference between RK4 and the third-order method
/// that replaces its last stage by the end's derivative (weights 1/6, 1/3, 1/3, 0, 1/6; it
/// meets the four order conditions up to order 3), so it is of order h^4 where the
/// right-hand side is smooth through the step (a bound on RK4's own error, of order h^5),
/// and of order h times the jump where the force changes abruptly between the fourth stage
/// and the end (an element's or E's velocity through zero, a speed a step does not
/// resolve). No evaluation: both stages exist. A step cut at a located event takes the
/// whole step's, scaled (`Observer::cut_step_error`): its own end lies on the event's
/// switching function, where the held mode's force need not be a function of the state.
#[inline(always)]
pub fn companion<const N: usize>(
    h: f64,
    k4: &Deriv<N>,
    k5: &Deriv<N>,
) -> (SVector<f64, N>, SVector<f64, N>) {
    let s6 = h / 6.0;
    (
        SVector::from_fn(|i, _| s6 * (k4.q[i] - k5.q[i])),
        SVector::from_fn(|i, _| s6 * (k4.qd[i] - k5.qd[i])),
    )
}

/// The Dormand-Prince 5(4) pair (Dormand & Prince 1980, J. Comput. Appl. Math. 6:19-26;
/// coefficients as tabulated in Hairer, Norsett & Wanner, Solving ODEs I, table 5.2).
mod dp {
    pub const A: [[f64; 6]; 7] = [
        [0.0; 6],
        [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
        [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
        [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
            0.0,
            0.0,
        ],
        [
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
            0.0,
        ],
        [
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
        ],
    ];
    /// b - b*: the 5th-order weights less the embedded 4th-order ones.
    pub const E: [f64; 7] = [
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ];
}

/// One Dormand-Prince 5(4) step of size `h` from `y` with known first stage `k1`.
/// Returns the 5th-order solution, its derivative there (the FSAL stage, costing the
/// step's sixth evaluation) and the error estimate's weighted RMS norm with tolerances
/// `rtol`, `atol` over the coordinates and rates.
#[allow(clippy::too_many_arguments)]
pub fn dopri5_step<const N: usize>(
    model: &Model<N>,
    modes: &Modes,
    y: &State<N>,
    k1: &Deriv<N>,
    h: f64,
    rtol: f64,
    atol: f64,
) -> (State<N>, Eval<N>, f64) {
    let mut k: [Deriv<N>; 6] = [*k1; 6];
    for s in 1..6 {
        let mut ys = *y;
        for (j, kj) in k.iter().enumerate().take(s) {
            let a = dp::A[s][j];
            if a != 0.0 {
                ys = ys.add(h * a, kj);
            }
        }
        let (qdd, power, joint_power) = model.rates(&ys.q, &ys.qd, modes);
        k[s] = Deriv {
            q: ys.qd,
            qd: qdd,
            work: power,
            dissipated: joint_power,
        };
    }
    // The solution is the seventh stage's argument (FSAL): y1 = y + h sum_j a_7j k_j.
    let mut y1 = *y;
    for (j, kj) in k.iter().enumerate() {
        let a = dp::A[6][j];
        if a != 0.0 {
            y1 = y1.add(h * a, kj);
        }
    }
    let e7 = model.eval(&y1.q, &y1.qd, modes);
    let k7 = deriv_of(&y1, &e7);
    let mut sum = 0.0;
    for i in 0..N {
        let mut eq = 0.0;
        let mut ev = 0.0;
        for (s, ks) in k.iter().enumerate() {
            eq += dp::E[s] * ks.q[i];
            ev += dp::E[s] * ks.qd[i];
        }
        eq += dp::E[6] * k7.q[i];
        ev += dp::E[6] * k7.qd[i];
        let sq = atol + rtol * y.q[i].abs().max(y1.q[i].abs());
        let sv = atol + rtol * y.qd[i].abs().max(y1.qd[i].abs());
        sum += (h * eq / sq).powi(2) + (h * ev / sv).powi(2);
    }
    let err = (sum / (2 * N) as f64).sqrt();
    (y1, e7, err)
}

/// A whole step of `method` of size `h` from `y`, whose derivative `k1` is known: the new
/// state, its evaluation written into `e1`, the error estimate's weighted RMS norm (0 for
/// RK4, whose step-size is fixed) and RK4's fourth stage (for [`companion`]; `None` for
/// Dopri5). RK4 shows `sample` each stage's coordinates and the drag's stiffest contact
/// there (see [`step_sampling`]). Counts the evaluations in `stats`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn full_step<const N: usize>(
    model: &Model<N>,
    method: Method,
    modes: &Modes,
    y: &State<N>,
    k1: &Deriv<N>,
    h: f64,
    e1: &mut Eval<N>,
    stats: &mut Stats,
    sample: impl FnMut(&SVector<f64, N>, &DragStiffness),
) -> (State<N>, f64, Option<Deriv<N>>) {
    match method {
        Method::Rk4 => {
            let (y1, k4) = step_sampling(model, modes, y, k1, h, sample);
            model.eval_into(&y1.q, &y1.qd, modes, e1);
            stats.rhs_evals += 4;
            (y1, 0.0, Some(k4))
        }
        Method::Dopri5 { rtol, atol } => {
            let (y1, e, err) = dopri5_step(model, modes, y, k1, h, rtol, atol);
            stats.rhs_evals += 6;
            *e1 = e;
            (y1, err, None)
        }
    }
}

/// A step of `method` of size `h` from `y` to a located event, without the evaluation at
/// its end (RK4: three evaluations; Dopri5 spends its six), and its error estimate's
/// weighted RMS norm (0 for RK4: the run estimates such a step's error from the whole step
/// it cuts, `Observer::cut_step_error`). RK4 shows `sample` its stages.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn partial_step<const N: usize>(
    model: &Model<N>,
    method: Method,
    modes: &Modes,
    y: &State<N>,
    k1: &Deriv<N>,
    h: f64,
    stats: &mut Stats,
    sample: impl FnMut(&SVector<f64, N>, &DragStiffness),
) -> (State<N>, f64) {
    match method {
        Method::Rk4 => {
            stats.rhs_evals += 3;
            (step_sampling(model, modes, y, k1, h, sample).0, 0.0)
        }
        Method::Dopri5 { rtol, atol } => {
            stats.rhs_evals += 6;
            let (y1, _, err) = dopri5_step(model, modes, y, k1, h, rtol, atol);
            (y1, err)
        }
    }
}

/// The cubic Hermite interpolant of one step: its dense output.
#[derive(Debug, Clone, Copy)]
pub struct Hermite<const N: usize> {
    /// State at the start.
    pub y0: State<N>,
    /// Derivative at the start.
    pub f0: Deriv<N>,
    /// State at the end.
    pub y1: State<N>,
    /// Derivative at the end.
    pub f1: Deriv<N>,
    /// Step size [s].
    pub h: f64,
}

impl<const N: usize> Hermite<N> {
    /// The interpolated state at `theta` in [0, 1] of the step.
    #[inline]
    pub fn at(&self, theta: f64) -> State<N> {
        let t = theta;
        let t2 = t * t;
        let t3 = t2 * t;
        let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
        let h10 = t3 - 2.0 * t2 + t;
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h11 = t3 - t2;
        let h = self.h;
        State {
            q: h00 * self.y0.q + (h10 * h) * self.f0.q + h01 * self.y1.q + (h11 * h) * self.f1.q,
            qd: h00 * self.y0.qd
                + (h10 * h) * self.f0.qd
                + h01 * self.y1.qd
                + (h11 * h) * self.f1.qd,
            work: h00 * self.y0.work
                + h10 * h * self.f0.work
                + h01 * self.y1.work
                + h11 * h * self.f1.work,
            dissipated: h00 * self.y0.dissipated
                + h10 * h * self.f0.dissipated
                + h01 * self.y1.dissipated
                + h11 * h * self.f1.dissipated,
        }
    }
}
