//! The two-link chain and the leg on the one articulated engine (issue 4): exact answers,
//! symmetry, the one-link case, energy bookkeeping per body and the joints.

mod common;

use _granrs::body::rod::ApplyAt;
use _granrs::body::{Joint, Link, Mechanism, RodContact};
use _granrs::dynamics::{Contact, Model, Shape};
use _granrs::forces::{Coefficients, ForceSet};
use _granrs::integrate::{solve, EndCondition, Outcome, Record};
use _granrs::presets::chain::Chain;
use _granrs::presets::free_link::FreeLink;
use _granrs::presets::leg::Leg;
use _granrs::presets::Setting;
use common::{drop_at, exact_vertical_depth, leg_setting, table_3_4_vertical, thesis_setting};
use nalgebra::{SVector, Vector2};

/// Table 4.4, case 1 (thesis), written out here independently of the package.
fn table_4_4_case_1() -> [Coefficients; 2] {
    [
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
    ]
}

fn series<'a>(out: &'a Outcome, name: &str) -> &'a [f64] {
    let s = out.series.as_ref().expect("recorded");
    &s.columns
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("no column {name}"))
        .1
}

/// Two coincident vertical links sinking side by side carry twice the mass on twice the
/// force: each behaves as one vertical rod, whose final depth is exact (MODEL.md).
#[test]
fn vertical_chain_matches_the_exact_depth() {
    let chain = Chain {
        q_deg: [0.0, 0.0],
        start: drop_at(1.0),
        ..Default::default()
    };
    let mut scene = chain.scene(thesis_setting(&[table_3_4_vertical(); 2]));
    scene.options.end = EndCondition::AllStops;
    let out = scene.run().unwrap();
    let rod = FreeLink {
        rod: chain.rod,
        start: drop_at(chain.start.v0),
        ..Default::default()
    };
    let exact = exact_vertical_depth(&rod, &rod.scene(thesis_setting(&[table_3_4_vertical()])));
    for c in &out.contacts {
        assert!(c.stopped);
        let err = (c.depth - exact).abs() / exact;
        assert!(err < 1e-7, "depth {} vs exact {exact}: {err:e}", c.depth);
    }
}

/// A mirror-symmetric chain (q1 = -q2, one coefficient set) stays symmetric to round-off
/// and both links stop together; the thesis's asymmetric case does not.
#[test]
fn mirror_symmetric_chain_stays_symmetric() {
    let chain = Chain {
        q_deg: [-15.0, 15.0],
        start: drop_at(2.575),
        ..Default::default()
    };
    let mut setting = thesis_setting(&[table_4_4_case_1()[1]; 2]);
    setting.options.end = EndCondition::AllStops;
    setting.options.record = Record {
        state: true,
        ..Default::default()
    };
    let out = chain.scene(setting.clone()).run().unwrap();
    let (x, q1, q2) = (series(&out, "q0"), series(&out, "q2"), series(&out, "q3"));
    let mut worst: f64 = 0.0;
    for i in 0..x.len() {
        worst = worst.max(x[i].abs()).max((q1[i] + q2[i]).abs());
    }
    assert!(worst < 1e-12, "asymmetry {worst:e}");
    let (a, b) = (&out.contacts[0], &out.contacts[1]);
    assert!(a.stopped && b.stopped);
    assert!((a.t_s - b.t_s).abs() < 1e-12, "{} vs {}", a.t_s, b.t_s);
    assert!((a.depth - b.depth).abs() < 1e-12);

    // The thesis's case 1: angles -16.72 / 13.48 deg, a coefficient set per link.
    let case_1 = Chain {
        q_deg: [-16.72, 13.48],
        ..chain
    };
    let out = case_1
        .scene(Setting {
            forces: ForceSet::thesis(&table_4_4_case_1()),
            ..setting
        })
        .run()
        .unwrap();
    let (a, b) = (&out.contacts[0], &out.contacts[1]);
    assert!(a.stopped && b.stopped);
    assert!((a.t_s - b.t_s).abs() > 1e-3, "{} vs {}", a.t_s, b.t_s);
    // Link 2 stops first and is held (x and y stuck) while link 1 turns about the pin: a
    // held contact must not chatter on the round-off sign of e x v_E (it once took 535
    // events; the mode changes are about ten).
    assert!(out.stats.events < 30, "{} events", out.stats.events);
}

/// The free link built by hand as a one-link mechanism of the general engine gives the
/// results of the linkage the free-link preset builds.
#[test]
fn one_link_engine_is_the_free_link() {
    for (q_deg, apply_at) in [
        (0.0, ApplyAt::Tip),
        (35.0, ApplyAt::Tip),
        (-55.0, ApplyAt::Centroid),
    ] {
        let rod = FreeLink {
            q_deg,
            ..Default::default()
        };
        let scene = rod.scene(Setting {
            apply_at,
            ..thesis_setting(&[table_3_4_vertical()])
        });
        let reference = scene.run().unwrap();
        let (l, d, m) = (rod.rod.length, rod.rod.diameter, rod.rod.mass);
        let model = Model::<3> {
            mechanism: Mechanism {
                links: vec![Link {
                    mass: m,
                    inertia: m * (l * l / 12.0 + d * d / 16.0),
                    com: Vector2::zeros(),
                    parent: None,
                    joint_on_parent: Vector2::zeros(),
                    joint: Joint::Free,
                }],
                root_mass: 0.0,
                root_fixed: false,
                root_rate: None,
            },
            contacts: vec![Contact {
                shape: Shape::Rod(RodContact {
                    link: 0,
                    tip: Vector2::new(-0.5 * l, 0.0),
                    length: l,
                    diameter: d,
                }),
            }],
            medium: scene.medium,
            apply_at,
            sign_model: scene.sign_model,
            forces: scene.forces.clone(),
        };
        let q = q_deg.to_radians();
        let q0 = SVector::<f64, 3>::new(0.5 * l * q.sin(), 0.5 * l * q.cos(), q);
        let qd0 = SVector::<f64, 3>::new(0.0, -rod.start.v0, 0.0);
        let out = solve(&model, q0, qd0, &scene.options).unwrap();
        let (a, b) = (&out.contacts[0], &reference.contacts[0]);
        assert!(
            (a.t_s - b.t_s).abs() < 1e-12,
            "q {q_deg}: {} vs {}",
            a.t_s,
            b.t_s
        );
        assert!((a.depth - b.depth).abs() < 1e-12 * b.depth);
        assert!((a.d_e - b.d_e).abs() < 1e-12 * b.d_e.abs());
    }
}

/// Two identical links locked together at the same angle, each with its own contact, are
/// one rod of twice the mass under twice the force: the free link, in other coordinates
/// (the pin instead of the centre of mass), so equal to RK4's accuracy, not to round-off.
#[test]
fn locked_coincident_chain_is_the_free_link_in_other_coordinates() {
    for q_deg in [0.0, 25.0, -40.0] {
        let mut chain = Chain {
            rod: FreeLink::default().rod,
            q_deg: [q_deg, q_deg],
            joint: Joint::Locked,
            start: drop_at(2.214),
            ..Default::default()
        }
        .scene(thesis_setting(&[table_3_4_vertical(); 2]));
        chain.options.end = EndCondition::FirstStop;
        let out = chain.run().unwrap();
        let rod = FreeLink {
            q_deg,
            start: drop_at(2.214),
            ..Default::default()
        }
        .scene(thesis_setting(&[table_3_4_vertical()]))
        .run()
        .unwrap();
        let (a, b) = (&out.contacts[0], &rod.contacts[0]);
        let err = (a.depth - b.depth).abs() / b.depth;
        assert!(
            err < 1e-6,
            "q {q_deg}: depth {} vs {} ({err:e})",
            a.depth,
            b.depth
        );
        assert!(
            (a.t_s - b.t_s).abs() < 1e-6,
            "q {q_deg}: {} vs {}",
            a.t_s,
            b.t_s
        );
    }
}

/// KE + PE (gravity and springs) - work of the sand + joint dissipation stays constant, per
/// body, to integration accuracy; the residual falls as the step is refined.
#[test]
fn energy_bookkeeping_closes_per_body() {
    // Leg-sized and chain-sized spring-dampers (a 34 g link under c = 5 N m s/rad would
    // be stiff far beyond what a 0.1 ms step resolves).
    let spring = Joint::Spring {
        k: 300.0,
        c: 5.0,
        rest: 0.0,
    };
    let small_spring = Joint::Spring {
        k: 0.05,
        c: 2e-4,
        rest: 0.0,
    };
    let residual = |out: &Outcome| {
        (out.energy_start - out.energy_end + out.work_sand - out.dissipated).abs()
            / out.energy_start.abs().max(out.work_sand.abs())
    };
    let mut leg_worst = Vec::new();
    for dt in [1e-4, 5e-5] {
        let mut leg_w: f64 = 0.0;
        let mut worst: f64 = 0.0;
        for apply_at in [ApplyAt::Tip, ApplyAt::Centroid] {
            let mut free = FreeLink {
                q_deg: 35.0,
                ..Default::default()
            }
            .scene(Setting {
                apply_at,
                ..Default::default()
            });
            free.options.dt = dt;
            worst = worst.max(residual(&free.run().unwrap()));
            for joint in [Joint::Free, Joint::Locked, spring] {
                let mut chain = Chain {
                    q_deg: [-16.72, 13.48],
                    pin_mass: 0.005,
                    joint: if joint == spring { small_spring } else { joint },
                    ..Default::default()
                }
                .scene(Setting {
                    apply_at,
                    ..thesis_setting(&table_4_4_case_1())
                });
                chain.options.end = EndCondition::AllStops;
                chain.options.dt = dt;
                let out = chain.run().unwrap();
                assert!(out.contacts.iter().all(|c| c.stopped));
                worst = worst.max(residual(&out));
                let mut leg = Leg {
                    joints: [joint; 3],
                    ..Default::default()
                }
                .scene(Setting {
                    apply_at,
                    ..leg_setting()
                });
                leg.options.dt = dt;
                let out = leg.run().unwrap();
                assert!(out.contacts[0].stopped);
                if joint == spring {
                    assert!(
                        out.dissipated > 1.0,
                        "dampers dissipate: {}",
                        out.dissipated
                    );
                }
                worst = worst.max(residual(&out));
                leg_w = leg_w.max(residual(&out));
            }
        }
        assert!(worst < 1e-6, "dt {dt}: energy residual {worst:e}");
        leg_worst.push(leg_w);
    }
    // Integration error, not a modelling leak: it shrinks with the step.
    assert!(leg_worst[1] < 0.5 * leg_worst[0], "{leg_worst:?}");
}

/// A locked joint keeps its angle to round-off; a spring-damper with k = c = 0 is a free
/// joint; with the pin's mass zero the root passes no force to link 1.
#[test]
fn joints_behave_as_declared() {
    let leg_preset = Leg::default();
    let mut leg = leg_preset.scene(leg_setting());
    leg.options.record = Record {
        state: true,
        forces: true,
        ..Default::default()
    };
    let out = leg.run().unwrap();
    let a = leg_preset.angles();
    for (i, name) in ["q3", "q4", "q5"].iter().enumerate() {
        let parent = series(&out, &format!("q{}", 2 + i));
        let child = series(&out, name);
        let rest = a[i + 1] - a[i];
        for (p, c) in parent.iter().zip(child) {
            assert!((c - p - rest).abs() < 1e-12, "joint {i}: {}", c - p - rest);
        }
    }
    // Locked joints carry torque; the hip holds the trunk.
    assert!(out.joints[3].torque_max > 1.0);

    let zero = Joint::Spring {
        k: 0.0,
        c: 0.0,
        rest: 0.0,
    };
    let free = Leg {
        joints: [Joint::Free; 3],
        ..Default::default()
    }
    .scene(leg_setting())
    .run()
    .unwrap();
    let soft = Leg {
        joints: [zero; 3],
        ..Default::default()
    }
    .scene(leg_setting())
    .run()
    .unwrap();
    assert_eq!(free.contacts[0].t_s, soft.contacts[0].t_s);
    assert_eq!(free.contacts[0].depth, soft.contacts[0].depth);

    let mut chain = Chain::default().scene(thesis_setting(&[Coefficients::TABLE_3_4_VERTICAL; 2]));
    chain.options.record = Record {
        forces: true,
        ..Default::default()
    };
    let out = chain.run().unwrap();
    let fx = series(&out, "joint0.Fx");
    let fy = series(&out, "joint0.Fy");
    let pin = series(&out, "joint1.Fx");
    let scale = pin.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.1, "the pin carries force: {scale}");
    for (x, y) in fx.iter().zip(fy) {
        assert!(x.abs() + y.abs() < 1e-12 * scale.max(1.0));
    }
}

/// With a pin of mass m_p, the root passes to link 1 exactly what accelerates the pin:
/// F = -m_p (a_pin - g) (Newton on the pin, from the accelerations alone).
#[test]
fn pin_force_balances_the_pin_mass() {
    let chain = Chain {
        pin_mass: 0.01,
        q_deg: [-16.72, 13.48],
        ..Default::default()
    }
    .scene(thesis_setting(&table_4_4_case_1()));
    let model = chain.model::<4>();
    let (q0, qd0) = chain.initial_state::<4>();
    // Some way into the impact: take the state after the run's first stop, evaluated fresh.
    let mut opts = chain.options;
    opts.t_end = 0.01;
    opts.end = EndCondition::Time;
    opts.record = Record {
        state: true,
        ..Default::default()
    };
    let out = solve(&model, q0, qd0, &opts).unwrap();
    let last = |n: &str| *series(&out, n).last().unwrap();
    let q = SVector::<f64, 4>::new(last("q0"), last("q1"), last("q2"), last("q3"));
    let qd = SVector::<f64, 4>::new(last("qd0"), last("qd1"), last("qd2"), last("qd3"));
    let mut modes = [_granrs::dynamics::ContactMode::default(); _granrs::dynamics::MAX_CONTACTS];
    for m in modes.iter_mut().take(2) {
        m.in_contact = true;
        m.sx = _granrs::dynamics::Slip::Neg;
        m.sy = _granrs::dynamics::Slip::Neg;
    }
    let e = model.eval(&q, &qd, &modes);
    let f = model.joint_forces(&q, &qd, &e, &modes);
    let expect = -0.01 * (Vector2::new(e.qdd[0], e.qdd[1]) - Vector2::new(0.0, -9.81));
    assert!(
        (f[0] - expect).norm() < 1e-9 * expect.norm().max(1e-3),
        "{} vs {expect}",
        f[0]
    );
}
