//! Shared helpers of the cargo integration tests.
#![allow(dead_code)]

use _granrs::bodies::LinkageScene;
use _granrs::forces::{Coefficients, ForceSet, Medium};
use _granrs::presets::free_link::FreeLink;
use _granrs::presets::{Setting, Start};

/// The default setting (the thesis's sand, default numerics) under the thesis's law with
/// `coefficients`, one set per contact.
pub fn thesis_setting(coefficients: &[Coefficients]) -> Setting {
    Setting {
        forces: ForceSet::thesis(coefficients),
        ..Default::default()
    }
}

/// The setting the leg ran in before it was a preset: the thesis's fine sand (sec. 5.3.2,
/// rho_g = 1600 kg/m^3) and the thesis's coefficients of the landing at v0 = 3.28 m/s
/// (sec. 5.3.2), written out here independently of the package.
pub fn leg_setting() -> Setting {
    Setting {
        medium: Medium {
            rho_g: 1600.0,
            g: 9.81,
        },
        ..thesis_setting(&[Coefficients {
            eta_h: 10.0,
            eta_d: 13.0,
            eta_v: 195.0,
            lambda: 1.05,
        }])
    }
}

/// An initial downward speed `v0` [m/s] from the surface, without sideways motion (every
/// preset's default start but for its speed).
pub fn drop_at(v0: f64) -> Start {
    Start {
        v0,
        depth0: 0.0,
        vx0: 0.0,
    }
}

/// The `static_v` term of a free link's force set (panics without one).
pub fn static_v_of(s: &LinkageScene) -> Coefficients {
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

/// Work done against F_sv by a vertical rod `p` sunk to depth d in the scene `s` it built
/// (force at the tip): with l = min(d, L),
/// int_0^d eta_v (s/L)^lambda g rho (pi d_c^2/4) min(s, L) ds.
pub fn vertical_static_work(p: &FreeLink, s: &LinkageScene, d: f64) -> f64 {
    let c = static_v_of(s);
    let a =
        c.eta_v * s.medium.g * s.medium.rho_g * std::f64::consts::PI * p.rod.diameter.powi(2) / 4.0;
    let l = p.rod.length;
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

/// The exact final depth of a vertical drop of the rod `p` in the scene `s` it built, with
/// the force at the tip (MODEL.md, "Exact answers"): only F_sv acts, so
/// (1/2) m v0^2 + m g d = W(d), the work of [`vertical_static_work`]. Solved by bisection to
/// round-off.
pub fn exact_vertical_depth(p: &FreeLink, s: &LinkageScene) -> f64 {
    let g = s.medium.g;
    let v0 = p.start.v0;
    let f =
        |d: f64| vertical_static_work(p, s, d) - 0.5 * p.rod.mass * v0 * v0 - p.rod.mass * g * d;
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
