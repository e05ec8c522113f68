//! A run's whole state at a step, as bytes, to go on from later (in another process, after a
//! crash) bit for bit.

pub(super) mod derived;
pub(super) mod shape;

use serde::{Deserialize, Serialize};

use super::divergence::EnergyWatch;
use super::{check_method, Dynamics, Method, NewtonOptions, StepperState};
use crate::Error;

/// Everything a run needs to go on from step n as if it had never stopped: the stepper's state
/// ([`StepperState`]: (tₙ, qₙ, pₙ), the compensated-summation carries (e_q, e_p), the method's
/// caches (the force of first same as last), the Newton and multiplier predictors, the
/// Wisdom–Holman inner variables, the counts and the clock), the run's energy check and the
/// [`Fingerprint`] of the model, method and options it was taken of.
///
/// [`Checkpoint::to_bytes`] writes it as a header (`MAGIC`, then the format number as a
/// little-endian u32) and serde's data model of the state in postcard's wire format
/// (<https://postcard.jamesmunns.com/wire-format>) with a trailing CRC-32, so that a damaged
/// checkpoint is refused rather than resumed. Only the library that wrote it reads it back to
/// the same bits: the format number changes whenever the state's layout does.
///
/// A CRC does not stop a crafted file: `Checkpoint::resume_on` checks every length and
/// index of the decoded state against the model and method before a step, the fingerprint
/// against the model's, and the values the method derives (its coefficients, its cached
/// forces) computed again (`checkpoint/derived.rs`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    pub(super) state: StepperState,
    pub(super) watch: Option<EnergyWatch>,
    fingerprint: Fingerprint,
    /// The tolerance of an energy check to start from the checkpoint's state, asked for by
    /// [`Checkpoint::check_energy`] where the run had none: a request, never written.
    #[serde(skip)]
    pub(super) fresh_check: Option<f64>,
}

/// What a checkpoint was taken of, to refuse another: the model's kind, size and constraint
/// counts, the method, the step, the summation and the Newton options, and a hash of what the
/// model computes at the checkpoint's state (L, ∂L/∂q, ∂L/∂q̇ at q̇ = ∂L/∂q̇⁻¹(p), the forces and
/// the constraints' residuals), which tells apart models of the same size and kind (another
/// scene, another parameter, another closure) whatever their type: native, compiled, closures,
/// reduced.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fingerprint {
    kind: String,
    dim: usize,
    constraints: (usize, usize),
    method: Method,
    dt: f64,
    compensated: bool,
    newton: Option<NewtonOptions>,
    model: u64,
}

impl Fingerprint {
    /// The fingerprint of `state` stepped on `model` (of as many coordinates).
    pub fn of<S: Dynamics + ?Sized>(model: &S, state: &StepperState) -> Self {
        Fingerprint {
            kind: model.kind().name().to_string(),
            dim: model.dim(),
            constraints: model.constraint_counts(),
            method: state.method(),
            dt: state.dt(),
            compensated: state.compensated(),
            newton: state.newton_options(),
            model: evaluations(model, state),
        }
    }

    /// Why a checkpoint of `self` does not resume as `other`, naming the first difference.
    fn differs(&self, other: &Fingerprint) -> Option<String> {
        let name = |m: Method| m.info().name;
        if (&self.kind, self.dim, self.constraints) != (&other.kind, other.dim, other.constraints) {
            return Some(format!(
                "it is of a {} model of {} coordinates and {} constraints, this is a {} model of {} and {}",
                self.kind, self.dim, self.constraints.0, other.kind, other.dim, other.constraints.0
            ));
        }
        if self.method != other.method {
            return Some(format!(
                "it is of a run of method {}, not {}",
                name(self.method),
                name(other.method)
            ));
        }
        if self.dt != other.dt {
            return Some(format!("it is of a run of dt = {:?}, not {:?}", self.dt, other.dt));
        }
        if (self.compensated, self.newton) != (other.compensated, other.newton) {
            return Some(format!(
                "it is of a run with compensated = {}, Newton options {:?}, not {} and {:?}",
                self.compensated, self.newton, other.compensated, other.newton
            ));
        }
        (self.model != other.model).then(|| {
            "it is of another model: this one's Lagrangian, forces or constraints evaluate differently at the \
             checkpoint's state (another parameter, or another model of the same size)"
                .to_string()
        })
    }
}

/// A hash (FNV-1a, 64 bits) of the bits of what `model` computes at `state`'s (q, p, t); an
/// evaluation that fails counts as a mark of its own.
fn evaluations<S: Dynamics + ?Sized>(model: &S, state: &StepperState) -> u64 {
    let (q, p, t) = (state.q(), state.p(), state.t());
    let lagrangian = model.as_lagrangian();
    let n = q.len();
    let mut hash = Fnv(0xcbf2_9ce4_8422_2325);
    let (mut v, mut out) = (vec![0.0; n], vec![0.0; n]);
    let velocity = lagrangian.velocity(q, p, t, &mut v);
    hash.slice(velocity.map(|_| v.as_slice()));
    let value = lagrangian.lagrangian(q, &v, t);
    hash.slice(value.as_ref().map(std::slice::from_ref));
    hash.slice(lagrangian.dl_dq(q, &v, t, &mut out).map(|_| out.as_slice()));
    hash.slice(lagrangian.dl_dv(q, &v, t, &mut out).map(|_| out.as_slice()));
    if lagrangian.is_forced() {
        hash.slice(lagrangian.force(q, &v, t, &mut out).map(|_| out.as_slice()));
    }
    if let Some(residuals) = model.constraint_residuals(q, p) {
        let r = residuals.map(|r| [r.position, r.velocity, r.position_size, r.velocity_size]);
        hash.slice(r.as_ref().map(|r| r.as_slice()));
    }
    hash.0
}

struct Fnv(u64);

impl Fnv {
    fn slice<E>(&mut self, values: Result<&[f64], E>) {
        match values {
            Ok(values) => values.iter().for_each(|v| self.word(v.to_bits())),
            Err(_) => self.word(0xe770_7e77_0e77_07e7),
        }
        self.word(0x5eb);
    }

    fn word(&mut self, w: u64) {
        for byte in w.to_le_bytes() {
            self.0 = (self.0 ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

const MAGIC: &[u8; 8] = b"varmech\x01";
/// The layout of [`StepperState`] and its parts; raise it whenever they change.
pub const FORMAT: u32 = 7;
const HEADER: usize = MAGIC.len() + 4;

impl Checkpoint {
    /// The checkpoint of `state` stepped on `model`, with the run's energy check if any.
    pub(super) fn new<S: Dynamics + ?Sized>(model: &S, state: StepperState, watch: Option<EnergyWatch>) -> Self {
        Checkpoint {
            fingerprint: Fingerprint::of(model, &state),
            state,
            watch,
            fresh_check: None,
        }
    }

    /// The checkpoint of a stepper's state on `model` (no run, so no energy check).
    pub fn of<S: Dynamics + ?Sized>(model: &S, state: &StepperState) -> Self {
        Self::new(model, state.clone(), None)
    }

    /// The state checkpointed, as decoded (not checked against a model: see
    /// `Checkpoint::resume_on`).
    pub fn state(&self) -> &StepperState {
        &self.state
    }

    /// The fingerprint recorded.
    pub fn fingerprint(&self) -> &Fingerprint {
        &self.fingerprint
    }

    /// The state and energy check, to go on with on `model`. Refuses, naming `checkpoint`, a
    /// state that does not fit the model and its method (every length, size and index
    /// checked, see [`shape::misfit`]) and a checkpoint of another model, method or
    /// options (its [`Fingerprint`], naming the first difference); naming `model` or `method`
    /// one of another size or kind ([`super::Stepper::resume`]'s checks).
    pub(super) fn resume_on<S: Dynamics + ?Sized>(
        self,
        model: &S,
    ) -> Result<(StepperState, Option<EnergyWatch>), Error> {
        let refuse = |reason: String| Error::invalid("checkpoint", reason);
        let Checkpoint {
            state,
            watch,
            fingerprint,
            ..
        } = self;
        // A state at odds with its own record is the checkpoint's fault, not the model's.
        if (fingerprint.dim, fingerprint.method) != (state.q().len(), state.method()) {
            return Err(refuse(format!(
                "its state ({} coordinates, method {}) disagrees with its record ({}, {})",
                state.q().len(),
                state.method().info().name,
                fingerprint.dim,
                fingerprint.method.info().name
            )));
        }
        if model.dim() != state.q().len() {
            let reason = format!(
                "has {} coordinates, the checkpoint's state {}",
                model.dim(),
                state.q().len()
            );
            return Err(Error::invalid("model", reason));
        }
        check_method(model, state.method(), state.dt())?;
        if let Some(reason) = shape::misfit(&state, model) {
            return Err(refuse(reason));
        }
        if let Some(reason) = fingerprint.differs(&Fingerprint::of(model, &state)) {
            return Err(refuse(reason));
        }
        if let Some(reason) = derived::misfit(&state, model) {
            return Err(refuse(format!("{reason}: it was edited or damaged")));
        }
        Ok((state, watch))
    }

    /// The energy check of the run going on from here, as `max_energy_error` sets a run's: None
    /// for none; `Some(tolerance)` for one at `tolerance` × the scale, the run's own (its first
    /// energy, scale and growth) where it checked its energy, else one from here. Without a
    /// call, the run's own check goes on as it was.
    pub fn check_energy(&mut self, tolerance: Option<f64>) {
        self.fresh_check = None;
        match (tolerance, self.watch.as_mut()) {
            (None, _) => self.watch = None,
            (Some(tolerance), Some(watch)) => watch.set_tolerance(tolerance),
            (Some(tolerance), None) => self.fresh_check = Some(tolerance),
        }
    }

    /// The stepper's state to go on with on `model`, checked as `Checkpoint::resume_on`
    /// does.
    pub fn into_state<S: Dynamics + ?Sized>(self, model: &S) -> Result<StepperState, Error> {
        self.resume_on(model).map(|(state, _)| state)
    }

    /// Refuses, naming `checkpoint`, a checkpoint of another method or step than the run it is
    /// to continue (the `method` and `dt` a file or trajectory records beside it).
    pub fn expect(&self, method: Option<Method>, dt: Option<f64>) -> Result<(), Error> {
        let f = &self.fingerprint;
        let reason = match (method, dt) {
            (Some(m), _) if m != f.method => format!(
                "it is of a run of method {}, not {}",
                f.method.info().name,
                m.info().name
            ),
            (_, Some(dt)) if dt != f.dt => format!("it is of a run of dt = {:?}, not {dt:?}", f.dt),
            _ => return Ok(()),
        };
        Err(Error::invalid("checkpoint", reason))
    }

    /// The bytes: header, postcard, CRC-32.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&FORMAT.to_le_bytes());
        let payload = postcard::to_stdvec_crc32(self, CRC32.digest());
        bytes.extend(payload.expect("a state serialises (it has no maps and no fallible parts)"));
        bytes
    }

    /// The checkpoint in `bytes`; refuses, naming `checkpoint`, bytes that are not a varmech
    /// checkpoint, of another format, truncated or damaged (CRC).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, Error> {
        let refuse = |reason: String| Error::invalid("checkpoint", reason);
        if bytes.len() < HEADER || &bytes[..MAGIC.len()] != MAGIC {
            return Err(refuse(format!(
                "not a varmech checkpoint ({} bytes without its header)",
                bytes.len()
            )));
        }
        let format = u32::from_le_bytes(bytes[MAGIC.len()..HEADER].try_into().expect("4 bytes"));
        if format != FORMAT {
            return Err(refuse(format!(
                "written in checkpoint format {format}, this varmech reads format {FORMAT}: resume it with the \
                 version that wrote it"
            )));
        }
        postcard::from_bytes_crc32(&bytes[HEADER..], CRC32.digest())
            .map_err(|e| refuse(format!("damaged or truncated ({e})")))
    }
}

static CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);
