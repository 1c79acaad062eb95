"""granrs.sweep: the parallel batch gives, row by row and in input order, what simulate()
gives for each scene alone; it validates everything first, reports failures, shows
progress, stops on Ctrl-C, and gives the same table on Dask."""

from __future__ import annotations

import itertools
import math
import multiprocessing
import os
import signal
import threading
import time

import numpy as np
import pandas as pd
import pytest
from _modules import REPO, load_module

import granrs
from granrs import _granrs, batch, cases
from granrs.errors import InvalidParameterError, InvalidSceneError, UnknownNameError
from granrs.forces import select, thesis

# Summary keys a sweep row shares with Result.summary.
SHARED = (
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
    "work_sand",
    "x_tip_end",
    "t_entry",
    "steps",
    "rhs_evals",
    "events",
    "t_final",
    "energy_start",
    "energy_end",
    "dissipated",
)


def _same(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or a == b


def test_product_rows_equal_single_runs_in_input_order() -> None:
    base = cases.free_link(q_deg=45, v0=2.27)
    qs, vs = [0.0, -30.0, 60.0], [0.5, 2.0, 4.0]
    df = granrs.sweep(base, q_deg=qs, v0=vs, threads=2)
    assert len(df) == 9
    for row, (q, v) in zip(df.itertuples(index=False), itertools.product(qs, vs), strict=True):
        assert (row.q_deg, row.v0) == (q, v)
        alone = granrs.simulate(base.replace(q_deg=q, v0=v))
        assert row.status == alone.status
        for key in SHARED:
            assert _same(getattr(row, key), alone.summary[key]), (q, v, key)


def test_a_product_over_thesis_rows_fills_the_frame_a_list_of_its_scenes_does(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The free link's q_deg selects each run's thesis row, so a product over it runs one
    part per row and puts each chunk's rows at their places in the whole table as it comes:
    the frame is the one a list of the same scenes gives (one table, in order), value for
    value, with the same dtypes, column order and index. Chunks of 5 runs, so that each part
    takes several, and q_deg the last axis, so that the parts' rows interleave."""
    monkeypatch.setattr(batch, "LOCAL_CHUNK", 5)
    parts = []
    by_row = batch._run_by_row

    def spy(kwargs, field, terms, n, run):  # type: ignore[no-untyped-def]
        parts.append(len({tuple(map(repr, t)) for t in terms}))
        return by_row(kwargs, field, terms, n, run)

    monkeypatch.setattr(batch, "_run_by_row", spy)
    base = cases.free_link(q_deg=0, v0=2.0)
    vs, qs = [0.5, 2.0, 4.0], [float(q) for q in np.linspace(-85, 85, 13)]
    df = granrs.sweep(base, v0=vs, q_deg=qs, threads=2, progress=False)
    assert len(parts) == 1 and parts[0] > 2
    alone = granrs.sweep(
        [base.replace(v0=v, q_deg=q) for v in vs for q in qs], threads=2, progress=False
    )
    assert list(df.columns[:2]) == ["v0", "q_deg"]
    assert df[["v0", "q_deg"]].values.tolist() == [[v, q] for v in vs for q in qs]
    pd.testing.assert_frame_equal(df.drop(columns=["v0", "q_deg"]), alone, check_exact=True)


def test_a_sweeps_columns_keep_their_dtypes() -> None:
    """The counters are int32, the ``stopped`` flags bool, ``status`` a categorical of
    :data:`granrs.batch.STATUSES`, every other column (the axes' too) float64; the index a
    RangeIndex."""
    counters = {"steps", "rhs_evals", "root_evals", "events", "rejected", "unresolved"}
    counters.add("unresolved_stops")
    df = granrs.sweep(cases.free_link(q_deg=0, v0=2.0), q_deg=[0.0, 45.0], v0=[1.0, 3.0])
    assert isinstance(df.index, pd.RangeIndex) and len(df) == 4
    assert list(df["status"].cat.categories) == list(batch.STATUSES)
    for name, dtype in df.dtypes.items():
        if name == "status":
            continue
        want = "int32" if name in counters else "bool" if name == "stopped" else "float64"
        assert str(dtype) == want, name
    assert counters <= set(df.columns) and "stopped" in df.columns


def test_list_of_scenes_chain_and_leg_equal_single_runs() -> None:
    chains = [cases.chain(case) for case in (1, 2, 3)]
    df = granrs.sweep(chains)
    for i, scene in enumerate(chains):
        alone = granrs.simulate(scene)
        for c, contact in enumerate(alone.contacts):
            assert _same(df.loc[i, f"c{c}.depth"], contact.depth)
            assert _same(df.loc[i, f"c{c}.t_s"], contact.t_s)
        assert df.loc[i, "pin.F_max"] == alone.joints["pin"]["F_max"]
    legs = granrs.sweep(cases.leg(v0=3.28), knee=["locked", "free"])
    for i, knee in enumerate(("locked", "free")):
        alone = granrs.simulate(cases.leg(v0=3.28).replace(knee=knee))
        assert legs.loc[i, "depth"] == alone.depth
        assert legs.loc[i, "knee.torque_max"] == alone.joints["knee"]["torque_max"]
    assert list(legs["knee"]) == ["locked", "free"]


def test_a_list_of_scenes_is_converted_once_per_scene() -> None:
    """A list sweep reads each scene's compiled form (kept on the scene, as ``simulate``
    keeps it): the rows equal the plain dicts' through the core, sweeping the same scenes
    again converts nothing, and a scene that does not compile is refused when built."""
    scenes = [cases.free_link(q_deg=q, v0=v) for q, v in ((0, 2.214), (45, 2.27), (85, 0.5))]
    scenes.append(cases.chain(1).replace(end="first_stop"))  # another body: refused
    with pytest.raises(InvalidSceneError) as err:
        granrs.sweep(scenes, progress=False)
    assert err.value.field == "body"
    scenes.pop()
    df = granrs.sweep(scenes, progress=False)
    plain = _granrs.sweep(scenes=[s._plain() for s in scenes], threads=1)
    columns = list(plain["columns"])
    for i, s in enumerate(scenes):
        assert "_compiled_cache" in s.__dict__
        assert df.loc[i, "depth"] == plain["data"][i][columns.index("c0.depth")]
        assert df.loc[i, "depth"] == granrs.simulate(s).depth
    cached = [s.__dict__["_compiled_cache"] for s in scenes]
    again = granrs.sweep(scenes, progress=False)
    assert all(s.__dict__["_compiled_cache"] is c for s, c in zip(scenes, cached, strict=True))
    pd.testing.assert_frame_equal(df, again)
    # A scene that does not compile cannot be built (a Scene is checked on construction).
    with pytest.raises(InvalidParameterError) as err:
        scenes[0].replace(mass=-1.0)
    assert err.value.field == "mass"


def test_thread_count_does_not_change_results() -> None:
    base = cases.free_link(q_deg=0, v0=2.0)
    kw = {"q_deg": np.linspace(-80, 80, 17), "v0": [0.3, 3.0]}
    one = granrs.sweep(base, threads=1, **kw)
    two = granrs.sweep(base, threads=2, **kw)
    pd.testing.assert_frame_equal(one, two)


def _depths_in_a_child(queue: multiprocessing.Queue) -> None:  # type: ignore[type-arg]
    df = granrs.sweep(cases.free_link(q_deg=0, v0=2.0), threads=2, progress=False, **POOL_AXES)
    queue.put(df["depth"].tolist())


POOL_AXES = {"q_deg": np.linspace(-60, 60, 9), "v0": [0.5, 2.5]}


@pytest.mark.skipif(not hasattr(os, "fork"), reason="fork")
def test_the_kept_thread_pools_serve_concurrent_sweeps_and_a_forked_child() -> None:
    """A sweep runs on a pool kept for the process (one per thread count): sweeps from
    several Python threads at once share it and each gets the frame of a sweep alone, and a
    forked child, which inherits the pools but not their threads, starts its own."""
    base = cases.free_link(q_deg=0, v0=2.0)
    reference = granrs.sweep(base, threads=1, progress=False, **POOL_AXES)
    frames: list[pd.DataFrame | None] = [None] * 6

    def work(k: int) -> None:
        frames[k] = granrs.sweep(base, threads=2, progress=False, **POOL_AXES)

    workers = [threading.Thread(target=work, args=(k,)) for k in range(len(frames))]
    for w in workers:
        w.start()
    for w in workers:
        w.join(60)
    for frame in frames:
        assert frame is not None
        pd.testing.assert_frame_equal(frame, reference)
    fork = multiprocessing.get_context("fork")
    queue = fork.Queue()
    child = fork.Process(target=_depths_in_a_child, args=(queue,))
    child.start()
    child.join(60)
    if child.is_alive():
        child.kill()
        pytest.fail("a forked child's sweep did not finish within 60 s")
    assert child.exitcode == 0
    assert queue.get(timeout=5) == reference["depth"].tolist()


def test_forces_axis() -> None:
    base = cases.free_link(q_deg=0, v0=2.0)
    weak = granrs.Coefficients(eta_h=6.5, eta_d=15.2, eta_v=124.0, lam=0.106)
    df = granrs.sweep(base, forces=[base.forces, thesis(weak)])
    # Half the vertical static force: the vertical rod sinks deeper.
    assert df.loc[1, "depth"] > df.loc[0, "depth"]
    df = granrs.sweep(base, forces=[base.forces, select(base.forces, "gravity", "static_v")])
    # A vertical drop feels only F_sv: pruning the other terms changes nothing.
    assert df.loc[0, "depth"] == pytest.approx(df.loc[1, "depth"], rel=1e-12)


def test_everything_is_validated_before_anything_runs() -> None:
    base = cases.free_link(q_deg=0, v0=2.0)
    with pytest.raises(InvalidParameterError) as err:
        granrs.sweep(base, q_deg=[0, 30], mass=[0.1, -1.0, 0.2])
    assert err.value.field == "mass"
    assert "run 1" in str(err.value)
    with pytest.raises(InvalidParameterError) as err:
        granrs.sweep(base, v0=[1.0, float("nan")])
    assert err.value.field == "v0"
    with pytest.raises(UnknownNameError, match="did you mean 'length'") as err:
        granrs.sweep(base, lenght=[0.1, 0.2])
    assert err.value.field == "lenght"
    with pytest.raises(InvalidSceneError) as err:
        granrs.sweep(base, body=["chain"])
    assert err.value.field == "body"
    with pytest.raises(InvalidSceneError) as err:
        granrs.sweep([base, cases.chain(1)])
    assert err.value.field == "body"
    with pytest.raises(InvalidSceneError) as err:
        granrs.sweep(base, knee=["free"])  # a leg field on a free link
    assert err.value.field == "knee"
    with pytest.raises(InvalidParameterError) as err:
        granrs.sweep(base, threads=0)
    assert err.value.field == "threads"


def test_progress_reaches_the_total() -> None:
    seen: list[int] = []
    raw = _granrs.sweep(
        base=cases.free_link(q_deg=0, v0=2.0).to_dict(),
        axes=[("q_deg", list(np.linspace(-60, 60, 40)))],
        progress=seen.append,
    )
    assert raw["data"].shape[0] == 40
    assert seen and seen[-1] == 40
    assert seen == sorted(seen)


def test_an_exception_in_progress_cancels() -> None:
    def boom(done: int) -> None:
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        base = cases.free_link(q_deg=0, v0=2.0).to_dict()
        _granrs.sweep(base=base, axes=[("v0", [1.0] * 5000)], progress=boom)


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to self")
def test_ctrl_c_stops_a_long_sweep_cleanly() -> None:
    # 200,000 leg impacts would take many minutes; Ctrl-C after 0.3 s must stop it.
    # A process started in a shell's background job inherits SIGINT ignored, and Python then
    # installs no handler for it (CI runs so): give this one the handler a terminal's Python
    # has, for this test only.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _interrupt_a_long_sweep()
    finally:
        signal.signal(signal.SIGINT, previous)


def _interrupt_a_long_sweep() -> None:
    base = cases.leg(v0=3.28)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        granrs.sweep(base, v0=np.linspace(1, 4, 400), knee_deg=np.linspace(5, 40, 500))
    elapsed = time.perf_counter() - start
    timer.cancel()
    assert elapsed < 60.0
    # The module still works afterwards.
    assert granrs.sweep(cases.free_link(q_deg=0, v0=2.0), v0=[1.0]).loc[0, "status"] == "stopped"


def test_dask_gives_the_same_frame() -> None:
    distributed = pytest.importorskip("distributed")
    base = cases.free_link(q_deg=0, v0=2.0)
    kw = {"q_deg": [-40.0, 0.0, 40.0, 70.0], "v0": [0.5, 1.5, 2.5]}
    local = granrs.sweep(base, **kw)
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        remote = granrs.sweep(base, client=client, chunk_size=5, **kw)
        with pytest.raises(InvalidParameterError) as err:
            granrs.sweep(base, client=client, mass=[0.1, -2.0])
        assert err.value.field == "mass"
    pd.testing.assert_frame_equal(local, remote)


def test_docstring_examples() -> None:
    import doctest

    import granrs.batch
    import granrs.forces

    for module in (granrs.batch, granrs.forces):
        failures, tried = doctest.testmod(module, verbose=False, report=True)
        assert tried > 0 and failures == 0, module.__name__


def test_a_sweep_of_linkages_with_several_links_names_their_joint_columns() -> None:
    """A list of user linkages with two links (their joint columns are ``joint<i>.*``) used
    to raise IndexError while naming the columns (found by the soak script)."""

    import numpy as np

    soak = load_module("soak", REPO / "benches" / "soak.py")
    scenes = soak.random_table_scenes(np.random.default_rng(1), 3, False, 500)
    df = granrs.sweep(scenes, progress=False)
    assert len(df) == 3
    assert any(c.startswith("joint") for c in df.columns), list(df.columns)
