//! The embedded worker pool. Each worker loops: re-queue expired leases, claim the oldest queued
//! job, run it on a blocking thread while a heartbeat renews the lease and writes progress, then
//! end the attempt with a fenced write (a stale attempt's result is discarded).
//!
//! At shutdown a running attempt is asked for a checkpoint ([`RunControl::request_checkpoint`]):
//! a simulation stops at its next accepted step with its complete state, which is stored
//! (fenced by the attempt) before the job is released; the next attempt resumes from it. A
//! computation that cannot checkpoint stops as cancelled and the job is released without one.
//! While it runs, a simulation hands its growing records to the attempt in chunks
//! ([`RunControl::record_sink`]), which stores them as they come: the checkpoint written at
//! shutdown then holds only the run's state and the records since the last chunk, so its
//! write time is bounded however long the run (docs/reference/operations.md).
//!
//! A job the runner splits ([`super::CaseRunner::fan_out`], a sweep) is not run: the attempt
//! stores its child jobs and leaves it waiting. When its last child succeeds the store re-queues
//! it, and the attempt that claims it then assembles its result from the children's results.

use super::inputs::JobInputs;
use super::model::{JobKind, JobProgress, JobRecord, JobStatus};
use super::runner::FanOutPlan;
use super::Jobs;
use crate::pipeline::{Progress, RecordChunk, RecordSink, RunControl, RunError, SavedRun};
use crate::store::{
    clock, tracks, CurveFidelity, FanOut, FanOutResult, Finish, NewChild, NewCurve, ReleaseOutcome,
};
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
        let mut stopping = self.stopping();
        loop {
            if *stopping.borrow_and_update() {
                tracing::info!(%worker, "worker stopped");
                return;
            }
            let now = clock::now_ms();
            if let Err(e) = self
                .store
                .requeue_expired(now, i64::from(self.settings.max_attempts))
                .await
            {
                tracing::warn!(%worker, error = %e, "re-queue of expired leases failed");
            }
            match self
                .store
                .claim_job_on(&worker, Some(&self.host), now, lease_ms)
                .await
            {
                Ok(Some(job)) => self.run_attempt(&worker, job).await,
                Ok(None) => {
                    tokio::select! {
                        _ = self.wake.notified() => {}
                        _ = tokio::time::sleep(self.settings.poll) => {}
                        _ = stopping.changed() => {}
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
        let mut params = job.params.clone();
        if let Some(map) = params.as_object_mut() {
            map.insert("seed".into(), serde_json::Value::from(job.seed));
        }
        // The plan stored at submission is what a job with one runs, fans out or assembles.
        let plan = self.stored_plan(id).await;
        // What this attempt does: assemble a fanned-out job whose children all succeeded, fan
        // a job out, or run it whole.
        let work = if job.children.is_some() {
            match self.store.children(id).await {
                Ok(children) => Work::Assemble(children_summaries(children)),
                Err(e) => {
                    // The lease expires and another attempt assembles.
                    tracing::warn!(job = %id, attempt, error = %e, "reading the children failed");
                    return;
                }
            }
        } else {
            let runner = Arc::clone(&self.runner);
            let (plan_params, stored) = (params.clone(), plan.clone());
            let fan_out = move || runner.fan_out(&kind, &plan_params, stored.as_ref());
            match tokio::task::spawn_blocking(fan_out).await {
                Ok(Ok(Some(plan))) => return self.fan_out(&job, plan).await,
                Ok(Ok(None)) => self.run_work(id, &kind, &params, plan.as_ref()).await,
                Ok(Err(e)) => Work::Refused(e),
                Err(join) => {
                    tracing::error!(job = %id, error = %join, "fan-out planning panicked");
                    Work::Refused(RunError::Diverged(
                        "internal error: the fan-out planning panicked".into(),
                    ))
                }
            }
        };
        // A checkpoint an earlier attempt stored at its shutdown: this attempt resumes from it.
        let resume = match work {
            Work::Run(_) => self.stored_checkpoint(id, attempt).await,
            _ => None,
        };
        // The record chunks the checkpoint follows (the library checks which it needs).
        let record_chunks = match &resume {
            Some(_) => self.store.load_record_chunks(id).await.unwrap_or_else(|e| {
                tracing::warn!(job = %id, attempt, error = %e, "reading the record chunks failed: the checkpoint will not fit");
                Vec::new()
            }),
            None => Vec::new(),
        };
        let cancel = Arc::new(AtomicBool::new(job.cancel_requested));
        let checkpoint = Arc::new(AtomicBool::new(false));
        self.running_flags().insert(id, Arc::clone(&cancel));
        self.metrics.attempt_started(id);
        if let Some(cp) = &resume {
            self.metrics.attempt_resumed(id, cp.simulated_s);
            // The job's progress starts at the checkpoint's time.
            let progress = crate::jobs::JobProgress {
                simulated_time_s: cp.simulated_s,
                end_time_s: cp.end_s,
                fraction: if cp.end_s > 0.0 {
                    (cp.simulated_s / cp.end_s).clamp(0.0, 1.0)
                } else {
                    0.0
                },
                eta_s: None,
            };
            let lease_ms = self.settings.lease.as_millis() as i64;
            if let Err(e) = self
                .store
                .heartbeat(id, attempt, Some(progress), clock::now_ms(), lease_ms)
                .await
            {
                tracing::warn!(job = %id, error = %e, "heartbeat failed");
            }
        }

        let latest: Arc<Mutex<Option<Progress>>> = Arc::new(Mutex::new(None));
        let sink = Arc::clone(&latest);
        let (chunk_tx, mut chunks) = tokio::sync::mpsc::unbounded_channel::<RecordChunk>();
        let control = RunControl {
            progress_interval: crate::pipeline::DEFAULT_PROGRESS_INTERVAL,
            cancel: Arc::clone(&cancel),
            checkpoint: Arc::clone(&checkpoint),
            progress: Arc::new(move |p: Progress| {
                if let Ok(mut slot) = sink.lock() {
                    *slot = Some(p);
                }
            }),
            record_sink: Some(RecordSink {
                chunk_samples: self.settings.record_chunk_samples,
                write: Arc::new(move |chunk: RecordChunk| {
                    // The attempt may be gone (grace spent): the chunk is then not needed.
                    let _ = chunk_tx.send(chunk);
                }),
            }),
        };
        let stop = control.clone();
        let runner = Arc::clone(&self.runner);
        let mut computation = tokio::task::spawn_blocking(move || match work {
            Work::Run(inputs) => runner.run_from(
                &kind,
                &params,
                plan.as_ref(),
                &inputs,
                &control,
                resume.as_ref().map(|c| SavedRun {
                    checkpoint: &c.data,
                    record_chunks: &record_chunks,
                }),
            ),
            Work::Assemble(Ok(summaries)) => {
                runner.assemble(&kind, &params, plan.as_ref(), &summaries)
            }
            Work::Assemble(Err(e)) | Work::Refused(e) => Err(e),
        });

        let started = Instant::now();
        let lease_ms = self.settings.lease.as_millis() as i64;
        let mut ticker = tokio::time::interval(self.settings.heartbeat);
        ticker.tick().await; // the first tick is immediate
        let mut lost = false;
        // Shutdown: the computation is asked for a checkpoint (a simulation stops with one at
        // its next accepted step; any other computation stops as cancelled) and the job is
        // given back by `give_back_by` at the latest.
        let mut stopping = self.stopping();
        let mut give_back_by: Option<tokio::time::Instant> = None;
        let outcome = loop {
            tokio::select! {
                result = &mut computation => break Some(result),
                Some(chunk) = chunks.recv() => self.save_record_chunk(id, attempt, chunk).await,
                _ = shutdown_begun(&mut stopping), if give_back_by.is_none() => {
                    tracing::info!(job = %id, attempt, "shutdown: asking the attempt for a checkpoint to give its job back");
                    stop.request_checkpoint();
                    give_back_by = Some(tokio::time::Instant::now() + self.settings.shutdown_grace);
                }
                _ = tokio::time::sleep_until(give_back_by.unwrap_or_else(tokio::time::Instant::now)),
                    if give_back_by.is_some() => break None,
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

        let Some(outcome) = outcome else {
            // The grace ran out: give the job back now; the computation is left to the
            // process's exit (a late result would be fenced out by the next attempt).
            self.running_flags().remove(&id);
            self.metrics.attempt_released(id, None);
            tracing::warn!(job = %id, attempt, "the shutdown grace ran out: released without a checkpoint");
            return self.give_back(id, attempt).await;
        };
        // A checkpoint is a stop like a cancellation, with the state to resume from.
        let (outcome, saved) = match outcome {
            Ok(Err(RunError::Checkpointed(cp))) => (Ok(Err(RunError::Cancelled)), Some(*cp)),
            other => (other, None),
        };
        let released =
            give_back_by.is_some() && matches!(outcome, Ok(Err(RunError::Cancelled))) && !lost;

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
                    (Some(data), Some(key)) => {
                        Some(Box::new(new_curve(&job, key, &data, output.curve_info)))
                    }
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
        if released {
            // Stopped for the shutdown, not cancelled by anyone: back to the queue, with the
            // checkpoint stored first (while this attempt still holds the lease).
            self.running_flags().remove(&id);
            let checkpoint_s = match saved {
                Some(cp) => {
                    // The chunks the checkpoint follows are stored before it.
                    while let Ok(chunk) = chunks.try_recv() {
                        self.save_record_chunk(id, attempt, chunk).await;
                    }
                    self.save_checkpoint(id, attempt, cp).await
                }
                None => None,
            };
            self.metrics.attempt_released(id, checkpoint_s);
            return self.give_back(id, attempt).await;
        }
        let status = finish.status();
        self.running_flags().remove(&id);
        match job.started_ms {
            // A fanned-out job's duration is the whole job's, from its first claim.
            Some(first_claim) if job.children.is_some() => {
                let whole_s = (clock::now_ms() - first_claim) as f64 / 1000.0;
                self.metrics
                    .fanned_out_job_finished(id, kind, status, whole_s);
            }
            _ => self.metrics.attempt_finished(id, kind, status),
        }
        if lost {
            tracing::warn!(job = %id, attempt, "lease lost to a newer attempt; result discarded");
            return;
        }
        self.finish(id, attempt, finish).await;
        if let (Some(child_of), JobStatus::Failed | JobStatus::Cancelled) = (job.parent, status) {
            self.observe_parent_end(child_of.parent_id, id).await;
        }
    }

    /// After child `child` ended unsuccessfully: when that failed its parent (the parent's
    /// error names this child; the store writes it in the child's finishing transaction), the
    /// parent ended without an attempt of its own, and its whole duration goes to the
    /// histogram here, once.
    async fn observe_parent_end(&self, parent: uuid::Uuid, child: uuid::Uuid) {
        let Ok(Some(record)) = self.store.get_job(parent).await else {
            return;
        };
        let named = record
            .error
            .as_deref()
            .is_some_and(|e| e.contains(&format!("(job {child})")));
        if let (JobStatus::Failed, true, Some(started), Some(finished)) =
            (record.status, named, record.started_ms, record.finished_ms)
        {
            self.metrics.job_ended(
                record.kind,
                record.status,
                (finished - started) as f64 / 1000.0,
            );
        }
    }

    /// Running job `id` whole: with the stored inputs its runner names, read once here (or
    /// refused, naming the input that cannot be read).
    async fn run_work(
        &self,
        id: uuid::Uuid,
        kind: &JobKind,
        params: &serde_json::Value,
        plan: Option<&serde_json::Value>,
    ) -> Work {
        let wanted = match self.runner.stored_inputs(kind, params, plan) {
            Ok(wanted) => wanted,
            Err(e) => return Work::Refused(e),
        };
        if wanted.is_empty() {
            return Work::Run(JobInputs::default());
        }
        match JobInputs::read(self.store.as_ref(), &wanted).await {
            Ok(inputs) => Work::Run(inputs),
            Err(e) => {
                tracing::warn!(job = %id, error = %e, "reading the job's stored inputs failed");
                Work::Refused(e)
            }
        }
    }

    /// The plan stored with job `id` at submission. A job without one (its kind has none, or
    /// it was queued before plans were stored) is planned from its params by the runner; so is
    /// one whose plan cannot be read now (logged).
    async fn stored_plan(&self, id: uuid::Uuid) -> Option<serde_json::Value> {
        match self.store.job_plan(id).await {
            Ok(plan) => plan,
            Err(e) => {
                tracing::warn!(job = %id, error = %e, "reading the job's plan failed: planning from its params");
                None
            }
        }
    }

    /// Give attempt `attempt` back to the queue (shutdown). A cancellation requested
    /// meanwhile ends it as cancelled instead.
    async fn give_back(&self, id: uuid::Uuid, attempt: i64) {
        for retry in 0..3u32 {
            match self.store.release_job(id, attempt, clock::now_ms()).await {
                Ok(ReleaseOutcome::Released) => {
                    tracing::info!(job = %id, attempt, "attempt released: the job is queued again");
                    return;
                }
                Ok(ReleaseOutcome::CancelRequested) => {
                    return self.finish(id, attempt, Finish::Cancelled).await;
                }
                Ok(ReleaseOutcome::Stale) => {
                    tracing::warn!(job = %id, attempt, "stale attempt; nothing to release");
                    return;
                }
                Err(e) => {
                    // If it never lands, the lease expires as after a crash.
                    tracing::warn!(job = %id, attempt, retry, error = %e, "release failed");
                    tokio::time::sleep(Duration::from_millis(100 << retry)).await;
                }
            }
        }
    }

    /// End an attempt. A finish that fails on a transient database error is retried; a
    /// fenced-out one is not.
    async fn finish(&self, id: uuid::Uuid, attempt: i64, finish: Finish) {
        let status = finish.status();
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

    /// Store the child jobs of `job` and leave it waiting for them (one transaction fenced by
    /// the attempt, retried on transient errors; if it never lands, the lease expires and the
    /// next attempt fans out again, there being nothing half-made to clean up).
    async fn fan_out(&self, job: &JobRecord, plan: FanOutPlan) {
        let (id, attempt) = (job.id, job.attempt);
        let fan_out = FanOut {
            children: plan
                .children
                .into_iter()
                .map(|child| NewChild {
                    id: uuid::Uuid::new_v4(),
                    kind: child.kind,
                    params: child.params,
                    plan: child.plan,
                })
                .collect(),
            end_time_s: plan.end_time_s,
        };
        let count = fan_out.children.len();
        for retry in 0..5u32 {
            match self
                .store
                .fan_out(id, attempt, fan_out.clone(), clock::now_ms())
                .await
            {
                Ok(FanOutResult::FannedOut) => {
                    tracing::info!(job = %id, attempt, children = count, "fanned out");
                    // Idle workers of this process take the children at once.
                    self.wake.notify_waiters();
                    return;
                }
                Ok(FanOutResult::Stale) => {
                    tracing::warn!(job = %id, attempt, "stale attempt; fan-out discarded");
                    return;
                }
                Ok(FanOutResult::CancelRequested) => {
                    return self.finish(id, attempt, Finish::Cancelled).await;
                }
                Err(e) => {
                    tracing::warn!(job = %id, attempt, retry, error = %e, "fan-out failed");
                    tokio::time::sleep(Duration::from_millis(200 << retry)).await;
                }
            }
        }
    }
}

/// Resolves once shutdown has begun (at once if it already has).
async fn shutdown_begun(stopping: &mut tokio::sync::watch::Receiver<bool>) {
    loop {
        if *stopping.borrow_and_update() {
            return;
        }
        if stopping.changed().await.is_err() {
            // The sender is gone with the job system: no shutdown will come.
            return std::future::pending().await;
        }
    }
}

/// What an attempt computes.
enum Work {
    /// The whole job, with the stored inputs read for it.
    Run(JobInputs),
    /// The result of a fanned-out job from its children's summaries (or why it cannot be).
    Assemble(Result<Vec<serde_json::Value>, RunError>),
    /// Nothing: the fan-out planning refused the params.
    Refused(RunError),
}

/// The children's result summaries in index order, once every child has succeeded.
fn children_summaries(
    children: Vec<crate::store::ChildRecord>,
) -> Result<Vec<serde_json::Value>, RunError> {
    children
        .into_iter()
        .map(|child| match (child.status, child.result) {
            (JobStatus::Succeeded, Some(summary)) => Ok(summary),
            (status, _) => Err(RunError::InvalidConfig {
                field: format!("children[{}]", child.index),
                rule: format!(
                    "child job {} is {}, not succeeded with a result",
                    child.id,
                    status.as_str()
                ),
            }),
        })
        .collect()
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

/// The curve version a sweep stores: the runner's fidelity and provenance (or, from a runner
/// that gives none, the curve's own point and seed counts with the duration unknown), plus who
/// submitted the sweep, the code version and the job.
fn new_curve(
    job: &crate::jobs::JobRecord,
    key: &str,
    curve: &crate::pipeline::PenalizationCurve,
    info: Option<super::runner::CurveInfo>,
) -> NewCurve {
    let (fidelity, mut provenance) = match info {
        Some(info) => (info.fidelity, info.provenance),
        None => (
            CurveFidelity {
                points: curve.points().len() as i64,
                duration_per_point_s: None,
                seeds: curve.seeds() as i64,
            },
            serde_json::json!({}),
        ),
    };
    if let Some(map) = provenance.as_object_mut() {
        map.insert("code_version".into(), job.code_version.clone().into());
        map.insert("created_by".into(), job.submitted_by.clone().into());
        map.insert("job_id".into(), job.id.to_string().into());
        map.insert("seed".into(), job.seed.into());
    }
    NewCurve {
        key: key.to_string(),
        job_id: job.id,
        curve: serde_json::to_value(curve).unwrap_or_default(),
        fidelity,
        provenance,
        created_by: job.submitted_by.clone(),
        code_version: job.code_version.clone(),
        created_ms: clock::now_ms(),
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
