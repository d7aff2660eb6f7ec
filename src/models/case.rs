//! From a case file to a model ready to run: reads and validates the case, resolves the
//! excitation (profiles by name), builds the model and maps the run settings. Running it is
//! [`super::case_run`]'s, packaging the outcome (summary, tracks, plots) [`crate::report`]'s.

use super::outcome::RunError;
use super::run::{BuiltModel, ModelRunError, RunOptions};
use super::spec::{CaseSpec, Excitation, ModelSpecRef};
use super::{launcher, persistent_contact, rattle_box};
use crate::excitation::profile::ProfileFile;
use crate::excitation::{BaseMotion, ExcitationSpec};
use crate::field_error::FieldError;
use crate::physics::contact::FaceContact;
use crate::physics::integrator::{IntegratorKind, IntegratorSettings, Tolerances};
use crate::physics::simulate::{DivergenceLimits, SimError};
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
            // Only `case_run::run_case_model` can keep a checkpoint (it knows the case); elsewhere the
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
    let case = read_case(path)?;
    case.validate()?;
    Ok(case)
}

/// Reads a case file without validating it: for a caller that changes the case (a job's
/// overrides) and validates what it makes of it, once.
pub fn read_case(path: &Path) -> Result<CaseSpec, RunError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| FieldError::new("config", format!("cannot read {}: {e}", path.display())))?;
    Ok(CaseSpec::from_toml_str_unchecked(&text)?)
}

/// Resolves the `[excitation]` table: `kind = "profile"` loads `configs/profiles/<profile>.toml`;
/// the case's `simulation.settle_s` becomes the excitation's settle time, and for random
/// profiles `simulation.seed` replaces the profile's seed (so sweeps and ensembles vary it).
pub fn resolve_excitation(case: &CaseSpec, configs_dir: &Path) -> Result<ExcitationSpec, RunError> {
    let mut spec = match case.excitation.kind() {
        Excitation::Profile(name) => {
            if name.contains('/') || name.contains("..") {
                return Err(
                    FieldError::new("excitation.profile", "must be a plain profile name").into(),
                );
            }
            let path = configs_dir.join("profiles").join(format!("{name}.toml"));
            let text = std::fs::read_to_string(&path).map_err(|e| {
                FieldError::new(
                    "excitation.profile",
                    format!(
                        "cannot read {} (profiles are looked up in the configs directory's \
                         profiles/, here {}; the CLI's --configs-dir sets it): {e}",
                        path.display(),
                        configs_dir.display()
                    ),
                )
            })?;
            let mut spec = ProfileFile::from_toml_str(&text)
                .map_err(|e| FieldError::new("excitation.profile", e.to_string()))?
                .excitation;
            if let ExcitationSpec::SineOnRandom { seed, .. } = &mut spec {
                *seed = case.simulation.seed;
            }
            spec
        }
        Excitation::Motion(spec) => spec.clone(),
    };
    match &mut spec {
        ExcitationSpec::None => {}
        ExcitationSpec::Sine { settle_s, .. }
        | ExcitationSpec::SineOnRandom { settle_s, .. }
        | ExcitationSpec::Measured { settle_s, .. } => *settle_s = case.simulation.settle_s,
    }
    Ok(spec)
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

/// Builds the model of a case (validated first).
pub fn build(case: &CaseSpec, configs_dir: &Path) -> Result<BuiltModel, RunError> {
    case.validate()?;
    build_validated(case, configs_dir)
}

/// [`build`] of a case the caller has just validated ([`CaseSpec::validate`] passed on this
/// very value), so the rules are not checked twice.
pub(crate) fn build_validated(case: &CaseSpec, configs_dir: &Path) -> Result<BuiltModel, RunError> {
    #[cfg(test)]
    super::counts::built();
    let excitation = resolve_excitation(case, configs_dir)?;
    let motion = BaseMotion::from_spec(&excitation)
        .map_err(|e| FieldError::new("excitation", e.to_string()))?;
    match case.model_spec()? {
        ModelSpecRef::RattleBox(spec) => Ok(rattle_box::build(case, spec, motion)),
        ModelSpecRef::Launcher(spec) => launcher::build(case, spec, motion),
        ModelSpecRef::PersistentContact(spec) => persistent_contact::build(spec),
    }
}

/// How a case's model resolves the faces of its rounded boxes: what `simulation.face_contact`
/// names, else the model's own default ([`launcher::FACE_CONTACT`],
/// [`rattle_box::FACE_CONTACT`]); `None` for a model without boxes (the persistent-contact
/// block). The builders take it from here, and a sweep's curve records it in its provenance.
pub fn face_contact(case: &CaseSpec) -> Result<Option<FaceContact>, RunError> {
    let default = match case.model_spec()? {
        ModelSpecRef::RattleBox(_) => rattle_box::FACE_CONTACT,
        ModelSpecRef::Launcher(_) => launcher::FACE_CONTACT,
        ModelSpecRef::PersistentContact(_) => return Ok(None),
    };
    Ok(Some(case.simulation.face_contact.unwrap_or(default)))
}

/// [`face_contact`] as a provenance record: `{"face_contact": "exact"}`, or with the lattice
/// its `contact_points_per_edge`; `null` for a model without boxes.
pub fn face_contact_record(case: &CaseSpec) -> Result<Value, RunError> {
    Ok(match face_contact(case)? {
        None => Value::Null,
        Some(FaceContact::Exact) => json!({"face_contact": FaceContact::Exact}),
        Some(FaceContact::Reduced) => json!({"face_contact": FaceContact::Reduced}),
        Some(FaceContact::Lattice) => json!({
            "face_contact": FaceContact::Lattice,
            "contact_points_per_edge": case.simulation.contact_points_per_edge,
        }),
    })
}

/// Run options of a case.
pub fn run_options(case: &CaseSpec) -> Result<RunOptions, RunError> {
    Ok(RunOptions {
        integrator: integrator_settings(case)?,
        limits: DivergenceLimits::default(),
        wear_law: case.wear.law,
        wear_mechanism: case.wear.mechanism,
        volume_split: case.wear.volume_split,
        record_interval_s: case.simulation.record_interval_s,
        response_rate_hz: 2000.0,
    })
}
