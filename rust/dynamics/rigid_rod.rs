//! The free link: a single rigid rod whose root is its centre of mass has a constant,
//! diagonal mass matrix `M = diag(m + m_root, m + m_root, I)` and no velocity products, so
//! its accelerations, sticking reactions and projection are in closed form (one `sin_cos`
//! per evaluation). Here: which bodies are one ([`Model::rigid_rod`]), their evaluation
//! through the one kernel of [`super::rod_lanes`] ([`Model::eval_free_link`]) and their
//! projection onto the sticking rows. The tests hold both to the general engine (the pose,
//! the mass matrix and the constraint rows of any body) to round-off.

use nalgebra::{SVector, Vector2};

use super::constraints::solve_upto2;
use super::rod_lanes::{rod_eval_terms, RodBody, RodEval, RodModes, RodTerms};
use super::{ContactMode, Model, Modes, Shape, Slip, PROJECTION_LIMIT};
use crate::body::{RodContact, RodGeometry};
use crate::forces::Switch;

/// The pose of a single rigid rod whose root is its centre of mass: what its projection
/// needs (one `sin_cos`, libm's).
#[derive(Debug, Clone, Copy)]
struct RodFrame {
    root: Vector2<f64>,
    axis: Vector2<f64>,
    normal: Vector2<f64>,
}

impl RodFrame {
    #[inline]
    fn new<const N: usize>(q: &SVector<f64, N>) -> Self {
        let (s, c) = q[2].sin_cos();
        RodFrame {
            root: Vector2::new(q[0], q[1]),
            axis: Vector2::new(s, c),
            normal: Vector2::new(c, -s),
        }
    }

    /// Position of the point with local coordinates `r`: `root + R r`.
    #[inline]
    fn at(&self, r: Vector2<f64>) -> Vector2<f64> {
        self.root + (r.x * self.axis + r.y * self.normal)
    }

    /// `d(R r)/dq`: the lever of `r` (velocity per unit rate, generalized force per unit force).
    #[inline]
    fn lever(&self, r: Vector2<f64>) -> Vector2<f64> {
        r.x * self.normal - r.y * self.axis
    }
}

/// The sticking rows of a single rigid rod about its centre of mass (at most two: the
/// velocity of the immersed centroid E along x and along y held at zero). Row `i` holds
/// axis `u = unit(axes[i])`: its Jacobian is `(u_x, u_y, u . lever_E)` and a unit reaction
/// along `u` at the point of application P gives the generalized force
/// `(u_x, u_y, u . lever_P)`; with `M = diag(m, m, I)` everything is in closed form.
#[derive(Debug, Clone, Copy)]
struct RodStick {
    len: usize,
    axes: [usize; 2],
    /// `u . lever_E` per row.
    lever_e: [f64; 2],
    /// `u . lever_P` per row.
    lever_p: [f64; 2],
}

impl RodStick {
    /// The constrained velocity of row `i`, `jac . v`.
    #[inline]
    fn velocity<const N: usize>(&self, i: usize, v: &SVector<f64, N>) -> f64 {
        v[self.axes[i]] + self.lever_e[i] * v[2]
    }
}

impl<const N: usize> Model<N> {
    /// The rod contact of a single free link with its centre of mass at the root (no
    /// parent, one rod contact on it), or `None` for any other body.
    #[inline]
    pub(super) fn rigid_rod(&self) -> Option<&RodContact> {
        if N != 3
            || self.mechanism.links.len() != 1
            || self.contacts.len() != 1
            || self.mechanism.root_fixed
            || self.mechanism.root_rate.is_some()
        {
            return None;
        }
        let link = &self.mechanism.links[0];
        if link.parent.is_some() || link.com != Vector2::zeros() {
            return None;
        }
        match &self.contacts[0].shape {
            Shape::Rod(rod) if rod.link == 0 => Some(rod),
            _ => None,
        }
    }

    /// The free link's evaluation at `(q, qd)` in `modes`: the kernel
    /// ([`rod_eval_terms`]) at `f64`, reading the model where it stands (its body's numbers
    /// in a few loads and two divisions, its terms in place: nothing copied or kept).
    #[inline(always)]
    pub(super) fn eval_free_link(
        &self,
        rod: &RodContact,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
    ) -> RodEval<f64> {
        let body = RodBody::of(self, rod);
        let mut numbers = [0.0; 4];
        let law = RodTerms::of_forces(&self.forces, &mut numbers);
        let m = RodModes::held(&modes[0], body.unheld, law.owns);
        rod_eval_terms(&body, &law, &m, &[q[0], q[1], q[2]], &[qd[0], qd[1], qd[2]])
    }

    /// `1 / (m + m_root)` and `1 / I`: M^-1 of a single rigid rod about its centre of mass,
    /// `M = diag(m + m_root, m + m_root, I)`.
    #[inline]
    fn rigid_rod_inverse_mass_parts(&self) -> (f64, f64) {
        let link = &self.mechanism.links[0];
        (
            1.0 / (link.mass + self.mechanism.root_mass),
            1.0 / link.inertia,
        )
    }

    /// The sticking rows of a single rigid rod about its centre of mass in `mode`, its tip
    /// `geom.depth > 0` deep ([`Model::constraint_rows`] for that body).
    #[inline]
    fn rigid_rod_stick(
        &self,
        rod: &RodContact,
        fr: &RodFrame,
        geom: &RodGeometry,
        mode: &ContactMode,
    ) -> RodStick {
        let centroid = Vector2::new(geom.centroid_s, rod.tip.y);
        let lever_e = fr.lever(centroid);
        let lever_p = fr.lever(self.application_point(&self.contacts[0], centroid));
        let mut stick = RodStick {
            len: 0,
            axes: [0; 2],
            lever_e: [0.0; 2],
            lever_p: [0.0; 2],
        };
        let stuck_x = self.forces.owns(Switch::SlipX) && mode.sx == Slip::Stick;
        let stuck_y = self.forces.owns(Switch::SlipY) && mode.sy == Slip::Stick;
        for (k, on) in [(0usize, stuck_x), (1usize, stuck_y)] {
            if on {
                let i = stick.len;
                stick.axes[i] = k;
                stick.lever_e[i] = lever_e[k];
                stick.lever_p[i] = lever_p[k];
                stick.len += 1;
            }
        }
        stick
    }

    /// [`Model::project_sticking`] of a single rigid rod ([`project_rows`] in closed form).
    pub(super) fn project_rigid_rod(
        &self,
        rod: &RodContact,
        q: &SVector<f64, N>,
        qd: &mut SVector<f64, N>,
        mode: &ContactMode,
    ) -> bool {
        let fr = RodFrame::new(q);
        let geom = rod.geometry(fr.at(rod.tip).y, fr.axis);
        if !mode.in_contact || geom.depth <= 0.0 {
            return false;
        }
        let stick = self.rigid_rod_stick(rod, &fr, &geom, mode);
        let k = stick.len;
        if k == 0 || (0..k).any(|i| stick.velocity(i, qd).abs() > PROJECTION_LIMIT) {
            return false;
        }
        // J M^-1 J^T, with M^-1 J^T's columns (u_x / m, u_y / m, u . lever_E / I).
        let (inv_m, inv_i) = self.rigid_rod_inverse_mass_parts();
        let mut a = [[0.0; 2]; 2];
        let mut b = [0.0; 2];
        for i in 0..k {
            b[i] = stick.velocity(i, qd);
            for (j, aij) in a[i].iter_mut().enumerate().take(k) {
                let linear = if stick.axes[i] == stick.axes[j] {
                    inv_m
                } else {
                    0.0
                };
                *aij = linear + stick.lever_e[i] * (stick.lever_e[j] * inv_i);
            }
        }
        match solve_upto2(k, a, b) {
            Some(lam) if lam[..k].iter().any(|&l| l != 0.0) => {
                for (i, &l) in lam.iter().enumerate().take(k) {
                    qd[stick.axes[i]] -= l * inv_m;
                    qd[2] -= l * (stick.lever_e[i] * inv_i);
                }
                true
            }
            _ => false,
        }
    }
}
