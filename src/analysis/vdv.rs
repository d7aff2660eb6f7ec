//! Vibration dose value, thesis eq. 2.51: `VDV = ((1/T) ∫_0^T a⁴ dt)^(1/4)`.
//!
//! The thesis used it to rank integrators (Table 2.3): spurious acceleration spikes from an
//! ill-suited integrator raise the fourth-power mean far more than the RMS. Note that eq. 2.51
//! divides by the duration `T`, so the result is in acceleration units (m/s² for a in m/s²);
//! ISO 2631-1's VDV omits the `1/T` and is in m/s^1.75. Only ratios are used in the thesis, so
//! the normalisation does not change its conclusions.

use crate::field_error::FieldError;

/// Errors from the VDV; each names the argument and the rule broken.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VdvError {
    /// An argument breaks a rule.
    #[error("VDV argument `{}`: {}", .0.field, .0.rule)]
    InvalidInput(#[from] FieldError),
}

/// VDV of eq. 2.51 for samples `acceleration[i]` at `time_s[i]` (strictly increasing, any
/// spacing), trapezoid rule on `a⁴`, `T = time_s[last] - time_s[0]`. Result in the unit of
/// `acceleration`.
pub fn vibration_dose_value(time_s: &[f64], acceleration: &[f64]) -> Result<f64, VdvError> {
    if time_s.len() != acceleration.len() {
        return Err(FieldError::new(
            "acceleration",
            format!(
                "length {} differs from time_s length {}",
                acceleration.len(),
                time_s.len()
            ),
        )
        .into());
    }
    if time_s.len() < 2 {
        return Err(FieldError::new("time_s", "needs at least 2 samples").into());
    }
    if let Some(i) = acceleration.iter().position(|a| !a.is_finite()) {
        return Err(FieldError::new("acceleration", format!("sample {i} is not finite")).into());
    }
    let mut integral = 0.0;
    for i in 1..time_s.len() {
        let dt = time_s[i] - time_s[i - 1];
        if !(dt.is_finite() && dt > 0.0) {
            return Err(FieldError::new(
                "time_s",
                format!("must increase strictly; sample {i} does not"),
            )
            .into());
        }
        integral += 0.5 * dt * (acceleration[i].powi(4) + acceleration[i - 1].powi(4));
    }
    let duration = time_s[time_s.len() - 1] - time_s[0];
    Ok((integral / duration).powf(0.25))
}

/// VDV of eq. 2.51 for uniformly sampled acceleration with step `dt_s` (trapezoid rule).
pub fn vibration_dose_value_uniform(acceleration: &[f64], dt_s: f64) -> Result<f64, VdvError> {
    if !(dt_s.is_finite() && dt_s > 0.0) {
        return Err(FieldError::new("dt_s", format!("must be finite and > 0, got {dt_s}")).into());
    }
    if acceleration.len() < 2 {
        return Err(FieldError::new("acceleration", "needs at least 2 samples").into());
    }
    if let Some(i) = acceleration.iter().position(|a| !a.is_finite()) {
        return Err(FieldError::new("acceleration", format!("sample {i} is not finite")).into());
    }
    let n = acceleration.len();
    let interior: f64 = acceleration[1..n - 1].iter().map(|a| a.powi(4)).sum();
    let ends = 0.5 * (acceleration[0].powi(4) + acceleration[n - 1].powi(4));
    let duration = (n - 1) as f64 * dt_s;
    Ok(((interior + ends) * dt_s / duration).powf(0.25))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn sine_vdv_is_amplitude_times_three_eighths_to_the_quarter() {
        // Mean of sin⁴ over whole periods is 3/8; the trapezoid rule is exact for this
        // trigonometric polynomial (harmonics up to 4 w) when there are more than 4 samples
        // per period.
        let amp = 147.1;
        let f = 20.0;
        let per_cycle = 64;
        let dt = 1.0 / (f * per_cycle as f64);
        let n = 5 * per_cycle + 1;
        let a: Vec<f64> = (0..n)
            .map(|i| amp * (TAU * f * i as f64 * dt + 0.3).sin())
            .collect();
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let expected = amp * 0.375f64.powf(0.25);
        assert!((vibration_dose_value(&t, &a).unwrap() - expected).abs() < 1e-10 * amp);
        assert!((vibration_dose_value_uniform(&a, dt).unwrap() - expected).abs() < 1e-10 * amp);
    }

    #[test]
    fn constant_and_bad_input() {
        let t = [0.0, 0.1, 0.3, 0.6];
        assert!((vibration_dose_value(&t, &[-2.0; 4]).unwrap() - 2.0).abs() < 1e-12);
        assert!(vibration_dose_value(&[0.0, 0.0], &[1.0, 1.0])
            .unwrap_err()
            .to_string()
            .contains("time_s"));
        assert!(vibration_dose_value(&t, &[1.0; 3]).is_err());
    }
}
