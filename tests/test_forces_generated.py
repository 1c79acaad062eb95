"""The term constructors of ``granrs.forces`` are generated from the core's registry: nothing
about a term (its name, parameters, defaults, units, sources) is written in Python by hand.

Each test reads the registry itself (``granrs._granrs.term_infos()``), never a value the
code under test produced. On the hand-written constructors these failed: ``rft``'s
signature (zeta, elements, coefficients) lacked the nine coefficients the registry lists,
the docstrings did not carry the registry's summaries and sources, there was no generator
to call with a new term, no stub, and the defaults were typed in ``forces.py`` and
``force.py`` (15.2, 6.5, 248.0, 0.106).
"""

from __future__ import annotations

import dataclasses
import inspect
import io
import math
import tokenize
from pathlib import Path
from typing import Any

import pytest

import granrs
from granrs import _granrs, _stubgen, forces

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "python" / "granrs"


def _docs_generator() -> Any:
    """The docs' page generator (``docs/_ext/granrs_docs.py``), as the docs tests load it."""
    from test_docs_api import gen

    return gen


def _registry() -> list[dict[str, Any]]:
    return list(_granrs.term_infos())


@pytest.mark.parametrize("raw", _registry(), ids=lambda d: d["name"])
def test_every_registry_term_has_a_constructor_with_its_signature(raw: dict[str, Any]) -> None:
    """The signature lists the registry's parameters in its order, a required one without a
    default, the others with the registry's default (a count as an int)."""
    constructor = getattr(forces, raw["name"])
    assert raw["name"] in forces.__all__
    params = [
        p for p in inspect.signature(constructor).parameters.values() if p.name != "coefficients"
    ]
    assert [p.name for p in params] == [p["name"] for p in raw["params"]]
    for p, want in zip(params, raw["params"], strict=True):
        if want["required"]:
            assert p.default is inspect.Parameter.empty, p.name
        else:
            assert p.default == want["default"], p.name
            assert isinstance(p.default, int) == want["integer"], p.name
    # Called with its required parameters, it builds the term at the registry's defaults.
    required = {p["name"]: 1.0 for p in raw["params"] if p["required"]}
    built = constructor(**required)
    assert built.name == raw["name"]
    expected = {p["name"]: required.get(p["name"], p["default"]) for p in raw["params"]}
    assert dict(built.params) == expected


@pytest.mark.parametrize("raw", _registry(), ids=lambda d: d["name"])
def test_every_constructor_documents_the_registry(raw: dict[str, Any]) -> None:
    """The docstring carries the summary, equation and source, and each parameter with its
    unit, default (or "required") and the default's source."""
    doc = " ".join((getattr(forces, raw["name"]).__doc__ or "").split())
    for key in ("summary", "equation", "source"):
        assert " ".join(raw[key].split()) in doc, key
    for p in raw["params"]:
        entry = doc[doc.index(f" {p['name']}: ") :]
        assert entry.startswith(f" {p['name']}: {p['description']} [{p['unit']}]")
        value = (
            "required"
            if p["required"]
            else repr(int(p["default"]) if p["integer"] else p["default"])
        )
        assert value in entry[: 200 + len(p["source"])], p["name"]
        assert " ".join(p["source"].split()) in entry, p["name"]


def _fake_registry() -> list[dict[str, Any]]:
    """The registry with one more term, as the core would list it (a test build's term)."""
    fake = {
        "name": "my_term",
        "summary": "a made-up pull on each contact",
        "equation": "F = (p, -q d)",
        "source": "a test of granrs.forces",
        "acts": "contact",
        "class": "static",
        "velocity_dependent": False,
        "reads": "the contact's depth d",
        "switches": [],
        "columns": ["F_mx", "F_my"],
        "params": [
            {
                "name": "p",
                "unit": "N",
                "default": 0.25,
                "source": "made up",
                "min": 0.0,
                "max": math.inf,
                "description": "the pull",
                "integer": False,
                "required": False,
            },
            {
                "name": "q",
                "unit": "N/m",
                "default": math.nan,
                "source": "none: fitted",
                "min": 0.0,
                "max": math.inf,
                "description": "the depth stiffness",
                "integer": False,
                "required": True,
            },
            {
                "name": "n",
                "unit": "-",
                "default": 3.0,
                "source": "a count",
                "min": 1.0,
                "max": 64.0,
                "description": "pieces",
                "integer": True,
                "required": False,
            },
        ],
    }
    return [*_registry(), fake]


def test_a_new_registry_term_gets_a_constructor_docstring_and_stub_without_an_edit() -> None:
    """A term the core registers appears in Python with no other edit: constructor,
    signature, docstring and stub line all come from its registry entry."""
    infos = forces._load(_fake_registry())
    assert "my_term" in infos
    made = forces.constructors(infos.values())
    assert set(made) == {*forces.TERMS, "my_term"}
    mine = made["my_term"]
    sig = inspect.signature(mine)
    assert str(sig) == "(p: 'ParamValue' = 0.25, *, q: 'ParamValue', n: 'int' = 3) -> 'Term'"
    doc = mine.__doc__ or ""
    assert "a made-up pull on each contact" in doc and "F = (p, -q d)" in doc
    assert "p: the pull [N]; default 0.25 (made up)." in doc
    assert "q: the depth stiffness [N/m]; required" in doc
    assert "n: pieces [-], an integer from 1 to 64; default 3 (a count)." in doc
    assert "``F_mx``, ``F_my``" in doc
    stub = forces.stub(infos.values())
    assert "def my_term(\n    p: ParamValue = 0.25,\n    *,\n    q: ParamValue,\n" in stub
    assert '    "my_term",\n' in stub
    # The core does not know the term: calling the constructor reaches its typed error.
    with pytest.raises(granrs.UnknownNameError):
        mine(q=1.0)


def test_the_shapes_a_term_acts_on_are_read_when_the_core_lists_them() -> None:
    """A registry entry with ``shapes`` (the contact shapes a term is defined on) has them in
    its info and its docs page; without the key (a core that does not list them) the info
    says ``None`` and the page claims nothing."""
    raw = _fake_registry()
    assert forces._load(raw)["my_term"].shapes is None
    raw[-1] = {**raw[-1], "shapes": ["rod", "box"]}
    assert forces._load(raw)["my_term"].shapes == ("rod", "box")
    for name, d in zip(forces.TERMS, _registry(), strict=True):
        page = _docs_generator().term_rst(name)
        if "shapes" in d and d["acts"] == "contact":
            assert f"contact shapes\n     - {', '.join(f'``{s}``' for s in d['shapes'])}" in page
        else:
            assert "contact shapes" not in page


def test_a_term_whose_name_the_module_uses_is_refused() -> None:
    infos = forces._load(_fake_registry())
    clash = dataclasses.replace(infos["my_term"], name="select")
    with pytest.raises(RuntimeError, match="'select'"):
        forces.constructors([clash])


def test_the_committed_stub_is_the_registry_s() -> None:
    """``granrs/_constructors.pyi`` is what ``python -m granrs._stubgen`` writes from this
    core: a term added to the core without regenerating it fails here."""
    assert _stubgen.PATH.read_text(encoding="utf-8") == _stubgen.text(), (
        "the stub is not the registry's: run python -m granrs._stubgen"
    )
    assert _stubgen.main(["--check"]) == 0


def test_constructor_arguments_keep_working() -> None:
    """The special arguments: rft's coefficients mapping (the paper's names too), a count,
    per-contact tuples; a wrong call is a typed error naming the parameter."""
    t = forces.rft(1e6, elements=4, coefficients={"B-11": 0.1, "A00": 0.3})
    assert t.params["Bm11"] == 0.1 and t.params["A00"] == 0.3 and t.params["elements"] == 4
    assert forces.drag(eta_d=(13.0, 10.0)).params["eta_d"] == (13.0, 10.0)
    for call, field in [
        (lambda: forces.drag(1.0, 2.0), "drag"),
        (lambda: forces.drag(1.0, eta_d=2.0), "drag.eta_d"),
        (lambda: forces.rft(1e6, A00=0.1, coefficients={"A00": 0.2}), "rft.A00"),
        (lambda: forces.rft(1e6, coefficients={"k": 1.0}), "rft.k"),
        (lambda: forces.static_v(eta=1.0), "static_v.eta"),
        # k left out is to come from a medium: refused where the term must have it.
        (lambda: forces.poncelet(c=1.0).require(), "poncelet.k"),
        (lambda: granrs.Scene(forces=[forces.poncelet(c=1.0)]), "poncelet.k"),
    ]:
        with pytest.raises(granrs.GranrsError) as info:
            call()
        assert isinstance(info.value, ValueError)
        assert info.value.field == field


def _default_literals() -> set[float]:
    """The registry's defaults that are distinctive numbers (not 0, 1, 8, ...)."""
    return {
        p["default"]
        for raw in _registry()
        for p in raw["params"]
        if not p["required"]
        and math.isfinite(p["default"])
        and not (p["default"] == int(p["default"]) and abs(p["default"]) <= 10)
    }


def test_no_term_default_is_written_in_the_package() -> None:
    """No number in the package's code equals a term's default (15.2, 248.0, 0.106, an RFT
    coefficient, ...): every default is read from the registry. Numbers in strings and
    comments (the thesis's tables quoted as data) are not code."""
    defaults = _default_literals()
    assert {15.2, 6.5, 248.0, 0.106} <= defaults
    found = []
    paths = sorted(PACKAGE.rglob("*.py"))
    assert PACKAGE / "forces.py" in paths
    for path in paths:
        source = path.read_text(encoding="utf-8")
        for tok in tokenize.generate_tokens(io.StringIO(source).readline):
            if tok.type != tokenize.NUMBER:
                continue
            try:
                value = float(tok.string.replace("_", ""))
            except ValueError:  # a complex literal
                continue
            if value in defaults:
                found.append(f"{path.relative_to(ROOT)}:{tok.start[0]}: {tok.string}")
    assert not found, found
