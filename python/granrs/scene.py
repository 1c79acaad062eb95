"""What a run is: :class:`Scene`, a frozen description of one impact.

Three bodies share one scene type (``body``): ``"free_link"`` (a round rod), ``"chain"``
(two rods pinned at their top ends, chapter 4) and ``"leg"`` (foot, shank, thigh and half
of head-arms-trunk for one leg of a person landing on both feet, chapter 5). Fields that
belong to one body only are listed in :data:`BODY_FIELDS`; setting one for another body
raises :class:`~granrs.errors.InvalidSceneError`. :mod:`granrs.cases` builds the thesis's
scenes with every default set.

A scene is plain data: the body and its size, the sand, the force terms that act (each with
its parameters: :mod:`granrs.forces`), the initial state, the step, the end condition and
the time series to record. :func:`granrs.simulate` runs it. Every field is checked by the
Rust core (one set of rules for Python, TOML and the CLI) before any work starts; an invalid
field raises a :class:`~granrs.errors.InvalidSceneError` subclass whose ``field`` names it.

Units are SI (m, kg, s, N, J), angles in degrees at this edge (``*_deg``).
Defaults are those of the thesis's free link (section 3.2.1): L = 0.190 m, d_c = 0.0127 m,
m = 0.184 kg, sand bulk density 1650 kg/m^3 (section 3.3.1), 10 kHz (section 3.3.2).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from . import _granrs
from .errors import InvalidParameterError, InvalidSceneError, UnknownNameError
from .forces import Term, as_terms, thesis

__all__ = ["BODIES", "BODY_FIELDS", "JOINTS", "RECORDS", "JointSpec", "Scene"]

#: The body models.
BODIES: tuple[str, ...] = ("free_link", "chain", "leg")
#: Named joint settings; a spring-damper is a mapping ``{"k": N m/rad, "c": N m s/rad}``.
JOINTS: tuple[str, ...] = ("free", "locked")
#: A joint: ``"free"``, ``"locked"`` or ``{"k": stiffness, "c": damping}``.
JointSpec = str | Mapping[str, float]

#: Time series a scene may list in ``record``.
RECORDS: tuple[str, ...] = ("state", "forces", "energy")

#: The thesis's law with each term's defaults (Table 3.4 of the thesis at q = 0).
_THESIS_DEFAULT: tuple[Term, ...] = thesis()

#: Fields of earlier versions and what to write instead.
_REPLACED: dict[str, str] = {
    "coefficients": (
        "the force terms carry their parameters: forces=granrs.forces.thesis(coefficients) "
        "(or granrs.cases.free_link(..., coefficients=...), which builds them)"
    ),
    "coefficients2": (
        "give link 2's parameters per contact: forces=granrs.forces.thesis(link1, link2) "
        "(or granrs.cases.chain(..., coefficients=(link1, link2)))"
    ),
    "effects": (
        "list the terms that act: forces=granrs.forces.select(scene.forces, 'gravity', "
        "'static_v') or forces=[granrs.forces.gravity(), granrs.forces.static_v(...)]"
    ),
}


def _names(value: Any, field_name: str, allowed: tuple[str, ...]) -> tuple[str, ...]:
    if isinstance(value, str) or not isinstance(value, Iterable):
        raise InvalidParameterError(
            f"{field_name} must be a list of names from {', '.join(allowed)}; got {value!r}",
            field=field_name,
        )
    names = tuple(value)
    for name in names:
        if name not in allowed:
            raise UnknownNameError(
                f"unknown {field_name} entry {name!r}; allowed: {', '.join(allowed)}",
                field=field_name,
            )
    return names


def _joint(value: Any, field_name: str) -> str | dict[str, float]:
    if isinstance(value, str):
        if value not in JOINTS:
            raise UnknownNameError(
                f"unknown {field_name} {value!r}; allowed: 'free', 'locked' or "
                "{'k': N m/rad, 'c': N m s/rad}",
                field=field_name,
            )
        return value
    if isinstance(value, Mapping):
        spec = dict(value)
        extra = set(spec) - {"k", "c"}
        if extra or not {"k", "c"} <= set(spec):
            raise InvalidParameterError(
                f"{field_name} as a spring-damper needs exactly the keys 'k' [N m/rad] and "
                f"'c' [N m s/rad]; got {sorted(spec)}",
                field=field_name,
            )
        return {"k": spec["k"], "c": spec["c"]}
    raise InvalidParameterError(
        f"{field_name} must be 'free', 'locked' or {{'k': .., 'c': ..}}; got {value!r}",
        field=field_name,
    )


#: Fields that only one or two bodies use (any other field applies to every body).
BODY_FIELDS: dict[str, tuple[str, ...]] = {
    "length": ("free_link", "chain"),
    "diameter": ("free_link", "chain"),
    "mass": ("free_link", "chain"),
    "inertia": ("free_link", "chain"),
    "q_deg": ("free_link", "chain"),
    "omega0": ("free_link", "chain"),
    "q2_deg": ("chain",),
    "pin_mass": ("chain",),
    "pin_joint": ("chain",),
    "body_mass": ("leg",),
    "height": ("leg",),
    "foot_length": ("leg",),
    "shoe_width": ("leg",),
    "tibia_length": ("leg",),
    "sole_height": ("leg",),
    "ankle": ("leg",),
    "knee": ("leg",),
    "hip": ("leg",),
    "knee_deg": ("leg",),
    "hip_deg": ("leg",),
    "trunk_deg": ("leg",),
    "foot_deg": ("leg",),
    "sole_model": ("leg",),
}


@dataclass(frozen=True)
class Scene:
    """One impact of a body with sand.

    Attributes:
        body: the body model: ``"free_link"`` (a round rod, 3 degrees of freedom),
            ``"chain"`` (two rods pinned at their top ends, 4) or ``"leg"`` (foot, shank,
            thigh, half trunk, 6).
        length: rod length L [m] (thesis sec. 3.2.1: 0.190); each chain link's.
        diameter: rod diameter d_c [m] (thesis sec. 3.2.1: 0.0127); each chain link's.
        mass: body mass m [kg] (thesis sec. 3.2.1: 0.184); each chain link's.
        inertia: moment of inertia about the centre of mass [kg m^2]; ``None`` for a solid
            cylinder, m (L^2/12 + d_c^2/16).
        rho_g: bulk density of the sand, packing included [kg/m^3] (thesis sec. 3.3.1: 1650).
        g: gravitational acceleration [m/s^2] (9.81).
        coefficients_source: where the force terms' parameters come from (for reports; not
            used by the run).
        q_deg: initial angle of the rod (chain: link 1) from the vertical [deg],
            -90 < q_deg < 90.
        v0: initial downward speed [m/s], >= 0.
        depth0: initial depth of the tip [m], >= 0 (0: at the surface, as in the thesis).
        vx0: initial horizontal velocity of the tip [m/s].
        omega0: initial angular velocity dq/dt [rad/s].
        apply_at: ``"tip"`` (default; the thesis's CAD runs, sec. 3.3.2) or ``"centroid"``
            (the immersed centroid E, sec. 3.3.1; strictly dissipative).
        sign_model: ``"modes"`` (default: each sign held through a step, switches located
            exactly, sticking handled), ``"raw"`` (the thesis's plain sign) or ``"smooth"``
            (tanh(v / smooth_eps)).
        smooth_eps: velocity scale of the ``"smooth"`` sign model [m/s].
        forces: the force terms that act, a list of :mod:`granrs.forces` terms, each with
            its parameters (one value for every contact or one per contact). Default: the
            thesis's law (gravity, drag, static_h, static_v, joint_springs) with each term's
            defaults, Table 3.4 at q = 0. A term not listed is neither computed nor stored,
            and a spring-damper joint is free without ``joint_springs``; ``[]``: nothing acts.
        dt: step of the fixed-step RK4 [s] (thesis sec. 3.3.2: 10 kHz, 1e-4); the first
            step of ``"dopri5"``.
        method: ``"rk4"`` (default: classical RK4 on the grid n dt) or ``"dopri5"``
            (adaptive Dormand-Prince 5(4) with tolerances ``rtol`` and ``atol``).
        rtol: relative tolerance of ``"dopri5"``.
        atol: absolute tolerance of ``"dopri5"`` [SI units of each coordinate].
        t_end: latest end time [s].
        end: ``"first_stop"`` (the thesis's end of the penetration phase), ``"all_stops"``
            or ``"time"``.
        record: time series to record, from ``RECORDS`` (none by default).
        record_stride: record every n-th step (events are always recorded).

    Chain only (thesis chapter 4):
        q2_deg: link 2's angle from the vertical [deg]; ``None``: -q_deg (mirror image).
        pin_mass: mass of the pin, a point mass at the joint [kg] (0).
        pin_joint: the pin: ``"free"`` (the thesis's frictionless joint, sec. 4.1),
            ``"locked"`` or ``{"k": .., "c": ..}`` (rest angle: the initial one).

    Leg only (thesis chapter 5; segment data from Winter 2009, Table 4.1 and Fig. 4.1,
    after Dempster 1955; see :func:`granrs.cases.leg`):
        body_mass: body mass [kg] (sec. 5.2.1: 75.35); the leg carries half of it.
        height: body height H [m] (sec. 5.2.1: 1.78).
        foot_length: foot size f_s [m] (sec. 5.3.2: 0.254).
        shoe_width: shoe width w_s [m] (sec. 5.3.2: 0.086).
        tibia_length: tibia l_l [m] (sec. 5.3.2: 0.432): the shank and L_ref of eq. 5.4.
        sole_height: height of the contact box above the sole [m]; ``None``: the tibia
            length (the sole's footprint carried up the leg, so V keeps growing as
            f_s w_s d past the ankle, as eq. 5.7 does); 0.039 H lets only the shoe count.
        ankle, knee, hip: each ``"locked"`` (default), ``"free"`` or a spring-damper
            ``{"k": N m/rad, "c": N m s/rad}`` relaxed at the touchdown posture.
        knee_deg, hip_deg: flexion at touchdown [deg] (granrs assumption: 20, 20).
        trunk_deg: trunk lean forward [deg] (granrs assumption: 10).
        foot_deg: sole pitch, toe up [deg] (0: flat landing).
        sole_model: ``"box"`` (the geometric box of MODEL.md) or ``"thesis"`` (eqs.
            5.5-5.7 with the shank's angle; finite only for 1 <= |shank angle| <= 89 deg).
    """

    body: str = "free_link"
    length: float = 0.190
    diameter: float = 0.0127
    mass: float = 0.184
    inertia: float | None = None
    rho_g: float = 1650.0
    g: float = 9.81
    coefficients_source: str = "Table 3.4, row q = 0 deg"
    q_deg: float = 0.0
    v0: float = 2.214
    depth0: float = 0.0
    vx0: float = 0.0
    omega0: float = 0.0
    apply_at: str = "tip"
    sign_model: str = "modes"
    smooth_eps: float = 1e-3
    forces: tuple[Term, ...] = _THESIS_DEFAULT
    dt: float = 1e-4
    method: str = "rk4"
    rtol: float = 1e-8
    atol: float = 1e-10
    t_end: float = 1.0
    end: str = "first_stop"
    record: tuple[str, ...] = ()
    record_stride: int = 1
    q2_deg: float | None = None
    pin_mass: float = 0.0
    pin_joint: JointSpec = "free"
    body_mass: float = 75.35
    height: float = 1.78
    foot_length: float = 0.254
    shoe_width: float = 0.086
    tibia_length: float = 0.432
    sole_height: float | None = None
    ankle: JointSpec = "locked"
    knee: JointSpec = "locked"
    hip: JointSpec = "locked"
    knee_deg: float = 20.0
    hip_deg: float = 20.0
    trunk_deg: float = 10.0
    foot_deg: float = 0.0
    sole_model: str = "box"

    def __post_init__(self) -> None:
        if self.body not in BODIES:
            raise UnknownNameError(
                f"unknown body {self.body!r}; allowed: {', '.join(BODIES)}", field="body"
            )
        for name in _NOT_NONE:
            if getattr(self, name) is None:
                raise InvalidParameterError(
                    f"{name} must be a value, not None (its default: {_DEFAULTS[name]!r})",
                    field=name,
                )
        for name in ("pin_joint", "ankle", "knee", "hip"):
            object.__setattr__(self, name, _joint(getattr(self, name), name))
        defaults = _DEFAULTS
        for name, bodies in BODY_FIELDS.items():
            if self.body not in bodies and getattr(self, name) != defaults[name]:
                raise InvalidSceneError(
                    f"{name} applies to body {' or '.join(repr(b) for b in bodies)} only, "
                    f"not {self.body!r}",
                    field=name,
                )
        object.__setattr__(self, "forces", as_terms(self.forces))
        object.__setattr__(self, "record", _names(self.record, "record", RECORDS))

    def replace(self, **changes: Any) -> Scene:
        """A copy with some fields changed; an unknown field raises UnknownNameError."""
        known = {f.name for f in dataclasses.fields(self)}
        for name in changes:
            if name in _REPLACED:
                raise UnknownNameError(
                    f"Scene has no field {name!r} any more: {_REPLACED[name]}", field=name
                )
            if name not in known:
                raise UnknownNameError(
                    f"Scene has no field {name!r}; fields: {', '.join(sorted(known))}",
                    field=name,
                )
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """The scene as plain Python values, every field (a new dict)."""
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        d["forces"] = [t.to_dict() for t in self.forces]
        d["record"] = list(self.record)
        return d

    def _plain(self) -> dict[str, Any]:
        """What the Rust core reads: the fields of this scene's body as plain values, built
        once per scene (it is frozen) and shared. Callers must not change it."""
        cached: dict[str, Any] | None = self.__dict__.get("_plain_cache")
        if cached is None:
            fields = self.__dict__
            cached = {name: fields[name] for name in _CORE_FIELDS[self.body]}
            cached["forces"] = list(self.forces)
            cached["record"] = list(self.record)
            object.__setattr__(self, "_plain_cache", cached)
        return cached

    def __getstate__(self) -> dict[str, Any]:
        # Pickle (Dask, multiprocessing) and copy the fields, not the caches of the core.
        return {k: v for k, v in self.__dict__.items() if not k.endswith("_cache")}

    def _compiled(self) -> Any:
        """The scene converted and validated by the core, once per scene (it is frozen)."""
        # The core keeps it in self.__dict__["_compiled_cache"] (what object.__setattr__
        # does for a frozen dataclass).
        return _granrs.compiled_scene(self.__dict__, _CORE_FIELDS)

    def validate(self) -> Scene:
        """Check every field in the Rust core; raise the typed error naming the first bad one."""
        _granrs.validate(self.to_dict())
        return self

    def leg_segments(self) -> list[dict[str, Any]]:
        """The leg's segments scaled to this scene's body: name, mass [kg], length [m], com
        (from the segment's lower joint) [m], inertia about the centre of mass [kg m^2]."""
        if self.body != "leg":
            raise InvalidSceneError("leg_segments() needs body='leg'", field="body")
        return list(_granrs.leg_segments(self.to_dict()))

    @property
    def q_rad(self) -> float:
        """Initial angle from the vertical [rad]."""
        return math.radians(self.q_deg)

    @classmethod
    def from_toml(cls, path_or_text: Any) -> Scene:
        """A validated scene from a TOML scene file (a ``str`` or ``os.PathLike`` path) or
        TOML text (a ``str`` holding a newline or an ``=``); see :mod:`granrs.scenefile`.
        Errors name the key and its line."""
        from . import scenefile

        if isinstance(path_or_text, str) and ("\n" in path_or_text or "=" in path_or_text):
            return scenefile.loads(path_or_text)
        return scenefile.load(path_or_text)

    def to_toml(self, path: Any = None) -> str:
        """The scene as TOML text (every field of its body, floats exact); also written to
        ``path`` (a ``str`` or ``os.PathLike``) if given.
        ``Scene.from_toml(scene.to_toml()) == scene``."""
        from . import scenefile

        return scenefile.dumps(self) if path is None else scenefile.dump(self, path)


_DEFAULTS: dict[str, Any] = {
    f.name: f.default for f in dataclasses.fields(Scene) if f.default is not dataclasses.MISSING
}
#: Per body, the fields the Rust core reads (those of the body; not coefficients_source).
_CORE_FIELDS: dict[str, tuple[str, ...]] = {
    body: tuple(
        f.name
        for f in dataclasses.fields(Scene)
        if body in BODY_FIELDS.get(f.name, (body,)) and f.name != "coefficients_source"
    )
    for body in BODIES
}
#: Fields whose default is a value: None is refused for them.
_NOT_NONE: tuple[str, ...] = tuple(
    f.name for f in dataclasses.fields(Scene) if f.default is not None and f.name != "body"
)
