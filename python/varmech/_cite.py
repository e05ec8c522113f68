"""How to cite varmech: :func:`cite`, the software entry of CITATION.cff as BibTeX.

The text is kept here, not read from CITATION.cff (which a wheel does not carry);
tests/python/test_packaging.py checks that the two agree."""

from ._version import __version__

__all__ = ["cite"]

#: The year of the release (CITATION.cff's date-released).
YEAR = 2026

TITLE = "varmech: variational integrators for long conservative simulations of mechanical systems"
URL = "https://github.com/varmech/varmech"


def cite() -> str:
    """The BibTeX entry that cites this version of varmech.

    Cite the methods you used too: each one's source is its ``reference`` in
    :func:`varmech.methods`.

    Returns
    -------
    str
        One ``@software`` entry, key ``varmech``, with this package's version
        (``varmech.__version__``), for a ``.bib`` file.

    See Also
    --------
    varmech.methods : Each method with its ``reference``, the source to cite for it.

    Examples
    --------
    >>> import varmech
    >>> print(varmech.cite())  # doctest: +ELLIPSIS
    @software{varmech,
      author = {{the varmech developers}},
      title = {varmech: variational integrators for long conservative simulations of mechanical systems},
      version = {...},
      year = {2026},
      url = {https://github.com/varmech/varmech},
      license = {MIT OR Apache-2.0},
    }
    """
    return (
        "@software{varmech,\n"
        "  author = {{the varmech developers}},\n"
        f"  title = {{{TITLE}}},\n"
        f"  version = {{{__version__}}},\n"
        f"  year = {{{YEAR}}},\n"
        f"  url = {{{URL}}},\n"
        "  license = {MIT OR Apache-2.0},\n"
        "}"
    )
