//! `axial_drag`: a quadratic drag along a rod's axis, on its end face, at the immersed
//! centroid E.
//!
//! ```text
//! F = - eta_a rho_g (pi d_c^2 / 4) |v_a| v_a e,     v_a = e . v_E
//! ```
//!
//! with `e` the rod's unit axis (from its tip towards its top) and `v_E` the velocity of the
//! immersed centroid E. It is the inertial (Poncelet) drag of the sand the rod's end face
//! pushes aside, for the part of the motion along the axis only: the thesis's drag
//! (`drag`) needs a velocity across the rod (its reference area is d_c l |e x v^|), so a rod
//! sinking along its axis feels no velocity-dependent force under the thesis's law, and the
//! thesis's vertical drops (Table 3.1, q = 0) cannot match their depths and their stopping
//! times together without one (`docs/calibration.md`). Unlike `poncelet`'s drag, it acts
//! along `e`, not along `v_E`: the broadside motion stays `drag`'s.
//!
//! The area is the end face, pi d_c^2 / 4, whatever the immersed length: in
//! Katsuragi & Durian's impact law the inertial drag is the momentum given to the sand
//! ahead of the body, set by its cross-section, not by how deep it is (a drag growing with
//! the immersed length would vanish at the entry, where the rod is fastest). The force is
//! finite from the moment the tip enters (reading the frame makes the entry a located
//! event). Its coefficient is dimensionless and scaled by the medium's rho_g and the rod's
//! face, like the thesis's `eta_d`, so that one value describes the sand for rods of any
//! diameter; in kg/m it is `c_a = eta_a rho_g pi d_c^2 / 4` (the thesis's rod, d_c = 12.7 mm,
//! in its sand, rho_g = 1650 kg/m^3: `c_a = 0.209 eta_a` kg/m).
//!
//! It dissipates: with `v_a` the axial speed, `F . v_E = - eta_a rho_g A |v_a|^3 <= 0`. It
//! acts at E (its moment about E is zero; it returns its moment about the point of
//! application P). It is symmetric in the sign of `v_a`: a rod pulled out along its axis is
//! braked alike.
//!
//! - **Source:** Katsuragi & Durian, "Unified force law for granular impact cratering",
//!   Nature Physics 3 (2007) 420, eq. 1 (the inertial term, m / d1 = eta_a rho_g A), taken
//!   along the rod's axis; the need for it: the thesis's vertical drops (Table 3.1).
//! - **Parameters:** `eta_a` [-], the axial drag coefficient on the end face. Required: it is
//!   fitted per medium (`granrs.media`; the laws chapter fits it to Table 3.1).
//! - **Reads:** the medium's rho_g; the contact's axis, outline (d_c), E and v_E, and the
//!   held signs of v_E (sticking).
//! - **Switches:** none: the force is smooth (C1) in v_E, and zero at v_a = 0.
//! - **Series:** `F_ax`, `F_ay`.

use super::{
    Acts, Boundary, Class, ContactKind, ContactState, Medium, Outline, Param, Rates, Real, Term,
    TermForce, TermInfo,
};

/// The quadratic drag along a rod's axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxialDrag {
    /// Axial drag coefficient eta_a [-] on the end face.
    pub eta_a: f64,
}

impl AxialDrag {
    /// The end face's area pi d_c^2 / 4 [m^2] (zero on an outline that is not a rod: such a
    /// contact is refused before any work, `Linkage::validate_terms_on_shapes`).
    #[inline(always)]
    fn face<F: Real>(b: &Boundary<F>) -> F {
        match b.outline {
            Outline::Rod { diameter, .. } => {
                F::splat(std::f64::consts::FRAC_PI_4) * diameter * diameter
            }
            Outline::Box { .. } | Outline::Arc { .. } => F::splat(0.0),
        }
    }

    /// E's velocity with the components held at zero by a sticking reaction removed, and
    /// its component along the axis.
    #[inline(always)]
    fn axial<F: Real>(b: &Boundary<F>) -> ([F; 2], F) {
        let one = F::splat(1.0);
        let [hx, hy] = b.held;
        let v = [(one - hx) * b.v_centroid[0], (one - hy) * b.v_centroid[1]];
        let e = b.frame.axis;
        (v, e[0] * v[0] + e[1] * v[1])
    }
}

impl Term for AxialDrag {
    const INFO: TermInfo = TermInfo {
        name: "axial_drag",
        summary: "quadratic drag along a rod's axis, on its end face, at the immersed centroid E",
        equation: "F = -eta_a rho_g (pi d_c^2 / 4) |v_a| v_a e  at E,  v_a = e . v_E (e: the \
                   rod's axis)",
        source: "Katsuragi & Durian, Nature Physics 3 (2007) 420, eq. 1 (the inertial term), \
                 along the rod's axis",
        params: &[Param {
            name: "eta_a",
            unit: "-",
            default: f64::NAN,
            source: "none: fitted per medium (c_a = eta_a rho_g pi d_c^2 / 4 [kg/m]; \
                     granrs.media)",
            min: 0.0,
            description: "axial drag coefficient on the rod's end face",
            integer: false,
            max: f64::INFINITY,
        }],
        acts: Acts::Contact,
        class: Class::Dynamic,
        velocity_dependent: true,
        reads: "rho_g; the contact's axis e, diameter d_c, E and v_E; the held signs of v_E \
                (sticking)",
        reads_area_speed: false,
        reads_frame: true,
        shapes: &[ContactKind::Rod],
        switches: &[],
        columns: &[("F_ax", 0), ("F_ay", 1)],
    };

    fn from_params(values: &[f64]) -> Self {
        AxialDrag { eta_a: values[0] }
    }

    fn params(&self) -> Vec<f64> {
        vec![self.eta_a]
    }

    #[inline(never)]
    fn contact_force<F: Real>(&self, c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        self.force_with(&[F::splat(self.eta_a)], c, m)
    }

    fn force_with<F: Real>(&self, p: &[F], c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        let zero = F::splat(0.0);
        let Some(b) = c.boundary else {
            return TermForce::force([zero; 2]);
        };
        let one = F::splat(1.0);
        let (_, v_a) = Self::axial(b);
        let k = -(p[0] * m.rho_g * Self::face(b) * v_a.abs() * v_a);
        let e = b.frame.axis;
        // No force along an axis held at zero: the sticking reaction stands in.
        let [hx, hy] = b.held;
        let force = [(one - hx) * k * e[0], (one - hy) * k * e[1]];
        // It acts at E: its moment about P.
        let r = [b.centroid[0] - b.apply[0], b.centroid[1] - b.apply[1]];
        TermForce {
            force,
            bound: [zero; 2],
            moment: r[0] * force[1] - r[1] * force[0],
        }
    }

    /// A quadratic drag along e: `dF/dv = -2 eta_a rho_g A |v_a| e e^T`, at most
    /// `2 eta_a rho_g A |v_a|`; it does not change with depth (the face is the same).
    fn rates(&self, c: &ContactState<f64>, m: &Medium<f64>) -> Rates {
        let Some(b) = c.boundary else {
            return Rates::NONE;
        };
        let (_, v_a) = Self::axial(b);
        Rates {
            damping: 2.0 * self.eta_a * m.rho_g * Self::face(b) * v_a.abs(),
            spring: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::body::rod::ApplyAt;
    use crate::dynamics::SignModel;
    use crate::evaluate::geoms::{GeomShape, SandGeoms};
    use crate::forces::{ForceSet, Medium, TermSpec};
    use crate::integrate::{EndCondition, Record};
    use crate::presets::{free_link::FreeLink, Setting, Start};

    const D_C: f64 = 0.0127;

    fn geoms(eta_a: f64, apply_at: ApplyAt) -> SandGeoms {
        let forces =
            ForceSet::build(&[TermSpec::new("axial_drag", &[("eta_a", eta_a)])], 1).unwrap();
        SandGeoms::new(
            &["rod".into()],
            &[GeomShape::Rod {
                diameter: D_C,
                length: 0.19,
            }],
            &forces,
            Medium::default(),
            apply_at,
            SignModel::Raw,
        )
        .unwrap()
    }

    /// A vertical rod sinking at a constant 1.3 m/s feels, by hand,
    /// eta_a rho_g (pi d_c^2 / 4) v^2 upward, whatever its depth, and no moment.
    #[test]
    fn a_vertical_rod_at_constant_speed_feels_the_face_drag() {
        let g = geoms(6.0, ApplyAt::Tip);
        let by_hand = 6.0 * 1650.0 * std::f64::consts::PI * D_C * D_C / 4.0 * 1.3 * 1.3;
        for depth in [0.01, 0.05, 0.12] {
            let mut out = [0.0; 18];
            g.evaluate(0, &[0.0, -depth, 0.0, 1.0, 0.0, -1.3, 0.0], &mut out);
            assert!((out[1] - by_hand).abs() < 1e-12 * by_hand, "{out:?}");
            assert_eq!(out[0], 0.0);
            assert_eq!(out[2], 0.0);
        }
        // Moving up along its axis, it is braked alike (pointing down).
        let mut out = [0.0; 18];
        g.evaluate(0, &[0.0, -0.05, 0.0, 1.0, 0.0, 1.3, 0.0], &mut out);
        assert!((out[1] + by_hand).abs() < 1e-12 * by_hand, "{out:?}");
    }

    /// A tilted rod moving at an angle to its axis: only the axial part of v_E is braked,
    /// along e, so F . v_E = -eta_a rho_g A |v_a|^3 (it dissipates), and F x e = 0. At the
    /// tip it has the moment of a force at E.
    #[test]
    fn an_oblique_rod_is_braked_along_its_axis_only_and_dissipates() {
        let q = 0.6f64;
        let (sx, cx) = q.sin_cos();
        let face = 1650.0 * std::f64::consts::PI * D_C * D_C / 4.0;
        for (vx, vy, omega) in [(0.7, -1.1, 0.0), (-0.4, -0.9, 2.0), (1.0, 0.3, -3.0)] {
            let mut out = [0.0; 18];
            let state = [0.0, -0.04, sx, cx, vx, vy, omega];
            geoms(4.0, ApplyAt::Centroid).evaluate(0, &state, &mut out);
            let (ex, ey) = (sx, cx);
            let v_e = [out[9], out[10]];
            let v_a = ex * v_e[0] + ey * v_e[1];
            let by_hand = [
                -4.0 * face * v_a.abs() * v_a * ex,
                -4.0 * face * v_a.abs() * v_a * ey,
            ];
            let scale = 4.0 * face * v_a * v_a;
            assert!((out[0] - by_hand[0]).abs() < 1e-12 * scale, "{out:?}");
            assert!((out[1] - by_hand[1]).abs() < 1e-12 * scale, "{out:?}");
            let power = out[0] * v_e[0] + out[1] * v_e[1];
            assert!(power <= 0.0);
            assert!((power + 4.0 * face * v_a.abs().powi(3)).abs() < 1e-12 * scale);
            // Applied at E: no moment about E (to rounding: P and E are computed apart).
            assert!(out[2].abs() <= 1e-15 * scale, "{out:?}");
            // Applied at the tip: r x F with r = E - T.
            let mut tip = [0.0; 18];
            geoms(4.0, ApplyAt::Tip).evaluate(0, &state, &mut tip);
            let r = [tip[5], tip[6] + 0.04];
            let moment = r[0] * tip[1] - r[1] * tip[0];
            assert!((tip[2] - moment).abs() <= 1e-12 * scale * 0.2, "{tip:?}");
        }
    }

    /// A vertical rod with only gravity and the axial drag, dropped at 3 m/s: along its
    /// path m v dv/dd = m g - c v^2 with c = eta_a rho_g pi d_c^2 / 4 constant, so
    /// v^2(d) = v_t^2 + (v0^2 - v_t^2) exp(-2 c d / m), v_t^2 = m g / c (a closed form, not
    /// the engine's). Every recorded (depth, speed) pair lies on it.
    #[test]
    fn a_vertical_drop_follows_the_closed_form_speed_in_depth() {
        let (v0, eta_a) = (3.0, 30.0);
        let rod = FreeLink {
            q_deg: 0.0,
            start: Start {
                v0,
                depth0: 0.0,
                vx0: 0.0,
            },
            ..Default::default()
        };
        let mut scene = rod.scene(Setting::default());
        let (m, g) = (rod.rod.mass, scene.medium.g);
        let c = eta_a * scene.medium.rho_g * std::f64::consts::PI * D_C * D_C / 4.0;
        assert_eq!(rod.rod.diameter, D_C);
        scene.forces = ForceSet::build(
            &[
                TermSpec::new("gravity", &[]),
                TermSpec::new("axial_drag", &[("eta_a", eta_a)]),
            ],
            1,
        )
        .unwrap();
        scene.options.end = EndCondition::Time;
        scene.options.t_end = 0.08;
        scene.options.record = Record {
            forces: true,
            ..Default::default()
        };
        let out = scene.run().unwrap();
        let series = out.series.unwrap();
        let col = |name: &str| {
            &series
                .columns
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("{name}"))
                .1
        };
        let (depth, vy) = (col("c0.depth"), col("c0.v_tip_y"));
        let v_t2 = m * g / c;
        let mut checked = 0;
        let mut last = 0.0;
        for (&d, &v) in depth.iter().zip(vy) {
            if d <= 0.0 {
                continue;
            }
            let closed = v_t2 + (v0 * v0 - v_t2) * (-2.0 * c * d / m).exp();
            assert!(
                (v * v - closed).abs() < 1e-7 * v0 * v0,
                "d {d} v {v} closed {closed}"
            );
            checked += 1;
            last = d;
        }
        // The drop slowed from v0 towards v_t over several decay lengths m / (2 c).
        assert!(
            checked > 100 && last > 2.0 * m / (2.0 * c),
            "{checked} {last}"
        );
        assert!(v_t2 < 0.5 * v0 * v0);
    }
}
