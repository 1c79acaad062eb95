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

use crate::dynamics::rod_lanes::{rod_eval_terms, RodBody, RodModes, RodTerms};
use crate::forces::drag::Drag;
use crate::forces::static_h::StaticH;
use crate::forces::static_v::StaticV;
use crate::forces::{AnyTerm, ForceSet, Medium};

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
/// order of [`OUTPUTS`]. The state is the free link's with its root at the tip (unit mass
/// and inertia, no gravity), evaluated by the free link's own kernel
/// ([`rod_eval_terms`]: the same geometry, signs and terms as a run's), with this state's
/// coefficients; in contact where the tip is below the surface.
pub fn evaluate(setup: &RodSetup, input: [f64; 9], out: &mut [f64]) {
    let [depth, q_deg, vx, vy, omega, eta_h, eta_d, eta_v, lam] = input;
    let q = q_deg.to_radians();
    let depth = depth.max(0.0);
    let mut terms = setup.forces.per_contact[0];
    for t in terms.iter_mut() {
        *t = match *t {
            AnyTerm::Drag(_) => AnyTerm::Drag(Drag { eta_d }),
            AnyTerm::StaticH(_) => AnyTerm::StaticH(StaticH { eta_h }),
            AnyTerm::StaticV(_) => AnyTerm::StaticV(StaticV { eta_v, lam }),
            other => other,
        };
    }
    let (smooth, eps) = match setup.sign {
        Sign::Raw => (0.0, 1.0),
        Sign::Smooth(eps) => (1.0, eps),
    };
    let body = RodBody {
        mass: 1.0,
        g: 0.0,
        inv_m: 1.0,
        inv_i: 1.0,
        tip: [0.0; 2],
        length: setup.length,
        diameter: setup.diameter,
        section: std::f64::consts::FRAC_PI_4 * setup.diameter * setup.diameter,
        at_centroid: 0.0,
        medium: setup.medium,
        unheld: 1.0,
        smooth,
        eps,
    };
    let mut numbers = [0.0; 4];
    let law = RodTerms::of_terms(&setup.forces, &terms, &mut numbers);
    // The signs are each evaluation's own: nothing is held, nothing sticks.
    let modes = RodModes {
        in_contact: if depth > 0.0 { 1.0 } else { 0.0 },
        sign: [0.0; 2],
        cross: 1.0,
        stuck_x: 0.0,
        stuck_y: 0.0,
    };
    let e = rod_eval_terms(&body, &law, &modes, &[0.0, -depth, q], &[vx, vy, omega]);
    let half = 0.5 * e.immersed;
    let [s, c] = e.axis;
    let (dynamic, statics) = (e.dynamic, e.statics);
    let values = [
        dynamic[0] + statics[0],
        dynamic[1] + statics[1],
        dynamic[0],
        dynamic[1],
        statics[0],
        statics[1],
        e.immersed,
        half * s,
        half * c,
        Vector2::new(e.v_centroid[0], e.v_centroid[1]).norm(),
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
    use crate::body::{Joint, Link, Mechanism, RodContact, SoleContact, SoleModel};
    use crate::dynamics::{
        Contact, ContactMode, DragStiffness, Model, Shape, SignModel, MAX_CONTACTS,
    };
    use crate::error::{check_finite, check_range, GranrsError, Result};
    use crate::forces::{ForceSet, Medium};

    /// The state of one geom, in this order: its reference point R [m] (a rod's tip T, the
    /// lower end of its axis; a sole box's centre), its unit axis e (a rod's, from the tip
    /// along the rod; a box's x axis, from heel to toe), R's velocity [m/s] and the angular
    /// velocity [rad/s] (x right, y up; omega turns e towards +x, dq/dt of the free link).
    pub const STATE: [&str; 7] = ["ref_x", "ref_y", "e_x", "e_y", "v_x", "v_y", "omega"];

    /// What [`SandGeoms::evaluate`] writes per geom, in this order: the force (x, y) [N] and
    /// its moment about the reference point R [N m] (positive turning e towards +x), the
    /// depth of the force law [m] (a rod's tip depth; a box's immersed area / length) and a
    /// rod's immersed length [m] (0 for a box), the immersed centroid E [m], the point of
    /// application P [m], E's velocity [m/s], the dynamic and static sums [N], the static
    /// terms' bounds along x and y [N] (the largest reaction they supply while sticking) and
    /// the drag's stiffness |F_d| / |v_E| [kg/s].
    pub const OUTPUTS: [&str; 18] = [
        "F_x", "F_y", "M", "depth", "l", "E_x", "E_y", "P_x", "P_y", "v_Ex", "v_Ey", "F_dx",
        "F_dy", "F_sx", "F_sy", "bound_x", "bound_y", "k_drag",
    ];

    /// The shape of one geom.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub enum GeomShape {
        /// The free link's rod (a capsule, a cylinder): diameter d_c and length L [m] (also
        /// L_ref); R is its tip.
        Rod {
            /// d_c [m].
            diameter: f64,
            /// L [m].
            length: f64,
        },
        /// The leg's sole box (`SoleModel::Box`) centred on R: its `length` f_s along e
        /// (also the width of `static_h`), `height` across it in the plane, `width` w_s out
        /// of the plane, and L_ref of the depth factor [m].
        Sole {
            /// f_s [m].
            length: f64,
            /// Height in the plane [m].
            height: f64,
            /// w_s [m].
            width: f64,
            /// L_ref [m].
            l_ref: f64,
        },
    }

    /// N geoms, each the free link's rod or the leg's sole box with its own terms, in the
    /// same sand.
    #[derive(Debug, Clone)]
    pub struct SandGeoms {
        models: Vec<Model<3>>,
    }

    impl SandGeoms {
        /// Geoms named `names` of `shapes`, under `forces` (built for `names.len()`
        /// contacts: a parameter is one value for every geom or one per geom). Contact terms
        /// only: a body term (`gravity`, `joint_springs`) acts through the other engine, and
        /// is an error naming it.
        pub fn new(
            names: &[String],
            shapes: &[GeomShape],
            forces: &ForceSet,
            medium: Medium,
            apply_at: ApplyAt,
            sign_model: SignModel,
        ) -> Result<SandGeoms> {
            if shapes.len() != names.len() || forces.per_contact.len() != names.len() {
                return Err(GranrsError::InvalidScene {
                    field: "geoms".into(),
                    message: "one shape and one set of terms per geom".into(),
                });
            }
            if let Some(t) = forces.body.first() {
                let body = t.info().name;
                return Err(GranrsError::InvalidScene {
                    field: format!("forces.{body}"),
                    message: format!(
                        "`{body}` acts through the engine's own model (its gravity, its \
                         joints); list only the medium's contact terms"
                    ),
                });
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
            for (i, name) in names.iter().enumerate() {
                let shape = match shapes[i] {
                    GeomShape::Rod { diameter, length } => {
                        check_range(&format!("{name}.diameter"), diameter, 0.0, true)?;
                        check_range(&format!("{name}.length"), length, 0.0, true)?;
                        Shape::Rod(RodContact {
                            link: 0,
                            tip: Vector2::zeros(),
                            length,
                            diameter,
                        })
                    }
                    GeomShape::Sole {
                        length,
                        height,
                        width,
                        l_ref,
                    } => {
                        check_range(&format!("{name}.length"), length, 0.0, true)?;
                        check_range(&format!("{name}.height"), height, 0.0, true)?;
                        check_range(&format!("{name}.width"), width, 0.0, true)?;
                        check_range(&format!("{name}.l_ref"), l_ref, 0.0, true)?;
                        // Centred on the root: the sole (the face towards +n) from heel to
                        // toe along e, the box rising towards -n.
                        Shape::Sole(SoleContact {
                            link: 0,
                            angle_link: 0,
                            heel: Vector2::new(-0.5 * length, 0.5 * height),
                            length,
                            height,
                            width,
                            l_ref,
                            model: SoleModel::Box,
                        })
                    }
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
                        root_fixed: false,
                        root_rate: None,
                    },
                    contacts: vec![Contact { shape }],
                    medium,
                    apply_at,
                    sign_model,
                    forces: own,
                });
            }
            Ok(SandGeoms { models })
        }

        /// Number of geoms.
        pub fn len(&self) -> usize {
            self.models.len()
        }

        /// Whether there are none.
        pub fn is_empty(&self) -> bool {
            self.models.is_empty()
        }

        /// Whether a term resists the geoms' turning about any point of their own: `rft`,
        /// whose elements spread over the boundary (the thesis's terms and `poncelet` act at
        /// one point, and give no moment about it).
        pub fn resist_turning(&self) -> bool {
            self.models.iter().any(|m| m.forces.names.contains(&"rft"))
        }

        /// Geom `i`'s length [m]: a rod's L, a sole box's f_s.
        pub fn length(&self, i: usize) -> f64 {
            match &self.models[i].contacts[0].shape {
                Shape::Rod(rod) => rod.length,
                Shape::Sole(sole) => sole.length,
                Shape::Arc(arc) => arc.radius * arc.span.abs(),
            }
        }

        /// Whether geom `i` is a sole box (else a rod).
        pub fn is_sole(&self, i: usize) -> bool {
            matches!(self.models[i].contacts[0].shape, Shape::Sole(_))
        }

        /// Check geom `i`'s state (finite, unit axis to 1e-6; a rod's axis pointing up
        /// from its tip), naming the geom and field.
        pub fn check_state(&self, i: usize, name: &str, state: &[f64; 7]) -> Result<()> {
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
            if state[3] < 0.0 && !self.is_sole(i) {
                return Err(GranrsError::InvalidParameter {
                    field: format!("{name}.e_y"),
                    value: state[3],
                    allowed: ">= 0: a rod's tip is the lower end of its axis".into(),
                });
            }
            Ok(())
        }

        /// Evaluate geom `i` at `state` (in the order of [`STATE`]) into `out` (in the
        /// order of [`OUTPUTS`]), through the free link's right-hand side (the general
        /// one for a sole box).
        pub fn evaluate(&self, i: usize, state: &[f64; 7], out: &mut [f64]) {
            let model = &self.models[i];
            let [ref_x, ref_y, e_x, e_y, v_x, v_y, omega] = *state;
            let q = SVector::<f64, 3>::new(ref_x, ref_y, e_x.atan2(e_y));
            let qd = SVector::<f64, 3>::new(v_x, v_y, omega);
            let mut modes = [ContactMode::default(); MAX_CONTACTS];
            modes[0].in_contact = true;
            let e = model.eval(&q, &qd, &modes);
            let c = &e.contacts[0];
            let axis = Vector2::new(e_x, e_y);
            let root = Vector2::new(ref_x, ref_y);
            let (l, centroid, reference) = match &model.contacts[0].shape {
                Shape::Rod(rod) => {
                    let l = if c.depth > 0.0 {
                        rod.geometry(ref_y, axis).immersed_length
                    } else {
                        0.0
                    };
                    (l, root + (0.5 * l) * axis, root)
                }
                Shape::Sole(sole) => {
                    let normal = Vector2::new(axis.y, -axis.x);
                    let t = sole.reference_point();
                    let centroid = sole.geometry(root, axis, normal).centroid;
                    (0.0, centroid, root + t.x * axis + t.y * normal)
                }
                Shape::Arc(arc) => {
                    let normal = Vector2::new(axis.y, -axis.x);
                    let t = arc.reference_point();
                    let g = arc.geometry(root, axis, normal);
                    (
                        g.immersed_length,
                        g.centroid,
                        root + t.x * axis + t.y * normal,
                    )
                }
            };
            let apply = match model.apply_at {
                ApplyAt::Tip => reference,
                ApplyAt::Centroid => centroid,
            };
            let k_drag = DragStiffness::of(0, c).k2().sqrt();
            let values = [
                e.qdd[0],
                e.qdd[1],
                e.qdd[2],
                c.depth,
                l,
                centroid.x,
                centroid.y,
                apply.x,
                apply.y,
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

    /// A geom's place in the other engine's model (MuJoCo's indices), fixed at setup.
    #[derive(Debug, Clone, PartialEq)]
    pub struct EnginePlace {
        /// The geom's index (rows of `geom_xpos`, `geom_xmat`).
        pub geom: usize,
        /// Its body (rows of `cvel`).
        pub body: usize,
        /// The root of its body's tree (rows of `subtree_com`: `cvel` is taken about it).
        pub root: usize,
        /// From the geom's centre to its reference point along its axis [m] (a rod's tip; 0
        /// for a box).
        pub reach: f64,
        /// The degrees of freedom that move it (the joints of its body and its ancestors).
        pub dofs: Vec<usize>,
    }

    /// One evaluation's arrays of the other engine, row-major (MuJoCo's `mjData` fields, in
    /// world coordinates; 3-d, with z up: the plane is x-z).
    #[derive(Debug, Clone, Copy)]
    pub struct EngineState<'a> {
        /// `geom_xpos` (ngeom x 3).
        pub geom_xpos: &'a [f64],
        /// `geom_xmat` (ngeom x 9).
        pub geom_xmat: &'a [f64],
        /// `cvel` (nbody x 6: angular, linear velocity at the tree's `subtree_com`).
        pub cvel: &'a [f64],
        /// `subtree_com` (nbody x 3).
        pub subtree_com: &'a [f64],
        /// `cdof` (nv x 6: each dof's motion, angular then linear, about the same point).
        pub cdof: &'a [f64],
        /// The mass matrix, dense (nv x nv).
        pub mass: &'a [f64],
        /// `qvel` (nv).
        pub qvel: &'a [f64],
        /// `qacc` of the last evaluation (nv): the acceleration the static terms' reactions
        /// take as the rest of the world's.
        pub qacc: &'a [f64],
    }

    /// Where one step's results go: per geom the outputs ([`OUTPUTS`]), the applied force
    /// and moment (x, z, about y), `h lambda`; and the generalized force (nv).
    #[derive(Debug)]
    pub struct EngineOut<'a> {
        /// n x [`OUTPUTS`].
        pub outputs: &'a mut [f64],
        /// n x 3: force x, force z [N] at the tip, moment about +y [N m].
        pub applied: &'a mut [f64],
        /// n: the timestep times the drag's rate.
        pub h_lambda: &'a mut [f64],
        /// nv: the generalized force of every geom's force.
        pub generalized: &'a mut [f64],
    }

    /// Most geoms one [`Coupling`] takes.
    pub const MAX_COUPLED: usize = 16;

    /// A [`Coupling`]'s buffers, sized once (an evaluation allocates next to nothing).
    #[derive(Debug, Clone, Default)]
    pub struct Work {
        j_tip: Vec<f64>,
        j_e: Vec<f64>,
        j_p: Vec<f64>,
        j_rot: Vec<f64>,
        chol_m: Vec<f64>,
        chol_h: Vec<f64>,
        w: Vec<f64>,
        tmp: Vec<f64>,
        tmp2: Vec<f64>,
        q_rest: Vec<f64>,
        raw: Vec<[f64; 2]>,
        levers: Vec<[f64; 2]>,
    }

    impl Work {
        /// Buffers for `n` geoms and `nv` dofs.
        pub fn new(n: usize, nv: usize) -> Work {
            Work {
                j_tip: vec![0.0; 2 * n * nv],
                j_e: vec![0.0; 2 * n * nv],
                j_p: vec![0.0; 2 * n * nv],
                j_rot: vec![0.0; n * nv],
                chol_m: vec![0.0; nv * nv],
                chol_h: vec![0.0; nv * nv],
                w: vec![0.0; 4 * n * n],
                tmp: vec![0.0; nv],
                tmp2: vec![0.0; nv],
                q_rest: vec![0.0; nv],
                raw: vec![[0.0; 2]; n],
                levers: vec![[0.0; 2]; n],
            }
        }
    }

    /// The coupling to another engine: [`SandGeoms`] placed on its bodies, with the sand's
    /// surface and patch, and the static terms' treatment.
    #[derive(Debug, Clone)]
    pub struct Coupling {
        /// The geoms' force law.
        pub rods: SandGeoms,
        /// Each geom's place.
        pub places: Vec<EnginePlace>,
        /// Number of degrees of freedom.
        pub nv: usize,
        /// Height of the sand's surface [m].
        pub surface: f64,
        /// The sand's extent in x [m].
        pub patch: (f64, f64),
        /// Whether the static terms act as reactions that bring E's velocity to zero within
        /// their bounds (`true`), or as evaluated.
        pub stick: bool,
        /// The last generalized force (nv), whose effect the last `qacc` holds.
        pub previous: Vec<f64>,
        /// The joints' damping that the engine's step takes implicitly, per dof [N s/m or
        /// N m s/rad] (MuJoCo's Euler, implicit and implicitfast: the velocity update is
        /// `(M + h B)^-1` times the force; zero for RK4).
        pub implicit_damping: Vec<f64>,
        /// Buffers ([`Work::new`] for the geoms and dofs).
        pub work: Work,
        /// Each geom's reactions as last solved (x, y) [N] and whether each was at its
        /// bound (sliding); `None` out of the sand.
        pub held: Vec<Option<([f64; 2], [bool; 2])>>,
        /// Under a term that resists turning ([`SandGeoms::resist_turning`]), with `stick`:
        /// each geom's whole wrench at R as last solved (force x, y [N], moment [N m]).
        pub held_wrench: Vec<Option<[f64; 3]>>,
        /// With `stick`: the speed [m/s] at which a geom held by the sand creeps under the
        /// sand's whole resistance (a term that resists turning: the law's wrench at the
        /// motion without the sand; else the size of the static terms' bounds; a geom
        /// carrying a load creeps at this speed times the load over that resistance), so
        /// that the reaction opposes the motion it leaves and the sand does no positive work.
        pub rest_speed: f64,
    }

    /// The x and z rows of the Jacobian of world point `p` on the tree of `place` into
    /// `rows` (2 x nv, zeroed), and the y row of its rotation into `rot`, from MuJoCo's
    /// `cdof` (as `mj_jac` builds them).
    fn jacobian(
        place: &EnginePlace,
        s: &EngineState,
        nv: usize,
        p: [f64; 3],
        rows: &mut [f64],
        mut rot: Option<&mut [f64]>,
    ) {
        let c = &s.subtree_com[3 * place.root..3 * place.root + 3];
        let o = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        for &j in &place.dofs {
            let d = &s.cdof[6 * j..6 * j + 6];
            rows[j] = d[3] + d[1] * o[2] - d[2] * o[1];
            rows[nv + j] = d[5] + d[0] * o[1] - d[1] * o[0];
            if let Some(r) = rot.as_deref_mut() {
                r[j] = d[1];
            }
        }
    }

    impl Coupling {
        /// One evaluation: every geom's state from the engine's arrays, its force through
        /// [`SandGeoms::evaluate`], the static terms' reactions (with `stick`), and the
        /// generalized force of it all. `timestep` [s] sets the reactions and `h lambda`;
        /// `hold` (a later stage of a multi-stage step, RK4's) keeps the reactions of the
        /// last evaluation that solved them, where every geom in the sand has one, so that
        /// they act through the whole step as they were solved for.
        pub fn step(&mut self, s: &EngineState, timestep: f64, hold: bool, out: EngineOut) {
            let nv = self.nv;
            let width = OUTPUTS.len();
            let mut tips = [[0.0; 3]; MAX_COUPLED];
            let mut states = [[0.0; 7]; MAX_COUPLED];
            let mut active_buf = [0usize; MAX_COUPLED];
            let mut n_active = 0;
            out.applied.fill(0.0);
            out.h_lambda.fill(0.0);
            out.generalized.fill(0.0);
            for (i, place) in self.places.iter().enumerate() {
                let m = &s.geom_xmat[9 * place.geom..9 * place.geom + 9];
                // A rod's axis is its local z, pointing up from its tip; a box's its local x.
                let mut e = if self.rods.is_sole(i) {
                    [m[0], m[3], m[6]]
                } else {
                    [m[2], m[5], m[8]]
                };
                if e[2] < 0.0 && !self.rods.is_sole(i) {
                    e = [-e[0], -e[1], -e[2]];
                }
                let x = &s.geom_xpos[3 * place.geom..3 * place.geom + 3];
                let tip = [
                    x[0] - place.reach * e[0],
                    x[1] - place.reach * e[1],
                    x[2] - place.reach * e[2],
                ];
                let v = &s.cvel[6 * place.body..6 * place.body + 6];
                let c = &s.subtree_com[3 * place.root..3 * place.root + 3];
                let r = [tip[0] - c[0], tip[1] - c[1], tip[2] - c[2]];
                let norm = e[0].hypot(e[2]);
                let state = [
                    tip[0],
                    tip[2] - self.surface,
                    e[0] / norm,
                    e[2] / norm,
                    v[3] + v[1] * r[2] - v[2] * r[1],
                    v[5] + v[0] * r[1] - v[1] * r[0],
                    v[1],
                ];
                let row = &mut out.outputs[i * width..(i + 1) * width];
                self.rods.evaluate(i, &state, row);
                tips[i] = tip;
                states[i] = state;
                if row[3] > 0.0 && tip[0] >= self.patch.0 && tip[0] <= self.patch.1 {
                    active_buf[n_active] = i;
                    n_active += 1;
                }
            }
            let active = &active_buf[..n_active];
            if active.is_empty() {
                // Nothing in the sand: no reaction is held into a later stage where a geom
                // enters it (that stage solves its own).
                self.previous.fill(0.0);
                self.held.fill(None);
                self.held_wrench.fill(None);
                return;
            }
            let k = active.len();
            let (c_fx, c_fy, c_m, c_ex, c_ey, c_px, c_py) = (0, 1, 2, 5, 6, 7, 8);
            let (c_vx, c_vy, c_sx, c_sy, c_bx, c_by, c_k) = (9, 10, 13, 14, 15, 16, 17);
            debug_assert_eq!(OUTPUTS[c_px], "P_x");
            debug_assert_eq!(OUTPUTS[c_sx], "F_sx");
            debug_assert_eq!(OUTPUTS[c_k], "k_drag");
            let w_ = &mut self.work;
            // Jacobians (rows of nv) of the reference point R (`j_tip`), of E and of the point
            // of application P (x and z per geom), and the rotation about y.
            w_.j_tip[..2 * k * nv].fill(0.0);
            w_.j_e[..2 * k * nv].fill(0.0);
            w_.j_p[..2 * k * nv].fill(0.0);
            w_.j_rot[..k * nv].fill(0.0);
            w_.q_rest.fill(0.0);
            for (a, &i) in active.iter().enumerate() {
                let place = &self.places[i];
                let row = &out.outputs[i * width..(i + 1) * width];
                let centroid = [row[c_ex], 0.0, row[c_ey] + self.surface];
                let (tip_rows, rot) = (
                    &mut w_.j_tip[2 * a * nv..(2 * a + 2) * nv],
                    &mut w_.j_rot[a * nv..(a + 1) * nv],
                );
                jacobian(place, s, nv, tips[i], tip_rows, Some(rot));
                jacobian(
                    place,
                    s,
                    nv,
                    centroid,
                    &mut w_.j_e[2 * a * nv..(2 * a + 2) * nv],
                    None,
                );
                let apply = [row[c_px], 0.0, row[c_py] + self.surface];
                jacobian(
                    place,
                    s,
                    nv,
                    apply,
                    &mut w_.j_p[2 * a * nv..(2 * a + 2) * nv],
                    None,
                );
                w_.raw[a] = [row[c_sx], row[c_sy]];
                w_.levers[a] = [apply[0] - tips[i][0], apply[2] - tips[i][2]];
                // Everything but the static terms: the force less the static sum, with its
                // moment about the tip less that of the static sum at P.
                let [lx, lz] = w_.levers[a];
                let raw = w_.raw[a];
                let f = [row[c_fx] - raw[0], row[c_fy] - raw[1]];
                let moment = row[c_m] - (lz * raw[0] - lx * raw[1]);
                for j in 0..nv {
                    w_.q_rest[j] += f[0] * w_.j_tip[2 * a * nv + j]
                        + f[1] * w_.j_tip[(2 * a + 1) * nv + j]
                        + moment * w_.j_rot[a * nv + j];
                }
            }
            // M and the matrix of the engine's velocity update, M + h B, factored.
            w_.chol_m.copy_from_slice(s.mass);
            w_.chol_h.copy_from_slice(s.mass);
            for (j, b) in self.implicit_damping.iter().enumerate() {
                w_.chol_h[j * nv + j] += timestep * b;
            }
            if !(cholesky(&mut w_.chol_m, nv) && cholesky(&mut w_.chol_h, nv)) {
                // Not positive definite (a degenerate state): the forces as evaluated.
                for (a, &i) in active.iter().enumerate() {
                    finish(
                        i,
                        &w_.raw[a],
                        &w_.raw[a],
                        &w_.levers[a],
                        out.outputs,
                        out.applied,
                    );
                }
                self.generalized(active, out.applied, out.generalized);
                return;
            }
            let rows = 2 * k;
            let j_p = &w_.j_p;
            // W = J_E H^-1 J_P^T: E's response to a unit force at P over the engine's step.
            for c in 0..rows {
                w_.tmp.copy_from_slice(&j_p[c * nv..(c + 1) * nv]);
                chol_solve(&w_.chol_h, nv, &mut w_.tmp);
                for r in 0..rows {
                    w_.w[r * rows + c] = dot(&w_.j_e[r * nv..(r + 1) * nv], &w_.tmp);
                }
            }
            // The drag's rate: 2 |F_d| / |v_E| times E's inverse effective mass along v_E.
            for (a, &i) in active.iter().enumerate() {
                let row = &out.outputs[i * width..(i + 1) * width];
                let speed = row[c_vx].hypot(row[c_vy]);
                if speed > 0.0 && row[c_k] > 0.0 {
                    let u = [row[c_vx] / speed, row[c_vy] / speed];
                    for j in 0..nv {
                        let ju =
                            u[0] * w_.j_e[2 * a * nv + j] + u[1] * w_.j_e[(2 * a + 1) * nv + j];
                        w_.tmp[j] = ju;
                        w_.tmp2[j] = ju;
                    }
                    chol_solve(&w_.chol_m, nv, &mut w_.tmp);
                    let inv_mass = dot(&w_.tmp2, &w_.tmp);
                    out.h_lambda[i] = timestep * 2.0 * row[c_k] * inv_mass;
                }
            }
            if self.stick && self.rods.resist_turning() {
                self.stick_wrenches(s, timestep, hold, active, &states, out);
                return;
            }
            let mut reaction = [0.0; 2 * MAX_COUPLED];
            let mut bounds = [0.0; 2 * MAX_COUPLED];
            let mut soft = [false; 2 * MAX_COUPLED];
            for (a, &i) in active.iter().enumerate() {
                let row = &out.outputs[i * width..(i + 1) * width];
                reaction[2 * a..2 * a + 2].copy_from_slice(&w_.raw[a]);
                // The static (rate-independent) terms' reaction is bounded by the bounds
                // they report (the thesis's terms: always; rft: only under the solver's held
                // modes, so not here). Where they report none but push, their force's size
                // along the axis bounds it (rft's force turns with the velocity), and a row
                // past that bound keeps the force as evaluated (`soft`): rft's components
                // need not oppose the motion axis by axis.
                for (k, (c_b, c_s)) in [(c_bx, c_sx), (c_by, c_sy)].into_iter().enumerate() {
                    soft[2 * a + k] = row[c_b] <= 0.0 && row[c_s] != 0.0;
                    bounds[2 * a + k] = row[c_b].max(row[c_s].abs());
                }
            }
            let held = hold && active.iter().all(|&i| self.held[i].is_some());
            if self.stick && held {
                // A later stage of the engine's step: the reactions of its first stage.
                // A sliding row (at its bound) takes this stage's bound, with its sign.
                for (a, &i) in active.iter().enumerate() {
                    let (r, sliding) = self.held[i].expect("held");
                    for axis in 0..2 {
                        let b = bounds[2 * a + axis];
                        // A soft row: sliding, the force as this stage evaluates it;
                        // sticking, the reaction as solved (its bound is the first stage's).
                        if soft[2 * a + axis] {
                            if !sliding[axis] {
                                reaction[2 * a + axis] = r[axis];
                            }
                        } else if b > 0.0 {
                            reaction[2 * a + axis] = if sliding[axis] {
                                b.copysign(r[axis])
                            } else {
                                r[axis].clamp(-b, b)
                            };
                        }
                    }
                }
            } else if self.stick && bounds[..rows].iter().any(|&b| b > 0.0) {
                // E's velocity at the step's end without reactions: v + h (M + h B)^-1 f, with
                // the rest of the world's force f from the last qacc (M qacc) less our last
                // force, plus this step's non-static force.
                for r in 0..nv {
                    w_.tmp[r] = dot(&s.mass[r * nv..(r + 1) * nv], s.qacc) - self.previous[r]
                        + w_.q_rest[r];
                }
                chol_solve(&w_.chol_h, nv, &mut w_.tmp);
                let b = nalgebra::DVector::from_fn(rows, |r, _| {
                    let je = &w_.j_e[r * nv..(r + 1) * nv];
                    dot(je, s.qvel) / timestep + dot(je, &w_.tmp)
                });
                // The sand at rest as a stiff viscous law ([`creep`]; each geom's
                // resistance the size of its bounds): E at the step's end creeps at `-C r`.
                // E slides along a tilting body (a rod lying nearly flat: its immersed
                // length is the depth over the tilt), so the point a step holds still is
                // not the next one's: a reaction that held E still exactly did positive
                // work, 1.1e-6 to 1.2e-5 J/s on a hopper's capsule foot.
                let mut hw =
                    timestep * nalgebra::DMatrix::from_row_slice(rows, rows, &w_.w[..rows * rows]);
                let resistance = nalgebra::DVector::from_column_slice(&bounds[..rows]);
                creep(&mut hw, &resistance, 2, 2, self.rest_speed, |_| 1.0);
                solve_boxed(
                    &hw,
                    &(timestep * b),
                    &bounds[..rows],
                    &soft[..rows],
                    &mut reaction[..rows],
                );
            }
            if !held {
                self.held.fill(None);
                for (a, &i) in active.iter().enumerate() {
                    let r = [reaction[2 * a], reaction[2 * a + 1]];
                    let at = |k: usize| {
                        let (b, raw) = (bounds[2 * a + k], w_.raw[a][k]);
                        r[k].abs() >= b * (1.0 - 1e-12) || (soft[2 * a + k] && r[k] == raw)
                    };
                    self.held[i] = Some((r, [at(0), at(1)]));
                }
            }
            for (a, &i) in active.iter().enumerate() {
                let r = [reaction[2 * a], reaction[2 * a + 1]];
                finish(i, &w_.raw[a], &r, &w_.levers[a], out.outputs, out.applied);
            }
            self.generalized(active, out.applied, out.generalized);
        }

        /// The static reactions of a term that resists turning (`rft`), solved as the
        /// implicit coupling in space does ([`stick_or_slide`]): each geom's whole wrench
        /// at R (force x, z and moment about y) that brings R's velocity and the rotation
        /// to zero at the end of the engine's step, where its force is no larger than the
        /// sand's resistance to the motion without it (the law's wrench at that motion),
        /// else the law's wrench at that motion (sliding). RFT's force does not shrink as
        /// the contact slows, so its reactions along x and y alone left the rotation free:
        /// a foot standing on one geom turned and chattered. The Jacobians and the factor
        /// of `M + h B` are this evaluation's ([`Coupling::step`]); `states` the geoms'.
        fn stick_wrenches(
            &mut self,
            s: &EngineState,
            timestep: f64,
            hold: bool,
            active: &[usize],
            states: &[[f64; 7]; MAX_COUPLED],
            out: EngineOut,
        ) {
            use nalgebra::{DMatrix, DVector};
            let (nv, k) = (self.nv, active.len());
            let rows = 3 * k;
            let w_ = &mut self.work;
            // R's x and z and the rotation about y, per geom.
            let j = DMatrix::from_fn(rows, nv, |r, c| {
                let a = r / 3;
                match r % 3 {
                    2 => w_.j_rot[a * nv + c],
                    axis => w_.j_tip[(2 * a + axis) * nv + c],
                }
            });
            let held = hold && active.iter().all(|&i| self.held_wrench[i].is_some());
            let mut w = DVector::zeros(rows);
            if held {
                for (a, &i) in active.iter().enumerate() {
                    let h = self.held_wrench[i].expect("held");
                    w.rows_mut(3 * a, 3).copy_from_slice(&h);
                }
            } else {
                // The twists without the sand: the rest of the world's force (the last
                // M qacc less the sand's last force) over the engine's step.
                for r in 0..nv {
                    w_.tmp[r] = dot(&s.mass[r * nv..(r + 1) * nv], s.qacc) - self.previous[r];
                }
                chol_solve(&w_.chol_h, nv, &mut w_.tmp);
                let qvel = DVector::from_column_slice(s.qvel);
                let free = &j * (qvel + timestep * DVector::from_column_slice(&w_.tmp));
                // Their response to a unit wrench over the step: J H^-1 J^T.
                let mut resp = DMatrix::zeros(rows, rows);
                for c in 0..rows {
                    for (d, x) in w_.tmp.iter_mut().enumerate() {
                        *x = j[(c, d)];
                    }
                    chol_solve(&w_.chol_h, nv, &mut w_.tmp);
                    for r in 0..rows {
                        resp[(r, c)] = (0..nv).map(|d| j[(r, d)] * w_.tmp[d]).sum::<f64>();
                    }
                }
                // The law's wrench at those twists (the step's start's pose).
                let mut full = DVector::zeros(rows);
                let mut row = [0.0; OUTPUTS.len()];
                for (a, &i) in active.iter().enumerate() {
                    let mut state = states[i];
                    state[4..7].copy_from_slice(&free.as_slice()[3 * a..3 * a + 3]);
                    self.rods.evaluate(i, &state, &mut row);
                    full.rows_mut(3 * a, 3).copy_from_slice(&row[..3]);
                }
                // The sand at rest as a stiff viscous law ([`creep`]).
                let mut ha = timestep * resp;
                creep(&mut ha, &full, 3, 2, self.rest_speed, |a| {
                    self.rods.length(active[a])
                });
                (w, _) = stick_or_slide(&ha, &free, &full, k, 3, 2, Slide::AsEvaluated);
                self.held_wrench.fill(None);
                for (a, &i) in active.iter().enumerate() {
                    self.held_wrench[i] = Some([w[3 * a], w[3 * a + 1], w[3 * a + 2]]);
                }
            }
            for (a, &i) in active.iter().enumerate() {
                out.applied[3 * i..3 * i + 3].copy_from_slice(&w.as_slice()[3 * a..3 * a + 3]);
            }
            self.generalized(active, out.applied, out.generalized);
        }

        /// The generalized force of the applied forces and moments (at the tip, through the
        /// Jacobians of the last evaluation), kept as `previous`.
        fn generalized(&mut self, active: &[usize], applied: &[f64], generalized: &mut [f64]) {
            let nv = self.nv;
            let w_ = &self.work;
            for (a, &i) in active.iter().enumerate() {
                let [fx, fz, m] = [applied[3 * i], applied[3 * i + 1], applied[3 * i + 2]];
                for (j, g) in generalized.iter_mut().enumerate() {
                    *g += fx * w_.j_tip[2 * a * nv + j]
                        + fz * w_.j_tip[(2 * a + 1) * nv + j]
                        + m * w_.j_rot[a * nv + j];
                }
            }
            self.previous.copy_from_slice(generalized);
        }
    }

    /// Geom `i`'s applied force and moment (its static sum `raw` replaced by `r` at P).
    fn finish(
        i: usize,
        raw: &[f64; 2],
        r: &[f64; 2],
        lever: &[f64; 2],
        outputs: &[f64],
        applied: &mut [f64],
    ) {
        let width = OUTPUTS.len();
        let row = &outputs[i * width..(i + 1) * width];
        let d = [r[0] - raw[0], r[1] - raw[1]];
        applied[3 * i] = row[0] + d[0];
        applied[3 * i + 1] = row[1] + d[1];
        applied[3 * i + 2] = row[2] + lever[1] * d[0] - lever[0] * d[1];
    }

    /// The sand at rest as a stiff viscous law, added to `ha` (the twists' response to the
    /// wrenches over the step, `block` rows per geom, its first `force` the force) before
    /// [`stick_or_slide`]: each geom's twist at the step's end is then its creep `-C w` (C:
    /// `rest_speed` over the geom's resistance, the size of its force in `full`; the
    /// rotation's over the resistance times `length(a)` squared), so that the reaction's
    /// power at that twist, `-w C w`, is never positive, and a geom carrying a load creeps
    /// at about `rest_speed` times the load over its resistance. A stick that brought the
    /// twist to zero exactly did positive work whenever the rest of the world's force moved
    /// between the steps (the reaction is solved against the last step's).
    pub fn creep(
        ha: &mut nalgebra::DMatrix<f64>,
        full: &nalgebra::DVector<f64>,
        block: usize,
        force: usize,
        rest_speed: f64,
        length: impl Fn(usize) -> f64,
    ) {
        for a in 0..full.len() / block {
            let resistance = full.rows(block * a, force).norm();
            if resistance > 0.0 {
                let c = rest_speed / resistance;
                let l = length(a);
                for r in block * a..block * (a + 1) {
                    ha[(r, r)] += if r < block * a + force {
                        c
                    } else {
                        c / (l * l)
                    };
                }
            }
        }
    }

    /// What a sliding geom receives in [`stick_or_slide`]: the stick's wrench scaled down
    /// to the sand's resistance (in space), or the law's wrench at the motion (the plane).
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub enum Slide {
        /// The wrench that would stop it, scaled to the resistance's size.
        Scaled,
        /// The law's own wrench at the motion without the sand.
        AsEvaluated,
    }

    /// The wrenches (`block` values per geom, `k` geoms, its first `force` the force) that
    /// bring every twist `free + ha w` to zero (the least, where the twists have fewer
    /// freedoms than `block k`), with each geom's force at most the sand's resistance
    /// `full` to its motion (the law's wrench at the twist without the sand): geom by geom,
    /// the one furthest past its resistance is held there ([`Slide`]) and the others are
    /// solved again with it held (an active set), so that no geom is pushed past rest by
    /// another's. Returns the wrenches and whether some geom slid (was held at its
    /// resistance). Shared by the planar coupling (rft's reactions) and the coupling in space
    /// (the rest, or the fallback, of its implicit solve).
    pub fn stick_or_slide(
        ha: &nalgebra::DMatrix<f64>,
        free: &nalgebra::DVector<f64>,
        full: &nalgebra::DVector<f64>,
        k: usize,
        block: usize,
        force: usize,
        slide: Slide,
    ) -> (nalgebra::DVector<f64>, bool) {
        use nalgebra::{DMatrix, DVector};
        let rows = block * k;
        let mut w = DVector::zeros(rows);
        let mut held = vec![false; k];
        for _ in 0..k {
            let open: Vec<usize> = (0..rows).filter(|&p| !held[p / block]).collect();
            if open.is_empty() {
                break;
            }
            let sub = DMatrix::from_fn(open.len(), open.len(), |p, q| ha[(open[p], open[q])]);
            let rhs = DVector::from_fn(open.len(), |p, _| {
                let row = open[p];
                -free[row]
                    - (0..rows)
                        .filter(|&q| held[q / block])
                        .map(|q| ha[(row, q)] * w[q])
                        .sum::<f64>()
            });
            let tol = 1e-12 * sub.amax();
            let Ok(x) = sub.svd(true, true).solve(&rhs, tol) else {
                break;
            };
            for (p, &row) in open.iter().enumerate() {
                w[row] = x[p];
            }
            // The open geom furthest past the sand's resistance, if any.
            let mut worst: Option<(usize, f64)> = None;
            for a in (0..k).filter(|&a| !held[a]) {
                let want = w.rows(block * a, force).norm();
                let can = full.rows(block * a, force).norm();
                if want > can {
                    let past = if can > 0.0 { want / can } else { f64::INFINITY };
                    if worst.is_none_or(|(_, x)| past > x) {
                        worst = Some((a, past));
                    }
                }
            }
            match worst {
                None => return (w, held.contains(&true)),
                Some((a, _)) => {
                    match slide {
                        Slide::Scaled => {
                            let want = w.rows(block * a, force).norm();
                            let can = full.rows(block * a, force).norm();
                            w.rows_mut(block * a, block).scale_mut(can / want);
                        }
                        Slide::AsEvaluated => {
                            w.rows_mut(block * a, block)
                                .copy_from(&full.rows(block * a, block));
                        }
                    }
                    held[a] = true;
                }
            }
        }
        (w, held.contains(&true))
    }

    /// `a . b`.
    #[inline]
    fn dot(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }

    /// The Cholesky factor L of the symmetric `a` (n x n, row-major) in its lower triangle,
    /// in place; `false` where `a` is not positive definite.
    fn cholesky(a: &mut [f64], n: usize) -> bool {
        for j in 0..n {
            let mut d = a[j * n + j];
            for k in 0..j {
                d -= a[j * n + k] * a[j * n + k];
            }
            if d.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return false;
            }
            let d = d.sqrt();
            a[j * n + j] = d;
            for i in j + 1..n {
                let mut v = a[i * n + j];
                for k in 0..j {
                    v -= a[i * n + k] * a[j * n + k];
                }
                a[i * n + j] = v / d;
            }
        }
        true
    }

    /// Solve `L L^T x = b` in place (`x` holds b), L from [`cholesky`].
    fn chol_solve(l: &[f64], n: usize, x: &mut [f64]) {
        for i in 0..n {
            let mut v = x[i];
            for k in 0..i {
                v -= l[i * n + k] * x[k];
            }
            x[i] = v / l[i * n + i];
        }
        for i in (0..n).rev() {
            let mut v = x[i];
            for k in i + 1..n {
                v -= l[k * n + i] * x[k];
            }
            x[i] = v / l[i * n + i];
        }
    }

    /// Solve `w r = -b` for the rows with a positive bound, each `|r_i| <= bound_i` (rows
    /// without a bound keep their value): solve the free rows; if some are past their
    /// bound, hold the one furthest past (relative to its bound) at its bound (a `soft` row
    /// at its value on entry) and solve the rest again (an active set, one row at a time: a sliding row's large value must not
    /// push the others past theirs).
    fn solve_boxed(
        w: &nalgebra::DMatrix<f64>,
        b: &nalgebra::DVector<f64>,
        bounds: &[f64],
        soft: &[bool],
        r: &mut [f64],
    ) {
        use nalgebra::{DMatrix, DVector};
        // A soft row past its bound is held at its value on entry (the force as evaluated).
        let entry: Vec<f64> = r.to_vec();
        let mut free: Vec<bool> = bounds.iter().map(|&x| x > 0.0).collect();
        for _ in 0..=bounds.len() {
            let f: Vec<usize> = (0..bounds.len()).filter(|&i| free[i]).collect();
            if f.is_empty() {
                return;
            }
            let held: Vec<usize> = (0..bounds.len()).filter(|&i| !free[i]).collect();
            let a = DMatrix::from_fn(f.len(), f.len(), |p, q| w[(f[p], f[q])]);
            let rhs = DVector::from_fn(f.len(), |p, _| {
                -(b[f[p]] + held.iter().map(|&h| w[(f[p], h)] * r[h]).sum::<f64>())
            });
            let Some(sol) = a.lu().solve(&rhs) else {
                return;
            };
            let mut worst: Option<(usize, f64)> = None;
            for (p, &i) in f.iter().enumerate() {
                let past = sol[p].abs() / bounds[i];
                if past > 1.0 && worst.is_none_or(|(_, x)| past > x) {
                    worst = Some((i, past));
                }
                r[i] = sol[p];
            }
            match worst {
                None => return,
                Some((i, _)) => {
                    r[i] = if soft[i] {
                        entry[i]
                    } else {
                        r[i].clamp(-bounds[i], bounds[i])
                    };
                    free[i] = false;
                }
            }
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;
        use crate::forces::{Coefficients, TermSpec};

        const ROD: GeomShape = GeomShape::Rod {
            diameter: 0.0127,
            length: 0.19,
        };

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
            let geoms = SandGeoms::new(
                &["foot".into()],
                &[ROD],
                &thesis_contact_terms(),
                Medium::default(),
                ApplyAt::Tip,
                SignModel::Raw,
            )
            .unwrap();
            let mut out = [0.0; 18];
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
            let geoms = SandGeoms::new(
                &["foot".into()],
                &[ROD],
                &thesis_contact_terms(),
                Medium::default(),
                ApplyAt::Centroid,
                SignModel::Raw,
            )
            .unwrap();
            let mut out = [0.0; 18];
            let q = 0.5f64;
            geoms.evaluate(0, &[0.0, -0.02, q.sin(), q.cos(), 1.0, -1.0, 0.0], &mut out);
            // Moment about the tip of F at E = T + (l/2) e: r x F with r = (l/2) e.
            let r = Vector2::new(out[5], out[6] + 0.02);
            let by_hand = r.y * out[0] - r.x * out[1];
            assert!((out[2] - by_hand).abs() < 1e-12 * by_hand.abs(), "{out:?}");
            let with_gravity = ForceSet::build(
                &[TermSpec::new("gravity", &[]), TermSpec::new("drag", &[])],
                1,
            )
            .unwrap();
            let err = SandGeoms::new(
                &["foot".into()],
                &[ROD],
                &with_gravity,
                Medium::default(),
                ApplyAt::Tip,
                SignModel::Raw,
            )
            .unwrap_err();
            assert!(err.to_string().contains("forces.gravity"), "{err}");
        }

        #[test]
        fn a_stick_within_the_resistance_rests_and_past_it_slides() {
            // One geom, its twist's response h A = 1e-3 I, sinking at 1 cm/s without the
            // sand: the stick that stops it is 10 N up.
            let ha = nalgebra::DMatrix::<f64>::identity(6, 6) * 1e-3;
            let free = nalgebra::DVector::from_row_slice(&[0.0, 0.0, -0.01, 0.0, 0.0, 0.0]);
            let resistance =
                |fz: f64| nalgebra::DVector::from_row_slice(&[0.0, 0.0, fz, 0.0, 0.0, 0.0]);
            let (w, slid) = stick_or_slide(&ha, &free, &resistance(20.0), 1, 6, 3, Slide::Scaled);
            assert!(!slid);
            assert!(
                (w[2] - 10.0).abs() < 1e-12 && w.rows(3, 3).amax() < 1e-12,
                "{w}"
            );
            // A resistance of 5 N: the geom slides, its wrench scaled down to 5 N.
            let (w, slid) = stick_or_slide(&ha, &free, &resistance(5.0), 1, 6, 3, Slide::Scaled);
            assert!(slid);
            assert!((w[2] - 5.0).abs() < 1e-12, "{w}");
        }
    }
}
