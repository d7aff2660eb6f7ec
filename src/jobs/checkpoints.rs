//! What a worker keeps of a running simulation for the next attempt: the record chunks the run
//! hands over as it goes and the checkpoint it stops with at shutdown, both written only while
//! the attempt holds the lease, and the checkpoint read back when a job is claimed again
//! (docs/reference/operations.md, "Checkpoints and the shutdown grace").

use super::Jobs;
use crate::pipeline::RecordChunk;
use crate::store::{clock, JobCheckpoint, NewCheckpoint};
use std::time::{Duration, Instant};

impl Jobs {
    /// The checkpoint stored for job `id` by an earlier attempt, if any.
    pub(super) async fn stored_checkpoint(
        &self,
        id: uuid::Uuid,
        attempt: i64,
    ) -> Option<JobCheckpoint> {
        match self.store.load_checkpoint(id).await {
            Ok(Some(cp)) => {
                tracing::info!(
                    job = %id,
                    attempt,
                    from_attempt = cp.attempt,
                    simulated_s = cp.simulated_s,
                    "resuming from the stored checkpoint"
                );
                Some(cp)
            }
            Ok(None) => None,
            Err(e) => {
                tracing::warn!(job = %id, attempt, error = %e, "reading the checkpoint failed: running from the start");
                None
            }
        }
    }

    /// Store a record chunk of attempt `attempt`'s run (fenced by the attempt; retried on
    /// transient errors). One that never lands leaves a gap: a checkpoint that follows it is
    /// then refused and the next attempt starts over.
    pub(super) async fn save_record_chunk(&self, id: uuid::Uuid, attempt: i64, chunk: RecordChunk) {
        for retry in 0..3u32 {
            match self
                .store
                .save_record_chunk(id, attempt, chunk.seq, chunk.bytes.clone())
                .await
            {
                Ok(true) => return,
                Ok(false) => {
                    tracing::debug!(job = %id, attempt, seq = chunk.seq, "stale attempt; record chunk discarded");
                    return;
                }
                Err(e) => {
                    tracing::warn!(job = %id, attempt, retry, seq = chunk.seq, error = %e, "storing a record chunk failed");
                    tokio::time::sleep(Duration::from_millis(100 << retry)).await;
                }
            }
        }
    }

    /// Store the checkpoint attempt `attempt` stopped with (fenced by the attempt; retried on
    /// transient errors). Its simulated time once stored.
    pub(super) async fn save_checkpoint(
        &self,
        id: uuid::Uuid,
        attempt: i64,
        cp: crate::pipeline::Checkpoint,
    ) -> Option<f64> {
        let t = cp.simulated_time_s;
        let new = NewCheckpoint {
            simulated_s: t,
            end_s: cp.end_time_s,
            data: cp.bytes,
        };
        for retry in 0..3u32 {
            let writing = Instant::now();
            match self
                .store
                .save_checkpoint(id, attempt, new.clone(), clock::now_ms())
                .await
            {
                Ok(true) => {
                    let write_ms = writing.elapsed().as_secs_f64() * 1e3;
                    tracing::info!(job = %id, attempt, simulated_s = t, bytes = new.data.len(), write_ms, "checkpoint stored");
                    return Some(t);
                }
                Ok(false) => {
                    tracing::warn!(job = %id, attempt, "stale attempt; checkpoint discarded");
                    return None;
                }
                Err(e) => {
                    tracing::warn!(job = %id, attempt, retry, error = %e, "storing the checkpoint failed");
                    tokio::time::sleep(Duration::from_millis(100 << retry)).await;
                }
            }
        }
        None
    }
}
