//! Force terms: the open model's unit of physics.
//!
//! A scene lists the terms that act on its body ([`ForceSet`]); a term that is not listed is
//! neither evaluated nor stored, and its sign switches are not watched. Each term is one file
//! here, opening (as a REBOUNDx effect does) with its equation in granrs's frame
//! (`docs/model.md`: x right, y up, sand surface at y = 0), its source, its parameters with
//! units and defaults, and the switches it owns. Its [`TermInfo`] is the one description of
//! it: validation, the TOML tables, the Python constructors (`granrs.forces`), the docs and
//! the error messages all read it.
//!
//! Two kinds of term:
//! - **contact terms** ([`Acts::Contact`]: `drag`, `static_h`, `static_v`, ...) read one
//!   contact's geometry and kinematics ([`ContactState`]) and return the force on it
//!   ([`TermForce`]), applied at the scene's point of application; their parameters may
//!   differ per contact;
//! - **body terms** ([`Acts::Body`]: `gravity`, `joint_springs`) act on the body as a whole,
//!   through the same trait's body methods: a uniform field on every mass
//!   ([`Term::field`], gravity's), torques at the joints ([`Term::add_joint_torques`],
//!   the spring-dampers'), with their energy and rates. They have no per-contact force, and
//!   the engine reads them only through those methods.
//!
//! A term's arithmetic is generic over [`Real`], so that the same code can later run on
//! several scenes at once in SIMD lanes (a lane type implementing [`Real`]) without a second
//! copy of the physics.
//!
//! Terms on a body in space (`rft3d`, `rft3d_inertial`; `poncelet` and `gravity` act there
//! too) name the shapes in space ([`SPACE_SHAPES`]) and give their element kernels for
//! `crate::space`; a planar scene refuses them before any work.
//!
//! Adding a term: one file with a struct implementing [`Term`] and one line in the registry
//! (`registry.rs`); its Python constructor is made from the registry. See `docs/forces.md`.

use std::fmt::Debug;

use nalgebra::SVector;

use crate::body::{Link, Mechanism};

pub mod axial_drag;
#[cfg(test)]
pub mod constant;
pub mod drag;
pub mod gravity;
pub mod joint_springs;
#[cfg(test)]
pub mod lift;
pub mod outline;
pub mod poncelet;
pub mod registry;
pub mod rft;
pub mod rft3d;
pub mod static_h;
pub mod static_v;

pub use crate::num::Real;
pub use registry::{AnyTerm, Coefficients, ForceSet, TermSpec, TERMS};

/// The granular medium (and the gravity that loads it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Medium<F = f64> {
    /// Bulk density of the sand, packing included [kg/m^3] (thesis sec. 3.3.1: 1650).
    pub rho_g: F,
    /// Gravitational acceleration [m/s^2] (9.81, as in the thesis). The static terms scale
    /// with it whether or not the `gravity` term acts on the body.
    pub g: F,
}

impl Default for Medium {
    fn default() -> Self {
        Medium {
            rho_g: 1650.0,
            g: 9.81,
        }
    }
}

/// What a contact term reads: one contact's geometry and kinematics below the surface
/// (`docs/model.md`, "What is immersed"). The engine fills it once per contact and
/// evaluation, and evaluates the contact terms where `depth > 0`, or from the moment of
/// entry when a listed term reads the frame ([`TermInfo::reads_frame`]: `rft`, `poncelet`,
/// `rft_inertial` are finite at depth 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactState<'a, F> {
    /// Depth of the contact d [m] (a rod's tip depth; a sole's immersed area / f_s).
    pub depth: F,
    /// Immersed volume V [m^3] (a rod's pi d_c^2 / 4 l).
    pub volume: F,
    /// Width w of the contact [m] (d_c for a rod, the sole length f_s for a foot).
    pub width: F,
    /// Reference length L_ref of the depth factor [m] (the rod length; the tibia).
    pub l_ref: F,
    /// Velocity of the immersed centroid E, v_E [m/s].
    pub v: [F; 2],
    /// Reference area times speed, A_r |v_E| [m^2/s] (a rod's d_c l |e x v_E|, with the sign
    /// of e x v_E held through the step in the `modes` sign model).
    pub area_speed: F,
    /// The signs of v_Ex and v_Ey as the sign model gives them: held (-1, 0 or +1, 0 where
    /// sticking), plain `sign()`, or `tanh(v / eps)`.
    pub sign: [F; 2],
    /// What the terms that integrate over the contact's boundary or act away from P read
    /// (`rft`, `rft_inertial`, `poncelet`): filled only when a listed term reads it
    /// ([`TermInfo::reads_frame`]), so that the thesis's law pays nothing for it.
    pub boundary: Option<&'a Boundary<F>>,
}

/// A contact's pose, motion and shape, for the terms that read more than a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Boundary<F> {
    /// Where the contact is and how it moves: its reference point T, T's velocity (as the
    /// mode holds it through a step: `dynamics::held_shift`), the link's angular velocity
    /// and the contact's axis.
    pub frame: Frame<F>,
    /// The contact's shape below the surface (its boundary plates).
    pub outline: Outline<F>,
    /// The point of application P of the scene (`apply_at`) [m]: a term with a moment
    /// returns it about P.
    pub apply: [F; 2],
    /// The immersed centroid E [m] (where `poncelet` acts).
    pub centroid: [F; 2],
    /// E's velocity as the mode holds it through the step [m/s] (`dynamics::held_shift`).
    pub v_centroid: [F; 2],
    /// Per axis, 1 where a sticking reaction holds E's velocity component at zero (a listed
    /// term owns the axis's slip switch and the mode sticks), else 0. A term gives no force
    /// along a held axis (the reaction stands in) and adds its capacity to the axis's bound.
    pub held: [F; 2],
}

/// A contact's pose and motion: what a term needs to find any point's velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame<F> {
    /// The reference point T [m] (a rod's tip; a sole's middle).
    pub origin: [F; 2],
    /// T's velocity [m/s].
    pub v: [F; 2],
    /// The link's angular velocity, counter-clockwise [rad/s].
    pub omega: F,
    /// Unit vector of the contact's axis: a rod's from its tip towards its top; a sole's
    /// from heel to toe.
    pub axis: [F; 2],
}

impl<F: Real> Frame<F> {
    /// Velocity of the point `p` [m/s] of the contact's rigid link.
    #[inline(always)]
    pub fn velocity_at(&self, p: [F; 2]) -> [F; 2] {
        let r = [p[0] - self.origin[0], p[1] - self.origin[1]];
        [self.v[0] - self.omega * r[1], self.v[1] + self.omega * r[0]]
    }
}

/// A contact's shape, for the terms that integrate over its boundary (`outline.rs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outline<F> {
    /// A round rod from T along the frame's axis: its diameter d_c and immersed length l.
    Rod {
        /// d_c [m].
        diameter: F,
        /// l [m].
        immersed: F,
    },
    /// A box (a sole): corners heel, toe, toe top, heel top [m], and its width out of
    /// the plane [m].
    Box {
        /// The four corners, world coordinates.
        corners: [[F; 2]; 4],
        /// w_s [m].
        width: F,
    },
    /// A thin circular arc cut into chords (`body::arc`): its centre, its first vertex,
    /// the turn from one vertex to the next about the centre, its chord count and its width
    /// out of the plane.
    Arc {
        /// The centre, world coordinates [m].
        centre: [F; 2],
        /// The first vertex, world coordinates [m].
        first: [F; 2],
        /// `(cos, sin)` of the world angle from one vertex to the next.
        turn: [F; 2],
        /// The number of chords.
        chords: usize,
        /// Width out of the plane [m].
        width: F,
    },
}

/// What a contact term returns: its force and, for a set-valued (Coulomb-like) term, the
/// bound of the reaction it can supply when the velocity component it opposes is held at
/// zero (sticking).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TermForce<F> {
    /// Force on the contact (x, y) [N].
    pub force: [F; 2],
    /// Largest reaction along x and y it supplies while sticking [N] (zero for a term that
    /// owns no slip switch).
    pub bound: [F; 2],
    /// Its moment about the point of application P, counter-clockwise [N m]: zero for a
    /// term that acts at P; a term that integrates over the contact's boundary (`rft`) or
    /// acts at T (`poncelet`) returns it.
    pub moment: F,
}

impl<F: Real> TermForce<F> {
    /// A force with no sticking bound and no moment.
    #[inline(always)]
    pub fn force(force: [F; 2]) -> Self {
        TermForce {
            force,
            bound: [F::splat(0.0); 2],
            moment: F::splat(0.0),
        }
    }
}

/// The discrete switches of the engine a term can own. The solver watches a switch only
/// while a listed term owns it ("modes" sign model), locates its crossing inside the step,
/// and holds the mode between crossings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Switch {
    /// The sign of e x v_E (a rod's drag reference area |e x v_E| has a kink at 0).
    Cross,
    /// The sign of v_Ex, with sticking in x (Karnopp) when both sides push back.
    SlipX,
    /// The sign of v_Ey, with sticking in y.
    SlipY,
}

impl Switch {
    /// The switch's name, as the docs write it.
    pub fn name(self) -> &'static str {
        match self {
            Switch::Cross => "sign of e x v_E",
            Switch::SlipX => "sign of v_Ex, sticking in x",
            Switch::SlipY => "sign of v_Ey, sticking in y",
        }
    }
}

/// Where a term acts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Acts {
    /// On each contact in the sand, at the scene's point of application.
    Contact,
    /// On the body through its mechanism (every link's weight, the joints).
    Body,
}

/// Which of the thesis's summary forces a contact term adds to: the dynamic force F_d
/// (eq. 3.23; its largest magnitude, `F_d_max`) or the static F_s (eq. 3.22; `F_s_end`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    /// Grows with speed (F_d).
    Dynamic,
    /// Depends on the velocity only through a sign (F_s).
    Static,
}

/// One parameter of a term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Param {
    /// Its name (`static_v.eta_v` in errors and calibration).
    pub name: &'static str,
    /// Unit ("-" for dimensionless).
    pub unit: &'static str,
    /// Default value.
    pub default: f64,
    /// Where the default comes from.
    pub source: &'static str,
    /// Smallest allowed value (inclusive); every value must also be finite.
    pub min: f64,
    /// What it is.
    pub description: &'static str,
    /// Whether it is a count (an integer >= `min`).
    pub integer: bool,
    /// Largest allowed value (inclusive; `f64::INFINITY`: no bound). A parameter that sizes
    /// the work of every force evaluation (an element count) has a finite one, so that no
    /// scene asks for unbounded work.
    pub max: f64,
}

impl Param {
    /// Whether the scene must give it (no default: `default` is NaN).
    pub fn required(&self) -> bool {
        self.default.is_nan()
    }
}

/// The shape of a contact, as a term's [`TermInfo::shapes`] names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactKind {
    /// A round rod (`body::rod`).
    Rod,
    /// A box: a sole, a plate (`body::sole`).
    Box,
    /// A thin circular arc (`body::arc`).
    Arc,
    /// A sphere in space (`space::shape`).
    Sphere,
    /// A capsule in space: a cylinder with hemispherical ends.
    Capsule,
    /// A cylinder in space, with flat ends.
    Cylinder,
    /// A cuboid (a box) in space.
    Cuboid,
    /// A closed triangle mesh in space.
    Mesh,
}

impl ContactKind {
    /// Its name (`granrs.bodies.Contact.shape`).
    pub const fn name(self) -> &'static str {
        match self {
            ContactKind::Rod => "rod",
            ContactKind::Box => "box",
            ContactKind::Arc => "arc",
            ContactKind::Sphere => "sphere",
            ContactKind::Capsule => "capsule",
            ContactKind::Cylinder => "cylinder",
            ContactKind::Cuboid => "cuboid",
            ContactKind::Mesh => "mesh",
        }
    }
}

/// Every planar contact shape (a term that reads nothing of the shape, or its boundary's
/// elements).
pub const EVERY_SHAPE: &[ContactKind] = &[ContactKind::Rod, ContactKind::Box, ContactKind::Arc];

/// The shapes with an immersed volume and area of their own (the thesis's law, Poncelet's).
pub const SOLID_SHAPES: &[ContactKind] = &[ContactKind::Rod, ContactKind::Box];

/// The shapes of a body in space (`crate::space`).
pub const SPACE_SHAPES: &[ContactKind] = &[
    ContactKind::Sphere,
    ContactKind::Capsule,
    ContactKind::Cylinder,
    ContactKind::Cuboid,
    ContactKind::Mesh,
];

/// The planar solids and every shape in space (Poncelet's law).
pub const SOLID_AND_SPACE_SHAPES: &[ContactKind] = &[
    ContactKind::Rod,
    ContactKind::Box,
    ContactKind::Sphere,
    ContactKind::Capsule,
    ContactKind::Cylinder,
    ContactKind::Cuboid,
    ContactKind::Mesh,
];

/// Every shape, planar and in space (`gravity`).
pub const ANY_SHAPE: &[ContactKind] = &[
    ContactKind::Rod,
    ContactKind::Box,
    ContactKind::Arc,
    ContactKind::Sphere,
    ContactKind::Capsule,
    ContactKind::Cylinder,
    ContactKind::Cuboid,
    ContactKind::Mesh,
];

/// Everything known about a term, for validation, docs, TOML and errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TermInfo {
    /// The name a scene lists (`granrs.forces.term(name)`, TOML `term = "name"`).
    pub name: &'static str,
    /// One line: what the term is.
    pub summary: &'static str,
    /// The term in granrs's frame, as plain text.
    pub equation: &'static str,
    /// Paper, thesis section and equation numbers.
    pub source: &'static str,
    /// Its parameters, in the order of [`Term::from_params`].
    pub params: &'static [Param],
    /// Where it acts.
    pub acts: Acts,
    /// For a contact term, which summary force it adds to.
    pub class: Class,
    /// Whether its magnitude grows with speed.
    pub velocity_dependent: bool,
    /// What it reads of the state.
    pub reads: &'static str,
    /// Whether it reads [`ContactState::area_speed`] (computed only when a listed term
    /// does: a sole's projected area is a polygon clip).
    pub reads_area_speed: bool,
    /// Whether it reads [`ContactState::boundary`] (filled only
    /// when a listed term does).
    pub reads_frame: bool,
    /// The contact shapes it is defined on. A contact term listed in a scene with a contact
    /// of another shape is refused before any work, naming the term and the contact (an arc,
    /// `body::arc`, takes the terms that read the boundary's chords, or none of the
    /// contact's shape).
    pub shapes: &'static [ContactKind],
    /// The switches it owns.
    pub switches: &'static [Switch],
    /// Its per-contact series columns (`c{i}.{column}` with `record=("forces",)`) and the
    /// force component each holds (0 = x, 1 = y). A term writes only the components its
    /// columns name: the others of its force are exactly zero (the engine relies on it).
    pub columns: &'static [(&'static str, usize)],
}

/// How stiff a term's force is at one contact: what the step-size check reads
/// (`Outcome::h_lambda`). With the body's inverse effective mass `w` at the contact
/// [1/kg], `w damping` is the fastest decay rate the term gives a fixed step (RK4 is stable
/// below 2.785 on the negative real axis) and `sqrt(w spring)` its oscillation rate (2.83
/// on the imaginary axis).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Rates {
    /// The largest |dF/dv| [N s/m]: how fast the force grows with the contact's speed (a
    /// quadratic drag's 2 |F| / |v|) or turns with its direction (a rate-independent force
    /// of magnitude F that follows the velocity: F / |v|, unbounded as |v| -> 0).
    pub damping: f64,
    /// The largest |dF/dx| [N/m]: how fast the force grows with the contact's position
    /// (its depth).
    pub spring: f64,
}

impl Rates {
    /// No stiffness at the contact (a body term, a constant force).
    pub const NONE: Rates = Rates {
        damping: 0.0,
        spring: 0.0,
    };

    /// The sum of two terms' rates (their forces add, so do their derivatives' bounds).
    #[inline]
    pub fn plus(self, other: Rates) -> Rates {
        Rates {
            damping: self.damping + other.damping,
            spring: self.spring + other.spring,
        }
    }
}

/// A force term. Implemented by one struct per file; the registry lists them.
pub trait Term: Copy + Debug + PartialEq {
    /// The term's description.
    const INFO: TermInfo;
    /// The term from its parameter values, in the order of `INFO.params`, already checked.
    fn from_params(values: &[f64]) -> Self;
    /// Its parameter values, in the order of `INFO.params`.
    fn params(&self) -> Vec<f64>;
    /// The force on one contact in the sand (contact terms; body terms return zero).
    #[inline(always)]
    fn contact_force<F: Real>(&self, _c: &ContactState<F>, _m: &Medium<F>) -> TermForce<F> {
        TermForce::force([F::splat(0.0); 2])
    }
    /// [`Term::contact_force`] with the term's parameters as numbers of type `F`, in the
    /// order of `INFO.params` (`p`: one scene's, or one per SIMD lane in the sweep's lanes,
    /// `dynamics::rod_lanes`, whose scenes differ in their numbers); a count
    /// ([`Param::integer`]) is `self`'s, shared by the lanes. The term's one copy of its
    /// arithmetic: `contact_force` is this with its own numbers. No default, as for
    /// [`Term::rates`]: a contact term that left it out would be blind in the lanes (a
    /// body term has no contact force: zero).
    fn force_with<F: Real>(&self, p: &[F], c: &ContactState<F>, m: &Medium<F>) -> TermForce<F>;
    /// Its stiffness at one contact in the sand (`c` as [`Term::contact_force`] reads it),
    /// for the step-size check. No default: each term says how its force changes with the
    /// contact's velocity and position, or why it does not ([`Rates::NONE`]), so that a new
    /// term cannot leave the check blind to it.
    fn rates(&self, c: &ContactState<f64>, m: &Medium<f64>) -> Rates;

    // What a body term ([`Acts::Body`]) does to the body as a whole; a contact term does
    // none of it (the defaults).

    /// The uniform field this term puts on every mass, as a multiple of the medium's g,
    /// pointing down (gravity: 1). The mechanism turns the scene's field into generalized
    /// forces, joint loads and the potential energy `m g y`.
    #[inline(always)]
    fn field(&self) -> f64 {
        0.0
    }
    /// Add the torques this term puts at the joints to the generalized forces `out` and to
    /// `torques` (by child link); return the power it dissipates [W].
    #[inline(always)]
    fn add_joint_torques<const N: usize>(
        &self,
        _body: &Mechanism<N>,
        _q: &SVector<f64, N>,
        _qd: &SVector<f64, N>,
        _out: &mut SVector<f64, N>,
        _torques: &mut [f64; N],
    ) -> f64 {
        0.0
    }
    /// The energy this term stores in the joints at `q` [J] (potential energy).
    fn joint_energy<const N: usize>(&self, _body: &Mechanism<N>, _q: &SVector<f64, N>) -> f64 {
        0.0
    }
    /// The stiffness [N m/rad] and damping [N m s/rad] this term puts on `link`'s joint, for
    /// the step-size check (`None`: none).
    fn joint_rates(&self, _link: &Link) -> Option<(f64, f64)> {
        None
    }
}
