//! The one table of a scene's fields: name, the part of the scene it belongs to, its unit,
//! a short note and its description with the default's source. Which bodies read a field is
//! said by the presets that read it (`crate::presets::Preset::fields`); a field no preset
//! reads applies to every body.
//!
//! Everything that describes a field reads this table: the spec's slots (the core's
//! conversion and validation), the error messages (a field's unit and note follow the
//! allowed range), `granrs.Scene`'s documentation, `granrs.scene.BODY_FIELDS`, the notes of
//! a TOML scene file and the docs site's field tables (through `_granrs.scene_fields()`).
//! Defaults live with their values: the `granrs.Scene` dataclass, whose fields a test holds
//! to this table. Sorted by name.

/// The most steps a run may take, `t_end / dt` (the bound of the `t_end` field): a run of
/// the free link takes about 1 us a step, so this is about a quarter of an hour.
pub const MAX_STEPS: f64 = 1e9;

/// The most samples a recorded series may hold, `t_end / dt / record_stride` (the bound of
/// the `record_stride` field with `record`): each sample takes a few dozen floats, so this is
/// a few GB at most.
pub const MAX_SAMPLES: f64 = 1e7;

/// One field of a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FieldInfo {
    /// The field's name (`granrs.Scene` attribute, TOML key, error `field`).
    pub name: &'static str,
    /// The part of the scene it belongs to: `body`, `medium`, `forces`, `start`, `solver`,
    /// `outputs`, or `notes` (provenance the run does not read).
    pub part: &'static str,
    /// Its unit (`-`: none; a name field: empty).
    pub unit: &'static str,
    /// A short note: the allowed values or range (TOML comments, error messages).
    pub note: &'static str,
    /// What it is, with the default's source.
    pub doc: &'static str,
}

macro_rules! scene_fields {
    ($($name:literal: $part:literal, $unit:literal, $note:literal, $doc:literal;)*) => {
        /// Every field of a scene, sorted by name (the core's slots).
        pub const SCENE_FIELDS: [&str; [$($name,)*].len()] = [$($name,)*];

        /// Every field's description, in the order of [`SCENE_FIELDS`].
        pub static FIELDS: [FieldInfo; SCENE_FIELDS.len()] = [$(FieldInfo {
            name: $name,
            part: $part,
            unit: $unit,
            note: $note,
            doc: $doc,
        },)*];

        /// The slot of a field of [`SCENE_FIELDS`]: a `match` on its name (a switch on the
        /// length and an inlined comparison, no search).
        #[inline]
        pub(crate) fn field_slot(name: &str) -> Option<usize> {
            match name {
                $($name => Some(const { position($name) }),)*
                _ => None,
            }
        }
    };
}

scene_fields! {
    "ankle": "body", "", "locked, free or { k = N m/rad, c = N m s/rad }",
        "the ankle: \"locked\" (default), \"free\" or a spring-damper {\"k\": N m/rad, \"c\": N m s/rad} relaxed at the touchdown posture (the thesis's CAD model does not say)";
    "apply_at": "forces", "", "tip or centroid",
        "where the contact terms act: \"tip\" (default; the thesis's CAD runs, sec. 3.3.2) or \"centroid\" (the immersed centroid E, sec. 3.3.1; strictly dissipative)";
    "atol": "solver", "-", "> 0",
        "absolute tolerance of \"dopri5\" [SI units of each coordinate]";
    "body": "body", "", "free_link, chain, leg or a linkage",
        "the body: \"free_link\" (a round rod, 3 degrees of freedom), \"chain\" (two rods pinned at their top ends, 4), \"leg\" (foot, shank, thigh, half trunk, 6), each held as a granrs.bodies.Linkage, or a granrs.bodies.Linkage of your own (links, joints, contacts, root)";
    "body_mass": "body", "kg", "> 0; the leg carries half",
        "body mass (thesis sec. 5.2.1: 75.35); the leg carries half of it";
    "coefficients_source": "notes", "", "text",
        "where the force terms' parameters come from (for reports; not used by the run)";
    "depth0": "start", "m", ">= 0",
        "initial depth of the tip (0: at the surface, as in the thesis)";
    "diameter": "body", "m", "> 0",
        "rod diameter d_c (thesis sec. 3.2.1: 0.0127); each chain link's";
    "dt": "solver", "s", "> 0",
        "step of the fixed-step RK4 (thesis sec. 3.3.2: 10 kHz, 1e-4); the first step of \"dopri5\"";
    "end": "solver", "", "first_stop, all_stops or time",
        "when the run ends: \"first_stop\" (the thesis's end of the penetration phase), \"all_stops\" or \"time\"";
    "foot_deg": "start", "deg", "-60..60",
        "sole pitch at touchdown, toe up (0: flat landing)";
    "foot_length": "body", "m", "> 0",
        "foot size f_s (thesis sec. 5.3.2: 0.254)";
    "forces": "forces", "", "[[forces]] tables: term = name and its parameters",
        "the force terms that act (granrs.forces), each with its parameters: one value for every contact or one per contact. Default: the thesis's law (gravity, drag, static_h, static_v, joint_springs) with each term's defaults, Table 3.4 at q = 0. A term not listed is neither computed nor stored, and a spring-damper joint is free without joint_springs; []: nothing acts";
    "g": "medium", "m/s^2", ">= 0",
        "gravitational acceleration (9.81, as in the thesis); the static terms scale with it, and the gravity term pulls with it";
    "height": "body", "m", "> 0",
        "body height H (thesis sec. 5.2.1: 1.78)";
    "hip": "body", "", "locked, free or { k = N m/rad, c = N m s/rad }",
        "the hip: as the ankle";
    "hip_deg": "start", "deg", "-30..150",
        "hip flexion at touchdown (granrs assumption: 20)";
    "inertia": "body", "kg m^2", "> 0; left out: solid cylinder",
        "moment of inertia about the centre of mass; None for a solid cylinder, m (L^2/12 + d_c^2/16)";
    "knee": "body", "", "locked, free or { k = N m/rad, c = N m s/rad }",
        "the knee: as the ankle";
    "knee_deg": "start", "deg", "0..150",
        "knee flexion at touchdown (granrs assumption: 20)";
    "length": "body", "m", "> 0",
        "rod length L (thesis sec. 3.2.1: 0.190); each chain link's";
    "mass": "body", "kg", "> 0",
        "body mass m (thesis sec. 3.2.1: 0.184); each chain link's (not in the thesis: 0.0341, a solid steel link)";
    "medium": "notes", "", "a medium's name, a card's path, or none",
        "the granular medium (granrs.media): a shipped card's name, a card file's path or a granrs.media.MediumCard; its rho_g and g, and each listed term's parameters the scene does not give, come from the card (default: none, the fields and the terms' defaults as given)";
    "method": "solver", "", "rk4 or dopri5",
        "the integrator: \"rk4\" (default: classical RK4 on the grid n dt) or \"dopri5\" (adaptive Dormand-Prince 5(4) with rtol and atol)";
    "omega0": "start", "rad/s", "finite",
        "initial angular velocity dq/dt";
    "outputs": "outputs", "", "names of summary fields (status always); left out: all",
        "the summary fields a run computes and returns (Result.summary's keys, a sweep's columns): names from granrs.OUTPUTS; None (default): every field. A field left out is not computed: its share of the run's work is saved (the energies at the stop, the largest drag, the stiffness sampling behind h_lambda, the steps' error estimate, the joints' loads); status is always returned";
    "pin_joint": "body", "", "free, locked or { k = N m/rad, c = N m s/rad }",
        "the pin: \"free\" (the thesis's frictionless joint, sec. 4.1), \"locked\" or a spring-damper (rest angle: the initial one)";
    "pin_mass": "body", "kg", ">= 0",
        "mass of the pin, a point mass at the joint (0)";
    "q2_deg": "start", "deg", "-90 < q2_deg < 90; left out: -q_deg",
        "link 2's angle from the vertical; None: -q_deg (mirror image)";
    "q_deg": "start", "deg", "-90 < q_deg < 90",
        "initial angle of the rod (chain: link 1) from the vertical";
    "record": "outputs", "", "from state, forces, energy",
        "time series to record, from RECORDS (none by default)";
    "record_stride": "outputs", "-", "a whole number >= 1; with record, t_end / dt / record_stride <= 1e7 samples",
        "record every n-th step (events are always recorded)";
    "rho_g": "medium", "kg/m^3", "> 0",
        "bulk density of the sand, packing included (thesis sec. 3.3.1: 1650; the leg's sand, sec. 5.3.2: 1600)";
    "rtol": "solver", "-", ">= 2.2e-14 (100 x f64's epsilon)",
        "relative tolerance of \"dopri5\"";
    "shoe_width": "body", "m", "> 0",
        "shoe width w_s (thesis sec. 5.3.2: 0.086)";
    "sign_model": "forces", "", "modes, raw or smooth",
        "how the static terms take the sign of the velocity: \"modes\" (default: each sign held through a step, switches located exactly, sticking handled), \"raw\" (the thesis's plain sign) or \"smooth\" (tanh(v / smooth_eps))";
    "smooth_eps": "forces", "m/s", "> 0",
        "velocity scale of the \"smooth\" sign model";
    "sole_height": "body", "m", "> 0; left out: the tibia length",
        "height of the contact box above the sole; None: the tibia length (the sole's footprint carried up the leg, so V keeps growing as f_s w_s d past the ankle, as eq. 5.7 does); 0.039 H lets only the shoe count";
    "sole_model": "body", "", "box or thesis",
        "the sole's contact: \"box\" (the geometric box of docs/model.md) or \"thesis\" (eqs. 5.5-5.7 with the shank's angle; finite only for 1 <= shank angle <= 89 deg)";
    "step_check": "solver", "", "true or false",
        "check a run whose step looks too coarse by running it again at dt / 10 (true, default): granrs.StepSizeWarning is raised only if t_s, the depth or the status moves by more than 1 %; the returned result is the run at dt either way. false: no re-run, no warning (raw speed)";
    "t_end": "solver", "s", "> 0; t_end / dt <= 1e9 steps",
        "latest end time";
    "tibia_length": "body", "m", "> 0",
        "tibia l_l (thesis sec. 5.3.2: 0.432): the shank and L_ref of eq. 5.4";
    "trunk_deg": "start", "deg", "-60..60",
        "trunk lean forward at touchdown (granrs assumption: 10)";
    "v0": "start", "m/s", ">= 0",
        "initial downward speed";
    "vx0": "start", "m/s", "finite",
        "initial horizontal velocity of the tip";
}

/// Where `name` is in [`SCENE_FIELDS`] (at compile time).
const fn position(name: &str) -> usize {
    let mut i = 0;
    while i < SCENE_FIELDS.len() {
        let (a, b) = (SCENE_FIELDS[i].as_bytes(), name.as_bytes());
        if a.len() == b.len() {
            let mut j = 0;
            while j < a.len() && a[j] == b[j] {
                j += 1;
            }
            if j == a.len() {
                return i;
            }
        }
        i += 1;
    }
    panic!("not a scene field")
}

/// The description of the scene field `name` (or of the field `name.sub` belongs to, e.g.
/// `knee` for `knee.k`), if it is one.
pub fn info(name: &str) -> Option<&'static FieldInfo> {
    let base = name.split('.').next().unwrap_or(name);
    field_slot(base).map(|i| &FIELDS[i])
}

/// One field of an element of a linkage (`granrs.bodies`: a link, a joint, a contact or
/// the root).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ElementField {
    /// The element: `link`, `joint`, `contact` or `root`.
    pub element: &'static str,
    /// The field's name (dataclass attribute, TOML key, error `field` after the element).
    pub name: &'static str,
    /// Its unit (`-`: none; a name or a kind: empty).
    pub unit: &'static str,
    /// A short note: the allowed values or range.
    pub note: &'static str,
    /// What it is.
    pub doc: &'static str,
}

/// Every field of a linkage's elements, by element (the one table: the core's parsing,
/// `granrs.bodies`' dataclasses and docs, the TOML notes).
pub static ELEMENT_FIELDS: [ElementField; 39] = {
    const fn f(
        element: &'static str,
        name: &'static str,
        unit: &'static str,
        note: &'static str,
        doc: &'static str,
    ) -> ElementField {
        ElementField {
            element,
            name,
            unit,
            note,
            doc,
        }
    }
    [
        f("link", "name", "", "unique", "the link's name (results: <name>.KE, <name>.PE)"),
        f("link", "mass", "kg", "> 0", "mass"),
        f("link", "inertia", "kg m^2", "> 0", "moment of inertia about the centre of mass, out of the plane"),
        f("link", "length", "m", "> 0", "length along the link's axis (drawing and reports)"),
        f("link", "com", "m", "(s, n), finite", "centre of mass in the link's (s, n) coordinates: s along the axis from the link's joint, n normal to it"),
        f("link", "q_deg", "deg", "finite", "initial angle of the link's axis from the vertical"),
        f("link", "omega0", "rad/s", "finite", "initial angular velocity (behind a locked or driven joint: the parent's plus the joint's rate)"),
        f("joint", "name", "", "unique", "the joint's name (results: <name>.Fx, .Fy, .torque)"),
        f("joint", "parent", "", "a link's name", "the link the joint sits on"),
        f("joint", "child", "", "a link's name", "the link the joint carries (its (s, n) origin is the joint)"),
        f("joint", "at", "m", "(s, n), finite", "where the joint sits on the parent, in the parent's (s, n) coordinates"),
        f("joint", "kind", "", "free, locked, spring or driven", "\"free\" (frictionless), \"locked\", \"spring\" (a spring-damper k, c about rest_deg) or \"driven\" (its relative angle moves at rate, plus a sinusoid; or along a table)"),
        f("joint", "k", "N m/rad", ">= 0", "a spring's stiffness"),
        f("joint", "c", "N m s/rad", ">= 0", "a spring's damping"),
        f("joint", "rest_deg", "deg", "finite; left out: the initial angle", "a spring's rest angle, child relative to parent; None: the initial relative angle"),
        f("joint", "rate", "rad/s", "finite; left out: 0", "a driven joint's constant relative rate; its angle is the initial one plus rate t plus the sinusoid; the run reports the torque it takes"),
        f("joint", "amplitude_deg", "deg", "finite; left out: 0", "a driven joint's sinusoid: amplitude_deg (sin(2 pi frequency t + phase) - sin(phase)) added to its angle"),
        f("joint", "frequency", "Hz", "finite; needed with an amplitude", "the sinusoid's frequency"),
        f("joint", "table", "s, deg", "(time, angle_deg) pairs: at least 2, finite, times strictly increasing; alone", "a driven joint's table of its relative angle child minus parent: the angle is its linear interpolation, held at the first angle before the first time and at the last after the last; its angle at t = 0 must be the initial relative angle (links' q_deg), and each time is a located event where the joint's rate jumps by an impulse the run reports (Result.impulses)"),
        f("joint", "phase_deg", "deg", "finite; left out: 0", "the sinusoid's phase at t = 0"),
        f("contact", "name", "", "text", "the contact's name"),
        f("contact", "shape", "", "rod, box or arc", "\"rod\" (a round rod meeting the sand with its tip: tip and outline), \"box\" (a sole, a plate) or \"arc\" (a thin circular arc, a C-shaped leg, cut into chords)"),
        f("contact", "link", "", "a link's name", "the link the contact is fixed on"),
        f("contact", "at", "m", "(s, n), finite", "a rod's tip, a box's corner on the sole, or an arc's centre, in the link's (s, n) coordinates"),
        f("contact", "length", "m", "> 0; a rod or a box", "a rod's length from its tip along +s, or a box's along +s (also the width of a box's horizontal static term)"),
        f("contact", "diameter", "m", "> 0", "a rod's diameter"),
        f("contact", "height", "m", "> 0", "a box's height from the sole towards -n"),
        f("contact", "width", "m", "> 0", "a box's or an arc's width out of the plane"),
        f("contact", "radius", "m", "> 0", "an arc's radius"),
        f("contact", "start_deg", "deg", "finite", "the angle of an arc's first end, from the link's +s axis towards its +n axis: the arc's point at angle phi is at + radius (cos phi, sin phi) in (s, n)"),
        f("contact", "end_deg", "deg", "start_deg < end_deg <= start_deg + 360", "the angle of an arc's last end (the arc runs from start_deg up to end_deg)"),
        f("contact", "chords", "-", "a whole number 1..64; left out: 16", "the chords an arc is cut into: each is a plate of its boundary for rft and rft_inertial"),
        f("contact", "l_ref", "m", "> 0; left out: length", "reference length of the depth factor (eq. 5.4)"),
        f("root", "kind", "", "free, pinned or moving", "\"free\" (a floating base), \"pinned\" (fixed in space) or \"moving\" (at a constant velocity)"),
        f("root", "link", "", "a link's name", "the root link: its (s, n) origin is the root point"),
        f("root", "position", "m", "(x, y), finite", "initial position of the root point (y = 0: the sand's surface)"),
        f("root", "mass", "kg", ">= 0", "a point mass at the root (the chain's pin)"),
        f("root", "velocity", "m/s", "(vx, vy), finite", "initial velocity of a free root; a moving root's constant one; none for a pinned root"),
        f("root", "rate", "rad/s", "finite; left out: the root link's angle is free", "the root link's angle driven at this constant rate (e.g. a C-leg turned about a fixed axle), from its q_deg; the run reports the torque it takes (the joint root)"),
    ]
};
