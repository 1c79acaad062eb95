"""The laws chapter's evidence on the chain and the leg targets.

:func:`leg_section`: the leg landing with the laws fitted on Table 3.1, carried over as the
thesis carried its vertical rod's coefficients (chapter 5 started from Table 3.2 at
alpha = 90 deg), and the smallest scaling of each law's coefficients (one common factor,
and each coefficient alone) that brings the leg's depth to Table 5.1's averages within the
relative error the thesis's own leg shows (eq. 5.16). :func:`chain_section`: why the chain's
stop order and link depths are missed: what the measurements allow, every law's counts
out of sample (leave one case out) against in sample (the fit to all six link rows), and
each row's z for the best laws. Both return their Markdown and the target's line;
:mod:`granrs.report.laws_sums` calls them.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from .. import cases
from .. import forces as _forces
from ..api import STEP_CHECK_FACTOR, STEP_ERROR_LIMIT
from ..calibrate import Measurements
from ..coefficients import table_3_2
from ..compare import DATASETS, _rows, _stop_order
from ..errors import GranrsError, StepSizeWarning
from .format import _fmt, md_table, relative_error
from .format import _rows as _data_rows
from .framework import ReportContext

__all__ = ["CHAIN_DEPTHS", "LEG_MAX_SCALE", "chain_section", "leg_section", "smallest_factor"]

#: Chain, out of sample: the measured stop order in every case and the depth within 1 sd
#: on at least this many of the 6 link rows of Tables 4.1-4.2.
CHAIN_DEPTHS = 4
#: Leg: no coefficient scaled by more than this factor.
LEG_MAX_SCALE = 3.0
#: The widest factor searched either way on the leg.
_SEARCH = 30.0
#: Fitted parameters that are exponents, not magnitudes: the common factor leaves them
#: (every other coefficient of these laws scales its term's force in proportion).
_EXPONENTS = frozenset({("static_v", "lam")})
#: The contact shape of the leg's sole (the terms a law carries to the leg act on it).
_SOLE = "box"
#: How many of the best fitted Table 3.1 laws the leg is run with (beside thesis_refit).
_LEG_LAWS = 3
#: The thesis's own law, refit: always run on the leg.
_THESIS_REFIT = "thesis_refit"
#: The leg table's row of the thesis's own leg coefficients (sec. 5.3.2, per speed).
_THESIS_OWN = "the thesis's leg coefficients (sec. 5.3.2; not fitted here)"
#: The chain's laws whose z per link row are shown (best out of sample first).
_CHAIN_SHOWN = 3


# ------------------------------------------------------------------------------------------
# The leg


def _coefficient(param: str) -> tuple[str, str]:
    """The (term, parameter) a fitted parameter's name sets (``scale.static_v.eta_v`` and
    ``rft.zeta`` alike)."""
    parts = param.split(".")
    return (parts[1], parts[2]) if parts[0] == "scale" else (parts[0], parts[1])


def _on_sole(terms: Sequence[_forces.Term]) -> tuple[tuple[_forces.Term, ...], list[str]]:
    """The terms defined on the sole's shape, and the names of those left out."""
    keep, dropped = [], []
    for t in terms:
        shapes = _forces.info(t.name).shapes
        if shapes is None or _SOLE in shapes:
            keep.append(t)
        else:
            dropped.append(t.name)
    return tuple(keep), dropped


def _scaled(
    terms: Sequence[_forces.Term], which: Sequence[tuple[str, str]], factor: float
) -> tuple[_forces.Term, ...]:
    out = []
    for t in terms:
        changes = {p: t.params[p] * factor for term, p in which if term == t.name}
        out.append(t.replace(**changes) if changes else t)
    return tuple(out)


def smallest_factor(
    errors: Callable[[float], Sequence[float]], tol: float, search: float = _SEARCH
) -> dict[str, Any]:
    """The factor nearest 1 (in log) at which every signed relative error ``errors(f)``
    is within ``tol``, each error monotone in the factor (a scaled resistance).

    Returns ``factor`` (None when no factor within ``search`` either way meets ``tol``),
    ``errors`` at it, and ``best``: the factor that balances the errors (their sum 0, where
    the largest |error| is smallest) with ``best_errors`` there.
    """
    from scipy.optimize import brentq

    cache: dict[float, list[float]] = {}

    def err(u: float) -> list[float]:
        if u not in cache:
            values = [float(e) for e in errors(math.exp(u))]
            cache[u] = [e if math.isfinite(e) else math.inf for e in values]
        return cache[u]

    def worst(u: float) -> float:
        return max(abs(e) for e in err(u))

    def balance(u: float) -> float:
        return float(np.clip(sum(err(u)), -1e9, 1e9))

    top = math.log(search)
    lo, hi = balance(-top), balance(top)
    if lo * hi < 0:
        u_best = brentq(balance, -top, top, xtol=5e-3)
    else:
        u_best = min((-top, top, 0.0), key=worst)
    out: dict[str, Any] = {
        "best": math.exp(u_best),
        "best_errors": err(u_best),
        "factor": None,
        "errors": None,
    }
    if worst(0.0) <= tol:
        out.update(factor=1.0, errors=err(0.0))
    elif worst(u_best) <= tol:
        u = brentq(lambda x: worst(x) - tol, 0.0, u_best, xtol=5e-3)
        # The end of brentq's bracket on the side that meets tol.
        u = u if worst(u) <= tol else u + math.copysign(5e-3, u_best)
        out.update(factor=math.exp(u), errors=err(u))
    return out


def _leg_reference() -> tuple[Measurements, float, str]:
    """Table 5.1's averages per height, the tolerance of the thesis's own leg (its
    simulated depths against those averages by eq. 5.16, the larger), and how it reads."""
    m = Measurements.thesis(DATASETS["leg"].measurements)
    thesis = _data_rows("human_coefficients")
    eps = []
    for r in m.rows.to_dict("records"):
        th = min(thesis, key=lambda t: abs(t["v0"] - r["v0_mean"]))
        eps.append((r, th, relative_error(r["depth_mean"], th["depth_sim"])))
    tol = max(e for _, _, e in eps)
    text = "; ".join(
        f"{th['depth_sim'] * 1e3:.0f} mm at {th['v0']:g} m/s against {r['depth_mean'] * 1e3:.1f} "
        f"mm, ε = {100 * e:.1f} % (printed: {th['depth_rel_err_pct']:g} %)"
        for r, th, e in eps
    )
    return m, tol, text


def _thesis_scaling(rho_g: float) -> tuple[str, float]:
    """The thesis's own leg coefficients against its start, Table 3.2 at alpha = 90 deg
    (q = 0: the vertical rod), per speed: a table and the largest factor either way."""
    start = table_3_2(0.0, rho_g)
    body, worst = [], 1.0
    for th in _data_rows("human_coefficients"):
        cells = [f"{th['v0']:g}"]
        for name, col in (
            ("eta_h", "eta_h"),
            ("eta_d", "eta_d"),
            ("eta_v", "eta_v"),
            ("lam", "lambda"),
        ):
            ref = getattr(start, name)
            f = th[col] / ref
            worst = max(worst, f, 1.0 / f)
            cells.append(f"{th[col]:g} / {ref:.3g} = {f:.2g}x")
        body.append(cells)
    table = md_table(
        [
            "v0 [m/s]",
            "eta_h: leg / Table 3.2 at 90°",
            "eta_d",
            "eta_v",
            "lambda",
        ],
        body,
        "l",
    )
    return table, worst


class _LegRuns:
    """The leg's runs of one law: :meth:`depths` (coefficients, factor) -> the depth per
    Table 5.1 row; the stopping times of every call and whether its step resolved the
    contact, by (coefficients, factor). Runs the step does not resolve (the core's
    :class:`~granrs.StepSizeWarning` check) are counted, not warned about once per run of
    a search."""

    def __init__(
        self, ctx: ReportContext, m: Measurements, terms_of: Callable[[Mapping[str, Any]], Any]
    ) -> None:
        self.ctx, self.terms_of = ctx, terms_of
        self.joints = DATASETS["leg"].published.get("joints")
        self.rows = m.rows.to_dict("records")
        self.t_s: dict[Any, list[float]] = {}
        self.unresolved: dict[Any, bool] = {}
        self.runs = 0
        self.unresolved_runs = 0

    def depths(self, which: Sequence[tuple[str, str]], factor: float) -> list[float]:
        out, t_s, flagged = [], [], False
        for r in self.rows:
            scene = cases.leg(
                r["v0_mean"],
                joints=self.joints,
                dt=self.ctx.dt,
                forces=_scaled(self.terms_of(r), which, factor),
            )
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", StepSizeWarning)
                try:
                    res = self.ctx.run(scene)
                    out.append(float(res.depth))
                    t_s.append(float(res.t_s))
                except GranrsError:
                    out.append(math.nan)
                    t_s.append(math.nan)
            self.runs += 1
            if any(issubclass(w.category, StepSizeWarning) for w in caught):
                self.unresolved_runs += 1
                flagged = True
        self.t_s[(tuple(which), factor)] = t_s
        self.unresolved[(tuple(which), factor)] = flagged
        return out


def _stops(
    stops: Mapping[Any, list[float]],
    which: Sequence[tuple[str, str]],
    common: Mapping[str, Any] | None,
    at_one: Sequence[float],
) -> str:
    """The leg's stopping times [ms] as carried, and at the common factor found."""
    text = ", ".join(f"{t * 1e3:.1f}" for t in at_one)
    if common and common.get("factor") is not None:
        scaled = stops.get((tuple(which), common["factor"]))
        if scaled:
            text += " (at the common factor " + ", ".join(f"{t * 1e3:.1f}" for t in scaled) + ")"
    return text


def _fmt_factor(f: float) -> str:
    return f"{f:.2g}x"


def _search_cell(res: Mapping[str, Any], tol: float) -> str:
    if res.get("failed"):
        return f"search failed ({res['failed']})"
    if res["factor"] is not None:
        errs = ", ".join(f"{100 * e:+.1f} %" for e in res["errors"])
        return f"{_fmt_factor(res['factor'])} (ε {errs})"
    errs = ", ".join(f"{100 * e:+.0f} %" for e in res["best_errors"])
    return (
        f"none within {1 / _SEARCH:.2g}x-{_SEARCH:g}x (closest {_fmt_factor(res['best'])}: "
        f"ε {errs})"
    )


def _size(res: Mapping[str, Any]) -> float:
    """How far a search's factor is from 1 either way (inf: none found)."""
    f = res.get("factor")
    return max(f, 1.0 / f) if f else math.inf


def _search(
    depths: Callable[[Sequence[tuple[str, str]], float], list[float]],
    which: Sequence[tuple[str, str]],
    targets: Sequence[float],
    tol: float,
) -> dict[str, Any]:
    def errors(f: float) -> list[float]:
        return [(d - t) / t for d, t in zip(depths(which, f), targets, strict=True)]

    try:
        return smallest_factor(errors, tol)
    except (ValueError, RuntimeError) as exc:  # a bracket without a root, no convergence
        return {"factor": None, "failed": str(exc)}


def _leg_candidates(ranked: Sequence[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    """thesis_refit and the best fitted laws of the Table 3.1 ranking, best first."""
    fitted = [r for r in ranked if r.get("result") is not None and r["folds"]]
    chosen = [r for r in fitted if r["law"] == _THESIS_REFIT]
    for r in fitted:
        if len(chosen) > _LEG_LAWS:
            break
        if r["law"] != _THESIS_REFIT:
            chosen.append(r)
    return sorted(chosen, key=lambda r: r["rank"])


def leg_section(ctx: ReportContext, ranked: Sequence[Mapping[str, Any]]) -> tuple[str, str]:
    """The leg with the laws fitted on Table 3.1 (the fits of ``ranked``, every row): the
    smallest scaling each needs; returns the Markdown and the target's line."""
    m, tol, thesis_eps = _leg_reference()
    targets = [float(x) for x in m.rows["depth_mean"]]
    free = Measurements.thesis(DATASETS["free_link"].measurements).rows
    vertical = free.iloc[int(np.argmin(np.abs(free["q_deg"].to_numpy(dtype=float))))].to_dict()
    thesis_table, thesis_worst = _thesis_scaling(cases.LEG["rho_g"])
    body, verdicts = [], []

    # The thesis's own leg coefficients (per speed), for comparison: not fitted here.
    def own_terms(row: Mapping[str, Any]) -> tuple[_forces.Term, ...]:
        return tuple(cases.leg(row["v0_mean"]).forces)

    own = [(t.name, p) for t in own_terms(m.rows.iloc[0]) for p in t.params]
    runs: list[tuple[str, Any, list[tuple[str, str]], list[str]]] = [
        (_THESIS_OWN, own_terms, own, [])
    ]
    for r in _leg_candidates(ranked):
        fit = r["result"]
        terms, dropped = _on_sole(fit.terms(vertical))
        which = []
        for p in fit.values:
            t, name = _coefficient(p)
            if any(x.name == t for x in terms) and (t, name) not in which:
                which.append((t, name))
        runs.append(
            (f"{r['law']} (rank {int(r['rank'])})", lambda _row, t=terms: t, which, dropped)
        )
    total = unresolved = 0
    with ctx.step("laws: the laws fitted on Table 3.1 on the leg, scaled"):
        for label, terms_of, which, dropped in runs:
            legs = _LegRuns(ctx, m, terms_of)
            depths, stops = legs.depths, legs.t_s
            at_one = depths([], 1.0)
            at_one_ts = stops[((), 1.0)]
            magnitudes = [w for w in which if w not in _EXPONENTS]
            common = _search(depths, magnitudes, targets, tol) if magnitudes else None
            each = {w: _search(depths, [w], targets, tol) for w in which}
            if common is not None and len(magnitudes) == 1:
                each[magnitudes[0]] = common
            total += legs.runs
            unresolved += legs.unresolved_runs

            def mark(key: Any, legs: _LegRuns = legs) -> str:
                return " (step not resolved)" if legs.unresolved.get(key) else ""

            sizes = [_size(common)] if common else []
            sizes += [_size(v) for v in each.values()]
            smallest = min(sizes, default=math.inf)
            if label != _THESIS_OWN:
                verdicts.append(
                    (
                        label.split(" (rank")[0],
                        smallest,
                        _stops(stops, magnitudes, common, at_one_ts),
                        bool(mark(((), 1.0))),
                    )
                )
            carried = "; ".join(
                ", ".join(
                    f"{t}.{p} {params[t][p]:.3g}"
                    for params in [{x.name: x.params for x in terms_of(row)}]
                    for t, p in which
                )
                for row in m.rows.to_dict("records")[: 1 if label != _THESIS_OWN else None]
            )
            body.append(
                [
                    label,
                    carried
                    + (
                        f"; left out (no term on the sole): {', '.join(dropped)}" if dropped else ""
                    ),
                    ", ".join(f"{d * 1e3:.1f}" for d in at_one) + mark(((), 1.0)),
                    _search_cell(common, tol) + mark((tuple(magnitudes), common.get("factor")))
                    if common
                    else "(no magnitude fitted)",
                    _stops(stops, magnitudes, common, at_one_ts),
                    "; ".join(
                        f"{t}.{p} {_search_cell(v, tol)}" + mark((((t, p),), v.get("factor")))
                        for (t, p), v in each.items()
                    ),
                    "yes" if smallest <= LEG_MAX_SCALE else "no",
                ]
            )
    t_s_measured = ", ".join(f"{t * 1e3:.1f}" for t in m.rows["t_s_mean"])
    met = [
        law + (" (its leg runs' step did not resolve the contact)" if flagged else "")
        for law, s, _, flagged in verdicts
        if s <= LEG_MAX_SCALE
    ]
    best = min(verdicts, key=lambda v: v[1], default=None)
    heights = ", ".join(
        f"{r['height_case']} {r['v0_mean']:.2f} m/s: {r['depth_mean'] * 1e3:.1f} mm"
        for r in m.rows.to_dict("records")
    )
    line = (
        f"- **Leg, laws fitted on Table 3.1** (the leg's depth on Table 5.1's averages within "
        f"the thesis's own ε = {100 * tol:.1f} %, no coefficient scaled by more than "
        f"{LEG_MAX_SCALE:g}x): "
        + (f"**met** by {', '.join(met)}" if met else "**not met** by any law run")
        + (
            f"; the smallest scaling is {best[0]}'s, {best[1]:.2g}x either way (the depth "
            f"alone, as the thesis compares: its t_s as carried {best[2]} ms against the measured "
            f"{t_s_measured} ms)"
            if best and math.isfinite(best[1])
            else ""
        )
        + f". The thesis's own leg scaled its start (Table 3.2 at 90°) by up to {thesis_worst:.2g}x"
        ' (the section "The leg with the laws fitted on Table 3.1" below).'
    )
    header = [
        "law (Table 3.1 rank)",
        "coefficients carried (the fit to every row, at q = 0)",
        "leg depth as carried [mm]",
        "one common factor (ε per height)",
        f"leg t_s [ms] as carried (measured {t_s_measured})",
        "each coefficient alone (ε per height)",
        f"≤ {LEG_MAX_SCALE:g}x",
    ]
    text = f"""#### The leg with the laws fitted on Table 3.1

The thesis's leg (chapter 5, sec. 5.3) is its average subject landing on the sole, the
force at the ankle, with the rod's law (eqs. 5.1-5.4) and hand-set coefficients per speed.
It took them from Table 3.2 at alpha = 90° (the vertical rod: the tibia lands near vertical)
"as a starting point" and changed them; its coefficients against that start:

{thesis_table}

Its comparison is the depth alone (the stopping times "significantly different"), by the
relative error of eq. 5.16 against the subjects' averages: {thesis_eps}. Its printed
depths give the larger ε, {100 * tol:.1f} %, which is the tolerance here (its printed ε cannot
be had from its printed depths). The reference: Table 5.1's averages ({heights}).

Each law below is carried as the thesis carried its own: its fit to every Table 3.1 row at
q = 0 (the vertical rod), on the leg at the averages' speeds, joints
{DATASETS["leg"].published.get("joints")} (the thesis's model), a term the sole does not
have left out. Then the factor nearest 1 that brings both depths within
{100 * tol:.1f} %: one factor on every magnitude (not the depth exponent lambda), and each
coefficient alone (searched from {1 / _SEARCH:.2g}x to {_SEARCH:g}x; the factor is found
to 0.5 %). Of the {total} leg runs, {unresolved} had a step that did not resolve the
contact (its depth or t_s moved by more than {100 * STEP_ERROR_LIMIT:g} % when run again
at dt / {STEP_CHECK_FACTOR:g}); a factor or
depth whose run is one of them is marked.

{md_table(header, body, "l")}
"""
    return text, line


# ------------------------------------------------------------------------------------------
# The chain


def _in_sample_rows(law: Mapping[str, Any], m: Measurements) -> list[dict[str, Any]] | None:
    """The chain's rows as the law's fit to every row predicts them (None: nothing fitted)."""
    result = law.get("result")
    if result is None:
        return None
    return _rows(m, result.residuals, None)


def _within(rows: Sequence[Mapping[str, Any]], q: str, k: float) -> int:
    return sum(1 for r in rows if abs(r[f"{q}_z"]) <= k + 1e-12)


def _measured_facts(m: Measurements) -> str:
    """What the chain's measurements allow: the stop order's margins and the depths'
    resolution."""
    rows = m.rows
    parts = []
    for case in sorted(pd.unique(rows["v0_case"])):
        sub = rows[rows["v0_case"] == case].set_index("link")
        dt = float(sub.loc[2, "t_s_mean"] - sub.loc[1, "t_s_mean"])
        sd = math.hypot(float(sub.loc[1, "t_s_sd"]), float(sub.loc[2, "t_s_sd"]))
        dd = float(sub.loc[2, "depth_mean"] - sub.loc[1, "depth_mean"])
        first = 1 if dt > 0 else 2
        parts.append(
            f"case {int(case)}: link {first} first by {abs(dt) * 1e3:.0f} ms ({abs(dt) / sd:.2g} "
            f"combined sd), link 2 {dd * 1e3:+.0f} mm deeper"
        )
    sd = rows["depth_sd"].to_numpy(dtype=float)
    step = float(m.resolution.get("depth", 0.0))
    return (
        "; ".join(parts)
        + f". The link depths' sd are {min(sd) * 1e3:.1g}-{max(sd) * 1e3:.1g} mm, the means "
        f"printed to {step * 1e3:g} mm: "
        + f"{int(np.sum(sd <= step / 2 + 1e-12))} of {len(sd)} rows have an sd no larger than "
        f"the printed means' rounding ({step / 2 * 1e3:g} mm)"
    )


def _firsts(order: Mapping[str, Any]) -> str:
    """The link predicted to stop first, case by case (``stop_order``'s ``per_case``)."""
    per_case = order["per_case"]
    return "first: " + ", ".join(str(per_case[c]["predicted_first"]) for c in sorted(per_case))


def chain_section(ctx: ReportContext, laws: Sequence[Mapping[str, Any]]) -> tuple[str, str]:
    """Why the chain's targets are missed: ``laws`` are the comparison's records on the
    chain (leave one case out, with their fit to every row). Returns the Markdown and the
    target's line."""
    m = Measurements.thesis(DATASETS["chain"].measurements)
    ran = [r for r in laws if r["available"]]
    ran = sorted(ran, key=lambda r: r["oos_chi2"] if math.isfinite(r["oos_chi2"]) else math.inf)
    body, insample, chi2_in = [], {}, {}
    for r in ran:
        rows_in = _in_sample_rows(r, m)
        so = r["stop_order"]
        n = int(r["n_rows"])
        if rows_in is None:
            cells = ["(nothing fitted: as out of sample)"] * 4
            insample[r["law"]] = (so["in_order"], int(r["depth_within_1sd"]))
        else:
            so_in = _stop_order(rows_in)
            d_in = _within(rows_in, "depth", 1.0)
            insample[r["law"]] = (so_in["in_order"], d_in)
            chi2_in[r["law"]] = r["chi2_dof"]
            full = r["folds"][0]
            d_fit = sum(1 for x in rows_in if abs(x["depth_zfit"]) <= 1.0 + 1e-12)
            cells = [
                f"{so_in['in_order']}/{so_in['cases']} ({_firsts(so_in)})",
                f"{d_in}/{n}",
                f"{d_fit}/{n}",
                _fmt(full["chi2"] / full["dof"], ".1f") if full["dof"] > 0 else "n/a",
            ]
        body.append(
            [
                r["law"],
                f"{so['in_order']}/{so['cases']} ({_firsts(so)})",
                f"{int(r['depth_within_1sd'])}/{n}",
                f"{int(r['ts_within_2sd'])}/{n}",
                *cells,
            ]
        )
    counts = md_table(
        [
            "law",
            "stop order (out of sample; link first in cases 1, 2, 3, 0: together)",
            "depth ≤ 1 sd",
            "t_s ≤ 2 sd",
            "stop order (in sample)",
            "depth ≤ 1 sd (in sample)",
            "depth ≤ 1 fit sd (in sample)",
            "χ²/dof (in sample)",
        ],
        body,
        "l",
    )
    shown = ran[:_CHAIN_SHOWN]
    z_body = []
    for i, src in enumerate(m.rows.to_dict("records")):
        cells = [
            f"{int(src['v0_case'])}",
            f"{int(src['link'])}",
            f"{src['depth_mean'] * 1e3:.0f} ± {src['depth_sd'] * 1e3:.1f}",
            f"{src['t_s_mean'] * 1e3:.0f} ± {src['t_s_sd'] * 1e3:.0f}",
        ]
        for r in shown:
            rows_in = _in_sample_rows(r, m)
            o = r["rows"][i]
            z_in = rows_in[i] if rows_in else o
            cells += [
                f"{o['depth_z']:+.1f} / {z_in['depth_z']:+.1f}",
                f"{o['t_s_z']:+.1f} / {z_in['t_s_z']:+.1f}",
            ]
        z_body.append(cells)
    z_header = ["case", "link", "depth [mm]", "t_s [ms]"]
    for r in shown:
        z_header += [f"{r['law']}: depth z (out / in)", "t_s z (out / in)"]
    meets_in = [law for law, (o, d) in insample.items() if o == 3 and d >= CHAIN_DEPTHS]
    best_in = max(insample.items(), key=lambda kv: (kv[1][1], kv[1][0]), default=None)
    never = [law for law, (o, _) in insample.items() if o == 0]
    if meets_in:
        cause = (
            f"In sample {', '.join(meets_in)} meet{'s' if len(meets_in) == 1 else ''} the target: "
            "the law can fit the chain, and the miss out of sample is the fit not carrying from "
            "two cases to the third."
        )
    else:
        cause = (
            "No law meets the target even in sample, fitted to all six link rows: no parameter "
            "set the fit finds (its least χ², two starts) gives the stop order in every case "
            f"with ≥ {CHAIN_DEPTHS} depths within 1 sd"
            + (
                f" (the most: {best_in[0]}, order {best_in[1][0]}/3, depths {best_in[1][1]}/6"
                + (
                    f", at χ²/dof {chi2_in[best_in[0]]:.2g}: the fit weighs depth and t_s "
                    "together, and its least χ² is not the most rows within 1 sd"
                    if best_in[0] in chi2_in
                    else ""
                )
                + ")"
                if best_in
                else ""
            )
            + ". The miss is the laws', not the cross-validation's."
        )
    if never:
        cause += (
            f" {', '.join(never)} stop{'s' if len(never) == 1 else ''} the links in the "
            "measured order in no case even in sample."
        )
    line = (
        f'- **Chain, why**: {cause} The section "Why the chain misses" below has every law\'s '
        "counts out of and in sample, and each link row's z."
    )
    text = f"""#### Why the chain misses

The measurements: {_measured_facts(m)}. A law must put link 1's stop first in every case
within a few ms and each link's depth within 0.3-2 mm.

No Table 3.1 fit is carried here: every law is fitted on the chain's own rows, so a miss is
not the rod's fit transferring badly. Every law on the chain, out of sample (each case
predicted by the fit to the other two) and in sample (the fit to all six link rows,
predicted at its own values); the fit's sd is the measured sd and the printed means'
rounding ({m.resolution.get("depth", 0.0) * 1e3:g} mm / sqrt(12)) in quadrature:

{counts}

{cause}

Each link row's z = (predicted - measured) / sd for the best {len(shown)} laws out of sample,
out of sample / in sample:

{md_table(z_header, z_body, "r")}
"""
    return text, line
