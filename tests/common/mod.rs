//! Shared helpers of the cargo integration tests.
#![allow(dead_code)]

use _granrs::bodies::FreeLinkScene;
use _granrs::forces::Coefficients;

/// The `static_v` term of a free link's force set (panics without one).
pub fn static_v_of(s: &FreeLinkScene) -> Coefficients {
    let k = s
        .forces
        .contact_info
        .iter()
        .position(|i| i.name == "static_v")
        .unwrap();
    let p = s.forces.per_contact[0][k].params();
    Coefficients {
        eta_h: f64::NAN,
        eta_d: f64::NAN,
        eta_v: p[0],
        lambda: p[1],
    }
}

/// Work done against F_sv by a vertical rod sunk to depth d (force at the tip): with
/// l = min(d, L), int_0^d eta_v (s/L)^lambda g rho (pi d_c^2/4) min(s, L) ds.
pub fn vertical_static_work(s: &FreeLinkScene, d: f64) -> f64 {
    let c = static_v_of(s);
    let a = c.eta_v * s.medium.g * s.medium.rho_g * std::f64::consts::PI * s.diameter.powi(2) / 4.0;
    let l = s.length;
    let lam = c.lambda;
    // Partly immersed: a d^(lam+2) / (L^lam (lam+2)) (MODEL.md, "Exact answers").
    let part = |x: f64| a * x.powf(lam + 2.0) / (l.powf(lam) * (lam + 2.0));
    if d <= l {
        part(d)
    } else {
        // Wholly immersed beyond L: V = pi d_c^2 / 4 * L.
        part(l) + a * l * (d.powf(lam + 1.0) - l.powf(lam + 1.0)) / (l.powf(lam) * (lam + 1.0))
    }
}

/// The exact final depth of a vertical drop with the force at the tip (MODEL.md, "Exact
/// answers"): only F_sv acts, so (1/2) m v0^2 + m g d = W(d), the work of
/// [`vertical_static_work`]. Solved by bisection to round-off.
pub fn exact_vertical_depth(s: &FreeLinkScene) -> f64 {
    let g = s.medium.g;
    let f = |d: f64| vertical_static_work(s, d) - 0.5 * s.mass * s.v0 * s.v0 - s.mass * g * d;
    let (mut a, mut b) = (0.0f64, 1.0f64);
    while f(b) < 0.0 {
        b *= 2.0;
    }
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if f(m) < 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// Table 3.4 at q = 0 (thesis), written out here independently of the package.
pub fn table_3_4_vertical() -> Coefficients {
    Coefficients {
        eta_h: 6.5,
        eta_d: 15.2,
        eta_v: 248.0,
        lambda: 0.106,
    }
}

/// Read a CSV shipped in the package data folder as rows of strings.
pub fn read_csv(name: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let path = format!(
        "{}/python/granrs/data/{name}.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .filter(|l| !l.trim().is_empty())
        .map(split_csv_line)
        .collect();
    (header, rows)
}

fn split_csv_line(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    for ch in line.chars() {
        match ch {
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur)),
            _ => cur.push(ch),
        }
    }
    out.push(cur);
    out
}
