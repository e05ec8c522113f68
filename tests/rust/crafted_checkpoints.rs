//! Crafted checkpoints: a valid CRC over a state whose parts disagree with the model or method
//! (every vector truncated or extended in turn, every count changed) is refused naming
//! `checkpoint`, never a panic; a checkpoint of another model, method or step is refused,
//! naming what differs; and an edited value that the method derives (a coefficient, a cached
//! force) is refused too.
//!
//! The crafting re-encodes a checkpoint through serde's data model: [`Value`] records the calls
//! a checkpoint's `Serialize` makes and replays them into postcard, so that a mutated tree is
//! exactly the bytes a crafted file would hold, with its CRC recomputed.

use std::panic::{catch_unwind, AssertUnwindSafe};

use serde::ser::{self, Serialize, SerializeSeq, SerializeStruct, SerializeTuple, SerializeTupleStruct};
use varmech::integrators::{integrate, resume, Checkpoint, Dynamics, General, Method, Options};
use varmech::scenes::{planar_chain, ChaplyginSleigh, DoublePendulum, HarmonicOscillator, HenonHeiles, Kepler, NBody};
use varmech::Error;

/// One call of serde's data model, with what it holds.
#[derive(Clone, Debug)]
enum Value {
    Bool(bool),
    U8(u8),
    U32(u32),
    U64(u64),
    F64(f64),
    None,
    Some(Box<Value>),
    Unit,
    UnitVariant(&'static str, u32, &'static str),
    NewtypeStruct(&'static str, Box<Value>),
    NewtypeVariant(&'static str, u32, &'static str, Box<Value>),
    Seq(Vec<Value>),
    Tuple(Vec<Value>),
    TupleStruct(&'static str, Vec<Value>),
    Struct(&'static str, Vec<(&'static str, Value)>),
}

impl Serialize for Value {
    fn serialize<S: ser::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Value::Bool(v) => s.serialize_bool(*v),
            Value::U8(v) => s.serialize_u8(*v),
            Value::U32(v) => s.serialize_u32(*v),
            Value::U64(v) => s.serialize_u64(*v),
            Value::F64(v) => s.serialize_f64(*v),
            Value::None => s.serialize_none(),
            Value::Some(v) => s.serialize_some(v),
            Value::Unit => s.serialize_unit(),
            Value::UnitVariant(n, i, v) => s.serialize_unit_variant(n, *i, v),
            Value::NewtypeStruct(n, v) => s.serialize_newtype_struct(n, v),
            Value::NewtypeVariant(n, i, var, v) => s.serialize_newtype_variant(n, *i, var, v),
            Value::Seq(items) => {
                let mut seq = s.serialize_seq(Some(items.len()))?;
                items.iter().try_for_each(|x| seq.serialize_element(x))?;
                seq.end()
            }
            Value::Tuple(items) => {
                let mut t = s.serialize_tuple(items.len())?;
                items.iter().try_for_each(|x| t.serialize_element(x))?;
                t.end()
            }
            Value::TupleStruct(n, items) => {
                let mut t = s.serialize_tuple_struct(n, items.len())?;
                items.iter().try_for_each(|x| t.serialize_field(x))?;
                t.end()
            }
            Value::Struct(n, fields) => {
                let mut st = s.serialize_struct(n, fields.len())?;
                fields.iter().try_for_each(|(k, v)| st.serialize_field(k, v))?;
                st.end()
            }
        }
    }
}

#[derive(Debug)]
struct Unsupported(String);

impl std::fmt::Display for Unsupported {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Unsupported {}

impl ser::Error for Unsupported {
    fn custom<T: std::fmt::Display>(msg: T) -> Self {
        Unsupported(msg.to_string())
    }
}

/// Records a value's calls into a [`Value`].
struct Recorder;

/// A compound being recorded.
struct Items {
    kind: Kind,
    items: Vec<Value>,
    fields: Vec<(&'static str, Value)>,
}

enum Kind {
    Seq,
    Tuple,
    TupleStruct(&'static str),
    Struct(&'static str),
}

fn record<T: Serialize + ?Sized>(value: &T) -> Value {
    value.serialize(Recorder).expect("a checkpoint records")
}

fn items(kind: Kind) -> Items {
    Items {
        kind,
        items: Vec::new(),
        fields: Vec::new(),
    }
}

fn unsupported<T>(what: &str) -> Result<T, Unsupported> {
    Err(Unsupported(format!("{what} is not in a checkpoint")))
}

/// Serializer methods of the scalars a checkpoint holds: each records its value as the variant.
macro_rules! recorded {
    ($($method:ident($ty:ty) => $variant:ident),+) => {$(
        fn $method(self, v: $ty) -> Result<Value, Unsupported> {
            Ok(Value::$variant(v))
        }
    )+};
}

/// Serializer methods of the scalars no checkpoint holds: each refuses, naming its type.
macro_rules! refused {
    ($($method:ident($ty:ident)),+) => {$(
        fn $method(self, _: $ty) -> Result<Value, Unsupported> {
            unsupported(stringify!($ty))
        }
    )+};
}

/// Serializer methods of the variants with fields, which no checkpoint holds: each refuses,
/// naming its kind.
macro_rules! refused_variants {
    ($($method:ident -> $compound:ident: $what:literal),+) => {$(
        fn $method(self, _: &'static str, _: u32, _: &'static str, _: usize) -> Result<Self::$compound, Unsupported> {
            unsupported($what)
        }
    )+};
}

impl ser::Serializer for Recorder {
    type Ok = Value;
    type Error = Unsupported;
    type SerializeSeq = Items;
    type SerializeTuple = Items;
    type SerializeTupleStruct = Items;
    type SerializeTupleVariant = ser::Impossible<Value, Unsupported>;
    type SerializeMap = ser::Impossible<Value, Unsupported>;
    type SerializeStruct = Items;
    type SerializeStructVariant = ser::Impossible<Value, Unsupported>;

    recorded!(
        serialize_bool(bool) => Bool,
        serialize_u8(u8) => U8,
        serialize_u32(u32) => U32,
        serialize_u64(u64) => U64,
        serialize_f64(f64) => F64
    );
    refused!(
        serialize_i8(i8),
        serialize_i16(i16),
        serialize_i32(i32),
        serialize_i64(i64),
        serialize_u16(u16),
        serialize_f32(f32),
        serialize_char(char)
    );
    fn serialize_str(self, v: &str) -> Result<Value, Unsupported> {
        // Strings travel as their bytes' sequence, as postcard writes them.
        Ok(Value::Seq(v.bytes().map(Value::U8).collect()))
    }
    fn serialize_bytes(self, _: &[u8]) -> Result<Value, Unsupported> {
        unsupported("bytes")
    }
    fn serialize_none(self) -> Result<Value, Unsupported> {
        Ok(Value::None)
    }
    fn serialize_some<T: Serialize + ?Sized>(self, v: &T) -> Result<Value, Unsupported> {
        Ok(Value::Some(Box::new(v.serialize(Recorder)?)))
    }
    fn serialize_unit(self) -> Result<Value, Unsupported> {
        Ok(Value::Unit)
    }
    fn serialize_unit_struct(self, _: &'static str) -> Result<Value, Unsupported> {
        Ok(Value::Unit)
    }
    fn serialize_unit_variant(self, n: &'static str, i: u32, v: &'static str) -> Result<Value, Unsupported> {
        Ok(Value::UnitVariant(n, i, v))
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, n: &'static str, v: &T) -> Result<Value, Unsupported> {
        Ok(Value::NewtypeStruct(n, Box::new(v.serialize(Recorder)?)))
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        n: &'static str,
        i: u32,
        var: &'static str,
        v: &T,
    ) -> Result<Value, Unsupported> {
        Ok(Value::NewtypeVariant(n, i, var, Box::new(v.serialize(Recorder)?)))
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Items, Unsupported> {
        Ok(items(Kind::Seq))
    }
    fn serialize_tuple(self, _: usize) -> Result<Items, Unsupported> {
        Ok(items(Kind::Tuple))
    }
    fn serialize_tuple_struct(self, n: &'static str, _: usize) -> Result<Items, Unsupported> {
        Ok(items(Kind::TupleStruct(n)))
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, Unsupported> {
        unsupported("a map")
    }
    fn serialize_struct(self, n: &'static str, _: usize) -> Result<Items, Unsupported> {
        Ok(items(Kind::Struct(n)))
    }
    refused_variants!(
        serialize_tuple_variant -> SerializeTupleVariant: "a tuple variant",
        serialize_struct_variant -> SerializeStructVariant: "a struct variant"
    );
}

impl Items {
    fn finish(self) -> Value {
        match self.kind {
            Kind::Seq => Value::Seq(self.items),
            Kind::Tuple => Value::Tuple(self.items),
            Kind::TupleStruct(n) => Value::TupleStruct(n, self.items),
            Kind::Struct(n) => Value::Struct(n, self.fields),
        }
    }
}

/// The compounds whose elements are collected in order: sequences, tuples and tuple structs.
macro_rules! collect_items {
    ($($compound:ident :: $element:ident),+) => {$(
        impl ser::$compound for Items {
            type Ok = Value;
            type Error = Unsupported;
            fn $element<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Unsupported> {
                self.items.push(v.serialize(Recorder)?);
                Ok(())
            }
            fn end(self) -> Result<Value, Unsupported> {
                Ok(self.finish())
            }
        }
    )+};
}

collect_items!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field
);

impl ser::SerializeStruct for Items {
    type Ok = Value;
    type Error = Unsupported;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, k: &'static str, v: &T) -> Result<(), Unsupported> {
        self.fields.push((k, v.serialize(Recorder)?));
        Ok(())
    }
    fn end(self) -> Result<Value, Unsupported> {
        Ok(self.finish())
    }
}

/// A mutation site: a sequence, an integer or a float, by its position in a depth-first walk.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Site {
    Seq,
    Integer,
    Float,
}

/// Applies `f` to the `target`-th node of `kind` (depth-first), with the fields' path to it.
fn visit(
    value: &mut Value,
    kind: Site,
    target: usize,
    seen: &mut usize,
    path: &mut Vec<String>,
    f: &mut dyn FnMut(&mut Value, &str),
) -> bool {
    let here = match value {
        Value::Seq(_) => kind == Site::Seq,
        Value::U32(_) | Value::U64(_) => kind == Site::Integer,
        Value::F64(_) => kind == Site::Float,
        _ => false,
    };
    if here {
        if *seen == target {
            f(value, &path.join("."));
            return true;
        }
        *seen += 1;
    }
    let mut go = |v: &mut Value, name: String, seen: &mut usize, path: &mut Vec<String>| {
        path.push(name);
        let done = visit(v, kind, target, seen, path, f);
        path.pop();
        done
    };
    match value {
        Value::Some(v) | Value::NewtypeStruct(_, v) => go(v, String::new(), seen, path),
        Value::NewtypeVariant(_, _, var, v) => go(v, var.to_string(), seen, path),
        Value::Seq(items) | Value::Tuple(items) | Value::TupleStruct(_, items) => items
            .iter_mut()
            .enumerate()
            .any(|(i, v)| go(v, i.to_string(), seen, path)),
        Value::Struct(_, fields) => fields.iter_mut().any(|(k, v)| go(v, k.to_string(), seen, path)),
        _ => false,
    }
}

fn encode(value: &Value) -> Vec<u8> {
    static CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);
    let mut bytes = b"varmech\x01".to_vec();
    bytes.extend_from_slice(&varmech::integrators::CHECKPOINT_FORMAT.to_le_bytes());
    bytes.extend(postcard::to_stdvec_crc32(value, CRC32.digest()).unwrap());
    bytes
}

/// A copy of `original` with its `target`-th node of `site` (depth-first) changed by `edit`, and
/// the fields' path to that node; None where it has no such node.
fn edited(original: &Value, site: Site, target: usize, mut edit: impl FnMut(&mut Value)) -> Option<(Value, String)> {
    let mut crafted = original.clone();
    let mut at = String::new();
    let found = visit(&mut crafted, site, target, &mut 0, &mut Vec::new(), &mut |v, path| {
        at = path.to_string();
        edit(v);
    });
    found.then_some((crafted, at))
}

/// Resumes `bytes` on `sys` for a few steps, catching a panic.
fn outcome<S: Dynamics + ?Sized>(sys: &S, bytes: &[u8]) -> Result<Result<(), Error>, String> {
    catch_unwind(AssertUnwindSafe(|| {
        let checkpoint = Checkpoint::from_bytes(bytes)?;
        resume(sys, checkpoint, 3, 1, || Ok(())).map(drop).map_err(|f| f.error)
    }))
    .map_err(|panic| {
        panic
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    })
}

/// Every sequence of the checkpoint of `sys` after 5 steps of `method`, truncated by one and
/// extended by one in turn, is refused naming `checkpoint`; every integer, changed, is
/// refused or resumed, never a panic.
fn crafted_are_refused(case: &str, sys: &dyn Dynamics, method: Method, q0: &[f64], p0: &[f64], dt: f64) {
    let traj = integrate(sys, method, q0, p0, &Options::new(dt, 5), || Ok(()))
        .unwrap_or_else(|f| panic!("{case}: {}", f.error));
    let original = record(&Checkpoint::from_bytes(&traj.checkpoint).unwrap());
    assert_eq!(
        encode(&original),
        traj.checkpoint,
        "{case}: the recorder replays the bytes"
    );
    assert!(
        outcome(sys, &traj.checkpoint).unwrap().is_ok(),
        "{case}: the checkpoint itself resumes"
    );
    let mut sites = 0;
    for target in 0.. {
        let mut changed = 0;
        for edit in ["truncated", "extended"] {
            let crafted = edited(&original, Site::Seq, target, |v| {
                if let Value::Seq(items) = v {
                    match (edit, items.last().cloned()) {
                        ("truncated", Some(_)) => drop(items.pop()),
                        ("extended", Some(last)) => items.push(last),
                        // An empty sequence: extended by a zero of postcard's every type.
                        _ => items.push(Value::U8(0)),
                    }
                }
            });
            let Some((crafted, at)) = crafted else {
                break;
            };
            changed += 1;
            match outcome(sys, &encode(&crafted)) {
                Err(panic) => panic!("{case}: {at} {edit} panics: {panic}"),
                Ok(Err(Error::InvalidArgument {
                    argument: "checkpoint", ..
                })) => {}
                Ok(other) => panic!("{case}: {at} {edit} is not refused naming checkpoint: {other:?}"),
            }
        }
        if changed == 0 {
            break;
        }
        sites += 1;
    }
    assert!(sites > 10, "{case}: {sites} sequences");
    for target in 0.. {
        let crafted = edited(&original, Site::Integer, target, |v| match v {
            Value::U32(x) => *x = x.wrapping_add(1),
            Value::U64(x) => *x = x.wrapping_add(1) | (1 << 40),
            _ => {}
        });
        let Some((crafted, at)) = crafted else {
            break;
        };
        if let Err(panic) = outcome(sys, &encode(&crafted)) {
            panic!("{case}: {at} changed panics: {panic}");
        }
    }
}

/// Runs `check` on a case of every method family and model kind: (name, model, method, q0, p0,
/// dt).
fn each_case(mut check: impl FnMut(&str, &dyn Dynamics, Method, &[f64], &[f64], f64)) {
    let kepler = Kepler::problem(0.6).unwrap();
    let (q0, p0) = (&kepler.initial.q, &kepler.initial.p);
    for method in crate::common::FAMILIES {
        check(&format!("kepler {method:?}"), &kepler.system, method, q0, p0, 0.05);
    }
    let dp = DoublePendulum::problem();
    let (q0, p0) = (&dp.initial.q, &dp.initial.p);
    check("double pendulum", &General(&dp.system), Method::Trapezoid, q0, p0, 0.01);
    let chain = planar_chain(2).unwrap();
    let (q0, p0) = (&chain.initial.q, &chain.initial.p);
    for method in [Method::Rattle, Method::Shake, Method::Rattle4] {
        check(&format!("planar chain {method:?}"), &chain.system, method, q0, p0, 0.01);
    }
    crate::common::with_rigid_body(|sys, s| check("rigid body", sys, Method::Midpoint, &s.q, &s.p, 0.01));
    let sleigh = ChaplyginSleigh::problem(1.0, 0.5, 1.0).unwrap();
    let (q0, p0) = (&sleigh.initial.q, &sleigh.initial.p);
    check("sleigh", &sleigh.system, Method::Dla4, q0, p0, 0.01);
    let solar = NBody::outer_solar_system();
    let (q0, p0) = (&solar.initial.q, &solar.initial.p);
    check(
        "solar system",
        &solar.system,
        Method::WisdomHolmanCorrected,
        q0,
        p0,
        100.0,
    );
}

#[test]
fn crafted_checkpoints_are_refused_never_a_panic() {
    each_case(crafted_are_refused);
}

/// The reproducer of the panic (a format-2 Kepler kahan_li8 checkpoint, two payload bytes
/// changed and the CRC recomputed) is refused naming `checkpoint` and both formats.
#[test]
fn the_crafted_format_2_checkpoint_is_refused() {
    let kepler = Kepler::problem(0.5).unwrap();
    let hex = include_str!("crafted_checkpoint.hex").trim();
    let bytes: Vec<u8> = (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect();
    match outcome(&kepler.system, &bytes) {
        Ok(Err(Error::InvalidArgument {
            argument: "checkpoint",
            reason,
        })) => {
            let now = format!("format {}", varmech::integrators::CHECKPOINT_FORMAT);
            assert!(reason.contains("format 2") && reason.contains(&now), "{reason}")
        }
        other => panic!("{other:?}"),
    }
}

/// A checkpoint is refused by the same scene with another parameter and by another model of
/// the same size, by a run of another method or step ([`Checkpoint::expect`]), and resumed by
/// the same model built again.
#[test]
fn a_checkpoint_of_another_model_method_or_step_is_refused() {
    let oscillator = |omega: f64| HarmonicOscillator::problem(omega).unwrap();
    let first = oscillator(1.0);
    let (q0, p0) = (&first.initial.q, &first.initial.p);
    let options = Options::new(0.01, 10);
    let bytes = integrate(&first.system, Method::Verlet, q0, p0, &options, || Ok(()))
        .unwrap()
        .checkpoint;
    let refused = |result: Result<(), Error>, says: &str| match result {
        Err(Error::InvalidArgument {
            argument: "checkpoint",
            reason,
        }) => assert!(reason.contains(says), "{reason}"),
        other => panic!("{other:?}"),
    };
    let resumed = |sys: &dyn Dynamics| {
        resume(sys, Checkpoint::from_bytes(&bytes).unwrap(), 10, 1, || Ok(()))
            .map(drop)
            .map_err(|f| f.error)
    };
    assert!(resumed(&oscillator(1.0).system).is_ok());
    refused(resumed(&oscillator(1.5).system), "another model");
    // Kepler and Hénon–Heiles: two coordinates each.
    let kepler = Kepler::problem(0.6).unwrap();
    let (q0, p0) = (&kepler.initial.q, &kepler.initial.p);
    let kepler_bytes = integrate(&kepler.system, Method::Verlet, q0, p0, &options, || Ok(()))
        .unwrap()
        .checkpoint;
    let other = HenonHeiles::problem();
    let on_other = resume(
        &other.system,
        Checkpoint::from_bytes(&kepler_bytes).unwrap(),
        10,
        1,
        || Ok(()),
    );
    refused(on_other.map(drop).map_err(|f| f.error), "another model");
    let checkpoint = Checkpoint::from_bytes(&bytes).unwrap();
    refused(
        checkpoint.expect(Some(Method::KahanLi8), None),
        "method verlet, not kahan_li8",
    );
    refused(checkpoint.expect(None, Some(0.02)), "dt = 0.01, not 0.02");
    assert!(checkpoint.expect(Some(Method::Verlet), Some(0.01)).is_ok());
}

/// The fields of the run's own state that a float edit may change silently: what a checkpoint
/// legitimately carries (the compensated-summation carries, the Newton and multiplier
/// predictors, the Wisdom–Holman inner variables' carries) and q where the model does not
/// see it (a cyclic coordinate). Everything else the method derives is checked.
const RUN_STATE: [&str; 8] = [
    "state.q.",
    "state.eq.",
    "state.ep.",
    "last_dq.",
    "lambda.",
    "Midpoint.x.",
    "inner.ex.",
    "inner.ev.",
];

/// Every float of the checkpoint of `sys` after 5 steps of `method`, scaled by 1.02 in turn
/// (a zero set to 0.5) with the CRC recomputed, is refused naming `checkpoint`, or leaves
/// the next 20 steps as they were, or lies in the run's own state ([`RUN_STATE`]): an edited
/// coefficient or cached force never steers the run.
fn edited_values_are_refused(case: &str, sys: &dyn Dynamics, method: Method, q0: &[f64], p0: &[f64], dt: f64) {
    let traj = integrate(sys, method, q0, p0, &Options::new(dt, 5), || Ok(())).unwrap();
    let original = record(&Checkpoint::from_bytes(&traj.checkpoint).unwrap());
    let run = |bytes: &[u8]| -> Result<Vec<f64>, Error> {
        let checkpoint = Checkpoint::from_bytes(bytes)?;
        let more = resume(sys, checkpoint, 20, 20, || Ok(())).map_err(|f| f.error)?;
        Ok([more.q, more.p].concat())
    };
    let unedited = run(&traj.checkpoint).unwrap();
    let (mut edits, mut refused) = (0, 0);
    for target in 0.. {
        let crafted = edited(&original, Site::Float, target, |v| {
            if let Value::F64(x) = v {
                *x = if *x != 0.0 { *x * 1.02 } else { 0.5 };
            }
        });
        let Some((crafted, path)) = crafted else {
            break;
        };
        let at = format!("{path}.");
        edits += 1;
        match run(&encode(&crafted)) {
            Err(Error::InvalidArgument {
                argument: "checkpoint", ..
            }) => refused += 1,
            Ok(r) if r.iter().zip(&unedited).any(|(a, b)| a.to_bits() != b.to_bits()) => {
                assert!(
                    RUN_STATE.iter().any(|s| at.contains(s)),
                    "{case}: {at} edited steers the run silently"
                )
            }
            _ => {}
        }
    }
    assert!(edits > 20 && refused > 5, "{case}: {refused} of {edits} edits refused");
}

#[test]
fn edited_coefficients_and_cached_forces_are_refused() {
    each_case(edited_values_are_refused);
}
