//! Accuracy of the located events (issue 3): the vertical drop against its exact answers.
//!
//! Exact depth: the energy balance of MODEL.md. Exact stop time: the quadrature of dd / v(d)
//! from 0 to the final depth, with v(d) from the same energy balance (an independent
//! computation: it shares no code with the integrator).

mod common;

use _granrs::bodies::LinkageScene;
use _granrs::dynamics::SignModel;
use _granrs::presets::free_link::FreeLink;
use common::{
    drop_at, exact_vertical_depth, table_3_4_vertical, thesis_setting, vertical_static_work,
};

/// t_s = int_0^df dd / v(d), with d = df (1 - u^2) to remove the 1/sqrt singularity at df;
/// composite 10-point Gauss-Legendre on u in [0, 1].
/// For the rod `p` in the scene `s` it built.
fn exact_vertical_stop_time(p: &FreeLink, s: &LinkageScene) -> f64 {
    let g = s.medium.g;
    let df = exact_vertical_depth(p, s);
    let v0 = p.start.v0;
    let v = |d: f64| {
        let v2 = v0 * v0 + 2.0 * g * d - 2.0 * vertical_static_work(p, s, d) / p.rod.mass;
        v2.max(0.0).sqrt()
    };
    let integrand = |u: f64| 2.0 * df * u / v(df * (1.0 - u * u));
    // 10-point Gauss-Legendre nodes and weights on [-1, 1].
    const X: [f64; 5] = [
        0.148_874_338_981_631_2,
        0.433_395_394_129_247_2,
        0.679_409_568_299_024_4,
        0.865_063_366_688_984_5,
        0.973_906_528_517_171_7,
    ];
    const W: [f64; 5] = [
        0.295_524_224_714_752_9,
        0.269_266_719_309_996_4,
        0.219_086_362_515_982,
        0.149_451_349_150_580_6,
        0.066_671_344_308_688_1,
    ];
    let panels = 2000;
    let mut total = 0.0;
    for p in 0..panels {
        let a = p as f64 / panels as f64;
        let b = (p + 1) as f64 / panels as f64;
        let (m, r) = (0.5 * (a + b), 0.5 * (b - a));
        for i in 0..5 {
            total += W[i] * r * (integrand(m - r * X[i]) + integrand(m + r * X[i]));
        }
    }
    total
}

/// Issue 3 acceptance: at dt = 1e-4 the vertical drop's depth is within 3e-8 relative of
/// the exact answer and t_s within 1e-8 s of the exact stop time, for every v0.
#[test]
fn vertical_drop_depth_and_stop_time_at_10_khz() {
    for v0 in [0.1, 0.3, 1.0, 2.214, 5.0, 10.0] {
        let rod = FreeLink {
            start: drop_at(v0),
            ..Default::default()
        };
        let s = rod.scene(thesis_setting(&[table_3_4_vertical()]));
        let out = s.run().unwrap();
        let exact_d = exact_vertical_depth(&rod, &s);
        let exact_t = exact_vertical_stop_time(&rod, &s);
        let c = &out.contacts[0];
        let rel_d = (c.depth - exact_d).abs() / exact_d;
        let err_t = (c.t_s - exact_t).abs();
        // The raw sign model, for the record.
        let raw = LinkageScene {
            sign_model: SignModel::Raw,
            ..s.clone()
        }
        .run()
        .unwrap();
        println!(
            "v0 = {v0:>6}: depth rel.err {rel_d:.2e}  t_s err {err_t:.2e} s  (raw: {:.2e}, {:.2e} s)  steps {} evals {}",
            (raw.contacts[0].depth - exact_d).abs() / exact_d,
            (raw.contacts[0].t_s - exact_t).abs(),
            out.stats.steps,
            out.stats.rhs_evals
        );
        assert!(rel_d < 3e-8, "v0 = {v0}: depth rel. error {rel_d:e}");
        assert!(err_t < 1e-8, "v0 = {v0}: t_s error {err_t:e} s");
    }
}
