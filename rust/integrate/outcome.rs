//! What a run returns (diffrax's `_solution.py`): why it ended, its work counters, the
//! results of each contact and joint, the recorded series, and [`OUTCOME_FIELDS`], the one
//! table of the output fields that the Python summary dicts and the sweep columns read.

use nalgebra::Vector2;

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

    /// Its code in a table of numbers (a sweep's `status` column): 0 stopped, 1 end time,
    /// 2 not stopped.
    pub const fn code(self) -> f64 {
        match self {
            Status::Stopped => 0.0,
            Status::EndTime => 1.0,
            Status::NotStopped => 2.0,
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
    ///
    /// [`MAX_EVENTS_PER_STEP`]: super::events::MAX_EVENTS_PER_STEP
    pub unresolved: usize,
    /// Contacts whose result the step did not resolve: at the located stop the tip's
    /// vertical velocity (the stop's switching function, zero there when the step resolves
    /// it) over its vertical acceleration, an estimate of the stop time's error, was above
    /// [`STOP_TIME_ERROR`] of t_s (the stop is located on the step's interpolant; an impact
    /// over in a few steps misses it, by up to several per cent in t_s); or the steps' own
    /// error estimate ([`Outcome::step_error`]) put its t_s or depth (at the stop, or at the
    /// end without one) above [`STOP_TIME_ERROR`]; or a sign switch's located velocity
    /// overshot zero where the static bound would have held the contact, so that it slid on
    /// the other way, speeding up: the step, not the contact, decided (an `rft` rod that
    /// sticks at dt = 1e-5 slides on at 1e-4 and stops 16 % early), and by its stop (or the
    /// end) that slide had lasted [`STOP_TIME_ERROR`] of the time or moved E by as much of
    /// the depth. Each contact counts once.
    ///
    /// [`STOP_TIME_ERROR`]: super::observe::STOP_TIME_ERROR
    pub unresolved_stops: usize,
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
    /// Work of the impulses of a table-driven joint over the run [J].
    pub impulse_work: f64,
}

/// One impulse of a table-driven joint, at one of its table's times.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impulse {
    /// The link the joint carries (the model's order).
    pub link: usize,
    /// When [s].
    pub t: f64,
    /// The angular impulse the joint applies to its link (and the opposite to the parent)
    /// [N m s].
    pub impulse: f64,
    /// The work it does, impulse times the mean of the relative rate before and after [J].
    pub energy: f64,
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
    /// The impulses of the table-driven joints, in time order.
    pub impulses: Vec<Impulse>,
    /// Largest `dt * lambda` over the run: the step times the contact's fastest rate. The
    /// drag's, `2 |F_d| / |v_E|` times E's inverse effective mass (see
    /// [`Model::centroid_inverse_mass`]), at the state where the drag was stiffest (step
    /// ends, events and RK4 stages: see [`crate::integrate::stepper::step_sampling`]); with
    /// a term that reads the contact's boundary (`rft`, `rft_inertial`, `poncelet`), also
    /// every listed term's own stiffness ([`crate::forces::Term::rates`]) at the start, the
    /// step ends and the events. Above [`RK4_STABILITY_LIMIT`] the fixed step does not
    /// resolve the impact. NaN with the adaptive method, 0 without a stiff term.
    ///
    /// [`Model::centroid_inverse_mass`]: crate::dynamics::Model::centroid_inverse_mass
    /// [`RK4_STABILITY_LIMIT`]: super::observe::RK4_STABILITY_LIMIT
    pub h_lambda: f64,
    /// The largest relative error of a contact's t_s or depth that the run's steps estimate
    /// (RK4; NaN for Dopri5): each step's error estimate
    /// ([`crate::integrate::stepper::companion`]; a step cut at an event takes the whole
    /// step's, scaled to its length), summed in magnitude over the run, carried
    /// to the tip's height and vertical velocity at the stop (or at the end without one);
    /// a stop's time error is that velocity's error and the residual left at the located
    /// stop over the tip's vertical acceleration. Above
    /// [`STOP_TIME_ERROR`](super::observe::STOP_TIME_ERROR) the result moves with the step,
    /// and the contact counts in [`Stats::unresolved_stops`] (except under the plain
    /// `sign()`, whose chatter the estimate overstates).
    pub step_error: f64,
    /// Time series, if any were asked for.
    pub series: Option<Series>,
    /// The terms that acted, in the scene's order.
    pub terms: Vec<&'static str>,
    /// The output fields the run computed and returns (its options' `outputs`): the
    /// others hold NaN or 0 and are not returned.
    pub outputs: Outputs,
}

/// The value of one output field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FieldValue {
    /// A real number (NaN where the run has none).
    Real(f64),
    /// A count.
    Count(usize),
    /// Yes or no.
    Flag(bool),
    /// Why the run ended.
    Status(Status),
}

impl FieldValue {
    /// The value as a number: a count as itself, a flag as 0 or 1, a status by its
    /// [`Status::code`].
    #[inline]
    pub fn as_f64(self) -> f64 {
        match self {
            FieldValue::Real(x) => x,
            FieldValue::Count(n) => n as f64,
            FieldValue::Flag(b) => {
                if b {
                    1.0
                } else {
                    0.0
                }
            }
            FieldValue::Status(s) => s.code(),
        }
    }
}

/// One output field: its name (a key of `granrs.Result.summary` and of its contacts' and
/// joints' summaries, a sweep column), its unit, and how to read it from `T`.
#[derive(Clone, Copy)]
pub struct Field<T> {
    /// The name.
    pub name: &'static str,
    /// Its unit ("-" for a count, a flag or a status).
    pub unit: &'static str,
    /// Whether a run that ends with it non-finite is refused (see
    /// `observe::check_outcome`); the others may be NaN (no stop, no entry).
    pub finite: bool,
    /// What the run must compute for it beyond what every run computes (a scene whose
    /// [`Outputs`] leave out every field that needs a part does not compute that part).
    pub needs: Needs,
    /// Its value in `T`.
    pub read: fn(&T) -> FieldValue,
}

impl<T> Field<T> {
    /// The same field, needing `needs`.
    const fn needing(self, needs: Needs) -> Self {
        Field {
            name: self.name,
            unit: self.unit,
            finite: self.finite,
            needs,
            read: self.read,
        }
    }
}

/// The parts of a run's observation that only some output fields need, as a set: what a run
/// computes beyond its steps, its events and the state at its stops and its end (which give
/// every other field for nothing).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Needs(u8);

impl Needs {
    /// Nothing beyond what every run computes.
    pub const NONE: Needs = Needs(0);
    /// The largest drag of each contact, at every step's end and event (`F_d_max`).
    pub const DRAG_MAX: Needs = Needs(1);
    /// The contact's stiffness at every RK4 stage, step end and event, and with a term that
    /// reads the contact's boundary each term's own rates there (`h_lambda`).
    pub const STIFFNESS: Needs = Needs(1 << 1);
    /// Each step's error estimate, summed over the run and carried to the tip at each stop
    /// (`step_error`, and the part of `unresolved_stops` that reads it).
    pub const STEP_ERROR: Needs = Needs(1 << 2);
    /// The body's and each contact link's energies at each stop (`dKE`, `dPE`, `dE`,
    /// `link_dKE`, `link_dPE`, `link_dE`).
    pub const ENERGY: Needs = Needs(1 << 3);
    /// The joints' forces and torques at every step's end (`F_max`, `torque_max`).
    pub const JOINT_LOADS: Needs = Needs(1 << 4);
    /// Every part.
    pub const ALL: Needs = Needs((1 << 5) - 1);
    /// What every run computes, whatever its outputs: the steps' error estimate and the
    /// checks of each stop behind `unresolved_stops`, which `granrs.StepSizeWarning` reads
    /// (a safety output, and cheap: one estimate per step from stages the step has, against
    /// the stiffness sampling's four offers a step). Returned only when asked for.
    pub const ALWAYS: Needs = Needs::STEP_ERROR;

    /// Both sets.
    #[inline]
    pub const fn union(self, other: Needs) -> Needs {
        Needs(self.0 | other.0)
    }

    /// Whether every part of `other` is in this set.
    #[inline]
    pub const fn has(self, other: Needs) -> bool {
        self.0 & other.0 == other.0
    }

    /// The parts' names (for the documentation of the fields).
    pub fn names(self) -> Vec<&'static str> {
        [
            (Needs::DRAG_MAX, "the largest drag"),
            (Needs::STIFFNESS, "the stiffness sampling"),
            (Needs::STEP_ERROR, "the steps' error estimate"),
            (Needs::ENERGY, "the energies at the stop"),
            (Needs::JOINT_LOADS, "the joints' loads"),
        ]
        .into_iter()
        .filter(|(n, _)| n.0 != 0 && self.has(*n))
        .map(|(_, name)| name)
        .collect()
    }
}

/// The output fields of a run, by what they belong to, each in its order.
#[derive(Clone, Copy)]
pub struct OutcomeFields {
    /// The run's (`Result.summary`'s run-level keys; a sweep's first columns).
    pub run: &'static [Field<Outcome>],
    /// Each contact's (`ContactResult.summary`; a sweep's `c{i}.` columns).
    pub contact: &'static [Field<ContactSummary>],
    /// Each joint's (`Result.joints`; a sweep's `joint{i}.` columns).
    pub joint: &'static [Field<JointSummary>],
}

/// A real field of `T`.
const fn real<T>(name: &'static str, unit: &'static str, read: fn(&T) -> FieldValue) -> Field<T> {
    Field {
        name,
        unit,
        finite: false,
        needs: Needs::NONE,
        read,
    }
}

/// A real field of `T` that a run must end with finite.
const fn finite<T>(name: &'static str, unit: &'static str, read: fn(&T) -> FieldValue) -> Field<T> {
    Field {
        name,
        unit,
        finite: true,
        needs: Needs::NONE,
        read,
    }
}

/// A count of `T`.
const fn count<T>(name: &'static str, read: fn(&T) -> FieldValue) -> Field<T> {
    Field {
        name,
        unit: "-",
        finite: false,
        needs: Needs::NONE,
        read,
    }
}

use FieldValue::{Count, Flag, Real};

/// Every output field of a run: the one list the bindings' summary dicts, the sweep's
/// columns and the check of a finished run read.
pub const OUTCOME_FIELDS: OutcomeFields = OutcomeFields {
    run: &[
        Field {
            name: "status",
            unit: "-",
            finite: false,
            needs: Needs::NONE,
            read: |o| FieldValue::Status(o.status),
        },
        real("t_final", "s", |o| Real(o.t_final)),
        count("steps", |o| Count(o.stats.steps)),
        count("rhs_evals", |o| Count(o.stats.rhs_evals)),
        count("root_evals", |o| Count(o.stats.root_evals)),
        count("events", |o| Count(o.stats.events)),
        count("rejected", |o| Count(o.stats.rejected)),
        count("unresolved", |o| Count(o.stats.unresolved)),
        count("unresolved_stops", |o: &Outcome| {
            Count(o.stats.unresolved_stops)
        })
        .needing(Needs::STEP_ERROR),
        real("energy_start", "J", |o| Real(o.energy_start)),
        real("energy_end", "J", |o| Real(o.energy_end)),
        real("dissipated", "J", |o| Real(o.dissipated)),
        real("h_lambda", "-", |o: &Outcome| Real(o.h_lambda)).needing(Needs::STIFFNESS),
        real("step_error", "-", |o: &Outcome| Real(o.step_error)).needing(Needs::STEP_ERROR),
    ],
    contact: &[
        Field {
            name: "stopped",
            unit: "-",
            finite: false,
            needs: Needs::NONE,
            read: |c| Flag(c.stopped),
        },
        real("t_s", "s", |c| Real(c.t_s)),
        finite("depth", "m", |c| Real(c.depth)),
        finite("dq", "rad", |c| Real(c.dq)),
        finite("omega_end", "rad/s", |c| Real(c.omega_end)),
        finite("F_d_max", "N", |c: &ContactSummary| Real(c.f_d_max)).needing(Needs::DRAG_MAX),
        finite("F_s_end", "N", |c| Real(c.f_s_end)),
        finite("F_r_end", "N", |c| Real(c.f_r_end)),
        finite("dKE", "J", |c: &ContactSummary| Real(c.d_ke)).needing(Needs::ENERGY),
        finite("dPE", "J", |c: &ContactSummary| Real(c.d_pe)).needing(Needs::ENERGY),
        real("dE", "J", |c: &ContactSummary| Real(c.d_e)).needing(Needs::ENERGY),
        finite("work_sand", "J", |c| Real(c.work_sand)),
        finite("x_tip_end", "m", |c| Real(c.tip_end.x)),
        real("t_entry", "s", |c| Real(c.t_entry)),
        real("link_dKE", "J", |c: &ContactSummary| Real(c.link_d_ke)).needing(Needs::ENERGY),
        real("link_dPE", "J", |c: &ContactSummary| Real(c.link_d_pe)).needing(Needs::ENERGY),
        real("link_dE", "J", |c: &ContactSummary| {
            Real(c.link_d_ke + c.link_d_pe)
        })
        .needing(Needs::ENERGY),
    ],
    joint: &[
        real("F_max", "N", |j: &JointSummary| Real(j.f_max)).needing(Needs::JOINT_LOADS),
        real("torque_max", "N m", |j: &JointSummary| Real(j.torque_max))
            .needing(Needs::JOINT_LOADS),
        real("impulse_work", "J", |j| Real(j.impulse_work)),
    ],
};

/// The set of `n` fields' bits (`n` <= 64).
const fn first_bits(n: usize) -> u64 {
    if n >= 64 {
        u64::MAX
    } else {
        (1u64 << n) - 1
    }
}

/// Which output fields of [`OUTCOME_FIELDS`] a run returns: a scene's `outputs`, as a set
/// (one bit per field of each part; a contact's field is every contact's, a joint's every
/// joint's). `status` is always in it. The run computes the parts of its observation that
/// the fields in it need ([`Outputs::needs`]) and no other: a field left out is neither
/// computed nor returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outputs {
    run: u64,
    contact: u64,
    joint: u64,
}

impl Default for Outputs {
    /// Every field (what a scene without `outputs` returns).
    fn default() -> Self {
        Outputs::ALL
    }
}

impl Outputs {
    /// Every field.
    pub const ALL: Outputs = Outputs {
        run: first_bits(OUTCOME_FIELDS.run.len()),
        contact: first_bits(OUTCOME_FIELDS.contact.len()),
        joint: first_bits(OUTCOME_FIELDS.joint.len()),
    };

    /// The fields named in `names` (and `status`, always): an unknown name or one listed
    /// twice is an error naming the field `outputs`.
    pub fn from_names<S: AsRef<str>>(names: &[S]) -> crate::error::Result<Outputs> {
        use crate::error::GranrsError;
        let fields = &OUTCOME_FIELDS;
        // `status` (the run's first field) is always returned.
        let mut out = Outputs {
            run: 1,
            contact: 0,
            joint: 0,
        };
        let mut listed = Outputs {
            run: 0,
            contact: 0,
            joint: 0,
        };
        for name in names {
            let name = name.as_ref();
            let find = |part: &[&'static str]| part.iter().position(|&n| n == name);
            let (set, bit) = if let Some(i) = find(&Self::part_names(fields.run)) {
                (&mut listed.run, i)
            } else if let Some(i) = find(&Self::part_names(fields.contact)) {
                (&mut listed.contact, i)
            } else if let Some(i) = find(&Self::part_names(fields.joint)) {
                (&mut listed.joint, i)
            } else {
                return Err(GranrsError::UnknownName {
                    field: "outputs".into(),
                    value: name.to_string(),
                    allowed: Self::names().join(", "),
                });
            };
            if *set & (1 << bit) != 0 {
                return Err(GranrsError::InvalidScene {
                    field: "outputs".into(),
                    message: format!("lists {name:?} twice (each field once)"),
                });
            }
            *set |= 1 << bit;
        }
        out.run |= listed.run;
        out.contact |= listed.contact;
        out.joint |= listed.joint;
        Ok(out)
    }

    fn part_names<T>(part: &[Field<T>]) -> Vec<&'static str> {
        part.iter().map(|f| f.name).collect()
    }

    /// Every output field's name: the run's, then a contact's, then a joint's, each in
    /// [`OUTCOME_FIELDS`]' order (what a scene's `outputs` may list).
    pub fn names() -> Vec<&'static str> {
        let fields = &OUTCOME_FIELDS;
        let mut out = Self::part_names(fields.run);
        out.extend(Self::part_names(fields.contact));
        out.extend(Self::part_names(fields.joint));
        out
    }

    /// Whether every field is in it.
    #[inline]
    pub fn is_all(&self) -> bool {
        *self == Outputs::ALL
    }

    /// What the run must compute for these fields beyond what every run computes.
    pub fn needs(&self) -> Needs {
        let mut needs = Needs::NONE;
        for f in self.run() {
            needs = needs.union(f.needs);
        }
        for f in self.contact() {
            needs = needs.union(f.needs);
        }
        for f in self.joint() {
            needs = needs.union(f.needs);
        }
        needs
    }

    fn pick<T>(part: &'static [Field<T>], bits: u64) -> impl Iterator<Item = &'static Field<T>> {
        part.iter()
            .enumerate()
            .filter(move |(i, _)| bits & (1 << i) != 0)
            .map(|(_, f)| f)
    }

    /// The run's fields in it, in [`OUTCOME_FIELDS`]' order (`status` first).
    pub fn run(&self) -> impl Iterator<Item = &'static Field<Outcome>> {
        Self::pick(OUTCOME_FIELDS.run, self.run)
    }

    /// Each contact's fields in it, in order.
    pub fn contact(&self) -> impl Iterator<Item = &'static Field<ContactSummary>> {
        Self::pick(OUTCOME_FIELDS.contact, self.contact)
    }

    /// Each joint's fields in it, in order.
    pub fn joint(&self) -> impl Iterator<Item = &'static Field<JointSummary>> {
        Self::pick(OUTCOME_FIELDS.joint, self.joint)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_names_are_unique_within_each_part() {
        fn unique(names: Vec<&str>) {
            let mut sorted = names.clone();
            sorted.sort_unstable();
            sorted.dedup();
            assert_eq!(sorted.len(), names.len(), "{names:?}");
        }
        unique(OUTCOME_FIELDS.run.iter().map(|f| f.name).collect());
        unique(OUTCOME_FIELDS.contact.iter().map(|f| f.name).collect());
        unique(OUTCOME_FIELDS.joint.iter().map(|f| f.name).collect());
        // A scene's `outputs` names fields of every part in one list.
        unique(Outputs::names());
    }

    #[test]
    fn outputs_select_fields_and_what_they_need() {
        let o = Outputs::from_names(&["depth", "t_s"]).unwrap();
        let run: Vec<_> = o.run().map(|f| f.name).collect();
        let contact: Vec<_> = o.contact().map(|f| f.name).collect();
        assert_eq!(run, ["status"]);
        assert_eq!(contact, ["t_s", "depth"]);
        assert_eq!(o.joint().count(), 0);
        assert_eq!(o.needs(), Needs::NONE);
        let o = Outputs::from_names(&["F_d_max", "h_lambda", "dE", "F_max"]).unwrap();
        assert!(o.needs().has(Needs::DRAG_MAX.union(Needs::STIFFNESS)));
        assert!(o.needs().has(Needs::ENERGY.union(Needs::JOINT_LOADS)));
        assert!(!o.needs().has(Needs::STEP_ERROR));
        assert_eq!(Outputs::ALL.needs(), Needs::ALL);
        assert_eq!(
            Outputs::from_names(&Outputs::names()).unwrap(),
            Outputs::ALL
        );
        assert_eq!(Outputs::ALL.run().count(), OUTCOME_FIELDS.run.len());
    }

    #[test]
    fn unknown_or_repeated_outputs_name_the_field() {
        match Outputs::from_names(&["depth", "dpeth"]) {
            Err(crate::error::GranrsError::UnknownName { field, value, .. }) => {
                assert_eq!((field.as_str(), value.as_str()), ("outputs", "dpeth"));
            }
            other => panic!("{other:?}"),
        }
        match Outputs::from_names(&["t_s", "t_s"]) {
            Err(crate::error::GranrsError::InvalidScene { field, .. }) => {
                assert_eq!(field, "outputs");
            }
            other => panic!("{other:?}"),
        }
    }
}
