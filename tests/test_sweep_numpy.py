"""granrs.sweep(..., as_frame=False): the sweep's columns as numpy arrays, without pandas.

On every path (a product over axes, a product over the thesis-row axis, a list of scenes,
Dask, bodies in space) the dict is the DataFrame the same sweep gives, column by column:
the same names in the same order, the same values, the numeric and flag columns with the
frame's dtypes (views of the sweep's blocks, not copies), ``status`` as its strings and
``error`` as in the frame. The path loads neither pandas nor pyarrow (checked in a fresh
interpreter)."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from typing import Any

import numpy as np
import pandas as pd
import pytest

import granrs
from granrs import batch, cases, forces, space
from granrs.coefficients import Coefficients
from granrs.errors import InvalidParameterError, SimulationError

#: A free link whose run diverges (eta 1000 times Table 3.4's on a 1 g rod at dt = 1 ms): a
#: sweep gives it a 'failed' row and an ``error`` column.
DIVERGES = cases.free_link(
    45.0,
    2.0,
    coefficients=Coefficients(eta_h=6500.0, eta_d=15200.0, eta_v=248000.0, lam=0.106),
    mass=1e-3,
    dt=1e-3,
)


def assert_columns_are_the_frame(columns: dict[str, np.ndarray], frame: pd.DataFrame) -> None:
    """``columns`` is ``frame`` column by column: names and order, values (exact; NaN where
    the frame has NaN), the dtypes of the numeric and flag columns, ``status`` the frame's
    strings, other columns object arrays of the frame's values."""
    assert list(columns) == list(frame.columns)
    for name, column in columns.items():
        assert isinstance(column, np.ndarray) and column.shape == (len(frame),), name
        want = frame[name]
        if name == "status":
            assert isinstance(want.dtype, pd.CategoricalDtype)
            assert column.dtype == object
            assert all(type(s) is str for s in column)
            np.testing.assert_array_equal(column, want.astype(object).to_numpy(), strict=True)
        elif not pd.api.types.is_numeric_dtype(want.dtype):
            # Text and other objects (``error``, a velocity axis): an object array of the
            # frame's values, None where the frame has a missing value (pandas 3 holds
            # ``error`` as strings, missing where the run did not fail).
            assert column.dtype == object, name
            missing = want.isna().to_numpy()
            assert all(v is None for v in column[missing]), name
            assert not any(v is None for v in column[~missing]), name
            np.testing.assert_array_equal(
                column[~missing], want[~missing].astype(object).to_numpy(), strict=True
            )
        else:
            assert column.dtype == want.dtype, (name, column.dtype, want.dtype)
            np.testing.assert_array_equal(column, want.to_numpy(), strict=True)


def _tables(monkeypatch: pytest.MonkeyPatch) -> list[batch._Table]:
    """The tables whose columns a sweep returns (``_Table.columns``), as they are made."""
    seen: list[batch._Table] = []
    columns = batch._Table.columns

    def spy(self: batch._Table, *args: Any) -> dict[str, np.ndarray]:
        seen.append(self)
        return columns(self, *args)

    monkeypatch.setattr(batch._Table, "columns", spy)
    return seen


def assert_views(columns: dict[str, np.ndarray], table: batch._Table) -> None:
    """Every numeric and flag output column is a view of its block of ``table`` (no copy)."""
    for name, (kind, row) in table.layout.rows_of.items():
        if kind == "status":
            continue
        block = table.blocks[kind]
        assert np.shares_memory(columns[name], block), name
        assert columns[name].base is block and np.array_equal(
            columns[name], block[row], equal_nan=True
        ), name


def test_a_product_over_axes(monkeypatch: pytest.MonkeyPatch) -> None:
    base = cases.free_link(q_deg=30.0, v0=2.0)
    kw: dict[str, Any] = {"v0": [0.5, 2.0, 4.0], "mass": [0.1, 0.184], "progress": False}
    frame = granrs.sweep(base, **kw)
    tables = _tables(monkeypatch)
    columns = granrs.sweep(base, as_frame=False, **kw)
    assert isinstance(columns, dict) and len(tables) == 1
    assert_columns_are_the_frame(columns, frame)
    assert_views(columns, tables[0])
    assert list(columns)[:3] == ["v0", "mass", "status"] and "error" not in columns
    assert columns["steps"].dtype == np.int32 and columns["stopped"].dtype == np.bool_
    # The strings compare and group as the frame's do.
    np.testing.assert_array_equal(columns["status"] == "stopped", frame["status"] == "stopped")
    assert list(np.unique(columns["status"])) == sorted(set(frame["status"]))
    # Each row refers to one of the five shared strings (8 bytes a row, no string per row).
    assert all(any(s is t for t in batch.STATUSES) for s in columns["status"])


def test_a_product_asking_for_the_depth_and_t_s(monkeypatch: pytest.MonkeyPatch) -> None:
    base = cases.free_link(q_deg=30.0, v0=2.0)
    kw: dict[str, Any] = {"v0": [0.5, 2.0], "mass": [0.1, 0.184], "outputs": ("depth", "t_s")}
    frame = granrs.sweep(base, **kw)
    tables = _tables(monkeypatch)
    columns = granrs.sweep(base, as_frame=False, **kw)
    assert list(columns) == ["v0", "mass", "status", "t_s", "depth"]
    assert_columns_are_the_frame(columns, frame)
    assert_views(columns, tables[0])


def test_a_product_over_the_thesis_row_axis(monkeypatch: pytest.MonkeyPatch) -> None:
    """q_deg selects each run's thesis row (``_run_by_row``): chunks of 5 runs, q_deg the
    last axis, so that the parts' rows interleave."""
    monkeypatch.setattr(batch, "LOCAL_CHUNK", 5)
    by_row = []
    run_by_row = batch._run_by_row

    def spy(*args: Any) -> Any:
        by_row.append(1)
        return run_by_row(*args)

    monkeypatch.setattr(batch, "_run_by_row", spy)
    base = cases.free_link(q_deg=0, v0=2.0)
    kw: dict[str, Any] = {"v0": [0.5, 2.0, 4.0], "q_deg": [float(q) for q in range(-80, 81, 20)]}
    frame = granrs.sweep(base, **kw)
    tables = _tables(monkeypatch)
    columns = granrs.sweep(base, as_frame=False, **kw)
    assert len(by_row) == 2
    assert_columns_are_the_frame(columns, frame)
    assert_views(columns, tables[0])


def test_a_list_of_scenes_with_a_failed_run(monkeypatch: pytest.MonkeyPatch) -> None:
    scenes = [cases.free_link(q_deg=q, v0=2.0) for q in (0.0, 45.0)]
    scenes.insert(1, DIVERGES)
    frame = granrs.sweep(scenes)
    assert list(frame["status"]) == ["stopped", "failed", "stopped"]
    tables = _tables(monkeypatch)
    columns = granrs.sweep(scenes, as_frame=False)
    names = list(columns)
    assert names[0] == "status" and names[-1] == "error"
    assert_columns_are_the_frame(columns, frame)
    assert_views(columns, tables[0])
    assert columns["error"][0] is None and columns["error"][2] is None
    assert isinstance(columns["error"][1], str) and columns["error"][1]


def test_a_list_of_chains_names_its_contacts_as_the_frame() -> None:
    scenes = [cases.chain(case) for case in (1, 2)]
    assert_columns_are_the_frame(
        granrs.sweep(scenes, as_frame=False), granrs.sweep(scenes, progress=False)
    )


def test_dask_gives_the_frames_columns() -> None:
    distributed = pytest.importorskip("distributed")
    base = cases.free_link(q_deg=30.0, v0=2.0)
    kw: dict[str, Any] = {"v0": [0.5, 1.5, 2.5], "mass": [0.1, 0.184]}
    local = granrs.sweep(base, **kw)
    rows = {"v0": [0.5, 2.0], "q_deg": [-40.0, 0.0, 40.0]}
    local_rows = granrs.sweep(base, **rows)
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        remote = granrs.sweep(base, client=client, chunk_size=4, as_frame=False, **kw)
        remote_rows = granrs.sweep(base, client=client, chunk_size=2, as_frame=False, **rows)
    assert_columns_are_the_frame(remote, local)
    assert_columns_are_the_frame(remote_rows, local_rows)


def test_bodies_in_space(monkeypatch: pytest.MonkeyPatch) -> None:
    """A product (a velocity axis of tuples, an integer axis) and a list with a failed run
    (the run raising SimulationError, as one that diverges does)."""
    ball = space.Body(space.Sphere(0.02), density=7800.0)
    base = space.Scene(body=ball, forces=[forces.rft3d(zeta=2e5), forces.gravity()])
    kw: dict[str, Any] = {"velocity": [(0.0, 0.0, -0.5), (0.0, 0.0, -2.0)], "quadrature": [3, 6]}
    frame = granrs.sweep(base, **kw)
    columns = granrs.sweep(base, as_frame=False, **kw)
    assert_columns_are_the_frame(columns, frame)
    assert columns["quadrature"].dtype == np.int64 and columns["velocity"].dtype == object
    assert columns["velocity"][2] == (0.0, 0.0, -2.0)

    run = space.run
    bad = base.replace(velocity=(0.0, 0.0, -1.0))

    def failing(scene: space.Scene) -> space.Result:
        if scene is bad:
            raise SimulationError("integration failed at t = 0.001 s: the test's failure")
        return run(scene)

    monkeypatch.setattr(space, "run", failing)
    scenes = [base.replace(velocity=v) for v in kw["velocity"]]
    scenes.insert(1, bad)
    frame = granrs.sweep(scenes)
    columns = granrs.sweep(scenes, as_frame=False)
    assert list(columns["status"]) == ["stopped", "failed", "stopped"]
    assert list(columns)[-1] == "error" and columns["error"][1].endswith("the test's failure")
    assert_columns_are_the_frame(columns, frame)


@pytest.mark.parametrize("value", ["no", 0, 1, None, np.bool_(False)])
def test_a_bad_as_frame_is_refused_before_anything_runs(
    monkeypatch: pytest.MonkeyPatch, value: Any
) -> None:
    def no_run(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("a run started")

    monkeypatch.setattr(batch._granrs, "sweep", no_run)
    monkeypatch.setattr(batch._granrs, "validate_sweep", no_run)
    base = cases.free_link(q_deg=30.0, v0=2.0)
    ball = space.Scene(
        body=space.Body(space.Sphere(0.02), density=7800.0), forces=[forces.gravity()]
    )
    # Before the other arguments' checks too (a bad thread count, a client in space).
    for call in (
        lambda: granrs.sweep(base, v0=[1.0, 2.0], as_frame=value, threads="two"),
        lambda: granrs.sweep([base], as_frame=value),
        lambda: granrs.sweep(ball, as_frame=value, client=object()),
    ):
        with pytest.raises(InvalidParameterError) as info:
            call()
        assert info.value.field == "as_frame" and "as_frame" in str(info.value)


def test_the_arrays_path_loads_no_pandas() -> None:
    """In a fresh interpreter: every local path with ``as_frame=False``, a failed run, and a
    sweep whose step check runs its suspect rows again and warns (``_check_rows``,
    ``_recheck``, the StepSizeWarning), with and without the t_s and depth columns; then
    neither pandas nor pyarrow is loaded."""
    code = textwrap.dedent(
        """
        import json, sys, warnings
        import numpy as np
        import granrs
        from granrs import cases, forces, space
        from granrs.coefficients import Coefficients

        base = cases.free_link(q_deg=30.0, v0=2.0)
        out = []
        out.append(granrs.sweep(base, v0=[0.5, 2.0], mass=[0.1, 0.2], as_frame=False))
        out.append(granrs.sweep(base, v0=[0.5, 2.0], q_deg=[-40.0, 40.0], as_frame=False))
        diverges = cases.free_link(
            45.0, 2.0, mass=1e-3, dt=1e-3,
            coefficients=Coefficients(eta_h=6500.0, eta_d=15200.0, eta_v=248000.0, lam=0.106),
        )
        out.append(granrs.sweep([base, diverges], as_frame=False))
        assert "error" in out[-1]
        stiff = cases.free_link(
            45.0, 2.0, mass=1e-3,
            coefficients=Coefficients(eta_h=650.0, eta_d=1520.0, eta_v=24800.0, lam=0.106),
        )
        for outputs in (None, ("steps",)):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                out.append(granrs.sweep([stiff, base], outputs=outputs, as_frame=False))
            assert any(issubclass(w.category, granrs.StepSizeWarning) for w in caught)
        ball = space.Body(space.Sphere(0.02), density=7800.0)
        ball_scene = space.Scene(body=ball, forces=[forces.rft3d(zeta=2e5), forces.gravity()])
        out.append(granrs.sweep(ball_scene, quadrature=[3, 6], as_frame=False))
        assert all(type(d) is dict and d["status"][0] == "stopped" for d in out)
        print(json.dumps(sorted({m.partition(".")[0] for m in sys.modules})))
        """
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    loaded = set(json.loads(run.stdout.splitlines()[-1]))
    assert "granrs" in loaded and "numpy" in loaded
    assert not loaded & {"pandas", "pyarrow"}, sorted(loaded & {"pandas", "pyarrow"})
