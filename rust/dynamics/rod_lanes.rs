//! The free link under the thesis's terms or a law of terms that read the contact's frame
//! (`rft`, `poncelet`, `rft_inertial`), for one scene or several at once:
//! [`Model::eval_rigid_rod`] written over [`Real`]. With `F = f64` it is the lean path of a
//! lone run's RK4 steps (`integrate::solve::Run::step`: a stage computes only what the step
//! reads, after inlining); with `F = F64x4` it evaluates four scenes, one per SIMD lane, in
//! the same instructions (the sweep's lanes, `integrate::lanes`).
//!
//! The force law is not copied: the terms' own arithmetic ([`Drag::law`], [`StaticH::law`],
//! [`StaticV::law`], what their `contact_force` runs) is called with one parameter per lane,
//! and the frame terms' own arithmetic (`force_with`, what their `contact_force` runs) on
//! the boundary the general path gives them, with one number per lane (the four lanes share
//! the terms and element counts: `rft`'s sets its loop). The mechanics (the rod's
//! frame, its immersed geometry, the closed-form sticking row and the sums of
//! [`super::rigid_rod`]) are written again without branches: each branch of the scalar path
//! becomes a blend ([`Real::select_pos`]) on a per-lane flag, and each operation is the
//! scalar path's, in its order, so that the results are [`Model::eval`]'s bit for bit (tests
//! hold them so over random states and modes, and whole runs to the general path). Two
//! blocks are skipped when every lane blends them away (the law out of the sand, the
//! sticking row when nothing sticks): the same bits, less work.
//!
//! What it covers: a free link ([`Model::rigid_rod`]), applied at the tip or at the centroid,
//! under any sign model (`modes`, held through a step; the thesis's plain sign `raw` and
//! `smooth`'s tanh, each evaluation's own, with no sticking), whose contact terms are
//! ([`RodParams::of`], [`RodLayout::of`]):
//! - the thesis's three or any of them (`drag`, `static_h`, `static_v`, in that order;
//!   `gravity` on or off: an absent term is one with a zero coefficient, whose force is
//!   exactly zero, so every sum has the general path's bits); or
//! - a [`FrameLaw`]: `rft` or `poncelet`, `rft_inertial`, or one of the first two with the
//!   third, in either order (their moments, the held sign's shift of the frame and the
//!   bounded reaction in y, from depth 0 while in contact, as the general path reads a law
//!   that reads the frame);
//!
//! and in modes with at most one sticking row ([`RodModes::of`]). A step in a mode that
//! sticks in both x and y, or whose one sticking row has a zero pivot ([`RodEval::pivot`]),
//! is taken on the general path.

use nalgebra::{SVector, Vector2};

use super::{ContactEval, ContactForce, ContactMode, DragStiffness, Eval, Model, SignModel, Slip};
use crate::body::rod::ApplyAt;
use crate::forces::drag::Drag;
use crate::forces::poncelet::Poncelet;
use crate::forces::rft::{Rft, RftCoefficients, RftInertial};
use crate::forces::static_h::StaticH;
use crate::forces::static_v::StaticV;
use crate::forces::{
    AnyTerm, Boundary, ContactState, Frame, Medium, Outline, Real, Term, TermForce,
};
use crate::num::{F64x4, LANES};

/// What the evaluation of one free link under the thesis's terms or a [`FrameLaw`] reads
/// that is fixed through a run: its mass, geometry, medium and the terms' parameters (one
/// lane per scene; a frame law's one for all four).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodParams<F> {
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
    /// drag.eta_d.
    pub eta_d: F,
    /// static_h.eta_h.
    pub eta_h: F,
    /// static_v.eta_v.
    pub eta_v: F,
    /// static_v.lam.
    pub lam: F,
    /// 1 where the signs of v_E and of e x v_E are each evaluation's own (`raw`, `smooth`),
    /// 0 under `modes` (held through a step).
    pub unheld: F,
    /// 1 under `smooth` (the signs of v_E are tanh(v / eps)), else 0.
    pub smooth: F,
    /// `smooth`'s eps [m/s] (1 under the other sign models).
    pub eps: F,
    /// The law when its terms read the contact's frame ([`FrameLaw`]; then the thesis's
    /// coefficients are zero): its terms and element counts one for every lane (the lanes
    /// take only runs with the same, [`same_law`], [`RodParams::set`]), its numbers in
    /// `frame_numbers`.
    pub frame: Option<FrameLaw>,
    /// The frame law's numbers, one per lane (zero for a term it does not list).
    pub frame_numbers: FrameNumbers<F>,
}

/// A [`FrameLaw`]'s numbers in `F`, one per lane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameNumbers<F> {
    /// `rft`'s `zeta` and coefficients.
    pub rft: RftCoefficients<F>,
    /// `poncelet`'s `c` and `k`.
    pub poncelet: [F; 2],
    /// `rft_inertial`'s `lam`.
    pub lam: F,
}

impl FrameNumbers<f64> {
    /// The numbers of `law` (zeros without one).
    fn of(law: Option<&FrameLaw>) -> Self {
        let mut n = FrameNumbers {
            rft: RftCoefficients {
                zeta: 0.0,
                k: [0.0; 9],
            },
            poncelet: [0.0; 2],
            lam: 0.0,
        };
        match law.and_then(|l| l.statics) {
            Some(FrameStatic::Rft(r)) => n.rft = r.coefficients_in(),
            Some(FrameStatic::Poncelet(t)) => n.poncelet = [t.c, t.k],
            None => {}
        }
        if let Some(r) = law.and_then(|l| l.inertial) {
            n.lam = r.lam;
        }
        n
    }
}

impl FrameNumbers<F64x4> {
    /// Every lane `n`.
    fn splat(n: &FrameNumbers<f64>) -> Self {
        let s = F64x4::splat;
        FrameNumbers {
            rft: RftCoefficients {
                zeta: s(n.rft.zeta),
                k: n.rft.k.map(s),
            },
            poncelet: n.poncelet.map(s),
            lam: s(n.lam),
        }
    }

    /// Each value.
    pub fn each(&mut self, mut f: impl FnMut(&mut F64x4)) {
        f(&mut self.rft.zeta);
        self.rft.k.iter_mut().for_each(&mut f);
        self.poncelet.iter_mut().for_each(&mut f);
        f(&mut self.lam);
    }

    /// Lane `i` becomes `n`.
    fn set(&mut self, i: usize, n: &FrameNumbers<f64>) {
        self.rft.zeta.0[i] = n.rft.zeta;
        for (x, v) in self.rft.k.iter_mut().zip(n.rft.k) {
            x.0[i] = v;
        }
        for (x, v) in self.poncelet.iter_mut().zip(n.poncelet) {
            x.0[i] = v;
        }
        self.lam.0[i] = n.lam;
    }
}

/// A law of terms that read the contact's frame, as the lean path runs it: at most one
/// static term (`rft` or `poncelet`, the owner of y's slip switch, in `static_v`'s place)
/// and at most one dynamic one (`rft_inertial`, in `drag`'s place), in either order (two
/// terms' sums are the same in either).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameLaw {
    /// The static term.
    pub statics: Option<FrameStatic>,
    /// `rft_inertial`.
    pub inertial: Option<RftInertial>,
}

/// The static term of a [`FrameLaw`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrameStatic {
    /// Resistive force theory.
    Rft(Rft),
    /// The Poncelet / Katsuragi-Durian law.
    Poncelet(Poncelet),
}

/// Whether two runs' frame laws can share the lanes: the same terms with the same element
/// counts (their numbers are per lane, [`FrameNumbers`]).
pub fn same_law(a: &Option<FrameLaw>, b: &Option<FrameLaw>) -> bool {
    let shape = |law: &Option<FrameLaw>| {
        law.map(|l| {
            let statics = match l.statics {
                Some(FrameStatic::Rft(r)) => (1, r.elements),
                Some(FrameStatic::Poncelet(_)) => (2, 0),
                None => (0, 0),
            };
            (statics, l.inertial.map(|r| r.elements))
        })
    };
    shape(a) == shape(b)
}

impl FrameLaw {
    /// The law `terms` make, with where each stands ([`RodLayout::slot`]), when they are
    /// terms that read the frame as [`FrameLaw`] allows.
    fn of(terms: &[AnyTerm]) -> Option<(Self, [usize; 3])> {
        let mut law = FrameLaw {
            statics: None,
            inertial: None,
        };
        let mut slot = [usize::MAX; 3];
        for (k, t) in terms.iter().enumerate() {
            let statics = match t {
                AnyTerm::Rft(r) => FrameStatic::Rft(*r),
                AnyTerm::Poncelet(p) => FrameStatic::Poncelet(*p),
                AnyTerm::RftInertial(r) if law.inertial.is_none() => {
                    law.inertial = Some(*r);
                    slot[0] = k;
                    continue;
                }
                _ => return None,
            };
            if law.statics.is_some() {
                return None;
            }
            law.statics = Some(statics);
            slot[2] = k;
        }
        (!terms.is_empty()).then_some((law, slot))
    }
}

/// Where a run's listed terms stand in the lean path's three places, read on the scalar
/// side only (kept out of [`RodParams`], which the lanes' arithmetic reads).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RodLayout {
    /// Where the terms in `drag`'s, `static_h`'s and `static_v`'s places (a frame law's
    /// `rft_inertial` in the first, its static term in the third) stand in the scene's list
    /// of contact terms (`usize::MAX` for a place it leaves empty): [`RodEval::write`] puts
    /// each term's force there.
    pub slot: [usize; 3],
    /// Whether the terms in the places of `static_h` and `static_v` are listed, so own the
    /// slip switches of x and y (only then does that component stick, [`RodModes::of`]).
    pub owns: [bool; 2],
}

impl Default for RodLayout {
    /// No term placed and no axis owned: the layout of a run off the lean path (never read).
    fn default() -> Self {
        RodLayout {
            slot: [usize::MAX; 3],
            owns: [false; 2],
        }
    }
}

impl RodLayout {
    /// The layout of `model`'s contact terms, where [`RodParams::of`] covers it.
    #[inline(never)]
    pub fn of<const N: usize>(model: &Model<N>) -> Option<Self> {
        // A free link (one contact) only: other bodies may list no contact at all.
        model.rigid_rod()?;
        let terms = model.forces.per_contact.first()?;
        if let Some((law, slot)) = FrameLaw::of(terms) {
            // The static term owns the slip switch of y, not of x.
            return Some(RodLayout {
                slot,
                owns: [false, law.statics.is_some()],
            });
        }
        let (slot, _) = thesis_slots(terms)?;
        Some(RodLayout {
            slot,
            owns: [slot[1] != usize::MAX, slot[2] != usize::MAX],
        })
    }
}

/// Where each of the thesis's terms stands in `terms` ([`RodLayout::slot`]), when `terms`
/// lists only those, each at most once and in the thesis's order.
#[inline(never)]
fn thesis_slots(terms: &[AnyTerm]) -> Option<([usize; 3], [Option<&AnyTerm>; 3])> {
    let mut slot = [usize::MAX; 3];
    let mut found = [None; 3];
    let mut next = 0;
    for (k, t) in terms.iter().enumerate() {
        let c = match t {
            AnyTerm::Drag(_) => 0,
            AnyTerm::StaticH(_) => 1,
            AnyTerm::StaticV(_) => 2,
            _ => return None,
        };
        if c < next {
            return None;
        }
        slot[c] = k;
        found[c] = Some(t);
        next = c + 1;
    }
    Some((slot, found))
}

impl RodParams<f64> {
    /// The parameters of `model`, or `None` when the lanes do not cover it (another body,
    /// another term set; see the module).
    #[inline(never)]
    pub fn of<const N: usize>(model: &Model<N>) -> Option<Self> {
        let rod = model.rigid_rod()?;
        let (unheld, smooth, eps) = match model.sign_model {
            SignModel::Modes => (0.0, 0.0, 1.0),
            SignModel::Raw => (1.0, 0.0, 1.0),
            SignModel::Smooth { eps } => (1.0, 1.0, eps),
        };
        let terms = &model.forces.per_contact[0];
        let frame = FrameLaw::of(terms);
        if model.forces.reads_frame && frame.is_none() {
            return None;
        }
        // A law of frame terms: no thesis term, its static term owning the slip switch of
        // y as the lanes place it ([`RodLayout::of`]).
        let (slot, found) = match frame {
            Some((_, slot)) => (slot, [None; 3]),
            None => thesis_slots(terms)?,
        };
        let listed = |c: usize| (slot[c] != usize::MAX).then_some(slot[c]);
        // The sticking reaction replaces its owner's component: the lanes' owners are the
        // terms in `static_h`'s place (x) and `static_v`'s (y, or a frame law's static
        // term), as the general path finds them.
        if model.forces.sole_static_owner != [listed(1), listed(2)] {
            return None;
        }
        let (mut eta_d, mut eta_h, mut eta_v, mut lam) = (0.0, 0.0, 0.0, 0.0);
        for t in found.into_iter().flatten() {
            match t {
                AnyTerm::Drag(d) => eta_d = d.eta_d,
                AnyTerm::StaticH(h) => eta_h = h.eta_h,
                AnyTerm::StaticV(v) => (eta_v, lam) = (v.eta_v, v.lam),
                _ => unreachable!("thesis_slots lists the thesis's terms only"),
            }
        }
        let link = &model.mechanism.links[0];
        let mass = link.mass + model.mechanism.root_mass;
        Some(RodParams {
            mass,
            g: model.gravity(),
            inv_m: 1.0 / (link.mass + model.mechanism.root_mass),
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
            eta_d,
            eta_h,
            eta_v,
            lam,
            unheld,
            smooth,
            eps,
            frame: frame.map(|(law, _)| law),
            frame_numbers: FrameNumbers::of(frame.as_ref().map(|(law, _)| law)),
        })
    }
}

impl RodParams<F64x4> {
    /// Every lane `p`.
    pub fn splat(p: &RodParams<f64>) -> Self {
        let s = F64x4::splat;
        RodParams {
            mass: s(p.mass),
            g: s(p.g),
            inv_m: s(p.inv_m),
            inv_i: s(p.inv_i),
            tip: [s(p.tip[0]), s(p.tip[1])],
            length: s(p.length),
            diameter: s(p.diameter),
            section: s(p.section),
            at_centroid: s(p.at_centroid),
            medium: Medium {
                rho_g: s(p.medium.rho_g),
                g: s(p.medium.g),
            },
            eta_d: s(p.eta_d),
            eta_h: s(p.eta_h),
            eta_v: s(p.eta_v),
            lam: s(p.lam),
            unheld: s(p.unheld),
            smooth: s(p.smooth),
            eps: s(p.eps),
            frame: p.frame,
            frame_numbers: FrameNumbers::splat(&p.frame_numbers),
        }
    }

    /// Lane `i` becomes `p`, whose [`FrameLaw`] must share the lanes' terms and element
    /// counts ([`same_law`]; its numbers are the lane's own).
    pub fn set(&mut self, i: usize, p: &RodParams<f64>) {
        debug_assert!(
            same_law(&self.frame, &p.frame),
            "the lanes run one frame law"
        );
        self.frame_numbers.set(i, &p.frame_numbers);
        self.mass.0[i] = p.mass;
        self.g.0[i] = p.g;
        self.inv_m.0[i] = p.inv_m;
        self.inv_i.0[i] = p.inv_i;
        self.tip[0].0[i] = p.tip[0];
        self.tip[1].0[i] = p.tip[1];
        self.length.0[i] = p.length;
        self.diameter.0[i] = p.diameter;
        self.section.0[i] = p.section;
        self.at_centroid.0[i] = p.at_centroid;
        self.medium.rho_g.0[i] = p.medium.rho_g;
        self.medium.g.0[i] = p.medium.g;
        self.eta_d.0[i] = p.eta_d;
        self.eta_h.0[i] = p.eta_h;
        self.eta_v.0[i] = p.eta_v;
        self.lam.0[i] = p.lam;
        self.unheld.0[i] = p.unheld;
        self.smooth.0[i] = p.smooth;
        self.eps.0[i] = p.eps;
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
    /// `mode` for the lanes of a run with `params` and `layout` ([`RodParams::of`],
    /// [`RodLayout::of`]), or `None` when it sticks in both x and y (two sticking rows: the
    /// scalar path takes the step). Where the signs are not held nothing sticks, nor does a
    /// component no listed term owns (`Model::eval_rigid_rod` takes no reaction there).
    #[inline]
    pub fn of(mode: &ContactMode, params: &RodParams<f64>, layout: &RodLayout) -> Option<Self> {
        let plain = params.unheld > 0.0;
        let stick = |s: Slip, owned: bool| !plain && owned && s == Slip::Stick;
        let (sx, sy) = (
            stick(mode.sx, layout.owns[0]),
            stick(mode.sy, layout.owns[1]),
        );
        if mode.in_contact && sx && sy {
            return None;
        }
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        Some(RodModes {
            in_contact: flag(mode.in_contact),
            sign: [mode.sx.sign(), mode.sy.sign()],
            cross: if mode.cross == Slip::Neg { -1.0 } else { 1.0 },
            stuck_x: flag(sx),
            stuck_y: flag(sy),
        })
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
    /// Each term's force in its place (drag or `rft_inertial`, static_h, static_v or the
    /// frame law's static term), a reaction in place of a stuck one.
    pub terms: [[F; 2]; 3],
    /// F_d.
    pub dynamic: [F; 2],
    /// F_s (or its reaction).
    pub statics: [F; 2],
    /// The terms' moment about P (a frame law's; zero under the thesis's terms).
    pub moment: F,
    /// The sticking bounds.
    pub bound: [F; 2],
    /// Where a sticking row acts: its pivot `1/m + lever_E lever_P / I`; 1 elsewhere. A
    /// lane whose pivot is not clearly nonzero takes the step on the scalar path.
    pub pivot: F,
}

/// [`super::raw_sign`] in `F`: -1, 0 or +1 (0 for a NaN, as there).
#[inline(always)]
fn plain_sign<F: Real>(v: F) -> F {
    let (zero, one) = (F::splat(0.0), F::splat(1.0));
    v.select_pos(one, (-v).select_pos(-one, zero))
}

/// [`Model::eval_rigid_rod`] of the free link under the thesis's terms or a [`FrameLaw`]
/// (`p.frame`), in `F`: [`rod_eval_law`] for the law at hand.
#[inline(always)]
pub fn rod_eval<F: Real>(p: &RodParams<F>, m: &RodModes<F>, q: &[F; 3], qd: &[F; 3]) -> RodEval<F> {
    if p.frame.is_some() {
        rod_eval_law::<F, true>(p, m, q, qd)
    } else {
        rod_eval_law::<F, false>(p, m, q, qd)
    }
}

/// [`Model::eval_rigid_rod`] of the free link under the thesis's terms (`FRAME` false) or
/// a [`FrameLaw`] (`FRAME` true, `p.frame` set), in `F`: the same operations in the same
/// order, with blends for branches (see the module). One compiled step per kind of law, so
/// that the thesis's carries no code of the others (measured: 4 % slower lanes with `rft`
/// in the same step).
#[inline(always)]
pub fn rod_eval_law<F: Real, const FRAME: bool>(
    p: &RodParams<F>,
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
    // (`rft`: `Model::eval_rigid_rod`).
    let forced = if FRAME { inside } else { depth_out };
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
    let area_speed = p.diameter * immersed * held;
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
    // Out of the sand in every lane, each use of the law below is blended away: skip it
    // (its `pow`). The results are the same bit for bit.
    let none = TermForce {
        force: [zero, zero],
        bound: [zero, zero],
        moment: zero,
    };
    let (fd, fh, fv, moment) = if forced.all_zero() {
        (none, none, none, zero)
    } else if let (true, Some(law)) = (FRAME, &p.frame) {
        // The frame law's terms on the boundary `Model::eval_rigid_rod` gives them: T's and
        // E's velocities held on the side of the held sign of v_Ey where the static term
        // owns its slip switch (`held_shift`: +0 otherwise, and always in x), P and E in
        // the world, y held while it sticks.
        let shift = if law.statics.is_some() {
            (-(sign[1] * v_centroid[1])).select_pos(F::splat(-2.0) * v_centroid[1], zero)
        } else {
            zero
        };
        let b = Boundary {
            frame: Frame {
                origin: tip,
                v: [v_tip[0] + zero, v_tip[1] + shift],
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
            v_centroid: [v_centroid[0] + zero, v_centroid[1] + shift],
            // Held only in contact: a lane out of the sand blends the law away, and its
            // held flag would make every lane pay `Rft::held`'s integrations.
            held: [sel(inside, m.stuck_x, zero), sel(inside, m.stuck_y, zero)],
        };
        let state = ContactState {
            area_speed: zero,
            boundary: Some(&b),
            ..state
        };
        // In the lanes the terms are inlined into their step (AVX2 where the CPU has it); a
        // lone run calls the general path's own copies (inlined into its AVX2 step, `rft`'s
        // group of eight elements was slower: measured).
        // The lanes read each lane's numbers; a lone run's are its law's own.
        let (lanes, n) = (F::LANES > 1, &p.frame_numbers);
        let fs = match law.statics {
            Some(FrameStatic::Rft(r)) if lanes => r.force_with(&n.rft, &state),
            Some(FrameStatic::Rft(r)) => r.contact_force(&state, &p.medium),
            Some(FrameStatic::Poncelet(_)) if lanes => {
                Poncelet::force_with(n.poncelet, &state, &p.medium)
            }
            Some(FrameStatic::Poncelet(t)) => t.contact_force(&state, &p.medium),
            None => none,
        };
        let fi = match law.inertial {
            Some(t) if lanes => t.force_with(n.lam, &state, &p.medium),
            Some(t) => t.contact_force(&state, &p.medium),
            None => none,
        };
        // `terms_on` sums the moments in the list's order from +0: the same bits either
        // way (IEEE addition commutes; only a -0 first becomes +0, in both).
        let moment = (zero + fs.moment) + fi.moment;
        (fi, none, fs, moment)
    } else {
        let fv = StaticV::law(p.eta_v, p.lam, &state, &p.medium);
        (
            Drag::law(p.eta_d, &state, &p.medium),
            StaticH::law(p.eta_h, &state, &p.medium),
            fv,
            zero + fv.moment,
        )
    };
    let dynamic = [zero + fd.force[0], zero + fd.force[1]];
    let statics = [
        (zero + fh.force[0]) + fv.force[0],
        (zero + fh.force[1]) + fv.force[1],
    ];
    let bound = [
        ((zero + fd.bound[0]) + fh.bound[0]) + fv.bound[0],
        ((zero + fd.bound[1]) + fh.bound[1]) + fv.bound[1],
    ];
    let total = [dynamic[0] + statics[0], dynamic[1] + statics[1]];
    let lever_p = lever(p_local);
    let torque = total[0] * lever_p[0] + total[1] * lever_p[1];
    let gen = [
        sel(forced, zero + total[0], zero),
        sel(forced, gen1 + total[1], gen1),
        sel(forced, zero + (torque - moment), zero),
    ];
    let qdd = [gen[0] * p.inv_m, gen[1] * p.inv_m, gen[2] * p.inv_i];
    // The sticking row (rigid_rod_reactions with one row): x or y.
    let row_x = sel(forced, m.stuck_x, zero);
    let row_y = sel(forced, m.stuck_y, zero);
    let row = row_x + row_y;
    // No lane sticks: each use of the row below is blended away; skip it (its divisions).
    let (qdd, mult, a) = if row.all_zero() {
        (qdd, zero, F::splat(1.0))
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
        let qdd = [
            sel(row_x, qdd[0] + mult * p.inv_m, qdd[0]),
            sel(row_y, qdd[1] + mult * p.inv_m, qdd[1]),
            sel(row, qdd[2] + mult * (lp * p.inv_i), qdd[2]),
        ];
        (qdd, mult, a)
    };
    let terms = [
        sel2(forced, fd.force, [zero, zero]),
        sel2(
            forced,
            [sel(row_x, mult, fh.force[0]), fh.force[1]],
            [zero, zero],
        ),
        sel2(
            forced,
            [fv.force[0], sel(row_y, mult, fv.force[1])],
            [zero, zero],
        ),
    ];
    let statics = sel2(
        forced,
        [sel(row_x, mult, statics[0]), sel(row_y, mult, statics[1])],
        [zero, zero],
    );
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
        terms,
        dynamic,
        statics,
        moment: sel(forced, moment, zero),
        bound: sel2(forced, bound, [zero, zero]),
        pivot: sel(row, a, F::splat(1.0)),
    }
}

/// Whether a sticking row's pivot `a` ([`RodEval::pivot`]) is clearly nonzero, as the
/// scalar path judges it (`rigid_rod_reactions`); else the scalar path takes the step.
#[inline]
pub fn pivot_ok(a: f64) -> bool {
    a.abs() > 1e-13 * a.abs().max(f64::MIN_POSITIVE)
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

    /// Write this evaluation of a run with `layout` into `out` as [`Model::eval_into`]
    /// does (each listed term's force in its place, [`RodLayout::slot`]).
    #[inline]
    pub fn write<const N: usize>(&self, layout: &RodLayout, out: &mut Eval<N>) {
        let v2 = |a: [f64; 2]| Vector2::new(a[0], a[1]);
        let mut terms = [Vector2::zeros(); crate::forces::registry::MAX_TERMS];
        if layout.slot == [0, 1, 2] {
            // The whole thesis set, the common case: fixed places (measured: placing them by
            // `slot` made a thesis impact 4-8 % slower).
            for (k, t) in self.terms.iter().enumerate() {
                terms[k] = v2(*t);
            }
        } else {
            for (&k, t) in layout.slot.iter().zip(&self.terms) {
                if k != usize::MAX {
                    terms[k] = v2(*t);
                }
            }
        }
        out.contacts[0] = ContactEval {
            tip: v2(self.tip),
            v_tip: v2(self.v_tip),
            depth: self.depth,
            lowest: self.lowest,
            v_centroid: v2(self.v_centroid),
            force: ContactForce {
                terms,
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
        let l = |x: F64x4| x.0[i];
        let l2 = |x: [F64x4; 2]| [x[0].0[i], x[1].0[i]];
        RodEval {
            qdd: [l(self.qdd[0]), l(self.qdd[1]), l(self.qdd[2])],
            power: l(self.power),
            tip: l2(self.tip),
            v_tip: l2(self.v_tip),
            depth: l(self.depth),
            lowest: l(self.lowest),
            v_centroid: l2(self.v_centroid),
            cross: l(self.cross),
            margin: l(self.margin),
            terms: [l2(self.terms[0]), l2(self.terms[1]), l2(self.terms[2])],
            dynamic: l2(self.dynamic),
            statics: l2(self.statics),
            moment: l(self.moment),
            bound: l2(self.bound),
            pivot: l(self.pivot),
        }
    }
}

/// Run scene `s` as [`crate::integrate::solve`] runs it (the lean path where it covers the
/// scene) and on the general path alone, assert the outcomes are the same bit for bit
/// (every field; `what` names the case) and return it. For tests here and in `batch.rs`.
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
        /// Four scenes in four lanes give, each, the scalar path's evaluation bit for bit:
        /// the accelerations, the power and every finding of the contact (what the events
        /// and the observer read), in every mode the lanes cover, under every sign model and
        /// with any of the thesis's terms, mixed across the lanes, or under one frame law's
        /// terms and element count with each lane's own numbers.
        #[test]
        fn lanes_are_the_scalar_evaluation_bitwise(
            scenes in proptest::array::uniform4(scene()),
            states in proptest::array::uniform4(state()),
            terms in proptest::array::uniform4(0u8..8),
            frame in prop_oneof![
                Just(None),
                (0u8..6, 1e4f64..3e6, 1usize..14).prop_map(Some),
            ],
        ) {
            let models: Vec<Model<3>> = scenes
                .iter()
                .zip(terms)
                .map(|(s, t)| match frame {
                    // One law's terms and element count, each lane's own numbers.
                    Some((kind, a, n)) => {
                        let a = a * (1.0 + s.2 / 40.0);
                        model_frame((s.0, s.1, s.6, s.7, s.8), &frame_law(kind, a, n))
                    }
                    None => model_signed(s.0, s.1, [s.2, s.3, s.4, s.5], s.6, s.7, s.8, t),
                })
                .collect();
            let params_of = |i: usize| RodParams::of(&models[i]).unwrap();
            let layout_of = |i: usize| RodLayout::of(&models[i]).unwrap();
            let mut params = RodParams::splat(&params_of(0));
            let default = ContactMode::default();
            let mut modes = [RodModes::of(&default, &params_of(0), &layout_of(0)).unwrap(); LANES];
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
                match RodModes::of(&all_modes[i][0], &params_of(i), &layout_of(i)) {
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
                lane.write(&layout_of(i), &mut mine);
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
    /// y stuck): the general path's rate of the immersed length is zero out of the sand,
    /// and the lean path's must be too (the proptest found it; pinned here). Alone and in
    /// every lane of the lanes.
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
            let (p, l) = (
                RodParams::of(&model).unwrap(),
                RodLayout::of(&model).unwrap(),
            );
            let m = RodModes::of(&mode, &p, &l).unwrap();
            assert_eq!(m.stuck_y, 1.0);
            let th: f64 = 0.34151223113018786;
            let q = [0.025 * th.sin(), 0.025 * th.cos(), th];
            let qd = [0.0, 0.0, 11.628250912542002];
            let general = model.eval(&SVector::from(q), &SVector::from(qd), &modes);
            let mut lean = general;
            let one = rod_eval(&p, &m, &q, &qd);
            assert!(one.pivot_ok());
            one.write(&l, &mut lean);
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
                lanes.lane(i).write(&l, &mut lane);
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

    /// A body the lean path does not cover has no layout, even one with no contact at all
    /// (a linkage with none: `Run::new` asks every model).
    #[test]
    fn only_a_free_link_has_a_layout() {
        let mut pendulum = model(0.184, 0.19, [15.2, 6.5, 248.0, 0.106], false, true);
        pendulum.forces.per_contact.clear();
        pendulum.contacts.clear();
        assert!(RodLayout::of(&pendulum).is_none());
        assert!(RodParams::of(&pendulum).is_none());
    }

    /// Runs share the lanes when their frame laws list the same terms with the same element
    /// counts, whatever their numbers (each lane has its own).
    #[test]
    fn frame_laws_share_the_lanes_by_their_terms_and_element_counts() {
        let law = |kind: u8, a: f64, n: usize| {
            let m = model_frame(
                (0.184, 0.19, false, true, SignModel::Modes),
                &frame_law(kind, a, n),
            );
            RodParams::of(&m).unwrap().frame
        };
        assert!(same_law(&law(0, 1e6, 8), &law(0, 3e5, 8)));
        assert!(same_law(&law(1, 1e6, 8), &law(1, 2e5, 3)));
        assert!(same_law(&law(3, 1e6, 8), &law(4, 5e5, 8)));
        assert!(!same_law(&law(0, 1e6, 8), &law(0, 1e6, 7)));
        assert!(!same_law(&law(0, 1e6, 8), &law(1, 1e6, 8)));
        assert!(!same_law(&law(0, 1e6, 8), &law(3, 1e6, 8)));
        assert!(!same_law(&law(2, 1e6, 8), &law(2, 1e6, 5)));
        assert!(!same_law(&law(0, 1e6, 8), &None));
        assert!(same_law(&None, &None));
    }

    /// The lanes cover the thesis's set under every sign model and the frame laws, and
    /// nothing else.
    #[test]
    fn lanes_cover_the_thesis_set_and_the_frame_laws() {
        let thesis = model(0.184, 0.19, [15.2, 6.5, 248.0, 0.106], false, true);
        let flags = |m: &Model<3>| RodParams::of(m).map(|p| (p.unheld, p.smooth, p.eps));
        assert_eq!(flags(&thesis), Some((0.0, 0.0, 1.0)));
        let mut raw = thesis.clone();
        raw.sign_model = SignModel::Raw;
        assert_eq!(flags(&raw), Some((1.0, 0.0, 1.0)));
        let mut smooth = thesis.clone();
        smooth.sign_model = SignModel::Smooth { eps: 1e-3 };
        assert_eq!(flags(&smooth), Some((1.0, 1.0, 1e-3)));
        // Any of the thesis's terms, in its order (gravity on or off).
        let subset = model_signed(
            0.184,
            0.19,
            [15.2, 6.5, 248.0, 0.106],
            false,
            false,
            SignModel::Modes,
            0b101,
        );
        let (p, l) = (
            RodParams::of(&subset).unwrap(),
            RodLayout::of(&subset).unwrap(),
        );
        assert_eq!(
            (l.slot, l.owns, p.eta_h),
            ([0, usize::MAX, 1], [false, true], 0.0)
        );
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
        assert!(RodParams::of(&reordered).is_none());
        let both = ContactMode {
            in_contact: true,
            ..ContactMode::default()
        };
        let layout = RodLayout::of(&thesis).unwrap();
        assert!(RodModes::of(&both, &RodParams::of(&thesis).unwrap(), &layout).is_none());
        // Under the plain sign nothing sticks: the same mode is covered, with no row.
        let plain = RodModes::of(&both, &RodParams::of(&raw).unwrap(), &layout).unwrap();
        assert_eq!((plain.stuck_x, plain.stuck_y), (0.0, 0.0));
        // `rft` alone: in static_v's place, owning y; x never sticks, so the mode that
        // sticks in both is covered with y's row alone.
        let base = (0.184, 0.19, false, true, SignModel::Modes);
        let rft = model_frame(base, &frame_law(0, 1e6, 8));
        let (p, l) = (RodParams::of(&rft).unwrap(), RodLayout::of(&rft).unwrap());
        assert_eq!(
            (l.slot, l.owns),
            ([usize::MAX, usize::MAX, 0], [false, true])
        );
        assert_eq!((p.eta_d, p.eta_h, p.eta_v), (0.0, 0.0, 0.0));
        let law = p.frame.unwrap();
        assert!(matches!(law.statics, Some(FrameStatic::Rft(r)) if r.zeta == 1e6));
        assert!(law.inertial.is_none());
        let m = RodModes::of(&both, &p, &l).unwrap();
        assert_eq!((m.stuck_x, m.stuck_y), (0.0, 1.0));
        // `rft_inertial` in drag's place, before or after the static term; alone it owns
        // nothing, so nothing sticks.
        let slots = |kind: u8| {
            let m = model_frame(base, &frame_law(kind, 1e6, 8));
            let (p, l) = (RodParams::of(&m).unwrap(), RodLayout::of(&m).unwrap());
            (l.slot, l.owns, p.frame.unwrap().inertial.is_some())
        };
        let none = usize::MAX;
        assert_eq!(slots(1), ([none, none, 0], [false, true], false));
        assert_eq!(slots(2), ([0, none, none], [false, false], true));
        assert_eq!(slots(3), ([1, none, 0], [false, true], true));
        assert_eq!(slots(4), ([0, none, 1], [false, true], true));
        assert_eq!(slots(5), ([1, none, 0], [false, true], true));
        let alone = model_frame(base, &frame_law(2, 1e6, 8));
        let m = RodModes::of(
            &both,
            &RodParams::of(&alone).unwrap(),
            &RodLayout::of(&alone).unwrap(),
        );
        assert_eq!(m.map(|m| (m.stuck_x, m.stuck_y)), Some((0.0, 0.0)));
        // Not two static frame terms (both own y), nor a frame term with a thesis term (a
        // term listed twice is refused before: `ForceSet::build`).
        let other = |specs: &[TermSpec]| {
            let mut m = thesis.clone();
            m.forces = ForceSet::build(specs, 1).unwrap();
            RodParams::of(&m).is_none() && RodLayout::of(&m).is_none()
        };
        let rft_spec = TermSpec::new("rft", &[("zeta", 1e6)]);
        let poncelet = TermSpec::new("poncelet", &[("c", 0.8), ("k", 150.0)]);
        let static_v = TermSpec::new("static_v", &[("eta_v", 248.0), ("lam", 0.106)]);
        assert!(other(&[rft_spec.clone(), static_v]));
        assert!(other(&[rft_spec.clone(), poncelet]));
        assert!(other(&[
            rft_spec,
            TermSpec::new("drag", &[("eta_d", 15.2)])
        ]));
    }
}
