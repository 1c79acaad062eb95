"""The thesis's cases as ready-made scenes.

* :func:`free_link`: the steel rod of chapter 3 (sec. 3.2.1) dropped tip first.
* :func:`chain`: the two-link chain of chapter 4 (sec. 4.1), cases 1-3 of Table 4.1.
* :func:`leg`: one leg of a person landing on both feet (chapter 5), v0 = 3.28 or 2.35 m/s.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from . import data, forces, scenefile
from .coefficients import Coefficients, resolve
from .errors import InvalidParameterError, UnknownNameError
from .scene import _REPLACED, BODIES, OWN_FORCES, Scene, leg_row, unknown_field_message

__all__ = ["CHAIN", "FREE_LINK", "LEG", "chain", "chain_case", "free_link", "leg", "template"]

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
    try:
        return float(value)
    except OverflowError:  # an int beyond the floats (10**400): not finite, refused by name
        return math.inf


def _check_overrides(function: str, overrides: Mapping[str, Any], own: tuple[str, ...]) -> None:
    """An unknown keyword of a case function raises UnknownNameError with the closest of its
    parameters and the Scene's fields (Python's own TypeError says neither)."""
    fields = [f.name for f in dataclasses.fields(Scene)]
    for name in overrides:
        if name not in fields and name not in _REPLACED:
            raise UnknownNameError(
                unknown_field_message(
                    name, [*own, *fields], f"{function}() takes no parameter and Scene no field"
                ),
                field=name,
            )


def free_link(
    q_deg: float | None = None,
    v0: float | None = None,
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
    Invalid input raises a :class:`~granrs.errors.InvalidSceneError` subclass naming the field
    (``q_deg`` and ``v0`` are required; an unknown keyword names the closest field).
    """
    _check_overrides("free_link", overrides, ("q_deg", "v0", "coefficients", "dt", "apply_at"))
    for name, value in (("q_deg", q_deg), ("v0", v0)):
        if value is None:
            raise InvalidParameterError(
                f"free_link() needs {name} (q_deg: deg from the vertical; v0: m/s downward)",
                field=name,
            )
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
        **_law(coef, None, source, overrides),
        dt=_number(dt, "dt"),
        apply_at=apply_at,
        **{k: v for k, v in FREE_LINK.items() if k not in overrides},
    )
    scene = base.replace(**overrides) if overrides else base
    return scene.validate()


#: The thesis's chain (sec. 4.1): SI units. The link mass is not in the thesis: a solid
#: steel cylinder (7850 kg/m^3) of the stated size (``bodies.csv``); the thesis's play sand
#: of chapter 3 (1650 kg/m^3) is assumed.
CHAIN: dict[str, float] = {
    "length": 0.135,
    "diameter": 0.0064,
    "mass": 0.0341,
    "rho_g": 1650.0,
}

#: The thesis's person and sand (secs. 5.2.1 and 5.3.2): SI units.
LEG: dict[str, float] = {
    "body_mass": 75.35,
    "height": 1.78,
    "foot_length": 0.254,
    "shoe_width": 0.086,
    "tibia_length": 0.432,
    "rho_g": 1600.0,
}


def _law(
    c1: Coefficients, c2: Coefficients | None, source: str, overrides: Mapping[str, Any]
) -> dict[str, Any]:
    """The scene fields of a case's force law: the thesis's terms with its coefficient
    table's row(s) as their parameters, unless the caller gives ``forces=``."""
    if "forces" in overrides:
        return {"coefficients_source": OWN_FORCES}
    rows = (c1,) if c2 is None else (c1, c2)
    return {"forces": forces.thesis(*rows), "coefficients_source": source}


def _coefficients_arg(value: Any, field: str) -> Coefficients:
    if isinstance(value, Coefficients):
        return value
    if isinstance(value, Mapping):
        return resolve(value, 0.0)[0]  # its keys and values checked, typed errors
    raise InvalidParameterError(
        f"{field} must be a granrs.Coefficients or a mapping of eta_h, eta_d, eta_v, lam; "
        f"got {value!r}",
        field=field,
    )


def _row_coefficients(table: Mapping[str, Any], row: int) -> Coefficients:
    """The coefficients in row ``row`` of a shipped table (columns eta_h, eta_d, eta_v, lambda)."""
    return Coefficients(
        eta_h=float(table["eta_h"][row]),
        eta_d=float(table["eta_d"][row]),
        eta_v=float(table["eta_v"][row]),
        lam=float(table["lambda"][row]),
    )


def chain_case(case: int) -> dict[str, Any]:
    """The thesis's chain case ``case`` (1, 2 or 3): per link the measured angle and speed
    (Table 4.1 / 4.2) and the coefficients of Table 4.4, with the chain's v0 (the mean of the
    two links' measured speeds: the chain falls as one body).

    Returns a dict with ``q_deg`` (two angles), ``v0_links``, ``v0``, ``coefficients`` (two
    :class:`~granrs.Coefficients`) and ``sources`` (two strings).
    """
    if (
        isinstance(case, bool | np.bool_)
        or not isinstance(case, int | float | np.number)
        or case not in (1, 2, 3)
    ):
        raise InvalidParameterError(f"case must be 1, 2 or 3; got {case!r}", field="case")
    exp = data.load("chain_experiments", as_="numpy")
    coef = data.load("chain_coefficients", as_="numpy")
    q, v, cs, sources = [], [], [], []
    for link in (1, 2):
        row = int(np.flatnonzero((exp["link"] == link) & (exp["v0_case"] == case))[0])
        q.append(float(exp["q0_deg"][row]))
        v.append(float(exp["v0_mean"][row]))
        crow = int(np.flatnonzero((coef["link"] == link) & (coef["v0_case"] == case))[0])
        cs.append(_row_coefficients(coef, crow))
        note = str(coef["note"][crow])
        sources.append(
            f"Table 4.4, link {link}, case {case}"
            + (
                " (row missing in the thesis: Table 4.3 expressions at alpha = 74 deg)"
                if note
                else ""
            )
        )
    return {
        "q_deg": tuple(q),
        "v0_links": tuple(v),
        "v0": 0.5 * (v[0] + v[1]),
        "coefficients": tuple(cs),
        "sources": tuple(sources),
    }


def chain(
    case: int = 1,
    q1_deg: float | None = None,
    q2_deg: float | None = None,
    coefficients: Coefficients | Mapping[str, float] | tuple[Any, Any] | None = None,
    dt: float = 1e-4,
    apply_at: str = "tip",
    **overrides: Any,
) -> Scene:
    """The thesis's two-link chain (sec. 4.1: L = 0.135 m, d = 0.0064 m per link, pinned at
    the top ends) falling onto sand, case ``case`` of Table 4.1 (1: v0 ~ 2.58, 2: ~2.29,
    3: ~1.60 m/s).

    The angles default to the case's measured ones (Table 4.1) and v0 to the mean of the two
    links' measured speeds. ``coefficients``: ``None`` for Table 4.4's row of each link, one
    :class:`~granrs.Coefficients` (or mapping) for both links, or a pair (link 1, link 2).
    The link mass is not in the thesis: the default 0.0341 kg is a solid steel link; pass
    ``mass=0.017`` (or any) to change it, and ``pin_mass`` for the pin. ``overrides`` set any
    other :class:`~granrs.Scene` field.
    """
    _check_overrides(
        "chain", overrides, ("case", "q1_deg", "q2_deg", "coefficients", "dt", "apply_at")
    )
    spec = chain_case(case)
    q1 = spec["q_deg"][0] if q1_deg is None else _number(q1_deg, "q1_deg")
    q2 = spec["q_deg"][1] if q2_deg is None else _number(q2_deg, "q2_deg")
    if coefficients is None:
        c1, c2 = spec["coefficients"]
        source = f"{spec['sources'][0]}; {spec['sources'][1]}"
    elif isinstance(coefficients, tuple):
        if len(coefficients) != 2:
            raise InvalidParameterError(
                "coefficients as a tuple must be (link 1, link 2)", field="coefficients"
            )
        c1 = _coefficients_arg(coefficients[0], "coefficients")
        c2 = _coefficients_arg(coefficients[1], "coefficients2")
        source = "user (per link)"
    else:
        c1 = c2 = _coefficients_arg(coefficients, "coefficients")
        source = "user (both links)"
    base = Scene(
        body="chain",
        q_deg=q1,
        q2_deg=q2,
        v0=spec["v0"],
        **_law(c1, c2, source, overrides),
        dt=_number(dt, "dt"),
        apply_at=apply_at,
        **{k: v for k, v in CHAIN.items() if k not in overrides},
    )
    scene = base.replace(**overrides) if overrides else base
    return scene.validate()


def leg(
    v0: float = 3.28,
    coefficients: Coefficients | Mapping[str, float] | None = None,
    joints: Any = None,
    dt: float = 1e-4,
    apply_at: str = "tip",
    **overrides: Any,
) -> Scene:
    """One leg of the thesis's average subject (75.35 kg, 1.78 m; foot 0.254 m, shoe 0.086 m,
    tibia 0.432 m; sec. 5.2.1 and 5.3.2) landing flat on fine sand (1600 kg/m^3) at ``v0``.

    ``coefficients``: ``None`` for the thesis's row (sec. 5.3.2) at the nearest of its two
    speeds, 3.28 and 2.35 m/s (the scene's ``coefficients_source`` says which). ``joints``
    sets ankle, knee and hip at once (``"locked"``, the default; ``"free"``; or a
    spring-damper ``{"k": N m/rad, "c": N m s/rad}``); ``ankle=``, ``knee=``, ``hip=``
    set one. Segment masses, lengths, centres of mass and inertias: Dempster's data as
    tabulated by Winter (2009, Table 4.1, Fig. 4.1), scaled to body mass and height; see
    :meth:`granrs.Scene.leg_segments`. ``overrides`` set any other :class:`~granrs.Scene`
    field (posture: ``knee_deg``, ``hip_deg``, ``trunk_deg``, ``foot_deg``).
    """
    _check_overrides("leg", overrides, ("v0", "coefficients", "joints", "dt", "apply_at"))
    v = _number(v0, "v0")
    if coefficients is None:
        coef, source = leg_row(v)
    else:
        coef = _coefficients_arg(coefficients, "coefficients")
        source = "user"
    joint_fields = {}
    if joints is not None:
        joint_fields = {name: joints for name in ("ankle", "knee", "hip")}
    fields = {**LEG, **joint_fields}
    base = Scene(
        body="leg",
        v0=v,
        **_law(coef, None, source, overrides),
        dt=_number(dt, "dt"),
        apply_at=apply_at,
        **{k: val for k, val in fields.items() if k not in overrides},
    )
    scene = base.replace(**overrides) if overrides else base
    return scene.validate()


def template(body: str) -> str:
    """A commented scene file for ``body``: the thesis's scene (this module's cases) with
    every field written out: the free link at q = 0 deg, v0 = 2.214 m/s (Table 3.5 row 1),
    chain case 1 (Table 4.1), the leg at 3.28 m/s (sec. 5.3.2)."""
    if body == "free_link":
        scene = free_link(q_deg=0.0, v0=2.214)
        what = "the thesis's free link (sec. 3.2.1), vertical, v0 = 2.214 m/s"
    elif body == "chain":
        scene = chain(case=1)
        what = "the thesis's two-link chain, case 1 of Table 4.1"
    elif body == "leg":
        scene = leg(v0=3.28)
        what = "one leg of the thesis's subject (chapter 5) landing at 3.28 m/s"
    else:
        raise UnknownNameError(f"unknown body {body!r}; allowed: {', '.join(BODIES)}", field="body")
    return scenefile.dumps(
        scene, header=f"Template: {what}. Edit any value; delete a line for its default."
    )
