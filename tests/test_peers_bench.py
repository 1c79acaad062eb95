"""The peers of ``benches/peers.py`` compute granrs's model (issue 5, "peers").

A peer that computes a different model is worthless as a timing reference: the numba RK4
loops must give granrs ``"raw"``'s depths (same model, same steps; they differ only in how
the stop is located), and solve_ivp must converge to granrs's reference depth.
"""

from __future__ import annotations

import importlib.util

import pytest
from _modules import REPO, load_module

# Benchmarks: deselected by default (pyproject's addopts), run with -m bench after
# pip install -e '.[bench]'. A mark, not a module-level importorskip, so that a default run
# without numba deselects these tests instead of reporting the module as skipped.
pytestmark = [
    pytest.mark.bench,
    pytest.mark.skipif(
        importlib.util.find_spec("numba") is None or importlib.util.find_spec("scipy") is None,
        reason="needs numba and scipy: pip install -e '.[bench]'",
    ),
]


def _peers():
    return load_module("granrs_bench_peers", REPO / "benches" / "peers.py")


def test_peers_agree_with_granrs_raw_and_solve_ivp_converges():
    """numba (user style, scalar and located) against granrs raw within ``AGREEMENT_TOL`` on three
    Table 3.5 rows (vertical, 45 and 85 deg); solve_ivp at rtol 1e-10 within 1e-8 m of
    granrs at dt = 1e-6."""
    peers = _peers()
    runs = [r for r in peers.build(quick=True) if r.q_deg in (0.0, 45.0, 85.0)]
    assert len(runs) == 3
    for r in runs:
        r.depth["granrs_raw"] = peers.granrs_depth(r.scene.replace(sign_model="raw"))
        r.depth["numba_user"] = peers.impact_user(r.y0, r.p, peers.DT, peers.T_END)[1]
        r.depth["numba_scalar"] = peers.impact_scalar(r.y0, r.p, peers.DT, peers.T_END)[1]
        r.depth["numba_located"] = peers.impact_located(r.y0, r.p, peers.DT, peers.T_END)[1]
    assert peers.check_agreement(runs) <= peers.AGREEMENT_TOL
    # The located stop is granrs raw's (the same steps, the same Hermite root, the same
    # partial step to it): they agree to round-off, far below the linear stop's 1e-7 m;
    # at 85 deg granrs also cuts a step at the full-immersion kink, which moves it by 3e-8 m.
    for r in runs:
        tol = 5e-8 if r.q_deg == 85.0 else 1e-12
        assert abs(r.depth["numba_located"] - r.depth["granrs_raw"]) < tol, r.q_deg
    r = runs[1]
    reference = peers.granrs_depth(r.scene.replace(dt=1e-6))
    _, depth, nfev = peers.impact_ivp(r.y0, r.p, 1e-10)
    assert abs(depth - reference) < 1e-8, (depth, reference, nfev)


def test_the_floor_makes_the_loops_calls():
    """``libm_floor`` makes n sin/cos/pow rounds at angles and depths that step on by a little:
    its value is that sum's, as plain Python computes it (so jitting it dropped no call), and
    it changes with n."""
    import math

    peers = _peers()
    q, depth, lam, acc = 0.7, 0.012, 0.25, 0.0
    for i in range(5):
        s, c = math.sin(q + 1e-7 * i), math.cos(q + 1e-7 * i)
        acc += math.pow(depth + 1e-9 * i, lam) + s * c
    assert peers.libm_floor(5, 0.7, 0.012, 0.25) == pytest.approx(acc, rel=1e-14)
    assert peers.libm_floor(4, 0.7, 0.012, 0.25) != peers.libm_floor(5, 0.7, 0.012, 0.25)


def test_what_the_targets_leave_is_the_time_above_the_floor():
    """The report's budget lines from made-up times: a loop of 800 evaluations taking 40 us
    of which its calls take 32 (40 ns per evaluation), and granrs taking 80 us over 1000
    evaluations: granrs's own work is 80 - 40 = 40 us against the loop's 8 (5x); the sweep
    line leaves 40 / 2 us over 1000 evaluations, 20 ns each. A located loop of 42 us and
    granrs raw of 80: 40 against 10 us (4x)."""
    peers = _peers()
    runs = peers.build(quick=True)[:2]
    for r in runs:
        r.evals_scalar, r.evals_granrs = 800, 1000
    times = {"libm_floor": 32.0, "numba_scalar": 40.0, "granrs": 80.0}
    times |= {"numba_located": 42.0, "granrs_raw": 80.0}
    lines = "\n".join(peers.targets_left(runs, times))
    assert "| evaluations per impact: hand-tuned loop, granrs | 800, 1000 |" in lines
    assert "| the calls, ns per evaluation | 40.0 |" in lines
    assert "| the loop's own, us per impact (ns per evaluation) | 8.0 (10.0) |" in lines
    assert "| granrs.simulate's own, us per impact (ns per evaluation) | 40.0 (40.0) |" in lines
    assert "| granrs.simulate's own / the loop's own | 5x |" in lines
    # The lean line: 1.2 x 40 us less granrs's calls (1000 x 40 ns) leaves 8 us of its own;
    # a lean run of 70 us takes 30.
    assert "granrs's own may take" not in lines
    times["granrs_lean"] = 70.0
    lean = "\n".join(peers.targets_left(runs, times))
    assert "granrs's own may take, us per impact (it takes) | 8.0 (30.0) |" in lean
    assert "granrs raw's own / the located loop's own | 4x |" in lines
    # The sweep line (1/2 x the loop) leaves 40 / 2 us over 1000 evaluations: 20 ns each.
    assert "all included | 20.0 |" in lines
    assert peers.targets_left(runs, {"numba_scalar": 40.0, "granrs": 80.0}) == []
