"""The parameter model of a calibration: parameter names parsed (plain coefficients,
angle nodes, scale factors, joints), their bounds and fitted space (log or not), and the
scenes and simulated depths and stopping times for a set of parameter values.
"""

from __future__ import annotations

import difflib
import math
import re
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from .. import cases as _cases
from .. import data
from ..coefficients import Coefficients, table_3_2, table_3_4
from ..errors import (
    InvalidParameterError,
    InvalidSceneError,
    UnknownNameError,
)
from ..scene import Scene

try:  # the core's step-resolution check (newer builds)
    from ..api import RK4_STABILITY_LIMIT as _RK4_LIMIT
    from ..errors import StepSizeWarning as _StepSizeWarning
except ImportError:  # pragma: no cover - older builds have neither
    _RK4_LIMIT = math.inf

    class _StepSizeWarning(UserWarning):  # type: ignore[no-redef]
        """Stand-in: never raised."""


__all__: list[str] = []  # all of it is internal to granrs.calibrate

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
        from ..batch import sweep

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
