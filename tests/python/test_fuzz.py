"""Fuzzing the public API with hypothesis (issue 13): every outcome is a valid run (status 0,
finite arrays) or one of the documented exceptions, whose message names the argument or the
closure at fault. Each case runs in-process with a hard step limit; the whole file is bounded
by ``max_examples`` and ``deadline``."""

import math

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import varmech  # noqa: E402
from varmech import scenes  # noqa: E402

FUZZ = settings(max_examples=150, deadline=2000, suppress_health_check=[HealthCheck.too_slow], derandomize=True)

#: The runs' hard step limit: the valid counts stay below it, the invalid ones go far beyond.
MAX_STEPS = 200

UNCONSTRAINED = [m.name for m in varmech.methods() if not m.constrained and not m.nonholonomic and not m.nbody]

floats = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.1, 1e-300, 1e308, -1e308, math.nan, math.inf]),
)
steps_like = st.one_of(st.integers(0, MAX_STEPS), st.integers(max_value=-1), st.integers(min_value=2**63, max_value=2**80))
wrong_types = st.sampled_from([None, "x", b"ab", 1j, [1.0, "a"], object()])


def valid_or_documented(call, names):
    """Calls ``call``; a result must be a finite trajectory with status 0 (or finite arrays), an
    error ValueError/TypeError naming one of ``names``, or a DivergenceError/ConvergenceError."""
    try:
        result = call()
    except (ValueError, TypeError) as err:
        assert any(name in str(err) for name in names), f"{type(err).__name__} names none of {names}: {err}"
        return None
    except (varmech.DivergenceError, varmech.ConvergenceError):
        return None
    if isinstance(result, varmech.Trajectory):
        assert result.status == 0
        for a in (result.t, result.q, result.p):
            assert np.all(np.isfinite(a))
    elif isinstance(result, tuple):
        for a in result:
            assert np.all(np.isfinite(a))
    return result


@FUZZ
@given(
    scene=st.sampled_from(["harmonic_oscillator", "pendulum", "kepler", "henon_heiles"]),
    method=st.sampled_from(UNCONSTRAINED),
    dt=st.one_of(st.floats(1e-4, 1.0), floats),
    steps=steps_like,
    save_every=st.one_of(st.integers(1, 50), steps_like, wrong_types),
    newton_max_iterations=st.one_of(st.integers(1, 100), steps_like),
)
def test_integrate_native_models(scene, method, dt, steps, save_every, newton_max_iterations):
    s = scenes.get(scene)
    valid_or_documented(
        lambda: varmech.integrate(
            s.model, s.q0, s.p0, dt=dt, steps=steps, method=method, save_every=save_every,
            newton_max_iterations=newton_max_iterations,
        ),
        ["dt", "steps", "save_every", "newton_max_iterations", "method"],
    )


def _returning(kind):
    return {
        "float64": lambda q: 2.0 * q,
        "float32": lambda q: (2.0 * q).astype(np.float32),
        "int": lambda q: np.zeros(len(q), dtype=np.int64),
        "list": lambda q: [float(x) for x in q],
        "complex": lambda q: q.astype(complex),
        "bool": lambda q: q > 0,
        "bytes": lambda q: b"ab",
        "object": lambda q: np.array(list(q), dtype=object),
        "masked": lambda q: np.ma.masked_array(q),
        "nan": lambda q: np.full(len(q), np.nan),
        "short": lambda q: q[:1],
        "none": lambda q: None,
    }[kind]


@FUZZ
@given(
    kind=st.sampled_from(["float64", "float32", "int", "list", "complex", "bool", "bytes", "object", "masked", "nan", "short", "none"]),
    method=st.sampled_from(["verlet", "midpoint", "rk4"]),
    q0=st.lists(st.floats(-2.0, 2.0), min_size=2, max_size=2),
    steps=st.integers(1, 20),
)
def test_integrate_closure_models(kind, method, q0, steps):
    model = varmech.MechanicalSystem(2, lambda q: float(q @ q), _returning(kind))
    valid_or_documented(
        lambda: varmech.integrate(model, q0, [0.0, 0.0], dt=0.05, steps=steps, method=method), ["gradient(q)"]
    )


@FUZZ
@given(
    q0=st.one_of(st.lists(floats, min_size=0, max_size=3), wrong_types),
    p0=st.one_of(st.lists(floats, min_size=0, max_size=3), wrong_types),
)
def test_integrate_shapes_and_values_of_the_state(q0, p0):
    s = scenes.kepler()
    valid_or_documented(lambda: varmech.integrate(s.model, q0, p0, dt=0.1, steps=5, method="verlet"), ["q0", "p0"])


@FUZZ
@given(
    scale=st.sampled_from([1.0, 1e3, 1e150, 1e300, 1e308]),
    q_noise=st.lists(st.floats(-0.1, 0.1), min_size=16, max_size=16),
    p=st.lists(st.one_of(st.floats(-1e308, 1e308), floats), min_size=16, max_size=16),
)
def test_project(scale, q_noise, p):
    chain = scenes.planar_chain()
    q0 = np.asarray(chain.q0) + np.asarray(q_noise)
    valid_or_documented(lambda: varmech.project(chain.model, q0, np.asarray(p) * scale), ["q0", "p0"])


@FUZZ
@given(cyclic=st.one_of(st.lists(st.integers(-3, 4), min_size=0, max_size=3), wrong_types), mu=floats)
def test_routh(cyclic, mu):
    model = varmech.Lagrangian(
        3, lambda q, v, t: 0.5 * float(v @ v) + math.cos(q[0] - q[1]), dl_dq=lambda q, v, t: np.array(
            [-math.sin(q[0] - q[1]), math.sin(q[0] - q[1]), 0.0]), dl_dv=lambda q, v, t: np.asarray(v, dtype=float),
    )
    valid_or_documented(lambda: varmech.routh(model, cyclic, [mu] * (len(cyclic) if isinstance(cyclic, list) else 1)),
                        ["cyclic", "momenta"])


@FUZZ
@given(
    case=st.one_of(
        st.tuples(st.just("kepler"), st.sampled_from(["e"]), floats),
        st.tuples(st.just("harmonic_oscillator"), st.sampled_from(["omega"]), floats.filter(lambda x: x != 0.0)),
        st.tuples(st.just("planar_chain"), st.sampled_from(["links"]), st.integers(0, 40)),
    )
)
def test_scenes_with_parameters(case):
    _scene_and_run(*case)


@FUZZ
@given(
    case=st.one_of(
        st.tuples(st.just("harmonic_oscillator"), st.just("omega"), st.just(0.0)),
        st.tuples(st.just("planar_chain"), st.just("links"), st.one_of(st.integers(max_value=-1), st.integers(2**64, 2**80))),
    )
)
def test_scenes_with_parameters_out_of_range(case):
    _scene_and_run(*case)


def _scene_and_run(name, argument, value):
    scene = valid_or_documented(lambda: getattr(scenes, name)(**{argument: value}), [argument])
    if scene is not None:
        valid_or_documented(lambda: varmech.integrate(scene.model, scene.q0, scene.p0, dt=scene.dt, steps=5), ["dt"])


@FUZZ
@given(
    n=st.one_of(st.integers(2, 30), st.integers(10**5, 10**6)),
)
def test_nbody_sizes(n):
    valid_or_documented(lambda: scenes.nbody(np.ones(n), np.zeros((n, 3)), np.zeros((n, 3))), ["masses", "positions"])


@FUZZ
@given(
    q=st.lists(st.floats(-1e308, 1e308), min_size=2, max_size=2),
    p=st.lists(st.floats(-1e308, 1e308), min_size=2, max_size=2),
    dt=st.one_of(st.floats(1e-3, 1.0), floats),
    method=st.sampled_from(["verlet", "rk4", "midpoint"]),
)
def test_symplecticity_defect(q, p, dt, method):
    s = scenes.kepler()

    def call():
        defect = varmech.symplecticity_defect(s.model, method, q, p, dt)
        assert math.isfinite(defect)
        return defect

    valid_or_documented(call, ["q, p, dt", "q", "p", "dt"])
