"""The discrete Lagrange–d'Alembert variants (``cortes_martinez``, non-reversible; ``dla4``,
the reversible step's triple jump) and the chart of a rolling disk's energy against RK4 with a
velocity projection (varmech.analysis.nonholonomic, varmech.charts.nonholonomic)."""

import doctest

import numpy as np
import pytest

import varmech
from varmech.analysis import nonholonomic
from varmech.analysis.nonholonomic import DISK_Q0, DISK_V0, nonholonomic_energy, rolling, rolling_disk
from varmech.charts import nonholonomic as chart_module


def test_the_variants_are_listed_and_take_velocity_constraints_alone():
    info = {m.name: m for m in varmech.methods()}
    assert (info["cortes_martinez"].order, info["cortes_martinez"].symmetric) == (1, False)
    assert (info["dla4"].order, info["dla4"].symmetric, info["dla4"].stages) == (4, True, 3)
    assert {m.name for m in info.values() if m.nonholonomic} == {"cortes_martinez", "dla4"}
    assert rolling_disk().kind.accurate_method == "dla4"
    free = varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2, lambda q: q, mass=[1.0])
    for method in ("cortes_martinez", "dla4"):
        with pytest.raises(ValueError, match=f"^method: {method} integrates velocity constraints A"):
            varmech.integrate(free, [1.0], [0.0], dt=0.1, steps=3, method=method)


def test_dla4_rolls_the_disk_on_its_constraint_with_constant_rates():
    # Every stage of the triple jump ends on A(q)q̇ = 0; the disk's rates are conserved.
    traj = varmech.integrate(rolling_disk(), DISK_Q0, v0=DISK_V0, dt=0.1, steps=2_000, method="dla4")
    v = traj.p / nonholonomic.DISK_MASS
    assert np.max(np.abs(v[:, 2:] - DISK_V0[2:])) < 1e-11
    residual = max(np.abs(rolling(q) @ w).max() for q, w in zip(traj.q, v))
    assert residual < 1e-12  # round-off: θ grows to 140 rad, ε|θ||q̇| ≈ 6e-14 (measured 5.7e-14)


@pytest.fixture(scope="module")
def table():
    """5000 steps of 0.1 (t = 500), the chart's --quick run."""
    return nonholonomic_energy(("midpoint", "cortes_martinez", "rk4_projection"), steps=5_000, samples=250)


def test_the_naive_projection_drifts_linearly_while_the_reversible_dla_stays_at_round_off(table):
    errors = {m: table.where(method=m) for m in table.unique("method")}
    t, naive = errors["rk4_projection"].column("t"), errors["rk4_projection"].column("energy_error")
    # RK4 with the velocity projected drifts ∝ t: its error doubles from t = 250 to 500
    # (measured 1.3e-7 at t = 500), and the verdict says so.
    half = np.argmin(np.abs(t - t[-1] / 2))
    assert 1.9 < naive[-1] / naive[half] < 2.1 and naive[-1] > 1e-7, (naive[half], naive[-1])
    assert table.meta["verdicts"]["rk4_projection"] == "secular drift"
    assert table.meta["drift_rates"]["rk4_projection"] > 0
    # The reversible DLA step keeps the energy at round-off (the angles' rounding, 5e-12
    # measured at t = 500, where θ = 350 and φ = 1000 rad): the naive drift is 10⁴ times its bound.
    bound = errors["midpoint"].column("energy_error").max()
    assert bound < 2e-11 and naive[-1] > 1e4 * bound, (bound, naive[-1])
    assert table.meta["verdicts"]["midpoint"] in ("conserved to round-off", "bounded")
    # Cortés–Martínez's step, not reversible, brakes the rolling: 98 % of E gone by t = 500.
    assert errors["cortes_martinez"].column("energy_error")[-1] > 0.9
    assert table.meta["verdicts"]["cortes_martinez"] == "failed"


def test_the_chart_says_what_it_plots(table, tmp_path):
    pytest.importorskip("matplotlib")
    path = tmp_path / "nonholonomic_energy.png"
    fig = chart_module.nonholonomic_energy_chart(table, path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    (ax,) = fig.axes
    assert ax.get_title() == "rolling disk: relative energy error over 5000 steps of dt = 0.1"
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("t (time units)", "relative energy error |E − E₀| / E₀")
    assert ax.get_xscale() == ax.get_yscale() == "log"
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert labels == [
        "midpoint (reversible DLA): bounded",
        "cortes_martinez (non-reversible DLA): failed",
        "RK4 + velocity projection: secular drift",
        "∝ t",
    ]


def test_the_command_line_writes_the_chart_and_its_data(tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    out = run_cli("chart", "nonholonomic", "--quick", "--out", tmp_path).stdout
    assert sorted(line for line in out.splitlines() if line.startswith("wrote ")) == [
        f"wrote {tmp_path / 'nonholonomic_energy.csv'}",
        f"wrote {tmp_path / 'nonholonomic_energy.png'}",
    ]
    header = next(line for line in open(tmp_path / "nonholonomic_energy.csv") if not line.startswith("#"))
    assert header.strip() == "method,t,energy_error"


def test_the_examples_run():
    result = doctest.testmod(nonholonomic, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0, result


def test_bad_sizes_are_named():
    with pytest.raises(ValueError, match="^steps:"):
        nonholonomic_energy(steps=0)
    with pytest.raises(ValueError, match="^samples:"):
        nonholonomic_energy(samples=0)
