//! One step of four runs of the free link at once, one per SIMD lane ([`lane_step`]): the
//! lanes' state ([`LaneStart`]), stages ([`LaneStage`]) and end ([`LaneEnd`]), what a run's
//! events read of a lane ([`LaneContact`]) and the instruction set picked at run time
//! ([`LaneIsa`]). The driver that feeds runs to the lanes is [`super::lanes`]; a run takes a
//! lane's step through [`super::solve::Run`], which reads these types and nothing of the
//! driver.

use nalgebra::{SVector, Vector2};

use super::events::SwitchInputs;
use super::stepper::{Deriv, State};
use crate::dynamics::rod_lanes::{pivot_ok, rod_eval_law, RodEval, RodModes, RodParams};
use crate::dynamics::DragStiffness;
use crate::forces::Real;
use crate::num::F64x4;

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
    pub(super) fn splat(x: f64) -> Self {
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
    pub(super) fn each(&mut self, mut f: impl FnMut(&mut F64x4, usize)) {
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
    pub(super) fn set(&mut self, i: usize, s: &LaneStart<f64>) {
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
    pub(super) fn take_end(&mut self, i: usize, end: &LaneEnd<F64x4>) {
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
    pub(super) fn copy_lane(&mut self, i: usize, j: usize) {
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
    /// The fourth stage's rates and q'' (the derivative `k4`, for the step's error
    /// estimate, [`super::stepper::companion`]).
    pub qd4: [F; 3],
    /// See `qd4`.
    pub qdd4: [F; 3],
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
    pub(super) fn of(q: [F; 3], e: &RodEval<F>) -> Self {
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
pub fn lane_step<F: Real, const THESIS: bool>(
    p: &RodParams<F>,
    m: &RodModes<F>,
    s: &LaneStart<F>,
) -> LaneEnd<F> {
    let rod_eval = rod_eval_law::<F, THESIS>;
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
        qd4,
        qdd4: e4.qdd,
    }
}

impl LaneEnd<F64x4> {
    /// Lane `i`.
    #[inline]
    pub fn lane(&self, i: usize) -> LaneEnd<f64> {
        // By reference, as `RodEval::lane`.
        let l = |x: &F64x4| x.0[i];
        let l3 = |x: &[F64x4; 3]| [x[0].0[i], x[1].0[i], x[2].0[i]];
        LaneEnd {
            q: l3(&self.q),
            qd: l3(&self.qd),
            work: l(&self.work),
            dissipated: l(&self.dissipated),
            eval: self.eval.lane(i),
            stages: [
                self.stages[0].lane(i),
                self.stages[1].lane(i),
                self.stages[2].lane(i),
            ],
            last: self.last.lane(i),
            qd4: l3(&self.qd4),
            qdd4: l3(&self.qdd4),
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
        let l = move |x: &F64x4| x.0[i];
        (
            move || SVector::from_fn(|k, _| l(&self.q[k])),
            DragStiffness {
                drag2: l(&self.drag2),
                speed2: l(&self.speed2),
                contact: 0,
                v: Vector2::new(l(&self.v[0]), l(&self.v[1])),
            },
        )
    }

    /// Lane `i`.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> LaneStage<f64> {
        let l = |x: &F64x4| x.0[i];
        LaneStage {
            q: [l(&self.q[0]), l(&self.q[1]), l(&self.q[2])],
            drag2: l(&self.drag2),
            speed2: l(&self.speed2),
            v: [l(&self.v[0]), l(&self.v[1])],
            pivot: l(&self.pivot),
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
    pub(super) fn at(&self, x: &F64x4) -> f64 {
        x.0[self.i]
    }
}

impl SwitchInputs for LaneContact<'_> {
    #[inline(always)]
    fn lowest(&self) -> f64 {
        self.at(&self.eval.lowest)
    }
    #[inline(always)]
    fn v_centroid(&self) -> [f64; 2] {
        [
            self.at(&self.eval.v_centroid[0]),
            self.at(&self.eval.v_centroid[1]),
        ]
    }
    #[inline(always)]
    fn bound(&self) -> [f64; 2] {
        [self.at(&self.eval.bound[0]), self.at(&self.eval.bound[1])]
    }
    #[inline(always)]
    fn statics(&self) -> [f64; 2] {
        [
            self.at(&self.eval.statics[0]),
            self.at(&self.eval.statics[1]),
        ]
    }
    #[inline(always)]
    fn v_tip_y(&self) -> f64 {
        self.at(&self.eval.v_tip[1])
    }
    #[inline(always)]
    fn cross(&self) -> f64 {
        self.at(&self.eval.cross)
    }
    #[inline(always)]
    fn immersion_margin(&self) -> f64 {
        self.at(&self.eval.margin)
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

    /// The fourth stage's derivative (rates and q''; no power), for the step's error
    /// estimate ([`super::stepper::companion`]).
    #[inline]
    pub fn k4<const N: usize>(&self) -> Deriv<N> {
        Deriv {
            q: SVector::from_fn(|i, _| self.qd4[i]),
            qd: SVector::from_fn(|i, _| self.qdd4[i]),
            work: 0.0,
            dissipated: 0.0,
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
pub(super) fn lane_step_base<F: Real, const THESIS: bool>(
    p: &RodParams<F>,
    m: &RodModes<F>,
    s: &LaneStart<F>,
) -> LaneEnd<F> {
    lane_step::<F, THESIS>(p, m, s)
}

/// [`lane_step`] compiled with AVX2 (256-bit registers for the lanes; for one lane, the
/// three-operand encodings).
///
/// # Safety
/// The CPU must have AVX2 ([`crate::num::avx2`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline(never)]
unsafe fn lane_step_avx2<F: Real, const THESIS: bool>(
    p: &RodParams<F>,
    m: &RodModes<F>,
    s: &LaneStart<F>,
) -> LaneEnd<F> {
    lane_step::<F, THESIS>(p, m, s)
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
        if crate::num::avx2() {
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
            LaneIsa::Avx2 if p.law.thesis => unsafe { lane_step_avx2::<F, true>(p, m, s) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            LaneIsa::Avx2 => unsafe { lane_step_avx2::<F, false>(p, m, s) },
            _ if p.law.thesis => lane_step_base::<F, true>(p, m, s),
            _ => lane_step_base::<F, false>(p, m, s),
        }
    }
}
