//! The one error type of the Rust core.
//!
//! Every variant names the field at fault, so that the Python layer (see
//! `rust/python/mod.rs`) can raise a typed exception that says what is wrong before
//! any simulation runs. An event (a stop, the end time) is an outcome, never an error.

use thiserror::Error;

/// Why a scene was refused or a run failed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum GranrsError {
    /// A numeric field is out of its allowed range (negative mass, NaN speed, ...).
    #[error("invalid value for `{field}`: {} (allowed: {allowed})", fmt_num(*value))]
    InvalidParameter {
        field: String,
        value: f64,
        allowed: String,
    },
    /// A field holds a value of the wrong type (a bool or a string where a number is expected).
    #[error("invalid value for `{field}`: expected {expected}, got {got}")]
    WrongType {
        field: String,
        expected: String,
        got: String,
    },
    /// A name (point of application, sign model, end condition, ...) is unknown.
    #[error("unknown {field} `{value}` (allowed: {allowed})")]
    UnknownName {
        field: String,
        value: String,
        allowed: String,
    },
    /// A force term has no parameter of this name.
    #[error("unknown parameter `{field}` ({allowed}){hint}")]
    UnknownParameter {
        field: String,
        allowed: String,
        hint: String,
    },
    /// A scene is inconsistent as a whole (e.g. a contact on a link that does not exist).
    #[error("invalid scene: `{field}`: {message}")]
    InvalidScene { field: String, message: String },
    /// The state became non-finite during integration. Never raised for valid input
    /// unless the physics itself blows up; the message says when and where.
    #[error("integration failed at t = {t} s: {message}")]
    NonFinite { t: f64, message: String },
    /// A run or a batch's validation was stopped from outside (Ctrl-C, a cancelled sweep):
    /// not a failure (see `integrate::cancel`).
    #[error("interrupted")]
    Cancelled,
}

pub type Result<T> = std::result::Result<T, GranrsError>;

impl GranrsError {
    /// The same error about another field, `rename(field)` (an element's key named within
    /// its element, a linkage's joint named as the preset's field); an error without a
    /// field is returned as it is.
    pub fn map_field(self, rename: impl FnOnce(String) -> String) -> GranrsError {
        use GranrsError::*;
        match self {
            InvalidParameter {
                field,
                value,
                allowed,
            } => InvalidParameter {
                field: rename(field),
                value,
                allowed,
            },
            WrongType {
                field,
                expected,
                got,
            } => WrongType {
                field: rename(field),
                expected,
                got,
            },
            InvalidScene { field, message } => InvalidScene {
                field: rename(field),
                message,
            },
            other => other,
        }
    }
}

/// A number for a message: as written when that is short (`0.184`, `1e-5`, `250`), else
/// in `%.3g`'s spirit (`1e300`, `1.23e-300`), never a line of digits.
pub fn fmt_num(x: f64) -> String {
    let plain = format!("{x}");
    if plain.len() <= 12 {
        return plain;
    }
    let short = format!("{x:e}");
    if short.len() <= 12 {
        return short;
    }
    // Three significant digits, trailing zeros dropped: 1.000e304 -> 1e304.
    let three = format!("{x:.2e}");
    match three.split_once('e') {
        Some((mantissa, exp)) if mantissa.contains('.') => {
            let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
            format!("{mantissa}e{exp}")
        }
        _ => three,
    }
}

/// Check that `value` is finite and at least `min` (or strictly above it).
pub fn check_range(field: &str, value: f64, min: f64, strict: bool) -> Result<f64> {
    let ok = value.is_finite() && if strict { value > min } else { value >= min };
    if ok {
        Ok(value)
    } else {
        Err(out_of_range(field, value, min, strict))
    }
}

/// The error of [`check_range`], kept out of line (every valid scene calls it many times).
#[cold]
#[inline(never)]
fn out_of_range(field: &str, value: f64, min: f64, strict: bool) -> GranrsError {
    GranrsError::InvalidParameter {
        field: field.to_string(),
        value,
        allowed: format!(
            "finite, {} {}{}",
            if strict { ">" } else { ">=" },
            min,
            unit_of(field)
        ),
    }
}

/// ` [unit]` of a scene field from the field table (empty for a field without a unit).
fn unit_of(field: &str) -> String {
    match crate::fields::info(field) {
        Some(f) if !f.unit.is_empty() && f.unit != "-" && !field.contains('.') => {
            format!(" [{}]", f.unit)
        }
        _ => String::new(),
    }
}

/// Check that `value` is finite.
pub fn check_finite(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(not_finite(field, value))
    }
}

/// The error of [`check_finite`], kept out of line.
#[cold]
#[inline(never)]
fn not_finite(field: &str, value: f64) -> GranrsError {
    GranrsError::InvalidParameter {
        field: field.to_string(),
        value,
        allowed: format!("finite{}", unit_of(field)),
    }
}

/// The closest of `candidates` to a mistyped `value` (at most two edits, or a third of its
/// length, away; or one a prefix of the other, `lambda` for `lam`), for "did you mean" in
/// error messages.
pub fn suggest<'a>(value: &str, candidates: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let limit = 2.max(value.chars().count() / 3);
    let prefix = |c: &str| c.len() >= 3 && (value.starts_with(c) || c.starts_with(value));
    candidates
        .map(|c| {
            (
                if prefix(c) {
                    1
                } else {
                    edit_distance(value, c)
                },
                c,
            )
        })
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Levenshtein distance between `a` and `b`.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_the_near_miss_only() {
        let names = ["gravity", "drag", "static_h", "static_v"];
        assert_eq!(suggest("stati_v", names.iter().copied()), Some("static_v"));
        assert_eq!(suggest("drgа", names.iter().copied()), Some("drag"));
        assert_eq!(suggest("wind", names.iter().copied()), None);
        assert_eq!(suggest("lambda", ["eta_v", "lam"].into_iter()), Some("lam"));
    }
}
