//! Sand under the bodies of another engine in space (MuJoCo's geoms, `granrs.mujoco.Sand`):
//! each geom is a shape in space ([`super::shape`]) under the terms in space, its wrench
//! put into the engine's generalized force, every geom in one call.
//!
//! The step is implicit in the sand. 3D-RFT reads only the direction of each element's
//! velocity, so it gives no unique force at rest, and a force that does not shrink as the
//! body slows cannot be taken explicitly: a foot at rest would chatter between full
//! resistance and none. Instead, with the engine's step `h`, its mass matrix `M` (plus
//! `h B` for the joint damping its integrator takes implicitly: `H`) and the geoms'
//! Jacobian `J` (each geom's centre velocity and angular velocity, its twist `xi`), the
//! twist at the step's end solves
//!
//! ```text
//! xi' = xi_free + h A W(xi'),      A = J H^-1 J^T,
//! xi_free = J (qvel + h H^-1 f_rest)
//! ```
//!
//! with `f_rest` the rest of the world's generalized force (the last `M qacc` less the
//! sand's last force) and `W` the sand's wrench at the step's end's velocity (at the
//! step's start's pose): each rate-independent term made continuous in the velocity over
//! the speed `rest_speed` (a stiff viscous law below it:
//! [`crate::forces::rft3d::stress_with_rate`]). The
//! solve is Newton's method with the law's exact rates ([`super::load::Wrench`]) and a
//! backtracking line search, started from the last step's twists with the last step's rates
//! (a chord: its points need the wrench alone) while each chord step cuts the residual
//! tenfold. The engine then applies `J^T W(xi')` through its own step, so
//! the twist it reaches is `xi'`: a resting body stays at rest (it creeps at most at about
//! `rest_speed` times its load over the sand's full resistance), its force balances its
//! load without chattering, and the step is backward Euler in the sand's velocity.
//!
//! Newton's method can fail where the law is far from smooth: at a large step (a body
//! toppling onto its side, a drop resolved in a few steps), and at rest under `poncelet`,
//! whose wrench turns with the direction of the creep (its leading area's centre moves
//! with it, which the rates leave out) and which therefore has no smooth solution there.
//! Where its residual stays above [`FALLBACK`] the step takes the rule of the sand at
//! rest, geom by geom: the wrench that brings every twist at the step's end to the sand's
//! creep `-C w` (the viscous law at rest, so that the wrench never does positive work on
//! the twist it leaves). Where every geom's force is then within the sand's resistance to
//! its motion (the law's wrench at the twist without the sand), the step is a rest
//! ([`Solve::rest`]): the sand's rate-independent terms are set-valued at rest, and this
//! wrench is their solution, not a failure. Otherwise a geom that would need more than its
//! resistance is held at that resistance, the others solved again with it held, and the
//! step falls back ([`Solve::fallback`]): the sand's law is not resolved at this step.

use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, UnitQuaternion, Vector3};

use super::load::{Sand, Wrench};
use crate::evaluate::geoms::{creep, stick_or_slide, EngineOut, EngineState, Slide};

type V3 = Vector3<f64>;

/// What [`SpaceCoupling::step`] writes per geom, in this order: the depth of its lowest
/// point below the surface [m], the number of surface elements below it, its centre's
/// velocity (x, y, z) [m/s] and its angular velocity (x, y, z) [rad/s] at the step's
/// start, and its centre's velocity at the step's end as the implicit step solved it
/// (x, y, z) [m/s].
pub const OUTPUTS: [&str; 11] = [
    "depth", "elements", "v_x", "v_y", "v_z", "omega_x", "omega_y", "omega_z", "v_end_x",
    "v_end_y", "v_end_z",
];

/// The default `rest_speed` [m/s]: below it the sand's rate-independent terms fade to a
/// viscous law (a resting foot under its full resistance creeps at about this speed).
pub const REST_SPEED: f64 = 1e-5;

/// A geom's place in the other engine's model (MuJoCo's indices), fixed at setup.
#[derive(Debug, Clone, PartialEq)]
pub struct Place {
    /// The geom's index (rows of `geom_xpos`, `geom_xmat`).
    pub geom: usize,
    /// Its body (rows of `cvel`).
    pub body: usize,
    /// The root of its body's tree (rows of `subtree_com`: `cdof` is taken about it).
    pub root: usize,
    /// The degrees of freedom that move it.
    pub dofs: Vec<usize>,
}

/// One geom: its shape under the sand, where the shape's centre is in the geom's frame
/// (a mesh's centre of mass), and its place.
#[derive(Debug, Clone)]
pub struct SpaceGeom {
    /// The shape, its terms, the medium, the surface and the rule.
    pub sand: Sand,
    /// The shape's centre in the geom's frame [m].
    pub centre: V3,
    /// Its place in the engine's model.
    pub place: Place,
}

/// How the last step's implicit solve went.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Solve {
    /// Newton iterations taken (0: no geom in the sand, or the wrenches held).
    pub iterations: usize,
    /// Whether the step is solved: Newton's residual came below its tolerance, or the step
    /// is a rest ([`Solve::rest`]).
    pub converged: bool,
    /// The residual's largest component over the twists' scale (the largest of the twists
    /// without the sand, plus `rest_speed`) at the end of Newton's solve (for a rest or a
    /// fallback, Newton's last, not the rest rule's).
    pub residual: f64,
    /// The largest `h lambda`: the timestep times the frequency of the sand's depth
    /// stiffness on the geom's vertical response, `sqrt(A_zz |dF_z / dz|)` (the velocity
    /// is implicit; the depth is the step's start's, so this is the rate the step must
    /// resolve: semi-implicit Euler is stable for an undamped oscillator below 2).
    pub h_lambda: f64,
    /// The geom it belongs to.
    pub geom: usize,
    /// Whether Newton's residual stayed above [`FALLBACK`] and every geom rests: the wrench
    /// that brings every twist to its creep at rest, each geom's force within the sand's
    /// resistance to its motion, is the step's solution.
    pub rest: bool,
    /// Whether Newton's residual stayed above [`FALLBACK`] and some geom asked for more
    /// than the sand's resistance to its motion: the step stuck or slid instead (the
    /// wrench that brings every twist to its creep at rest, a sliding geom's scaled down to
    /// its resistance).
    pub fallback: bool,
}

/// The solve's relative residual above which the step takes the rule of the sand at rest
/// (a rest, or a fallback where a geom slides).
pub const FALLBACK: f64 = 1e-2;

/// The line search's shortest step: `2^-SHORTEST_STEP` of Newton's. Where no step down to
/// it lowers the residual enough, Newton's direction is of no use at this point (the law is
/// not smooth on the scale of `rest_speed`), and the solve ends there: its residual then
/// decides, as at the iteration limit. Gymnasium's Ant standing in the sand meets such
/// points at about one step in ten; steps down to `2^-30` moved its residual there by less
/// than a thousandth over the rest of the 40 iterations, at some 30 evaluations of the
/// wrench each. Its solves that converge backtrack to `2^-8` at most.
pub const SHORTEST_STEP: i32 = 10;

/// The factor by which each full step of the chord (Newton's matrix with the rates last
/// evaluated) must bring the residual down for the solve to go on without new rates.
pub const CHORD: f64 = 0.1;

/// The coupling: geoms in space on another engine's bodies.
#[derive(Debug, Clone)]
pub struct SpaceCoupling {
    /// The geoms.
    pub geoms: Vec<SpaceGeom>,
    /// Number of degrees of freedom.
    pub nv: usize,
    /// The sand's extent: x from `patch[0]` to `patch[1]`, y from `patch[2]` to `patch[3]`
    /// [m]; a geom whose centre is outside feels nothing.
    pub patch: [f64; 4],
    /// Below this speed [m/s] the rate-independent terms fade to a viscous law.
    pub rest_speed: f64,
    /// The joints' damping that the engine's step takes implicitly, per dof.
    pub implicit_damping: Vec<f64>,
    /// The last generalized force (nv), whose effect the last `qacc` holds.
    pub previous: Vec<f64>,
    /// Each geom's wrench as last solved (for the later stages of a multi-stage step).
    pub held: Vec<Option<[f64; 6]>>,
    /// Each geom's element count at its last cut (the held stages of a multi-stage step
    /// keep it).
    pub cut: Vec<usize>,
    /// Each geom's twist at the end of the last step as solved (where the next solve
    /// starts, if it is closer than the twist without the sand).
    pub solved: Vec<Option<[f64; 6]>>,
    /// Each geom's rates `k` ([`Wrench::k`]) as last evaluated (the chord that the next
    /// solve's Newton matrix starts with).
    pub rates: Vec<Option<[[f64; 6]; 6]>>,
}

/// The x, y, z rows of the Jacobian of world point `p` and of the rotation, on the tree of
/// `place`, into `rows` (6 x nv, zeroed), from `cdof` (as MuJoCo's `mj_jac`).
fn jacobian(place: &Place, s: &EngineState, nv: usize, p: &V3, rows: &mut [f64]) {
    let c = &s.subtree_com[3 * place.root..3 * place.root + 3];
    let o = [p.x - c[0], p.y - c[1], p.z - c[2]];
    for &j in &place.dofs {
        let d = &s.cdof[6 * j..6 * j + 6];
        rows[j] = d[3] + d[1] * o[2] - d[2] * o[1];
        rows[nv + j] = d[4] + d[2] * o[0] - d[0] * o[2];
        rows[2 * nv + j] = d[5] + d[0] * o[1] - d[1] * o[0];
        rows[3 * nv + j] = d[0];
        rows[4 * nv + j] = d[1];
        rows[5 * nv + j] = d[2];
    }
}

/// Whether every active geom has a solved twist from the last step.
fn last_given(solved: &[Option<[f64; 6]>], active: &[usize]) -> bool {
    active.iter().all(|&i| solved[i].is_some())
}

/// The Cholesky factor of the symmetric positive definite `a` (n x n), or `None`.
fn factor(a: DMatrix<f64>) -> Option<nalgebra::Cholesky<f64, nalgebra::Dyn>> {
    nalgebra::Cholesky::new(a)
}

impl SpaceCoupling {
    /// The pose of geom `i` (its shape's centre and orientation) from the engine's arrays.
    pub fn pose(&self, i: usize, s: &EngineState) -> (V3, UnitQuaternion<f64>) {
        let g = &self.geoms[i];
        let k = g.place.geom;
        let m = &s.geom_xmat[9 * k..9 * k + 9];
        let r = Matrix3::new(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8]);
        let x = &s.geom_xpos[3 * k..3 * k + 3];
        let c = V3::new(x[0], x[1], x[2]) + r * g.centre;
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
        (c, q)
    }

    /// One evaluation: each geom's pose and twist from the engine's arrays, the implicit
    /// solve for the twists at the step's end (or, with `hold` where every geom in the sand
    /// has one, the wrenches of the last solve: a later stage of RK4's step), and the
    /// generalized force of the wrenches. Writes per geom the outputs ([`OUTPUTS`]), the
    /// applied wrench (force and moment about its shape's centre, world frame; n x 6) and
    /// its `h lambda`.
    pub fn step(&mut self, s: &EngineState, h: f64, hold: bool, out: EngineOut) -> Solve {
        let nv = self.nv;
        let width = OUTPUTS.len();
        out.outputs.fill(0.0);
        out.applied.fill(0.0);
        out.h_lambda.fill(0.0);
        out.generalized.fill(0.0);
        let mut report = Solve {
            converged: true,
            ..Solve::default()
        };
        let n = self.geoms.len();
        let mut poses = Vec::with_capacity(n);
        let mut candidates = Vec::with_capacity(n);
        for i in 0..n {
            let (c, q) = self.pose(i, s);
            let g = &self.geoms[i];
            let low = g.sand.shape.lowest_point(&c, &q);
            let depth = g.sand.surface - low.z;
            out.outputs[i * width] = depth.max(0.0);
            let inside = c.x >= self.patch[0]
                && c.x <= self.patch[1]
                && c.y >= self.patch[2]
                && c.y <= self.patch[3];
            if depth > 0.0 && inside {
                candidates.push(i);
            }
            poses.push((c, q));
        }
        // A later stage of a multi-stage step (RK4's) whose geoms in the sand all hold the
        // wrench of its first stage applies that wrench at this stage's pose: no cut (a
        // geom that entered the sand since has none, and the stage solves anew).
        let keep = hold && candidates.iter().all(|&i| self.held[i].is_some());
        let mut active = Vec::with_capacity(n);
        for &i in &candidates {
            if !keep {
                let (c, q) = &poses[i];
                self.cut[i] = self.geoms[i].sand.cut_at_rest(c, q);
            }
            out.outputs[i * width + 1] = self.cut[i] as f64;
            if self.cut[i] > 0 {
                active.push(i);
            }
        }
        if active.is_empty() {
            self.previous.fill(0.0);
            self.held.fill(None);
            self.solved.fill(None);
            self.rates.fill(None);
            return report;
        }
        let k = active.len();
        let rows = 6 * k;
        let mut jac = vec![0.0; rows * nv];
        for (a, &i) in active.iter().enumerate() {
            let place = &self.geoms[i].place;
            jacobian(
                place,
                s,
                nv,
                &poses[i].0,
                &mut jac[6 * a * nv..6 * (a + 1) * nv],
            );
        }
        let j = DMatrix::from_row_slice(rows, nv, &jac);
        let qvel = DVector::from_column_slice(s.qvel);
        let xi0 = &j * &qvel;
        for (a, &i) in active.iter().enumerate() {
            let row = &mut out.outputs[i * width..(i + 1) * width];
            row[2..8].copy_from_slice(xi0.as_slice()[6 * a..6 * a + 6].as_ref());
        }
        // The wrenches at the twists `xi`, with their rates `k` where `rates` (else only the
        // wrenches and their height rates, the same bits: a trial point of the line search
        // that may be rejected).
        let eval_with = |geoms: &[SpaceGeom], xi: &DVector<f64>, rates: bool| -> Vec<Wrench> {
            active
                .iter()
                .enumerate()
                .map(|(a, &i)| {
                    let x = &xi.as_slice()[6 * a..6 * a + 6];
                    let (c, q) = &poses[i];
                    let (v, w) = (V3::new(x[0], x[1], x[2]), V3::new(x[3], x[4], x[5]));
                    let sand = &geoms[i].sand;
                    match rates {
                        true => sand.wrench(c, q, &v, &w, self.rest_speed),
                        false => sand.wrench_value(c, q, &v, &w, self.rest_speed),
                    }
                })
                .collect()
        };
        let eval = |geoms: &[SpaceGeom], xi: &DVector<f64>| eval_with(geoms, xi, true);
        let mass = DMatrix::from_row_slice(nv, nv, s.mass);
        let mut hm = mass.clone();
        for (d, b) in self.implicit_damping.iter().enumerate() {
            hm[(d, d)] += h * b;
        }
        let wrenches: Vec<[f64; 6]>;
        let held = hold && active.iter().all(|&i| self.held[i].is_some());
        if held {
            wrenches = active
                .iter()
                .map(|&i| self.held[i].expect("held"))
                .collect();
        } else if let Some(chol) = factor(hm) {
            // The twists without the sand, and the response of each to a unit wrench.
            let qacc = DVector::from_column_slice(s.qacc);
            let rest = &mass * &qacc - DVector::from_column_slice(&self.previous);
            let free = &j * (&qvel + h * chol.solve(&rest));
            let resp = &j * chol.solve(&j.transpose());
            let scale = free.amax() + self.rest_speed;
            let tol = 1e-10 * scale;
            // The wrenches at a twist, stacked, and the residual.
            let effective = |ws: &[Wrench]| -> DVector<f64> {
                DVector::from_fn(rows, |p, _| ws[p / 6].w[p % 6])
            };
            let residual = |ws: &[Wrench], xi: &DVector<f64>| -> DVector<f64> {
                xi - &free - h * (&resp * effective(ws))
            };
            // Start from the last step's solved twists where every geom has one (a body at
            // rest is then solved at once), else, or if the twists without the sand are
            // closer, from those.
            let last = last_given(&self.solved, &active).then(|| {
                DVector::from_fn(rows, |p, _| {
                    self.solved[active[p / 6]].expect("solved")[p % 6]
                })
            });
            // The rates of the Newton matrix: each geom's last evaluated (a chord: its trial
            // points need no rates) while each of its full steps brings the residual down by
            // at least `CHORD`, else the rates at the iterate.
            let mut chord: Option<Vec<[[f64; 6]; 6]>> = active
                .iter()
                .map(|&i| self.rates[i])
                .collect::<Option<Vec<_>>>()
                .filter(|_| last.is_some());
            let mut use_chord = chord.is_some();
            let (mut xi, mut ws, mut r) = match last {
                Some(last) => {
                    let lw = eval_with(&self.geoms, &last, !use_chord);
                    let lr = residual(&lw, &last);
                    (last, lw, lr)
                }
                None => {
                    let fw = eval(&self.geoms, &free);
                    let fr = residual(&fw, &free);
                    (free.clone(), fw, fr)
                }
            };
            let mut norm = r.norm();
            // Whether `ws` holds the rates (a backtracked trial's wrench does not).
            let mut rated = !use_chord;
            // The twists without the sand are the closer start only where the last step's
            // leave a residual of the order of the sand's whole response (`h A W`, of the
            // order of the twists' scale for a geom carrying its load): not at a rest or a
            // slow step, whose solve then costs no evaluation there.
            if r.amax() > FALLBACK * scale && last_given(&self.solved, &active) {
                // Only compared: its wrench without the rates (the same bits).
                let fw = eval_with(&self.geoms, &free, false);
                let fr = residual(&fw, &free);
                if fr.norm() < norm {
                    norm = fr.norm();
                    (xi, ws, r) = (free.clone(), fw, fr);
                    rated = false;
                }
            }
            if rated {
                chord = Some(ws.iter().map(|w| w.k).collect());
            }
            let mut converged = r.amax() <= tol;
            let mut iterations = 0;
            // The residual before the last full Newton step, if the last step was full.
            let mut before: Option<f64> = None;
            // The Newton matrix's LU factors, kept while they are the chord's (the same
            // matrix at every chord step).
            let mut factored: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>> = None;
            while !converged && iterations < 40 {
                iterations += 1;
                if !rated && !use_chord {
                    ws = eval(&self.geoms, &xi);
                    rated = true;
                }
                if rated {
                    chord = Some(ws.iter().map(|w| w.k).collect());
                }
                let chording = !rated;
                let ks = chord.as_ref().expect("rates evaluated or kept");
                // Whether Newton's quadratic convergence, at the rate of its last full step,
                // brings the full step below the tolerance (or the step is the chord's): its
                // trial is then evaluated without the rates (the same bits; if it does not
                // converge after all, the next iteration evaluates them or keeps the chord).
                let now = r.amax();
                let last_step = chording || before.is_some_and(|b| now * (now / b).powi(2) <= tol);
                if !chording {
                    factored = None;
                }
                if factored.is_none() {
                    let mut kk = DMatrix::zeros(rows, rows);
                    for (a, k) in ks.iter().enumerate() {
                        for p in 0..6 {
                            for q in 0..6 {
                                kk[(6 * a + p, 6 * a + q)] = k[p][q];
                            }
                        }
                    }
                    let newton = DMatrix::identity(rows, rows) - h * (&resp * kk);
                    factored = Some(newton.lu());
                }
                let Some(step) = factored.as_ref().expect("factored").solve(&(-&r)) else {
                    break;
                };
                let mut t = 1.0;
                let mut moved = false;
                for _ in 0..=SHORTEST_STEP {
                    let trial = &xi + t * &step;
                    // The full step with its rates (usually taken, and unless it is likely
                    // the last); a shorter one without.
                    let rates = t == 1.0 && !last_step;
                    let tw = eval_with(&self.geoms, &trial, rates);
                    let tr = residual(&tw, &trial);
                    let tn = tr.norm();
                    // The chord's step is taken whole where it brings the residual down by
                    // `CHORD`, else not at all (the rates at the iterate then decide).
                    let good = match chording {
                        true => tr.amax() <= CHORD * now,
                        false => tn < (1.0 - 1e-4 * t) * norm,
                    };
                    if good || tr.amax() <= tol {
                        (xi, ws, r, norm) = (trial, tw, tr, tn);
                        rated = rates;
                        moved = true;
                        break;
                    }
                    if chording {
                        break;
                    }
                    t *= 0.5;
                }
                before = (moved && t == 1.0 && !chording).then_some(now);
                converged = r.amax() <= tol;
                if chording && !moved {
                    // The chord is too slow here: the rates at the iterate from now on.
                    use_chord = false;
                    continue;
                }
                if !moved {
                    break;
                }
            }
            report.iterations = iterations;
            report.converged = converged;
            report.residual = r.amax() / scale;
            let mut w = effective(&ws);
            if report.residual > FALLBACK {
                let full = effective(&eval_with(&self.geoms, &free, false));
                // The sand held as a stiff viscous law ([`creep`]; the rotation's over the
                // shape's reach): a stop to zero exactly did positive work whenever the
                // rest of the world's force moved between the steps. A hopper resting on
                // `poncelet`, whose wrench at rest turns with the direction of the creep
                // and takes this rule at nearly every step, gained 2e-4 to 3e-4 J/s that
                // way.
                let mut ha = h * &resp;
                creep(&mut ha, &full, 6, 3, self.rest_speed, |a| {
                    self.geoms[active[a]].sand.shape.reach()
                });
                let slid;
                (w, slid) = stick_or_slide(&ha, &free, &full, k, 6, 3, Slide::Scaled);
                xi = &free + h * (&resp * &w);
                report.rest = !slid;
                report.fallback = slid;
                report.converged = !slid;
            }
            wrenches = (0..k)
                .map(|a| std::array::from_fn(|r| w[6 * a + r]))
                .collect();
            self.solved.fill(None);
            self.rates.fill(None);
            for (a, &i) in active.iter().enumerate() {
                self.rates[i] = chord.as_ref().map(|k| k[a]);
                let row = &mut out.outputs[i * width..(i + 1) * width];
                row[8..11].copy_from_slice(&xi.as_slice()[6 * a..6 * a + 3]);
                self.solved[i] = Some(std::array::from_fn(|p| xi[6 * a + p]));
            }
            // h lambda: h times the frequency of the sand's depth stiffness on the geom's
            // vertical response (the one rate the implicit step leaves explicit: the depth
            // is the step's start's).
            for (a, &i) in active.iter().enumerate() {
                let stiff = (-ws[a].kz[2]).max(0.0);
                let rate = (resp[(6 * a + 2, 6 * a + 2)] * stiff).sqrt();
                out.h_lambda[i] = h * rate;
                if h * rate > report.h_lambda {
                    report.h_lambda = h * rate;
                    report.geom = i;
                }
            }
        } else {
            // Not positive definite (a degenerate state): the wrenches as evaluated.
            let ws = eval(&self.geoms, &xi0);
            wrenches = ws.iter().map(|w| w.w).collect();
        }
        if !held {
            self.held.fill(None);
            for (a, &i) in active.iter().enumerate() {
                self.held[i] = Some(wrenches[a]);
            }
        }
        for (a, &i) in active.iter().enumerate() {
            out.applied[6 * i..6 * i + 6].copy_from_slice(&wrenches[a]);
            let rows_a = &jac[6 * a * nv..6 * (a + 1) * nv];
            for (d, g) in out.generalized.iter_mut().enumerate() {
                *g += (0..6)
                    .map(|r| rows_a[r * nv + d] * wrenches[a][r])
                    .sum::<f64>();
            }
        }
        self.previous.copy_from_slice(out.generalized);
        report
    }
}

#[cfg(test)]
mod timing {
    use super::*;
    use crate::forces::rft3d::Rft3d;
    use crate::forces::Medium;
    use crate::space::load::Terms3;
    use crate::space::shape::{Quadrature, Shape};

    #[test]
    #[ignore]
    fn time_the_parts() {
        let terms = Terms3 {
            rft3d: Some(Rft3d {
                zeta: 4.6e5,
                mu_surf: f64::INFINITY,
                grazing: true,
            }),
            ..Terms3::default()
        };
        for nodes in [3, 5, 6] {
            let shape = Shape::capsule("c", 0.08, 0.4).unwrap();
            let mut s = Sand::new(shape, terms, Medium::default(), 0.0, Quadrature::new(nodes));
            let q = UnitQuaternion::from_euler_angles(0.0, 1.2, 0.3);
            let c = V3::new(0.0, 0.0, 0.02);
            let n = 20000;
            let t = std::time::Instant::now();
            let mut k = 0;
            for _ in 0..n {
                k += s.cut_at_rest(&c, &q);
            }
            let cut = t.elapsed().as_secs_f64() / n as f64;
            let el = k / n;
            let mut line = format!(
                "nodes {nodes}: {el} elements, cut {:.1} us ({:.0} ns/el)",
                cut * 1e6,
                cut * 1e9 / el as f64
            );
            // Creeping (every element on the ramp) and moving (the trailing half off it).
            for (what, v) in [("creeping", -1e-6), ("moving", -0.1)] {
                let v = V3::new(0.3 * v, 0.0, v);
                let mut acc = 0.0;
                let t = std::time::Instant::now();
                for _ in 0..n {
                    acc += s.wrench(&c, &q, &v, &V3::zeros(), 1e-5).w[2];
                }
                let rated = t.elapsed().as_secs_f64() / n as f64;
                let t = std::time::Instant::now();
                for _ in 0..n {
                    acc += s.wrench_value(&c, &q, &v, &V3::zeros(), 1e-5).w[2];
                }
                let value = t.elapsed().as_secs_f64() / n as f64;
                line += &format!(
                    "; {what}: wrench {:.1} us ({:.0} ns/el), without rates {:.1} us ({:.0} ns/el) {acc:e}",
                    rated * 1e6,
                    rated * 1e9 / el as f64,
                    value * 1e6,
                    value * 1e9 / el as f64
                );
            }
            eprintln!("{line}");
        }
    }
}
