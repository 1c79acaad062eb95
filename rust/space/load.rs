//! The sand's force and moment on a body in space: each listed term over the immersed
//! surface elements ([`super::shape::Elements`]).
//!
//! `rft3d` and `rft3d_inertial` act per element (their kernels are in their term file,
//! `forces/rft3d.rs`, generic over the number type, so that four elements go through one
//! set of SIMD instructions); `poncelet` acts at the centre of the immersed leading area
//! (see [`Terms3`]); `gravity` is the body's weight.

use nalgebra::{UnitQuaternion, Vector3};

use super::quad::Gauss;
use super::shape::{Elements, Quadrature, Shape};
use crate::error::{GranrsError, Result};
use crate::forces::poncelet::Poncelet;
use crate::forces::rft3d::{
    direction, ramp_position, stress_as, stress_capped, stress_on_ramp, stress_with_ramp,
    stress_with_rate, stress_with_rate_on_ramp, Rft3d, Rft3dInertial, Rft3dLanes,
};
use crate::forces::{Acts, AnyTerm, Medium, TermSpec, TERMS};
use crate::num::Real;

type V3 = Vector3<f64>;

/// The terms that act on a body in space, each at most once.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Terms3 {
    /// 3D-RFT.
    pub rft3d: Option<Rft3d>,
    /// Its inertial term.
    pub inertial: Option<Rft3dInertial>,
    /// Poncelet / Katsuragi-Durian: `F = -c rho_g A |v_E| v_E - k d v_E / |v_E|` at E, with
    /// A the immersed leading area projected on the plane normal to the centre's velocity,
    /// E its centre and d the lowest point's depth (a sphere fully under: A = pi r^2).
    pub poncelet: Option<Poncelet>,
    /// The field the body terms put on the body's mass, in units of the medium's g,
    /// downward (1 under `gravity`).
    pub field: f64,
}

impl Terms3 {
    /// The terms of `specs` for a body of shape `kind`, checked (an unknown term or
    /// parameter, a term not defined in space, a term listed twice: a typed error naming
    /// it, `forces[i]`).
    pub fn from_specs(specs: &[TermSpec], shape: &Shape) -> Result<Terms3> {
        let mut t = Terms3::default();
        let kind = shape.kind();
        for (i, spec) in specs.iter().enumerate() {
            let (info, values) = spec
                .resolve(1)
                .map_err(|e| e.map_field(|f| format!("forces[{i}].{f}")))?;
            let v = &values[0];
            let twice = || GranrsError::InvalidScene {
                field: format!("forces[{i}]"),
                message: format!("`{}` is listed twice", info.name),
            };
            if specs[..i].iter().any(|s| s.name == info.name) {
                return Err(twice());
            }
            match info.name {
                _ if !info.shapes.contains(&kind) => {
                    let here: Vec<&str> = TERMS
                        .iter()
                        .filter(|t| t.shapes.contains(&kind))
                        .map(|t| t.name)
                        .collect();
                    return Err(GranrsError::InvalidScene {
                        field: format!("forces[{i}]"),
                        message: format!(
                            "`{}` does not act on a {} in space (terms on it: {})",
                            info.name,
                            kind.name(),
                            here.join(", ")
                        ),
                    });
                }
                _ if info.acts == Acts::Body => {
                    t.field += AnyTerm::from_name(info.name, v)
                        .expect("a registered term")
                        .field();
                }
                "rft3d" => {
                    t.rft3d = Some(<Rft3d as crate::forces::Term>::from_params(v));
                }
                "rft3d_inertial" => {
                    t.inertial = Some(<Rft3dInertial as crate::forces::Term>::from_params(v));
                }
                "poncelet" => {
                    t.poncelet = Some(<Poncelet as crate::forces::Term>::from_params(v));
                }
                other => {
                    return Err(GranrsError::InvalidScene {
                        field: format!("forces[{i}]"),
                        message: format!("`{other}` has no form in space yet"),
                    })
                }
            }
        }
        Ok(t)
    }

    /// Whether any term reads the immersed surface.
    pub fn any_sand(&self) -> bool {
        self.rft3d.is_some() || self.inertial.is_some() || self.poncelet.is_some()
    }
}

/// The sand's load on the body at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Load {
    /// The sand's force, world frame [N] (the weight not included).
    pub force: V3,
    /// Its moment about the centre of mass, world frame [N m].
    pub moment: V3,
    /// `rft3d`'s share of the force [N].
    pub rft3d: V3,
    /// `rft3d_inertial`'s share [N].
    pub inertial: V3,
    /// `poncelet`'s share [N].
    pub poncelet: V3,
    /// The immersed surface's area [m^2].
    pub wetted_area: f64,
    /// The immersed leading area projected normal to the centre's velocity [m^2].
    pub projected_area: f64,
    /// How many surface elements were evaluated.
    pub elements: usize,
}

/// What an evaluation of the load needs besides the state: the shape, the terms, the
/// medium, the surface and the rule, with the buffers it reuses.
#[derive(Debug, Clone)]
pub struct Sand {
    /// The body's shape.
    pub shape: Shape,
    /// The listed terms.
    pub terms: Terms3,
    /// The medium.
    pub medium: Medium,
    /// The sand's surface z [m].
    pub surface: f64,
    /// The surface rule.
    pub rule: Quadrature,
    /// Whether [`Load::wetted_area`] and [`Load::projected_area`] are computed where no term
    /// needs them (a caller that reports them; a run does not).
    pub report_areas: bool,
    elements: Elements,
    /// The rule of [`Sand::axisymmetric`] in `n_z` ([`RING_NODES`] points).
    rings: Gauss,
}

/// Gauss-Legendre points in `n_z` of the closed form on a sphere moving straight up or
/// down ([`Sand::axisymmetric`]): exact for a polynomial of degree `2 * 4 - 1 = 7`; the
/// integrands there have degree 5 at most.
pub const RING_NODES: usize = 4;

impl Sand {
    /// The sand acting on `shape`.
    pub fn new(
        shape: Shape,
        terms: Terms3,
        medium: Medium,
        surface: f64,
        rule: Quadrature,
    ) -> Sand {
        Sand {
            shape,
            terms,
            medium,
            surface,
            rule,
            report_areas: false,
            elements: Elements::default(),
            rings: Gauss::new(RING_NODES),
        }
    }

    /// The immersed elements at the pose (for a caller that shows them).
    pub fn elements_at(
        &mut self,
        c: &V3,
        q: &UnitQuaternion<f64>,
        v: &V3,
        omega: &V3,
    ) -> &Elements {
        self.elements.clear();
        self.shape
            .elements(c, q, v, omega, self.surface, &self.rule, &mut self.elements);
        &self.elements
    }

    /// The load at the pose (`c`, `q`) and motion (`v` of the centre, `omega`).
    pub fn load(&mut self, c: &V3, q: &UnitQuaternion<f64>, v: &V3, omega: &V3) -> Load {
        if !self.terms.any_sand() {
            return Load::default();
        }
        if let Some(out) = self.axisymmetric(c, q, v, omega) {
            return out;
        }
        self.load_cut(c, q, v, omega)
    }

    /// [`Sand::load`] over the cut elements (the general path).
    fn load_cut(&mut self, c: &V3, q: &UnitQuaternion<f64>, v: &V3, omega: &V3) -> Load {
        let mut out = Load::default();
        let areas = self.report_areas || self.terms.poncelet.is_some();
        let speed = v.norm();
        self.elements.clear();
        if areas && speed > 0.0 {
            // The areas summed as the elements are cut (no second pass over them).
            self.elements.sum_areas(v / speed);
        }
        self.shape
            .elements(c, q, v, omega, self.surface, &self.rule, &mut self.elements);
        let e = &self.elements;
        out.elements = e.len();
        if e.is_empty() {
            return out;
        }
        let mut moment = V3::zeros();
        if let Some(law) = self.terms.rft3d {
            let (f, m) = rft3d_sum(&law.lanes(), e, c, v, omega);
            out.rft3d = f;
            moment += m;
        }
        if let Some(t) = self.terms.inertial {
            let k = t.lam * self.medium.rho_g;
            let mut f = V3::zeros();
            for i in 0..e.len() {
                let r = e.point(i) - c;
                let vx = v + omega.cross(&r);
                let nn = e.normal(i);
                let tr = Rft3dInertial::traction(k, [nn.x, nn.y, nn.z], [vx.x, vx.y, vx.z]);
                let df = V3::from(tr) * e.area[i];
                f += df;
                moment += r.cross(&df);
            }
            out.inertial = f;
        }
        if !areas {
            out.force = out.rft3d + out.inertial;
            out.moment = moment;
            return out;
        }
        if let Some(sums) = e.sums {
            let a = sums.projected;
            out.wetted_area = sums.wetted;
            out.projected_area = a;
            let at = (a > 0.0).then(|| sums.moment / a);
            self.poncelet(&mut out, &mut moment, c, q, v, omega, a, at);
        } else {
            out.wetted_area = e.area.iter().sum();
        }
        out.force = out.rft3d + out.inertial + out.poncelet;
        out.moment = moment;
        out
    }

    /// `poncelet`'s force (into `out.poncelet`) and its moment (added to `moment`), from the
    /// immersed leading area `a` projected normal to the centre's velocity and its centre
    /// `at` (`None` where `a` is zero: the lowest point).
    #[allow(clippy::too_many_arguments)]
    fn poncelet(
        &self,
        out: &mut Load,
        moment: &mut V3,
        c: &V3,
        q: &UnitQuaternion<f64>,
        v: &V3,
        omega: &V3,
        a: f64,
        at: Option<V3>,
    ) {
        let Some(p) = self.terms.poncelet else {
            return;
        };
        let low = self.shape.lowest_point(c, q);
        let d = (self.surface - low.z).max(0.0);
        let at = at.unwrap_or(low);
        let r = at - c;
        let ve = v + omega.cross(&r);
        let s = ve.norm();
        if s > 0.0 {
            let f = -(p.c * self.medium.rho_g * a * s) * ve - (p.k * d / s) * ve;
            out.poncelet = f;
            *moment += r.cross(&f);
        }
    }

    /// The load on a sphere whose centre moves straight up or down (`v` vertical, not zero)
    /// without spin (`omega` zero), in closed form; `None` for any other shape or motion,
    /// and where `rft3d` has a friction cap (its stress is then not a polynomial in `n_z`).
    ///
    /// Every point of the sphere then moves with `v`: a term's stress on an element
    /// depends on its normal only through `n_z` (`rft3d`: `x1 = -v^_z`, `x2 = |n_z|`,
    /// `x3 = m_z v^_z`, and its vertical part `f1 m_z + f2 v^_z - f3`; `rft3d_inertial`:
    /// `(n_z v_z)^2 n_z`), and the horizontal parts cancel around each circle `n_z =
    /// const`. With `dA = r^2 dn_z dphi`, the force is `2 pi r^2` times an integral over
    /// `n_z` between the leading and immersed limits of a polynomial of degree 5 at most
    /// (the stress's cubic times `m_z` times the depth, linear in `n_z`), which
    /// Gauss-Legendre with [`RING_NODES`] points integrates exactly. The moment is zero,
    /// and so is the sideways force. The result is the exact surface integral to round-off,
    /// whatever the scene's rule (the rule's own error, at most ~1e-6 of the force at the
    /// default 6 nodes, is what it differs by from the general cut). `Load::elements` counts
    /// the circles evaluated.
    fn axisymmetric(&self, c: &V3, q: &UnitQuaternion<f64>, v: &V3, omega: &V3) -> Option<Load> {
        let Shape::Sphere { radius: r } = self.shape else {
            return None;
        };
        if !(v.x == 0.0 && v.y == 0.0 && v.z != 0.0 && *omega == V3::zeros()) {
            return None;
        }
        if self.terms.rft3d.is_some_and(|l| l.mu_surf != f64::INFINITY) {
            return None;
        }
        let mut out = Load::default();
        // The leading hemisphere (n . v >= 0) below the surface, in n_z.
        let top = (self.surface - c.z) / r;
        let (lo, hi) = if v.z < 0.0 {
            (-1.0, top.min(0.0))
        } else {
            (0.0, top.min(1.0))
        };
        if hi <= lo {
            return Some(out);
        }
        let ring = 2.0 * std::f64::consts::PI * r * r;
        let law = self.terms.rft3d.map(|l| l.lanes());
        let k_inertial = self.terms.inertial.map(|t| t.lam * self.medium.rho_g);
        let (mut fz, mut iz, mut a, mut az) = (0.0, 0.0, 0.0, 0.0);
        let vv = [v.x, v.y, v.z];
        self.rings.each(lo, hi, |nz, w| {
            // The element at phi = 0 of the circle n_z: its vertical stress is the circle's.
            let n = [(1.0 - nz * nz).max(0.0).sqrt(), 0.0, nz];
            let z = c.z + r * nz;
            let weight = ring * w;
            if let Some(law) = &law {
                let depth = (self.surface - z).max(0.0);
                fz += stress_capped::<f64, false>(law, n, vv)[2] * (weight * depth);
            }
            if let Some(k) = k_inertial {
                iz += Rft3dInertial::traction(k, n, vv)[2] * weight;
            }
            // The leading area projected normal to v, and its centre's height.
            let p = nz.abs() * weight;
            a += p;
            az += p * z;
        });
        out.elements = RING_NODES;
        out.rft3d = V3::new(0.0, 0.0, fz);
        out.inertial = V3::new(0.0, 0.0, iz);
        let mut moment = V3::zeros();
        if self.report_areas || self.terms.poncelet.is_some() {
            out.wetted_area = ring * (hi - lo);
            out.projected_area = a;
            // On the axis (so that the moment is zero, not round-off).
            let at = (a > 0.0).then(|| V3::new(c.x, c.y, az / a));
            self.poncelet(&mut out, &mut moment, c, q, v, omega, a, at);
        }
        out.force = out.rft3d + out.inertial + out.poncelet;
        out.moment = moment;
        Some(out)
    }
}

/// The sand's wrench on a body at one instant with its rates, as an implicit step needs
/// them (`super::engine`): the force and the moment about the centre `c`, their
/// derivatives with respect to the centre's velocity and the angular velocity, and to the
/// body's height.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// Force (x, y, z) [N] and moment about the centre (x, y, z) [N m], world frame.
    pub w: [f64; 6],
    /// `d w / d (v, omega)` [6 x 6; N s/m, N s, N m s].
    pub k: [[f64; 6]; 6],
    /// `d w / d c_z`: the body raised by dz, every element's depth less by dz [N/m, N].
    pub kz: [f64; 6],
}

impl Wrench {
    /// Add a force `f` at arm `r` from the centre with its rate `g = d f / d u` (u the
    /// point's velocity, `v + omega x r`) and its height rate `fz`.
    #[inline]
    fn add(&mut self, r: &V3, f: [f64; 3], g: &[[f64; 3]; 3], fz: [f64; 3]) {
        let t = element_terms(r, f, g, fz);
        let mut acc = self.terms();
        for (a, x) in acc.iter_mut().zip(t) {
            *a += x;
        }
        self.set_terms(&acc);
    }

    /// Its numbers in the order of [`element_terms`]: `w`, `kz`, then `k` by rows.
    #[inline(always)]
    fn terms(&self) -> [f64; TERMS_PER_ELEMENT] {
        let mut t = [0.0; TERMS_PER_ELEMENT];
        t[..6].copy_from_slice(&self.w);
        t[6..12].copy_from_slice(&self.kz);
        for (i, row) in self.k.iter().enumerate() {
            t[12 + 6 * i..18 + 6 * i].copy_from_slice(row);
        }
        t
    }

    /// [`Wrench::terms`] written back.
    #[inline(always)]
    fn set_terms(&mut self, t: &[f64; TERMS_PER_ELEMENT]) {
        self.w.copy_from_slice(&t[..6]);
        self.kz.copy_from_slice(&t[6..12]);
        for (i, row) in self.k.iter_mut().enumerate() {
            row.copy_from_slice(&t[12 + 6 * i..18 + 6 * i]);
        }
    }
}

/// How many numbers an element adds to a [`Wrench`] with its rates.
const TERMS_PER_ELEMENT: usize = 48;

/// What a force `f` at arm `r` from the centre with its rate `g = d f / d u` (u the point's
/// velocity, `v + omega x r`) and its height rate `fz` adds to a [`Wrench`]: to `w` (the
/// force, its moment), to `kz` (the height rate, its moment) and to `k` by rows, in this
/// order ([`Wrench::terms`]).
#[inline(always)]
fn element_terms(r: &V3, f: [f64; 3], g: &[[f64; 3]; 3], fz: [f64; 3]) -> [f64; TERMS_PER_ELEMENT] {
    let mut t = [0.0; TERMS_PER_ELEMENT];
    let rf = cross(r, f);
    let rzf = cross(r, fz);
    t[..3].copy_from_slice(&f);
    t[3..6].copy_from_slice(&rf);
    t[6..9].copy_from_slice(&fz);
    t[9..12].copy_from_slice(&rzf);
    {
        let (rx, ry, rz) = (r.x, r.y, r.z);
        let cross = |a: [f64; 3]| cross(r, a);
        // u = v - R omega, R a = r x a: the force's rate in the twist is G [I, -R]; the
        // moment's, R G [I, -R]. Row i of -G R is -(r x^T)... written out: (G R)_ij =
        // sum_k G_ik R_kj, with R = [[0, -rz, ry], [rz, 0, -rx], [-ry, rx, 0]].
        let mut gt = [[0.0; 6]; 3];
        for i in 0..3 {
            let gi = g[i];
            gt[i][0] = gi[0];
            gt[i][1] = gi[1];
            gt[i][2] = gi[2];
            gt[i][3] = -(gi[1] * rz - gi[2] * ry);
            gt[i][4] = -(-gi[0] * rz + gi[2] * rx);
            gt[i][5] = -(gi[0] * ry - gi[1] * rx);
        }
        let [g0, g1, g2] = gt;
        for (c, ((a, b), d)) in g0.into_iter().zip(g1).zip(g2).enumerate() {
            let col = [a, b, d];
            let m = cross(col);
            for (i, (&x, y)) in col.iter().zip(m).enumerate() {
                t[12 + 6 * i + c] = x;
                t[12 + 6 * (3 + i) + c] = y;
            }
        }
    }
    t
}

impl Wrench {
    /// [`Wrench::add`] without the rate `g`: the force, its moment and their height rates
    /// (the same operations).
    #[inline]
    fn add_value(&mut self, r: &V3, f: [f64; 3], fz: [f64; 3]) {
        let rf = cross(r, f);
        let rzf = cross(r, fz);
        for i in 0..3 {
            self.w[i] += f[i];
            self.w[3 + i] += rf[i];
            self.kz[i] += fz[i];
            self.kz[3 + i] += rzf[i];
        }
    }
}

/// `r x a`.
#[inline(always)]
fn cross(r: &V3, a: [f64; 3]) -> [f64; 3] {
    let (rx, ry, rz) = (r.x, r.y, r.z);
    [
        ry * a[2] - rz * a[1],
        rz * a[0] - rx * a[2],
        rx * a[1] - ry * a[0],
    ]
}

impl Sand {
    /// Cut the body's whole immersed surface at the pose (`c`, `q`), leading or not (the
    /// terms then take the leading elements at whatever velocity [`Sand::wrench`] is
    /// given), and keep it for [`Sand::wrench`]. Returns how many elements.
    pub fn cut_at_rest(&mut self, c: &V3, q: &UnitQuaternion<f64>) -> usize {
        self.elements.clear();
        self.shape.elements(
            c,
            q,
            &V3::zeros(),
            &V3::zeros(),
            self.surface,
            &self.rule,
            &mut self.elements,
        );
        self.elements.len()
    }

    /// The wrench and its rates on the elements of the last [`Sand::cut_at_rest`] (at the
    /// pose `c`, `q`) moving with (`v`, `omega`), each rate-independent term made to vanish
    /// at rest over the speed `eps` [m/s] (`rft3d` per element,
    /// [`crate::forces::rft3d::stress_with_rate`]; `poncelet`'s depth term
    /// `k d v / sqrt(|v|^2 + eps^2)`). `poncelet`'s rate is taken with its area, its point
    /// and the depth held (their change with the velocity's direction is left out).
    pub fn wrench(&self, c: &V3, q: &UnitQuaternion<f64>, v: &V3, omega: &V3, eps: f64) -> Wrench {
        self.wrench_with(c, q, v, omega, eps, true)
    }

    /// [`Sand::wrench`] without the rates `k` (zero; the wrench `w` and its height rates
    /// `kz` the same bits): a solver's trial points, where only the residual is read. About
    /// a third of the work per element.
    pub fn wrench_value(
        &self,
        c: &V3,
        q: &UnitQuaternion<f64>,
        v: &V3,
        omega: &V3,
        eps: f64,
    ) -> Wrench {
        self.wrench_with(c, q, v, omega, eps, false)
    }

    /// [`Sand::wrench`], its rates `k` where `rates` (else zero).
    fn wrench_with(
        &self,
        c: &V3,
        q: &UnitQuaternion<f64>,
        v: &V3,
        omega: &V3,
        eps: f64,
        rates: bool,
    ) -> Wrench {
        let mut out = Wrench::default();
        let e = &self.elements;
        if let Some(law) = self.terms.rft3d {
            match rates {
                _ if eps <= 0.0 || law.mu_surf != f64::INFINITY => {
                    rft3d_elements(&law, e, c, v, omega, eps, rates, &mut out)
                }
                true => rft3d_rated(&law, e, c, v, omega, eps, &mut out),
                false => rft3d_value(&law, e, c, v, omega, eps, &mut out),
            }
        }
        if let Some(t) = self.terms.inertial {
            let k = t.lam * self.medium.rho_g;
            for i in 0..e.len() {
                let r = e.point(i) - c;
                let u = v + omega.cross(&r);
                let n = e.normal(i);
                let un = n.dot(&u);
                if un <= 0.0 {
                    continue;
                }
                let a = e.area[i];
                let tr = Rft3dInertial::traction(k, [n.x, n.y, n.z], [u.x, u.y, u.z]);
                if !rates {
                    out.add_value(&r, tr.map(|x| x * a), [0.0; 3]);
                    continue;
                }
                let mut g = [[0.0; 3]; 3];
                for (p, row) in g.iter_mut().enumerate() {
                    for (q, x) in row.iter_mut().enumerate() {
                        *x = -2.0 * k * un * n[p] * n[q] * a;
                    }
                }
                out.add(&r, tr.map(|x| x * a), &g, [0.0; 3]);
            }
        }
        if let Some(p) = self.terms.poncelet {
            let speed = v.norm();
            if speed > 0.0 && !e.is_empty() {
                let vh = v / speed;
                let (mut a, mut centre) = (0.0, V3::zeros());
                for i in 0..e.len() {
                    let w = (e.normal(i).dot(&vh)).max(0.0) * e.area[i];
                    a += w;
                    centre += w * e.point(i);
                }
                let low = self.shape.lowest_point(c, q);
                let d = (self.surface - low.z).max(0.0);
                let at = if a > 0.0 { centre / a } else { low };
                let r = at - c;
                let u = v + omega.cross(&r);
                let s = u.norm();
                if s > 0.0 {
                    let cr = p.c * self.medium.rho_g * a;
                    let root = (s * s + eps * eps).sqrt();
                    let kd = p.k * d / root;
                    let f = -(cr * s + kd) * u;
                    let fz = (p.k / root) * u;
                    if !rates {
                        out.add_value(&r, [f.x, f.y, f.z], [fz.x, fz.y, fz.z]);
                        return out;
                    }
                    let mut g = [[0.0; 3]; 3];
                    for (i, row) in g.iter_mut().enumerate() {
                        for (j, x) in row.iter_mut().enumerate() {
                            let id = if i == j { 1.0 } else { 0.0 };
                            *x = -cr * (s * id + u[i] * u[j] / s)
                                - kd * (id - u[i] * u[j] / (root * root));
                        }
                    }
                    out.add(&r, [f.x, f.y, f.z], &g, [fz.x, fz.y, fz.z]);
                }
            }
        }
        out
    }
}

/// `rft3d`'s wrench (its rates `k` where `rates`) over the elements into `out`, one element
/// at a time: any law, any `eps` (the kernels [`rft3d_rated`] and [`rft3d_value`] take a
/// law without a friction cap at `eps > 0`, to the same bits).
#[allow(clippy::too_many_arguments)]
fn rft3d_elements(
    law: &Rft3d,
    e: &Elements,
    c: &V3,
    v: &V3,
    omega: &V3,
    eps: f64,
    rates: bool,
    out: &mut Wrench,
) {
    for i in 0..e.len() {
        let r = e.point(i) - c;
        let u = v + omega.cross(&r);
        let n = e.normal(i);
        let (a, d) = (e.area[i], e.depth[i]);
        let w = a * d;
        if !rates {
            // A zero stress adds nothing (a sum that starts at +0 is never -0).
            let s = stress_with_ramp(law, [n.x, n.y, n.z], [u.x, u.y, u.z], eps);
            out.add_value(&r, s.map(|x| x * w), s.map(|x| -x * a));
            continue;
        }
        let (s, j) = stress_with_rate(law, [n.x, n.y, n.z], [u.x, u.y, u.z], eps);
        if s == [0.0; 3] && j == [[0.0; 3]; 3] {
            continue;
        }
        let g = j.map(|row| row.map(|x| x * w));
        out.add(&r, s.map(|x| x * w), &g, s.map(|x| -x * a));
    }
}

/// `rft3d`'s wrench with its rates over the elements into `out`, as [`rft3d_elements`] with
/// `rates` (a law without a friction cap, `eps > 0`): per block, each element's
/// [`element_terms`] in a loop without a branch ([`stress_with_rate_on_ramp`]; AVX2 where
/// the CPU has it: the same IEEE operations), then added in the elements' order, so the
/// same bits (an element left out there adds zeros here, and a sum that starts at +0 is
/// never -0).
fn rft3d_rated(law: &Rft3d, e: &Elements, c: &V3, v: &V3, omega: &V3, eps: f64, out: &mut Wrench) {
    #[cfg(target_arch = "x86_64")]
    if crate::num::avx2() {
        // SAFETY: this CPU has AVX2 (checked).
        return unsafe { rft3d_rated_avx2(law, e, c, v, omega, eps, out) };
    }
    rft3d_rated_blocks(law, e, c, v, omega, eps, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn rft3d_rated_avx2(
    law: &Rft3d,
    e: &Elements,
    c: &V3,
    v: &V3,
    omega: &V3,
    eps: f64,
    out: &mut Wrench,
) {
    rft3d_rated_blocks(law, e, c, v, omega, eps, out)
}

#[inline(always)]
fn rft3d_rated_blocks(
    law: &Rft3d,
    e: &Elements,
    c: &V3,
    v: &V3,
    omega: &V3,
    eps: f64,
    out: &mut Wrench,
) {
    if law.grazing {
        rft3d_rated_with::<true>(law.zeta, e, c, v, omega, eps, out)
    } else {
        rft3d_rated_with::<false>(law.zeta, e, c, v, omega, eps, out)
    }
}

/// Elements per block of [`rft3d_rated`] (its 48 terms per element and the elements it
/// keeps live on the stack: 28 kB).
const RATED_BLOCK: usize = 64;

#[inline(always)]
fn rft3d_rated_with<const GRAZING: bool>(
    zeta: f64,
    e: &Elements,
    c: &V3,
    v: &V3,
    omega: &V3,
    eps: f64,
    out: &mut Wrench,
) {
    let n = e.len();
    // Per block: the elements whose stress is not zero (moving, on the leading ramp),
    // copied side by side, then each one's terms (one row per element, so that the sums
    // below run across the terms in SIMD lanes). The others add zeros in the element loop,
    // and a sum that starts at +0 is never -0: leaving them out gives the same bits, and
    // a moving body's trailing half costs nothing.
    // (Both written before they are read: not zeroed, 4 kB and 24 kB per call.)
    let mut on = [[std::mem::MaybeUninit::<f64>::uninit(); RATED_BLOCK]; 8];
    let mut buf = [std::mem::MaybeUninit::<[f64; TERMS_PER_ELEMENT]>::uninit(); RATED_BLOCK];
    let mut acc = out.terms();
    let mut start = 0;
    while start < n {
        let len = RATED_BLOCK.min(n - start);
        let (xs, ns) = (&e.x, &e.n);
        let mut m = 0;
        for i in start..start + len {
            let (x, nn) = (
                [xs[0][i], xs[1][i], xs[2][i]],
                [ns[0][i], ns[1][i], ns[2][i]],
            );
            let (_, u) = arm_and_velocity(x, c, v, omega);
            let (s2, _, _, nu) = direction(nn, u);
            let keep = s2.select_pos(ramp_position(nu, eps, GRAZING), 0.0) > 0.0;
            let values = [x[0], x[1], x[2], nn[0], nn[1], nn[2], e.area[i], e.depth[i]];
            for (col, y) in on.iter_mut().zip(values) {
                col[m].write(y);
            }
            m += usize::from(keep);
        }
        // SAFETY: the loop above wrote each column's first `m` (and more).
        let [x0, x1, x2, n0, n1, n2, area, depth]: [&[f64]; 8] = std::array::from_fn(|k| unsafe {
            std::slice::from_raw_parts(on[k].as_ptr().cast::<f64>(), m)
        });
        for (j, row) in buf[..m].iter_mut().enumerate() {
            let (r, u) = arm_and_velocity([x0[j], x1[j], x2[j]], c, v, omega);
            let n = [n0[j], n1[j], n2[j]];
            let (s, jac) = stress_with_rate_on_ramp(zeta, n, u, eps, GRAZING);
            let a = area[j];
            let w = a * depth[j];
            let g = jac.map(|row| row.map(|x| x * w));
            let r = V3::new(r[0], r[1], r[2]);
            row.write(element_terms(&r, s.map(|x| x * w), &g, s.map(|x| -x * a)));
        }
        // Each sum in the elements' order (48 running sums side by side).
        for row in &buf[..m] {
            // SAFETY: the loop above wrote the first `m` rows.
            let row = unsafe { row.assume_init_ref() };
            for (a, x) in acc.iter_mut().zip(row) {
                *a += x;
            }
        }
        start += len;
    }
    out.set_terms(&acc);
}

/// `rft3d`'s wrench and its height rates over the elements into `out` (no rates `k`), as
/// [`Sand::wrench_value`]'s element loop (a law without a friction cap, `eps > 0`): per
/// block, each element's force, height rate and their moments in a loop the compiler
/// vectorizes ([`stress_on_ramp`], branch-free; AVX2 where the CPU has it: the same IEEE
/// operations), then added in the elements' order, so the same bits as
/// [`Wrench::add_value`] one element at a time.
fn rft3d_value(law: &Rft3d, e: &Elements, c: &V3, v: &V3, omega: &V3, eps: f64, out: &mut Wrench) {
    #[cfg(target_arch = "x86_64")]
    if crate::num::avx2() {
        // SAFETY: this CPU has AVX2 (checked).
        return unsafe { rft3d_value_avx2(law, e, c, v, omega, eps, out) };
    }
    rft3d_value_blocks(law, e, c, v, omega, eps, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn rft3d_value_avx2(
    law: &Rft3d,
    e: &Elements,
    c: &V3,
    v: &V3,
    omega: &V3,
    eps: f64,
    out: &mut Wrench,
) {
    rft3d_value_blocks(law, e, c, v, omega, eps, out)
}

#[inline(always)]
fn rft3d_value_blocks(
    law: &Rft3d,
    e: &Elements,
    c: &V3,
    v: &V3,
    omega: &V3,
    eps: f64,
    out: &mut Wrench,
) {
    if law.grazing {
        rft3d_value_with::<true>(law.zeta, e, c, v, omega, eps, out)
    } else {
        rft3d_value_with::<false>(law.zeta, e, c, v, omega, eps, out)
    }
}

#[inline(always)]
fn rft3d_value_with<const GRAZING: bool>(
    zeta: f64,
    e: &Elements,
    c: &V3,
    v: &V3,
    omega: &V3,
    eps: f64,
    out: &mut Wrench,
) {
    let n = e.len();
    // Per block: each element's force (3), its moment (3), the height rate (3) and its
    // moment (3), written before they are read (not zeroed).
    let mut buf = [[std::mem::MaybeUninit::<f64>::uninit(); BLOCK]; 12];
    let mut start = 0;
    while start < n {
        let len = BLOCK.min(n - start);
        let (xs, ns) = (&e.x, &e.n);
        let (area, depth) = (&e.area[start..start + len], &e.depth[start..start + len]);
        let x = [0, 1, 2].map(|k| &xs[k][start..start + len]);
        let nn = [0, 1, 2].map(|k| &ns[k][start..start + len]);
        for j in 0..len {
            let (r, u) = arm_and_velocity([x[0][j], x[1][j], x[2][j]], c, v, omega);
            let s = stress_on_ramp(zeta, [nn[0][j], nn[1][j], nn[2][j]], u, eps, GRAZING);
            let a = area[j];
            let w = a * depth[j];
            let f = s.map(|x| x * w);
            let fz = s.map(|x| -x * a);
            let r = V3::new(r[0], r[1], r[2]);
            let (rf, rzf) = (cross(&r, f), cross(&r, fz));
            for k in 0..3 {
                buf[k][j].write(f[k]);
                buf[3 + k][j].write(rf[k]);
                buf[6 + k][j].write(fz[k]);
                buf[9 + k][j].write(rzf[k]);
            }
        }
        // SAFETY: the loop above wrote each column's first `len`.
        let cols: [&[f64]; 12] = std::array::from_fn(|k| unsafe {
            std::slice::from_raw_parts(buf[k].as_ptr().cast::<f64>(), len)
        });
        // Each sum in the elements' order (twelve running sums side by side: `j` runs over
        // the elements, each column's).
        let mut acc = [
            out.w[0], out.w[1], out.w[2], out.w[3], out.w[4], out.w[5], out.kz[0], out.kz[1],
            out.kz[2], out.kz[3], out.kz[4], out.kz[5],
        ];
        #[allow(clippy::needless_range_loop)]
        for j in 0..len {
            for (k, a) in acc.iter_mut().enumerate() {
                *a += cols[k][j];
            }
        }
        out.w.copy_from_slice(&acc[..6]);
        out.kz.copy_from_slice(&acc[6..]);
        start += len;
    }
}

/// `rft3d` over the elements: the force and its moment about `c`. The term's kernel runs
/// over a block of elements in a loop the compiler vectorizes (each coordinate contiguous;
/// AVX2 and FMA where the CPU has them: the same IEEE operations, so the same bits; the
/// fitted functions in fused multiply-adds, [`stress_as`], which a CPU without FMA takes
/// from libm, to the same bits), then the block's forces are summed in order.
pub fn rft3d_sum(law: &Rft3dLanes<f64>, e: &Elements, c: &V3, v: &V3, omega: &V3) -> (V3, V3) {
    #[cfg(target_arch = "x86_64")]
    if crate::num::avx2() && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: this CPU has AVX2 and FMA (checked).
        return unsafe { rft3d_sum_avx2(law, e, c, v, omega) };
    }
    rft3d_sum_blocks(law, e, c, v, omega)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn rft3d_sum_avx2(
    law: &Rft3dLanes<f64>,
    e: &Elements,
    c: &V3,
    v: &V3,
    omega: &V3,
) -> (V3, V3) {
    rft3d_sum_blocks(law, e, c, v, omega)
}

/// Elements per block of the kernel (its force buffer lives on the stack).
const BLOCK: usize = 256;

#[inline(always)]
fn rft3d_sum_blocks(law: &Rft3dLanes<f64>, e: &Elements, c: &V3, v: &V3, omega: &V3) -> (V3, V3) {
    if law.mu_surf == f64::INFINITY {
        rft3d_sum_blocks_with::<false>(law, e, c, v, omega)
    } else {
        rft3d_sum_blocks_with::<true>(law, e, c, v, omega)
    }
}

#[inline(always)]
fn rft3d_sum_blocks_with<const CAP: bool>(
    law: &Rft3dLanes<f64>,
    e: &Elements,
    c: &V3,
    v: &V3,
    omega: &V3,
) -> (V3, V3) {
    let n = e.len();
    // Per block: the force and its moment about c of each element, then their sums (the
    // buffers are written before they are read: not zeroed, 12 kB per call).
    let mut out = [[std::mem::MaybeUninit::<f64>::uninit(); BLOCK]; 6];
    let mut total = [0.0f64; 6];
    let mut start = 0;
    while start < n {
        let len = BLOCK.min(n - start);
        let (xs, ns) = (&e.x, &e.n);
        let (area, depth) = (&e.area[start..start + len], &e.depth[start..start + len]);
        let (x0, x1, x2) = (
            &xs[0][start..start + len],
            &xs[1][start..start + len],
            &xs[2][start..start + len],
        );
        let (n0, n1, n2) = (
            &ns[0][start..start + len],
            &ns[1][start..start + len],
            &ns[2][start..start + len],
        );
        let [f0, f1, f2, m0, m1, m2] = &mut out;
        for j in 0..len {
            let (r, vel) = arm_and_velocity([x0[j], x1[j], x2[j]], c, v, omega);
            let s = stress_as::<f64, CAP, true>(law, [n0[j], n1[j], n2[j]], vel);
            let w = area[j] * depth[j];
            let d = [s[0] * w, s[1] * w, s[2] * w];
            f0[j].write(d[0]);
            f1[j].write(d[1]);
            f2[j].write(d[2]);
            m0[j].write(r[1] * d[2] - r[2] * d[1]);
            m1[j].write(r[2] * d[0] - r[0] * d[2]);
            m2[j].write(r[0] * d[1] - r[1] * d[0]);
        }
        for (t, col) in total.iter_mut().zip(out.iter()) {
            // SAFETY: the loop above wrote col[..len].
            let col = unsafe { std::slice::from_raw_parts(col.as_ptr().cast::<f64>(), len) };
            *t += sum4(col);
        }
        start += len;
    }
    (
        V3::new(total[0], total[1], total[2]),
        V3::new(total[3], total[4], total[5]),
    )
}

/// The sum of `a` in four interleaved partial sums (a fixed order, so the same bits every
/// time; vectorizable, unlike one running sum).
#[inline(always)]
fn sum4(a: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let mut chunks = a.chunks_exact(4);
    for ch in &mut chunks {
        for k in 0..4 {
            acc[k] += ch[k];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for x in chunks.remainder() {
        s += x;
    }
    s
}

/// The arm `x - c` of a point and its velocity `v + omega x (x - c)`, written out once for
/// the lanes and the rest alike (the same operations, so the same bits).
#[inline(always)]
pub fn arm_and_velocity(x: [f64; 3], c: &V3, v: &V3, omega: &V3) -> ([f64; 3], [f64; 3]) {
    let r = [x[0] - c.x, x[1] - c.y, x[2] - c.z];
    let u = [
        v.x + (omega.y * r[2] - omega.z * r[1]),
        v.y + (omega.z * r[0] - omega.x * r[2]),
        v.z + (omega.x * r[1] - omega.y * r[0]),
    ];
    (r, u)
}

/// The load at a pose with the rule's error estimated by doubling its nodes: `(load,
/// |F(2n) - F(n)|, |M(2n) - M(n)|)`.
pub fn load_with_error(
    sand: &mut Sand,
    c: &V3,
    q: &UnitQuaternion<f64>,
    v: &V3,
    omega: &V3,
) -> (Load, f64, f64) {
    let coarse = sand.load(c, q, v, omega);
    let rule = sand.rule.clone();
    sand.rule = Quadrature::new((2 * rule.nodes).min(2 * Quadrature::MAX_NODES));
    let fine = sand.load(c, q, v, omega);
    sand.rule = rule;
    (
        coarse,
        (fine.force - coarse.force).norm(),
        (fine.moment - coarse.moment).norm(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forces::poncelet::Poncelet;
    use crate::forces::rft3d::stress;
    use crate::space::tests::sphere_fz;

    fn sand(shape: Shape, nodes: usize) -> Sand {
        let terms = Terms3 {
            rft3d: Some(Rft3d {
                zeta: 1.0,
                mu_surf: f64::INFINITY,
                grazing: true,
            }),
            ..Terms3::default()
        };
        Sand::new(shape, terms, Medium::default(), 0.0, Quadrature::new(nodes))
    }

    #[test]
    fn a_sphere_straight_down_feels_the_axisymmetric_integral_and_no_sideways_force() {
        for (r, d) in [(0.02, 0.005), (0.02, 0.03), (0.05, 0.2)] {
            let mut s = sand(Shape::sphere("s", r).unwrap(), 6);
            let c = V3::new(0.0, 0.0, r - d);
            let l = s.load(
                &c,
                &UnitQuaternion::identity(),
                &V3::new(0.0, 0.0, -1.5),
                &V3::zeros(),
            );
            let expect = sphere_fz(r, d);
            assert!(
                (l.force.z - expect).abs() < 1e-6 * expect,
                "r {r} d {d}: {} vs {expect}",
                l.force.z
            );
            assert!(l.force.x.abs() < 1e-12 * expect && l.force.y.abs() < 1e-12 * expect);
            assert!(l.moment.norm() < 1e-12 * expect * r);
        }
    }

    /// The closed form on a sphere moving straight up or down without spin against the
    /// general cut at a fine rule and against the integral written from the table: the
    /// same load to the rule's error, every term, in and out of the sand.
    #[test]
    fn the_closed_form_on_a_sphere_straight_down_is_the_cut_integral() {
        let terms = Terms3 {
            rft3d: Some(Rft3d {
                zeta: 1e6,
                mu_surf: f64::INFINITY,
                grazing: true,
            }),
            inertial: Some(Rft3dInertial { lam: 1.0 }),
            poncelet: Some(Poncelet { c: 0.5, k: 30.0 }),
            field: 0.0,
        };
        let r = 0.02;
        let mut s = Sand::new(
            Shape::sphere("s", r).unwrap(),
            terms,
            Medium::default(),
            0.1,
            Quadrature::new(24),
        );
        s.report_areas = true;
        let q = UnitQuaternion::identity();
        let w = V3::zeros();
        let mut closed_forms = 0;
        for (d, vz) in [
            (0.005, -1.5),
            (0.03, -0.7),
            (0.05, -2.0),
            (0.03, 0.8),
            (0.045, 0.3),
            (-0.001, -1.0),
        ] {
            let c = V3::new(0.3, -0.2, 0.1 + r - d);
            let v = V3::new(0.0, 0.0, vz);
            let fast = s.axisymmetric(&c, &q, &v, &w).expect("the closed form");
            let cut = s.load_cut(&c, &q, &v, &w);
            assert_eq!(s.load(&c, &q, &v, &w), fast);
            if d < 0.0 {
                assert_eq!(fast.force, V3::zeros());
                assert_eq!(fast.elements, 0);
                continue;
            }
            closed_forms += 1;
            let scale = cut.force.norm();
            assert!(scale > 0.0);
            for (a, b) in [
                (fast.rft3d, cut.rft3d),
                (fast.inertial, cut.inertial),
                (fast.poncelet, cut.poncelet),
                (fast.force, cut.force),
            ] {
                assert!(
                    (a - b).norm() <= 1e-9 * scale,
                    "d {d} vz {vz}: {a:?} vs {b:?}"
                );
            }
            assert_eq!(fast.moment, V3::zeros());
            assert!(cut.moment.norm() < 1e-12 * scale * r);
            assert!((fast.wetted_area - cut.wetted_area).abs() < 1e-12 * cut.wetted_area);
            assert!((fast.projected_area - cut.projected_area).abs() < 1e-12 * cut.projected_area);
            if vz < 0.0 {
                let only = Terms3 {
                    inertial: None,
                    poncelet: None,
                    ..terms
                };
                let mut t = Sand::new(
                    Shape::sphere("s", r).unwrap(),
                    only,
                    Medium::default(),
                    0.1,
                    Quadrature::new(2),
                );
                let f = t.load(&c, &q, &v, &w).force.z;
                let expect = 1e6 * sphere_fz(r, d);
                assert!((f - expect).abs() < 1e-13 * expect, "{f} vs {expect}");
            }
        }
        assert_eq!(closed_forms, 5);
        // Not for a spin, a sideways velocity or a capped law: the cut.
        let c = V3::new(0.0, 0.0, 0.1);
        let v = V3::new(0.0, 0.0, -1.0);
        assert!(s
            .axisymmetric(&c, &q, &v, &V3::new(0.0, 1e-9, 0.0))
            .is_none());
        assert!(s
            .axisymmetric(&c, &q, &V3::new(1e-9, 0.0, -1.0), &w)
            .is_none());
        s.terms.rft3d = Some(Rft3d {
            zeta: 1e6,
            mu_surf: 0.3,
            grazing: true,
        });
        assert!(s.axisymmetric(&c, &q, &v, &w).is_none());
    }

    #[test]
    fn rotating_everything_about_the_vertical_rotates_the_load() {
        let shapes = [
            Shape::cuboid("b", [0.1, 0.05, 0.03]).unwrap(),
            Shape::capsule("c", 0.02, 0.1).unwrap(),
            Shape::cylinder("y", 0.03, 0.08).unwrap(),
            Shape::sphere("s", 0.04).unwrap(),
        ];
        let q = UnitQuaternion::from_euler_angles(0.3, 0.8, -0.4);
        let (c, v, w) = (
            V3::new(0.01, -0.02, -0.01),
            V3::new(0.4, -0.2, -0.9),
            V3::new(1.0, 2.0, -0.5),
        );
        let turn = UnitQuaternion::from_axis_angle(&V3::z_axis(), 0.77);
        for shape in shapes {
            let mut s = sand(shape, 6);
            let a = s.load(&c, &q, &v, &w);
            let b = s.load(&(turn * c), &(turn * q), &(turn * v), &(turn * w));
            let scale = a.force.norm();
            assert!(scale > 0.0);
            assert!(
                (turn * a.force - b.force).norm() < 1e-12 * scale,
                "{:?} {:?}",
                turn * a.force,
                b.force
            );
            assert!(
                (turn * a.moment - b.moment).norm() < 1e-12 * scale,
                "moment"
            );
        }
    }

    #[test]
    fn the_vectorized_kernel_is_the_element_sum_to_round_off() {
        let mut s = sand(Shape::capsule("c", 0.02, 0.1).unwrap(), 12);
        let q = UnitQuaternion::from_euler_angles(0.3, 0.8, -0.4);
        let (c, v, w) = (
            V3::new(0.0, 0.0, 0.0),
            V3::new(0.4, -0.2, -0.9),
            V3::new(1.0, 2.0, -0.5),
        );
        let e = s.elements_at(&c, &q, &v, &w).clone();
        assert!(e.len() > 2 * BLOCK, "several blocks: {}", e.len());
        let law = s.terms.rft3d.unwrap().lanes();
        let (f, m) = rft3d_sum(&law, &e, &c, &v, &w);
        let (mut f1, mut m1) = (V3::zeros(), V3::zeros());
        // One element at a time, summed in one running sum: equal to round-off (the kernel
        // sums in four interleaved partial sums per block).
        for i in 0..e.len() {
            let (r, vl) = arm_and_velocity([e.x[0][i], e.x[1][i], e.x[2][i]], &c, &v, &w);
            let st = stress(&law, [e.n[0][i], e.n[1][i], e.n[2][i]], vl);
            let wd = e.area[i] * e.depth[i];
            let df = V3::new(st[0] * wd, st[1] * wd, st[2] * wd);
            f1 += df;
            m1 += V3::from(r).cross(&df);
        }
        assert!((f - f1).norm() <= 1e-13 * f1.norm(), "{f:?} {f1:?}");
        assert!((m - m1).norm() <= 1e-13 * m1.norm(), "{m:?} {m1:?}");
        // And the same bits every time.
        assert_eq!(rft3d_sum(&law, &e, &c, &v, &w), (f, m));
    }

    /// The rated kernel is the element loop bit for bit (the wrench, its rates and its
    /// height rates): over several blocks, grazing counted or not, moving, creeping within
    /// the ramp and at rest.
    #[test]
    fn the_rated_kernel_is_the_element_loop_bit_for_bit() {
        let bits = |w: &Wrench| {
            let mut t = w.w.to_vec();
            t.extend(w.kz);
            t.extend(w.k.iter().flatten());
            t.iter().map(|y| y.to_bits()).collect::<Vec<_>>()
        };
        let mut s = sand(Shape::capsule("c", 0.02, 0.1).unwrap(), 12);
        let q = UnitQuaternion::from_euler_angles(0.3, 0.8, -0.4);
        let c = V3::new(0.0, 0.0, 0.01);
        let e = s.elements_at(&c, &q, &V3::zeros(), &V3::zeros()).clone();
        assert!(e.len() > 2 * RATED_BLOCK + 1, "several blocks: {}", e.len());
        let mut checked = 0;
        for grazing in [true, false] {
            let law = Rft3d {
                zeta: 1e6,
                mu_surf: f64::INFINITY,
                grazing,
            };
            for scale in [1.0, 3e-6, 0.0] {
                let xi = [0.3, -0.2, -1.0, 2.0, -1.5, 0.7].map(|x| x * scale);
                let (v, w) = (V3::new(xi[0], xi[1], xi[2]), V3::new(xi[3], xi[4], xi[5]));
                let (mut kernel, mut one) = (Wrench::default(), Wrench::default());
                rft3d_rated(&law, &e, &c, &v, &w, 1e-5, &mut kernel);
                rft3d_elements(&law, &e, &c, &v, &w, 1e-5, true, &mut one);
                assert_eq!(bits(&kernel), bits(&one), "grazing {grazing} scale {scale}");
                if scale > 0.0 {
                    assert!(one.w[2] != 0.0 && one.k[2][2] != 0.0 && one.k[5][3] != 0.0);
                }
                checked += 1;
            }
        }
        assert_eq!(checked, 6);
    }

    /// The wrench without its rates is the wrench's value and height rates bit for bit:
    /// every term, with and without the friction cap, grazing counted or not, moving,
    /// creeping within the ramp, at rest and with the law's step (eps 0).
    #[test]
    fn the_wrench_value_is_the_wrench_bit_for_bit() {
        let bits = |x: &[f64]| x.iter().map(|y| y.to_bits()).collect::<Vec<_>>();
        let mut checked = 0;
        for (mu, grazing) in [(f64::INFINITY, true), (0.3, true), (f64::INFINITY, false)] {
            let terms = Terms3 {
                rft3d: Some(Rft3d {
                    zeta: 1e6,
                    mu_surf: mu,
                    grazing,
                }),
                inertial: Some(Rft3dInertial { lam: 1.0 }),
                poncelet: Some(Poncelet { c: 0.5, k: 300.0 }),
                field: 0.0,
            };
            for shape in [
                Shape::capsule("c", 0.01, 0.06).unwrap(),
                Shape::cuboid("b", [0.05, 0.03, 0.02]).unwrap(),
            ] {
                let mut s = Sand::new(shape, terms, Medium::default(), 0.0, Quadrature::new(4));
                let q = UnitQuaternion::from_euler_angles(0.3, 0.5, 0.1);
                let c = V3::new(0.0, 0.0, -0.005);
                assert!(s.cut_at_rest(&c, &q) > 0);
                for (scale, eps) in [(1.0, 1e-5), (3e-6, 1e-5), (0.0, 1e-5), (0.3, 0.0)] {
                    let xi = [0.3, -0.2, -1.0, 2.0, -1.5, 0.7].map(|x| x * scale);
                    let (v, w) = (V3::new(xi[0], xi[1], xi[2]), V3::new(xi[3], xi[4], xi[5]));
                    let full = s.wrench(&c, &q, &v, &w, eps);
                    let value = s.wrench_value(&c, &q, &v, &w, eps);
                    assert_eq!(bits(&value.w), bits(&full.w), "mu {mu} scale {scale}");
                    assert_eq!(bits(&value.kz), bits(&full.kz), "mu {mu} scale {scale}");
                    assert_eq!(value.k, [[0.0; 6]; 6]);
                    if scale > 0.0 {
                        assert!(full.w[2] != 0.0 && full.k[2][2] != 0.0);
                    }
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 24);
    }

    /// The wrench's rates against central differences in the twist and the height, on a
    /// tilted capsule half sunk under all three terms, moving and near rest.
    #[test]
    fn the_wrench_rates_are_its_derivatives() {
        let terms = Terms3 {
            rft3d: Some(Rft3d {
                zeta: 1e6,
                mu_surf: 0.3,
                grazing: true,
            }),
            inertial: Some(Rft3dInertial { lam: 1.0 }),
            poncelet: None,
            field: 0.0,
        };
        let shape = Shape::capsule("c", 0.01, 0.06).unwrap();
        let mut s = Sand::new(shape, terms, Medium::default(), 0.0, Quadrature::new(4));
        let q = UnitQuaternion::from_euler_angles(0.3, 0.5, 0.1);
        let c = V3::new(0.0, 0.0, -0.005);
        assert!(s.cut_at_rest(&c, &q) > 0);
        for (scale, eps) in [(1.0, 1e-5), (1e-6, 1e-5), (0.3, 0.0)] {
            let xi = [0.3, -0.2, -1.0, 2.0, -1.5, 0.7].map(|x| x * scale);
            let at = |x: &[f64; 6], dz: f64| {
                let cz = c + V3::new(0.0, 0.0, dz);
                let mut t = s.clone();
                t.cut_at_rest(&cz, &q);
                t.wrench(
                    &cz,
                    &q,
                    &V3::new(x[0], x[1], x[2]),
                    &V3::new(x[3], x[4], x[5]),
                    eps,
                )
            };
            let w = at(&xi, 0.0);
            let size = w.w.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(size > 0.0);
            for col in 0..6 {
                let hstep = 1e-6 * scale;
                let (mut up, mut dn) = (xi, xi);
                up[col] += hstep;
                dn[col] -= hstep;
                let (a, b) = (at(&up, 0.0), at(&dn, 0.0));
                for row in 0..6 {
                    let fd = (a.w[row] - b.w[row]) / (2.0 * hstep);
                    let k = w.k[row][col];
                    assert!(
                        (fd - k).abs() <= 1e-4 * (k.abs() + size / scale),
                        "scale {scale} eps {eps}: K[{row}][{col}] {k} vs {fd}"
                    );
                }
            }
            // The height: a rigid shift of the elements (the cut's own change, where new
            // area enters at zero depth, is second order).
            let dz = 1e-7;
            let (a, b) = (at(&xi, dz), at(&xi, -dz));
            for row in 0..3 {
                let fd = (a.w[row] - b.w[row]) / (2.0 * dz);
                assert!(
                    (fd - w.kz[row]).abs() <= 2e-2 * (w.kz[row].abs() + size / 0.005),
                    "scale {scale}: kz[{row}] {} vs {fd}",
                    w.kz[row]
                );
            }
        }
    }
}
