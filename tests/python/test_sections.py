"""Poincaré sections of Hénon–Heiles and phase portraits of the pendulum, tested on their numbers.

Hénon–Heiles: H = ½(p_x² + p_y²) + ½(x² + y²) + x²y − y³/3, section x = 0 with p_x > 0, seen in
(y, p_y). Hénon & Heiles (1964) found the motion mostly regular at E = 1/12 and widely chaotic at
E = 1/8; the section points show it, and so does the divergence of neighbouring orbits.
"""

import math

import numpy as np
import pytest

import varmech
from varmech import phase_portrait, sections

HH = varmech.scenes.henon_heiles()
E12, E8 = sections.HENON_HEILES_ENERGIES
# A regular orbit at 1/12 (a torus around the elliptic point near y = 0.26 on p_y = 0) and a
# chaotic one at 1/8.
REGULAR_1_12 = (0.1, 0.0)
CHAOTIC_1_8 = (0.3, -0.3)


def hh_energy(q, p):
    x, y = q[..., 0], q[..., 1]
    return 0.5 * (p[..., 0] ** 2 + p[..., 1] ** 2) + 0.5 * (x**2 + y**2) + x**2 * y - y**3 / 3


def radial_jump(table):
    """Largest jump of the distance to the centroid between points adjacent in angle around the
    centroid, relative to the mean distance: small for points on a smooth closed curve around
    their centroid, of order 1 for points scattered over an area."""
    y, py = table.column("y"), table.column("p_y")
    dy, dp = y - y.mean(), py - py.mean()
    r = np.hypot(dy, dp)[np.argsort(np.arctan2(dp, dy))]
    return float(np.max(np.abs(np.diff(np.r_[r, r[:1]]))) / r.mean())


@pytest.fixture(scope="module")
def section_1_8():
    return sections.poincare_section(HH, E8, orbits=6, t_end=500.0)


def test_section_points_lie_on_the_section_and_the_energy_shell(section_1_8):
    tab = section_1_8
    assert len(tab) > 400 and len(tab.unique("orbit")) == 6
    # x at the located crossing: the point is a state of the integrator (a partial step), so
    # on the section to round-off; crossings go the asked way (p_x > 0).
    assert tab.meta["max_section_residual"] <= 1e-15
    assert np.max(np.abs(tab.column("x"))) <= 1e-15
    assert np.all(tab.column("p_x") > 0)
    # The energy error of kahan_li6 at h = 0.05 is ≤ 2e-11 relative here (measured 2.0e-11),
    # at the located points as at the grid points. Checked against an independent formula.
    q = np.c_[tab.column("x"), tab.column("y")]
    p = np.c_[tab.column("p_x"), tab.column("p_y")]
    rel = (hh_energy(q, p) - E8) / E8
    np.testing.assert_allclose(rel, tab.column("energy_error"), atol=1e-14)
    assert np.max(np.abs(rel)) <= 5e-11
    # Crossing times increase along each orbit, about once per 2π.
    for o in tab.unique("orbit"):
        t = tab.where(orbit=o).column("t")
        assert np.all(np.diff(t) > 1.0)


def test_located_crossings_agree_with_a_fine_integration_of_the_flow(section_1_8):
    """From the saved state before each crossing, the exact flow (kahan_li8 with 64 substeps)
    over the same τ lands on x = 0 and on the reported point to ≤ 1e-10 (measured 1.1e-12)."""
    tab = section_1_8.where(orbit=0)
    seed = tab.meta["seeds"][0]
    y0, py0 = seed
    px0 = math.sqrt(2 * E8 - py0**2 - y0**2 + 2 * y0**3 / 3)
    dt = tab.meta["dt"]
    traj = varmech.integrate(HH, [0.0, y0], [px0, py0], dt=dt, t_end=500.0, method="kahan_li6")
    worst_x = worst_state = 0.0
    for row in tab:
        i = int(math.floor(row["t"] / dt))
        if traj.t[i] >= row["t"]:
            i -= 1
        tau = row["t"] - traj.t[i]
        assert 0 < tau <= dt * (1 + 1e-12)
        fine = varmech.integrate(HH, traj.q[i], traj.p[i], dt=tau / 64, steps=64, method="kahan_li8")
        worst_x = max(worst_x, abs(fine.q[-1, 0]))
        got = np.array([row["x"], row["y"], row["p_x"], row["p_y"]])
        worst_state = max(worst_state, float(np.max(np.abs(np.r_[fine.q[-1], fine.p[-1]] - got))))
    assert worst_x <= 1e-10
    assert worst_state <= 1e-10


def test_hermite_location_converges_at_order_4():
    """The cubic Hermite estimate (no extra integration) is O(h⁴) from the partial-step point:
    measured gaps 3.8e-8 and 2.4e-9 at h = 0.05 and 0.025 (ratio 15.8)."""
    gaps = [sections.poincare_section(HH, E8, orbits=3, t_end=200.0, dt=dt).meta["max_hermite_gap"] for dt in (0.05, 0.025)]
    assert gaps[0] <= 1e-7
    assert 10 <= gaps[0] / gaps[1] <= 25
    hermite = sections.poincare_section(HH, E8, orbits=3, t_end=200.0, locate="hermite")
    assert np.max(np.abs(hermite.column("x"))) == 0.0
    assert hermite.meta["max_energy_error"] <= 1e-6


def test_regular_orbit_at_1_12_lies_on_a_smooth_closed_curve_and_a_chaotic_one_at_1_8_fills_an_area():
    reg = sections.poincare_section(HH, E12, seeds=[REGULAR_1_12], t_end=6000.0)
    cha = sections.poincare_section(HH, E8, seeds=[CHAOTIC_1_8], t_end=6000.0)
    assert len(reg) >= 800 and len(cha) >= 800
    # Points sorted by angle around their centroid: a smooth curve (measured 0.004) against a
    # cloud (measured 1.3).
    assert radial_jump(reg) <= 0.02
    assert radial_jump(cha) >= 0.5
    # Box counting over the same 40 × 40 grid of the E = 1/8 region, first 800 points each:
    # the curve covers 44 cells, the chaotic orbit 428.
    box = ((-0.5, 0.7), (-0.5, 0.5))
    cells_reg = sections.covered_cells(reg, bins=40, extent=box, points=800).rows[0][2]
    cells_cha = sections.covered_cells(cha, bins=40, extent=box, points=800).rows[0][2]
    assert cells_reg <= 100
    assert cells_cha >= 4 * cells_reg
    # The divergence indicator agrees: linear separation against saturation.
    div_reg = sections.orbit_divergence(HH, E12, seeds=[REGULAR_1_12], t_end=500.0)
    div_cha = sections.orbit_divergence(HH, E8, seeds=[CHAOTIC_1_8], t_end=500.0)
    assert div_reg.rows[0][3] <= 2.0 and not div_reg.rows[0][4]
    assert div_cha.rows[0][3] >= 7.0 and div_cha.rows[0][4]


def test_chaotic_fraction_grows_from_1_12_to_1_8():
    """Hénon & Heiles (1964): regular motion dominates at E = 1/12, chaos is widespread at 1/8.
    With 40 seeds uniform on each section, a neighbour 1e-9 away that gets 1e5 times farther
    within t = 1000 marks a chaotic orbit. Measured over 200 seeds: 1.5% at 1/12, 52% at 1/8."""
    low = sections.orbit_divergence(HH, E12, orbits=40, seed=1)
    high = sections.orbit_divergence(HH, E8, orbits=40, seed=1)
    f12, f8 = low.meta["chaotic_fraction"], high.meta["chaotic_fraction"]
    assert f12 <= 0.1
    assert f8 >= 0.3
    assert f8 - f12 >= 0.25
    # The indicator is bimodal: most regular orbits stay below 3 decades, chaotic ones saturate.
    d8 = high.column("divergence")
    assert np.median(d8[d8 >= sections.CHAOS_THRESHOLD]) >= 8.0
    assert np.median(low.column("divergence")) <= 2.5


def test_closure_model_gives_the_native_section(henon_heiles_closure):
    """The general path (velocity and ∂L/∂q from the model) on a closure twin of Hénon–Heiles,
    with explicit seeds and a box-free set-up, reproduces the native section."""
    # Its coordinates named as the native scene's, so that the tables' columns are the same.
    closure = henon_heiles_closure(name="henon_heiles closure", coordinates=("x", "y"))
    seeds = [(0.2, 0.1), (-0.1, 0.2)]
    a = sections.poincare_section(closure, E12, seeds=seeds, t_end=100.0)
    b = sections.poincare_section(HH, E12, seeds=seeds, t_end=100.0)
    assert len(a) == len(b) >= 20
    for name in ("t", "y", "p_y", "p_x"):
        np.testing.assert_allclose(a.column(name), b.column(name), atol=1e-11)
    # Seeding at random needs a box for a model that is not the native Hénon–Heiles.
    with pytest.raises(ValueError, match="box"):
        sections.poincare_section(closure, E12, orbits=2, t_end=10.0)
    with pytest.raises(ValueError, match="seeds"):
        sections.poincare_section(HH, E12, seeds=[(0.9, 0.0)], t_end=10.0)


def test_a_sweep_can_be_interrupted_with_its_rows_so_far(henon_heiles_closure):
    calls = {"n": 0, "limit": math.inf}

    def gradient(q):
        # One Ctrl-C, as a user presses it: the evaluations after it go on normally.
        calls["n"] += 1
        if calls["n"] == calls["limit"]:
            raise KeyboardInterrupt
        return henon_heiles_closure.gradient(q)

    closure = henon_heiles_closure(gradient)
    seeds = [(0.2, 0.1), (-0.1, 0.2), (0.0, 0.0)]
    first = sections.poincare_section(closure, E12, seeds=seeds[:1], t_end=100.0, progress=False)
    # Ctrl-C (here raised by the closure) half-way through the second orbit.
    calls["n"], calls["limit"] = 0, 3 * calls["n"] // 2
    with pytest.raises(KeyboardInterrupt) as info:
        sections.poincare_section(closure, E12, seeds=seeds, t_end=100.0, progress=False)
    partial = info.value.partial
    assert isinstance(partial, varmech.Table)
    assert partial.unique("orbit") == [0]
    assert partial.rows == first.rows


def test_pendulum_phase_portrait_conserves_energy_and_classifies_against_the_separatrix():
    energies = [-0.9, 0.0, 0.9, 0.999, 1.001, 1.1, 2.5]
    tab = phase_portrait(varmech.scenes.pendulum(), energies, dt=0.01, t_end=40.0)
    # kahan_li6 at h = 0.01: energy error |H − H₀| at round-off level (measured 6e-15).
    assert tab.meta["max_energy_error"] <= 1e-12
    by_orbit = {o: tab.where(orbit=o) for o in tab.unique("orbit")}
    # Each rotation gets its mirror (p < 0): 7 energies, 3 rotations.
    assert len(by_orbit) == 10
    for t in by_orbit.values():
        e = t.rows[0][1]
        motion = t.rows[0][2]
        assert motion == ("libration" if e < 1 else "rotation"), (e, motion)
        q, p = t.column("q"), t.column("p")
        if motion == "libration":
            # Turning points at cos q = −E (sampled every 5 steps: within 1e-3).
            assert abs(np.max(q) - math.acos(-e)) <= 1e-3
            assert abs(np.min(q) + math.acos(-e)) <= 1e-3
        else:
            assert np.all(p > 0) or np.all(p < 0)
            # The momentum at the top: p² = 2(E − 1).
            assert abs(np.min(np.abs(p)) - math.sqrt(2 * (e - 1))) <= 1e-3
    assert {t.rows[0][2] for t in by_orbit.values()} == {"libration", "rotation"}
    with pytest.raises(ValueError, match="one degree of freedom"):
        phase_portrait(HH, [0.1])


def test_charts_write_files(tmp_path, section_1_8):
    pytest.importorskip("matplotlib")
    from varmech.charts.sections import phase_portrait_chart, poincare_chart

    low = sections.poincare_section(HH, E12, orbits=4, t_end=200.0)
    poincare_chart([low, section_1_8], tmp_path / "henon_heiles.png", title="Hénon–Heiles")
    assert (tmp_path / "henon_heiles.png").stat().st_size > 10_000
    pp = phase_portrait(varmech.scenes.pendulum(), t_end=20.0)
    phase_portrait_chart(pp, tmp_path / "pendulum.svg", title="pendulum")
    assert (tmp_path / "pendulum.svg").stat().st_size > 10_000
    csv = section_1_8.to_csv(tmp_path / "section.csv")
    assert "orbit,t,x,y,p_x,p_y,energy_error" in csv.read_text()


@pytest.mark.parametrize("model", [HH, "closure"])
def test_a_sections_orbits_are_their_single_runs_with_the_crossing_event(model, henon_heiles_closure):
    # The orbits run as one ensemble (in parallel for the native scene, serially for closures):
    # each orbit's points are bit for bit the crossings its own integrate call locates.
    from varmech.analysis._orbits import solve_momentum
    from varmech.events import crossing

    model = henon_heiles_closure() if model == "closure" else HH.model
    seeds = [(0.1, 0.0), (-0.2, 0.1), (0.3, -0.05)]
    table = sections.poincare_section(model, E8, seeds=seeds, t_end=60.0, method="verlet", dt=0.02, progress=False)
    for o, (y, py) in enumerate(seeds):
        q0, p0 = np.array([[0.0, y]]), np.array([[0.0, py]])
        p0, ok = solve_momentum(model, q0, p0, 0, E8, 1)
        assert ok[0]
        single = varmech.integrate(model, q0[0], p0[0], dt=0.02, t_end=60.0, method="verlet", events=[crossing(0, 0.0, direction=1)])
        found = single.events[0]
        rows = np.array([r[1:6] for r in table.rows if r[0] == o])
        assert len(found) >= 5 and rows.shape == (len(found), 5)
        assert np.array_equal(rows[:, 0], found.t)
        assert np.array_equal(rows[:, 1:3], found.q) and np.array_equal(rows[:, 3:5], found.p)


def forced_henon_heiles():
    """Hénon–Heiles with a weak drag and a weak periodic push along y: forced, L depending on
    no t but its force on t."""
    sp = pytest.importorskip("sympy")
    x, y, vx, vy, t = sp.symbols("x y vx vy t")
    V = (x**2 + y**2) / 2 + x**2 * y - y**3 / 3
    return varmech.symbolic.lagrangian(
        (vx**2 + vy**2) / 2 - V, [x, y], [vx, vy], t=t, rayleigh=0.001 * (vx**2 + vy**2) / 2, force=[0, 0.002 * sp.cos(t)]
    )


FORCED_SEEDS = [[0.0, 0.1, 0.45, 0.0], [0.0, -0.2, 0.4, 0.1]]


def test_a_forced_models_section_is_judged_by_its_energy_balance():
    # The crossings are the integrator's own partial steps, on x = 0 to round-off; the balance
    # E − W at the step before each holds to the method's accuracy (galerkin6: below 1e-11),
    # and under the midpoint rule it falls at order 2 from h to h/2.
    model = forced_henon_heiles()
    table = sections.poincare_section(model, None, seeds=FORCED_SEEDS, dt=0.05, t_end=400.0, progress=False)
    assert table.columns[-1] == "balance_error" and table.title.endswith("forced")
    assert len(table.rows) > 100
    assert table.meta["max_section_residual"] < 1e-15
    assert table.meta["max_balance_error"] < 1e-11
    errors = [
        sections.poincare_section(model, None, seeds=FORCED_SEEDS, dt=dt, t_end=400.0, method="midpoint", progress=False).meta["max_balance_error"]
        for dt in (0.05, 0.025)
    ]
    assert math.log2(errors[0] / errors[1]) == pytest.approx(2.0, abs=0.2), errors


@pytest.mark.parametrize(
    ("energy", "kwargs", "name"),
    [
        (0.1, {"seeds": FORCED_SEEDS}, "energy"),
        (None, {"seeds": "random"}, "seeds"),
        (None, {"seeds": [[0.0, 0.1, 0.4]]}, "seeds"),
        (None, {"seeds": FORCED_SEEDS, "locate": "hermite"}, "locate"),
    ],
)
def test_a_forced_sections_bad_requests_name_the_argument(energy, kwargs, name):
    with pytest.raises(ValueError, match=f"^{name}:"):
        sections.poincare_section(forced_henon_heiles(), energy, dt=0.05, t_end=10.0, progress=False, **kwargs)


def test_a_conservative_section_needs_its_energy():
    with pytest.raises(ValueError, match="^energy:"):
        sections.poincare_section(varmech.scenes.henon_heiles(), None, progress=False)
