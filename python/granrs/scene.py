"""What a run is: :class:`Scene`, a frozen description of one impact.

A scene is plain data: the body and its size, the sand, the coefficients of the force law,
the initial state, the step, the end condition, the force terms (effects) to evaluate and
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
from dataclasses import dataclass, field
from typing import Any

from . import _granrs
from .coefficients import Coefficients
from .errors import InvalidParameterError, UnknownNameError

__all__ = ["EFFECTS", "RECORDS", "Scene"]

#: Force terms a scene may list in ``effects``.
EFFECTS: tuple[str, ...] = ("gravity", "drag", "static_h", "static_v")
#: Time series a scene may list in ``record``.
RECORDS: tuple[str, ...] = ("state", "forces", "energy")

#: Table 3.4 of the thesis at q = 0 (the vertical rod).
_TABLE_3_4_VERTICAL = Coefficients(eta_h=6.5, eta_d=15.2, eta_v=248.0, lam=0.106)


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


@dataclass(frozen=True)
class Scene:
    """One impact of a body with sand.

    Attributes:
        body: the body model: ``"free_link"`` (a round rod, 3 degrees of freedom).
        length: rod length L [m] (thesis sec. 3.2.1: 0.190).
        diameter: rod diameter d_c [m] (thesis sec. 3.2.1: 0.0127).
        mass: body mass m [kg] (thesis sec. 3.2.1: 0.184).
        inertia: moment of inertia about the centre of mass [kg m^2]; ``None`` for a solid
            cylinder, m (L^2/12 + d_c^2/16).
        rho_g: bulk density of the sand, packing included [kg/m^3] (thesis sec. 3.3.1: 1650).
        g: gravitational acceleration [m/s^2] (9.81).
        coefficients: the force law's coefficients (default: Table 3.4 at q = 0).
        coefficients_source: where the coefficients come from (for reports; not used).
        q_deg: initial angle of the rod from the vertical [deg], -90 < q_deg < 90.
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
        effects: the force terms to evaluate, from ``EFFECTS``; a term not listed is neither
            computed nor stored.
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
    """

    body: str = "free_link"
    length: float = 0.190
    diameter: float = 0.0127
    mass: float = 0.184
    inertia: float | None = None
    rho_g: float = 1650.0
    g: float = 9.81
    coefficients: Coefficients = field(default=_TABLE_3_4_VERTICAL)
    coefficients_source: str = "Table 3.4, row q = 0 deg"
    q_deg: float = 0.0
    v0: float = 2.214
    depth0: float = 0.0
    vx0: float = 0.0
    omega0: float = 0.0
    apply_at: str = "tip"
    sign_model: str = "modes"
    smooth_eps: float = 1e-3
    effects: tuple[str, ...] = EFFECTS
    dt: float = 1e-4
    method: str = "rk4"
    rtol: float = 1e-8
    atol: float = 1e-10
    t_end: float = 1.0
    end: str = "first_stop"
    record: tuple[str, ...] = ()
    record_stride: int = 1

    def __post_init__(self) -> None:
        coefficients = self.coefficients
        if isinstance(coefficients, Mapping):
            coefficients = Coefficients(**dict(coefficients))
        if not isinstance(coefficients, Coefficients):
            raise InvalidParameterError(
                f"coefficients must be a granrs.Coefficients, got {type(coefficients).__name__}",
                field="coefficients",
            )
        object.__setattr__(self, "coefficients", coefficients)
        object.__setattr__(self, "effects", _names(self.effects, "effects", EFFECTS))
        object.__setattr__(self, "record", _names(self.record, "record", RECORDS))

    def replace(self, **changes: Any) -> Scene:
        """A copy with some fields changed; an unknown field raises UnknownNameError."""
        known = {f.name for f in dataclasses.fields(self)}
        for name in changes:
            if name not in known:
                raise UnknownNameError(
                    f"Scene has no field {name!r}; fields: {', '.join(sorted(known))}",
                    field=name,
                )
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """The scene as plain Python values (the form the Rust core reads)."""
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        d["coefficients"] = self.coefficients.as_dict()
        d["effects"] = list(self.effects)
        d["record"] = list(self.record)
        return d

    def validate(self) -> Scene:
        """Check every field in the Rust core; raise the typed error naming the first bad one."""
        _granrs.validate(self.to_dict())
        return self

    @property
    def q_rad(self) -> float:
        """Initial angle from the vertical [rad]."""
        return math.radians(self.q_deg)
