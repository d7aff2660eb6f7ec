//! Simulate jobs: params (`config`, `overrides`, `seed`) to a validated case, the typed plan a
//! job stores ([`SimulatePlan`]), and the run.

use super::{check_keys, parse_seed, CaseOutcome, RunControl, RunError, SIMULATE_KEYS};
use crate::cases::{resolve_config, run_case, CaseSource};
use crate::field_error::FieldError;
use crate::models::spec::CaseSpec;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Resolves job parameters to a validated case: `{"config": "<reference name>" | {inline
/// case}, "overrides": {...}, "seed": n}` (other keys are the caller's to check), read into
/// their parts and resolved by [`resolve_config`]. Errors name the params path (`config`,
/// `config.<path>` or `overrides.<path>`).
pub fn resolve_case(
    params: &serde_json::Value,
    configs_dir: &Path,
    adjust: impl FnOnce(&mut CaseSpec) -> Result<(), RunError>,
) -> Result<CaseSpec, RunError> {
    resolve_case_seeded(params, configs_dir, None, adjust)
}

/// [`resolve_case`] for a job whose seed the caller has parsed already (`job_seed`: the
/// params' own `seed`, or the one drawn for a job that names none), so the params' `seed` is
/// not read again: it becomes the case's `simulation.seed`, set after the config's own value
/// is checked. Without one, the params' `seed` is parsed here.
pub fn resolve_case_seeded(
    params: &serde_json::Value,
    configs_dir: &Path,
    job_seed: Option<u64>,
    adjust: impl FnOnce(&mut CaseSpec) -> Result<(), RunError>,
) -> Result<CaseSpec, RunError> {
    let source = match params.get("config") {
        Some(serde_json::Value::String(name)) => CaseSource::Reference(name),
        Some(obj @ serde_json::Value::Object(_)) => CaseSource::Inline(obj),
        Some(_) => {
            return Err(FieldError::new(
                "config",
                "must be a reference config name or a config object",
            )
            .into())
        }
        None => {
            return Err(FieldError::new(
                "config",
                "is required (a reference config name or a config object)",
            )
            .into())
        }
    };
    // The params' seed merged into the case before its checks (as an override would be): the
    // job's when the caller parsed it, otherwise parsed here.
    let params_seed = match job_seed {
        Some(seed) => params.get("seed").map(|_| seed),
        None => params.get("seed").map(parse_seed).transpose()?,
    };
    resolve_config(
        source,
        params.get("overrides"),
        params_seed,
        configs_dir,
        |case| {
            if let Some(seed) = job_seed {
                case.simulation.seed = seed;
            }
            adjust(case)
        },
    )
}

/// [`resolve_case`] without adjustment (the params' other keys are not checked).
pub fn case_from_params(
    params: &serde_json::Value,
    configs_dir: &Path,
) -> Result<CaseSpec, RunError> {
    resolve_case(params, configs_dir, |_| Ok(()))
}

/// A simulate job's params, parsed and checked: [`SIMULATE_KEYS`] only, `config` required.
pub fn simulate_case(params: &serde_json::Value, configs_dir: &Path) -> Result<CaseSpec, RunError> {
    check_keys(params, "params", SIMULATE_KEYS)?;
    case_from_params(params, configs_dir)
}

/// A simulate job parsed and checked once, at submission: the complete case (reference config,
/// overrides and seed merged; `simulation.seed` is the job's seed), stored with the job as its
/// canonical JSON ([`SimulatePlan::to_json`]) and run by the worker from there
/// ([`SimulatePlan::from_json`]) without reading the params or the reference config again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulatePlan {
    /// The case to run.
    pub case: CaseSpec,
}

impl SimulatePlan {
    /// Parses and checks a simulate job's params as submitted (the rules of [`simulate_case`],
    /// and the model built once) for a job run with `seed` (the params' `seed`, or the one
    /// drawn for the job): the case's `simulation.seed` is set to it before it is checked, as
    /// the worker sets it for a job planned from its params. Errors name the params path.
    pub fn from_params(
        params: &serde_json::Value,
        configs_dir: &Path,
        seed: u64,
    ) -> Result<Self, RunError> {
        check_keys(params, "params", SIMULATE_KEYS)?;
        let case = resolve_case_seeded(params, configs_dir, Some(seed), |_| Ok(()))?;
        Ok(Self { case })
    }

    /// The plan's canonical JSON (every number round-trips exactly).
    pub fn to_json(&self) -> Result<serde_json::Value, RunError> {
        super::plan_to_json(self)
    }

    /// A stored plan, as [`SimulatePlan::to_json`] wrote it. It was checked at submission; the
    /// run validates the case once more as it builds the model.
    pub fn from_json(value: &serde_json::Value) -> Result<Self, RunError> {
        super::plan_from_json(value, "simulate")
    }
}

/// A simulate job: one case end to end.
pub fn simulate_job(
    params: &serde_json::Value,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<CaseOutcome, RunError> {
    let case = simulate_case(params, configs_dir)?;
    let (_, outcome) = run_case(&case, configs_dir, control)?;
    Ok(outcome)
}
