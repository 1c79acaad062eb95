"""The parameter model of a calibration: parameter names parsed (any term's parameter,
angle nodes, scale factors, the body's unknowns), their bounds and fitted space (log or
not), the law's terms per row, and the scenes and simulated depths and stopping times for
a set of parameter values.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import re
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import cases as _cases
from .. import data
from .. import forces as _forces
from ..coefficients import Coefficients, table_3_2, table_3_4
from ..errors import (
    InvalidParameterError,
    InvalidSceneError,
    UnknownNameError,
)
from ..scene import Scene

if TYPE_CHECKING:
    import pandas as pd

try:  # the core's step-resolution check (newer builds)
    from ..api import RK4_STABILITY_LIMIT as _RK4_LIMIT
    from ..errors import StepSizeWarning as _StepSizeWarning
except ImportError:  # pragma: no cover - older builds have neither
    _RK4_LIMIT = math.inf

    class _StepSizeWarning(UserWarning):  # type: ignore[no-redef]
        """Stand-in: never raised."""


__all__: list[str] = []  # all of it is internal to granrs.calibrate

#: The thesis's coefficients by their short names: the term and parameter each is.
ALIASES: Mapping[str, tuple[str, str]] = _forces.THESIS_COLUMNS
_COEFS = tuple(ALIASES)
_JOINTS = ("k", "c")
#: A body's unknowns that a fit may take, by body: Scene fields (``mass``: the link mass
#: [kg]; the free link's is measured, the chain's is not in the thesis) and the leg's joints.
BODY_PARAMS: dict[str, tuple[str, ...]] = {
    "free_link": ("mass",),
    "chain": ("mass", "pin_mass"),
    "leg": ("joints.k", "joints.c"),
    "space": (),
}
#: Parameters fitted as they are (not in log space): exponents, which may be 0.
_PLAIN: frozenset[tuple[str, str]] = frozenset({("static_v", "lam")})
#: Default bounds in natural units, by kind.
_DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    "eta_h": (1e-3, 1e5),
    "eta_d": (1e-3, 1e5),
    "eta_v": (1e-3, 1e6),
    "lam": (0.0, 3.0),
    "scale": (1e-3, 1e3),
    "joints.k": (1.0, 1e5),
    "joints.c": (1e-2, 100.0),
    "mass": (1e-4, 100.0),
    "pin_mass": (1e-4, 100.0),
}
#: Start of the joint settings when not given [N m/rad], [N m s/rad].
_JOINT_START: dict[str, float] = {"k": 1000.0, "c": 10.0}


# --------------------------------------------------------------------------------------------
# Parameters


@dataclass(frozen=True)
class _Param:
    """One fitted parameter.

    ``kind`` is ``coef`` (a term's parameter, one value for every row), ``node`` (a term's
    parameter at an angle node), ``scale`` (a factor on a term's base parameter), ``joint``
    (the leg's joints: ``target`` k or c) or ``body`` (a Scene field: ``target``)."""

    name: str
    kind: str
    target: str
    term: str = ""
    node: float = math.nan

    @property
    def key(self) -> str:
        """``term.param`` for a term's parameter, else the name."""
        return f"{self.term}.{self.target}" if self.term else self.name

    @property
    def log(self) -> bool:
        if self.kind in ("scale", "joint", "body"):
            return True
        if (self.term, self.target) in _PLAIN:
            return False
        return _param_info(self.term, self.target).min >= 0.0

    def default_bounds(self) -> tuple[float, float]:
        if self.kind == "scale":
            return _DEFAULT_BOUNDS["scale"]
        if self.kind == "joint":
            return _DEFAULT_BOUNDS[f"joints.{self.target}"]
        if self.kind == "body":
            return _DEFAULT_BOUNDS[self.target]
        if (self.term, self.target) in ALIASES.values():
            return _DEFAULT_BOUNDS[self.target]
        default = _param_info(self.term, self.target).default
        if math.isfinite(default) and default > 0.0:
            return (default * 1e-3, default * 1e3)
        raise InvalidParameterError(
            f"{self.name} has no default to take bounds from; give bounds[{self.name!r}] = "
            "(low, high)",
            field=f"bounds.{self.name}",
        )


def _param_info(term: str, param: str) -> Any:
    """The registry's description of ``term.param`` (unknown names raise, with a hint)."""
    info = _forces.info(term)
    for p in info.params:
        if p.name == param:
            return p
    names = [p.name for p in info.params]
    hint = difflib.get_close_matches(param, names, n=1)
    more = f"; did you mean {term + '.' + hint[0]!r}?" if hint else ""
    raise UnknownNameError(
        f"the term {term!r} has no parameter {param!r}{more} (its parameters: "
        f"{', '.join(names) or 'none'})",
        field=f"{term}.{param}",
    )


def _known_names(body: str) -> list[str]:
    names = [*_COEFS, *(f"scale.{c}" for c in _COEFS)]
    names += [f"{t}.{p.name}" for t in _forces.TERMS for p in _forces.info(t).params]
    if body == "free_link":
        names += [f"{c}@45" for c in _COEFS]
    names += list(BODY_PARAMS[body])
    return names


_NODE = re.compile(r"^(.+)@([-+]?\d+(\.\d*)?)$")


def _term_param(text: str, full: str) -> tuple[str, str] | None:
    """``(term, param)`` for a short coefficient name or ``term.param``; None if neither
    (an unknown parameter of a known term raises)."""
    plain = text.replace("lambda", "lam")
    if plain in ALIASES:
        return ALIASES[plain]
    if "." in plain:
        term, param = plain.split(".", 1)
        if term in _forces.TERMS:
            _param_info(term, param)
            return term, param
        if term not in ("scale", "joints"):
            hint = difflib.get_close_matches(term, _forces.TERMS, n=1)
            more = f"; did you mean {hint[0]!r}?" if hint else ""
            raise UnknownNameError(
                f"parameter {full!r}: no term {term!r}{more} (terms: {', '.join(_forces.TERMS)})",
                field=full,
            )
    return None


def _parse_param(name: Any, body: str) -> _Param:
    if not isinstance(name, str):
        raise InvalidParameterError(f"parameter names are strings; got {name!r}", field="params")
    plain = name.replace("lambda", "lam")
    if plain.startswith("scale."):
        tp = _term_param(plain[6:], name)
        if tp is not None:
            return _Param(plain, "scale", tp[1], tp[0])
    match = _NODE.match(plain)
    if match:
        tp = _term_param(match.group(1), name)
        if tp is not None and body == "free_link":
            q = abs(float(match.group(2)))
            if q >= 90.0:
                raise InvalidParameterError(
                    f"parameter {name!r}: the angle node must be |q| < 90 deg", field=name
                )
            return _Param(f"{match.group(1)}@{q:g}", "node", tp[1], tp[0], q)
    else:
        tp = _term_param(plain, name)
        if tp is not None:
            return _Param(plain, "coef", tp[1], tp[0])
    if plain in BODY_PARAMS[body]:
        if plain.startswith("joints."):
            return _Param(plain, "joint", plain[7:])
        return _Param(plain, "body", plain)
    known = _known_names(body)
    hint = difflib.get_close_matches(name, known, n=1)
    more = f"; did you mean {hint[0]!r}?" if hint else ""
    extra = " (angle nodes 'eta_v@45' are for the free link)" if match else ""
    raise UnknownNameError(
        f"unknown parameter {name!r} for the {body}{more}{extra}; parameters are "
        f"{', '.join(_COEFS)} or any term's TERM.PARAM (e.g. static_v.eta_v), "
        f"<param>@<q_deg> (free link), scale.<param>, and the body's "
        f"{', '.join(BODY_PARAMS[body])}",
        field=name,
    )


# --------------------------------------------------------------------------------------------
# The model: parameters -> scenes -> simulated values

#: A law given to the model: terms for every row, or a function of the row giving them.
LawSpec = Sequence[_forces.Term] | Callable[[Mapping[str, Any]], Sequence[_forces.Term]]


def base_coefficients(
    body: str, row: Mapping[str, Any], base: Any = None, rho_g: float = 1650.0
) -> Coefficients:
    """The thesis's published coefficients of one measurement row: free link Table 3.4's
    nearest row (``base="table_3_2"``: the closed forms at the row's angle), chain Table 4.4
    per link and case, leg the row of sec. 5.3.2 at the nearest speed; or ``base`` itself
    if it is a :class:`~granrs.Coefficients`."""
    if isinstance(base, Coefficients):
        return base
    if body == "free_link":
        if base == "table_3_2":
            return table_3_2(row["q_deg"], rho_g)
        return table_3_4(row["q_deg"])[0]
    if body == "chain":
        case = int(row["v0_case"])
        spec = _cases.chain_case(case if case in (1, 2, 3) else 1)
        return spec["coefficients"][int(row["link"]) - 1]
    table = data.load("human_coefficients", as_="numpy")
    i = int(np.argmin(np.abs(table["v0"] - row["v0_mean"])))
    return Coefficients(
        eta_h=float(table["eta_h"][i]),
        eta_d=float(table["eta_d"][i]),
        eta_v=float(table["eta_v"][i]),
        lam=float(table["lambda"][i]),
    )


def _contact(row: Mapping[str, Any]) -> int:
    """The contact a measurement row is (the chain's link 2 is contact 1)."""
    return int(row["link"]) - 1 if "link" in row else 0


def _at(value: Any, i: int) -> float:
    return float(value[i]) if isinstance(value, tuple) else float(value)


def _merge(per_contact: Sequence[Sequence[_forces.Term]]) -> tuple[_forces.Term, ...]:
    """One term list from per-contact single-valued ones (the chain's two links): a
    parameter that differs between contacts becomes a tuple."""
    first = per_contact[0]
    names = [t.name for t in first]
    for other in per_contact[1:]:
        if [t.name for t in other] != names:
            raise InvalidParameterError(
                f"the links' laws list different terms: {names} and {[t.name for t in other]}",
                field="forces",
            )
    out = []
    for j, t in enumerate(first):
        params: dict[str, Any] = {}
        for k in t.params:
            vals = tuple(_at(c[j].params[k], 0) for c in per_contact)
            params[k] = vals[0] if all(v == vals[0] for v in vals) else vals
        out.append(_forces.Term(t.name, params))
    return tuple(out)


@dataclass
class _Model:
    body: str
    params: tuple[_Param, ...]
    base: Any
    dt: float
    overrides: dict[str, Any]
    fixed_joints: dict[str, float]
    #: The law's terms (None: the thesis's, from ``base``'s coefficients).
    law: LawSpec | None = None
    #: Bodies in space: the function of the row that makes its scene.
    scene_of: Callable[[dict[str, Any]], Any] | None = None
    #: Per vector and row of the last :meth:`simulate`: the step did not resolve the run.
    last_unresolved: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=bool))

    def to_internal(self, values: Sequence[float]) -> np.ndarray:
        return np.array(
            [math.log(v) if p.log else v for p, v in zip(self.params, values, strict=True)]
        )

    def to_natural(self, x: Sequence[float]) -> np.ndarray:
        return np.array([math.exp(u) if p.log else u for p, u in zip(self.params, x, strict=True)])

    # base law ----------------------------------------------------------------------------
    def base_coefficients(self, row: Mapping[str, Any]) -> Coefficients:
        return base_coefficients(self.body, row, self.base, self.overrides.get("rho_g", 1650.0))

    def base_terms(self, row: Mapping[str, Any]) -> tuple[_forces.Term, ...]:
        """The law's terms for one row (one contact), before the fitted parameters."""
        if self.law is None and self.body == "space":
            return tuple(self.space_scene(row).forces)
        if self.law is None:
            return _forces.thesis(self.base_coefficients(row))
        terms = self.law(row) if callable(self.law) else self.law
        i = _contact(row)
        return tuple(
            _forces.Term(t.name, {k: _at(v, i) for k, v in t.params.items()})
            for t in _forces.as_terms(terms)
        )

    def row_terms(
        self, row: Mapping[str, Any], values: Sequence[float], scene: Any = None
    ) -> tuple[Any, ...]:
        """The terms of one row (one contact) at the natural parameter ``values``; ``scene``:
        a body in space's scene of the row, already made (its forces are the law's base)."""
        given = scene.forces if scene is not None and self.law is None else None
        base_terms = self.base_terms(row) if given is None else tuple(given)
        terms = {t.name: dict(t.params) for t in base_terms}
        base = {name: dict(p) for name, p in terms.items()}
        nodes: dict[tuple[str, str], list[tuple[float, float, bool]]] = {}
        for p, v in zip(self.params, values, strict=True):
            if p.kind not in ("coef", "scale", "node"):
                continue
            if p.term not in terms:
                raise UnknownNameError(
                    f"parameter {p.name!r}: the term {p.term!r} is not in the law "
                    f"({', '.join(terms) or 'no terms'})",
                    field=p.name,
                )
            if p.kind == "scale":
                terms[p.term][p.target] = base[p.term][p.target] * v
            elif p.kind == "coef":
                terms[p.term][p.target] = v
            else:
                nodes.setdefault((p.term, p.target), []).append((p.node, v, p.log))
        if nodes:
            q = abs(float(row.get("q_deg", row.get("q0_deg", 0.0))))
            for (term, target), pts in nodes.items():
                pts.sort()
                xs = np.array([a for a, _, _ in pts])
                ys = np.array([b for _, b, _ in pts])
                if pts[0][2]:
                    terms[term][target] = float(np.exp(np.interp(q, xs, np.log(ys))))
                else:
                    terms[term][target] = float(np.interp(q, xs, ys))
        return tuple(_forces.Term(name, p) for name, p in terms.items())

    def coefficients(self, row: Mapping[str, Any], values: Sequence[float]) -> Coefficients:
        """The thesis's coefficients of one row (one link) at the natural parameter
        ``values`` (a view of its terms; raises if the law is not the thesis's)."""
        row_c = _forces.thesis_row(self.row_terms(row, values))
        if row_c is None:
            raise InvalidParameterError(
                "the law has no drag, static_h and static_v: no thesis coefficients; use terms()",
                field="forces",
            )
        return row_c

    def body_default(self, target: str) -> float:
        """A body field's value when not fitted: the override, else the case's default."""
        if target in self.overrides:
            return float(self.overrides[target])
        defaults = {"free_link": _cases.FREE_LINK, "chain": _cases.CHAIN}.get(self.body, {})
        return float(defaults.get(target, getattr(Scene, target, 0.0)))

    def body_values(self, values: Sequence[float]) -> tuple[dict[str, Any], Any]:
        """The Scene fields and the leg's joints at ``values``."""
        fields = dict(self.overrides)
        named = {}
        for p, v in zip(self.params, values, strict=True):
            if p.kind == "body":
                fields[p.target] = float(v)
            elif p.kind == "joint":
                named[p.target] = float(v)
        joints: Any = None
        if named or self.fixed_joints:
            joints = {**_JOINT_START, **self.fixed_joints, **named}
        return fields, joints

    def space_scene(self, row: Mapping[str, Any]) -> Any:
        """A body in space's scene of one row, from the caller's function (checked)."""
        from .. import space

        assert self.scene_of is not None
        scene = self.scene_of(dict(row))
        if not isinstance(scene, space.Scene):
            raise InvalidParameterError(
                "cases: the function of the measurement row must return a "
                f"granrs.space.Scene; got {type(scene).__name__}",
                field="cases",
            )
        return scene

    def scenes(self, rows: pd.DataFrame, values: Sequence[float]) -> list[Any]:
        """One scene per run: per row (free link, leg, space) or per chain case (two rows)."""
        records = rows.to_dict("records")
        if self.body == "space":
            out = []
            for r in records:
                # The caller's function runs once per row.
                scene = self.space_scene(r)
                terms = self.row_terms(r, values, scene)
                out.append(dataclasses.replace(scene, forces=terms, dt=self.dt))
            return out
        fields, joints = self.body_values(values)
        if self.body == "free_link":
            return [
                _cases.free_link(
                    r["q_deg"],
                    r["v0_mean"],
                    dt=self.dt,
                    **{**fields, "forces": self.row_terms(r, values)},
                )
                for r in records
            ]
        if self.body == "leg":
            return [
                _cases.leg(
                    r["v0_mean"],
                    joints=joints,
                    dt=self.dt,
                    **{**fields, "forces": self.row_terms(r, values)},
                )
                for r in records
            ]
        out = []
        for link1, link2 in _chain_pairs(rows):
            r1, r2 = records[link1], records[link2]
            case = int(r1["v0_case"])
            overrides = {"end": "all_stops", **fields}
            overrides.setdefault("v0", 0.5 * (r1["v0_mean"] + r2["v0_mean"]))
            overrides["forces"] = _merge([self.row_terms(r1, values), self.row_terms(r2, values)])
            out.append(
                _cases.chain(
                    case=case if case in (1, 2, 3) else 1,
                    q1_deg=r1["q0_deg"],
                    q2_deg=r2["q0_deg"],
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

        scenes: list[Any] = []
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
            # (A body in space's sweep has its own fixed columns.)
            planar = isinstance(scenes[0], Scene)
            outputs = _SWEEP_OUTPUTS if planar else None
            frame = sweep(scenes, threads=threads, progress=False, outputs=outputs)
        failed = (frame["status"] == "failed").to_numpy()
        run_unresolved = np.zeros(len(frame), dtype=bool)
        if "unresolved" in frame.columns:
            run_unresolved |= frame["unresolved"].to_numpy(dtype=float) > 0
        if "unresolved_stops" in frame.columns:
            run_unresolved |= frame["unresolved_stops"].to_numpy(dtype=float) > 0
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


#: The columns a fit's sweep reads (and so the only fields its runs compute): the depth and
#: t_s (the run's end for a run without a stop), and what says the step did not resolve a run.
_SWEEP_OUTPUTS = ("t_s", "depth", "t_final", "unresolved", "unresolved_stops", "h_lambda")


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
