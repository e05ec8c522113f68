//! The shape of a state: every length, matrix size, enum variant and structural count in it,
//! read through serde's data model (the values of the numbers left out), so that a decoded
//! state is checked against the state its model and method would have, whatever its parts;
//! and its constants, the floats a method derives from its coefficients, the step and the
//! model alone ([`constants`]), which a decoded state must hold to the bit.

use std::fmt;

use serde::ser::{self, Serialize};

use crate::integrators::{Dynamics, StepperState};

/// Integer fields that hold values (counts, the clock, the predictor's history), not sizes:
/// their values are not part of the shape. A field named `…pivots` is checked instead: each
/// pivot is an index into its own vector.
const VALUES: [&str; 7] = [
    "steps",
    "n0",
    "evaluations",
    "sweeps",
    "iterations",
    "history",
    "max_iterations",
];

/// The fields whose floats are constants of the method, the step and the model, never of the
/// run: a kick–drift splitting's fractions (its `scaled`, the fractions times the step it last
/// took, are checked against them, see `KickDrift::misfit`), a composition's γ, a quadrature's
/// nodes, weights and Lagrange basis with its sign, and a delayed force's lags (where t − τ
/// lies, and the interpolant's weights there).
const CONSTANTS: [&str; 7] = ["fractions", "gamma", "nodes", "weights", "basis", "slopes", "lags"];

/// One mark of a shape: where it is (the fields' path) and what (a length, a variant, …).
#[derive(Debug, PartialEq)]
pub(in crate::integrators) struct Mark {
    path: String,
    what: What,
}

#[derive(Debug, PartialEq)]
pub(in crate::integrators) enum What {
    Length(usize),
    Variant(u32),
    Present(bool),
    Count(u64),
    /// A pivot beyond its vector: no template has one.
    PivotOutOfRange(u64),
    /// A constant's bits ([`constants`]).
    Constant(u64),
}

impl fmt::Display for Mark {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = if self.path.is_empty() { "the state" } else { &self.path };
        match self.what {
            What::Length(n) => write!(f, "{at} of length {n}"),
            What::Variant(v) => write!(f, "{at} of variant {v}"),
            What::Present(true) => write!(f, "{at} present"),
            What::Present(false) => write!(f, "{at} absent"),
            What::Count(c) => write!(f, "{at} = {c}"),
            What::PivotOutOfRange(p) => write!(f, "{at} holding the index {p}, beyond its length"),
            What::Constant(bits) => write!(f, "{at} = {:?}", f64::from_bits(bits)),
        }
    }
}

/// Why a decoded state (a checkpoint's, which its CRC does not protect against a crafted file)
/// cannot be stepped on `model`, if it cannot: its values in range
/// ([`StepperState::values_misfit`]), and every length, matrix size, variant and count in it as
/// in the state its method has on `model`, fresh or after a step (the constrained methods size
/// their buffers at the first step), every pivot indexing its vector. The caller has checked
/// the dimension and that the method integrates the model's kind.
pub(in crate::integrators) fn misfit<S: Dynamics + ?Sized>(state: &StepperState, model: &S) -> Option<String> {
    if let Some(reason) = state.values_misfit() {
        return Some(reason);
    }
    let (fresh, stepped) = state.templates(model);
    let (found, fresh, stepped) = (shape(state), shape(&fresh), shape(&stepped));
    if found == fresh || found == stepped {
        return None;
    }
    let (at, expected) = found
        .iter()
        .zip(&stepped)
        .find(|(a, b)| a != b)
        .map_or_else(|| (None, None), |(a, b)| (Some(a), Some(b)));
    Some(match (at, expected) {
        (Some(a), Some(b)) => format!(
            "its state does not fit this model and its method {}: {a} where they have {b}",
            state.method().info().name
        ),
        _ => format!(
            "its state does not fit this model and its method {}: {} parts where they have {}",
            state.method().info().name,
            found.len(),
            stepped.len()
        ),
    })
}

/// The marks of `value`'s shape, in order.
pub(in crate::integrators) fn shape<T: Serialize + ?Sized>(value: &T) -> Vec<Mark> {
    marks(value, false)
}

/// The floats of `value`'s constants (the fields [`CONSTANTS`] names, and all they hold), in
/// order, with their paths.
pub(in crate::integrators) fn constants<T: Serialize + ?Sized>(value: &T) -> Vec<Mark> {
    let mut marks = marks(value, true);
    marks.retain(|m| matches!(m.what, What::Constant(_)));
    marks
}

fn marks<T: Serialize + ?Sized>(value: &T, constants: bool) -> Vec<Mark> {
    let mut marks = Vec::new();
    let mut path = Vec::new();
    value
        .serialize(Shaper {
            marks: &mut marks,
            path: &mut path,
            mode: Mode::Shape,
            constants,
        })
        .expect("a state's shape is always readable");
    marks
}

#[derive(Clone, Copy, PartialEq)]
enum Mode {
    Shape,
    /// Integers are values, not sizes.
    Values,
    /// Indices below the given length.
    Pivots(u64),
}

struct Shaper<'a> {
    marks: &'a mut Vec<Mark>,
    path: &'a mut Vec<&'static str>,
    mode: Mode,
    /// Whether the constants' floats are marked too.
    constants: bool,
}

#[derive(Debug)]
pub(in crate::integrators) struct Never;

impl fmt::Display for Never {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("no shape")
    }
}

impl std::error::Error for Never {}

impl ser::Error for Never {
    fn custom<T: fmt::Display>(_: T) -> Self {
        Never
    }
}

impl<'a> Shaper<'a> {
    fn mark(&mut self, what: What) {
        self.marks.push(Mark {
            path: self.path.join("."),
            what,
        });
    }

    fn integer(mut self, v: u64) -> Result<(), Never> {
        match self.mode {
            Mode::Shape => self.mark(What::Count(v)),
            Mode::Values => {}
            Mode::Pivots(len) if v < len => {}
            Mode::Pivots(_) => self.mark(What::PivotOutOfRange(v)),
        }
        Ok(())
    }

    fn compound(self, length: Option<usize>) -> Compound<'a> {
        let Shaper {
            marks,
            path,
            mode,
            constants,
        } = self;
        let mut shaper = Shaper {
            marks,
            path,
            mode,
            constants,
        };
        if let Some(n) = length {
            shaper.mark(What::Length(n));
        }
        let mode = match (mode, length) {
            (Mode::Pivots(_), Some(n)) => Mode::Pivots(n as u64),
            (mode, _) => mode,
        };
        Compound {
            marks: shaper.marks,
            path: shaper.path,
            mode,
            constants,
            named: false,
        }
    }

    fn variant(mut self, index: u32, name: &'static str) -> Compound<'a> {
        self.mark(What::Variant(index));
        self.path.push(name);
        let mut c = self.compound(None);
        c.named = true;
        c
    }
}

struct Compound<'a> {
    marks: &'a mut Vec<Mark>,
    path: &'a mut Vec<&'static str>,
    mode: Mode,
    constants: bool,
    /// The compound pushed a name on the path (a variant's), to pop at its end.
    named: bool,
}

impl Compound<'_> {
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Never> {
        value.serialize(Shaper {
            marks: self.marks,
            path: self.path,
            mode: self.mode,
            constants: self.constants,
        })
    }

    fn field<T: Serialize + ?Sized>(&mut self, key: &'static str, value: &T) -> Result<(), Never> {
        let mode = if key.ends_with("pivots") {
            Mode::Pivots(0)
        } else if VALUES.contains(&key) {
            Mode::Values
        } else {
            self.mode
        };
        self.path.push(key);
        let result = value.serialize(Shaper {
            marks: self.marks,
            path: self.path,
            mode,
            constants: self.constants,
        });
        self.path.pop();
        result
    }

    fn finish(self) -> Result<(), Never> {
        if self.named {
            self.path.pop();
        }
        Ok(())
    }
}

macro_rules! integers {
    ($($name:ident: $t:ty),*) => {
        $(fn $name(self, v: $t) -> Result<(), Never> {
            self.integer(v as u64)
        })*
    };
}

macro_rules! ignored {
    ($($name:ident: $t:ty),*) => {
        $(fn $name(self, _: $t) -> Result<(), Never> {
            Ok(())
        })*
    };
}

// A tuple struct and a struct are a compound of unnamed length; a tuple and a struct variant
// mark their variant (`$ok` the compound, which names the impl's lifetime).
macro_rules! compounds {
    ($ok:ty: $($name:ident),*) => {
        $(fn $name(self, _: &'static str, _: usize) -> Result<$ok, Never> {
            Ok(self.compound(None))
        })*
    };
}

macro_rules! variants {
    ($ok:ty: $($name:ident),*) => {
        $(fn $name(self, _: &'static str, index: u32, variant: &'static str, _: usize) -> Result<$ok, Never> {
            Ok(self.variant(index, variant))
        })*
    };
}

impl<'a> ser::Serializer for Shaper<'a> {
    type Ok = ();
    type Error = Never;
    type SerializeSeq = Compound<'a>;
    type SerializeTuple = Compound<'a>;
    type SerializeTupleStruct = Compound<'a>;
    type SerializeTupleVariant = Compound<'a>;
    type SerializeMap = Compound<'a>;
    type SerializeStruct = Compound<'a>;
    type SerializeStructVariant = Compound<'a>;

    integers!(serialize_u8: u8, serialize_u16: u16, serialize_u32: u32, serialize_u64: u64);
    integers!(serialize_i8: i8, serialize_i16: i16, serialize_i32: i32, serialize_i64: i64);
    ignored!(serialize_bool: bool, serialize_f32: f32, serialize_char: char);
    ignored!(serialize_str: &str, serialize_bytes: &[u8]);

    fn serialize_f64(mut self, v: f64) -> Result<(), Never> {
        if self.constants && self.path.iter().any(|field| CONSTANTS.contains(field)) {
            self.mark(What::Constant(v.to_bits()));
        }
        Ok(())
    }

    fn serialize_none(mut self) -> Result<(), Never> {
        self.mark(What::Present(false));
        Ok(())
    }

    fn serialize_some<T: Serialize + ?Sized>(mut self, value: &T) -> Result<(), Never> {
        self.mark(What::Present(true));
        value.serialize(self)
    }

    fn serialize_unit(self) -> Result<(), Never> {
        Ok(())
    }

    fn serialize_unit_struct(self, _: &'static str) -> Result<(), Never> {
        Ok(())
    }

    fn serialize_unit_variant(mut self, _: &'static str, index: u32, _: &'static str) -> Result<(), Never> {
        self.mark(What::Variant(index));
        Ok(())
    }

    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _: &'static str, value: &T) -> Result<(), Never> {
        value.serialize(self)
    }

    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        index: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), Never> {
        let mut c = self.variant(index, variant);
        c.element(value)?;
        c.finish()
    }

    fn serialize_seq(self, len: Option<usize>) -> Result<Compound<'a>, Never> {
        Ok(self.compound(Some(len.unwrap_or(usize::MAX))))
    }

    fn serialize_tuple(self, _: usize) -> Result<Compound<'a>, Never> {
        Ok(self.compound(None))
    }

    fn serialize_map(self, len: Option<usize>) -> Result<Compound<'a>, Never> {
        Ok(self.compound(Some(len.unwrap_or(usize::MAX))))
    }

    compounds!(Compound<'a>: serialize_tuple_struct, serialize_struct);
    variants!(Compound<'a>: serialize_tuple_variant, serialize_struct_variant);
}

// Every compound a serializer hands out is a Compound: its elements (sequences, tuples, their
// variants) go to `element`, its named fields (structs, their variants) to `field`.
macro_rules! elements {
    ($($trait:ident :: $method:ident),*) => {$(
        impl ser::$trait for Compound<'_> {
            type Ok = ();
            type Error = Never;

            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Never> {
                self.element(value)
            }

            fn end(self) -> Result<(), Never> {
                self.finish()
            }
        }
    )*};
}

macro_rules! fields {
    ($($trait:ident),*) => {$(
        impl ser::$trait for Compound<'_> {
            type Ok = ();
            type Error = Never;

            fn serialize_field<T: Serialize + ?Sized>(&mut self, key: &'static str, value: &T) -> Result<(), Never> {
                self.field(key, value)
            }

            fn end(self) -> Result<(), Never> {
                self.finish()
            }
        }
    )*};
}

elements!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field
);
fields!(SerializeStruct, SerializeStructVariant);

impl ser::SerializeMap for Compound<'_> {
    type Ok = ();
    type Error = Never;

    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Never> {
        self.element(key)
    }

    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Never> {
        self.element(value)
    }

    fn end(self) -> Result<(), Never> {
        self.finish()
    }
}
