//! Row mapping shared by both engines: one `#[derive(sqlx::FromRow)]` struct per result shape
//! (the derive is generic over the row type, so the same struct reads a `SqliteRow` and a
//! `PgRow`) and one `TryFrom` per record, which is where a stored value that does not read back
//! (bad UUID text, unknown enum name, JSON that does not parse) becomes
//! [`StoreError::Corrupt`]. Column types agree between the schemas except UUIDs (TEXT on SQLite,
//! UUID on PostgreSQL), read through [`StoredUuid`] and bound through [`DbUuid`], and booleans
//! (INTEGER 0/1 on SQLite), which sqlx decodes into `bool` on both.

use super::job_records::{ChildCounts, ChildOf, JobKind, JobProgress, JobRecord, JobStatus};
use super::Role;
use super::{
    AttemptOutcome, AttemptRecord, CampaignCounts, CampaignRecord, CampaignSummary, ChildRecord,
    CurveFidelity, CurveRecord, HostLease, MeasurementRecord, Page, Publication, StoreError,
    TokenRecord,
};
use sqlx::encode::IsNull;
use sqlx::error::BoxDynError;
use sqlx::postgres::{PgArgumentBuffer, PgTypeInfo, PgValueRef};
use sqlx::sqlite::{SqliteArgumentValue, SqliteTypeInfo, SqliteValueRef};
use sqlx::{Decode, Encode, Postgres, Sqlite, Type};
use uuid::Uuid;

pub(crate) fn corrupt(what: impl Into<String>) -> StoreError {
    StoreError::Corrupt(what.into())
}

fn parse_json(text: &str, what: &str) -> Result<serde_json::Value, StoreError> {
    serde_json::from_str(text).map_err(|e| corrupt(format!("{what}: {e}")))
}

fn parse_status(status: &str) -> Result<JobStatus, StoreError> {
    JobStatus::parse(status).ok_or_else(|| corrupt(format!("job status `{status}`")))
}

/// A UUID column as read: the TEXT SQLite stores (checked when the row becomes a record) or
/// PostgreSQL's native UUID.
#[derive(Debug, Clone)]
pub(crate) struct StoredUuid(Result<Uuid, String>);

impl StoredUuid {
    pub(crate) fn get(self) -> Result<Uuid, StoreError> {
        self.0.map_err(|text| corrupt(format!("bad uuid `{text}`")))
    }
}

impl Type<Sqlite> for StoredUuid {
    fn type_info() -> SqliteTypeInfo {
        <String as Type<Sqlite>>::type_info()
    }
    fn compatible(ty: &SqliteTypeInfo) -> bool {
        <String as Type<Sqlite>>::compatible(ty)
    }
}

impl<'r> Decode<'r, Sqlite> for StoredUuid {
    fn decode(value: SqliteValueRef<'r>) -> Result<Self, BoxDynError> {
        let text = <&str as Decode<Sqlite>>::decode(value)?;
        Ok(Self(Uuid::parse_str(text).map_err(|_| text.to_string())))
    }
}

impl Type<Postgres> for StoredUuid {
    fn type_info() -> PgTypeInfo {
        <Uuid as Type<Postgres>>::type_info()
    }
}

impl<'r> Decode<'r, Postgres> for StoredUuid {
    fn decode(value: PgValueRef<'r>) -> Result<Self, BoxDynError> {
        Ok(Self(Ok(<Uuid as Decode<Postgres>>::decode(value)?)))
    }
}

/// A UUID to bind: hyphenated TEXT on SQLite, a native UUID on PostgreSQL.
#[derive(Debug, Clone, Copy)]
pub(crate) struct DbUuid(pub Uuid);

impl Type<Sqlite> for DbUuid {
    fn type_info() -> SqliteTypeInfo {
        <String as Type<Sqlite>>::type_info()
    }
}

impl<'q> Encode<'q, Sqlite> for DbUuid {
    fn encode_by_ref(
        &self,
        args: &mut Vec<SqliteArgumentValue<'q>>,
    ) -> Result<IsNull, BoxDynError> {
        <String as Encode<Sqlite>>::encode(self.0.to_string(), args)
    }
}

impl Type<Postgres> for DbUuid {
    fn type_info() -> PgTypeInfo {
        <Uuid as Type<Postgres>>::type_info()
    }
}

impl Encode<'_, Postgres> for DbUuid {
    fn encode_by_ref(&self, buf: &mut PgArgumentBuffer) -> Result<IsNull, BoxDynError> {
        <Uuid as Encode<Postgres>>::encode_by_ref(&self.0, buf)
    }
}

/// Cut a fetched `limit + 1` list into a page; `cursor` gives the next page's start.
pub(crate) fn cut_page<T>(mut items: Vec<T>, limit: i64, cursor: impl Fn(&T) -> i64) -> Page<T> {
    let limit = limit.max(0) as usize;
    let next_cursor = if items.len() > limit {
        items.truncate(limit);
        items.last().map(|last| cursor(last).to_string())
    } else {
        None
    };
    Page { items, next_cursor }
}

/// Convert rows one by one into records.
pub(crate) fn records<R, T>(rows: Vec<R>) -> Result<Vec<T>, StoreError>
where
    T: TryFrom<R>,
    StoreError: From<T::Error>,
{
    rows.into_iter()
        .map(|row| T::try_from(row).map_err(StoreError::from))
        .collect()
}

/// The columns of [`JobRow`].
pub(crate) const JOB_COLUMNS: &str = "seq, id, kind, status, params, seed, code_version, \
    submitted_by, attempt, cancel_requested, created_ms, started_ms, finished_ms, \
    progress_simulated_s, progress_end_s, progress_fraction, progress_eta_s, result, error, \
    track_samples, curve_key, lease_owner, parent_id, child_index, children_total, \
    children_succeeded, children_failed, children_cancelled";

/// Curve versions with their publication, the columns of [`CurveRow`] (left join:
/// `p.curve_id = v.id` only for the published one).
pub(crate) const CURVE_SELECT: &str = "SELECT v.id, v.curve_key, v.version, v.job_id, v.curve, \
     v.provenance, v.points, v.duration_per_point_s, v.seeds, v.created_by, v.code_version, \
     v.created_ms, p.curve_id AS published_id, p.published_by, p.published_ms \
     FROM curve_versions v LEFT JOIN published_curves p ON p.curve_key = v.curve_key";

/// The columns of [`CampaignRow`]: a campaign's summary (everything but the content).
pub(crate) const CAMPAIGN_SUMMARY: &str = "seq, id, name, created_by, created_ms, \
    content_sha256, content_bytes, tests, specimens, increments, accelerometer_records";

/// A `jobs` row as `JOB_COLUMNS` selects it.
#[derive(sqlx::FromRow)]
pub(crate) struct JobRow {
    seq: i64,
    id: StoredUuid,
    kind: String,
    status: String,
    params: String,
    /// The u64 seed's bit pattern.
    seed: i64,
    code_version: String,
    submitted_by: String,
    attempt: i64,
    cancel_requested: bool,
    created_ms: i64,
    started_ms: Option<i64>,
    finished_ms: Option<i64>,
    progress_simulated_s: Option<f64>,
    progress_end_s: Option<f64>,
    progress_fraction: Option<f64>,
    progress_eta_s: Option<f64>,
    result: Option<String>,
    error: Option<String>,
    track_samples: i64,
    curve_key: Option<String>,
    lease_owner: Option<String>,
    parent_id: Option<StoredUuid>,
    child_index: Option<i64>,
    children_total: i64,
    children_succeeded: i64,
    children_failed: i64,
    children_cancelled: i64,
}

impl TryFrom<JobRow> for JobRecord {
    type Error = StoreError;

    fn try_from(row: JobRow) -> Result<Self, StoreError> {
        let progress = match (
            row.progress_simulated_s,
            row.progress_end_s,
            row.progress_fraction,
        ) {
            (Some(simulated_time_s), Some(end_time_s), Some(fraction)) => Some(JobProgress {
                simulated_time_s,
                end_time_s,
                fraction,
                eta_s: row.progress_eta_s,
            }),
            _ => None,
        };
        let kind = &row.kind;
        Ok(JobRecord {
            id: row.id.get()?,
            seq: row.seq,
            kind: JobKind::parse(kind).ok_or_else(|| corrupt(format!("job kind `{kind}`")))?,
            status: parse_status(&row.status)?,
            params: parse_json(&row.params, "job params")?,
            seed: row.seed as u64,
            code_version: row.code_version,
            submitted_by: row.submitted_by,
            attempt: row.attempt,
            cancel_requested: row.cancel_requested,
            created_ms: row.created_ms,
            started_ms: row.started_ms,
            finished_ms: row.finished_ms,
            progress,
            result: row
                .result
                .as_deref()
                .map(|r| parse_json(r, "job result"))
                .transpose()?,
            error: row.error,
            track_samples: row.track_samples,
            curve_key: row.curve_key,
            lease_owner: row.lease_owner,
            parent: child_of(row.parent_id, row.child_index)?,
            children: match row.children_total {
                0 => None,
                total => Some(ChildCounts {
                    total,
                    succeeded: row.children_succeeded,
                    failed: row.children_failed,
                    cancelled: row.children_cancelled,
                }),
            },
        })
    }
}

/// A job's stored plan (`jobs.plan`), as `Store::job_plan` reads it.
#[derive(sqlx::FromRow)]
pub(crate) struct PlanRow {
    plan: Option<String>,
}

impl PlanRow {
    /// The plan's JSON, if one was stored.
    pub(crate) fn plan(self) -> Result<Option<serde_json::Value>, StoreError> {
        self.plan
            .map(|text| parse_json(&text, "job plan"))
            .transpose()
    }
}

/// One stored record chunk of a job's run, as `Store::load_record_chunks` reads it.
#[derive(sqlx::FromRow)]
pub(crate) struct RecordChunkRow {
    pub(crate) seq: i64,
    pub(crate) data: Vec<u8>,
}

/// The parent link a finishing job's update returns.
#[derive(sqlx::FromRow)]
pub(crate) struct ParentLinkRow {
    pub parent_id: Option<StoredUuid>,
    pub child_index: Option<i64>,
}

/// A job with the request hash of its idempotency key (`SELECT <job columns>,
/// request_sha256`), as a submission with that key reads it.
#[derive(sqlx::FromRow)]
pub(crate) struct KeyedJobRow {
    #[sqlx(flatten)]
    pub job: JobRow,
    pub request_sha256: Option<String>,
}

/// A job whose lease expired, as the re-queue's `RETURNING id, attempt, status, error,
/// parent_id, child_index` gives it.
#[derive(sqlx::FromRow)]
pub(crate) struct LostRow {
    id: StoredUuid,
    attempt: i64,
    status: String,
    error: Option<String>,
    parent_id: Option<StoredUuid>,
    child_index: Option<i64>,
}

/// An attempt that lost its lease and what its job became (queued again, or failed or
/// cancelled, which a parent hears of).
#[derive(Debug, Clone)]
pub(crate) struct LostAttempt {
    pub id: Uuid,
    pub attempt: i64,
    pub status: JobStatus,
    pub error: Option<String>,
    pub parent: Option<ChildOf>,
}

impl TryFrom<LostRow> for LostAttempt {
    type Error = StoreError;

    fn try_from(row: LostRow) -> Result<Self, StoreError> {
        Ok(LostAttempt {
            id: row.id.get()?,
            attempt: row.attempt,
            status: parse_status(&row.status)?,
            error: row.error,
            parent: child_of(row.parent_id, row.child_index)?,
        })
    }
}

/// The parent link of a job row (both columns set for a child, neither otherwise).
pub(crate) fn child_of(
    parent_id: Option<StoredUuid>,
    child_index: Option<i64>,
) -> Result<Option<ChildOf>, StoreError> {
    match (parent_id, child_index) {
        (Some(parent_id), Some(index)) => Ok(Some(ChildOf {
            parent_id: parent_id.get()?,
            index,
        })),
        _ => Ok(None),
    }
}

/// A child job as its parent's assembly reads it.
#[derive(sqlx::FromRow)]
pub(crate) struct ChildRow {
    id: StoredUuid,
    child_index: i64,
    status: String,
    result: Option<String>,
    error: Option<String>,
}

impl TryFrom<ChildRow> for ChildRecord {
    type Error = StoreError;

    fn try_from(row: ChildRow) -> Result<Self, StoreError> {
        Ok(ChildRecord {
            id: row.id.get()?,
            index: row.child_index,
            status: parse_status(&row.status)?,
            result: row
                .result
                .as_deref()
                .map(|r| parse_json(r, "child result"))
                .transpose()?,
            error: row.error,
        })
    }
}

/// A `job_attempts` row.
#[derive(sqlx::FromRow)]
pub(crate) struct AttemptRow {
    attempt: i64,
    worker: String,
    started_ms: i64,
    ended_ms: Option<i64>,
    outcome: String,
    checkpoint_s: Option<f64>,
}

impl TryFrom<AttemptRow> for AttemptRecord {
    type Error = StoreError;

    fn try_from(row: AttemptRow) -> Result<Self, StoreError> {
        let outcome = &row.outcome;
        Ok(AttemptRecord {
            attempt: row.attempt,
            worker: row.worker,
            started_ms: row.started_ms,
            ended_ms: row.ended_ms,
            outcome: AttemptOutcome::parse(outcome)
                .ok_or_else(|| corrupt(format!("attempt outcome `{outcome}`")))?,
            checkpoint_s: row.checkpoint_s,
        })
    }
}

/// A running job's lease holder (`host_leases`).
#[derive(sqlx::FromRow)]
pub(crate) struct HostLeaseRow {
    id: StoredUuid,
    attempt: i64,
    lease_pid: i64,
    lease_instance: String,
}

impl TryFrom<HostLeaseRow> for HostLease {
    type Error = StoreError;

    fn try_from(row: HostLeaseRow) -> Result<Self, StoreError> {
        let pid = row.lease_pid;
        Ok(HostLease {
            job: row.id.get()?,
            attempt: row.attempt,
            pid: u32::try_from(pid).map_err(|_| corrupt(format!("pid {pid}")))?,
            instance: row.lease_instance,
        })
    }
}

/// A curve version with its publication, as `CURVE_SELECT` reads it (`published_id` is the
/// key's published version, this one or another).
#[derive(sqlx::FromRow)]
pub(crate) struct CurveRow {
    id: i64,
    curve_key: String,
    version: i64,
    job_id: StoredUuid,
    curve: String,
    provenance: String,
    points: i64,
    duration_per_point_s: Option<f64>,
    seeds: i64,
    created_by: String,
    code_version: String,
    created_ms: i64,
    published_id: Option<i64>,
    published_by: Option<String>,
    published_ms: Option<i64>,
}

impl TryFrom<CurveRow> for CurveRecord {
    type Error = StoreError;

    fn try_from(row: CurveRow) -> Result<Self, StoreError> {
        let published = match (row.published_id, row.published_by, row.published_ms) {
            (Some(p), Some(published_by), Some(published_ms)) if p == row.id => Some(Publication {
                published_by,
                published_ms,
            }),
            (Some(p), _, _) if p == row.id => {
                return Err(corrupt(format!(
                    "publication of curve {} incomplete",
                    row.id
                )))
            }
            _ => None,
        };
        Ok(CurveRecord {
            id: row.id,
            key: row.curve_key,
            version: row.version,
            job_id: row.job_id.get()?,
            curve: parse_json(&row.curve, "penalization curve")?,
            fidelity: CurveFidelity {
                points: row.points,
                duration_per_point_s: row.duration_per_point_s,
                seeds: row.seeds,
            },
            provenance: parse_json(&row.provenance, "curve provenance")?,
            created_by: row.created_by,
            code_version: row.code_version,
            created_ms: row.created_ms,
            published,
        })
    }
}

/// A `rail_measurements` row.
#[derive(sqlx::FromRow)]
pub(crate) struct MeasurementRow {
    id: StoredUuid,
    seq: i64,
    serial: String,
    dimensions_mm: String,
    measured_by: String,
    measured_at: String,
    measured_ms: i64,
    location: String,
    rattle_space: f64,
    recorded_by: String,
    recorded_ms: i64,
}

impl TryFrom<MeasurementRow> for MeasurementRecord {
    type Error = StoreError;

    fn try_from(row: MeasurementRow) -> Result<Self, StoreError> {
        Ok(MeasurementRecord {
            id: row.id.get()?,
            seq: row.seq,
            serial: row.serial,
            dimensions_mm: parse_json(&row.dimensions_mm, "measurement dimensions")?,
            measured_by: row.measured_by,
            measured_at: row.measured_at,
            measured_ms: row.measured_ms,
            location: row.location,
            rattle_space: row.rattle_space,
            recorded_by: row.recorded_by,
            recorded_ms: row.recorded_ms,
        })
    }
}

/// An `api_tokens` row (the hash is not read back).
#[derive(sqlx::FromRow)]
pub(crate) struct TokenRow {
    id: StoredUuid,
    name: String,
    role: String,
    created_ms: i64,
    revoked_ms: Option<i64>,
}

impl TryFrom<TokenRow> for TokenRecord {
    type Error = StoreError;

    fn try_from(row: TokenRow) -> Result<Self, StoreError> {
        let role = &row.role;
        Ok(TokenRecord {
            id: row.id.get()?,
            name: row.name,
            role: Role::parse(role).ok_or_else(|| corrupt(format!("token role `{role}`")))?,
            created_ms: row.created_ms,
            revoked: row.revoked_ms.is_some(),
        })
    }
}

/// A campaign's summary columns (`CAMPAIGN_SUMMARY`).
#[derive(sqlx::FromRow)]
pub(crate) struct CampaignRow {
    id: StoredUuid,
    seq: i64,
    name: String,
    created_by: String,
    created_ms: i64,
    content_sha256: String,
    content_bytes: i64,
    #[sqlx(flatten)]
    counts: CampaignCounts,
}

impl TryFrom<CampaignRow> for CampaignSummary {
    type Error = StoreError;

    fn try_from(row: CampaignRow) -> Result<Self, StoreError> {
        Ok(CampaignSummary {
            id: row.id.get()?,
            seq: row.seq,
            name: row.name,
            created_by: row.created_by,
            created_ms: row.created_ms,
            content_sha256: row.content_sha256,
            content_bytes: row.content_bytes,
            counts: row.counts,
        })
    }
}

/// A campaign's summary columns and its content.
#[derive(sqlx::FromRow)]
pub(crate) struct CampaignContentRow {
    #[sqlx(flatten)]
    summary: CampaignRow,
    content: String,
}

impl TryFrom<CampaignContentRow> for CampaignRecord {
    type Error = StoreError;

    fn try_from(row: CampaignContentRow) -> Result<Self, StoreError> {
        Ok(CampaignRecord {
            summary: row.summary.try_into()?,
            content: row.content,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A queued top-level job row as both engines store it.
    fn job_row() -> JobRow {
        JobRow {
            seq: 7,
            id: StoredUuid(Ok(Uuid::from_u128(7))),
            kind: "sweep".into(),
            status: "queued".into(),
            params: r#"{"points":3}"#.into(),
            seed: -1,
            code_version: "test".into(),
            submitted_by: "planner".into(),
            attempt: 0,
            cancel_requested: false,
            created_ms: 1_000,
            started_ms: None,
            finished_ms: None,
            progress_simulated_s: None,
            progress_end_s: None,
            progress_fraction: None,
            progress_eta_s: None,
            result: None,
            error: None,
            track_samples: 0,
            curve_key: None,
            lease_owner: None,
            parent_id: None,
            child_index: None,
            children_total: 0,
            children_succeeded: 0,
            children_failed: 0,
            children_cancelled: 0,
        }
    }

    fn corrupt_message(result: Result<JobRecord, StoreError>) -> String {
        match result {
            Err(StoreError::Corrupt(what)) => what,
            other => panic!("expected a corrupt row, got {other:?}"),
        }
    }

    #[test]
    fn a_job_row_reads_back_as_stored() {
        let mut row = job_row();
        row.parent_id = Some(StoredUuid(Ok(Uuid::from_u128(1))));
        row.child_index = Some(2);
        let job = JobRecord::try_from(row).unwrap();
        // The seed is stored as its i64 bit pattern: -1 is u64::MAX.
        assert_eq!(job.seed, u64::MAX);
        assert_eq!(job.kind, JobKind::Sweep);
        assert_eq!(job.params, serde_json::json!({ "points": 3 }));
        assert_eq!(
            job.parent,
            Some(ChildOf {
                parent_id: Uuid::from_u128(1),
                index: 2
            })
        );
        // No children and no complete progress triple: neither is reported.
        assert_eq!(job.children, None);
        assert_eq!(job.progress, None);
    }

    #[test]
    fn a_bad_stored_value_is_a_corrupt_row() {
        let mut row = job_row();
        row.id = StoredUuid(Err("not-a-uuid".into()));
        assert_eq!(corrupt_message(row.try_into()), "bad uuid `not-a-uuid`");
        let mut row = job_row();
        row.status = "exploded".into();
        assert_eq!(corrupt_message(row.try_into()), "job status `exploded`");
        let mut row = job_row();
        row.kind = "teleport".into();
        assert_eq!(corrupt_message(row.try_into()), "job kind `teleport`");
        let mut row = job_row();
        row.result = Some("{".into());
        assert!(corrupt_message(row.try_into()).starts_with("job result: "));
    }

    #[test]
    fn a_page_ends_where_the_fetch_found_no_extra_item() {
        // `limit + 1` fetched: the page keeps `limit` and the cursor is the last kept item.
        let page = cut_page(vec![9, 8, 7, 6], 3, |&seq| seq);
        assert_eq!(page.items, vec![9, 8, 7]);
        assert_eq!(page.next_cursor.as_deref(), Some("7"));
        // Exactly `limit` (or fewer): the last page.
        let page = cut_page(vec![9, 8, 7], 3, |&seq| seq);
        assert_eq!(page.items, vec![9, 8, 7]);
        assert_eq!(page.next_cursor, None);
        let page = cut_page(vec![9], -1, |&seq| seq);
        assert!(page.items.is_empty());
        assert_eq!(page.next_cursor, None);
    }
}
