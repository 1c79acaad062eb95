//! Events (diffrax's `Event`): the switching functions of the force law's discontinuities
//! (surface entry and exit, full immersion, the held signs, the end of a stick) and the
//! stops; their detection at a step's end, their location on the step's cubic Hermite
//! interpolant (Illinois), the polishing of the kinks no mode holds on the step map itself,
//! and the mode changes an event makes (`choose_slip`, `enter_contact`).

use super::observe::Observer;
use super::options::EndCondition;
use super::outcome::Stats;
use super::stepper::{deriv_of, step, Deriv, Hermite, State};
use crate::body::{SoleContact, SoleModel};
use crate::dynamics::{
    ContactEval, ContactMode, Eval, Model, Modes, Shape, SignModel, Slip, MAX_CONTACTS,
};
use crate::forces::Switch;

/// Relative tolerance of event location, in units of the step.
const ROOT_TOL: f64 = 1e-13;
/// Events closer than this (in units of the step) to the earliest are handled with it.
const SIMULTANEOUS: f64 = 1e-9;
/// A velocity component above this [m/s] at a mode decision is moving, not at rest.
const SLIP_SPEED: f64 = 1e-9;
/// At most this many events within one grid step before the step is taken as it is.
pub const MAX_EVENTS_PER_STEP: usize = 32;

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
    /// A box's corner (0..4) crossing the surface.
    Corner(u8),
}

/// What the switching functions read of a contact's evaluation: a [`ContactEval`], or a
/// lane of the sweep's lanes ([`super::lanes::LaneContact`]), so that both are judged by
/// one definition ([`switching_of`]).
pub(super) trait SwitchInputs {
    /// The contact's lowest point's height [m].
    fn lowest(&self) -> f64;
    /// v_E.
    fn v_centroid(&self) -> [f64; 2];
    /// The static terms' bounds.
    fn bound(&self) -> [f64; 2];
    /// The static force.
    fn statics(&self) -> [f64; 2];
    /// The tip's vertical velocity.
    fn v_tip_y(&self) -> f64;
    /// e x v_E.
    fn cross(&self) -> f64;
    /// The full-immersion margin.
    fn immersion_margin(&self) -> f64;
    /// Corner `k`'s height (a box).
    fn corner_y(&self, k: usize) -> f64;
}

impl SwitchInputs for ContactEval {
    #[inline(always)]
    fn lowest(&self) -> f64 {
        self.lowest
    }
    #[inline(always)]
    fn v_centroid(&self) -> [f64; 2] {
        [self.v_centroid.x, self.v_centroid.y]
    }
    #[inline(always)]
    fn bound(&self) -> [f64; 2] {
        self.bound
    }
    #[inline(always)]
    fn statics(&self) -> [f64; 2] {
        [self.force.statics.x, self.force.statics.y]
    }
    #[inline(always)]
    fn v_tip_y(&self) -> f64 {
        self.v_tip.y
    }
    #[inline(always)]
    fn cross(&self) -> f64 {
        self.cross
    }
    #[inline(always)]
    fn immersion_margin(&self) -> f64 {
        self.immersion_margin
    }
    #[inline(always)]
    fn corner_y(&self, k: usize) -> f64 {
        self.corners_y[k]
    }
}

/// The value of a switching function: non-negative while the mode holds; the event is
/// where it turns negative (the stop: where -v_Ty reaches zero).
#[inline(always)]
fn switching<const N: usize>(kind: Kind, ci: usize, e: &Eval<N>, modes: &Modes) -> f64 {
    switching_of(kind, &e.contacts[ci], &modes[ci])
}

/// [`switching`] of a contact `c` in mode `m`.
#[inline(always)]
fn switching_of(kind: Kind, c: &impl SwitchInputs, m: &ContactMode) -> f64 {
    match kind {
        Kind::Entry => c.lowest(),
        Kind::Exit => -c.lowest(),
        Kind::SlipX => m.sx.sign() * c.v_centroid()[0],
        Kind::SlipY => m.sy.sign() * c.v_centroid()[1],
        Kind::StickX => c.bound()[0] - c.statics()[0].abs(),
        Kind::StickY => c.bound()[1] - c.statics()[1].abs(),
        Kind::Stop => -c.v_tip_y(),
        Kind::Cross => m.cross.sign() * c.cross(),
        Kind::Immersion => {
            if m.full {
                -c.immersion_margin()
            } else {
                c.immersion_margin()
            }
        }
        Kind::Corner(k) => {
            if m.corners & (1 << k) != 0 {
                -c.corner_y(k as usize)
            } else {
                c.corner_y(k as usize)
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
        if is_box(model, ci) {
            for k in 0..4 {
                out.push((Kind::Corner(k), ci));
            }
        }
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

/// Whether contact `ci` is a box (a sole): its corners are events.
#[inline]
fn is_box<const N: usize>(model: &Model<N>, ci: usize) -> bool {
    matches!(
        model.contacts[ci].shape,
        Shape::Sole(SoleContact {
            model: SoleModel::Box,
            ..
        })
    )
}

/// The corners of box contact `ci` in the sand at `e` (bit k: corner k at or below the
/// surface).
#[inline]
fn corners_in<const N: usize>(e: &Eval<N>, ci: usize) -> u8 {
    let y = e.contacts[ci].corners_y;
    (0..4).fold(0, |bits, k| if y[k] <= 0.0 { bits | 1 << k } else { bits })
}

/// Whether the function has crossed (the event happened by the end of the step).
#[inline(always)]
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
///
/// Returns whether the step, not the contact, made the decision: the component was slipping
/// and the located switch left it moving the other way by more than [`SLIP_SPEED`] (the
/// event's location on the step's interpolant overshot the zero), so it slips on that way,
/// although the static bound would hold it there, and it speeds up that way
/// ([`runs_away`]; a slip that comes back to zero is judged again there). The run's result
/// then moves with the step (an `rft` rod that sticks at dt = 1e-5 slides on at 1e-4: t_s
/// 0.014 s against 0.017 s); the observer counts it ([`Observer::overshot_stick`]). The
/// decision itself is not changed: the run is what it was.
fn choose_slip<const N: usize>(
    model: &Model<N>,
    modes: &mut Modes,
    ci: usize,
    axis: usize,
    at: &State<N>,
    lookahead: &State<N>,
    stats: &mut Stats,
) -> bool {
    let was = *modes[ci].slip_mut(axis);
    let mut trial = *modes;
    *trial[ci].slip_mut(axis) = Slip::Stick;
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
    let mut overshot = false;
    let slip = if model.mechanism.prescribed() {
        // A body whose every coordinate is prescribed does not stick: its E passes through
        // zero velocity the way the motion takes it (read at the step's end).
        let (_, _, ahead) = judge(lookahead, stats);
        if ahead < 0.0 || (ahead == 0.0 && v < 0.0) {
            Slip::Neg
        } else {
            Slip::Pos
        }
    } else {
        if v.abs() <= SLIP_SPEED && bound == 0.0 {
            (reaction, bound, _) = judge(lookahead, stats);
        }
        if v.abs() > SLIP_SPEED {
            let slip = if v < 0.0 { Slip::Neg } else { Slip::Pos };
            if was != Slip::Stick && slip != was && reaction.abs() <= bound {
                overshot = runs_away(model, modes, ci, axis, slip, at, stats);
            }
            slip
        } else if reaction.abs() <= bound {
            Slip::Stick
        } else if reaction > 0.0 {
            Slip::Neg
        } else {
            Slip::Pos
        }
    };
    *modes[ci].slip_mut(axis) = slip;
    overshot
}

/// Whether contact `ci`'s E, moving at `at` along `axis` the way `slip` says, speeds up
/// that way when it slips so (the derivative of its velocity component along the motion,
/// by a forward difference of 1e-9 s): a slip that runs away from zero, rather than one that
/// comes back to it within moments and is judged again there.
fn runs_away<const N: usize>(
    model: &Model<N>,
    modes: &Modes,
    ci: usize,
    axis: usize,
    slip: Slip,
    at: &State<N>,
    stats: &mut Stats,
) -> bool {
    const EPS: f64 = 1e-9;
    let mut trial = *modes;
    *trial[ci].slip_mut(axis) = slip;
    let e0 = model.eval(&at.q, &at.qd, &trial);
    let ahead = at.add(EPS, &deriv_of(at, &e0));
    let e1 = model.eval(&ahead.q, &ahead.qd, &trial);
    stats.rhs_evals += 2;
    let (v0, v1) = (
        e0.contacts[ci].v_centroid[axis],
        e1.contacts[ci].v_centroid[axis],
    );
    slip.sign() * (v1 - v0) > 0.0
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
    if is_box(model, ci) {
        let e = model.eval(&y.q, &y.qd, modes);
        stats.rhs_evals += 1;
        modes[ci].corners = corners_in(&e, ci);
    }
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
            Some(s) => *modes[ci].slip_mut(axis) = s,
            None => {
                choose_slip(model, modes, ci, axis, y, probe, stats);
            }
        }
    }
}

/// The modes at the start of a run from `y`: a contact whose tip is below the surface, or
/// at it and moving down, is in contact. A zero velocity component is judged a little
/// later, at the end of a probe step of size `dt` free of the static terms' signs (they are
/// zero at the surface).
pub(super) fn initial_modes<const N: usize>(
    model: &Model<N>,
    y: &State<N>,
    dt: f64,
    stats: &mut Stats,
) -> Modes {
    let mut modes: Modes = [ContactMode::default(); MAX_CONTACTS];
    let e_free = model.eval(&y.q, &y.qd, &modes);
    stats.rhs_evals += 1;
    for ci in 0..model.contacts.len() {
        let c = &e_free.contacts[ci];
        if c.lowest < 0.0 || (c.lowest == 0.0 && c.v_tip.y < 0.0) {
            let k1 = deriv_of(y, &e_free);
            let probe = y.add(dt, &k1);
            enter_contact(model, &mut modes, ci, y, &probe, stats);
        }
    }
    modes
}

/// One switching function's crossing within a step.
#[derive(Debug, Clone, Copy)]
struct Hit {
    /// Which function.
    kind: Kind,
    /// Of which contact.
    contact: usize,
    /// Where in the step, as a fraction of it.
    theta: f64,
    /// The function at the step's start (at least 0) and at its end.
    g0: f64,
    /// See `g0`.
    g1: f64,
}

/// A step as the events see it: its start (state, first stage, evaluation), its end (state,
/// evaluation) and its size [s].
pub(super) struct Span<'a, const N: usize> {
    /// The state at the start.
    pub y0: &'a State<N>,
    /// Its derivative (the step's first stage).
    pub k1: &'a Deriv<N>,
    /// Its evaluation.
    pub e0: &'a Eval<N>,
    /// The state at the end.
    pub y1: &'a State<N>,
    /// Its evaluation.
    pub e1: &'a Eval<N>,
    /// The step's size [s].
    pub h: f64,
}

/// Where the run lands on the earliest event: time, state and its evaluation, the state at
/// which an event at the very start of the step is judged (`probe`), and the step's end
/// (`lookahead`, where a slip mode is decided when the surface gives no reaction yet).
pub(super) struct Landing<'a, const N: usize> {
    /// Time [s].
    pub t: f64,
    /// The state.
    pub y: &'a State<N>,
    /// Its evaluation in the modes before the event.
    pub e: &'a Eval<N>,
    /// See the struct.
    pub probe: &'a State<N>,
    /// See the struct.
    pub lookahead: &'a State<N>,
    /// The lookahead's time [s]: the end of the step that found the event.
    pub t_lookahead: f64,
}

/// The events' state through a run.
pub(super) struct Events {
    /// The switching functions active under the modes they were listed for.
    funcs: Vec<(Kind, usize)>,
    /// Whether `funcs` is up to date: the list changes only with the modes, and only
    /// [`Events::handle`] changes them (it clears this). A flag, not a comparison of the
    /// modes at every step (measured: about 60 instructions per step).
    listed: bool,
    /// The modes `funcs` was listed for (checked in debug builds).
    listed_for: Option<Modes>,
    /// Events handled within the current grid step.
    in_step: usize,
    /// The crossings found in the current step.
    hits: Vec<Hit>,
}

impl Events {
    /// No events yet.
    pub(super) fn new() -> Self {
        Events {
            funcs: Vec::with_capacity(4 * MAX_CONTACTS),
            listed: false,
            listed_for: None,
            in_step: 0,
            hits: Vec::new(),
        }
    }

    /// Whether a step that ends at `end` (the evaluation of a body's only contact) crosses
    /// none of the switching functions active under `modes`: [`Events::detect`]'s finding
    /// where it locates nothing. False, to be left to [`Events::detect`], also where that
    /// would do more: the functions not yet listed for `modes`, or the step past
    /// [`MAX_EVENTS_PER_STEP`] events.
    #[inline]
    pub(super) fn plain(&self, modes: &Modes, end: &impl SwitchInputs) -> bool {
        debug_assert!(!self.listed || self.listed_for == Some(*modes));
        self.listed
            && self.in_step < MAX_EVENTS_PER_STEP
            && self
                .funcs
                .iter()
                .all(|&(kind, ci)| ci == 0 && !crossed(kind, switching_of(kind, end, &modes[0])))
    }

    /// The run moves on to the next grid step.
    #[inline]
    pub(super) fn next_step(&mut self) {
        self.in_step = 0;
    }

    /// Find the switching functions that crossed within `span` (in `modes`), each located
    /// on the step's Hermite interpolant; returns the earliest crossing as a fraction of
    /// the step (infinite without one). After [`MAX_EVENTS_PER_STEP`] events within one grid
    /// step none are looked for, and the step counts as unresolved.
    pub(super) fn detect<const N: usize>(
        &mut self,
        model: &Model<N>,
        modes: &Modes,
        span: &Span<N>,
        stats: &mut Stats,
    ) -> f64 {
        if !self.listed {
            active(model, modes, &mut self.funcs);
            self.listed = true;
            self.listed_for = Some(*modes);
        }
        debug_assert_eq!(
            self.listed_for,
            Some(*modes),
            "modes changed outside handle()"
        );
        self.hits.clear();
        let mut earliest = f64::INFINITY;
        if self.in_step >= MAX_EVENTS_PER_STEP {
            stats.unresolved += 1;
            return earliest;
        }
        for &(kind, ci) in &self.funcs {
            let g1 = switching(kind, ci, span.e1, modes);
            if !crossed(kind, g1) {
                continue;
            }
            let g0 = switching(kind, ci, span.e0, modes).max(0.0);
            let theta = if g1 == 0.0 {
                1.0
            } else if g0 == 0.0 {
                0.0
            } else {
                let dense = Hermite {
                    y0: *span.y0,
                    f0: *span.k1,
                    y1: *span.y1,
                    f1: deriv_of(span.y1, span.e1),
                    h: span.h,
                };
                let (theta, evals) = locate(
                    |th| {
                        let s = dense.at(th);
                        let e = model.eval(&s.q, &s.qd, modes);
                        switching(kind, ci, &e, modes)
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
            self.hits.push(Hit {
                kind,
                contact: ci,
                theta,
                g0,
                g1,
            });
        }
        earliest
    }

    /// A drive's impulse changed the rates at `y`: decide again every component held by a
    /// stick (the sand takes no impulse, so it may move now; it slips the way it moves, or
    /// sticks again if it does not), and list the switching functions anew.
    pub(super) fn after_impulse<const N: usize>(
        &mut self,
        model: &Model<N>,
        modes: &mut Modes,
        y: &State<N>,
        stats: &mut Stats,
    ) {
        self.listed = false;
        if model.sign_model != SignModel::Modes {
            return;
        }
        for ci in 0..model.contacts.len() {
            if !modes[ci].in_contact {
                continue;
            }
            if model.forces.owns(Switch::SlipX) && modes[ci].sx == Slip::Stick {
                choose_slip(model, modes, ci, 0, y, y, stats);
            }
            if model.forces.owns(Switch::SlipY) && modes[ci].sy == Slip::Stick {
                choose_slip(model, modes, ci, 1, y, y, stats);
            }
        }
    }

    /// Whether the last [`Events::detect`] found no crossing.
    #[inline]
    pub(super) fn none(&self) -> bool {
        self.hits.is_empty()
    }

    /// Polish the crossings of an RK4 step whose earliest is inside it; returns the new
    /// earliest.
    ///
    /// The interpolant's root is the step map's only to the interpolant's error: O(h^4)
    /// where the held modes keep the right-hand side smooth through the step, but first
    /// order where the step straddles a kink no mode holds: a box's corner crossing the
    /// surface, the cap of the immersed
    /// length (l <= L, a sole box under the surface) and the exit, where the static
    /// term's d^lambda has an unbounded derivative. Polish those events on the map
    /// itself, h' -> g(step(y, h')), which is what the run will follow; its bracket [0, 1]
    /// is the step's own ends. Every such hit is polished, so that mirror-image events
    /// stay simultaneous.
    pub(super) fn polish<const N: usize>(
        &mut self,
        model: &Model<N>,
        modes: &Modes,
        span: &Span<N>,
        earliest: f64,
        stats: &mut Stats,
    ) -> f64 {
        if !(earliest > 0.0 && earliest < 1.0) {
            return earliest;
        }
        for hit in self.hits.iter_mut() {
            let Hit {
                kind,
                contact: ci,
                theta: guess,
                g0,
                g1,
            } = *hit;
            if !matches!(kind, Kind::Immersion | Kind::Exit | Kind::Corner(_))
                || guess <= 0.0
                || guess >= 1.0
            {
                continue;
            }
            let mut map = |th: f64| {
                let s = step(model, modes, span.y0, span.k1, th * span.h);
                let e = model.eval(&s.q, &s.qd, modes);
                switching(kind, ci, &e, modes)
            };
            let at = map(guess);
            let (theta, evals) = if at < 0.0 {
                locate_in(&mut map, (0.0, g0), (guess, at), ROOT_TOL)
            } else {
                locate_in(&mut map, (guess, at), (1.0, g1), ROOT_TOL)
            };
            stats.root_evals += evals + 1;
            stats.rhs_evals += 4 * (evals + 1);
            hit.theta = theta;
        }
        self.hits
            .iter()
            .fold(f64::INFINITY, |m, hit| m.min(hit.theta))
    }

    /// Handle the crossings simultaneous with the `earliest` where the run has landed
    /// (`at`): change the modes, and tell `obs` of entries and stops. Returns whether the
    /// run ends here (the stop that the end condition `end` waits for).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn handle<const N: usize>(
        &mut self,
        model: &Model<N>,
        modes: &mut Modes,
        earliest: f64,
        at: &Landing<N>,
        end: EndCondition,
        obs: &mut Observer<N>,
        stats: &mut Stats,
    ) -> bool {
        let nc = model.contacts.len();
        let mut terminal = false;
        self.listed = false;
        for hit in &self.hits {
            if hit.theta > earliest + SIMULTANEOUS {
                continue;
            }
            let ci = hit.contact;
            stats.events += 1;
            match hit.kind {
                Kind::Entry => {
                    obs.entered(ci, at.t);
                    enter_contact(model, modes, ci, at.y, at.probe, stats);
                }
                Kind::Exit => {
                    modes[ci].in_contact = false;
                    modes[ci].sx = Slip::Stick;
                    modes[ci].sy = Slip::Stick;
                }
                Kind::Immersion => modes[ci].full = !modes[ci].full,
                Kind::Corner(k) => modes[ci].corners ^= 1 << k,
                Kind::Cross => {
                    modes[ci].cross = if modes[ci].cross == Slip::Pos {
                        Slip::Neg
                    } else {
                        Slip::Pos
                    }
                }
                Kind::SlipX | Kind::StickX | Kind::SlipY | Kind::StickY => {
                    let axis = usize::from(matches!(hit.kind, Kind::SlipY | Kind::StickY));
                    // A stopped contact's results are settled.
                    if choose_slip(model, modes, ci, axis, at.y, at.lookahead, stats)
                        && !modes[ci].stopped
                    {
                        obs.overshot_stick(ci, axis, at.t);
                    }
                }
                Kind::Stop => {
                    modes[ci].stopped = true;
                    obs.stopped(model, ci, at.t, at.y, at.e, at.t_lookahead - at.t);
                    terminal |= match end {
                        EndCondition::FirstStop => true,
                        EndCondition::AllStops => modes[..nc].iter().all(|m| m.stopped),
                        EndCondition::Time => false,
                    };
                }
            }
        }
        self.in_step += 1;
        terminal
    }
}

/// Find a root of `g` in [0, 1] given `g(0) = g0 >= 0` and `g(1) = g1 < 0` (a sign change),
/// by the Illinois variant of regula falsi. Returns `(theta, evaluations)`; `theta` is the
/// right end of the final bracket, so that `g(theta) <= 0` (the event has happened there).
pub fn locate(g: impl FnMut(f64) -> f64, g0: f64, g1: f64, tol: f64) -> (f64, usize) {
    locate_in(g, (0.0, g0), (1.0, g1), tol)
}

/// [`locate`] on the bracket `[a, b]` with `g(a) = fa >= 0` and `g(b) = fb < 0`.
pub fn locate_in(
    mut g: impl FnMut(f64) -> f64,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    tol: f64,
) -> (f64, usize) {
    let mut side = 0i8;
    let mut evals = 0usize;
    while b - a > tol && evals < 200 {
        let mut x = if fa == fb {
            0.5 * (a + b)
        } else {
            (a * fb - b * fa) / (fb - fa)
        };
        if !(x > a && x < b) {
            x = 0.5 * (a + b);
        }
        let fx = g(x);
        evals += 1;
        if fx < 0.0 {
            b = x;
            fb = fx;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = x;
            fa = fx;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
        if fx == 0.0 {
            return (x, evals);
        }
    }
    (b, evals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locates_a_simple_root() {
        let (x, n) = locate(|t| 0.3 - t * t, 0.3, -0.7, 1e-14);
        assert!((x - 0.3f64.sqrt()).abs() < 1e-13, "{x}");
        assert!(n < 60);
    }
}
