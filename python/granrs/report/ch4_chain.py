"""Chapter 4 of the report: the two-link chain (Tables 4.2 and 4.5-4.6, the link-mass
sweep, Figs. 4.7-4.16 and the pin force).
"""

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
    _pct,
    _pm,
    _rms,
    _rows,
    md_table,
    relative_error,
)
from .framework import ReportContext, register_chapter

__all__ = ["chapter_4"]

_CHAIN_CASES: tuple[int, ...] = (1, 2, 3)
_CHAIN_LINKS: tuple[int, ...] = (1, 2)
#: The link masses reported side by side [kg], with what each stands for. The thesis does
#: not give the mass: the granrs default is a solid steel link of the stated size
#: (``cases.CHAIN``, ``bodies.csv``); the other is half of it.
_CHAIN_MASSES: tuple[tuple[float, str], ...] = (
    (cases.CHAIN["mass"], "solid steel, the granrs default"),
    (0.017, "half the solid-steel mass"),
)
#: The coarse link-mass sweep [kg]; then a fine one of :data:`_MASS_FINE_POINTS` masses
#: within one coarse step of the coarse best.
_MASS_SWEEP: tuple[float, ...] = tuple(round(float(m), 6) for m in np.linspace(0.010, 0.040, 13))
_MASS_FINE_POINTS = 11
_CHAIN_RECORD = ("state", "forces", "energy")

#: Numbers quoted in the text of sec. 4.3 (no table holds them; also listed in the data's
#: PROVENANCE.md): the largest |F_d| per (link, case) (Fig. 4.9 text) and |F_s| at the stop
#: (Fig. 4.10 text) [N]; the total energy dissipated per case (Fig. 4.15 text) [J].
_THESIS_FD_MAX: dict[tuple[int, int], float] = {
    (1, 1): 3.5,
    (1, 2): 3.25,
    (1, 3): 1.4,
    (2, 1): 2.5,
    (2, 2): 1.7,
    (2, 3): 0.85,
}
_THESIS_FS_END: dict[tuple[int, int], float] = {
    (1, 1): 3.1,
    (1, 2): 2.8,
    (1, 3): 2.6,
    (2, 1): 4.0,
    (2, 2): 3.7,
    (2, 3): 2.8,
}
_THESIS_DE: dict[int, float] = {1: 0.24, 2: 0.18, 3: 0.10}
#: The measured entry offsets Delta t(0) = t1(0) - t2(0) of sec. 4.2.2 [s], by case.
_THESIS_ENTRY_OFFSET: dict[int, float] = {1: 0.0013, 2: 0.0005, 3: 0.0003}

ChainRuns = Mapping[int, Result]


def _link_case(row: Mapping[str, Any]) -> tuple[int, int]:
    """(link, case) of a chapter 4 table row."""
    return int(row["link"]), int(row["v0_case"])


def _link_stop(result: Result, link: int) -> tuple[float, float]:
    """Link ``link``'s (1 or 2) stopping time [s] and tip depth at its stop [m].

    The thesis counts each link's impact from the moment its own tip is at the surface
    (sec. 4.2.2); a granrs contact's ``t_s`` counts from the start of the run (the first
    tip's entry), so the link's entry time is subtracted. NaN time if the link did not stop.
    """
    contact = result.contacts[link - 1]
    t_s = contact.t_s - float(contact.summary["t_entry"]) if contact.stopped else math.nan
    return t_s, contact.depth


def _link_note(result: Result, link: int) -> str:
    """`` (not stopped)`` for a link that did not stop, else empty."""
    return "" if result.contacts[link - 1].stopped else " (not stopped)"


def _chain_errors(
    experiments: Sequence[Mapping[str, Any]], runs: ChainRuns
) -> tuple[list[float], list[float]]:
    """Relative depth (eq. 4.8) and t_s errors vs Table 4.2, one per link-case row."""
    e_d, e_t = [], []
    for row in experiments:
        link, case = _link_case(row)
        t_s, depth = _link_stop(runs[case], link)
        stopped = runs[case].contacts[link - 1].stopped
        e_d.append(relative_error(row["depth_mean"], depth) if stopped else math.nan)
        e_t.append(relative_error(row["t_s_mean"], t_s))
    return e_d, e_t


def _chain_depth_rms(experiments: Sequence[Mapping[str, Any]], runs: ChainRuns) -> float:
    """RMS relative depth error over every link-case; infinite if a link did not stop."""
    e_d, _ = _chain_errors(experiments, runs)
    rms, n = _rms(e_d)
    return rms if n == len(experiments) else math.inf


def _chain_energy(result: Result) -> float:
    """Energy the two links lost, each from the start to its own stop (eqs. 4.9-4.10) [J]."""
    return sum(float(c.summary["link_dE"]) for c in result.contacts)


def _chain_energy_rms(runs: ChainRuns) -> float:
    """RMS relative error of the links' total energy lost vs the sec. 4.3 numbers."""
    rms, n = _rms(relative_error(_THESIS_DE[c], _chain_energy(runs[c])) for c in _CHAIN_CASES)
    return rms if n == len(_CHAIN_CASES) else math.inf


def _grams(mass: float) -> str:
    """A mass [kg] in grams for the text."""
    return f"{mass * 1e3:.1f} g"


def _ch4_table_4_2(
    experiments: Sequence[Mapping[str, Any]], runs_by_mass: Mapping[float, ChainRuns]
) -> tuple[str, dict[float, float]]:
    """Table 4.2 (experiments) against granrs at each of :data:`_CHAIN_MASSES`.

    Returns the Markdown and the RMS relative depth error per mass.
    """
    header = [
        "link",
        "case",
        "q0 [deg] (Table 4.1)",
        "v0 exp. [m/s]",
        "v0 run [m/s]",
        "t_s exp. [ms]",
        "t_s granrs [ms]",
        "Δt_s granrs - exp. [ms]",
        "depth exp. [mm]",
        "depth granrs [mm]",
        "ε depth (eq. 4.8) [%]",
    ]
    parts, rms_by_mass = [], {}
    for mass, label in _CHAIN_MASSES:
        runs = runs_by_mass[mass]
        body = []
        for row in experiments:
            link, case = _link_case(row)
            r = runs[case]
            t_s, depth = _link_stop(r, link)
            body.append(
                [
                    str(link),
                    str(case),
                    f"{row['q0_deg']:+.2f}",
                    _pm(row["v0_mean"], row["v0_sd"], ".2f"),
                    f"{r.scene.v0:.3f}",
                    _pm(row["t_s_mean"], row["t_s_sd"], ".0f", 1e3),
                    _fmt(t_s, ".1f", 1e3) + _link_note(r, link),
                    _fmt(t_s - row["t_s_mean"], "+.1f", 1e3),
                    _pm(row["depth_mean"], row["depth_sd"], ".1f", 1e3),
                    _fmt(depth, ".1f", 1e3),
                    _pct(relative_error(row["depth_mean"], depth)),
                ]
            )
        e_d, e_t = _chain_errors(experiments, runs)
        rms_d, n_d = _rms(e_d)
        rms_t, n_t = _rms(e_t)
        med_dt, _ = _median(
            abs(_link_stop(runs[_link_case(row)[1]], _link_case(row)[0])[0] - row["t_s_mean"])
            for row in experiments
        )
        rms_by_mass[mass] = rms_d
        parts.append(
            f"""#### Link mass {mass:g} kg ({label})

{md_table(header, body)}

- RMS relative depth error (eq. 4.8) over the {n_d} link-cases: **{_pct(rms_d)} %**
  (largest {_pct(max((e for e in e_d if math.isfinite(e)), default=math.nan))} %).
- RMS relative t_s error: {_pct(rms_t)} % (n = {n_t}); median |Δt_s|
  {_fmt(med_dt, ".1f", 1e3)} ms.
"""
        )
    masses = ", ".join(f"{m:g} kg ({label})" for m, label in _CHAIN_MASSES)
    text = f"""### Table 4.2: the experiments against granrs

Each link of each case of Table 4.2 (mean ± sd of four drops): granrs runs the chain at the
case's measured angles (Table 4.1) and the mean of the two links' measured speeds (the chain
falls as one body; column "v0 run"), Table 4.4 coefficients per link, force at the tip, until
both links have stopped. A link's t_s counts from its own tip's entry, as in the thesis
(sec. 4.2.2). ε is eq. 4.8 with the experiment as reference. The link mass is not in the
thesis, and the result hangs on it; two masses are shown: {masses}.

{chr(10).join(parts)}"""
    return text, rms_by_mass


def _ch4_table_4_5(experiments: Sequence[Mapping[str, Any]]) -> str:
    """Tables 4.5 and 4.6: the thesis's own simulation and its depth errors."""
    thesis = {_link_case(row): row for row in _rows("chain_coefficients")}
    missing = "n/a (missing in thesis)"
    body, recomputed = [], []
    for row in experiments:
        key = _link_case(row)
        th = thesis[key]
        has_row = math.isfinite(th["depth_sim"])
        eps = relative_error(row["depth_mean"], th["depth_sim"]) if has_row else math.nan
        recomputed.append(eps)
        body.append(
            [
                str(key[0]),
                str(key[1]),
                f"{th['v0_sim']:.2f}",
                _fmt(th["t_s_sim"], ".0f", 1e3) if has_row else missing,
                _fmt(row["t_s_mean"], ".0f", 1e3),
                _fmt(th["depth_sim"], ".0f", 1e3) if has_row else missing,
                _fmt(row["depth_mean"], ".1f", 1e3),
                _fmt(th["depth_rel_err_pct"], ".2f") if has_row else missing,
                _pct(eps) if has_row else missing,
            ]
        )
    header = [
        "link",
        "case",
        "v0 thesis sim. [m/s]",
        "t_s thesis sim. (Table 4.5) [ms]",
        "t_s exp. (Table 4.2) [ms]",
        "depth thesis sim. (Table 4.5) [mm]",
        "depth exp. (Table 4.2) [mm]",
        "ε depth as printed (Table 4.6) [%]",
        "ε depth recomputed (eq. 4.8) [%]",
    ]
    rms, n = _rms(recomputed)
    return f"""### Tables 4.5-4.6: the thesis's own simulation

The thesis's SolidWorks runs (Table 4.5) and the depth errors it printed (Table 4.6), beside
eq. 4.8 recomputed from the rounded values of Tables 4.2 and 4.5 (the printed errors were
presumably computed from unrounded values; they do not follow from the tables). The case 3,
link 2 row is missing in the source.

{md_table(header, body)}

RMS of the recomputed depth errors: {_pct(rms)} % (n = {n}).
"""


def _ch4_mass_sweep(
    ctx: ReportContext,
    experiments: Sequence[Mapping[str, Any]],
    rms_by_mass: Mapping[float, float],
) -> tuple[str, float, dict[float, dict[int, Result]]]:
    """The link-mass sweep: the mass that best fits the Table 4.2 depths.

    ``rms_by_mass`` holds the RMS depth errors of the masses of :data:`_CHAIN_MASSES` (marked
    on the figure). Returns the Markdown, the best-fit mass [kg] and every run by mass and
    case.
    """
    from .. import plots

    runs: dict[float, dict[int, Result]] = {}
    with ctx.step(f"chapter 4: link mass sweep ({len(_MASS_SWEEP)} masses x 3 cases)"):
        for mass in _MASS_SWEEP:
            runs[mass] = {case: ctx.chain(case, mass=mass) for case in _CHAIN_CASES}

    def objective(mass: float) -> float:
        """RMS relative depth error over the six link-cases at ``mass``."""
        return _chain_depth_rms(experiments, runs[mass])

    coarse_best = min(_MASS_SWEEP, key=objective)
    step = _MASS_SWEEP[1] - _MASS_SWEEP[0]
    lo, hi = max(_MASS_SWEEP[0], coarse_best - step), min(_MASS_SWEEP[-1], coarse_best + step)
    fine = [round(float(m), 6) for m in np.linspace(lo, hi, _MASS_FINE_POINTS)]
    with ctx.step(f"chapter 4: link mass sweep, fine grid ({_grams(lo)}-{_grams(hi)})"):
        for mass in fine:
            if mass not in runs:
                runs[mass] = {case: ctx.chain(case, mass=mass) for case in _CHAIN_CASES}
    best = min(runs, key=objective)
    best_energy = min(runs, key=lambda m: _chain_energy_rms(runs[m]))

    rows = sorted(set(_MASS_SWEEP) | {best, best_energy})
    body = []
    for mass in rows:
        _, e_t = _chain_errors(experiments, runs[mass])
        depths = {
            link: " / ".join(
                _fmt(_link_stop(runs[mass][case], link)[1], ".1f", 1e3) for case in _CHAIN_CASES
            )
            for link in _CHAIN_LINKS
        }
        notes = []
        if mass == best:
            notes.append("best fit to the depths")
        if mass == best_energy:
            notes.append("best fit to the sec. 4.3 energies")
        if mass not in _MASS_SWEEP:
            notes.append("fine grid")
        body.append(
            [
                f"{mass * 1e3:.2f}",
                depths[1],
                depths[2],
                _pct(objective(mass)),
                _pct(_rms(e_t)[0]),
                " / ".join(_fmt(_chain_energy(runs[mass][c]), ".3f") for c in _CHAIN_CASES),
                _pct(_chain_energy_rms(runs[mass])),
                "; ".join(notes),
            ]
        )
    header = [
        "link mass [g]",
        "depth link 1, cases 1 / 2 / 3 [mm]",
        "depth link 2, cases 1 / 2 / 3 [mm]",
        "RMS ε depth vs Table 4.2 [%]",
        "RMS ε t_s vs Table 4.2 [%]",
        "ΔE1 + ΔE2, cases 1 / 2 / 3 [J]",
        "RMS ε ΔE vs sec. 4.3 [%]",
        "note",
    ]
    exp_depths = {
        link: " / ".join(
            _fmt(row["depth_mean"], ".1f", 1e3) for row in experiments if _link_case(row)[0] == link
        )
        for link in _CHAIN_LINKS
    }
    best_e, best_t = _chain_errors(experiments, runs[best])
    agree = (
        ": the thesis's depths and its energies point at different masses."
        if abs(best - best_energy) > step
        else ", within one coarse step of the depth fit."
    )
    ctx.add_headline(
        f"Chain (chapter 4): the link mass is not in the thesis and the depths hang on it. "
        f"Best fit to the Table 4.2 depths over {_grams(_MASS_SWEEP[0])}-"
        f"{_grams(_MASS_SWEEP[-1])}: m = {_grams(best)} per link, RMS relative depth error "
        f"{_pct(objective(best))} % over the 6 link-cases (RMS t_s error "
        f"{_pct(_rms(best_t)[0])} %); the energies the thesis quotes (sec. 4.3) fit "
        f"m = {_grams(best_energy)} best."
    )
    masses = sorted(runs)
    depth_rms = [objective(m) for m in masses]
    time_rms = [_rms(_chain_errors(experiments, runs[m])[1])[0] for m in masses]
    energy_rms = [_chain_energy_rms(runs[m]) for m in masses]
    with ctx.step("chapter 4: link mass figure"):
        panel = plots.Panel(
            "RMS relative errors of the chain against the link mass",
            "RMS relative error [%]",
            [
                plots.Curve(
                    np.array(masses), np.array(depth_rms), 0, "depth vs Table 4.2", marker="."
                ),
                plots.Curve(
                    np.array(masses), np.array(time_rms), 1, "t_s vs Table 4.2", marker="."
                ),
                plots.Curve(
                    np.array(masses), np.array(energy_rms), 2, "ΔE1 + ΔE2 vs sec. 4.3", marker="."
                ),
            ],
            [
                plots.Point(best, objective(best), 0, "chosen"),
                plots.Point(best_energy, _chain_energy_rms(runs[best_energy]), 2, "chosen"),
                *(plots.Point(m, rms_by_mass[m], 0, "other") for m, _ in _CHAIN_MASSES),
            ],
            xlabel="link mass m [g]",
            x_scale=1e3,
            y_scale=100.0,
            legend=True,
        )
        figure = ctx.add_figure(
            "fig_4_link_mass.png",
            plots.png_bytes(
                plots.panel_grid(
                    [[panel]],
                    point_labels={
                        "chosen": "best fit",
                        "other": "depth error at "
                        + " and ".join(_grams(m) for m, _ in _CHAIN_MASSES),
                    },
                    width=8.0,
                    row_height=4.8,
                )
            ),
            "RMS relative errors against the link mass",
        )
    text = f"""### Link mass: which mass fits the experiments?

The chain's depths hang on the link mass, which the thesis does not give. granrs runs the
three cases at {len(_MASS_SWEEP)} masses from {_grams(_MASS_SWEEP[0])} to
{_grams(_MASS_SWEEP[-1])} ({_grams(step)} apart), then at {_MASS_FINE_POINTS} masses within
one step of the best of those ({_grams(lo)}-{_grams(hi)}), and takes the mass with the
smallest RMS relative depth error (eq. 4.8) over the six link-cases of Table 4.2. The
experiments' depths are {exp_depths[1]} mm (link 1) and {exp_depths[2]} mm (link 2). The
last columns compare the energy the two links lose (each from the start to its own stop,
eqs. 4.9-4.10) with the totals the thesis quotes in sec. 4.3 (0.24, 0.18, 0.10 J; whether
they are per link or for the chain is not said: they are taken as the chain's). Shown: the
coarse grid, and the best masses.

{md_table(header, body, "rllrrlrl")}

**Best-fit link mass: {_grams(best)} per link (chain {_grams(2 * best)}), RMS relative depth
error {_pct(objective(best))} % (largest {_pct(max(best_e))} %), RMS relative t_s error
{_pct(_rms(best_t)[0])} %.** The solid-steel default ({_grams(cases.CHAIN["mass"])}) is
{cases.CHAIN["mass"] / best:.2f} times the best fit. The energies quoted in sec. 4.3 are
fitted best at {_grams(best_energy)} (RMS {_pct(_chain_energy_rms(runs[best_energy]))} %){agree}

{figure}
"""
    return text, best, runs


def _ch4_stop_times(
    ctx: ReportContext,
    experiments: Sequence[Mapping[str, Any]],
    runs_by_mass: Mapping[float, ChainRuns],
) -> str:
    """Do the two links stop at the same time? Experiments, thesis and granrs per case."""
    exp = {_link_case(row): row for row in experiments}
    thesis = {_link_case(row): row for row in _rows("chain_coefficients")}
    header = [
        "case",
        "exp. t_s link 1 / 2 [ms]",
        "exp. link 2 - link 1 [ms]",
        "thesis sim. t_s link 1 / 2 [ms]",
        "thesis link 2 - link 1 [ms]",
        "entry offset t1(0) - t2(0), exp. / granrs [ms]",
    ]
    for mass in runs_by_mass:
        header += [f"granrs {_grams(mass)}: t_s link 1 / 2 [ms]", "link 2 - link 1 [ms]"]
    body = []
    later: dict[float, list[float]] = {mass: [] for mass in runs_by_mass}
    for case in _CHAIN_CASES:
        e1, e2 = exp[(1, case)]["t_s_mean"], exp[(2, case)]["t_s_mean"]
        t1, t2 = thesis[(1, case)]["t_s_sim"], thesis[(2, case)]["t_s_sim"]
        first = next(iter(runs_by_mass.values()))[case]
        entry = first.contacts[0].summary["t_entry"] - first.contacts[1].summary["t_entry"]
        cells = [
            str(case),
            f"{_fmt(e1, '.0f', 1e3)} / {_fmt(e2, '.0f', 1e3)}",
            _fmt(e2 - e1, "+.0f", 1e3),
            f"{_fmt(t1, '.0f', 1e3)} / {_fmt(t2, '.0f', 1e3)}",
            _fmt(t2 - t1, "+.0f", 1e3),
            f"{_fmt(_THESIS_ENTRY_OFFSET[case], '+.1f', 1e3)} / {_fmt(entry, '+.2f', 1e3)}",
        ]
        for mass, runs in runs_by_mass.items():
            s1, _ = _link_stop(runs[case], 1)
            s2, _ = _link_stop(runs[case], 2)
            later[mass].append(s2 - s1)
            cells += [
                f"{_fmt(s1, '.1f', 1e3)} / {_fmt(s2, '.1f', 1e3)}",
                _fmt(s2 - s1, "+.1f", 1e3),
            ]
        body.append(cells)

    def order(diffs: Sequence[float]) -> str:
        """Which link stops later, by how much, over the cases."""
        finite = [d for d in diffs if math.isfinite(d)]
        if not finite:
            return "no case has both stops"
        low, high = min(abs(d) for d in finite), max(abs(d) for d in finite)
        spread = (
            f"{_fmt(low, '.1f', 1e3)} ms"
            if math.isclose(low, high, abs_tol=5e-5)
            else f"{_fmt(low, '.1f', 1e3)}-{_fmt(high, '.1f', 1e3)} ms"
        )
        if all(d > 0 for d in finite):
            return f"link 2 stops after link 1 in every case (n = {len(finite)}), by {spread}"
        if all(d < 0 for d in finite):
            return f"link 1 stops after link 2 in every case (n = {len(finite)}), by {spread}"
        return f"the order changes between cases (differences {spread})"

    exp_diffs = [exp[(2, c)]["t_s_mean"] - exp[(1, c)]["t_s_mean"] for c in _CHAIN_CASES]
    thesis_diffs = [thesis[(2, c)]["t_s_sim"] - thesis[(1, c)]["t_s_sim"] for c in _CHAIN_CASES]
    best_mass, best_diffs = list(later.items())[-1]
    ctx.add_headline(
        f"Chain stop times per link (each from its own entry). Experiments (Table 4.2): "
        f"{order(exp_diffs)}; the thesis's simulation: {order(thesis_diffs)}; granrs at "
        f"{_grams(best_mass)}: {order(best_diffs)}."
    )
    granrs_lines = "\n".join(
        f"- granrs, link mass {_grams(mass)}: {order(diffs)}." for mass, diffs in later.items()
    )
    return f"""### Do the two links stop at the same time?

The cases are asymmetric (q1 and q2 of opposite sign and unequal size, different
coefficients per link), so the links need not stop together. Times are per link from its own
tip's entry; the entry offset t1(0) - t2(0) is the measured one (sec. 4.2.2) against the
one granrs gets from the measured angles (the lower tip starts at the surface).

{md_table(header, body)}

- Experiments (Table 4.2): {order(exp_diffs)}.
- The thesis's simulation (Table 4.5): {order(thesis_diffs)}.
{granrs_lines}
"""


def _span(values: Sequence[float], fmt: str, scale: float = 1.0) -> str:
    """``low-high`` of ``values`` (one value if they round the same), for the text."""
    low, high = _fmt(min(values), fmt, scale), _fmt(max(values), fmt, scale)
    return low if low == high else f"{low} to {high}"


def _later(result: Result) -> float:
    """Link 2's stop minus link 1's, each from its own entry [s]."""
    return _link_stop(result, 2)[0] - _link_stop(result, 1)[0]


def _ch4_stop_order_why(ctx: ReportContext, mass: float, runs: ChainRuns) -> str:
    """Why granrs's links stop in the reverse of the measured order: the numbers that show
    it, computed at link mass ``mass`` from ``runs`` (recorded with forces) and from runs
    with the links' coefficients exchanged or made equal, and with each link alone."""
    coef = {_link_case(row): row for row in _rows("chain_coefficients")}
    swapped, same1, same2, alone = [], [], [], []
    static_before, static_after, pin_before, pin_after, creep = [], [], [], [], []
    with ctx.step(f"chapter 4: why the links stop in this order ({_grams(mass)})"):
        for case in _CHAIN_CASES:
            spec = cases.chain_case(case)
            c1, c2 = spec["coefficients"]
            swapped.append(_later(ctx.chain(case, mass=mass, coefficients=(c2, c1))))
            same1.append(_later(ctx.chain(case, mass=mass, coefficients=c1)))
            same2.append(_later(ctx.chain(case, mass=mass, coefficients=c2)))
            t_alone = []
            for link in (0, 1):
                rod = cases.free_link(
                    q_deg=spec["q_deg"][link],
                    v0=spec["v0"],
                    coefficients=spec["coefficients"][link],
                    dt=ctx.dt,
                    **{k: cases.CHAIN[k] for k in ("length", "diameter")},
                    mass=mass,
                )
                t_alone.append(ctx.run(rod).t_s)
            alone.append(t_alone[1] - t_alone[0])
            # The forces on either side of link 2's stop, from the recorded run.
            r = runs[case]
            s = r.series
            assert s is not None
            time = np.asarray(s["t"])
            t1, t2 = r.contacts[0].t_s, r.contacts[1].t_s
            before = max(int(np.searchsorted(time, t2)) - 1, 0)
            after = int(np.searchsorted(time, 0.5 * (t1 + t2)))
            static_before.append((float(s["c0.F_sv"][before]), float(s["c1.F_sv"][before])))
            static_after.append((float(s["c0.F_sv"][after]), float(s["c1.F_sv"][after])))
            pin_before.append(float(s["pin.Fy"][before]))
            pin_after.append(float(s["pin.Fy"][after]))
            creep.append(t1 - t2)
    eta_v1 = [coef[(1, c)]["eta_v"] for c in _CHAIN_CASES]
    eta_v2 = [coef[(2, c)]["eta_v"] for c in _CHAIN_CASES]
    lam1 = [coef[(1, c)]["lambda"] for c in _CHAIN_CASES]
    lam2 = [coef[(2, c)]["lambda"] for c in _CHAIN_CASES]
    eta_d1 = [coef[(1, c)]["eta_d"] for c in _CHAIN_CASES]
    eta_d2 = [coef[(2, c)]["eta_d"] for c in _CHAIN_CASES]
    weight = mass * 9.81
    published = [_later(runs[c]) for c in _CHAIN_CASES]
    ctx.add_headline(
        f"Chain stop order: granrs's reversed order follows Table 4.4's per-link coefficients "
        f"(link 1's eta_v {_span(eta_v1, '.0f')} against link 2's {_span(eta_v2, '.0f')}): "
        f"exchanging the two links' rows exchanges it (link 2 - link 1 "
        f"{_span(published, '+.1f', 1e3)} ms becomes {_span(swapped, '+.1f', 1e3)} ms at "
        f"{_grams(mass)}), and the pin lengthens the gap."
    )
    return f"""**Why granrs's links stop in the reverse order.** Checked at {_grams(mass)} per
link in every case; "link 2 - link 1" is the difference of the stops, each from its link's
own entry.

- **The coefficients set the order.** Table 4.4 gives link 1 a static vertical coefficient
  eta_v = {_span(eta_v1, ".0f")} against link 2's {_span(eta_v2, ".0f")} (lambda
  {_span(lam1, ".3f")} against {_span(lam2, ".3f")}) and more drag (eta_d
  {_span(eta_d1, ".0f")} against {_span(eta_d2, ".1f")}): link 1 is braked mostly by drag,
  link 2 by the static term, the term that brings a tip to rest. Just before link 2 stops,
  the static vertical force is {_span([a for a, _ in static_before], ".2f")} N on link 1
  against {_span([b for _, b in static_before], ".2f")} N on link 2. Each link alone (a free
  rod of the chain's size and mass at its measured angle and the chain's speed, with its own
  Table 4.4 row): link 2 - link 1 = {_span(alone, "+.1f", 1e3)} ms, already the reverse
  order. Exchanging the two links' rows in the chain exchanges the order:
  {_span(swapped, "+.1f", 1e3)} ms, against {_span(published, "+.1f", 1e3)} ms with the
  rows as published. With one row for both links the gap shrinks: link 1's row
  {_span(same1, "+.1f", 1e3)} ms, link 2's row {_span(same2, "+.1f", 1e3)} ms.
- **The pin lengthens the gap.** At link 2's stop its tip turns back and its static force
  drops to a small sticking reaction ({_span([b for _, b in static_after], "+.3f")} N,
  halfway to link 1's stop); the pin's vertical force on link 2 turns from
  {_span(pin_before, "+.2f")} N (link 1 pushing it down) to {_span(pin_after, "+.2f")} N
  (link 1 holding it up; link 2 weighs {weight:.2f} N). Link 1, with a static force of
  {_span([a for a, _ in static_after], ".2f")} N, then carries the chain and keeps sinking
  slowly while the chain turns about link 2's tip, for another {_span(creep, ".0f", 1e3)} ms.

So the order is that of Table 4.4's per-link coefficients, lengthened by the pin. The
thesis's own simulation (Table 4.5) reports the measured order with the same rows; what its
model did differently (its link mass, how it coupled the links) is not stated, so that
difference is not explained here.
"""


def _ch4_quoted(
    experiments: Sequence[Mapping[str, Any]], runs_by_mass: Mapping[float, ChainRuns]
) -> str:
    """The forces and energies quoted in the text of sec. 4.3 against granrs."""
    masses = list(runs_by_mass)
    f_header = ["link", "case", "F_d,max thesis [N]"]
    f_header += [f"F_d,max granrs {_grams(m)} [N]" for m in masses]
    f_header += ["F_s,end thesis [N]"] + [f"F_s,end granrs {_grams(m)} [N]" for m in masses]
    f_body = []
    for row in experiments:
        key = _link_case(row)
        link, case = key
        cells = [str(link), str(case), f"{_THESIS_FD_MAX[key]:g}"]
        cells += [
            _fmt(runs_by_mass[m][case].contacts[link - 1].summary["F_d_max"], ".2f") for m in masses
        ]
        cells.append(f"{_THESIS_FS_END[key]:g}")
        cells += [
            _fmt(runs_by_mass[m][case].contacts[link - 1].summary["F_s_end"], ".2f") for m in masses
        ]
        f_body.append(cells)
    e_header = ["case", "ΔE thesis (sec. 4.3) [J]"]
    e_header += [f"ΔE1 + ΔE2 granrs {_grams(m)} [J]" for m in masses]
    e_header += [f"ΔE1 / ΔE2 granrs {_grams(m)} [J]" for m in masses[:1]]
    e_body = []
    for case in _CHAIN_CASES:
        cells = [str(case), f"{_THESIS_DE[case]:g}"]
        cells += [_fmt(_chain_energy(runs_by_mass[m][case]), ".3f") for m in masses]
        contacts = runs_by_mass[masses[0]][case].contacts
        cells.append(" / ".join(_fmt(c.summary["link_dE"], ".3f") for c in contacts))
        e_body.append(cells)
    return f"""### Forces and energy: the numbers quoted in sec. 4.3

The thesis gives its chain forces and energies only in the text beside Figs. 4.9, 4.10 and
4.15 (its Appendix H plots are images). F_d,max is the largest |F_d| of the link during its
penetration phase, F_s,end |F_s| at its stop; ΔE is the mechanical energy the links lose
from the start of the run to their own stops (eqs. 4.9-4.10), summed over the two links.

{md_table(f_header, f_body)}

{md_table(e_header, e_body)}
"""


def _link_series(result: Result, link: int) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
    """Time since link ``link``'s entry [s], the mask of its penetration phase (entry to
    its stop) and its series by short name (``depth``, ``v_tip_y``, ``F_dx``, ``KE``...)."""
    if result.series is None:  # pragma: no cover - the figure runs record
        raise RuntimeError("chapter 4 figure runs must record their series")
    contact = result.contacts[link - 1]
    t_entry = float(contact.summary["t_entry"])
    t = result.series["t"] - t_entry
    end = contact.t_s - t_entry if contact.stopped else math.inf
    phase = (t >= -1e-12) & (t <= end + 1e-12)
    prefix = f"c{link - 1}."
    named = {k[len(prefix) :]: v for k, v in result.series.items() if k.startswith(prefix)}
    named["KE"] = result.series[f"link{link}.KE"]
    named["PE"] = result.series[f"link{link}.PE"]
    return t, phase, named


def _case_label(runs: ChainRuns, case: int) -> str:
    """``case k (v0 = x m/s)``."""
    return f"case {case} (v0 = {runs[case].scene.v0:.2f} m/s)"


def _ch4_figures(
    ctx: ReportContext,
    experiments: Sequence[Mapping[str, Any]],
    best: float,
    best_runs: ChainRuns,
    steel_runs: ChainRuns,
) -> str:
    """Figs. 4.7-4.16 analogues and the pin force, at the best-fit mass."""
    from .. import plots

    exp = {_link_case(row): row for row in experiments}
    thesis = {_link_case(row): row for row in _rows("chain_coefficients")}
    steel = cases.CHAIN["mass"]
    steel_label = f"granrs, {_grams(steel)} (solid steel)"
    links = []
    with ctx.step("chapter 4: Figs. 4.7-4.16 and the pin force"):
        # Figs. 4.7-4.8: depth and downward tip velocity per link.
        depth_panels, velocity_panels = [], []
        for link in _CHAIN_LINKS:
            d_curves, v_curves, d_points, v_points = [], [], [], []
            for i, case in enumerate(_CHAIN_CASES):
                for runs, style, label in (
                    (best_runs, "-", f"granrs {_case_label(best_runs, case)}, {_grams(best)}"),
                    (steel_runs, "--", steel_label if case == _CHAIN_CASES[-1] else None),
                ):
                    t, _, named = _link_series(runs[case], link)
                    keep = t >= -1e-12
                    d_curves.append(
                        plots.Curve(t[keep], named["depth"][keep], i, label, style, width=1.4)
                    )
                    v_curves.append(
                        plots.Curve(t[keep], -named["v_tip_y"][keep], i, label, style, width=1.4)
                    )
                row = exp[(link, case)]
                e = {"x_sd": row["t_s_sd"]}
                d_points.append(
                    plots.Point(row["t_s_mean"], row["depth_mean"], i, y_sd=row["depth_sd"], **e)
                )
                v_points.append(plots.Point(row["t_s_mean"], 0.0, i, **e))
                th = thesis[(link, case)]
                if math.isfinite(th["t_s_sim"]):
                    d_points.append(plots.Point(th["t_s_sim"], th["depth_sim"], i, "thesis"))
                    v_points.append(plots.Point(th["t_s_sim"], 0.0, i, "thesis"))
                t_s, depth = _link_stop(best_runs[case], link)
                if math.isfinite(t_s):
                    d_points.append(plots.Point(t_s, depth, i, "stop"))
                    v_points.append(plots.Point(t_s, 0.0, i, "stop"))
            depth_panels.append(
                plots.Panel(
                    f"Fig. 4.7 ({'ab'[link - 1]}): tip depth, link {link}",
                    "tip depth d [mm]",
                    d_curves,
                    d_points,
                    y_scale=1e3,
                    xlabel="time since the link's entry [ms]",
                    legend=link == 1,
                )
            )
            velocity_panels.append(
                plots.Panel(
                    f"Fig. 4.8 ({'ab'[link - 1]}): tip vertical velocity, link {link}",
                    r"downward tip velocity $-v_{y,T}$ [m/s]",
                    v_curves,
                    v_points,
                    xlabel="time since the link's entry [ms]",
                    y_from_zero=False,
                    zero_line=True,
                )
            )
        labels = {
            "experiment": "experiment end (Table 4.2, mean ± sd)",
            "thesis": "thesis simulation end (Table 4.5)",
            "stop": f"granrs stop, {_grams(best)}",
        }
        fig = plots.panel_grid(
            [depth_panels, velocity_panels],
            title=f"Figs. 4.7-4.8: the chain's tips, link mass {_grams(best)} (best fit; "
            f"dashed: {_grams(steel)})",
            point_labels=labels,
            row_height=4.6,
        )
        links.append(
            ctx.add_figure(
                "fig_4_7_4_8_depth_velocity.png",
                plots.png_bytes(fig),
                "Figs. 4.7-4.8: tip depth and velocity per link",
            )
            + "\n\n*Top: Fig. 4.7, tip depth against time, (a) link 1, (b) link 2; bottom: "
            "Fig. 4.8, downward tip velocity against time.*"
        )

        # Figs. 4.9-4.12: |F_d|, |F_s|, |F_r| and the dynamic / static shares.
        force_rows: list[list[Any]] = [[], [], [], []]
        for link in _CHAIN_LINKS:
            curves: list[list[Any]] = [[], [], [], []]
            for i, case in enumerate(_CHAIN_CASES):
                t, phase, n = _link_series(best_runs[case], link)
                f_d = np.hypot(n["F_dx"], n["F_dy"])[phase]
                f_s = np.hypot(n["F_sh"], n["F_sv"])[phase]
                f_r = np.hypot(n["F_dx"] + n["F_sh"], n["F_dy"] + n["F_sv"])[phase]
                total = f_d + f_s
                share = np.divide(f_d, total, out=np.full_like(total, np.nan), where=total > 0)
                tp = t[phase]
                label = f"granrs {_case_label(best_runs, case)}"
                curves[0].append(plots.Curve(tp, f_d, i, label))
                curves[1].append(plots.Curve(tp, f_s, i, label))
                curves[2].append(plots.Curve(tp, f_r, i, label))
                curves[3].append(plots.Curve(tp, share, i, f"dynamic, case {case}"))
                curves[3].append(plots.Curve(tp, 1.0 - share, i, f"static, case {case}", ":"))
            ab = "ab"[link - 1]
            for r, (number, name, symbol) in enumerate(
                (
                    ("4.9", "dynamic force", "|F_d|"),
                    ("4.10", "static force", "|F_s|"),
                    ("4.11", "resistance force", "|F_r|"),
                )
            ):
                force_rows[r].append(
                    plots.Panel(
                        f"Fig. {number} ({ab}): {name} {symbol}, link {link}",
                        f"{symbol} [N]",
                        curves[r],
                        xlabel="time since the link's entry [ms]",
                        legend=link == 1 and r == 0,
                    )
                )
            force_rows[3].append(
                plots.Panel(
                    f"Fig. 4.12 ({ab}): dynamic and static share, link {link}",
                    "share of |F_d| + |F_s| [%]",
                    curves[3],
                    y_scale=100.0,
                    xlabel="time since the link's entry [ms]",
                    legend=link == 1,
                )
            )
        fig = plots.panel_grid(
            force_rows,
            title=f"Figs. 4.9-4.12: resistance forces per link during the penetration phase, "
            f"link mass {_grams(best)}",
            row_height=3.6,
        )
        links.append(
            ctx.add_figure(
                "fig_4_9_4_12_forces.png",
                plots.png_bytes(fig),
                "Figs. 4.9-4.12: forces per link",
            )
            + "\n\n*Rows: Fig. 4.9, |F_d|; Fig. 4.10, |F_s|; Fig. 4.11, |F_r|; Fig. 4.12, "
            "the dynamic and static shares; left: link 1, right: link 2.*"
        )

        # Figs. 4.13-4.16: KE, PE and E lost per link and the KE / PE shares.
        energy_rows: list[list[Any]] = [[], [], [], []]
        for link in _CHAIN_LINKS:
            curves = [[], [], [], []]
            for i, case in enumerate(_CHAIN_CASES):
                t, phase, n = _link_series(best_runs[case], link)
                tp = t[phase]
                ke0 = float(np.interp(0.0, t, n["KE"]))
                pe0 = float(np.interp(0.0, t, n["PE"]))
                ke_lost = ke0 - n["KE"][phase]
                pe_lost = pe0 - n["PE"][phase]
                total = ke_lost + pe_lost
                floor = 1e-3 * float(np.max(np.abs(total))) if total.size else 0.0
                ke_share = np.divide(
                    ke_lost, total, out=np.full_like(total, np.nan), where=np.abs(total) > floor
                )
                label = f"granrs {_case_label(best_runs, case)}"
                curves[0].append(plots.Curve(tp, ke_lost, i, label))
                curves[1].append(plots.Curve(tp, pe_lost, i, label))
                curves[2].append(plots.Curve(tp, total, i, label))
                curves[3].append(plots.Curve(tp, ke_share, i, f"KE, case {case}"))
                curves[3].append(plots.Curve(tp, 1.0 - ke_share, i, f"PE, case {case}", ":"))
            ab = "ab"[link - 1]
            for r, (number, name) in enumerate(
                (
                    ("4.13", "kinetic energy lost ΔKE"),
                    ("4.14", "potential energy lost ΔPE"),
                    ("4.15", "mechanical energy lost ΔE"),
                )
            ):
                energy_rows[r].append(
                    plots.Panel(
                        f"Fig. {number}: {name}, link {link}",
                        f"{name.split()[-1]} [mJ]",
                        curves[r],
                        y_scale=1e3,
                        xlabel="time since the link's entry [ms]",
                        legend=link == 1 and r == 0,
                    )
                )
            energy_rows[3].append(
                plots.Panel(
                    f"Fig. 4.16 ({ab}): shares of ΔKE and ΔPE in ΔE, link {link}",
                    "share of ΔE [%]",
                    curves[3],
                    y_scale=100.0,
                    ylim=(0.0, 110.0),
                    xlabel="time since the link's entry [ms]",
                    legend=link == 1,
                )
            )
        fig = plots.panel_grid(
            energy_rows,
            title=f"Figs. 4.13-4.16: energy each link loses since its entry (eqs. 4.9-4.10), "
            f"link mass {_grams(best)}",
            row_height=3.6,
        )
        links.append(
            ctx.add_figure(
                "fig_4_13_4_16_energy.png",
                plots.png_bytes(fig),
                "Figs. 4.13-4.16: energy per link",
            )
            + "\n\n*Rows: Fig. 4.13, ΔKE; Fig. 4.14, ΔPE; Fig. 4.15, ΔE; Fig. 4.16, the "
            "shares of ΔKE and ΔPE in ΔE; left: link 1, right: link 2.*"
        )

        # The pin force (the thesis has no figure of it).
        pin_curves = []
        for i, case in enumerate(_CHAIN_CASES):
            for runs, style, label in (
                (best_runs, "-", f"granrs {_case_label(best_runs, case)}, {_grams(best)}"),
                (steel_runs, "--", steel_label if case == _CHAIN_CASES[-1] else None),
            ):
                series = runs[case].series
                assert series is not None
                force = np.hypot(series["pin.Fx"], series["pin.Fy"])
                pin_curves.append(plots.Curve(series["t"], force, i, label, style, width=1.4))
        fig = plots.panel_grid(
            [
                [
                    plots.Panel(
                        "Pin force: the force link 1 exerts on link 2",
                        "|F_pin| [N]",
                        pin_curves,
                        xlabel="time since the first tip's entry [ms]",
                        legend=True,
                    )
                ]
            ],
            width=8.0,
            row_height=4.6,
        )
        links.append(
            ctx.add_figure("fig_4_pin_force.png", plots.png_bytes(fig), "Pin force against time")
            + "\n\n*The magnitude of the force link 1 exerts on link 2 at the pin (no thesis "
            "figure).*"
        )
    return f"""### Figs. 4.7-4.16: the chain against time

granrs at the best-fit link mass ({_grams(best)}), Table 4.4 coefficients, force at the tip;
each link's time runs from its own tip's entry. Figs. 4.7-4.8: tip depth and downward tip
velocity per link over the whole run (solid; dashed: the solid-steel mass), with the
experiments' end points (Table 4.2, mean ± sd), the thesis's simulated end points (Table 4.5)
and the granrs stops. Figs. 4.9-4.16 cover each link's penetration phase (its entry to its
own stop): |F_d|, |F_s| = |(F_sh, F_sv)| and |F_r| = |F_d + F_s| (eqs. 4.1-4.2); the dynamic
share |F_d| / (|F_d| + |F_s|) and the static share 1 - that (Fig. 4.12); and the kinetic,
potential and mechanical energy each link has lost since its entry (eqs. 4.9-4.10), with the
kinetic and potential shares of the total (Fig. 4.16; just after entry a link still gains
kinetic energy, so ΔKE < 0 and the potential share exceeds 100 %: that panel is clipped at
110 %). The thesis's own curves are images
and are not reproduced. Last: the magnitude of the pin force on link 2 over the whole run
(the thesis has no such figure).

{chr(10).join(chr(10) + link for link in links)}
"""


@register_chapter("4", "Chapter 4: the two-link chain")
def chapter_4(ctx: ReportContext) -> str:
    """Chapter 4: the chain against Tables 4.2 and 4.5-4.6, the link mass, Figs. 4.7-4.16."""
    experiments = _rows("chain_experiments")
    runs_by_mass: dict[float, dict[int, Result]] = {}
    with ctx.step("chapter 4: Table 4.2 (experiments) vs granrs at two link masses"):
        for mass, _ in _CHAIN_MASSES:
            runs_by_mass[mass] = {
                case: ctx.chain(case, mass=mass, record=_CHAIN_RECORD) for case in _CHAIN_CASES
            }
    table_4_2, rms_by_mass = _ch4_table_4_2(experiments, runs_by_mass)
    ctx.add_headline(
        "Chain (chapter 4) depths vs Table 4.2, RMS relative error over the 6 link-cases: "
        + "; ".join(
            f"{_pct(rms_by_mass[m])} % at {_grams(m)} per link ({label})"
            for m, label in _CHAIN_MASSES
        )
        + "."
    )
    table_4_5 = _ch4_table_4_5(experiments)
    sweep_text, best, _ = _ch4_mass_sweep(ctx, experiments, rms_by_mass)
    with ctx.step(f"chapter 4: runs at the best-fit mass ({_grams(best)})"):
        best_runs = {
            case: ctx.chain(case, mass=best, record=_CHAIN_RECORD) for case in _CHAIN_CASES
        }
    compared: dict[float, ChainRuns] = {**runs_by_mass, best: best_runs}
    stops = _ch4_stop_times(ctx, experiments, compared)
    stops += "\n" + _ch4_stop_order_why(ctx, best, best_runs)
    quoted = _ch4_quoted(experiments, compared)
    figures = _ch4_figures(ctx, experiments, best, best_runs, runs_by_mass[cases.CHAIN["mass"]])
    return "\n".join(
        [
            "The thesis's two-link chain (sec. 4.1): two round-ended steel links, L = 0.135 m, "
            "d = 0.0064 m, pinned at their top ends by a frictionless joint, falling onto the "
            "play sand of chapter 3 (rho_g = 1650 kg/m³ assumed; the thesis does not restate "
            "it). Link 1 leans at q1 ≈ -15°, link 2 at q2 ≈ +15° (Table 4.1). Coefficients: "
            "Table 4.4 per link and case (the case 3, link 2 row is missing in the source: "
            "the Table 4.3 expressions at alpha = 74°). **The link mass is not in the thesis**; "
            "the report shows it as an unknown.",
            "",
            table_4_2,
            table_4_5,
            sweep_text,
            stops,
            quoted,
            figures,
            _watch(ctx),
        ]
    )


def _watch(ctx: ReportContext) -> str:
    """Chain case 1 as an animation."""
    return ctx.watch(
        "ch4_chain_case1.gif",
        cases.chain(case=1, dt=ctx.dt, end="all_stops"),
        "Case 1 until both links stop, one frame per 2 ms (solid-steel link mass).",
        frame_dt=2e-3,
    )
