//! What a job is: its kind, its lifecycle and its stored record (kept here, with the store;
//! `jobs::model` re-exports it).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// Kind of computation a job runs. The set is open: a new kind is one variant here plus one arm
/// in the production runner.
// Read from text only (`try_from = "String"`): serde_json answers a unit enum given a number
// with a syntax error ("expected value"), which named no field; as text, `{"kind": 1}` is a
// type error at `kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum JobKind {
    /// One case: a model config (by name or inline) with overrides -> wear, tracks, plots.
    Simulate,
    /// A tolerance sweep over rattle space -> rail wear rate versus k_rs -> penalization curve.
    Sweep,
    /// Fit friction and K(sigma) from persistent-contact fixture records (thesis chapter 4).
    Calibrate,
    /// One point of a sweep: a child job the service creates when a sweep fans out (not
    /// submitted directly). Its result is the point's rattle space and rail wear rate.
    SweepPoint,
    /// Gap diagnosis of a stored test campaign (issue 15): submitted through
    /// `POST /v1/campaigns/{id}/diagnoses`, which stores the campaign with the params. Its
    /// result is the diagnosis report; its plots are the report's SVG figures.
    Diagnose,
}

impl JobKind {
    /// Lower-case name as stored and shown.
    pub fn as_str(self) -> &'static str {
        match self {
            JobKind::Simulate => "simulate",
            JobKind::Sweep => "sweep",
            JobKind::Calibrate => "calibrate",
            JobKind::SweepPoint => "sweep_point",
            JobKind::Diagnose => "diagnose",
        }
    }

    /// Parse a stored kind name.
    pub fn parse(text: &str) -> Option<JobKind> {
        match text {
            "simulate" => Some(JobKind::Simulate),
            "sweep" => Some(JobKind::Sweep),
            "calibrate" => Some(JobKind::Calibrate),
            "sweep_point" => Some(JobKind::SweepPoint),
            "diagnose" => Some(JobKind::Diagnose),
            _ => None,
        }
    }
}

impl TryFrom<String> for JobKind {
    type Error = String;

    fn try_from(text: String) -> Result<Self, Self::Error> {
        JobKind::parse(&text).ok_or_else(|| {
            format!(
                "unknown variant `{text}`, expected one of `simulate`, `sweep`, `calibrate`, \
                 `sweep_point`, `diagnose`"
            )
        })
    }
}

/// Lifecycle: queued -> running -> succeeded | failed | cancelled. A running job whose lease
/// expires goes back to queued (next attempt). A job that fans out (a sweep) goes
/// running -> waiting while its child jobs run, then queued -> running once more to assemble
/// its result when the last child has succeeded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum JobStatus {
    Queued,
    Running,
    /// Fanned out: waiting for its child jobs (no worker holds it).
    Waiting,
    Succeeded,
    Failed,
    Cancelled,
}

impl JobStatus {
    /// Lower-case name as stored and shown.
    pub fn as_str(self) -> &'static str {
        match self {
            JobStatus::Queued => "queued",
            JobStatus::Running => "running",
            JobStatus::Waiting => "waiting",
            JobStatus::Succeeded => "succeeded",
            JobStatus::Failed => "failed",
            JobStatus::Cancelled => "cancelled",
        }
    }

    /// Parse a stored status name.
    pub fn parse(text: &str) -> Option<JobStatus> {
        match text {
            "queued" => Some(JobStatus::Queued),
            "running" => Some(JobStatus::Running),
            "waiting" => Some(JobStatus::Waiting),
            "succeeded" => Some(JobStatus::Succeeded),
            "failed" => Some(JobStatus::Failed),
            "cancelled" => Some(JobStatus::Cancelled),
            _ => None,
        }
    }

    /// True for succeeded, failed and cancelled: nothing changes the job any more.
    pub fn is_terminal(self) -> bool {
        matches!(
            self,
            JobStatus::Succeeded | JobStatus::Failed | JobStatus::Cancelled
        )
    }

    /// All statuses, in lifecycle order.
    pub const ALL: [JobStatus; 6] = [
        JobStatus::Queued,
        JobStatus::Running,
        JobStatus::Waiting,
        JobStatus::Succeeded,
        JobStatus::Failed,
        JobStatus::Cancelled,
    ];
}

/// Progress of a running job as stored by its heartbeat.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct JobProgress {
    /// Simulated time reached, s.
    pub simulated_time_s: f64,
    /// Simulated time at which the run ends, s.
    pub end_time_s: f64,
    /// Fraction done in [0, 1].
    pub fraction: f64,
    /// Estimated wall-clock time left, s, from the rate since the attempt started.
    pub eta_s: Option<f64>,
}

/// A job as stored.
#[derive(Debug, Clone, PartialEq)]
pub struct JobRecord {
    pub id: uuid::Uuid,
    /// Submission order (pagination cursor).
    pub seq: i64,
    pub kind: JobKind,
    pub status: JobStatus,
    /// Parameters as submitted (a sweep's `vehicle_profile`, `environment` and `wear_law`
    /// filled in from the defaults when absent).
    pub params: serde_json::Value,
    /// Seed handed to the run (from `params.seed`, or drawn at submission).
    pub seed: u64,
    /// `CARGO_PKG_VERSION` (+ git hash when known at build) of the code that accepted the job.
    pub code_version: String,
    /// Token name of the submitter.
    pub submitted_by: String,
    /// Attempts started so far (fencing token: only the current attempt may write).
    pub attempt: i64,
    /// True once cancellation was requested.
    pub cancel_requested: bool,
    /// Unix times, ms.
    pub created_ms: i64,
    pub started_ms: Option<i64>,
    pub finished_ms: Option<i64>,
    /// Latest progress written by the heartbeat.
    pub progress: Option<JobProgress>,
    /// Result summary (JSON object) once succeeded.
    pub result: Option<serde_json::Value>,
    /// Last error (failed jobs, or attempts lost to dead workers).
    pub error: Option<String>,
    /// Number of stored contact-track samples.
    pub track_samples: i64,
    /// Penalization-curve key (sweeps only): `vehicle_profile/environment/wear_law`.
    pub curve_key: Option<String>,
    /// Worker holding the current attempt's lease (`<host>-<pid>-<n>`), while running.
    pub lease_owner: Option<String>,
    /// Child jobs: the job that fanned out, and this child's index among its siblings (for a
    /// sweep, the point index, tight to loose).
    pub parent: Option<ChildOf>,
    /// Jobs that fanned out: how their children stand.
    pub children: Option<ChildCounts>,
}

/// Where a child job sits in its parent's fan-out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChildOf {
    pub parent_id: uuid::Uuid,
    pub index: i64,
}

/// Children of a job that fanned out, by how they ended (the rest are queued or running).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
pub struct ChildCounts {
    /// Child jobs created by the fan-out.
    pub total: i64,
    pub succeeded: i64,
    /// Failed after their bounded retries (the first such failure fails the parent).
    pub failed: i64,
    /// Cancelled (with the parent, or one by one).
    pub cancelled: i64,
}
