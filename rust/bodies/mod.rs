//! What a run is: a linkage (its links, joints, contacts and root, with its initial
//! state), the medium, the force terms (with their parameters), the time step, the end
//! condition and the outputs wanted ([`LinkageScene`]). Every body is one: the thesis's
//! bodies are presets that build it (`crate::presets`). Here, the checks of the numerics.
//!
//! Field names are those of the Python `granrs.Scene`, so that an error names the field the
//! user wrote. Angles are in degrees at the API edge and radians inside the engine.

use nalgebra::SVector;

use crate::dynamics::{Model, SignModel};
use crate::error::{check_range, fmt_num, GranrsError, Result};
use crate::fields::{MAX_SAMPLES, MAX_STEPS};
use crate::forces::Medium;
use crate::integrate::{Method, SolveOptions, RTOL_MIN};

pub mod linkage;

pub use linkage::{
    ContactShape, ContactSpec, JointSpec, LinkSpec, LinkageScene, RootKind, RootSpec, MAX_LINKS,
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

/// Largest `h lambda` the fixed-step RK4 is given for a joint's fastest mode (its stability
/// limit is 2.78 on the negative real axis and 2.83 on the imaginary one).
const RK4_STABLE: f64 = 2.5;

/// Check that the fixed-step RK4 resolves every spring-damper joint at the initial posture:
/// for the joint's relative rate `a . qdot` (a = e_child - e_parent) the damper's rate is
/// `c a^T M^-1 a` and the spring's angular frequency `sqrt(k a^T M^-1 a)`; each times `dt`
/// must stay below [`RK4_STABLE`]. A stiffer joint is refused before any work starts, with the
/// largest value that would run (or use a smaller `dt`, or `method="dopri5"`).
pub(crate) fn validate_joint_stiffness<const N: usize>(
    model: &Model<N>,
    q0: &SVector<f64, N>,
    options: &SolveOptions,
    names: &[&str],
) -> Result<()> {
    if options.method != Method::Rk4 {
        return Ok(());
    }
    // Each jointed link's stiffness and damping as the body terms give them.
    let mut joints = Vec::new();
    for (i, link) in model.mechanism.links.iter().enumerate() {
        if let Some(p) = link.parent {
            let rates = model.forces.body.iter().filter_map(|t| t.joint_rates(link));
            joints.extend(rates.map(|kc| (i, p, kc)));
        }
    }
    if joints.is_empty() {
        return Ok(());
    }
    let pose = model.mechanism.pose(q0);
    let Some(chol) = model.mechanism.mass_matrix(&pose).cholesky() else {
        return Ok(());
    };
    for (i, p, (k, c)) in joints {
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
