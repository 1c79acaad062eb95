//! Criterion benches of bodies in space (`granrs::space`), one group per layer:
//!
//! * `space_kernel/rft3d`: the 3D-RFT element kernel alone (`space::load::rft3d_sum`) over a
//!   fixed set of elements (a capsule in oblique, spinning motion, cut with 24 nodes per
//!   panel: several thousand elements), reported as elements per second;
//! * `space_elements/<shape>`: cutting a shape's immersed surface into elements at the
//!   default rule (6 nodes per panel), oblique and spinning;
//! * `space_load/<shape>`: one evaluation of `rft3d` on it (the cut, then the kernel);
//!   `space_load/mesh1280`: `benches/bench_space.py`'s mesh (a 1280-facet icosphere of
//!   radius 50 mm, half sunk, oblique and spinning, its areas reported);
//! * `space_impact/<case>`: one whole impact: a steel sphere dropped at 2 m/s on the exact
//!   primitive, straight down (the closed form) and obliquely, (0.5, 0, -2) m/s, at 6, 3
//!   and 2 nodes per panel, beside the thesis's free link at q = 45 deg (the planar
//!   engine), so that their ratio comes from one run.
//!
//! `cargo bench --bench space`; `cargo bench --bench space -- --test` runs each once. The
//! machines are shared: compare ratios, not absolute times.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{UnitQuaternion, Vector3};

use _granrs::forces::rft3d::Rft3d;
use _granrs::forces::{Coefficients, ForceSet, Medium, TermSpec};
use _granrs::presets::free_link::FreeLink;
use _granrs::presets::{Setting, Start};
use _granrs::space::load::{rft3d_sum, Sand, Terms3};
use _granrs::space::shape::{Elements, Quadrature, Shape};
use _granrs::space::{MassSpec, Scene3};

fn shapes() -> Vec<(&'static str, Shape)> {
    vec![
        ("sphere", Shape::sphere("s", 0.03).unwrap()),
        ("capsule", Shape::capsule("c", 0.02, 0.1).unwrap()),
        ("cylinder", Shape::cylinder("y", 0.02, 0.1).unwrap()),
        ("cuboid", Shape::cuboid("b", [0.1, 0.06, 0.04]).unwrap()),
    ]
}

/// An icosphere of radius `r`: the icosahedron's faces cut in four `k` times, the vertices
/// put back on the sphere (`granrs.space.Mesh.icosphere`'s construction; 20 4^k facets).
fn icosphere(r: f64, k: usize) -> Shape {
    let p = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = [
        [-1.0, p, 0.0],
        [1.0, p, 0.0],
        [-1.0, -p, 0.0],
        [1.0, -p, 0.0],
        [0.0, -1.0, p],
        [0.0, 1.0, p],
        [0.0, -1.0, -p],
        [0.0, 1.0, -p],
        [p, 0.0, -1.0],
        [p, 0.0, 1.0],
        [-p, 0.0, -1.0],
        [-p, 0.0, 1.0],
    ]
    .iter()
    .map(|x| {
        let l = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        [x[0] / l, x[1] / l, x[2] / l]
    })
    .collect();
    let mut faces: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..k {
        let mut middle = std::collections::HashMap::new();
        let mut mid = |a: usize, b: usize, v: &mut Vec<[f64; 3]>| {
            *middle.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = [0, 1, 2].map(|i| (v[a][i] + v[b][i]) / 2.0);
                let l = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
                v.push(m.map(|x| x / l));
                v.len() - 1
            })
        };
        let mut next = Vec::with_capacity(4 * faces.len());
        for [a, b, c] in faces {
            let (ab, bc, ca) = (mid(a, b, &mut v), mid(b, c, &mut v), mid(c, a, &mut v));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let v: Vec<[f64; 3]> = v.iter().map(|x| x.map(|c| c * r)).collect();
    let t: Vec<[i64; 3]> = faces.iter().map(|f| f.map(|i| i as i64)).collect();
    Shape::mesh("m", &v, &t).unwrap()
}

fn motion() -> (
    Vector3<f64>,
    UnitQuaternion<f64>,
    Vector3<f64>,
    Vector3<f64>,
) {
    (
        Vector3::new(0.0, 0.0, 0.0),
        UnitQuaternion::from_euler_angles(0.4, 0.7, -0.2),
        Vector3::new(0.5, -0.3, -1.2),
        Vector3::new(2.0, -1.0, 4.0),
    )
}

fn kernel(c: &mut Criterion) {
    let (x, q, v, w) = motion();
    let mut e = Elements::default();
    Shape::capsule("c", 0.02, 0.1).unwrap().elements(
        &x,
        &q,
        &v,
        &w,
        0.0,
        &Quadrature::new(24),
        &mut e,
    );
    let law = Rft3d {
        zeta: 1e6,
        mu_surf: f64::INFINITY,
        grazing: true,
    }
    .lanes();
    eprintln!("space_kernel: {} elements", e.len());
    let mut g = c.benchmark_group("space_kernel");
    g.throughput(Throughput::Elements(e.len() as u64));
    g.bench_function("rft3d", |b| {
        b.iter(|| rft3d_sum(black_box(&law), black_box(&e), &x, &v, &w))
    });
    g.finish();
}

fn layers(c: &mut Criterion) {
    let (x, q, v, w) = motion();
    let rule = Quadrature::new(Quadrature::DEFAULT_NODES);
    let mut g = c.benchmark_group("space_elements");
    for (name, shape) in shapes() {
        let mut e = Elements::default();
        g.bench_function(name, |b| {
            b.iter(|| {
                e.clear();
                shape.elements(black_box(&x), &q, &v, &w, 0.0, &rule, &mut e);
                e.len()
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("space_load");
    for (name, shape) in shapes() {
        let terms = Terms3 {
            rft3d: Some(Rft3d {
                zeta: 1e6,
                mu_surf: f64::INFINITY,
                grazing: true,
            }),
            ..Terms3::default()
        };
        let mut sand = Sand::new(shape, terms, Medium::default(), 0.0, rule.clone());
        g.bench_function(name, |b| b.iter(|| sand.load(black_box(&x), &q, &v, &w)));
    }
    // bench_space.py's mesh: a 1280-facet icosphere of radius 50 mm, half sunk, moving
    // obliquely and spinning, its areas reported (as granrs.space.load does).
    let terms = Terms3 {
        rft3d: Some(Rft3d {
            zeta: 1e6,
            mu_surf: f64::INFINITY,
            grazing: true,
        }),
        ..Terms3::default()
    };
    let mut sand = Sand::new(icosphere(0.05, 3), terms, Medium::default(), 0.0, rule);
    sand.report_areas = true;
    let (c, v, w) = (
        Vector3::zeros(),
        Vector3::new(0.3, -0.2, -1.0),
        Vector3::new(1.0, 2.0, -0.5),
    );
    let id = UnitQuaternion::identity();
    eprintln!(
        "space_load/mesh1280: {} elements",
        sand.load(&c, &id, &v, &w).elements
    );
    g.bench_function("mesh1280", |b| {
        b.iter(|| sand.load(black_box(&c), &id, &v, &w))
    });
    g.finish();
}

fn sphere_drop(nodes: usize, vx: f64) -> Scene3 {
    Scene3 {
        shape: Shape::sphere("s", 0.02).unwrap(),
        mass: MassSpec::Density(7800.0),
        position: [0.0, 0.0, 0.02],
        orientation: [1.0, 0.0, 0.0, 0.0],
        velocity: [vx, 0.0, -2.0],
        omega: [0.0; 3],
        forces: vec![
            TermSpec::new("rft3d", &[("zeta", 2e5)]),
            TermSpec::new("gravity", &[]),
        ],
        medium: Medium::default(),
        surface: 0.0,
        dt: 1e-4,
        t_end: 1.0,
        end_at_stop: true,
        record: false,
        nodes,
    }
}

fn impacts(c: &mut Criterion) {
    let mut g = c.benchmark_group("space_impact");
    g.sample_size(20).measurement_time(Duration::from_secs(8));
    for (name, nodes, vx) in [
        ("sphere_down", 6, 0.0),
        ("sphere_oblique_rule6", 6, 0.5),
        ("sphere_oblique_rule3", 3, 0.5),
        ("sphere_oblique_rule2", 2, 0.5),
    ] {
        let scene = sphere_drop(nodes, vx);
        let (body, y0, opts) = scene.build().unwrap();
        let out = body.clone().run(y0, &opts).unwrap();
        eprintln!(
            "{name}: {} steps, {} rhs evaluations, {} elements at most",
            out.steps, out.rhs_evals, out.max_elements
        );
        g.bench_function(name, |b| {
            b.iter(|| body.clone().run(black_box(y0), &opts).unwrap().t_s)
        });
    }
    // The thesis's free link, Table 3.5 row q = 45 deg, v0 = 2.27 m/s, Table 3.4 row q = 45.
    let free_link = FreeLink {
        q_deg: 45.0,
        start: Start {
            v0: 2.27,
            depth0: 0.0,
            vx0: 0.0,
        },
        ..Default::default()
    }
    .scene(Setting {
        forces: ForceSet::thesis(&[Coefficients {
            eta_h: 5.5,
            eta_d: 11.0,
            eta_v: 53.0,
            lambda: 0.25,
        }]),
        ..Default::default()
    });
    g.bench_function("free_link_q45", |b| {
        b.iter(|| free_link.run().unwrap().status)
    });
    g.finish();
}

criterion_group!(benches, kernel, layers, impacts);
criterion_main!(benches);
