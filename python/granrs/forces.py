"""Force terms: what acts on a body in a scene (:attr:`granrs.Scene.forces`).

A term is one unit of physics with its own parameters: the thesis's law is the terms
:func:`drag`, :func:`static_h` and :func:`static_v` (their coefficients are the terms'
parameters), and :func:`gravity` and :func:`joint_springs` are terms too. A scene lists the
terms that act; a term that is not listed is neither evaluated nor stored, and its sign
switches are not watched. ``forces=[]`` means nothing acts.

Everything known about a term (its equation, parameters with units, defaults and their
sources, the switches it owns, its series columns) comes from the Rust core's registry
(``rust/forces/``), the one description that validation, TOML, the docs and the error
messages all read: ``granrs.forces.drag().info``.

A parameter is a number for every contact, or a tuple with one value per contact (the
chain's two links)::

    >>> import granrs
    >>> granrs.forces.static_v(eta_v=248.0, lam=0.106)
    static_v(eta_v=248.0, lam=0.106)
    >>> granrs.forces.term("drag", eta_d=(13.0, 10.0)).params["eta_d"]
    (13.0, 10.0)
    >>> granrs.forces.drag().info.params[0].unit
    '-'

Errors are both :class:`granrs.GranrsError` and :class:`ValueError`, name the term and the
parameter (``static_v.eta_v``), and suggest the near miss of a mistyped name.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from . import _granrs
from .errors import InvalidParameterError

__all__ = [
    "TERMS",
    "Param",
    "Term",
    "TermInfo",
    "drag",
    "gravity",
    "info",
    "joint_springs",
    "poncelet",
    "rft",
    "rft_alpha",
    "rft_inertial",
    "select",
    "static_h",
    "static_v",
    "term",
    "thesis",
    "thesis_row",
]

#: A parameter's value: one number for every contact, or one per contact.
ParamValue = float | tuple[float, ...]


@dataclass(frozen=True)
class Param:
    """One parameter of a term (from the core's registry).

    Attributes:
        name: its name (``static_v.eta_v`` in errors and calibration).
        unit: its unit (``"-"``: dimensionless).
        default: its default value.
        source: where the default comes from.
        min: smallest allowed value (inclusive); every value must also be finite.
        description: what it is.
        integer: whether it is a count (an integer >= ``min``).
        required: whether a scene must give it (no default; ``default`` is NaN).
        max: largest allowed value (inclusive; ``inf``: no bound). A count that sizes the
            work of every force evaluation (``elements``) has one.
    """

    name: str
    unit: str
    default: float
    source: str
    min: float
    description: str
    integer: bool = False
    required: bool = False
    max: float = math.inf


@dataclass(frozen=True)
class TermInfo:
    """Everything known about a term (from the core's registry).

    Attributes:
        name: the name a scene lists (``term = "name"`` in TOML).
        summary: one line: what the term is.
        equation: the term in granrs's frame (``docs/model.md``), as plain text.
        source: paper, thesis section and equation numbers.
        params: its parameters.
        acts: ``"contact"`` (on each contact in the sand) or ``"body"`` (through the
            mechanism: every link's weight, the joints).
        klass: ``"dynamic"`` (adds to the thesis's F_d) or ``"static"`` (to F_s).
        velocity_dependent: whether its magnitude grows with speed.
        reads: what it reads of the state.
        switches: the engine's sign switches it owns (located events with ``"modes"``).
        columns: its per-contact series columns with ``record=("forces",)``.
    """

    name: str
    summary: str
    equation: str
    source: str
    params: tuple[Param, ...]
    acts: str
    klass: str
    velocity_dependent: bool
    reads: str
    switches: tuple[str, ...]
    columns: tuple[str, ...]


def _load() -> dict[str, TermInfo]:
    out = {}
    for d in _granrs.term_infos():
        out[d["name"]] = TermInfo(
            name=d["name"],
            summary=d["summary"],
            equation=d["equation"],
            source=d["source"],
            params=tuple(Param(**p) for p in d["params"]),
            acts=d["acts"],
            klass=d["class"],
            velocity_dependent=d["velocity_dependent"],
            reads=d["reads"],
            switches=tuple(d["switches"]),
            columns=tuple(d["columns"]),
        )
    return out


_INFO: dict[str, TermInfo] = _load()

#: Every registered term's name, in the registry's order.
TERMS: tuple[str, ...] = tuple(_INFO)


def info(name: str) -> TermInfo:
    """The description of the term ``name`` (an unknown name raises, with a near miss)."""
    if name not in _INFO:
        _granrs.check_term(name, {})  # raises UnknownNameError naming it
    return _INFO[name]


@dataclass(frozen=True)
class Term:
    """One force term with its parameters, checked by the core when built.

    Build terms with the constructors of this module (:func:`drag`, ...) or :func:`term`.

    Attributes:
        name: the term's registered name.
        params: every parameter, defaults filled in: a float for every contact or a tuple
            with one value per contact (read-only).
    """

    name: str
    params: Mapping[str, ParamValue] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise InvalidParameterError(
                f"a term's name must be a string, got {self.name!r}", field="term"
            )
        if not isinstance(self.params, Mapping):
            raise InvalidParameterError(
                f"{self.name}: params must be a mapping, got {self.params!r}", field=self.name
            )
        checked = dict(_granrs.check_term(self.name, dict(self.params)))
        for p in _INFO[self.name].params:
            v = checked[p.name]
            if p.integer:
                checked[p.name] = tuple(int(x) for x in v) if isinstance(v, tuple) else int(v)
        object.__setattr__(self, "params", MappingProxyType(checked))

    @property
    def info(self) -> TermInfo:
        """The term's equation, parameters with units, source, switches and columns."""
        return _INFO[self.name]

    def to_dict(self) -> dict[str, Any]:
        """The term as plain values: ``{"term": name, param: float or list, ...}`` (the
        form of a TOML ``[[forces]]`` table)."""
        return {
            "term": self.name,
            **{k: list(v) if isinstance(v, tuple) else v for k, v in self.params.items()},
        }

    def replace(self, **params: ParamValue) -> Term:
        """A copy with some parameters changed (checked like the constructor)."""
        return Term(self.name, {**self.params, **params})

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.items())
        return f"{self.name}({args})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Term):
            return NotImplemented
        return self.name == other.name and dict(self.params) == dict(other.params)

    def __hash__(self) -> int:
        return hash((self.name, tuple(sorted(self.params.items()))))

    def __reduce__(self) -> tuple[Any, ...]:
        # Pickle (Dask, multiprocessing) by name and plain parameters.
        return (Term, (self.name, dict(self.params)))


def term(name: str, **params: ParamValue) -> Term:
    """Any registered term by its name, e.g. ``term("static_v", eta_v=248.0, lam=0.106)``.

    A parameter left out takes its default (``info(name).params``). An unknown term or
    parameter, or a bad value (NaN, negative), raises a :class:`granrs.GranrsError` that is
    also a :class:`ValueError`, naming ``term.parameter``, before any work starts.
    """
    return Term(name, params)


def gravity() -> Term:
    """``gravity``: the weight of every link, -m g y_hat at its centre of mass (g: the
    scene's, 9.81 m/s^2). Without it the body has no potential energy from gravity."""
    return Term("gravity", {})


def drag(eta_d: ParamValue = 15.2) -> Term:
    """``drag``: F_d = -eta_d rho_g A_r |v_E| v_E (thesis eqs. 2.1, 3.1, 3.13-3.14).

    Args:
        eta_d: dynamic scaling constant [-]; default 15.2, thesis Table 3.4 at q = 0.
    """
    return Term("drag", {"eta_d": eta_d})


def static_h(eta_h: ParamValue = 6.5) -> Term:
    """``static_h``: F_sh = -sgn(v_Ex) eta_h g rho_g w d^2 along x (thesis eqs. 2.2, 3.2).

    Args:
        eta_h: horizontal static scaling constant [-]; default 6.5, thesis Table 3.4 at
            q = 0.
    """
    return Term("static_h", {"eta_h": eta_h})


def static_v(eta_v: ParamValue = 248.0, lam: ParamValue = 0.106) -> Term:
    """``static_v``: F_sv = -sgn(v_Ey) eta_v (d / L_ref)^lam g rho_g V along y (thesis
    eqs. 2.3-2.4, 3.3, 3.15).

    Args:
        eta_v: vertical static scaling constant [-]; default 248.0, thesis Table 3.4 at q = 0.
        lam: depth exponent lambda [-]; default 0.106, thesis Table 3.4 at q = 0.
    """
    return Term("static_v", {"eta_v": eta_v, "lam": lam})


def joint_springs() -> Term:
    """``joint_springs``: the joints' spring-dampers, tau = -k (theta - theta_rest) -
    c dtheta/dt, with k and c on each joint (``knee={"k": 300.0, "c": 5.0}``); without it a
    spring-damper joint is free."""
    return Term("joint_springs", {})


#: Names of the nine RFT coefficients, in the order of ``granrs.forces.RFT_GENERIC`` (``m1`` is the
#: paper's -1: ``Bm11`` is B_{-1,1}).
RFT_COEFFICIENTS: tuple[str, ...] = tuple(_granrs.RFT_COEFFICIENTS)
#: The generic coefficients of Li, Zhang & Goldman 2013 (supplementary Table S2).
RFT_GENERIC: Mapping[str, float] = MappingProxyType(
    dict(zip(RFT_COEFFICIENTS, _granrs.RFT_GENERIC, strict=True))
)


def rft(
    zeta: ParamValue,
    elements: int = 8,
    coefficients: Mapping[str, float] | None = None,
) -> Term:
    """``rft``: planar resistive force theory (Li, Zhang & Goldman, Science 339 (2013) 1408).

    Each element of the contact's boundary below the surface feels
    ``dF = zeta |z| dA (-alpha_x(beta, gamma), alpha_z(beta, gamma))`` (:func:`rft_alpha`),
    with ``z`` its depth, ``beta`` its line's angle and ``gamma`` its velocity's angle below
    +x. A rod's boundary is its shaft (on the axis, from the tip along the immersed length)
    and its tip end (``d_c`` across the axis), both ``d_c`` wide; a sole box's is its bottom
    and the immersed parts of its front and back faces. Force and moment come from the
    elements. At rest the force is a reaction bounded by the sand's resistance (the
    engine's sticking). See ``docs/laws.md``.

    Args:
        zeta: the medium's scale [N/m^3]: alpha_z of a horizontal plate pushed straight down
            per unit depth. Required (no default): Li et al. measured about 1e6 N/m^3
            (1 N/cm^3) for their media; the docs tabulate values with sources.
        elements: elements per boundary plate (default 8; the docs show the convergence).
        coefficients: the nine Fourier coefficients of another medium, by name
            (``granrs.forces.RFT_COEFFICIENTS``; the paper's ``B-11``, ``C-11`` are also accepted);
            those left out keep the generic values (``granrs.forces.RFT_GENERIC``).
    """
    params: dict[str, ParamValue] = {"zeta": zeta, "elements": elements}
    for k, v in _coefficients(coefficients).items():
        params[str(k).replace("-1", "m1")] = v
    return Term("rft", params)


def _coefficients(value: Any) -> Mapping[Any, Any]:
    """RFT coefficients by name (``None``: none), or a typed error naming the argument."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise InvalidParameterError(
            f"rft coefficients must be a mapping of name to value (names: "
            f"{', '.join(RFT_COEFFICIENTS)}); got {value!r}",
            field="rft.coefficients",
        )
    return value


def rft_inertial(lam: ParamValue = 1.0, elements: int = 8) -> Term:
    """``rft_inertial``: the rate-dependent term of dynamic RFT (Agarwal, Karsai, Goldman &
    Kamrin, Science Advances 2021): on each immersed boundary element,
    ``dF = -lam rho_g |v_n| v_n n dA`` with ``v_n`` the element's speed along its normal
    ``n``: the momentum flux of the sand its leading face brings to its speed.

    Args:
        lam: scale of the momentum flux [-]; default 1 (the momentum-flux value).
        elements: elements per boundary plate (default 8), as for :func:`rft`.
    """
    return Term("rft_inertial", {"lam": lam, "elements": elements})


def poncelet(c: ParamValue, k: ParamValue) -> Term:
    """``poncelet``: the Poncelet / Katsuragi-Durian impact law (Nature Physics 3 (2007)
    420), at the contact's reference point T (a rod's tip):
    ``F = -c rho_g A |v| v - k d v/|v|``, with ``A`` the immersed cross-section normal to
    ``v`` (a rod: ``pi d_c^2/4 |e.v^| + d_c l |e x v^|``). The ``k d`` part is set-valued
    at rest (``|F| <= k d`` per component): a body lighter than ``k d / g`` sticks, and is
    never pushed back out.

    Args:
        c: inertial drag coefficient [-] (``m / d1 = c rho_g A`` in K&D's form). Required.
        k: depth-friction coefficient [N/m]. Required.
    """
    return Term("poncelet", {"c": c, "k": k})


def rft_alpha(beta: Any, gamma: Any, coefficients: Mapping[str, float] | None = None) -> Any:
    """The RFT coefficients ``(alpha_x, alpha_z)`` (dimensionless) at the element angle
    ``beta`` and the velocity angle ``gamma`` [rad], any real angles, numpy broadcasting.

    Conventions (granrs's frame: x right, y up): ``gamma`` is the velocity's angle below +x
    (``pi/2``: straight down), ``beta`` the element's line angle counter-clockwise from +x
    (mod pi), and the force on an element is ``zeta |z| dA (-alpha_x, alpha_z)``. So
    ``rft_alpha(0, pi/2) == (0, 1)``, and ``rft_alpha(-beta, pi - gamma) == (-alpha_x,
    alpha_z)``. ``coefficients`` as for :func:`rft`.

    >>> import numpy as np, granrs
    >>> ax, az = granrs.forces.rft_alpha(0.0, np.pi / 2)
    >>> round(float(ax), 12), round(float(az), 12)
    (0.0, 1.0)
    """
    import numpy as np

    k = dict(RFT_GENERIC)
    for name, v in _coefficients(coefficients).items():
        key = str(name).replace("-1", "m1")
        if key not in k:
            raise InvalidParameterError(
                f"unknown parameter `rft.{key}` (an RFT coefficient); the coefficients are "
                f"{', '.join(RFT_COEFFICIENTS)}",
                field=f"rft.{key}",
            )
        k[key] = float(v)
    b, g = np.broadcast_arrays(np.asarray(beta, dtype=float), np.asarray(gamma, dtype=float))
    ax, az = _granrs.rft_alpha(
        np.ascontiguousarray(b).ravel(),
        np.ascontiguousarray(g).ravel(),
        [k[n] for n in RFT_COEFFICIENTS],
    )
    return ax.reshape(b.shape), az.reshape(b.shape)


def thesis(coefficients: Any = None, *more: Any) -> tuple[Term, ...]:
    """The thesis's law as terms: gravity, drag, static_h, static_v and joint_springs.

    ``coefficients`` is a :class:`granrs.Coefficients` (or a mapping of eta_h, eta_d,
    eta_v, lam) for every contact, ``None`` for the terms' defaults (Table 3.4 at q = 0);
    further arguments give the next contacts' (the chain's link 2).
    """
    rows = [coefficients, *more]
    if rows == [None]:
        return (gravity(), drag(), static_h(), static_v(), joint_springs())
    values = [_row(c, i) for i, c in enumerate(rows)]

    def col(k: str) -> ParamValue:
        vals = tuple(v[k] for v in values)
        return vals[0] if all(x == vals[0] for x in vals) else vals

    return (
        gravity(),
        drag(eta_d=col("eta_d")),
        static_h(eta_h=col("eta_h")),
        static_v(eta_v=col("eta_v"), lam=col("lam")),
        joint_springs(),
    )


def select(terms: Iterable[Term], *names: str) -> tuple[Term, ...]:
    """The terms of ``terms`` whose names are among ``names``, in their order (what the
    ``effects=`` names of earlier versions did): ``select(scene.forces, "gravity",
    "static_v")``. An unknown name raises, with a near miss."""
    for n in names:
        if not isinstance(n, str):
            raise InvalidParameterError(
                f"select takes term names (strings), got {n!r}", field="names"
            )
        info(n)
    items = as_terms(terms, "terms")
    return tuple(t for t in items if t.name in names)


def thesis_row(terms: Iterable[Term], contact: int = 0) -> Any:
    """The thesis-law parameters of ``terms`` at one contact as a
    :class:`granrs.Coefficients` row (eta_h, eta_d, eta_v, lam), for reading them the way
    the thesis's tables print them; ``None`` unless drag, static_h and static_v are all
    listed. A view of the terms, not a second copy: change the terms to change the law."""
    from .coefficients import Coefficients

    by_name = {t.name: t.params for t in terms}
    if not {"drag", "static_h", "static_v"} <= set(by_name):
        return None

    def at(v: ParamValue) -> float:
        return float(v[contact]) if isinstance(v, tuple) else float(v)

    return Coefficients(
        eta_h=at(by_name["static_h"]["eta_h"]),
        eta_d=at(by_name["drag"]["eta_d"]),
        eta_v=at(by_name["static_v"]["eta_v"]),
        lam=at(by_name["static_v"]["lam"]),
    )


def _row(c: Any, i: int) -> dict[str, float]:
    if hasattr(c, "as_dict"):
        return dict(c.as_dict())
    if isinstance(c, Mapping):
        return {k: c[k] for k in ("eta_h", "eta_d", "eta_v", "lam")}
    raise InvalidParameterError(
        f"coefficients of contact {i} must be a granrs.Coefficients or a mapping of eta_h, "
        f"eta_d, eta_v, lam; got {c!r}",
        field="coefficients",
    )


def as_terms(value: Any, field_name: str = "forces") -> tuple[Term, ...]:
    """``value`` (a sequence of :class:`Term`) as a tuple, or a typed error naming the item."""
    items: Sequence[Any] | None = None
    if not isinstance(value, (str, Term)) and isinstance(value, Iterable):
        try:
            items = tuple(value)
        except TypeError:  # iterable by type only (a 0-d numpy array)
            items = None
    if items is None:
        raise InvalidParameterError(
            f"{field_name} must be a list of granrs.forces terms (e.g. "
            f"[granrs.forces.gravity(), granrs.forces.drag()]); got {value!r}",
            field=field_name,
        )
    for i, t in enumerate(items):
        if not isinstance(t, Term):
            raise InvalidParameterError(
                f"{field_name}[{i}] must be a granrs.forces term, got {t!r}", field=field_name
            )
    names = [t.name for t in items]
    for n in names:
        if names.count(n) > 1:
            raise InvalidParameterError(f"{field_name} lists {n!r} twice", field=field_name)
    return tuple(items)
