"""The thesis's cases as ready-made scenes.

* :func:`free_link`: the steel rod of chapter 3 (sec. 3.2.1) dropped tip first.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from .coefficients import Coefficients, resolve
from .errors import InvalidParameterError
from .scene import Scene

__all__ = ["FREE_LINK", "free_link"]

#: The thesis's free link (sec. 3.2.1 and 3.3.1): SI units.
FREE_LINK: dict[str, float] = {
    "length": 0.190,
    "diameter": 0.0127,
    "mass": 0.184,
    "rho_g": 1650.0,
}


def _number(value: Any, field: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        try:
            import numpy as np

            if isinstance(value, np.floating | np.integer):
                return float(value)
        except ImportError:  # pragma: no cover
            pass
        raise InvalidParameterError(f"{field} must be a number, got {value!r}", field=field)
    return float(value)


def free_link(
    q_deg: float,
    v0: float,
    coefficients: str | Coefficients | Mapping[str, float] = "table_3_4",
    dt: float = 1e-4,
    apply_at: str = "tip",
    **overrides: Any,
) -> Scene:
    """The thesis's free link (L = 0.190 m, d_c = 0.0127 m, m = 0.184 kg, rho_g = 1650 kg/m^3)
    dropped with its tip at the surface, at ``q_deg`` from the vertical, moving straight down
    at ``v0`` [m/s].

    ``coefficients`` is ``"table_3_4"`` (the thesis's row at the nearest tabulated angle; the
    scene's ``coefficients_source`` says which), ``"table_3_2"`` (the closed forms at q and
    rho_g), or a :class:`~granrs.Coefficients` (or mapping). ``overrides`` set any other
    :class:`~granrs.Scene` field (e.g. ``mass=0.2``, ``record=("state", "forces")``).
    Invalid input raises a :class:`~granrs.errors.InvalidSceneError` subclass naming the field.
    """
    q = _number(q_deg, "q_deg")
    if not math.isfinite(q) or abs(q) >= 90.0:
        raise InvalidParameterError(
            f"q_deg must be finite with -90 < q_deg < 90 (the tip meets the sand first); got {q}",
            field="q_deg",
        )
    rho_g = overrides.get("rho_g", FREE_LINK["rho_g"])
    coef, source = resolve(coefficients, q, rho_g)
    base = Scene(
        body="free_link",
        q_deg=q,
        v0=_number(v0, "v0"),
        coefficients=coef,
        coefficients_source=source,
        dt=_number(dt, "dt"),
        apply_at=apply_at,
        **{k: v for k, v in FREE_LINK.items() if k not in overrides},
    )
    scene = base.replace(**overrides) if overrides else base
    return scene.validate()
