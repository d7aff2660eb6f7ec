//! The PostgreSQL store against the local server: concurrent claims hand every job out exactly
//! once, expired leases are re-queued and fence out the stale attempt, retries are bounded with
//! the last error kept, racing uploads and idempotent submissions make one record. The scripted
//! use of every `Store` method compared with SQLite is in `postgres_store_script.rs`; the
//! fixed jobs and campaigns below serve both.

use crate::fresh_db;
use railwear::jobs::{JobKind, JobProgress, JobStatus};
use railwear::store::{
    self, CampaignCounts, CampaignInsert, CampaignSummary, Finish, Heartbeat, NewCampaign, NewJob,
    PageRequest, Submitted, TrackBlock,
};
use std::collections::HashMap;
use std::sync::Arc;
use uuid::Uuid;

/// Job `n` of a test: fixed id and params so two stores can be compared record for record.
pub(crate) fn new_job(n: u128, kind: JobKind, idempotency: Option<(&str, &str)>) -> NewJob {
    NewJob {
        id: Uuid::from_u128(0x5eed_0000 + n),
        kind,
        params: serde_json::json!({ "n": n as u64, "x": 0.1 + 1e-17 * n as f64 }),
        plan: None,
        seed: u64::MAX - n as u64, // above i64::MAX: the bit-pattern round trip matters
        code_version: "test".into(),
        submitted_by: "tester".into(),
        idempotency: idempotency.map(|(k, s)| (k.to_string(), s.to_string())),
        curve_key: (kind == JobKind::Sweep).then(|| "ah64/clean/modified-archard".to_string()),
        created_ms: 1_000 + n as i64,
    }
}

pub(crate) fn succeeded(samples: i64) -> Finish {
    Finish::Succeeded {
        summary: serde_json::json!({ "rail_wear_mg": 1.25 }),
        blocks: if samples > 0 {
            vec![TrackBlock {
                index: 0,
                samples,
                t_start_s: 0.0,
                t_end_s: 0.5,
                data: vec![1, 2, 3, 0, 255],
            }]
        } else {
            Vec::new()
        },
        plots: vec![
            ("wear".into(), "<svg>w</svg>".into()),
            ("Force".into(), "<svg>f</svg>".into()),
        ],
        curve: None,
    }
}

fn count(counts: &[(JobStatus, i64)], status: JobStatus) -> i64 {
    counts
        .iter()
        .find(|(s, _)| *s == status)
        .map_or(-1, |(_, n)| *n)
}

/// Must-have (a): 8 workers, each with its own connection pool as separate processes would
/// have, race to claim 200 queued jobs. Every job is claimed exactly once, at attempt 1.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn eight_workers_claim_two_hundred_jobs_each_exactly_once() {
    let db = fresh_db!("claims");
    let store = store::open(&db.url).await.expect("open postgres store");
    for n in 0..200 {
        let submitted = store
            .submit_job(new_job(n, JobKind::Simulate, None))
            .await
            .unwrap();
        assert!(matches!(submitted, Submitted::Created(_)));
    }
    let start = Arc::new(tokio::sync::Barrier::new(8));
    let mut workers = Vec::new();
    for w in 0..8 {
        let store = store::open(&db.url).await.expect("open worker store");
        let start = Arc::clone(&start);
        workers.push(tokio::spawn(async move {
            let name = format!("worker-{w}");
            let mut claimed = Vec::new();
            start.wait().await;
            while let Some(job) = store.claim_job(&name, 10_000, 60_000).await.unwrap() {
                assert_eq!(job.status, JobStatus::Running);
                claimed.push((job.id, job.attempt));
                // Finishing while others claim exercises the claim against concurrent updates.
                let done = store
                    .finish_job(job.id, job.attempt, succeeded(0), 10_001)
                    .await
                    .unwrap();
                assert!(done, "worker {name} was fenced out of its own claim");
            }
            claimed
        }));
    }
    let mut times_claimed: HashMap<Uuid, usize> = HashMap::new();
    let mut busy_workers = 0;
    for worker in workers {
        let claimed = worker.await.unwrap();
        busy_workers += usize::from(!claimed.is_empty());
        for (id, attempt) in claimed {
            assert_eq!(attempt, 1, "job {id} was claimed on a later attempt");
            *times_claimed.entry(id).or_default() += 1;
        }
    }
    assert_eq!(times_claimed.len(), 200, "every job claimed");
    assert!(
        times_claimed.values().all(|&n| n == 1),
        "a job was claimed twice: {:?}",
        times_claimed
            .iter()
            .filter(|(_, &n)| n > 1)
            .collect::<Vec<_>>()
    );
    assert!(busy_workers >= 2, "the claims did not run concurrently");
    let counts = store.job_counts().await.unwrap();
    assert_eq!(count(&counts, JobStatus::Succeeded), 200);
    assert_eq!(count(&counts, JobStatus::Queued), 0);
    assert_eq!(count(&counts, JobStatus::Running), 0);
}

/// Must-have (b): a lease that is not renewed expires, the job goes back to the queue, a newer
/// attempt takes it, and the stale attempt can neither heartbeat nor finish. After
/// `max_attempts` lost attempts the job fails with the last error kept.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn expired_lease_is_requeued_and_the_stale_attempt_is_fenced_out() {
    let db = fresh_db!("lease");
    let store = store::open(&db.url).await.expect("open postgres store");
    let id = match store
        .submit_job(new_job(1, JobKind::Simulate, None))
        .await
        .unwrap()
    {
        Submitted::Created(job) => job.id,
        other => panic!("{other:?}"),
    };
    let lease_ms = 1_000;
    let first = store
        .claim_job("a", 10_000, lease_ms)
        .await
        .unwrap()
        .unwrap();
    assert_eq!((first.id, first.attempt), (id, 1));
    // A heartbeat inside the lease renews it: at 10 900 the lease runs to 11 900.
    let beat = store
        .heartbeat(id, 1, None, 10_900, lease_ms)
        .await
        .unwrap();
    assert_eq!(
        beat,
        Heartbeat {
            owned: true,
            cancel_requested: false
        }
    );
    assert_eq!(store.requeue_expired(11_500, 3).await.unwrap(), 0);
    // Past the renewed lease the job is re-queued with the reason recorded.
    assert_eq!(store.requeue_expired(11_901, 3).await.unwrap(), 1);
    let job = store.get_job(id).await.unwrap().unwrap();
    assert_eq!(job.status, JobStatus::Queued);
    assert_eq!(
        job.error.as_deref(),
        Some("attempt 1 lost its worker (lease expired)")
    );
    let second = store
        .claim_job("b", 12_000, lease_ms)
        .await
        .unwrap()
        .unwrap();
    assert_eq!((second.id, second.attempt), (id, 2));
    assert_eq!(second.started_ms, Some(10_000), "first start is kept");

    // The stale attempt 1 is refused everywhere and writes nothing.
    let stale_beat = store
        .heartbeat(
            id,
            1,
            Some(JobProgress {
                simulated_time_s: 9.0,
                end_time_s: 10.0,
                fraction: 0.9,
                eta_s: Some(1.0),
            }),
            12_100,
            lease_ms,
        )
        .await
        .unwrap();
    assert!(!stale_beat.owned);
    assert!(!store.finish_job(id, 1, succeeded(7), 12_200).await.unwrap());
    let job = store.get_job(id).await.unwrap().unwrap();
    assert_eq!((job.status, job.attempt), (JobStatus::Running, 2));
    assert_eq!(job.progress, None, "the stale heartbeat wrote progress");
    assert!(store.track_blocks(id).await.unwrap().is_empty());

    // Attempts 2 and 3 die too; with max_attempts = 3 the third loss fails the job.
    assert_eq!(store.requeue_expired(13_001, 3).await.unwrap(), 1);
    let third = store
        .claim_job("c", 14_000, lease_ms)
        .await
        .unwrap()
        .unwrap();
    assert_eq!(third.attempt, 3);
    assert_eq!(store.requeue_expired(15_001, 3).await.unwrap(), 1);
    let job = store.get_job(id).await.unwrap().unwrap();
    assert_eq!(job.status, JobStatus::Failed);
    assert_eq!(job.finished_ms, Some(15_001));
    assert_eq!(
        job.error.as_deref(),
        Some("attempt 3 lost its worker (lease expired)")
    );
    assert!(store
        .claim_job("d", 16_000, lease_ms)
        .await
        .unwrap()
        .is_none());
    assert!(!store.finish_job(id, 3, succeeded(7), 16_000).await.unwrap());
}

/// Campaign `n` of a test with the given content (fixed id and times).
pub(crate) fn new_campaign(n: u128, content: &str) -> NewCampaign {
    NewCampaign {
        id: Uuid::from_u128(0xca3a_0000 + n),
        name: format!("campaign-{n}"),
        created_by: format!("lab-{n}"),
        created_ms: 10_000 + n as i64,
        content: content.to_string(),
        content_sha256: railwear::jobs::hex(&<sha2::Sha256 as sha2::Digest>::digest(
            content.as_bytes(),
        )),
        counts: CampaignCounts {
            tests: 4,
            specimens: 6,
            increments: 10 + n as i64,
            accelerometer_records: 2,
        },
    }
}

/// A campaign summary without its store-assigned sequence number (an upload refused as a
/// duplicate uses up a PostgreSQL identity value, not an SQLite one), for comparing traces.
pub(crate) fn campaign_no_seq(c: &CampaignSummary) -> String {
    format!(
        "{} {} {} {} {} {} {:?}",
        c.id, c.name, c.created_by, c.created_ms, c.content_sha256, c.content_bytes, c.counts
    )
}

/// Eight concurrent uploads of the same campaign content store it once: one `Created`, seven
/// `Existing` naming that record, no unique-key error.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn racing_identical_campaign_uploads_store_one() {
    let db = fresh_db!("campaign");
    let store = store::open(&db.url).await.expect("open postgres store");
    let mut tasks = Vec::new();
    for n in 0..8 {
        let store = Arc::clone(&store);
        tasks.push(tokio::spawn(async move {
            store
                .insert_campaign(new_campaign(n, r#"{"name":"same"}"#))
                .await
                .unwrap()
        }));
    }
    let (mut created, mut existing) = (Vec::new(), Vec::new());
    for task in tasks {
        match task.await.unwrap() {
            CampaignInsert::Created(c) => created.push(c.id),
            CampaignInsert::Existing(c) => existing.push(c.id),
        }
    }
    assert_eq!(created.len(), 1);
    assert_eq!(existing.len(), 7);
    assert!(existing.iter().all(|id| *id == created[0]));
    let page = store
        .list_campaigns(PageRequest {
            limit: 100,
            after_seq: None,
        })
        .await
        .unwrap();
    assert_eq!(page.items.len(), 1);
}

/// Eight concurrent submissions with one Idempotency-Key make one job: one `Created`, seven
/// `Replayed` of that job, no unique-key error.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn racing_idempotent_submissions_make_one_job() {
    let db = fresh_db!("idem");
    let store = store::open(&db.url).await.expect("open postgres store");
    let mut tasks = Vec::new();
    for n in 0..8 {
        let store = Arc::clone(&store);
        tasks.push(tokio::spawn(async move {
            store
                .submit_job(new_job(100 + n, JobKind::Simulate, Some(("k", "sha"))))
                .await
                .unwrap()
        }));
    }
    let (mut created, mut replayed) = (Vec::new(), Vec::new());
    for task in tasks {
        match task.await.unwrap() {
            Submitted::Created(job) => created.push(job.id),
            Submitted::Replayed(job) => replayed.push(job.id),
            Submitted::KeyConflict(id) => panic!("conflict with {id}"),
        }
    }
    assert_eq!(created.len(), 1);
    assert_eq!(replayed.len(), 7);
    assert!(replayed.iter().all(|id| *id == created[0]));
    let counts = store.job_counts().await.unwrap();
    assert_eq!(count(&counts, JobStatus::Queued), 1);
}
