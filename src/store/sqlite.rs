//! SQLite implementation of [`Store`]: WAL journal (readers never block the writer), a busy
//! timeout, `BEGIN IMMEDIATE` for multi-statement writes (takes the write lock up front, so two
//! writers queue instead of deadlocking on a lock upgrade), single-statement job claims.

use super::job_records::{JobKind, JobProgress, JobRecord, JobStatus};
use super::{
    publish_refusal, AttemptOutcome, AttemptRecord, CampaignCounts, CampaignInsert, CampaignRecord,
    CampaignSummary, ChildCounts, ChildOf, ChildRecord, CurveFidelity, CurveFilter, CurveRecord,
    FanOut, FanOutResult, Finish, Heartbeat, HostLease, JobFilter, MeasurementRecord, NewCampaign,
    NewCurve, NewJob, NewMeasurement, Page, PageRequest, Publication, PublishOutcome, RailRecord,
    ReleaseOutcome, Store, StoreError, StoreFuture, Submitted, TokenRecord, TrackBlock, WorkerHost,
};
use super::{JobCheckpoint, NewCheckpoint};
use crate::config::Role;
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteConnection, SqliteJournalMode, SqlitePool, SqlitePoolOptions,
    SqliteRow, SqliteSynchronous,
};
use sqlx::Row;
use std::str::FromStr;
use std::time::Duration;
use uuid::Uuid;

/// Store on one SQLite file.
#[derive(Clone)]
pub struct SqliteStore {
    pool: SqlitePool,
}

const BEGIN_WRITE: &str = "BEGIN IMMEDIATE";

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

fn corrupt(what: impl Into<String>) -> StoreError {
    StoreError::Corrupt(what.into())
}

fn parse_uuid(text: &str) -> Result<Uuid, StoreError> {
    Uuid::parse_str(text).map_err(|_| corrupt(format!("bad uuid `{text}`")))
}

fn parse_json(text: &str, what: &str) -> Result<serde_json::Value, StoreError> {
    serde_json::from_str(text).map_err(|e| corrupt(format!("{what}: {e}")))
}

/// Curve versions with their publication (left join: `p.curve_id = v.id` only for the
/// published one).
const CURVE_SELECT: &str = "SELECT v.id, v.curve_key, v.version, v.job_id, v.curve, v.provenance, \
     v.points, v.duration_per_point_s, v.seeds, v.created_by, v.code_version, v.created_ms, \
     p.curve_id AS published_id, p.published_by, p.published_ms \
     FROM curve_versions v LEFT JOIN published_curves p ON p.curve_key = v.curve_key";

fn curve_from_row(row: &SqliteRow) -> Result<CurveRecord, StoreError> {
    let id: i64 = row.try_get("id")?;
    let job_id: String = row.try_get("job_id")?;
    let job_id = parse_uuid(&job_id)?;
    let curve: String = row.try_get("curve")?;
    let provenance: String = row.try_get("provenance")?;
    let published_id: Option<i64> = row.try_get("published_id")?;
    Ok(CurveRecord {
        id,
        key: row.try_get("curve_key")?,
        version: row.try_get("version")?,
        job_id,
        curve: parse_json(&curve, "penalization curve")?,
        fidelity: CurveFidelity {
            points: row.try_get("points")?,
            duration_per_point_s: row.try_get("duration_per_point_s")?,
            seeds: row.try_get("seeds")?,
        },
        provenance: parse_json(&provenance, "curve provenance")?,
        created_by: row.try_get("created_by")?,
        code_version: row.try_get("code_version")?,
        created_ms: row.try_get("created_ms")?,
        published: match published_id {
            Some(p) if p == id => Some(Publication {
                published_by: row.try_get("published_by")?,
                published_ms: row.try_get("published_ms")?,
            }),
            _ => None,
        },
    })
}

/// Store a sweep's curve as the next version of its key (inside the finishing transaction).
async fn insert_curve_version(
    tx: &mut SqliteConnection,
    curve: NewCurve,
) -> Result<(), StoreError> {
    sqlx::query(
        "INSERT INTO curve_versions (curve_key, version, job_id, curve, provenance, points, \
         duration_per_point_s, seeds, created_by, code_version, created_ms) \
         SELECT ?1, COALESCE(MAX(version), 0) + 1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10 \
         FROM curve_versions WHERE curve_key = ?1",
    )
    .bind(curve.key)
    .bind(curve.job_id.to_string())
    .bind(curve.curve.to_string())
    .bind(curve.provenance.to_string())
    .bind(curve.fidelity.points)
    .bind(curve.fidelity.duration_per_point_s)
    .bind(curve.fidelity.seeds)
    .bind(curve.created_by)
    .bind(curve.code_version)
    .bind(curve.created_ms)
    .execute(&mut *tx)
    .await?;
    Ok(())
}

fn job_from_row(row: &SqliteRow) -> Result<JobRecord, StoreError> {
    let kind: String = row.try_get("kind")?;
    let status: String = row.try_get("status")?;
    let params: String = row.try_get("params")?;
    let result: Option<String> = row.try_get("result")?;
    let id: String = row.try_get("id")?;
    let progress = match (
        row.try_get::<Option<f64>, _>("progress_simulated_s")?,
        row.try_get::<Option<f64>, _>("progress_end_s")?,
        row.try_get::<Option<f64>, _>("progress_fraction")?,
    ) {
        (Some(simulated_time_s), Some(end_time_s), Some(fraction)) => Some(JobProgress {
            simulated_time_s,
            end_time_s,
            fraction,
            eta_s: row.try_get("progress_eta_s")?,
        }),
        _ => None,
    };
    Ok(JobRecord {
        id: parse_uuid(&id)?,
        seq: row.try_get("seq")?,
        kind: JobKind::parse(&kind).ok_or_else(|| corrupt(format!("job kind `{kind}`")))?,
        status: JobStatus::parse(&status)
            .ok_or_else(|| corrupt(format!("job status `{status}`")))?,
        params: parse_json(&params, "job params")?,
        seed: row.try_get::<i64, _>("seed")? as u64,
        code_version: row.try_get("code_version")?,
        submitted_by: row.try_get("submitted_by")?,
        attempt: row.try_get("attempt")?,
        cancel_requested: row.try_get::<i64, _>("cancel_requested")? != 0,
        created_ms: row.try_get("created_ms")?,
        started_ms: row.try_get("started_ms")?,
        finished_ms: row.try_get("finished_ms")?,
        progress,
        result: result
            .as_deref()
            .map(|r| parse_json(r, "job result"))
            .transpose()?,
        error: row.try_get("error")?,
        track_samples: row.try_get("track_samples")?,
        curve_key: row.try_get("curve_key")?,
        lease_owner: row.try_get("lease_owner")?,
        parent: match (
            row.try_get::<Option<String>, _>("parent_id")?,
            row.try_get::<Option<i64>, _>("child_index")?,
        ) {
            (Some(parent_id), Some(index)) => Some(ChildOf {
                parent_id: parse_uuid(&parent_id)?,
                index,
            }),
            _ => None,
        },
        children: match row.try_get::<i64, _>("children_total")? {
            0 => None,
            total => Some(ChildCounts {
                total,
                succeeded: row.try_get("children_succeeded")?,
                failed: row.try_get("children_failed")?,
                cancelled: row.try_get("children_cancelled")?,
            }),
        },
    })
}

fn measurement_from_row(row: &SqliteRow) -> Result<MeasurementRecord, StoreError> {
    let id: String = row.try_get("id")?;
    let dims: String = row.try_get("dimensions_mm")?;
    Ok(MeasurementRecord {
        id: parse_uuid(&id)?,
        seq: row.try_get("seq")?,
        serial: row.try_get("serial")?,
        dimensions_mm: parse_json(&dims, "measurement dimensions")?,
        measured_by: row.try_get("measured_by")?,
        measured_at: row.try_get("measured_at")?,
        measured_ms: row.try_get("measured_ms")?,
        location: row.try_get("location")?,
        rattle_space: row.try_get("rattle_space")?,
        recorded_by: row.try_get("recorded_by")?,
        recorded_ms: row.try_get("recorded_ms")?,
    })
}

fn rail_from_row(row: &SqliteRow) -> Result<RailRecord, StoreError> {
    Ok(RailRecord {
        serial: row.try_get("serial")?,
        seq: row.try_get("seq")?,
        created_ms: row.try_get("created_ms")?,
        measurements: row.try_get("measurements")?,
    })
}

fn token_from_row(row: &SqliteRow) -> Result<TokenRecord, StoreError> {
    let id: String = row.try_get("id")?;
    let role: String = row.try_get("role")?;
    Ok(TokenRecord {
        id: parse_uuid(&id)?,
        name: row.try_get("name")?,
        role: Role::parse(&role).ok_or_else(|| corrupt(format!("token role `{role}`")))?,
        created_ms: row.try_get("created_ms")?,
        revoked: row.try_get::<Option<i64>, _>("revoked_ms")?.is_some(),
    })
}

/// Columns of a campaign summary (everything but the content).
const CAMPAIGN_SUMMARY: &str = "seq, id, name, created_by, created_ms, content_sha256, \
    content_bytes, tests, specimens, increments, accelerometer_records";

fn campaign_from_row(row: &SqliteRow) -> Result<CampaignSummary, StoreError> {
    let id: String = row.try_get("id")?;
    Ok(CampaignSummary {
        id: parse_uuid(&id)?,
        seq: row.try_get("seq")?,
        name: row.try_get("name")?,
        created_by: row.try_get("created_by")?,
        created_ms: row.try_get("created_ms")?,
        content_sha256: row.try_get("content_sha256")?,
        content_bytes: row.try_get("content_bytes")?,
        counts: CampaignCounts {
            tests: row.try_get("tests")?,
            specimens: row.try_get("specimens")?,
            increments: row.try_get("increments")?,
            accelerometer_records: row.try_get("accelerometer_records")?,
        },
    })
}

/// Cut a fetched `limit + 1` list into a page.
fn paginate<T>(mut items: Vec<T>, limit: i64, seq: impl Fn(&T) -> i64) -> Page<T> {
    let limit = limit.max(0) as usize;
    let next_cursor = if items.len() > limit {
        items.truncate(limit);
        items.last().map(|last| seq(last).to_string())
    } else {
        None
    };
    Page { items, next_cursor }
}

const JOB_COLUMNS: &str = "seq, id, kind, status, params, seed, code_version, submitted_by, \
    attempt, cancel_requested, created_ms, started_ms, finished_ms, progress_simulated_s, \
    progress_end_s, progress_fraction, progress_eta_s, result, error, track_samples, curve_key, \
    lease_owner, parent_id, child_index, children_total, children_succeeded, children_failed, \
    children_cancelled";

/// Parent bookkeeping when child `child` (index `index`) of `parent` ended with `status`, in the
/// caller's write transaction (SQLite has one writer, so the count it reads is final). The
/// success that completes the set re-queues a waiting parent for its assembly; a failure or
/// cancellation fails a waiting parent, naming the child, and cancels the siblings.
async fn child_ended(
    conn: &mut SqliteConnection,
    parent: &str,
    child: &str,
    index: i64,
    status: JobStatus,
    error: Option<&str>,
    now_ms: i64,
) -> Result<(), StoreError> {
    if status == JobStatus::Succeeded {
        sqlx::query(
            "UPDATE jobs SET children_succeeded = children_succeeded + 1, \
             progress_fraction = CAST(children_succeeded + 1 AS REAL) / children_total, \
             progress_simulated_s = progress_end_s * (children_succeeded + 1) / children_total, \
             status = CASE WHEN status = 'waiting' AND children_succeeded + 1 >= children_total \
               THEN 'queued' ELSE status END \
             WHERE id = ?1",
        )
        .bind(parent)
        .execute(&mut *conn)
        .await?;
        return Ok(());
    }
    let message = super::child_failure_message(child, index, status, error);
    let row = sqlx::query(
        "UPDATE jobs SET children_failed = children_failed + ?2, \
         children_cancelled = children_cancelled + ?3, \
         error = CASE WHEN status = 'waiting' THEN ?4 ELSE error END, \
         finished_ms = CASE WHEN status = 'waiting' THEN ?5 ELSE finished_ms END, \
         status = CASE WHEN status = 'waiting' THEN 'failed' ELSE status END \
         WHERE id = ?1 RETURNING status",
    )
    .bind(parent)
    .bind(i64::from(status == JobStatus::Failed))
    .bind(i64::from(status == JobStatus::Cancelled))
    .bind(message)
    .bind(now_ms)
    .fetch_optional(&mut *conn)
    .await?;
    if let Some(row) = row {
        let parent_status: String = row.try_get("status")?;
        if parent_status == "failed" || parent_status == "cancelled" {
            cancel_children(conn, parent, now_ms).await?;
        }
    }
    Ok(())
}

/// Cancel the queued children of a terminal parent at once and flag its running ones.
async fn cancel_children(
    conn: &mut SqliteConnection,
    parent: &str,
    now_ms: i64,
) -> Result<(), StoreError> {
    let cancelled = sqlx::query(
        "UPDATE jobs SET status = 'cancelled', cancel_requested = 1, finished_ms = ?2 \
         WHERE parent_id = ?1 AND status = 'queued'",
    )
    .bind(parent)
    .bind(now_ms)
    .execute(&mut *conn)
    .await?
    .rows_affected();
    if cancelled > 0 {
        sqlx::query("UPDATE jobs SET children_cancelled = children_cancelled + ?2 WHERE id = ?1")
            .bind(parent)
            .bind(cancelled as i64)
            .execute(&mut *conn)
            .await?;
    }
    sqlx::query("UPDATE jobs SET cancel_requested = 1 WHERE parent_id = ?1 AND status = 'running'")
        .bind(parent)
        .execute(&mut *conn)
        .await?;
    Ok(())
}

/// Record how attempt `attempt` of job `id` ended.
async fn end_attempt(
    conn: &mut SqliteConnection,
    id: &str,
    attempt: i64,
    outcome: AttemptOutcome,
    now_ms: i64,
) -> Result<(), StoreError> {
    sqlx::query(
        "UPDATE job_attempts SET outcome = ?3, ended_ms = ?4 WHERE job_id = ?1 AND attempt = ?2",
    )
    .bind(id)
    .bind(attempt)
    .bind(outcome.as_str())
    .bind(now_ms)
    .execute(&mut *conn)
    .await?;
    Ok(())
}

impl SqliteStore {
    async fn job_by_id(&self, id: Uuid) -> Result<Option<JobRecord>, StoreError> {
        let sql = format!("SELECT {JOB_COLUMNS} FROM jobs WHERE id = ?1");
        let row = sqlx::query(&sql)
            .bind(id.to_string())
            .fetch_optional(&self.pool)
            .await?;
        row.as_ref().map(job_from_row).transpose()
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

    fn ping(&self) -> StoreFuture<'_, ()> {
        Box::pin(async move {
            sqlx::query("SELECT 1").execute(&self.pool).await?;
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
                    let id: String = row.try_get("id")?;
                    let stored_sha: Option<String> = row.try_get("request_sha256")?;
                    let id = parse_uuid(&id)?;
                    tx.rollback().await?;
                    if stored_sha.as_deref() == Some(sha.as_str()) {
                        let record = self
                            .job_by_id(id)
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
            let sql = format!("SELECT {JOB_COLUMNS} FROM jobs WHERE id = ?1");
            let row = sqlx::query(&sql)
                .bind(job.id.to_string())
                .fetch_one(&mut *tx)
                .await?;
            let record = job_from_row(&row)?;
            tx.commit().await?;
            Ok(Submitted::Created(record))
        })
    }

    fn get_job(&self, id: Uuid) -> StoreFuture<'_, Option<JobRecord>> {
        Box::pin(self.job_by_id(id))
    }

    fn list_jobs(&self, page: PageRequest, filter: JobFilter) -> StoreFuture<'_, Page<JobRecord>> {
        Box::pin(async move {
            let sql = format!(
                "SELECT {JOB_COLUMNS} FROM jobs WHERE (?1 IS NULL OR seq < ?1) \
                 AND (?2 IS NULL OR status = ?2) AND (?4 IS NULL OR parent_id = ?4) \
                 AND (?5 = 0 OR parent_id IS NULL) ORDER BY seq DESC LIMIT ?3"
            );
            let rows = sqlx::query(&sql)
                .bind(page.after_seq)
                .bind(filter.status.map(|s| s.as_str()))
                .bind(page.limit + 1)
                .bind(filter.parent.map(|p| p.to_string()))
                .bind(i64::from(filter.top_level))
                .fetch_all(&self.pool)
                .await?;
            let items = rows
                .iter()
                .map(job_from_row)
                .collect::<Result<Vec<_>, _>>()?;
            Ok(paginate(items, page.limit, |j| j.seq))
        })
    }

    fn claim_job_on(
        &self,
        worker: &str,
        host: Option<&WorkerHost>,
        now_ms: i64,
        lease_ms: i64,
    ) -> StoreFuture<'_, Option<JobRecord>> {
        let worker = worker.to_string();
        let host = host.cloned();
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
            let row = sqlx::query(&sql)
                .bind(&worker)
                .bind(now_ms)
                .bind(lease_ms)
                .bind(host.as_ref().map(|h| h.host.clone()))
                .bind(host.as_ref().map(|h| i64::from(h.pid)))
                .bind(host.as_ref().map(|h| h.instance.clone()))
                .fetch_optional(&mut *tx)
                .await?;
            let Some(job) = row.as_ref().map(job_from_row).transpose()? else {
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

    fn host_leases(&self, host: &str) -> StoreFuture<'_, Vec<HostLease>> {
        let host = host.to_string();
        Box::pin(async move {
            let rows = sqlx::query(
                "SELECT id, attempt, lease_pid, lease_instance FROM jobs \
                 WHERE status = 'running' AND lease_host = ?1 AND lease_pid IS NOT NULL \
                 AND lease_instance IS NOT NULL ORDER BY seq",
            )
            .bind(host)
            .fetch_all(&self.pool)
            .await?;
            rows.iter()
                .map(|row| {
                    let id: String = row.try_get("id")?;
                    let pid: i64 = row.try_get("lease_pid")?;
                    Ok(HostLease {
                        job: parse_uuid(&id)?,
                        attempt: row.try_get("attempt")?,
                        pid: u32::try_from(pid).map_err(|_| corrupt(format!("pid {pid}")))?,
                        instance: row.try_get("lease_instance")?,
                    })
                })
                .collect()
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

    fn release_job(&self, id: Uuid, attempt: i64, now_ms: i64) -> StoreFuture<'_, ReleaseOutcome> {
        Box::pin(async move {
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let row = sqlx::query(
                "SELECT cancel_requested FROM jobs WHERE id = ?1 AND attempt = ?2 \
                 AND status = 'running'",
            )
            .bind(id.to_string())
            .bind(attempt)
            .fetch_optional(&mut *tx)
            .await?;
            let outcome = match row {
                None => ReleaseOutcome::Stale,
                Some(row) if row.try_get::<i64, _>("cancel_requested")? != 0 => {
                    ReleaseOutcome::CancelRequested
                }
                Some(_) => {
                    sqlx::query(
                        "UPDATE jobs SET status = 'queued', lease_owner = NULL, \
                         lease_expires_ms = NULL, progress_eta_s = NULL WHERE id = ?1",
                    )
                    .bind(id.to_string())
                    .execute(&mut *tx)
                    .await?;
                    end_attempt(
                        &mut tx,
                        &id.to_string(),
                        attempt,
                        AttemptOutcome::Released,
                        now_ms,
                    )
                    .await?;
                    ReleaseOutcome::Released
                }
            };
            tx.commit().await?;
            Ok(outcome)
        })
    }

    fn heartbeat(
        &self,
        id: Uuid,
        attempt: i64,
        progress: Option<JobProgress>,
        now_ms: i64,
        lease_ms: i64,
    ) -> StoreFuture<'_, Heartbeat> {
        Box::pin(async move {
            let row = sqlx::query(
                "UPDATE jobs SET lease_expires_ms = ?3 + ?4, \
                 progress_simulated_s = COALESCE(?5, progress_simulated_s), \
                 progress_end_s = COALESCE(?6, progress_end_s), \
                 progress_fraction = COALESCE(?7, progress_fraction), \
                 progress_eta_s = CASE WHEN ?5 IS NULL THEN progress_eta_s ELSE ?8 END \
                 WHERE id = ?1 AND attempt = ?2 AND status = 'running' \
                 RETURNING cancel_requested",
            )
            .bind(id.to_string())
            .bind(attempt)
            .bind(now_ms)
            .bind(lease_ms)
            .bind(progress.map(|p| p.simulated_time_s))
            .bind(progress.map(|p| p.end_time_s))
            .bind(progress.map(|p| p.fraction))
            .bind(progress.and_then(|p| p.eta_s))
            .fetch_optional(&self.pool)
            .await?;
            Ok(match row {
                Some(row) => Heartbeat {
                    owned: true,
                    cancel_requested: row.try_get::<i64, _>("cancel_requested")? != 0,
                },
                None => Heartbeat {
                    owned: false,
                    cancel_requested: false,
                },
            })
        })
    }

    fn finish_job(
        &self,
        id: Uuid,
        attempt: i64,
        finish: Finish,
        now_ms: i64,
    ) -> StoreFuture<'_, bool> {
        Box::pin(async move {
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let (status, result, error, samples) = match &finish {
                Finish::Succeeded {
                    summary, blocks, ..
                } => (
                    JobStatus::Succeeded,
                    Some(summary.to_string()),
                    None,
                    blocks.iter().map(|b| b.samples).sum::<i64>(),
                ),
                Finish::Failed(message) => (JobStatus::Failed, None, Some(message.clone()), 0),
                Finish::Cancelled => (JobStatus::Cancelled, None, None, 0),
            };
            // Fenced: only the current attempt of a running job may end it.
            let updated = sqlx::query(
                "UPDATE jobs SET status = ?3, finished_ms = ?4, result = ?5, error = ?6, \
                 track_samples = ?7, lease_owner = NULL, lease_expires_ms = NULL, \
                 progress_fraction = CASE WHEN ?3 = 'succeeded' THEN 1.0 ELSE progress_fraction END, \
                 progress_simulated_s = CASE WHEN ?3 = 'succeeded' THEN progress_end_s ELSE progress_simulated_s END, \
                 progress_eta_s = CASE WHEN ?3 = 'succeeded' THEN 0.0 ELSE progress_eta_s END \
                 WHERE id = ?1 AND attempt = ?2 AND status = 'running' \
                 RETURNING parent_id, child_index",
            )
            .bind(id.to_string())
            .bind(attempt)
            .bind(status.as_str())
            .bind(now_ms)
            .bind(result)
            .bind(&error)
            .bind(samples)
            .fetch_optional(&mut *tx)
            .await?;
            let Some(updated) = updated else {
                tx.rollback().await?;
                return Ok(false);
            };
            end_attempt(&mut tx, &id.to_string(), attempt, status.into(), now_ms).await?;
            let parent: Option<String> = updated.try_get("parent_id")?;
            if let Some(parent) = parent {
                let index: i64 = updated.try_get("child_index")?;
                child_ended(
                    &mut tx,
                    &parent,
                    &id.to_string(),
                    index,
                    status,
                    error.as_deref(),
                    now_ms,
                )
                .await?;
            }
            if let Finish::Succeeded {
                blocks,
                plots,
                curve,
                ..
            } = finish
            {
                for block in blocks {
                    sqlx::query(
                        "INSERT INTO job_track_blocks (job_id, block, samples, t_start_s, t_end_s, data) \
                         VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
                    )
                    .bind(id.to_string())
                    .bind(block.index)
                    .bind(block.samples)
                    .bind(block.t_start_s)
                    .bind(block.t_end_s)
                    .bind(block.data)
                    .execute(&mut *tx)
                    .await?;
                }
                for (name, svg) in plots {
                    sqlx::query(
                        "INSERT OR REPLACE INTO job_plots (job_id, name, svg) VALUES (?1, ?2, ?3)",
                    )
                    .bind(id.to_string())
                    .bind(name)
                    .bind(svg)
                    .execute(&mut *tx)
                    .await?;
                }
                if let Some(curve) = curve {
                    insert_curve_version(&mut tx, *curve).await?;
                }
            }
            tx.commit().await?;
            Ok(true)
        })
    }

    fn fan_out(
        &self,
        parent: Uuid,
        attempt: i64,
        fan_out: FanOut,
        now_ms: i64,
    ) -> StoreFuture<'_, FanOutResult> {
        Box::pin(async move {
            if fan_out.children.is_empty() {
                return Err(corrupt("a fan-out needs at least one child"));
            }
            let parent_id = parent.to_string();
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let moved = sqlx::query(
                "UPDATE jobs SET status = 'waiting', children_total = ?3, lease_owner = NULL, \
                 lease_expires_ms = NULL, progress_simulated_s = 0.0, progress_end_s = ?4, \
                 progress_fraction = 0.0, progress_eta_s = NULL \
                 WHERE id = ?1 AND attempt = ?2 AND status = 'running' AND cancel_requested = 0",
            )
            .bind(&parent_id)
            .bind(attempt)
            .bind(fan_out.children.len() as i64)
            .bind(fan_out.end_time_s)
            .execute(&mut *tx)
            .await?;
            if moved.rows_affected() != 1 {
                let owned_but_cancelled = sqlx::query(
                    "SELECT 1 FROM jobs WHERE id = ?1 AND attempt = ?2 AND status = 'running' \
                     AND cancel_requested = 1",
                )
                .bind(&parent_id)
                .bind(attempt)
                .fetch_optional(&mut *tx)
                .await?
                .is_some();
                tx.rollback().await?;
                return Ok(if owned_but_cancelled {
                    FanOutResult::CancelRequested
                } else {
                    FanOutResult::Stale
                });
            }
            for (index, child) in fan_out.children.iter().enumerate() {
                // Seed, code version and submitter are the parent's.
                sqlx::query(
                    "INSERT INTO jobs (id, kind, status, params, seed, code_version, submitted_by, \
                     created_ms, parent_id, child_index) \
                     SELECT ?1, ?2, 'queued', ?3, seed, code_version, submitted_by, ?4, id, ?5 \
                     FROM jobs WHERE id = ?6",
                )
                .bind(child.id.to_string())
                .bind(child.kind.as_str())
                .bind(child.params.to_string())
                .bind(now_ms)
                .bind(index as i64)
                .bind(&parent_id)
                .execute(&mut *tx)
                .await?;
            }
            end_attempt(
                &mut tx,
                &parent_id,
                attempt,
                AttemptOutcome::FannedOut,
                now_ms,
            )
            .await?;
            tx.commit().await?;
            Ok(FanOutResult::FannedOut)
        })
    }

    fn children(&self, parent: Uuid) -> StoreFuture<'_, Vec<ChildRecord>> {
        Box::pin(async move {
            let rows = sqlx::query(
                "SELECT id, child_index, status, result, error FROM jobs WHERE parent_id = ?1 \
                 ORDER BY child_index",
            )
            .bind(parent.to_string())
            .fetch_all(&self.pool)
            .await?;
            rows.iter()
                .map(|row| {
                    let id: String = row.try_get("id")?;
                    let status: String = row.try_get("status")?;
                    let result: Option<String> = row.try_get("result")?;
                    Ok(ChildRecord {
                        id: parse_uuid(&id)?,
                        index: row.try_get("child_index")?,
                        status: JobStatus::parse(&status)
                            .ok_or_else(|| corrupt(format!("job status `{status}`")))?,
                        result: result
                            .as_deref()
                            .map(|r| parse_json(r, "child result"))
                            .transpose()?,
                        error: row.try_get("error")?,
                    })
                })
                .collect()
        })
    }

    fn attempts(&self, id: Uuid) -> StoreFuture<'_, Vec<AttemptRecord>> {
        Box::pin(async move {
            let rows = sqlx::query(
                "SELECT attempt, worker, started_ms, ended_ms, outcome, checkpoint_s FROM job_attempts \
                 WHERE job_id = ?1 ORDER BY attempt",
            )
            .bind(id.to_string())
            .fetch_all(&self.pool)
            .await?;
            rows.iter()
                .map(|row| {
                    let outcome: String = row.try_get("outcome")?;
                    Ok(AttemptRecord {
                        attempt: row.try_get("attempt")?,
                        worker: row.try_get("worker")?,
                        started_ms: row.try_get("started_ms")?,
                        ended_ms: row.try_get("ended_ms")?,
                        outcome: AttemptOutcome::parse(&outcome)
                            .ok_or_else(|| corrupt(format!("attempt outcome `{outcome}`")))?,
                        checkpoint_s: row.try_get("checkpoint_s")?,
                    })
                })
                .collect()
        })
    }

    fn request_cancel(&self, id: Uuid, now_ms: i64) -> StoreFuture<'_, Option<JobRecord>> {
        Box::pin(async move {
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let Some(before) = sqlx::query("SELECT status FROM jobs WHERE id = ?1")
                .bind(id.to_string())
                .fetch_optional(&mut *tx)
                .await?
            else {
                tx.rollback().await?;
                return Ok(None);
            };
            let before: String = before.try_get("status")?;
            // SET expressions all see the old row, so `status IN (...)` tests the old status:
            // queued and waiting jobs end at once, a running one is flagged for its worker.
            let sql = format!(
                "UPDATE jobs SET \
                 cancel_requested = CASE WHEN status IN ('queued', 'running', 'waiting') THEN 1 ELSE cancel_requested END, \
                 finished_ms = CASE WHEN status IN ('queued', 'waiting') THEN ?2 ELSE finished_ms END, \
                 status = CASE WHEN status IN ('queued', 'waiting') THEN 'cancelled' ELSE status END \
                 WHERE id = ?1 RETURNING {JOB_COLUMNS}"
            );
            let row = sqlx::query(&sql)
                .bind(id.to_string())
                .bind(now_ms)
                .fetch_one(&mut *tx)
                .await?;
            let mut job = job_from_row(&row)?;
            if before == "queued" || before == "waiting" {
                if before == "waiting" {
                    cancel_children(&mut tx, &id.to_string(), now_ms).await?;
                }
                if let Some(of) = job.parent {
                    child_ended(
                        &mut tx,
                        &of.parent_id.to_string(),
                        &id.to_string(),
                        of.index,
                        JobStatus::Cancelled,
                        None,
                        now_ms,
                    )
                    .await?;
                }
                let sql = format!("SELECT {JOB_COLUMNS} FROM jobs WHERE id = ?1");
                let row = sqlx::query(&sql)
                    .bind(id.to_string())
                    .fetch_one(&mut *tx)
                    .await?;
                job = job_from_row(&row)?;
            }
            tx.commit().await?;
            Ok(Some(job))
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
            let expired = sqlx::query(
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
            for row in &expired {
                let id: String = row.try_get("id")?;
                let attempt: i64 = row.try_get("attempt")?;
                end_attempt(&mut tx, &id, attempt, AttemptOutcome::Lost, now_ms).await?;
                let status: String = row.try_get("status")?;
                let status = JobStatus::parse(&status)
                    .ok_or_else(|| corrupt(format!("job status `{status}`")))?;
                let parent: Option<String> = row.try_get("parent_id")?;
                if let (Some(parent), true) = (parent, status.is_terminal()) {
                    let error: Option<String> = row.try_get("error")?;
                    let index: i64 = row.try_get("child_index")?;
                    child_ended(
                        &mut tx,
                        &parent,
                        &id,
                        index,
                        status,
                        error.as_deref(),
                        now_ms,
                    )
                    .await?;
                }
            }
            tx.commit().await?;
            Ok(expired.len() as u64)
        })
    }

    fn job_counts(&self) -> StoreFuture<'_, Vec<(JobStatus, i64)>> {
        Box::pin(async move {
            let rows = sqlx::query("SELECT status, COUNT(*) AS n FROM jobs GROUP BY status")
                .fetch_all(&self.pool)
                .await?;
            let mut counts: Vec<(JobStatus, i64)> =
                JobStatus::ALL.iter().map(|s| (*s, 0)).collect();
            for row in rows {
                let status: String = row.try_get("status")?;
                let n: i64 = row.try_get("n")?;
                if let Some(slot) = counts.iter_mut().find(|(s, _)| s.as_str() == status) {
                    slot.1 = n;
                }
            }
            Ok(counts)
        })
    }

    fn track_blocks(&self, id: Uuid) -> StoreFuture<'_, Vec<TrackBlock>> {
        Box::pin(async move {
            let rows = sqlx::query(
                "SELECT block, samples, t_start_s, t_end_s, data FROM job_track_blocks \
                 WHERE job_id = ?1 ORDER BY block",
            )
            .bind(id.to_string())
            .fetch_all(&self.pool)
            .await?;
            rows.iter()
                .map(|row| {
                    Ok(TrackBlock {
                        index: row.try_get("block")?,
                        samples: row.try_get("samples")?,
                        t_start_s: row.try_get("t_start_s")?,
                        t_end_s: row.try_get("t_end_s")?,
                        data: row.try_get("data")?,
                    })
                })
                .collect()
        })
    }

    fn plot_names(&self, id: Uuid) -> StoreFuture<'_, Vec<String>> {
        Box::pin(async move {
            let rows = sqlx::query("SELECT name FROM job_plots WHERE job_id = ?1 ORDER BY name")
                .bind(id.to_string())
                .fetch_all(&self.pool)
                .await?;
            rows.iter()
                .map(|r| r.try_get("name").map_err(StoreError::from))
                .collect()
        })
    }

    fn plot(&self, id: Uuid, name: &str) -> StoreFuture<'_, Option<String>> {
        let name = name.to_string();
        Box::pin(async move {
            let row = sqlx::query("SELECT svg FROM job_plots WHERE job_id = ?1 AND name = ?2")
                .bind(id.to_string())
                .bind(name)
                .fetch_optional(&self.pool)
                .await?;
            row.map(|r| r.try_get("svg").map_err(StoreError::from))
                .transpose()
        })
    }

    fn active_sweep(&self, curve_key: &str) -> StoreFuture<'_, Option<JobRecord>> {
        let curve_key = curve_key.to_string();
        Box::pin(async move {
            let sql = format!(
                "SELECT {JOB_COLUMNS} FROM jobs WHERE curve_key = ?1 AND kind = 'sweep' \
                 AND status IN ('queued', 'running', 'waiting') ORDER BY seq DESC LIMIT 1"
            );
            let row = sqlx::query(&sql)
                .bind(curve_key)
                .fetch_optional(&self.pool)
                .await?;
            row.as_ref().map(job_from_row).transpose()
        })
    }

    fn add_measurement(&self, m: NewMeasurement) -> StoreFuture<'_, MeasurementRecord> {
        Box::pin(async move {
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            sqlx::query(
                "INSERT INTO rails (serial, created_ms) VALUES (?1, ?2) ON CONFLICT (serial) DO NOTHING",
            )
            .bind(&m.serial)
            .bind(m.recorded_ms)
            .execute(&mut *tx)
            .await?;
            let row = sqlx::query(
                "INSERT INTO rail_measurements (id, serial, dimensions_mm, measured_by, measured_at, \
                 location, rattle_space, recorded_by, recorded_ms, measured_ms) \
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10) RETURNING *",
            )
            .bind(m.id.to_string())
            .bind(&m.serial)
            .bind(m.dimensions_mm.to_string())
            .bind(&m.measured_by)
            .bind(&m.measured_at)
            .bind(&m.location)
            .bind(m.rattle_space)
            .bind(&m.recorded_by)
            .bind(m.recorded_ms)
            .bind(m.measured_ms)
            .fetch_one(&mut *tx)
            .await?;
            let record = measurement_from_row(&row)?;
            tx.commit().await?;
            Ok(record)
        })
    }

    fn get_rail(&self, serial: &str) -> StoreFuture<'_, Option<RailRecord>> {
        let serial = serial.to_string();
        Box::pin(async move {
            let row = sqlx::query(
                "SELECT r.serial, r.seq, r.created_ms, \
                 (SELECT COUNT(*) FROM rail_measurements m WHERE m.serial = r.serial) AS measurements \
                 FROM rails r WHERE r.serial = ?1",
            )
            .bind(serial)
            .fetch_optional(&self.pool)
            .await?;
            row.as_ref().map(rail_from_row).transpose()
        })
    }

    fn list_rails(&self, page: PageRequest) -> StoreFuture<'_, Page<RailRecord>> {
        Box::pin(async move {
            let rows = sqlx::query(
                "SELECT r.serial, r.seq, r.created_ms, \
                 (SELECT COUNT(*) FROM rail_measurements m WHERE m.serial = r.serial) AS measurements \
                 FROM rails r WHERE (?1 IS NULL OR r.seq < ?1) ORDER BY r.seq DESC LIMIT ?2",
            )
            .bind(page.after_seq)
            .bind(page.limit + 1)
            .fetch_all(&self.pool)
            .await?;
            let items = rows
                .iter()
                .map(rail_from_row)
                .collect::<Result<Vec<_>, _>>()?;
            Ok(paginate(items, page.limit, |r| r.seq))
        })
    }

    fn measurements(
        &self,
        serial: &str,
        page: PageRequest,
    ) -> StoreFuture<'_, Page<MeasurementRecord>> {
        let serial = serial.to_string();
        Box::pin(async move {
            let rows = sqlx::query(
                "SELECT * FROM rail_measurements WHERE serial = ?1 AND (?2 IS NULL OR seq < ?2) \
                 ORDER BY seq DESC LIMIT ?3",
            )
            .bind(serial)
            .bind(page.after_seq)
            .bind(page.limit + 1)
            .fetch_all(&self.pool)
            .await?;
            let items = rows
                .iter()
                .map(measurement_from_row)
                .collect::<Result<Vec<_>, _>>()?;
            Ok(paginate(items, page.limit, |m| m.seq))
        })
    }

    fn latest_measurement(&self, serial: &str) -> StoreFuture<'_, Option<MeasurementRecord>> {
        let serial = serial.to_string();
        Box::pin(async move {
            let row = sqlx::query(
                "SELECT * FROM rail_measurements WHERE serial = ?1 \
                 ORDER BY measured_ms DESC, seq DESC LIMIT 1",
            )
            .bind(serial)
            .fetch_optional(&self.pool)
            .await?;
            row.as_ref().map(measurement_from_row).transpose()
        })
    }

    fn get_curve(&self, id: i64) -> StoreFuture<'_, Option<CurveRecord>> {
        Box::pin(async move {
            let row = sqlx::query(&format!("{CURVE_SELECT} WHERE v.id = ?1"))
                .bind(id)
                .fetch_optional(&self.pool)
                .await?;
            row.as_ref().map(curve_from_row).transpose()
        })
    }

    fn published_curve(&self, key: &str) -> StoreFuture<'_, Option<CurveRecord>> {
        let key = key.to_string();
        Box::pin(async move {
            let row = sqlx::query(&format!(
                "{CURVE_SELECT} WHERE p.curve_key = ?1 AND p.curve_id = v.id"
            ))
            .bind(key)
            .fetch_optional(&self.pool)
            .await?;
            row.as_ref().map(curve_from_row).transpose()
        })
    }

    fn list_curves(
        &self,
        page: PageRequest,
        filter: CurveFilter,
    ) -> StoreFuture<'_, Page<CurveRecord>> {
        Box::pin(async move {
            let rows = sqlx::query(&format!(
                "{CURVE_SELECT} WHERE (?1 IS NULL OR v.curve_key = ?1) \
                 AND (?2 IS NULL OR v.id < ?2) ORDER BY v.id DESC LIMIT ?3"
            ))
            .bind(filter.key)
            .bind(page.after_seq)
            .bind(page.limit + 1)
            .fetch_all(&self.pool)
            .await?;
            let items = rows
                .iter()
                .map(curve_from_row)
                .collect::<Result<Vec<_>, _>>()?;
            Ok(paginate(items, page.limit, |c| c.id))
        })
    }

    fn publish_curve(
        &self,
        id: i64,
        published_by: &str,
        force: bool,
        now_ms: i64,
    ) -> StoreFuture<'_, PublishOutcome> {
        let published_by = published_by.to_string();
        Box::pin(async move {
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            let Some(candidate) = sqlx::query(&format!("{CURVE_SELECT} WHERE v.id = ?1"))
                .bind(id)
                .fetch_optional(&mut *tx)
                .await?
                .as_ref()
                .map(curve_from_row)
                .transpose()?
            else {
                tx.rollback().await?;
                return Ok(PublishOutcome::NotFound);
            };
            let current = sqlx::query(&format!(
                "{CURVE_SELECT} WHERE p.curve_key = ?1 AND p.curve_id = v.id"
            ))
            .bind(&candidate.key)
            .fetch_optional(&mut *tx)
            .await?
            .as_ref()
            .map(curve_from_row)
            .transpose()?;
            if let Some(refused) = publish_refusal(&candidate, current.as_ref(), force) {
                tx.rollback().await?;
                return Ok(refused);
            }
            if current.as_ref().map(|c| c.id) != Some(candidate.id) {
                sqlx::query(
                    "INSERT INTO published_curves (curve_key, curve_id, published_by, published_ms) \
                     VALUES (?1, ?2, ?3, ?4) ON CONFLICT (curve_key) DO UPDATE SET \
                     curve_id = excluded.curve_id, published_by = excluded.published_by, \
                     published_ms = excluded.published_ms",
                )
                .bind(&candidate.key)
                .bind(candidate.id)
                .bind(&published_by)
                .bind(now_ms)
                .execute(&mut *tx)
                .await?;
            }
            let record = sqlx::query(&format!("{CURVE_SELECT} WHERE v.id = ?1"))
                .bind(id)
                .fetch_one(&mut *tx)
                .await?;
            let record = curve_from_row(&record)?;
            tx.commit().await?;
            Ok(PublishOutcome::Published(record))
        })
    }

    fn insert_campaign(&self, c: NewCampaign) -> StoreFuture<'_, CampaignInsert> {
        Box::pin(async move {
            let inserted = sqlx::query(&format!(
                "INSERT INTO campaigns (id, name, created_by, created_ms, content, \
                 content_sha256, content_bytes, tests, specimens, increments, \
                 accelerometer_records) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11) \
                 ON CONFLICT (content_sha256) DO NOTHING RETURNING {CAMPAIGN_SUMMARY}"
            ))
            .bind(c.id.to_string())
            .bind(&c.name)
            .bind(&c.created_by)
            .bind(c.created_ms)
            .bind(&c.content)
            .bind(&c.content_sha256)
            .bind(c.content.len() as i64)
            .bind(c.counts.tests)
            .bind(c.counts.specimens)
            .bind(c.counts.increments)
            .bind(c.counts.accelerometer_records)
            .fetch_optional(&self.pool)
            .await?;
            if let Some(row) = inserted {
                return Ok(CampaignInsert::Created(campaign_from_row(&row)?));
            }
            let row = sqlx::query(&format!(
                "SELECT {CAMPAIGN_SUMMARY} FROM campaigns WHERE content_sha256 = ?1"
            ))
            .bind(&c.content_sha256)
            .fetch_one(&self.pool)
            .await?;
            Ok(CampaignInsert::Existing(campaign_from_row(&row)?))
        })
    }

    fn get_campaign(&self, id: Uuid) -> StoreFuture<'_, Option<CampaignRecord>> {
        Box::pin(async move {
            let row = sqlx::query(&format!(
                "SELECT {CAMPAIGN_SUMMARY}, content FROM campaigns WHERE id = ?1"
            ))
            .bind(id.to_string())
            .fetch_optional(&self.pool)
            .await?;
            row.map(|row| {
                Ok(CampaignRecord {
                    summary: campaign_from_row(&row)?,
                    content: row.try_get("content")?,
                })
            })
            .transpose()
        })
    }

    fn list_campaigns(&self, page: PageRequest) -> StoreFuture<'_, Page<CampaignSummary>> {
        Box::pin(async move {
            let rows = sqlx::query(&format!(
                "SELECT {CAMPAIGN_SUMMARY} FROM campaigns WHERE (?1 IS NULL OR seq < ?1) \
                 ORDER BY seq DESC LIMIT ?2"
            ))
            .bind(page.after_seq)
            .bind(page.limit + 1)
            .fetch_all(&self.pool)
            .await?;
            let items = rows
                .iter()
                .map(campaign_from_row)
                .collect::<Result<Vec<_>, _>>()?;
            Ok(paginate(items, page.limit, |c| c.seq))
        })
    }

    fn create_token(
        &self,
        name: &str,
        role: Role,
        token_sha256: &str,
        now_ms: i64,
    ) -> StoreFuture<'_, TokenRecord> {
        let (name, sha) = (name.to_string(), token_sha256.to_string());
        Box::pin(async move {
            let row = sqlx::query(
                "INSERT INTO api_tokens (id, name, role, token_sha256, created_ms) \
                 VALUES (?1, ?2, ?3, ?4, ?5) RETURNING *",
            )
            .bind(Uuid::new_v4().to_string())
            .bind(name)
            .bind(role.as_str())
            .bind(sha)
            .bind(now_ms)
            .fetch_one(&self.pool)
            .await?;
            token_from_row(&row)
        })
    }

    fn find_token(&self, token_sha256: &str) -> StoreFuture<'_, Option<TokenRecord>> {
        let sha = token_sha256.to_string();
        Box::pin(async move {
            let row = sqlx::query(
                "SELECT * FROM api_tokens WHERE token_sha256 = ?1 AND revoked_ms IS NULL",
            )
            .bind(sha)
            .fetch_optional(&self.pool)
            .await?;
            row.as_ref().map(token_from_row).transpose()
        })
    }

    fn list_tokens(&self) -> StoreFuture<'_, Vec<TokenRecord>> {
        Box::pin(async move {
            let rows = sqlx::query("SELECT * FROM api_tokens ORDER BY created_ms, id")
                .fetch_all(&self.pool)
                .await?;
            rows.iter().map(token_from_row).collect()
        })
    }

    fn revoke_token(&self, id: Uuid, now_ms: i64) -> StoreFuture<'_, bool> {
        Box::pin(async move {
            let done = sqlx::query(
                "UPDATE api_tokens SET revoked_ms = ?2 WHERE id = ?1 AND revoked_ms IS NULL",
            )
            .bind(id.to_string())
            .bind(now_ms)
            .execute(&self.pool)
            .await?;
            Ok(done.rows_affected() == 1)
        })
    }

    fn save_checkpoint(
        &self,
        id: Uuid,
        attempt: i64,
        checkpoint: NewCheckpoint,
        now_ms: i64,
    ) -> StoreFuture<'_, bool> {
        Box::pin(async move {
            let mut tx = self.pool.begin_with(BEGIN_WRITE).await?;
            // Fenced by the attempt: only the lease holder writes; progress moves to the
            // checkpoint's time.
            let owned = sqlx::query(
                "UPDATE jobs SET progress_simulated_s = ?3, progress_end_s = ?4, \
                 progress_fraction = CASE WHEN ?4 > 0 THEN ?3 / ?4 ELSE progress_fraction END \
                 WHERE id = ?1 AND attempt = ?2 AND status = 'running'",
            )
            .bind(id.to_string())
            .bind(attempt)
            .bind(checkpoint.simulated_s)
            .bind(checkpoint.end_s)
            .execute(&mut *tx)
            .await?
            .rows_affected()
                == 1;
            if !owned {
                return Ok(false);
            }
            sqlx::query(
                "INSERT INTO job_checkpoints (job_id, attempt, simulated_s, end_s, created_ms, data) \
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6) \
                 ON CONFLICT (job_id) DO UPDATE SET attempt = excluded.attempt, \
                 simulated_s = excluded.simulated_s, end_s = excluded.end_s, \
                 created_ms = excluded.created_ms, data = excluded.data",
            )
            .bind(id.to_string())
            .bind(attempt)
            .bind(checkpoint.simulated_s)
            .bind(checkpoint.end_s)
            .bind(now_ms)
            .bind(checkpoint.data)
            .execute(&mut *tx)
            .await?;
            sqlx::query(
                "UPDATE job_attempts SET checkpoint_s = ?3 WHERE job_id = ?1 AND attempt = ?2",
            )
            .bind(id.to_string())
            .bind(attempt)
            .bind(checkpoint.simulated_s)
            .execute(&mut *tx)
            .await?;
            tx.commit().await?;
            Ok(true)
        })
    }

    fn load_checkpoint(&self, id: Uuid) -> StoreFuture<'_, Option<JobCheckpoint>> {
        Box::pin(async move {
            let row = sqlx::query(
                "SELECT attempt, simulated_s, end_s, created_ms, data FROM job_checkpoints \
                 WHERE job_id = ?1",
            )
            .bind(id.to_string())
            .fetch_optional(&self.pool)
            .await?;
            row.map(|row| {
                Ok(JobCheckpoint {
                    attempt: row.try_get("attempt")?,
                    simulated_s: row.try_get("simulated_s")?,
                    end_s: row.try_get("end_s")?,
                    created_ms: row.try_get("created_ms")?,
                    data: row.try_get("data")?,
                })
            })
            .transpose()
        })
    }
}
