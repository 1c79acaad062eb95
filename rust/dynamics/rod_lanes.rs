//! The free link's mechanics, written once, over [`Real`]: [`rod_kernel`] evaluates a
//! single rigid rod whose root is its centre of mass ([`Model::rigid_rod`]): its frame, its
//! immersed geometry, its terms' sums, its accelerations under `M = diag(m + m_root,
//! m + m_root, I)`, its sticking reactions and the power of the sand's force. It is what
//! [`Model::eval`] runs for a free link (in `f64`, one scene: the events, stops, samples,
//! the ledger, the forces and bounds, the MuJoCo coupling's geoms), what a lone run's RK4
//! steps run (`integrate::solve::Run::step`, the same kernel in `f64` inside
//! `integrate::lane_step`: a stage computes only what the step reads, after inlining), and
//! what the sweep's lanes run with `F = F64x4` (four scenes, one per SIMD lane, in the same
//! instructions, `integrate::lanes`).
//!
//! The force law is not copied, nor listed here: each contact term the scene lists is
//! evaluated by its own arithmetic, [`Term::force_with`] (what its `contact_force` runs),
//! with its numbers from its parameter table, one per lane ([`RodParams::numbers`]; one
//! scene calls the term's `contact_force`, its own numbers). The lanes share the terms and
//! their counts ([`RodLaw`], [`RodLaw::shares`]). Branches are blends
//! ([`Real::select_pos`]) on per-lane flags, so that a lane's result is the one-scene
//! result bit for bit (tests hold them so over random states, modes and laws); two blocks
//! are skipped when every lane blends them away (the law out of the sand, the sticking row
//! when nothing sticks): the same bits, less work.
//!
//! What it reads: the body ([`RodBody`], built from the model at every evaluation without
//! allocating), the terms ([`RodTerms`], borrowed: from the model's force set for one
//! scene, from a run's [`RodParams`] in the lanes) and the modes ([`RodModes`]). It covers
//! any sign model (`modes`, held through a step; the thesis's plain sign `raw` and
//! `smooth`'s tanh, each evaluation's own, with no sticking), a force at the tip or at the
//! centroid, and any contact terms the free link accepts. A sticking row is solved in
//! closed form; for one scene the kernel also solves the rows the closed form leaves
//! ([`one_scene_rows`]): x and y stuck together, a reaction shared by several static terms,
//! a pivot that is not clearly nonzero. The lanes hand such steps to the one-scene
//! evaluation ([`RodModes::of`], [`pivot_ok`]).

use nalgebra::{SVector, Vector2};

use super::constraints::solve_upto2;
use super::{ContactEval, ContactForce, ContactMode, DragStiffness, Eval, Model, SignModel, Slip};
use crate::body::rod::ApplyAt;
use crate::body::RodContact;
use crate::forces::drag::Drag;
use crate::forces::registry::{TermList, LANE_NUMBERS, MAX_TERMS};
use crate::forces::static_h::StaticH;
use crate::forces::static_v::StaticV;
use crate::forces::{
    AnyTerm, Boundary, ContactState, ForceSet, Frame, Medium, Outline, Real, Switch, Term,
    TermForce,
};
use crate::num::{F64x4, LANES};

/// The contact terms of a free link as the lanes run them, with what the force set
/// derives from them (`ForceSet`): one for every lane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodLaw {
    /// The contact terms, in the scene's order (their counts, `Param::integer`, are the
    /// lanes'; their other numbers are each lane's own, [`RodParams::numbers`]).
    pub terms: TermList,
    /// Where term `k`'s numbers start in [`RodParams::numbers`].
    pub at: [usize; MAX_TERMS],
    /// Whether term `k` adds to F_d (its class).
    pub dynamic: [bool; MAX_TERMS],
    /// Whether a listed term owns the slip switch of x, of y.
    pub owns: [bool; 2],
    /// Per axis, the one static term whose component a sticking reaction replaces
    /// (`ForceSet::sole_static_owner`; `usize::MAX`: none).
    pub owner: [usize; 2],
    /// Whether a listed term reads the contact's frame (then the law acts from depth 0).
    pub reads_frame: bool,
    /// Whether a listed term reads A_r |v_E|.
    pub reads_area_speed: bool,
    /// Whether the terms are the thesis's three in its order (`drag`, `static_h`,
    /// `static_v`): the lanes compile them into a step of their own, with no dispatch
    /// between the terms (the common case; the same arithmetic).
    pub thesis: bool,
}

impl RodLaw {
    /// The law of `model`'s one contact.
    fn of<const N: usize>(model: &Model<N>) -> Self {
        let forces = &model.forces;
        let terms = forces.per_contact[0];
        let mut at = [0; MAX_TERMS];
        let mut next = 0;
        for (k, t) in terms.iter().enumerate() {
            at[k] = next;
            next += t.info().params.len();
        }
        RodLaw {
            terms,
            at,
            dynamic: forces.dynamic,
            owns: [forces.owns(Switch::SlipX), forces.owns(Switch::SlipY)],
            owner: forces.sole_static_owner.map(|o| o.unwrap_or(usize::MAX)),
            reads_frame: forces.reads_frame,
            reads_area_speed: forces.reads_area_speed,
            thesis: matches!(
                terms[..],
                [AnyTerm::Drag(_), AnyTerm::StaticH(_), AnyTerm::StaticV(_)]
            ),
        }
    }

    /// Whether runs under `self` and `other` can share the lanes: the same terms in the same
    /// order with the same counts (`Param::integer`: `rft`'s elements set its loop); their
    /// other numbers are per lane.
    pub fn shares(&self, other: &RodLaw) -> bool {
        self.terms.len() == other.terms.len()
            && self.terms.iter().zip(other.terms.iter()).all(|(a, b)| {
                let info = a.info();
                info.name == b.info().name
                    && info
                        .params
                        .iter()
                        .zip(a.params().into_iter().zip(b.params()))
                        .all(|(p, (x, y))| !p.integer || x == y)
            })
    }
}

/// What the evaluation of one free link reads of its body, its contact, the sand and the
/// sign model (one lane per scene): built from the model in a few loads and two divisions,
/// without allocating, so that [`Model::eval`] builds it at every call and nothing derived
/// from the model is kept beside it (a test that changes a model's terms or sign model
/// after building it evaluates what it changed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodBody<F> {
    /// m + m_root [kg].
    pub mass: F,
    /// The acceleration of gravity on the body ([`Model::gravity`]) [m/s^2].
    pub g: F,
    /// 1 / (m + m_root) [1/kg].
    pub inv_m: F,
    /// 1 / I [1/(kg m^2)].
    pub inv_i: F,
    /// The tip's local coordinates [m].
    pub tip: [F; 2],
    /// L [m].
    pub length: F,
    /// d_c [m].
    pub diameter: F,
    /// pi / 4 d_c^2 [m^2]: the immersed volume per immersed length.
    pub section: F,
    /// 1 where the force acts at the centroid E, 0 at the tip T.
    pub at_centroid: F,
    /// The sand.
    pub medium: Medium<F>,
    /// 1 where the signs of v_E and of e x v_E are each evaluation's own (`raw`, `smooth`),
    /// 0 under `modes` (held through a step).
    pub unheld: F,
    /// 1 under `smooth` (the signs of v_E are tanh(v / eps)), else 0.
    pub smooth: F,
    /// `smooth`'s eps [m/s] (1 under the other sign models).
    pub eps: F,
}

impl RodBody<f64> {
    /// The body of `model`, whose free link's contact is `rod` ([`Model::rigid_rod`]).
    #[inline(always)]
    pub fn of<const N: usize>(model: &Model<N>, rod: &RodContact) -> Self {
        let (unheld, smooth, eps) = match model.sign_model {
            SignModel::Modes => (0.0, 0.0, 1.0),
            SignModel::Raw => (1.0, 0.0, 1.0),
            SignModel::Smooth { eps } => (1.0, 1.0, eps),
        };
        let link = &model.mechanism.links[0];
        let mass = link.mass + model.mechanism.root_mass;
        RodBody {
            mass,
            g: model.gravity(),
            inv_m: 1.0 / mass,
            inv_i: 1.0 / link.inertia,
            tip: [rod.tip.x, rod.tip.y],
            length: rod.length,
            diameter: rod.diameter,
            section: std::f64::consts::FRAC_PI_4 * rod.diameter * rod.diameter,
            at_centroid: match model.apply_at {
                ApplyAt::Tip => 0.0,
                ApplyAt::Centroid => 1.0,
            },
            medium: model.medium,
            unheld,
            smooth,
            eps,
        }
    }
}

impl<F: Copy> RodBody<F> {
    /// The same body, each number through `f`.
    fn map<G>(&self, f: impl Fn(F) -> G) -> RodBody<G> {
        RodBody {
            mass: f(self.mass),
            g: f(self.g),
            inv_m: f(self.inv_m),
            inv_i: f(self.inv_i),
            tip: self.tip.map(&f),
            length: f(self.length),
            diameter: f(self.diameter),
            section: f(self.section),
            at_centroid: f(self.at_centroid),
            medium: Medium {
                rho_g: f(self.medium.rho_g),
                g: f(self.medium.g),
            },
            unheld: f(self.unheld),
            smooth: f(self.smooth),
            eps: f(self.eps),
        }
    }

    /// Each number, in [`RodBody::map`]'s order.
    fn each_mut(&mut self, mut f: impl FnMut(&mut F)) {
        for x in [
            &mut self.mass,
            &mut self.g,
            &mut self.inv_m,
            &mut self.inv_i,
        ] {
            f(x);
        }
        self.tip.iter_mut().for_each(&mut f);
        for x in [
            &mut self.length,
            &mut self.diameter,
            &mut self.section,
            &mut self.at_centroid,
            &mut self.medium.rho_g,
            &mut self.medium.g,
            &mut self.unheld,
            &mut self.smooth,
            &mut self.eps,
        ] {
            f(x);
        }
    }
}

/// What a run in the lanes keeps of its free link: its body ([`RodBody`]) and its terms'
/// numbers (one lane per scene), and its law (one for all four). Built once per run (it
/// copies the term list and allocates); a lone evaluation ([`Model::eval`]) reads the
/// model's own terms instead ([`RodTerms::of_forces`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodParams<F> {
    /// The body, its contact, the sand and the sign model.
    pub body: RodBody<F>,
    /// Each listed term's parameter values in its table's order (`Term::params`), the
    /// terms one after the other ([`RodLaw::at`]); zero past them.
    pub numbers: [F; LANE_NUMBERS],
    /// The contact terms, one law for every lane.
    pub law: RodLaw,
}

impl<F: Copy> RodParams<F> {
    /// The same parameters, each number through `f`.
    fn map<G>(&self, f: impl Fn(F) -> G) -> RodParams<G> {
        RodParams {
            body: self.body.map(&f),
            numbers: self.numbers.map(&f),
            law: self.law,
        }
    }

    /// Each number, in [`RodParams::map`]'s order.
    fn each_mut(&mut self, mut f: impl FnMut(&mut F)) {
        self.body.each_mut(&mut f);
        self.numbers.iter_mut().for_each(f);
    }

    /// The terms as the kernel reads them: this law with these numbers.
    #[inline(always)]
    pub fn terms(&self) -> RodTerms<'_, F> {
        let law = &self.law;
        RodTerms {
            terms: &law.terms,
            numbers: &self.numbers,
            at: &law.at,
            dynamic: &law.dynamic,
            owns: law.owns,
            owner: law.owner,
            reads_frame: law.reads_frame,
            reads_area_speed: law.reads_area_speed,
            thesis: law.thesis,
            forces: None,
        }
    }
}

impl RodParams<f64> {
    /// The parameters of `model`, or `None` when it is not a free link.
    #[inline(never)]
    pub fn of<const N: usize>(model: &Model<N>) -> Option<Self> {
        let rod = model.rigid_rod()?;
        let law = RodLaw::of(model);
        let mut numbers = [0.0; LANE_NUMBERS];
        for (k, t) in law.terms.iter().enumerate() {
            for (j, v) in t.params().into_iter().enumerate() {
                numbers[law.at[k] + j] = v;
            }
        }
        Some(RodParams {
            body: RodBody::of(model, rod),
            numbers,
            law,
        })
    }
}

/// The contact terms of a free link as one evaluation reads them, borrowed: from a run's
/// [`RodParams`] in the lanes (each lane's numbers), or from the model's [`ForceSet`] for
/// one scene ([`RodTerms::of_forces`]: each term's own numbers).
#[derive(Debug, Clone, Copy)]
pub struct RodTerms<'a, F> {
    /// The contact terms, in the scene's order.
    pub terms: &'a [AnyTerm],
    /// The lanes' numbers of the terms ([`RodParams::numbers`]); for one scene, the
    /// thesis's four (`eta_d`, `eta_h`, `eta_v`, `lam`) when `thesis`, else none (each term
    /// reads its own).
    pub numbers: &'a [F],
    /// Where term `k`'s numbers start in `numbers` (read in the lanes only).
    pub at: &'a [usize; MAX_TERMS],
    /// Whether term `k` adds to F_d (its class).
    pub dynamic: &'a [bool; MAX_TERMS],
    /// Whether a listed term owns the slip switch of x, of y.
    pub owns: [bool; 2],
    /// Per axis, the one static term whose component a sticking reaction replaces
    /// (`usize::MAX`: none, the reaction is shared).
    pub owner: [usize; 2],
    /// Whether a listed term reads the contact's frame (then the law acts from depth 0).
    pub reads_frame: bool,
    /// Whether a listed term reads A_r |v_E|.
    pub reads_area_speed: bool,
    /// Whether the terms are the thesis's three in its order ([`RodLaw::thesis`]).
    pub thesis: bool,
    /// For one scene, its force set: the kernel then solves every sticking row itself (two
    /// rows, a reaction shared by several static terms, a pivot that is not clear).
    /// `None` in the lanes, which hand such steps to the one-scene evaluation.
    pub forces: Option<&'a ForceSet>,
}

/// Where the numbers of terms read by no one start (one scene: each term reads its own).
const NO_AT: [usize; MAX_TERMS] = [0; MAX_TERMS];

impl<'a> RodTerms<'a, f64> {
    /// The terms of one scene's force set `forces`, read in place (nothing copied but
    /// their flags): the thesis's four numbers go to `thesis_numbers` when its three terms
    /// are listed in its order.
    #[inline(always)]
    pub fn of_forces(forces: &'a ForceSet, thesis_numbers: &'a mut [f64; 4]) -> Self {
        Self::of_terms(forces, &forces.per_contact[0], thesis_numbers)
    }

    /// [`RodTerms::of_forces`] with the contact terms `terms` in place of the set's own:
    /// the same terms, in the same order, with other numbers (`granrs.resistance_force`
    /// gives each state its own).
    #[inline(always)]
    pub fn of_terms(
        forces: &'a ForceSet,
        terms: &'a [AnyTerm],
        thesis_numbers: &'a mut [f64; 4],
    ) -> Self {
        debug_assert_eq!(terms.len(), forces.per_contact[0].len(), "the set's terms");
        let thesis = if let [AnyTerm::Drag(d), AnyTerm::StaticH(h), AnyTerm::StaticV(v)] = terms {
            *thesis_numbers = [d.eta_d, h.eta_h, v.eta_v, v.lam];
            true
        } else {
            false
        };
        let numbers: &'a [f64; 4] = thesis_numbers;
        RodTerms {
            terms,
            numbers,
            at: &NO_AT,
            dynamic: &forces.dynamic,
            owns: [forces.owns(Switch::SlipX), forces.owns(Switch::SlipY)],
            owner: forces.sole_static_owner.map(|o| o.unwrap_or(usize::MAX)),
            reads_frame: forces.reads_frame,
            reads_area_speed: forces.reads_area_speed,
            thesis,
            forces: Some(forces),
        }
    }
}

impl RodParams<F64x4> {
    /// Every lane `p`.
    pub fn splat(p: &RodParams<f64>) -> Self {
        p.map(F64x4::splat)
    }

    /// Lane `i` becomes `p`, whose law must share the lanes' ([`RodLaw::shares`]).
    pub fn set(&mut self, i: usize, p: &RodParams<f64>) {
        debug_assert!(self.law.shares(&p.law), "the lanes run one law");
        let mut values = Vec::with_capacity(16 + LANE_NUMBERS);
        let mut p = *p;
        p.each_mut(|x| values.push(*x));
        let mut values = values.into_iter();
        self.each_mut(|x| x.0[i] = values.next().unwrap_or(0.0));
    }

    /// Lane `i` takes lane `j`'s parameters.
    pub fn copy_lane(&mut self, i: usize, j: usize) {
        self.each_mut(|x| x.0[i] = x.0[j]);
    }
}

/// The contact's mode as the lanes read it (held through a step), as numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodModes<F> {
    /// 1 in contact, else 0.
    pub in_contact: F,
    /// The held signs of v_Ex and v_Ey (`Slip::sign`: -1, 0 sticking, +1).
    pub sign: [F; 2],
    /// The held sign of e x v_E (-1 or +1).
    pub cross: F,
    /// 1 where x sticks, else 0.
    pub stuck_x: F,
    /// 1 where y sticks, else 0.
    pub stuck_y: F,
}

impl RodModes<f64> {
    /// `mode` as the kernel reads it, for a body whose signs are each evaluation's own
    /// where `unheld` ([`RodBody::unheld`]) and whose terms own the slip switches `owns`:
    /// where the signs are not held nothing sticks, nor does a component no listed term owns
    /// (no reaction there). It may stick in both x and y.
    #[inline(always)]
    pub fn held(mode: &ContactMode, unheld: f64, owns: [bool; 2]) -> Self {
        let plain = unheld > 0.0;
        let stick = |s: Slip, owned: bool| !plain && owned && s == Slip::Stick;
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        RodModes {
            in_contact: flag(mode.in_contact),
            sign: [mode.sx.sign(), mode.sy.sign()],
            cross: if mode.cross == Slip::Neg { -1.0 } else { 1.0 },
            stuck_x: flag(stick(mode.sx, owns[0])),
            stuck_y: flag(stick(mode.sy, owns[1])),
        }
    }

    /// `mode` for the lanes of a run with `params` ([`RodParams::of`]), or `None` when the
    /// lanes hand the step to the one-scene evaluation: in contact, it sticks in both x and
    /// y (two sticking rows), or in an axis with no one term whose component the reaction
    /// replaces (shared among several).
    #[inline]
    pub fn of(mode: &ContactMode, params: &RodParams<f64>) -> Option<Self> {
        let law = &params.law;
        let m = Self::held(mode, params.body.unheld, law.owns);
        let (sx, sy) = (m.stuck_x > 0.0, m.stuck_y > 0.0);
        let shared = |s: bool, axis: usize| s && law.owner[axis] == usize::MAX;
        if mode.in_contact && ((sx && sy) || shared(sx, 0) || shared(sy, 1)) {
            return None;
        }
        Some(m)
    }
}

impl RodModes<F64x4> {
    /// Every lane `x`.
    pub fn splat(x: f64) -> Self {
        let s = F64x4::splat(x);
        RodModes {
            in_contact: s,
            sign: [s; 2],
            cross: s,
            stuck_x: s,
            stuck_y: s,
        }
    }

    /// Lane by lane.
    pub fn gather(m: &[RodModes<f64>; LANES]) -> Self {
        let mut out = Self::splat(0.0);
        for (i, mi) in m.iter().enumerate() {
            out.set(i, mi);
        }
        out
    }

    /// Lane `i` becomes `m`.
    #[inline]
    pub fn set(&mut self, i: usize, m: &RodModes<f64>) {
        self.in_contact.0[i] = m.in_contact;
        self.sign[0].0[i] = m.sign[0];
        self.sign[1].0[i] = m.sign[1];
        self.cross.0[i] = m.cross;
        self.stuck_x.0[i] = m.stuck_x;
        self.stuck_y.0[i] = m.stuck_y;
    }

    /// Lane `i` takes lane `j`'s modes.
    pub fn copy_lane(&mut self, i: usize, j: usize) {
        let m = self.lane(j);
        self.set(i, &m);
    }

    /// Lane `i`.
    pub fn lane(&self, i: usize) -> RodModes<f64> {
        RodModes {
            in_contact: self.in_contact.0[i],
            sign: [self.sign[0].0[i], self.sign[1].0[i]],
            cross: self.cross.0[i],
            stuck_x: self.stuck_x.0[i],
            stuck_y: self.stuck_y.0[i],
        }
    }
}

/// One evaluation of the free link in lanes: what [`Model::eval`] returns for it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodEval<F> {
    /// Generalized accelerations.
    pub qdd: [F; 3],
    /// Power of the sand's force [W].
    pub power: F,
    /// The tip T and its velocity.
    pub tip: [F; 2],
    /// See `tip`.
    pub v_tip: [F; 2],
    /// The contact's depth (0 out of contact).
    pub depth: F,
    /// The lowest point (the tip's height).
    pub lowest: F,
    /// v_E (v_T out of contact).
    pub v_centroid: [F; 2],
    /// e x v_E (0 out of contact).
    pub cross: F,
    /// Margin to full immersion (0 out of contact).
    pub margin: F,
    /// The immersed length l = min(d / cos q, L) (in contact or not).
    pub immersed: F,
    /// The rod's axis e = (sin q, cos q), from the tip.
    pub axis: [F; 2],
    /// Each listed term's force in its place (a reaction in place of a stuck component;
    /// zero past the list).
    pub terms: [[F; 2]; MAX_TERMS],
    /// F_d.
    pub dynamic: [F; 2],
    /// F_s (or its reaction).
    pub statics: [F; 2],
    /// The terms' moment about P.
    pub moment: F,
    /// The sticking bounds.
    pub bound: [F; 2],
    /// Where a sticking row acts: its pivot `1/m + lever_E lever_P / I`; 1 elsewhere. A
    /// lane whose pivot is not clearly nonzero hands the step to the one-scene evaluation.
    pub pivot: F,
}

/// [`super::raw_sign`] in `F`: -1, 0 or +1 (0 for a NaN, as there).
#[inline(always)]
fn plain_sign<F: Real>(v: F) -> F {
    let (zero, one) = (F::splat(0.0), F::splat(1.0));
    v.select_pos(one, (-v).select_pos(-one, zero))
}

/// The free link's evaluation of a run in the lanes, in `F`: [`rod_kernel`] for its law.
#[inline(always)]
pub fn rod_eval<F: Real>(p: &RodParams<F>, m: &RodModes<F>, q: &[F; 3], qd: &[F; 3]) -> RodEval<F> {
    rod_eval_terms(&p.body, &p.terms(), m, q, qd)
}

/// [`rod_kernel`] for the law at hand: the thesis's three terms compiled into a kernel of
/// their own where they are listed.
#[inline(always)]
pub fn rod_eval_terms<F: Real>(
    p: &RodBody<F>,
    law: &RodTerms<'_, F>,
    m: &RodModes<F>,
    q: &[F; 3],
    qd: &[F; 3],
) -> RodEval<F> {
    if law.thesis {
        rod_kernel::<F, true>(p, law, m, q, qd)
    } else {
        rod_kernel::<F, false>(p, law, m, q, qd)
    }
}

/// [`rod_kernel`] of a run in the lanes whose law is known when compiled (`THESIS`:
/// [`RodLaw::thesis`]).
#[inline(always)]
pub fn rod_eval_law<F: Real, const THESIS: bool>(
    p: &RodParams<F>,
    m: &RodModes<F>,
    q: &[F; 3],
    qd: &[F; 3],
) -> RodEval<F> {
    rod_kernel::<F, THESIS>(&p.body, &p.terms(), m, q, qd)
}

/// The sums of one evaluation's terms: F_d, F_s, the moment, the sticking bounds, and each
/// term's force (zero past the list).
#[derive(Clone, Copy)]
struct Sums<F> {
    dynamic: [F; 2],
    statics: [F; 2],
    moment: F,
    bound: [F; 2],
    forces: [[F; 2]; MAX_TERMS],
}

impl<F: Real> Sums<F> {
    /// No term.
    #[inline(always)]
    fn zero() -> Self {
        let zero = F::splat(0.0);
        Sums {
            dynamic: [zero; 2],
            statics: [zero; 2],
            moment: zero,
            bound: [zero; 2],
            forces: [[zero; 2]; MAX_TERMS],
        }
    }

    /// Term `k`'s force `tf` (of class `dynamic`) added as `terms_on` adds it.
    #[inline(always)]
    fn add(&mut self, k: usize, dynamic: bool, tf: TermForce<F>) {
        let f = tf.force;
        self.forces[k] = f;
        if dynamic {
            self.dynamic = [self.dynamic[0] + f[0], self.dynamic[1] + f[1]];
        } else {
            self.statics = [self.statics[0] + f[0], self.statics[1] + f[1]];
        }
        self.moment = self.moment + tf.moment;
        self.bound = [self.bound[0] + tf.bound[0], self.bound[1] + tf.bound[1]];
    }
}

/// The terms of `law` on `state`, summed in the list's order (`terms_on`): each term's own
/// arithmetic, with its numbers from `law.numbers` in the lanes and its own in one lane
/// (`contact_force`: a term's fast path for one scene, the same bits). `THESIS`: the
/// thesis's three, known when compiled (`law.thesis`): their `force_with` reads nothing of
/// the term but the numbers given it (their `contact_force` is it with their own), so the
/// kernel reads their numbers from `law.numbers` in one lane too and never looks at the
/// list.
#[inline(always)]
fn term_sums<F: Real, const THESIS: bool>(
    law: &RodTerms<'_, F>,
    state: &ContactState<F>,
    medium: &Medium<F>,
    sums: &mut Sums<F>,
) {
    let (lanes, numbers) = (F::LANES > 1, law.numbers);
    if THESIS {
        // Their numbers stand in `numbers` (`RodParams::of`, `RodTerms::of_forces`): these terms' own are not read
        // (NaN, so that a term that came to read them would show at once in the tests).
        let (d, h, v) = (
            Drag { eta_d: f64::NAN },
            StaticH { eta_h: f64::NAN },
            StaticV {
                eta_v: f64::NAN,
                lam: f64::NAN,
            },
        );
        sums.add(0, true, d.force_with(&numbers[0..1], state, medium));
        sums.add(1, false, h.force_with(&numbers[1..2], state, medium));
        sums.add(2, false, v.force_with(&numbers[2..4], state, medium));
        return;
    }
    for (k, t) in law.terms.iter().enumerate() {
        let tf = if lanes {
            t.force_with(&numbers[law.at[k]..], state, medium)
        } else {
            t.contact_force(state, medium)
        };
        sums.add(k, law.dynamic[k], tf);
    }
}

/// The free link's evaluation, in `F` (one scene in `f64`, four in `F64x4`): body `p`,
/// terms `law`, modes `m`, at `(q, qd)`; branches are blends (see the module). `THESIS`:
/// the law is the thesis's three terms (`law.thesis`), compiled into a kernel of their own,
/// with no dispatch between them (measured: 4 % slower lanes with `rft` in the same step);
/// else any terms.
#[inline(always)]
pub fn rod_kernel<F: Real, const THESIS: bool>(
    p: &RodBody<F>,
    law: &RodTerms<'_, F>,
    m: &RodModes<F>,
    q: &[F; 3],
    qd: &[F; 3],
) -> RodEval<F> {
    let zero = F::splat(0.0);
    let sel = |flag: F, a: F, b: F| flag.select_pos(a, b);
    let sel2 = |flag: F, a: [F; 2], b: [F; 2]| [sel(flag, a[0], b[0]), sel(flag, a[1], b[1])];
    // RodFrame.
    let (s, c) = q[2].sin_cos();
    let axis = [s, c];
    let normal = [c, -s];
    let omega = qd[2];
    let at = |r: [F; 2]| {
        [
            q[0] + (r[0] * axis[0] + r[1] * normal[0]),
            q[1] + (r[0] * axis[1] + r[1] * normal[1]),
        ]
    };
    let lever = |r: [F; 2]| {
        [
            r[0] * normal[0] - r[1] * axis[0],
            r[0] * normal[1] - r[1] * axis[1],
        ]
    };
    let velocity = |r: [F; 2]| {
        let l = lever(r);
        [qd[0] + omega * l[0], qd[1] + omega * l[1]]
    };
    let gen1 = -p.mass * p.g;
    let tip = at(p.tip);
    let v_tip = velocity(p.tip);
    // RodContact::geometry.
    let depth = (-tip[1]).max(zero);
    let full_at = p.length * axis[1];
    let immersed = sel(full_at - depth, depth / axis[1], p.length);
    let centroid = [p.tip[0] + F::splat(0.5) * immersed, p.tip[1]];
    let inside = m.in_contact;
    let depth_out = sel(inside, depth, zero);
    let margin = sel(inside, full_at - depth, zero);
    let v_in = velocity(centroid);
    let v_centroid = sel2(inside, v_in, v_tip);
    let cross = sel(inside, axis[0] * v_in[1] - axis[1] * v_in[0], zero);
    // Forced: in contact and below the surface; in contact for a law that reads the frame
    // (a `poncelet` drag or a plate's `rft_inertial` is finite at depth 0: the entry is a
    // jump).
    let reads_frame = !THESIS && law.reads_frame;
    let forced = if reads_frame { inside } else { depth_out };
    // |e x v_E| as the drag reads it and the signs of v_E: the held ones under `modes`,
    // each evaluation's own under `raw` and `smooth` (`Model::held_cross`, `Model::signs`).
    // What every lane blends away is skipped (the same bits, less work: `tanh` is libm's).
    let held = if p.unheld.all_zero() {
        m.cross * cross
    } else {
        sel(p.unheld, cross.abs(), m.cross * cross)
    };
    let own = |v: F| {
        if p.smooth.all_zero() {
            plain_sign(v)
        } else {
            sel(p.smooth, (v / p.eps).tanh(), plain_sign(v))
        }
    };
    let sign = if p.unheld.all_zero() {
        m.sign
    } else {
        [
            sel(p.unheld, own(v_centroid[0]), m.sign[0]),
            sel(p.unheld, own(v_centroid[1]), m.sign[1]),
        ]
    };
    let area_speed = if THESIS || law.reads_area_speed {
        p.diameter * immersed * held
    } else {
        zero
    };
    let p_local = sel2(p.at_centroid, centroid, p.tip);
    let state = ContactState {
        depth,
        volume: p.section * immersed,
        width: p.diameter,
        l_ref: p.length,
        v: v_centroid,
        area_speed,
        sign,
        boundary: None,
    };
    let mut sums = Sums::zero();
    // Out of the sand in every lane, each use of the law below is blended away: skip it
    // (its `pow`). The results are the same bit for bit.
    if !forced.all_zero() {
        if reads_frame {
            // The boundary the terms read: T's and E's velocities
            // held on the side of the held signs of v_E where a listed term owns the slip
            // switch (`held_shift`: +0 otherwise), P and E in the world, the stuck axes held.
            let shift = |a: usize| {
                if law.owns[a] {
                    (-(sign[a] * v_centroid[a])).select_pos(F::splat(-2.0) * v_centroid[a], zero)
                } else {
                    zero
                }
            };
            let shift = [shift(0), shift(1)];
            let b = Boundary {
                frame: Frame {
                    origin: tip,
                    v: [v_tip[0] + shift[0], v_tip[1] + shift[1]],
                    // q turns clockwise: the counter-clockwise rate is -dq/dt.
                    omega: -omega,
                    axis,
                },
                outline: Outline::Rod {
                    diameter: p.diameter,
                    immersed,
                },
                apply: at(p_local),
                centroid: at(centroid),
                v_centroid: [v_centroid[0] + shift[0], v_centroid[1] + shift[1]],
                // Held only in contact: a lane out of the sand blends the law away, and its
                // held flag would make every lane pay `Rft::held`'s integrations.
                held: [sel(inside, m.stuck_x, zero), sel(inside, m.stuck_y, zero)],
            };
            let state = ContactState {
                boundary: Some(&b),
                ..state
            };
            term_sums::<F, THESIS>(law, &state, &p.medium, &mut sums);
        } else {
            term_sums::<F, THESIS>(law, &state, &p.medium, &mut sums);
        }
    }
    let Sums {
        dynamic,
        statics,
        moment,
        bound,
        forces: each,
    } = sums;
    let total = [dynamic[0] + statics[0], dynamic[1] + statics[1]];
    let lever_p = lever(p_local);
    let torque = total[0] * lever_p[0] + total[1] * lever_p[1];
    let gen = [
        sel(forced, zero + total[0], zero),
        sel(forced, gen1 + total[1], gen1),
        sel(forced, zero + (torque - moment), zero),
    ];
    let qdd = [gen[0] * p.inv_m, gen[1] * p.inv_m, gen[2] * p.inv_i];
    // The sticking row, in closed form: x or y (the lanes' modes have at most one).
    let row_x = sel(forced, m.stuck_x, zero);
    let row_y = sel(forced, m.stuck_y, zero);
    let row = row_x + row_y;
    // No lane sticks: each use of the row below is blended away; skip it (its divisions).
    let (qdd, mult, a, solved) = if row.all_zero() {
        (qdd, zero, F::splat(1.0), None)
    } else {
        let lever_e = lever(centroid);
        // Without spin in every lane (the vertical drop) the bias is blended to zero: skip
        // E's sliding rate (two divisions).
        let a_bias = if omega.all_zero() {
            [zero, zero]
        } else {
            let l_rate = {
                let depth_rate = -v_tip[1];
                let e_y_rate = -axis[0] * omega;
                let rate = depth_rate / axis[1] - depth * e_y_rate / (axis[1] * axis[1]);
                // Zero out of the sand (a law that reads the frame sticks from depth 0) and
                // once fully immersed (`RodContact::immersed_length_rate`).
                sel(depth, sel(p.length - immersed, rate, zero), zero)
            };
            let slide = [
                (F::splat(0.5) * l_rate) * normal[0],
                (F::splat(0.5) * l_rate) * normal[1],
            ];
            let spin = -(omega * omega);
            let a_bias = [
                spin * (centroid[0] * axis[0] + centroid[1] * normal[0]) + omega * slide[0],
                spin * (centroid[0] * axis[1] + centroid[1] * normal[1]) + omega * slide[1],
            ];
            sel2(omega.abs(), a_bias, [zero, zero])
        };
        let bias = sel(row_x, a_bias[0], a_bias[1]);
        let le = sel(row_x, lever_e[0], lever_e[1]);
        let lp = sel(row_x, lever_p[0], lever_p[1]);
        let qdd_row = sel(row_x, qdd[0], qdd[1]);
        let a = p.inv_m + le * (lp * p.inv_i);
        let mult = -(bias + (qdd_row + le * qdd[2])) * a.recip();
        let closed = [
            sel(row_x, qdd[0] + mult * p.inv_m, qdd[0]),
            sel(row_y, qdd[1] + mult * p.inv_m, qdd[1]),
            sel(row, qdd[2] + mult * (lp * p.inv_i), qdd[2]),
        ];
        // One scene (its force set given): the rows the closed form leaves, solved here
        // ([`one_scene_rows`]); the lanes hand such steps to it (`RodModes::of`,
        // [`pivot_ok`]). Ruled out for the lanes when compiled: left to the optimizer, the
        // lanes kept this block's inputs alive (measured: a sweep's lanes 6 % slower).
        let one_scene = if F::LANES == 1 { law.forces } else { None };
        let solved = one_scene.and_then(|set| {
            let l = |x: F| x.lane(0);
            let l2 = |x: [F; 2]| [l(x[0]), l(x[1])];
            let stuck = [l(row_x) > 0.0, l(row_y) > 0.0];
            let shared = |k: usize| stuck[k] && law.owner[k] == usize::MAX;
            let single = !(stuck[0] && stuck[1]) && pivot_ok(l(a));
            if single && !shared(0) && !shared(1) {
                return None;
            }
            let found = ContactForce {
                terms: each.map(|f| Vector2::new(l(f[0]), l(f[1]))),
                dynamic: Vector2::new(l(dynamic[0]), l(dynamic[1])),
                statics: Vector2::new(l(statics[0]), l(statics[1])),
                moment: l(moment),
            };
            Some(one_scene_rows(
                set,
                stuck,
                single.then(|| (closed.map(l), l(mult))),
                (l2(lever_e), l2(lever_p), l2(a_bias)),
                (l(p.inv_m), l(p.inv_i)),
                qdd.map(l),
                found,
            ))
        });
        (closed, mult, a, solved)
    };
    // Each listed term's force, the reaction in its owner's place
    // (`ContactForce::set_reaction`); zero past the list (as the sums left them). A plain
    // loop, inlined, so that a stage that does not read the forces drops them (measured:
    // `std::array::from_fn` here stayed a call, which kept every stage's forces in memory,
    // a tenth to a quarter of a free-link impact on one scene).
    let (owner, listed) = if THESIS {
        ([1, 2], 3)
    } else {
        (law.owner, law.terms.len())
    };
    let mut terms = [[zero; 2]; MAX_TERMS];
    for (k, (term, f)) in terms.iter_mut().zip(each).take(listed).enumerate() {
        let fx = if k == owner[0] {
            sel(row_x, mult, f[0])
        } else {
            f[0]
        };
        let fy = if k == owner[1] {
            sel(row_y, mult, f[1])
        } else {
            f[1]
        };
        *term = sel2(forced, [fx, fy], [zero, zero]);
    }
    let mut statics = sel2(
        forced,
        [sel(row_x, mult, statics[0]), sel(row_y, mult, statics[1])],
        [zero, zero],
    );
    let mut qdd = qdd;
    if let Some((solved_qdd, force)) = solved {
        // (In the sand: a row sticks.)
        let v = |x: Vector2<f64>| [F::splat(x.x), F::splat(x.y)];
        qdd = solved_qdd.map(F::splat);
        terms = force.terms.map(v);
        statics = v(force.statics);
    }
    let dynamic = sel2(forced, dynamic, [zero, zero]);
    let total = [dynamic[0] + statics[0], dynamic[1] + statics[1]];
    let v_p = sel2(p.at_centroid, v_centroid, v_tip);
    let power = sel(
        forced,
        (total[0] * v_p[0] + total[1] * v_p[1]) - moment * omega,
        zero,
    );
    RodEval {
        qdd,
        power,
        tip,
        v_tip,
        depth: depth_out,
        lowest: tip[1],
        v_centroid,
        cross,
        margin,
        immersed,
        axis,
        terms,
        dynamic,
        statics,
        moment: sel(forced, moment, zero),
        bound: sel2(forced, bound, [zero, zero]),
        pivot: sel(row, a, F::splat(1.0)),
    }
}

/// Whether a sticking row's pivot `a` ([`RodEval::pivot`]) is clearly nonzero: else the
/// closed form's reaction would divide by (nearly) zero, and the row is solved with the
/// shifted fallback of [`solve_upto2`] ([`one_scene_rows`]; the lanes hand the step to
/// the one-scene evaluation).
#[inline]
pub fn pivot_ok(a: f64) -> bool {
    a.abs() > 1e-13 * a.abs().max(f64::MIN_POSITIVE)
}

/// The sticking rows of one scene that the kernel's closed form leaves: x and y stuck
/// together (two rows, solved together), or one row whose pivot is not clearly nonzero
/// (solved with [`solve_upto2`]'s shifted fallback; where that fails too, no reaction);
/// `closed` holds the closed form's accelerations and reaction where it stands (one row,
/// a clear pivot). Row `i` holds E's velocity along its axis `u` at zero: its Jacobian is
/// `(u_x, u_y, lever_E . u)`, and its reaction at P gives `(u_x, u_y, lever_P . u)`;
/// `M = diag(m, m, I)` and the bias `a_bias` (E slides over the rod as the immersed part
/// grows) make the system `1/m [u_i = u_j] + lever_E,i lever_P,j / I`. Each reaction goes in
/// place of the static terms that own its axis ([`ContactForce::set_reaction`]: shared by
/// several in proportion to their magnitudes). Returns the accelerations and the forces.
#[cold]
#[inline(never)]
fn one_scene_rows(
    set: &ForceSet,
    stuck: [bool; 2],
    closed: Option<([f64; 3], f64)>,
    (lever_e, lever_p, a_bias): ([f64; 2], [f64; 2], [f64; 2]),
    (inv_m, inv_i): (f64, f64),
    mut qdd: [f64; 3],
    mut force: ContactForce,
) -> ([f64; 3], ContactForce) {
    let mut axes = [0usize; 2];
    let mut k = 0;
    for (axis, _) in stuck.iter().enumerate().filter(|(_, &on)| on) {
        axes[k] = axis;
        k += 1;
    }
    let mut mults = [0.0; 2];
    if let Some((closed_qdd, mult)) = closed {
        qdd = closed_qdd;
        mults[0] = mult;
    } else {
        let mut a = [[0.0; 2]; 2];
        let mut b = [0.0; 2];
        for i in 0..k {
            let ai = axes[i];
            b[i] = -(a_bias[ai] + (qdd[ai] + lever_e[ai] * qdd[2]));
            for j in 0..k {
                let linear = if ai == axes[j] { inv_m } else { 0.0 };
                a[i][j] = linear + lever_e[ai] * (lever_p[axes[j]] * inv_i);
            }
        }
        mults = solve_upto2(k, a, b).unwrap_or([0.0; 2]);
        for i in 0..k {
            qdd[axes[i]] += mults[i] * inv_m;
            qdd[2] += mults[i] * (lever_p[axes[i]] * inv_i);
        }
    }
    for i in 0..k {
        force.set_reaction(set, axes[i], mults[i]);
    }
    (qdd, force)
}

impl RodEval<f64> {
    /// See [`pivot_ok`].
    #[inline]
    pub fn pivot_ok(&self) -> bool {
        pivot_ok(self.pivot)
    }

    /// The drag's stiffness at this evaluation, as [`DragStiffness::of`] finds it.
    #[inline]
    pub fn stiffness(&self) -> DragStiffness {
        let v = Vector2::new(self.v_centroid[0], self.v_centroid[1]);
        DragStiffness {
            drag2: Vector2::new(self.dynamic[0], self.dynamic[1]).norm_squared(),
            speed2: v.norm_squared(),
            contact: 0,
            v,
        }
    }

    /// Write this evaluation into `out` as [`Model::eval_into`] does.
    #[inline]
    pub fn write<const N: usize>(&self, out: &mut Eval<N>) {
        let v2 = |a: [f64; 2]| Vector2::new(a[0], a[1]);
        out.contacts[0] = ContactEval {
            tip: v2(self.tip),
            v_tip: v2(self.v_tip),
            depth: self.depth,
            lowest: self.lowest,
            v_centroid: v2(self.v_centroid),
            force: ContactForce {
                terms: self.terms.map(v2),
                dynamic: v2(self.dynamic),
                statics: v2(self.statics),
                moment: self.moment,
            },
            cross: self.cross,
            immersion_margin: self.margin,
            corners_y: [0.0; 4],
            bound: self.bound,
        };
        out.qdd = SVector::from_fn(|i, _| self.qdd[i]);
        out.power = self.power;
        out.joint_power = 0.0;
        out.joint_torque = [0.0; N];
    }
}

impl RodEval<F64x4> {
    /// Lane `i`.
    #[inline]
    pub fn lane(&self, i: usize) -> RodEval<f64> {
        // Each number read in place (by reference: a lane picked at run time from a value
        // copied into registers went through a copy on the stack, four numbers for one).
        let l = |x: &F64x4| x.0[i];
        let l2 = |x: &[F64x4; 2]| [x[0].0[i], x[1].0[i]];
        let mut terms = [[0.0; 2]; MAX_TERMS];
        for (t, x) in terms.iter_mut().zip(&self.terms) {
            *t = l2(x);
        }
        RodEval {
            qdd: [l(&self.qdd[0]), l(&self.qdd[1]), l(&self.qdd[2])],
            power: l(&self.power),
            tip: l2(&self.tip),
            v_tip: l2(&self.v_tip),
            depth: l(&self.depth),
            lowest: l(&self.lowest),
            v_centroid: l2(&self.v_centroid),
            cross: l(&self.cross),
            margin: l(&self.margin),
            immersed: l(&self.immersed),
            axis: l2(&self.axis),
            terms,
            dynamic: l2(&self.dynamic),
            statics: l2(&self.statics),
            moment: l(&self.moment),
            bound: l2(&self.bound),
            pivot: l(&self.pivot),
        }
    }
}

/// Run scene `s` as [`crate::integrate::solve`] runs it (its RK4 steps through the lane
/// step in one lane, `integrate::lane_step`, where the lanes cover the step) and with every
/// step on the stepper (`Run::general`: `full_step` over [`Model::eval`]), assert the
/// outcomes are the same bit for bit (every field; `what` names the case) and return it:
/// the lane step's stages, sums and hand-overs are the stepper's. For tests here and in
/// `batch.rs`.
#[cfg(test)]
pub(crate) fn lean_equals_general(
    s: &crate::bodies::LinkageScene,
    what: &str,
) -> crate::integrate::outcome::Outcome {
    use crate::integrate::solve::{solve, Run};
    let (model, (q0, qd0)) = (s.model::<3>(), s.initial_state::<3>());
    let lean = solve(&model, q0, qd0, &s.options).unwrap();
    let mut run = Run::new(&model, q0, qd0, &s.options).general();
    while let Some(h) = run.next_step(&model) {
        run.step(&model, h).unwrap();
    }
    let general = run.finish(&model).unwrap();
    assert_eq!(format!("{lean:?}"), format!("{general:?}"), "{what}");
    lean
}

/// Every contact term of the registry that a free link accepts (defined on a rod), as a
/// scene lists it: each number its default or, where it has none (or a zero one that
/// would hide the term), a value given here, times `scale`, within its bounds; each count
/// `count`, within its bounds. A new term with a required parameter fails here, naming it,
/// until it has a value. For the tests here and in `integrate::lanes`.
#[cfg(test)]
pub(crate) fn rod_terms(scale: f64, count: usize) -> Vec<crate::forces::TermSpec> {
    use crate::forces::{Acts, ContactKind, TermSpec, TERMS};
    TERMS
        .iter()
        .filter(|t| t.acts == Acts::Contact && t.shapes.contains(&ContactKind::Rod))
        .map(|t| {
            let params: Vec<(&str, f64)> = t
                .params
                .iter()
                .map(|p| {
                    let base = match (t.name, p.name) {
                        _ if p.integer => count as f64,
                        ("rft", "zeta") => 1e6,
                        ("poncelet", "c") => 0.8,
                        ("poncelet", "k") => 150.0,
                        ("axial_drag", "eta_a") => 0.5,
                        ("constant", "fx") => 0.05,
                        ("constant", "fy") => 0.3,
                        _ if p.required() => panic!("give {}.{} a value here", t.name, p.name),
                        _ => p.default,
                    };
                    let v = if p.integer { base } else { base * scale };
                    (p.name, v.clamp(p.min, p.max))
                })
                .collect();
            TermSpec::new(t.name, &params)
        })
        .collect()
}

/// The terms of [`rod_terms`] that the bits of `mask` pick (bit k: the k-th).
#[cfg(test)]
pub(crate) fn rod_law(mask: u32, scale: f64, count: usize) -> Vec<crate::forces::TermSpec> {
    rod_terms(scale, count)
        .into_iter()
        .enumerate()
        .filter(|(k, _)| mask & (1 << k) != 0)
        .map(|(_, t)| t)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bodies::LinkageScene;
    use crate::dynamics::{Modes, MAX_CONTACTS};
    use crate::forces::{ForceSet, TermSpec};
    use crate::presets::{free_link::FreeLink, Rod, Setting};
    use proptest::prelude::*;

    /// A free link with its own mass, length, law and point of application.
    fn model(mass: f64, length: f64, eta: [f64; 4], centroid: bool, gravity: bool) -> Model<3> {
        model_signed(
            mass,
            length,
            eta,
            centroid,
            gravity,
            SignModel::Modes,
            0b111,
        )
    }

    /// [`model`] under a sign model of its own, with the thesis's terms that `terms` lists
    /// (bits 1: `drag`, 2: `static_h`, 4: `static_v`).
    fn model_signed(
        mass: f64,
        length: f64,
        eta: [f64; 4],
        centroid: bool,
        gravity: bool,
        sign_model: SignModel,
        terms: u8,
    ) -> Model<3> {
        let mut specs = vec![];
        if gravity {
            specs.push(TermSpec::new("gravity", &[]));
        }
        specs.extend(thesis_subset(eta, terms));
        let rod = FreeLink::default().rod;
        let scene = FreeLink {
            rod: Rod {
                mass,
                length,
                ..rod
            },
            ..FreeLink::default()
        }
        .scene(Setting {
            apply_at: if centroid {
                ApplyAt::Centroid
            } else {
                ApplyAt::Tip
            },
            forces: ForceSet::build(&specs, 1).unwrap(),
            ..Setting::default()
        });
        let mut model = scene.model::<3>();
        model.sign_model = sign_model;
        model
    }

    /// [`model_signed`] under the frame terms `law` (and `gravity` as it says).
    fn model_frame(base: (f64, f64, bool, bool, SignModel), law: &[TermSpec]) -> Model<3> {
        let (mass, length, centroid, gravity, sign_model) = base;
        let mut model = model_signed(mass, length, [0.0; 4], centroid, gravity, sign_model, 0);
        let mut specs = vec![];
        if gravity {
            specs.push(TermSpec::new("gravity", &[]));
        }
        specs.extend_from_slice(law);
        model.forces = ForceSet::build(&specs, 1).unwrap();
        model
    }

    /// Frame laws the lean path covers, by number (the proptest's and the runs' axis): `rft`
    /// (`zeta`, elements), `poncelet` (`c`, `k`), `rft_inertial` alone, and `rft` with
    /// `rft_inertial` in either order, `poncelet` with it.
    fn frame_law(kind: u8, a: f64, n: usize) -> Vec<TermSpec> {
        let rft = TermSpec::new("rft", &[("zeta", a), ("elements", n as f64)]);
        let poncelet = TermSpec::new("poncelet", &[("c", 1e-6 * a), ("k", 1e-4 * a)]);
        let inertial = TermSpec::new("rft_inertial", &[("lam", 1e-6 * a), ("elements", n as f64)]);
        match kind % 6 {
            0 => vec![rft],
            1 => vec![poncelet],
            2 => vec![inertial],
            3 => vec![rft, inertial],
            4 => vec![inertial, rft],
            _ => vec![poncelet, inertial],
        }
    }

    /// The thesis's terms with coefficients `eta` that `terms` lists (see [`model_signed`]).
    fn thesis_subset(eta: [f64; 4], terms: u8) -> Vec<TermSpec> {
        let all = [
            TermSpec::new("drag", &[("eta_d", eta[0])]),
            TermSpec::new("static_h", &[("eta_h", eta[1])]),
            TermSpec::new("static_v", &[("eta_v", eta[2]), ("lam", eta[3])]),
        ];
        all.into_iter()
            .enumerate()
            .filter(|(k, _)| terms & (1 << k) != 0)
            .map(|(_, t)| t)
            .collect()
    }

    fn slip(i: u8) -> Slip {
        [Slip::Neg, Slip::Pos, Slip::Stick][i as usize % 3]
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// A sign model: `modes`, `raw` or `smooth` with an eps of 1e-3 .. 0.5 m/s.
    fn sign_model() -> impl Strategy<Value = SignModel> {
        prop_oneof![
            Just(SignModel::Modes),
            Just(SignModel::Raw),
            (1e-3f64..0.5).prop_map(|eps| SignModel::Smooth { eps }),
        ]
    }

    /// One lane's scene: (mass, length, eta_d, eta_h, eta_v, lam, centroid, gravity, signs).
    #[allow(clippy::type_complexity)]
    fn scene() -> impl Strategy<Value = (f64, f64, f64, f64, f64, f64, bool, bool, SignModel)> {
        (
            0.05f64..1.0,
            0.05f64..0.4,
            0.0f64..40.0,
            0.0f64..20.0,
            0.0f64..600.0,
            0.0f64..1.0,
            any::<bool>(),
            any::<bool>(),
            sign_model(),
        )
    }

    /// One lane's state and mode: (th, depth, vx, vy, w, sx, sy, cross, in_contact, spin).
    fn state() -> impl Strategy<Value = (f64, f64, f64, f64, f64, u8, u8, bool, bool, bool)> {
        (
            -3.2f64..3.2,
            -0.05f64..0.3,
            -3.0f64..3.0,
            -3.0f64..3.0,
            -40.0f64..40.0,
            0u8..3,
            0u8..3,
            any::<bool>(),
            any::<bool>(),
            any::<bool>(),
        )
    }

    proptest! {
        /// Four scenes in four lanes give, each, the one-scene evaluation ([`Model::eval`],
        /// the kernel in `f64` with the model's own terms) bit for bit (the blends are the
        /// branches):
        /// the accelerations, the power and every finding of the contact (what the events
        /// and the observer read), in every mode the lanes cover, under every sign model and
        /// any law the free link accepts (any of the registry's terms a rod takes, alone or
        /// mixed), its terms and counts shared by the lanes, each lane's own numbers.
        #[test]
        fn lanes_are_the_scalar_evaluation_bitwise(
            scenes in proptest::array::uniform4(scene()),
            states in proptest::array::uniform4(state()),
            mask in 1u32..(1 << rod_terms(1.0, 1).len()),
            count in 1usize..14,
        ) {
            let models: Vec<Model<3>> = scenes
                .iter()
                .map(|s| {
                    let law = rod_law(mask, 0.5 + s.2 / 40.0, count);
                    model_frame((s.0, s.1, s.6, s.7, s.8), &law)
                })
                .collect();
            let params_of = |i: usize| RodParams::of(&models[i]).unwrap();
            let mut params = RodParams::splat(&params_of(0));
            let default = ContactMode::default();
            let mut modes = [RodModes::of(&default, &params_of(0)).unwrap(); LANES];
            let mut all_modes = [[ContactMode::default(); MAX_CONTACTS]; LANES];
            let (mut q, mut qd) = ([F64x4::splat(0.0); 3], [F64x4::splat(0.0); 3]);
            let mut covered = [true; LANES];
            for i in 0..LANES {
                params.set(i, &params_of(i));
                let (th, depth, vx, vy, w, sx, sy, cross, inside, spin) = states[i];
                let half = 0.5 * scenes[i].1;
                let state_q = [half * th.sin(), half * th.cos() - depth, th];
                let state_qd = [vx, vy, if spin { w } else { 0.0 }];
                for k in 0..3 {
                    q[k].0[i] = state_q[k];
                    qd[k].0[i] = state_qd[k];
                }
                all_modes[i][0] = ContactMode {
                    in_contact: inside,
                    sx: slip(sx),
                    sy: slip(sy),
                    cross: if cross { Slip::Neg } else { Slip::Pos },
                    ..ContactMode::default()
                };
                match RodModes::of(&all_modes[i][0], &params_of(i)) {
                    Some(m) => modes[i] = m,
                    None => covered[i] = false,
                }
            }
            let lanes = rod_eval(&params, &RodModes::gather(&modes), &q, &qd);
            for i in 0..LANES {
                if !covered[i] {
                    continue;
                }
                let lane = lanes.lane(i);
                let m: &Modes = &all_modes[i];
                let sq = SVector::<f64, 3>::new(q[0].0[i], q[1].0[i], q[2].0[i]);
                let sqd = SVector::<f64, 3>::new(qd[0].0[i], qd[1].0[i], qd[2].0[i]);
                let scalar = models[i].eval(&sq, &sqd, m);
                if !lane.pivot_ok() {
                    continue;
                }
                let mut mine = scalar;
                lane.write(&mut mine);
                prop_assert_eq!(bits(mine.qdd.as_slice()), bits(scalar.qdd.as_slice()), "lane {}", i);
                prop_assert_eq!(mine.power.to_bits(), scalar.power.to_bits());
                let (a, b) = (mine.contacts[0], scalar.contacts[0]);
                let flat = |c: &ContactEval| {
                    let mut v = vec![
                        c.tip.x, c.tip.y, c.v_tip.x, c.v_tip.y, c.depth, c.lowest,
                        c.v_centroid.x, c.v_centroid.y, c.cross, c.immersion_margin,
                        c.bound[0], c.bound[1], c.force.dynamic.x, c.force.dynamic.y,
                        c.force.statics.x, c.force.statics.y, c.force.moment,
                    ];
                    for t in &c.force.terms {
                        v.extend([t.x, t.y]);
                    }
                    v
                };
                prop_assert_eq!(bits(&flat(&a)), bits(&flat(&b)), "lane {}", i);
                let st = lane.stiffness();
                let sc = DragStiffness::of(0, &b);
                prop_assert_eq!(bits(&[st.drag2, st.speed2]), bits(&[sc.drag2, sc.speed2]));
            }
        }
    }

    /// The free link dropped at `[q_deg, v0, vx0]` under `sign` model, applied `at`, with
    /// `gravity` and the contact terms `law`.
    fn drop_scene(
        start: [f64; 3],
        sign: &'static str,
        at: &'static str,
        law: &[TermSpec],
    ) -> LinkageScene {
        use crate::spec::Value;
        let mut spec = crate::spec::free_link_spec();
        for (field, x) in ["q_deg", "v0", "vx0"].into_iter().zip(start) {
            spec.set(field, Value::Num(x));
        }
        spec.set("sign_model", Value::Str(sign.into()));
        spec.set("apply_at", Value::Str(at.into()));
        let Ok(mut s) = spec.build() else {
            panic!("the free link does not build");
        };
        let mut specs = vec![TermSpec::new("gravity", &[])];
        specs.extend_from_slice(law);
        s.forces = ForceSet::build(&specs, 1).unwrap();
        s
    }

    /// [`lean_equals_general`] for a scene the lean path covers (asserted).
    fn lean_run_is_the_general_one(
        s: &LinkageScene,
        what: &str,
    ) -> crate::integrate::outcome::Outcome {
        assert!(RodParams::of(&s.model::<3>()).is_some(), "{what}");
        lean_equals_general(s, what)
    }

    /// A free link with any of the thesis's terms runs its lean steps to the general path's
    /// outcome bit for bit (every field, summaries and counts): the terms it lists, under
    /// each sign model, at the tip and the centroid, through entry, sticking and stops.
    #[test]
    fn lean_runs_with_any_of_the_thesis_terms_are_the_general_path_bitwise() {
        let mut lean_steps = 0;
        for terms in 0u8..8 {
            for sign in ["modes", "raw", "smooth"] {
                for at in ["tip", "centroid"] {
                    for (q, v0) in [(0.0, 2.214), (5.0, 1.12), (45.0, 2.27), (85.0, 0.7)] {
                        let law = thesis_subset([15.2, 6.5, 248.0, 0.106], terms);
                        let s = drop_scene([q, v0, 0.0], sign, at, &law);
                        let what = format!("terms {terms:03b} {sign} {at} q {q}");
                        lean_steps += lean_run_is_the_general_one(&s, &what).stats.steps;
                    }
                }
            }
        }
        assert!(lean_steps > 50_000, "{lean_steps} steps");
    }

    /// A frame law's sticking row at depth 0 with spin (the tip at the surface, in contact,
    /// y stuck): the rate of the immersed length is zero out of the sand, in every lane of
    /// the lanes as in one scene (the proptest found it; pinned here).
    #[test]
    fn a_frame_law_sticking_at_depth_zero_with_spin_is_the_general_path() {
        let mode = ContactMode {
            in_contact: true,
            sx: Slip::Neg,
            sy: Slip::Stick,
            ..ContactMode::default()
        };
        let mut modes = [ContactMode::default(); MAX_CONTACTS];
        modes[0] = mode;
        for kind in [0u8, 1, 3] {
            let base = (0.05, 0.05, false, false, SignModel::Modes);
            let model = model_frame(base, &frame_law(kind, 1e4, 1));
            let p = RodParams::of(&model).unwrap();
            let m = RodModes::of(&mode, &p).unwrap();
            assert_eq!(m.stuck_y, 1.0);
            let th: f64 = 0.34151223113018786;
            let q = [0.025 * th.sin(), 0.025 * th.cos(), th];
            let qd = [0.0, 0.0, 11.628250912542002];
            let general = model.eval(&SVector::from(q), &SVector::from(qd), &modes);
            let mut lean = general;
            let one = rod_eval(&p, &m, &q, &qd);
            assert!(one.pivot_ok());
            one.write(&mut lean);
            assert_eq!(
                bits(lean.qdd.as_slice()),
                bits(general.qdd.as_slice()),
                "{kind}"
            );
            assert_eq!(lean.power.to_bits(), general.power.to_bits(), "{kind}");
            let s = |x: f64| F64x4::splat(x);
            let lanes = rod_eval(
                &RodParams::splat(&p),
                &RodModes::gather(&[m; LANES]),
                &q.map(s),
                &qd.map(s),
            );
            for i in 0..LANES {
                let mut lane = general;
                lanes.lane(i).write(&mut lane);
                assert_eq!(
                    bits(lane.qdd.as_slice()),
                    bits(general.qdd.as_slice()),
                    "{kind}"
                );
            }
        }
    }

    /// A free link under a frame law (`rft`, `poncelet`, `rft_inertial`, alone or paired)
    /// runs its lean steps to the general path's outcome bit for bit: the moments, the held
    /// reaction in y, the held sign's shift of the frame, under each sign model, at the tip
    /// and the centroid, with the paper's and other coefficients and element counts, through
    /// drops with sideways speed.
    #[test]
    fn lean_runs_under_frame_laws_are_the_general_path_bitwise() {
        use crate::integrate::solve::Run;
        let mut lean_steps = 0;
        let mut stuck = 0;
        let rft = |law: &[(&str, f64)]| TermSpec::new("rft", law);
        let inertial = TermSpec::new("rft_inertial", &[("lam", 0.7)]);
        let poncelet = TermSpec::new("poncelet", &[("c", 0.8), ("k", 150.0)]);
        let laws: Vec<Vec<TermSpec>> = vec![
            vec![rft(&[("zeta", 1e6)])],
            vec![rft(&[("zeta", 3e5), ("elements", 3.0)])],
            vec![rft(&[
                ("zeta", 2e6),
                ("elements", 13.0),
                ("A10", 0.3),
                ("C01", 0.4),
                ("D10", -0.1),
            ])],
            vec![poncelet.clone()],
            vec![rft(&[("zeta", 1e6)]), inertial.clone()],
            vec![inertial.clone(), rft(&[("zeta", 3e5), ("elements", 5.0)])],
            vec![poncelet, inertial.clone()],
            vec![inertial],
        ];
        for (k, law) in laws.iter().enumerate() {
            for sign in ["modes", "raw", "smooth"] {
                for at in ["tip", "centroid"] {
                    for (q, v0, vx0) in [
                        (0.0, 2.214, 0.0),
                        (5.0, 1.12, 0.0),
                        (45.0, 2.27, 0.0),
                        (85.0, 0.7, 0.0),
                        (0.0, 0.3, 2.0),
                        (-30.0, 0.5, 3.0),
                        (60.0, 0.2, -2.5),
                    ] {
                        let s = drop_scene([q, v0, vx0], sign, at, law);
                        let what = format!("law {k} {sign} {at} q {q}");
                        lean_steps += lean_run_is_the_general_one(&s, &what).stats.steps;
                        let (model, (q0, qd0)) = (s.model::<3>(), s.initial_state::<3>());
                        // Steps the lean path takes with y stuck (its sticking row).
                        let mut run = Run::new(&model, q0, qd0, &s.options);
                        while let Some(h) = run.next_step(&model) {
                            if let Some((_, m, _)) = run.lane_start(h) {
                                stuck += usize::from(m.stuck_y > 0.0);
                            }
                            run.step(&model, h).unwrap();
                        }
                    }
                }
            }
        }
        assert!(
            lean_steps > 20_000 && stuck > 100,
            "{lean_steps} steps, {stuck} stuck"
        );
    }

    proptest! {
        /// One scene's term sums (`term_sums` over the model's own force set,
        /// [`RodTerms::of_forces`]) are `terms_on`'s, bitwise: every term's force, the sums
        /// by class, the moment and the bounds; the thesis's three in its order take the
        /// compiled-in kernel (their numbers copied out of the terms), in any other order
        /// each term's own `contact_force`.
        #[test]
        fn one_scenes_term_sums_are_terms_on(
            depth in 1e-6f64..0.2, l in 1e-4f64..0.19, vx in -3.0f64..3.0,
            vy in -3.0f64..3.0, area_speed in 0.0f64..0.01, sx in 0u8..3, sy in 0u8..3,
            order in 0usize..6,
        ) {
            let state = ContactState {
                depth,
                volume: std::f64::consts::FRAC_PI_4 * 0.0127 * 0.0127 * l,
                width: 0.0127,
                l_ref: 0.19,
                v: [vx, vy],
                area_speed,
                sign: [slip(sx).sign(), slip(sy).sign()],
                boundary: None,
            };
            let terms = [
                TermSpec::new("drag", &[("eta_d", 11.0)]),
                TermSpec::new("static_h", &[("eta_h", 5.5)]),
                TermSpec::new("static_v", &[("eta_v", 53.0), ("lam", 0.25)]),
            ];
            let perm = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]][order];
            let specs: Vec<TermSpec> = perm.iter().map(|&i| terms[i].clone()).collect();
            let forces = ForceSet::build(&specs, 1).unwrap();
            let medium = Medium::default();
            let mut numbers = [0.0; 4];
            let law = RodTerms::of_forces(&forces, &mut numbers);
            prop_assert_eq!(law.thesis, order == 0);
            let mut sums = Sums::zero();
            if law.thesis {
                prop_assert_eq!(law.numbers, &[11.0, 5.5, 53.0, 0.25][..]);
                term_sums::<f64, true>(&law, &state, &medium, &mut sums);
            } else {
                term_sums::<f64, false>(&law, &state, &medium, &mut sums);
            }
            let mut general = ContactForce::default();
            let mut bound = [0.0; 2];
            crate::dynamics::terms_on(
                &forces,
                &forces.per_contact[0],
                &state,
                &medium,
                &mut general,
                &mut bound,
            );
            let v2 = |a: [f64; 2]| Vector2::new(a[0], a[1]);
            let mine = ContactForce {
                terms: sums.forces.map(v2),
                dynamic: v2(sums.dynamic),
                statics: v2(sums.statics),
                moment: sums.moment,
            };
            prop_assert_eq!(mine, general);
            prop_assert_eq!(sums.bound, bound);
        }
    }

    /// A sticking row whose pivot `1/m + lever_E lever_P / I` is exactly zero: one scene's
    /// kernel solves it with the shifted system (`solve_upto2`), where the closed form
    /// would divide by zero. A vertical rod at rest, stuck in x, pressed only downwards:
    /// the row's right-hand side is zero, so the reaction is zero (not 0 / 0) and the
    /// accelerations are those with nothing stuck. The lanes hand the step over.
    #[test]
    fn a_zero_pivot_is_solved_in_one_scene_and_handed_over_by_the_lanes() {
        let model = model(0.184, 0.19, [15.2, 6.5, 248.0, 0.106], false, true);
        let rod = *model.rigid_rod().unwrap();
        let mut body = RodBody::of(&model, &rod);
        let depth = 0.05;
        // Vertical (e = (0, 1), n = (1, 0)): a point's lever along x is its local x.
        let q = [0.0, -rod.tip.x - depth, 0.0];
        let qd = [0.0; 3];
        let (lever_p, lever_e) = (rod.tip.x, rod.tip.x + 0.5 * depth);
        body.inv_m = -(lever_e * (lever_p * body.inv_i));
        let mut numbers = [0.0; 4];
        let law = RodTerms::of_forces(&model.forces, &mut numbers);
        let stuck = ContactMode {
            in_contact: true,
            sx: Slip::Stick,
            sy: Slip::Neg,
            ..ContactMode::default()
        };
        let free = ContactMode {
            sx: Slip::Pos,
            ..stuck
        };
        let m = RodModes::held(&stuck, body.unheld, law.owns);
        assert_eq!((m.stuck_x, m.stuck_y), (1.0, 0.0));
        let one = rod_eval_terms(&body, &law, &m, &q, &qd);
        assert_eq!(one.pivot, 0.0);
        let m_free = RodModes::held(&free, body.unheld, law.owns);
        let slides = rod_eval_terms(&body, &law, &m_free, &q, &qd);
        // At rest and vertical, nothing pushes sideways nor turns the rod: stuck, the
        // reaction in static_h's place is zero; the vertical acceleration is the same as
        // sliding (y's terms are the same).
        assert_eq!(one.terms[1][0], 0.0);
        assert_eq!(one.statics[0], 0.0);
        assert_eq!(one.qdd[0], 0.0);
        assert_eq!(one.qdd[1], slides.qdd[1]);
        assert!(one.qdd.iter().all(|x| x.is_finite()), "{:?}", one.qdd);
        // Without the force set (as the lanes read their law) the closed form divides by
        // the zero pivot, which `pivot_ok` flags for the hand-over.
        let lanes_law = RodTerms {
            forces: None,
            ..law
        };
        let lanes = rod_eval_terms(&body, &lanes_law, &m, &q, &qd);
        assert!(!lanes.pivot_ok());
        assert!(lanes.qdd[0].is_nan(), "{:?}", lanes.qdd);
    }

    /// Only a free link runs in the lanes: not a body with no contact at all (a linkage
    /// with none: `Run::new` asks every model).
    #[test]
    fn only_a_free_link_runs_in_the_lanes() {
        let mut pendulum = model(0.184, 0.19, [15.2, 6.5, 248.0, 0.106], false, true);
        pendulum.forces.per_contact.clear();
        pendulum.contacts.clear();
        assert!(RodParams::of(&pendulum).is_none());
    }

    /// Runs share the lanes when their laws list the same terms in the same order with the
    /// same counts, whatever their numbers (each lane has its own).
    #[test]
    fn laws_share_the_lanes_by_their_terms_and_counts() {
        let base = (0.184, 0.19, false, true, SignModel::Modes);
        let law = |kind: u8, a: f64, n: usize| {
            RodParams::of(&model_frame(base, &frame_law(kind, a, n)))
                .unwrap()
                .law
        };
        assert!(law(0, 1e6, 8).shares(&law(0, 3e5, 8)));
        assert!(law(1, 1e6, 8).shares(&law(1, 2e5, 3)));
        assert!(!law(0, 1e6, 8).shares(&law(0, 1e6, 7)));
        assert!(!law(0, 1e6, 8).shares(&law(1, 1e6, 8)));
        assert!(!law(0, 1e6, 8).shares(&law(3, 1e6, 8)));
        // The same terms in another order: another law (the sums' order is the list's).
        assert!(!law(3, 1e6, 8).shares(&law(4, 1e6, 8)));
        assert!(!law(2, 1e6, 8).shares(&law(2, 1e6, 5)));
        let thesis = |eta: [f64; 4], terms: u8| {
            let m = model_signed(0.184, 0.19, eta, false, true, SignModel::Modes, terms);
            RodParams::of(&m).unwrap().law
        };
        let table = [15.2, 6.5, 248.0, 0.106];
        assert!(thesis(table, 0b111).shares(&thesis([9.0, 1.0, 100.0, 0.3], 0b111)));
        assert!(!thesis(table, 0b111).shares(&thesis(table, 0b101)));
        assert!(!thesis(table, 0b111).shares(&law(0, 1e6, 8)));
    }

    /// The lanes cover every law, and hand the one-scene evaluation the steps they do not: two
    /// sticking rows, or a row whose reaction several static terms share.
    #[test]
    fn lanes_cover_every_law_and_hand_over_the_rows_they_do_not() {
        let thesis = model(0.184, 0.19, [15.2, 6.5, 248.0, 0.106], false, true);
        let flags =
            |m: &Model<3>| RodParams::of(m).map(|p| (p.body.unheld, p.body.smooth, p.body.eps));
        assert_eq!(flags(&thesis), Some((0.0, 0.0, 1.0)));
        let mut raw = thesis.clone();
        raw.sign_model = SignModel::Raw;
        assert_eq!(flags(&raw), Some((1.0, 0.0, 1.0)));
        let mut smooth = thesis.clone();
        smooth.sign_model = SignModel::Smooth { eps: 1e-3 };
        assert_eq!(flags(&smooth), Some((1.0, 1.0, 1e-3)));
        let p = RodParams::of(&thesis).unwrap();
        assert!(p.law.thesis);
        assert_eq!((p.law.owns, p.law.owner), ([true, true], [1, 2]));
        assert_eq!(p.numbers[..4], [15.2, 6.5, 248.0, 0.106]);
        // Any of the thesis's terms in any order: covered, on the step for any law.
        let mut reordered = thesis.clone();
        reordered.forces = ForceSet::build(
            &[
                TermSpec::new("static_h", &[("eta_h", 6.5)]),
                TermSpec::new("drag", &[("eta_d", 15.2)]),
                TermSpec::new("static_v", &[("eta_v", 248.0), ("lam", 0.106)]),
            ],
            1,
        )
        .unwrap();
        let p = RodParams::of(&reordered).unwrap();
        assert!(!p.law.thesis);
        assert_eq!(
            (p.law.at[..3].to_vec(), p.law.owner),
            (vec![0, 1, 2], [0, 2])
        );
        assert_eq!(p.numbers[..4], [6.5, 15.2, 248.0, 0.106]);
        let both = ContactMode {
            in_contact: true,
            ..ContactMode::default()
        };
        assert!(RodModes::of(&both, &RodParams::of(&thesis).unwrap()).is_none());
        // Under the plain sign nothing sticks: the same mode is covered, with no row.
        let plain = RodModes::of(&both, &RodParams::of(&raw).unwrap()).unwrap();
        assert_eq!((plain.stuck_x, plain.stuck_y), (0.0, 0.0));
        // `rft` alone owns y, not x: the mode that sticks in both is covered with y's row.
        let base = (0.184, 0.19, false, true, SignModel::Modes);
        let rft = RodParams::of(&model_frame(base, &frame_law(0, 1e6, 8))).unwrap();
        assert_eq!(
            (rft.law.owns, rft.law.owner),
            ([false, true], [usize::MAX, 0])
        );
        let m = RodModes::of(&both, &rft).unwrap();
        assert_eq!((m.stuck_x, m.stuck_y), (0.0, 1.0));
        // `poncelet` and `static_v` share y's reaction: a step sticking in y is the scalar
        // path's, one sliding is the lanes'.
        let shared = model_frame(
            base,
            &[
                TermSpec::new("poncelet", &[("c", 0.8), ("k", 150.0)]),
                TermSpec::new("static_v", &[("eta_v", 248.0), ("lam", 0.106)]),
            ],
        );
        let p = RodParams::of(&shared).unwrap();
        assert_eq!((p.law.owns, p.law.owner), ([false, true], [usize::MAX; 2]));
        assert!(RodModes::of(&both, &p).is_none());
        let sliding = ContactMode {
            sy: Slip::Neg,
            ..both
        };
        assert!(RodModes::of(&sliding, &p).is_some());
    }
}
