"""Charts (matplotlib, the optional extra ``varmech[charts]``).

Each chart takes the measurements a data function returns (a :class:`~varmech.Table`, or
trajectories) and writes a PNG or SVG file; the measurements themselves need no matplotlib.
"""

from .chaos import lyapunov_chart, orbit_diagram_chart, strobe_chart
from .energy import energy_error
from .nonholonomic import nonholonomic_energy_chart
from .sections import phase_portrait_chart, poincare_chart
from .stability import implicit_regions_chart, spectrum_chart, stability_chart
from .work_precision import energy_growth_chart, work_precision_chart

__all__ = [
    "energy_error",
    "energy_growth_chart",
    "implicit_regions_chart",
    "lyapunov_chart",
    "nonholonomic_energy_chart",
    "orbit_diagram_chart",
    "phase_portrait_chart",
    "poincare_chart",
    "spectrum_chart",
    "stability_chart",
    "strobe_chart",
    "work_precision_chart",
]
