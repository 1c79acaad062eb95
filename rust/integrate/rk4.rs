//! The classical fourth-order Runge-Kutta step on the body's state.
//!
//! The state is the generalized coordinates, their rates, and the work done by the sand
//! on the body (integrated alongside, so that the energy balance can be checked against an
//! independent quadrature). The modes are held fixed through a step.

use nalgebra::SVector;

use crate::dynamics::{Eval, Model, Modes};

/// The integrated state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State<const N: usize> {
    /// Generalized coordinates [m, m, rad...].
    pub q: SVector<f64, N>,
    /// Their rates [m/s, m/s, rad/s...].
    pub qd: SVector<f64, N>,
    /// Work done by the sand on the body since the start [J] (non-positive at E).
    pub work: f64,
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
}

impl<const N: usize> State<N> {
    /// `self + h * d`.
    #[inline]
    pub fn add(&self, h: f64, d: &Deriv<N>) -> State<N> {
        State {
            q: self.q + h * d.q,
            qd: self.qd + h * d.qd,
            work: self.work + h * d.work,
        }
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.q.iter().all(|v| v.is_finite())
            && self.qd.iter().all(|v| v.is_finite())
            && self.work.is_finite()
    }
}

/// Derivative of the state from an evaluation.
#[inline]
pub fn deriv_of<const N: usize>(y: &State<N>, e: &Eval<N>) -> Deriv<N> {
    Deriv {
        q: y.qd,
        qd: e.qdd,
        work: e.power,
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
    let f = |s: &State<N>| deriv_of(s, &model.eval(&s.q, &s.qd, modes));
    let y2 = y.add(0.5 * h, k1);
    let k2 = f(&y2);
    let y3 = y.add(0.5 * h, &k2);
    let k3 = f(&y3);
    let y4 = y.add(h, &k3);
    let k4 = f(&y4);
    State {
        q: y.q + (h / 6.0) * (k1.q + 2.0 * k2.q + 2.0 * k3.q + k4.q),
        qd: y.qd + (h / 6.0) * (k1.qd + 2.0 * k2.qd + 2.0 * k3.qd + k4.qd),
        work: y.work + (h / 6.0) * (k1.work + 2.0 * k2.work + 2.0 * k3.work + k4.work),
    }
}
