//! `constant`: a constant force on each contact in the sand. A test fixture: the worked
//! example of adding a term (`docs/forces.md`), compiled only in the crate's own tests, and
//! run end to end by them (one file, one registry line).
//!
//! ```text
//! F = (fx, fy)   while the contact is below the surface
//! ```
//!
//! - **Source:** granrs (a test fixture).
//! - **Parameters:** `fx`, `fy` [N], default 0.
//! - **Switches:** none. **Series:** `F_cx`, `F_cy`.

use super::{Acts, Class, ContactState, Medium, Param, Rates, Real, Term, TermForce, TermInfo};

/// A constant force on each contact in the sand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constant {
    /// x component [N].
    pub fx: f64,
    /// y component [N].
    pub fy: f64,
}

impl Term for Constant {
    const INFO: TermInfo = TermInfo {
        name: "constant",
        summary: "a constant force on each contact in the sand",
        equation: "F = (fx, fy)",
        source: "granrs (a test fixture)",
        params: &[
            Param {
                name: "fx",
                unit: "N",
                default: 0.0,
                source: "-",
                min: f64::NEG_INFINITY,
                description: "x component",
                integer: false,
                max: f64::INFINITY,
            },
            Param {
                name: "fy",
                unit: "N",
                default: 0.0,
                source: "-",
                min: f64::NEG_INFINITY,
                description: "y component",
                integer: false,
                max: f64::INFINITY,
            },
        ],
        acts: Acts::Contact,
        class: Class::Static,
        velocity_dependent: false,
        reads: "nothing",
        reads_area_speed: false,
        reads_frame: false,
        shapes: super::EVERY_SHAPE,
        switches: &[],
        columns: &[("F_cx", 0), ("F_cy", 1)],
    };

    fn from_params(v: &[f64]) -> Self {
        Constant { fx: v[0], fy: v[1] }
    }

    fn params(&self) -> Vec<f64> {
        vec![self.fx, self.fy]
    }

    fn contact_force<F: Real>(&self, c: &ContactState<F>, m: &Medium<F>) -> TermForce<F> {
        self.force_with(&[F::splat(self.fx), F::splat(self.fy)], c, m)
    }

    fn force_with<F: Real>(&self, p: &[F], _c: &ContactState<F>, _m: &Medium<F>) -> TermForce<F> {
        TermForce::force([p[0], p[1]])
    }

    /// None: the force is the same at every velocity and depth.
    fn rates(&self, _c: &ContactState<f64>, _m: &Medium<f64>) -> Rates {
        Rates::NONE
    }
}

#[cfg(test)]
mod tests {
    use crate::forces::{ForceSet, TermSpec};
    use crate::integrate::{EndCondition, Record};
    use crate::presets::{free_link::FreeLink, Setting, Start};

    /// A new term takes one file and one registry line, and then runs. A vertical
    /// rod already in the sand, pushed up by a constant 2 m g at its tip against gravity,
    /// decelerates at exactly g: it stops at t = v0 / g, v0^2 / (2 g) deeper.
    #[test]
    fn a_constant_force_term_runs_end_to_end() {
        let rod = FreeLink {
            q_deg: 0.0,
            start: Start {
                v0: 1.5,
                depth0: 0.01,
                vx0: 0.0,
            },
            ..Default::default()
        };
        let mut scene = rod.scene(Setting::default());
        let (m, g) = (rod.rod.mass, scene.medium.g);
        scene.forces = ForceSet::build(
            &[
                TermSpec::new("gravity", &[]),
                TermSpec::new("constant", &[("fy", 2.0 * m * g)]),
            ],
            1,
        )
        .unwrap();
        scene.options.end = EndCondition::FirstStop;
        scene.options.record = Record {
            forces: true,
            ..Default::default()
        };
        let out = scene.run().unwrap();
        let c = &out.contacts[0];
        assert!(c.stopped);
        assert!((c.t_s - 1.5 / g).abs() < 1e-9, "t_s {}", c.t_s);
        let depth = 0.01 + 1.5 * 1.5 / (2.0 * g);
        assert!((c.depth - depth).abs() < 1e-9 * depth, "depth {}", c.depth);
        let series = out.series.unwrap();
        let fy = &series
            .columns
            .iter()
            .find(|(n, _)| n == "c0.F_cy")
            .unwrap()
            .1;
        assert!(fy.iter().all(|&f| f == 2.0 * m * g));
        assert_eq!(out.terms, vec!["gravity", "constant"]);
    }
}
