"""The symbolic front end without the binding: every derived function's tape, run by a small
NumPy interpreter of the tape contract, equals the lambdified SymPy expressions it came from;
the derivations agree with the closure examples' hand-written derivatives; the kind, the mass,
the cyclic coordinates and the refusals of bad input are as promised.

The core's compiled model is replaced by a recorder of what would cross into it."""

import importlib
import math
import pickle
from dataclasses import replace

import numpy as np
import pytest

sp = pytest.importorskip("sympy")

import varmech  # noqa: E402
import varmech.symbolic as symbolic  # noqa: E402
from varmech import examples, scenes  # noqa: E402
from varmech.symbolic import TAPE_OPS  # noqa: E402
from varmech.symbolic.examples import double_pendulum, heavy_top, kepler  # noqa: E402

UNARY = {
    "neg": np.negative,
    "sqrt": np.sqrt,
    "exp": np.exp,
    "log": np.log,
    "sin": np.sin,
    "cos": np.cos,
    "tan": np.tan,
    "asin": np.arcsin,
    "acos": np.arccos,
    "atan": np.arctan,
    "sinh": np.sinh,
    "cosh": np.cosh,
    "tanh": np.tanh,
    "asinh": np.arcsinh,
    "acosh": np.arccosh,
    "atanh": np.arctanh,
    "abs": np.abs,
    "sign": np.sign,
}
BINARY = {"add": np.add, "sub": np.subtract, "mul": np.multiply, "div": np.divide, "pow": np.power, "atan2": np.arctan2}


def run_tape(tape, inputs, parameters):
    """The outputs of a tape at the columns of ``inputs`` (2n + 1, N), per the contract: one
    register per instruction, operands only from earlier registers."""
    ops, constants, outputs = tape
    assert ops.dtype == np.int64 and ops.ndim == 2 and ops.shape[1] == 3
    assert constants.dtype == np.float64 and outputs.dtype == np.int64
    registers = []
    for i, (code, a, b) in enumerate(ops.tolist()):
        op = TAPE_OPS[code]
        if op == "const":
            value = np.full(inputs.shape[1], constants[a])
        elif op == "input":
            value = inputs[a]
        elif op == "param":
            value = np.full(inputs.shape[1], parameters[a])
        elif op == "powi":
            assert a < i
            value = registers[a] ** float(b)
        elif op in UNARY:
            assert a < i
            value = UNARY[op](registers[a])
        else:
            assert a < i and b < i
            value = BINARY[op](registers[a], registers[b])
        registers.append(value)
    assert all(0 <= k < len(registers) for k in outputs)
    return np.array([registers[k] for k in outputs])


class Recorder:
    """Stands in for the core's CompiledModel: keeps the spec it would be built from."""

    def __init__(self, spec):
        self.spec = spec
        self.dim = spec.dim

    def with_parameters(self, values):
        return Recorder(replace(self.spec, parameters=values))


@pytest.fixture(autouse=True)
def recorded(monkeypatch):
    monkeypatch.setattr(importlib.import_module("varmech.symbolic._model"), "_compile", Recorder)


# The double pendulum of issue 14 (varmech.symbolic.examples): its L, symbols and parameters.
with pytest.MonkeyPatch.context() as patch:
    patch.setattr(importlib.import_module("varmech.symbolic._model"), "_compile", Recorder)
    _ISSUE = double_pendulum()
DOUBLE_PENDULUM = _ISSUE.L
Q1, Q2 = _ISSUE.q
V1, V2 = _ISSUE.v
_SYMBOLS = {s.name: s for s in DOUBLE_PENDULUM.free_symbols}
M1, L2 = _SYMBOLS["m1"], _SYMBOLS["l2"]
DOUBLE_PENDULUM_PARAMETERS = {_SYMBOLS[name]: value for name, value in _ISSUE.parameters.items()}


def check_tapes(model, points):
    """Every function's tape equals the lambdified expressions at ``points`` (2n + 1, N) with
    the model's parameters, to 1e-13 relative to the function's size there."""
    spec = model._core.spec
    assert set(spec.functions) == set(model.expressions)
    symbols = {s.name: s for expressions in model.expressions.values() for e in expressions for s in e.free_symbols}
    arguments = [*model.q, *model.v, model.t, *(symbols.get(name, sp.Symbol(name)) for name in model.parameters)]
    values = list(model.parameters.values())
    for name, expressions in model.expressions.items():
        tape = spec.functions[name]
        assert len(tape[2]) == len(expressions)
        reference = sp.lambdify(arguments, list(expressions), "numpy")(*points, *values)
        reference = np.array([np.broadcast_to(np.asarray(r, dtype=float), points.shape[1:]) for r in reference])
        got = run_tape(tape, points, spec.parameters)
        scale = np.max(np.abs(reference), axis=0)
        assert np.all(np.abs(got - reference) <= 1e-13 * np.maximum(scale, 1e-300)), name
        # One register per distinct value: no instruction and no constant twice.
        ops, constants, _ = tape
        assert len({tuple(row) for row in ops.tolist()}) == len(ops), name
        assert len({c.hex() for c in constants.tolist()}) == len(constants), name


def points(n, samples=50, low=-1.5, high=1.5, seed=1):
    """Random columns (q, v, t): positions and velocities in [low, high], t in [0, 10]."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(low, high, (2 * n + 1, samples))
    x[2 * n] = rng.uniform(0.0, 10.0, samples)
    return x


# ------------------------------------------------------------------------ the systems

X, Y, VX, VY = sp.symbols("x y v_x v_y")


def check_against_closure(model, hand, x):
    """L, ∂L/∂q, ∂L/∂q̇ and the Hessians of the tapes equal those of the hand-written closure
    twin (the native scene's formulas) at the columns of ``x``."""
    spec, n = model._core.spec, model.dim
    values = {
        name: run_tape(spec.functions[name], x, spec.parameters) for name in ("lagrangian", "gradients", "hessians")
    }
    for k in range(x.shape[1]):
        q, v = x[:n, k], x[n : 2 * n, k]
        assert values["lagrangian"][0, k] == pytest.approx(hand.lagrangian(q, v, 0.0), rel=1e-14)
        gradients = np.concatenate([hand.dl_dq(q, v, 0.0), hand.dl_dv(q, v, 0.0)])
        np.testing.assert_allclose(values["gradients"][:, k], gradients, rtol=1e-13, atol=1e-12)
        hessians = np.concatenate([h.ravel() for h in hand.hessians(q, v, 0.0)])
        np.testing.assert_allclose(values["hessians"][:, k], hessians, rtol=1e-13, atol=1e-12)


def test_double_pendulum_tapes_equal_their_expressions_and_the_hand_derivatives():
    model = double_pendulum()
    assert model.kind_name == "lagrangian" and model.cyclic == () and model.symmetries == ()
    assert model.parameters == {"m1": 1.0, "m2": 2.0, "l1": 2.0, "l2": 3.0, "g": 9.80665}
    assert list(model._core.spec.functions) == ["lagrangian", "gradients", "hessians"]
    x = points(2)
    check_tapes(model, x)
    check_against_closure(model, examples.double_pendulum(), x)


def test_kepler_is_separable_with_a_scalar_mass():
    model = kepler()
    assert model.kind_name == "separable"
    assert list(model._core.spec.functions) == ["potential", "gradient", "mass"]
    assert model.expressions["mass"] == (1,)
    x = points(2, low=0.2, high=1.5)
    check_tapes(model, x)
    gradient = run_tape(model._core.spec.functions["gradient"], x, [])
    hand = examples.kepler()
    for k in range(x.shape[1]):
        np.testing.assert_allclose(gradient[:, k], hand.gradient(x[:2, k]), rtol=1e-15)
    # The same system as a Lagrangian is recognised as separable too.
    L = (VX**2 + VY**2) / 2 + 1 / sp.sqrt(X**2 + Y**2)
    assert symbolic.lagrangian(L, [X, Y], [VX, VY]).expressions == model.expressions


def test_diagonal_and_full_constant_masses_keep_their_smallest_form():
    a, b, c, k = sp.symbols("a b c k", positive=True)
    V = k * (X**2 + Y**2) / 2 + X * Y**3
    diagonal = symbolic.mechanical(V, [X, Y], [[a, 0], [0, b]], v=[VX, VY], parameters={a: 2.0, b: 3.0, k: 1.5})
    assert diagonal.kind_name == "separable" and diagonal.expressions["mass"] == (a, b)
    check_tapes(diagonal, points(2))
    equal = symbolic.mechanical(V, [X, Y], sp.diag(a, a), v=[VX, VY], parameters={a: 2.0, k: 1.5})
    assert equal.expressions["mass"] == (a,)
    L = (a * VX**2 + 2 * c * VX * VY + b * VY**2) / 2 - V
    full = symbolic.lagrangian(L, [X, Y], [VX, VY], parameters={a: 2.0, b: 3.0, c: 0.5, k: 1.5})
    assert full.kind_name == "separable" and full.expressions["mass"] == (a, c, c, b)
    check_tapes(full, points(2))
    spec = full._core.spec
    np.testing.assert_array_equal(
        run_tape(spec.functions["mass"], points(2, samples=1), spec.parameters)[:, 0], [2.0, 0.5, 0.5, 3.0]
    )


def test_heavy_top_tapes_derivatives_and_cyclic_angles():
    model = heavy_top()
    assert model.kind_name == "lagrangian"
    assert model.cyclic == (1, 2)
    assert model.symmetries == (varmech.Cyclic(1), varmech.Cyclic(2))
    x = points(3)
    check_tapes(model, x)
    check_against_closure(model, examples.heavy_top(), x)
    # A declared symmetry is kept, and a found one is not added twice.
    th, ph, ps = model.q
    again = symbolic.lagrangian(model.L, model.q, model.v, parameters=model.parameters, symmetries=[varmech.Cyclic(2)])
    assert again.symmetries == (varmech.Cyclic(2), varmech.Cyclic(1))


def test_cartesian_pendulum_constraint_and_its_jacobian():
    m, l, g = sp.symbols("m l g", positive=True)
    model = symbolic.mechanical(
        m * g * Y, [X, Y], m, v=[VX, VY], constraints=[X**2 + Y**2 - l**2], parameters={m: 1.0, l: 1.0, g: 1.0}
    )
    assert model.kind_name == "separable"
    assert model._core.spec.constraints == 1
    assert model.expressions["constraint_jacobian"] == (2 * X, 2 * Y)
    # x is absent from L, but the constraint binds it: not cyclic.
    assert model.cyclic == ()
    check_tapes(model, points(2))


def test_elastic_pendulum():
    r, th, vr, vth = sp.symbols("r theta v_r v_theta")
    m, g, k, l0 = sp.symbols("m g k l0", positive=True)
    L = m / 2 * (vr**2 + r**2 * vth**2) + m * g * r * sp.cos(th) - k / 2 * (r - l0) ** 2
    model = symbolic.lagrangian(L, [r, th], [vr, vth], parameters={m: 1.0, g: 9.81, k: 40.0, l0: 1.0})
    assert model.kind_name == "lagrangian" and model.cyclic == ()
    check_tapes(model, points(2, low=0.3))


def test_bead_on_a_hoop_turning_in_its_plane_depends_on_t():
    """The bead at angle θ on a hoop of radius R turning at ω in a vertical plane: its inertial
    angle is θ + ωt, so L = ½mR²(θ̇ + ω)² + mgR cos(θ + ωt) depends on t."""
    th, vth, t = sp.symbols("theta v_theta t")
    m, R, g, w = sp.symbols("m R g omega", positive=True)
    L = m * R**2 / 2 * (vth + w) ** 2 + m * g * R * sp.cos(th + w * t)
    model = symbolic.lagrangian(L, [th], [vth], t=t, parameters={m: 1.0, R: 0.5, g: 9.81, w: 3.0})
    assert model.kind_name == "lagrangian" and model._core.spec.time_dependent
    check_tapes(model, points(1))


def test_hoop_spun_about_the_vertical_is_time_independent_once_simplified():
    """Written in the inertial frame, x = R sin θ cos ωt, y = R sin θ sin ωt, z = −R cos θ, the
    bead's L holds t, yet depends on it only through cos² + sin² = 1."""
    th, vth, t = sp.symbols("theta v_theta t")
    R, g, w = sp.symbols("R g omega", positive=True)
    theta = sp.Function("theta")(t)
    position = sp.Matrix([R * sp.sin(theta) * sp.cos(w * t), R * sp.sin(theta) * sp.sin(w * t), -R * sp.cos(theta)])
    velocity = position.diff(t)
    L = ((velocity.T * velocity)[0, 0] / 2 - g * position[2]).subs(theta.diff(t), vth).subs(theta, th)
    assert t in L.free_symbols
    model = symbolic.lagrangian(L, [th], [vth], t=t, parameters={R: 1.0, g: 9.81, w: 4.0})
    assert not model._core.spec.time_dependent
    check_tapes(model, points(1))


def test_rayleigh_damped_driven_oscillator_has_a_force():
    x, v, t = sp.symbols("x v t")
    k, gamma, A, W = sp.symbols("k gamma A Omega")
    model = symbolic.lagrangian(
        v**2 / 2 - k * x**2 / 2,
        [x],
        [v],
        t=t,
        force=[A * sp.cos(W * t)],
        rayleigh=gamma * v**2 / 2,
        parameters={k: 1.0, gamma: 0.5, A: 1.5, W: 2 / 3},
    )
    spec = model._core.spec
    assert model.kind_name == "lagrangian" and spec.forced and not spec.time_dependent
    assert model.expressions["force"] == (A * sp.cos(W * t) - gamma * v,)
    assert model.cyclic == ()
    check_tapes(model, points(1))


def test_abs_differentiates_to_sign():
    """A V-shaped well V = k|x|: ∇V = k sign x (over real symbols, not an expression in re x)."""
    x, v, k = sp.symbols("x v k")
    model = symbolic.lagrangian(v**2 / 2 - k * sp.Abs(x), [x], [v], parameters={k: 2.0})
    assert model.kind_name == "separable"
    assert model.expressions["gradient"] == (k * sp.sign(x),)
    assert model.q == (x,) and model.expressions["potential"][0].free_symbols == {x, k}
    check_tapes(model, points(1))


def test_cyclic_coordinates_need_no_force_on_them():
    x, y, vx, vy = sp.symbols("x y vx vy")
    L = (vx**2 + vy**2) / 2 - y**2
    assert symbolic.lagrangian(L, [x, y], [vx, vy]).cyclic == (0,)
    assert symbolic.lagrangian(L, [x, y], [vx, vy], rayleigh=vx**2 / 2).cyclic == ()
    assert symbolic.lagrangian(L, [x, y], [vx, vy], force=[0, -x]).cyclic == ()
    assert symbolic.lagrangian(L, [x, y], [vx, vy], force=[0, -vy]).cyclic == (0,)
    # ∂L/∂x vanishes only once simplified.
    hidden = L + sp.sin(x) ** 2 * y + sp.cos(x) ** 2 * y
    assert symbolic.lagrangian(hidden, [x, y], [vx, vy]).cyclic == (0,)


def test_separable_needs_constant_mass_no_velocity_terms_and_no_t():
    x, y, vx, vy, t, b = sp.symbols("x y vx vy t b")
    kinetic = (vx**2 + vy**2) / 2
    assert symbolic.lagrangian(kinetic - x**2, [x, y], [vx, vy]).kind_name == "separable"
    # A magnetic field: constant mass, but L is linear in q̇ with q-dependent coefficients.
    magnetic = kinetic + b / 2 * (x * vy - y * vx)
    assert symbolic.lagrangian(magnetic, [x, y], [vx, vy], parameters={b: 1.0}).kind_name == "lagrangian"
    # A constant drift term b·q̇, a total derivative, is still not ½q̇ᵀMq̇ − V.
    assert symbolic.lagrangian(kinetic + b * vx, [x, y], [vx, vy], parameters={b: 1.0}).kind_name == "lagrangian"
    assert symbolic.lagrangian(kinetic - t * x, [x, y], [vx, vy], t=t).kind_name == "lagrangian"
    assert symbolic.lagrangian(kinetic * (1 + x**2), [x, y], [vx, vy]).kind_name == "lagrangian"


def test_dynamicsymbols_give_the_tapes_of_plain_symbols():
    from sympy.physics.mechanics import dynamicsymbols

    q1, q2 = dynamicsymbols("q1 q2")
    t = dynamicsymbols._t
    L = DOUBLE_PENDULUM.subs({V1: q1.diff(t), V2: q2.diff(t)}).subs({Q1: q1, Q2: q2})
    dynamic = symbolic.lagrangian(L, [q1, q2], parameters=DOUBLE_PENDULUM_PARAMETERS)
    assert [str(s) for s in dynamic.v] == ["q1_dot", "q2_dot"] and dynamic.t == t
    dots = sp.symbols("q1_dot q2_dot")
    plain_L = DOUBLE_PENDULUM.subs({V1: dots[0], V2: dots[1]})
    plain = symbolic.lagrangian(plain_L, [Q1, Q2], dots, parameters=DOUBLE_PENDULUM_PARAMETERS)
    assert dynamic.kind_name == plain.kind_name
    for name, (ops, constants, outputs) in plain._core.spec.functions.items():
        other = dynamic._core.spec.functions[name]
        np.testing.assert_array_equal(other[0], ops)
        np.testing.assert_array_equal(other[1], constants)
        np.testing.assert_array_equal(other[2], outputs)
    # A second derivative of a coordinate is refused, naming it.
    with pytest.raises(ValueError, match=r"^L: Derivative\(q1\(t\), \(t, 2\)\)"):
        symbolic.lagrangian(L + q1.diff(t, 2), [q1, q2], parameters=DOUBLE_PENDULUM_PARAMETERS)


def test_lowering_folds_coefficients_and_powers():
    x, y, k = sp.symbols("x y k")

    def ops_of(expr):
        ops, constants, _ = symbolic._lower.lower([expr], {x: 0, y: 1}, {k: 0})
        return [TAPE_OPS[c] for c in ops[:, 0]], constants.tolist(), ops

    assert ops_of(-x)[0] == ["input", "neg"]
    assert ops_of(x - y)[0] == ["input", "input", "sub"]
    assert ops_of(x / y)[0] == ["input", "input", "div"]
    assert ops_of(sp.sqrt(x))[0] == ["input", "sqrt"]
    assert ops_of(1 / sp.sqrt(x))[0] == ["const", "input", "sqrt", "div"]
    assert ops_of(x ** sp.Rational(3, 2))[0] == ["input", "sqrt", "mul"]
    names, constants, ops = ops_of(x**-3)
    assert names == ["input", "powi"] and ops[1, 2] == -3
    names, constants, _ = ops_of(x ** sp.Rational(1, 3))
    assert names == ["input", "const", "pow"] and constants == [1 / 3]
    assert ops_of(x**k)[0] == ["input", "param", "pow"]
    names, constants, _ = ops_of(sp.Rational(2, 3) * x + sp.pi)
    assert names == ["const", "input", "mul", "const", "add"] and constants == [2 / 3, math.pi]
    assert ops_of(sp.atan2(y, x))[0] == ["input", "input", "atan2"]
    # One register for a constant, an input or a parameter used many times.
    names, constants, _ = ops_of(2 * x * k + 2 * sp.sin(x * k) + 2 * y)
    assert names.count("input") == 2 and names.count("param") == 1 and constants == [2.0]


# ------------------------------------------------------------------------ parameters, pickling


def test_with_parameters_shares_the_tapes_and_checks_names_and_values():
    model = double_pendulum()
    longer = model.with_parameters(l2=2.0)
    assert longer.parameters == {"m1": 1.0, "m2": 2.0, "l1": 2.0, "l2": 2.0, "g": 9.80665}
    assert longer._core.spec.functions is model._core.spec.functions
    assert longer.expressions == model.expressions
    np.testing.assert_array_equal(longer._core.spec.parameters, double_pendulum(l2=2.0)._core.spec.parameters)
    with pytest.raises(ValueError, match="^parameters: l3, mass not a parameter"):
        model.with_parameters(l3=1.0, mass=2.0)
    with pytest.raises(ValueError, match="^parameters: g: must be finite"):
        model.with_parameters(g=math.inf)
    with pytest.raises(ValueError, match="^parameters: m1: must be finite"):
        symbolic.lagrangian(DOUBLE_PENDULUM, [Q1, Q2], [V1, V2], parameters=DOUBLE_PENDULUM_PARAMETERS | {M1: math.nan})


def test_parameters_by_name():
    model = symbolic.lagrangian(
        DOUBLE_PENDULUM, [Q1, Q2], [V1, V2], parameters={str(s): x for s, x in DOUBLE_PENDULUM_PARAMETERS.items()}
    )
    for name, tape in double_pendulum()._core.spec.functions.items():
        np.testing.assert_array_equal(model._core.spec.functions[name][0], tape[0])


def test_integrate_refuses_parameters_for_other_models():
    scene = scenes.kepler()
    with pytest.raises(TypeError, match="^parameters: .*only symbolic models"):
        varmech.integrate(scene, dt=scene.dt, steps=1, parameters={"e": 0.5})


def test_pickle_keeps_tapes_and_expressions_and_compiles_again():
    model = double_pendulum().with_parameters(g=1.0)
    copy = pickle.loads(pickle.dumps(model))
    assert isinstance(copy, symbolic.SymbolicModel) and copy._core is not model._core
    assert copy.expressions == model.expressions and copy.parameters == model.parameters
    assert (copy.q, copy.v, copy.kind_name, copy.cyclic, copy.name) == (model.q, model.v, "lagrangian", (), model.name)
    for name, tape in model._core.spec.functions.items():
        for a, b in zip(copy._core.spec.functions[name], tape):
            np.testing.assert_array_equal(a, b)


# ------------------------------------------------------------------------ bad input


def test_a_non_scalar_lagrangian_is_a_type_error_naming_L():
    with pytest.raises(TypeError, match="^L: must be a scalar SymPy expression, got a MutableDenseMatrix"):
        symbolic.lagrangian(sp.Matrix([DOUBLE_PENDULUM, 0]), [Q1, Q2], [V1, V2], parameters=DOUBLE_PENDULUM_PARAMETERS)
    with pytest.raises(TypeError, match="^L: must be a scalar"):
        symbolic.lagrangian([DOUBLE_PENDULUM], [Q1, Q2], [V1, V2], parameters=DOUBLE_PENDULUM_PARAMETERS)


def test_an_undeclared_symbol_is_named():
    parameters = dict(DOUBLE_PENDULUM_PARAMETERS)
    del parameters[L2]
    with pytest.raises(ValueError, match="^L: symbol l2 is neither a coordinate, a velocity, t, nor a parameter"):
        symbolic.lagrangian(DOUBLE_PENDULUM, [Q1, Q2], [V1, V2], parameters=parameters)
    x, v, t = sp.symbols("x v t")
    with pytest.raises(ValueError, match=r"^force\[0\]: symbol t .*pass t="):
        symbolic.lagrangian(v**2 / 2, [x], [v], force=[sp.cos(t)])


def test_constraints_of_the_wrong_number_or_on_velocities_are_refused():
    with pytest.raises(ValueError, match=r"^constraints: need between 1 and 1 constraints .* got 2"):
        symbolic.mechanical(Y, [X, Y], 1, v=[VX, VY], constraints=[X**2 + Y**2 - 1, X - Y])
    with pytest.raises(ValueError, match=r"^constraints: must be a list or a column, got a matrix of shape \(2, 2\)"):
        symbolic.mechanical(Y, [X, Y], 1, v=[VX, VY], constraints=sp.eye(2))
    with pytest.raises(ValueError, match=r"^constraints: v_x\*x \+ v_y\*y depends on v_x, v_y"):
        symbolic.mechanical(Y, [X, Y], 1, v=[VX, VY], constraints=[X * VX + Y * VY])


def test_unsupported_functions_are_named():
    f = sp.Function("f")
    with pytest.raises(ValueError, match=r"^L: f\(q1\) cannot be compiled: unsupported function f"):
        symbolic.lagrangian(DOUBLE_PENDULUM + f(Q1), [Q1, Q2], [V1, V2], parameters=DOUBLE_PENDULUM_PARAMETERS)
    with pytest.raises(ValueError, match=r"^V: .*Piecewise"):
        symbolic.mechanical(sp.Piecewise((X, X > 0), (0, True)), [X, Y], 1, v=[VX, VY])
    with pytest.raises(ValueError, match=r"^L: I cannot be compiled"):
        symbolic.lagrangian(VX**2 / 2 + sp.I * X, [X], [VX])


def test_other_malformed_arguments_are_named():
    with pytest.raises(ValueError, match=r"^force: must have one component per coordinate \(2\), got 1"):
        symbolic.lagrangian((VX**2 + VY**2) / 2, [X, Y], [VX, VY], force=[X])
    with pytest.raises(ValueError, match=r"^v: needs one symbol per coordinate \(2\), got 1"):
        symbolic.lagrangian((VX**2 + VY**2) / 2, [X, Y], [VX])
    with pytest.raises(ValueError, match="^v: give the velocity symbols"):
        symbolic.lagrangian((VX**2 + VY**2) / 2, [X, Y])
    with pytest.raises(TypeError, match="^q: expected SymPy symbols"):
        symbolic.lagrangian(VX**2 / 2, [X + 1], [VX])
    with pytest.raises(ValueError, match=r"^mass: must be a scalar or a 2×2 matrix, got shape \(3, 3\)"):
        symbolic.mechanical(X, [X, Y], sp.eye(3), v=[VX, VY])
    with pytest.raises(ValueError, match="^mass: must be symmetric"):
        symbolic.mechanical(X, [X, Y], [[1, X], [0, 1]], v=[VX, VY])
    with pytest.raises(ValueError, match="^parameters: x is a coordinate"):
        symbolic.lagrangian(VX**2 / 2, [X], [VX], parameters={"x": 1.0})
