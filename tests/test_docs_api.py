"""The documentation site covers the package (issue 20: "documented like a scientific Python
library").

The API reference and the force-term pages are generated from the package when the docs
are built (``docs/_ext/granrs_docs.py``, called by ``docs/conf.py``). These tests read what
that generator writes, without Sphinx, and compare it with ``granrs.__all__``,
``granrs.forces.TERMS`` and the ``Scene`` dataclass. With ``GRANRS_DOCS_HTML`` set to a
built site (``.ci/run`` sets it after building the docs), they also check the built pages.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import os
import re
from pathlib import Path
from types import ModuleType

import pytest
from _modules import load_module

import granrs
from granrs import forces

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _generator() -> ModuleType:
    return load_module("granrs_docs", DOCS / "_ext" / "granrs_docs.py", reuse=True)


gen = _generator()


#: Python blocks of the pages that are not run, by (page, index among its python blocks).
NOT_RUN = {
    ("sweeps.md", 5): "needs a Dask scheduler",
    ("compare.md", 4): "a search of four sums on Table 3.1, about a minute of fits (sums are "
    "tested on a cheap set in test_compare.py)",
}
#: Blocks that show an error: the exception they must raise.
RAISES = {("getting_started.md", 1): "InvalidParameterError"}


def _pages() -> list[Path]:
    skip = {"_build", "generated", "auto_examples", "_templates", "_ext"}
    return sorted(p for p in DOCS.rglob("*.md") if not skip & set(p.relative_to(DOCS).parts))


def _built_site() -> Path:
    html = os.environ.get("GRANRS_DOCS_HTML")
    if not html:
        pytest.skip("GRANRS_DOCS_HTML is not set: no built site to check")
    path = Path(html)
    assert (path / "index.html").is_file(), f"GRANRS_DOCS_HTML={html} holds no built site"
    return path


def test_api_reference_lists_every_public_name_once() -> None:
    """Every name of granrs.__all__ has an autosummary entry (and so a page) in the API
    reference, and nothing else does."""
    entries = gen.autosummary_entries(gen.api_rst())
    assert sorted(set(entries)) == sorted(entries), "a name is listed twice"
    missing = sorted(set(granrs.__all__) - set(entries))
    extra = sorted(set(entries) - set(granrs.__all__))
    assert not missing, f"public names missing from the API reference: {missing}"
    assert not extra, f"API reference lists names that are not public: {extra}"


def test_api_sections_name_only_public_names() -> None:
    """The hand-ordered sections of the API reference (API_SECTIONS) list no name that has
    left granrs.__all__; a new public name needs no edit (it is documented anyway)."""
    assert gen.stale_api_names() == []


def test_autosummary_entries_reads_the_tables() -> None:
    """The parser the two tests above rely on finds the entries, and only them."""
    text = ".. autosummary::\n   :toctree: api\n\n   simulate\n   sweep\n\nNot an entry\n"
    assert gen.autosummary_entries(text) == ["simulate", "sweep"]


def test_every_force_term_has_a_page_from_the_registry() -> None:
    """One generated page per registered term, with its equation and each parameter's
    name and default as granrs.forces.info gives them."""
    pages = gen.generated_pages()
    for name in forces.TERMS:
        page = pages[f"{gen.GENERATED}/terms/{name}.rst"]
        info = forces.info(name)
        assert info.equation in page
        for p in info.params:
            default = "required" if p.required else repr(p.default)
            assert f"``{p.name}``" in page and default in page
        if info.shapes is not None and not set(info.shapes) & set(gen.PLANAR_SHAPES):
            # A term of bodies in space only: its page shows its use there.
            assert "granrs.space.Scene" in page
        else:
            assert f'term = "{name}"' in page
    index = pages[f"{gen.GENERATED}/terms/index.rst"]
    assert all(f"<term-{name}>" in index for name in forces.TERMS)


def test_the_forces_page_table_is_the_registry_s() -> None:
    """docs/forces.md's table of terms is generated (it was typed by hand, with the
    defaults 15.2, 6.5, 248.0 and 0.106 written there): one row per registered term, each
    parameter with its registry default and source."""
    page = (DOCS / "forces.md").read_text(encoding="utf-8")
    assert ".. granrs-terms-table::" in page
    assert "| `drag` |" not in page
    rows = gen.terms_table_rows()
    assert [r[0] for r in rows] == [f":ref:`{n} <term-{n}>`" for n in forces.TERMS]
    for row, name in zip(rows, forces.TERMS, strict=True):
        for p in forces.info(name).params:
            value = "required" if p.required else repr(int(p.default) if p.integer else p.default)
            assert f"``{p.name}`` [" in row[3] and f"({value};" in row[3], (name, p.name)


def test_scene_docstring_describes_every_field() -> None:
    """The body pages' field tables take each field's description from the Scene
    docstring: every field must have one."""
    described = gen.scene_field_docs()
    undescribed = [f.name for f in dataclasses.fields(granrs.Scene) if f.name not in described]
    assert undescribed == []


@pytest.mark.parametrize("page", _pages(), ids=lambda p: str(p.relative_to(DOCS)))
def test_docs_pages_python_examples_run(
    page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every ```python block of a page runs as written, in order, in one namespace (as a
    reader would paste them), with no warning."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    monkeypatch.chdir(tmp_path)  # pages write scene.toml and the like
    name = str(page.relative_to(DOCS))
    namespace: dict[str, object] = {}
    blocks = re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)
    for i, block in enumerate(blocks):
        if (name, i) in NOT_RUN:
            continue
        code = compile(block, f"{name}, python block {i}", "exec")
        with contextlib.redirect_stdout(io.StringIO()):
            if (name, i) in RAISES:
                with pytest.raises(granrs.GranrsError) as caught:
                    exec(code, namespace)
                assert type(caught.value).__name__ == RAISES[(name, i)]
            else:
                exec(code, namespace)
    plt.close("all")


def test_built_api_reference_covers_every_public_name() -> None:
    """In the built site, each public name has its page and the API index links to it."""
    html = _built_site()
    index = (html / "generated" / "api.html").read_text(encoding="utf-8")
    for name in granrs.__all__:
        page = html / "generated" / "api" / f"granrs.{name}.html"
        assert page.is_file(), f"no page for granrs.{name}"
        assert re.search(rf'href="api/granrs\.{re.escape(name)}\.html"', index), name


def test_built_site_has_every_term_and_gallery_page() -> None:
    """In the built site, each force term has its page and every gallery script its
    executed page with a figure."""
    html = _built_site()
    for name in forces.TERMS:
        assert (html / "generated" / "terms" / f"{name}.html").is_file(), name
    scripts = sorted((DOCS.parent / "examples" / "gallery").glob("plot_*.py"))
    assert scripts
    for script in scripts:
        page = (html / "auto_examples" / f"{script.stem}.html").read_text(encoding="utf-8")
        assert f"sphx_glr_{script.stem}_001.png" in page, f"{script.name} drew no figure"


def test_built_site_serves_its_math_locally() -> None:
    """The site renders its math offline: no page loads a script or a stylesheet from
    another host (the default MathJax comes from a CDN, so an offline reader saw raw
    ``\\(x\\)``; sphinx-gallery's computation-times pages load DataTables from CDNs), and
    the MathJax that the pages with math load is in the site itself."""
    html = _built_site()
    remote = {
        (str(page.relative_to(html)), src)
        for page in html.rglob("*.html")
        for src in re.findall(
            r'<(?:script[^>]*\ssrc|link[^>]*\shref)="((?:https?:)?//[^"]*)"',
            page.read_text(encoding="utf-8"),
        )
    }
    assert not remote, sorted(remote)[:5]
    model = (html / "model.html").read_text(encoding="utf-8")
    assert 'class="math' in model, "docs/model.md has no math any more: pick another page"
    scripts = re.findall(r'<script[^>]*\ssrc="([^"]*mathjax[^"]*)"', model, flags=re.I)
    assert scripts, "model.html loads no MathJax"
    for src in scripts:
        assert (html / src.split("?")[0]).is_file(), f"{src} is not in the built site"
