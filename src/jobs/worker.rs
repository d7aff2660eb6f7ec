//! The embedded worker pool. Each worker loops: re-queue expired leases, claim the oldest queued
//! job, run it on a blocking thread while a heartbeat renews the lease and writes progress, then
//! end the attempt with a fenced write (a stale attempt's result is discarded).

use super::model::{JobProgress, JobRecord, JobStatus};
use super::Jobs;
use crate::pipeline::{Progress, RunControl, RunError};
use crate::store::{clock, tracks, CurveRecord, Finish};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tokio::task::JoinHandle;

impl Jobs {
    /// Start `count` workers named `<prefix>-<i>`; they run until the runtime shuts down.
    pub fn spawn_workers(self: &Arc<Self>, count: usize, prefix: &str) -> Vec<JoinHandle<()>> {
        (0..count)
            .map(|i| {
                let jobs = Arc::clone(self);
                let name = format!("{prefix}-{i}");
                tokio::spawn(async move { jobs.worker_loop(name).await })
            })
            .collect()
    }

    async fn worker_loop(self: Arc<Self>, worker: String) {
        let lease_ms = self.settings.lease.as_millis() as i64;
        loop {
            let now = clock::now_ms();
            if let Err(e) = self
                .store
                .requeue_expired(now, i64::from(self.settings.max_attempts))
                .await
            {
                tracing::warn!(%worker, error = %e, "re-queue of expired leases failed");
            }
            match self.store.claim_job(&worker, now, lease_ms).await {
                Ok(Some(job)) => self.run_attempt(&worker, job).await,
                Ok(None) => {
                    tokio::select! {
                        _ = self.wake.notified() => {}
                        _ = tokio::time::sleep(self.settings.poll) => {}
                    }
                }
                Err(e) => {
                    tracing::warn!(%worker, error = %e, "claim failed");
                    tokio::time::sleep(self.settings.poll).await;
                }
            }
        }
    }

    async fn run_attempt(self: &Arc<Self>, worker: &str, job: JobRecord) {
        let (id, attempt, kind) = (job.id, job.attempt, job.kind);
        tracing::info!(%worker, job = %id, attempt, kind = kind.as_str(), "attempt started");
        let cancel = Arc::new(AtomicBool::new(job.cancel_requested));
        self.running_flags().insert(id, Arc::clone(&cancel));
        self.metrics.attempt_started(id);

        let latest: Arc<Mutex<Option<Progress>>> = Arc::new(Mutex::new(None));
        let sink = Arc::clone(&latest);
        let control = RunControl {
            cancel: Arc::clone(&cancel),
            progress: Arc::new(move |p: Progress| {
                if let Ok(mut slot) = sink.lock() {
                    *slot = Some(p);
                }
            }),
        };
        let mut params = job.params.clone();
        if let Some(map) = params.as_object_mut() {
            map.insert("seed".into(), serde_json::Value::from(job.seed));
        }
        let runner = Arc::clone(&self.runner);
        let mut computation =
            tokio::task::spawn_blocking(move || runner.run(&kind, &params, &control));

        let started = Instant::now();
        let lease_ms = self.settings.lease.as_millis() as i64;
        let mut ticker = tokio::time::interval(self.settings.heartbeat);
        ticker.tick().await; // the first tick is immediate
        let mut lost = false;
        let outcome = loop {
            tokio::select! {
                result = &mut computation => break result,
                _ = ticker.tick() => {
                    let progress = latest
                        .lock()
                        .ok()
                        .and_then(|p| *p)
                        .map(|p| job_progress(p, started.elapsed()));
                    if let Some(p) = progress {
                        self.metrics.attempt_progress(id, p.simulated_time_s);
                    }
                    match self
                        .store
                        .heartbeat(id, attempt, progress, clock::now_ms(), lease_ms)
                        .await
                    {
                        Ok(beat) => {
                            if !beat.owned {
                                // A newer attempt owns the job (our lease expired): stop.
                                lost = true;
                                cancel.store(true, Ordering::Relaxed);
                            } else if beat.cancel_requested {
                                cancel.store(true, Ordering::Relaxed);
                            }
                        }
                        Err(e) => tracing::warn!(job = %id, error = %e, "heartbeat failed"),
                    }
                }
            }
        };

        // Write the last progress the computation reported (a short run may end before the
        // first heartbeat).
        let last = latest
            .lock()
            .ok()
            .and_then(|p| *p)
            .map(|p| job_progress(p, started.elapsed()));
        if let (Some(p), false) = (last, lost) {
            self.metrics.attempt_progress(id, p.simulated_time_s);
            if let Ok(beat) = self
                .store
                .heartbeat(id, attempt, Some(p), clock::now_ms(), lease_ms)
                .await
            {
                lost = !beat.owned;
            }
        }

        let finish = match outcome {
            Ok(Ok(output)) => {
                let block_samples = self.settings.track_block_samples;
                let tracks = output.tracks;
                let blocks = tokio::task::spawn_blocking(move || {
                    tracks::encode_blocks(&tracks, block_samples)
                })
                .await
                .unwrap_or_default();
                let curve = match (output.penalization, &job.curve_key) {
                    (Some(data), Some(key)) => Some(CurveRecord {
                        key: key.clone(),
                        job_id: id,
                        curve: serde_json::to_value(&data).unwrap_or_default(),
                        created_ms: clock::now_ms(),
                    }),
                    _ => None,
                };
                Finish::Succeeded {
                    summary: output.summary,
                    blocks,
                    plots: output.plots,
                    curve,
                }
            }
            Ok(Err(RunError::Cancelled)) => Finish::Cancelled,
            Ok(Err(e)) => Finish::Failed(e.to_string()),
            Err(join) => {
                tracing::error!(job = %id, error = %join, "computation panicked");
                Finish::Failed("internal error: the computation panicked".into())
            }
        };
        let status = match &finish {
            Finish::Succeeded { .. } => JobStatus::Succeeded,
            Finish::Failed(_) => JobStatus::Failed,
            Finish::Cancelled => JobStatus::Cancelled,
        };
        self.running_flags().remove(&id);
        self.metrics.attempt_finished(id, kind, status);
        if lost {
            tracing::warn!(job = %id, attempt, "lease lost to a newer attempt; result discarded");
            return;
        }
        // A finish that fails on a transient database error is retried; a fenced-out one is not.
        for retry in 0..5u32 {
            match self
                .store
                .finish_job(id, attempt, finish.clone(), clock::now_ms())
                .await
            {
                Ok(true) => {
                    tracing::info!(job = %id, attempt, status = status.as_str(), "attempt finished");
                    return;
                }
                Ok(false) => {
                    tracing::warn!(job = %id, attempt, "stale attempt; result discarded");
                    return;
                }
                Err(e) => {
                    tracing::warn!(job = %id, attempt, retry, error = %e, "finish failed");
                    tokio::time::sleep(Duration::from_millis(200 << retry)).await;
                }
            }
        }
    }
}

/// Stored progress with an ETA from the attempt's rate so far.
fn job_progress(p: Progress, elapsed: Duration) -> JobProgress {
    let fraction = if p.fraction.is_finite() {
        p.fraction.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let eta_s = (fraction > 0.0).then(|| elapsed.as_secs_f64() * (1.0 - fraction) / fraction);
    JobProgress {
        simulated_time_s: p.simulated_time_s,
        end_time_s: p.end_time_s,
        fraction,
        eta_s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eta_is_linear_extrapolation() {
        let p = Progress {
            simulated_time_s: 1.0,
            end_time_s: 4.0,
            fraction: 0.25,
        };
        let jp = job_progress(p, Duration::from_secs(10));
        // 25 % took 10 s, so 75 % takes 30 s more.
        assert!((jp.eta_s.unwrap() - 30.0).abs() < 1e-9);
        let nan = Progress {
            fraction: f64::NAN,
            ..p
        };
        assert_eq!(job_progress(nan, Duration::from_secs(1)).eta_s, None);
    }
}
