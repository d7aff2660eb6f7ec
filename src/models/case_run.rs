//! A case run: builds the model of a case ([`super::case`]), resumes it from a checkpoint when
//! one fits ([`super::checkpoint`]) and runs it ([`super::run`]); a checkpoint request ends it
//! with the checkpoint kept. Packaging the finished run (summary JSON, plots) is
//! [`crate::report`]'s; `pipeline::run_case` does both.

use super::case::{build, run_options};
use super::checkpoint::{self, RunIdentity};
use super::outcome::{RunError, SavedRun};
use super::run::{run_model_from, BuiltModel, ModelRunError, RunOptions, RunReport};
use super::spec::CaseSpec;
use crate::physics::control::RunControl;
use crate::physics::simulate::SimError;
use std::path::Path;

/// A finished case run: the model it ran, its options and its raw report.
pub struct CaseRun {
    /// The model built from the case.
    pub model: BuiltModel,
    /// The case's run options.
    pub options: RunOptions,
    /// The run's report, with `resumed_from_s` set when it resumed from a checkpoint.
    pub report: RunReport,
}

/// Builds and runs a case, resuming from `resume` (the bytes of a [`RunError::Checkpointed`] of
/// the same case and code, with the record chunks written before it) when it fits; a checkpoint that does not is logged and the run restarts
/// from t = 0. A checkpoint request ([`RunControl::request_checkpoint`]) ends the run with
/// [`RunError::Checkpointed`] at its next accepted step.
pub fn run_case_model(
    case: &CaseSpec,
    configs_dir: &Path,
    control: &RunControl,
    resume: Option<SavedRun<'_>>,
) -> Result<CaseRun, RunError> {
    let model = build(case, configs_dir)?;
    let options = run_options(case)?;
    let identity = RunIdentity::of(case, &model, configs_dir);
    let resume = resume.and_then(|saved| match checkpoint::decode(
        saved.checkpoint,
        &identity,
        saved.record_chunks,
    ) {
        Ok(cp) => {
            tracing::info!(case = %case.name, time_s = cp.time_s(), "resuming from checkpoint");
            Some(cp)
        }
        Err(reason) => {
            tracing::warn!(case = %case.name, %reason, "checkpoint not used: the run restarts from t = 0");
            None
        }
    });
    let mut resumed_from_s = resume.as_ref().map(|cp| cp.time_s());
    let run = match run_model_from(&model, &options, control, resume) {
        Err(ModelRunError::Sim(SimError::BadCheckpoint(reason))) => {
            // Refused before the first step: nothing of it was used.
            tracing::warn!(case = %case.name, %reason, "checkpoint not used: the run restarts from t = 0");
            resumed_from_s = None;
            run_model_from(&model, &options, control, None)
        }
        other => other,
    };
    let mut report = match run {
        Ok(report) => report,
        Err(ModelRunError::Checkpointed(cp)) => {
            return Err(match checkpoint::encode(&identity, &cp) {
                Ok(saved) => RunError::Checkpointed(Box::new(saved)),
                Err(e) => {
                    tracing::warn!(case = %case.name, error = %e, "stopped without a checkpoint");
                    RunError::Cancelled
                }
            })
        }
        Err(e) => return Err(e.into()),
    };
    report.resumed_from_s = resumed_from_s;
    Ok(CaseRun {
        model,
        options,
        report,
    })
}
