//! A planar tree of rigid links with a floating root, in absolute link angles.
//!
//! Link `i` has the angle `q_i` from the vertical and the unit axis `e_i = (sin q_i, cos q_i)`
//! (MODEL.md); its normal is `n_i = (cos q_i, -sin q_i) = d e_i / d q_i`. A point fixed on
//! link `i` has local coordinates `(s, n)`: position `J_i + s e_i + n n_i`, where `J_i` is the
//! link's joint: the root for a link with no parent, else a point fixed on its parent.
//!
//! With absolute angles the Jacobian of a point is `[I_2 | ... d(R(q_a) r_a)/dq_a ...]` over the
//! chain of ancestors `a`, and its velocity-product acceleration is `-sum_a qdot_a^2 R(q_a) r_a`.
//! The mass matrix is `sum_i m_i J_ci^T J_ci + I_i u_i u_i^T` (u_i picks link i's angle),
//! plus a point mass at the root (the chain's pin).
//!
//! A joint between a link and its parent is free, locked, or a rotational spring-damper on
//! the relative angle `q_i - q_parent`. A locked joint is the linear constraint
//! `qdot_i - qdot_parent = 0` ([`Mechanism::locked_rows`]), enforced with the contacts'
//! sticking constraints by `dynamics`; since it is linear in `q`, RK4 keeps it exactly (to
//! round-off). A joint driven at a constant rate is the same row with the rate as its target
//! (`qdot_i - qdot_parent = rate`, zero relative acceleration), and a root whose motion is
//! prescribed (pinned, or moved at a constant velocity) holds `xddot = yddot = 0`.

use nalgebra::{SMatrix, SVector, Vector2};

/// The joint between a link and its parent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Joint {
    /// A frictionless revolute joint.
    Free,
    /// No relative rotation: the link moves rigidly with its parent.
    Locked,
    /// A rotational spring-damper: torque `-k (theta - rest) - c thetadot` on the relative
    /// angle `theta = q_i - q_parent`.
    Spring {
        /// Stiffness [N m/rad].
        k: f64,
        /// Damping [N m s/rad].
        c: f64,
        /// Relative angle at which the spring is relaxed [rad].
        rest: f64,
    },
    /// Driven: the relative angle `q_i - q_parent` follows
    /// `theta_0 + rate t + amplitude (sin(omega t + phase) - sin phase)` (its initial value
    /// plus a constant rate and a sinusoid), held by an unbounded torque that the run reports.
    /// A sinusoid reads the time from the mechanism's clock (see [`Mechanism::clock`]).
    Driven {
        /// Constant relative rate [rad/s].
        rate: f64,
        /// Amplitude of the sinusoid [rad] (0: none).
        amplitude: f64,
        /// Its angular frequency [rad/s].
        omega: f64,
        /// Its phase at t = 0 [rad].
        phase: f64,
    },
    /// Driven along a piecewise-linear table of the relative angle ([`super::DriveTable`]):
    /// between the table's times a constant-rate drive whose rate is the one the rates have
    /// (the run lands on each time and takes the impulse that sets the new segment's slope).
    Table,
}

impl Joint {
    /// A joint driven at a constant rate [rad/s].
    pub fn driven(rate: f64) -> Joint {
        Joint::Driven {
            rate,
            amplitude: 0.0,
            omega: 0.0,
            phase: 0.0,
        }
    }

    /// Whether the joint's motion depends on the time beyond a constant rate.
    #[inline]
    pub fn reads_clock(&self) -> bool {
        matches!(self, Joint::Driven { amplitude, .. } if *amplitude != 0.0)
    }
}

/// One constraint row of the mechanism itself: `qdot_link - qdot_parent - clock_coef *
/// qdot_clock = target`, whose velocity-product acceleration is `bias`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeldRow {
    /// The child link.
    pub link: usize,
    /// Its parent.
    pub parent: usize,
    /// The clock's coefficient, `-theta'(t)` of a sinusoid (0 otherwise).
    pub clock_coef: f64,
    /// `d(jac)/dt . qdot` [rad/s^2].
    pub bias: f64,
    /// The constrained rate [rad/s].
    pub target: f64,
}

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
    /// The joint to the parent (ignored without parent: a root link's angle is free).
    pub joint: Joint,
}

/// A planar tree of `N - 2` links with a floating root: `N` generalized coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Mechanism<const N: usize> {
    /// The links; a parent always comes before its children.
    pub links: Vec<Link>,
    /// A point mass at the root [kg] (the chain's pin; 0 for none).
    pub root_mass: f64,
    /// Whether the root's motion is prescribed (pinned, or moved at its initial velocity):
    /// its coordinates then have zero acceleration, held by a reaction.
    pub root_fixed: bool,
    /// The root link's angle driven at this constant rate [rad/s] (held by a torque that the
    /// run reports as the root link's joint torque), or `None`: free.
    pub root_rate: Option<f64>,
}

/// Positions and axes of every link for one configuration.
#[derive(Debug, Clone, Copy)]
pub struct Pose<const N: usize> {
    /// The root point [m].
    pub root: Vector2<f64>,
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
        self.root_mass + self.links.iter().map(|l| l.mass).sum::<f64>()
    }

    /// The (link, parent) pairs of the locked and driven joints.
    pub fn locked_rows(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.links
            .iter()
            .enumerate()
            .filter_map(|(i, l)| match (l.parent, l.joint) {
                (Some(p), Joint::Locked | Joint::Driven { .. } | Joint::Table) => Some((i, p)),
                _ => None,
            })
    }

    /// The root links (no parent) whose angle is driven at a constant rate, with the rate.
    pub fn driven_roots(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.links
            .iter()
            .enumerate()
            .filter(|(_, l)| l.parent.is_none())
            .filter_map(|(i, _)| self.root_rate.map(|r| (i, r)))
    }

    /// Whether every coordinate's motion is prescribed (a pinned or moving root, a driven
    /// root angle, and every other joint locked or driven): nothing the sand does moves it.
    pub fn prescribed(&self) -> bool {
        self.root_fixed
            && self.root_rate.is_some()
            && self.links.iter().all(|l| {
                l.parent.is_none()
                    || matches!(l.joint, Joint::Locked | Joint::Driven { .. } | Joint::Table)
            })
    }

    /// The clock's coordinate, if the mechanism has one: `N - 1` when `N` exceeds the
    /// links' coordinates by one. It is the time (`q = t`, `qdot = 1`, held by a row of its
    /// own), read by the sinusoidally driven joints; it has unit mass and no other part in
    /// the dynamics or the energies.
    #[inline]
    pub fn clock(&self) -> Option<usize> {
        (self.links.len() + 3 == N).then_some(N - 1)
    }

    /// The rows of the locked and driven joints at `(q, qd)`: a locked joint holds
    /// `qdot_i - qdot_parent = 0`; a driven one `qdot_i - qdot_parent - theta'(t) = 0`, with
    /// `theta'(t) = rate + amplitude omega cos(omega t + phase)` and `t` the clock's
    /// coordinate.
    pub fn held_rows<'a>(
        &'a self,
        q: &'a SVector<f64, N>,
        qd: &'a SVector<f64, N>,
    ) -> impl Iterator<Item = HeldRow> + 'a {
        let clock = self.clock();
        self.links.iter().enumerate().filter_map(move |(i, l)| {
            let p = l.parent?;
            let row = |clock_coef, bias, target| HeldRow {
                link: i,
                parent: p,
                clock_coef,
                bias,
                target,
            };
            match l.joint {
                Joint::Locked => Some(row(0.0, 0.0, 0.0)),
                Joint::Driven {
                    rate,
                    amplitude,
                    omega,
                    phase,
                } => match clock {
                    Some(c) if amplitude != 0.0 => {
                        let (s, co) = (omega * q[c] + phase).sin_cos();
                        let speed = amplitude * omega * co;
                        let accel = -amplitude * omega * omega * s;
                        // jac = e_i - e_p - theta' e_c; d(jac)/dt . qd = -theta'' qd_c^2.
                        Some(row(-(rate + speed), -accel * qd[c] * qd[c], 0.0))
                    }
                    _ => Some(row(0.0, 0.0, rate)),
                },
                // The segment's slope is the rate the joint has (set at each of the table's
                // times by an impulse): the row holds it.
                Joint::Table => Some(row(0.0, 0.0, qd[2 + i] - qd[2 + p])),
                _ => None,
            }
        })
    }

    /// Whether any constraint of the mechanism itself is in force: a locked or driven joint,
    /// a prescribed root, or a clock.
    #[inline]
    pub fn has_constraints(&self) -> bool {
        self.root_fixed
            || self.root_rate.is_some()
            || self.clock().is_some()
            || self.locked_rows().next().is_some()
    }

    /// Force the parent (or the root) exerts on each link at its joint [N], from Newton's
    /// law on the subtree the joint carries: `sum_subtree m (a_c - g) - F_external`.
    /// `external[i]` is the external force (the sand's) on link `i`.
    pub fn joint_forces(
        &self,
        pose: &Pose<N>,
        qd: &SVector<f64, N>,
        qdd: &SVector<f64, N>,
        g: f64,
        external: &[Vector2<f64>; N],
    ) -> [Vector2<f64>; N] {
        let mut f = [Vector2::zeros(); N];
        for (i, link) in self.links.iter().enumerate() {
            let a = self.jacobian(pose, i, link.com) * qdd
                + self.point_bias_acceleration(pose, i, link.com, qd);
            f[i] = link.mass * (a - Vector2::new(0.0, -g)) - external[i];
        }
        for i in (0..self.links.len()).rev() {
            if let Some(p) = self.links[i].parent {
                let fi = f[i];
                f[p] += fi;
            }
        }
        f
    }

    /// Positions and axes of every link at configuration `q`.
    #[inline]
    pub fn pose(&self, q: &SVector<f64, N>) -> Pose<N> {
        let root = Vector2::new(q[0], q[1]);
        let mut pose = Pose {
            root,
            joint: [Vector2::zeros(); N],
            axis: [Vector2::zeros(); N],
            normal: [Vector2::zeros(); N],
        };
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
        m[(0, 0)] += self.root_mass;
        m[(1, 1)] += self.root_mass;
        if let Some(c) = self.clock() {
            m[(c, c)] = 1.0;
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
        out[1] -= self.root_mass * g;
        out
    }

    /// Kinetic energy 1/2 qdot^T M qdot [J].
    pub fn kinetic_energy(&self, pose: &Pose<N>, qd: &SVector<f64, N>) -> f64 {
        let mut ke = 0.5 * self.root_mass * (qd[0] * qd[0] + qd[1] * qd[1]);
        for (i, link) in self.links.iter().enumerate() {
            let v = self.point_velocity(pose, i, link.com, qd);
            ke += 0.5 * link.mass * v.norm_squared() + 0.5 * link.inertia * qd[2 + i] * qd[2 + i];
        }
        ke
    }

    /// Kinetic and gravitational potential energy of link `i` alone [J] (thesis eqs.
    /// 4.9-4.10: 1/2 m v_c^2 + 1/2 I omega^2 and m g y_c).
    pub fn link_energy(
        &self,
        pose: &Pose<N>,
        qd: &SVector<f64, N>,
        g: f64,
        i: usize,
    ) -> (f64, f64) {
        let l = &self.links[i];
        let v = self.point_velocity(pose, i, l.com, qd);
        (
            0.5 * l.mass * v.norm_squared() + 0.5 * l.inertia * qd[2 + i] * qd[2 + i],
            l.mass * g * self.point(pose, i, l.com).y,
        )
    }

    /// Gravitational potential energy sum m_i g y_ci [J] (zero at the sand surface).
    pub fn potential_energy(&self, pose: &Pose<N>, g: f64) -> f64 {
        self.root_mass * g * pose.root.y
            + self
                .links
                .iter()
                .enumerate()
                .map(|(i, l)| l.mass * g * self.point(pose, i, l.com).y)
                .sum::<f64>()
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
            joint: Joint::Free,
        };
        Mechanism {
            links: vec![link.clone(), link],
            root_mass: 0.01,
            root_fixed: false,
            root_rate: None,
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
