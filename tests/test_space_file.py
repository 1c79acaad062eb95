"""Bodies in space as scene files (``space = true``) and through ``granrs run``."""

from __future__ import annotations

import json
import math
import sys
import warnings

import numpy as np
import pytest
from PIL import Image

import granrs
import granrs._space_animation
from granrs import forces, scenefile, space
from granrs.cli import main
from granrs.errors import AnimationSizeWarning

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


# --- granrs animate of a body in space ------------------------------------------------------


def _ball(tmp_path):
    """The sphere's scene file, and its series as ``granrs animate`` records them."""
    path = tmp_path / "ball.toml"
    scenefile.dump(scenes()["sphere"], path)
    return path, granrs.simulate(scenes()["sphere"].replace(record=True)).series


def _gif(path):
    """A GIF's frame count, size [px] and first frame's duration [ms]."""
    with Image.open(path) as image:
        assert image.format == "GIF"
        return int(image.n_frames), image.size, image.info["duration"]


def test_granrs_animate_writes_a_body_in_space_as_a_gif(tmp_path, capsys):
    """`granrs animate FILE` on a space scene file (it failed with a TypeError traceback on
    the scene's record = false): one frame per --frame-dt of the run, --fps the frame's
    duration, --dpi its size (a 5.5 x 5 inch figure)."""
    path, series = _ball(tmp_path)
    out = tmp_path / "drop.gif"
    argv = ["animate", str(path), "--out", str(out), "--frame-dt", "0.002", "--fps", "10"]
    code = main([*argv, "--dpi", "40"])
    err = capsys.readouterr().err
    assert code == 0, err
    n = math.floor(series["t"][-1] / 0.002) + 1
    assert f"animation written to {out} ({n} frames, 2 ms per frame, 10 fps" in err
    assert _gif(out) == (n, (220, 200), 100)


def test_granrs_animate_of_a_body_in_space_takes_every_option(tmp_path, capsys, monkeypatch):
    """Every option of `granrs animate` applies in 3D, none is ignored: --speed and --fps
    give the frames, .html writes a player, --quiet turns the progress bar off, and a
    write that would be big warns first."""
    path, series = _ball(tmp_path)
    html = tmp_path / "drop.html"
    argv = ["animate", str(path), "--speed", "0.01", "--fps", "5", "--dpi", "30"]
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    assert main([*argv, "--out", str(html)]) == 0
    err = capsys.readouterr().err
    n = math.floor(series["t"][-1] / 0.002) + 1
    assert "<script" in html.read_text() and f"({n} frames, 2 ms per frame, 5 fps" in err
    assert "granrs animate: 100%|" in err and f"{n}/{n}" in err  # the progress bar
    assert main([*argv, "--out", str(html), "--quiet"]) == 0
    assert "granrs animate:" not in capsys.readouterr().err
    monkeypatch.setattr(granrs._space_animation, "BIG_SAVE_BYTES", 1)
    with warnings.catch_warnings():
        warnings.simplefilter("default", AnimationSizeWarning)
        assert main([*argv, "--out", str(tmp_path / "big.gif"), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert f"granrs: warning: writing {tmp_path / 'big.gif'}: {n} frames of 165 x 150 px" in err


def test_granrs_animate_of_a_body_in_space_writes_whole_or_not_at_all(
    tmp_path, capsys, monkeypatch
):
    """A bad --out is refused before the run (exit 2, one line naming it); a write that fails
    part way leaves the old file as it was (exit 1)."""
    path, _ = _ball(tmp_path)

    def no_run(*_: object) -> None:
        raise AssertionError("the scene ran")

    with monkeypatch.context() as patch:
        patch.setattr(granrs.api, "simulate", no_run)
        assert main(["animate", str(path), "--out", str(tmp_path / "drop.avi")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "unknown suffix" in err[0] and "drop.avi" in err[0]
    out = tmp_path / "drop.gif"
    out.write_bytes(b"the old file")

    draw = granrs._space_animation.SpaceAnimation._draw

    def full_disk(self, k):  # the third frame fails, as a full disk would
        if k == 2:
            raise OSError(28, "No space left on device")
        return draw(self, k)

    monkeypatch.setattr(granrs._space_animation.SpaceAnimation, "_draw", full_disk)
    code = main(["animate", str(path), "--out", str(out), "--frame-dt", "0.002", "--quiet"])
    assert code == 1 and "No space left on device" in capsys.readouterr().err
    assert out.read_bytes() == b"the old file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ball.toml", "drop.gif"]


def test_granrs_animate_of_a_body_in_space_takes_set(tmp_path, capsys):
    """--set changes the run that is animated: a faster drop into firmer sand stops sooner
    (the frames are those of that scene run directly)."""
    path, series = _ball(tmp_path)
    out = tmp_path / "drop.gif"
    sets = ["--set", "velocity=[0.0, 0.0, -2.0]", "--set", "rft3d.zeta=4e6"]
    code = main(["animate", str(path), "--out", str(out), "--frame-dt", "0.001", *sets])
    assert code == 0, capsys.readouterr().err
    changed = scenes()["sphere"].replace(
        velocity=(0.0, 0.0, -2.0), forces=[forces.rft3d(zeta=4e6), forces.gravity()], record=True
    )
    t_end = granrs.simulate(changed).series["t"][-1]
    assert t_end != pytest.approx(series["t"][-1], rel=0.05)
    assert _gif(out)[0] == math.floor(t_end / 0.001) + 1


@pytest.mark.parametrize(
    ("override", "named", "corrected"),
    [
        ("velocty=[0.0, 0.0, -2.0]", "did you mean 'velocity'", "velocity=[0.0, 0.0, -2.0]"),
        ("rft3d.zetta=2e6", "did you mean `rft3d.zeta`", "rft3d.zeta=2e6"),
        ("body.shape.radious=0.01", "no key 'radious'", "body.shape.radius=0.01"),
        ("velocity=[0.0, -1.0]", "`velocity`: a sequence of 3", "velocity=[0.0, 0.0, -1.0]"),
        ("q_deg=30", "'q_deg': not a field of a body in space", "orientation=[0.0, 1.0, 0.0, 0.0]"),
    ],
)
def test_granrs_animate_of_a_body_in_space_names_a_bad_set(
    tmp_path, capsys, override, named, corrected
):
    """A --set the body in space does not have (or a bad value; a planar scene's field) is
    exit 2 with one line naming the key, before anything runs or is written; corrected, the
    same command writes the movie."""
    path, _ = _ball(tmp_path)
    out = tmp_path / "drop.gif"
    argv = ["animate", str(path), "--out", str(out), "--frame-dt", "0.005", "--dpi", "30"]
    code = main([*argv, "--set", override])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and err[0].startswith("granrs: error: ") and named in err[0], err
    assert f"--set {override.split('=')[0]}=" in err[0]
    assert not out.exists()
    code = main([*argv, "--set", corrected])
    assert code == 0, capsys.readouterr().err
    assert out.read_bytes()[:6] == b"GIF89a"
