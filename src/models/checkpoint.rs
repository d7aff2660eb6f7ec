//! A case's run stopped mid-way and stored as bytes, to be finished later, possibly by another
//! process (issue 17: graceful shutdown).
//!
//! The bytes are a zlib stream of bincode values: first the format version alone, then the
//! header (code version, the case's identity, simulated time), then the
//! [`ModelCheckpoint`]. A reader checks the format and the header before it reads the body,
//! so a checkpoint from another format, code version or case is refused with a reason and the
//! run restarts from t = 0; it is never resumed into a different run. Bincode rather than
//! JSON: serde_json writes non-finite numbers as `null` and cannot read them back, and a run
//! carries some (the infinite pressure of a zero-area track sample, Archard's infinite
//! cutoff); bincode writes every `f64` as its eight bytes, so the round trip is exact by
//! construction. zlib (flate2, already used for the stored tracks) shrinks the recorded track
//! samples the checkpoint carries.
//!
//! What is rebuilt rather than stored: the model (geometry, bodies, contacts, the excitation
//! signal from its seed) and the run options, all from the case. What the run handed to its
//! record sink before the checkpoint (track samples, response, finished parts' reports:
//! `models::run`'s record chunks) is not repeated: the checkpoint holds the records since the
//! last chunk and the chained SHA-256 of the chunks, and [`decode`] takes the chunks back. So
//! a checkpoint's size is bounded by a chunk's worth of records plus the run's state, however
//! long the run.

use super::case::{code_version, resolve_excitation};
use super::outcome::Checkpoint;
use super::run::{BuiltModel, ModelCheckpoint};
use super::spec::CaseSpec;
use bincode::Options;
use flate2::read::ZlibDecoder;
use flate2::write::ZlibEncoder;
use flate2::Compression;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::io::Write;
use std::path::Path;

/// Version of the checkpoint layout; bump it whenever a checkpointed type changes shape.
pub const CHECKPOINT_FORMAT: u32 = 3;

/// Largest checkpoint decoded, bytes (after decompression): a guard against a corrupt length.
const MAX_DECODED_BYTES: u64 = 4 << 30;

fn codec() -> impl Options {
    bincode::DefaultOptions::new()
        .with_fixint_encoding()
        .with_little_endian()
        .with_limit(MAX_DECODED_BYTES)
}

/// What a checkpoint must match to be resumed: the code version and the SHA-256 of the case
/// (its canonical JSON, the resolved excitation, which may come from a named profile file,
/// and the model's initial state).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RunIdentity {
    /// [`code_version`] of the writer.
    pub code_version: String,
    /// Hex SHA-256 of the case.
    pub case_sha256: String,
}

impl RunIdentity {
    /// The identity of `case` built as `model` by this code.
    pub fn of(case: &CaseSpec, model: &BuiltModel, configs_dir: &Path) -> Self {
        let mut hash = Sha256::new();
        hash.update(serde_json::to_string(case).unwrap_or_default().as_bytes());
        hash.update([0]);
        let excitation = resolve_excitation(case, configs_dir)
            .ok()
            .and_then(|e| serde_json::to_string(&e).ok())
            .unwrap_or_default();
        hash.update(excitation.as_bytes());
        hash.update([0]);
        for x in &model.initial_state {
            hash.update(x.to_le_bytes());
        }
        hash.update(model.end_time_s.to_le_bytes());
        Self {
            code_version: code_version().to_string(),
            case_sha256: hash.finalize().iter().map(|b| format!("{b:02x}")).collect(),
        }
    }
}

#[derive(Debug, Serialize, Deserialize)]
struct Header {
    identity: RunIdentity,
    simulated_time_s: f64,
    end_time_s: f64,
    finished_parts: u64,
}

/// Why a checkpoint was not resumed (the run restarts from t = 0).
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// Written in another layout.
    #[error("checkpoint format {found}, this code reads format {CHECKPOINT_FORMAT}")]
    Format { found: u32 },
    /// Written by another code version.
    #[error("checkpoint of code version {found}, this is {}", code_version())]
    CodeVersion { found: String },
    /// Written for another case.
    #[error("checkpoint of another case (SHA-256 {found}, this case {expected})")]
    Case { found: String, expected: String },
    /// Unreadable.
    #[error("unreadable checkpoint: {0}")]
    Decode(String),
    /// The record chunks given are not those the checkpoint follows.
    #[error("checkpoint without its records: {0}")]
    Records(String),
    /// Could not be written.
    #[error("checkpoint could not be encoded: {0}")]
    Encode(String),
}

/// Encodes the checkpoint of the run identified by `identity`.
pub fn encode(identity: &RunIdentity, cp: &ModelCheckpoint) -> Result<Checkpoint, CheckpointError> {
    let header = Header {
        identity: identity.clone(),
        simulated_time_s: cp.time_s(),
        end_time_s: cp.end_time_s(),
        finished_parts: cp.finished_parts() as u64,
    };
    let enc = |e: bincode::Error| CheckpointError::Encode(e.to_string());
    let mut z = ZlibEncoder::new(Vec::new(), Compression::fast());
    codec()
        .serialize_into(&mut z, &CHECKPOINT_FORMAT)
        .map_err(enc)?;
    codec().serialize_into(&mut z, &header).map_err(enc)?;
    codec().serialize_into(&mut z, cp).map_err(enc)?;
    z.flush()
        .map_err(|e| CheckpointError::Encode(e.to_string()))?;
    let bytes = z
        .finish()
        .map_err(|e| CheckpointError::Encode(e.to_string()))?;
    Ok(Checkpoint {
        simulated_time_s: header.simulated_time_s,
        end_time_s: header.end_time_s,
        bytes,
    })
}

/// Decodes a checkpoint for the run identified by `expected`, with the record chunks the run
/// wrote before it (in order from the first; none for a run without a record sink): the
/// format, code version and case are checked before the body is read, the chunks' chain
/// after.
pub fn decode(
    bytes: &[u8],
    expected: &RunIdentity,
    record_chunks: &[Vec<u8>],
) -> Result<ModelCheckpoint, CheckpointError> {
    let dec = |e: bincode::Error| CheckpointError::Decode(e.to_string());
    let mut z = ZlibDecoder::new(bytes);
    let format: u32 = codec().deserialize_from(&mut z).map_err(dec)?;
    if format != CHECKPOINT_FORMAT {
        return Err(CheckpointError::Format { found: format });
    }
    let header: Header = codec().deserialize_from(&mut z).map_err(dec)?;
    if header.identity.code_version != expected.code_version {
        return Err(CheckpointError::CodeVersion {
            found: header.identity.code_version,
        });
    }
    if header.identity.case_sha256 != expected.case_sha256 {
        return Err(CheckpointError::Case {
            found: header.identity.case_sha256,
            expected: expected.case_sha256.clone(),
        });
    }
    let mut cp: ModelCheckpoint = codec().deserialize_from(&mut z).map_err(dec)?;
    if cp.time_s().to_bits() != header.simulated_time_s.to_bits()
        || cp.finished_parts() as u64 != header.finished_parts
    {
        return Err(CheckpointError::Decode(
            "the header does not match the body".into(),
        ));
    }
    cp.restore_records(record_chunks)
        .map_err(CheckpointError::Records)?;
    Ok(cp)
}
