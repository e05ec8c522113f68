//! One model function: a tape, run by its machine code where it was compiled and by the
//! interpreter otherwise.

use std::cell::RefCell;
use std::sync::Arc;

use super::Tape;
use crate::Error;

/// A model function y = f(q, q̇, t; parameters) of a compiled model, its inputs in the slots
/// [q, q̇, t], run by its machine code where it was compiled ([`Function::compiled`]) and by
/// the tape's interpreter otherwise. Cloning shares the tape and its code.
#[derive(Clone, Debug)]
pub struct Function {
    tape: Arc<Tape>,
    #[cfg(feature = "jit")]
    code: Option<Arc<super::Code>>,
}

thread_local! {
    /// The interpreter's registers and the input slots: grown on a thread's first evaluation
    /// of the largest tape, then reused, so that evaluations allocate nothing.
    static SCRATCH: RefCell<(Vec<f64>, Vec<f64>)> = const { RefCell::new((Vec::new(), Vec::new())) };
    /// Outputs on their way to a caller's layout (matrices, split vectors).
    static OUT: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

impl Function {
    /// The function of `tape`, interpreted.
    pub fn new(tape: Tape) -> Self {
        Function {
            tape: Arc::new(tape),
            #[cfg(feature = "jit")]
            code: None,
        }
    }

    /// The function of `tape`, compiled to machine code where the crate has its `jit` feature
    /// and Cranelift a backend for the host; interpreted otherwise (the fallback, which
    /// [`Function::is_compiled`] tells).
    pub fn compiled(tape: Tape) -> Self {
        #[cfg(feature = "jit")]
        if let Ok(code) = super::Code::compile(&tape) {
            return Function {
                tape: Arc::new(tape),
                code: Some(Arc::new(code)),
            };
        }
        Self::new(tape)
    }

    /// The function of its outputs `outputs` alone ([`Tape::restricted`]), compiled where this
    /// one is.
    pub fn restricted(&self, outputs: std::ops::Range<usize>) -> Self {
        let tape = self.tape.restricted(outputs);
        if self.is_compiled() {
            Self::compiled(tape)
        } else {
            Self::new(tape)
        }
    }

    /// Whether machine code runs this function.
    pub fn is_compiled(&self) -> bool {
        #[cfg(feature = "jit")]
        return self.code.is_some();
        #[cfg(not(feature = "jit"))]
        false
    }

    pub fn tape(&self) -> &Tape {
        &self.tape
    }

    /// Number of outputs.
    pub fn outputs(&self) -> usize {
        self.tape.outputs().len()
    }

    /// f(q, q̇, t; params) into `out`; `v` may be empty for a function of q alone, whose slots
    /// for q̇ and t it does not read.
    pub fn eval(&self, q: &[f64], v: &[f64], t: f64, params: &[f64], out: &mut [f64]) {
        SCRATCH.with(|scratch| {
            let (slots, regs) = &mut *scratch.borrow_mut();
            let n = q.len();
            // Grown, never shrunk: functions of other sizes share the slots, and a resize
            // each call would clear them again (a memset an evaluation). The tape reads its own.
            let needed = self.tape.inputs().max(2 * n + 1);
            if slots.len() < needed {
                slots.resize(needed, 0.0);
            }
            crate::solve::copy(&mut slots[..n], q);
            crate::solve::copy(&mut slots[n..n + v.len()], v);
            slots[2 * n] = t;
            #[cfg(feature = "jit")]
            if let Some(code) = &self.code {
                return code.call(slots, params, out);
            }
            self.interpret(slots, params, regs, out);
        })
    }

    /// The tape's interpreter, its registers `regs` grown to its length.
    fn interpret(&self, slots: &[f64], params: &[f64], regs: &mut Vec<f64>, out: &mut [f64]) {
        if regs.len() < self.tape.ops().len() {
            regs.resize(self.tape.ops().len(), 0.0);
        }
        self.tape.eval(slots, params, regs, out);
    }

    /// f of the slots `slots` as the tape reads them (its inputs, in their order), into `out`:
    /// for a caller that keeps its arguments laid out so, no copy.
    pub fn eval_slots(&self, slots: &[f64], params: &[f64], out: &mut [f64]) {
        #[cfg(feature = "jit")]
        if let Some(code) = &self.code {
            return code.call(slots, params, out);
        }
        SCRATCH.with(|scratch| self.interpret(slots, params, &mut scratch.borrow_mut().1, out))
    }

    /// f(q, q̇, t; params), its outputs handed to `scatter` (which must not evaluate another
    /// function through this method).
    pub fn eval_into<R>(&self, q: &[f64], v: &[f64], t: f64, params: &[f64], scatter: impl FnOnce(&[f64]) -> R) -> R {
        OUT.with(|out| {
            let out = &mut *out.borrow_mut();
            out.resize(self.outputs(), 0.0);
            self.eval(q, v, t, params, out);
            scatter(out)
        })
    }
}

/// Copies row-major `values` into the matrix `m`.
pub fn rows_into(values: &[f64], m: &mut nalgebra::DMatrix<f64>) {
    let cols = m.ncols();
    for (i, row) in values.chunks_exact(cols).enumerate() {
        for (j, x) in row.iter().enumerate() {
            m[(i, j)] = *x;
        }
    }
}

/// What a function may read: all the slots [q, q̇, t], q alone, or the delayed forces' slots
/// [q, q̇, q̈, t] (n of each, n = m of [`crate::model::delayed_block`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inputs {
    All,
    Positions,
    Delayed,
}

/// Refuses, naming the function, one with other than `outputs` outputs, slots other than
/// those of `inputs` for n coordinates, reads beyond them, or other than the model's parameters
/// (checked once per model by [`check_parameters`]).
pub(super) fn check(
    name: &'static str,
    f: &Function,
    outputs: usize,
    n: usize,
    inputs: Inputs,
    params: &[f64],
) -> Result<(), Error> {
    let tape = f.tape();
    if f.outputs() != outputs {
        return Err(Error::invalid(
            name,
            format!("has {} outputs where {outputs} are needed for n = {n}", f.outputs()),
        ));
    }
    let (slots, layout) = match inputs {
        Inputs::Delayed => (3 * n + 1, "[q, q̇, q̈, t]"),
        _ => (2 * n + 1, "[q, q̇, t]"),
    };
    if tape.inputs() != slots || tape.params() != params.len() {
        return Err(Error::invalid(
            name,
            format!(
                "takes {} inputs and {} parameters where the model has {slots} ({layout}) and {}",
                tape.inputs(),
                tape.params(),
                params.len()
            ),
        ));
    }
    if inputs == Inputs::Positions && tape.slots_read() > n {
        return Err(Error::invalid(name, "must depend on the positions q alone"));
    }
    Ok(())
}

/// Refuses a parameter vector of other than `count` values, or with one not finite.
pub(super) fn check_parameters(params: &[f64], count: usize) -> Result<(), Error> {
    if params.len() != count {
        return Err(Error::invalid(
            "parameters",
            format!("has {} values where the model has {count} parameters", params.len()),
        ));
    }
    if let Some(i) = params.iter().position(|x| !x.is_finite()) {
        return Err(Error::invalid(
            "parameters",
            format!("value {i} is not finite: {}", params[i]),
        ));
    }
    Ok(())
}
