"""Sphinx configuration of varmech's documentation: numpydoc docstrings, the pydata theme,
Markdown pages (MyST) and a sphinx-gallery of examples run at build time.

Build: ``make docs`` (html in docs/_build/html); the test command builds it with ``-W --keep-going``.
"""

import os
import re
import sys
import types
import zlib
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # the gallery's figures are drawn off-screen

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))  # the package of this tree, with its compiled _core
sys.path.insert(0, str(ROOT / "docs" / "_ext"))  # mathml (math at build time), apilinks (guide → reference)

import varmech  # noqa: E402

project = "varmech"
author = "the varmech developers"
copyright = "the varmech developers"  # noqa: A001 (Sphinx's name)
release = version = varmech.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.intersphinx",
    "sphinx.ext.autosummary",
    "mathml",
    "apilinks",
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

# Math: MathML from the LaTeX at build time (docs/_ext/mathml.py), no script and no network.
html_math_renderer = "mathml"

# Markdown: the README's pages keep their text; headings get anchors for links between pages.
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]

# API reference: one page an object, from the docstrings (numpydoc's sections).
autosummary_generate = True
autodoc_default_options = {"members": True, "inherited-members": False}
autodoc_typehints = "signature"  # the types in every rendered signature, the numpydoc sections say what they mean
autodoc_typehints_format = "short"
python_maximum_signature_line_length = 88  # longer signatures one parameter a line
# A class documented at the top level and on its module's page is one object under two names;
# a signature's reference to it may take either (Sphinx's "more than one target" warning).
suppress_warnings = ["ref.python"]
# Aliases shown by name, not expanded (numpy's ArrayLike is a union of seven protocols).
autodoc_type_aliases = {"ArrayLike": "numpy.typing.ArrayLike", "EventFunction": "varmech.events.EventFunction"}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
# The types of the Parameters and Returns sections link where they name a known class; every
# other word stays text.
numpydoc_xref_param_type = True
numpydoc_xref_ignore = "all"
numpydoc_xref_aliases = {
    "ndarray": "numpy.ndarray",
    "array_like": "numpy.typing.ArrayLike",
    "Figure": "matplotlib.figure.Figure",
    "Axes": "matplotlib.axes.Axes",
    "Dataset": "xarray.Dataset",
    "DataFrame": "pandas.DataFrame",
    **{name: f"sympy.physics.mechanics.{name}" for name in ("LagrangesMethod", "KanesMethod", "System")},
    **{name: f"varmech.{name}" for name in ("Model", "Scene", "Trajectory", "Table", "Ensemble", "Stepper", "Contact", "Impulse")},
}

# Links into NumPy, SciPy, SymPy, matplotlib, xarray and pandas, from inventories written here:
# the build runs where no network is, so none is fetched. Each lists the objects these pages
# name (Sphinx's inventory format 2), at its project's stable address.
MECHANICS = "modules/physics/mechanics/api"


def _pages(folder: str, *names: str, role: str = "py:class") -> dict[str, tuple[str, str]]:
    """Objects each documented on a page of its own, ``<folder>/<name>.html#<name>`` (the layout
    of autosummary's generated pages)."""
    return {name: (role, f"{folder}/{name}.html#{name}") for name in names}


EXTERNAL = {
    # numpydoc links the Python types of the docstrings' sections (bool, list, callable, …).
    "python": ("https://docs.python.org/3/", {
        "bltin-boolean-values": ("std:label", "library/stdtypes.html#bltin-boolean-values", "Boolean Values"),
        "None": ("py:data", "library/constants.html#None"),
        "True": ("py:data", "library/constants.html#True"),
        "False": ("py:data", "library/constants.html#False"),
        **{name: ("py:class", f"library/stdtypes.html#{name}") for name in ("list", "tuple", "str", "dict", "bytes", "set")},
        **{name: ("py:class", f"library/functions.html#{name}") for name in ("float", "int", "complex", "bool")},
        "callable": ("py:function", "library/functions.html#callable"),
        **{name: ("std:term", f"glossary.html#term-{name}") for name in ("function", "iterable", "sequence", "generator", "mapping")},
    }),
    "numpy": ("https://numpy.org/doc/stable/", {
        **_pages("reference/generated", "numpy.ndarray"),
        # An alias (py:data in NumPy's own inventory), listed as a class: annotations link classes.
        "numpy.typing.ArrayLike": ("py:class", "reference/typing.html#numpy.typing.ArrayLike"),
    }),
    "scipy": ("https://docs.scipy.org/doc/scipy/", _pages("reference/generated", "scipy.integrate.solve_ivp", role="py:function")),
    "sympy": ("https://docs.sympy.org/latest/", {
        **{
            f"sympy.physics.mechanics.{name}": ("py:class", f"{MECHANICS}/kane_lagrange.html#sympy.physics.mechanics.{module}.{name}")
            for name, module in (("LagrangesMethod", "lagrange"), ("KanesMethod", "kane"))
        },
        "sympy.physics.mechanics.System": ("py:class", f"{MECHANICS}/system.html#sympy.physics.mechanics.system.System"),
    }),
    "matplotlib": ("https://matplotlib.org/stable/", _pages("api/_as_gen", "matplotlib.axes.Axes", "matplotlib.figure.Figure")),
    "xarray": ("https://docs.xarray.dev/en/stable/", _pages("generated", "xarray.Dataset")),
    "pandas": ("https://pandas.pydata.org/docs/", _pages("reference/api", "pandas.DataFrame")),
}  # fmt: skip


def _inventory(project: str, objects: dict[str, tuple[str, ...]]) -> Path:
    """A Sphinx inventory (format 2) of ``objects`` (name → (role, address[, shown name])), under
    _build."""
    path = ROOT / "docs" / "_build" / "inventories" / f"{project}.inv"
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = "".join(f"{name} {entry[0]} 1 {entry[1]} {entry[2] if len(entry) > 2 else '-'}\n" for name, entry in objects.items())
    header = f"# Sphinx inventory version 2\n# Project: {project}\n# Version: \n# The remainder of this file is compressed using zlib.\n"
    path.write_bytes(header.encode() + zlib.compress(lines.encode()))
    return path


intersphinx_mapping = {name: (url, str(_inventory(name, objects))) for name, (url, objects) in EXTERNAL.items()}

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
html_static_path = ["_static"]
html_css_files = ["varmech.css"]
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


_ALIAS = re.compile(r"TypeAliasForwardRef\('([\w.]+)'\)")


def _alias_names(app, what, name, obj, options, signature, return_annotation):
    """An alias inside a union (``ArrayLike | None``) by its name: Sphinx writes its forward
    reference's repr there."""
    if signature is None:
        return None
    return _ALIAS.sub(r"~\1", signature), _ALIAS.sub(r"~\1", return_annotation) if return_annotation else return_annotation


def _skip_aliases(app, what, name, obj, skip, options):
    """Type aliases (``Piece = tuple[...]``) are annotations, not API: autodoc cannot sign them."""
    return True if isinstance(obj, types.GenericAlias) else None


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars, priority=600)
    app.connect("autodoc-skip-member", _skip_aliases)
    app.connect("autodoc-process-signature", _alias_names)
