//! `/v1/rails`: the rail registry by serial number, measured dimensions -> rattle space at once
//! (eq. 6.1-6.3) and measurement history; the service-life report (K_SL and the penalized life
//! with 0.9/0.8 bands, eq. 6.4, Figure 6.68, or a clear answer saying which sweep to run) is
//! `report`.

mod report;

pub use report::*;

use super::auth::{Area, Caller};
use super::pagination::{PageQuery, PageView};
use super::problem::{read_json, Problem};
use super::AppState;
use crate::analysis::rattle_space::LauncherDimensions;
use crate::store::{clock, MeasurementRecord, NewMeasurement, RailRecord};
use axum::extract::{Path, Query, State};
use axum::http::{HeaderValue, Method, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;
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

/// Measured dimensions of one rail (and its rear shoe) with who, when and where.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct MeasurementRequest {
    /// Rear-shoe and rail dimensions of eq. 6.1-6.2 (thesis Figures 6.29, 6.30), mm, as an
    /// object of named fields (a positional array is refused: its order is not documented).
    /// Checked for assembly: shoe head wider than the rail slot, neck narrower than it, each
    /// value in its plausible range (docs/reference/launcher-dimensions.md).
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
    } else if value.chars().any(char::is_control) {
        Err(Problem::invalid_field(
            field,
            "must not contain control characters (tab, newline, escape, ...)",
        ))
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
    let rattle_space = crate::service_life::rattle_space(&request.dimensions_mm)
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
