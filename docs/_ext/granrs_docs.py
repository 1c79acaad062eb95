"""Pages and tables of the granrs docs that are generated from the package itself.

Nothing here is written by hand twice: the API reference lists ``granrs.__all__``, each force
term's page reads ``granrs.forces.info(name)`` (the Rust core's registry), the body tables
read the :class:`granrs.Scene` dataclass, its docstring and :mod:`granrs.cases`, and the
scene templates come from :func:`granrs.cases.template`. So these pages cannot drift
from the code.

``docs/conf.py`` calls :func:`generate` before Sphinx looks for source files (so that the
generated pages are found on a cold build and autosummary sees the API page), and loads this
module as an extension for its directives:

In Markdown pages these directives go inside an ``{eval-rst}`` block.

``.. granrs-body-fields:: BODY``
    The :class:`granrs.Scene` fields of one body: name, default, the value the
    ``:case:`` expression gives (e.g. ``granrs.cases.chain()``) and the field's description
    from the ``Scene`` docstring (units, default, source). ``:shared:`` lists the fields
    every body has instead.
``.. granrs-terms-table::``
    Every registered force term: what it acts on, its equation, its parameters with units,
    defaults and their sources, and the switches it owns (``granrs.forces.info``).
``.. granrs-media-table::``
    Every shipped medium card (``granrs.media``): each value with its unit, uncertainty
    and source, and what the card could not source.
``.. granrs-leg-segments::``
    The leg's segments (mass, length, centre of mass, inertia) of ``granrs.cases.leg()``.
``.. granrs-scene-template:: BODY``
    The commented starting point that ``granrs scene new --body BODY`` writes.

Importing this module needs granrs but not Sphinx (``tests/test_docs_api.py`` imports it).
"""

from __future__ import annotations

import dataclasses
import inspect
import re
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import granrs
from granrs import forces

#: Where the generated pages go, relative to the docs source directory (not committed).
GENERATED = "generated"

#: Sections of the API reference, in order. A name of ``granrs.__all__`` that no section
#: lists is still documented, under "Other public names"; a name listed here that is not in
#: ``granrs.__all__`` is left out (``tests/test_docs_api.py`` checks both).
API_SECTIONS: tuple[tuple[str, str, tuple[str, ...]], ...] = (
    (
        "Running impacts",
        "A scene is one impact; :func:`granrs.simulate` runs one and :func:`granrs.sweep` many.",
        (
            "simulate",
            "sweep",
            "Scene",
            "cases",
            "scenefile",
            "RECORDS",
            "OUTPUTS",
            "RK4_STABILITY_LIMIT",
        ),
    ),
    (
        "Bodies in space",
        "A free rigid body of any shape in three dimensions, under 3D resistive force theory.",
        ("space",),
    ),
    (
        "Results",
        "What a run returns, and how to watch it.",
        ("Result", "ContactResult", "animate", "animation", "ImpactAnimation"),
    ),
    (
        "The force law",
        "Force terms, the thesis's coefficients, and the law evaluated on its own.",
        (
            "forces",
            "Coefficients",
            "coefficients",
            "resistance_force",
            "ResistanceForce",
        ),
    ),
    (
        "Media",
        "Named granular media as data: each card's values for the force terms, with sources.",
        ("media",),
    ),
    (
        "Calibration",
        "Fitting the coefficients to measurements, and comparing force laws.",
        ("calibrate", "compare", "Measurements", "CalibrationResult"),
    ),
    (
        "The thesis's data",
        "The thesis's tables as shipped CSV files, with their provenance.",
        ("data",),
    ),
    (
        "Errors and warnings",
        "Every error is a :class:`granrs.GranrsError`; those caused by the input are also "
        ":class:`ValueError`.",
        (
            "GranrsError",
            "InvalidSceneError",
            "InvalidParameterError",
            "UnknownNameError",
            "CoefficientTableError",
            "MediumError",
            "MeasurementError",
            "SimulationError",
            "StepSizeWarning",
            "AnimationSizeWarning",
        ),
    ),
    ("Version", "", ("__version__",)),
)


# ---------------------------------------------------------------------------------------------
# The API reference
# ---------------------------------------------------------------------------------------------


def public_names() -> list[str]:
    """``granrs.__all__``, as the package declares it."""
    return list(granrs.__all__)


def api_sections() -> list[tuple[str, str, list[str]]]:
    """The API reference's sections with the names each documents: every name of
    ``granrs.__all__`` exactly once."""
    public = public_names()
    out = []
    seen: set[str] = set()
    for title, intro, names in API_SECTIONS:
        kept = [n for n in names if n in public and n not in seen]
        seen.update(kept)
        if kept:
            out.append((title, intro, kept))
    rest = [n for n in public if n not in seen]
    if rest:
        out.append(("Other public names", "", rest))
    return out


def stale_api_names() -> list[str]:
    """Names :data:`API_SECTIONS` lists that are not in ``granrs.__all__``."""
    public = set(public_names())
    return [n for _, _, names in API_SECTIONS for n in names if n not in public]


def api_rst() -> str:
    """The API reference page: one autosummary table per section (with a page per name)."""
    lines = [
        ".. _api:",
        "",
        "API reference",
        "=============",
        "",
        "Every public name of the ``granrs`` package (``granrs.__all__``), each with its own "
        "page generated from its docstring and signature. This page is generated from "
        "``granrs.__all__`` when the docs are built, so a name added to the package appears "
        "here without an edit.",
        "",
        ".. currentmodule:: granrs",
        "",
    ]
    for title, intro, names in api_sections():
        lines += [title, "-" * len(title), ""]
        if intro:
            lines += [intro, ""]
        lines += [".. autosummary::", "   :toctree: api", ""]
        lines += [f"   {name}" for name in names]
        lines.append("")
    return "\n".join(lines)


def autosummary_entries(text: str) -> list[str]:
    """The names listed in the autosummary tables of an rst text (what the API page
    documents)."""
    names: list[str] = []
    inside = False
    for line in text.splitlines():
        if line.startswith(".. autosummary::"):
            inside = True
            continue
        if inside:
            if line.startswith("   :") or not line.strip():
                continue
            if line.startswith("   "):
                names.append(line.strip())
            else:
                inside = False
    return names


# ---------------------------------------------------------------------------------------------
# Force terms
# ---------------------------------------------------------------------------------------------


def rst_escape(text: str) -> str:
    """Plain text made safe for reStructuredText (``|v_E|`` is not a substitution)."""
    return re.sub(r"([\\`*_|])", r"\\\1", text)


def _literal(text: str) -> str:
    return f"``{text}``" if text else "none"


def _number(value: float) -> str:
    return "-inf" if value == float("-inf") else repr(value)


#: Example values of the parameters that have no default, by unit, for the pages' "Use"
#: sections (each page says the value is an example).
EXAMPLE_BY_UNIT = {"N/m^3": 1e6, "N/m": 100.0, "-": 1.0}


#: The contact shapes of planar bodies (a term on none of them acts only in space).
PLANAR_SHAPES = ("rod", "box", "arc")


def example_params(name: str) -> dict[str, float]:
    """A value for each required parameter of the term ``name`` (none has a default)."""
    return {
        p.name: EXAMPLE_BY_UNIT.get(p.unit, 1.0) for p in forces.info(name).params if p.required
    }


def term_toml(name: str) -> str:
    """The term with its default parameters as a ``[[forces]]`` table, written by granrs's
    own scene writer (so it is what a scene file holds)."""
    scene = granrs.Scene(forces=[forces.term(name, **example_params(name))])
    text = granrs.scenefile.dumps(scene, comments=False)
    return text[text.index("[[forces]]") :].strip()


def term_rst(name: str) -> str:
    """The page of one force term, from ``granrs.forces.info(name)``."""
    info = forces.info(name)
    constructor = getattr(forces, name, None)
    example = example_params(name)
    args = ", ".join(f"{k}={v!r}" for k, v in example.items())
    if callable(constructor):
        python = f":func:`granrs.forces.{name}`"
        call = f"granrs.forces.{name}({args})"
    else:
        python = f':func:`granrs.forces.term` (``granrs.forces.term("{name}")``)'
        call = f'granrs.forces.term("{name}"{", " + args if args else ""})'
    title = f"``{name}``"
    lines = [
        f".. _term-{name}:",
        "",
        title,
        "=" * len(title),
        "",
        f"{rst_escape(info.summary[:1].upper() + info.summary[1:])}.",
        "",
        ".. code-block:: text",
        "",
        f"   {info.equation}",
        "",
        ".. list-table::",
        "   :widths: 25 75",
        "",
        "   * - acts on",
        f"     - {'each contact in the sand' if info.acts == 'contact' else 'the body'}"
        f" (``{info.acts}``)",
        *(
            ["   * - contact shapes", f"     - {', '.join(_literal(s) for s in info.shapes)}"]
            if info.shapes is not None and info.acts == "contact"
            else []
        ),
        "   * - class",
        f"     - ``{info.klass}`` (adds to the thesis's "
        f"{'F_d' if info.klass == 'dynamic' else 'F_s'})",
        "   * - velocity-dependent",
        f"     - {'yes' if info.velocity_dependent else 'no'}",
        "   * - reads",
        f"     - {rst_escape(info.reads)}",
        "   * - switches it owns",
        f"     - {'; '.join(rst_escape(s) for s in info.switches) or 'none'}",
        "   * - series columns",
        f"     - {', '.join(_literal(c) for c in info.columns) or 'none'}"
        + (" (with ``record=('forces',)``)" if info.columns else ""),
        "   * - source",
        f"     - {rst_escape(info.source)}",
        "   * - Python",
        f"     - {python}",
        "",
        "Parameters",
        "----------",
        "",
    ]
    if info.params:
        lines += [
            ".. list-table::",
            "   :header-rows: 1",
            "",
            "   * - name",
            "     - unit",
            "     - default",
            "     - smallest value",
            "     - largest value",
            "     - what it is",
            "     - source of the default",
        ]
        for p in info.params:
            lines += [
                f"   * - ``{p.name}``",
                f"     - {'dimensionless' if p.unit == '-' else rst_escape(p.unit)}",
                f"     - {'required' if p.required else _number(p.default)}",
                f"     - {_number(p.min)}",
                f"     - {'none' if p.max == float('inf') else _number(p.max)}",
                f"     - {rst_escape(p.description)}",
                f"     - {rst_escape(p.source)}",
            ]
        lines += [
            "",
            "A parameter is one number for every contact or a tuple with one value per "
            "contact (the chain's two links). In errors and in calibration it is named "
            f"``{name}.<parameter>``.",
        ]
    else:
        lines.append("None: the term reads what it needs from the scene.")
    lines += [
        "",
        "Use",
        "---",
        "",
        ".. code-block:: python",
        "",
        f"   {call}",
        "",
    ]
    if info.shapes is not None and not set(info.shapes) & set(PLANAR_SHAPES):
        # A term of bodies in space only: its use is a granrs.space scene (scene files hold
        # planar scenes).
        lines += [
            f"It acts on bodies in space (:doc:`/space`), e.g. ``granrs.space.Scene(body=..., "
            f"forces=[{call}, granrs.forces.gravity()])``.",
            "",
        ]
        return "\n".join(lines)
    lines += [
        "In a scene file (:doc:`/scenes_toml`), with every parameter at its default"
        + (
            f" ({', '.join(f'``{k}``' for k in example)}: an example value; it has no default)"
            if example
            else ""
        )
        + ":",
        "",
        ".. code-block:: toml",
        "",
        *("   " + line if line else "" for line in term_toml(name).splitlines()),
        "",
    ]
    return "\n".join(lines)


def _param_cell(p: Any) -> str:
    unit = "dimensionless" if p.unit == "-" else rst_escape(p.unit)
    value = "required" if p.required else _number(int(p.default) if p.integer else p.default)
    return f"``{p.name}`` [{unit}] ({value}; {rst_escape(p.source)})"


def terms_table_rows() -> list[list[str]]:
    """Rows of the terms' table: term, acts on, equation, parameters (unit, default and its
    source), switches owned; from the registry, in its order."""
    rows = []
    for name in forces.TERMS:
        info = forces.info(name)
        rows.append(
            [
                f":ref:`{name} <term-{name}>`",
                info.acts,
                f"``{info.equation}``",
                "; ".join(_param_cell(p) for p in info.params) or "none",
                "; ".join(rst_escape(s) for s in info.switches) or "none",
            ]
        )
    return rows


def terms_index_rst() -> str:
    """The index of the force-term pages, in the registry's order."""
    lines = [
        ".. _term-reference:",
        "",
        "Force term reference",
        "====================",
        "",
        "One page per registered force term, generated when the docs are built from "
        ":func:`granrs.forces.info` (the Rust core's registry: the same description that "
        "validation, TOML scenes and error messages read). :doc:`/forces` explains how a "
        "run evaluates them and how to add one.",
        "",
        ".. list-table::",
        "   :header-rows: 1",
        "",
        "   * - term",
        "     - acts on",
        "     - what it is",
        "     - parameters",
    ]
    for name in forces.TERMS:
        info = forces.info(name)
        params = ", ".join(f"``{p.name}``" for p in info.params) or "none"
        lines += [
            f"   * - :ref:`{name} <term-{name}>`",
            f"     - {info.acts}",
            f"     - {rst_escape(info.summary)}",
            f"     - {params}",
        ]
    lines += ["", ".. toctree::", "   :hidden:", ""]
    lines += [f"   {name}" for name in forces.TERMS]
    lines.append("")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# Writing the generated pages
# ---------------------------------------------------------------------------------------------


def _write(path: Path, text: str) -> None:
    """Write ``text`` unless the file already holds it (keeps incremental builds fast)."""
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")


def generated_pages() -> dict[str, str]:
    """Every generated page: path (relative to the docs source directory) -> text."""
    pages = {
        f"{GENERATED}/api.rst": api_rst(),
        f"{GENERATED}/terms/index.rst": terms_index_rst(),
    }
    for name in forces.TERMS:
        pages[f"{GENERATED}/terms/{name}.rst"] = term_rst(name)
    return pages


def generate(srcdir: str | Path) -> list[str]:
    """Write the generated pages under ``srcdir``; remove generated term pages of terms
    that no longer exist. Returns the paths written (relative)."""
    srcdir = Path(srcdir)
    pages = generated_pages()
    for rel, text in pages.items():
        _write(srcdir / rel, text)
    for old in (srcdir / GENERATED / "terms").glob("*.rst"):
        if f"{GENERATED}/terms/{old.name}" not in pages:
            old.unlink()
    return sorted(pages)


# ---------------------------------------------------------------------------------------------
# Scene fields, from the dataclass and its docstring
# ---------------------------------------------------------------------------------------------


def scene_field_docs() -> dict[str, str]:
    """Each :class:`granrs.Scene` field's description from the ``Scene`` docstring (its
    Google-style attribute lists), as reStructuredText."""
    doc = inspect.cleandoc(granrs.Scene.__doc__ or "")
    entries: list[tuple[list[str], list[str]]] = []
    entry = re.compile(r"^    ([a-z_0-9]+(?:, [a-z_0-9]+)*): (.*)$")
    inside = False
    for line in doc.splitlines():
        m = entry.match(line)
        if m:
            entries.append((m.group(1).split(", "), [m.group(2)]))
            inside = True
        elif line.startswith("        ") and inside:
            entries[-1][1].append(line.strip())
        else:
            inside = False
    return {name: " ".join(text) for names, text in entries for name in names}


def _format_value(value: Any) -> str:
    if isinstance(value, granrs.Coefficients):
        return ", ".join(f"{k} = {v!r}" for k, v in value.as_dict().items())
    if isinstance(value, tuple) and all(isinstance(v, str) for v in value):
        return ", ".join(value) if value else "()"
    if isinstance(value, tuple) and all(isinstance(v, granrs.Coefficients) for v in value):
        return "; ".join(_format_value(v) for v in value)
    return repr(value)


def body_fields(body: str, shared: bool = False) -> list[str]:
    """The Scene fields of one body (``shared=False``: those of that body alone; ``True``:
    those every body has)."""
    names = [f.name for f in dataclasses.fields(granrs.Scene)]
    built_in = set(granrs.scene.BODIES)
    # Fields of every built-in body (v0, depth0, vx0: a linkage's are in its elements).
    body_only = {n: b for n, b in granrs.scene.BODY_FIELDS.items() if not built_in <= set(b)}
    if shared:
        return [n for n in names if n not in body_only]
    return [n for n in names if body in body_only.get(n, ())]


def body_fields_rows(body: str, case: Any = None, shared: bool = False) -> list[list[str]]:
    """Rows of the body-fields table: field, ``Scene`` default, the case's value (if a case
    scene is given) and the description."""
    docs = scene_field_docs()
    defaults = {f.name: f.default for f in dataclasses.fields(granrs.Scene)}
    rows = []
    fields = body_fields(body, shared=shared)
    if case is not None and not shared:
        # Fields every body has, where the case differs from the Scene's default.
        fields += [
            n
            for n in body_fields(body, shared=True)
            if n not in fields and getattr(case, n) != defaults[n] and n != "body"
        ]
    for name in fields:
        row = [f"``{name}``", f"``{_format_value(defaults[name])}``"]
        if case is not None:
            row.append(f"``{_format_value(getattr(case, name))}``")
        row.append(_escape_prose(docs.get(name, "")))
        rows.append(row)
    return rows


def list_table(header: Sequence[str], rows: Iterable[Sequence[str]], widths: str = "") -> str:
    """An rst list-table."""
    lines = [".. list-table::", "   :header-rows: 1"]
    if widths:
        lines.append(f"   :widths: {widths}")
    lines.append("")
    for row in [list(header), *rows]:
        for i, cell in enumerate(row):
            lines.append(f"   {'* -' if i == 0 else '  -'} {cell}")
    return "\n".join(lines) + "\n"


def _unit_of(key: str) -> str:
    """The unit of a card's entry: the scene field's (``rho_g``) or the parameter's."""
    if "." not in key:
        return granrs.scene.FIELD_INFO[key]["unit"]
    term, param = key.split(".")
    return next(p.unit for p in forces.info(term).params if p.name == param)


def _uncertainty(v: Any) -> str:
    parts = []
    if v.sd is not None:
        parts.append(f"sd {v.sd:g}")
    if v.interval is not None:
        level = 0.95 if v.level is None else v.level
        parts.append(f"{level:.0%} [{v.interval[0]:g}, {v.interval[1]:g}]")
    if v.samples:
        parts.append(f"{len(v.samples)} samples")
    return "; ".join(parts)


def media_table_rows() -> list[list[str]]:
    """Rows of the media table: every shipped card's every value (medium, entry, value,
    unit, uncertainty, source) and what it could not source, from the cards themselves."""
    rows = []
    for name in granrs.media.names():
        card = granrs.media.load(name)
        entries = [*card.medium.items(), *card.params.items()]
        for key, v in entries:
            unit = _unit_of(key)
            rows.append(
                [
                    f"``{name}``",
                    f"``{key}``",
                    f"{v.value:g}",
                    "dimensionless" if unit == "-" else rst_escape(unit),
                    _uncertainty(v),
                    rst_escape(v.source),
                ]
            )
        for key, why in card.missing.items():
            rows.append([f"``{name}``", f"``{key}``", "not given", "", "", rst_escape(why)])
    return rows


def element_fields_rows() -> list[list[str]]:
    """Rows of the linkage elements' table (the core's ``ELEMENT_FIELDS``): element, field,
    unit, allowed values and what it is."""
    return [
        [
            element,
            f"``{name}``",
            f["unit"] if f["unit"] not in ("", "-") else "",
            _escape_prose(f["note"]),
            _escape_prose(f["doc"]),
        ]
        for element, table in granrs.bodies.ELEMENT_FIELDS.items()
        for name, f in table.items()
    ]


def leg_segments_rows() -> list[list[str]]:
    """The leg's segments of ``granrs.cases.leg()``: name, mass, length, com, inertia."""
    return [
        [
            f"``{s['name']}``",
            f"{s['mass']:.4g}",
            f"{s['length']:.4g}",
            f"{s['com']:.4g}",
            f"{s['inertia']:.4g}",
        ]
        for s in granrs.cases.leg().leg_segments()
    ]


# ---------------------------------------------------------------------------------------------
# Docstrings: how the package's plain-text conventions become reStructuredText
# ---------------------------------------------------------------------------------------------

#: Known rst mistakes in granrs docstrings, fixed here by exact replacement until they are
#: fixed in the package: object name -> ((text, replacement), ...). A fix-up that no longer
#: matches fails the build (like a strict xfail), so that it is removed once the docstring
#: is fixed.
DOCSTRING_FIXUPS: dict[str, tuple[tuple[str, str], ...]] = {}

#: Cross-references in granrs docstrings whose target is not public (so not documented):
#: (role, target) -> where. They are reported, not fixed here; each is a finding for the
#: package's docstrings. An entry that stops being needed fails the build, so that it is
#: removed once the docstring is fixed.
KNOWN_BROKEN_REFERENCES: dict[tuple[str, str], str] = {}


def attributes_section(doc: str | None) -> list[str]:
    """The names a Google-style ``Attributes:`` section of ``doc`` describes (napoleon
    documents those; autodoc must not document them a second time)."""
    lines = inspect.cleandoc(doc or "").splitlines()
    names: list[str] = []
    inside = False
    entry = re.compile(r"^    ([A-Za-z_0-9]+(?:, [A-Za-z_0-9]+)*)(?: \(.*\))?: ")
    for line in lines:
        if line.strip() == "Attributes:" and not line.startswith(" "):
            inside = True
            continue
        if inside:
            if line and not line.startswith(" "):
                # Another section (or a group rendered as attributes: see group_sections).
                inside = line.rstrip().endswith(":")
                continue
            m = entry.match(line)
            if m:
                names += m.group(1).split(", ")
    return names


def documented_attributes() -> dict[str, list[str]]:
    """For each class the API reference documents (by the name its page uses), the
    attributes its docstring's ``Attributes:`` section describes."""
    out: dict[str, list[str]] = {}

    def visit(prefix: str, namespace: Any, names: Iterable[str]) -> None:
        for name in names:
            obj = getattr(namespace, name, None)
            if inspect.isclass(obj):
                attrs = attributes_section(obj.__doc__)
                if attrs:
                    out[f"{prefix}.{name}"] = attrs

    visit("granrs", granrs, public_names())
    for name in public_names():
        module = getattr(granrs, name, None)
        if inspect.ismodule(module):
            visit(module.__name__, module, getattr(module, "__all__", ()))
    return out


def long_values(limit: int = 300) -> list[str]:
    """The documented constants whose value is too long to show in full (e.g.
    ``granrs.RECORDS``): their pages show the description only."""
    out = []
    for name in public_names():
        obj = getattr(granrs, name, None)
        if inspect.ismodule(obj):
            out += [
                f"{obj.__name__}.{n}"
                for n in getattr(obj, "__all__", ())
                if not callable(getattr(obj, n, None)) and len(repr(getattr(obj, n))) > limit
            ]
        elif not callable(obj) and len(repr(obj)) > limit:
            out.append(f"granrs.{name}")
    return out


_SECTION = re.compile(r"^[A-Z][^:]*:$")
_KNOWN_SECTIONS = {
    "Args:",
    "Arguments:",
    "Attributes:",
    "Example:",
    "Examples:",
    "Note:",
    "Notes:",
    "Raises:",
    "Returns:",
    "Return:",
    "Yields:",
    "Warns:",
    "Warning:",
    "See Also:",
    "References:",
    "Parameters:",
    "Keyword Args:",
    "Other Parameters:",
    "Methods:",
    "Todo:",
}


def group_sections(lines: list[str]) -> list[str]:
    """Groups of attributes under a heading of their own (``Chain only (thesis chapter
    4):`` in :class:`granrs.Scene`, a heading that may run over two lines) rendered as a
    rubric and an ``Attributes:`` section, with one entry per name of an entry that names
    several (``ankle, knee, hip: ...``)."""
    out: list[str] = []
    i = 0
    entry = re.compile(r"^    ([a-z_0-9]+(?:, [a-z_0-9]+)+): (.*)$")
    while i < len(lines):
        line = lines[i]
        # A heading: unindented lines ending in ":" followed by indented "name: text".
        j = i
        while j < len(lines) and lines[j] and not lines[j].startswith(" "):
            if lines[j].rstrip().endswith(":"):
                break
            j += 1
        is_heading = (
            line
            and not line.startswith(" ")
            and j < len(lines)
            and lines[j].rstrip().endswith(":")
            and j + 1 < len(lines)
            and re.match(r"^    [a-z_0-9, ]+: ", lines[j + 1]) is not None
            and " ".join(lines[i : j + 1]).strip() not in _KNOWN_SECTIONS
            and (j > i or _SECTION.match(line.strip()))
        )
        if not is_heading:
            out.append(line)
            i += 1
            continue
        title = " ".join(s.strip() for s in lines[i : j + 1]).rstrip(":")
        out += [f".. rubric:: {title}", "", "Attributes:"]
        i = j + 1
        while i < len(lines) and (not lines[i] or lines[i].startswith(" ")):
            m = entry.match(lines[i])
            if not m:
                out.append(lines[i])
                i += 1
                continue
            body = [m.group(2)]
            i += 1
            while i < len(lines) and lines[i].startswith("        "):
                body.append(lines[i])
                i += 1
            for name in m.group(1).split(", "):
                out.append(f"    {name}: {body[0]}")
                out += body[1:]
    return out


def escape_pipes(lines: list[str]) -> list[str]:
    """``|v_E|`` is plain-text notation in granrs docstrings, not a substitution: escape
    ``|`` in prose, leaving inline literals, literal blocks and doctests alone."""
    out: list[str] = []
    literal_indent: int | None = None  # inside an indented literal block
    doctest = False
    expect_literal = False
    for line in lines:
        stripped = line.strip()
        indent = len(line) - len(line.lstrip())
        if literal_indent is not None:
            if stripped and indent <= literal_indent:
                literal_indent = None
            else:
                out.append(line)
                continue
        if expect_literal and stripped:
            expect_literal = False
            out.append(line)
            continue
        if doctest:
            if not stripped:
                doctest = False
            out.append(line)
            continue
        if stripped.startswith(">>>"):
            doctest = True
            out.append(line)
            continue
        if stripped.endswith("::") or stripped.startswith(".. code-block::"):
            literal_indent = indent
            out.append(_escape_prose(line) if not stripped.startswith("..") else line)
            continue
        out.append(_escape_prose(line))
    return out


def _escape_prose(line: str) -> str:
    """Escape ``|`` outside inline literals and role targets on one line."""
    parts = re.split(r"(``.*?``|`[^`]*`)", line)
    return "".join(p if i % 2 else p.replace("|", "\\|") for i, p in enumerate(parts))


def _doc_comment(obj: Any, name: str) -> list[str] | None:
    """The ``#:`` comment of the module where ``obj`` was defined under ``name`` (for a
    constant re-exported by ``granrs``, whose own module has the comment)."""
    import sys

    from sphinx.pycode import ModuleAnalyzer

    short = name.rpartition(".")[2]
    for modname, module in sorted(sys.modules.items()):
        if not modname.startswith("granrs") or module is None:
            continue
        if getattr(module, short, None) is not obj:
            continue
        try:
            docs = ModuleAnalyzer.for_module(modname).find_attr_docs()
        except Exception:
            continue
        if ("", short) in docs:
            return list(docs[("", short)])
    return None


# ---------------------------------------------------------------------------------------------
# Sphinx
# ---------------------------------------------------------------------------------------------


def setup(app: Any) -> dict[str, Any]:
    """Register the directives (Sphinx extension entry point)."""
    from docutils import nodes
    from docutils.parsers.rst import directives
    from docutils.statemachine import StringList
    from sphinx.util.docutils import SphinxDirective

    class _RstDirective(SphinxDirective):
        def rst(self) -> str:
            raise NotImplementedError

        def run(self) -> list[Any]:
            if type(self.state).__module__.startswith("myst_parser"):
                # MyST would parse the generated reStructuredText as Markdown.
                raise self.error(f"{self.name}: use it inside an {{eval-rst}} block in Markdown")
            container = nodes.container()
            lines = StringList(self.rst().splitlines(), source="<granrs_docs>")
            self.state.nested_parse(lines, self.content_offset, container)
            return list(container.children)

    class BodyFields(_RstDirective):
        """``.. granrs-body-fields:: BODY`` with ``:case: EXPR`` or ``:shared:``."""

        required_arguments = 1
        option_spec = {"case": directives.unchanged, "shared": directives.flag}  # noqa: RUF012

        def rst(self) -> str:
            body = self.arguments[0]
            shared = "shared" in self.options
            case_expr = self.options.get("case")
            case = eval(case_expr, {"granrs": granrs}) if case_expr else None
            header = ["field", "``Scene`` default"]
            if case is not None:
                header.append(f"``{case_expr.removeprefix('granrs.')}``")
            header.append("what it is (units, source)")
            widths = "18 14 14 54" if case is not None else "20 15 65"
            rows = body_fields_rows(body, case=case, shared=shared)
            return list_table(header, rows, widths)

    class ElementFields(_RstDirective):
        """``.. granrs-element-fields::``: the fields of a linkage's elements."""

        def rst(self) -> str:
            header = ["element", "field", "unit", "allowed", "what it is"]
            return list_table(header, element_fields_rows(), "10 14 10 20 46")

    class TermsTable(_RstDirective):
        """``.. granrs-terms-table::``: every registered term, from the registry."""

        def rst(self) -> str:
            header = ["term", "acts on", "equation (granrs frame)", "parameters", "switches"]
            return list_table(header, terms_table_rows(), "12 8 30 35 15")

    class MediaTable(_RstDirective):
        """``.. granrs-media-table::``: every shipped medium card's values, with sources."""

        def rst(self) -> str:
            header = ["medium", "entry", "value", "unit", "uncertainty", "source"]
            return list_table(header, media_table_rows(), "12 14 9 8 14 43")

    class LegSegments(_RstDirective):
        """``.. granrs-leg-segments::``."""

        def rst(self) -> str:
            header = [
                "segment",
                "mass [kg]",
                "length [m]",
                "centre of mass from its lower joint [m]",
                "inertia about the centre of mass [kg m^2]",
            ]
            return list_table(header, leg_segments_rows())

    class SceneTemplate(SphinxDirective):
        """``.. granrs-scene-template:: BODY``: what ``granrs scene new`` writes."""

        required_arguments = 1

        def run(self) -> list[Any]:
            text = granrs.cases.template(self.arguments[0])
            block = nodes.literal_block(text, text)
            block["language"] = "toml"
            return [block]

    from sphinx.util import logging

    logger = logging.getLogger("granrs_docs")
    saved: dict[tuple[str, str], list[str]] = {}
    fixups_used: set[tuple[str, str]] = set()
    references_seen: set[tuple[str, str]] = set()
    full_read: list[bool] = [False]

    def before_napoleon(
        app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]
    ) -> None:
        if what == "data" and type(obj).__module__ == "builtins":
            type_doc = inspect.cleandoc(type(obj).__doc__ or "").splitlines()
            if [x for x in lines if x.strip()] == [x for x in type_doc if x.strip()]:
                # A re-exported constant: its doc comment is in the module defining it.
                lines[:] = _doc_comment(obj, name) or []
        if what in ("data", "attribute", "property"):
            # Napoleon reads "text: more" there as "type: description"; granrs's doc
            # comments are prose ("The thesis's free link (sec. 3.2.1): SI units.").
            saved[(what, name)] = list(lines)
        else:
            lines[:] = group_sections(lines)

    def after_napoleon(
        app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]
    ) -> None:
        if (what, name) in saved:
            lines[:] = saved.pop((what, name))
        for old, new in DOCSTRING_FIXUPS.get(name, ()):
            text = "\n".join(lines)
            if old in text:
                fixups_used.add((name, old))
                lines[:] = text.replace(old, new).split("\n")
        lines[:] = escape_pipes(lines)

    def missing_reference(app: Any, domain: Any, node: Any) -> bool | None:
        key = (node.get("reftype", ""), node.get("reftarget", ""))
        if key in KNOWN_BROKEN_REFERENCES:
            references_seen.add(key)
            return True
        return None

    def before_read(app: Any, env: Any, docnames: list[str]) -> None:
        full_read[0] = set(docnames) >= set(env.found_docs)

    def finished(app: Any, exception: Exception | None) -> None:
        if exception is not None or not full_read[0]:
            return
        for name, fixes in DOCSTRING_FIXUPS.items():
            for old, _ in fixes:
                if (name, old) not in fixups_used:
                    logger.warning(
                        f"granrs_docs: the docstring fix-up of {name} ({old!r}) no longer "
                        "matches: remove it from DOCSTRING_FIXUPS"
                    )
        for key in KNOWN_BROKEN_REFERENCES:
            if key not in references_seen:
                logger.warning(
                    f"granrs_docs: the reference {key} resolves or is gone: remove it from "
                    "KNOWN_BROKEN_REFERENCES"
                )

    app.connect("autodoc-process-docstring", before_napoleon, priority=400)
    app.connect("autodoc-process-docstring", after_napoleon, priority=600)
    app.connect("warn-missing-reference", missing_reference)
    app.connect("env-before-read-docs", before_read)
    app.connect("build-finished", finished)
    app.add_directive("granrs-body-fields", BodyFields)
    app.add_directive("granrs-leg-segments", LegSegments)
    app.add_directive("granrs-terms-table", TermsTable)
    app.add_directive("granrs-media-table", MediaTable)
    app.add_directive("granrs-element-fields", ElementFields)
    app.add_directive("granrs-scene-template", SceneTemplate)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
