//! The rate window: where a run's rates (mean powers, mean normal force, wear-mass rates) are
//! taken.
//!
//! The excitation ramps in over its first cycles (three cycles of the lowest frequency by
//! default: 0.62 s at the launcher profile's 4.86 Hz tone, 0.15 s at the rattle boxes' 20 Hz),
//! during which the contacts see less than the steady drive. A rate averaged over the whole
//! excited window mixes that ramp in with a weight `ramp / window`, so a 2 s and a 20 s window
//! of the same case disagree by up to a quarter of the ramp's share. The run's rates are
//! therefore taken from the end of the ramp-in (`BuiltModel::rate_start_s`) to the end of the
//! run; the totals (wear mass, friction work, the wear totals) stay over the whole excited
//! window, which is what the rig and the diagnosis add up per increment.
//!
//! The window's start falls between two accepted steps. Each cumulative quantity (the normal
//! force and `N |v_slip|` integrals, the energy account's friction work, each contact's wear
//! volume) is read at the step before and the step after and interpolated linearly to the
//! start, so the window is exactly `end - rate_start_s` and each quantity's base carries an
//! error of the order of one step's change of its rate (the steps are tens of microseconds;
//! the quantities' rates vary over the drive's period, tens of milliseconds).
//!
//! A run that ends before its ramp-in does (a window shorter than the ramp) takes its rates
//! over the whole excited window and says so (`RateWindow::after_ramp` false).

use serde::{Deserialize, Serialize};

/// Cumulative quantities of a run at one instant, per contact (from the excitation's start).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct Cumulative {
    /// Instant, s.
    pub t_s: f64,
    /// ∫ N dt, N·s.
    pub normal: Vec<f64>,
    /// ∫ N |v_slip| dt, J.
    pub normal_slip: Vec<f64>,
    /// The energy account's friction work since t = 0, J.
    pub friction: Vec<f64>,
    /// Wear volume, m³.
    pub volume: Vec<f64>,
}

impl Cumulative {
    /// The quantities at `t_s` between `self` (earlier) and `later`, linear in time; `later`
    /// itself when the two are at one instant.
    pub fn interpolate_to(&self, later: &Cumulative, t_s: f64) -> Cumulative {
        let span = later.t_s - self.t_s;
        if !(span > 0.0) {
            return later.clone();
        }
        let s = ((t_s - self.t_s) / span).clamp(0.0, 1.0);
        let lerp = |a: &[f64], b: &[f64]| -> Vec<f64> {
            a.iter().zip(b).map(|(a, b)| a + s * (b - a)).collect()
        };
        Cumulative {
            t_s: self.t_s + s * span,
            normal: lerp(&self.normal, &later.normal),
            normal_slip: lerp(&self.normal_slip, &later.normal_slip),
            friction: lerp(&self.friction, &later.friction),
            volume: lerp(&self.volume, &later.volume),
        }
    }
}

/// `now - base`, entry by entry: a cumulative quantity's growth since its base.
pub(super) fn difference(now: &[f64], base: &[f64]) -> Vec<f64> {
    now.iter().zip(base).map(|(n, b)| n - b).collect()
}

/// Where a run's rates were taken.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RateWindow {
    /// Start of the rate window, s of simulated time.
    pub start_s: f64,
    /// Its length, s.
    pub length_s: f64,
    /// True when the window starts at the end of the excitation's ramp-in (or there is no
    /// ramp); false when the run ended before the ramp did and the rates are over the whole
    /// excited window, ramp included.
    pub after_ramp: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(t: f64, x: f64) -> Cumulative {
        Cumulative {
            t_s: t,
            normal: vec![x],
            normal_slip: vec![2.0 * x],
            friction: vec![3.0 * x],
            volume: vec![4.0 * x],
        }
    }

    #[test]
    fn interpolation_is_exact_for_quantities_linear_in_time() {
        // x(t) = 5 t: every quantity is linear, so the base at 0.25 is exact.
        let base = at(0.2, 1.0).interpolate_to(&at(0.3, 1.5), 0.25);
        assert_eq!(base.t_s, 0.25);
        assert!((base.normal[0] - 1.25).abs() < 1e-15);
        assert!((base.normal_slip[0] - 2.5).abs() < 1e-15);
        assert!((base.friction[0] - 3.75).abs() < 1e-15);
        assert!((base.volume[0] - 5.0).abs() < 1e-15);
    }

    #[test]
    fn a_start_outside_the_step_is_clamped_to_it() {
        let later = at(0.3, 1.5);
        assert_eq!(at(0.2, 1.0).interpolate_to(&later, 0.9), later);
        assert_eq!(at(0.3, 1.0).interpolate_to(&later, 0.3), later);
    }
}
