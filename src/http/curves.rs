//! `/v1/curves`: penalization curve versions with provenance and fidelity. A successful sweep
//! stores a new version of its key (`vehicle_profile/environment/wear_law`); reports use the
//! version an engineer published (`POST /v1/curves/{id}/publish`). Publishing a version with
//! fewer points, a shorter duration per point or fewer seeds than the published one, or swept
//! on the contact-point lattice over one swept with the exact face contact, needs
//! `{"force": true}`, else 409; so does publishing a version whose points ran shorter than the
//! excited window (`simulation.duration_s`) of the reference config it swept.

use super::auth::{Area, Caller};
use super::pagination::{PageQuery, PageView};
use super::problem::{read_json, Problem};
use super::AppState;
use crate::store::{clock, CurveFilter, CurveRecord, PublishOutcome};
use axum::extract::{Path, Query, State};
use axum::http::{header, Method, StatusCode};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};
use uuid::Uuid;

pub fn router() -> Router<AppState> {
    Router::new()
        .route("/v1/curves", get(list_curves))
        .route("/v1/curves/{id}", get(get_curve))
        .route("/v1/curves/{id}/publish", post(publish_curve))
}

/// How much simulation stands behind a curve.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct FidelityView {
    /// Points of the sweep (distinct rattle spaces).
    pub points: i64,
    /// Excited simulated duration of each run, s; null for curves stored before versions
    /// existed (not recorded).
    pub duration_per_point_s: Option<f64>,
    /// Seeds (independent runs) per point; K_SL has a confidence interval from 2 on.
    pub seeds: i64,
}

/// A penalization curve version.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct CurveView {
    /// Id (`/v1/curves/{id}`).
    pub id: i64,
    /// `vehicle_profile/environment/wear_law`.
    pub curve_key: String,
    /// 1, 2, ... per key, in the order sweeps stored them.
    pub version: i64,
    /// The sweep job that produced it.
    pub job_id: Uuid,
    pub fidelity: FidelityView,
    /// Swept rattle-space range [min, max].
    pub rattle_space_range: Option<[f64; 2]>,
    /// Config, vehicle_profile, environment, wear_law, points, duration_per_point_s, seeds,
    /// range, offsets, base dimensions, face_contact (with the lattice its
    /// contact_points_per_edge; absent on curves swept before it was recorded), code_version,
    /// created_by.
    #[schema(value_type = Object)]
    pub provenance: serde_json::Value,
    /// Token name of who submitted the sweep.
    pub created_by: String,
    pub code_version: String,
    pub created_at: String,
    /// True while reports use this version.
    pub published: bool,
    pub published_by: Option<String>,
    pub published_at: Option<String>,
    /// The curve: design rattle space, points (rail wear rate vs k_rs, geometric mean over
    /// seeds) and the rate of each seed.
    #[schema(value_type = Object)]
    pub curve: serde_json::Value,
    pub links: CurveLinks,
}

/// Related resources.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct CurveLinks {
    #[serde(rename = "self")]
    pub self_: String,
    pub publish: String,
    pub job: String,
}

impl From<CurveRecord> for CurveView {
    fn from(c: CurveRecord) -> Self {
        let range = <crate::analysis::penalization::PenalizationCurve as Deserialize>::deserialize(
            &c.curve,
        )
        .ok()
        .map(|curve| {
            let (a, b) = curve.range();
            [a, b]
        });
        CurveView {
            links: CurveLinks {
                self_: format!("/v1/curves/{}", c.id),
                publish: format!("/v1/curves/{}/publish", c.id),
                job: format!("/v1/jobs/{}", c.job_id),
            },
            id: c.id,
            curve_key: c.key,
            version: c.version,
            job_id: c.job_id,
            fidelity: FidelityView {
                points: c.fidelity.points,
                duration_per_point_s: c.fidelity.duration_per_point_s,
                seeds: c.fidelity.seeds,
            },
            rattle_space_range: range,
            provenance: c.provenance,
            created_by: c.created_by,
            code_version: c.code_version,
            created_at: clock::rfc3339(c.created_ms),
            published: c.published.is_some(),
            published_by: c.published.as_ref().map(|p| p.published_by.clone()),
            published_at: c.published.as_ref().map(|p| clock::rfc3339(p.published_ms)),
            curve: c.curve,
        }
    }
}

/// Which curves to list.
#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct CurveQuery {
    /// Only versions of this key, `vehicle_profile/environment/wear_law`.
    pub curve_key: Option<String>,
}

/// Publish options.
#[derive(Debug, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct PublishRequest {
    /// Publish even when this version has a lower fidelity (fewer points, shorter duration per
    /// point, fewer seeds, or the contact-point lattice against the exact face contact) than
    /// the published one. Default false.
    #[serde(default)]
    pub force: bool,
}

fn parse_id(text: &str) -> Result<i64, Problem> {
    text.parse::<i64>()
        .ok()
        .filter(|id| *id > 0)
        .ok_or_else(|| Problem::bad_parameter("id", "must be a positive integer curve id"))
}

/// Curve versions, newest first.
#[utoipa::path(
    get, path = "/v1/curves", tag = "curves",
    params(CurveQuery, PageQuery),
    responses((status = 200, body = PageView<CurveView>), (status = 400, body = Problem, content_type = "application/problem+json")),
    security(("bearer" = []))
)]
pub async fn list_curves(
    State(state): State<AppState>,
    caller: Caller,
    page: Query<PageQuery>,
    query: Result<Query<CurveQuery>, axum::extract::rejection::QueryRejection>,
) -> Result<Json<PageView<CurveView>>, Problem> {
    caller.require(Area::Curves, &Method::GET)?;
    let Query(query) =
        query.map_err(|_| Problem::bad_parameter("curve_key", "must be given at most once"))?;
    let page = state
        .store
        .list_curves(
            page.to_request()?,
            CurveFilter {
                key: query.curve_key,
            },
        )
        .await?;
    Ok(Json(PageView::from_page(page, CurveView::from)))
}

/// One curve version.
#[utoipa::path(
    get, path = "/v1/curves/{id}", tag = "curves",
    params(("id" = i64, Path, description = "Curve id", minimum = 1)),
    responses((status = 200, body = CurveView), (status = 400, body = Problem, content_type = "application/problem+json"), (status = 404, body = Problem, content_type = "application/problem+json")),
    security(("bearer" = []))
)]
pub async fn get_curve(
    State(state): State<AppState>,
    caller: Caller,
    Path(id): Path<String>,
) -> Result<Json<CurveView>, Problem> {
    caller.require(Area::Curves, &Method::GET)?;
    let id = parse_id(&id)?;
    let curve = state
        .store
        .get_curve(id)
        .await?
        .ok_or_else(|| Problem::not_found(format!("no curve with id {id}")))?;
    Ok(Json(curve.into()))
}

/// Make this version the one reports use for its key (engineer). Body optional:
/// Why `curve`'s points ran shorter than the excited window of the reference config it swept
/// (its provenance's `config`), if they did. A curve whose config or duration is not recorded,
/// or whose config is not a reference one, is not judged here.
fn shorter_than_reference(
    curve: &crate::store::CurveRecord,
    configs_dir: &std::path::Path,
) -> Option<String> {
    let duration = curve.fidelity.duration_per_point_s?;
    let config = curve.provenance.get("config")?.as_str()?;
    let path = crate::models::reference::reference_config_path(configs_dir, config).ok()?;
    let reference = crate::models::case::load_case(&path).ok()?;
    let window = reference.simulation.duration_s;
    (duration < window).then(|| {
        format!(
            "its points ran {duration} s each, shorter than the {window} s excited window of \
             the reference config `{config}`"
        )
    })
}

/// `{"force": true}` to publish a lower-fidelity version over the published one.
#[utoipa::path(
    post, path = "/v1/curves/{id}/publish", tag = "curves",
    params(("id" = i64, Path, description = "Curve id", minimum = 1)),
    request_body(content = Option<PublishRequest>, description = "Optional; `force` defaults to false"),
    responses(
        (status = 200, description = "Published (also when it already was)", body = CurveView),
        (status = 403, body = Problem, content_type = "application/problem+json"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 409, description = "Lower fidelity than the published version, or points shorter than the reference config's excited window, and `force` not set; `field` is `force`", body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn publish_curve(
    State(state): State<AppState>,
    caller: Caller,
    Path(id): Path<String>,
    body: axum::extract::Request,
) -> Result<Json<CurveView>, Problem> {
    caller.require(Area::Curves, &Method::POST)?;
    let id = parse_id(&id)?;
    let empty = body.headers().get(header::CONTENT_TYPE).is_none()
        && body
            .headers()
            .get(header::CONTENT_LENGTH)
            .is_none_or(|v| v.as_bytes() == b"0");
    // No body, or JSON `null`, publishes without force.
    let request: PublishRequest = if empty {
        PublishRequest::default()
    } else {
        read_json::<Option<PublishRequest>>(body)
            .await?
            .unwrap_or_default()
    };
    if !request.force {
        if let Some(curve) = state.store.get_curve(id).await? {
            if let Some(reason) = shorter_than_reference(&curve, &state.config.configs_dir) {
                let mut p = Problem::new(
                    StatusCode::CONFLICT,
                    "short-sweep",
                    "Sweep points shorter than the reference window",
                    format!(
                        "`force` must be true to publish curve {id}: {reason}. Short windows \
                         scatter (a 0.5 s-per-point sweep's slope can have the opposite sign of a \
                         10 s sweep's); sweep at the reference duration, or publish with force \
                         (the curve's fidelity says how it was swept)"
                    ),
                );
                p.field = Some("force".into());
                return Err(p);
            }
        }
    }
    match state
        .store
        .publish_curve(id, &caller.name, request.force, clock::now_ms())
        .await?
    {
        PublishOutcome::Published(curve) => {
            tracing::info!(curve = id, key = %curve.key, version = curve.version, by = %caller.name, force = request.force, "curve published");
            Ok(Json(curve.into()))
        }
        PublishOutcome::NotFound => Err(Problem::not_found(format!("no curve with id {id}"))),
        PublishOutcome::LowerFidelity { published, reason } => {
            let mut p = Problem::new(
                StatusCode::CONFLICT,
                "lower-fidelity",
                "Lower fidelity than the published curve",
                format!(
                    "`force` must be true to publish curve {id} over the published curve {} \
                     (version {} of {}): it has a lower fidelity ({reason})",
                    published.id, published.version, published.key
                ),
            );
            p.field = Some("force".into());
            Err(p)
        }
    }
}
