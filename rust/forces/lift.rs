//! `lift`: a uniform upward pull on every mass, a fraction of its weight. A test fixture: the
//! worked example of adding a body term (`docs/forces.md`), compiled only in the crate's own
//! tests, and run end to end by them (one file, one registry line).
//!
//! ```text
//! F_i = f m_i g (0, 1)   at each link's centre of mass
//! ```
//!
//! - **Source:** granrs (a test fixture).
//! - **Parameters:** `f` [1], the fraction of the weight, default 0.
//! - **Energy:** its potential energy, -f m g y, is part of the body's (the field's).

use super::{Acts, Class, ContactState, Medium, Param, Rates, Real, Term, TermForce, TermInfo};

/// An upward pull of `f` times the weight on every mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lift {
    /// The fraction of the weight [1].
    pub f: f64,
}

impl Term for Lift {
    const INFO: TermInfo = TermInfo {
        name: "lift",
        summary: "an upward pull on every mass, a fraction of its weight",
        equation: "F_i = f m_i g y_hat  (each link i)",
        source: "granrs (a test fixture)",
        params: &[Param {
            name: "f",
            unit: "1",
            default: 0.0,
            source: "-",
            min: 0.0,
            description: "the fraction of the weight",
            integer: false,
            max: 1.0,
        }],
        acts: Acts::Body,
        class: Class::Static,
        velocity_dependent: false,
        reads: "each link's mass and centre of mass; g of the medium",
        reads_area_speed: false,
        reads_frame: false,
        shapes: super::EVERY_SHAPE,
        switches: &[],
        columns: &[],
    };

    fn from_params(v: &[f64]) -> Self {
        Lift { f: v[0] }
    }

    fn params(&self) -> Vec<f64> {
        vec![self.f]
    }

    /// None: a body term has no contact force.
    fn force_with<F: Real>(&self, _p: &[F], _c: &ContactState<F>, _m: &Medium<F>) -> TermForce<F> {
        TermForce::force([F::splat(0.0); 2])
    }

    /// None at a contact: a constant force on each link.
    fn rates(&self, _c: &ContactState<f64>, _m: &Medium<f64>) -> Rates {
        Rates::NONE
    }

    /// `-f` of the medium's g: up.
    fn field(&self) -> f64 {
        -self.f
    }
}

#[cfg(test)]
mod tests {
    use crate::forces::{ForceSet, TermSpec};
    use crate::integrate::EndCondition;
    use crate::presets::{free_link::FreeLink, Setting, Start};

    /// A new body term takes one file and one registry line, and then runs. A vertical rod
    /// already in the sand, under gravity, `lift` at half its weight and a constant push of
    /// m g up at its tip, decelerates at exactly g / 2: it stops at t = 2 v0 / g, v0^2 / g
    /// deeper, and its energy (the field's potential m g y / 2 included) falls by the
    /// push's work alone.
    #[test]
    fn a_body_term_runs_end_to_end() {
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
                TermSpec::new("lift", &[("f", 0.5)]),
                TermSpec::new("constant", &[("fy", m * g)]),
            ],
            1,
        )
        .unwrap();
        scene.options.end = EndCondition::FirstStop;
        let out = scene.run().unwrap();
        let c = &out.contacts[0];
        assert!(c.stopped);
        assert!((c.t_s - 2.0 * 1.5 / g).abs() < 1e-9, "t_s {}", c.t_s);
        let sink = 1.5 * 1.5 / g;
        assert!((c.depth - (0.01 + sink)).abs() < 1e-9, "depth {}", c.depth);
        // Kinetic energy 1/2 m v0^2 and the field's m (g / 2) sink go into the push's m g sink.
        let lost = out.energy_start - out.energy_end;
        let want = 0.5 * m * 1.5 * 1.5 + 0.5 * m * g * sink;
        assert!(
            (lost - want).abs() < 1e-9 * want,
            "lost {lost}, want {want}"
        );
        assert_eq!(out.terms, vec!["gravity", "lift", "constant"]);
    }
}
