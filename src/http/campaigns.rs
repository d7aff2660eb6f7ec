//! `/v1/campaigns` (issue 14): test campaigns, the measured wear and accelerometer records of
//! physical tests, stored for the sim-to-real gap diagnosis. A test engineer (or an admin)
//! uploads one as JSON, the same content as the TOML manifest with the samples inline
//! (`railwear campaign check <file> --json` prints it); it is parsed and validated against the
//! service's configs (`gap::Campaign::from_json_str`, `validate`) before anything is stored,
//! and a broken rule is a 422 naming the field (`tests[0].specimens[0].accelerometers[0]
//! .samples[7]` names the sample row). Every role reads campaigns. The stored text is the
//! canonical JSON of the parsed campaign, served unchanged by `GET /v1/campaigns/{id}`.
//!
//! The upload route has its own body limit, `campaign_body_limit_bytes` (default 32 MiB), as
//! samples travel inline.

use super::auth::{Area, Caller};
use super::pagination::{PageQuery, PageView};
use super::problem::{check_json_syntax, json_body_bytes, read_json, Problem};
use super::AppState;
use crate::gap::{Campaign, GapError};
use crate::store::{clock, CampaignCounts, CampaignInsert, CampaignSummary, NewCampaign};
use axum::extract::{Path, Query, State};
use axum::http::{header, HeaderValue, Method, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use utoipa::ToSchema;
use uuid::Uuid;

/// Routes under `/v1/campaigns` (the caller layers the campaign body limit on them).
pub fn router() -> Router<AppState> {
    Router::new()
        .route("/v1/campaigns", get(list_campaigns).post(upload_campaign))
        .route("/v1/campaigns/{id}", get(get_campaign))
        .route("/v1/campaigns/{id}/diagnoses", post(submit_diagnosis))
}

/// A diagnosis request: every field optional, unknown ones refused.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)] // documents the body; the handler reads it as JSON and checks each key
pub struct DiagnosisRequest {
    /// Simulated excitation per increment, s, in [0.05, 600] (default 2).
    pub window_s: Option<f64>,
    /// Settle before each window, s, in [0, 600] (default 0.3).
    pub settle_s: Option<f64>,
    /// Grid points of each dynamics effect, 2..=12 (default 5).
    pub grid_points: Option<u32>,
    /// Library effects to consider (`railwear effects`); default: every effect that applies
    /// to the campaign's models.
    pub effects: Option<Vec<String>>,
    /// Seed (integer in [0, 2^53)); drawn when absent.
    pub seed: Option<u64>,
}

/// What a campaign holds.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct CampaignCountsView {
    pub tests: i64,
    /// Specimens (repeats) over all tests.
    pub specimens: i64,
    /// Increments over all specimens.
    pub increments: i64,
    /// Accelerometer records over all specimens.
    pub accelerometer_records: i64,
}

/// A stored campaign, without its content (`links.self` serves the content).
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct CampaignView {
    pub id: Uuid,
    /// The campaign's `name`.
    pub name: String,
    /// Token name of the uploader.
    pub created_by: String,
    /// RFC 3339 UTC time of the upload.
    pub created_at: String,
    /// SHA-256 (lower-case hex) of the stored canonical JSON, the body of `links.self` (also
    /// its `ETag`). The same content is stored once.
    pub content_sha256: String,
    /// Length of the canonical JSON, bytes.
    pub content_bytes: i64,
    pub counts: CampaignCountsView,
    pub links: CampaignLinks,
}

/// Related resources.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct CampaignLinks {
    /// The campaign's JSON.
    #[serde(rename = "self")]
    pub self_: String,
}

impl From<CampaignSummary> for CampaignView {
    fn from(c: CampaignSummary) -> Self {
        CampaignView {
            links: CampaignLinks {
                self_: format!("/v1/campaigns/{}", c.id),
            },
            id: c.id,
            name: c.name,
            created_by: c.created_by,
            created_at: clock::rfc3339(c.created_ms),
            content_sha256: c.content_sha256,
            content_bytes: c.content_bytes,
            counts: CampaignCountsView {
                tests: c.counts.tests,
                specimens: c.counts.specimens,
                increments: c.counts.increments,
                accelerometer_records: c.counts.accelerometer_records,
            },
        }
    }
}

// The campaign format as an OpenAPI schema. `gap::Campaign` is the format itself; these
// types mirror it for the document only (a unit test checks that they read and write the
// canonical JSON of a campaign unchanged, so the schema cannot drift from the format).

/// A test campaign (format version 1): physical tests with their configuration and their
/// measurements. Units are in the key names. Unknown keys are refused at every level. See
/// docs/reference/campaigns.md.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CampaignDocument {
    /// Format version: 1.
    #[schema(minimum = 1, maximum = 1)]
    pub format_version: u32,
    /// Short identifier (not empty).
    pub name: String,
    /// What was tested, where and when.
    #[serde(default)]
    pub description: String,
    /// Where the data come from (report, lab book, thesis table).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// The physical tests (at least one).
    pub tests: Vec<CampaignTestDocument>,
}

/// One physical test configuration with its repeats.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CampaignTestDocument {
    /// Identifier, unique in the campaign: 1-64 letters, digits, `-` or `_`.
    pub id: String,
    /// Reference config name in the service's configs directory (e.g. `rattle-box-c`).
    pub config: String,
    /// What differs from the reference, in words.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    /// Case keys deep-merged into the config, as a job's `overrides` (e.g. measured
    /// dimensions `{"rattle_box": {"tube_inner_side_m": 0.03181}}`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<Object>)]
    pub overrides: Option<serde_json::Value>,
    /// Rattle space k_rs in (0, 1] (eq. 5.1-5.2), rattle box only: sets the tube inner side
    /// to `cube_side / sqrt(k_rs)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rattle_space: Option<f64>,
    /// Drive profile and level.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive: Option<DriveDocument>,
    /// Excited duration of each increment, s, in (0, 2592000] (30 days).
    pub increment_duration_s: f64,
    /// Resolution of the scale the components were weighed on, mg, in (0, 1000].
    pub scale_resolution_mg: f64,
    /// Weighed components: body names of the model (rattle box: `cube`, `tube`).
    pub components: Vec<String>,
    /// Specimens (repeats of the test), at least one.
    pub specimens: Vec<SpecimenDocument>,
}

/// Drive of a test, replacing parts of the config's excitation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct DriveDocument {
    /// Vibration profile, a file name in `configs/profiles` (without `.toml`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<String>,
    /// Peak acceleration of the single drive tone, g, in (0, 200].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub level_g: Option<f64>,
    /// Frequency of the single drive tone, Hz, in (0, 10000].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency_hz: Option<f64>,
}

/// One specimen (a repeat) of a test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SpecimenDocument {
    /// Identifier, unique in its test: 1-64 letters, digits, `-` or `_`.
    pub id: String,
    /// Increments run on this specimen, in order (at least one).
    pub increments: Vec<IncrementDocument>,
    /// Accelerometer records.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub accelerometers: Vec<AccelRecordDocument>,
}

/// One increment: the mass each weighed component lost over it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct IncrementDocument {
    /// Mass loss per weighed component, mg (finite, >= 0); keys are the test's components.
    #[serde(default)]
    pub mass_loss_mg: BTreeMap<String, f64>,
}

/// Where an accelerometer sat.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum AccelLocationDocument {
    /// On the driven part (shaker table, tube, rail).
    Input,
    /// On the free part (test item, missile).
    Response,
}

/// One accelerometer record of one increment of one specimen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct AccelRecordDocument {
    /// Increment the record was taken in, 1-based.
    pub increment: usize,
    pub location: AccelLocationDocument,
    /// Sample rate, Hz (> 0); every time step must match `1 / sample_rate_hz` within 1 %.
    pub sample_rate_hz: f64,
    /// Sensor noise, RMS, m/s² (>= 0).
    pub sensor_noise_m_s2: f64,
    /// Name of the CSV file the samples came from (provenance only in JSON).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub csv: Option<String>,
    /// Samples, one row each: `[time_s, a_x_m_s2, a_y_m_s2, a_z_m_s2]` (rail frame: x
    /// transverse, y vertical, z longitudinal); at least 2, finite, time strictly increasing.
    /// An error names the row as `samples[<index>]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub samples: Vec<[f64; 4]>,
}

/// The 422 for a campaign that breaks a rule: the field, and for CSV data the row.
fn campaign_problem(e: GapError) -> Problem {
    match e {
        GapError::Field { field, rule } => Problem::invalid_field(field, rule),
        GapError::Csv {
            field,
            file,
            row,
            column,
            rule,
        } => Problem::invalid_field(
            field,
            format!("{file} row {row}, column `{column}`: {rule}"),
        ),
        other => Problem::invalid_field("campaign", other),
    }
}

/// Parse, validate and serialize an uploaded campaign: its canonical JSON and counts.
fn check_campaign(
    bytes: &[u8],
    configs_dir: &std::path::Path,
) -> Result<(Campaign, String), Problem> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        Problem::new(
            StatusCode::BAD_REQUEST,
            "malformed-json",
            "Malformed JSON",
            format!("the body is not UTF-8: {e}"),
        )
    })?;
    let campaign = Campaign::from_json_str(text).map_err(campaign_problem)?;
    campaign.validate(configs_dir).map_err(campaign_problem)?;
    let content = serde_json::to_string(&campaign).map_err(|e| Problem::internal(&e))?;
    Ok((campaign, content))
}

/// Upload a test campaign (test engineer, admin).
///
/// The body is the campaign's JSON form (the TOML manifest's content with each accelerometer
/// record's samples inline). It is validated completely against the service's configs before
/// anything is stored; a broken rule is a 422 whose `field` names it, down to the sample row
/// (`tests[0].specimens[0].accelerometers[0].samples[7]`). Content already stored (same
/// SHA-256 of the canonical JSON) is not stored again: 200 with the stored campaign. Bodies
/// up to `campaign_body_limit_bytes` (default 32 MiB) are accepted; larger ones get 413.
#[utoipa::path(
    post, path = "/v1/campaigns", tag = "campaigns",
    request_body = CampaignDocument,
    responses(
        (status = 201, description = "Stored; `Location` names it", body = CampaignView),
        (status = 200, description = "The same content was stored before: that campaign", body = CampaignView),
        (status = 400, description = "Malformed JSON", body = Problem, content_type = "application/problem+json"),
        (status = 401, body = Problem, content_type = "application/problem+json"),
        (status = 403, description = "Role may not upload campaigns (checked before the body is read)", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "A rule is broken; `field` names it (and the sample row)", body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn upload_campaign(
    State(state): State<AppState>,
    caller: Caller,
    body: axum::extract::Request,
) -> Result<Response, Problem> {
    caller.require(Area::Campaigns, &Method::POST)?;
    let bytes = json_body_bytes(body).await?;
    check_json_syntax(&bytes)?;
    let configs_dir = state.config.configs_dir.clone();
    // Validation builds each test's model: a blocking thread.
    let (campaign, content) =
        tokio::task::spawn_blocking(move || check_campaign(&bytes, &configs_dir))
            .await
            .map_err(|e| Problem::internal(&e))??;
    let (tests, specimens, increments, records) = campaign.counts();
    let count = |n: usize| i64::try_from(n).unwrap_or(i64::MAX);
    let content_sha256 = crate::jobs::hex(&Sha256::digest(content.as_bytes()));
    let inserted = state
        .store
        .insert_campaign(NewCampaign {
            id: Uuid::new_v4(),
            name: campaign.name.clone(),
            created_by: caller.name.clone(),
            created_ms: clock::now_ms(),
            content,
            content_sha256,
            counts: CampaignCounts {
                tests: count(tests),
                specimens: count(specimens),
                increments: count(increments),
                accelerometer_records: count(records),
            },
        })
        .await?;
    let (status, summary) = match inserted {
        CampaignInsert::Created(s) => {
            tracing::info!(campaign = %s.id, name = %s.name, by = %caller.name, bytes = s.content_bytes, "campaign stored");
            (StatusCode::CREATED, s)
        }
        CampaignInsert::Existing(s) => (StatusCode::OK, s),
    };
    let location = format!("/v1/campaigns/{}", summary.id);
    let mut response = (status, Json(CampaignView::from(summary))).into_response();
    if let Ok(value) = HeaderValue::from_str(&location) {
        let name = if status == StatusCode::CREATED {
            header::LOCATION
        } else {
            header::CONTENT_LOCATION
        };
        response.headers_mut().insert(name, value);
    }
    Ok(response)
}

/// Stored campaigns, newest first (summaries; `links.self` serves each campaign).
#[utoipa::path(
    get, path = "/v1/campaigns", tag = "campaigns",
    params(PageQuery),
    responses(
        (status = 200, body = PageView<CampaignView>),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 401, body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn list_campaigns(
    State(state): State<AppState>,
    caller: Caller,
    page: Query<PageQuery>,
) -> Result<Json<PageView<CampaignView>>, Problem> {
    caller.require(Area::Campaigns, &Method::GET)?;
    let page = state.store.list_campaigns(page.to_request()?).await?;
    Ok(Json(PageView::from_page(page, CampaignView::from)))
}

/// One campaign: its JSON as stored (the canonical form of what was uploaded; uploading it
/// again gives the same campaign). `ETag` is its `content_sha256`.
#[utoipa::path(
    get, path = "/v1/campaigns/{id}", tag = "campaigns",
    params(("id" = Uuid, Path, description = "Campaign id")),
    responses(
        (status = 200, body = CampaignDocument, content_type = "application/json"),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 401, body = Problem, content_type = "application/problem+json"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn get_campaign(
    State(state): State<AppState>,
    caller: Caller,
    Path(id): Path<String>,
) -> Result<Response, Problem> {
    caller.require(Area::Campaigns, &Method::GET)?;
    let id = Uuid::parse_str(&id).map_err(|_| Problem::bad_parameter("id", "must be a UUID"))?;
    let record = state
        .store
        .get_campaign(id)
        .await?
        .ok_or_else(|| Problem::not_found(format!("no campaign {id}")))?;
    let mut response =
        ([(header::CONTENT_TYPE, "application/json")], record.content).into_response();
    if let Ok(value) = HeaderValue::from_str(&format!("\"{}\"", record.summary.content_sha256)) {
        response.headers_mut().insert(header::ETAG, value);
    }
    Ok(response)
}

/// Diagnose a stored campaign (test engineer, engineer, admin): queues a `diagnose` job.
///
/// The job simulates the campaign's tests (its progress is the fraction of those simulations
/// done), then locates the sim-to-real gap and ranks the library's effects on held-out tests
/// (docs/results/diagnosis.md). `GET /v1/jobs/{id}` follows it; once it succeeded,
/// `GET /v1/jobs/{id}/result` holds the report as `summary` and lists its SVG figures, served
/// by `GET /v1/jobs/{id}/plots/{name}`. `POST /v1/jobs/{id}/cancel` stops it. The params are
/// checked at submission (a broken rule is a 422 naming the field, e.g. `window_s` or
/// `effects[0]`); `Idempotency-Key` works as for `POST /v1/jobs`.
#[utoipa::path(
    post, path = "/v1/campaigns/{id}/diagnoses", tag = "campaigns",
    params(
        ("id" = Uuid, Path, description = "Campaign id"),
        ("Idempotency-Key" = Option<String>, Header, description = "Makes retries safe: same key + same body = same job. 1 to 255 visible ASCII characters (inner spaces allowed).", pattern = "^[!-~]([ !-~]{0,253}[!-~])?$"),
    ),
    request_body = DiagnosisRequest,
    responses(
        (status = 201, description = "Diagnosis job queued; `Location` names it", body = crate::http::jobs::JobView),
        (status = 200, description = "Replay of an earlier submission with the same Idempotency-Key", body = crate::http::jobs::JobView),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 401, body = Problem, content_type = "application/problem+json"),
        (status = 403, description = "Role may not diagnose (planner)", body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "No such campaign", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "A parameter breaks a rule (`field` names it), or Idempotency-Key reused with a different body", body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn submit_diagnosis(
    State(state): State<AppState>,
    caller: Caller,
    Path(id): Path<String>,
    headers: axum::http::HeaderMap,
    body: axum::extract::Request,
) -> Result<Response, Problem> {
    if !caller.may_diagnose() {
        return Err(Problem::forbidden(format!(
            "role `{}` may not diagnose campaigns",
            caller.role.as_str()
        )));
    }
    let id = Uuid::parse_str(&id).map_err(|_| Problem::bad_parameter("id", "must be a UUID"))?;
    let key = super::jobs::idempotency_key(&headers)?;
    let options: serde_json::Value = read_json(body).await?;
    let record = state
        .store
        .get_campaign(id)
        .await?
        .ok_or_else(|| Problem::not_found(format!("no campaign {id}")))?;
    check_effects_against(&state, &options, &record.content).await?;
    let submitted = state
        .jobs
        .submit_diagnosis(
            id,
            &record.summary.content_sha256,
            options,
            &caller.name,
            key,
        )
        .await
        .map_err(|e| match e {
            crate::jobs::SubmitError::Invalid(e) => Problem::from(e),
            crate::jobs::SubmitError::Store(e) => Problem::from(e),
        })?;
    super::jobs::submitted_response(submitted)
}

/// The effects a diagnosis asks for, against the stored campaign (one rule set with the CLI:
/// `gap::diagnose::check_effects`): each once and applying to every test's model, else a 422
/// naming `effects[i]`. A list that is not one of strings is left to the plan's own check.
async fn check_effects_against(
    state: &AppState,
    options: &serde_json::Value,
    content: &str,
) -> Result<(), Problem> {
    let Some(names) = options
        .get("effects")
        .and_then(serde_json::Value::as_array)
        .and_then(|a| {
            a.iter()
                .map(|v| v.as_str().map(str::to_string))
                .collect::<Option<Vec<String>>>()
        })
    else {
        return Ok(());
    };
    let campaign = Campaign::from_json_str(content).map_err(|e| Problem::internal(&e))?;
    let configs_dir = state.config.configs_dir.clone();
    // Resolving each test's case builds its model: a blocking thread.
    tokio::task::spawn_blocking(move || {
        crate::gap::diagnose::check_effects(&campaign, &names, &configs_dir)
    })
    .await
    .map_err(|e| Problem::internal(&e))?
    .map_err(campaign_problem)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn repo() -> &'static Path {
        Path::new(env!("CARGO_MANIFEST_DIR"))
    }

    /// A campaign with every optional key set, accelerometer records included.
    fn full_campaign() -> Campaign {
        let mut c = Campaign::load(&repo().join("campaigns/thesis-rattle-box.toml"))
            .expect("thesis campaign loads");
        c.source = Some("lab book 7".into());
        let test = &mut c.tests[2];
        test.rattle_space = Some(0.64);
        test.overrides = serde_json::json!({"simulation": {"duration_s": 1.0}});
        test.drive = Some(crate::gap::campaign::DriveSpec {
            profile: None,
            level_g: Some(15.0),
            frequency_hz: Some(20.0),
        });
        let rec: crate::gap::accel::AccelRecord = serde_json::from_value(serde_json::json!({
            "increment": 1, "location": "response", "sample_rate_hz": 1000.0,
            "sensor_noise_m_s2": 0.05, "csv": "c1.csv",
            "samples": [[0.0, 0.1, -0.2, 0.3], [0.001, 0.4, 0.5, -0.6], [0.002, 0.0, 1e-9, 2.5]],
        }))
        .expect("record");
        test.specimens[0].accelerometers.push(rec);
        c
    }

    #[test]
    fn the_schema_types_read_and_write_the_campaign_format_unchanged() {
        for campaign in [
            Campaign::load(&repo().join("campaigns/thesis-rattle-box.toml")).expect("loads"),
            full_campaign(),
        ] {
            let canonical = serde_json::to_value(&campaign).expect("serializes");
            let doc: CampaignDocument =
                serde_json::from_value(canonical.clone()).expect("the schema reads the format");
            assert_eq!(serde_json::to_value(&doc).expect("writes"), canonical);
        }
    }

    #[test]
    fn errors_name_the_field_and_the_csv_row() {
        let p = campaign_problem(GapError::Csv {
            field: "tests[0].specimens[0].accelerometers[0].csv".into(),
            file: "a.csv".into(),
            row: 7,
            column: "time_s".into(),
            rule: "time must increase strictly".into(),
        });
        assert_eq!(p.status, 422);
        assert_eq!(
            p.field.as_deref(),
            Some("tests[0].specimens[0].accelerometers[0].csv")
        );
        assert!(
            p.detail.contains("a.csv row 7, column `time_s`"),
            "{}",
            p.detail
        );
    }

    #[test]
    fn an_uploaded_campaign_is_stored_in_canonical_form() {
        let campaign = full_campaign();
        let compact = serde_json::to_string(&campaign).expect("json");
        let pretty = serde_json::to_string_pretty(&campaign).expect("json");
        let (_, a) = check_campaign(compact.as_bytes(), &repo().join("configs")).expect("valid");
        let (_, b) = check_campaign(pretty.as_bytes(), &repo().join("configs")).expect("valid");
        assert_eq!(a, compact);
        assert_eq!(a, b, "layout does not change the stored text");
    }

    /// The upload is the one validation of a campaign: once, each test's case validated and
    /// its model built once (the model the measurements are checked against).
    #[test]
    fn an_upload_validates_the_campaign_once_and_builds_each_test_once() {
        let campaign = full_campaign();
        let body = serde_json::to_string(&campaign).expect("json");
        crate::models::counts::take();
        crate::models::counts::take_campaign_validations();
        check_campaign(body.as_bytes(), &repo().join("configs")).expect("valid");
        assert_eq!(crate::models::counts::take_campaign_validations(), 1);
        let tests = campaign.tests.len() as u32;
        assert_eq!(
            crate::models::counts::take(),
            (tests, tests),
            "(case validations, builds) for {tests} tests"
        );
    }
}
