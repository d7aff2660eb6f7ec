//! `/v1/rails`: the rail registry by serial number, measured dimensions -> rattle space at once
//! (eq. 6.1-6.3), measurement history, and the service-life report: K_SL and the penalized life
//! with 0.9/0.8 bands (eq. 6.4, Figure 6.68) from the matching penalization curve, or a clear
//! answer saying which sweep to run.

use super::auth::{Area, Caller};
use super::pagination::{PageQuery, PageView};
use super::problem::{read_json, Problem};
use super::AppState;
use crate::analysis::penalization::PenalizationCurve;
use crate::analysis::rattle_space::LauncherDimensions;
use crate::jobs::{curve_key, JobStatus};
use crate::store::{
    clock, CurveFilter, CurveRecord, MeasurementRecord, NewMeasurement, RailRecord,
};
use axum::extract::{Path, Query, State};
use axum::http::{HeaderValue, Method, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};
use uuid::Uuid;

pub fn router() -> Router<AppState> {
    Router::new()
        .route("/v1/rails", get(list_rails))
        .route("/v1/rails/{serial}", get(get_rail))
        .route(
            "/v1/rails/{serial}/measurements",
            post(post_measurement).get(list_measurements),
        )
        .route("/v1/rails/{serial}/report", get(get_report))
}

/// The analysis library behind one seam: rattle space from measured dimensions and the
/// penalization of service life by a sweep's curve.
pub mod seam {
    use crate::analysis::penalization::PenalizationCurve;
    use crate::analysis::rattle_space::{LauncherDimensions, RattleSpaceError};
    use crate::field_error::FieldError;

    /// Rattle space k_rs (eq. 6.1-6.3) of measured dimensions, or the field at fault and why.
    pub fn rattle_space(dimensions: &LauncherDimensions) -> Result<f64, FieldError> {
        dimensions
            .rattle_space()
            .map_err(|RattleSpaceError::InvalidDimension(e)| e)
    }

    /// K_SL at `k_rs` and its 0.9/0.8 bands (eq. 6.4), or why the curve does not cover it.
    pub fn penalize(curve: &PenalizationCurve, k_rs: f64) -> Result<(f64, f64, f64), String> {
        let f = curve.factors(k_rs).map_err(|e| e.to_string())?;
        Ok((f.k_sl, f.k_sl_conservative_90, f.k_sl_conservative_80))
    }

    /// K_SL's confidence interval over the curve's seeds at `k_rs` (None for one seed).
    pub fn interval(
        curve: &PenalizationCurve,
        k_rs: f64,
    ) -> Option<crate::analysis::penalization::KslInterval> {
        curve.k_sl_interval(k_rs).ok().flatten()
    }

    /// [k_rs, K_SL] at the swept rattle spaces (for the plot).
    pub fn samples(curve: &PenalizationCurve) -> Vec<[f64; 2]> {
        curve
            .points()
            .iter()
            .filter_map(|p| curve.k_sl(p.rattle_space).ok().map(|k| [p.rattle_space, k]))
            .collect()
    }
}

/// One point of the sweep behind a report.
#[derive(Debug, Serialize, ToSchema)]
pub struct CurvePointView {
    /// Rattle space k_rs (eq. 6.3), dimensionless.
    pub rattle_space: f64,
    /// Simulated rail wear rate there, mg/h.
    pub rail_wear_rate_mg_per_h: f64,
}

/// Measured dimensions of one rail (and its rear shoe) with who, when and where.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct MeasurementRequest {
    /// Rear-shoe and rail dimensions of eq. 6.1-6.2 (thesis Figures 6.29, 6.30), mm, as an
    /// object of named fields (a positional array is refused: its order is not documented).
    /// Checked for assembly: shoe head wider than the rail slot, neck narrower than it, each
    /// value in its plausible range (docs/launcher-dimensions.md).
    #[serde(deserialize_with = "named_dimensions")]
    pub dimensions_mm: LauncherDimensions,
    /// Who measured (name or badge), 1-200 characters.
    pub measured_by: String,
    /// When, ISO 8601 date (2024-05-01) or RFC 3339 date-time (2024-05-01T08:30:00Z): a day
    /// that exists, from 1970 on and not in the future. The report uses the measurement with
    /// the latest `measured_at`, whatever order they were recorded in.
    pub measured_at: String,
    /// Where (depot, vehicle, station), 1-200 characters.
    pub location: String,
}

/// `dimensions_mm` as an object of named fields only: serde would also read the struct from a
/// positional array of 14 numbers, whose order is nowhere documented for users.
fn named_dimensions<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> Result<LauncherDimensions, D::Error> {
    struct Named;
    impl<'de> serde::de::Visitor<'de> for Named {
        type Value = LauncherDimensions;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str(
                "an object of named dimensions in mm ({\"a_shoe_mm\": 38.1, ..., \"q_rail_mm\": \
                 10.13}), not a positional array",
            )
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
            LauncherDimensions::deserialize(serde::de::value::MapAccessDeserializer::new(map))
        }
    }
    deserializer.deserialize_map(Named)
}

/// Earliest accepted `measured_at`: 1970-01-01 (before any Hellfire-class rail was made; an
/// earlier date is a typing error).
pub const EARLIEST_MEASURED_MS: i64 = 0;
/// How far `measured_at` may lie ahead of the server clock: 14 h, the furthest time zone ahead
/// of UTC (a date alone is read as midnight UTC, so a local "today" may be ahead of it).
pub const FUTURE_ALLOWANCE_MS: i64 = 14 * 3_600_000;

/// `measured_at` as Unix ms, or the rule it breaks.
fn check_measured_at(text: &str, now_ms: i64) -> Result<i64, Problem> {
    let ms = clock::parse_iso8601_ms(text).ok_or_else(|| {
        Problem::invalid_field(
            "measured_at",
            "must be an ISO 8601 date (2024-05-01) or RFC 3339 date-time \
             (2024-05-01T08:30:00Z) naming a day that exists",
        )
    })?;
    if ms < EARLIEST_MEASURED_MS {
        return Err(Problem::invalid_field(
            "measured_at",
            "must not be before 1970-01-01",
        ));
    }
    if ms > now_ms + FUTURE_ALLOWANCE_MS {
        return Err(Problem::invalid_field(
            "measured_at",
            format!(
                "must not be in the future (server time {})",
                clock::rfc3339(now_ms)
            ),
        ));
    }
    Ok(ms)
}

/// A stored measurement.
#[derive(Debug, Serialize, ToSchema)]
pub struct MeasurementView {
    pub id: Uuid,
    pub serial: String,
    /// Dimensions as posted, mm.
    #[schema(value_type = Object)]
    pub dimensions_mm: serde_json::Value,
    pub measured_by: String,
    /// When the rail was measured, as posted.
    pub measured_at: String,
    pub location: String,
    /// Rattle space k_rs = A_ti / A_encl (eq. 6.1-6.3), dimensionless.
    pub rattle_space: f64,
    /// Token name of who recorded it.
    pub recorded_by: String,
    /// When the service recorded it (RFC 3339 UTC); history is listed in this order.
    pub recorded_at: String,
    /// The rail's report.
    pub report_url: String,
}

impl From<MeasurementRecord> for MeasurementView {
    fn from(m: MeasurementRecord) -> Self {
        MeasurementView {
            report_url: format!("/v1/rails/{}/report", m.serial),
            id: m.id,
            serial: m.serial,
            dimensions_mm: m.dimensions_mm,
            measured_by: m.measured_by,
            measured_at: m.measured_at,
            location: m.location,
            rattle_space: m.rattle_space,
            recorded_by: m.recorded_by,
            recorded_at: clock::rfc3339(m.recorded_ms),
        }
    }
}

/// A registered rail.
#[derive(Debug, Serialize, ToSchema)]
pub struct RailView {
    pub serial: String,
    pub registered_at: String,
    /// Number of measurements on record.
    pub measurements: i64,
    pub report_url: String,
}

impl From<RailRecord> for RailView {
    fn from(r: RailRecord) -> Self {
        RailView {
            report_url: format!("/v1/rails/{}/report", r.serial),
            serial: r.serial,
            registered_at: clock::rfc3339(r.created_ms),
            measurements: r.measurements,
        }
    }
}

/// Service life penalized for this rail's rattle space (eq. 6.4).
#[derive(Debug, Serialize, ToSchema)]
pub struct ServiceLife {
    /// K_SL = min(1, rail wear rate at design / rail wear rate at this k_rs), dimensionless.
    pub k_sl: f64,
    /// Conservative bands 0.9*K_SL and 0.8*K_SL (Figure 6.68).
    pub k_sl_band_90: f64,
    pub k_sl_band_80: f64,
    /// T_SL,design, h.
    pub design_life_h: f64,
    /// T_SL,real = K_SL * T_SL,design, h; and with the 0.9/0.8 bands.
    pub penalized_life_h: f64,
    pub penalized_life_band_90_h: f64,
    pub penalized_life_band_80_h: f64,
    /// K_SL and penalized life 90 % confidence interval over the curve's seeds; null when
    /// the curve has one seed per point (`uncertainty` says so).
    pub interval: Option<ServiceLifeInterval>,
    /// How the interval was computed, or why there is none.
    pub uncertainty: String,
}

/// Confidence interval of K_SL and the penalized life over the sweep's seeds: a t-interval at
/// 90 % of the per-seed log ratio `ln rate_j(design) - ln rate_j(k_rs)` (seeds paired, as each
/// seed drives every point), mapped through `min(1, exp(.))`. It covers seed-to-seed scatter of
/// the simulated wear only, not model error.
#[derive(Debug, Serialize, ToSchema)]
pub struct ServiceLifeInterval {
    /// Two-sided confidence level, 0.9.
    pub confidence: f64,
    /// Seeds per point (n); the t quantile has n - 1 degrees of freedom.
    pub seeds: usize,
    /// t(0.95; n - 1).
    pub t_quantile: f64,
    pub k_sl_low: f64,
    pub k_sl_high: f64,
    /// k_sl_low and k_sl_high times the design life, h.
    pub penalized_life_low_h: f64,
    pub penalized_life_high_h: f64,
}

/// The curve version a report used: which one and how much simulation stands behind it.
#[derive(Debug, Serialize, ToSchema)]
pub struct ReportCurve {
    /// Curve id (`/v1/curves/{id}`).
    pub id: i64,
    /// Version of its key (1, 2, ...).
    pub version: i64,
    pub curve_key: String,
    /// The sweep job that produced it.
    pub job_id: Uuid,
    pub fidelity: super::curves::FidelityView,
    /// Swept rattle-space range [min, max].
    pub rattle_space_range: [f64; 2],
    pub created_by: String,
    pub code_version: String,
    pub published_by: Option<String>,
    pub published_at: Option<String>,
    pub url: String,
}

/// Why no service life could be given, and what to do about it.
#[derive(Debug, Serialize, ToSchema)]
pub struct MissingCurve {
    /// `vehicle_profile/environment/wear_law`.
    pub curve_key: String,
    /// In words: what is missing and what to do.
    pub detail: String,
    /// The sweep already queued, running or waiting for this key whose range covers this
    /// rail, if any.
    pub sweep_job_id: Option<Uuid>,
    pub sweep_job_status: Option<JobStatus>,
    /// A stored but unpublished curve version that covers this rail: an engineer publishes it
    /// (`POST /v1/curves/{id}/publish`).
    pub unpublished_curve_id: Option<i64>,
    /// The job request an engineer should submit (POST /v1/jobs) when none is under way: a
    /// sweep whose rattle-space range covers this rail and the design point (the published
    /// curve's sweep, widened), then publish its curve.
    #[schema(value_type = Option<Object>)]
    pub suggested_job: Option<serde_json::Value>,
}

/// A rail's service-life report.
#[derive(Debug, Serialize, ToSchema)]
pub struct ReportView {
    pub serial: String,
    /// The measurement the report is based on: the latest `measured_at` (ties: the last
    /// recorded), not the last one recorded.
    pub measurement: MeasurementView,
    /// Rattle space k_rs of that measurement, dimensionless.
    pub rattle_space: f64,
    /// Key of the penalization curve used.
    pub curve_key: String,
    /// The published curve version the report used (id, version, fidelity), if any.
    pub curve: Option<ReportCurve>,
    /// The sweep job that produced the curve.
    pub curve_job_id: Option<Uuid>,
    /// Rattle space of the design rail (K_SL = 1 there).
    pub design_rattle_space: Option<f64>,
    /// The sweep's points: rail wear rate versus rattle space.
    pub curve_points: Vec<CurvePointView>,
    /// K_SL at the swept rattle spaces, for plotting: [k_rs, K_SL] pairs.
    pub k_sl_curve: Vec<[f64; 2]>,
    /// Present when a curve covers this rattle space.
    pub service_life: Option<ServiceLife>,
    /// Present when no curve covers it.
    pub missing_curve: Option<MissingCurve>,
}

/// Which penalization curve and design life a report uses (defaults from the settings'
/// `[report]`). The three labels must name what a sweep can run: an unknown one is a 422
/// naming the parameter (it could never have a curve). Unknown parameters are refused (400).
#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct ReportQuery {
    /// Vehicle profile of the curve: `ah64` or a profile file name in `configs/profiles`.
    pub vehicle_profile: Option<String>,
    /// Environment of the curve: `clean` (the only one modelled).
    pub environment: Option<String>,
    /// Wear law of the curve: `modified-archard`, `archard` or `legacy-appendix`.
    pub wear_law: Option<String>,
    /// T_SL,design, h (> 0).
    #[param(value_type = Option<f64>, exclusive_minimum = 0)]
    pub design_life_h: Option<String>,
}

/// The curve labels of a report query, defaults filled in; a label given but unknown is a 422
/// naming its parameter (the same names a sweep accepts, `pipeline::SweepPlan`).
fn report_labels(
    query: &ReportQuery,
    defaults: &crate::config::service::ReportSettings,
    configs_dir: &std::path::Path,
) -> Result<(String, String, String), Problem> {
    if let Some(profile) = &query.vehicle_profile {
        crate::pipeline::vehicle_profile_file(configs_dir, profile).map_err(|e| match e {
            crate::pipeline::RunError::InvalidConfig { rule, .. } => {
                Problem::invalid_field("vehicle_profile", rule)
            }
            other => Problem::invalid_field("vehicle_profile", other),
        })?;
    }
    if let Some(environment) = &query.environment {
        if !crate::pipeline::ENVIRONMENTS.contains(&environment.as_str()) {
            return Err(Problem::invalid_field(
                "environment",
                format!(
                    "`{environment}` is not modelled (known: {})",
                    crate::pipeline::ENVIRONMENTS.join(", ")
                ),
            ));
        }
    }
    if let Some(law) = &query.wear_law {
        if !crate::pipeline::WEAR_LAWS.contains(&law.as_str()) {
            return Err(Problem::invalid_field(
                "wear_law",
                format!(
                    "`{law}` is not a wear law (known: {})",
                    crate::pipeline::WEAR_LAWS.join(", ")
                ),
            ));
        }
    }
    Ok((
        query
            .vehicle_profile
            .clone()
            .unwrap_or_else(|| defaults.vehicle_profile.clone()),
        query
            .environment
            .clone()
            .unwrap_or_else(|| defaults.environment.clone()),
        query
            .wear_law
            .clone()
            .unwrap_or_else(|| defaults.wear_law.clone()),
    ))
}

/// Pattern of a rail serial: a letter or digit, then up to 63 letters, digits, `-`, `_` or
/// `.`. Starting with a letter or digit rules out `.` and `..`, which a URL path would resolve
/// away (their report URL was unreachable).
pub const SERIAL_PATTERN: &str = "^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$";

/// True when `serial` matches [`SERIAL_PATTERN`].
pub fn is_valid_serial(serial: &str) -> bool {
    let mut chars = serial.chars();
    serial.len() <= 64
        && chars.next().is_some_and(|c| c.is_ascii_alphanumeric())
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
}

fn check_serial(serial: &str) -> Result<(), Problem> {
    if is_valid_serial(serial) {
        Ok(())
    } else {
        Err(Problem::bad_parameter(
            "serial",
            format!(
                "must match {SERIAL_PATTERN}: 1-64 characters, letters, digits, '-', '_' or '.', \
                 starting with a letter or digit"
            ),
        ))
    }
}

fn check_text(field: &str, value: &str) -> Result<String, Problem> {
    let value = value.trim();
    if value.is_empty() || value.chars().count() > 200 {
        Err(Problem::invalid_field(field, "must be 1 to 200 characters"))
    } else {
        Ok(value.to_string())
    }
}

/// Record a measurement; the rail is registered on its first one. Answers with the rattle space
/// at once.
#[utoipa::path(
    post, path = "/v1/rails/{serial}/measurements", tag = "rails",
    params(("serial" = String, Path, description = "Rail serial number: a letter or digit, then up to 63 letters, digits, '-', '_' or '.'", pattern = "^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$")),
    request_body = MeasurementRequest,
    responses(
        (status = 201, body = MeasurementView),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 403, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "A dimension is missing, negative, not finite, implausible (unit mistake) or makes the shoe interfere with the rail; `field` names it", body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn post_measurement(
    State(state): State<AppState>,
    caller: Caller,
    Path(serial): Path<String>,
    body: axum::extract::Request,
) -> Result<Response, Problem> {
    caller.require(Area::Rails, &Method::POST)?;
    check_serial(&serial)?;
    let request: MeasurementRequest = read_json(body).await?;
    let measured_by = check_text("measured_by", &request.measured_by)?;
    let location = check_text("location", &request.location)?;
    let measured_at = request.measured_at.trim().to_string();
    let recorded_ms = clock::now_ms();
    let measured_ms = check_measured_at(&measured_at, recorded_ms)?;
    let rattle_space = seam::rattle_space(&request.dimensions_mm)
        .map_err(|e| Problem::from(e.at("dimensions_mm")))?;
    let dimensions_mm =
        serde_json::to_value(request.dimensions_mm).map_err(|e| Problem::internal(&e))?;
    let record = state
        .store
        .add_measurement(NewMeasurement {
            id: Uuid::new_v4(),
            serial,
            dimensions_mm,
            measured_by,
            measured_at,
            measured_ms,
            location,
            rattle_space,
            recorded_by: caller.name,
            recorded_ms,
        })
        .await?;
    let location_header = format!("/v1/rails/{}/measurements", record.serial);
    let mut response = (StatusCode::CREATED, Json(MeasurementView::from(record))).into_response();
    if let Ok(value) = HeaderValue::from_str(&location_header) {
        response
            .headers_mut()
            .insert(axum::http::header::LOCATION, value);
    }
    Ok(response)
}

/// List registered rails, newest first.
#[utoipa::path(
    get, path = "/v1/rails", tag = "rails",
    params(PageQuery),
    responses((status = 200, body = PageView<RailView>), (status = 400, body = Problem, content_type = "application/problem+json")),
    security(("bearer" = []))
)]
pub async fn list_rails(
    State(state): State<AppState>,
    caller: Caller,
    page: Query<PageQuery>,
) -> Result<Json<PageView<RailView>>, Problem> {
    caller.require(Area::Rails, &Method::GET)?;
    let page = state.store.list_rails(page.to_request()?).await?;
    Ok(Json(PageView::from_page(page, RailView::from)))
}

async fn load_rail(state: &AppState, serial: &str) -> Result<RailRecord, Problem> {
    check_serial(serial)?;
    state
        .store
        .get_rail(serial)
        .await?
        .ok_or_else(|| Problem::not_found(format!("no rail with serial `{serial}`")))
}

/// One rail.
#[utoipa::path(
    get, path = "/v1/rails/{serial}", tag = "rails",
    params(("serial" = String, Path, pattern = "^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$")),
    responses((status = 200, body = RailView), (status = 404, body = Problem, content_type = "application/problem+json")),
    security(("bearer" = []))
)]
pub async fn get_rail(
    State(state): State<AppState>,
    caller: Caller,
    Path(serial): Path<String>,
) -> Result<Json<RailView>, Problem> {
    caller.require(Area::Rails, &Method::GET)?;
    Ok(Json(load_rail(&state, &serial).await?.into()))
}

/// A rail's measurement history, newest recorded first; each shows when it was measured
/// (`measured_at`) and when it was recorded (`recorded_at`).
#[utoipa::path(
    get, path = "/v1/rails/{serial}/measurements", tag = "rails",
    params(("serial" = String, Path, pattern = "^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$"), PageQuery),
    responses((status = 200, body = PageView<MeasurementView>), (status = 404, body = Problem, content_type = "application/problem+json")),
    security(("bearer" = []))
)]
pub async fn list_measurements(
    State(state): State<AppState>,
    caller: Caller,
    Path(serial): Path<String>,
    page: Query<PageQuery>,
) -> Result<Json<PageView<MeasurementView>>, Problem> {
    caller.require(Area::Rails, &Method::GET)?;
    let request = page.to_request()?;
    load_rail(&state, &serial).await?;
    let page = state.store.measurements(&serial, request).await?;
    Ok(Json(PageView::from_page(page, MeasurementView::from)))
}

/// The rail's service-life report from its latest measurement (latest `measured_at`).
#[utoipa::path(
    get, path = "/v1/rails/{serial}/report", tag = "rails",
    params(("serial" = String, Path, pattern = "^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$"), ReportQuery),
    responses(
        (status = 200, description = "Report; `service_life` when a curve covers the rail, otherwise `missing_curve` says which sweep to run", body = ReportView),
        (status = 400, description = "Malformed serial or design_life_h, unknown or repeated parameter", body = Problem, content_type = "application/problem+json"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "vehicle_profile, environment or wear_law names nothing a sweep can run; `field` is the parameter", body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn get_report(
    State(state): State<AppState>,
    caller: Caller,
    Path(serial): Path<String>,
    query: Result<Query<ReportQuery>, axum::extract::rejection::QueryRejection>,
) -> Result<Json<ReportView>, Problem> {
    caller.require(Area::Rails, &Method::GET)?;
    // A repeated or unknown key is named by serde_urlencoded's message.
    let Query(query) = query.map_err(|rejection| {
        super::problem::bare_error_problem(StatusCode::BAD_REQUEST, &rejection.body_text())
    })?;
    let defaults = &state.config.report;
    let design_life_h = match &query.design_life_h {
        None => defaults.design_life_h,
        Some(text) => text
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|h| h.is_finite() && *h > 0.0)
            .ok_or_else(|| {
                Problem::bad_parameter("design_life_h", "must be a positive number of hours")
            })?,
    };
    let (profile, environment, wear_law) =
        report_labels(&query, defaults, &state.config.configs_dir)?;
    load_rail(&state, &serial).await?;
    let measurement = state
        .store
        .latest_measurement(&serial)
        .await?
        .ok_or_else(|| Problem::not_found(format!("rail `{serial}` has no measurement")))?;
    let key = curve_key(&profile, &environment, &wear_law);
    let k_rs = measurement.rattle_space;

    let rail_dims: Option<LauncherDimensions> =
        serde_json::from_value(measurement.dimensions_mm.clone()).ok();
    let mut report = ReportView {
        serial: serial.clone(),
        measurement: measurement.into(),
        rattle_space: k_rs,
        curve_key: key.clone(),
        curve: None,
        curve_job_id: None,
        design_rattle_space: None,
        curve_points: Vec::new(),
        k_sl_curve: Vec::new(),
        service_life: None,
        missing_curve: None,
    };
    let read = |c: &CurveRecord| {
        serde_json::from_value::<PenalizationCurve>(c.curve.clone())
            .map_err(|e| tracing::warn!(curve = c.id, error = %e, "unreadable stored curve"))
            .ok()
    };
    let published = state.store.published_curve(&key).await?;
    let published_data = published.as_ref().and_then(read);
    let mut why = format!("no published penalization curve for {key}");
    if let (Some(stored), Some(data)) = (&published, &published_data) {
        let (lo, hi) = data.range();
        report.curve = Some(ReportCurve {
            id: stored.id,
            version: stored.version,
            curve_key: stored.key.clone(),
            job_id: stored.job_id,
            fidelity: super::curves::FidelityView {
                points: stored.fidelity.points,
                duration_per_point_s: stored.fidelity.duration_per_point_s,
                seeds: stored.fidelity.seeds,
            },
            rattle_space_range: [lo, hi],
            created_by: stored.created_by.clone(),
            code_version: stored.code_version.clone(),
            published_by: stored.published.as_ref().map(|p| p.published_by.clone()),
            published_at: stored
                .published
                .as_ref()
                .map(|p| clock::rfc3339(p.published_ms)),
            url: format!("/v1/curves/{}", stored.id),
        });
        report.curve_job_id = Some(stored.job_id);
        report.design_rattle_space = Some(data.design_rattle_space());
        report.k_sl_curve = seam::samples(data);
        report.curve_points = data
            .points()
            .iter()
            .map(|p| CurvePointView {
                rattle_space: p.rattle_space,
                rail_wear_rate_mg_per_h: p.rail_wear_rate_mg_per_h,
            })
            .collect();
        match seam::penalize(data, k_rs) {
            Ok((k_sl, band_90, band_80)) => {
                let interval = seam::interval(data, k_rs);
                let uncertainty = match &interval {
                    Some(i) => format!(
                        "90 % t-interval over {} seeds per point (t = {:.4}, {} degrees of \
                         freedom) of the paired log ratio of wear rates; seed-to-seed scatter \
                         of the simulation only, not model error",
                        i.seeds,
                        i.t_quantile,
                        i.seeds - 1
                    ),
                    None => "no interval: the curve has one seed per point; publish a sweep \
                             with seeds >= 3 for one"
                        .to_string(),
                };
                report.service_life = Some(ServiceLife {
                    k_sl,
                    k_sl_band_90: band_90,
                    k_sl_band_80: band_80,
                    design_life_h,
                    penalized_life_h: k_sl * design_life_h,
                    penalized_life_band_90_h: band_90 * design_life_h,
                    penalized_life_band_80_h: band_80 * design_life_h,
                    interval: interval.map(|i| ServiceLifeInterval {
                        confidence: i.confidence,
                        seeds: i.seeds,
                        t_quantile: i.t_quantile,
                        k_sl_low: i.k_sl_low,
                        k_sl_high: i.k_sl_high,
                        penalized_life_low_h: i.k_sl_low * design_life_h,
                        penalized_life_high_h: i.k_sl_high * design_life_h,
                    }),
                    uncertainty,
                });
                return Ok(Json(report));
            }
            Err(reason) => {
                why = format!(
                    "the published penalization curve {key} (curve {} version {}, sweep job {}) \
                     does not cover rattle space {k_rs:.4}: {reason}",
                    stored.id, stored.version, stored.job_id
                );
            }
        }
    }
    // No published curve covers the rail: a sweep under way that will, a stored version that
    // does (publish it), or the sweep to run.
    let covers = |bounds: (f64, f64)| bounds.0 <= k_rs && k_rs <= bounds.1;
    let active = state.store.active_sweep(&key).await?;
    let active_covers = active.as_ref().is_some_and(|job| {
        crate::pipeline::SweepRange::from_params(&job.params)
            .map(|r| covers(r.rattle_space_bounds()))
            .unwrap_or(true)
    });
    let mut unpublished = None;
    let versions = state
        .store
        .list_curves(
            crate::store::PageRequest {
                limit: 50,
                after_seq: None,
            },
            CurveFilter {
                key: Some(key.clone()),
            },
        )
        .await?;
    for c in &versions.items {
        if c.published.is_none() && read(c).is_some_and(|d| covers(d.range())) {
            unpublished = Some(c);
            break;
        }
    }
    let template = match &published {
        Some(p) => state
            .store
            .get_job(p.job_id)
            .await?
            .map(|job| job.params)
            .unwrap_or_default(),
        None => serde_json::Value::Null,
    };
    let template = if template.is_object() {
        template
    } else {
        serde_json::json!({"config": "launcher-design"})
    };
    let mut template = template;
    if let Some(map) = template.as_object_mut() {
        map.insert("vehicle_profile".into(), profile.clone().into());
        map.insert("environment".into(), environment.clone().into());
        map.insert("wear_law".into(), wear_law.clone().into());
    }
    let suggested = crate::pipeline::covering_sweep_params(&template, k_rs, rail_dims.as_ref())
        .map(|params| serde_json::json!({"kind": "sweep", "params": params}));
    report.missing_curve = Some(match (active, unpublished) {
        (Some(job), _) if active_covers => MissingCurve {
            curve_key: key.clone(),
            detail: format!(
                "{why}; sweep job {} covering it is {}: once it succeeds an engineer publishes \
                 its curve and the report includes K_SL",
                job.id,
                job.status.as_str()
            ),
            sweep_job_id: Some(job.id),
            sweep_job_status: Some(job.status),
            unpublished_curve_id: None,
            suggested_job: None,
        },
        (_, Some(c)) => MissingCurve {
            curve_key: key.clone(),
            detail: format!(
                "{why}; curve {} (version {}, sweep job {}) covers it but is not published: an \
                 engineer publishes it with POST /v1/curves/{}/publish",
                c.id, c.version, c.job_id, c.id
            ),
            sweep_job_id: None,
            sweep_job_status: None,
            unpublished_curve_id: Some(c.id),
            suggested_job: None,
        },
        _ => MissingCurve {
            curve_key: key.clone(),
            detail: match &suggested {
                Some(_) => format!(
                    "{why}: an engineer runs the suggested sweep (POST /v1/jobs with the \
                     suggested_job body; its rattle_space_range covers {k_rs:.4} and the design \
                     point) and publishes its curve"
                ),
                None => format!(
                    "{why}, and no tolerance sweep reaches rattle space {k_rs:.4} from the \
                     design rail or this rail's dimensions as a valid rail"
                ),
            },
            sweep_job_id: None,
            sweep_job_status: None,
            unpublished_curve_id: None,
            suggested_job: suggested,
        },
    });
    Ok(Json(report))
}
