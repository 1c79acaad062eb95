//! The solve loop: fixed-step RK4 on a fixed time grid, with every discontinuity of the
//! force law (surface entry and exit, a sign switch, the end of a stick) and every stop
//! located on the step's Hermite interpolant and restarted from exactly there.
//!
//! The loop keeps the grid `t_n = n dt` (computed by multiplication, so round-off never adds
//! a step past `t_end`): after an event the step to the next grid point is shortened. An
//! event is an outcome, reported in [`Status`]; only a non-finite state is an error.

use nalgebra::{SVector, Vector2};

use super::dense::{locate, locate_in, Hermite};
use super::rk4::{deriv_of, dopri5_step, step, step_sampling, Deriv, State};
use crate::dynamics::{
    ContactMode, DragStiffness, Eval, Model, Modes, Shape, SignModel, Slip, MAX_CONTACTS,
};
use crate::error::{GranrsError, Result};
use crate::forces::{ForceSet, Switch};

/// When a run ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndCondition {
    /// At the first stop of any contact (the thesis's end of the penetration phase).
    FirstStop,
    /// When every contact has stopped.
    AllStops,
    /// At `t_end`, whatever happens before.
    Time,
}

/// What to record as time series. Nothing is stored for a field that is off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Record {
    /// Generalized coordinates and rates, and the work of the sand.
    pub state: bool,
    /// Per contact: tip position and velocity, depth, and the four force components.
    pub forces: bool,
    /// Kinetic and potential energy.
    pub energy: bool,
    /// Record every `stride`-th grid step (events are always recorded). 0 means 1.
    pub stride: usize,
}

impl Record {
    /// Whether anything is recorded.
    pub fn any(&self) -> bool {
        self.state || self.forces || self.energy
    }
}

/// The time stepper.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Classical RK4 on the fixed grid `n dt` (default; the thesis ran at 10 kHz).
    Rk4,
    /// Adaptive Dormand-Prince 5(4): tolerances instead of a step; `dt` is the first step.
    Dopri5 {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance [SI units of each coordinate].
        atol: f64,
    },
}

/// Options of one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// Step size of the fixed grid [s] (thesis: 10 kHz, 1e-4 s); the first step of Dopri5.
    pub dt: f64,
    /// The time stepper.
    pub method: Method,
    /// Latest end time [s].
    pub t_end: f64,
    /// When to end.
    pub end: EndCondition,
    /// What to record.
    pub record: Record,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            dt: 1e-4,
            method: Method::Rk4,
            t_end: 1.0,
            end: EndCondition::FirstStop,
            record: Record::default(),
        }
    }
}

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// The end condition's stop(s) happened.
    Stopped,
    /// `t_end` was reached with the end condition `Time`.
    EndTime,
    /// `t_end` was reached before the stop(s) the end condition waits for.
    NotStopped,
}

impl Status {
    /// A short name for reports.
    pub fn name(&self) -> &'static str {
        match self {
            Status::Stopped => "stopped",
            Status::EndTime => "end_time",
            Status::NotStopped => "not_stopped",
        }
    }
}

/// Work counters of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Stats {
    /// Accepted steps (full and shortened).
    pub steps: usize,
    /// Right-hand-side evaluations, root finding included.
    pub rhs_evals: usize,
    /// Right-hand-side evaluations spent locating events.
    pub root_evals: usize,
    /// Events handled (entries, exits, sign switches, sticks, stops).
    pub events: usize,
    /// Steps rejected by the adaptive method's error control.
    pub rejected: usize,
    /// Steps taken as they were after [`MAX_EVENTS_PER_STEP`] events within them: the
    /// sign modes chattered, the step does not resolve the contact.
    pub unresolved: usize,
}

/// The results of one contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSummary {
    /// Whether the contact's stop happened.
    pub stopped: bool,
    /// Time of the stop (NaN without one) [s].
    pub t_s: f64,
    /// Depth of the tip at the stop, or at the end without one [m].
    pub depth: f64,
    /// Change of the contact link's angle from the start to the stop [rad].
    pub dq: f64,
    /// Angular velocity dq/dt of the contact link at the stop [rad/s].
    pub omega_end: f64,
    /// Largest |F_d| before the stop, over step ends and events [N] (eq. 3.23).
    pub f_d_max: f64,
    /// |F_s| at the stop, as the stop is approached [N] (eq. 3.22).
    pub f_s_end: f64,
    /// |F_r| at the stop [N] (eq. 3.24).
    pub f_r_end: f64,
    /// Kinetic energy lost from the start to the stop, KE(0) - KE(t_s) [J] (eq. 3.25).
    pub d_ke: f64,
    /// Potential energy lost, PE(0) - PE(t_s) [J] (eq. 3.26).
    pub d_pe: f64,
    /// Mechanical energy lost, dKE + dPE [J].
    pub d_e: f64,
    /// Work done by the sand on the body up to the stop (integrated power) [J].
    pub work_sand: f64,
    /// Tip position at the stop (or end) [m].
    pub tip_end: Vector2<f64>,
    /// Time the tip entered the sand (NaN if it never did) [s].
    pub t_entry: f64,
    /// Kinetic energy lost by the contact's own link, start to stop [J] (thesis eq. 4.9).
    pub link_d_ke: f64,
    /// Potential energy lost by the contact's own link, start to stop [J] (eq. 4.10).
    pub link_d_pe: f64,
}

/// The results of one joint (the force and torque a link receives from its parent, or
/// from the root for a root link).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JointSummary {
    /// Largest |F| over the run [N].
    pub f_max: f64,
    /// Largest |torque| over the run [N m].
    pub torque_max: f64,
}

/// Recorded time series, column by column (each the same length as `t`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Time [s].
    pub t: Vec<f64>,
    /// Named columns.
    pub columns: Vec<(String, Vec<f64>)>,
}

/// What a run returns.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Why it ended.
    pub status: Status,
    /// Time it ended [s].
    pub t_final: f64,
    /// Work counters.
    pub stats: Stats,
    /// Per contact.
    pub contacts: Vec<ContactSummary>,
    /// Mechanical energy KE + PE (gravity and springs) at the start and the end [J].
    pub energy_start: f64,
    /// See `energy_start`.
    pub energy_end: f64,
    /// Work done by the sand over the whole run [J].
    pub work_sand: f64,
    /// Energy dissipated by the joints' dampers over the whole run [J].
    pub dissipated: f64,
    /// Per link: the joint that carries it.
    pub joints: Vec<JointSummary>,
    /// Largest `dt * lambda` of the drag over the run: the step times the drag's fastest
    /// rate, `2 |F_d| / |v_E|` times E's inverse effective mass (see
    /// [`Model::centroid_inverse_mass`]), at the state where the drag was stiffest (step
    /// ends, events and RK4 stages: see [`crate::integrate::rk4::step_sampling`]). Above
    /// [`RK4_STABILITY_LIMIT`] the fixed step does not resolve the impact. NaN with the
    /// adaptive method, 0 without drag.
    pub h_lambda: f64,
    /// Time series, if any were asked for.
    pub series: Option<Series>,
    /// The terms that acted, in the scene's order.
    pub terms: Vec<&'static str>,
}

/// `h lambda` beyond which the classical RK4 is unstable for a real, negative rate.
pub const RK4_STABILITY_LIMIT: f64 = 2.785;

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

/// The drag's stiffest moment of a run so far, and the coordinates where it was.
struct Stiffest<const N: usize> {
    best: DragStiffness,
    q: SVector<f64, N>,
}

impl<const N: usize> Stiffest<N> {
    #[inline]
    fn offer(&mut self, q: &SVector<f64, N>, s: &DragStiffness) {
        if s.beats(&self.best) {
            self.best = *s;
            self.q = *q;
        }
    }
}

/// Relative tolerance of event location, in units of the step.
const ROOT_TOL: f64 = 1e-13;
/// Events closer than this (in units of the step) to the earliest are handled with it.
const SIMULTANEOUS: f64 = 1e-9;
/// A velocity component above this [m/s] at a mode decision is moving, not at rest.
const SLIP_SPEED: f64 = 1e-9;
/// At most this many events within one grid step before the step is taken as it is.
const MAX_EVENTS_PER_STEP: usize = 32;

/// Kind of a switching function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Entry,
    Exit,
    SlipX,
    SlipY,
    StickX,
    StickY,
    Stop,
    Immersion,
    Cross,
}

/// The value of a switching function: non-negative while the mode holds; the event is
/// where it turns negative (the stop: where -v_Ty reaches zero).
fn switching<const N: usize>(kind: Kind, ci: usize, e: &Eval<N>, modes: &Modes) -> f64 {
    let c = &e.contacts[ci];
    match kind {
        Kind::Entry => c.lowest,
        Kind::Exit => -c.lowest,
        Kind::SlipX => modes[ci].sx.sign() * c.v_centroid.x,
        Kind::SlipY => modes[ci].sy.sign() * c.v_centroid.y,
        Kind::StickX => c.bound[0] - c.force.statics.x.abs(),
        Kind::StickY => c.bound[1] - c.force.statics.y.abs(),
        Kind::Stop => -c.v_tip.y,
        Kind::Cross => modes[ci].cross.sign() * c.cross,
        Kind::Immersion => {
            if modes[ci].full {
                -c.immersion_margin
            } else {
                c.immersion_margin
            }
        }
    }
}

/// The switching functions active under `modes`.
fn active<const N: usize>(model: &Model<N>, modes: &Modes, out: &mut Vec<(Kind, usize)>) {
    out.clear();
    let with_modes = model.sign_model == SignModel::Modes;
    for (ci, m) in modes.iter().enumerate().take(model.contacts.len()) {
        if !m.in_contact {
            out.push((Kind::Entry, ci));
            continue;
        }
        out.push((Kind::Exit, ci));
        out.push((Kind::Immersion, ci));
        if !m.stopped {
            out.push((Kind::Stop, ci));
        }
        if with_modes {
            // A contact held in both directions has v_E = 0: no drag, and e x v_E is
            // round-off whose sign would flip back and forth (Zeno events).
            let (own_x, own_y) = (
                model.forces.owns(Switch::SlipX),
                model.forces.owns(Switch::SlipY),
            );
            let held = own_x && own_y && m.sx == Slip::Stick && m.sy == Slip::Stick;
            if model.forces.owns(Switch::Cross) && !held {
                out.push((Kind::Cross, ci));
            }
            if own_x {
                out.push((
                    if m.sx == Slip::Stick {
                        Kind::StickX
                    } else {
                        Kind::SlipX
                    },
                    ci,
                ));
            }
            if own_y {
                out.push((
                    if m.sy == Slip::Stick {
                        Kind::StickY
                    } else {
                        Kind::SlipY
                    },
                    ci,
                ));
            }
        }
    }
}

/// Whether the function has crossed (the event happened by the end of the step).
#[inline]
fn crossed(kind: Kind, g1: f64) -> bool {
    if kind == Kind::Stop {
        g1 <= 0.0
    } else {
        g1 < 0.0
    }
}

/// Choose the mode of the static term along `axis` of contact `ci` at the state `at`,
/// where its velocity component is (about) zero. Karnopp: stick if the reaction that holds
/// the component is within the static bound, else slip the way the other forces push. A
/// component that already moves decidedly keeps its direction. At the surface the bound and
/// the reaction are both zero; there the decision is taken at `lookahead` (the end of the
/// step that found the event), where they have grown.
fn choose_slip<const N: usize>(
    model: &Model<N>,
    modes: &mut Modes,
    ci: usize,
    axis: usize,
    at: &State<N>,
    lookahead: &State<N>,
    stats: &mut Stats,
) {
    let mut trial = *modes;
    if axis == 0 {
        trial[ci].sx = Slip::Stick;
    } else {
        trial[ci].sy = Slip::Stick;
    }
    let judge = |s: &State<N>, stats: &mut Stats| {
        let e = model.eval(&s.q, &s.qd, &trial);
        stats.rhs_evals += 1;
        let c = e.contacts[ci];
        if axis == 0 {
            (c.force.statics.x, c.bound[0], c.v_centroid.x)
        } else {
            (c.force.statics.y, c.bound[1], c.v_centroid.y)
        }
    };
    let (mut reaction, mut bound, v) = judge(at, stats);
    if v.abs() <= SLIP_SPEED && bound == 0.0 {
        (reaction, bound, _) = judge(lookahead, stats);
    }
    let slip = if v.abs() > SLIP_SPEED {
        if v < 0.0 {
            Slip::Neg
        } else {
            Slip::Pos
        }
    } else if reaction.abs() <= bound {
        Slip::Stick
    } else if reaction > 0.0 {
        Slip::Neg
    } else {
        Slip::Pos
    };
    if axis == 0 {
        modes[ci].sx = slip;
    } else {
        modes[ci].sy = slip;
    }
}

/// The modes at a state where contact `ci` has just entered the sand (or starts in it).
fn enter_contact<const N: usize>(
    model: &Model<N>,
    modes: &mut Modes,
    ci: usize,
    y: &State<N>,
    probe: &State<N>,
    stats: &mut Stats,
) {
    modes[ci].in_contact = true;
    if model.sign_model != SignModel::Modes {
        return;
    }
    let e = model.eval(&y.q, &y.qd, modes);
    stats.rhs_evals += 1;
    let v = e.contacts[ci].v_centroid;
    // The drag's kink: the sign of e x v_E now, or where it is going.
    let mut cross = e.contacts[ci].cross;
    if cross == 0.0 {
        cross = model.eval(&probe.q, &probe.qd, modes).contacts[ci].cross;
        stats.rhs_evals += 1;
    }
    modes[ci].cross = if cross < 0.0 { Slip::Neg } else { Slip::Pos };
    for axis in 0..2 {
        let vk = if axis == 0 { v.x } else { v.y };
        let slip = if vk < 0.0 {
            Some(Slip::Neg)
        } else if vk > 0.0 {
            Some(Slip::Pos)
        } else {
            None
        };
        match slip {
            Some(s) if axis == 0 => modes[ci].sx = s,
            Some(s) => modes[ci].sy = s,
            None => choose_slip(model, modes, ci, axis, y, probe, stats),
        }
    }
}

/// Recorder of time series.
struct Recorder {
    on: Record,
    n_dof: usize,
    n_contacts: usize,
    n_links: usize,
    t: Vec<f64>,
    cols: Vec<Vec<f64>>,
    names: Vec<String>,
}

impl Recorder {
    fn new(on: Record, forces: &ForceSet, n_dof: usize, n_contacts: usize, n_links: usize) -> Self {
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
            if n_links > 1 {
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
            if self.n_links > 1 {
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

/// Run `model` from `y0` at `t = 0` with `options`.
pub fn solve<const N: usize>(
    model: &Model<N>,
    q0: SVector<f64, N>,
    qd0: SVector<f64, N>,
    options: &SolveOptions,
) -> Result<Outcome> {
    let nc = model.contacts.len();
    let dt = options.dt;
    let mut stats = Stats::default();
    let mut y = State {
        q: q0,
        qd: qd0,
        work: 0.0,
        dissipated: 0.0,
    };
    let mut modes: Modes = [ContactMode::default(); MAX_CONTACTS];

    // Initial modes: a tip below the surface, or at it and moving down, is in contact.
    let e_free = model.eval(&y.q, &y.qd, &modes);
    stats.rhs_evals += 1;
    for ci in 0..nc {
        let c = &e_free.contacts[ci];
        if c.lowest < 0.0 || (c.lowest == 0.0 && c.v_tip.y < 0.0) {
            // Judge a zero velocity component a little later: take a probe step free of
            // the static terms' signs (they are zero at the surface).
            let k1 = deriv_of(&y, &e_free);
            let probe = y.add(dt, &k1);
            enter_contact(model, &mut modes, ci, &y, &probe, &mut stats);
        }
    }

    let (ke0, pe0) = model.energies(&y.q, &y.qd);
    let energy_start = ke0 + pe0;
    let mut summaries: Vec<ContactSummary> = (0..nc)
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
    let link_energy = |y: &State<N>, i: usize| {
        let pose = model.mechanism.pose(&y.q);
        model
            .mechanism
            .link_energy(&pose, &y.qd, model.gravity(), i)
    };
    let link_e0: Vec<(f64, f64)> = (0..n_links).map(|i| link_energy(&y, i)).collect();
    let mut joints = vec![JointSummary::default(); n_links];
    let update_joints =
        |joints: &mut Vec<JointSummary>, y: &State<N>, e: &Eval<N>, modes: &Modes| {
            if n_links < 2 {
                return;
            }
            let f = model.joint_forces(&y.q, &y.qd, e, modes);
            for (i, j) in joints.iter_mut().enumerate() {
                j.f_max = j.f_max.max(f[i].norm());
                j.torque_max = j.torque_max.max(e.joint_torque[i].abs());
            }
        };

    let mut recorder = Recorder::new(options.record, &model.forces, N, nc, n_links);
    let stride = options.record.stride.max(1);
    let mut t = 0.0f64;
    // The evaluations at the step's start (`evals[cur]`) and end: an accepted step swaps
    // their roles instead of copying (an `Eval` holds every contact's findings).
    let mut evals = [model.eval(&y.q, &y.qd, &modes); 2];
    let mut cur = 0usize;
    stats.rhs_evals += 1;
    recorder.push(model, t, &y, &evals[cur], &modes);
    let n_grid = (options.t_end / dt).ceil() as u64;
    let mut n: u64 = 0;
    let mut events_this_step = 0usize;
    let mut funcs: Vec<(Kind, usize)> = Vec::with_capacity(4 * MAX_CONTACTS);
    // The modes `funcs` was listed for.
    let mut funcs_modes: Option<Modes> = None;

    // The drag's stiffest moment: ((|F_d| / |v_E|)^2, the state, the contact, v_E), over the
    // step ends, the events and the RK4 stages (within a step that does not resolve the
    // contact, the stages meet a stiffness the ends do not). Squared norms: a square root
    // only when a maximum is beaten.
    let mut stiffest = Stiffest {
        best: DragStiffness::default(),
        q: y.q,
    };
    let update_fd_max = |summaries: &mut Vec<ContactSummary>,
                         stiffest: &mut Stiffest<N>,
                         e: &Eval<N>,
                         q: &SVector<f64, N>,
                         modes: &Modes| {
        for (ci, s) in summaries.iter_mut().enumerate() {
            if !modes[ci].stopped {
                let c = &e.contacts[ci];
                let drag2 = c.force.dynamic.norm_squared();
                if drag2 > s.f_d_max * s.f_d_max {
                    s.f_d_max = drag2.sqrt();
                }
                stiffest.offer(q, &DragStiffness::of(ci, c));
            }
        }
    };

    let mut h_adapt = dt;
    let adaptive = matches!(options.method, Method::Dopri5 { .. });
    let status = loop {
        let finished = if adaptive {
            t >= options.t_end
        } else {
            n >= n_grid
        };
        if finished {
            break if options.end == EndCondition::Time {
                Status::EndTime
            } else {
                Status::NotStopped
            };
        }
        let t_next = if adaptive {
            let target = t + h_adapt;
            // Do not leave a sliver before t_end.
            if target >= options.t_end || options.t_end - target < 1e-3 * h_adapt {
                options.t_end
            } else {
                target
            }
        } else {
            ((n + 1) as f64 * dt).min(options.t_end)
        };
        let h = t_next - t;
        if !adaptive && h <= 1e-12 * dt {
            // An event landed on the grid point.
            n += 1;
            events_this_step = 0;
            continue;
        }
        let (head, tail) = evals.split_at_mut(1);
        let (e0, e1_slot) = if cur == 0 {
            (&head[0], &mut tail[0])
        } else {
            (&tail[0], &mut head[0])
        };
        let k1: Deriv<N> = deriv_of(&y, e0);
        let y1 = match options.method {
            Method::Rk4 => {
                let y1 = step_sampling(model, &modes, &y, &k1, h, |q, s| stiffest.offer(q, s));
                model.eval_into(&y1.q, &y1.qd, &modes, e1_slot);
                stats.rhs_evals += 4;
                y1
            }
            Method::Dopri5 { rtol, atol } => {
                let (y1, e1, err) = dopri5_step(model, &modes, &y, &k1, h, rtol, atol);
                stats.rhs_evals += 6;
                let factor = if err == 0.0 {
                    5.0
                } else {
                    (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
                };
                if err.is_nan() || err > 1.0 {
                    stats.rejected += 1;
                    h_adapt = h * factor.min(0.9);
                    if h_adapt.is_nan() || h_adapt <= 1e-14 * options.t_end.max(1.0) {
                        return Err(GranrsError::NonFinite {
                            t,
                            message: format!("step size underflow at t = {t} s (error norm {err})"),
                        });
                    }
                    continue;
                }
                h_adapt = h * factor;
                *e1_slot = e1;
                y1
            }
        };
        let e1: &Eval<N> = e1_slot;
        if !y1.is_finite() || !e1.qdd.iter().all(|v| v.is_finite()) {
            return Err(GranrsError::NonFinite {
                t,
                message: format!("state became non-finite in the step from t = {t} s (h = {h} s)"),
            });
        }

        // Which switching functions crossed? (The list changes only with the modes.)
        if funcs_modes != Some(modes) {
            active(model, &modes, &mut funcs);
            funcs_modes = Some(modes);
        }
        let mut earliest = f64::INFINITY;
        // (kind, contact, theta, g at the step's start, g at its end)
        let mut hits: Vec<(Kind, usize, f64, f64, f64)> = Vec::new();
        if events_this_step >= MAX_EVENTS_PER_STEP {
            stats.unresolved += 1;
        } else {
            for &(kind, ci) in &funcs {
                let g1 = switching(kind, ci, e1, &modes);
                if !crossed(kind, g1) {
                    continue;
                }
                let g0 = switching(kind, ci, e0, &modes).max(0.0);
                let theta = if g1 == 0.0 {
                    1.0
                } else if g0 == 0.0 {
                    0.0
                } else {
                    let dense = Hermite {
                        y0: y,
                        f0: k1,
                        y1,
                        f1: deriv_of(&y1, e1),
                        h,
                    };
                    let (theta, evals) = locate(
                        |th| {
                            let s = dense.at(th);
                            let e = model.eval(&s.q, &s.qd, &modes);
                            switching(kind, ci, &e, &modes)
                        },
                        g0,
                        g1,
                        ROOT_TOL,
                    );
                    stats.root_evals += evals;
                    stats.rhs_evals += evals;
                    theta
                };
                earliest = earliest.min(theta);
                hits.push((kind, ci, theta, g0, g1));
            }
        }

        if hits.is_empty() {
            // Accept the whole step.
            y = y1;
            cur = 1 - cur;
            // `evals[cur]` is the step's end: it tells when the projection has nothing to do.
            if model.sticking_may_drift(&evals[cur], &modes)
                && model.project_sticking(&y.q, &mut y.qd, &modes)
            {
                stats.rhs_evals += 1;
                model.eval_into(&y.q, &y.qd, &modes, &mut evals[cur]);
            }
            let e0 = &evals[cur];
            t = t_next;
            n += 1;
            events_this_step = 0;
            stats.steps += 1;
            update_fd_max(&mut summaries, &mut stiffest, e0, &y.q, &modes);
            update_joints(&mut joints, &y, e0, &modes);
            if n.is_multiple_of(stride as u64) {
                recorder.push(model, t, &y, e0, &modes);
            }
            continue;
        }

        // The interpolant's root is the step map's only to the interpolant's error: O(h^4)
        // where the held modes keep the right-hand side smooth through the step, but first
        // order where the step straddles a kink no mode holds: the cap of the immersed
        // length (l <= L, a sole box under the surface) and the exit, where the static
        // term's d^lambda has an unbounded derivative. Polish those events on the map
        // itself, h' -> g(step(y, h')), which is what the run will follow; its bracket [0, 1]
        // is the step's own ends. Every such hit is polished, so that mirror-image events
        // stay simultaneous.
        if options.method == Method::Rk4 && earliest > 0.0 && earliest < 1.0 {
            for hit in hits.iter_mut() {
                let (kind, ci, guess, g0, g1) = *hit;
                if !matches!(kind, Kind::Immersion | Kind::Exit) || guess <= 0.0 || guess >= 1.0 {
                    continue;
                }
                let mut map = |th: f64| {
                    let s = step(model, &modes, &y, &k1, th * h);
                    let e = model.eval(&s.q, &s.qd, &modes);
                    switching(kind, ci, &e, &modes)
                };
                let at = map(guess);
                let (theta, evals) = if at < 0.0 {
                    locate_in(&mut map, (0.0, g0), (guess, at), ROOT_TOL)
                } else {
                    locate_in(&mut map, (guess, at), (1.0, g1), ROOT_TOL)
                };
                stats.root_evals += evals + 1;
                stats.rhs_evals += 4 * (evals + 1);
                hit.2 = theta;
            }
            earliest = hits.iter().fold(f64::INFINITY, |m, hit| m.min(hit.2));
        }

        // Step to the earliest event, exactly: a real RK4 step of the located length.
        let h_star = earliest * h;
        let y_star = if earliest >= 1.0 {
            y1
        } else if h_star > 0.0 {
            match options.method {
                Method::Rk4 => {
                    stats.rhs_evals += 3;
                    step_sampling(model, &modes, &y, &k1, h_star, |q, s| stiffest.offer(q, s))
                }
                Method::Dopri5 { rtol, atol } => {
                    stats.rhs_evals += 6;
                    dopri5_step(model, &modes, &y, &k1, h_star, rtol, atol).0
                }
            }
        } else {
            y
        };
        let t_star = if earliest >= 1.0 { t_next } else { t + h_star };
        let e_star_old = model.eval(&y_star.q, &y_star.qd, &modes);
        stats.rhs_evals += 1;
        if h_star > 0.0 {
            stats.steps += 1;
            update_fd_max(
                &mut summaries,
                &mut stiffest,
                &e_star_old,
                &y_star.q,
                &modes,
            );
            update_joints(&mut joints, &y_star, &e_star_old, &modes);
        }
        // An event at the very start of the step is judged at the step's end.
        let probe = if earliest * h <= 1e-12 * dt {
            y1
        } else {
            y_star
        };
        let mut terminal = false;
        for &(kind, ci, theta, _, _) in &hits {
            if theta > earliest + SIMULTANEOUS {
                continue;
            }
            stats.events += 1;
            match kind {
                Kind::Entry => {
                    if summaries[ci].t_entry.is_nan() {
                        summaries[ci].t_entry = t_star;
                    }
                    enter_contact(model, &mut modes, ci, &y_star, &probe, &mut stats);
                }
                Kind::Exit => {
                    modes[ci].in_contact = false;
                    modes[ci].sx = Slip::Stick;
                    modes[ci].sy = Slip::Stick;
                }
                Kind::Immersion => modes[ci].full = !modes[ci].full,
                Kind::Cross => {
                    modes[ci].cross = if modes[ci].cross == Slip::Pos {
                        Slip::Neg
                    } else {
                        Slip::Pos
                    }
                }
                Kind::SlipX | Kind::StickX => {
                    choose_slip(model, &mut modes, ci, 0, &y_star, &y1, &mut stats)
                }
                Kind::SlipY | Kind::StickY => {
                    choose_slip(model, &mut modes, ci, 1, &y_star, &y1, &mut stats)
                }
                Kind::Stop => {
                    modes[ci].stopped = true;
                    let c = &e_star_old.contacts[ci];
                    let (ke, pe) = model.energies(&y_star.q, &y_star.qd);
                    let link = model.contacts[ci].link();
                    let s = &mut summaries[ci];
                    s.stopped = true;
                    s.t_s = t_star;
                    s.depth = (-c.tip.y).max(0.0);
                    s.dq = y_star.q[2 + link] - q0[2 + link];
                    s.omega_end = y_star.qd[2 + link];
                    s.f_s_end = c.force.static_magnitude();
                    s.f_r_end = c.force.total_magnitude();
                    s.d_ke = ke0 - ke;
                    s.d_pe = pe0 - pe;
                    s.d_e = s.d_ke + s.d_pe;
                    s.work_sand = y_star.work;
                    s.tip_end = c.tip;
                    let (lk, lp) = link_energy(&y_star, link);
                    s.link_d_ke = link_e0[link].0 - lk;
                    s.link_d_pe = link_e0[link].1 - lp;
                    terminal |= match options.end {
                        EndCondition::FirstStop => true,
                        EndCondition::AllStops => modes[..nc].iter().all(|m| m.stopped),
                        EndCondition::Time => false,
                    };
                }
            }
        }
        y = y_star;
        t = t_star;
        events_this_step += 1;
        if terminal {
            recorder.push(model, t, &y, &e_star_old, &modes);
            break Status::Stopped;
        }
        model.project_sticking(&y.q, &mut y.qd, &modes);
        model.eval_into(&y.q, &y.qd, &modes, &mut evals[cur]);
        stats.rhs_evals += 1;
        recorder.push(model, t, &y, &evals[cur], &modes);
    };

    // Contacts without a stop report their state at the end.
    let e_end = model.eval(&y.q, &y.qd, &modes);
    let (ke, pe) = model.energies(&y.q, &y.qd);
    for (ci, s) in summaries.iter_mut().enumerate() {
        if s.stopped {
            continue;
        }
        let c = &e_end.contacts[ci];
        let link = model.contacts[ci].link();
        s.depth = (-c.tip.y).max(0.0);
        s.dq = y.q[2 + link] - q0[2 + link];
        s.omega_end = y.qd[2 + link];
        s.f_s_end = c.force.static_magnitude();
        s.f_r_end = c.force.total_magnitude();
        s.d_ke = ke0 - ke;
        s.d_pe = pe0 - pe;
        s.d_e = s.d_ke + s.d_pe;
        s.work_sand = y.work;
        s.tip_end = c.tip;
        let (lk, lp) = link_energy(&y, link);
        s.link_d_ke = link_e0[link].0 - lk;
        s.link_d_pe = link_e0[link].1 - lp;
    }
    if status != Status::Stopped && options.record.any() && recorder.t.last() != Some(&t) {
        recorder.push(model, t, &y, &e_end, &modes);
    }
    let h_lambda = if adaptive {
        f64::NAN
    } else if stiffest.best.k2() > 0.0 {
        let (k2, q, ci, v) = (
            stiffest.best.k2(),
            stiffest.q,
            stiffest.best.contact,
            stiffest.best.v,
        );
        dt * drag_rate(
            &model.centroid_inverse_mass(&q, ci),
            k2.sqrt(),
            v.normalize(),
        )
    } else {
        0.0
    };
    let out = Outcome {
        h_lambda,
        status,
        t_final: t,
        stats,
        contacts: summaries,
        energy_start,
        energy_end: ke + pe,
        work_sand: y.work,
        dissipated: y.dissipated,
        joints,
        series: recorder.finish(),
        terms: model.forces.names.clone(),
    };
    check_outcome(model, &out)?;
    Ok(out)
}

/// How many times the body's energy scale a run may gain before it counts as diverged.
/// With the force at the tip the sand can feed energy in; over the property tests' domain
/// the gain stayed below 0.11 of that scale (docs/hard_cases.md), so this is 90x margin.
pub const DIVERGENCE_FACTOR: f64 = 10.0;

/// Refuse an outcome that is not a physical answer: a non-finite result, or a run whose
/// mechanical energy grew past [`DIVERGENCE_FACTOR`] times the body's energy scale
/// (|E(0)| + M g l, with M the total mass and l the links' size). Both happen only when the
/// step is beyond RK4's stability limit for the scene's contact stiffness; the error says so
/// instead of returning a "stopped" run with enormous numbers.
fn check_outcome<const N: usize>(model: &Model<N>, out: &Outcome) -> Result<()> {
    let fail = |message: String| {
        Err(GranrsError::NonFinite {
            t: out.t_final,
            message,
        })
    };
    for (i, c) in out.contacts.iter().enumerate() {
        let values = [
            ("depth", c.depth),
            ("dq", c.dq),
            ("omega_end", c.omega_end),
            ("F_d_max", c.f_d_max),
            ("F_s_end", c.f_s_end),
            ("F_r_end", c.f_r_end),
            ("dKE", c.d_ke),
            ("dPE", c.d_pe),
            ("work_sand", c.work_sand),
            ("x_tip_end", c.tip_end.x),
        ];
        if let Some((name, v)) = values.iter().find(|(_, v)| !v.is_finite()) {
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
