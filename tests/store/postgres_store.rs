//! The PostgreSQL store against the local server: concurrent claims hand every job out exactly
//! once, expired leases are re-queued and fence out the stale attempt, retries are bounded with
//! the last error kept, and one scripted use of every `Store` method gives the same records on
//! PostgreSQL as on SQLite.
//!
//! Over 700 lines: the scripted use of every `Store` method and its record-by-record comparison
//! are one check.

use crate::fresh_db;
use railwear::config::Role;
use railwear::jobs::{JobKind, JobProgress, JobStatus};
use railwear::store::{
    self, CampaignCounts, CampaignInsert, CampaignSummary, CurveFidelity, CurveFilter, Finish,
    Heartbeat, JobFilter, NewCampaign, NewCurve, NewJob, NewMeasurement, PageRequest,
    PublishOutcome, Store, Submitted, TrackBlock,
};
use std::collections::HashMap;
use std::sync::Arc;
use uuid::Uuid;

/// Job `n` of a test: fixed id and params so two stores can be compared record for record.
fn new_job(n: u128, kind: JobKind, idempotency: Option<(&str, &str)>) -> NewJob {
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

fn succeeded(samples: i64) -> Finish {
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

/// A curve record without its store-assigned id (identity columns may differ between
/// engines after a failed insert), for comparing traces.
#[derive(Debug)]
#[allow(dead_code)]
struct CurveNoId {
    key: String,
    version: i64,
    job_id: Uuid,
    curve: serde_json::Value,
    fidelity: CurveFidelity,
    provenance: serde_json::Value,
    created_by: String,
    created_ms: i64,
    published: Option<(String, i64)>,
}

impl From<&store::CurveRecord> for CurveNoId {
    fn from(c: &store::CurveRecord) -> Self {
        CurveNoId {
            key: c.key.clone(),
            version: c.version,
            job_id: c.job_id,
            curve: c.curve.clone(),
            fidelity: c.fidelity,
            provenance: c.provenance.clone(),
            created_by: c.created_by.clone(),
            created_ms: c.created_ms,
            published: c
                .published
                .as_ref()
                .map(|p| (p.published_by.clone(), p.published_ms)),
        }
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
fn new_campaign(n: u128, content: &str) -> NewCampaign {
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
fn campaign_no_seq(c: &CampaignSummary) -> String {
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

/// One script over every `Store` method; returns what each call gave (ids and times are fixed,
/// so the two engines must agree exactly).
async fn script(store: &dyn Store) -> Vec<String> {
    let mut trace = Vec::new();
    let mut log = |what: &str, value: String| trace.push(format!("{what}: {value}"));
    store.ping().await.unwrap();

    // Idempotency: replay, conflict.
    let a = store
        .submit_job(new_job(1, JobKind::Simulate, Some(("key-1", "sha-a"))))
        .await
        .unwrap();
    assert!(matches!(a, Submitted::Created(_)));
    log("submit a", format!("{a:?}"));
    let replay = store
        .submit_job(new_job(2, JobKind::Simulate, Some(("key-1", "sha-a"))))
        .await
        .unwrap();
    assert!(matches!(&replay, Submitted::Replayed(j) if j.id == Uuid::from_u128(0x5eed_0001)));
    log("replay", format!("{replay:?}"));
    let conflict = store
        .submit_job(new_job(3, JobKind::Simulate, Some(("key-1", "sha-b"))))
        .await
        .unwrap();
    assert!(matches!(conflict, Submitted::KeyConflict(id) if id == Uuid::from_u128(0x5eed_0001)));
    log("conflict", format!("{conflict:?}"));
    for n in 4..=7 {
        let kind = if n == 6 {
            JobKind::Sweep
        } else {
            JobKind::Simulate
        };
        log(
            "submit",
            format!(
                "{:?}",
                store.submit_job(new_job(n, kind, None)).await.unwrap()
            ),
        );
    }
    let seed_back = store
        .get_job(Uuid::from_u128(0x5eed_0004))
        .await
        .unwrap()
        .unwrap()
        .seed;
    assert_eq!(seed_back, u64::MAX - 4);

    // Claim order is submission order.
    let c1 = store.claim_job("w", 2_000, 5_000).await.unwrap().unwrap();
    assert_eq!(c1.id, Uuid::from_u128(0x5eed_0001));
    log("claim", format!("{c1:?}"));
    let progress = JobProgress {
        simulated_time_s: 0.25,
        end_time_s: 0.5,
        fraction: 0.5,
        eta_s: Some(2.0),
    };
    log(
        "beat",
        format!(
            "{:?}",
            store
                .heartbeat(c1.id, 1, Some(progress), 2_500, 5_000)
                .await
                .unwrap()
        ),
    );
    // A heartbeat without progress keeps the stored progress.
    store.heartbeat(c1.id, 1, None, 2_600, 5_000).await.unwrap();
    assert_eq!(
        store.get_job(c1.id).await.unwrap().unwrap().progress,
        Some(progress)
    );
    assert!(store
        .finish_job(c1.id, 1, succeeded(42), 3_000)
        .await
        .unwrap());
    log("done", format!("{:?}", store.get_job(c1.id).await.unwrap()));
    log(
        "blocks",
        format!("{:?}", store.track_blocks(c1.id).await.unwrap()),
    );
    let names = store.plot_names(c1.id).await.unwrap();
    assert_eq!(names, vec!["Force".to_string(), "wear".to_string()]);
    log(
        "plot",
        format!("{:?}", store.plot(c1.id, "wear").await.unwrap()),
    );
    log(
        "no plot",
        format!("{:?}", store.plot(c1.id, "none").await.unwrap()),
    );

    // Cancel: queued job at once; running job flagged, seen by its heartbeat.
    let c4 = store.claim_job("w", 3_100, 5_000).await.unwrap().unwrap();
    assert_eq!(c4.id, Uuid::from_u128(0x5eed_0004));
    let queued_cancel = store
        .request_cancel(Uuid::from_u128(0x5eed_0005), 3_200)
        .await
        .unwrap()
        .unwrap();
    assert_eq!(queued_cancel.status, JobStatus::Cancelled);
    log("cancel queued", format!("{queued_cancel:?}"));
    let running_cancel = store.request_cancel(c4.id, 3_300).await.unwrap().unwrap();
    assert_eq!(running_cancel.status, JobStatus::Running);
    assert!(running_cancel.cancel_requested);
    let beat = store.heartbeat(c4.id, 1, None, 3_400, 5_000).await.unwrap();
    assert!(beat.owned && beat.cancel_requested);
    assert!(store
        .finish_job(c4.id, 1, Finish::Cancelled, 3_500)
        .await
        .unwrap());
    let terminal = store.request_cancel(c1.id, 3_600).await.unwrap().unwrap();
    assert_eq!(terminal.status, JobStatus::Succeeded);
    assert!(!terminal.cancel_requested);
    assert!(store
        .request_cancel(Uuid::from_u128(1), 0)
        .await
        .unwrap()
        .is_none());

    // A cancelled-while-running job whose worker died ends cancelled, not re-queued.
    let sweep_key = "ah64/clean/modified-archard";
    log(
        "active sweep",
        format!("{:?}", store.active_sweep(sweep_key).await.unwrap()),
    );
    let c6 = store.claim_job("w", 4_000, 100).await.unwrap().unwrap();
    assert_eq!(c6.kind, JobKind::Sweep);
    store.request_cancel(c6.id, 4_010).await.unwrap();
    assert_eq!(store.requeue_expired(4_200, 3).await.unwrap(), 1);
    log(
        "cancelled by sweep",
        format!("{:?}", store.get_job(c6.id).await.unwrap()),
    );
    assert_eq!(
        store.get_job(c6.id).await.unwrap().unwrap().status,
        JobStatus::Cancelled
    );
    // A failure keeps its message; a sweep success stores its curve.
    let c7 = store.claim_job("w", 5_000, 5_000).await.unwrap().unwrap();
    assert!(store
        .finish_job(
            c7.id,
            1,
            Finish::Failed("field `x` must be > 0".into()),
            5_100
        )
        .await
        .unwrap());
    assert_eq!(
        store
            .get_job(c7.id)
            .await
            .unwrap()
            .unwrap()
            .error
            .as_deref(),
        Some("field `x` must be > 0")
    );
    let s = store
        .submit_job(new_job(8, JobKind::Sweep, None))
        .await
        .unwrap();
    log("sweep", format!("{s:?}"));
    log(
        "active sweep",
        format!("{:?}", store.active_sweep(sweep_key).await.unwrap()),
    );
    let c8 = store.claim_job("w", 6_000, 5_000).await.unwrap().unwrap();
    let curve = |points: i64, duration: f64, seeds: i64, at: i64| NewCurve {
        key: sweep_key.into(),
        job_id: c8.id,
        curve: serde_json::json!({"k_sl": [1.0, 0.8125], "points": points}),
        fidelity: CurveFidelity {
            points,
            duration_per_point_s: Some(duration),
            seeds,
        },
        provenance: serde_json::json!({"config": "launcher-design", "seeds": [1, 2, 3]}),
        created_by: "tester".into(),
        code_version: "test".into(),
        created_ms: at,
    };
    let finish_with = |c: NewCurve| {
        let Finish::Succeeded {
            summary,
            blocks,
            plots,
            ..
        } = succeeded(0)
        else {
            unreachable!()
        };
        Finish::Succeeded {
            summary,
            blocks,
            plots,
            curve: Some(Box::new(c)),
        }
    };
    assert!(store
        .finish_job(c8.id, 1, finish_with(curve(5, 10.0, 3, 6_500)), 6_500)
        .await
        .unwrap());
    // A sweep stores version 1, not published: reports do not use it yet.
    let v1 = store::latest_curve(store, sweep_key)
        .await
        .unwrap()
        .unwrap();
    assert_eq!((v1.version, v1.published.clone()), (1, None));
    assert_eq!(v1.fidelity, curve(5, 10.0, 3, 0).fidelity);
    assert_eq!(store.published_curve(sweep_key).await.unwrap(), None);
    assert_eq!(store.get_curve(v1.id).await.unwrap(), Some(v1.clone()));
    log("curve v1", format!("{:?}", CurveNoId::from(&v1)));
    let published = store
        .publish_curve(v1.id, "eng", false, 6_600)
        .await
        .unwrap();
    let PublishOutcome::Published(p1) = published else {
        panic!("{published:?}")
    };
    assert_eq!(p1.published.as_ref().map(|p| p.published_ms), Some(6_600));
    assert_eq!(
        store.published_curve(sweep_key).await.unwrap(),
        Some(p1.clone())
    );
    assert!(store.claim_job("w", 7_000, 5_000).await.unwrap().is_none());

    // Listing: newest first, cursor pages, status filter; counts.
    let page = store
        .list_jobs(
            PageRequest {
                limit: 3,
                after_seq: None,
            },
            JobFilter::default(),
        )
        .await
        .unwrap();
    log("page 1", format!("{page:?}"));
    let cursor = page
        .next_cursor
        .as_deref()
        .map(|c| c.parse::<i64>().unwrap());
    let page2 = store
        .list_jobs(
            PageRequest {
                limit: 3,
                after_seq: cursor,
            },
            JobFilter::default(),
        )
        .await
        .unwrap();
    log("page 2", format!("{page2:?}"));
    assert_eq!(page.items.len() + page2.items.len(), 6);
    assert_eq!(page2.next_cursor, None);
    let cancelled = store
        .list_jobs(
            PageRequest {
                limit: 10,
                after_seq: None,
            },
            JobFilter {
                status: Some(JobStatus::Cancelled),
                ..JobFilter::default()
            },
        )
        .await
        .unwrap();
    assert_eq!(cancelled.items.len(), 3);
    log("counts", format!("{:?}", store.job_counts().await.unwrap()));

    // Rails and measurements. The third (R-1) is a back-filled older reading: recorded last,
    // measured first; the latest measurement is still the first one (issue 17).
    let measured = [
        ("2024-01-02", 1_704_153_600_000_i64),
        ("2024-01-02", 1_704_153_600_000),
        ("2019-03-04", 1_551_657_600_000),
    ];
    for (i, serial) in ["R-1", "R-2", "R-1"].iter().enumerate() {
        let m = store
            .add_measurement(NewMeasurement {
                id: Uuid::from_u128(0xabc0 + i as u128),
                serial: serial.to_string(),
                dimensions_mm: serde_json::json!({"w": 10.25 + i as f64}),
                measured_by: "insp".into(),
                measured_at: measured[i].0.into(),
                measured_ms: measured[i].1,
                location: "depot".into(),
                rattle_space: 0.01 * (i + 1) as f64,
                recorded_by: "eng".into(),
                recorded_ms: 8_000 + i as i64,
            })
            .await
            .unwrap();
        log("measurement", format!("{m:?}"));
    }
    let r1 = store.get_rail("R-1").await.unwrap().unwrap();
    assert_eq!(r1.measurements, 2);
    assert_eq!(r1.created_ms, 8_000);
    assert_eq!(store.get_rail("R-9").await.unwrap(), None);
    log(
        "rails",
        format!(
            "{:?}",
            store
                .list_rails(PageRequest {
                    limit: 1,
                    after_seq: None
                })
                .await
                .unwrap()
        ),
    );
    log(
        "measurements",
        format!(
            "{:?}",
            store
                .measurements(
                    "R-1",
                    PageRequest {
                        limit: 5,
                        after_seq: None
                    }
                )
                .await
                .unwrap()
        ),
    );
    let latest = store.latest_measurement("R-1").await.unwrap().unwrap();
    assert_eq!(latest.id, Uuid::from_u128(0xabc0));
    assert_eq!(latest.measured_at, "2024-01-02");

    // Version 2 of the same key: fewer points, shorter runs, one seed.
    let c9 = store
        .submit_job(new_job(9, JobKind::Sweep, None))
        .await
        .unwrap();
    log("sweep 9", format!("{c9:?}"));
    let c9 = store.claim_job("w", 6_700, 5_000).await.unwrap().unwrap();
    let mut low = curve(2, 0.3, 1, 6_800);
    low.job_id = c9.id;
    assert!(store
        .finish_job(c9.id, 1, finish_with(low), 6_800)
        .await
        .unwrap());
    let v2 = store::latest_curve(store, sweep_key)
        .await
        .unwrap()
        .unwrap();
    assert_eq!(v2.version, 2);
    // Publishing the lower-fidelity v2 over v1 is refused without force; nothing changes.
    let refused = store
        .publish_curve(v2.id, "eng", false, 6_900)
        .await
        .unwrap();
    match &refused {
        PublishOutcome::LowerFidelity { published, reason } => {
            assert_eq!(published.id, v1.id);
            assert!(reason.contains("2 points < 5"), "{reason}");
            assert!(reason.contains("0.3 s per point < 10 s"), "{reason}");
            assert!(reason.contains("1 seeds per point < 3"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        store.published_curve(sweep_key).await.unwrap(),
        Some(p1.clone())
    );
    // With force it is published, and v1 no longer is.
    let forced = store
        .publish_curve(v2.id, "boss", true, 7_000)
        .await
        .unwrap();
    assert!(matches!(&forced, PublishOutcome::Published(c) if c.id == v2.id));
    assert_eq!(
        store
            .published_curve(sweep_key)
            .await
            .unwrap()
            .map(|c| c.id),
        Some(v2.id)
    );
    assert_eq!(
        store.get_curve(v1.id).await.unwrap().unwrap().published,
        None
    );
    // Back to the higher-fidelity v1: no force needed; publishing it again is a no-op success.
    assert!(matches!(
        store
            .publish_curve(v1.id, "eng", false, 7_100)
            .await
            .unwrap(),
        PublishOutcome::Published(_)
    ));
    let again = store
        .publish_curve(v1.id, "eng", false, 7_200)
        .await
        .unwrap();
    let PublishOutcome::Published(again) = again else {
        panic!("{again:?}")
    };
    assert_eq!(again.published.map(|p| p.published_ms), Some(7_100));
    assert_eq!(
        store
            .publish_curve(999_999, "eng", true, 7_300)
            .await
            .unwrap(),
        PublishOutcome::NotFound
    );
    assert_eq!(store.published_curve("none").await.unwrap(), None);
    let all = store
        .list_curves(
            PageRequest {
                limit: 1,
                after_seq: None,
            },
            CurveFilter {
                key: Some(sweep_key.into()),
            },
        )
        .await
        .unwrap();
    assert_eq!(all.items.len(), 1);
    assert_eq!(all.items[0].version, 2);
    let rest = store
        .list_curves(
            PageRequest {
                limit: 10,
                after_seq: all.next_cursor.as_deref().and_then(|c| c.parse().ok()),
            },
            CurveFilter::default(),
        )
        .await
        .unwrap();
    let versions: Vec<_> = rest.items.iter().map(CurveNoId::from).collect();
    log("curves page 2", format!("{versions:?}"));
    assert_eq!(rest.items.len(), 1);

    // Campaigns: the content comes back as the exact text stored (floats, non-ASCII, 2 MB);
    // the same content is stored once; lists are newest first, without content.
    let big = format!(
        r#"{{"name":"c2","samples":[{}]}}"#,
        vec!["[0.30000000000000004,-1e-300,2.5e300,0.1]"; 50_000].join(",")
    );
    let c1 = store
        .insert_campaign(new_campaign(1, r#"{"name":"c1","µ":"ü","x":0.1}"#))
        .await
        .unwrap();
    let CampaignInsert::Created(c1) = c1 else {
        panic!("{c1:?}")
    };
    assert_eq!(
        c1.content_bytes,
        r#"{"name":"c1","µ":"ü","x":0.1}"#.len() as i64
    );
    let c2 = store.insert_campaign(new_campaign(2, &big)).await.unwrap();
    let CampaignInsert::Created(c2) = c2 else {
        panic!("{c2:?}")
    };
    assert!(c2.seq > c1.seq);
    let again = store
        .insert_campaign(new_campaign(3, r#"{"name":"c1","µ":"ü","x":0.1}"#))
        .await
        .unwrap();
    assert_eq!(again, CampaignInsert::Existing(c1.clone()));
    let got = store.get_campaign(c2.id).await.unwrap().unwrap();
    assert_eq!(got.content, big);
    assert_eq!(got.summary, c2);
    let got = store.get_campaign(c1.id).await.unwrap().unwrap();
    assert_eq!(got.content, r#"{"name":"c1","µ":"ü","x":0.1}"#);
    assert_eq!(
        store
            .get_campaign(Uuid::from_u128(0xca3a_0003))
            .await
            .unwrap(),
        None
    );
    let first = store
        .list_campaigns(PageRequest {
            limit: 1,
            after_seq: None,
        })
        .await
        .unwrap();
    assert_eq!(first.items, vec![c2.clone()]);
    let second = store
        .list_campaigns(PageRequest {
            limit: 1,
            after_seq: first.next_cursor.as_deref().and_then(|c| c.parse().ok()),
        })
        .await
        .unwrap();
    assert_eq!(second.items, vec![c1.clone()]);
    assert_eq!(second.next_cursor, None);
    log(
        "campaigns",
        format!("{} | {}", campaign_no_seq(&c2), campaign_no_seq(&c1)),
    );

    // Tokens (their ids are random: compare the rest).
    let t = store
        .create_token("ops", Role::Engineer, "sha-t", 9_000)
        .await
        .unwrap();
    store
        .create_token("boss", Role::Admin, "sha-u", 9_001)
        .await
        .unwrap();
    store
        .create_token("lab", Role::TestEngineer, "sha-v", 9_002)
        .await
        .unwrap();
    assert_eq!(
        store.find_token("sha-v").await.unwrap().map(|t| t.role),
        Some(Role::TestEngineer)
    );
    assert_eq!(
        store.find_token("sha-t").await.unwrap().map(|t| t.role),
        Some(Role::Engineer)
    );
    assert!(store.revoke_token(t.id, 9_100).await.unwrap());
    assert!(!store.revoke_token(t.id, 9_200).await.unwrap());
    assert_eq!(store.find_token("sha-t").await.unwrap(), None);
    let tokens: Vec<_> = store
        .list_tokens()
        .await
        .unwrap()
        .into_iter()
        .map(|t| (t.name, t.role, t.created_ms, t.revoked))
        .collect();
    log("tokens", format!("{tokens:?}"));
    trace
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_store_method_behaves_as_on_sqlite() {
    let db = fresh_db!("script");
    let pg = store::open(&db.url).await.expect("open postgres store");
    let pg_trace = script(pg.as_ref()).await;

    let dir = crate::support::temp_dir("pg-script");
    let sqlite = store::open(&dir.db_url()).await.expect("open sqlite store");
    let sqlite_trace = script(sqlite.as_ref()).await;
    assert_eq!(pg_trace.len(), sqlite_trace.len());
    for (p, s) in pg_trace.iter().zip(&sqlite_trace) {
        assert_eq!(p, s);
    }
}
