//! Exact answers, rigid-body checks, symmetries and bad input for bodies in space.

use std::f64::consts::PI;

use nalgebra::{UnitQuaternion, Vector3};

use super::shape::Shape;
use super::solve::{angle_between, Status};
use super::*;
use crate::forces::TermSpec;

type V3 = Vector3<f64>;

/// alpha_z of a horizontal plate pushed straight down and of a vertical wall sliding straight
/// down, from the coefficient table's sums (written here, not read from the code).
const PLATE_DOWN: f64 = 0.87574;
const WALL_DOWN: f64 = 0.24898;

fn scene(shape: Shape, density: f64, v0: f64, zeta: f64) -> Scene3 {
    // The lowest point starts at the surface.
    let low = shape.lowest_point(&V3::zeros(), &UnitQuaternion::identity());
    Scene3 {
        shape,
        mass: MassSpec::Density(density),
        position: [0.0, 0.0, -low.z],
        orientation: [1.0, 0.0, 0.0, 0.0],
        velocity: [0.0, 0.0, -v0],
        omega: [0.0; 3],
        forces: vec![
            TermSpec::new("rft3d", &[("zeta", zeta)]),
            TermSpec::new("gravity", &[]),
        ],
        medium: Medium::default(),
        surface: 0.0,
        dt: 1e-4,
        t_end: 2.0,
        end_at_stop: true,
        record: false,
        nodes: 6,
    }
}

/// The depth D where m v0^2 / 2 + m g D = W(D) (W: the work of the quasi-static force
/// F_z(d) from 0 to D, increasing faster than m g D), by bisection.
fn final_depth(m: f64, v0: f64, work: impl Fn(f64) -> f64) -> f64 {
    let g = 9.81;
    let excess = |d: f64| work(d) - 0.5 * m * v0 * v0 - m * g * d;
    let (mut lo, mut hi) = (0.0, 1e-3);
    while excess(hi) < 0.0 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if excess(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// F_z of a sphere of radius r at depth d moving straight down, written from the table:
/// on the lower hemisphere x1 = 1 and x2 = x3 = cos(theta); integrated over theta by
/// Gauss-Legendre of high order on [0, theta_w] (independent of the code's surface rule).
pub(super) fn sphere_fz(r: f64, d: f64) -> f64 {
    let c = crate::forces::rft3d::COEFFICIENTS;
    let tw = (1.0 - d / r).clamp(-1.0, 1.0).acos().min(PI / 2.0);
    let g = super::quad::Gauss::new(40);
    let mut s = 0.0;
    g.each(0.0, tw, |th, w| {
        let u = th.cos();
        let t = [
            1.0,
            1.0,
            u,
            u,
            1.0,
            u * u,
            u * u,
            u,
            u * u,
            u,
            1.0,
            u.powi(3),
            u.powi(3),
            u * u,
            u,
            u.powi(3),
            u.powi(3),
            u,
            u * u,
            u * u,
        ];
        let f: Vec<f64> = c
            .iter()
            .map(|row| row.iter().zip(t).map(|(a, b)| a * b).sum())
            .collect();
        let az = -(f[0] * u + f[1] + f[2]);
        s += w * az * (d - r * (1.0 - u)) * 2.0 * PI * r * r * th.sin();
    });
    // Below the equator (d > r) the leading side is still the lower hemisphere: done.
    s
}

fn sphere_work(r: f64, zeta: f64, d: f64) -> f64 {
    let g = super::quad::Gauss::new(40);
    // F_z is smooth in d except at d = r (the equator wets): split there.
    let mut w = 0.0;
    let mut seg = |a: f64, b: f64| g.each(a, b, |x, wx| w += wx * zeta * sphere_fz(r, x));
    if d > r {
        seg(0.0, r);
        seg(r, d);
    } else {
        seg(0.0, d);
    }
    w
}

/// The work per unit perimeter and unit stress of a vertical wall of height `h` whose bottom
/// goes from depth 0 to `d`: its wet depths run from max(0, s - h) to s, so the force is
/// s^2 / 2 while s <= h, then h s - h^2 / 2; the work is d^3 / 6, then
/// h^3 / 6 + h d (d - h) / 2.
fn walls_work(d: f64, h: f64) -> f64 {
    if d <= h {
        d.powi(3) / 6.0
    } else {
        h.powi(3) / 6.0 + h * d * (d - h) / 2.0
    }
}

#[test]
fn vertical_drops_meet_the_energy_balance() {
    let zeta = 2e5;
    let mut worst: f64 = 0.0;
    for v0 in [0.5, 1.0, 2.0, 4.0] {
        // Spheres of two radii.
        for r in [0.01, 0.025] {
            let s = scene(Shape::sphere("s", r).unwrap(), 7800.0, v0, zeta);
            let (mut body, y0, opts) = s.build().unwrap();
            let out = body.run(y0, &opts).unwrap();
            assert_eq!(out.status, Status::Stopped);
            let m = body.inertia.mass;
            let expect = final_depth(m, v0, |d| sphere_work(r, zeta, d));
            let rel = (out.depth - expect).abs() / expect;
            worst = worst.max(rel);
            assert!(
                rel < 1e-6,
                "sphere r {r} v0 {v0}: {} vs {expect} ({rel:e})",
                out.depth
            );
            assert!(
                out.end.v.x.abs() < 1e-9 * v0 && out.end.v.y.abs() < 1e-9 * v0,
                "r {r} v0 {v0}: {:?} {:?}",
                out.end.v,
                out.status
            );
        }
        // A vertical cylinder: its base pushed down, its side grazing.
        let (r, l) = (0.01, 0.1);
        let s = scene(Shape::cylinder("c", r, l).unwrap(), 7800.0, v0, zeta);
        let (mut body, y0, opts) = s.build().unwrap();
        let out = body.run(y0, &opts).unwrap();
        let m = body.inertia.mass;
        let expect = final_depth(m, v0, |d| {
            zeta * (PLATE_DOWN * PI * r * r * d * d / 2.0
                + WALL_DOWN * 2.0 * PI * r * walls_work(d, l))
        });
        let rel = (out.depth - expect).abs() / expect;
        worst = worst.max(rel);
        assert!(
            rel < 1e-6,
            "cylinder v0 {v0}: {} vs {expect} ({rel:e})",
            out.depth
        );
        // A flat box.
        let (a, b, h) = (0.08, 0.05, 0.01);
        let s = scene(Shape::cuboid("b", [a, b, h]).unwrap(), 2700.0, v0, zeta);
        let (mut body, y0, opts) = s.build().unwrap();
        let out = body.run(y0, &opts).unwrap();
        let m = body.inertia.mass;
        let expect = final_depth(m, v0, |d| {
            zeta * (PLATE_DOWN * a * b * d * d / 2.0 + WALL_DOWN * 2.0 * (a + b) * walls_work(d, h))
        });
        let rel = (out.depth - expect).abs() / expect;
        worst = worst.max(rel);
        assert!(
            rel < 1e-6,
            "box v0 {v0}: {} vs {expect} ({rel:e})",
            out.depth
        );
    }
    eprintln!("worst relative depth error {worst:e}");
}

#[test]
fn a_torque_free_spinning_box_keeps_its_energy_and_momentum_and_precesses_as_euler_says() {
    // A symmetric box (a = b): w3 is constant and (w1, w2) turns at
    // lambda = (I3 - I1) / I1 w3 in the body frame.
    let shape = Shape::cuboid("b", [0.1, 0.1, 0.3]).unwrap();
    let mut s = scene(shape, 1000.0, 0.0, 1.0);
    s.forces.clear();
    s.position = [0.0, 0.0, 10.0];
    let w0 = V3::new(0.7, 0.0, 3.0);
    s.omega = w0.into();
    s.t_end = 10.0;
    s.record = true;
    let (mut body, y0, opts) = s.build().unwrap();
    let out = body.run(y0, &opts).unwrap();
    let i = body.inertia.tensor;
    let e0 = 0.5 * w0.dot(&(i * w0));
    let l0 = i * w0;
    let (i1, i3) = (i[(0, 0)], i[(2, 2)]);
    let lambda = (i3 - i1) / i1 * w0.z;
    let mut worst_w: f64 = 0.0;
    for smp in &out.series {
        let y = smp.state;
        let e = 0.5 * y.w.dot(&(i * y.w));
        assert!(
            (e - e0).abs() < 1e-10 * e0,
            "energy at t {}: {e} vs {e0}",
            smp.t
        );
        let l = y.rotation() * (i * y.w);
        assert!(
            (l - l0).norm() < 1e-10 * l0.norm(),
            "momentum at t {}",
            smp.t
        );
        let (s_, c_) = (lambda * smp.t).sin_cos();
        let expect = V3::new(w0.x * c_, w0.x * s_, w0.z);
        worst_w = worst_w.max((y.w - expect).norm());
    }
    assert!(
        worst_w < 1e-9,
        "body-frame spin off Euler's solution by {worst_w:e} rad/s"
    );
}

#[test]
fn zeta_zero_is_free_fall_exactly() {
    let mut s = scene(Shape::capsule("c", 0.01, 0.05).unwrap(), 7800.0, 1.0, 0.0);
    s.t_end = 0.05;
    s.omega = [0.0, 2.0, 0.0];
    let (mut body, y0, opts) = s.build().unwrap();
    let out = body.run(y0, &opts).unwrap();
    let t = out.t_end;
    let z = y0.c.z - 1.0 * t - 0.5 * 9.81 * t * t;
    assert!((out.end.c.z - z).abs() < 1e-12, "{} vs {z}", out.end.c.z);
    assert_eq!(out.status, Status::NotStopped);
    assert!((out.energy_end - out.energy_start).abs() < 1e-12 * out.energy_start.abs());
}

#[test]
fn a_sphere_straight_down_turns_no_way() {
    let s = scene(Shape::sphere("s", 0.02).unwrap(), 7800.0, 2.0, 1e6);
    let (mut body, y0, opts) = s.build().unwrap();
    let out = body.run(y0, &opts).unwrap();
    assert!(out.end.c.x.abs() < 1e-15 && out.end.c.y.abs() < 1e-15);
    assert!(angle_between(&out.end.rotation(), &UnitQuaternion::identity()) < 1e-12);
}

#[test]
fn mirror_images_mirror() {
    // A capsule falling obliquely, spinning; its image in the plane x = 0.
    let mk = |sx: f64| {
        let mut s = scene(Shape::capsule("c", 0.01, 0.06).unwrap(), 7800.0, 1.5, 5e5);
        let q = UnitQuaternion::from_axis_angle(&V3::y_axis(), sx * 0.6);
        s.orientation = [q.w, q.i, q.j, q.k];
        s.position = [0.0, 0.0, 0.05];
        s.velocity = [sx * 0.8, 0.0, -1.5];
        s.omega = [0.0, sx * 3.0, 0.0];
        s
    };
    let (mut a, ya, oa) = mk(1.0).build().unwrap();
    let (mut b, yb, ob) = mk(-1.0).build().unwrap();
    let ra = a.run(ya, &oa).unwrap();
    let rb = b.run(yb, &ob).unwrap();
    assert_eq!(ra.status, Status::Stopped);
    assert!(
        (ra.t_s - rb.t_s).abs() < 1e-9 * ra.t_s,
        "{} {}",
        ra.t_s,
        rb.t_s
    );
    assert!(
        (ra.end.c.x + rb.end.c.x).abs() < 1e-9,
        "{} {}",
        ra.end.c.x,
        rb.end.c.x
    );
    assert!((ra.end.c.z - rb.end.c.z).abs() < 1e-9);
    assert!((ra.load_end.force.z - rb.load_end.force.z).abs() < 1e-6 * ra.load_end.force.z.abs());
}

#[test]
fn bad_input_is_refused_naming_the_field_before_any_work() {
    let ok = scene(Shape::sphere("s", 0.02).unwrap(), 7800.0, 1.0, 1e6);
    let field = |s: Scene3| match s.build() {
        Err(e) => format!("{e}"),
        Ok(_) => panic!("accepted"),
    };
    let mut s = ok.clone();
    s.orientation = [1.0, 0.1, 0.0, 0.0];
    assert!(field(s).contains("`orientation`"));
    let mut s = ok.clone();
    s.orientation = [f64::NAN, 0.0, 0.0, 0.0];
    assert!(field(s).contains("orientation[0]"));
    assert!(Shape::sphere("body.shape", -1.0)
        .unwrap_err()
        .to_string()
        .contains("body.shape.radius"));
    let mut s = ok.clone();
    s.mass = MassSpec::Given(1.0, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]);
    assert!(field(s).contains("body.inertia"));
    let mut s = ok.clone();
    s.mass = MassSpec::Given(1.0, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 3.0]]);
    assert!(
        field(s).contains("body.inertia"),
        "no body has moments 1, 1, 3"
    );
    let mut s = ok.clone();
    s.forces.push(TermSpec::new("drag", &[]));
    assert!(field(s).contains("forces[2]"));
    let mut s = ok.clone();
    s.forces = vec![TermSpec::new("rft3d", &[("zeta", 1.0), ("zetta", 2.0)])];
    assert!(field(s).contains("rft3d.zetta"));
    let mut s = ok.clone();
    s.forces = vec![TermSpec::new("rft3d", &[])];
    assert!(field(s).contains("rft3d.zeta"), "zeta is required");
    let mut s = ok.clone();
    s.forces.push(TermSpec::new("gravity", &[]));
    assert!(field(s).contains("listed twice"));
    let mut s = ok.clone();
    s.dt = 0.0;
    assert!(field(s).contains("`dt`"));
    let mut s = ok;
    s.nodes = 1000;
    assert!(field(s).contains("quadrature"));
}

#[test]
fn a_thin_or_degenerate_mesh_facet_is_handled() {
    // A tetrahedron with one very thin face is fine; a zero-area facet is refused.
    let v = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.3, 0.3, 1e-7],
    ];
    let t = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
    let m = Shape::mesh("m", &v, &t).unwrap();
    assert!(m.volume() > 0.0);
    let v2 = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.3, 0.3, 1.0],
    ];
    let e = Shape::mesh("body.shape", &v2, &t).unwrap_err().to_string();
    assert!(e.contains("body.shape.triangles"), "{e}");
}
