"""varmech.table.Table: lookups of a column that does not exist name it, whichever method asks."""

import pytest

from varmech.table import Table


def test_an_unknown_column_is_a_key_error_naming_it_in_column_where_and_unique():
    table = Table(("method", "error"), [("verlet", 1e-3), ("midpoint", 2e-3)])
    with pytest.raises(KeyError, match=r"name: no column 'h' in \('method', 'error'\)"):
        table.column("h")
    with pytest.raises(KeyError, match=r"name: no column 'h'"):
        table.unique("h")
    with pytest.raises(KeyError, match=r"methd: no column 'methd'"):
        table.where(methd="verlet")
    assert table.where(method="verlet").rows == [("verlet", 1e-3)]
    assert table.unique("method") == ["verlet", "midpoint"]
