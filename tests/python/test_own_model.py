"""The user's own model through every analysis, chart and the CLI (issue 38): Scene.of, the
computed reference (against DOP853 and exact solutions, to its stated tolerance), reports and
charts in the model's own words, and the charts' notes of what they measured."""

import math
import textwrap
import warnings

import numpy as np
import pytest

import varmech
from varmech.analysis.reference import ReferenceWarning, reference_solution
from varmech.charts.recipes import chart

sympy = pytest.importorskip("sympy")
from varmech.symbolic import examples  # noqa: E402

# The elastic pendulum (SymPy, Cartesian x, y), released 0.6 off the vertical with the spring
# stretched to 1.5, from rest.
ELASTIC_Q0 = [1.5 * math.sin(0.6), -1.5 * math.cos(0.6)]


def duffing():
    """A closure model, the hardening Duffing oscillator V = x²/2 + x⁴/4, its coordinate named."""
    return varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2 + 0.25 * q[0] ** 4, lambda q: q + q**3, coordinates=["x"])


def svg_texts(path):
    """The texts of a matplotlib SVG (each drawn text is preceded by a comment holding it, XML
    escaped, "--" written "- -"), whitespace collapsed; a wrapped note is a text a line."""
    import html
    import re

    comments = re.findall(r"<!-- (.*?) -->", path.read_text(), flags=re.S)
    return [" ".join(html.unescape(t).replace("- -", "--").split()) for t in comments]


def dop853(model, q0, p0, t_end, rtol):
    """(q, p) at t_end by SciPy's DOP853 on Hamilton's equations of the model."""
    from scipy.integrate import solve_ivp

    from varmech.analysis import baselines

    scene = varmech.Scene.of(model, q0, p0, t_end=t_end)
    sol, _ = baselines.solve(solve_ivp, scene, "DOP853", t_end, rtol, np.full(2 * model.dim, rtol * 1e-2))
    return sol.y[:, -1]


# ------------------------------------------------------------------------------------ Scene.of


def test_scene_of_a_model_takes_its_step_from_its_fastest_oscillation():
    model = duffing()
    scene = varmech.Scene.of(model, [1e-4], [0.0], t_end=1000.0)
    # ω = 1 at the bottom: 20 steps a period.
    assert scene.dt == pytest.approx(2 * math.pi / 20, rel=2e-3)
    assert scene.invariants == {"energy": pytest.approx(0.5e-8 + 0.25e-16)}
    assert scene.name == "mechanical system" and scene.reference is None
    # At most a hundredth of the horizon; velocities as the initial state.
    short = varmech.Scene.of(model, [1.0], v0=[0.5], t_end=10.0)
    assert short.dt == 0.1 and short.p0.tolist() == [0.5]
    # A model with no oscillation (a free particle): a thousandth of the horizon.
    free = varmech.MechanicalSystem(1, lambda q: 0.0, lambda q: 0 * q)
    assert varmech.Scene.of(free, [0.0], [1.0], t_end=50.0).dt == 0.05


#: The swinging Atwood machine (issue 64): a mass M = 3 on a rope over a pulley, its other end a
#: mass m = 1 swinging at length r; from rest at r = 1, θ = 0.5 the swinging mass falls in to
#: r = 0.16 at t = 0.66, where θ whirls.
ATWOOD = """
import sympy as sp
r, th, vr, vth = sp.symbols("r theta v_r v_theta")
q = [r, th]; v = [vr, vth]
M, m, g = 3.0, 1.0, 9.81
L = sp.Rational(1,2)*(M+m)*vr**2 + sp.Rational(1,2)*m*r**2*vth**2 - M*g*r + m*g*r*sp.cos(th)
"""


def test_scene_of_takes_the_step_at_which_a_trial_from_q0_is_accurate():
    namespace: dict = {}
    exec(ATWOOD, namespace)
    model = varmech.symbolic.lagrangian(namespace["L"], namespace["q"], namespace["v"])
    # A twentieth of the fastest period at q0, 0.104, does not converge at the whirl (step 7);
    # the trial halves it twice, to where 8 steps agree with 16 half steps to 2% of the motion.
    with pytest.raises(varmech.ConvergenceError, match="at step 7"):
        varmech.integrate(model, [1.0, 0.5], v0=[0.0, 0.0], dt=0.104, t_end=52.0)
    scene = varmech.Scene.of(model, [1.0, 0.5], v0=[0.0, 0.0], t_end=50.0)
    assert scene.dt == 0.0259
    traj = varmech.integrate(scene, dt=50.0 / math.ceil(50.0 / scene.dt), t_end=50.0)
    assert varmech.check_conservation(traj).energy.verdict == "bounded"
    # Where no step of the trial runs, the default is refused naming dt, with what was tried.
    cliff = varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2, lambda q: q if q[0] < 1 else np.array([np.nan]))
    with pytest.raises(ValueError, match=r"^dt: no step of verlet is accurate .* tried 0\.1 \(DivergenceError at step 7\), 0\.05 .*; pass dt"):
        varmech.Scene.of(cliff, [0.5], [1.0], t_end=10.0)


def test_scene_of_refuses_what_is_not_a_scene_naming_the_argument():
    model = duffing()
    with pytest.raises(TypeError, match="model: expected a varmech Model"):
        varmech.Scene.of(lambda q: q, [0.0], [0.0], t_end=1.0)
    with pytest.raises(ValueError, match="p0, v0: give exactly one"):
        varmech.Scene.of(model, [0.0], t_end=1.0)
    with pytest.raises(TypeError, match="t_end"):
        varmech.Scene.of(model, [0.0], [0.0], t_end="10")
    with pytest.raises(ValueError, match="dt: must not exceed t_end"):
        varmech.Scene.of(model, [0.0], [0.0], t_end=1.0, dt=2.0)
    with pytest.raises(ValueError, match="q0"):
        varmech.Scene.of(model, [0.0, 1.0], [0.0], t_end=1.0)


def test_a_model_without_its_state_or_horizon_is_a_type_error_naming_them():
    with pytest.raises(TypeError, match=r"scene: a model needs its initial state and horizon: pass q0 and t_end"):
        varmech.work_precision(duffing(), ["verlet"])
    with pytest.raises(TypeError, match=r"pass t_end"):
        varmech.energy_growth(duffing(), ["verlet"], q0=[1.0], p0=[0.0])
    with pytest.raises(TypeError, match="scene: expected a varmech Scene, a scene's name or a Model"):
        varmech.work_precision(object(), ["verlet"])


# ------------------------------------------------------------------------ the computed reference


def test_the_computed_reference_agrees_with_dop853_at_1e_12_to_its_stated_tolerance():
    """The elastic pendulum (SymPy) over 20 time units, about ten radial periods: kahan_li6 at
    doubling steps against DOP853 at rtol 1e-12 (a different method, a different code)."""
    pytest.importorskip("scipy")
    model = examples.elastic_pendulum_cartesian()
    ref = reference_solution(model, q0=ELASTIC_Q0, v0=[0.0, 0.0], t_end=20.0)
    assert ref.source.startswith("computed: kahan_li6 at ") and ref.t == 20.0
    assert ref.tolerance <= 1e-10 * max(1.0, np.linalg.norm(np.concatenate([ref.q, ref.p])))
    x = dop853(model, ELASTIC_Q0, [0.0, 0.0], 20.0, 1e-12)
    assert np.linalg.norm(np.concatenate([ref.q, ref.p]) - x) <= ref.tolerance


def test_the_computed_reference_of_a_closure_model_and_a_general_l_against_exact_solutions():
    # The harmonic oscillator as closures, and as a general L (galerkin6): exact cos and sin.
    t = 10.0
    spring = varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2, lambda q: q)
    general = varmech.Lagrangian(
        1, lambda q, v, t: 0.5 * (v[0] ** 2 - q[0] ** 2), dl_dq=lambda q, v, t: -q, dl_dv=lambda q, v, t: v
    )
    for model, method in ((spring, "kahan_li6"), (general, "galerkin6")):
        ref = reference_solution(model, q0=[1.0], p0=[0.0], t_end=t)
        assert ref.source.startswith(f"computed: {method} at ")
        error = math.hypot(ref.q[0] - math.cos(t), ref.p[0] + math.sin(t))
        assert error <= ref.tolerance <= 1e-10, (method, error, ref.tolerance)


def test_a_reference_short_of_its_tolerance_warns_and_states_what_it_reached():
    with pytest.warns(ReferenceWarning, match=r"agrees only to .*max_steps came first"):
        ref = reference_solution(duffing(), q0=[1.0], p0=[0.0], t_end=100.0, max_steps=2**10)
    # Order 6: the differences fall 64-fold a doubling; here the budget ends at 1.6e-4.
    assert "at 1024 steps, agreeing with 512 steps to 1.6e-04" in ref.source and ref.tolerance > 1e-4
    with pytest.raises(ValueError, match="max_steps: two runs from the scene's own 512 steps over t_end = 100 need 1024, got 512"):
        reference_solution(duffing(), q0=[1.0], p0=[0.0], t_end=100.0, max_steps=512)


# ----------------------------------------------------------------------- the analyses, any model


def test_work_precision_of_a_sympy_model_computes_its_reference_and_says_so():
    pytest.importorskip("scipy")
    model = examples.elastic_pendulum_cartesian()
    kwargs = dict(q0=ELASTIC_Q0, v0=[0.0, 0.0], t_end=20.0, repeat=1, progress=False, rebound=())
    table = varmech.work_precision(model, ["verlet", "kahan_li6"], steps=[256, 512], baselines=("DOP853",), rtols=(1e-6, 1e-9), **kwargs)
    assert table.meta["reference"].startswith("computed: kahan_li6")
    assert any(n.startswith("reference computed: kahan_li6") and "(the scene has none)" in n for n in table.meta["notes"])
    errors = table.where(method="verlet").column("final_error")
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.1)  # order 2, measured
    six = table.where(method="kahan_li6").column("final_error")
    assert six[0] / six[1] == pytest.approx(64.0, rel=0.25)  # order 6
    assert np.all(table.where(tool="scipy").column("final_error") < 1e-4)
    assert table.meta["evaluation_units"].keys() == {"varmech, explicit", "scipy"}

    # A reference given is used as it is; None measures the energy alone.
    given = reference_solution(model, q0=ELASTIC_Q0, v0=[0.0, 0.0], t_end=20.0)
    same = varmech.work_precision(model, ["verlet"], steps=[256], baselines=(), reference=given, **kwargs)
    assert same.column("final_error")[0] == errors[0] and not same.meta["notes"]
    none = varmech.work_precision(model, ["verlet"], steps=[256], baselines=(), reference=None, **kwargs)
    assert math.isnan(none.column("final_error")[0]) and none.meta["reference"] is None
    assert none.column("max_energy_error")[0] == table.where(method="verlet").column("max_energy_error")[0]
    with pytest.raises(TypeError, match="reference: expected a varmech.scenes.Reference, 'auto' or None"):
        varmech.work_precision(model, ["verlet"], steps=[256], baselines=(), reference="exact", **kwargs)


def test_a_scenes_reference_at_another_horizon_is_computed_there():
    scene = varmech.scenes.pendulum()
    table = varmech.work_precision(scene, ["kahan_li6"], steps=[64], t_end=3.0, baselines=(), rebound=(), repeat=1, progress=False)
    assert "the scene's is at t = 6.28319" in table.meta["notes"][0]
    assert table.column("final_error")[0] < 1e-6


def test_energy_growth_of_a_closure_model():
    table = varmech.energy_growth(duffing(), ["verlet", "rk4"], q0=[1.0], p0=[0.0], t_end=500.0, samples=50, baselines=(), progress=False)
    verdicts = {m: v["verdict"] for m, v in table.meta["verdicts"].items()}
    assert verdicts == {"verlet": "bounded", "rk4": "secular drift"}
    assert table.meta["t_end"] == pytest.approx(500.0, rel=1e-3) and table.meta["scene"] == "mechanical system"


def test_a_scene_of_ones_own_runs_through_the_chaos_tools():
    """The elastic pendulum's Poincaré section from its Scene: the columns in its own names."""
    model = examples.elastic_pendulum_cartesian()
    scene = varmech.Scene.of(model, ELASTIC_Q0, v0=[0.0, 0.0], t_end=100.0, name="elastic pendulum")
    energy = scene.invariants["energy"]
    box = ((-1.3, -1.1), (-0.5, 0.5))
    table = varmech.poincare_section(scene, energy, orbits=2, dt=0.05, t_end=200.0, box=box, progress=False)
    assert {"x", "y", "p_x", "p_y"} <= set(table.columns) and table.meta["plane"] == ("y", "p_y")
    assert np.all(np.abs(table.column("energy_error")) < 1e-3)


# ----------------------------------------------------------------------------------- the charts


@pytest.fixture
def svg_text_mode():
    """matplotlib, whose SVG files keep each text in a comment before its glyphs."""
    pytest.importorskip("matplotlib")


def test_the_charts_of_a_computed_reference_a_quick_sweep_and_evaluations_say_so(tmp_path, svg_text_mode):
    pytest.importorskip("scipy")
    model = examples.elastic_pendulum_cartesian()
    scene = varmech.Scene.of(model, ELASTIC_Q0, v0=[0.0, 0.0], t_end=20.0, name="elastic pendulum")
    paths = chart("work-precision", scene, methods=("verlet", "galerkin4"), out=tmp_path, quick=True, fmt="svg", progress=False)
    assert [p.name for p in paths][:2] == ["work_precision_elastic_pendulum.csv", "work_precision_elastic_pendulum.svg"]
    error = svg_texts(tmp_path / "work_precision_elastic_pendulum.svg")
    joined = " ".join(error)
    assert any(t.startswith("reference tolerance ") for t in error), error
    assert "note: reference computed: kahan_li6 at" in joined and "--quick: a short measurement" in joined
    evaluations = " ".join(svg_texts(tmp_path / "work_precision_evaluations_elastic_pendulum.svg"))
    for family in ("varmech, explicit: one force", "varmech, implicit: one evaluation of the discrete Lagrangian", "scipy: one right-hand side"):
        assert family in evaluations, family


def test_the_energy_chart_draws_its_shorter_baseline_as_such(tmp_path, svg_text_mode):
    pytest.importorskip("scipy")
    scene = varmech.Scene.of(duffing(), [1.0], [0.0], t_end=1000.0, name="duffing")
    chart("energy", scene, methods=("verlet",), out=tmp_path, quick=True, fmt="svg", progress=False)
    texts = svg_texts(tmp_path / "energy_growth_duffing.svg")
    # The horizon in whole steps of the scene's dt (0.157: 20 a period of the small oscillations
    # at x = 1, ω = 2), the baseline's a tenth of it.
    assert "baselines end at t = 10.0009" in texts, texts
    assert "DOP853 (scipy, rtol 1e-10), run to t = 10.0009 only: bounded" in texts, texts
    assert any(t.startswith("--quick: a short measurement") for t in texts), texts


def test_chart_axes_carry_the_models_coordinates(tmp_path, svg_text_mode):
    """The double pendulum's Poincaré chart names its angles; a phase portrait its coordinate."""
    chart("poincare", "double_pendulum", out=tmp_path, quick=True, fmt="svg", progress=False)
    (path,) = tmp_path.glob("poincare_*double_pendulum.svg")
    texts = svg_texts(path)
    assert "theta2" in texts and "p_theta2" in texts, texts
    assert any(t.startswith("double_pendulum: Poincaré section theta1 = ") and "(p_theta1 > 0), energy = " in t for t in texts)
    scene = varmech.Scene.of(duffing(), [1.0], [0.0], t_end=20.0, name="duffing")
    chart("phase", scene, out=tmp_path, quick=True, fmt="svg", progress=False)
    texts = svg_texts(tmp_path / "phase_portrait_duffing.svg")
    assert "x" in texts and "p_x" in texts, texts


# -------------------------------------------------------------------------------------- the CLI

OWN = textwrap.dedent(
    """
    import sympy as sp
    import varmech

    r, th, rd, thd = sp.symbols("r theta r_dot theta_dot")
    q, v = [r, th], [rd, thd]
    # The elastic pendulum in polar coordinates: a general L, the spring's stiffness k.
    k = sp.Symbol("k")
    L = (rd**2 + r**2 * thd**2) / 2 + r * sp.cos(th) - k * (r - 1) ** 2 / 2
    parameters = {k: 10.0}

    duffing = varmech.MechanicalSystem(1, lambda q: q[0] ** 2 / 2 + q[0] ** 4 / 4, lambda q: q + q**3, coordinates=["x"])


    def swing():
        return varmech.Scene.of(duffing, [1.0], [0.0], t_end=50.0, name="swing")
    """
)


@pytest.fixture
def own(tmp_path):
    path = tmp_path / "own.py"
    path.write_text(OWN)
    return path


def test_run_integrates_ones_own_model_and_speaks_its_names(own, run_cli):
    out = run_cli("run", f"{own}:duffing", "--q0", "1.0", "--t-end", "100").stdout
    assert "duffing: mechanical system; verlet, dt = " in out and "to t = 100 time units" in out
    assert "energy      verdict: bounded" in out and "final state: x = " in out and ", p_x = " in out
    sympy_l = run_cli("run", f"{own}:L", "--q0", "1.2,0.5", "--t-end", "10").stdout
    assert "final state: r = " in sympy_l and "p_theta = " in sympy_l and "midpoint" in sympy_l
    scene = run_cli("run", f"{own}:swing").stdout
    assert scene.startswith("swing: ") and "to t = 50 time units" in scene


def test_the_cli_says_what_ones_own_model_lacks(own, run_cli):
    missing = run_cli("run", f"{own}:duffing", check=False)
    assert missing.returncode == 2 and "--q0 and --t-end: " in missing.stderr and "is a model" in missing.stderr
    typo = run_cli("run", f"{own}:dufing", "--q0", "1", "--t-end", "1", check=False)
    assert typo.returncode == 2 and "defines no 'dufing'; it defines " in typo.stderr and "duffing" in typo.stderr
    builtin = run_cli("run", "pendulum", "--q0", "1", check=False)
    assert builtin.returncode == 2 and "--q0: a built-in scene has its own initial state" in builtin.stderr
    nofile = run_cli("chart", "energy", "nowhere.py:model", check=False)
    assert nofile.returncode == 2 and "scene: no file nowhere.py" in nofile.stderr


def test_chart_of_ones_own_model_from_the_command_line(own, tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    done = run_cli("chart", "work-precision", f"{own}:duffing", "--q0", "1.0", "--t-end", "20", "--quick", "--out", tmp_path)
    assert (tmp_path / "work_precision_duffing.png").exists() and (tmp_path / "work_precision_evaluations_duffing.png").exists()
    # Notes go to standard error, apart from the files written.
    assert "note: reference computed: kahan_li6" in done.stderr and "note:" not in done.stdout
    assert f"wrote {tmp_path / 'work_precision_duffing.csv'}" in done.stdout


def test_scenes_lists_the_catalogue(run_cli):
    out = run_cli("scenes").stdout
    assert "pendulum | 1 | separable | " in out and "double_pendulum | 2 | lagrangian | " in out
    assert "elastic_pendulum | 2 | separable" in out


def test_a_failed_run_is_an_error_status_with_the_reason(own, run_cli):
    blown = run_cli("run", f"{own}:duffing", "--q0", "1e3", "--t-end", "10", "--dt", "1", "--method", "verlet", check=False)
    # Warned of first (the step is beyond verlet's limit there), then failed with its reason.
    assert "StabilityWarning: dt: h·ω_max = " in blown.stderr
    assert blown.returncode == 1 and "\nerror: DivergenceError: " in blown.stderr


def test_the_swinging_atwood_machine_runs_from_the_command_line_and_a_failed_chart_says_why(tmp_path, run_cli):
    path = tmp_path / "mine.py"
    path.write_text(ATWOOD)
    run = run_cli("run", f"{path}:L", "--q0", "1.0,0.5", "--t-end", "50")
    assert "L: L; midpoint, dt = 0.0258933, 1931 steps" in run.stdout and "verdict: bounded" in run.stdout
    # A chart whose run fails says so on one line, with status 1, as run does.
    pytest.importorskip("matplotlib")
    chart = run_cli("chart", "energy", f"{path}:L", "--q0", "1.0,0.5", "--t-end", "50", "--dt", "0.104", "--out", tmp_path, check=False)
    assert chart.returncode == 1 and chart.stdout == ""
    assert chart.stderr.startswith("error: ConvergenceError: Newton's method did not converge at step 7")
    assert chart.stderr.count("\n") == 1 and "Traceback" not in chart.stderr


def test_no_warning_from_a_reference_that_converges():
    with warnings.catch_warnings():
        warnings.simplefilter("error", ReferenceWarning)
        reference_solution(varmech.scenes.harmonic_oscillator())


def test_every_chart_kind_takes_ones_own_scene_or_says_why_not(tmp_path):
    """The kinds not drawn above: the spectrum of the elastic pendulum, the implicit methods'
    regions on the Duffing oscillator; the driven pendulum's strobe refuses it with the reason."""
    pytest.importorskip("matplotlib")
    elastic = varmech.Scene.of(examples.elastic_pendulum_cartesian(), ELASTIC_Q0, v0=[0.0, 0.0], t_end=20.0, name="elastic")
    assert [p.name for p in chart("spectrum", elastic, out=tmp_path, quick=True, progress=False)] == ["spectrum_elastic.csv", "spectrum_elastic.png"]
    spring = varmech.Scene.of(duffing(), [1.0], [0.0], t_end=20.0, name="duffing")
    written = chart("implicit-regions", spring, methods=("midpoint",), out=tmp_path, quick=True, progress=False)
    assert [p.name for p in written] == ["implicit_regions_duffing.csv", "implicit_regions_duffing.png"]
    with pytest.raises(ValueError, match="scene: the orbit diagram and the strobe are of the damped, driven pendulum"):
        chart("strobe", spring, out=tmp_path)
    with pytest.raises(ValueError, match="scene: the stability chart is of the linear test equation"):
        chart("stability", spring, out=tmp_path)


def test_energy_growth_of_the_sympy_elastic_pendulum_and_implicit_regions_of_a_bare_model():
    model = examples.elastic_pendulum_cartesian()
    table = varmech.energy_growth(model, ["verlet", "rk4"], q0=ELASTIC_Q0, v0=[0.0, 0.0], t_end=200.0, samples=50, baselines=(), progress=False)
    assert {m: v["verdict"] for m, v in table.meta["verdicts"].items()} == {"verlet": "bounded", "rk4": "secular drift"}
    regions = varmech.implicit_regions("midpoint", scene=duffing(), h_values=(0.1,), q0_values=(0.5,))
    assert regions.column("outcome").tolist() == ["ok"] and regions.meta["scene"] == "mechanical system"
    with pytest.raises(TypeError, match="scene: expected a varmech Scene, a scene's name or a Model"):
        varmech.implicit_regions("midpoint", scene=3.0)


def test_chart_of_a_sympy_lagrangian_from_the_command_line(own, tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    done = run_cli("chart", "energy", f"{own}:L", "--q0", "1.2,0.5", "--t-end", "200", "--quick", "--out", tmp_path)
    assert (tmp_path / "energy_growth_L.png").exists(), done.stdout
    verdicts = (tmp_path / "energy_verdicts_L.csv").read_text()
    assert "galerkin6" in verdicts and "midpoint" in verdicts
