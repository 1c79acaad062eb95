//! The constraints in force: locked joints (`qdot_i - qdot_parent = 0`, an unbounded
//! torque) and sticking components (a static term's reaction holding a velocity component
//! of E at zero, Karnopp), as rows `jac . qdot = 0` solved together for their multipliers
//! without allocating ([`solve_small`]); the projection of the rates onto them (drift only);
//! and the inverse effective mass of a contact's centroid with the locked joints held.

use nalgebra::{Matrix2, SMatrix, SVector, Vector2};

use super::{
    ContactEval, ContactMode, Eval, Model, Modes, SignModel, Slip, MAX_CONTACTS, MAX_LOCKED,
    PROJECTION_LIMIT,
};
use crate::body::mechanism::Pose;
use crate::forces::{ForceSet, Switch};

/// Most constraint rows at once: two sticking components per contact, the locked (and
/// driven) joints, a prescribed root's two, a driven root angle's and the clock's.
const MAX_ROWS: usize = 2 * MAX_CONTACTS + MAX_LOCKED + 4;

/// Unit vector of axis `k` (0 = x, 1 = y).
#[inline]
fn unit(k: usize) -> Vector2<f64> {
    if k == 0 {
        Vector2::new(1.0, 0.0)
    } else {
        Vector2::new(0.0, 1.0)
    }
}

/// What a constraint row holds. (Bytes, not words: a [`Row`] of the leg, `N = 6`, stays
/// within 128 bytes, which a move copies inline; past that each push called `memmove`,
/// measured at about 5 % of the leg's run.)
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RowKind {
    /// A sticking component: contact and axis (0 = x, 1 = y).
    Stick { contact: u8, axis: u8 },
    /// A locked (or driven) joint of this link, or its driven angle for a root link.
    Lock { link: u8 },
    /// A prescribed root's coordinate (0 = x, 1 = y).
    Root,
}

/// One constraint `jac . qdot = 0`, with what its multiplier does.
#[derive(Debug, Clone, Copy)]
struct Row<const N: usize> {
    kind: RowKind,
    /// The constrained velocity is `jac . qdot`.
    jac: SVector<f64, N>,
    /// `d(jac)/dt . qdot`: the constraint's acceleration at `qddot = 0` beyond `jac . qddot`.
    bias: f64,
    /// `M^-1 Q_u`: the accelerations caused by a unit multiplier.
    response: SVector<f64, N>,
    /// The constrained velocity's value, `jac . qdot = target` (a driven joint's rate; 0
    /// otherwise).
    target: f64,
}

/// A set of at most `R` constraint rows (no allocation in the right-hand side): `R` is
/// [`MAX_ROWS`] for any body, 2 for a single rod (its two sticking components).
struct Rows<const N: usize, const R: usize> {
    rows: [Option<Row<N>>; R],
    len: usize,
}

impl<const N: usize, const R: usize> Rows<N, R> {
    fn new() -> Self {
        Rows {
            rows: [None; R],
            len: 0,
        }
    }
    fn push(&mut self, r: Row<N>) {
        self.rows[self.len] = Some(r);
        self.len += 1;
    }
    fn get(&self, i: usize) -> &Row<N> {
        self.rows[i].as_ref().expect("row within len")
    }
}

/// A constraint system `a x = b` of size `k <= R` on the stack.
type Small<const R: usize> = ([[f64; R]; R], [f64; R]);

/// Solve the `k x k` system that `fill` assembles, by Gaussian elimination with partial
/// pivoting. A (near-)singular system, from redundant constraints, is assembled again with a
/// tiny diagonal shift (only then: the common case copies nothing). Returns the solution, or
/// `None` if that fails too.
fn solve_small<const R: usize>(k: usize, fill: impl Fn(&mut Small<R>)) -> Option<[f64; R]> {
    let mut sys: Small<R> = ([[0.0; R]; R], [0.0; R]);
    fill(&mut sys);
    let scale = (0..k).fold(0.0f64, |m, i| m.max(sys.0[i][i].abs()));
    if eliminate(&mut sys, k, 1e-13 * scale.max(f64::MIN_POSITIVE)) {
        return Some(sys.1);
    }
    fill(&mut sys);
    for (i, row) in sys.0.iter_mut().enumerate().take(k) {
        row[i] += 1e-10 * scale.max(f64::MIN_POSITIVE);
    }
    eliminate(&mut sys, k, 1e-13 * scale.max(f64::MIN_POSITIVE)).then_some(sys.1)
}

/// Gaussian elimination with partial pivoting in place (`b` becomes `x`); false at a pivot
/// at or below `tiny`.
fn eliminate<const R: usize>((a, b): &mut Small<R>, k: usize, tiny: f64) -> bool {
    for col in 0..k {
        let piv = (col..k)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        if a[piv][col].abs() <= tiny {
            return false;
        }
        // Row operations on the first `k` entries only, in place: a whole row of `R`
        // (152 bytes) copied per operation called `memmove`.
        if piv != col {
            // (piv > col: the pivot is searched below the diagonal.)
            let (top, rest) = a.split_at_mut(piv);
            top[col][..k].swap_with_slice(&mut rest[0][..k]);
            b.swap(col, piv);
        }
        for r in col + 1..k {
            let f = a[r][col] / a[col][col];
            if f != 0.0 {
                let (top, rest) = a.split_at_mut(r);
                let pivot_row = &top[col];
                for (x, p) in rest[0][col..k].iter_mut().zip(&pivot_row[col..k]) {
                    *x -= f * p;
                }
                b[r] -= f * b[col];
            }
        }
    }
    for col in (0..k).rev() {
        let mut v = b[col];
        for c in col + 1..k {
            v -= a[col][c] * b[c];
        }
        b[col] = v / a[col][col];
    }
    true
}

/// [`solve_small`] of a system of one or two rows, unrolled: the same elimination with
/// partial pivoting as [`eliminate`], falling back to [`solve_small`] (which shifts the
/// diagonal) only at a tiny pivot.
#[inline(always)]
pub(super) fn solve_upto2(k: usize, a: [[f64; 2]; 2], b: [f64; 2]) -> Option<[f64; 2]> {
    #[cold]
    #[inline(never)]
    fn shifted(k: usize, a: [[f64; 2]; 2], b: [f64; 2]) -> Option<[f64; 2]> {
        solve_small::<2>(k, |sys| {
            sys.0 = a;
            sys.1 = b;
        })
    }
    let fallback = || shifted(k, a, b);
    if k == 1 {
        let tiny = 1e-13 * a[0][0].abs().max(f64::MIN_POSITIVE);
        if a[0][0].abs() <= tiny {
            return fallback();
        }
        return Some([b[0] / a[0][0], 0.0]);
    }
    let scale = a[0][0].abs().max(a[1][1].abs());
    let tiny = 1e-13 * scale.max(f64::MIN_POSITIVE);
    // `max_by` keeps the last of equal maxima: row 1 on a tie.
    let (r0, r1, b0, b1) = if a[1][0].abs() >= a[0][0].abs() {
        (a[1], a[0], b[1], b[0])
    } else {
        (a[0], a[1], b[0], b[1])
    };
    if r0[0].abs() <= tiny {
        return fallback();
    }
    let f = r1[0] / r0[0];
    let (a11, b1) = if f != 0.0 {
        (r1[1] - f * r0[1], b1 - f * b0)
    } else {
        (r1[1], b1)
    };
    if a11.abs() <= tiny {
        return fallback();
    }
    let x1 = b1 / a11;
    Some([(b0 - r0[1] * x1) / r0[0], x1])
}

/// Solve for the multipliers of `rows` at the unconstrained accelerations `qdd`, correct
/// `qdd`, and store each multiplier: a sticking component's reaction in place of its static
/// term, a locked joint's torque.
fn apply_rows<const N: usize, const R: usize>(
    rows: &Rows<N, R>,
    qdd: &mut SVector<f64, N>,
    contacts: &mut [ContactEval],
    joint_torque: &mut [f64; N],
    forces: &ForceSet,
) {
    let k = rows.len;
    if k == 0 {
        return;
    }
    let free = *qdd;
    let mults = solve_small::<R>(k, |(a, b)| {
        for i in 0..k {
            let ri = rows.get(i);
            b[i] = -(ri.bias + ri.jac.dot(&free));
            for (j, aij) in a[i].iter_mut().enumerate().take(k) {
                *aij = ri.jac.dot(&rows.get(j).response);
            }
        }
    })
    .unwrap_or([0.0; R]);
    for (i, &mult) in mults.iter().enumerate().take(k) {
        let r = rows.get(i);
        *qdd += mult * r.response;
        match r.kind {
            RowKind::Stick { contact, axis } => {
                contacts[contact as usize]
                    .force
                    .set_reaction(forces, axis as usize, mult);
            }
            RowKind::Lock { link } => joint_torque[link as usize] = mult,
            RowKind::Root => {}
        }
    }
}

/// Project `qd` onto `rows` (each `jac . qd = 0`) M-orthogonally, `minv` applying M^-1.
/// Only drift is removed: a violation above [`PROJECTION_LIMIT`] is a wrong mode, left for
/// the solver's switching functions to see. Returns whether `qd` changed.
fn project_rows<const N: usize, const R: usize>(
    rows: &Rows<N, R>,
    qd: &mut SVector<f64, N>,
    minv: impl Fn(&SVector<f64, N>) -> SVector<f64, N>,
) -> bool {
    let k = rows.len;
    if k == 0 {
        return false;
    }
    if (0..k).any(|i| (rows.get(i).jac.dot(qd) - rows.get(i).target).abs() > PROJECTION_LIMIT) {
        return false;
    }
    // M^-1 J^T columns and J M^-1 J^T.
    let mut minv_jt = [SVector::<f64, N>::zeros(); R];
    for (i, m) in minv_jt.iter_mut().enumerate().take(k) {
        *m = minv(&rows.get(i).jac);
    }
    let v = *qd;
    let lam = solve_small::<R>(k, |(a, b)| {
        for i in 0..k {
            let ji = &rows.get(i).jac;
            b[i] = ji.dot(&v) - rows.get(i).target;
            for (j, aij) in a[i].iter_mut().enumerate().take(k) {
                *aij = ji.dot(&minv_jt[j]);
            }
        }
    });
    match lam {
        Some(lam) if lam[..k].iter().any(|&l| l != 0.0) => {
            for (l, m) in lam.iter().zip(&minv_jt).take(k) {
                *qd -= *l * m;
            }
            true
        }
        _ => false,
    }
}

impl<const N: usize> Model<N> {
    /// Inverse effective mass of contact `ci`'s immersed centroid E at `q`, with the locked
    /// joints held: `W = J_E (M^-1 - M^-1 A^T (A M^-1 A^T)^-1 A M^-1) J_E^T` [1/kg], A the
    /// locked joints' rows. Sticking rows are left out: they can only slow E down. With the
    /// drag's velocity stiffness K it gives the drag's fastest rate, the largest eigenvalue
    /// of `W K`, which a fixed RK4 step must keep below about 2.78 (its stability limit on
    /// the negative real axis).
    pub fn centroid_inverse_mass(&self, q: &SVector<f64, N>, ci: usize) -> Matrix2<f64> {
        let nan = Matrix2::repeat(f64::NAN);
        let Some(c) = self.contacts.get(ci) else {
            return nan;
        };
        let pose = self.mechanism.pose(q);
        let Some(chol) = self.mechanism.mass_matrix(&pose).cholesky() else {
            return nan;
        };
        let centroid = self.geometry(c, &pose).centroid;
        let locks: Vec<SVector<f64, N>> = self
            .mechanism
            .locked_rows()
            .map(|(link, parent)| {
                let mut a = SVector::<f64, N>::zeros();
                a[2 + link] = 1.0;
                a[2 + parent] = -1.0;
                a
            })
            .chain(self.mechanism.driven_roots().map(|(link, _)| {
                let mut a = SVector::<f64, N>::zeros();
                a[2 + link] = 1.0;
                a
            }))
            .chain(
                (0..2)
                    .filter(|_| self.mechanism.root_fixed)
                    .chain(self.mechanism.clock())
                    .map(|k| {
                        let mut a = SVector::<f64, N>::zeros();
                        a[k] = 1.0;
                        a
                    }),
            )
            .collect();
        let responses: Vec<SVector<f64, N>> = locks.iter().map(|a| chol.solve(a)).collect();
        let schur = nalgebra::DMatrix::from_fn(locks.len(), locks.len(), |i, j| {
            locks[i].dot(&responses[j])
        });
        let Some(schur_inv) = schur.try_inverse() else {
            return nan;
        };
        let gen: [SVector<f64, N>; 2] = std::array::from_fn(|k| {
            let mut g = SVector::<f64, N>::zeros();
            self.mechanism
                .add_point_force(&pose, c.link(), centroid, unit(k), &mut g);
            g
        });
        let free: [SVector<f64, N>; 2] = std::array::from_fn(|k| chol.solve(&gen[k]));
        let along: [Vec<f64>; 2] =
            std::array::from_fn(|k| locks.iter().map(|a| a.dot(&free[k])).collect());
        Matrix2::from_fn(|a, b| {
            let mut held = 0.0;
            for (i, ai) in along[a].iter().enumerate() {
                for (j, bj) in along[b].iter().enumerate() {
                    held += ai * schur_inv[(i, j)] * bj;
                }
            }
            gen[a].dot(&free[b]) - held
        })
    }

    /// The impulse at one of the times of the table-driven joints: the smallest change of
    /// the rates (M-orthogonal, `dqd = M^-1 J^T lambda`) that puts each joint of `targets`
    /// (`(link, rate)`) on its new relative rate and keeps every other joint's and the
    /// root's rows (a table joint without a time here keeps its rate). The sand's forces are
    /// bounded and take no impulse: the contacts are left out (the run decides their modes
    /// again). Returns, per joint of `targets`, `(link, impulse, energy)`: the angular
    /// impulse the joint applies to its link [N m s] and the work it does,
    /// `impulse (before + after) / 2` [J] (the rate moves linearly with the impulse).
    pub fn drive_impulse(
        &self,
        q: &SVector<f64, N>,
        qd: &mut SVector<f64, N>,
        targets: &[(usize, f64)],
    ) -> Vec<(usize, f64, f64)> {
        let pose = self.mechanism.pose(q);
        let Some(chol) = self.mechanism.mass_matrix(&pose).cholesky() else {
            return Vec::new();
        };
        let free: Modes = [ContactMode::default(); MAX_CONTACTS];
        let mut rows = self.constraint_rows(&pose, q, qd, &free, &chol);
        let k = rows.len;
        for row in rows.rows.iter_mut().take(k).flatten() {
            if let RowKind::Lock { link } = row.kind {
                if let Some(&(_, rate)) = targets.iter().find(|(l, _)| *l == link as usize) {
                    row.target = rate;
                }
            }
        }
        let mut minv_jt = [SVector::<f64, N>::zeros(); MAX_ROWS];
        for (i, m) in minv_jt.iter_mut().enumerate().take(k) {
            *m = chol.solve(&rows.get(i).jac);
        }
        let v = *qd;
        let Some(lam) = solve_small::<MAX_ROWS>(k, |(a, b)| {
            for i in 0..k {
                let ji = &rows.get(i).jac;
                b[i] = ji.dot(&v) - rows.get(i).target;
                for (j, aij) in a[i].iter_mut().enumerate().take(k) {
                    *aij = ji.dot(&minv_jt[j]);
                }
            }
        }) else {
            return Vec::new();
        };
        for (l, m) in lam.iter().zip(&minv_jt).take(k) {
            *qd -= *l * m;
        }
        let mut out = Vec::with_capacity(targets.len());
        for (i, l) in lam.iter().enumerate().take(k) {
            let r = rows.get(i);
            if let RowKind::Lock { link } = r.kind {
                if targets.iter().any(|(t, _)| *t == link as usize) {
                    let impulse = -l;
                    let (before, after) = (r.jac.dot(&v), r.jac.dot(qd));
                    out.push((link as usize, impulse, 0.5 * impulse * (before + after)));
                }
            }
        }
        out
    }

    /// Whether any sticking component is in force under `modes`.
    #[inline]
    pub(crate) fn any_stuck(&self, modes: &Modes) -> bool {
        self.sign_model == SignModel::Modes
            && modes[..self.contacts.len()].iter().any(|m| self.stuck(m))
    }

    /// Whether a static term of a contact in mode `m` sticks (with `SignModel::Modes`).
    #[inline]
    pub(super) fn stuck(&self, m: &ContactMode) -> bool {
        m.in_contact
            && ((self.forces.owns(Switch::SlipX) && m.sx == Slip::Stick)
                || (self.forces.owns(Switch::SlipY) && m.sy == Slip::Stick))
    }

    /// The constraint rows in force under `modes` at this configuration: the locked joints
    /// and the sticking components.
    fn constraint_rows(
        &self,
        pose: &Pose<N>,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
        chol: &nalgebra::Cholesky<f64, nalgebra::Const<N>>,
    ) -> Rows<N, MAX_ROWS> {
        let mut rows = Rows::new();
        let clock = self.mechanism.clock();
        for r in self.mechanism.held_rows(q, qd) {
            let mut jac = SVector::<f64, N>::zeros();
            jac[2 + r.link] = 1.0;
            jac[2 + r.parent] = -1.0;
            if let Some(c) = clock {
                jac[c] = r.clock_coef;
            }
            rows.push(Row {
                kind: RowKind::Lock { link: r.link as u8 },
                jac,
                bias: r.bias,
                response: chol.solve(&jac),
                target: r.target,
            });
        }
        for (link, rate) in self.mechanism.driven_roots() {
            // A root link's angle driven at a constant rate: qdot_link = rate.
            let mut jac = SVector::<f64, N>::zeros();
            jac[2 + link] = 1.0;
            rows.push(Row {
                kind: RowKind::Lock { link: link as u8 },
                jac,
                bias: 0.0,
                response: chol.solve(&jac),
                target: rate,
            });
        }
        if self.mechanism.root_fixed || clock.is_some() {
            let root = if self.mechanism.root_fixed {
                0..2
            } else {
                0..0
            };
            for k in root.chain(clock) {
                let mut jac = SVector::<f64, N>::zeros();
                jac[k] = 1.0;
                rows.push(Row {
                    kind: RowKind::Root,
                    jac,
                    bias: 0.0,
                    response: chol.solve(&jac),
                    target: qd[k],
                });
            }
        }
        if self.sign_model != SignModel::Modes {
            return rows;
        }
        for (ci, c) in self.contacts.iter().enumerate() {
            let mode = &modes[ci];
            if !mode.in_contact {
                continue;
            }
            let stuck_x = self.forces.owns(Switch::SlipX) && mode.sx == Slip::Stick;
            let stuck_y = self.forces.owns(Switch::SlipY) && mode.sy == Slip::Stick;
            if !(stuck_x || stuck_y) {
                continue;
            }
            let link = c.link();
            let geom = self.geometry(c, pose);
            if geom.depth <= 0.0 {
                continue;
            }
            let jac_e: SMatrix<f64, 2, N> = self.mechanism.jacobian(pose, link, geom.centroid);
            let omega = qd[2 + link];
            // E moves over the link: d/dt v_E = J qddot + bias + omega dR/dq r_E'.
            let r_rate = self.centroid_local_rate(c, pose, q, qd, &geom);
            let slide = r_rate.x * pose.normal[link] - r_rate.y * pose.axis[link];
            let a_bias = self
                .mechanism
                .point_bias_acceleration(pose, link, geom.centroid, qd)
                + omega * slide;
            let p = self.application_point(c, geom.centroid);
            for (k, on) in [(0usize, stuck_x), (1usize, stuck_y)] {
                if !on {
                    continue;
                }
                let u = unit(k);
                let mut gen = SVector::<f64, N>::zeros();
                self.mechanism.add_point_force(pose, link, p, u, &mut gen);
                rows.push(Row {
                    kind: RowKind::Stick {
                        contact: ci as u8,
                        axis: k as u8,
                    },
                    jac: (u.transpose() * jac_e).transpose(),
                    bias: u.dot(&a_bias),
                    response: chol.solve(&gen),
                    target: 0.0,
                });
            }
        }
        rows
    }

    /// Solve for the multipliers of the locked joints and the sticking components (each
    /// sticking component's static term becomes the reaction that holds its velocity at
    /// zero) and correct the accelerations.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn solve_constraints(
        &self,
        pose: &Pose<N>,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        modes: &Modes,
        chol: &nalgebra::Cholesky<f64, nalgebra::Const<N>>,
        qdd: &mut SVector<f64, N>,
        contacts: &mut [ContactEval; MAX_CONTACTS],
        joint_torque: &mut [f64; N],
    ) {
        let rows = self.constraint_rows(pose, q, qd, modes, chol);
        apply_rows(&rows, qdd, contacts, joint_torque, &self.forces);
    }

    /// Project `qd` so that every sticking component's velocity (and every locked joint's
    /// rate) is zero, with the smallest change in kinetic energy (an M-orthogonal
    /// projection). Returns whether it changed.
    pub fn project_sticking(
        &self,
        q: &SVector<f64, N>,
        qd: &mut SVector<f64, N>,
        modes: &Modes,
    ) -> bool {
        if !self.any_stuck(modes) {
            return false;
        }
        if let Some(rod) = self.rigid_rod() {
            return self.project_rigid_rod(rod, q, qd, &modes[0]);
        }
        self.project_sticking_general(q, qd, modes)
    }

    /// Whether [`Model::project_sticking`] may change the rates of the state that `e`
    /// evaluated in `modes`. False when there is nothing stuck, and for a single rigid rod
    /// whose stuck components of v_E are exactly zero in `e`: the projection's right-hand
    /// side is those very components (the same products, bitwise), so it would solve for
    /// zero multipliers and leave the rates as they are.
    #[inline]
    pub fn sticking_may_drift(&self, e: &Eval<N>, modes: &Modes) -> bool {
        if !self.any_stuck(modes) {
            return false;
        }
        if self.rigid_rod().is_none() {
            return true;
        }
        let (mode, v_e) = (&modes[0], e.contacts[0].v_centroid);
        (self.forces.owns(Switch::SlipX) && mode.sx == Slip::Stick && v_e.x != 0.0)
            || (self.forces.owns(Switch::SlipY) && mode.sy == Slip::Stick && v_e.y != 0.0)
    }

    /// [`Model::project_sticking`] for any body (after the `any_stuck` check).
    pub(super) fn project_sticking_general(
        &self,
        q: &SVector<f64, N>,
        qd: &mut SVector<f64, N>,
        modes: &Modes,
    ) -> bool {
        let pose = self.mechanism.pose(q);
        let mass = self.mechanism.mass_matrix(&pose);
        let chol = match mass.cholesky() {
            Some(c) => c,
            None => return false,
        };
        let rows = self.constraint_rows(&pose, q, qd, modes, &chol);
        project_rows(&rows, qd, |v| chol.solve(v))
    }
}
