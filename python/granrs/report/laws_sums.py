"""The laws chapter's sums of terms: the axial quadratic drag (:data:`SUM_BASE`) plus up
to :data:`SUM_MAX_TERMS` of :data:`SUM_PIECES` (the thesis's static terms, planar RFT,
its inertial term), each piece alone, and the named laws of :data:`SUM_ON_LAWS` plus the
drag, fitted to Table 3.1 and ranked out of sample
(leave one angle out) beside the named laws; the out-of-sample residuals per row of the
best; the media cards of the best fits (:meth:`granrs.CalibrationResult.card`); and the
best fitted law on the chain and the leg. :func:`section` returns the chapter's Markdown
for it; the chapter (:mod:`granrs.report.laws`) calls it."""

from __future__ import annotations

import itertools
import json
import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from ..calibrate import Measurements
from ..cases import FREE_LINK, free_link
from ..compare import DATASETS, LAWS, PIECES, Law, _rank, compare, to_json
from ..errors import InvalidParameterError
from .format import _fmt, md_table
from .framework import ReportContext
from .laws_evidence import CHAIN_DEPTHS, LEG_MAX_SCALE, chain_section, leg_section

__all__ = [
    "AXIAL_DRAG",
    "RFT_INERTIAL",
    "SUMS_JSON",
    "SUM_BASE",
    "SUM_MAX_TERMS",
    "SUM_ON_LAWS",
    "SUM_PIECES",
    "THESIS_STATIC",
    "section",
    "sum_laws",
]

#: The sums' data file in the output directory (``{dataset: {law: {...}}}``, as
#: ``laws.json``).
SUMS_JSON = "laws_sums.json"
#: The quadratic drag along the rod's axis on its end face (the term ``axial_drag``,
#: :data:`granrs.compare.PIECES`): the axial, velocity-dependent drag the thesis's law lacks
#: at q = 0 (its drag needs a velocity across the rod).
AXIAL_DRAG = PIECES["axial_drag"]
#: The thesis's static terms alone (no drag): each a factor on its default (Table 3.4 at
#: q = 0), the same for every angle.
THESIS_STATIC = Law(
    "thesis_static",
    "the thesis's static terms without its drag, eta_h, eta_v and lambda scaled from their "
    "defaults (Table 3.4, q = 0)",
    terms=(("static_h", {}), ("static_v", {})),
    fit={
        "scale.static_h.eta_h": (1.0, 0.02, 50.0),
        "scale.static_v.eta_v": (1.0, 0.02, 50.0),
        "scale.static_v.lam": (1.0, 0.02, 50.0),
    },
)
#: Dynamic RFT's inertial term (Agarwal et al. 2021) as a piece of its own.
RFT_INERTIAL = Law(
    "rft_inertial",
    "rft's inertial (rate-dependent) term, its coefficient fitted",
    terms=(("rft_inertial", {}),),
    fit={"rft_inertial.lam": (1.0, 1e-3, 1e3)},
)
#: The pieces added to the axial drag on Table 3.1 (one or two at a time), and the
#: thesis's static terms alone (without the drag) to tell what the drag adds.
SUM_PIECES: tuple[Law, ...] = (THESIS_STATIC, LAWS["rft"], RFT_INERTIAL)
#: The law every searched sum is built on.
SUM_BASE: Law = AXIAL_DRAG
#: The named laws the base is added to (``thesis_refit+axial_drag``): the thesis's law
#: refit, with the axial drag it lacks.
SUM_ON_LAWS: tuple[str, ...] = ("thesis_refit",)
#: The most pieces added to the base.
SUM_MAX_TERMS = 2
#: The terms whose force grows with depth: a sum without one (a drag alone) never stops
#: the rod, and a sum with two (the thesis's static terms and rft: two laws of the static
#: resistance) is no law of the field; neither is searched.
_DEPTH_TERMS = frozenset({"static_v", "rft"})
#: The best sums shown, and whose residuals per row are shown.
_SHOWN = 10
_PER_ROW = 3
#: The targets on Table 3.1 (out of sample): depth within 1 sd, t_s within 2 sd.
_TARGET = {"depth_within_1sd": 10, "ts_within_2sd": 10}


def sum_laws(
    pieces: Sequence[Law] | None = None,
    max_terms: int | None = None,
    named: Mapping[str, Law] | None = None,
    base: Law | None = None,
) -> list[Law]:
    """The sums searched: each piece alone, the laws of :data:`SUM_ON_LAWS` plus ``base``
    (default :data:`SUM_BASE`), and ``base`` plus every sum of 1 to ``max_terms`` of
    ``pieces`` (added with ``+`` as :func:`granrs.compare.sums` adds them; a sum listing a
    term twice left out), keeping those with exactly one term growing with depth
    (``static_v`` or ``rft``) and without those named as a law of ``named`` (default
    :data:`granrs.compare.LAWS`): those are compared already."""
    pieces = SUM_PIECES if pieces is None else tuple(pieces)
    max_terms = SUM_MAX_TERMS if max_terms is None else max_terms
    named = LAWS if named is None else named
    base = SUM_BASE if base is None else base
    candidates = list(pieces) + [LAWS[n] + base for n in SUM_ON_LAWS]
    for k in range(1, min(max_terms, len(pieces)) + 1):
        for combo in itertools.combinations(pieces, k):
            law = base
            try:
                for piece in combo:
                    law = law + piece
            except InvalidParameterError:
                continue
            candidates.append(law)
    out = []
    for law in candidates:
        # Every term the law lists, the thesis's included (a term twice: no law).
        terms = law.needs()
        depth = set(terms) & _DEPTH_TERMS
        once = len(set(terms)) == len(terms)
        if (
            once
            and len(depth) == 1
            and law.name not in named
            and law.name not in {x.name for x in out}
        ):
            out.append(law)
    return out


def _counts(r: Mapping[str, Any]) -> tuple[str, str]:
    n = int(r["n_rows"])
    return f"{int(r['depth_within_1sd'])}/{n}", f"{int(r['ts_within_2sd'])}/{n}"


def _ranking(frame: pd.DataFrame) -> str:
    ran = frame[frame["available"]].sort_values("rank")
    body = []
    for r in ran.head(_SHOWN).to_dict("records"):
        d1, t2 = _counts(r)
        full = r["folds"][0] if r["folds"] else None
        insample = (
            f"{sum(abs(z) <= 1.0 for z in full['depth_z'])}, "
            f"{sum(abs(z) <= 2.0 for z in full['t_s_z'])}"
            if full
            else "(nothing fitted)"
        )
        body.append(
            [
                r["law"],
                f"{int(r['rank'])}",
                f"{int(r['n_params'])}",
                _fmt(r["chi2_dof"], ".2f"),
                _fmt(r["aic"], ".1f"),
                _fmt(r["oos_chi2"], ".1f"),
                d1,
                t2,
                insample,
            ]
        )
    return md_table(
        [
            "law",
            "rank",
            "params",
            "χ²/dof (in sample)",
            "AIC",
            "χ² out of sample",
            "depth ≤ 1 sd (out of sample)",
            "t_s ≤ 2 sd (out of sample)",
            "in sample: depth ≤ 1 sd, t_s ≤ 2 sd",
        ],
        body,
        "l",
    )


def _z(v: Any) -> str:
    return _fmt(float(v), "+.1f") if v is not None else "n/a"


def _per_row(laws: Sequence[Mapping[str, Any]]) -> str:
    """The out-of-sample residuals of ``laws`` on every Table 3.1 row, in measured sd."""
    rows = laws[0]["rows"]
    body = []
    for i, r in enumerate(rows):
        cells = [
            f"{r['q_deg']:g}",
            f"{r['v0_mean']:.3f}",
            f"{r['depth_mean'] * 1e3:.0f} ± {r['depth_sd'] * 1e3:.0f}",
            f"{r['t_s_mean'] * 1e3:.0f} ± {r['t_s_sd'] * 1e3:.0f}",
        ]
        for law in laws:
            row = law["rows"][i]
            cells += [_z(row["depth_z"]), _z(row["t_s_z"])]
        body.append(cells)
    header = ["q [deg]", "v0 [m/s]", "depth [mm]", "t_s [ms]"]
    for law in laws:
        header += [f"{law['law']}: depth z", "t_s z"]
    return md_table(header, body, "r")


#: The axial drag's fitted coefficient, as the comparison names it.
_DRAG_PARAM = "axial_drag.eta_a"


def _has_drag(law: Mapping[str, Any]) -> bool:
    return _DRAG_PARAM in law["params"]


def _drag_evidence(laws: Sequence[Mapping[str, Any]]) -> str:
    """Why the laws with the axial drag miss out of sample: each fold's fitted values, and
    the vertical drops' residuals in sample (the fit to every row) against out of sample
    (the fit without q = 0)."""
    out = []
    for law in laws:
        full = law["folds"][0]
        vertical = [i for i, r in enumerate(law["rows"]) if r["q_deg"] == 0.0]
        ins = ", ".join(f"{full['depth_z'][i]:+.1f}/{full['t_s_z'][i]:+.1f}" for i in vertical)
        oos = ", ".join(
            f"{law['rows'][i]['depth_z']:+.1f}/{law['rows'][i]['t_s_z']:+.1f}" for i in vertical
        )
        folds = "; ".join(
            ("all rows" if f["held_out"] == "all" else f"without {f['held_out']:g}°")
            + ": "
            + ", ".join(
                f"{p} {v:.3g}" + (" (bound)" if p in f["at_bound"] else "")
                for p, v in f["values"].items()
            )
            for f in law["folds"]
        )
        no_vertical = next((f for f in law["folds"] if f["held_out"] == 0.0), None)
        note = ""
        if _DRAG_PARAM in full["at_bound"]:
            note = (
                " Fitted to every row, the drag's eta_a ends on its lower bound: the law takes "
                "its dependence on speed from its other terms, not from the axial drag."
            )
        elif no_vertical is not None and _DRAG_PARAM in no_vertical["at_bound"]:
            note = (
                " Fitted without the vertical drops, the drag's eta_a ends on its lower bound: "
                "the oblique drops do not ask for it, so the fold that predicts the vertical "
                "drops has no axial drag."
            )
        eta = full["values"][_DRAG_PARAM]
        # In kg/m at the density of the free link's scenes, which the fit ran.
        axial = eta * free_link(0.0, 1.0).rho_g * math.pi * FREE_LINK["diameter"] ** 2 / 4.0
        out.append(
            f"- **{law['law']}**: the vertical drops' depth/t_s z in sample {ins}; out of "
            f"sample {oos}. Fitted to every row, the axial drag is eta_a rho_g pi d_c^2 / 4 "
            f"= {axial:.3g} kg/m.{note} Fitted values ({folds})."
        )
    return "\n".join(out)


def _card_name(law: str) -> str:
    return "table_3_1_" + re.sub(r"[^A-Za-z0-9_.-]", "_", law.replace("+", "_plus_"))


def _cards(ctx: ReportContext, ranked: Sequence[Mapping[str, Any]]) -> str:
    """The media cards of the best law and of the best law whose every fitted parameter is
    one value of the medium, each written by its calibration (the fit to every row)."""
    fitted = [r for r in ranked if r.get("result") is not None]
    if not fitted:
        return "No law was fitted: no card written."
    chosen = [fitted[0]]
    for r in fitted:
        card = r["result"].card(_card_name(r["law"]))
        if not card.missing:
            if r is not fitted[0]:
                chosen.append(r)
            break
    parts = []
    for r in chosen:
        card = r["result"].card(
            _card_name(r["law"]),
            description=f"the thesis's play sand under the law {r['law']}, fitted to Table 3.1",
        )
        name = f"{card.name}.toml"
        ctx.add_file(name, card.dumps().encode("utf-8"))
        parts.append(
            f"`{name}` ({r['law']}, rank {int(r['rank'])}; read it with "
            f'`granrs.media.load("{name}")` or give its path as a scene\'s `medium`):\n\n'
            f"```toml\n{card.dumps().strip()}\n```"
        )
    return "\n\n".join(parts)


def _elsewhere(
    ctx: ReportContext, best: Law, main: pd.DataFrame, starts: int
) -> tuple[pd.DataFrame, str]:
    """The best law on the chain (leave one case out) and the leg (in sample: its two rows
    cannot test a fit out of sample); reuse the main comparison's rows when it ran it."""
    have = main[main["law"] == best.name]
    if len(have) and set(have["dataset"]) >= {"chain", "leg"}:
        return have[have["dataset"].isin(["chain", "leg"])], "from the comparison above"
    data = {d: Measurements.thesis(DATASETS[d].measurements) for d in ("chain", "leg")}
    with ctx.step(f"laws: {best.name} on the chain and the leg"):
        frame = compare(
            [best],
            data,
            folds={"chain": "auto", "leg": None},
            dt=ctx.dt,
            starts=starts,
            progress=ctx.progress,
        )
        ctx.runs += int(frame["simulations"].sum())
        ctx.sim_seconds += float(frame["seconds"].sum())
    return frame, "fitted here; the leg in sample (two rows)"


def _chain_leg_lines(frame: pd.DataFrame, how: str, law: str, free: Mapping[str, Any]) -> str:
    lines = []
    chain = frame[frame["dataset"] == "chain"].to_dict("records")
    if chain and chain[0]["available"]:
        r = chain[0]
        so = r["stop_order"]
        ok = so["in_order"] == so["cases"] and r["depth_within_1sd"] >= CHAIN_DEPTHS
        lines.append(
            f"- **Chain** with {law} (leave one case out; target: the measured stop order in "
            f"all {so['cases']} cases and depths within 1 sd on ≥ {CHAIN_DEPTHS} of "
            f"{r['n_rows']} links): **{'met' if ok else 'not met'}**: stop order "
            f"{so['in_order']}/{so['cases']}, depths within 1 sd {int(r['depth_within_1sd'])}/"
            f"{r['n_rows']}, t_s within 2 sd {int(r['ts_within_2sd'])}/{r['n_rows']}."
        )
    elif chain:
        lines.append(f"- **Chain** with {law}: not run ({chain[0]['reason']}).")
    # The factors the free link's fit (every row) already puts on the thesis's coefficients.
    factors_free = {
        p: v
        for p, v in (free["folds"][0]["values"] if free.get("folds") else {}).items()
        if p.startswith("scale.") and max(v, 1 / v) > LEG_MAX_SCALE
    }
    on_free = (
        " On Table 3.1 the law's fit already scales "
        + ", ".join(f"{p[6:]} by {v:.3g}" for p, v in factors_free.items())
        + f" (more than {LEG_MAX_SCALE:g}x either way)."
        if factors_free
        else ""
    )
    leg = frame[frame["dataset"] == "leg"].to_dict("records")
    if leg and leg[0]["available"]:
        r = leg[0]
        full = r["folds"][0] if r["folds"] else None
        ref = {}
        if free.get("folds"):
            ref = free["folds"][0]["values"]
        factors = {}
        for p, v in (full["values"] if full else {}).items():
            if p.startswith("scale."):
                factors[p] = v
            elif p in ref and ref[p] > 0:
                factors[p] = v / ref[p]
        worst = max(factors.items(), key=lambda kv: max(kv[1], 1 / kv[1]), default=None)
        n = r["n_rows"]
        within = f"depth within 1 sd {r['depth_within_1sd']}/{n}, t_s {r['ts_within_1sd']}/{n}"
        all_within = r["depth_within_1sd"] == n and r["ts_within_1sd"] == n
        if full is None:
            scale = "nothing fitted (the thesis's coefficients as published)"
            ok = all_within
        elif worst is None:
            scale = "no coefficient of the law fitted"
            ok = all_within
        else:
            big = max(worst[1], 1 / worst[1])
            ok = big <= LEG_MAX_SCALE and all_within
            scale = (
                f"largest factor {big:.2g} ({worst[0]}"
                + (", against the free link's fit" if not worst[0].startswith("scale.") else "")
                + ")"
            )
        bound = f"; on a bound: {', '.join(full['at_bound'])}" if full and full["at_bound"] else ""
        lines.append(
            f"- **Leg** with {law} ({how}; target: Table 5.1's averages within 1 sd, no "
            f"coefficient scaled by more than {LEG_MAX_SCALE:g}x): "
            f"**{'met' if ok else 'not met'}**: {within}; {scale}{bound}.{on_free}"
        )
    elif leg:
        lines.append(
            f"- **Leg** with {law}: not run ({leg[0]['reason']}: Table 5.1 has two averages)."
            + on_free
        )
    return "\n".join(lines)


def section(ctx: ReportContext, main: pd.DataFrame, starts: int) -> tuple[str, list[str]]:
    """Fit the sums on Table 3.1, rank them with the named laws, and return the section
    and the lines it adds to the chapter's targets (the leg with the laws fitted here, and
    why the chain misses: :mod:`granrs.report.laws_evidence`)."""
    m = Measurements.thesis(DATASETS["free_link"].measurements)
    laws = sum_laws(named={n: LAWS[n] for n in main["law"]} if len(main) else LAWS)
    with ctx.step(f"laws: {len(laws)} sums of terms on Table 3.1"):
        sums = compare(laws, {"free_link": m}, dt=ctx.dt, starts=starts, progress=ctx.progress)
        ctx.runs += int(sums["simulations"].sum())
        ctx.sim_seconds += float(sums["seconds"].sum())
    ctx.add_file(SUMS_JSON, (json.dumps(to_json(sums), indent=1, allow_nan=False) + "\n").encode())
    frame = pd.concat([main[main["dataset"] == "free_link"], sums], ignore_index=True)
    frame["rank"] = _rank(frame)
    ranked = frame[frame["available"]].sort_values("rank").to_dict("records")
    if not ranked:
        return "No law ran on Table 3.1.", []
    best = ranked[0]
    met = [r["law"] for r in ranked if all(r[k] >= v for k, v in _TARGET.items())]
    closest = max(ranked, key=lambda r: (r["depth_within_1sd"] + r["ts_within_2sd"], -r["rank"]))
    drag = [r for r in ranked if _has_drag(r) and r["folds"]][:3]
    target = (
        f"**met** by {', '.join(met)}"
        if met
        else (
            f"**not met** by any of the {len(ranked)} laws: the most rows are "
            f"{closest['law']}'s, depth {closest['depth_within_1sd']}/12 and t_s "
            f"{closest['ts_within_2sd']}/12"
        )
    )
    drag_text = ""
    if drag:
        d = drag[0]
        drag_text = (
            f"The best law with the axial drag is {d['law']} (rank {int(d['rank'])}: depth "
            f"{d['depth_within_1sd']}/12, t_s {d['ts_within_2sd']}/12 out of sample). What "
            "the drag does, fold by fold, and the vertical drops it was added for:\n\n"
            + _drag_evidence(drag)
        )
    # The best law that fits something: its out-of-sample numbers are a test.
    fitted = next((r for r in ranked if r["folds"]), None)
    known = {law.name: law for law in [*laws, *(LAWS[n] for n in main["law"] if n in LAWS)]}
    elsewhere = ""
    chain = main[main["dataset"] == "chain"]
    if fitted is not None and fitted["law"] in known:
        other, how = _elsewhere(ctx, known[fitted["law"]], main, starts)
        elsewhere = _chain_leg_lines(other, how, fitted["law"], fitted)
        extra = other[(other["dataset"] == "chain") & ~other["law"].isin(chain["law"])]
        chain = pd.concat([chain, extra], ignore_index=True)
    leg_text, leg_line = leg_section(ctx, ranked)
    chain_text, chain_line = (
        chain_section(ctx, chain.to_dict("records")) if len(chain) else ("", "")
    )
    lines = [x for x in (leg_line, chain_line) if x]
    caveat = ""
    if not best["folds"]:
        caveat = (
            f" {best['law']} fits nothing here, but the thesis tuned its coefficients by hand, "
            "one row of Table 3.4 per angle, to these drops: its numbers are in sample. The "
            f"best law fitted here is {fitted['law'] if fitted else 'none'}."
        )
    shown = [r for r in ranked[:_PER_ROW]]
    return (
        f"""### Sums of terms (Table 3.1)

The axial drag (`{SUM_BASE.name}`: {SUM_BASE.summary}) added to
{", ".join(f"`{n}`" for n in SUM_ON_LAWS)} and to up to {SUM_MAX_TERMS} of these pieces, and
each piece alone, each sum with one term growing with depth
({len(laws)} sums beside the laws above: {", ".join(f"`{law.name}`" for law in laws)}),
fitted to Table 3.1 and predicted out of sample (leave one angle out), ranked with the
laws above by the out-of-sample χ²; the numbers are in `{SUMS_JSON}`:

{chr(10).join(f"- `{p.name}`: {p.summary}." for p in SUM_PIECES)}

{_ranking(frame)}

({len(ranked)} laws ran; the best {min(_SHOWN, len(ranked))} shown.)

Out-of-sample residuals per row of the best {len(shown)} (z = (predicted - measured) /
measured sd; each angle predicted by the fit without it):

{_per_row(shown)}

**Target on Table 3.1** (out of sample: depth within 1 sd on ≥ {_TARGET["depth_within_1sd"]}/12
and t_s within 2 sd on ≥ {_TARGET["ts_within_2sd"]}/12): {target}.{caveat}

{drag_text}

#### The best fitted law on the chain and the leg

{elsewhere or "(no law was fitted)"}

{leg_text}
{chain_text}
#### Media cards written by the calibration

{_cards(ctx, ranked)}
""",
        lines,
    )
