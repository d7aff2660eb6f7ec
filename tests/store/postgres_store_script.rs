//! The PostgreSQL store against the local server, one scripted use of every `Store` method:
//! it gives the same records on PostgreSQL as on SQLite, call by call (the races and leases are
//! in `postgres_store.rs`).

use crate::fresh_db;
use crate::postgres_store::{campaign_no_seq, new_campaign, new_job, succeeded};
use railwear::config::Role;
use railwear::jobs::{JobKind, JobProgress, JobStatus};
use railwear::store::{
    self, CampaignInsert, CurveFidelity, CurveFilter, Finish, JobFilter, NewCurve, NewMeasurement,
    PageRequest, PublishOutcome, Store, Submitted,
};
use uuid::Uuid;

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
