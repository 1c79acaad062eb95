"""Calibration: fit the force law's coefficients (and the leg's joints) to measurements.

The thesis tuned its coefficients by hand, one angle at a time (sec. 3.3.1, Table 3.4), and
concludes that its simulated stopping times disagree with the experiments even where the
depths match (Figs. 3.15-3.20). :func:`calibrate` does the tuning as a weighted least squares
fit instead: given measured depths and stopping times with their spread
(:class:`Measurements`), it finds the chosen parameters that minimise

    sum over rows and quantities of ((simulated - measured mean) / sd_fit)^2,

with :func:`scipy.optimize.least_squares` (trust-region reflective, with bounds), and
reports the fitted values, their standard errors and ~95 % intervals, the residuals of every
row in units of the measured sd, and what the fit cost (simulations and seconds).

Every residual evaluation runs all rows in one :func:`granrs.sweep` call (a list of scenes,
run in parallel in the Rust core), and the forward-difference Jacobian puts the scenes of
all p + 1 parameter vectors (the point and one step per parameter) in one sweep as well.

Parameters (``params``), by name:

* ``eta_h``, ``eta_d``, ``eta_v``, ``lam`` (``lambda`` is accepted): one value of the
  coefficient for every row (both links of the chain, both speeds of the leg);
* ``eta_v@45`` (any coefficient, any angle in degrees, free link only): the coefficient at
  the angle node q = 45 deg; a row at another angle takes the value interpolated between
  the nodes on either side (linearly in q: in log for the etas, plainly for lambda; constant
  beyond the outermost nodes). Nodes at the measured angles are per-angle coefficients,
  as Table 3.4 tabulates them; ``per_angle=True`` makes them from plain names;
* ``scale.eta_h``, ``scale.eta_d``, ``scale.eta_v``, ``scale.lam``: a factor on the base
  coefficients of every row (``base``: Table 3.4's nearest row or the Table 3.2 closed forms
  for the free link, Table 4.4 per link and case for the chain, the thesis's row of sec.
  5.3.2 for the leg), so that the shape in angle (or link, or speed) of the base is kept;
* ``joints.k`` [N m/rad] and ``joints.c`` [N m s/rad] (leg only): one rotational
  spring-damper at the ankle, knee and hip.

The etas, the scale factors and the joint settings are positive and fitted in log space;
lambda is fitted as it is. Bounds are given in natural units.

Weights. Each quantity's sd in the fit is ``sd_fit = sqrt(sd^2 + resolution^2 / 12)``: the
measured sd and, in quadrature, the rounding of the printed mean (uniform over one unit of
the last printed digit). The thesis prints depths and stopping times to the millimetre and
the millisecond, so :meth:`Measurements.thesis` sets ``resolution`` = 0.001 m and 0.001 s
(0.29 mm and 0.29 ms in quadrature: a few % on the typical sd of 1-3, and what keeps the
weight finite where Table 5.1 prints an sd of 0.000). A user CSV has no rounding term
unless asked. The counts "within k sd" that the report quotes use the measured sd alone
(``*_z`` columns of the residuals), so the rounding term never makes a count look better.

Uncertainty. The standard errors come from the Jacobian at the optimum: the covariance of
the fitted (transformed) parameters is (J^T J)^-1 with J the Jacobian of the weighted
residuals (J^T W J of the unweighted ones), multiplied by the reduced chi-square when that is
above 1 (``error_scale="auto"``: a misfitting model widens the intervals, a good one does not
shrink them). The ~95 % interval is +-1.96 standard errors in the fitted space, mapped back
(so asymmetric for a log-space parameter). A parameter that ends on a bound has no reliable
interval; it is listed in :attr:`CalibrationResult.at_bound`.

Finite differences. The stopping time and the depth are located on the step's interpolant
(dt = 1e-4), so they are continuous in the parameters, but the sign modes of the static
terms and the event search add round-off-level noise (about 1e-9 s, 1e-9 m here). The
default step, a relative 1e-3 (``rel_step``), changes t_s by ~1e-6 s, a thousand times the
noise, while the truncation error of a forward difference at that step is ~1e-3 of the
derivative; see ``tests/test_calibrate.py`` for the check.
"""

from __future__ import annotations

import csv
import difflib
import math
import os
import re
import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import IO, Any

import numpy as np
import pandas as pd

from . import cases as _cases
from . import data
from .coefficients import Coefficients, table_3_2, table_3_4
from .errors import (
    InvalidParameterError,
    InvalidSceneError,
    MeasurementError,
    SimulationError,
    UnknownNameError,
)
from .scene import Scene

try:  # the core's step-resolution check (newer builds)
    from .api import RK4_STABILITY_LIMIT as _RK4_LIMIT
    from .errors import StepSizeWarning as _StepSizeWarning
except ImportError:  # pragma: no cover - older builds have neither
    _RK4_LIMIT = math.inf

    class _StepSizeWarning(UserWarning):  # type: ignore[no-redef]
        """Stand-in: never raised."""


__all__ = [
    "BODIES",
    "QUANTITIES",
    "THESIS_MEASUREMENTS",
    "CalibrationResult",
    "Measurements",
    "calibrate",
    "evaluate",
    "within",
]

#: The bodies :func:`calibrate` can fit, each built by the function of :mod:`granrs.cases`
#: of the same name.
BODIES: tuple[str, ...] = ("free_link", "chain", "leg")
#: The measured quantities: depth at the stop [m] and stopping time [s].
QUANTITIES: tuple[str, ...] = ("depth", "t_s")
#: Columns every measurement table has (besides the body's own, see :data:`_KEY_COLUMNS`).
_VALUE_COLUMNS: tuple[str, ...] = ("t_s_mean", "t_s_sd", "depth_mean", "depth_sd")
#: The columns that say which run a row is, per body.
_KEY_COLUMNS: dict[str, tuple[str, ...]] = {
    "free_link": ("q_deg", "v0_mean"),
    "chain": ("link", "v0_case", "q0_deg", "v0_mean"),
    "leg": ("v0_mean",),
}
#: The thesis's measurements by name: (body, data table, what the rows are).
THESIS_MEASUREMENTS: dict[str, tuple[str, str, str]] = {
    "table_3_1": ("free_link", "table_3_1", "Table 3.1: the free link, 4 angles x 3 speeds"),
    "table_4_chain": (
        "chain",
        "chain_experiments",
        "Tables 4.1-4.2: the chain, 3 cases x 2 links",
    ),
    "table_5_1": ("leg", "table_5_1", "Table 5.1: 5 subjects x 2 heights"),
    "table_5_1_means": (
        "leg",
        "table_5_1",
        "Table 5.1 averaged per height: mean and sd across the 5 subjects' means",
    ),
}
#: The rounding of the thesis's printed means: 1 mm and 1 ms.
THESIS_RESOLUTION: dict[str, float] = {"depth": 0.001, "t_s": 0.001}

_COEFS = ("eta_h", "eta_d", "eta_v", "lam")
_JOINTS = ("k", "c")
#: Default bounds in natural units, by kind.
_DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    "eta_h": (1e-3, 1e5),
    "eta_d": (1e-3, 1e5),
    "eta_v": (1e-3, 1e6),
    "lam": (0.0, 3.0),
    "scale": (1e-3, 1e3),
    "joints.k": (1.0, 1e5),
    "joints.c": (1e-2, 100.0),
}
#: Start of the joint settings when not given [N m/rad], [N m s/rad].
_JOINT_START: dict[str, float] = {"k": 1000.0, "c": 10.0}
#: Residual of a run that failed (SimulationError): large, finite, so that the optimizer
#: steps back.
_FAILED_RESIDUAL = 1e3


# --------------------------------------------------------------------------------------------
# Measurements


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


@dataclass(frozen=True)
class Measurements:
    """Measured depths and stopping times with their spread, one row per measured case.

    Attributes:
        body: ``"free_link"``, ``"chain"`` or ``"leg"``: what the rows were measured on.
        rows: one row per case: the body's key columns (free link: ``q_deg`` [deg],
            ``v0_mean`` [m/s]; chain: ``link`` (1 or 2), ``v0_case``, ``q0_deg`` [deg],
            ``v0_mean`` [m/s], one row per link; leg: ``v0_mean`` [m/s]), then
            ``t_s_mean``, ``t_s_sd`` [s], ``depth_mean``, ``depth_sd`` [m], and any other
            columns of the source (ignored).
        source: where the rows come from (a thesis table or a file name).
        resolution: the rounding of the printed means, by quantity [m, s]: added in
            quadrature to the sd of the fit (see the module's notes); 0 for none.
    """

    body: str
    rows: pd.DataFrame
    source: str
    resolution: Mapping[str, float] = field(default_factory=lambda: {"depth": 0.0, "t_s": 0.0})

    def __post_init__(self) -> None:
        if self.body not in BODIES:
            raise UnknownNameError(
                f"unknown body {self.body!r}; measurements fit one of {', '.join(BODIES)}",
                field="body",
            )
        for q in QUANTITIES:
            r = self.resolution.get(q, 0.0)
            if not _is_number(r) or not math.isfinite(r) or r < 0:
                raise InvalidParameterError(
                    f"resolution[{q!r}] must be a finite number >= 0 [m or s]; got {r!r}",
                    field="resolution",
                )

    def __len__(self) -> int:
        return len(self.rows)

    @classmethod
    def thesis(cls, name: str = "table_3_1") -> Measurements:
        """The thesis's measurements: ``"table_3_1"`` (free link), ``"table_4_chain"``
        (chain), ``"table_5_1"`` (the leg, per subject and height) or ``"table_5_1_means"``
        (the leg: per height, the mean and sd across the subjects' means). The means are
        printed to 1 mm and 1 ms: ``resolution`` is set to that."""
        if name not in THESIS_MEASUREMENTS:
            hint = difflib.get_close_matches(str(name), list(THESIS_MEASUREMENTS), n=1)
            more = f"; did you mean {hint[0]!r}?" if hint else ""
            raise UnknownNameError(
                f"unknown thesis measurements {name!r}{more} "
                f"(available: {', '.join(THESIS_MEASUREMENTS)})",
                field="measurements",
            )
        body, table, what = THESIS_MEASUREMENTS[name]
        rows = data.load(table)
        if name == "table_5_1_means":
            groups = []
            for height, g in rows.groupby("height_case", sort=True):
                groups.append(
                    {
                        "height_case": height,
                        "v0_mean": g["v0_mean"].mean(),
                        "v0_sd": g["v0_mean"].std(ddof=1),
                        "t_s_mean": g["t_s_mean"].mean(),
                        "t_s_sd": g["t_s_mean"].std(ddof=1),
                        "depth_mean": g["depth_mean"].mean(),
                        "depth_sd": g["depth_mean"].std(ddof=1),
                        "subjects": len(g),
                    }
                )
            rows = pd.DataFrame(groups)
        _check_frame(rows, body, f"thesis {name}")
        return cls(body, rows.reset_index(drop=True), f"thesis {what}", dict(THESIS_RESOLUTION))

    @classmethod
    def from_csv(
        cls,
        path_or_file: str | os.PathLike[str] | IO[str],
        body: str = "free_link",
        resolution: Mapping[str, float] | None = None,
    ) -> Measurements:
        """Read measurements from a CSV file with the columns of the thesis's table for
        ``body`` (see :attr:`rows`; other columns are kept and ignored).

        Raises :class:`~granrs.errors.MeasurementError` naming the file, the row (the line of
        the file; the header is line 1) and the column when a column is missing, a cell is
        not a number, a mean is not finite and > 0 or an sd is not finite and >= 0, a chain
        case lacks one of its links, or the file has no rows. ``resolution`` (default: none)
        as in :attr:`resolution`.
        """
        if body not in BODIES:
            raise UnknownNameError(
                f"unknown body {body!r}; measurements fit one of {', '.join(BODIES)}",
                field="body",
            )
        if isinstance(path_or_file, (str, os.PathLike)):
            name = os.fspath(path_or_file)
            try:
                with open(name, encoding="utf-8-sig", newline="") as handle:
                    rows = _read_csv(handle, name, body)
            except OSError as error:
                raise MeasurementError(
                    f"cannot read measurements {name}: {error.strerror or error}",
                    field="measurements",
                ) from None
        else:
            name = str(getattr(path_or_file, "name", "<file>"))
            rows = _read_csv(path_or_file, name, body)
        res = {"depth": 0.0, "t_s": 0.0}
        res.update(resolution or {})
        return cls(body, rows, name, res)

    @classmethod
    def load(cls, spec: str | os.PathLike[str], body: str | None = None) -> Measurements:
        """``"thesis:NAME"`` or a thesis name (see :meth:`thesis`), or a CSV path read with
        :meth:`from_csv` for ``body`` (default ``"free_link"``)."""
        text = os.fspath(spec)
        name = text.removeprefix("thesis:")
        if text.startswith("thesis:") or name in THESIS_MEASUREMENTS:
            m = cls.thesis(name)
            if body is not None and body != m.body:
                raise InvalidParameterError(
                    f"thesis {name} measures the {m.body}, not the {body}", field="body"
                )
            return m
        return cls.from_csv(text, body or "free_link")

    def subset(self, mask: Any = None, **columns: Any) -> Measurements:
        """The rows where ``mask`` (a boolean array) holds and every ``column=values`` matches
        (one value or a list), e.g. ``subset(q_deg=[0, 45, 75])``."""
        keep = np.ones(len(self.rows), dtype=bool)
        if mask is not None:
            keep &= np.asarray(mask, dtype=bool)
        for name, values in columns.items():
            if name not in self.rows.columns:
                hint = difflib.get_close_matches(name, list(self.rows.columns), n=1)
                more = f"; did you mean {hint[0]!r}?" if hint else ""
                raise UnknownNameError(f"measurements have no column {name!r}{more}", field=name)
            vals = list(values) if isinstance(values, (list, tuple, set, np.ndarray)) else [values]
            keep &= self.rows[name].isin(vals).to_numpy()
        return Measurements(
            self.body, self.rows[keep].reset_index(drop=True), self.source, dict(self.resolution)
        )

    def sd_fit(self, quantity: str) -> np.ndarray:
        """The sd of ``quantity`` used as the fit's weight: measured sd and rounding in
        quadrature [m or s]."""
        sd = self.rows[f"{quantity}_sd"].to_numpy(dtype=float)
        r = float(self.resolution.get(quantity, 0.0))
        return np.sqrt(sd**2 + r**2 / 12.0)


def _check_frame(rows: pd.DataFrame, body: str, name: str) -> None:
    """The checks of :func:`_read_csv` on a frame (for the shipped tables)."""
    for column in (*_KEY_COLUMNS[body], *_VALUE_COLUMNS):
        if column not in rows.columns:
            raise MeasurementError(f"{name}: missing column {column!r}", field=column)


def _read_csv(handle: IO[str], filename: str, body: str) -> pd.DataFrame:
    required = (*_KEY_COLUMNS[body], *_VALUE_COLUMNS)
    try:
        reader = csv.DictReader(handle, strict=True)
        if reader.fieldnames is None:
            raise MeasurementError(f"{filename}: the file is empty", field="measurements")
        reader.fieldnames = [name.strip() for name in reader.fieldnames]
        for column in required:
            if column not in reader.fieldnames:
                raise MeasurementError(
                    f"{filename}, row 1 (header): missing column {column!r}; the {body} needs "
                    f"{', '.join(required)}",
                    field=column,
                )
        records: list[dict[str, Any]] = []
        for record in reader:
            row = reader.line_num
            if not any((v or "").strip() for v in record.values() if isinstance(v, str)):
                continue
            out: dict[str, Any] = {k: v for k, v in record.items() if k is not None}
            for column in required:
                cell = record.get(column)
                try:
                    value = float((cell or "").strip())
                except ValueError:
                    raise MeasurementError(
                        f"{filename}, row {row}, column {column!r}: {cell!r} is not a number",
                        field=column,
                    ) from None
                bad = not math.isfinite(value)
                if column.endswith("_sd"):
                    bad = bad or value < 0.0
                    what = "a finite sd >= 0"
                elif column in ("t_s_mean", "depth_mean", "v0_mean"):
                    bad = bad or value <= 0.0
                    what = "a finite mean > 0"
                elif column == "link":
                    bad = bad or value not in (1.0, 2.0)
                    what = "1 or 2"
                else:
                    what = "finite"
                if column in ("q_deg", "q0_deg") and not bad and abs(value) >= 90.0:
                    bad, what = True, "an angle with |q| < 90 deg"
                if bad:
                    raise MeasurementError(
                        f"{filename}, row {row}, column {column!r}: {cell!r} must be {what}",
                        field=column,
                    )
                out[column] = value
            out["_line"] = row
            records.append(out)
    except UnicodeDecodeError as error:
        raise MeasurementError(
            f"{filename}: not a UTF-8 text file ({error})", field="measurements"
        ) from error
    except csv.Error as error:
        raise MeasurementError(
            f"{filename}: not a valid CSV file ({error})", field="measurements"
        ) from error
    if not records:
        raise MeasurementError(f"{filename}: no data rows", field="measurements")
    frame = pd.DataFrame(records)
    if body == "chain":
        for case, g in frame.groupby("v0_case"):
            links = sorted(g["link"])
            if links != [1.0, 2.0]:
                raise MeasurementError(
                    f"{filename}, row {int(g['_line'].iloc[0])}, column 'link': chain case "
                    f"{case:g} needs one row for link 1 and one for link 2; got links {links}",
                    field="link",
                )
    return frame.drop(columns="_line")


# --------------------------------------------------------------------------------------------
# Parameters


@dataclass(frozen=True)
class _Param:
    """One fitted parameter: ``kind`` is coef, node, scale or joint."""

    name: str
    kind: str
    target: str
    node: float = math.nan

    @property
    def log(self) -> bool:
        return self.target != "lam" or self.kind == "scale"

    def default_bounds(self) -> tuple[float, float]:
        if self.kind == "scale":
            return _DEFAULT_BOUNDS["scale"]
        if self.kind == "joint":
            return _DEFAULT_BOUNDS[f"joints.{self.target}"]
        return _DEFAULT_BOUNDS[self.target]


def _known_names(body: str) -> list[str]:
    names = [*_COEFS, *(f"scale.{c}" for c in _COEFS)]
    if body == "free_link":
        names += [f"{c}@45" for c in _COEFS]
    if body == "leg":
        names += [f"joints.{j}" for j in _JOINTS]
    return names


_NODE = re.compile(r"^(eta_h|eta_d|eta_v|lam|lambda)@([-+]?\d+(\.\d*)?)$")


def _parse_param(name: Any, body: str) -> _Param:
    if not isinstance(name, str):
        raise InvalidParameterError(f"parameter names are strings; got {name!r}", field="params")
    plain = name.replace("lambda", "lam")
    if plain in _COEFS:
        return _Param(plain, "coef", plain)
    if plain.startswith("scale.") and plain[6:] in _COEFS:
        return _Param(plain, "scale", plain[6:])
    match = _NODE.match(name)
    if match and body == "free_link":
        q = abs(float(match.group(2)))
        if q >= 90.0:
            raise InvalidParameterError(
                f"parameter {name!r}: the angle node must be |q| < 90 deg", field=name
            )
        target = match.group(1).replace("lambda", "lam")
        return _Param(f"{target}@{q:g}", "node", target, q)
    if body == "leg" and plain.startswith("joints.") and plain[7:] in _JOINTS:
        return _Param(plain, "joint", plain[7:])
    known = _known_names(body)
    hint = difflib.get_close_matches(name, known, n=1)
    more = f"; did you mean {hint[0]!r}?" if hint else ""
    extra = " (angle nodes 'eta_v@45' are for the free link)" if match else ""
    raise UnknownNameError(
        f"unknown parameter {name!r} for the {body}{more}{extra}; parameters are "
        f"{', '.join(_COEFS)}, <coef>@<q_deg> (free link), scale.<coef>"
        + (", joints.k, joints.c" if body == "leg" else ""),
        field=name,
    )


# --------------------------------------------------------------------------------------------
# The model: parameters -> scenes -> simulated values


@dataclass
class _Model:
    body: str
    params: tuple[_Param, ...]
    base: Any
    dt: float
    overrides: dict[str, Any]
    fixed_joints: dict[str, float]
    #: Per vector and row of the last :meth:`simulate`: the step did not resolve the run.
    last_unresolved: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=bool))

    def to_internal(self, values: Sequence[float]) -> np.ndarray:
        return np.array(
            [math.log(v) if p.log else v for p, v in zip(self.params, values, strict=True)]
        )

    def to_natural(self, x: Sequence[float]) -> np.ndarray:
        return np.array([math.exp(u) if p.log else u for p, u in zip(self.params, x, strict=True)])

    # base coefficients -------------------------------------------------------------------
    def base_coefficients(self, row: Mapping[str, Any]) -> Coefficients:
        if isinstance(self.base, Coefficients):
            return self.base
        if self.body == "free_link":
            if self.base == "table_3_2":
                return table_3_2(row["q_deg"], self.overrides.get("rho_g", 1650.0))
            return table_3_4(row["q_deg"])[0]
        if self.body == "chain":
            case = int(row["v0_case"])
            spec = _cases.chain_case(case)
            return spec["coefficients"][int(row["link"]) - 1]
        table = data.load("human_coefficients", as_="numpy")
        i = int(np.argmin(np.abs(table["v0"] - row["v0_mean"])))
        return Coefficients(
            eta_h=float(table["eta_h"][i]),
            eta_d=float(table["eta_d"][i]),
            eta_v=float(table["eta_v"][i]),
            lam=float(table["lambda"][i]),
        )

    def coefficients(self, row: Mapping[str, Any], values: Sequence[float]) -> Coefficients:
        """The coefficients of one row (one link) at the natural parameter ``values``."""
        c = self.base_coefficients(row).as_dict()
        nodes: dict[str, list[tuple[float, float]]] = {}
        for p, v in zip(self.params, values, strict=True):
            if p.kind == "scale":
                c[p.target] *= v
            elif p.kind == "coef":
                c[p.target] = v
            elif p.kind == "node":
                nodes.setdefault(p.target, []).append((p.node, v))
        if nodes:
            q = abs(float(row.get("q_deg", row.get("q0_deg", 0.0))))
            for target, pts in nodes.items():
                pts.sort()
                xs = np.array([a for a, _ in pts])
                ys = np.array([b for _, b in pts])
                if target == "lam":
                    c[target] = float(np.interp(q, xs, ys))
                else:
                    c[target] = float(np.exp(np.interp(q, xs, np.log(ys))))
        return Coefficients(**c)

    def scenes(self, rows: pd.DataFrame, values: Sequence[float]) -> list[Scene]:
        """One scene per run: per row (free link, leg) or per chain case (two rows)."""
        records = rows.to_dict("records")
        if self.body == "free_link":
            return [
                _cases.free_link(
                    r["q_deg"],
                    r["v0_mean"],
                    coefficients=self.coefficients(r, values),
                    dt=self.dt,
                    **self.overrides,
                )
                for r in records
            ]
        if self.body == "leg":
            joints: Any = None
            named = {
                p.target: v for p, v in zip(self.params, values, strict=True) if p.kind == "joint"
            }
            if named or self.fixed_joints:
                joints = {**_JOINT_START, **self.fixed_joints, **named}
            return [
                _cases.leg(
                    r["v0_mean"],
                    coefficients=self.coefficients(r, values),
                    joints=joints,
                    dt=self.dt,
                    **self.overrides,
                )
                for r in records
            ]
        out = []
        for link1, link2 in _chain_pairs(rows):
            r1, r2 = records[link1], records[link2]
            case = int(r1["v0_case"])
            overrides = {"end": "all_stops", **self.overrides}
            overrides.setdefault("v0", 0.5 * (r1["v0_mean"] + r2["v0_mean"]))
            out.append(
                _cases.chain(
                    case=case if case in (1, 2, 3) else 1,
                    q1_deg=r1["q0_deg"],
                    q2_deg=r2["q0_deg"],
                    coefficients=(self.coefficients(r1, values), self.coefficients(r2, values)),
                    dt=self.dt,
                    **overrides,
                )
            )
        return out

    def simulate(
        self, rows: pd.DataFrame, vectors: Sequence[Sequence[float]], threads: int | None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Simulated (depth, t_s, ok) per vector and row: arrays (len(vectors), len(rows)).

        All vectors' scenes run in one sweep. A run that does not stop before its end time
        gets t_s = its end time (a lower bound); one that fails gets NaN and ok = False.
        """
        from .batch import sweep

        scenes: list[Scene] = []
        invalid = np.zeros(len(vectors), dtype=bool)
        n_runs = len(rows) if self.body != "chain" else len(_chain_pairs(rows))
        for v, values in enumerate(vectors):
            try:
                scenes += self.scenes(rows, values)
            except InvalidSceneError:
                # A value the core refuses (e.g. a damper past RK4's stability limit) is a
                # failed point of the fit, not an error: the optimizer steps back.
                invalid[v] = True
        depth = np.full((len(vectors), len(rows)), np.nan)
        t_s = np.full_like(depth, np.nan)
        ok = np.zeros_like(depth, dtype=bool)
        if not scenes:
            self.last_unresolved = np.zeros_like(depth, dtype=bool)
            return depth, t_s, ok
        with warnings.catch_warnings():
            # Runs the step did not resolve are counted (``unresolved``), not warned about
            # once per sweep of a fit.
            warnings.simplefilter("ignore", _StepSizeWarning)
            frame = sweep(scenes, threads=threads, progress=False)
        failed = (frame["status"] == "failed").to_numpy()
        run_unresolved = np.zeros(len(frame), dtype=bool)
        if "unresolved" in frame.columns:
            run_unresolved |= frame["unresolved"].to_numpy(dtype=float) > 0
        if "h_lambda" in frame.columns:
            run_unresolved |= frame["h_lambda"].to_numpy(dtype=float) > _RK4_LIMIT
        unresolved = np.zeros((len(vectors), len(rows)), dtype=bool)
        valid = np.flatnonzero(~invalid)
        if self.body == "chain":
            pairs = _chain_pairs(rows)
            for slot, v in enumerate(valid):
                for j, (i1, i2) in enumerate(pairs):
                    k = slot * n_runs + j
                    for link, i in ((0, i1), (1, i2)):
                        t = frame[f"c{link}.t_s"].iloc[k]
                        depth[v, i] = frame[f"c{link}.depth"].iloc[k]
                        t_s[v, i] = t if math.isfinite(t) else frame["t_final"].iloc[k]
                        ok[v, i] = not failed[k]
                        unresolved[v, i] = run_unresolved[k]
        else:
            t = frame["t_s"].to_numpy(dtype=float)
            t = np.where(np.isfinite(t), t, frame["t_final"].to_numpy(dtype=float))
            shape = (len(valid), len(rows))
            depth[valid] = frame["depth"].to_numpy(dtype=float).reshape(shape)
            t_s[valid] = t.reshape(shape)
            ok[valid] = ~failed.reshape(shape)
            unresolved[valid] = run_unresolved.reshape(shape)
        self.last_unresolved = unresolved
        depth[~ok] = np.nan
        t_s[~ok] = np.nan
        return depth, t_s, ok


def _chain_pairs(rows: pd.DataFrame) -> list[tuple[int, int]]:
    """Index pairs (link 1 row, link 2 row) per chain case, in order of first appearance."""
    pairs = []
    seen: list[float] = []
    for case in rows["v0_case"]:
        if case in seen:
            continue
        seen.append(case)
        idx = np.flatnonzero(rows["v0_case"].to_numpy() == case)
        links = rows["link"].to_numpy()[idx]
        i1 = int(idx[np.flatnonzero(links == 1)[0]])
        i2 = int(idx[np.flatnonzero(links == 2)[0]])
        pairs.append((i1, i2))
    return pairs


# --------------------------------------------------------------------------------------------
# The result


def within(residuals: pd.DataFrame, quantity: str, k: float) -> int:
    """How many rows of ``residuals`` have ``|quantity_z| <= k`` (the simulated value within
    k measured sd of the measured mean)."""
    z = residuals[f"{quantity}_z"].to_numpy(dtype=float)
    return int(np.sum(np.abs(z) <= k + 1e-12))


@dataclass(frozen=True)
class CalibrationResult:
    """What :func:`calibrate` returns.

    Attributes:
        body: the body fitted.
        params: the fitted parameters' names, in order.
        values: fitted value of each parameter (natural units: coefficients dimensionless,
            ``joints.k`` N m/rad, ``joints.c`` N m s/rad).
        start: the starting value of each.
        std_errors: standard error of each (delta method from the fitted space; NaN when
            undetermined).
        intervals: ~95 % interval of each (+-1.96 standard errors in the fitted space, log
            or plain, mapped back).
        at_bound: parameters that ended on a bound (their interval is not reliable).
        residuals: one row per measurement: the key columns, measured mean and sd, simulated
            value, ``<q>_z`` = (simulated - mean) / measured sd, ``<q>_zfit`` the same over
            the fit's sd, and ``<q>_z_start`` at the start; for q in depth, t_s.
        cost: half the sum of the squared weighted residuals at the optimum.
        chi2: the sum of the squared weighted residuals; ``dof`` = residuals - parameters.
        error_scale: the factor applied to the standard errors (sqrt of the reduced chi2
            when above 1 and ``error_scale="auto"``, else 1).
        correlation: the parameters' correlation matrix.
        simulations: simulations run by the fit (every sweep, Jacobians included).
        seconds: wall time of the fit [s].
        nfev, njev: residual and Jacobian evaluations.
        success, message: scipy's convergence flag and message.
        failed_runs: simulations that failed (SimulationError) during the fit.
        unresolved_runs: simulations during the fit whose step did not resolve the contact
            (the core's :class:`~granrs.StepSizeWarning` check; counted, not warned); the
            ``unresolved`` column of :attr:`residuals` flags them at the optimum.
    """

    body: str
    params: tuple[str, ...]
    values: dict[str, float]
    start: dict[str, float]
    std_errors: dict[str, float]
    intervals: dict[str, tuple[float, float]]
    at_bound: tuple[str, ...]
    residuals: pd.DataFrame
    cost: float
    chi2: float
    dof: int
    error_scale: float
    correlation: np.ndarray
    simulations: int
    seconds: float
    nfev: int
    njev: int
    success: bool
    message: str
    failed_runs: int
    unresolved_runs: int
    _model: _Model = field(repr=False, compare=False)
    _measurements: Measurements = field(repr=False, compare=False)
    _threads: int | None = field(default=None, repr=False, compare=False)

    def predict(self, measurements: Measurements) -> pd.DataFrame:
        """The residuals (as in :attr:`residuals`, without the start columns) of other
        measurements of the same body at the fitted values: an out-of-sample check."""
        _check_measurements(measurements, self.body)
        values = [self.values[p] for p in self.params]
        depth, t_s, _ = self._model.simulate(measurements.rows, [values], self._threads)
        frame = _residual_frame(measurements, depth[0], t_s[0])
        frame["unresolved"] = self._model.last_unresolved[0]
        return frame

    def coefficients(self, row: Mapping[str, Any]) -> Coefficients:
        """The fitted coefficients for one measurement row (e.g. ``{"q_deg": 60,
        "v0_mean": 1.5}``; the chain's rows need ``link`` and ``v0_case``)."""
        return self._model.coefficients(row, [self.values[p] for p in self.params])

    def within(self, quantity: str, k: float) -> int:
        """Rows with the fitted simulation within ``k`` measured sd (see :func:`within`)."""
        return within(self.residuals, quantity, k)

    def summary(self) -> str:
        """A few lines of text: the parameters with intervals, the fit, its cost."""
        lines = [
            f"calibration of the {self.body}: {len(self.residuals)} rows, "
            f"{len(self.params)} parameters; chi2 = {self.chi2:.3g} on {self.dof} dof; "
            f"{self.simulations} simulations in {self.seconds:.2f} s; {self.message}"
        ]
        for p in self.params:
            lo, hi = self.intervals[p]
            flag = " (at bound)" if p in self.at_bound else ""
            lines.append(
                f"  {p:<12} {self.values[p]:12.5g}  start {self.start[p]:10.4g}  "
                f"se {self.std_errors[p]:10.3g}  95% [{lo:.4g}, {hi:.4g}]{flag}"
            )
        for q in QUANTITIES:
            lines.append(
                f"  {q}: within 1 sd {self.within(q, 1)}, within 2 sd {self.within(q, 2)} "
                f"of {len(self.residuals)}"
            )
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """Plain data (what ``granrs calibrate --json`` prints)."""
        return {
            "body": self.body,
            "params": list(self.params),
            "values": self.values,
            "start": self.start,
            "std_errors": self.std_errors,
            "intervals": {k: list(v) for k, v in self.intervals.items()},
            "at_bound": list(self.at_bound),
            "chi2": self.chi2,
            "dof": self.dof,
            "error_scale": self.error_scale,
            "simulations": self.simulations,
            "seconds": self.seconds,
            "nfev": self.nfev,
            "njev": self.njev,
            "success": self.success,
            "message": self.message,
            "failed_runs": self.failed_runs,
            "unresolved_runs": self.unresolved_runs,
            "within": {q: {"1sd": self.within(q, 1), "2sd": self.within(q, 2)} for q in QUANTITIES},
            "residuals": self.residuals.to_dict("records"),
        }


def _residual_frame(m: Measurements, depth: np.ndarray, t_s: np.ndarray) -> pd.DataFrame:
    keys = [c for c in _KEY_COLUMNS[m.body] if c in m.rows.columns]
    extra = [c for c in ("height_case", "subject") if c in m.rows.columns]
    out = m.rows[extra + keys].copy()
    for q, sim in (("depth", depth), ("t_s", t_s)):
        mean = m.rows[f"{q}_mean"].to_numpy(dtype=float)
        sd = m.rows[f"{q}_sd"].to_numpy(dtype=float)
        out[f"{q}_mean"] = mean
        out[f"{q}_sd"] = sd
        out[f"{q}_sim"] = sim
        with np.errstate(divide="ignore", invalid="ignore"):
            z = (sim - mean) / sd
        out[f"{q}_z"] = np.where((sd == 0) & (sim == mean), 0.0, z)
        out[f"{q}_zfit"] = (sim - mean) / m.sd_fit(q)
    return out


# --------------------------------------------------------------------------------------------
# calibrate


def _check_measurements(m: Any, body: str) -> Measurements:
    if isinstance(m, (str, os.PathLike)):
        m = Measurements.load(m, body)
    if not isinstance(m, Measurements):
        raise InvalidParameterError(
            "measurements must be a granrs.Measurements, a thesis name ('table_3_1', ...) or "
            f"a CSV path; got {type(m).__name__}",
            field="measurements",
        )
    if m.body != body:
        raise InvalidParameterError(
            f"the measurements are of the {m.body}, the cases of the {body}", field="cases"
        )
    if len(m) == 0:
        raise InvalidParameterError("no measurement rows to fit", field="measurements")
    return m


def _bounds_for(
    params: Sequence[_Param], bounds: Mapping[str, Any] | None
) -> list[tuple[float, float]]:
    given = dict(bounds or {})
    names = {p.name for p in params}
    for key in given:
        if key.replace("lambda", "lam") not in names:
            hint = difflib.get_close_matches(key, sorted(names), n=1)
            more = f"; did you mean {hint[0]!r}?" if hint else ""
            raise UnknownNameError(
                f"bounds given for {key!r}, which is not a fitted parameter{more}",
                field=f"bounds.{key}",
            )
    given = {k.replace("lambda", "lam"): v for k, v in given.items()}
    out = []
    for p in params:
        pair = given.get(p.name, p.default_bounds())
        try:
            lo, hi = (float(pair[0]), float(pair[1]))
            if len(pair) != 2:
                raise TypeError
        except (TypeError, ValueError, IndexError):
            raise InvalidParameterError(
                f"bounds for {p.name!r} must be a pair (low, high); got {pair!r}",
                field=f"bounds.{p.name}",
            ) from None
        if not (math.isfinite(lo) and math.isfinite(hi)) or not lo < hi:
            raise InvalidParameterError(
                f"bounds for {p.name!r} must be finite with low < high; got ({lo}, {hi})",
                field=f"bounds.{p.name}",
            )
        if p.log and lo <= 0.0:
            raise InvalidParameterError(
                f"bounds for {p.name!r} must be > 0 (it is fitted in log space); got low = {lo}",
                field=f"bounds.{p.name}",
            )
        if p.target == "lam" and p.kind != "scale" and lo < 0.0:
            raise InvalidParameterError(
                f"bounds for {p.name!r}: lambda must be >= 0; got low = {lo}",
                field=f"bounds.{p.name}",
            )
        out.append((lo, hi))
    return out


def calibrate(
    cases: str,
    measurements: Measurements | str | os.PathLike[str],
    params: Sequence[str] = ("eta_h", "eta_d", "eta_v", "lam"),
    *,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    start: Mapping[str, float] | None = None,
    base: str | Coefficients | None = None,
    per_angle: bool = False,
    quantities: Sequence[str] = QUANTITIES,
    joints: Mapping[str, float] | None = None,
    dt: float = 1e-4,
    rel_step: float = 1e-3,
    error_scale: str = "auto",
    starts: int = 1,
    seed: int = 0,
    max_nfev: int = 200,
    threads: int | None = None,
    **overrides: Any,
) -> CalibrationResult:
    """Fit ``params`` so that the simulated depth and stopping time match ``measurements``.

    Args:
        cases: the body, built per row by the :mod:`granrs.cases` function of that name:
            ``"free_link"`` (a row runs ``cases.free_link(q_deg, v0_mean)``), ``"chain"``
            (a case's two rows run ``cases.chain`` with both links' angles and the mean of
            their speeds, ``end="all_stops"``) or ``"leg"`` (``cases.leg(v0_mean)``).
        measurements: a :class:`Measurements`, a thesis name (``"table_3_1"``,
            ``"table_4_chain"``, ``"table_5_1_means"``, ...; ``"thesis:"`` may prefix it) or
            the path of a CSV with the same columns.
        params: the parameters to fit (see the module's notes): ``eta_h``, ``eta_d``,
            ``eta_v``, ``lam``; ``<coef>@<q_deg>`` angle nodes (free link);
            ``scale.<coef>``; ``joints.k``, ``joints.c`` (leg). The rest keep their base value.
        bounds: ``{name: (low, high)}`` in natural units; defaults: etas 1e-3..1e5 (eta_v
            1e-3..1e6), lambda 0..3, scale factors 1e-3..1e3, joints.k 1..1e5 N m/rad,
            joints.c 0.01..100 N m s/rad (the damper's rate must stay within RK4's stability
            limit at dt = 1e-4, about 150 N m s/rad for the foot).
        start: ``{name: value}``; default: the base value (at the row nearest the node for
            a node; 1 for a scale factor; k = 1000 N m/rad, c = 10 N m s/rad).
        base: the coefficients of what is not fitted: free link ``"table_3_4"`` (default;
            the nearest row) or ``"table_3_2"`` (closed forms at the row's angle); chain:
            Table 4.4 per link and case; leg: the thesis's row at the nearest speed (sec.
            5.3.2); or one :class:`~granrs.Coefficients` for every row.
        per_angle: free link: turn each plain coefficient name into one node per measured
            angle (``eta_v`` -> ``eta_v@0``, ``eta_v@45``, ...).
        quantities: which of ``"depth"``, ``"t_s"`` to fit (default both).
        joints: leg: fixed joint settings ``{"k": ..., "c": ...}`` for what is not fitted
            (default: locked joints unless ``joints.k`` or ``joints.c`` is fitted).
        dt: integration step [s] (default 1e-4, the thesis's 10 kHz).
        rel_step: forward-difference step of the Jacobian, relative (log-space parameters)
            or times max(|lambda|, 0.1) (lambda).
        error_scale: ``"auto"`` (multiply the standard errors by sqrt(chi2 / dof) when that
            is above 1) or ``"none"`` (trust the measured sd as they are).
        starts: the number of starts; beyond the first, each is drawn (seeded by ``seed``)
            uniformly in the fitted space within the bounds and +-2.3 (x10 for log
            parameters) of the start; the best fit is kept.
        max_nfev: residual evaluations allowed per start.
        threads: the sweep's worker threads (default: every core).
        **overrides: any other :class:`~granrs.Scene` field for every run (e.g.
            ``mass=0.017`` for the chain's links, ``apply_at="E"``).

    Returns:
        A :class:`CalibrationResult`.

    Raises:
        UnknownNameError: an unknown parameter, body or thesis table (did-you-mean in the
            message; ``field`` the name).
        InvalidParameterError: empty ``params`` or measurements, bounds not finite or not
            ordered, a start outside the bounds, a bad option (``field`` names it).
        MeasurementError: a measurements CSV that cannot be read (before any simulation).
    """
    from scipy.optimize import least_squares

    t0 = time.perf_counter()
    if not isinstance(cases, str) or cases not in BODIES:
        hint = difflib.get_close_matches(str(cases), BODIES, n=1)
        more = f"; did you mean {hint[0]!r}?" if hint else ""
        raise UnknownNameError(
            f"unknown cases {cases!r}{more}; calibrate fits {', '.join(BODIES)}", field="cases"
        )
    body = cases
    m = _check_measurements(measurements, body)
    if isinstance(params, str):
        params = [params]
    if not params:
        raise InvalidParameterError("no parameter to fit", field="params")
    parsed = [_parse_param(p, body) for p in params]
    if per_angle:
        if body != "free_link":
            raise InvalidParameterError("per_angle is for the free link", field="per_angle")
        angles = sorted({abs(float(q)) for q in m.rows["q_deg"]})
        expanded = []
        for p in parsed:
            if p.kind == "coef":
                expanded += [_Param(f"{p.target}@{q:g}", "node", p.target, q) for q in angles]
            else:
                expanded.append(p)
        parsed = expanded
    names = [p.name for p in parsed]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise InvalidParameterError(f"parameter {dupes[0]!r} is given twice", field=dupes[0])
    kinds = {p.target: p.kind for p in parsed if p.kind in ("coef", "node")}
    for p in parsed:
        if p.kind in ("coef", "node") and kinds[p.target] != p.kind:
            raise InvalidParameterError(
                f"{p.target} is fitted both as one value and per angle node; choose one",
                field=p.name,
            )
    qs = [quantities] if isinstance(quantities, str) else list(quantities)
    if not qs or any(q not in QUANTITIES for q in qs):
        raise UnknownNameError(
            f"quantities must be among {', '.join(QUANTITIES)}; got {quantities!r}",
            field="quantities",
        )
    n_res = len(m) * len(qs)
    if n_res < len(parsed):
        raise InvalidParameterError(
            f"{len(parsed)} parameters cannot be fitted to {n_res} measured values",
            field="params",
        )
    if base is None:
        base = "table_3_4" if body == "free_link" else "thesis"
    if isinstance(base, str):
        allowed = {
            "free_link": ("table_3_4", "table_3_2"),
            "chain": ("thesis", "table_4_4"),
            "leg": ("thesis",),
        }[body]
        if base not in allowed:
            raise UnknownNameError(
                f"unknown base {base!r} for the {body}; use {', '.join(allowed)} or a "
                "granrs.Coefficients",
                field="base",
            )
    elif not isinstance(base, Coefficients):
        raise InvalidParameterError(
            f"base must be a name or a granrs.Coefficients; got {type(base).__name__}",
            field="base",
        )
    for name, value, ok in (
        ("dt", dt, _is_number(dt) and math.isfinite(dt) and dt > 0),
        ("rel_step", rel_step, _is_number(rel_step) and 1e-8 <= rel_step <= 0.1),
        (
            "starts",
            starts,
            isinstance(starts, int) and not isinstance(starts, bool) and starts >= 1,
        ),
        (
            "max_nfev",
            max_nfev,
            isinstance(max_nfev, int) and not isinstance(max_nfev, bool) and max_nfev >= 1,
        ),
        ("error_scale", error_scale, error_scale in ("auto", "none")),
    ):
        if not ok:
            raise InvalidParameterError(f"invalid {name}: {value!r}", field=name)
    fixed = dict(joints or {})
    for key, value in fixed.items():
        if body != "leg" or key not in _JOINTS:
            raise InvalidParameterError(
                f"joints takes 'k' and 'c' for the leg; got {key!r}", field=f"joints.{key}"
            )
        if not _is_number(value) or not math.isfinite(value) or value < 0:
            raise InvalidParameterError(
                f"joints.{key} must be a finite number >= 0; got {value!r}", field=f"joints.{key}"
            )
    box = _bounds_for(parsed, bounds)
    model = _Model(body, tuple(parsed), base, float(dt), dict(overrides), fixed)

    # Start values.
    given_start = {k.replace("lambda", "lam"): v for k, v in dict(start or {}).items()}
    for key in given_start:
        if key not in names:
            hint = difflib.get_close_matches(key, names, n=1)
            more = f"; did you mean {hint[0]!r}?" if hint else ""
            raise UnknownNameError(
                f"start given for {key!r}, which is not a fitted parameter{more}",
                field=f"start.{key}",
            )
    records = m.rows.to_dict("records")
    x_start = []
    for p, (lo, hi) in zip(parsed, box, strict=True):
        if p.name in given_start:
            v = given_start[p.name]
            if not _is_number(v) or not lo <= v <= hi:
                raise InvalidParameterError(
                    f"start of {p.name!r} must be a number within its bounds [{lo}, {hi}]; "
                    f"got {v!r}",
                    field=f"start.{p.name}",
                )
            v = float(v)
        elif p.kind == "scale":
            v = 1.0
        elif p.kind == "joint":
            v = fixed.get(p.target, _JOINT_START[p.target])
        else:
            if p.kind == "node":
                row = min(records, key=lambda r: abs(abs(float(r["q_deg"])) - p.node))
                row = {**row, "q_deg": p.node}
            else:
                row = records[0]
            v = getattr(model.base_coefficients(row), p.target)
        x_start.append(min(max(v, lo), hi))
    # Build every scene once up front: bad overrides or values fail here, before any run.
    model.scenes(m.rows, x_start)

    lo_x = model.to_internal([b[0] for b in box])
    hi_x = model.to_internal([b[1] for b in box])
    x0 = model.to_internal(x_start)
    x0 = np.clip(x0, lo_x, hi_x)
    sd = {q: m.sd_fit(q) for q in qs}
    means = {q: m.rows[f"{q}_mean"].to_numpy(dtype=float) for q in qs}
    counters = {"sims": 0, "failed": 0, "unresolved": 0}
    n_runs = len(model.scenes(m.rows, x_start))

    def weighted(depth: np.ndarray, t_s: np.ndarray) -> np.ndarray:
        sims = {"depth": depth, "t_s": t_s}
        parts = [(sims[q] - means[q][None, :]) / sd[q][None, :] for q in qs]
        r = np.concatenate(parts, axis=1)
        return np.where(np.isfinite(r), r, _FAILED_RESIDUAL)

    def evaluate(xs: Sequence[np.ndarray]) -> np.ndarray:
        vectors = [model.to_natural(x) for x in xs]
        depth, t_s, ok = model.simulate(m.rows, vectors, threads)
        counters["sims"] += n_runs * len(xs)  # refused vectors count as attempted
        counters["failed"] += int(np.sum(~ok))
        counters["unresolved"] += int(np.sum(model.last_unresolved))
        return weighted(depth, t_s)

    cache: dict[bytes, np.ndarray] = {}

    def fun(x: np.ndarray) -> np.ndarray:
        key = np.asarray(x, dtype=float).tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = evaluate([x])[0]
        return cache[key]

    def steps(x: np.ndarray) -> np.ndarray:
        h = np.array(
            [
                rel_step if p.log else rel_step * max(abs(u), 0.1)
                for p, u in zip(parsed, x, strict=True)
            ]
        )
        # Step inwards where the forward step would leave the box.
        return np.where(x + h > hi_x, -h, h)

    def jac(x: np.ndarray) -> np.ndarray:
        h = steps(x)
        xs = [np.asarray(x, dtype=float)] + [x + h[i] * np.eye(len(x))[i] for i in range(len(x))]
        r = evaluate(xs)
        cache.clear()
        cache[np.asarray(x, dtype=float).tobytes()] = r[0]
        return ((r[1:] - r[0]) / h[:, None]).T

    rng = np.random.default_rng(seed)
    candidates = [x0]
    for _ in range(starts - 1):
        lo_s = np.maximum(lo_x, x0 - 2.3)
        hi_s = np.minimum(hi_x, x0 + 2.3)
        candidates.append(rng.uniform(lo_s, hi_s))
    best = None
    nfev = njev = 0
    for cand in candidates:
        try:
            fit = least_squares(
                fun,
                cand,
                jac=jac,
                bounds=(lo_x, hi_x),
                method="trf",
                x_scale="jac",
                max_nfev=max_nfev,
            )
        except SimulationError:  # pragma: no cover - runs fail into residuals, not raise
            raise
        nfev += fit.nfev
        njev += fit.njev or 0
        if best is None or fit.cost < best.cost:
            best = fit
    assert best is not None

    # Uncertainty from the Jacobian at the optimum.
    x = best.x
    jmat = jac(x)
    r = fun(x)
    chi2 = float(r @ r)
    dof = n_res - len(x)
    scale = 1.0
    if error_scale == "auto" and dof > 0 and chi2 / dof > 1.0:
        scale = math.sqrt(chi2 / dof)
    jtj = jmat.T @ jmat
    try:
        cov = np.linalg.pinv(jtj, rcond=1e-12, hermitian=True) * scale**2
        se_x = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    except np.linalg.LinAlgError:  # pragma: no cover
        cov = np.full((len(x), len(x)), np.nan)
        se_x = np.full(len(x), np.nan)
    rank = np.linalg.matrix_rank(jtj) if np.all(np.isfinite(jtj)) else 0
    if rank < len(x):
        # Directions the data do not determine: their errors are not finite.
        w, v = np.linalg.eigh(jtj)
        null = v[:, w <= w.max() * 1e-12]
        for i in range(len(x)):
            if np.any(np.abs(null[i]) > 1e-6):
                se_x[i] = math.inf
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.sqrt(np.diag(cov))
        corr = cov / np.outer(d, d)
    natural = model.to_natural(x)
    values, se, intervals = {}, {}, {}
    span = hi_x - lo_x
    at_bound = []
    for i, p in enumerate(parsed):
        values[p.name] = float(natural[i])
        lo_i, hi_i = x[i] - 1.96 * se_x[i], x[i] + 1.96 * se_x[i]
        if p.log:
            se[p.name] = float(natural[i] * se_x[i])
            intervals[p.name] = (_exp(lo_i), _exp(hi_i))
        else:
            se[p.name] = float(se_x[i])
            intervals[p.name] = (float(lo_i), float(hi_i))
        if min(x[i] - lo_x[i], hi_x[i] - x[i]) <= 1e-6 * max(span[i], 1.0):
            at_bound.append(p.name)

    # Residual tables at the optimum and at the start (one sweep).
    depth, t_s, _ = model.simulate(m.rows, [natural, model.to_natural(x0)], threads)
    counters["sims"] += 2 * n_runs
    flags = model.last_unresolved
    frame = _residual_frame(m, depth[0], t_s[0])
    frame["unresolved"] = flags[0] if flags.size else False
    start_frame = _residual_frame(m, depth[1], t_s[1])
    for q in QUANTITIES:
        frame[f"{q}_z_start"] = start_frame[f"{q}_z"]
    return CalibrationResult(
        body=body,
        params=tuple(names),
        values=values,
        start={p.name: float(v) for p, v in zip(parsed, model.to_natural(x0), strict=True)},
        std_errors=se,
        intervals=intervals,
        at_bound=tuple(at_bound),
        residuals=frame,
        cost=float(best.cost),
        chi2=chi2,
        dof=dof,
        error_scale=scale,
        correlation=corr,
        simulations=counters["sims"],
        seconds=time.perf_counter() - t0,
        nfev=nfev,
        njev=njev,
        success=bool(best.success),
        message=str(best.message),
        failed_runs=counters["failed"],
        unresolved_runs=counters["unresolved"],
        _model=model,
        _measurements=m,
        _threads=threads,
    )


def _exp(u: float) -> float:
    try:
        return math.exp(u)
    except OverflowError:
        return math.inf


def evaluate(
    cases: str,
    measurements: Measurements | str | os.PathLike[str],
    *,
    base: str | Coefficients | None = None,
    dt: float = 1e-4,
    threads: int | None = None,
    **overrides: Any,
) -> pd.DataFrame:
    """The residuals of ``measurements`` with the base coefficients, nothing fitted (e.g.
    the thesis's Table 3.4 rows): a frame as :attr:`CalibrationResult.residuals` without
    the start columns. Arguments as in :func:`calibrate`."""
    if not isinstance(cases, str) or cases not in BODIES:
        raise UnknownNameError(
            f"unknown cases {cases!r}; calibrate fits {', '.join(BODIES)}", field="cases"
        )
    m = _check_measurements(measurements, cases)
    if base is None:
        base = "table_3_4" if cases == "free_link" else "thesis"
    model = _Model(cases, (), base, float(dt), dict(overrides), {})
    depth, t_s, _ = model.simulate(m.rows, [[]], threads)
    frame = _residual_frame(m, depth[0], t_s[0])
    frame["unresolved"] = model.last_unresolved[0]
    return frame
