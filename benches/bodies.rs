//! Criterion benches of every body model side by side, one group per layer (STYLE.md,
//! "Benchmarks"), so that the bodies' ratios come from one run:
//!
//! * `rhs_by_body/<body>`: one right-hand-side evaluation at a mid-impact state (half the
//!   run's end time), every contact in the sand with the modes the solver would hold there
//!   (each static term's sign that of E's velocity, or sticking where it is below 1e-9 m/s);
//! * `step_by_body/<body>`: one RK4 step from that state (three more evaluations);
//! * `impact_by_body/<body>`: one whole impact, `.run()` (validation, the solve loop).
//!
//! The bodies (`q` is 3, 4 and 6 generalized coordinates):
//!
//! * `free_link_q45`: the preset `FreeLink`, Table 3.5 row q = 45 deg, v0 = 2.27 m/s, Table 3.4
//!   coefficients (the scene of `free_link`'s `impact/table_3_5_q45`);
//! * `chain_default`: the preset `Chain::default()` (q = -15/15 deg, v0 = 2.29 m/s) in the
//!   default setting with Table 3.4's q = 0 coefficients on both links, ending at the first
//!   stop;
//! * `chain_case1`: the thesis's chain case 1 (Table 4.1 angles -16.72/13.48 deg, v0 =
//!   2.575 m/s, Table 4.4 coefficients per link), run until both links stop;
//! * `leg_locked`, `leg_spring`, `leg_free`: the preset `Leg::default()` (v0 = 3.28 m/s) in
//!   the thesis's fine sand (rho_g = 1600 kg/m^3) under its sec. 5.3.2 coefficients, with
//!   ankle, knee and hip locked (a constraint solve in every evaluation), spring-dampers
//!   (k = 300 N m/rad, c = 5 N m s/rad) or free.
//!
//! Every body is a preset (`granrs::presets`: `FreeLink`, `Chain`, `Leg`) that builds a
//! `LinkageScene`; the scenes are those the benches ran before the presets, so that the
//! numbers pair with an older build's.
//!
//! At the initial state every body only touches the surface (depth 0), where an evaluation
//! skips the force law; hence the mid-impact state, as in `free_link`'s `rhs/eval`.
//!
//! `cargo bench --bench bodies` (about two minutes); `cargo bench --bench bodies -- --test`
//! runs each once as a check; `python benches/criterion_ratios.py` then prints the medians
//! and the ratios to the free link. The work counters of each impact (steps, rhs
//! evaluations) are printed to stderr at the start. The machines are shared: compare ratios,
//! not absolute times.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::SVector;

use _granrs::bodies::LinkageScene;
use _granrs::body::Joint;
use _granrs::dynamics::{ContactMode, Modes, Slip, MAX_CONTACTS};
use _granrs::forces::{Coefficients, ForceSet, Medium};
use _granrs::integrate::stepper::{deriv_of, step, State};
use _granrs::integrate::{EndCondition, Outcome, Record, SolveOptions, Status};
use _granrs::presets::chain::Chain;
use _granrs::presets::free_link::FreeLink;
use _granrs::presets::leg::{self, Leg};
use _granrs::presets::{Setting, Start};

/// A velocity component below this [m/s] sticks (the solver's own threshold).
const SLIP_SPEED: f64 = 1e-9;

/// Table 3.4 of the thesis, row q = 45 deg.
const TABLE_3_4_Q45: Coefficients = Coefficients {
    eta_h: 5.5,
    eta_d: 11.0,
    eta_v: 53.0,
    lambda: 0.25,
};

/// A run of a bench scene (they are valid).
fn run(scene: &LinkageScene) -> Outcome {
    scene.run().expect("bench scenes are valid")
}

/// An initial downward speed `v0` [m/s] from the surface, without sideways motion.
fn drop_at(v0: f64) -> Start {
    Start {
        v0,
        depth0: 0.0,
        vx0: 0.0,
    }
}

/// The default setting under the thesis's law with `coefficients`, one set per contact.
fn thesis_setting(coefficients: &[Coefficients]) -> Setting {
    Setting {
        forces: ForceSet::thesis(coefficients),
        ..Default::default()
    }
}

/// The Table 3.5 row q = 45 deg, v0 = 2.27 m/s with Table 3.4 coefficients (force at the tip).
fn free_link_q45() -> LinkageScene {
    FreeLink {
        q_deg: 45.0,
        start: drop_at(2.27),
        ..Default::default()
    }
    .scene(thesis_setting(&[TABLE_3_4_Q45]))
}

/// The default chain with Table 3.4's q = 0 coefficients on both links.
fn chain_default() -> LinkageScene {
    Chain::default().scene(thesis_setting(&[Coefficients::TABLE_3_4_VERTICAL; 2]))
}

/// The thesis's chain case 1: Table 4.1 angles and speed, Table 4.4 coefficients of link 1
/// and link 2, run until both links have stopped.
fn chain_case1() -> LinkageScene {
    let mut s = Chain {
        q_deg: [-16.72, 13.48],
        start: drop_at(2.575),
        ..Default::default()
    }
    .scene(thesis_setting(&[
        Coefficients {
            eta_h: 8.0,
            eta_d: 13.0,
            eta_v: 33.0,
            lambda: 0.125,
        },
        Coefficients {
            eta_h: 11.8,
            eta_d: 10.0,
            eta_v: 137.0,
            lambda: 0.205,
        },
    ]));
    s.options.end = EndCondition::AllStops;
    s
}

/// The default leg with all three joints set to `joint`, in the thesis's fine sand
/// (sec. 5.3.2) under the thesis's coefficients of the landing at v0 = 3.28 m/s.
fn leg(joint: Joint) -> LinkageScene {
    Leg {
        joints: [joint; 3],
        ..Default::default()
    }
    .scene(Setting {
        medium: Medium {
            rho_g: leg::defaults::RHO_G,
            g: 9.81,
        },
        ..thesis_setting(&[Coefficients {
            eta_h: 10.0,
            eta_d: 13.0,
            eta_v: 195.0,
            lambda: 1.05,
        }])
    })
}

/// The spring-damper of the `leg_spring` bench (the rest angle is set by the scene).
const LEG_SPRING: Joint = Joint::Spring {
    k: 300.0,
    c: 5.0,
    rest: 0.0,
};

fn slip(v: f64) -> Slip {
    if v < -SLIP_SPEED {
        Slip::Neg
    } else if v > SLIP_SPEED {
        Slip::Pos
    } else {
        Slip::Stick
    }
}

/// Print a run's work counters (stderr, so that criterion's report stays clean).
fn report(name: &str, out: &Outcome) {
    let depths: Vec<String> = out
        .contacts
        .iter()
        .map(|c| format!("{:.4}", c.depth))
        .collect();
    eprintln!(
        "{name:>14}: {:<8} t = {:.4} s, {:>4} steps, {:>5} rhs evals ({} in root finding), \
         {} events, depth [{}] m",
        out.status.name(),
        out.t_final,
        out.stats.steps,
        out.stats.rhs_evals,
        out.stats.root_evals,
        out.stats.events,
        depths.join(", ")
    );
}

/// A mid-impact state of `scene` (half its end time) and the modes the solver holds there:
/// every contact in the sand, each static term's sign that of E's velocity (sticking below
/// `SLIP_SPEED`), the drag's e x v_E sign that of its value.
fn mid_impact<const N: usize>(
    name: &str,
    scene: &LinkageScene,
) -> (SVector<f64, N>, SVector<f64, N>, Modes) {
    let out = run(scene);
    assert_eq!(out.status, Status::Stopped, "{name}");
    report(name, &out);
    let mut to_half = scene.clone();
    to_half.options = SolveOptions {
        t_end: 0.5 * out.t_final,
        end: EndCondition::Time,
        record: Record {
            state: true,
            ..Default::default()
        },
        ..scene.options
    };
    let half = run(&to_half);
    assert_eq!(half.status, Status::EndTime, "{name}");
    let series = half.series.expect("state recorded");
    let last = |column: String| {
        *series
            .columns
            .iter()
            .find(|(n, _)| *n == column)
            .unwrap_or_else(|| panic!("{name}: no column {column}"))
            .1
            .last()
            .unwrap()
    };
    let q = SVector::<f64, N>::from_fn(|i, _| last(format!("q{i}")));
    let qd = SVector::<f64, N>::from_fn(|i, _| last(format!("qd{i}")));

    let model = scene.model::<N>();
    let mut modes: Modes = [ContactMode::default(); MAX_CONTACTS];
    for m in modes.iter_mut().take(model.contacts.len()) {
        *m = ContactMode {
            in_contact: true,
            sx: Slip::Neg,
            sy: Slip::Neg,
            ..ContactMode::default()
        };
    }
    let e = model.eval(&q, &qd, &modes);
    for (ci, m) in modes.iter_mut().enumerate().take(model.contacts.len()) {
        let c = &e.contacts[ci];
        assert!(c.depth > 0.0, "{name}: contact {ci} is in the sand: {c:?}");
        assert!(
            c.v_centroid.y < 0.0,
            "{name}: contact {ci} moves down: {c:?}"
        );
        m.sx = slip(c.v_centroid.x);
        m.sy = slip(c.v_centroid.y);
        m.cross = if c.cross < 0.0 { Slip::Neg } else { Slip::Pos };
    }
    let shown: Vec<String> = modes
        .iter()
        .take(model.contacts.len())
        .map(|m| format!("({:?}, {:?})", m.sx, m.sy))
        .collect();
    eprintln!(
        "{name:>14}: mid-impact at t = {:.4} s, modes (sx, sy) {}",
        half.t_final,
        shown.join(", ")
    );
    (q, qd, modes)
}

/// Add `rhs_by_body/<name>`, `step_by_body/<name>` and `impact_by_body/<name>` for `scene`.
fn bench_body<const N: usize>(c: &mut Criterion, name: &str, scene: &LinkageScene) {
    let model = scene.model::<N>();
    let (q, qd, modes) = mid_impact::<N>(name, scene);

    c.benchmark_group("rhs_by_body").bench_function(name, |b| {
        b.iter(|| black_box(&model).eval(black_box(&q), black_box(&qd), black_box(&modes)))
    });

    let y = State {
        q,
        qd,
        work: 0.0,
        dissipated: 0.0,
    };
    let k1 = deriv_of(&y, &model.eval(&q, &qd, &modes));
    let dt = scene.options.dt;
    c.benchmark_group("step_by_body").bench_function(name, |b| {
        b.iter(|| {
            step(
                black_box(&model),
                black_box(&modes),
                black_box(&y),
                black_box(&k1),
                black_box(dt),
            )
        })
    });

    c.benchmark_group("impact_by_body")
        .bench_function(name, |b| b.iter(|| run(black_box(scene))));
}

fn bodies(c: &mut Criterion) {
    bench_body::<3>(c, "free_link_q45", &free_link_q45());
    bench_body::<4>(c, "chain_default", &chain_default());
    bench_body::<4>(c, "chain_case1", &chain_case1());
    bench_body::<6>(c, "leg_locked", &leg(Joint::Locked));
    bench_body::<6>(c, "leg_spring", &leg(LEG_SPRING));
    bench_body::<6>(c, "leg_free", &leg(Joint::Free));
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(30)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
}

criterion_group! {
    name = benches;
    config = config();
    targets = bodies
}
criterion_main!(benches);
