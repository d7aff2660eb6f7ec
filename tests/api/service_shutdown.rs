//! Issue 17: clean shutdown with the counting test runner. Stopping the service stops the
//! workers taking jobs and gives running attempts back to the queue at once (attempt logged
//! `released`), within the shutdown grace even when the computation does not stop; the next
//! worker runs the job to a result identical to an uninterrupted run. A sweep keeps the points
//! that finished (the sweep-level checkpoint) and re-runs only the rest. A real simulation
//! (the library runner) stopped late (past 80 %) stores its records in chunks as it runs and a
//! checkpoint much smaller than them at the stop; the next worker resumes from both to the
//! uninterrupted run's result.

use crate::helpers::{Api, Runner, TestApp};
use crate::support::runner::{start, start_library, test_config};
use crate::support::{temp_dir, ENGINEER};
use railwear::jobs::JobStatus;
use railwear::store::{AttemptOutcome, Store};
use serde_json::Value;
use std::sync::Arc;
use std::time::{Duration, Instant};

async fn outcomes(store: &Arc<dyn Store>, id: &str) -> Vec<AttemptOutcome> {
    let id = id.parse().expect("uuid");
    store
        .attempts(id)
        .await
        .expect("attempts")
        .iter()
        .map(|a| a.outcome)
        .collect()
}

/// Tracks CSV and result summary of a succeeded job.
fn results(api: &Api, id: &str) -> (String, Value) {
    let csv = api.get(&format!("/v1/jobs/{id}/tracks"), Some(ENGINEER));
    assert_eq!(csv.status, 200, "{}", csv.body);
    (
        csv.body,
        api.get_json(&format!("/v1/jobs/{id}/result"))["summary"].clone(),
    )
}

/// Submits `body` and waits until the job's progress passes `fraction`; the job's id.
fn submit_until_progress(api: &Api, body: &str, fraction: f64, timeout: Duration) -> String {
    let id = api.submit_job(body);
    api.wait_job_until(&id, "progress", timeout, |j| {
        j.progress.is_some_and(|p| p.fraction > fraction)
    });
    id
}

/// How long the counting runner's jobs may take to reach a state, and a real simulation.
const SHORT: Duration = Duration::from_secs(30);
const LONG: Duration = Duration::from_secs(300);

const BODY: &str =
    r#"{"kind":"simulate","params":{"steps":30,"step_ms":50,"samples":400,"seed":8}}"#;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_stopped_worker_gives_its_job_back_and_the_next_one_finishes_it_identically() {
    // Reference: uninterrupted.
    let ref_dir = temp_dir("shutdown-ref");
    let reference = start(test_config(&ref_dir.db_url()), true).await;
    let api = Api::new(&format!("http://{}", reference.addr));
    let expected = tokio::task::spawn_blocking(move || {
        let id = api.submit_job(BODY);
        api.wait_job(&id, JobStatus::Succeeded, SHORT);
        results(&api, &id)
    })
    .await
    .unwrap();
    reference.stop().await;

    let dir = temp_dir("shutdown");
    let mut config = test_config(&dir.db_url());
    config.workers = 1;
    config.shutdown_grace_s = 1.0;
    config.lease_s = 60.0; // only the release can hand the job on this fast
    let first = start(config.clone(), true).await;
    let store = first.state.store.clone();
    let api = Api::new(&format!("http://{}", first.addr));
    let id = tokio::task::spawn_blocking(move || submit_until_progress(&api, BODY, 0.2, SHORT))
        .await
        .unwrap();
    let asked = Instant::now();
    first.stop().await;
    // The runner stops at its next 50 ms step: far inside the grace.
    assert!(
        asked.elapsed() < Duration::from_millis(1000),
        "{:?}",
        asked.elapsed()
    );
    let job = store.get_job(id.parse().unwrap()).await.unwrap().unwrap();
    assert_eq!(job.status, JobStatus::Queued, "given back at once");
    assert_eq!(job.lease_owner, None);
    assert_eq!(job.attempt, 1);
    assert_eq!(outcomes(&store, &id).await, [AttemptOutcome::Released]);

    let second = start(config, true).await;
    let api = Api::new(&format!("http://{}", second.addr));
    let (got, job) = tokio::task::spawn_blocking({
        let id = id.clone();
        move || {
            let job = api.wait_job(&id, JobStatus::Succeeded, SHORT);
            (results(&api, &id), job)
        }
    })
    .await
    .unwrap();
    assert_eq!(job.attempt, 2);
    assert_eq!(
        got.0, expected.0,
        "tracks identical to the uninterrupted run"
    );
    assert_eq!(got.1, expected.1);
    assert_eq!(
        outcomes(&store, &id).await,
        [AttemptOutcome::Released, AttemptOutcome::Succeeded]
    );
    second.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_grace_bounds_the_shutdown_when_the_computation_does_not_stop() {
    let app = TestApp::spawn_with(Runner::Counting, true, |config| {
        config.workers = 1;
        config.shutdown_grace_s = 0.5;
        config.lease_s = 60.0;
    })
    .await;
    let store = app.service.state.store.clone();
    let api = app.api.clone();
    // One step of 4 s: the runner looks at its cancel flag only between steps.
    let id = tokio::task::spawn_blocking(move || {
        let id =
            api.submit_job(r#"{"kind":"simulate","params":{"steps":2,"step_ms":4000,"seed":1}}"#);
        api.wait_job(&id, JobStatus::Running, SHORT);
        id
    })
    .await
    .unwrap();
    let asked = Instant::now();
    let _db = app.stop().await;
    let took = asked.elapsed();
    assert!(
        took >= Duration::from_millis(450) && took < Duration::from_millis(1500),
        "{took:?}"
    );
    let id: uuid::Uuid = id.parse().unwrap();
    let job = store.get_job(id).await.unwrap().unwrap();
    assert_eq!(job.status, JobStatus::Queued);
    let log: Vec<_> = store
        .attempts(id)
        .await
        .unwrap()
        .iter()
        .map(|a| a.outcome)
        .collect();
    assert_eq!(log, [AttemptOutcome::Released]);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_stopped_sweep_keeps_its_finished_points_and_resumes_to_the_same_result() {
    let body = r#"{"kind":"sweep","params":{"children":6,"steps":8,"step_ms":50,"seed":77}}"#;
    let ref_dir = temp_dir("shutdown-sweep-ref");
    let reference = start(test_config(&ref_dir.db_url()), true).await;
    let api = Api::new(&format!("http://{}", reference.addr));
    let expected = tokio::task::spawn_blocking(move || {
        let id = api.submit_job(body);
        api.wait_job(&id, JobStatus::Succeeded, SHORT);
        api.get_json(&format!("/v1/jobs/{id}/result"))["summary"].clone()
    })
    .await
    .unwrap();
    reference.stop().await;

    let dir = temp_dir("shutdown-sweep");
    let mut config = test_config(&dir.db_url());
    config.workers = 2;
    config.shutdown_grace_s = 1.0;
    config.lease_s = 60.0;
    let first = start(config.clone(), true).await;
    let store = first.state.store.clone();
    let api = Api::new(&format!("http://{}", first.addr));
    let id = tokio::task::spawn_blocking(move || {
        let id = api.submit_job(body);
        // Stop once some points are done and others run.
        api.wait_job_until(&id, "a point done", SHORT, |j| {
            j.children.is_some_and(|c| c.succeeded >= 2)
        });
        id
    })
    .await
    .unwrap();
    first.stop().await;
    let sweep: uuid::Uuid = id.parse().unwrap();
    let parent = store.get_job(sweep).await.unwrap().unwrap();
    assert_eq!(parent.status, JobStatus::Waiting);
    let children = store.children(sweep).await.unwrap();
    let done_before: Vec<_> = children
        .iter()
        .filter(|c| c.status == JobStatus::Succeeded)
        .map(|c| c.id)
        .collect();
    assert!(
        done_before.len() >= 2 && done_before.len() < 6,
        "{children:?}"
    );
    assert!(
        children
            .iter()
            .all(|c| matches!(c.status, JobStatus::Succeeded | JobStatus::Queued)),
        "nothing left running: {children:?}"
    );
    let mut released = 0;
    for c in &children {
        let log = outcomes(&store, &c.id.to_string()).await;
        released += log
            .iter()
            .filter(|o| **o == AttemptOutcome::Released)
            .count();
    }
    assert!(released >= 1, "a running point was given back");

    let second = start(config, true).await;
    let api = Api::new(&format!("http://{}", second.addr));
    let summary = tokio::task::spawn_blocking({
        let id = id.clone();
        move || {
            api.wait_job(&id, JobStatus::Succeeded, SHORT);
            api.get_json(&format!("/v1/jobs/{id}/result"))["summary"].clone()
        }
    })
    .await
    .unwrap();
    assert_eq!(
        summary, expected,
        "the resumed sweep equals the uninterrupted one"
    );
    // The points finished before the shutdown were not run again; every point succeeded once.
    for c in store.children(sweep).await.unwrap() {
        let log = outcomes(&store, &c.id.to_string()).await;
        assert_eq!(
            log.iter()
                .filter(|o| **o == AttemptOutcome::Succeeded)
                .count(),
            1,
            "{log:?}"
        );
        if done_before.contains(&c.id) {
            assert_eq!(log, [AttemptOutcome::Succeeded]);
        }
    }
    let parent_log: Vec<_> = store
        .attempts(sweep)
        .await
        .unwrap()
        .iter()
        .map(|a| a.outcome)
        .collect();
    assert_eq!(
        parent_log,
        [AttemptOutcome::FannedOut, AttemptOutcome::Succeeded]
    );
    second.stop().await;
}

/// Rattle box C, 50 ms settle and 12 s excited, recording about every accepted step: about ten
/// seconds of computation (the last 20 % leave time to stop it on a loaded machine) and tens
/// of thousands of track samples.
const SIMULATE_BODY: &str = r#"{"kind":"simulate","params":{"config":"rattle-box-c","overrides":{"simulation":{"settle_s":0.05,"duration_s":12.0,"record_interval_s":1e-5}},"seed":8}}"#;
const SIMULATE_END_S: f64 = 12.05;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_stopped_simulation_stores_a_checkpoint_and_the_next_worker_resumes_it_identically() {
    // Reference: uninterrupted.
    let ref_dir = temp_dir("checkpoint-ref");
    let reference = start_library(test_config(&ref_dir.db_url()), true).await;
    let api = Api::new(&format!("http://{}", reference.addr));
    let expected = tokio::task::spawn_blocking(move || {
        let id = api.submit_job(SIMULATE_BODY);
        api.wait_job(&id, JobStatus::Succeeded, LONG);
        results(&api, &id)
    })
    .await
    .unwrap();
    reference.stop().await;
    assert!(expected.0.lines().count() > 100, "tracks recorded");

    let dir = temp_dir("checkpoint");
    let mut config = test_config(&dir.db_url());
    config.workers = 1;
    config.shutdown_grace_s = 5.0;
    config.lease_s = 60.0; // only the release can hand the job on this fast
    config.checkpoint_chunk_samples = 1024; // many chunks in a short run
    let first = start_library(config.clone(), true).await;
    let store = first.state.store.clone();
    let first_jobs = first.state.jobs.clone();
    let api = Api::new(&format!("http://{}", first.addr));
    let id =
        tokio::task::spawn_blocking(move || submit_until_progress(&api, SIMULATE_BODY, 0.8, LONG))
            .await
            .unwrap();
    let asked = Instant::now();
    first.stop().await;
    // The engine stops at its next accepted step: far inside the grace.
    assert!(
        asked.elapsed() < Duration::from_secs(5),
        "{:?}",
        asked.elapsed()
    );
    let uuid: uuid::Uuid = id.parse().unwrap();
    let job = store.get_job(uuid).await.unwrap().unwrap();
    assert_eq!(job.status, JobStatus::Queued, "given back at once");
    assert_eq!(job.lease_owner, None);
    let attempts = store.attempts(uuid).await.unwrap();
    assert_eq!(attempts.len(), 1);
    assert_eq!(attempts[0].outcome, AttemptOutcome::Released);
    let checkpoint_s = attempts[0]
        .checkpoint_s
        .expect("the released attempt stored a checkpoint");
    assert!(
        (0.8 * SIMULATE_END_S..SIMULATE_END_S).contains(&checkpoint_s),
        "checkpoint at {checkpoint_s} s"
    );
    let stored = store.load_checkpoint(uuid).await.unwrap().expect("stored");
    assert_eq!(stored.simulated_s, checkpoint_s);
    // The records went out in chunks as the run went; the checkpoint carries the run's state
    // and less than a chunk's worth of records, far less than the records themselves.
    let chunks = store.load_record_chunks(uuid).await.unwrap();
    let chunk_bytes: usize = chunks.iter().map(Vec::len).sum();
    let largest = chunks.iter().map(Vec::len).max().unwrap_or(0);
    eprintln!(
        "checkpoint at {checkpoint_s} s: {} bytes; {} record chunks, {chunk_bytes} bytes, the \
         largest {largest}",
        stored.data.len(),
        chunks.len()
    );
    assert!(chunks.len() >= 20, "{} record chunks stored", chunks.len());
    assert!(
        4 * stored.data.len() < chunk_bytes,
        "checkpoint of {} bytes beside {chunk_bytes} bytes of chunks",
        stored.data.len()
    );
    assert_eq!(stored.end_s, SIMULATE_END_S);
    assert_eq!(stored.attempt, 1);
    // The job's progress stands at the checkpoint.
    let progress = job.progress.expect("progress");
    assert_eq!(progress.simulated_time_s, checkpoint_s);
    let metrics = first_jobs.metrics.render(&[]);
    assert!(
        metrics.contains("railwear_attempts_released_total{checkpoint=\"true\"} 1"),
        "{metrics}"
    );

    // The next worker resumes: its progress starts at the checkpoint's time.
    let second = start_library(config, true).await;
    let api = Api::new(&format!("http://{}", second.addr));
    let (got, job, first_progress) = tokio::task::spawn_blocking({
        let id = id.clone();
        move || {
            let mut first_progress = None;
            let job = api.wait_job_until(&id, "succeeded", LONG, |j| {
                if first_progress.is_none() && j.status == JobStatus::Running {
                    first_progress = j.progress.map(|p| p.simulated_time_s);
                }
                j.status == JobStatus::Succeeded
            });
            let attempts = api.get_json(&format!("/v1/jobs/{id}/attempts"));
            (results(&api, &id), (job, attempts), first_progress)
        }
    })
    .await
    .unwrap();
    let (job, attempts) = job;
    assert_eq!(job.attempt, 2);
    if let Some(t) = first_progress {
        assert!(
            t >= checkpoint_s,
            "progress of the resumed attempt at {t} s"
        );
    }
    assert_eq!(attempts[0]["outcome"], "released", "{attempts}");
    assert_eq!(attempts[0]["checkpoint_s"], checkpoint_s, "{attempts}");
    assert_eq!(attempts[1]["outcome"], "succeeded", "{attempts}");
    let metrics = second.state.jobs.metrics.render(&[]);
    assert!(
        metrics.contains("railwear_attempts_resumed_total 1"),
        "{metrics}"
    );
    assert_eq!(
        got.0, expected.0,
        "tracks identical to the uninterrupted run"
    );
    assert_eq!(
        got.1, expected.1,
        "summary identical to the uninterrupted run"
    );
    assert_eq!(
        store.load_checkpoint(uuid).await.unwrap(),
        None,
        "the checkpoint is deleted when the job ends"
    );
    assert!(
        store.load_record_chunks(uuid).await.unwrap().is_empty(),
        "the record chunks are deleted when the job ends"
    );
    second.stop().await;
}
