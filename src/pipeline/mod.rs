//! The library's one door for the service's jobs: every job kind (simulate, sweep, calibrate,
//! diagnose) reaches the simulation library through here, and `jobs` imports no simulation room
//! itself. It stands above `gap`, so a diagnosis runs behind it like a simulation.
//!
//! One file per job kind's parameters, each parsed once, at submission, into its typed plan,
//! stored as canonical JSON ([`plan_to_json`]) and run by the worker from there
//! ([`plan_from_json`]): `simulate` (params to a validated case, [`SimulatePlan`]),
//! `sweep_range` (the rattle-space range a sweep covers), `sweep` (the planned sweep, its
//! points, labels and assembly), `sweep_curve` (a finished sweep's penalization curve, plot
//! and provenance), [`calibrate`] (calibration data sets), `diagnose` (a diagnosis' plan, its
//! options built and checked once, and its run).
//!
//! The case itself (its parser, [`bounds`], [`limits`], [`run_case`]) is the room below,
//! [`crate::cases`], re-exported here with the types a job's caller handles ([`RunControl`],
//! [`CaseOutcome`], [`RunError`], [`PenalizationCurve`], [`TrackSample`]).

#[cfg(test)]
mod bounds_tests;
mod calibrate;
mod diagnose;
mod simulate;
mod sweep;
mod sweep_curve;
mod sweep_range;
#[cfg(test)]
mod tests;

pub use calibrate::*;
pub use diagnose::*;
pub use simulate::*;
pub use sweep::*;
pub use sweep_curve::*;
pub use sweep_range::*;

pub use crate::cases::{
    bounds, check_grid_points, check_settle_s, check_window_s, limits, merge_json, resolve_config,
    resolve_model, run_case, run_case_from, CaseOutcome, CaseSource, DiagnosedWearLaw, Progress,
    RecordChunk, RecordSink, RunControl, RunError, SavedRun, SweepWearLaw,
};
use crate::field_error::FieldError;
/// What the service handles of a run without looking inside: a checkpoint's bytes, the code
/// version a result records, a contact-track sample, a sweep's curve, the progress interval.
pub use crate::{
    analysis::penalization::PenalizationCurve, models::case::code_version,
    models::outcome::Checkpoint, physics::control::DEFAULT_PROGRESS_INTERVAL,
    physics::track::TrackSample,
};
/// What the tests of `jobs` count and read through this door: validations and builds per
/// attempt, and a campaign to diagnose.
#[cfg(test)]
pub(crate) use crate::{gap::Campaign, models::counts};

/// A typed job plan as its canonical JSON, what a job stores at submission (every number
/// round-trips exactly).
pub fn plan_to_json<T: serde::Serialize>(plan: &T) -> Result<serde_json::Value, RunError> {
    serde_json::to_value(plan).map_err(|e| FieldError::new("plan", e.to_string()).into())
}

/// A stored plan of a `kind` job read back, as [`plan_to_json`] wrote it. It was checked at
/// submission and is not checked again; an error names `plan`.
pub fn plan_from_json<T: serde::de::DeserializeOwned>(
    value: &serde_json::Value,
    kind: &str,
) -> Result<T, RunError> {
    T::deserialize(value).map_err(|e| {
        FieldError::new("plan", format!("is not a {kind} job's stored plan: {e}")).into()
    })
}

/// Parameters of a simulate job.
pub const SIMULATE_KEYS: &[&str] = &["config", "overrides", "seed"];
/// Parameters of a sweep job (`point` only in the `sweep_point` children the sweep creates).
pub const SWEEP_KEYS: &[&str] = &[
    "config",
    "overrides",
    "seed",
    "points",
    "vehicle_profile",
    "environment",
    "wear_law",
    "rattle_space_range",
    "offset_mm_range",
    "base_dimensions_mm",
    "seeds",
];
/// Seeds per sweep point when a sweep names none (see [`limits::SWEEP_SEEDS`]).
pub const DEFAULT_SWEEP_SEEDS: u64 = 3;
/// Parameters of a calibrate job.
pub const CALIBRATE_KEYS: &[&str] = &["friction", "wear_law", "seed"];

/// The params object, refusing keys outside `allowed` (a typo such as `confg` is an error,
/// not silently ignored).
pub fn check_keys<'a>(
    value: &'a serde_json::Value,
    field: &str,
    allowed: &[&str],
) -> Result<&'a serde_json::Map<String, serde_json::Value>, RunError> {
    let map = value
        .as_object()
        .ok_or_else(|| FieldError::new(field, "must be a JSON object"))?;
    for key in map.keys() {
        if !allowed.contains(&key.as_str()) {
            let path = if field == "params" {
                key.clone()
            } else {
                format!("{field}.{key}")
            };
            return Err(FieldError::new(
                &path,
                format!("is not a known parameter (known: {})", allowed.join(", ")),
            )
            .into());
        }
    }
    Ok(map)
}

/// A seed: an integer in [0, 2^53).
pub fn parse_seed(value: &serde_json::Value) -> Result<u64, RunError> {
    value
        .as_u64()
        .filter(|s| *s <= limits::MAX_SEED)
        .ok_or_else(|| {
            FieldError::new(
                "seed",
                "must be an integer in [0, 2^53) (JavaScript reads larger integers inexactly)",
            )
            .into()
        })
}
