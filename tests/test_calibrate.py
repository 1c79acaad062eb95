"""Tests of granrs.calibrate (issue 7): recovery of known coefficients from synthetic
measurements, the Jacobian's finite differences, the measurements loader, input errors and
the command line.

Synthetic measurements are made here with granrs.sweep at coefficients chosen here, plus
seeded Gaussian noise of a stated sd; the expected values are those chosen coefficients,
never numbers the code under test computes.
"""

from __future__ import annotations

import io
import json
import math

import numpy as np
import pandas as pd
import pytest

import granrs
from granrs import Coefficients, cases
from granrs.calibrate import Measurements, calibrate, evaluate, within
from granrs.cli import main
from granrs.errors import InvalidParameterError, MeasurementError, UnknownNameError
from granrs.forces import thesis

#: The truth of the synthetic tests, and the noise added to every measured value.
TRUE = Coefficients(eta_h=8.0, eta_d=12.0, eta_v=200.0, lam=0.3)
NOISE_SD = 0.0005  # 0.5 mm and 0.5 ms
ANGLES = (0.0, 30.0)
SPEEDS = (1.2, 1.8, 2.4)


def _synthetic(seed: int) -> Measurements:
    """Free-link drops at ANGLES x SPEEDS simulated at TRUE, plus N(0, NOISE_SD) noise."""
    grid = [(q, v) for q in ANGLES for v in SPEEDS]
    scenes = [cases.free_link(q, v, coefficients=TRUE) for q, v in grid]
    out = granrs.sweep(scenes, progress=False)
    rng = np.random.default_rng(seed)
    n = len(grid)
    rows = pd.DataFrame(
        {
            "q_deg": [q for q, _ in grid],
            "v0_mean": [v for _, v in grid],
            "t_s_mean": out["t_s"].to_numpy() + rng.normal(0.0, NOISE_SD, n),
            "t_s_sd": np.full(n, NOISE_SD),
            "depth_mean": out["depth"].to_numpy() + rng.normal(0.0, NOISE_SD, n),
            "depth_sd": np.full(n, NOISE_SD),
        }
    )
    return Measurements("free_link", rows, "synthetic")


@pytest.mark.parametrize("seed", [1, 2])
def test_recovers_known_coefficients_within_intervals(seed: int) -> None:
    """Issue 7: a fit of eta_v and lambda to noisy synthetic measurements made at known
    values brings them back inside the reported ~95 % intervals, much closer than the start."""
    m = _synthetic(seed)
    start = {"eta_v": 80.0, "lam": 0.8}
    r = calibrate(
        "free_link",
        m,
        ["eta_v", "lam"],
        base=TRUE,
        start=start,
        error_scale="none",
    )
    assert r.success
    truth = {"eta_v": TRUE.eta_v, "lam": TRUE.lam}
    for name, value in truth.items():
        lo, hi = r.intervals[name]
        assert lo <= value <= hi, f"{name}: true {value} outside [{lo}, {hi}]"
        assert hi - lo < 0.5 * abs(start[name] - value), f"{name}: interval too wide"
        assert abs(r.values[name] - value) < 0.1 * abs(start[name] - value)
    # chi2 of a right model with the right noise: about dof (12 - 2), not hundreds.
    assert r.chi2 < 4.0 * r.dof
    assert r.simulations > 0 and r.seconds > 0
    assert np.all(np.abs(r.residuals["depth_z"]) < 4.0)


def test_recovers_four_coefficients_from_scale_factors() -> None:
    """Scale factors on a base: the fitted factors times the base give the truth back
    (eta_d, eta_v, lambda scaled; eta_h left at its true value)."""
    m = _synthetic(3)
    base = Coefficients(eta_h=TRUE.eta_h, eta_d=6.0, eta_v=400.0, lam=0.6)
    r = calibrate(
        "free_link",
        m,
        ["scale.eta_d", "scale.eta_v", "scale.lam"],
        base=base,
        error_scale="none",
    )
    expected = {
        "scale.eta_d": TRUE.eta_d / base.eta_d,
        "scale.eta_v": TRUE.eta_v / base.eta_v,
        "scale.lam": TRUE.lam / base.lam,
    }
    for name, value in expected.items():
        lo, hi = r.intervals[name]
        assert lo <= value <= hi, f"{name}: true {value} outside [{lo}, {hi}]"


def test_finite_differences_are_above_the_noise() -> None:
    """The residuals are smooth enough for the default forward step (relative 1e-3): the
    change of t_s and depth over one step is far above their round-off noise, seen as the
    scatter of second differences over steps of 1e-6."""
    base = cases.free_link(30.0, 1.8, coefficients=TRUE)
    factors = 1.0 + 1e-6 * np.arange(8)
    scenes = [base.replace(forces=thesis(Coefficients(8.0, 12.0, 200.0 * f, 0.3))) for f in factors]
    scenes.append(base.replace(forces=thesis(Coefficients(8.0, 12.0, 200.0 * 1.001, 0.3))))
    out = granrs.sweep(scenes, progress=False)
    for q in ("t_s", "depth"):
        values = out[q].to_numpy()
        noise = np.max(np.abs(np.diff(values[:8], 2)))
        step = abs(values[8] - values[0])
        assert step > 100.0 * max(noise, 1e-15), f"{q}: step {step} vs noise {noise}"


def test_thesis_measurements_load() -> None:
    """The shipped thesis tables load with their rows and the 1 mm / 1 ms rounding."""
    m = Measurements.thesis("table_3_1")
    assert m.body == "free_link" and len(m) == 12
    assert sorted(set(m.rows["q_deg"])) == [0, 45, 60, 75]
    assert m.resolution == {"depth": 0.001, "t_s": 0.001}
    # sd_fit: the published sd with the rounding (1 mm / sqrt(12)) in quadrature.
    expected = math.sqrt(0.001**2 + 0.001**2 / 12.0)
    assert m.sd_fit("depth")[0] == pytest.approx(expected)
    assert len(Measurements.thesis("table_4_chain")) == 6
    means = Measurements.thesis("table_5_1_means")
    assert list(means.rows["height_case"]) == ["h1", "h2"]
    h1 = [0.07, 0.09, 0.05, 0.04, 0.07]  # Table 5.1 depths, h1
    assert means.rows["depth_mean"][0] == pytest.approx(np.mean(h1))
    assert means.rows["depth_sd"][0] == pytest.approx(np.std(h1, ddof=1))
    assert len(Measurements.load("thesis:table_3_1").subset(q_deg=[0, 45])) == 6


def test_csv_loader_reads_a_user_file(tmp_path) -> None:
    """A user CSV with the Table 3.1 columns (and extra ones) loads as measurements."""
    path = tmp_path / "drops.csv"
    path.write_text(
        "q_deg,v0_mean,t_s_mean,t_s_sd,depth_mean,depth_sd,operator\n"
        "0,2.0,0.035,0.002,0.048,0.002,ab\n"
        "30,1.5,0.030,0.002,0.035,0.003,cd\n",
        encoding="utf-8",
    )
    m = Measurements.from_csv(path)
    assert len(m) == 2
    assert list(m.rows["depth_sd"]) == [0.002, 0.003]
    assert m.resolution == {"depth": 0.0, "t_s": 0.0}


@pytest.mark.parametrize(
    ("text", "column", "where"),
    [
        ("q_deg,v0_mean,t_s_mean,t_s_sd,depth_mean\n0,2,0.03,0.001,0.04\n", "depth_sd", "row 1"),
        (
            "q_deg,v0_mean,t_s_mean,t_s_sd,depth_mean,depth_sd\n0,2,0.03,0.001,0.04,0.001\n"
            "0,2,abc,0.001,0.04,0.001\n",
            "t_s_mean",
            "row 3",
        ),
        (
            "q_deg,v0_mean,t_s_mean,t_s_sd,depth_mean,depth_sd\n0,2,0.03,-0.001,0.04,0.001\n",
            "t_s_sd",
            "row 2",
        ),
        (
            "q_deg,v0_mean,t_s_mean,t_s_sd,depth_mean,depth_sd\n95,2,0.03,0.001,0.04,0.001\n",
            "q_deg",
            "row 2",
        ),
    ],
)
def test_csv_errors_name_column_and_row(text: str, column: str, where: str) -> None:
    """A CSV that lacks a column or holds a bad cell raises MeasurementError naming the
    column (``field``) and the row, before any simulation."""
    handle = io.StringIO(text)
    handle.name = "bad.csv"
    with pytest.raises(MeasurementError) as info:
        Measurements.from_csv(handle)
    assert info.value.field == column
    assert where in str(info.value) and "bad.csv" in str(info.value)


def test_chain_csv_needs_both_links() -> None:
    """A chain case with one link only is refused, naming the column."""
    handle = io.StringIO(
        "link,v0_case,q0_deg,v0_mean,t_s_mean,t_s_sd,depth_mean,depth_sd\n"
        "1,1,-15,2.5,0.024,0.003,0.035,0.002\n"
    )
    with pytest.raises(MeasurementError) as info:
        Measurements.from_csv(handle, body="chain")
    assert info.value.field == "link"


@pytest.mark.parametrize(
    ("kwargs", "error", "field"),
    [
        ({"params": ["eta_x"]}, UnknownNameError, "eta_x"),
        ({"params": []}, InvalidParameterError, "params"),
        ({"params": ["joints.k"]}, UnknownNameError, "joints.k"),
        ({"params": ["eta_v"], "bounds": {"eta_v": (10.0, 1.0)}}, InvalidParameterError, None),
        (
            {"params": ["eta_v"], "bounds": {"eta_v": (0.0, math.inf)}},
            InvalidParameterError,
            "bounds.eta_v",
        ),
        ({"params": ["eta_v"], "bounds": {"eta_vv": (1, 2)}}, UnknownNameError, "bounds.eta_vv"),
        ({"params": ["eta_v"], "start": {"eta_v": -1.0}}, InvalidParameterError, "start.eta_v"),
        ({"params": ["eta_v", "eta_v"]}, InvalidParameterError, "eta_v"),
        ({"params": ["eta_v"], "base": "table_9"}, UnknownNameError, "base"),
        ({"params": ["eta_v"], "quantities": ["speed"]}, UnknownNameError, "quantities"),
        ({"params": ["eta_v"], "rel_step": 0.5}, InvalidParameterError, "rel_step"),
    ],
)
def test_bad_arguments_are_typed_errors(kwargs, error, field) -> None:
    """Every argument is checked before any simulation; errors name the field."""
    m = Measurements.thesis("table_3_1").subset(q_deg=0)
    with pytest.raises(error) as info:
        calibrate("free_link", m, **kwargs)
    if field is not None:
        assert info.value.field == field
    else:
        assert info.value.field == "bounds.eta_v"
    if kwargs.get("params") == ["eta_x"]:
        assert "did you mean 'eta_v'" in str(info.value)


def test_bad_cases_and_empty_measurements() -> None:
    """Unknown cases, measurements of another body and no rows are refused."""
    m = Measurements.thesis("table_3_1")
    with pytest.raises(UnknownNameError) as info:
        calibrate("free_lnk", m, ["eta_v"])
    assert info.value.field == "cases" and "free_link" in str(info.value)
    with pytest.raises(InvalidParameterError) as info:
        calibrate("chain", m, ["eta_v"])
    assert info.value.field == "cases"
    with pytest.raises(InvalidParameterError) as info:
        calibrate("free_link", m.subset(q_deg=10), ["eta_v"])
    assert info.value.field == "measurements"
    with pytest.raises(UnknownNameError) as info:
        Measurements.thesis("table_3_2")
    assert info.value.field == "measurements"


def test_evaluate_matches_simulate() -> None:
    """evaluate() runs each row with the base coefficients: the same as granrs.simulate,
    and z is (simulated - mean) / sd."""
    m = Measurements.thesis("table_3_1").subset(q_deg=45)
    frame = evaluate("free_link", m)
    for i, row in m.rows.iterrows():
        r = granrs.simulate(cases.free_link(row["q_deg"], row["v0_mean"]))
        assert frame["depth_sim"][i] == pytest.approx(r.depth, rel=1e-12)
        z = (r.t_s - row["t_s_mean"]) / row["t_s_sd"]
        assert frame["t_s_z"][i] == pytest.approx(z, rel=1e-9)
    assert within(frame, "t_s", 1e9) == len(m)


def test_predict_uses_fitted_values() -> None:
    """predict() of rows not fitted runs them at the fitted coefficients."""
    m = Measurements.thesis("table_3_1")
    r = calibrate("free_link", m.subset(q_deg=0), ["eta_v", "lam"], max_nfev=3)
    pred = r.predict(m.subset(q_deg=45))
    c = r.coefficients({"q_deg": 45.0, "v0_mean": 2.27})
    assert c.eta_v == pytest.approx(r.values["eta_v"])
    sim = granrs.simulate(cases.free_link(45.0, 2.27, coefficients=c))
    assert pred["depth_sim"][0] == pytest.approx(sim.depth, rel=1e-12)


def test_cli_calibrate_json(capsys) -> None:
    """granrs calibrate --json: exit 0, the fitted values and the predicted rows."""
    code = main(
        [
            "calibrate",
            "--params",
            "eta_v,lam",
            "--fit",
            "q_deg=0",
            "--predict",
            "q_deg=45",
            "--json",
        ]
    )
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["values"]) == {"eta_v", "lam"}
    assert len(out["residuals"]) == 3 and len(out["predicted"]) == 3
    assert out["simulations"] > 0


def test_cli_calibrate_bad_input(capsys, tmp_path) -> None:
    """Bad input: exit 2 and one line naming the field."""
    assert main(["calibrate", "--params", "eta_q"]) == 2
    assert "eta_q" in capsys.readouterr().err
    bad = tmp_path / "m.csv"
    bad.write_text("q_deg,v0_mean\n0,2\n", encoding="utf-8")
    assert main(["calibrate", "--measurements", str(bad)]) == 2
    assert "t_s_mean" in capsys.readouterr().err
    assert main(["calibrate", "--fit", "q_deg"]) == 2


# --------------------------------------------------------------------------------------------
# Bodies in space: each row's scene from a function of the row


def _ball_drops(zeta: float, speeds=(1.0, 2.0, 3.0)) -> Measurements:
    """Drops of a steel ball under rft3d at ``zeta``, simulated, as measurements (sd 0.1 mm
    and 0.1 ms)."""
    rows = []
    for v0 in speeds:
        r = granrs.simulate(_ball(v0, zeta))
        assert r.status == "stopped"
        rows.append(dict(v0=v0, depth_mean=r.depth, depth_sd=1e-4, t_s_mean=r.t_s, t_s_sd=1e-4))
    return Measurements(body="space", rows=pd.DataFrame(rows), source="ball drops")


def _ball(v0: float, zeta: float = 1e6) -> granrs.space.Scene:
    from granrs import space

    body = space.Body(space.Sphere(radius=0.02), density=7800.0)
    terms = [granrs.forces.rft3d(zeta=zeta), granrs.forces.gravity()]
    return space.Scene(body=body, velocity=(0.0, 0.0, -v0), forces=terms)


def test_calibrate_recovers_rft3d_zeta_from_drops_of_a_body_in_space():
    # The truth is chosen here (2e5 N/m^3); the fit starts from the scene's 1e6.
    truth = 2e5
    fit = calibrate(
        lambda row: _ball(row["v0"]),
        _ball_drops(truth),
        params=["rft3d.zeta"],
        bounds={"rft3d.zeta": (1e4, 1e7)},
    )
    assert fit.body == "space"
    assert fit.start["rft3d.zeta"] == pytest.approx(1e6)
    assert fit.values["rft3d.zeta"] == pytest.approx(truth, rel=1e-6)
    lo, hi = fit.intervals["rft3d.zeta"]
    assert lo < truth < hi
    assert fit.failed_runs == 0


def test_calibrate_in_space_takes_forces_as_the_law_over_the_scenes_own():
    # The scene's own law has rft3d only; forces= adds poncelet, whose c is fitted.
    m = _ball_drops(2e5, speeds=(1.0, 3.0))
    law = [
        granrs.forces.rft3d(zeta=2e5),
        granrs.forces.poncelet(c=0.5, k=1.0),
        granrs.forces.gravity(),
    ]
    fit = calibrate(
        lambda row: _ball(row["v0"]),
        m,
        params=["poncelet.c"],
        forces=law,
        bounds={"poncelet.c": (1e-4, 10.0)},
        quantities=["depth"],
    )
    # The data hold no poncelet: its drag coefficient goes to the lower bound's side.
    assert fit.values["poncelet.c"] < 1e-2
    with pytest.raises(granrs.UnknownNameError, match="poncelet") as e:
        calibrate(
            lambda row: _ball(row["v0"]), m, params=["poncelet.c"], bounds={"poncelet.c": (0.1, 1)}
        )
    assert e.value.field == "poncelet.c"


def test_calibrate_in_space_refuses_bad_cases_before_any_run():
    m = _ball_drops(2e5, speeds=(1.0, 2.0))
    with pytest.raises(granrs.InvalidParameterError, match=r"granrs\.space\.Scene") as e:
        calibrate(
            lambda row: granrs.Scene(), m, params=["rft3d.zeta"], bounds={"rft3d.zeta": (1e4, 1e7)}
        )
    assert e.value.field == "cases"
    with pytest.raises(granrs.InvalidParameterError, match="measurements are of the") as e:
        calibrate(lambda row: _ball(1.0), Measurements.thesis("table_3_1"), params=["rft3d.zeta"])
    assert e.value.field == "cases"
    with pytest.raises(granrs.InvalidParameterError, match="no thesis coefficients") as e:
        calibrate(lambda row: _ball(row["v0"]), m, params=["rft3d.zeta"], base="table_3_4")
    assert e.value.field == "base"
    with pytest.raises(granrs.UnknownNameError, match="function of the measurement row") as e:
        calibrate("space", m, params=["rft3d.zeta"])
    assert e.value.field == "cases"


# --------------------------------------------------------------------------------------------
# Posterior samples


def test_posterior_samples_agree_with_the_fit_and_give_predictive_intervals():
    fit = calibrate("free_link", "table_3_1", ["scale.static_v.eta_v"], posterior=40, walkers=4)
    post = fit.posterior
    assert post is not None and post.walkers == 4 and post.burn == 20
    assert list(post.samples.columns) == ["scale.static_v.eta_v"]
    assert len(post.samples) == 4 * 20 == len(post.log_prob)
    assert 0.0 < post.acceptance < 1.0
    # One parameter, a near-linear model: the posterior sits where the least-squares fit
    # puts it, its median inside the fit's ~95 % interval and its 90 % interval about the
    # fitted value.
    value = fit.values["scale.static_v.eta_v"]
    lo95, hi95 = fit.intervals["scale.static_v.eta_v"]
    median = float(post.samples["scale.static_v.eta_v"].median())
    assert lo95 < median < hi95
    lo, hi = post.interval(0.9)["scale.static_v.eta_v"]
    assert lo < value < hi
    assert post.interval(0.5)["scale.static_v.eta_v"][1] < hi
    # Seeded: the same call draws the same chains.
    again = calibrate("free_link", "table_3_1", ["scale.static_v.eta_v"], posterior=40, walkers=4)
    pd.testing.assert_frame_equal(post.samples, again.posterior.samples)
    pred = fit.predictive(draws=20)
    assert len(pred) == 12
    for q in ("depth", "t_s"):
        assert np.all(pred[f"{q}_lo"] <= pred[f"{q}_median"])
        assert np.all(pred[f"{q}_median"] <= pred[f"{q}_hi"])
        assert np.all(pred[f"{q}_lo"] < pred[f"{q}_hi"])


def test_posterior_options_are_refused_before_any_run():
    for kwargs, name in (
        ({"posterior": 5}, "posterior"),
        ({"posterior": -1}, "posterior"),
        ({"posterior": 40, "walkers": 3}, "walkers"),
        ({"posterior": 40, "walkers": 1}, "walkers"),
    ):
        with pytest.raises(granrs.InvalidParameterError) as e:
            calibrate("free_link", "table_3_1", ["scale.static_v.eta_v"], **kwargs)
        assert e.value.field == name
    fit = calibrate("free_link", "table_3_1", ["scale.static_v.eta_v"])
    assert fit.posterior is None
    with pytest.raises(granrs.InvalidParameterError) as e:
        fit.predictive()
    assert e.value.field == "posterior"
