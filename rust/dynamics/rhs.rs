//! The right-hand side of every body: geometry -> terms -> constraints.
//!
//! For each contact in the sand: its immersed geometry ([`Geometry`]), the velocity of its
//! immersed centroid E, the force terms on it ([`terms_on`], the one evaluation of the force
//! law) and their generalized force through the Jacobian of the point of application; then
//! the mass matrix, its Cholesky factor, and the constraints in force (locked joints,
//! sticking; `constraints.rs`). A single rigid rod about its centre of mass takes the same
//! equations in closed form (`rigid_rod.rs`).

use nalgebra::{SVector, Vector2};

use super::{
    held_shift, raw_sign, terms_on, Contact, ContactEval, ContactMode, DragStiffness, Eval, Model,
    Modes, Shape, SignModel, Slip, MAX_CONTACTS,
};
use crate::body::mechanism::Pose;
use crate::body::rod::ApplyAt;
use crate::body::SoleModel;
use crate::forces::{Boundary, ContactState, Frame, Outline, Rates, Switch};

/// The immersed geometry of one contact, as the force law needs it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Geometry {
    /// Depth of the force law [m].
    pub(super) depth: f64,
    /// Local coordinates of the immersed centroid E.
    pub(super) centroid: Vector2<f64>,
    /// Immersed volume [m^3].
    pub(super) volume: f64,
    /// Width w of the horizontal static term [m].
    pub(super) width: f64,
    /// Reference length of the depth factor [m].
    pub(super) l_ref: f64,
    /// Margin to full immersion [m].
    pub(super) margin: f64,
    /// Lowest point of the shape [m].
    pub(super) lowest: f64,
    /// The axis whose cross product with v_E sets a rod's (or the thesis sole's) drag area.
    pub(super) cross_axis: Vector2<f64>,
    /// Drag factor along `cross_axis`: `A_r |v_E| = factor * |cross_axis x v_E|`, or for the
    /// box `A_r |v_E|` comes from the polygon (`sole`).
    pub(super) factor: f64,
    /// The sole's polygon, for the box drag.
    pub(super) sole: Option<crate::body::SoleGeometry>,
}

impl<const N: usize> Model<N> {
    /// The geometry of contact `c` at `pose` (depth zero when out of the sand).
    pub(super) fn geometry(&self, c: &Contact, pose: &Pose<N>) -> Geometry {
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
            Shape::Arc(arc) => {
                let joint = pose.joint[link];
                let normal = pose.normal[link];
                let g = arc.geometry(joint, axis, normal);
                let rel = g.centroid - joint;
                Geometry {
                    depth: g.depth,
                    centroid: Vector2::new(rel.dot(&axis), rel.dot(&normal)),
                    // A thin arc has no volume; the terms that read it (and A_r, w, L_ref)
                    // are refused on an arc before any work (`ForceSet::check_shapes`).
                    volume: 0.0,
                    width: arc.width,
                    l_ref: arc.radius,
                    margin: g.highest,
                    lowest: g.lowest,
                    cross_axis: axis,
                    factor: 0.0,
                    sole: None,
                }
            }
        }
    }

    /// What the terms that integrate over a contact's boundary read ([`Boundary`]): its
    /// frame (T, v_T, the link's angular velocity, its axis), its outline, the point of
    /// application `p` and the immersed centroid, in world coordinates.
    pub(super) fn boundary(
        &self,
        c: &Contact,
        pose: &Pose<N>,
        qd: &SVector<f64, N>,
        geom: &Geometry,
        p: Vector2<f64>,
    ) -> Boundary<f64> {
        let link = c.link();
        let e = pose.axis[link];
        let t_local = c.reference_point();
        let outline = match &c.shape {
            Shape::Rod(rod) => Outline::Rod {
                diameter: rod.diameter,
                immersed: rod.geometry(-geom.depth, e).immersed_length,
            },
            Shape::Sole(sole) => Outline::Box {
                corners: sole
                    .corners_local()
                    .map(|r| self.mechanism.point(pose, link, r))
                    .map(|w| [w.x, w.y]),
                width: sole.width,
            },
            Shape::Arc(arc) => {
                let centre = self.mechanism.point(pose, link, arc.centre);
                let first = self.mechanism.point(pose, link, arc.vertex(0));
                // phi grows from +s towards +n, the axis turned clockwise: in the world a
                // chord turns the vertex by -span / chords.
                let (sin, cos) = arc.chord_angle().sin_cos();
                Outline::Arc {
                    centre: [centre.x, centre.y],
                    first: [first.x, first.y],
                    turn: [cos, -sin],
                    chords: arc.chords,
                    width: arc.width,
                }
            }
        };
        let tip = self.mechanism.point(pose, link, t_local);
        let v_tip = self.mechanism.point_velocity(pose, link, t_local, qd);
        // The link's angular velocity from two of its points: v(T + e) - v(T) = omega x e.
        let v_ahead =
            self.mechanism
                .point_velocity(pose, link, t_local + Vector2::new(1.0, 0.0), qd);
        let dv = v_ahead - v_tip;
        let w = self.mechanism.point(pose, link, p);
        let centroid = self.mechanism.point(pose, link, geom.centroid);
        Boundary {
            frame: Frame {
                origin: [tip.x, tip.y],
                v: [v_tip.x, v_tip.y],
                omega: e.x * dv.y - e.y * dv.x,
                axis: [e.x, e.y],
            },
            outline,
            apply: [w.x, w.y],
            centroid: [centroid.x, centroid.y],
            v_centroid: [0.0; 2],
            held: [0.0; 2],
        }
    }

    /// Per axis, 1.0 where a sticking reaction holds E's velocity component at zero in
    /// `mode` (`Modes` sign model, a listed term owns the slip switch, the mode sticks).
    #[inline]
    pub(super) fn held_axes(&self, mode: &ContactMode) -> [f64; 2] {
        let held = |switch: Switch, slip: Slip| {
            if self.sign_model == SignModel::Modes
                && self.forces.owns(switch)
                && slip == Slip::Stick
            {
                1.0
            } else {
                0.0
            }
        };
        [held(Switch::SlipX, mode.sx), held(Switch::SlipY, mode.sy)]
    }

    /// Rate of change of E's local coordinates on its link (E moves over the body as the
    /// immersed part grows).
    pub(super) fn centroid_local_rate(
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
            Shape::Sole(_) | Shape::Arc(_) => {
                // Central difference along the motion (the polygon's or the chords' centroid
                // has no simple closed-form rate).
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
    pub(super) fn application_point(&self, c: &Contact, centroid: Vector2<f64>) -> Vector2<f64> {
        match self.apply_at {
            ApplyAt::Tip => c.reference_point(),
            ApplyAt::Centroid => centroid,
        }
    }

    /// The acceleration of gravity on the body [m/s^2]: the field its body terms put on
    /// every mass (the medium's g under `gravity`, zero without it: the body then has no
    /// potential energy from gravity either).
    #[inline(always)]
    pub fn gravity(&self) -> f64 {
        self.forces.field * self.medium.g
    }

    /// The signs of v_Ex and v_Ey that the static terms take in `mode`, by the sign model.
    #[inline(always)]
    pub(super) fn signs(&self, mode: &ContactMode, v_e: Vector2<f64>) -> [f64; 2] {
        match self.sign_model {
            SignModel::Modes => [mode.sx.sign(), mode.sy.sign()],
            SignModel::Raw => [raw_sign(v_e.x), raw_sign(v_e.y)],
            SignModel::Smooth { eps } => [(v_e.x / eps).tanh(), (v_e.y / eps).tanh()],
        }
    }

    /// |e x v_E| as the drag reads it: with its sign held in `Modes` (the kink at zero is a
    /// located event), plainly otherwise.
    #[inline(always)]
    pub(super) fn held_cross(&self, mode: &ContactMode, cross_signed: f64) -> f64 {
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
        terms_on(
            &self.forces,
            &self.forces.per_contact[ci],
            state,
            &self.medium,
            &mut out.force,
            &mut out.bound,
        );
    }

    /// What the terms read of a contact in the sand beyond its geometry `geom` and E's
    /// velocity `v_e`: A_r |v_E| (for a rod |e x v_E| times d_c l: in `Modes` the sign is
    /// held, the kink at 0 is a located event), the point of application P, the signs of
    /// v_E, and the boundary (only when a listed term reads it).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn immersed_state(
        &self,
        c: &Contact,
        pose: &Pose<N>,
        qd: &SVector<f64, N>,
        mode: &ContactMode,
        geom: &Geometry,
        v_e: Vector2<f64>,
        cross_signed: f64,
    ) -> (f64, Vector2<f64>, [f64; 2], Option<Boundary<f64>>) {
        let area_speed = match (&geom.sole, &c.shape) {
            _ if !self.forces.reads_area_speed => 0.0,
            (Some(sg), Shape::Sole(sole)) => sole.drag_area_speed(sg, v_e),
            _ => geom.factor * self.held_cross(mode, cross_signed),
        };
        let p = self.application_point(c, geom.centroid);
        let sign = self.signs(mode, v_e);
        let boundary = if self.forces.reads_frame {
            let mut b = self.boundary(c, pose, qd, geom, p);
            let shift = held_shift(
                sign,
                v_e,
                [
                    self.forces.owns(Switch::SlipX),
                    self.forces.owns(Switch::SlipY),
                ],
            );
            b.frame.v = [b.frame.v[0] + shift.x, b.frame.v[1] + shift.y];
            b.v_centroid = [v_e.x + shift.x, v_e.y + shift.y];
            b.held = self.held_axes(mode);
            Some(b)
        } else {
            None
        };
        (area_speed, p, sign, boundary)
    }

    /// The stiffness of contact `ci`'s terms at `(q, qd)` in `modes` (the sum of each listed
    /// term's [`crate::forces::Term::rates`]), or none out of the sand.
    pub fn contact_rates(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
        ci: usize,
    ) -> Rates {
        let (Some(c), Some(mode)) = (self.contacts.get(ci), modes.get(ci)) else {
            return Rates::NONE;
        };
        let pose = self.mechanism.pose(q);
        let geom = self.geometry(c, &pose);
        if !mode.in_contact || (geom.depth <= 0.0 && !self.forces.reads_frame) {
            return Rates::NONE;
        }
        let v_e = self
            .mechanism
            .point_velocity(&pose, c.link(), geom.centroid, qd);
        let e = geom.cross_axis;
        let cross_signed = e.x * v_e.y - e.y * v_e.x;
        let (area_speed, _, sign, boundary) =
            self.immersed_state(c, &pose, qd, mode, &geom, v_e, cross_signed);
        let state = ContactState {
            depth: geom.depth,
            volume: geom.volume,
            width: geom.width,
            l_ref: geom.l_ref,
            v: [v_e.x, v_e.y],
            area_speed,
            sign,
            boundary: boundary.as_ref(),
        };
        self.forces.per_contact[ci]
            .iter()
            .fold(Rates::NONE, |r, t| r.plus(t.rates(&state, &self.medium)))
    }

    /// Evaluate the accelerations and the per-contact forces at `(q, qd)` in `modes`.
    ///
    /// A single rigid rod whose root is its centre of mass (the free link) has a constant,
    /// diagonal mass matrix and no velocity products: it takes the free link's kernel
    /// ([`Model::eval_free_link`], the same equations in closed form).
    #[inline]
    pub fn eval(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>, modes: &Modes) -> Eval<N> {
        match self.rigid_rod() {
            Some(rod) => {
                let mut e = Eval {
                    qdd: SVector::zeros(),
                    power: 0.0,
                    joint_power: 0.0,
                    joint_torque: [0.0; N],
                    contacts: [ContactEval::default(); MAX_CONTACTS],
                };
                self.eval_free_link(rod, q, qd, modes).write(&mut e);
                e
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
            Some(rod) => self.eval_free_link(rod, q, qd, modes).write(out),
            None => self.eval_general_into(q, qd, modes, out),
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
                let e = self.eval_free_link(rod, q, qd, modes);
                let qdd = SVector::from_fn(|i, _| e.qdd[i]);
                (qdd, e.power, 0.0, e.stiffness())
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

    /// [`Model::eval`] for any body: pose, bias forces, contact forces through the
    /// Jacobians, mass matrix and its Cholesky factor, and the constraints in force.
    pub fn eval_general(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
    ) -> Eval<N> {
        let mut e = Eval {
            qdd: SVector::zeros(),
            power: 0.0,
            joint_power: 0.0,
            joint_torque: [0.0; N],
            contacts: [ContactEval::default(); MAX_CONTACTS],
        };
        self.eval_general_into(q, qd, modes, &mut e);
        e
    }

    /// [`Model::eval_general`] into `out`, in place: the contacts' findings are written
    /// where they stay (an `Eval` is about 1 kB; built aside and moved, it was copied
    /// twice per evaluation). Only the body's contacts are written: the slots past them
    /// keep their default (nothing writes there).
    pub fn eval_general_into(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
        out_eval: &mut Eval<N>,
    ) {
        let pose = self.mechanism.pose(q);
        let g = self.gravity();
        let mut rhs = self.mechanism.bias_forces(&pose, qd, g);
        let mut joint_torque = [0.0; N];
        let mut joint_power = 0.0;
        for t in self.forces.body.iter() {
            joint_power += t.add_joint_torques(&self.mechanism, q, qd, &mut rhs, &mut joint_torque);
        }
        let contacts = &mut out_eval.contacts;
        for c in contacts.iter_mut().take(self.contacts.len()) {
            *c = ContactEval::default();
        }
        let mut moment_power = 0.0;
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
            if let Some(sg) = &geom.sole {
                out.corners_y = sg.corners_y;
            }
            let is_rod = matches!(c.shape, Shape::Rod(_));
            // A box in contact with an edge on the surface (a flat sole at touchdown) takes
            // its forces' limit from inside: no area yet, but the drag's extent is the edge.
            let on_surface = geom.sole.as_ref().is_some_and(|sg| sg.n_vertices >= 3);
            let at_entry = geom.depth <= 0.0 && !self.forces.reads_frame && !on_surface;
            if at_entry && !is_rod {
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
            if at_entry {
                continue;
            }
            let (area_speed, p, sign, boundary) =
                self.immersed_state(c, &pose, qd, mode, &geom, v_e, cross_signed);
            let state = ContactState {
                depth: geom.depth,
                volume: geom.volume,
                width: geom.width,
                l_ref: geom.l_ref,
                v: [v_e.x, v_e.y],
                area_speed,
                sign,
                boundary: boundary.as_ref(),
            };
            self.apply_terms(ci, &state, out);
            self.mechanism
                .add_point_force(&pose, link, p, out.force.total(), &mut rhs);
            if out.force.moment != 0.0 {
                // The moment as a couple: f at P + e and -f at P, with e x f = M.
                let e = pose.axis[link];
                let f = out.force.moment * Vector2::new(-e.y, e.x);
                self.mechanism.add_point_force(
                    &pose,
                    link,
                    p + Vector2::new(1.0, 0.0),
                    f,
                    &mut rhs,
                );
                self.mechanism.add_point_force(&pose, link, p, -f, &mut rhs);
                moment_power += out.force.moment * boundary.map_or(0.0, |b| b.frame.omega);
            }
        }
        let mass = self.mechanism.mass_matrix(&pose);
        // Positive masses give a positive definite M for any finite state; a state that has
        // already blown up (NaN) does not: return NaN and let the solver report it.
        let Some(chol) = mass.cholesky() else {
            out_eval.qdd = SVector::repeat(f64::NAN);
            out_eval.power = f64::NAN;
            out_eval.joint_power = f64::NAN;
            out_eval.joint_torque = joint_torque;
            return;
        };
        let mut qdd = chol.solve(&rhs);
        if self.mechanism.has_constraints() || self.any_stuck(modes) {
            self.solve_constraints(
                &pose,
                q,
                qd,
                modes,
                &chol,
                &mut qdd,
                contacts,
                &mut joint_torque,
            );
        }
        // Power of the sand's forces at their points of application.
        let mut power = moment_power;
        for (ci, ce) in contacts.iter().enumerate().take(self.contacts.len()) {
            // (A contact whose force was not evaluated holds a zero force.)
            if !modes[ci].in_contact {
                continue;
            }
            let p = match self.apply_at {
                ApplyAt::Tip => ce.v_tip,
                ApplyAt::Centroid => ce.v_centroid,
            };
            power += ce.force.total().dot(&p);
        }
        out_eval.qdd = qdd;
        out_eval.power = power;
        out_eval.joint_power = joint_power;
        out_eval.joint_torque = joint_torque;
    }

    /// Force each link receives at its joint from its parent (or the root) [N], from the
    /// accelerations of an evaluation (see
    /// [`Mechanism::joint_forces`](crate::body::Mechanism::joint_forces)).
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

    /// Kinetic and potential energy at `(q, qd)` [J]; the potential energy is the body
    /// terms' field's (gravity's) plus what they store in the joints (the springs').
    pub fn energies(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> (f64, f64) {
        let pose = self.mechanism.pose(q);
        let springs: f64 = self
            .forces
            .body
            .iter()
            .map(|t| t.joint_energy(&self.mechanism, q))
            .sum();
        (
            self.mechanism.kinetic_energy(&pose, qd),
            self.mechanism.potential_energy(&pose, self.gravity()) + springs,
        )
    }
}
