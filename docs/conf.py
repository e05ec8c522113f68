"""Sphinx configuration of varmech's documentation: numpydoc docstrings, the pydata theme,
Markdown pages (MyST) and a sphinx-gallery of examples run at build time.

Build: ``make docs`` (html in docs/_build/html); the test command builds it with ``-W --keep-going``.
"""

import os
import sys
import types
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # the gallery's figures are drawn off-screen

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))  # the package of this tree, with its compiled _core

import varmech  # noqa: E402

project = "varmech"
author = "the varmech developers"
copyright = "the varmech developers"  # noqa: A001 (Sphinx's name)
release = version = varmech.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = [
    "_build",
    "examples/README.rst",
    "auto_examples/*.ipynb",
    "auto_examples/*.py",
    "auto_examples/*.zip",
]
templates_path = ["_templates"]

# Markdown: the README's pages keep their text; headings get anchors for links between pages.
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]

# API reference: one page an object, from the docstrings (numpydoc's sections).
autosummary_generate = True
autodoc_default_options = {"members": True, "inherited-members": False}
autodoc_typehints = "none"  # the numpydoc Parameters sections carry the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# The examples run when the docs build and their figures are drawn then.
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "show_memory": False,
    "min_reported_time": 1,
}

html_theme = "pydata_sphinx_theme"
html_title = "varmech"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_depth": 2,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False

# The build runs where no network is: nothing is fetched.
os.environ.setdefault("MPLBACKEND", "Agg")


def _escape_bars(app, what, name, obj, options, lines):
    """The docstrings write absolute values and norms as |x| (plain text for help()); reST reads
    |x| as a substitution, so the bars are escaped outside literals, doctests and tables."""
    literal_indent = None
    in_doctest = False  # a doctest block runs from its first >>> to the next blank line
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        in_doctest = bool(stripped) and (in_doctest or stripped.startswith(">>>"))
        if literal_indent is not None:
            if stripped and indent <= literal_indent:
                literal_indent = None
            else:
                continue
        if in_doctest or stripped.startswith(("| ", "+-", "+=")) or "|" not in line:
            if line.rstrip().endswith("::"):
                literal_indent = indent
            continue
        parts = line.split("``")
        parts[::2] = [part.replace("|", r"\|") for part in parts[::2]]
        lines[i] = "``".join(parts)
        if line.rstrip().endswith("::"):
            literal_indent = indent


def _skip_aliases(app, what, name, obj, skip, options):
    """Type aliases (``Piece = tuple[...]``) are annotations, not API: autodoc cannot sign them."""
    return True if isinstance(obj, types.GenericAlias) else None


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars, priority=600)
    app.connect("autodoc-skip-member", _skip_aliases)
