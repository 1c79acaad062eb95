//! What a run is, body by body: the body, its contacts, the medium, the force terms (with
//! their parameters), the initial state, the time step, the end condition and the outputs
//! wanted. One file per body model (`free_link.rs`, `chain.rs`, `leg.rs`); here, the checks
//! they share and [`AnyScene`].
//!
//! Field names are those of the Python `granrs.Scene`, so that an error names the field the
//! user wrote. Angles are in degrees here (`*_deg`, the API edge) and radians inside the
//! engine.

use nalgebra::SVector;

use crate::body::Joint;
use crate::dynamics::{Model, SignModel};
use crate::error::{check_finite, check_range, fmt_num, GranrsError, Result};
use crate::forces::Medium;
use crate::integrate::{Method, Outcome, SolveOptions, RTOL_MIN};
use crate::spec::fields::{MAX_SAMPLES, MAX_STEPS};

pub mod chain;
pub mod free_link;
pub mod leg;
pub mod linkage;

pub use chain::{chain_defaults, ChainScene};
pub use free_link::{free_link_defaults, FreeLinkScene};
pub use leg::{leg_defaults, LegScene, Segment, LEG_JOINTS};
pub use linkage::{
    ContactShape, ContactSpec, JointSpec, LinkSpec, LinkageScene, PartNames, RootKind, RootSpec,
    MAX_LINKS,
};

/// Validate the medium.
pub fn validate_medium(m: &Medium) -> Result<()> {
    check_range("rho_g", m.rho_g, 0.0, true)?;
    check_range("g", m.g, 0.0, false)?;
    Ok(())
}

/// Validate step, end time and sign model.
pub fn validate_options(o: &SolveOptions, sign_model: &SignModel) -> Result<()> {
    check_range("dt", o.dt, 0.0, true)?;
    check_range("t_end", o.t_end, 0.0, true)?;
    // The work a run may ask for is bounded (the field table's MAX_STEPS, MAX_SAMPLES).
    let steps = o.t_end / o.dt;
    if steps > MAX_STEPS {
        return Err(GranrsError::InvalidParameter {
            field: "t_end".into(),
            value: o.t_end,
            allowed: format!(
                "t_end / dt <= {MAX_STEPS:e} steps, so t_end <= {} s at dt = {} s (it asks \
                 for {} steps); shorten t_end or lengthen dt",
                fmt_num(MAX_STEPS * o.dt),
                fmt_num(o.dt),
                fmt_num(steps)
            ),
        });
    }
    let stride = o.record.stride.max(1) as f64;
    if o.record.any() && steps / stride > MAX_SAMPLES {
        return Err(GranrsError::InvalidParameter {
            field: "record_stride".into(),
            value: stride,
            allowed: format!(
                "t_end / dt / record_stride <= {MAX_SAMPLES:e} recorded samples, so \
                 record_stride >= {} for t_end / dt = {} steps",
                (steps / MAX_SAMPLES).ceil(),
                fmt_num(steps)
            ),
        });
    }
    if let SignModel::Smooth { eps } = sign_model {
        check_range("smooth_eps", *eps, 0.0, true)?;
    }
    if let Method::Dopri5 { rtol, atol } = o.method {
        check_range("rtol", rtol, 0.0, true)?;
        if rtol < RTOL_MIN {
            return Err(GranrsError::InvalidParameter {
                field: "rtol".into(),
                value: rtol,
                allowed: format!(
                    ">= {RTOL_MIN:.1e} (100 x f64's epsilon: a smaller relative tolerance is \
                     below what the arithmetic resolves)"
                ),
            });
        }
        check_range("atol", atol, 0.0, true)?;
    }
    Ok(())
}

/// Check a joint's parameters; `field` names it.
fn validate_joint(field: &str, j: &Joint) -> Result<()> {
    if let Joint::Spring { k, c, rest } = j {
        check_range(&format!("{field}.k"), *k, 0.0, false)?;
        check_range(&format!("{field}.c"), *c, 0.0, false)?;
        check_finite(&format!("{field}.rest"), *rest)?;
    }
    Ok(())
}

/// Largest `h lambda` the fixed-step RK4 is given for a joint's fastest mode (its stability
/// limit is 2.78 on the negative real axis and 2.83 on the imaginary one).
const RK4_STABLE: f64 = 2.5;

/// Check that the fixed-step RK4 resolves every spring-damper joint at the initial posture:
/// for the joint's relative rate `a . qdot` (a = e_child - e_parent) the damper's rate is
/// `c a^T M^-1 a` and the spring's angular frequency `sqrt(k a^T M^-1 a)`; each times `dt`
/// must stay below [`RK4_STABLE`]. A stiffer joint is refused before any work starts, with the
/// largest value that would run (or use a smaller `dt`, or `method="dopri5"`).
fn validate_joint_stiffness<const N: usize>(
    model: &Model<N>,
    q0: &SVector<f64, N>,
    options: &SolveOptions,
    names: &[&str],
) -> Result<()> {
    if options.method != Method::Rk4 || !model.forces.joint_springs {
        return Ok(());
    }
    let pose = model.mechanism.pose(q0);
    let Some(chol) = model.mechanism.mass_matrix(&pose).cholesky() else {
        return Ok(());
    };
    for (i, link) in model.mechanism.links.iter().enumerate() {
        let (Some(p), Joint::Spring { k, c, .. }) = (link.parent, link.joint) else {
            continue;
        };
        let mut a = SVector::<f64, N>::zeros();
        a[2 + i] = 1.0;
        a[2 + p] = -1.0;
        let inv_inertia = a.dot(&chol.solve(&a));
        let name = names.get(i).copied().unwrap_or("joint");
        let dt = options.dt;
        if c * inv_inertia * dt > RK4_STABLE {
            return Err(GranrsError::InvalidParameter {
                field: format!("{name}.c"),
                value: c,
                allowed: format!(
                    "c <= {:.4e} N m s/rad at dt = {dt} s (the damper's rate c / I_eff, \
                     I_eff = {:.3e} kg m^2, must stay under {RK4_STABLE} / dt for RK4); use a \
                     smaller dt or method='dopri5'",
                    RK4_STABLE / (inv_inertia * dt),
                    1.0 / inv_inertia
                ),
            });
        }
        if (k * inv_inertia).sqrt() * dt > RK4_STABLE {
            return Err(GranrsError::InvalidParameter {
                field: format!("{name}.k"),
                value: k,
                allowed: format!(
                    "k <= {:.4e} N m/rad at dt = {dt} s (the spring's frequency \
                     sqrt(k / I_eff), I_eff = {:.3e} kg m^2, must stay under {RK4_STABLE} / dt \
                     for RK4); use a smaller dt or method='dopri5'",
                    (RK4_STABLE / dt).powi(2) / inv_inertia,
                    1.0 / inv_inertia
                ),
            });
        }
    }
    Ok(())
}

/// Check an angle from the vertical at which a rod's tip meets the sand first.
fn validate_rod_angle(field: &str, q_deg: f64) -> Result<()> {
    check_finite(field, q_deg)?;
    if q_deg.abs() >= 90.0 {
        return Err(GranrsError::InvalidParameter {
            field: field.into(),
            value: q_deg,
            allowed: format!("-90 < {field} < 90 (the tip must meet the sand first)"),
        });
    }
    Ok(())
}

/// Check the fields every body shares: medium, initial motion and numerics.
fn validate_common(
    medium: &Medium,
    v0: f64,
    depth0: f64,
    vx0: f64,
    options: &SolveOptions,
    sign_model: &SignModel,
) -> Result<()> {
    validate_medium(medium)?;
    check_range("v0", v0, 0.0, false)?;
    check_range("depth0", depth0, 0.0, false)?;
    check_finite("vx0", vx0)?;
    validate_options(options, sign_model)
}

/// Any of the body models.
#[derive(Debug, Clone, PartialEq)]
pub enum AnyScene {
    /// The free link.
    FreeLink(FreeLinkScene),
    /// The two-link chain.
    Chain(ChainScene),
    /// The leg.
    Leg(LegScene),
    /// A user-defined linkage.
    Linkage(LinkageScene),
}

impl AnyScene {
    /// Check every field.
    pub fn validate(&self) -> Result<()> {
        match self {
            AnyScene::FreeLink(s) => s.validate(),
            AnyScene::Chain(s) => s.validate(),
            AnyScene::Leg(s) => s.validate(),
            AnyScene::Linkage(s) => s.validate(),
        }
    }

    /// The body as a linkage: a built-in body's links, joints, contacts and initial state
    /// (names: the result's link and joint names), or the linkage itself.
    pub fn linkage(&self) -> Result<LinkageScene> {
        match self {
            AnyScene::FreeLink(s) => {
                let (q0, qd0) = s.initial_state();
                let names = PartNames {
                    links: &["rod"],
                    joints: &["root"],
                    contacts: &["rod"],
                    lengths: &[s.length],
                };
                LinkageScene::from_model(&s.model(), &q0, &qd0, &names, &s.options)
            }
            AnyScene::Chain(s) => {
                let (q0, qd0) = s.initial_state();
                let names = PartNames {
                    links: &["link1", "link2"],
                    joints: &["pin_on_link1", "pin"],
                    contacts: &["link1", "link2"],
                    lengths: &[s.length, s.length],
                };
                LinkageScene::from_model(&s.model(), &q0, &qd0, &names, &s.options)
            }
            AnyScene::Leg(s) => {
                let (q0, qd0) = s.initial_state();
                let seg = s.segments();
                let names = PartNames {
                    links: &["foot", "shank", "thigh", "trunk"],
                    joints: &["root", "ankle", "knee", "hip"],
                    contacts: &["sole"],
                    lengths: &[seg[0].length, seg[1].length, seg[2].length, seg[3].length],
                };
                LinkageScene::from_model(&s.model(), &q0, &qd0, &names, &s.options)
            }
            AnyScene::Linkage(s) => Ok(s.clone()),
        }
    }

    /// Validate and run.
    pub fn run(&self) -> Result<Outcome> {
        match self {
            AnyScene::FreeLink(s) => s.run(),
            AnyScene::Chain(s) => s.run(),
            AnyScene::Leg(s) => s.run(),
            AnyScene::Linkage(s) => s.run(),
        }
    }
}
