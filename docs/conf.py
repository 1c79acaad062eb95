"""Sphinx configuration of the granrs documentation site.

Build (from the repository root; README "Documentation")::

    pip install -e '.[docs]' && sphinx-build -W --keep-going -b html docs docs/_build/html

The pages generated from the package (API reference, one page per force term) are written
by ``docs/_ext/granrs_docs.py`` below, before Sphinx looks for sources; the gallery
(``examples/gallery``) is executed by sphinx-gallery on every build.
"""

from __future__ import annotations

import builtins
import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(DOCS / "_ext"))

import granrs_docs  # noqa: E402

import granrs  # noqa: E402

granrs_docs.generate(DOCS)

# -- Project ----------------------------------------------------------------------------------

project = "granrs"
author = "the granrs developers"
copyright = "the granrs developers"
release = granrs.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    # MathJax served from the site itself, not a CDN, so that the math renders offline: the
    # package (a ``docs`` extra) ships MathJax 3 and copies it into _static/mathjax when the
    # build finishes; it points mathjax_path there.
    "sphinx-mathjax-offline",
    "sphinx.ext.viewcode",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "sphinxarg.ext",
    "granrs_docs",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = [
    "_build",
    "_templates",
    "auto_examples/*.ipynb",
    "auto_examples/*.py",
    "auto_examples/*.zip",
]

# A broken cross-reference fails the build (CI passes -n too).
nitpicky = True

# The script the pages load for their math: the copy above, never a URL
# (tests/test_docs_api.py checks the built pages).
mathjax_path = "mathjax/tex-chtml.js"

# -- Markdown (MyST) --------------------------------------------------------------------------

myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# -- API reference ----------------------------------------------------------------------------

autosummary_generate = True
autosummary_ignore_module_all = False
# Attributes a class docstring describes (napoleon documents them; autodoc must not again).
# Constants too long to print in full show their description only.
autosummary_context = {
    "documented_attributes": granrs_docs.documented_attributes(),
    "long_values": granrs_docs.long_values(),
}
autodoc_member_order = "bysource"
autodoc_preserve_defaults = True
autodoc_typehints = "description"
autodoc_typehints_description_target = "documented_params"
# One parameter per line in signatures longer than this (Scene has 45 fields).
python_maximum_signature_line_length = 88
napoleon_google_docstring = True
napoleon_numpy_docstring = False
napoleon_use_rtype = False

# The build runs offline (no intersphinx inventories), so references to Python's own and to
# third-party types cannot resolve; they are ignored here, and only they. A reference to a
# granrs name that does not resolve still fails the build.
_BUILTINS = "|".join(sorted(n for n in dir(builtins) if not n.startswith("_")))
_EXTERNAL = (
    rf"({_BUILTINS})",
    r"(collections\.abc|typing|types|os|io|pathlib|argparse|numbers|dataclasses|enum)\.\w+",
    r"(numpy|np|pandas|pd|matplotlib|mpl|dask|distributed|scipy|tqdm|gymnasium)(\.\w+)*",
    r"(NDArray|ArrayLike|DataFrame|Series|Figure|Axes|FuncAnimation)",
    r"importlib\.(abc|resources)(\.\w+)*",
    # importlib's Traversable, named bare in granrs.data's annotations (imported for typing).
    r"Traversable",
)
nitpick_ignore_regex = [(r"py:.*", pattern) for pattern in _EXTERNAL]

# -- Gallery ----------------------------------------------------------------------------------

sphinx_gallery_conf = {
    "examples_dirs": os.path.relpath(ROOT / "examples" / "gallery", DOCS),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "show_memory": False,
    "min_reported_time": 1,
    # No "computation times" pages: their sortable tables load jQuery and DataTables from
    # CDNs, and the site loads nothing from another host (tests/test_docs_api.py).
    "write_computation_times": False,
    "reference_url": {"granrs": None},
}

# -- HTML -------------------------------------------------------------------------------------

html_theme = "pydata_sphinx_theme"
html_title = f"granrs {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc", "sourcelink"],
}
html_show_sourcelink = True
