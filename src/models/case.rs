//! From a case file to a finished run: resolves the excitation (profiles by name), builds the
//! model, maps the run settings, runs it and writes the summary, tracks and plots.

use super::checkpoint::{self, RunIdentity};
use super::rattle_box;
use super::run::{run_model_from, BuiltModel, ModelRunError, RunOptions, RunReport};
use super::specs::{CaseSpec, ModelSpecRef};
use crate::analysis::spectra::welch_psd;
use crate::analysis::svg::{AxisSpec, Plot, Series};
use crate::analysis::vdv::vibration_dose_value_uniform;
use crate::excitation::profile::ProfileFile;
use crate::excitation::{BaseMotion, ExcitationSpec};
use crate::field_error::FieldError;
use crate::physics::integrator::{IntegratorKind, IntegratorSettings, Tolerances};
use crate::physics::simulate::{DivergenceLimits, SimError};
use crate::pipeline::{CaseOutcome, RunControl, RunError};
use serde_json::{json, Value};
use std::path::Path;

/// Version of the code, the one stamp recorded with every result, job, diagnosis and
/// checkpoint: `CARGO_PKG_VERSION`, plus `+<git hash>` when `RAILWEAR_GIT_HASH` was set at
/// build time (`.ci/run` and the Dockerfile set it). A checkpoint resumes only in the code
/// version that wrote it.
pub fn code_version() -> &'static str {
    static VERSION: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    VERSION.get_or_init(|| {
        let version = env!("CARGO_PKG_VERSION");
        match option_env!("RAILWEAR_GIT_HASH") {
            Some(hash) if !hash.is_empty() => format!("{version}+{hash}"),
            _ => version.to_string(),
        }
    })
}

impl From<ModelRunError> for RunError {
    fn from(e: ModelRunError) -> Self {
        match e {
            ModelRunError::Sim(SimError::Cancelled { .. }) => RunError::Cancelled,
            // Only `run_case_from` can keep a checkpoint (it knows the case); elsewhere the
            // request stopped the run like a cancellation.
            ModelRunError::Sim(SimError::Checkpointed(_)) | ModelRunError::Checkpointed(_) => {
                RunError::Cancelled
            }
            ModelRunError::Sim(d) => RunError::Diverged(d.to_string()),
            ModelRunError::Wear(w) => RunError::Diverged(format!("wear post-processing: {w}")),
        }
    }
}

/// Reads and validates a case file.
pub fn load_case(path: &Path) -> Result<CaseSpec, RunError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| FieldError::new("config", format!("cannot read {}: {e}", path.display())))?;
    Ok(CaseSpec::from_toml_str(&text)?)
}

/// Resolves the `[excitation]` table: `kind = "profile"` loads `configs/profiles/<profile>.toml`;
/// the case's `simulation.settle_s` becomes the excitation's settle time, and for random
/// profiles `simulation.seed` replaces the profile's seed (so sweeps and ensembles vary it).
pub fn resolve_excitation(case: &CaseSpec, configs_dir: &Path) -> Result<ExcitationSpec, RunError> {
    let mut value = case.excitation.clone();
    if value.get("kind").and_then(Value::as_str) == Some("profile") {
        let name = value
            .get("profile")
            .and_then(Value::as_str)
            .ok_or_else(|| {
                FieldError::new("excitation.profile", "must name a file in configs/profiles")
            })?;
        if name.contains('/') || name.contains("..") {
            return Err(
                FieldError::new("excitation.profile", "must be a plain profile name").into(),
            );
        }
        let path = configs_dir.join("profiles").join(format!("{name}.toml"));
        let text = std::fs::read_to_string(&path).map_err(|e| {
            FieldError::new(
                "excitation.profile",
                format!("cannot read {}: {e}", path.display()),
            )
        })?;
        let file = ProfileFile::from_toml_str(&text)
            .map_err(|e| FieldError::new("excitation.profile", e.to_string()))?;
        value = serde_json::to_value(&file.excitation)
            .map_err(|e| FieldError::new("excitation", e.to_string()))?;
        if let Some(obj) = value.as_object_mut() {
            if obj.contains_key("seed") {
                obj.insert("seed".into(), json!(case.simulation.seed));
            }
        }
    }
    if let Some(obj) = value.as_object_mut() {
        if obj.get("kind").and_then(Value::as_str) != Some("none") {
            obj.insert("settle_s".into(), json!(case.simulation.settle_s));
        }
    }
    serde_json::from_value(value).map_err(|e| FieldError::new("excitation", e.to_string()).into())
}

/// Maps the `[simulation]` table to integrator settings. The position tolerance sets the
/// others: velocities `abs_m / 1 ms`, quaternion `abs_m / 10 mm`, angular velocity
/// `abs_m / (10 mm · 1 ms)`.
pub fn integrator_settings(case: &CaseSpec) -> Result<IntegratorSettings, RunError> {
    let kind = match case.simulation.integrator.as_str() {
        "trbdf2" => IntegratorKind::Trbdf2,
        "sdirk2" => IntegratorKind::Sdirk2,
        "dopri5" => IntegratorKind::Dopri5,
        other => {
            return Err(FieldError::new(
                "simulation.integrator",
                format!("unknown integrator {other:?}; use trbdf2, sdirk2 or dopri5"),
            )
            .into())
        }
    };
    let a = case.simulation.abs_tolerance_m;
    Ok(IntegratorSettings {
        kind,
        newton: case.simulation.newton_jacobian,
        patches: case.simulation.contact_patches,
        tolerances: Tolerances {
            rel: case.simulation.rel_tolerance,
            abs_position_m: a,
            abs_rotation: a / 0.01,
            abs_velocity_m_s: a * 1e3,
            abs_angular_velocity_rad_s: a * 1e5,
            // The work quadrature follows the state's tolerance (1e-3 at the default 1e-4), so
            // a tolerance-halving study halves it too.
            energy_rel: case
                .simulation
                .energy_rel_tolerance
                .unwrap_or(10.0 * case.simulation.rel_tolerance),
            error_control: case.simulation.error_control,
        },
        initial_step_s: 1e-6,
        max_step_s: 1e-3,
        min_step_s: 1e-15,
    })
}

/// Builds the model of a case.
pub fn build(case: &CaseSpec, configs_dir: &Path) -> Result<BuiltModel, RunError> {
    case.validate()?;
    let excitation = resolve_excitation(case, configs_dir)?;
    let motion = BaseMotion::from_spec(&excitation)
        .map_err(|e| FieldError::new("excitation", e.to_string()))?;
    match case.model_spec()? {
        ModelSpecRef::RattleBox(spec) => Ok(rattle_box::build(case, spec, motion)),
        ModelSpecRef::Launcher(spec) => super::launcher::build(case, spec, motion),
        ModelSpecRef::PersistentContact(_) => Err(FieldError::new(
            "model",
            "the persistent-contact fixture runs through `railwear calibrate`, not as a dynamic case in this build",
        ).into()),
    }
}

/// Run options of a case.
pub fn run_options(case: &CaseSpec) -> Result<RunOptions, RunError> {
    Ok(RunOptions {
        integrator: integrator_settings(case)?,
        limits: DivergenceLimits::default(),
        wear_law: case.wear.law,
        volume_split: case.wear.volume_split,
        record_interval_s: case.simulation.record_interval_s,
        response_rate_hz: 2000.0,
    })
}

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
    (summary, plots(case, r, psd.as_ref()))
}

fn plots(
    case: &CaseSpec,
    r: &RunReport,
    psd: Option<&crate::analysis::spectra::Psd>,
) -> Vec<(String, String)> {
    let mut out = Vec::new();
    // Wear versus time per contact, mg.
    // The rattle box and the launcher are one material (7075-T73 unless the config says
    // otherwise); the persistent-contact case has no dynamic run.
    let material = match case.model_spec() {
        Ok(ModelSpecRef::RattleBox(s)) => s.material,
        Ok(ModelSpecRef::Launcher(s)) => s.material,
        _ => crate::wear::material::Material::default(),
    };
    let density = material.density_kg_per_m3;
    let mut wear_plot = Plot::new(
        format!("{}: wear versus time", case.name),
        AxisSpec::linear("time (s)"),
        AxisSpec::linear("wear mass (mg)"),
    );
    for (ci, c) in r.contacts.iter().enumerate() {
        let pts: Vec<(f64, f64)> = r
            .wear_history
            .iter()
            .map(|(t, v)| (*t, v.get(ci).copied().unwrap_or(0.0) * density * 1e6))
            .collect();
        wear_plot = wear_plot.with_series(Series::line(&c.name, pts));
    }
    out.push(("wear_vs_time.svg".to_string(), wear_plot.to_svg()));
    // Contact-pressure PDF per contact with S_y and the cutoff marked.
    for c in &r.contacts {
        let dens = c.wear.pressure_histogram.time_density_per_pa();
        let nonzero: Vec<(f64, f64)> = dens.into_iter().filter(|(_, d)| *d > 0.0).collect();
        if nonzero.is_empty() {
            continue;
        }
        let edges: Vec<f64> = (0..=c.wear.pressure_histogram.len())
            .map(|i| c.wear.pressure_histogram.edge_pa(i) / 1e6)
            .collect();
        let values: Vec<f64> = c
            .wear
            .pressure_histogram
            .time_density_per_pa()
            .iter()
            .map(|(_, d)| d * 1e6)
            .collect();
        let mut p = Plot::new(
            format!("{}: contact-pressure PDF, {}", case.name, c.name),
            AxisSpec::log("contact pressure (MPa)"),
            AxisSpec::linear("time density (1/MPa)"),
        )
        .with_series(Series::histogram("time share", &edges, &values));
        p = p.with_marker(material.yield_strength_pa / 1e6, "Sy");
        if let Some(cut) = c.wear.cutoff_pressure_pa {
            p = p.with_marker(cut / 1e6, "cutoff");
        }
        out.push((format!("pressure_pdf_{}.svg", c.name), p.to_svg()));
    }
    if let Some(psd) = psd {
        let pts: Vec<(f64, f64)> = psd
            .frequency_hz
            .iter()
            .zip(&psd.density)
            .filter(|(f, d)| **f > 0.0 && **d > 0.0)
            .map(|(f, d)| (*f, *d))
            .collect();
        if !pts.is_empty() {
            let p = Plot::new(
                format!("{}: response acceleration PSD (x)", case.name),
                AxisSpec::log("frequency (Hz)"),
                AxisSpec::log("PSD ((m/s²)²/Hz)"),
            )
            .with_series(Series::line("x", pts));
            out.push(("response_psd.svg".to_string(), p.to_svg()));
        }
    }
    out
}
