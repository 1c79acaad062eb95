//! A planar tree of rigid links with a floating root, in absolute link angles.
//!
//! Link `i` has the angle `q_i` from the vertical and the unit axis `e_i = (sin q_i, cos q_i)`
//! (MODEL.md); its normal is `n_i = (cos q_i, -sin q_i) = d e_i / d q_i`. A point fixed on
//! link `i` has local coordinates `(s, n)`: position `J_i + s e_i + n n_i`, where `J_i` is the
//! link's joint: the root for a link with no parent, else a point fixed on its parent.
//!
//! With absolute angles the Jacobian of a point is `[I_2 | ... d(R(q_a) r_a)/dq_a ...]` over the
//! chain of ancestors `a`, and its velocity-product acceleration is `-sum_a qdot_a^2 R(q_a) r_a`.
//! The mass matrix is `sum_i m_i J_ci^T J_ci + I_i u_i u_i^T` (u_i picks link i's angle).

use nalgebra::{SMatrix, SVector, Vector2};

/// One rigid link.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// Mass [kg].
    pub mass: f64,
    /// Moment of inertia about the centre of mass, out of the plane [kg m^2].
    pub inertia: f64,
    /// Centre of mass in the link's local (s, n) coordinates, from its joint [m].
    pub com: Vector2<f64>,
    /// Parent link, or `None` for a link hinged at (or, for a single link, fixed to) the root.
    pub parent: Option<usize>,
    /// This link's joint in the parent's local (s, n) coordinates [m] (ignored without parent).
    pub joint_on_parent: Vector2<f64>,
}

/// A planar tree of `N - 2` links with a floating root: `N` generalized coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Mechanism<const N: usize> {
    /// The links; a parent always comes before its children.
    pub links: Vec<Link>,
}

/// Positions and axes of every link for one configuration.
#[derive(Debug, Clone, Copy)]
pub struct Pose<const N: usize> {
    /// Joint position of each link [m].
    pub joint: [Vector2<f64>; N],
    /// Axis e_i of each link.
    pub axis: [Vector2<f64>; N],
    /// Normal n_i of each link.
    pub normal: [Vector2<f64>; N],
}

/// `R(q) r` for local coordinates `r = (s, n)`.
#[inline]
fn rotate(axis: Vector2<f64>, normal: Vector2<f64>, r: Vector2<f64>) -> Vector2<f64> {
    r.x * axis + r.y * normal
}

/// `d(R(q) r)/dq` for local coordinates `r = (s, n)`: `s n - n e`.
#[inline]
fn rotate_dq(axis: Vector2<f64>, normal: Vector2<f64>, r: Vector2<f64>) -> Vector2<f64> {
    r.x * normal - r.y * axis
}

impl<const N: usize> Mechanism<N> {
    /// Number of links.
    #[inline]
    pub fn n_links(&self) -> usize {
        self.links.len()
    }

    /// Total mass [kg].
    pub fn total_mass(&self) -> f64 {
        self.links.iter().map(|l| l.mass).sum()
    }

    /// Positions and axes of every link at configuration `q`.
    #[inline]
    pub fn pose(&self, q: &SVector<f64, N>) -> Pose<N> {
        let mut pose = Pose {
            joint: [Vector2::zeros(); N],
            axis: [Vector2::zeros(); N],
            normal: [Vector2::zeros(); N],
        };
        let root = Vector2::new(q[0], q[1]);
        for (i, link) in self.links.iter().enumerate() {
            let (s, c) = q[2 + i].sin_cos();
            pose.axis[i] = Vector2::new(s, c);
            pose.normal[i] = Vector2::new(c, -s);
            pose.joint[i] = match link.parent {
                None => root,
                Some(p) => {
                    pose.joint[p] + rotate(pose.axis[p], pose.normal[p], link.joint_on_parent)
                }
            };
        }
        pose
    }

    /// Position of the point with local coordinates `r` on link `i` [m].
    #[inline]
    pub fn point(&self, pose: &Pose<N>, i: usize, r: Vector2<f64>) -> Vector2<f64> {
        pose.joint[i] + rotate(pose.axis[i], pose.normal[i], r)
    }

    /// Visit the chain of (link, local lever) pairs from link `i`'s point `r` back to the root:
    /// `(i, r)`, `(parent, joint_on_parent of i)`, ...
    #[inline]
    fn for_each_lever(&self, i: usize, r: Vector2<f64>, mut f: impl FnMut(usize, Vector2<f64>)) {
        let mut link = i;
        let mut lever = r;
        loop {
            f(link, lever);
            match self.links[link].parent {
                None => break,
                Some(p) => {
                    lever = self.links[link].joint_on_parent;
                    link = p;
                }
            }
        }
    }

    /// Jacobian of the point `r` on link `i`: `v_P = J qdot` (2 x N).
    #[inline]
    pub fn jacobian(&self, pose: &Pose<N>, i: usize, r: Vector2<f64>) -> SMatrix<f64, 2, N> {
        let mut j = SMatrix::<f64, 2, N>::zeros();
        j[(0, 0)] = 1.0;
        j[(1, 1)] = 1.0;
        self.for_each_lever(i, r, |a, lever| {
            let col = rotate_dq(pose.axis[a], pose.normal[a], lever);
            j[(0, 2 + a)] = col.x;
            j[(1, 2 + a)] = col.y;
        });
        j
    }

    /// Velocity of the point `r` on link `i` [m/s].
    #[inline]
    pub fn point_velocity(
        &self,
        pose: &Pose<N>,
        i: usize,
        r: Vector2<f64>,
        qd: &SVector<f64, N>,
    ) -> Vector2<f64> {
        let mut v = Vector2::new(qd[0], qd[1]);
        self.for_each_lever(i, r, |a, lever| {
            v += qd[2 + a] * rotate_dq(pose.axis[a], pose.normal[a], lever);
        });
        v
    }

    /// Velocity-product part of the acceleration of the point `r` on link `i` [m/s^2]:
    /// the acceleration it has when `qddot = 0`.
    #[inline]
    pub fn point_bias_acceleration(
        &self,
        pose: &Pose<N>,
        i: usize,
        r: Vector2<f64>,
        qd: &SVector<f64, N>,
    ) -> Vector2<f64> {
        let mut a = Vector2::zeros();
        self.for_each_lever(i, r, |l, lever| {
            a -= qd[2 + l] * qd[2 + l] * rotate(pose.axis[l], pose.normal[l], lever);
        });
        a
    }

    /// Add `J_P^T f` (the generalized force of the force `f` at point `r` of link `i`) to `out`.
    #[inline]
    pub fn add_point_force(
        &self,
        pose: &Pose<N>,
        i: usize,
        r: Vector2<f64>,
        f: Vector2<f64>,
        out: &mut SVector<f64, N>,
    ) {
        out[0] += f.x;
        out[1] += f.y;
        self.for_each_lever(i, r, |a, lever| {
            out[2 + a] += f.dot(&rotate_dq(pose.axis[a], pose.normal[a], lever));
        });
    }

    /// Mass matrix M(q) (N x N, symmetric positive definite for positive masses).
    pub fn mass_matrix(&self, pose: &Pose<N>) -> SMatrix<f64, N, N> {
        let mut m = SMatrix::<f64, N, N>::zeros();
        for (i, link) in self.links.iter().enumerate() {
            let j = self.jacobian(pose, i, link.com);
            m += link.mass * j.transpose() * j;
            m[(2 + i, 2 + i)] += link.inertia;
        }
        m
    }

    /// Generalized forces of gravity and of the velocity products, `Q_g - C(q, qdot) qdot`:
    /// the right-hand side of `M qddot = bias + Q_contact`.
    pub fn bias_forces(&self, pose: &Pose<N>, qd: &SVector<f64, N>, g: f64) -> SVector<f64, N> {
        let mut out = SVector::<f64, N>::zeros();
        for (i, link) in self.links.iter().enumerate() {
            let a = self.point_bias_acceleration(pose, i, link.com, qd);
            let f = link.mass * (Vector2::new(0.0, -g) - a);
            self.add_point_force(pose, i, link.com, f, &mut out);
        }
        out
    }

    /// Kinetic energy 1/2 qdot^T M qdot [J].
    pub fn kinetic_energy(&self, pose: &Pose<N>, qd: &SVector<f64, N>) -> f64 {
        let mut ke = 0.0;
        for (i, link) in self.links.iter().enumerate() {
            let v = self.point_velocity(pose, i, link.com, qd);
            ke += 0.5 * link.mass * v.norm_squared() + 0.5 * link.inertia * qd[2 + i] * qd[2 + i];
        }
        ke
    }

    /// Gravitational potential energy sum m_i g y_ci [J] (zero at the sand surface).
    pub fn potential_energy(&self, pose: &Pose<N>, g: f64) -> f64 {
        self.links
            .iter()
            .enumerate()
            .map(|(i, l)| l.mass * g * self.point(pose, i, l.com).y)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two links hanging from the root, as the chain of chapter 4.
    fn two_link() -> Mechanism<4> {
        let link = Link {
            mass: 0.034,
            inertia: 0.034 * 0.135 * 0.135 / 12.0,
            com: Vector2::new(-0.0675, 0.0),
            parent: None,
            joint_on_parent: Vector2::zeros(),
        };
        Mechanism {
            links: vec![link.clone(), link],
        }
    }

    #[test]
    fn jacobian_matches_finite_difference() {
        let m = two_link();
        let q = SVector::<f64, 4>::new(0.1, 0.2, 0.3, -0.4);
        let qd = SVector::<f64, 4>::new(0.5, -1.0, 2.0, -3.0);
        let r = Vector2::new(-0.1, 0.01);
        let pose = m.pose(&q);
        let v = m.point_velocity(&pose, 1, r, &qd);
        let h = 1e-7;
        let p1 = m.point(&m.pose(&(q + h * qd)), 1, r);
        let p0 = m.point(&m.pose(&(q - h * qd)), 1, r);
        let fd = (p1 - p0) / (2.0 * h);
        assert!((v - fd).norm() < 1e-7, "{v} vs {fd}");
        assert!((m.jacobian(&pose, 1, r) * qd - v).norm() < 1e-14);
    }

    #[test]
    fn mass_matrix_gives_kinetic_energy() {
        let m = two_link();
        let q = SVector::<f64, 4>::new(0.0, 0.0, 0.3, -0.2);
        let qd = SVector::<f64, 4>::new(0.4, -2.0, 1.0, 3.0);
        let pose = m.pose(&q);
        let ke = 0.5 * (qd.transpose() * m.mass_matrix(&pose) * qd)[0];
        assert!((ke - m.kinetic_energy(&pose, &qd)).abs() < 1e-14);
    }
}
