"""Scenes as files: one TOML file is one reproducible run.

The format (``format = 1``)::

    # granrs 0.1.0 scene file
    format = 1
    body = "free_link"
    length = 0.19            # m
    q_deg = 45.0             # deg
    record = []
    knee = { k = 300.0, c = 5.0 }   # leg joints: "free", "locked" or a spring-damper

    [[forces]]
    term = "gravity"

    [[forces]]
    term = "static_v"
    eta_v = 53.0
    lam = [0.25, 0.3]        # one value per contact, or one for all

Top-level keys are :class:`~granrs.Scene` field names; each ``[[forces]]`` table is one
force term (:mod:`granrs.forces`): ``term`` names it and its other keys are its parameters;
the tables list the terms that act, in order (no table: the default terms). A field left
out takes its default (the fields whose default is ``None`` can only be left out). The
writer (:func:`dumps`) writes every field that applies to the scene's body
(``granrs.scene.BODY_FIELDS``) and floats via ``repr``, so that
``loads(dumps(scene)) == scene`` exactly.

Reading validates in full (``Scene(...).validate()``) and every error points at the
offending key: a TOML syntax error raises :class:`~granrs.errors.InvalidSceneError` with
``file:line:col``; an unknown key :class:`~granrs.errors.UnknownNameError` with its line and
the closest field name; a wrong type or an out-of-range value the typed error of
:class:`~granrs.Scene` (``field`` set) with ``file:line`` of that key prepended.

A scene file is UTF-8 text (a byte-order mark at its start is allowed) in a regular file of
at most :data:`MAX_FILE_BYTES`; its arrays and tables nest at most :data:`MAX_NESTING`
deep (a scene needs five). Anything else (``/dev/zero``, a pipe, a folder, a file of
gigabytes, a value nested 500 deep in the file or in an override) is refused with an
:class:`~granrs.errors.InvalidSceneError` before it is parsed further.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import numbers
import os
import re
import stat
import sys
from collections.abc import Callable, Mapping
from typing import Any

from . import _granrs, forces, media, space
from ._files import write_text
from .bodies import ELEMENT_FIELDS
from .errors import InvalidParameterError, InvalidSceneError, UnknownNameError
from .scene import BODY_FIELDS, FIELD_INFO, Scene

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = [
    "FORMAT_VERSION",
    "MAX_FILE_BYTES",
    "MAX_NESTING",
    "dump",
    "dumps",
    "load",
    "loads",
    "parse_override",
]

#: Version of the scene file format written by :func:`dumps` (the ``format`` key).
FORMAT_VERSION = 1
#: Versions :func:`loads` reads.
SUPPORTED_FORMATS: tuple[int, ...] = (1,)
#: The largest scene file :func:`load` reads [bytes] (1 MiB; a linkage of a hundred links
#: takes about 20 kB).
MAX_FILE_BYTES = 1 << 20
#: How deep tables and arrays may nest in a scene file or an override, the file's top level
#: being 1 (a scene's deepest, a linkage's ``body`` -> ``links`` -> a link -> a list, is 5).
MAX_NESTING = 32

_FIELDS: tuple[dataclasses.Field[Any], ...] = dataclasses.fields(Scene)
_FIELD_NAMES: tuple[str, ...] = tuple(f.name for f in _FIELDS)
_FLOAT_FIELDS = frozenset(f.name for f in _FIELDS if "float" in str(f.type))
_JOINT_FIELDS = ("pin_joint", "ankle", "knee", "hip")
_KNOWN_KEYS = ("format", *_FIELD_NAMES)
#: Keys of earlier versions of the format and what to write instead.
_TOML_REPLACED: dict[str, str] = {
    "coefficients": 'the law must be [[forces]] tables (term = "drag" with eta_d = ..., '
    'term = "static_v" with eta_v and lam, ...; `granrs scene new` writes them)',
    "coefficients2": "link 2's values must be given per contact in the [[forces]] tables "
    "(eta_d = [13.0, 10.0]: link 1, link 2)",
    "effects": 'the terms that act must be listed as [[forces]] tables (term = "gravity", ...)',
}

#: One short note per field (unit first), written as a trailing comment: from the core's
#: field table (:data:`granrs.scene.FIELD_INFO`).
_NOTES: dict[str, str] = {
    name: ", ".join(x for x in (f["unit"] if f["unit"] != "-" else "", f["note"]) if x)
    for name, f in FIELD_INFO.items()
}

#: The same for the fields of a linkage's elements (:data:`granrs.bodies.ELEMENT_FIELDS`).
_ELEMENT_NOTES: dict[str, dict[str, str]] = {
    element: {
        name: ", ".join(x for x in (f["unit"] if f["unit"] != "-" else "", f["note"]) if x)
        for name, f in table.items()
    }
    for element, table in ELEMENT_FIELDS.items()
}

# ---------------------------------------------------------------------------------------
# Writing


def _format_string(text: str) -> str:
    """``text`` as a TOML basic string (quotes, backslashes and control characters escaped)."""
    out = ['"']
    for ch in text:
        code = ord(ch)
        if ch == '"':
            out.append('\\"')
        elif ch == "\\":
            out.append("\\\\")
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif ch == "\r":
            out.append("\\r")
        elif code < 0x20 or code == 0x7F:
            out.append(f"\\u{code:04X}")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def _format_float(value: float) -> str:
    """A float that TOML reads back bit for bit (``repr``; ``inf``/``nan`` spelled TOML's way)."""
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return repr(value)


def _format_value(value: Any) -> str:
    """A TOML value: bool, int, float, string, list (array) or mapping (inline table)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return _format_float(float(value))
    if isinstance(value, str):
        return _format_string(value)
    if isinstance(value, Mapping):
        items = ", ".join(f"{_format_key(k)} = {_format_value(v)}" for k, v in value.items())
        return "{ " + items + " }" if items else "{}"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_format_value(v) for v in value) + "]"
    raise InvalidParameterError(
        f"cannot write {value!r} ({type(value).__name__}) to TOML", field=None
    )


def _format_key(key: Any) -> str:
    key = str(key)
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else _format_string(key)


def _line(key: str, value: str, note: str | None) -> str:
    text = f"{key} = {value}"
    if note:
        text = f"{text:<27}  # {note}"
    return text


def _applies(name: str, body: str) -> bool:
    return name not in BODY_FIELDS or body in BODY_FIELDS[name]


def dumps(scene: Scene | space.Scene, *, comments: bool = True, header: str | None = None) -> str:
    """The scene as TOML text: every field that applies to its body, floats exact.

    Fields whose value is ``None`` (their default) are written as comments only.
    ``comments=False`` leaves out the per-field notes; ``header`` adds lines (each prefixed
    with ``"# "``) after the version line.
    """
    if isinstance(scene, space.Scene):
        return _dumps_space(scene, header)
    if not isinstance(scene, Scene):
        raise InvalidParameterError(
            f"dumps() takes a granrs.Scene or a granrs.space.Scene, got {type(scene).__name__}",
            field="scene",
        )
    lines = [f"# granrs {_granrs.__version__} scene file: one reproducible run."]
    if header:
        lines.extend(f"# {h}".rstrip() for h in header.splitlines())
    lines.append("# Units are SI (m, kg, s), angles in degrees. Run it: granrs run FILE")
    lines.append(f"format = {FORMAT_VERSION}")
    tables: list[str] = []
    for name in _FIELD_NAMES:
        if not _applies(name, scene.kind):
            continue
        value = getattr(scene, name)
        note = _NOTES.get(name) if comments else None
        if value is None:
            lines.append(f"# {name} = ...  ({note})" if note else f"# {name} = (left out)")
            continue
        if name == "body":
            if scene.kind != "linkage":
                lines.append(_line(name, _format_value(scene.kind), note))
            else:
                tables.extend(_body_tables(value._core_value))
            continue
        if name == "medium":
            ref = media.reference(value)
            if ref is None:
                tables.extend(["", *value.toml_lines("medium")])
            else:
                lines.append(_line(name, _format_value(ref), note))
            continue
        if name == "forces":
            if not value:
                lines.append(_line(name, "[]", "nothing acts"))
            for t in value:
                tables.append("")
                tables.append("[[forces]]")
                tables.append(f"term = {_format_value(t.name)}")
                tables.extend(
                    f"{_format_key(k)} = {_format_value(list(v) if isinstance(v, tuple) else v)}"
                    for k, v in t.params.items()
                )
            continue
        lines.append(_line(name, _format_value(value), note))
    return "\n".join(lines + tables) + "\n"


#: The fields of a body in space's scene file (``space = true``), in the order written.
_SPACE_FIELDS: tuple[str, ...] = tuple(
    f.name for f in dataclasses.fields(space.Scene) if f.init and f.name != "body"
)
#: Each shape's keys in its ``[body.shape]`` table (besides ``kind``).
_SPACE_SHAPES: dict[str, tuple[type, tuple[str, ...]]] = {
    "sphere": (space.Sphere, ("radius",)),
    "capsule": (space.Capsule, ("radius", "length")),
    "cylinder": (space.Cylinder, ("radius", "length")),
    "cuboid": (space.Cuboid, ("size",)),
    "mesh": (space.Mesh, ("vertices", "triangles")),
}


def _dumps_space(scene: Any, header: str | None) -> str:
    """A body in space as TOML: ``space = true``, its fields, ``[body]`` with its mass and
    ``[body.shape]``, and its ``[[forces]]``; floats exact."""
    lines = [f"# granrs {_granrs.__version__} scene file: a body in space, one reproducible run."]
    if header:
        lines.extend(f"# {h}".rstrip() for h in header.splitlines())
    lines.append("# Units are SI (m, kg, s); z is up. Run it: granrs run FILE")
    lines.append(f"format = {FORMAT_VERSION}")
    lines.append("space = true")
    tables: list[str] = []
    for name in _SPACE_FIELDS:
        value = getattr(scene, name)
        if name == "forces":
            for t in value:
                tables += ["", "[[forces]]", f"term = {_format_value(t.name)}"]
                tables += [f"{_format_key(k)} = {_format_value(v)}" for k, v in t.params.items()]
            continue
        if name == "medium":
            ref = None if value is None else media.reference(value)
            if value is not None and ref is None:
                tables.extend(["", *value.toml_lines("medium")])
            elif ref is not None:
                lines.append(f"{name} = {_format_value(ref)}")
            continue
        if isinstance(value, tuple):
            value = list(value)
        lines.append(f"{name} = {_format_value(value)}")
    body = scene.body
    lines += ["", "[body]"]
    for name in ("density", "mass"):
        if getattr(body, name) is not None:
            lines.append(f"{name} = {_format_value(getattr(body, name))}")
    if body.inertia is not None:
        rows = [[float(x) for x in row] for row in body.inertia]
        lines.append(f"inertia = {_format_value(rows)}")
    shape = body.shape
    kind = next(k for k, (cls, _) in _SPACE_SHAPES.items() if isinstance(shape, cls))
    lines += ["", "[body.shape]", f"kind = {_format_value(kind)}"]
    for key in _SPACE_SHAPES[kind][1]:
        value = getattr(shape, key)
        if kind == "mesh":
            value = value.tolist()
        lines.append(f"{key} = {_format_value(list(value) if isinstance(value, tuple) else value)}")
    return "\n".join(lines + tables) + "\n"


def _build_space(data: dict[str, Any], locate: Callable[[tuple[str, ...]], str]) -> Any:
    """A body in space's scene (:class:`granrs.space.Scene`) from parsed TOML data."""
    known = ("format", "space", "body", *_SPACE_FIELDS)
    for name in data:
        if name not in known:
            raise UnknownNameError(
                f"{locate((name,))}: unknown key {name!r}: not a field of a body in space"
                f"{_suggest(name, known)}",
                field=name,
            )
    body = data.get("body")
    if not isinstance(body, dict):
        raise InvalidSceneError(
            f"{locate(('body',))}: a body in space needs a [body] table with its mass "
            "(density = ..., or mass = ...) and a [body.shape] table",
            field="body",
        )
    for name in body:
        if name not in ("shape", "density", "mass", "inertia"):
            raise UnknownNameError(
                f"{locate(('body', name))}: unknown key {name!r} of [body] (shape, density, "
                "mass, inertia)",
                field=f"body.{name}",
            )
    shape = body.get("shape")
    if not isinstance(shape, dict) or shape.get("kind") not in _SPACE_SHAPES:
        raise InvalidSceneError(
            f"{locate(('body', 'shape'))}: [body.shape] needs kind = one of "
            f"{', '.join(repr(k) for k in _SPACE_SHAPES)}",
            field="body.shape.kind",
        )
    cls, keys = _SPACE_SHAPES[shape["kind"]]
    for name in shape:
        if name != "kind" and name not in keys:
            raise UnknownNameError(
                f"{locate(('body', 'shape', name))}: a {shape['kind']} has no key {name!r} "
                f"({', '.join(keys)})",
                field=f"body.shape.{name}",
            )
    missing = [k for k in keys if k not in shape]
    if missing:
        raise InvalidSceneError(
            f"{locate(('body', 'shape'))}: a {shape['kind']} needs {', '.join(missing)}",
            field=f"body.shape.{missing[0]}",
        )
    fields: dict[str, Any] = {}
    for name in _SPACE_FIELDS:
        if name not in data:
            continue
        value = data[name]
        if name == "forces":
            fields[name] = _forces(value, locate)
        elif isinstance(value, list):
            fields[name] = tuple(value)
        else:
            fields[name] = value
    try:
        args = [tuple(shape[k]) if k == "size" else shape[k] for k in keys]
        made = cls(*args)
        mass = {k: body[k] for k in ("density", "mass", "inertia") if k in body}
        return space.Scene(body=space.Body(made, **mass), **fields)
    except (InvalidSceneError, InvalidParameterError) as exc:
        path = tuple((exc.field or "").split(".")) if exc.field else ()
        term = re.match(r"forces\[(\d+)\]", exc.field or "")
        if term:
            path = ("forces", f"#{term.group(1)}")
        raise _reraise(exc, locate(path)) from None
    except TypeError as exc:
        raise InvalidSceneError(f"{locate(('body',))}: {exc}", field="body") from None


def _body_tables(body: Mapping[str, Any]) -> list[str]:
    """A linkage as ``[body.root]`` and ``[[body.links]]``, ``[[body.joints]]``,
    ``[[body.contacts]]`` tables (each element's fields left at ``None`` left out)."""

    def lines(element: str, values: Mapping[str, Any]) -> list[str]:
        return [
            _line(_format_key(k), _format_value(v), _ELEMENT_NOTES[element].get(k))
            for k, v in values.items()
        ]

    out = [
        "",
        "# The body: a linkage (granrs.bodies.Linkage): its root, links, joints, contacts.",
        "[body.root]",
    ]
    out.extend(lines("root", body["root"]))
    for part, element in (("links", "link"), ("joints", "joint"), ("contacts", "contact")):
        for values in body[part]:
            out.extend(["", f"[[body.{part}]]"])
            out.extend(lines(element, values))
    return out


def _body_path(field: str, body: Any) -> tuple[str, ...]:
    """Where a linkage's element field (``links.shank.mass``, ``joints[2].parent``,
    ``root.kind``) is in the TOML data: ``("body", "links", "#1", "mass")``."""
    parts = field.split(".")
    head = re.fullmatch(r"(links|joints|contacts)(?:\[(\d+)\])?", parts[0])
    if parts[0] == "root":
        return ("body", *parts)
    if not head or not isinstance(body, Mapping):
        return ("body",)
    part, index = head.group(1), head.group(2)
    rest = parts[1:]
    if index is None and rest:
        names = [e.get("name") if isinstance(e, Mapping) else None for e in body.get(part, [])]
        if rest[0] in names:
            index = str(names.index(rest[0]))
        rest = rest[1:]
    return ("body", part, f"#{index}", *rest) if index is not None else ("body", part)


def dump(scene: Scene | space.Scene, path: str | os.PathLike[str]) -> str:
    """Write the scene to ``path`` (UTF-8; whole or not at all: an error leaves an existing
    file as it was) and return the text written."""
    text = dumps(scene)
    write_text(path, text)
    return text


# ---------------------------------------------------------------------------------------
# Finding keys in the text

_KEY_PART = r'(?:[A-Za-z0-9_-]+|"(?:[^"\\]|\\.)*"|\'[^\']*\')'
_KEY_PATH = rf"{_KEY_PART}(?:\s*\.\s*{_KEY_PART})*"
_HEADER_RE = re.compile(rf"^\s*\[\[?\s*({_KEY_PATH})\s*\]\]?")
_KEY_RE = re.compile(rf"^\s*({_KEY_PATH})\s*=")
_PART_RE = re.compile(_KEY_PART)


def _split_key(path: str) -> tuple[str, ...]:
    parts = []
    for match in _PART_RE.finditer(path):
        part = match.group(0)
        if part[0] in "\"'":
            part = part[1:-1]
        parts.append(part)
    return tuple(parts)


def key_lines(text: str) -> dict[tuple[str, ...], int]:
    """The first line (1-based) at which each key path (and each of its prefixes) is set:
    ``{("length",): 4, ("forces", "#0"): 12, ("forces", "#0", "term"): 13, ...}`` (the
    n-th table of an array of tables is ``"#n"``).

    A plain scan of the text: table headers, ``key =`` lines and dotted keys; lines inside a
    multi-line string are skipped."""
    lines: dict[tuple[str, ...], int] = {}
    arrays: dict[tuple[str, ...], int] = {}
    table: tuple[str, ...] = ()
    in_string: str | None = None
    for number, raw in enumerate(text.splitlines(), start=1):
        if in_string is not None:
            if raw.count(in_string) % 2 == 1:
                in_string = None
            continue
        header = _HEADER_RE.match(raw)
        if header:
            table = _split_key(header.group(1))
            if raw.lstrip().startswith("[["):
                # An array of tables: the n-th is ("name", "#n").
                count = arrays[table] = arrays.get(table, -1) + 1
                table = (*table, f"#{count}")
            path = table
        else:
            key = _KEY_RE.match(raw)
            if not key:
                continue
            path = table + _split_key(key.group(1))
            rest = raw[key.end() :]
            for quote in ('"""', "'''"):
                if rest.count(quote) % 2 == 1:
                    in_string = quote
                    break
        for i in range(1, len(path) + 1):
            lines.setdefault(path[:i], number)
    return lines


# ---------------------------------------------------------------------------------------
# Reading


def _where(source: str, line: int | None) -> str:
    return f"{source}:{line}" if line is not None else source


def _reraise(exc: InvalidSceneError, where: str) -> InvalidSceneError:
    """``exc``'s class and field, with ``where: field:`` prepended to its message."""
    message = str(exc)
    if exc.field and exc.field not in message.split(":", 1)[0]:
        message = f"{exc.field}: {message}"
    try:
        new = type(exc)(f"{where}: {message}", field=exc.field)
    except TypeError:  # pragma: no cover - every granrs error takes (message, field)
        new = InvalidSceneError(f"{where}: {message}", field=exc.field)
    return new


def _syntax_error(exc: Exception, text: str, source: str) -> InvalidSceneError:
    message = str(exc)
    match = re.search(r"\(at line (\d+), column (\d+)\)", message)
    if match:
        line, col = int(match.group(1)), int(match.group(2))
        reason = message[: match.start()].strip()
    elif "end of document" in message:
        line = max(1, len(text.splitlines()))
        col = len(text.splitlines()[-1]) + 1 if text.splitlines() else 1
        reason = message.split("(at end of document)")[0].strip()
    else:  # pragma: no cover - tomllib always says where
        return InvalidSceneError(f"{source}: invalid TOML: {message}")
    field = None
    lines = text.splitlines()
    if 1 <= line <= len(lines):
        key = _KEY_RE.match(lines[line - 1])
        if key:
            field = ".".join(_split_key(key.group(1)))
    return InvalidSceneError(f"{source}:{line}:{col}: invalid TOML: {reason}", field=field)


def _suggest(name: str, choices: tuple[str, ...]) -> str:
    close = difflib.get_close_matches(name, choices, n=1)
    return f"; did you mean {close[0]!r}?" if close else ""


def _as_field_value(name: str, value: Any) -> Any:
    """TOML integers in float fields become floats (``length = 1`` is 1.0 m)."""
    if name in _FLOAT_FIELDS and isinstance(value, int) and not isinstance(value, bool):
        try:
            return float(value)
        except OverflowError:
            raise InvalidParameterError(
                f"invalid value for `{name}`: {value} is too large for a float "
                "(allowed: a finite real number within the field's range)",
                field=name,
            ) from None
    if name in _JOINT_FIELDS and isinstance(value, dict):
        return {
            k: float(v) if isinstance(v, int) and not isinstance(v, bool) else v
            for k, v in value.items()
        }
    return value


def _forces(value: Any, locate: Callable[[tuple[str, ...]], str]) -> tuple[Any, ...]:
    """The ``[[forces]]`` tables as terms: each ``term = "name"`` and its parameters (a
    number, or a list with one per contact). An error names the term, the parameter and the
    line of its ``[[forces]]`` table."""
    if not isinstance(value, list) or not all(isinstance(t, dict) for t in value):
        raise InvalidParameterError(
            f"{locate(('forces',))}: forces must be [[forces]] tables, each with "
            '`term = "name"` and its parameters',
            field="forces",
        )
    out = []
    for i, table in enumerate(value):
        where = locate(("forces", f"#{i}"))
        params = dict(table)
        name = params.pop("term", None)
        if not isinstance(name, str):
            raise InvalidParameterError(
                f'{where}: [[forces]] table {i + 1} needs `term = "name"` (one of '
                f"{', '.join(forces.TERMS)})",
                field="forces",
            )
        params = {k: tuple(v) if isinstance(v, list) else v for k, v in params.items()}
        try:
            out.append(forces.term(name, **params))
        except InvalidSceneError as exc:
            raise _reraise(exc, where) from None
    return tuple(out)


def _check_format(data: dict[str, Any], locate: Callable[[tuple[str, ...]], str]) -> None:
    """Take the ``format`` key out of ``data``: a version this granrs reads, else a typed
    error."""
    version = data.pop("format", FORMAT_VERSION)
    if isinstance(version, bool) or version not in SUPPORTED_FORMATS:
        raise InvalidSceneError(
            f"{locate(('format',))}: unknown scene file format {version!r}; this granrs "
            f"({_granrs.__version__}) reads format "
            f"{', '.join(str(v) for v in SUPPORTED_FORMATS)} (a newer granrs may read it)",
            field="format",
        )


def _build(
    data: dict[str, Any],
    locate: Callable[[tuple[str, ...]], str],
) -> Scene:
    """A validated Scene from parsed TOML data; ``locate`` says where a key path was set."""
    _check_format(data, locate)
    for name in data:
        if name in _TOML_REPLACED:
            raise UnknownNameError(
                f"{locate((name,))}: {name!r} is not a scene key any more: {_TOML_REPLACED[name]}",
                field=name,
            )
        if name not in _FIELD_NAMES:
            raise UnknownNameError(
                f"{locate((name,))}: unknown key {name!r}: not a Scene field"
                f"{_suggest(name, _KNOWN_KEYS)}",
                field=name,
            )
    fields: dict[str, Any] = {}
    for name, value in data.items():
        if name == "forces":
            fields[name] = _forces(value, locate)
            continue
        try:
            fields[name] = _as_field_value(name, value)
        except InvalidSceneError as exc:
            raise _reraise(exc, locate((name,))) from None
    try:
        scene = Scene(**fields)
        scene.validate()
    except InvalidSceneError as exc:
        path = tuple((exc.field or "").split(".")) if exc.field else ()
        if exc.field and isinstance(fields.get("body"), Mapping) and path[0] not in fields:
            path = _body_path(exc.field, fields["body"])
        raise _reraise(exc, locate(path)) from None
    return scene


def _nesting(value: Any) -> tuple[int, str | None]:
    """How deep tables and arrays nest in ``value`` (a table or array counts 1), and the
    top-level key of the deepest (without recursion: any depth is measured)."""
    deepest, key = 0, None
    stack: list[tuple[Any, int, str | None]] = [(value, 1, None)]
    while stack:
        item, depth, top = stack.pop()
        if isinstance(item, dict):
            children = [(v, str(k) if top is None else top) for k, v in item.items()]
        elif isinstance(item, list):
            children = [(v, top) for v in item]
        else:
            continue
        if depth > deepest:
            deepest, key = depth, top
        stack.extend((v, depth + 1, k) for v, k in children)
    return deepest, key


def _parse_toml(text: str, where: str, field: str | None = None) -> dict[str, Any]:
    """TOML text as data (a byte-order mark at its start is skipped), nested at most
    :data:`MAX_NESTING` deep, else :class:`~granrs.errors.InvalidSceneError` naming
    ``where`` and the key (or ``field``). A syntax error is ``tomllib``'s."""
    text = text.removeprefix("\ufeff")
    try:
        data = tomllib.loads(text)
        depth, key = _nesting(data)
    except RecursionError:
        # The parser recurses at least once per level: far past the limit.
        depth, key = MAX_NESTING + 1, None
    if depth > MAX_NESTING:
        key = field or key
        raise InvalidSceneError(
            f"{where}: {key + ': ' if key else ''}nested more than {MAX_NESTING} tables or "
            "arrays deep (a scene needs five)",
            field=key,
        )
    return data


def parse_override(text: str) -> tuple[str, Any]:
    """``"field=value"`` (a ``--set`` argument) as ``(field, value)``: the value is a TOML
    value (``30``, ``1e-5``, ``"tip"``, ``["state"]``, ``{ k = 300.0, c = 5.0 }``); a bare
    word that is not one is taken as a string (``body=chain``). ``field`` may be dotted
    (``knee.k=300``); ``term.param`` sets a parameter of the ``[[forces]]`` table of that
    term (``static_v.eta_v=300``)."""
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise InvalidSceneError(
            f"--set {text!r}: expected FIELD=VALUE (e.g. q_deg=30)", field=key or None
        )
    value = value.strip()
    try:
        parsed = _parse_toml(f"v = {value}", "--set", field=key)["v"]
    except tomllib.TOMLDecodeError:
        if not re.fullmatch(r"[A-Za-z0-9_.+-]+", value):
            raise InvalidSceneError(
                f"--set {text}: {value!r} is not a TOML value (quote strings: {key}='\"...\"')",
                field=key,
            ) from None
        parsed = value
    return key, parsed


def _apply_overrides(
    data: dict[str, Any], overrides: Mapping[str, Any] | None
) -> dict[tuple[str, ...], str]:
    """Set each ``--set`` override in ``data``; returns where each overridden path came from."""
    origins: dict[tuple[str, ...], str] = {}
    for key, value in (overrides or {}).items():
        path = tuple(part.strip() for part in key.split("."))
        shown = _format_value(value) if _is_writable(value) else repr(value)
        where = f"--set {key}={shown}"
        if len(path) == 2 and path[0] in forces.TERMS:
            # term.param: a parameter of that term's [[forces]] table (a file without
            # tables has the default terms).
            if "forces" not in data:
                data["forces"] = [t.to_dict() for t in Scene().forces]
            tables = data.get("forces")
            found = [
                i
                for i, t in enumerate(tables if isinstance(tables, list) else [])
                if isinstance(t, dict) and t.get("term") == path[0]
            ]
            if not found:
                raise InvalidSceneError(
                    f"{where}: the scene has no [[forces]] table with term = {path[0]!r}",
                    field=key,
                )
            tables[found[0]][path[1]] = value  # type: ignore[index]
            origins[("forces", f"#{found[0]}", path[1])] = where
            origins[("forces", f"#{found[0]}")] = where
            continue
        target = data
        for part in path[:-1]:
            existing = target.get(part)
            if not isinstance(existing, dict):
                existing = {}
                target[part] = existing
            target = existing
        target[path[-1]] = value
        origins[path] = where
    return origins


def _is_writable(value: Any) -> bool:
    try:
        _format_value(value)
    except InvalidSceneError:
        return False
    return True


def loads(text: str, source: str = "<string>", overrides: Mapping[str, Any] | None = None) -> Any:
    """A validated :class:`~granrs.Scene` from TOML text (a :class:`granrs.space.Scene`
    where the file says ``space = true``); ``source`` names it in errors.

    ``overrides`` (``{"q_deg": 30.0, "static_v.eta_v": 300.0}``) replace values of the
    file before validation; an error in one points at ``--set field=value``.
    """
    text = text.removeprefix("\ufeff")
    try:
        data = _parse_toml(text, source)
    except tomllib.TOMLDecodeError as exc:
        raise _syntax_error(exc, text, source) from None
    in_space = data.get("space") is True
    if in_space and "forces" not in data:
        data["forces"] = []
    origins = _apply_overrides(data, overrides)
    _medium_path(data, source)
    lines = key_lines(text)

    def locate(path: tuple[str, ...]) -> str:
        for n in range(len(path), 0, -1):
            if path[:n] in origins:
                return f"{source}: {origins[path[:n]]}"
            if path[:n] in lines:
                return _where(source, lines[path[:n]])
        return source

    if "space" in data:
        if data["space"] is not True:
            raise InvalidSceneError(
                f"{locate(('space',))}: `space` is true for a body in space (leave it out for "
                "a planar scene)",
                field="space",
            )
        _check_format(data, locate)
        return _build_space(data, locate)
    return _build(data, locate)


def _medium_path(data: dict[str, Any], source: str) -> None:
    """A scene file's ``medium`` given as a relative path is relative to the file's folder
    (when the file is read from a path and the card is there)."""
    value = data.get("medium")
    if not isinstance(value, str) or value in media.names() or os.path.isabs(value):
        return
    try:
        folder = os.path.dirname(source) if os.path.isfile(source) else ""
        candidate = os.path.join(folder, value)
        if folder and os.path.isfile(candidate):
            data["medium"] = candidate
    except (OSError, ValueError):
        return


def load(path: str | os.PathLike[str], overrides: Mapping[str, Any] | None = None) -> Any:
    """A validated :class:`~granrs.Scene` from the TOML file at ``path`` (see :func:`loads`).

    A file that is not a regular file, is larger than :data:`MAX_FILE_BYTES` or is not
    UTF-8 raises :class:`~granrs.errors.InvalidSceneError` (``field="scene"``) before it is
    read whole; one that cannot be opened raises the ``OSError`` of the operating system."""
    return loads(_read(path), source=os.fspath(path), overrides=overrides)


def _read(path: str | os.PathLike[str]) -> str:
    """The text of the scene file at ``path``, checked before it is read whole: a regular
    file (not a folder, a device such as ``/dev/zero`` or a pipe) of at most
    :data:`MAX_FILE_BYTES`, UTF-8 (a byte-order mark is dropped). Else
    :class:`~granrs.errors.InvalidSceneError` with ``field="scene"``; an ``OSError`` if it
    cannot be opened."""
    name = os.fspath(path)
    info = os.stat(path)
    if not stat.S_ISREG(info.st_mode):
        kind = "a directory" if stat.S_ISDIR(info.st_mode) else "not a regular file"
        raise InvalidSceneError(
            f"cannot read scene file {name}: it is {kind}; a scene file is read from a "
            "regular file",
            field="scene",
        )
    too_large = (
        f"cannot read scene file {name}: larger than {MAX_FILE_BYTES} bytes, the limit of a "
        "scene file"
    )
    if info.st_size > MAX_FILE_BYTES:
        raise InvalidSceneError(too_large, field="scene")
    with open(path, "rb") as handle:
        data = handle.read(MAX_FILE_BYTES + 1)  # it may have grown since
    if len(data) > MAX_FILE_BYTES:
        raise InvalidSceneError(too_large, field="scene")
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        raise InvalidSceneError(
            f"cannot read scene file {name}: not UTF-8 text (byte {exc.start}: {exc.reason})",
            field="scene",
        ) from None
