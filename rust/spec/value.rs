//! A field's value as plain data, and the words a scene uses.

use std::borrow::Cow;

use crate::forces::TermSpec;

/// A field's value, as plain data.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// Absent or `None`.
    None,
    /// A boolean (never a valid number: `True` is not 1.0 here).
    Bool(bool),
    /// A real number.
    Num(f64),
    /// A string (see [`word`]).
    Str(Cow<'static, str>),
    /// A list of names.
    Names(Vec<Cow<'static, str>>),
    /// A mapping (coefficients, a spring-damper).
    Map(Vec<(Cow<'static, str>, Value)>),
    /// A list of force terms, each with its parameters.
    Terms(Vec<TermSpec>),
    /// A list of other values (a linkage's elements, a point's coordinates).
    List(Vec<Value>),
    /// Anything else, by its type name (for the error message).
    Other(String),
}

impl Value {
    /// What the value is, for error messages.
    pub fn kind(&self) -> String {
        match self {
            Value::None => "None".into(),
            Value::Bool(_) => "a bool".into(),
            Value::Num(_) => "a number".into(),
            Value::Str(s) => format!("the string {s:?}"),
            Value::Names(_) => "a list".into(),
            Value::Map(_) => "a mapping".into(),
            Value::Terms(_) => "a list of force terms".into(),
            Value::List(_) => "a list".into(),
            Value::Other(t) => t.clone(),
        }
    }
}

/// `s` as a `'static` string when it is one of the words a scene uses (bodies, models,
/// effects, series, mapping keys), found by a `match`; any other string is copied. A scene's
/// strings then take no allocation.
pub fn word(s: &str) -> Cow<'static, str> {
    macro_rules! words {
        ($($w:literal)*) => {
            match s {
                $($w => Cow::Borrowed($w),)*
                _ => Cow::Owned(s.to_owned()),
            }
        };
    }
    words!(
        "free_link" "chain" "leg" "tip" "centroid" "modes" "raw" "smooth" "rk4" "dopri5"
        "first_stop" "all_stops" "time" "free" "locked" "box" "thesis" "gravity" "drag"
        "static_h" "static_v" "joint_springs" "state" "forces" "energy" "eta_h" "eta_d"
        "eta_v" "lam" "k" "c" "links" "joints" "contacts" "root" "name" "mass" "inertia"
        "length" "com" "q_deg" "omega0" "parent" "child" "at" "kind" "rest_deg" "rate" "shape"
        "link" "diameter" "height" "width" "l_ref" "position" "velocity" "rod" "spring"
        "driven" "pinned" "moving" "arc" "radius" "start_deg" "end_deg" "chords"
    )
}
