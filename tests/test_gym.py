"""granrs.gym.SandWrapper: sand under Gymnasium's MuJoCo environments, the sand installed as
MuJoCo's passive-force callback just around each step and reset."""

from __future__ import annotations

import gc
import importlib
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import granrs
from granrs import forces

gymnasium = pytest.importorskip("gymnasium")
mujoco = pytest.importorskip("mujoco")
# Gymnasium's MuJoCo environments need imageio besides mujoco (gymnasium[mujoco]).
pytest.importorskip("gymnasium.envs.mujoco.mujoco_env")
from gymnasium.envs.mujoco.mujoco_env import MujocoEnv  # noqa: E402

from granrs.gym import FEET, INFO_KEYS, SandWrapper, make  # noqa: E402
from granrs.mujoco import Sand  # noqa: E402

# A step whose implicit solve falls back to sticking or sliding warns once (the landing of
# a robot at its own timestep); the tests check the outcome itself.
pytestmark = pytest.mark.filterwarnings("ignore::granrs.StepSizeWarning")

#: The wrapper's documented default sand, from its source (Agarwal, Goldman & Kamrin 2023):
#: xi_n for a bulk density of 1520 kg/m^3 and an internal friction of 0.4.
ZETA = granrs.space.xi_n(1520.0, 0.4)

ANT_FEET = ["left_ankle_geom", "right_ankle_geom", "third_ankle_geom", "fourth_ankle_geom"]


@pytest.fixture(autouse=True)
def _no_callback_left_behind():
    """Every test starts and ends with no passive callback installed."""
    assert mujoco.get_mjcb_passive() is None
    yield
    installed = mujoco.get_mjcb_passive()
    mujoco.set_mjcb_passive(None)
    assert installed is None


def geom_id(model, name: str) -> int:
    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)


def twin(env_id: str, sand_geoms, through=(), **kwargs):
    """The same environment with the sand put under it by hand: its geoms' contacts off and
    a Sand on its model, to install around each call."""
    env = gymnasium.make(env_id, **kwargs)
    m = env.unwrapped.model
    for g in list(sand_geoms) + list(through):
        m.geom_contype[geom_id(m, g)] = 0
        m.geom_conaffinity[geom_id(m, g)] = 0
    return env, Sand(m, list(sand_geoms), [forces.rft3d(zeta=ZETA)])


def installed(sand, call, *args, **kwargs):
    sand.install()
    try:
        return call(*args, **kwargs)
    finally:
        sand.uninstall()


def weight(model) -> float:
    return float(model.body_subtreemass[1] * np.linalg.norm(model.opt.gravity))


# --- the wrapper's step is MuJoCo's step with the sand installed ----------------------------


@pytest.mark.parametrize(
    ("env_id", "feet", "through", "kwargs"),
    [
        ("Hopper-v5", ["foot_geom"], ["leg_geom"], {}),
        # No reset noise: the Ant lands level (see the noisy landing below).
        ("Ant-v5", ANT_FEET, [], {"reset_noise_scale": 0.0}),
    ],
)
def test_step_is_the_env_s_step_with_the_callback_installed(env_id, feet, through, kwargs):
    # Three copies of one environment from one seed: the wrapper's; one stepped by its own
    # step() with the sand installed by hand; and one whose model is stepped by hand,
    # mj_step(nstep=frame_skip) with the sand installed, as Gymnasium's do_simulation does.
    env = SandWrapper(gymnasium.make(env_id, **kwargs))
    by_hand, sand_b = twin(env_id, feet, through, **kwargs)
    raw, sand_c = twin(env_id, feet, through, **kwargs)
    m_c, d_c = raw.unwrapped.model, raw.unwrapped.data
    assert env.geoms == tuple(feet) and env.pass_through == tuple(through)
    for g in feet + through:
        m = env.unwrapped.model
        assert m.geom_contype[geom_id(m, g)] == 0 and m.geom_conaffinity[geom_id(m, g)] == 0

    obs, info = env.reset(seed=3)
    obs_b, info_b = installed(sand_b, by_hand.reset, seed=3)
    installed(sand_c, raw.reset, seed=3)
    assert np.max(np.abs(obs - obs_b)) <= 1e-12
    assert set(info) == set(info_b) | {"sand"}
    assert set(info["sand"]) == set(INFO_KEYS)

    n = len(feet)
    action = np.zeros(env.action_space.shape)
    frame_skip = raw.unwrapped.frame_skip
    for _ in range(100):
        obs, reward, terminated, truncated, info = env.step(action)
        obs_b, reward_b, terminated_b, truncated_b, info_b = installed(sand_b, by_hand.step, action)
        d_c.ctrl[:] = action
        installed(sand_c, mujoco.mj_step, m_c, d_c, frame_skip)
        mujoco.mj_rnePostConstraint(m_c, d_c)
        d_a = env.unwrapped.data
        assert np.all(np.isfinite(obs))
        assert np.max(np.abs(obs - obs_b)) <= 1e-12
        assert reward == reward_b
        assert (terminated, truncated) == (terminated_b, truncated_b)
        assert np.max(np.abs(d_a.qpos - d_c.qpos)) <= 1e-12
        assert np.max(np.abs(d_a.qvel - d_c.qvel)) <= 1e-12
        assert np.max(np.abs(obs - raw.unwrapped._get_obs())) <= 1e-12
        assert set(info) == set(info_b) | {"sand"}
        for key in info_b:
            assert np.all(info[key] == info_b[key])
        sand = info["sand"]
        assert sand["geoms"] == tuple(feet)
        assert sand["force"].shape == (n, 3) and sand["moment"].shape == (n, 3)
        assert sand["depth"].shape == (n,)
        assert isinstance(sand["fallbacks"], int) and sand["fallbacks"] >= 0
        assert np.array_equal(sand["force"], sand_b.applied[:, :3])
        assert np.array_equal(sand["moment"], sand_b.applied[:, 3:])
        assert np.array_equal(sand["depth"], sand_b.output[:, 0])
        assert mujoco.get_mjcb_passive() is None
    # The sand holds the feet up: some are in it, and the robot does not fall through.
    assert np.any(sand["depth"] > 0.0)
    assert sand["force"][:, 2].sum() > 0.0
    assert env.unwrapped.data.qpos[2 if env_id == "Ant-v5" else 1] > 0.0


def test_a_reset_into_the_sand_is_made_with_the_sand_installed():
    # The hopper reset 7 cm lower, its foot 3 cm into the sand, after an episode: the
    # reset's mj_forward meets the sand (info["sand"] holds its force at the reset state),
    # and the next episode goes on as with the sand installed by hand around reset and step.
    env = SandWrapper(gymnasium.make("Hopper-v5"))
    by_hand, sand_b = twin("Hopper-v5", ["foot_geom"], ["leg_geom"])
    env.reset(seed=0)
    installed(sand_b, by_hand.reset, seed=0)
    for _ in range(30):
        env.step(np.zeros(3))
        installed(sand_b, by_hand.step, np.zeros(3))
    for e in (env, by_hand):
        e.unwrapped.init_qpos[1] -= 0.07
    obs, info = env.reset(seed=1)
    obs_b, _ = installed(sand_b, by_hand.reset, seed=1)
    assert np.max(np.abs(obs - obs_b)) <= 1e-12
    assert 0.02 < info["sand"]["depth"][0] < 0.04
    assert np.linalg.norm(info["sand"]["force"][0]) > 0.0
    assert np.array_equal(info["sand"]["force"], sand_b.applied[:, :3])
    for _ in range(20):
        obs, *_ = env.step(np.zeros(3))
        obs_b, *_ = installed(sand_b, by_hand.step, np.zeros(3))
        assert np.max(np.abs(obs - obs_b)) <= 1e-12


def test_without_the_callback_the_feet_fall_through():
    # The same steps with the feet's contacts off and no sand: the hopper sinks (so the
    # wrapper's sand is what holds it up above).
    env = SandWrapper(gymnasium.make("Hopper-v5"))
    bare = gymnasium.make("Hopper-v5")
    m = bare.unwrapped.model
    for g in ("foot_geom", "leg_geom"):
        m.geom_contype[geom_id(m, g)] = m.geom_conaffinity[geom_id(m, g)] = 0
    env.reset(seed=0)
    bare.reset(seed=0)
    for _ in range(60):
        _, _, _, _, info = env.step(np.zeros(3))
        bare.step(np.zeros(3))
    foot = geom_id(m, "foot_geom")
    # The foot capsule's radius is 0.06 m: its lowest point is below the surface by depth.
    low = env.unwrapped.data.geom_xpos[foot][2] - 0.06
    assert abs(-low - info["sand"]["depth"][0]) < 0.01
    assert 0.0 < info["sand"]["depth"][0] < 0.2
    assert bare.unwrapped.data.geom_xpos[foot][2] < low - 0.1


def test_ant_settles_on_its_feet_and_the_sand_carries_its_weight():
    # No reset noise: the Ant lands level (see the noisy landing below). 3 s at its own RK4
    # 0.01 s: it stands on its four feet in the sand, nothing else touching the floor.
    env = make("Ant-v5", reset_noise_scale=0.0)
    env.reset(seed=0)
    model, data = env.unwrapped.model, env.unwrapped.data
    for _ in range(60):
        obs, _, _, _, info = env.step(np.zeros(8))
    assert np.all(np.isfinite(obs))
    sand = info["sand"]
    assert np.all(sand["depth"] > 0.0)
    assert abs(sand["force"][:, 2].sum() / weight(model) - 1.0) < 0.1
    assert data.ncon == 0
    # Level: the torso's z axis within 5 degrees of vertical.
    assert data.xmat[1][8] > math.cos(math.radians(5.0))


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_ant_from_a_noisy_reset_is_not_thrown_up(seed):
    # From Gymnasium's default reset noise the Ant lands unevenly; the sand must not throw
    # it up (a fallback that capped one foot and left the others' wrenches as solved for it
    # once threw seed 0's torso from 0.66 m to 1.07 m).
    env = make("Ant-v5")
    env.reset(seed=seed)
    start = env.unwrapped.data.qpos[2]
    top = start
    for _ in range(40):
        env.step(np.zeros(8))
        top = max(top, env.unwrapped.data.qpos[2])
    assert top <= start + 0.05


# --- every known environment ------------------------------------------------------------


@pytest.mark.filterwarnings("ignore:.*is out of date.*:DeprecationWarning")
@pytest.mark.parametrize(
    "env_id",
    [
        "Hopper-v4",
        "Walker2d-v5",
        "Walker2d-v4",
        "Ant-v4",
        "HalfCheetah-v5",
        "Humanoid-v5",
        "Humanoid-v4",
        "HumanoidStandup-v5",
    ],
)
def test_known_environments_have_their_feet_in_the_sand(env_id, tmp_path, monkeypatch):
    # MuJoCo logs the deprecated attributes of some models (HalfCheetah's settotalmass) to
    # MUJOCO_LOG.TXT in the working directory.
    monkeypatch.chdir(tmp_path)
    env = SandWrapper(gymnasium.make(env_id))
    family = env_id.split("-")[0]
    assert env.geoms == FEET[family].geoms
    model = env.unwrapped.model
    for g in env.geoms + env.pass_through:
        assert model.geom_contype[geom_id(model, g)] == 0
    # The other geoms keep their contacts.
    floor = geom_id(model, "floor")
    assert model.geom_conaffinity[floor] == 1
    _, info = env.reset(seed=0)
    for _ in range(10):
        obs, _, _, _, info = env.step(env.action_space.sample() * 0.0)
    assert np.all(np.isfinite(obs))
    assert info["sand"]["force"].shape == (len(env.geoms), 3)


def test_humanoid_feet_and_shins():
    # The shins end inside the foot spheres, 7.6 cm above their bottoms: they pass through
    # the sand (the humanoid's feet sink 8.6 cm under its weight on both).
    env = SandWrapper(gymnasium.make("Humanoid-v5"))
    assert env.geoms == ("right_foot", "left_foot")
    assert env.pass_through == ("right_shin1", "left_shin1")
    model = env.unwrapped.model
    assert [mujoco.mjtGeom(model.geom_type[geom_id(model, g)]).name for g in env.geoms] == [
        "mjGEOM_SPHERE",
        "mjGEOM_SPHERE",
    ]


# --- a user's own MuJoCo environment ---------------------------------------------------------

BALL_XML = """<mujoco>
  <option timestep="0.002" integrator="RK4"/>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="block" pos="0 0 0.2">
      <freejoint/>
      <geom name="block" type="box" size="0.1 0.1 0.05" mass="2.0"/>
      <geom name="ball" type="sphere" pos="0 0 -0.1" size="0.05" mass="0.5"/>
    </body>
  </worldbody>
</mujoco>"""


class BallEnv(MujocoEnv):
    """A block on a ball: a user's MujocoEnv, no actuators."""

    metadata = {"render_modes": ["human", "rgb_array", "depth_array"], "render_fps": 100}  # noqa: RUF012

    def __init__(self, path: str) -> None:
        space = gymnasium.spaces.Box(-np.inf, np.inf, shape=(13,), dtype=np.float64)
        super().__init__(path, 5, observation_space=space)

    def step(self, action):
        self.do_simulation(action, self.frame_skip)
        return self._get_obs(), 0.0, False, False, {"mine": 1}

    def reset_model(self):
        self.set_state(self.init_qpos, self.init_qvel)
        return self._get_obs()

    def _get_obs(self):
        return np.concatenate([self.data.qpos, self.data.qvel])


@pytest.fixture
def ball_env(tmp_path):
    path = tmp_path / "ball.xml"
    path.write_text(BALL_XML)
    return BallEnv(str(path))


def test_a_user_s_own_mujoco_env(ball_env):
    env = SandWrapper(ball_env, geoms=["ball"], surface=0.02)
    model = env.unwrapped.model
    assert model.geom_contype[geom_id(model, "ball")] == 0
    assert model.geom_contype[geom_id(model, "block")] == 1
    env.reset(seed=0)
    for _ in range(150):  # 1.5 s
        obs, reward, _, _, info = env.step(np.zeros(0))
    assert reward == 0.0 and info["mine"] == 1
    # At rest on the ball in the sand: the sand carries the block's 2.5 kg; the block itself
    # is above the floor (its bottom 0.05 m above the ball's).
    assert abs(info["sand"]["force"][0, 2] / (2.5 * 9.81) - 1.0) < 0.02
    depth = info["sand"]["depth"][0]
    assert 0.0 < depth < 0.1
    low = env.unwrapped.data.geom_xpos[geom_id(model, "ball")][2] - 0.05
    assert abs(0.02 - low - depth) < 1e-6
    assert abs(obs[9]) < 1e-3  # at rest


def test_a_user_s_env_without_geoms_names_what_to_pass(ball_env):
    with pytest.raises(granrs.UnknownNameError) as caught:
        SandWrapper(ball_env)
    assert caught.value.field == "geoms"
    assert "geoms=" in str(caught.value) and "ball" in str(caught.value)


# --- the global callback ----------------------------------------------------------------


def test_the_callback_is_back_after_each_call_and_models_compile_between_steps():
    env = SandWrapper(gymnasium.make("Hopper-v5"))
    env.reset(seed=0)
    env.step(np.zeros(3))
    assert mujoco.get_mjcb_passive() is None
    other = gymnasium.make("Walker2d-v5")  # compiles its model
    other.reset(seed=0)
    env.step(np.zeros(3))
    assert mujoco.get_mjcb_passive() is None
    # Also when the step raises (a wrong action's shape).
    with pytest.raises(ValueError, match="Action dimension mismatch"):
        env.step(np.zeros(5))
    assert mujoco.get_mjcb_passive() is None


def test_a_callback_installed_before_is_called_and_restored():
    env = SandWrapper(gymnasium.make("Hopper-v5"))
    env.reset(seed=0)
    calls = []

    def mine(m, d):
        calls.append(d.time)

    mujoco.set_mjcb_passive(mine)
    try:
        env.step(np.zeros(3))
        assert mujoco.get_mjcb_passive() is mine
    finally:
        mujoco.set_mjcb_passive(None)
    # Hopper: 4 MuJoCo steps of RK4, each four evaluations.
    assert len(calls) == 16


# --- vector environments ------------------------------------------------------------------


def test_sync_vector_env_of_two_ants():
    vec = gymnasium.vector.SyncVectorEnv(
        [lambda: SandWrapper(gymnasium.make("Ant-v5")) for _ in range(2)]
    )
    single = [SandWrapper(gymnasium.make("Ant-v5")) for _ in range(2)]
    obs, info = vec.reset(seed=[4, 5])
    for i, env in enumerate(single):
        env.reset(seed=4 + i)
    assert vec.envs[0].sand is not vec.envs[1].sand
    assert vec.envs[0].sand.model is vec.envs[0].unwrapped.model
    for _ in range(20):
        obs, _, _, _, info = vec.step(np.zeros((2, 8)))
        for i, env in enumerate(single):
            obs_i, *_ = env.step(np.zeros(8))
            # Each sub-environment meets its own sand only.
            assert np.max(np.abs(obs[i] - obs_i)) <= 1e-12
    assert info["sand"]["force"].shape == (2, 4, 3)
    assert info["sand"]["moment"].shape == (2, 4, 3)
    assert info["sand"]["depth"].shape == (2, 4)
    assert tuple(info["sand"]["geoms"][1]) == tuple(ANT_FEET)
    assert np.all(np.isfinite(obs))


def _standing_ant():
    return SandWrapper(gymnasium.make("Ant-v5", reset_noise_scale=0.0))


def test_async_vector_env_one_sand_per_process():
    vec = gymnasium.vector.AsyncVectorEnv([_standing_ant] * 2)
    try:
        vec.reset(seed=0)
        for _ in range(40):
            obs, _, _, _, info = vec.step(np.zeros((2, 8)))
    finally:
        vec.close()
    ant = gymnasium.make("Ant-v5").unwrapped.model
    assert np.all(np.isfinite(obs))
    assert np.all(info["sand"]["depth"] > 0.0)
    carried = info["sand"]["force"][:, :, 2].sum(axis=1) / weight(ant)
    assert np.all(np.abs(carried - 1.0) < 0.1)


@pytest.mark.skipif(not hasattr(gymnasium, "make_vec"), reason="gymnasium has no make_vec")
def test_make_vec_with_the_wrapper():
    vec = gymnasium.make_vec(
        "Hopper-v5", num_envs=2, vectorization_mode="sync", wrappers=[SandWrapper]
    )
    vec.reset(seed=0)
    for _ in range(30):
        obs, _, _, _, info = vec.step(np.zeros((2, 3)))
    assert obs.shape == (2, 11) and np.all(np.isfinite(obs))
    assert info["sand"]["depth"].shape == (2, 1)
    assert np.all(info["sand"]["depth"] > 0.0)


# --- make, spec ---------------------------------------------------------------------------


def test_make_passes_its_arguments_on():
    env = make(
        "Hopper-v5",
        max_episode_steps=5,
        surface=0.01,
        forces=[forces.rft3d(zeta=2 * ZETA)],
        sand_kwargs={"quadrature": 3},
    )
    assert isinstance(env, SandWrapper)
    assert env.sand.surface == 0.01
    env.reset(seed=0)
    truncated = [env.step(np.zeros(3))[3] for _ in range(5)]
    assert truncated == [False] * 4 + [True]
    # The wrapper is in the environment's spec: Gymnasium can make it again.
    again = gymnasium.make(env.spec)
    assert isinstance(again, SandWrapper)
    assert again.sand.surface == 0.01 and again.sand is not env.sand


# --- bad input ------------------------------------------------------------------------------


def _hopper():
    return gymnasium.make("Hopper-v5")


BAD = {
    "not an env": (lambda: object(), {}, granrs.InvalidParameterError, "env"),
    "a vector env": (
        lambda: gymnasium.vector.SyncVectorEnv([_hopper]),
        {},
        granrs.InvalidParameterError,
        "env",
    ),
    "not mujoco": (lambda: gymnasium.make("CartPole-v1"), {}, granrs.InvalidParameterError, "env"),
    "twice": (lambda: SandWrapper(_hopper()), {}, granrs.InvalidParameterError, "env"),
    "unknown env": (
        lambda: gymnasium.make("InvertedPendulum-v5"),
        {},
        granrs.UnknownNameError,
        "geoms",
    ),
    "geoms a str": (_hopper, {"geoms": "foot_geom"}, granrs.InvalidParameterError, "geoms"),
    "geoms empty": (_hopper, {"geoms": []}, granrs.InvalidParameterError, "geoms"),
    "geom not a str": (_hopper, {"geoms": [3]}, granrs.InvalidParameterError, "geoms[0]"),
    "unknown geom": (_hopper, {"geoms": ["nope"]}, granrs.UnknownNameError, "geoms[0]"),
    "geom twice": (
        _hopper,
        {"geoms": ["foot_geom", "foot_geom"]},
        granrs.InvalidSceneError,
        "geoms",
    ),
    "a plane": (_hopper, {"geoms": ["floor"]}, granrs.InvalidSceneError, "geoms[0]"),
    "forces a str": (_hopper, {"forces": "rft3d"}, granrs.InvalidParameterError, "forces"),
    "no forces": (_hopper, {"forces": []}, granrs.InvalidSceneError, "forces"),
    "planar term": (_hopper, {"forces": [forces.drag()]}, granrs.InvalidSceneError, "forces[0]"),
    "gravity": (
        _hopper,
        {"forces": [forces.gravity(), forces.rft3d(zeta=ZETA)]},
        granrs.InvalidSceneError,
        "forces.gravity",
    ),
    "surface nan": (_hopper, {"surface": math.nan}, granrs.InvalidParameterError, "surface"),
    "surface a str": (_hopper, {"surface": "low"}, granrs.InvalidParameterError, "surface"),
    "unknown pass_through": (
        _hopper,
        {"pass_through": ["nope"]},
        granrs.UnknownNameError,
        "pass_through[0]",
    ),
    "pass_through a sand geom": (
        _hopper,
        {"pass_through": ["foot_geom"]},
        granrs.InvalidSceneError,
        "pass_through[0]",
    ),
    "pass_through a str": (
        _hopper,
        {"pass_through": "leg_geom"},
        granrs.InvalidParameterError,
        "pass_through",
    ),
    "unknown argument": (_hopper, {"frobnicate": 1}, granrs.UnknownNameError, "frobnicate"),
    "planar Sand": (_hopper, {"space": False}, granrs.UnknownNameError, "space"),
    "rho_g": (_hopper, {"rho_g": -1.0}, granrs.InvalidParameterError, "rho_g"),
    "rest_speed": (_hopper, {"rest_speed": 0.0}, granrs.InvalidParameterError, "rest_speed"),
    "quadrature": (_hopper, {"quadrature": True}, granrs.InvalidParameterError, "quadrature"),
    "patch": (_hopper, {"patch": (1.0, 0.0)}, granrs.InvalidParameterError, "patch"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_is_a_typed_error_naming_the_field(case):
    build, kwargs, error, field = BAD[case]
    env = build()
    inner = getattr(env, "unwrapped", None)
    model = getattr(inner, "model", None)
    before = None if model is None else model.geom_contype.copy()
    with pytest.raises(error) as caught:
        SandWrapper(env, **kwargs)
    assert type(caught.value) is error
    assert caught.value.field == field
    assert isinstance(caught.value, ValueError)
    # Nothing of the model was changed (by this wrapper: a first one, good, had).
    if before is not None:
        assert np.array_equal(model.geom_contype, before)


def test_one_sand_per_model():
    base = _hopper()
    first = SandWrapper(base)
    with pytest.raises(granrs.InvalidParameterError) as caught:
        SandWrapper(base)
    assert caught.value.field == "env"
    del first
    gc.collect()
    assert SandWrapper(base).geoms == ("foot_geom",)


def test_make_checks_sand_kwargs_before_making_the_env():
    with pytest.raises(granrs.UnknownNameError) as caught:
        make("Hopper-v5", sand_kwargs={"frobnicate": 1})
    assert caught.value.field == "sand_kwargs.frobnicate"
    with pytest.raises(granrs.InvalidParameterError) as caught:
        make("Hopper-v5", sand_kwargs=[("quadrature", 3)])
    assert caught.value.field == "sand_kwargs"
    with pytest.raises(granrs.UnknownNameError) as caught:
        make("Hopper-v5", geoms=["nope"])
    assert caught.value.field == "geoms[0]"


def test_a_custom_model_without_the_known_feet_names_geoms(tmp_path):
    # Hopper-v5 with its own xml_file whose foot is renamed: the default geoms are not there.
    source = Path(gymnasium.__file__).parent / "envs" / "mujoco" / "assets" / "hopper.xml"
    xml = source.read_text().replace('name="foot_geom"', 'name="sole"')
    path = tmp_path / "hopper.xml"
    path.write_text(xml)
    env = gymnasium.make("Hopper-v5", xml_file=str(path))
    with pytest.raises(granrs.UnknownNameError) as caught:
        SandWrapper(env)
    assert caught.value.field == "geoms" and "foot_geom" in str(caught.value)
    wrapped = SandWrapper(env, geoms=["sole"], pass_through=["leg_geom"])
    assert wrapped.geoms == ("sole",)


# --- without gymnasium ------------------------------------------------------------------------


def test_import_without_gymnasium_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "gymnasium", None)
    monkeypatch.delitem(sys.modules, "granrs.gym")
    with pytest.raises(ImportError, match="pip install gymnasium"):
        importlib.import_module("granrs.gym")


def test_hopper_model_swaps_the_foot_and_refuses_an_unknown_one() -> None:
    """granrs.gym.hopper_model: Gymnasium's hopper with no contacts, its foot the shipped
    capsule or a box of the same length; any other foot is a typed error naming it."""
    from granrs.gym import hopper_model

    capsule, box = hopper_model(), hopper_model("box")
    gid = mujoco.mj_name2id(capsule, mujoco.mjtObj.mjOBJ_GEOM, "foot_geom")
    assert capsule.geom_type[gid] == mujoco.mjtGeom.mjGEOM_CAPSULE
    assert box.geom_type[gid] == mujoco.mjtGeom.mjGEOM_BOX
    assert list(box.geom_size[gid]) == pytest.approx([0.195, 0.05, 0.03])
    assert not capsule.geom_contype.any() and not capsule.geom_conaffinity.any()
    with pytest.raises(granrs.InvalidParameterError, match="foot"):
        hopper_model("sphere")
