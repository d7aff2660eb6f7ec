//! Fan-out in the store, on SQLite and on PostgreSQL: a job's children are created with the move
//! to `waiting` in one transaction fenced by the parent's attempt; the child finish that
//! completes the set re-queues the parent exactly once, even when all children finish at the
//! same moment through separate connection pools (as separate worker processes would); only
//! one assembler can claim and finish the parent; a failed, cancelled or lost child fails the
//! parent naming the child and cancels its siblings; cancelling the parent cancels the children.
//! One scripted lifecycle gives the same records on both engines. The migrations of a database
//! written before fan-out are in `store_fanout_migration.rs`.

use crate::fresh_db;
use railwear::jobs::{ChildCounts, ChildOf, JobKind, JobProgress, JobStatus};
use railwear::store::{
    self, AttemptOutcome, CurveFidelity, FanOut, FanOutResult, Finish, JobFilter, NewChild,
    NewCurve, NewJob, PageRequest, Store, Submitted,
};
use std::sync::Arc;
use uuid::Uuid;

pub(crate) const CURVE_KEY: &str = "ah64/clean/modified-archard";

/// Sweep `n` of a test: fixed id, seed and times so two stores can be compared exactly.
pub(crate) fn sweep_job(n: u128) -> NewJob {
    NewJob {
        id: Uuid::from_u128(0xf0_0000 + n),
        kind: JobKind::Sweep,
        params: serde_json::json!({ "points": 3, "n": n as u64 }),
        plan: None,
        seed: u64::MAX - n as u64,
        code_version: "test".into(),
        submitted_by: "planner-7".into(),
        idempotency: None,
        curve_key: Some(CURVE_KEY.into()),
        created_ms: 1_000 + n as i64,
    }
}

/// The fan-out of sweep `n` into `count` children with fixed ids.
fn children_of(n: u128, count: usize) -> FanOut {
    FanOut {
        children: (0..count)
            .map(|i| NewChild {
                id: Uuid::from_u128(0xc0_0000 + n * 0x100 + i as u128),
                kind: JobKind::SweepPoint,
                params: serde_json::json!({ "points": count, "point": i }),
                plan: Some(serde_json::json!({ "point": i })),
            })
            .collect(),
        end_time_s: 0.5 * count as f64,
    }
}

fn child_id(n: u128, i: usize) -> Uuid {
    Uuid::from_u128(0xc0_0000 + n * 0x100 + i as u128)
}

pub(crate) fn point_result(i: usize) -> Finish {
    Finish::Succeeded {
        summary: serde_json::json!({ "point": i, "rail_wear_rate_mg_per_h": 1.0 + 0.1 * i as f64 }),
        blocks: Vec::new(),
        plots: Vec::new(),
        curve: None,
    }
}

fn assembled(job_id: Uuid, created_ms: i64) -> Finish {
    Finish::Succeeded {
        summary: serde_json::json!({ "points": 3 }),
        blocks: Vec::new(),
        plots: vec![("penalization.svg".into(), "<svg/>".into())],
        curve: Some(Box::new(NewCurve {
            key: CURVE_KEY.into(),
            job_id,
            curve: serde_json::json!({ "k_sl": [1.0, 0.75] }),
            fidelity: CurveFidelity {
                points: 3,
                duration_per_point_s: Some(1.0),
                seeds: 3,
            },
            provenance: serde_json::json!({}),
            created_by: "eng".into(),
            code_version: "test".into(),
            created_ms,
        })),
    }
}

fn outcomes(attempts: &[store::AttemptRecord]) -> Vec<AttemptOutcome> {
    attempts.iter().map(|a| a.outcome).collect()
}

pub(crate) async fn submit(store: &dyn Store, job: NewJob) -> Uuid {
    match store.submit_job(job).await.unwrap() {
        Submitted::Created(job) => job.id,
        other => panic!("{other:?}"),
    }
}

/// The fan-out lifecycle step by step; returns what each step gave (ids and times are fixed,
/// so both engines must agree exactly).
async fn script(store: &dyn Store) -> Vec<String> {
    let mut trace = Vec::new();
    let mut log = |what: &str, value: String| trace.push(format!("{what}: {value}"));

    // 1. Fan-out fenced by the parent's attempt; children inherit seed, version, submitter.
    let p = submit(store, sweep_job(1)).await;
    let claim = store.claim_job("w1", 2_000, 5_000).await.unwrap().unwrap();
    assert_eq!((claim.id, claim.attempt), (p, 1));
    assert_eq!(
        store.fan_out(p, 2, children_of(1, 3), 2_100).await.unwrap(),
        FanOutResult::Stale,
        "a fan-out by an attempt that does not own the job"
    );
    assert!(store.children(p).await.unwrap().is_empty());
    assert_eq!(
        store.fan_out(p, 1, children_of(1, 3), 2_100).await.unwrap(),
        FanOutResult::FannedOut
    );
    let parent = store.get_job(p).await.unwrap().unwrap();
    assert_eq!(parent.status, JobStatus::Waiting);
    assert_eq!(parent.lease_owner, None);
    assert_eq!(
        parent.children,
        Some(ChildCounts {
            total: 3,
            succeeded: 0,
            failed: 0,
            cancelled: 0
        })
    );
    assert_eq!(
        parent.progress,
        Some(JobProgress {
            simulated_time_s: 0.0,
            end_time_s: 1.5,
            fraction: 0.0,
            eta_s: None
        })
    );
    log("waiting parent", format!("{parent:?}"));
    // The same attempt cannot fan out twice: no duplicate children.
    assert_eq!(
        store.fan_out(p, 1, children_of(1, 3), 2_200).await.unwrap(),
        FanOutResult::Stale
    );
    assert_eq!(store.children(p).await.unwrap().len(), 3);
    assert_eq!(
        outcomes(&store.attempts(p).await.unwrap()),
        [AttemptOutcome::FannedOut]
    );
    // Each child keeps the plan its fan-out gave it.
    for (i, child) in store.children(p).await.unwrap().iter().enumerate() {
        assert_eq!(
            store.job_plan(child.id).await.unwrap(),
            Some(serde_json::json!({ "point": i }))
        );
    }

    // 2. Listing: children by parent; top level without them.
    let page = PageRequest {
        limit: 10,
        after_seq: None,
    };
    let kids = store
        .list_jobs(
            page,
            JobFilter {
                parent: Some(p),
                ..JobFilter::default()
            },
        )
        .await
        .unwrap();
    assert_eq!(kids.items.len(), 3);
    let top = store
        .list_jobs(
            page,
            JobFilter {
                top_level: true,
                ..JobFilter::default()
            },
        )
        .await
        .unwrap();
    assert_eq!(top.items.iter().map(|j| j.id).collect::<Vec<_>>(), [p]);

    // 3. Children run: claimed in index order, each with the parent's seed.
    let mut claimed = Vec::new();
    for i in 0..3 {
        let c = store.claim_job("w2", 3_000, 1_000).await.unwrap().unwrap();
        assert_eq!(c.id, child_id(1, i));
        assert_eq!(c.kind, JobKind::SweepPoint);
        assert_eq!(
            c.parent,
            Some(ChildOf {
                parent_id: p,
                index: i as i64
            })
        );
        assert_eq!(
            (c.seed, c.code_version.as_str(), c.submitted_by.as_str()),
            (u64::MAX - 1, "test", "planner-7")
        );
        assert_eq!(c.lease_owner.as_deref(), Some("w2"));
        claimed.push(c);
    }
    log("child", format!("{:?}", claimed[0]));
    assert!(store
        .finish_job(child_id(1, 0), 1, point_result(0), 3_500)
        .await
        .unwrap());
    assert!(store
        .finish_job(child_id(1, 2), 1, point_result(2), 3_600)
        .await
        .unwrap());
    let parent = store.get_job(p).await.unwrap().unwrap();
    assert_eq!(parent.status, JobStatus::Waiting);
    assert_eq!(parent.children.map(|c| c.succeeded), Some(2));
    log("two of three", format!("{parent:?}"));

    // 4. Child 1's worker dies: its lease expires, it is re-queued, the stale attempt is fenced
    //    out, the new attempt's finish completes the set and re-queues the parent.
    assert_eq!(store.requeue_expired(4_001, 3).await.unwrap(), 1);
    let again = store.claim_job("w3", 4_100, 1_000).await.unwrap().unwrap();
    assert_eq!((again.id, again.attempt), (child_id(1, 1), 2));
    assert!(!store
        .finish_job(child_id(1, 1), 1, point_result(1), 4_200)
        .await
        .unwrap());
    assert_eq!(
        store.get_job(p).await.unwrap().unwrap().status,
        JobStatus::Waiting
    );
    assert!(store
        .finish_job(child_id(1, 1), 2, point_result(1), 4_300)
        .await
        .unwrap());
    let attempts = store.attempts(child_id(1, 1)).await.unwrap();
    assert_eq!(
        outcomes(&attempts),
        [AttemptOutcome::Lost, AttemptOutcome::Succeeded]
    );
    assert_eq!(attempts[0].worker, "w2");
    log("child attempts", format!("{attempts:?}"));
    let parent = store.get_job(p).await.unwrap().unwrap();
    assert_eq!(parent.status, JobStatus::Queued);
    assert_eq!(parent.progress.map(|p| p.fraction), Some(1.0));
    log("ready parent", format!("{parent:?}"));

    // 5. Assembly: one claim (keeps the children's progress), one fenced finish with the curve.
    let assembly = store.claim_job("w1", 5_000, 5_000).await.unwrap().unwrap();
    assert_eq!((assembly.id, assembly.attempt), (p, 2));
    assert_eq!(assembly.progress, parent.progress);
    let results = store.children(p).await.unwrap();
    assert!(results.iter().all(|c| c.status == JobStatus::Succeeded));
    assert_eq!(
        results.iter().map(|c| c.index).collect::<Vec<_>>(),
        [0, 1, 2]
    );
    log("children", format!("{results:?}"));
    assert!(store
        .finish_job(p, 2, assembled(p, 5_100), 5_100)
        .await
        .unwrap());
    assert!(!store
        .finish_job(p, 2, assembled(p, 5_200), 5_200)
        .await
        .unwrap());
    assert_eq!(
        outcomes(&store.attempts(p).await.unwrap()),
        [AttemptOutcome::FannedOut, AttemptOutcome::Succeeded]
    );
    assert_eq!(
        store::latest_curve(store, CURVE_KEY)
            .await
            .unwrap()
            .map(|c| c.job_id),
        Some(p)
    );
    log(
        "assembled",
        format!("{:?}", store.get_job(p).await.unwrap()),
    );

    // 6. A child fails: the parent fails naming it; the queued sibling is cancelled at once,
    //    the running one is flagged and ends cancelled.
    let q = submit(store, sweep_job(2)).await;
    store.claim_job("w1", 6_000, 5_000).await.unwrap().unwrap();
    store.fan_out(q, 1, children_of(2, 3), 6_100).await.unwrap();
    store.claim_job("w2", 6_200, 5_000).await.unwrap().unwrap();
    store.claim_job("w3", 6_200, 5_000).await.unwrap().unwrap();
    assert!(store
        .finish_job(
            child_id(2, 0),
            1,
            Finish::Failed("simulation diverged: at t = 0.1 s".into()),
            6_300
        )
        .await
        .unwrap());
    let failed = store.get_job(q).await.unwrap().unwrap();
    assert_eq!(failed.status, JobStatus::Failed);
    assert_eq!(
        failed.error.as_deref(),
        Some(
            format!(
                "child 0 (job {}) failed: simulation diverged: at t = 0.1 s",
                child_id(2, 0)
            )
            .as_str()
        )
    );
    assert_eq!(
        store.get_job(child_id(2, 2)).await.unwrap().unwrap().status,
        JobStatus::Cancelled
    );
    let beat = store
        .heartbeat(child_id(2, 1), 1, None, 6_400, 5_000)
        .await
        .unwrap();
    assert!(beat.owned && beat.cancel_requested);
    store
        .finish_job(child_id(2, 1), 1, Finish::Cancelled, 6_500)
        .await
        .unwrap();
    let failed = store.get_job(q).await.unwrap().unwrap();
    assert_eq!(
        failed.children,
        Some(ChildCounts {
            total: 3,
            succeeded: 0,
            failed: 1,
            cancelled: 2
        })
    );
    assert_eq!(failed.finished_ms, Some(6_300));
    log("failed parent", format!("{failed:?}"));

    // 7. Cancelling a waiting parent: its queued child ends at once, its running child is
    //    flagged, and when that child's lease expires it ends cancelled, not re-queued.
    let r = submit(store, sweep_job(3)).await;
    store.claim_job("w1", 7_000, 5_000).await.unwrap().unwrap();
    store.fan_out(r, 1, children_of(3, 2), 7_100).await.unwrap();
    store.claim_job("w2", 7_200, 100).await.unwrap().unwrap();
    let cancelled = store.request_cancel(r, 7_300).await.unwrap().unwrap();
    assert_eq!(cancelled.status, JobStatus::Cancelled);
    assert_eq!(cancelled.children.map(|c| c.cancelled), Some(1));
    let running = store.get_job(child_id(3, 0)).await.unwrap().unwrap();
    assert_eq!(
        (running.status, running.cancel_requested),
        (JobStatus::Running, true)
    );
    assert_eq!(store.requeue_expired(7_400, 3).await.unwrap(), 1);
    assert_eq!(
        store.get_job(child_id(3, 0)).await.unwrap().unwrap().status,
        JobStatus::Cancelled
    );
    log(
        "cancelled parent",
        format!("{:?}", store.get_job(r).await.unwrap()),
    );

    // 8. Cancelling a queued child fails its parent, naming it.
    let s = submit(store, sweep_job(4)).await;
    store.claim_job("w1", 8_000, 5_000).await.unwrap().unwrap();
    store.fan_out(s, 1, children_of(4, 2), 8_100).await.unwrap();
    let child = store
        .request_cancel(child_id(4, 1), 8_200)
        .await
        .unwrap()
        .unwrap();
    assert_eq!(child.status, JobStatus::Cancelled);
    let failed = store.get_job(s).await.unwrap().unwrap();
    assert_eq!(failed.status, JobStatus::Failed);
    assert_eq!(
        failed.error.as_deref(),
        Some(format!("child 1 (job {}) was cancelled", child_id(4, 1)).as_str())
    );
    assert_eq!(failed.children.map(|c| c.cancelled), Some(2));

    // 9. A child that keeps losing its worker fails after max_attempts, and so does its parent.
    let t = submit(store, sweep_job(5)).await;
    store.claim_job("w1", 9_000, 5_000).await.unwrap().unwrap();
    store.fan_out(t, 1, children_of(5, 2), 9_100).await.unwrap();
    store.claim_job("w2", 9_200, 100).await.unwrap().unwrap();
    assert_eq!(store.requeue_expired(9_400, 1).await.unwrap(), 1);
    let failed = store.get_job(t).await.unwrap().unwrap();
    assert_eq!(failed.status, JobStatus::Failed);
    assert_eq!(
        failed.error.as_deref(),
        Some(
            format!(
                "child 0 (job {}) failed: attempt 1 lost its worker (lease expired)",
                child_id(5, 0)
            )
            .as_str()
        )
    );
    assert_eq!(
        store.get_job(child_id(5, 1)).await.unwrap().unwrap().status,
        JobStatus::Cancelled
    );

    // 10. A cancel requested before the fan-out: nothing is created.
    let u = submit(store, sweep_job(6)).await;
    store.claim_job("w1", 10_000, 5_000).await.unwrap().unwrap();
    store.request_cancel(u, 10_100).await.unwrap();
    assert_eq!(
        store
            .fan_out(u, 1, children_of(6, 2), 10_200)
            .await
            .unwrap(),
        FanOutResult::CancelRequested
    );
    assert!(store.children(u).await.unwrap().is_empty());
    assert!(store
        .finish_job(u, 1, Finish::Cancelled, 10_300)
        .await
        .unwrap());
    assert!(store
        .claim_job("w1", 11_000, 5_000)
        .await
        .unwrap()
        .is_none());
    log("counts", format!("{:?}", store.job_counts().await.unwrap()));
    trace
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn fan_out_lifecycle_is_the_same_on_sqlite_and_postgres() {
    let dir = crate::support::temp_dir("fanout-script");
    let sqlite = store::open(&dir.db_url()).await.expect("open sqlite store");
    let sqlite_trace = script(sqlite.as_ref()).await;

    let db = fresh_db!("fanout_script");
    let pg = store::open(&db.url).await.expect("open postgres store");
    let pg_trace = script(pg.as_ref()).await;
    assert_eq!(pg_trace.len(), sqlite_trace.len());
    for (p, s) in pg_trace.iter().zip(&sqlite_trace) {
        assert_eq!(p, s);
    }
}

/// `rounds` sweeps of `n` children each. Per round, every child is finished at the same moment
/// by its own task, spread over `stores` (separate connection pools, as separate worker
/// processes have); then every store tries to claim the parent at the same moment. The parent
/// must be re-queued exactly once, claimed by exactly one assembler, and finished once.
async fn race(stores: Vec<Arc<dyn Store>>, rounds: u128, n: usize) {
    let store = Arc::clone(&stores[0]);
    for round in 0..rounds {
        let p = submit(store.as_ref(), sweep_job(100 + round)).await;
        let claim = store
            .claim_job("fanner", 0, 600_000)
            .await
            .unwrap()
            .unwrap();
        assert_eq!(claim.id, p);
        assert_eq!(
            store
                .fan_out(p, 1, children_of(100 + round, n), 1)
                .await
                .unwrap(),
            FanOutResult::FannedOut
        );
        for i in 0..n {
            let c = store
                .claim_job("runner", 2, 600_000)
                .await
                .unwrap()
                .unwrap();
            assert_eq!(c.id, child_id(100 + round, i));
        }
        // All children finish at once.
        let start = Arc::new(tokio::sync::Barrier::new(n));
        let mut tasks = Vec::new();
        for i in 0..n {
            let s = Arc::clone(&stores[i % stores.len()]);
            let start = Arc::clone(&start);
            tasks.push(tokio::spawn(async move {
                start.wait().await;
                s.finish_job(child_id(100 + round, i), 1, point_result(i), 10)
                    .await
                    .unwrap()
            }));
        }
        for t in tasks {
            assert!(t.await.unwrap(), "a child's own finish was fenced out");
        }
        let parent = store.get_job(p).await.unwrap().unwrap();
        assert_eq!(
            parent.children.map(|c| c.succeeded),
            Some(n as i64),
            "a child's count was lost"
        );
        assert_eq!(parent.status, JobStatus::Queued, "round {round}");

        // Every store tries to assemble at once: one claim wins.
        let start = Arc::new(tokio::sync::Barrier::new(stores.len()));
        let mut tasks = Vec::new();
        for (w, s) in stores.iter().enumerate() {
            let s = Arc::clone(s);
            let start = Arc::clone(&start);
            tasks.push(tokio::spawn(async move {
                start.wait().await;
                s.claim_job(&format!("assembler-{w}"), 20, 600_000)
                    .await
                    .unwrap()
            }));
        }
        let mut winners = Vec::new();
        for t in tasks {
            if let Some(job) = t.await.unwrap() {
                winners.push(job);
            }
        }
        assert_eq!(
            winners.len(),
            1,
            "round {round}: {} assemblers",
            winners.len()
        );
        assert_eq!((winners[0].id, winners[0].attempt), (p, 2));
        // The winner and a late duplicate both try to finish: one write lands.
        let (a, b) = tokio::join!(
            stores[0].finish_job(p, 2, assembled(p, 30), 30),
            stores[stores.len() - 1].finish_job(p, 2, assembled(p, 31), 31),
        );
        assert!(
            a.unwrap() ^ b.unwrap(),
            "exactly one finish of the assembly"
        );
        assert_eq!(
            outcomes(&store.attempts(p).await.unwrap()),
            [AttemptOutcome::FannedOut, AttemptOutcome::Succeeded]
        );
        for i in 0..n {
            assert_eq!(
                outcomes(&store.attempts(child_id(100 + round, i)).await.unwrap()),
                [AttemptOutcome::Succeeded]
            );
        }
        assert_eq!(
            store.get_job(p).await.unwrap().unwrap().status,
            JobStatus::Succeeded
        );
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn racing_child_finishes_on_sqlite_assemble_the_parent_once() {
    let dir = crate::support::temp_dir("fanout-race");
    let mut stores = Vec::new();
    for _ in 0..4 {
        stores.push(store::open(&dir.db_url()).await.expect("open sqlite store"));
    }
    race(stores, 8, 8).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn racing_child_finishes_on_postgres_assemble_the_parent_once() {
    let db = fresh_db!("fanout_race");
    let mut stores = Vec::new();
    for _ in 0..4 {
        stores.push(store::open(&db.url).await.expect("open postgres store"));
    }
    race(stores, 8, 8).await;
}
