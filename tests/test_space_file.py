"""Bodies in space as scene files (``space = true``) and through ``granrs run``."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import granrs
from granrs import forces, scenefile, space
from granrs.cli import main

RFT = forces.rft3d(zeta=1e6)


def scenes() -> dict[str, space.Scene]:
    tilt = (math.cos(0.2), 0.0, math.sin(0.2), 0.0)
    return {
        "sphere": space.Scene(
            body=space.Body(space.Sphere(0.02), density=2500.0),
            forces=[RFT, forces.gravity()],
            velocity=(0.1, 0.0, -1.0),
        ),
        "capsule": space.Scene(
            body=space.Body(space.Capsule(0.01, 0.06), mass=0.05),
            forces=[RFT, forces.rft3d_inertial(lam=0.5), forces.gravity()],
            orientation=tilt,
            omega=(0.0, 3.0, 0.0),
            dt=5e-5,
            quadrature=4,
        ),
        "cuboid": space.Scene(
            body=space.Body(
                space.Cuboid((0.04, 0.03, 0.02)),
                mass=0.1,
                inertia=[[2e-5, 0, 0], [0, 3e-5, 0], [0, 0, 4e-5]],
            ),
            forces=[RFT, forces.poncelet(c=1.0, k=0.0), forces.gravity()],
            velocity=(0.0, 0.0, -2.0),
            t_end=0.5,
            surface=0.01,
        ),
        "mesh": space.Scene(
            body=space.Body(space.Mesh.icosphere(0.02, 1), density=2000.0),
            forces=[RFT],
            record=True,
        ),
    }


@pytest.mark.parametrize("name", list(scenes()))
def test_a_body_in_space_round_trips_through_its_scene_file(name, tmp_path):
    s = scenes()[name]
    text = scenefile.dumps(s)
    assert "space = true" in text
    back = scenefile.loads(text)
    assert isinstance(back, space.Scene)
    assert back.position == s.position and back.orientation == s.orientation
    assert back.forces == s.forces
    assert back.mass == s.mass and np.array_equal(back.inertia, s.inertia)
    a, b = granrs.simulate(s), granrs.simulate(back)
    assert a.summary == b.summary or all(
        (math.isnan(x) and math.isnan(b.summary[k])) or x == b.summary[k]
        for k, x in a.summary.items()
    )
    path = tmp_path / f"{name}.toml"
    scenefile.dump(s, path)
    assert scenefile.load(path).position == s.position


def test_overrides_set_fields_and_term_parameters():
    text = scenefile.dumps(scenes()["sphere"])
    s = scenefile.loads(text, overrides={"velocity": [0.0, 0.0, -2.0], "rft3d.zeta": 2e6})
    assert s.velocity == (0.0, 0.0, -2.0)
    assert s.forces[0].params["zeta"] == 2e6


@pytest.mark.parametrize(
    ("text", "field", "line"),
    [
        ("space = true\nvelocty = [0, 0, 1]\n", "velocty", 2),
        ("space = 1\n", "space", 1),
        (
            'space = true\n[body]\ndensity = 1.0\n[body.shape]\nkind = "cone"\n',
            "body.shape.kind",
            4,
        ),
        (
            'space = true\n[body]\ndensity = 1.0\n[body.shape]\nkind = "sphere"\nradius = -1.0\n'
            '[[forces]]\nterm = "rft3d"\nzeta = 1e6\n',
            "body.shape.radius",
            6,
        ),
        ('space = true\n[body]\ndensity = 1.0\n[body.shape]\nkind = "sphere"\n', "radius", 4),
        (
            'space = true\n[body]\ndensity = 1.0\ncolour = "red"\n[body.shape]\nkind = "sphere"\n'
            "radius = 0.02\n",
            "body.colour",
            4,
        ),
        (
            'space = true\n[body]\ndensity = 1.0\n[body.shape]\nkind = "sphere"\nradius = 0.02\n'
            '[[forces]]\nterm = "rft3d"\nzeta = -5.0\n',
            "zeta",
            7,
        ),
        (
            'space = true\n[body]\ndensity = 1.0\n[body.shape]\nkind = "sphere"\nradius = 0.02\n'
            '[[forces]]\nterm = "drag"\n',
            "forces",
            7,
        ),
    ],
)
def test_a_bad_scene_file_is_a_typed_error_naming_the_key_and_its_line(text, field, line):
    with pytest.raises(granrs.GranrsError) as e:
        scenefile.loads(text, source="bad.toml")
    assert field in str(e.value.field) + str(e.value), e.value
    assert f"bad.toml:{line}" in str(e.value), e.value


def test_granrs_run_prints_a_body_in_space_and_writes_its_series(tmp_path, capsys):
    path = tmp_path / "ball.toml"
    scenefile.dump(scenes()["sphere"], path)
    assert main(["run", str(path)]) == 0
    out = capsys.readouterr().out
    ref = granrs.simulate(scenes()["sphere"])
    assert "sphere in space, status stopped" in out
    assert f"{ref.t_s:.6g}" in out
    series = tmp_path / "ball.csv"
    assert main(["run", str(path), "--json", "--series", str(series)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["summary"]["t_s"] == ref.t_s and data["units"]["t_s"] == "s"
    rows = series.read_text().splitlines()
    assert rows[0].startswith("t [s],x [m]")
    recorded = granrs.simulate(scenes()["sphere"].replace(record=True)).series
    assert len(rows) - 1 == len(recorded["t"])
