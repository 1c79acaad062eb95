//! Several runs of the free link stepped at once, one per SIMD lane: the sweep's fast path.
//! The lanes run one law's arithmetic at a time: the thesis's terms (any of them, with any
//! coefficients per lane) or one law of terms that read the frame (`rft`, `poncelet`,
//! `rft_inertial`: `dynamics::rod_lanes::FrameLaw`), its terms and element counts shared by
//! the four, its numbers per lane.
//!
//! Layout (structure of arrays): each lane holds one scene; the state (q, q', work), the
//! first stage, the step size, the held modes and the scene's parameters are each one
//! `F64x4` (`RodParams<F64x4>`, `RodModes<F64x4>`), so one instruction advances the same
//! quantity of four scenes. A step's four RK4 stages and its end evaluation run in the lanes
//! ([`lane_step`], through `dynamics::rod_lanes`). A step that meets nothing is accepted
//! there ([`Run::accept_plain`]: every pivot clear, the end finite, no switching function
//! crossed, judged by the events' own functions on the lane's values): the observer is
//! shown its stages and end, and the run's next step starts from its lane, with no round trip
//! through the run's scalar state. Any other step is the run's own, on the scalar path
//! ([`Run::after_step`]): a lane whose step meets an event (an entry, a switch, the end of a
//! stick, the stop) has it located, the step cut there and the modes changed by the same
//! code as a lone run. A lane whose step the lanes do not cover (a mode that sticks in x and
//! in y, a zero pivot) takes that step on the scalar path, and so does a run that sticks,
//! records series or has a drive ahead at every step (its accepted step needs more than the
//! lanes keep). A lane whose run ends takes the next scene at once, so lanes ending at
//! different times never wait for each other.
//!
//! The lanes compute each operation of the scalar path in its order (`F64x4` is four
//! IEEE f64 operations, with libm's `sin_cos` and `pow` per lane), so a run's outcome is the
//! same bit for bit whether it ran in a lane or alone (tests).

use nalgebra::{SVector, Vector2};

use super::events::SwitchInputs;
use super::outcome::Outcome;
use super::solve::{solve, Run, SolveOptions};
use super::stepper::{Deriv, Method, State};
use crate::dynamics::rod_lanes::{pivot_ok, rod_eval_law, same_law, RodEval, RodModes, RodParams};
use crate::dynamics::{DragStiffness, Model};
use crate::error::Result;
use crate::forces::Real;
use crate::simd::{F64x4, LANES};

/// One step of several runs in lanes: its start, first stage and size, per lane.
#[derive(Debug, Clone, Copy)]
pub struct LaneStart<F> {
    /// Coordinates at the start.
    pub q: [F; 3],
    /// Rates at the start.
    pub qd: [F; 3],
    /// Work at the start.
    pub work: F,
    /// Dissipation at the start.
    pub dissipated: F,
    /// The first stage: q'' and the power.
    pub qdd1: [F; 3],
    /// See `qdd1`.
    pub power1: F,
    /// The joints' power at the first stage (0 for a free link, carried as the scalar path
    /// carries it).
    pub joint_power1: F,
    /// Step size [s].
    pub h: F,
}

impl LaneStart<F64x4> {
    /// Every lane `x`.
    fn splat(x: f64) -> Self {
        let s = F64x4::splat(x);
        LaneStart {
            q: [s; 3],
            qd: [s; 3],
            work: s,
            dissipated: s,
            qdd1: [s; 3],
            power1: s,
            joint_power1: s,
            h: s,
        }
    }

    /// Every field's lane `i`, as `f` gives it from that field.
    #[inline(always)]
    fn each(&mut self, mut f: impl FnMut(&mut F64x4, usize)) {
        for k in 0..3 {
            f(&mut self.q[k], k);
            f(&mut self.qd[k], 3 + k);
            f(&mut self.qdd1[k], 6 + k);
        }
        f(&mut self.work, 9);
        f(&mut self.dissipated, 10);
        f(&mut self.power1, 11);
        f(&mut self.joint_power1, 12);
        f(&mut self.h, 13);
    }

    /// Lane `i` becomes `s`.
    #[inline]
    fn set(&mut self, i: usize, s: &LaneStart<f64>) {
        let v = [
            s.q[0],
            s.q[1],
            s.q[2],
            s.qd[0],
            s.qd[1],
            s.qd[2],
            s.qdd1[0],
            s.qdd1[1],
            s.qdd1[2],
            s.work,
            s.dissipated,
            s.power1,
            s.joint_power1,
            s.h,
        ];
        self.each(|x, k| x.0[i] = v[k]);
    }

    /// Lane `i` starts the next step where `end`'s lane `i` ended (as [`Run::lane_start`]
    /// would give it after the step was accepted; the step size is set apart).
    #[inline]
    fn take_end(&mut self, i: usize, end: &LaneEnd<F64x4>) {
        for k in 0..3 {
            self.q[k].0[i] = end.q[k].0[i];
            self.qd[k].0[i] = end.qd[k].0[i];
            self.qdd1[k].0[i] = end.eval.qdd[k].0[i];
        }
        self.work.0[i] = end.work.0[i];
        self.dissipated.0[i] = end.dissipated.0[i];
        self.power1.0[i] = end.eval.power.0[i];
        // `RodEval::write` gives the end's evaluation no joint power.
        self.joint_power1.0[i] = 0.0;
    }

    /// Lane `i` takes lane `j`'s values.
    fn copy_lane(&mut self, i: usize, j: usize) {
        self.each(|x, _| x.0[i] = x.0[j]);
    }
}

/// What [`lane_step`] returns: the end state, its evaluation, each later stage's
/// coordinates and evaluation (the observer is shown them), and whether every stage's
/// pivot was clear (else the scalar path redoes the step).
#[derive(Debug, Clone, Copy)]
pub struct LaneEnd<F> {
    /// Coordinates at the end.
    pub q: [F; 3],
    /// Rates at the end.
    pub qd: [F; 3],
    /// Work at the end.
    pub work: F,
    /// Dissipation at the end.
    pub dissipated: F,
    /// The evaluation at the end.
    pub eval: RodEval<F>,
    /// Stages 2, 3 and 4: what the observer is shown of them.
    pub stages: [LaneStage<F>; 3],
    /// What the observer is shown of the end (read when the lanes accept the step,
    /// [`Run::accept_plain`]).
    pub last: LaneStage<F>,
}

/// What the observer is shown of an RK4 stage (see [`super::stepper::step_sampling`]),
/// and whether its sticking row's pivot was clear.
#[derive(Debug, Clone, Copy)]
pub struct LaneStage<F> {
    /// The stage's coordinates.
    pub q: [F; 3],
    /// |F_d|^2 and |v_E|^2, as [`DragStiffness::of`] computes them.
    pub drag2: F,
    /// See `drag2`.
    pub speed2: F,
    /// v_E.
    pub v: [F; 2],
    /// The sticking row's pivot ([`RodEval::pivot`]).
    pub pivot: F,
}

impl<F: Real> LaneStage<F> {
    #[inline(always)]
    fn of(q: [F; 3], e: &RodEval<F>) -> Self {
        let zero = F::splat(0.0);
        let (d, v) = (e.dynamic, e.v_centroid);
        LaneStage {
            q,
            drag2: zero + (d[0] * d[0] + d[1] * d[1]),
            speed2: zero + (v[0] * v[0] + v[1] * v[1]),
            v,
            pivot: e.pivot,
        }
    }
}

/// One RK4 step ([`super::stepper::step_sampling`] and the end evaluation of
/// [`super::stepper::full_step`]) in `F`, in the scalar path's order of operations.
#[inline(always)]
pub fn lane_step<F: Real, const FRAME: bool>(
    p: &RodParams<F>,
    m: &RodModes<F>,
    s: &LaneStart<F>,
) -> LaneEnd<F> {
    let rod_eval = rod_eval_law::<F, FRAME>;
    let h = s.h;
    let half = F::splat(0.5) * h;
    let zero = F::splat(0.0);
    // A stage's state `y + c k`, as `State::add`.
    let add = |c: F, k_q: &[F; 3], k_qd: &[F; 3], k_w: F, k_d: F| {
        (
            [
                s.q[0] + c * k_q[0],
                s.q[1] + c * k_q[1],
                s.q[2] + c * k_q[2],
            ],
            [
                s.qd[0] + c * k_qd[0],
                s.qd[1] + c * k_qd[1],
                s.qd[2] + c * k_qd[2],
            ],
            s.work + c * k_w,
            s.dissipated + c * k_d,
        )
    };
    // k1: (q' = qd, q'' = qdd1, power1, joint power).
    let (q2, qd2, _, _) = add(half, &s.qd, &s.qdd1, s.power1, s.joint_power1);
    let e2 = rod_eval(p, m, &q2, &qd2);
    let (q3, qd3, _, _) = add(half, &qd2, &e2.qdd, e2.power, zero);
    let e3 = rod_eval(p, m, &q3, &qd3);
    let (q4, qd4, _, _) = add(h, &qd3, &e3.qdd, e3.power, zero);
    let e4 = rod_eval(p, m, &q4, &qd4);
    let s6 = h / F::splat(6.0);
    let two = F::splat(2.0);
    let comb = |y: F, k1: F, k2: F, k3: F, k4: F| y + s6 * (k1 + two * k2 + two * k3 + k4);
    let q = [
        comb(s.q[0], s.qd[0], qd2[0], qd3[0], qd4[0]),
        comb(s.q[1], s.qd[1], qd2[1], qd3[1], qd4[1]),
        comb(s.q[2], s.qd[2], qd2[2], qd3[2], qd4[2]),
    ];
    let qd = [
        comb(s.qd[0], s.qdd1[0], e2.qdd[0], e3.qdd[0], e4.qdd[0]),
        comb(s.qd[1], s.qdd1[1], e2.qdd[1], e3.qdd[1], e4.qdd[1]),
        comb(s.qd[2], s.qdd1[2], e2.qdd[2], e3.qdd[2], e4.qdd[2]),
    ];
    let work = comb(s.work, s.power1, e2.power, e3.power, e4.power);
    let dissipated = comb(s.dissipated, s.joint_power1, zero, zero, zero);
    let eval = rod_eval(p, m, &q, &qd);
    LaneEnd {
        q,
        qd,
        work,
        dissipated,
        eval,
        stages: [
            LaneStage::of(q2, &e2),
            LaneStage::of(q3, &e3),
            LaneStage::of(q4, &e4),
        ],
        last: LaneStage::of(q, &eval),
    }
}

impl LaneEnd<F64x4> {
    /// Lane `i`.
    #[inline]
    pub fn lane(&self, i: usize) -> LaneEnd<f64> {
        let l = |x: F64x4| x.0[i];
        let l3 = |x: [F64x4; 3]| [x[0].0[i], x[1].0[i], x[2].0[i]];
        LaneEnd {
            q: l3(self.q),
            qd: l3(self.qd),
            work: l(self.work),
            dissipated: l(self.dissipated),
            eval: self.eval.lane(i),
            stages: [
                self.stages[0].lane(i),
                self.stages[1].lane(i),
                self.stages[2].lane(i),
            ],
            last: self.last.lane(i),
        }
    }
}

impl LaneStage<F64x4> {
    /// What the observer is shown of lane `i`: the drag's stiffness, and the coordinates
    /// (read only when asked for).
    #[inline(always)]
    pub fn seen_in_lane<const N: usize>(
        &self,
        i: usize,
    ) -> (impl FnOnce() -> SVector<f64, N> + '_, DragStiffness) {
        let l = move |x: F64x4| x.0[i];
        (
            move || SVector::from_fn(|k, _| l(self.q[k])),
            DragStiffness {
                drag2: l(self.drag2),
                speed2: l(self.speed2),
                contact: 0,
                v: Vector2::new(l(self.v[0]), l(self.v[1])),
            },
        )
    }

    /// Lane `i`.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> LaneStage<f64> {
        let l = |x: F64x4| x.0[i];
        LaneStage {
            q: [l(self.q[0]), l(self.q[1]), l(self.q[2])],
            drag2: l(self.drag2),
            speed2: l(self.speed2),
            v: [l(self.v[0]), l(self.v[1])],
            pivot: l(self.pivot),
        }
    }
}

impl LaneStage<f64> {
    /// What the observer is shown: the coordinates and the drag's stiffness.
    #[inline(always)]
    pub fn seen<const N: usize>(&self) -> (SVector<f64, N>, DragStiffness) {
        (
            SVector::from_fn(|i, _| self.q[i]),
            DragStiffness {
                drag2: self.drag2,
                speed2: self.speed2,
                contact: 0,
                v: Vector2::new(self.v[0], self.v[1]),
            },
        )
    }
}

/// Lane `i` of an evaluation in the lanes, as the switching functions read its contact
/// ([`RodEval::write`] gives a [`crate::dynamics::ContactEval`] these same values).
pub(super) struct LaneContact<'a> {
    eval: &'a RodEval<F64x4>,
    i: usize,
}

impl<'a> LaneContact<'a> {
    /// Lane `i` of `eval`.
    #[inline(always)]
    pub(super) fn new(eval: &'a RodEval<F64x4>, i: usize) -> Self {
        LaneContact { eval, i }
    }

    #[inline(always)]
    fn at(&self, x: F64x4) -> f64 {
        x.0[self.i]
    }
}

impl SwitchInputs for LaneContact<'_> {
    #[inline(always)]
    fn lowest(&self) -> f64 {
        self.at(self.eval.lowest)
    }
    #[inline(always)]
    fn v_centroid(&self) -> [f64; 2] {
        [
            self.at(self.eval.v_centroid[0]),
            self.at(self.eval.v_centroid[1]),
        ]
    }
    #[inline(always)]
    fn bound(&self) -> [f64; 2] {
        [self.at(self.eval.bound[0]), self.at(self.eval.bound[1])]
    }
    #[inline(always)]
    fn statics(&self) -> [f64; 2] {
        [self.at(self.eval.statics[0]), self.at(self.eval.statics[1])]
    }
    #[inline(always)]
    fn v_tip_y(&self) -> f64 {
        self.at(self.eval.v_tip[1])
    }
    #[inline(always)]
    fn cross(&self) -> f64 {
        self.at(self.eval.cross)
    }
    #[inline(always)]
    fn immersion_margin(&self) -> f64 {
        self.at(self.eval.margin)
    }
    #[inline(always)]
    fn corner_y(&self, _k: usize) -> f64 {
        // A rod has no corners (`RodEval::write` writes zeros).
        0.0
    }
}

impl LaneEnd<f64> {
    /// Whether every stage's and the end's sticking pivot is clear ([`pivot_ok`]): else
    /// the scalar path redoes the step.
    #[inline]
    pub fn pivots_ok(&self) -> bool {
        self.stages.iter().all(|st| pivot_ok(st.pivot)) && pivot_ok(self.eval.pivot)
    }

    /// The end state (of a body with `N` = 3 coordinates).
    #[inline]
    pub fn state<const N: usize>(&self) -> State<N> {
        State {
            q: SVector::from_fn(|i, _| self.q[i]),
            qd: SVector::from_fn(|i, _| self.qd[i]),
            work: self.work,
            dissipated: self.dissipated,
        }
    }

    /// What the observer is shown of stage `k` (2, 3, 4): its coordinates and stiffness.
    #[inline]
    pub fn stage<const N: usize>(&self, k: usize) -> (SVector<f64, N>, DragStiffness) {
        self.stages[k].seen()
    }
}

/// [`lane_step`] compiled for the baseline target.
#[inline(never)]
fn lane_step_base<F: Real, const FRAME: bool>(
    p: &RodParams<F>,
    m: &RodModes<F>,
    s: &LaneStart<F>,
) -> LaneEnd<F> {
    lane_step::<F, FRAME>(p, m, s)
}

/// [`lane_step`] compiled with AVX2 (256-bit registers for the lanes; for one lane, the
/// three-operand encodings).
///
/// # Safety
/// The CPU must have AVX2 ([`crate::simd::avx2`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline(never)]
unsafe fn lane_step_avx2<F: Real, const FRAME: bool>(
    p: &RodParams<F>,
    m: &RodModes<F>,
    s: &LaneStart<F>,
) -> LaneEnd<F> {
    lane_step::<F, FRAME>(p, m, s)
}

/// How the lanes run: with AVX2 where the CPU has it, else the baseline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LaneIsa {
    /// The baseline target (SSE2 on x86-64, NEON on arm64).
    Base,
    /// AVX2.
    Avx2,
}

impl LaneIsa {
    /// The best this CPU runs.
    pub fn detect() -> Self {
        if crate::simd::avx2() {
            LaneIsa::Avx2
        } else {
            LaneIsa::Base
        }
    }

    /// [`lane_step`] in `F` (four lanes, or one for a run's scalar path) as this CPU runs
    /// it best.
    #[inline]
    pub(crate) fn step<F: Real>(
        self,
        p: &RodParams<F>,
        m: &RodModes<F>,
        s: &LaneStart<F>,
    ) -> LaneEnd<F> {
        match self {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `Avx2` comes from `detect`, which found AVX2 on this CPU (this method
            // is the crate's own, so no caller outside it picks the variant).
            LaneIsa::Avx2 if p.frame.is_some() => unsafe { lane_step_avx2::<F, true>(p, m, s) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            LaneIsa::Avx2 => unsafe { lane_step_avx2::<F, false>(p, m, s) },
            _ if p.frame.is_some() => lane_step_base::<F, true>(p, m, s),
            _ => lane_step_base::<F, false>(p, m, s),
        }
    }
}

/// A scene for [`run_lanes`]: its tag (given back with its outcome), model, start and
/// options.
pub type LaneScene<T> = (T, Model<3>, SVector<f64, 3>, SVector<f64, 3>, SolveOptions);

/// Whether the lanes cover a run of `model` with `options` (else it runs alone).
pub fn covered(model: &Model<3>, options: &SolveOptions) -> bool {
    options.method == Method::Rk4 && RodParams::of(model).is_some()
}

/// A run in a lane.
struct Slot<T> {
    tag: T,
    model: Model<3>,
    run: Run<3>,
    /// Whether the lanes may accept its plain steps ([`Run::may_stay_in_lanes`]), as of its
    /// last step on its own (it holds while the lanes accept its steps: nothing changes
    /// then that it depends on).
    may_stay: bool,
}

/// Scenes that wait for the lanes to take their law, at most (beyond this, a scene under
/// another law than the lanes' leaves its lane empty until the lanes have drained).
const WAITING: usize = 4 * LANES;

/// What [`run_lanes`] did with its scenes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LaneCounts {
    /// Runs it ran alone from start to end (not covered, or not RK4).
    pub alone: usize,
    /// Runs it took into the lanes.
    pub in_lanes: usize,
    /// Times the lanes took another law (a sweep that mixes laws).
    pub law_changes: usize,
}

/// Run every scene `next` gives, four at a time in lanes (`isa`), and hand each outcome
/// to `done` with its tag as the run ends (not in input order). A scene the lanes do not
/// cover ([`covered`]) runs alone, on the scalar path, as [`solve`] runs it.
///
/// The lanes run one law's arithmetic at a time (the thesis's terms with any coefficients
/// per lane, or one [`crate::dynamics::rod_lanes::FrameLaw`]'s terms and element counts,
/// with any numbers per lane: [`crate::dynamics::rod_lanes::same_law`]). A scene under
/// another law waits (up to [`WAITING`] of them; its lane stays empty) until the lanes have
/// drained, and then they take its law.
///
/// A step that meets nothing (no event, every pivot clear) of a run that
/// [`Run::may_stay_in_lanes`] is accepted by the lanes ([`Run::accept_plain`]): the run's next
/// step starts where its lane ended, and the run takes back the end's evaluation
/// ([`Run::resume`]) only when it next steps on its own, or ends.
pub fn run_lanes<T>(
    isa: LaneIsa,
    mut next: impl FnMut() -> Option<LaneScene<T>>,
    mut done: impl FnMut(T, Result<Outcome>),
) -> LaneCounts {
    let mut slots: [Option<Slot<T>>; LANES] = std::array::from_fn(|_| None);
    let mut params: Option<RodParams<F64x4>> = None;
    let mut feed = Feed {
        waiting: std::collections::VecDeque::new(),
        empty: false,
        counts: LaneCounts::default(),
    };
    // Each lane's step start and held modes; a run the lanes keep ([`Run::in_lanes`]) starts
    // its next step from its lane here, and `kept` holds its last end's evaluation.
    let mut start = LaneStart::<F64x4>::splat(0.0);
    let mut lane_modes = RodModes::<F64x4>::splat(0.0);
    let mut kept: Option<RodEval<F64x4>> = None;
    let resume = |run: &mut Run<3>, kept: &Option<RodEval<F64x4>>, i: usize| {
        if let (true, Some(e)) = (run.in_lanes(), kept) {
            run.resume(&e.lane(i));
        }
    };
    loop {
        // Fill the lanes and find each run's next step.
        let mut h = [0.0; LANES];
        let mut live = [false; LANES];
        for i in 0..LANES {
            loop {
                if slots[i].is_none() {
                    match feed.take(i, &slots, &mut params, &mut next, &mut done) {
                        Some(slot) => slots[i] = Some(slot),
                        None => break,
                    }
                }
                let Some(slot) = slots[i].as_mut() else {
                    break;
                };
                match slot.run.next_step(&slot.model) {
                    Some(hi) => {
                        h[i] = hi;
                        live[i] = true;
                        break;
                    }
                    None => {
                        if let Some(mut s) = slots[i].take() {
                            resume(&mut s.run, &kept, i);
                            let out = s.run.finish(&s.model);
                            done(s.tag, out);
                        }
                    }
                }
            }
        }
        if !live.iter().any(|&l| l) {
            if feed.waiting.is_empty() {
                break;
            }
            continue;
        }
        let Some(params) = params.as_ref() else {
            break;
        };

        // Gather the lanes whose mode the lanes cover (a run the lanes keep is there
        // already); the others step alone.
        let mut k1s: [Option<Deriv<3>>; LANES] = [None; LANES];
        let mut stepped = [false; LANES];
        for i in 0..LANES {
            if !live[i] {
                continue;
            }
            let Some(slot) = slots[i].as_mut() else {
                continue;
            };
            if slot.run.in_lanes() {
                start.h.0[i] = h[i];
                stepped[i] = true;
                continue;
            }
            match slot.run.lane_start(h[i]) {
                Some((s, m, k1)) => {
                    start.set(i, &s);
                    lane_modes.set(i, &m);
                    k1s[i] = Some(k1);
                    stepped[i] = true;
                    slot.may_stay = slot.run.may_stay_in_lanes(&slot.model);
                }
                None => {
                    if let Err(e) = slot.run.step_general(&slot.model, h[i]) {
                        fail(&mut slots[i], e, &mut done);
                    }
                }
            }
        }
        let Some(first) = (0..LANES).find(|&i| stepped[i]) else {
            continue;
        };
        // One run left in the lanes (a batch's tail, a one-scene sweep): its step on the
        // scalar path, the same arithmetic in one lane, without the idle lanes' `pow` and
        // `sin_cos` (libm's, called lane by lane).
        if stepped.iter().filter(|&&s| s).count() == 1 {
            if let Some(slot) = slots[first].as_mut() {
                resume(&mut slot.run, &kept, first);
                if let Err(e) = slot.run.step(&slot.model, h[first]) {
                    fail(&mut slots[first], e, &mut done);
                }
            }
            continue;
        }
        // An idle lane repeats the first one's step, with its parameters (its results are
        // dropped).
        let end = if stepped.iter().all(|&s| s) {
            isa.step(params, &lane_modes, &start)
        } else {
            let mut lane_params = *params;
            for i in (0..LANES).filter(|&i| !stepped[i]) {
                copy_lane(&mut lane_params, i, first);
                start.copy_lane(i, first);
                lane_modes.copy_lane(i, first);
            }
            isa.step(&lane_params, &lane_modes, &start)
        };

        for i in 0..LANES {
            if !stepped[i] {
                continue;
            }
            let Some(slot) = slots[i].as_mut() else {
                continue;
            };
            if slot.may_stay && slot.run.accept_plain(&slot.model, &end, i) {
                start.take_end(i, &end);
                continue;
            }
            resume(&mut slot.run, &kept, i);
            let k1 = k1s[i].unwrap_or_else(|| slot.run.first_stage());
            let result = slot
                .run
                .lane_step_done(&slot.model, h[i], &k1, &end.lane(i))
                .unwrap_or_else(|| slot.run.step_general(&slot.model, h[i]));
            if let Err(e) = result {
                fail(&mut slots[i], e, &mut done);
            }
        }
        kept = Some(end.eval);
    }
    feed.counts
}

/// Where [`run_lanes`]'s lanes take their scenes from: the batch, and the scenes that wait
/// for the lanes to take their law.
struct Feed<T> {
    waiting: std::collections::VecDeque<(LaneScene<T>, RodParams<f64>)>,
    /// Whether the batch has run dry.
    empty: bool,
    counts: LaneCounts,
}

impl<T> Feed<T> {
    /// The run lane `i` takes (its slot is empty; `slots` are the lanes', `params` their
    /// parameters): a waiting scene under the lanes' law, or, the lanes idle, the first
    /// waiting one (its law becomes theirs); else the batch's next, if under the lanes'
    /// law. A scene the lanes do not cover runs alone here. `None`: the lane stays empty
    /// this step (the batch is dry, or a scene under another law now waits). Out of line:
    /// it runs once a scene, not once a step.
    #[inline(never)]
    fn take(
        &mut self,
        i: usize,
        slots: &[Option<Slot<T>>; LANES],
        params: &mut Option<RodParams<F64x4>>,
        next: &mut impl FnMut() -> Option<LaneScene<T>>,
        done: &mut impl FnMut(T, Result<Outcome>),
    ) -> Option<Slot<T>> {
        let idle = slots.iter().all(Option::is_none);
        loop {
            let waited = match params.as_ref().map(|p| p.frame) {
                _ if idle && !self.waiting.is_empty() => self.waiting.pop_front(),
                Some(f) => self
                    .waiting
                    .iter()
                    .position(|(_, p)| same_law(&p.frame, &f))
                    .and_then(|k| self.waiting.remove(k)),
                None => None,
            };
            let ((tag, model, q0, qd0, options), p) = match waited {
                Some(w) => w,
                None => {
                    if self.empty || self.waiting.len() >= WAITING {
                        return None;
                    }
                    let Some(scene) = next() else {
                        self.empty = true;
                        return None;
                    };
                    match RodParams::of(&scene.1) {
                        Some(p) if scene.4.method == Method::Rk4 => (scene, p),
                        _ => {
                            let (tag, model, q0, qd0, options) = scene;
                            done(tag, solve(&model, q0, qd0, &options));
                            self.counts.alone += 1;
                            continue;
                        }
                    }
                }
            };
            match params {
                Some(lanes) if same_law(&lanes.frame, &p.frame) => lanes.set(i, &p),
                Some(lanes) if idle => {
                    *lanes = RodParams::splat(&p);
                    self.counts.law_changes += 1;
                }
                Some(_) => {
                    // Another law: it waits, and this lane stays empty, so that the lanes
                    // drain and can take it.
                    self.waiting.push_back(((tag, model, q0, qd0, options), p));
                    return None;
                }
                None => *params = Some(RodParams::splat(&p)),
            }
            self.counts.in_lanes += 1;
            let run = Run::new(&model, q0, qd0, &options);
            return Some(Slot {
                tag,
                model,
                run,
                may_stay: false,
            });
        }
    }
}

/// Lane `i` of `p` takes lane `j`'s parameters.
fn copy_lane(p: &mut RodParams<F64x4>, i: usize, j: usize) {
    let one = |x: &mut F64x4| x.0[i] = x.0[j];
    one(&mut p.mass);
    one(&mut p.g);
    one(&mut p.inv_m);
    one(&mut p.inv_i);
    one(&mut p.tip[0]);
    one(&mut p.tip[1]);
    one(&mut p.length);
    one(&mut p.diameter);
    one(&mut p.section);
    one(&mut p.at_centroid);
    one(&mut p.medium.rho_g);
    one(&mut p.medium.g);
    one(&mut p.eta_d);
    one(&mut p.eta_h);
    one(&mut p.eta_v);
    one(&mut p.lam);
    one(&mut p.unheld);
    one(&mut p.smooth);
    one(&mut p.eps);
    p.frame_numbers.each(one);
}

/// A run that failed leaves its lane with its error.
fn fail<T>(
    slot: &mut Option<Slot<T>>,
    e: crate::GranrsError,
    done: &mut impl FnMut(T, Result<Outcome>),
) {
    if let Some(s) = slot.take() {
        done(s.tag, Err(e));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forces::{ForceSet, TermSpec};
    use crate::spec::Value;

    /// A frame law: `rft` with `rft_inertial`, or `poncelet` (with `gravity`).
    fn frame_law(rft: bool) -> Vec<TermSpec> {
        let mut law = vec![TermSpec::new("gravity", &[])];
        if rft {
            law.push(TermSpec::new("rft", &[("zeta", 1e6)]));
            law.push(TermSpec::new("rft_inertial", &[]));
        } else {
            law.push(TermSpec::new("poncelet", &[("c", 0.8), ("k", 150.0)]));
        }
        law
    }

    /// The free link at `q` deg and `v0` m/s under `law` (the thesis's by default).
    fn scene(q: f64, v0: f64, law: Option<&[TermSpec]>) -> crate::bodies::LinkageScene {
        let mut spec = crate::spec::free_link_spec();
        spec.set("q_deg", Value::Num(q));
        spec.set("v0", Value::Num(v0));
        let Ok(mut s) = spec.build() else {
            panic!("the free link does not build");
        };
        if let Some(law) = law {
            s.forces = ForceSet::build(law, 1).unwrap();
        }
        s
    }

    /// Each lean step's start of a run of [`scene`], with its parameters and modes.
    fn lane_starts(
        q: f64,
        v0: f64,
        law: Option<&[TermSpec]>,
    ) -> Vec<(RodParams<f64>, RodModes<f64>, LaneStart<f64>)> {
        let s = scene(q, v0, law);
        let (model, (q0, qd0)) = (s.model::<3>(), s.initial_state::<3>());
        let mut run = Run::new(&model, q0, qd0, &s.options);
        let p = RodParams::of(&model).unwrap();
        let mut starts = Vec::new();
        while let Some(h) = run.next_step(&model) {
            if let Some((one, m, _)) = run.lane_start(h) {
                starts.push((p, m, one));
            }
            run.step(&model, h).unwrap();
        }
        starts
    }

    /// A sweep that mixes laws runs every covered scene in the lanes (none alone): a scene
    /// under another law than the lanes' waits for them to drain and take it, and each
    /// outcome is the lone run's bit for bit.
    #[test]
    fn a_sweep_that_mixes_laws_runs_them_all_in_the_lanes() {
        let laws = [None, Some(frame_law(true)), Some(frame_law(false))];
        let mut scenes = Vec::new();
        // Runs of one law, then interleaved laws.
        for k in 0..40usize {
            let law = if k < 6 { 1 } else { (k * 7 + k / 3) % 3 };
            let s = scene(
                -80.0 + 4.0 * k as f64,
                0.5 + 0.05 * k as f64,
                laws[law].as_deref(),
            );
            let (model, (q0, qd0)) = (s.model::<3>(), s.initial_state::<3>());
            scenes.push((k, model, q0, qd0, s.options));
        }
        let expected: Vec<String> = scenes
            .iter()
            .map(|(_, m, q0, qd0, o)| format!("{:?}", solve(m, *q0, *qd0, o)))
            .collect();
        let mut queue = scenes.into_iter();
        let mut got = vec![String::new(); expected.len()];
        let counts = run_lanes(
            LaneIsa::detect(),
            || queue.next(),
            |k, out| {
                got[k] = format!("{out:?}");
            },
        );
        assert_eq!(got, expected);
        assert_eq!((counts.alone, counts.in_lanes), (0, 40), "{counts:?}");
        assert!(counts.law_changes >= 2, "{counts:?}");
    }

    /// A step gives the same bits compiled for the baseline target as with AVX2 (the CPU's
    /// pick, [`LaneIsa::detect`]), in one lane (`f64`: the scalar path's lean step) and in
    /// four, on steps of runs at several angles and speeds through entry, sinking and
    /// stopping, under the thesis's law and two frame laws (their forces inlined into the
    /// lanes' step). On a CPU without AVX2 both are the baseline and this checks nothing new.
    #[test]
    fn a_step_is_the_same_bits_on_every_instruction_set() {
        let mut starts = Vec::new();
        for law in [None, Some(frame_law(true)), Some(frame_law(false))] {
            for (q, v0) in [(0.0, 2.2), (5.0, 1.1), (45.0, 2.27), (85.0, 0.7)] {
                starts.extend(lane_starts(q, v0, law.as_deref()));
            }
        }
        assert!(starts.len() > 1200, "{} steps", starts.len());
        let isa = LaneIsa::detect();
        for (p, m, s) in &starts {
            let (a, b) = (LaneIsa::Base.step(p, m, s), isa.step(p, m, s));
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
        for group in starts.chunks_exact(LANES) {
            let mut s = LaneStart::<F64x4>::splat(0.0);
            for (i, (_, _, one)) in group.iter().enumerate() {
                s.set(i, one);
            }
            let p = RodParams::splat(&group[0].0);
            let m = RodModes::gather(&[group[0].1; LANES]);
            let (a, b) = (LaneIsa::Base.step(&p, &m, &s), isa.step(&p, &m, &s));
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
    }

    /// The lanes accept a run's step ([`Run::accept_plain`]) only where the scalar path
    /// would accept it whole: a lane whose end is not finite, whose pivot is not clear or
    /// whose end crosses a switching function (here the stop's) is refused, and the run is
    /// left as it was for the scalar path.
    #[test]
    fn the_lanes_accept_only_a_plain_finite_step() {
        let mut spec = crate::spec::free_link_spec();
        spec.set("q_deg", Value::Num(45.0));
        let Ok(s) = spec.build() else {
            panic!("the free link does not build");
        };
        let (model, (q0, qd0)) = (s.model::<3>(), s.initial_state::<3>());
        let mut run = Run::new(&model, q0, qd0, &s.options);
        // Into the sand, alone: the run's switching functions are listed.
        for _ in 0..50 {
            let h = run.next_step(&model).unwrap();
            run.step(&model, h).unwrap();
        }
        assert!(run.may_stay_in_lanes(&model));
        let h = run.next_step(&model).unwrap();
        let (one, m, _) = run.lane_start(h).unwrap();
        let mut start = LaneStart::<F64x4>::splat(0.0);
        for i in 0..LANES {
            start.set(i, &one);
        }
        let p = RodParams::splat(&RodParams::of(&model).unwrap());
        let end = lane_step::<_, false>(&p, &RodModes::gather(&[m; LANES]), &start);
        let mut bad = end;
        bad.qd[0].0[1] = f64::NAN;
        bad.stages[1].pivot.0[2] = 0.0;
        bad.eval.v_tip[1].0[3] = 1e-3;
        for i in 1..LANES {
            assert!(!run.accept_plain(&model, &bad, i), "lane {i} accepted");
            assert!(!run.in_lanes());
        }
        assert!(run.accept_plain(&model, &end, 0));
        assert!(run.in_lanes());
    }
}
