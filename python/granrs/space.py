"""Bodies in space: a free rigid body of any shape falling into sand, in three dimensions.

A sphere, a capsule, a cylinder, a cuboid or a closed triangle mesh moves freely (position,
orientation as a unit quaternion, velocity, angular velocity) under the terms that act in
three dimensions:

- :func:`granrs.forces.rft3d`: 3D resistive force theory (Agarwal, Goldman & Kamrin, PNAS
  2023), on each element of the body's immersed surface;
- :func:`granrs.forces.rft3d_inertial`: its rate-dependent term, the momentum flux on the
  leading elements;
- :func:`granrs.forces.poncelet`: the Poncelet / Katsuragi-Durian law, with ``A`` the
  immersed leading area projected normal to the motion (a sphere fully under: pi r^2);
- :func:`granrs.forces.gravity`.

The frame is granrs's planar one extended: x right, y into the page, z up; the sand's
surface is the plane ``z = surface``. Each shape's surface is cut exactly where it meets
the sand and where its leading side ends, and integrated there (``quadrature`` nodes per
panel; :func:`load` estimates the rule's error). The run is the classical RK4 at a fixed
step (10 kHz by default) with the entry and the stop located inside the step; the stop
(the lowest point's vertical velocity turns >= 0 in the sand) ends the run.

Example::

    >>> import granrs
    >>> from granrs import space
    >>> ball = space.Body(space.Sphere(radius=0.02), density=7800.0)
    >>> scene = space.Scene(body=ball, velocity=(0.0, 0.0, -2.0),
    ...                     forces=[granrs.forces.rft3d(zeta=2e5), granrs.forces.gravity()])
    >>> r = granrs.simulate(scene)
    >>> r.status, round(r.depth * 1e3, 1)
    ('stopped', 76.0)
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _granrs, media
from .errors import InvalidParameterError
from .forces import Term

__all__ = [
    "DEFAULT_QUADRATURE",
    "SERIES_COLUMNS",
    "SUMMARY_FIELDS",
    "Body",
    "Capsule",
    "Cuboid",
    "Cylinder",
    "Load",
    "Mesh",
    "Result",
    "Scene",
    "Sphere",
    "load",
    "rft3d_alpha",
    "xi_n",
]

#: Gauss-Legendre nodes per panel of a curved surface unless a scene says otherwise.
DEFAULT_QUADRATURE: int = _granrs.SPACE_DEFAULT_NODES
#: Every summary field of a run in space: name -> (unit, description).
SUMMARY_FIELDS: Mapping[str, tuple[str, str]] = {n: (u, d) for n, u, d in _granrs.SPACE_SUMMARY}
#: Every series column of a run in space (``record=True``): name -> (unit, description).
SERIES_COLUMNS: Mapping[str, tuple[str, str]] = {n: (u, d) for n, u, d in _granrs.SPACE_SERIES}


@dataclass(frozen=True)
class Sphere:
    """A sphere of ``radius`` [m], its centre the centre of mass."""

    radius: float

    def _dict(self) -> dict[str, Any]:
        return {"kind": "sphere", "radius": self.radius}


@dataclass(frozen=True)
class Capsule:
    """A capsule along the body's z axis: a cylinder of ``length`` [m] (between the centres
    of its ends) capped by hemispheres of ``radius`` [m]; MuJoCo's capsule of size
    ``(radius, length / 2)``."""

    radius: float
    length: float

    def _dict(self) -> dict[str, Any]:
        return {"kind": "capsule", "radius": self.radius, "length": self.length}


@dataclass(frozen=True)
class Cylinder:
    """A cylinder along the body's z axis with flat ends: ``radius`` and ``length`` [m]."""

    radius: float
    length: float

    def _dict(self) -> dict[str, Any]:
        return {"kind": "cylinder", "radius": self.radius, "length": self.length}


@dataclass(frozen=True)
class Cuboid:
    """A cuboid (a box) with edge lengths ``size = (x, y, z)`` [m] along the body's axes."""

    size: tuple[float, float, float]

    def _dict(self) -> dict[str, Any]:
        return {"kind": "cuboid", "size": self.size}


@dataclass(frozen=True, eq=False)
class Mesh:
    """A closed triangle mesh: ``vertices`` (n x 3) [m] and ``triangles`` (m x 3 vertex
    indices, counter-clockwise seen from outside, so that the normals point out).

    The body's origin is the mesh's centre of mass (of a uniform solid): the body's
    position is where that centre is (the vertices are moved so that it is their origin;
    :meth:`Scene.body_vertices` gives them so). A mesh that is not closed, not consistently
    oriented, turned inside out, or has a triangle of zero area is refused naming the
    triangle.
    """

    vertices: np.ndarray
    triangles: np.ndarray

    def __post_init__(self) -> None:
        try:
            v = np.asarray(self.vertices, dtype=float)
        except (TypeError, ValueError, OverflowError) as e:
            raise InvalidParameterError(
                f"a mesh's vertices are an n x 3 array of numbers: {e}", field="body.shape.vertices"
            ) from e
        try:
            t = np.asarray(self.triangles)
        except (TypeError, ValueError, OverflowError) as e:
            raise InvalidParameterError(
                f"a mesh's triangles are an m x 3 array of vertex indices: {e}",
                field="body.shape.triangles",
            ) from e
        if v.ndim != 2 or v.shape[1] != 3:
            raise InvalidParameterError(
                f"a mesh's vertices are an n x 3 array, got shape {v.shape}",
                field="body.shape.vertices",
            )
        if t.ndim != 2 or t.shape[1] != 3 or not np.issubdtype(t.dtype, np.integer):
            raise InvalidParameterError(
                f"a mesh's triangles are an m x 3 array of vertex indices, got shape {t.shape} "
                f"of {t.dtype}",
                field="body.shape.triangles",
            )
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "triangles", t.astype(np.int64))

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Mesh:
        """A mesh from an STL, OBJ, PLY or OFF file, read by ``trimesh`` (``pip install
        trimesh``); its units are taken as metres."""
        try:
            import trimesh
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise InvalidParameterError(
                "reading a mesh file needs trimesh: pip install trimesh", field="path"
            ) from e
        try:
            m = trimesh.load_mesh(os.fspath(path), process=True)
        except Exception as e:
            raise InvalidParameterError(
                f"{path}: not a mesh file trimesh reads ({e})", field="path"
            ) from e
        if not hasattr(m, "vertices") or not hasattr(m, "faces"):
            raise InvalidParameterError(f"{path}: holds no single mesh", field="path")
        return cls(np.asarray(m.vertices, dtype=float), np.asarray(m.faces, dtype=np.int64))

    @classmethod
    def icosphere(cls, radius: float, subdivisions: int = 2) -> Mesh:
        """A sphere of ``radius`` as an icosahedron subdivided ``subdivisions`` times (20 * 4^k
        triangles, vertices on the sphere)."""
        if not isinstance(subdivisions, int) or not 0 <= subdivisions <= 7:
            raise InvalidParameterError(
                f"subdivisions must be an integer in 0..7, got {subdivisions!r}",
                field="subdivisions",
            )
        p = (1 + 5**0.5) / 2
        verts = [
            (-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0),
            (0, -1, p), (0, 1, p), (0, -1, -p), (0, 1, -p),
            (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1),
        ]  # fmt: skip
        faces = [
            (0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11),
            (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
            (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
            (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1),
        ]  # fmt: skip
        v = [np.array(x, dtype=float) / np.linalg.norm(x) for x in verts]
        for _ in range(subdivisions):
            middle: dict[tuple[int, int], int] = {}
            new = []
            for a, b, c in faces:
                ab, bc, ca = (_middle(v, middle, x, y) for x, y in ((a, b), (b, c), (c, a)))
                new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
            faces = new
        return cls(np.array(v) * float(radius), np.array(faces, dtype=np.int64))

    def _dict(self) -> dict[str, Any]:
        return {
            "kind": "mesh",
            "vertices": self.vertices.tolist(),
            "triangles": self.triangles.tolist(),
        }


def _middle(v: list[np.ndarray], middle: dict[tuple[int, int], int], a: int, b: int) -> int:
    """The index of the vertex on the unit sphere halfway between ``a`` and ``b`` (added
    to ``v`` the first time it is asked for)."""
    key = (min(a, b), max(a, b))
    if key not in middle:
        m = v[a] + v[b]
        v.append(m / np.linalg.norm(m))
        middle[key] = len(v) - 1
    return middle[key]


Shape = Sphere | Capsule | Cylinder | Cuboid | Mesh


@dataclass(frozen=True)
class Body:
    """A rigid body: its shape and its mass.

    Give its uniform ``density`` [kg/m^3], or its ``mass`` [kg] (uniform over the shape), or
    its ``mass`` and ``inertia``, the 3 x 3 tensor about its centre of mass in the body frame
    [kg m^2] (symmetric, positive definite, a real body's).
    """

    shape: Shape
    density: float | None = None
    mass: float | None = None
    inertia: Any = None

    def _dict(self) -> dict[str, Any]:
        shape = getattr(self.shape, "_dict", None)
        if shape is None:
            raise InvalidParameterError(
                f"a body's shape is a granrs.space shape (Sphere, Capsule, Cylinder, Cuboid, "
                f"Mesh), got {type(self.shape).__name__}",
                field="body.shape",
            )
        return {
            "shape": shape(),
            "density": self.density,
            "mass": self.mass,
            "inertia": self.inertia,
        }


def _terms(forces: Any) -> list[tuple[str, dict[str, Any]]]:
    if isinstance(forces, Term):
        forces = [forces]
    if isinstance(forces, str | bytes) or not isinstance(forces, Sequence):
        raise InvalidParameterError(
            f"forces must be a list of terms (granrs.forces.rft3d(...), ...), got {forces!r}",
            field="forces",
        )
    out = []
    for i, t in enumerate(forces):
        if not isinstance(t, Term):
            raise InvalidParameterError(
                f"forces[{i}] must be a term (granrs.forces.rft3d(...), ...), got {t!r}",
                field=f"forces[{i}]",
            )
        out.append((t.name, dict(t.params)))
    return out


@dataclass(frozen=True)
class Scene:
    """A run of a body in space. Every field is checked when the scene is built (a typed
    error naming the first bad one), before any work.

    Attributes:
        body: the body (:class:`Body`).
        forces: the terms that act (:func:`granrs.forces.rft3d`, ``rft3d_inertial``,
            ``poncelet``, ``gravity``); required, since no medium's ``zeta`` is a default.
        position: the centre of mass at t = 0 [m]; ``None`` (default): the lowest point on
            the surface, the centre above the origin.
        orientation: the orientation at t = 0, a unit quaternion ``(w, x, y, z)`` (body to
            world; its norm within 1e-6 of 1).
        velocity: the centre's velocity at t = 0 [m/s].
        omega: the angular velocity at t = 0, world frame [rad/s].
        rho_g: the sand's bulk density [kg/m^3] (1650, the thesis's sand), read by
            ``rft3d_inertial`` and ``poncelet``; the medium's where one is given (and
            this is left at its default).
        g: gravity [m/s^2] (9.81); the medium's, as ``rho_g``.
        medium: the granular medium (:mod:`granrs.media`): a shipped card's name, a card
            file's path or a :class:`granrs.media.MediumCard`. Its ``rho_g`` and ``g``, and
            its values of the listed terms' parameters not given (``rft3d(...)`` without
            ``zeta``), are the scene's. ``None`` (default): no medium.
        surface: the sand's surface z [m].
        dt: the step [s] (1e-4: 10 kHz, as the planar scenes).
        t_end: the end time [s].
        end: ``"stop"`` (default): the run ends at the stop; ``"t_end"``: it runs on
            through it (a speed-independent law has no rest: expect the body to creep).
        record: whether to record the series (every step and event).
        quadrature: Gauss-Legendre nodes per panel of a curved surface (6).
    """

    body: Body
    forces: Sequence[Term]
    position: tuple[float, float, float] | None = None
    orientation: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    omega: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rho_g: float = 1650.0
    g: float = 9.81
    medium: str | os.PathLike[str] | media.MediumCard | None = None
    surface: float = 0.0
    dt: float = 1e-4
    t_end: float = 1.0
    end: str = "stop"
    record: bool = False
    quadrature: int = DEFAULT_QUADRATURE
    _compiled: Any = field(default=None, init=False, repr=False, compare=False)

    def _dict(self, position: Any) -> dict[str, Any]:
        if not isinstance(self.body, Body):
            raise InvalidParameterError(
                f"body must be a granrs.space.Body, got {type(self.body).__name__}", field="body"
            )
        return {
            "body": self.body._dict(),
            "forces": _terms(self.forces),
            "position": position,
            "orientation": self.orientation,
            "velocity": self.velocity,
            "omega": self.omega,
            "rho_g": self.rho_g,
            "g": self.g,
            "surface": self.surface,
            "dt": self.dt,
            "t_end": self.t_end,
            "end": self.end,
            "record": self.record,
            "quadrature": self.quadrature,
        }

    def __post_init__(self) -> None:
        if isinstance(self.forces, list | tuple):
            object.__setattr__(self, "forces", tuple(self.forces))
        media.apply(self)
        if self.position is None:
            probe = _granrs.space_scene(self._dict((0.0, 0.0, 0.0)))
            low = probe.lowest_offset()
            surface = float(self.surface)
            object.__setattr__(self, "position", (0.0, 0.0, surface - low[2]))
        object.__setattr__(self, "_compiled", _granrs.space_scene(self._dict(self.position)))

    def replace(self, **changes: Any) -> Scene:
        """A copy with ``changes`` (checked as a new scene). A new ``medium`` applies as to
        a new scene: what the old one set goes back to its default first."""
        defaults = {f.name: f.default for f in dataclasses.fields(self)}
        media.leave(self, changes, defaults)
        return dataclasses.replace(self, **changes)

    @property
    def mass(self) -> float:
        """The body's mass [kg]."""
        return float(self._compiled.mass_properties()[0])

    @property
    def inertia(self) -> np.ndarray:
        """The body's inertia tensor about its centre of mass, body frame [kg m^2]."""
        return np.array(self._compiled.mass_properties()[1])

    @property
    def volume(self) -> float:
        """The body's volume [m^3]."""
        return float(self._compiled.mass_properties()[2])

    def body_vertices(self) -> np.ndarray | None:
        """A mesh body's vertices in the body frame, its centre of mass the origin [m]
        (n x 3); None for another shape."""
        v = self._compiled.body_vertices()
        return None if v is None else np.array(v, dtype=float)


@dataclass(frozen=True)
class Result:
    """What a run of a body in space gives.

    Attributes:
        scene: the scene that ran.
        status: ``"stopped"`` or ``"not_stopped"`` (``t_end`` came first).
        summary: every field of :data:`SUMMARY_FIELDS` (floats; NaN where it does not apply).
        series: the recorded columns of :data:`SERIES_COLUMNS` (numpy arrays), or None.
        orientation_end: the orientation at the end, ``(w, x, y, z)``.
        run_seconds: the core's time for the run [s].
    """

    scene: Scene
    status: str
    summary: Mapping[str, float]
    series: Mapping[str, np.ndarray] | None
    orientation_end: tuple[float, float, float, float]
    run_seconds: float

    @property
    def t_s(self) -> float:
        """The time of the stop [s] (NaN: none)."""
        return self.summary["t_s"]

    @property
    def depth(self) -> float:
        """The lowest point's depth at the end (the stop) [m]."""
        return self.summary["depth"]

    @property
    def dE(self) -> float:
        """The energy the sand took [J]."""
        return self.summary["dE"]


def run(scene: Scene) -> Result:
    """Run ``scene`` (``granrs.simulate`` does, and warns where the step is too large)."""
    if not isinstance(scene, Scene):
        raise InvalidParameterError(
            f"run() takes a granrs.space.Scene, got {type(scene).__name__}", field="scene"
        )
    out = _granrs.space_run(scene._compiled)
    return Result(
        scene=scene,
        status=out["status"],
        summary=dict(out["summary"]),
        series=None if out["series"] is None else dict(out["series"]),
        orientation_end=tuple(out["orientation_end"]),
        run_seconds=out["run_seconds"],
    )


@dataclass(frozen=True)
class Load:
    """The sand's load on a body at one pose and motion.

    Attributes:
        force: the sand's force [N] (x, y, z), the weight not included.
        moment: its moment about the centre of mass [N m].
        terms: each listed sand term's share of the force [N].
        wetted_area: the immersed surface's area [m^2].
        projected_area: the immersed leading area projected normal to the centre's velocity
            [m^2].
        elements: how many surface elements were evaluated.
        force_error: the surface rule's error estimate of the force [N] (how much the force
            moves when the nodes per panel are doubled; NaN if not asked for).
        moment_error: the same for the moment [N m].
    """

    force: tuple[float, float, float]
    moment: tuple[float, float, float]
    terms: Mapping[str, tuple[float, float, float]]
    wetted_area: float
    projected_area: float
    elements: int
    force_error: float
    moment_error: float


def load(
    scene: Scene,
    position: Sequence[float] | None = None,
    orientation: Sequence[float] | None = None,
    velocity: Sequence[float] | None = None,
    omega: Sequence[float] | None = None,
    error: bool = True,
) -> Load:
    """The sand's load on ``scene``'s body under its terms, at its initial state or at the
    pose and motion given (each checked as the scene's field of that name). With ``error``
    (default) the surface rule's error is estimated by evaluating again with twice the
    nodes per panel (the cost of several evaluations); without, ``force_error`` and
    ``moment_error`` are NaN.

    Example: the stress on a sphere dragged sideways under the surface has lift::

        >>> import granrs
        >>> from granrs import space
        >>> s = space.Scene(body=space.Body(space.Sphere(0.02), density=2500.0),
        ...                 forces=[granrs.forces.rft3d(zeta=1e6)])
        >>> f = space.load(s, position=(0, 0, -0.05), velocity=(1.0, 0, 0)).force
        >>> f[0] < 0 < f[2]
        True
    """
    if not isinstance(scene, Scene):
        raise InvalidParameterError(
            f"load() takes a granrs.space.Scene, got {type(scene).__name__}", field="scene"
        )
    # The core gives Load's fields as a dict, which becomes the instance's own: the frozen
    # dataclass built without its __init__'s assignment per field.
    out = _new(Load)
    _setattr(
        out,
        "__dict__",
        _granrs.space_load(
            scene._compiled,
            scene.position if position is None else position,
            scene.orientation if orientation is None else orientation,
            scene.velocity if velocity is None else velocity,
            scene.omega if omega is None else omega,
            bool(error),
        ),
    )
    return out


_new = object.__new__
_setattr = object.__setattr__


def xi_n(rho_c: float, mu: float) -> float:
    """3D-RFT's material scale xi_n [N/m^3] (``rft3d``'s ``zeta``) from the medium's
    critical-state (bulk) density ``rho_c`` [kg/m^3] and internal friction coefficient
    ``mu`` [-]: ``rho_c g (894 mu^3 - 386 mu^2 + 89 mu)``, g = 9.81 (Agarwal, Goldman &
    Kamrin 2023, as the public codes of the paper give it; fitted for mu in 0.3 to 0.9)."""
    for name, v in (("rho_c", rho_c), ("mu", mu)):
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) or v < 0:
            raise InvalidParameterError(
                f"{name} must be a finite number >= 0, got {v!r}", field=name
            )
    return float(_granrs.xi_n(float(rho_c), float(mu)))


def rft3d_alpha(
    normal: Sequence[float], velocity: Sequence[float], grazing: bool = True
) -> tuple[float, float, float]:
    """The generic (dimensionless) 3D-RFT stress per unit depth on an element with outward
    unit ``normal`` moving with ``velocity``: zero on a trailing element (normal . velocity
    < 0). A horizontal plate pushed straight down gives (0, 0, 0.87574)."""
    n = np.asarray(normal, dtype=float)
    v = np.asarray(velocity, dtype=float)
    if n.shape != (3,) or v.shape != (3,) or not (np.isfinite(n).all() and np.isfinite(v).all()):
        raise InvalidParameterError("normal and velocity are 3 finite numbers each", field="normal")
    norm = float(np.linalg.norm(n))
    if abs(norm - 1.0) > 1e-9:
        raise InvalidParameterError(
            f"the normal must be a unit vector, its norm is {norm}", field="normal"
        )
    return tuple(_granrs.rft3d_alpha(tuple(n), tuple(v), bool(grazing)))
