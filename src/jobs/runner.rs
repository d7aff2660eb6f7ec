//! The one narrow interface between the job queue and the simulation library: [`CaseRunner`].
//! The queue never looks inside a computation; it hands over kind + params + [`RunControl`] and
//! stores what comes back.

use super::model::JobKind;
use crate::analysis::penalization::PenalizationCurve;
use crate::field_error::FieldError;
use crate::models::spec::CaseSpec;
use crate::physics::track::TrackSample;
use crate::pipeline::{
    CalibrateParams, RunControl, RunError, SimulatePlan, SweepOutcome, SweepPlan, SweepPointSummary,
};
use std::path::PathBuf;

/// What a finished job produces.
#[derive(Debug, Clone, Default)]
pub struct JobOutput {
    /// Result summary (JSON object): wear per contact and body, pressure PDFs, spectra,
    /// settings used.
    pub summary: serde_json::Value,
    /// Contact-track samples to store.
    pub tracks: Vec<TrackSample>,
    /// SVG plots: (file name, SVG text).
    pub plots: Vec<(String, String)>,
    /// Sweeps: the penalization curve (eq. 6.4, Figure 6.68), stored under the job's curve key
    /// as a new, unpublished version.
    pub penalization: Option<PenalizationCurve>,
    /// Sweeps: the curve's fidelity and provenance (the worker adds who and which code).
    pub curve_info: Option<CurveInfo>,
}

/// What a sweep tells about the curve it made, beyond the curve itself.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveInfo {
    /// Points, excited duration per point and seeds per point.
    pub fidelity: crate::store::CurveFidelity,
    /// Provenance (JSON object): config, vehicle_profile, environment, wear_law, range,
    /// offsets, base dimensions, settle, seeds.
    pub provenance: serde_json::Value,
}

/// A child job of a fan-out: what to run.
#[derive(Debug, Clone, PartialEq)]
pub struct ChildJob {
    pub kind: JobKind,
    /// Complete params of the child (they carry the parent's seed): the child's result depends
    /// on them alone.
    pub params: serde_json::Value,
}

/// How a job splits into child jobs that any worker (any process, any host) can run.
#[derive(Debug, Clone, PartialEq)]
pub struct FanOutPlan {
    /// The children, in index order; the parent's result is assembled from their results in
    /// this order.
    pub children: Vec<ChildJob>,
    /// Simulated time all children reach together, s (the parent's progress end time).
    pub end_time_s: f64,
}

/// Runs one job's computation on a blocking thread. Must return [`RunError::Cancelled`] within
/// a second of `control.cancel` being set, and should call `control.progress` a few times per
/// second at most. `params` carry the job's `seed`.
///
/// A job may instead fan out ([`CaseRunner::fan_out`]): the queue then stores the child jobs,
/// and once every child has succeeded one worker calls [`CaseRunner::assemble`] with their
/// results.
pub trait CaseRunner: Send + Sync {
    fn run(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        control: &RunControl,
    ) -> Result<JobOutput, RunError>;

    /// [`CaseRunner::run`] resuming from `checkpoint`, the bytes of an earlier attempt's
    /// [`RunError::Checkpointed`] for this job. A computation that can checkpoint returns
    /// [`RunError::Checkpointed`] at its next step boundary after
    /// [`RunControl::request_checkpoint`], resumes from a checkpoint to the result of an
    /// uninterrupted run, and starts over (saying why) from one that does not fit. The default
    /// cannot checkpoint: it ignores `checkpoint` and runs from the start.
    ///
    /// `plan` is what [`CaseRunner::submit_plan`] returned for this job at submission, when it
    /// returned one: the job is run from it, not from `params`. The default has no plans.
    fn run_from(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        plan: Option<&serde_json::Value>,
        control: &RunControl,
        checkpoint: Option<&[u8]>,
    ) -> Result<JobOutput, RunError> {
        let _ = (plan, checkpoint);
        self.run(kind, params, control)
    }

    /// Check at submission (on a blocking thread) so a bad request gets a 422 naming the field
    /// instead of a failed job: the same parse [`CaseRunner::run`] does
    /// ([`LibraryRunner::plan`]) of the params as submitted; `seed` is the job's seed (the
    /// params' or the one drawn for it). Returns the job's typed plan as canonical JSON when
    /// its kind has one (a simulate job's [`SimulatePlan`], seed included): the queue stores it
    /// with the job and hands it to [`CaseRunner::run_from`], so the job is parsed and checked
    /// once. The default accepts everything and has no plan.
    fn submit_plan(
        &self,
        _kind: &JobKind,
        _params: &serde_json::Value,
        _seed: u64,
    ) -> Result<Option<serde_json::Value>, RunError> {
        Ok(None)
    }

    /// The store this runner's jobs read their stored inputs from (a diagnosis's campaign);
    /// `Jobs::new` calls it with the queue's store. The default reads nothing.
    fn bind_store(&self, _store: std::sync::Arc<dyn crate::store::Store>) {}

    /// The child jobs this job splits into, or `None` to run it whole with
    /// [`CaseRunner::run`] (the default). Called on a blocking thread; should be quick (no
    /// simulation).
    fn fan_out(
        &self,
        _kind: &JobKind,
        _params: &serde_json::Value,
    ) -> Result<Option<FanOutPlan>, RunError> {
        Ok(None)
    }

    /// The output of a job that fanned out, from its children's result summaries in index
    /// order (all succeeded). Must depend on `params` and the summaries only: if the worker
    /// assembling dies, another assembles again and only one result is stored.
    fn assemble(
        &self,
        kind: &JobKind,
        _params: &serde_json::Value,
        _children: &[serde_json::Value],
    ) -> Result<JobOutput, RunError> {
        Err(RunError::InvalidConfig {
            field: "kind".into(),
            rule: format!("{} jobs do not fan out", kind.as_str()),
        })
    }
}

/// A job's params parsed and checked for its kind: what the worker runs. Built by
/// [`LibraryRunner::plan`], which submission ([`CaseRunner::submit_plan`]) and the worker call,
/// so an accepted job's params are never re-interpreted by a second set of rules.
#[derive(Debug, Clone)]
pub enum JobPlan {
    /// The case to simulate.
    Simulate(Box<CaseSpec>),
    /// The sweep to fan out (or run in one process).
    Sweep(Box<SweepPlan>),
    /// One run of a sweep: the sweep's plan, the point's index and the replica (seed) index.
    SweepPoint(Box<SweepPlan>, usize, usize),
    /// The calibration data.
    Calibrate(CalibrateParams),
    /// The campaign to diagnose and how.
    Diagnose(Box<DiagnosePlan>),
}

/// A `diagnose` job, parsed: the campaign (read from the store by the id in the params and
/// checked against their SHA-256) and the options.
#[derive(Debug, Clone)]
pub struct DiagnosePlan {
    pub campaign: crate::gap::Campaign,
    pub options: crate::gap::diagnose::DiagnoseOptions,
}

/// Params a client may give a diagnosis (`POST /v1/campaigns/{id}/diagnoses`).
pub const DIAGNOSE_CLIENT_KEYS: &[&str] =
    &["window_s", "settle_s", "grid_points", "effects", "seed"];

/// Params of a stored `diagnose` job: the client's plus the campaign's id and the SHA-256 of
/// its content, which the service adds at submission.
pub const DIAGNOSE_KEYS: &[&str] = &[
    "campaign_id",
    "campaign_sha256",
    "window_s",
    "settle_s",
    "grid_points",
    "effects",
    "seed",
];

impl DiagnosePlan {
    /// Parse a `diagnose` job's params and read its campaign from `inputs`. Errors name the
    /// params field.
    pub fn from_params(
        params: &serde_json::Value,
        configs_dir: &std::path::Path,
        inputs: &super::inputs::StoredInputs,
    ) -> Result<Self, RunError> {
        let map = params
            .as_object()
            .ok_or_else(|| FieldError::new("params", "must be a JSON object"))?;
        for key in map.keys() {
            if !DIAGNOSE_KEYS.contains(&key.as_str()) {
                return Err(FieldError::new(
                    key,
                    format!(
                        "is not a known parameter (known: {})",
                        DIAGNOSE_CLIENT_KEYS.join(", ")
                    ),
                )
                .into());
            }
        }
        let submit_here = "is required (submit through POST /v1/campaigns/{id}/diagnoses)";
        let campaign_id = map
            .get("campaign_id")
            .ok_or_else(|| FieldError::new("campaign_id", submit_here))?
            .as_str()
            .and_then(|s| uuid::Uuid::parse_str(s).ok())
            .ok_or_else(|| FieldError::new("campaign_id", "must be a campaign's UUID"))?;
        let is_sha256 =
            |s: &&str| s.len() == 64 && s.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'));
        let sha256 = map
            .get("campaign_sha256")
            .ok_or_else(|| FieldError::new("campaign_sha256", submit_here))?
            .as_str()
            .filter(is_sha256)
            .ok_or_else(|| {
                FieldError::new("campaign_sha256", "must be 64 lower-case hex digits")
            })?;
        let content = inputs.campaign(campaign_id, sha256)?;
        let campaign = crate::gap::Campaign::from_json_str(&content)
            .and_then(|c| c.validate(configs_dir).map(|_| c))
            .map_err(|e| {
                FieldError::new(
                    "campaign_id",
                    format!("names a campaign that no longer checks out against the configs: {e}"),
                )
            })?;
        let mut options = crate::gap::diagnose::DiagnoseOptions::default();
        // Types here; bounds in the one rule set, `gap::diagnose::check_options`, below.
        let number = |name: &str| -> Result<Option<f64>, RunError> {
            map.get(name)
                .map(|value| {
                    value
                        .as_f64()
                        .ok_or_else(|| FieldError::new(name, "must be a number of seconds").into())
                })
                .transpose()
        };
        if let Some(x) = number("window_s")? {
            options.emulator.window_s = x;
        }
        if let Some(x) = number("settle_s")? {
            options.emulator.settle_s = x;
        }
        if let Some(value) = map.get("grid_points") {
            let n = value
                .as_u64()
                .ok_or_else(|| FieldError::new("grid_points", "must be an integer in 2..=12"))?;
            options.emulator.grid_points = usize::try_from(n).unwrap_or(usize::MAX);
        }
        if let Some(value) = map.get("effects") {
            let names: Vec<String> = serde_json::from_value(value.clone())
                .map_err(|_| FieldError::new("effects", "must be a list of effect names"))?;
            if names.is_empty() {
                return Err(FieldError::new("effects", "must name at least one effect").into());
            }
            let library = crate::gap::effects::LIBRARY;
            for (i, name) in names.iter().enumerate() {
                if !library.iter().any(|e| e.name == name) {
                    let known: Vec<&str> = library.iter().map(|e| e.name).collect();
                    return Err(FieldError::new(
                        format!("effects[{i}]"),
                        format!(
                            "`{name}` is not a library effect (known: {})",
                            known.join(", ")
                        ),
                    )
                    .into());
                }
            }
            options.emulator.effects = Some(names);
        }
        crate::gap::diagnose::check_options(&options).map_err(|e| match e {
            crate::gap::GapError::Field { field, rule } => FieldError::new(field, rule),
            other => FieldError::new("params", other.to_string()),
        })?;
        Ok(Self { campaign, options })
    }
}

/// The production runner: calls `railwear::pipeline` with reference configs from `configs_dir`.
pub struct LibraryRunner {
    /// Directory of the reference model configs (`configs/`).
    pub configs_dir: PathBuf,
    /// Where a diagnosis reads its campaign (bound to the queue's store by `Jobs::new`).
    pub inputs: super::inputs::StoredInputs,
}

impl LibraryRunner {
    /// A runner for the reference configs in `configs_dir`, not yet bound to a store.
    pub fn new(configs_dir: impl Into<PathBuf>) -> Self {
        LibraryRunner {
            configs_dir: configs_dir.into(),
            inputs: super::inputs::StoredInputs::default(),
        }
    }

    /// Parse and check `params` for `kind` (the one set of rules; see [`JobPlan`]). Errors
    /// name the params field (`config`, `overrides.simulation.duration_s`, `points`, ...).
    pub fn plan(&self, kind: &JobKind, params: &serde_json::Value) -> Result<JobPlan, RunError> {
        let dir = &self.configs_dir;
        match kind {
            JobKind::Simulate => Ok(JobPlan::Simulate(Box::new(crate::pipeline::simulate_case(
                params, dir,
            )?))),
            JobKind::Sweep => {
                if params.get("point").is_some() {
                    return Err(RunError::InvalidConfig {
                        field: "point".into(),
                        rule: format!(
                            "is not a known parameter (known: {})",
                            crate::pipeline::SWEEP_KEYS.join(", ")
                        ),
                    });
                }
                Ok(JobPlan::Sweep(Box::new(SweepPlan::from_params(
                    params, dir,
                )?)))
            }
            JobKind::SweepPoint => {
                let plan = SweepPlan::from_params(params, dir)?;
                let index = plan.point.ok_or_else(|| RunError::InvalidConfig {
                    field: "point".into(),
                    rule: "is required (a non-negative integer)".into(),
                })?;
                let replica = plan.replica.unwrap_or(0);
                Ok(JobPlan::SweepPoint(Box::new(plan), index, replica))
            }
            JobKind::Calibrate => Ok(JobPlan::Calibrate(CalibrateParams::parse(params)?)),
            JobKind::Diagnose => Ok(JobPlan::Diagnose(Box::new(DiagnosePlan::from_params(
                params,
                dir,
                &self.inputs,
            )?))),
        }
    }
}

impl CaseRunner for LibraryRunner {
    fn run(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        control: &RunControl,
    ) -> Result<JobOutput, RunError> {
        self.run_from(kind, params, None, control, None)
    }

    /// Simulate jobs and sweep points checkpoint and resume (`pipeline::run_case_from`);
    /// the other kinds stop as cancelled on a checkpoint request and start over. A simulate
    /// job with its stored [`SimulatePlan`] runs it (one validation and one build); without one
    /// (a job queued before plans were stored) it is planned from its params first.
    fn run_from(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        stored: Option<&serde_json::Value>,
        control: &RunControl,
        checkpoint: Option<&[u8]>,
    ) -> Result<JobOutput, RunError> {
        let plan = match (kind, stored) {
            (JobKind::Simulate, Some(stored)) => {
                JobPlan::Simulate(Box::new(SimulatePlan::from_json(stored)?.case))
            }
            _ => self.plan(kind, params)?,
        };
        let control = &match plan {
            JobPlan::Simulate(_) | JobPlan::SweepPoint(..) => control.clone(),
            _ => control.without_checkpoint(),
        };
        match plan {
            JobPlan::Simulate(case) => {
                let (_, out) =
                    crate::pipeline::run_case_from(&case, &self.configs_dir, control, checkpoint)?;
                Ok(JobOutput {
                    summary: out.summary,
                    tracks: out.tracks,
                    plots: out.plots,
                    ..JobOutput::default()
                })
            }
            JobPlan::Sweep(plan) => {
                let (_, sweep) = crate::pipeline::run_sweep(&plan, &self.configs_dir, control)?;
                sweep_output(&plan, params, &sweep)
            }
            JobPlan::SweepPoint(plan, index, replica) => {
                let point = crate::pipeline::sweep_point_from(
                    &plan,
                    index,
                    replica,
                    &self.configs_dir,
                    control,
                    checkpoint,
                )?;
                let summary = SweepPointSummary {
                    point: index,
                    replica,
                    sweep: point,
                };
                let summary =
                    serde_json::to_value(summary).map_err(|e| RunError::InvalidConfig {
                        field: "summary".into(),
                        rule: format!("could not be serialized: {e}"),
                    })?;
                Ok(JobOutput {
                    summary,
                    ..JobOutput::default()
                })
            }
            JobPlan::Calibrate(data) => Ok(JobOutput {
                summary: crate::pipeline::run_calibration(&data)?,
                ..JobOutput::default()
            }),
            JobPlan::Diagnose(plan) => run_diagnosis(&plan, &self.configs_dir, control),
        }
    }

    fn submit_plan(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        seed: u64,
    ) -> Result<Option<serde_json::Value>, RunError> {
        match kind {
            JobKind::Simulate => SimulatePlan::from_params(params, &self.configs_dir, seed)?
                .to_json()
                .map(Some),
            _ => self.plan(kind, params).map(|_| None),
        }
    }

    fn bind_store(&self, store: std::sync::Arc<dyn crate::store::Store>) {
        self.inputs.bind(store);
    }

    /// A sweep fans out into one `sweep_point` child per point and seed (point-major).
    fn fan_out(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
    ) -> Result<Option<FanOutPlan>, RunError> {
        if *kind != JobKind::Sweep {
            return Ok(None);
        }
        let JobPlan::Sweep(plan) = self.plan(kind, params)? else {
            return Ok(None);
        };
        let seeds = plan.seeds.len();
        Ok(Some(FanOutPlan {
            children: (0..plan.runs())
                .map(|run| ChildJob {
                    kind: JobKind::SweepPoint,
                    params: crate::pipeline::sweep_point_params(params, run / seeds, run % seeds),
                })
                .collect(),
            end_time_s: plan.runs() as f64 * plan.point_end_time_s(),
        }))
    }

    /// A sweep's outcome from its points' results, exactly as the sequential sweep makes it.
    fn assemble(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        children: &[serde_json::Value],
    ) -> Result<JobOutput, RunError> {
        if *kind != JobKind::Sweep {
            return Err(RunError::InvalidConfig {
                field: "kind".into(),
                rule: format!("{} jobs do not fan out", kind.as_str()),
            });
        }
        let plan = SweepPlan::from_params(params, &self.configs_dir)?;
        if children.len() != plan.runs() {
            return Err(RunError::InvalidConfig {
                field: "points".into(),
                rule: format!(
                    "the sweep has {} runs but {} child results",
                    plan.runs(),
                    children.len()
                ),
            });
        }
        let points = children
            .iter()
            .enumerate()
            .map(|(index, summary)| {
                serde_json::from_value::<SweepPointSummary>(summary.clone())
                    .map(|child| child.sweep)
                    .map_err(|e| RunError::InvalidConfig {
                        field: format!("children[{index}]"),
                        rule: format!("is not a sweep point result: {e}"),
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        sweep_output(&plan, params, &plan.outcome(points)?)
    }
}

/// Runs a diagnosis: progress is the fraction of its test simulations done (reported as
/// `simulated_time_s` = simulations done of `end_time_s` = simulations in all); the summary is
/// the report, the plots its figures.
pub fn run_diagnosis(
    plan: &DiagnosePlan,
    configs_dir: &std::path::Path,
    control: &RunControl,
) -> Result<JobOutput, RunError> {
    // The window simulations see the cancel flag but not the progress sink: the job's progress
    // counts simulations, not one window's simulated time.
    // Its windows keep no checkpoint: a request stops the diagnosis as cancelled.
    let inner = RunControl::new(control.cancel.clone(), std::sync::Arc::new(|_| {}));
    let report_progress = |done: usize, total: usize| {
        let total = total.max(1);
        (control.progress)(crate::physics::control::Progress {
            simulated_time_s: done as f64,
            end_time_s: total as f64,
            fraction: (done as f64 / total as f64).clamp(0.0, 1.0),
        });
    };
    let cache = crate::gap::window::WindowCache::new();
    let (report, _) = crate::gap::diagnose::diagnose(
        &plan.campaign,
        configs_dir,
        &plan.options,
        &inner,
        &cache,
        &report_progress,
    )
    .map_err(|e| {
        if control.is_cancelled() {
            RunError::Cancelled
        } else {
            match e {
                crate::gap::GapError::Field { field, rule } => {
                    RunError::InvalidConfig { field, rule }
                }
                other => RunError::Diverged(other.to_string()),
            }
        }
    })?;
    let summary = serde_json::to_value(&report).map_err(|e| RunError::InvalidConfig {
        field: "report".into(),
        rule: format!("could not be serialized: {e}"),
    })?;
    Ok(JobOutput {
        summary,
        plots: crate::gap::diagnose::plots::plots(&report),
        ..JobOutput::default()
    })
}

/// A sweep job's output from its outcome (sequential or assembled): the outcome as summary, the
/// penalization curve (eq. 6.4) with the rates of each seed, its plot, fidelity and
/// provenance.
pub fn sweep_output(
    plan: &SweepPlan,
    params: &serde_json::Value,
    sweep: &SweepOutcome,
) -> Result<JobOutput, RunError> {
    let ks: Vec<f64> = sweep.points.iter().map(|p| p.rattle_space).collect();
    let rates: Vec<Vec<f64>> = if sweep.rate_by_seed_mg_per_h.len() == ks.len() {
        sweep.rate_by_seed_mg_per_h.clone()
    } else {
        sweep
            .points
            .iter()
            .map(|p| vec![p.rail_wear_rate_mg_per_h])
            .collect()
    };
    let curve =
        PenalizationCurve::from_seeds(&ks, &rates, sweep.design_rattle_space).map_err(|e| {
            RunError::Diverged(format!("sweep produced no usable penalization curve: {e}"))
        })?;
    let (k_min, k_max) = plan.range.rattle_space_bounds();
    let config = match params.get("config") {
        None => serde_json::Value::from("launcher-design"),
        Some(serde_json::Value::String(name)) => serde_json::Value::from(name.as_str()),
        Some(_) => serde_json::Value::from("inline"),
    };
    let curve_info = CurveInfo {
        fidelity: crate::store::CurveFidelity {
            points: plan.len() as i64,
            duration_per_point_s: Some(plan.duration_per_point_s()),
            seeds: plan.seeds.len() as i64,
        },
        provenance: serde_json::json!({
            "config": config,
            "overrides": params.get("overrides").cloned().unwrap_or(serde_json::Value::Null),
            "vehicle_profile": plan.vehicle_profile,
            "environment": plan.environment,
            "wear_law": plan.wear_law,
            "diagnosed_wear_law": plan.diagnosed,
            "points": plan.len(),
            "duration_per_point_s": plan.duration_per_point_s(),
            "settle_s": plan.base.simulation.settle_s,
            "seeds": plan.seeds,
            "rattle_space_range": {"min": k_min, "max": k_max},
            "offsets_mm": plan.offsets_mm,
            "base_dimensions_mm": plan.range.base,
            "design_base": plan.range.design_base,
        }),
    };
    let plot = crate::report::curve_plot(&curve);
    let summary = serde_json::to_value(sweep).map_err(|e| RunError::InvalidConfig {
        field: "sweep".into(),
        rule: e.to_string(),
    })?;
    Ok(JobOutput {
        summary,
        tracks: Vec::new(),
        plots: vec![("penalization.svg".to_string(), plot)],
        penalization: Some(curve),
        curve_info: Some(curve_info),
    })
}
