"""The laws chapter's evidence on the chain and the leg (granrs.report.laws_evidence):
the factor search against closed forms, the thesis's own leg scaling and tolerance from its
published numbers, and the leg's table against independent runs."""

from __future__ import annotations

import math
import re
import types

import pandas as pd
import pytest

import granrs
from granrs import cases
from granrs import forces as F
from granrs.report import laws_evidence as ev
from granrs.report.framework import ReportContext


def test_smallest_factor_depth_inverse_in_the_factor() -> None:
    """depth = c / f (a resistance scaled by f): within 10 % at both heights means
    c1 / f and c2 / f in [0.9, 1.1]: f in [c / 1.1, c / 0.9] for each, by hand."""

    def errors(c1: float, c2: float):
        return lambda f: [c1 / f - 1.0, c2 / f - 1.0]

    # [2 / 1.1, 2 / 0.9] and [2.2 / 1.1, 2.2 / 0.9] meet on [2.0, 2.22]: nearest 1 is 2.0.
    res = ev.smallest_factor(errors(2.0, 2.2), 0.1)
    assert res["factor"] == pytest.approx(2.0, rel=0.011)
    assert max(abs(e) for e in res["errors"]) <= 0.1 + 1e-12
    # Below 1 the same way: [0.5 / 1.1, 0.5 / 0.9] and [0.52 / 1.1, 0.52 / 0.9]: 0.5 / 0.9.
    res = ev.smallest_factor(errors(0.5, 0.52), 0.1)
    assert res["factor"] == pytest.approx(0.5 / 0.9, rel=0.011)
    # Already within: factor 1.
    assert ev.smallest_factor(errors(1.05, 0.95), 0.1)["factor"] == 1.0
    # [0.91, 1.11] and [1.82, 2.22] do not meet: no factor; the balanced one has
    # 1 / f + 2 / f = 2, f = 1.5, errors -1/3 and +1/3.
    res = ev.smallest_factor(errors(1.0, 2.0), 0.1)
    assert res["factor"] is None
    assert res["best"] == pytest.approx(1.5, rel=0.011)
    assert res["best_errors"][0] == pytest.approx(-1 / 3, abs=0.01)
    # Out of the searched range (x30): none.
    assert ev.smallest_factor(errors(100.0, 100.0), 0.1)["factor"] is None


def test_thesis_leg_scaling_against_table_3_2_at_90_degrees() -> None:
    """The thesis's leg coefficients (sec. 5.3.2) against Table 3.2's closed forms at
    alpha = pi/2 with rho_g = 1600: lambda = rho_g / alpha * 1e-4 = 0.1019, and the leg's
    lambda 1.05 is x10.3 that, the largest factor."""
    table, worst = ev._thesis_scaling(1600.0)
    lam_start = 1600.0 / (math.pi / 2) * 1e-4
    assert worst == pytest.approx(1.05 / lam_start, rel=1e-9)
    assert "= 10x" in table
    eta_h = 1600.0 / ((math.pi / 2) ** 2 * 100.0)
    assert f"{eta_h:.3g}" in table


def test_leg_tolerance_is_the_thesis_own_depth_error() -> None:
    """Table 5.1's subject means per height (0.064 and 0.0528 m) against the thesis's
    simulated 0.06 and 0.05 m: eq. 5.16 gives 6.25 % and 5.3 %; the larger is the
    tolerance."""
    m, tol, text = ev._leg_reference()
    assert tol == pytest.approx(abs(0.064 - 0.06) / 0.064, rel=1e-6)
    assert list(m.rows["depth_mean"]) == pytest.approx([0.064, 0.0528], rel=1e-9)
    assert "printed: 1.17 %" in text


def _thesis_q0_terms():
    """The thesis's terms with Table 3.4's q = 0 row, the body's terms included, and the
    rod's axial drag (not defined on the sole)."""
    return (
        F.term("gravity"),
        F.term("drag", eta_d=15.2),
        F.term("static_h", eta_h=6.5),
        F.term("static_v", eta_v=248.0, lam=0.106),
        F.term("axial_drag", eta_a=2.0),
        F.term("joint_springs"),
    )


def test_leg_section_factors_reproduce_the_depths_in_independent_runs() -> None:
    terms = _thesis_q0_terms()
    values = {
        "scale.drag.eta_d": 1.0,
        "scale.static_h.eta_h": 1.0,
        "scale.static_v.eta_v": 1.0,
        "scale.static_v.lam": 1.0,
        "axial_drag.eta_a": 2.0,
    }
    result = types.SimpleNamespace(terms=lambda row: terms, values=values)
    record = {"law": "thesis_refit+axial_drag", "rank": 1, "result": result, "folds": [{}]}
    ctx = ReportContext(dt=1e-4, progress=False)
    text, line = ev.leg_section(ctx, [record])
    assert "#### The leg with the laws fitted on Table 3.1" in text
    assert "left out (no term on the sole): axial_drag" in text
    m, tol, _ = ev._leg_reference()
    rows = m.rows.to_dict("records")
    sole = tuple(t for t in terms if t.name != "axial_drag")

    def runs(eta_v_factor: float) -> list[granrs.Result]:
        out = []
        for r in rows:
            scaled = tuple(
                t.replace(eta_v=t.params["eta_v"] * eta_v_factor) if t.name == "static_v" else t
                for t in sole
            )
            scene = cases.leg(r["v0_mean"], joints="locked", forces=scaled)
            out.append(granrs.simulate(scene))
        return out

    def depths(eta_v_factor: float) -> list[float]:
        return [r.depth for r in runs(eta_v_factor)]

    # The depths as carried (factor 1), from independent runs.
    row = next(x for x in text.splitlines() if x.startswith("| thesis_refit+axial_drag"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[2] == ", ".join(f"{d * 1e3:.1f}" for d in depths(1.0))
    assert cells[4].startswith(", ".join(f"{r.t_s * 1e3:.1f}" for r in runs(1.0)))
    # eta_v alone: its factor, run here, puts both depths within the tolerance.
    found = re.search(r"static_v\.eta_v ([0-9.]+)x", cells[5])
    assert found, cells[5]
    f = float(found.group(1))
    for d, r in zip(depths(f), rows, strict=True):
        assert abs(d - r["depth_mean"]) / r["depth_mean"] <= tol + 0.01
    assert line.startswith("- **Leg, laws fitted on Table 3.1**")
    assert ("**met**" in line) == (cells[6] == "yes")


def test_chain_measured_facts_from_tables_4_1_and_4_2() -> None:
    """Link 1 stops first in every case (Tables 4.1-4.2: 24 vs 26, 26 vs 30, 29 vs 32 ms)
    and 2 of the 6 depth sd (0.5 and 0.3 mm) are within the printed means' rounding."""
    m = granrs.Measurements.thesis("table_4_chain")
    text = ev._measured_facts(m)
    for case, ms in ((1, 2), (2, 4), (3, 3)):
        assert f"case {case}: link 1 first by {ms} ms" in text
    assert "2 of 6 rows have an sd no larger" in text


def test_chain_section_counts_in_and_out_of_sample() -> None:
    """The published law fits nothing: its in-sample counts are its out-of-sample ones, and
    its row z are those of independent runs of the thesis's chain cases."""
    frame = granrs.compare(["thesis_published"], "table_4_chain", progress=False)
    records = frame.to_dict("records")
    ctx = ReportContext(dt=1e-4, progress=False)
    text, line = ev.chain_section(ctx, records)
    assert "#### Why the chain misses" in text
    assert line.startswith("- **Chain, why**")
    rows = pd.read_csv(granrs.data.path("table_4_chain_experiments"))
    runs = {c: granrs.simulate(cases.chain(case=c, end="all_stops")) for c in (1, 2, 3)}
    lines = [x for x in text.splitlines() if re.match(r"\| [123] \| [12] \|", x)]
    assert len(lines) == 6
    for x in lines:
        cells = [c.strip() for c in x.strip("|").split("|")]
        case, link = int(cells[0]), int(cells[1])
        r = rows[(rows["v0_case"] == case) & (rows["link"] == link)].iloc[0]
        depth = runs[case].contacts[link - 1].depth
        z = (depth - r["depth_mean"]) / r["depth_sd"]
        out, _ = cells[4].split(" / ")
        assert float(out) == pytest.approx(z, abs=0.051)
    # The link that stops first per case, from the same independent runs.
    firsts = []
    for c in (1, 2, 3):
        t1, t2 = (runs[c].contacts[i].t_s for i in (0, 1))
        firsts.append("1" if t1 < t2 else "2" if t2 < t1 else "0")
    row = next(x for x in text.splitlines() if x.startswith("| thesis_published |"))
    assert f"(first: {', '.join(firsts)})" in row
