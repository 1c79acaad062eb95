"""Properties of the physics over the whole valid domain (issue 6), with hypothesis.

The domain: angle in (-90, 90) deg, v0 in [0, 10] m/s (plus a sideways speed and a spin,
to break the symmetry), coefficients from 0 to 10x the thesis's Table 3.4 at q = 0
(eta_h 6.5, eta_d 15.2, eta_v 248, lambda 0.106), masses from 1 g to 100 kg, dt from 1e-6
to 1e-3 s, every sign model. A run is capped at 2e4 steps (t_end = min(0.3 s, 2e4 dt)) so
that the suite stays fast; a run cut short says "not_stopped", which is one of the outcomes
checked.

What MODEL.md guarantees holds only where the step resolves the contact: a fixed-step
explicit RK4 is stable only while dt is below about 2.8 / (the contact's fastest rate), and
the domain reaches far past that (a 1 g rod with 10x coefficients at dt = 1e-3).
:func:`step_resolves` estimates the rate from the scene and calls a scene resolved when
dt x rate <= 0.5. Asserted:

- on resolved scenes: the run ends with finite numbers (or the typed SimulationError),
  depth >= 0, no force while the tip is above the surface; each term's power on the
  immersed centroid E is <= 0 at every recorded point (every sign model, both points of
  application); with the force at E and the sign modes or the smooth sign, KE + PE never
  rises;
- over the whole domain: mirror symmetry to 1e-12; each term's power <= 0 with the plain
  and the smooth sign (their sign is the velocity's at the point);
- outside the resolved domain a run can return huge or infinite numbers with status
  "stopped" instead of failing: pinned as strict xfails with their reproducers.

With the force at the tip T nothing bounds the energy: the work is done at the tip's
velocity, not at v_E. It is measured (:func:`tip_energy_rise`; docs/hard_cases.md), not
bounded here.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import granrs
from granrs import Coefficients, Result, Scene
from granrs.forces import thesis, thesis_row

#: Table 3.4 at q = 0: the scale of the coefficients (the domain is 0..10x these).
SCALE = {"eta_h": 6.5, "eta_d": 15.2, "eta_v": 248.0, "lam": 0.106}
SIGN_MODELS = ("modes", "raw", "smooth")
MAX_STEPS = 2e4
RECORD = ("state", "forces", "energy")
FORCES = ("F_dx", "F_dy", "F_sh", "F_sv")
#: Derandomized: CI draws the same examples every run (a failure found by a random run
#: becomes a pinned reproducer below, not a flaky CI).
SETTINGS = settings(
    max_examples=60,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)


def t_end_for(dt: float) -> float:
    return min(0.3, MAX_STEPS * dt)


def rates(scene: Scene) -> tuple[float, float]:
    """Upper estimates of the contact's fastest rates [1/s] for the free link: the drag's,
    4 eta_d rho d_c L v / m (the 4: a force at the tip of a rod with I = m L^2 / 12 moves
    the tip 4x as fast as the centre), and the static terms', sqrt(4 k / m) with k their
    stiffness in depth: eta_v g rho (pi d_c^2/4) (1 + lambda) / cos q + 2 eta_h g rho d_c L.
    v is the largest speed the rod can have: the initial one plus a fall of L. With the
    ``smooth`` sign, tanh(v / eps) adds the rate 4 F_s / (m eps) near rest, F_s the largest
    static force: that of the spring k that absorbs all the energy, sqrt(2 k E)."""
    c = thesis_row(scene.forces)
    v = math.hypot(scene.v0, scene.vx0) + abs(scene.omega0) * scene.length
    v += math.sqrt(2.0 * scene.g * scene.length)
    drag = 4.0 * c.eta_d * scene.rho_g * scene.diameter * scene.length * v / scene.mass
    area = math.pi * scene.diameter**2 / 4.0
    cos_q = max(math.cos(math.radians(scene.q_deg)), 1e-3)
    k = c.eta_v * scene.g * scene.rho_g * area * (1.0 + c.lam) / cos_q
    k += 2.0 * c.eta_h * scene.g * scene.rho_g * scene.diameter * scene.length
    static = math.sqrt(4.0 * k / scene.mass)
    if scene.sign_model == "smooth":
        # The largest static force: a spring of stiffness k absorbing all the energy.
        force = math.sqrt(
            2.0 * k * (0.5 * scene.mass * v * v + scene.mass * scene.g * scene.length)
        )
        static = max(static, 4.0 * force / (scene.mass * scene.smooth_eps))
    return drag, static


def step_resolves(scene: Scene, limit: float = 0.5) -> bool:
    """Whether dt is below ``limit`` / (the fastest rate): a fifth of RK4's stability limit
    (2.8). Measured on 1200 random scenes: above 0.15 energy rose by more than 1e-6 of the
    scale; at or below 1, only with the plain sign (``raw``)."""
    return scene.dt * max(rates(scene)) <= limit


@st.composite
def scenes(
    draw: st.DrawFn,
    apply_at: tuple[str, ...] = ("tip", "centroid"),
    sign_models: tuple[str, ...] = SIGN_MODELS,
    resolved: bool = False,
) -> Scene:
    """A random valid free-link scene of the domain (see the module docstring)."""
    coefficients = Coefficients(
        **{k: v * draw(st.floats(0.0, 10.0)) for k, v in SCALE.items()}  # 0..10x
    )
    scene = Scene(
        q_deg=draw(st.floats(-89.99, 89.99)),
        v0=draw(st.floats(0.0, 10.0)),
        vx0=draw(st.one_of(st.just(0.0), st.floats(-2.0, 2.0))),
        omega0=draw(st.one_of(st.just(0.0), st.floats(-20.0, 20.0))),
        mass=10.0 ** draw(st.floats(-3.0, 2.0)),
        forces=thesis(coefficients),
        apply_at=draw(st.sampled_from(apply_at)),
        sign_model=draw(st.sampled_from(sign_models)),
        dt=1e-4,
    )
    if resolved:
        # The largest step that resolves the contact, times a fraction; within 1e-6..1e-3.
        rate = max(rates(scene))
        bound = 0.5 / rate if rate > 0.0 else math.inf
        dt = min(1e-3, bound * draw(st.floats(0.01, 1.0)))
        assume(dt >= 1e-6)
    else:
        dt = 10.0 ** draw(st.floats(-6.0, -3.0))
    return scene.replace(dt=dt, t_end=t_end_for(dt))


def energy_rise(energy: np.ndarray) -> float:
    """The largest rise of a recorded energy above its running minimum [J]."""
    return float(np.max(energy - np.minimum.accumulate(energy)))


def energy_scale(scene: Scene, r: Result) -> float:
    """The energy the run has to lose or gain [J]: its start plus m g L (PE is measured
    from the surface, so E itself may pass through 0)."""
    return abs(r.summary["energy_start"]) + scene.mass * scene.g * scene.length


def simulate_or_fail(scene: Scene) -> Result | None:
    """The run, or None if it raised the typed SimulationError (a non-finite state)."""
    try:
        return granrs.simulate(scene)
    except granrs.SimulationError:
        return None


def check_finite(r: Result) -> None:
    """Finite summary; NaN only where it means "never": t_s without a stop, t_entry for a
    tip that never entered the sand (thrown up or spun out of it at the surface)."""
    assert r.status in ("stopped", "not_stopped"), r.status
    for key, value in r.summary.items():
        if key == "t_s" and not r.stopped:
            continue
        if key == "t_entry" and math.isnan(value) and not r.stopped and r.depth == 0.0:
            continue
        if isinstance(value, float):
            assert math.isfinite(value), (key, value)
    assert r.depth >= 0.0


# ---------------------------------------------------------------------------------------
# The whole domain


# Resolved here means the step resolves the contact's stiffness (step_resolves); a stop
# that falls between two steps (a spinning tip that only grazes the sand) still warns,
# which is right and not what this property is about.
@pytest.mark.filterwarnings("ignore::granrs.StepSizeWarning")
@SETTINGS
@given(scenes(resolved=True))
def test_finite_or_typed_error_and_no_force_above_the_surface(scene: Scene) -> None:
    """A valid scene whose step resolves the contact ends with finite results (t_s NaN only
    without a stop) or with SimulationError; depth >= 0 throughout; every force column is
    0 where the tip is above the surface (tip_y > 0). Over the whole domain (unresolved
    steps too) this does not hold: see test_sweep_of_random_scenes_whole_domain."""
    r = simulate_or_fail(scene.replace(record=RECORD))
    if r is None:
        return
    check_finite(r)
    s = r.series
    assert s is not None
    assert np.all(s["depth"] >= 0.0)
    above = s["tip_y"] > 0.0
    for name in FORCES:
        assert np.all(np.isfinite(s[name]))
        assert np.all(s[name][above] == 0.0), name


def _mirror_close(a: float, b: float) -> bool:
    return abs(a + b) <= 1e-12 * max(abs(a), abs(b)) or (math.isnan(a) and math.isnan(b))


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-12 * max(abs(a), abs(b)) or (math.isnan(a) and math.isnan(b))


@SETTINGS
@given(scenes(resolved=True))
def test_mirror_symmetry(scene: Scene) -> None:
    """(q, vx0, omega0) -> -(q, vx0, omega0) gives -(x_tip_end, dq, omega_end) and the same
    depth, t_s and energies, to 1e-12 relative (MODEL.md "Exact answers"), on resolved
    scenes (bit for bit in every run seen). A scene that fails fails mirrored too. Past
    the stability limit a blowing-up run and its mirror can part: see the next test."""
    mirrored = scene.replace(q_deg=-scene.q_deg, vx0=-scene.vx0, omega0=-scene.omega0)
    a, b = simulate_or_fail(scene), simulate_or_fail(mirrored)
    assert (a is None) == (b is None)
    if a is None or b is None:
        return
    assert a.status == b.status
    for key in ("x_tip_end", "dq", "omega_end"):
        assert _mirror_close(a.summary[key], b.summary[key]), (key, a.summary[key], b.summary[key])
    for key in ("depth", "t_s", "dE", "energy_end", "t_final"):
        assert _same(a.summary[key], b.summary[key]), (key, a.summary[key], b.summary[key])


#: Found by test_mirror_symmetry over the whole domain: a 10 g rod with drag only, spun
#: (omega0 = 15 rad/s) at dt = 1e-3 s, flips over and re-enters the sand at t = 0.1916 s.
MIRROR_PARTS = Scene(
    q_deg=1.5,
    v0=0.0,
    omega0=15.0,
    mass=0.01,
    dt=1e-3,
    t_end=0.3,
    forces=thesis(Coefficients(eta_h=0.0, eta_d=15.2, eta_v=0.0, lam=0.0)),
)


@pytest.mark.filterwarnings("ignore::granrs.StepSizeWarning")
def test_mirror_symmetry_past_the_stability_limit() -> None:
    """MIRROR_PARTS (drag only, 10 g, dt = 1e-3: not resolved) and its mirror (q_deg=-1.5,
    omega0=-15.0): the rod spins past horizontal and re-enters with its tip T at t =
    0.1916 s, where l jumps to L. Both runs must mirror each other. They did not: at depth
    0 the drag's sign of e x v_E was not evaluated, so both entered with the mode "+"; the
    mirrored run then had negative drag for a step and diverged while the other stopped.
    At dt = 1e-5 both agree as mirrors (x_tip_end +-0.20603 m)."""
    assert not step_resolves(MIRROR_PARTS)
    a = simulate_or_fail(MIRROR_PARTS)
    b = simulate_or_fail(MIRROR_PARTS.replace(q_deg=-1.5, omega0=-15.0))
    assert a is not None and b is not None
    for key in ("x_tip_end", "dq", "omega_end"):
        assert _mirror_close(a.summary[key], b.summary[key]), (key, a.summary[key], b.summary[key])


# ---------------------------------------------------------------------------------------
# Force at the centroid: strictly dissipative


def powers(r: Result) -> tuple[dict[str, np.ndarray], dict[str, float]]:
    """Each term's power on the immersed centroid at every recorded point, in units of the
    run's largest |F| |v_E| (so that a run that blew up to huge finite values does not
    overflow), and its tolerance in the same units.

    The tolerance: where a term's sign (or the drag's kink |e x v_E|) switches, the mode is
    held through the step up to the located root, where the switching function is 0 only to
    the root finder's tolerance, so a term may point the wrong way by that residual
    and the step's interpolant differs from the step's end by its own error (measured, on
    the resolved domain: up to 1.0e-6 of the term's peak at dt = 1e-3). Allow 1e-5 of the
    term's largest |F| |v_E| over the run, and 1e-12 W."""
    s = r.series
    assert s is not None
    f_scale = max(float(np.max(np.abs(s[name]), initial=0.0)) for name in FORCES) or 1.0
    vx, vy = s["v_E_x"], s["v_E_y"]
    v_scale = float(np.max(np.hypot(vx, vy), initial=0.0)) or 1.0
    f = {name: s[name] / f_scale for name in FORCES}
    vx, vy = vx / v_scale, vy / v_scale
    speed = np.hypot(vx, vy)
    p = {
        "drag": f["F_dx"] * vx + f["F_dy"] * vy,
        "static_h": f["F_sh"] * vx,
        "static_v": f["F_sv"] * vy,
    }
    peaks = {
        "drag": np.hypot(f["F_dx"], f["F_dy"]) * speed,
        "static_h": np.abs(f["F_sh"]) * speed,
        "static_v": np.abs(f["F_sv"]) * speed,
    }
    floor = 1e-12 / (f_scale * v_scale)
    tol = {name: 1e-5 * float(np.max(peak, initial=0.0)) + floor for name, peak in peaks.items()}
    return p, tol


# Resolved here means the step resolves the contact's stiffness (step_resolves); a stop
# that falls between two steps (a spinning tip that only grazes the sand) still warns,
# which is right and not what this property is about.
@pytest.mark.filterwarnings("ignore::granrs.StepSizeWarning")
@SETTINGS
@given(scenes(resolved=True))
def test_each_force_term_does_non_positive_power(scene: Scene) -> None:
    """F_d . v_E <= 0, F_sh v_Ex <= 0 and F_sv v_Ey <= 0 at every recorded point, every sign
    model, both points of application (where the force is applied does not change the
    force, only where it works), where the step resolves the contact. With the sign modes,
    past the step's resolution the mode located on the step's interpolant can disagree
    with the sign at the step's end by the interpolation error (found: 2e-6 of the peak
    power at dt x rate = 1.2), so the unresolved domain is checked for the plain and
    smooth signs only (next test)."""
    r = simulate_or_fail(scene.replace(record=RECORD))
    if r is None:
        return
    p, tol = powers(r)
    for name, values in p.items():
        assert np.all(values <= tol[name]), (name, float(np.max(values - tol[name])))


@pytest.mark.filterwarnings("ignore::granrs.StepSizeWarning")
@SETTINGS
@given(scenes(sign_models=("raw", "smooth")))
def test_each_force_term_does_non_positive_power_whole_domain(scene: Scene) -> None:
    """With the plain and the smooth sign the sign is that of the velocity at the point, so
    each term's power is <= 0 at every recorded point over the whole domain, to rounding
    (1e-12 of the run's peak |F| |v_E|)."""
    r = simulate_or_fail(scene.replace(record=RECORD))
    if r is None:
        return
    p, _ = powers(r)
    for name, values in p.items():
        assert np.all(values <= 1e-12), (name, float(np.max(values)))


ENERGY_RTOL = 1e-8


@SETTINGS
@given(scenes(apply_at=("centroid",), sign_models=("modes", "smooth"), resolved=True))
def test_centroid_energy_never_rises(scene: Scene) -> None:
    """With the force at E, KE + PE is non-increasing at every recorded point, to 1e-8 of the
    energy scale, where the step resolves the contact (measured: at most 2.8e-15 on 1056
    random resolved scenes with the sign modes or the smooth sign)."""
    r = granrs.simulate(scene.replace(record=RECORD))
    check_finite(r)
    assert r.series is not None
    energy = r.series["E"]
    rise = energy_rise(energy)
    assert rise <= ENERGY_RTOL * energy_scale(scene, r), (rise, energy_scale(scene, r))


#: Found by test_centroid_energy_never_rises (random run, 2026-11-22): horizontal static
#: term only, a 10 g rod thrown sideways; E sticks in x and the static force spins the rod
#: up to 15.5 rad/s; at dt = 1e-3 s the energy jumps by 1.8e-8 J (5.5e-7 of the scale) at
#: t = 0.1635 s, where the rod becomes fully immersed (l = L) and E stops sliding along it.
STUCK_AND_SPINNING = Scene(
    q_deg=7.0,
    v0=0.0,
    vx0=-1.0,
    mass=0.01,
    forces=thesis(Coefficients(eta_h=6.5, eta_d=0.0, eta_v=0.0, lam=0.0)),
    apply_at="centroid",
    dt=1e-3,
    t_end=0.3,
)


def test_centroid_energy_stuck_and_spinning() -> None:
    """simulate(STUCK_AND_SPINNING): KE + PE must not rise by more than 1e-8 of the energy
    scale (the step resolves the contact by the domain's rule). It rose by 5.5e-7 while the
    full-immersion event was located on the step's interpolant (24 us late at dt = 1e-3, past
    the kink of l = min(d / cos q, L), where the projection no longer caught the drift of
    v_Ex); on the RK4 map the largest rise is 1.9e-12 J per step (measured), O(dt^5)."""
    assert step_resolves(STUCK_AND_SPINNING)
    r = granrs.simulate(STUCK_AND_SPINNING.replace(record=RECORD))
    assert r.series is not None
    energy = r.series["E"]
    rise = energy_rise(energy)
    assert rise <= ENERGY_RTOL * energy_scale(STUCK_AND_SPINNING, r), rise


def test_centroid_energy_with_the_plain_sign_rises_by_chatter() -> None:
    """The plain sign (``raw``) is not held through a step: where v_E crosses 0 inside a
    step, RK4's stages see both signs, and KE + PE can rise by a first-order amount even at
    E. Measured on the resolved domain: up to 8.9e-5 of the energy scale. Pinned as a
    measurement (the sign modes are the fix), on a deterministic sample."""
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(150):
        scene = random_scene(rng, apply_at="centroid", sign_model="raw")
        if not step_resolves(scene):
            continue
        r = granrs.simulate(scene.replace(record=("energy",)))
        energy = r.series["E"] if r.series is not None else np.zeros(1)
        rise = energy_rise(energy)
        worst = max(worst, rise / energy_scale(scene, r))
    assert math.isfinite(worst)
    assert worst < 1e-3  # first order in dt: far above the modes' 1e-8, far below 1


def test_centroid_energy_never_rises_unresolved_step() -> None:
    """Minimal reproducer found by the property search: outside step_resolves the run must
    not gain energy (or must raise SimulationError)."""
    scene = Scene(
        q_deg=88.84340374264745,
        v0=7.003627951620519,
        vx0=1.6382063709534989,
        mass=0.009301677090852944,
        dt=0.00042469238738902614,
        t_end=0.3,
        apply_at="centroid",
        forces=thesis(
            Coefficients(
                eta_h=58.36127622830018,
                eta_d=150.37275349570797,
                eta_v=827.4179780793743,
                lam=0.49665650686981155,
            )
        ),
        record=("energy",),
    )
    assert not step_resolves(scene)
    r = simulate_or_fail(scene)
    if r is None:
        return
    assert r.series is not None
    energy = r.series["E"]
    rise = energy_rise(energy)
    assert rise <= ENERGY_RTOL * energy_scale(scene, r)


# ---------------------------------------------------------------------------------------
# Force at the tip: measured, not bounded


def random_scene(rng: np.random.Generator, **fixed: Any) -> Scene:
    """A random valid free-link scene of the domain, from a seeded numpy generator (the
    same distribution as :func:`scenes` without hypothesis's shrinking)."""
    dt = 10.0 ** rng.uniform(-6.0, -3.0)
    fields: dict[str, Any] = {
        "q_deg": rng.uniform(-89.99, 89.99),
        "v0": rng.uniform(0.0, 10.0),
        "vx0": rng.uniform(-2.0, 2.0) if rng.random() < 0.5 else 0.0,
        "omega0": rng.uniform(-20.0, 20.0) if rng.random() < 0.5 else 0.0,
        "mass": 10.0 ** rng.uniform(-3.0, 2.0),
        "forces": thesis(Coefficients(**{k: v * rng.uniform(0, 10) for k, v in SCALE.items()})),
        "sign_model": SIGN_MODELS[int(rng.integers(3))],
        "dt": dt,
        "t_end": t_end_for(dt),
    }
    fields.update(fixed)
    return Scene(**fields)


def tip_energy_rise(
    n: int, seed: int = 0, resolved: bool = True, sign_model: str | None = None
) -> dict[str, Any]:
    """Over ``n`` random scenes with the force at the tip: the largest rise of KE + PE above
    its running minimum and above its start, relative to the energy scale, and the scene
    that gave it. ``resolved`` keeps only scenes whose step resolves the contact."""
    rng = np.random.default_rng(seed)
    worst: dict[str, Any] = {"rise": 0.0, "above_start": 0.0, "scene": None, "runs": 0}
    rising = 0
    while worst["runs"] < n:
        scene = random_scene(rng, apply_at="tip", record=("energy",))
        if sign_model is not None:
            scene = scene.replace(sign_model=sign_model)
        if resolved and not step_resolves(scene):
            continue
        r = simulate_or_fail(scene)
        if r is None or r.series is None:
            continue
        worst["runs"] += 1
        energy = r.series["E"]
        scale = energy_scale(scene, r)
        rise = energy_rise(energy) / scale
        above = float(np.max(energy) - energy[0]) / scale
        rising += rise > ENERGY_RTOL
        if rise > worst["rise"]:
            worst.update(rise=rise, scene=scene)
        worst["above_start"] = max(worst["above_start"], above)
    worst["fraction_rising"] = rising / n
    return worst


#: Found by tip_energy_rise(1000, seed=1, sign_model="modes"): the largest rise.
TIP_INJECTS = Scene(
    q_deg=-2.1015010473137465,
    v0=2.272504878144944,
    vx0=-1.1657921361209196,
    mass=10.873012299341996,
    dt=0.00044981417675368194,
    t_end=0.3,
    forces=thesis(
        Coefficients(
            eta_h=35.91637436940101,
            eta_d=4.9463052993698655,
            eta_v=51.9281928100492,
            lam=0.05800022960674102,
        )
    ),
    record=("energy",),
)


def test_tip_application_can_inject_energy() -> None:
    """With the force at the tip, KE + PE can rise (MODEL.md: "at T it need not be"
    dissipative): a 10.9 kg rod nearly vertical, thrown sideways, gains about a tenth of its
    energy scale while it sinks (E rises above its running minimum by 0.1 x (E_0 + m g L)).
    The size of the rise over the domain is measured by :func:`tip_energy_rise` (see
    docs/hard_cases.md), not bounded here. The same scene at E never gains energy."""
    assert step_resolves(TIP_INJECTS)
    at_tip = granrs.simulate(TIP_INJECTS)
    at_e = granrs.simulate(TIP_INJECTS.replace(apply_at="centroid"))
    rises = []
    for r in (at_tip, at_e):
        assert r.series is not None
        energy = r.series["E"]
        rises.append(energy_rise(energy))
    assert rises[0] > 0.01 * energy_scale(TIP_INJECTS, at_tip), rises
    assert rises[1] <= ENERGY_RTOL * energy_scale(TIP_INJECTS, at_e), rises


@pytest.mark.slow
def test_measure_tip_energy_injection() -> None:
    """The figure of docs/hard_cases.md (``pytest -m slow -s -k tip_energy``)."""
    for resolved in (True, False):
        found = tip_energy_rise(2000, seed=1, resolved=resolved)
        s = found["scene"]
        print(
            f"\nresolved={resolved}: runs {found['runs']}, "
            f"rising {found['fraction_rising']:.3f}, "
            f"max rise / scale {found['rise']:.3g}, max above start / scale "
            f"{found['above_start']:.3g}"
        )
        if s is not None:
            print(
                f"  worst: q_deg={s.q_deg!r}, v0={s.v0!r}, vx0={s.vx0!r}, omega0={s.omega0!r}, "
                f"mass={s.mass!r}, dt={s.dt!r}, sign_model={s.sign_model!r}, "
                f"coefficients={thesis_row(s.forces)}"
            )


# ---------------------------------------------------------------------------------------
# Many scenes at once through the sweep


def check_sweep(scenes_: list[Scene]) -> None:
    """Run the scenes through granrs.sweep: no NaN or infinity in any run that did not fail,
    failures only with their message, depth >= 0, a stopped run has its t_s; at the centroid
    (sign modes or smooth, resolving step) the energy at the end is at most the start's."""
    df = granrs.sweep(scenes_, progress=False)
    assert len(df) == len(scenes_)
    failed = (df["status"] == "failed").to_numpy()
    if failed.any():
        assert df.loc[failed, "error"].notna().all()
    ok = df[~failed]
    numeric = ok.drop(columns=["status", "t_s", "t_entry", "error"], errors="ignore")
    finite = np.isfinite(numeric.select_dtypes("number").to_numpy()).all(axis=1)
    # t_entry is NaN only for a tip that never entered (depth 0, no stop).
    never = ok["t_entry"].isna()
    assert ((ok.loc[never, "depth"] == 0.0) & ~ok.loc[never, "stopped"]).all()
    assert finite.all(), [scenes_[i] for i in np.flatnonzero(~failed)[~finite][:2]]
    assert (ok["depth"] >= 0.0).all()
    assert set(ok["status"]) <= {"stopped", "not_stopped"}
    assert ok.loc[ok["status"] == "stopped", "t_s"].notna().all()
    for i, scene in enumerate(scenes_):
        if scene.apply_at != "centroid" or failed[i] or scene.sign_model == "raw":
            continue
        if not step_resolves(scene):
            continue
        row = df.iloc[i]
        scale = abs(row["energy_start"]) + scene.mass * scene.g * scene.length
        assert row["energy_end"] <= row["energy_start"] + ENERGY_RTOL * scale, (i, scene)


def test_sweep_of_random_scenes() -> None:
    """1500 random scenes of the domain whose step resolves the contact, through
    granrs.sweep (both points of application, every sign model): see check_sweep."""
    rng = np.random.default_rng(2024)
    chosen: list[Scene] = []
    while len(chosen) < 1500:
        scene = random_scene(rng, apply_at=("tip", "centroid")[len(chosen) % 2])
        if step_resolves(scene):
            chosen.append(scene)
    check_sweep(chosen)


#: Found by the whole-domain sweep (seed 2024, run 500): a 5 g rod at 79 deg, coefficients
#: 1.8x-9.6x Table 3.4, dt = 3.1e-4 s (far past RK4's stability limit), plain sign, force
#: at the tip.
BLOWS_UP_TO_INF = Scene(
    q_deg=79.44290744893819,
    v0=3.356644858166582,
    vx0=-0.4701871515831888,
    mass=0.0049748411465528495,
    dt=0.0003108636710855665,
    t_end=0.3,
    sign_model="raw",
    forces=thesis(
        Coefficients(
            eta_h=39.627668521544585,
            eta_d=146.26441509520092,
            eta_v=116.62286464761162,
            lam=0.6619883229043338,
        )
    ),
)

WHOLE_DOMAIN_REASON = (
    "past RK4's stability limit a run can blow up to huge finite states without raising "
    "SimulationError: it returns status 'stopped' with F_d_max = F_r_end = inf and depth "
    "~1.7e42 m (1 of 1500 random scenes of the whole domain, seed 2024, run 500; "
    "reproducer BLOWS_UP_TO_INF; 20 others fail cleanly with SimulationError)"
)


def test_sweep_of_random_scenes_whole_domain() -> None:
    """The same 1500 scenes as the domain draws them, unresolved steps included: every run
    must be finite or fail with its message (a 'failed' row), never return inf."""
    rng = np.random.default_rng(2024)
    scenes = [random_scene(rng, apply_at=("tip", "centroid")[i % 2]) for i in range(1500)]
    # Some of these steps do not resolve their contact: the sweep must say so.
    with pytest.warns(granrs.StepSizeWarning, match="did not resolve their contact"):
        check_sweep(scenes)


def test_blow_up_is_reported_not_returned() -> None:
    """Minimal reproducer: simulate(BLOWS_UP_TO_INF) must return finite numbers or raise
    SimulationError."""
    assert not step_resolves(BLOWS_UP_TO_INF)
    r = simulate_or_fail(BLOWS_UP_TO_INF)
    if r is None:
        return
    check_finite(r)
