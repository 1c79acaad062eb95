"""granrs.mujoco.Sand: granrs's terms on the geoms of a planar MuJoCo model (issue 21).

Skipped without the ``mujoco`` package (``pip install 'granrs[mujoco]'``), except the test
that ``import granrs`` works without it.
"""

from __future__ import annotations

import math
import subprocess
import sys
import warnings

import numpy as np
import pytest

import granrs
from granrs import forces

THESIS = [forces.drag(), forces.static_h(), forces.static_v()]


def test_granrs_imports_without_mujoco_and_says_what_to_install():
    """Without mujoco, `import granrs` works and `granrs.mujoco` names the extra."""
    code = (
        "import sys; sys.modules['mujoco'] = None\n"
        "import granrs\n"
        "try:\n"
        "    import granrs.mujoco\n"
        "except ImportError as e:\n"
        "    print('IMPORTERROR', e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "IMPORTERROR" in out.stdout
    assert "pip install 'granrs[mujoco]'" in out.stdout


mujoco = pytest.importorskip("mujoco")
from hopper_hold import assert_rests, hold_upright  # noqa: E402

from granrs.mujoco import Sand, free_link_mjcf, rod_drop  # noqa: E402

ROD = free_link_mjcf(granrs.cases.free_link(q_deg=0, v0=2.0))


def _rod(xml: str = ROD):
    model = mujoco.MjModel.from_xml_string(xml)
    return model, mujoco.MjData(model)


RFT = forces.term("rft", zeta=1e6, elements=64)


@pytest.mark.parametrize("law", ["thesis", "rft"])
@pytest.mark.parametrize("q_deg", [0, 30, 60])
def test_rod_drop_matches_simulate_at_1e_4(q_deg, law):
    """Acceptance: the free link dropped in MuJoCo (Euler, 1e-4 s) under the thesis's law
    and under rft(zeta=1e6, elements=64) stops within 2 % of granrs.simulate's depth and 5 %
    of its t_s."""
    scene = granrs.cases.free_link(q_deg=q_deg, v0=2.0)
    if law == "rft":
        scene = scene.replace(forces=(forces.gravity(), RFT))
    ref = granrs.simulate(scene)
    got = rod_drop(scene, timestep=1e-4, integrator="Euler")
    assert got["depth"] == pytest.approx(ref.depth, rel=0.02)
    assert got["t_s"] == pytest.approx(ref.t_s, rel=0.05)


def test_step_and_callback_give_the_same_drop():
    """sand.step before mj_step and the passive callback apply the same force with Euler
    (the callback runs inside mj_step at the same state)."""
    scene = granrs.cases.free_link(q_deg=30, v0=2.0)
    a = rod_drop(scene, timestep=1e-3, mode="step")
    b = rod_drop(scene, timestep=1e-3, mode="callback")
    assert b["depth"] == pytest.approx(a["depth"], rel=1e-9)
    assert b["t_s"] == pytest.approx(a["t_s"], rel=1e-9)


@pytest.mark.parametrize("mode", ["step", "callback"])
def test_a_resting_rod_stays_put_and_gains_no_energy(mode):
    """Acceptance (rest): after the stop of the q = 0, v0 = 2 m/s drop, the tip stays within
    0.1 mm of where it stopped and E(t) - E(t_stop) <= 1e-6 J/s x max(t - t_stop, 1 s)."""
    scene = granrs.cases.free_link(q_deg=0, v0=2.0)
    got = rod_drop(scene, timestep=1e-4, mode=mode, t_after=10.0)
    moved = np.max(np.hypot(*(got["tip"] - got["tip"][0]).T))
    assert moved < 1e-4
    elapsed = got["t"] - got["t"][0]
    rise = got["energy"] - got["energy"][0]
    assert np.all(rise <= 1e-6 * np.maximum(elapsed, 1.0))


def test_the_raw_static_terms_chatter_at_rest():
    """The reason for the stick: with the thesis's plain sign the resting rod's static terms
    flip every step, the rod creeps and the energy bound of the rest test fails."""
    scene = granrs.cases.free_link(q_deg=0, v0=2.0)
    got = rod_drop(scene, timestep=1e-4, statics="raw", t_after=1.0)
    moved = np.max(np.hypot(*(got["tip"] - got["tip"][0]).T))
    elapsed = got["t"] - got["t"][0]
    rise = got["energy"] - got["energy"][0]
    assert moved > 1e-4 or np.any(rise > 1e-6 * np.maximum(elapsed, 1.0))


def test_step_replaces_its_own_force_and_keeps_the_users():
    """qfrc_applied: each step replaces the Sand's previous contribution; the user's own
    entries (set once, or assigned anew before a step) are kept exactly."""
    model, data = _rod()
    data.qpos[:] = [0.0, 0.095 - 0.03, 0.1]
    data.qvel[:] = [0.3, -1.0, 0.5]
    sand = Sand(model, ["rod"], THESIS)
    data.qfrc_applied[:] = [0.125, 0.0, -0.25]
    sand.step(data)
    first = data.qfrc_applied.copy()
    assert np.any(first != [0.125, 0.0, -0.25])
    sand.step(data)  # same state: same force, not twice the force
    np.testing.assert_array_equal(data.qfrc_applied, first)
    data.qfrc_applied[2] = 1.5  # the user assigns one entry anew
    sand.step(data)
    contribution = first - np.array([0.125, 0.0, -0.25])
    np.testing.assert_allclose(
        data.qfrc_applied, np.array([0.125, 0.0, 1.5]) + contribution, rtol=0, atol=1e-15
    )
    data.qpos[1] = 1.0  # out of the sand: only the user's entries remain, exactly
    sand.step(data)
    np.testing.assert_array_equal(data.qfrc_applied, [0.125, 0.0, 1.5])


def test_the_force_is_the_cores_at_the_tip():
    """The applied generalized force is the core's force at the tip and its moment, through
    the rod's Jacobian: check against the free link's terms by hand (vertical rod sinking
    straight down: only static_v, no drag)."""
    model, data = _rod()
    data.qpos[:] = [0.0, 0.095 - 0.05, 0.0]
    data.qvel[:] = [0.0, -1.0, 0.0]
    sand = Sand(model, ["rod"], THESIS, statics="raw")
    sand.step(data)
    v = math.pi / 4 * 0.0127**2 * 0.05
    by_hand = 248.0 * (0.05 / 0.19) ** 0.106 * 9.81 * 1650.0 * v
    np.testing.assert_allclose(data.qfrc_applied, [0.0, by_hand, 0.0], rtol=1e-12, atol=1e-15)


def test_two_sands_act_on_their_own_models_and_uninstall_restores_the_callback():
    """The passive callback is global: each installed Sand acts only on its own model, and
    the callback that was there before comes back when the last one is uninstalled."""
    seen = []

    def before(m, d):
        seen.append(m)

    # Models are compiled first: MuJoCo's compiler fails while a Python passive callback is
    # installed (it calls it with a model that has no Python wrapper).
    (m1, d1), (m2, d2) = _rod(), _rod()
    mujoco.set_mjcb_passive(before)
    try:
        for d in (d1, d2):
            d.qpos[:] = [0.0, 0.095 - 0.05, 0.0]
            d.qvel[:] = [0.0, -1.0, 0.0]
        s1 = Sand(m1, ["rod"], THESIS, statics="raw")
        s2 = Sand(m2, ["rod"], [forces.static_v(eta_v=100.0)], statics="raw")
        s1.install()
        s2.install()
        mujoco.mj_forward(m1, d1)
        mujoco.mj_forward(m2, d2)
        assert d1.qfrc_passive[1] > d2.qfrc_passive[1] > 0.0
        assert seen == [m1, m2]
        s1.uninstall()
        mujoco.mj_forward(m1, d1)
        assert d1.qfrc_passive[1] == 0.0
        s2.uninstall()
        assert mujoco.get_mjcb_passive() is before
    finally:
        mujoco.set_mjcb_passive(None)


def test_a_patch_is_a_region_of_x():
    """A geom whose tip is outside the patch feels nothing from the sand."""
    model, data = _rod()
    data.qpos[:] = [0.0, 0.095 - 0.05, 0.0]
    data.qvel[:] = [0.0, -1.0, 0.0]
    Sand(model, ["rod"], THESIS, patch=(0.5, 1.0)).step(data)
    assert np.all(data.qfrc_applied == 0.0)
    Sand(model, ["rod"], THESIS, patch=(-0.5, 0.5)).step(data)
    assert data.qfrc_applied[1] > 0.0


def test_a_timestep_too_coarse_for_the_drag_warns_with_one_that_resolves_it():
    """h lambda per step; past the integrator's limit a StepSizeWarning names a timestep."""
    scene = granrs.cases.free_link(q_deg=30, v0=2.0, forces=[forces.drag(eta_d=15.2e3)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got = rod_drop(scene, timestep=2e-3)
    assert got["sand"].max_h_lambda > 2.0
    [w] = [w for w in caught if issubclass(w.category, granrs.StepSizeWarning)]
    assert "use timestep <=" in str(w.message)
    small = rod_drop(granrs.cases.free_link(q_deg=30, v0=2.0), timestep=1e-4)
    assert 0.0 < small["sand"].max_h_lambda < 0.5


BAD_MODELS = {
    "sphere": ROD.replace('type="cylinder" size="0.00635 0.095"', 'type="sphere" size="0.05"'),
    "free": ROD.replace(
        '<joint name="x" type="slide" axis="1 0 0"/>\n      <joint name="z" type="slide" '
        'axis="0 0 1"/>\n      <joint name="q" type="hinge" axis="0 1 0"/>',
        '<freejoint name="free"/>',
    ),
    "tilted hinge": ROD.replace('name="q" type="hinge" axis="0 1 0"', 'name="q" type="hinge"'),
}


@pytest.mark.parametrize(
    ("xml", "geoms", "terms", "kwargs", "named"),
    [
        (ROD, ["foot"], THESIS, {}, "foot"),
        (BAD_MODELS["sphere"], ["rod"], THESIS, {}, "sphere"),
        (BAD_MODELS["free"], ["rod"], THESIS, {}, "free"),
        (BAD_MODELS["tilted hinge"], ["rod"], THESIS, {}, "`q`"),
        (ROD, ["rod"], [forces.gravity(), *THESIS], {}, "gravity"),
        (ROD, ["rod"], [*THESIS, forces.joint_springs()], {}, "joint_springs"),
        (ROD, ["rod"], THESIS, {"rho_g": math.nan}, "rho_g"),
        (ROD, ["rod"], [forces.drag(eta_d=(1.0, 2.0))], {}, "drag.eta_d"),
        (ROD, ["rod"], THESIS, {"surface": math.inf}, "surface"),
        (ROD, ["rod"], THESIS, {"apply_at": "heel"}, "apply_at"),
        (ROD, ["rod"], THESIS, {"patch": (1.0, 0.0)}, "patch"),
        (ROD, ["rod"], [RFT], {"rest_speed": 0.0}, "rest_speed"),
        (ROD, ["rod"], [RFT], {"rest_speed": math.nan}, "rest_speed"),
    ],
)
def test_bad_input_is_a_typed_error_naming_it_before_the_first_step(
    xml, geoms, terms, kwargs, named
):
    """A missing geom, an unsupported geom type, a model that is not planar, a body term or a
    non-finite parameter: each a GranrsError (a ValueError) naming it, from Sand(...)."""
    model = mujoco.MjModel.from_xml_string(xml)
    with pytest.raises(granrs.GranrsError) as info:
        Sand(model, geoms, terms, **kwargs)
    assert isinstance(info.value, ValueError)
    assert named in str(info.value)


@pytest.mark.parametrize("law", ["thesis", "rft"])
@pytest.mark.parametrize("mode", ["step", "callback"])
def test_a_walker_standing_in_sand_stays_put(mode, law):
    """Two sand geoms on one tree, with MuJoCo's implicit joint damping: once the gallery's
    walker has landed (0.3 s), for 1 s its shanks' tips stay within 0.1 mm, under the
    thesis's law and under rft, and under the thesis's law its energy (MuJoCo's KE + PE,
    springs included) rises by no more than 1e-6 J/s x max(t, 1 s). Pins the chatter of the
    first version, whose reactions drove each other to their bounds. Under rft the energy
    bound is not held (measured: rises of 3e-7 to 1.9e-5 J in the second, by mode and element
    count; docs/mujoco.md): its force turns with the velocity and it reports no sticking
    bound outside the solver's held modes, so its reactions are bounded by its force."""
    from granrs.mujoco import WALKER_SAND_GEOMS, walker_mjcf

    model = mujoco.MjModel.from_xml_string(walker_mjcf())
    model.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    data = mujoco.MjData(model)
    data.qvel[1] = -2.0
    terms = THESIS if law == "thesis" else [forces.term("rft", zeta=1e6, elements=16)]
    sand = Sand(model, list(WALKER_SAND_GEOMS), terms)
    ids = [model.geom(name).id for name in WALKER_SAND_GEOMS]

    def tips():
        return np.array([data.geom_xpos[g] - data.geom_xmat[g, 2::3] * 0.26 for g in ids])

    if mode == "callback":
        sand.install()
    try:
        landed = round(0.3 / model.opt.timestep)
        for k in range(landed + round(1.0 / model.opt.timestep)):
            if mode == "step":
                sand.step(data)
            mujoco.mj_step(model, data)
            if k == landed:
                t0, e0, x0 = data.time, data.energy.sum(), tips()
            elif k > landed:
                assert np.abs(tips() - x0).max() < 1e-4
                if law == "thesis":
                    assert data.energy.sum() - e0 <= 1e-6 * max(data.time - t0, 1.0)
    finally:
        if mode == "callback":
            sand.uninstall()


def test_the_gallery_walker_runs():
    """The gallery's walker example (docs) runs on its short horizon."""
    import runpy
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    script = Path(__file__).resolve().parents[1] / "examples/gallery/plot_07_mujoco_walker.py"
    namespace = runpy.run_path(str(script))
    plt.close("all")
    runs = namespace["runs"]
    assert set(runs) == {"sand, rft", "sand, thesis's law", "rigid ground"}
    for _, t, depth, force, _ in runs.values():
        assert np.all(np.isfinite(depth)) and np.all(np.isfinite(force))
        assert t[-1] == pytest.approx(namespace["T_END"], abs=1e-9)


def test_the_generalized_force_is_mj_applyFT_of_each_geoms_force_at_its_tip():
    """The core's generalized force (its own Jacobians from MuJoCo's cdof) equals MuJoCo's
    mj_applyFT of each geom's applied force and moment at its tip, on the walker's two
    shanks mid-impact (different angles, moving, apply_at centroid)."""
    from granrs.mujoco import WALKER_SAND_GEOMS, walker_mjcf

    model = mujoco.MjModel.from_xml_string(walker_mjcf())
    data = mujoco.MjData(model)
    data.qvel[:3] = [0.4, -2.0, 0.8]
    sand = Sand(model, list(WALKER_SAND_GEOMS), THESIS, apply_at="centroid")
    for _ in range(60):
        sand.step(data)
        mujoco.mj_step(model, data)
    data.qfrc_applied[:] = 0.0
    sand.step(data)
    assert np.all(sand.output[:, 3] > 0.0)
    expected = np.zeros(model.nv)
    for i, name in enumerate(WALKER_SAND_GEOMS):
        g = model.geom(name).id
        axis = data.geom_xmat[g, 2::3] * np.sign(data.geom_xmat[g, 8])
        tip = data.geom_xpos[g] - (model.geom_size[g, 1] + model.geom_size[g, 0]) * axis
        fx, fz, m = sand.applied[i]
        mujoco.mj_applyFT(
            model,
            data,
            np.array([fx, 0.0, fz]),
            np.array([0.0, m, 0.0]),
            tip,
            int(model.geom_bodyid[g]),
            expected,
        )
    np.testing.assert_allclose(data.qfrc_applied, expected, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("q_deg", [0, 30, 60])
def test_rk4_as_the_callback_matches_simulate_at_2e_3(q_deg):
    """As the callback under RK4 the force is evaluated at each stage, and the static
    reactions solved at the first stage act through the whole step (a sliding one with each
    stage's bound): the drop stays within 0.5 % of granrs.simulate's depth and 5 % of its
    t_s even at 2e-3 s (Sand.step, which holds the whole force through the step, is off by
    2.5-4 % in depth there)."""
    scene = granrs.cases.free_link(q_deg=q_deg, v0=2.0)
    ref = granrs.simulate(scene)
    got = rod_drop(scene, timestep=2e-3, integrator="RK4", mode="callback")
    assert got["depth"] == pytest.approx(ref.depth, rel=0.005)
    assert got["t_s"] == pytest.approx(ref.t_s, rel=0.05)


def test_a_box_is_the_legs_sole():
    """A box geom is the leg's sole box (SoleModel::Box): f_s its length along x, w_s its
    width along y, L_ref its length. A flat box sinking straight down at 0.5 m/s with its
    sole 10 mm deep: static_v = eta_v (d/L_ref)^lam g rho_g w_s f_s d and the drag
    eta_d rho_g (w_s f_s) v^2, both up, at the sole's middle (no moment about the centre)."""
    xml = ROD.replace('type="cylinder" size="0.00635 0.095"', 'type="box" size="0.127 0.043 0.02"')
    model, data = _rod(xml)
    data.qpos[:] = [0.0, 0.02 - 0.01, 0.0]
    data.qvel[:] = [0.0, -0.5, 0.0]
    sand = Sand(model, ["rod"], [forces.drag(), forces.static_v()], statics="raw")
    sand.step(data)
    f_s, w_s, d = 0.254, 0.086, 0.01
    static_v = 248.0 * (d / f_s) ** 0.106 * 9.81 * 1650.0 * w_s * f_s * d
    drag = 15.2 * 1650.0 * w_s * f_s * 0.5**2
    np.testing.assert_allclose(
        data.qfrc_applied, [0.0, static_v + drag, 0.0], rtol=1e-12, atol=1e-9
    )


def test_a_box_dropped_flat_settles_without_gaining_energy():
    """A 1.5 kg sole box dropped flat at 1 m/s (and 0.2 m/s sideways), the force at the
    immersed centroid: MuJoCo's energy never rises (beyond round-off) and after 2 s the box
    has stopped sinking."""
    xml = ROD.replace(
        'type="cylinder" size="0.00635 0.095"', 'type="box" size="0.127 0.043 0.02"'
    ).replace('mass="0.184"', 'mass="1.5"')
    model, data = _rod(xml)
    model.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    data.qpos[:] = [0.0, 0.02, 0.0]
    data.qvel[:] = [0.2, -1.0, 0.0]
    sand = Sand(model, ["rod"], THESIS, apply_at="centroid")
    lowest = math.inf
    for _ in range(20000):
        sand.step(data)
        mujoco.mj_step(model, data)
        energy = data.energy.sum()
        assert energy <= lowest + 1e-9
        lowest = min(lowest, energy)
    assert abs(data.qvel[1]) < 1e-2
    assert sand.output[0, 3] > 0.0  # still in the sand


def _hopper(foot: str):
    """Gymnasium's own hopper (RK4 at 2 ms), no floor, its foot a capsule or a box."""
    pytest.importorskip("gymnasium")
    from granrs.gym import hopper_model

    return hopper_model(foot)


@pytest.mark.parametrize("mode", ["step", "callback"])
@pytest.mark.parametrize("foot", ["capsule", "box"])
def test_gymnasiums_hopper_foot_rests_on_sand_under_planar_rft(mode, foot):
    """Acceptance (rest under the planar rft): the hopper held upright by a PD controller
    on its own motors, its whole weight on its foot in the sand, 10 s: over the last 5 s
    the foot moves less than 0.1 mm and the sand's force carries the weight with a
    step-to-step spread under 5 % of it. rft's reactions held only E's velocity along x and
    z before, and the foot turned: it moved 46 to 167 mm with a spread of 0.86 to 4.9 times
    the weight. The sand never gains energy: its own work (its generalized force on the
    step's displacement; the PD controller's motors do work too, so MuJoCo's energy is not
    the measure) from the window's start stays within 1e-6 J/s x max(t, 1 s). A reaction
    that brought the foot's twist to zero exactly did positive work: 6e-6 to 4e-5 J in the
    window's first second."""
    model = _hopper(foot)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    foot_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "foot_geom")
    rft = forces.term("rft", zeta=463082.2272)
    sand = Sand(model, ["foot_geom"], [rft], apply_at="centroid")
    h = model.opt.timestep
    weight = model.body_subtreemass[1] * np.linalg.norm(model.opt.gravity)
    pos, fz, work = [], [], []
    qpos = [data.qpos.copy()]

    def record(d):
        pos.append(d.geom_xpos[foot_id].copy())
        fz.append(sand.applied[0, 1])
        # The hopper's joints are slides and hinges: qpos moves with qvel, and the sand's
        # generalized force, held through the step, does this work.
        work.append(sand._generalized @ (d.qpos - qpos[0]))
        qpos[0] = d.qpos.copy()

    hold_upright(model, data, sand, mode, 10.0, record)
    last = assert_rests(pos, fz, weight, h)
    gained = np.cumsum(np.array(work)[last])
    elapsed = np.arange(1, len(gained) + 1) * h
    assert np.all(gained <= 1e-6 * np.maximum(elapsed, 1.0))
