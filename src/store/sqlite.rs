//! SQLite implementation of [`Store`]: WAL journal (readers never block the writer), a busy
//! timeout, `BEGIN IMMEDIATE` for multi-statement writes (takes the write lock up front, so two
//! writers queue instead of deadlocking on a lock upgrade), single-statement job claims. The
//! operations both engines share are in [`super::portable`]; this file holds the connection,
//! the dialect ([`Dialect`]), submission, claims and the lease sweeps.

use super::bookkeeping::Bookkeeping;
use super::delegate::portable_store_methods;
use super::dialect::Dialect;
use super::job_records::JobRecord;
use super::portable::Portable;
use super::rows::{corrupt, JobRow, LostRow, StoredUuid, JOB_COLUMNS};
use super::{NewJob, Store, StoreError, StoreFuture, Submitted, WorkerHost};
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteJournalMode, SqlitePool, SqlitePoolOptions, SqliteSynchronous,
};
use sqlx::{Row, Sqlite};
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
/// Attempt log and fan-out bookkeeping (shared with PostgreSQL), inside a `BEGIN IMMEDIATE`
/// transaction: SQLite has one writer, so the child counts it reads are final.
type Books = Bookkeeping<Sqlite>;

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
        Box::pin(async move {
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            if let Some((key, sha)) = &job.idempotency {
                let existing =
                    sqlx::query("SELECT id, request_sha256 FROM jobs WHERE idempotency_key = ?1")
                        .bind(key)
                        .fetch_optional(&mut *tx)
                        .await?;
                if let Some(row) = existing {
                    let id = row.try_get::<StoredUuid, _>("id")?.get()?;
                    let stored_sha: Option<String> = row.try_get("request_sha256")?;
                    tx.rollback().await?;
                    if stored_sha.as_deref() == Some(sha.as_str()) {
                        let record = Shared::job_in(&mut *self.pool.acquire().await?, id)
                            .await?
                            .ok_or_else(|| corrupt("idempotent job vanished"))?;
                        return Ok(Submitted::Replayed(record));
                    }
                    return Ok(Submitted::KeyConflict(id));
                }
            }
            let (key, sha) = match &job.idempotency {
                Some((k, s)) => (Some(k.clone()), Some(s.clone())),
                None => (None, None),
            };
            sqlx::query(
                "INSERT INTO jobs (id, kind, status, params, seed, code_version, submitted_by, \
                 idempotency_key, request_sha256, curve_key, created_ms) \
                 VALUES (?1, ?2, 'queued', ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
            )
            .bind(job.id.to_string())
            .bind(job.kind.as_str())
            .bind(job.params.to_string())
            .bind(job.seed as i64)
            .bind(&job.code_version)
            .bind(&job.submitted_by)
            .bind(key)
            .bind(sha)
            .bind(&job.curve_key)
            .bind(job.created_ms)
            .execute(&mut *tx)
            .await?;
            let record = Shared::job_in(&mut tx, job.id)
                .await?
                .ok_or_else(|| corrupt("submitted job vanished"))?;
            tx.commit().await?;
            Ok(Submitted::Created(record))
        })
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
            // One statement: the sub-select and the update run under the same write lock, so
            // two workers can never take the same job. A parent queued for its assembly keeps
            // the progress of its children.
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let sql = format!(
                "UPDATE jobs SET status = 'running', attempt = attempt + 1, lease_owner = ?1, \
                 lease_expires_ms = ?2 + ?3, started_ms = COALESCE(started_ms, ?2), \
                 attempt_started_ms = ?2, lease_host = ?4, lease_pid = ?5, lease_instance = ?6, \
                 progress_simulated_s = CASE WHEN children_total > 0 THEN progress_simulated_s END, \
                 progress_end_s = CASE WHEN children_total > 0 THEN progress_end_s END, \
                 progress_fraction = CASE WHEN children_total > 0 THEN progress_fraction END, \
                 progress_eta_s = NULL \
                 WHERE seq = (SELECT seq FROM jobs WHERE status = 'queued' ORDER BY seq LIMIT 1) \
                 AND status = 'queued' RETURNING {JOB_COLUMNS}"
            );
            let row: Option<JobRow> = sqlx::query_as(&sql)
                .bind(&worker)
                .bind(now_ms)
                .bind(lease_ms)
                .bind(host.as_ref().map(|h| h.host.clone()))
                .bind(host.as_ref().map(|h| i64::from(h.pid)))
                .bind(host.as_ref().map(|h| h.instance.clone()))
                .fetch_optional(&mut *tx)
                .await?;
            let Some(job) = row.map(JobRecord::try_from).transpose()? else {
                tx.rollback().await?;
                return Ok(None);
            };
            sqlx::query(
                "INSERT INTO job_attempts (job_id, attempt, worker, started_ms, outcome) \
                 VALUES (?1, ?2, ?3, ?4, 'running')",
            )
            .bind(job.id.to_string())
            .bind(job.attempt)
            .bind(&worker)
            .bind(now_ms)
            .execute(&mut *tx)
            .await?;
            tx.commit().await?;
            Ok(Some(job))
        })
    }
    fn expire_leases(&self, attempts: Vec<(Uuid, i64)>, now_ms: i64) -> StoreFuture<'_, u64> {
        Box::pin(async move {
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let mut n = 0;
            for (id, attempt) in attempts {
                n += sqlx::query(
                    "UPDATE jobs SET lease_expires_ms = ?3 - 1 \
                     WHERE id = ?1 AND attempt = ?2 AND status = 'running'",
                )
                .bind(id.to_string())
                .bind(attempt)
                .bind(now_ms)
                .execute(&mut *tx)
                .await?
                .rows_affected();
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
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let expired: Vec<LostRow> = sqlx::query_as(
                "UPDATE jobs SET \
                 error = CASE WHEN cancel_requested = 1 THEN error \
                   ELSE 'attempt ' || attempt || ' lost its worker (lease expired)' END, \
                 finished_ms = CASE WHEN cancel_requested = 1 OR attempt >= ?2 THEN ?1 ELSE NULL END, \
                 status = CASE WHEN cancel_requested = 1 THEN 'cancelled' \
                   WHEN attempt >= ?2 THEN 'failed' ELSE 'queued' END, \
                 lease_owner = NULL, lease_expires_ms = NULL \
                 WHERE status = 'running' AND lease_expires_ms < ?1 \
                 RETURNING id, attempt, status, error, parent_id, child_index",
            )
            .bind(now_ms)
            .bind(max_attempts)
            .fetch_all(&mut *tx)
            .await?;
            let changed = expired.len() as u64;
            for row in expired {
                Books::lost(&mut tx, row.try_into()?, now_ms).await?;
            }
            tx.commit().await?;
            Ok(changed)
        })
    }

    portable_store_methods!(Shared);
}
