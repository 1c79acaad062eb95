//! `rft`: planar resistive force theory, and `rft_inertial`, its rate-dependent term.
//!
//! ```text
//! dF = zeta |z| dA (-alpha_x(beta, gamma), alpha_z(beta, gamma))        (rft)
//! alpha_z = A00 + A10 cos 2b + B11 sin(2b + g) + B01 sin g + B-11 sin(-2b + g)
//! alpha_x = C11 cos(2b + g) + C01 cos g + C-11 cos(-2b + g) + D10 sin 2b
//! ```
//!
//! over every element of the contact's boundary below the surface (`outline.rs`), with `z`
//! the element's depth, `beta` its line's angle counter-clockwise from +x (mod pi) and
//! `gamma` its velocity's angle below +x (pi/2: straight down). A horizontal plate pushed
//! straight down has alpha = (0, 1): `zeta` [N/m^3] is its stress per unit depth. The force
//! and its moment come from the elements, so `rft` has no point of application.
//!
//! - **Source:** Li, Zhang & Goldman, "A terradynamics of legged locomotion on granular
//!   media", Science 339 (2013) 1408, eq. 1 and the generic coefficients (supplementary
//!   material, Table S2; `shared/LAWS.md`). Checked against the identities, not a code:
//!   alpha(0, pi/2) = (0, 1); alpha(-beta, pi - gamma) = (-alpha_x, alpha_z); pi-periodic
//!   in beta; F . v <= 0 for every (beta, gamma) (the tests).
//! - **Parameters:** `zeta` [N/m^3], required (the paper's values are 1e6 order, e.g.
//!   "1 N/cm^3 = 1e6 N/m^3"; see docs/laws.md); `elements` [-], elements per plate, default
//!   [`DEFAULT_ELEMENTS`]; the nine coefficients `A00 A10 B11 B01 Bm11 C11 C01 Cm11 D10`
//!   (`m1` for the paper's -1), default the paper's generic set.
//! - **Reads:** the contact's frame (T, v_T, omega, axis), its outline and the held signs
//!   (sticking only).
//! - **Switches:** the sign of v_Ey with sticking ([`Switch::SlipY`]), as `static_v`: RFT
//!   does not depend on speed, so at rest its force is set-valued. Moving, each element's
//!   direction is its own velocity's (continuous while it moves; through a step the mode's
//!   held sign of v_Ey holds the motion, `dynamics::held_shift`). Along an axis held at zero
//!   (y by its own stick, x by another term's), the force is a bounded reaction: up to the
//!   sand's resistance to sinking straight down (y) and the smaller of its resistances to
//!   sliding either way (x). It owns no switch in x: while the contact moves, an RFT force
//!   is continuous where v_Ex passes zero, and a switch there only made events chatter.
//! - **Series:** `F_rft_x`, `F_rft_y`.
//!
//! `rft_inertial`:
//!
//! ```text
//! dF = -lam rho_g |v_n| v_n n dA,   v_n = v . n   (n: the element's normal)
//! ```
//!
//! on each immersed element, whose leading face (the one moving into the sand) meets sand
//! that must be brought to the element's normal speed: the momentum flux rho_g v_n^2 per
//! unit area, scaled by `lam`. After Agarwal, Karsai, Goldman & Kamrin, "Surprising
//! simplicity in the modeling of dynamic granular intrusion", Science Advances 7 (2021)
//! eabe0631 (dynamic RFT: quasi-static RFT plus a rate-dependent term in rho_g v_n^2 on the
//! leading surfaces). `lam` = 1 is the momentum-flux value; the paper's own coefficient
//! could not be checked here (see docs/laws.md). It is zero at rest, so it owns no switch.

use super::outline::Plate;
use super::{
    Acts, Boundary, Class, ContactState, Medium, Param, Real, Switch, Term, TermForce, TermInfo,
};

/// Elements per plate unless the scene says otherwise (the convergence in docs/laws.md:
/// second order in the element count on an oblique drop).
pub const DEFAULT_ELEMENTS: usize = 8;

/// The paper's generic coefficients, in the order A00 A10 B11 B01 B-11 C11 C01 C-11 D10
/// (Li, Zhang & Goldman 2013, supplementary Table S2; `shared/LAWS.md`).
pub const GENERIC: [f64; 9] = [
    0.206, 0.169, 0.212, 0.358, 0.055, -0.124, 0.253, 0.007, 0.088,
];

/// The nine coefficients' parameter names.
pub const COEFFICIENT_NAMES: [&str; 9] = [
    "A00", "A10", "B11", "B01", "Bm11", "C11", "C01", "Cm11", "D10",
];

const SOURCE_GENERIC: &str = "Li, Zhang & Goldman 2013, generic coefficients";

macro_rules! coefficient {
    ($i:expr, $what:expr) => {
        Param {
            name: COEFFICIENT_NAMES[$i],
            unit: "-",
            default: GENERIC[$i],
            source: SOURCE_GENERIC,
            min: f64::NEG_INFINITY,
            description: $what,
            integer: false,
        }
    };
}

/// The element count parameter.
const ELEMENTS: Param = Param {
    name: "elements",
    unit: "-",
    default: DEFAULT_ELEMENTS as f64,
    source: "granrs (convergence study, docs/laws.md)",
    min: 1.0,
    description: "elements per boundary plate",
    integer: true,
};

/// alpha = (alpha_x, alpha_z) for the line angle's `(cos 2 beta, sin 2 beta)` and the
/// velocity angle's `(cos gamma, sin gamma)`, with the coefficients `k` (order of
/// [`GENERIC`]). No trigonometric call: the angles enter through their sines and cosines.
#[inline(always)]
pub fn alpha<F: Real>(k: &[f64; 9], c2: F, s2: F, cg: F, sg: F) -> (F, F) {
    let p = |i: usize| F::splat(k[i]);
    // sin(2b + g), sin(-2b + g), cos(2b + g), cos(-2b + g).
    let sin_pg = s2 * cg + c2 * sg;
    let sin_mg = c2 * sg - s2 * cg;
    let cos_pg = c2 * cg - s2 * sg;
    let cos_mg = c2 * cg + s2 * sg;
    let az = p(0) + p(1) * c2 + p(2) * sin_pg + p(3) * sg + p(4) * sin_mg;
    let ax = p(5) * cos_pg + p(6) * cg + p(7) * cos_mg + p(8) * s2;
    (ax, az)
}

/// alpha at the angles `beta` and `gamma` [rad] (`granrs.forces.rft_alpha`).
pub fn alpha_at(k: &[f64; 9], beta: f64, gamma: f64) -> (f64, f64) {
    let (s2, c2) = (2.0 * beta).sin_cos();
    let (sg, cg) = gamma.sin_cos();
    alpha(k, c2, s2, cg, sg)
}

/// `(cos 2 beta, sin 2 beta)` of a plate's line, or zeros for a plate of no length.
#[inline(always)]
fn line_angle<F: Real>(p: &Plate<F>) -> (F, F) {
    let len = p.length();
    let inv = len.select_pos(len.recip(), F::splat(0.0));
    let u = [(p.b[0] - p.a[0]) * inv, (p.b[1] - p.a[1]) * inv];
    (u[0] * u[0] - u[1] * u[1], F::splat(2.0) * u[0] * u[1])
}

/// The 2-D cross product `a x b`.
#[inline(always)]
fn cross<F: Real>(a: [F; 2], b: [F; 2]) -> F {
    a[0] * b[1] - a[1] * b[0]
}

/// Planar resistive force theory on a contact's boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rft {
    /// zeta [N/m^3].
    pub zeta: f64,
    /// Elements per plate.
    pub elements: usize,
    /// The nine coefficients, in the order of [`GENERIC`].
    pub coefficients: [f64; 9],
}

impl Rft {
    /// The force on the contact's immersed boundary and its moment about P, every element
    /// moving along its own velocity, or all along `dir` (a unit vector) when given.
    #[inline(always)]
    fn integrate<F: Real>(&self, b: &Boundary<F>, dir: Option<[F; 2]>) -> ([F; 2], F) {
        let zero = F::splat(0.0);
        let one = F::splat(1.0);
        let zeta = F::splat(self.zeta);
        let (plates, np) = b.outline.plates(&b.frame);
        let mut f = [zero; 2];
        let mut moment = zero;
        let twelfth = F::splat(1.0 / 12.0);
        for p in &plates[..np] {
            let (c2, s2) = line_angle(p);
            let el = p.elements(self.elements);
            // Each element's load zeta w L |z_mid| (exact: the depth is linear along it).
            let load = zeta * el.width * el.length;
            // Its moment about its middle, for the depth's slope along it: zeta w (u x f)
            // int (s - s_mid) |z| ds = zeta w (u x f) L^2 dz / 12 = zeta w (step x f) L dz
            // / 12, with dz = -step_y the depth's change over one element.
            let lever = -el.step[1] * el.length * twelfth;
            for k in 0..self.elements {
                let at = el.mid(k);
                let v = dir.unwrap_or_else(|| b.frame.velocity_at(at));
                let s = (v[0] * v[0] + v[1] * v[1]).sqrt();
                // An element at rest has no direction: no force (the sticking reaction
                // stands in where the whole contact is at rest).
                let inv = s.select_pos(s.recip(), zero);
                let (ax, az) = alpha(&self.coefficients, c2, s2, v[0] * inv, -v[1] * inv);
                let w = load * (-at[1]) * s.select_pos(one, zero);
                let df = [-ax * w, az * w];
                f[0] = f[0] + df[0];
                f[1] = f[1] + df[1];
                let slope = zeta * el.width * lever * s.select_pos(one, zero);
                moment = moment
                    + cross([at[0] - b.apply[0], at[1] - b.apply[1]], df)
                    + slope * cross(el.step, [-ax, az]);
            }
        }
        (f, moment)
    }
}

impl Term for Rft {
    const INFO: TermInfo = TermInfo {
        name: "rft",
        summary: "planar resistive force theory over the contact's boundary elements",
        equation: "dF = zeta |z| dA (-alpha_x(beta, gamma), alpha_z(beta, gamma)), summed over \
                   the immersed elements",
        source: "Li, Zhang & Goldman, Science 339 (2013) 1408, eq. 1 and Table S2",
        params: &[
            Param {
                name: "zeta",
                unit: "N/m^3",
                default: f64::NAN,
                source: "none: a property of the medium (Li et al. 2013 measured ~1e6 for \
                         their media)",
                min: 0.0,
                description: "alpha_z of a horizontal plate pushed straight down, per unit depth",
                integer: false,
            },
            ELEMENTS,
            coefficient!(0, "Fourier coefficient A00 of alpha_z"),
            coefficient!(1, "Fourier coefficient A10 of alpha_z"),
            coefficient!(2, "Fourier coefficient B11 of alpha_z"),
            coefficient!(3, "Fourier coefficient B01 of alpha_z"),
            coefficient!(4, "Fourier coefficient B-11 of alpha_z"),
            coefficient!(5, "Fourier coefficient C11 of alpha_x"),
            coefficient!(6, "Fourier coefficient C01 of alpha_x"),
            coefficient!(7, "Fourier coefficient C-11 of alpha_x"),
            coefficient!(8, "Fourier coefficient D10 of alpha_x"),
        ],
        acts: Acts::Contact,
        class: Class::Static,
        velocity_dependent: false,
        reads: "the contact's boundary plates (frame and outline), each element's depth and \
                velocity; the held signs of v_E (sticking)",
        reads_area_speed: false,
        reads_frame: true,
        switches: &[Switch::SlipY],
        columns: &[("F_rft_x", 0), ("F_rft_y", 1)],
    };

    fn from_params(values: &[f64]) -> Self {
        let mut coefficients = [0.0; 9];
        coefficients.copy_from_slice(&values[2..11]);
        Rft {
            zeta: values[0],
            elements: values[1] as usize,
            coefficients,
        }
    }

    fn params(&self) -> Vec<f64> {
        let mut v = vec![self.zeta, self.elements as f64];
        v.extend_from_slice(&self.coefficients);
        v
    }

    #[inline(never)]
    fn contact_force<F: Real>(&self, c: &ContactState<F>, _m: &Medium<F>) -> TermForce<F> {
        let zero = F::splat(0.0);
        let Some(b) = c.boundary else {
            return TermForce::force([zero; 2]);
        };
        let (mut force, mut moment) = self.integrate(b, None);
        let mut bound = [zero; 2];
        let [held_x, held_y] = b.held;
        if !(held_x + held_y).all_zero() {
            // Held at zero along an axis: the reaction stands in for that component, up to
            // the sand's resistance to sinking straight down (y) and the smaller of its
            // resistances to sliding either way (x). Rotation is not held: the moment stays
            // the moving elements' while one axis moves, and is zero at rest.
            let one = F::splat(1.0);
            if !held_y.all_zero() {
                let (down, _) = self.integrate(b, Some([zero, -one]));
                bound[1] = held_y * down[1].max(zero);
                force[1] = (one - held_y) * force[1];
            }
            if !held_x.all_zero() {
                let (right, _) = self.integrate(b, Some([one, zero]));
                let (left, _) = self.integrate(b, Some([-one, zero]));
                bound[0] = held_x * (-right[0]).max(zero).min(left[0].max(zero));
                force[0] = (one - held_x) * force[0];
            }
            moment = (one - held_x * held_y) * moment;
        }
        TermForce {
            force,
            bound,
            moment,
        }
    }
}

/// The rate-dependent term of dynamic RFT.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RftInertial {
    /// Scale of the momentum flux lam [-].
    pub lam: f64,
    /// Elements per plate.
    pub elements: usize,
}

impl Term for RftInertial {
    const INFO: TermInfo = TermInfo {
        name: "rft_inertial",
        summary: "the inertial term of dynamic RFT: momentum flux on the leading elements",
        equation: "dF = -lam rho_g |v_n| v_n n dA,  v_n = v . n, summed over the immersed elements",
        source: "Agarwal, Karsai, Goldman & Kamrin, Science Advances 7 (2021) eabe0631 \
                 (dynamic RFT)",
        params: &[
            Param {
                name: "lam",
                unit: "-",
                default: 1.0,
                source: "the momentum-flux value (sand brought to the element's normal speed)",
                min: 0.0,
                description: "scale of the momentum flux rho_g v_n^2",
                integer: false,
            },
            ELEMENTS,
        ],
        acts: Acts::Contact,
        class: Class::Dynamic,
        velocity_dependent: true,
        reads: "rho_g; the contact's boundary plates (frame and outline), each element's \
                velocity normal to it",
        reads_area_speed: false,
        reads_frame: true,
        switches: &[],
        columns: &[("F_ri_x", 0), ("F_ri_y", 1)],
    };

    fn from_params(values: &[f64]) -> Self {
        RftInertial {
            lam: values[0],
            elements: values[1] as usize,
        }
    }

    fn params(&self) -> Vec<f64> {
        vec![self.lam, self.elements as f64]
    }

    #[inline(never)]
    fn contact_force<F: Real>(&self, c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        let zero = F::splat(0.0);
        let Some(b) = c.boundary else {
            return TermForce::force([zero; 2]);
        };
        let k = -(F::splat(self.lam) * m.rho_g);
        let (plates, np) = b.outline.plates(&b.frame);
        let mut f = [zero; 2];
        let mut moment = zero;
        for p in &plates[..np] {
            let len = p.length();
            let inv = len.select_pos(len.recip(), zero);
            // The plate's normal (-u_y, u_x); either face leads, by the sign of v_n.
            let n = [-(p.b[1] - p.a[1]) * inv, (p.b[0] - p.a[0]) * inv];
            let el = p.elements(self.elements);
            let area = el.length * el.width;
            for e in 0..self.elements {
                let at = el.mid(e);
                let v = b.frame.velocity_at(at);
                let vn = v[0] * n[0] + v[1] * n[1];
                let w = k * vn.abs() * vn * area;
                let df = [w * n[0], w * n[1]];
                f[0] = f[0] + df[0];
                f[1] = f[1] + df[1];
                moment = moment + cross([at[0] - b.apply[0], at[1] - b.apply[1]], df);
            }
        }
        TermForce {
            force: f,
            bound: [zero; 2],
            moment,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forces::{Frame, Outline};
    use std::f64::consts::{FRAC_PI_2, PI};

    #[test]
    fn alpha_is_normalised_mirrored_periodic_and_dissipative() {
        let (ax, az) = alpha_at(&GENERIC, 0.0, FRAC_PI_2);
        assert!(ax.abs() < 1e-12 && (az - 1.0).abs() < 1e-12, "{ax} {az}");
        for i in 0..=36 {
            for j in 0..=72 {
                let beta = -PI + i as f64 * PI / 18.0;
                let gamma = -PI + j as f64 * PI / 36.0;
                let (ax, az) = alpha_at(&GENERIC, beta, gamma);
                let (mx, mz) = alpha_at(&GENERIC, -beta, PI - gamma);
                assert!((mx + ax).abs() < 1e-12 && (mz - az).abs() < 1e-12);
                let (px, pz) = alpha_at(&GENERIC, beta + PI, gamma);
                assert!((px - ax).abs() < 1e-12 && (pz - az).abs() < 1e-12);
                // F = (-ax, az) against v = (cos g, -sin g).
                assert!(
                    -ax * gamma.cos() - az * gamma.sin() <= 1e-12,
                    "{beta} {gamma}"
                );
            }
        }
    }

    #[test]
    fn a_vertical_rod_sinking_feels_the_plates_stresses() {
        let (d, d_c, zeta) = (0.03, 0.0127, 1e6);
        let b = Boundary {
            frame: Frame {
                origin: [0.0, -d],
                v: [0.0, -1.0],
                omega: 0.0,
                axis: [0.0, 1.0],
            },
            outline: Outline::Rod {
                diameter: d_c,
                immersed: d,
            },
            apply: [0.0, -d],
            centroid: [0.0, -0.5 * d],
            v_centroid: [0.0, -1.0],
            held: [0.0; 2],
        };
        let state = ContactState {
            depth: d,
            volume: 0.0,
            width: d_c,
            l_ref: 0.19,
            v: [0.0, -1.0],
            area_speed: 0.0,
            sign: [0.0, -1.0],
            boundary: Some(&b),
        };
        // The shaft (beta = pi/2), the tip plate (beta = 0), both moving straight down.
        let shaft = GENERIC[0] - GENERIC[1] - GENERIC[2] + GENERIC[3] - GENERIC[4];
        let expected = zeta * d_c * (shaft * d * d / 2.0 + d_c * d);
        for n in [1, 3, 8] {
            let t = Rft {
                zeta,
                elements: n,
                coefficients: GENERIC,
            };
            let f = t.contact_force(&state, &crate::forces::Medium::default());
            assert!(
                (f.force[1] - expected).abs() < 1e-12 * expected,
                "{n}: {f:?}"
            );
            assert!(f.force[0].abs() < 1e-12 * expected && f.moment.abs() < 1e-12);
        }
    }
}
