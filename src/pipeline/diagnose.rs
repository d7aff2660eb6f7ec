//! Diagnose jobs: the params of a diagnosis of a stored campaign (its id, the SHA-256 of its
//! content and the client's options), parsed once into [`DiagnosePlan`]; its options built
//! from the plan in one place ([`DiagnosePlan::options`]) and checked at submission by the
//! diagnosis' own rules ([`crate::gap::diagnose::check_options`], the ones the CLI's diagnosis
//! applies, with the window, settle and grid bounds of [`super::limits`]); and the run
//! ([`run_diagnosis`]): the stored campaign read, the diagnosis run, its report and figures.

use super::{RunControl, RunError};
use crate::cases::limits::grid_points_range;
use crate::field_error::FieldError;
use crate::gap::diagnose::{check_options, DiagnoseOptions};
use crate::gap::{Campaign, GapError};
use serde::{Deserialize, Serialize};
use std::path::Path;

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

/// A `diagnose` job, parsed and checked: the stored campaign it reads (by id, pinned by the
/// SHA-256 of its content) and the options the client set (absent ones keep the diagnosis'
/// defaults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiagnosePlan {
    /// The campaign's id.
    pub campaign_id: uuid::Uuid,
    /// SHA-256 of the campaign's stored canonical JSON, lower-case hex.
    pub campaign_sha256: String,
    /// Simulated excitation per increment, s ([`super::check_window_s`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window_s: Option<f64>,
    /// Settle time before each window, s ([`super::check_settle_s`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_s: Option<f64>,
    /// Grid points per effect parameter ([`super::check_grid_points`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid_points: Option<usize>,
    /// Library effects to consider (all when absent); at least one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effects: Option<Vec<String>>,
}

/// Lower-case hex of a SHA-256: 64 digits.
fn is_sha256(s: &str) -> bool {
    s.len() == 64 && s.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'))
}

/// Names of the gap library's effects, which a diagnosis may name.
fn library_effects() -> Vec<&'static str> {
    crate::gap::effects::LIBRARY
        .iter()
        .map(|e| e.name)
        .collect()
}

/// A diagnosis' error as a job's: a broken rule names its field, anything else is a failed
/// computation.
fn job_error(e: GapError) -> RunError {
    match e {
        GapError::Field { field, rule } => RunError::InvalidConfig { field, rule },
        other => RunError::Diverged(other.to_string()),
    }
}

impl DiagnosePlan {
    /// Parses a `diagnose` job's params ([`DIAGNOSE_KEYS`]); `effects` must name effects of
    /// the gap library, and the options the plan gives ([`DiagnosePlan::options`]) must pass
    /// the diagnosis' rules. Errors name the params field.
    pub fn from_params(params: &serde_json::Value) -> Result<Self, RunError> {
        Self::from_params_in(params, &library_effects())
    }

    /// The diagnosis' options: its defaults with what the plan sets. The one place a job's
    /// options are built (at submission to check them, per attempt to run them).
    pub fn options(&self) -> DiagnoseOptions {
        let mut options = DiagnoseOptions::default();
        let emulator = &mut options.emulator;
        emulator.window_s = self.window_s.unwrap_or(emulator.window_s);
        emulator.settle_s = self.settle_s.unwrap_or(emulator.settle_s);
        emulator.grid_points = self.grid_points.unwrap_or(emulator.grid_points);
        if let Some(effects) = &self.effects {
            emulator.effects = Some(effects.clone());
        }
        options
    }

    /// [`DiagnosePlan::from_params`] with `effects` names taken from `library`.
    fn from_params_in(params: &serde_json::Value, library: &[&str]) -> Result<Self, RunError> {
        let known = DIAGNOSE_CLIENT_KEYS.join(", ");
        let map = params
            .as_object()
            .ok_or_else(|| FieldError::new("params", "must be a JSON object"))?;
        if let Some(key) = map.keys().find(|k| !DIAGNOSE_KEYS.contains(&k.as_str())) {
            return Err(
                FieldError::new(key, format!("is not a known parameter (known: {known})")).into(),
            );
        }
        let submit_here = "is required (submit through POST /v1/campaigns/{id}/diagnoses)";
        let campaign_id = map
            .get("campaign_id")
            .ok_or_else(|| FieldError::new("campaign_id", submit_here))?
            .as_str()
            .and_then(|s| uuid::Uuid::parse_str(s).ok())
            .ok_or_else(|| FieldError::new("campaign_id", "must be a campaign's UUID"))?;
        let campaign_sha256 = map
            .get("campaign_sha256")
            .ok_or_else(|| FieldError::new("campaign_sha256", submit_here))?
            .as_str()
            .filter(|s| is_sha256(s))
            .ok_or_else(|| FieldError::new("campaign_sha256", "must be 64 lower-case hex digits"))?
            .to_string();
        let seconds = |name: &str| -> Result<Option<f64>, FieldError> {
            map.get(name)
                .map(|value| {
                    value
                        .as_f64()
                        .ok_or_else(|| FieldError::new(name, "must be a number of seconds"))
                })
                .transpose()
        };
        let window_s = seconds("window_s")?;
        let settle_s = seconds("settle_s")?;
        let grid_points = map
            .get("grid_points")
            .map(|value| {
                value
                    .as_u64()
                    .map(|n| usize::try_from(n).unwrap_or(usize::MAX))
                    .ok_or_else(|| {
                        FieldError::new(
                            "grid_points",
                            format!("must be an integer in {}", grid_points_range()),
                        )
                    })
            })
            .transpose()?;
        let effects = map
            .get("effects")
            .map(|value| parse_effects(value, library))
            .transpose()?;
        let plan = Self {
            campaign_id,
            campaign_sha256,
            window_s,
            settle_s,
            grid_points,
            effects,
        };
        check_options(&plan.options()).map_err(job_error)?;
        Ok(plan)
    }
}

/// A finished diagnosis: its report (JSON) and figures (file name, SVG).
#[derive(Debug, Clone)]
pub struct DiagnosisOutcome {
    /// The report.
    pub report: serde_json::Value,
    /// Its figures.
    pub plots: Vec<(String, String)>,
}

/// Runs the diagnosis `plan` of the stored campaign `campaign_json` (its canonical JSON as the
/// store holds it: validated on upload and pinned by its SHA-256, so parsed here and not
/// checked again). Progress is the fraction of its test simulations done (reported as
/// `simulated_time_s` = simulations done of `end_time_s` = simulations in all, the stage after
/// the last simulation counting as one more); a checkpoint request is not honoured (its
/// windows keep none), so `control` should come without one.
pub fn run_diagnosis(
    plan: &DiagnosePlan,
    campaign_json: &str,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<DiagnosisOutcome, RunError> {
    let campaign = Campaign::from_json_str(campaign_json).map_err(|e| {
        FieldError::new(
            "campaign_id",
            format!("names a stored campaign that does not parse: {e}"),
        )
    })?;
    let options = plan.options();
    // The window simulations see the cancel flag but not the progress sink: the job's progress
    // counts simulations, not one window's simulated time.
    let inner = RunControl::new(control.cancel.clone(), std::sync::Arc::new(|_| {}));
    // The stage after the last simulation (fits, ranking, held-out tests, report and plots)
    // counts as one more unit, so the job reads 100 % only once the report is made.
    let units = std::sync::atomic::AtomicUsize::new(1);
    let report_progress = |done: usize, total: usize| {
        let total = total.max(1) + 1;
        units.fetch_max(total, std::sync::atomic::Ordering::SeqCst);
        (control.progress)(diagnosis_progress(done.min(total - 1), total));
    };
    let cache = crate::gap::window::WindowCache::new();
    let (report, _) = crate::gap::diagnose::diagnose(
        &campaign,
        configs_dir,
        &options,
        &inner,
        &cache,
        &report_progress,
    )
    .map_err(|e| {
        if control.is_cancelled() {
            RunError::Cancelled
        } else {
            job_error(e)
        }
    })?;
    let summary = serde_json::to_value(&report).map_err(|e| RunError::InvalidConfig {
        field: "report".into(),
        rule: format!("could not be serialized: {e}"),
    })?;
    let plots = crate::gap::diagnose::plots::plots(&report);
    let total = units.load(std::sync::atomic::Ordering::SeqCst);
    (control.progress)(diagnosis_progress(total, total));
    Ok(DiagnosisOutcome {
        report: summary,
        plots,
    })
}

/// A diagnosis' progress: `done` of `total` units (its simulations, then the final stage).
fn diagnosis_progress(done: usize, total: usize) -> super::Progress {
    super::Progress {
        simulated_time_s: done as f64,
        end_time_s: total as f64,
        fraction: (done as f64 / total as f64).clamp(0.0, 1.0),
    }
}

/// The wear law a sweep carries from a diagnosis, read from its stored report.
pub use crate::gap::diagnose::carry::carried_wear_law;

/// A non-empty list of names of `library` effects.
fn parse_effects(value: &serde_json::Value, library: &[&str]) -> Result<Vec<String>, FieldError> {
    let names: Vec<String> = serde_json::from_value(value.clone())
        .map_err(|_| FieldError::new("effects", "must be a list of effect names"))?;
    if names.is_empty() {
        return Err(FieldError::new("effects", "must name at least one effect"));
    }
    for (i, name) in names.iter().enumerate() {
        if let Some(first) = names[..i].iter().position(|n| n == name) {
            return Err(FieldError::new(
                format!("effects[{i}]"),
                format!("`{name}` is already effects[{first}]: name each effect once"),
            ));
        }
        if !library.contains(&name.as_str()) {
            return Err(FieldError::new(
                format!("effects[{i}]"),
                format!(
                    "`{name}` is not a library effect (known: {})",
                    library.join(", ")
                ),
            ));
        }
    }
    Ok(names)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn params(options: serde_json::Value) -> serde_json::Value {
        let mut p = json!({
            "campaign_id": "6f1c1c64-0f4e-4d57-9a53-0d7c2b3a1e10",
            "campaign_sha256": "a".repeat(64),
        });
        super::super::merge_json(&mut p, &options);
        p
    }

    #[test]
    fn options_are_bounded_once_naming_the_field() {
        let library = ["third_body", "misalignment"];
        let ok = DiagnosePlan::from_params_in(
            &params(json!({"window_s": 0.1, "grid_points": 2, "effects": ["third_body"]})),
            &library,
        )
        .unwrap();
        assert_eq!(ok.window_s, Some(0.1));
        assert_eq!(ok.grid_points, Some(2));
        for (bad, field) in [
            (json!({"window_s": 0}), "window_s"),
            (json!({"window_s": 0.04}), "window_s"),
            (json!({"window_s": 601}), "window_s"),
            (json!({"settle_s": -1.0}), "settle_s"),
            (json!({"grid_points": 13}), "grid_points"),
            (json!({"grid_points": 2.5}), "grid_points"),
            (json!({"effects": []}), "effects"),
            (json!({"effects": ["third_body", "gremlins"]}), "effects[1]"),
            (
                json!({"effects": ["third_body", "third_body"]}),
                "effects[1]",
            ),
            (json!({"colour": "red"}), "colour"),
        ] {
            let Err(RunError::InvalidConfig { field: got, .. }) =
                DiagnosePlan::from_params_in(&params(bad.clone()), &library)
            else {
                panic!("{bad} is refused");
            };
            assert_eq!(got, field, "{bad}");
        }
    }

    #[test]
    fn a_plan_round_trips_through_its_json() {
        let plan = DiagnosePlan::from_params_in(
            &params(json!({"window_s": 0.1, "settle_s": 0.02})),
            &["third_body"],
        )
        .unwrap();
        let json = super::super::plan_to_json(&plan).unwrap();
        assert_eq!(
            super::super::plan_from_json::<DiagnosePlan>(&json, "diagnose").unwrap(),
            plan
        );
    }
}
