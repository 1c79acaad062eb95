"""Mirror images agree bit for bit: a free-link scene and its mirror image (x -> -x: q, vx0
and omega0 -> -q, -vx0, -omega0) give the same t_s and depth and the negated x_tip_end, dq
and omega_end, to the last bit.

IEEE negation is exact, so a computation that is mirror-symmetric operation by operation
gives the same magnitudes. Before, the rod's tip end (a boundary plate across the axis)
ran from the corner on the axis's left, so a rod and its mirror image walked that plate's
elements from opposite corners: ``rft`` and ``rft_inertial`` differed in the last bit from
the first step, and where a run is sensitive to rounding the pair parted (the four silent
pairs of ``benches/step_warning.py`` below, by 7.6e-8 to 4.8e-5 in t_s or depth). The plate
now runs from its deeper corner in both.
"""

from __future__ import annotations

import math
import warnings
from types import ModuleType

import pytest
from _modules import REPO, load_module
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import granrs
from granrs import cases
from granrs import forces as f

#: Read as the mirror of the run: the same (t_s, depth, ...) and the negated (x_tip_end, ...).
SAME = ("t_s", "depth", "energy_end", "dissipated", "steps", "events")
NEGATED = ("x_tip_end", "dq", "omega_end")


def _bench() -> ModuleType:
    return load_module("granrs_bench_step_warning_mirror", REPO / "benches" / "step_warning.py")


def simulate_quiet(scene: granrs.Scene) -> tuple[granrs.Result, bool]:
    """The run and whether it warned StepSizeWarning."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = granrs.simulate(scene)
    return r, any(issubclass(w.category, granrs.StepSizeWarning) for w in caught)


def assert_mirrored(a: granrs.Result, b: granrs.Result) -> None:
    """`b` is `a`'s mirror image bit for bit (NaN where both are NaN)."""
    assert a.status == b.status
    for key in SAME + NEGATED:
        x, y = float(a.summary[key]), float(b.summary[key])
        if math.isnan(x) and math.isnan(y):
            continue
        want = y if key in SAME else -y
        assert x == want, f"{key}: {x!r} against the mirror's {y!r}"


#: The four silent pairs of ``python benches/step_warning.py --scenes 200 --seed S`` at
#: dt = 1e-4 that differed by more than 1e-9, (seed, scene): by 8.7e-7, 1.8e-6, 4.8e-5 and
#: 7.6e-8 (relative, the larger of t_s's and depth's).
SILENT_PAIRS = [(11, 82), (11, 181), (3, 59), (3, 102)]


@pytest.mark.parametrize(("seed", "index"), SILENT_PAIRS)
def test_the_silent_pairs_of_the_random_set_agree_bit_for_bit(seed: int, index: int) -> None:
    bench = _bench()
    scene = bench.scenes(200, seed)[index]
    a, warned_a = simulate_quiet(scene.at(1e-4))
    b, warned_b = simulate_quiet(scene.at(1e-4, mirror=True))
    assert not warned_a and not warned_b
    assert_mirrored(a, b)


#: The laws of the property below, each with its parameters drawn.
LAWS = {
    "thesis": lambda d: list(f.thesis()),
    "rft": lambda d: [f.gravity(), f.rft(zeta=10 ** d(st.floats(5.5, 6.5)))],
    "rft_inertial": lambda d: [f.gravity(), f.rft_inertial(lam=d(st.floats(0.5, 2.0)))],
    "poncelet": lambda d: [
        f.gravity(),
        f.poncelet(c=d(st.floats(0.3, 3.0)), k=d(st.floats(20.0, 500.0))),
    ],
}


@st.composite
def free_links(draw: st.DrawFn) -> granrs.Scene:
    law = draw(st.sampled_from(sorted(LAWS)))
    return cases.free_link(
        draw(st.floats(-85.0, 85.0)), draw(st.floats(0.1, 5.0)), dt=1e-4
    ).replace(
        mass=10 ** draw(st.floats(-2.0, 0.0)),
        vx0=draw(st.floats(-1.0, 1.0)),
        omega0=draw(st.floats(-10.0, 10.0)),
        forces=LAWS[law](draw),
        apply_at=draw(st.sampled_from(("tip", "centroid"))),
        t_end=0.3,
        # The mirror identity is of the run itself: the step's check (a second run at dt / 10)
        # is the same computation again.
        step_check=False,
    )


def mirror(scene: granrs.Scene) -> granrs.Scene:
    return scene.replace(q_deg=-scene.q_deg, vx0=-scene.vx0, omega0=-scene.omega0)


@settings(
    max_examples=80,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(free_links())
def test_a_free_link_and_its_mirror_image_agree_bit_for_bit(scene: granrs.Scene) -> None:
    a, _ = simulate_quiet(scene)
    b, _ = simulate_quiet(mirror(scene))
    assert_mirrored(a, b)
