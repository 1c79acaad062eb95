"""Tests of the public Python API: granrs.simulate, Scene, Result.

Expected numbers never come from the code under test: the vertical drop's depth is solved
here from the energy balance of MODEL.md ("Exact answers") with the thesis's constants
written out below; energies are recomputed from the recorded state with the rod's mass and
inertia; the mirror image of a run is compared with the run.
"""

from __future__ import annotations

import contextlib
import io
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import granrs
from granrs import Coefficients, Result
from granrs.errors import UnknownNameError

# The thesis's free link (sec. 3.2.1), its sand (sec. 3.3.1) and Table 3.4 row q = 0,
# written out independently of the package.
LENGTH = 0.190
DIAMETER = 0.0127
MASS = 0.184
RHO_G = 1650.0
G = 9.81
ETA_H_0, ETA_D_0, ETA_V_0, LAMBDA_0 = 6.5, 15.2, 248.0, 0.106

SUMMARY_KEYS = (
    "t_s",
    "depth",
    "dq",
    "omega_end",
    "F_d_max",
    "F_s_end",
    "F_r_end",
    "dKE",
    "dPE",
    "dE",
    "steps",
    "rhs_evals",
)

#: A few scenes covering the cases a user meets first: the thesis rows at 45 and 0 degrees,
#: a negative angle, a near-grazing rod, a slow drop, and the force at the centroid.
SCENES = {
    "q45_v2.27": lambda: granrs.cases.free_link(45, 2.27),
    "vertical_v2.214": lambda: granrs.cases.free_link(0, 2.214),
    "q-30_v1.5": lambda: granrs.cases.free_link(-30, 1.5),
    "q85_v1.787": lambda: granrs.cases.free_link(85, 1.787),
    "q15_v0.3": lambda: granrs.cases.free_link(15, 0.3),
    "q45_centroid": lambda: granrs.cases.free_link(45, 2.27, apply_at="centroid"),
}

RECORD_ALL = ("state", "forces", "energy")


def rel(a: float, b: float) -> float:
    """Relative difference of a from b."""
    return abs(a - b) / abs(b)


def exact_vertical_depth(v0: float) -> float:
    """Final depth of the vertical rod, force at the tip (MODEL.md "Exact answers"):
    (1/2) m v0^2 + m g d = eta_v g rho (pi d_c^2/4) d^(lambda+2) / (L^lambda (lambda+2)),
    solved by bisection (the right side minus the left is negative, then increasing)."""
    k = ETA_V_0 * G * RHO_G * math.pi * DIAMETER**2 / 4.0 / (LENGTH**LAMBDA_0 * (LAMBDA_0 + 2.0))

    def f(d: float) -> float:
        return k * d ** (LAMBDA_0 + 2.0) - 0.5 * MASS * v0 * v0 - MASS * G * d

    lo, hi = 0.0, 1.0
    while f(hi) < 0.0:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if f(mid) < 0.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@pytest.fixture(scope="module", params=sorted(SCENES))
def run(request: pytest.FixtureRequest) -> Result:
    """Each scene of SCENES, recorded in full."""
    scene = SCENES[request.param]().replace(record=RECORD_ALL)
    return granrs.simulate(scene)


# ---------------------------------------------------------------------------------------
# Result and summary


def test_result_fields_and_summary_are_finite(run: Result) -> None:
    """A stopped run has every documented summary key, each a finite number."""
    assert isinstance(run, Result)
    assert run.status == "stopped"
    assert run.stopped
    assert len(run.contacts) == 1
    for key in SUMMARY_KEYS:
        assert key in run.summary, key
        value = run.summary[key]
        assert isinstance(value, (int, float)) and not isinstance(value, bool), (key, value)
        assert math.isfinite(value), (key, value)
    assert run.t_s == run.summary["t_s"] > 0.0
    assert run.depth == run.summary["depth"] > 0.0
    assert run.summary["steps"] > 0
    assert run.summary["rhs_evals"] >= 4 * run.summary["steps"]
    assert run.summary["F_d_max"] >= 0.0
    assert run.summary["F_s_end"] >= 0.0
    assert run.summary["F_r_end"] >= 0.0
    assert run.contacts[0].t_s == run.t_s
    assert run.contacts[0].depth == run.depth
    assert run.contacts[0].stopped


def test_energy_bookkeeping(run: Result) -> None:
    """dE = dKE + dPE, and dE equals minus the sand's work, an independent quadrature of
    the sand's power integrated alongside the state: a real energy balance."""
    s = run.summary
    assert s["dE"] == pytest.approx(s["dKE"] + s["dPE"], rel=1e-12, abs=1e-15)
    assert math.isfinite(s["work_sand"])
    assert rel(s["dE"], -s["work_sand"]) <= 1e-6, (s["dE"], s["work_sand"])


def test_energy_from_recorded_state(run: Result) -> None:
    """dKE and dPE of the summary agree with the energies recomputed here from the recorded
    start and stop state, with m and the solid-cylinder inertia m (L^2/12 + d_c^2/16)."""
    scene, series = run.scene, run.series
    assert series is not None
    inertia = scene.mass * (scene.length**2 / 12.0 + scene.diameter**2 / 16.0)

    def ke(i: int) -> float:
        v2 = series["vx"][i] ** 2 + series["vy"][i] ** 2
        return 0.5 * scene.mass * v2 + 0.5 * inertia * series["omega"][i] ** 2

    def pe(i: int) -> float:
        return scene.mass * scene.g * series["y"][i]

    # The start: tip at the surface moving straight down at v0, no spin.
    assert ke(0) == pytest.approx(0.5 * scene.mass * scene.v0**2, rel=1e-12)
    assert series["y"][0] == pytest.approx(0.5 * scene.length * math.cos(scene.q_rad), rel=1e-12)
    assert run.summary["dKE"] == pytest.approx(ke(0) - ke(-1), rel=1e-9, abs=1e-12)
    assert run.summary["dPE"] == pytest.approx(pe(0) - pe(-1), rel=1e-9, abs=1e-12)


def test_series_consistent(run: Result) -> None:
    """Recorded columns have one length, t increases strictly, the last t is the stop, and
    the last recorded depth is the result's depth."""
    series = run.series
    assert series is not None
    t = series["t"]
    for name, column in series.items():
        assert isinstance(column, np.ndarray), name
        assert column.shape == t.shape, name
        assert np.all(np.isfinite(column)), name
    assert t[0] == 0.0
    assert np.all(np.diff(t) > 0.0)
    assert t[-1] == run.t_s
    assert series["depth"][-1] == run.depth
    # The depth column is the tip's: max(0, -y_tip).
    np.testing.assert_array_equal(series["depth"], np.maximum(0.0, -series["tip_y"]))
    for name in ("x", "y", "q", "vx", "vy", "omega", "F_dx", "F_dy", "F_sh", "F_sv", "KE", "PE"):
        assert name in series, name


def test_record_stride_keeps_the_end() -> None:
    """With a stride, fewer rows are stored and the stop is still the last one."""
    full = granrs.simulate(granrs.cases.free_link(45, 2.27, record=("state",)))
    strided = granrs.simulate(granrs.cases.free_link(45, 2.27, record=("state",), record_stride=10))
    assert full.series is not None and strided.series is not None
    assert len(strided.series["t"]) < len(full.series["t"]) / 5
    assert strided.series["t"][-1] == strided.t_s == full.t_s
    assert np.all(np.diff(strided.series["t"]) > 0.0)


def test_nothing_recorded_by_default() -> None:
    """What a scene does not ask for is not stored."""
    r = granrs.simulate(granrs.cases.free_link(45, 2.27))
    assert r.series is None
    with pytest.raises(ValueError, match="record"):
        r.to_frame()


def test_to_frame() -> None:
    """to_frame gives a DataFrame indexed by t with every recorded column."""
    r = granrs.simulate(granrs.cases.free_link(30, 2.0, record=RECORD_ALL))
    assert r.series is not None
    frame = r.to_frame()
    assert isinstance(frame, pd.DataFrame)
    assert frame.index.name == "t"
    assert len(frame) == len(r.series["t"])
    assert set(frame.columns) == set(r.series) - {"t"}
    np.testing.assert_array_equal(frame.index.to_numpy(), r.series["t"])
    np.testing.assert_array_equal(frame["depth"].to_numpy(), r.series["depth"])


# ---------------------------------------------------------------------------------------
# Scene


def test_scene_replace_unknown_field() -> None:
    """Scene.replace with a misspelt field names it instead of silently ignoring it."""
    scene = granrs.cases.free_link(45, 2.27)
    with pytest.raises(UnknownNameError, match="masss") as info:
        scene.replace(masss=0.2)
    assert info.value.field == "masss"
    assert isinstance(info.value, ValueError)


def test_scene_replace_known_field() -> None:
    """Scene.replace returns a changed copy and leaves the original alone."""
    scene = granrs.cases.free_link(45, 2.27)
    heavier = scene.replace(mass=0.3)
    assert heavier.mass == 0.3
    assert scene.mass == MASS
    assert granrs.simulate(heavier).depth > granrs.simulate(scene).depth


def test_free_link_defaults_are_the_thesis_rod() -> None:
    """The free-link case is the thesis's rod and sand, with Table 3.4 row q = 0 at q = 0."""
    scene = granrs.cases.free_link(0, 2.214)
    assert (scene.length, scene.diameter, scene.mass, scene.rho_g, scene.g) == (
        LENGTH,
        DIAMETER,
        MASS,
        RHO_G,
        G,
    )
    assert scene.forces == granrs.forces.thesis(Coefficients(ETA_H_0, ETA_D_0, ETA_V_0, LAMBDA_0))
    assert scene.dt == 1e-4
    assert scene.apply_at == "tip"


# ---------------------------------------------------------------------------------------
# Physics checks against independent answers


@pytest.mark.parametrize("v0", [0.3, 1.0, 2.214, 5.0])
def test_vertical_drop_exact_depth(v0: float) -> None:
    """Vertical rod, force at the tip: only F_sv acts, and the final depth is the root of
    the energy balance (MODEL.md "Exact answers"), to 1e-6 relative at 10 kHz."""
    scene = granrs.cases.free_link(
        0,
        v0,
        coefficients={"eta_h": ETA_H_0, "eta_d": ETA_D_0, "eta_v": ETA_V_0, "lam": LAMBDA_0},
        length=LENGTH,
        diameter=DIAMETER,
        mass=MASS,
        rho_g=RHO_G,
        g=G,
    )
    r = granrs.simulate(scene)
    assert r.status == "stopped"
    expected = exact_vertical_depth(v0)
    assert rel(r.depth, expected) <= 1e-6, (r.depth, expected)
    # Nothing turns a vertical rod.
    assert r.summary["dq"] == 0.0
    assert r.summary["omega_end"] == 0.0


@pytest.mark.parametrize(
    ("q_deg", "v0", "extra"),
    [
        (45, 2.27, {}),
        (5, 2.245, {}),
        (30, 1.5, {}),
        (60, 0.656, {}),
        (85, 2.257, {}),
        (45, 2.27, {"apply_at": "centroid"}),
        (25, 1.12, {"sign_model": "raw"}),
        (35, 1.766, {"vx0": 0.4, "omega0": -3.0}),
    ],
)
def test_mirror_symmetry(q_deg: float, v0: float, extra: dict[str, float]) -> None:
    """(x, q, v_x, omega) -> -(x, q, v_x, omega) maps a run to a run (MODEL.md): the mirror
    scene stops at the same time and depth (1e-12 relative), with the opposite turn."""
    mirror_extra = {k: (-v if k in ("vx0", "omega0") else v) for k, v in extra.items()}
    a = granrs.simulate(granrs.cases.free_link(q_deg, v0, **extra))
    b = granrs.simulate(granrs.cases.free_link(-q_deg, v0, **mirror_extra))
    assert a.status == b.status == "stopped"
    assert rel(b.t_s, a.t_s) <= 1e-12, (a.t_s, b.t_s)
    assert rel(b.depth, a.depth) <= 1e-12, (a.depth, b.depth)
    assert a.summary["dq"] != 0.0
    assert b.summary["dq"] == pytest.approx(-a.summary["dq"], rel=1e-12)
    assert b.summary["omega_end"] == pytest.approx(-a.summary["omega_end"], rel=1e-12)
    assert b.summary["x_tip_end"] == pytest.approx(-a.summary["x_tip_end"], rel=1e-12)
    assert b.summary["dE"] == pytest.approx(a.summary["dE"], rel=1e-12)


def test_not_stopped_before_t_end() -> None:
    """A scene whose t_end comes before the stop is not an error: status "not_stopped",
    t_s NaN, and the state at t_end is reported."""
    full = granrs.simulate(granrs.cases.free_link(45, 2.27))
    t_end = 0.5 * full.t_s
    r = granrs.simulate(granrs.cases.free_link(45, 2.27, t_end=t_end, record=("state",)))
    assert r.status == "not_stopped"
    assert not r.stopped
    assert not r.contacts[0].stopped
    assert math.isnan(r.t_s)
    assert math.isnan(r.summary["t_s"])
    assert 0.0 < r.depth < full.depth
    assert r.series is not None
    assert r.series["t"][-1] == pytest.approx(t_end, rel=1e-12)
    assert r.summary["t_final"] == pytest.approx(t_end, rel=1e-12)


def test_end_time_status() -> None:
    """end="time" runs to t_end and says so."""
    r = granrs.simulate(granrs.cases.free_link(45, 2.27, end="time", t_end=0.01))
    assert r.status == "end_time"
    assert r.summary["t_final"] == pytest.approx(0.01, rel=1e-12)


# ---------------------------------------------------------------------------------------
# Examples run as tests

README_EXAMPLE = """
import granrs

scene = granrs.cases.free_link(q_deg=45, v0=2.27)
result = granrs.simulate(scene)
print(f"depth {result.depth * 1e3:.1f} mm after {result.t_s * 1e3:.1f} ms")
"""


def _exec_printing(code: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "<example>", "exec"), {"__name__": "__example__"})
    return out.getvalue()


def test_five_line_example() -> None:
    """The five-line example, as a README would show it, runs and prints a depth of a few
    centimetres (thesis Table 3.5, q = 45, v0 = 2.27: 0.026 m) and a stop of tens of ms."""
    printed = _exec_printing(README_EXAMPLE)
    match = re.fullmatch(r"depth (\S+) mm after (\S+) ms\n", printed)
    assert match, printed
    depth_mm, t_s_ms = float(match[1]), float(match[2])
    assert 10.0 < depth_mm < 50.0
    assert 10.0 < t_s_ms < 50.0


README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_blocks_run() -> None:
    """Every ```python block of README.md runs."""
    if not README.exists():
        pytest.skip("no README.md")
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
    assert blocks, "README.md has no python example"
    for block in blocks:
        assert _exec_printing(block).strip()


def test_simulate_doctest() -> None:
    """The example in granrs.simulate's docstring holds."""
    import doctest

    import granrs.api

    failures, tried = doctest.testmod(granrs.api, verbose=False, report=True)
    assert tried > 0
    assert failures == 0
