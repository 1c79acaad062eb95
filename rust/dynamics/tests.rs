//! The free link's closed form against the general engine, and the inverse effective mass.

use super::*;
use crate::presets::{free_link::FreeLink, Setting};
use nalgebra::Matrix2;
use proptest::prelude::*;

fn slip(i: u8) -> Slip {
    [Slip::Neg, Slip::Pos, Slip::Stick][i as usize % 3]
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-13 * scale.max(a.abs()).max(b.abs())
}

/// The thesis's terms at Table 3.4's q = 0 row, those of `mask` only (bits: gravity,
/// drag, static_h, static_v), on `n` contacts.
pub(crate) fn thesis_subset(mask: u8, n: usize) -> ForceSet {
    use crate::forces::TermSpec;
    let all = [
        TermSpec::new("gravity", &[]),
        TermSpec::new("drag", &[("eta_d", 15.2)]),
        TermSpec::new("static_h", &[("eta_h", 6.5)]),
        TermSpec::new("static_v", &[("eta_v", 248.0), ("lam", 0.106)]),
    ];
    let specs: Vec<TermSpec> = all
        .into_iter()
        .enumerate()
        .filter(|(i, _)| mask & (1 << i) != 0)
        .map(|(_, t)| t)
        .collect();
    ForceSet::build(&specs, n).unwrap()
}

proptest! {
    /// The free link's closed-form evaluation (its kernel, `Model::eval_free_link`) is the
    /// general engine's (`eval_general`: the pose, the mass matrix and the constraint rows
    /// of any body) to round-off, for every sign model, point of application, mode (x and y
    /// stuck together: two rows), term switched off, a reaction that several static terms
    /// share (`shared`), and a point mass at the root.
    #[test]
    fn rigid_rod_path_is_the_general_engine(
        x in -0.1f64..0.1, y in -0.12f64..0.12, th in -1.55f64..1.55,
        // w = 0 exactly: a stuck rod without spin skips the bias of its sticking rows.
        vx in -3.0f64..3.0, vy in -3.0f64..3.0,
        w in prop_oneof![Just(0.0f64), -30.0f64..30.0],
        sign in 0u8..3, centroid in any::<bool>(), in_contact in any::<bool>(),
        sx in 0u8..3, sy in 0u8..3, cross in 0u8..2, effects in 0u8..16,
        root_mass in prop_oneof![Just(0.0f64), Just(0.05f64)],
        shared in any::<bool>(),
    ) {
        let mut model = FreeLink::default()
            .scene(Setting {
                apply_at: if centroid { ApplyAt::Centroid } else { ApplyAt::Tip },
                sign_model: [
                    SignModel::Modes,
                    SignModel::Raw,
                    SignModel::Smooth { eps: 1e-3 },
                ][sign as usize],
                ..Setting::default()
            })
            .model::<3>();
        model.mechanism.root_mass = root_mass;
        model.forces = if shared {
            // `poncelet` owns both slip switches, with `static_h` x's and `static_v` y's:
            // a reaction along either axis is shared.
            use crate::forces::TermSpec;
            let mut specs = vec![
                TermSpec::new("poncelet", &[("c", 0.8), ("k", 150.0)]),
                TermSpec::new("static_h", &[("eta_h", 6.5)]),
                TermSpec::new("static_v", &[("eta_v", 248.0), ("lam", 0.106)]),
            ];
            if effects & 1 != 0 {
                specs.insert(0, TermSpec::new("gravity", &[]));
            }
            let set = ForceSet::build(&specs, 1).unwrap();
            prop_assert_eq!(set.sole_static_owner, [None, None]);
            set
        } else {
            thesis_subset(effects, 1)
        };
        let rod = model.rigid_rod().copied();
        prop_assert!(rod.is_some());
        let mut modes: Modes = [ContactMode::default(); MAX_CONTACTS];
        modes[0] = ContactMode {
            in_contact,
            sx: slip(sx),
            sy: slip(sy),
            cross: slip(cross),
            ..ContactMode::default()
        };
        let q = SVector::<f64, 3>::new(x, y, th);
        let qd = SVector::<f64, 3>::new(vx, vy, w);
        let a = model.eval(&q, &qd, &modes);
        prop_assert!(model.rigid_rod().is_some());
        let mut a_into = model.eval(&q, &qd, &modes);
        a_into.qdd *= 2.0;
        a_into.contacts[0].depth = -1.0;
        model.eval_into(&q, &qd, &modes, &mut a_into);
        prop_assert_eq!(a.qdd, a_into.qdd);
        prop_assert_eq!(a.contacts, a_into.contacts);
        let (qdd, power, joint_power) = model.rates(&q, &qd, &modes);
        prop_assert_eq!((qdd, power, joint_power), (a.qdd, a.power, a.joint_power));
        let b = model.eval_general(&q, &qd, &modes);
        // `poncelet` reads the frame, so it acts from the moment of entry; at depth 0 the
        // free link's path holds its sticking rows there too, the general engine only below
        // the surface (`constraint_rows`): not compared.
        if shared && in_contact && a.contacts[0].depth <= 0.0 {
            return Ok(());
        }
        let scale = b.qdd.amax().max(model.medium.g);
        // The angular acceleration is a force times a lever over I = m L^2 / 12: its
        // round-off scale is that of the linear ones times 12 / L (seen: 3.6e-12 rad/s^2
        // against 0 for a stuck rod at rest, where the linear scale gave 1e-12).
        let length = 0.19;
        for i in 0..3 {
            let s = if i == 2 { scale * 12.0 / length } else { scale };
            prop_assert!(close(a.qdd[i], b.qdd[i], s), "qdd {:?} vs {:?}", a.qdd, b.qdd);
        }
        // Power is a force times a speed: its round-off scale is m a |v| (seen: 4e-14 W
        // against 0 with an absolute scale of 1e-12).
        let p_scale = FreeLink::default().rod.mass * scale * qd.amax() * (1.0 + length);
        prop_assert!(close(a.power, b.power, p_scale.max(1e-12)), "{} vs {}", a.power, b.power);
        let (ca, cb) = (&a.contacts[0], &b.contacts[0]);
        let pairs = [
            (ca.tip.x, cb.tip.x), (ca.tip.y, cb.tip.y), (ca.v_tip.x, cb.v_tip.x),
            (ca.v_tip.y, cb.v_tip.y), (ca.depth, cb.depth), (ca.lowest, cb.lowest),
            (ca.v_centroid.x, cb.v_centroid.x), (ca.v_centroid.y, cb.v_centroid.y),
            (ca.force.dynamic.x, cb.force.dynamic.x), (ca.force.dynamic.y, cb.force.dynamic.y),
            (ca.force.statics.x, cb.force.statics.x), (ca.force.statics.y, cb.force.statics.y),
            (ca.cross, cb.cross), (ca.immersion_margin, cb.immersion_margin),
            (ca.bound[0], cb.bound[0]), (ca.bound[1], cb.bound[1]),
        ];
        // A sticking reaction (fields 10, 11) solves for what holds E against every
        // force on the body: its round-off scale is the body's m a (seen: 1.1e-16 N on
        // a 8.7e-4 N reaction of a rod stuck both ways, against m g = 1.8 N).
        let f_scale = (model.mechanism.links[0].mass + root_mass) * scale;
        for (i, (u, v)) in pairs.into_iter().enumerate() {
            let s = if i == 10 || i == 11 { f_scale } else { 1e-12 };
            prop_assert!(close(u, v, s), "field {i}: {u} vs {v}");
        }
        // Each term's force, a reaction (whole, or its share) in place of its static
        // terms, and the terms' moment.
        for (k, (u, v)) in ca.force.terms.iter().zip(&cb.force.terms).enumerate() {
            for i in 0..2 {
                prop_assert!(close(u[i], v[i], f_scale), "term {k}: {u} vs {v}");
            }
        }
        prop_assert!(close(ca.force.moment, cb.force.moment, f_scale * length));
        prop_assert_eq!(&a.contacts[1..], &b.contacts[1..]);
    }
}

proptest! {
    /// The rod's closed-form projection onto its sticking rows is the general one; and
    /// where `sticking_may_drift` lets the solver skip it (`exact`: no spin, no drift),
    /// it would have changed nothing.
    #[test]
    fn rigid_rod_projection_is_the_general_engine(
        th in -1.5f64..1.5, depth in 0.001f64..0.1, vy in -3.0f64..3.0,
        w in -30.0f64..30.0, drift in -5e-7f64..5e-7, sx in 0u8..3, sy in 0u8..3,
        exact in any::<bool>(),
    ) {
        let (w, drift) = if exact { (0.0, 0.0) } else { (w, drift) };
        let model = FreeLink::default().scene(Setting::default()).model::<3>();
        let mut modes: Modes = [ContactMode::default(); MAX_CONTACTS];
        modes[0] = ContactMode {
            in_contact: true,
            sx: slip(sx),
            sy: slip(sy),
            ..ContactMode::default()
        };
        // The tip `depth` deep; v_E within `drift` of zero along each stuck axis.
        let half = 0.5 * model.contacts[0].reference_point().x.abs();
        let q = SVector::<f64, 3>::new(0.0, half * th.cos() - depth, th);
        let mut qd = SVector::<f64, 3>::new(0.0, vy, w);
        let v_e = model.eval_general(&q, &qd, &modes).contacts[0].v_centroid;
        if modes[0].sx == Slip::Stick {
            qd[0] -= v_e.x - drift;
        }
        if modes[0].sy == Slip::Stick {
            qd[1] -= v_e.y + drift;
        }
        let (mut a, mut b) = (qd, qd);
        let changed_a = model.project_sticking(&q, &mut a, &modes);
        let changed_b = model.any_stuck(&modes)
            && model.project_sticking_general(&q, &mut b, &modes);
        prop_assert_eq!(changed_a, changed_b);
        for i in 0..3 {
            prop_assert!(close(a[i], b[i], 1e-9), "{a:?} vs {b:?}");
        }
        if !model.sticking_may_drift(&model.eval(&q, &qd, &modes), &modes) {
            prop_assert!(!changed_a && a == qd, "skipped a projection: {qd:?} to {a:?}");
        }
    }
}

/// Any other body keeps the general engine.
#[test]
fn centroid_inverse_mass_of_a_rod_and_of_a_locked_chain() {
    // A free rod at q = 0.3 with its tip 0.05 m deep: E is l/2 above the tip, at
    // r = L/2 - l/2 from the centre; the trace is 2/m + r^2/I.
    let model = FreeLink::default().scene(Setting::default()).model::<3>();
    let link = &model.mechanism.links[0];
    let (m, inertia, big_l) = (link.mass, link.inertia, 0.19);
    let q0: f64 = 0.3;
    let depth = 0.05;
    let y = -depth + 0.5 * big_l * q0.cos();
    let w = model.centroid_inverse_mass(&SVector::<f64, 3>::new(0.0, y, q0), 0);
    // E = centre - r e; its velocity per unit force: 1/m + (r e_perp)(r e_perp)^T / I.
    let r = 0.5 * big_l - 0.5 * depth / q0.cos();
    let lever = Vector2::new(q0.cos(), -q0.sin()) * r;
    let expected = Matrix2::identity() / m + lever * lever.transpose() / inertia;
    assert!(
        (w - expected).norm() < 1e-9 * expected.norm(),
        "{w} {expected}"
    );
    // A chain: locking the pin can only make the tip's E heavier.
    use crate::body::mechanism::Joint;
    use crate::presets::chain::Chain;
    let q = SVector::<f64, 4>::new(0.0, 0.0, 0.2, 0.5);
    let chain = |joint| {
        Chain {
            joint,
            ..Chain::default()
        }
        .scene(Setting::default())
        .model::<4>()
    };
    let (free, locked) = (chain(Joint::Free), chain(Joint::Locked));
    let last = free.contacts.len() - 1;
    let (wf, wl) = (
        free.centroid_inverse_mass(&q, last),
        locked.centroid_inverse_mass(&q, last),
    );
    let (tl, tf) = (wl.trace(), wf.trace());
    assert!(tl.is_finite() && tl > 0.0 && tl < tf, "{wl} {wf}");
    assert!(wl.symmetric_eigenvalues().min() >= -1e-12 * tl, "{wl}");
}

#[test]
fn only_a_rod_about_its_centre_of_mass_is_closed_form() {
    let mut model = FreeLink::default().scene(Setting::default()).model::<3>();
    assert!(model.rigid_rod().is_some());
    model.mechanism.links[0].com = Vector2::new(0.01, 0.0);
    assert!(model.rigid_rod().is_none());
}

/// An arc's outline, as the terms walk it, runs through the arc's own vertices (placed on
/// the link by the mechanism): the world turn from one to the next has the sign of the
/// link's frame (phi from +s towards +n, a clockwise turn in the world).
#[test]
fn an_arc_outline_walks_its_vertices() {
    use crate::body::{ArcContact, Joint, Link, Mechanism};
    let arc = ArcContact {
        link: 0,
        centre: Vector2::new(0.03, 0.01),
        radius: 0.03,
        start: 2.5,
        span: 4.0,
        width: 0.01,
        chords: 7,
    };
    let model = Model::<3> {
        mechanism: Mechanism {
            links: vec![Link {
                mass: 0.1,
                inertia: 1e-4,
                com: Vector2::zeros(),
                parent: None,
                joint_on_parent: Vector2::zeros(),
                joint: Joint::Free,
            }],
            root_mass: 0.0,
            root_fixed: true,
            root_rate: Some(3.0),
        },
        contacts: vec![Contact {
            shape: Shape::Arc(arc),
        }],
        medium: Default::default(),
        apply_at: ApplyAt::Tip,
        sign_model: SignModel::Modes,
        forces: thesis_subset(1, 1),
    };
    let q = SVector::<f64, 3>::new(0.1, -0.02, 0.7);
    let qd = SVector::<f64, 3>::new(0.0, 0.0, 3.0);
    let pose = model.mechanism.pose(&q);
    let c = &model.contacts[0];
    let geom = model.geometry(c, &pose);
    let b = model.boundary(c, &pose, &qd, &geom, Vector2::zeros());
    let mut plates = Vec::new();
    b.outline.for_each_plate(&b.frame, |p| plates.push(*p));
    assert_eq!(plates.len(), 7);
    for (k, p) in plates.iter().enumerate() {
        let a = model.mechanism.point(&pose, 0, arc.vertex(k));
        let e = model.mechanism.point(&pose, 0, arc.vertex(k + 1));
        assert!((Vector2::new(p.a[0], p.a[1]) - a).norm() < 1e-15, "{k}");
        assert!((Vector2::new(p.b[0], p.b[1]) - e).norm() < 1e-15, "{k}");
        assert_eq!(p.width, 0.01);
    }
    // The driven root angle: qdot_link = rate held, the root pinned; nothing else moves.
    let e = model.eval(&q, &qd, &Default::default());
    assert!(e.qdd.norm() < 1e-12, "{}", e.qdd);
}
