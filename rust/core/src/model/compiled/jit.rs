//! The JIT backend: a tape compiled to machine code by Cranelift, agreeing with the interpreter
//! [`Tape::eval`] bit for bit.
//!
//! Lowering, instruction by instruction into one basic block of SSA values:
//! - a constant is an immediate; an input or parameter a load from its array at its instruction;
//! - −, √, |·|, +, −, ×, ÷ are Cranelift's own instructions, correctly rounded as IEEE 754
//!   requires and as Rust's operators are. Cranelift contracts no multiply-add into a fused one,
//!   and folds constants only where the result is not NaN, so every result is the interpreter's;
//! - sign is two comparisons and two selects, [`sign`](super::sign) exactly (±0 and NaN pass through);
//! - every other function (exp, log, the trigonometric and hyperbolic ones and their inverses,
//!   pow, atan2, powi) is a call to the interpreter's own Rust function ([`Unary::apply`],
//!   [`Binary::apply`], `f64::powi`) behind a C entry point, so that both share one libm;
//! - except a sine and a cosine of one register, which on glibc are one call of its `sincos`:
//!   glibc computes them with the very code of its `sin` and `cos` (one argument reduction for
//!   both), so the bits are the interpreter's (tests/rust/jit.rs holds it to that).

use std::collections::{HashMap, HashSet};
use std::sync::{Mutex, PoisonError};

use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{
    types, AbiParam, FuncRef, InstBuilder, MemFlagsData, Signature, StackSlotData, StackSlotKind, Value,
};
use cranelift_codegen::settings::{self, Configurable};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{default_libcall_names, FuncId, Linkage, Module};

use super::tape::{Binary, Op, Tape, Unary};
use crate::Error;

/// The generated function: out = f(inputs, params).
type Function = unsafe extern "C" fn(inputs: *const f64, params: *const f64, out: *mut f64);

/// Machine code of one tape: out = f(inputs, params), the tape's outputs in order.
///
/// `Send + Sync`: the code is immutable once compiled and touches only the three arrays of a
/// call, so any number of threads may call it at once. Dropping it frees the code's memory.
pub struct Code {
    function: Function,
    inputs: usize,
    params: usize,
    outputs: usize,
    /// Owns the memory `function` lives in, freed on drop. Never used while code runs; the
    /// mutex only makes `Code` `Sync` (the module itself is `Send` but not `Sync`).
    module: Mutex<Option<JITModule>>,
}

impl std::fmt::Debug for Code {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Code")
            .field("inputs", &self.inputs)
            .field("params", &self.params)
            .field("outputs", &self.outputs)
            .finish_non_exhaustive()
    }
}

impl Code {
    /// Compiles `tape` for the host. Fails (`Error::InvalidArgument` for "jit") if the host has
    /// no Cranelift backend or code generation fails; the interpreter then remains.
    pub fn compile(tape: &Tape) -> Result<Code, Error> {
        let fail = |e: &dyn std::fmt::Display| Error::invalid("jit", e.to_string());
        let mut flags = settings::builder();
        for (name, value) in [
            ("opt_level", "speed"),
            ("is_pic", "false"),
            ("use_colocated_libcalls", "false"),
            // A long tape's spills can make a frame larger than the stack's guard page: probe it.
            ("enable_probestack", "true"),
            ("probestack_strategy", "inline"),
        ] {
            flags.set(name, value).map_err(|e| fail(&e))?;
        }
        let isa = cranelift_native::builder()
            .map_err(|e| fail(&e))?
            .finish(settings::Flags::new(flags))
            .map_err(|e| fail(&e))?;
        let mut builder = JITBuilder::with_isa(isa, default_libcall_names());
        for (name, address) in Library::symbols() {
            builder.symbol(name, address);
        }
        let mut module = JITModule::new(builder);
        let id = define(&mut module, tape).map_err(|e| fail(&e))?;
        module.finalize_definitions().map_err(|e| fail(&e))?;
        let address = module.get_finalized_function(id);
        // SAFETY: `define` gave the function at `address` this very signature (the host's C
        // calling convention), and `module` keeps its memory alive as long as the `Code`.
        let function = unsafe { std::mem::transmute::<*const u8, Function>(address) };
        Ok(Code {
            function,
            inputs: tape.inputs(),
            params: tape.params(),
            outputs: tape.outputs().len(),
            module: Mutex::new(Some(module)),
        })
    }

    /// out[..outputs] = f(inputs, params). Panics if an array is shorter than the tape's
    /// inputs, parameters or outputs: callers size them from the tape, so that is a bug.
    #[inline]
    pub fn call(&self, inputs: &[f64], params: &[f64], out: &mut [f64]) {
        assert!(
            inputs.len() >= self.inputs && params.len() >= self.params && out.len() >= self.outputs,
            "jit code of {} inputs, {} parameters and {} outputs called with {}, {} and {}",
            self.inputs,
            self.params,
            self.outputs,
            inputs.len(),
            params.len(),
            out.len()
        );
        // SAFETY: the code reads inputs[..self.inputs] and params[..self.params] (the tape was
        // checked to index no further) and writes out[..self.outputs], all in bounds by the
        // assertion; its memory lives as long as `self`.
        unsafe { (self.function)(inputs.as_ptr(), params.as_ptr(), out.as_mut_ptr()) }
    }
}

impl Drop for Code {
    fn drop(&mut self) {
        let module = self.module.get_mut().unwrap_or_else(PoisonError::into_inner).take();
        if let Some(module) = module {
            // SAFETY: `&mut self` proves no call is running, and `function` dies with `self`.
            unsafe { module.free_memory() }
        }
    }
}

/// Declares and defines the tape's function in `module`.
fn define(module: &mut JITModule, tape: &Tape) -> Result<FuncId, Box<dyn std::error::Error>> {
    let pointer = module.target_config().pointer_type();
    let mut signature = module.make_signature();
    signature.params.extend([AbiParam::new(pointer); 3]);
    let id = module.declare_function("tape", Linkage::Local, &signature)?;
    let mut library = Library::new(module);

    let mut context = module.make_context();
    context.func.signature = signature;
    let mut builder_context = FunctionBuilderContext::new();
    let mut b = FunctionBuilder::new(&mut context.func, &mut builder_context);
    let block = b.create_block();
    b.append_block_params_for_function_params(block);
    b.switch_to_block(block);
    b.seal_block(block);
    let &[inputs, params, out] = b.block_params(block) else {
        unreachable!("the signature has three parameters")
    };
    // The arrays are f64-aligned Rust slices the caller checked to be long enough.
    let memory = MemFlagsData::trusted();
    let offset = |index: usize| i32::try_from(index * 8).map_err(|_| format!("array index {index} too large"));

    // Each output is stored as soon as its register is computed, so that it is not kept live
    // (and spilled around every call) to the end: (register, output index) in register order.
    let mut stores: Vec<(u32, usize)> = tape.outputs().iter().enumerate().map(|(j, &o)| (o, j)).collect();
    stores.sort_unstable();
    let mut stores = stores.into_iter().peekable();

    // The registers both a sine and a cosine take, and their (sin, cos) once computed.
    let mut fused: HashMap<u32, Option<(Value, Value)>> = HashMap::new();
    if SINCOS.is_some() {
        let of = |f: Unary| {
            (tape.ops().iter()).filter_map(move |op| match *op {
                Op::Unary(g, a) if g == f => Some(a),
                _ => None,
            })
        };
        let sines: HashSet<u32> = of(Unary::Sin).collect();
        fused.extend(of(Unary::Cos).filter(|a| sines.contains(a)).map(|a| (a, None)));
    }
    // Where `sincos` writes them: one slot for every call, each read back at once.
    let mut pair = None;

    let mut registers: Vec<Value> = Vec::with_capacity(tape.ops().len());
    for (i, &op) in tape.ops().iter().enumerate() {
        let r = |a: u32| registers[a as usize];
        let value = match op {
            Op::Unary(f @ (Unary::Sin | Unary::Cos), a) if fused.contains_key(&a) => {
                let (sin, cos) = match fused[&a] {
                    Some(both) => both,
                    None => {
                        let callee = library.import(module, &mut b, Callee::SinCos)?;
                        let slot = *pair.get_or_insert_with(|| {
                            b.create_sized_stack_slot(StackSlotData::new(StackSlotKind::ExplicitSlot, 16, 3))
                        });
                        let address = b.ins().stack_addr(pointer, slot, 0);
                        b.ins().call(callee, &[r(a), address]);
                        let both = (
                            b.ins().load(types::F64, memory, address, 0),
                            b.ins().load(types::F64, memory, address, 8),
                        );
                        fused.insert(a, Some(both));
                        both
                    }
                };
                if f == Unary::Sin {
                    sin
                } else {
                    cos
                }
            }
            Op::Const(c) => b.ins().f64const(c),
            Op::Input(s) => b.ins().load(types::F64, memory, inputs, offset(s as usize)?),
            Op::Param(k) => b.ins().load(types::F64, memory, params, offset(k as usize)?),
            Op::Unary(f, a) => {
                let x = r(a);
                match f {
                    Unary::Neg => b.ins().fneg(x),
                    Unary::Sqrt => b.ins().sqrt(x),
                    Unary::Abs => b.ins().fabs(x),
                    Unary::Sign => {
                        let zero = b.ins().f64const(0.0);
                        let (one, minus_one) = (b.ins().f64const(1.0), b.ins().f64const(-1.0));
                        let positive = b.ins().fcmp(FloatCC::GreaterThan, x, zero);
                        let negative = b.ins().fcmp(FloatCC::LessThan, x, zero);
                        let otherwise = b.ins().select(negative, minus_one, x);
                        b.ins().select(positive, one, otherwise)
                    }
                    _ => {
                        let callee = library.import(module, &mut b, Callee::Unary(f))?;
                        let call = b.ins().call(callee, &[x]);
                        b.inst_results(call)[0]
                    }
                }
            }
            Op::Binary(f, a, c) => {
                let (x, y) = (r(a), r(c));
                match f {
                    Binary::Add => b.ins().fadd(x, y),
                    Binary::Sub => b.ins().fsub(x, y),
                    Binary::Mul => b.ins().fmul(x, y),
                    Binary::Div => b.ins().fdiv(x, y),
                    Binary::Pow | Binary::Atan2 => {
                        let callee = library.import(module, &mut b, Callee::Binary(f))?;
                        let call = b.ins().call(callee, &[x, y]);
                        b.inst_results(call)[0]
                    }
                }
            }
            Op::Powi(a, n) => {
                let callee = library.import(module, &mut b, Callee::Powi)?;
                let n = b.ins().iconst(types::I32, i64::from(n));
                let call = b.ins().call(callee, &[r(a), n]);
                b.inst_results(call)[0]
            }
        };
        registers.push(value);
        while let Some((_, j)) = stores.next_if(|&(o, _)| o as usize == i) {
            b.ins().store(memory, value, out, offset(j)?);
        }
    }
    b.ins().return_(&[]);
    b.finalize(module.target_config());

    module.define_function(id, &mut context)?;
    module.clear_context(&mut context);
    Ok(id)
}

/// A function the code calls instead of inlining it.
#[derive(Clone, Copy)]
enum Callee {
    Unary(Unary),
    Binary(Binary),
    Powi,
    SinCos,
}

/// The interpreter's functions as C entry points, imported into the function being built on
/// first use.
struct Library {
    unary: Signature,
    binary: Signature,
    powi: Signature,
    sincos: Signature,
    /// Each callee once imported, by [`Callee::index`].
    imported: [Option<FuncRef>; Unary::ALL.len() + Binary::ALL.len() + 2],
}

/// `Unary::ALL[F].apply`, the interpreter's f(x), as a C function.
extern "C" fn unary<const F: usize>(x: f64) -> f64 {
    Unary::ALL[F].apply(x)
}

/// `Binary::ALL[F].apply`, the interpreter's f(a, b), as a C function.
extern "C" fn binary<const F: usize>(a: f64, b: f64) -> f64 {
    Binary::ALL[F].apply(a, b)
}

/// aⁿ as the interpreter computes it, as a C function.
extern "C" fn powi(a: f64, n: i32) -> f64 {
    a.powi(n)
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
extern "C" {
    /// glibc's libm: sin x and cos x, each to the bit its `sin` and `cos` give.
    fn sincos(x: f64, sin: *mut f64, cos: *mut f64);
}

/// (sin x, cos x) into `out[0..2]`, where the C library computes them in one call with the
/// bits of its `sin` and `cos`: glibc's `sincos`; elsewhere none, and each is its own call.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const SINCOS: Option<extern "C" fn(f64, *mut f64)> = Some(sin_cos);
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
const SINCOS: Option<extern "C" fn(f64, *mut f64)> = None;

#[cfg(all(target_os = "linux", target_env = "gnu"))]
extern "C" fn sin_cos(x: f64, out: *mut f64) {
    // SAFETY: the code passes the address of its own 16-byte stack slot.
    unsafe { sincos(x, out, out.add(1)) }
}

/// The unary entry points, indexed as [`Unary::ALL`].
const UNARY: [extern "C" fn(f64) -> f64; Unary::ALL.len()] = [
    unary::<0>,
    unary::<1>,
    unary::<2>,
    unary::<3>,
    unary::<4>,
    unary::<5>,
    unary::<6>,
    unary::<7>,
    unary::<8>,
    unary::<9>,
    unary::<10>,
    unary::<11>,
    unary::<12>,
    unary::<13>,
    unary::<14>,
    unary::<15>,
    unary::<16>,
    unary::<17>,
];

/// The binary entry points, indexed as [`Binary::ALL`].
const BINARY: [extern "C" fn(f64, f64) -> f64; Binary::ALL.len()] = [
    binary::<0>,
    binary::<1>,
    binary::<2>,
    binary::<3>,
    binary::<4>,
    binary::<5>,
];

impl Callee {
    /// Unary functions by their position in [`Unary::ALL`], then binary ones by theirs in
    /// [`Binary::ALL`], then powi: the order of their codes in [`Tape::OPS`], less 3.
    fn index(self) -> usize {
        match self {
            Callee::Unary(f) => Unary::ALL
                .iter()
                .position(|&g| g == f)
                .expect("Unary::ALL lists every function"),
            Callee::Binary(f) => {
                Unary::ALL.len()
                    + Binary::ALL
                        .iter()
                        .position(|&g| g == f)
                        .expect("Binary::ALL lists every function")
            }
            Callee::Powi => Unary::ALL.len() + Binary::ALL.len(),
            Callee::SinCos => Unary::ALL.len() + Binary::ALL.len() + 1,
        }
    }

    /// The symbol of the callee of `index`, after its op's name.
    fn name(index: usize) -> String {
        match Tape::OPS.get(3 + index) {
            Some(op) => format!("varmech_tape_{op}"),
            None => "varmech_tape_sincos".to_string(),
        }
    }
}

impl Library {
    fn new(module: &JITModule) -> Self {
        let signature = |params: &[types::Type]| {
            let mut s = module.make_signature();
            s.params.extend(params.iter().map(|&t| AbiParam::new(t)));
            s.returns.push(AbiParam::new(types::F64));
            s
        };
        Library {
            unary: signature(&[types::F64]),
            binary: signature(&[types::F64, types::F64]),
            powi: signature(&[types::F64, types::I32]),
            sincos: {
                let mut s = module.make_signature();
                let pointer = module.target_config().pointer_type();
                s.params.extend([AbiParam::new(types::F64), AbiParam::new(pointer)]);
                s
            },
            imported: [None; Unary::ALL.len() + Binary::ALL.len() + 2],
        }
    }

    /// Every entry point by its symbol, for the JIT's symbol table.
    fn symbols() -> impl Iterator<Item = (String, *const u8)> {
        let unary = UNARY.iter().map(|&f| f as *const u8);
        let binary = BINARY.iter().map(|&f| f as *const u8);
        let all = unary
            .chain(binary)
            .chain([powi as extern "C" fn(f64, i32) -> f64 as *const u8])
            .chain(SINCOS.map(|f| f as *const u8));
        all.enumerate().map(|(i, address)| (Callee::name(i), address))
    }

    /// `callee`, callable from the function `builder` builds.
    fn import(
        &mut self,
        module: &mut JITModule,
        builder: &mut FunctionBuilder,
        callee: Callee,
    ) -> Result<FuncRef, Box<dyn std::error::Error>> {
        let index = callee.index();
        if let Some(reference) = self.imported[index] {
            return Ok(reference);
        }
        let signature = match callee {
            Callee::Unary(_) => &self.unary,
            Callee::Binary(_) => &self.binary,
            Callee::Powi => &self.powi,
            Callee::SinCos => &self.sincos,
        };
        let id = module.declare_function(&Callee::name(index), Linkage::Import, signature)?;
        let reference = module.declare_func_in_func(id, builder.func);
        self.imported[index] = Some(reference);
        Ok(reference)
    }
}
