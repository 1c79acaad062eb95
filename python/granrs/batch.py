"""``granrs.sweep`` (module ``granrs.batch``): many runs in parallel, one row of results per run.

:func:`sweep` runs the Cartesian product of field values over a base scene (or a list of
scenes) in the Rust core, on a rayon pool with the GIL released, and returns a pandas
DataFrame of summaries in input order (or, with ``as_frame=False``, its columns as numpy
arrays, without pandas). Every run is validated before the first starts; a
bad value raises the typed error naming the field and the run. A progress bar (tqdm) shows
on long sweeps; Ctrl-C cancels the sweep (its validation and the runs in flight included)
within a fraction of a second and raises ``KeyboardInterrupt``.
Given a ``dask.distributed`` client, the same sweep is cut into chunks that each run the
Rust batch on a worker (``pip install 'granrs[dask]'``).
"""

from __future__ import annotations

import concurrent.futures
import difflib
import functools
import itertools
import math
import re
import uuid
import warnings
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal, overload

import numpy as np

from . import _granrs, space
from .api import (
    RK4_STABILITY_LIMIT,
    STEP_CHECK_FACTOR,
    STEP_ERROR_LIMIT,
    describe_move,
    loud,
    step_move,
    suspects,
)
from .coefficients import Coefficients
from .errors import (
    GranrsError,
    InvalidParameterError,
    InvalidSceneError,
    SimulationError,
    StepSizeWarning,
    UnknownNameError,
)
from .forces import Term
from .result import JOINT_NAMES
from .scene import OUTPUTS, Scene, axis_rows
from .scene import _names as _listed

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["STATUSES", "sweep"]

#: Values of the ``status`` column, by the core's status code.
STATUSES: tuple[str, ...] = ("stopped", "end_time", "not_stopped", "failed", "cancelled")
#: Sweeps with at least this many runs show a progress bar by default (on a terminal).
PROGRESS_MIN_RUNS = 2000
_INT_COLUMNS = (
    "steps",
    "rhs_evals",
    "root_evals",
    "events",
    "rejected",
    "unresolved",
    "unresolved_stops",
)


def _plain(name: str, value: Any) -> Any:
    """A field value in the form ``Scene.to_dict()`` gives it."""
    if isinstance(value, Coefficients):
        return value.as_dict()
    if isinstance(value, np.generic):
        return value.item()
    if name == "record" and isinstance(value, tuple):
        return list(value)
    if name == "forces" and isinstance(value, list | tuple):
        return [t.to_dict() if isinstance(t, Term) else t for t in value]
    return value


def _axis_values(name: str, values: Any) -> list[Any]:
    if isinstance(values, (str, bytes, Mapping, Coefficients)) or not isinstance(values, Iterable):
        values = [values]
    if name == "record" and all(isinstance(v, str) for v in values):
        # One list of names is one value of the axis, not an axis of names.
        values = [tuple(values)]
    if name == "forces" and all(isinstance(v, Term) for v in values):
        # One list of terms is one value of the axis.
        values = [tuple(values)]
    out = list(values)
    if not out:
        raise InvalidParameterError(f"sweep axis {name!r} has no values", field=name)
    return out


def _check_axes(scene: Scene, axes: dict[str, list[Any]]) -> None:
    """Python-level checks of every distinct axis value (field names, body fields, types)."""
    known = [f for f in scene.to_dict() if f != "body"]
    for name, values in axes.items():
        if name == "body":
            raise InvalidSceneError(
                "a sweep runs one body; sweep each body separately", field="body"
            )
        if name == "medium":
            raise InvalidSceneError(
                "a sweep's axis cannot change the medium (it sets rho_g, g and the terms' "
                "parameters); sweep a list of scenes: [scene.replace(medium=m) for m in ...]",
                field="medium",
            )
        if name not in known:
            hint = difflib.get_close_matches(name, known, n=1)
            more = f"; did you mean {hint[0]!r}?" if hint else ""
            raise UnknownNameError(f"Scene has no field {name!r}{more}", field=name)
        # Each distinct object once (by identity: the axis holds them, so their ids stay
        # unique; a set, so that the check is linear in the axis's length).
        seen: set[int] = set()
        for v in values:
            if isinstance(v, float | np.floating) or (
                isinstance(v, int | np.integer) and not isinstance(v, bool) and abs(v) < 2**53
            ):
                continue  # ranges are checked in the core, for every run
            if id(v) in seen:
                continue
            seen.add(id(v))
            scene.replace(**{name: v})


def _axis_sweep(
    scene: Scene, axes: Mapping[str, Any]
) -> tuple[dict[str, Any], dict[str, list[Any]]]:
    """A sweep over ``axes`` of ``scene`` as the core takes it (``base`` and ``axes``), and
    the axes' values, after the Python-level checks (:func:`_check_axes`); the core
    validates every run (``_granrs.validate_sweep``)."""
    plain_axes = {name: _axis_values(name, values) for name, values in axes.items()}
    _check_axes(scene, plain_axes)
    kwargs: dict[str, Any] = {
        "base": scene._plain(),
        "axes": [(k, [_plain(k, v) for v in vs]) for k, vs in plain_axes.items()],
    }
    return kwargs, plain_axes


def _names(columns: Sequence[str], body: str) -> list[str]:
    """The DataFrame's names of the core's columns (a free link drops ``c0.``; a built-in
    body's joints by name; a linkage's keep the core's ``joint<i>``, i in the engine's
    order of links, since the core names them by the link each carries)."""
    n_contacts = len({c.partition(".")[0] for c in columns if re.fullmatch(r"c\d+\..+", c)})
    joints = JOINT_NAMES.get(body, ())
    names = []
    for c in columns:
        if n_contacts == 1 and c.startswith("c0."):
            c = c[3:]
        elif c.startswith("joint") and "." in c:
            idx, _, rest = c[5:].partition(".")
            if int(idx) < len(joints):
                c = f"{joints[int(idx)]}.{rest}"
        names.append(c)
    return names


@functools.cache
def _status_dtype() -> pd.CategoricalDtype:
    """The ``status`` column's dtype (:data:`STATUSES`), checked once, not per sweep."""
    import pandas as pd

    return pd.CategoricalDtype(list(STATUSES))


class _Layout:
    """Where each of a core table's columns goes in a sweep's result, made once per body and
    column list (:func:`_layout`): the DataFrame's names (:func:`_names`) and, by kind, the
    core's column indices. Floats, counters and flags each fill one block (columns x rows),
    whose rows become the frame's columns; ``status`` is its own array."""

    def __init__(self, columns: tuple[str, ...], body: str) -> None:
        self.names = tuple(_names(columns, body))
        kinds = [_kind(c) for c in self.names]
        self.status = kinds.index("status") if "status" in kinds else None
        self.index = {
            kind: np.array([j for j, k in enumerate(kinds) if k == kind], dtype=np.intp)
            for kind in ("float", "int", "bool")
        }
        # Each name's block and row within it, in column order.
        rank = dict.fromkeys(self.index, 0)
        self.places: list[tuple[str, int]] = []
        for k in kinds:
            if k == "status":
                self.places.append((k, 0))
            else:
                self.places.append((k, rank[k]))
                rank[k] += 1
        self.rows_of = {name: place for name, place in zip(self.names, self.places, strict=True)}


@functools.lru_cache(maxsize=32)
def _layout(columns: tuple[str, ...], body: str) -> _Layout:
    return _Layout(columns, body)


def _kind(name: str) -> str:
    if name == "status":
        return "status"
    if name.endswith("stopped"):
        return "bool"
    if name in _INT_COLUMNS:
        return "int"
    return "float"


#: The dtype of each kind's block.
_DTYPES = {"float": np.float64, "int": np.int32, "bool": np.bool_}


class _Table:
    """A sweep's result columns, filled chunk by chunk from the core's tables (``rows x
    columns`` floats) and then made a DataFrame without copying them: the floats are one
    ``columns x rows`` block (the frame's own), the counters and the flags one block each,
    ``status`` its own array. The counters are int32 (a run's stay far below 2^31; a block
    that does not fit is widened to int64). So a sweep holds its result plus one chunk, a
    product over a thesis-row axis too (each part's chunks go to their rows in the whole:
    :func:`_run_by_row`); the sweeps guide gives the peak memory of a million runs."""

    def __init__(self, columns: Sequence[str], body: str, n: int) -> None:
        self.layout = _layout(tuple(columns), body)
        self.blocks = {
            kind: np.empty((len(idx), n), dtype=_DTYPES[kind])
            for kind, idx in self.layout.index.items()
        }
        self.status = np.empty(n, dtype=np.int8)
        self.n = n

    def put(self, data: np.ndarray, rows: slice | np.ndarray) -> None:
        """The rows ``rows`` (as many as ``data`` has: a slice, or their indices) from a core
        table: one operation per kind."""
        index = self.layout.index
        self.blocks["float"][:, rows] = data[:, index["float"]].T
        self.blocks["bool"][:, rows] = data[:, index["bool"]].T == 1.0
        ints = np.nan_to_num(data[:, index["int"]].T, nan=0.0)
        block = self.blocks["int"]
        if block.dtype == np.int32 and ints.size and ints.max() > np.iinfo(np.int32).max:
            block = self.blocks["int"] = block.astype(np.int64)
        block[:, rows] = ints
        if self.layout.status is not None:
            self.status[rows] = np.nan_to_num(data[:, self.layout.status], nan=3)

    def column(self, name: str) -> np.ndarray:
        """The column ``name`` (the frame's name), a view of its block."""
        kind, row = self.layout.rows_of[name]
        return self.status if kind == "status" else self.blocks[kind][row]

    def _columns(
        self,
        failures: Sequence[tuple[int, str]],
        start: int,
        axis_columns: dict[str, np.ndarray] | None,
        status: Any,
    ) -> dict[str, Any]:
        """The result's columns in order, none copied: the axis columns (taken from
        ``axis_columns``) first, then each of :attr:`layout`'s names, a row of its block
        (``status``: ``status(codes)`` of its codes, :data:`STATUSES` indices), then
        ``error`` where a run failed (an object array, None where the run did not fail)."""
        columns: dict[str, Any] = {}
        for name in list(axis_columns or {}):
            columns[name] = axis_columns.pop(name)  # type: ignore[union-attr]
        for name, (kind, row) in zip(self.layout.names, self.layout.places, strict=True):
            if name in columns:
                raise ValueError(f"a sweep's axis and its output are both named {name!r}")
            columns[name] = status(self.status) if kind == "status" else self.blocks[kind][row]
        if failures:
            columns["error"] = _errors(failures, start, self.n)
        return columns

    def frame(
        self,
        failures: Sequence[tuple[int, str]],
        start: int,
        axis_columns: dict[str, np.ndarray] | None,
    ) -> pd.DataFrame:
        """The DataFrame, made without copying a column (:meth:`_columns`; ``status`` a
        categorical over its codes)."""
        import pandas as pd

        def status(codes: np.ndarray) -> pd.Categorical:
            return pd.Categorical.from_codes(codes, dtype=_status_dtype())

        return pd.DataFrame(self._columns(failures, start, axis_columns, status), copy=False)

    def columns(
        self,
        failures: Sequence[tuple[int, str]],
        start: int,
        axis_columns: dict[str, np.ndarray] | None,
    ) -> dict[str, np.ndarray]:
        """The frame's columns as numpy arrays, without pandas (``sweep(...,
        as_frame=False)``): the same names in the same order (:meth:`_columns`), each
        numeric or flag column a view of its block; ``status`` an object array of the
        :data:`STATUSES` strings (:func:`_status_strings`)."""
        return self._columns(failures, start, axis_columns, _status_strings)


#: The ``status`` strings by code, as an object array: indexing it by a sweep's codes gives
#: its ``status`` column without pandas (each row a reference to one of these five strings).
_STATUS_OBJECTS = np.array(STATUSES, dtype=object)


def _status_strings(codes: np.ndarray) -> np.ndarray:
    """A ``status`` column of :data:`STATUSES` strings (an object array) from its codes."""
    return _STATUS_OBJECTS[codes]


def _errors(failures: Sequence[tuple[int, str]], start: int, n: int) -> np.ndarray:
    """The ``error`` column of ``n`` runs from ``start``: each failed run's message (``failures``
    holds (run index, message)), None elsewhere."""
    errors = np.full(n, None, dtype=object)
    for i, message in failures:
        errors[i - start] = message
    return errors


def _table(raw: dict[str, Any]) -> _Table:
    """The :class:`_Table` of a sweep's raw result (a local sweep fills its own by chunks)."""
    table = raw.pop("table", None)
    if table is None:
        data = np.asarray(raw.pop("data"))
        table = _Table(raw["columns"], raw["body"], len(data))
        table.put(data, slice(0, len(data)))
    return table


def _axis_columns(axes: dict[str, list[Any]], start: int, stop: int) -> dict[str, np.ndarray]:
    """The axis columns of runs ``start..stop``, filled a chunk at a time (no temporaries of
    the sweep's length)."""
    n = stop - start
    cols: dict[str, np.ndarray] = {}
    values: dict[str, np.ndarray] = {}
    for name, vs in axes.items():
        if all(
            isinstance(v, float | np.floating)
            or (isinstance(v, int | np.integer) and not isinstance(v, bool) and abs(v) < 2**1023)
            for v in vs
        ):
            values[name] = np.asarray(vs, dtype=float)
        else:  # text, lists, terms, and integers no float holds (a text field's value)
            values[name] = np.empty(len(vs), dtype=object)
            values[name][:] = vs
        cols[name] = np.empty(n, dtype=values[name].dtype)
    shape = [len(v) for v in axes.values()]
    for lo in range(start, stop, LOCAL_CHUNK):
        hi = min(stop, lo + LOCAL_CHUNK)
        idx = np.unravel_index(np.arange(lo, hi), shape)
        for (name, vs), ix in zip(values.items(), idx, strict=True):
            cols[name][lo - start : hi - start] = vs[ix]
    return cols


def _compiled(scenes: list[Scene]) -> list[Any]:
    """Each scene compiled by the core (``Scene._compiled()``, kept on the scene). A scene
    that does not compile gets its typed error from the sweep's own validation, which names
    the run."""
    try:
        return [s._compiled() for s in scenes]
    except GranrsError:
        _granrs.validate_sweep(scenes=[s._plain() for s in scenes])
        raise


def _threads(threads: int | None) -> int:
    """The core's thread count of a sweep's ``threads`` (0: every core). A count above the
    machine's cores runs on every core, with a :class:`RuntimeWarning` saying so: every sweep
    shares one pool of one thread per core."""
    if threads is None:
        return 0
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise InvalidParameterError(
            f"threads must be a whole number >= 1 (or None for every core); got {threads!r}",
            field="threads",
        )
    cores = _granrs.max_threads()
    if threads > cores:
        warnings.warn(
            f"threads={threads} is more than this machine's {cores} cores: the sweep runs on "
            f"{cores} threads",
            RuntimeWarning,
            stacklevel=3,
        )
        return cores
    return threads


def _progress_bar(total: int, progress: bool | None) -> Any:
    if progress is False or (progress is None and total < PROGRESS_MIN_RUNS):
        return None
    from tqdm.auto import tqdm

    disable = None if progress is None else False  # None: off when not on a terminal
    return tqdm(total=total, unit="run", desc="granrs sweep", disable=disable)


#: Runs per call into the core in a local sweep: each call's table (about 250 B a run) is
#: copied into the result's columns as it comes (:class:`_Table`).
LOCAL_CHUNK = 1 << 13


class _Places:
    """Where the runs of a part of a product sweep go in the whole: the part is the product
    ``shape`` (the last axis fastest) with its axis ``axis`` taking only the values
    ``members`` (indices into that axis), and its runs ``runs`` are the whole's rows
    ``self.of(runs)`` (taken a chunk at a time: no index of the sweep's length)."""

    def __init__(self, shape: Sequence[int], axis: int, members: Sequence[int]) -> None:
        self.shape = tuple(shape)
        self.part = tuple(len(members) if k == axis else m for k, m in enumerate(shape))
        self.axis = axis
        self.members = np.asarray(members, dtype=np.intp)

    def __len__(self) -> int:
        return math.prod(self.part)

    def of(self, runs: np.ndarray) -> np.ndarray:
        at = list(np.unravel_index(runs, self.part))
        at[self.axis] = self.members[at[self.axis]]
        return np.ravel_multi_index(at, self.shape)


#: Where a part of a sweep puts its runs (:func:`_run_local`): the whole sweep's table (None
#: until its first chunk makes it), the whole's run count, and the part's :class:`_Places`.
_Into = tuple[_Table | None, int, _Places]


def _run_local(
    kwargs: dict[str, Any],
    start: int,
    stop: int,
    threads: int,
    progress: bool | None,
    into: _Into | None = None,
) -> dict[str, Any]:
    """Runs ``start..stop`` of a sweep on this machine, a chunk at a time, each chunk's
    table copied into the result's columns as it comes: a table of ``stop - start`` rows,
    or with ``into``, the whole sweep's table at the part's places (its failures and
    ``unresolved`` are still the part's run indices)."""
    if stop - start > LOCAL_CHUNK:
        # Every run is validated before the first chunk runs.
        plain = {k: v for k, v in kwargs.items() if k != "lanes"}
        _granrs.validate_sweep(**plain, threads=threads)
    bar = _progress_bar(stop - start, progress)
    table: _Table | None = None
    size, places = stop - start, None
    if into is not None:
        table, size, places = into
    failures: list[tuple[int, str]] = []
    unresolved: list[int] = []
    body = ""
    columns: list[str] = []
    try:
        for lo in range(start, max(stop, start + 1), LOCAL_CHUNK):
            hi = min(stop, lo + LOCAL_CHUNK)
            callback = None
            if bar is not None:
                done_before = lo - start

                def callback(done: int, done_before: int = done_before) -> None:
                    bar.update(done_before + done - bar.n)

            raw = _granrs.sweep(**kwargs, start=lo, stop=hi, threads=threads, progress=callback)
            body, columns = raw["body"], list(raw["columns"])
            if table is None:
                table = _Table(columns, body, size)
            rows: slice | np.ndarray = slice(lo - start, hi - start)
            if places is not None:  # a part of a sweep: its rows' places in the whole
                rows = places.of(np.arange(lo - start, hi - start))
            table.put(np.asarray(raw["data"]), rows)
            failures += raw["failures"]
            unresolved += raw["unresolved"]
            del raw
    finally:
        if bar is not None:
            bar.close()
    return {
        "table": table,
        "failures": failures,
        "unresolved": unresolved,
        "body": body,
        "columns": columns,
        "start": start,
    }


def run_chunk(kwargs: dict[str, Any], start: int, stop: int, threads: int) -> dict[str, Any]:
    """Run runs ``start..stop`` of a sweep (the task a Dask worker runs)."""
    raw = dict(_granrs.sweep(**kwargs, start=start, stop=stop, threads=threads))
    raw["start"] = start
    return raw


def _run_dask(
    client: Any,
    kwargs: dict[str, Any],
    n: int,
    chunk_size: int | None,
    progress: bool | None,
) -> dict[str, Any]:
    workers = max(1, sum(client.nthreads().values()))
    size = chunk_size or max(1, math.ceil(n / (4 * workers)))
    bounds = [(s, min(n, s + size)) for s in range(0, n, size)]
    tag = uuid.uuid4().hex
    futures = [
        client.submit(run_chunk, kwargs, s, e, 1, pure=False, key=f"granrs-sweep-{tag}-{s}")
        for s, e in bounds
    ]
    bar = _progress_bar(n, progress)
    try:
        from dask.distributed import as_completed

        for fut in as_completed(futures):
            if bar is not None:
                s, e = bounds[futures.index(fut)]
                bar.update(e - s)
        parts = client.gather(futures)
    except BaseException:
        client.cancel(futures)
        raise
    finally:
        if bar is not None:
            bar.close()
    return {
        "columns": parts[0]["columns"],
        "data": np.concatenate([p["data"] for p in parts]),
        "failures": [f for p in parts for f in p["failures"]],
        "unresolved": [i for p in parts for i in p["unresolved"]],
        "body": parts[0]["body"],
        "start": 0,
    }


def _sweep_space(
    scene: space.Scene | Sequence[space.Scene],
    threads: int,
    progress: bool | None,
    client: Any,
    axes: dict[str, Any],
    as_frame: bool,
) -> pd.DataFrame | dict[str, np.ndarray]:
    """``sweep`` of bodies in space (see :func:`sweep`): each run on a worker thread, the
    GIL released; one row per run of its status and :data:`granrs.space.SUMMARY_FIELDS`: a
    DataFrame, or with ``as_frame=False`` its columns (numpy arrays; ``status`` strings)."""
    if client is not None:
        raise InvalidParameterError(
            "a sweep of bodies in space runs on this machine's threads; Dask takes planar "
            "scenes only",
            field="client",
        )
    if isinstance(scene, space.Scene):
        names = list(axes)
        for name in names:
            if name not in {f for f in space.Scene.__dataclass_fields__ if not f.startswith("_")}:
                raise UnknownNameError(
                    f"unknown axis {name!r}: a granrs.space.Scene field", field=name
                )
        values = [_axis_values(name, axes[name]) for name in names]
        combos = list(itertools.product(*values))
        scenes = []
        for i, combo in enumerate(combos):
            try:
                scenes.append(scene.replace(**dict(zip(names, combo, strict=True))))
            except GranrsError as e:
                raise type(e)(f"run {i}: {e}", field=getattr(e, "field", None)) from e
        axis_values: dict[str, list[Any]] = {
            name: [c[k] for c in combos] for k, name in enumerate(names)
        }
    else:
        scenes = list(scene)
        for i, s in enumerate(scenes):
            if not isinstance(s, space.Scene):
                raise InvalidParameterError(
                    f"a sweep of bodies in space takes granrs.space.Scene items; item {i} is "
                    f"{type(s).__name__}",
                    field="scene",
                )
        axis_values = {}

    def one(s: space.Scene) -> tuple[str, dict[str, float], str]:
        try:
            r = space.run(s)
        except SimulationError as e:
            return "failed", {}, str(e)
        return r.status, dict(r.summary), ""

    n = len(scenes)
    rows: list[tuple[str, dict[str, float], str]] = []
    bar = _progress_bar(n, progress)
    try:
        workers = threads or _granrs.max_threads()
        with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
            for row in pool.map(one, scenes):
                rows.append(row)
                if bar is not None:
                    bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    columns: dict[str, Any] = {name: _space_axis(values) for name, values in axis_values.items()}
    columns["status"] = _STATUS_OBJECTS[[STATUSES.index(r[0]) for r in rows]]
    for name in space.SUMMARY_FIELDS:
        columns[name] = np.array([r[1].get(name, np.nan) for r in rows], dtype=float)
    if any(r[0] == "failed" for r in rows):
        columns["error"] = _errors([(i, r[2]) for i, r in enumerate(rows) if r[2]], 0, n)
    stiff = int((columns["h_lambda"] > RK4_STABILITY_LIMIT).sum()) if n else 0
    if stiff:
        warnings.warn(
            StepSizeWarning(
                f"{stiff} of {n} runs were stiffer than their step resolves (h_lambda above "
                f"{RK4_STABILITY_LIMIT}): their results are not the converged answer; use a "
                "smaller dt there"
            ),
            stacklevel=3,
        )
    if not as_frame:
        return columns
    import pandas as pd

    frame = pd.DataFrame(axis_values)
    for name, column in columns.items():
        if name == "status":
            column = pd.Categorical(column, categories=list(_SPACE_STATUSES))
        if name not in axis_values:
            frame[name] = column
    return frame


#: Values of a sweep in space's ``status`` column (its DataFrame's categories).
_SPACE_STATUSES: tuple[str, ...] = ("stopped", "not_stopped", "failed")


def _space_axis(values: list[Any]) -> np.ndarray:
    """A sweep in space's axis column as a numpy array: numbers and flags as numpy makes them
    (as pandas does: int64, float64, bool), anything else (a velocity's tuple, text) an
    object array of the values themselves."""
    try:
        array = np.asarray(values)
    except ValueError:  # ragged sequences
        array = np.empty(0)
    if array.ndim == 1 and len(array) == len(values) and array.dtype.kind in "biuf":
        return array
    out = np.empty(len(values), dtype=object)
    for i, v in enumerate(values):
        out[i] = v
    return out


def fast_lanes() -> bool:
    """Whether this process's sweeps call glibc's four-lane ``sin``, ``cos`` and ``pow`` in
    their SIMD lanes.

    Off by default: a sweep's row is then :func:`granrs.simulate`'s bit for bit. On with
    ``GRANRS_FAST_LANES=1`` in the environment before Python starts (read once per process),
    on a CPU with AVX2 where glibc's vector math library is found; a row is then near
    ``simulate``'s, not its bits (the sweeps guide, "The lanes and the scalar path", has
    what it gains and how far rows move).

    Returns:
        True where the lanes call the four-lane functions.
    """
    return bool(_granrs.fast_lanes())


# The result's type follows ``as_frame`` for type checkers: a DataFrame by default, a dict
# of numpy arrays with ``as_frame=False`` (the signature is the implementation's below).
@overload
def sweep(
    scene: Scene | Sequence[Scene],
    *,
    threads: int | None = ...,
    progress: bool | None = ...,
    client: Any = ...,
    chunk_size: int | None = ...,
    lanes: bool = ...,
    outputs: Sequence[str] | None = ...,
    as_frame: Literal[True] = ...,
    **axes: Any,
) -> pd.DataFrame: ...


@overload
def sweep(
    scene: Scene | Sequence[Scene],
    *,
    threads: int | None = ...,
    progress: bool | None = ...,
    client: Any = ...,
    chunk_size: int | None = ...,
    lanes: bool = ...,
    outputs: Sequence[str] | None = ...,
    as_frame: Literal[False],
    **axes: Any,
) -> dict[str, np.ndarray]: ...


@overload
def sweep(
    scene: Scene | Sequence[Scene],
    *,
    threads: int | None = ...,
    progress: bool | None = ...,
    client: Any = ...,
    chunk_size: int | None = ...,
    lanes: bool = ...,
    outputs: Sequence[str] | None = ...,
    as_frame: bool = ...,
    **axes: Any,
) -> pd.DataFrame | dict[str, np.ndarray]: ...


def sweep(
    scene: Scene | Sequence[Scene],
    *,
    threads: int | None = None,
    progress: bool | None = None,
    client: Any = None,
    chunk_size: int | None = None,
    lanes: bool = True,
    outputs: Sequence[str] | None = None,
    as_frame: bool = True,
    **axes: Any,
) -> pd.DataFrame | dict[str, np.ndarray]:
    """Run many scenes in parallel and return one row of summaries per run.

    Args:
        scene: the base scene, whose fields the ``axes`` vary; or a list of scenes (then no
            axes), all of one body. A body in space (:class:`granrs.space.Scene`, or a list
            of them) runs each scene on a worker thread and gives its status and the fields
            of :data:`granrs.space.SUMMARY_FIELDS` (no Dask, no lanes).
        threads: worker threads (default: one per core). Results do not depend on it. Every
            sweep shares one pool of one thread per core: a larger count runs on every core,
            with a ``RuntimeWarning``.
        progress: show a tqdm progress bar: None (default) shows it on a terminal for
            sweeps of at least 2000 runs; True always; False never.
        client: a ``dask.distributed.Client``: cut the sweep into chunks of ``chunk_size``
            runs (default: about four chunks per worker thread), each run by the Rust batch
            on a worker with one thread. The result is the same.
        chunk_size: runs per Dask task.
        lanes: run free-link scenes (under any terms, alone or mixed; any sign model; RK4)
            four at a time in SIMD lanes, with AVX2 where the CPU has it (default). The
            results are the same bit for bit as with ``lanes=False``, which runs every
            scene alone on the scalar path (for comparisons and benchmarks). Other scenes
            always run alone.
        outputs: the output fields every run computes and returns, from
            :data:`granrs.OUTPUTS` (``status`` always): the result's columns. None (default)
            keeps the scenes' own ``outputs`` (by default every field; a list of scenes must
            then agree on them). A field left out is not computed: ``outputs=("depth",
            "t_s")`` runs only what those need (see the sweeps guide, "Outputs").
        as_frame: True (default): return a pandas DataFrame. False: return its columns as a
            dict of numpy arrays instead, without importing pandas (for numpy, JAX or torch
            code, or where pandas is not installed): the same names in the same order,
            with the same values; the numeric and flag columns with the frame's dtypes,
            not copied; ``status`` an object array of its strings (``d["status"] ==
            "stopped"`` and ``np.unique(d["status"])`` work), ``error`` as in the frame.
        **axes: field name = values (any Scene field but ``body`` and ``outputs``; a single
            value is an axis of one). The sweep runs their Cartesian product, the last axis varying
            fastest, as ``itertools.product``.

    Returns:
        A DataFrame with one row per run, in input order: the axis columns (for a list of
        scenes, none), then ``status`` (``stopped``, ``end_time``, ``not_stopped``,
        ``failed`` or ``cancelled``), the work counters, the energies, and the contact
        results of :attr:`granrs.Result.summary` (``t_s``, ``depth``, ``dq``, ...; the
        chain's prefixed ``c0.`` and ``c1.``), and per joint ``<joint>.F_max``,
        ``<joint>.torque_max`` and ``<joint>.impulse_work``: those of ``outputs`` only, when
        given, in that same order. A run that failed has status ``"failed"`` and its message
        in an ``error`` column (present only then). With ``as_frame=False``, a dict of
        those columns, name -> numpy array of one value per run: float64 for the floats
        (and numeric axes), int32 for the counters (int64 if one does not fit), bool for
        the ``stopped`` flags, and object arrays for ``status`` (its strings), ``error``
        (the message, None where the run did not fail) and non-numeric axes.

    Warns:
        StepSizeWarning: once, listing the rows whose t_s, depth or status moves by more
            than 1 % at ``dt / 10``: the rows whose step looks too coarse (as
            :func:`granrs.simulate` judges a run) are run again together at ``dt / 10``, on
            this machine, where their scene's ``step_check`` is on (the default); the
            table's rows and columns are the runs at their own ``dt`` either way.

    Raises:
        InvalidSceneError: (or a subclass) before anything runs, naming the field, with
            the index of the first bad run.
        KeyboardInterrupt: on Ctrl-C, within a fraction of a second (the runs in flight
            stop too).

    Example:
        >>> import granrs
        >>> base = granrs.cases.free_link(q_deg=0, v0=2.0)
        >>> df = granrs.sweep(base, q_deg=[0, 30, 60], v0=[1.0, 2.0])
        >>> len(df), list(df.columns[:3])
        (6, ['q_deg', 'v0', 'status'])
        >>> cols = granrs.sweep(base, q_deg=[0, 30, 60], v0=[1.0, 2.0], as_frame=False)
        >>> list(cols)[:3], cols["depth"].dtype, bool((cols["status"] == "stopped").all())
        (['q_deg', 'v0', 'status'], dtype('float64'), True)
    """
    if not isinstance(as_frame, bool):
        raise InvalidParameterError(
            "as_frame must be True (a pandas DataFrame) or False (a dict of numpy arrays); "
            f"got {as_frame!r}",
            field="as_frame",
        )
    n_threads = _threads(threads)
    if outputs is not None:
        outputs = list(_listed(outputs, "outputs", OUTPUTS))
    if axes and not isinstance(scene, Scene | space.Scene):
        raise InvalidParameterError(
            "sweep() over a list of scenes takes no axes; vary the scenes instead",
            field=next(iter(axes)),
        )
    if isinstance(scene, space.Scene) or (
        isinstance(scene, Sequence)
        and not isinstance(scene, str)
        and len(scene) > 0
        and isinstance(scene[0], space.Scene)
    ):
        if outputs is not None:
            raise InvalidParameterError(
                "a sweep of bodies in space returns granrs.space.SUMMARY_FIELDS; it takes no "
                "outputs",
                field="outputs",
            )
        return _sweep_space(scene, n_threads, progress, client, axes, as_frame)
    if isinstance(scene, Scene):
        kwargs, plain_axes = _axis_sweep(scene, axes)
        # A thesis-row scene swept over the field that selects its row (the free link's
        # q_deg): each run takes its value's row, as scene.replace does.
        rows = axis_rows(scene, plain_axes)
        n = math.prod(len(v) for v in plain_axes.values())
        keep_axes = plain_axes
    else:
        scenes = list(scene)
        for i, s in enumerate(scenes):
            if not isinstance(s, Scene):
                raise InvalidParameterError(
                    f"sweep() takes a granrs.Scene or a list of them; item {i} is "
                    f"{type(s).__name__}",
                    field="scene",
                )
        # Locally, each scene's compiled form (converted once per scene and kept, as
        # `simulate` keeps it): sweeping the same scenes again converts nothing. A Dask task
        # is pickled, so it takes the plain values.
        kwargs = {"scenes": _compiled(scenes) if client is None else [s._plain() for s in scenes]}
        n = len(scenes)
        keep_axes = {}
        rows = None
    if not isinstance(lanes, bool):
        raise InvalidParameterError(f"lanes must be True or False; got {lanes!r}", field="lanes")
    kwargs["lanes"] = lanes
    if outputs is not None:
        kwargs["outputs"] = outputs
    if client is not None and chunk_size is not None:
        if not isinstance(chunk_size, int) or chunk_size < 1:
            raise InvalidParameterError(
                f"chunk_size must be a whole number >= 1; got {chunk_size!r}", field="chunk_size"
            )

    def run(
        kw: dict[str, Any], count: int, validated: bool = False, into: _Into | None = None
    ) -> dict[str, Any]:
        if client is None:
            return _run_local(kw, 0, count, n_threads, progress, into)
        if count == 0:
            return run_chunk(kw, 0, 0, 1)
        if not validated:
            # Validate everything here, before any task is sent.
            _granrs.validate_sweep(
                **{k: v for k, v in kw.items() if k != "lanes"}, threads=n_threads
            )
        return _run_dask(client, kw, count, chunk_size, progress)

    axis_columns = _axis_columns(keep_axes, 0, n) if keep_axes else None
    if rows is None:
        raw = run(kwargs, n)
        table = _table(raw)
        failures, start = raw["failures"], raw["start"]
        unresolved = [i - start for i in raw["unresolved"]]
        del raw
    else:
        # Every run validated first, so that an error names its index in the whole sweep.
        _granrs.validate_sweep(
            **{k: v for k, v in kwargs.items() if k != "lanes"}, threads=n_threads
        )
        table, failures, unresolved = _run_by_row(
            kwargs, *rows, n, lambda kw, c, into: run(kw, c, True, into)
        )
        start = 0
    if isinstance(scene, Scene):
        names, values = list(plain_axes), list(plain_axes.values())
        shape = [len(v) for v in values]

        def row_scene(i: int) -> Scene:
            at = np.unravel_index(i, shape)
            return scene.replace(**{k: v[j] for k, v, j in zip(names, values, at, strict=True)})
    else:
        row_scene = scenes.__getitem__
    _check_rows(table, unresolved, row_scene, n_threads, lanes)
    make = table.frame if as_frame else table.columns
    result = make(failures, start, axis_columns)
    del axis_columns, table
    return result


def _run_by_row(
    kwargs: dict[str, Any],
    field: str,
    terms: list[Any],
    n: int,
    run: Any,
) -> tuple[_Table, list[tuple[int, str]], list[int]]:
    """A product sweep whose ``field`` axis selects each run's force terms (``terms``, one
    per value of that axis): one product per distinct set of terms, over the values that
    select it, each row put at its place in the whole product (the last axis fastest):
    locally as each chunk comes (``run(kwargs, count, into)``: :func:`_run_local`), from
    Dask's table once it is back."""
    axes = kwargs["axes"]
    k = [name for name, _ in axes].index(field)
    shape = [len(values) for _, values in axes]
    groups: list[tuple[Any, list[int]]] = []
    for i, t in enumerate(terms):
        for group_terms, members in groups:
            if group_terms == t:
                members.append(i)
                break
        else:
            groups.append((t, [i]))
    table: _Table | None = None
    failures: list[tuple[int, str]] = []
    unresolved: list[int] = []
    for group_terms, members in groups:
        sub_axes = list(axes)
        sub_axes[k] = (field, [axes[k][1][i] for i in members])
        sub = {**kwargs, "base": {**kwargs["base"], "forces": list(group_terms)}, "axes": sub_axes}
        places = _Places(shape, k, members)
        raw = run(sub, len(places), (table, n, places))
        if raw.get("table") is not None:
            table = raw["table"]
        else:  # Dask's table, whole
            data = np.asarray(raw.pop("data"))
            if table is None:
                table = _Table(raw["columns"], raw["body"], n)
            table.put(data, places.of(np.arange(len(data))))
            del data
        start = raw["start"]
        at = places.of(np.array([i - start for i, _ in raw["failures"]], dtype=np.intp))
        failures += [(int(i), m) for i, (_, m) in zip(at, raw["failures"], strict=True)]
        unresolved += places.of(np.array(raw["unresolved"], dtype=np.intp) - start).tolist()
        del raw
    assert table is not None
    return table, failures, sorted(unresolved)


#: A contact's t_s and depth columns in a sweep's table (a body with several contacts
#: prefixes them ``c0.``, ``c1.``, ...).
_CONTACT_COLUMN = re.compile(r"(?:c(\d+)\.)?(t_s|depth)")


def _contact_values(table: _Table, rows: np.ndarray) -> list[dict[str, list[float]]] | None:
    """Each of ``rows``' contacts' ``t_s`` and ``depth`` from a sweep's table (None if its
    outputs left them out)."""
    found: dict[str, dict[int, np.ndarray]] = {"t_s": {}, "depth": {}}
    for name in table.layout.names:
        m = _CONTACT_COLUMN.fullmatch(name)
        if m:
            found[m[2]][int(m[1] or 0)] = table.column(name)[rows]
    if not found["t_s"] or sorted(found["t_s"]) != sorted(found["depth"]):
        return None
    contacts = sorted(found["t_s"])
    return [
        {key: [float(found[key][c][k]) for c in contacts] for key in ("t_s", "depth")}
        for k in range(len(rows))
    ]


def _rerun(
    scenes: Sequence[Scene], threads: int, lanes: bool
) -> tuple[list[int], _Table | None, list[tuple[int, str]]]:
    """``scenes`` run through the sweep's machinery with the outputs the step's check reads
    (``t_s`` and ``depth``; no series): the indices of those the core accepted, their table
    and their failures (indices into the accepted). A scene the core refuses (a finer step
    whose ``t_end / dt`` exceeds what a run may take) is left out."""
    compiled, kept = [], []
    for i, s in enumerate(scenes):
        try:
            compiled.append(s.replace(record=(), outputs=("t_s", "depth"))._compiled())
        except GranrsError:
            continue
        kept.append(i)
    if not compiled:
        return kept, None, []
    raw = _run_local({"scenes": compiled, "lanes": lanes}, 0, len(compiled), threads, False)
    return kept, _table(raw), raw["failures"]


def _check_rows(
    table: _Table, unresolved: Sequence[int], row_scene: Any, threads: int, lanes: bool
) -> None:
    """The step's check of a sweep (see :func:`granrs.simulate`): the rows that look too
    coarse (:func:`granrs.api.suspects`; ``unresolved`` are the rows with
    ``unresolved_stops`` > 0, which every run computes whatever its outputs; ``h_lambda``,
    ``step_error`` and the energies need their columns in the sweep's outputs, as the default
    has them) and whose scene (``row_scene(i)``) has ``step_check`` on, run again together at
    ``dt / STEP_CHECK_FACTOR`` through the sweep's machinery on this machine; one
    :class:`~granrs.errors.StepSizeWarning` lists the rows that moved and their moves, and
    the rows that warn unchecked (``step_check`` off, or a finer step no run may take). The
    table is left as it is."""
    n = table.n
    have = table.layout.rows_of
    stopped_at = np.asarray(unresolved, dtype=np.intp)
    # A chunk of rows at a time: no temporaries of the sweep's length.
    found, loud_found = [], []
    for lo in range(0, n, LOCAL_CHUNK):
        hi = min(n, lo + LOCAL_CHUNK)

        def column(name: str, fill: float, lo: int = lo, hi: int = hi) -> np.ndarray:
            return table.column(name)[lo:hi] if name in have else np.full(hi - lo, fill)

        stops = np.zeros(hi - lo, dtype=np.int64)
        stops[stopped_at[(lo <= stopped_at) & (stopped_at < hi)] - lo] = 1
        numbers = (
            column("h_lambda", math.nan),
            stops,
            column("unresolved", 0),
            column("energy_start", math.nan),
            column("energy_end", math.nan),
        )
        here = np.flatnonzero(
            suspects(numbers[0], column("step_error", math.nan), *numbers[1:], True)
        )
        found.append(lo + here)
        loud_found.append(loud(*numbers)[here])
    if not any(c.size for c in found):
        return
    candidates = np.concatenate(found)
    loud_rows = dict(zip(candidates.tolist(), np.concatenate(loud_found).tolist(), strict=True))
    moved: list[tuple[int, str]] = []
    unchecked: list[int] = []
    # CHECK_BATCH rows at a time: their scenes are built and run again a batch at a time.
    for lo in range(0, len(candidates), CHECK_BATCH):
        m, u = _recheck(
            table, candidates[lo : lo + CHECK_BATCH], loud_rows, row_scene, threads, lanes
        )
        moved += m
        unchecked += u
    if not moved and not unchecked:
        return
    bad = sorted([i for i, _ in moved] + unchecked)
    rows_text = f"{bad[:5]}{', ...' if len(bad) > 5 else ''}"
    parts = []
    if moved:
        listed = "; ".join(f"row {i}: {what}" for i, what in moved[:10])
        more = f"; and {len(moved) - 10} more" if len(moved) > 10 else ""
        parts.append(
            f"checked at dt / {STEP_CHECK_FACTOR}, {len(moved)} moved by more than "
            f"{100 * STEP_ERROR_LIMIT:g} % "
            f"({listed}{more})"
        )
    if unchecked:
        listed = f"{sorted(unchecked)[:5]}{', ...' if len(unchecked) > 5 else ''}"
        parts.append(
            f"{len(unchecked)} unchecked (rows {listed}: h_lambda above "
            f"{RK4_STABILITY_LIMIT}, 'unresolved_stops' the step missed, or 'unresolved' "
            "steps where the sign modes chattered and the energy rose)"
        )
    warnings.warn(
        StepSizeWarning(
            f"{len(bad)} of {n} runs (rows {rows_text}) did not resolve their contact: "
            f"{'; '.join(parts)}. Use a "
            f"smaller dt for those runs (dt / {STEP_CHECK_FACTOR} or less)"
        ),
        stacklevel=3,
    )


#: How many of a sweep's rows its step check builds and runs again at a time
#: (:func:`_check_rows`): a batch's scenes are held together, not every suspect row's.
CHECK_BATCH = 256


def _recheck(
    table: _Table,
    rows_to_check: np.ndarray,
    loud_rows: Mapping[int, bool],
    row_scene: Any,
    threads: int,
    lanes: bool,
) -> tuple[list[tuple[int, str]], list[int]]:
    """The step's check of some of a sweep's suspect rows (:func:`_check_rows`): those that
    moved at ``dt / STEP_CHECK_FACTOR`` (with their moves) and those that warn unchecked."""
    checked: list[tuple[int, Scene]] = []
    unchecked: list[int] = []
    for i in rows_to_check.tolist():
        s = row_scene(i)
        if not s.step_check:
            if loud_rows[i]:
                unchecked.append(i)
        elif s.sign_model != "raw" or loud_rows[i]:
            checked.append((i, s))
    fine_dt = {i: s.dt / STEP_CHECK_FACTOR for i, s in checked}
    kept, fine, fine_failures = _rerun(
        [s.replace(dt=fine_dt[i]) for i, s in checked], threads, lanes
    )
    unchecked += [i for k, (i, _) in enumerate(checked) if k not in set(kept)]
    moved: list[tuple[int, str]] = []
    if fine is not None:
        rows = np.array([checked[k][0] for k in kept], dtype=np.intp)
        coarse_values = _contact_values(table, rows)
        coarse_status = table.status[rows]
        if coarse_values is None:
            # The sweep's outputs left t_s or depth out: the rows at their own dt too.
            _, coarse, _ = _rerun([checked[k][1] for k in kept], threads, lanes)
            assert coarse is not None
            coarse_values = _contact_values(coarse, np.arange(len(kept)))
            coarse_status = coarse.status
        fine_values = _contact_values(fine, np.arange(len(kept)))
        assert coarse_values is not None and fine_values is not None
        failed = {j for j, _ in fine_failures}
        for j, i in enumerate(rows.tolist()):
            status = (STATUSES[coarse_status[j]], STATUSES[fine.status[j]])
            if j in failed:
                status = (status[0], "failed")
            check = step_move(coarse_values[j], fine_values[j], status, fine_dt[i])
            if check["moved"]:
                moved.append((i, describe_move(check)))
    return moved, unchecked
