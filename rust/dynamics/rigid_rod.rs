//! The free link's fast path: a single rigid rod whose root is its centre of mass has a
//! constant, diagonal mass matrix `M = diag(m + m_root, m + m_root, I)` and no velocity
//! products, so its accelerations, sticking reactions and projection are in closed form (one
//! `sin_cos` per evaluation). A mechanics specialization, not a second copy of the force
//! law: the forces come from the same [`terms_on`](super::terms_on) as every body's (through
//! [`Model::apply_terms`]), and the tests hold it to the general engine to round-off.

use nalgebra::{SVector, Vector2};

use super::constraints::solve_upto2;
use super::{
    held_shift, ContactEval, ContactForce, ContactMode, Model, Modes, Shape, SignModel, Slip,
    PROJECTION_LIMIT,
};
use crate::body::rod::ApplyAt;
use crate::body::{RodContact, RodGeometry};
use crate::forces::drag::Drag;
use crate::forces::static_h::StaticH;
use crate::forces::static_v::StaticV;
use crate::forces::{
    AnyTerm, Boundary, Class, ContactState, Frame, Outline, Switch, Term, TermForce, TermInfo,
};

/// Position and velocity of a single rigid rod whose root is its centre of mass: what
/// [`Model::eval_rigid_rod`] and its constraints need (one `sin_cos` per evaluation, libm's,
/// as the lanes call it lane by lane).
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

/// One contact term's force added into `out` and `bound` as [`terms_on`](super::terms_on)
/// adds it: its own slot, its class's sum, the sticking bounds.
#[inline(always)]
fn add_term(
    k: usize,
    dynamic: bool,
    tf: TermForce<f64>,
    out: &mut ContactForce,
    bound: &mut [f64; 2],
) {
    let v = Vector2::new(tf.force[0], tf.force[1]);
    out.terms[k] = v;
    if dynamic {
        out.dynamic += v;
    } else {
        out.statics += v;
    }
    bound[0] += tf.bound[0];
    bound[1] += tf.bound[1];
}

/// The sticking reactions of one evaluation: (axis, reaction [N]) per row.
#[derive(Debug, Clone, Copy)]
struct Reactions {
    len: usize,
    rows: [(usize, f64); 2],
}

impl<const N: usize> Model<N> {
    /// The rod contact of a single free link with its centre of mass at the root (no
    /// parent, one rod contact on it), or `None` for any other body.
    #[inline]
    pub(super) fn rigid_rod(&self) -> Option<&RodContact> {
        if N != 3
            || self.mechanism.links.len() != 1
            || self.contacts.len() != 1
            || self.mechanism.root_fixed
            || self.mechanism.root_rate.is_some()
        {
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

    /// [`Model::apply_terms`] of the rod's contact, with the thesis's set (`drag`, `static_h`,
    /// `static_v`, in the order [`ForceSet::thesis`](crate::forces::ForceSet::thesis) lists
    /// them) unrolled: the same terms and the same sums in the same order as
    /// [`terms_on`](super::terms_on), with each class known at compile time and no dispatch
    /// between the terms, so that their arithmetic (the one `pow`) overlaps. Any other set
    /// takes [`Model::apply_terms`].
    #[inline(always)]
    pub(super) fn rigid_rod_terms(&self, state: &ContactState<f64>, out: &mut ContactEval) {
        if let [AnyTerm::Drag(d), AnyTerm::StaticH(h), AnyTerm::StaticV(v)] =
            self.forces.per_contact[0][..]
        {
            let m = &self.medium;
            let (fd, fh, fv) = (
                d.contact_force(state, m),
                h.contact_force(state, m),
                v.contact_force(state, m),
            );
            let dynamic = |info: &TermInfo| info.class == Class::Dynamic;
            let f = &mut out.force;
            f.dynamic = Vector2::zeros();
            f.statics = Vector2::zeros();
            f.moment = 0.0;
            out.bound = [0.0; 2];
            add_term(0, dynamic(&Drag::INFO), fd, f, &mut out.bound);
            add_term(1, dynamic(&StaticH::INFO), fh, f, &mut out.bound);
            add_term(2, dynamic(&StaticV::INFO), fv, f, &mut out.bound);
            return;
        }
        self.apply_terms(0, state, out);
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
    #[inline(always)]
    pub(super) fn eval_rigid_rod(
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
        // Terms that read the frame are evaluated from the moment of entry: a `poncelet`
        // drag or a plate's `rft_inertial` is finite at depth 0 (the entry is a jump).
        let forced = mode.in_contact && (geom.depth > 0.0 || self.forces.reads_frame);
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
            let p_local = self.application_point(&self.contacts[0], centroid);
            let sign = self.signs(mode, v_e);
            let boundary = if self.forces.reads_frame {
                let shift = held_shift(
                    sign,
                    v_e,
                    [
                        self.forces.owns(Switch::SlipX),
                        self.forces.owns(Switch::SlipY),
                    ],
                );
                let v_held = v_tip + shift;
                let v_e_held = v_e + shift;
                let (apply, e) = (fr.at(p_local), fr.at(centroid));
                Some(Boundary {
                    frame: Frame {
                        origin: [tip.x, tip.y],
                        v: [v_held.x, v_held.y],
                        // q turns clockwise (e = (sin q, cos q)): omega = -dq/dt.
                        omega: -fr.omega,
                        axis: [fr.axis.x, fr.axis.y],
                    },
                    outline: Outline::Rod {
                        diameter: rod.diameter,
                        immersed: geom.immersed_length,
                    },
                    apply: [apply.x, apply.y],
                    centroid: [e.x, e.y],
                    v_centroid: [v_e_held.x, v_e_held.y],
                    held: self.held_axes(mode),
                })
            } else {
                None
            };
            let state = ContactState {
                depth: geom.depth,
                volume: rod.immersed_volume(&geom),
                width: rod.diameter,
                l_ref: rod.length,
                v: [v_e.x, v_e.y],
                area_speed,
                sign,
                boundary: boundary.as_ref(),
            };
            self.rigid_rod_terms(&state, out);
            let total = out.force.total();
            gen[0] += total.x;
            gen[1] += total.y;
            // A counter-clockwise moment does work -M dq.
            gen[2] += total.dot(&fr.lever(p_local)) - out.force.moment;
        }
        // M^-1 by multiplication: the divisions are off the force's path and overlap it.
        let (inv_m, inv_i) = self.rigid_rod_inverse_mass_parts();
        let mut qdd = SVector::<f64, N>::zeros();
        qdd[0] = gen[0] * inv_m;
        qdd[1] = gen[1] * inv_m;
        qdd[2] = gen[2] * inv_i;
        if forced && self.sign_model == SignModel::Modes && self.stuck(mode) {
            // The reactions come back by value: `out` does not escape, so that a Runge-Kutta
            // stage (which reads only the rates) drops the findings it never reads.
            let reactions =
                self.rigid_rod_reactions(rod, &fr, &geom, v_tip, mode, (inv_m, inv_i), &mut qdd);
            for &(axis, mult) in &reactions.rows[..reactions.len] {
                // Through a copy: `out` itself is never borrowed past this function.
                let mut force = out.force;
                force.set_reaction(&self.forces, axis, mult);
                out.force = force;
            }
        }
        let joint_torque = [0.0; N];
        let power = if forced {
            let v_p = match self.apply_at {
                ApplyAt::Tip => out.v_tip,
                ApplyAt::Centroid => out.v_centroid,
            };
            out.force.total().dot(&v_p) - out.force.moment * fr.omega
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
    /// correct `qdd`, and return the reactions (each stands in place of its static term). E
    /// moves over the rod at half the rate of the immersed length, which the rows' bias holds.
    /// Inlined: the vertical drop sticks in x at every evaluation (measured: its impact 4 %
    /// faster than through a call, the other rows level).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn rigid_rod_reactions(
        &self,
        rod: &RodContact,
        fr: &RodFrame,
        geom: &RodGeometry,
        v_tip: Vector2<f64>,
        mode: &ContactMode,
        (inv_m, inv_i): (f64, f64),
        qdd: &mut SVector<f64, N>,
    ) -> Reactions {
        let mut reactions = Reactions {
            len: 0,
            rows: [(0, 0.0); 2],
        };
        let stick = self.rigid_rod_stick(rod, fr, geom, mode);
        let centroid = Vector2::new(geom.centroid_s, rod.tip.y);
        // Without spin (the vertical drop) the bias is zero: skip E's sliding rate (two
        // divisions) that it would multiply by zero.
        let a_bias = if fr.omega == 0.0 {
            Vector2::zeros()
        } else {
            let l_rate = rod.immersed_length_rate(geom, fr.axis, -v_tip.y, -fr.axis.x * fr.omega);
            let slide = (0.5 * l_rate) * fr.normal;
            -(fr.omega * fr.omega) * (centroid.x * fr.axis + centroid.y * fr.normal)
                + fr.omega * slide
        };
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
                reactions.rows[0] = (axis, mult);
                reactions.len = 1;
                return reactions;
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
            reactions.rows[i] = (axis, mult);
        }
        reactions.len = k;
        reactions
    }

    /// [`Model::project_sticking`] of a single rigid rod ([`project_rows`] in closed form).
    pub(super) fn project_rigid_rod(
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
}
