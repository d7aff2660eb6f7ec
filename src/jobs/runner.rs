//! The one narrow interface between the job queue and the simulation library: [`CaseRunner`].
//! The queue never looks inside a computation; it hands over kind + params + [`RunControl`] and
//! stores what comes back.

use super::model::JobKind;
use crate::analysis::penalization::PenalizationCurve;
use crate::config::reference_config_path;
use crate::physics::track::TrackSample;
use crate::pipeline::{RunControl, RunError};
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
    /// Sweeps: the penalization curve (eq. 6.4, Figure 6.68), stored under the job's curve key.
    pub penalization: Option<PenalizationCurve>,
}

/// Runs one job's computation on a blocking thread. Must return [`RunError::Cancelled`] within
/// a second of `control.cancel` being set, and should call `control.progress` a few times per
/// second at most. `params` carry the job's `seed`.
pub trait CaseRunner: Send + Sync {
    fn run(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        control: &RunControl,
    ) -> Result<JobOutput, RunError>;

    /// Cheap check at submission so a bad request gets a 422 naming the field instead of a
    /// failed job. The default accepts everything and leaves checks to [`CaseRunner::run`].
    fn validate(&self, _kind: &JobKind, _params: &serde_json::Value) -> Result<(), RunError> {
        Ok(())
    }
}

/// The production runner: calls `railwear::pipeline` with reference configs from `configs_dir`.
pub struct LibraryRunner {
    /// Directory of the reference model configs (`configs/`).
    pub configs_dir: PathBuf,
}

impl LibraryRunner {
    fn check_config_name(&self, params: &serde_json::Value) -> Result<(), RunError> {
        match params.get("config") {
            None => Ok(()),
            Some(serde_json::Value::String(name)) => {
                reference_config_path(&self.configs_dir, name).map_err(|e| {
                    RunError::InvalidConfig {
                        field: "config".into(),
                        rule: e.to_string(),
                    }
                })?;
                Ok(())
            }
            // An inline config object is the library's to validate.
            Some(serde_json::Value::Object(_)) => Ok(()),
            Some(_) => Err(RunError::InvalidConfig {
                field: "config".into(),
                rule: "must be a reference config name or a config object".into(),
            }),
        }
    }
}

impl CaseRunner for LibraryRunner {
    fn run(
        &self,
        kind: &JobKind,
        params: &serde_json::Value,
        _control: &RunControl,
    ) -> Result<JobOutput, RunError> {
        self.validate(kind, params)?;
        // Each kind is wired to its `railwear::pipeline` entry point as the library provides
        // it; until then the job fails with a clear reason instead of a fake result.
        match kind {
            JobKind::Simulate | JobKind::Sweep | JobKind::Calibrate => {
                Err(RunError::InvalidConfig {
                    field: "kind".into(),
                    rule: format!("`{}` is not available in this build", kind.as_str()),
                })
            }
        }
    }

    fn validate(&self, _kind: &JobKind, params: &serde_json::Value) -> Result<(), RunError> {
        self.check_config_name(params)
    }
}
