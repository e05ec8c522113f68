"""The docstring examples of the symbolic front end run as written (numpydoc ``Examples``)."""

import doctest
import importlib

import pytest

pytest.importorskip("sympy")


@pytest.mark.parametrize(
    "name", ["varmech.symbolic", "varmech.symbolic.examples", "varmech.symbolic._lower", "varmech.symbolic._derive", "varmech.events"]
)
def test_examples_run(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0, result
