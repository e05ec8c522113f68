"""Each scene of the core's catalogue declared once, with what Python adds to it: its coordinates'
names, its units, its contact surfaces, its twins (the closure model of :mod:`varmech.examples`,
the symbolic one of :mod:`varmech.symbolic.examples`) and its runs in the tour. A new scene is its
file in ``rust/core/src/scenes/``, its line in the core's catalogue and its line here
(tests/python/test_scenes.py holds the two tables to the same names)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

from .impacts import Contact

#: The units of a scene without its own: every quantity dimensionless.
DIMENSIONLESS: Mapping[str, str] = MappingProxyType({"t": "1", "q": "1", "p": "1", "v": "1", "E": "1"})

#: Hairer, Lubich and Wanner's units of the outer solar system: distances in astronomical units,
#: time in days, masses in the Sun's.
_SOLAR = MappingProxyType(
    {"t": "days", "q": "AU", "p": "solar masses AU/day", "v": "AU/day", "E": "solar masses AU^2/day^2"}
)

Contacts = Callable[[Mapping[str, float]], tuple[Contact, ...]]


@dataclass(frozen=True)
class Declared:
    """What Python says of a catalogue scene besides the core's entry.

    ``coordinates``: their names, spelled as the names of the scene's invariants (``p_phi``);
    None where they go by index (the chains, the planets, the quaternion). ``units``: of t, q,
    p, q̇ and E (:attr:`varmech.Model.units`); None: :data:`DIMENSIONLESS`. ``contacts``: the
    contact surfaces from the scene's parameters (the core's scenes use the model layer only, so
    they are attached here, and watched natively all the same). ``closure``, ``symbolic``:
    whether the twin of the scene's name exists. ``tour``: the tour's showcase run, (methods,
    horizon) with None for the scene's t_end; without it the tour runs the kind's default and
    accurate methods."""

    coordinates: tuple[str, ...] | None = None
    units: Mapping[str, str] | None = None
    contacts: Contacts | None = None
    closure: bool = False
    symbolic: bool = False
    tour: tuple[tuple[str, ...], float | None] | None = None


def _floor(p: Mapping[str, float]) -> tuple[Contact, ...]:
    return (Contact.wall(0, restitution=p["restitution"], name="floor"),)


def _table(p: Mapping[str, float]) -> tuple[Contact, ...]:
    return (Contact.ellipsoid((p["A"], p["B"]), name="wall"),)


_XY = ("x", "y")
_BALL = ("x", "y", "phi", "theta", "psi")

#: The declarations by scene name, in the catalogue's order.
DECLARED: dict[str, Declared] = {
    "harmonic_oscillator": Declared(("x",), closure=True, tour=(("verlet", "rk4", "symplectic_euler"), 1000.0)),
    "pendulum": Declared(("theta",), closure=True, tour=(("verlet", "yoshida4", "rk4"), 2000.0)),
    "kepler": Declared(_XY, closure=True, symbolic=True, tour=(("verlet", "kahan_li8", "rk4"), None)),
    "henon_heiles": Declared(_XY, closure=True, tour=(("verlet", "kahan_li6", "rk4"), 5000.0)),
    "fermi_pasta_ulam": Declared(closure=True, tour=(("verlet", "mclachlan4", "rk4"), 200.0)),
    # Its closure twin is examples.nbody of the scene's G and masses.
    "outer_solar_system": Declared(units=_SOLAR, tour=(("verlet", "kahan_li8", "rk4"), None)),
    "double_pendulum": Declared(("theta1", "theta2"), closure=True, symbolic=True, tour=(("midpoint", "trapezoid"), 100.0)),
    "spherical_pendulum": Declared(("theta", "phi"), closure=True, symbolic=True, tour=(("midpoint", "trapezoid"), 1000.0)),
    "heavy_top": Declared(("theta", "phi", "psi"), closure=True, symbolic=True, tour=(("midpoint", "galerkin4"), None)),
    "kepler_polar": Declared(("r", "theta"), closure=True, symbolic=True, tour=(("midpoint", "galerkin4"), None)),
    "charged_particle": Declared(_XY, closure=True, symbolic=True, tour=(("midpoint", "galerkin4"), 1000.0)),
    "charged_particle_nonuniform": Declared(_XY, closure=True, symbolic=True, tour=(("midpoint", "trapezoid"), 1000.0)),
    "damped_driven_pendulum": Declared(("phi",), closure=True, symbolic=True),
    "cartesian_pendulum": Declared(_XY, closure=True, symbolic=True, tour=(("rattle", "shake"), 1000.0)),
    "cartesian_spherical_pendulum": Declared(("x", "y", "z")),
    "planar_chain": Declared(tour=(("rattle", "rattle4"), 100.0)),
    "rigid_body": Declared(closure=True, tour=(("trapezoid", "midpoint"), 100.0)),
    # A hundred bounces and more, where the variational impacts' O(h²) energy jumps stay bounded.
    "bouncing_ball": Declared(("y",), contacts=_floor, closure=True, tour=(("verlet", "kahan_li6"), 1000.0)),
    "elliptic_billiard": Declared(_XY, contacts=_table, closure=True),
    "rolling_disk": Declared(("x", "y", "theta", "phi"), closure=True),
    "chaplygin_sleigh": Declared(("x", "y", "theta"), closure=True),
    "rolling_sphere": Declared(_BALL, closure=True),
    "ball_on_turntable": Declared(_BALL, closure=True),
}


def declared(name: str) -> Declared:
    """The declaration of scene ``name`` (an empty one for a name the table lacks)."""
    return DECLARED.get(name, Declared())
