"""Sand under a MuJoCo model: granrs's force terms on the geoms of a planar MuJoCo robot.

``pip install 'granrs[mujoco]'`` (the ``mujoco`` package from PyPI). MuJoCo has no granular
ground; :class:`Sand` gives the named capsule, cylinder and box geoms of a model that moves
in the x-z plane (the hopper and walker2d pattern: slide x, slide z and hinge y at the root)
the resistance force of granrs's terms, evaluated by the same Rust code as
:func:`granrs.simulate` (a rod geom is the free link's rod, a box the leg's sole; one call
for all geoms)::

    import mujoco
    from granrs import forces
    from granrs.mujoco import Sand

    model = mujoco.MjModel.from_xml_path("hopper.xml")
    data = mujoco.MjData(model)
    sand = Sand(model, geoms=["foot"], forces=[forces.drag(), forces.static_h(), forces.static_v()])
    for _ in range(1000):
        sand.step(data)          # before mujoco.mj_step
        mujoco.mj_step(model, data)

or ``sand.install()`` once, to run as MuJoCo's passive-force callback inside every
``mj_step`` (``sand.uninstall()`` to stop). See ``docs/mujoco.md`` for the frame, the geoms'
contact geometry, where the force is applied, the static terms at rest and the stability
limit (:class:`granrs.StepSizeWarning`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

try:
    import mujoco
except ImportError as exc:  # pragma: no cover - exercised in a venv without mujoco
    raise ImportError(
        "granrs.mujoco needs the `mujoco` package: pip install 'granrs[mujoco]' "
        "(or pip install 'mujoco>=3')"
    ) from exc

from . import _granrs, media
from .api import RK4_STABILITY_LIMIT
from .errors import InvalidParameterError, InvalidSceneError, StepSizeWarning, UnknownNameError
from .forces import Term, as_terms
from .space import DEFAULT_QUADRATURE, Capsule, Cuboid, Cylinder, Mesh, Sphere
from .space import Scene as SpaceScene

__all__ = [
    "EULER_STABILITY_LIMIT",
    "GEOM_OUTPUTS",
    "INTEGRATORS",
    "REST_SPEED",
    "SPACE_GEOM_OUTPUTS",
    "SPACE_TERMS",
    "STATICS",
    "WALKER_SAND_GEOMS",
    "Sand",
    "body_drop",
    "body_mjcf",
    "free_link_mjcf",
    "rod_drop",
    "walker_mjcf",
]

#: ``h lambda`` beyond which explicit Euler is unstable for a real, negative rate (|1 - h
#: lambda| > 1). MuJoCo's Euler, implicit and implicitfast integrators all take the sand's
#: force explicitly, as a constant through the step.
EULER_STABILITY_LIMIT = 2.0

#: The columns of ``Sand.output``, one row per geom (the core's ``GEOM_OUTPUTS``).
GEOM_OUTPUTS: tuple[str, ...] = tuple(_granrs.GEOM_OUTPUTS)

#: The columns of ``Sand.output`` in three dimensions, one row per geom: the depth of its
#: lowest point [m], its surface elements below the sand, its centre's velocity and its
#: angular velocity at the step's start, and its centre's velocity at the step's end as the
#: implicit step solved it.
SPACE_GEOM_OUTPUTS: tuple[str, ...] = tuple(_granrs.SPACE_GEOM_OUTPUTS)

#: The speed [m/s] below which, in three dimensions, the sand's rate-independent terms fade
#: to a viscous law (a foot at rest under its full resistance creeps at about this speed):
#: :class:`Sand`'s default ``rest_speed``.
REST_SPEED: float = float(_granrs.SPACE_REST_SPEED)

#: The terms that make :class:`Sand` three-dimensional (any of them listed: every geom is a
#: shape in space; ``poncelet`` acts in either, and with ``space=True`` in space).
SPACE_TERMS = ("rft3d", "rft3d_inertial")

#: How :class:`Sand` treats the static terms (those with a sticking bound: ``static_h``,
#: ``static_v``): ``"stick"`` solves each step for the reaction that brings the immersed
#: centroid's velocity to zero at the step's end, within the terms' bounds (the default);
#: ``"raw"`` applies the terms as evaluated (the thesis's plain sign, which chatters at rest).
STATICS = ("stick", "raw")

_SUPPORTED = {
    int(mujoco.mjtGeom.mjGEOM_CAPSULE): "capsule",
    int(mujoco.mjtGeom.mjGEOM_CYLINDER): "cylinder",
    int(mujoco.mjtGeom.mjGEOM_BOX): "box",
}
_PLANE_TOL = 1e-9
#: MuJoCo's geom types that are shapes in space (an ellipsoid as a subdivided icosahedron
#: scaled by its semi-axes, a mesh from the model's own vertices and faces).
_SPACE_TYPES = {
    int(mujoco.mjtGeom.mjGEOM_SPHERE): "sphere",
    int(mujoco.mjtGeom.mjGEOM_CAPSULE): "capsule",
    int(mujoco.mjtGeom.mjGEOM_CYLINDER): "cylinder",
    int(mujoco.mjtGeom.mjGEOM_BOX): "box",
    int(mujoco.mjtGeom.mjGEOM_ELLIPSOID): "ellipsoid",
    int(mujoco.mjtGeom.mjGEOM_MESH): "mesh",
}
#: Subdivisions of the icosahedron an ellipsoid geom is made of (1280 triangles).
ELLIPSOID_SUBDIVISIONS = 3


def _default(value: Any, default: float) -> bool:
    """Whether an argument is its default (an array or another type is not)."""
    try:
        return bool(value == default)
    except (TypeError, ValueError):
        return False


def _number(value: Any, name: str) -> float:
    if isinstance(value, bool | np.bool_):
        raise InvalidParameterError(f"`{name}` must be a number, got {value!r}", field=name)
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InvalidParameterError(
            f"`{name}` must be a number, got {value!r}", field=name
        ) from None
    if not math.isfinite(x):
        raise InvalidParameterError(f"`{name}` must be finite, got {x}", field=name)
    return x


class Sand:
    """granrs's sand under named geoms of a MuJoCo model: in three dimensions under the
    terms in space, or on a planar model under the planar terms.

    **In three dimensions** (any of :data:`SPACE_TERMS` listed, or ``space=True``): every
    sphere, capsule, cylinder, box, ellipsoid or mesh geom is the shape in space of
    :mod:`granrs.space` (a mesh from the model's own vertices and faces; an ellipsoid a
    subdivided icosahedron scaled by its semi-axes), its whole surface below ``surface``
    cut exactly, under ``rft3d``, ``rft3d_inertial`` and ``poncelet``; the model may move in
    any way. The sand is taken implicitly: the wrench each geom receives is the one at the
    end of MuJoCo's step, solved with the law's exact derivatives, so that a foot at rest
    holds still without chattering at the model's own timestep (see docs/mujoco.md).
    ``applied`` holds each geom's force (x, y, z) [N] and moment (x, y, z) [N m] about its
    shape's centre, world frame; ``output`` the columns :data:`SPACE_GEOM_OUTPUTS`.

    **On a planar model** (the planar terms): the named capsule, cylinder and box geoms of a
    model that moves in the x-z plane are the free link's rod and the leg's sole box, as
    below; ``applied`` holds the force (x, z) [N] and moment about y [N m] at the tip,
    ``output`` the columns :data:`GEOM_OUTPUTS`.

    Args:
        model: a ``mujoco.MjModel`` (gravity along -z).
        geoms: names of the geoms in the sand. Planar: capsule, cylinder or box geoms. A
            capsule or cylinder is the free link's rod: its tip T is the lower end of its
            axis, its diameter d_c twice its radius, its length L (also L_ref) the
            cylinder's length; a capsule's caps count (T is the bottom of the lower cap, L
            the capsule's whole length, as the thesis's round-ended rod). A box is the leg's
            sole box: f_s its length along x (also L_ref), w_s its width along y; use
            ``apply_at="centroid"`` with boxes (see docs/mujoco.md).
        forces: the medium's contact terms (``granrs.forces``): ``rft3d``,
            ``rft3d_inertial``, ``poncelet`` in three dimensions; ``drag``, ``static_h``,
            ``static_v``, ``rft``, ... on a planar model. MuJoCo applies gravity and the
            joints: a ``gravity`` or ``joint_springs`` term is an error naming it. Planar: a
            parameter is one value for every geom or a tuple with one per geom.
        surface: height z of the sand's surface [m].
        rho_g: the sand's bulk density [kg/m^3] (the thesis's 1650). The static terms use
            g = |``model.opt.gravity``|.
        apply_at: planar only: ``"tip"`` (as :func:`granrs.simulate`'s default; a box's sole
            middle) or ``"centroid"``.
        patch: the sand's extent, ``(x_min, x_max)`` or ``(x_min, x_max, y_min, y_max)``
            [m]; a geom whose tip (planar) or centre (in space) is outside feels nothing
            from the sand. Geoms not listed keep MuJoCo's own contacts.
        statics: planar only: ``"stick"`` (default) or ``"raw"``: see :data:`STATICS`.
        sign_model: planar only: ``"raw"`` (the thesis's sign) or ``"smooth"``
            (``tanh(v / smooth_eps)``).
        smooth_eps: planar only: the smooth sign's velocity scale [m/s].
        space: ``True`` for three dimensions whatever the terms, ``False`` for planar;
            ``None`` (default): three dimensions where a term of :data:`SPACE_TERMS` is
            listed.
        rest_speed: in space: below this speed [m/s] the rate-independent terms fade to a
            viscous law (:data:`REST_SPEED`). Planar, with ``statics="stick"``: a geom the
            sand holds creeps at this speed times its load over the sand's resistance, so
            that the sand never does positive work.
        quadrature: in space: Gauss-Legendre nodes per panel of a curved surface
            (:data:`granrs.space.DEFAULT_QUADRATURE`).
        medium: the granular medium (:mod:`granrs.media`): a shipped card's name, a card
            file's path or a card. Its ``rho_g`` (where ``rho_g`` is left at its default)
            and its values of the terms' parameters not given (``rft3d()`` without
            ``zeta``) are the sand's; gravity stays the model's.

    Every argument is checked here, before the first step; each error is a
    :class:`granrs.GranrsError` (a ``ValueError``) naming the geom or parameter.

    After each step, ``output`` holds each geom's evaluation, ``applied`` what it
    received, and ``h_lambda`` each geom's timestep times the sand's rate (planar: the
    drag's; in space: the largest rate an explicit step would meet, which the implicit step
    does not need).
    """

    def __init__(
        self,
        model: Any,
        geoms: Sequence[str],
        forces: Sequence[Any],
        surface: float = 0.0,
        rho_g: float = 1650.0,
        apply_at: str = "tip",
        patch: tuple[float, float] = (-math.inf, math.inf),
        statics: str = "stick",
        sign_model: str = "raw",
        smooth_eps: float = 1e-3,
        space: bool | None = None,
        rest_speed: float = REST_SPEED,
        quadrature: int = DEFAULT_QUADRATURE,
        medium: Any = None,
    ) -> None:
        if not isinstance(model, mujoco.MjModel):
            raise InvalidParameterError(
                f"`model` must be a mujoco.MjModel, got {type(model).__name__}", field="model"
            )
        self.model = model
        if isinstance(geoms, str) or not isinstance(geoms, Sequence) or len(geoms) == 0:
            raise InvalidParameterError(
                "`geoms` must be a non-empty list of geom names", field="geoms"
            )
        names = [str(g) for g in geoms]
        if len(set(names)) != len(names):
            raise InvalidSceneError("`geoms` lists a geom twice", field="geoms")
        self.surface = _number(surface, "surface")
        card = None if medium is None else media.load(medium)
        self.medium = card
        if card is not None and card.rho_g is not None and _default(rho_g, 1650.0):
            rho_g = card.rho_g
        rho = _number(rho_g, "rho_g")
        if rho <= 0.0:
            raise InvalidParameterError(f"`rho_g` must be > 0, got {rho}", field="rho_g")
        if statics not in STATICS:
            raise UnknownNameError(
                f"unknown statics `{statics}` (allowed: {', '.join(STATICS)})", field="statics"
            )
        self.statics = statics
        # Checked whichever sign model is chosen (as a Scene's smooth_eps).
        eps = _number(smooth_eps, "smooth_eps")
        if eps <= 0.0:
            raise InvalidParameterError(f"`smooth_eps` must be > 0, got {eps}", field="smooth_eps")
        try:
            bounds = [float(x) for x in patch]
        except (TypeError, ValueError):
            bounds = []
        pairs = list(zip(bounds[::2], bounds[1::2], strict=False))
        if len(bounds) not in (2, 4) or not all(lo < hi for lo, hi in pairs):
            raise InvalidParameterError(
                "`patch` must be (x_min, x_max) or (x_min, x_max, y_min, y_max), each "
                f"min below its max, got {patch!r}",
                field="patch",
            )
        if len(bounds) == 2:
            bounds += [-math.inf, math.inf]
        self.patch = tuple(bounds)
        gravity = np.asarray(model.opt.gravity, dtype=float)
        if not np.all(np.isfinite(gravity)) or abs(gravity[0]) > 0 or abs(gravity[1]) > 0:
            raise InvalidSceneError(
                f"the sand needs gravity along -z, got model.opt.gravity = {gravity.tolist()}",
                field="model.opt.gravity",
            )
        self.g = float(np.linalg.norm(gravity))
        terms = (
            list(media.resolve_terms(as_terms(forces), card)) if card else list(as_terms(forces))
        )
        for t in terms:
            if t.missing:
                try:
                    t.require()
                except InvalidSceneError as e:
                    where = f"the medium {card.name!r}" if card else "a medium= whose card has it"
                    raise type(e)(f"{e}; give it, or {where}", field=e.field) from None
        if space is None:
            space = any(t.name in SPACE_TERMS for t in terms)
        elif not isinstance(space, bool | np.bool_):
            raise InvalidParameterError(
                f"`space` must be True, False or None, got {space!r}", field="space"
            )
        #: Whether the geoms are shapes in space (else the planar rod and box).
        self.space = bool(space)
        self._warned = False
        self._stage = (0, math.nan)
        # The model's options (a live view: the timestep is read at every step) and its
        # integrator, read here as the implicit damping is.
        self._opt = model.opt
        self._rk4 = model.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4
        self._data_ref: Any = None
        self._mass = np.zeros((model.nv, model.nv))
        self._generalized = np.zeros(model.nv)
        self._before = np.zeros(model.nv)
        self._after = np.zeros(model.nv)
        #: The largest of ``h_lambda`` over every step so far.
        self.max_h_lambda = 0.0
        speed = _number(rest_speed, "rest_speed")
        if speed <= 0.0:
            raise InvalidParameterError(
                f"`rest_speed` must be > 0, got {speed}", field="rest_speed"
            )
        #: The sand's creep speed at rest [m/s] (the ``rest_speed`` argument).
        self.rest_speed = speed
        if self.space:
            self._init_space(names, terms, rho, quadrature)
            return
        if len(self.patch) == 4 and math.isfinite(self.patch[2] - self.patch[3]):
            raise InvalidParameterError(
                "a planar model's patch is (x_min, x_max): it has no y extent", field="patch"
            )
        self.patch = self.patch[:2]

        ids, half, shapes = [], [], []
        for i, name in enumerate(names):
            gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
            if gid < 0:
                raise UnknownNameError(f"the model has no geom named `{name}`", field=f"geoms[{i}]")
            kind = int(model.geom_type[gid])
            if kind not in _SUPPORTED:
                type_name = mujoco.mjtGeom(kind).name.removeprefix("mjGEOM_").lower()
                raise InvalidSceneError(
                    f"geom `{name}` is a {type_name}; Sand takes "
                    f"{', '.join(_SUPPORTED.values())} geoms",
                    field=f"geoms[{i}]",
                )
            ids.append(gid)
            size = [float(x) for x in model.geom_size[gid]]
            if _SUPPORTED[kind] == "box":
                # The leg's sole box, centred on the geom: f_s along its x, its height along
                # z, w_s along y; L_ref its length.
                half.append(0.0)
                shapes.append(("sole", [2 * size[0], 2 * size[2], 2 * size[1], 2 * size[0]]))
                continue
            r, h = size[0], size[1]
            # A capsule's caps count: its tip is the bottom of the lower cap.
            reach = h + r if _SUPPORTED[kind] == "capsule" else h
            half.append(reach)
            shapes.append(("rod", [2.0 * r, 2.0 * reach]))
        self.geoms = tuple(names)
        self._ids = np.asarray(ids, dtype=np.intp)
        self._body = np.asarray(model.geom_bodyid[self._ids], dtype=np.intp)
        self._root = np.asarray(model.body_rootid[self._body], dtype=np.intp)
        self._half = np.asarray(half, dtype=float)
        self._check_planar()
        self._core = _granrs.SandGeoms(
            list(names),
            shapes,
            list(as_terms(forces)),
            rho,
            self.g,
            apply_at,
            sign_model,
            eps,
        )
        self.apply_at = apply_at
        dofs = self._dofs(self._body)
        self._coupling = _granrs.MujocoCoupling.planar(
            self._core,
            [int(i) for i in self._ids],
            [int(b) for b in self._body],
            [int(r) for r in self._root],
            [float(h) for h in self._half],
            dofs,
            model.nv,
            self.surface,
            self.patch,
            statics == "stick",
            self._implicit_damping(),
            self.rest_speed,
        )
        n = len(names)
        #: Each geom's evaluation at the last step (columns :data:`GEOM_OUTPUTS`).
        self.output = np.zeros((n, len(GEOM_OUTPUTS)))
        #: The force (x, z) [N] and moment about +y [N m] applied at each tip, last step.
        self.applied = np.zeros((n, 3))
        #: Each geom's timestep times the drag's rate at the last step (0 out of the sand).
        self.h_lambda = np.zeros(n)

    def _dofs(self, bodies: Any) -> list[list[int]]:
        """The dofs that move each body: its joints' and its ancestors'."""
        m = self.model
        out = []
        for body in bodies:
            chain, b = [], int(body)
            while b > 0:
                chain.extend(range(m.body_dofadr[b], m.body_dofadr[b] + m.body_dofnum[b]))
                b = int(m.body_parentid[b])
            out.append(sorted(chain))
        return out

    def _space_shape(self, i: int, name: str, gid: int) -> Any:
        """Geom ``gid``'s shape in space (its frame the geom's)."""
        m = self.model
        kind = int(m.geom_type[gid])
        if kind not in _SPACE_TYPES:
            type_name = mujoco.mjtGeom(kind).name.removeprefix("mjGEOM_").lower()
            raise InvalidSceneError(
                f"geom `{name}` is a {type_name}; Sand in space takes "
                f"{', '.join(_SPACE_TYPES.values())} geoms",
                field=f"geoms[{i}]",
            )
        size = [float(x) for x in m.geom_size[gid]]
        what = _SPACE_TYPES[kind]
        if what == "sphere":
            return Sphere(size[0])
        if what == "capsule":
            return Capsule(size[0], 2.0 * size[1])
        if what == "cylinder":
            return Cylinder(size[0], 2.0 * size[1])
        if what == "box":
            return Cuboid((2.0 * size[0], 2.0 * size[1], 2.0 * size[2]))
        if what == "ellipsoid":
            ball = Mesh.icosphere(1.0, ELLIPSOID_SUBDIVISIONS)
            return Mesh(ball.vertices * np.asarray(size), ball.triangles)
        mesh = int(m.geom_dataid[gid])
        if mesh < 0 or m.mesh_vertnum[mesh] == 0 or m.mesh_facenum[mesh] == 0:
            raise InvalidSceneError(
                f"mesh geom `{name}` has no vertex or face data in the model",
                field=f"geoms[{i}]",
            )
        v0, nvert = int(m.mesh_vertadr[mesh]), int(m.mesh_vertnum[mesh])
        f0, nface = int(m.mesh_faceadr[mesh]), int(m.mesh_facenum[mesh])
        return Mesh(
            np.array(m.mesh_vert[v0 : v0 + nvert], dtype=float),
            np.array(m.mesh_face[f0 : f0 + nface], dtype=np.int64),
        )

    def _init_space(self, names: list[str], terms: list[Term], rho: float, quadrature: Any) -> None:
        m = self.model
        if isinstance(quadrature, bool | np.bool_) or not isinstance(quadrature, int | np.integer):
            raise InvalidParameterError(
                f"`quadrature` must be an integer, got {quadrature!r}", field="quadrature"
            )
        ids, shapes = [], []
        for i, name in enumerate(names):
            gid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, name)
            if gid < 0:
                raise UnknownNameError(f"the model has no geom named `{name}`", field=f"geoms[{i}]")
            ids.append(gid)
            shapes.append(self._space_shape(i, name, gid)._dict())
        self.geoms = tuple(names)
        self._ids = np.asarray(ids, dtype=np.intp)
        self._body = np.asarray(m.geom_bodyid[self._ids], dtype=np.intp)
        self._root = np.asarray(m.body_rootid[self._body], dtype=np.intp)
        self.apply_at = "centre"
        self._coupling = _granrs.MujocoCoupling.space(
            list(names),
            shapes,
            [(t.name, dict(t.params)) for t in terms],
            rho,
            self.surface,
            list(self.patch),
            self.rest_speed,
            int(quadrature),
            [int(g) for g in self._ids],
            [int(b) for b in self._body],
            [int(r) for r in self._root],
            self._dofs(self._body),
            m.nv,
            self._implicit_damping(),
        )
        n = len(names)
        self.output = np.zeros((n, len(SPACE_GEOM_OUTPUTS)))
        self.applied = np.zeros((n, 6))
        self._rk4_applied = np.zeros((n, 6))
        self.h_lambda = np.zeros(n)
        #: Newton iterations of the last step's implicit solve, its residual (the twists'
        #: largest error over their scale) and whether it is solved (the residual below
        #: 1e-10, or a rest: every geom at its creep within the sand's resistance).
        self.iterations, self.residual, self.converged = 0, 0.0, True
        #: The largest residual over every step so far.
        self.max_residual = 0.0
        #: Steps whose implicit solve did not converge and where a geom slid (not a rest).
        self.fallbacks = 0

    def _implicit_damping(self) -> list[float]:
        """The dof damping that MuJoCo's step takes implicitly (its velocity update is
        ``(M + h B)^-1`` times the force): Euler (unless ``eulerdamp`` is disabled), implicit
        and implicitfast; none for RK4. Read when the Sand is built."""
        m = self.model
        kind = m.opt.integrator
        euler = kind == mujoco.mjtIntegrator.mjINT_EULER
        implicit = kind in (
            mujoco.mjtIntegrator.mjINT_IMPLICIT,
            mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
        )
        off = m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_EULERDAMP
        if implicit or (euler and not off):
            return [float(b) for b in m.dof_damping]
        return [0.0] * m.nv

    # -- checks -------------------------------------------------------------------------

    def _check_planar(self) -> None:
        """Every joint above each geom keeps it in the x-z plane: slides in x-z, hinges
        about y; and each geom's axis lies in the plane (at the model's qpos0)."""
        m = self.model
        d = mujoco.MjData(m)
        mujoco.mj_kinematics(m, d)
        for i, (name, body) in enumerate(zip(self.geoms, self._body, strict=True)):
            b = int(body)
            while b > 0:
                for j in range(m.body_jntadr[b], m.body_jntadr[b] + m.body_jntnum[b]):
                    kind = int(m.jnt_type[j])
                    axis = d.xaxis[j]
                    joint = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) or f"#{j}"
                    if kind == mujoco.mjtJoint.mjJNT_SLIDE:
                        ok = abs(axis[1]) <= _PLANE_TOL
                    elif kind == mujoco.mjtJoint.mjJNT_HINGE:
                        ok = abs(axis[0]) <= _PLANE_TOL and abs(axis[2]) <= _PLANE_TOL
                    else:
                        ok = False
                    if not ok:
                        raise InvalidSceneError(
                            f"geom `{name}` is not planar: joint `{joint}` of body "
                            f"`{mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)}` lets it "
                            "leave the x-z plane (the rod terms need slides in x-z and "
                            "hinges about y)",
                            field=f"geoms[{i}]",
                        )
                b = int(m.body_parentid[b])
            frame = d.geom_xmat[self._ids[i]].reshape(3, 3)
            # A rod's axis (local z) and a box's x and z lie in the plane: its local y is y.
            e = frame[:, 2]
            if abs(e[1]) > 1e-6 or (
                int(m.geom_type[self._ids[i]]) == mujoco.mjtGeom.mjGEOM_BOX
                and abs(frame[1, 1]) < 1 - 1e-6
            ):
                raise InvalidSceneError(
                    f"geom `{name}` is not planar: its axis {e.round(6).tolist()} leaves the "
                    "x-z plane",
                    field=f"geoms[{i}]",
                )

    # -- the coupling -------------------------------------------------------------------

    def step(self, data: Any) -> None:
        """Compute each geom's force from ``data.qpos`` and ``data.qvel`` and put it in
        ``data.qfrc_applied`` (call before ``mujoco.mj_step``). Replaces this Sand's own
        previous contribution; an entry of ``qfrc_applied`` that changed since this Sand
        last wrote it is taken as the user's and kept as it is."""
        m = self.model
        # Right after mj_step, xpos and cvel still hold the previous state: bring the
        # kinematics and the mass matrix to qpos and qvel.
        mujoco.mj_kinematics(m, data)
        mujoco.mj_comPos(m, data)
        if not self.space:
            mujoco.mj_comVel(m, data)
        mujoco.mj_makeM(m, data)
        self._evaluate(data, passive=False)

    def _callback(self, m: Any, data: Any) -> None:
        """The passive-force callback: add the sand's force to ``qfrc_passive`` (MuJoCo
        recomputes it at every evaluation, so there is nothing of ours to replace)."""
        if m is not self.model:
            return
        self._evaluate(data, passive=True, hold=self._later_stage(data))
        if self.space and self._rk4:
            # What the body receives over RK4's step is its stages' wrenches weighted 1, 2,
            # 2, 1 (sixths): after the fourth, ``applied`` says so (a stage where a geom
            # entered the sand solves its own).
            stage = self._stage[0]
            weight = (1.0, 2.0, 2.0, 1.0)[stage - 1] / 6.0
            if stage == 1:
                self._rk4_applied[:] = weight * self.applied
            else:
                self._rk4_applied += weight * self.applied
            if stage == 4:
                self.applied[:] = self._rk4_applied

    def install(self) -> None:
        """Run as MuJoCo's passive-force callback (``mujoco.set_mjcb_passive``), inside
        every ``mj_step`` and ``mj_forward`` of this Sand's model (at each RK4 stage, with
        that stage's state). The callback is global to the process: every installed Sand is
        called, each acting only on its own model (so two Sands on one model both act, and
        their forces add), and a callback that was installed before the first Sand is
        called first and restored when the last Sand is uninstalled.

        MuJoCo's compiler fails (``engine error: Python exception raised``) while any Python
        passive callback is installed: compile every model before ``install()``, or use
        :meth:`step`."""
        _Dispatch.add(self)

    def uninstall(self) -> None:
        """Stop acting as the passive-force callback (other installed Sands go on)."""
        _Dispatch.remove(self)

    def _later_stage(self, data: Any) -> bool:
        """Whether this callback is a later stage of MuJoCo's RK4 step (its four
        evaluations are at t, t + h/2, t + h/2 and t + h): the static reactions solved at
        its first stage then act through the whole step, as with :meth:`step`. Any other
        call (Euler's one evaluation, an ``mj_forward``) solves them anew."""
        if not self._rk4:
            return False
        t, h = data.time, self._opt.timestep
        stage, t0 = self._stage
        same = math.isclose
        if stage == 1 and same(t, t0 + 0.5 * h, rel_tol=1e-12, abs_tol=1e-15):
            stage = 2
        elif stage == 2 and same(t, t0 + 0.5 * h, rel_tol=1e-12, abs_tol=1e-15):
            stage = 3
        elif stage == 3 and same(t, t0 + h, rel_tol=1e-12, abs_tol=1e-15):
            stage = 4
        else:
            stage, t0 = 1, t
        self._stage = (stage, t0)
        return stage > 1

    def _evaluate(self, data: Any, passive: bool, hold: bool = False) -> None:
        """One call of the core for every geom: each geom's state from MuJoCo's arrays, its
        force through the free link's right-hand side, the static terms' reactions (with
        ``statics="stick"``), the generalized force of it all into ``qfrc_passive``
        (``passive``) or ``qfrc_applied``, and the drag's h lambda."""
        m = self.model
        fresh = data is not self._data_ref
        if fresh:
            # MuJoCo allocates an mjData's arrays once: the core binds their views once (the
            # planar coupling reads each body's velocity, cvel; in space the Jacobian's).
            velocity = () if self.space else (data.cvel,)
            self._coupling.bind(
                data.geom_xpos,
                data.geom_xmat,
                *velocity,
                data.subtree_com,
                data.cdof,
                data.qvel,
                data.qacc,
                data.qfrc_applied,
                data.qfrc_passive,
                self._mass,
                self.output,
                self.applied,
                self.h_lambda,
                self._generalized,
                self._before,
                self._after,
            )
            self._data_ref = data
        mujoco.mj_fullM(m, data, self._mass)
        worst, geom, iterations, residual, converged, fell = self._coupling.step(
            self._opt.timestep, passive, fresh, hold
        )
        if self.space:
            self.iterations, self.residual, self.converged = iterations, residual, converged
            self.max_residual = max(self.max_residual, self.residual)
            self.max_h_lambda = max(self.max_h_lambda, worst)
            self.fallbacks += int(fell)
            if fell and not self._warned:
                self._warned = True
                warnings.warn(
                    StepSizeWarning(
                        f"the sand's implicit step did not converge at MuJoCo's timestep "
                        f"{self._opt.timestep:g} s (its residual is {self.residual:.2g} of the "
                        f"geoms' speeds after {self.iterations} Newton iterations): that step "
                        "stuck or slid instead (see Sand.fallbacks); a smaller timestep "
                        "resolves the sand"
                    ),
                    stacklevel=4,
                )
            return
        if worst > self.max_h_lambda:
            self.max_h_lambda = worst
            self._warn_step_size(worst, geom)

    def _warn_step_size(self, h_lambda: float, geom: int) -> None:
        limit = RK4_STABILITY_LIMIT if self._rk4 else EULER_STABILITY_LIMIT
        if h_lambda > limit and not self._warned:
            self._warned = True
            h = self._opt.timestep
            rate = h_lambda / h
            warnings.warn(
                StepSizeWarning(
                    f"MuJoCo's timestep {h:g} s does not resolve the sand's drag on geom "
                    f"`{self.geoms[geom]}`: timestep x rate = {h_lambda:.3g} (the integrator "
                    f"is stable below {limit}); use timestep <= {0.5 / rate:.2g} s "
                    "(timestep x rate <= 0.5)"
                ),
                stacklevel=4,
            )


class _Dispatch:
    """The one passive-force callback of the process, calling every installed Sand."""

    installed: list[Sand] = []  # noqa: RUF012
    previous: Any = None

    @classmethod
    def add(cls, sand: Sand) -> None:
        if sand in cls.installed:
            return
        if not cls.installed:
            cls.previous = mujoco.get_mjcb_passive()
            mujoco.set_mjcb_passive(cls.call)
        cls.installed.append(sand)

    @classmethod
    def remove(cls, sand: Sand) -> None:
        if sand not in cls.installed:
            return
        cls.installed.remove(sand)
        if not cls.installed:
            mujoco.set_mjcb_passive(cls.previous)
            cls.previous = None

    @classmethod
    def call(cls, m: Any, d: Any) -> None:
        if cls.previous is not None:
            cls.previous(m, d)
        for sand in cls.installed:
            sand._callback(m, d)


#: MuJoCo's integrators by their MJCF names.
INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast")


def free_link_mjcf(scene: Any, timestep: float = 1e-4, integrator: str = "Euler") -> str:
    """The MJCF of a free-link scene (:func:`granrs.cases.free_link`): its rod as a
    cylinder geom ``rod`` of the scene's length, diameter and mass (MuJoCo's solid-cylinder
    inertia, the scene's default) on a body with slide x, slide z and hinge y at its centre,
    gravity ``scene.g`` along -z, no contacts."""
    if integrator not in INTEGRATORS:
        raise UnknownNameError(
            f"unknown integrator `{integrator}` (allowed: {', '.join(INTEGRATORS)})",
            field="integrator",
        )
    if scene.inertia is not None:
        raise InvalidSceneError(
            "free_link_mjcf builds MuJoCo's solid cylinder; the scene sets its own inertia",
            field="inertia",
        )
    return f"""<mujoco model="granrs free link">
  <option timestep="{_number(timestep, "timestep")!r}" integrator="{integrator}"
          gravity="0 0 {-scene.g!r}"/>
  <worldbody>
    <body name="rod" pos="0 0 0">
      <joint name="x" type="slide" axis="1 0 0"/>
      <joint name="z" type="slide" axis="0 0 1"/>
      <joint name="q" type="hinge" axis="0 1 0"/>
      <geom name="rod" type="cylinder" size="{scene.diameter / 2!r} {scene.length / 2!r}"
            mass="{scene.mass!r}" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>"""


def rod_drop(
    scene: Any,
    timestep: float = 1e-4,
    integrator: str = "Euler",
    mode: str = "step",
    statics: str = "stick",
    t_after: float = 0.0,
) -> dict[str, Any]:
    """Drop a free-link scene's rod in MuJoCo with :class:`Sand` under the scene's contact
    terms, from the scene's initial state (tip at the surface, velocity (vx0, -v0), spin
    omega0), until its stop, and ``t_after`` seconds on.

    The stop is the first step at whose end the tip's vertical velocity is >= 0 or within
    the Sand's ``rest_speed`` of it (a rod the sand holds creeps slower than
    ``rest_speed``), interpolated linearly inside the step
    to where that velocity is 0. Returns ``t_s`` [s], ``depth`` [m] (the tip's, at the
    stop), ``steps``, and after the stop ``t``, ``tip`` (x, z) and ``energy`` (KE +
    gravitational PE [J]) per step.
    ``mode`` is ``"step"`` (:meth:`Sand.step`) or ``"callback"`` (:meth:`Sand.install`).
    """
    from . import forces as _forces

    if mode not in ("step", "callback"):
        raise UnknownNameError(f"unknown mode `{mode}` (allowed: step, callback)", field="mode")
    model = mujoco.MjModel.from_xml_string(free_link_mjcf(scene, timestep, integrator))
    data = mujoco.MjData(model)
    q = math.radians(scene.q_deg)
    half = scene.length / 2
    e = np.array([math.sin(q), math.cos(q)])
    normal = np.array([math.cos(q), -math.sin(q)])
    v_c = np.array([scene.vx0, -scene.v0]) + scene.omega0 * half * normal
    data.qpos[:] = [half * e[0], half * e[1] - scene.depth0, q]
    data.qvel[:] = [v_c[0], v_c[1], scene.omega0]
    contact = [t for t in scene.forces if t.info.acts == "contact"]
    sand = Sand(
        model,
        ["rod"],
        list(_forces.as_terms(contact)),
        rho_g=scene.rho_g,
        apply_at=scene.apply_at,
        statics=statics,
    )
    mass = scene.mass
    inertia = float(model.body_inertia[1, 1])
    g = sand.g

    def tip() -> tuple[float, float, float]:
        angle = data.qpos[2]
        s, c = math.sin(angle), math.cos(angle)
        return (
            data.qpos[0] - half * s,
            data.qpos[1] - half * c,
            data.qvel[1] + data.qvel[2] * half * s,
        )

    def energy() -> float:
        v = data.qvel
        return (
            0.5 * mass * (v[0] ** 2 + v[1] ** 2)
            + 0.5 * inertia * v[2] ** 2
            + mass * g * (data.qpos[1])
        )

    if mode == "callback":
        sand.install()
    try:
        t_prev, z_prev, v_prev = 0.0, tip()[1], tip()[2]
        limit = math.ceil(max(scene.t_end, 1.0) / timestep)
        for steps in range(1, limit + 1):  # noqa: B007
            if mode == "step":
                sand.step(data)
            mujoco.mj_step(model, data)
            _, z, v = tip()
            if v >= -sand.rest_speed:
                f = min(-v_prev / (v - v_prev), 1.0) if v != v_prev else 1.0
                t_s = t_prev + f * (data.time - t_prev)
                depth = -(z_prev + f * (z - z_prev))
                break
            t_prev, z_prev, v_prev = data.time, z, v
        else:
            return {"t_s": math.nan, "depth": math.nan, "steps": limit, "sand": sand}
        after_t, after_tip, after_e = [data.time], [tip()[:2]], [energy()]
        for _ in range(round(t_after / timestep)):
            if mode == "step":
                sand.step(data)
            mujoco.mj_step(model, data)
            after_t.append(data.time)
            after_tip.append(tip()[:2])
            after_e.append(energy())
    finally:
        if mode == "callback":
            sand.uninstall()
    return {
        "t_s": t_s,
        "depth": depth,
        "steps": steps,
        "t": np.asarray(after_t),
        "tip": np.asarray(after_tip),
        "energy": np.asarray(after_e),
        "sand": sand,
    }


def body_mjcf(scene: Any, timestep: float = 1e-4, integrator: str = "Euler") -> str:
    """The MJCF of a body in space (a :class:`granrs.space.Scene`): its shape as a geom
    ``body`` (a mesh from :meth:`granrs.space.Scene.body_vertices`) on a body with a free
    joint, the scene's mass and inertia tensor, gravity ``scene.g`` along -z, no
    contacts."""
    if not isinstance(scene, SpaceScene):
        raise InvalidParameterError(
            f"body_mjcf takes a granrs.space.Scene, got {type(scene).__name__}", field="scene"
        )
    if integrator not in INTEGRATORS:
        raise UnknownNameError(
            f"unknown integrator `{integrator}` (allowed: {', '.join(INTEGRATORS)})",
            field="integrator",
        )
    shape = scene.body.shape
    asset = ""
    if isinstance(shape, Sphere):
        geom = f'type="sphere" size="{shape.radius!r}"'
    elif isinstance(shape, Capsule | Cylinder):
        kind = "capsule" if isinstance(shape, Capsule) else "cylinder"
        geom = f'type="{kind}" size="{shape.radius!r} {shape.length / 2!r}"'
    elif isinstance(shape, Cuboid):
        geom = 'type="box" size="{!r} {!r} {!r}"'.format(*(x / 2 for x in shape.size))
    else:
        v = scene.body_vertices()
        t = np.asarray(shape.triangles)
        asset = (
            '<asset><mesh name="body" vertex="'
            + " ".join(repr(float(x)) for x in np.ravel(v))
            + '" face="'
            + " ".join(str(int(x)) for x in np.ravel(t))
            + '"/></asset>'
        )
        geom = 'type="mesh" mesh="body"'
    i = np.asarray(scene.inertia, dtype=float)
    full = " ".join(repr(float(x)) for x in (i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]))
    return f"""<mujoco model="granrs body in space">
  <option timestep="{_number(timestep, "timestep")!r}" integrator="{integrator}"
          gravity="0 0 {-float(scene.g)!r}"/>
  {asset}
  <worldbody>
    <body name="body">
      <freejoint name="free"/>
      <inertial pos="0 0 0" mass="{scene.mass!r}" fullinertia="{full}"/>
      <geom name="body" {geom} contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>"""


def body_drop(
    scene: Any,
    timestep: float = 1e-4,
    integrator: str = "Euler",
    mode: str = "step",
    t_after: float = 0.0,
    stop_speed: float = 1e-3,
    **sand: Any,
) -> dict[str, Any]:
    """Drop a body in space (a :class:`granrs.space.Scene`) in MuJoCo (:func:`body_mjcf`)
    with :class:`Sand` under the scene's terms (less ``gravity``, which MuJoCo applies),
    from the scene's initial state, until its stop and ``t_after`` seconds on; ``sand``:
    more arguments of :class:`Sand`.

    The implicit sand brings the body to rest at a creep, not to an upward velocity: the
    stop is the first step over which the lowest point sinks slower than ``stop_speed``
    [m/s], interpolated linearly inside the step. Returns ``t_s`` [s], ``depth`` [m] (the
    lowest point's, at the stop), ``steps``; and per step after the stop ``t``, ``depth``,
    ``force`` (the sand's, x, y, z [N]) and ``energy`` (KE + gravitational PE [J]).
    ``mode`` is ``"step"`` (:meth:`Sand.step`) or ``"callback"`` (:meth:`Sand.install`).
    """
    if mode not in ("step", "callback"):
        raise UnknownNameError(f"unknown mode `{mode}` (allowed: step, callback)", field="mode")
    speed = _number(stop_speed, "stop_speed")
    if speed <= 0.0:
        raise InvalidParameterError(f"`stop_speed` must be > 0, got {speed}", field="stop_speed")
    model = mujoco.MjModel.from_xml_string(body_mjcf(scene, timestep, integrator))
    data = mujoco.MjData(model)
    w, x, y, z = (float(c) for c in scene.orientation)
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, np.array([w, x, y, z]))
    data.qpos[:3] = scene.position
    data.qpos[3:7] = (w, x, y, z)
    data.qvel[:3] = scene.velocity
    # A free joint's angular velocity is in the body's frame.
    data.qvel[3:6] = rot.reshape(3, 3).T @ np.asarray(scene.omega, dtype=float)
    terms = [t for t in scene.forces if t.name != "gravity"]
    sand_ = Sand(
        model, ["body"], terms, surface=scene.surface, rho_g=scene.rho_g, space=True, **sand
    )
    mass, inertia, g = scene.mass, np.asarray(scene.inertia, dtype=float), float(scene.g)

    def energy() -> float:
        v, om = data.qvel[:3], data.qvel[3:6]
        return float(0.5 * mass * v @ v + 0.5 * om @ inertia @ om + mass * g * data.qpos[2])

    def advance() -> float:
        if mode == "step":
            sand_.step(data)
        mujoco.mj_step(model, data)
        return float(sand_.output[0, 0])

    if mode == "callback":
        sand_.install()
    try:
        mujoco.mj_forward(model, data)
        limit = math.ceil(max(scene.t_end, 1.0) / timestep)
        # The depth each step starts from (the sand's output at that step).
        d_prev, t_s, depth, steps = math.nan, math.nan, math.nan, limit
        rate_prev = math.inf
        for k in range(limit):
            d = advance()
            if k > 0:
                rate = (d - d_prev) / timestep
                if rate < speed and d > 0.0:
                    f = (rate_prev - speed) / (rate_prev - rate) if rate_prev > rate else 1.0
                    f = min(max(f, 0.0), 1.0)
                    t_s = (k - 1 + f) * timestep
                    depth = d_prev + f * (d - d_prev)
                    steps = k
                    break
                rate_prev = rate
            d_prev = d
        after_t, after_d, after_f, after_e = [], [], [], []
        for _ in range(round(t_after / timestep)):
            after_d.append(advance())
            after_t.append(float(data.time))
            after_f.append(sand_.applied[0, :3].copy())
            after_e.append(energy())
    finally:
        if mode == "callback":
            sand_.uninstall()
    return {
        "t_s": t_s,
        "depth": depth,
        "steps": steps,
        "t": np.asarray(after_t),
        "depth_after": np.asarray(after_d),
        "force": np.asarray(after_f).reshape(-1, 3),
        "energy": np.asarray(after_e),
        "sand": sand_,
    }


#: The sand geoms of :func:`walker_mjcf`: its two shanks.
WALKER_SAND_GEOMS = ("shank_r", "shank_l")


def walker_mjcf(floor: bool = False, timestep: float = 2e-4, integrator: str = "Euler") -> str:
    """The MJCF of the gallery's passive planar walker (written for granrs; SI units): a
    torso on slide x, slide z and hinge y; two legs, each a thigh and a shank (capsules of
    density 1000 kg/m^3, about 13 kg in all) with stiff, damped hinges about y at the hip
    and knee (600 N m/rad, 10 N m s/rad), no actuators. The shanks' tips (the bottoms of
    their caps) start at z = 0; ``floor`` adds MuJoCo's rigid ground there (a plane).
    :data:`WALKER_SAND_GEOMS` are the shanks."""
    if integrator not in INTEGRATORS:
        raise UnknownNameError(
            f"unknown integrator `{integrator}` (allowed: {', '.join(INTEGRATORS)})",
            field="integrator",
        )
    ground = (
        '<geom name="floor" type="plane" size="5 1 0.1" rgba="0.6 0.5 0.35 1"/>' if floor else ""
    )
    # The hip is 0.05 m below the torso's origin, the knee 0.4 m lower, the shank's end
    # 0.45 m below the knee, and its cap reaches one radius (0.035 m) further.
    z0 = 0.05 + 0.4 + 0.45 + 0.035
    return f"""<mujoco model="granrs planar walker">
  <option timestep="{_number(timestep, "timestep")!r}" integrator="{integrator}"
          gravity="0 0 -9.81"/>
  <default>
    <joint type="hinge" axis="0 1 0" stiffness="600" damping="10" armature="0.01"/>
    <geom type="capsule" density="1000" friction="0.9"/>
  </default>
  <worldbody>
    {ground}
    <body name="torso" pos="0 0 {z0!r}">
      <joint name="rootx" type="slide" axis="1 0 0" stiffness="0" damping="0" armature="0"/>
      <joint name="rootz" type="slide" axis="0 0 1" stiffness="0" damping="0" armature="0"/>
      <joint name="rooty" stiffness="0" damping="0" armature="0"/>
      <geom name="torso" fromto="0 0 0.3 0 0 -0.05" size="0.06"/>
      <body name="thigh_r" pos="0 0 -0.05">
        <joint name="hip_r"/>
        <geom name="thigh_r" fromto="0 0 0 0.12 0 -0.4" size="0.045"/>
        <body name="shank_r" pos="0.12 0 -0.4">
          <joint name="knee_r"/>
          <geom name="shank_r" fromto="0 0 0 0.05 0 -0.45" size="0.035"/>
        </body>
      </body>
      <body name="thigh_l" pos="0 0 -0.05">
        <joint name="hip_l"/>
        <geom name="thigh_l" fromto="0 0 0 -0.12 0 -0.4" size="0.045"/>
        <body name="shank_l" pos="-0.12 0 -0.4">
          <joint name="knee_l"/>
          <geom name="shank_l" fromto="0 0 0 -0.05 0 -0.45" size="0.035"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""
