//! Properties of the force law over its whole valid domain (issue 6), with proptest:
//! finite everywhere, zero above the surface, every term dissipative with respect to the
//! velocity of the immersed centroid, mirror symmetric, and the static terms growing with
//! depth. Evaluated through `evaluate::evaluate`, the same path as
//! `granrs.resistance_force`, which wraps `force::resistance::rod_force`.

use proptest::prelude::*;

use _granrs::evaluate::{evaluate, RodSetup, Sign, OUTPUTS};
use _granrs::forces::{Coefficients, ForceSet, Medium};

const F_X: usize = 0;
const F_Y: usize = 1;
const F_DX: usize = 2;
const F_DY: usize = 3;
const F_SH: usize = 4;
const F_SV: usize = 5;

fn setup(length: f64, diameter: f64, rho_g: f64, sign: Sign) -> RodSetup {
    RodSetup {
        length,
        diameter,
        medium: Medium { rho_g, g: 9.81 },
        forces: ForceSet::thesis(&[Coefficients::TABLE_3_4_VERTICAL]),
        sign,
    }
}

fn eval(s: &RodSetup, input: [f64; 9]) -> [f64; 10] {
    let mut out = [0.0; OUTPUTS.len()];
    evaluate(s, input, &mut out);
    out
}

/// Inputs over the valid domain: coefficients 0..10x Table 3.4 (q = 0 row), angles in
/// (-90, 90), speeds up to 10 m/s, spins up to 100 rad/s, depths up to twice the rod.
fn state() -> impl Strategy<Value = [f64; 9]> {
    (
        0.0..0.4f64,
        -89.999..89.999f64,
        -10.0..10.0f64,
        -10.0..10.0f64,
        -100.0..100.0f64,
        0.0..65.0f64,
        0.0..152.0f64,
        0.0..2480.0f64,
        0.0..3.0f64,
    )
        .prop_map(|(d, q, vx, vy, w, h, dd, v, lam)| [d, q, vx, vy, w, h, dd, v, lam])
}

fn sign() -> impl Strategy<Value = Sign> {
    prop_oneof![Just(Sign::Raw), (1e-6..1.0f64).prop_map(Sign::Smooth)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn finite_everywhere(input in state(), sign in sign(), length in 0.01..2.0f64,
                         diameter in 1e-4..0.1f64, rho in 100.0..3000.0f64) {
        let out = eval(&setup(length, diameter, rho, sign), input);
        prop_assert!(out.iter().all(|x| x.is_finite()), "{:?} -> {:?}", input, out);
    }

    #[test]
    fn nothing_above_the_surface(mut input in state(), sign in sign(), up in 0.0..1.0f64) {
        input[0] = -up;
        let out = eval(&setup(0.19, 0.0127, 1650.0, sign), input);
        prop_assert!(out[..6].iter().all(|&x| x == 0.0), "{:?}", out);
    }

    #[test]
    fn every_term_opposes_the_centroid_velocity(input in state(), sign in sign()) {
        let out = eval(&setup(0.19, 0.0127, 1650.0, sign), input);
        // v_E from the outputs: E - T = (l/2) e, so v_E = v_T + omega (E_y, -E_x).
        let (ex, ey) = (out[7], out[8]);
        let v = (input[2] + input[4] * ey, input[3] - input[4] * ex);
        prop_assert!(out[F_DX] * v.0 + out[F_DY] * v.1 <= 0.0);
        prop_assert!(out[F_SH] * v.0 <= 0.0);
        prop_assert!(out[F_SV] * v.1 <= 0.0);
    }

    #[test]
    fn mirror_symmetric(input in state(), sign in sign()) {
        let s = setup(0.19, 0.0127, 1650.0, sign);
        let a = eval(&s, input);
        let mut m = input;
        m[1] = -m[1]; // q
        m[2] = -m[2]; // vx
        m[4] = -m[4]; // omega
        let b = eval(&s, m);
        let tol = |x: f64| 1e-12 * x.abs().max(1e-300) + 1e-300;
        prop_assert!((a[F_X] + b[F_X]).abs() <= tol(a[F_X]), "{} vs {}", a[F_X], b[F_X]);
        prop_assert!((a[F_Y] - b[F_Y]).abs() <= tol(a[F_Y]), "{} vs {}", a[F_Y], b[F_Y]);
        prop_assert!((a[F_SH] + b[F_SH]).abs() <= tol(a[F_SH]));
        prop_assert!((a[F_SV] - b[F_SV]).abs() <= tol(a[F_SV]));
    }

    #[test]
    fn static_terms_never_shrink_with_depth(input in state(), deeper in 0.0..0.2f64) {
        // Fixed signs (sinking, moving right) so only the magnitudes are compared.
        let s = setup(0.19, 0.0127, 1650.0, Sign::Raw);
        let mut a = input;
        a[2] = 1.0;
        a[3] = -1.0;
        a[4] = 0.0;
        let mut b = a;
        b[0] += deeper;
        let (fa, fb) = (eval(&s, a), eval(&s, b));
        prop_assert!(fb[F_SV] >= fa[F_SV] * (1.0 - 1e-12));
        prop_assert!(fb[F_SH].abs() >= fa[F_SH].abs() * (1.0 - 1e-12));
    }
}

#[test]
fn no_static_force_at_rest_for_either_sign_model() {
    // v_E = 0 exactly: the raw sign gives no static force; tanh gives none either.
    for sign in [Sign::Raw, Sign::Smooth(1e-3)] {
        let out = eval(
            &setup(0.19, 0.0127, 1650.0, sign),
            [0.05, 20.0, 0.0, 0.0, 0.0, 6.5, 15.2, 248.0, 0.106],
        );
        assert_eq!(&out[..6], &[0.0; 6]);
    }
}
