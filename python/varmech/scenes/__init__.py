"""Built-in scenes: native models in the fewest coordinates their physics needs, with initial
data, test horizon, invariants and, where known, a reference solution (sources in
``reference/`` of the repository).

Every scene, its parameters, description, step and invariants come from the core's catalogue
(``rust/core/src/scenes/catalogue.rs``): :func:`get` builds any of them by name, and the
functions here name them with their parameters for the reader, by family: separable
Hamiltonians, general Lagrangians, and scenes on constraints."""

from __future__ import annotations

from ._constrained import (
    ball_on_turntable,
    bouncing_ball,
    cartesian_pendulum,
    cartesian_spherical_pendulum,
    chaplygin_sleigh,
    elliptic_billiard,
    planar_chain,
    rigid_body,
    rolling_disk,
    rolling_sphere,
)
from ._hamiltonian import (
    fermi_pasta_ulam,
    harmonic_oscillator,
    henon_heiles,
    kepler,
    nbody,
    outer_solar_system,
    pendulum,
)
from ._lagrangian import (
    charged_particle,
    charged_particle_nonuniform,
    damped_driven_pendulum,
    double_pendulum,
    heavy_top,
    kepler_polar,
    spherical_pendulum,
)
from ._scene import CATALOGUE, SYMBOLIC, TIME_UNITS, as_scene, get
from ._scene import LONG_RUNS as LONG_RUNS
from ._scene import Reference as Reference
from ._scene import Scene as Scene

# Scene and Reference are documented once, as varmech.Scene and varmech.Reference.
__all__ = [
    "CATALOGUE",
    "SYMBOLIC",
    "TIME_UNITS",
    "as_scene",
    "ball_on_turntable",
    "bouncing_ball",
    "cartesian_pendulum",
    "cartesian_spherical_pendulum",
    "chaplygin_sleigh",
    "charged_particle",
    "charged_particle_nonuniform",
    "damped_driven_pendulum",
    "double_pendulum",
    "elliptic_billiard",
    "fermi_pasta_ulam",
    "get",
    "harmonic_oscillator",
    "heavy_top",
    "henon_heiles",
    "kepler",
    "kepler_polar",
    "nbody",
    "outer_solar_system",
    "pendulum",
    "planar_chain",
    "rigid_body",
    "rolling_disk",
    "rolling_sphere",
    "spherical_pendulum",
]
