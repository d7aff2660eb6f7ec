//! The library's door for the service's simulate, sweep and calibrate jobs, and the parser of
//! a diagnosis' options (the diagnosis itself runs in `gap`, which stands on this door).
//!
//! A job hands a case configuration (JSON, the same schema as the TOML files in `configs/`)
//! and a [`RunControl`]; it gets back a [`CaseOutcome`] or a [`RunError`].
//!
//! [`run_case`] runs a case to its packaged outcome (`run`). One file per job kind's
//! parameters: `case` (simulate jobs: params to a validated case),
//! `sweep_range` (the rattle-space range a sweep covers), `sweep` (the planned sweep, its
//! points, labels and assembly), [`calibrate`] (calibration data sets), `diagnose` (a
//! diagnosis' options). The bounds every parser applies are in [`limits`], the physical range
//! of every case field in [`bounds`]. Each kind's params are parsed once, at submission, into
//! its typed plan, stored as canonical JSON ([`plan_to_json`]) and run by the worker from there
//! ([`plan_from_json`]).

pub mod bounds;
#[cfg(test)]
mod bounds_tests;
mod calibrate;
mod case;
mod diagnose;
mod diagnosed_wear;
mod run;
mod sweep;
mod sweep_range;
#[cfg(test)]
mod tests;

pub use calibrate::*;
pub use case::*;
pub use diagnose::*;
pub use diagnosed_wear::{DiagnosedWearLaw, SweepWearLaw};
pub use run::{run_case, run_case_from};
pub use sweep::*;
pub use sweep_range::*;

use crate::field_error::FieldError;
pub use crate::models::outcome::{CaseOutcome, RunError, SavedRun};
pub use crate::physics::control::{Progress, RecordChunk, RecordSink, RunControl};

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

/// Deep-merges `patch` into `base` (objects merge key by key; anything else replaces).
pub fn merge_json(base: &mut serde_json::Value, patch: &serde_json::Value) {
    match (base, patch) {
        (serde_json::Value::Object(b), serde_json::Value::Object(p)) => {
            for (k, v) in p {
                merge_json(b.entry(k.clone()).or_insert(serde_json::Value::Null), v);
            }
        }
        (b, p) => *b = p.clone(),
    }
}

/// Bounds on job parameters, each with its physical or operational reason. They are checked
/// by the parsers below, which both the submission (422 before anything is stored) and the
/// worker call: one set of rules.
pub mod limits {
    /// Longest excited duration of a job, s: 24 h of simulated time. The thesis' longest run is
    /// the 12 h launcher validation (6.7); beyond a day a run is a typing error (1e308 s was
    /// once accepted and grew memory without end).
    pub const MAX_DURATION_S: f64 = 86_400.0;
    /// Longest settle phase, s: ten minutes, well past the tens-of-seconds creep time constant
    /// of a body resting on a face (SPEC 8); the thesis settles for 2 s (6.6.1).
    pub const MAX_SETTLE_S: f64 = 600.0;
    /// Shortest track-record interval, s: 1 us resolves a 500 Hz excitation 2000 times over;
    /// finer only multiplies stored samples.
    pub const MIN_RECORD_INTERVAL_S: f64 = 1.0e-6;
    /// Most recorded time points of one run (`(settle_s + duration_s) / record_interval_s`):
    /// tracks are held in memory until stored, about 150 bytes a sample and contact.
    pub const MAX_RECORDED_POINTS: f64 = 1.0e7;
    /// Relative error tolerance range: looser than 10 % is no error control; tighter than
    /// 1e-10 is below what double precision holds over a run.
    pub const REL_TOLERANCE_RANGE: (f64, f64) = (1.0e-10, 0.1);
    /// Absolute position tolerance range, m: coarser than 0.1 mm does not resolve the 0.2 mm
    /// clearance of the tight rail; finer than 1e-15 m is below double precision on metres.
    pub const ABS_TOLERANCE_M_RANGE: (f64, f64) = (1.0e-15, 1.0e-4);
    /// Points of a tolerance sweep: at least 2 (a curve needs two ends), at most 50 (each
    /// point is a full launcher simulation).
    pub const SWEEP_POINTS: std::ops::RangeInclusive<u64> = 2..=50;
    /// Seeds (independent excitation draws) per sweep point: 1 to 10. One seed gives no
    /// confidence interval; 3 (the default, [`super::DEFAULT_SWEEP_SEEDS`]) is the fewest whose
    /// t-interval is not dominated by the t quantile (df 1 needs 6.31 standard errors, df 2
    /// 2.92); beyond 10 the interval narrows by less than 5 % a seed.
    pub const SWEEP_SEEDS: std::ops::RangeInclusive<u64> = 1..=10;
    /// Most simulations of one sweep (`points * seeds`): each is a full launcher run and one
    /// child job; 200 keeps a sweep's fan-out and its assembly in one short transaction.
    pub const MAX_SWEEP_RUNS: u64 = 200;
    /// Largest seed, 2^53 - 1: every seed a JSON reader parses into a double (JavaScript, jq)
    /// is then exact, so a run can be reproduced from what a dashboard shows.
    pub const MAX_SEED: u64 = (1 << 53) - 1;
    /// Material density range of a wear calibration, kg/m³: from polymers to the densest
    /// metals (osmium 22 590).
    pub const DENSITY_KG_M3_RANGE: (f64, f64) = (500.0, 25_000.0);
    /// Largest wear-law cutoff pressure, Pa: 10 GPa, above the hardness of any engineering
    /// alloy (7075-T73: 2 S_y = 870 MPa).
    pub const MAX_CUTOFF_PRESSURE_PA: f64 = 1.0e10;
    /// Most records of one calibration data set (a request body holds them anyway).
    pub const MAX_CALIBRATION_RECORDS: usize = 100_000;
    /// Simulated excitation per increment of a diagnosis (and of the virtual rig), s: at least
    /// one period of the thesis' slowest drive (20 Hz), at most ten minutes
    /// ([`MAX_SETTLE_S`]'s reason: past that a window is a typing error, not a test).
    pub const WINDOW_S_RANGE: (f64, f64) = (0.05, 600.0);
    /// Grid points per effect parameter of a diagnosis' emulator: two ends at least; each point
    /// costs one simulation per test, and 12 caps that cost.
    pub const GRID_POINTS: std::ops::RangeInclusive<usize> = 2..=12;
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
