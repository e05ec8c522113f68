//! The instruction tape: a function of (q, q̇, t) and the parameters as straight-line SSA code.

use crate::Error;

/// A function of one argument, applied as Rust's `f64` method of the same name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unary {
    Neg,
    Sqrt,
    Exp,
    Log,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Asinh,
    Acosh,
    Atanh,
    Abs,
    /// +1, −1 or 0 by the sign of x (SymPy's `sign`); NaN stays NaN.
    Sign,
}

/// A function of two arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binary {
    Add,
    Sub,
    Mul,
    Div,
    /// a^b, `f64::powf`.
    Pow,
    /// atan2(a, b), the angle of the point (x, y) = (b, a).
    Atan2,
}

/// One instruction; instruction i defines register i, and its operands are earlier registers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    Const(f64),
    /// Input slot: qᵢ at i, q̇ᵢ at n + i, t at 2n.
    Input(u32),
    /// Parameter index.
    Param(u32),
    Unary(Unary, u32),
    Binary(Binary, u32, u32),
    /// aⁿ for an integer n, `f64::powi`.
    Powi(u32, i32),
}

impl Unary {
    /// Every unary function, in the order of their codes (see [`Tape::OPS`]).
    pub const ALL: [Unary; 18] = [
        Unary::Neg,
        Unary::Sqrt,
        Unary::Exp,
        Unary::Log,
        Unary::Sin,
        Unary::Cos,
        Unary::Tan,
        Unary::Asin,
        Unary::Acos,
        Unary::Atan,
        Unary::Sinh,
        Unary::Cosh,
        Unary::Tanh,
        Unary::Asinh,
        Unary::Acosh,
        Unary::Atanh,
        Unary::Abs,
        Unary::Sign,
    ];

    /// f(x).
    #[inline]
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Unary::Neg => -x,
            Unary::Sqrt => x.sqrt(),
            Unary::Exp => x.exp(),
            Unary::Log => x.ln(),
            Unary::Sin => x.sin(),
            Unary::Cos => x.cos(),
            Unary::Tan => x.tan(),
            Unary::Asin => x.asin(),
            Unary::Acos => x.acos(),
            Unary::Atan => x.atan(),
            Unary::Sinh => x.sinh(),
            Unary::Cosh => x.cosh(),
            Unary::Tanh => x.tanh(),
            Unary::Asinh => x.asinh(),
            Unary::Acosh => x.acosh(),
            Unary::Atanh => x.atanh(),
            Unary::Abs => x.abs(),
            Unary::Sign => sign(x),
        }
    }
}

/// +1, −1 or 0 by the sign of x; NaN stays NaN.
#[inline]
pub fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        x
    }
}

impl Binary {
    /// Every binary function, in the order of their codes (see [`Tape::OPS`]).
    pub const ALL: [Binary; 6] = [
        Binary::Add,
        Binary::Sub,
        Binary::Mul,
        Binary::Div,
        Binary::Pow,
        Binary::Atan2,
    ];

    /// f(a, b).
    #[inline]
    pub fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Binary::Add => a + b,
            Binary::Sub => a - b,
            Binary::Mul => a * b,
            Binary::Div => a / b,
            Binary::Pow => a.powf(b),
            Binary::Atan2 => a.atan2(b),
        }
    }
}

/// A function ℝ^inputs × ℝ^params → ℝ^outputs as straight-line code: instruction i computes
/// register i from constants, inputs, parameters and earlier registers, and the outputs are
/// registers. Checked when it is built, so that evaluating it cannot index out of bounds.
#[derive(Clone, Debug, PartialEq)]
pub struct Tape {
    ops: Vec<Op>,
    outputs: Vec<u32>,
    inputs: usize,
    params: usize,
}

impl Tape {
    /// The names of the ops by code, as the binding encodes them: const, input, param, the
    /// unary functions ([`Unary::ALL`]), the binary ones ([`Binary::ALL`]) and powi.
    pub const OPS: [&'static str; 28] = [
        "const", "input", "param", "neg", "sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos", "atan", "sinh",
        "cosh", "tanh", "asinh", "acosh", "atanh", "abs", "sign", "add", "sub", "mul", "div", "pow", "atan2", "powi",
    ];

    /// A tape of `ops` with `outputs`, over `inputs` input slots and `params` parameters.
    /// Refuses (naming `argument`) an operand that is not an earlier register, an input slot
    /// or parameter index out of range, an output that is not a register, and a constant that
    /// is not finite.
    pub fn new(
        argument: &'static str,
        ops: Vec<Op>,
        outputs: Vec<u32>,
        inputs: usize,
        params: usize,
    ) -> Result<Self, Error> {
        let bad = |reason: String| Err(Error::invalid(argument, reason));
        for (i, op) in ops.iter().enumerate() {
            let earlier = |r: u32| (r as usize) < i;
            let ok = match *op {
                Op::Const(c) => c.is_finite(),
                Op::Input(s) => (s as usize) < inputs,
                Op::Param(k) => (k as usize) < params,
                Op::Unary(_, a) | Op::Powi(a, _) => earlier(a),
                Op::Binary(_, a, b) => earlier(a) && earlier(b),
            };
            if !ok {
                return bad(format!(
                    "instruction {i} ({op:?}) refers to a later register, an input or parameter out of range \
                     ({inputs} inputs, {params} parameters), or a constant that is not finite"
                ));
            }
        }
        if let Some(o) = outputs.iter().find(|&&o| o as usize >= ops.len()) {
            return bad(format!("output register {o} is beyond the {} instructions", ops.len()));
        }
        Ok(Tape {
            ops,
            outputs,
            inputs,
            params,
        })
    }

    /// The tape of the binding's encoding: rows (code, a, b) with codes indexing [`Tape::OPS`],
    /// a constant's a indexing `constants`, powi's b the integer exponent.
    pub fn decode(
        argument: &'static str,
        rows: &[[i64; 3]],
        constants: &[f64],
        outputs: &[i64],
        inputs: usize,
        params: usize,
    ) -> Result<Self, Error> {
        let bad = |i: usize, what: &str| Error::invalid(argument, format!("instruction {i}: {what}"));
        let index = |i: usize, x: i64| u32::try_from(x).map_err(|_| bad(i, "operand out of range"));
        let mut ops = Vec::with_capacity(rows.len());
        for (i, &[code, a, b]) in rows.iter().enumerate() {
            let unary = Unary::ALL.len() as i64;
            let binary = Binary::ALL.len() as i64;
            let op = match code {
                0 => {
                    let c = usize::try_from(a).ok().and_then(|a| constants.get(a));
                    Op::Const(*c.ok_or_else(|| bad(i, "constant index out of range"))?)
                }
                1 => Op::Input(index(i, a)?),
                2 => Op::Param(index(i, a)?),
                c if (3..3 + unary).contains(&c) => Op::Unary(Unary::ALL[(c - 3) as usize], index(i, a)?),
                c if (3 + unary..3 + unary + binary).contains(&c) => {
                    Op::Binary(Binary::ALL[(c - 3 - unary) as usize], index(i, a)?, index(i, b)?)
                }
                27 => Op::Powi(
                    index(i, a)?,
                    i32::try_from(b).map_err(|_| bad(i, "powi exponent out of range"))?,
                ),
                _ => return Err(bad(i, &format!("unknown op code {code}"))),
            };
            ops.push(op);
        }
        let outputs = outputs
            .iter()
            .map(|&o| {
                u32::try_from(o).map_err(|_| Error::invalid(argument, format!("output register {o} out of range")))
            })
            .collect::<Result<_, _>>()?;
        Tape::new(argument, ops, outputs, inputs, params)
    }

    pub fn ops(&self) -> &[Op] {
        &self.ops
    }

    /// The registers that are the outputs, in order.
    pub fn outputs(&self) -> &[u32] {
        &self.outputs
    }

    /// Number of input slots.
    pub fn inputs(&self) -> usize {
        self.inputs
    }

    /// Number of parameters.
    pub fn params(&self) -> usize {
        self.params
    }

    /// The highest input slot read, plus one (0 for a tape that reads none).
    pub fn slots_read(&self) -> usize {
        self.ops
            .iter()
            .map(|op| match *op {
                Op::Input(s) => s as usize + 1,
                _ => 0,
            })
            .max()
            .unwrap_or(0)
    }

    /// Whether every output is the constant +0 (not −0, which sums to other bits).
    pub fn is_zero(&self) -> bool {
        self.outputs
            .iter()
            .all(|&r| matches!(self.ops[r as usize], Op::Const(c) if c.to_bits() == 0))
    }

    /// Whether any of the outputs `outputs` reads an input slot for which `slot` is true,
    /// directly or through earlier registers.
    pub fn reads(&self, outputs: std::ops::Range<usize>, slot: impl Fn(usize) -> bool) -> bool {
        let mut reads = vec![false; self.ops.len()];
        for i in 0..self.ops.len() {
            reads[i] = match self.ops[i] {
                Op::Input(s) => slot(s as usize),
                Op::Const(_) | Op::Param(_) => false,
                Op::Unary(_, a) | Op::Powi(a, _) => reads[a as usize],
                Op::Binary(_, a, b) => reads[a as usize] || reads[b as usize],
            };
        }
        self.outputs[outputs].iter().any(|&r| reads[r as usize])
    }

    /// The tape of the outputs `outputs` alone: the instructions they do not read left out,
    /// the others in their order (so the same arithmetic, to the bit).
    pub fn restricted(&self, outputs: std::ops::Range<usize>) -> Tape {
        let outputs = &self.outputs[outputs];
        let mut live = vec![false; self.ops.len()];
        outputs.iter().for_each(|&o| live[o as usize] = true);
        for i in (0..self.ops.len()).rev() {
            if !live[i] {
                continue;
            }
            match self.ops[i] {
                Op::Unary(_, a) | Op::Powi(a, _) => live[a as usize] = true,
                Op::Binary(_, a, b) => (live[a as usize], live[b as usize]) = (true, true),
                Op::Const(_) | Op::Input(_) | Op::Param(_) => {}
            }
        }
        let mut register = vec![0; self.ops.len()];
        let mut ops = Vec::new();
        for (i, op) in self.ops.iter().enumerate().filter(|&(i, _)| live[i]) {
            let r = |a: u32| register[a as usize];
            let op = match *op {
                Op::Unary(f, a) => Op::Unary(f, r(a)),
                Op::Powi(a, n) => Op::Powi(r(a), n),
                Op::Binary(f, a, b) => Op::Binary(f, r(a), r(b)),
                op => op,
            };
            register[i] = ops.len() as u32;
            ops.push(op);
        }
        Tape {
            ops,
            outputs: outputs.iter().map(|&o| register[o as usize]).collect(),
            inputs: self.inputs,
            params: self.params,
        }
    }

    /// Runs the tape: registers in `regs` (at least as many as instructions), outputs into
    /// `out` (as many as outputs). `inputs` and `params` have the tape's lengths.
    pub fn eval(&self, inputs: &[f64], params: &[f64], regs: &mut [f64], out: &mut [f64]) {
        let (inputs, params) = (&inputs[..self.inputs], &params[..self.params]);
        let regs = &mut regs[..self.ops.len()];
        for i in 0..regs.len() {
            // Operands were checked to be earlier registers, inputs and parameters in range.
            regs[i] = match self.ops[i] {
                Op::Const(c) => c,
                Op::Input(s) => inputs[s as usize],
                Op::Param(k) => params[k as usize],
                Op::Unary(f, a) => f.apply(regs[a as usize]),
                Op::Binary(f, a, b) => f.apply(regs[a as usize], regs[b as usize]),
                Op::Powi(a, n) => regs[a as usize].powi(n),
            };
        }
        for (o, &r) in out.iter_mut().zip(&self.outputs) {
            *o = regs[r as usize];
        }
    }
}
