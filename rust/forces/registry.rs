//! The registry of force terms, and a scene's [`ForceSet`].
//!
//! One line per term in [`registry!`]: the macro builds [`AnyTerm`] (an enum, so that the
//! hot path dispatches with a `match`, not a virtual call) and [`TERMS`], every term's
//! [`TermInfo`] in the order the docs list them.

use super::{
    axial_drag, drag, gravity, joint_springs, poncelet, rft, rft3d, static_h, static_v, Acts,
    Class, ContactState, Medium, Rates, Real, Switch, Term, TermForce, TermInfo,
};
use crate::body::{Link, Mechanism};
use crate::error::{suggest, GranrsError, Result};
use nalgebra::SVector;

/// Most contact terms a scene may list: every contact term of the registry (each at most
/// once). The per-term forces of an evaluation are a fixed-size array of this length (an
/// evaluation allocates nothing).
pub const MAX_TERMS: usize = contact_terms(ALL_TERMS);

/// Most body terms a scene may list: every body term of the registry (each at most once).
pub const MAX_BODY_TERMS: usize = ALL_TERMS.len() - MAX_TERMS;

/// Most parameter values the contact terms of one free link list together (each term at
/// most once, every contact term defined on a rod): the length of the lanes' numbers
/// (`dynamics::rod_lanes::RodParams::numbers`).
pub const LANE_NUMBERS: usize = rod_numbers(ALL_TERMS);

/// The sum of the parameter counts of `terms`' contact terms defined on a rod.
const fn rod_numbers(terms: &[&TermInfo]) -> usize {
    let (mut n, mut i) = (0, 0);
    while i < terms.len() {
        let t = terms[i];
        let mut j = 0;
        while j < t.shapes.len() {
            if matches!(t.acts, Acts::Contact) && matches!(t.shapes[j], super::ContactKind::Rod) {
                n += t.params.len();
                break;
            }
            j += 1;
        }
        i += 1;
    }
    n
}

/// How many of `terms` act at a contact.
const fn contact_terms(terms: &[&TermInfo]) -> usize {
    let (mut n, mut i) = (0, 0);
    while i < terms.len() {
        if matches!(terms[i].acts, Acts::Contact) {
            n += 1;
        }
        i += 1;
    }
    n
}

macro_rules! registry {
    ($($(#[$m:meta])* $variant:ident($ty:ty),)*) => {
        /// Any registered term, with its parameters for one contact.
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum AnyTerm {
            $($(#[$m])* #[doc = concat!("[`", stringify!($ty), "`]")] $variant($ty),)*
        }

        /// Every registered term's description.
        pub static TERMS: &[&TermInfo] = ALL_TERMS;

        /// [`TERMS`] as a constant (for [`MAX_TERMS`]).
        const ALL_TERMS: &[&TermInfo] = &[$($(#[$m])* &<$ty as Term>::INFO,)*];

        impl AnyTerm {
            /// The term's description.
            pub fn info(&self) -> &'static TermInfo {
                match self {
                    $($(#[$m])* AnyTerm::$variant(_) => &<$ty as Term>::INFO,)*
                }
            }

            /// Its parameter values, in the order of its `info().params`.
            pub fn params(&self) -> Vec<f64> {
                match self {
                    $($(#[$m])* AnyTerm::$variant(t) => t.params(),)*
                }
            }

            /// The term `name` from checked parameter values (`None`: no such term).
            pub(crate) fn from_name(name: &str, values: &[f64]) -> Option<AnyTerm> {
                $($(#[$m])* if name == <$ty as Term>::INFO.name {
                    return Some(AnyTerm::$variant(<$ty as Term>::from_params(values)));
                })*
                None
            }

            /// The force on one contact in the sand.
            #[inline(always)]
            pub fn contact_force<F: Real>(&self, c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
                match self {
                    $($(#[$m])* AnyTerm::$variant(t) => t.contact_force(c, m),)*
                }
            }

            /// The force on one contact with the parameters `p` ([`Term::force_with`]).
            #[inline(always)]
            pub fn force_with<F: Real>(&self, p: &[F], c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
                match self {
                    $($(#[$m])* AnyTerm::$variant(t) => t.force_with(p, c, m),)*
                }
            }

            /// Its stiffness at one contact in the sand ([`Term::rates`]).
            pub fn rates(&self, c: &ContactState<f64>, m: &Medium<f64>) -> Rates {
                match self {
                    $($(#[$m])* AnyTerm::$variant(t) => t.rates(c, m),)*
                }
            }

            /// The field it puts on every mass, in units of the medium's g ([`Term::field`]).
            pub fn field(&self) -> f64 {
                match self {
                    $($(#[$m])* AnyTerm::$variant(t) => t.field(),)*
                }
            }

            /// Its torques at the joints ([`Term::add_joint_torques`]); the power it
            /// dissipates [W].
            #[inline(always)]
            pub fn add_joint_torques<const N: usize>(
                &self,
                body: &Mechanism<N>,
                q: &SVector<f64, N>,
                qd: &SVector<f64, N>,
                out: &mut SVector<f64, N>,
                torques: &mut [f64; N],
            ) -> f64 {
                match self {
                    $($(#[$m])* AnyTerm::$variant(t) => t.add_joint_torques(body, q, qd, out, torques),)*
                }
            }

            /// The energy it stores in the joints ([`Term::joint_energy`]) [J].
            pub fn joint_energy<const N: usize>(&self, body: &Mechanism<N>, q: &SVector<f64, N>) -> f64 {
                match self {
                    $($(#[$m])* AnyTerm::$variant(t) => t.joint_energy(body, q),)*
                }
            }

            /// Its stiffness and damping at `link`'s joint ([`Term::joint_rates`]).
            pub fn joint_rates(&self, link: &Link) -> Option<(f64, f64)> {
                match self {
                    $($(#[$m])* AnyTerm::$variant(t) => t.joint_rates(link),)*
                }
            }

            /// [`AnyTerm::contact_force`] of a term that does not read the contact's
            /// boundary; zero for one that does (`TermInfo::reads_frame`, known at compile
            /// time). The loop of a scene whose terms read no boundary dispatches here: its
            /// arms are all inlined arithmetic, with no call that would make the loop keep
            /// its values in memory (measured: 7 % of a free-link run).
            #[inline(always)]
            pub fn contact_force_local<F: Real>(
                &self,
                c: &ContactState<F>,
                m: &Medium<F>,
            ) -> TermForce<F> {
                match self {
                    $($(#[$m])* AnyTerm::$variant(t) => {
                        if <$ty as Term>::INFO.reads_frame {
                            TermForce::force([F::splat(0.0); 2])
                        } else {
                            t.contact_force(c, m)
                        }
                    })*
                }
            }
        }
    };
}

registry! {
    Gravity(gravity::Gravity),
    Drag(drag::Drag),
    StaticH(static_h::StaticH),
    StaticV(static_v::StaticV),
    JointSprings(joint_springs::JointSprings),
    Poncelet(poncelet::Poncelet),
    AxialDrag(axial_drag::AxialDrag),
    Rft(rft::Rft),
    RftInertial(rft::RftInertial),
    Rft3d(rft3d::Rft3d),
    Rft3dInertial(rft3d::Rft3dInertial),
    // The worked example of docs/forces.md, a fixture of the crate's own tests.
    #[cfg(test)]
    Constant(super::constant::Constant),
    // The worked example of a body term, a fixture of the crate's own tests.
    #[cfg(test)]
    Lift(super::lift::Lift),
}

/// The description of the term `name`, or a typed error naming it (with a near miss).
pub fn info_of(name: &str) -> Result<&'static TermInfo> {
    TERMS
        .iter()
        .copied()
        .find(|t| t.name == name)
        .ok_or_else(|| unknown_term(name))
}

#[cold]
#[inline(never)]
fn unknown_term(name: &str) -> GranrsError {
    let names: Vec<&str> = TERMS.iter().map(|t| t.name).collect();
    let hint = suggest(name, names.iter().copied())
        .map(|s| format!("; did you mean `{s}`?"))
        .unwrap_or_default();
    GranrsError::UnknownName {
        field: "term".into(),
        value: name.into(),
        allowed: format!("{}{hint}", names.join(", ")),
    }
}

/// A row of the thesis's coefficient tables (Tables 3.4, 4.4, sec. 5.3.2): the parameters
/// of its law's three contact terms, for [`ForceSet::thesis`]. Not a scene field: a scene
/// holds its terms, each with its own parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// `static_h.eta_h` [-].
    pub eta_h: f64,
    /// `drag.eta_d` [-].
    pub eta_d: f64,
    /// `static_v.eta_v` [-].
    pub eta_v: f64,
    /// `static_v.lam` [-].
    pub lambda: f64,
}

impl Coefficients {
    /// Table 3.4 of the thesis at q = 0 (the vertical rod): the terms' defaults.
    pub const TABLE_3_4_VERTICAL: Coefficients = Coefficients {
        eta_h: 6.5,
        eta_d: 15.2,
        eta_v: 248.0,
        lambda: 0.106,
    };

    /// (eta_h, eta_d, eta_v, lambda).
    pub fn as_array(&self) -> [f64; 4] {
        [self.eta_h, self.eta_d, self.eta_v, self.lambda]
    }
}

/// One term as a scene lists it: its name and its parameters, each one value for every
/// contact or one per contact.
#[derive(Debug, Clone, PartialEq)]
pub struct TermSpec {
    /// The term's name.
    pub name: String,
    /// Its parameters by name; a missing one takes its default.
    pub params: Vec<(String, Vec<f64>)>,
}

impl TermSpec {
    /// The term `name` with `params` given once for every contact.
    pub fn new(name: &str, params: &[(&str, f64)]) -> Self {
        TermSpec {
            name: name.into(),
            params: params
                .iter()
                .map(|(k, v)| ((*k).to_string(), vec![*v]))
                .collect(),
        }
    }

    /// Check the term and its parameters for a body with `n_contacts` contacts, and give the
    /// values per contact (`[contact][param]`, in the order of the term's `params`).
    pub fn resolve(&self, n_contacts: usize) -> Result<(&'static TermInfo, Vec<Vec<f64>>)> {
        let info = info_of(&self.name)?;
        for (k, _) in &self.params {
            if !info.params.iter().any(|p| p.name == k) {
                return Err(unknown_param(info, k));
            }
        }
        let mut per_contact = vec![Vec::with_capacity(info.params.len()); n_contacts.max(1)];
        for p in info.params {
            let field = || format!("{}.{}", info.name, p.name);
            let given = self
                .params
                .iter()
                .rev()
                .find(|(k, _)| k == p.name)
                .map(|(_, v)| v.as_slice());
            let values: Vec<f64> = match given {
                None if p.required() => {
                    return Err(GranrsError::InvalidScene {
                        field: field(),
                        message: format!(
                            "required: {} [{}] has no default ({})",
                            p.description, p.unit, p.source
                        ),
                    })
                }
                None => vec![p.default],
                Some(v) => v.to_vec(),
            };
            if values.len() != 1 && values.len() != n_contacts {
                return Err(GranrsError::InvalidScene {
                    field: field(),
                    message: format!(
                        "{} values given; one for every contact or one per contact ({n_contacts})",
                        values.len()
                    ),
                });
            }
            for &v in &values {
                // An infinite default (no bound: `rft3d.mu_surf`) may also be given.
                let finite = v.is_finite() || (v == f64::INFINITY && p.default == f64::INFINITY);
                if !(finite && v >= p.min && v <= p.max) || (p.integer && v.fract() != 0.0) {
                    let kind = if p.integer { "an integer" } else { "finite" };
                    let min = if p.min == f64::NEG_INFINITY {
                        String::new()
                    } else {
                        format!(", >= {}", p.min)
                    };
                    let max = if p.max == f64::INFINITY {
                        String::new()
                    } else {
                        format!(", <= {}", p.max)
                    };
                    return Err(GranrsError::InvalidParameter {
                        field: field(),
                        value: v,
                        allowed: format!("{kind}{min}{max} ({} [{}])", p.description, p.unit),
                    });
                }
            }
            for (ci, row) in per_contact.iter_mut().enumerate() {
                row.push(if values.len() == 1 {
                    values[0]
                } else {
                    values[ci]
                });
            }
        }
        Ok((info, per_contact))
    }
}

#[cold]
#[inline(never)]
fn unknown_param(info: &TermInfo, name: &str) -> GranrsError {
    let names: Vec<&str> = info.params.iter().map(|p| p.name).collect();
    let hint = suggest(name, names.iter().copied())
        .map(|s| format!("; did you mean `{}.{s}`?", info.name))
        .unwrap_or_default();
    GranrsError::UnknownParameter {
        field: format!("{}.{name}", info.name),
        allowed: if names.is_empty() {
            format!("{} takes no parameters", info.name)
        } else {
            format!("{} takes {}", info.name, names.join(", "))
        },
        hint,
    }
}

/// One contact's terms (or the body's, `C` = [`MAX_BODY_TERMS`]) in a fixed-size array (the
/// hot path loops over it without a heap indirection); it reads as a slice of its `len`
/// terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TermList<const C: usize = MAX_TERMS> {
    terms: [AnyTerm; C],
    len: usize,
}

impl<const C: usize> Default for TermList<C> {
    fn default() -> Self {
        TermList {
            terms: [AnyTerm::Gravity(gravity::Gravity); C],
            len: 0,
        }
    }
}

impl<const C: usize> TermList<C> {
    /// Append `term` (the caller checks the capacity `C`).
    pub fn push(&mut self, term: AnyTerm) {
        self.terms[self.len] = term;
        self.len += 1;
    }
}

impl<const C: usize> std::ops::Deref for TermList<C> {
    type Target = [AnyTerm];
    #[inline(always)]
    fn deref(&self) -> &[AnyTerm] {
        &self.terms[..self.len]
    }
}

impl<const C: usize> std::ops::DerefMut for TermList<C> {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [AnyTerm] {
        &mut self.terms[..self.len]
    }
}

/// The terms a scene lists, ready for the engine: which body terms act, and each contact
/// term with its parameters per contact, in the scene's order.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceSet {
    /// Every listed term's name, in the scene's order.
    pub names: Vec<&'static str>,
    /// The body terms ([`Acts::Body`]), in the scene's order.
    pub body: TermList<MAX_BODY_TERMS>,
    /// The field the body terms put on every mass, in units of the medium's g (the sum of
    /// their [`Term::field`]: 1 under `gravity`, 0 without it).
    pub field: f64,
    /// The contact terms per contact, in the scene's order: `per_contact[c][k]`.
    pub per_contact: Vec<TermList>,
    /// The contact terms' descriptions, in the same order.
    pub contact_info: Vec<&'static TermInfo>,
    /// Whether the k-th contact term adds to the dynamic force F_d (its class), by index.
    pub dynamic: [bool; MAX_TERMS],
    /// Whether some listed term owns each switch ([`Switch::Cross`], `SlipX`, `SlipY`).
    pub owns: [bool; 3],
    /// Whether a listed term reads A_r |v_E|.
    pub reads_area_speed: bool,
    /// Whether a listed term reads the contact's frame and outline.
    pub reads_frame: bool,
    /// Per axis, the one static term that writes that axis (by its columns) when it also
    /// owns the axis's slip switch: a sticking reaction then simply replaces its component
    /// and the static sum's (see `ContactForce::set_reaction`).
    pub sole_static_owner: [Option<usize>; 2],
}

impl ForceSet {
    /// Check `specs` for a body with `n_contacts` contacts. Every error names the term and
    /// parameter (`static_v.eta_v`), before any work starts.
    pub fn build(specs: &[TermSpec], n_contacts: usize) -> Result<ForceSet> {
        let mut set = ForceSet {
            names: Vec::with_capacity(specs.len()),
            body: TermList::default(),
            field: 0.0,
            per_contact: vec![TermList::default(); n_contacts],
            contact_info: Vec::new(),
            owns: [false; 3],
            dynamic: [false; MAX_TERMS],
            reads_area_speed: false,
            reads_frame: false,
            sole_static_owner: [None; 2],
        };
        for spec in specs {
            let (info, values) = spec.resolve(n_contacts)?;
            if set.names.contains(&info.name) {
                return Err(GranrsError::InvalidScene {
                    field: "forces".into(),
                    message: format!("`{}` is listed twice", info.name),
                });
            }
            set.names.push(info.name);
            match info.acts {
                Acts::Body => {
                    let term =
                        AnyTerm::from_name(info.name, &values[0]).expect("a registered term");
                    set.field += term.field();
                    set.body.push(term);
                }
                Acts::Contact => {
                    if set.contact_info.len() == MAX_TERMS {
                        return Err(GranrsError::InvalidScene {
                            field: "forces".into(),
                            message: format!("at most {MAX_TERMS} contact terms"),
                        });
                    }
                    set.dynamic[set.contact_info.len()] = info.class == Class::Dynamic;
                    set.contact_info.push(info);
                    for (ci, row) in set.per_contact.iter_mut().enumerate() {
                        let term =
                            AnyTerm::from_name(info.name, &values[ci]).expect("a registered term");
                        row.push(term);
                    }
                    for s in info.switches {
                        set.owns[*s as usize] = true;
                    }
                    set.reads_area_speed |= info.reads_area_speed;
                    set.reads_frame |= info.reads_frame;
                }
            }
        }
        for (axis, switch) in [(0, Switch::SlipX), (1, Switch::SlipY)] {
            let writers: Vec<usize> = (0..set.contact_info.len())
                .filter(|&k| {
                    let info = set.contact_info[k];
                    info.class == Class::Static && info.columns.iter().any(|&(_, a)| a == axis)
                })
                .collect();
            if let [k] = writers[..] {
                if set.contact_info[k].switches.contains(&switch) {
                    set.sole_static_owner[axis] = Some(k);
                }
            }
        }
        Ok(set)
    }

    /// Whether a listed term owns `switch`.
    #[inline(always)]
    pub fn owns(&self, switch: Switch) -> bool {
        self.owns[switch as usize]
    }

    /// Whether the k-th contact term adds to the dynamic force F_d.
    #[inline(always)]
    pub fn is_dynamic(&self, k: usize) -> bool {
        self.dynamic[k]
    }

    /// The listed terms as specs (per-contact values collapsed where all contacts agree).
    pub fn specs(&self) -> Vec<TermSpec> {
        let mut out = Vec::with_capacity(self.names.len());
        let mut k = 0;
        for &name in &self.names {
            let info = info_of(name).expect("a listed term");
            let mut params = Vec::new();
            if info.acts == Acts::Contact {
                for (pi, p) in info.params.iter().enumerate() {
                    let vals: Vec<f64> = self
                        .per_contact
                        .iter()
                        .map(|row| row[k].params()[pi])
                        .collect();
                    let same = vals.windows(2).all(|w| w[0] == w[1]);
                    let vals = if same { vals[..1].to_vec() } else { vals };
                    params.push((p.name.to_string(), vals));
                }
                k += 1;
            }
            out.push(TermSpec {
                name: name.into(),
                params,
            });
        }
        out
    }

    /// The thesis's law: gravity, drag, static_h, static_v and the joints' springs, with
    /// a row of the thesis's coefficient tables per contact.
    pub fn thesis(per_contact: &[Coefficients]) -> ForceSet {
        let col = |i: usize| {
            per_contact
                .iter()
                .map(|c| c.as_array()[i])
                .collect::<Vec<_>>()
        };
        let specs = [
            TermSpec::new("gravity", &[]),
            TermSpec {
                name: "drag".into(),
                params: vec![("eta_d".into(), col(1))],
            },
            TermSpec {
                name: "static_h".into(),
                params: vec![("eta_h".into(), col(0))],
            },
            TermSpec {
                name: "static_v".into(),
                params: vec![("eta_v".into(), col(2)), ("lam".into(), col(3))],
            },
            TermSpec::new("joint_springs", &[]),
        ];
        ForceSet::build(&specs, per_contact.len()).expect("the thesis's law")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_term_is_registered_once_with_its_own_name() {
        let mut names: Vec<&str> = TERMS.iter().map(|t| t.name).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), TERMS.len());
        for t in TERMS {
            let term = AnyTerm::from_name(
                t.name,
                &t.params.iter().map(|p| p.default).collect::<Vec<_>>(),
            );
            assert_eq!(term.map(|x| x.info().name), Some(t.name));
        }
    }

    /// A scene may list every registered term at once: [`MAX_TERMS`] is the count of the
    /// contact terms (it was a fixed 4 while six existed, and a scene listing more failed).
    #[test]
    fn every_term_may_be_listed_at_once() {
        let contact = TERMS.iter().filter(|t| t.acts == Acts::Contact).count();
        assert!(contact >= 6, "{contact}");
        assert_eq!(MAX_TERMS, contact);
        let specs: Vec<TermSpec> = TERMS
            .iter()
            .map(|t| TermSpec {
                name: t.name.into(),
                params: t
                    .params
                    .iter()
                    .map(|p| {
                        let value = if p.required() {
                            p.min.max(0.0) + 1.0
                        } else {
                            p.default
                        };
                        (p.name.to_string(), vec![value])
                    })
                    .collect(),
            })
            .collect();
        let set = ForceSet::build(&specs, 2).unwrap();
        assert_eq!(set.contact_info.len(), contact);
        assert_eq!(set.names.len(), TERMS.len());
    }

    #[test]
    fn unknown_terms_and_parameters_are_named_with_a_near_miss() {
        let err = ForceSet::build(&[TermSpec::new("stati_v", &[])], 1).unwrap_err();
        assert!(err.to_string().contains("did you mean `static_v`"), "{err}");
        let err = ForceSet::build(&[TermSpec::new("static_v", &[("eta", 1.0)])], 1).unwrap_err();
        assert!(
            matches!(&err, GranrsError::UnknownParameter { field, .. } if field == "static_v.eta")
        );
        assert!(
            err.to_string().contains("did you mean `static_v.eta_v`"),
            "{err}"
        );
        let err = ForceSet::build(&[TermSpec::new("drag", &[("eta_d", -1.0)])], 1).unwrap_err();
        assert!(
            matches!(&err, GranrsError::InvalidParameter { field, .. } if field == "drag.eta_d")
        );
        let err =
            ForceSet::build(&[TermSpec::new("static_v", &[("lam", f64::NAN)])], 1).unwrap_err();
        assert!(
            matches!(&err, GranrsError::InvalidParameter { field, .. } if field == "static_v.lam")
        );
    }

    #[test]
    fn a_sticking_reaction_replaces_the_one_static_term_of_its_axis() {
        let thesis = ForceSet::thesis(&[Coefficients::TABLE_3_4_VERTICAL]);
        // gravity is a body term: drag 0, static_h 1, static_v 2 among the contact terms.
        assert_eq!(thesis.sole_static_owner, [Some(1), Some(2)]);
        // A second static term writing x (the test fixture, both axes): shared.
        let shared = ForceSet::build(
            &[
                TermSpec::new("static_h", &[]),
                TermSpec::new("static_v", &[]),
                TermSpec::new("constant", &[("fx", 1.0)]),
            ],
            1,
        )
        .unwrap();
        assert_eq!(shared.sole_static_owner, [None, None]);
    }

    #[test]
    fn parameters_per_contact_or_for_all() {
        let spec = TermSpec {
            name: "static_v".into(),
            params: vec![("eta_v".into(), vec![1.0, 2.0]), ("lam".into(), vec![0.5])],
        };
        let set = ForceSet::build(std::slice::from_ref(&spec), 2).unwrap();
        assert_eq!(set.per_contact[1][0].params(), vec![2.0, 0.5]);
        assert_eq!(set.specs()[0], spec);
        assert!(ForceSet::build(&[spec], 3).is_err());
    }
}
