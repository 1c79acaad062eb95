"""granrs against the same free-link model written without granrs, on the Table 3.5 scenes.

One command times granrs and its peers on the same scenes in one run and prints ratios
(issue 5, "peers"). The model is the one of ``shared/MODEL.md`` as granrs runs it by default
for the free link: a rod of L = 0.190 m, d_c = 0.0127 m, m = 0.184 kg, I = m (L^2/12 +
d_c^2/16), sand of 1650 kg/m^3, g = 9.81, Table 3.4 coefficients (the row at the tabulated
angle nearest |q|, ties to the larger angle: ``granrs.cases.free_link``), the resistance
force applied at the tip T, dropped tip first at q with velocity (0, -v0). The peers:

* ``numba_user``: a numba-jitted fixed-step RK4 written the way a user would: the state
  (x, y, q, vx, vy, omega) as a numpy array, a right-hand side that returns a new array,
  k1..k4 temporaries, the thesis's plain ``sign()`` (``np.sign``), dt = 1e-4 s, and the stop
  (the tip's vertical velocity reaching 0 from below) located by linear interpolation
  between the two step ends. Compiled before timing.
* ``numba_scalar``: the same algorithm hand-tuned as a strong user would: no arrays, every
  quantity a scalar local, constants folded, one sin/cos pair and one pow per evaluation
  (the stop check reuses the next step's first sine and cosine). A ceiling for what a
  jitted loop of this algorithm gives.
* ``numba_located``: ``numba_scalar`` with granrs's stop: located on the step's cubic
  Hermite interpolant by Illinois regula falsi, as granrs does. It reaches granrs
  ``"raw"``'s accuracy at ``numba_scalar``'s cost. A loop with granrs's ``"modes"``
  accuracy is not written: holding the signs through each step (``numba_held`` on the
  work-precision figure, ``impact_located(..., hold=True)``) fixes the vertical drops
  (their error falls from 1e-6 to granrs's 9e-10 m) but makes the 5 and 15 deg rows worse
  (to 2e-5 m), whose v_Ex changes sign and sticks mid-impact: granrs locates that switch
  and decides stick or slip (Karnopp, a reaction solve); and the 85 deg rows stay at 3e-8 m
  against granrs's 4e-10 until the kink of l = min(d / cos q, L) is located and polished
  on the step map. With those, the loop is granrs's event engine written again.
* ``libm_floor``: not a peer but a floor: ``numba_scalar``'s calls into the C library alone,
  as many as its impact makes (one sin/cos pair and one pow per evaluation, four
  evaluations per step), none waiting for another: their cost at full throughput, under any
  loop that makes them. granrs makes the same calls (glibc's ``sincos`` and ``pow``) once
  per evaluation. What an impact costs above this floor is each method's own work and its
  waiting; the report sets the targets against it ("What the targets leave").
* ``solve_ivp``: ``scipy.integrate.solve_ivp`` (RK45) on a plain-Python right-hand side
  (``math``, a list returned), with a terminal event on the tip's vertical velocity
  (direction +1); a run past ``IVP_MAX_NFEV`` evaluations is abandoned as failed (the
  plain sign() can trap RK45 where v_Ey reaches 0). Its tolerance is matched to granrs's
  depth accuracy per scene: the reference depth is granrs (``"modes"``) at dt = 1e-7 s
  (1e-6 with ``--quick``), granrs's error is that of its default run at dt = 1e-4, and
  the matched rtol is the loosest of 1e-3 .. 1e-12 from which on (it and every tighter
  rtol of the sweep) solve_ivp's depth error is at most granrs's; atol = 1e-3 rtol. A
  scene where no rtol gets there is timed at its most accurate rtol and flagged; one where
  every rtol fails is not timed, and the solve_ivp ratio is over the scenes it ran.

granrs itself is timed per impact, summary only (no time series):

* through ``granrs.simulate(scene)`` per scene from Python, with the default sign model
  ``"modes"`` (each sign a mode held through a step, switches located exactly) and with
  ``"raw"`` (the thesis's plain sign: the peers' algorithm, with granrs's exact stop); and
  with the scene asking only for the depth and t_s (``outputs=("depth", "t_s")``: what the
  peers return; the rest of the summary is not computed);
* Rust only: criterion's ``impact/table_3_5_all`` and ``impact/table_3_5_all_raw``
  (``benches/free_link.rs``), run by this script through ``cargo bench`` unless
  ``--no-criterion``; and, in the same interleaved loop as the peers, the run alone as the
  core times it (``_granrs.run(...).run_seconds``: no Python around it).

* ``granrs.sweep`` over the scenes (each ``SWEEP_COPIES`` times, or ``--sweep-copies``) on one
  and on two threads, against ``numba_scalar`` over the same scenes in a ``prange`` on one
  and two threads (a
  perfectly parallel loop: the ceiling of what two cores give). The sweep is timed with its
  SIMD lanes (the default, ``lanes=True``: four scenes per lane group) and on the scalar
  path (``lanes=False``), in the same loop; and with its lanes asking only for the depth and
  t_s (``outputs=("depth", "t_s")``: the columns the numba loop returns).

* The free link under ``rft`` (gravity and ``rft(zeta=...)``, 8 elements) on the same scenes,
  against the thesis's law: ``granrs.simulate`` per scene and a sweep's lanes on one thread,
  at ``zeta = 1e6`` and at the ``zeta`` fitted to Table 3.1 (the ``thesis_sand`` medium
  card's ``rft.zeta``), and the run alone as the core times it. Targets: a ``simulate`` at
  most ``TARGET_RFT_SIMULATE`` times the thesis's, a sweep per core at most
  ``TARGET_RFT_SWEEP`` times the thesis's sweep. ``simulate`` and a sweep include the step's
  check (a run whose ``step_error`` is above 1e-5 runs again at ``dt / 10``: under ``rft``
  the vertical drops do); the run alone does not.

It prints a work-precision table and writes its figure (``--figure``, a PNG): every peer at
several steps (solve_ivp at several rtols), the median over the scenes of the depth error
against the reference, against the time per impact. solve_ivp is timed at matched accuracy
per scene (above); the target is that granrs is faster on every scene (the minimum of the
per-scene ratios at least 1; the median is printed too).

Every method runs the whole table in turn within each repeat, and each scene's time is the
minimum over the repeats: the ratios come from the same stretch of a shared, noisy machine.
Before timing, the peers' depths are checked against granrs ``"raw"``: the same model and the
same steps, so they must agree to RK4 accuracy (the two differ only where granrs cuts a step
at a kink of the force law and in how the stop is located); the script fails otherwise.

Usage::

    python benches/peers.py [--quick] [--repeats N] [--out results.csv|results.md]
        [--no-criterion] [--figure work_precision.png] [--no-figure] [--sweep-copies N]
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numba
import numpy as np
from numba import njit, prange, set_num_threads
from scipy.integrate import solve_ivp

import granrs
from granrs import _granrs
from granrs.forces import thesis_row

#: numba's parallel loop on its own thread pool: the default OpenMP layer spin-waits after a
#: parallel region and takes the cores from whatever is timed next (seen: granrs.sweep
#: measured 1.5-2.6x slower right after a prange than alone).
numba.config.THREADING_LAYER = "workqueue"

#: RK4 step of granrs's default and of the numba peers [s] (thesis: 10 kHz).
DT = 1e-4
#: Latest end time of the peers [s] (every Table 3.5 impact stops within about 40 ms).
T_END = 0.2
#: granrs reference steps [s] (``"modes"``): full and ``--quick``.
REFERENCE_DT = 1e-7
REFERENCE_DT_QUICK = 1e-6
#: solve_ivp tolerances swept, loosest first; atol = ATOL_FACTOR * rtol.
RTOLS = tuple(10.0**-k for k in range(3, 13))
ATOL_FACTOR = 1e-3
#: Right-hand-side evaluations after which a solve_ivp run is abandoned as failed: with the
#: plain sign() the vertical force flips where v_Ey reaches 0 and RK45 can shrink its step
#: without end there instead of reaching the stop event.
IVP_MAX_NFEV = 50_000
#: Largest |depth(numba) - depth(granrs raw)| accepted [m]: RK4 accuracy at 10 kHz. The
#: steps are the same; the stop differs (linear against Hermite interpolation, an error of
#: about |a| dt^2 / 8 ~ 1e-7 m) and so do steps that granrs cuts at the full-immersion kink.
AGREEMENT_TOL = 2e-6
#: The Table 3.5 rows run in ``--quick`` mode (q_deg, v0).
QUICK_ROWS = ((0.0, 2.214), (25.0, 1.766), (45.0, 2.27), (65.0, 1.119), (85.0, 2.257))
#: Targets: granrs / numba user; a sweep's lanes on one thread / numba scalar (first 1/3,
#: re-set to 1/2 when the one-kernel decision was taken; ``simulate`` against numba scalar
#: is judged by the two lines below, which replaced its first target of 1); the sweep's
#: two-thread speed-up against a perfectly parallel numba loop's; faster than solve_ivp at
#: matched accuracy on every scene.
TARGET_NUMBA = 1.0 / 3.0
TARGET_SWEEP = 0.5
TARGET_SCALING = 0.95
TARGET_SOLVE_IVP = 1.0
#: Targets of granrs.simulate against the hand-tuned loop (``numba_scalar``) with a scene that
#: asks only for ``LEAN_OUTPUTS`` (its ``outputs``), and with the default summary.
TARGET_SCALAR_LEAN = 1.2
TARGET_SCALAR_DEFAULT = 1.6
#: What the lean rows ask for: the depth and the stopping time (the peers' two results).
LEAN_OUTPUTS = ("depth", "t_s")
#: Targets of the free link under ``rft`` against the thesis's law on the same scenes: a
#: ``simulate`` per scene, and a sweep's lanes on one thread.
TARGET_RFT_SIMULATE = 3.0
TARGET_RFT_SWEEP = 2.0
#: Copies of the scenes in one timed sweep (so that a sweep's fixed cost is spread), and
#: the sweeps' repeats per repeat of the per-scene timing: a sweep is timed as a whole, and
#: on a shared machine only a best of many short batches escapes the other loads.
SWEEP_COPIES = 5
SWEEP_REPEATS = 4
REPO = Path(__file__).resolve().parents[1]


# --- the model, as a user writes it -------------------------------------------------------


def parameters(scene: granrs.Scene) -> np.ndarray:
    """The peers' parameter vector: m, I, L, d_c, rho_g, g, eta_h, eta_d, eta_v, lambda."""
    c = thesis_row(scene.forces)
    inertia = scene.inertia
    if inertia is None:
        inertia = scene.mass * (scene.length**2 / 12.0 + scene.diameter**2 / 16.0)
    return np.array(
        [
            scene.mass,
            inertia,
            scene.length,
            scene.diameter,
            scene.rho_g,
            scene.g,
            c.eta_h,
            c.eta_d,
            c.eta_v,
            c.lam,
        ]
    )


def initial_state(scene: granrs.Scene) -> np.ndarray:
    """(x, y, q, vx, vy, omega) of the centre of mass: tip at the origin, moving (0, -v0)."""
    q = math.radians(scene.q_deg)
    half = 0.5 * scene.length
    return np.array([half * math.sin(q), half * math.cos(q), q, 0.0, -scene.v0, 0.0])


@njit
def rhs_user(y, p):
    """dy/dt of the free link (user style: arrays in, a new array out)."""
    m, inertia, length, dc, rho, g = p[0], p[1], p[2], p[3], p[4], p[5]
    eta_h, eta_d, eta_v, lam = p[6], p[7], p[8], p[9]
    q, vx, vy, w = y[2], y[3], y[4], y[5]
    e = np.array([np.sin(q), np.cos(q)])  # axis, tip to top
    n = np.array([e[1], -e[0]])  # d e / d q
    tip = y[0:2] - 0.5 * length * e
    d = max(0.0, -tip[1])
    force = np.zeros(2)
    torque = 0.0
    if d > 0.0:
        # Immersed length, capped at L; centroid E of the immersed part and its velocity.
        if d >= length * e[1]:
            ell = length
        else:
            ell = d / e[1]
        s_e = -0.5 * length + 0.5 * ell
        v_e = np.array([vx, vy]) + w * s_e * n
        cross = abs(e[0] * v_e[1] - e[1] * v_e[0])
        drag = -eta_d * rho * dc * ell * cross * v_e
        f_h = eta_h * g * rho * dc * d**2
        f_v = eta_v * (d / length) ** lam * g * rho * (np.pi / 4 * dc**2 * ell)
        force = drag - np.array([np.sign(v_e[0]) * f_h, np.sign(v_e[1]) * f_v])
        # Applied at the tip, r = -L/2 e: generalized torque F . dr/dq.
        torque = np.dot(force, -0.5 * length * n)
    return np.array([vx, vy, w, force[0] / m, force[1] / m - g, torque / inertia])


@njit
def tip_height_and_vy(y, length):
    """Height y_T and vertical velocity of the tip."""
    return y[1] - 0.5 * length * np.cos(y[2]), y[4] + 0.5 * length * y[5] * np.sin(y[2])


@njit
def impact_user(y0, p, dt, t_end):
    """Fixed-step RK4 to the stop; returns (t_s, depth at t_s, steps). User style."""
    y = y0.copy()
    h_prev, vt_prev = tip_height_and_vy(y, p[2])
    n_max = int(np.ceil(t_end / dt))
    for i in range(n_max):
        k1 = rhs_user(y, p)
        k2 = rhs_user(y + 0.5 * dt * k1, p)
        k3 = rhs_user(y + 0.5 * dt * k2, p)
        k4 = rhs_user(y + dt * k3, p)
        y_new = y + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        h_tip, vt = tip_height_and_vy(y_new, p[2])
        if vt >= 0.0:
            theta = -vt_prev / (vt - vt_prev)
            height = h_prev + theta * (h_tip - h_prev)
            return (i + theta) * dt, max(0.0, -height), i + 1
        y = y_new
        h_prev, vt_prev = h_tip, vt
    return np.nan, max(0.0, -h_prev), n_max


@njit(inline="always")
def _accel(s, c, x_y, vx, vy, w, inv_m, inv_i, half, length, c_d, c_h, c_v, lam, g):
    """(ax, ay, alpha) at the angle whose sine and cosine are ``s``, ``c``, with every
    constant folded (hand-tuned scalar peer): one pow, no arrays, the plain sign()."""
    return _accel_held(s, c, x_y, vx, vy, w, inv_m, inv_i, half, length, c_d, c_h, c_v, lam,
                       g, PLAIN, PLAIN, PLAIN)  # fmt: skip


#: A held sign that stands for "the plain sign() at each evaluation".
PLAIN = 2.0


@njit(inline="always")
def _held(v, held):
    """``held`` (-1, 0 or +1), or the plain sign of ``v`` where ``held`` is ``PLAIN``."""
    if held != PLAIN:
        return held
    return 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)


@njit(inline="always")
def _accel_held(s, c, x_y, vx, vy, w, inv_m, inv_i, half, length, c_d, c_h, c_v, lam, g,
                hx, hy, hc):  # fmt: skip
    """:func:`_accel` with the signs of v_Ex, v_Ey and e x v_E held (``PLAIN``: not held)."""
    d = half * c - x_y  # depth of the tip: -(y - L/2 cos q)
    if d <= 0.0:
        return 0.0, -g, 0.0
    ell = length if d >= length * c else d / c
    s_e = 0.5 * (ell - length)
    vex = vx + w * s_e * c
    vey = vy - w * s_e * s
    cross = s * vey - c * vex
    k = c_d * ell * (abs(cross) if hc == PLAIN else hc * cross)
    f_h = c_h * d * d
    f_v = c_v * math.pow(d, lam) * ell
    fx = -k * vex - _held(vex, hx) * f_h
    fy = -k * vey - _held(vey, hy) * f_v
    return fx * inv_m, fy * inv_m - g, -half * (c * fx - s * fy) * inv_i


@njit(inline="always")
def _constants(p):
    """The scalar peers' folded constants: 1/m, 1/I, L/2, L, eta_d rho d_c,
    eta_h g rho d_c, eta_v g rho pi d_c^2 / 4 / L^lambda, lambda, g."""
    m, inertia, length, dc, rho, g = p[0], p[1], p[2], p[3], p[4], p[5]
    eta_h, eta_d, eta_v, lam = p[6], p[7], p[8], p[9]
    c_v = eta_v * g * rho * (math.pi / 4.0) * dc * dc / math.pow(length, lam)
    return (
        1.0 / m,
        1.0 / inertia,
        0.5 * length,
        length,
        eta_d * rho * dc,
        eta_h * g * rho * dc,
        c_v,
        lam,
        g,
    )


@njit(inline="always")
def _rk4(x, y, q, vx, vy, w, s, c, a1x, a1y, a1w, dt, k, hx, hy, hc):
    """One RK4 step from a state whose sine, cosine and first stage are known (``k``: the
    folded constants; ``hx``, ``hy``, ``hc``: the held signs, see :func:`_accel_held`).
    Returns the new state (x, y, q, vx, vy, w)."""
    inv_m, inv_i, half, length, c_d, c_h, c_v, lam, g = k
    hdt = 0.5 * dt
    vx2, vy2, w2 = vx + hdt * a1x, vy + hdt * a1y, w + hdt * a1w
    q2 = q + hdt * w
    a2x, a2y, a2w = _accel_held(math.sin(q2), math.cos(q2), y + hdt * vy, vx2, vy2, w2, inv_m,
                                inv_i, half, length, c_d, c_h, c_v, lam, g, hx, hy, hc)  # fmt: skip
    vx3, vy3, w3 = vx + hdt * a2x, vy + hdt * a2y, w + hdt * a2w
    q3 = q + hdt * w2
    a3x, a3y, a3w = _accel_held(math.sin(q3), math.cos(q3), y + hdt * vy2, vx3, vy3, w3,
                                inv_m, inv_i, half, length, c_d, c_h, c_v, lam, g, hx, hy,
                                hc)  # fmt: skip
    vx4, vy4, w4 = vx + dt * a3x, vy + dt * a3y, w + dt * a3w
    q4 = q + dt * w3
    a4x, a4y, a4w = _accel_held(math.sin(q4), math.cos(q4), y + dt * vy3, vx4, vy4, w4, inv_m,
                                inv_i, half, length, c_d, c_h, c_v, lam, g, hx, hy, hc)  # fmt: skip
    s6 = dt / 6.0
    return (
        x + s6 * (vx + 2.0 * vx2 + 2.0 * vx3 + vx4),
        y + s6 * (vy + 2.0 * vy2 + 2.0 * vy3 + vy4),
        q + s6 * (w + 2.0 * w2 + 2.0 * w3 + w4),
        vx + s6 * (a1x + 2.0 * a2x + 2.0 * a3x + a4x),
        vy + s6 * (a1y + 2.0 * a2y + 2.0 * a3y + a4y),
        w + s6 * (a1w + 2.0 * a2w + 2.0 * a3w + a4w),
    )


@njit
def impact_scalar(y0, p, dt, t_end):
    """The same RK4 and stop as :func:`impact_user`, all in scalars: one sin/cos pair and
    one pow per evaluation (the stop check reuses the next step's first sine and cosine)."""
    k = _constants(p)
    inv_m, inv_i, half, length, c_d, c_h, c_v, lam, g = k
    x, y, q, vx, vy, w = y0[0], y0[1], y0[2], y0[3], y0[4], y0[5]
    s, c = math.sin(q), math.cos(q)
    h_prev = y - half * c
    vt_prev = vy + half * w * s
    n_max = math.ceil(t_end / dt)
    for i in range(n_max):
        a1x, a1y, a1w = _accel(s, c, y, vx, vy, w, inv_m, inv_i, half, length, c_d, c_h, c_v,
                               lam, g)  # fmt: skip
        x, y, q, vx, vy, w = _rk4(x, y, q, vx, vy, w, s, c, a1x, a1y, a1w, dt, k, PLAIN, PLAIN,
                                  PLAIN)  # fmt: skip
        s, c = math.sin(q), math.cos(q)
        h_tip = y - half * c
        vt = vy + half * w * s
        if vt >= 0.0:
            theta = -vt_prev / (vt - vt_prev)
            height = h_prev + theta * (h_tip - h_prev)
            return (i + theta) * dt, max(0.0, -height), i + 1
        h_prev, vt_prev = h_tip, vt
    return np.nan, max(0.0, -h_prev), n_max


@njit
def libm_floor(n, q, depth, lam):
    """``n`` evaluations' calls into the C library alone, as :func:`impact_scalar` makes them
    (a sine and a cosine of an angle, the pow of a depth): the angle and depth step on by a
    little each time, so that no call waits for another. Their cost at full throughput: a
    floor under any loop that makes them, however well its own work hides behind them.
    Returns a value that depends on every call (so that none is dropped)."""
    acc = 0.0
    for i in range(n):
        s, c = math.sin(q + 1e-7 * i), math.cos(q + 1e-7 * i)
        acc += math.pow(depth + 1e-9 * i, lam) + s * c
    return acc


@njit(inline="always")
def _hermite(theta, dt, u0, du0, u1, du1):
    """The cubic Hermite interpolant of one step at ``theta`` in [0, 1]."""
    t2 = theta * theta
    t3 = t2 * theta
    return ((2.0 * t3 - 3.0 * t2 + 1.0) * u0 + (t3 - 2.0 * t2 + theta) * dt * du0
            + (-2.0 * t3 + 3.0 * t2) * u1 + (t3 - t2) * dt * du1)  # fmt: skip


@njit
def impact_located(y0, p, dt, t_end, hold=False):
    """:func:`impact_scalar` with granrs's stop: the tip's vertical velocity located on the
    step's cubic Hermite interpolant (through both ends and their derivatives, the end's
    being the next step's first stage) by Illinois regula falsi to 1e-13 of the step, and
    the depth read at the end of a real step of the located length. With ``hold``, the
    signs of v_Ex, v_Ey and e x v_E are held through each step at their values at its
    start (granrs's ``"modes"``), so that the last step's stages see the force law of the
    motion that the stop ends; a sign that changes inside a step is not located (it takes
    effect at the next step), nor are the kinks of l = min(d / cos q, L) and of the exit,
    nor sticking (granrs's other events)."""
    k = _constants(p)
    inv_m, inv_i, half, length, c_d, c_h, c_v, lam, g = k
    x, y, q, vx, vy, w = y0[0], y0[1], y0[2], y0[3], y0[4], y0[5]
    s, c = math.sin(q), math.cos(q)
    a1x, a1y, a1w = _accel(s, c, y, vx, vy, w, inv_m, inv_i, half, length, c_d, c_h, c_v,
                           lam, g)  # fmt: skip
    vt_prev = vy + half * w * s
    n_max = math.ceil(t_end / dt)
    for i in range(n_max):
        # The signs held through the step: those at its start (e x v_E's: + at zero).
        d = half * c - y
        ell = length if d >= length * c else d / c
        s_e = 0.5 * (ell - length)
        vex, vey = vx + w * s_e * c, vy - w * s_e * s
        hx, hy = _held(vex, PLAIN), _held(vey, PLAIN)
        hc = -1.0 if s * vey - c * vex < 0.0 else 1.0
        if hold:
            a1x, a1y, a1w = _accel_held(s, c, y, vx, vy, w, inv_m, inv_i, half, length, c_d,
                                        c_h, c_v, lam, g, hx, hy, hc)  # fmt: skip
        else:
            hx = hy = hc = PLAIN
        x1, y1, q1, vx1, vy1, w1 = _rk4(x, y, q, vx, vy, w, s, c, a1x, a1y, a1w, dt, k, hx, hy,
                                        hc)  # fmt: skip
        s1, c1 = math.sin(q1), math.cos(q1)
        b1x, b1y, b1w = _accel_held(s1, c1, y1, vx1, vy1, w1, inv_m, inv_i, half, length, c_d,
                                    c_h, c_v, lam, g, hx, hy, hc)  # fmt: skip
        vt = vy1 + half * w1 * s1
        if vt >= 0.0:
            # g(theta) = -v_Ty >= 0 before the stop; Illinois on [0, 1].
            a, fa, b, fb = 0.0, -vt_prev, 1.0, -vt
            side = 0
            for _ in range(200):
                if b - a <= 1e-13:
                    break
                th = (a * fb - b * fa) / (fb - fa) if fa != fb else 0.5 * (a + b)
                if not (a < th < b):
                    th = 0.5 * (a + b)
                qt = _hermite(th, dt, q, w, q1, w1)
                vyt = _hermite(th, dt, vy, a1y, vy1, b1y)
                wt = _hermite(th, dt, w, a1w, w1, b1w)
                f = -(vyt + half * wt * math.sin(qt))
                if f < 0.0:
                    b, fb = th, f
                    if side == -1:
                        fa *= 0.5
                    side = -1
                else:
                    a, fa = th, f
                    if side == 1:
                        fb *= 0.5
                    side = 1
                if f == 0.0:
                    b = th
                    break
            # As granrs: a real step of the located length from the step's start.
            _, ys, qs, _, _, _ = _rk4(x, y, q, vx, vy, w, s, c, a1x, a1y, a1w, b * dt, k, hx,
                                      hy, hc)  # fmt: skip
            return (i + b) * dt, max(0.0, -(ys - half * math.cos(qs))), i + 1
        x, y, q, vx, vy, w = x1, y1, q1, vx1, vy1, w1
        s, c, a1x, a1y, a1w = s1, c1, b1x, b1y, b1w
        vt_prev = vt
    return np.nan, max(0.0, -(y - half * c)), n_max


@njit(parallel=True)
def batch_scalar(y0s, ps, dt, t_end, out):
    """:func:`impact_scalar` over many scenes, one per iteration of a ``prange`` (a perfectly
    parallel loop: no shared state); the depths into ``out``."""
    for i in prange(y0s.shape[0]):
        out[i] = impact_scalar(y0s[i], ps[i], dt, t_end)[1]


class IvpBudgetError(Exception):
    """A solve_ivp run passed ``IVP_MAX_NFEV`` evaluations."""


def make_ivp(
    p: np.ndarray, budget: bool = True
) -> tuple[Callable[..., list[float]], Callable[..., float]]:
    """solve_ivp's right-hand side and stop event (plain Python, ``math``), user style."""
    m, inertia, length, dc, rho, g, eta_h, eta_d, eta_v, lam = (float(v) for v in p)

    calls = [0]

    def rhs(t: float, y: np.ndarray) -> list[float]:
        if budget:
            calls[0] += 1
            if calls[0] > IVP_MAX_NFEV:
                raise IvpBudgetError
        q, vx, vy, w = y[2], y[3], y[4], y[5]
        s, c = math.sin(q), math.cos(q)
        d = max(0.0, -(y[1] - 0.5 * length * c))
        fx = fy = torque = 0.0
        if d > 0.0:
            ell = length if d >= length * c else d / c
            s_e = -0.5 * length + 0.5 * ell
            vex, vey = vx + w * s_e * c, vy - w * s_e * s
            k = eta_d * rho * dc * ell * abs(s * vey - c * vex)
            f_h = eta_h * g * rho * dc * d**2
            f_v = eta_v * (d / length) ** lam * g * rho * (math.pi / 4 * dc**2 * ell)
            fx = -k * vex - np.sign(vex) * f_h
            fy = -k * vey - np.sign(vey) * f_v
            torque = -0.5 * length * (c * fx - s * fy)
        return [vx, vy, w, fx / m, fy / m - g, torque / inertia]

    def stop(t: float, y: np.ndarray) -> float:
        return y[4] + 0.5 * length * y[5] * math.sin(y[2])

    stop.terminal = True  # type: ignore[attr-defined]
    stop.direction = 1.0  # type: ignore[attr-defined]
    return rhs, stop


def impact_ivp(
    y0: np.ndarray, p: np.ndarray, rtol: float, budget: bool = True
) -> tuple[float, float, int]:
    """solve_ivp (RK45) to the stop: (t_s, depth, rhs evaluations); NaNs when it fails
    (no stop by ``T_END``, or more than ``IVP_MAX_NFEV`` evaluations)."""
    rhs, stop = make_ivp(p, budget)
    try:
        sol = solve_ivp(
            rhs, (0.0, T_END), y0, method="RK45", rtol=rtol, atol=ATOL_FACTOR * rtol, events=stop
        )
    except IvpBudgetError:
        return math.nan, math.nan, IVP_MAX_NFEV
    if sol.status != 1 or len(sol.t_events[0]) == 0:
        return math.nan, math.nan, int(sol.nfev)
    ye = sol.y_events[0][0]
    depth = max(0.0, -(ye[1] - 0.5 * float(p[2]) * math.cos(ye[2])))
    return float(sol.t_events[0][0]), depth, int(sol.nfev)


# --- the run ------------------------------------------------------------------------------


@dataclass
class SceneRun:
    """One Table 3.5 scene: its inputs and every method's depth and best time."""

    q_deg: float
    v0: float
    scene: granrs.Scene
    p: np.ndarray
    y0: np.ndarray
    depth: dict[str, float] = field(default_factory=dict)
    seconds: dict[str, float] = field(default_factory=dict)
    depth_ref: float = math.nan
    err_granrs: float = math.nan
    err_granrs_raw: float = math.nan
    rtol: float = math.nan
    err_ivp: float = math.nan
    ivp_matched: bool = False
    ivp_failed: bool = False
    ivp_nfev: int = 0
    #: Evaluations of one impact: ``numba_scalar``'s (four per step) and granrs's.
    evals_scalar: int = 0
    evals_granrs: int = 0


def build(quick: bool) -> list[SceneRun]:
    """The Table 3.5 scenes (all 31, or the ``QUICK_ROWS``)."""
    table = granrs.data.load("table_3_5", as_="numpy")
    runs = []
    for q, v0 in zip(table["q_deg"], table["v0"], strict=True):
        if quick and (float(q), float(v0)) not in QUICK_ROWS:
            continue
        scene = granrs.cases.free_link(float(q), float(v0))
        runs.append(SceneRun(float(q), float(v0), scene, parameters(scene), initial_state(scene)))
    return runs


def rft_laws() -> dict[str, list[granrs.forces.Term]]:
    """The ``rft`` laws timed against the thesis's, by key suffix: ``zeta = 1e6`` and the
    ``zeta`` fitted to Table 3.1 (the ``thesis_sand`` card's)."""
    fitted = granrs.media.load("thesis_sand").value("rft.zeta").value
    rft = granrs.forces.rft
    return {
        "rft": [granrs.forces.gravity(), rft(zeta=1e6)],
        "rft_fitted": [granrs.forces.gravity(), rft(zeta=fitted)],
    }


def granrs_result(scene: granrs.Scene) -> granrs.Result:
    r = granrs.simulate(scene)
    if r.status != "stopped":
        raise RuntimeError(f"q = {scene.q_deg}, v0 = {scene.v0}: {r.status}")
    return r


def granrs_depth(scene: granrs.Scene) -> float:
    return float(granrs_result(scene).depth)


def check_agreement(runs: list[SceneRun]) -> float:
    """Depths of the peers against granrs ``"raw"``; raises if any is off by more than
    ``AGREEMENT_TOL``. Returns the largest difference [m]."""
    worst = 0.0
    for r in runs:
        raw = r.depth["granrs_raw"]
        for name in ("numba_user", "numba_scalar", "numba_located"):
            diff = abs(r.depth[name] - raw)
            worst = max(worst, diff)
            if not diff <= AGREEMENT_TOL:
                raise AssertionError(
                    f"{name} computes a different model: q = {r.q_deg}, v0 = {r.v0}: depth "
                    f"{r.depth[name]!r} against granrs raw {raw!r}"
                )
    return worst


def match_tolerance(runs: list[SceneRun], ref_dt: float, progress: bool) -> None:
    """Reference depths, granrs's error, and solve_ivp's matched rtol per scene."""
    for r in runs:
        r.depth_ref = granrs_depth(r.scene.replace(dt=ref_dt))
        r.err_granrs = abs(r.depth["granrs"] - r.depth_ref)
        r.err_granrs_raw = abs(r.depth["granrs_raw"] - r.depth_ref)
        errs = []
        for rtol in RTOLS:
            _, depth, _ = impact_ivp(r.y0, r.p, rtol)
            errs.append(abs(depth - r.depth_ref) if math.isfinite(depth) else math.inf)
        # The loosest rtol from which on every tighter one also meets granrs's error; else
        # the most accurate one that ran (unmatched); none ran: failed, not timed.
        ok = [e <= r.err_granrs for e in errs]
        idx = next((i for i in range(len(RTOLS)) if all(ok[i:])), None)
        r.ivp_matched = idx is not None
        if idx is None and any(math.isfinite(e) for e in errs):
            idx = min(range(len(RTOLS)), key=lambda i: errs[i])
        r.ivp_failed = idx is None
        if idx is not None:
            r.rtol, r.err_ivp = RTOLS[idx], errs[idx]
        if progress:
            note = " (FAILED at every rtol)" if r.ivp_failed else ""
            note = note or ("" if r.ivp_matched else " (NOT matched within the sweep)")
            print(
                f"  q = {r.q_deg:4.0f}, v0 = {r.v0:5.3f}: granrs error {r.err_granrs:.2e} m, "
                f"solve_ivp rtol {r.rtol:.0e} error {r.err_ivp:.2e} m{note}",
                file=sys.stderr,
            )


def methods(runs: list[SceneRun]) -> dict[str, Callable[[SceneRun], Any]]:
    """Name -> one impact of a scene (what is timed)."""
    raw = {id(r): r.scene.replace(sign_model="raw") for r in runs}
    lean = {id(r): r.scene.replace(outputs=LEAN_OUTPUTS) for r in runs}
    rft = {
        key: {id(r): r.scene.replace(forces=law) for r in runs} for key, law in rft_laws().items()
    }
    for scene in [*raw.values(), *lean.values(), *(s for d in rft.values() for s in d.values())]:
        scene._compiled()  # compiled once here, as the default scenes are, not in the timing
    return {
        "granrs": lambda r: granrs.simulate(r.scene),
        "granrs_rft": lambda r: granrs.simulate(rft["rft"][id(r)]),
        "granrs_rft_fitted": lambda r: granrs.simulate(rft["rft_fitted"][id(r)]),
        "granrs_rft_core": lambda r: _granrs.run(rft["rft"][id(r)]._compiled()).run_seconds,
        "granrs_rft_fitted_core": lambda r: (
            _granrs.run(rft["rft_fitted"][id(r)]._compiled()).run_seconds
        ),
        "granrs_lean": lambda r: granrs.simulate(lean[id(r)]),
        "granrs_raw": lambda r: granrs.simulate(raw[id(r)]),
        # The run alone, as the core times it (no Python around it), in the same loop.
        "granrs_core": lambda r: _granrs.run(r.scene._compiled()).run_seconds,
        "numba_user": lambda r: impact_user(r.y0, r.p, DT, T_END),
        "numba_scalar": lambda r: impact_scalar(r.y0, r.p, DT, T_END),
        "numba_located": lambda r: impact_located(r.y0, r.p, DT, T_END),
        # The loop's library calls alone, at the scene's angle, half its depth and lambda.
        "libm_floor": lambda r: libm_floor(
            r.evals_scalar, math.radians(r.q_deg), 0.5 * r.depth["numba_scalar"], r.p[9]
        ),
        # Timed without the evaluation budget (the matched rtol is known to run).
        "solve_ivp": lambda r: impact_ivp(r.y0, r.p, r.rtol, budget=False),
    }


def time_all(runs: list[SceneRun], repeats: int, ivp_repeats: int) -> None:
    """Best time per scene and method; the methods take turns within each repeat. Each
    method's pass starts with one untimed call (solve_ivp's aside, seconds long): the code
    the method before it ran has evicted this one's from the caches, which cost the first
    scene of every pass (Table 3.5's 0 deg, 2.214 m/s) about 40 us more in granrs's column."""
    todo = methods(runs)
    for rep in range(repeats):
        for name, fn in todo.items():
            if name == "solve_ivp" and rep >= ivp_repeats:
                continue
            if name != "solve_ivp":
                fn(runs[0])
            for r in runs:
                if name == "solve_ivp" and r.ivp_failed:
                    r.seconds[name] = math.nan
                    continue
                if name.endswith("_core"):
                    dt = fn(r)
                else:
                    t0 = time.perf_counter()
                    fn(r)
                    dt = time.perf_counter() - t0
                r.seconds[name] = min(r.seconds.get(name, math.inf), dt)


def time_sweeps(runs: list[SceneRun], repeats: int, copies: int) -> dict[str, float]:
    """Per impact [s]: ``granrs.sweep`` over the scenes (each ``copies`` times) on one and on
    two threads, and the scalar numba loop over the same scenes in a ``prange`` on one and
    on two threads (a perfectly parallel loop: the ceiling of what two cores give). The four
    take turns within each repeat; each keeps its best."""
    scenes = [r.scene for r in runs] * copies
    y0s = np.array([r.y0 for r in runs] * copies)
    ps = np.array([r.p for r in runs] * copies)
    out = np.empty(len(scenes))
    batch_scalar(y0s[:1], ps[:1], DT, T_END, out[:1])  # compile

    lean = [s.replace(outputs=LEAN_OUTPUTS) for s in scenes[: len(runs)]] * copies
    rft = {
        key: [s.replace(forces=law) for s in scenes[: len(runs)]] * copies
        for key, law in rft_laws().items()
    }

    def sweep(threads: int, lanes: bool = True) -> None:
        granrs.sweep(scenes, threads=threads, progress=False, lanes=lanes)

    def sweep_lean(threads: int) -> None:
        granrs.sweep(lean, threads=threads, progress=False)

    def in_prange(threads: int) -> None:
        set_num_threads(threads)
        batch_scalar(y0s, ps, DT, T_END, out)

    todo = {
        "sweep_1": lambda: sweep(1),
        "sweep_2": lambda: sweep(2),
        "sweep_scalar_1": lambda: sweep(1, lanes=False),
        "sweep_scalar_2": lambda: sweep(2, lanes=False),
        "sweep_lean_1": lambda: sweep_lean(1),
        "sweep_lean_2": lambda: sweep_lean(2),
        "sweep_rft_1": lambda: granrs.sweep(rft["rft"], threads=1, progress=False),
        "sweep_rft_fitted_1": lambda: granrs.sweep(rft["rft_fitted"], threads=1, progress=False),
        "numba_parallel_1": lambda: in_prange(1),
        "numba_parallel_2": lambda: in_prange(2),
    }
    best = dict.fromkeys(todo, math.inf)
    for _ in range(repeats):
        for name, fn in todo.items():
            t0 = time.perf_counter()
            fn()
            best[name] = min(best[name], time.perf_counter() - t0)
    set_num_threads(numba.config.NUMBA_NUM_THREADS)  # type: ignore[attr-defined]
    return {k: v / len(scenes) for k, v in best.items()}


#: Step sizes [s] of the work-precision figure's fixed-step methods, and solve_ivp's rtols.
WP_DTS = (4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5)
WP_RTOLS = (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)


@dataclass
class WorkPoint:
    """One method at one setting: its depth error (median and largest over the scenes [m])
    and its time per impact (mean over the scenes of the best per scene [s])."""

    method: str
    setting: str
    err_median: float
    err_max: float
    seconds: float


def work_precision(runs: list[SceneRun], repeats: int) -> list[WorkPoint]:
    """Every peer at several step sizes (solve_ivp: tolerances): error against time."""
    # Each scene at each step is built here, outside the timing, as the numba peers' arrays
    # are: a scene built inside the timed call added its construction (about 35 us) to
    # granrs's points. Like every peer, each keeps its best of the repeats. The step's check
    # is off: it times the run alone, as the peers' (at dt = 4e-4, 2 of the 31 impacts under
    # "modes" read step_error 2e-5, above the check's 1e-5, and would be run again).
    at_dt = {
        (i, dt, sign): r.scene.replace(dt=dt, sign_model=sign, step_check=False)
        for i, r in enumerate(runs)
        for dt in WP_DTS
        for sign in ("modes", "raw")
    }
    fixed: dict[str, Callable[[int, float], float]] = {
        "granrs": lambda i, dt: float(granrs.simulate(at_dt[i, dt, "modes"]).depth),
        "granrs_raw": lambda i, dt: float(granrs.simulate(at_dt[i, dt, "raw"]).depth),
        "numba_user": lambda i, dt: impact_user(runs[i].y0, runs[i].p, dt, T_END)[1],
        "numba_scalar": lambda i, dt: impact_scalar(runs[i].y0, runs[i].p, dt, T_END)[1],
        "numba_located": lambda i, dt: impact_located(runs[i].y0, runs[i].p, dt, T_END)[1],
        "numba_held": lambda i, dt: impact_located(runs[i].y0, runs[i].p, dt, T_END, True)[1],
    }
    points = []

    def measure(method: str, setting: str, fn: Callable[[int], float], reps: int) -> None:
        errs, secs = [], []
        for i, r in enumerate(runs):
            best = math.inf
            depth = math.nan
            for _ in range(reps):
                t0 = time.perf_counter()
                depth = fn(i)
                best = min(best, time.perf_counter() - t0)
            errs.append(abs(depth - r.depth_ref) if math.isfinite(depth) else math.inf)
            secs.append(best)
        points.append(
            WorkPoint(method, setting, statistics.median(errs), max(errs), statistics.fmean(secs))
        )

    for method, fn in fixed.items():
        for dt in WP_DTS:
            measure(method, f"dt={dt:g}", lambda i, fn=fn, dt=dt: fn(i, dt), repeats)
    for rtol in WP_RTOLS:
        measure(
            "solve_ivp",
            f"rtol={rtol:g}",
            lambda i, rtol=rtol: impact_ivp(runs[i].y0, runs[i].p, rtol)[1],
            1,
        )
    return points


def work_precision_lines(points: list[WorkPoint]) -> list[str]:
    """The work-precision points as a Markdown table."""
    lines = [
        "",
        "Work-precision: depth error against granrs at the reference step (median and largest "
        "over the scenes) and time per impact (mean over the scenes of the best per scene).",
        "",
        "| method | setting | error median [m] | error max [m] | us / impact |",
        "|---|---|---:|---:|---:|",
    ]
    for p in points:
        lines.append(
            f"| {p.method} | {p.setting} | {p.err_median:.1e} | {p.err_max:.1e} | "
            f"{p.seconds * 1e6:.1f} |"
        )
    return lines


def plot_work_precision(points: list[WorkPoint], path: Path) -> None:
    """Error against time per impact, one line per method: the median over the scenes
    (left) and the largest (right: a method that is accurate on most scenes but not on
    the vertical drops or the rows that stick shows there)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 5), sharex=True)
    floor = 1e-13  # an exact hit plots at the floor
    for ax, attr, what in ((axes[0], "err_median", "median"), (axes[1], "err_max", "largest")):
        for method in dict.fromkeys(p.method for p in points):
            pts = [p for p in points if p.method == method and math.isfinite(getattr(p, attr))]
            ax.loglog(
                [p.seconds * 1e6 for p in pts],
                [max(getattr(p, attr), floor) for p in pts],
                "o-",
                label=method,
            )
        ax.set_xlabel("time per impact [us] (mean over the scenes of the best per scene)")
        ax.set_ylabel(f"depth error [m] ({what} over the scenes)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend()
    fig.suptitle("Work-precision, Table 3.5 free-link impacts")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run_criterion(quick: bool) -> dict[str, float]:
    """Per-impact medians [s] of criterion's ``impact/table_3_5_all`` (``"modes"``) and
    ``impact/table_3_5_all_raw`` (``"raw"``); empty if cargo is missing or it fails."""
    if shutil.which("cargo") is None:
        print("cargo not found: no Rust-only timing", file=sys.stderr)
        return {}
    secs = "1" if quick else "3"
    cmd = [
        "cargo",
        "bench",
        "--bench",
        "free_link",
        "--",
        "impact/table_3_5_all",
        "--warm-up-time",
        "1",
        "--measurement-time",
        secs,
    ]
    print("running: " + " ".join(cmd), file=sys.stderr)
    proc = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        print(proc.stderr[-2000:], file=sys.stderr)
        return {}
    out = {}
    n_rows = len(granrs.data.load("table_3_5", as_="numpy")["q_deg"])
    for bench, key in (("table_3_5_all", "rust"), ("table_3_5_all_raw", "rust_raw")):
        path = REPO / "target" / "criterion" / "impact" / bench / "new" / "estimates.json"
        if path.is_file():
            median = json.loads(path.read_text())["median"]["point_estimate"]
            out[key] = median * 1e-9 / n_rows
    return out


def per_impact(runs: list[SceneRun], name: str) -> float:
    """Mean over the scenes of the best time per impact [s]."""
    return statistics.fmean(r.seconds[name] for r in runs)


def summarize(
    runs: list[SceneRun],
    crit: dict[str, float],
    sweeps: dict[str, float],
    agreement: float,
    copies: int = SWEEP_COPIES,
) -> list[str]:
    """The report, as lines of Markdown."""
    t = {name: per_impact(runs, name) for name in runs[0].seconds}
    t.update(sweeps)
    # solve_ivp over the scenes where it ran, against granrs on the same scenes.
    ran = [r for r in runs if not r.ivp_failed]
    t["solve_ivp"] = per_impact(ran, "solve_ivp") if ran else math.nan
    t["granrs_ivp_scenes"] = per_impact(ran, "granrs") if ran else math.nan
    t.update(crit)
    us = {k: v * 1e6 for k, v in t.items()}
    ivp_ratios = [r.seconds["solve_ivp"] / r.seconds["granrs"] for r in ran] or [math.nan]
    lines = [
        f"granrs {granrs.__version__}, {len(runs)} Table 3.5 scenes, dt = {DT:g} s; per impact, "
        "single thread, mean over scenes of the best time per scene; a sweep runs the scenes "
        f"{copies} times ({copies * len(runs)} runs).",
        "",
        "| method | us / impact | / granrs (modes, simulate) |",
        "|---|---:|---:|",
    ]
    labels = {
        "granrs": 'granrs.simulate, sign_model="modes" (default)',
        "granrs_lean": 'granrs.simulate, outputs=("depth", "t_s")',
        "granrs_rft": "granrs.simulate, rft (zeta 1e6)",
        "granrs_rft_fitted": "granrs.simulate, rft (zeta fitted to Table 3.1)",
        "granrs_rft_core": "granrs rft (zeta 1e6), the run alone (timed in the core)",
        "granrs_rft_fitted_core": "granrs rft (zeta fitted), the run alone (timed in the core)",
        "granrs_raw": 'granrs.simulate, sign_model="raw"',
        "granrs_core": "granrs modes, the run alone (timed in the core, same loop)",
        "rust": "granrs modes, Rust only (criterion impact/table_3_5_all)",
        "rust_raw": "granrs raw, Rust only (criterion impact/table_3_5_all_raw)",
        "numba_user": "numba RK4, user style (arrays)",
        "numba_scalar": "numba RK4, hand-tuned scalars",
        "numba_located": "numba RK4, hand-tuned scalars, stop located as granrs does",
        "libm_floor": "floor: the hand-tuned loop's sin/cos and pow calls alone",
        "solve_ivp": "scipy solve_ivp RK45, matched rtol",
        "sweep_1": "granrs.sweep, SIMD lanes, 1 thread (per impact)",
        "sweep_2": "granrs.sweep, SIMD lanes, 2 threads (per impact)",
        "sweep_scalar_1": "granrs.sweep, scalar path (lanes=False), 1 thread (per impact)",
        "sweep_scalar_2": "granrs.sweep, scalar path (lanes=False), 2 threads (per impact)",
        "sweep_lean_1": 'granrs.sweep, SIMD lanes, outputs=("depth", "t_s"), 1 thread',
        "sweep_lean_2": 'granrs.sweep, SIMD lanes, outputs=("depth", "t_s"), 2 threads',
        "sweep_rft_1": "granrs.sweep, SIMD lanes, rft (zeta 1e6), 1 thread",
        "sweep_rft_fitted_1": "granrs.sweep, SIMD lanes, rft (zeta fitted), 1 thread",
        "numba_parallel_1": "numba scalars in a prange, 1 thread (per impact)",
        "numba_parallel_2": "numba scalars in a prange, 2 threads (per impact)",
    }
    for key, label in labels.items():
        if key in us:
            lines.append(f"| {label} | {us[key]:.1f} | {t[key] / t['granrs']:.3g} |")
    lines += ["", "| ratio | value | target | met |", "|---|---:|---:|---|"]

    def ratio(name: str, num: str, den: str, target: float | None, below: bool) -> None:
        if num not in t or den not in t:
            return
        v = t[num] / t[den]
        if target is None:
            lines.append(f"| {name} | {v:.3g} | | |")
        else:
            met = v <= target if below else v >= target
            sign = "<=" if below else ">="
            lines.append(f"| {name} | {v:.3g} | {sign} {target:.3g} | {'yes' if met else 'NO'} |")

    ratio("granrs (simulate) / numba user", "granrs", "numba_user", TARGET_NUMBA, True)
    ratio("granrs raw (simulate) / numba user", "granrs_raw", "numba_user", TARGET_NUMBA, True)
    ratio("granrs run alone / numba user", "granrs_core", "numba_user", TARGET_NUMBA, True)
    ratio("granrs Rust only (criterion) / numba user", "rust", "numba_user", TARGET_NUMBA, True)
    ratio("granrs (simulate), default summary / numba scalar", "granrs", "numba_scalar",
          TARGET_SCALAR_DEFAULT, True)  # fmt: skip
    ratio('granrs (simulate), outputs=("depth", "t_s") / numba scalar', "granrs_lean",
          "numba_scalar", TARGET_SCALAR_LEAN, True)  # fmt: skip
    ratio('granrs sweep (lanes), outputs=("depth", "t_s"), 1 thread / numba scalar',
          "sweep_lean_1", "numba_scalar", None, True)  # fmt: skip
    ratio('granrs sweep lanes, outputs=("depth", "t_s") / all columns, 1 thread',
          "sweep_lean_1", "sweep_1", None, True)  # fmt: skip
    ratio("granrs run alone / numba scalar", "granrs_core", "numba_scalar", None, True)
    ratio("granrs sweep (lanes) 1 thread / numba scalar", "sweep_1", "numba_scalar",
          TARGET_SWEEP, True)  # fmt: skip
    ratio("granrs sweep (lanes) 1 thread / numba prange 1 thread", "sweep_1",
          "numba_parallel_1", TARGET_SWEEP, True)  # fmt: skip
    ratio("granrs sweep (scalar) 1 thread / numba scalar", "sweep_scalar_1", "numba_scalar",
          None, True)  # fmt: skip
    ratio("granrs sweep lanes / scalar, 1 thread", "sweep_1", "sweep_scalar_1", None, True)
    ratio("granrs sweep lanes / scalar, 2 threads", "sweep_2", "sweep_scalar_2", None, True)
    for suffix, label in (("", "lanes"), ("_scalar", "scalar")):
        one, two = f"sweep{suffix}_1", f"sweep{suffix}_2"
        if all(k in t for k in (one, two, "numba_parallel_1", "numba_parallel_2")):
            ours = t[one] / t[two]
            theirs = t["numba_parallel_1"] / t["numba_parallel_2"]
            lines.append(
                f"| sweep ({label}) speed-up 1 -> 2 threads ({ours:.2f}x) / numba prange's "
                f"({theirs:.2f}x) | {ours / theirs:.3g} | >= {TARGET_SCALING:g} | "
                f"{'yes' if ours / theirs >= TARGET_SCALING else 'NO'} |"
            )
    for key, zeta in (("rft", "1e6"), ("rft_fitted", "fitted to Table 3.1")):
        ratio(f"granrs (simulate) rft, zeta {zeta} / thesis", f"granrs_{key}", "granrs",
              TARGET_RFT_SIMULATE, True)  # fmt: skip
        ratio(f"granrs sweep (lanes) 1 thread, rft, zeta {zeta} / thesis", f"sweep_{key}_1",
              "sweep_1", TARGET_RFT_SWEEP, True)  # fmt: skip
        ratio(f"granrs run alone, rft, zeta {zeta} / thesis (no step check)",
              f"granrs_{key}_core", "granrs_core", None, True)  # fmt: skip
    ratio("granrs Rust only / numba scalar", "rust", "numba_scalar", None, True)
    ratio("granrs raw Rust only / numba scalar", "rust_raw", "numba_scalar", None, True)
    ratio("solve_ivp / granrs (simulate), mean over the scenes it ran", "solve_ivp",
          "granrs_ivp_scenes", None, False)  # fmt: skip
    # Faster than solve_ivp at matched accuracy on every scene: the smallest ratio >= 1.
    low = min(ivp_ratios)
    lines.append(
        f"| solve_ivp / granrs per scene at matched accuracy: min, median | {low:.3g}, "
        f"{statistics.median(ivp_ratios):.3g} | min >= {TARGET_SOLVE_IVP:g} | "
        f"{'yes' if low >= TARGET_SOLVE_IVP else 'NO'} |"
    )
    lines += targets_left(runs, us)
    unmatched = sum(not r.ivp_matched and not r.ivp_failed for r in runs)
    failed = sum(r.ivp_failed for r in runs)
    lines += [
        "",
        f"Depth agreement (same model): max |depth(numba) - depth(granrs raw)| = "
        f"{agreement:.2e} m (accepted up to {AGREEMENT_TOL:g} m).",
        f"Matched rtol: median {statistics.median(r.rtol for r in ran) if ran else math.nan:.0e}; "
        f"{unmatched} scene(s) not matched within 1e-3..1e-12 (timed at their most accurate "
        f"rtol, marked *); solve_ivp FAILED on {failed} scene(s) at every rtol (no stop within "
        f"{IVP_MAX_NFEV} evaluations; not timed, marked !).",
        "",
        "| q_deg | v0 | depth_ref [m] | err granrs | err granrs raw | err numba user | "
        "err numba located | rtol | err solve_ivp | granrs us | raw us | numba user us | "
        "numba scalar us | numba located us | solve_ivp us |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in runs:
        s = {k: v * 1e6 for k, v in r.seconds.items()}
        lines.append(
            f"| {r.q_deg:g} | {r.v0:g} | {r.depth_ref:.6f} | {r.err_granrs:.1e} | "
            f"{r.err_granrs_raw:.1e} | {abs(r.depth['numba_user'] - r.depth_ref):.1e} | "
            f"{abs(r.depth['numba_located'] - r.depth_ref):.1e} | "
            f"{r.rtol:.0e}{'!' if r.ivp_failed else '' if r.ivp_matched else '*'} | "
            f"{r.err_ivp:.1e} | "
            f"{s['granrs']:.0f} | {s['granrs_raw']:.0f} | {s['numba_user']:.0f} | "
            f"{s['numba_scalar']:.0f} | {s['numba_located']:.0f} | {s['solve_ivp']:.0f} |"
        )
    return lines


def targets_left(runs: list[SceneRun], us: dict[str, float]) -> list[str]:
    """What the ``simulate`` and sweep targets leave granrs once the calls into the C library
    are paid (``libm_floor``: the loop's sin/cos and pow calls at full throughput, the same
    calls granrs makes once per evaluation): each side's own work and waiting per impact and
    per evaluation, as lines of Markdown."""
    if "libm_floor" not in us:
        return []
    n_loop = statistics.fmean(r.evals_scalar for r in runs)
    n_granrs = statistics.fmean(r.evals_granrs for r in runs)
    per_call = 1e3 * us["libm_floor"] / n_loop  # ns per evaluation's calls

    def own(key: str, evals: float) -> float:
        """``key``'s time per impact above its evaluations' calls [us]."""
        return us[key] - per_call * evals / 1e3

    loop_own, granrs_own = own("numba_scalar", n_loop), own("granrs", n_granrs)
    sweep_budget = 1e3 * TARGET_SWEEP * us["numba_scalar"] / n_granrs
    lines = [
        "",
        "What the targets leave: the calls into the C library (one sin/cos pair and one pow "
        "per evaluation, at full throughput: the floor above) against each side's own work "
        "and waiting.",
        "",
        "| | value |",
        "|---|---:|",
        f"| evaluations per impact: hand-tuned loop, granrs | {n_loop:.0f}, {n_granrs:.0f} |",
        f"| the calls, ns per evaluation | {per_call:.1f} |",
        f"| the loop's own, us per impact (ns per evaluation) | {loop_own:.1f} "
        f"({1e3 * loop_own / n_loop:.1f}) |",
        f"| granrs.simulate's own, us per impact (ns per evaluation) | {granrs_own:.1f} "
        f"({1e3 * granrs_own / n_granrs:.1f}) |",
        f"| granrs.simulate's own / the loop's own | {granrs_own / loop_own:.2g}x |",
    ]
    if "granrs_lean" in us:
        # The lean line's budget: what is left of TARGET_SCALAR_LEAN x the loop once
        # granrs's own evaluations' calls are paid.
        budget = TARGET_SCALAR_LEAN * us["numba_scalar"] - per_call * n_granrs / 1e3
        lines.append(
            f'| simulate asking for ("depth", "t_s") <= {TARGET_SCALAR_LEAN:g} x the loop: '
            f"granrs's own may take, us per impact (it takes) | {budget:.1f} "
            f"({own('granrs_lean', n_granrs):.1f}) |"
        )
    if "granrs_raw" in us and "numba_located" in us:
        raw_own, located_own = own("granrs_raw", n_granrs), own("numba_located", n_loop)
        lines.append(
            "| the same at the same accuracy: granrs raw's own / the located loop's own | "
            f"{raw_own / located_own:.2g}x |"
        )
    lines += [
        f"| sweep <= {TARGET_SWEEP:.2g} x the loop: ns per scene evaluation, all included | "
        f"{sweep_budget:.1f} |",
        "| of which the calls take, one lane at a time (the lanes' results are the scalar "
        f"path's bit for bit) | {per_call:.1f} |",
    ]
    return lines


def write_out(path: Path, runs: list[SceneRun], lines: list[str]) -> None:
    """Markdown report (``.md``) or one CSV row per scene (anything else)."""
    if path.suffix == ".md":
        path.write_text("\n".join(lines) + "\n")
        return
    import csv

    with path.open("w", newline="") as f:
        w = csv.writer(f)
        names = sorted(runs[0].seconds)
        w.writerow(
            ["q_deg", "v0", "depth_ref", "rtol", "ivp_matched", "err_granrs", "err_granrs_raw"]
            + [f"depth_{k}" for k in sorted(runs[0].depth)]
            + ["err_solve_ivp"]
            + [f"seconds_{k}" for k in names]
        )
        for r in runs:
            w.writerow(
                [r.q_deg, r.v0, r.depth_ref, r.rtol, r.ivp_matched, r.err_granrs]
                + [r.err_granrs_raw]
                + [r.depth[k] for k in sorted(r.depth)]
                + [r.err_ivp]
                + [r.seconds[k] for k in names]
            )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="5 scenes, coarser reference")
    parser.add_argument("--repeats", type=int, default=None, help="timing repeats")
    parser.add_argument("--out", type=Path, default=None, help="write .md or .csv results")
    parser.add_argument("--no-criterion", action="store_true", help="skip cargo bench")
    parser.add_argument(
        "--figure",
        type=Path,
        default=REPO / "bench-out" / "peers_work_precision.png",
        help="where to write the work-precision figure (PNG)",
    )
    parser.add_argument("--no-figure", action="store_true", help="skip the work-precision runs")
    parser.add_argument(
        "--sweep-copies",
        type=int,
        default=SWEEP_COPIES,
        help=f"copies of the scenes in one timed sweep (default {SWEEP_COPIES})",
    )
    args = parser.parse_args(argv)
    repeats = args.repeats or (3 if args.quick else 7)
    runs = build(args.quick)

    # Depths of every method (and the numba compile: the warm-up call).
    for r in runs:
        result = granrs_result(r.scene)
        r.depth["granrs"] = float(result.depth)
        r.evals_granrs = int(result.summary["rhs_evals"]) + int(result.summary["root_evals"])
        r.depth["granrs_raw"] = granrs_depth(r.scene.replace(sign_model="raw"))
        r.depth["numba_user"] = impact_user(r.y0, r.p, DT, T_END)[1]
        _, r.depth["numba_scalar"], steps = impact_scalar(r.y0, r.p, DT, T_END)
        r.evals_scalar = 4 * int(steps)
        r.depth["numba_located"] = impact_located(r.y0, r.p, DT, T_END)[1]
    agreement = check_agreement(runs)
    print("matching solve_ivp's tolerance to granrs's depth error ...", file=sys.stderr)
    match_tolerance(runs, REFERENCE_DT_QUICK if args.quick else REFERENCE_DT, progress=True)
    print(f"timing ({repeats} repeats) ...", file=sys.stderr)
    time_all(runs, repeats, ivp_repeats=min(repeats, 3))
    print("timing sweeps ...", file=sys.stderr)
    sweeps = time_sweeps(runs, SWEEP_REPEATS * repeats, args.sweep_copies)
    crit = {} if args.no_criterion else run_criterion(args.quick)
    lines = summarize(runs, crit, sweeps, agreement, args.sweep_copies)
    if not args.no_figure:
        print("work-precision runs ...", file=sys.stderr)
        points = work_precision(runs, min(repeats, 3))
        lines += work_precision_lines(points)
        args.figure.parent.mkdir(parents=True, exist_ok=True)
        plot_work_precision(points, args.figure)
        lines += ["", f"Work-precision figure: {args.figure}"]
    print("\n".join(lines))
    if args.out is not None:
        write_out(args.out, runs, lines)
    return 0


if __name__ == "__main__":
    sys.exit(main())
