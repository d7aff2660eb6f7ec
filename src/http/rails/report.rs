//! `GET /v1/rails/{serial}/report`: the service life of a rail from its latest measurement and
//! the published penalization curve of the asked key ([`crate::service_life`]), or, when no
//! curve covers it, what is under way or what to run.

use super::{load_rail, MeasurementView};
use crate::analysis::penalization::PenalizationCurve;
use crate::analysis::rattle_space::LauncherDimensions;
use crate::http::auth::{Area, Caller};
use crate::http::problem::Problem;
use crate::http::AppState;
use crate::jobs::{curve_key, JobStatus};
use crate::store::{clock, CurveFilter, CurveRecord};
use axum::extract::{Path, Query, State};
use axum::http::{Method, StatusCode};
use axum::Json;
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};
use uuid::Uuid;

/// Largest design life a report accepts, h (114 years of flight).
const MAX_DESIGN_LIFE_H: f64 = 1e6;

/// One point of the sweep behind a report.
#[derive(Debug, Serialize, ToSchema)]
pub struct CurvePointView {
    /// Rattle space k_rs (eq. 6.3), dimensionless.
    pub rattle_space: f64,
    /// Simulated rail wear rate there, mg/h.
    pub rail_wear_rate_mg_per_h: f64,
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
    pub fidelity: crate::http::curves::FidelityView,
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
    /// K_SL and the penalized life under another stored curve (`?compare=<curve id>`), e.g.
    /// one swept under another wear mechanism: how much the life depends on it.
    pub comparison: Option<CurveComparison>,
}

/// This rail's K_SL and penalized life under a named alternative curve.
#[derive(Debug, Serialize, ToSchema)]
pub struct CurveComparison {
    /// Curve id (`/v1/curves/{id}`).
    pub curve_id: i64,
    /// Its key `vehicle_profile/environment/wear_law`: the wear law is its last part.
    pub curve_key: String,
    pub version: i64,
    /// Whether that curve is published (a comparison may use an unpublished one).
    pub published: bool,
    /// The sweep job that produced it (its params say how it was made).
    pub job_id: Uuid,
    /// K_SL under it (null when it does not cover this rattle space: `detail` says why).
    pub k_sl: Option<f64>,
    /// Design life times that K_SL, h.
    pub penalized_life_h: Option<f64>,
    /// K_SL under it over K_SL under the report's curve (null without both).
    pub k_sl_ratio: Option<f64>,
    /// In words.
    pub detail: String,
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
    /// Wear law of the curve: `modified-archard`, `archard`, `legacy-appendix`, or
    /// `diagnosis-<diagnose job id>` for a curve swept with a diagnosis' fitted mechanism.
    pub wear_law: Option<String>,
    /// T_SL,design, h (> 0).
    #[param(value_type = Option<f64>, exclusive_minimum = 0)]
    pub design_life_h: Option<String>,
    /// Id of a stored curve (`/v1/curves`) to compare with: the report adds K_SL and the
    /// penalized life under it (`comparison`).
    #[param(value_type = Option<i64>, minimum = 1)]
    pub compare: Option<String>,
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
        let diagnosed = law
            .strip_prefix("diagnosis-")
            .is_some_and(|id| uuid::Uuid::parse_str(id).is_ok());
        if !diagnosed && !crate::pipeline::WEAR_LAWS.contains(&law.as_str()) {
            return Err(Problem::invalid_field(
                "wear_law",
                format!(
                    "`{law}` is not a wear law (known: {}, or diagnosis-<diagnose job id>)",
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

/// The rail's service-life report from its latest measurement (latest `measured_at`).
#[utoipa::path(
    get, path = "/v1/rails/{serial}/report", tag = "rails",
    params(("serial" = String, Path, pattern = "^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$"), ReportQuery),
    responses(
        (status = 200, description = "Report; `service_life` when a curve covers the rail, otherwise `missing_curve` says which sweep to run", body = ReportView),
        (status = 400, description = "Malformed serial, design_life_h or compare, unknown or repeated parameter", body = Problem, content_type = "application/problem+json"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "vehicle_profile, environment or wear_law names nothing a sweep can run, or compare names no stored curve; `field` is the parameter", body = Problem, content_type = "application/problem+json"),
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
        crate::http::problem::bare_error_problem(StatusCode::BAD_REQUEST, &rejection.body_text())
    })?;
    let defaults = &state.config.report;
    let design_life_h = match &query.design_life_h {
        None => defaults.design_life_h,
        Some(text) => text
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|h| h.is_finite() && *h > 0.0 && *h <= MAX_DESIGN_LIFE_H)
            .ok_or_else(|| {
                Problem::bad_parameter(
                    "design_life_h",
                    "must be a positive number of hours, at most 1e6 (114 years of flight: \
                     more is a unit mistake)",
                )
            })?,
    };
    let compare_id = match &query.compare {
        None => None,
        Some(text) => Some(
            text.trim()
                .parse::<i64>()
                .ok()
                .filter(|id| *id >= 1)
                .ok_or_else(|| Problem::bad_parameter("compare", "must be a curve id (>= 1)"))?,
        ),
    };
    let (profile, environment, wear_law) =
        report_labels(&query, defaults, &state.config.configs_dir)?;
    load_rail(&state, &serial).await?;
    let compare_curve = match compare_id {
        None => None,
        Some(id) => Some(state.store.get_curve(id).await?.ok_or_else(|| {
            Problem::invalid_field("compare", format!("curve {id} is not stored"))
        })?),
    };
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
        comparison: None,
    };
    let read = |c: &CurveRecord| {
        serde_json::from_value::<PenalizationCurve>(c.curve.clone())
            .map_err(|e| tracing::warn!(curve = c.id, error = %e, "unreadable stored curve"))
            .ok()
    };
    let published = state.store.published_curve(&key).await?;
    let published_data = published.as_ref().and_then(read);
    let base_k_sl = published_data.as_ref().and_then(|d| d.k_sl(k_rs).ok());
    report.comparison = compare_curve.map(|c| {
        let under = read(&c)
            .ok_or("its stored data cannot be read".to_string())
            .and_then(|d| {
                crate::service_life::service_life(&d, k_rs, design_life_h)
                    .map_err(|e| e.to_string())
            });
        let (k_sl, life, detail) = match under {
            Ok(l) => (
                Some(l.life.factors.k_sl),
                Some(l.life.life_h),
                format!(
                    "K_SL {:.4} under curve {} ({}), penalized life {:.1} h of {design_life_h} h",
                    l.life.factors.k_sl, c.id, c.key, l.life.life_h
                ),
            ),
            Err(reason) => (
                None,
                None,
                format!(
                    "curve {} ({}) gives no K_SL at rattle space {k_rs:.4}: {reason}",
                    c.id, c.key
                ),
            ),
        };
        CurveComparison {
            curve_id: c.id,
            curve_key: c.key.clone(),
            version: c.version,
            published: c.published.is_some(),
            job_id: c.job_id,
            k_sl,
            penalized_life_h: life,
            k_sl_ratio: match (k_sl, base_k_sl) {
                (Some(a), Some(b)) if b > 0.0 => Some(a / b),
                _ => None,
            },
            detail,
        }
    });
    let mut why = format!("no published penalization curve for {key}");
    if let (Some(stored), Some(data)) = (&published, &published_data) {
        let (lo, hi) = data.range();
        report.curve = Some(ReportCurve {
            id: stored.id,
            version: stored.version,
            curve_key: stored.key.clone(),
            job_id: stored.job_id,
            fidelity: crate::http::curves::FidelityView {
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
        report.k_sl_curve = crate::service_life::k_sl_samples(data);
        report.curve_points = data
            .points()
            .iter()
            .map(|p| CurvePointView {
                rattle_space: p.rattle_space,
                rail_wear_rate_mg_per_h: p.rail_wear_rate_mg_per_h,
            })
            .collect();
        match crate::service_life::service_life(data, k_rs, design_life_h) {
            Ok(life) => {
                let crate::service_life::ServiceLife {
                    life,
                    interval,
                    uncertainty,
                } = life;
                report.service_life = Some(ServiceLife {
                    k_sl: life.factors.k_sl,
                    k_sl_band_90: life.factors.k_sl_conservative_90,
                    k_sl_band_80: life.factors.k_sl_conservative_80,
                    design_life_h: life.design_life_h,
                    penalized_life_h: life.life_h,
                    penalized_life_band_90_h: life.life_conservative_90_h,
                    penalized_life_band_80_h: life.life_conservative_80_h,
                    interval: interval.map(|i| ServiceLifeInterval {
                        confidence: i.k_sl.confidence,
                        seeds: i.k_sl.seeds,
                        t_quantile: i.k_sl.t_quantile,
                        k_sl_low: i.k_sl.k_sl_low,
                        k_sl_high: i.k_sl.k_sl_high,
                        penalized_life_low_h: i.life_low_h,
                        penalized_life_high_h: i.life_high_h,
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
