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
use crate::forces::{AnyTerm, ContactState, ForceSet, Medium};

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
    let state = ContactState {
        depth,
        volume: std::f64::consts::FRAC_PI_4 * setup.diameter * setup.diameter * l,
        width: setup.diameter,
        l_ref: setup.length,
        v: [v_e.x, v_e.y],
        area_speed: setup.diameter * l * cross,
        sign,
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

/// Rod geoms of another engine (`granrs.mujoco.Sand`): each geom is the free link's rod, and
/// its force and moment come from the free link's own right-hand side
/// ([`Model::eval`](crate::dynamics::Model::eval) of a one-link model with unit mass and
/// inertia, no gravity and the rod's tip at the root), so that every term, its geometry and
/// its point of application are evaluated by the same code as a run's, with no copy of the
/// law. With unit mass and inertia the accelerations are the generalized forces: the force
/// on the rod and its moment about the tip.
pub mod geoms {
    use nalgebra::{SVector, Vector2};

    use crate::body::rod::ApplyAt;
    use crate::body::{Joint, Link, Mechanism, RodContact};
    use crate::dynamics::{
        Contact, ContactMode, DragStiffness, Model, Shape, SignModel, MAX_CONTACTS,
    };
    use crate::error::{check_finite, check_range, GranrsError, Result};
    use crate::forces::{ForceSet, Medium};

    /// The state of one geom, in this order: its tip T (the lower end of its axis) [m], its
    /// unit axis e from the tip along the rod, the tip's velocity [m/s] and the angular
    /// velocity [rad/s] (x right, y up; omega turns e towards +x, dq/dt of the free link).
    pub const STATE: [&str; 7] = ["tip_x", "tip_y", "e_x", "e_y", "v_x", "v_y", "omega"];

    /// What [`RodGeoms::evaluate`] writes per geom, in this order: the force (x, y) [N] and
    /// its moment about the tip [N m] (positive turning e towards +x), the tip's depth and
    /// the immersed length [m], the immersed centroid E [m] and its velocity [m/s], the
    /// dynamic and static sums [N], the static terms' bounds along x and y [N] (the largest
    /// reaction they supply while sticking) and the drag's stiffness |F_d| / |v_E| [kg/s].
    pub const OUTPUTS: [&str; 16] = [
        "F_x", "F_y", "M", "depth", "l", "E_x", "E_y", "v_Ex", "v_Ey", "F_dx", "F_dy", "F_sx",
        "F_sy", "bound_x", "bound_y", "k_drag",
    ];

    /// N rod geoms, each the free link's rod with its own terms, in the same sand.
    #[derive(Debug, Clone)]
    pub struct RodGeoms {
        models: Vec<Model<3>>,
        contacts: Vec<RodContact>,
    }

    impl RodGeoms {
        /// Geoms named `names` with diameters d_c and lengths L (L is also L_ref, as for
        /// the free link), under `forces` (built for `names.len()` contacts: a parameter
        /// is one value for every geom or one per geom). Contact terms only: `gravity` and
        /// `joint_springs` act through the other engine, and are an error naming them.
        pub fn new(
            names: &[String],
            diameters: &[f64],
            lengths: &[f64],
            forces: &ForceSet,
            medium: Medium,
            apply_at: ApplyAt,
            sign_model: SignModel,
        ) -> Result<RodGeoms> {
            if diameters.len() != names.len() || lengths.len() != names.len() {
                return Err(GranrsError::InvalidScene {
                    field: "geoms".into(),
                    message: "one diameter and one length per geom".into(),
                });
            }
            for body in ["gravity", "joint_springs"] {
                if forces.names.contains(&body) {
                    return Err(GranrsError::InvalidScene {
                        field: format!("forces.{body}"),
                        message: format!(
                            "`{body}` acts through the engine's own model (its gravity, its \
                             joints); list only the medium's contact terms"
                        ),
                    });
                }
            }
            check_range("rho_g", medium.rho_g, 0.0, true)?;
            check_range("g", medium.g, 0.0, false)?;
            if let SignModel::Smooth { eps } = sign_model {
                check_range("smooth_eps", eps, 0.0, true)?;
            }
            if sign_model == SignModel::Modes {
                return Err(GranrsError::UnknownName {
                    field: "sign_model".into(),
                    value: "modes".into(),
                    allowed: "raw, smooth (the held signs of \"modes\" need the solver's events)"
                        .into(),
                });
            }
            let mut models = Vec::with_capacity(names.len());
            let mut contacts = Vec::with_capacity(names.len());
            for (i, name) in names.iter().enumerate() {
                check_range(&format!("{name}.diameter"), diameters[i], 0.0, true)?;
                check_range(&format!("{name}.length"), lengths[i], 0.0, true)?;
                let rod = RodContact {
                    link: 0,
                    tip: Vector2::zeros(),
                    length: lengths[i],
                    diameter: diameters[i],
                };
                let mut own = forces.clone();
                own.per_contact = vec![forces.per_contact[i]];
                models.push(Model {
                    mechanism: Mechanism {
                        links: vec![Link {
                            mass: 1.0,
                            inertia: 1.0,
                            com: Vector2::zeros(),
                            parent: None,
                            joint_on_parent: Vector2::zeros(),
                            joint: Joint::Free,
                        }],
                        root_mass: 0.0,
                    },
                    contacts: vec![Contact {
                        shape: Shape::Rod(rod),
                    }],
                    medium,
                    apply_at,
                    sign_model,
                    forces: own,
                });
                contacts.push(rod);
            }
            Ok(RodGeoms { models, contacts })
        }

        /// Number of geoms.
        pub fn len(&self) -> usize {
            self.models.len()
        }

        /// Whether there are none.
        pub fn is_empty(&self) -> bool {
            self.models.is_empty()
        }

        /// Check one geom's state (finite, unit axis to 1e-6), naming the geom and field.
        pub fn check_state(name: &str, state: &[f64; 7]) -> Result<()> {
            for (k, &x) in state.iter().enumerate() {
                check_finite(&format!("{name}.{}", STATE[k]), x)?;
            }
            let norm = state[2].hypot(state[3]);
            if (norm - 1.0).abs() > 1e-6 {
                return Err(GranrsError::InvalidParameter {
                    field: format!("{name}.axis"),
                    value: norm,
                    allowed: "a unit vector in the plane (|e| = 1)".into(),
                });
            }
            if state[3] < 0.0 {
                return Err(GranrsError::InvalidParameter {
                    field: format!("{name}.e_y"),
                    value: state[3],
                    allowed: ">= 0: the tip is the lower end of the axis".into(),
                });
            }
            Ok(())
        }

        /// Evaluate geom `i` at `state` (in the order of [`STATE`]) into `out` (in the
        /// order of [`OUTPUTS`]), through the free link's right-hand side.
        pub fn evaluate(&self, i: usize, state: &[f64; 7], out: &mut [f64]) {
            let model = &self.models[i];
            let [tip_x, tip_y, e_x, e_y, v_x, v_y, omega] = *state;
            let q = SVector::<f64, 3>::new(tip_x, tip_y, e_x.atan2(e_y));
            let qd = SVector::<f64, 3>::new(v_x, v_y, omega);
            let mut modes = [ContactMode::default(); MAX_CONTACTS];
            modes[0].in_contact = true;
            let e = model.eval(&q, &qd, &modes);
            let c = &e.contacts[0];
            let axis = Vector2::new(e_x, e_y);
            let l = self.contacts[i].geometry(tip_y, axis).immersed_length;
            let l = if c.depth > 0.0 { l } else { 0.0 };
            let centroid = Vector2::new(tip_x, tip_y) + (0.5 * l) * axis;
            let k_drag = DragStiffness::of(0, c).k2().sqrt();
            let values = [
                e.qdd[0],
                e.qdd[1],
                e.qdd[2],
                c.depth,
                l,
                centroid.x,
                centroid.y,
                c.v_centroid.x,
                c.v_centroid.y,
                c.force.dynamic.x,
                c.force.dynamic.y,
                c.force.statics.x,
                c.force.statics.y,
                c.bound[0],
                c.bound[1],
                k_drag,
            ];
            out[..values.len()].copy_from_slice(&values);
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;
        use crate::forces::{Coefficients, TermSpec};

        fn thesis_contact_terms() -> ForceSet {
            let c = Coefficients::TABLE_3_4_VERTICAL;
            ForceSet::build(
                &[
                    TermSpec::new("drag", &[("eta_d", c.eta_d)]),
                    TermSpec::new("static_h", &[("eta_h", c.eta_h)]),
                    TermSpec::new("static_v", &[("eta_v", c.eta_v), ("lam", c.lambda)]),
                ],
                1,
            )
            .unwrap()
        }

        #[test]
        fn a_sinking_vertical_rod_feels_the_free_links_force_at_its_tip() {
            let geoms = RodGeoms::new(
                &["foot".into()],
                &[0.0127],
                &[0.19],
                &thesis_contact_terms(),
                Medium::default(),
                ApplyAt::Tip,
                SignModel::Raw,
            )
            .unwrap();
            let mut out = [0.0; 16];
            geoms.evaluate(0, &[0.0, -0.05, 0.0, 1.0, 0.0, -1.0, 0.0], &mut out);
            // By hand: F_sv = eta_v (d/L)^lam g rho V up, F_d = eta_d rho A_r |v| v with
            // A_r = 0 for axial motion; no moment about the tip.
            let v = std::f64::consts::FRAC_PI_4 * 0.0127f64.powi(2) * 0.05;
            let by_hand = 248.0 * (0.05f64 / 0.19).powf(0.106) * 9.81 * 1650.0 * v;
            assert!((out[1] - by_hand).abs() < 1e-12 * by_hand, "{out:?}");
            assert_eq!(out[0], 0.0);
            assert_eq!(out[2], 0.0);
            assert_eq!(out[4], 0.05);
        }

        #[test]
        fn the_centroid_carries_the_moment_and_a_body_term_is_refused() {
            let geoms = RodGeoms::new(
                &["foot".into()],
                &[0.0127],
                &[0.19],
                &thesis_contact_terms(),
                Medium::default(),
                ApplyAt::Centroid,
                SignModel::Raw,
            )
            .unwrap();
            let mut out = [0.0; 16];
            let q = 0.5f64;
            geoms.evaluate(0, &[0.0, -0.02, q.sin(), q.cos(), 1.0, -1.0, 0.0], &mut out);
            // Moment about the tip of F at E = T + (l/2) e: r x F with r = (l/2) e.
            let r = Vector2::new(out[5], out[6] + 0.02);
            let by_hand = r.y * out[0] - r.x * out[1];
            assert!((out[2] - by_hand).abs() < 1e-12 * by_hand.abs(), "{out:?}");
            let mut with_gravity = thesis_contact_terms();
            with_gravity.names.push("gravity");
            let err = RodGeoms::new(
                &["foot".into()],
                &[0.0127],
                &[0.19],
                &with_gravity,
                Medium::default(),
                ApplyAt::Tip,
                SignModel::Raw,
            )
            .unwrap_err();
            assert!(err.to_string().contains("forces.gravity"), "{err}");
        }
    }
}
