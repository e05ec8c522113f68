"""Fuzzing the public API with hypothesis (issue 13): every outcome is a valid run (status 0,
finite arrays) or one of the documented exceptions, whose message names the argument or the
closure at fault. Each case runs in-process with a hard step limit; the whole file is bounded
by ``max_examples`` and ``deadline``.

The features of issue 32 (contacts, impulses, events, t_eval, files, checkpoints, ensembles,
symbolic models) are fuzzed with the same outcome classes, a few examples each by default;
``VARMECH_FUZZ_EXAMPLES=n`` runs n examples of each (the long version)."""

import datetime
import math
import os

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import varmech  # noqa: E402
from varmech import scenes  # noqa: E402

FUZZ = settings(max_examples=150, deadline=2000, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
#: The newer features' fuzz: a few examples each unless VARMECH_FUZZ_EXAMPLES asks for more.
FEATURES = settings(
    FUZZ,
    max_examples=int(os.environ.get("VARMECH_FUZZ_EXAMPLES", "20")),
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)

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
    """Calls ``call``; a result must be a finite trajectory with status 0 (1: stopped by a
    terminal event) (or finite arrays), an error ValueError/TypeError naming one of ``names``,
    or a DivergenceError/ConvergenceError/ContactError."""
    try:
        result = call()
    except (ValueError, TypeError) as err:
        assert any(name in str(err) for name in names), f"{type(err).__name__} names none of {names}: {err}"
        return None
    except (varmech.DivergenceError, varmech.ConvergenceError, varmech.ContactError):
        return None
    if isinstance(result, varmech.Trajectory):
        assert result.status in (0, 1), result.message
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


# The features of issue 32.

methods_and_wrong = st.one_of(st.sampled_from(["verlet", "midpoint", "yoshida4", "rk4"]), wrong_types, st.integers(-2, 2))


@FEATURES
@given(
    dt=st.one_of(st.floats(1e-3, 0.1), floats),
    steps=st.one_of(st.integers(0, MAX_STEPS), steps_like),
    restitution=st.one_of(st.floats(0.0, 1.0), floats, wrong_types),
    law=st.sampled_from(["variational", "reflect", "bounce", 1, None]),
    method=methods_and_wrong,
)
def test_contacts(dt, steps, restitution, law, method):
    ball = scenes.bouncing_ball()

    def call():
        floor = varmech.Contact.wall(0, restitution=restitution, law=law)
        return varmech.integrate(ball, dt=dt, steps=steps, method=method, contacts=[floor])

    valid_or_documented(call, ["dt", "steps", "restitution", "law", "method", "contacts"])


@FEATURES
@given(
    generalized=st.one_of(st.lists(floats, min_size=0, max_size=2), wrong_types),
    t=st.one_of(st.floats(0.0, 2.0), floats, wrong_types),
    steps=st.integers(0, 40),
)
def test_impulses(generalized, t, steps):
    oscillator = scenes.harmonic_oscillator()

    def call():
        blow = varmech.Impulse(generalized=generalized, t=t)
        return varmech.integrate(oscillator, dt=0.05, steps=steps, impulses=[blow])

    valid_or_documented(call, ["impulses", "generalized", "t"])


@FEATURES
@given(
    k=st.one_of(st.integers(-2, 3), st.integers(2**63, 2**80), wrong_types, st.just(1.5)),
    value=st.one_of(st.floats(-1.0, 1.0), floats, wrong_types),
    direction=st.one_of(st.integers(-2, 2), floats, wrong_types),
    terminal=st.one_of(st.booleans(), st.integers(-2, 3), wrong_types),
)
def test_events(k, value, direction, terminal):
    pendulum = scenes.pendulum()

    def call():
        event = varmech.events.crossing(k, value, direction=direction, terminal=terminal)
        return varmech.integrate(pendulum, dt=0.05, steps=MAX_STEPS, events=[event])

    valid_or_documented(call, ["k", "value", "direction", "terminal", "events"])


@FEATURES
@given(t_eval=st.one_of(st.lists(st.one_of(st.floats(0.0, 5.0), floats), min_size=0, max_size=5), wrong_types))
def test_t_eval(t_eval):
    kepler = scenes.kepler()
    valid_or_documented(lambda: varmech.integrate(kepler, dt=0.05, steps=100, t_eval=t_eval), ["t_eval"])


@FEATURES
@given(
    checkpoint_every=st.one_of(
        st.integers(1, 50), st.integers(max_value=0), st.integers(2**63, 2**80), floats, wrong_types,
        st.sampled_from([datetime.timedelta(seconds=1), datetime.timedelta(seconds=-1), datetime.timedelta(0)]),
    ),
    save_every=st.one_of(st.integers(1, 10), steps_like),
    more=st.one_of(st.integers(0, 50), steps_like, wrong_types),
)
def test_files_and_resume(tmp_path_factory, checkpoint_every, save_every, more):
    pytest.importorskip("h5py")
    path = tmp_path_factory.mktemp("fuzz") / "run.h5"
    kepler = scenes.kepler()
    names = ["checkpoint_every", "save_every", "output", "steps"]
    run = valid_or_documented(
        lambda: varmech.integrate(kepler, dt=0.05, steps=60, save_every=save_every, output=path, checkpoint_every=checkpoint_every),
        names,
    )
    if run is not None:
        valid_or_documented(lambda: varmech.load(path), ["path"])
        valid_or_documented(lambda: varmech.resume(path, steps=more), ["steps", "path"])


@FEATURES
@given(
    cut=st.integers(0, 400),
    flips=st.lists(st.tuples(st.integers(0, 400), st.integers(1, 255)), max_size=3),
    wrong=st.one_of(st.none(), wrong_types),
)
def test_checkpoints(cut, flips, wrong):
    kepler = scenes.kepler()
    stepper = varmech.Stepper(kepler, dt=0.01, method="kahan_li8")
    stepper.advance(10)
    data = bytearray(stepper.checkpoint())
    for at, bits in flips:
        data[at % len(data)] ^= bits
    given = wrong if wrong is not None else bytes(data[: max(cut, len(data) - cut)])

    def call():
        again = varmech.Stepper.from_checkpoint(kepler, given)
        again.advance(5)
        assert np.all(np.isfinite(again.q)) and np.all(np.isfinite(again.p))

    valid_or_documented(call, ["checkpoint"])


@FEATURES
@given(
    q0=st.one_of(st.lists(st.lists(floats, min_size=2, max_size=2), min_size=0, max_size=3), wrong_types),
    workers=st.one_of(st.none(), st.integers(-1, 1), st.integers(2**63, 2**80), wrong_types),
    chunk_size=st.one_of(st.none(), st.integers(-1, 3), wrong_types),
    method=methods_and_wrong,
)
def test_ensembles(q0, workers, chunk_size, method):
    kepler = scenes.kepler()

    def call():
        runs = varmech.ensemble(
            kepler, q0, np.zeros((len(q0), 2)) if isinstance(q0, list) else q0, dt=0.05, steps=20, method=method,
            workers=workers, chunk_size=chunk_size, progress=False,
        )
        # A member that fails is kept with its error, of the classes integrate raises.
        for traj, error in zip(runs, runs.errors):
            assert (traj.status == 0 and error is None) or isinstance(error, (varmech.DivergenceError, varmech.ConvergenceError))
            assert np.all(np.isfinite(traj.q))

    valid_or_documented(call, ["q0", "p0", "workers", "chunk_size", "method"])


@pytest.fixture(scope="module")
def symbolic_pendulum():
    sp = pytest.importorskip("sympy")
    theta, omega, g = sp.symbols("theta omega g")
    return varmech.symbolic.lagrangian(omega**2 / 2 + g * sp.cos(theta), [theta], [omega], parameters={g: 1.0}, jit=False)


@FEATURES
@given(
    g=st.one_of(st.floats(0.0, 10.0), floats, wrong_types),
    key=st.sampled_from(["g", "h", 1]),
    q0=st.one_of(st.lists(floats, min_size=1, max_size=1), wrong_types),
)
def test_symbolic_parameters(symbolic_pendulum, g, key, q0):
    valid_or_documented(
        lambda: varmech.integrate(symbolic_pendulum, q0, [0.0], dt=0.05, steps=20, parameters={key: g}),
        ["parameters", "g", "h", "q0"],
    )
