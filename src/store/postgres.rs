//! PostgreSQL implementation of [`Store`], the shared queue and store when API servers and
//! `railwear worker` processes run on many hosts (issue 6). Same semantics as
//! [`super::sqlite::SqliteStore`]: a claim takes the oldest queued row with
//! `FOR UPDATE SKIP LOCKED` inside one transaction (concurrent claimers skip each other's row
//! instead of waiting or taking it twice), every worker write is fenced by the job's attempt, and
//! expired leases go back to the queue until `max_attempts`. The operations both engines share
//! are in `store::portable`; this file holds the connection, the dialect (`Dialect`), and
//! how claims and the lease sweeps pick and lock their rows.
//!
//! Lock order, to keep concurrent writers free of deadlocks: a transaction that touches a child
//! job and its parent locks the parent row first (`Dialect::LOCK_PARENT`), then the child.

use super::delegate::portable_store_methods;
use super::dialect::Dialect;
use super::job_records::JobRecord;
use super::portable::Portable;
use super::{NewJob, Store, StoreError, StoreFuture, Submitted, WorkerHost};
use sqlx::postgres::{PgConnectOptions, PgPool, PgPoolOptions};
use sqlx::{Postgres, Row};
use std::str::FromStr;
use std::time::Duration;
use uuid::Uuid;

/// Store on one PostgreSQL database.
#[derive(Clone)]
pub struct PgStore {
    pool: PgPool,
}

/// The operations shared with SQLite.
type Shared = Portable<Postgres>;

impl Dialect for Postgres {
    const BEGIN_WRITE: Option<&'static str> = None;
    const FOR_UPDATE: &'static str = " FOR UPDATE";
    /// `parent_id` never changes, so the sub-select reads it unlocked.
    const LOCK_PARENT: Option<&'static str> =
        Some("SELECT 1 FROM jobs WHERE id = (SELECT parent_id FROM jobs WHERE id = $1) FOR UPDATE");
    const LOCK_CURVE_KEY: Option<&'static str> = Some("SELECT pg_advisory_xact_lock(hashtext($1))");

    const JOBS_PAGE: &'static str = "WHERE ($4::BIGINT IS NULL OR seq < $4) \
        AND ($1::TEXT IS NULL OR status = $1) AND ($2::UUID IS NULL OR parent_id = $2) \
        AND (NOT $3 OR parent_id IS NULL) ORDER BY seq DESC LIMIT $5";
    const HEARTBEAT: &'static str = "UPDATE jobs SET lease_expires_ms = $3 + $4, \
        progress_simulated_s = COALESCE($5, progress_simulated_s), \
        progress_end_s = COALESCE($6, progress_end_s), \
        progress_fraction = COALESCE($7, progress_fraction), \
        progress_eta_s = CASE WHEN $5::DOUBLE PRECISION IS NULL THEN progress_eta_s ELSE $8 END \
        WHERE id = $1 AND attempt = $2 AND status = 'running' RETURNING cancel_requested";
    const RAILS_PAGE: &'static str = "SELECT r.serial, r.seq, r.created_ms, \
        (SELECT COUNT(*) FROM rail_measurements m WHERE m.serial = r.serial) AS measurements \
        FROM rails r WHERE ($1::BIGINT IS NULL OR r.seq < $1) ORDER BY r.seq DESC LIMIT $2";
    const MEASUREMENTS_PAGE: &'static str = "SELECT * FROM rail_measurements \
        WHERE serial = $1 AND ($2::BIGINT IS NULL OR seq < $2) ORDER BY seq DESC LIMIT $3";
    const CURVES_PAGE: &'static str = "WHERE ($1::TEXT IS NULL OR v.curve_key = $1) \
        AND ($2::BIGINT IS NULL OR v.id < $2) ORDER BY v.id DESC LIMIT $3";
    const CAMPAIGNS_PAGE: &'static str =
        "WHERE ($1::BIGINT IS NULL OR seq < $1) ORDER BY seq DESC LIMIT $2";
    /// COLLATE "C": byte order, the same order SQLite's default BINARY collation gives.
    const PLOT_NAMES: &'static str =
        "SELECT name FROM job_plots WHERE job_id = $1 ORDER BY name COLLATE \"C\"";
    /// SQLite orders UUID text by bytes; `id::TEXT COLLATE "C"` gives the same order.
    const TOKENS: &'static str =
        "SELECT * FROM api_tokens ORDER BY created_ms, id::TEXT COLLATE \"C\"";
}

impl PgStore {
    /// Connect to `postgres://user@host:port/database` (any URL sqlx accepts).
    pub async fn connect(url: &str) -> Result<Self, StoreError> {
        let options = PgConnectOptions::from_str(url)?;
        let pool = PgPoolOptions::new()
            .max_connections(8)
            .acquire_timeout(Duration::from_secs(10))
            .connect_with(options)
            .await?;
        Ok(Self { pool })
    }

    /// The underlying pool (benchmarks and tests).
    pub fn pool(&self) -> &PgPool {
        &self.pool
    }
}

impl Store for PgStore {
    fn migrate(&self) -> StoreFuture<'_, ()> {
        Box::pin(async move {
            // sqlx takes an advisory lock, so API and worker processes starting together on
            // one database apply the migrations once.
            sqlx::migrate!("./migrations/postgres")
                .run(&self.pool)
                .await?;
            Ok(())
        })
    }
    fn submit_job(&self, job: NewJob) -> StoreFuture<'_, Submitted> {
        Box::pin(Shared::submit_job(&self.pool, job))
    }
    fn claim_job_on(
        &self,
        worker: &str,
        host: Option<&WorkerHost>,
        now_ms: i64,
        lease_ms: i64,
    ) -> StoreFuture<'_, Option<JobRecord>> {
        let (worker, host) = (worker.to_string(), host.cloned());
        Box::pin(async move {
            let mut tx = self.pool.begin().await?;
            // The row lock is held to commit; a concurrent claimer skips the locked row and
            // takes the next one, so no job is handed out twice and nobody waits.
            let picked = sqlx::query(
                "SELECT seq FROM jobs WHERE status = 'queued' ORDER BY seq LIMIT 1 \
                 FOR UPDATE SKIP LOCKED",
            )
            .fetch_optional(&mut *tx)
            .await?;
            let Some(picked) = picked else {
                tx.rollback().await?;
                return Ok(None);
            };
            let seq: i64 = picked.try_get("seq")?;
            let record =
                Shared::claim(&mut tx, Some(seq), &worker, host.as_ref(), now_ms, lease_ms).await?;
            tx.commit().await?;
            Ok(record)
        })
    }
    fn expire_leases(&self, attempts: Vec<(Uuid, i64)>, now_ms: i64) -> StoreFuture<'_, u64> {
        Box::pin(async move {
            let mut n = 0;
            // One statement per job (no other row touched): no lock order to keep.
            let mut conn = self.pool.acquire().await?;
            for (id, attempt) in attempts {
                n += u64::from(Shared::expire_lease(&mut conn, id, attempt, now_ms).await?);
            }
            Ok(n)
        })
    }
    fn requeue_expired(&self, now_ms: i64, max_attempts: i64) -> StoreFuture<'_, u64> {
        Box::pin(async move {
            let candidates: Vec<(Uuid,)> = sqlx::query_as(
                "SELECT id FROM jobs WHERE status = 'running' AND lease_expires_ms < $1 \
                 ORDER BY seq LIMIT 1000",
            )
            .bind(now_ms)
            .fetch_all(&self.pool)
            .await?;
            let mut changed = 0;
            // One transaction per job: parent row first (children), then the job itself with
            // SKIP LOCKED, so every idle worker can run this at once: they split the expired
            // rows and skip a row whose worker is finishing it right now.
            for (id,) in candidates {
                let mut tx = self.pool.begin().await?;
                Shared::lock_parent_of(&mut tx, id).await?;
                let locked = sqlx::query(
                    "SELECT 1 FROM jobs WHERE id = $1 AND status = 'running' \
                     AND lease_expires_ms < $2 FOR UPDATE SKIP LOCKED",
                )
                .bind(id)
                .bind(now_ms)
                .fetch_optional(&mut *tx)
                .await?;
                if locked.is_none() {
                    tx.rollback().await?;
                    continue;
                }
                changed += Shared::lose_leases(&mut tx, Some(id), now_ms, max_attempts).await?;
                tx.commit().await?;
            }
            Ok(changed)
        })
    }

    portable_store_methods!(Shared);
}
