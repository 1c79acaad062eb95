"""Tests of the law comparison (granrs.compare, ``granrs compare``) and of calibrating any
term's parameter by name (issue 18); failed runs counted, never a better fit (issue 34).

Expected values come from independent granrs.simulate runs, from granrs.calibrate called
directly on the same rows, from the shipped tables, and from the parameters that made
synthetic measurements; never from numbers the comparison computes for itself.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pandas as pd
import pytest

import granrs
from granrs import cases, forces
from granrs.calibrate import Measurements, calibrate
from granrs.cli import main
from granrs.compare import LAWS, Law, compare, sums, synthetic, to_json
from granrs.errors import InvalidParameterError, SimulationError, StepSizeWarning, UnknownNameError

TABLE_3_1 = Measurements.thesis("table_3_1")
#: The keys the issue asks of each law's entry in laws.json.
ENTRY_KEYS = {
    "n_params",
    "chi2_dof",
    "aic",
    "bic",
    "n_rows",
    "depth_within_1sd",
    "ts_within_1sd",
    "ts_within_2sd",
    "rows",
}
ROW_KEYS = {"depth_mean", "depth_sd", "depth_pred", "t_s_mean", "t_s_sd", "t_s_pred"}

#: The thesis's static terms without the drag: a second law to tell apart from the
#: thesis's (and to make synthetic data with), one set of values for every angle.
STATIC_ONLY = Law(
    "static_only",
    "gravity, static_h and static_v; no drag",
    terms=(("static_h", {"eta_h": 6.5}), ("static_v", {"eta_v": 248.0, "lam": 0.106})),
    fit={"static_v.eta_v": (150.0, 1.0, 1e4), "static_v.lam": (0.3, 0.0, 3.0)},
)
#: The thesis's law with two of its four scale factors fitted.
THESIS_TWO = Law(
    "thesis_two",
    "the thesis's law, drag and static_v scaled",
    thesis=True,
    fit={"scale.drag.eta_d": (1.0, 0.05, 20.0), "scale.static_v.eta_v": (1.0, 0.05, 20.0)},
)


# ------------------------------------------------------------------------------------------
# calibrate: any term's parameter by name


def test_term_parameter_names_are_the_thesis_short_names() -> None:
    """``static_v.eta_v`` and ``eta_v`` are one parameter: the same fit either way."""
    rows = TABLE_3_1.subset(q_deg=45.0)
    a = calibrate("free_link", rows, ["static_v.eta_v", "drag.eta_d"])
    b = calibrate("free_link", rows, ["eta_v", "eta_d"])
    assert a.values["static_v.eta_v"] == pytest.approx(b.values["eta_v"], rel=1e-9)
    assert a.values["drag.eta_d"] == pytest.approx(b.values["eta_d"], rel=1e-9)
    # The fitted terms carry the values: the row's scene is the thesis's with them.
    row = {"q_deg": 45.0, "v0_mean": 2.27}
    terms = {t.name: t for t in a.terms(row)}
    assert terms["static_v"].params["eta_v"] == a.values["static_v.eta_v"]
    assert terms["drag"].params["eta_d"] == a.values["drag.eta_d"]


def test_fits_a_term_of_a_user_law_and_recovers_it() -> None:
    """A law given as terms: its parameter is fitted by name and recovered from noiseless
    runs made with granrs.simulate."""
    law = [forces.gravity(), forces.static_v(eta_v=100.0, lam=0.2)]
    rows = TABLE_3_1.subset(q_deg=[0.0, 45.0]).rows.copy()
    for i, r in rows.iterrows():
        scene = cases.free_link(
            r["q_deg"], r["v0_mean"], forces=[law[0], law[1].replace(eta_v=180.0)]
        )
        res = granrs.simulate(scene)
        rows.loc[i, "depth_mean"], rows.loc[i, "t_s_mean"] = res.depth, res.t_s
    m = Measurements("free_link", rows, "made by granrs")
    fit = calibrate(
        "free_link", m, ["static_v.eta_v"], forces=law, bounds={"static_v.eta_v": (10, 1e4)}
    )
    assert fit.values["static_v.eta_v"] == pytest.approx(180.0, rel=1e-4)


def test_chain_link_mass_is_fitted_within_bounds() -> None:
    fit = calibrate(
        "chain",
        Measurements.thesis("table_4_chain"),
        ["mass"],
        bounds={"mass": (0.005, 0.0341)},
    )
    assert 0.005 <= fit.values["mass"] <= 0.0341
    # The fitted mass is what the scenes ran with: one run at that mass agrees.
    res = granrs.simulate(cases.chain(case=1, mass=fit.values["mass"], end="all_stops"))
    row = fit.residuals[(fit.residuals["v0_case"] == 1) & (fit.residuals["link"] == 1)].iloc[0]
    assert row["depth_sim"] == pytest.approx(res.contacts[0].depth, rel=1e-9)


@pytest.mark.parametrize(
    ("params", "kwargs", "error", "field"),
    [
        (["stati_v.eta_v"], {}, UnknownNameError, "stati_v.eta_v"),
        (["static_v.eta"], {}, UnknownNameError, "static_v.eta"),
        (["eta_v", "static_v.eta_v"], {}, InvalidParameterError, "static_v.eta_v"),
        (
            ["drag.eta_d"],
            {"forces": [forces.gravity(), forces.static_v()]},
            UnknownNameError,
            "drag.eta_d",
        ),
        (["mass"], {"forces": "static_v"}, InvalidParameterError, "forces"),
    ],
)
def test_bad_term_parameters_are_typed_errors(params, kwargs, error, field) -> None:
    with pytest.raises(error) as info:
        calibrate("free_link", TABLE_3_1, params, **kwargs)
    assert info.value.field == field


@pytest.mark.skipif("poncelet" not in forces.TERMS, reason="no poncelet term in this build")
def test_a_parameter_without_default_needs_bounds() -> None:
    """poncelet.c has no default: fitting it needs bounds (a typed error names them)."""
    law = [forces.gravity(), forces.term("poncelet", c=1.0, k=100.0)]
    rows = TABLE_3_1.subset(q_deg=45.0)
    with pytest.raises(InvalidParameterError) as info:
        calibrate("free_link", rows, ["poncelet.c"], forces=law)
    assert info.value.field == "bounds.poncelet.c"
    fit = calibrate(
        "free_link", rows, ["poncelet.c"], forces=law, bounds={"poncelet.c": (0.01, 100)}
    )
    assert 0.01 <= fit.values["poncelet.c"] <= 100


def test_joints_are_leg_only() -> None:
    with pytest.raises(UnknownNameError):
        calibrate("free_link", TABLE_3_1, ["joints.k"])


# ------------------------------------------------------------------------------------------
# compare


@pytest.fixture(scope="module")
def free_link_frame():
    return compare(["thesis_published", THESIS_TWO], TABLE_3_1, progress=False)


def test_published_law_is_the_thesis_simulation(free_link_frame) -> None:
    """thesis_published fits nothing; its predictions are the thesis's Table 3.4 runs."""
    entry = to_json(free_link_frame)["free_link"]["thesis_published"]
    assert entry["n_params"] == 0
    assert entry["folds"] == []
    for r in entry["rows"]:
        res = granrs.simulate(cases.free_link(r["q_deg"], r["v0_mean"]))
        assert r["depth_pred"] == pytest.approx(res.depth, rel=1e-12)
        assert r["t_s_pred"] == pytest.approx(res.t_s, rel=1e-12)


def test_out_of_sample_rows_come_from_the_fold_without_them(free_link_frame) -> None:
    """Each held-out angle is predicted by calibrate fitted to the other angles."""
    entry = to_json(free_link_frame)["free_link"]["thesis_two"]
    folds = {f["held_out"]: f for f in entry["folds"]}
    assert set(folds) == {"all", 0.0, 45.0, 60.0, 75.0}
    q = 60.0
    train = TABLE_3_1.subset(TABLE_3_1.rows["q_deg"] != q)
    fit = calibrate(
        "free_link",
        train,
        list(THESIS_TWO.fit),
        bounds={k: v[1:] for k, v in THESIS_TWO.fit.items()},
        forces=THESIS_TWO.terms_for("free_link"),
    )
    for p, v in fit.values.items():
        assert folds[q]["values"][p] == pytest.approx(v, rel=1e-9)
    pred = fit.predict(TABLE_3_1.subset(q_deg=q))
    rows = [r for r in entry["rows"] if r["q_deg"] == q]
    assert [r["depth_pred"] for r in rows] == pytest.approx(list(pred["depth_sim"]), rel=1e-12)
    assert all(r["held_out_with"] == q for r in rows)


def test_counts_and_criteria_follow_from_the_rows(free_link_frame) -> None:
    """The counts are the rows' z within 1 and 2 sd; AIC and BIC follow chi2 and k."""
    for entry in to_json(free_link_frame)["free_link"].values():
        rows = entry["rows"]
        z_d = [(r["depth_pred"] - r["depth_mean"]) / r["depth_sd"] for r in rows]
        z_t = [(r["t_s_pred"] - r["t_s_mean"]) / r["t_s_sd"] for r in rows]
        assert entry["depth_within_1sd"] == sum(abs(z) <= 1 + 1e-12 for z in z_d)
        assert entry["ts_within_1sd"] == sum(abs(z) <= 1 + 1e-12 for z in z_t)
        assert entry["ts_within_2sd"] == sum(abs(z) <= 2 + 1e-12 for z in z_t)
        k, n = entry["n_params"], 2 * entry["n_rows"]
        assert entry["aic"] == pytest.approx(entry["chi2"] + 2 * k)
        assert entry["bic"] == pytest.approx(entry["chi2"] + k * math.log(n))
        assert entry["chi2_dof"] == pytest.approx(entry["chi2"] / (n - k))
        assert ENTRY_KEYS <= set(entry)
        assert all(ROW_KEYS <= set(r) for r in rows)


def test_a_law_whose_term_is_missing_is_unavailable() -> None:
    ghost = Law("ghost", "a term this build lacks", terms=(("no_such_term", {}),))
    frame = compare(["thesis_published", ghost], TABLE_3_1.subset(q_deg=45.0), progress=False)
    row = frame.set_index("law").loc["ghost"]
    assert not row["available"]
    assert "no_such_term" in row["reason"]
    assert frame.set_index("law").loc["thesis_published", "available"]
    # The named laws whose terms are not built are reported the same way.
    for name, law in LAWS.items():
        if any(t not in forces.TERMS for t in law.needs()):
            f = compare([name], TABLE_3_1.subset(q_deg=45.0), progress=False)
            assert not f["available"].iloc[0], name


#: No sand force: every run falls to its end time (a finite t_s and depth, far off).
FREE_FALL = Law("free_fall", "gravity alone, no sand force")


def _failing_rows(m: Measurements, dt: float) -> int:
    """The rows of ``m`` whose thesis run (granrs.simulate) fails at ``dt``: counted
    independently of the comparison."""
    failed = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StepSizeWarning)
        for r in m.rows.to_dict("records"):
            try:
                granrs.simulate(cases.free_link(r["q_deg"], r["v0_mean"], dt=dt))
            except SimulationError:
                failed += 1
    return failed


def test_failed_runs_are_counted_and_never_a_better_fit() -> None:
    """Issue 34: a failed run leaves NaN residuals that the sum skipped, so at dt = 0.05
    (six of Table 3.1's twelve runs diverge under the thesis's law) the law got the chi2 of
    the six that ran, and no count said so. Now each failed row is counted, the statistics
    over it are undefined (None in JSON), and the law ranks after a law whose every run
    ran, however far off that one is (free fall)."""
    dt = 0.05
    failed = _failing_rows(TABLE_3_1, dt)
    assert 0 < failed < len(TABLE_3_1)
    frame = compare([FREE_FALL, "thesis_published"], TABLE_3_1, dt=dt, progress=False)
    entries = to_json(frame)["free_link"]
    published = entries["thesis_published"]
    assert published["failed_in_sample"] == failed
    assert published["failed_out_of_sample"] == failed
    assert sum(r["failed"] for r in published["rows"]) == failed
    for r in published["rows"]:
        assert r["failed"] == (r["depth_pred"] is None or r["t_s_pred"] is None)
    for key in ("chi2", "chi2_dof", "aic", "bic", "oos_chi2"):
        assert published[key] is None, key
    fall = entries["free_fall"]
    assert fall["failed_in_sample"] == fall["failed_out_of_sample"] == 0
    assert all(math.isfinite(fall[k]) for k in ("chi2", "aic", "oos_chi2"))
    assert (fall["rank"], published["rank"]) == (1, 2)


def test_a_fitted_law_with_failed_runs_has_no_chi2() -> None:
    """The fit's chi2 counts a failed run as a large residual (1e3 sd, so that the
    optimizer steps back): it is not the law's chi2. At dt = 0.05 the rows at 45 deg
    fail; the fit's and its fold's chi2 are undefined and the failures counted."""
    m = TABLE_3_1.subset(q_deg=[0.0, 45.0])
    failed = _failing_rows(m, 0.05)
    assert failed > 0
    frame = compare([THESIS_TWO], m, dt=0.05, folds=None, progress=False)
    entry = to_json(frame)["free_link"]["thesis_two"]
    assert entry["failed_in_sample"] >= 1
    assert entry["chi2"] is None and entry["aic"] is None
    (fold,) = entry["folds"]
    assert fold["failed"] == entry["failed_in_sample"]
    assert fold["chi2"] is None


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"dt": 0.0}, "dt"),
        ({"dt": math.nan}, "dt"),
        ({"dt": -1e-4}, "dt"),
        ({"dt": "abc"}, "dt"),
        ({"threads": -2}, "threads"),
        ({"threads": 0}, "threads"),
        ({"laws": []}, "laws"),
    ],
)
def test_bad_options_are_typed_errors_before_any_run(kwargs, field, monkeypatch) -> None:
    """Issue 34: an invalid dt was caught as a failed point of every run (dt = 0: every run
    failed and the law got chi2 = 0, AIC 0); threads=-2 gave a 'law unavailable' row per
    law, laws=[] a KeyError. Each is now the typed error naming the option, raised
    before any run (the sweep is replaced by one that fails the test if called)."""
    import granrs.batch

    def no_run(*args, **kw):
        raise AssertionError("a run started before the options were checked")

    monkeypatch.setattr(granrs.batch, "sweep", no_run)
    args = {"laws": ["thesis_published"], "measurements": TABLE_3_1, "progress": False}
    with pytest.raises(InvalidParameterError) as info:
        compare(**{**args, **kwargs})
    assert info.value.field == field


def test_synthetic_refuses_a_bad_step_and_failed_runs() -> None:
    """Issue 34: ``synthetic`` caught an invalid dt as failed runs and drew measurements
    around NaN (dt = 0: all twelve means NaN; dt = 0.05: six). An invalid dt is the scene's
    typed error; failed runs a SimulationError saying how many."""
    with pytest.raises(InvalidParameterError) as info:
        synthetic("thesis_published", {}, TABLE_3_1, dt=0.0)
    assert info.value.field == "dt"
    failed = _failing_rows(TABLE_3_1, 0.05)
    with pytest.raises(SimulationError, match=f"{failed} of 12 rows failed"):
        synthetic("thesis_published", {}, TABLE_3_1, dt=0.05)


def test_bad_arguments() -> None:
    with pytest.raises(UnknownNameError) as info:
        compare(["thesis_publish"], TABLE_3_1)
    assert "thesis_published" in str(info.value)
    with pytest.raises(UnknownNameError):
        compare(["thesis_published"], TABLE_3_1, folds="angle")
    with pytest.raises(InvalidParameterError):
        compare(["thesis_published", "thesis_published"], TABLE_3_1)
    with pytest.raises(InvalidParameterError):
        compare(["thesis_published"], 3.0)


# ------------------------------------------------------------------------------------------
# Synthetic recovery: the comparison picks the law that made the data and recovers it


@pytest.mark.parametrize(
    ("maker", "truth"),
    [
        (
            "thesis_refit",
            {
                "scale.static_h.eta_h": 1.4,
                "scale.drag.eta_d": 0.7,
                "scale.static_v.eta_v": 1.3,
                "scale.static_v.lam": 0.8,
            },
        ),
        (STATIC_ONLY, {"static_v.eta_v": 150.0, "static_v.lam": 0.4}),
    ],
    ids=["thesis_refit", "static_only"],
)
def test_synthetic_recovery(maker, truth) -> None:
    data = synthetic(maker, truth, TABLE_3_1, rel_sd=0.03, seed=1)
    frame = compare(["thesis_published", "thesis_refit", STATIC_ONLY], data, progress=False)
    name = maker if isinstance(maker, str) else maker.name
    ranked = frame.sort_values("rank")
    assert ranked["law"].iloc[0] == name, ranked[["law", "oos_chi2", "aic"]]
    assert frame.set_index("law")["aic"].idxmin() == name
    entry = to_json(frame)["free_link"][name]
    full = next(f for f in entry["folds"] if f["held_out"] == "all")
    for p, v in truth.items():
        lo, hi = full["intervals"][p]
        assert lo <= v <= hi, (p, v, lo, hi, full["values"][p])
        # Determined, not merely bounded: the interval is less than a factor 20 wide (a
        # direction the data do not fix has an interval of many decades).
        assert 0 < lo and hi / lo < 20, (p, lo, hi)


@pytest.mark.skipif("poncelet" not in forces.TERMS, reason="no poncelet term in this build")
def test_synthetic_recovery_poncelet() -> None:
    """Measurements made under poncelet alone: the comparison picks it over the thesis's
    laws and recovers c and k within their intervals."""
    truth = {"poncelet.c": 2.0, "poncelet.k": 400.0}
    data = synthetic("poncelet", truth, TABLE_3_1, rel_sd=0.03, seed=1)
    frame = compare(["thesis_published", "thesis_refit", "poncelet"], data, progress=False)
    ranked = frame.sort_values("rank")
    assert ranked["law"].iloc[0] == "poncelet", ranked[["law", "oos_chi2", "aic"]]
    assert frame.set_index("law")["aic"].idxmin() == "poncelet"
    full = to_json(frame)["free_link"]["poncelet"]["folds"][0]
    for p, v in truth.items():
        lo, hi = full["intervals"][p]
        assert lo <= v <= hi, (p, v, lo, hi, full["values"][p])
        assert 0 < lo and hi / lo < 20, (p, lo, hi)


def test_synthetic_is_what_granrs_simulates() -> None:
    """With almost no noise the synthetic means are the law's runs at the given values."""
    data = synthetic(
        STATIC_ONLY, {"static_v.eta_v": 150.0, "static_v.lam": 0.4}, TABLE_3_1, rel_sd=1e-9, seed=0
    )
    r = data.rows.iloc[4]
    law = [
        forces.gravity(),
        forces.static_h(6.5),
        forces.static_v(150.0, 0.4),
        forces.joint_springs(),
    ]
    res = granrs.simulate(cases.free_link(r["q_deg"], r["v0_mean"], forces=law))
    assert r["depth_mean"] == pytest.approx(res.depth, rel=1e-6)
    assert r["t_s_mean"] == pytest.approx(res.t_s, rel=1e-6)


# ------------------------------------------------------------------------------------------
# Command line


def test_cli_compare_json(capsys, tmp_path) -> None:
    out = tmp_path / "laws.json"
    code = main(
        [
            "compare",
            "--laws",
            "thesis_published",
            "--measurements",
            "thesis:table_4_chain",
            "--json",
            "--quiet",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert data == json.loads(out.read_text())
    entry = data["chain"]["thesis_published"]
    assert entry["n_rows"] == 6
    assert entry["stop_order"]["cases"] == 3
    res = granrs.simulate(cases.chain(case=2, end="all_stops"))
    row = next(r for r in entry["rows"] if r["v0_case"] == 2 and r["link"] == 2)
    assert row["depth_pred"] == pytest.approx(res.contacts[1].depth, rel=1e-12)


def test_cli_compare_table_and_errors(capsys) -> None:
    assert (
        main(
            [
                "compare",
                "--laws",
                "thesis_published",
                "--measurements",
                "thesis:table_5_1_means",
                "--quiet",
            ]
        )
        == 0
    )
    text = capsys.readouterr().out
    assert "leg" in text and "thesis_published" in text
    assert main(["compare", "--laws", "nope", "--quiet"]) == 2
    assert "unknown law" in capsys.readouterr().err


@pytest.mark.parametrize(
    "option, field",
    [(["--dt", "nan"], "dt"), (["--dt", "0"], "dt"), (["--laws", ""], "laws")],
)
def test_cli_compare_bad_option_exits_2_with_one_line(option, field, capsys) -> None:
    """Issue 34: ``granrs compare ... --dt nan`` exited 0 (every run failed, the law got
    chi2 = 0); ``--laws ''`` raised a KeyError. Both now exit 2 with one line."""
    args = ["compare", "--laws", "thesis_published", "--measurements", "thesis:table_3_1"]
    assert main([*args, *option, "--quiet"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("granrs: error:")
    assert field in lines[0].removeprefix("granrs: error:")


def test_cli_compare_reports_failed_runs(capsys) -> None:
    """The table has a ``failed`` column and a note names the failed rows (issue 34)."""
    dt = 0.05
    failed = _failing_rows(TABLE_3_1, dt)
    args = ["compare", "--laws", "thesis_published", "--measurements", "thesis:table_3_1"]
    assert main([*args, "--dt", str(dt), "--quiet"]) == 0
    text = capsys.readouterr().out
    header, _, row = text.splitlines()[:3]
    assert header.split()[-2:] == ["failed", "n_rows"]
    assert row.split()[-2:] == [str(failed), "12"]
    assert f"runs failed on {failed} of 12 rows in sample and {failed} out of sample" in text


def test_leg_published_is_locked_thesis() -> None:
    frame = compare(["thesis_published"], "table_5_1_means", progress=False)
    entry = to_json(frame)["leg"]["thesis_published"]
    for r in entry["rows"]:
        res = granrs.simulate(cases.leg(r["v0_mean"]))
        assert r["depth_pred"] == pytest.approx(res.depth, rel=1e-12)
    assert np.isfinite(entry["aic"])


# ------------------------------------------------------------------------------------------
# The report chapter


#: The laws of the fast chapter run (the full run, every law, is marked slow).
FAST_LAWS = ("thesis_published", "thesis_refit")


#: The pieces of the fast chapter's sums: rft alone and on the axial drag (the sums rft
#: and axial_drag+rft).
def _fast_pieces():
    return (LAWS["rft"],)


def _build_chapter(tmp_path_factory, laws):
    import sys

    from granrs.report import laws as chapter_module
    from granrs.report import laws_sums, reproduce

    subset = {k: v for k, v in LAWS.items() if k in laws}
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(sys.modules["granrs.compare"], "LAWS", subset)
        mp.setattr(chapter_module, "LAWS", subset)
        if laws == FAST_LAWS:
            mp.setattr(laws_sums, "SUM_PIECES", _fast_pieces())
            mp.setattr(laws_sums, "SUM_MAX_TERMS", 1)
            mp.setattr(laws_sums, "SUM_ON_LAWS", ())
        out = tmp_path_factory.mktemp("laws") / "out"
        path = reproduce(out, chapters=["laws"], progress=False)
    return out, path.read_text(encoding="utf-8"), subset


@pytest.fixture(
    scope="module",
    params=[
        pytest.param(FAST_LAWS, id="two-laws"),
        pytest.param(tuple(LAWS), id="every-law", marks=pytest.mark.slow),
    ],
)
def chapter(request, tmp_path_factory):
    return _build_chapter(tmp_path_factory, request.param)


def test_chapter_writes_laws_json(chapter) -> None:
    out, text, laws_run = chapter
    data = json.loads((out / "laws.json").read_text())
    assert set(data) == {"free_link", "chain", "leg"}
    sizes = {"free_link": 12, "chain": 6, "leg": 2}
    for dataset, laws in data.items():
        assert set(laws) == set(laws_run)
        for name, entry in laws.items():
            assert ENTRY_KEYS <= set(entry), (dataset, name)
            if entry["available"]:
                assert entry["n_rows"] == sizes[dataset]
                assert len(entry["rows"]) == sizes[dataset]
                assert all(ROW_KEYS <= set(r) for r in entry["rows"])
    # The published law's free-link rows are the thesis's runs.
    for r in data["free_link"]["thesis_published"]["rows"]:
        res = granrs.simulate(cases.free_link(r["q_deg"], r["v0_mean"]))
        assert r["depth_pred"] == pytest.approx(res.depth, rel=1e-12)
    for name in ("laws_predicted.png", "laws_residuals.png", "laws_depth_time.png"):
        assert (out / "figures" / name).read_bytes().startswith(b"\x89PNG")
        assert f"figures/{name}" in text


def test_chapter_verdict_names_the_winner_of_laws_json(chapter) -> None:
    out, text, _ = chapter
    data = json.loads((out / "laws.json").read_text())
    for dataset, laws in data.items():
        ran = {k: v for k, v in laws.items() if v["available"]}
        best = min(ran, key=lambda k: ran[k]["oos_chi2"])
        # Where the folds cannot test a law (no dof left) the winner only "ranks first".
        assert f"**{best}** predicts best out of sample" in text or (
            f"**{best}** ranks first by the held-out χ²" in text
        ), dataset
    assert "### Targets" in text


def _md_rows(text: str, heading: str, header_start: str) -> tuple[list[str], list[list[str]]]:
    """The header and body cells of the first Markdown table after ``heading`` whose
    header starts with ``header_start``."""
    part = text[text.index(heading) :]
    lines = part.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(header_start))
    header = [c.strip() for c in lines[start].strip("|").split("|")]
    body = []
    for line in lines[start + 2 :]:
        if not line.startswith("|"):
            break
        body.append([c.strip() for c in line.strip("|").split("|")])
    return header, body


def test_chapter_ranks_sums_with_residuals_per_table_3_1_row(chapter) -> None:
    """The sums of terms: every Table 3.1 row (from the shipped CSV) has a line with its
    measured depth and t_s, and the out-of-sample z of the published law there are those of
    independent runs of the thesis's cases; the sums are ranked with the laws."""
    out, text, _ = chapter
    assert "### Sums of terms (Table 3.1)" in text
    data = json.loads((out / "laws_sums.json").read_text())
    assert "axial_drag+rft" in data["free_link"]
    header, ranking = _md_rows(text, "### Sums of terms", "| law | rank")
    names = [r[0] for r in ranking]
    assert "axial_drag+rft" in names and "thesis_published" in names
    assert [int(r[1]) for r in ranking] == sorted(int(r[1]) for r in ranking)
    header, body = _md_rows(text, "### Sums of terms", "| q [deg]")
    assert len(body) == 12
    rows = pd.read_csv(granrs.data.path("table_3_1_free_link_experiments"))
    assert "thesis_published: depth z" in header
    col = header.index("thesis_published: depth z")
    for cells, r in zip(body, rows.itertuples(), strict=True):
        assert float(cells[0]) == r.q_deg and float(cells[1]) == r.v0_mean
        assert cells[2] == f"{r.depth_mean * 1e3:.0f} ± {r.depth_sd * 1e3:.0f}"
        assert cells[3] == f"{r.t_s_mean * 1e3:.0f} ± {r.t_s_sd * 1e3:.0f}"
        res = granrs.simulate(cases.free_link(r.q_deg, r.v0_mean))
        assert float(cells[col]) == pytest.approx(
            (res.depth - r.depth_mean) / r.depth_sd, abs=0.051
        )
        assert float(cells[col + 1]) == pytest.approx((res.t_s - r.t_s_mean) / r.t_s_sd, abs=0.051)
    assert "**Target on Table 3.1**" in text
    assert "#### The best fitted law on the chain and the leg" in text


def test_chapter_writes_the_media_card_of_a_fit_and_a_drop_runs_in_it(chapter) -> None:
    """The chapter writes the cards of its best fits (granrs.calibrate's card): each is a
    file granrs.media loads, shown in the chapter, whose values are those of its law's fit
    to every row (laws.json, laws_sums.json); a drop in a card's medium takes its values."""
    import re

    out, text, _ = chapter
    entries = {}
    for name in ("laws.json", "laws_sums.json"):
        entries.update(json.loads((out / name).read_text())["free_link"])
    written = re.findall(r"`(table_3_1_[^`]+\.toml)` \(([^,]+), rank", text)
    assert written
    with_values = 0
    for name, law in written:
        card = granrs.media.load(out / name)
        assert f'name = "{card.name}"' in text
        fitted = entries[law]["folds"][0]["values"]
        for key, v in card.params.items():
            assert v.value == pytest.approx(fitted.get(key, math.nan), rel=1e-12) or (
                f"scale.{key}" in fitted
            ), (law, key)
        with_values += bool(card.params)
        if "rft.zeta" in card.params and all(p in fitted for p in card.params):
            r = TABLE_3_1.rows.iloc[0]
            base = cases.free_link(r["q_deg"], r["v0_mean"])
            terms = [forces.term(t) for t in {k.split(".")[0] for k in card.params}]
            scene = base.replace(medium=str(out / name), forces=[forces.gravity(), *terms])
            given = [
                forces.term(
                    t.name,
                    **{
                        p.split(".")[1]: fitted[p]
                        for p in card.params
                        if p.startswith(t.name + ".")
                    },
                )
                for t in terms
            ]
            expected = granrs.simulate(base.replace(forces=[forces.gravity(), *given]))
            assert granrs.simulate(scene).depth == expected.depth
    assert with_values >= 1


def test_chapter_gives_the_leg_and_chain_evidence(chapter) -> None:
    """The targets carry a line on the leg with the laws fitted on Table 3.1 and one on why
    the chain misses; the leg's table runs thesis_refit; the chain's table lists every law
    of laws.json's chain with its out-of-sample counts there, and a z line per link row of
    Tables 4.1-4.2."""
    out, text, _ = chapter
    targets = text[text.index("### Targets") : text.index("### Free link, Table 3.1")]
    assert "- **Leg, laws fitted on Table 3.1**" in targets
    assert "- **Chain, why**" in targets
    _, body = _md_rows(text, "#### The leg with the laws fitted on Table 3.1", "| law (Table")
    assert any(r[0].startswith("thesis_refit (rank") for r in body)
    assert all(r[-1] in ("yes", "no") for r in body)
    chain = json.loads((out / "laws.json").read_text())["chain"]
    _, counts = _md_rows(text, "#### Why the chain misses", "| law |")
    assert {r[0] for r in counts} >= {k for k, v in chain.items() if v["available"]}
    for r in counts:
        if r[0] in chain:
            entry = chain[r[0]]
            assert r[1].startswith(f"{entry['stop_order']['in_order']}/3")
            assert r[2] == f"{entry['depth_within_1sd']}/6"
    _, z = _md_rows(text, "#### Why the chain misses", "| case |")
    rows = pd.read_csv(granrs.data.path("table_4_chain_experiments"))
    assert sorted((int(c[0]), int(c[1])) for c in z) == sorted(
        zip(rows["v0_case"], rows["link"], strict=True)
    )


def test_chain_mass_and_force_scale_are_one_direction() -> None:
    """Why the comparison does not fit the link mass beside a law: halving the mass and
    every eta together leaves the motion unchanged (a = g + F/m)."""
    base = cases.chain(case=2, end="all_stops")
    half = base.replace(
        mass=base.mass / 2.0,
        forces=tuple(
            t.replace(
                **{
                    k: tuple(x / 2 for x in v) if isinstance(v, tuple) else v / 2
                    for k, v in t.params.items()
                    if k.startswith("eta")
                }
            )
            for t in base.forces
        ),
    )
    a, b = granrs.simulate(base), granrs.simulate(half)
    for ca, cb in zip(a.contacts, b.contacts, strict=True):
        assert cb.depth == pytest.approx(ca.depth, rel=1e-9)
        assert cb.t_s == pytest.approx(ca.t_s, rel=1e-9)


def test_synthetic_chain_recovers_the_link_mass() -> None:
    """With the law held fixed (the thesis's published coefficients), the link mass is a
    body unknown the comparison recovers from measurements made at another mass."""
    law = Law(
        "thesis_mass",
        "the thesis's published law, the link mass fitted",
        thesis=True,
        fit={"mass": (0.0341, 0.0341 / 10, 0.0341)},
    )
    data = synthetic(law, {"mass": 0.02}, "table_4_chain", rel_sd=0.02, seed=3)
    frame = compare(["thesis_published", law], data, progress=False)
    assert frame.set_index("law")["rank"].idxmin() == "thesis_mass"
    for fold in to_json(frame)["chain"]["thesis_mass"]["folds"]:
        lo, hi = fold["intervals"]["mass"]
        assert lo <= 0.02 <= hi, fold
        assert hi / lo < 1.5, fold  # determined, not merely bounded


# --------------------------------------------------------------------------------------------
# Bodies in space


def _ball(v0: float, radius: float) -> granrs.space.Scene:
    body = granrs.space.Body(granrs.space.Sphere(radius=radius), density=7800.0)
    terms = [granrs.forces.rft3d(zeta=2e5), granrs.forces.gravity()]
    return granrs.space.Scene(body=body, velocity=(0.0, 0.0, -v0), forces=terms)


def test_compare_ranks_laws_on_bodies_in_space_out_of_sample():
    # Balls of two radii dropped under rft3d (zeta 2e5, chosen here), sd 0.2 % of each value;
    # each radius is predicted by the law fitted to the other. rft3d made the data and must
    # predict them; poncelet cannot follow the depth's growth with the speed under a
    # rate-independent law; the planar laws do not act in space.
    rows = []
    for radius in (0.015, 0.025):
        for v0 in (1.0, 3.0):
            r = granrs.simulate(_ball(v0, radius))
            rows.append(
                dict(
                    radius=radius,
                    v0=v0,
                    depth_mean=r.depth,
                    depth_sd=2e-3 * r.depth,
                    t_s_mean=r.t_s,
                    t_s_sd=2e-3 * r.t_s,
                )
            )
    m = granrs.Measurements(body="space", rows=pd.DataFrame(rows), source="balls")
    laws = [
        Law("rft3d", "3D-RFT", terms=(("rft3d", {}),), fit={"rft3d.zeta": (1e6, 1e4, 1e8)}),
        Law(
            "poncelet",
            "Poncelet",
            terms=(("poncelet", {}),),
            fit={"poncelet.c": (1.0, 1e-3, 1e3), "poncelet.k": (300.0, 1.0, 1e7)},
        ),
        "rft",
    ]
    frame = compare(
        laws,
        {"balls": m},
        cases=lambda row: _ball(row["v0"], row["radius"]),
        folds="radius",
        progress=False,
    ).set_index("law")
    assert frame.loc["rft3d", "rank"] == 1
    assert frame.loc["rft3d", "depth_within_1sd"] == 4
    assert frame.loc["rft3d", "ts_within_2sd"] == 4
    fitted = frame.loc["rft3d", "folds"]
    assert len(fitted) == 3  # every row, then each radius left out
    assert all(f["values"]["rft3d.zeta"] == pytest.approx(2e5, rel=1e-6) for f in fitted)
    assert frame.loc["poncelet", "oos_chi2"] > 1e3 * max(frame.loc["rft3d", "oos_chi2"], 1e-9)
    assert not frame.loc["rft", "available"]
    assert "does not act on a body in space" in frame.loc["rft", "reason"]
    with pytest.raises(granrs.InvalidParameterError, match="bodies in space") as e:
        compare(laws[:1], {"balls": m}, folds="radius", progress=False)
    assert e.value.field == "cases"


# --------------------------------------------------------------------------------------------
# Sums of laws


def test_laws_add_their_terms_and_fits_and_refuse_a_term_listed_twice():
    a = Law("a", "A", terms=(("poncelet", {"k": 0.0}),), fit={"poncelet.c": (1.0, 1e-3, 1e3)})
    b = Law("b", "B", terms=(("rft", {}),), fit={"rft.zeta": (1e6, 1e3, 1e9)}, body_unknowns=False)
    s = LAWS["thesis_refit"] + a + b
    assert s.name == "thesis_refit+a+b"
    assert s.thesis
    assert s.terms == (("poncelet", {"k": 0.0}), ("rft", {}))
    assert set(s.params_for("free_link")) == {
        *LAWS["thesis_refit"].fit,
        "poncelet.c",
        "rft.zeta",
    }
    assert not s.body_unknowns
    # The leg's own setting of the thesis refit survives the sum.
    assert s.params_for("leg") == (LAWS["thesis_refit"] + a).params_for("leg") | {
        "rft.zeta": (1e6, 1e3, 1e9)
    }
    with pytest.raises(granrs.InvalidParameterError, match="both list the term 'poncelet'") as e:
        _ = a + LAWS["poncelet"]
    assert e.value.field == "laws"


def test_a_name_spells_a_sum_of_named_laws_and_pieces():
    """``"thesis_refit+axial_drag"`` is LAWS["thesis_refit"] + PIECES["axial_drag"]; a named
    law whose own name has a ``+`` keeps it; a piece alone, or an unknown part, is no law."""
    from granrs.compare import PIECES, _law_list

    (law,) = _law_list("thesis_refit+axial_drag")
    assert law == LAWS["thesis_refit"] + PIECES["axial_drag"]
    assert law.needs()[-1] == "axial_drag" and "axial_drag.eta_a" in law.fit
    (law,) = _law_list("rft+rft_inertial+axial_drag")
    assert law == LAWS["rft+rft_inertial"] + PIECES["axial_drag"]
    for bad in ("axial_drag", "thesis_refit+axial_dreg", "axial_drag+axial_drag"):
        with pytest.raises(UnknownNameError, match="pieces to add") as e:
            _law_list(bad)
        assert e.value.field == "laws"
    with pytest.raises(InvalidParameterError, match="both list the term 'poncelet'"):
        _law_list("poncelet+thesis+poncelet")


def test_the_chapters_sums_add_the_axial_drag_to_the_thesis_refit():
    """The laws chapter's search: the thesis's law refit plus the axial drag, and no sum
    listing a term twice or with no term growing with depth (or two)."""
    from granrs.report.laws_sums import sum_laws

    names = [law.name for law in sum_laws()]
    assert "thesis_refit+axial_drag" in names
    assert "axial_drag+thesis_static" in names and "axial_drag+rft" in names
    assert "axial_drag+rft_inertial" not in names  # no depth term: never stops
    assert "axial_drag+thesis_static+rft" not in names  # two laws of the static resistance
    for law in sum_laws():
        assert len(set(law.needs())) == len(law.needs()), law.name


def test_sums_compares_every_small_sum_in_one_call():
    # Pieces with nothing to fit (each evaluated once), on three rows of Table 3.1: every sum
    # of at most two, and a sum whose pieces list the same term left out.
    m = Measurements.thesis("table_3_1")
    m = Measurements(m.body, m.rows.iloc[:3].reset_index(drop=True), m.source, m.resolution)
    a = Law("a", "A", terms=(("poncelet", {"c": 0.5, "k": 20.0}),), body_unknowns=False)
    b = Law("b", "B", terms=(("static_v", {}),), body_unknowns=False)
    c = Law("c", "C", terms=(("poncelet", {"c": 1.0, "k": 0.0}),), body_unknowns=False)
    frame = sums([a, b, c], m, max_terms=2, folds=None, progress=False)
    assert list(frame["law"]) == ["a", "b", "c", "a+b", "b+c"]
    alone = compare([a + b], m, folds=None, progress=False)
    assert frame.set_index("law").loc["a+b", "oos_chi2"] == alone.loc[0, "oos_chi2"]
    pairs = zip(frame["law"], frame["rows"], strict=True)
    depth = {law: [r["depth_pred"] for r in rows] for law, rows in pairs}
    assert depth["a+b"] != depth["a"] and depth["a+b"] != depth["b"]
    with pytest.raises(granrs.InvalidParameterError) as e:
        sums([a, b], m, max_terms=0)
    assert e.value.field == "max_terms"
