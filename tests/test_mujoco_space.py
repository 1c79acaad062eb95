"""granrs.mujoco.Sand in three dimensions: geoms as shapes in space under rft3d, the
implicit step, rest, and the momentum it hands MuJoCo."""

from __future__ import annotations

import math
import os
import warnings

import numpy as np
import pytest

import granrs
from granrs import forces, space

mujoco = pytest.importorskip("mujoco")
from hopper_hold import assert_rests, hold_upright  # noqa: E402

from granrs.mujoco import Sand, body_drop, body_mjcf  # noqa: E402

ZETA = 1e6

# A step whose implicit solve falls back to sticking or sliding warns once; the tests
# below check the outcome itself.
pytestmark = pytest.mark.filterwarnings("ignore::granrs.StepSizeWarning")


def q_about_y(deg: float) -> tuple[float, float, float, float]:
    a = math.radians(deg) / 2
    return (math.cos(a), 0.0, math.sin(a), 0.0)


def scene(shape, **kw):
    return space.Scene(
        body=space.Body(shape, density=2500.0),
        forces=[forces.rft3d(zeta=ZETA), forces.gravity()],
        velocity=kw.pop("velocity", (0.0, 0.0, -1.0)),
        **kw,
    )


CASES = {
    "sphere": scene(space.Sphere(0.02)),
    "sphere at 30 degrees": scene(space.Sphere(0.02), velocity=(0.5, 0.0, -0.866)),
    "capsule vertical": scene(space.Capsule(0.01, 0.06)),
    "capsule at 30 degrees": scene(space.Capsule(0.01, 0.06), orientation=q_about_y(30)),
    "capsule at 60 degrees": scene(space.Capsule(0.01, 0.06), orientation=q_about_y(60)),
    "capsule side-on": scene(space.Capsule(0.01, 0.06), orientation=q_about_y(90)),
}


@pytest.mark.parametrize("name", list(CASES))
def test_a_drop_in_mujoco_matches_granrs_own_engine(name):
    # granrs.simulate (RK4, located stop) against MuJoCo's Euler at 1e-4 s with the
    # implicit sand: depth within 2 %, t_s within 5 %.
    s = CASES[name]
    ref = granrs.simulate(s)
    d = body_drop(s, timestep=1e-4)
    assert abs(d["depth"] / ref.depth - 1) < 0.02, (d["depth"], ref.depth)
    assert abs(d["t_s"] / ref.t_s - 1) < 0.05, (d["t_s"], ref.t_s)


@pytest.mark.parametrize("integrator", ["Euler", "implicitfast", "RK4"])
@pytest.mark.parametrize("timestep", [1e-3, 1e-2])
def test_a_sphere_at_rest_holds_still_without_chattering_or_gaining_energy(integrator, timestep):
    s = CASES["sphere"]
    d = body_drop(s, timestep=timestep, integrator=integrator, t_after=3.0)
    weight = s.mass * s.g
    last = slice(-round(1.0 / timestep), None)
    # Less than 0.1 mm over the last second, force within 5 % of the weight step to step.
    assert np.ptp(d["depth_after"][last]) < 1e-4
    fz = d["force"][last, 2]
    assert np.all(np.abs(fz - weight) < 0.05 * weight), (fz.min(), fz.max(), weight)
    # The energy never rises beyond 1e-6 J/s after the stop.
    e = d["energy"]
    assert np.max(np.diff(e)) <= 1e-6 * timestep, np.max(np.diff(e))


@pytest.mark.parametrize(
    ("mode", "integrator"), [("step", "Euler"), ("callback", "Euler"), ("callback", "RK4")]
)
def test_the_force_handed_to_mujoco_is_the_momentum_the_body_receives(mode, integrator):
    s = CASES["capsule at 30 degrees"]
    h = 1e-3
    m = mujoco.MjModel.from_xml_string(body_mjcf(s, h, integrator))
    d = mujoco.MjData(m)
    d.qpos[:3] = s.position
    d.qpos[3:7] = s.orientation
    d.qvel[:3] = s.velocity
    sand = Sand(m, ["body"], [forces.rft3d(zeta=ZETA)], space=True)
    impulse = np.zeros(3)
    p0 = s.mass * d.qvel[:3].copy()
    if mode == "callback":
        sand.install()
    try:
        for _ in range(60):
            if mode == "step":
                sand.step(d)
            mujoco.mj_step(m, d)
            impulse += h * (sand.applied[0, :3] + np.array([0.0, 0.0, -s.mass * s.g]))
    finally:
        if mode == "callback":
            sand.uninstall()
    p1 = s.mass * d.qvel[:3]
    assert np.all(np.abs(p1 - p0 - impulse) < 1e-9 * (1 + np.abs(impulse).max()))
    assert impulse[2] > 0.5 * s.mass  # the sand did stop it


def test_step_and_callback_agree():
    s = CASES["capsule at 60 degrees"]
    a = body_drop(s, timestep=1e-4, mode="step")
    b = body_drop(s, timestep=1e-4, mode="callback")
    assert abs(a["depth"] - b["depth"]) < 1e-9 and abs(a["t_s"] - b["t_s"]) < 1e-9


def test_every_geom_type_is_a_shape_in_space_and_feels_the_sand():
    xml = """<mujoco><option timestep="0.001"/>
      <asset><mesh name="tet" vertex="0 0 0  0.04 0 0  0 0.04 0  0 0 0.04"/></asset>
      <worldbody>
      <body pos="0 0 0"><freejoint/><geom name="sphere" type="sphere" size="0.02"/></body>
      <body pos="1 0 0"><freejoint/><geom name="capsule" type="capsule" size="0.01 0.03"/></body>
      <body pos="2 0 0"><freejoint/><geom name="cylinder" type="cylinder" size="0.01 0.03"/></body>
      <body pos="3 0 0"><freejoint/><geom name="box" type="box" size="0.02 0.02 0.02"/></body>
      <body pos="4 0 0"><freejoint/>
        <geom name="ellipsoid" type="ellipsoid" size="0.02 0.03 0.01"/></body>
      <body pos="5 0 0"><freejoint/><geom name="mesh" type="mesh" mesh="tet"/></body>
      </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    names = ["sphere", "capsule", "cylinder", "box", "ellipsoid", "mesh"]
    sand = Sand(m, names, [forces.rft3d(zeta=ZETA)])
    assert sand.space
    for k in range(6):
        d.qvel[6 * k + 2] = -1.0
    sand.step(d)
    depth = sand.output[:, 0]
    # Every geom's centre is at the surface: each is half sunk (the mesh by its own
    # lowest point), and each is pushed up.
    assert np.all(depth > 0.0) and np.all(sand.output[:, 1] > 0)
    assert np.all(sand.applied[:, 2] > 0.0), sand.applied


def test_bad_input_is_a_typed_error_naming_it():
    xml = """<mujoco><worldbody><geom name="floor" type="plane" size="1 1 1"/>
      <body><freejoint/><geom name="ball" type="sphere" size="0.02"/></body>
      </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    rft = forces.rft3d(zeta=ZETA)
    cases = [
        (dict(geoms=["nope"], forces=[rft]), "geoms[0]"),
        (dict(geoms=["floor"], forces=[rft]), "geoms[0]"),
        (dict(geoms=["ball"], forces=[rft, forces.gravity()]), "gravity"),
        (dict(geoms=["ball"], forces=[rft], rest_speed=0.0), "rest_speed"),
        (dict(geoms=["ball"], forces=[rft], rest_speed=math.nan), "rest_speed"),
        (dict(geoms=["ball"], forces=[rft], quadrature=True), "quadrature"),
        (dict(geoms=["ball"], forces=[rft], quadrature=0), "quadrature"),
        (dict(geoms=["ball"], forces=[rft], patch=(1, 0)), "patch"),
        (dict(geoms=["ball"], forces=[rft], surface=math.inf), "surface"),
        (dict(geoms=["ball"], forces=[forces.drag()], space=True), "forces[0]"),
    ]
    for kw, field in cases:
        with pytest.raises(granrs.GranrsError) as e:
            Sand(m, **kw)
        assert field in (e.value.field or "") + str(e.value), (kw, e.value)


@pytest.mark.parametrize("space", [True, False])
def test_the_cores_binding_of_mujocos_arrays_names_the_array_it_refuses(space):
    # Both couplings bind one mjData's arrays through one checked table (the planar one
    # with cvel as well): a wrong count or a wrong shape is refused naming the array.
    xml = """<mujoco><worldbody><body name="rod" pos="0 0 0.05">
      <joint type="slide" axis="1 0 0"/><joint type="slide" axis="0 0 1"/>
      <joint type="hinge" axis="0 1 0"/>
      <geom name="rod" type="capsule" size="0.006 0.09" mass="0.18"/>
      </body></worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    terms = [forces.rft3d(zeta=ZETA)] if space else [forces.drag(), forces.static_v()]
    sand = Sand(m, ["rod"], terms, space=space)
    sand.step(d)
    core = sand._coupling
    name = "MujocoCoupling." + ("space" if space else "planar")
    velocity = () if space else (d.cvel,)
    arrays = [d.geom_xpos, d.geom_xmat, *velocity, d.subtree_com, d.cdof, d.qvel, d.qacc]
    arrays += [d.qfrc_applied, d.qfrc_passive, sand._mass, sand.output, sand.applied]
    arrays += [sand.h_lambda, sand._generalized, sand._before, sand._after]
    core.bind(*arrays)
    with pytest.raises(ValueError, match=f"{name}.bind: {len(arrays)} arrays, got"):
        core.bind(*arrays[:-1])
    k = 3 if space else 4
    bad = list(arrays)
    bad[k] = np.zeros((m.nv, 5))
    with pytest.raises(ValueError, match=f"{name}.bind: cdof"):
        core.bind(*bad)
    bad = list(arrays)
    bad[-3] = np.zeros(m.nv + 1)
    with pytest.raises(ValueError, match=f"{name}.bind: generalized"):
        core.bind(*bad)
    bad = list(arrays)
    bad[0] = [[0.0] * 3]
    with pytest.raises(ValueError, match=f"{name}.bind: geom_xpos"):
        core.bind(*bad)


def test_a_geom_outside_the_patch_feels_nothing():
    s = CASES["sphere"]
    m = mujoco.MjModel.from_xml_string(body_mjcf(s, 1e-3))
    d = mujoco.MjData(m)
    d.qpos[2] = 0.0
    d.qvel[2] = -1.0
    sand = Sand(m, ["body"], [forces.rft3d(zeta=ZETA)], patch=(-1, 1, 0.5, 1.0))
    sand.step(d)
    assert np.all(sand.applied == 0.0)
    inside = Sand(m, ["body"], [forces.rft3d(zeta=ZETA)], patch=(-1, 1, -1, 1))
    inside.step(d)
    assert inside.applied[0, 2] > 0.0


def test_gymnasiums_ant_stands_on_sand_at_its_own_timestep():
    gymnasium = pytest.importorskip("gymnasium")
    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets/ant.xml")
    m = mujoco.MjModel.from_xml_path(path)
    feet = ["left_ankle_geom", "right_ankle_geom", "third_ankle_geom", "fourth_ankle_geom"]
    for g in feet:
        gid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, g)
        m.geom_contype[gid] = 0
        m.geom_conaffinity[gid] = 0
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    sand = Sand(m, feet, [forces.rft3d(zeta=space.xi_n(1520.0, 0.4))], quadrature=3)
    h = m.opt.timestep
    tilt, z = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", granrs.StepSizeWarning)
        for _ in range(round(4.0 / h)):
            sand.step(d)
            mujoco.mj_step(m, d)
            r = d.xmat[1].reshape(3, 3)
            tilt.append(math.degrees(math.acos(min(1.0, max(-1.0, r[2, 2])))))
            z.append(d.qpos[2])
    assert np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))
    assert max(tilt) < 30.0
    # Standing on the sand: the feet in it, the weight carried by them.
    assert np.all(sand.output[:, 0] > 0.0)
    weight = m.body_subtreemass[1] * np.linalg.norm(m.opt.gravity)
    assert abs(sand.applied[:, 2].sum() / weight - 1) < 0.1


@pytest.mark.parametrize("mode", ["step", "callback"])
@pytest.mark.parametrize("foot", ["capsule", "box"])
def test_gymnasiums_hopper_foot_rests_on_sand_under_rft3d(mode, foot):
    # The hopper held upright by a PD controller on its own motors, its whole weight on
    # its foot in the sand (no floor), 10 s at its own RK4 2 ms: the foot moves less than
    # 0.1 mm over the last 5 s, the sand's force is the weight without step-to-step spread,
    # and the sand never does positive work.
    pytest.importorskip("gymnasium")
    from granrs.gym import hopper_model

    m = hopper_model(foot)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    foot_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "foot_geom")
    sand = Sand(m, ["foot_geom"], [forces.rft3d(zeta=space.xi_n(1520.0, 0.4))])
    h = m.opt.timestep
    weight = m.body_subtreemass[1] * np.linalg.norm(m.opt.gravity)
    pos, fz, power = [], [], []

    def record(d):
        pos.append(d.geom_xpos[foot_id].copy())
        fz.append(sand.applied[0, 2])
        power.append(sand.applied[0, :3] @ sand.output[0, 8:11])

    hold_upright(m, d, sand, mode, 10.0, record)
    last = assert_rests(pos, fz, weight, h)
    assert max(power[last]) <= 1e-9


@pytest.mark.parametrize("mode", ["step", "callback"])
@pytest.mark.parametrize("foot", ["capsule", "box"])
def test_gymnasiums_hopper_foot_rests_on_sand_under_poncelet_in_space(mode, foot):
    # The same hopper on poncelet in space (its depth term k d does not vanish at rest):
    # over the last 5 s of 10 s the sand's own work (its generalized force, J^T of its
    # wrench from MuJoCo's own Jacobians at the step's start, on each step's displacement)
    # never rises by more than 1e-6 J/s over max(t, 1 s), and no step's power is
    # positive; the foot holds still and the force balances the weight.
    pytest.importorskip("gymnasium")
    from granrs.gym import hopper_model

    m = hopper_model(foot)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    foot_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "foot_geom")
    body = m.geom_bodyid[foot_id]
    sand = Sand(m, ["foot_geom"], [forces.poncelet(c=1.0, k=2000.0)], space=True)
    h = m.opt.timestep
    weight = m.body_subtreemass[1] * np.linalg.norm(m.opt.gravity)
    assert m.nq == m.nv  # slides and hinges: the displacement is the change of qpos
    pos, fz, power = [], [], []
    before = [d.qpos.copy()]
    jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))

    def record(d):
        # After mj_step the kinematics are still the step's start's: the sand's pose.
        mujoco.mj_jac(m, d, jacp, jacr, d.geom_xpos[foot_id], body)
        generalized = jacp.T @ sand.applied[0, :3] + jacr.T @ sand.applied[0, 3:]
        power.append(generalized @ (d.qpos - before[0]) / h)
        before[0] = d.qpos.copy()
        pos.append(d.geom_xpos[foot_id].copy())
        fz.append(sand.applied[0, 2])

    hold_upright(m, d, sand, mode, 10.0, record)
    last = assert_rests(pos, fz, weight, h)
    w = np.array(power)[last]
    work = np.cumsum(w) * h
    work -= work[0]
    elapsed = np.arange(len(work)) * h
    assert np.max(work / np.maximum(elapsed, 1.0)) <= 1e-6
    assert np.max(w) <= 0.0, np.max(w)


def test_gymnasiums_humanoid_dropped_on_sand_stays_finite():
    gymnasium = pytest.importorskip("gymnasium")
    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets/humanoid.xml")
    m = mujoco.MjModel.from_xml_path(path)
    geoms = ["right_foot", "left_foot", "right_shin1", "left_shin1"]
    for g in geoms:
        gid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, g)
        m.geom_contype[gid] = 0
        m.geom_conaffinity[gid] = 0
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    sand = Sand(m, geoms, [forces.rft3d(zeta=space.xi_n(1520.0, 0.4))], quadrature=3)
    for _ in range(round(3.0 / m.opt.timestep)):
        sand.step(d)
        mujoco.mj_step(m, d)
        assert np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))
        assert np.all(np.isfinite(sand.applied))
    assert np.any(sand.output[:, 0] > 0.0)  # it is in the sand


def test_the_gallery_ant_runs():
    """The gallery's Ant-on-sand example (docs) runs: finite, standing on both grounds."""
    import runpy
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pytest.importorskip("gymnasium")
    script = Path(__file__).resolve().parents[1] / "examples/gallery/plot_10_ant_on_sand.py"
    namespace = runpy.run_path(str(script))
    plt.close("all")
    runs = namespace["runs"]
    assert set(runs) == {"sand", "rigid floor"}
    weight = namespace["weight"]
    for r in runs.values():
        assert np.all(np.isfinite(r["x"])) and np.all(np.isfinite(r["fz"]))
    stand = runs["sand"]["t"] <= namespace["T_STAND"] + 1e-9
    assert abs(runs["sand"]["fz"][stand][-1].sum() / weight - 1) < 0.05
