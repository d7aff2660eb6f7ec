//! Persistence behind one interface, [`Store`], so the SQLite implementation (embedded default)
//! and a PostgreSQL one (issue 6) serve the same code paths. Every method that writes more than
//! one row does it in one transaction; every write by a worker is fenced by the job's attempt.

mod bookkeeping;
mod campaigns;
pub mod clock;
mod delegate;
mod dialect;
mod portable;
pub mod postgres;
mod rail_records;
mod role;
mod rows;
pub mod sqlite;
pub mod tracks;

pub mod job_records;
use crate::physics::track::TrackSample;
pub use campaigns::{CampaignCounts, CampaignInsert, CampaignRecord, CampaignSummary, NewCampaign};
pub use job_records::{ChildCounts, ChildOf};
use job_records::{JobKind, JobProgress, JobRecord, JobStatus};
pub use rail_records::{
    latest_curve, publish_refusal, CurveFidelity, CurveFilter, CurveRecord, MeasurementRecord,
    NewCurve, NewMeasurement, Publication, PublishOutcome, RailRecord,
};
pub use role::Role;
use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;
pub use tracks::TrackBlock;
use uuid::Uuid;

/// Boxed future returned by [`Store`] methods (keeps the trait object-safe).
pub type StoreFuture<'a, T> = Pin<Box<dyn Future<Output = Result<T, StoreError>> + Send + 'a>>;

/// Storage failure. The cause is kept for logs; clients see a generic 500/503.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// The database reported an error.
    #[error("database error: {0}")]
    Database(#[from] sqlx::Error),
    /// Migrations could not be applied.
    #[error("migration error: {0}")]
    Migrate(#[from] sqlx::migrate::MigrateError),
    /// A stored value could not be read back (corrupt row, unknown enum name).
    #[error("corrupt stored data: {0}")]
    Corrupt(String),
    /// The database URL names an engine this build does not support.
    #[error("unsupported database URL `{0}` (expected sqlite://... or postgres://...)")]
    UnsupportedUrl(String),
}

/// A record read as it is stored (no conversion that could fail).
impl From<std::convert::Infallible> for StoreError {
    fn from(never: std::convert::Infallible) -> Self {
        match never {}
    }
}

/// A job to insert.
#[derive(Debug, Clone)]
pub struct NewJob {
    pub id: Uuid,
    pub kind: JobKind,
    pub params: serde_json::Value,
    /// The job's typed plan as canonical JSON, when its kind has one
    /// (`jobs::CaseRunner::submit_plan`): what the worker runs.
    pub plan: Option<serde_json::Value>,
    pub seed: u64,
    pub code_version: String,
    pub submitted_by: String,
    /// Idempotency-Key header and the SHA-256 of the canonical request body.
    pub idempotency: Option<(String, String)>,
    pub curve_key: Option<String>,
    pub created_ms: i64,
}

/// Result of a submission.
#[derive(Debug, Clone)]
pub enum Submitted {
    /// A new job was queued.
    Created(JobRecord),
    /// Same Idempotency-Key and same body as an earlier submission: that job.
    Replayed(JobRecord),
    /// Same Idempotency-Key with a different body: refused; the earlier job's id.
    KeyConflict(Uuid),
}

/// What the heartbeat learned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Heartbeat {
    /// False when this attempt no longer owns the job (lease lost, newer attempt, terminal).
    pub owned: bool,
    /// True when someone asked to cancel the job.
    pub cancel_requested: bool,
}

/// How an attempt ended.
#[derive(Debug, Clone)]
pub enum Finish {
    /// Summary, contact tracks (encoded blocks), SVG plots and, for sweeps, the curve.
    Succeeded {
        summary: serde_json::Value,
        blocks: Vec<TrackBlock>,
        plots: Vec<(String, String)>,
        curve: Option<Box<NewCurve>>,
    },
    Failed(String),
    Cancelled,
}

/// A child job to create when a job fans out. Its index among its siblings is its position in
/// [`FanOut::children`]; seed, code version and submitter are the parent's.
#[derive(Debug, Clone)]
pub struct NewChild {
    pub id: Uuid,
    pub kind: JobKind,
    pub params: serde_json::Value,
    /// The child's typed plan (canonical JSON), as [`NewJob::plan`].
    pub plan: Option<serde_json::Value>,
}

/// A fan-out to store: the children, and the simulated time all of them reach together, s
/// (the parent's progress end time; its progress is the fraction of children that succeeded).
#[derive(Debug, Clone)]
pub struct FanOut {
    pub children: Vec<NewChild>,
    pub end_time_s: f64,
}

/// What [`Store::fan_out`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FanOutResult {
    /// Children created, the parent is waiting for them.
    FannedOut,
    /// This attempt no longer owns the parent: nothing written.
    Stale,
    /// Cancellation was requested before the fan-out: nothing written; end the attempt as
    /// cancelled.
    CancelRequested,
}

/// A child job as its parent's assembly reads it.
#[derive(Debug, Clone, PartialEq)]
pub struct ChildRecord {
    pub id: Uuid,
    pub index: i64,
    pub status: JobStatus,
    pub result: Option<serde_json::Value>,
    pub error: Option<String>,
}

/// How an attempt ended (the attempt log).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AttemptOutcome {
    /// Still running (or its worker died and the lease has not been found expired yet).
    Running,
    Succeeded,
    Failed,
    Cancelled,
    /// The attempt created the job's children and left it waiting for them.
    FannedOut,
    /// The lease expired (or its process was found dead on its host): the worker died or lost
    /// contact; its later writes are fenced out.
    Lost,
    /// Given back by its worker at shutdown: the job went back to the queue at once.
    Released,
}

impl AttemptOutcome {
    /// Name as stored.
    pub fn as_str(self) -> &'static str {
        match self {
            AttemptOutcome::Running => "running",
            AttemptOutcome::Succeeded => "succeeded",
            AttemptOutcome::Failed => "failed",
            AttemptOutcome::Cancelled => "cancelled",
            AttemptOutcome::FannedOut => "fanned_out",
            AttemptOutcome::Lost => "lost",
            AttemptOutcome::Released => "released",
        }
    }

    /// Parse a stored name.
    pub fn parse(text: &str) -> Option<Self> {
        [
            AttemptOutcome::Running,
            AttemptOutcome::Succeeded,
            AttemptOutcome::Failed,
            AttemptOutcome::Cancelled,
            AttemptOutcome::FannedOut,
            AttemptOutcome::Lost,
            AttemptOutcome::Released,
        ]
        .into_iter()
        .find(|o| o.as_str() == text)
    }
}

impl From<JobStatus> for AttemptOutcome {
    /// The outcome of an attempt that ended the job with `status` (succeeded, failed or
    /// cancelled; a job still queued, running or waiting has its attempt running).
    fn from(status: JobStatus) -> Self {
        match status {
            JobStatus::Succeeded => AttemptOutcome::Succeeded,
            JobStatus::Failed => AttemptOutcome::Failed,
            JobStatus::Cancelled => AttemptOutcome::Cancelled,
            JobStatus::Queued | JobStatus::Running | JobStatus::Waiting => AttemptOutcome::Running,
        }
    }
}

/// The error a parent fails with when its child `child` (index `index`) ended with `status`
/// (failed or cancelled), with the child's error if any.
pub fn child_failure_message(
    child: &str,
    index: i64,
    status: JobStatus,
    error: Option<&str>,
) -> String {
    let what = if status == JobStatus::Cancelled {
        "was cancelled".to_string()
    } else {
        format!("failed: {}", error.unwrap_or("no error recorded"))
    };
    format!("child {index} (job {child}) {what}")
}

/// One attempt of a job: written at the claim and at the attempt's end, in the same
/// transactions as the job row, so it shows every write that took effect.
#[derive(Debug, Clone, PartialEq)]
pub struct AttemptRecord {
    pub attempt: i64,
    /// Lease owner: `<host>-<pid>-<n>` for `railwear worker`.
    pub worker: String,
    pub started_ms: i64,
    pub ended_ms: Option<i64>,
    pub outcome: AttemptOutcome,
    /// Simulated time of the checkpoint the attempt stored before it was released, s.
    pub checkpoint_s: Option<f64>,
}

/// A checkpoint to store ([`Store::save_checkpoint`]).
#[derive(Clone, PartialEq)]
pub struct NewCheckpoint {
    /// Simulated time of the checkpoint, s.
    pub simulated_s: f64,
    /// End of the run it belongs to, s.
    pub end_s: f64,
    /// The encoded checkpoint (`models::checkpoint`).
    pub data: Vec<u8>,
}

/// A job's stored checkpoint ([`Store::load_checkpoint`]), read as the row it is.
#[derive(Clone, PartialEq, sqlx::FromRow)]
pub struct JobCheckpoint {
    /// The attempt that stored it.
    pub attempt: i64,
    /// Simulated time of the checkpoint, s.
    pub simulated_s: f64,
    /// End of the run it belongs to, s.
    pub end_s: f64,
    pub created_ms: i64,
    /// The encoded checkpoint.
    pub data: Vec<u8>,
}

impl std::fmt::Debug for NewCheckpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NewCheckpoint")
            .field("simulated_s", &self.simulated_s)
            .field("end_s", &self.end_s)
            .field("bytes", &self.data.len())
            .finish()
    }
}

impl std::fmt::Debug for JobCheckpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JobCheckpoint")
            .field("attempt", &self.attempt)
            .field("simulated_s", &self.simulated_s)
            .field("end_s", &self.end_s)
            .field("created_ms", &self.created_ms)
            .field("bytes", &self.data.len())
            .finish()
    }
}

/// Where a worker process runs, recorded with each claim so that a worker starting on the same
/// host can tell a dead holder's lease from a live one.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WorkerHost {
    /// Host name (`HOSTNAME`, else the kernel's).
    pub host: String,
    /// Process id.
    pub pid: u32,
    /// Random id of this process start (a restarted process may get the same pid, PID 1 in a
    /// container).
    pub instance: String,
}

/// A running job's lease held by a process of some host.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HostLease {
    pub job: Uuid,
    pub attempt: i64,
    pub pid: u32,
    pub instance: String,
}

/// What [`Store::release_job`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReleaseOutcome {
    /// The job is queued again and the attempt logged `released`.
    Released,
    /// Cancellation was requested: nothing written; end the attempt as cancelled.
    CancelRequested,
    /// The attempt no longer owns the job: nothing written.
    Stale,
}

/// Which jobs a list shows.
#[derive(Debug, Clone, Copy, Default)]
pub struct JobFilter {
    /// Only jobs in this status.
    pub status: Option<JobStatus>,
    /// Only the children of this job.
    pub parent: Option<Uuid>,
    /// Only jobs that are not children of another.
    pub top_level: bool,
}

impl Finish {
    /// The status the job ends in.
    pub fn status(&self) -> JobStatus {
        match self {
            Finish::Succeeded { .. } => JobStatus::Succeeded,
            Finish::Failed(_) => JobStatus::Failed,
            Finish::Cancelled => JobStatus::Cancelled,
        }
    }
}

/// One page of a list, newest first.
#[derive(Debug, Clone)]
pub struct Page<T> {
    pub items: Vec<T>,
    /// Pass as `cursor` to get the next page; `None` on the last page.
    pub next_cursor: Option<String>,
}

/// Page request: at most `limit` items after `cursor`.
#[derive(Debug, Clone, Copy)]
pub struct PageRequest {
    pub limit: i64,
    /// Opaque cursor from the previous page: the last seen sequence number.
    pub after_seq: Option<i64>,
}

/// An API token as stored (the secret itself is only kept as its SHA-256).
#[derive(Debug, Clone, PartialEq)]
pub struct TokenRecord {
    pub id: Uuid,
    pub name: String,
    pub role: Role,
    pub created_ms: i64,
    pub revoked: bool,
}

/// The persistence interface. SQLite: [`sqlite::SqliteStore`]; PostgreSQL: [`postgres::PgStore`].
pub trait Store: Send + Sync {
    /// Apply pending migrations.
    fn migrate(&self) -> StoreFuture<'_, ()>;
    /// Cheap round trip (readiness).
    fn ping(&self) -> StoreFuture<'_, ()>;

    /// Insert a job, honouring its idempotency key (one transaction).
    fn submit_job(&self, job: NewJob) -> StoreFuture<'_, Submitted>;
    fn get_job(&self, id: Uuid) -> StoreFuture<'_, Option<JobRecord>>;
    fn list_jobs(&self, page: PageRequest, filter: JobFilter) -> StoreFuture<'_, Page<JobRecord>>;
    /// Atomically take the oldest queued job: status running, attempt + 1, lease until
    /// `now_ms + lease_ms`, and log the attempt. `None` when the queue is empty.
    fn claim_job(
        &self,
        worker: &str,
        now_ms: i64,
        lease_ms: i64,
    ) -> StoreFuture<'_, Option<JobRecord>> {
        self.claim_job_on(worker, None, now_ms, lease_ms)
    }
    /// [`Store::claim_job`], recording the host, pid and instance of the worker's process.
    fn claim_job_on(
        &self,
        worker: &str,
        host: Option<&WorkerHost>,
        now_ms: i64,
        lease_ms: i64,
    ) -> StoreFuture<'_, Option<JobRecord>>;
    /// Running jobs whose lease is held by a process of `host`.
    fn host_leases(&self, host: &str) -> StoreFuture<'_, Vec<HostLease>>;
    /// End the leases of these attempts now (fenced: a job whose attempt moved on is left
    /// alone), so that [`Store::requeue_expired`] re-queues them at once. Returns how many.
    fn expire_leases(&self, attempts: Vec<(Uuid, i64)>, now_ms: i64) -> StoreFuture<'_, u64>;
    /// Give attempt `attempt` back (shutdown): the job is queued again at once (ahead of later
    /// submissions, it keeps its place) and the attempt is logged `released`; a fanned-out
    /// job keeps its children's progress. Fenced by the attempt; refused when cancellation was
    /// requested.
    fn release_job(&self, id: Uuid, attempt: i64, now_ms: i64) -> StoreFuture<'_, ReleaseOutcome>;
    /// Renew the lease of attempt `attempt` and write its progress (fenced).
    fn heartbeat(
        &self,
        id: Uuid,
        attempt: i64,
        progress: Option<JobProgress>,
        now_ms: i64,
        lease_ms: i64,
    ) -> StoreFuture<'_, Heartbeat>;
    /// End attempt `attempt`; returns false (and writes nothing) if that attempt is stale.
    /// For a child job the parent's bookkeeping is part of the same transaction: the child
    /// that completes the set re-queues the parent (to assemble its result, exactly once); a
    /// child that fails or is cancelled fails the parent, naming the child, and cancels its
    /// siblings.
    fn finish_job(
        &self,
        id: Uuid,
        attempt: i64,
        finish: Finish,
        now_ms: i64,
    ) -> StoreFuture<'_, bool>;
    /// Fan attempt `attempt` of a running job out into child jobs, in one transaction fenced by
    /// the attempt: insert the children (queued; unique per parent and index) and move the
    /// parent to waiting. Nothing is written unless the attempt owns the job and no
    /// cancellation was requested.
    fn fan_out(
        &self,
        parent: Uuid,
        attempt: i64,
        fan_out: FanOut,
        now_ms: i64,
    ) -> StoreFuture<'_, FanOutResult>;
    /// The children of a job, by index.
    fn children(&self, parent: Uuid) -> StoreFuture<'_, Vec<ChildRecord>>;
    /// The attempt log of a job, oldest first.
    fn attempts(&self, id: Uuid) -> StoreFuture<'_, Vec<AttemptRecord>>;
    /// Ask a job to stop: a queued or waiting job is cancelled at once (a waiting job's queued
    /// children too, its running ones are flagged), a running one is flagged for its worker.
    /// Terminal jobs are unchanged. `None` if no such job.
    fn request_cancel(&self, id: Uuid, now_ms: i64) -> StoreFuture<'_, Option<JobRecord>>;
    /// Re-queue running jobs whose lease expired (or fail them after `max_attempts`, or cancel
    /// them if cancellation was requested), logging the attempt as lost. A child that ends
    /// this way fails its parent. Returns how many jobs changed.
    fn requeue_expired(&self, now_ms: i64, max_attempts: i64) -> StoreFuture<'_, u64>;
    /// Number of jobs per status.
    fn job_counts(&self) -> StoreFuture<'_, Vec<(JobStatus, i64)>>;
    /// Encoded contact-track blocks of a job, in order.
    fn track_blocks(&self, id: Uuid) -> StoreFuture<'_, Vec<TrackBlock>>;
    /// Names of a job's SVG plots.
    fn plot_names(&self, id: Uuid) -> StoreFuture<'_, Vec<String>>;
    fn plot(&self, id: Uuid, name: &str) -> StoreFuture<'_, Option<String>>;
    /// The newest queued, running or waiting sweep for a curve key.
    fn active_sweep(&self, curve_key: &str) -> StoreFuture<'_, Option<JobRecord>>;

    /// Register the rail if new and insert the measurement (one transaction).
    fn add_measurement(&self, m: NewMeasurement) -> StoreFuture<'_, MeasurementRecord>;
    fn get_rail(&self, serial: &str) -> StoreFuture<'_, Option<RailRecord>>;
    fn list_rails(&self, page: PageRequest) -> StoreFuture<'_, Page<RailRecord>>;
    fn measurements(
        &self,
        serial: &str,
        page: PageRequest,
    ) -> StoreFuture<'_, Page<MeasurementRecord>>;
    /// The measurement with the latest `measured_at` (ties: the last recorded), whatever order
    /// they were recorded in (a back-filled old reading does not become the latest).
    fn latest_measurement(&self, serial: &str) -> StoreFuture<'_, Option<MeasurementRecord>>;
    /// One curve version by id.
    fn get_curve(&self, id: i64) -> StoreFuture<'_, Option<CurveRecord>>;
    /// The published version of a key (what reports use).
    fn published_curve(&self, key: &str) -> StoreFuture<'_, Option<CurveRecord>>;
    /// Curve versions, newest first (cursor: the id).
    fn list_curves(
        &self,
        page: PageRequest,
        filter: CurveFilter,
    ) -> StoreFuture<'_, Page<CurveRecord>>;
    /// Make version `id` the published one of its key, in one transaction that compares it
    /// with the version published now: a lower fidelity is refused unless `force`.
    fn publish_curve(
        &self,
        id: i64,
        published_by: &str,
        force: bool,
        now_ms: i64,
    ) -> StoreFuture<'_, PublishOutcome>;

    /// Store a validated campaign; when one with the same content SHA-256 exists, nothing is
    /// written and that one is returned (also under concurrent uploads of the same content).
    fn insert_campaign(&self, campaign: NewCampaign) -> StoreFuture<'_, CampaignInsert>;
    /// One campaign with its content.
    fn get_campaign(&self, id: Uuid) -> StoreFuture<'_, Option<CampaignRecord>>;
    /// Campaign summaries, newest first (cursor: the upload sequence number).
    fn list_campaigns(&self, page: PageRequest) -> StoreFuture<'_, Page<CampaignSummary>>;

    fn create_token(
        &self,
        name: &str,
        role: Role,
        token_sha256: &str,
        now_ms: i64,
    ) -> StoreFuture<'_, TokenRecord>;
    /// The unrevoked token with this hash.
    fn find_token(&self, token_sha256: &str) -> StoreFuture<'_, Option<TokenRecord>>;
    fn list_tokens(&self) -> StoreFuture<'_, Vec<TokenRecord>>;
    fn revoke_token(&self, id: Uuid, now_ms: i64) -> StoreFuture<'_, bool>;

    // Checkpoints (issue 17, migration 0007).
    /// Store `checkpoint` for job `id` (replacing an older one) only while attempt `attempt`
    /// holds the running lease; in the same transaction the attempt records the checkpoint's
    /// time and the job's progress moves to it. False when the attempt is stale (nothing
    /// written). The checkpoint is deleted when the job ends.
    fn save_checkpoint(
        &self,
        id: Uuid,
        attempt: i64,
        checkpoint: NewCheckpoint,
        now_ms: i64,
    ) -> StoreFuture<'_, bool>;
    /// The job's stored checkpoint, if any.
    fn load_checkpoint(&self, id: Uuid) -> StoreFuture<'_, Option<JobCheckpoint>>;
    /// Store record chunk `seq` of job `id`'s run (migration 0010; replacing one of the same
    /// number) only while attempt `attempt` holds the running lease. False when the attempt
    /// is stale (nothing written). The chunks are deleted when the job ends.
    fn save_record_chunk(
        &self,
        id: Uuid,
        attempt: i64,
        seq: u64,
        data: Vec<u8>,
    ) -> StoreFuture<'_, bool>;
    /// The job's stored record chunks from number 0 on, in order, up to the first gap.
    fn load_record_chunks(&self, id: Uuid) -> StoreFuture<'_, Vec<Vec<u8>>>;
    /// The typed plan stored with the job at submission ([`NewJob::plan`]), if any.
    fn job_plan(&self, id: Uuid) -> StoreFuture<'_, Option<serde_json::Value>>;
}

/// Open the store named by `database_url` and apply migrations.
pub async fn open(database_url: &str) -> Result<Arc<dyn Store>, StoreError> {
    if database_url.starts_with("sqlite:") {
        let store = sqlite::SqliteStore::connect(database_url).await?;
        store.migrate().await?;
        Ok(Arc::new(store))
    } else if database_url.starts_with("postgres:") || database_url.starts_with("postgresql:") {
        let store = postgres::PgStore::connect(database_url).await?;
        store.migrate().await?;
        Ok(Arc::new(store))
    } else {
        Err(StoreError::UnsupportedUrl(database_url.to_string()))
    }
}

/// Decode all of a job's track samples (used by exports and tests).
pub fn decode_tracks(blocks: &[TrackBlock]) -> Result<Vec<TrackSample>, tracks::BlockError> {
    let mut out = Vec::new();
    for block in blocks {
        out.extend(tracks::decode_block(block)?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attempt_outcomes_round_trip_their_stored_names() {
        for outcome in [
            AttemptOutcome::Running,
            AttemptOutcome::Succeeded,
            AttemptOutcome::Failed,
            AttemptOutcome::Cancelled,
            AttemptOutcome::FannedOut,
            AttemptOutcome::Lost,
            AttemptOutcome::Released,
        ] {
            assert_eq!(AttemptOutcome::parse(outcome.as_str()), Some(outcome));
        }
        assert_eq!(AttemptOutcome::parse("done"), None);
    }

    #[test]
    fn a_failed_child_is_named_with_its_error() {
        assert_eq!(
            child_failure_message("c-1", 3, JobStatus::Failed, Some("simulation diverged")),
            "child 3 (job c-1) failed: simulation diverged"
        );
        assert_eq!(
            child_failure_message("c-2", 0, JobStatus::Cancelled, None),
            "child 0 (job c-2) was cancelled"
        );
    }
}
