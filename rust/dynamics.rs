//! The equations of motion of a body in sand: a [`Mechanism`], its rod contacts, the
//! medium and the force terms a scene asks for, evaluated for a given set of discrete
//! modes (in contact or not; the sign of each static term, or sticking).
//!
//! `M(q) qddot = bias(q, qdot) + sum_c J_Pc^T F_c`, with `F_c` the resistance force of
//! contact `c` (see `force::resistance`) applied at its point `P_c` (tip or centroid).
//!
//! Sticking (MODEL.md, "sgn"): where a static term holds a velocity component of the
//! centroid E at zero, that term becomes a reaction `R` (along x or y, at `P_c`) chosen so
//! that the component's rate of change is zero, as in stick-slip friction (Karnopp). The
//! solver keeps the stick while `|R|` stays below the static term's magnitude.

use nalgebra::{DMatrix, DVector, SMatrix, SVector, Vector2};

use crate::body::rod::ApplyAt;
use crate::body::{Mechanism, RodContact};
use crate::force::resistance::{raw_sign, static_bounds};
use crate::force::{Coefficients, ForceComponents, Medium, RodContactState};

/// Largest sticking-velocity violation [m/s] that the projection treats as drift.
pub const PROJECTION_LIMIT: f64 = 1e-6;

/// Most contacts a body may have.
pub const MAX_CONTACTS: usize = 4;

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
    /// Sign of e x v_E held through a step: the drag's reference area is |e x v_E|, whose
    /// kink where v_E is parallel to the axis is a located event in the `Modes` model.
    pub cross: Slip,
    /// Whether the rod is wholly immersed (l = L): the kink of l = min(d / cos q, L) is a
    /// located event too, so that a step never straddles it.
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

/// Which force terms a scene evaluates. A term that is off is neither computed nor stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Effects {
    /// Gravity on the body.
    pub gravity: bool,
    /// Dynamic drag F_d.
    pub drag: bool,
    /// Static horizontal term F_sh.
    pub static_h: bool,
    /// Static vertical term F_sv.
    pub static_v: bool,
}

impl Default for Effects {
    fn default() -> Self {
        Effects {
            gravity: true,
            drag: true,
            static_h: true,
            static_v: true,
        }
    }
}

/// One contact of a body with its coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Geometry: which link, where the tip is, rod length and diameter.
    pub rod: RodContact,
    /// Coefficients of the force law for this contact.
    pub coefficients: Coefficients,
}

/// A body in sand: everything the right-hand side needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Model<const N: usize> {
    /// The rigid links.
    pub mechanism: Mechanism<N>,
    /// The contacts (at most [`MAX_CONTACTS`]).
    pub contacts: Vec<Contact>,
    /// The sand.
    pub medium: Medium,
    /// Point of application of the resistance force.
    pub apply_at: ApplyAt,
    /// Sign model of the static terms.
    pub sign_model: SignModel,
    /// Which force terms are on.
    pub effects: Effects,
}

/// What one evaluation finds at one contact.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactEval {
    /// Tip position [m].
    pub tip: Vector2<f64>,
    /// Tip velocity [m/s].
    pub v_tip: Vector2<f64>,
    /// Depth of the tip [m].
    pub depth: f64,
    /// Velocity of the material point at the immersed centroid E [m/s].
    pub v_centroid: Vector2<f64>,
    /// Force components (with any sticking reaction in place of its static term) [N].
    pub force: ForceComponents,
    /// e x v_E, the signed sine of the drag's reference area times |v_E| [m/s].
    pub cross: f64,
    /// Margin to full immersion, L cos q - d [m] (negative when wholly immersed).
    pub immersion_margin: f64,
    /// Magnitudes of the static terms (the bounds of a sticking reaction) [N].
    pub bound_h: f64,
    /// See `bound_h`.
    pub bound_v: f64,
}

/// The result of one right-hand-side evaluation.
#[derive(Debug, Clone, Copy)]
pub struct Eval<const N: usize> {
    /// Generalized accelerations.
    pub qdd: SVector<f64, N>,
    /// Power of the sand's forces on the body, sum_c F_c . v_Pc [W] (non-positive at E).
    pub power: f64,
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

/// A sticking component: contact, axis, and what the solve needs of it.
struct StuckRow<const N: usize> {
    contact: usize,
    axis: usize,
    /// Row of the constraint `u . v_E = jac_e . qdot`.
    jac_e: SVector<f64, N>,
    /// `u . (velocity-product acceleration of E + sliding of E along the link)`.
    bias: f64,
    /// `M^-1 J_P^T u`: the accelerations caused by a unit reaction.
    response: SVector<f64, N>,
}

impl<const N: usize> Model<N> {
    /// The local (s, n) coordinates of the point where contact `c`'s force acts.
    #[inline]
    fn application_point(&self, c: &Contact, centroid_s: f64) -> Vector2<f64> {
        match self.apply_at {
            ApplyAt::Tip => c.rod.tip,
            ApplyAt::Centroid => Vector2::new(centroid_s, c.rod.tip.y),
        }
    }

    /// Evaluate the accelerations and the per-contact forces at `(q, qd)` in `modes`.
    pub fn eval(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>, modes: &Modes) -> Eval<N> {
        let pose = self.mechanism.pose(q);
        let g = if self.effects.gravity {
            self.medium.g
        } else {
            0.0
        };
        let mut rhs = self.mechanism.bias_forces(&pose, qd, g);
        let mut contacts = [ContactEval::default(); MAX_CONTACTS];
        let mut any_stuck = false;
        for (ci, c) in self.contacts.iter().enumerate() {
            let link = c.rod.link;
            let tip = self.mechanism.point(&pose, link, c.rod.tip);
            let v_tip = self.mechanism.point_velocity(&pose, link, c.rod.tip, qd);
            let out = &mut contacts[ci];
            out.tip = tip;
            out.v_tip = v_tip;
            // With nothing immersed, E is the tip.
            out.v_centroid = v_tip;
            let mode = &modes[ci];
            if !mode.in_contact {
                continue;
            }
            let axis = pose.axis[link];
            let geom = c.rod.geometry(tip.y, axis);
            out.depth = geom.depth;
            out.immersion_margin = c.rod.length * axis.y - geom.depth;
            if geom.depth <= 0.0 {
                continue;
            }
            let e_local = Vector2::new(geom.centroid_s, c.rod.tip.y);
            let v_e = self.mechanism.point_velocity(&pose, link, e_local, qd);
            out.v_centroid = v_e;
            let state = RodContactState {
                depth: geom.depth,
                immersed_length: geom.immersed_length,
                axis,
                v_centroid: v_e,
            };
            let (sx, sy) = match self.sign_model {
                SignModel::Modes => (mode.sx.sign(), mode.sy.sign()),
                SignModel::Raw => (raw_sign(v_e.x), raw_sign(v_e.y)),
                SignModel::Smooth { eps } => ((v_e.x / eps).tanh(), (v_e.y / eps).tanh()),
            };
            let coef = &c.coefficients;
            let (bh, bv) = static_bounds(
                coef,
                &self.medium,
                c.rod.diameter,
                c.rod.diameter,
                c.rod.length,
                &state,
            );
            let mut f = ForceComponents::default();
            let cross_signed = axis.x * v_e.y - axis.y * v_e.x;
            out.cross = cross_signed;
            if self.effects.drag {
                // |e x v_E|; in `Modes` the sign is held (the kink at 0 is a located event).
                let cross = match self.sign_model {
                    SignModel::Modes if mode.cross == Slip::Neg => -cross_signed,
                    SignModel::Modes => cross_signed,
                    _ => cross_signed.abs(),
                };
                let k =
                    coef.eta_d * self.medium.rho_g * c.rod.diameter * geom.immersed_length * cross;
                f.drag = -k * v_e;
            }
            if self.effects.static_h {
                out.bound_h = bh;
                f.static_h = -sx * bh;
            }
            if self.effects.static_v {
                out.bound_v = bv;
                f.static_v = -sy * bv;
            }
            out.force = f;
            if self.sign_model == SignModel::Modes
                && ((self.effects.static_h && mode.sx == Slip::Stick)
                    || (self.effects.static_v && mode.sy == Slip::Stick))
            {
                any_stuck = true;
            }
            let p = self.application_point(c, geom.centroid_s);
            self.mechanism
                .add_point_force(&pose, link, p, f.total(), &mut rhs);
        }
        let mass = self.mechanism.mass_matrix(&pose);
        let chol = mass
            .cholesky()
            .expect("mass matrix of positive masses is positive definite");
        let mut qdd = chol.solve(&rhs);
        if any_stuck {
            self.solve_sticking(&pose, q, qd, modes, &chol, &mut qdd, &mut contacts);
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
            contacts,
        }
    }

    /// Rows of the sticking constraints in force under `modes` at this configuration.
    fn stuck_rows(
        &self,
        pose: &crate::body::mechanism::Pose<N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
        chol: &nalgebra::Cholesky<f64, nalgebra::Const<N>>,
    ) -> Vec<StuckRow<N>> {
        let mut rows = Vec::new();
        for (ci, c) in self.contacts.iter().enumerate() {
            let mode = &modes[ci];
            if !mode.in_contact {
                continue;
            }
            let link = c.rod.link;
            let axis = pose.axis[link];
            let tip = self.mechanism.point(pose, link, c.rod.tip);
            let geom = c.rod.geometry(tip.y, axis);
            if geom.depth <= 0.0 {
                continue;
            }
            let e_local = Vector2::new(geom.centroid_s, c.rod.tip.y);
            let jac_e: SMatrix<f64, 2, N> = self.mechanism.jacobian(pose, link, e_local);
            let v_tip = self.mechanism.point_velocity(pose, link, c.rod.tip, qd);
            let omega = qd[2 + link];
            // E slides along the link as l changes: d(s_E)/dt = l'/2.
            let l_rate = c
                .rod
                .immersed_length_rate(&geom, axis, -v_tip.y, -axis.x * omega);
            let a_bias = self
                .mechanism
                .point_bias_acceleration(pose, link, e_local, qd)
                + omega * pose.normal[link] * (0.5 * l_rate);
            let p = self.application_point(c, geom.centroid_s);
            for (k, slip, on) in [
                (0usize, mode.sx, self.effects.static_h),
                (1usize, mode.sy, self.effects.static_v),
            ] {
                if !on || slip != Slip::Stick {
                    continue;
                }
                let u = unit(k);
                let mut gen = SVector::<f64, N>::zeros();
                self.mechanism.add_point_force(pose, link, p, u, &mut gen);
                rows.push(StuckRow {
                    contact: ci,
                    axis: k,
                    jac_e: (u.transpose() * jac_e).transpose(),
                    bias: u.dot(&a_bias),
                    response: chol.solve(&gen),
                });
            }
        }
        rows
    }

    /// Replace the static term of each sticking component by the reaction that holds its
    /// velocity component at zero (d/dt (u . v_E) = 0), and correct the accelerations.
    #[allow(clippy::too_many_arguments)]
    fn solve_sticking(
        &self,
        pose: &crate::body::mechanism::Pose<N>,
        _q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
        chol: &nalgebra::Cholesky<f64, nalgebra::Const<N>>,
        qdd: &mut SVector<f64, N>,
        contacts: &mut [ContactEval; MAX_CONTACTS],
    ) {
        let rows = self.stuck_rows(pose, qd, modes, chol);
        let k = rows.len();
        if k == 0 {
            return;
        }
        let mut a = DMatrix::<f64>::zeros(k, k);
        let mut b = DVector::<f64>::zeros(k);
        for (i, ri) in rows.iter().enumerate() {
            b[i] = -(ri.bias + ri.jac_e.dot(qdd));
            for (j, rj) in rows.iter().enumerate() {
                a[(i, j)] = ri.jac_e.dot(&rj.response);
            }
        }
        let reactions = match a.clone().lu().solve(&b) {
            Some(r) => r,
            None => a.pseudo_inverse(1e-14).map(|p| p * &b).unwrap_or(b * 0.0),
        };
        for (i, r) in rows.iter().enumerate() {
            *qdd += reactions[i] * r.response;
            let ce = &mut contacts[r.contact];
            if r.axis == 0 {
                ce.force.static_h = reactions[i];
            } else {
                ce.force.static_v = reactions[i];
            }
        }
    }

    /// Project `qd` so that every sticking component's velocity is zero, with the smallest
    /// change in kinetic energy (an M-orthogonal projection). Returns whether it changed.
    pub fn project_sticking(
        &self,
        q: &SVector<f64, N>,
        qd: &mut SVector<f64, N>,
        modes: &Modes,
    ) -> bool {
        if self.sign_model != SignModel::Modes {
            return false;
        }
        let any = self.contacts.iter().enumerate().any(|(ci, _)| {
            let m = &modes[ci];
            m.in_contact
                && ((self.effects.static_h && m.sx == Slip::Stick)
                    || (self.effects.static_v && m.sy == Slip::Stick))
        });
        if !any {
            return false;
        }
        let pose = self.mechanism.pose(q);
        let mass = self.mechanism.mass_matrix(&pose);
        let chol = match mass.cholesky() {
            Some(c) => c,
            None => return false,
        };
        let rows = self.stuck_rows(&pose, qd, modes, &chol);
        let k = rows.len();
        if k == 0 {
            return false;
        }
        // Only drift is removed: a violation larger than this is not drift but a wrong mode,
        // and is left for the solver's switching functions to see.
        if rows
            .iter()
            .any(|r| r.jac_e.dot(qd).abs() > PROJECTION_LIMIT)
        {
            return false;
        }
        // M^-1 J^T columns and J M^-1 J^T.
        let minv_jt: Vec<SVector<f64, N>> = rows.iter().map(|r| chol.solve(&r.jac_e)).collect();
        let mut a = DMatrix::<f64>::zeros(k, k);
        let mut b = DVector::<f64>::zeros(k);
        for i in 0..k {
            b[i] = rows[i].jac_e.dot(qd);
            for j in 0..k {
                a[(i, j)] = rows[i].jac_e.dot(&minv_jt[j]);
            }
        }
        match a.lu().solve(&b) {
            Some(lam) if lam.iter().any(|&l| l != 0.0) => {
                for i in 0..k {
                    *qd -= lam[i] * minv_jt[i];
                }
                true
            }
            _ => false,
        }
    }

    /// Kinetic and potential energy at `(q, qd)` [J].
    pub fn energies(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> (f64, f64) {
        let pose = self.mechanism.pose(q);
        (
            self.mechanism.kinetic_energy(&pose, qd),
            self.mechanism.potential_energy(&pose, self.medium.g),
        )
    }
}
