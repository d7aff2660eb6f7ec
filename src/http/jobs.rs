//! `/v1/jobs`: submit (with Idempotency-Key), list, inspect, cancel; results, tracks, plots.

use super::auth::{Area, Caller};
use super::pagination::{PageQuery, PageView};
use super::problem::{read_json, Problem};
use super::AppState;
use crate::jobs::{ChildCounts, JobKind, JobProgress, JobRecord, JobStatus, SubmitError};
use crate::physics::track::TrackSample;
use crate::store::{clock, tracks, AttemptRecord, Submitted};
use axum::extract::{Path, Query, State};
use axum::http::{header, HeaderMap, HeaderValue, Method, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};
use uuid::Uuid;

/// Routes under `/v1/jobs`.
pub fn router() -> Router<AppState> {
    Router::new()
        .route("/v1/jobs", post(submit_job).get(list_jobs))
        .route("/v1/jobs/{id}", get(get_job))
        .route("/v1/jobs/{id}/cancel", post(cancel_job))
        .route("/v1/jobs/{id}/attempts", get(get_attempts))
        .route("/v1/jobs/{id}/result", get(get_result))
        .route("/v1/jobs/{id}/tracks", get(get_tracks))
        .route("/v1/jobs/{id}/plots/{name}", get(get_plot))
}

/// A job submission.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct JobRequest {
    /// What to run.
    pub kind: JobKind,
    /// Kind-specific parameters (JSON object), checked completely at submission (a broken
    /// rule is a 422 naming the field, e.g. `params.overrides.simulation.duration_s`, and
    /// nothing is stored); the worker runs them through the same parser. Unknown keys are
    /// refused at every level.
    /// `simulate`: `{"config": "<reference name>" or {inline config}, "overrides": {...},
    /// "seed": n}`; `config` is required, `overrides` must be an object that deep-merges into
    /// the config. Bounds: `simulation.duration_s` in (0, 86400] s (24 h), `settle_s` in [0,
    /// 600] s, `rel_tolerance` in [1e-10, 0.1], `abs_tolerance_m` in [1e-15, 1e-4] m,
    /// `record_interval_s` in [1e-6 s, duration_s] and at most 1e7 recorded time points.
    /// `seed` is an integer in [0, 2^53), drawn at submission (also below 2^53) when absent.
    /// `sweep` takes the same keys (config default `launcher-design`; it must be a launcher
    /// case) plus `points` (2..=50, default 5), `vehicle_profile` (selects the excitation:
    /// `ah64` or a profile in `configs/profiles`), `environment` (`clean`) and `wear_law`
    /// (`modified-archard`, `archard` or `legacy-appendix`, matching the config's wear law;
    /// or `{"diagnosis": "<diagnose job id>"}`: the wear-law effect a succeeded diagnosis
    /// explained the gap with, added to the config's law, curve name `diagnosis-<id>`);
    /// the three default to the service's `[report]` settings and form the penalization-curve
    /// key. A sweep fans out into one `sweep_point` child job per point (`sweep_point` jobs
    /// cannot be submitted). `calibrate`: `{"friction": {"fixture": {...}, "records":
    /// [...]}}` and/or `{"wear_law": {"density_kg_m3", "cutoff_pressure_pa", "records"}}`.
    /// `diagnose` jobs are submitted with `POST /v1/campaigns/{id}/diagnoses`, not here.
    #[schema(value_type = Object)]
    pub params: serde_json::Value,
}

/// A job as shown by the API.
#[derive(Debug, Serialize, Deserialize, ToSchema)]
pub struct JobView {
    pub id: Uuid,
    pub kind: JobKind,
    pub status: JobStatus,
    /// Parameters as submitted (a sweep's `vehicle_profile`, `environment` and `wear_law`
    /// filled in from the defaults when absent, and a `wear_law` diagnosis resolved to its
    /// effect, fitted parameters and verdict; a diagnosis adds `campaign_id` and
    /// `campaign_sha256`, the content it reads from the store when it runs).
    #[schema(value_type = Object)]
    pub params: serde_json::Value,
    /// Seed the run uses (from `params.seed` or drawn at submission).
    pub seed: u64,
    /// Version of the code that accepted the job (`x.y.z` or `x.y.z+githash`).
    pub code_version: String,
    /// Token name of the submitter.
    pub submitted_by: String,
    /// Attempts started (more than 1 when a worker died and the job was re-run).
    pub attempt: i64,
    /// True once cancellation was requested.
    pub cancel_requested: bool,
    /// RFC 3339 UTC times.
    pub created_at: String,
    pub started_at: Option<String>,
    pub finished_at: Option<String>,
    /// Progress of the running attempt (simulated time, fraction, ETA).
    pub progress: Option<JobProgress>,
    /// Why the job failed (or the last lost attempt).
    pub error: Option<String>,
    /// Stored contact-track samples.
    pub track_samples: i64,
    /// Sweeps: the penalization-curve key `vehicle_profile/environment/wear_law`.
    pub curve_key: Option<String>,
    /// Worker holding the running attempt (`<host>-<pid>-<n>` for `railwear worker`).
    pub worker: Option<String>,
    /// Child jobs (a sweep's `sweep_point` jobs): the job that fanned out.
    pub parent_id: Option<Uuid>,
    /// Child jobs: index among the siblings (a sweep's point, tight to loose).
    pub child_index: Option<i64>,
    /// Jobs that fanned out (sweeps): how their children stand. The job waits while they run,
    /// its progress is the fraction that succeeded, and its result is assembled once all have.
    pub children: Option<ChildCounts>,
    /// Related URLs: `self`, `result`, `tracks_csv`, `tracks_json`, `cancel`, `attempts`, and
    /// `children` for a job that fanned out.
    pub links: JobLinks,
}

/// One attempt of a job, from the attempt log: which worker ran it, when, and how it ended.
/// Written in the same transactions as the job row, so it shows every claim and every end that
/// took effect (a lost attempt is one whose lease expired; the job was re-queued).
#[derive(Debug, Serialize, ToSchema)]
pub struct AttemptView {
    /// Attempt number, from 1 (the job's `attempt` is the latest).
    pub attempt: i64,
    /// Lease owner: `<host>-<pid>-<n>` for a `railwear worker` or a service worker.
    pub worker: String,
    /// RFC 3339 UTC time of the claim.
    pub started_at: String,
    /// RFC 3339 UTC time the attempt ended; absent while it runs.
    pub ended_at: Option<String>,
    /// `running`, `succeeded`, `failed`, `cancelled`, `fanned_out` (made the job's children
    /// and left it waiting for them), `lost` (lease expired, or its process was found dead by
    /// a worker starting on the same host) or `released` (given back to the queue when its
    /// worker shut down).
    pub outcome: String,
    /// Simulated time, s, of the checkpoint a `released` attempt stored before giving its job
    /// back: the next attempt resumes from it. Absent when the attempt stored none (it did not
    /// stop within the shutdown grace, or its computation cannot checkpoint).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub checkpoint_s: Option<f64>,
}

impl From<AttemptRecord> for AttemptView {
    fn from(a: AttemptRecord) -> Self {
        AttemptView {
            attempt: a.attempt,
            worker: a.worker,
            started_at: clock::rfc3339(a.started_ms),
            ended_at: a.ended_ms.map(clock::rfc3339),
            outcome: a.outcome.as_str().to_string(),
            checkpoint_s: a.checkpoint_s,
        }
    }
}

/// URLs of a job's resources.
#[derive(Debug, Serialize, Deserialize, ToSchema)]
pub struct JobLinks {
    #[serde(rename = "self")]
    pub self_: String,
    pub cancel: String,
    pub result: String,
    pub tracks_csv: String,
    pub tracks_json: String,
    /// The attempt log (`/v1/jobs/<id>/attempts`).
    pub attempts: String,
    /// The job's children (`/v1/jobs?parent=<id>`), for a job that fanned out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub children: Option<String>,
}

impl From<JobRecord> for JobView {
    fn from(j: JobRecord) -> Self {
        let base = format!("/v1/jobs/{}", j.id);
        JobView {
            id: j.id,
            kind: j.kind,
            status: j.status,
            params: j.params,
            seed: j.seed,
            code_version: j.code_version,
            submitted_by: j.submitted_by,
            attempt: j.attempt,
            cancel_requested: j.cancel_requested,
            created_at: clock::rfc3339(j.created_ms),
            started_at: j.started_ms.map(clock::rfc3339),
            finished_at: j.finished_ms.map(clock::rfc3339),
            progress: j.progress,
            error: j.error,
            track_samples: j.track_samples,
            curve_key: j.curve_key,
            worker: j.lease_owner,
            parent_id: j.parent.map(|p| p.parent_id),
            child_index: j.parent.map(|p| p.index),
            children: j.children,
            links: JobLinks {
                cancel: format!("{base}/cancel"),
                result: format!("{base}/result"),
                tracks_csv: format!("{base}/tracks?format=csv"),
                tracks_json: format!("{base}/tracks?format=json"),
                attempts: format!("{base}/attempts"),
                children: j
                    .children
                    .map(|_| format!("/v1/jobs?parent={}&limit=100", j.id)),
                self_: base,
            },
        }
    }
}

/// A finished job's results.
#[derive(Debug, Serialize, ToSchema)]
pub struct JobResultView {
    pub id: Uuid,
    pub kind: JobKind,
    pub seed: u64,
    pub code_version: String,
    /// Summary: wear per contact and body, pressure PDFs, spectra, settings used.
    #[schema(value_type = Object)]
    pub summary: serde_json::Value,
    /// Stored contact-track samples.
    pub track_samples: i64,
    /// SVG plots, by name, with their URLs.
    pub plots: Vec<PlotLink>,
}

/// A plot of a job.
#[derive(Debug, Serialize, ToSchema)]
pub struct PlotLink {
    pub name: String,
    pub url: String,
}

/// Filter for the job list (kept as text so a bad value gets a problem naming it).
#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct JobFilter {
    /// Only jobs in this status.
    #[param(value_type = Option<JobStatus>)]
    pub status: Option<String>,
    /// Only the children of this job (a sweep's points).
    #[param(value_type = Option<Uuid>)]
    pub parent: Option<String>,
    /// `true`: only jobs that are not children of another (what was submitted).
    #[param(value_type = Option<bool>)]
    pub top_level: Option<String>,
}

impl JobFilter {
    fn to_filter(&self) -> Result<crate::store::JobFilter, Problem> {
        let status = match &self.status {
            None => None,
            Some(text) => Some(JobStatus::parse(text).ok_or_else(|| {
                Problem::bad_parameter(
                    "status",
                    "must be queued, running, waiting, succeeded, failed or cancelled",
                )
            })?),
        };
        let parent = match &self.parent {
            None => None,
            Some(text) => Some(
                Uuid::parse_str(text)
                    .map_err(|_| Problem::bad_parameter("parent", "must be a job id (UUID)"))?,
            ),
        };
        let top_level = match self.top_level.as_deref() {
            None | Some("false") => false,
            Some("true") => true,
            Some(_) => return Err(Problem::bad_parameter("top_level", "must be true or false")),
        };
        Ok(crate::store::JobFilter {
            status,
            parent,
            top_level,
        })
    }
}

/// Track export options.
#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct TrackQuery {
    /// `csv` (default) or `json`.
    #[param(pattern = "^(csv|json)$")]
    pub format: Option<String>,
    /// Keep every N-th sample (downsampling), N >= 1; default 1.
    #[param(minimum = 1)]
    pub every: Option<u64>,
}

fn parse_id(text: &str) -> Result<Uuid, Problem> {
    Uuid::parse_str(text).map_err(|_| Problem::bad_parameter("id", "must be a UUID"))
}

async fn load_job(state: &AppState, id: &str) -> Result<JobRecord, Problem> {
    let id = parse_id(id)?;
    state
        .store
        .get_job(id)
        .await?
        .ok_or_else(|| Problem::not_found(format!("no job {id}")))
}

pub(super) fn idempotency_key(headers: &HeaderMap) -> Result<Option<String>, Problem> {
    if headers.get_all("idempotency-key").iter().nth(1).is_some() {
        return Err(Problem::bad_parameter(
            "Idempotency-Key",
            "must be given once (two headers name two different retries)",
        ));
    }
    match headers.get("idempotency-key") {
        None => Ok(None),
        Some(value) => {
            let key = value
                .to_str()
                .ok()
                .map(str::trim)
                .filter(|k| !k.is_empty() && k.len() <= 255)
                .ok_or_else(|| {
                    Problem::bad_parameter(
                        "Idempotency-Key",
                        "must be 1 to 255 visible ASCII characters",
                    )
                })?;
            Ok(Some(key.to_string()))
        }
    }
}

/// Submit a job.
///
/// With an `Idempotency-Key` header, repeating the same request returns the job created by the
/// first one (200, header `Idempotent-Replayed: true`); the same key with a different body is
/// refused with 422.
#[utoipa::path(
    post, path = "/v1/jobs", tag = "jobs",
    request_body = JobRequest,
    params(("Idempotency-Key" = Option<String>, Header, description = "Makes retries safe: same key + same body = same job. 1 to 255 visible ASCII characters (inner spaces allowed).", pattern = "^[!-~]([ !-~]{0,253}[!-~])?$")),
    responses(
        (status = 201, description = "Job queued", body = JobView),
        (status = 200, description = "Replay of an earlier submission with the same Idempotency-Key", body = JobView),
        (status = 401, body = Problem, content_type = "application/problem+json"),
        (status = 403, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Invalid field, or Idempotency-Key reused with a different body", body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn submit_job(
    State(state): State<AppState>,
    caller: Caller,
    headers: HeaderMap,
    body: axum::extract::Request,
) -> Result<Response, Problem> {
    caller.require(Area::Jobs, &Method::POST)?;
    let request: JobRequest = read_json(body).await?;
    let key = idempotency_key(&headers)?;
    let submitted = state
        .jobs
        .submit(request.kind, request.params, &caller.name, key)
        .await
        .map_err(|e| match e {
            SubmitError::Invalid(e) => Problem::from(e),
            SubmitError::Store(e) => Problem::from(e),
        })?;
    submitted_response(submitted)
}

/// The response to a submission: 201 with the job and `Location`, 200 for a replay, 422 for an
/// Idempotency-Key reused with another body.
pub(super) fn submitted_response(submitted: Submitted) -> Result<Response, Problem> {
    match submitted {
        Submitted::Created(job) => {
            let location = format!("/v1/jobs/{}", job.id);
            let mut response = (StatusCode::CREATED, Json(JobView::from(job))).into_response();
            if let Ok(value) = HeaderValue::from_str(&location) {
                response.headers_mut().insert(header::LOCATION, value);
            }
            Ok(response)
        }
        Submitted::Replayed(job) => {
            let mut response = (StatusCode::OK, Json(JobView::from(job))).into_response();
            response
                .headers_mut()
                .insert("idempotent-replayed", HeaderValue::from_static("true"));
            Ok(response)
        }
        Submitted::KeyConflict(existing) => {
            let mut p = Problem::new(
                StatusCode::UNPROCESSABLE_ENTITY,
                "idempotency-key-reused",
                "Idempotency-Key reused",
                format!(
                    "this Idempotency-Key was used for job {existing} with a different body; use a new key"
                ),
            );
            p.field = Some("Idempotency-Key".into());
            Err(p)
        }
    }
}

/// List jobs, newest first. `parent=<id>` lists the children of a sweep (one `sweep_point`
/// job per point); `top_level=true` leaves children out.
#[utoipa::path(
    get, path = "/v1/jobs", tag = "jobs",
    params(PageQuery, JobFilter),
    responses(
        (status = 200, body = PageView<JobView>),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 401, body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn list_jobs(
    State(state): State<AppState>,
    caller: Caller,
    page: Query<PageQuery>,
    filter: Result<Query<JobFilter>, axum::extract::rejection::QueryRejection>,
) -> Result<Json<PageView<JobView>>, Problem> {
    caller.require(Area::Jobs, &Method::GET)?;
    let Query(filter) =
        filter.map_err(|_| Problem::bad_parameter("query", "must be status, parent, top_level"))?;
    let filter = filter.to_filter()?;
    let request = page.to_request()?;
    let mut page = state.store.list_jobs(request, filter).await?;
    // Sweeps waiting for their points show the points' combined progress (few at a time).
    let now_ms = crate::store::clock::now_ms();
    for job in &mut page.items {
        if let Some(progress) =
            crate::jobs::family::live_parent_progress(state.store.as_ref(), job, now_ms).await?
        {
            job.progress = Some(progress);
        }
    }
    Ok(Json(PageView::from_page(page, JobView::from)))
}

/// One job with its status and progress. A sweep waiting for its points shows their
/// combined progress: the mean of their fractions and an ETA at the rate so far.
#[utoipa::path(
    get, path = "/v1/jobs/{id}", tag = "jobs",
    params(("id" = Uuid, Path)),
    responses(
        (status = 200, body = JobView),
        (status = 404, body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn get_job(
    State(state): State<AppState>,
    caller: Caller,
    Path(id): Path<String>,
) -> Result<Json<JobView>, Problem> {
    caller.require(Area::Jobs, &Method::GET)?;
    let mut job = load_job(&state, &id).await?;
    // A parent waiting for its children shows their progress, not only their successes.
    let now_ms = crate::store::clock::now_ms();
    if let Some(progress) =
        crate::jobs::family::live_parent_progress(state.store.as_ref(), &job, now_ms).await?
    {
        job.progress = Some(progress);
    }
    Ok(Json(job.into()))
}

/// The job's attempt log, oldest first: every claim by a worker and how it ended. A job that
/// was never claimed has none; a job re-run after its worker died shows the lost attempt.
#[utoipa::path(
    get, path = "/v1/jobs/{id}/attempts", tag = "jobs",
    params(("id" = Uuid, Path)),
    responses(
        (status = 200, body = Vec<AttemptView>),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn get_attempts(
    State(state): State<AppState>,
    caller: Caller,
    Path(id): Path<String>,
) -> Result<Json<Vec<AttemptView>>, Problem> {
    caller.require(Area::Jobs, &Method::GET)?;
    let job = load_job(&state, &id).await?;
    let attempts = state.store.attempts(job.id).await?;
    Ok(Json(attempts.into_iter().map(AttemptView::from).collect()))
}

/// Cancel a job: a queued job is cancelled at once, a running one stops within a second.
/// Cancelling a finished job changes nothing. Engineers and admins may cancel any job; every
/// caller may cancel the jobs it started (a test engineer's diagnosis).
#[utoipa::path(
    post, path = "/v1/jobs/{id}/cancel", tag = "jobs",
    params(("id" = Uuid, Path)),
    responses(
        (status = 202, description = "Cancellation requested (or the job had already finished)", body = JobView),
        (status = 404, body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn cancel_job(
    State(state): State<AppState>,
    caller: Caller,
    Path(id): Path<String>,
) -> Result<(StatusCode, Json<JobView>), Problem> {
    let id = parse_id(&id)?;
    if !caller.allowed(Area::Jobs, &Method::POST) {
        // Whoever started a job may cancel it (a test engineer's diagnosis), whatever the
        // role's other rights.
        let job = load_job(&state, &id.to_string()).await?;
        if job.submitted_by != caller.name {
            return Err(Problem::forbidden(format!(
                "role `{}` may cancel only the jobs its token started; job {id} was started \
                 by `{}`",
                caller.role.as_str(),
                job.submitted_by
            )));
        }
    }
    let job = state
        .jobs
        .cancel(id)
        .await?
        .ok_or_else(|| Problem::not_found(format!("no job {id}")))?;
    Ok((StatusCode::ACCEPTED, Json(job.into())))
}

fn require_succeeded(job: &JobRecord) -> Result<(), Problem> {
    if job.status == JobStatus::Succeeded {
        Ok(())
    } else {
        Err(Problem::conflict(
            "job-not-succeeded",
            "Job has no results",
            format!(
                "job {} is {}; results exist once it has succeeded{}",
                job.id,
                job.status.as_str(),
                job.error
                    .as_deref()
                    .map(|e| format!(" (error: {e})"))
                    .unwrap_or_default()
            ),
        ))
    }
}

/// Results of a succeeded job: summary and plot links.
#[utoipa::path(
    get, path = "/v1/jobs/{id}/result", tag = "jobs",
    params(("id" = Uuid, Path)),
    responses(
        (status = 200, body = JobResultView),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 409, description = "The job has not succeeded", body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn get_result(
    State(state): State<AppState>,
    caller: Caller,
    Path(id): Path<String>,
) -> Result<Json<JobResultView>, Problem> {
    caller.require(Area::Jobs, &Method::GET)?;
    let job = load_job(&state, &id).await?;
    require_succeeded(&job)?;
    let names = state.store.plot_names(job.id).await?;
    Ok(Json(JobResultView {
        id: job.id,
        kind: job.kind,
        seed: job.seed,
        code_version: job.code_version,
        summary: job.result.unwrap_or(serde_json::Value::Null),
        track_samples: job.track_samples,
        plots: names
            .into_iter()
            .map(|name| PlotLink {
                url: format!("/v1/jobs/{}/plots/{name}", job.id),
                name,
            })
            .collect(),
    }))
}

/// Contact tracks of a succeeded job as CSV (header row with units) or JSON (array of samples),
/// optionally downsampled to every N-th sample.
#[utoipa::path(
    get, path = "/v1/jobs/{id}/tracks", tag = "jobs",
    params(("id" = Uuid, Path), TrackQuery),
    responses(
        (status = 200, description = "CSV (text/csv) or JSON array of track samples", content_type = "text/csv"),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 409, body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn get_tracks(
    State(state): State<AppState>,
    caller: Caller,
    Path(id): Path<String>,
    query: Result<Query<TrackQuery>, axum::extract::rejection::QueryRejection>,
) -> Result<Response, Problem> {
    caller.require(Area::Jobs, &Method::GET)?;
    // A repeated or unknown key is named by serde_urlencoded's message; a bad value is `every`'s
    // (`format` is a string, checked below).
    let Query(query) = query.map_err(|rejection| {
        let text = rejection.body_text();
        if text.contains("duplicate field") || text.contains("unknown field") {
            crate::http::problem::bare_error_problem(StatusCode::BAD_REQUEST, &text)
        } else {
            Problem::bad_parameter("every", "must be a positive integer")
        }
    })?;
    let every = query.every.unwrap_or(1);
    if every == 0 {
        return Err(Problem::bad_parameter(
            "every",
            "must be a positive integer",
        ));
    }
    let csv = match query.format.as_deref() {
        None | Some("csv") => true,
        Some("json") => false,
        Some(_) => return Err(Problem::bad_parameter("format", "must be csv or json")),
    };
    let job = load_job(&state, &id).await?;
    require_succeeded(&job)?;
    let blocks = state.store.track_blocks(job.id).await?;
    let body = tokio::task::spawn_blocking(
        move || -> Result<String, Box<dyn std::error::Error + Send + Sync>> {
            let mut index: u64 = 0;
            let mut keep: Vec<TrackSample> = Vec::new();
            for block in &blocks {
                for sample in tracks::decode_block(block)? {
                    if index % every == 0 {
                        keep.push(sample);
                    }
                    index += 1;
                }
            }
            if csv {
                let mut out = Vec::new();
                TrackSample::write_csv(&keep, &mut out)?;
                Ok(String::from_utf8(out)?)
            } else {
                Ok(serde_json::to_string(&keep).unwrap_or_else(|_| "[]".into()))
            }
        },
    )
    .await
    .map_err(|e| Problem::internal(&e))?
    .map_err(|e| Problem::internal(&e))?;
    let content_type = if csv {
        "text/csv; charset=utf-8"
    } else {
        "application/json"
    };
    Ok(([(header::CONTENT_TYPE, content_type)], body).into_response())
}

/// One SVG plot of a succeeded job.
#[utoipa::path(
    get, path = "/v1/jobs/{id}/plots/{name}", tag = "jobs",
    params(("id" = Uuid, Path), ("name" = String, Path)),
    responses(
        (status = 200, description = "SVG image", content_type = "image/svg+xml"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn get_plot(
    State(state): State<AppState>,
    caller: Caller,
    Path((id, name)): Path<(String, String)>,
) -> Result<Response, Problem> {
    caller.require(Area::Jobs, &Method::GET)?;
    let id = parse_id(&id)?;
    let svg = state
        .store
        .plot(id, &name)
        .await?
        .ok_or_else(|| Problem::not_found(format!("job {id} has no plot `{name}`")))?;
    Ok(([(header::CONTENT_TYPE, "image/svg+xml")], svg).into_response())
}
