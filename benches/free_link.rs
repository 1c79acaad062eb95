//! Criterion benches of the free link, one group per layer (STYLE.md, "Benchmarks"):
//!
//! * `force/rod_force`: one evaluation of the resistance-force law; `force/rft/N`: `rft`'s
//!   force on the same rod, tilted and spinning, at N elements per plate (a lone rod's fast
//!   path up to 8, the plain loop beyond; docs/laws.md, "Cost": its speed hangs on how LLVM
//!   packs the element groups, so compare 2 and 8 against 16 before and after a change);
//! * `rhs/eval`: one right-hand-side evaluation of the free-link model at a mid-impact state
//!   of the q = 45 row (both static terms sliding); `rhs/eval_vertical_stick` the same for
//!   the vertical drop, whose horizontal term sticks (v_Ex = 0 held by a reaction);
//! * `step/rk4`: one RK4 step from that state (three more evaluations);
//! * `impact/*`: whole impacts: the Table 3.5 row q = 45, v0 = 2.27, the vertical drop at
//!   v0 = 2.214, and every row of Table 3.5 (31 as shipped) with its Table 3.4 coefficients
//!   (the row at the tabulated angle nearest |q|, ties to the larger angle);
//!   `impact/table_3_5_all_raw` the same with the plain sign() (`SignModel::Raw`), the
//!   algorithm of the peers in `benches/peers.py`.
//!
//! `cargo bench --bench free_link` (about a minute); `cargo bench --bench free_link -- --test`
//! runs each once as a check. The machines are shared: compare ratios (an impact against
//! `rhs_evals` x `rhs/eval`), not absolute times.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{SVector, Vector2};

use _granrs::bodies::LinkageScene;
use _granrs::dynamics::terms_on;
use _granrs::dynamics::{ContactMode, Modes, SignModel, Slip, MAX_CONTACTS};
use _granrs::forces::rft::{Rft, GENERIC};
use _granrs::forces::{
    Boundary, Coefficients, ContactState, ForceSet, Frame, Medium, Outline, Term,
};
use _granrs::integrate::stepper::{deriv_of, step, State};
use _granrs::integrate::{EndCondition, Record, SolveOptions, Status};
use _granrs::presets::free_link::FreeLink;
use _granrs::presets::{Setting, Start};

/// Table 3.4 of the thesis, row q = 45 deg.
const TABLE_3_4_Q45: Coefficients = Coefficients {
    eta_h: 5.5,
    eta_d: 11.0,
    eta_v: 53.0,
    lambda: 0.25,
};

/// The free link (the preset) at `q_deg` dropped at `v0` under the thesis's law with
/// `coefficients`, in the default setting (force at the tip): the rod and its scene.
fn rod(q_deg: f64, v0: f64, coefficients: Coefficients) -> (FreeLink, LinkageScene) {
    let rod = FreeLink {
        q_deg,
        start: Start {
            v0,
            depth0: 0.0,
            vx0: 0.0,
        },
        ..Default::default()
    };
    let scene = rod.scene(Setting {
        forces: ForceSet::thesis(&[coefficients]),
        ..Default::default()
    });
    (rod, scene)
}

/// The Table 3.5 row q = 45 deg, v0 = 2.27 m/s with Table 3.4 coefficients (force at the tip).
fn scene_q45() -> (FreeLink, LinkageScene) {
    rod(45.0, 2.27, TABLE_3_4_Q45)
}

/// Read a CSV of the package data folder: header and rows of strings (no quoted commas in
/// the columns read here).
fn read_csv(name: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let path = format!(
        "{}/python/granrs/data/{name}.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header = lines
        .next()
        .unwrap_or_else(|| panic!("{path}: empty"))
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|s| s.trim().to_string()).collect())
        .collect();
    (header, rows)
}

/// Column index by name.
fn column(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

fn number(row: &[String], i: usize) -> f64 {
    row[i]
        .parse()
        .unwrap_or_else(|e| panic!("{:?} in {row:?}: {e}", row[i]))
}

/// Table 3.4 as (q_deg, coefficients).
fn table_3_4() -> Vec<(f64, Coefficients)> {
    let (h, rows) = read_csv("table_3_4_free_link_coefficients");
    let (q, eh, ed, ev, la) = (
        column(&h, "q_deg"),
        column(&h, "eta_h"),
        column(&h, "eta_d"),
        column(&h, "eta_v"),
        column(&h, "lambda"),
    );
    rows.iter()
        .map(|r| {
            (
                number(r, q),
                Coefficients {
                    eta_h: number(r, eh),
                    eta_d: number(r, ed),
                    eta_v: number(r, ev),
                    lambda: number(r, la),
                },
            )
        })
        .collect()
}

/// The Table 3.4 row at the tabulated angle nearest |q_deg|, ties to the larger angle.
fn nearest_row(table: &[(f64, Coefficients)], q_deg: f64) -> Coefficients {
    let q = q_deg.abs();
    let mut best = table[0];
    for &(tq, c) in &table[1..] {
        let (d, bd) = ((tq - q).abs(), (best.0 - q).abs());
        if d < bd || (d == bd && tq > best.0) {
            best = (tq, c);
        }
    }
    best.1
}

/// The rods and scenes of Table 3.5 (31 rows as shipped), each with its Table 3.4 row.
fn table_3_5_scenes() -> Vec<(FreeLink, LinkageScene)> {
    let coefficients = table_3_4();
    let (h, rows) = read_csv("table_3_5_free_link_thesis_simulation");
    let (q, v0) = (column(&h, "q_deg"), column(&h, "v0"));
    rows.iter()
        .map(|r| {
            let q_deg = number(r, q);
            rod(q_deg, number(r, v0), nearest_row(&coefficients, q_deg))
        })
        .collect()
}

/// A mid-impact state of `scene` (half its stopping time) and the modes the solver holds
/// there: in contact, each static term's sign that of the centroid's velocity, or sticking
/// where that component is exactly zero (the vertical drop's horizontal term).
fn mid_impact(scene: &LinkageScene) -> (SVector<f64, 3>, SVector<f64, 3>, Modes) {
    let t_s = scene.run().expect("impact runs").contacts[0].t_s;
    let mut to_half = scene.clone();
    to_half.options = SolveOptions {
        t_end: 0.5 * t_s,
        end: EndCondition::Time,
        record: Record {
            state: true,
            ..Default::default()
        },
        ..scene.options
    };
    let out = to_half.run().expect("impact runs");
    assert_eq!(out.status, Status::EndTime);
    let series = out.series.expect("state recorded");
    let last = |name: &str| {
        *series
            .columns
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("no column {name}"))
            .1
            .last()
            .unwrap()
    };
    let q = SVector::<f64, 3>::new(last("q0"), last("q1"), last("q2"));
    let qd = SVector::<f64, 3>::new(last("qd0"), last("qd1"), last("qd2"));
    let mut modes: Modes = [ContactMode::default(); MAX_CONTACTS];
    modes[0] = ContactMode {
        in_contact: true,
        sx: Slip::Neg,
        sy: Slip::Neg,
        ..ContactMode::default()
    };
    let v_e = scene.model::<3>().eval(&q, &qd, &modes).contacts[0].v_centroid;
    let slip = |v: f64| {
        if v < 0.0 {
            Slip::Neg
        } else if v > 0.0 {
            Slip::Pos
        } else {
            Slip::Stick
        }
    };
    assert!(v_e.y < 0.0, "mid-impact state moves down: {v_e:?}");
    modes[0].sx = slip(v_e.x);
    modes[0].sy = slip(v_e.y);
    (q, qd, modes)
}

/// The cost of one evaluation of each force term, and of the thesis's set as a whole (the
/// per-term table of issue 16), on a mid-impact contact of the q = 45 row: 2 cm deep,
/// moving down and sideways.
fn force(c: &mut Criterion) {
    let mut g = c.benchmark_group("force");
    let q = 45f64.to_radians();
    let depth = 0.02;
    let d_c = 0.0127;
    let l = depth / q.cos();
    let v = Vector2::new(0.4, -1.3);
    let axis = Vector2::new(q.sin(), q.cos());
    let state = ContactState {
        depth,
        volume: std::f64::consts::FRAC_PI_4 * d_c * d_c * l,
        width: d_c,
        l_ref: 0.190,
        v: [v.x, v.y],
        area_speed: d_c * l * (axis.x * v.y - axis.y * v.x).abs(),
        sign: [1.0, -1.0],
        boundary: None,
    };
    let medium = Medium::default();
    let set = ForceSet::thesis(&[TABLE_3_4_Q45]);
    for (k, info) in set.contact_info.iter().enumerate() {
        let term = set.per_contact[0][k];
        g.bench_function(format!("term/{}", info.name), |b| {
            b.iter(|| black_box(&term).contact_force(black_box(&state), black_box(&medium)))
        });
    }
    // `rft` on the rod's boundary: tip T at the depth, turning.
    let tip = [0.0, -depth];
    let boundary = Boundary {
        frame: Frame {
            origin: tip,
            v: [v.x, v.y],
            omega: 3.0,
            axis: [axis.x, axis.y],
        },
        outline: Outline::Rod {
            diameter: d_c,
            immersed: l,
        },
        apply: tip,
        centroid: [0.5 * l * axis.x, -depth + 0.5 * l * axis.y],
        v_centroid: [v.x, v.y],
        held: [0.0; 2],
    };
    let on_rod = ContactState {
        boundary: Some(&boundary),
        ..state
    };
    for n in [2, 8, 16] {
        let rft = Rft {
            zeta: 1e6,
            elements: n,
            coefficients: GENERIC,
        };
        g.bench_function(format!("rft/{n}"), |b| {
            b.iter(|| black_box(&rft).contact_force(black_box(&on_rod), black_box(&medium)))
        });
    }
    g.bench_function("thesis_set", |b| {
        let mut out = Default::default();
        let mut bound = [0.0; 2];
        b.iter(|| {
            terms_on(
                black_box(&set),
                black_box(&set.per_contact[0]),
                black_box(&state),
                black_box(&medium),
                &mut out,
                &mut bound,
            );
            black_box(&out);
        })
    });
    g.finish();
}

fn rhs(c: &mut Criterion) {
    let (_, scene) = scene_q45();
    let model = scene.model::<3>();
    let (q, qd, modes) = mid_impact(&scene);
    assert!(modes[0].sx != Slip::Stick && modes[0].sy != Slip::Stick);
    // The vertical drop holds v_Ex = 0 by a sticking reaction: the costlier path of eval.
    let (_, vertical) = vertical_scene();
    let vertical_model = vertical.model::<3>();
    let (vq, vqd, vmodes) = mid_impact(&vertical);
    assert_eq!(vmodes[0].sx, Slip::Stick, "vertical drop sticks in x");

    let mut g = c.benchmark_group("rhs");
    g.bench_function("eval", |b| {
        b.iter(|| black_box(&model).eval(black_box(&q), black_box(&qd), black_box(&modes)))
    });
    g.bench_function("eval_vertical_stick", |b| {
        b.iter(|| {
            black_box(&vertical_model).eval(black_box(&vq), black_box(&vqd), black_box(&vmodes))
        })
    });
    g.finish();

    let y = State {
        q,
        qd,
        work: 0.0,
        dissipated: 0.0,
    };
    let k1 = deriv_of(&y, &model.eval(&q, &qd, &modes));
    let dt = scene.options.dt;
    let mut g = c.benchmark_group("step");
    g.bench_function("rk4", |b| {
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
    g.finish();
}

/// The vertical drop at v0 = 2.214 m/s (Table 3.5, first row) with Table 3.4 row q = 0.
fn vertical_scene() -> (FreeLink, LinkageScene) {
    rod(0.0, 2.214, Coefficients::TABLE_3_4_VERTICAL)
}

fn impact(c: &mut Criterion) {
    let q45 = scene_q45();
    let vertical = vertical_scene();
    // Table 3.5 as shipped has 31 rows (11 angles x 3 speeds, two rows missing in the source).
    let rows = table_3_5_scenes();
    for (p, s) in std::iter::once(&q45)
        .chain(std::iter::once(&vertical))
        .chain(&rows)
    {
        let out = s.run().expect("Table 3.5 scenes run");
        assert_eq!(
            out.status,
            Status::Stopped,
            "q = {}, v0 = {}",
            p.q_deg,
            p.start.v0
        );
    }
    let (q45, vertical) = (q45.1, vertical.1);
    let all: Vec<LinkageScene> = rows.into_iter().map(|(_, s)| s).collect();

    let mut g = c.benchmark_group("impact");
    g.bench_function("table_3_5_q45", |b| {
        b.iter(|| black_box(&q45).run().unwrap())
    });
    g.bench_function("vertical_2.214", |b| {
        b.iter(|| black_box(&vertical).run().unwrap())
    });
    // Throughput in impacts: criterion reports impacts per second for the whole table.
    g.throughput(Throughput::Elements(all.len() as u64));
    g.bench_function("table_3_5_all", |b| {
        b.iter(|| {
            black_box(&all)
                .iter()
                .map(|s| s.run().unwrap().contacts[0].depth)
                .sum::<f64>()
        })
    });
    // The same table with the thesis's plain sign() (SignModel::Raw): the algorithm of the
    // numba and scipy peers of `benches/peers.py`.
    let all_raw: Vec<LinkageScene> = all
        .iter()
        .map(|s| LinkageScene {
            sign_model: SignModel::Raw,
            ..s.clone()
        })
        .collect();
    g.bench_function("table_3_5_all_raw", |b| {
        b.iter(|| {
            black_box(&all_raw)
                .iter()
                .map(|s| s.run().unwrap().contacts[0].depth)
                .sum::<f64>()
        })
    });
    g.finish();
}

/// The Table 3.5 scenes as a sweep on one thread: in SIMD lanes against alone, each run
/// as the batch runs it (no Python, no scene building).
fn lanes(c: &mut Criterion) {
    use _granrs::integrate::lanes::{run_lanes, LaneIsa};
    let all = table_3_5_scenes();
    let scenes: Vec<_> = all
        .iter()
        .map(|(_, s)| {
            let (q0, qd0) = s.initial_state::<3>();
            (s.model::<3>(), q0, qd0, s.options)
        })
        .collect();
    let mut g = c.benchmark_group("sweep");
    g.throughput(Throughput::Elements(scenes.len() as u64));
    for (name, isa) in [
        ("table_3_5_lanes", Some(LaneIsa::detect())),
        ("table_3_5_lanes_baseline", Some(LaneIsa::Base)),
        ("table_3_5_scalar", None),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut depth = 0.0;
                match isa {
                    Some(isa) => {
                        let mut it = scenes.iter().enumerate();
                        run_lanes(
                            isa,
                            || {
                                it.next()
                                    .map(|(i, (m, q, qd, o))| (i, m.clone(), *q, *qd, *o))
                            },
                            |_, out| depth += out.unwrap().contacts[0].depth,
                        );
                    }
                    None => {
                        for (m, q, qd, o) in &scenes {
                            let out = _granrs::integrate::solve(&m.clone(), *q, *qd, o);
                            depth += out.unwrap().contacts[0].depth;
                        }
                    }
                }
                black_box(depth)
            })
        });
    }
    g.finish();
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
    targets = force, rhs, impact, lanes
}
criterion_main!(benches);
