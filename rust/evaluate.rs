//! The force law on its own, over many contact states at once: for users who couple
//! granrs's resistance force to their own simulator (`granrs.resistance_force`).
//!
//! A state is a rod of length L and diameter d_c whose tip is at depth `d`, at angle `q`
//! from the vertical, with tip velocity `v_T` and angular velocity `omega = dq/dt`. The
//! immersed length is `l = min(d / cos q, L)`, the immersed centroid `E = T + (l/2) e`
//! with `e = (sin q, cos q)`, and its velocity `v_E = v_T + (l/2) omega (cos q, -sin q)`
//! (MODEL.md, "Contact geometry"). The signs of the static terms are the thesis's plain
//! sign of `v_E` ("raw") or `tanh(v_E / eps)` ("smooth"); the held signs of the solver's
//! "modes" need a time history and are not offered here.

use nalgebra::Vector2;

use crate::dynamics::{raw_sign, terms_on};
use crate::forces::drag::Drag;
use crate::forces::static_h::StaticH;
use crate::forces::static_v::StaticV;
use crate::forces::{AnyTerm, Boundary, ContactState, ForceSet, Frame, Medium, Outline};

/// Inputs per state, in this order.
pub const INPUTS: [&str; 9] = [
    "depth", "q_deg", "vx", "vy", "omega", "eta_h", "eta_d", "eta_v", "lam",
];
/// Outputs per state, in this order.
pub const OUTPUTS: [&str; 10] = [
    "F_x", "F_y", "F_dx", "F_dy", "F_sh", "F_sv", "l", "E_x", "E_y", "v_E_norm",
];

/// How the static terms take the sign of the velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sign {
    /// The thesis's sign(): -1, 0 or +1.
    Raw,
    /// tanh(v / eps).
    Smooth(f64),
}

/// The rod and the sand, shared by every state.
#[derive(Debug, Clone, PartialEq)]
pub struct RodSetup {
    /// Rod length L [m] (also L_ref).
    pub length: f64,
    /// Rod diameter d_c [m] (also the width w).
    pub diameter: f64,
    /// The sand.
    pub medium: Medium,
    /// The terms that act (the thesis's contact terms; each state brings their parameters).
    pub forces: ForceSet,
    /// Sign model.
    pub sign: Sign,
}

/// Evaluate one state: `input` in the order of [`INPUTS`] (angle in degrees), `out` in the
/// order of [`OUTPUTS`]. The forces come from the same term evaluation as a run's
/// ([`terms_on`]), with this state's coefficients.
pub fn evaluate(setup: &RodSetup, input: [f64; 9], out: &mut [f64]) {
    let [depth, q_deg, vx, vy, omega, eta_h, eta_d, eta_v, lam] = input;
    let q = q_deg.to_radians();
    let (s, c) = q.sin_cos();
    let depth = depth.max(0.0);
    let l = if depth >= setup.length * c {
        setup.length
    } else {
        depth / c
    };
    let half = 0.5 * l;
    let v_e = Vector2::new(vx + half * omega * c, vy - half * omega * s);
    let mut terms = setup.forces.per_contact[0];
    for t in terms.iter_mut() {
        *t = match *t {
            AnyTerm::Drag(_) => AnyTerm::Drag(Drag { eta_d }),
            AnyTerm::StaticH(_) => AnyTerm::StaticH(StaticH { eta_h }),
            AnyTerm::StaticV(_) => AnyTerm::StaticV(StaticV { eta_v, lam }),
            other => other,
        };
    }
    let sign = match setup.sign {
        Sign::Raw => [raw_sign(v_e.x), raw_sign(v_e.y)],
        Sign::Smooth(eps) => [(v_e.x / eps).tanh(), (v_e.y / eps).tanh()],
    };
    // A_r |v_E| = d_c l |e x v_E|: smooth at v_E = 0, no division.
    let cross = (s * v_e.y - c * v_e.x).abs();
    // T at depth d; omega = dq/dt turns e clockwise.
    let boundary = Boundary {
        frame: Frame {
            origin: [0.0, -depth],
            v: [vx, vy],
            omega: -omega,
            axis: [s, c],
        },
        outline: Outline::Rod {
            diameter: setup.diameter,
            immersed: l,
        },
        apply: [0.0, -depth],
        centroid: [half * s, -depth + half * c],
        v_centroid: [v_e.x, v_e.y],
        held: [0.0; 2],
    };
    let state = ContactState {
        depth,
        volume: std::f64::consts::FRAC_PI_4 * setup.diameter * setup.diameter * l,
        width: setup.diameter,
        l_ref: setup.length,
        v: [v_e.x, v_e.y],
        area_speed: setup.diameter * l * cross,
        sign,
        boundary: Some(&boundary),
    };
    let mut f = crate::dynamics::ContactForce::default();
    if depth > 0.0 {
        terms_on(
            &setup.forces,
            &terms,
            &state,
            &setup.medium,
            &mut f,
            &mut [0.0; 2],
        );
    }
    let total = f.total();
    let values = [
        total.x,
        total.y,
        f.dynamic.x,
        f.dynamic.y,
        f.statics.x,
        f.statics.y,
        l,
        half * s,
        half * c,
        v_e.norm(),
    ];
    out[..values.len()].copy_from_slice(&values);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup(sign: Sign) -> RodSetup {
        RodSetup {
            length: 0.19,
            diameter: 0.0127,
            medium: Medium::default(),
            forces: ForceSet::thesis(&[crate::forces::Coefficients::TABLE_3_4_VERTICAL]),
            sign,
        }
    }

    #[test]
    fn vertical_rod_at_rest_feels_only_what_its_sign_allows() {
        let mut out = [0.0; 10];
        // v = 0: the raw sign is 0, so no static force at all, and no drag.
        evaluate(
            &setup(Sign::Raw),
            [0.05, 0.0, 0.0, 0.0, 0.0, 6.5, 15.2, 248.0, 0.106],
            &mut out,
        );
        assert_eq!(&out[..6], &[0.0; 6]);
        // Sinking: F_sv pushes up by eta_v (d/L)^lam g rho V.
        evaluate(
            &setup(Sign::Raw),
            [0.05, 0.0, 0.0, -1.0, 0.0, 6.5, 15.2, 248.0, 0.106],
            &mut out,
        );
        let v = std::f64::consts::FRAC_PI_4 * 0.0127f64.powi(2) * 0.05;
        let by_hand = 248.0 * (0.05f64 / 0.19).powf(0.106) * 9.81 * 1650.0 * v;
        assert!((out[5] - by_hand).abs() < 1e-12 * by_hand);
        assert_eq!(out[6], 0.05);
    }

    #[test]
    fn spin_moves_the_centroid() {
        let mut out = [0.0; 10];
        // Tip at rest, rod turning: E moves at (l/2) omega (cos q, -sin q).
        evaluate(
            &setup(Sign::Smooth(1e-3)),
            [0.02, 30.0, 0.0, 0.0, 2.0, 5.0, 10.0, 50.0, 0.2],
            &mut out,
        );
        let q = 30f64.to_radians();
        let l = 0.02 / q.cos();
        let speed = 0.5 * l * 2.0;
        assert!((out[9] - speed).abs() < 1e-15);
        assert!((out[7] - 0.5 * l * q.sin()).abs() < 1e-15);
        // The drag opposes v_E.
        let v_e = Vector2::new(speed * q.cos(), -speed * q.sin());
        assert!(out[2] * v_e.x + out[3] * v_e.y < 0.0);
    }
}
