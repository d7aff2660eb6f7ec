//! The [`Store`](super::Store) operations that read the same on both engines, written once and
//! generic over the sqlx [`Database`](sqlx::Database): one statement text (`$N` placeholders,
//! `TRUE`, `ON CONFLICT`, `RETURNING`: all accepted by SQLite and PostgreSQL), the dialect's
//! statements and locks from [`Dialect`], rows read through [`super::rows`]. `sqlite.rs` and
//! `postgres.rs` call these from their `Store` impls and keep what really differs: connecting,
//! migrations, which queued row a claim takes and how it is locked, and which expired leases
//! a sweep takes and how (the statements they run on those rows are here: [`Portable::claim`],
//! [`Portable::expire_lease`], [`Portable::lose_leases`]).
//!
//! A generic `QueryResult` has no `rows_affected`, so statements that must say whether they
//! wrote return a column (`RETURNING seq`).
//!
//! Over 700 lines on purpose: the operations share one `impl` block so that its bound list
//! (what `DB` must encode, decode and execute) is written once; split, it would stand twice.

use super::bookkeeping::{Bookkeeping, FinishColumns};
use super::dialect::Dialect;
use super::job_records::{JobProgress, JobRecord, JobStatus};
use super::rows::{
    child_of, corrupt, cut_page, records, AttemptRow, CampaignContentRow, CampaignRow, ChildRow,
    CurveRow, DbUuid, HostLeaseRow, JobRow, KeyedJobRow, LostRow, MeasurementRow, ParentLinkRow,
    PlanRow, RecordChunkRow, TokenRow, CAMPAIGN_SUMMARY, CURVE_SELECT, JOB_COLUMNS,
};
use super::Role;
use super::{
    publish_refusal, AttemptOutcome, AttemptRecord, CampaignInsert, CampaignRecord,
    CampaignSummary, ChildRecord, CurveFilter, CurveRecord, FanOut, FanOutResult, Finish,
    Heartbeat, HostLease, JobCheckpoint, JobFilter, MeasurementRecord, NewCampaign, NewCheckpoint,
    NewJob, NewMeasurement, Page, PageRequest, PublishOutcome, RailRecord, ReleaseOutcome,
    StoreError, Submitted, TokenRecord, TrackBlock, WorkerHost,
};
use sqlx::query::QueryAs;
use sqlx::Type;
use sqlx::{ColumnIndex, Decode, Encode, Executor, FromRow, IntoArguments, Pool, Transaction};
use std::marker::PhantomData;
use uuid::Uuid;

/// The shared operations on engine `DB` (`Portable::<Sqlite>::get_job(&pool, id)`).
pub(crate) struct Portable<DB>(PhantomData<DB>);

impl<DB> Portable<DB>
where
    DB: Dialect,
    JobRow: for<'r> FromRow<'r, DB::Row>,
    KeyedJobRow: for<'r> FromRow<'r, DB::Row>,
    LostRow: for<'r> FromRow<'r, DB::Row>,
    ParentLinkRow: for<'r> FromRow<'r, DB::Row>,
    ChildRow: for<'r> FromRow<'r, DB::Row>,
    AttemptRow: for<'r> FromRow<'r, DB::Row>,
    HostLeaseRow: for<'r> FromRow<'r, DB::Row>,
    CurveRow: for<'r> FromRow<'r, DB::Row>,
    MeasurementRow: for<'r> FromRow<'r, DB::Row>,
    RailRecord: for<'r> FromRow<'r, DB::Row>,
    TrackBlock: for<'r> FromRow<'r, DB::Row>,
    TokenRow: for<'r> FromRow<'r, DB::Row>,
    CampaignRow: for<'r> FromRow<'r, DB::Row>,
    CampaignContentRow: for<'r> FromRow<'r, DB::Row>,
    JobCheckpoint: for<'r> FromRow<'r, DB::Row>,
    PlanRow: for<'r> FromRow<'r, DB::Row>,
    RecordChunkRow: for<'r> FromRow<'r, DB::Row>,
    for<'c> &'c mut DB::Connection: Executor<'c, Database = DB>,
    for<'q> DB::Arguments<'q>: IntoArguments<'q, DB>,
    for<'q> bool: Encode<'q, DB> + Decode<'q, DB> + Type<DB>,
    for<'q> i64: Encode<'q, DB> + Decode<'q, DB> + Type<DB>,
    for<'q> DbUuid: Encode<'q, DB> + Type<DB>,
    for<'q> f64: Encode<'q, DB> + Type<DB>,
    for<'q> String: Encode<'q, DB> + Decode<'q, DB> + Type<DB>,
    for<'q> Vec<u8>: Encode<'q, DB> + Type<DB>,
    for<'q> Option<i64>: Encode<'q, DB> + Type<DB>,
    for<'q> Option<f64>: Encode<'q, DB> + Type<DB>,
    for<'q> Option<String>: Encode<'q, DB> + Type<DB>,
    for<'q> Option<DbUuid>: Encode<'q, DB> + Type<DB>,
    usize: ColumnIndex<DB::Row>,
{
    /// Begin a transaction that writes, as the dialect does.
    pub(crate) async fn begin_write(
        pool: &Pool<DB>,
    ) -> Result<Transaction<'static, DB>, StoreError> {
        Ok(match DB::BEGIN_WRITE {
            Some(begin) => pool.begin_with(begin).await?,
            None => pool.begin().await?,
        })
    }

    /// Lock the parent of job `id` where the dialect does (see [`Dialect::LOCK_PARENT`]).
    pub(crate) async fn lock_parent_of(
        conn: &mut DB::Connection,
        id: Uuid,
    ) -> Result<(), StoreError> {
        if let Some(lock) = DB::LOCK_PARENT {
            sqlx::query(lock)
                .bind(DbUuid(id))
                .execute(&mut *conn)
                .await?;
        }
        Ok(())
    }

    /// One page of `query`, newest first: its filters are bound, the cursor (`after_seq`) and
    /// `limit + 1` are bound here as its last two parameters; `cursor` names an item's place
    /// in the order (its sequence number or id), what the next page starts after.
    async fn fetch_page<'q, R, T>(
        pool: &Pool<DB>,
        query: QueryAs<'q, DB, R, DB::Arguments<'q>>,
        page: PageRequest,
        cursor: impl Fn(&T) -> i64,
    ) -> Result<Page<T>, StoreError>
    where
        R: for<'r> FromRow<'r, DB::Row> + Send + Unpin,
        T: TryFrom<R>,
        StoreError: From<T::Error>,
    {
        let rows = query
            .bind(page.after_seq)
            .bind(page.limit + 1)
            .fetch_all(pool)
            .await?;
        Ok(cut_page(records(rows)?, page.limit, cursor))
    }

    pub(crate) async fn ping(pool: &Pool<DB>) -> Result<(), StoreError> {
        sqlx::query("SELECT 1").execute(pool).await?;
        Ok(())
    }

    /// Job `id` read on `conn` (inside a transaction, or a pooled connection).
    pub(crate) async fn job_in(
        conn: &mut DB::Connection,
        id: Uuid,
    ) -> Result<Option<JobRecord>, StoreError> {
        let sql = format!("SELECT {JOB_COLUMNS} FROM jobs WHERE id = $1");
        let row: Option<JobRow> = sqlx::query_as(&sql)
            .bind(DbUuid(id))
            .fetch_optional(&mut *conn)
            .await?;
        row.map(JobRecord::try_from).transpose()
    }

    /// Queue `job`, or, when its Idempotency-Key was seen before, the earlier job: a replay
    /// when the body hash matches, a conflict otherwise. The key is looked up first, so a
    /// replay does not consume a `seq` (both engines list jobs in the same order); `ON
    /// CONFLICT DO NOTHING` makes a concurrent insert of the same key (PostgreSQL; SQLite's
    /// `BEGIN IMMEDIATE` has one writer) a replay, never a unique-key error.
    pub(crate) async fn submit_job(pool: &Pool<DB>, job: NewJob) -> Result<Submitted, StoreError> {
        let (key, sha) = match job.idempotency {
            Some((k, s)) => (Some(k), Some(s)),
            None => (None, None),
        };
        let mut tx = Self::begin_write(pool).await?;
        if let Some(found) = Self::keyed_job(&mut tx, key.as_deref(), sha.as_deref()).await? {
            tx.commit().await?;
            return Ok(found);
        }
        let sql = format!(
            "INSERT INTO jobs (id, kind, status, params, seed, code_version, submitted_by, \
             idempotency_key, request_sha256, curve_key, created_ms, plan) \
             VALUES ($1, $2, 'queued', $3, $4, $5, $6, $7, $8, $9, $10, $11) \
             ON CONFLICT (idempotency_key) DO NOTHING RETURNING {JOB_COLUMNS}"
        );
        let inserted: Option<JobRow> = sqlx::query_as(&sql)
            .bind(DbUuid(job.id))
            .bind(job.kind.as_str().to_string())
            .bind(job.params.to_string())
            .bind(job.seed as i64)
            .bind(job.code_version)
            .bind(job.submitted_by)
            .bind(key.clone())
            .bind(sha.clone())
            .bind(job.curve_key)
            .bind(job.created_ms)
            .bind(job.plan.as_ref().map(|plan| plan.to_string()))
            .fetch_optional(&mut *tx)
            .await?;
        let submitted = match inserted {
            Some(row) => Submitted::Created(row.try_into()?),
            // Lost the race to a concurrent submission with the same key.
            None => Self::keyed_job(&mut tx, key.as_deref(), sha.as_deref())
                .await?
                .ok_or_else(|| corrupt("idempotent job vanished"))?,
        };
        tx.commit().await?;
        Ok(submitted)
    }

    /// The job submitted earlier with Idempotency-Key `key`: a replay when its body hash is
    /// `sha`, a conflict otherwise. `None` without a key or when no job has it.
    async fn keyed_job(
        conn: &mut DB::Connection,
        key: Option<&str>,
        sha: Option<&str>,
    ) -> Result<Option<Submitted>, StoreError> {
        let Some(key) = key else {
            return Ok(None);
        };
        let sql =
            format!("SELECT {JOB_COLUMNS}, request_sha256 FROM jobs WHERE idempotency_key = $1");
        let row: Option<KeyedJobRow> = sqlx::query_as(&sql)
            .bind(key.to_string())
            .fetch_optional(&mut *conn)
            .await?;
        let Some(KeyedJobRow {
            job,
            request_sha256: stored_sha,
        }) = row
        else {
            return Ok(None);
        };
        let record = JobRecord::try_from(job)?;
        Ok(Some(
            if stored_sha.is_some() && stored_sha.as_deref() == sha {
                Submitted::Replayed(record)
            } else {
                Submitted::KeyConflict(record.id)
            },
        ))
    }

    /// Hand a queued job to `worker` for `lease_ms` from `now_ms` and log the attempt, inside
    /// the caller's transaction. `picked` is the `seq` of the queued row the caller chose and
    /// locked (PostgreSQL); `None` takes the oldest queued row in the same statement (SQLite:
    /// under its one write lock two workers can never take the same job). A parent queued for
    /// its assembly keeps the progress of its children. `None` when no row was taken.
    pub(crate) async fn claim(
        conn: &mut DB::Connection,
        picked: Option<i64>,
        worker: &str,
        host: Option<&WorkerHost>,
        now_ms: i64,
        lease_ms: i64,
    ) -> Result<Option<JobRecord>, StoreError> {
        let row = if picked.is_some() {
            "$7"
        } else {
            "(SELECT seq FROM jobs WHERE status = 'queued' ORDER BY seq LIMIT 1)"
        };
        let sql = format!(
            "UPDATE jobs SET status = 'running', attempt = attempt + 1, lease_owner = $1, \
             lease_expires_ms = $2 + $3, started_ms = COALESCE(started_ms, $2), \
             attempt_started_ms = $2, lease_host = $4, lease_pid = $5, lease_instance = $6, \
             progress_simulated_s = CASE WHEN children_total > 0 THEN progress_simulated_s END, \
             progress_end_s = CASE WHEN children_total > 0 THEN progress_end_s END, \
             progress_fraction = CASE WHEN children_total > 0 THEN progress_fraction END, \
             progress_eta_s = NULL \
             WHERE seq = {row} AND status = 'queued' RETURNING {JOB_COLUMNS}"
        );
        let mut query = sqlx::query_as::<_, JobRow>(&sql)
            .bind(worker.to_string())
            .bind(now_ms)
            .bind(lease_ms)
            .bind(host.map(|h| h.host.clone()))
            .bind(host.map(|h| i64::from(h.pid)))
            .bind(host.map(|h| h.instance.clone()));
        if let Some(seq) = picked {
            query = query.bind(seq);
        }
        let Some(job) = query
            .fetch_optional(&mut *conn)
            .await?
            .map(JobRecord::try_from)
            .transpose()?
        else {
            return Ok(None);
        };
        Bookkeeping::<DB>::start_attempt(conn, job.id, job.attempt, worker, now_ms).await?;
        Ok(Some(job))
    }

    /// Expire the lease of attempt `attempt` of running job `id` at `now_ms` (the next sweep
    /// re-queues it); whether it was that attempt's.
    pub(crate) async fn expire_lease(
        conn: &mut DB::Connection,
        id: Uuid,
        attempt: i64,
        now_ms: i64,
    ) -> Result<bool, StoreError> {
        let row = sqlx::query(
            "UPDATE jobs SET lease_expires_ms = $3 - 1 \
             WHERE id = $1 AND attempt = $2 AND status = 'running' RETURNING seq",
        )
        .bind(DbUuid(id))
        .bind(attempt)
        .bind(now_ms)
        .fetch_optional(&mut *conn)
        .await?;
        Ok(row.is_some())
    }

    /// End the attempts whose lease expired before `now_ms` (only job `only`'s, which the
    /// caller found expired and locked, when given): a job that asked to be cancelled is
    /// cancelled, one at `max_attempts` fails, the others are queued again; then the attempt
    /// log and the parents' bookkeeping ([`Bookkeeping::lost`]). How many jobs it ended.
    pub(crate) async fn lose_leases(
        conn: &mut DB::Connection,
        only: Option<Uuid>,
        now_ms: i64,
        max_attempts: i64,
    ) -> Result<u64, StoreError> {
        let rows = if only.is_some() {
            "id = $3"
        } else {
            "status = 'running' AND lease_expires_ms < $1"
        };
        let sql = format!(
            "UPDATE jobs SET \
             error = CASE WHEN cancel_requested = TRUE THEN error \
               ELSE 'attempt ' || attempt || ' lost its worker (lease expired)' END, \
             finished_ms = CASE WHEN cancel_requested = TRUE OR attempt >= $2 THEN $1 \
               ELSE NULL END, \
             status = CASE WHEN cancel_requested = TRUE THEN 'cancelled' \
               WHEN attempt >= $2 THEN 'failed' ELSE 'queued' END, \
             lease_owner = NULL, lease_expires_ms = NULL \
             WHERE {rows} RETURNING id, attempt, status, error, parent_id, child_index"
        );
        let mut query = sqlx::query_as::<_, LostRow>(&sql)
            .bind(now_ms)
            .bind(max_attempts);
        if let Some(id) = only {
            query = query.bind(DbUuid(id));
        }
        let lost = query.fetch_all(&mut *conn).await?;
        let changed = lost.len() as u64;
        for row in lost {
            Bookkeeping::<DB>::lost(conn, row.try_into()?, now_ms).await?;
        }
        Ok(changed)
    }

    pub(crate) async fn list_jobs(
        pool: &Pool<DB>,
        page: PageRequest,
        filter: JobFilter,
    ) -> Result<Page<JobRecord>, StoreError> {
        let sql = format!("SELECT {JOB_COLUMNS} FROM jobs {}", DB::JOBS_PAGE);
        let query = sqlx::query_as::<_, JobRow>(&sql)
            .bind(filter.status.map(|s| s.as_str().to_string()))
            .bind(filter.parent.map(DbUuid))
            .bind(filter.top_level);
        Self::fetch_page(pool, query, page, |j: &JobRecord| j.seq).await
    }

    pub(crate) async fn host_leases(
        pool: &Pool<DB>,
        host: String,
    ) -> Result<Vec<HostLease>, StoreError> {
        let rows: Vec<HostLeaseRow> = sqlx::query_as(
            "SELECT id, attempt, lease_pid, lease_instance FROM jobs \
             WHERE status = 'running' AND lease_host = $1 AND lease_pid IS NOT NULL \
             AND lease_instance IS NOT NULL ORDER BY seq",
        )
        .bind(host)
        .fetch_all(pool)
        .await?;
        records(rows)
    }

    /// Only the job's own row (and its attempt) is written: no parent lock needed.
    pub(crate) async fn release_job(
        pool: &Pool<DB>,
        id: Uuid,
        attempt: i64,
        now_ms: i64,
    ) -> Result<ReleaseOutcome, StoreError> {
        let mut tx = Self::begin_write(pool).await?;
        let sql = format!(
            "SELECT cancel_requested FROM jobs WHERE id = $1 AND attempt = $2 \
             AND status = 'running'{}",
            DB::FOR_UPDATE
        );
        let row: Option<(bool,)> = sqlx::query_as(&sql)
            .bind(DbUuid(id))
            .bind(attempt)
            .fetch_optional(&mut *tx)
            .await?;
        let outcome = match row {
            None => ReleaseOutcome::Stale,
            Some((true,)) => ReleaseOutcome::CancelRequested,
            Some((false,)) => {
                sqlx::query(
                    "UPDATE jobs SET status = 'queued', lease_owner = NULL, \
                     lease_expires_ms = NULL, progress_eta_s = NULL WHERE id = $1",
                )
                .bind(DbUuid(id))
                .execute(&mut *tx)
                .await?;
                let released = AttemptOutcome::Released;
                Bookkeeping::<DB>::end_attempt(&mut tx, id, attempt, released, now_ms).await?;
                ReleaseOutcome::Released
            }
        };
        tx.commit().await?;
        Ok(outcome)
    }

    pub(crate) async fn heartbeat(
        pool: &Pool<DB>,
        id: Uuid,
        attempt: i64,
        progress: Option<JobProgress>,
        now_ms: i64,
        lease_ms: i64,
    ) -> Result<Heartbeat, StoreError> {
        let row: Option<(bool,)> = sqlx::query_as(DB::HEARTBEAT)
            .bind(DbUuid(id))
            .bind(attempt)
            .bind(now_ms)
            .bind(lease_ms)
            .bind(progress.map(|p| p.simulated_time_s))
            .bind(progress.map(|p| p.end_time_s))
            .bind(progress.map(|p| p.fraction))
            .bind(progress.and_then(|p| p.eta_s))
            .fetch_optional(pool)
            .await?;
        Ok(Heartbeat {
            owned: row.is_some(),
            cancel_requested: row.is_some_and(|(cancel,)| cancel),
        })
    }

    pub(crate) async fn finish_job(
        pool: &Pool<DB>,
        id: Uuid,
        attempt: i64,
        finish: Finish,
        now_ms: i64,
    ) -> Result<bool, StoreError> {
        let columns = FinishColumns::of(&finish);
        let mut tx = Self::begin_write(pool).await?;
        // A child locks its parent first: the parent's bookkeeping is then serialized across
        // the children finishing at once.
        Self::lock_parent_of(&mut tx, id).await?;
        // Fenced: only the current attempt of a running job may end it.
        let updated: Option<ParentLinkRow> = sqlx::query_as(
            "UPDATE jobs SET status = $3, finished_ms = $4, result = $5, error = $6, \
             track_samples = $7, lease_owner = NULL, lease_expires_ms = NULL, \
             progress_fraction = \
               CASE WHEN $3 = 'succeeded' THEN 1.0 ELSE progress_fraction END, \
             progress_simulated_s = \
               CASE WHEN $3 = 'succeeded' THEN progress_end_s ELSE progress_simulated_s END, \
             progress_eta_s = CASE WHEN $3 = 'succeeded' THEN 0.0 ELSE progress_eta_s END \
             WHERE id = $1 AND attempt = $2 AND status = 'running' \
             RETURNING parent_id, child_index",
        )
        .bind(DbUuid(id))
        .bind(attempt)
        .bind(columns.status.as_str().to_string())
        .bind(now_ms)
        .bind(columns.result)
        .bind(columns.error)
        .bind(columns.track_samples)
        .fetch_optional(&mut *tx)
        .await?;
        let Some(updated) = updated else {
            tx.rollback().await?;
            return Ok(false);
        };
        let parent = child_of(updated.parent_id, updated.child_index)?;
        Bookkeeping::<DB>::finished(&mut tx, id, attempt, finish, parent, now_ms).await?;
        tx.commit().await?;
        Ok(true)
    }

    pub(crate) async fn fan_out(
        pool: &Pool<DB>,
        parent: Uuid,
        attempt: i64,
        fan_out: FanOut,
        now_ms: i64,
    ) -> Result<FanOutResult, StoreError> {
        if fan_out.children.is_empty() {
            return Err(corrupt("a fan-out needs at least one child"));
        }
        let mut tx = Self::begin_write(pool).await?;
        // PostgreSQL: the row lock taken here is held to commit, so a concurrent cancel or
        // re-queue of the parent waits, then sees it waiting with all its children in place.
        let moved = sqlx::query(
            "UPDATE jobs SET status = 'waiting', children_total = $3, lease_owner = NULL, \
             lease_expires_ms = NULL, progress_simulated_s = 0.0, progress_end_s = $4, \
             progress_fraction = 0.0, progress_eta_s = NULL \
             WHERE id = $1 AND attempt = $2 AND status = 'running' AND NOT cancel_requested \
             RETURNING seq",
        )
        .bind(DbUuid(parent))
        .bind(attempt)
        .bind(fan_out.children.len() as i64)
        .bind(fan_out.end_time_s)
        .fetch_optional(&mut *tx)
        .await?;
        if moved.is_none() {
            let owned_but_cancelled = sqlx::query(
                "SELECT 1 FROM jobs WHERE id = $1 AND attempt = $2 AND status = 'running' \
                 AND cancel_requested",
            )
            .bind(DbUuid(parent))
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
                 created_ms, parent_id, child_index, plan) \
                 SELECT $1, $2, 'queued', $3, seed, code_version, submitted_by, $4, id, $5, $7 \
                 FROM jobs WHERE id = $6",
            )
            .bind(DbUuid(child.id))
            .bind(child.kind.as_str().to_string())
            .bind(child.params.to_string())
            .bind(now_ms)
            .bind(index as i64)
            .bind(DbUuid(parent))
            .bind(child.plan.as_ref().map(|plan| plan.to_string()))
            .execute(&mut *tx)
            .await?;
        }
        let fanned_out = AttemptOutcome::FannedOut;
        Bookkeeping::<DB>::end_attempt(&mut tx, parent, attempt, fanned_out, now_ms).await?;
        tx.commit().await?;
        Ok(FanOutResult::FannedOut)
    }

    pub(crate) async fn children(
        pool: &Pool<DB>,
        parent: Uuid,
    ) -> Result<Vec<ChildRecord>, StoreError> {
        let rows: Vec<ChildRow> = sqlx::query_as(
            "SELECT id, child_index, status, result, error FROM jobs WHERE parent_id = $1 \
             ORDER BY child_index",
        )
        .bind(DbUuid(parent))
        .fetch_all(pool)
        .await?;
        records(rows)
    }

    pub(crate) async fn attempts(
        pool: &Pool<DB>,
        id: Uuid,
    ) -> Result<Vec<AttemptRecord>, StoreError> {
        let rows: Vec<AttemptRow> = sqlx::query_as(
            "SELECT attempt, worker, started_ms, ended_ms, outcome, checkpoint_s \
             FROM job_attempts WHERE job_id = $1 ORDER BY attempt",
        )
        .bind(DbUuid(id))
        .fetch_all(pool)
        .await?;
        records(rows)
    }

    pub(crate) async fn request_cancel(
        pool: &Pool<DB>,
        id: Uuid,
        now_ms: i64,
    ) -> Result<Option<JobRecord>, StoreError> {
        let mut tx = Self::begin_write(pool).await?;
        Self::lock_parent_of(&mut tx, id).await?;
        let sql = format!("SELECT status FROM jobs WHERE id = $1{}", DB::FOR_UPDATE);
        let before: Option<(String,)> = sqlx::query_as(&sql)
            .bind(DbUuid(id))
            .fetch_optional(&mut *tx)
            .await?;
        let Some((before,)) = before else {
            tx.rollback().await?;
            return Ok(None);
        };
        // SET expressions all see the old row, so `status IN (...)` tests the old status:
        // queued and waiting jobs end at once, a running one is flagged for its worker.
        let sql = format!(
            "UPDATE jobs SET \
             cancel_requested = CASE WHEN status IN ('queued', 'running', 'waiting') \
               THEN TRUE ELSE cancel_requested END, \
             finished_ms = CASE WHEN status IN ('queued', 'waiting') THEN $2 \
               ELSE finished_ms END, \
             status = CASE WHEN status IN ('queued', 'waiting') THEN 'cancelled' \
               ELSE status END \
             WHERE id = $1 RETURNING {JOB_COLUMNS}"
        );
        let row: JobRow = sqlx::query_as(&sql)
            .bind(DbUuid(id))
            .bind(now_ms)
            .fetch_one(&mut *tx)
            .await?;
        let mut job = JobRecord::try_from(row)?;
        if before == "queued" || before == "waiting" {
            Bookkeeping::<DB>::cancelled(&mut tx, &job, before == "waiting", now_ms).await?;
            job = Self::job_in(&mut tx, id)
                .await?
                .ok_or_else(|| corrupt("cancelled job vanished"))?;
        }
        tx.commit().await?;
        Ok(Some(job))
    }

    pub(crate) async fn job_counts(pool: &Pool<DB>) -> Result<Vec<(JobStatus, i64)>, StoreError> {
        let rows: Vec<(String, i64)> =
            sqlx::query_as("SELECT status, COUNT(*) AS n FROM jobs GROUP BY status")
                .fetch_all(pool)
                .await?;
        let mut counts: Vec<(JobStatus, i64)> = JobStatus::ALL.iter().map(|s| (*s, 0)).collect();
        for (status, n) in rows {
            if let Some(slot) = counts.iter_mut().find(|(s, _)| s.as_str() == status) {
                slot.1 = n;
            }
        }
        Ok(counts)
    }

    pub(crate) async fn track_blocks(
        pool: &Pool<DB>,
        id: Uuid,
    ) -> Result<Vec<TrackBlock>, StoreError> {
        Ok(sqlx::query_as(
            "SELECT block, samples, t_start_s, t_end_s, data FROM job_track_blocks \
             WHERE job_id = $1 ORDER BY block",
        )
        .bind(DbUuid(id))
        .fetch_all(pool)
        .await?)
    }

    pub(crate) async fn plot_names(pool: &Pool<DB>, id: Uuid) -> Result<Vec<String>, StoreError> {
        let rows: Vec<(String,)> = sqlx::query_as(DB::PLOT_NAMES)
            .bind(DbUuid(id))
            .fetch_all(pool)
            .await?;
        Ok(rows.into_iter().map(|(name,)| name).collect())
    }

    pub(crate) async fn plot(
        pool: &Pool<DB>,
        id: Uuid,
        name: String,
    ) -> Result<Option<String>, StoreError> {
        let row: Option<(String,)> =
            sqlx::query_as("SELECT svg FROM job_plots WHERE job_id = $1 AND name = $2")
                .bind(DbUuid(id))
                .bind(name)
                .fetch_optional(pool)
                .await?;
        Ok(row.map(|(svg,)| svg))
    }

    pub(crate) async fn active_sweep(
        pool: &Pool<DB>,
        curve_key: String,
    ) -> Result<Option<JobRecord>, StoreError> {
        let sql = format!(
            "SELECT {JOB_COLUMNS} FROM jobs WHERE curve_key = $1 AND kind = 'sweep' \
             AND status IN ('queued', 'running', 'waiting') ORDER BY seq DESC LIMIT 1"
        );
        let row: Option<JobRow> = sqlx::query_as(&sql)
            .bind(curve_key)
            .fetch_optional(pool)
            .await?;
        row.map(JobRecord::try_from).transpose()
    }

    pub(crate) async fn add_measurement(
        pool: &Pool<DB>,
        m: NewMeasurement,
    ) -> Result<MeasurementRecord, StoreError> {
        let mut tx = Self::begin_write(pool).await?;
        sqlx::query(
            "INSERT INTO rails (serial, created_ms) VALUES ($1, $2) \
             ON CONFLICT (serial) DO NOTHING",
        )
        .bind(m.serial.clone())
        .bind(m.recorded_ms)
        .execute(&mut *tx)
        .await?;
        let row: MeasurementRow = sqlx::query_as(
            "INSERT INTO rail_measurements (id, serial, dimensions_mm, measured_by, \
             measured_at, location, rattle_space, recorded_by, recorded_ms, measured_ms) \
             VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10) RETURNING *",
        )
        .bind(DbUuid(m.id))
        .bind(m.serial)
        .bind(m.dimensions_mm.to_string())
        .bind(m.measured_by)
        .bind(m.measured_at)
        .bind(m.location)
        .bind(m.rattle_space)
        .bind(m.recorded_by)
        .bind(m.recorded_ms)
        .bind(m.measured_ms)
        .fetch_one(&mut *tx)
        .await?;
        let record = MeasurementRecord::try_from(row)?;
        tx.commit().await?;
        Ok(record)
    }

    pub(crate) async fn get_rail(
        pool: &Pool<DB>,
        serial: String,
    ) -> Result<Option<RailRecord>, StoreError> {
        Ok(sqlx::query_as(
            "SELECT r.serial, r.seq, r.created_ms, \
             (SELECT COUNT(*) FROM rail_measurements m WHERE m.serial = r.serial) \
             AS measurements FROM rails r WHERE r.serial = $1",
        )
        .bind(serial)
        .fetch_optional(pool)
        .await?)
    }

    pub(crate) async fn list_rails(
        pool: &Pool<DB>,
        page: PageRequest,
    ) -> Result<Page<RailRecord>, StoreError> {
        let query = sqlx::query_as::<_, RailRecord>(DB::RAILS_PAGE);
        Self::fetch_page(pool, query, page, |r: &RailRecord| r.seq).await
    }

    pub(crate) async fn measurements(
        pool: &Pool<DB>,
        serial: String,
        page: PageRequest,
    ) -> Result<Page<MeasurementRecord>, StoreError> {
        let query = sqlx::query_as::<_, MeasurementRow>(DB::MEASUREMENTS_PAGE).bind(serial);
        Self::fetch_page(pool, query, page, |m: &MeasurementRecord| m.seq).await
    }

    pub(crate) async fn latest_measurement(
        pool: &Pool<DB>,
        serial: String,
    ) -> Result<Option<MeasurementRecord>, StoreError> {
        let row: Option<MeasurementRow> = sqlx::query_as(
            "SELECT * FROM rail_measurements WHERE serial = $1 \
             ORDER BY measured_ms DESC, seq DESC LIMIT 1",
        )
        .bind(serial)
        .fetch_optional(pool)
        .await?;
        row.map(MeasurementRecord::try_from).transpose()
    }

    /// Curve version `id` read on `conn`.
    pub(crate) async fn curve_in(
        conn: &mut DB::Connection,
        id: i64,
    ) -> Result<Option<CurveRecord>, StoreError> {
        let row: Option<CurveRow> = sqlx::query_as(&format!("{CURVE_SELECT} WHERE v.id = $1"))
            .bind(id)
            .fetch_optional(&mut *conn)
            .await?;
        row.map(CurveRecord::try_from).transpose()
    }

    /// The published version of `key` read on `conn`.
    pub(crate) async fn published_in(
        conn: &mut DB::Connection,
        key: String,
    ) -> Result<Option<CurveRecord>, StoreError> {
        let sql = format!("{CURVE_SELECT} WHERE p.curve_key = $1 AND p.curve_id = v.id");
        let row: Option<CurveRow> = sqlx::query_as(&sql)
            .bind(key)
            .fetch_optional(&mut *conn)
            .await?;
        row.map(CurveRecord::try_from).transpose()
    }

    pub(crate) async fn list_curves(
        pool: &Pool<DB>,
        page: PageRequest,
        filter: CurveFilter,
    ) -> Result<Page<CurveRecord>, StoreError> {
        let sql = format!("{CURVE_SELECT} {}", DB::CURVES_PAGE);
        let query = sqlx::query_as::<_, CurveRow>(&sql).bind(filter.key);
        Self::fetch_page(pool, query, page, |c: &CurveRecord| c.id).await
    }

    pub(crate) async fn publish_curve(
        pool: &Pool<DB>,
        id: i64,
        published_by: String,
        force: bool,
        now_ms: i64,
    ) -> Result<PublishOutcome, StoreError> {
        let mut tx = Self::begin_write(pool).await?;
        let Some(candidate) = Self::curve_in(&mut tx, id).await? else {
            tx.rollback().await?;
            return Ok(PublishOutcome::NotFound);
        };
        if let Some(lock) = DB::LOCK_CURVE_KEY {
            sqlx::query(lock)
                .bind(candidate.key.clone())
                .execute(&mut *tx)
                .await?;
        }
        let current = Self::published_in(&mut tx, candidate.key.clone()).await?;
        if let Some(refused) = publish_refusal(&candidate, current.as_ref(), force) {
            tx.rollback().await?;
            return Ok(refused);
        }
        if current.as_ref().map(|c| c.id) != Some(candidate.id) {
            sqlx::query(
                "INSERT INTO published_curves (curve_key, curve_id, published_by, published_ms) \
                 VALUES ($1, $2, $3, $4) ON CONFLICT (curve_key) DO UPDATE SET \
                 curve_id = excluded.curve_id, published_by = excluded.published_by, \
                 published_ms = excluded.published_ms",
            )
            .bind(candidate.key.clone())
            .bind(candidate.id)
            .bind(published_by)
            .bind(now_ms)
            .execute(&mut *tx)
            .await?;
        }
        let record = Self::curve_in(&mut tx, id)
            .await?
            .ok_or_else(|| corrupt(format!("curve {id} vanished while published")))?;
        tx.commit().await?;
        Ok(PublishOutcome::Published(record))
    }

    /// PostgreSQL: a concurrent insert of the same content waits for the first to commit, then
    /// does nothing; the select below then sees the committed row.
    pub(crate) async fn insert_campaign(
        pool: &Pool<DB>,
        c: NewCampaign,
    ) -> Result<CampaignInsert, StoreError> {
        let content_bytes = c.content.len() as i64;
        let inserted: Option<CampaignRow> = sqlx::query_as(&format!(
            "INSERT INTO campaigns (id, name, created_by, created_ms, content, \
             content_sha256, content_bytes, tests, specimens, increments, \
             accelerometer_records) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11) \
             ON CONFLICT (content_sha256) DO NOTHING RETURNING {CAMPAIGN_SUMMARY}"
        ))
        .bind(DbUuid(c.id))
        .bind(c.name)
        .bind(c.created_by)
        .bind(c.created_ms)
        .bind(c.content)
        .bind(c.content_sha256.clone())
        .bind(content_bytes)
        .bind(c.counts.tests)
        .bind(c.counts.specimens)
        .bind(c.counts.increments)
        .bind(c.counts.accelerometer_records)
        .fetch_optional(pool)
        .await?;
        if let Some(row) = inserted {
            return Ok(CampaignInsert::Created(row.try_into()?));
        }
        let sql = format!("SELECT {CAMPAIGN_SUMMARY} FROM campaigns WHERE content_sha256 = $1");
        let row: CampaignRow = sqlx::query_as(&sql)
            .bind(c.content_sha256)
            .fetch_one(pool)
            .await?;
        Ok(CampaignInsert::Existing(row.try_into()?))
    }

    pub(crate) async fn get_campaign(
        pool: &Pool<DB>,
        id: Uuid,
    ) -> Result<Option<CampaignRecord>, StoreError> {
        let sql = format!("SELECT {CAMPAIGN_SUMMARY}, content FROM campaigns WHERE id = $1");
        let row: Option<CampaignContentRow> = sqlx::query_as(&sql)
            .bind(DbUuid(id))
            .fetch_optional(pool)
            .await?;
        row.map(CampaignRecord::try_from).transpose()
    }

    pub(crate) async fn list_campaigns(
        pool: &Pool<DB>,
        page: PageRequest,
    ) -> Result<Page<CampaignSummary>, StoreError> {
        let sql = format!(
            "SELECT {CAMPAIGN_SUMMARY} FROM campaigns {}",
            DB::CAMPAIGNS_PAGE
        );
        let query = sqlx::query_as::<_, CampaignRow>(&sql);
        Self::fetch_page(pool, query, page, |c: &CampaignSummary| c.seq).await
    }

    pub(crate) async fn create_token(
        pool: &Pool<DB>,
        name: String,
        role: Role,
        token_sha256: String,
        now_ms: i64,
    ) -> Result<TokenRecord, StoreError> {
        let row: TokenRow = sqlx::query_as(
            "INSERT INTO api_tokens (id, name, role, token_sha256, created_ms) \
             VALUES ($1, $2, $3, $4, $5) RETURNING *",
        )
        .bind(DbUuid(Uuid::new_v4()))
        .bind(name)
        .bind(role.as_str().to_string())
        .bind(token_sha256)
        .bind(now_ms)
        .fetch_one(pool)
        .await?;
        row.try_into()
    }

    pub(crate) async fn find_token(
        pool: &Pool<DB>,
        token_sha256: String,
    ) -> Result<Option<TokenRecord>, StoreError> {
        let row: Option<TokenRow> = sqlx::query_as(
            "SELECT * FROM api_tokens WHERE token_sha256 = $1 AND revoked_ms IS NULL",
        )
        .bind(token_sha256)
        .fetch_optional(pool)
        .await?;
        row.map(TokenRecord::try_from).transpose()
    }

    pub(crate) async fn list_tokens(pool: &Pool<DB>) -> Result<Vec<TokenRecord>, StoreError> {
        let rows: Vec<TokenRow> = sqlx::query_as(DB::TOKENS).fetch_all(pool).await?;
        records(rows)
    }

    pub(crate) async fn revoke_token(
        pool: &Pool<DB>,
        id: Uuid,
        now_ms: i64,
    ) -> Result<bool, StoreError> {
        let revoked = sqlx::query(
            "UPDATE api_tokens SET revoked_ms = $2 WHERE id = $1 AND revoked_ms IS NULL \
             RETURNING id",
        )
        .bind(DbUuid(id))
        .bind(now_ms)
        .fetch_optional(pool)
        .await?;
        Ok(revoked.is_some())
    }

    /// Stores `checkpoint` while `attempt` holds the running lease (fenced by the attempt, as
    /// every worker write); in the same transaction progress moves to its time and the attempt
    /// records it. False, with nothing written, for a stale attempt.
    pub(crate) async fn save_checkpoint(
        pool: &Pool<DB>,
        id: Uuid,
        attempt: i64,
        checkpoint: NewCheckpoint,
        now_ms: i64,
    ) -> Result<bool, StoreError> {
        let mut tx = Self::begin_write(pool).await?;
        let owned: Option<(i64,)> = sqlx::query_as(
            "UPDATE jobs SET progress_simulated_s = $3, progress_end_s = $4, \
             progress_fraction = CASE WHEN $4 > 0 THEN $3 / $4 ELSE progress_fraction END \
             WHERE id = $1 AND attempt = $2 AND status = 'running' RETURNING seq",
        )
        .bind(DbUuid(id))
        .bind(attempt)
        .bind(checkpoint.simulated_s)
        .bind(checkpoint.end_s)
        .fetch_optional(&mut *tx)
        .await?;
        if owned.is_none() {
            tx.rollback().await?;
            return Ok(false);
        }
        sqlx::query(
            "INSERT INTO job_checkpoints (job_id, attempt, simulated_s, end_s, created_ms, data) \
             VALUES ($1, $2, $3, $4, $5, $6) \
             ON CONFLICT (job_id) DO UPDATE SET attempt = excluded.attempt, \
             simulated_s = excluded.simulated_s, end_s = excluded.end_s, \
             created_ms = excluded.created_ms, data = excluded.data",
        )
        .bind(DbUuid(id))
        .bind(attempt)
        .bind(checkpoint.simulated_s)
        .bind(checkpoint.end_s)
        .bind(now_ms)
        .bind(checkpoint.data)
        .execute(&mut *tx)
        .await?;
        sqlx::query("UPDATE job_attempts SET checkpoint_s = $3 WHERE job_id = $1 AND attempt = $2")
            .bind(DbUuid(id))
            .bind(attempt)
            .bind(checkpoint.simulated_s)
            .execute(&mut *tx)
            .await?;
        tx.commit().await?;
        Ok(true)
    }

    /// The job's stored checkpoint, if any.
    pub(crate) async fn load_checkpoint(
        pool: &Pool<DB>,
        id: Uuid,
    ) -> Result<Option<JobCheckpoint>, StoreError> {
        Ok(sqlx::query_as(
            "SELECT attempt, simulated_s, end_s, created_ms, data FROM job_checkpoints \
             WHERE job_id = $1",
        )
        .bind(DbUuid(id))
        .fetch_optional(pool)
        .await?)
    }

    /// Stores record chunk `seq` of job `id` while `attempt` holds the running lease (one
    /// statement: the insert happens only if the job row says so). False for a stale attempt.
    pub(crate) async fn save_record_chunk(
        pool: &Pool<DB>,
        id: Uuid,
        attempt: i64,
        seq: u64,
        data: Vec<u8>,
    ) -> Result<bool, StoreError> {
        let seq = i64::try_from(seq).map_err(|e| StoreError::Corrupt(e.to_string()))?;
        let mut tx = Self::begin_write(pool).await?;
        // A write that changes nothing, so that PostgreSQL locks the job row as the other
        // fenced writes do (a claim cannot slip in between).
        let owned: Option<(i64,)> = sqlx::query_as(
            "UPDATE jobs SET attempt = attempt \
             WHERE id = $1 AND attempt = $2 AND status = 'running' RETURNING seq",
        )
        .bind(DbUuid(id))
        .bind(attempt)
        .fetch_optional(&mut *tx)
        .await?;
        if owned.is_none() {
            tx.rollback().await?;
            return Ok(false);
        }
        sqlx::query(
            "INSERT INTO job_record_chunks (job_id, seq, attempt, data) VALUES ($1, $2, $3, $4) \
             ON CONFLICT (job_id, seq) DO UPDATE SET attempt = excluded.attempt, \
             data = excluded.data",
        )
        .bind(DbUuid(id))
        .bind(seq)
        .bind(attempt)
        .bind(data)
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(true)
    }

    /// Job `id`'s record chunks from number 0 on, in order, up to the first gap.
    pub(crate) async fn load_record_chunks(
        pool: &Pool<DB>,
        id: Uuid,
    ) -> Result<Vec<Vec<u8>>, StoreError> {
        let rows: Vec<RecordChunkRow> = sqlx::query_as(
            "SELECT seq, data FROM job_record_chunks WHERE job_id = $1 ORDER BY seq",
        )
        .bind(DbUuid(id))
        .fetch_all(pool)
        .await?;
        Ok(rows
            .into_iter()
            .enumerate()
            .take_while(|(i, row)| row.seq == *i as i64)
            .map(|(_, row)| row.data)
            .collect())
    }

    /// The plan stored with job `id` at submission (none: no such job, or none stored).
    pub(crate) async fn job_plan(
        pool: &Pool<DB>,
        id: Uuid,
    ) -> Result<Option<serde_json::Value>, StoreError> {
        let row: Option<PlanRow> = sqlx::query_as("SELECT plan FROM jobs WHERE id = $1")
            .bind(DbUuid(id))
            .fetch_optional(pool)
            .await?;
        row.map_or(Ok(None), PlanRow::plan)
    }
}
