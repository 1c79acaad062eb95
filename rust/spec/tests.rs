//! The spec's tests: a spec builds the scene the Rust defaults build, errors name the field,
//! and every field has its own slot.

use super::*;

/// (Tests.) The Table 3.5 row q = 45 deg as a spec (what `granrs.Scene().to_dict()` sends).
pub(crate) fn free_link_spec() -> SceneSpec {
    let mut s = SceneSpec::new();
    for (k, v) in [
        ("length", 0.19),
        ("diameter", 0.0127),
        ("mass", 0.184),
        ("rho_g", 1650.0),
        ("g", 9.81),
        ("q_deg", 45.0),
        ("v0", 2.27),
        ("dt", 1e-4),
        ("t_end", 1.0),
        ("smooth_eps", 1e-3),
    ] {
        s.set(k, Value::Num(v));
    }
    for (k, v) in [
        ("body", "free_link"),
        ("apply_at", "tip"),
        ("sign_model", "modes"),
        ("method", "rk4"),
        ("end", "first_stop"),
    ] {
        s.set(k, Value::Str(v.into()));
    }
    // Table 3.4, row q = 45 deg.
    let row = Coefficients {
        eta_h: 5.5,
        eta_d: 11.0,
        eta_v: 53.0,
        lambda: 0.25,
    };
    s.set("forces", Value::Terms(ForceSet::thesis(&[row]).specs()));
    s
}

#[test]
fn spec_builds_the_same_scene_as_rust_defaults() {
    let AnyScene::FreeLink(built) = free_link_spec().build().unwrap() else {
        panic!("not a free link");
    };
    let mut by_hand = FreeLinkScene {
        q_deg: 45.0,
        v0: 2.27,
        forces: ForceSet::thesis(&[Coefficients {
            eta_h: 5.5,
            eta_d: 11.0,
            eta_v: 53.0,
            lambda: 0.25,
        }]),
        ..Default::default()
    };
    by_hand.options.record.stride = 1; // the spec's record_stride default
    assert_eq!(built, by_hand);
}

#[test]
fn errors_name_the_field() {
    let mut s = free_link_spec();
    s.set("mass", Value::Bool(true));
    match s.build() {
        Err(GranrsError::WrongType { field, got, .. }) => {
            assert_eq!(field, "mass");
            assert_eq!(got, "a bool");
        }
        other => panic!("{other:?}"),
    }
    let mut s = free_link_spec();
    s.set("mass", Value::Num(-1.0));
    assert!(
        matches!(s.build(), Err(GranrsError::InvalidParameter { field, .. }) if field == "mass")
    );
    let mut s = free_link_spec();
    s.set(
        "forces",
        Value::Terms(vec![TermSpec::new("drag", &[("eta_d", -1.0)])]),
    );
    assert!(
        matches!(s.build(), Err(GranrsError::InvalidParameter { field, .. }) if field == "drag.eta_d")
    );
    let mut s = free_link_spec();
    s.set("forces", Value::Terms(vec![TermSpec::new("wind", &[])]));
    assert!(
        matches!(s.build(), Err(GranrsError::UnknownName { field, value, .. }) if field == "term" && value == "wind")
    );
    let mut s = free_link_spec();
    s.set("forces", Value::Num(1.0));
    assert!(matches!(s.build(), Err(GranrsError::WrongType { field, .. }) if field == "forces"));
    let mut s = free_link_spec();
    s.set("body", Value::Str("tripod".into()));
    assert!(matches!(s.build(), Err(GranrsError::UnknownName { field, .. }) if field == "body"));
}

#[test]
fn scene_fields_have_their_own_slots() {
    assert!(SCENE_FIELDS.is_sorted_by(|a, b| a < b));
    for (i, name) in SCENE_FIELDS.iter().enumerate() {
        assert_eq!(field_slot(name), Some(i));
    }
    assert_eq!(field_slot("zzz"), None);
    // Known and other names, set twice, read back (the last value wins).
    let mut s = SceneSpec::from_pairs(vec![
        ("mass".into(), Value::Num(1.0)),
        ("zeta".into(), Value::Num(2.0)),
        ("alpha".into(), Value::Num(3.0)),
        ("mass".into(), Value::Num(4.0)),
    ]);
    s.set("zeta", Value::Num(5.0));
    assert_eq!(s.get("mass"), Some(&Value::Num(4.0)));
    assert_eq!(s.get("zeta"), Some(&Value::Num(5.0)));
    assert_eq!(s.get("alpha"), Some(&Value::Num(3.0)));
    assert_eq!(s.get("length"), None);
    assert_eq!(s.get("beta"), None);
}

#[test]
fn springs_are_free_without_the_effect() {
    let mut s = free_link_spec();
    s.set("body", Value::Str("chain".into()));
    s.set("q_deg", Value::Num(20.0));
    s.set(
        "pin_joint",
        Value::Map(vec![
            ("k".into(), Value::Num(1.0)),
            ("c".into(), Value::Num(0.01)),
        ]),
    );
    let AnyScene::Chain(with) = s.build().unwrap() else {
        panic!()
    };
    assert!(matches!(with.joint, Joint::Spring { .. }));
    s.set(
        "forces",
        Value::Terms(vec![
            TermSpec::new("gravity", &[]),
            TermSpec::new("static_v", &[]),
        ]),
    );
    let AnyScene::Chain(without) = s.build().unwrap() else {
        panic!()
    };
    // The joint keeps its spring-damper; without the `joint_springs` term it exerts
    // nothing (the engine reads the force set, not a rewritten joint).
    assert!(matches!(without.joint, Joint::Spring { .. }));
    assert!(!without.forces.joint_springs);
    assert_eq!(without.forces.names, vec!["gravity", "static_v"]);
}
