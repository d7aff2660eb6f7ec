//! The writes that follow an attempt's end, written once for both engines: the attempt log,
//! a fanned-out parent's counts when one of its children ends (and, when that fails the
//! parent, cancelling the siblings), and a successful job's outputs (track blocks, plots, the
//! sweep's curve version).
//!
//! These statements read the same on SQLite and PostgreSQL (`$N` placeholders, `TRUE`,
//! `CAST(.. AS DOUBLE PRECISION)` and `ON CONFLICT .. DO UPDATE` are accepted by both), so they
//! are generic over the [`sqlx::Database`] and run on the caller's connection, inside the
//! caller's transaction. What differs stays with the engine: how that transaction serializes
//! the counting (SQLite: `BEGIN IMMEDIATE`, one writer; PostgreSQL: the parent's row lock,
//! taken first), and how the job's own row is fenced and ended.

use super::job_records::{ChildOf, JobRecord, JobStatus};
use super::rows::{DbUuid, LostAttempt};
use super::{child_failure_message, AttemptOutcome, Finish, NewCurve, StoreError};
use sqlx::{ColumnIndex, Database, Decode, Encode, Executor, IntoArguments, Row, Type};
use std::marker::PhantomData;
use uuid::Uuid;

/// The shared writes on engine `DB` (`Bookkeeping::<Sqlite>::end_attempt(..)`); one bound list
/// for all of them.
pub(crate) struct Bookkeeping<DB>(PhantomData<DB>);

/// What the fenced update of a finishing job writes into its row.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FinishColumns {
    pub status: JobStatus,
    /// The summary's JSON text (succeeded).
    pub result: Option<String>,
    /// The failure message (failed).
    pub error: Option<String>,
    /// Contact-track samples stored (succeeded).
    pub track_samples: i64,
}

impl FinishColumns {
    pub(crate) fn of(finish: &Finish) -> Self {
        match finish {
            Finish::Succeeded {
                summary, blocks, ..
            } => FinishColumns {
                status: JobStatus::Succeeded,
                result: Some(summary.to_string()),
                error: None,
                track_samples: blocks.iter().map(|b| b.samples).sum(),
            },
            Finish::Failed(message) => FinishColumns {
                status: JobStatus::Failed,
                result: None,
                error: Some(message.clone()),
                track_samples: 0,
            },
            Finish::Cancelled => FinishColumns {
                status: JobStatus::Cancelled,
                result: None,
                error: None,
                track_samples: 0,
            },
        }
    }
}

impl<DB> Bookkeeping<DB>
where
    DB: Database,
    for<'c> &'c mut DB::Connection: Executor<'c, Database = DB>,
    for<'q> DB::Arguments<'q>: IntoArguments<'q, DB>,
    for<'q> DbUuid: Encode<'q, DB> + Type<DB>,
    for<'q> i64: Encode<'q, DB> + Type<DB>,
    for<'q> f64: Encode<'q, DB> + Type<DB>,
    for<'q> String: Encode<'q, DB> + Decode<'q, DB> + Type<DB>,
    for<'q> Vec<u8>: Encode<'q, DB> + Type<DB>,
    for<'q> Option<f64>: Encode<'q, DB> + Type<DB>,
    for<'q> Option<String>: Encode<'q, DB> + Type<DB>,
    usize: ColumnIndex<DB::Row>,
{
    /// Log attempt `attempt` of job `id`, claimed by `worker` at `now_ms`, as running.
    pub(crate) async fn start_attempt(
        conn: &mut DB::Connection,
        id: Uuid,
        attempt: i64,
        worker: &str,
        now_ms: i64,
    ) -> Result<(), StoreError> {
        sqlx::query(
            "INSERT INTO job_attempts (job_id, attempt, worker, started_ms, outcome) \
             VALUES ($1, $2, $3, $4, 'running')",
        )
        .bind(DbUuid(id))
        .bind(attempt)
        .bind(worker.to_string())
        .bind(now_ms)
        .execute(&mut *conn)
        .await?;
        Ok(())
    }

    /// Record how attempt `attempt` of job `id` ended.
    pub(crate) async fn end_attempt(
        conn: &mut DB::Connection,
        id: Uuid,
        attempt: i64,
        outcome: AttemptOutcome,
        now_ms: i64,
    ) -> Result<(), StoreError> {
        sqlx::query(
            "UPDATE job_attempts SET outcome = $3, ended_ms = $4 \
             WHERE job_id = $1 AND attempt = $2",
        )
        .bind(DbUuid(id))
        .bind(attempt)
        .bind(outcome.as_str().to_string())
        .bind(now_ms)
        .execute(&mut *conn)
        .await?;
        Ok(())
    }

    /// What follows the fenced update that ended attempt `attempt` of job `id` (a child of
    /// `parent`, if any) as `finish` says: the attempt log, the parent's bookkeeping, and a
    /// success's outputs.
    pub(crate) async fn finished(
        conn: &mut DB::Connection,
        id: Uuid,
        attempt: i64,
        finish: Finish,
        parent: Option<ChildOf>,
        now_ms: i64,
    ) -> Result<(), StoreError> {
        let columns = FinishColumns::of(&finish);
        Self::end_attempt(conn, id, attempt, columns.status.into(), now_ms).await?;
        if let Some(of) = parent {
            let error = columns.error.as_deref();
            Self::child_ended(conn, of, id, columns.status, error, now_ms).await?;
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
                    "INSERT INTO job_track_blocks \
                     (job_id, block, samples, t_start_s, t_end_s, data) \
                     VALUES ($1, $2, $3, $4, $5, $6)",
                )
                .bind(DbUuid(id))
                .bind(block.index)
                .bind(block.samples)
                .bind(block.t_start_s)
                .bind(block.t_end_s)
                .bind(block.data)
                .execute(&mut *conn)
                .await?;
            }
            for (name, svg) in plots {
                sqlx::query(
                    "INSERT INTO job_plots (job_id, name, svg) VALUES ($1, $2, $3) \
                     ON CONFLICT (job_id, name) DO UPDATE SET svg = excluded.svg",
                )
                .bind(DbUuid(id))
                .bind(name)
                .bind(svg)
                .execute(&mut *conn)
                .await?;
            }
            if let Some(curve) = curve {
                Self::insert_curve_version(conn, *curve).await?;
            }
        }
        Ok(())
    }

    /// The writes after an attempt lost its lease: the attempt log and, when that ended the
    /// job, its parent's bookkeeping.
    pub(crate) async fn lost(
        conn: &mut DB::Connection,
        lost: LostAttempt,
        now_ms: i64,
    ) -> Result<(), StoreError> {
        Self::end_attempt(conn, lost.id, lost.attempt, AttemptOutcome::Lost, now_ms).await?;
        if let (Some(of), true) = (lost.parent, lost.status.is_terminal()) {
            let error = lost.error.as_deref();
            Self::child_ended(conn, of, lost.id, lost.status, error, now_ms).await?;
        }
        Ok(())
    }

    /// The writes after a queued or waiting `job` was cancelled at once: a waiting job's
    /// children are cancelled (`was_waiting`), a child's parent hears of it.
    pub(crate) async fn cancelled(
        conn: &mut DB::Connection,
        job: &JobRecord,
        was_waiting: bool,
        now_ms: i64,
    ) -> Result<(), StoreError> {
        if was_waiting {
            Self::cancel_children(conn, job.id, now_ms).await?;
        }
        if let Some(of) = job.parent {
            Self::child_ended(conn, of, job.id, JobStatus::Cancelled, None, now_ms).await?;
        }
        Ok(())
    }

    /// Parent bookkeeping when child `child` (index `of.index` of `of.parent_id`) ended with
    /// `status`. The success that completes the set re-queues a waiting parent for its
    /// assembly; a failure or cancellation fails a waiting parent, naming the child, and
    /// cancels the siblings. The caller's transaction must make the count it reads final (see
    /// the module doc).
    pub(crate) async fn child_ended(
        conn: &mut DB::Connection,
        of: ChildOf,
        child: Uuid,
        status: JobStatus,
        error: Option<&str>,
        now_ms: i64,
    ) -> Result<(), StoreError> {
        let parent = of.parent_id;
        if status == JobStatus::Succeeded {
            sqlx::query(
                "UPDATE jobs SET children_succeeded = children_succeeded + 1, \
                 progress_fraction = \
                   CAST(children_succeeded + 1 AS DOUBLE PRECISION) / children_total, \
                 progress_simulated_s = \
                   progress_end_s * (children_succeeded + 1) / children_total, \
                 status = CASE WHEN status = 'waiting' \
                   AND children_succeeded + 1 >= children_total THEN 'queued' ELSE status END \
                 WHERE id = $1",
            )
            .bind(DbUuid(parent))
            .execute(&mut *conn)
            .await?;
            return Ok(());
        }
        let message = child_failure_message(&child.to_string(), of.index, status, error);
        let row = sqlx::query(
            "UPDATE jobs SET children_failed = children_failed + $2, \
             children_cancelled = children_cancelled + $3, \
             error = CASE WHEN status = 'waiting' THEN $4 ELSE error END, \
             finished_ms = CASE WHEN status = 'waiting' THEN $5 ELSE finished_ms END, \
             status = CASE WHEN status = 'waiting' THEN 'failed' ELSE status END \
             WHERE id = $1 RETURNING status",
        )
        .bind(DbUuid(parent))
        .bind(i64::from(status == JobStatus::Failed))
        .bind(i64::from(status == JobStatus::Cancelled))
        .bind(message)
        .bind(now_ms)
        .fetch_optional(&mut *conn)
        .await?;
        if let Some(row) = row {
            let parent_status: String = row.try_get(0)?;
            if parent_status == "failed" || parent_status == "cancelled" {
                Self::cancel_children(conn, parent, now_ms).await?;
            }
        }
        Ok(())
    }

    /// Cancel the queued children of a terminal parent at once and flag its running ones.
    pub(crate) async fn cancel_children(
        conn: &mut DB::Connection,
        parent: Uuid,
        now_ms: i64,
    ) -> Result<(), StoreError> {
        // Counted from RETURNING: a generic `QueryResult` has no `rows_affected`.
        let cancelled = sqlx::query(
            "UPDATE jobs SET status = 'cancelled', cancel_requested = TRUE, finished_ms = $2 \
             WHERE parent_id = $1 AND status = 'queued' RETURNING seq",
        )
        .bind(DbUuid(parent))
        .bind(now_ms)
        .fetch_all(&mut *conn)
        .await?
        .len();
        if cancelled > 0 {
            sqlx::query(
                "UPDATE jobs SET children_cancelled = children_cancelled + $2 WHERE id = $1",
            )
            .bind(DbUuid(parent))
            .bind(cancelled as i64)
            .execute(&mut *conn)
            .await?;
        }
        sqlx::query(
            "UPDATE jobs SET cancel_requested = TRUE WHERE parent_id = $1 AND status = 'running'",
        )
        .bind(DbUuid(parent))
        .execute(&mut *conn)
        .await?;
        Ok(())
    }

    /// Store a sweep's curve as the next version of its key (inside the finishing transaction).
    async fn insert_curve_version(
        conn: &mut DB::Connection,
        curve: NewCurve,
    ) -> Result<(), StoreError> {
        sqlx::query(
            "INSERT INTO curve_versions (curve_key, version, job_id, curve, provenance, points, \
             duration_per_point_s, seeds, created_by, code_version, created_ms) \
             SELECT $1, COALESCE(MAX(version), 0) + 1, $2, $3, $4, $5, $6, $7, $8, $9, $10 \
             FROM curve_versions WHERE curve_key = $1",
        )
        .bind(curve.key)
        .bind(DbUuid(curve.job_id))
        .bind(curve.curve.to_string())
        .bind(curve.provenance.to_string())
        .bind(curve.fidelity.points)
        .bind(curve.fidelity.duration_per_point_s)
        .bind(curve.fidelity.seeds)
        .bind(curve.created_by)
        .bind(curve.code_version)
        .bind(curve.created_ms)
        .execute(&mut *conn)
        .await?;
        Ok(())
    }
}
