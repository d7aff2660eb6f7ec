//! Tolerance sweeps: the plan, its points and labels (vehicle profile, environment, wear
//! law), one point's run, and the sequential sweep.

use super::{
    check_keys, design_rattle_space, merge_json, replica_seed, resolve_case_seeded, Progress,
    RunControl, RunError, SweepRange, SWEEP_KEYS,
};
use crate::analysis::penalization::SweepPoint;
use crate::field_error::FieldError;
use crate::models::spec::CaseSpec;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Arc;

/// Result of a tolerance sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepOutcome {
    /// Rattle space of the design dimensions.
    pub design_rattle_space: f64,
    /// Points, tight to loose; each rate is the geometric mean over the seeds (the mean of
    /// ln(rate), the quantity the curve interpolates).
    pub points: Vec<SweepPoint>,
    /// Seeds of the replicas, in replica order ([`replica_seed`]).
    #[serde(default)]
    pub seeds: Vec<u64>,
    /// Per point (same order), the rail wear rate of each seed, mg/h.
    #[serde(default)]
    pub rate_by_seed_mg_per_h: Vec<Vec<f64>>,
}

/// Vehicle profile of a sweep when its params name none (the service fills in its own default
/// from `[report]` before storing a sweep).
pub const DEFAULT_VEHICLE_PROFILE: &str = "ah64";
/// Environment of a sweep when its params name none.
pub const DEFAULT_ENVIRONMENT: &str = "clean";
/// Wear law of a sweep when its params name none.
pub const DEFAULT_WEAR_LAW: &str = "modified-archard";
/// Vehicle-profile names that are not file stems: `ah64` is the AH-64 transverse
/// sine-on-random of `configs/profiles/ah64-transverse.toml`.
pub const VEHICLE_PROFILE_ALIASES: &[(&str, &str)] = &[("ah64", "ah64-transverse")];
/// Environments the wear model represents: only clean, dry contacts (third-body abrasion by
/// sand or dust is not modelled, SPEC 7).
pub const ENVIRONMENTS: &[&str] = &["clean"];
/// Wear-law names of a sweep and what they select: `modified-archard` (eq. 3.10-3.15; Table
/// 4.3 unless the config gives other constants), `archard` (eq. 3.8; the config or overrides
/// must give `wear.law = {kind = "archard", coefficient_m2_per_n = ..}`), `legacy-appendix`
/// (the thesis' appendix C code with Table 4.3).
pub const WEAR_LAWS: &[&str] = &["modified-archard", "archard", "legacy-appendix"];

/// Vehicle profiles a sweep may name: the aliases and every profile file in
/// `<configs_dir>/profiles`, sorted.
pub fn vehicle_profile_names(configs_dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = VEHICLE_PROFILE_ALIASES
        .iter()
        .map(|(alias, _)| alias.to_string())
        .collect();
    names.extend(crate::models::reference::reference_config_names(
        &configs_dir.join("profiles"),
    ));
    names.sort();
    names.dedup();
    names
}

/// The profile file stem (`configs/profiles/<stem>.toml`) a vehicle-profile name selects.
pub fn vehicle_profile_file(configs_dir: &Path, name: &str) -> Result<String, RunError> {
    let stem = VEHICLE_PROFILE_ALIASES
        .iter()
        .find(|(alias, _)| *alias == name)
        .map_or(name, |(_, stem)| stem);
    let dir = configs_dir.join("profiles");
    match crate::models::reference::reference_config_path(&dir, stem) {
        Ok(_) => Ok(stem.to_string()),
        Err(_) => Err(FieldError::new(
            "vehicle_profile",
            format!(
                "`{name}` is not a vehicle profile in {} (known: {})",
                dir.display(),
                vehicle_profile_names(configs_dir).join(", ")
            ),
        )
        .into()),
    }
}

/// The wear-law name of a law (see [`WEAR_LAWS`]).
pub fn wear_law_name(law: &crate::wear::law::WearLaw) -> &'static str {
    use crate::wear::law::WearLaw;
    match law {
        WearLaw::Modified { .. } => "modified-archard",
        WearLaw::Archard { .. } => "archard",
        WearLaw::LegacyAppendix { .. } => "legacy-appendix",
    }
}

/// Makes the case's wear law the one `name` selects: a case whose law already is of that kind
/// keeps its constants; a case on one of the Table 4.3 presets moves to the other preset;
/// anything else (an Archard law without a coefficient) is refused.
fn select_wear_law(case: &mut CaseSpec, name: &str) -> Result<(), RunError> {
    use crate::wear::law::WearLaw;
    if !WEAR_LAWS.contains(&name) {
        return Err(FieldError::new(
            "wear_law",
            format!(
                "`{name}` is not a wear law (known: {})",
                WEAR_LAWS.join(", ")
            ),
        )
        .into());
    }
    let current = case.wear.law;
    if wear_law_name(&current) == name {
        return Ok(());
    }
    let preset = current == WearLaw::table_4_3() || current == WearLaw::legacy_table_4_3();
    case.wear.law = match name {
        "modified-archard" if preset => WearLaw::table_4_3(),
        "legacy-appendix" if preset => WearLaw::legacy_table_4_3(),
        _ => {
            return Err(FieldError::new(
                "wear_law",
                format!(
                    "`{name}` does not match the config's wear law ({}); give its constants in \
                     overrides.wear.law (e.g. {{\"kind\": \"archard\", \
                     \"coefficient_m2_per_n\": 1e-15}})",
                    wear_law_name(&current)
                ),
            )
            .into())
        }
    };
    Ok(())
}

/// A planned tolerance sweep: the launcher case every point starts from and the
/// material-condition offsets of its points. Built from a sweep job's params alone, so the
/// sequential [`sweep_job`] and each `sweep_point` child job of a fanned-out sweep agree on it.
/// A sweep job stores it at submission as its canonical JSON, and each child the same plan
/// with its `point` and `replica` set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepPlan {
    /// The launcher case of `params.config` (default `launcher-design`) with `overrides` and
    /// `seed` applied, its excitation the vehicle profile's and its wear law the one named;
    /// each point replaces its launcher dimensions.
    pub base: CaseSpec,
    /// Material-condition offsets of the points, mm, tight to loose (`range.offsets_mm`).
    pub offsets_mm: Vec<f64>,
    /// Range, points, seeds and base dimensions ([`SweepRange`]).
    pub range: SweepRange,
    /// Seed of each replica ([`replica_seed`] of the sweep's seed).
    pub seeds: Vec<u64>,
    /// Rattle space of the design dimensions (eq. 6.1-6.3), dimensionless.
    pub design_rattle_space: f64,
    /// Vehicle profile (excitation) name, e.g. `ah64`.
    pub vehicle_profile: String,
    /// Environment name (`clean`).
    pub environment: String,
    /// Wear-law name ([`WEAR_LAWS`], or `diagnosis-<id>` for a diagnosed mechanism).
    pub wear_law: String,
    /// The diagnosis' mechanism the base case carries (`wear_law = {diagnosis = ..}`).
    pub diagnosed: Option<super::DiagnosedWearLaw>,
    /// `sweep_point` children: the point this child runs.
    pub point: Option<usize>,
    /// `sweep_point` children: the replica (seed index) this child runs.
    pub replica: Option<usize>,
}

impl SweepPlan {
    /// Plan the sweep of `params` ([`SWEEP_KEYS`], plus `point` for a child): `config`
    /// (default `launcher-design`, must be a launcher case), `overrides`, `seed`, `points`
    /// (default 5, [`super::limits::SWEEP_POINTS`]), `vehicle_profile` (selects the excitation: a
    /// profile in `configs/profiles`, see [`vehicle_profile_file`]), `environment`
    /// ([`ENVIRONMENTS`]) and `wear_law` ([`WEAR_LAWS`]). Every rule of [`super::resolve_case`]
    /// applies to the base case.
    pub fn from_params(params: &serde_json::Value, configs_dir: &Path) -> Result<Self, RunError> {
        Self::from_params_seeded(params, configs_dir, None)
    }

    /// [`SweepPlan::from_params`] for a job run with `seed` when given (a submitted job's, which
    /// its params may lack): the base case's `simulation.seed`, set after the config's own value
    /// is checked, and the replicas' seeds drawn from it.
    pub fn from_params_seeded(
        params: &serde_json::Value,
        configs_dir: &Path,
        seed: Option<u64>,
    ) -> Result<Self, RunError> {
        let mut keys = SWEEP_KEYS.to_vec();
        keys.extend(["point", "replica"]);
        check_keys(params, "params", &keys)?;
        let text = |name: &str, default: &str| -> Result<String, RunError> {
            match params.get(name) {
                None => Ok(default.to_string()),
                Some(serde_json::Value::String(s)) => Ok(s.clone()),
                Some(_) => Err(FieldError::new(name, "must be a string").into()),
            }
        };
        let vehicle_profile = text("vehicle_profile", DEFAULT_VEHICLE_PROFILE)?;
        let environment = text("environment", DEFAULT_ENVIRONMENT)?;
        let law_param = super::SweepWearLaw::from_param(params.get("wear_law"), DEFAULT_WEAR_LAW)?;
        let wear_law = law_param.curve_name();
        let diagnosed = match &law_param {
            super::SweepWearLaw::Diagnosed(d) => Some(d.clone()),
            super::SweepWearLaw::Named(_) => None,
        };
        let profile_file = vehicle_profile_file(configs_dir, &vehicle_profile)?;
        if !ENVIRONMENTS.contains(&environment.as_str()) {
            return Err(FieldError::new(
                "environment",
                format!(
                    "`{environment}` is not modelled (known: {}; sand or dust abrasion is not \
                     part of the wear model)",
                    ENVIRONMENTS.join(", ")
                ),
            )
            .into());
        }
        if params
            .get("overrides")
            .is_some_and(|o| o.get("excitation").is_some())
        {
            return Err(FieldError::new(
                "overrides.excitation",
                "a sweep's excitation is its vehicle_profile; remove it (or run simulate jobs)",
            )
            .into());
        }
        let range = SweepRange::from_params(params)?;
        let n = range.offsets_mm.len();
        let point =
            match params.get("point") {
                None => None,
                Some(v) => Some(v.as_u64().filter(|i| *i < n as u64).ok_or_else(|| {
                    FieldError::new("point", format!("must be an integer below {n}"))
                })? as usize),
            };
        let replica = match params.get("replica") {
            None => None,
            Some(v) => Some(
                v.as_u64()
                    .filter(|i| *i < range.seeds as u64)
                    .ok_or_else(|| {
                        FieldError::new(
                            "replica",
                            format!("must be an integer below {}", range.seeds),
                        )
                    })? as usize,
            ),
        };
        let mut p = params.clone();
        if p.get("config").is_none() {
            merge_json(&mut p, &serde_json::json!({"config": "launcher-design"}));
        }
        let base = resolve_case_seeded(&p, configs_dir, seed, |case| {
            if case.launcher.is_none() {
                return Err(FieldError::new(
                    "config",
                    "a sweep varies launcher rail dimensions: it needs a launcher case \
                     (launcher-tight, launcher-design, launcher-loose or an inline launcher)",
                )
                .into());
            }
            case.excitation = crate::models::spec::CaseExcitation::profile(&profile_file);
            match (&diagnosed, case.launcher.as_ref()) {
                (Some(d), Some(launcher)) => {
                    // A legacy law is refused by the case's own rule (`wear.mechanism`).
                    case.wear.mechanism = Some(d.mechanism(launcher.material.hardness_pa())?);
                    Ok(())
                }
                _ => select_wear_law(case, &wear_law),
            }
        })?;
        let design_rattle_space = design_rattle_space();
        let seeds = (0..range.seeds)
            .map(|j| replica_seed(base.simulation.seed, j))
            .collect();
        Ok(Self {
            base,
            offsets_mm: range.offsets_mm.clone(),
            range,
            seeds,
            design_rattle_space,
            vehicle_profile,
            environment,
            wear_law,
            diagnosed,
            point,
            replica,
        })
    }

    /// Simulations of the sweep: points x seeds (one child job each).
    pub fn runs(&self) -> usize {
        self.len() * self.seeds.len()
    }

    /// Child index of point `point`, replica `replica` (point-major).
    pub fn run_index(&self, point: usize, replica: usize) -> usize {
        point * self.seeds.len() + replica
    }

    /// Excited duration of each simulation, s (the curve's fidelity).
    pub fn duration_per_point_s(&self) -> f64 {
        self.base.simulation.duration_s
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

    /// The outcome of the sweep from its runs in child order ([`SweepPlan::run_index`]): per
    /// point, the geometric mean of its seeds' rates and the rates themselves.
    pub fn outcome(&self, runs: Vec<SweepPoint>) -> Result<SweepOutcome, RunError> {
        let per = self.seeds.len().max(1);
        if runs.len() != self.runs() {
            return Err(FieldError::new(
                "points",
                format!(
                    "the sweep has {} runs but {} results",
                    self.runs(),
                    runs.len()
                ),
            )
            .into());
        }
        let mut points = Vec::with_capacity(self.len());
        let mut rates = Vec::with_capacity(self.len());
        for chunk in runs.chunks(per) {
            let by_seed: Vec<f64> = chunk.iter().map(|r| r.rail_wear_rate_mg_per_h).collect();
            let mean_ln = by_seed.iter().map(|r| r.ln()).sum::<f64>() / by_seed.len() as f64;
            let rate = if by_seed.len() == 1 {
                by_seed[0]
            } else {
                mean_ln.exp()
            };
            points.push(SweepPoint {
                offset_mm: chunk[0].offset_mm,
                rattle_space: chunk[0].rattle_space,
                rail_wear_rate_mg_per_h: rate,
            });
            rates.push(by_seed);
        }
        Ok(SweepOutcome {
            design_rattle_space: self.design_rattle_space,
            points,
            seeds: self.seeds.clone(),
            rate_by_seed_mg_per_h: rates,
        })
    }
}

/// Point `index` of a planned sweep: the base case with the design dimensions moved by the
/// point's material-condition offset, run to the end; the rail's wear rate there. The
/// sequential [`sweep_job`] and a fanned-out sweep's `sweep_point` child jobs both call this, so a
/// point depends only on the sweep's params and seed.
pub fn sweep_point(
    plan: &SweepPlan,
    index: usize,
    replica: usize,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<SweepPoint, RunError> {
    sweep_point_from(plan, index, replica, configs_dir, control, None)
}

/// [`sweep_point`] resuming from `resume`, a checkpoint of this point's run
/// (`RunError::Checkpointed`), as a simulate job does.
pub fn sweep_point_from(
    plan: &SweepPlan,
    index: usize,
    replica: usize,
    configs_dir: &Path,
    control: &RunControl,
    resume: Option<super::SavedRun<'_>>,
) -> Result<SweepPoint, RunError> {
    let offset_mm = *plan
        .offsets_mm
        .get(index)
        .ok_or_else(|| FieldError::new("point", format!("must be below {}", plan.len())))?;
    let seed = *plan
        .seeds
        .get(replica)
        .ok_or_else(|| FieldError::new("replica", format!("must be below {}", plan.seeds.len())))?;
    let mut case = plan.base.clone();
    case.simulation.seed = seed;
    if let Some(l) = case.launcher.as_mut() {
        l.dimensions = plan.range.base.with_material_condition(offset_mm);
    }
    let rattle_space = case
        .launcher
        .as_ref()
        .and_then(|l| l.rattle_space().ok())
        .unwrap_or(f64::NAN);
    // A point needs the run's report, not its packaging (summary JSON, plots): not made.
    let report =
        crate::models::case_run::run_case_model(&case, configs_dir, control, resume)?.report;
    let rail_wear_rate_mg_per_h = report
        .bodies
        .iter()
        .find(|b| b.name == "rail")
        .map(|b| b.mass_rate_mg_per_h)
        .ok_or_else(|| FieldError::new("config", "the launcher model has no body named `rail`"))?;
    Ok(SweepPoint {
        offset_mm: Some(offset_mm),
        rattle_space,
        rail_wear_rate_mg_per_h,
    })
}

/// Result summary of a `sweep_point` child job: its point and replica indices and the run's
/// point, flattened (`{"point", "replica", "offset_mm", "rattle_space",
/// "rail_wear_rate_mg_per_h"}`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SweepPointSummary {
    /// Index of the point in the sweep (tight to loose).
    pub point: usize,
    /// Index of the replica (the seed) at that point.
    pub replica: usize,
    /// The run's point.
    #[serde(flatten)]
    pub sweep: SweepPoint,
}

/// Params of the child job that runs point `index`, replica `replica` of the sweep with
/// `params`: the sweep's params (which carry its seed) plus `"point"` and `"replica"`.
pub fn sweep_point_params(
    params: &serde_json::Value,
    index: usize,
    replica: usize,
) -> serde_json::Value {
    let mut p = params.clone();
    merge_json(
        &mut p,
        &serde_json::json!({ "point": index, "replica": replica }),
    );
    p
}

/// The replica index of a `sweep_point` child job's params (0 when absent: children of
/// sweeps from before seeds were replicated).
pub fn sweep_replica_index(params: &serde_json::Value) -> Result<usize, RunError> {
    match params.get("replica") {
        None => Ok(0),
        Some(v) => v
            .as_u64()
            .map(|i| i as usize)
            .ok_or_else(|| FieldError::new("replica", "must be a non-negative integer").into()),
    }
}

/// The point index of a `sweep_point` child job's params.
pub fn sweep_point_index(params: &serde_json::Value) -> Result<usize, RunError> {
    params
        .get("point")
        .and_then(serde_json::Value::as_u64)
        .map(|i| i as usize)
        .ok_or_else(|| FieldError::new("point", "is required (a non-negative integer)").into())
}

/// A sweep job run in one process: the launcher case of `params` (default `launcher-design`) at
/// `points` (default 5, at least 2) dimension sets from tight to loose ([`SweepRange`]), each
/// with `seeds` seeds (default 3), one after the other; returns the rail wear rate versus rattle space for the penalization curve (eq. 6.4).
/// The service fans the same points out to child jobs instead (see ARCHITECTURE.md).
pub fn sweep_job(
    params: &serde_json::Value,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<(serde_json::Value, SweepOutcome), RunError> {
    let plan = SweepPlan::from_params(params, configs_dir)?;
    run_sweep(&plan, configs_dir, control)
}

/// Runs every point of a planned sweep in this process, tight to loose (see [`sweep_job`]).
pub fn run_sweep(
    plan: &SweepPlan,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<(serde_json::Value, SweepOutcome), RunError> {
    let total = plan.runs() as f64;
    let mut runs = Vec::with_capacity(plan.runs());
    for i in 0..plan.len() {
        for j in 0..plan.seeds.len() {
            if control.is_cancelled() {
                return Err(RunError::Cancelled);
            }
            let done = plan.run_index(i, j) as f64;
            let outer = control.progress.clone();
            // A sequential sweep keeps no checkpoint: a request stops it as cancelled.
            let sub = RunControl::new(
                control.cancel.clone(),
                Arc::new(move |pr: Progress| {
                    outer(Progress {
                        simulated_time_s: pr.simulated_time_s,
                        end_time_s: pr.end_time_s,
                        fraction: (done + pr.fraction) / total,
                    })
                }),
            );
            runs.push(sweep_point(plan, i, j, configs_dir, &sub)?);
        }
    }
    let outcome = plan.outcome(runs)?;
    let summary =
        serde_json::to_value(&outcome).map_err(|e| FieldError::new("sweep", e.to_string()))?;
    Ok((summary, outcome))
}
