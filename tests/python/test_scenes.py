"""The scenes come from the core's catalogue: each builds from Python with its defaults, its
stated invariants are the model's energy and momenta at t = 0, parameters change the model, and
unknown names are refused by name."""

import inspect
import math

import numpy as np
import pytest

from varmech import _core, examples, scenes
from varmech._catalogue import DECLARED
from varmech.analysis._energy import energy_of

#: The catalogue names cyclic momenta by their angle; the model's generators by their index.
CYCLIC = {"p_phi": "p[1]", "p_theta": "p[1]", "p_psi": "p[2]"}


def oscillatory_energy(q, p, omega=50.0):
    """The Fermi–Pasta–Ulam adiabatic invariant I = Σⱼ ½(ẋⱼ² + ω²xⱼ²) with
    xⱼ = (q₂ⱼ − q₂ⱼ₋₁)/√2 over the stiff springs (unit masses)."""
    x = (q[1::2] - q[0::2]) / math.sqrt(2)
    y = (p[1::2] - p[0::2]) / math.sqrt(2)
    return float(np.sum(0.5 * (y * y + omega * omega * x * x)))


def computed(scene, name):
    """The invariant ``name`` computed from the scene's model at (q0, p0)."""
    q, p = scene.q0, scene.p0
    if name in ("H", "E"):
        return float(energy_of(scene.model, np.zeros(1), q[None, :], p[None, :])[0])
    if name == "I":
        return oscillatory_energy(q, p)
    if name == "J":
        # The turntable ball's Jacobi integral E − Ω(x p_y − y p_x).
        energy = float(energy_of(scene.model, np.zeros(1), q[None, :], p[None, :])[0])
        return energy - scene.parameters["omega"] * (q[0] * p[1] - q[1] * p[0])
    if name == "L1L2":
        # The elliptic billiard's product of the angular momenta about its foci (±c, 0).
        c = math.sqrt(scene.parameters["A"] ** 2 - scene.parameters["B"] ** 2)
        return ((q[0] - c) * p[1] - q[1] * p[0]) * ((q[0] + c) * p[1] - q[1] * p[0])
    generator = next(g for g in scene.model._core.symmetries if g.name == CYCLIC.get(name, name))
    return float(_core.momentum(generator, q[None, :], p[None, :])[0][0])


@pytest.mark.parametrize("name", list(scenes.CATALOGUE))
def test_every_scene_builds_with_its_defaults(name):
    entry = scenes.CATALOGUE[name]
    scene = scenes.get(name)
    assert scene.name == name and scene.model.name == name
    assert scene.description == entry.description and scene.parameters == entry.parameters
    assert scene.dt > 0 and scene.t_end > 0
    assert scene.q0.shape == scene.p0.shape == (scene.model.dim,)
    for invariant, stated in scene.invariants.items():
        assert computed(scene, invariant) == pytest.approx(stated, rel=1e-12, abs=0.0), invariant


@pytest.mark.parametrize("name", list(scenes.CATALOGUE))
def test_the_scene_functions_are_the_catalogue_with_its_defaults(name):
    function = getattr(scenes, name)
    assert function().description == scenes.CATALOGUE[name].description
    defaults = {p.name: p.default for p in inspect.signature(function).parameters.values()}
    assert defaults == scenes.CATALOGUE[name].parameters


def test_a_parameter_changes_the_model():
    scene = scenes.kepler(e=0.3)
    assert scene.parameters == {"e": 0.3} and scene.description == "Kepler orbit, eccentricity 0.3"
    assert computed(scene, "H") == pytest.approx(-0.5, rel=1e-12)
    assert abs(computed(scene, "L")) == pytest.approx(math.sqrt(1 - 0.3**2), rel=1e-12)
    assert scene.invariants == {"H": -0.5, "L": math.sqrt(1 - 0.3**2)}
    assert scene.reference is not None and scene.reference.q[0] == pytest.approx(0.7)
    chain = scenes.planar_chain(links=3)
    assert chain.model.dim == 6 and chain.model.constraints == 3 and chain.parameters == {"links": 3}


def test_an_unknown_scene_is_refused_by_name():
    with pytest.raises(ValueError, match="tippe_top") as err:
        scenes.get("tippe_top")
    assert all(name in str(err.value) for name in scenes.CATALOGUE)


def test_an_unknown_parameter_is_refused_by_name():
    with pytest.raises(ValueError, match="omega"):
        scenes.get("kepler", omega=2.0)
    with pytest.raises(ValueError, match="links"):
        scenes.planar_chain(links=2.5)
    with pytest.raises(ValueError, match="e"):
        scenes.kepler(e=1.5)
    with pytest.raises(TypeError, match="e: must be a number"):
        scenes.get("kepler", e="high")


def test_each_scene_is_declared_once_with_what_python_adds():
    """The declarations name the catalogue's scenes, in its order: a new scene is one line there.
    What each declares is what its scene and model carry, and its closure twin exists exactly
    where declared (the N-body planets aside, whose twin is examples.nbody of their masses)."""
    assert list(DECLARED) == list(scenes.CATALOGUE)
    for name, declared in DECLARED.items():
        scene = scenes.get(name)
        assert scene.model.coordinates == (declared.coordinates or tuple(f"q[{i}]" for i in range(scene.model.dim)))
        assert scene.model.units["t"] == scene.time_unit.replace("time units", "1")
        assert bool(scene.contacts) == (declared.contacts is not None), name
        if declared.closure or name == "outer_solar_system":
            assert examples.closure_of(scene).dim == scene.model.dim
        else:
            with pytest.raises(ValueError, match=name):
                examples.closure_of(scene)


def test_a_scene_without_a_closure_twin_is_refused_by_name():
    assert examples.closure_of(scenes.charged_particle_nonuniform()).name == "charged_particle (closure)"
    with pytest.raises(ValueError, match="planar_chain"):
        examples.closure_of(scenes.planar_chain())


@pytest.mark.parametrize(
    "change, argument",
    [
        ({"masses": [1.0, -1.0]}, r"masses: must be finite and positive, got masses\[1\] = -1"),
        ({"positions": [[0, 0, np.nan], [1, 0, 0]]}, "positions, velocities: must be finite"),
        ({"velocities": [[0, 0, np.inf], [0, 0, 0]]}, "positions, velocities: must be finite"),
        ({"G": 0.0}, "G: must be finite and positive"),
        ({"t_end": np.nan}, "t_end: must be finite and positive"),
        ({"dt": -1.0}, "dt: must be finite and positive"),
    ],
)
def test_nbody_refuses_bad_data_naming_the_argument(change, argument):
    # A step or horizon the scene would carry to integrate, and masses named as the caller gave
    # them (the core's check counts coordinates, not bodies).
    data = {"masses": [1.0, 1.0], "positions": [[0, 0, 0], [1, 0, 0]], "velocities": [[0, 0, 0], [0, 1, 0]]}
    with pytest.raises(ValueError, match=f"^{argument}"):
        scenes.nbody(**{**data, **change})


@pytest.mark.parametrize(
    "build, argument",
    [
        (lambda: scenes.rolling_sphere(vy0=math.nan), "vy0"),
        (lambda: scenes.rolling_sphere(spin=math.inf), "spin"),
        (lambda: scenes.ball_on_turntable(x0=math.nan), "x0"),
        (lambda: scenes.ball_on_turntable(vx0=math.inf), "vx0"),
        (lambda: scenes.elliptic_billiard(A=0.5), "A"),
        (lambda: scenes.elliptic_billiard(B=-1.0), "B"),
        (lambda: scenes.elliptic_billiard(y0=math.nan), "y0"),
        (lambda: scenes.elliptic_billiard(py0=math.inf), "py0"),
        (lambda: scenes.charged_particle(B=math.nan), "B"),
        (lambda: scenes.damped_driven_pendulum(drive=math.nan), "drive"),
    ],
)
def test_scene_parameters_are_named_as_the_constructor_names_them(build, argument):
    with pytest.raises(ValueError, match=rf"^{argument}: "):
        build()
