//! Compiled models written by hand as tapes, shared by the compiled-model and allocation tests.

use varmech::model::compiled::{Binary, CompiledLagrangian, CompiledSeparable, Function, Op, Tape, Unary};

/// Straight-line code written by hand: each method appends an instruction and returns its
/// register.
#[derive(Default)]
pub struct Builder {
    ops: Vec<Op>,
}

impl Builder {
    pub fn op(&mut self, op: Op) -> u32 {
        self.ops.push(op);
        self.ops.len() as u32 - 1
    }
    pub fn input(&mut self, slot: u32) -> u32 {
        self.op(Op::Input(slot))
    }
    pub fn binary(&mut self, f: Binary, a: u32, b: u32) -> u32 {
        self.op(Op::Binary(f, a, b))
    }
    pub fn unary(&mut self, f: Unary, a: u32) -> u32 {
        self.op(Op::Unary(f, a))
    }
    pub fn function(self, outputs: Vec<u32>, n: usize, params: usize) -> Function {
        Function::new(self.tape(outputs, n, params))
    }
    /// The function compiled to machine code (interpreted without the `jit` feature).
    pub fn compiled(self, outputs: Vec<u32>, n: usize, params: usize) -> Function {
        let f = Function::compiled(self.tape(outputs, n, params));
        assert_eq!(f.is_compiled(), cfg!(feature = "jit"));
        f
    }
    pub fn tape(self, outputs: Vec<u32>, n: usize, params: usize) -> Tape {
        Tape::new("test", self.ops, outputs, 2 * n + 1, params).unwrap()
    }
}

/// Kepler's V = −μ/r and ∇V = μq/r³ with the native scene's operations in its order (r² =
/// x² + y², μ/(r²·√r²)), μ a parameter, and M = 1; run by machine code when `jit` holds.
pub fn kepler(mu: f64, jit: bool) -> CompiledSeparable {
    let finish = |b: Builder, outputs, n, params| {
        if jit {
            b.compiled(outputs, n, params)
        } else {
            b.function(outputs, n, params)
        }
    };
    // Both tapes start alike: a builder with x, y, μ, r² and √r².
    let start = || {
        let mut b = Builder::default();
        let (x, y, m) = (b.input(0), b.input(1), b.op(Op::Param(0)));
        let (xx, yy) = (b.binary(Binary::Mul, x, x), b.binary(Binary::Mul, y, y));
        let r2 = b.binary(Binary::Add, xx, yy);
        let s = b.unary(Unary::Sqrt, r2);
        (b, [x, y, m, r2, s])
    };
    let (mut b, [x, y, m, r2, s]) = start();
    let d = b.binary(Binary::Mul, r2, s);
    let k = b.binary(Binary::Div, m, d);
    let (gx, gy) = (b.binary(Binary::Mul, k, x), b.binary(Binary::Mul, k, y));
    let gradient = finish(b, vec![gx, gy], 2, 1);

    let (mut b, [_, _, m, _, s]) = start();
    let v = b.binary(Binary::Div, m, s);
    let v = b.unary(Unary::Neg, v);
    let potential = finish(b, vec![v], 2, 1);

    let mut b = Builder::default();
    let one = b.op(Op::Const(1.0));
    let mass = b.function(vec![one], 2, 1);
    CompiledSeparable::new(2, vec![mu], potential, gradient, mass).unwrap()
}

/// The pendulum as a general Lagrangian L = ½q̇² + cos q, with exact derivatives and Hessians.
pub fn pendulum_lagrangian() -> CompiledLagrangian {
    let n = 1;
    let mut b = Builder::default();
    let (q, v) = (b.input(0), b.input(1));
    let vv = b.binary(Binary::Mul, v, v);
    let half = b.op(Op::Const(0.5));
    let t = b.binary(Binary::Mul, half, vv);
    let c = b.unary(Unary::Cos, q);
    let l = b.binary(Binary::Add, t, c);
    let lagrangian = b.function(vec![l], n, 0);

    let mut b = Builder::default();
    let (q, v) = (b.input(0), b.input(1));
    let s = b.unary(Unary::Sin, q);
    let dq = b.unary(Unary::Neg, s);
    let gradients = b.function(vec![dq, v], n, 0);

    let mut b = Builder::default();
    let q = b.input(0);
    let c = b.unary(Unary::Cos, q);
    let qq = b.unary(Unary::Neg, c);
    let (zero, one) = (b.op(Op::Const(0.0)), b.op(Op::Const(1.0)));
    let hessians = b.function(vec![qq, zero, one], n, 0);
    CompiledLagrangian::new(
        n,
        vec![],
        lagrangian,
        gradients,
        hessians,
        None,
        (None, false),
        None,
        (None, None),
    )
    .unwrap()
}
