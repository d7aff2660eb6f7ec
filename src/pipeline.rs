//! The one narrow interface between the service (jobs) and the simulation library.
//!
//! A job hands a case configuration (JSON, the same schema as the TOML files in `configs/`)
//! and a [`RunControl`]; it gets back a [`CaseOutcome`] or a [`RunError`].

use crate::physics::track::TrackSample;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Progress of a running simulation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    /// Simulated time reached, s.
    pub simulated_time_s: f64,
    /// Simulated time at which the run ends, s.
    pub end_time_s: f64,
    /// Fraction done in [0, 1].
    pub fraction: f64,
}

/// Cancellation flag and progress sink handed to a run.
#[derive(Clone)]
pub struct RunControl {
    /// Set to true to stop the run; it returns [`RunError::Cancelled`] within a second.
    pub cancel: Arc<AtomicBool>,
    /// Called from the simulation thread, at most a few times per second.
    pub progress: Arc<dyn Fn(Progress) + Send + Sync>,
}

impl RunControl {
    /// A control that is never cancelled and drops progress.
    pub fn silent() -> Self {
        Self {
            cancel: Arc::new(AtomicBool::new(false)),
            progress: Arc::new(|_| {}),
        }
    }

    /// True once cancellation was requested.
    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

/// What a finished case produces.
#[derive(Debug, Clone)]
pub struct CaseOutcome {
    /// Summary: wear per contact and body (mg, mg/h), above-cutoff work share, pressure PDFs,
    /// spectra, settings used. JSON object.
    pub summary: serde_json::Value,
    /// Recorded contact-track samples (may be many).
    pub tracks: Vec<TrackSample>,
    /// Named SVG plots: (file name, SVG text).
    pub plots: Vec<(String, String)>,
}

/// Why a run did not produce an outcome.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The configuration broke a rule; `field` is a dotted path into the config.
    #[error("invalid configuration: field `{field}` {rule}")]
    InvalidConfig { field: String, rule: String },
    /// The simulation diverged; the message names time, body, contact and energy.
    #[error("simulation diverged: {0}")]
    Diverged(String),
    /// Cancelled through [`RunControl::cancel`].
    #[error("cancelled")]
    Cancelled,
}

use crate::models::case::{load_case, run_case};
use crate::models::specs::CaseSpec;
use std::path::Path;

fn invalid(field: &str, rule: impl Into<String>) -> RunError {
    RunError::InvalidConfig {
        field: field.to_string(),
        rule: rule.into(),
    }
}

/// Deep-merges `patch` into `base` (objects merge key by key; anything else replaces).
pub fn merge_json(base: &mut serde_json::Value, patch: &serde_json::Value) {
    match (base, patch) {
        (serde_json::Value::Object(b), serde_json::Value::Object(p)) => {
            for (k, v) in p {
                merge_json(b.entry(k.clone()).or_insert(serde_json::Value::Null), v);
            }
        }
        (b, p) => *b = p.clone(),
    }
}

/// Resolves job parameters to a case: `{"config": "<reference name>" | {inline case},
/// "overrides": {...}, "seed": n}`. Overrides deep-merge into the case (e.g.
/// `{"simulation": {"duration_s": 0.5}}`); `seed` sets `simulation.seed`.
pub fn case_from_params(
    params: &serde_json::Value,
    configs_dir: &Path,
) -> Result<CaseSpec, RunError> {
    let mut value = match params.get("config") {
        Some(serde_json::Value::String(name)) => {
            let path = crate::config::reference_config_path(configs_dir, name)
                .map_err(|e| invalid("config", e.to_string()))?;
            let case = load_case(&path)?;
            serde_json::to_value(&case).map_err(|e| invalid("config", e.to_string()))?
        }
        Some(obj @ serde_json::Value::Object(_)) => obj.clone(),
        Some(_) => {
            return Err(invalid(
                "config",
                "must be a reference config name or a config object",
            ))
        }
        None => {
            return Err(invalid(
                "config",
                "is required (a reference config name or a config object)",
            ))
        }
    };
    if let Some(over) = params.get("overrides") {
        if !over.is_object() {
            return Err(invalid("overrides", "must be an object"));
        }
        merge_json(&mut value, over);
    }
    if let Some(seed) = params.get("seed") {
        let seed = seed
            .as_u64()
            .ok_or_else(|| invalid("seed", "must be a non-negative integer"))?;
        merge_json(
            &mut value,
            &serde_json::json!({"simulation": {"seed": seed}}),
        );
    }
    let case: CaseSpec =
        serde_json::from_value(value).map_err(|e| invalid("config", e.to_string()))?;
    case.validate()?;
    Ok(case)
}

/// A simulate job: one case end to end.
pub fn simulate(
    params: &serde_json::Value,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<CaseOutcome, RunError> {
    let case = case_from_params(params, configs_dir)?;
    let (_, outcome) = run_case(&case, configs_dir, control)?;
    Ok(outcome)
}

/// One point of a tolerance sweep.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SweepPoint {
    /// Material-condition offset applied to the launcher dimensions, mm (negative = tighter).
    pub offset_mm: f64,
    /// Rattle space k_rs (eq. 6.1-6.3).
    pub rattle_space: f64,
    /// Rail wear rate, mg/h.
    pub rail_wear_rate_mg_per_h: f64,
}

/// Result of a tolerance sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepOutcome {
    /// Rattle space of the design dimensions.
    pub design_rattle_space: f64,
    /// Points, tight to loose.
    pub points: Vec<SweepPoint>,
}

/// Material-condition offsets (mm) of an n-point sweep from tight to loose.
pub fn sweep_offsets_mm(n: usize) -> Vec<f64> {
    use crate::analysis::rattle_space::{LOOSE_MATERIAL_CONDITION_MM, TIGHT_MATERIAL_CONDITION_MM};
    let n = n.max(2);
    (0..n)
        .map(|i| {
            TIGHT_MATERIAL_CONDITION_MM
                + (LOOSE_MATERIAL_CONDITION_MM - TIGHT_MATERIAL_CONDITION_MM) * i as f64
                    / (n - 1) as f64
        })
        .collect()
}

/// A planned tolerance sweep: the launcher case every point starts from and the
/// material-condition offsets of its points. Built from a sweep job's params alone, so the
/// sequential [`sweep`] and each `sweep_point` child job of a fanned-out sweep agree on it.
#[derive(Debug, Clone)]
pub struct SweepPlan {
    /// The launcher case of `params.config` (default `launcher-design`) with `overrides` and
    /// `seed` applied; each point replaces its launcher dimensions.
    pub base: CaseSpec,
    /// Material-condition offsets of the points, mm, tight to loose ([`sweep_offsets_mm`]).
    pub offsets_mm: Vec<f64>,
    /// Rattle space of the design dimensions (eq. 6.1-6.3), dimensionless.
    pub design_rattle_space: f64,
}

impl SweepPlan {
    /// Plan the sweep of `params`: `config` (default `launcher-design`, must be a launcher case),
    /// `overrides`, `seed`, `points` (default 5, 2..=50).
    pub fn from_params(params: &serde_json::Value, configs_dir: &Path) -> Result<Self, RunError> {
        let mut p = params.clone();
        if p.get("config").is_none() {
            merge_json(&mut p, &serde_json::json!({"config": "launcher-design"}));
        }
        let base = case_from_params(&p, configs_dir)?;
        if base.launcher.is_none() {
            return Err(invalid("config", "a sweep needs a launcher case"));
        }
        let n = match params.get("points") {
            None => 5,
            Some(v) => v
                .as_u64()
                .filter(|n| (2..=50).contains(n))
                .ok_or_else(|| invalid("points", "must be an integer in 2..=50"))?
                as usize,
        };
        let design_rattle_space = crate::analysis::rattle_space::LauncherDimensions::design()
            .rattle_space()
            .map_err(|e| invalid("launcher.dimensions", e.to_string()))?;
        Ok(Self {
            base,
            offsets_mm: sweep_offsets_mm(n),
            design_rattle_space,
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.offsets_mm.len()
    }

    /// True when the plan has no points (never for a plan from [`SweepPlan::from_params`]).
    pub fn is_empty(&self) -> bool {
        self.offsets_mm.is_empty()
    }

    /// Simulated time one point runs to, s (settle + duration).
    pub fn point_end_time_s(&self) -> f64 {
        self.base.simulation.settle_s + self.base.simulation.duration_s
    }

    /// The outcome of the sweep from its points, tight to loose.
    pub fn outcome(&self, points: Vec<SweepPoint>) -> SweepOutcome {
        SweepOutcome {
            design_rattle_space: self.design_rattle_space,
            points,
        }
    }
}

/// Point `index` of a planned sweep: the base case with the design dimensions moved by the
/// point's material-condition offset, run to the end; the rail's wear rate there. The
/// sequential [`sweep`] and a fanned-out sweep's `sweep_point` child jobs both call this, so a
/// point depends only on the sweep's params and seed.
pub fn sweep_point(
    plan: &SweepPlan,
    index: usize,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<SweepPoint, RunError> {
    let offset_mm = *plan
        .offsets_mm
        .get(index)
        .ok_or_else(|| invalid("point", format!("must be below {}", plan.len())))?;
    let mut case = plan.base.clone();
    if let Some(l) = case.launcher.as_mut() {
        l.dimensions = crate::analysis::rattle_space::LauncherDimensions::design()
            .with_material_condition(offset_mm);
    }
    let rattle_space = case
        .launcher
        .as_ref()
        .and_then(|l| l.rattle_space().ok())
        .unwrap_or(f64::NAN);
    let (report, _) = run_case(&case, configs_dir, control)?;
    let rail_wear_rate_mg_per_h = report
        .bodies
        .iter()
        .find(|b| b.name == "rail")
        .map(|b| b.mass_rate_mg_per_h)
        .ok_or_else(|| invalid("config", "the launcher model has no body named `rail`"))?;
    Ok(SweepPoint {
        offset_mm,
        rattle_space,
        rail_wear_rate_mg_per_h,
    })
}

/// Params of the child job that runs point `index` of the sweep with `params`: the sweep's
/// params (which carry its seed) plus `"point": index`.
pub fn sweep_point_params(params: &serde_json::Value, index: usize) -> serde_json::Value {
    let mut p = params.clone();
    merge_json(&mut p, &serde_json::json!({ "point": index }));
    p
}

/// The point index of a `sweep_point` child job's params.
pub fn sweep_point_index(params: &serde_json::Value) -> Result<usize, RunError> {
    params
        .get("point")
        .and_then(serde_json::Value::as_u64)
        .map(|i| i as usize)
        .ok_or_else(|| invalid("point", "is required (a non-negative integer)"))
}

/// A sweep job run in one process: the launcher case of `params` (default `launcher-design`) at
/// `points` (default 5, at least 2) dimension sets from tight to loose, same seed, one after the
/// other; returns the rail wear rate versus rattle space for the penalization curve (eq. 6.4).
/// The service fans the same points out to child jobs instead (see ARCHITECTURE.md).
pub fn sweep(
    params: &serde_json::Value,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<(serde_json::Value, SweepOutcome), RunError> {
    let plan = SweepPlan::from_params(params, configs_dir)?;
    let total = plan.len() as f64;
    let mut points = Vec::with_capacity(plan.len());
    for i in 0..plan.len() {
        if control.is_cancelled() {
            return Err(RunError::Cancelled);
        }
        let outer = control.progress.clone();
        let sub = RunControl {
            cancel: control.cancel.clone(),
            progress: Arc::new(move |pr: Progress| {
                outer(Progress {
                    simulated_time_s: pr.simulated_time_s,
                    end_time_s: pr.end_time_s,
                    fraction: (i as f64 + pr.fraction) / total,
                })
            }),
        };
        points.push(sweep_point(&plan, i, configs_dir, &sub)?);
    }
    let outcome = plan.outcome(points);
    let summary = serde_json::to_value(&outcome).map_err(|e| invalid("sweep", e.to_string()))?;
    Ok((summary, outcome))
}

/// A calibrate job (thesis 4.3-4.4). `{"friction": {"fixture": {...}, "records": [...]}}` fits
/// eq. 4.5 to torque records (eq. 4.1-4.4); `{"wear_law": {"density_kg_m3": .., "cutoff_pressure_pa": ..,
/// "records": [...]}}` fits K(sigma) (eq. 4.16-4.18). Either or both.
pub fn calibrate(params: &serde_json::Value) -> Result<serde_json::Value, RunError> {
    use crate::analysis::calibration as cal;
    let mut out = serde_json::Map::new();
    if let Some(f) = params.get("friction") {
        let fixture: cal::Fixture =
            serde_json::from_value(f.get("fixture").cloned().unwrap_or_default())
                .map_err(|e| invalid("friction.fixture", e.to_string()))?;
        let records: Vec<cal::TorqueRecord> =
            serde_json::from_value(f.get("records").cloned().unwrap_or_default())
                .map_err(|e| invalid("friction.records", e.to_string()))?;
        let samples = cal::friction_samples(&records, &fixture)
            .map_err(|e| invalid("friction.records", e.to_string()))?;
        let fit = cal::fit_friction(&samples, crate::physics::step::StepKind::Cycloidal)
            .map_err(|e| invalid("friction", e.to_string()))?;
        out.insert(
            "friction".into(),
            serde_json::to_value(fit).map_err(|e| invalid("friction", e.to_string()))?,
        );
    }
    if let Some(w) = params.get("wear_law") {
        let records: Vec<cal::WearTestRecord> =
            serde_json::from_value(w.get("records").cloned().unwrap_or_default())
                .map_err(|e| invalid("wear_law.records", e.to_string()))?;
        let density = w
            .get("density_kg_m3")
            .and_then(serde_json::Value::as_f64)
            .unwrap_or(2810.0);
        let cutoff = w
            .get("cutoff_pressure_pa")
            .and_then(serde_json::Value::as_f64)
            .unwrap_or(870e6);
        let fit = cal::fit_wear_law(&records, density, cutoff)
            .map_err(|e| invalid("wear_law", e.to_string()))?;
        out.insert(
            "wear_law".into(),
            serde_json::to_value(fit).map_err(|e| invalid("wear_law", e.to_string()))?,
        );
    }
    if out.is_empty() {
        return Err(invalid(
            "params",
            "give `friction` and/or `wear_law` calibration data",
        ));
    }
    Ok(serde_json::Value::Object(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn configs() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
    }

    #[test]
    fn a_point_child_plans_the_same_sweep_as_its_parent() {
        let parent = serde_json::json!({"points": 4, "seed": 9, "vehicle_profile": "ah64"});
        let child = sweep_point_params(&parent, 3);
        assert_eq!(sweep_point_index(&child).unwrap(), 3);
        let a = SweepPlan::from_params(&parent, &configs()).unwrap();
        let b = SweepPlan::from_params(&child, &configs()).unwrap();
        assert_eq!(a.offsets_mm, b.offsets_mm);
        assert_eq!(a.base.simulation.seed, 9);
        assert_eq!(b.base.simulation.seed, 9);
        assert_eq!(a.design_rattle_space, b.design_rattle_space);
        // Tight to loose, ends at the named material conditions.
        use crate::analysis::rattle_space::{
            LOOSE_MATERIAL_CONDITION_MM, TIGHT_MATERIAL_CONDITION_MM,
        };
        assert_eq!(a.offsets_mm.first(), Some(&TIGHT_MATERIAL_CONDITION_MM));
        assert_eq!(a.offsets_mm.last(), Some(&LOOSE_MATERIAL_CONDITION_MM));
        assert!(matches!(
            sweep_point_index(&parent),
            Err(RunError::InvalidConfig { field, .. }) if field == "point"
        ));
        assert!(matches!(
            sweep_point(&a, 4, &configs(), &RunControl::silent()),
            Err(RunError::InvalidConfig { field, .. }) if field == "point"
        ));
    }
}
