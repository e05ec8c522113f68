//! The JIT backend (`model::compiled::Code`) against the interpreter (`Tape::eval`): the same
//! bits for every op, at random and special points, on long tapes, from several threads.

use varmech::model::compiled::{Binary, Code, Op, Tape, Unary};

use crate::common::Points;

impl Points {
    /// A value from a mix of scales: inside (−1, 1) for asin and atanh, moderate, large.
    fn value(&mut self) -> f64 {
        match self.next_u64() % 4 {
            0 => self.uniform(1.0),
            1 => self.uniform(4.0),
            2 => self.uniform(50.0),
            _ => self.uniform(1e-3),
        }
    }
}

/// Values where functions branch: signed zeros, NaN, infinities, ±1, subnormal, huge.
const SPECIAL: [f64; 11] = [
    0.0,
    -0.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1.0,
    -1.0,
    5e-324,
    -1e300,
    0.5,
    -2.5,
];

/// Ops pushed one at a time; each push returns its register.
#[derive(Default)]
struct Builder(Vec<Op>);

impl Builder {
    fn push(&mut self, op: Op) -> u32 {
        self.0.push(op);
        (self.0.len() - 1) as u32
    }
}

/// Asserts that the JIT and the interpreter give the same bits at `(inputs, params)`.
fn assert_agree(tape: &Tape, code: &Code, inputs: &[f64], params: &[f64]) {
    let mut registers = vec![0.0; tape.ops().len()];
    let mut interpreted = vec![0.0; tape.outputs().len()];
    let mut compiled = vec![f64::from_bits(0x7FF4_0000_0000_0001); tape.outputs().len()];
    tape.eval(inputs, params, &mut registers, &mut interpreted);
    code.call(inputs, params, &mut compiled);
    for (j, (a, b)) in interpreted.iter().zip(&compiled).enumerate() {
        assert_eq!(
            a.to_bits(),
            b.to_bits(),
            "output {j} (register {}, {:?}) at inputs {inputs:?}, params {params:?}: interpreter {a:e}, jit {b:e}",
            tape.outputs()[j],
            tape.ops()[tape.outputs()[j] as usize],
        );
    }
}

/// Every unary function of x and of p, every binary one of (x, y) and (y, x), powi of x
/// for exponents of both signs, and sums and products chaining them; every register an output.
fn every_op() -> Tape {
    let mut b = Builder::default();
    let x = b.push(Op::Input(0));
    let y = b.push(Op::Input(1));
    let p = b.push(Op::Param(1));
    let c = b.push(Op::Const(-0.75));
    for f in Unary::ALL {
        for a in [x, p] {
            b.push(Op::Unary(f, a));
        }
    }
    for f in Binary::ALL {
        for (u, v) in [(x, y), (y, x), (x, c), (p, x)] {
            b.push(Op::Binary(f, u, v));
        }
    }
    for n in [-31, -7, -3, -2, -1, 0, 1, 2, 3, 4, 5, 10, 31, i32::MIN, i32::MAX] {
        b.push(Op::Powi(x, n));
    }
    // Chains: results of calls feeding native instructions and back.
    let s = b.push(Op::Unary(Unary::Sin, x));
    let t = b.push(Op::Unary(Unary::Cos, y));
    let st = b.push(Op::Binary(Binary::Mul, s, t));
    let sum = b.push(Op::Binary(Binary::Add, st, p));
    let q = b.push(Op::Powi(sum, -2));
    let e = b.push(Op::Unary(Unary::Exp, q));
    let sg = b.push(Op::Unary(Unary::Sign, st));
    b.push(Op::Binary(Binary::Atan2, e, sg));
    let outputs = (0..b.0.len() as u32).collect();
    Tape::new("tape", b.0, outputs, 2, 2).unwrap()
}

#[test]
fn every_op_agrees_with_the_interpreter_bit_for_bit() {
    let tape = every_op();
    let code = Code::compile(&tape).unwrap();
    // Every pair of special values, x's and y's signed zeros included (sign, atan2's quadrants).
    for &x in &SPECIAL {
        for &y in &SPECIAL {
            assert_agree(&tape, &code, &[x, y], &[0.0, y]);
        }
    }
    // Random points over all four quadrants, longer arrays than the tape reads.
    let mut points = Points(14);
    for _ in 0..20_000 {
        let (x, y, p) = (points.value(), points.value(), points.value());
        assert_agree(&tape, &code, &[x, y, 7.0], &[f64::NAN, p, 3.0]);
    }
}

#[test]
fn a_sine_and_a_cosine_of_one_register_agree_with_the_interpreter_at_every_scale() {
    // One call of libm's sincos where the C library has it (glibc): the bits of its sin and cos
    // at arguments that take each of its reductions (none, the fast one, the Payne–Hanek one
    // past 10⁸), at the special values, and with a sine and cosine of another register beside.
    let mut b = Builder::default();
    let (x, y) = (b.push(Op::Input(0)), b.push(Op::Input(1)));
    let cos = b.push(Op::Unary(Unary::Cos, x));
    let sin = b.push(Op::Unary(Unary::Sin, x));
    let other = b.push(Op::Unary(Unary::Sin, y));
    let sum = b.push(Op::Binary(Binary::Add, sin, other));
    let alone = b.push(Op::Unary(Unary::Cos, y));
    let tape = Tape::new("tape", b.0, vec![cos, sin, sum, alone], 2, 0).unwrap();
    let code = Code::compile(&tape).unwrap();
    for &x in &SPECIAL {
        assert_agree(&tape, &code, &[x, x], &[]);
    }
    let mut points = Points(36);
    for exponent in -320..=300 {
        for _ in 0..40 {
            let x = points.uniform(10f64.powi(exponent));
            assert_agree(&tape, &code, &[x, -x], &[]);
        }
    }
}

#[test]
fn sign_keeps_signed_zeros_and_nan() {
    let mut b = Builder::default();
    let x = b.push(Op::Input(0));
    let s = b.push(Op::Unary(Unary::Sign, x));
    let tape = Tape::new("tape", b.0, vec![s], 1, 0).unwrap();
    let code = Code::compile(&tape).unwrap();
    let sign = |x: f64| {
        let mut out = [0.0];
        code.call(&[x], &[], &mut out);
        out[0]
    };
    assert_eq!(sign(0.0).to_bits(), 0.0f64.to_bits());
    assert_eq!(sign(-0.0).to_bits(), (-0.0f64).to_bits());
    assert_eq!(sign(f64::NAN).to_bits(), f64::NAN.to_bits());
    assert_eq!(sign(-f64::NAN).to_bits(), (-f64::NAN).to_bits());
    assert_eq!(sign(-5e-324), -1.0);
    assert_eq!(sign(f64::INFINITY), 1.0);
}

/// A long random tape: every op, operands drawn among the last few dozen registers.
fn long_tape(length: usize, seed: u64) -> Tape {
    let mut points = Points(seed);
    let mut b = Builder::default();
    for i in 0..3 {
        b.push(Op::Input(i));
    }
    b.push(Op::Param(0));
    while b.0.len() < length {
        let n = b.0.len() as u64;
        let mut earlier = || (n - 1 - points.next_u64() % n.min(40)) as u32;
        let (a, c) = (earlier(), earlier());
        let op = match points.next_u64() % 10 {
            0 => Op::Const(points.uniform(2.0)),
            1 => Op::Unary(Unary::ALL[(points.next_u64() % Unary::ALL.len() as u64) as usize], a),
            2 => Op::Binary(
                Binary::ALL[(points.next_u64() % Binary::ALL.len() as u64) as usize],
                a,
                c,
            ),
            3 => Op::Powi(a, (points.next_u64() % 7) as i32 - 3),
            4 => Op::Input((points.next_u64() % 3) as u32),
            // Mostly arithmetic, as derived expressions are.
            5 | 6 => Op::Binary(Binary::Mul, a, c),
            _ => Op::Binary(Binary::Add, a, c),
        };
        b.push(op);
    }
    let outputs = (0..length as u32).step_by(7).collect();
    Tape::new("tape", b.0, outputs, 3, 1).unwrap()
}

#[test]
fn a_tape_of_thousands_of_instructions_compiles_and_agrees() {
    let tape = long_tape(5_000, 3);
    let code = Code::compile(&tape).unwrap();
    let mut points = Points(5);
    for _ in 0..200 {
        let inputs = [points.value(), points.value(), points.value()];
        assert_agree(&tape, &code, &inputs, &[points.value()]);
    }
}

#[test]
fn a_frame_of_many_pages_compiles_and_agrees() {
    // Every sine stays live across the later calls to its sum at the end: 3000 spills.
    let mut b = Builder::default();
    let x = b.push(Op::Input(0));
    let sines: Vec<u32> = (0..3000)
        .map(|k| {
            let c = b.push(Op::Const(1.0 + k as f64 / 1000.0));
            let a = b.push(Op::Binary(Binary::Mul, x, c));
            b.push(Op::Unary(Unary::Sin, a))
        })
        .collect();
    let mut sum = sines[0];
    for &s in sines.iter().rev() {
        sum = b.push(Op::Binary(Binary::Add, sum, s));
    }
    let tape = Tape::new("tape", b.0, vec![sum], 1, 0).unwrap();
    let code = Code::compile(&tape).unwrap();
    let mut points = Points(8);
    for _ in 0..100 {
        assert_agree(&tape, &code, &[points.value()], &[]);
    }
}

#[test]
fn code_moved_to_another_thread_runs_and_is_freed_there() {
    let tape = long_tape(300, 2);
    let code = Code::compile(&tape).unwrap();
    let inputs = [0.25, -1.5, 3.0];
    std::thread::spawn(move || assert_agree(&tape, &code, &inputs, &[0.5]))
        .join()
        .unwrap();
}

#[test]
fn threads_calling_one_code_at_once_agree() {
    let tape = long_tape(600, 11);
    let code = Code::compile(&tape).unwrap();
    std::thread::scope(|scope| {
        for thread in 0..4 {
            let (tape, code) = (&tape, &code);
            scope.spawn(move || {
                let mut points = Points(100 + thread);
                for _ in 0..2_000 {
                    let inputs = [points.value(), points.value(), points.value()];
                    assert_agree(tape, code, &inputs, &[points.value()]);
                }
            });
        }
    });
}

#[test]
fn outputs_may_repeat_and_come_in_any_order() {
    let mut b = Builder::default();
    let x = b.push(Op::Input(1));
    let p = b.push(Op::Param(0));
    let d = b.push(Op::Binary(Binary::Sub, x, p));
    let tape = Tape::new("tape", b.0, vec![d, x, d, p], 2, 1).unwrap();
    let code = Code::compile(&tape).unwrap();
    let mut out = [0.0; 5];
    code.call(&[9.0, 3.0], &[0.5], &mut out);
    assert_eq!(out, [2.5, 3.0, 2.5, 0.5, 0.0]);
}

#[test]
fn an_empty_tape_compiles() {
    let tape = Tape::new("tape", vec![], vec![], 0, 0).unwrap();
    Code::compile(&tape).unwrap().call(&[], &[], &mut []);
}

#[test]
#[should_panic(expected = "called with")]
fn a_short_output_array_is_refused() {
    let tape = Tape::new("tape", vec![Op::Const(1.0)], vec![0, 0], 0, 0).unwrap();
    Code::compile(&tape).unwrap().call(&[], &[], &mut [0.0]);
}
