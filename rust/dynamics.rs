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

use nalgebra::{Matrix2, SMatrix, SVector, Vector2};

use crate::body::mechanism::Pose;
use crate::body::rod::ApplyAt;
use crate::body::{Mechanism, RodContact, RodGeometry, SoleContact, SoleModel};
use crate::forces::registry::MAX_TERMS;
use crate::forces::{AnyTerm, ContactState, ForceSet, Medium, Switch};

/// Largest sticking-velocity violation [m/s] that the projection treats as drift.
pub const PROJECTION_LIMIT: f64 = 1e-6;

/// Most contacts a body may have.
pub const MAX_CONTACTS: usize = 4;

/// Most locked joints a body may have.
pub const MAX_LOCKED: usize = 8;

/// Most constraint rows at once: two sticking components per contact and the locked joints.
const MAX_ROWS: usize = 2 * MAX_CONTACTS + MAX_LOCKED;

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
        }
    }

    /// The reference point T (local coordinates): a rod's tip, the middle of a sole. Its
    /// depth and vertical velocity give the contact's depth and stop.
    #[inline]
    pub fn reference_point(&self) -> Vector2<f64> {
        match &self.shape {
            Shape::Rod(r) => r.tip,
            Shape::Sole(s) => s.reference_point(),
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
    fn set_reaction(&mut self, forces: &ForceSet, axis: usize, reaction: f64) {
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
/// order) on one contact's `state`: each term's force, their sums by class, and the bounds
/// of a sticking reaction along x and y. The one evaluation of the force law, for a run of
/// any body and for `granrs.resistance_force`.
#[inline(always)]
pub fn terms_on(
    forces: &ForceSet,
    terms: &[AnyTerm],
    state: &ContactState<f64>,
    medium: &Medium,
) -> (ContactForce, [f64; 2]) {
    let mut f = ContactForce::default();
    let mut bound = [0.0; 2];
    for (k, t) in terms.iter().enumerate() {
        let tf = t.contact_force(state, medium);
        let v = Vector2::new(tf.force[0], tf.force[1]);
        f.terms[k] = v;
        if forces.is_dynamic(k) {
            f.dynamic += v;
        } else {
            f.statics += v;
        }
        bound[0] += tf.bound[0];
        bound[1] += tf.bound[1];
    }
    (f, bound)
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

/// Unit vector of axis `k` (0 = x, 1 = y).
#[inline]
fn unit(k: usize) -> Vector2<f64> {
    if k == 0 {
        Vector2::new(1.0, 0.0)
    } else {
        Vector2::new(0.0, 1.0)
    }
}

/// What a constraint row holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RowKind {
    /// A sticking component: contact and axis (0 = x, 1 = y).
    Stick { contact: usize, axis: usize },
    /// A locked joint of this link.
    Lock { link: usize },
}

/// One constraint `jac . qdot = 0`, with what its multiplier does.
#[derive(Debug, Clone, Copy)]
struct Row<const N: usize> {
    kind: RowKind,
    /// The constrained velocity is `jac . qdot`.
    jac: SVector<f64, N>,
    /// `d(jac)/dt . qdot`: the constraint's acceleration at `qddot = 0` beyond `jac . qddot`.
    bias: f64,
    /// `M^-1 Q_u`: the accelerations caused by a unit multiplier.
    response: SVector<f64, N>,
}

/// A set of at most `R` constraint rows (no allocation in the right-hand side): `R` is
/// [`MAX_ROWS`] for any body, 2 for a single rod (its two sticking components).
struct Rows<const N: usize, const R: usize> {
    rows: [Option<Row<N>>; R],
    len: usize,
}

impl<const N: usize, const R: usize> Rows<N, R> {
    fn new() -> Self {
        Rows {
            rows: [None; R],
            len: 0,
        }
    }
    fn push(&mut self, r: Row<N>) {
        self.rows[self.len] = Some(r);
        self.len += 1;
    }
    fn get(&self, i: usize) -> &Row<N> {
        self.rows[i].as_ref().expect("row within len")
    }
}

/// A constraint system `a x = b` of size `k <= R` on the stack.
type Small<const R: usize> = ([[f64; R]; R], [f64; R]);

/// Solve the `k x k` system that `fill` assembles, by Gaussian elimination with partial
/// pivoting. A (near-)singular system, from redundant constraints, is assembled again with a
/// tiny diagonal shift (only then: the common case copies nothing). Returns the solution, or
/// `None` if that fails too.
fn solve_small<const R: usize>(k: usize, fill: impl Fn(&mut Small<R>)) -> Option<[f64; R]> {
    let mut sys: Small<R> = ([[0.0; R]; R], [0.0; R]);
    fill(&mut sys);
    let scale = (0..k).fold(0.0f64, |m, i| m.max(sys.0[i][i].abs()));
    if eliminate(&mut sys, k, 1e-13 * scale.max(f64::MIN_POSITIVE)) {
        return Some(sys.1);
    }
    fill(&mut sys);
    for (i, row) in sys.0.iter_mut().enumerate().take(k) {
        row[i] += 1e-10 * scale.max(f64::MIN_POSITIVE);
    }
    eliminate(&mut sys, k, 1e-13 * scale.max(f64::MIN_POSITIVE)).then_some(sys.1)
}

/// Gaussian elimination with partial pivoting in place (`b` becomes `x`); false at a pivot
/// at or below `tiny`.
fn eliminate<const R: usize>((a, b): &mut Small<R>, k: usize, tiny: f64) -> bool {
    for col in 0..k {
        let piv = (col..k)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        if a[piv][col].abs() <= tiny {
            return false;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for r in col + 1..k {
            let f = a[r][col] / a[col][col];
            if f != 0.0 {
                let pivot_row = a[col];
                for (x, p) in a[r][col..k].iter_mut().zip(&pivot_row[col..k]) {
                    *x -= f * p;
                }
                b[r] -= f * b[col];
            }
        }
    }
    for col in (0..k).rev() {
        let mut v = b[col];
        for c in col + 1..k {
            v -= a[col][c] * b[c];
        }
        b[col] = v / a[col][col];
    }
    true
}

/// [`solve_small`] of a system of one or two rows, unrolled: the same elimination with
/// partial pivoting as [`eliminate`], falling back to [`solve_small`] (which shifts the
/// diagonal) only at a tiny pivot.
#[inline(always)]
fn solve_upto2(k: usize, a: [[f64; 2]; 2], b: [f64; 2]) -> Option<[f64; 2]> {
    #[cold]
    #[inline(never)]
    fn shifted(k: usize, a: [[f64; 2]; 2], b: [f64; 2]) -> Option<[f64; 2]> {
        solve_small::<2>(k, |sys| {
            sys.0 = a;
            sys.1 = b;
        })
    }
    let fallback = || shifted(k, a, b);
    if k == 1 {
        let tiny = 1e-13 * a[0][0].abs().max(f64::MIN_POSITIVE);
        if a[0][0].abs() <= tiny {
            return fallback();
        }
        return Some([b[0] / a[0][0], 0.0]);
    }
    let scale = a[0][0].abs().max(a[1][1].abs());
    let tiny = 1e-13 * scale.max(f64::MIN_POSITIVE);
    // `max_by` keeps the last of equal maxima: row 1 on a tie.
    let (r0, r1, b0, b1) = if a[1][0].abs() >= a[0][0].abs() {
        (a[1], a[0], b[1], b[0])
    } else {
        (a[0], a[1], b[0], b[1])
    };
    if r0[0].abs() <= tiny {
        return fallback();
    }
    let f = r1[0] / r0[0];
    let (a11, b1) = if f != 0.0 {
        (r1[1] - f * r0[1], b1 - f * b0)
    } else {
        (r1[1], b1)
    };
    if a11.abs() <= tiny {
        return fallback();
    }
    let x1 = b1 / a11;
    Some([(b0 - r0[1] * x1) / r0[0], x1])
}

/// The immersed geometry of one contact, as the force law needs it.
#[derive(Debug, Clone, Copy)]
struct Geometry {
    /// Depth of the force law [m].
    depth: f64,
    /// Local coordinates of the immersed centroid E.
    centroid: Vector2<f64>,
    /// Immersed volume [m^3].
    volume: f64,
    /// Width w of the horizontal static term [m].
    width: f64,
    /// Reference length of the depth factor [m].
    l_ref: f64,
    /// Margin to full immersion [m].
    margin: f64,
    /// Lowest point of the shape [m].
    lowest: f64,
    /// The axis whose cross product with v_E sets a rod's (or the thesis sole's) drag area.
    cross_axis: Vector2<f64>,
    /// Drag factor along `cross_axis`: `A_r |v_E| = factor * |cross_axis x v_E|`, or for the
    /// box `A_r |v_E|` comes from the polygon (`sole`).
    factor: f64,
    /// The sole's polygon, for the box drag.
    sole: Option<crate::body::SoleGeometry>,
}

/// Solve for the multipliers of `rows` at the unconstrained accelerations `qdd`, correct
/// `qdd`, and store each multiplier: a sticking component's reaction in place of its static
/// term, a locked joint's torque.
fn apply_rows<const N: usize, const R: usize>(
    rows: &Rows<N, R>,
    qdd: &mut SVector<f64, N>,
    contacts: &mut [ContactEval],
    joint_torque: &mut [f64; N],
    forces: &ForceSet,
) {
    let k = rows.len;
    if k == 0 {
        return;
    }
    let free = *qdd;
    let mults = solve_small::<R>(k, |(a, b)| {
        for i in 0..k {
            let ri = rows.get(i);
            b[i] = -(ri.bias + ri.jac.dot(&free));
            for (j, aij) in a[i].iter_mut().enumerate().take(k) {
                *aij = ri.jac.dot(&rows.get(j).response);
            }
        }
    })
    .unwrap_or([0.0; R]);
    for (i, &mult) in mults.iter().enumerate().take(k) {
        let r = rows.get(i);
        *qdd += mult * r.response;
        match r.kind {
            RowKind::Stick { contact, axis } => {
                contacts[contact].force.set_reaction(forces, axis, mult);
            }
            RowKind::Lock { link } => joint_torque[link] = mult,
        }
    }
}

/// Project `qd` onto `rows` (each `jac . qd = 0`) M-orthogonally, `minv` applying M^-1.
/// Only drift is removed: a violation above [`PROJECTION_LIMIT`] is a wrong mode, left for
/// the solver's switching functions to see. Returns whether `qd` changed.
fn project_rows<const N: usize, const R: usize>(
    rows: &Rows<N, R>,
    qd: &mut SVector<f64, N>,
    minv: impl Fn(&SVector<f64, N>) -> SVector<f64, N>,
) -> bool {
    let k = rows.len;
    if k == 0 {
        return false;
    }
    if (0..k).any(|i| rows.get(i).jac.dot(qd).abs() > PROJECTION_LIMIT) {
        return false;
    }
    // M^-1 J^T columns and J M^-1 J^T.
    let mut minv_jt = [SVector::<f64, N>::zeros(); R];
    for (i, m) in minv_jt.iter_mut().enumerate().take(k) {
        *m = minv(&rows.get(i).jac);
    }
    let v = *qd;
    let lam = solve_small::<R>(k, |(a, b)| {
        for i in 0..k {
            let ji = &rows.get(i).jac;
            b[i] = ji.dot(&v);
            for (j, aij) in a[i].iter_mut().enumerate().take(k) {
                *aij = ji.dot(&minv_jt[j]);
            }
        }
    });
    match lam {
        Some(lam) if lam[..k].iter().any(|&l| l != 0.0) => {
            for (l, m) in lam.iter().zip(&minv_jt).take(k) {
                *qd -= *l * m;
            }
            true
        }
        _ => false,
    }
}

/// Position and velocity of a single rigid rod whose root is its centre of mass: what
/// [`Model::eval_rigid_rod`] and its constraints need (one `sin_cos` per evaluation).
#[derive(Debug, Clone, Copy)]
struct RodFrame {
    root: Vector2<f64>,
    v_root: Vector2<f64>,
    omega: f64,
    axis: Vector2<f64>,
    normal: Vector2<f64>,
}

impl RodFrame {
    #[inline]
    fn new<const N: usize>(q: &SVector<f64, N>, qd: &SVector<f64, N>) -> Self {
        let (s, c) = q[2].sin_cos();
        RodFrame {
            root: Vector2::new(q[0], q[1]),
            v_root: Vector2::new(qd[0], qd[1]),
            omega: qd[2],
            axis: Vector2::new(s, c),
            normal: Vector2::new(c, -s),
        }
    }

    /// Position of the point with local coordinates `r`: `root + R r`.
    #[inline]
    fn at(&self, r: Vector2<f64>) -> Vector2<f64> {
        self.root + (r.x * self.axis + r.y * self.normal)
    }

    /// `d(R r)/dq`: the lever of `r` (velocity per unit rate, generalized force per unit force).
    #[inline]
    fn lever(&self, r: Vector2<f64>) -> Vector2<f64> {
        r.x * self.normal - r.y * self.axis
    }

    /// Velocity of the point with local coordinates `r`.
    #[inline]
    fn velocity(&self, r: Vector2<f64>) -> Vector2<f64> {
        self.v_root + self.omega * self.lever(r)
    }
}

/// The sticking rows of a single rigid rod about its centre of mass (at most two: the
/// velocity of the immersed centroid E along x and along y held at zero). Row `i` holds
/// axis `u = unit(axes[i])`: its Jacobian is `(u_x, u_y, u . lever_E)` and a unit reaction
/// along `u` at the point of application P gives the generalized force
/// `(u_x, u_y, u . lever_P)`; with `M = diag(m, m, I)` everything is in closed form.
#[derive(Debug, Clone, Copy)]
struct RodStick {
    len: usize,
    axes: [usize; 2],
    /// `u . lever_E` per row.
    lever_e: [f64; 2],
    /// `u . lever_P` per row.
    lever_p: [f64; 2],
}

impl RodStick {
    /// The constrained velocity of row `i`, `jac . v`.
    #[inline]
    fn velocity<const N: usize>(&self, i: usize, v: &SVector<f64, N>) -> f64 {
        v[self.axes[i]] + self.lever_e[i] * v[2]
    }
}

impl<const N: usize> Model<N> {
    /// The geometry of contact `c` at `pose` (depth zero when out of the sand).
    fn geometry(&self, c: &Contact, pose: &Pose<N>) -> Geometry {
        let link = c.link();
        let axis = pose.axis[link];
        match &c.shape {
            Shape::Rod(rod) => {
                let tip = self.mechanism.point(pose, link, rod.tip);
                let g = rod.geometry(tip.y, axis);
                Geometry {
                    depth: g.depth,
                    centroid: Vector2::new(g.centroid_s, rod.tip.y),
                    volume: rod.immersed_volume(&g),
                    width: rod.diameter,
                    l_ref: rod.length,
                    margin: rod.length * axis.y - g.depth,
                    lowest: tip.y,
                    cross_axis: axis,
                    factor: rod.diameter * g.immersed_length,
                    sole: None,
                }
            }
            Shape::Sole(sole) => {
                let joint = pose.joint[link];
                let normal = pose.normal[link];
                let g = sole.geometry(joint, axis, normal);
                let rel = g.centroid - joint;
                let centroid = Vector2::new(rel.dot(&axis), rel.dot(&normal));
                let (volume, factor, cross_axis) = match sole.model {
                    SoleModel::Box => (sole.volume(&g), 0.0, axis),
                    SoleModel::Thesis => {
                        // Eqs. 5.5-5.7 with q the shank's angle from the vertical: infinite
                        // at q = 0 (V) and |q| = 90 deg (A_r); NaN there stops the run.
                        let e = pose.axis[sole.angle_link];
                        let (sin_q, cos_q) = (e.x.abs(), e.y);
                        let ok = sin_q > 1e-9 && cos_q > 1e-9;
                        let nan = f64::NAN;
                        (
                            if ok {
                                sole.length * sole.width * g.depth / sin_q
                            } else {
                                nan
                            },
                            if ok {
                                sole.length * g.depth / cos_q
                            } else {
                                nan
                            },
                            e,
                        )
                    }
                };
                Geometry {
                    depth: g.depth,
                    centroid,
                    volume,
                    width: sole.length,
                    l_ref: sole.l_ref,
                    margin: g.highest,
                    lowest: g.lowest,
                    cross_axis,
                    factor,
                    sole: if sole.model == SoleModel::Box {
                        Some(g)
                    } else {
                        None
                    },
                }
            }
        }
    }

    /// Rate of change of E's local coordinates on its link (E moves over the body as the
    /// immersed part grows).
    fn centroid_local_rate(
        &self,
        c: &Contact,
        pose: &Pose<N>,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        geom: &Geometry,
    ) -> Vector2<f64> {
        let link = c.link();
        match &c.shape {
            Shape::Rod(rod) => {
                let axis = pose.axis[link];
                let v_tip = self.mechanism.point_velocity(pose, link, rod.tip, qd);
                let omega = qd[2 + link];
                let g = rod.geometry(-geom.depth, axis);
                let l_rate = rod.immersed_length_rate(&g, axis, -v_tip.y, -axis.x * omega);
                Vector2::new(0.5 * l_rate, 0.0)
            }
            Shape::Sole(_) => {
                // Central difference along the motion (the polygon's centroid has no simple
                // closed-form rate).
                let h = 1e-7;
                let at = |sign: f64| {
                    let qh = q + (sign * h) * qd;
                    self.geometry(c, &self.mechanism.pose(&qh)).centroid
                };
                (at(1.0) - at(-1.0)) / (2.0 * h)
            }
        }
    }

    /// The local (s, n) coordinates of the point where contact `c`'s force acts.
    #[inline]
    fn application_point(&self, c: &Contact, centroid: Vector2<f64>) -> Vector2<f64> {
        match self.apply_at {
            ApplyAt::Tip => c.reference_point(),
            ApplyAt::Centroid => centroid,
        }
    }

    /// Inverse effective mass of contact `ci`'s immersed centroid E at `q`, with the locked
    /// joints held: `W = J_E (M^-1 - M^-1 A^T (A M^-1 A^T)^-1 A M^-1) J_E^T` [1/kg], A the
    /// locked joints' rows. Sticking rows are left out: they can only slow E down. With the
    /// drag's velocity stiffness K it gives the drag's fastest rate, the largest eigenvalue
    /// of `W K`, which a fixed RK4 step must keep below about 2.78 (its stability limit on
    /// the negative real axis).
    pub fn centroid_inverse_mass(&self, q: &SVector<f64, N>, ci: usize) -> Matrix2<f64> {
        let nan = Matrix2::repeat(f64::NAN);
        let Some(c) = self.contacts.get(ci) else {
            return nan;
        };
        let pose = self.mechanism.pose(q);
        let Some(chol) = self.mechanism.mass_matrix(&pose).cholesky() else {
            return nan;
        };
        let centroid = self.geometry(c, &pose).centroid;
        let locks: Vec<SVector<f64, N>> = self
            .mechanism
            .locked_rows()
            .map(|(link, parent)| {
                let mut a = SVector::<f64, N>::zeros();
                a[2 + link] = 1.0;
                a[2 + parent] = -1.0;
                a
            })
            .collect();
        let responses: Vec<SVector<f64, N>> = locks.iter().map(|a| chol.solve(a)).collect();
        let schur = nalgebra::DMatrix::from_fn(locks.len(), locks.len(), |i, j| {
            locks[i].dot(&responses[j])
        });
        let Some(schur_inv) = schur.try_inverse() else {
            return nan;
        };
        let gen: [SVector<f64, N>; 2] = std::array::from_fn(|k| {
            let mut g = SVector::<f64, N>::zeros();
            self.mechanism
                .add_point_force(&pose, c.link(), centroid, unit(k), &mut g);
            g
        });
        let free: [SVector<f64, N>; 2] = std::array::from_fn(|k| chol.solve(&gen[k]));
        let along: [Vec<f64>; 2] =
            std::array::from_fn(|k| locks.iter().map(|a| a.dot(&free[k])).collect());
        Matrix2::from_fn(|a, b| {
            let mut held = 0.0;
            for (i, ai) in along[a].iter().enumerate() {
                for (j, bj) in along[b].iter().enumerate() {
                    held += ai * schur_inv[(i, j)] * bj;
                }
            }
            gen[a].dot(&free[b]) - held
        })
    }

    /// The acceleration of gravity on the body [m/s^2]: the medium's g while the `gravity`
    /// term acts, else zero (the body then has no potential energy from gravity either).
    #[inline(always)]
    pub fn gravity(&self) -> f64 {
        if self.forces.gravity {
            self.medium.g
        } else {
            0.0
        }
    }

    /// The signs of v_Ex and v_Ey that the static terms take in `mode`, by the sign model.
    #[inline(always)]
    fn signs(&self, mode: &ContactMode, v_e: Vector2<f64>) -> [f64; 2] {
        match self.sign_model {
            SignModel::Modes => [mode.sx.sign(), mode.sy.sign()],
            SignModel::Raw => [raw_sign(v_e.x), raw_sign(v_e.y)],
            SignModel::Smooth { eps } => [(v_e.x / eps).tanh(), (v_e.y / eps).tanh()],
        }
    }

    /// |e x v_E| as the drag reads it: with its sign held in `Modes` (the kink at zero is a
    /// located event), plainly otherwise.
    #[inline(always)]
    fn held_cross(&self, mode: &ContactMode, cross_signed: f64) -> f64 {
        match self.sign_model {
            SignModel::Modes if mode.cross == Slip::Neg => -cross_signed,
            SignModel::Modes => cross_signed,
            _ => cross_signed.abs(),
        }
    }

    /// Evaluate the listed contact terms of contact `ci` on `state` into `out`: each term's
    /// force, their sums by class, and the bounds of a sticking reaction. The one place the
    /// force law is evaluated, for every body and for `granrs.resistance_force`.
    #[inline(always)]
    pub fn apply_terms(&self, ci: usize, state: &ContactState<f64>, out: &mut ContactEval) {
        (out.force, out.bound) = terms_on(
            &self.forces,
            &self.forces.per_contact[ci],
            state,
            &self.medium,
        );
    }

    /// Whether any sticking component is in force under `modes`.
    #[inline]
    fn any_stuck(&self, modes: &Modes) -> bool {
        self.sign_model == SignModel::Modes
            && modes[..self.contacts.len()].iter().any(|m| self.stuck(m))
    }

    /// Whether a static term of a contact in mode `m` sticks (with `SignModel::Modes`).
    #[inline]
    fn stuck(&self, m: &ContactMode) -> bool {
        m.in_contact
            && ((self.forces.owns(Switch::SlipX) && m.sx == Slip::Stick)
                || (self.forces.owns(Switch::SlipY) && m.sy == Slip::Stick))
    }

    /// Evaluate the accelerations and the per-contact forces at `(q, qd)` in `modes`.
    ///
    /// A single rigid rod whose root is its centre of mass (the free link) has a constant,
    /// diagonal mass matrix and no velocity products: it takes [`Model::eval_rigid_rod`],
    /// the same equations in closed form.
    #[inline]
    pub fn eval(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>, modes: &Modes) -> Eval<N> {
        match self.rigid_rod() {
            Some(rod) => {
                let mut contacts = [ContactEval::default(); MAX_CONTACTS];
                let (qdd, power, joint_torque) =
                    self.eval_rigid_rod(rod, q, qd, modes, &mut contacts[0]);
                Eval {
                    qdd,
                    power,
                    joint_power: 0.0,
                    joint_torque,
                    contacts,
                }
            }
            None => self.eval_general(q, qd, modes),
        }
    }

    /// [`Model::eval`] into `out`, in place (an `Eval` holds every contact's findings: the
    /// solver keeps two and writes each step's end into one). Every field is overwritten
    /// except the findings past the model's contacts, which stay as they were (the defaults,
    /// when `out` came from this model).
    #[inline]
    pub fn eval_into(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
        out: &mut Eval<N>,
    ) {
        match self.rigid_rod() {
            Some(rod) => {
                out.contacts[0] = ContactEval::default();
                let (qdd, power, joint_torque) =
                    self.eval_rigid_rod(rod, q, qd, modes, &mut out.contacts[0]);
                out.qdd = qdd;
                out.power = power;
                out.joint_power = 0.0;
                out.joint_torque = joint_torque;
            }
            None => *out = self.eval_general(q, qd, modes),
        }
    }

    /// What a Runge-Kutta stage needs of [`Model::eval`]: the accelerations, the power of
    /// the sand's forces and that of the joints' dampers [W] (the free link skips the
    /// per-contact findings).
    #[inline]
    pub fn rates(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
    ) -> (SVector<f64, N>, f64, f64) {
        let (qdd, power, joint_power, _) = self.rates_sampled(q, qd, modes);
        (qdd, power, joint_power)
    }

    /// [`Model::rates`] and the drag's stiffest contact at the stage.
    #[inline]
    pub fn rates_sampled(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
    ) -> (SVector<f64, N>, f64, f64, DragStiffness) {
        match self.rigid_rod() {
            Some(rod) => {
                let mut contact = ContactEval::default();
                let (qdd, power, _) = self.eval_rigid_rod(rod, q, qd, modes, &mut contact);
                (qdd, power, 0.0, DragStiffness::of(0, &contact))
            }
            None => {
                let e = self.eval_general(q, qd, modes);
                let stiff = (0..self.contacts.len())
                    .map(|ci| DragStiffness::of(ci, &e.contacts[ci]))
                    .fold(
                        DragStiffness::default(),
                        |a, b| if b.beats(&a) { b } else { a },
                    );
                (e.qdd, e.power, e.joint_power, stiff)
            }
        }
    }

    /// The rod contact of a single free link with its centre of mass at the root (no
    /// parent, one rod contact on it), or `None` for any other body.
    #[inline]
    fn rigid_rod(&self) -> Option<&RodContact> {
        if N != 3 || self.mechanism.links.len() != 1 || self.contacts.len() != 1 {
            return None;
        }
        let link = &self.mechanism.links[0];
        if link.parent.is_some() || link.com != Vector2::zeros() {
            return None;
        }
        match &self.contacts[0].shape {
            Shape::Rod(rod) if rod.link == 0 => Some(rod),
            _ => None,
        }
    }

    /// `1 / (m + m_root)` and `1 / I`: M^-1 of a single rigid rod about its centre of mass,
    /// `M = diag(m + m_root, m + m_root, I)`.
    #[inline]
    fn rigid_rod_inverse_mass_parts(&self) -> (f64, f64) {
        let link = &self.mechanism.links[0];
        (
            1.0 / (link.mass + self.mechanism.root_mass),
            1.0 / link.inertia,
        )
    }

    /// [`Model::eval`] of a single rigid rod whose root is its centre of mass, in closed
    /// form: `M = diag(m + m_root, m + m_root, I)`, gravity the only bias force, a force `F`
    /// applied at `P` giving the torque `F . dP/dq`, and at most two sticking rows. The same
    /// equations as [`Model::eval_general`], equal to round-off (the tests compare the two).
    ///
    /// Writes the contact's findings into `out` (which must hold the defaults) and returns
    /// the accelerations, the power of the sand's force and the joint torques.
    #[inline]
    fn eval_rigid_rod(
        &self,
        rod: &RodContact,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
        out: &mut ContactEval,
    ) -> (SVector<f64, N>, f64, [f64; N]) {
        let link = &self.mechanism.links[0];
        let mass = link.mass + self.mechanism.root_mass;
        let g = self.gravity();
        let fr = RodFrame::new(q, qd);
        let mut gen = SVector::<f64, N>::zeros();
        gen[1] = -mass * g;
        let tip = fr.at(rod.tip);
        let v_tip = fr.velocity(rod.tip);
        out.tip = tip;
        out.v_tip = v_tip;
        out.v_centroid = v_tip;
        out.lowest = tip.y;
        let mode = &modes[0];
        let geom = rod.geometry(tip.y, fr.axis);
        let forced = mode.in_contact && geom.depth > 0.0;
        let centroid = Vector2::new(geom.centroid_s, rod.tip.y);
        if mode.in_contact {
            out.depth = geom.depth;
            out.immersion_margin = rod.length * fr.axis.y - geom.depth;
            // E and the sign of e x v_E also at depth 0: entering, the drag's mode is
            // chosen from them (a rod past horizontal enters with l = L, E its middle).
            out.v_centroid = fr.velocity(centroid);
            out.cross = fr.axis.x * out.v_centroid.y - fr.axis.y * out.v_centroid.x;
        }
        if forced {
            let v_e = out.v_centroid;
            let area_speed = if self.forces.reads_area_speed {
                rod.diameter * geom.immersed_length * self.held_cross(mode, out.cross)
            } else {
                0.0
            };
            let state = ContactState {
                depth: geom.depth,
                volume: rod.immersed_volume(&geom),
                width: rod.diameter,
                l_ref: rod.length,
                v: [v_e.x, v_e.y],
                area_speed,
                sign: self.signs(mode, v_e),
            };
            self.apply_terms(0, &state, out);
            let total = out.force.total();
            gen[0] += total.x;
            gen[1] += total.y;
            gen[2] += total.dot(&fr.lever(self.application_point(&self.contacts[0], centroid)));
        }
        // M^-1 by multiplication: the divisions are off the force's path and overlap it.
        let (inv_m, inv_i) = self.rigid_rod_inverse_mass_parts();
        let mut qdd = SVector::<f64, N>::zeros();
        qdd[0] = gen[0] * inv_m;
        qdd[1] = gen[1] * inv_m;
        qdd[2] = gen[2] * inv_i;
        if forced && self.sign_model == SignModel::Modes && self.stuck(mode) {
            self.rigid_rod_reactions(rod, &fr, &geom, v_tip, mode, &mut qdd, out);
        }
        let joint_torque = [0.0; N];
        let power = if forced {
            let v_p = match self.apply_at {
                ApplyAt::Tip => out.v_tip,
                ApplyAt::Centroid => out.v_centroid,
            };
            out.force.total().dot(&v_p)
        } else {
            0.0
        };
        (qdd, power, joint_torque)
    }

    /// The sticking rows of a single rigid rod about its centre of mass in `mode`, its tip
    /// `geom.depth > 0` deep ([`Model::constraint_rows`] for that body).
    #[inline]
    fn rigid_rod_stick(
        &self,
        rod: &RodContact,
        fr: &RodFrame,
        geom: &RodGeometry,
        mode: &ContactMode,
    ) -> RodStick {
        let centroid = Vector2::new(geom.centroid_s, rod.tip.y);
        let lever_e = fr.lever(centroid);
        let lever_p = fr.lever(self.application_point(&self.contacts[0], centroid));
        let mut stick = RodStick {
            len: 0,
            axes: [0; 2],
            lever_e: [0.0; 2],
            lever_p: [0.0; 2],
        };
        let stuck_x = self.forces.owns(Switch::SlipX) && mode.sx == Slip::Stick;
        let stuck_y = self.forces.owns(Switch::SlipY) && mode.sy == Slip::Stick;
        for (k, on) in [(0usize, stuck_x), (1usize, stuck_y)] {
            if on {
                let i = stick.len;
                stick.axes[i] = k;
                stick.lever_e[i] = lever_e[k];
                stick.lever_p[i] = lever_p[k];
                stick.len += 1;
            }
        }
        stick
    }

    /// The sticking reactions of a single rigid rod ([`apply_rows`] in closed form): solve
    /// its (at most two) rows for the reactions at the unconstrained accelerations `qdd`,
    /// correct `qdd`, and store each reaction in place of its static term in `out`. E moves
    /// over the rod at half the rate of the immersed length, which the rows' bias holds.
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    fn rigid_rod_reactions(
        &self,
        rod: &RodContact,
        fr: &RodFrame,
        geom: &RodGeometry,
        v_tip: Vector2<f64>,
        mode: &ContactMode,
        qdd: &mut SVector<f64, N>,
        out: &mut ContactEval,
    ) {
        let stick = self.rigid_rod_stick(rod, fr, geom, mode);
        let centroid = Vector2::new(geom.centroid_s, rod.tip.y);
        let l_rate = rod.immersed_length_rate(geom, fr.axis, -v_tip.y, -fr.axis.x * fr.omega);
        let slide = (0.5 * l_rate) * fr.normal;
        let a_bias = -(fr.omega * fr.omega) * (centroid.x * fr.axis + centroid.y * fr.normal)
            + fr.omega * slide;
        let (inv_m, inv_i) = self.rigid_rod_inverse_mass_parts();
        let k = stick.len;
        if k == 1 {
            // One row (a vertical rod holds v_Ex): its 1 x 1 system's inverse depends on the
            // geometry alone, off the accelerations' path. A zero pivot takes the shift below.
            let (axis, lever_e, lever_p) = (stick.axes[0], stick.lever_e[0], stick.lever_p[0]);
            let a = inv_m + lever_e * (lever_p * inv_i);
            if a.abs() > 1e-13 * a.abs().max(f64::MIN_POSITIVE) {
                let inv_a = 1.0 / a;
                let mult = -(a_bias[axis] + stick.velocity(0, qdd)) * inv_a;
                qdd[axis] += mult * inv_m;
                qdd[2] += mult * (lever_p * inv_i);
                out.force.set_reaction(&self.forces, axis, mult);
                return;
            }
        }
        let mut a = [[0.0; 2]; 2];
        let mut b = [0.0; 2];
        for i in 0..k {
            b[i] = -(a_bias[stick.axes[i]] + stick.velocity(i, qdd));
            for (j, aij) in a[i].iter_mut().enumerate().take(k) {
                let linear = if stick.axes[i] == stick.axes[j] {
                    inv_m
                } else {
                    0.0
                };
                *aij = linear + stick.lever_e[i] * (stick.lever_p[j] * inv_i);
            }
        }
        let mults = solve_upto2(k, a, b).unwrap_or([0.0; 2]);
        for (i, &mult) in mults.iter().enumerate().take(k) {
            let axis = stick.axes[i];
            qdd[axis] += mult * inv_m;
            qdd[2] += mult * (stick.lever_p[i] * inv_i);
            out.force.set_reaction(&self.forces, axis, mult);
        }
    }

    /// [`Model::project_sticking`] of a single rigid rod ([`project_rows`] in closed form).
    fn project_rigid_rod(
        &self,
        rod: &RodContact,
        q: &SVector<f64, N>,
        qd: &mut SVector<f64, N>,
        mode: &ContactMode,
    ) -> bool {
        let fr = RodFrame::new(q, qd);
        let geom = rod.geometry(fr.at(rod.tip).y, fr.axis);
        if !mode.in_contact || geom.depth <= 0.0 {
            return false;
        }
        let stick = self.rigid_rod_stick(rod, &fr, &geom, mode);
        let k = stick.len;
        if k == 0 || (0..k).any(|i| stick.velocity(i, qd).abs() > PROJECTION_LIMIT) {
            return false;
        }
        // J M^-1 J^T, with M^-1 J^T's columns (u_x / m, u_y / m, u . lever_E / I).
        let (inv_m, inv_i) = self.rigid_rod_inverse_mass_parts();
        let mut a = [[0.0; 2]; 2];
        let mut b = [0.0; 2];
        for i in 0..k {
            b[i] = stick.velocity(i, qd);
            for (j, aij) in a[i].iter_mut().enumerate().take(k) {
                let linear = if stick.axes[i] == stick.axes[j] {
                    inv_m
                } else {
                    0.0
                };
                *aij = linear + stick.lever_e[i] * (stick.lever_e[j] * inv_i);
            }
        }
        match solve_upto2(k, a, b) {
            Some(lam) if lam[..k].iter().any(|&l| l != 0.0) => {
                for (i, &l) in lam.iter().enumerate().take(k) {
                    qd[stick.axes[i]] -= l * inv_m;
                    qd[2] -= l * (stick.lever_e[i] * inv_i);
                }
                true
            }
            _ => false,
        }
    }

    /// [`Model::eval`] for any body: pose, bias forces, contact forces through the
    /// Jacobians, mass matrix and its Cholesky factor, and the constraints in force.
    pub fn eval_general(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
    ) -> Eval<N> {
        let pose = self.mechanism.pose(q);
        let g = self.gravity();
        let mut rhs = self.mechanism.bias_forces(&pose, qd, g);
        let mut joint_torque = [0.0; N];
        let joint_power = if self.forces.joint_springs {
            self.mechanism
                .add_joint_torques(q, qd, &mut rhs, &mut joint_torque)
        } else {
            0.0
        };
        let mut contacts = [ContactEval::default(); MAX_CONTACTS];
        for (ci, c) in self.contacts.iter().enumerate() {
            let link = c.link();
            let t_local = c.reference_point();
            let tip = self.mechanism.point(&pose, link, t_local);
            let v_tip = self.mechanism.point_velocity(&pose, link, t_local, qd);
            let out = &mut contacts[ci];
            out.tip = tip;
            out.v_tip = v_tip;
            // With nothing immersed, E is the reference point.
            out.v_centroid = v_tip;
            let geom = self.geometry(c, &pose);
            out.lowest = geom.lowest;
            let mode = &modes[ci];
            if !mode.in_contact {
                continue;
            }
            out.depth = geom.depth;
            out.immersion_margin = geom.margin;
            let is_rod = matches!(c.shape, Shape::Rod(_));
            if geom.depth <= 0.0 && !is_rod {
                continue;
            }
            // A rod's E and sign of e x v_E also at depth 0: entering, the drag's mode is
            // chosen from them (a rod past horizontal enters with l = L, E its middle).
            let v_e = self
                .mechanism
                .point_velocity(&pose, link, geom.centroid, qd);
            out.v_centroid = v_e;
            let e = geom.cross_axis;
            let cross_signed = e.x * v_e.y - e.y * v_e.x;
            out.cross = if geom.sole.is_some() {
                1.0
            } else {
                cross_signed
            };
            if geom.depth <= 0.0 {
                continue;
            }
            // A_r |v_E|; for a rod |e x v_E| times d_c l: in `Modes` the sign is held (the
            // kink at 0 is a located event).
            let area_speed = match (&geom.sole, &c.shape) {
                _ if !self.forces.reads_area_speed => 0.0,
                (Some(sg), Shape::Sole(sole)) => sole.drag_area_speed(sg, v_e),
                _ => geom.factor * self.held_cross(mode, cross_signed),
            };
            let state = ContactState {
                depth: geom.depth,
                volume: geom.volume,
                width: geom.width,
                l_ref: geom.l_ref,
                v: [v_e.x, v_e.y],
                area_speed,
                sign: self.signs(mode, v_e),
            };
            self.apply_terms(ci, &state, out);
            let p = self.application_point(c, geom.centroid);
            self.mechanism
                .add_point_force(&pose, link, p, out.force.total(), &mut rhs);
        }
        let mass = self.mechanism.mass_matrix(&pose);
        // Positive masses give a positive definite M for any finite state; a state that has
        // already blown up (NaN) does not: return NaN and let the solver report it.
        let Some(chol) = mass.cholesky() else {
            return Eval {
                qdd: SVector::repeat(f64::NAN),
                power: f64::NAN,
                joint_power: f64::NAN,
                joint_torque,
                contacts,
            };
        };
        let mut qdd = chol.solve(&rhs);
        let has_locks = self.mechanism.locked_rows().next().is_some();
        if has_locks || self.any_stuck(modes) {
            self.solve_constraints(
                &pose,
                q,
                qd,
                modes,
                &chol,
                &mut qdd,
                &mut contacts,
                &mut joint_torque,
            );
        }
        // Power of the sand's forces at their points of application.
        let mut power = 0.0;
        for (ci, ce) in contacts.iter().enumerate().take(self.contacts.len()) {
            if ce.depth <= 0.0 || !modes[ci].in_contact {
                continue;
            }
            let p = match self.apply_at {
                ApplyAt::Tip => ce.v_tip,
                ApplyAt::Centroid => ce.v_centroid,
            };
            power += ce.force.total().dot(&p);
        }
        Eval {
            qdd,
            power,
            joint_power,
            joint_torque,
            contacts,
        }
    }

    /// The constraint rows in force under `modes` at this configuration: the locked joints
    /// and the sticking components.
    fn constraint_rows(
        &self,
        pose: &Pose<N>,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
        chol: &nalgebra::Cholesky<f64, nalgebra::Const<N>>,
    ) -> Rows<N, MAX_ROWS> {
        let mut rows = Rows::new();
        for (link, parent) in self.mechanism.locked_rows() {
            let mut jac = SVector::<f64, N>::zeros();
            jac[2 + link] = 1.0;
            jac[2 + parent] = -1.0;
            rows.push(Row {
                kind: RowKind::Lock { link },
                jac,
                bias: 0.0,
                response: chol.solve(&jac),
            });
        }
        if self.sign_model != SignModel::Modes {
            return rows;
        }
        for (ci, c) in self.contacts.iter().enumerate() {
            let mode = &modes[ci];
            if !mode.in_contact {
                continue;
            }
            let stuck_x = self.forces.owns(Switch::SlipX) && mode.sx == Slip::Stick;
            let stuck_y = self.forces.owns(Switch::SlipY) && mode.sy == Slip::Stick;
            if !(stuck_x || stuck_y) {
                continue;
            }
            let link = c.link();
            let geom = self.geometry(c, pose);
            if geom.depth <= 0.0 {
                continue;
            }
            let jac_e: SMatrix<f64, 2, N> = self.mechanism.jacobian(pose, link, geom.centroid);
            let omega = qd[2 + link];
            // E moves over the link: d/dt v_E = J qddot + bias + omega dR/dq r_E'.
            let r_rate = self.centroid_local_rate(c, pose, q, qd, &geom);
            let slide = r_rate.x * pose.normal[link] - r_rate.y * pose.axis[link];
            let a_bias = self
                .mechanism
                .point_bias_acceleration(pose, link, geom.centroid, qd)
                + omega * slide;
            let p = self.application_point(c, geom.centroid);
            for (k, on) in [(0usize, stuck_x), (1usize, stuck_y)] {
                if !on {
                    continue;
                }
                let u = unit(k);
                let mut gen = SVector::<f64, N>::zeros();
                self.mechanism.add_point_force(pose, link, p, u, &mut gen);
                rows.push(Row {
                    kind: RowKind::Stick {
                        contact: ci,
                        axis: k,
                    },
                    jac: (u.transpose() * jac_e).transpose(),
                    bias: u.dot(&a_bias),
                    response: chol.solve(&gen),
                });
            }
        }
        rows
    }

    /// Solve for the multipliers of the locked joints and the sticking components (each
    /// sticking component's static term becomes the reaction that holds its velocity at
    /// zero) and correct the accelerations.
    #[allow(clippy::too_many_arguments)]
    fn solve_constraints(
        &self,
        pose: &Pose<N>,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
        chol: &nalgebra::Cholesky<f64, nalgebra::Const<N>>,
        qdd: &mut SVector<f64, N>,
        contacts: &mut [ContactEval; MAX_CONTACTS],
        joint_torque: &mut [f64; N],
    ) {
        let rows = self.constraint_rows(pose, q, qd, modes, chol);
        apply_rows(&rows, qdd, contacts, joint_torque, &self.forces);
    }

    /// Project `qd` so that every sticking component's velocity (and every locked joint's
    /// rate) is zero, with the smallest change in kinetic energy (an M-orthogonal
    /// projection). Returns whether it changed.
    pub fn project_sticking(
        &self,
        q: &SVector<f64, N>,
        qd: &mut SVector<f64, N>,
        modes: &Modes,
    ) -> bool {
        if !self.any_stuck(modes) {
            return false;
        }
        if let Some(rod) = self.rigid_rod() {
            return self.project_rigid_rod(rod, q, qd, &modes[0]);
        }
        self.project_sticking_general(q, qd, modes)
    }

    /// Whether [`Model::project_sticking`] may change the rates of the state that `e`
    /// evaluated in `modes`. False when there is nothing stuck, and for a single rigid rod
    /// whose stuck components of v_E are exactly zero in `e`: the projection's right-hand
    /// side is those very components (the same products, bitwise), so it would solve for
    /// zero multipliers and leave the rates as they are.
    #[inline]
    pub fn sticking_may_drift(&self, e: &Eval<N>, modes: &Modes) -> bool {
        if !self.any_stuck(modes) {
            return false;
        }
        if self.rigid_rod().is_none() {
            return true;
        }
        let (mode, v_e) = (&modes[0], e.contacts[0].v_centroid);
        (self.forces.owns(Switch::SlipX) && mode.sx == Slip::Stick && v_e.x != 0.0)
            || (self.forces.owns(Switch::SlipY) && mode.sy == Slip::Stick && v_e.y != 0.0)
    }

    /// [`Model::project_sticking`] for any body (after the `any_stuck` check).
    fn project_sticking_general(
        &self,
        q: &SVector<f64, N>,
        qd: &mut SVector<f64, N>,
        modes: &Modes,
    ) -> bool {
        let pose = self.mechanism.pose(q);
        let mass = self.mechanism.mass_matrix(&pose);
        let chol = match mass.cholesky() {
            Some(c) => c,
            None => return false,
        };
        let rows = self.constraint_rows(&pose, q, qd, modes, &chol);
        project_rows(&rows, qd, |v| chol.solve(v))
    }

    /// Force each link receives at its joint from its parent (or the root) [N], from the
    /// accelerations of an evaluation (see [`Mechanism::joint_forces`]).
    pub fn joint_forces(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        e: &Eval<N>,
        modes: &Modes,
    ) -> [Vector2<f64>; N] {
        let pose = self.mechanism.pose(q);
        let mut external = [Vector2::zeros(); N];
        for (ci, c) in self.contacts.iter().enumerate() {
            if modes[ci].in_contact {
                external[c.link()] += e.contacts[ci].force.total();
            }
        }
        let g = self.gravity();
        self.mechanism.joint_forces(&pose, qd, &e.qdd, g, &external)
    }

    /// Kinetic and potential energy at `(q, qd)` [J]; the potential energy is gravity's
    /// (while the `gravity` term acts) plus the joints' springs' (while `joint_springs`
    /// acts).
    pub fn energies(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> (f64, f64) {
        let pose = self.mechanism.pose(q);
        let springs = if self.forces.joint_springs {
            self.mechanism.spring_energy(q)
        } else {
            0.0
        };
        (
            self.mechanism.kinetic_energy(&pose, qd),
            self.mechanism.potential_energy(&pose, self.gravity()) + springs,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::FreeLinkScene;
    use proptest::prelude::*;

    fn slip(i: u8) -> Slip {
        [Slip::Neg, Slip::Pos, Slip::Stick][i as usize % 3]
    }

    fn close(a: f64, b: f64, scale: f64) -> bool {
        (a - b).abs() <= 1e-13 * scale.max(a.abs()).max(b.abs())
    }

    /// The thesis's terms at Table 3.4's q = 0 row, those of `mask` only (bits: gravity,
    /// drag, static_h, static_v), on `n` contacts.
    pub(crate) fn thesis_subset(mask: u8, n: usize) -> ForceSet {
        use crate::forces::TermSpec;
        let all = [
            TermSpec::new("gravity", &[]),
            TermSpec::new("drag", &[("eta_d", 15.2)]),
            TermSpec::new("static_h", &[("eta_h", 6.5)]),
            TermSpec::new("static_v", &[("eta_v", 248.0), ("lam", 0.106)]),
        ];
        let specs: Vec<TermSpec> = all
            .into_iter()
            .enumerate()
            .filter(|(i, _)| mask & (1 << i) != 0)
            .map(|(_, t)| t)
            .collect();
        ForceSet::build(&specs, n).unwrap()
    }

    proptest! {
        /// The free link's closed-form evaluation (`eval_rigid_rod`) is the general engine's
        /// (`eval_general`) to round-off, for every sign model, point of application, mode,
        /// term switched off, and a point mass at the root.
        #[test]
        fn rigid_rod_path_is_the_general_engine(
            x in -0.1f64..0.1, y in -0.12f64..0.12, th in -1.55f64..1.55,
            vx in -3.0f64..3.0, vy in -3.0f64..3.0, w in -30.0f64..30.0,
            sign in 0u8..3, centroid in any::<bool>(), in_contact in any::<bool>(),
            sx in 0u8..3, sy in 0u8..3, cross in 0u8..2, effects in 0u8..16,
            root_mass in prop_oneof![Just(0.0f64), Just(0.05f64)],
        ) {
            let mut model = FreeLinkScene {
                apply_at: if centroid { ApplyAt::Centroid } else { ApplyAt::Tip },
                sign_model: [
                    SignModel::Modes,
                    SignModel::Raw,
                    SignModel::Smooth { eps: 1e-3 },
                ][sign as usize],
                ..Default::default()
            }
            .model();
            model.mechanism.root_mass = root_mass;
            model.forces = thesis_subset(effects, 1);
            let rod = model.rigid_rod().copied();
            prop_assert!(rod.is_some());
            let mut modes: Modes = [ContactMode::default(); MAX_CONTACTS];
            modes[0] = ContactMode {
                in_contact,
                sx: slip(sx),
                sy: slip(sy),
                cross: slip(cross),
                ..ContactMode::default()
            };
            let q = SVector::<f64, 3>::new(x, y, th);
            let qd = SVector::<f64, 3>::new(vx, vy, w);
            let a = model.eval(&q, &qd, &modes);
            prop_assert!(model.rigid_rod().is_some());
            let mut a_into = model.eval(&q, &qd, &modes);
            a_into.qdd *= 2.0;
            a_into.contacts[0].depth = -1.0;
            model.eval_into(&q, &qd, &modes, &mut a_into);
            prop_assert_eq!(a.qdd, a_into.qdd);
            prop_assert_eq!(a.contacts, a_into.contacts);
            let (qdd, power, joint_power) = model.rates(&q, &qd, &modes);
            prop_assert_eq!((qdd, power, joint_power), (a.qdd, a.power, a.joint_power));
            let b = model.eval_general(&q, &qd, &modes);
            let scale = b.qdd.amax().max(model.medium.g);
            // The angular acceleration is a force times a lever over I = m L^2 / 12: its
            // round-off scale is that of the linear ones times 12 / L (seen: 3.6e-12 rad/s^2
            // against 0 for a stuck rod at rest, where the linear scale gave 1e-12).
            let length = 0.19;
            for i in 0..3 {
                let s = if i == 2 { scale * 12.0 / length } else { scale };
                prop_assert!(close(a.qdd[i], b.qdd[i], s), "qdd {:?} vs {:?}", a.qdd, b.qdd);
            }
            // Power is a force times a speed: its round-off scale is m a |v| (seen: 4e-14 W
            // against 0 with an absolute scale of 1e-12).
            let p_scale = FreeLinkScene::default().mass * scale * qd.amax() * (1.0 + length);
            prop_assert!(close(a.power, b.power, p_scale.max(1e-12)), "{} vs {}", a.power, b.power);
            let (ca, cb) = (&a.contacts[0], &b.contacts[0]);
            let pairs = [
                (ca.tip.x, cb.tip.x), (ca.tip.y, cb.tip.y), (ca.v_tip.x, cb.v_tip.x),
                (ca.v_tip.y, cb.v_tip.y), (ca.depth, cb.depth), (ca.lowest, cb.lowest),
                (ca.v_centroid.x, cb.v_centroid.x), (ca.v_centroid.y, cb.v_centroid.y),
                (ca.force.dynamic.x, cb.force.dynamic.x), (ca.force.dynamic.y, cb.force.dynamic.y),
                (ca.force.statics.x, cb.force.statics.x), (ca.force.statics.y, cb.force.statics.y),
                (ca.cross, cb.cross), (ca.immersion_margin, cb.immersion_margin),
                (ca.bound[0], cb.bound[0]), (ca.bound[1], cb.bound[1]),
            ];
            // A sticking reaction (fields 10, 11) solves for what holds E against every
            // force on the body: its round-off scale is the body's m a (seen: 1.1e-16 N on
            // a 8.7e-4 N reaction of a rod stuck both ways, against m g = 1.8 N).
            let f_scale = (model.mechanism.links[0].mass + root_mass) * scale;
            for (i, (u, v)) in pairs.into_iter().enumerate() {
                let s = if i == 10 || i == 11 { f_scale } else { 1e-12 };
                prop_assert!(close(u, v, s), "field {i}: {u} vs {v}");
            }
            prop_assert_eq!(&a.contacts[1..], &b.contacts[1..]);
        }
    }

    proptest! {
        /// The rod's closed-form projection onto its sticking rows is the general one; and
        /// where `sticking_may_drift` lets the solver skip it (`exact`: no spin, no drift),
        /// it would have changed nothing.
        #[test]
        fn rigid_rod_projection_is_the_general_engine(
            th in -1.5f64..1.5, depth in 0.001f64..0.1, vy in -3.0f64..3.0,
            w in -30.0f64..30.0, drift in -5e-7f64..5e-7, sx in 0u8..3, sy in 0u8..3,
            exact in any::<bool>(),
        ) {
            let (w, drift) = if exact { (0.0, 0.0) } else { (w, drift) };
            let model = FreeLinkScene::default().model();
            let mut modes: Modes = [ContactMode::default(); MAX_CONTACTS];
            modes[0] = ContactMode {
                in_contact: true,
                sx: slip(sx),
                sy: slip(sy),
                ..ContactMode::default()
            };
            // The tip `depth` deep; v_E within `drift` of zero along each stuck axis.
            let half = 0.5 * model.contacts[0].reference_point().x.abs();
            let q = SVector::<f64, 3>::new(0.0, half * th.cos() - depth, th);
            let mut qd = SVector::<f64, 3>::new(0.0, vy, w);
            let v_e = model.eval_general(&q, &qd, &modes).contacts[0].v_centroid;
            if modes[0].sx == Slip::Stick {
                qd[0] -= v_e.x - drift;
            }
            if modes[0].sy == Slip::Stick {
                qd[1] -= v_e.y + drift;
            }
            let (mut a, mut b) = (qd, qd);
            let changed_a = model.project_sticking(&q, &mut a, &modes);
            let changed_b = model.any_stuck(&modes)
                && model.project_sticking_general(&q, &mut b, &modes);
            prop_assert_eq!(changed_a, changed_b);
            for i in 0..3 {
                prop_assert!(close(a[i], b[i], 1e-9), "{a:?} vs {b:?}");
            }
            if !model.sticking_may_drift(&model.eval(&q, &qd, &modes), &modes) {
                prop_assert!(!changed_a && a == qd, "skipped a projection: {qd:?} to {a:?}");
            }
        }
    }

    /// Any other body keeps the general engine.
    #[test]
    fn centroid_inverse_mass_of_a_rod_and_of_a_locked_chain() {
        // A free rod at q = 0.3 with its tip 0.05 m deep: E is l/2 above the tip, at
        // r = L/2 - l/2 from the centre; the trace is 2/m + r^2/I.
        let model = FreeLinkScene::default().model();
        let link = &model.mechanism.links[0];
        let (m, inertia, big_l) = (link.mass, link.inertia, 0.19);
        let q0: f64 = 0.3;
        let depth = 0.05;
        let y = -depth + 0.5 * big_l * q0.cos();
        let w = model.centroid_inverse_mass(&SVector::<f64, 3>::new(0.0, y, q0), 0);
        // E = centre - r e; its velocity per unit force: 1/m + (r e_perp)(r e_perp)^T / I.
        let r = 0.5 * big_l - 0.5 * depth / q0.cos();
        let lever = Vector2::new(q0.cos(), -q0.sin()) * r;
        let expected = Matrix2::identity() / m + lever * lever.transpose() / inertia;
        assert!(
            (w - expected).norm() < 1e-9 * expected.norm(),
            "{w} {expected}"
        );
        // A chain: locking the pin can only make the tip's E heavier.
        use crate::body::mechanism::Joint;
        use crate::scene::ChainScene;
        let q = SVector::<f64, 4>::new(0.0, 0.0, 0.2, 0.5);
        let free = ChainScene {
            joint: Joint::Free,
            ..ChainScene::default()
        }
        .model();
        let locked = ChainScene {
            joint: Joint::Locked,
            ..ChainScene::default()
        }
        .model();
        let last = free.contacts.len() - 1;
        let (wf, wl) = (
            free.centroid_inverse_mass(&q, last),
            locked.centroid_inverse_mass(&q, last),
        );
        let (tl, tf) = (wl.trace(), wf.trace());
        assert!(tl.is_finite() && tl > 0.0 && tl < tf, "{wl} {wf}");
        assert!(wl.symmetric_eigenvalues().min() >= -1e-12 * tl, "{wl}");
    }

    #[test]
    fn only_a_rod_about_its_centre_of_mass_is_closed_form() {
        let mut model = FreeLinkScene::default().model();
        assert!(model.rigid_rod().is_some());
        model.mechanism.links[0].com = Vector2::new(0.01, 0.0);
        assert!(model.rigid_rod().is_none());
    }
}
