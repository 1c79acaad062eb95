//! The quadrature of a body's surface in space: Gauss-Legendre rules, and the exact clipping
//! of a one-parameter family (an interval, an arc of a circle) by linear and trigonometric
//! conditions. Every curved surface is integrated as a family of 1D integrals whose limits
//! are cut exactly where the sand's surface or a leading edge crosses them, so that what
//! is left to the rule is a smooth integrand.

use std::f64::consts::PI;

/// Gauss-Legendre nodes and weights on [-1, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct Gauss {
    /// Nodes, increasing.
    pub x: Vec<f64>,
    /// Weights (summing to 2).
    pub w: Vec<f64>,
}

impl Gauss {
    /// The `n`-point rule (Newton on the Legendre polynomial from Chebyshev guesses; nodes to
    /// machine precision).
    pub fn new(n: usize) -> Self {
        let n = n.max(1);
        let mut x = vec![0.0; n];
        let mut w = vec![0.0; n];
        for i in 0..n.div_ceil(2) {
            let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (p, d) = legendre(n, z);
                dp = d;
                let dz = p / d;
                z -= dz;
                if dz.abs() < 1e-16 {
                    break;
                }
            }
            let (_, d) = legendre(n, z);
            dp = if d != 0.0 { d } else { dp };
            x[i] = -z;
            x[n - 1 - i] = z;
            let wi = 2.0 / ((1.0 - z * z) * dp * dp);
            w[i] = wi;
            w[n - 1 - i] = wi;
        }
        Gauss { x, w }
    }

    /// Call `f(t, weight)` at the rule's nodes mapped onto `[a, b]`.
    #[inline]
    pub fn each(&self, a: f64, b: f64, mut f: impl FnMut(f64, f64)) {
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        for (x, w) in self.x.iter().zip(&self.w) {
            f(mid + half * x, half * w);
        }
    }
}

/// P_n(z) and P_n'(z).
fn legendre(n: usize, z: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, z);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (z * p1 - p0) / (z * z - 1.0);
    (p1, d)
}

/// The part of `[lo, hi]` where `a + b t >= 0`, or `None`.
#[inline]
pub fn clip_linear(lo: f64, hi: f64, a: f64, b: f64) -> Option<(f64, f64)> {
    if b == 0.0 {
        return (a >= 0.0).then_some((lo, hi));
    }
    let root = -a / b;
    let (lo, hi) = if b > 0.0 {
        (lo.max(root), hi)
    } else {
        (lo, hi.min(root))
    };
    (hi > lo).then_some((lo, hi))
}

/// An arc of the circle: the angles `start .. start + len` (`len` in [0, 2 pi]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arc {
    /// Its first angle, in [0, 2 pi).
    pub start: f64,
    /// Its length [rad].
    pub len: f64,
}

impl Arc {
    /// The whole circle.
    pub const FULL: Arc = Arc {
        start: 0.0,
        len: 2.0 * PI,
    };
}

/// The angles `phi` where `a cos(phi) + b sin(phi) <= c`: the whole circle, nothing, or one
/// arc.
pub fn arc_below(a: f64, b: f64, c: f64) -> Option<Arc> {
    let rho = a.hypot(b);
    if rho <= c {
        return Some(Arc::FULL);
    }
    if -rho >= c {
        return None;
    }
    // rho cos(phi - phi0) <= c  <=>  phi - phi0 in [delta, 2 pi - delta].
    let phi0 = b.atan2(a);
    let delta = (c / rho).clamp(-1.0, 1.0).acos();
    Some(Arc {
        start: (phi0 + delta).rem_euclid(2.0 * PI),
        len: 2.0 * (PI - delta),
    })
}

/// The common part of two arcs (at most two arcs).
pub fn intersect(p: Arc, q: Arc) -> ([Option<Arc>; 2], usize) {
    let mut out = [None, None];
    let mut k = 0;
    if p.len >= 2.0 * PI {
        out[0] = Some(q);
        return (out, 1);
    }
    if q.len >= 2.0 * PI {
        out[0] = Some(p);
        return (out, 1);
    }
    // q relative to p's start: [s, s + q.len] and its turn back, [s - 2 pi, ...].
    let s = (q.start - p.start).rem_euclid(2.0 * PI);
    for shift in [0.0, -2.0 * PI] {
        let lo = (s + shift).max(0.0);
        let hi = (s + shift + q.len).min(p.len);
        if hi > lo {
            out[k] = Some(Arc {
                start: (p.start + lo).rem_euclid(2.0 * PI),
                len: hi - lo,
            });
            k += 1;
        }
    }
    (out, k)
}

/// The angles in `[lo, hi]` where `a cos(t) + b sin(t) = c`, appended to `out`.
pub fn trig_roots(a: f64, b: f64, c: f64, lo: f64, hi: f64, out: &mut Vec<f64>) {
    let rho = a.hypot(b);
    if rho == 0.0 || c.abs() > rho {
        return;
    }
    let phi0 = b.atan2(a);
    let delta = (c / rho).clamp(-1.0, 1.0).acos();
    for base in [phi0 + delta, phi0 - delta] {
        // every 2 pi copy inside [lo, hi]
        let mut t = base + ((lo - base) / (2.0 * PI)).ceil() * 2.0 * PI;
        while t <= hi {
            if t > lo {
                out.push(t);
            }
            t += 2.0 * PI;
        }
    }
}

/// Cut `[lo, hi]` at the sorted `breaks` inside it and into panels no longer than `max_len`;
/// call `f(a, b)` for each piece.
pub fn pieces(lo: f64, hi: f64, breaks: &mut [f64], max_len: f64, mut f: impl FnMut(f64, f64)) {
    breaks.sort_by(|a, b| a.total_cmp(b));
    let mut a = lo;
    let mut each = |a: f64, b: f64| {
        let n = ((b - a) / max_len).ceil().max(1.0) as usize;
        let h = (b - a) / n as f64;
        for i in 0..n {
            f(
                a + i as f64 * h,
                if i + 1 == n {
                    b
                } else {
                    a + (i + 1) as f64 * h
                },
            );
        }
    };
    for &t in breaks.iter() {
        if t > a + 1e-14 && t < hi - 1e-14 {
            each(a, t);
            a = t;
        }
    }
    if hi > a {
        each(a, hi);
    }
}

/// Integrate over the angles `lo .. hi` cut at `breaks`: on a whole circle with no break,
/// where the integrand is smooth and periodic, by the trapezoidal rule with `2 n` points
/// (exact for trigonometric polynomials of degree below `2 n`, converging exponentially
/// for a smooth periodic integrand); otherwise by `g` on panels of at most `max_len`
/// between the breaks. Calls `f(angle, weight)`.
pub fn around(
    lo: f64,
    hi: f64,
    breaks: &mut [f64],
    max_len: f64,
    g: &Gauss,
    mut f: impl FnMut(f64, f64),
) {
    let inside = breaks
        .iter()
        .filter(|&&t| t > lo + 1e-14 && t < hi - 1e-14)
        .count();
    if inside == 0 && hi - lo >= 2.0 * PI * (1.0 - 1e-15) {
        let n = 2 * g.x.len();
        let w = (hi - lo) / n as f64;
        for k in 0..n {
            f(lo + (k as f64 + 0.5) * w, w);
        }
        return;
    }
    pieces(lo, hi, breaks, max_len, |a, b| g.each(a, b, &mut f));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_integrates_polynomials_of_degree_2n_minus_1_exactly() {
        for n in 1..12 {
            let g = Gauss::new(n);
            for deg in 0..(2 * n) {
                let mut s = 0.0;
                g.each(0.0, 2.0, |t, w| s += w * t.powi(deg as i32));
                let exact = 2f64.powi(deg as i32 + 1) / (deg as f64 + 1.0);
                assert!(
                    (s - exact).abs() < 1e-13 * exact,
                    "n {n} deg {deg}: {s} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn an_arc_below_holds_the_angles_it_says() {
        let (a, b, c) = (0.3, -0.7, 0.2);
        let arc = arc_below(a, b, c).unwrap();
        for k in 0..1000 {
            let phi = 2.0 * PI * (k as f64 + 0.5) / 1000.0;
            let inside = (phi - arc.start).rem_euclid(2.0 * PI) <= arc.len;
            assert_eq!(inside, a * phi.cos() + b * phi.sin() <= c, "phi {phi}");
        }
    }

    #[test]
    fn a_whole_circle_takes_the_trapezoidal_rule_and_an_arc_gauss() {
        let g = Gauss::new(6);
        // cos(3 phi)^2 over the circle: pi, exactly with 12 points.
        let mut s = 0.0;
        around(0.0, 2.0 * PI, &mut [], PI / 4.0, &g, |p, w| {
            s += w * (3.0 * p).cos().powi(2)
        });
        assert!((s - PI).abs() < 1e-14, "{s}");
        let mut s = 0.0;
        around(0.3, 1.3, &mut [0.5], PI / 4.0, &g, |p, w| s += w * p.cos());
        assert!((s - (1.3f64.sin() - 0.3f64.sin())).abs() < 1e-14, "{s}");
    }

    #[test]
    fn two_arcs_meet_where_both_hold() {
        let p = Arc {
            start: 5.5,
            len: 2.0,
        };
        let q = Arc {
            start: 0.2,
            len: 5.6,
        };
        let (parts, n) = intersect(p, q);
        for k in 0..2000 {
            let phi = 2.0 * PI * (k as f64 + 0.5) / 2000.0;
            let within = |a: Arc| (phi - a.start).rem_euclid(2.0 * PI) <= a.len;
            let got = parts[..n].iter().any(|a| within(a.unwrap()));
            assert_eq!(got, within(p) && within(q), "phi {phi}");
        }
    }
}
