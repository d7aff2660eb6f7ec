//! What the job queue runs: [`CaseRunner`], the trait between the queue and a computation (the
//! queue never looks inside one; it hands over kind + params + [`RunControl`] and stores what
//! comes back), and [`LibraryRunner`], the production computation: every job kind through
//! `pipeline`, the library's one door.

pub use super::inputs::{JobInputs, StoredInput};
use super::model::JobKind;
use crate::field_error::FieldError;
use crate::pipeline::{
    plan_from_json, plan_to_json, CalibrateParams, DiagnosePlan, PenalizationCurve, RunControl,
    RunError, SavedRun, SimulatePlan, SweepOutcome, SweepPlan, SweepPointSummary, TrackSample,
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
    /// The child's typed plan as canonical JSON (what [`CaseRunner::run_from`] runs), when the
    /// runner has one; stored with the child like a submitted job's.
    pub plan: Option<serde_json::Value>,
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
/// `plan`, where a method takes it, is what [`CaseRunner::submit_plan`] returned for the job at
/// submission (or the parent's fan-out gave a child), when it returned one: the job is run from
/// it, not from `params`. A job stored without one is planned from its params.
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

    /// [`CaseRunner::run`] from the job's stored `plan`, with the `inputs` the worker read for
    /// it ([`CaseRunner::stored_inputs`]), resuming from `checkpoint`: the bytes of an earlier
    /// attempt's [`RunError::Checkpointed`] for this job with the record chunks its attempts
    /// handed to [`RunControl::record_sink`] before it. A computation that can checkpoint
    /// returns [`RunError::Checkpointed`] at its next step boundary after
    /// [`RunControl::request_checkpoint`], resumes from a checkpoint to the result of an
    /// uninterrupted run, and starts over (saying why) from one that does not fit. The default
    /// has no plans, reads nothing and cannot checkpoint: it runs from the start.
    fn run_from(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        plan: Option<&serde_json::Value>,
        inputs: &JobInputs,
        control: &RunControl,
        checkpoint: Option<SavedRun<'_>>,
    ) -> Result<JobOutput, RunError> {
        let _ = (plan, inputs, checkpoint);
        self.run(kind, params, control)
    }

    /// Check at submission (on a blocking thread) so a bad request gets a 422 naming the field
    /// instead of a failed job: the one parse of the params as submitted
    /// ([`LibraryRunner::plan`]); `seed` is the job's seed (the params' or the one drawn for
    /// it). Returns the job's typed plan as canonical JSON when it has one (seed included):
    /// the queue stores it with the job and hands it to [`CaseRunner::run_from`],
    /// [`CaseRunner::fan_out`] and [`CaseRunner::assemble`], so the job is parsed and checked
    /// once. The default accepts everything and has no plan.
    fn submit_plan(
        &self,
        _kind: &JobKind,
        _params: &serde_json::Value,
        _seed: u64,
    ) -> Result<Option<serde_json::Value>, RunError> {
        Ok(None)
    }

    /// What the job reads from the store when it runs (a diagnosis's campaign): the worker
    /// reads it once per attempt, asynchronously, and hands it to [`CaseRunner::run_from`].
    /// Should be quick (no simulation, no I/O). The default reads nothing.
    fn stored_inputs(
        &self,
        _kind: &JobKind,
        _params: &serde_json::Value,
        _plan: Option<&serde_json::Value>,
    ) -> Result<Vec<StoredInput>, RunError> {
        Ok(Vec::new())
    }

    /// The child jobs this job splits into, or `None` to run it whole with
    /// [`CaseRunner::run`] (the default). Called on a blocking thread; should be quick (no
    /// simulation).
    fn fan_out(
        &self,
        _kind: &JobKind,
        _params: &serde_json::Value,
        _plan: Option<&serde_json::Value>,
    ) -> Result<Option<FanOutPlan>, RunError> {
        Ok(None)
    }

    /// The output of a job that fanned out, from its children's result summaries in index
    /// order (all succeeded). Must depend on `params`, `plan` and the summaries only: if the
    /// worker assembling dies, another assembles again and only one result is stored.
    fn assemble(
        &self,
        kind: &JobKind,
        _params: &serde_json::Value,
        _plan: Option<&serde_json::Value>,
        _children: &[serde_json::Value],
    ) -> Result<JobOutput, RunError> {
        Err(RunError::InvalidConfig {
            field: "kind".into(),
            rule: format!("{} jobs do not fan out", kind.as_str()),
        })
    }
}

/// A job's params parsed and checked for its kind: what the worker runs. Built once, at
/// submission, by [`LibraryRunner::plan`] and stored as its canonical JSON
/// ([`JobPlan::to_json`]); the worker reads it back ([`JobPlan::from_json`]) without checking
/// it again.
#[derive(Debug, Clone)]
pub enum JobPlan {
    /// The case to simulate.
    Simulate(Box<SimulatePlan>),
    /// The sweep to fan out (or run in one process).
    Sweep(Box<SweepPlan>),
    /// One run of a sweep: the sweep's plan, the point's index and the replica (seed) index.
    SweepPoint(Box<SweepPlan>, usize, usize),
    /// The calibration data.
    Calibrate(Box<CalibrateParams>),
    /// The stored campaign to diagnose and how.
    Diagnose(Box<DiagnosePlan>),
}

impl JobPlan {
    /// The run of a sweep that `plan` (a `sweep_point` child's) names.
    fn sweep_point(plan: SweepPlan) -> Result<Self, RunError> {
        let index = plan.point.ok_or_else(|| RunError::InvalidConfig {
            field: "point".into(),
            rule: "is required (a non-negative integer)".into(),
        })?;
        let replica = plan.replica.unwrap_or(0);
        Ok(JobPlan::SweepPoint(Box::new(plan), index, replica))
    }

    /// The plan's canonical JSON, as a job stores it.
    pub fn to_json(&self) -> Result<serde_json::Value, RunError> {
        match self {
            JobPlan::Simulate(plan) => plan_to_json(plan),
            JobPlan::Sweep(plan) | JobPlan::SweepPoint(plan, ..) => plan_to_json(plan),
            JobPlan::Calibrate(plan) => plan_to_json(plan),
            JobPlan::Diagnose(plan) => plan_to_json(plan),
        }
    }

    /// A `kind` job's stored plan, as [`JobPlan::to_json`] wrote it. Errors name `plan`.
    pub fn from_json(kind: &JobKind, value: &serde_json::Value) -> Result<Self, RunError> {
        let name = kind.as_str();
        Ok(match kind {
            JobKind::Simulate => JobPlan::Simulate(Box::new(plan_from_json(value, name)?)),
            JobKind::Sweep => JobPlan::Sweep(Box::new(plan_from_json(value, name)?)),
            JobKind::SweepPoint => JobPlan::sweep_point(plan_from_json(value, name)?)?,
            JobKind::Calibrate => JobPlan::Calibrate(Box::new(plan_from_json(value, name)?)),
            JobKind::Diagnose => JobPlan::Diagnose(Box::new(plan_from_json(value, name)?)),
        })
    }
}

/// The production runner: calls `railwear::pipeline` with reference configs from `configs_dir`.
pub struct LibraryRunner {
    /// Directory of the reference model configs (`configs/`).
    pub configs_dir: PathBuf,
}

impl LibraryRunner {
    /// A runner for the reference configs in `configs_dir`.
    pub fn new(configs_dir: impl Into<PathBuf>) -> Self {
        LibraryRunner {
            configs_dir: configs_dir.into(),
        }
    }

    /// Parse and check `params` for `kind` (the one set of rules; see [`JobPlan`]), the seed
    /// in the params. Errors name the params field (`config`,
    /// `overrides.simulation.duration_s`, `points`, ...).
    pub fn plan(&self, kind: &JobKind, params: &serde_json::Value) -> Result<JobPlan, RunError> {
        self.plan_seeded(kind, params, None)
    }

    /// [`LibraryRunner::plan`] for a job run with `seed` when given (a submitted job's; the
    /// params may lack it): it is set as the case's `simulation.seed` after the config's own
    /// value is checked.
    fn plan_seeded(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        seed: Option<u64>,
    ) -> Result<JobPlan, RunError> {
        let dir = &self.configs_dir;
        match kind {
            JobKind::Simulate => Ok(JobPlan::Simulate(Box::new(match seed {
                Some(seed) => SimulatePlan::from_params(params, dir, seed)?,
                None => SimulatePlan {
                    case: crate::pipeline::simulate_case(params, dir)?,
                },
            }))),
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
                Ok(JobPlan::Sweep(Box::new(SweepPlan::from_params_seeded(
                    params, dir, seed,
                )?)))
            }
            JobKind::SweepPoint => {
                JobPlan::sweep_point(SweepPlan::from_params_seeded(params, dir, seed)?)
            }
            JobKind::Calibrate => Ok(JobPlan::Calibrate(Box::new(CalibrateParams::parse_seeded(
                params, seed,
            )?))),
            JobKind::Diagnose => Ok(JobPlan::Diagnose(Box::new(DiagnosePlan::from_params(
                params,
            )?))),
        }
    }

    /// The job's plan: the `stored` one, or (a job queued before plans were stored) planned
    /// from its params.
    fn job_plan(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        stored: Option<&serde_json::Value>,
    ) -> Result<JobPlan, RunError> {
        match stored {
            Some(stored) => JobPlan::from_json(kind, stored),
            None => self.plan(kind, params),
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
        self.run_from(kind, params, None, &JobInputs::default(), control, None)
    }

    /// Simulate jobs and sweep points checkpoint and resume (`pipeline::run_case_from`);
    /// the other kinds stop as cancelled on a checkpoint request and start over. A simulate
    /// job or sweep point runs its stored plan with one validation and one build.
    fn run_from(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        stored: Option<&serde_json::Value>,
        inputs: &JobInputs,
        control: &RunControl,
        checkpoint: Option<SavedRun<'_>>,
    ) -> Result<JobOutput, RunError> {
        let plan = self.job_plan(kind, params, stored)?;
        let control = &match plan {
            JobPlan::Simulate(_) | JobPlan::SweepPoint(..) => control.clone(),
            _ => control.without_checkpoint(),
        };
        match plan {
            JobPlan::Simulate(plan) => {
                let (_, out) = crate::pipeline::run_case_from(
                    &plan.case,
                    &self.configs_dir,
                    control,
                    checkpoint,
                )?;
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
            JobPlan::Diagnose(plan) => {
                let content = inputs.campaign.as_deref().ok_or_else(|| {
                    FieldError::new(
                        "campaign_id",
                        "was not read: diagnoses run in the service's workers, which read the \
                         stored campaign",
                    )
                })?;
                let done =
                    crate::pipeline::run_diagnosis(&plan, content, &self.configs_dir, control)?;
                Ok(JobOutput {
                    summary: done.report,
                    plots: done.plots,
                    ..JobOutput::default()
                })
            }
        }
    }

    fn submit_plan(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        seed: u64,
    ) -> Result<Option<serde_json::Value>, RunError> {
        self.plan_seeded(kind, params, Some(seed))?
            .to_json()
            .map(Some)
    }

    /// A diagnosis reads its campaign.
    fn stored_inputs(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        stored: Option<&serde_json::Value>,
    ) -> Result<Vec<StoredInput>, RunError> {
        if *kind != JobKind::Diagnose {
            return Ok(Vec::new());
        }
        let JobPlan::Diagnose(plan) = self.job_plan(kind, params, stored)? else {
            return Ok(Vec::new());
        };
        Ok(vec![StoredInput::Campaign {
            id: plan.campaign_id,
            sha256: plan.campaign_sha256,
        }])
    }

    /// A sweep fans out into one `sweep_point` child per point and seed (point-major), each
    /// with the sweep's plan naming its point and replica.
    fn fan_out(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        stored: Option<&serde_json::Value>,
    ) -> Result<Option<FanOutPlan>, RunError> {
        if *kind != JobKind::Sweep {
            return Ok(None);
        }
        let JobPlan::Sweep(plan) = self.job_plan(kind, params, stored)? else {
            return Ok(None);
        };
        let seeds = plan.seeds.len();
        let children = (0..plan.runs())
            .map(|run| {
                let (point, replica) = (run / seeds, run % seeds);
                let child = SweepPlan {
                    point: Some(point),
                    replica: Some(replica),
                    ..(*plan).clone()
                };
                Ok(ChildJob {
                    kind: JobKind::SweepPoint,
                    params: crate::pipeline::sweep_point_params(params, point, replica),
                    plan: Some(plan_to_json(&child)?),
                })
            })
            .collect::<Result<Vec<_>, RunError>>()?;
        Ok(Some(FanOutPlan {
            children,
            end_time_s: plan.runs() as f64 * plan.point_end_time_s(),
        }))
    }

    /// A sweep's outcome from its points' results, exactly as the sequential sweep makes it.
    fn assemble(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        stored: Option<&serde_json::Value>,
        children: &[serde_json::Value],
    ) -> Result<JobOutput, RunError> {
        let JobPlan::Sweep(plan) = self.job_plan(kind, params, stored)? else {
            return Err(RunError::InvalidConfig {
                field: "kind".into(),
                rule: format!("{} jobs do not fan out", kind.as_str()),
            });
        };
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

/// A sweep job's output from its outcome (sequential or assembled): the outcome as summary, the
/// penalization curve (eq. 6.4) with the rates of each seed, its plot, fidelity and
/// provenance ([`crate::pipeline::sweep_curve`]).
pub fn sweep_output(
    plan: &SweepPlan,
    params: &serde_json::Value,
    sweep: &SweepOutcome,
) -> Result<JobOutput, RunError> {
    let made = crate::pipeline::sweep_curve(plan, params, sweep)?;
    Ok(JobOutput {
        summary: made.summary,
        tracks: Vec::new(),
        plots: vec![made.plot],
        penalization: Some(made.curve),
        curve_info: Some(CurveInfo {
            fidelity: crate::store::CurveFidelity {
                points: made.points as i64,
                duration_per_point_s: Some(made.duration_per_point_s),
                seeds: made.seeds as i64,
            },
            provenance: made.provenance,
        }),
    })
}
