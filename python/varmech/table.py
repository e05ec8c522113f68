"""Tables of measurements: what the chart data functions return, and what the CLI writes as CSV."""

from __future__ import annotations

import copy
import csv
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import pandas

__all__ = [
    "Table",
]


@dataclass
class Table:
    """Measurements in named columns: ``rows`` are tuples in the order of ``columns``.

    ``title`` says what was measured and ``meta`` how (scene, step sizes, reference values), so
    that a chart or a CSV file carries its provenance. ``table.column(name)`` is a NumPy array,
    ``table.where(method="verlet")`` the matching rows, and ``table.to_csv(path)`` writes it.
    Iterating gives each row as a dict by column name.

    Attributes
    ----------
    columns : tuple of str
        The column names, distinct.
    rows : list of tuple
        The rows, each with one value per column, in column order.
    title : str, default ""
        What was measured.
    meta : dict, default {}
        How it was measured: scene, steps, reference values, notes.

    Raises
    ------
    ValueError
        Naming ``columns`` when names repeat, or ``row`` for a row of the wrong length.

    Examples
    --------
    >>> from varmech.table import Table
    >>> table = Table(("method", "h", "error"), title="Energy error", meta={"scene": "kepler"})
    >>> table.append("verlet", 0.1, 3.2e-3)
    >>> table.append("verlet", 0.05, 8.1e-4)
    >>> table.append("midpoint", 0.1, 1.6e-3)
    >>> table.column("error").max(), table.unique("method"), len(table.where(method="verlet"))
    (np.float64(0.0032), ['verlet', 'midpoint'], 2)
    >>> print(table.format(max_rows=2))
    Energy error
    method | h | error
    verlet | 0.1 | 0.0032
    verlet | 0.05 | 0.00081
    … 1 more rows
    """

    columns: tuple[str, ...]
    rows: list[tuple[Any, ...]] = field(default_factory=list)
    title: str = ""
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.columns = tuple(self.columns)
        if len(set(self.columns)) != len(self.columns):
            raise ValueError(f"columns: names repeat in {self.columns}")
        for row in self.rows:
            self._check(row)

    def _check(self, row: Sequence[Any]) -> None:
        if len(row) != len(self.columns):
            raise ValueError(f"row: has {len(row)} values for {len(self.columns)} columns {self.columns}")

    def append(self, *values: Any) -> None:
        """Add one row, its values in column order.

        Parameters
        ----------
        *values
            One value per column.

        Raises
        ------
        ValueError
            Naming ``row``: not one value per column.

        Examples
        --------
        >>> table = Table(("method", "h"))
        >>> table.append("verlet", 0.1)
        >>> table.rows
        [('verlet', 0.1)]
        >>> table.append("verlet")
        Traceback (most recent call last):
            ...
        ValueError: row: has 1 values for 2 columns ('method', 'h')
        """
        self._check(values)
        self.rows.append(tuple(values))

    def _index(self, name: str, argument: str) -> int:
        """The position of column ``name``; KeyError naming ``argument`` when there is none."""
        try:
            return self.columns.index(name)
        except ValueError:
            raise KeyError(f"{argument}: no column {name!r} in {self.columns}") from None

    def column(self, name: str) -> np.ndarray:
        """The values of column ``name``, as an array (float where they are numbers).

        Parameters
        ----------
        name : str
            The column.

        Returns
        -------
        ndarray, shape (len(rows),)
            Its values, as floats, or as objects where they are not all numbers.

        Raises
        ------
        KeyError
            Naming ``name``: no such column.

        Examples
        --------
        A column of numbers is a float array, any other an object array:

        >>> table = Table(("method", "h"), [("verlet", 0.1), ("midpoint", 0.05)])
        >>> table.column("h"), table.column("method")
        (array([0.1 , 0.05]), array(['verlet', 'midpoint'], dtype=object))
        """
        i = self._index(name, "name")
        values = [row[i] for row in self.rows]
        try:
            return np.array(values, dtype=float)
        except (TypeError, ValueError):
            return np.array(values, dtype=object)

    def where(self, **equal: Any) -> Table:
        """The rows whose columns equal the given values.

        Parameters
        ----------
        **equal
            Values by column name.

        Returns
        -------
        Table
            The matching rows, with the same columns, title and (a copy of the) metadata.

        Raises
        ------
        KeyError
            Naming the keyword that is not a column.

        Examples
        --------
        >>> table = Table(("method", "h"), [("verlet", 0.1), ("verlet", 0.05), ("midpoint", 0.1)])
        >>> table.where(method="verlet", h=0.05).rows, len(table.where(h=0.1))
        ([('verlet', 0.05)], 2)
        """
        idx = {self._index(k, k): v for k, v in equal.items()}
        rows = [r for r in self.rows if all(r[i] == v for i, v in idx.items())]
        return Table(self.columns, rows, self.title, dict(self.meta))

    def unique(self, name: str) -> list[Any]:
        """The distinct values of column ``name``, in order of appearance.

        Parameters
        ----------
        name : str
            The column.

        Returns
        -------
        list
            Its distinct values.

        Raises
        ------
        KeyError
            Naming ``name``: no such column.

        Examples
        --------
        >>> Table(("method", "h"), [("verlet", 0.1), ("midpoint", 0.1), ("verlet", 0.05)]).unique("method")
        ['verlet', 'midpoint']
        """
        i = self._index(name, "name")
        return list(dict.fromkeys(r[i] for r in self.rows))

    def to_csv(self, path: str | Path) -> Path:
        """Write the table as CSV (a header row, then the rows; the title and metadata as
        leading ``#`` comment lines).

        Parameters
        ----------
        path : str or pathlib.Path
            The file to write; its folder is created if needed, an existing file replaced.

        Returns
        -------
        pathlib.Path
            The path written.

        Raises
        ------
        OSError
            The file cannot be written.

        Examples
        --------
        >>> import pathlib, tempfile
        >>> table = Table(("method", "h"), [("verlet", 0.1)], title="Step sizes", meta={"scene": "kepler"})
        >>> path = table.to_csv(pathlib.Path(tempfile.mkdtemp()) / "steps.csv")
        >>> print(path.read_text(), end="")
        # Step sizes
        # scene: kepler
        method,h
        verlet,0.1
        """
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="") as f:
            if self.title:
                f.write(f"# {self.title}\n")
            for k, v in self.meta.items():
                f.write(f"# {k}: {v}\n")
            writer = csv.writer(f)
            writer.writerow(self.columns)
            writer.writerows(self.rows)
        return path

    def to_pandas(self) -> pandas.DataFrame:
        """The table as a :class:`pandas.DataFrame` (needs pandas, which the extra ``xarray``
        brings): one column per column, one row per row, and the title and metadata, which say
        what was measured and how, in ``DataFrame.attrs`` (``"title"`` and ``meta``'s entries).

        Returns
        -------
        pandas.DataFrame
            The rows under the table's column names.

        Raises
        ------
        ImportError
            pandas is missing.

        Examples
        --------
        >>> table = Table(("method", "h", "error"), [("verlet", 0.1, 3.2e-3), ("rk4", 0.1, 2.0e-6)],
        ...               title="Energy error", meta={"scene": "kepler"})
        >>> frame = table.to_pandas()
        >>> frame.loc[frame.error.idxmin(), "method"], frame.attrs
        ('rk4', {'title': 'Energy error', 'scene': 'kepler'})
        """
        try:
            import pandas
        except ImportError as err:
            raise ImportError("to_pandas needs pandas: pip install pandas (or 'varmech[xarray]')") from err
        frame = pandas.DataFrame.from_records(self.rows, columns=list(self.columns))
        frame.attrs = {"title": self.title, **copy.deepcopy(self.meta)}
        return frame

    def __len__(self) -> int:
        return len(self.rows)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        return (dict(zip(self.columns, r)) for r in self.rows)

    def format(self, max_rows: int | None = 20) -> str:
        """The title, the column names and the rows as text, numbers to four significant digits.

        Parameters
        ----------
        max_rows : int or None, default 20
            The rows shown (the first ones); None for all.

        Returns
        -------
        str
            One line for the title, one for the column names, one per row (" | " between
            values), and a last line counting the rows left out.

        Examples
        --------
        >>> table = Table(("h", "error"), [(0.1, 1 / 3), (0.05, float("nan"))])
        >>> print(table.format(max_rows=None))
        h | error
        0.1 | 0.3333
        0.05 | nan
        """

        def fmt(x: Any) -> str:
            if isinstance(x, float):
                return f"{x:.4g}" if math.isfinite(x) else str(x)
            return str(x)

        shown = self.rows if max_rows is None else self.rows[:max_rows]
        lines = [self.title] if self.title else []
        lines.append(" | ".join(self.columns))
        lines += [" | ".join(fmt(x) for x in r) for r in shown]
        if len(shown) < len(self.rows):
            lines.append(f"… {len(self.rows) - len(shown)} more rows")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return self.format()
