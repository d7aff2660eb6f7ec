//! Bounds on job parameters and a case's run control, each with its physical or operational
//! reason (the ranges of single case fields are declared beside the fields, in `models::spec`;
//! those that job options share are re-exported here). They are checked by the one case parser
//! ([`super::resolve_config`]) and by the job parsers of `pipeline`, which both the submission
//! (422 before anything is stored) and the worker call, and by the diagnosis' and the virtual
//! rig's options: one set of rules.

use crate::field_error::FieldError;

pub use crate::models::spec::{
    ABS_TOLERANCE_M_RANGE, DENSITY_KG_M3_RANGE, MAX_CUTOFF_PRESSURE_PA, MAX_DURATION_S, MAX_SEED,
    MAX_SETTLE_S, MIN_RECORD_INTERVAL_S, REL_TOLERANCE_RANGE,
};

/// Most recorded time points of one run (`(settle_s + duration_s) / record_interval_s`):
/// tracks are held in memory until stored, about 150 bytes a sample and contact.
pub const MAX_RECORDED_POINTS: f64 = 1.0e7;
/// Points of a tolerance sweep: at least 2 (a curve needs two ends), at most 50 (each
/// point is a full launcher simulation).
pub const SWEEP_POINTS: std::ops::RangeInclusive<u64> = 2..=50;
/// Seeds (independent excitation draws) per sweep point: 1 to 10. One seed gives no
/// confidence interval; 3 (the default, [`crate::pipeline::DEFAULT_SWEEP_SEEDS`]) is the fewest whose
/// t-interval is not dominated by the t quantile (df 1 needs 6.31 standard errors, df 2
/// 2.92); beyond 10 the interval narrows by less than 5 % a seed.
pub const SWEEP_SEEDS: std::ops::RangeInclusive<u64> = 1..=10;
/// Most simulations of one sweep (`points * seeds`): each is a full launcher run and one
/// child job; 200 keeps a sweep's fan-out and its assembly in one short transaction.
pub const MAX_SWEEP_RUNS: u64 = 200;
/// Most records of one calibration data set (a request body holds them anyway).
pub const MAX_CALIBRATION_RECORDS: usize = 100_000;
/// Simulated excitation per increment of a diagnosis (and of the virtual rig), s: at least
/// one period of the thesis' slowest drive (20 Hz), at most ten minutes
/// ([`MAX_SETTLE_S`]'s reason: past that a window is a typing error, not a test).
pub const WINDOW_S_RANGE: (f64, f64) = (0.05, 600.0);
/// Grid points per effect parameter of a diagnosis' emulator: two ends at least; each point
/// costs one simulation per test, and 12 caps that cost.
pub const GRID_POINTS: std::ops::RangeInclusive<usize> = 2..=12;

/// `window_s` within [`WINDOW_S_RANGE`].
pub fn check_window_s(window_s: f64) -> Result<(), FieldError> {
    let (lo, hi) = WINDOW_S_RANGE;
    if window_s.is_finite() && (lo..=hi).contains(&window_s) {
        Ok(())
    } else {
        Err(FieldError::new(
            "window_s",
            format!("must lie in [{lo}, {hi}] s"),
        ))
    }
}

/// `settle_s` within [0, [`MAX_SETTLE_S`]].
pub fn check_settle_s(settle_s: f64) -> Result<(), FieldError> {
    if settle_s.is_finite() && (0.0..=MAX_SETTLE_S).contains(&settle_s) {
        Ok(())
    } else {
        Err(FieldError::new(
            "settle_s",
            format!("must lie in [0, {}] s", MAX_SETTLE_S),
        ))
    }
}

/// `grid_points` within [`GRID_POINTS`].
pub fn check_grid_points(grid_points: usize) -> Result<(), FieldError> {
    if GRID_POINTS.contains(&grid_points) {
        Ok(())
    } else {
        Err(FieldError::new(
            "grid_points",
            format!("must lie in {}", grid_points_range()),
        ))
    }
}

/// [`GRID_POINTS`] as a rule shows it: `2..=12`.
pub fn grid_points_range() -> String {
    format!("{}..={}", GRID_POINTS.start(), GRID_POINTS.end())
}
