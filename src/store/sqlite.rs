//! SQLite implementation of [`Store`]: WAL journal (readers never block the writer), a busy
//! timeout, `BEGIN IMMEDIATE` for multi-statement writes (takes the write lock up front, so two
//! writers queue instead of deadlocking on a lock upgrade), single-statement job claims. The
//! operations both engines share are in `store::portable`; this file holds the connection,
//! the dialect (`Dialect`), and how claims and the lease sweeps pick and lock their rows.

use super::delegate::portable_store_methods;
use super::dialect::Dialect;
use super::job_records::JobRecord;
use super::portable::Portable;
use super::{NewJob, Store, StoreError, StoreFuture, Submitted, WorkerHost};
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteJournalMode, SqlitePool, SqlitePoolOptions, SqliteSynchronous,
};
use sqlx::Sqlite;
use std::str::FromStr;
use std::time::Duration;
use uuid::Uuid;

/// Store on one SQLite file.
#[derive(Clone)]
pub struct SqliteStore {
    pool: SqlitePool,
}

const BEGIN_WRITE: &str = "BEGIN IMMEDIATE";

/// The operations shared with PostgreSQL.
type Shared = Portable<Sqlite>;

impl Dialect for Sqlite {
    const BEGIN_WRITE: Option<&'static str> = Some(BEGIN_WRITE);
    const FOR_UPDATE: &'static str = "";
    const LOCK_PARENT: Option<&'static str> = None;
    const LOCK_CURVE_KEY: Option<&'static str> = None;

    const JOBS_PAGE: &'static str = "WHERE (?4 IS NULL OR seq < ?4) \
        AND (?1 IS NULL OR status = ?1) AND (?2 IS NULL OR parent_id = ?2) \
        AND (?3 = 0 OR parent_id IS NULL) ORDER BY seq DESC LIMIT ?5";
    const HEARTBEAT: &'static str = "UPDATE jobs SET lease_expires_ms = ?3 + ?4, \
        progress_simulated_s = COALESCE(?5, progress_simulated_s), \
        progress_end_s = COALESCE(?6, progress_end_s), \
        progress_fraction = COALESCE(?7, progress_fraction), \
        progress_eta_s = CASE WHEN ?5 IS NULL THEN progress_eta_s ELSE ?8 END \
        WHERE id = ?1 AND attempt = ?2 AND status = 'running' RETURNING cancel_requested";
    const RAILS_PAGE: &'static str = "SELECT r.serial, r.seq, r.created_ms, \
        (SELECT COUNT(*) FROM rail_measurements m WHERE m.serial = r.serial) AS measurements \
        FROM rails r WHERE (?1 IS NULL OR r.seq < ?1) ORDER BY r.seq DESC LIMIT ?2";
    const MEASUREMENTS_PAGE: &'static str = "SELECT * FROM rail_measurements \
        WHERE serial = ?1 AND (?2 IS NULL OR seq < ?2) ORDER BY seq DESC LIMIT ?3";
    const CURVES_PAGE: &'static str = "WHERE (?1 IS NULL OR v.curve_key = ?1) \
        AND (?2 IS NULL OR v.id < ?2) ORDER BY v.id DESC LIMIT ?3";
    const CAMPAIGNS_PAGE: &'static str =
        "WHERE (?1 IS NULL OR seq < ?1) ORDER BY seq DESC LIMIT ?2";
    const PLOT_NAMES: &'static str = "SELECT name FROM job_plots WHERE job_id = ?1 ORDER BY name";
    const TOKENS: &'static str = "SELECT * FROM api_tokens ORDER BY created_ms, id";
}

impl SqliteStore {
    /// Connect (creating the file when the URL says `mode=rwc`).
    pub async fn connect(url: &str) -> Result<Self, StoreError> {
        let options = SqliteConnectOptions::from_str(url)?
            .journal_mode(SqliteJournalMode::Wal)
            .synchronous(SqliteSynchronous::Normal)
            .busy_timeout(Duration::from_secs(10))
            .foreign_keys(true);
        let pool = SqlitePoolOptions::new()
            .max_connections(8)
            .connect_with(options)
            .await?;
        Ok(Self { pool })
    }

    /// The underlying pool (benchmarks and tests).
    pub fn pool(&self) -> &SqlitePool {
        &self.pool
    }
}

impl Store for SqliteStore {
    fn migrate(&self) -> StoreFuture<'_, ()> {
        Box::pin(async move {
            sqlx::migrate!("./migrations/sqlite")
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
            // One statement picks the oldest queued row and takes it: the sub-select and the
            // update run under the same write lock, so two workers can never take the same job.
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let job =
                Shared::claim(&mut tx, None, &worker, host.as_ref(), now_ms, lease_ms).await?;
            if job.is_some() {
                tx.commit().await?;
            } else {
                tx.rollback().await?;
            }
            Ok(job)
        })
    }
    fn expire_leases(&self, attempts: Vec<(Uuid, i64)>, now_ms: i64) -> StoreFuture<'_, u64> {
        Box::pin(async move {
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let mut n = 0;
            for (id, attempt) in attempts {
                n += u64::from(Shared::expire_lease(&mut tx, id, attempt, now_ms).await?);
            }
            tx.commit().await?;
            Ok(n)
        })
    }
    fn requeue_expired(&self, now_ms: i64, max_attempts: i64) -> StoreFuture<'_, u64> {
        Box::pin(async move {
            // Cheap check first: most calls find nothing and need no write lock.
            let any = sqlx::query(
                "SELECT 1 FROM jobs WHERE status = 'running' AND lease_expires_ms < ?1 LIMIT 1",
            )
            .bind(now_ms)
            .fetch_optional(&self.pool)
            .await?;
            if any.is_none() {
                return Ok(0);
            }
            // All expired leases in one statement, under the one write lock.
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let changed = Shared::lose_leases(&mut tx, None, now_ms, max_attempts).await?;
            tx.commit().await?;
            Ok(changed)
        })
    }

    portable_store_methods!(Shared);
}
