"""Issue 13, part A: no hangs, no aborts, no silent coercion or garbage; errors that name what
was wrong, and exceptions that pickle."""

import pickle
import resource
import time

import numpy as np
import pytest

import varmech
from varmech import scenes


def test_newton_max_iterations_is_bounded():
    chain = scenes.planar_chain(3)
    for bad in (10_001, 2**63, 2**64, -1):
        with pytest.raises(ValueError, match="^newton_max_iterations:"):
            varmech.integrate(chain.model, chain.q0, chain.p0, dt=0.01, steps=1, method="rattle", newton_max_iterations=bad)


def test_the_largest_iteration_cap_on_a_step_without_a_solution_fails_quickly(kink):
    # Newton cycles about the kink until the cap.
    start = time.perf_counter()
    with pytest.raises(varmech.ConvergenceError, match="not smooth here") as info:
        varmech.integrate(kink, [0.0], v0=[0.0], dt=0.1, steps=3, method="midpoint", newton_max_iterations=10_000)
    assert info.value.iterations == 10_000
    assert time.perf_counter() - start < 5.0


def test_an_unreachable_tolerance_stops_at_the_noise_floor():
    # RATTLE's multipliers to 1e-300: the iteration stops where its corrections stall at the
    # rounding of the constraints, with the run the default tolerance gives to round-off.
    chain = scenes.planar_chain(30)
    runs = [
        varmech.integrate(chain.model, chain.q0, chain.p0, dt=0.01, steps=3, method="rattle", newton_tolerance=tolerance)
        for tolerance in (1e-14, 1e-300)
    ]
    np.testing.assert_allclose(runs[1].q, runs[0].q, rtol=0, atol=1e-13)


def test_ctrl_c_stops_one_long_newton_iteration(interrupt_after):
    # One step of RATTLE on 100 links: 10⁴ iterations of about 1 ms each, never converging.
    chain = scenes.planar_chain(100)
    timer, sent = interrupt_after(0.3)
    with pytest.raises(KeyboardInterrupt):
        varmech.integrate(
            chain.model, chain.q0, chain.p0, dt=0.01, steps=1, method="rattle",
            newton_tolerance=1e-300, newton_max_iterations=10_000,
        )
    latency = time.perf_counter() - sent["at"]
    timer.join()
    assert latency < 0.2, f"interrupt took {latency:.3f} s"


def _rss_mib():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


@pytest.mark.parametrize(
    "make, argument",
    [
        (lambda: scenes.planar_chain(100_000), "links"),
        (lambda: varmech.MechanicalSystem(
            2000, lambda q: 0.0, lambda q: np.zeros(2000), mass=lambda q: np.eye(2000),
            mass_derivative=lambda q: np.zeros((2000,) * 3)), "mass_derivative"),
        (lambda: varmech.MechanicalSystem(10**6, lambda q: 0.0, lambda q: q), "dim"),
        # 3·10⁹ saved states of Kepler: 168 GB, which Linux would reserve and then kill.
        (lambda: varmech.integrate(scenes.kepler(), dt=1e-6, steps=3 * 10**9, save_every=1), "save_every"),
    ],
)
def test_allocations_sized_by_arguments_are_refused_before_they_are_made(make, argument):
    before, start = _rss_mib(), time.perf_counter()
    with pytest.raises(ValueError, match=f"^{argument}: needs .* GiB of memory, more than is available"):
        make()
    assert time.perf_counter() - start < 2.0
    assert _rss_mib() - before < 200


def test_an_nbody_model_of_10_5_bodies_is_built_in_o_n_memory():
    # G·mᵢ and mᵢ, not a table of the 5·10⁹ pairs (40 GB, which was refused): a few MB.
    before = _rss_mib()
    scene = scenes.nbody(np.ones(10**5), np.zeros((10**5, 3)), np.zeros((10**5, 3)))
    assert scene.model.dim == 3 * 10**5
    assert _rss_mib() - before < 100


def test_a_mass_closure_with_2000_coordinates_is_built_without_the_n3_buffer():
    model = varmech.MechanicalSystem(2000, lambda q: 0.0, lambda q: np.zeros(2000), mass=lambda q: np.eye(2000))
    assert model.dim == 2000


@pytest.mark.parametrize(
    "returned, kind",
    [
        (lambda q: q.astype(complex), "complex128"),
        (lambda q: [1j, 0.0], "complex128"),
        (lambda q: b"ab", "bytes"),
        (lambda q: np.array([True, False]), "bool"),
        (lambda q: np.array([1.0, None], dtype=object), "object"),
        (lambda q: np.ma.masked_array(q, mask=[True, False]), "masked array"),
        (lambda q: np.array(["1", "2"]), "str"),
    ],
)
def test_closure_results_that_do_not_convert_exactly_are_refused(returned, kind):
    model = varmech.MechanicalSystem(2, lambda q: 0.5 * q @ q, returned)
    with pytest.raises(TypeError, match=rf"^gradient\(q\) must return .* got .*{kind}"):
        varmech.integrate(model, [0.1, 0.2], [0.0, 0.0], dt=0.1, steps=2, method="verlet")


@pytest.mark.parametrize("potential, kind", [(lambda q: 1j, "complex"), (lambda q: True, "bool"), (lambda q: np.bool_(True), "bool")])
def test_scalar_closure_results_that_do_not_convert_exactly_are_refused(potential, kind):
    model = varmech.MechanicalSystem(1, potential, lambda q: q)
    with pytest.raises(TypeError, match=rf"^potential\(q\) must return a float, got {kind}"):
        varmech.integrate(model, [0.1], [0.0], dt=0.1, steps=2, method="verlet", max_energy_error=1.0)


@pytest.mark.parametrize(
    "gradient", [lambda q: q.astype(np.float32), lambda q: [0, 0], lambda q: q.astype(np.int64), lambda q: list(q)]
)
def test_closure_results_that_convert_exactly_are_accepted(gradient):
    model = varmech.MechanicalSystem(2, lambda q: 0.5 * q @ q, gradient)
    # Truncated to integers, the gradient is not V's: the energy check would rightly stop the run.
    traj = varmech.integrate(model, [1.0, 2.0], [0.0, 0.0], dt=0.1, steps=3, method="verlet", max_energy_error=None)
    assert np.all(np.isfinite(traj.q))


def test_a_float32_mass_matrix_is_upcast():
    model = varmech.MechanicalSystem(
        1, lambda q: -np.cos(q[0]), lambda q: np.sin(q), mass=lambda q: np.array([[2.0]], dtype=np.float32),
        mass_derivative=lambda q: np.zeros((1, 1, 1), dtype=np.float32),
    )
    traj = varmech.integrate(model, [0.5], [0.0], dt=0.05, steps=20, method="midpoint")
    assert traj.success


def test_exceptions_report_module_varmech_and_pickle_with_their_data(kepler):
    for cls in (varmech.VarmechError, varmech.DivergenceError, varmech.ConvergenceError, varmech.SpuriousBranchError):
        assert cls.__module__ == "varmech"
    with pytest.raises(varmech.DivergenceError) as info:
        varmech.integrate(kepler.model, [1e-300, 0.0], [0.0, 1e300], dt=1.0, steps=5, method="verlet")
    err = info.value
    copy = pickle.loads(pickle.dumps(err))
    assert type(copy) is varmech.DivergenceError and str(copy) == str(err)
    assert (copy.step, copy.time) == (err.step, err.time)
    np.testing.assert_array_equal(copy.partial.q, err.partial.q)
    assert copy.partial.status == -1 and copy.partial.model is None


def test_routh_refuses_a_coordinate_that_is_not_cyclic():
    # Two angles coupled through their difference: neither is cyclic, their sum's conjugate is.
    model = varmech.Lagrangian(2, lambda q, v, t: 0.5 * (v[0] ** 2 + v[1] ** 2) + np.cos(q[0] - q[1]))
    with pytest.raises(ValueError, match=r"^cyclic: coordinate 1 is not cyclic: \|∂L/∂q1\| reaches [0-9.e+-]+"):
        varmech.routh(model, [1], [0.3])


def test_project_refuses_to_overflow():
    chain = scenes.planar_chain()
    with pytest.raises(ValueError, match="^p0: its projection overflows"):
        varmech.project(chain.model, chain.q0, np.full(len(chain.q0), 1e308))


def test_symplecticity_defect_that_overflows_is_an_error(kepler):
    with pytest.raises(ValueError, match="^q, p, dt: one step of verlet from this state overflows"):
        varmech.symplecticity_defect(kepler.model, "verlet", [1e300, 0.0], [0.0, 1e300], 1e300)


@pytest.mark.parametrize("argument", ["steps", "save_every", "newton_max_iterations"])
def test_huge_counts_are_value_errors_naming_the_argument(kepler, argument):
    from varmech import _core

    kwargs = dict(dt=0.1, steps=1, method="verlet") | {argument: 2**70}
    with pytest.raises(ValueError, match=f"^{argument}:"):
        _core.RunSpec(**kwargs)
