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
//!   material, Table S2; `docs/laws.md`). Checked against the identities, not a code:
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
#[cfg(target_arch = "x86_64")]
mod lone_rod;

use super::{
    Acts, Boundary, Class, ContactState, Medium, Outline, Param, Rates, Real, Switch, Term,
    TermForce, TermInfo,
};

/// Elements per plate unless the scene says otherwise (the convergence in docs/laws.md:
/// second order in the element count on an oblique drop).
pub const DEFAULT_ELEMENTS: usize = 8;

/// The most elements per plate a scene may ask for (the `elements` parameter's bound):
/// twice the 512 of the docs' convergence reference. The work of every force evaluation
/// grows with it (a whole impact takes about 4 us per element and plate), so an unbounded
/// count would be unbounded work.
pub const MAX_ELEMENTS: usize = 1024;

/// The paper's generic coefficients, in the order A00 A10 B11 B01 B-11 C11 C01 C-11 D10
/// (Li, Zhang & Goldman 2013, supplementary Table S2; `docs/laws.md`).
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
            max: f64::INFINITY,
        }
    };
}

/// The element count parameter.
/// The inertial terms' scale of the momentum flux (`rft_inertial`, and `rft3d_inertial` on
/// a body in space).
pub const LAM: Param = Param {
    name: "lam",
    unit: "-",
    default: 1.0,
    source: "the momentum-flux value (sand brought to the element's normal speed)",
    min: 0.0,
    description: "scale of the momentum flux rho_g v_n^2",
    integer: false,
    max: f64::INFINITY,
};

const ELEMENTS: Param = Param {
    name: "elements",
    unit: "-",
    default: DEFAULT_ELEMENTS as f64,
    source: "granrs (convergence study, docs/laws.md)",
    min: 1.0,
    description: "elements per boundary plate",
    integer: true,
    max: MAX_ELEMENTS as f64,
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
    let u = p.u;
    (u[0] * u[0] - u[1] * u[1], F::splat(2.0) * u[0] * u[1])
}

/// The 2-D cross product `a x b`.
#[inline(always)]
fn cross<F: Real>(a: [F; 2], b: [F; 2]) -> F {
    a[0] * b[1] - a[1] * b[0]
}

/// `rft`'s numbers in `F` (one value per lane in the SIMD lanes, where the scenes' laws
/// share only their element count): `zeta` and the nine coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RftCoefficients<F> {
    /// zeta [N/m^3].
    pub zeta: F,
    /// The nine coefficients, in the order of [`GENERIC`].
    pub k: [F; 9],
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

/// alpha as an affine map of the velocity's direction for one plate: with `(cos 2 beta,
/// sin 2 beta)` fixed, [`alpha`] is affine in `(cos gamma, sin gamma) = (v_x, -v_y) / |v|`,
/// so the force direction `(-alpha_x, alpha_z)` is `g0 + (v_x gx + v_y gy) / |v|`. Returns
/// `(g0, gx, gy)` (the same nine-term series, gathered once per plate).
#[inline(always)]
fn alpha_affine<F: Real>(k: &[F; 9], c2: F, s2: F) -> ([F; 2], [F; 2], [F; 2]) {
    let p = |i: usize| k[i];
    // alpha_z = z0 + zc cos g + zs sin g; alpha_x = x0 + xc cos g + xs sin g (expand the
    // sums of angles in [`alpha`]).
    let z0 = p(0) + p(1) * c2;
    let zc = (p(2) - p(4)) * s2;
    let zs = (p(2) + p(4)) * c2 + p(3);
    let x0 = p(8) * s2;
    let xc = (p(5) + p(7)) * c2 + p(6);
    let xs = (p(7) - p(5)) * s2;
    // (-alpha_x, alpha_z) with cos g = v_x / |v|, sin g = -v_y / |v|.
    ([-x0, z0], [-xc, zc], [xs, -zs])
}

/// One plate's element sums (`Rft::integrate`): the element at `t = k + 1/2` from the
/// immersed part's start has depth `d0 + t dd` and velocity `v0 + t dv`; `g` is
/// [`alpha_affine`]'s map; `sums` gathers `df`, `t df` and the moving elements' `(-alpha_x,
/// alpha_z)`.
struct PlateSums<F> {
    v0: [F; 2],
    dv: [F; 2],
    d0: F,
    dd: F,
    load: F,
    g: [[F; 2]; 3],
    sums: [[F; 2]; 3],
}

impl<F: Real> PlateSums<F> {
    /// Adds the `L` elements from `first`.
    #[inline(always)]
    fn add<const L: usize>(&mut self, first: usize) {
        let zero = F::splat(0.0);
        let one = F::splat(1.0);
        let t: [F; L] = std::array::from_fn(|j| F::splat((first + j) as f64 + 0.5));
        let v: [[F; 2]; L] = std::array::from_fn(|j| {
            [
                self.v0[0] + t[j] * self.dv[0],
                self.v0[1] + t[j] * self.dv[1],
            ]
        });
        // An element at rest has no direction: no force (the sticking reaction stands in
        // where the whole contact is at rest).
        let inv: [F; L] = std::array::from_fn(|j| {
            let s = (v[j][0] * v[j][0] + v[j][1] * v[j][1]).sqrt();
            s.select_pos(s.recip(), zero)
        });
        let [g0, gx, gy] = self.g;
        let [mut sf, mut st, mut sg] = self.sums;
        for j in 0..L {
            let moving = inv[j].select_pos(one, zero);
            let c = [v[j][0] * inv[j], v[j][1] * inv[j]];
            let g = [
                moving * g0[0] + c[0] * gx[0] + c[1] * gy[0],
                moving * g0[1] + c[0] * gx[1] + c[1] * gy[1],
            ];
            let w = self.load * (self.d0 + t[j] * self.dd);
            let df = [w * g[0], w * g[1]];
            sf = [sf[0] + df[0], sf[1] + df[1]];
            st = [st[0] + t[j] * df[0], st[1] + t[j] * df[1]];
            sg = [sg[0] + g[0], sg[1] + g[1]];
        }
        self.sums = [sf, st, sg];
    }
}

impl Rft {
    /// The force on the contact's immersed boundary and its moment about P, every element
    /// moving along its own velocity, or all along `dir` (a unit vector) when given.
    ///
    /// Along a plate the elements' middles, depths and velocities are affine in the element's
    /// position `t = k + 1/2` (a rigid link), and alpha is affine in the direction of motion,
    /// so the loop keeps only what differs per element (one square root and one division)
    /// and the moment comes from sums over the plate: `sum r_k x df_k = r_0 x sum df_k +
    /// step x sum t_k df_k`, with `r_0` the immersed part's start from P.
    #[inline(always)]
    fn integrate<F: Real>(
        &self,
        co: &RftCoefficients<F>,
        b: &Boundary<F>,
        dir: Option<[F; 2]>,
    ) -> ([F; 2], F) {
        if let Outline::Arc { .. } = b.outline {
            return self.integrate_chords(co, b, dir);
        }
        // A rod's or a box's plates: the plain loop over their array.
        let (plates, n) = b.outline.fixed_plates(&b.frame);
        let mut sum = ([F::splat(0.0); 2], F::splat(0.0));
        for p in &plates[..n] {
            self.add_plate::<F, 0>(co, p, b, dir, &mut sum);
        }
        sum
    }

    /// [`Rft::integrate`] over an arc's chords, kept out of the rod's and the box's path.
    #[inline(never)]
    fn integrate_chords<F: Real>(
        &self,
        co: &RftCoefficients<F>,
        b: &Boundary<F>,
        dir: Option<[F; 2]>,
    ) -> ([F; 2], F) {
        let mut sum = ([F::splat(0.0); 2], F::splat(0.0));
        b.outline.for_each_plate(&b.frame, |p| {
            self.add_plate::<F, 0>(co, p, b, dir, &mut sum)
        });
        sum
    }

    /// Add plate `p`'s force and moment about P to `sum` ([`Rft::integrate`]), at `N`
    /// elements (known when compiled), or `self.elements` where `N` is 0.
    #[inline(always)]
    fn add_plate<F: Real, const N: usize>(
        &self,
        co: &RftCoefficients<F>,
        p: &Plate<F>,
        b: &Boundary<F>,
        dir: Option<[F; 2]>,
        sum: &mut ([F; 2], F),
    ) {
        let zero = F::splat(0.0);
        let zeta = co.zeta;
        let twelfth = F::splat(1.0 / 12.0);
        let (c2, s2) = line_angle(p);
        let (g0, gx, gy) = alpha_affine(&co.k, c2, s2);
        let n = if N > 0 { N } else { self.elements };
        let el = p.elements(n);
        // Each element's load zeta w L |z_mid| (exact: the depth is linear along it).
        let load = zeta * el.width * el.length;
        // Its moment about its middle, for the depth's slope along it: zeta w (u x f)
        // int (s - s_mid) |z| ds = zeta w (u x f) L^2 dz / 12 = zeta w (step x f) L dz
        // / 12, with dz = -step_y the depth's change over one element.
        let slope = zeta * el.width * (-el.step[1] * el.length * twelfth);
        // At t = k + 1/2 from the start: depth d0 + t dd, velocity v0 + t dv.
        let d0 = -el.start[1];
        let dd = -el.step[1];
        let (v0, dv) = match dir {
            Some(u) => (u, [zero; 2]),
            None => {
                let w = b.frame.omega;
                (
                    b.frame.velocity_at(el.start),
                    [-w * el.step[1], w * el.step[0]],
                )
            }
        };
        let mut plate = PlateSums {
            v0,
            dv,
            d0,
            dd,
            load,
            g: [g0, gx, gy],
            sums: [[zero; 2]; 3],
        };
        // Elements in groups of 8 and 4 (independent square roots and divisions), the
        // rest one by one.
        let mut c = 0;
        while c + 8 <= n {
            plate.add::<8>(c);
            c += 8;
        }
        if c + 4 <= n {
            plate.add::<4>(c);
            c += 4;
        }
        for k in c..n {
            plate.add::<1>(k);
        }
        // df, t df and the moving elements' (-alpha_x, alpha_z), over the plate.
        let [sf, st, sg] = plate.sums;
        let (f, moment) = sum;
        *f = [f[0] + sf[0], f[1] + sf[1]];
        let r0 = [el.start[0] - b.apply[0], el.start[1] - b.apply[1]];
        *moment = *moment + cross(r0, sf) + cross(el.step, st) + slope * cross(el.step, sg);
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
                source: "none: a property of the medium (granrs.media's cards give values \
                         with sources; the docs tabulate them)",
                min: 0.0,
                description: "alpha_z of a horizontal plate pushed straight down, per unit depth",
                integer: false,
                max: f64::INFINITY,
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
        shapes: super::EVERY_SHAPE,
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
        let co = self.coefficients_in();
        #[cfg(target_arch = "x86_64")]
        if let Some((force, moment)) = self.lone_rod(&co, c) {
            return TermForce {
                force,
                bound: [F::splat(0.0); 2],
                moment,
            };
        }
        self.force_base(&co, c)
    }

    /// [`Rft::law`] with `p` its parameters in the table's order (`zeta`, `elements`, the
    /// nine coefficients; the count `self`'s).
    #[inline(always)]
    fn force_with<F: Real>(&self, p: &[F], c: &ContactState<F>, _m: &Medium<F>) -> TermForce<F> {
        let co = RftCoefficients {
            zeta: p[0],
            k: std::array::from_fn(|i| p[2 + i]),
        };
        self.law(&co, c)
    }

    /// Per element, `zeta |z| dA (g0 + G v^)`: in depth, `zeta |alpha| dA`, summed over the
    /// immersed elements. Rate-independent: it does not grow with speed. Its direction
    /// turns with each element's velocity (`|G| zeta |z| dA / |v_k|` across it), which is
    /// not counted, as for `poncelet`'s friction: it grows as 1 / |v_k| wherever an element
    /// passes through rest (a pivot in the sand, the approach to a stop), and read about
    /// 1 / dt there on converged runs too.
    fn rates(&self, c: &ContactState<f64>, _m: &Medium<f64>) -> Rates {
        let Some(b) = c.boundary else {
            return Rates::NONE;
        };
        let co = self.coefficients_in::<f64>();
        let mut rates = Rates::NONE;
        b.outline.for_each_plate(&b.frame, |p| {
            let (c2, s2) = line_angle(p);
            let (g0, gx, gy) = alpha_affine(&co.k, c2, s2);
            // The largest |alpha| over the directions: |g0| + |G| (Frobenius norm).
            let turn = (gx[0] * gx[0] + gx[1] * gx[1] + gy[0] * gy[0] + gy[1] * gy[1]).sqrt();
            let el = p.elements(self.elements);
            // Every element of the immersed part: zeta dA |alpha| each.
            rates.spring +=
                co.zeta * el.width * el.length * self.elements as f64 * (g0[0].hypot(g0[1]) + turn);
        });
        rates
    }
}

impl Rft {
    /// [`Rft::law`], out of line, with the numbers behind a reference (seen through,
    /// they were ten more values held in registers in the AVX2 path: 13 % slower there).
    #[inline(never)]
    fn force_base<F: Real>(&self, co: &RftCoefficients<F>, c: &ContactState<F>) -> TermForce<F> {
        self.law(co, c)
    }
}

impl Rft {
    /// Its numbers in `F` (every lane the same).
    #[inline(always)]
    pub fn coefficients_in<F: Real>(&self) -> RftCoefficients<F> {
        RftCoefficients {
            zeta: F::splat(self.zeta),
            k: self.coefficients.map(F::splat),
        }
    }

    /// [`Rft::contact_force`] with the numbers `co` (this law's, or one per lane),
    /// inlined where it is called: the SIMD lanes ([`crate::dynamics::rod_lanes`]) compile
    /// it into their AVX2 step. Only the element count is `self`'s.
    #[inline(always)]
    pub fn law<F: Real>(&self, co: &RftCoefficients<F>, c: &ContactState<F>) -> TermForce<F> {
        let zero = F::splat(0.0);
        let Some(b) = c.boundary else {
            return TermForce::force([zero; 2]);
        };
        let (force, moment) = self.integrate(co, b, None);
        let [held_x, held_y] = b.held;
        if (held_x + held_y).all_zero() {
            return TermForce {
                force,
                bound: [zero; 2],
                moment,
            };
        }
        self.held(co, b, force, moment)
    }
}

impl Rft {
    /// [`Rft::contact_force`] along an axis held at zero: the reaction stands in for that
    /// component, up to the sand's resistance to sinking straight down (y) and the smaller
    /// of its resistances to sliding either way (x). Rotation is not held: the moment stays
    /// the moving elements' while one axis moves, and is zero at rest. Out of line: the
    /// moving contact's path stays one copy of [`Rft::integrate`].
    #[inline(never)]
    fn held<F: Real>(
        &self,
        co: &RftCoefficients<F>,
        b: &Boundary<F>,
        force: [F; 2],
        moment: F,
    ) -> TermForce<F> {
        let zero = F::splat(0.0);
        let one = F::splat(1.0);
        let [held_x, held_y] = b.held;
        let (mut force, mut moment) = (force, moment);
        let mut bound = [zero; 2];
        if !held_y.all_zero() {
            let (down, _) = self.integrate(co, b, Some([zero, -one]));
            bound[1] = held_y * down[1].max(zero);
            force[1] = (one - held_y) * force[1];
        }
        if !held_x.all_zero() {
            let (right, _) = self.integrate(co, b, Some([one, zero]));
            let (left, _) = self.integrate(co, b, Some([-one, zero]));
            bound[0] = held_x * (-right[0]).max(zero).min(left[0].max(zero));
            force[0] = (one - held_x) * force[0];
        }
        moment = (one - held_x * held_y) * moment;
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
        params: &[LAM, ELEMENTS],
        acts: Acts::Contact,
        class: Class::Dynamic,
        velocity_dependent: true,
        reads: "rho_g; the contact's boundary plates (frame and outline), each element's \
                velocity normal to it",
        reads_area_speed: false,
        reads_frame: true,
        shapes: super::EVERY_SHAPE,
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
        #[cfg(target_arch = "x86_64")]
        if let Some((force, moment)) = self.lone_rod(c, m) {
            return TermForce {
                force,
                bound: [F::splat(0.0); 2],
                moment,
            };
        }
        self.law(F::splat(self.lam), c, m)
    }

    /// [`RftInertial::law`] with `p = [lam, elements]` (the count `self`'s).
    #[inline(always)]
    fn force_with<F: Real>(&self, p: &[F], c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        self.law(p[0], c, m)
    }

    /// Per element a quadratic drag along its normal: `dF/dv = -2 lam rho_g |v_n| n n^T dA`.
    /// It does not grow with depth (the immersed area does, as the elements' sum shows).
    fn rates(&self, c: &ContactState<f64>, m: &Medium<f64>) -> Rates {
        let Some(b) = c.boundary else {
            return Rates::NONE;
        };
        let mut damping = 0.0;
        b.outline.for_each_plate(&b.frame, |p| {
            let n = [-p.u[1], p.u[0]];
            let el = p.elements(self.elements);
            for k in 0..self.elements {
                let t = k as f64 + 0.5;
                let mid = [el.start[0] + t * el.step[0], el.start[1] + t * el.step[1]];
                let v = b.frame.velocity_at(mid);
                let vn = (v[0] * n[0] + v[1] * n[1]).abs();
                damping += 2.0 * self.lam * m.rho_g * vn * el.length * el.width;
            }
        });
        Rates {
            damping,
            spring: 0.0,
        }
    }
}

impl RftInertial {
    /// [`RftInertial::contact_force`] with the scale `lam` (this law's, or one per lane),
    /// inlined where it is called: the SIMD lanes ([`crate::dynamics::rod_lanes`]) compile
    /// it into their AVX2 step. Only the element count is `self`'s.
    #[inline(always)]
    pub fn law<F: Real>(&self, lam: F, c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        let zero = F::splat(0.0);
        let Some(b) = c.boundary else {
            return TermForce::force([zero; 2]);
        };
        let k = -(lam * m.rho_g);
        let mut sum = ([zero; 2], zero);
        b.outline
            .for_each_plate(&b.frame, |p| self.add_plate::<F, 0>(k, p, b, &mut sum));
        TermForce {
            force: sum.0,
            bound: [zero; 2],
            moment: sum.1,
        }
    }

    /// Add plate `p`'s force and moment about P to `sum`, with `k = -lam rho_g`, at `N`
    /// elements (known when compiled), or `self.elements` where `N` is 0.
    #[inline(always)]
    fn add_plate<F: Real, const N: usize>(
        &self,
        k: F,
        p: &Plate<F>,
        b: &Boundary<F>,
        sum: &mut ([F; 2], F),
    ) {
        let zero = F::splat(0.0);
        let n_el = if N > 0 { N } else { self.elements };
        // The plate's normal (-u_y, u_x); either face leads, by the sign of v_n.
        let n = [-p.u[1], p.u[0]];
        let el = p.elements(n_el);
        let area = el.length * el.width;
        // v_n at t = k + 1/2 from the start is affine in t (a rigid link): vn0 + t dvn.
        let v0 = b.frame.velocity_at(el.start);
        let dv = [-b.frame.omega * el.step[1], b.frame.omega * el.step[0]];
        let vn0 = v0[0] * n[0] + v0[1] * n[1];
        let dvn = dv[0] * n[0] + dv[1] * n[1];
        // Sums of w and t w; df = w n, so sum r_k x df_k = (r_0 sum w + step sum t w) x n.
        let (mut sw, mut stw) = (zero, zero);
        for e in 0..n_el {
            let t = F::splat(e as f64) + F::splat(0.5);
            let vn = vn0 + t * dvn;
            let w = vn.abs() * vn;
            sw = sw + w;
            stw = stw + t * w;
        }
        let (sw, stw) = (k * area * sw, k * area * stw);
        let (f, moment) = sum;
        *f = [f[0] + sw * n[0], f[1] + sw * n[1]];
        let r0 = [el.start[0] - b.apply[0], el.start[1] - b.apply[1]];
        let lever = [sw * r0[0] + stw * el.step[0], sw * r0[1] + stw * el.step[1]];
        *moment = *moment + cross(lever, n);
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

    /// The force and moment about `apply` as a plain element sum, written out here from
    /// eq. 1 with [`alpha`] per element (its direction from its middle's velocity) and the
    /// two-point Gauss rule along it (exact: the load is linear, the moment quadratic).
    fn element_sum(t: &Rft, b: &Boundary<f64>) -> ([f64; 2], f64) {
        let (mut f, mut m) = ([0.0; 2], 0.0);
        let g = 0.5 / 3f64.sqrt();
        b.outline.for_each_plate(&b.frame, |p| {
            let u = [p.b[0] - p.a[0], p.b[1] - p.a[1]];
            let beta = u[1].atan2(u[0]);
            let part = p.immersed();
            let n = t.elements as f64;
            let step = [(part.b[0] - part.a[0]) / n, (part.b[1] - part.a[1]) / n];
            let len = (step[0] * step[0] + step[1] * step[1]).sqrt();
            for e in 0..t.elements {
                let mid = e as f64 + 0.5;
                let at = [part.a[0] + mid * step[0], part.a[1] + mid * step[1]];
                let v = b.frame.velocity_at(at);
                let gamma = (-v[1]).atan2(v[0]);
                let (ax, az) = alpha_at(&t.coefficients, beta, gamma);
                for q in [mid - g, mid + g] {
                    let x = [part.a[0] + q * step[0], part.a[1] + q * step[1]];
                    let w = t.zeta * p.width * 0.5 * len * (-x[1]);
                    let df = [-ax * w, az * w];
                    f = [f[0] + df[0], f[1] + df[1]];
                    m += (x[0] - b.apply[0]) * df[1] - (x[1] - b.apply[1]) * df[0];
                }
            }
        });
        (f, m)
    }

    #[test]
    fn the_plate_sums_equal_the_element_sum_on_an_oblique_rotating_rod() {
        let (d_c, l) = (0.0127, 0.05);
        let axis = [0.6f64, 0.8];
        for (omega, v) in [(7.0, [0.8, -1.5]), (-40.0, [0.3, -0.2]), (0.0, [1.0, -1.0])] {
            let b = Boundary {
                frame: Frame {
                    origin: [0.01, -0.03],
                    v,
                    omega,
                    axis,
                },
                outline: Outline::Rod {
                    diameter: d_c,
                    immersed: l,
                },
                apply: [0.002, -0.01],
                centroid: [0.0; 2],
                v_centroid: v,
                held: [0.0; 2],
            };
            // 3: one by one; 13: a group of 8, one of 4 and one alone.
            for elements in [3, 13] {
                let t = Rft {
                    zeta: 1e6,
                    elements,
                    coefficients: GENERIC,
                };
                let (f, m) = t.integrate(&t.coefficients_in(), &b, None);
                let (fe, me) = element_sum(&t, &b);
                let scale = fe[0].hypot(fe[1]);
                assert!((f[0] - fe[0]).abs() < 1e-12 * scale, "{f:?} {fe:?}");
                assert!((f[1] - fe[1]).abs() < 1e-12 * scale, "{f:?} {fe:?}");
                assert!((m - me).abs() < 1e-12 * scale * l, "{omega}: {m} {me}");
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

    /// A lone rod's fast paths (`Rft::rod_avx2`, `RftInertial::rod_avx2`, taken by
    /// `contact_force` where the CPU has AVX2) give the plain loop's bits at every element
    /// count they cover, on tilted, spinning rods partly out of the sand, with an element at
    /// rest, and held or not.
    #[test]
    fn a_lone_rods_fast_path_is_the_plain_loop_bit_for_bit() {
        use proptest::prelude::*;
        let medium = crate::forces::Medium::default();
        let case = |q: f64, v: [f64; 2], omega: f64, depth: f64, held: [f64; 2], n: usize| {
            let (s, c) = q.sin_cos();
            let axis = [-s, c];
            let immersed = (depth / c.abs().max(1e-3)).min(0.19);
            let b = Boundary {
                frame: Frame {
                    origin: [0.01, -depth],
                    v,
                    omega,
                    axis,
                },
                outline: Outline::Rod {
                    diameter: 0.0127,
                    immersed,
                },
                apply: [
                    0.01 + 0.3 * immersed * axis[0],
                    -depth + 0.3 * immersed * axis[1],
                ],
                centroid: [0.0; 2],
                v_centroid: v,
                held,
            };
            let state = ContactState {
                depth,
                volume: 0.0,
                width: 0.0127,
                l_ref: 0.19,
                v,
                area_speed: 0.0,
                sign: [0.0, -1.0],
                boundary: Some(&b),
            };
            let t = Rft {
                zeta: 1.3e6,
                elements: n,
                coefficients: GENERIC,
            };
            let inertial = RftInertial {
                lam: 1.7,
                elements: n,
            };
            let pairs = [
                (
                    t.contact_force(&state, &medium),
                    t.law(&t.coefficients_in(), &state),
                ),
                (
                    inertial.contact_force(&state, &medium),
                    inertial.law(1.7, &state, &medium),
                ),
            ];
            // The fast paths are what ran (where this CPU has them).
            #[cfg(target_arch = "x86_64")]
            if crate::num::avx2() && held == [0.0; 2] && n <= 8 {
                // SAFETY: this CPU has AVX2 (checked).
                let (f, m) = unsafe { t.rod_avx2(&t.coefficients_in(), (0.0127, immersed), &b) };
                prop_assert_eq!(
                    [f[0], f[1], m],
                    [pairs[0].1.force[0], pairs[0].1.force[1], pairs[0].1.moment]
                );
                let k = -(1.7 * medium.rho_g);
                // SAFETY: as above.
                let (f, m) = unsafe { inertial.rod_avx2(k, (0.0127, immersed), &b) };
                prop_assert_eq!(
                    [f[0], f[1], m],
                    [pairs[1].1.force[0], pairs[1].1.force[1], pairs[1].1.moment]
                );
            }
            for (fast, plain) in pairs {
                for (a, b) in [
                    (fast.force[0], plain.force[0]),
                    (fast.force[1], plain.force[1]),
                    (fast.bound[0], plain.bound[0]),
                    (fast.bound[1], plain.bound[1]),
                    (fast.moment, plain.moment),
                ] {
                    prop_assert_eq!(a.to_bits(), b.to_bits(), "n {} held {:?}", n, held);
                }
            }
            Ok(())
        };
        // Every element at rest (no direction: no force), and the rod turning about its tip.
        for n in 1..=10 {
            case(0.4, [0.0; 2], 0.0, 0.03, [0.0; 2], n).unwrap();
            case(0.4, [0.0; 2], 5.0, 0.03, [0.0; 2], n).unwrap();
        }
        proptest!(ProptestConfig::with_cases(400), |(
            q in -1.5f64..1.5,
            vx in -2.0f64..2.0,
            vy in -3.0f64..1.0,
            omega in -40.0f64..40.0,
            depth in 0.001f64..0.12,
            hold in 0usize..4,
            n in prop::sample::select(vec![1usize, 2, 3, 4, 5, 6, 7, 8, 9, 16]),
        )| {
            let held = [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0], [1.0, 1.0]][hold];
            case(q, [vx, vy], omega, depth, held, n)?;
        });
    }
}
