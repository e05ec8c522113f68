//! A run's whole state at a step, as bytes, to go on from later (in another process, after a
//! crash) bit for bit.

use serde::{Deserialize, Serialize};

use super::run::EnergyWatch;
use super::StepperState;
use crate::Error;

/// Everything a run needs to go on from step n as if it had never stopped: the stepper's state
/// ([`StepperState`]: (tₙ, qₙ, pₙ), the compensated-summation carries (e_q, e_p), the method's
/// caches (the force of first same as last), the Newton and multiplier predictors, the
/// Wisdom–Holman inner variables, the counts and the clock) and the run's energy check.
///
/// [`Checkpoint::to_bytes`] writes it as a header (`MAGIC`, then the format number as a
/// little-endian u32) and serde's data model of the state in postcard's wire format
/// (<https://postcard.jamesmunns.com/wire-format>) with a trailing CRC-32, so that a damaged
/// checkpoint is refused rather than resumed. Only the library that wrote it reads it back to
/// the same bits: the format number changes whenever the state's layout does.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    pub(super) state: StepperState,
    pub(super) watch: Option<EnergyWatch>,
}

const MAGIC: &[u8; 8] = b"varmech\x01";
/// The layout of [`StepperState`] and its parts; raise it whenever they change.
pub const FORMAT: u32 = 2;
const HEADER: usize = MAGIC.len() + 4;

impl Checkpoint {
    /// The checkpoint of a stepper's state (no run, so no energy check).
    pub fn of(state: &StepperState) -> Self {
        Checkpoint {
            state: state.clone(),
            watch: None,
        }
    }

    /// The stepper's state, to [`super::Stepper::resume`] on its model.
    pub fn into_state(self) -> StepperState {
        self.state
    }

    /// The state checkpointed.
    pub fn state(&self) -> &StepperState {
        &self.state
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
