"""A calibration written as a medium card (CalibrationResult.card): write, load, run a drop
in it; a factor on per-row base values and the body's unknowns not written as the medium's;
the posterior's samples kept; a base card of another density refused."""

from __future__ import annotations

import json
import math

import pytest

import granrs
from granrs import cases, media
from granrs import forces as f
from granrs.cli import main
from granrs.coefficients import table_3_4
from granrs.errors import MediumError

#: The vertical drops of Table 3.1 (three rows): cheap to fit.
VERTICAL = granrs.Measurements.thesis("table_3_1").subset(q_deg=0.0)


@pytest.fixture(scope="module")
def zeta_fit() -> granrs.CalibrationResult:
    return granrs.calibrate(
        "free_link",
        VERTICAL,
        ["rft.zeta"],
        forces=[f.gravity(), f.rft(zeta=1e6)],
        bounds={"rft.zeta": (1e5, 1e8)},
        posterior=20,
    )


def test_a_fit_written_as_a_card_loads_and_a_drop_in_it_is_the_fit_s_run(
    zeta_fit: granrs.CalibrationResult, tmp_path
) -> None:
    """Round trip: the card's file read back is the card, its rft.zeta is the fit's with its
    sd and interval, and a drop in the card's medium (rft.zeta taken from the card) runs as
    the fit ran that row."""
    card = zeta_fit.card("my_sand")
    path = tmp_path / "my_sand.toml"
    card.save(path)
    loaded = media.load(path)
    assert loaded == card
    v = loaded.value("rft.zeta")
    assert v.value == zeta_fit.values["rft.zeta"]
    assert v.sd == zeta_fit.std_errors["rft.zeta"]
    assert v.interval == tuple(zeta_fit.intervals["rft.zeta"])
    assert v.level == 0.95
    assert "fitted here" in v.source and "3 rows of thesis Table 3.1" in v.source
    assert loaded.rho_g == 1650.0  # the scenes' density, written since no base card gave one
    row = VERTICAL.rows.iloc[0]
    scene = cases.free_link(q_deg=0.0, v0=float(row["v0_mean"])).replace(
        medium=str(path), forces=[f.gravity(), f.rft()]
    )
    assert scene.forces[1].params["zeta"] == zeta_fit.values["rft.zeta"]
    r = granrs.simulate(scene)
    expected = zeta_fit.residuals.iloc[0]
    assert math.isclose(r.depth, expected["depth_sim"], rel_tol=1e-12)
    assert math.isclose(r.t_s, expected["t_s_sim"], rel_tol=1e-12)


def test_the_card_keeps_the_posterior_samples(zeta_fit: granrs.CalibrationResult) -> None:
    samples = zeta_fit.posterior.samples["rft.zeta"].tolist()
    v = zeta_fit.card("my_sand").value("rft.zeta")
    assert len(samples) > 0 and list(v.samples) == samples
    assert "posterior samples" in v.source


def test_a_card_from_a_base_keeps_its_other_values(zeta_fit: granrs.CalibrationResult) -> None:
    base = media.load("thesis_sand")
    card = zeta_fit.card("mine", base="thesis_sand", source="my own drops")
    assert card.value("rft.zeta").value == zeta_fit.values["rft.zeta"]
    assert card.source("rft.zeta").startswith("my own drops")
    assert card.value("poncelet.c") == base.value("poncelet.c")
    assert card.description == base.description


def test_a_factor_on_one_base_value_is_written_as_the_value_it_gives() -> None:
    fit = granrs.calibrate(
        "free_link",
        VERTICAL,
        ["scale.rft.zeta"],
        forces=[f.gravity(), f.rft(zeta=2e6)],
        bounds={"scale.rft.zeta": (0.05, 20.0)},
    )
    v = fit.card("x").value("rft.zeta")
    s = fit.values["scale.rft.zeta"]
    assert v.value == pytest.approx(2e6 * s, rel=1e-14)
    lo, hi = fit.intervals["scale.rft.zeta"]
    assert v.interval == pytest.approx((2e6 * lo, 2e6 * hi), rel=1e-14)


def test_a_factor_on_per_angle_values_and_the_body_s_mass_are_not_the_medium_s() -> None:
    """The thesis's eta_v differs between the Table 3.4 rows of 0 and 45 degrees, so a
    factor on it is no one value of the sand; the link's mass is the body's."""
    assert table_3_4(0.0)[0].eta_v != table_3_4(45.0)[0].eta_v
    m = granrs.Measurements.thesis("table_3_1").subset(q_deg=[0.0, 45.0])
    fit = granrs.calibrate("free_link", m, ["scale.static_v.eta_v", "mass"], max_nfev=3)
    card = fit.card("x")
    assert "static_v.eta_v" not in card.params
    assert "differ from row to row" in card.missing["static_v.eta_v"]
    assert not any("mass" in k for k in [*card.params, *card.missing])


def test_a_base_card_of_another_density_is_refused(zeta_fit) -> None:
    fit = granrs.calibrate(
        "free_link",
        VERTICAL,
        ["rft.zeta"],
        forces=[f.gravity(), f.rft(zeta=1e6)],
        bounds={"rft.zeta": (1e5, 1e8)},
        rho_g=1500.0,
        max_nfev=2,
    )
    with pytest.raises(MediumError, match="rho_g") as caught:
        fit.card("x", base="thesis_sand")
    assert caught.value.field == "rho_g"
    assert fit.card("x").rho_g == 1500.0


def test_cli_calibrate_writes_a_card(tmp_path, capsys) -> None:
    """``granrs calibrate --card FILE.toml``: the vertical drops share Table 3.4's row of
    q = 0, so the factor on eta_v is written as the eta_v it gives."""
    path = tmp_path / "vertical_sand.toml"
    args = ["calibrate", "--fit", "q_deg=0", "--params", "scale.eta_v", "--quiet", "--json"]
    assert main([*args, "--card", str(path)]) == 0
    scale = json.loads(capsys.readouterr().out)["values"]["scale.eta_v"]
    card = media.load(path)
    assert card.name == "vertical_sand"
    assert card.value("static_v.eta_v").value == pytest.approx(
        table_3_4(0.0)[0].eta_v * scale, rel=1e-14
    )


def test_cli_calibrate_refuses_a_card_name_before_any_run(tmp_path, capsys) -> None:
    path = tmp_path / "bad name!.toml"
    assert main(["calibrate", "--quiet", "--card", str(path)]) == 2
    assert "name" in capsys.readouterr().err
    assert not path.exists()
