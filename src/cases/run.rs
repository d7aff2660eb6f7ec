//! Running a case to its packaged outcome, the entry every caller uses (jobs, sweeps,
//! validation, the CLI): the model's run ([`crate::models::case_run`], which builds the case and
//! resumes from a checkpoint when one fits) packaged by [`crate::report::package_run`].

use crate::models::case_run::run_case_model;
use crate::models::outcome::{CaseOutcome, RunError, SavedRun};
use crate::models::run::RunReport;
use crate::models::spec::CaseSpec;
use crate::physics::control::RunControl;
use crate::report::package_run;
use std::path::Path;

/// Builds and runs a case; returns the raw report and the packaged outcome.
pub fn run_case(
    case: &CaseSpec,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<(RunReport, CaseOutcome), RunError> {
    run_case_from(case, configs_dir, control, None)
}

/// [`run_case`], resuming from `resume` (the bytes of a [`RunError::Checkpointed`] of the
/// same case and code, with the record chunks written before it) when it fits; a checkpoint that does not is logged and the run restarts
/// from t = 0. A checkpoint request ([`RunControl::request_checkpoint`]) ends the run with
/// [`RunError::Checkpointed`] at its next accepted step.
pub fn run_case_from(
    case: &CaseSpec,
    configs_dir: &Path,
    control: &RunControl,
    resume: Option<SavedRun<'_>>,
) -> Result<(RunReport, CaseOutcome), RunError> {
    let run = run_case_model(case, configs_dir, control, resume)?;
    Ok(package_run(case, run))
}
