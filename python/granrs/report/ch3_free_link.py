"""Chapter 3 of the report: the free link (Tables 3.1 and 3.5-3.7, Figs. 3.15-3.23)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .. import cases
from ..result import Result
from .format import (
    _fmt,
    _median,
    _median_sentence,
    _pct,
    _pm,
    _rows,
    _status_note,
    md_table,
    relative_error,
    table_3_1_drop,
    watch_caption,
)
from .framework import ReportContext, register_chapter

__all__ = ["chapter_3"]

#: Table 3.1 angles shown in Figs. 3.15-3.20, with the thesis's figure numbers
#: (depth, velocity).
_FIGS_3_15_3_20: dict[float, tuple[str, str]] = {
    0.0: ("3.15", "3.16"),
    45.0: ("3.17", "3.18"),
    75.0: ("3.19", "3.20"),
}
#: Tables 3.6-3.7 list their speeds by nominal value; the runs use the sweep_3_4 speeds
#: (v01, v02, v03) at each angle.
_NOMINAL_TO_SWEEP: dict[float, str] = {2.24: "v01", 1.77: "v02", 1.15: "v03"}
_SWEEP_COLUMNS: tuple[str, ...] = ("v01", "v02", "v03")
#: Largest speed difference [m/s] at which a Table 3.5 row is taken as the thesis's run of a
#: Table 3.1 experiment (the thesis rounded its speeds, e.g. 1.19 for 1.264 +- 0.035 at 45 deg).
_MATCH_V0_TOL = 0.1
_RECORD = ("state", "forces")


def _table_3_4_row(result: Result) -> str:
    """The coefficient source of a run, shortened for a table cell."""
    return result.scene.coefficients_source.removeprefix("Table 3.4, ")


def _thesis_match(
    thesis_rows: Sequence[dict[str, Any]], q: float, v0: float
) -> dict[str, Any] | None:
    """The Table 3.5 row at angle q whose speed is nearest v0 (within _MATCH_V0_TOL)."""
    candidates = [r for r in thesis_rows if r["q_deg"] == q]
    if not candidates:
        return None
    best = min(candidates, key=lambda r: abs(r["v0"] - v0))
    return best if abs(best["v0"] - v0) <= _MATCH_V0_TOL else None


def _ch3_table_3_1(ctx: ReportContext) -> tuple[str, list[tuple[dict[str, Any], Result]]]:
    """Table 3.1 (experiments) against granrs; also the thesis's own Table 3.5 errors."""
    experiments = _rows("table_3_1")
    thesis_rows = _rows("table_3_5")
    runs: list[tuple[dict[str, Any], Result]] = []
    with ctx.step("chapter 3: Table 3.1 (experiments) vs granrs"):
        for row in experiments:
            result = ctx.free_link(row["q_deg"], row["v0_mean"], record=_RECORD)
            runs.append((row, result))

    table = []
    eps_t, eps_d, signed_t, thesis_eps_t, thesis_eps_d = [], [], [], [], []
    for row, r in runs:
        e_t = relative_error(row["t_s_mean"], r.t_s)
        e_d = relative_error(row["depth_mean"], r.depth)
        eps_t.append(e_t)
        eps_d.append(e_d)
        signed_t.append((r.t_s - row["t_s_mean"]) / row["t_s_mean"])
        match = _thesis_match(thesis_rows, row["q_deg"], row["v0_mean"])
        if match is not None:
            thesis_eps_t.append(relative_error(row["t_s_mean"], match["t_s"]))
            thesis_eps_d.append(relative_error(row["depth_mean"], match["depth"]))
        table.append(
            [
                f"{row['q_deg']:g}",
                _pm(row["v0_mean"], row["v0_sd"], ".3f"),
                _table_3_4_row(r),
                _pm(row["t_s_mean"], row["t_s_sd"], ".0f", 1e3),
                _fmt(r.t_s, ".1f", 1e3) + _status_note(r),
                _pct(e_t),
                _fmt((r.t_s - row["t_s_mean"]) / row["t_s_sd"], "+.1f"),
                _pm(row["depth_mean"], row["depth_sd"], ".0f", 1e3),
                _fmt(r.depth, ".1f", 1e3),
                _pct(e_d),
                _fmt((r.depth - row["depth_mean"]) / row["depth_sd"], "+.1f"),
            ]
        )
    header = [
        "q [deg]",
        "v0 [m/s] (exp. mean ± sd)",
        "Table 3.4 row used",
        "t_s exp. [ms]",
        "t_s granrs [ms]",
        "ε t_s [%]",
        "Δt_s / sd",
        "depth exp. [mm]",
        "depth granrs [mm]",
        "ε depth [%]",
        "Δdepth / sd",
    ]
    med_d, _ = _median(eps_d)
    med_t, n_t = _median(eps_t)
    med_signed, _ = _median(signed_t)
    earlier = sum(1 for s in signed_t if math.isfinite(s) and s < 0)
    th_d, n_th = _median(thesis_eps_d)
    th_t, _ = _median(thesis_eps_t)
    n_rows = len(runs)
    ctx.add_headline(
        f"Depth vs the experiments (Table 3.1, {n_rows} drops): median relative error "
        f"{_pct(med_d)} % (granrs, Table 3.4 coefficients at the tip); the thesis's own "
        f"simulation: {_pct(th_d)} % (n = {n_th})."
    )
    ctx.add_headline(
        f"**Known gap: stopping times.** The thesis itself says its simulated stopping times "
        f"do not match the experiments (sec. 3.3.2, Figs. 3.15-3.20). granrs has the same "
        f"gap: median relative t_s error vs Table 3.1 **{_pct(med_t)} %** (n = {n_t}); "
        f"granrs stops earlier than the experiment in {earlier} of {n_t} drops (median "
        f"signed error {_fmt(med_signed, '+.1f', 100.0)} %). The thesis's own Table 3.5 "
        f"t_s are off by a median {_pct(th_t)} % (n = {n_th})."
    )
    text = f"""### Table 3.1: the experiments against granrs

Each row of Table 3.1 (mean and sd of five drops, sec. 3.2.2) simulated at the measured mean
speed and angle, with the Table 3.4 coefficients of the nearest tabulated angle (the column
"Table 3.4 row used"; q = 60 deg, halfway between rows, takes the 65 deg row) and the force
applied at the tip. ε is eq. 3.21 with the experiment as reference; Δ/sd is
(granrs - experiment mean) / experiment sd.

{md_table(header, table, "rrl")}

- {_median_sentence("Median relative depth error vs Table 3.1 (eq. 3.21)", eps_d)}
- {_median_sentence("Median relative t_s error vs Table 3.1", eps_t)}; granrs stops earlier
  than the experiment in {earlier} of {n_t} drops.
- For comparison, the thesis's own simulation (Table 3.5 rows at the same angle and within
  {_MATCH_V0_TOL} m/s of the experiment's speed, n = {n_th}): median relative depth error
  **{_pct(th_d)} %**, median relative t_s error **{_pct(th_t)} %**.
"""
    return text, runs


def _ch3_table_3_5(ctx: ReportContext) -> str:
    """Table 3.5 (the thesis's simulation) against granrs, with Table 3.4 and Table 3.2."""
    thesis_rows = _rows("table_3_5")
    runs: dict[str, list[Result]] = {"table_3_4": [], "table_3_2": []}
    for coefficients, results in runs.items():
        label = coefficients.replace("table_", "Table ").replace("_", ".")
        with ctx.step(f"chapter 3: Table 3.5 (thesis simulation), {label} coefficients"):
            for row in thesis_rows:
                results.append(ctx.free_link(row["q_deg"], row["v0"], coefficients=coefficients))

    def errors(results: Sequence[Result]) -> tuple[list[float], list[float]]:
        """Relative depth and t_s errors (eq. 3.21) of ``results`` vs Table 3.5, per row."""
        pairs = list(zip(thesis_rows, results, strict=True))
        e_d = [relative_error(row["depth"], r.depth) for row, r in pairs]
        e_t = [relative_error(row["t_s"], r.t_s) for row, r in pairs]
        return e_d, e_t

    clean = [not row["note"] for row in thesis_rows]

    def clean_median(values: Sequence[float]) -> tuple[float, int]:
        """Median over the rows without a note."""
        return _median(e for e, ok in zip(values, clean, strict=True) if ok)

    table = []
    eps_d, eps_t = errors(runs["table_3_4"])
    for row, r, e_d, e_t in zip(thesis_rows, runs["table_3_4"], eps_d, eps_t, strict=True):
        table.append(
            [
                f"{row['q_deg']:g}",
                f"{row['v0']:.3f}",
                _fmt(row["t_s"], ".0f", 1e3),
                _fmt(r.t_s, ".1f", 1e3) + _status_note(r),
                _pct(e_t),
                _fmt(row["depth"], ".1f", 1e3),
                _fmt(r.depth, ".1f", 1e3),
                _pct(e_d),
                _table_3_4_row(r),
                row["note"],
            ]
        )
    header = [
        "q [deg]",
        "v0 [m/s]",
        "t_s thesis [ms]",
        "t_s granrs [ms]",
        "ε t_s [%]",
        "depth thesis [mm]",
        "depth granrs [mm]",
        "ε depth [%]",
        "Table 3.4 row used",
        "note (doubtful source row)",
    ]
    med_clean, n_clean = clean_median(eps_d)
    med_all, n_all = _median(eps_d)
    med_t_clean, _ = clean_median(eps_t)

    variant_rows = []
    for coefficients, label in (
        ("table_3_4", "Table 3.4 (hand-tuned values; as above)"),
        ("table_3_2", "Table 3.2 (closed forms at q, rho_g = 1650 kg/m³)"),
    ):
        variant_d, variant_t = errors(runs[coefficients])
        variant_rows.append(
            [
                label,
                _pct(clean_median(variant_d)[0]),
                _pct(_median(variant_d)[0]),
                _pct(clean_median(variant_t)[0]),
                _pct(_median(variant_t)[0]),
            ]
        )
    variant_header = [
        "coefficients",
        "median ε depth, rows without a note [%]",
        "median ε depth, all rows [%]",
        "median ε t_s, rows without a note [%]",
        "median ε t_s, all rows [%]",
    ]
    e32_clean, _ = clean_median(errors(runs["table_3_2"])[0])
    ctx.add_headline(
        f"Depth vs the thesis's simulation (Table 3.5, {n_all} rows): median relative error "
        f"{_pct(med_clean)} % over the {n_clean} rows without a note, {_pct(med_all)} % over "
        f"all rows (Table 3.4 coefficients); {_pct(e32_clean)} % without a note with the "
        f"Table 3.2 closed forms."
    )
    worst = sorted(
        (pair for pair in zip(eps_d, thesis_rows, strict=True) if pair[0] > 0.1),
        key=lambda pair: -pair[0],
    )
    worst_text = (
        "; ".join(
            f"q = {row['q_deg']:g}°, v0 = {row['v0']:.3f} m/s: {_pct(e)} %"
            + (" (doubtful row)" if row["note"] else "")
            for e, row in worst
        )
        or "none"
    )
    median_line = (
        f"**Median relative depth error (eq. 3.21) vs Table 3.5: {_pct(med_clean)} % over the "
        f"{n_clean} rows without a note; {_pct(med_all)} % over all {n_all} rows.**"
    )
    return f"""### Table 3.5: the thesis's simulation against granrs

Every row of Table 3.5 (the thesis's CAD runs at 10 kHz), including the ones whose source is
doubtful (a non-empty note; they are shown, and counted separately in the medians). granrs
uses the Table 3.4 coefficients of the nearest tabulated angle and the force at the tip.
ε is eq. 3.21 with the thesis's value as reference.

{md_table(header, table, "rrrrrrrrll")}

{median_line}

Median relative t_s error over the rows without a note: {_pct(med_t_clean)} %.

Rows with a depth error above 10 %: {worst_text}.

#### Table 3.2 variant (closed-form coefficients instead of Table 3.4)

The same {n_all} rows with the coefficients of the thesis's Table 3.2 closed forms evaluated
at each angle (instead of the hand-tuned Table 3.4 values), for comparison:

{md_table(variant_header, variant_rows, "lrrrr")}
"""


def _ch3_sweep(ctx: ReportContext) -> dict[tuple[float, str], Result]:
    """The sec. 3.4 sweep: 10 angles x 3 speeds (sweep_3_4), Table 3.4 coefficients."""
    runs: dict[tuple[float, str], Result] = {}
    with ctx.step("chapter 3: sec. 3.4 sweep (10 angles x 3 speeds)"):
        for row in _rows("sweep_3_4"):
            for column in _SWEEP_COLUMNS:
                runs[(row["q_deg"], column)] = ctx.free_link(row["q_deg"], row[column])
    return runs


def _sweep_result(
    sweep: Mapping[tuple[float, str], Result], q: float, nominal: float
) -> Result | None:
    """The sweep run at angle q for a Table 3.6/3.7 nominal speed (None if there is none)."""
    column = _NOMINAL_TO_SWEEP.get(round(nominal, 2))
    return None if column is None else sweep.get((q, column))


def _ch3_side_by_side(
    sweep: Mapping[tuple[float, str], Result],
    table: str,
    quantities: Sequence[tuple[str, str, str, str, str]],
) -> tuple[str, str]:
    """A thesis table (3.6 or 3.7) and granrs side by side; returns (table, medians).

    ``quantities`` holds (thesis column, granrs summary key, name, unit, format) per
    quantity.
    """
    rows = _rows(table)
    body = []
    errs: dict[str, list[float]] = {name: [] for _, _, name, _, _ in quantities}
    for row in rows:
        r = _sweep_result(sweep, row["q_deg"], row["v0_nominal"])
        cells = [f"{row['q_deg']:g}", f"{row['v0_nominal']:.2f}"]
        cells.append("n/a" if r is None else f"{r.scene.v0:.2f}" + _status_note(r))
        for column, key, name, _, spec in quantities:
            value = math.nan if r is None else float(r.summary[key])
            e = relative_error(row[column], value)
            errs[name].append(e)
            cells += [_fmt(row[column], spec), _fmt(value, spec), _pct(e)]
        body.append(cells)
    header = ["q [deg]", "v0 nominal [m/s]", "v0 run [m/s]"]
    for _, _, name, unit, _ in quantities:
        header += [f"{name} thesis [{unit}]", f"{name} granrs [{unit}]", f"ε {name} [%]"]
    medians = "\n".join(
        f"- {_median_sentence(f'Median relative error of {name}', e)}" for name, e in errs.items()
    )
    return md_table(header, body), medians


def _ch3_tables_3_6_3_7(ctx: ReportContext, sweep: Mapping[tuple[float, str], Result]) -> str:
    """Tables 3.6 (forces) and 3.7 (energies) against granrs."""
    with ctx.step("chapter 3: Tables 3.6 and 3.7"):
        forces, forces_median = _ch3_side_by_side(
            sweep,
            "table_3_6",
            [
                ("F_d_max_N", "F_d_max", "F_d,max", "N", ".2f"),
                ("F_s_end_N", "F_s_end", "F_s,end", "N", ".2f"),
                ("F_r_end_N", "F_r_end", "F_r,end", "N", ".2f"),
            ],
        )
        energy, energy_median = _ch3_side_by_side(
            sweep,
            "table_3_7",
            [
                ("dKE_J", "dKE", "ΔKE", "J", ".3f"),
                ("dPE_J", "dPE", "ΔPE", "J", ".3f"),
                ("dE_J", "dE", "ΔE", "J", ".3f"),
            ],
        )
    return f"""### Table 3.6: resistance forces

The thesis lists its speeds by nominal value (2.24, 1.77, 1.15 m/s); granrs runs each angle
at the speeds of sec. 3.4 (v01, v02, v03 of `sweep_3_4`, column "v0 run"), Table 3.4
coefficients, force at the tip. F_d,max is the largest |F_d| (eq. 3.23) during the
penetration phase, F_s,end and F_r,end the static and total force (eq. 3.24) at the stop.
ε is eq. 3.21 with the thesis's value as reference (n/a where the thesis's value is zero);
relative errors of small values are large by construction.

{forces}

{forces_median}

### Table 3.7: energy

ΔKE, ΔPE and ΔE = ΔKE + ΔPE from the first contact to the stop (eqs. 3.25-3.26), positive
when lost, as in the thesis.

{energy}

{energy_median}
"""


def _ch3_figs_3_15_3_20(
    ctx: ReportContext, runs_3_1: Sequence[tuple[dict[str, Any], Result]]
) -> str:
    """Figs. 3.15-3.20: depth and tip velocity against time at q = 0, 45, 75 deg."""
    from .. import plots

    thesis_rows = _rows("table_3_5")
    links = []
    with ctx.step("chapter 3: Figs. 3.15-3.20"):
        for q, numbers in _FIGS_3_15_3_20.items():
            curves = []
            for row, r in sorted(
                ((row, r) for row, r in runs_3_1 if row["q_deg"] == q),
                key=lambda item: -item[0]["v0_mean"],
            ):
                if r.series is None:  # pragma: no cover - recorded above
                    raise RuntimeError("Table 3.1 runs must record their series")
                match = _thesis_match(thesis_rows, q, row["v0_mean"])
                curves.append(
                    plots.SpeedCurve(
                        v0=row["v0_mean"],
                        t=r.series["t"],
                        depth=r.series["depth"],
                        v_tip_y=r.series["v_tip_y"],
                        experiment=plots.EndPoint(
                            row["t_s_mean"], row["depth_mean"], row["t_s_sd"], row["depth_sd"]
                        ),
                        thesis=None
                        if match is None
                        else plots.EndPoint(match["t_s"], match["depth"]),
                    )
                )
            fig = plots.impact_figure(q, curves, numbers)
            links.append(
                ctx.add_figure(
                    f"fig_{numbers[0].replace('.', '_')}_{numbers[1].replace('.', '_')}_q{q:g}.png",
                    plots.png_bytes(fig),
                    f"Fig. {numbers[0]} (depth) and Fig. {numbers[1]} (tip velocity) at "
                    f"q = {q:g} deg",
                )
                + f"\n\n*Left: Fig. {numbers[0]}, tip depth against time; right: Fig. "
                f"{numbers[1]}, downward tip velocity against time; q = {q:g} deg.*"
            )
    figures = "\n\n".join(links)
    return f"""### Figs. 3.15-3.20: depth and tip velocity against time

granrs curves (Table 3.4 coefficients, force at the tip) at the Table 3.1 speeds for
q = 0, 45 and 75 deg; filled circles: the experiments' end points (Table 3.1: t_s and depth,
mean ± sd of five drops; on the velocity panel at zero velocity, with the t_s sd as the
horizontal bar); hollow squares: the thesis's simulated end points (Table 3.5, the row within
{_MATCH_V0_TOL} m/s of the experiment's speed; at q = 45 deg the 1.88 m/s row is missing in
the source). The thesis's own curves are not reproduced (its figures are images).

{figures}
"""


def _ch3_figs_3_22_3_23(ctx: ReportContext, sweep: Mapping[tuple[float, str], Result]) -> str:
    """Figs. 3.22-3.23: depth and stopping time against alpha for the three speeds."""
    from .. import plots

    sweep_rows = _rows("sweep_3_4")
    thesis_rows = _rows("table_3_5")
    sweep_by_q = {row["q_deg"]: row for row in sweep_rows}
    links = []
    with ctx.step("chapter 3: Figs. 3.22-3.23"):
        for number, key, quantity, title in (
            ("3.22", "depth", "tip depth at the stop d", "penetration depth"),
            ("3.23", "t_s", "stopping time t_s", "stopping time"),
        ):
            series = []
            for column in _SWEEP_COLUMNS:
                speeds = [row[column] for row in sweep_rows]
                series.append(
                    plots.AlphaSeries(
                        label=f"granrs, {column} = {min(speeds):.2f}-{max(speeds):.2f} m/s",
                        alpha_deg=np.array([row["alpha_deg"] for row in sweep_rows]),
                        values=np.array(
                            [getattr(sweep[(row["q_deg"], column)], key) for row in sweep_rows]
                        ),
                    )
                )
            points = []
            for row in thesis_rows:
                srow = sweep_by_q.get(row["q_deg"])
                index = None
                if srow is not None:
                    index = min(
                        range(len(_SWEEP_COLUMNS)),
                        key=lambda i: abs(srow[_SWEEP_COLUMNS[i]] - row["v0"]),
                    )
                points.append(
                    plots.AlphaPoint(
                        alpha_deg=90.0 - row["q_deg"],
                        value=row[key],
                        series=index,
                        doubtful=bool(row["note"]),
                    )
                )
            fig = plots.alpha_figure(
                series,
                points,
                quantity=quantity,
                unit_scale=1e3,
                unit="mm" if key == "depth" else "ms",
                title=f"Fig. {number}: {title} against the impact angle",
                other_label="thesis, q = 60° (Table 3.1 speeds, not in sec. 3.4)",
            )
            links.append(
                ctx.add_figure(
                    f"fig_{number.replace('.', '_')}_{key}_vs_alpha.png",
                    plots.png_bytes(fig),
                    f"Fig. {number}: {title} against alpha",
                )
            )
    figures = "\n\n".join(links)
    return f"""### Figs. 3.22-3.23: depth and stopping time against the impact angle

granrs at the ten angles and three speeds of sec. 3.4 (lines; the colour is the speed), the
thesis's Table 3.5 values as diamonds in the colour of the nearest speed (hollow: a row
with a note; grey triangles: the q = 60 deg rows, run at the Table 3.1 speeds).

{figures}
"""


@register_chapter("3", "Chapter 3: the free link")
def chapter_3(ctx: ReportContext) -> str:
    """Chapter 3: the free link against Tables 3.1 and 3.5-3.7 and Figs. 3.15-3.23."""
    table_3_1, runs_3_1 = _ch3_table_3_1(ctx)
    table_3_5 = _ch3_table_3_5(ctx)
    sweep = _ch3_sweep(ctx)
    tables_3_6_3_7 = _ch3_tables_3_6_3_7(ctx, sweep)
    figs_3_15 = _ch3_figs_3_15_3_20(ctx, runs_3_1)
    figs_3_22 = _ch3_figs_3_22_3_23(ctx, sweep)
    return "\n".join(
        [
            "The thesis's steel rod (L = 0.190 m, d_c = 0.0127 m, m = 0.184 kg; sand "
            "rho_g = 1650 kg/m³) dropped tip first at an angle q from the vertical "
            "(alpha = 90° - q from the horizontal), moving straight down at v0.",
            "",
            table_3_1,
            table_3_5,
            tables_3_6_3_7,
            figs_3_15,
            figs_3_22,
            _watch(ctx),
        ]
    )


def _watch(ctx: ReportContext) -> str:
    """Table 3.1's fastest drop at q = 45 deg as an animation."""
    scene = cases.free_link(*table_3_1_drop(45.0), dt=ctx.dt)
    return ctx.watch(
        "ch3_free_link_q45.gif",
        scene,
        watch_caption(scene, "The fastest Table 3.1 drop at 45°")
        + ", one frame per millisecond: the rod to scale, the immersed part shaded, the "
        "force at the tip split by term.",
        frame_dt=1e-3,
    )
