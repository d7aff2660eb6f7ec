//! What a case run gives its caller: the packaged [`CaseOutcome`] (summary JSON, track samples,
//! SVG plots) or why there is none, [`RunError`] (the one error of a model run, from a bad
//! configuration to a checkpointed stop, which carries the stopped run's [`Checkpoint`]: its
//! bytes, encoded and decoded by [`super::checkpoint`]). `pipeline` re-exports both for the
//! jobs.

use crate::physics::track::TrackSample;

/// What a finished case produces.
#[derive(Debug, Clone)]
pub struct CaseOutcome {
    /// Summary: wear per contact and body (mg, mg/h), above-cutoff work share, pressure PDFs,
    /// spectra, settings used. JSON object.
    pub summary: serde_json::Value,
    /// Recorded contact-track samples (may be many).
    pub tracks: Vec<TrackSample>,
    /// Named SVG plots: (file name, SVG text).
    pub plots: Vec<(String, String)>,
}

/// Why a run did not produce an outcome.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The configuration broke a rule; `field` is a dotted path into the config.
    #[error("invalid configuration: field `{field}` {rule}")]
    InvalidConfig { field: String, rule: String },
    /// The simulation diverged; the message names time, body, contact and energy.
    #[error("simulation diverged: {0}")]
    Diverged(String),
    /// Cancelled through
    /// [`RunControl::cancel`](crate::physics::control::RunControl::cancel).
    #[error("cancelled")]
    Cancelled,
    /// Stopped with a checkpoint
    /// ([`RunControl::request_checkpoint`](crate::physics::control::RunControl::request_checkpoint)):
    /// handing its bytes to the same computation again resumes it
    /// (`pipeline::run_case_from`).
    #[error("checkpointed at t = {:.6} s", .0.simulated_time_s)]
    Checkpointed(Box<Checkpoint>),
}

/// A field error is an invalid configuration (the variant keeps its named fields, which
/// callers and tests construct).
impl From<crate::field_error::FieldError> for RunError {
    fn from(
        crate::field_error::FieldError { field, rule }: crate::field_error::FieldError,
    ) -> Self {
        RunError::InvalidConfig { field, rule }
    }
}

/// A stopped run as its caller kept it, to resume from: the checkpoint's bytes and the record
/// chunks the run handed to its record sink
/// ([`RunControl::record_sink`](crate::physics::control::RunControl)) before it, in order from
/// the first (empty when it had no sink).
#[derive(Debug, Clone, Copy)]
pub struct SavedRun<'a> {
    /// [`Checkpoint::bytes`].
    pub checkpoint: &'a [u8],
    /// The record chunks' bytes.
    pub record_chunks: &'a [Vec<u8>],
}

impl<'a> SavedRun<'a> {
    /// A checkpoint of a run that wrote no record chunks.
    pub fn without_chunks(checkpoint: &'a [u8]) -> Self {
        Self {
            checkpoint,
            record_chunks: &[],
        }
    }
}

/// A stored checkpoint: its bytes and where it stands.
#[derive(Clone, PartialEq)]
pub struct Checkpoint {
    /// Simulated time of the run in progress, s.
    pub simulated_time_s: f64,
    /// End of that run, s.
    pub end_time_s: f64,
    /// The encoded checkpoint.
    pub bytes: Vec<u8>,
}

impl std::fmt::Debug for Checkpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Checkpoint")
            .field("simulated_time_s", &self.simulated_time_s)
            .field("end_time_s", &self.end_time_s)
            .field("bytes", &self.bytes.len())
            .finish()
    }
}
