//! Compiled models: tapes run as the hand-written scenes they transcribe.

use varmech::integrators::{integrate, General, Method, Options, Trajectory};
use varmech::model::compiled::{sign, Binary, CompiledSeparable, Op, Tape, Unary};

use crate::common::tapes::{kepler, pendulum_lagrangian, Builder};
use varmech::scenes::{Kepler, Pendulum};

fn options(dt: f64, steps: usize) -> Options {
    Options {
        save_every: 10,
        ..Options::new(dt, steps)
    }
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn a_kepler_tape_runs_bit_for_bit_as_the_native_scene() {
    let problem = Kepler::problem(0.6).unwrap();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let cases = [Method::Verlet, Method::KahanLi8, Method::Midpoint].map(|m| [(m, false), (m, true)]);
    for (method, jit) in cases.into_iter().flatten() {
        let o = options(2.0 * std::f64::consts::PI / 200.0, 1000);
        let native = integrate(&problem.system, method, q0, p0, &o, || Ok(()))
            .map_err(|f| f.error)
            .unwrap();
        let compiled = integrate(&kepler(1.0, jit), method, q0, p0, &o, || Ok(()))
            .map_err(|f| f.error)
            .unwrap();
        let what = format!("{method:?}, jit {jit}");
        assert!(
            same_bits(&native.q, &compiled.q) && same_bits(&native.p, &compiled.p),
            "{what}"
        );
        assert_eq!(native.newton_iterations, compiled.newton_iterations, "{what}");
    }
}

#[test]
fn a_parameter_rescales_time_exactly() {
    let problem = Kepler::problem(0.6).unwrap();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let dt = 2.0 * std::f64::consts::PI / 200.0;
    let one = kepler(1.0, true);
    let four = one.with_parameters(&[4.0]).unwrap();
    let p0_four: Vec<f64> = p0.iter().map(|p| 2.0 * p).collect();
    for method in [Method::Verlet, Method::KahanLi6] {
        let run = |sys: &CompiledSeparable, p0: &[f64], dt: f64| -> Trajectory {
            integrate(sys, method, q0, p0, &options(dt, 1000), || Ok(()))
                .map_err(|f| f.error)
                .unwrap()
        };
        let (a, b) = (run(&one, p0, dt), run(&four, &p0_four, 0.5 * dt));
        let doubled: Vec<f64> = a.p.iter().map(|p| 2.0 * p).collect();
        assert!(same_bits(&a.q, &b.q) && same_bits(&doubled, &b.p), "{method:?}");
    }
    assert!(one.with_parameters(&[f64::NAN]).is_err());
    assert!(one.with_parameters(&[1.0, 2.0]).is_err());
}

#[test]
fn a_compiled_lagrangian_follows_the_native_pendulum() {
    let problem = Pendulum::problem();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let sys = pendulum_lagrangian();
    for method in [Method::Midpoint, Method::Galerkin4] {
        let o = options(0.05, 1000);
        let native = integrate(&General(&problem.system), method, q0, p0, &o, || Ok(()))
            .map_err(|f| f.error)
            .unwrap();
        let compiled = integrate(&General(&sys), method, q0, p0, &o, || Ok(()))
            .map_err(|f| f.error)
            .unwrap();
        let gap = native
            .q
            .iter()
            .chain(&native.p)
            .zip(compiled.q.iter().chain(&compiled.p));
        let gap = gap.map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(gap <= 1e-12, "{method:?}: {gap:.3e}");
    }
}

#[test]
fn a_tape_says_which_outputs_read_which_slots() {
    // Outputs [sin q₀ · q̇₁, 2·q̇₁, t] of the slots [q₀, q₁, q̇₀, q̇₁, t]: what the delayed forces
    // ask of their function (whether a term reads the state now).
    let mut b = Builder::default();
    let (q0, v1, t) = (b.input(0), b.input(3), b.input(4));
    let s = b.unary(Unary::Sin, q0);
    let product = b.binary(Binary::Mul, s, v1);
    let two = b.op(Op::Const(2.0));
    let double = b.binary(Binary::Mul, two, v1);
    let tape = b.tape(vec![product, double, t], 2, 0);
    assert!(tape.reads(0..1, |slot| slot == 0) && !tape.reads(1..3, |slot| slot == 0));
    assert!(tape.reads(1..2, |slot| slot == 3) && !tape.reads(2..3, |slot| slot < 4));
    assert!(!tape.reads(0..3, |slot| slot == 1 || slot == 2));
}

#[test]
fn a_tape_of_zeros_is_zero_and_no_other_is() {
    // A model forced by its delayed terms alone has Q = 0: its tape is not evaluated. Only +0
    // counts (−0 + x is not 0 + x for x = −0), and only a constant (0·q is NaN for q = ∞).
    let zeros = |outputs: &dyn Fn(&mut Builder) -> Vec<u32>| {
        let mut b = Builder::default();
        let outputs = outputs(&mut b);
        b.tape(outputs, 1, 0).is_zero()
    };
    assert!(zeros(&|b| {
        let z = b.op(Op::Const(0.0));
        vec![z, z]
    }));
    assert!(!zeros(&|b| vec![b.op(Op::Const(-0.0))]));
    assert!(!zeros(&|b| vec![b.op(Op::Const(1e-300))]));
    assert!(!zeros(&|b| {
        let (z, q0) = (b.op(Op::Const(0.0)), b.input(0));
        vec![b.binary(Binary::Mul, z, q0)]
    }));
}

#[test]
fn a_restricted_tape_keeps_its_outputs_instructions_and_their_bits() {
    // [sin q₀ · q̇₀, cos t · q₀] restricted to its first output: cos t and its product go, and
    // what stays computes the same bits, interpreted and compiled (the gradients without ∂L/∂t).
    let mut b = Builder::default();
    let (q0, v0, t) = (b.input(0), b.input(1), b.input(2));
    let s = b.unary(Unary::Sin, q0);
    let product = b.binary(Binary::Mul, s, v0);
    let c = b.unary(Unary::Cos, t);
    let late = b.binary(Binary::Mul, c, q0);
    let tape = b.tape(vec![product, late], 1, 0);
    let first = tape.restricted(0..1);
    assert_eq!((first.ops().len(), first.outputs().len()), (4, 1), "{:?}", first.ops());
    assert!(!first.reads(0..1, |slot| slot == 2));
    let (mut all, mut alone) = ([0.0; 2], [0.0; 1]);
    let inputs = [0.7, -1.3, 2.5];
    tape.eval(&inputs, &[], &mut [0.0; 8], &mut all);
    first.eval(&inputs, &[], &mut [0.0; 8], &mut alone);
    assert_eq!(all[0].to_bits(), alone[0].to_bits());
    let second = tape.restricted(1..2);
    assert_eq!(second.ops().len(), 4, "{:?}", second.ops());
    second.eval(&inputs, &[], &mut [0.0; 8], &mut alone);
    assert_eq!(all[1].to_bits(), alone[0].to_bits());
    let compiled = varmech::model::compiled::Function::compiled(tape).restricted(0..1);
    compiled.eval(&inputs[..1], &inputs[1..2], inputs[2], &[], &mut alone);
    assert_eq!(all[0].to_bits(), alone[0].to_bits());
}

#[test]
fn malformed_tapes_are_refused_with_their_name() {
    let later = Tape::new("gradient", vec![Op::Unary(Unary::Sin, 0)], vec![0], 3, 0);
    assert!(later.unwrap_err().to_string().starts_with("gradient: instruction 0"));
    let slot = Tape::new("f", vec![Op::Input(3)], vec![0], 3, 0);
    assert!(slot.is_err());
    let param = Tape::new("f", vec![Op::Param(0)], vec![0], 3, 0);
    assert!(param.is_err());
    let output = Tape::new("f", vec![Op::Input(0)], vec![1], 3, 0);
    assert!(output.unwrap_err().to_string().contains("output register 1"));
    let constant = Tape::new("f", vec![Op::Const(f64::INFINITY)], vec![0], 3, 0);
    assert!(constant.is_err());
    let code = Tape::decode("hessians", &[[99, 0, 0]], &[], &[0], 3, 0);
    assert!(code.unwrap_err().to_string().contains("unknown op code 99"));
    let index = Tape::decode("f", &[[0, 5, 0]], &[1.0], &[0], 3, 0);
    assert!(index.unwrap_err().to_string().contains("constant index"));

    // A separable system's potential may not read q̇, nor its mass q.
    let mut b = Builder::default();
    let v = b.input(1);
    let potential = b.function(vec![v], 1, 0);
    let mut b = Builder::default();
    let q = b.input(0);
    let gradient = b.function(vec![q], 1, 0);
    let mut b = Builder::default();
    let one = b.op(Op::Const(1.0));
    let mass = b.function(vec![one], 1, 0);
    let err = CompiledSeparable::new(1, vec![], potential, gradient.clone(), mass.clone()).unwrap_err();
    assert!(
        err.to_string().starts_with("potential: must depend on the positions"),
        "{err}"
    );
    let err = CompiledSeparable::new(1, vec![], gradient.clone(), gradient.clone(), gradient.clone()).unwrap_err();
    assert!(err.to_string().starts_with("mass: must be constant"), "{err}");
    let mut b = Builder::default();
    let neg = b.op(Op::Const(-1.0));
    let negative = b.function(vec![neg], 1, 0);
    assert!(CompiledSeparable::new(1, vec![], gradient.clone(), gradient, negative).is_err());
}

#[test]
fn the_interpreter_applies_rusts_f64_functions() {
    assert_eq!(sign(-0.0).to_bits(), (-0.0f64).to_bits());
    assert_eq!((sign(3.0), sign(-2.0)), (1.0, -1.0));
    assert!(sign(f64::NAN).is_nan());
    let mut b = Builder::default();
    let x = b.input(0);
    let cube = b.op(Op::Powi(x, -3));
    let y = b.input(1);
    let angle = b.binary(Binary::Atan2, y, x);
    let p = b.binary(Binary::Pow, x, y);
    let f = b.function(vec![cube, angle, p], 1, 0);
    let mut out = [0.0; 3];
    f.eval(&[-2.0], &[0.5], 0.0, &[], &mut out);
    assert_eq!(out[0], (-2.0f64).powi(-3));
    assert_eq!(out[1], 0.5f64.atan2(-2.0));
    assert!(out[2].is_nan()); // a negative base to a fractional power
}
