//! Observing a run: its summaries as it goes (the largest drag, the joints' loads, each
//! contact's results at its stop or at the end), the drag's stiffest moment (`h_lambda`),
//! the recorder of time series, and the check that a finished run is a physical answer.
//!
//! Each contact's results are written in one place (`Observer::settle`), at its stop or,
//! without one, at the end of the run.

use nalgebra::{SVector, Vector2};

use super::options::{Record, SolveOptions};
use super::outcome::{
    ContactSummary, Impulse, JointSummary, Needs, Outcome, Series, Stats, Status, OUTCOME_FIELDS,
};
use super::stepper::{companion, Deriv, Method, State};
use crate::dynamics::{ContactEval, DragStiffness, Eval, Model, Modes, Shape, SignModel, Slip};
use crate::error::{GranrsError, Result};
use crate::forces::{ForceSet, Switch};

/// `h lambda` beyond which the classical RK4 is unstable for a real, negative rate.
pub const RK4_STABILITY_LIMIT: f64 = 2.785;

/// The largest error of a located stop time, as a fraction of t_s, that counts as resolved
/// (`Stats::unresolved_stops`): 1 %, the change that `benches/step_warning.py` counts as a
/// result that moves with the step. The error is estimated at the located stop from its
/// switching function, the tip's vertical velocity (zero there when the step resolves the
/// stop): that velocity over the tip's vertical acceleration.
pub const STOP_TIME_ERROR: f64 = 0.01;

/// The tip's vertical velocity [m/s] below which a located stop that is still sinking counts
/// as reached (round-off at a stop the step resolves is far below it).
const STOP_SPEED: f64 = 1e-9;

/// The fastest rate [1/s] of a quadratic drag `F = -c |v| v` on a point of inverse effective
/// mass `w`, with `k = |F| / |v|` and `dir` the unit velocity: the largest eigenvalue of
/// `w K`, `K = dF/dv = -k (I + dir dir^T)` (twice as stiff along the motion as across).
/// A rod's drag `-c |e x v| v` has the same stiffness broadside and less otherwise.
fn drag_rate(w: &nalgebra::Matrix2<f64>, k: f64, dir: Vector2<f64>) -> f64 {
    let stiffness = k * (nalgebra::Matrix2::identity() + dir * dir.transpose());
    let p = w * stiffness;
    let (tr, det) = (p.trace(), p.determinant());
    // Both factors are symmetric positive semi-definite: the eigenvalues are real, >= 0.
    0.5 * (tr + (tr * tr - 4.0 * det).max(0.0).sqrt())
}

/// The listed terms' stiffest moments so far: the largest damping D [N s/m] and the
/// largest spring K [N/m] met, each with the coordinates and the contact where it was (the
/// inverse effective mass there is taken once, at the end, as for the drag).
#[derive(Debug, Clone, Copy)]
struct TermStiffest<const N: usize> {
    damping: (f64, SVector<f64, N>, usize),
    spring: (f64, SVector<f64, N>, usize),
}

impl<const N: usize> TermStiffest<N> {
    /// The terms' rates at `y`, over the contacts in the sand and not stopped.
    fn offer(&mut self, model: &Model<N>, y: &State<N>, modes: &Modes) {
        for ci in 0..model.contacts.len() {
            if modes[ci].stopped || !modes[ci].in_contact {
                continue;
            }
            let r = model.contact_rates(&y.q, &y.qd, modes, ci);
            if r.damping > self.damping.0 {
                self.damping = (r.damping, y.q, ci);
            }
            if r.spring > self.spring.0 {
                self.spring = (r.spring, y.q, ci);
            }
        }
    }

    /// The fastest rate [1/s]: with `w` the largest eigenvalue of E's inverse effective
    /// mass (`Model::centroid_inverse_mass`) where each was met, `w D` (a decay) or
    /// `sqrt(w K)` (an oscillation), whichever is faster.
    fn rate(&self, model: &Model<N>) -> f64 {
        let w = |q: &SVector<f64, N>, ci: usize| {
            largest_eigenvalue(&model.centroid_inverse_mass(q, ci))
        };
        let (d, qd, cd) = self.damping;
        let (k, qk, ck) = self.spring;
        let decay = if d > 0.0 { w(&qd, cd) * d } else { 0.0 };
        let oscillation = if k > 0.0 {
            (w(&qk, ck) * k).sqrt()
        } else {
            0.0
        };
        decay.max(oscillation)
    }
}

/// The largest eigenvalue of a symmetric positive semi-definite 2 x 2 matrix (an inverse
/// effective mass [1/kg]); NaN in, NaN out.
fn largest_eigenvalue(w: &nalgebra::Matrix2<f64>) -> f64 {
    let (tr, det) = (w.trace(), w.determinant());
    0.5 * (tr + (tr * tr - 4.0 * det).max(0.0).sqrt())
}

/// The drag's stiffest moment of a run so far, and the coordinates where it was.
struct Stiffest<const N: usize> {
    best: DragStiffness,
    q: SVector<f64, N>,
}

impl<const N: usize> Stiffest<N> {
    /// `s` at the coordinates `q()`, read only when `s` is the stiffest yet.
    #[inline(always)]
    fn offer(&mut self, q: impl FnOnce() -> SVector<f64, N>, s: &DragStiffness) {
        if s.beats(&self.best) {
            self.best = *s;
            self.q = q();
        }
    }
}

/// What a run keeps of itself as it goes: each contact's and joint's summary, the drag's
/// stiffest moment, the recorded series, and the start's energies the summaries compare to.
pub(super) struct Observer<const N: usize> {
    /// What the run's output fields need computed ([`super::outcome::Outputs::needs`]): a
    /// part no field asked for is not computed (its fields stay NaN or 0 and are not
    /// returned).
    needs: Needs,
    /// Whether the joints' loads are followed: the body reports them ([`joint_loads`]) and
    /// an output field needs them.
    loads_on: bool,
    summaries: Vec<ContactSummary>,
    joints: Vec<JointSummary>,
    impulses: Vec<Impulse>,
    /// The drag's stiffest moment: ((|F_d| / |v_E|)^2, the state, the contact, v_E), over
    /// the step ends, the events and the RK4 stages (within a step that does not resolve the
    /// contact, the stages meet a stiffness the ends do not). Squared norms: a square root
    /// only when a maximum is beaten.
    stiffest: Stiffest<N>,
    /// Whether the terms' own stiffness is sampled ([`Observer::sample_rates`]): a listed
    /// term reads the contact's boundary (`rft`, `rft_inertial`, `poncelet`), whose rates the
    /// drag's |F_d| / |v_E| does not see. The thesis's terms keep the drag's estimate alone.
    rates_on: bool,
    /// Each contact: whether the step did not resolve it (`Stats::unresolved_stops` counts
    /// them): its stop's estimated error past [`STOP_TIME_ERROR`] (or its depth's at the end
    /// without a stop), or a stick decision the step made ([`Observer::overshot_stick`]).
    unresolved: Vec<bool>,
    /// Each contact: the time [s] and axis of its first stick the step decided
    /// ([`Observer::overshot_stick`]), judged at its stop or at the end ([`Observer::slid`]).
    overshot: Vec<Option<(f64, usize)>>,
    /// The terms' stiffest moments at the start, the step ends and the events so far.
    terms: TermStiffest<N>,
    /// The run's error so far, as its steps estimate it ([`super::stepper::companion`]):
    /// each accepted step's estimate summed per coordinate and rate, signed (errors of
    /// opposite sign in two steps cancel, as they do in the run). The sum does not carry an
    /// error through the dynamics: the sand damps a perturbation rather than growing it.
    err_q: SVector<f64, N>,
    /// See `err_q`.
    err_qd: SVector<f64, N>,
    /// The largest relative error of a contact's t_s or depth, estimated at its stop (or at
    /// the end without one) from `err_q`, `err_qd` and the stop's own residual
    /// (`Outcome::step_error`).
    step_error: f64,
    /// Whether `step_error` counts in `unresolved_stops`: under a sign model that holds or
    /// smooths the static terms' signs. Under the plain `sign()` they switch inside the
    /// steps by construction, each step's estimate holds the switch's jump, and those jumps
    /// cancel over a stick where the sum does not see it (measured on the property tests'
    /// domain: half of its runs above 1 % moved by less than 1 % at dt / 10); its chatter
    /// has its own rule (`Stats::unresolved` and the energy). Its `step_error` is reported.
    estimates: bool,
    recorder: Recorder,
    /// Record every `stride`-th grid step.
    stride: u64,
    /// The start: coordinates, kinetic and potential energy, and each link's.
    q0: SVector<f64, N>,
    ke0: f64,
    pe0: f64,
    link_e0: Vec<(f64, f64)>,
}

/// Kinetic and potential energy of link `i` at `y` [J].
fn link_energy<const N: usize>(model: &Model<N>, y: &State<N>, i: usize) -> (f64, f64) {
    let pose = model.mechanism.pose(&y.q);
    model
        .mechanism
        .link_energy(&pose, &y.qd, model.gravity(), i)
}

impl<const N: usize> Observer<N> {
    /// Start observing a run from `y` in `modes` (a contact in the sand at the start
    /// entered it at t = 0).
    pub(super) fn new(
        model: &Model<N>,
        y: &State<N>,
        modes: &Modes,
        options: &SolveOptions,
    ) -> Self {
        let record = options.record;
        let needs = options.outputs.needs().union(Needs::ALWAYS);
        let rates_on = model.forces.reads_frame && needs.has(Needs::STIFFNESS);
        let nc = model.contacts.len();
        let (ke0, pe0) = model.energies(&y.q, &y.qd);
        let summaries = (0..nc)
            .map(|ci| ContactSummary {
                stopped: false,
                t_s: f64::NAN,
                depth: 0.0,
                dq: 0.0,
                omega_end: 0.0,
                f_d_max: 0.0,
                f_s_end: f64::NAN,
                f_r_end: f64::NAN,
                d_ke: f64::NAN,
                d_pe: f64::NAN,
                d_e: f64::NAN,
                work_sand: f64::NAN,
                tip_end: Vector2::zeros(),
                t_entry: if modes[ci].in_contact { 0.0 } else { f64::NAN },
                link_d_ke: f64::NAN,
                link_d_pe: f64::NAN,
            })
            .collect();
        let n_links = model.mechanism.n_links();
        Observer {
            needs,
            loads_on: joint_loads(model) && needs.has(Needs::JOINT_LOADS),
            summaries,
            joints: vec![JointSummary::default(); n_links],
            impulses: Vec::new(),
            stiffest: Stiffest {
                best: DragStiffness::default(),
                q: y.q,
            },
            rates_on,
            unresolved: vec![false; nc],
            overshot: vec![None; nc],
            err_q: SVector::zeros(),
            err_qd: SVector::zeros(),
            step_error: 0.0,
            estimates: model.sign_model != SignModel::Raw,
            terms: {
                let mut terms = TermStiffest {
                    damping: (0.0, y.q, 0),
                    spring: (0.0, y.q, 0),
                };
                if rates_on {
                    terms.offer(model, y, modes);
                }
                terms
            },
            recorder: Recorder::new(record, &model.forces, N, nc, n_links, joint_loads(model)),
            stride: record.stride.max(1) as u64,
            q0: y.q,
            ke0,
            pe0,
            link_e0: if needs.has(Needs::ENERGY) {
                (0..n_links).map(|i| link_energy(model, y, i)).collect()
            } else {
                Vec::new()
            },
        }
    }

    /// A step's end at coordinates `q` where a contact not yet stopped has the drag `s`
    /// ([`Observer::step_end`]'s part for that contact): its largest drag and stiffness.
    #[inline(always)]
    pub(super) fn drag_at(&mut self, q: &SVector<f64, N>, s: &DragStiffness) {
        if self.needs.has(Needs::DRAG_MAX) {
            let f_d_max = &mut self.summaries[s.contact].f_d_max;
            if s.drag2 > *f_d_max * *f_d_max {
                *f_d_max = s.drag2.sqrt();
            }
        }
        if self.needs.has(Needs::STIFFNESS) {
            self.stiffest.offer(|| *q, s);
        }
    }

    /// Whether [`Observer::step_end`] and [`Observer::record_step`] need nothing of a step's
    /// end but each contact's drag ([`Observer::drag_at`]): nothing is recorded and the body
    /// reports no joint loads.
    #[inline]
    pub(super) fn drag_only(&self) -> bool {
        !self.recorder.on.any() && !self.loads_on && !self.rates_on
    }

    /// The terms' stiffness at a step's end or an event `y` ([`Observer::rates_on`]).
    pub(super) fn sample_rates(&mut self, model: &Model<N>, y: &State<N>, modes: &Modes) {
        if self.rates_on {
            self.terms.offer(model, y, modes);
        }
    }

    /// An RK4 step of size `h` whose fourth stage was `k4` ended where the derivative is
    /// `k5`: add its error estimate ([`super::stepper::companion`]) to the run's.
    #[inline(always)]
    pub(super) fn step_error(&mut self, h: f64, k4: &Deriv<N>, k5: &Deriv<N>) {
        if !self.needs.has(Needs::STEP_ERROR) {
            return;
        }
        let (dq, dqd) = companion(h, k4, k5);
        self.err_q += dq;
        self.err_qd += dqd;
    }

    /// An RK4 step of size `h` whose fourth stage was `k4` and whose end's derivative is `k5`
    /// was cut at `h_cut <= h`, where the run located an event: add the cut step's error
    /// estimate, the whole step's ([`super::stepper::companion`]) scaled by its order,
    /// `(h_cut / h)^4` (what the companion of the cut step gives where the right-hand side
    /// is smooth).
    ///
    /// The cut step's own companion would read the derivative at the event, on the switching
    /// function's zero, where the held modes' force need not be a function of the state: a
    /// force that follows only a velocity's direction (`rft`) is set-valued at rest, and at a
    /// located stop that direction is the round-off's. A vertical `rft` rod stops with
    /// v_E = (-2.7e-12, 1.5e-15) m/s: its force turns sideways there, qdd = (83, 22.7, -1998)
    /// against (0, 82.7, 0) at the step's fourth stage, and the companion read that jump,
    /// 1.5e-4 m/s in the tip's velocity, as the step's error (step_error 1.3e-4 where t_s
    /// moves by 1e-12 at dt / 10). RK4's end does not read that derivative (its four stages
    /// lie inside the step), so neither does the estimate: the whole step ends past the
    /// event, inside the held mode, where its derivative is evaluated anyway.
    #[inline(always)]
    pub(super) fn cut_step_error(&mut self, h: f64, h_cut: f64, k4: &Deriv<N>, k5: &Deriv<N>) {
        if !self.needs.has(Needs::STEP_ERROR) {
            return;
        }
        let (dq, dqd) = companion(h, k4, k5);
        let scale = (h_cut / h).powi(4);
        self.err_q += scale * dq;
        self.err_qd += scale * dqd;
    }

    /// The errors of contact `ci`'s tip height and vertical velocity [m, m/s] at `q, qd`
    /// that the run's estimate (`err_q`, `err_qd`) gives, through the tip's Jacobian J (its
    /// height moves by J dq, its velocity J dqd + (dJ/dq qd) dq), each coordinate's part
    /// in magnitude.
    fn tip_errors(
        &self,
        model: &Model<N>,
        ci: usize,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> (f64, f64) {
        let contact = &model.contacts[ci];
        let (link, tip) = (contact.link(), contact.reference_point());
        let m = &model.mechanism;
        let pose = m.pose(q);
        let v0 = m.point_velocity(&pose, link, tip, qd).y;
        let (mut dy, mut dv) = (0.0, 0.0);
        for i in 0..N {
            let unit = SVector::<f64, N>::from_fn(|k, _| if k == i { 1.0 } else { 0.0 });
            let j = m.point_velocity(&pose, link, tip, &unit).y.abs();
            // dJ/dq_i qd, by a forward difference.
            let eps = 1e-7 * (1.0 + q[i].abs());
            let mut qe = *q;
            qe[i] += eps;
            let dj = (m.point_velocity(&m.pose(&qe), link, tip, qd).y - v0).abs() / eps;
            dy += j * self.err_q[i].abs();
            dv += j * self.err_qd[i].abs() + dj * self.err_q[i].abs();
        }
        (dy, dv)
    }

    /// Show the drag's stiffness `s` at an RK4 stage with coordinates `q()` (read only when
    /// `s` is the stiffest yet).
    #[inline(always)]
    pub(super) fn offer(&mut self, q: impl FnOnce() -> SVector<f64, N>, s: &DragStiffness) {
        if self.needs.has(Needs::STIFFNESS) {
            self.stiffest.offer(q, s);
        }
    }

    /// Whether the stiffness is sampled ([`Observer::offer`]): else its caller need not
    /// compute what it reads.
    #[inline(always)]
    pub(super) fn wants_stiffness(&self) -> bool {
        self.needs.has(Needs::STIFFNESS)
    }

    /// Whether a step's error estimate is asked for ([`Observer::step_error`]): else its
    /// caller need not compute what it reads.
    #[inline(always)]
    pub(super) fn wants_step_error(&self) -> bool {
        self.needs.has(Needs::STEP_ERROR)
    }

    /// A step ended at `y` (its evaluation `e`): the largest drag of each contact not yet
    /// stopped, the drag's stiffness there, and the joints' largest loads.
    #[inline(always)]
    pub(super) fn step_end(&mut self, model: &Model<N>, y: &State<N>, e: &Eval<N>, modes: &Modes) {
        if self.needs.has(Needs::DRAG_MAX) || self.needs.has(Needs::STIFFNESS) {
            let n = self.summaries.len();
            for (ci, (m, c)) in modes.iter().zip(&e.contacts).take(n).enumerate() {
                if !m.stopped {
                    self.drag_at(&y.q, &DragStiffness::of(ci, c));
                }
            }
        }
        if !self.loads_on {
            return;
        }
        let f = model.joint_forces(&y.q, &y.qd, e, modes);
        for (i, j) in self.joints.iter_mut().enumerate() {
            j.f_max = j.f_max.max(f[i].norm());
            j.torque_max = j.torque_max.max(e.joint_torque[i].abs());
        }
    }

    /// Record the state at `t` (events and the run's ends are always recorded).
    #[inline]
    pub(super) fn record(
        &mut self,
        model: &Model<N>,
        t: f64,
        y: &State<N>,
        e: &Eval<N>,
        modes: &Modes,
    ) {
        self.recorder.push(model, t, y, e, modes);
    }

    /// Record the state at `t` unless the last record is at `t` already (the state before
    /// a drive's impulse, which a step's end may have recorded).
    #[inline]
    pub(super) fn record_new(
        &mut self,
        model: &Model<N>,
        t: f64,
        y: &State<N>,
        e: &Eval<N>,
        modes: &Modes,
    ) {
        if self.recorder.t.last() != Some(&t) {
            self.record(model, t, y, e, modes);
        }
    }

    /// A table-driven joint (carrying `link`) applied `impulse` [N m s], doing `energy` [J],
    /// at `t`.
    pub(super) fn impulse(&mut self, link: usize, t: f64, impulse: f64, energy: f64) {
        self.joints[link].impulse_work += energy;
        self.impulses.push(Impulse {
            link,
            t,
            impulse,
            energy,
        });
    }

    /// Record the end of the `n`-th grid step, if it is one of every `stride`.
    #[inline]
    pub(super) fn record_step(
        &mut self,
        n: u64,
        model: &Model<N>,
        t: f64,
        y: &State<N>,
        e: &Eval<N>,
        modes: &Modes,
    ) {
        // Nothing recorded (the default): no remainder (a 64-bit division) per step.
        if self.recorder.on.any() && n.is_multiple_of(self.stride) {
            self.recorder.push(model, t, y, e, modes);
        }
    }

    /// Contact `ci` slid on along `axis` at `t` where its static bound would have held it,
    /// because the located sign switch overshot the zero (see `events::choose_slip`): the
    /// step, not the contact, decided. Judged at its stop or at the end ([`Observer::slid`]).
    pub(super) fn overshot_stick(&mut self, ci: usize, axis: usize, t: f64) {
        if self.estimates && self.needs.has(Needs::STEP_ERROR) && self.overshot[ci].is_none() {
            self.overshot[ci] = Some((t, axis));
        }
    }

    /// Whether contact `ci`'s stick the step decided ([`Observer::overshot_stick`]) moved
    /// its results: by `t`, where E moves at `v_e` and the tip is `depth` deep, E slid that
    /// way for `t - t_o`, speeding up (`events::runs_away`), so by at most |v_e| (t - t_o);
    /// more than [`STOP_TIME_ERROR`] of the depth counts it in `unresolved_stops` (an
    /// `rft` rod at the centroid slid up for 0.04 s and stopped at 0.049 s against 0.198 s;
    /// a chain's link that stops 17 us after the switch does not move).
    fn slid(&mut self, ci: usize, t: f64, v_e: Vector2<f64>, depth: f64) {
        if let Some((t_o, axis)) = self.overshot[ci] {
            if t - t_o > STOP_TIME_ERROR * t
                || v_e[axis].abs() * (t - t_o) > STOP_TIME_ERROR * depth
            {
                self.unresolved[ci] = true;
            }
        }
    }

    /// Contact `ci` entered the sand at `t` (the first entry counts).
    pub(super) fn entered(&mut self, ci: usize, t: f64) {
        let s = &mut self.summaries[ci];
        if s.t_entry.is_nan() {
            s.t_entry = t;
        }
    }

    /// Contact `ci` stopped at `t`, at the state `y` (its evaluation `e`), `rest` [s] before
    /// the end of the step that found the stop (where the tip rises).
    pub(super) fn stopped(
        &mut self,
        model: &Model<N>,
        ci: usize,
        t: f64,
        y: &State<N>,
        e: &Eval<N>,
        rest: f64,
    ) {
        if self.needs.has(Needs::STEP_ERROR) {
            self.stop_error(model, ci, t, y, e, rest);
        }
        let s = &mut self.summaries[ci];
        s.stopped = true;
        s.t_s = t;
        let energies = if self.needs.has(Needs::ENERGY) {
            model.energies(&y.q, &y.qd)
        } else {
            (f64::NAN, f64::NAN)
        };
        self.settle(model, ci, y, &e.contacts[ci], energies);
    }

    /// The error of contact `ci`'s stop at `t` (`Outcome::step_error`), and whether the
    /// step resolved it (`Stats::unresolved_stops`): see [`Observer::stopped`].
    fn stop_error(
        &mut self,
        model: &Model<N>,
        ci: usize,
        t: f64,
        y: &State<N>,
        e: &Eval<N>,
        rest: f64,
    ) {
        // The stop's switching function there (zero where the step resolves the stop) over
        // its rate, the tip's vertical acceleration: the stop time's error.
        let contact = &model.contacts[ci];
        let (link, tip) = (contact.link(), contact.reference_point());
        let pose = model.mechanism.pose(&y.q);
        let accel = model.mechanism.point_velocity(&pose, link, tip, &e.qdd)
            + model
                .mechanism
                .point_bias_acceleration(&pose, link, tip, &y.qd);
        // The stop's time error: the residual, and the run's error in the tip's vertical
        // velocity, over its rate; the depth's: the run's error in the tip's height.
        let (dy, dv) = self.tip_errors(model, ci, &y.q, &y.qd);
        let depth = (-e.contacts[ci].tip.y).max(0.0);
        // Finite however small the stop's rate (a blow-up's NaN counts as no estimate: the
        // outcome check refuses that run).
        let ratio = |err: f64, of: f64| {
            if err > 0.0 {
                (err / of).min(f64::MAX)
            } else {
                0.0
            }
        };
        let v_res = e.contacts[ci].v_tip.y;
        let mut relative = ratio(v_res.abs() + dv, t * accel.y.abs()).max(ratio(dy, depth));
        // Still sinking where the stop was located, and not slowing down: the interpolant's
        // root is not one of the run's own map, whose velocity moves away from zero there
        // (a force that follows a velocity's direction flipped inside the step). The map's
        // own root lies between here and the step's end, where the tip rises (the stop was
        // found there): the stop time's error is at most the `rest` of the step, the depth's
        // the tip's sinking over it. Not under the plain `sign()`, whose static terms chatter
        // through every stop by construction (see `estimates`).
        let spurious = self.estimates && v_res < -STOP_SPEED && accel.y <= 0.0;
        if spurious {
            let rest = rest.max(0.0);
            relative = relative
                .max(ratio(rest, t))
                .max(ratio(v_res.abs() * rest, depth));
        }
        self.step_error = self.step_error.max(relative);
        if (!spurious && v_res.abs() > STOP_TIME_ERROR * t * accel.y.abs())
            || (self.estimates && relative > STOP_TIME_ERROR)
        {
            self.unresolved[ci] = true;
        }
        self.slid(ci, t, e.contacts[ci].v_centroid, depth);
    }

    /// Write contact `ci`'s results at the state `y` (`c` its findings there, `(ke, pe)` the
    /// body's energies): at its stop, or at the end of a run without one.
    fn settle(
        &mut self,
        model: &Model<N>,
        ci: usize,
        y: &State<N>,
        c: &ContactEval,
        (ke, pe): (f64, f64),
    ) {
        let link = model.contacts[ci].link();
        let energy = self.needs.has(Needs::ENERGY);
        let s = &mut self.summaries[ci];
        s.depth = (-c.tip.y).max(0.0);
        s.dq = y.q[2 + link] - self.q0[2 + link];
        s.omega_end = y.qd[2 + link];
        s.f_s_end = c.force.static_magnitude();
        s.f_r_end = c.force.total_magnitude();
        s.work_sand = y.work;
        s.tip_end = c.tip;
        if energy {
            let (lk, lp) = link_energy(model, y, link);
            s.d_ke = self.ke0 - ke;
            s.d_pe = self.pe0 - pe;
            s.d_e = s.d_ke + s.d_pe;
            s.link_d_ke = self.link_e0[link].0 - lk;
            s.link_d_pe = self.link_e0[link].1 - lp;
        }
    }

    /// The run ended at `t` in the state `y` with `status`: the results of the contacts that
    /// did not stop, the last record, the drag's `h lambda`, and the outcome, checked.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn finish(
        mut self,
        model: &Model<N>,
        status: Status,
        t: f64,
        y: &State<N>,
        modes: &Modes,
        stats: Stats,
        options: &SolveOptions,
    ) -> Result<Outcome> {
        // Contacts without a stop report their state at the end.
        let e_end = model.eval(&y.q, &y.qd, modes);
        let energies = model.energies(&y.q, &y.qd);
        for ci in 0..self.summaries.len() {
            if !self.summaries[ci].stopped {
                self.settle(model, ci, y, &e_end.contacts[ci], energies);
                if !self.needs.has(Needs::STEP_ERROR) {
                    continue;
                }
                let c = &e_end.contacts[ci];
                self.slid(ci, t, c.v_centroid, (-c.tip.y).max(0.0));
                if options.method == Method::Rk4 {
                    let (dy, _) = self.tip_errors(model, ci, &y.q, &y.qd);
                    let depth = (-e_end.contacts[ci].tip.y).max(0.0);
                    if depth > 0.0 && dy > 0.0 {
                        self.step_error = self.step_error.max((dy / depth).min(f64::MAX));
                        if self.estimates && dy > STOP_TIME_ERROR * depth {
                            self.unresolved[ci] = true;
                        }
                    }
                }
            }
        }
        if status != Status::Stopped && options.record.any() && self.recorder.t.last() != Some(&t) {
            self.recorder.push(model, t, y, &e_end, modes);
        }
        let best = &self.stiffest.best;
        let h_lambda = if options.method != Method::Rk4 || !self.needs.has(Needs::STIFFNESS) {
            f64::NAN
        } else {
            let drag = if best.k2() > 0.0 {
                let inverse_mass = model.centroid_inverse_mass(&self.stiffest.q, best.contact);
                drag_rate(&inverse_mass, best.k2().sqrt(), best.v.normalize())
            } else {
                0.0
            };
            options.dt * drag.max(self.terms.rate(model))
        };
        let mut stats = stats;
        stats.unresolved_stops = self.unresolved.iter().filter(|&&u| u).count();
        let step_error = if options.method == Method::Rk4 && self.needs.has(Needs::STEP_ERROR) {
            self.step_error
        } else {
            f64::NAN
        };
        let out = Outcome {
            h_lambda,
            step_error,
            status,
            t_final: t,
            stats,
            contacts: self.summaries,
            energy_start: self.ke0 + self.pe0,
            energy_end: energies.0 + energies.1,
            work_sand: y.work,
            dissipated: y.dissipated,
            joints: self.joints,
            impulses: self.impulses,
            series: self.recorder.finish(),
            terms: model.forces.names.clone(),
            outputs: options.outputs,
        };
        check_outcome(model, &out, self.needs)?;
        Ok(out)
    }
}

/// How many times the body's energy scale a run may gain before it counts as diverged.
/// With the force at the tip the sand can feed energy in; over the property tests' domain
/// the gain stayed below 0.11 of that scale (docs/hard_cases.md), so this is 90x margin.
pub const DIVERGENCE_FACTOR: f64 = 10.0;

/// Refuse an outcome that is not a physical answer: a non-finite result (a contact field of
/// [`OUTCOME_FIELDS`] marked `finite`, of those the run computed: whose `needs` are in
/// `needs`), or a run whose mechanical energy grew past
/// [`DIVERGENCE_FACTOR`] times the body's energy scale (|E(0)| + M g l, with M the total
/// mass and l the links' size). Both happen only when the step is beyond RK4's stability
/// limit for the scene's contact stiffness; the error says so instead of returning a
/// "stopped" run with enormous numbers.
fn check_outcome<const N: usize>(model: &Model<N>, out: &Outcome, needs: Needs) -> Result<()> {
    let fail = |message: String| {
        Err(GranrsError::NonFinite {
            t: out.t_final,
            message,
        })
    };
    for (i, c) in out.contacts.iter().enumerate() {
        let bad = OUTCOME_FIELDS
            .contact
            .iter()
            .filter(|f| f.finite && needs.has(f.needs))
            .map(|f| (f.name, (f.read)(c).as_f64()))
            .find(|(_, v)| !v.is_finite());
        if let Some((name, v)) = bad {
            return fail(format!(
                "contact {i}: {name} = {v}; the step dt is too large for this scene's \
                 contact stiffness (try a smaller dt, or method=\"dopri5\")"
            ));
        }
    }
    let links = &model.mechanism.links;
    let mass: f64 = links.iter().map(|l| l.mass).sum::<f64>() + model.mechanism.root_mass;
    // The body's size: its links' extents and its contacts' lengths (a free link's root is
    // its centre of mass, so only the rod's length says how tall it is).
    let size: f64 = links
        .iter()
        .map(|l| 2.0 * l.com.norm() + l.joint_on_parent.norm())
        .sum::<f64>()
        + model
            .contacts
            .iter()
            .map(|c| match c.shape {
                Shape::Rod(r) => r.length,
                Shape::Sole(s) => s.length + s.height,
                Shape::Arc(a) => 2.0 * a.radius,
            })
            .sum::<f64>();
    let scale = out.energy_start.abs() + mass * model.gravity() * size + 1e-12 * mass;
    let gain = out.energy_end - out.energy_start;
    if !out.energy_end.is_finite() || gain > DIVERGENCE_FACTOR * scale {
        return fail(format!(
            "the run diverged: its energy grew from {:.4e} J to {:.4e} J (more than {} times \
             the body's energy scale {:.3e} J); the step dt is too large for this scene's \
             contact stiffness (try a smaller dt, or method=\"dopri5\")",
            out.energy_start, out.energy_end, DIVERGENCE_FACTOR, scale
        ));
    }
    Ok(())
}

/// Whether a body's joint loads are reported: several links, or a root link whose angle is
/// driven (its torque).
#[inline]
fn joint_loads<const N: usize>(model: &Model<N>) -> bool {
    model.mechanism.n_links() > 1 || model.mechanism.root_rate.is_some()
}

/// Recorder of time series.
struct Recorder {
    on: Record,
    n_dof: usize,
    n_contacts: usize,
    n_links: usize,
    /// Whether the joints' loads are recorded (several links, or a driven root angle).
    joint_loads: bool,
    t: Vec<f64>,
    cols: Vec<Vec<f64>>,
    names: Vec<String>,
}

impl Recorder {
    fn new(
        on: Record,
        forces: &ForceSet,
        n_dof: usize,
        n_contacts: usize,
        n_links: usize,
        joint_loads: bool,
    ) -> Self {
        let mut names = Vec::new();
        if on.state {
            for i in 0..n_dof {
                names.push(format!("q{i}"));
            }
            for i in 0..n_dof {
                names.push(format!("qd{i}"));
            }
            names.push("work_sand".into());
        }
        if on.forces {
            // A force term that is off is not stored, nor the mode of its sign.
            let mut fields = vec![
                "tip_x", "tip_y", "v_tip_x", "v_tip_y", "depth", "v_E_x", "v_E_y",
            ];
            for info in &forces.contact_info {
                fields.extend(info.columns.iter().map(|(name, _)| *name));
            }
            if forces.owns(Switch::SlipX) {
                fields.push("mode_x");
            }
            if forces.owns(Switch::SlipY) {
                fields.push("mode_y");
            }
            for c in 0..n_contacts {
                for f in &fields {
                    names.push(format!("c{c}.{f}"));
                }
            }
            if joint_loads {
                for i in 0..n_links {
                    for f in ["Fx", "Fy", "torque"] {
                        names.push(format!("joint{i}.{f}"));
                    }
                }
            }
        }
        if on.energy {
            names.push("KE".into());
            names.push("PE".into());
            names.push("joint_loss".into());
            if n_links > 1 {
                for i in 0..n_links {
                    names.push(format!("link{i}.KE"));
                    names.push(format!("link{i}.PE"));
                }
            }
        }
        let cols = vec![Vec::new(); names.len()];
        Recorder {
            on,
            n_dof,
            n_contacts,
            n_links,
            joint_loads,
            t: Vec::new(),
            cols,
            names,
        }
    }

    fn push<const N: usize>(
        &mut self,
        model: &Model<N>,
        t: f64,
        y: &State<N>,
        e: &Eval<N>,
        modes: &Modes,
    ) {
        if !self.on.any() {
            return;
        }
        self.t.push(t);
        let mut k = 0;
        let mut put = |cols: &mut Vec<Vec<f64>>, v: f64| {
            cols[k].push(v);
            k += 1;
        };
        if self.on.state {
            for i in 0..self.n_dof {
                put(&mut self.cols, y.q[i]);
            }
            for i in 0..self.n_dof {
                put(&mut self.cols, y.qd[i]);
            }
            put(&mut self.cols, y.work);
        }
        if self.on.forces {
            for (c, m) in e.contacts[..self.n_contacts].iter().zip(modes) {
                // The modes: -1, +1, 0 for stick; NaN out of the sand or without modes.
                let mode = |s: Slip| {
                    if m.in_contact && model.sign_model == SignModel::Modes {
                        s.sign()
                    } else {
                        f64::NAN
                    }
                };
                for v in [
                    c.tip.x,
                    c.tip.y,
                    c.v_tip.x,
                    c.v_tip.y,
                    (-c.tip.y).max(0.0),
                    c.v_centroid.x,
                    c.v_centroid.y,
                ] {
                    put(&mut self.cols, v);
                }
                let forces = &model.forces;
                for (k, info) in forces.contact_info.iter().enumerate() {
                    for &(_, axis) in info.columns {
                        put(&mut self.cols, c.force.terms[k][axis]);
                    }
                }
                if forces.owns(Switch::SlipX) {
                    put(&mut self.cols, mode(m.sx));
                }
                if forces.owns(Switch::SlipY) {
                    put(&mut self.cols, mode(m.sy));
                }
            }
            if self.joint_loads {
                let f = model.joint_forces(&y.q, &y.qd, e, modes);
                for (fi, ti) in f.iter().zip(&e.joint_torque).take(self.n_links) {
                    put(&mut self.cols, fi.x);
                    put(&mut self.cols, fi.y);
                    put(&mut self.cols, *ti);
                }
            }
        }
        if self.on.energy {
            let (ke, pe) = model.energies(&y.q, &y.qd);
            put(&mut self.cols, ke);
            put(&mut self.cols, pe);
            put(&mut self.cols, y.dissipated);
            if self.n_links > 1 {
                let pose = model.mechanism.pose(&y.q);
                for i in 0..self.n_links {
                    let (k, p) = model
                        .mechanism
                        .link_energy(&pose, &y.qd, model.gravity(), i);
                    put(&mut self.cols, k);
                    put(&mut self.cols, p);
                }
            }
        }
    }

    fn finish(self) -> Option<Series> {
        if !self.on.any() {
            return None;
        }
        Some(Series {
            t: self.t,
            columns: self.names.into_iter().zip(self.cols).collect(),
        })
    }
}
