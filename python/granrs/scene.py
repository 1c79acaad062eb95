"""What a run is: :class:`Scene`, a frozen description of one impact.

Three built-in bodies share one scene type (``body``): ``"free_link"`` (a round rod),
``"chain"`` (two rods pinned at their top ends, chapter 4) and ``"leg"`` (foot, shank, thigh
and half of head-arms-trunk for one leg of a person landing on both feet, chapter 5); each is
held as a :class:`granrs.bodies.Linkage` built from the scene's fields (``scene.body.name``
says which; ``scene.kind`` too). Any other body is a :class:`granrs.bodies.Linkage` of your
own, whose initial state is in its elements. Fields that belong to some bodies only are
listed in :data:`BODY_FIELDS`; setting one for another body raises
:class:`~granrs.errors.InvalidSceneError`. :mod:`granrs.cases` builds the thesis's scenes
with every default set.

A scene is plain data: the body and its size, the sand, the force terms that act (each with
its parameters: :mod:`granrs.forces`), the initial state, the step, the end condition and
the time series to record. :func:`granrs.simulate` runs it. Every field is checked by the
Rust core (one set of rules for Python, TOML, the CLI and sweeps) when the scene is built,
whether or not its model or method reads it; an invalid field raises a
:class:`~granrs.errors.InvalidSceneError` subclass whose ``field`` names it.

A scene made from one of the thesis's coefficient rows follows its angle: when the
free link's ``q_deg`` (or the leg's ``v0``) changes, by :meth:`Scene.replace`, a scene file's
``--set``, or a sweep's axis, and ``coefficients_source`` names a row of Table 3.4 (or of
sec. 5.3.2, for the leg) whose values the force terms still hold, the terms take the row of
the new value (the nearest tabulated one; the thesis tuned each row by hand, so rows are not
interpolated) and ``coefficients_source`` says which. Terms given anew (``replace(forces=
...)``) are the caller's: their source becomes ``"the scene's forces"`` and they are kept.
The thesis's terms with parameters changed in place (a scene file's values, ``--set
static_v.eta_v=...``) while the source still names a row are kept too, with one
:class:`~granrs.errors.CoefficientsWarning`. Another law, terms given with the default
source (``Scene(forces=...)``: the default describes the default terms), or any other
``coefficients_source`` keep the terms as they are, silently.

Units are SI (m, kg, s, N, J), angles in degrees at this edge (``*_deg``).
Defaults are those of the thesis's free link (section 3.2.1): L = 0.190 m, d_c = 0.0127 m,
m = 0.184 kg, sand bulk density 1650 kg/m^3 (section 3.3.1), 10 kHz (section 3.3.2).
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import math
import os
import re
import sys
import textwrap
import warnings
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _granrs, data, media
from .bodies import Linkage
from .coefficients import Coefficients, resolve
from .errors import CoefficientsWarning, InvalidParameterError, InvalidSceneError, UnknownNameError
from .forces import Term, as_terms, thesis, thesis_row

__all__ = [
    "BODIES",
    "BODY_FIELDS",
    "FIELD_INFO",
    "JOINTS",
    "KINDS",
    "OUTPUTS",
    "OWN_FORCES",
    "RECORDS",
    "JointSpec",
    "Scene",
]

#: The built-in bodies: the core's presets, each a function from a few parameters to a
#: linkage.
BODIES: tuple[str, ...] = tuple(_granrs.PRESETS)
#: What a scene's body may be: a built-in body, or a linkage of your own.
KINDS: tuple[str, ...] = (*BODIES, "linkage")
#: Named joint settings; a spring-damper is a mapping ``{"k": N m/rad, "c": N m s/rad}``.
JOINTS: tuple[str, ...] = ("free", "locked")
#: A joint: ``"free"``, ``"locked"`` or ``{"k": stiffness, "c": damping}``.
JointSpec = str | Mapping[str, float]

#: The ``coefficients_source`` of a scene whose terms the caller gave (no table row).
OWN_FORCES = "the scene's forces"

#: Time series a scene may list in ``record``.
RECORDS: tuple[str, ...] = ("state", "forces", "energy")

#: The output fields of a run, from the core's one table of them: what a scene's
#: ``outputs`` may list (``Result.summary``'s keys, a contact's and a joint's, and a sweep's
#: columns), the run's first, then a contact's, then a joint's.
OUTPUTS: tuple[str, ...] = tuple(f["name"] for f in _granrs.output_fields())

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
    names: tuple[Any, ...] | None = None
    if not isinstance(value, str) and isinstance(value, Iterable):
        try:
            names = tuple(value)
        except TypeError:  # iterable by type only (a 0-d numpy array)
            names = None
    if names is None:
        raise InvalidParameterError(
            f"{field_name} must be a list of names from {', '.join(allowed)}; got {value!r}",
            field=field_name,
        )
    for name in names:
        if name not in allowed:
            raise UnknownNameError(
                f"unknown {field_name} entry {name!r}; allowed: {', '.join(allowed)}",
                field=field_name,
            )
    return names


def _differs(value: Any, default: Any) -> bool:
    """Whether a field's value is not its default; a value that does not compare as one
    truth value (an array) differs."""
    if value is default:
        return False
    try:
        return bool(value != default)
    except (TypeError, ValueError):
        return True


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


def unknown_field_message(name: str, known: Iterable[str], what: str = "Scene has no field") -> str:
    """``what 'name'``, with the closest of ``known`` as a suggestion (or, with none close,
    the list of them): the text of every unknown-field error of a scene."""
    choices = sorted(set(known))
    close = difflib.get_close_matches(name, choices, n=1, cutoff=0.5)
    if close:
        return f"{what} {name!r}; did you mean {close[0]!r}?"
    return f"{what} {name!r}; fields: {', '.join(choices)}"


@dataclass(frozen=True)
class _RowRule:
    """A thesis coefficient table whose row a scene field selects."""

    #: The field that selects the row (the free link's angle, the leg's speed).
    field: str
    #: A ``coefficients_source`` naming a row; group 1 is the row's value of ``field``.
    pattern: re.Pattern[str]
    #: The coefficients of the row nearest a value of ``field``, and their source sentence.
    row: Callable[[float], tuple[Coefficients, str]]
    #: How to build the thesis's scene at another value (``{}``: the value; for the warning).
    case: str


def leg_row(v0: float) -> tuple[Coefficients, str]:
    """The thesis's leg coefficients (sec. 5.3.2) at the nearest of its two speeds, 3.28 and
    2.35 m/s, and their source sentence."""
    table = data.load("human_coefficients", as_="numpy")
    row = int(np.argmin(np.abs(table["v0"] - float(v0))))
    coefficients = Coefficients(
        eta_h=float(table["eta_h"][row]),
        eta_d=float(table["eta_d"][row]),
        eta_v=float(table["eta_v"][row]),
        lam=float(table["lambda"][row]),
    )
    return coefficients, f"thesis sec. 5.3.2, row v0 = {float(table['v0'][row])} m/s"


#: Per built-in body, the table whose row its coefficients follow (the chain's Table 4.4
#: rows are per measured case, not per field: a chain keeps its coefficients).
_ROW_RULES: dict[str, _RowRule] = {
    "free_link": _RowRule(
        "q_deg",
        re.compile(r"Table 3\.4, row q = ([0-9.]+) deg(?: \([^()]*\))?"),
        lambda q: resolve("table_3_4", q),
        "granrs.cases.free_link(q_deg={}, v0=...)",
    ),
    "leg": _RowRule(
        "v0",
        re.compile(r"thesis sec\. 5\.3\.2, row v0 = ([0-9.]+) m/s"),
        leg_row,
        "granrs.cases.leg(v0={})",
    ),
}


@functools.lru_cache(maxsize=64)
def _thesis_terms(row: Coefficients) -> tuple[Term, ...]:
    """The thesis's terms with a table row's values (made once per row)."""
    return thesis(row)


@dataclass(frozen=True)
class _Kept:
    """A row change refused: the forces were changed from the named row."""

    message: str
    source: str


def _row_change(scene: Any, value: Any) -> tuple[tuple[Term, ...], str] | _Kept | None:
    """What the force terms of ``scene`` become when its row field (:data:`_ROW_RULES`) is
    ``value``: ``(forces, source)`` to take the row of ``value`` (the terms still hold the
    values of the row ``coefficients_source`` names); a :class:`_Kept` when they are the
    thesis's terms with other values (the warning, and the source that says they were
    kept); None when nothing changes (another body, a source naming no row, the same row, a
    value the core will refuse, another law, terms given with the default source).

    The one place where a scene follows its row: :class:`Scene` (so ``replace``, the cases
    and scene files with their ``--set``) and :func:`axis_rows` (a sweep's axis) call it."""
    rule = _ROW_RULES.get(scene.body.name if isinstance(scene.body, Linkage) else scene.body)
    source = scene.coefficients_source
    named = rule.pattern.fullmatch(source) if rule and isinstance(source, str) else None
    if rule is None or named is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        return None
    try:
        if not math.isfinite(value):  # an integer past any float overflows here
            return None
    except OverflowError:
        return None
    try:
        new, new_source = rule.row(float(value))
        old = rule.row(float(named.group(1)))[0]
    except InvalidSceneError:  # out of range: the core names the field
        return None
    if new_source == source:
        return None
    if scene.forces == _thesis_terms(old):
        return _thesis_terms(new), new_source
    if new == old or thesis_row(scene.forces) is None or source == _DEFAULTS["coefficients_source"]:
        # The same row; another law than the thesis's; or the terms given without a source
        # (the default source describes the default terms): nothing to follow or warn about.
        return None
    field, shown = rule.field, f"{float(value):g}"
    values = ", ".join(f"{k} = {v:g}" for k, v in new.as_dict().items())
    message = (
        f"{field} = {shown} selects {new_source} ({values}), but the force parameters were "
        f"changed from the row the scene names ({source}), so they are kept as given. For the "
        f"new row, set those values (or start from {rule.case.format(shown)}); to keep yours "
        "without this warning, set coefficients_source to say where they come from"
    )
    return _Kept(message, f"{source}, parameters changed (kept at {field} = {float(value):g})")


def axis_rows(scene: Any, axes: Mapping[str, list[Any]]) -> tuple[str, list[Any]] | None:
    """For a sweep of ``scene`` over ``axes``: the field that selects its coefficient row
    and, per value of that axis, the force terms ``scene.replace(field=value)`` has (the
    same :func:`_row_change`), or None where every run keeps the scene's terms (or the axes
    give the terms themselves). Parameters changed from the named row are kept, with one
    :class:`~granrs.errors.CoefficientsWarning` for the whole sweep."""
    rule = _ROW_RULES.get(scene.kind)
    if rule is None or rule.field not in axes or {"forces", "coefficients_source"} & set(axes):
        return None
    values = axes[rule.field]
    terms: list[Any] = []
    kept: list[_Kept] = []
    for value in values:
        change = _row_change(scene, value)
        terms.append(change[0] if isinstance(change, tuple) else scene.forces)
        if isinstance(change, _Kept):
            kept.append(change)
    if kept:
        warnings.warn(
            CoefficientsWarning(
                f"{len(kept)} of the {len(values)} values of the sweep's {rule.field} axis: "
                f"{kept[0].message}"
            ),
            stacklevel=3,
        )
    if all(t == scene.forces for t in terms):
        return None
    return rule.field, terms


def _caller_stacklevel() -> int:
    """The ``stacklevel`` of the first caller outside granrs and the dataclass machinery
    (for a warning raised while a scene is built)."""
    here = os.path.dirname(os.path.abspath(__file__))
    frame = sys._getframe(1)
    level = 1
    while frame.f_back is not None and (
        frame.f_code.co_filename.startswith(here)
        or frame.f_code.co_filename in ("<string>", dataclasses.__file__)
    ):
        frame = frame.f_back
        level += 1
    return level


#: The one table of a scene's fields (the core's, ``rust/spec/fields.rs``): name, part,
#: bodies, unit, note and doc of each, by name.
FIELD_INFO: dict[str, dict[str, Any]] = {f["name"]: f for f in _granrs.scene_fields()}

#: Fields that only one or two bodies use (any other field applies to every body), from
#: :data:`FIELD_INFO`.
BODY_FIELDS: dict[str, tuple[str, ...]] = {
    name: tuple(f["bodies"]) for name, f in FIELD_INFO.items() if f["bodies"]
}


@dataclass(frozen=True)
class Scene:
    """One impact of a body with sand (its fields are described below, from the one field
    table of the core: ``granrs.scene.FIELD_INFO``).
    """

    body: str | Linkage = "free_link"
    length: float = 0.190
    diameter: float = 0.0127
    mass: float = 0.184
    inertia: float | None = None
    rho_g: float = 1650.0
    g: float = 9.81
    medium: str | os.PathLike[str] | media.MediumCard | None = None
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
    outputs: tuple[str, ...] | None = None
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
    step_check: bool = True

    def __post_init__(self) -> None:
        for name in ("pin_joint", "ankle", "knee", "hip"):
            object.__setattr__(self, name, _joint(getattr(self, name), name))
        body = self.body
        if isinstance(body, Mapping):
            body = Linkage.from_mapping(body)
        if isinstance(body, Linkage):
            kind = body.name
        elif isinstance(body, str) and body in BODIES:
            kind = body
        else:
            raise UnknownNameError(
                f"unknown body {body!r}; allowed: {', '.join(BODIES)} or a granrs.bodies.Linkage",
                field="body",
            )
        if kind != "linkage":
            fields = self.__dict__
            body = Linkage._built_in(kind, {n: fields[n] for n in _BODY_PART_FIELDS[kind]})
        object.__setattr__(self, "body", body)
        for name in _NOT_NONE:
            if getattr(self, name) is None:
                raise InvalidParameterError(
                    f"{name} must be a value, not None (its default: {_DEFAULTS[name]!r})",
                    field=name,
                )

        defaults = _DEFAULTS
        for name, bodies in BODY_FIELDS.items():
            if kind not in bodies and _differs(getattr(self, name), defaults[name]):
                raise InvalidSceneError(
                    f"{name} applies to body {' or '.join(repr(b) for b in bodies)} only, "
                    f"not {kind!r}"
                    + (
                        " (a linkage's initial state is in its links and root)"
                        if kind == "linkage"
                        else ""
                    ),
                    field=name,
                )
        object.__setattr__(self, "forces", as_terms(self.forces))
        media.apply(self)
        object.__setattr__(self, "record", _names(self.record, "record", RECORDS))
        if self.outputs is not None:
            object.__setattr__(self, "outputs", _names(self.outputs, "outputs", OUTPUTS))
        rule = _ROW_RULES.get(kind)
        change = _row_change(self, getattr(self, rule.field)) if rule else None
        if isinstance(change, tuple):
            object.__setattr__(self, "forces", change[0])
            object.__setattr__(self, "coefficients_source", change[1])
        elif isinstance(change, _Kept):
            warnings.warn(CoefficientsWarning(change.message), stacklevel=_caller_stacklevel())
            object.__setattr__(self, "coefficients_source", change.source)
        # Every field checked by the core now, whoever built the scene (Python, TOML, the
        # CLI, cases): a bad field is a typed error naming it at construction, not when a
        # run, a model or a method first reads it. The compiled scene is kept for the run.
        self._compiled()

    def replace(self, **changes: Any) -> Scene:
        """A copy with some fields changed; an unknown field raises UnknownNameError (with
        the closest field name). Changing the free link's ``q_deg`` (the leg's ``v0``) of
        a scene made from a thesis coefficient row takes the new value's row (see the module
        doc); new ``forces`` (without a ``coefficients_source``) make the source
        ``"the scene's forces"`` (``granrs.scene.OWN_FORCES``)."""
        known = [f.name for f in dataclasses.fields(self)]
        for name in changes:
            if name in _REPLACED:
                raise UnknownNameError(
                    f"Scene has no field {name!r} any more: {_REPLACED[name]}", field=name
                )
            if name not in known:
                raise UnknownNameError(unknown_field_message(name, known), field=name)
        if (
            "forces" in changes
            and "coefficients_source" not in changes
            and as_terms(changes["forces"]) != self.forces
        ):
            # Terms given by the caller are theirs: no table row is followed any more.
            changes["coefficients_source"] = OWN_FORCES
        media.leave(self, changes, _DEFAULTS)
        return dataclasses.replace(self, **changes)

    @property
    def kind(self) -> str:
        """The body's kind: a built-in body's name (``"free_link"``, ``"chain"``,
        ``"leg"``) or ``"linkage"``."""
        return self.body.name  # type: ignore[union-attr]

    def as_linkage(self) -> Scene:
        """This scene with its body as a plain linkage (``body.detached()``) and every field
        that belongs to the built-in bodies only back at its default: the same run through
        the linkage's path, to the same result."""
        if self.kind == "linkage":
            return self
        reset = {n: _DEFAULTS[n] for n in BODY_FIELDS if "linkage" not in BODY_FIELDS[n]}
        return dataclasses.replace(self, body=self.body.detached(), **reset)  # type: ignore[union-attr]

    def to_dict(self) -> dict[str, Any]:
        """The scene as plain Python values, every field (a new dict): ``body`` is a
        built-in body's name or a linkage's mapping (links, joints, contacts, root)."""
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        d["body"] = self.body._core_value  # type: ignore[union-attr]
        d["forces"] = [t.to_dict() for t in self.forces]
        d["record"] = list(self.record)
        d["outputs"] = None if self.outputs is None else list(self.outputs)
        if self.medium is not None:
            card = self.medium
            d["medium"] = media.reference(card) or card.to_dict()  # type: ignore[arg-type,union-attr]
        return d

    def _plain(self) -> dict[str, Any]:
        """What the Rust core reads: the fields of this scene's body as plain values, built
        once per scene (it is frozen) and shared. Callers must not change it."""
        cached: dict[str, Any] | None = self.__dict__.get("_plain_cache")
        if cached is None:
            fields = self.__dict__
            cached = {name: fields[name] for name in _CORE_FIELDS[self.kind]}
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
        """This scene, checked in full by the Rust core (which a Scene is on construction:
        a bad field raises the typed error naming it then)."""
        self._compiled()
        return self

    def leg_segments(self) -> list[dict[str, Any]]:
        """The leg's segments scaled to this scene's body: name, mass [kg], length [m], com
        (from the segment's lower joint) [m], inertia about the centre of mass [kg m^2]."""
        if self.kind != "leg":
            raise InvalidSceneError("leg_segments() needs body='leg'", field="body")
        return list(_granrs.leg_segments(self.to_dict()))

    @property
    def q_rad(self) -> float:
        """Initial angle from the vertical [rad]."""
        return math.radians(self.q_deg)


def _field_doc(name: str) -> str:
    f = FIELD_INFO[name]
    unit = f" [{f['unit']}]" if f["unit"] not in ("", "-") else ""
    text = f"{name}: {f['doc']}{unit}."
    return textwrap.fill(
        text, width=92, initial_indent=" " * 8, subsequent_indent=" " * 12, break_on_hyphens=False
    )


def _scene_doc() -> str:
    names = [f.name for f in dataclasses.fields(Scene)]
    missing = set(names) ^ set(FIELD_INFO)
    if missing:  # the dataclass and the core's table name the same fields (tested)
        raise ImportError(f"granrs.Scene and the core's field table differ: {sorted(missing)}")
    groups = [
        (
            "    Attributes:",
            [n for n in names if FIELD_INFO[n]["bodies"] in ([], RODS, list(BODIES))],
        ),
        (
            "    Chain only (thesis chapter 4):",
            [n for n in names if FIELD_INFO[n]["bodies"] == ["chain"]],
        ),
        (
            "    Leg only (thesis chapter 5; segment data from Winter 2009, Table 4.1 and Fig. "
            "4.1, after\n    Dempster 1955; see :func:`granrs.cases.leg`):",
            [n for n in names if FIELD_INFO[n]["bodies"] == ["leg"]],
        ),
    ]
    parts = [(Scene.__doc__ or "").rstrip(), ""]
    for title, group in groups:
        parts.append(title)
        parts.extend(_field_doc(n) for n in group)
        parts.append("")
    return "\n".join(parts) + "    "


RODS = ["free_link", "chain"]
Scene.__doc__ = _scene_doc()

_DEFAULTS: dict[str, Any] = {
    f.name: f.default for f in dataclasses.fields(Scene) if f.default is not dataclasses.MISSING
}
#: Per body, the fields the Rust core reads (those of the body; not the notes).
_CORE_FIELDS: dict[str, tuple[str, ...]] = {
    body: tuple(
        f.name
        for f in dataclasses.fields(Scene)
        if body in BODY_FIELDS.get(f.name, (body,)) and FIELD_INFO[f.name]["part"] != "notes"
    )
    for body in KINDS
}
#: Per built-in body, the fields its linkage is built from (its body and start fields).
_BODY_PART_FIELDS: dict[str, tuple[str, ...]] = {
    body: tuple(
        n for n in _CORE_FIELDS[body] if FIELD_INFO[n]["part"] in ("body", "start") and n != "body"
    )
    for body in BODIES
}
#: Fields whose default is a value: None is refused for them.
_NOT_NONE: tuple[str, ...] = tuple(
    f.name for f in dataclasses.fields(Scene) if f.default is not None and f.name != "body"
)
