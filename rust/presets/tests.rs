//! The presets' tests: each reads exactly the fields it declares, and a new preset is one
//! file and one line.

use std::cell::RefCell;

use super::*;
use crate::spec::{SceneSpec, Value};

/// A spec that writes down every field a preset reads of it (besides its setting).
struct Reads<'a> {
    spec: &'a SceneSpec,
    seen: RefCell<Vec<String>>,
}

impl Reads<'_> {
    fn saw(&self, field: &str) {
        self.seen.borrow_mut().push(field.to_string());
    }
}

impl Fields for Reads<'_> {
    fn f64(&self, field: &str) -> Result<f64> {
        self.saw(field);
        Fields::f64(self.spec, field)
    }
    fn opt_f64(&self, field: &str) -> Result<Option<f64>> {
        self.saw(field);
        Fields::opt_f64(self.spec, field)
    }
    fn f64_or(&self, field: &str, default: f64) -> Result<f64> {
        self.saw(field);
        Fields::f64_or(self.spec, field, default)
    }
    fn joint(&self, field: &str, default: Joint) -> Result<Joint> {
        self.saw(field);
        Fields::joint(self.spec, field, default)
    }
    fn choice<'a>(&'a self, field: &str, default: &'a str, allowed: &[&str]) -> Result<&'a str> {
        self.saw(field);
        Fields::choice(self.spec, field, default, allowed)
    }
    fn setting(&self, n_contacts: usize) -> Result<Setting> {
        Fields::setting(self.spec, n_contacts)
    }
}

/// The thesis's free link scene as a spec, with `body` set to `preset`.
fn spec_of(preset: &str) -> SceneSpec {
    let mut s = crate::spec::free_link_spec();
    s.set("body", Value::Str(preset.to_string().into()));
    s
}

/// A preset's `fields` are the fields its build reads, no more and no fewer: the list that
/// says which bodies a field applies to (the scene's field table, `granrs.Scene`) cannot
/// drift from what the preset reads.
#[test]
fn every_preset_reads_exactly_the_fields_it_declares() {
    for p in PRESETS.iter() {
        let spec = spec_of(p.name);
        let reads = Reads {
            spec: &spec,
            seen: RefCell::new(Vec::new()),
        };
        (p.build)(&reads).unwrap_or_else(|e| panic!("{}: {e}", p.name));
        let mut seen = reads.seen.into_inner();
        seen.sort_unstable();
        seen.dedup();
        let mut declared: Vec<String> = p.fields.iter().map(|f| f.to_string()).collect();
        declared.sort_unstable();
        assert_eq!(seen, declared, "{}", p.name);
    }
}

/// A new preset is one file (`plate.rs`) and its line in [`PRESETS`]: the spec knows its
/// name, the field table says which fields apply to it, it builds, runs, and its errors
/// name the scene's fields.
#[test]
fn a_new_preset_is_one_file_and_one_line() {
    assert!(names().contains(&"plate"));
    assert!(bodies_of("length").contains(&"plate"));
    assert!(!bodies_of("q_deg").contains(&"plate"));
    let mut spec = spec_of("plate");
    spec.set("v0", Value::Num(1.0));
    let scene = spec.build().unwrap();
    assert_eq!(scene.contacts.len(), 1);
    let out = scene.run().unwrap();
    // Level, dropped at 1 m/s under the thesis's law: it sinks and stops, its lower face
    // below the surface.
    assert!(out.contacts[0].stopped, "{:?}", out.status);
    assert!(out.contacts[0].depth > 0.0);
    spec.set("length", Value::Num(-1.0));
    match spec.build() {
        Err(GranrsError::InvalidParameter { field, .. }) => assert_eq!(field, "length"),
        other => panic!("{other:?}"),
    }
    spec.set("body", Value::Str("plates".into()));
    match spec.build() {
        Err(GranrsError::UnknownName { field, allowed, .. }) => {
            assert_eq!(field, "body");
            assert!(allowed.contains("plate"), "{allowed}");
        }
        other => panic!("{other:?}"),
    }
}
