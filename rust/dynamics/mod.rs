//! The equations of motion of a body in sand: a [`Mechanism`], its contacts (rods or
//! soles), the medium and the force terms a scene asks for, evaluated for a given set of
//! discrete modes (in contact or not; the sign of each static term, or sticking).
//!
//! `M(q) qddot = bias(q, qdot) + Q_joints + sum_c J_Pc^T F_c`, with `F_c` the resistance
//! force of contact `c` (see `force::resistance`) applied at its point `P_c` (reference
//! point or centroid), and `Q_joints` the joints' spring-damper torques.
//!
//! Constraints, solved together for their multipliers without allocating:
//! - a locked joint, `qdot_i - qdot_parent = 0`, with an unbounded torque;
//! - sticking (MODEL.md, "sgn"): where a static term holds a velocity component of the
//!   centroid E at zero, that term becomes a reaction `R` (along x or y, at `P_c`) chosen so
//!   that the component's rate of change is zero, as in stick-slip friction (Karnopp). The
//!   solver keeps the stick while `|R|` stays below the static term's magnitude.
//!
//! Here: the model, its modes and what an evaluation returns, and [`terms_on`], the one
//! evaluation of the force law. Beside it: `rhs.rs` (geometry -> terms -> constraints, one
//! pipeline for every body: [`Model::eval`], [`Model::eval_general`]), `constraints.rs` (the
//! constraint rows, their multipliers and the projection onto them), `rigid_rod.rs` (the
//! free link: its closed-form evaluation and projection) and `rod_lanes.rs` (the free
//! link's mechanics written once, for one scene and for four in SIMD lanes, calling the
//! same terms).

use nalgebra::{SVector, Vector2};

use crate::body::rod::ApplyAt;
use crate::body::{ArcContact, Mechanism, RodContact, SoleContact};
use crate::forces::registry::MAX_TERMS;
use crate::forces::{AnyTerm, ContactState, ForceSet, Medium, Switch};

mod constraints;
mod rhs;
mod rigid_rod;
pub mod rod_lanes;
#[cfg(test)]
mod tests;

/// Largest sticking-velocity violation [m/s] that the projection treats as drift.
pub const PROJECTION_LIMIT: f64 = 1e-6;

/// Most contacts a body may have.
pub const MAX_CONTACTS: usize = 4;

/// Most locked joints a body may have.
pub const MAX_LOCKED: usize = 8;

/// How the signs of the static terms are evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SignModel {
    /// Each sign is a discrete mode held through a step; switches are located events,
    /// and a component that both sides push back on sticks (default).
    Modes,
    /// The thesis's plain `sign()`, evaluated at every right-hand-side call.
    Raw,
    /// `tanh(v / eps)`, with `eps` in m/s.
    Smooth { eps: f64 },
}

/// The mode of one static term.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slip {
    /// The velocity component is negative: the term pushes in +.
    Neg,
    /// The velocity component is positive: the term pushes in -.
    Pos,
    /// The velocity component is held at zero by a bounded reaction.
    Stick,
}

impl Slip {
    /// The sign of the velocity component in this mode (0 for stick).
    #[inline]
    pub fn sign(self) -> f64 {
        match self {
            Slip::Neg => -1.0,
            Slip::Pos => 1.0,
            Slip::Stick => 0.0,
        }
    }
}

/// The discrete state of one contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactMode {
    /// Whether the tip is in the sand (forces are evaluated only then).
    pub in_contact: bool,
    /// Mode of the horizontal static term.
    pub sx: Slip,
    /// Mode of the vertical static term.
    pub sy: Slip,
    /// Whether this contact's stop event has happened.
    pub stopped: bool,
    /// Sign of e x v_E held through a step: a rod's drag reference area is |e x v_E|, whose
    /// kink where v_E is parallel to the axis is a located event in the `Modes` model.
    pub cross: Slip,
    /// Whether the contact is wholly immersed (a rod's l = L; a sole box under the surface):
    /// the kink of l = min(d / cos q, L) is a located event too, so that a step never
    /// straddles it.
    pub full: bool,
    /// Which of a box's four corners are in the sand (bit k: corner k of
    /// `SoleContact::corners_local`): a corner crossing the surface adds or removes a vertex
    /// of the immersed polygon, a kink of its area and of the drag's extent, located as an
    /// event.
    pub corners: u8,
}

impl Default for ContactMode {
    fn default() -> Self {
        ContactMode {
            in_contact: false,
            sx: Slip::Stick,
            sy: Slip::Stick,
            stopped: false,
            cross: Slip::Pos,
            full: false,
            corners: 0,
        }
    }
}

impl ContactMode {
    /// The mode of the static term along `axis` (0: x, `sx`; 1: y, `sy`).
    #[inline]
    pub fn slip_mut(&mut self, axis: usize) -> &mut Slip {
        if axis == 0 {
            &mut self.sx
        } else {
            &mut self.sy
        }
    }
}

/// The modes of every contact.
pub type Modes = [ContactMode; MAX_CONTACTS];

/// The shape of a contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A round rod meeting the sand with its tip (free link, chain links).
    Rod(RodContact),
    /// A foot's sole box (leg).
    Sole(SoleContact),
    /// A thin circular arc (a C-shaped leg), as its chords.
    Arc(ArcContact),
}

/// One contact of a body: which link, where, what shape. The force terms and their
/// parameters per contact are the model's [`ForceSet`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Geometry: which link, where, what shape.
    pub shape: Shape,
}

impl Contact {
    /// The link the contact belongs to.
    #[inline]
    pub fn link(&self) -> usize {
        match &self.shape {
            Shape::Rod(r) => r.link,
            Shape::Sole(s) => s.link,
            Shape::Arc(a) => a.link,
        }
    }

    /// The reference point T (local coordinates): a rod's tip, the middle of a sole, the
    /// middle of an arc. Its
    /// depth and vertical velocity give the contact's depth and stop.
    #[inline]
    pub fn reference_point(&self) -> Vector2<f64> {
        match &self.shape {
            Shape::Rod(r) => r.tip,
            Shape::Sole(s) => s.reference_point(),
            Shape::Arc(a) => a.reference_point(),
        }
    }
}

/// A body in sand: everything the right-hand side needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Model<const N: usize> {
    /// The rigid links and their joints.
    pub mechanism: Mechanism<N>,
    /// The contacts (at most [`MAX_CONTACTS`]).
    pub contacts: Vec<Contact>,
    /// The sand.
    pub medium: Medium,
    /// Point of application of the resistance force.
    pub apply_at: ApplyAt,
    /// Sign model of the static terms.
    pub sign_model: SignModel,
    /// The force terms that act, with their parameters per contact.
    pub forces: ForceSet,
}

/// The forces on one contact: each listed contact term's (in the scene's order), and their
/// sums by the thesis's classes (F_d dynamic, F_s static) [N].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactForce {
    /// Each contact term's force, in the order of `ForceSet::contact_info` [N]; a sticking
    /// reaction stands in place of the static terms that own the stuck component.
    pub terms: [Vector2<f64>; MAX_TERMS],
    /// Sum of the dynamic terms, F_d [N].
    pub dynamic: Vector2<f64>,
    /// Sum of the static terms (or their reactions), F_s [N].
    pub statics: Vector2<f64>,
    /// The terms' moment about the point of application P [N m] (terms that act over the
    /// boundary or at T: `rft`, `rft_inertial`, `poncelet`).
    pub moment: f64,
}

impl ContactForce {
    /// Total resistance force F_R = F_d + F_s [N].
    #[inline]
    pub fn total(&self) -> Vector2<f64> {
        self.dynamic + self.statics
    }
    /// |F_d| (thesis eq. 3.23) [N].
    #[inline]
    pub fn drag_magnitude(&self) -> f64 {
        self.dynamic.norm()
    }
    /// |F_s| (thesis eq. 3.22) [N].
    #[inline]
    pub fn static_magnitude(&self) -> f64 {
        self.statics.x.hypot(self.statics.y)
    }
    /// |F_r| (thesis eq. 3.24) [N].
    #[inline]
    pub fn total_magnitude(&self) -> f64 {
        self.total().norm()
    }

    /// Put a sticking reaction `reaction` along `axis` in place of the static terms that own
    /// that component's slip switch, and sum again.
    #[inline]
    fn set_reaction(&mut self, forces: &ForceSet, axis: usize, reaction: f64) {
        // One static term writes this axis (the thesis's law: static_h in x, static_v in y):
        // the other static terms' components along it are exactly zero (a term writes only
        // the axes its columns name), so the reaction is the axis's static sum too.
        if let Some(k) = forces.sole_static_owner[axis] {
            self.terms[k][axis] = reaction;
            self.statics[axis] = reaction;
            return;
        }
        self.set_reaction_shared(forces, axis, reaction);
    }

    /// [`ContactForce::set_reaction`] where several static terms share an axis: the
    /// reaction is split among the owners of its switch in proportion to their magnitudes.
    #[cold]
    fn set_reaction_shared(&mut self, forces: &ForceSet, axis: usize, reaction: f64) {
        let switch = if axis == 0 {
            Switch::SlipX
        } else {
            Switch::SlipY
        };
        let owners = || {
            forces
                .contact_info
                .iter()
                .enumerate()
                .filter(move |(_, i)| i.switches.contains(&switch))
                .map(|(k, _)| k)
        };
        let n = owners().count();
        let held: f64 = owners().map(|k| self.terms[k][axis].abs()).sum();
        for k in owners() {
            self.terms[k][axis] = if n == 1 || held == 0.0 {
                reaction / n as f64
            } else {
                reaction * (self.terms[k][axis].abs() / held)
            };
        }
        self.statics = Vector2::zeros();
        for k in 0..forces.contact_info.len() {
            if !forces.is_dynamic(k) {
                self.statics += self.terms[k];
            }
        }
    }
}

/// The contact terms `terms` (a contact's instances of `forces`' contact terms, in their
/// order) on one contact's `state`, written into `out` and `bound`: each term's force, their
/// sums by class, and the bounds of a sticking reaction along x and y. The one evaluation of the force law, for a run of
/// any body and for `granrs.resistance_force`.
#[inline(always)]
pub fn terms_on(
    forces: &ForceSet,
    terms: &[AnyTerm],
    state: &ContactState<f64>,
    medium: &Medium,
    out: &mut ContactForce,
    bound: &mut [f64; 2],
) {
    if forces.reads_frame {
        return terms_on_boundary(forces, terms, state, medium, out, bound);
    }
    sum_terms(forces, terms, out, bound, |t| {
        t.contact_force_local(state, medium)
    });
}

/// [`terms_on`] for a scene with a term that reads the contact's boundary (`rft`,
/// `poncelet`, ...): every term through the full dispatch, and their moments.
#[inline(never)]
fn terms_on_boundary(
    forces: &ForceSet,
    terms: &[AnyTerm],
    state: &ContactState<f64>,
    medium: &Medium,
    out: &mut ContactForce,
    bound: &mut [f64; 2],
) {
    sum_terms(forces, terms, out, bound, |t| {
        t.contact_force(state, medium)
    });
}

/// Each term's force by `force_of` into `out`, their sums by class, their moments and the
/// bounds of a sticking reaction.
#[inline(always)]
fn sum_terms(
    forces: &ForceSet,
    terms: &[AnyTerm],
    out: &mut ContactForce,
    bound: &mut [f64; 2],
    force_of: impl Fn(&AnyTerm) -> crate::forces::TermForce<f64>,
) {
    out.dynamic = Vector2::zeros();
    out.statics = Vector2::zeros();
    out.moment = 0.0;
    *bound = [0.0; 2];
    for (k, t) in terms.iter().enumerate() {
        let tf = force_of(t);
        let v = Vector2::new(tf.force[0], tf.force[1]);
        out.terms[k] = v;
        if forces.dynamic[k] {
            out.dynamic += v;
        } else {
            out.statics += v;
        }
        out.moment += tf.moment;
        bound[0] += tf.bound[0];
        bound[1] += tf.bound[1];
    }
}

/// The shift that holds E's velocity components on the side of their held signs `sign`
/// through a step: a component whose sign disagrees with its held one (it has crossed zero
/// inside the step, before the crossing is located) is mirrored, `-2 v_k`. Added to the
/// contact frame's velocity, it makes the terms that read the frame (`rft`, `poncelet`)
/// see the motion as the mode holds it, the way the static terms read a held sign; zero
/// while the signs agree, so continuous at the crossing.
/// Only a component whose slip switch a listed term owns is held (`owns`: x, y); the
/// others' modes are not kept up to date.
#[inline(always)]
pub fn held_shift(sign: [f64; 2], v_e: Vector2<f64>, owns: [bool; 2]) -> Vector2<f64> {
    let one = |own: bool, s: f64, v: f64| if own && s * v < 0.0 { -2.0 * v } else { 0.0 };
    Vector2::new(one(owns[0], sign[0], v_e.x), one(owns[1], sign[1], v_e.y))
}

/// The thesis's plain sign: -1, 0 or +1.
#[inline]
pub fn raw_sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// What one evaluation finds at one contact.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactEval {
    /// Reference point T (a rod's tip, a sole's middle) [m].
    pub tip: Vector2<f64>,
    /// Velocity of T [m/s].
    pub v_tip: Vector2<f64>,
    /// Depth of the force law [m] (a rod's tip depth; a sole's immersed area / f_s).
    pub depth: f64,
    /// Lowest point of the contact's shape [m] (the entry and exit function).
    pub lowest: f64,
    /// Velocity of the material point at the immersed centroid E [m/s].
    pub v_centroid: Vector2<f64>,
    /// Forces (with any sticking reaction in place of its static terms) [N].
    pub force: ContactForce,
    /// e x v_E, the signed sine of a rod's drag reference area times |v_E| [m/s].
    pub cross: f64,
    /// Margin to full immersion [m] (negative when wholly immersed).
    pub immersion_margin: f64,
    /// y of a box's corners [m] (0 for a rod).
    pub corners_y: [f64; 4],
    /// Magnitudes of the set-valued terms along x and y (the bounds of a sticking
    /// reaction) [N].
    pub bound: [f64; 2],
}

/// How stiff one contact's drag is at one evaluation: |F_d|^2 and |v_E|^2 (their ratio is
/// the square of |F_d| / |v_E|, the drag's velocity stiffness up to a factor 1..2), the
/// contact and v_E.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DragStiffness {
    /// |F_d|^2 [N^2].
    pub drag2: f64,
    /// |v_E|^2 [m^2/s^2].
    pub speed2: f64,
    /// The contact.
    pub contact: usize,
    /// v_E [m/s].
    pub v: Vector2<f64>,
}

impl DragStiffness {
    /// Contact `ci`'s, from its evaluation.
    #[inline]
    pub fn of(ci: usize, c: &ContactEval) -> Self {
        DragStiffness {
            drag2: c.force.dynamic.norm_squared(),
            speed2: c.v_centroid.norm_squared(),
            contact: ci,
            v: c.v_centroid,
        }
    }

    /// (|F_d| / |v_E|)^2, 0 at rest.
    #[inline]
    pub fn k2(&self) -> f64 {
        if self.speed2 > 0.0 {
            self.drag2 / self.speed2
        } else {
            0.0
        }
    }

    /// Whether this is stiffer than `other` (no division: products of squares).
    #[inline]
    pub fn beats(&self, other: &DragStiffness) -> bool {
        self.speed2 > 0.0 && self.drag2 * other.speed2 > other.drag2 * self.speed2
            || (other.speed2 == 0.0 && self.speed2 > 0.0 && self.drag2 > 0.0)
    }
}

/// The result of one right-hand-side evaluation.
#[derive(Debug, Clone, Copy)]
pub struct Eval<const N: usize> {
    /// Generalized accelerations.
    pub qdd: SVector<f64, N>,
    /// Power of the sand's forces on the body, sum_c F_c . v_Pc [W] (non-positive at E).
    pub power: f64,
    /// Power dissipated by the joints' dampers [W] (non-negative).
    pub joint_power: f64,
    /// Torque on each link at its joint, from its parent [N m]: a spring-damper's torque,
    /// or a locked joint's reaction (0 at a free joint and for a root link).
    pub joint_torque: [f64; N],
    /// Per-contact findings.
    pub contacts: [ContactEval; MAX_CONTACTS],
}
