//! Shapes in space and their surface elements below the sand.
//!
//! Every shape is described in its body frame, with its centre of mass at the origin (a
//! mesh is moved there when it is built). At a pose (position `c`, orientation `R`) and a
//! motion (the centre's velocity, the angular velocity `omega`), [`Shape::elements`] gives
//! the immersed part of the surface as quadrature points: position, outward normal, area
//! weight and depth below the surface `z = s`. The immersed part is cut exactly:
//!
//! - a flat face (a cuboid's, a mesh's triangle) is clipped as a polygon at the surface and
//!   at its leading edge (`n . v(x) = 0` is a line on a flat face: `v` is linear in `x`); on
//!   what is left the depth is linear, so a 3-point rule per triangle integrates the depth
//!   exactly for a translating body, and to second order in the facet's size otherwise;
//! - a curved surface is a family of lines or circles (a cylinder's generators and a cap's
//!   radii, a sphere's circles about its velocity) on each of which the depth and `n . v`
//!   are linear or trigonometric, so each is cut exactly and integrated by Gauss-Legendre;
//!   the outer integral is cut at every angle where an inner limit changes its kind, and
//!   split into panels of at most 45 degrees.
//!
//! The rule's error is controlled by the nodes per panel ([`Quadrature::nodes`]);
//! `space::load` estimates it by doubling them.

use std::f64::consts::PI;
use std::mem::MaybeUninit;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use super::quad::{arc_below, around, clip_linear, intersect, pieces, trig_roots, Gauss};
use crate::error::{GranrsError, Result};
use crate::forces::ContactKind;

type V3 = Vector3<f64>;

/// Surface elements below the sand: a structure of arrays (each coordinate contiguous, so
/// that the element kernels run in SIMD lanes), reused between evaluations.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Elements {
    /// Positions' x, y and z, world frame [m].
    pub x: [Vec<f64>; 3],
    /// Outward unit normals' x, y and z, world frame.
    pub n: [Vec<f64>; 3],
    /// Area weights [m^2].
    pub area: Vec<f64>,
    /// Depths below the surface [m] (>= 0).
    pub depth: Vec<f64>,
    /// The area sums taken as the elements are written, where asked for
    /// ([`Elements::sum_areas`]; none after [`Elements::clear`]).
    pub sums: Option<AreaSums>,
    /// A mesh's vertices in the world frame and their velocities (buffers kept between
    /// evaluations).
    scratch: Vec<V3>,
    scratch_v: Vec<V3>,
}

/// The immersed surface's areas summed over the elements in their order as they are
/// written (the same bits as a pass over them after; the sums' additions, each a chain
/// that waits on the one before, overlap with the cutting's work): the wetted area, the
/// leading area projected normal to the unit direction `toward`, and that projection's
/// first moment (its centre times it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaSums {
    /// The unit direction the projected area is taken normal to (the centre's velocity's).
    pub toward: V3,
    /// The wetted area [m^2].
    pub wetted: f64,
    /// The projected leading area [m^2]: each element's `max(n . toward, 0) area`.
    pub projected: f64,
    /// The sum of each element's projected area times its position [m^3].
    pub moment: V3,
}

impl AreaSums {
    /// No elements yet, the projection normal to the unit `toward`.
    pub fn toward(toward: V3) -> AreaSums {
        AreaSums {
            toward,
            wetted: 0.0,
            projected: 0.0,
            moment: V3::zeros(),
        }
    }

    /// Add an element at `x` of normal `n` and area weight `area`.
    #[inline(always)]
    pub fn add(&mut self, x: &V3, n: &V3, area: f64) {
        self.wetted += area;
        let p = n.dot(&self.toward).max(0.0) * area;
        self.projected += p;
        self.moment += p * x;
    }
}

impl Elements {
    /// Forget every element (keep the buffers).
    pub fn clear(&mut self) {
        for k in 0..3 {
            self.x[k].clear();
            self.n[k].clear();
        }
        self.area.clear();
        self.depth.clear();
        self.sums = None;
    }

    /// Sum the areas of the elements written from now on ([`AreaSums`], projected normal
    /// to the unit `toward`), until [`Elements::clear`].
    pub fn sum_areas(&mut self, toward: V3) {
        self.sums = Some(AreaSums::toward(toward));
    }

    /// Element `i`'s position [m].
    #[inline]
    pub fn point(&self, i: usize) -> V3 {
        V3::new(self.x[0][i], self.x[1][i], self.x[2][i])
    }

    /// Element `i`'s outward normal.
    #[inline]
    pub fn normal(&self, i: usize) -> V3 {
        V3::new(self.n[0][i], self.n[1][i], self.n[2][i])
    }

    /// How many elements.
    pub fn len(&self) -> usize {
        self.area.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.area.is_empty()
    }

    /// Room for `more` elements past the current ones in every array.
    fn reserve(&mut self, more: usize) {
        for k in 0..3 {
            self.x[k].reserve(more);
            self.n[k].reserve(more);
        }
        self.area.reserve(more);
        self.depth.reserve(more);
    }

    /// Run `f` with the arrays' spare room ([`Elements::reserve`]d before) to write
    /// elements into by index, then count what it wrote (a mesh's triangles, whole and cut:
    /// no array's length or capacity is read or written per element).
    fn fill<R>(&mut self, f: impl FnOnce(&mut Room<'_>) -> R) -> R {
        let [x0, x1, x2] = &mut self.x;
        let [n0, n1, n2] = &mut self.n;
        let mut room = Room {
            x: [
                x0.spare_capacity_mut(),
                x1.spare_capacity_mut(),
                x2.spare_capacity_mut(),
            ],
            n: [
                n0.spare_capacity_mut(),
                n1.spare_capacity_mut(),
                n2.spare_capacity_mut(),
            ],
            area: self.area.spare_capacity_mut(),
            depth: self.depth.spare_capacity_mut(),
            sums: self.sums,
            len: 0,
            cap: 0,
        };
        room.cap = room
            .x
            .iter()
            .chain(&room.n)
            .chain([&room.area, &room.depth])
            .map(|s| s.len())
            .min()
            .unwrap_or(0);
        let out = f(&mut room);
        let more = room.len;
        self.sums = room.sums;
        for v in self
            .x
            .iter_mut()
            .chain(self.n.iter_mut())
            .chain([&mut self.area, &mut self.depth])
        {
            // SAFETY: `Room::put3`, the only way `room.len` grows, wrote entries
            // `..room.len` of every array's spare room (within its capacity: it indexes
            // the spare slices, checked) before it counted them.
            unsafe { v.set_len(v.len() + more) };
        }
        out
    }
}

/// Elements per [`Batch`].
const BATCH: usize = 64;

/// A curved surface's elements as they are cut, one at a time: written to arrays on the
/// stack and appended to [`Elements`] a batch at a time (in their order: the same
/// elements), where a push onto each of its eight arrays would check and grow each one per
/// element. The last batch goes in when it is dropped.
struct Batch<'a> {
    out: &'a mut Elements,
    /// The batch's positions, normals, area weights and depths, each by coordinate (its
    /// first `len` of each written; not zeroed, 4 kB).
    cols: [[MaybeUninit<f64>; BATCH]; 8],
    len: usize,
}

impl<'a> Batch<'a> {
    fn new(out: &'a mut Elements) -> Self {
        Batch {
            out,
            // SAFETY: an array of `MaybeUninit` needs no initialization (a repeat of
            // `MaybeUninit::uninit()` here was compiled as a 4 kB memset).
            cols: unsafe { MaybeUninit::uninit().assume_init() },
            len: 0,
        }
    }

    /// An element at `x` of normal `n` and area weight `area`, below `surface`.
    #[inline(always)]
    fn push(&mut self, x: V3, n: V3, area: f64, surface: f64) {
        if self.len == BATCH {
            self.flush();
        }
        let i = self.len;
        let values = [x.x, x.y, x.z, n.x, n.y, n.z, area, depth_below(surface, &x)];
        for (col, v) in self.cols.iter_mut().zip(values) {
            col[i].write(v);
        }
        if let Some(s) = &mut self.out.sums {
            s.add(&x, &n, area);
        }
        self.len = i + 1;
    }

    /// Append the batch to the elements.
    fn flush(&mut self) {
        let (len, out) = (self.len, &mut *self.out);
        let [x0, x1, x2] = &mut out.x;
        let [n0, n1, n2] = &mut out.n;
        let to = [x0, x1, x2, n0, n1, n2, &mut out.area, &mut out.depth];
        for (v, col) in to.into_iter().zip(&self.cols) {
            // SAFETY: `push`, the only way `len` grows, wrote entries `..len` of each column.
            v.extend_from_slice(unsafe {
                std::slice::from_raw_parts(col.as_ptr().cast::<f64>(), len)
            });
        }
        self.len = 0;
    }
}

impl Drop for Batch<'_> {
    fn drop(&mut self) {
        self.flush();
    }
}

/// A point's depth below the surface `z = surface` [m] (0 above it).
#[inline(always)]
fn depth_below(surface: f64, x: &V3) -> f64 {
    (surface - x.z).max(0.0)
}

/// Where a triangle's 3-point rule puts its elements: [`Elements`] (growing) or the room
/// [`Elements::fill`] lends.
trait Sink {
    /// Three elements of the same normal and area weight (a triangle's 3-point rule).
    fn put3(&mut self, x: [V3; 3], n: &V3, area: f64, surface: f64);
}

impl Sink for Elements {
    #[inline]
    fn put3(&mut self, x: [V3; 3], n: &V3, area: f64, surface: f64) {
        for k in 0..3 {
            self.x[k].extend_from_slice(&[x[0][k], x[1][k], x[2][k]]);
            self.n[k].extend_from_slice(&[n[k]; 3]);
        }
        self.area.extend_from_slice(&[area; 3]);
        self.depth
            .extend_from_slice(&x.map(|p| depth_below(surface, &p)));
        if let Some(s) = &mut self.sums {
            for p in &x {
                s.add(p, n, area);
            }
        }
    }
}

/// The spare room of [`Elements`]' arrays, written by index ([`Elements::fill`]).
struct Room<'a> {
    x: [&'a mut [MaybeUninit<f64>]; 3],
    n: [&'a mut [MaybeUninit<f64>]; 3],
    area: &'a mut [MaybeUninit<f64>],
    depth: &'a mut [MaybeUninit<f64>],
    /// [`Elements::sums`], taken on.
    sums: Option<AreaSums>,
    /// How many elements are written.
    len: usize,
    /// How many fit.
    cap: usize,
}

impl Room<'_> {
    /// How many more elements fit.
    fn left(&self) -> usize {
        self.cap - self.len
    }
}

impl Sink for Room<'_> {
    #[inline(always)]
    fn put3(&mut self, x: [V3; 3], n: &V3, area: f64, surface: f64) {
        let i = self.len;
        let put = |to: &mut [MaybeUninit<f64>], v: [f64; 3]| {
            for (t, v) in to[i..i + 3].iter_mut().zip(v) {
                t.write(v);
            }
        };
        for k in 0..3 {
            put(self.x[k], [x[0][k], x[1][k], x[2][k]]);
            put(self.n[k], [n[k]; 3]);
        }
        put(self.area, [area; 3]);
        put(self.depth, x.map(|p| depth_below(surface, &p)));
        if let Some(s) = &mut self.sums {
            for p in &x {
                s.add(p, n, area);
            }
        }
        self.len = i + 3;
    }
}

/// How finely a curved surface is integrated.
#[derive(Debug, Clone, PartialEq)]
pub struct Quadrature {
    /// Gauss-Legendre nodes per panel along each parameter (a flat face: its triangles are
    /// cut into `(nodes / 6)^2` before the 3-point rule).
    pub nodes: usize,
    gauss: Gauss,
}

/// Panels of a curved surface's angles are at most this long [rad].
const PANEL: f64 = PI / 4.0;

impl Quadrature {
    /// Most nodes per panel a scene may ask for (bounded work per evaluation).
    pub const MAX_NODES: usize = 64;
    /// Nodes per panel unless the scene says otherwise.
    pub const DEFAULT_NODES: usize = 6;

    /// The rule with `nodes` nodes per panel.
    pub fn new(nodes: usize) -> Self {
        Quadrature {
            nodes,
            gauss: Gauss::new(nodes),
        }
    }

    fn subdivisions(&self) -> usize {
        (self.nodes / 6).max(1)
    }
}

/// A closed triangle mesh, its centre of mass at the origin.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Vertices, body frame [m] (moved so that the centre of mass is the origin).
    pub vertices: Vec<V3>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
    /// Volume [m^3].
    pub volume: f64,
    /// Inertia tensor per unit density about the centre of mass [m^5].
    pub inertia: Matrix3<f64>,
    /// Where the given vertices' origin is in the body frame [m] (minus the centre of mass).
    pub offset: V3,
    /// Each triangle's outward unit normal, body frame (a rotation turns it; worked out
    /// once, not per evaluation).
    pub normals: Vec<V3>,
    /// Each triangle's area [m^2] (a rotation keeps it).
    pub areas: Vec<f64>,
}

/// A shape in space.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A sphere of radius `radius` [m].
    Sphere {
        /// [m]
        radius: f64,
    },
    /// A capsule along the body's z axis: a cylinder of `2 half_length` between two
    /// hemispheres of `radius`.
    Capsule {
        /// [m]
        radius: f64,
        /// Half the length of the cylindrical part [m].
        half_length: f64,
    },
    /// A cylinder along the body's z axis, with flat ends.
    Cylinder {
        /// [m]
        radius: f64,
        /// Half its length [m].
        half_length: f64,
    },
    /// A cuboid with half edge lengths along the body's axes [m].
    Cuboid {
        /// [m]
        half: [f64; 3],
    },
    /// A closed triangle mesh.
    Mesh(Box<Mesh>),
}

/// The smallest size of a shape [m] (a micrometre: below it the body's mass and inertia
/// leave what a double holds well).
pub const MIN_SIZE: f64 = 1e-6;
/// The largest size of a shape [m].
pub const MAX_SIZE: f64 = 1e6;

fn positive(field: &str, v: f64, what: &str) -> Result<f64> {
    if (MIN_SIZE..MAX_SIZE).contains(&v) {
        Ok(v)
    } else {
        Err(GranrsError::InvalidParameter {
            field: field.into(),
            value: v,
            allowed: format!("finite, >= {MIN_SIZE:e}, < {MAX_SIZE:e} ({what} [m])"),
        })
    }
}

fn nonneg(field: &str, v: f64, what: &str) -> Result<f64> {
    if (0.0..MAX_SIZE).contains(&v) {
        Ok(v)
    } else {
        Err(GranrsError::InvalidParameter {
            field: field.into(),
            value: v,
            allowed: format!("finite, >= 0, < {MAX_SIZE:e} ({what} [m])"),
        })
    }
}

impl Shape {
    /// A sphere, checked (`field`: where the shape is in the scene, e.g. `body.shape`).
    pub fn sphere(field: &str, radius: f64) -> Result<Shape> {
        Ok(Shape::Sphere {
            radius: positive(&format!("{field}.radius"), radius, "radius")?,
        })
    }

    /// A capsule of cylindrical length `length` (between its hemispheres' centres), checked.
    pub fn capsule(field: &str, radius: f64, length: f64) -> Result<Shape> {
        Ok(Shape::Capsule {
            radius: positive(&format!("{field}.radius"), radius, "radius")?,
            half_length: 0.5 * nonneg(&format!("{field}.length"), length, "cylinder length")?,
        })
    }

    /// A cylinder of length `length`, checked.
    pub fn cylinder(field: &str, radius: f64, length: f64) -> Result<Shape> {
        Ok(Shape::Cylinder {
            radius: positive(&format!("{field}.radius"), radius, "radius")?,
            half_length: 0.5 * positive(&format!("{field}.length"), length, "length")?,
        })
    }

    /// A cuboid of edge lengths `size`, checked.
    pub fn cuboid(field: &str, size: [f64; 3]) -> Result<Shape> {
        let mut half = [0.0; 3];
        for (k, (h, s)) in half.iter_mut().zip(size).enumerate() {
            *h = 0.5 * positive(&format!("{field}.size[{k}]"), s, "edge length")?;
        }
        Ok(Shape::Cuboid { half })
    }

    /// A closed mesh from its vertices and triangles (counter-clockwise seen from outside),
    /// checked: finite vertices, triangles of existing and distinct vertices, every edge
    /// shared by exactly two triangles in opposite directions (closed and consistently
    /// oriented), no degenerate triangle, a positive volume (outward normals).
    pub fn mesh(field: &str, vertices: &[[f64; 3]], triangles: &[[i64; 3]]) -> Result<Shape> {
        let bad = |what: &str, message: String| GranrsError::InvalidScene {
            field: format!("{field}.{what}"),
            message,
        };
        if vertices.len() < 4 || triangles.len() < 4 {
            return Err(bad(
                "triangles",
                format!(
                    "a closed mesh needs at least 4 vertices and 4 triangles, got {} and {}",
                    vertices.len(),
                    triangles.len()
                ),
            ));
        }
        if triangles.len() > 1_000_000 {
            return Err(bad(
                "triangles",
                format!("{} triangles; at most 1000000", triangles.len()),
            ));
        }
        for (i, v) in vertices.iter().enumerate() {
            for (k, x) in v.iter().enumerate() {
                if !(x.is_finite() && x.abs() < 1e6) {
                    return Err(GranrsError::InvalidParameter {
                        field: format!("{field}.vertices[{i}][{k}]"),
                        value: *x,
                        allowed: "finite, |x| < 1e6 [m]".into(),
                    });
                }
            }
        }
        let verts: Vec<V3> = vertices.iter().map(|v| V3::new(v[0], v[1], v[2])).collect();
        let mut tris = Vec::with_capacity(triangles.len());
        let mut edges = std::collections::HashMap::with_capacity(3 * triangles.len());
        let mut scale: f64 = 0.0;
        for v in &verts {
            scale = scale.max(v.norm());
        }
        let (lo, hi) = verts.iter().fold(
            (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY)),
            |(lo, hi), v| (lo.inf(v), hi.sup(v)),
        );
        if (hi - lo).max() < MIN_SIZE {
            return Err(bad(
                "vertices",
                format!(
                    "the mesh spans {:.3e} m; at least {MIN_SIZE:e} m",
                    (hi - lo).max()
                ),
            ));
        }
        for (i, t) in triangles.iter().enumerate() {
            let mut idx = [0usize; 3];
            for k in 0..3 {
                if t[k] < 0 || t[k] as usize >= verts.len() {
                    return Err(bad(
                        &format!("triangles[{i}]"),
                        format!("vertex index {} is not in 0..{}", t[k], verts.len()),
                    ));
                }
                idx[k] = t[k] as usize;
            }
            if idx[0] == idx[1] || idx[1] == idx[2] || idx[0] == idx[2] {
                return Err(bad(
                    &format!("triangles[{i}]"),
                    "a triangle repeats a vertex".into(),
                ));
            }
            let (a, b, c) = (verts[idx[0]], verts[idx[1]], verts[idx[2]]);
            let area2 = (b - a).cross(&(c - a)).norm();
            if area2.is_nan() || area2 <= 1e-24 * scale.max(1e-300).powi(2) {
                return Err(bad(
                    &format!("triangles[{i}]"),
                    "a degenerate triangle (zero area)".into(),
                ));
            }
            for k in 0..3 {
                let e = (idx[k], idx[(k + 1) % 3]);
                if edges.insert(e, i).is_some() {
                    return Err(bad(
                        &format!("triangles[{i}]"),
                        format!(
                            "the edge {} -> {} appears twice in the same direction: the mesh is \
                             not consistently oriented (or an edge has more than two triangles)",
                            e.0, e.1
                        ),
                    ));
                }
            }
            tris.push(idx);
        }
        for (&(a, b), &i) in &edges {
            if !edges.contains_key(&(b, a)) {
                return Err(bad(
                    &format!("triangles[{i}]"),
                    format!("the edge {a} -> {b} has no triangle on its other side: the mesh is not closed"),
                ));
            }
        }
        // Volume, centre and inertia from signed tetrahedra on the origin.
        let mut vol = 0.0;
        let mut first = V3::zeros();
        let mut second = Matrix3::zeros(); // integral of x x^T dV
        for t in &tris {
            let (a, b, c) = (verts[t[0]], verts[t[1]], verts[t[2]]);
            let d = a.dot(&b.cross(&c)) / 6.0;
            vol += d;
            first += d * (a + b + c) / 4.0;
            let s = a + b + c;
            second += d / 20.0
                * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
        }
        if vol.is_nan() || vol <= 0.0 {
            return Err(bad(
                "triangles",
                format!(
                    "the mesh's volume is {vol:.3e} m^3: its triangles must be counter-clockwise \
                     seen from outside (outward normals)"
                ),
            ));
        }
        let com = first / vol;
        let second_c = second - vol * com * com.transpose();
        let inertia = Matrix3::identity() * second_c.trace() - second_c;
        let vertices: Vec<V3> = verts.iter().map(|v| v - com).collect();
        let (normals, areas) = tris
            .iter()
            .map(|t| {
                let pts = t.map(|i| vertices[i]);
                (face_normal(&pts), triangle_area(&pts[0], &pts[1], &pts[2]))
            })
            .unzip();
        Ok(Shape::Mesh(Box::new(Mesh {
            vertices,
            triangles: tris,
            volume: vol,
            inertia,
            offset: -com,
            normals,
            areas,
        })))
    }

    /// Its kind, as a term's list of shapes names it.
    pub fn kind(&self) -> ContactKind {
        match self {
            Shape::Sphere { .. } => ContactKind::Sphere,
            Shape::Capsule { .. } => ContactKind::Capsule,
            Shape::Cylinder { .. } => ContactKind::Cylinder,
            Shape::Cuboid { .. } => ContactKind::Cuboid,
            Shape::Mesh(_) => ContactKind::Mesh,
        }
    }

    /// Its volume [m^3].
    pub fn volume(&self) -> f64 {
        match self {
            Shape::Sphere { radius: r } => 4.0 / 3.0 * PI * r.powi(3),
            Shape::Capsule {
                radius: r,
                half_length: h,
            } => PI * r * r * 2.0 * h + 4.0 / 3.0 * PI * r.powi(3),
            Shape::Cylinder {
                radius: r,
                half_length: h,
            } => PI * r * r * 2.0 * h,
            Shape::Cuboid { half } => 8.0 * half[0] * half[1] * half[2],
            Shape::Mesh(m) => m.volume,
        }
    }

    /// Its inertia tensor about the centre of mass per unit density [m^5], body frame.
    pub fn unit_inertia(&self) -> Matrix3<f64> {
        match self {
            Shape::Sphere { radius: r } => Matrix3::identity() * (0.4 * self.volume() * r * r),
            Shape::Capsule {
                radius: r,
                half_length: h,
            } => {
                let mc = PI * r * r * 2.0 * h;
                let ms = 4.0 / 3.0 * PI * r.powi(3);
                let l = 2.0 * h;
                let axial = mc * r * r / 2.0 + ms * 0.4 * r * r;
                let across =
                    mc * (l * l / 12.0 + r * r / 4.0) + ms * (0.4 * r * r + h * h + 0.75 * h * r);
                Matrix3::from_diagonal(&V3::new(across, across, axial))
            }
            Shape::Cylinder {
                radius: r,
                half_length: h,
            } => {
                let m = self.volume();
                let l = 2.0 * h;
                let across = m * (3.0 * r * r + l * l) / 12.0;
                Matrix3::from_diagonal(&V3::new(across, across, m * r * r / 2.0))
            }
            Shape::Cuboid { half: [a, b, c] } => {
                let m = self.volume();
                Matrix3::from_diagonal(&V3::new(
                    m * (b * b + c * c) / 3.0,
                    m * (a * a + c * c) / 3.0,
                    m * (a * a + b * b) / 3.0,
                ))
            }
            Shape::Mesh(m) => m.inertia,
        }
    }

    /// Its lowest point at the pose (position of the centre `c`, orientation `q`), world
    /// frame.
    pub fn lowest_point(&self, c: &V3, q: &UnitQuaternion<f64>) -> V3 {
        let z = V3::z();
        match self {
            Shape::Sphere { radius } => c - *radius * z,
            Shape::Capsule {
                radius,
                half_length,
            } => lower_end(c, &(q * z), *half_length) - *radius * z,
            Shape::Cylinder {
                radius,
                half_length,
            } => {
                let a = q * z;
                let end = lower_end(c, &a, *half_length);
                let down = z - a.z * a;
                let norm = down.norm();
                if norm > 1e-12 {
                    end - *radius * down / norm
                } else {
                    end
                }
            }
            Shape::Cuboid { half } => {
                let r = q.to_rotation_matrix();
                let mut p = *c;
                for (k, h) in half.iter().enumerate() {
                    let col = r.matrix().column(k).into_owned();
                    p -= col * *h * col.z.signum_or_zero();
                }
                p
            }
            Shape::Mesh(m) => {
                let r = q.to_rotation_matrix();
                m.vertices
                    .iter()
                    .map(|v| c + r * v)
                    .min_by(|a, b| a.z.total_cmp(&b.z))
                    .unwrap_or(*c)
            }
        }
    }

    /// A bound on the distance of any of its points from the centre of mass [m].
    pub fn reach(&self) -> f64 {
        match self {
            Shape::Sphere { radius } => *radius,
            Shape::Capsule {
                radius,
                half_length,
            } => radius + half_length,
            Shape::Cylinder {
                radius,
                half_length,
            } => radius.hypot(*half_length),
            Shape::Cuboid { half } => V3::new(half[0], half[1], half[2]).norm(),
            Shape::Mesh(m) => m.vertices.iter().map(|v| v.norm()).fold(0.0, f64::max),
        }
    }

    /// The immersed surface's elements at the pose (`c`, `q`) moving with (`v`, `omega`),
    /// below the surface `z = surface`, appended to `out`.
    #[allow(clippy::too_many_arguments)]
    pub fn elements(
        &self,
        c: &V3,
        q: &UnitQuaternion<f64>,
        v: &V3,
        omega: &V3,
        surface: f64,
        rule: &Quadrature,
        out: &mut Elements,
    ) {
        // Out of the sand: nothing (a mesh's triangles are each skipped when above, without
        // a second pass over its vertices). A face that lies on the surface is in: the load
        // at the instant a body enters is the limit from inside (a flat end's drag, c rho_g A
        // v^2 under `poncelet`, acts from the first instant, as the planar engine's does).
        if !matches!(self, Shape::Mesh(_)) && self.lowest_point(c, q).z > surface {
            return;
        }
        let motion = Motion {
            c: *c,
            v: *v,
            omega: *omega,
            surface,
        };
        match self {
            Shape::Sphere { radius } => sphere_patch(&motion, c, *radius, None, rule, out),
            Shape::Capsule {
                radius,
                half_length,
            } => {
                let a = q * V3::z();
                cylinder_side(&motion, &a, *radius, *half_length, rule, out);
                sphere_patch(
                    &motion,
                    &(c + *half_length * a),
                    *radius,
                    Some(a),
                    rule,
                    out,
                );
                sphere_patch(
                    &motion,
                    &(c - *half_length * a),
                    *radius,
                    Some(-a),
                    rule,
                    out,
                );
            }
            Shape::Cylinder {
                radius,
                half_length,
            } => {
                let a = q * V3::z();
                cylinder_side(&motion, &a, *radius, *half_length, rule, out);
                disk(&motion, &(c + *half_length * a), &a, *radius, rule, out);
                disk(&motion, &(c - *half_length * a), &(-a), *radius, rule, out);
            }
            Shape::Cuboid { half } => {
                let r = q.to_rotation_matrix();
                let corner = |sx: f64, sy: f64, sz: f64| {
                    c + r * V3::new(sx * half[0], sy * half[1], sz * half[2])
                };
                // Each face counter-clockwise seen from outside.
                const FACES: [[[f64; 3]; 4]; 6] = [
                    [[1., -1., -1.], [1., 1., -1.], [1., 1., 1.], [1., -1., 1.]],
                    [
                        [-1., -1., -1.],
                        [-1., -1., 1.],
                        [-1., 1., 1.],
                        [-1., 1., -1.],
                    ],
                    [[-1., 1., -1.], [-1., 1., 1.], [1., 1., 1.], [1., 1., -1.]],
                    [
                        [-1., -1., -1.],
                        [1., -1., -1.],
                        [1., -1., 1.],
                        [-1., -1., 1.],
                    ],
                    [[-1., -1., 1.], [1., -1., 1.], [1., 1., 1.], [-1., 1., 1.]],
                    [
                        [-1., -1., -1.],
                        [-1., 1., -1.],
                        [1., 1., -1.],
                        [1., -1., -1.],
                    ],
                ];
                for face in FACES {
                    let pts = face.map(|p| corner(p[0], p[1], p[2]));
                    polygon(&motion, &pts, rule, out);
                }
            }
            Shape::Mesh(m) => {
                // Each vertex moved to the world frame and its velocity once (a vertex is
                // shared by about six triangles), the same operations as per triangle.
                let r = q.to_rotation_matrix();
                let mut world = std::mem::take(&mut out.scratch);
                let mut vel = std::mem::take(&mut out.scratch_v);
                world.clear();
                vel.clear();
                world.extend(m.vertices.iter().map(|p| c + r * p));
                vel.extend(world.iter().map(|p| motion.velocity_at(p)));
                let (k, tris) = (rule.subdivisions(), &m.triangles);
                let per = 3 * k * k;
                let mut next = 0;
                while next < tris.len() {
                    // Every triangle's elements written straight into the arrays' room (for up
                    // to 1024 triangles at a time, and two more for a cut's up to three
                    // triangles: a big mesh grows the arrays as it needs), in mesh order.
                    out.reserve(per * ((tris.len() - next).min(1024) + 2));
                    out.fill(|room| {
                        while next < tris.len() {
                            let i = next;
                            let t = tris[i];
                            let pts = [world[t[0]], world[t[1]], world[t[2]]];
                            if pts.iter().all(|p| p.z > surface) {
                                next += 1;
                                continue;
                            }
                            let u = [vel[t[0]], vel[t[1]], vel[t[2]]];
                            let n = r * m.normals[i];
                            match facet(&motion, &pts, &u, &n) {
                                Facet::Whole if room.left() < per => return,
                                Facet::Whole => {
                                    let [a, b, c] = &pts;
                                    triangle_with(a, b, c, &n, m.areas[i], k, surface, room);
                                }
                                Facet::Trailing => {}
                                // A triangle cut by two lines has at most five corners: three
                                // triangles.
                                Facet::Cut if room.left() < 3 * per => return,
                                Facet::Cut => polygon_with(&motion, &pts, &n, rule, room),
                            }
                            next += 1;
                        }
                    });
                }
                out.scratch = world;
                out.scratch_v = vel;
            }
        }
    }
}

/// The lower of the two ends `c +- h a` of an axis.
fn lower_end(c: &V3, a: &V3, h: f64) -> V3 {
    if a.z > 0.0 {
        c - h * a
    } else {
        c + h * a
    }
}

trait SignumOrZero {
    fn signum_or_zero(self) -> f64;
}

impl SignumOrZero for f64 {
    fn signum_or_zero(self) -> f64 {
        if self > 0.0 {
            1.0
        } else if self < 0.0 {
            -1.0
        } else {
            0.0
        }
    }
}

/// The body's motion and the surface, as the elements are cut.
struct Motion {
    c: V3,
    v: V3,
    omega: V3,
    surface: f64,
}

impl Motion {
    #[inline]
    fn velocity_at(&self, x: &V3) -> V3 {
        self.v + self.omega.cross(&(x - self.c))
    }

    /// Whether `n . v` over a set of points is zero within round-off (a grazing face).
    fn grazing(&self, n: &V3, points: &[V3]) -> bool {
        let mut most = 0.0f64;
        let mut speed2 = 0.0f64;
        for p in points {
            let v = self.velocity_at(p);
            most = most.max(n.dot(&v).abs());
            speed2 = speed2.max(v.norm_squared());
        }
        most * most <= 1e-24 * speed2
    }
}

/// A unit vector perpendicular to the unit `a`, as close to +z as can be (any, where `a`
/// is vertical).
fn towards_up(a: &V3) -> V3 {
    let u = V3::z() - a.z * a;
    let n = u.norm();
    if n > 1e-12 {
        u / n
    } else {
        let w = if a.x.abs() < 0.9 { V3::x() } else { V3::y() };
        let u = w - a.dot(&w) * a;
        u / u.norm()
    }
}

/// The part of a sphere (centre `b`, radius `r`) below the surface on its leading side
/// (n . v_b >= 0: on a sphere, `omega x (x - b)` is tangent, so every point's `n . v` is
/// the centre's), and on the side `n . a >= 0` when `half` is given (a capsule's end).
fn sphere_patch(
    m: &Motion,
    b: &V3,
    r: f64,
    half: Option<V3>,
    rule: &Quadrature,
    out: &mut Elements,
) {
    if b.z - r > m.surface {
        return;
    }
    let vb = m.velocity_at(b);
    let speed = vb.norm();
    // The pole: the direction of motion; the leading side is the hemisphere about it.
    let (p, theta_max) = if speed > 0.0 {
        (vb / speed, 0.5 * PI)
    } else {
        // At rest every element grazes: the law decides whether they count.
        (-V3::z(), PI)
    };
    let e1 = towards_up(&p);
    let e2 = p.cross(&e1);
    let depth_ref = m.surface - b.z;
    let mut breaks = Vec::with_capacity(8);
    // Where the circle about the pole at theta is wholly in or out of the sand.
    let qz = e1.z.hypot(e2.z);
    trig_roots(r * p.z, r * qz, depth_ref, 0.0, theta_max, &mut breaks);
    trig_roots(r * p.z, -r * qz, depth_ref, 0.0, theta_max, &mut breaks);
    // Where a circle about the pole touches the horizon n_z = 0 (the law's m flips there).
    trig_roots(p.z, qz, 0.0, 0.0, theta_max, &mut breaks);
    trig_roots(p.z, -qz, 0.0, 0.0, theta_max, &mut breaks);
    if let Some(a) = half {
        let ra = e1.dot(&a).hypot(e2.dot(&a));
        trig_roots(p.dot(&a), ra, 0.0, 0.0, theta_max, &mut breaks);
        trig_roots(p.dot(&a), -ra, 0.0, 0.0, theta_max, &mut breaks);
    }
    let g = &rule.gauss;
    let mut out = Batch::new(out);
    // The horizon's angles on each circle (one buffer for all of them).
    let mut flips = Vec::with_capacity(4);
    pieces(0.0, theta_max, &mut breaks, PANEL, |t0, t1| {
        g.each(t0, t1, |theta, wt| {
            let (st, ct) = theta.sin_cos();
            // Below the surface: r st (cos e1_z + sin e2_z) <= depth_ref - r ct p_z.
            let Some(wet) = arc_below(r * st * e1.z, r * st * e2.z, depth_ref - r * ct * p.z)
            else {
                return;
            };
            let (arcs, k) = match half {
                // n . a >= 0:  -st (cos e1.a + sin e2.a) <= ct p.a
                Some(a) => match arc_below(-st * e1.dot(&a), -st * e2.dot(&a), ct * p.dot(&a)) {
                    Some(side) => intersect(wet, side),
                    None => return,
                },
                None => ([Some(wet), None], 1),
            };
            for arc in arcs[..k].iter().flatten() {
                // Cut where the circle crosses the horizon n_z = 0 (the law jumps there).
                let (lo, hi) = (arc.start, arc.start + arc.len);
                flips.clear();
                trig_roots(st * e1.z, st * e2.z, -ct * p.z, lo, hi, &mut flips);
                around(lo, hi, &mut flips, PANEL, g, |phi, wf| {
                    let (sp, cp) = phi.sin_cos();
                    let n = ct * p + st * (cp * e1 + sp * e2);
                    let x = b + r * n;
                    out.push(x, n, r * r * st * wt * wf, m.surface);
                });
            }
        });
    });
}

/// A cylinder's side about its axis `a` through the centre (radius `r`, half length `h`).
fn cylinder_side(m: &Motion, a: &V3, r: f64, h: f64, rule: &Quadrature, out: &mut Elements) {
    if h <= 0.0 {
        return;
    }
    let u1 = towards_up(a);
    let u2 = a.cross(&u1);
    let c = m.c;
    let wa = m.omega.cross(a);
    let mut breaks = Vec::with_capacity(8);
    for t in [-h, h] {
        // depth at the generator's end: surface - c_z - t a_z - r n_z = 0
        trig_roots(
            r * u1.z,
            r * u2.z,
            m.surface - c.z - t * a.z,
            0.0,
            2.0 * PI,
            &mut breaks,
        );
        // n . v at the end: n . (v + t omega x a) = 0
        let w = m.v + t * wa;
        trig_roots(u1.dot(&w), u2.dot(&w), 0.0, 0.0, 2.0 * PI, &mut breaks);
    }
    // Where the side's normal is horizontal (the law's m flips there).
    trig_roots(u1.z, u2.z, 0.0, 0.0, 2.0 * PI, &mut breaks);
    let g = &rule.gauss;
    let mut out = Batch::new(out);
    let speed = m.v.norm() + m.omega.norm() * (r + h);
    around(0.0, 2.0 * PI, &mut breaks, PANEL, g, |phi, wf| {
        {
            let (sp, cp) = phi.sin_cos();
            let n = cp * u1 + sp * u2;
            // Depth along the generator: (surface - c_z - r n_z) - t a_z >= 0.
            let Some((lo, hi)) = clip_linear(-h, h, m.surface - c.z - r * n.z, -a.z) else {
                return;
            };
            // Leading: n . v + t n . (omega x a) >= 0, unless it grazes all along.
            let (l0, l1) = (n.dot(&m.v), n.dot(&wa));
            let (lo, hi) = if l0.abs() + h * l1.abs() <= 1e-12 * speed {
                (lo, hi)
            } else {
                match clip_linear(lo, hi, l0, l1) {
                    Some(x) => x,
                    None => return,
                }
            };
            g.each(lo, hi, |t, wt| {
                let x = c + r * n + t * a;
                out.push(x, n, r * wf * wt, m.surface);
            });
        }
    });
}

/// A flat disk (centre `e`, outward normal `nu`, radius `r`): a cylinder's end.
fn disk(m: &Motion, e: &V3, nu: &V3, r: f64, rule: &Quadrature, out: &mut Elements) {
    let u1 = towards_up(nu);
    let u2 = nu.cross(&u1);
    let ve = m.velocity_at(e);
    let (w1, w2) = (nu.dot(&m.omega.cross(&u1)), nu.dot(&m.omega.cross(&u2)));
    let depth0 = m.surface - e.z;
    let mut breaks = Vec::with_capacity(4);
    trig_roots(r * u1.z, r * u2.z, depth0, 0.0, 2.0 * PI, &mut breaks);
    trig_roots(r * w1, r * w2, -nu.dot(&ve), 0.0, 2.0 * PI, &mut breaks);
    let rim = [e + r * u1, e - r * u1, e + r * u2, e - r * u2, *e];
    let grazing = m.grazing(nu, &rim);
    let g = &rule.gauss;
    let mut out = Batch::new(out);
    around(0.0, 2.0 * PI, &mut breaks, PANEL, g, |phi, wf| {
        let (sp, cp) = phi.sin_cos();
        let d = cp * u1 + sp * u2;
        let Some((lo, hi)) = clip_linear(0.0, r, depth0, -d.z) else {
            return;
        };
        let (lo, hi) = if grazing {
            (lo, hi)
        } else {
            match clip_linear(lo, hi, nu.dot(&ve), cp * w1 + sp * w2) {
                Some(x) => x,
                None => return,
            }
        };
        g.each(lo, hi, |rho, wr| {
            out.push(e + rho * d, *nu, rho * wf * wr, m.surface);
        });
    });
}

/// A convex polygon of at most 8 vertices (a quad cut by two lines has at most 6), on the
/// stack.
#[derive(Clone, Copy)]
struct Poly {
    p: [V3; 8],
    len: usize,
}

impl Poly {
    fn of(pts: &[V3]) -> Poly {
        let mut p = [V3::zeros(); 8];
        p[..pts.len()].copy_from_slice(pts);
        Poly { p, len: pts.len() }
    }

    fn points(&self) -> &[V3] {
        &self.p[..self.len]
    }

    /// The part where the linear function `f` is >= 0 (`f` at each vertex given).
    fn clip(&self, f: &[f64]) -> Poly {
        let mut out = Poly {
            p: [V3::zeros(); 8],
            len: 0,
        };
        let k = self.len;
        for i in 0..k {
            let j = (i + 1) % k;
            let (p, q) = (self.p[i], self.p[j]);
            let (fp, fq) = (f[i], f[j]);
            if fp >= 0.0 {
                out.p[out.len] = p;
                out.len += 1;
            }
            if (fp >= 0.0) != (fq >= 0.0) {
                let t = fp / (fp - fq);
                out.p[out.len] = p + t * (q - p);
                out.len += 1;
            }
        }
        out
    }
}

/// What the cut keeps of a mesh's triangle.
enum Facet {
    /// All of it.
    Whole,
    /// None: trailing.
    Trailing,
    /// What [`polygon_with`] finds.
    Cut,
}

/// A mesh's triangle (vertices `pts` counter-clockwise seen from outside, `u` their
/// velocities, `n` its normal) classed at its vertices for [`polygon_with`]: its two common
/// cases first, wholly below the surface and leading (the triangle itself, as
/// [`polygon_with`] keeps it), and wholly trailing by a margin far above the grazing test's
/// (nothing, as [`polygon_with`] finds); the rest is cut. The same elements, bit for bit,
/// given the same normal `n` and area (the mesh's own, turned: they differ from the world
/// vertices' by round-off).
#[inline(always)]
fn facet(m: &Motion, pts: &[V3; 3], u: &[V3; 3], n: &V3) -> Facet {
    let nu = [n.dot(&u[0]), n.dot(&u[1]), n.dot(&u[2])];
    if nu.iter().all(|x| *x >= 0.0) && pts.iter().all(|p| m.surface - p.z >= 0.0) {
        return Facet::Whole;
    }
    let speed2 = u.iter().map(|x| x.norm_squared()).fold(0.0, f64::max);
    let least = nu.iter().map(|x| -x).fold(f64::INFINITY, f64::min);
    // Trailing at every vertex by more than 1e-6 |v|: so at every point of the face (n . v
    // is linear on it, |v| convex), far from the grazing test's 1e-12.
    if least > 0.0 && least * least > 1e-12 * speed2 {
        return Facet::Trailing;
    }
    Facet::Cut
}

/// A flat face's outward unit normal (vertices counter-clockwise seen from outside).
#[inline]
fn face_normal(pts: &[V3]) -> V3 {
    let n = (pts[1] - pts[0]).cross(&(pts[2] - pts[0]));
    n / n.norm()
}

/// A flat convex face (vertices counter-clockwise seen from outside).
fn polygon(m: &Motion, pts: &[V3], rule: &Quadrature, out: &mut Elements) {
    polygon_with(m, pts, &face_normal(pts), rule, out);
}

/// [`polygon`] with its normal `n` given.
fn polygon_with(m: &Motion, pts: &[V3], n: &V3, rule: &Quadrature, out: &mut impl Sink) {
    let n = *n;
    let face = Poly::of(pts);
    let mut f = [0.0; 8];
    let mut all_in = true;
    for (fi, p) in f.iter_mut().zip(face.points()) {
        *fi = m.surface - p.z;
        all_in &= *fi >= 0.0;
    }
    let wet = if all_in {
        face
    } else {
        face.clip(&f[..face.len])
    };
    if wet.len < 3 {
        return;
    }
    let lead = if m.grazing(&n, wet.points()) {
        wet
    } else {
        let mut all_lead = true;
        for (fi, p) in f.iter_mut().zip(wet.points()) {
            *fi = n.dot(&m.velocity_at(p));
            all_lead &= *fi >= 0.0;
        }
        if all_lead {
            wet
        } else {
            wet.clip(&f[..wet.len])
        }
    };
    if lead.len < 3 {
        return;
    }
    let k = rule.subdivisions();
    let p = lead.points();
    for i in 1..p.len() - 1 {
        triangle(&p[0], &p[i], &p[i + 1], &n, k, m.surface, out);
    }
}

/// A triangle's area [m^2].
#[inline]
fn triangle_area(a: &V3, b: &V3, c: &V3) -> f64 {
    0.5 * (b - a).cross(&(c - a)).norm()
}

/// The 3-point rule (degree 2) on each of the `k^2` triangles a triangle is cut into.
fn triangle(a: &V3, b: &V3, c: &V3, n: &V3, k: usize, surface: f64, out: &mut impl Sink) {
    triangle_with(a, b, c, n, triangle_area(a, b, c), k, surface, out);
}

/// [`triangle`] with its area given (always inlined: its corners kept in registers, as
/// [`emit`]'s).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn triangle_with(
    a: &V3,
    b: &V3,
    c: &V3,
    n: &V3,
    area: f64,
    k: usize,
    surface: f64,
    out: &mut impl Sink,
) {
    // The default rule's case (k = 1) on its own: the same operations, its divisions by 1
    // and its loop's counters folded away by the compiler.
    if k == 1 {
        triangle_cut(a, b, c, n, area, 1, surface, out);
    } else {
        triangle_cut(a, b, c, n, area, k, surface, out);
    }
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn triangle_cut(
    a: &V3,
    b: &V3,
    c: &V3,
    n: &V3,
    area: f64,
    k: usize,
    surface: f64,
    out: &mut impl Sink,
) {
    if area <= 0.0 {
        return;
    }
    let weight = area / (k * k) as f64 / 3.0;
    let (ab, ac) = ((b - a) / k as f64, (c - a) / k as f64);
    let at = |i: usize, j: usize| a + i as f64 * ab + j as f64 * ac;
    for i in 0..k {
        for j in 0..k - i {
            emit(
                at(i, j),
                at(i + 1, j),
                at(i, j + 1),
                n,
                weight,
                surface,
                out,
            );
            if i + j + 2 <= k {
                emit(
                    at(i + 1, j),
                    at(i + 1, j + 1),
                    at(i, j + 1),
                    n,
                    weight,
                    surface,
                    out,
                );
            }
        }
    }
}

/// A small triangle's 3-point rule: each point (4 p + q + r) / 6, times the sixth rather
/// than divided by 6 (a product is several times cheaper than a division; the same point
/// to round-off). Always inlined: its corners stay in registers (passed through memory,
/// each load of a corner stalled on the stores that had just written it).
#[inline(always)]
fn emit(p: V3, q: V3, r: V3, n: &V3, weight: f64, surface: f64, out: &mut impl Sink) {
    const SIXTH: f64 = 1.0 / 6.0;
    let x = [4.0 * p + q + r, p + 4.0 * q + r, p + q + 4.0 * r].map(|x| x * SIXTH);
    out.put3(x, n, weight, surface);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_below(shape: &Shape, c: V3, q: UnitQuaternion<f64>, nodes: usize) -> f64 {
        let mut e = Elements::default();
        // Resting: every element grazes, so the cut is only the surface's.
        shape.elements(
            &c,
            &q,
            &V3::zeros(),
            &V3::zeros(),
            0.0,
            &Quadrature::new(nodes),
            &mut e,
        );
        e.area.iter().sum()
    }

    #[test]
    fn a_half_sunk_sphere_has_half_its_area_below_and_a_cap_its_formula() {
        let s = Shape::sphere("s", 0.1).unwrap();
        let a = area_below(&s, V3::zeros(), UnitQuaternion::identity(), 6);
        assert!((a - 2.0 * PI * 0.01).abs() < 1e-13, "{a}");
        // A cap of height d: 2 pi r d (the sphere tilted: the same).
        let q = UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1);
        let a = area_below(&s, V3::new(0.0, 0.0, 0.07), q, 6);
        assert!((a - 2.0 * PI * 0.1 * 0.03).abs() < 1e-13, "{a}");
    }

    #[test]
    fn a_tilted_cylinder_half_sunk_has_half_its_area_below() {
        let s = Shape::cylinder("s", 0.05, 0.3).unwrap();
        let q = UnitQuaternion::from_euler_angles(0.4, 0.9, 0.2);
        let a = area_below(&s, V3::zeros(), q, 6);
        let total = 2.0 * PI * 0.05 * 0.3 + 2.0 * PI * 0.05 * 0.05;
        assert!(
            (a - total / 2.0).abs() < 1e-12 * total,
            "{a} vs {}",
            total / 2.0
        );
    }

    /// An octahedron stretched to 0.2 x 0.12 x 0.08 m about the origin: its corners and its
    /// 8 outward triangles.
    fn octahedron_data() -> (Vec<[f64; 3]>, Vec<[i64; 3]>) {
        let v = vec![
            [0.1, 0.0, 0.0],
            [-0.1, 0.0, 0.0],
            [0.0, 0.06, 0.0],
            [0.0, -0.06, 0.0],
            [0.0, 0.0, 0.04],
            [0.0, 0.0, -0.04],
        ];
        let t = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (v, t)
    }

    /// A UV sphere of radius 50 mm about the origin: `rings` rings of `around` corners
    /// between its poles, and its outward triangles.
    fn uv_sphere_data(rings: usize, around: usize) -> (Vec<[f64; 3]>, Vec<[i64; 3]>) {
        let mut v = vec![[0.0, 0.0, 0.05]];
        for i in 1..rings {
            let th = PI * i as f64 / rings as f64;
            for j in 0..around {
                let ph = 2.0 * PI * j as f64 / around as f64;
                let (s, c) = (0.05 * th.sin(), 0.05 * th.cos());
                v.push([s * ph.cos(), s * ph.sin(), c]);
            }
        }
        v.push([0.0, 0.0, -0.05]);
        let ring = |i: usize, j: usize| (1 + (i - 1) * around + j % around) as i64;
        let bottom = v.len() as i64 - 1;
        let mut t = Vec::new();
        for j in 0..around {
            t.push([0, ring(1, j), ring(1, j + 1)]);
            for i in 1..rings - 1 {
                t.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
                t.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
            }
            t.push([bottom, ring(rings - 1, j + 1), ring(rings - 1, j)]);
        }
        (v, t)
    }

    /// The 0.2 x 0.1 x 0.3 m box about the origin: its corners and 12 outward triangles.
    fn box_mesh_data() -> (Vec<[f64; 3]>, Vec<[i64; 3]>) {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|i| {
                [
                    if i & 1 != 0 { 0.1 } else { -0.1 },
                    if i & 2 != 0 { 0.05 } else { -0.05 },
                    if i & 4 != 0 { 0.15 } else { -0.15 },
                ]
            })
            .collect();
        let t: Vec<[i64; 3]> = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        (v, t)
    }

    #[test]
    fn a_mesh_and_a_cuboid_agree_on_the_same_box() {
        let cube = Shape::cuboid("b", [0.2, 0.1, 0.3]).unwrap();
        let (v, t) = box_mesh_data();
        let mesh = Shape::mesh("m", &v, &t).unwrap();
        assert!((mesh.volume() - cube.volume()).abs() < 1e-15);
        assert!((mesh.unit_inertia() - cube.unit_inertia()).norm() < 1e-15);
        let q = UnitQuaternion::from_euler_angles(0.3, 0.5, -0.2);
        let c = V3::new(0.0, 0.0, 0.05);
        let (a, b) = (area_below(&cube, c, q, 6), area_below(&mesh, c, q, 6));
        assert!((a - b).abs() < 1e-14, "{a} {b}");
        // An inward mesh is refused.
        let flipped: Vec<[i64; 3]> = t.iter().map(|x| [x[0], x[2], x[1]]).collect();
        assert!(Shape::mesh("m", &v, &flipped).is_err());
        // An open one too.
        assert!(Shape::mesh("m", &v, &t[..11]).is_err());
    }

    /// A mesh's triangles taken at their vertices first give the elements the general
    /// clip of each face gives (with the mesh's normal), bit for bit but for a whole
    /// triangle's area (the mesh's, to round-off), at every depth and motion tried.
    #[test]
    fn a_mesh_cut_per_vertex_is_the_clip_of_each_face() {
        // An octahedron stretched and turned: faces in, out, across the surface, leading,
        // trailing and across their leading edge.
        let (v, t) = octahedron_data();
        let shape = Shape::mesh("m", &v, &t).unwrap();
        let Shape::Mesh(m) = &shape else {
            unreachable!()
        };
        let q = UnitQuaternion::from_euler_angles(0.3, 0.5, -0.2);
        let motions = [
            (V3::new(0.4, -0.2, -1.0), V3::new(1.0, 2.0, -0.5)),
            (V3::new(0.0, 0.0, -1.0), V3::zeros()),
            (V3::new(0.3, 0.1, 0.2), V3::new(0.0, 0.0, 3.0)),
            (V3::zeros(), V3::zeros()),
        ];
        for rule in [Quadrature::new(6), Quadrature::new(12)] {
            for z in [-0.2, -0.03, 0.0, 0.02, 0.2] {
                for (v, w) in motions {
                    let c = V3::new(0.01, 0.0, z);
                    let mut fast = Elements::default();
                    shape.elements(&c, &q, &v, &w, 0.0, &rule, &mut fast);
                    let mut each = Elements::default();
                    let r = q.to_rotation_matrix();
                    let motion = Motion {
                        c,
                        v,
                        omega: w,
                        surface: 0.0,
                    };
                    for (t, nb) in m.triangles.iter().zip(&m.normals) {
                        let pts = t.map(|i| c + r * m.vertices[i]);
                        polygon_with(&motion, &pts, &(r * nb), &rule, &mut each);
                    }
                    assert_eq!(
                        (&fast.x, &fast.n, &fast.depth),
                        (&each.x, &each.n, &each.depth),
                        "z {z} v {v:?}"
                    );
                    // A whole triangle's weight is the mesh's area, the clip's from the
                    // world vertices: equal to round-off.
                    assert_eq!(fast.area.len(), each.area.len());
                    for (a, b) in fast.area.iter().zip(&each.area) {
                        assert!((a - b).abs() <= 1e-15 * b, "z {z} v {v:?}: {a} vs {b}");
                    }
                }
            }
        }
    }

    /// The same on a mesh of more triangles than the cut makes room for at a time (a
    /// UV sphere of 2208, all under and at rest: every one whole), at two rules.
    #[test]
    fn a_big_mesh_cut_in_runs_is_the_clip_of_each_face() {
        let (v, t) = uv_sphere_data(24, 48);
        assert_eq!(t.len(), 2208);
        let shape = Shape::mesh("m", &v, &t).unwrap();
        let Shape::Mesh(m) = &shape else {
            unreachable!()
        };
        let q = UnitQuaternion::from_euler_angles(0.3, 0.5, -0.2);
        let r = q.to_rotation_matrix();
        for rule in [Quadrature::new(6), Quadrature::new(12)] {
            for (z, v, w) in [
                (-0.2, V3::zeros(), V3::zeros()),
                (0.01, V3::new(0.3, -0.2, -1.0), V3::new(1.0, 2.0, -0.5)),
            ] {
                let c = V3::new(0.0, 0.0, z);
                let mut fast = Elements::default();
                shape.elements(&c, &q, &v, &w, 0.0, &rule, &mut fast);
                let motion = Motion {
                    c,
                    v,
                    omega: w,
                    surface: 0.0,
                };
                let mut each = Elements::default();
                for (t, nb) in m.triangles.iter().zip(&m.normals) {
                    let pts = t.map(|i| c + r * m.vertices[i]);
                    polygon_with(&motion, &pts, &(r * nb), &rule, &mut each);
                }
                if z < -0.1 {
                    let k = rule.subdivisions();
                    assert_eq!(fast.len(), 3 * k * k * t.len());
                }
                assert_eq!(
                    (&fast.x, &fast.n, &fast.depth),
                    (&each.x, &each.n, &each.depth)
                );
                // The areas: the mesh's against the world vertices' (their edges, 30 times
                // shorter than their distance from the origin here, lose digits to it).
                assert_eq!(fast.area.len(), each.area.len());
                for (a, b) in fast.area.iter().zip(&each.area) {
                    assert!((a - b).abs() <= 1e-13 * b, "{a} vs {b}");
                }
            }
        }
    }

    /// The areas summed as the elements are written are a pass over the elements after,
    /// bit for bit: on every shape, a mesh across the surface (an octahedron with vertices
    /// exactly on it, a box with a face lying on it, a mesh of more triangles than one run
    /// of the cut), leading, trailing, spinning and at rest, at two rules.
    #[test]
    fn the_areas_summed_while_cutting_are_a_pass_over_the_elements() {
        fn pass(e: &Elements, toward: &V3) -> [u64; 5] {
            let (mut wet, mut a, mut m) = (0.0, 0.0, V3::zeros());
            for i in 0..e.len() {
                wet += e.area[i];
                let p = (e.normal(i).dot(toward)).max(0.0) * e.area[i];
                a += p;
                m += p * e.point(i);
            }
            [wet, a, m.x, m.y, m.z].map(f64::to_bits)
        }
        let (v, t) = octahedron_data();
        let octahedron = Shape::mesh("m", &v, &t).unwrap();
        let (corners, faces) = box_mesh_data();
        let boxed = Shape::mesh("b", &corners, &faces).unwrap();
        // A UV sphere of 2208 triangles (more than one run of the cut).
        let (v, t) = uv_sphere_data(24, 48);
        let uv = Shape::mesh("u", &v, &t).unwrap();
        let shapes = [
            (octahedron, vec![-0.2, -0.03, 0.0, 0.02, 0.04]),
            (boxed, vec![-0.2, 0.0, 0.15, 0.1]),
            (uv, vec![-0.2, 0.0, 0.01]),
            (Shape::sphere("s", 0.05).unwrap(), vec![-0.1, 0.0, 0.03]),
            (
                Shape::capsule("c", 0.02, 0.1).unwrap(),
                vec![-0.1, 0.0, 0.03],
            ),
            (
                Shape::cylinder("y", 0.02, 0.1).unwrap(),
                vec![-0.1, 0.0, 0.03],
            ),
            (
                Shape::cuboid("k", [0.1, 0.06, 0.04]).unwrap(),
                vec![-0.1, 0.0, 0.02],
            ),
        ];
        let motions = [
            (V3::new(0.4, -0.2, -1.0), V3::new(1.0, 2.0, -0.5)),
            (V3::new(0.0, 0.0, -1.0), V3::zeros()),
            (V3::new(0.3, 0.1, 0.2), V3::new(0.0, 0.0, 3.0)),
            (V3::new(1.0, 0.0, 0.0), V3::zeros()),
        ];
        let turns = [
            UnitQuaternion::identity(),
            UnitQuaternion::from_euler_angles(0.3, 0.5, -0.2),
        ];
        let mut cases = 0;
        for rule in [Quadrature::new(6), Quadrature::new(12)] {
            for (shape, heights) in &shapes {
                for &z in heights {
                    for (v, w) in motions {
                        for q in &turns {
                            let c = V3::new(0.01, 0.0, z);
                            let toward = v / v.norm();
                            let mut e = Elements::default();
                            e.sum_areas(toward);
                            shape.elements(&c, q, &v, &w, 0.0, &rule, &mut e);
                            let s = e.sums.expect("asked for");
                            assert_eq!(
                                [s.wetted, s.projected, s.moment.x, s.moment.y, s.moment.z]
                                    .map(f64::to_bits),
                                pass(&e, &toward),
                                "{shape:?} z {z} v {v:?} w {w:?}"
                            );
                            cases += usize::from(!e.is_empty());
                            // Cleared, no sums (a caller that does not ask pays nothing).
                            e.clear();
                            shape.elements(&c, q, &v, &w, 0.0, &rule, &mut e);
                            assert!(e.sums.is_none());
                        }
                    }
                }
            }
        }
        assert!(cases > 300, "{cases}");
    }

    #[test]
    fn the_inertia_of_a_capsule_is_its_parts() {
        // A capsule's tensor against a fine mesh-free sum: a cylinder plus a sphere split.
        let (r, h) = (0.1, 0.2);
        let s = Shape::capsule("c", r, 2.0 * h).unwrap();
        let i = s.unit_inertia();
        // Numerical integral over the solid (midpoint rule on a fine grid).
        let n = 120;
        let (mut ixx, mut izz) = (0.0, 0.0);
        let dx = 2.0 * r / n as f64;
        let dz = 2.0 * (h + r) / (2 * n) as f64;
        for a in 0..n {
            for b in 0..n {
                for k in 0..2 * n {
                    let x = -r + (a as f64 + 0.5) * dx;
                    let y = -r + (b as f64 + 0.5) * dx;
                    let z = -(h + r) + (k as f64 + 0.5) * dz;
                    let zc = z.abs() - h;
                    let inside = if zc <= 0.0 {
                        x * x + y * y <= r * r
                    } else {
                        x * x + y * y + zc * zc <= r * r
                    };
                    if inside {
                        let dv = dx * dx * dz;
                        ixx += (y * y + z * z) * dv;
                        izz += (x * x + y * y) * dv;
                    }
                }
            }
        }
        assert!((i[(0, 0)] - ixx).abs() < 5e-3 * ixx, "{} {ixx}", i[(0, 0)]);
        assert!((i[(2, 2)] - izz).abs() < 5e-3 * izz, "{} {izz}", i[(2, 2)]);
    }
}
