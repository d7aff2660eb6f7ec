//! Fan-out's migrations, on SQLite and on PostgreSQL: a database written before fan-out keeps
//! its data through the fan-out migration, and its curve through the curve versions migration
//! (published version 1); the queue carries on.

use crate::fresh_db;
use crate::store_fanout::{point_result, submit, sweep_job, CURVE_KEY};
use railwear::jobs::{JobKind, JobStatus};
use railwear::store::{self, CurveFidelity, Store};
use uuid::Uuid;

/// The migrator of the first migration only (the schema before fan-out), from the repository's
/// file, so its checksum is the one `store::open` expects.
async fn first_migration(engine: &str, dir: &crate::support::TempDir) -> sqlx::migrate::Migrator {
    let source = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("migrations")
        .join(engine)
        .join("0001_init.sql");
    std::fs::copy(&source, dir.path().join("0001_init.sql")).expect("copy migration 0001");
    sqlx::migrate::Migrator::new(dir.path())
        .await
        .expect("migrator")
}

const OLD_DONE: Uuid = Uuid::from_u128(0x01d_0001);
const OLD_QUEUED: Uuid = Uuid::from_u128(0x01d_0002);

/// What a database written before fan-out holds, read through the migrated store: the jobs,
/// their tracks, plots and curve are intact and the queue carries on.
async fn check_migrated(store: &dyn Store) {
    let done = store.get_job(OLD_DONE).await.unwrap().unwrap();
    assert_eq!(
        (done.status, done.kind, done.seq, done.track_samples),
        (JobStatus::Succeeded, JobKind::Sweep, 1, 7)
    );
    assert_eq!(done.result, Some(serde_json::json!({"points": 5})));
    assert_eq!((done.parent, done.children), (None, None));
    let blocks = store.track_blocks(OLD_DONE).await.unwrap();
    assert_eq!(blocks.len(), 1);
    assert_eq!(blocks[0].data, vec![1, 2, 3]);
    assert_eq!(
        store.plot(OLD_DONE, "penalization.svg").await.unwrap(),
        Some("<svg/>".to_string())
    );
    // The curve stored before curve versions is version 1 of its key, published (reports keep
    // using it), with the sweep's provenance and its fidelity as far as it was recorded.
    let curve = store
        .published_curve(CURVE_KEY)
        .await
        .unwrap()
        .expect("migrated curve");
    assert_eq!((curve.job_id, curve.version), (OLD_DONE, 1));
    assert_eq!(
        curve.published.as_ref().map(|p| p.published_by.as_str()),
        Some("migration")
    );
    assert_eq!(
        curve.fidelity,
        CurveFidelity {
            points: 2,
            duration_per_point_s: None,
            seeds: 1
        }
    );
    assert_eq!(curve.created_by, "eng");
    assert_eq!(curve.provenance["params"], serde_json::json!({}));
    let data: railwear::analysis::penalization::PenalizationCurve =
        serde_json::from_value(curve.curve.clone()).expect("the migrated curve still reads");
    assert!((data.k_sl(0.7684).unwrap() - 0.5).abs() < 1e-12);
    let claimed = store.claim_job("w", 10, 1_000).await.unwrap().unwrap();
    assert_eq!((claimed.id, claimed.attempt), (OLD_QUEUED, 1));
    assert!(store
        .finish_job(OLD_QUEUED, 1, point_result(0), 20)
        .await
        .unwrap());
    let new = submit(store, sweep_job(1)).await;
    assert_eq!(store.get_job(new).await.unwrap().unwrap().seq, 3);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_fan_out_migration_keeps_sqlite_data() {
    let dir = crate::support::temp_dir("migrate-sqlite");
    let url = dir.db_url();
    let old = store::sqlite::SqliteStore::connect(&url).await.unwrap();
    first_migration("sqlite", &dir)
        .await
        .run(old.pool())
        .await
        .unwrap();
    for (id, status, result) in [
        (OLD_DONE, "succeeded", Some("{\"points\":5}")),
        (OLD_QUEUED, "queued", None),
    ] {
        sqlx::query(
            "INSERT INTO jobs (id, kind, status, params, seed, code_version, submitted_by, \
             created_ms, result, track_samples) VALUES (?1, 'sweep', ?2, '{}', 5, 'old', 'eng', 1, ?3, ?4)",
        )
        .bind(id.to_string())
        .bind(status)
        .bind(result)
        .bind(if result.is_some() { 7 } else { 0 })
        .execute(old.pool())
        .await
        .unwrap();
    }
    for sql in [
        "INSERT INTO job_track_blocks VALUES (?1, 0, 7, 0.0, 1.0, x'010203')",
        "INSERT INTO job_plots VALUES (?1, 'penalization.svg', '<svg/>')",
        "INSERT INTO penalization_curves VALUES ('ah64/clean/modified-archard', ?1, '{\"design_rattle_space\":0.8317,\"points\":[{\"rattle_space\":0.7684,\"rail_wear_rate_mg_per_h\":2.0},{\"rattle_space\":0.8317,\"rail_wear_rate_mg_per_h\":1.0}]}', 2)",
    ] {
        sqlx::query(sql)
            .bind(OLD_DONE.to_string())
            .execute(old.pool())
            .await
            .unwrap();
    }
    old.pool().close().await;
    let store = store::open(&url)
        .await
        .expect("open applies the fan-out migration");
    check_migrated(store.as_ref()).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_fan_out_migration_keeps_postgres_data() {
    let db = fresh_db!("migrate");
    let dir = crate::support::temp_dir("migrate-pg");
    let old = store::postgres::PgStore::connect(&db.url).await.unwrap();
    first_migration("postgres", &dir)
        .await
        .run(old.pool())
        .await
        .unwrap();
    for (id, status, result) in [
        (OLD_DONE, "succeeded", Some("{\"points\":5}")),
        (OLD_QUEUED, "queued", None),
    ] {
        sqlx::query(
            "INSERT INTO jobs (id, kind, status, params, seed, code_version, submitted_by, \
             created_ms, result, track_samples) VALUES ($1, 'sweep', $2, '{}', 5, 'old', 'eng', 1, $3, $4)",
        )
        .bind(id)
        .bind(status)
        .bind(result)
        .bind(if result.is_some() { 7i64 } else { 0 })
        .execute(old.pool())
        .await
        .unwrap();
    }
    for sql in [
        "INSERT INTO job_track_blocks VALUES ($1, 0, 7, 0.0, 1.0, '\\x010203')",
        "INSERT INTO job_plots VALUES ($1, 'penalization.svg', '<svg/>')",
        "INSERT INTO penalization_curves VALUES ('ah64/clean/modified-archard', $1, '{\"design_rattle_space\":0.8317,\"points\":[{\"rattle_space\":0.7684,\"rail_wear_rate_mg_per_h\":2.0},{\"rattle_space\":0.8317,\"rail_wear_rate_mg_per_h\":1.0}]}', 2)",
    ] {
        sqlx::query(sql)
            .bind(OLD_DONE)
            .execute(old.pool())
            .await
            .unwrap();
    }
    old.pool().close().await;
    let store = store::open(&db.url)
        .await
        .expect("open applies the fan-out migration");
    check_migrated(store.as_ref()).await;
}
