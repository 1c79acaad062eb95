//! The free link end to end (issue 2): exact vertical drop, event location, statuses.

mod common;

use _granrs::bodies::LinkageScene;
use _granrs::integrate::{EndCondition, Status};
use _granrs::presets::free_link::FreeLink;
use common::{drop_at, exact_vertical_depth, table_3_4_vertical, thesis_setting};

/// The vertical rod dropped at `v0` and the scene it builds.
fn vertical(v0: f64) -> (FreeLink, LinkageScene) {
    let rod = FreeLink {
        start: drop_at(v0),
        ..Default::default()
    };
    let scene = rod.scene(thesis_setting(&[table_3_4_vertical()]));
    (rod, scene)
}

/// Issue 2 acceptance: the vertical drop matches the exact energy answer of MODEL.md.
#[test]
fn vertical_drop_matches_exact_energy_depth() {
    for v0 in [0.3, 1.0, 2.214, 5.0] {
        let (rod, s) = vertical(v0);
        let out = s.run().unwrap();
        assert_eq!(out.status, Status::Stopped);
        let exact = exact_vertical_depth(&rod, &s);
        let got = out.contacts[0].depth;
        let rel = (got - exact).abs() / exact;
        println!(
            "v0 = {v0}: depth {got:.12} exact {exact:.12} rel.err {rel:.2e} t_s {:.9}",
            out.contacts[0].t_s
        );
        assert!(rel < 1e-6, "v0 = {v0}: rel. error {rel}");
    }
}

/// The stop time comes from the located event, not the grid: it is not a multiple of dt.
#[test]
fn stop_is_located_inside_the_step() {
    let out = vertical(2.214).1.run().unwrap();
    let t_s = out.contacts[0].t_s;
    let steps = t_s / 1e-4;
    assert!(
        (steps - steps.round()).abs() > 1e-6,
        "t_s = {t_s} sits on the grid"
    );
}

/// A body that cannot stop before t_end reports a clean status, not an error.
#[test]
fn not_stopped_is_a_status() {
    let mut s = vertical(2.0).1;
    s.options.t_end = 0.005;
    let out = s.run().unwrap();
    assert_eq!(out.status, Status::NotStopped);
    assert!(out.contacts[0].t_s.is_nan());
    assert!(out.t_final <= 0.005 + 1e-15);
    s.options.end = EndCondition::Time;
    assert_eq!(s.run().unwrap().status, Status::EndTime);
}
