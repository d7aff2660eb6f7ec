//! Issue 17: at start-up a worker process gives the jobs of dead processes of its own host
//! back to the queue at once (their attempt logged `lost`), instead of leaving them `running`
//! for the whole lease; live processes, and other hosts, keep theirs. Same behaviour on SQLite
//! and PostgreSQL.

use crate::fresh_db;
use crate::support::runner::{test_config, CountingRunner};
use railwear::jobs::{JobKind, JobStatus, Jobs};
use railwear::store::{self, AttemptOutcome, Store, Submitted, WorkerHost};
use std::process::Command;
use std::sync::Arc;
use uuid::Uuid;

/// A pid that no process of this host has: a child that ran and was reaped.
fn dead_pid() -> u32 {
    let mut child = Command::new("true").spawn().expect("spawn true");
    let pid = child.id();
    child.wait().expect("reap");
    pid
}

async fn submit(jobs: &Jobs, n: u64) -> Uuid {
    match jobs
        .submit(
            JobKind::Simulate,
            serde_json::json!({"steps": 1, "seed": n}),
            "tester",
            None,
        )
        .await
        .expect("submit")
    {
        Submitted::Created(job) => job.id,
        other => panic!("{other:?}"),
    }
}

async fn dead_leases_of_this_host_are_released_at_start_up(store: Arc<dyn Store>) {
    let dir = crate::support::temp_dir("leases-cfg");
    let config = test_config(&dir.db_url());
    let jobs = Jobs::new(
        Arc::clone(&store),
        Arc::new(CountingRunner),
        config.worker_settings(),
        railwear::jobs::CurveDefaults {
            vehicle_profile: "ah64".into(),
            environment: "clean".into(),
            wear_law: "modified-archard".into(),
        },
    );
    let here = jobs.host.host.clone();
    let mut alive = Command::new("sleep")
        .arg("60")
        .spawn()
        .expect("spawn sleep");
    let holders = [
        (
            "dead pid, this host",
            here.clone(),
            dead_pid(),
            "i-1".to_string(),
        ),
        (
            "live pid, this host",
            here.clone(),
            alive.id(),
            "i-2".to_string(),
        ),
        // A process that had this process's pid before it (a restart as PID 1 does).
        (
            "this pid, earlier start",
            here.clone(),
            std::process::id(),
            "i-3".to_string(),
        ),
        (
            "dead pid, other host",
            format!("{here}-other"),
            dead_pid(),
            "i-4".to_string(),
        ),
        (
            "this very process",
            here.clone(),
            jobs.host.pid,
            jobs.host.instance.clone(),
        ),
    ];
    let mut ids = Vec::new();
    let now = railwear::store::clock::now_ms();
    for (n, (what, host, pid, instance)) in holders.iter().enumerate() {
        let id = submit(&jobs, n as u64).await;
        let worker = WorkerHost {
            host: host.clone(),
            pid: *pid,
            instance: instance.clone(),
        };
        // A lease of ten minutes: only the release can end it during this test.
        let claimed = store
            .claim_job_on(&format!("{host}-{pid}-0"), Some(&worker), now, 600_000)
            .await
            .expect("claim")
            .expect("a queued job");
        assert_eq!(claimed.id, id, "{what}");
        ids.push(id);
    }
    // Without host records (older workers, tests) nothing is released.
    let plain = submit(&jobs, 99).await;
    store
        .claim_job("anonymous", now, 600_000)
        .await
        .expect("claim")
        .expect("job");

    let released = jobs.release_dead_leases().await.expect("release");
    assert_eq!(released, 2);
    for (i, (what, ..)) in holders.iter().enumerate() {
        let job = store.get_job(ids[i]).await.unwrap().unwrap();
        let attempts = store.attempts(ids[i]).await.unwrap();
        if i == 0 || i == 2 {
            assert_eq!(job.status, JobStatus::Queued, "{what}");
            assert_eq!(job.lease_owner, None, "{what}");
            assert_eq!(
                job.error.as_deref(),
                Some("attempt 1 lost its worker (lease expired)"),
                "{what}"
            );
            assert_eq!(attempts.len(), 1);
            assert_eq!(attempts[0].outcome, AttemptOutcome::Lost, "{what}");
            assert!(attempts[0].ended_ms.is_some());
        } else {
            assert_eq!(job.status, JobStatus::Running, "{what}");
            assert_eq!(attempts[0].outcome, AttemptOutcome::Running, "{what}");
        }
    }
    let plain = store.get_job(plain).await.unwrap().unwrap();
    assert_eq!(plain.status, JobStatus::Running);
    // Done once: a second start-up finds nothing more, until the live holder dies.
    assert_eq!(jobs.release_dead_leases().await.expect("release"), 0);
    let _ = alive.kill();
    let _ = alive.wait();
    assert_eq!(jobs.release_dead_leases().await.expect("release"), 1);
    let job = store.get_job(ids[1]).await.unwrap().unwrap();
    assert_eq!(job.status, JobStatus::Queued);
    // The released jobs are claimed again, oldest first, as attempt 2.
    let again = store
        .claim_job("next", now + 1, 60_000)
        .await
        .unwrap()
        .unwrap();
    assert_eq!((again.id, again.attempt), (ids[0], 2));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sqlite_releases_the_leases_of_dead_workers_of_this_host() {
    let dir = crate::support::temp_dir("leases");
    let store = store::open(&dir.db_url()).await.expect("sqlite");
    dead_leases_of_this_host_are_released_at_start_up(store).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn postgres_releases_the_leases_of_dead_workers_of_this_host() {
    let db = fresh_db!("leases");
    let store = store::open(&db.url).await.expect("postgres");
    dead_leases_of_this_host_are_released_at_start_up(store).await;
}

/// Simulate job number `n` of a test, its id `base + n`.
fn numbered_job(base: u128, n: u128) -> railwear::store::NewJob {
    railwear::store::NewJob {
        id: Uuid::from_u128(base + n),
        kind: JobKind::Simulate,
        params: serde_json::json!({"n": n as u64}),
        plan: None,
        seed: n as u64,
        code_version: "test".into(),
        submitted_by: "tester".into(),
        idempotency: None,
        curve_key: None,
        created_ms: 1_000 + n as i64,
    }
}

/// `release_job` (shutdown): the job goes back to the queue with its attempt logged
/// `released`; a stale attempt releases nothing; a job whose cancellation was requested is not
/// released (the worker ends it as cancelled).
async fn release_is_fenced_and_yields_to_cancellation(store: Arc<dyn Store>) {
    use railwear::store::{Finish, ReleaseOutcome};
    let job = |n: u128| numbered_job(0xfee1_0000, n);
    store.submit_job(job(1)).await.unwrap();
    store.submit_job(job(2)).await.unwrap();
    let a = store.claim_job("w", 2_000, 60_000).await.unwrap().unwrap();
    assert_eq!(a.id, Uuid::from_u128(0xfee1_0001));
    assert_eq!(
        store.release_job(a.id, 2, 2_100).await.unwrap(),
        ReleaseOutcome::Stale
    );
    assert_eq!(
        store.release_job(a.id, 1, 2_100).await.unwrap(),
        ReleaseOutcome::Released
    );
    let back = store.get_job(a.id).await.unwrap().unwrap();
    assert_eq!(back.status, JobStatus::Queued);
    assert_eq!(back.lease_owner, None);
    let log = store.attempts(a.id).await.unwrap();
    assert_eq!(log[0].outcome, AttemptOutcome::Released);
    assert_eq!(log[0].ended_ms, Some(2_100));
    // It keeps its place in the queue: claimed before the later job, as attempt 2.
    let again = store.claim_job("w2", 2_200, 60_000).await.unwrap().unwrap();
    assert_eq!((again.id, again.attempt), (a.id, 2));
    // A cancel requested meanwhile wins over the release.
    store.request_cancel(a.id, 2_300).await.unwrap();
    assert_eq!(
        store.release_job(a.id, 2, 2_400).await.unwrap(),
        ReleaseOutcome::CancelRequested
    );
    assert!(store
        .finish_job(a.id, 2, Finish::Cancelled, 2_500)
        .await
        .unwrap());
    assert_eq!(
        store.release_job(a.id, 2, 2_600).await.unwrap(),
        ReleaseOutcome::Stale
    );
    let outcomes: Vec<_> = store
        .attempts(a.id)
        .await
        .unwrap()
        .iter()
        .map(|a| a.outcome)
        .collect();
    assert_eq!(
        outcomes,
        [AttemptOutcome::Released, AttemptOutcome::Cancelled]
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sqlite_release_is_fenced_and_yields_to_cancellation() {
    let dir = crate::support::temp_dir("release");
    let store = store::open(&dir.db_url()).await.expect("sqlite");
    release_is_fenced_and_yields_to_cancellation(store).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn postgres_release_is_fenced_and_yields_to_cancellation() {
    let db = fresh_db!("release");
    let store = store::open(&db.url).await.expect("postgres");
    release_is_fenced_and_yields_to_cancellation(store).await;
}

/// Checkpoints (migration 0007) and record chunks (migration 0010): stored only by the attempt
/// holding the lease (a checkpoint recorded on the attempt, progress moved to its time),
/// replaced by a later save of the same one, kept across the release for the next attempt, and
/// deleted when the job ends, whichever way it ends. Chunks are read from number 0 up to the
/// first gap.
async fn checkpoints_are_fenced_and_end_with_the_job(store: Arc<dyn Store>) {
    use railwear::store::{Finish, NewCheckpoint};
    let job = |n: u128| numbered_job(0xc4ec_0000, n);
    let checkpoint = |t: f64, fill: u8| NewCheckpoint {
        simulated_s: t,
        end_s: 2.0,
        data: vec![fill; 1000],
    };
    store.submit_job(job(1)).await.unwrap();
    store.submit_job(job(2)).await.unwrap();
    let a = store.claim_job("w", 2_000, 60_000).await.unwrap().unwrap();
    assert_eq!(a.id, Uuid::from_u128(0xc4ec_0001));
    // Not the lease holder: nothing stored.
    assert!(!store
        .save_checkpoint(a.id, 2, checkpoint(0.5, 1), 2_050)
        .await
        .unwrap());
    assert_eq!(store.load_checkpoint(a.id).await.unwrap(), None);
    assert!(!store
        .save_record_chunk(a.id, 2, 0, vec![9; 10])
        .await
        .unwrap());
    assert!(store.load_record_chunks(a.id).await.unwrap().is_empty());
    for (seq, fill) in [(0, 10u8), (1, 11), (1, 12), (3, 13)] {
        assert!(store
            .save_record_chunk(a.id, 1, seq, vec![fill; 10])
            .await
            .unwrap());
    }
    assert_eq!(
        store.load_record_chunks(a.id).await.unwrap(),
        vec![vec![10u8; 10], vec![12u8; 10]],
        "chunk 1 replaced; chunk 3 is past the gap"
    );
    assert!(store
        .save_checkpoint(a.id, 1, checkpoint(0.5, 1), 2_100)
        .await
        .unwrap());
    assert!(store
        .save_checkpoint(a.id, 1, checkpoint(0.75, 2), 2_150)
        .await
        .unwrap());
    let stored = store.load_checkpoint(a.id).await.unwrap().expect("stored");
    assert_eq!(
        (
            stored.attempt,
            stored.simulated_s,
            stored.end_s,
            stored.created_ms
        ),
        (1, 0.75, 2.0, 2_150)
    );
    assert_eq!(
        stored.data,
        vec![2u8; 1000],
        "the later save replaced the first"
    );
    let progress = store
        .get_job(a.id)
        .await
        .unwrap()
        .unwrap()
        .progress
        .unwrap();
    assert_eq!(progress.simulated_time_s, 0.75);
    assert_eq!(progress.fraction, 0.375);
    store.release_job(a.id, 1, 2_200).await.unwrap();
    let log = store.attempts(a.id).await.unwrap();
    assert_eq!(log[0].outcome, AttemptOutcome::Released);
    assert_eq!(log[0].checkpoint_s, Some(0.75));
    // Kept for the next attempt; the old attempt can no longer write one.
    let again = store.claim_job("w2", 2_300, 60_000).await.unwrap().unwrap();
    assert_eq!((again.id, again.attempt), (a.id, 2));
    assert!(store.load_checkpoint(a.id).await.unwrap().is_some());
    assert_eq!(store.load_record_chunks(a.id).await.unwrap().len(), 2);
    assert!(!store
        .save_checkpoint(a.id, 1, checkpoint(0.9, 3), 2_350)
        .await
        .unwrap());
    assert!(!store
        .save_record_chunk(a.id, 1, 2, vec![14; 10])
        .await
        .unwrap());
    assert!(store
        .save_record_chunk(a.id, 2, 2, vec![15; 10])
        .await
        .unwrap());
    assert_eq!(store.load_record_chunks(a.id).await.unwrap().len(), 4);
    assert_eq!(store.attempts(a.id).await.unwrap()[1].checkpoint_s, None);
    // The job ends: the checkpoint goes with it.
    assert!(store
        .finish_job(a.id, 2, Finish::Failed("x".into()), 2_400)
        .await
        .unwrap());
    assert_eq!(store.load_checkpoint(a.id).await.unwrap(), None);
    assert!(store.load_record_chunks(a.id).await.unwrap().is_empty());
    // A queued job with a checkpoint, cancelled: gone too.
    let b = store.claim_job("w", 2_500, 60_000).await.unwrap().unwrap();
    assert!(store
        .save_checkpoint(b.id, 1, checkpoint(0.25, 4), 2_550)
        .await
        .unwrap());
    assert!(store
        .save_record_chunk(b.id, 1, 0, vec![16; 10])
        .await
        .unwrap());
    store.release_job(b.id, 1, 2_600).await.unwrap();
    store.request_cancel(b.id, 2_700).await.unwrap();
    assert_eq!(
        store.get_job(b.id).await.unwrap().unwrap().status,
        JobStatus::Cancelled
    );
    assert_eq!(store.load_checkpoint(b.id).await.unwrap(), None);
    assert!(store.load_record_chunks(b.id).await.unwrap().is_empty());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sqlite_checkpoints_are_fenced_and_end_with_the_job() {
    let dir = crate::support::temp_dir("checkpoints");
    let store = store::open(&dir.db_url()).await.expect("sqlite");
    checkpoints_are_fenced_and_end_with_the_job(store).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn postgres_checkpoints_are_fenced_and_end_with_the_job() {
    let db = fresh_db!("checkpoints");
    let store = store::open(&db.url).await.expect("postgres");
    checkpoints_are_fenced_and_end_with_the_job(store).await;
}
