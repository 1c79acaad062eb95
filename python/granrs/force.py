"""``granrs.resistance_force``: the force law on its own, vectorized over numpy arrays.

For users who couple granrs's granular resistance force to their own simulator (a
multibody code, a robot model, a controller): give the kinematics of a rod's contact and get
the force components, evaluated in the Rust core with the GIL released.

The model (``docs/model.md``; thesis eqs. 2.1-2.4, 3.1-3.3 and 3.13-3.15), for a rod whose tip T is
at depth ``d`` with angle ``q`` from the vertical, tip velocity ``(vx, vy)`` and angular
velocity ``omega = dq/dt``:

- immersed length ``l = min(d / cos q, L)``; centroid ``E = T + (l/2) e``, ``e = (sin q,
  cos q)``; ``v_E = (vx, vy) + (l/2) omega (cos q, -sin q)``;
- ``F_d = -eta_d rho_g d_c l |e x v_E| v_E`` (``A_r |v_E| = d_c l |e x v_E|``);
- ``F_sh = -sgn(v_Ex) eta_h g rho_g d_c d^2`` along x;
- ``F_sv = -sgn(v_Ey) eta_v (d/L)^lambda g rho_g (pi d_c^2 / 4) l`` along y.

The simulator in granrs applies the sum at the tip T by default (the thesis's CAD runs) or
at E; the offset ``E - T`` is returned so that either can be reproduced.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any, NamedTuple

import numpy as np

from . import _granrs, forces
from .coefficients import Coefficients
from .errors import InvalidParameterError

__all__ = ["ResistanceForce", "resistance_force"]

#: The thesis's law at its terms' defaults (Table 3.4 at q = 0), read from the registry.
_DEFAULT_COEFFICIENTS: Coefficients = forces.thesis_row(forces.thesis())
#: The thesis's terms that act on a contact (the others have no force here).
_THESIS_CONTACT_TERMS: tuple[str, ...] = tuple(
    name for name in forces.THESIS_TERMS if forces.info(name).acts == "contact"
)


class ResistanceForce(NamedTuple):
    """The force on each state, as arrays of the broadcast input shape.

    Attributes:
        F_x, F_y: the total resistance force F_R = F_d + F_s [N].
        F_dx, F_dy: the dynamic drag F_d [N].
        F_sh: the static horizontal term (x) [N].
        F_sv: the static vertical term (y) [N].
        immersed_length: immersed length l [m].
        E_x, E_y: the immersed centroid E relative to the tip T [m].
        v_E: speed of E, |v_E| [m/s].
    """

    F_x: np.ndarray
    F_y: np.ndarray
    F_dx: np.ndarray
    F_dy: np.ndarray
    F_sh: np.ndarray
    F_sv: np.ndarray
    immersed_length: np.ndarray
    E_x: np.ndarray
    E_y: np.ndarray
    v_E: np.ndarray


def _array(name: str, value: Any) -> np.ndarray:
    if type(value) is np.ndarray and value.dtype == np.float64:
        return value
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidParameterError(
            f"{name} must be a number or an array of numbers; got {type(value).__name__}",
            field=name,
        ) from exc


def _scalar(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise InvalidParameterError(
            f"{name} must be a real number; got {type(value).__name__}", field=name
        )
    return float(value)


def resistance_force(
    depth: Any,
    q_deg: Any,
    vx: Any,
    vy: Any,
    omega: Any = 0.0,
    *,
    coefficients: Coefficients | Mapping[str, Any] | None = None,
    length: float = 0.190,
    diameter: float = 0.0127,
    rho_g: float = 1650.0,
    g: float = 9.81,
    effects: Iterable[str] = _THESIS_CONTACT_TERMS,
    sign_model: str = "raw",
    smooth_eps: float = 1e-3,
) -> ResistanceForce:
    """The granular resistance force on a rod, for arrays of contact states.

    Every array argument broadcasts against the others (numpy rules); scalars are fine.

    Args:
        depth: depth of the tip below the surface, d [m]; 0 or less: no force.
        q_deg: angle of the rod from the vertical [deg], -90 < q_deg < 90.
        vx, vy: velocity of the tip [m/s] (y up: a sinking tip has vy < 0).
        omega: angular velocity dq/dt [rad/s].
        coefficients: a :class:`granrs.Coefficients`, or a mapping of ``eta_h``, ``eta_d``,
            ``eta_v``, ``lam`` to numbers or arrays (default: the defaults of the terms,
            :func:`granrs.forces.thesis`: Table 3.4 at q = 0).
        length: rod length L [m] (also L_ref; thesis sec. 3.2.1: 0.190).
        diameter: rod diameter d_c [m] (also the width w; thesis sec. 3.2.1: 0.0127).
        rho_g: bulk density of the sand [kg/m^3] (thesis sec. 3.3.1: 1650).
        g: gravitational acceleration [m/s^2].
        effects: the force terms to evaluate, from ``drag``, ``static_h``, ``static_v``
            (the names of :mod:`granrs.forces`; ``gravity`` and ``joint_springs`` are accepted
            and have no force here).
        sign_model: ``"raw"`` (the thesis's sign(): 0 at zero velocity) or ``"smooth"``
            (``tanh(v / smooth_eps)``). The simulator's default ``"modes"`` holds signs
            through a step and needs a time history, so it is not offered here.
        smooth_eps: velocity scale of ``"smooth"`` [m/s].

    Returns:
        A :class:`ResistanceForce` of arrays of the broadcast shape.

    Raises:
        InvalidParameterError: a non-finite value, an angle out of range or a negative
            coefficient, naming the field and the first bad index, before any evaluation.

    Example:
        >>> import granrs
        >>> f = granrs.resistance_force(depth=0.05, q_deg=0.0, vx=0.0, vy=-1.0)
        >>> round(float(f.F_sv), 2)
        22.07
    """
    c = _DEFAULT_COEFFICIENTS if coefficients is None else coefficients
    if isinstance(c, Coefficients):
        c = c.as_dict()
    if not isinstance(c, Mapping):
        raise InvalidParameterError(
            "coefficients must be a granrs.Coefficients or a mapping of eta_h, eta_d, eta_v, "
            f"lam; got {type(c).__name__}",
            field="coefficients",
        )
    missing = {"eta_h", "eta_d", "eta_v", "lam"} - set(c)
    extra = set(c) - {"eta_h", "eta_d", "eta_v", "lam"}
    if missing or extra:
        raise InvalidParameterError(
            f"coefficients needs exactly eta_h, eta_d, eta_v, lam; missing {sorted(missing)}, "
            f"unknown {sorted(extra)}",
            field="coefficients",
        )
    if isinstance(effects, str):
        raise InvalidParameterError(
            "effects must be a list of names, e.g. ('drag', 'static_v')", field="effects"
        )
    names = ("depth", "q_deg", "vx", "vy", "omega", "eta_h", "eta_d", "eta_v", "lam")
    values = (depth, q_deg, vx, vy, omega, c["eta_h"], c["eta_d"], c["eta_v"], c["lam"])
    arrays = [_array(n, v) for n, v in zip(names, values, strict=True)]
    shapes = {a.shape for a in arrays if a.size != 1}
    if len(shapes) <= 1:
        # The common cases: scalars, and arrays of one shape. Scalars go to the core as one
        # value (broadcast there without copying), arrays as flat views.
        shape = shapes.pop() if shapes else np.broadcast_shapes(*(a.shape for a in arrays))
        flat = [np.ascontiguousarray(a).reshape(-1) for a in arrays]
    else:
        try:
            shaped = np.broadcast_arrays(*arrays)
        except ValueError as exc:
            listed = ", ".join(f"{n} {a.shape}" for n, a in zip(names, arrays, strict=True))
            raise InvalidParameterError(
                f"the arrays do not broadcast together: {listed}", field="depth"
            ) from exc
        shape = shaped[0].shape
        flat = [
            a.reshape(1) if a.size == 1 else np.ascontiguousarray(b).reshape(-1)
            for a, b in zip(arrays, shaped, strict=True)
        ]
    out = _granrs.resistance_force(
        flat,
        _scalar("length", length),
        _scalar("diameter", diameter),
        _scalar("rho_g", rho_g),
        _scalar("g", g),
        [str(e) for e in effects],
        str(sign_model),
        _scalar("smooth_eps", smooth_eps),
    )
    return ResistanceForce(*(out[:, k].reshape(shape) for k in range(out.shape[1])))
