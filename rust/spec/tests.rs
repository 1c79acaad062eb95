//! The spec's tests: a spec builds the scene the Rust defaults build, errors name the field,
//! and every field has its own slot.

use super::*;
use crate::presets::free_link::FreeLink;
use crate::presets::Start;

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
    let built = free_link_spec().build().unwrap();
    let mut setting = Setting {
        forces: ForceSet::thesis(&[Coefficients {
            eta_h: 5.5,
            eta_d: 11.0,
            eta_v: 53.0,
            lambda: 0.25,
        }]),
        ..Setting::default()
    };
    setting.options.record.stride = 1; // the spec's record_stride default
    let by_hand = FreeLink {
        q_deg: 45.0,
        start: Start {
            v0: 2.27,
            depth0: 0.0,
            vx0: 0.0,
        },
        ..Default::default()
    }
    .scene(setting);
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
fn step_check_is_true_or_false() {
    // Read by granrs.simulate and granrs.sweep, not by the run; checked with every field.
    for ok in [Value::Bool(true), Value::Bool(false)] {
        let mut s = free_link_spec();
        s.set("step_check", ok);
        assert!(s.build().is_ok());
    }
    for bad in [Value::Num(1.0), Value::Str("yes".into()), Value::None] {
        let mut s = free_link_spec();
        s.set("step_check", bad);
        assert!(
            matches!(s.build(), Err(GranrsError::WrongType { field, .. }) if field == "step_check")
        );
    }
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
    let with = s.build().unwrap();
    assert!(matches!(with.joints[0].joint, Joint::Spring { .. }));
    s.set(
        "forces",
        Value::Terms(vec![
            TermSpec::new("gravity", &[]),
            TermSpec::new("static_v", &[]),
        ]),
    );
    let without = s.build().unwrap();
    // The joint keeps its spring-damper; without the `joint_springs` term it exerts
    // nothing (the engine reads the force set, not a rewritten joint).
    assert!(matches!(without.joints[0].joint, Joint::Spring { .. }));
    let body: Vec<_> = without.forces.body.iter().map(|t| t.info().name).collect();
    assert_eq!(body, vec!["gravity"]);
    assert_eq!(without.forces.names, vec!["gravity", "static_v"]);
}

/// The field a spec's build refuses (or `None` when it builds).
fn refused_field(s: &SceneSpec) -> Option<String> {
    match s.build() {
        Ok(_) => None,
        Err(
            GranrsError::InvalidParameter { field, .. }
            | GranrsError::WrongType { field, .. }
            | GranrsError::UnknownName { field, .. }
            | GranrsError::InvalidScene { field, .. },
        ) => Some(field),
        Err(other) => panic!("{other:?}"),
    }
}

#[test]
fn fields_a_model_or_method_reads_are_checked_whatever_is_chosen() {
    // rk4 and the "modes" sign read none of them; a bad one was kept until switched on.
    for (field, v) in [
        ("smooth_eps", Value::Num(f64::NAN)),
        ("smooth_eps", Value::Num(-1.0)),
        ("rtol", Value::Str("abc".into())),
        ("atol", Value::Num(-1.0)),
        ("rtol", Value::Num(0.0)),
    ] {
        let mut s = free_link_spec();
        s.set(field, v);
        assert_eq!(refused_field(&s).as_deref(), Some(field));
    }
    // Left out (a TOML file may leave them out): nothing to check.
    assert_eq!(refused_field(&free_link_spec()), None);
}

#[test]
fn a_series_listed_twice_is_refused() {
    let mut s = free_link_spec();
    s.set("record", Value::Names(vec!["state".into(), "state".into()]));
    assert_eq!(refused_field(&s).as_deref(), Some("record"));
    s.set(
        "record",
        Value::Names(vec!["state".into(), "energy".into()]),
    );
    assert_eq!(refused_field(&s), None);
}

#[test]
fn the_work_of_a_run_is_bounded_naming_the_field() {
    use crate::fields::{MAX_SAMPLES, MAX_STEPS};
    // Too many steps: t_end is blamed (it was dt), with the limit in short numbers.
    let mut s = free_link_spec();
    s.set("t_end", Value::Num(1e300));
    let e = s.build().unwrap_err();
    assert!(matches!(&e, GranrsError::InvalidParameter { field, .. } if field == "t_end"));
    let text = e.to_string();
    assert!(text.contains("1e9 steps") && text.len() < 250, "{text}");
    // At the bound it builds.
    s.set("t_end", Value::Num(MAX_STEPS * 1e-4));
    assert_eq!(refused_field(&s), None);
    // Recorded samples: bounded too, naming the stride that fits.
    s.set("t_end", Value::Num(MAX_SAMPLES * 1e-4 * 10.0));
    s.set("record", Value::Names(vec!["state".into()]));
    assert_eq!(refused_field(&s).as_deref(), Some("record_stride"));
    s.set("record_stride", Value::Num(10.0));
    assert_eq!(refused_field(&s), None);
}

#[test]
fn parameters_a_contact_shape_or_joint_kind_does_not_read_are_refused() {
    let link = Value::Map(vec![
        ("name".into(), Value::Str("a".into())),
        ("mass".into(), Value::Num(1.0)),
        ("inertia".into(), Value::Num(0.01)),
        ("length".into(), Value::Num(0.3)),
    ]);
    let rod = |extra: Option<(&'static str, f64)>| {
        let mut c = vec![
            ("name".into(), Value::Str("r".into())),
            ("shape".into(), Value::Str("rod".into())),
            ("link".into(), Value::Str("a".into())),
            ("length".into(), Value::Num(0.2)),
            ("diameter".into(), Value::Num(0.01)),
        ];
        if let Some((k, v)) = extra {
            c.push((k.into(), Value::Num(v)));
        }
        Value::Map(c)
    };
    let mut s = free_link_spec();
    s.set("forces", Value::Names(vec![]));
    for (extra, want) in [
        (None, None),
        (Some(("radius", 0.05)), Some("contacts.r.radius")),
        (Some(("chords", 4.0)), Some("contacts.r.chords")),
    ] {
        s.set(
            "body",
            Value::Map(vec![
                ("links".into(), Value::List(vec![link.clone()])),
                ("contacts".into(), Value::List(vec![rod(extra)])),
            ]),
        );
        assert_eq!(refused_field(&s).as_deref(), want);
    }
}

#[test]
fn numbers_in_messages_are_short() {
    use crate::error::fmt_num;
    assert_eq!(fmt_num(0.184), "0.184");
    assert_eq!(fmt_num(1e-4), "0.0001");
    assert_eq!(fmt_num(1e300), "1e300");
    assert_eq!(fmt_num(1e-300), "1e-300");
    assert_eq!(fmt_num(1.0000000000000001e304), "1e304");
    assert_eq!(fmt_num(1.23456789e-300), "1.23e-300");
    assert_eq!(fmt_num(f64::NAN), "NaN");
}

#[test]
fn the_notes_state_the_work_bounds() {
    // The field table's notes (TOML comments, docs, errors) say the bounds the checks use.
    use crate::fields::{info, MAX_SAMPLES, MAX_STEPS};
    let steps = format!("t_end / dt <= {MAX_STEPS:e} steps");
    assert!(info("t_end").unwrap().note.contains(&steps));
    let samples = format!("t_end / dt / record_stride <= {MAX_SAMPLES:e} samples");
    assert!(info("record_stride").unwrap().note.contains(&samples));
}
