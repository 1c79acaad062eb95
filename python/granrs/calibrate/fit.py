"""The fit: :func:`calibrate` (weighted least squares over the parameter model, with
standard errors from the Jacobian), :class:`CalibrationResult`, :func:`evaluate` and
:func:`within`.
"""

from __future__ import annotations

import difflib
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._progress import progress_bar
from ..coefficients import Coefficients
from ..errors import (
    InvalidParameterError,
    SimulationError,
    UnknownNameError,
)
from . import posterior as _posterior
from .measurements import _KEY_COLUMNS, BODIES, QUANTITIES, Measurements, _is_number
from .model import _JOINT_START, _JOINTS, LawSpec, _Model, _Param, _parse_param
from .posterior import Posterior

if TYPE_CHECKING:
    import pandas as pd

    from ..media import MediumCard

__all__ = ["CalibrationResult", "calibrate", "evaluate", "within"]

#: steps back.
_FAILED_RESIDUAL = 1e3


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
        posterior: the posterior samples and their diagnostics
            (:class:`~granrs.calibrate.Posterior`) when calibrate was asked for
            them (``posterior=``), else None.
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
    posterior: Posterior | None = field(default=None, repr=False, compare=False)

    def predictive(
        self,
        measurements: Measurements | None = None,
        *,
        draws: int = 200,
        level: float = 0.9,
        seed: int = 0,
    ) -> pd.DataFrame:
        """Posterior predictive intervals of depth and t_s for each row of
        ``measurements`` (default: the fitted ones): the values simulated at ``draws``
        posterior samples (one sweep), their median and central ``level`` interval
        (``<q>_median``, ``<q>_lo``, ``<q>_hi``), beside the measured mean and sd. Needs
        ``calibrate(..., posterior=...)``."""
        if self.posterior is None:
            raise InvalidParameterError(
                "no posterior samples: calibrate with posterior=<steps>", field="posterior"
            )
        if isinstance(draws, bool) or not isinstance(draws, int) or draws < 2:
            raise InvalidParameterError(
                f"draws must be an integer >= 2; got {draws!r}", field="draws"
            )
        if not (isinstance(level, (int, float)) and 0.0 < level < 1.0):
            raise InvalidParameterError(f"level must be in (0, 1); got {level!r}", field="level")
        m = self._measurements if measurements is None else measurements
        _check_measurements(m, self.body)

        def simulate(vectors: Sequence[Sequence[float]]) -> tuple[np.ndarray, np.ndarray]:
            depth, t_s, _ = self._model.simulate(m.rows, vectors, self._threads)
            return depth, t_s

        pred = _posterior.predictive(simulate, self.posterior, draws, level, seed)
        keys = [c for c in _KEY_COLUMNS[m.body] if c in m.rows.columns]
        frame = m.rows[[*keys, "depth_mean", "depth_sd", "t_s_mean", "t_s_sd"]].copy()
        for k, v in pred.items():
            frame[k] = v
        return frame

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

    def terms(self, row: Mapping[str, Any]) -> tuple[Any, ...]:
        """The fitted law's terms for one measurement row (one contact: the chain's rows
        need ``link`` and ``v0_case``)."""
        return self._model.row_terms(row, [self.values[p] for p in self.params])

    def card(
        self,
        name: str,
        *,
        base: Any = None,
        description: str | None = None,
        source: str | None = None,
    ) -> MediumCard:
        """The fit as a medium card (:class:`granrs.media.MediumCard`; its ``save`` method
        writes its TOML file, which :func:`granrs.media.load` and a scene's ``medium=``
        read).

        Each fitted term's parameter becomes the card's value with its source (``source``,
        default: "fitted here" with the measurements and the method), its standard error
        as ``sd``, its ~95 % interval (level 0.95) and, when the fit sampled its posterior
        (``posterior=``), the samples. A factor ``scale.TERM.PARAM`` is written as the
        value it gives when every row's base value is the same; where they differ (the
        thesis's Table 3.4 per angle), and for angle nodes, the parameter is listed under
        the card's ``missing`` with the reason. The body's unknowns (``mass``, ``joints.k``,
        ...) are not the medium's and are left out. The scenes' ``rho_g`` is written when
        the card has none.

        Args:
            name: the card's name (a file stem).
            base: a card (name, path or :class:`~granrs.media.MediumCard`) to start from:
                its other values are kept; its ``rho_g`` must be the fit's.
            description: the card's description (default: the base's, or what wrote it).
            source: the source of every value written (default: "fitted here: ...").

        Raises:
            MediumError: ``base`` has another ``rho_g`` than the fit's scenes
                (``field="rho_g"``), or a value out of its parameter's range.
        """
        from .card import card_of

        return card_of(self, name, base=base, description=description, source=source)

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
        pair = given[p.name] if p.name in given else p.default_bounds()
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
        if not p.log and p.kind != "scale" and lo < 0.0:
            raise InvalidParameterError(
                f"bounds for {p.name!r}: lambda must be >= 0; got low = {lo}",
                field=f"bounds.{p.name}",
            )
        out.append((lo, hi))
    return out


def _check_law(law: Any) -> LawSpec | None:
    """The law's terms as given: None, a function of the row, or a list of terms (checked
    here: a typed error names the item)."""
    if law is None or callable(law):
        return law
    from ..forces import as_terms

    return as_terms(law, "forces")


def _check_body(cases: Any) -> str:
    """The body named by ``cases`` (one of :data:`BODIES`), with a did-you-mean if not; a
    function of the row (that makes a body in space's scene) is ``"space"``."""
    if callable(cases):
        return "space"
    if not isinstance(cases, str) or cases not in BODIES or cases == "space":
        hint = difflib.get_close_matches(str(cases), BODIES, n=1)
        more = f"; did you mean {hint[0]!r}?" if hint else ""
        raise UnknownNameError(
            f"unknown cases {cases!r}{more}; calibrate fits "
            f"{', '.join(b for b in BODIES if b != 'space')}, or bodies in space through a "
            "function of the measurement row that returns a granrs.space.Scene",
            field="cases",
        )
    return cases


def _parse_params(
    params: Sequence[str], body: str, m: Measurements, per_angle: bool
) -> list[_Param]:
    """The parameters to fit, parsed, with ``per_angle`` expanded into one node per
    measured angle; each name once, and no coefficient both plain and per node."""
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
                expanded += [_Param(f"{p.name}@{q:g}", "node", p.target, p.term, q) for q in angles]
            else:
                expanded.append(p)
        parsed = expanded
    names = [p.name for p in parsed]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise InvalidParameterError(f"parameter {dupes[0]!r} is given twice", field=dupes[0])
    seen: dict[str, _Param] = {}
    for p in parsed:
        key = (p.key + f"@{p.node:g}") if p.kind == "node" else f"{p.kind}:{p.key}"
        if p.kind == "coef":
            key = p.key
        if key in seen and seen[key].name != p.name:
            raise InvalidParameterError(
                f"{p.name!r} and {seen[key].name!r} are the same parameter", field=p.name
            )
        seen[key] = p
    kinds = {p.key: p.kind for p in parsed if p.kind in ("coef", "node")}
    for p in parsed:
        if p.kind in ("coef", "node") and kinds[p.key] != p.kind:
            raise InvalidParameterError(
                f"{p.key} is fitted both as one value and per angle node; choose one",
                field=p.name,
            )
    return parsed


def _check_quantities(quantities: Sequence[str] | str) -> list[str]:
    """The quantities to fit, as a list of names from :data:`QUANTITIES`."""
    qs = [quantities] if isinstance(quantities, str) else list(quantities)
    if not qs or any(q not in QUANTITIES for q in qs):
        raise UnknownNameError(
            f"quantities must be among {', '.join(QUANTITIES)}; got {quantities!r}",
            field="quantities",
        )
    return qs


def _check_base(base: str | Coefficients | None, body: str) -> str | Coefficients:
    """The base coefficients' name (the body's default for None) or the Coefficients."""
    if body == "space":
        if base is not None:
            raise InvalidParameterError(
                "a body in space has no thesis coefficients: its law is its scene's forces "
                "(or forces=)",
                field="base",
            )
        return "none"
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
    return base


def _check_options(dt: Any, rel_step: Any, starts: Any, max_nfev: Any, error_scale: Any) -> None:
    """Reject an invalid ``dt``, ``rel_step``, ``starts``, ``max_nfev`` or ``error_scale``
    (``field`` names it)."""
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


def _check_joints(joints: Mapping[str, float] | None, body: str) -> dict[str, float]:
    """The leg's fixed joint settings (``k``, ``c``: finite, >= 0) as a new dict."""
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
    return fixed


def _start_values(
    parsed: Sequence[_Param],
    box: Sequence[tuple[float, float]],
    start: Mapping[str, float] | None,
    model: _Model,
    m: Measurements,
    fixed: Mapping[str, float],
) -> list[float]:
    """The start of every parameter in natural units, clipped to its bounds: the given
    one, else 1 for a scale factor, the fixed or default joint setting, or the base value
    (at the row nearest the node for a node)."""
    names = [p.name for p in parsed]
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
        elif p.kind == "body":
            v = model.body_default(p.target)
        else:
            if p.kind == "node":
                row = min(records, key=lambda r: abs(abs(float(r["q_deg"])) - p.node))
                row = {**row, "q_deg": p.node}
            else:
                row = records[0]
            by_name = {t.name: t.params for t in model.base_terms(row)}
            if p.term not in by_name:
                raise UnknownNameError(
                    f"parameter {p.name!r}: the term {p.term!r} is not in the law "
                    f"({', '.join(by_name) or 'no terms'})",
                    field=p.name,
                )
            v = float(by_name[p.term][p.target])
        x_start.append(min(max(v, lo), hi))
    return x_start


class _Objective:
    """The weighted residuals of the fit as a function of the fitted (internal) parameter
    vector, and their forward-difference Jacobian, both run as one sweep; counts the
    simulations, failed and unresolved runs as it goes (``counters``)."""

    def __init__(
        self,
        model: _Model,
        m: Measurements,
        qs: Sequence[str],
        n_runs: int,
        rel_step: float,
        hi_x: np.ndarray,
        threads: int | None,
    ) -> None:
        self.model, self.m, self.qs, self.n_runs = model, m, qs, n_runs
        self.rel_step, self.hi_x, self.threads = rel_step, hi_x, threads
        self.sd = {q: m.sd_fit(q) for q in qs}
        self.means = {q: m.rows[f"{q}_mean"].to_numpy(dtype=float) for q in qs}
        self.counters = {"sims": 0, "failed": 0, "unresolved": 0}
        self.cache: dict[bytes, np.ndarray] = {}
        #: The progress bar the runs advance (set by calibrate), or None.
        self.bar: Any = None

    def weighted(self, depth: np.ndarray, t_s: np.ndarray) -> np.ndarray:
        """Residuals over sd_fit, one row per parameter vector; a failed run's are large."""
        sims = {"depth": depth, "t_s": t_s}
        parts = [(sims[q] - self.means[q][None, :]) / self.sd[q][None, :] for q in self.qs]
        r = np.concatenate(parts, axis=1)
        return np.where(np.isfinite(r), r, _FAILED_RESIDUAL)

    def evaluate(self, xs: Sequence[np.ndarray]) -> np.ndarray:
        """The weighted residuals of every vector of ``xs``, all in one sweep."""
        vectors = [self.model.to_natural(x) for x in xs]
        depth, t_s, ok = self.model.simulate(self.m.rows, vectors, self.threads)
        self.counters["sims"] += self.n_runs * len(xs)  # refused vectors count as attempted
        if self.bar is not None:
            self.bar.update(self.n_runs * len(xs))
        self.counters["failed"] += int(np.sum(~ok))
        self.counters["unresolved"] += int(np.sum(self.model.last_unresolved))
        return self.weighted(depth, t_s)

    def fun(self, x: np.ndarray) -> np.ndarray:
        """The residuals at ``x`` (the last point is cached: the Jacobian has it)."""
        key = np.asarray(x, dtype=float).tobytes()
        if key not in self.cache:
            self.cache.clear()
            self.cache[key] = self.evaluate([x])[0]
        return self.cache[key]

    def steps(self, x: np.ndarray) -> np.ndarray:
        """The forward-difference step of each parameter at ``x``."""
        rel_step = self.rel_step
        h = np.array(
            [
                rel_step if p.log else rel_step * max(abs(u), 0.1)
                for p, u in zip(self.model.params, x, strict=True)
            ]
        )
        # Step inwards where the forward step would leave the box.
        return np.where(x + h > self.hi_x, -h, h)

    def jac(self, x: np.ndarray) -> np.ndarray:
        """The forward-difference Jacobian at ``x``: the point and one step per parameter
        in one sweep (the point's residuals are cached for :meth:`fun`)."""
        h = self.steps(x)
        xs = [np.asarray(x, dtype=float)] + [x + h[i] * np.eye(len(x))[i] for i in range(len(x))]
        r = self.evaluate(xs)
        self.cache.clear()
        self.cache[np.asarray(x, dtype=float).tobytes()] = r[0]
        return ((r[1:] - r[0]) / h[:, None]).T


def _fit_starts(
    objective: _Objective,
    x0: np.ndarray,
    lo_x: np.ndarray,
    hi_x: np.ndarray,
    starts: int,
    seed: int,
    max_nfev: int,
) -> tuple[Any, int, int]:
    """Least squares from ``x0`` and ``starts - 1`` seeded random starts; the best fit (the
    lowest cost) and the residual and Jacobian evaluations of all of them."""
    from scipy.optimize import least_squares

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
                objective.fun,
                cand,
                jac=objective.jac,
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
    return best, nfev, njev


def _covariance(
    jmat: np.ndarray, r: np.ndarray, n_res: int, error_scale: str
) -> tuple[float, int, float, np.ndarray, np.ndarray, np.ndarray]:
    """From the Jacobian and residuals at the optimum: chi2, dof, the error scale, the
    covariance and standard errors of the fitted (internal) parameters (infinite along
    directions the data do not determine), and their correlation matrix."""
    n = jmat.shape[1]
    chi2 = float(r @ r)
    dof = n_res - n
    scale = 1.0
    if error_scale == "auto" and dof > 0 and chi2 / dof > 1.0:
        scale = math.sqrt(chi2 / dof)
    jtj = jmat.T @ jmat
    try:
        cov = np.linalg.pinv(jtj, rcond=1e-12, hermitian=True) * scale**2
        se_x = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    except np.linalg.LinAlgError:  # pragma: no cover
        cov = np.full((n, n), np.nan)
        se_x = np.full(n, np.nan)
    rank = np.linalg.matrix_rank(jtj) if np.all(np.isfinite(jtj)) else 0
    if rank < n:
        # Directions the data do not determine: their errors are not finite.
        w, v = np.linalg.eigh(jtj)
        null = v[:, w <= w.max() * 1e-12]
        for i in range(n):
            if np.any(np.abs(null[i]) > 1e-6):
                se_x[i] = math.inf
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.sqrt(np.diag(cov))
        corr = cov / np.outer(d, d)
    return chi2, dof, scale, cov, se_x, corr


def _natural_estimates(
    parsed: Sequence[_Param],
    natural: np.ndarray,
    x: np.ndarray,
    se_x: np.ndarray,
    lo_x: np.ndarray,
    hi_x: np.ndarray,
) -> tuple[dict[str, float], dict[str, float], dict[str, tuple[float, float]], list[str]]:
    """Values, standard errors and ~95 % intervals in natural units (mapped back from the
    fitted space), and the parameters that ended on a bound."""
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
    return values, se, intervals, at_bound


def _final_residuals(objective: _Objective, natural: np.ndarray, x0: np.ndarray) -> pd.DataFrame:
    """The residual table at the optimum, with the start's z columns (one sweep)."""
    model, m = objective.model, objective.m
    depth, t_s, _ = model.simulate(m.rows, [natural, model.to_natural(x0)], objective.threads)
    objective.counters["sims"] += 2 * objective.n_runs
    flags = model.last_unresolved
    frame = _residual_frame(m, depth[0], t_s[0])
    frame["unresolved"] = flags[0] if flags.size else False
    start_frame = _residual_frame(m, depth[1], t_s[1])
    for q in QUANTITIES:
        frame[f"{q}_z_start"] = start_frame[f"{q}_z"]
    return frame


def calibrate(
    cases: str | Callable[[dict[str, Any]], Any],
    measurements: Measurements | str | os.PathLike[str],
    params: Sequence[str] = ("eta_h", "eta_d", "eta_v", "lam"),
    *,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    start: Mapping[str, float] | None = None,
    base: str | Coefficients | None = None,
    per_angle: bool = False,
    quantities: Sequence[str] = QUANTITIES,
    joints: Mapping[str, float] | None = None,
    forces: LawSpec | None = None,
    dt: float = 1e-4,
    rel_step: float = 1e-3,
    error_scale: str = "auto",
    starts: int = 1,
    seed: int = 0,
    max_nfev: int = 200,
    threads: int | None = None,
    progress: bool | None = False,
    posterior: int = 0,
    walkers: int | None = None,
    **overrides: Any,
) -> CalibrationResult:
    """Fit ``params`` so that the simulated depth and stopping time match ``measurements``.

    Args:
        cases: the body, built per row by the :mod:`granrs.cases` function of that name:
            ``"free_link"`` (a row runs ``cases.free_link(q_deg, v0_mean)``), ``"chain"``
            (a case's two rows run ``cases.chain`` with both links' angles and the mean of
            their speeds, ``end="all_stops"``) or ``"leg"`` (``cases.leg(v0_mean)``); or,
            for bodies in space, a function of the measurement row (a dict of its columns)
            returning that row's :class:`granrs.space.Scene`: its forces are the law (or
            ``forces=``) and its step ``dt``; the measurements' body is then ``"space"``.
        measurements: a :class:`Measurements`, a thesis name (``"table_3_1"``,
            ``"table_4_chain"``, ``"table_5_1_means"``, ...; ``"thesis:"`` may prefix it) or
            the path of a CSV with the same columns.
        params: the parameters to fit (see the module's notes): any term's parameter as
            ``TERM.PARAM`` (``static_v.eta_v``, ``poncelet.c``, ...) or the thesis's short
            names ``eta_h``, ``eta_d``, ``eta_v``, ``lam``; ``<param>@<q_deg>`` angle nodes
            (free link); ``scale.<param>``; the body's unknowns: ``mass`` (free link,
            chain), ``pin_mass`` (chain), ``joints.k``, ``joints.c`` (leg). The rest keep
            their base value.
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
        forces: the law's terms, instead of the thesis's from ``base``: a list of
            :mod:`granrs.forces` terms for every row (a per-contact tuple gives each chain
            link its own value), or a function of the measurement row (a dict of its
            columns) returning them. A fitted parameter of a term that is not listed
            raises :class:`~granrs.errors.UnknownNameError` before any simulation.
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
        progress: a tqdm bar counting the fit's runs on stderr: False (default: calibrate
            is called inside compare and the report), True, or None (when stderr is a
            terminal; ``granrs calibrate`` asks for that).
        posterior: the steps of a posterior sampler's chains (emcee's ensemble, each
            chain's first half dropped as burn-in; at least 20) run from the optimum:
            the result's ``posterior`` holds the samples and their diagnostics, and its
            ``predictive()`` the predictive intervals. 0 (default): none.
        walkers: the sampler's walkers (an even number, at least twice the parameters;
            default 4 per parameter, at least 8).
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

    # scipy first, as before the split: without it, calibrate fails before any check.
    from scipy.optimize import least_squares  # noqa: F401

    t0 = time.perf_counter()
    body = _check_body(cases)
    m = _check_measurements(measurements, body)
    parsed = _parse_params(params, body, m, per_angle)
    names = [p.name for p in parsed]
    qs = _check_quantities(quantities)
    n_res = len(m) * len(qs)
    if n_res < len(parsed):
        raise InvalidParameterError(
            f"{len(parsed)} parameters cannot be fitted to {n_res} measured values",
            field="params",
        )
    base = _check_base(base, body)
    _check_options(dt, rel_step, starts, max_nfev, error_scale)
    _posterior.check_options(posterior, walkers, len(parsed))
    fixed = _check_joints(joints, body)
    box = _bounds_for(parsed, bounds)
    law = _check_law(forces)
    model = _Model(
        body,
        tuple(parsed),
        base,
        float(dt),
        dict(overrides),
        fixed,
        law,
        scene_of=cases if body == "space" else None,
    )
    x_start = _start_values(parsed, box, start, model, m, fixed)
    # Build every scene once up front: bad overrides or values fail here, before any run.
    model.scenes(m.rows, x_start)

    lo_x = model.to_internal([b[0] for b in box])
    hi_x = model.to_internal([b[1] for b in box])
    x0 = model.to_internal(x_start)
    x0 = np.clip(x0, lo_x, hi_x)
    n_runs = len(model.scenes(m.rows, x_start))
    objective = _Objective(model, m, qs, n_runs, rel_step, hi_x, threads)
    objective.bar = progress_bar(None, progress, "granrs calibrate", "run")
    try:
        best, nfev, njev = _fit_starts(objective, x0, lo_x, hi_x, starts, seed, max_nfev)

        # Uncertainty from the Jacobian at the optimum.
        x = best.x
        jmat = objective.jac(x)
        r = objective.fun(x)
        chi2, dof, scale, cov, se_x, corr = _covariance(jmat, r, n_res, error_scale)
        natural = model.to_natural(x)
        values, se, intervals, at_bound = _natural_estimates(parsed, natural, x, se_x, lo_x, hi_x)

        # Residual tables at the optimum and at the start (one sweep).
        frame = _final_residuals(objective, natural, x0)
        samples = None
        if posterior:
            samples = _posterior.sample(
                objective.evaluate,
                model.to_natural,
                names,
                x,
                cov / scale**2,
                (lo_x, hi_x),
                posterior,
                walkers,
                seed,
            )
    finally:
        objective.bar.close()
    counters = objective.counters
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
        posterior=samples,
    )


def _exp(u: float) -> float:
    try:
        return math.exp(u)
    except OverflowError:
        return math.inf


def evaluate(
    cases: str | Callable[[dict[str, Any]], Any],
    measurements: Measurements | str | os.PathLike[str],
    *,
    base: str | Coefficients | None = None,
    forces: LawSpec | None = None,
    joints: Mapping[str, float] | None = None,
    dt: float = 1e-4,
    threads: int | None = None,
    **overrides: Any,
) -> pd.DataFrame:
    """The residuals of ``measurements`` with the base coefficients, nothing fitted (e.g.
    the thesis's Table 3.4 rows): a frame as :attr:`CalibrationResult.residuals` without
    the start columns. Arguments as in :func:`calibrate`."""
    body = _check_body(cases)
    m = _check_measurements(measurements, body)
    base = _check_base(base, body)
    fixed = _check_joints(joints, body)
    model = _Model(
        body,
        (),
        base,
        float(dt),
        dict(overrides),
        fixed,
        _check_law(forces),
        scene_of=cases if body == "space" else None,
    )
    # Build every scene up front: a bad dt or override raises here (naming the field), not
    # as a failed run of every row.
    model.scenes(m.rows, [])
    depth, t_s, _ = model.simulate(m.rows, [[]], threads)
    frame = _residual_frame(m, depth[0], t_s[0])
    frame["unresolved"] = model.last_unresolved[0]
    return frame
