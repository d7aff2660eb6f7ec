//! A test double for the queue (not a physics stub): a deterministic computation that takes a
//! known wall time, reports progress, honours cancellation and produces tracks from its seed.
//! Injected through `CaseRunner` so queue semantics can be tested without the engine.
//!
//! A sweep with `"children": n` fans out into n `sweep_point` children (each the same counted
//! computation, `"fail_point": i` makes child i fail) and is assembled from their results.
//!
//! A sweep's curve is fixed ([`fixed_curve`]) unless its params name a `rattle_space_range`:
//! then it is [`synthetic_curve`], a closed form over the real sweep's points and seeds
//! (`pipeline::SweepRange`), so reports and publishing can be tested with known values.

use railwear::analysis::penalization::{PenalizationCurve, SweepPoint};
use railwear::analysis::rattle_space::LauncherDimensions;
use railwear::config::ServiceConfig;
use railwear::http::RunningService;
use railwear::jobs::{CaseRunner, ChildJob, FanOutPlan, JobKind, JobOutput};
use railwear::physics::track::TrackSample;
use railwear::pipeline::{Progress, RunControl, RunError};
use std::sync::Arc;
use std::time::Duration;

/// Runs `steps` steps of `step_ms` each (params `steps`, `step_ms`, `samples`).
pub struct CountingRunner;

/// Sample `i` of the run seeded with `seed`: a splitmix64 stream, so any two runs of the same
/// seed agree bit for bit and different seeds differ.
pub fn sample(seed: u64, i: u64) -> TrackSample {
    let mut z = seed.wrapping_add(i.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    let u = (z >> 11) as f64 / (1u64 << 53) as f64;
    TrackSample {
        time_s: i as f64 * 1e-3,
        contact: (i % 3) as u32,
        track: 0,
        normal_force_n: 10.0 * u,
        slip_velocity_m_s: [u, -u, 0.5 * u],
        slip_speed_m_s: u * 1.5f64.sqrt(),
        penetration_m: 1e-6 * u,
        penetration_rate_m_s: 1e-4 * (u - 0.5),
        area_m2: 1e-6,
        pressure_pa: 1e7 * u,
        point_in_a_m: [0.0, 0.01, u],
        point_in_b_m: [u, 0.0, -0.01],
    }
}

impl CaseRunner for CountingRunner {
    fn run(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        control: &RunControl,
    ) -> Result<JobOutput, RunError> {
        let get =
            |name: &str, default: u64| params.get(name).and_then(|v| v.as_u64()).unwrap_or(default);
        let (steps, step_ms, samples) = (get("steps", 10), get("step_ms", 20), get("samples", 100));
        let seed = params
            .get("seed")
            .and_then(|v| v.as_u64())
            .ok_or(RunError::InvalidConfig {
                field: "seed".into(),
                rule: "the queue must hand the seed to the runner".into(),
            })?;
        for step in 0..steps {
            if control.is_cancelled() {
                return Err(RunError::Cancelled);
            }
            std::thread::sleep(Duration::from_millis(step_ms));
            (control.progress)(Progress {
                simulated_time_s: (step + 1) as f64 * 0.1,
                end_time_s: steps as f64 * 0.1,
                fraction: (step + 1) as f64 / steps as f64,
            });
        }
        if *kind == JobKind::SweepPoint {
            let point = params
                .get("point")
                .and_then(|v| v.as_u64())
                .unwrap_or(u64::MAX);
            if params.get("fail_point").and_then(|v| v.as_u64()) == Some(point) {
                return Err(RunError::Diverged(format!(
                    "point {point} diverged on purpose"
                )));
            }
            // A value that depends on the seed and the point only.
            return Ok(JobOutput {
                summary: serde_json::json!({
                    "point": point,
                    "value": sample(seed, point).normal_force_n,
                }),
                ..JobOutput::default()
            });
        }
        let tracks: Vec<TrackSample> = (0..samples).map(|i| sample(seed, i)).collect();
        let force_sum: f64 = tracks.iter().map(|t| t.normal_force_n).sum();
        let (penalization, curve_info) = if *kind == JobKind::Sweep {
            sweep_curve(params)?
        } else {
            (None, None)
        };
        Ok(JobOutput {
            summary: serde_json::json!({ "seed": seed, "force_sum_n": force_sum, "steps": steps }),
            tracks,
            plots: vec![(
                "force.svg".into(),
                "<svg xmlns=\"http://www.w3.org/2000/svg\"/>".into(),
            )],
            penalization,
            curve_info,
        })
    }

    fn fan_out(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        _plan: Option<&serde_json::Value>,
    ) -> Result<Option<FanOutPlan>, RunError> {
        let Some(n) = params.get("children").and_then(|v| v.as_u64()) else {
            return Ok(None);
        };
        if *kind != JobKind::Sweep {
            return Ok(None);
        }
        let steps = params.get("steps").and_then(|v| v.as_u64()).unwrap_or(10);
        Ok(Some(FanOutPlan {
            children: (0..n)
                .map(|i| {
                    let mut child = params.clone();
                    child["point"] = serde_json::json!(i);
                    ChildJob {
                        kind: JobKind::SweepPoint,
                        params: child,
                        plan: None,
                    }
                })
                .collect(),
            end_time_s: n as f64 * steps as f64 * 0.1,
        }))
    }

    fn assemble(
        &self,
        _kind: &JobKind,
        params: &serde_json::Value,
        _plan: Option<&serde_json::Value>,
        children: &[serde_json::Value],
    ) -> Result<JobOutput, RunError> {
        for (i, child) in children.iter().enumerate() {
            if child["point"] != serde_json::json!(i) {
                return Err(RunError::InvalidConfig {
                    field: format!("children[{i}]"),
                    rule: format!("holds point {}", child["point"]),
                });
            }
        }
        let (penalization, curve_info) = sweep_curve(params)?;
        Ok(JobOutput {
            summary: serde_json::json!({ "points": children }),
            plots: vec![(
                "penalization.svg".into(),
                "<svg xmlns=\"http://www.w3.org/2000/svg\"/>".into(),
            )],
            penalization,
            curve_info,
            ..JobOutput::default()
        })
    }

    fn submit_plan(
        &self,
        _kind: &JobKind,
        params: &serde_json::Value,
        _seed: u64,
    ) -> Result<Option<serde_json::Value>, RunError> {
        match params.get("steps") {
            Some(v) if v.as_u64().is_none() => Err(RunError::InvalidConfig {
                field: "steps".into(),
                rule: "must be a non-negative integer".into(),
            }),
            _ => Ok(None),
        }
    }
}

/// Rail wear rate of seed `j` at rattle space `k` in a synthetic sweep, mg/h:
/// `exp((8 + 0.5 j)(0.80 - k))`. ln(rate) is linear in k, so the curve's interpolation is exact
/// and seed j's log ratio to the design point is `-(8 + 0.5 j)(k_design - k)`.
pub fn synthetic_rate(j: usize, k: f64) -> f64 {
    ((8.0 + 0.5 * j as f64) * (0.80 - k)).exp()
}

/// A synthetic sweep's curve: [`synthetic_rate`] at the points and seeds the real sweep of
/// `params` would run; fidelity `points`, `seeds` and `duration_s` (default 1 s) from params.
pub fn synthetic_curve(
    params: &serde_json::Value,
) -> Result<(PenalizationCurve, railwear::jobs::CurveInfo), RunError> {
    let range = railwear::pipeline::SweepRange::from_params(params)?;
    let rates: Vec<Vec<f64>> = range
        .rattle_spaces
        .iter()
        .map(|&k| (0..range.seeds).map(|j| synthetic_rate(j, k)).collect())
        .collect();
    let design = LauncherDimensions::design()
        .rattle_space()
        .unwrap_or(f64::NAN);
    let curve =
        PenalizationCurve::from_seeds(&range.rattle_spaces, &rates, design).map_err(|e| {
            RunError::InvalidConfig {
                field: "points".into(),
                rule: e.to_string(),
            }
        })?;
    let info = railwear::jobs::CurveInfo {
        fidelity: railwear::store::CurveFidelity {
            points: range.rattle_spaces.len() as i64,
            duration_per_point_s: Some(
                params
                    .get("duration_s")
                    .and_then(|v| v.as_f64())
                    .unwrap_or(1.0),
            ),
            seeds: range.seeds as i64,
        },
        provenance: serde_json::json!({"runner": "counting", "params": params}),
    };
    Ok((curve, info))
}

/// The curve of a counted sweep: [`synthetic_curve`] when params name a `rattle_space_range`,
/// else [`fixed_curve`] (no fidelity given: the worker derives it).
pub fn sweep_curve(
    params: &serde_json::Value,
) -> Result<(Option<PenalizationCurve>, Option<railwear::jobs::CurveInfo>), RunError> {
    if params.get("rattle_space_range").is_some() {
        let (curve, info) = synthetic_curve(params)?;
        Ok((Some(curve), Some(info)))
    } else {
        Ok((Some(fixed_curve()?), None))
    }
}

/// The curve every counted sweep yields: fixed points (rates in mg/h at the thesis' loose,
/// design and tight rattle spaces; only their ratios matter to K_SL).
fn fixed_curve() -> Result<PenalizationCurve, RunError> {
    let point = |rattle_space, rail_wear_rate_mg_per_h| SweepPoint {
        offset_mm: None,
        rattle_space,
        rail_wear_rate_mg_per_h,
    };
    // At the exact rattle spaces of the named loose/design/tight dimension sets.
    let k = |d: LauncherDimensions| d.rattle_space().unwrap_or(f64::NAN);
    let design = k(LauncherDimensions::design());
    let points = [
        point(k(LauncherDimensions::loose()), 2.0),
        point(design, 1.5),
        point(k(LauncherDimensions::tight()), 1.0),
    ];
    PenalizationCurve::new(&points, design).map_err(|e| RunError::InvalidConfig {
        field: "points".into(),
        rule: e.to_string(),
    })
}

/// Settings for an in-process test service on a free port with a fresh database.
pub fn test_config(db_url: &str) -> ServiceConfig {
    let mut config = ServiceConfig {
        listen: "127.0.0.1:0".into(),
        database_url: db_url.to_string(),
        workers: 2,
        lease_s: 2.0,
        heartbeat_s: 0.2,
        poll_interval_ms: 50,
        body_limit_bytes: 64 * 1024,
        configs_dir: std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs"),
        ..ServiceConfig::default()
    };
    config
        .apply_env(|key| (key == "RAILWEAR_TOKENS").then(super::tokens_env))
        .expect("tokens");
    config
}

/// Start the service in this process with the production runner (the shipped `configs/`).
pub async fn start_library(config: ServiceConfig, workers: bool) -> RunningService {
    let runner = Arc::new(railwear::jobs::LibraryRunner::new(
        config.configs_dir.clone(),
    ));
    railwear::http::start(config, runner, workers)
        .await
        .expect("service starts")
}

/// Start the service in this process with the counting runner.
pub async fn start(config: ServiceConfig, workers: bool) -> RunningService {
    railwear::http::start(config, Arc::new(CountingRunner), workers)
        .await
        .expect("service starts")
}
