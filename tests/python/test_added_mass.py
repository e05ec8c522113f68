"""Forces of the acceleration (issue 36): a force −A(q)q̈ stated as the source states it
(``added_mass=A``), folded into the metric for the variational step:

- the pendulum in water, (I_O + μ)θ̈ + λθ̇ + Mgl sin θ = 0: bit for bit the hand-folded model,
  and at small amplitude the exact damped oscillator's decay rate and frequency (from its modes
  and from a run);
- an added mass that depends on q: the fold's extra force taken back, so that the motion is the
  source's, q̈ = −q/(1 + a(1 + q²)), against SciPy's DOP853 at the method's order;
- a non-symmetric A, or one that depends on q̇, refused naming ``added_mass``.
"""

import math

import numpy as np
import pytest
import sympy as sp

import varmech

scipy_integrate = pytest.importorskip("scipy.integrate")

# I_O, μ, λ, Mgl: sums exact in binary, so that the fold is the hand-folded L to the bit.
INERTIA, ADDED, DAMPING, WEIGHT = 0.75, 0.25, 0.125, 4.0


def _pendulum(folded_by_hand: bool) -> varmech.Model:
    theta, w = sp.symbols("theta w")
    if folded_by_hand:
        L = (INERTIA + ADDED) * w**2 / 2 + WEIGHT * sp.cos(theta)
        return varmech.symbolic.lagrangian(L, [theta], [w], rayleigh=DAMPING * w**2 / 2)
    L = INERTIA * w**2 / 2 + WEIGHT * sp.cos(theta)
    return varmech.symbolic.lagrangian(L, [theta], [w], rayleigh=DAMPING * w**2 / 2, added_mass=ADDED)


def test_the_pendulum_in_water_is_the_hand_folded_model_bit_for_bit():
    stated, folded = _pendulum(False), _pendulum(True)
    a, b = (varmech.integrate(m, [1.0], [0.0], dt=0.01, t_end=20.0, method="galerkin4") for m in (stated, folded))
    assert np.array_equal(a.q, b.q) and np.array_equal(a.p, b.p)


def test_the_pendulum_in_water_decays_as_the_exact_damped_oscillator():
    model = _pendulum(False)
    inertia = INERTIA + ADDED
    sigma = -DAMPING / (2 * inertia)
    omega = math.sqrt(WEIGHT / inertia - sigma**2)
    # The linearization's modes (M δθ̈ + D δθ̇ + K δθ = 0) are the exact ones.
    modes = varmech.normal_modes(model, [0.0])
    assert abs(modes.frequencies[0] / omega - 1) < 1e-9 and abs(modes.growth[0] / sigma - 1) < 1e-9
    # A run at small amplitude: successive maxima a period 2π/ω apart, shrinking by e^{2πσ/ω}.
    traj = varmech.integrate(model, [1e-4], [0.0], dt=0.002, t_end=30.0, method="galerkin4")
    q = traj.q[:, 0]
    peaks = [k for k in range(1, len(q) - 1) if q[k - 1] < q[k] >= q[k + 1]]
    times = np.array([traj.t[k] for k in peaks])
    assert abs(np.mean(np.diff(times)) / (2 * math.pi / omega) - 1) < 1e-4
    ratio = q[peaks[-1]] / q[peaks[0]]
    assert abs(math.log(ratio) / (sigma * (times[-1] - times[0])) - 1) < 1e-3


def test_an_added_mass_that_depends_on_q_gives_the_sources_motion():
    # L = ½q̇² − ½q², A(q) = a(1 + q²): (1 + A(q))q̈ + q = 0.
    a = 0.5
    q, v = sp.symbols("q v")
    model = varmech.symbolic.lagrangian(v**2 / 2 - q**2 / 2, [q], [v], added_mass=[[a * (1 + q**2)]])
    assert model.forced

    def rhs(_, y):
        return [y[1], -y[0] / (1 + a * (1 + y[0] ** 2))]

    t_end = 10.0
    exact = scipy_integrate.solve_ivp(rhs, (0, t_end), [1.2, 0.0], method="DOP853", rtol=1e-13, atol=1e-13, dense_output=True)
    errors = []
    for dt in (0.02, 0.01):
        traj = varmech.integrate(model, [1.2], v0=[0.0], dt=dt, t_end=t_end, method="midpoint")
        errors.append(np.max(np.abs(traj.q[:, 0] - exact.sol(traj.t)[0])))
    assert errors[1] < 1e-3 and abs(math.log2(errors[0] / errors[1]) - 2) < 0.1, errors
    # Folding A in without taking its force back would be another motion.
    wrong = varmech.symbolic.lagrangian(v**2 / 2 - q**2 / 2 + a * (1 + q**2) * v**2 / 2, [q], [v])
    traj = varmech.integrate(wrong, [1.2], v0=[0.0], dt=0.01, t_end=t_end, method="midpoint")
    assert np.max(np.abs(traj.q[:, 0] - exact.sol(traj.t)[0])) > 100 * errors[1]


def test_an_added_mass_that_is_no_mass_is_refused_naming_it():
    x, y, vx, vy = sp.symbols("x y vx vy")
    L = (vx**2 + vy**2) / 2
    with pytest.raises(ValueError, match="^added_mass: must be symmetric.*antisymmetric part would leave q̈"):
        varmech.symbolic.lagrangian(L, [x, y], [vx, vy], added_mass=[[1, 0.5], [0, 1]])
    with pytest.raises(ValueError, match="^added_mass: must depend on the positions q alone"):
        varmech.symbolic.lagrangian(L, [x, y], [vx, vy], added_mass=[[vx, 0], [0, 1]])
    with pytest.raises(ValueError, match=r"^added_mass: must be a scalar or a 2×2 matrix"):
        varmech.symbolic.lagrangian(L, [x, y], [vx, vy], added_mass=[[1, 0, 0]])
