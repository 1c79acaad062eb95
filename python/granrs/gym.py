"""Sand under Gymnasium's MuJoCo environments: :class:`SandWrapper` puts granrs's sand in
three dimensions (:class:`granrs.mujoco.Sand`) under the feet of Hopper, Walker2d, Ant,
HalfCheetah, Humanoid and HumanoidStandup (v4 and v5), or under the named geoms of any
environment built on Gymnasium's ``MujocoEnv``::

    import gymnasium
    from granrs.gym import SandWrapper

    env = SandWrapper(gymnasium.make("Ant-v5"))
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    info["sand"]["force"]        # each foot's force from the sand [N], world frame

``pip install gymnasium`` (its MuJoCo environments also need ``imageio``: ``pip install
'gymnasium[mujoco]'``, or ``pip install 'granrs[gym]'`` for both). See ``docs/mujoco.md``,
"With Gymnasium".
"""

from __future__ import annotations

import contextlib
import weakref
from collections.abc import Iterator, Sequence
from typing import Any, NamedTuple, SupportsFloat

try:
    import gymnasium
except ImportError as exc:  # pragma: no cover - exercised in a venv without gymnasium
    raise ImportError(
        "granrs.gym needs the `gymnasium` package: pip install gymnasium (its MuJoCo "
        "environments also need imageio: pip install 'gymnasium[mujoco]'; or pip install "
        "'granrs[gym]' for both)"
    ) from exc

try:
    import mujoco
except ImportError as exc:  # pragma: no cover - exercised in a venv without mujoco
    raise ImportError(
        "granrs.gym needs the `mujoco` package: pip install 'granrs[gym]' "
        "(or pip install 'gymnasium[mujoco]')"
    ) from exc

from . import forces as _forces
from . import space as _space
from .errors import InvalidParameterError, InvalidSceneError, UnknownNameError
from .forces import Term
from .mujoco import Sand

__all__ = [
    "FEET",
    "INFO_KEYS",
    "SAND_ARGUMENTS",
    "Feet",
    "SandWrapper",
    "default_forces",
    "hopper_model",
    "make",
]


class Feet(NamedTuple):
    """The geoms of one of Gymnasium's environments that :class:`SandWrapper` takes by
    default."""

    #: The geoms in the sand (they stop colliding with the floor).
    geoms: tuple[str, ...]
    #: Geoms whose lower end lies inside a foot (a leg's end in the hopper's foot, a shin's
    #: in the humanoid's): they stop colliding with the floor too, and feel no sand, since
    #: what of them is in the sand is inside the foot. Without this, a foot sunk a few
    #: centimetres would stand on the rigid floor through its leg.
    pass_through: tuple[str, ...] = ()


#: The default geoms of Gymnasium's MuJoCo environments, by the name of the environment's
#: class less ``Env`` (``HopperEnv``: ``"Hopper"``; v4 and v5 name their geoms alike). The
#: hopper's and walker's lower legs reach to 2 cm above the bottoms of their feet, the
#: humanoid's shins to 7.6 cm above the bottoms of its foot spheres: under their weight the
#: feet sink 4.5 cm (the hopper) and 8.6 cm (a humanoid on both feet), so those legs and
#: shins pass through the sand (``Feet.pass_through``).
FEET: dict[str, Feet] = {
    "Hopper": Feet(("foot_geom",), ("leg_geom",)),
    "Walker2d": Feet(("foot_geom", "foot_left_geom"), ("leg_geom", "leg_left_geom")),
    "Ant": Feet(("left_ankle_geom", "right_ankle_geom", "third_ankle_geom", "fourth_ankle_geom")),
    "HalfCheetah": Feet(("bfoot", "ffoot")),
    "Humanoid": Feet(("right_foot", "left_foot"), ("right_shin1", "left_shin1")),
    "HumanoidStandup": Feet(("right_foot", "left_foot"), ("right_shin1", "left_shin1")),
}

#: The arguments of :class:`granrs.mujoco.Sand` that :class:`SandWrapper` passes on (the
#: wrapper's sand is always in three dimensions: the planar ones do not apply).
SAND_ARGUMENTS = ("rho_g", "patch", "rest_speed", "quadrature")

#: The keys of ``info["sand"]`` (see :class:`SandWrapper`).
INFO_KEYS = ("geoms", "force", "moment", "depth", "fallbacks")

#: The sand of :func:`default_forces`: the sensitivity of 3D-RFT's normal stress to depth
#: [N/m^3] from a bulk density of 1520 kg/m^3 and an internal friction of 0.4
#: (:func:`granrs.space.xi_n`).
_DENSITY, _FRICTION = 1520.0, 0.4

#: The SandWrapper on each model (one sand per environment).
_WRAPPED: weakref.WeakKeyDictionary[Any, weakref.ref[SandWrapper]] = weakref.WeakKeyDictionary()


def default_forces() -> list[Term]:
    """The wrapper's sand when ``forces`` is not given: ``[granrs.forces.rft3d(zeta=
    granrs.space.xi_n(1520.0, 0.4))]``, 3D-RFT scaled from a bulk density of 1520 kg/m^3
    and an internal friction coefficient of 0.4 (about 4.6e5 N/m^3), after Agarwal, Goldman
    & Kamrin (2023)."""
    return [_forces.rft3d(zeta=_space.xi_n(_DENSITY, _FRICTION))]


#: The hopper's feet :func:`hopper_model` builds: Gymnasium's own capsule, or a box of the
#: same length (0.39 x 0.1 x 0.06 m).
HOPPER_FEET = ("capsule", "box")


def hopper_model(foot: str = "capsule") -> mujoco.MjModel:
    """Gymnasium's own hopper (its ``hopper.xml``: RK4 at 2 ms) with no contacts (its floor
    would hold the foot up: the sand is to), its foot a capsule lying side-on, as shipped,
    or a box of the same length (``foot="box"``): the model of the docs' rest checks.

    Args:
        foot: ``"capsule"`` or ``"box"``.

    Returns:
        A new ``mujoco.MjModel``; the foot geom is ``"foot_geom"``.

    Raises:
        InvalidParameterError: an unknown ``foot``.
    """
    if foot not in HOPPER_FEET:
        raise InvalidParameterError(f"foot: {foot!r} is not one of {', '.join(HOPPER_FEET)}")
    import os

    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets/hopper.xml")
    with open(path, encoding="utf-8") as f:
        xml = f.read()
    if foot == "box":
        capsule = 'quat="0.70710678118654757 0 -0.70710678118654746 0" name="foot_geom" '
        box = xml.replace(capsule, 'name="foot_geom" ').replace(
            'name="foot_geom" size="0.06 0.195" type="capsule"',
            'name="foot_geom" size="0.195 0.05 0.03" type="box"',
        )
        if 'type="box"' not in box:  # pragma: no cover - a Gymnasium that changed its hopper
            raise InvalidSceneError("foot: this Gymnasium's hopper.xml has no capsule foot to swap")
        xml = box
    model = mujoco.MjModel.from_xml_string(xml)
    model.geom_contype[:] = 0
    model.geom_conaffinity[:] = 0
    return model


def _known_feet(unwrapped: Any) -> tuple[str, Feet] | None:
    """The entry of :data:`FEET` for a Gymnasium MuJoCo environment (or a subclass of one)."""
    for cls in type(unwrapped).__mro__:
        if not cls.__module__.startswith("gymnasium.envs.mujoco."):
            continue
        name = cls.__name__.removesuffix("Env")
        if name in FEET:
            return name, FEET[name]
    return None


def _geom_names(model: Any) -> list[str]:
    names = (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, i) for i in range(model.ngeom))
    return [n for n in names if n]


def _names(value: Any, field: str) -> list[str]:
    """``value`` as a list of geom names, or a typed error naming ``field``."""
    if isinstance(value, str) or not isinstance(value, Sequence):
        raise InvalidParameterError(
            f"`{field}` must be a list of geom names, got {value!r}", field=field
        )
    for i, name in enumerate(value):
        if not isinstance(name, str):
            raise InvalidParameterError(
                f"`{field}[{i}]` must be a geom name (a str), got {name!r}", field=f"{field}[{i}]"
            )
    return list(value)


class SandWrapper(gymnasium.Wrapper[Any, Any, Any, Any], gymnasium.utils.RecordConstructorArgs):
    """Sand under a Gymnasium MuJoCo environment: a ``gymnasium.Wrapper`` that puts
    :class:`granrs.mujoco.Sand` in three dimensions under the named geoms of ``env``'s
    model, at every MuJoCo step.

    The environment is any of Gymnasium's MuJoCo environments, v4 or v5 (:data:`FEET` has
    the feet of Hopper, Walker2d, Ant, HalfCheetah, Humanoid and HumanoidStandup), or a
    user's own: anything whose ``env.unwrapped`` has a MuJoCo ``model`` and ``data``
    (Gymnasium's ``MujocoEnv``). The sand geoms, and the ``pass_through`` geoms, stop
    colliding with anything (their ``contype`` and ``conaffinity`` are set to 0 on the
    environment's model, once, here): the feet meet the sand instead of the floor; every
    other geom keeps MuJoCo's own contacts, the floor among them, at the floor's own height
    (the sand's ``surface`` defaults to 0, the height of the floors of Gymnasium's
    environments).

    The sand acts as MuJoCo's passive-force callback (:meth:`granrs.mujoco.Sand.install`),
    installed just around each :meth:`step` and :meth:`reset` and uninstalled after them
    (also when they raise): the environment's ``mj_step(model, data, nstep=frame_skip)``
    then meets the sand at each of its inner steps (and at each RK4 stage), exactly as a
    loop over ``mujoco.mj_step`` with the Sand installed would, and the callback that was
    installed before (usually none) is back after each call, so that other environments can
    compile their models between steps. Each wrapper has its own Sand on its own model: the
    sub-environments of a vector environment (``gymnasium.vector.SyncVectorEnv``,
    ``gymnasium.make_vec(..., wrappers=[SandWrapper])``, or ``AsyncVectorEnv``, one process
    each) each have their own.

    :meth:`step` returns the environment's own observation, reward, ``terminated`` and
    ``truncated``, unchanged (an observation that holds ``cfrc_ext``, as Ant's does, has no
    sand in it: MuJoCo's ``cfrc_ext`` holds the contacts' forces); its ``info``, and that of
    :meth:`reset`, carry ``info["sand"]``, a dict (:data:`INFO_KEYS`):

    - ``"geoms"``: the sand geoms' names, a tuple of n;
    - ``"force"``: each geom's force from the sand [N], world frame, n x 3;
    - ``"moment"``: its moment [N m] about the centre of the geom's shape, world frame,
      n x 3;
    - ``"depth"``: the depth of each geom's lowest point below the surface [m] (0 out of
      the sand), n;
    - ``"fallbacks"``: how many of the call's MuJoCo evaluations fell back from the
      implicit solve to sticking or sliding (the increase of
      ``Sand.fallbacks``; the first warns with
      :class:`granrs.StepSizeWarning`).

    ``force``, ``moment`` and ``depth`` are those of the call's last MuJoCo step (after
    :meth:`reset`, at the reset state), copies; the Sand itself is the wrapper's ``sand`` (its
    ``output`` has every column of :data:`granrs.mujoco.SPACE_GEOM_OUTPUTS`).

    Args:
        env: the environment (a ``gymnasium.Env`` on MuJoCo; one Sand per environment: an
            environment already under a SandWrapper is an error).
        geoms: names of the geoms in the sand; ``None`` (default): the feet of a known
            environment (:data:`FEET`), an error naming ``geoms`` for any other.
        forces: the sand's terms in space (``granrs.forces.rft3d``, ``rft3d_inertial``,
            ``poncelet``); ``None`` (default): :func:`default_forces`, 3D-RFT with
            ``zeta = granrs.space.xi_n(1520.0, 0.4)``, the scale from a bulk density of
            1520 kg/m^3 and an internal friction coefficient of 0.4 (Agarwal, Goldman &
            Kamrin 2023).
        surface: height z of the sand's surface [m].
        pass_through: geoms that stop colliding too but feel no sand (a leg whose end lies
            inside its foot); ``None`` (default): those of :data:`FEET` when ``geoms`` is
            ``None``, else none.
        **sand_kwargs: more arguments of :class:`granrs.mujoco.Sand`: ``rho_g``,
            ``patch``, ``rest_speed``, ``quadrature`` (:data:`SAND_ARGUMENTS`).

    Every argument is checked here, before the first step and before the model is changed;
    each error is a :class:`granrs.GranrsError` (a ``ValueError``) whose ``field`` names
    the argument (``env``, ``geoms``, ``geoms[i]``, ``forces``, ``surface``, ...).
    """

    def __init__(
        self,
        env: gymnasium.Env[Any, Any],
        geoms: Sequence[str] | None = None,
        forces: Sequence[Term] | None = None,
        surface: float = 0.0,
        pass_through: Sequence[str] | None = None,
        **sand_kwargs: Any,
    ) -> None:
        if not isinstance(env, gymnasium.Env):
            hint = (
                ": wrap each sub-environment instead (gymnasium.make_vec(..., "
                "wrappers=[SandWrapper]) or SyncVectorEnv([lambda: SandWrapper(...)]))"
                if isinstance(env, gymnasium.vector.VectorEnv)
                else ""
            )
            raise InvalidParameterError(
                f"`env` must be a gymnasium.Env, got {type(env).__name__}{hint}", field="env"
            )
        unwrapped = env.unwrapped
        model = getattr(unwrapped, "model", None)
        data = getattr(unwrapped, "data", None)
        if not isinstance(model, mujoco.MjModel) or not isinstance(data, mujoco.MjData):
            raise InvalidParameterError(
                f"`env` must be a MuJoCo environment (its `unwrapped` with a mujoco.MjModel "
                f"`model` and a mujoco.MjData `data`, as Gymnasium's MujocoEnv); "
                f"{type(unwrapped).__name__} has none",
                field="env",
            )
        earlier = _WRAPPED.get(model)
        if earlier is not None and earlier() is not None:
            raise InvalidParameterError(
                "`env`'s model already has a SandWrapper's sand: one sand per environment",
                field="env",
            )
        for key in sand_kwargs:
            if key not in SAND_ARGUMENTS:
                raise UnknownNameError(
                    f"unknown argument `{key}` (SandWrapper passes on to Sand: "
                    f"{', '.join(SAND_ARGUMENTS)}; its sand is always in three dimensions)",
                    field=key,
                )

        known = _known_feet(unwrapped)
        if geoms is None:
            if known is None:
                listed = _geom_names(model)
                shown = ", ".join(listed[:20]) + (", ..." if len(listed) > 20 else "")
                raise UnknownNameError(
                    f"granrs.gym does not know the feet of {type(unwrapped).__name__} (it "
                    f"knows {', '.join(FEET)}): pass geoms=[...], the names of the geoms in "
                    f"the sand (the model's geoms: {shown})",
                    field="geoms",
                )
            family, feet = known
            names = list(feet.geoms)
            through = list(feet.pass_through) if pass_through is None else None
            for g in names + (through or []):
                if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, g) < 0:
                    raise UnknownNameError(
                        f"this {family} model has no geom `{g}` (its own xml_file?): pass "
                        f"geoms=[...] (and pass_through=[...]), the names of its geoms in the "
                        "sand",
                        field="geoms",
                    )
        else:
            names = _names(geoms, "geoms")
            through = None
        if through is None:
            through = [] if pass_through is None else _names(pass_through, "pass_through")
        ids = []
        for i, g in enumerate(through):
            gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, g)
            if gid < 0:
                raise UnknownNameError(
                    f"the model has no geom named `{g}`", field=f"pass_through[{i}]"
                )
            if g in names:
                raise InvalidSceneError(
                    f"geom `{g}` is both in the sand (`geoms`) and passes through it",
                    field=f"pass_through[{i}]",
                )
            ids.append(gid)
        if len(set(through)) != len(through):
            raise InvalidSceneError("`pass_through` lists a geom twice", field="pass_through")
        terms = default_forces() if forces is None else forces

        # Sand checks the rest (geom names and types, the terms, surface, ...) before the
        # model is changed.
        sand = Sand(model, names, terms, surface=surface, space=True, **sand_kwargs)

        gymnasium.utils.RecordConstructorArgs.__init__(
            self,
            geoms=geoms,
            forces=forces,
            surface=surface,
            pass_through=pass_through,
            **sand_kwargs,
        )
        gymnasium.Wrapper.__init__(self, env)
        #: The :class:`granrs.mujoco.Sand` under the environment's model.
        self.sand: Sand = sand
        #: The names of the geoms in the sand.
        self.geoms: tuple[str, ...] = tuple(sand.geoms)
        #: The names of the geoms that pass through the sand.
        self.pass_through: tuple[str, ...] = tuple(through)
        for gid in [int(i) for i in sand._ids] + ids:
            model.geom_contype[gid] = 0
            model.geom_conaffinity[gid] = 0
        _WRAPPED[model] = weakref.ref(self)

    @contextlib.contextmanager
    def _installed(self) -> Iterator[None]:
        """The Sand installed as MuJoCo's passive-force callback for the ``with`` block."""
        self.sand.install()
        try:
            yield
        finally:
            self.sand.uninstall()

    def _info(self, fallbacks_before: int) -> dict[str, Any]:
        sand = self.sand
        return {
            "geoms": self.geoms,
            "force": sand.applied[:, :3].copy(),
            "moment": sand.applied[:, 3:6].copy(),
            "depth": sand.output[:, 0].copy(),
            "fallbacks": int(sand.fallbacks - fallbacks_before),
        }

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        """Step the environment with the sand installed as MuJoCo's passive-force callback,
        uninstalled after (also when the step raises).

        Args:
            action: the environment's action.

        Returns:
            The environment's own ``(observation, reward, terminated, truncated, info)``,
            ``info`` with ``info["sand"]`` added (see :class:`SandWrapper`).
        """
        before = self.sand.fallbacks
        with self._installed():
            obs, reward, terminated, truncated, info = self.env.step(action)
        return obs, reward, terminated, truncated, {**info, "sand": self._info(before)}

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Reset the environment with the sand installed, uninstalled after: the
        ``mj_forward`` of the reset state meets the sand, as every step's MuJoCo calls do.

        Args:
            seed: the environment's seed.
            options: the environment's reset options.

        Returns:
            The environment's own ``(observation, info)``, ``info`` with ``info["sand"]``
            at the reset state added (see :class:`SandWrapper`).
        """
        before = self.sand.fallbacks
        with self._installed():
            obs, info = self.env.reset(seed=seed, options=options)
        return obs, {**info, "sand": self._info(before)}


def make(
    env_id: str | Any,
    *,
    geoms: Sequence[str] | None = None,
    forces: Sequence[Term] | None = None,
    surface: float = 0.0,
    pass_through: Sequence[str] | None = None,
    sand_kwargs: dict[str, Any] | None = None,
    **kwargs: Any,
) -> SandWrapper:
    """``SandWrapper(gymnasium.make(env_id, **kwargs), geoms, forces, surface,
    pass_through, **sand_kwargs)``: a Gymnasium environment on sand.

    Args:
        env_id: the environment's id (``"Ant-v5"``) or ``EnvSpec``.
        geoms: see :class:`SandWrapper`.
        forces: see :class:`SandWrapper`.
        surface: see :class:`SandWrapper`.
        pass_through: see :class:`SandWrapper`.
        sand_kwargs: more arguments of :class:`granrs.mujoco.Sand` (:data:`SAND_ARGUMENTS`).
        **kwargs: ``gymnasium.make``'s (``render_mode``, ``max_episode_steps``, the
            environment's own: ``frame_skip``, ``xml_file``, ...).

    Raises:
        granrs.GranrsError: a bad argument of the wrapper (the environment is then closed).
    """
    if sand_kwargs is not None and not isinstance(sand_kwargs, dict):
        raise InvalidParameterError(
            f"`sand_kwargs` must be a dict, got {type(sand_kwargs).__name__}",
            field="sand_kwargs",
        )
    for key in sand_kwargs or {}:
        if key not in SAND_ARGUMENTS:
            raise UnknownNameError(
                f"unknown argument `{key}` of Sand (allowed: {', '.join(SAND_ARGUMENTS)})",
                field=f"sand_kwargs.{key}",
            )
    env = gymnasium.make(env_id, **kwargs)
    try:
        return SandWrapper(
            env,
            geoms=geoms,
            forces=forces,
            surface=surface,
            pass_through=pass_through,
            **(sand_kwargs or {}),
        )
    except BaseException:
        env.close()
        raise
