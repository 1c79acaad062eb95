//! Issue 3: sticking holds its velocity at zero and releases when the bound is exceeded;
//! RK4 in `modes` keeps its fourth order across located sign switches.

mod common;

use _granrs::bodies::LinkageScene;
use _granrs::dynamics::{ContactMode, Slip, MAX_CONTACTS};
use _granrs::forces::Coefficients;
use _granrs::integrate::{EndCondition, Record, Series};
use _granrs::presets::free_link::FreeLink;
use _granrs::presets::{Setting, Start};
use common::{drop_at, exact_vertical_depth, table_3_4_vertical, thesis_setting};
use nalgebra::SVector;

fn col<'a>(s: &'a Series, name: &str) -> &'a [f64] {
    &s.columns
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("{name}"))
        .1
}

fn recorded(scene: &LinkageScene) -> Series {
    let mut s = scene.clone();
    s.options.record = Record {
        state: true,
        forces: true,
        energy: false,
        stride: 1,
    };
    s.options.end = EndCondition::Time;
    s.run().unwrap().series.unwrap()
}

/// A rod resting tilted in the sand, pushed sideways: the horizontal static term stops the
/// sideways motion of E and then holds it at zero.
#[test]
fn horizontal_stick_holds_velocity_at_zero() {
    let scene = FreeLink {
        q_deg: 30.0,
        start: Start {
            v0: 0.0,
            depth0: 0.03,
            vx0: 0.05,
        },
        ..Default::default()
    }
    .scene(Setting {
        options: _granrs::integrate::SolveOptions {
            t_end: 0.05,
            ..Default::default()
        },
        ..thesis_setting(&[table_3_4_vertical()])
    });
    let s = recorded(&scene);
    let (t, mode_x, v_ex) = (&s.t, col(&s, "c0.mode_x"), col(&s, "c0.v_E_x"));
    let first = mode_x.iter().position(|&m| m == 0.0).expect("never stuck");
    assert!(t[first] > 0.0 && t[first] < 0.01, "stuck at {}", t[first]);
    let stuck: Vec<usize> = (first..t.len()).filter(|&i| mode_x[i] == 0.0).collect();
    assert!(stuck.len() > 100, "stuck for {} samples only", stuck.len());
    for &i in &stuck {
        assert!(
            v_ex[i].abs() <= 1e-12,
            "t = {}: v_Ex = {:e} while stuck",
            t[i],
            v_ex[i]
        );
    }
}

/// A rod sinking at 45 deg with a sideways push: its vertical motion sticks, and the stick
/// is released exactly when the holding reaction reaches the static bound.
#[test]
fn vertical_stick_releases_when_bound_is_exceeded() {
    let scene = FreeLink {
        q_deg: 45.0,
        start: Start {
            v0: 0.5,
            depth0: 0.0,
            vx0: 0.3,
        },
        ..Default::default()
    }
    .scene(Setting {
        options: _granrs::integrate::SolveOptions {
            t_end: 0.1,
            ..Default::default()
        },
        // Table 3.4, row q = 45 deg.
        ..thesis_setting(&[Coefficients {
            eta_h: 5.5,
            eta_d: 11.0,
            eta_v: 53.0,
            lambda: 0.25,
        }])
    });
    let s = recorded(&scene);
    let (t, mode_y, v_ey) = (&s.t, col(&s, "c0.mode_y"), col(&s, "c0.v_E_y"));
    let stick = mode_y.iter().position(|&m| m == 0.0).expect("never stuck");
    let release = (stick..t.len())
        .find(|&i| mode_y[i] == -1.0)
        .expect("never released");
    for i in stick..release {
        assert!(
            v_ey[i].abs() <= 1e-12,
            "t = {}: v_Ey = {:e} while stuck",
            t[i],
            v_ey[i]
        );
    }
    // After the release E moves down again.
    assert!(v_ey[(release + 20).min(t.len() - 1)] < -1e-6);
    // At the release the holding reaction equals the bound (the located switching point).
    let q = SVector::<f64, 3>::new(
        col(&s, "q0")[release],
        col(&s, "q1")[release],
        col(&s, "q2")[release],
    );
    let qd = SVector::<f64, 3>::new(
        col(&s, "qd0")[release],
        col(&s, "qd1")[release],
        col(&s, "qd2")[release],
    );
    let mut modes = [ContactMode::default(); MAX_CONTACTS];
    modes[0] = ContactMode {
        in_contact: true,
        sx: Slip::Pos,
        sy: Slip::Stick,
        stopped: false,
        cross: Slip::Pos,
        full: false,
        corners: 0,
    };
    modes[0].sx = if col(&s, "c0.mode_x")[release] < 0.0 {
        Slip::Neg
    } else {
        Slip::Pos
    };
    // The drag's held sign follows e x v_E at this state.
    if scene.model::<3>().eval(&q, &qd, &modes).contacts[0].cross < 0.0 {
        modes[0].cross = Slip::Neg;
    }
    let e = scene.model::<3>().eval(&q, &qd, &modes);
    let c = &e.contacts[0];
    let rel = (c.force.statics.y.abs() - c.bound[1]).abs() / c.bound[1];
    println!(
        "stick {:.6} s, release {:.6} s, |R| vs bound rel. {rel:.1e}",
        t[stick], t[release]
    );
    assert!(
        rel < 1e-6,
        "reaction {} vs bound {}",
        c.force.statics.y,
        c.bound[1]
    );
}

fn fmt(v: &[f64]) -> Vec<String> {
    v.iter().map(|e| format!("{e:.2e}")).collect()
}

/// Slope of log(error) against log(dt), least squares.
fn slope(dts: &[f64], errs: &[f64]) -> f64 {
    let xs: Vec<f64> = dts.iter().map(|d| d.ln()).collect();
    let ys: Vec<f64> = errs.iter().map(|e| e.ln()).collect();
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// Issue 3 acceptance: the convergence order of RK4 in `modes`, on a scene whose steps avoid
/// the entry (it starts 1 cm deep) and crosses located sign switches, is at least 3.8.
#[test]
fn rk4_modes_is_fourth_order_away_from_entry() {
    let base = FreeLink {
        q_deg: 45.0,
        start: Start {
            v0: 1.0,
            depth0: 0.01,
            vx0: 0.3,
        },
        ..Default::default()
    }
    .scene(thesis_setting(&[table_3_4_vertical()]));
    let run = |dt: f64| {
        let mut s = base.clone();
        s.options.dt = dt;
        s.options.t_end = 0.02;
        s.options.end = EndCondition::Time;
        let out = s.run().unwrap();
        (out.contacts[0].tip_end, out.stats.events)
    };
    let (reference, events) = run(1e-6);
    assert!(
        events >= 1,
        "the scene should cross at least one sign switch"
    );
    let dts = [8e-4, 4e-4, 2e-4, 1e-4, 5e-5];
    let errs: Vec<f64> = dts
        .iter()
        .map(|&dt| (run(dt).0 - reference).norm())
        .collect();
    let p = slope(&dts, &errs);
    println!(
        "away from entry: errors {:?}, order {p:.2} ({events} events)",
        fmt(&errs)
    );
    assert!(p >= 3.8, "order {p}");
}

/// The order over a whole vertical impact, entry included (d^lambda is not smooth at d = 0),
/// measured against the exact depth; stated in the issue note, asserted only to be > 1.
#[test]
fn order_over_whole_impact_including_entry() {
    let dts = [4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5];
    let mut errs = Vec::new();
    for &dt in &dts {
        let rod = FreeLink {
            start: drop_at(2.214),
            ..Default::default()
        };
        let mut s = rod.scene(thesis_setting(&[table_3_4_vertical()]));
        s.options.dt = dt;
        let exact = exact_vertical_depth(&rod, &s);
        errs.push((s.run().unwrap().contacts[0].depth - exact).abs() / exact);
    }
    let p = slope(&dts, &errs);
    println!(
        "whole impact (entry included): rel. depth errors {:?}, order {p:.2}",
        fmt(&errs)
    );
    assert!(p > 1.0, "order {p}");
}
