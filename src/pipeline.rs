//! The one narrow interface between the service (jobs) and the simulation library.
//!
//! A job hands a case configuration (JSON, the same schema as the TOML files in `configs/`)
//! and a [`RunControl`]; it gets back a [`CaseOutcome`] or a [`RunError`].

use crate::physics::track::TrackSample;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

pub use crate::physics::control::{Progress, RunControl};

/// What a finished case produces.
#[derive(Debug, Clone)]
pub struct CaseOutcome {
    /// Summary: wear per contact and body (mg, mg/h), above-cutoff work share, pressure PDFs,
    /// spectra, settings used. JSON object.
    pub summary: serde_json::Value,
    /// Recorded contact-track samples (may be many).
    pub tracks: Vec<TrackSample>,
    /// Named SVG plots: (file name, SVG text).
    pub plots: Vec<(String, String)>,
}

/// Why a run did not produce an outcome.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The configuration broke a rule; `field` is a dotted path into the config.
    #[error("invalid configuration: field `{field}` {rule}")]
    InvalidConfig { field: String, rule: String },
    /// The simulation diverged; the message names time, body, contact and energy.
    #[error("simulation diverged: {0}")]
    Diverged(String),
    /// Cancelled through [`RunControl::cancel`].
    #[error("cancelled")]
    Cancelled,
    /// Stopped with a checkpoint ([`RunControl::request_checkpoint`]): handing its bytes to
    /// the same computation again resumes it (`models::case::run_case_from`).
    #[error("checkpointed at t = {:.6} s", .0.simulated_time_s)]
    Checkpointed(Box<crate::models::checkpoint::Checkpoint>),
}

use crate::models::case::{load_case, run_case};
use crate::models::specs::CaseSpec;
use std::path::Path;

fn invalid(field: &str, rule: impl Into<String>) -> RunError {
    RunError::InvalidConfig {
        field: field.to_string(),
        rule: rule.into(),
    }
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
        .ok_or_else(|| invalid(field, "must be a JSON object"))?;
    for key in map.keys() {
        if !allowed.contains(&key.as_str()) {
            let path = if field == "params" {
                key.clone()
            } else {
                format!("{field}.{key}")
            };
            return Err(invalid(
                &path,
                format!("is not a known parameter (known: {})", allowed.join(", ")),
            ));
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
            invalid(
                "seed",
                "must be an integer in [0, 2^53) (JavaScript reads larger integers inexactly)",
            )
        })
}

/// True when the dotted `path` (`simulation.duration_s`) is set in `value`.
fn sets_path(value: &serde_json::Value, path: &str) -> bool {
    let mut v = value;
    for part in path.split('.') {
        match v.get(part) {
            Some(next) => v = next,
            None => return false,
        }
    }
    true
}

/// Where a case field's value came from, as a params path: the overrides when they set it (or
/// a parent of it), otherwise the config.
fn locate(case_field: &str, overrides: Option<&serde_json::Value>) -> String {
    let field = case_field.trim_matches('.');
    if field.is_empty() || field == "toml" {
        return "config".into();
    }
    if let Some(over) = overrides {
        let parts: Vec<&str> = field.split('.').collect();
        for n in (1..=parts.len()).rev() {
            if sets_path(over, &parts[..n].join(".")) {
                return format!("overrides.{field}");
            }
        }
    }
    format!("config.{field}")
}

/// Checks the run-control bounds of [`limits`]; the error's field is a case path.
fn check_simulation_bounds(case: &CaseSpec) -> Result<(), (String, String)> {
    let s = &case.simulation;
    let bad = |field: &str, rule: String| Err((format!("simulation.{field}"), rule));
    if !(s.duration_s.is_finite() && s.duration_s > 0.0 && s.duration_s <= limits::MAX_DURATION_S) {
        return bad(
            "duration_s",
            format!(
                "must be > 0 and <= {} s (24 h of simulated time), got {}",
                limits::MAX_DURATION_S,
                s.duration_s
            ),
        );
    }
    if !(s.settle_s.is_finite() && s.settle_s >= 0.0 && s.settle_s <= limits::MAX_SETTLE_S) {
        return bad(
            "settle_s",
            format!(
                "must be >= 0 and <= {} s (past the contact creep time constant), got {}",
                limits::MAX_SETTLE_S,
                s.settle_s
            ),
        );
    }
    let (lo, hi) = limits::REL_TOLERANCE_RANGE;
    if !(s.rel_tolerance >= lo && s.rel_tolerance <= hi) {
        return bad(
            "rel_tolerance",
            format!("must lie in [{lo:e}, {hi}], got {}", s.rel_tolerance),
        );
    }
    let (lo, hi) = limits::ABS_TOLERANCE_M_RANGE;
    if !(s.abs_tolerance_m >= lo && s.abs_tolerance_m <= hi) {
        return bad(
            "abs_tolerance_m",
            format!("must lie in [{lo:e}, {hi:e}] m, got {}", s.abs_tolerance_m),
        );
    }
    let dt = s.record_interval_s;
    if !(dt.is_finite() && dt >= limits::MIN_RECORD_INTERVAL_S && dt <= s.duration_s) {
        return bad(
            "record_interval_s",
            format!(
                "must lie in [{:e} s, duration_s], got {dt}",
                limits::MIN_RECORD_INTERVAL_S
            ),
        );
    }
    let points = (s.settle_s + s.duration_s) / dt;
    if points > limits::MAX_RECORDED_POINTS {
        return bad(
            "record_interval_s",
            format!(
                "records {points:.3e} time points over settle_s + duration_s; at most {:e} \
                 are kept in memory: raise record_interval_s or shorten the run",
                limits::MAX_RECORDED_POINTS
            ),
        );
    }
    Ok(())
}

/// Resolves job parameters to a validated case: `{"config": "<reference name>" | {inline
/// case}, "overrides": {...}, "seed": n}` (other keys are the caller's to check). Overrides
/// deep-merge into the case (e.g. `{"simulation": {"duration_s": 0.5}}`); `seed` sets
/// `simulation.seed`. `adjust` edits the typed case before it is checked (a sweep sets its
/// excitation). The case is checked completely: unknown keys anywhere, the model's own rules,
/// the bounds of [`limits`], and the model is built once (excitation, geometry, integrator),
/// so an accepted job does not fail on its configuration later. Errors name the params path
/// (`config`, `config.<path>` or `overrides.<path>`).
pub fn resolve_case(
    params: &serde_json::Value,
    configs_dir: &Path,
    adjust: impl FnOnce(&mut CaseSpec) -> Result<(), RunError>,
) -> Result<CaseSpec, RunError> {
    let mut value = match params.get("config") {
        Some(serde_json::Value::String(name)) => {
            let path = crate::config::reference_config_path(configs_dir, name)
                .map_err(|e| invalid("config", e.to_string()))?;
            let case = load_case(&path)?;
            serde_json::to_value(&case).map_err(|e| invalid("config", e.to_string()))?
        }
        Some(obj @ serde_json::Value::Object(_)) => obj.clone(),
        Some(_) => {
            return Err(invalid(
                "config",
                "must be a reference config name or a config object",
            ))
        }
        None => {
            return Err(invalid(
                "config",
                "is required (a reference config name or a config object)",
            ))
        }
    };
    let overrides = params.get("overrides");
    if let Some(over) = overrides {
        if !over.is_object() {
            return Err(invalid("overrides", "must be an object"));
        }
        merge_json(&mut value, over);
    }
    if let Some(seed) = params.get("seed") {
        let seed = parse_seed(seed)?;
        merge_json(
            &mut value,
            &serde_json::json!({"simulation": {"seed": seed}}),
        );
    }
    let mut case: CaseSpec = serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        invalid(&locate(&path, overrides), e.into_inner().to_string())
    })?;
    adjust(&mut case)?;
    let relocate = |e: RunError| match e {
        RunError::InvalidConfig { field, rule } => RunError::InvalidConfig {
            field: locate(&field, overrides),
            rule,
        },
        other => other,
    };
    case.validate().map_err(|e| relocate(e.into()))?;
    check_simulation_bounds(&case).map_err(|(field, rule)| relocate(invalid(&field, rule)))?;
    crate::models::case::run_options(&case).map_err(relocate)?;
    crate::models::case::build(&case, configs_dir).map_err(relocate)?;
    Ok(case)
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

/// The rattle-space range, points and seeds of a tolerance sweep, read from its params alone
/// (no config is loaded: the report reads it from a queued sweep's params to tell whether that
/// sweep will cover a rail).
///
/// Every point is `base.with_material_condition(offset)`: rail dimensions grow by the offset,
/// shoe dimensions shrink by it (docs/launcher-dimensions.md). The range is given as one of
/// - `rattle_space_range: {"min": k1, "max": k2}`: points evenly spaced in k_rs, or
/// - `offset_mm_range: {"min": d1, "max": d2}`: points evenly spaced in the offset, mm,
/// - neither: the thesis' tolerance band, offsets -0.201 to +0.1955 mm (k_rs 0.8317 to 0.7684).
///
/// Bounds, with their reasons: every point's dimensions must pass the checks a measured rail
/// passes ([`LauncherDimensions::validate`]: assembly, +-50 % of design), so a sweep reaches
/// exactly the rails a planner can record; for the design base that is offsets in
/// (-0.30, +4.765] mm, k_rs about 0.28 to 0.848. The range must contain the design rattle
/// space, because K_SL is the ratio to the wear rate there (eq. 6.4). A rail tighter than the
/// design family reaches (a measured k_rs of 0.861) is covered by a sweep around its own
/// dimensions: `base_dimensions_mm` (default: the design rail).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRange {
    /// Dimensions the offsets apply to, mm.
    pub base: LauncherDimensions,
    /// True when `base` is the design rail.
    pub design_base: bool,
    /// Offsets of the points, mm, tight to loose (increasing).
    pub offsets_mm: Vec<f64>,
    /// Rattle space of each point (eq. 6.1-6.3), decreasing.
    pub rattle_spaces: Vec<f64>,
    /// Seeds per point.
    pub seeds: usize,
}

use crate::analysis::rattle_space::LauncherDimensions;

/// Rattle space of `base` moved by `offset_mm`, if those dimensions are a valid rail.
fn offset_rattle_space(base: &LauncherDimensions, offset_mm: f64) -> Option<f64> {
    base.with_material_condition(offset_mm).rattle_space().ok()
}

/// The offsets (mm) over which `base` stays a valid rail ([`LauncherDimensions::validate`]):
/// each rule is linear in the offset, so they form an interval around 0; its ends are found by
/// bisection to 1e-9 mm and returned on the valid side.
pub fn offset_limits_mm(base: &LauncherDimensions) -> (f64, f64) {
    let valid = |o: f64| offset_rattle_space(base, o).is_some();
    let edge = |far: f64| {
        let (mut good, mut bad) = (0.0, far);
        if valid(far) {
            return far;
        }
        while (bad - good).abs() > 1e-9 {
            let mid = 0.5 * (good + bad);
            if valid(mid) {
                good = mid;
            } else {
                bad = mid;
            }
        }
        good
    };
    (edge(-100.0), edge(100.0))
}

/// The offset (mm) at which `base` has rattle space `target`, within `limits`; k_rs falls as the
/// offset grows (looser). `None` if no offset in the limits reaches it to 1e-9.
fn offset_for_rattle_space(
    base: &LauncherDimensions,
    target: f64,
    limits: (f64, f64),
) -> Option<f64> {
    let k = |o: f64| offset_rattle_space(base, o).unwrap_or(f64::NAN);
    let (mut lo, mut hi) = limits;
    if !(k(lo) >= target && k(hi) <= target) {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if k(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-13 {
            break;
        }
    }
    let o = 0.5 * (lo + hi);
    ((k(o) - target).abs() < 1e-9).then_some(o)
}

/// `{"min": a, "max": b}` at `field`, with `a < b`, both finite.
fn parse_min_max(value: &serde_json::Value, field: &str) -> Result<(f64, f64), RunError> {
    let map = check_keys(value, field, &["min", "max"])?;
    let num = |name: &str| {
        map.get(name)
            .and_then(serde_json::Value::as_f64)
            .filter(|x| x.is_finite())
            .ok_or_else(|| invalid(&format!("{field}.{name}"), "is required (a finite number)"))
    };
    let (min, max) = (num("min")?, num("max")?);
    if min >= max {
        return Err(invalid(
            field,
            format!("needs min < max, got min {min} and max {max}"),
        ));
    }
    Ok((min, max))
}

impl SweepRange {
    /// Reads `points`, `seeds`, `base_dimensions_mm` and `rattle_space_range` or
    /// `offset_mm_range` (see the type's documentation); errors name the params field.
    pub fn from_params(params: &serde_json::Value) -> Result<Self, RunError> {
        let n = match params.get("points") {
            None => 5,
            Some(v) => v
                .as_u64()
                .filter(|n| limits::SWEEP_POINTS.contains(n))
                .ok_or_else(|| {
                    invalid(
                        "points",
                        format!(
                            "must be an integer in {}..={}",
                            limits::SWEEP_POINTS.start(),
                            limits::SWEEP_POINTS.end()
                        ),
                    )
                })? as usize,
        };
        let seeds = match params.get("seeds") {
            None => DEFAULT_SWEEP_SEEDS,
            Some(v) => v
                .as_u64()
                .filter(|n| limits::SWEEP_SEEDS.contains(n))
                .ok_or_else(|| {
                    invalid(
                        "seeds",
                        format!(
                            "must be an integer in {}..={} (seeds per point; 1 gives no \
                             confidence interval)",
                            limits::SWEEP_SEEDS.start(),
                            limits::SWEEP_SEEDS.end()
                        ),
                    )
                })?,
        };
        if n as u64 * seeds > limits::MAX_SWEEP_RUNS {
            return Err(invalid(
                "seeds",
                format!(
                    "points x seeds = {} simulations; at most {} per sweep",
                    n as u64 * seeds,
                    limits::MAX_SWEEP_RUNS
                ),
            ));
        }
        let (base, design_base) = match params.get("base_dimensions_mm") {
            None => (LauncherDimensions::design(), true),
            Some(v) => {
                if !v.is_object() {
                    return Err(invalid(
                        "base_dimensions_mm",
                        "must be an object of named dimensions in mm (as a measurement's \
                         dimensions_mm)",
                    ));
                }
                let dims: LauncherDimensions = serde_path_to_error::deserialize(v.clone())
                    .map_err(|e| {
                        let path = e.path().to_string();
                        let field = if path == "." || path.is_empty() {
                            "base_dimensions_mm".to_string()
                        } else {
                            format!("base_dimensions_mm.{path}")
                        };
                        invalid(&field, e.into_inner().to_string())
                    })?;
                dims.rattle_space().map_err(
                    |crate::analysis::rattle_space::RattleSpaceError::InvalidDimension {
                         field,
                         rule,
                     }| invalid(&format!("base_dimensions_mm.{field}"), rule),
                )?;
                (dims, dims == LauncherDimensions::design())
            }
        };
        let limits_mm = offset_limits_mm(&base);
        let k_of = |o: f64| offset_rattle_space(&base, o).unwrap_or(f64::NAN);
        let (k_hi, k_lo) = (k_of(limits_mm.0), k_of(limits_mm.1));
        let spaced = |a: f64, b: f64| -> Vec<f64> {
            (0..n)
                .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
                .collect()
        };
        let (offsets_mm, field) = match (
            params.get("rattle_space_range"),
            params.get("offset_mm_range"),
        ) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "offset_mm_range",
                    "give either rattle_space_range or offset_mm_range, not both",
                ))
            }
            (Some(range), None) => {
                let (min, max) = parse_min_max(range, "rattle_space_range")?;
                if min < k_lo || max > k_hi {
                    return Err(invalid(
                        "rattle_space_range",
                        format!(
                            "[{min}, {max}] leaves the rattle spaces the base dimensions reach \
                             as a valid rail, [{k_lo:.4}, {k_hi:.4}] (offsets {:.3} to {:.3} \
                             mm); for a tighter or looser rail give its own dimensions as \
                             base_dimensions_mm",
                            limits_mm.0, limits_mm.1
                        ),
                    ));
                }
                let offsets = spaced(max, min)
                    .into_iter()
                    .map(|k| {
                        offset_for_rattle_space(&base, k, limits_mm).ok_or_else(|| {
                            invalid(
                                "rattle_space_range",
                                format!("rattle space {k} is not reached by the base dimensions"),
                            )
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                (offsets, "rattle_space_range")
            }
            (None, Some(range)) => {
                let (min, max) = parse_min_max(range, "offset_mm_range")?;
                if min < limits_mm.0 || max > limits_mm.1 {
                    return Err(invalid(
                        "offset_mm_range",
                        format!(
                            "[{min}, {max}] mm leaves the offsets at which the base dimensions \
                             stay a valid rail, [{:.4}, {:.4}] mm (assembly and +-50 % of \
                             design, docs/launcher-dimensions.md)",
                            limits_mm.0, limits_mm.1
                        ),
                    ));
                }
                (spaced(min, max), "offset_mm_range")
            }
            (None, None) => (sweep_offsets_mm(n), "base_dimensions_mm"),
        };
        let rattle_spaces = offsets_mm
            .iter()
            .map(|&o| {
                offset_rattle_space(&base, o).ok_or_else(|| {
                    invalid(
                        field,
                        format!(
                            "offset {o} mm does not give a valid rail from the base dimensions"
                        ),
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let design = design_rattle_space();
        let (k_min, k_max) = rattle_spaces
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &k| {
                (a.min(k), b.max(k))
            });
        if !(k_min <= design && design <= k_max) {
            return Err(invalid(
                field,
                format!(
                    "gives rattle spaces [{k_min:.4}, {k_max:.4}], which must contain the design \
                     rattle space {design:.4}: K_SL is the ratio to the wear rate there (eq. 6.4)"
                ),
            ));
        }
        Ok(Self {
            base,
            design_base,
            offsets_mm,
            rattle_spaces,
            seeds: seeds as usize,
        })
    }

    /// Swept rattle-space range `(min, max)`.
    pub fn rattle_space_bounds(&self) -> (f64, f64) {
        self.rattle_spaces
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &k| {
                (a.min(k), b.max(k))
            })
    }
}

/// Rattle space of the design rail (eq. 6.1-6.3), 0.7990.
pub fn design_rattle_space() -> f64 {
    LauncherDimensions::design()
        .rattle_space()
        .unwrap_or(f64::NAN)
}

/// Params of a sweep whose range covers rattle space `k_rs` (and the design point), built on
/// `template` (the published curve's sweep params, or a bare sweep): its range is replaced by
/// `rattle_space_range` from `min(k_rs, design) - 0.005` to `max(k_rs, design) + 0.005`
/// (clipped to what a valid rail reaches), with no fewer points than the template nor a coarser
/// spacing than the thesis' band in 5 points. A k_rs the design family cannot reach (tighter
/// than its zero vertical clearance) gets `base_dimensions_mm` = the rail's own dimensions.
/// `None` when even the rail's own dimensions cannot span it.
pub fn covering_sweep_params(
    template: &serde_json::Value,
    k_rs: f64,
    rail: Option<&LauncherDimensions>,
) -> Option<serde_json::Value> {
    let design = design_rattle_space();
    let mut params = template.as_object().cloned().unwrap_or_default();
    for key in [
        "rattle_space_range",
        "offset_mm_range",
        "base_dimensions_mm",
        "seed",
    ] {
        params.remove(key);
    }
    let margin = 0.005;
    let candidates: Vec<(LauncherDimensions, bool)> =
        std::iter::once((LauncherDimensions::design(), true))
            .chain(rail.map(|r| (*r, false)))
            .collect();
    for (base, is_design) in candidates {
        let limits_mm = offset_limits_mm(&base);
        let k_of = |o: f64| offset_rattle_space(&base, o).unwrap_or(f64::NAN);
        // Keep a hair inside the valid interval so the ends are reachable by bisection.
        let (k_lo, k_hi) = (k_of(limits_mm.1), k_of(limits_mm.0));
        let lo = (k_rs.min(design) - margin).max(k_lo + 1e-6);
        let hi = (k_rs.max(design) + margin).min(k_hi - 1e-6);
        if !(lo <= k_rs.min(design) && hi >= k_rs.max(design) && lo < hi) {
            continue;
        }
        let thesis_spacing = (0.8317 - 0.7684) / 4.0;
        let template_points = template
            .get("points")
            .and_then(serde_json::Value::as_u64)
            .unwrap_or(5);
        let needed = ((hi - lo) / thesis_spacing).ceil() as u64 + 1;
        let seeds = template
            .get("seeds")
            .and_then(serde_json::Value::as_u64)
            .unwrap_or(DEFAULT_SWEEP_SEEDS)
            .max(1);
        let max_points = (limits::MAX_SWEEP_RUNS / seeds).min(*limits::SWEEP_POINTS.end());
        let points = needed.max(template_points).clamp(2, max_points);
        params.insert("points".into(), points.into());
        let (rlo, rhi) = (round_to(lo, 4, false), round_to(hi, 4, true));
        let rlo = if rlo > k_lo + 1e-6 { rlo } else { lo };
        let rhi = if rhi < k_hi - 1e-6 { rhi } else { hi };
        params.insert(
            "rattle_space_range".into(),
            serde_json::json!({"min": rlo, "max": rhi}),
        );
        if !is_design {
            params.insert(
                "base_dimensions_mm".into(),
                serde_json::to_value(base).unwrap_or_default(),
            );
        }
        let candidate = serde_json::Value::Object(params.clone());
        // The suggestion must itself be a valid range (rounding stays inside the limits).
        if SweepRange::from_params(&candidate).is_ok() {
            return Some(candidate);
        }
        params.remove("base_dimensions_mm");
    }
    None
}

/// `x` rounded to `digits` decimals, up or down.
fn round_to(x: f64, digits: i32, up: bool) -> f64 {
    let f = 10f64.powi(digits);
    let y = if up { (x * f).ceil() } else { (x * f).floor() };
    y / f
}

/// The seed of replica `replica` of a sweep seeded `seed`: `seed + replica` modulo 2^53, so
/// replica 0 runs the sweep's own seed (a one-seed sweep is the sweep of before) and every seed
/// stays below 2^53 ([`limits::MAX_SEED`]).
pub fn replica_seed(seed: u64, replica: usize) -> u64 {
    (seed.wrapping_add(replica as u64)) & limits::MAX_SEED
}

/// One point of a tolerance sweep.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SweepPoint {
    /// Material-condition offset applied to the launcher dimensions, mm (negative = tighter).
    pub offset_mm: f64,
    /// Rattle space k_rs (eq. 6.1-6.3).
    pub rattle_space: f64,
    /// Rail wear rate, mg/h.
    pub rail_wear_rate_mg_per_h: f64,
}

/// Result of a tolerance sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepOutcome {
    /// Rattle space of the design dimensions.
    pub design_rattle_space: f64,
    /// Points, tight to loose; each rate is the geometric mean over the seeds (the mean of
    /// ln(rate), the quantity the curve interpolates).
    pub points: Vec<SweepPoint>,
    /// Seeds of the replicas, in replica order ([`replica_seed`]).
    #[serde(default)]
    pub seeds: Vec<u64>,
    /// Per point (same order), the rail wear rate of each seed, mg/h.
    #[serde(default)]
    pub rate_by_seed_mg_per_h: Vec<Vec<f64>>,
}

/// Material-condition offsets (mm) of an n-point sweep from tight to loose.
pub fn sweep_offsets_mm(n: usize) -> Vec<f64> {
    use crate::analysis::rattle_space::{LOOSE_MATERIAL_CONDITION_MM, TIGHT_MATERIAL_CONDITION_MM};
    let n = n.max(2);
    (0..n)
        .map(|i| {
            TIGHT_MATERIAL_CONDITION_MM
                + (LOOSE_MATERIAL_CONDITION_MM - TIGHT_MATERIAL_CONDITION_MM) * i as f64
                    / (n - 1) as f64
        })
        .collect()
}

/// Vehicle profile of a sweep when its params name none (the service fills in its own default
/// from `[report]` before storing a sweep).
pub const DEFAULT_VEHICLE_PROFILE: &str = "ah64";
/// Environment of a sweep when its params name none.
pub const DEFAULT_ENVIRONMENT: &str = "clean";
/// Wear law of a sweep when its params name none.
pub const DEFAULT_WEAR_LAW: &str = "modified-archard";
/// Vehicle-profile names that are not file stems: `ah64` is the AH-64 transverse
/// sine-on-random of `configs/profiles/ah64-transverse.toml`.
pub const VEHICLE_PROFILE_ALIASES: &[(&str, &str)] = &[("ah64", "ah64-transverse")];
/// Environments the wear model represents: only clean, dry contacts (third-body abrasion by
/// sand or dust is not modelled, SPEC 7).
pub const ENVIRONMENTS: &[&str] = &["clean"];
/// Wear-law names of a sweep and what they select: `modified-archard` (eq. 3.10-3.15; Table
/// 4.3 unless the config gives other constants), `archard` (eq. 3.8; the config or overrides
/// must give `wear.law = {kind = "archard", coefficient_m2_per_n = ..}`), `legacy-appendix`
/// (the thesis' appendix C code with Table 4.3).
pub const WEAR_LAWS: &[&str] = &["modified-archard", "archard", "legacy-appendix"];

/// Vehicle profiles a sweep may name: the aliases and every profile file in
/// `<configs_dir>/profiles`, sorted.
pub fn vehicle_profile_names(configs_dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = VEHICLE_PROFILE_ALIASES
        .iter()
        .map(|(alias, _)| alias.to_string())
        .collect();
    names.extend(crate::config::reference_config_names(
        &configs_dir.join("profiles"),
    ));
    names.sort();
    names.dedup();
    names
}

/// The profile file stem (`configs/profiles/<stem>.toml`) a vehicle-profile name selects.
pub fn vehicle_profile_file(configs_dir: &Path, name: &str) -> Result<String, RunError> {
    let stem = VEHICLE_PROFILE_ALIASES
        .iter()
        .find(|(alias, _)| *alias == name)
        .map_or(name, |(_, stem)| stem);
    let dir = configs_dir.join("profiles");
    match crate::config::reference_config_path(&dir, stem) {
        Ok(_) => Ok(stem.to_string()),
        Err(_) => Err(invalid(
            "vehicle_profile",
            format!(
                "`{name}` is not a vehicle profile in {} (known: {})",
                dir.display(),
                vehicle_profile_names(configs_dir).join(", ")
            ),
        )),
    }
}

/// The wear-law name of a law (see [`WEAR_LAWS`]).
pub fn wear_law_name(law: &crate::wear::law::WearLaw) -> &'static str {
    use crate::wear::law::WearLaw;
    match law {
        WearLaw::Modified { .. } => "modified-archard",
        WearLaw::Archard { .. } => "archard",
        WearLaw::LegacyAppendix { .. } => "legacy-appendix",
    }
}

/// Makes the case's wear law the one `name` selects: a case whose law already is of that kind
/// keeps its constants; a case on one of the Table 4.3 presets moves to the other preset;
/// anything else (an Archard law without a coefficient) is refused.
fn select_wear_law(case: &mut CaseSpec, name: &str) -> Result<(), RunError> {
    use crate::wear::law::WearLaw;
    if !WEAR_LAWS.contains(&name) {
        return Err(invalid(
            "wear_law",
            format!(
                "`{name}` is not a wear law (known: {})",
                WEAR_LAWS.join(", ")
            ),
        ));
    }
    let current = case.wear.law;
    if wear_law_name(&current) == name {
        return Ok(());
    }
    let preset = current == WearLaw::table_4_3() || current == WearLaw::legacy_table_4_3();
    case.wear.law = match name {
        "modified-archard" if preset => WearLaw::table_4_3(),
        "legacy-appendix" if preset => WearLaw::legacy_table_4_3(),
        _ => {
            return Err(invalid(
                "wear_law",
                format!(
                    "`{name}` does not match the config's wear law ({}); give its constants in \
                     overrides.wear.law (e.g. {{\"kind\": \"archard\", \
                     \"coefficient_m2_per_n\": 1e-15}})",
                    wear_law_name(&current)
                ),
            ))
        }
    };
    Ok(())
}

/// A planned tolerance sweep: the launcher case every point starts from and the
/// material-condition offsets of its points. Built from a sweep job's params alone, so the
/// sequential [`sweep_job`] and each `sweep_point` child job of a fanned-out sweep agree on it.
#[derive(Debug, Clone)]
pub struct SweepPlan {
    /// The launcher case of `params.config` (default `launcher-design`) with `overrides` and
    /// `seed` applied, its excitation the vehicle profile's and its wear law the one named;
    /// each point replaces its launcher dimensions.
    pub base: CaseSpec,
    /// Material-condition offsets of the points, mm, tight to loose (`range.offsets_mm`).
    pub offsets_mm: Vec<f64>,
    /// Range, points, seeds and base dimensions ([`SweepRange`]).
    pub range: SweepRange,
    /// Seed of each replica ([`replica_seed`] of the sweep's seed).
    pub seeds: Vec<u64>,
    /// Rattle space of the design dimensions (eq. 6.1-6.3), dimensionless.
    pub design_rattle_space: f64,
    /// Vehicle profile (excitation) name, e.g. `ah64`.
    pub vehicle_profile: String,
    /// Environment name (`clean`).
    pub environment: String,
    /// Wear-law name ([`WEAR_LAWS`]).
    pub wear_law: String,
    /// `sweep_point` children: the point this child runs.
    pub point: Option<usize>,
    /// `sweep_point` children: the replica (seed index) this child runs.
    pub replica: Option<usize>,
}

impl SweepPlan {
    /// Plan the sweep of `params` ([`SWEEP_KEYS`], plus `point` for a child): `config`
    /// (default `launcher-design`, must be a launcher case), `overrides`, `seed`, `points`
    /// (default 5, [`limits::SWEEP_POINTS`]), `vehicle_profile` (selects the excitation: a
    /// profile in `configs/profiles`, see [`vehicle_profile_file`]), `environment`
    /// ([`ENVIRONMENTS`]) and `wear_law` ([`WEAR_LAWS`]). Every rule of [`resolve_case`]
    /// applies to the base case.
    pub fn from_params(params: &serde_json::Value, configs_dir: &Path) -> Result<Self, RunError> {
        let mut keys = SWEEP_KEYS.to_vec();
        keys.extend(["point", "replica"]);
        check_keys(params, "params", &keys)?;
        let text = |name: &str, default: &str| -> Result<String, RunError> {
            match params.get(name) {
                None => Ok(default.to_string()),
                Some(serde_json::Value::String(s)) => Ok(s.clone()),
                Some(_) => Err(invalid(name, "must be a string")),
            }
        };
        let vehicle_profile = text("vehicle_profile", DEFAULT_VEHICLE_PROFILE)?;
        let environment = text("environment", DEFAULT_ENVIRONMENT)?;
        let wear_law = text("wear_law", DEFAULT_WEAR_LAW)?;
        let profile_file = vehicle_profile_file(configs_dir, &vehicle_profile)?;
        if !ENVIRONMENTS.contains(&environment.as_str()) {
            return Err(invalid(
                "environment",
                format!(
                    "`{environment}` is not modelled (known: {}; sand or dust abrasion is not \
                     part of the wear model)",
                    ENVIRONMENTS.join(", ")
                ),
            ));
        }
        if params
            .get("overrides")
            .is_some_and(|o| o.get("excitation").is_some())
        {
            return Err(invalid(
                "overrides.excitation",
                "a sweep's excitation is its vehicle_profile; remove it (or run simulate jobs)",
            ));
        }
        let range = SweepRange::from_params(params)?;
        let n = range.offsets_mm.len();
        let point = match params.get("point") {
            None => None,
            Some(v) => Some(
                v.as_u64()
                    .filter(|i| *i < n as u64)
                    .ok_or_else(|| invalid("point", format!("must be an integer below {n}")))?
                    as usize,
            ),
        };
        let replica = match params.get("replica") {
            None => None,
            Some(v) => Some(
                v.as_u64()
                    .filter(|i| *i < range.seeds as u64)
                    .ok_or_else(|| {
                        invalid(
                            "replica",
                            format!("must be an integer below {}", range.seeds),
                        )
                    })? as usize,
            ),
        };
        let mut p = params.clone();
        if p.get("config").is_none() {
            merge_json(&mut p, &serde_json::json!({"config": "launcher-design"}));
        }
        let base = resolve_case(&p, configs_dir, |case| {
            if case.launcher.is_none() {
                return Err(invalid(
                    "config",
                    "a sweep varies launcher rail dimensions: it needs a launcher case \
                     (launcher-tight, launcher-design, launcher-loose or an inline launcher)",
                ));
            }
            case.excitation = serde_json::json!({"kind": "profile", "profile": profile_file});
            select_wear_law(case, &wear_law)
        })?;
        let design_rattle_space = design_rattle_space();
        let seeds = (0..range.seeds)
            .map(|j| replica_seed(base.simulation.seed, j))
            .collect();
        Ok(Self {
            base,
            offsets_mm: range.offsets_mm.clone(),
            range,
            seeds,
            design_rattle_space,
            vehicle_profile,
            environment,
            wear_law,
            point,
            replica,
        })
    }

    /// Simulations of the sweep: points x seeds (one child job each).
    pub fn runs(&self) -> usize {
        self.len() * self.seeds.len()
    }

    /// Child index of point `point`, replica `replica` (point-major).
    pub fn run_index(&self, point: usize, replica: usize) -> usize {
        point * self.seeds.len() + replica
    }

    /// Excited duration of each simulation, s (the curve's fidelity).
    pub fn duration_per_point_s(&self) -> f64 {
        self.base.simulation.duration_s
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.offsets_mm.len()
    }

    /// True when the plan has no points (never for a plan from [`SweepPlan::from_params`]).
    pub fn is_empty(&self) -> bool {
        self.offsets_mm.is_empty()
    }

    /// Simulated time one point runs to, s (settle + duration).
    pub fn point_end_time_s(&self) -> f64 {
        self.base.simulation.settle_s + self.base.simulation.duration_s
    }

    /// The outcome of the sweep from its runs in child order ([`SweepPlan::run_index`]): per
    /// point, the geometric mean of its seeds' rates and the rates themselves.
    pub fn outcome(&self, runs: Vec<SweepPoint>) -> Result<SweepOutcome, RunError> {
        let per = self.seeds.len().max(1);
        if runs.len() != self.runs() {
            return Err(invalid(
                "points",
                format!(
                    "the sweep has {} runs but {} results",
                    self.runs(),
                    runs.len()
                ),
            ));
        }
        let mut points = Vec::with_capacity(self.len());
        let mut rates = Vec::with_capacity(self.len());
        for chunk in runs.chunks(per) {
            let by_seed: Vec<f64> = chunk.iter().map(|r| r.rail_wear_rate_mg_per_h).collect();
            let mean_ln = by_seed.iter().map(|r| r.ln()).sum::<f64>() / by_seed.len() as f64;
            let rate = if by_seed.len() == 1 {
                by_seed[0]
            } else {
                mean_ln.exp()
            };
            points.push(SweepPoint {
                offset_mm: chunk[0].offset_mm,
                rattle_space: chunk[0].rattle_space,
                rail_wear_rate_mg_per_h: rate,
            });
            rates.push(by_seed);
        }
        Ok(SweepOutcome {
            design_rattle_space: self.design_rattle_space,
            points,
            seeds: self.seeds.clone(),
            rate_by_seed_mg_per_h: rates,
        })
    }
}

/// Point `index` of a planned sweep: the base case with the design dimensions moved by the
/// point's material-condition offset, run to the end; the rail's wear rate there. The
/// sequential [`sweep_job`] and a fanned-out sweep's `sweep_point` child jobs both call this, so a
/// point depends only on the sweep's params and seed.
pub fn sweep_point(
    plan: &SweepPlan,
    index: usize,
    replica: usize,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<SweepPoint, RunError> {
    sweep_point_from(plan, index, replica, configs_dir, control, None)
}

/// [`sweep_point`] resuming from `resume`, a checkpoint of this point's run
/// (`RunError::Checkpointed`), as a simulate job does.
pub fn sweep_point_from(
    plan: &SweepPlan,
    index: usize,
    replica: usize,
    configs_dir: &Path,
    control: &RunControl,
    resume: Option<&[u8]>,
) -> Result<SweepPoint, RunError> {
    let offset_mm = *plan
        .offsets_mm
        .get(index)
        .ok_or_else(|| invalid("point", format!("must be below {}", plan.len())))?;
    let seed = *plan
        .seeds
        .get(replica)
        .ok_or_else(|| invalid("replica", format!("must be below {}", plan.seeds.len())))?;
    let mut case = plan.base.clone();
    case.simulation.seed = seed;
    if let Some(l) = case.launcher.as_mut() {
        l.dimensions = plan.range.base.with_material_condition(offset_mm);
    }
    let rattle_space = case
        .launcher
        .as_ref()
        .and_then(|l| l.rattle_space().ok())
        .unwrap_or(f64::NAN);
    let (report, _) = crate::models::case::run_case_from(&case, configs_dir, control, resume)?;
    let rail_wear_rate_mg_per_h = report
        .bodies
        .iter()
        .find(|b| b.name == "rail")
        .map(|b| b.mass_rate_mg_per_h)
        .ok_or_else(|| invalid("config", "the launcher model has no body named `rail`"))?;
    Ok(SweepPoint {
        offset_mm,
        rattle_space,
        rail_wear_rate_mg_per_h,
    })
}

/// Params of the child job that runs point `index`, replica `replica` of the sweep with
/// `params`: the sweep's params (which carry its seed) plus `"point"` and `"replica"`.
pub fn sweep_point_params(
    params: &serde_json::Value,
    index: usize,
    replica: usize,
) -> serde_json::Value {
    let mut p = params.clone();
    merge_json(
        &mut p,
        &serde_json::json!({ "point": index, "replica": replica }),
    );
    p
}

/// The replica index of a `sweep_point` child job's params (0 when absent: children of
/// sweeps from before seeds were replicated).
pub fn sweep_replica_index(params: &serde_json::Value) -> Result<usize, RunError> {
    match params.get("replica") {
        None => Ok(0),
        Some(v) => v
            .as_u64()
            .map(|i| i as usize)
            .ok_or_else(|| invalid("replica", "must be a non-negative integer")),
    }
}

/// The point index of a `sweep_point` child job's params.
pub fn sweep_point_index(params: &serde_json::Value) -> Result<usize, RunError> {
    params
        .get("point")
        .and_then(serde_json::Value::as_u64)
        .map(|i| i as usize)
        .ok_or_else(|| invalid("point", "is required (a non-negative integer)"))
}

/// A sweep job run in one process: the launcher case of `params` (default `launcher-design`) at
/// `points` (default 5, at least 2) dimension sets from tight to loose ([`SweepRange`]), each
/// with `seeds` seeds (default 3), one after the other; returns the rail wear rate versus rattle space for the penalization curve (eq. 6.4).
/// The service fans the same points out to child jobs instead (see ARCHITECTURE.md).
pub fn sweep_job(
    params: &serde_json::Value,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<(serde_json::Value, SweepOutcome), RunError> {
    let plan = SweepPlan::from_params(params, configs_dir)?;
    run_sweep(&plan, configs_dir, control)
}

/// Runs every point of a planned sweep in this process, tight to loose (see [`sweep_job`]).
pub fn run_sweep(
    plan: &SweepPlan,
    configs_dir: &Path,
    control: &RunControl,
) -> Result<(serde_json::Value, SweepOutcome), RunError> {
    let total = plan.runs() as f64;
    let mut runs = Vec::with_capacity(plan.runs());
    for i in 0..plan.len() {
        for j in 0..plan.seeds.len() {
            if control.is_cancelled() {
                return Err(RunError::Cancelled);
            }
            let done = plan.run_index(i, j) as f64;
            let outer = control.progress.clone();
            // A sequential sweep keeps no checkpoint: a request stops it as cancelled.
            let sub = RunControl::new(
                control.cancel.clone(),
                Arc::new(move |pr: Progress| {
                    outer(Progress {
                        simulated_time_s: pr.simulated_time_s,
                        end_time_s: pr.end_time_s,
                        fraction: (done + pr.fraction) / total,
                    })
                }),
            );
            runs.push(sweep_point(plan, i, j, configs_dir, &sub)?);
        }
    }
    let outcome = plan.outcome(runs)?;
    let summary = serde_json::to_value(&outcome).map_err(|e| invalid("sweep", e.to_string()))?;
    Ok((summary, outcome))
}

/// Friction data of a calibrate job (thesis 4.3): the fixture and its torque records.
#[derive(Debug, Clone)]
pub struct FrictionData {
    pub fixture: crate::analysis::calibration::Fixture,
    pub records: Vec<crate::analysis::calibration::TorqueRecord>,
}

/// Wear-law data of a calibrate job (thesis 4.4): material density, cutoff and wear tests.
#[derive(Debug, Clone)]
pub struct WearLawData {
    /// kg/m³ (default 2810, 7075-T73), within [`limits::DENSITY_KG_M3_RANGE`].
    pub density_kg_m3: f64,
    /// Pa (default 870e6, 2 S_y of 7075-T73), in (0, [`limits::MAX_CUTOFF_PRESSURE_PA`]].
    pub cutoff_pressure_pa: f64,
    pub records: Vec<crate::analysis::calibration::WearTestRecord>,
}

/// A calibrate job's params, parsed and checked ([`CALIBRATE_KEYS`]).
#[derive(Debug, Clone)]
pub struct CalibrateParams {
    pub friction: Option<FrictionData>,
    pub wear_law: Option<WearLawData>,
}

/// Typed records at `field` (an array of objects with exactly `keys`), 1 to
/// [`limits::MAX_CALIBRATION_RECORDS`] of them.
fn parse_records<T: serde::de::DeserializeOwned>(
    value: Option<&serde_json::Value>,
    field: &str,
    keys: &[&str],
) -> Result<Vec<T>, RunError> {
    let items = value
        .ok_or_else(|| invalid(field, "is required (an array of records)"))?
        .as_array()
        .ok_or_else(|| invalid(field, "must be an array of records"))?;
    if items.is_empty() || items.len() > limits::MAX_CALIBRATION_RECORDS {
        return Err(invalid(
            field,
            format!(
                "must hold 1 to {} records, got {}",
                limits::MAX_CALIBRATION_RECORDS,
                items.len()
            ),
        ));
    }
    items
        .iter()
        .enumerate()
        .map(|(i, item)| {
            let at = format!("{field}[{i}]");
            check_keys(item, &at, keys)?;
            serde_json::from_value(item.clone()).map_err(|e| invalid(&at, e.to_string()))
        })
        .collect()
}

/// A number at `field` in `[lo, hi]`, or `default` when absent.
fn bounded_number(
    map: &serde_json::Map<String, serde_json::Value>,
    name: &str,
    field: &str,
    default: f64,
    (lo, hi): (f64, f64),
    why: &str,
) -> Result<f64, RunError> {
    match map.get(name) {
        None => Ok(default),
        Some(v) => v
            .as_f64()
            .filter(|x| *x >= lo && *x <= hi)
            .ok_or_else(|| invalid(field, format!("must be a number in [{lo}, {hi}] ({why})"))),
    }
}

impl CalibrateParams {
    /// `{"friction": {"fixture": {...}, "records": [...]}}` and/or `{"wear_law":
    /// {"density_kg_m3": .., "cutoff_pressure_pa": .., "records": [...]}}`; unknown keys at
    /// any level are refused, numbers bounded ([`limits`]), friction records checked as the
    /// fit reads them (eq. 4.1-4.4) and at least 8 of them (the fit's minimum).
    pub fn parse(params: &serde_json::Value) -> Result<Self, RunError> {
        use crate::analysis::calibration as cal;
        let map = check_keys(params, "params", CALIBRATE_KEYS)?;
        if let Some(seed) = map.get("seed") {
            parse_seed(seed)?;
        }
        let friction = match map.get("friction") {
            None => None,
            Some(f) => {
                let f = check_keys(f, "friction", &["fixture", "records"])?;
                let fixture_value = f
                    .get("fixture")
                    .ok_or_else(|| invalid("friction.fixture", "is required"))?;
                check_keys(
                    fixture_value,
                    "friction.fixture",
                    &["polar_inertia_kg_m2", "mean_radius_m"],
                )?;
                let fixture: cal::Fixture = serde_json::from_value(fixture_value.clone())
                    .map_err(|e| invalid("friction.fixture", e.to_string()))?;
                let records: Vec<cal::TorqueRecord> = parse_records(
                    f.get("records"),
                    "friction.records",
                    &[
                        "time_s",
                        "angle_rad",
                        "angular_velocity_rad_s",
                        "normal_load_n",
                        "input_torque_n_m",
                    ],
                )?;
                if records.len() < 8 {
                    return Err(invalid(
                        "friction.records",
                        "need at least 8 records (the friction fit's minimum)",
                    ));
                }
                cal::friction_samples(&records, &fixture)
                    .map_err(|e| invalid("friction.records", e.to_string()))?;
                Some(FrictionData { fixture, records })
            }
        };
        let wear_law = match map.get("wear_law") {
            None => None,
            Some(w) => {
                let w = check_keys(
                    w,
                    "wear_law",
                    &["density_kg_m3", "cutoff_pressure_pa", "records"],
                )?;
                let density_kg_m3 = bounded_number(
                    w,
                    "density_kg_m3",
                    "wear_law.density_kg_m3",
                    crate::wear::material::Material::aluminium_7075_t73().density_kg_m3,
                    limits::DENSITY_KG_M3_RANGE,
                    "kg/m³, polymers to the densest metals",
                )?;
                let cutoff_pressure_pa = bounded_number(
                    w,
                    "cutoff_pressure_pa",
                    "wear_law.cutoff_pressure_pa",
                    2.0 * crate::wear::material::Material::aluminium_7075_t73().yield_strength_pa,
                    (1.0, limits::MAX_CUTOFF_PRESSURE_PA),
                    "Pa, up to 10 GPa, above any engineering alloy's hardness",
                )?;
                let records = parse_records(
                    w.get("records"),
                    "wear_law.records",
                    &[
                        "normal_load_n",
                        "contact_pressure_pa",
                        "sliding_distance_m",
                        "wear_mass_kg",
                    ],
                )?;
                Some(WearLawData {
                    density_kg_m3,
                    cutoff_pressure_pa,
                    records,
                })
            }
        };
        if friction.is_none() && wear_law.is_none() {
            return Err(invalid(
                "params",
                "give `friction` and/or `wear_law` calibration data",
            ));
        }
        Ok(Self { friction, wear_law })
    }
}

/// A calibrate job (thesis 4.3-4.4): [`CalibrateParams::parse`], then [`run_calibration`].
pub fn calibrate(params: &serde_json::Value) -> Result<serde_json::Value, RunError> {
    run_calibration(&CalibrateParams::parse(params)?)
}

/// Fits eq. 4.5 to torque records (eq. 4.1-4.4) and/or K(sigma) to wear tests (eq.
/// 4.16-4.18).
pub fn run_calibration(params: &CalibrateParams) -> Result<serde_json::Value, RunError> {
    use crate::analysis::calibration as cal;
    let mut out = serde_json::Map::new();
    if let Some(f) = &params.friction {
        let samples = cal::friction_samples(&f.records, &f.fixture)
            .map_err(|e| invalid("friction.records", e.to_string()))?;
        let fit = cal::fit_friction(&samples, crate::physics::step::StepKind::Cycloidal)
            .map_err(|e| invalid("friction", e.to_string()))?;
        out.insert(
            "friction".into(),
            serde_json::to_value(fit).map_err(|e| invalid("friction", e.to_string()))?,
        );
    }
    if let Some(w) = &params.wear_law {
        let fit = cal::fit_wear_law(&w.records, w.density_kg_m3, w.cutoff_pressure_pa)
            .map_err(|e| invalid("wear_law", e.to_string()))?;
        out.insert(
            "wear_law".into(),
            serde_json::to_value(fit).map_err(|e| invalid("wear_law", e.to_string()))?,
        );
    }
    Ok(serde_json::Value::Object(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn configs() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
    }

    #[test]
    fn a_point_child_plans_the_same_sweep_as_its_parent() {
        let parent = serde_json::json!({"points": 4, "seed": 9, "vehicle_profile": "ah64"});
        let child = sweep_point_params(&parent, 3, 1);
        assert_eq!(sweep_point_index(&child).unwrap(), 3);
        let a = SweepPlan::from_params(&parent, &configs()).unwrap();
        let b = SweepPlan::from_params(&child, &configs()).unwrap();
        assert_eq!(a.offsets_mm, b.offsets_mm);
        assert_eq!(a.base.simulation.seed, 9);
        assert_eq!(b.base.simulation.seed, 9);
        assert_eq!(a.design_rattle_space, b.design_rattle_space);
        // Tight to loose, ends at the named material conditions.
        use crate::analysis::rattle_space::{
            LOOSE_MATERIAL_CONDITION_MM, TIGHT_MATERIAL_CONDITION_MM,
        };
        assert_eq!(a.offsets_mm.first(), Some(&TIGHT_MATERIAL_CONDITION_MM));
        assert_eq!(a.offsets_mm.last(), Some(&LOOSE_MATERIAL_CONDITION_MM));
        assert!(matches!(
            sweep_point_index(&parent),
            Err(RunError::InvalidConfig { field, .. }) if field == "point"
        ));
        assert!(matches!(
            sweep_point(&a, 4, 0, &configs(), &RunControl::silent()),
            Err(RunError::InvalidConfig { field, .. }) if field == "point"
        ));
    }

    fn field_of(e: RunError) -> String {
        match e {
            RunError::InvalidConfig { field, .. } => field,
            other => panic!("{other}"),
        }
    }

    #[test]
    fn a_sweep_takes_its_rattle_space_range_points_and_seeds() {
        use serde_json::json;
        // Default: the thesis' band, 5 points, 3 seeds.
        let r = SweepRange::from_params(&json!({})).unwrap();
        assert_eq!(r.offsets_mm, sweep_offsets_mm(5));
        assert_eq!(r.seeds, DEFAULT_SWEEP_SEEDS as usize);
        let (lo, hi) = r.rattle_space_bounds();
        assert!((lo - 0.7684).abs() < 1e-4 && (hi - 0.8317).abs() < 1e-4);
        // A rattle-space range: evenly spaced k_rs, tight to loose, ends exact.
        let r = SweepRange::from_params(
            &json!({"rattle_space_range": {"min": 0.64, "max": 0.82}, "points": 7, "seeds": 1}),
        )
        .unwrap();
        assert_eq!(r.rattle_spaces.len(), 7);
        assert!((r.rattle_spaces[0] - 0.82).abs() < 1e-9);
        assert!((r.rattle_spaces[6] - 0.64).abs() < 1e-9);
        assert!((r.rattle_spaces[3] - 0.73).abs() < 1e-9);
        assert!(r.offsets_mm.windows(2).all(|w| w[0] < w[1]));
        // An offset range.
        let r = SweepRange::from_params(&json!({"offset_mm_range": {"min": -0.25, "max": 1.0}}))
            .unwrap();
        assert_eq!(r.offsets_mm.first(), Some(&-0.25));
        assert_eq!(r.offsets_mm.last(), Some(&1.0));
        // Bounds, each naming the field.
        let bad = |p: serde_json::Value| field_of(SweepRange::from_params(&p).unwrap_err());
        // Beyond zero vertical clearance (offset -0.30 mm, k_rs 0.848) no rail assembles.
        assert_eq!(
            bad(json!({"rattle_space_range": {"min": 0.78, "max": 0.86}})),
            "rattle_space_range"
        );
        assert_eq!(
            bad(json!({"offset_mm_range": {"min": -0.35, "max": 0.1}})),
            "offset_mm_range"
        );
        // The design point must be inside (K_SL is relative to it).
        assert_eq!(
            bad(json!({"rattle_space_range": {"min": 0.60, "max": 0.70}})),
            "rattle_space_range"
        );
        assert_eq!(
            bad(json!({"rattle_space_range": {"min": 0.8, "max": 0.7}})),
            "rattle_space_range"
        );
        assert_eq!(
            bad(json!({"rattle_space_range": {"min": 0.7}})),
            "rattle_space_range.max"
        );
        assert_eq!(
            bad(json!({"rattle_space_range": {"min": 0.7, "max": 0.8, "mid": 1}})),
            "rattle_space_range.mid"
        );
        assert_eq!(
            bad(json!({"rattle_space_range": {"min": 0.7, "max": 0.8},
                       "offset_mm_range": {"min": 0, "max": 1}})),
            "offset_mm_range"
        );
        assert_eq!(bad(json!({"seeds": 0})), "seeds");
        assert_eq!(bad(json!({"seeds": 11})), "seeds");
        assert_eq!(bad(json!({"points": 50, "seeds": 5})), "seeds");
        assert_eq!(
            bad(json!({"base_dimensions_mm": {"a_shoe_mm": 38.1}})),
            "base_dimensions_mm"
        );
        let mut dims = serde_json::to_value(LauncherDimensions::design()).unwrap();
        dims["a_shoe_mm"] = json!(9.0);
        assert!(bad(json!({"base_dimensions_mm": dims})).starts_with("base_dimensions_mm."));
    }

    #[test]
    fn the_suggested_sweep_covers_the_rail() {
        use serde_json::json;
        let template = json!({"config": "launcher-design", "points": 5, "seed": 3});
        // Looser than the thesis' band: the design family reaches it.
        let loose = LauncherDimensions::design().with_material_condition(1.075);
        let k = loose.rattle_space().unwrap();
        let p = covering_sweep_params(&template, k, Some(&loose)).unwrap();
        assert!(p.get("base_dimensions_mm").is_none(), "{p}");
        assert!(p.get("seed").is_none());
        let r = SweepRange::from_params(&p).unwrap();
        let (lo, hi) = r.rattle_space_bounds();
        assert!(lo <= k && k <= hi && hi >= design_rattle_space(), "{p}");
        // No coarser than the thesis' band in 5 points.
        assert!(r.offsets_mm.len() as f64 >= (hi - lo) / ((0.8317 - 0.7684) / 4.0));
        // Tighter than the design family reaches: around the rail's own dimensions.
        let mut tight = LauncherDimensions::design().with_material_condition(-0.28);
        tight.f_shoe_mm -= 1.0;
        tight.h_shoe_mm -= 1.0;
        tight.j_shoe_mm -= 1.0;
        tight.l_shoe_mm -= 1.0;
        let k = tight.rattle_space().unwrap();
        assert!(k > 0.86);
        assert!(covering_sweep_params(&template, k, None).is_none());
        let p = covering_sweep_params(&template, k, Some(&tight)).unwrap();
        assert!(p["base_dimensions_mm"].is_object());
        let (lo, hi) = SweepRange::from_params(&p).unwrap().rattle_space_bounds();
        assert!(lo <= design_rattle_space() && k <= hi, "{p}");
    }

    #[test]
    fn replicas_run_their_own_seeds_below_2_pow_53() {
        assert_eq!(replica_seed(7, 0), 7);
        assert_eq!(replica_seed(7, 2), 9);
        assert_eq!(replica_seed(limits::MAX_SEED, 1), 0);
        let plan = SweepPlan::from_params(&serde_json::json!({"points": 2, "seed": 5}), &configs())
            .unwrap();
        assert_eq!(plan.seeds, vec![5, 6, 7]);
        assert_eq!(plan.runs(), 6);
        assert_eq!(plan.run_index(1, 2), 5);
    }
}
