//! `rft3d`: three-dimensional resistive force theory, and `rft3d_inertial`, its
//! rate-dependent term, on the surface elements of a body in space (`crate::space`).
//!
//! ```text
//! dF = zeta |z| dA alpha_gen(n, v^)                          on leading elements (n . v >= 0)
//! alpha_gen = f1 m + f2 v^ - f3 z^
//! m  = n if n_z < 0 else -n        (the element as a two-sided plate, normal facing down;
//!                                    the tie, |n_z| <= 1e-12, is -n)
//! x1 = -v^_z,  x2 = |n_z|,  x3 = m . v^
//! f_i = sum_k c_ik T_k(x1, x2, x3),
//! T = (1, x1, x2, x3, x1^2, x2^2, x3^2, x1 x2, x2 x3, x3 x1, x1^3, x2^3, x3^3,
//!      x1 x2^2, x2 x1^2, x2 x3^2, x3 x2^2, x3 x1^2, x1 x3^2, x1 x2 x3)
//! ```
//!
//! with `n` the element's outward unit normal, `v^` the direction of its velocity, `z^` up
//! and `|z|` its depth below the sand's surface. This is the angle form of the source
//! (velocity angle gamma, plate tilt beta, twist psi, in the frame of the velocity's
//! horizontal direction r) written in vectors: `x1 = sin gamma`, `x2 = cos beta`,
//! `x3 = cos psi cos gamma sin beta + sin gamma cos beta`, and
//! `(alpha_r, alpha_theta, alpha_z) = (f1 sin b cos p + f2 cos g, f1 sin b sin p,
//! -f1 cos b - f2 sin g - f3)`; the vector form needs no frame, so it has no degenerate
//! case when v or n is vertical. A horizontal plate pushed straight down has
//! `alpha_z = 0.87574`; a vertical wall sliding straight down `0.24898`. Trailing elements
//! (n . v < 0) carry nothing (no suction). Elements whose velocity is exactly zero carry
//! nothing either: the law gives no force at rest (a stop ends a run, `crate::space`).
//!
//! An optional surface-friction cap: where the tangential part of the stress exceeds
//! `mu_surf` times its normal part, the tangential part is scaled down to it.
//!
//! - **Source:** Agarwal, Goldman & Kamrin, "Mechanistic framework for reduced-order
//!   models in soft materials: Application to three-dimensional granular intrusion", PNAS
//!   120 (2023) e2214017120, SI section S3 (the fitted functions and their coefficients).
//!   The paper's SI could not be read here; the form, the coefficients and the rules come
//!   from four public codes that cite it, cross-read against each other and against the
//!   physics (`docs/space.md` lists where they disagree and which value is used).
//! - **Parameters:** `zeta` [N/m^3], required: the material scale multiplying the
//!   dimensionless generic stress (the paper's xi_n; [`xi_n`] gives it from the medium's
//!   critical-state density and internal friction); `mu_surf` [-], the surface-friction
//!   cap, default infinite (no cap); `grazing` [-], 1 (default) to count elements moving
//!   along their own surface (n . v = 0, within 1e-12 of |v|), as the public codes do, 0
//!   to leave them out.
//! - **Reads:** each surface element's normal, depth, area and velocity.
//! - **Shapes:** the shapes in space (sphere, capsule, cylinder, cuboid, mesh); a planar
//!   scene refuses it before any work.
//!
//! `rft3d_inertial`:
//!
//! ```text
//! dF = -lam rho_g (n . v)^2 n dA      on leading elements (n . v > 0)
//! ```
//!
//! the momentum flux of the sand each leading element brings to its normal speed (as the
//! planar `rft_inertial`; Agarwal, Karsai, Goldman & Kamrin, Science Advances 7 (2021)
//! eabe0631).

use super::{
    Acts, Class, ContactState, Medium, Param, Rates, Real, Term, TermForce, TermInfo, SPACE_SHAPES,
};

/// The fitted coefficients c_ik of the three functions f_1, f_2, f_3 (rows), in the order of
/// the monomials T_k (columns; see the module's doc). Where public transcriptions of the SI
/// table disagree, the value that three of four agree on is used (`docs/space.md`).
pub const COEFFICIENTS: [[f64; 20]; 3] = [
    [
        0.00212, -0.02320, -0.20890, -0.43083, -0.00259, 0.48872, -0.00415, 0.07204, -0.02750,
        -0.08772, 0.01992, -0.45961, 0.40799, -0.10107, -0.06576, 0.05664, -0.09269, 0.01892,
        0.01033, 0.15120,
    ],
    [
        -0.06796, -0.10941, 0.04725, -0.06914, -0.05835, -0.65880, -0.11985, -0.25739, -0.26834,
        0.02692, -0.00736, 0.63758, 0.08997, 0.21069, 0.04748, 0.20406, 0.18519, 0.04934, 0.13527,
        -0.33207,
    ],
    [
        -0.02634, -0.03436, 0.45256, 0.00835, 0.02553, -1.31290, -0.05532, 0.06790, -0.16404,
        0.02287, 0.02927, 0.95406, -0.00131, -0.11028, 0.01487, -0.02730, 0.10911, -0.04097,
        0.07881, -0.27519,
    ],
];

/// Tolerance of the leading-edge test on `n . v^` (grazing elements are within it).
pub const GRAZING_TOL: f64 = 1e-12;

/// The material scale xi_n [N/m^3] of 3D-RFT from the medium's critical-state (bulk)
/// density `rho_c` [kg/m^3] and internal friction coefficient `mu` [-]:
/// `xi_n = rho_c g (894 mu^3 - 386 mu^2 + 89 mu)`, g = 9.81 m/s^2 (Agarwal et al. 2023, as
/// the public codes give it; fitted over mu 0.3 to 0.9).
pub fn xi_n(rho_c: f64, mu: f64) -> f64 {
    rho_c * 9.81 * (894.0 * mu * mu * mu - 386.0 * mu * mu + 89.0 * mu)
}

/// The three fitted functions (f1, f2, f3) at the invariants (x1, x2, x3), each the sum of
/// [`COEFFICIENTS`] times the monomials T_k, evaluated in nested (Horner) form, in x1 over
/// polynomials in x2 and x3:
///
/// ```text
/// f = P0 + x1 (P1 + x1 (P2 + x1 c10))
/// P0 = c0 + x3 (c3 + x3 (c6 + x3 c12)) + x2 (c2 + x3 (c8 + x3 c15) + x2 (c5 + x3 c16 + x2 c11))
/// P1 = c1 + x3 (c9 + x3 c18) + x2 (c7 + x3 c19 + x2 c13)
/// P2 = c4 + x2 c14 + x3 c17
/// ```
///
/// (19 products per function instead of 16 monomials and 19 products each; the same sum to
/// round-off).
#[inline(always)]
pub fn fitted<F: Real>(x1: F, x2: F, x3: F) -> [F; 3] {
    fitted_as::<F, false>(x1, x2, x3)
}

/// [`fitted`], each product and sum `a b + c` of its nested form rounded once where
/// `FUSED` (a fused multiply-add: half the operations and a shorter chain; the element
/// kernel's), else twice (the same bits as the sums written out).
#[inline(always)]
pub fn fitted_as<F: Real, const FUSED: bool>(x1: F, x2: F, x3: F) -> [F; 3] {
    // a b + c; unfused, the same operations as `c + a b`.
    let fma = |a: F, b: F, c: F| if FUSED { a.mul_add(b, c) } else { a * b + c };
    let mut f = [F::splat(0.0); 3];
    for (fi, c) in f.iter_mut().zip(COEFFICIENTS.iter()) {
        let k = |i: usize| F::splat(c[i]);
        let p0 = fma(
            x2,
            fma(
                x2,
                fma(x2, k(11), fma(x3, k(16), k(5))),
                fma(x3, fma(x3, k(15), k(8)), k(2)),
            ),
            fma(x3, fma(x3, fma(x3, k(12), k(6)), k(3)), k(0)),
        );
        let p1 = fma(
            x2,
            fma(x2, k(13), fma(x3, k(19), k(7))),
            fma(x3, fma(x3, k(18), k(9)), k(1)),
        );
        let p2 = fma(x3, k(17), fma(x2, k(14), k(4)));
        *fi = fma(x1, fma(x1, fma(x1, k(10), p2), p1), p0);
    }
    f
}

/// The generic (dimensionless) stress alpha_gen on an element with outward unit normal `n`
/// moving along the unit direction `vh` (z up), before the leading-edge test and the
/// friction cap.
#[inline(always)]
pub fn generic_stress<F: Real>(n: [F; 3], vh: [F; 3]) -> [F; 3] {
    let nv = n[0] * vh[0] + n[1] * vh[1] + n[2] * vh[2];
    generic_stress_nv::<F, false>(n, vh, nv)
}

/// [`generic_stress`] with `n . vh` given (as [`stress`] has it already). With `m = s n`,
/// `s = +-1`: `x3 = m . v^ = s (n . v^)` and `f1 m = (s f1) n`, bit for bit (a product by
/// +-1 is exact).
#[inline(always)]
fn generic_stress_nv<F: Real, const FUSED: bool>(n: [F; 3], vh: [F; 3], nv: F) -> [F; 3] {
    // m: the plate's normal facing down (n where n_z < -tol, else -n). The law jumps where
    // a face turns through vertical (f1 m flips, and f1 is not zero there); the tie within
    // round-off goes one way, so that a vertical wall is one plate whatever the round-off
    // of its normal (else a wall tilted by 1e-26 rad pushes sideways).
    let s = (-n[2] - F::splat(GRAZING_TOL)).select_pos(F::splat(1.0), F::splat(-1.0));
    let x1 = -vh[2];
    let x2 = n[2].abs();
    let x3 = s * nv;
    let [f1, f2, f3] = fitted_as::<F, FUSED>(x1, x2, x3);
    let f1 = s * f1;
    [
        f1 * n[0] + f2 * vh[0],
        f1 * n[1] + f2 * vh[1],
        f1 * n[2] + f2 * vh[2] - f3,
    ]
}

/// The stress per unit depth [N/m^3] of `rft3d` on an element (normal `n`, velocity `v`):
/// `zeta alpha_gen`, capped by `mu_surf`, zero on trailing elements, at rest, and (when
/// `grazing` is 0) on grazing ones. Branch-free, so that it runs in SIMD lanes.
#[inline(always)]
pub fn stress<F: Real>(law: &Rft3dLanes<F>, n: [F; 3], v: [F; 3]) -> [F; 3] {
    stress_capped::<F, true>(law, n, v)
}

/// [`stress`], with the friction cap applied only where `CAP` (a law whose `mu_surf` is
/// infinite has none: the kernel then skips its arithmetic; the result is the same).
#[inline(always)]
pub fn stress_capped<F: Real, const CAP: bool>(
    law: &Rft3dLanes<F>,
    n: [F; 3],
    v: [F; 3],
) -> [F; 3] {
    stress_as::<F, CAP, false>(law, n, v)
}

/// [`stress_capped`], its fitted functions fused where `FUSED` ([`fitted_as`]: the element
/// kernel's form; the same stress to round-off).
#[inline(always)]
pub fn stress_as<F: Real, const CAP: bool, const FUSED: bool>(
    law: &Rft3dLanes<F>,
    n: [F; 3],
    v: [F; 3],
) -> [F; 3] {
    let zero = F::splat(0.0);
    let speed2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    // 1 / |v|, finite at rest (the element is then left out below).
    let moving = speed2.select_pos(F::splat(1.0), zero);
    let inv = (speed2 + (F::splat(1.0) - moving)).sqrt().recip();
    let vh = [v[0] * inv, v[1] * inv, v[2] * inv];
    let nv = n[0] * vh[0] + n[1] * vh[1] + n[2] * vh[2];
    // Leading: n . v^ > -tol (grazing counted) or > tol (grazing left out).
    let leading = (nv + law.threshold).select_pos(F::splat(1.0), zero) * moving;
    let a = generic_stress_nv::<F, FUSED>(n, vh, nv);
    let k = law.zeta * leading;
    if !CAP {
        return [k * a[0], k * a[1], k * a[2]];
    }
    // The friction cap: tangential part <= mu_surf |normal part|.
    let an = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
    let at = [a[0] - an * n[0], a[1] - an * n[1], a[2] - an * n[2]];
    let at_norm = (at[0] * at[0] + at[1] * at[1] + at[2] * at[2]).sqrt();
    let cap = law.mu_surf * an.abs();
    let over = at_norm - cap;
    // cap / |at| where over the cap (then |at| > cap >= 0), else 1; with no cap (infinite
    // mu_surf) `over` is -inf or NaN and the scale is 1.
    let scale = over.select_pos(
        cap * at_norm.max(F::splat(f64::MIN_POSITIVE)).recip(),
        F::splat(1.0),
    );
    [
        k * (an * n[0] + scale * at[0]),
        k * (an * n[1] + scale * at[1]),
        k * (an * n[2] + scale * at[2]),
    ]
}

/// Where each monomial's derivatives fall in the quadratic monomials
/// `Q = (1, x1, x2, x3, x1^2, x2^2, x3^2, x1 x2, x2 x3, x3 x1)`: for T_k, per variable
/// (x1, x2, x3), the factor and the index into Q (factor 0: no term).
const MONOMIAL_DERIVATIVES: [[(f64, usize); 3]; 20] = [
    [(0.0, 0), (0.0, 0), (0.0, 0)], // 1
    [(1.0, 0), (0.0, 0), (0.0, 0)], // x1
    [(0.0, 0), (1.0, 0), (0.0, 0)], // x2
    [(0.0, 0), (0.0, 0), (1.0, 0)], // x3
    [(2.0, 1), (0.0, 0), (0.0, 0)], // x1^2
    [(0.0, 0), (2.0, 2), (0.0, 0)], // x2^2
    [(0.0, 0), (0.0, 0), (2.0, 3)], // x3^2
    [(1.0, 2), (1.0, 1), (0.0, 0)], // x1 x2
    [(0.0, 0), (1.0, 3), (1.0, 2)], // x2 x3
    [(1.0, 3), (0.0, 0), (1.0, 1)], // x3 x1
    [(3.0, 4), (0.0, 0), (0.0, 0)], // x1^3
    [(0.0, 0), (3.0, 5), (0.0, 0)], // x2^3
    [(0.0, 0), (0.0, 0), (3.0, 6)], // x3^3
    [(1.0, 5), (2.0, 7), (0.0, 0)], // x1 x2^2
    [(2.0, 7), (1.0, 4), (0.0, 0)], // x2 x1^2
    [(0.0, 0), (1.0, 6), (2.0, 8)], // x2 x3^2
    [(0.0, 0), (2.0, 8), (1.0, 5)], // x3 x2^2
    [(2.0, 9), (0.0, 0), (1.0, 4)], // x3 x1^2
    [(1.0, 6), (0.0, 0), (2.0, 9)], // x1 x3^2
    [(1.0, 8), (1.0, 9), (1.0, 7)], // x1 x2 x3
];

/// The gradients' coefficients on the quadratic monomials: `G[i][k][j]` multiplies `Q_j`
/// in `d f_i / d x_k` (derived from [`COEFFICIENTS`] at compile time).
const GRADIENT: [[[f64; 10]; 3]; 3] = {
    let mut g = [[[0.0; 10]; 3]; 3];
    let mut i = 0;
    while i < 3 {
        let mut t = 0;
        while t < 20 {
            let mut k = 0;
            while k < 3 {
                let (factor, j) = MONOMIAL_DERIVATIVES[t][k];
                g[i][k][j] += factor * COEFFICIENTS[i][t];
                k += 1;
            }
            t += 1;
        }
        i += 1;
    }
    g
};

/// The three fitted functions and their gradients: `(f, g)` with `g[i][k] = d f_i / d x_k`
/// (generic over the number type: the element kernel runs it in lanes, the same operations).
#[inline(always)]
pub fn fitted_with_gradient<F: Real>(x1: F, x2: F, x3: F) -> ([F; 3], [[F; 3]; 3]) {
    let f = fitted(x1, x2, x3);
    let q = [
        F::splat(1.0),
        x1,
        x2,
        x3,
        x1 * x1,
        x2 * x2,
        x3 * x3,
        x1 * x2,
        x2 * x3,
        x3 * x1,
    ];
    let mut g = [[F::splat(0.0); 3]; 3];
    for i in 0..3 {
        for k in 0..3 {
            let c = &GRADIENT[i][k];
            let mut acc = F::splat(0.0);
            for j in 0..10 {
                acc = acc + F::splat(c[j]) * q[j];
            }
            g[i][k] = acc;
        }
    }
    (f, g)
}

/// The stress per unit depth [N/m^3] of `rft3d` on an element (normal `n`, velocity `u`)
/// made continuous in the velocity over the speed `eps` [m/s], and its derivative with
/// respect to `u`: `(sigma, d sigma / d u)` with
/// `sigma = lead(n . u) phi(|u|) stress(n, u)`, `phi(s) = s / sqrt(s^2 + eps^2)`, and the
/// leading test a ramp over `eps`: `lead = clamp(n . u / eps + 1, 0, 1)` (grazing elements
/// counted; `clamp(n . u / eps, 0, 1)` where they are not). With `eps = 0` it is
/// [`stress`] exactly (phi = 1, the law's step).
///
/// The law gives no unique force at rest (it reads only the direction of the velocity)
/// and jumps where an element turns from leading to trailing; `phi` makes it a stiff
/// viscous law below `eps` and the ramp makes it continuous, so that an implicit step can
/// hold a body at rest (`crate::space::engine`). At speed `|u|` the ramp changes the law
/// only on elements within `eps / |u|` of grazing. The derivative is exact away from the
/// law's own jump where a face turns through vertical (a change of position, not of
/// velocity), the cap's switch and the ramp's ends; it is zero at `u = 0`.
pub fn stress_with_rate(
    law: &Rft3d,
    n: [f64; 3],
    u: [f64; 3],
    eps: f64,
) -> ([f64; 3], [[f64; 3]; 3]) {
    let zero = ([0.0; 3], [[0.0; 3]; 3]);
    let (s2, s, vh, nu) = direction(n, u);
    if s2 <= 0.0 {
        return zero;
    }
    let threshold = if law.grazing {
        GRAZING_TOL
    } else {
        -GRAZING_TOL
    };
    // Leading: with eps, a ramp from n . u = -eps (nothing) to 0 (all; grazing counted),
    // or from 0 to eps where grazing elements are left out; else the law's step.
    let (lead, dlead) = if eps > 0.0 {
        let x = ramp_position(nu, eps, law.grazing);
        if x > 0.0 {
            ramp(x, eps)
        } else {
            return zero;
        }
    } else if nu / s + threshold > 0.0 {
        (1.0, 0.0)
    } else {
        return zero;
    };
    let (mut a, mut ja) = alpha_with_rate(n, vh);
    if law.mu_surf != f64::INFINITY {
        // The cap: alpha_c = an n + (cap / |at|) at where |at| > cap = mu |an|.
        let (an, at, at_norm, cap) = cap_parts(law.mu_surf, n, a);
        if at_norm > cap {
            let k = cap / at_norm;
            let sg = if an >= 0.0 { 1.0 } else { -1.0 };
            // d alpha_c / d alpha = n n^T + at (mu sg n / |at| - cap at / |at|^3)^T + k P
            let mut jc = [[0.0; 3]; 3];
            for r in 0..3 {
                for c in 0..3 {
                    let p = if r == c { 1.0 } else { 0.0 } - n[r] * n[c];
                    jc[r][c] = n[r] * n[c]
                        + at[r]
                            * (law.mu_surf * sg * n[c] / at_norm
                                - cap * at[c] / (at_norm * at_norm * at_norm))
                        + k * p;
                }
            }
            let mut prod = [[0.0; 3]; 3];
            for r in 0..3 {
                for c in 0..3 {
                    prod[r][c] = (0..3).map(|j| jc[r][j] * ja[j][c]).sum();
                }
            }
            ja = prod;
            a = capped(n, an, at, k);
        }
    }
    sigma_with_rate(law.zeta, lead, dlead, s, s2, eps, n, vh, a, ja)
}

/// [`stress_with_rate`]'s stress alone (its rate not computed), the same bits: for a
/// solver's trial points, where only the value is read.
pub fn stress_with_ramp(law: &Rft3d, n: [f64; 3], u: [f64; 3], eps: f64) -> [f64; 3] {
    if eps > 0.0 && law.mu_surf == f64::INFINITY {
        return stress_on_ramp(law.zeta, n, u, eps, law.grazing);
    }
    let (s2, s, vh, nu) = direction(n, u);
    if s2 <= 0.0 {
        return [0.0; 3];
    }
    let lead = if eps > 0.0 {
        let x = ramp_position(nu, eps, law.grazing);
        if x > 0.0 {
            ramp(x, eps).0
        } else {
            return [0.0; 3];
        }
    } else {
        let threshold = if law.grazing {
            GRAZING_TOL
        } else {
            -GRAZING_TOL
        };
        if nu / s + threshold > 0.0 {
            1.0
        } else {
            return [0.0; 3];
        }
    };
    let (m, x1, x2, x3) = plate(n, vh);
    let mut a = alpha_of(m, vh, fitted(x1, x2, x3));
    if law.mu_surf != f64::INFINITY {
        let (an, at, at_norm, cap) = cap_parts(law.mu_surf, n, a);
        if at_norm > cap {
            a = capped(n, an, at, cap / at_norm);
        }
    }
    let (_, phi) = phi_of(s, s2, eps);
    sigma_of(law.zeta, lead, phi, a)
}

/// [`stress_with_ramp`] of a law without a friction cap (`zeta`, `grazing`) at `eps > 0`,
/// without a branch (so that the element kernel's loop runs in SIMD lanes): every part
/// computed and the stress selected where the element moves and is on its ramp, else zero.
/// The same operations, so the same bits.
#[inline(always)]
pub fn stress_on_ramp(zeta: f64, n: [f64; 3], u: [f64; 3], eps: f64, grazing: bool) -> [f64; 3] {
    let (s2, s, vh, nu) = direction(n, u);
    let x = ramp_position(nu, eps, grazing);
    let (lead, _) = ramp(x, eps);
    let (m, x1, x2, x3) = plate(n, vh);
    let a = alpha_of(m, vh, fitted(x1, x2, x3));
    let (_, phi) = phi_of(s, s2, eps);
    let sigma = sigma_of(zeta, lead, phi, a);
    // x where it moves (s2 > 0), else 0: positive where the stress is not zero.
    let on = s2.select_pos(x, 0.0);
    sigma.map(|v| on.select_pos(v, 0.0))
}

/// [`stress_with_rate`] of a law without a friction cap (`zeta`, `grazing`) at `eps > 0`,
/// without a branch (so that the element kernel's loop runs in SIMD lanes): every part
/// computed, the stress and its rate selected where the element moves and is on its ramp,
/// else zero. The same operations, so the same bits.
#[inline(always)]
pub fn stress_with_rate_on_ramp(
    zeta: f64,
    n: [f64; 3],
    u: [f64; 3],
    eps: f64,
    grazing: bool,
) -> ([f64; 3], [[f64; 3]; 3]) {
    let (s2, s, vh, nu) = direction(n, u);
    let x = ramp_position(nu, eps, grazing);
    let (lead, dlead) = ramp(x, eps);
    let (a, ja) = alpha_with_rate(n, vh);
    let (sigma, jac) = sigma_with_rate(zeta, lead, dlead, s, s2, eps, n, vh, a, ja);
    // x where it moves (s2 > 0), else 0: positive where the stress is not zero.
    let on = s2.select_pos(x, 0.0);
    (
        sigma.map(|v| on.select_pos(v, 0.0)),
        jac.map(|row| row.map(|v| on.select_pos(v, 0.0))),
    )
}

/// The cap's parts of alpha on an element of normal `n`: its normal part `an`, its
/// tangential part `at` and that one's norm, and the cap `mu |an|`.
#[inline(always)]
fn cap_parts(mu: f64, n: [f64; 3], a: [f64; 3]) -> (f64, [f64; 3], f64, f64) {
    let an = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
    let at = [a[0] - an * n[0], a[1] - an * n[1], a[2] - an * n[2]];
    let at_norm = (at[0] * at[0] + at[1] * at[1] + at[2] * at[2]).sqrt();
    (an, at, at_norm, mu * an.abs())
}

/// alpha capped: `an n + k at`.
#[inline(always)]
fn capped(n: [f64; 3], an: f64, at: [f64; 3], k: f64) -> [f64; 3] {
    [
        an * n[0] + k * at[0],
        an * n[1] + k * at[1],
        an * n[2] + k * at[2],
    ]
}

/// An element's velocity `u`: `|u|^2`, `|u|`, its direction `u / |u|` (not finite at rest)
/// and `n . u`.
#[inline(always)]
pub fn direction<F: Real>(n: [F; 3], u: [F; 3]) -> (F, F, [F; 3], F) {
    let s2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    let s = s2.sqrt();
    let vh = [u[0] / s, u[1] / s, u[2] / s];
    let nu = n[0] * u[0] + n[1] * u[1] + n[2] * u[2];
    (s2, s, vh, nu)
}

/// Where `n . u` is on the leading ramp over `eps`: `n . u / eps + 1` (grazing elements
/// counted) or `n . u / eps`; the element leads where it is positive.
#[inline(always)]
pub fn ramp_position<F: Real>(nu: F, eps: F, grazing: bool) -> F {
    if grazing {
        nu / eps + F::splat(1.0)
    } else {
        nu / eps
    }
}

/// The leading ramp and its rate at a positive position `x` ([`ramp_position`]): `(1, 0)`
/// from `x = 1` on, `(x, 1 / eps)` below.
#[inline(always)]
pub fn ramp<F: Real>(x: F, eps: F) -> (F, F) {
    let below = F::splat(1.0) - x;
    (
        below.select_pos(x, F::splat(1.0)),
        below.select_pos(F::splat(1.0) / eps, F::splat(0.0)),
    )
}

/// alpha (uncapped, as [`generic_stress`]) on an element of normal `n` moving along the
/// unit `vh`, and `d alpha / d v^`: [`stress_with_rate`]'s and the element kernel's
/// (`crate::space::load`, in lanes), the same operations.
#[inline(always)]
pub fn alpha_with_rate<F: Real>(n: [F; 3], vh: [F; 3]) -> ([F; 3], [[F; 3]; 3]) {
    let (m, x1, x2, x3) = plate(n, vh);
    let (f, g) = fitted_with_gradient(x1, x2, x3);
    let a = alpha_of(m, vh, f);
    // d f_i / d v^ = -g_i1 z^ + g_i3 m
    let df = |i: usize| [g[i][2] * m[0], g[i][2] * m[1], g[i][2] * m[2] - g[i][0]];
    let (df1, df2, df3) = (df(0), df(1), df(2));
    let mut ja = [[F::splat(0.0); 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            let z = F::splat(if r == 2 { 1.0 } else { 0.0 });
            let delta = if r == c { f[1] } else { F::splat(0.0) };
            ja[r][c] = m[r] * df1[c] + delta + vh[r] * df2[c] - z * df3[c];
        }
    }
    (a, ja)
}

/// The plate's normal `m` facing down (as [`generic_stress`]) and the fitted functions'
/// arguments `x1`, `x2`, `x3` on an element of normal `n` moving along the unit `vh`.
#[inline(always)]
fn plate<F: Real>(n: [F; 3], vh: [F; 3]) -> ([F; 3], F, F, F) {
    let sign = (-n[2] - F::splat(GRAZING_TOL)).select_pos(F::splat(1.0), F::splat(-1.0));
    let m = [sign * n[0], sign * n[1], sign * n[2]];
    let x3 = m[0] * vh[0] + m[1] * vh[1] + m[2] * vh[2];
    (m, -vh[2], n[2].abs(), x3)
}

/// alpha from the plate's normal `m`, the direction `vh` and the fitted functions `f`.
#[inline(always)]
fn alpha_of<F: Real>(m: [F; 3], vh: [F; 3], f: [F; 3]) -> [F; 3] {
    [
        f[0] * m[0] + f[1] * vh[0],
        f[0] * m[1] + f[1] * vh[1],
        f[0] * m[2] + f[1] * vh[2] - f[2],
    ]
}

/// `sqrt(s^2 + eps^2)` and `phi(s) = s / sqrt(s^2 + eps^2)`.
#[inline(always)]
fn phi_of<F: Real>(s: F, s2: F, eps: F) -> (F, F) {
    let root = (s2 + eps * eps).sqrt();
    (root, s / root)
}

/// `sigma = zeta lead phi alpha`.
#[inline(always)]
fn sigma_of<F: Real>(zeta: F, lead: F, phi: F, a: [F; 3]) -> [F; 3] {
    a.map(|x| zeta * lead * phi * x)
}

/// [`stress_with_rate`]'s last part, from alpha (`a`, capped where the law has a cap) and
/// its rate `ja` in `v^`, the ramp `lead` and its rate `dlead`, the speed `s` (`s2` its
/// square) and `eps`:
///
/// `sigma = zeta lead(n . u) phi(s) alpha(u / s)`,
/// `d sigma / d u = zeta (lead (phi'(s) alpha v^T + (phi(s) / s) J_alpha (I - v^ v^T)) +
/// lead' phi(s) alpha n^T)`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn sigma_with_rate<F: Real>(
    zeta: F,
    lead: F,
    dlead: F,
    s: F,
    s2: F,
    eps: F,
    n: [F; 3],
    vh: [F; 3],
    a: [F; 3],
    ja: [[F; 3]; 3],
) -> ([F; 3], [[F; 3]; 3]) {
    let (root, phi) = phi_of(s, s2, eps);
    let dphi = eps * eps / (root * root * root);
    let over_s = F::splat(1.0) / root;
    let sigma = sigma_of(zeta, lead, phi, a);
    let mut jac = [[F::splat(0.0); 3]; 3];
    for r in 0..3 {
        // (A sum of three from -0.0, as `Iterator::sum`: the same bits.)
        let jv = ja[r][0] * vh[0] + ja[r][1] * vh[1] + ja[r][2] * vh[2];
        for c in 0..3 {
            jac[r][c] = zeta
                * (lead * (dphi * a[r] * vh[c] + over_s * (ja[r][c] - jv * vh[c]))
                    + dlead * phi * a[r] * n[c]);
        }
    }
    (sigma, jac)
}

/// `rft3d`'s numbers as the element kernel reads them (one value, or one per lane).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rft3dLanes<F> {
    /// zeta [N/m^3].
    pub zeta: F,
    /// The friction cap mu_surf [-] (infinite: none).
    pub mu_surf: F,
    /// `GRAZING_TOL` where grazing elements count, `-GRAZING_TOL` where they do not: an
    /// element leads where `n . v^ + threshold > 0`.
    pub threshold: F,
}

/// 3D resistive force theory (Agarwal, Goldman & Kamrin 2023).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rft3d {
    /// The material scale zeta [N/m^3].
    pub zeta: f64,
    /// The surface-friction cap mu_surf [-] (infinite: none).
    pub mu_surf: f64,
    /// Whether grazing elements (n . v = 0) count.
    pub grazing: bool,
}

impl Rft3d {
    /// Its numbers for the element kernel.
    pub fn lanes<F: Real>(&self) -> Rft3dLanes<F> {
        Rft3dLanes {
            zeta: F::splat(self.zeta),
            mu_surf: F::splat(self.mu_surf),
            threshold: F::splat(if self.grazing {
                GRAZING_TOL
            } else {
                -GRAZING_TOL
            }),
        }
    }
}

impl Term for Rft3d {
    const INFO: TermInfo = TermInfo {
        name: "rft3d",
        summary: "three-dimensional resistive force theory on a body's surface elements",
        equation: "dF = zeta |z| dA (f1 m + f2 v^ - f3 z^) on leading elements (n . v >= 0); \
                   m: the element's normal facing down; f_i: cubic fits in (-v^_z, |n_z|, m . v^)",
        source: "Agarwal, Goldman & Kamrin, PNAS 120 (2023) e2214017120, SI sec. S3",
        params: &[
            Param {
                name: "zeta",
                unit: "N/m^3",
                default: f64::NAN,
                source: "none: the medium's scale xi_n (granrs.space.xi_n from its density and \
                         internal friction, a granrs.media card, or fitted)",
                min: 0.0,
                description: "material scale of the generic stress",
                integer: false,
                max: f64::INFINITY,
            },
            Param {
                name: "mu_surf",
                unit: "-",
                default: f64::INFINITY,
                source: "no cap unless given (the public codes take 0.15 to 0.4)",
                min: 0.0,
                description: "surface friction: cap on the stress's tangential part",
                integer: false,
                max: f64::INFINITY,
            },
            Param {
                name: "grazing",
                unit: "-",
                default: 1.0,
                source: "1 as the public codes of the paper (grazing elements count)",
                min: 0.0,
                description: "whether elements moving along their own surface count (1 or 0)",
                integer: true,
                max: 1.0,
            },
        ],
        acts: Acts::Contact,
        class: Class::Static,
        velocity_dependent: false,
        reads: "each surface element's normal, depth, area and velocity direction",
        reads_area_speed: false,
        reads_frame: true,
        shapes: SPACE_SHAPES,
        switches: &[],
        columns: &[],
    };

    fn from_params(values: &[f64]) -> Self {
        Rft3d {
            zeta: values[0],
            mu_surf: values[1],
            grazing: values[2] != 0.0,
        }
    }

    fn params(&self) -> Vec<f64> {
        vec![self.zeta, self.mu_surf, f64::from(u8::from(self.grazing))]
    }

    /// None: never evaluated on a planar contact (refused before any work).
    fn force_with<F: Real>(&self, _p: &[F], _c: &ContactState<F>, _m: &Medium<F>) -> TermForce<F> {
        TermForce::force([F::splat(0.0); 2])
    }

    /// Never evaluated on a planar contact (refused before any work; the trait's
    /// `contact_force` gives it zero there); a body in space estimates its own stiffness
    /// (`crate::space::solve`).
    fn rates(&self, _c: &ContactState<f64>, _m: &Medium<f64>) -> Rates {
        Rates::NONE
    }
}

/// The inertial term of dynamic RFT on the surface elements of a body in space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rft3dInertial {
    /// Scale of the momentum flux lam [-].
    pub lam: f64,
}

impl Rft3dInertial {
    /// Its force per unit area [N/m^2] on an element (normal `n`, velocity `v`):
    /// `-lam rho_g (n . v)^2 n` where `n . v > 0`.
    #[inline(always)]
    pub fn traction<F: Real>(k: F, n: [F; 3], v: [F; 3]) -> [F; 3] {
        let vn = (n[0] * v[0] + n[1] * v[1] + n[2] * v[2]).max(F::splat(0.0));
        let p = -(k * vn * vn);
        [p * n[0], p * n[1], p * n[2]]
    }
}

impl Term for Rft3dInertial {
    const INFO: TermInfo = TermInfo {
        name: "rft3d_inertial",
        summary: "the inertial term of dynamic RFT on a body's surface elements in space",
        equation: "dF = -lam rho_g (n . v)^2 n dA on leading elements (n . v > 0)",
        source: "Agarwal, Karsai, Goldman & Kamrin, Science Advances 7 (2021) eabe0631 \
                 (dynamic RFT)",
        params: &[super::rft::LAM],
        acts: Acts::Contact,
        class: Class::Dynamic,
        velocity_dependent: true,
        reads: "rho_g; each surface element's normal, area and velocity",
        reads_area_speed: false,
        reads_frame: true,
        shapes: SPACE_SHAPES,
        switches: &[],
        columns: &[],
    };

    fn from_params(values: &[f64]) -> Self {
        Rft3dInertial { lam: values[0] }
    }

    fn params(&self) -> Vec<f64> {
        vec![self.lam]
    }

    /// None: never evaluated on a planar contact (refused before any work).
    fn force_with<F: Real>(&self, _p: &[F], _c: &ContactState<F>, _m: &Medium<F>) -> TermForce<F> {
        TermForce::force([F::splat(0.0); 2])
    }

    /// Never evaluated on a planar contact (as `Rft3d::rates`).
    fn rates(&self, _c: &ContactState<f64>, _m: &Medium<f64>) -> Rates {
        Rates::NONE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law(mu: f64, grazing: bool) -> Rft3dLanes<f64> {
        Rft3d {
            zeta: 1.0,
            mu_surf: mu,
            grazing,
        }
        .lanes()
    }

    #[test]
    fn a_plate_pushed_down_and_a_wall_sliding_down_give_the_tabulated_stresses() {
        // Sums of the table's columns (computed by hand in the docs): -(sum c1 + c2 + c3).
        let a = stress(
            &law(f64::INFINITY, true),
            [0.0, 0.0, -1.0],
            [0.0, 0.0, -2.0],
        );
        assert!((a[2] - 0.87574).abs() < 1e-12, "{a:?}");
        assert!(a[0].abs() < 1e-15 && a[1].abs() < 1e-15);
        // A vertical wall (n = +x) sliding down: grazing, counted by default.
        let w = stress(&law(f64::INFINITY, true), [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]);
        assert!((w[2] - 0.24898).abs() < 1e-12, "{w:?}");
        let none = stress(
            &law(f64::INFINITY, false),
            [1.0, 0.0, 0.0],
            [0.0, 0.0, -1.0],
        );
        assert_eq!(none, [0.0; 3]);
    }

    #[test]
    fn trailing_elements_and_rest_carry_nothing() {
        let l = law(f64::INFINITY, true);
        assert_eq!(stress(&l, [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]), [0.0; 3]);
        assert_eq!(stress(&l, [0.0, 0.0, -1.0], [0.0, 0.0, 0.0]), [0.0; 3]);
    }

    #[test]
    fn the_vector_form_equals_the_angle_form() {
        // The angle form of the source, written out with its frame, on a grid of pairs.
        let l = law(f64::INFINITY, true);
        let mut checked = 0;
        for i in 0..13 {
            for j in 0..13 {
                for k in 0..7 {
                    let th = std::f64::consts::PI * i as f64 / 12.0;
                    let ph = 2.0 * std::f64::consts::PI * j as f64 / 13.0 + 0.1;
                    let n = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
                    let g = -std::f64::consts::FRAC_PI_2
                        + std::f64::consts::PI * (k as f64 + 0.5) / 7.0;
                    // velocity in the (x, z) plane: r = +x
                    let v = [g.cos(), 0.0, -g.sin()];
                    if n[0] * v[0] + n[1] * v[1] + n[2] * v[2] <= 1e-9 {
                        continue;
                    }
                    // angle form: frame r = x, theta = z x r = y.
                    let (nr, nt, nz) = (n[0], n[1], n[2]);
                    let m = if nz < 0.0 {
                        [nr, nt, nz]
                    } else {
                        [-nr, -nt, -nz]
                    };
                    let b = (-m[2]).acos() * if m[0] >= 0.0 { 1.0 } else { -1.0 };
                    let p = if m[0].abs() < 1e-300 && m[1].abs() < 1e-300 {
                        0.0
                    } else if m[0].abs() < 1e-15 {
                        std::f64::consts::FRAC_PI_2 * m[1].signum() * m[0].signum().max(1.0)
                    } else {
                        (m[1] / m[0]).atan()
                    };
                    let x1 = g.sin();
                    let x2 = b.cos();
                    let x3 = p.cos() * g.cos() * b.sin() + g.sin() * b.cos();
                    let f = fitted(x1, x2, x3);
                    let ar = f[0] * b.sin() * p.cos() + f[1] * g.cos();
                    let at = f[0] * b.sin() * p.sin();
                    let az = -f[0] * b.cos() - f[1] * g.sin() - f[2];
                    let a = stress(&l, n, v);
                    for (x, y) in a.iter().zip([ar, at, az]) {
                        assert!(
                            (x - y).abs() < 1e-12,
                            "n {n:?} v {v:?}: {a:?} vs {:?}",
                            [ar, at, az]
                        );
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 300, "{checked}");
    }

    #[test]
    fn the_friction_cap_limits_the_tangential_part_and_keeps_the_normal_part() {
        let n = [0.6, 0.0, -0.8];
        let v = [1.0, 0.0, -0.3];
        let free = stress(&law(f64::INFINITY, true), n, v);
        let capped = stress(&law(0.1, true), n, v);
        let dot = |a: [f64; 3]| a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
        assert!((dot(free) - dot(capped)).abs() < 1e-15);
        let tang = |a: [f64; 3]| {
            let an = dot(a);
            ((a[0] - an * n[0]).powi(2) + (a[1] - an * n[1]).powi(2) + (a[2] - an * n[2]).powi(2))
                .sqrt()
        };
        assert!(
            tang(free) > 0.1 * dot(free).abs() * 1.01,
            "the case must be capped"
        );
        assert!((tang(capped) - 0.1 * dot(capped).abs()).abs() < 1e-14);
    }

    /// The derivative of `stress_with_rate` against central differences, with and without
    /// the cap and the rest speed, on random leading pairs away from the law's jumps.
    #[test]
    fn the_rate_is_the_derivative_of_the_stress() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let (mut checked, mut ramped) = (0, 0);
        for trial in 0..2000 {
            let unit = |v: [f64; 3]| {
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                [v[0] / l, v[1] / l, v[2] / l]
            };
            let n = unit([rnd(), rnd(), rnd()]);
            let scale = [1e-6, 1e-3, 1.0][trial % 3];
            let u = [scale * rnd(), scale * rnd(), scale * rnd()];
            let law = Rft3d {
                zeta: 2.0e5,
                mu_surf: if trial % 2 == 0 { f64::INFINITY } else { 0.2 },
                grazing: true,
            };
            let eps = if trial % 4 < 2 { 1e-5 } else { 0.0 };
            let speed = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            let nu = n[0] * u[0] + n[1] * u[1] + n[2] * u[2];
            // Leading, or (with eps) inside the leading test's ramp, away from its ends.
            let ramp = eps > 0.0 && (0.05..0.95).contains(&(nu / eps + 1.0));
            if (nu / speed < 0.05 && !ramp) || n[2].abs() < 0.05 {
                continue;
            }
            ramped += usize::from(ramp);
            let (sig, jac) = stress_with_rate(&law, n, u, eps);
            if eps == 0.0 {
                let plain = stress(&law.lanes(), n, u);
                for k in 0..3 {
                    assert!(
                        (sig[k] - plain[k]).abs() <= 1e-12 * law.zeta,
                        "{sig:?} {plain:?}"
                    );
                }
            }
            let h = 1e-6 * speed;
            for c in 0..3 {
                let (mut up, mut dn) = (u, u);
                up[c] += h;
                dn[c] -= h;
                let (a, _) = stress_with_rate(&law, n, up, eps);
                let (b, _) = stress_with_rate(&law, n, dn, eps);
                for r in 0..3 {
                    let fd = (a[r] - b[r]) / (2.0 * h);
                    let size = jac[r]
                        .iter()
                        .map(|x| x.abs())
                        .fold(law.zeta / speed * 1e-3, f64::max);
                    assert!(
                        (fd - jac[r][c]).abs() <= 1e-5 * size,
                        "n {n:?} u {u:?} eps {eps}: d{r}/d{c} {} vs {fd}",
                        jac[r][c]
                    );
                }
            }
            checked += 1;
        }
        assert!(checked > 300 && ramped > 20, "{checked} {ramped}");
    }

    /// Both nested forms of the fitted functions (fused and not) against the sum of the
    /// table times the monomials written out, on a grid over the invariants' range.
    #[test]
    fn the_nested_forms_are_the_table_times_the_monomials() {
        let mut checked = 0;
        for i in 0..=10 {
            for j in 0..=10 {
                for k in 0..=10 {
                    let (a, b, c) = (-1.0 + 0.2 * i as f64, 0.1 * j as f64, -1.0 + 0.2 * k as f64);
                    let t = [
                        1.0,
                        a,
                        b,
                        c,
                        a * a,
                        b * b,
                        c * c,
                        a * b,
                        b * c,
                        c * a,
                        a * a * a,
                        b * b * b,
                        c * c * c,
                        a * b * b,
                        b * a * a,
                        b * c * c,
                        c * b * b,
                        c * a * a,
                        a * c * c,
                        a * b * c,
                    ];
                    let plain = fitted_as::<f64, false>(a, b, c);
                    let fused = fitted_as::<f64, true>(a, b, c);
                    for f in 0..3 {
                        let sum: f64 = (0..20).map(|m| COEFFICIENTS[f][m] * t[m]).sum();
                        assert!((plain[f] - sum).abs() < 1e-14, "{a} {b} {c}: f{f}");
                        assert!((fused[f] - sum).abs() < 1e-14, "{a} {b} {c}: f{f}");
                    }
                    assert_eq!(plain, fitted(a, b, c));
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 1331);
    }

    #[test]
    fn xi_n_is_the_cubic_in_mu() {
        // 1520 kg/m^3 and mu 0.4: 1520 * 9.81 * (894 * 0.064 - 386 * 0.16 + 35.6)
        let expect = 1520.0 * 9.81 * (57.216 - 61.76 + 35.6);
        assert!((xi_n(1520.0, 0.4) - expect).abs() < 1e-6 * expect);
    }
}
