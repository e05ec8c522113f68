"""
Kepler: Verlet and Kahan–Li 8 against RK4
=========================================

The relative energy error of an eccentric Kepler orbit (e = 0.6) over 100 periods, at 200 steps a
period. The symplectic methods' errors stay in a band; RK4's drifts. SciPy's DOP853, when SciPy is
installed, drifts too, at a smaller rate.
"""

import matplotlib.pyplot as plt
import numpy as np

import varmech

kepler = varmech.scenes.kepler()
dt, periods = 2 * np.pi / 200, 100
fig, ax = plt.subplots(figsize=(7, 4))
for method in ["verlet", "kahan_li8", "rk4"]:
    traj = varmech.integrate(kepler, dt=dt, steps=200 * periods, method=method, save_every=20)
    error = np.abs(traj.energy() / traj.energy()[0] - 1)
    verdict = varmech.check_conservation(traj).energy.verdict
    ax.loglog(traj.t[1:] / (2 * np.pi), error[1:] + 1e-17, label=f"{method}: {verdict}")

try:
    from scipy.integrate import solve_ivp

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        q, p = y[:2], y[2:]
        return np.concatenate([p, -q / np.linalg.norm(q) ** 3])

    sol = solve_ivp(
        rhs,
        (0, periods * 2 * np.pi),
        np.concatenate([kepler.q0, kepler.p0]),
        method="DOP853",
        rtol=1e-10,
        atol=1e-12,
        dense_output=True,
    )
    t = np.linspace(0.1, periods, 1000) * 2 * np.pi
    y = sol.sol(t)
    energy = 0.5 * (y[2] ** 2 + y[3] ** 2) - 1 / np.hypot(y[0], y[1])
    ax.loglog(t / (2 * np.pi), np.abs(energy / -0.5 - 1) + 1e-17, label="DOP853 (SciPy), rtol 1e-10")
except ImportError:
    ax.text(0.02, 0.02, "SciPy not installed: the DOP853 baseline is skipped", transform=ax.transAxes)

ax.set_xlabel("t (Kepler periods)")
ax.set_ylabel("|ΔH / H₀|")
ax.set_title("Kepler, e = 0.6: relative energy error, 200 steps a period")
ax.set_ylim(1e-17, 10)
ax.legend(loc="upper left", ncol=2, fontsize="small")
fig.tight_layout()
