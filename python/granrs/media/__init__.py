"""Granular media as data: which numbers for my sand?

A medium card is one granular medium as a TOML file: its name, a description, the medium's
own numbers (the core's ``Medium``: ``rho_g`` and ``g``) and the parameters of the force
terms it has values for (``rft.zeta``, ``poncelet.c``, ``drag.eta_d``, ...), **every value
with its source** (paper and table, figure or equation; or "fitted here", with the data
and the method) and, optionally, its uncertainty: a standard deviation, an interval (with
its level) and posterior samples. What a card could not source it leaves out, and says so
(``missing``). The cards granrs ships are listed by :func:`names`; ``docs/media.md``
tabulates every value with its source. A card of your own is a file of the same form
(:meth:`MediumCard.save` writes one, :func:`load` reads it)::

    >>> import granrs
    >>> sand = granrs.media.load("thesis_sand")
    >>> sand.rho_g
    1650.0
    >>> sand.params_for("rft")
    {'zeta': 1871000.0}
    >>> sand.source("rft.zeta")[:40]
    'fitted here: granrs.calibrate("free_link'

A scene takes ``medium=`` (a card's name, a card file's path or a card): its ``rho_g`` and
``g`` come from the card, and each listed term takes the card's values for the parameters
the scene does not give (given values win; a term's own default is kept where the card has
no value)::

    >>> scene = granrs.Scene(medium="thesis_sand", forces=[granrs.forces.gravity(),
    ...                                                    granrs.forces.rft()])
    >>> scene.forces[1].params["zeta"]
    1871000.0

The names of the terms and parameters, their units and allowed ranges are the core's
registry's (:mod:`granrs.forces`): a card is checked against them when it is read, and an
unknown term or parameter, a value out of range or without a source raises
:class:`~granrs.errors.MediumError` naming the entry (``field="rft.zeta"``) before any run.

The file format (``format = 1``)::

    format = 1
    name = "my_sand"
    description = "..."

    [medium.rho_g]
    value = 1650.0
    source = "thesis sec. 3.3.1"

    [terms.rft.zeta]
    value = 1871000.0
    source = "fitted here: ..."
    sd = 126000.0                       # optional
    interval = [1640000.0, 2136000.0]   # optional, with level (default 0.95)
    level = 0.95
    samples = []                        # optional: posterior samples

    [missing]
    "poncelet.c" = "why the card has no value"
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import json
import math
import numbers
import os
import re
import stat
import sys
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any

from .. import _granrs, forces
from .._files import write_text
from ..errors import InvalidParameterError, InvalidSceneError, MediumError, UnknownNameError
from ..forces import Term

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = [
    "FORMAT_VERSION",
    "MEDIUM_FIELDS",
    "MediumCard",
    "Value",
    "load",
    "loads",
    "names",
]

#: Version of the card format :meth:`MediumCard.save` writes (the ``format`` key).
FORMAT_VERSION = 1
#: The largest card file :func:`load` reads [bytes] (posterior samples make a card large).
MAX_FILE_BYTES = 16 << 20

_FIELDS: dict[str, dict[str, Any]] = {f["name"]: f for f in _granrs.scene_fields()}
#: The medium's own numbers a card may give: the scene fields of the core's ``Medium``
#: (the field table's part ``"medium"``).
MEDIUM_FIELDS: tuple[str, ...] = tuple(n for n, f in _FIELDS.items() if f["part"] == "medium")

_VALUE_KEYS = ("value", "source", "sd", "interval", "level", "samples")
_CARD_KEYS = ("format", "name", "description", "medium", "terms", "missing")
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")
#: The ``coefficients_source`` of a scene whose terms took a medium's values.
_SOURCE = "medium {}"


def _near(name: str, known: Iterable[str]) -> str:
    close = difflib.get_close_matches(name, list(known), n=1, cutoff=0.5)
    return f"; did you mean {close[0]!r}?" if close else ""


def _real(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _finite(key: str, what: str, value: Any) -> float:
    try:
        number = float(value) if _real(value) else math.nan
    except OverflowError:  # an integer past any float
        number = math.nan
    if not math.isfinite(number):
        shown = repr(value) if len(repr(value)) < 40 else f"{repr(value)[:30]}..."
        raise MediumError(f"{key}: {what} must be a finite number, got {shown}", field=key)
    return number


def _items(value: Any) -> list[Any] | None:
    """``value`` as a list of its items, or None if it is not a sequence of them (a string,
    a number, a 0-d array, a mapping)."""
    if isinstance(value, str | bytes | Mapping) or not isinstance(value, Iterable):
        return None
    try:
        return list(value)
    except TypeError:  # iterable by type only (a 0-d numpy array)
        return None


@dataclass(frozen=True)
class Value:
    """One number of a card, with its source and (optionally) its uncertainty.

    Attributes:
        value: the number, in the unit of the parameter it sets (``granrs.forces.info``).
        source: where it comes from: paper and table, figure or equation, or "fitted here"
            with the data and the method. Required.
        sd: its standard deviation (``None``: not given).
        interval: an interval ``(low, high)`` around it (``None``: not given).
        level: the interval's level (0.95 unless said).
        samples: posterior samples of it (empty: none).
    """

    value: float
    source: str
    sd: float | None = None
    interval: tuple[float, float] | None = None
    level: float | None = None
    samples: tuple[float, ...] = ()

    def _checked(self, key: str) -> Value:
        value = _finite(key, "its value", self.value)
        if not isinstance(self.source, str) or not self.source.strip():
            raise MediumError(
                f"{key} has no source: every value of a card says where it comes from (paper "
                "and table, figure or equation; or 'fitted here' with the data and method)",
                field=f"{key}.source",
            )
        sd = None if self.sd is None else _finite(f"{key}.sd", "sd", self.sd)
        if sd is not None and sd < 0:
            raise MediumError(f"{key}.sd must be >= 0, got {sd!r}", field=f"{key}.sd")
        interval = None
        if self.interval is not None:
            pair = _items(self.interval)
            if pair is None or len(pair) != 2:
                raise MediumError(
                    f"{key}.interval must be [low, high], got {self.interval!r}",
                    field=f"{key}.interval",
                )
            low, high = (_finite(f"{key}.interval", "each end", x) for x in pair)
            if low > high:
                raise MediumError(
                    f"{key}.interval must be [low, high] with low <= high, got {pair!r}",
                    field=f"{key}.interval",
                )
            interval = (low, high)
        level = None if self.level is None else _finite(f"{key}.level", "level", self.level)
        if level is not None and not 0.0 < level < 1.0:
            raise MediumError(f"{key}.level must be in (0, 1), got {level!r}", field=f"{key}.level")
        if level is not None and interval is None:
            raise MediumError(f"{key}.level needs an interval", field=f"{key}.level")
        samples = _items(self.samples)
        if samples is None:
            raise MediumError(
                f"{key}.samples must be a list of numbers, got {self.samples!r}",
                field=f"{key}.samples",
            )
        out = tuple(_finite(f"{key}.samples", "each sample", x) for x in samples)
        return Value(value, self.source.strip(), sd, interval, level, out)

    def to_dict(self) -> dict[str, Any]:
        """The value as the table a card file holds (only the keys given)."""
        d: dict[str, Any] = {"value": self.value, "source": self.source}
        if self.sd is not None:
            d["sd"] = self.sd
        if self.interval is not None:
            d["interval"] = list(self.interval)
        if self.level is not None:
            d["level"] = self.level
        if self.samples:
            d["samples"] = list(self.samples)
        return d


def _as_value(key: str, raw: Any) -> Value:
    if isinstance(raw, Value):
        return raw._checked(key)
    if not isinstance(raw, Mapping):
        raise MediumError(
            f'{key} must be a table with value and source (value = ..., source = "..."), '
            f"got {raw!r}",
            field=key,
        )
    for k in raw:
        if k not in _VALUE_KEYS:
            raise MediumError(
                f"{key}: unknown key {k!r}{_near(str(k), _VALUE_KEYS)} (keys: "
                f"{', '.join(_VALUE_KEYS)})",
                field=f"{key}.{k}",
            )
    if "value" not in raw:
        raise MediumError(f"{key} has no value", field=f"{key}.value")
    if "source" not in raw:
        raise MediumError(
            f"{key} has no source: every value of a card says where it comes from",
            field=f"{key}.source",
        )
    return Value(
        value=raw["value"],
        source=raw["source"],
        sd=raw.get("sd"),
        interval=raw.get("interval"),
        level=raw.get("level"),
        samples=raw.get("samples", ()),
    )._checked(key)


def _bound(name: str) -> tuple[str, float] | None:
    """The lower bound the core's field table states for a medium field (``> 0``)."""
    m = re.fullmatch(r"\s*(>=?)\s*([-+0-9.eE]+)\s*", _FIELDS[name]["note"])
    return (m.group(1), float(m.group(2))) if m else None


def _check_medium(key: str, v: Value) -> None:
    bound = _bound(key)
    if bound and not (v.value > bound[1] if bound[0] == ">" else v.value >= bound[1]):
        unit = _FIELDS[key]["unit"]
        raise MediumError(
            f"{key} = {v.value!r} [{unit}] is out of range: it must be {bound[0]} {bound[1]:g}",
            field=key,
        )


def _split(key: Any) -> tuple[str, str]:
    """``"rft.zeta"`` as the term and the parameter, each checked against the registry."""
    if not isinstance(key, str) or key.count(".") != 1:
        raise MediumError(
            f"a card's parameter is named term.parameter (rft.zeta), got {key!r}", field=str(key)
        )
    term, param = key.split(".")
    if term not in forces.TERMS:
        raise MediumError(
            f"{key}: unknown term {term!r}{_near(term, forces.TERMS)} (terms: "
            f"{', '.join(forces.TERMS)})",
            field=key,
        )
    known = [p.name for p in forces.info(term).params]
    if param not in known:
        listed = ", ".join(known) or "none"
        raise MediumError(
            f"{key}: {term} has no parameter {param!r}{_near(param, known)} (its parameters: "
            f"{listed})",
            field=key,
        )
    return term, param


def _check_param(key: str, v: Value) -> None:
    term, param = _split(key)
    try:
        Term(term, {param: v.value})
    except InvalidSceneError as e:
        raise MediumError(f"{key}: {e}", field=key) from None


@dataclass(frozen=True)
class MediumCard:
    """One granular medium: its numbers and the force terms' parameters, each with its
    source. Frozen; read one with :func:`load`, write one with :meth:`save`.

    Attributes:
        name: its name (a file stem: letters, digits, ``_``, ``-``, ``.``).
        description: what the medium is, and what the card could and could not source.
        medium: the medium's own numbers by field (:data:`MEDIUM_FIELDS`: ``rho_g``,
            ``g``), each a :class:`Value`.
        params: the force terms' parameters by ``term.parameter`` (``rft.zeta``), each a
            :class:`Value`.
        missing: what the card has no value for and why, by ``term.parameter`` or field.
        path: the file it was read from (``None``: a shipped card or one made here); not
            compared.
    """

    name: str
    description: str = ""
    medium: Mapping[str, Any] = field(default_factory=dict)
    params: Mapping[str, Any] = field(default_factory=dict)
    missing: Mapping[str, str] = field(default_factory=dict)
    path: str | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not _NAME.fullmatch(self.name):
            raise MediumError(
                f"a card's name is a file stem (letters, digits, _, -, .), got {self.name!r}",
                field="name",
            )
        if not isinstance(self.description, str):
            raise MediumError(
                f"description must be text, got {self.description!r}", field="description"
            )
        for what, table in (("medium", self.medium), ("params", self.params)):
            if not isinstance(table, Mapping):
                raise MediumError(f"{what} must be a mapping, got {table!r}", field=what)
        medium = {}
        for key, raw in self.medium.items():
            if key not in MEDIUM_FIELDS:
                raise MediumError(
                    f"unknown medium field {key!r}{_near(str(key), MEDIUM_FIELDS)} (the "
                    f"medium's fields: {', '.join(MEDIUM_FIELDS)}; a term's parameter goes "
                    "in [terms.TERM.PARAM])",
                    field=str(key),
                )
            medium[key] = _as_value(key, raw)
            _check_medium(key, medium[key])
        params = {}
        for key, raw in self.params.items():
            _split(key)
            params[key] = _as_value(key, raw)
            _check_param(key, params[key])
        if not isinstance(self.missing, Mapping):
            raise MediumError(f"missing must be a mapping, got {self.missing!r}", field="missing")
        missing = {}
        for key, why in self.missing.items():
            if key not in MEDIUM_FIELDS:
                _split(key)
            if not isinstance(why, str) or not why.strip():
                raise MediumError(
                    f"missing.{key} must say why the card has no value for it", field=str(key)
                )
            if key in params or key in medium:
                raise MediumError(
                    f"{key} is both given and listed as missing", field=f"missing.{key}"
                )
            missing[key] = why.strip()
        object.__setattr__(self, "medium", MappingProxyType(dict(sorted(medium.items()))))
        object.__setattr__(self, "params", MappingProxyType(dict(sorted(params.items()))))
        object.__setattr__(self, "missing", MappingProxyType(dict(sorted(missing.items()))))

    def __hash__(self) -> int:
        return hash((self.name, tuple(self.medium.items()), tuple(self.params.items())))

    def __repr__(self) -> str:
        given = ", ".join([*self.medium, *self.params])
        return f"MediumCard({self.name!r}: {given or 'no values'})"

    def __reduce__(self) -> tuple[Any, ...]:
        # Pickle (Dask, multiprocessing) by its plain values.
        return (MediumCard.from_dict, (self.to_dict(), self.path))

    @property
    def rho_g(self) -> float | None:
        """The medium's bulk density [kg/m^3] (``None``: the card has none)."""
        v = self.medium.get("rho_g")
        return None if v is None else v.value

    @property
    def g(self) -> float | None:
        """Gravitational acceleration [m/s^2] (``None``: the card has none)."""
        v = self.medium.get("g")
        return None if v is None else v.value

    def value(self, key: str) -> Value:
        """The :class:`Value` of ``key`` (``rft.zeta``, ``rho_g``); a key the card has no
        value for raises :class:`~granrs.errors.UnknownNameError` saying why."""
        if key in self.params:
            return self.params[key]  # type: ignore[no-any-return]
        if key in self.medium:
            return self.medium[key]  # type: ignore[no-any-return]
        if key in self.missing:
            raise UnknownNameError(
                f"medium {self.name!r} has no value for {key}: {self.missing[key]}", field=key
            )
        if key not in MEDIUM_FIELDS:
            _split(key)
        given = ", ".join([*self.medium, *self.params]) or "none"
        raise UnknownNameError(
            f"medium {self.name!r} has no value for {key} (it gives: {given})", field=key
        )

    def source(self, key: str) -> str:
        """Where the card's value of ``key`` (``rft.zeta``, ``rho_g``) comes from."""
        return self.value(key).source

    def params_for(self, term: str) -> dict[str, float]:
        """The card's values of the term ``term``'s parameters, by parameter name (empty:
        the card has none); an unknown term raises, with a near miss."""
        forces.info(term)
        prefix = f"{term}."
        return {k[len(prefix) :]: v.value for k, v in self.params.items() if k.startswith(prefix)}

    def terms(self, *names: str) -> tuple[Term, ...]:
        """The terms ``names`` with this card's values (the others at their defaults), e.g.
        ``card.terms("gravity", "rft")``."""
        return tuple(Term(n, self.params_for(n), frozenset()) for n in names)

    def replace(self, **changes: Any) -> MediumCard:
        """A copy with some attributes changed (``name``, ``description``, ``medium``,
        ``params``, ``missing``), checked like a new card."""
        known = ("name", "description", "medium", "params", "missing")
        for k in changes:
            if k not in known:
                raise UnknownNameError(
                    f"MediumCard has no attribute {k!r}{_near(k, known)}", field=k
                )
        d = {k: getattr(self, k) for k in known}
        return MediumCard(**{**d, **changes})

    def with_value(
        self,
        key: str,
        value: float,
        source: str,
        *,
        sd: float | None = None,
        interval: tuple[float, float] | None = None,
        level: float | None = None,
        samples: Iterable[float] = (),
    ) -> MediumCard:
        """A copy with ``key`` (``rft.zeta``, ``rho_g``) set to ``value`` from ``source``
        (what a calibration writes): it is no longer listed as missing."""
        v = Value(value, source, sd, interval, level, tuple(samples))
        missing = {k: w for k, w in self.missing.items() if k != key}
        if key in MEDIUM_FIELDS:
            return self.replace(medium={**self.medium, key: v}, missing=missing)
        return self.replace(params={**self.params, key: v}, missing=missing)

    def to_dict(self) -> dict[str, Any]:
        """The card as the plain, nested data its file holds."""
        terms: dict[str, dict[str, Any]] = {}
        for key, v in self.params.items():
            term, param = key.split(".")
            terms.setdefault(term, {})[param] = v.to_dict()
        return {
            "format": FORMAT_VERSION,
            "name": self.name,
            "description": self.description,
            "medium": {k: v.to_dict() for k, v in self.medium.items()},
            "terms": terms,
            "missing": dict(self.missing),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], path: str | None = None) -> MediumCard:
        """A card from the nested data of its file (:meth:`to_dict`'s form)."""
        if not isinstance(data, Mapping):
            raise MediumError(f"a card is a table, got {type(data).__name__}", field="card")
        for k in data:
            if k not in _CARD_KEYS:
                raise MediumError(
                    f"unknown key {k!r} of a card{_near(str(k), _CARD_KEYS)} (keys: "
                    f"{', '.join(_CARD_KEYS)})",
                    field=str(k),
                )
        version = data.get("format", FORMAT_VERSION)
        if isinstance(version, bool) or version != FORMAT_VERSION:
            raise MediumError(
                f"unknown card format {version!r}; this granrs reads format {FORMAT_VERSION}",
                field="format",
            )
        if "name" not in data:
            raise MediumError("a card needs a name", field="name")
        terms = data.get("terms", {})
        if not isinstance(terms, Mapping):
            raise MediumError(f"terms must be tables [terms.TERM.PARAM], got {terms!r}", "terms")
        params: dict[str, Any] = {}
        for term, table in terms.items():
            if not isinstance(table, Mapping):
                raise MediumError(
                    f"terms.{term} must be a table of its parameters, got {table!r}",
                    field=str(term),
                )
            for param, raw in table.items():
                params[f"{term}.{param}"] = raw
        return cls(
            name=data["name"],
            description=data.get("description", ""),
            medium=data.get("medium", {}),
            params=params,
            missing=data.get("missing", {}),
            path=path,
        )

    def toml_lines(self, table: str = "") -> list[str]:
        """The card as TOML lines, under the table ``table`` (``""``: at the top level; a
        scene file writes a card made in memory as its ``[medium]`` table)."""
        head = f"{table}." if table else ""
        lines = [f"[{table}]"] if table else []
        lines += [
            f"format = {FORMAT_VERSION}",
            f"name = {_string(self.name)}",
            f"description = {_string(self.description)}",
        ]
        for section, values in (("medium", self.medium), ("terms", self.params)):
            for key, v in values.items():
                lines += ["", f"[{head}{section}.{key}]"]
                lines += [f"{k} = {_toml(x)}" for k, x in v.to_dict().items()]
        if self.missing:
            lines += ["", f"[{head}missing]"]
            lines += [f"{_string(k)} = {_string(w)}" for k, w in self.missing.items()]
        return lines

    def dumps(self) -> str:
        """The card as TOML text (floats exact: ``load`` gives back an equal card)."""
        top = (
            f"# granrs {_granrs.__version__} medium card: one granular medium, every value "
            "with its source."
        )
        return "\n".join([top, *self.toml_lines()]) + "\n"

    def save(self, path: str | os.PathLike[str]) -> str:
        """Write the card to ``path`` (whole or not at all) and return the text written."""
        text = self.dumps()
        write_text(path, text)
        return text


def _string(text: str) -> str:
    return json.dumps(text, ensure_ascii=False)


def _toml(value: Any) -> str:
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml(x) for x in value) + "]"
    return repr(float(value))


def loads(text: str, source: str = "<string>") -> MediumCard:
    """A card from TOML text; ``source`` names it in errors."""
    try:
        data = tomllib.loads(text.removeprefix("\ufeff"))
    except tomllib.TOMLDecodeError as e:
        raise MediumError(f"{source}: not a TOML card: {e}", field="card") from None
    try:
        return MediumCard.from_dict(data, None if source.startswith("<") else source)
    except MediumError as e:
        raise MediumError(f"{source}: {e}", field=e.field) from None


@functools.cache
def _shipped_files() -> dict[str, Any]:
    out = {}
    for entry in resources.files(__name__).iterdir():
        if entry.name.endswith(".toml"):
            out[entry.name[: -len(".toml")]] = entry
    return dict(sorted(out.items()))


def names() -> tuple[str, ...]:
    """The names of the cards granrs ships, sorted."""
    return tuple(_shipped_files())


@functools.cache
def _shipped(name: str) -> MediumCard:
    card = loads(_shipped_files()[name].read_text(encoding="utf-8"), f"<granrs.media {name}>")
    if card.name != name:  # pragma: no cover - a fault of the package, tested
        raise MediumError(f"the shipped card {name}.toml is named {card.name!r}", field="name")
    return card


def _read(path: str | os.PathLike[str]) -> str:
    name = os.fspath(path)
    info = os.stat(path)
    if not stat.S_ISREG(info.st_mode) or info.st_size > MAX_FILE_BYTES:
        raise MediumError(
            f"cannot read medium card {name}: not a regular file of at most {MAX_FILE_BYTES} bytes",
            field="medium",
        )
    with open(path, "rb") as handle:
        data = handle.read(MAX_FILE_BYTES + 1)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise MediumError(
            f"cannot read medium card {name}: not UTF-8 text ({e.reason})", field="medium"
        ) from None


def load(medium: str | os.PathLike[str] | MediumCard | Mapping[str, Any]) -> MediumCard:
    """The card ``medium``: a shipped card's name (:func:`names`), the path of a card file,
    a card (returned as it is) or a card's data (:meth:`MediumCard.to_dict`). An unknown name raises
    :class:`~granrs.errors.UnknownNameError` (``field="medium"``) with the closest name; a
    bad card :class:`~granrs.errors.MediumError` naming the entry."""
    if isinstance(medium, MediumCard):
        return medium
    if isinstance(medium, Mapping):
        return MediumCard.from_dict(medium)
    if not isinstance(medium, str | os.PathLike):
        raise InvalidParameterError(
            f"medium must be a medium's name, a card file's path or a granrs.media.MediumCard; "
            f"got {type(medium).__name__}",
            field="medium",
        )
    if isinstance(medium, str) and medium in _shipped_files():
        return _shipped(medium)
    path = os.fspath(medium)
    if isinstance(path, bytes) or not path or "\0" in path:
        raise InvalidParameterError(f"medium {medium!r} is not a name or a path", field="medium")
    try:
        is_file = os.path.exists(path)
    except (OSError, ValueError):
        is_file = False
    if not is_file:
        shipped = names()
        raise UnknownNameError(
            f"unknown medium {path!r}{_near(path, shipped)} (the shipped media: "
            f"{', '.join(shipped)}; or a card file's path)",
            field="medium",
        )
    absolute = str(Path(path).resolve())
    return loads(_read(path), absolute)


def reference(card: MediumCard) -> str | None:
    """How a scene file names ``card``: its name if it is a shipped card as shipped, the
    path it was read from, else ``None`` (a card made in memory: save it first)."""
    if card.name in _shipped_files() and _shipped(card.name) == card:
        return card.name
    return card.path


def scene_source(card: MediumCard) -> str:
    """The ``coefficients_source`` of a scene whose terms took ``card``'s values."""
    return _SOURCE.format(card.name)


def is_scene_source(text: Any) -> bool:
    """Whether ``text`` is a :func:`scene_source`."""
    return (
        isinstance(text, str)
        and re.fullmatch(r"medium [A-Za-z0-9][A-Za-z0-9_.-]*", text) is not None
    )


def resolve_terms(terms: Iterable[Term], card: MediumCard | None) -> tuple[Term, ...]:
    """``terms`` with each parameter their caller did not give (``Term.given``) taken from
    ``card`` where it has a value, else the term's default (a required one stays missing):
    the same terms where nothing changes."""
    out = []
    for t in terms:
        values = card.params_for(t.name) if card is not None else {}
        given = t.given or frozenset()
        params: dict[str, Any] = {}
        for p in t.info.params:
            if p.name in given:
                params[p.name] = t.params[p.name]
            elif p.name in values:
                params[p.name] = values[p.name]
            elif not p.required:
                params[p.name] = int(p.default) if p.integer else p.default
        same = dict(t.params) == params
        out.append(t if same else Term(t.name, params, given))
    return tuple(out)


def medium_values(card: MediumCard) -> dict[str, float]:
    """The card's values of the medium's fields (``rho_g``, ``g``) it gives."""
    return {k: v.value for k, v in card.medium.items()}


def _same(value: Any, other: Any) -> bool:
    """Whether a field's value equals ``other`` (a value that does not compare as one truth
    value, an array, does not)."""
    try:
        return bool(value == other)
    except (TypeError, ValueError):
        return False


def _scene_card(medium: Any) -> MediumCard:
    """:func:`load` for a scene's ``medium`` field: an error about an entry of the card
    keeps the entry as its ``field`` (``name``, ``rft.zeta``) and says in its message that
    it comes from the scene's ``medium``."""
    try:
        return load(medium)
    except MediumError as e:
        if str(e).startswith("medium") or getattr(e, "field", None) == "medium":
            raise
        raise MediumError(f"medium: {e}", field=e.field) from None


def apply(scene: Any) -> None:
    """Apply the scene's medium (a name, a path or a card: :func:`granrs.media.load`): its
    ``rho_g`` and ``g`` where the scene's are their defaults, and its values of the listed
    terms' parameters the caller did not give; the terms' source then names the medium
    (unless it names something else). A term still missing a required parameter is refused
    naming it. Shared by :class:`granrs.Scene` and :class:`granrs.space.Scene`."""
    card = None if scene.medium is None else _scene_card(scene.medium)
    object.__setattr__(scene, "medium", card)
    if card is not None:
        defaults = {f.name: f.default for f in dataclasses.fields(scene)}
        for name, value in medium_values(card).items():
            if _same(getattr(scene, name), defaults[name]):
                object.__setattr__(scene, name, value)
        terms = scene.forces
        if not isinstance(terms, tuple) or not all(isinstance(t, Term) for t in terms):
            return  # not terms: the scene's own check names the field
        resolved = resolve_terms(terms, card)
        if resolved != terms:
            object.__setattr__(scene, "forces", resolved)
            source = getattr(scene, "coefficients_source", None)
            if source is not None and (
                source == defaults["coefficients_source"] or is_scene_source(source)
            ):
                object.__setattr__(scene, "coefficients_source", scene_source(card))
    for t in scene.forces if isinstance(scene.forces, tuple) else ():
        if isinstance(t, Term) and t.missing:
            try:
                t.require()
            except InvalidSceneError as e:
                hint = (
                    f"; the medium {card.name!r} has no value for it either"
                    if card is not None
                    else "; give it, or a medium= whose card has it (granrs.media.names())"
                )
                raise type(e)(f"{e}{hint}", field=e.field) from None


def leave(scene: Any, changes: dict[str, Any], defaults: Mapping[str, Any]) -> None:
    """For ``scene.replace(**changes)`` that changes the medium: what the old medium set
    goes back to its default first (the fields equal to the card's values, the terms'
    parameters the caller did not give, a source naming the medium), so that the new
    medium (or none) applies as to a new scene. Changes the caller gave are kept."""
    old = scene.medium
    if "medium" not in changes or old is None or changes["medium"] is old:
        return
    for name, value in medium_values(old).items():
        if name not in changes and _same(getattr(scene, name), value):
            changes[name] = defaults[name]
    if "forces" not in changes:
        changes["forces"] = resolve_terms(scene.forces, None)
    source = getattr(scene, "coefficients_source", None)
    if "coefficients_source" not in changes and source == scene_source(old):
        changes["coefficients_source"] = defaults["coefficients_source"]
