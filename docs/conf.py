"""Sphinx configuration of the gsdf documentation (offline: no intersphinx, no remote images).

Build: ``python -m sphinx -W -b html docs docs/_build/html`` (``pip install -e ".[docs]"``).
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "src"))  # document the checkout, not an installed copy

import gsdf  # noqa: E402

project = "gsdf"
author = "gsdf contributors"
release = version = gsdf.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "myst_parser",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "_generated", "_templates", "_static", "Thumbs.db", ".DS_Store"]
root_doc = "index"
templates_path = ["_templates"]  # autosummary/class.rst: a page per public method

# API reference: one page per public name (docs/api/index.rst lists gsdf.__all__; test_docs checks it)
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3
# docs/architecture.md and docs/batch.md link to source files outside docs/ (they read fine on GitHub)
suppress_warnings = ["myst.xref_missing"]

# offline: no intersphinx inventories, no remote images or assets at build time
intersphinx_mapping = {}
html_theme = "alabaster"
html_static_path = ["_static"]
html_css_files = ["gsdf.css"]  # code blocks scroll instead of being cut off; images fit the page
html_theme_options = {"description": "winding numbers and signed distance for broken geometry",
                      "fixed_sidebar": True}


def _numpy_headings(app, what, name, obj, options, lines):
    """Read the singular "Example" heading some internal docstrings use as numpy's "Examples"."""
    for i in range(len(lines) - 1):
        if lines[i].strip() == "Example" and set(lines[i + 1].strip()) == {"-"}:
            lines[i] = lines[i].replace("Example", "Examples")
            lines[i + 1] = lines[i + 1].replace("-------", "--------", 1)


def setup(app):
    app.connect("autodoc-process-docstring", _numpy_headings, priority=100)  # before numpydoc (500)
