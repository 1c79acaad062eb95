"""A scene's ``outputs``: the summary fields a run computes and returns.

A run computes what its listed fields need and no more (the energies at the stop, the
largest drag, the stiffness sampling behind ``h_lambda``, the steps' error estimate, the
joints' loads); what it returns is the same bit for bit as the full summary's. An unknown
name is a typed error naming the field, before anything runs, from Python, a scene file,
the command line and a sweep.
"""

from __future__ import annotations

import pathlib
import struct
import sys
import warnings

import numpy as np
import pytest

import granrs
from granrs.cli import main as cli_main

sys.path.insert(0, str(pathlib.Path(__file__).parent))
from record_thesis_cases import cases
from test_step_warning import short_impact  # a stop between the steps at dt = 1e-3

CASES = cases()
TABLE_3_5 = granrs.data.load("table_3_5", as_="numpy")
TABLE_SCENES = [
    granrs.cases.free_link(float(q), float(v))
    for q, v in zip(TABLE_3_5["q_deg"], TABLE_3_5["v0"], strict=True)
]
#: Each part of the observation that only some fields need, with a field that needs it.
PARTS = {
    "largest drag": "F_d_max",
    "stiffness": "h_lambda",
    "step error": "step_error",
    "energies": "dE",
}


def bits(x: float) -> bytes:
    return struct.pack("<d", float(x))


def contact_bits(result: granrs.Result, key: str) -> list[bytes]:
    return [bits(c.summary[key]) for c in result.contacts]


@pytest.mark.parametrize(("name", "scene"), CASES, ids=[n for n, _ in CASES])
def test_depth_and_t_s_alone_are_the_full_runs_bit_for_bit(name: str, scene: granrs.Scene):
    full = granrs.simulate(scene)
    lean = granrs.simulate(scene.replace(outputs=("depth", "t_s")))
    for key in ("depth", "t_s"):
        assert contact_bits(lean, key) == contact_bits(full, key), f"{name}: {key}"
    assert bits(lean.depth) == bits(full.depth) and bits(lean.t_s) == bits(full.t_s)
    assert lean.status == full.status
    # Nothing else is returned: the contact's two fields and the run's status.
    assert set(lean.summary) == {"depth", "t_s", "status"}
    for c in lean.contacts:
        assert set(c.summary) == {"depth", "t_s"}


@pytest.mark.parametrize("index", range(len(TABLE_SCENES)))
def test_table_3_5_depth_and_t_s_bit_for_bit(index: int):
    scene = TABLE_SCENES[index]
    full = granrs.simulate(scene)
    lean = granrs.simulate(scene.replace(outputs=["t_s", "depth"]))
    assert bits(lean.summary["depth"]) == bits(full.summary["depth"])
    assert bits(lean.summary["t_s"]) == bits(full.summary["t_s"])


@pytest.mark.parametrize("part", PARTS)
def test_each_part_asked_alone_is_the_full_runs_value(part: str):
    """Each field that needs a part of the observation, asked with depth alone, is the full
    run's value bit for bit, on the three bodies (the chain's and the leg's joints too)."""
    key = PARTS[part]
    for scene in (
        granrs.cases.free_link(q_deg=45, v0=2.27),
        granrs.cases.free_link(q_deg=5, v0=1.0, sign_model="raw"),
        granrs.cases.chain(case=2, end="all_stops"),
        granrs.cases.leg(v0=3.28, joints={"k": 300.0, "c": 5.0}),
    ):
        full = granrs.simulate(scene)
        lean = granrs.simulate(scene.replace(outputs=("depth", key)))
        if key in full.contacts[0].summary:
            assert contact_bits(lean, key) == contact_bits(full, key), (scene.kind, key)
        else:
            assert bits(lean.summary[key]) == bits(full.summary[key]), (scene.kind, key)
        assert contact_bits(lean, "depth") == contact_bits(full, "depth")


def test_joint_loads_asked_alone_are_the_full_runs():
    scene = granrs.cases.leg(v0=2.0, joints="locked")
    full = granrs.simulate(scene)
    lean = granrs.simulate(scene.replace(outputs=("F_max",)))
    assert list(lean.joints) == list(full.joints)
    for name, joint in lean.joints.items():
        assert set(joint) == {"F_max"}
        assert bits(joint["F_max"]) == bits(full.joints[name]["F_max"])
    # Not asked: not computed, not returned.
    assert "torque_max" not in next(iter(lean.joints.values()))


def test_the_default_returns_every_field():
    scene = granrs.cases.chain(case=1)
    assert scene.outputs is None
    result = granrs.simulate(scene)
    run_and_contact = [
        f["name"]
        for f in granrs._granrs.output_fields()
        if f["part"] != "joint" and f["name"] != "stopped"
    ]
    assert sorted(result.summary) == sorted(run_and_contact)
    assert all(set(j) == {"F_max", "torque_max", "impulse_work"} for j in result.joints.values())
    # The outputs listed in full are the default.
    every = granrs.simulate(scene.replace(outputs=granrs.OUTPUTS))
    assert every.summary.keys() == result.summary.keys()
    for key, value in result.summary.items():
        if isinstance(value, float):
            assert bits(every.summary[key]) == bits(value), key
        else:
            assert every.summary[key] == value, key


def test_outputs_names_come_from_the_core_table():
    assert granrs.OUTPUTS == tuple(f["name"] for f in granrs._granrs.output_fields())
    assert len(set(granrs.OUTPUTS)) == len(granrs.OUTPUTS)
    for name in ("status", "t_s", "depth", "h_lambda", "F_max", "dE"):
        assert name in granrs.OUTPUTS
    computes = {f["name"]: f["computes"] for f in granrs._granrs.output_fields()}
    assert computes["depth"] == "" and computes["t_s"] == ""
    assert computes["h_lambda"] and computes["dE"] and computes["F_max"]


@pytest.mark.parametrize(
    ("outputs", "error"),
    [
        (("depth", "dpeth"), granrs.UnknownNameError),
        (("depth", "depth"), granrs.InvalidSceneError),
        ("depth", granrs.InvalidParameterError),
        ((1, 2), granrs.UnknownNameError),
    ],
)
def test_bad_outputs_are_a_typed_error_naming_the_field(outputs, error):
    with pytest.raises(error) as info:
        granrs.Scene(outputs=outputs)
    assert info.value.field == "outputs"


def test_a_scene_file_refuses_an_unknown_output(tmp_path):
    text = granrs.scenefile.dumps(granrs.cases.free_link(q_deg=45, v0=2.27))

    def with_outputs(value: str) -> str:
        # A top-level key, before the [[forces]] tables.
        return text.replace("format = 1", f"format = 1\noutputs = {value}", 1)

    good = granrs.scenefile.loads(with_outputs('["depth", "t_s"]'))
    assert good.outputs == ("depth", "t_s")
    with pytest.raises(granrs.UnknownNameError) as info:
        granrs.scenefile.loads(with_outputs('["depth", "t_stop"]'))
    assert info.value.field == "outputs"
    assert ":4:" in str(info.value)  # the key's line
    # Written and read back as it was.
    assert granrs.scenefile.loads(granrs.scenefile.dumps(good)) == good


def test_the_command_line_runs_and_refuses_outputs(tmp_path, capsys):
    path = tmp_path / "rod.toml"
    granrs.scenefile.dump(granrs.cases.free_link(q_deg=45, v0=2.27), path)
    assert cli_main(["run", str(path), "--set", 'outputs=["depth", "t_s"]']) == 0
    out = capsys.readouterr().out
    assert "depth" in out and "F_d_max" not in out
    code = cli_main(["run", str(path), "--set", 'outputs=["depth", "F_dmax"]'])
    err = capsys.readouterr().err
    assert code != 0
    assert "outputs" in err and "F_dmax" in err


def test_a_sweep_returns_and_computes_only_its_outputs():
    base = granrs.cases.free_link(q_deg=0, v0=2.0)
    full = granrs.sweep(base, q_deg=[0.0, 45.0, 85.0], v0=[1.0, 2.27], progress=False)
    lean = granrs.sweep(
        base, q_deg=[0.0, 45.0, 85.0], v0=[1.0, 2.27], progress=False, outputs=("depth", "t_s")
    )
    # The core's order (status, then a contact's t_s before its depth), after the axes.
    assert list(lean.columns) == ["q_deg", "v0", "status", "t_s", "depth"]
    for key in ("t_s", "depth"):
        assert lean[key].to_numpy().tobytes() == full[key].to_numpy().tobytes()
    # A list of scenes that ask for them, on both paths.
    scenes = [base.replace(q_deg=q, outputs=("depth", "h_lambda")) for q in (0.0, 25.0, 65.0)]
    for lanes in (True, False):
        listed = granrs.sweep(scenes, progress=False, lanes=lanes)
        assert list(listed.columns) == ["status", "h_lambda", "depth"]
        alone = [granrs.simulate(s) for s in scenes]
        assert listed["depth"].to_numpy().tobytes() == np.array([r.depth for r in alone]).tobytes()
        assert (
            listed["h_lambda"].to_numpy().tobytes()
            == np.array([r.summary["h_lambda"] for r in alone]).tobytes()
        )
    # The sweep's outputs for every listed scene, whatever theirs.
    chain = [granrs.cases.chain(case=c) for c in (1, 2)]
    two = granrs.sweep(chain, progress=False, outputs=["depth", "F_max"])
    assert list(two.columns) == [
        "status",
        "c0.depth",
        "c1.depth",
        "pin_on_link1.F_max",
        "pin.F_max",
    ]
    assert two["c1.depth"].tolist() == [granrs.simulate(s).contacts[1].depth for s in chain]


def test_a_sweep_refuses_bad_or_varying_outputs_before_running():
    base = granrs.cases.free_link(q_deg=0, v0=2.0)
    with pytest.raises(granrs.UnknownNameError) as info:
        granrs.sweep(base, v0=[1.0, 2.0], outputs=["depth", "tS"], progress=False)
    assert info.value.field == "outputs"
    # Not an axis: one set of columns (a list of lists is not a list of names).
    with pytest.raises(granrs.UnknownNameError) as info:
        granrs.sweep(base, progress=False, outputs=[("depth",), ("t_s",)], v0=[1.0])
    assert info.value.field == "outputs"
    mixed = [base, base.replace(outputs=("depth",))]
    with pytest.raises(granrs.InvalidSceneError) as info:
        granrs.sweep(mixed, progress=False)
    assert info.value.field == "outputs"
    # The core refuses them too (a caller of the batch that skips the Python checks).
    with pytest.raises(granrs.UnknownNameError) as info:
        granrs._granrs.sweep(base=base._plain(), axes=[("v0", [1.0])], outputs=["dpth"])
    assert info.value.field == "outputs"
    with pytest.raises(granrs.InvalidSceneError) as info:
        granrs._granrs.sweep(
            base=base._plain(), axes=[("outputs", [["depth"], ["t_s"]])], outputs=None
        )
    assert info.value.field == "outputs"


def caught(fn):
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        out = fn()
    return out, [w for w in got if issubclass(w.category, granrs.StepSizeWarning)]


def test_an_unresolved_stop_warns_whatever_the_outputs():
    """The steps' error estimate and the checks of each stop run whatever the outputs (the
    warning's cheap half): a stop the step did not resolve warns with depth alone asked for,
    from simulate and from a sweep, and a resolved one does not."""
    for outputs in (None, ("depth",), ("depth", "t_s")):
        lean, warned = caught(lambda o=outputs: granrs.simulate(short_impact(1e-3, outputs=o)))
        assert len(warned) == 1, outputs
        assert "dt" in str(warned[0].message)
        _, quiet = caught(lambda o=outputs: granrs.simulate(short_impact(1e-5, outputs=o)))
        assert quiet == [], outputs
    full, _ = caught(lambda: granrs.simulate(short_impact(1e-3)))
    assert full.summary["unresolved_stops"] == 1
    assert bits(lean.depth) == bits(full.depth)
    frame, warned = caught(
        lambda: granrs.sweep(
            short_impact(1e-3), dt=[1e-5, 1e-3], outputs=("depth",), progress=False
        )
    )
    assert list(frame.columns) == ["dt", "status", "depth"]
    assert len(warned) == 1 and "rows [1]" in str(warned[0].message)
    _, quiet = caught(
        lambda: granrs.sweep(short_impact(1e-5), v0=[2.0, 2.2], outputs=("depth",), progress=False)
    )
    assert quiet == []


def test_h_lambda_is_computed_only_when_asked():
    """h_lambda (the stiffness sampled at every stage) is the default's and is computed
    when listed; left out, it is not computed (a stiff step then warns only through the
    stop checks)."""
    scene = granrs.cases.free_link(q_deg=45, v0=2.27)
    full = granrs.simulate(scene)
    assert 0 < full.summary["h_lambda"] < 1
    asked = granrs.simulate(scene.replace(outputs=("h_lambda",)))
    assert bits(asked.summary["h_lambda"]) == bits(full.summary["h_lambda"])
    assert "h_lambda" not in granrs.simulate(scene.replace(outputs=("depth",))).summary
