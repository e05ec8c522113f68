"""Charts (matplotlib, the optional extra ``varmech[charts]``).

Each chart takes the measurements a data function returns (a :class:`~varmech.Table`, or
trajectories) and writes a PNG or SVG file; the measurements themselves need no matplotlib.
"""

from .energy import energy_error

__all__ = ["energy_error"]
