"""Newton's method stops where its equations' evaluation allows, and says why when it fails
(issue 64).

A model of closures without derivatives gives the step's equations through central
differences of L, whose rounding, ε|L|/h with h = ε^{1/3}, makes F an irregular staircase of
steps near 1e-10: below it no correction can be resolved, and the iteration stalls there. The
stall is convergence when F is within the noise its evaluation carries (the differences'
rounding and the rounding of F's terms); a stall far above it, a cycle, a slow linear
convergence or a growth is a failure whose advice comes from that course.
"""

import warnings

import numpy as np
import pytest

import property_models as pm
import varmech

G = 9.81


def _pendulum(derivatives: bool) -> varmech.Model:
    """L = ½q̇² + g cos q, from closures; with ∂L/∂q and ∂L/∂q̇, or without (differences)."""
    if not derivatives:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", varmech.DerivativeWarning)
            return varmech.Lagrangian(1, lambda q, v, t: 0.5 * v[0] ** 2 + G * np.cos(q[0]))
    return varmech.Lagrangian(
        1,
        lambda q, v, t: 0.5 * v[0] ** 2 + G * np.cos(q[0]),
        dl_dq=lambda q, v, t: np.array([-G * np.sin(q[0])]),
        dl_dv=lambda q, v, t: v.copy(),
    )


@pytest.mark.parametrize("dt", [0.05, 0.01, 0.002])
@pytest.mark.parametrize("method", ["midpoint", "trapezoid", "galerkin4"])
@pytest.mark.parametrize("q0", [0.1, 2.0])
def test_a_closure_pendulum_without_derivatives_runs_as_its_twin_with_them(q0, method, dt):
    # The table: 11 of these 18 runs failed at the fixed tolerance 1e-14, some at step 1.
    runs = [varmech.integrate(_pendulum(d), [q0], v0=[0.0], dt=dt, t_end=50.0, method=method) for d in (False, True)]
    assert all(r.status == 0 and r.t[-1] == pytest.approx(50.0) for r in runs)
    # The differences' truncation (ε^{2/3} of L) and each step's stall at their rounding move
    # the run by at most 3.1e-7 over these 1 000 – 25 000 steps (q0 = 2, midpoint, dt = 0.002):
    # far below the method's own error, which is 1e-5 or more at every step here.
    np.testing.assert_allclose(runs[0].q, runs[1].q, rtol=0, atol=1e-6)
    assert varmech.check_conservation(runs[0]).energy.verdict == "bounded"


def _diagnosed(model, q0, **options) -> str:
    with pytest.raises(varmech.ConvergenceError) as info:
        varmech.integrate(model, [q0], v0=[0.0], method="midpoint", **options)
    return str(info.value)


def test_a_step_without_a_solution_is_a_model_that_is_not_smooth_and_no_smaller_step_helps(kink):
    # F jumps over 0 at q₁ = q₀ whatever the step.
    for dt in (0.1, 0.001):
        assert "not smooth here" in _diagnosed(kink, 0.0, dt=dt, steps=3)


def _wrong_mass(mass: float) -> varmech.Model:
    """The pendulum whose Hessians give ∂²L/∂q̇² as ``mass`` instead of 1."""
    return varmech.Lagrangian(
        1,
        lambda q, v, t: 0.5 * v[0] ** 2 + G * np.cos(q[0]),
        dl_dq=lambda q, v, t: np.array([-G * np.sin(q[0])]),
        dl_dv=lambda q, v, t: v.copy(),
        hessians=lambda q, v, t: (np.array([[-G * np.cos(q[0])]]), np.zeros((1, 1)), np.full((1, 1), mass)),
    )


def test_wrong_second_derivatives_are_named_and_a_smaller_step_is_not_advised():
    # ∂²L/∂q̇² given as 0.6 instead of 1: Newton converges linearly at |1 − 1/0.6| = 2/3.
    message = _diagnosed(_wrong_mass(0.6), 1.0, dt=0.1, steps=5, newton_max_iterations=20)
    assert "second derivatives (hessians) are not those of its first" in message
    assert "a smaller step does not help" in message


def test_second_derivatives_that_make_newton_grow_are_named_not_the_step():
    # ∂²L/∂q̇² given as 0.4 instead of 1: the corrections grow by |1 − 1/0.4| = 1.5 from any
    # start, so that the course alone reads as a predictor outside Newton's region. The
    # Jacobian disagrees with differences of F: the Hessians are named, at every step size,
    # where "a smaller step" was advised and failed alike (found by tests/python/test_properties.py).
    for dt in (0.1, 0.001):
        message = _diagnosed(_wrong_mass(0.4), 1.0, dt=dt, steps=5)
        assert "second derivatives (hessians) are not those of its first" in message
        assert "a smaller step does not help" in message and "brings it closer" not in message


def test_a_cap_reached_while_converging_advises_more_iterations_which_then_run():
    message = _diagnosed(_pendulum(True), 1.0, dt=0.1, steps=5, newton_max_iterations=1)
    assert "allow more iterations (newton_max_iterations)" in message
    varmech.integrate(_pendulum(True), [1.0], v0=[0.0], dt=0.1, steps=5, method="midpoint", newton_max_iterations=10)


def test_a_predictor_far_from_the_solution_advises_a_smaller_step_which_then_runs():
    # Kepler e = 0.9 from its pericentre: the first step's predictor (rest) is far from the
    # step's solution at dt = 0.05, and Newton wanders; at dt/4 it converges.
    kepler = varmech.scenes.kepler(0.9)
    with pytest.raises(varmech.ConvergenceError, match="a smaller step \\(dt\\) brings it closer"):
        varmech.integrate(kepler, dt=0.05, steps=200, method="midpoint", max_energy_error=None)
    varmech.integrate(kepler, dt=0.0125, steps=800, method="midpoint", max_energy_error=None)


# Two cases of tests/python/test_properties.py (issue 64) whose failures read as the model's.
# (a) A SymPy chain with exact Hessians: Newton wanders from the predictor of step 58 and
# grows to ‖F‖ = 2e7, where differences of F with a step relative to q ≈ 1e4 span its
# cos q terms and disagree with the exact J by 1 %: it was told its Hessians were wrong.
BLOW_UP = pm.Spec(
    family="chain", api="symbolic", n=2, derivatives="exact", mass="configuration", method="trapezoid",
    coefficients={
        "m": [2.5353717821052655, 1.6266289609897215], "k": [0.61, 5.0], "beta": [0.0, 0.0],
        "g": [0.4396831119394929, 2.9750422578361747e-199], "kappa": [0.0], "alpha": [-0.0],
        "gamma": [0.8965131768748473], "eps": [6.103515625e-05, 0.22034614814786832],
        "u": [0.2122195489486255, 0.656074964230164], "damping": [0.17434880985175175, 0.4336023464256219],
        "drive": [1.3852141799618047, 2.5237542098072145],
    },
    q0=[-0.45328713876291726, -0.05040135693682657], v0=[-0.46443684615749364, 0.5798956509667093],
    h_fraction=0.823860208178289, steps=60,
)  # fmt: skip
# (b) A particle on a circle, Jacobian by differences: the first correction from the predictor
# of step 7 is followed by one 4 750 times larger (no contraction at the start), and the
# iteration settles into a wander at ‖F‖ ≈ 0.2, which read as a kink.
WANDER = pm.Spec(
    family="sphere", api="mechanical", n=2, derivatives="none", mass="configuration", method="trapezoid",
    coefficients={
        "r": [0.8258045511943796], "m": [1.3156996533966765], "linked": [1.0], "g": [9.588026076562837],
        "k": [0.8893557735572968], "kappa": [0.5000281971151291],
    },
    q0=[-0.13965046507369716, 5.996381133103278e-155], v0=[0.502777654301982, 0.7146438635155903],
    h_fraction=0.5118059582301526, steps=69,
)  # fmt: skip


@pytest.mark.parametrize("spec", [BLOW_UP, WANDER], ids=["blow_up", "wander"])
def test_a_predictor_outside_newtons_region_is_told_so_and_a_quarter_step_runs(spec):
    if spec.api == "symbolic":
        pytest.importorskip("sympy")
    case = pm.build(spec)
    with pytest.raises(varmech.ConvergenceError) as info:
        case.run()
    message = str(info.value)
    assert "a smaller step (dt) brings it closer" in message and "does not help" not in message
    quarter = case.run(case.dt / 4)
    assert quarter.status == 0 and quarter.t[-1] == pytest.approx(case.dt * spec.steps)
    assert varmech.check_conservation(quarter).energy.verdict == "bounded"


def test_a_routhian_of_closures_without_derivatives_runs_through_its_nested_solves():
    # The Routhian's derivatives solve ∂L/∂ċ = μ at every evaluation: the step's equations
    # carry that solve's noise as well as the differences'.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", varmech.DerivativeWarning)
        spherical = varmech.Lagrangian(
            2, lambda q, v, t: 0.5 * (v[0] ** 2 + np.sin(q[0]) ** 2 * v[1] ** 2) + G * np.cos(q[0]), symmetries=[varmech.Cyclic(1)]
        )
        reduced = varmech.routh(spherical, cyclic=[1], momenta=[1.5])
    for method in ("midpoint", "trapezoid", "galerkin4"):
        traj = varmech.integrate(reduced, [1.0], v0=[0.0], dt=0.01, t_end=20.0, method=method)
        assert varmech.check_conservation(traj).energy.verdict == "bounded"


def test_a_ball_on_a_turntable_near_gimbal_lock_is_told_apart_from_one_a_smaller_step_saves():
    # The ball's attitude is Euler angles: where θ comes near 0 (sin θ ≈ 0.02) ∂²L/∂q̇² is nearly
    # singular, and no step that keeps is safe for long; where the run fails farther from it
    # (sin θ ≈ 0.16), a quarter of the step runs.
    near = varmech.scenes.ball_on_turntable(omega=1.0, x0=1.0, vx0=0.5, spin=0.0)
    with pytest.raises(varmech.ConvergenceError, match="nearly singular here") as info:
        varmech.integrate(near, dt=near.dt, t_end=near.t_end)
    assert np.min(np.abs(np.sin(info.value.partial.q[:, 3]))) < 0.05
    far = varmech.scenes.ball_on_turntable(omega=0.5, x0=1.0, vx0=0.5, spin=0.0)
    with pytest.raises(varmech.ConvergenceError, match="a smaller step \\(dt\\) brings it closer"):
        varmech.integrate(far, dt=far.dt, t_end=far.t_end)
    varmech.integrate(far, dt=far.dt / 4, t_end=far.t_end)


def test_a_solve_inside_the_model_that_fails_is_a_typed_error_with_its_own_advice():
    # L = −cos q̇ is not convex in q̇: ∂L/∂q̇ = sin q̇ reaches no p beyond 1.
    model = varmech.Lagrangian(
        1, lambda q, v, t: -np.cos(v[0]) - 0.5 * q[0] ** 2, dl_dq=lambda q, v, t: -q.copy(), dl_dv=lambda q, v, t: np.sin(v)
    )
    with pytest.raises(ValueError, match="^q0, p0: the inverse Legendre transform .* has no solution near the last velocity"):
        varmech.integrate(model, [1.0], [2.0], dt=0.01, steps=10, method="midpoint")
    # From p = 0.5 the motion drives q̇ to π/2, where ∂²L/∂q̇² vanishes: the inverse Legendre
    # transform inside a step fails, typed, at the step it failed in.
    with pytest.raises(varmech.ConvergenceError, match="^the inverse Legendre transform") as info:
        varmech.integrate(model, [1.0], [0.5], dt=0.01, steps=2000, method="midpoint")
    assert info.value.step > 1 and len(info.value.partial) >= info.value.step


def test_galerkin6_sums_the_differences_rounding_as_its_slots_do():
    # Found by `make campaign`: a chain of three coupled pendula under Rayleigh damping, of
    # closures without derivatives, stalled under galerkin6 at step 99 at ‖F‖ = 2.4e-12, 5.7
    # times the differences' rounding, which its slots sum with weights adding up to 3; its
    # twin with exact derivatives ran. Now it runs as the twin does.
    spec = pm.Spec(
        family="chain", api="lagrangian", n=3, derivatives="none", forcing="rayleigh", method="galerkin6",
        coefficients={
            "m": [1.1, 2.1197209694967185, 1.6936793803619825], "k": [1.6729242680429748, 4.502063941259683, 0.21175453769315866],
            "beta": [0.0, 0.0, 0.0], "g": [1.3943427373721253, 3.5317563429123116, 1.4362460124667977],
            "kappa": [3.861680695888383, 1.3737375293454492], "alpha": [-9.329569425197823e-71, -1.5568902873954484],
            "gamma": [0.6413744909602518, 0.7745460337448022], "eps": [0.6182735329662071, 1.1754943508222875e-38, 0.06559558092491506],
            "u": [-0.004223887963336392, 0.403608123210218, 0.38625516808008764],
            "damping": [0.28139051954528144, 0.4697688355728725, 0.08257495233851476], "drive": [1.224560633226243, 1.5],
        },
        q0=[-1.50609013938987e-222, 0.23220439526642656, 1.175494351e-38], v0=[-0.17453848485890466, -1.5133675336700831, 0.4],
        h_fraction=0.6095597349151984, steps=113,
    )  # fmt: skip
    case = pm.build(spec)
    runs = [case.run(model=m) for m in (case.model, case.twin)]
    assert all(r.status == 0 and r.steps == 113 for r in runs)
    np.testing.assert_allclose(runs[0].q, runs[1].q, rtol=0, atol=1e-6)
