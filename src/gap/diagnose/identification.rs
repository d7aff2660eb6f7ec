//! Whether the data identify a fitted parameter (docs/results/diagnosis.md, "Identified or said not to
//! be"): a 95 % interval that spans (nearly) the parameter's whole physical range says the
//! data do not measure it, and the report then gives no point value as a measurement; an
//! interval that reaches a physical bound says the fit would go beyond what the library
//! allows.

use crate::gap::effects::ParameterInfo;

/// Share of a parameter's physical range its 95 % interval must span for the parameter to be
/// reported not identified: at 0.9 the data leave less than a tenth of the range out, so
/// whatever value the fit prints is the search's choice, not the data's.
pub const UNIDENTIFIED_SHARE: f64 = 0.9;

/// Whether a parameter is tabulated on a log scale: positive bounds more than a factor 20
/// apart (the scale the profile's values are spread on, `super::secondary_values`).
pub fn log_scale(p: &ParameterInfo) -> bool {
    p.min > 0.0 && p.max / p.min > 20.0
}

/// Share of `p`'s physical range `[lo, hi]` spans, on the parameter's scale (log for a
/// log-scale parameter), clipped to the bounds.
pub fn range_share(p: &ParameterInfo, [lo, hi]: [f64; 2]) -> f64 {
    let (lo, hi) = (lo.max(p.min), hi.min(p.max));
    if hi <= lo || p.max <= p.min {
        return 0.0;
    }
    if log_scale(p) {
        (hi / lo).ln() / (p.max / p.min).ln()
    } else {
        (hi - lo) / (p.max - p.min)
    }
}

/// Identified by the data: the 95 % interval spans less than [`UNIDENTIFIED_SHARE`] of the
/// physical range.
pub fn identified(p: &ParameterInfo, interval: [f64; 2]) -> bool {
    range_share(p, interval) < UNIDENTIFIED_SHARE
}

/// The physical bounds the 95 % interval reaches (`"min"`, `"max"`), within a millionth of
/// the range: the data would take the parameter there or beyond.
pub fn bounds_reached(p: &ParameterInfo, [lo, hi]: [f64; 2]) -> Vec<&'static str> {
    let tol = 1e-6 * (p.max - p.min).abs();
    let mut out = Vec::new();
    if lo <= p.min + tol {
        out.push("min");
    }
    if hi >= p.max - tol {
        out.push("max");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parameter(min: f64, max: f64) -> ParameterInfo {
        ParameterInfo {
            name: "p",
            unit: "-",
            min,
            max,
            default: min,
            reason: "test",
        }
    }

    #[test]
    fn a_phase_interval_over_the_whole_circle_is_not_identified() {
        let phase = parameter(-180.0, 180.0);
        assert!(!identified(&phase, [-180.0, 180.0]));
        assert_eq!(range_share(&phase, [-180.0, 180.0]), 1.0);
        // Two grid steps of 60° either side of 120° (the interval reaches the bound).
        assert!(identified(&phase, [0.0, 180.0]));
        assert_eq!(bounds_reached(&phase, [0.0, 180.0]), vec!["max"]);
        // 330° of 360° is more than nine tenths.
        assert!(!identified(&phase, [-150.0, 180.0]));
    }

    #[test]
    fn a_log_scale_parameter_is_measured_in_decades() {
        // 100 m to 10 km: two decades. 1 to 10 km is half of them.
        let slip_scale = parameter(100.0, 1e4);
        assert!(log_scale(&slip_scale));
        assert!((range_share(&slip_scale, [1e3, 1e4]) - 0.5).abs() < 1e-12);
        assert!(identified(&slip_scale, [1e3, 1e4]));
        assert!(!identified(&slip_scale, [120.0, 1e4]));
        // A magnitude from 0 is linear: [0.204, 0.3] of [0, 0.3] is 32 % and reaches the top.
        let share = parameter(0.0, 0.3);
        assert!(!log_scale(&share));
        assert!((range_share(&share, [0.204, 0.3]) - 0.32).abs() < 1e-12);
        assert_eq!(bounds_reached(&share, [0.204, 0.3]), vec!["max"]);
        assert!(bounds_reached(&share, [0.1, 0.2]).is_empty());
    }
}
