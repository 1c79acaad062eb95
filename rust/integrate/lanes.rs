//! Several runs of the free link stepped at once, one per SIMD lane: the sweep's fast path.
//! The lanes run one law at a time: any contact terms the free link accepts, their terms
//! and counts shared by the four, their numbers per lane
//! (`dynamics::rod_lanes::RodLaw::shares`).
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

use nalgebra::SVector;

pub use super::lane_step::{lane_step, LaneEnd, LaneIsa, LaneStage, LaneStart};
use super::options::SolveOptions;
use super::outcome::Outcome;
use super::solve::{solve, Run};
use super::stepper::{Deriv, Method};
use crate::dynamics::rod_lanes::{RodEval, RodModes, RodParams};
use crate::dynamics::Model;
use crate::error::Result;
use crate::num::{F64x4, LANES};

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
/// The lanes run one law at a time (its terms and counts, with any numbers per lane:
/// [`crate::dynamics::rod_lanes::RodLaw::shares`]). A scene under
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
    // its next step from its lane here, and `kept` holds its last end's evaluation (taken
    // only from a step whose end the lanes kept for some run: an evaluation holds every
    // term's force per lane, a kilobyte).
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
                lane_params.copy_lane(i, first);
                start.copy_lane(i, first);
                lane_modes.copy_lane(i, first);
            }
            isa.step(&lane_params, &lane_modes, &start)
        };

        let mut keep = false;
        for i in 0..LANES {
            if !stepped[i] {
                continue;
            }
            let Some(slot) = slots[i].as_mut() else {
                continue;
            };
            if slot.may_stay && slot.run.accept_plain(&slot.model, &end, i) {
                start.take_end(i, &end);
                keep = true;
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
        // Every run the lanes kept before this step was stepped in it (a run in the lanes
        // steps there while it lives, and takes back its end as it ends), so only the runs
        // this step kept read `kept`.
        if keep {
            kept = Some(end.eval);
        }
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
            let waited = match params.as_ref() {
                _ if idle && !self.waiting.is_empty() => self.waiting.pop_front(),
                Some(lanes) => self
                    .waiting
                    .iter()
                    .position(|(_, p)| lanes.law.shares(&p.law))
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
                Some(lanes) if lanes.law.shares(&p.law) => lanes.set(i, &p),
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

    /// Every law the free link accepts runs in the lanes, each outcome the general path's
    /// bit for bit (every field): each of the registry's contact terms that a rod takes
    /// alone, and mixed (the thesis's three, each pair, all of them), four scenes of each
    /// law in one sweep, each with its own numbers, through entry, sticking and stops; and
    /// with the registry's body terms that a rod takes (`gravity`, `joint_springs`), each
    /// scene listing its own choice of them (none: no gravity), which the lanes share.
    #[test]
    fn every_law_runs_in_the_lanes_as_on_the_general_path() {
        use crate::dynamics::rod_lanes::{rod_law, rod_terms};
        use crate::forces::{Acts, ContactKind, TERMS};
        let body: Vec<TermSpec> = TERMS
            .iter()
            .filter(|t| t.acts == Acts::Body && t.shapes.contains(&ContactKind::Rod))
            .map(|t| {
                let params: Vec<(&str, f64)> = t
                    .params
                    .iter()
                    .map(|p| match (t.name, p.name) {
                        ("lift", "f") => (p.name, 0.3),
                        _ if p.required() => panic!("give {}.{} a value here", t.name, p.name),
                        _ => (p.name, p.default),
                    })
                    .collect();
                TermSpec::new(t.name, &params)
            })
            .collect();
        let names: Vec<&str> = body.iter().map(|t| t.name.as_str()).collect();
        assert!(
            names.contains(&"gravity") && names.contains(&"joint_springs"),
            "{names:?}"
        );
        let n = rod_terms(1.0, 1).len() as u32;
        let mut masks: Vec<u32> = (0..n).map(|k| 1 << k).collect();
        masks.push(0b111);
        masks.push((1 << n) - 1);
        for a in 0..n {
            for b in a + 1..n {
                masks.push((1 << a) | (1 << b));
            }
        }
        let mut scenes = Vec::new();
        let mut expected = Vec::new();
        for (k, &mask) in masks.iter().enumerate() {
            for j in 0..LANES {
                // Scene j of law k lists the body terms that the bits of k + j pick, so that
                // every choice of them meets every law.
                let pick = (k + j) % (1 << body.len());
                let mut law: Vec<TermSpec> = (body.iter().enumerate())
                    .filter(|(b, _)| pick & (1 << b) != 0)
                    .map(|(_, t)| t.clone())
                    .collect();
                law.extend(rod_law(mask, 0.6 + 0.3 * j as f64, 3 + k % 5));
                let s = scene(-40.0 + 27.0 * j as f64, 0.4 + 0.5 * j as f64, Some(&law));
                let (model, (q0, qd0)) = (s.model::<3>(), s.initial_state::<3>());
                let mut run = Run::new(&model, q0, qd0, &s.options).general();
                while let Some(h) = run.next_step(&model) {
                    run.step(&model, h).unwrap();
                }
                expected.push(format!("{:?}", run.finish(&model)));
                scenes.push((scenes.len(), model, q0, qd0, s.options));
            }
        }
        let mut queue = scenes.into_iter();
        let mut got = vec![String::new(); expected.len()];
        let counts = run_lanes(
            LaneIsa::detect(),
            || queue.next(),
            |k, out| got[k] = format!("{out:?}"),
        );
        for (k, (a, b)) in got.iter().zip(&expected).enumerate() {
            assert_eq!(a, b, "law {:b}, scene {}", masks[k / LANES], k % LANES);
        }
        assert_eq!(counts.alone, 0, "{counts:?}");
        assert!(counts.law_changes + 1 >= masks.len(), "{counts:?}");
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
