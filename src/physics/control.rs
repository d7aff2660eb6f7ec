//! The engine's run hooks: a cancellation flag, a checkpoint request, a progress sink and a
//! sink for the run's recorded samples the caller hands to
//! [`simulate`](super::simulate::simulate) (the engine owns its hooks, as rapier's pipeline
//! does; the service passes them in through `pipeline`).

use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Progress of a running simulation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    /// Simulated time reached, s.
    pub simulated_time_s: f64,
    /// Simulated time at which the run ends, s.
    pub end_time_s: f64,
    /// Fraction done in [0, 1].
    pub fraction: f64,
}

/// Cancellation flag, checkpoint request and progress sink handed to a run.
#[derive(Clone)]
pub struct RunControl {
    /// Set to true to stop the run; it returns a cancellation error within a second.
    pub cancel: Arc<AtomicBool>,
    /// Set together with `cancel` ([`RunControl::request_checkpoint`]) to stop the run with a
    /// checkpoint of its state instead of a cancellation: a simulation returns it at its next
    /// accepted step. A computation that cannot checkpoint sees only `cancel`.
    pub checkpoint: Arc<AtomicBool>,
    /// Called from the simulation thread: at the start, after an accepted step once
    /// `progress_interval` of wall time has passed since the last call, and at the end.
    pub progress: Arc<dyn Fn(Progress) + Send + Sync>,
    /// Least wall time between two progress calls ([`DEFAULT_PROGRESS_INTERVAL`]). Zero calls
    /// the sink after every accepted step, so a sink that acts on the simulated time acts at
    /// the same step in every run (deterministic tests of checkpoints).
    pub progress_interval: std::time::Duration,
    /// Where a run that can checkpoint writes its recorded samples as they accumulate (None:
    /// they stay in the run and a checkpoint carries them all). What is handed here is not
    /// repeated in a checkpoint, so a checkpoint stays small however long the run; resuming
    /// needs the chunks back (`models::checkpoint`).
    pub record_sink: Option<RecordSink>,
}

/// Where a run's recorded samples go as they accumulate, and how many make a chunk.
#[derive(Clone)]
pub struct RecordSink {
    /// Samples of one record (track samples, or response samples) that make a chunk: a
    /// checkpoint carries fewer than this many of each. Larger chunks mean fewer writes and a
    /// larger checkpoint; at least 1.
    pub chunk_samples: usize,
    /// Called from the simulation thread with each chunk, in order.
    pub write: Arc<dyn Fn(RecordChunk) + Send + Sync>,
}

/// One chunk of a run's recorded samples, in the order the run wrote them: the `seq`-th since
/// t = 0 (a resumed run goes on counting from its checkpoint). Opaque bytes to the caller.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordChunk {
    /// Position in the run's sequence of chunks, from 0.
    pub seq: u64,
    /// The encoded chunk.
    pub bytes: Vec<u8>,
}

/// Wall time between progress calls of a [`RunControl::new`] control: 200 ms, a few
/// heartbeats per second without measurable cost.
pub const DEFAULT_PROGRESS_INTERVAL: std::time::Duration = std::time::Duration::from_millis(200);

impl RunControl {
    /// A control with this cancel flag and progress sink and no checkpoint request.
    pub fn new(cancel: Arc<AtomicBool>, progress: Arc<dyn Fn(Progress) + Send + Sync>) -> Self {
        Self {
            cancel,
            checkpoint: Arc::new(AtomicBool::new(false)),
            progress,
            progress_interval: DEFAULT_PROGRESS_INTERVAL,
            record_sink: None,
        }
    }

    /// A control that is never cancelled and drops progress.
    pub fn silent() -> Self {
        Self::new(Arc::new(AtomicBool::new(false)), Arc::new(|_| {}))
    }

    /// True once cancellation (or a checkpoint) was requested.
    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::SeqCst)
    }

    /// True once a checkpoint was requested. Read it after [`Self::is_cancelled`] returned
    /// true: the request sets this flag first, so a run that sees the cancellation also sees
    /// the request.
    pub fn checkpoint_requested(&self) -> bool {
        self.checkpoint.load(Ordering::SeqCst)
    }

    /// Asks the run to stop with a checkpoint (a computation that cannot checkpoint stops as
    /// cancelled).
    pub fn request_checkpoint(&self) {
        self.checkpoint.store(true, Ordering::SeqCst);
        self.cancel.store(true, Ordering::SeqCst);
    }

    /// The same cancel flag and progress sink without the checkpoint request and the record
    /// sink: for runs whose caller cannot keep a checkpoint (a request then stops them as a
    /// cancellation).
    pub fn without_checkpoint(&self) -> Self {
        Self {
            progress_interval: self.progress_interval,
            ..Self::new(self.cancel.clone(), self.progress.clone())
        }
    }
}
