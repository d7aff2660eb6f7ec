//! A case run to its packaged outcome: builds the model ([`crate::models::case`]), runs it
//! (resuming from a checkpoint when one fits) and writes the summary JSON, the tracks and the
//! plots ([`super::plots`]).

use super::plots::case_plots;
use crate::analysis::spectra::welch_psd;
use crate::analysis::vdv::vibration_dose_value_uniform;
use crate::models::case::{build, code_version, run_options};
use crate::models::checkpoint::{self, RunIdentity};
use crate::models::outcome::{CaseOutcome, RunError};
use crate::models::run::{run_model_from, BuiltModel, ModelRunError, RunOptions, RunReport};
use crate::models::spec::{CaseSpec, ModelSpecRef};
use crate::physics::control::RunControl;
use crate::physics::simulate::SimError;
use serde_json::{json, Value};
use std::path::Path;

/// Builds and runs a case; returns the raw report and the packaged outcome.
pub fn run_case(
    case: &CaseSpec,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<(RunReport, CaseOutcome), RunError> {
    run_case_from(case, configs_dir, control, None)
}

/// [`run_case`], resuming from `resume` (bytes of a [`RunError::Checkpointed`] of the same
/// case and code) when it fits; a checkpoint that does not is logged and the run restarts
/// from t = 0. A checkpoint request ([`RunControl::request_checkpoint`]) ends the run with
/// [`RunError::Checkpointed`] at its next accepted step.
pub fn run_case_from(
    case: &CaseSpec,
    configs_dir: &Path,
    control: &RunControl,
    resume: Option<&[u8]>,
) -> Result<(RunReport, CaseOutcome), RunError> {
    let model = build(case, configs_dir)?;
    let options = run_options(case)?;
    let identity = RunIdentity::of(case, &model, configs_dir);
    let resume = resume.and_then(|bytes| match checkpoint::decode(bytes, &identity) {
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
    // The track samples move to the outcome (the report's `tracks` is left empty): a long run
    // holds them once (a 60 s launcher run records ~0.7 million).
    let tracks = std::mem::take(&mut report.tracks);
    let (summary, plots) = package_parts(case, &model, &options, &report, tracks.len());
    Ok((
        report,
        CaseOutcome {
            summary,
            tracks,
            plots,
        },
    ))
}

/// Summary JSON and plots of a finished run.
pub fn package(
    case: &CaseSpec,
    model: &BuiltModel,
    options: &RunOptions,
    r: &RunReport,
) -> CaseOutcome {
    let (summary, plots) = package_parts(case, model, options, r, r.tracks.len());
    CaseOutcome {
        summary,
        tracks: r.tracks.clone(),
        plots,
    }
}

/// The summary JSON and the plots of a finished run with `track_samples` recorded samples.
fn package_parts(
    case: &CaseSpec,
    model: &BuiltModel,
    options: &RunOptions,
    r: &RunReport,
    track_samples: usize,
) -> (Value, Vec<(String, String)>) {
    let simulated = model.end_time_s;
    let rattle_space = match case.model_spec() {
        Ok(ModelSpecRef::RattleBox(s)) => s.rattle_space().ok(),
        Ok(ModelSpecRef::Launcher(s)) => s.rattle_space().ok(),
        _ => None,
    };
    let dt = 1.0 / r.response_rate_hz;
    let resp_x: Vec<f64> = r.response_acceleration.iter().map(|a| a[0]).collect();
    let vdv = vibration_dose_value_uniform(&resp_x, dt).ok();
    let psd = welch_psd(&resp_x, r.response_rate_hz, 512.min(resp_x.len().max(4))).ok();
    let summary = json!({
        "name": case.name,
        "model": case.model,
        "code_version": code_version(),
        "seed": case.simulation.seed,
        "config": case,
        "rattle_space": rattle_space,
        "integrator": {
            "kind": options.integrator.kind.name(),
            "tolerances": options.integrator.tolerances,
            "stats": r.integrator,
            "note": "wall-clock timings are kept out of the summary so results are reproducible; the job record holds durations",
        },
        "simulated_s": simulated,
        "window_s": r.window_s,
        "mean_normal_force_n": r.mean_normal_force_n,
        "mean_friction_power_w": r.mean_friction_power_w,
        "contacts": r.contacts,
        "bodies": r.bodies,
        "energy": r.energy,
        "response": {
            "body": model.system.bodies[model.response_body].name,
            "vdv_x_m_s2": vdv,
            "psd_x": psd.as_ref().map(|p| json!({"frequency_hz": p.frequency_hz, "density_m2_s4_per_hz": p.density})),
        },
        "track_samples": track_samples,
    });
    (summary, case_plots(case, r, psd.as_ref()))
}
