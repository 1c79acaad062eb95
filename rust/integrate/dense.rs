//! Dense output of a step: the cubic Hermite interpolant through both ends and their
//! derivatives (free with RK4: the end derivative is the next step's first stage), and a
//! root finder (Illinois) for an event function on it.

use super::rk4::{Deriv, State};

/// The cubic Hermite interpolant of one step.
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

/// Find a root of `g` in [0, 1] given `g(0) = g0 >= 0` and `g(1) = g1 < 0` (a sign change),
/// by the Illinois variant of regula falsi. Returns `(theta, evaluations)`; `theta` is the
/// right end of the final bracket, so that `g(theta) <= 0` (the event has happened there).
pub fn locate(g: impl FnMut(f64) -> f64, g0: f64, g1: f64, tol: f64) -> (f64, usize) {
    locate_in(g, (0.0, g0), (1.0, g1), tol)
}

/// [`locate`] on the bracket `[a, b]` with `g(a) = fa >= 0` and `g(b) = fb < 0`.
pub fn locate_in(
    mut g: impl FnMut(f64) -> f64,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    tol: f64,
) -> (f64, usize) {
    let mut side = 0i8;
    let mut evals = 0usize;
    while b - a > tol && evals < 200 {
        let mut x = if fa == fb {
            0.5 * (a + b)
        } else {
            (a * fb - b * fa) / (fb - fa)
        };
        if !(x > a && x < b) {
            x = 0.5 * (a + b);
        }
        let fx = g(x);
        evals += 1;
        if fx < 0.0 {
            b = x;
            fb = fx;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = x;
            fa = fx;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
        if fx == 0.0 {
            return (x, evals);
        }
    }
    (b, evals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locates_a_simple_root() {
        let (x, n) = locate(|t| 0.3 - t * t, 0.3, -0.7, 1e-14);
        assert!((x - 0.3f64.sqrt()).abs() < 1e-13, "{x}");
        assert!(n < 60);
    }
}
