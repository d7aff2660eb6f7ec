//! Bounds on job parameters and a case's run control, each with its physical or operational
//! reason. They are checked by the one case parser ([`super::resolve_config`]) and by the job
//! parsers of `pipeline`, which both the submission (422 before anything is stored) and the
//! worker call, and by the diagnosis' and the virtual rig's options: one set of rules.

use crate::field_error::FieldError;

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
/// confidence interval; 3 (the default, [`crate::pipeline::DEFAULT_SWEEP_SEEDS`]) is the fewest whose
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
