"""Bodies of your own: a planar :class:`~granrs.bodies.Linkage` of rigid
:class:`~granrs.bodies.Link` s, revolute :class:`~granrs.bodies.Joint` s,
:class:`~granrs.bodies.Contact` s with the sand and a :class:`~granrs.bodies.Root`.

A linkage is a tree: one link (the root link) hangs from the root point, every other link
from one joint on its parent. Each link has its local coordinates ``(s, n)``: ``s`` along
its axis from its own joint, ``n`` normal to it (the axis at ``q`` from the vertical is
``(sin q, cos q)``, the normal ``(cos q, -sin q)``). Units are SI, angles in degrees
(``*_deg``).

The thesis's bodies are linkages too: ``granrs.cases.chain(case=1).body`` is a
:class:`Linkage` built from the scene's fields (its ``name`` is ``"chain"``), and
:meth:`Linkage.detached` gives the same body as a plain linkage, which runs to the same
result through the same engine.

Every element is checked by the Rust core before any work; an error names the element
(``links.shank.mass``, ``joints.knee.parent``, ``contacts.sole.link``). The fields of every
element are one table of the core (:data:`ELEMENT_FIELDS`); the dataclasses below are held to
it by a test.

Limits: at most :data:`MAX_LINKS` links and :data:`MAX_CONTACTS` contacts, and an arc of
at most :data:`MAX_CHORDS` chords.

Example::

    import granrs
    from granrs.bodies import Joint, Link, Linkage, Root

    arm = Linkage(
        links=[Link("upper", mass=1.0, inertia=0.01, length=0.3, com=(0.15, 0.0), q_deg=120),
               Link("lower", mass=1.0, inertia=0.01, length=0.3, com=(0.15, 0.0), q_deg=150)],
        joints=[Joint("elbow", parent="upper", child="lower", at=(0.3, 0.0))],
        root=Root("pinned", link="upper", position=(0.0, 1.0)),
    )
    result = granrs.simulate(granrs.Scene(body=arm, forces=[granrs.forces.gravity()],
                                          end="time", t_end=0.5))
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import MISSING, asdict, dataclass, fields
from typing import Any

from . import _granrs
from .errors import InvalidParameterError, UnknownNameError

__all__ = [
    "DEFAULT_CHORDS",
    "ELEMENT_FIELDS",
    "MAX_CHORDS",
    "MAX_CONTACTS",
    "MAX_LINKS",
    "Contact",
    "Joint",
    "Link",
    "Linkage",
    "Root",
]

#: Most links a linkage may have (the engine is compiled for 1 to MAX_LINKS links).
MAX_LINKS: int = int(_granrs.MAX_LINKS)
#: Most contacts a body may have.
MAX_CONTACTS: int = int(_granrs.MAX_CONTACTS)

#: The one table of a linkage's element fields (the core's, ``rust/spec/fields.rs``): per
#: element (``link``, ``joint``, ``contact``, ``root``), each field's unit, note and doc.
ELEMENT_FIELDS: dict[str, dict[str, dict[str, str]]] = {}
for _f in _granrs.element_fields():
    ELEMENT_FIELDS.setdefault(_f["element"], {})[_f["name"]] = _f

Point = tuple[float, float]


def _not_none(element: Any, prefix: str) -> None:
    """Refuse ``None`` for each field of ``element`` whose default is a value (or that has
    no default): ``None`` means "left out" only where the field says so."""
    for f in fields(element):
        if f.default is not None and getattr(element, f.name) is None:
            raise InvalidParameterError(
                f"{prefix}{f.name} must be a value, not None"
                + ("" if f.default is MISSING else f" (its default: {f.default!r})"),
                field=f"{prefix}{f.name}",
            )


def _point(value: Any, field: str) -> Point:
    try:
        x, y = value
        if any(type(c).__name__ in ("bool", "bool_") for c in (x, y)):
            raise TypeError("a truth value is not a coordinate")
        return (float(x), float(y))
    except (TypeError, ValueError, OverflowError):
        raise InvalidParameterError(
            f"{field} must be a pair of numbers (s, n) or (x, y); got {value!r}", field=field
        ) from None


@dataclass(frozen=True)
class Link:
    """A rigid link: mass [kg], moment of inertia about its centre of mass [kg m^2], length
    [m], centre of mass ``com`` in its ``(s, n)`` coordinates [m], initial angle of its axis
    from the vertical ``q_deg`` and initial angular velocity ``omega0`` [rad/s]."""

    name: str
    mass: float
    inertia: float
    length: float
    com: Point = (0.0, 0.0)
    q_deg: float = 0.0
    omega0: float = 0.0

    def __post_init__(self) -> None:
        _not_none(self, f"links.{self.name}.")
        object.__setattr__(self, "com", _point(self.com, f"links.{self.name}.com"))

    @classmethod
    def rod(
        cls,
        name: str,
        length: float,
        diameter: float,
        density: float,
        q_deg: float = 0.0,
        omega0: float = 0.0,
    ) -> Link:
        """A solid round rod of ``density`` [kg/m^3] along ``+s`` from its joint: mass
        ``density pi d^2/4 L``, inertia ``m (L^2/12 + d^2/16)`` (a solid cylinder about a
        transverse axis through its centre), centre of mass at ``(L/2, 0)``."""
        mass = density * math.pi * diameter * diameter / 4.0 * length
        inertia = mass * (length * length / 12.0 + diameter * diameter / 16.0)
        return cls(name, mass, inertia, length, (0.5 * length, 0.0), q_deg, omega0)

    @classmethod
    def box(
        cls,
        name: str,
        length: float,
        height: float,
        width: float,
        density: float,
        q_deg: float = 0.0,
        omega0: float = 0.0,
    ) -> Link:
        """A solid box of ``density`` [kg/m^3]: ``length`` along ``+s`` from its joint,
        ``height`` towards ``-n``, ``width`` out of the plane: mass ``density L h w``,
        inertia ``m (L^2 + h^2)/12``, centre of mass at ``(L/2, -h/2)``."""
        mass = density * length * height * width
        inertia = mass * (length * length + height * height) / 12.0
        return cls(name, mass, inertia, length, (0.5 * length, -0.5 * height), q_deg, omega0)


#: The kinds of joint.
JOINT_KINDS: tuple[str, ...] = ("free", "locked", "spring", "driven")


@dataclass(frozen=True)
class Joint:
    """A revolute joint: ``child`` hangs from ``parent`` at the parent's point ``at`` (its
    ``(s, n)`` coordinates, m); the child's own origin is the joint. ``kind``:

    * ``"free"``: frictionless;
    * ``"locked"``: no relative rotation (the run reports the torque it takes);
    * ``"spring"``: a spring-damper, torque ``-k (theta - rest) - c thetadot`` on the
      relative angle ``theta = q_child - q_parent`` (``k`` N m/rad, ``c`` N m s/rad,
      ``rest_deg``; ``None``: the initial relative angle); acts while the
      ``joint_springs`` term does;
    * ``"driven"``: the relative angle follows its initial value plus ``rate t`` [rad/s]
      plus a sinusoid ``amplitude_deg (sin(2 pi frequency t + phase) - sin(phase))``
      (``frequency`` in Hz, ``phase_deg``); the run reports the torque it takes
      (``Result.joints``). A sinusoid reads the time from a clock coordinate of its own
      (the series ``clock``), so such a linkage has at most ``MAX_LINKS - 1`` links;
      or, with ``table=[(t0, angle0_deg), (t1, angle1_deg), ...]`` (alone, without ``rate``
      or a sinusoid), the relative angle ``q_child - q_parent`` itself [deg] follows the
      table's linear interpolation, held at the first angle before ``t0`` and at the last
      after the last time. Its angle at ``t = 0`` must be the initial relative angle (the
      links' ``q_deg``, to 1e-9 rad). At each time the joint's rate jumps by an impulse,
      reported in ``Result.impulses``.
    """

    name: str
    parent: str
    child: str
    at: Point = (0.0, 0.0)
    kind: str = "free"
    k: float | None = None
    c: float | None = None
    rest_deg: float | None = None
    rate: float | None = None
    amplitude_deg: float | None = None
    frequency: float | None = None
    phase_deg: float | None = None
    table: tuple[tuple[float, float], ...] | None = None

    def __post_init__(self) -> None:
        _not_none(self, f"joints.{self.name}.")
        object.__setattr__(self, "at", _point(self.at, f"joints.{self.name}.at"))
        object.__setattr__(self, "table", _table(self.table))


def _table(value: Any) -> Any:
    """A table as a tuple of ``(time, angle)`` tuples (hashable, comparable); anything that is
    not rows of values is left as it is, for the core to refuse naming the field."""
    if value is None or isinstance(value, str | bytes | Mapping):
        return value
    try:
        return tuple(
            tuple(row)
            if isinstance(row, Iterable) and not isinstance(row, str | bytes | Mapping)
            else row
            for row in value
        )
    except TypeError:
        return value


#: The shapes of contact.
CONTACT_SHAPES: tuple[str, ...] = ("rod", "box", "arc")
#: Most chords of an arc contact.
MAX_CHORDS: int = int(_granrs.MAX_CHORDS)
#: The chords of an arc contact unless it says otherwise.
DEFAULT_CHORDS: int = int(_granrs.DEFAULT_CHORDS)


@dataclass(frozen=True)
class Contact:
    """A contact with the sand, fixed on ``link``. ``shape``:

    * ``"rod"``: a round rod (``length``, ``diameter``) from its tip ``at`` along ``+s``,
      meeting the sand with its tip (immersed length, centroid, reference area and volume of
      the thesis's eqs. 3.4-3.15);
    * ``"box"``: a box (a sole, a plate) with its corner ``at`` on the sole, ``length``
      along ``+s``, ``height`` towards ``-n`` and ``width`` out of the plane; its immersed
      part is the box clipped by the surface (``docs/model.md``, "What is immersed").
      ``l_ref``: the depth factor's reference length (default: ``length``);
    * ``"arc"``: a thin circular arc (a C-shaped leg) with its centre ``at``, ``radius``,
      from the angle ``start_deg`` to ``end_deg`` and ``width`` out of the plane, cut into
      ``chords`` chords (default :data:`DEFAULT_CHORDS`, at most :data:`MAX_CHORDS`). The
      angles are measured in the link's frame from its ``+s`` axis towards its ``+n`` axis:
      the arc's point at angle ``phi`` is ``at + radius (cos phi, sin phi)`` in ``(s, n)``.
      ``length`` is not used. Only the terms that read the boundary's chords act on it
      (``rft``, ``rft_inertial``; and the body terms).
    """

    link: str
    shape: str
    length: float | None = None
    at: Point = (0.0, 0.0)
    diameter: float | None = None
    height: float | None = None
    width: float | None = None
    l_ref: float | None = None
    name: str = ""
    radius: float | None = None
    start_deg: float | None = None
    end_deg: float | None = None
    chords: int | None = None

    def __post_init__(self) -> None:
        label = self.name if isinstance(self.name, str) and self.name else self.link
        _not_none(self, f"contacts.{label}.")
        object.__setattr__(self, "at", _point(self.at, f"contacts.{label}.at"))

    @classmethod
    def rod(
        cls, link: str, length: float, diameter: float, at: Point = (0.0, 0.0), name: str = ""
    ) -> Contact:
        """A rod contact (see the class)."""
        return cls(link, "rod", length, at, diameter=diameter, name=name)

    @classmethod
    def box(
        cls,
        link: str,
        length: float,
        height: float,
        width: float,
        at: Point = (0.0, 0.0),
        l_ref: float | None = None,
        name: str = "",
    ) -> Contact:
        """A box contact (see the class)."""
        return cls(link, "box", length, at, height=height, width=width, l_ref=l_ref, name=name)

    @classmethod
    def arc(
        cls,
        link: str,
        radius: float,
        start_deg: float,
        end_deg: float,
        width: float,
        at: Point = (0.0, 0.0),
        chords: int | None = None,
        name: str = "",
    ) -> Contact:
        """An arc contact (see the class): centre ``at``, from ``start_deg`` to ``end_deg``
        (from ``+s`` towards ``+n``)."""
        return cls(
            link,
            "arc",
            at=at,
            width=width,
            radius=radius,
            start_deg=start_deg,
            end_deg=end_deg,
            chords=chords,
            name=name,
        )


#: How a root may move.
ROOT_KINDS: tuple[str, ...] = ("free", "pinned", "moving")


@dataclass(frozen=True)
class Root:
    """The root point the root ``link`` hangs from (its ``(s, n)`` origin): ``"free"`` (a
    floating base starting at ``position`` with ``velocity``), ``"pinned"`` (fixed at
    ``position``) or ``"moving"`` (at the constant ``velocity``, e.g. a leg on a robot body
    moving at constant speed). ``mass``: a point mass at the root [kg]. ``link=None``: the
    first link. ``rate`` [rad/s]: the root link's angle driven at this constant rate from
    its ``q_deg`` (e.g. a C-leg turned about a fixed axle), held by a torque the run reports
    as the joint ``root``'s; ``None``: its angle is free."""

    kind: str = "free"
    link: str | None = None
    position: Point = (0.0, 0.0)
    velocity: Point = (0.0, 0.0)
    mass: float = 0.0
    rate: float | None = None

    def __post_init__(self) -> None:
        _not_none(self, "root.")
        object.__setattr__(self, "position", _point(self.position, "root.position"))
        object.__setattr__(self, "velocity", _point(self.velocity, "root.velocity"))


def _plain(element: Any) -> dict[str, Any]:
    """An element's fields as plain values, without those left at ``None``."""
    return {k: v for k, v in asdict(element).items() if v is not None}


def _element(cls: type, value: Any, field: str) -> Any:
    if isinstance(value, cls):
        return value
    if isinstance(value, Mapping):
        names = {f.name for f in fields(cls)}
        for k in value:
            if k not in names:
                raise UnknownNameError(
                    f"unknown key {field}.{k}; a {cls.__name__.lower()} has "
                    f"{', '.join(sorted(names))}",
                    field=f"{field}.{k}",
                )
        try:
            return cls(**dict(value))
        except TypeError as e:
            raise InvalidParameterError(f"{field}: {e}", field=field) from None
    raise InvalidParameterError(
        f"{field} must be a granrs.bodies.{cls.__name__} or a mapping; got {value!r}",
        field=field,
    )


def _elements(cls: type, values: Any, field: str) -> tuple[Any, ...]:
    if isinstance(values, str | Mapping) or not isinstance(values, Iterable):
        raise InvalidParameterError(
            f"{field} must be a list of granrs.bodies.{cls.__name__}; got {values!r}",
            field=field,
        )
    return tuple(_element(cls, v, f"{field}[{i}]") for i, v in enumerate(values))


class Linkage:
    """A planar linkage: ``links``, ``joints``, ``contacts`` and a ``root`` (see the
    module). Checked in full by the core on construction; an error names the element.

    ``name`` is ``"linkage"``, or the built-in body (``"free_link"``, ``"chain"``,
    ``"leg"``) a scene built it from; :meth:`detached` gives the plain linkage.
    """

    __slots__ = ("_fields", "_order", "_parts", "_preset")

    def __init__(
        self,
        links: Iterable[Link | Mapping[str, Any]],
        joints: Iterable[Joint | Mapping[str, Any]] = (),
        contacts: Iterable[Contact | Mapping[str, Any]] = (),
        root: Root | Mapping[str, Any] | None = None,
    ) -> None:
        parts = (
            _elements(Link, links, "links"),
            _elements(Joint, joints, "joints"),
            _elements(Contact, contacts, "contacts"),
            Root() if root is None else _element(Root, root, "root"),
        )
        object.__setattr__(self, "_parts", parts)
        object.__setattr__(self, "_preset", None)
        object.__setattr__(self, "_fields", None)
        object.__setattr__(self, "_order", None)
        # The core checks the structure and every element (raises the typed error).
        found = _granrs.body_linkage({"body": self._core_value, **_NUMERICS}, True)
        object.__setattr__(self, "_order", tuple(found["order"]))

    @classmethod
    def from_mapping(cls, body: Mapping[str, Any]) -> Linkage:
        """A linkage from plain values (``{"links": [...], "joints": [...], "contacts":
        [...], "root": {...}}``, a TOML ``[body]`` table); an unknown key raises
        :class:`~granrs.errors.UnknownNameError` naming it."""
        allowed = ("links", "joints", "contacts", "root")
        for k in body:
            if k not in allowed:
                raise UnknownNameError(
                    f"unknown key body.{k}: a linkage has {', '.join(allowed)}", field=f"body.{k}"
                )
        if "links" not in body:
            raise InvalidParameterError("a linkage needs links (body.links)", field="body.links")
        return cls(**dict(body))

    @classmethod
    def _built_in(cls, body: str, fields: Mapping[str, Any]) -> Linkage:
        """The built-in body ``body`` of a scene with these body and start ``fields``: its
        parts are asked of the core when first read."""
        obj = cls.__new__(cls)
        object.__setattr__(obj, "_preset", body)
        object.__setattr__(obj, "_fields", dict(fields))
        object.__setattr__(obj, "_parts", None)
        object.__setattr__(obj, "_order", None)
        return obj

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("a Linkage is frozen")

    @property
    def name(self) -> str:
        """The built-in body this is (``"free_link"``, ``"chain"``, ``"leg"``), or
        ``"linkage"``."""
        return self._preset or "linkage"

    @property
    def _core_value(self) -> Any:
        """What the core reads for the scene's ``body``: a built-in body's name, or the
        linkage as plain values."""
        if self._preset is not None:
            return self._preset
        links, joints, contacts, root = self._parts
        return {
            "links": [_plain(x) for x in links],
            "joints": [_plain(x) for x in joints],
            "contacts": [_plain(x) for x in contacts],
            "root": _plain(root),
        }

    def _resolve(self) -> tuple[Any, ...]:
        if self._parts is None:
            found = _granrs.body_linkage(
                {**_NUMERICS, **self._fields, "body": self._preset}  # type: ignore[dict-item]
            )
            parts = (
                tuple(Link(**d) for d in found["links"]),
                tuple(Joint(**d) for d in found["joints"]),
                tuple(Contact(**d) for d in found["contacts"]),
                Root(**found["root"]),
            )
            object.__setattr__(self, "_parts", parts)
            object.__setattr__(self, "_order", tuple(found["order"]))
        return self._parts  # type: ignore[return-value]

    @property
    def links(self) -> tuple[Link, ...]:
        """The links."""
        return self._resolve()[0]  # type: ignore[no-any-return]

    @property
    def joints(self) -> tuple[Joint, ...]:
        """The joints."""
        return self._resolve()[1]  # type: ignore[no-any-return]

    @property
    def contacts(self) -> tuple[Contact, ...]:
        """The contacts."""
        return self._resolve()[2]  # type: ignore[no-any-return]

    @property
    def root(self) -> Root:
        """The root."""
        return self._resolve()[3]  # type: ignore[no-any-return]

    @property
    def order(self) -> tuple[str, ...]:
        """The links' names in the engine's order (a parent before its children): the order
        of the state's angles and of the results' links and joints."""
        self._resolve()
        return self._order  # type: ignore[return-value]

    def detached(self) -> Linkage:
        """The same body as a plain linkage (``name == "linkage"``), with its initial state
        in its elements: it runs through the same engine to the same result."""
        return Linkage(self.links, self.joints, self.contacts, self.root)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Linkage):
            return NotImplemented
        if self._preset is not None or other._preset is not None:
            return self._preset == other._preset and self._fields == other._fields
        return self._parts == other._parts

    def __hash__(self) -> int:
        return hash(self.name)

    def __repr__(self) -> str:
        if self._preset is not None:
            return f"Linkage.{self._preset}()"
        links, joints, contacts, root = self._parts
        return f"Linkage(links={links!r}, joints={joints!r}, contacts={contacts!r}, root={root!r})"

    def __reduce__(self) -> tuple[Any, ...]:
        if self._preset is not None:
            return (Linkage._built_in, (self._preset, self._fields))
        return (Linkage, self._parts)


#: The scene fields the core needs beside a body to read it (their values do not matter
#: to the body).
_NUMERICS: dict[str, Any] = {
    "rho_g": 1650.0,
    "g": 9.81,
    "apply_at": "tip",
    "sign_model": "modes",
    "end": "first_stop",
    "method": "rk4",
    "dt": 1e-4,
    "t_end": 1.0,
    "v0": 0.0,
}


def _check_table() -> None:
    """The dataclasses and the core's table name the same fields (tested)."""
    for element, cls in (("link", Link), ("joint", Joint), ("contact", Contact), ("root", Root)):
        names = {f.name for f in fields(cls)}
        if names != set(ELEMENT_FIELDS[element]):
            raise ImportError(
                f"granrs.bodies.{cls.__name__} and the core's table differ: "
                f"{sorted(names ^ set(ELEMENT_FIELDS[element]))}"
            )


_check_table()
