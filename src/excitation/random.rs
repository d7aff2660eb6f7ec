//! Random-phase inverse-FFT synthesis of a broadband acceleration PSD (the random background of
//! MIL-STD-810G Method 514.6 sine-on-random profiles).
//!
//! For a record of `n` samples at rate `fs` (period `T = n / fs`, line spacing `df = 1/T`), line
//! `k` at `f_k = k df` gets the deterministic amplitude `A_k = sqrt(2 G(f_k) df)` and a phase
//! drawn uniformly in [0, 2 pi) from ChaCha20 seeded with `seed`. So the record's mean square is
//! exactly `sum_k G(f_k) df` (the Riemann sum of the PSD) and its periodogram at resolution `df`
//! is the target itself; only the phases are random. Velocity and displacement are integrated
//! in the frequency domain (divide by `i w` and `-w²`), with DC and lines below `low_cutoff_hz`
//! zeroed, so the record is exactly periodic: no drift, no offset.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha20Rng;
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

use super::{
    require_positive, Axis, ExcitationError, MotionSample, SampledRecord, MAX_RECORD_SAMPLES,
};
use crate::field_error::FieldError;
use crate::units::STANDARD_GRAVITY;

/// Validates PSD breakpoints `(Hz, g²/Hz)`: at least two, frequencies finite, > 0 and strictly
/// increasing, levels finite and > 0 (log-log interpolation needs positive values).
pub(crate) fn validate_breakpoints(breakpoints: &[(f64, f64)]) -> Result<(), ExcitationError> {
    if breakpoints.len() < 2 {
        return Err(FieldError::new(
            "psd_breakpoints",
            "needs at least two (frequency_hz, g2_per_hz) pairs",
        )
        .into());
    }
    for (i, &(f, g)) in breakpoints.iter().enumerate() {
        require_positive(&format!("psd_breakpoints[{i}].frequency_hz"), f)?;
        require_positive(&format!("psd_breakpoints[{i}].g2_per_hz"), g)?;
        if i > 0 && f <= breakpoints[i - 1].0 {
            return Err(FieldError::new(
                format!("psd_breakpoints[{i}].frequency_hz"),
                "frequencies must be strictly increasing",
            )
            .into());
        }
    }
    Ok(())
}

/// One-sided PSD at `frequency_hz`, g²/Hz: log-log interpolation between breakpoints, zero
/// outside the first..last breakpoint. Breakpoints must satisfy the rules of the
/// `psd_breakpoints` field (checked when a spec is built); fewer than two gives zero.
pub fn psd_at(breakpoints: &[(f64, f64)], frequency_hz: f64) -> f64 {
    if breakpoints.len() < 2 {
        return 0.0;
    }
    let first = breakpoints[0].0;
    let last = breakpoints[breakpoints.len() - 1].0;
    if !(frequency_hz >= first && frequency_hz <= last) {
        return 0.0;
    }
    for pair in breakpoints.windows(2) {
        let ((f1, g1), (f2, g2)) = (pair[0], pair[1]);
        if frequency_hz <= f2 {
            let slope = (g2 / g1).ln() / (f2 / f1).ln();
            return g1 * (frequency_hz / f1).powf(slope);
        }
    }
    breakpoints[breakpoints.len() - 1].1
}

/// Mean square of the PSD between `f_lo_hz` and `f_hi_hz`, g², by the closed-form integral of
/// each log-log segment `G1 (f/f1)^b` (the usual "g rms squared" of a vibration profile).
pub fn psd_mean_square(breakpoints: &[(f64, f64)], f_lo_hz: f64, f_hi_hz: f64) -> f64 {
    let mut total = 0.0;
    for pair in breakpoints.windows(2) {
        let ((f1, g1), (f2, g2)) = (pair[0], pair[1]);
        let a = f1.max(f_lo_hz);
        let b = f2.min(f_hi_hz);
        if b <= a {
            continue;
        }
        let slope = (g2 / g1).ln() / (f2 / f1).ln();
        total += if (slope + 1.0).abs() < 1e-12 {
            g1 * f1 * (b / a).ln()
        } else {
            g1 * f1 / (slope + 1.0) * ((b / f1).powf(slope + 1.0) - (a / f1).powf(slope + 1.0))
        };
    }
    total
}

/// Synthesises the random background on `axes` (independent phases per axis, drawn in the
/// order the axes are listed) as a periodic record of `round(duration_s * sample_rate_hz)`
/// samples. Errors name the field and rule broken.
pub fn synthesize_random(
    axes: &[Axis],
    psd_breakpoints: &[(f64, f64)],
    duration_s: f64,
    sample_rate_hz: f64,
    seed: u64,
    low_cutoff_hz: f64,
) -> Result<SampledRecord, ExcitationError> {
    if axes.is_empty() {
        return Err(FieldError::new("axes", "must name at least one axis (x, y or z)").into());
    }
    for (i, axis) in axes.iter().enumerate() {
        if axes[..i].contains(axis) {
            return Err(
                FieldError::new(format!("axes[{i}]"), "each axis may appear only once").into(),
            );
        }
    }
    validate_breakpoints(psd_breakpoints)?;
    require_positive("duration_s", duration_s)?;
    require_positive("sample_rate_hz", sample_rate_hz)?;
    require_positive("low_cutoff_hz", low_cutoff_hz)?;
    let f_max = psd_breakpoints[psd_breakpoints.len() - 1].0;
    if f_max >= 0.5 * sample_rate_hz {
        return Err(FieldError::new(
            "sample_rate_hz",
            format!(
                "Nyquist frequency {} Hz must exceed the last PSD breakpoint {f_max} Hz",
                0.5 * sample_rate_hz
            ),
        )
        .into());
    }
    if low_cutoff_hz >= f_max {
        return Err(FieldError::new(
            "low_cutoff_hz",
            format!("must be below the last PSD breakpoint {f_max} Hz"),
        )
        .into());
    }
    let n_f = (duration_s * sample_rate_hz).round();
    if !(16.0..=MAX_RECORD_SAMPLES as f64).contains(&n_f) {
        return Err(FieldError::new(
            "duration_s",
            format!(
                "duration_s * sample_rate_hz = {n_f} samples; must be between 16 and {MAX_RECORD_SAMPLES}"
            ),
        ).into());
    }
    let n = n_f as usize;
    let df = sample_rate_hz / n as f64;
    // Highest line strictly below Nyquist.
    let k_max = (n - 1) / 2;

    let mut rng = ChaCha20Rng::seed_from_u64(seed);
    let mut planner = FftPlanner::<f64>::new();
    let ifft = planner.plan_fft_inverse(n);
    let mut samples = vec![MotionSample::default(); n];
    let mut acc = vec![Complex::new(0.0, 0.0); n];
    let mut vel = vec![Complex::new(0.0, 0.0); n];
    let mut dis = vec![Complex::new(0.0, 0.0); n];

    for axis in axes {
        acc.fill(Complex::new(0.0, 0.0));
        vel.fill(Complex::new(0.0, 0.0));
        dis.fill(Complex::new(0.0, 0.0));
        for k in 1..=k_max {
            // Draw for every line so the phase of line k does not depend on the cutoff.
            let phase = rng.gen::<f64>() * std::f64::consts::TAU;
            let f = k as f64 * df;
            if f < low_cutoff_hz {
                continue;
            }
            let g_si = psd_at(psd_breakpoints, f) * STANDARD_GRAVITY * STANDARD_GRAVITY;
            if g_si <= 0.0 {
                continue;
            }
            // x[m] = A cos(w t + phi) = (A/2) e^{i(..)} + c.c.
            let half_amp = 0.5 * (2.0 * g_si * df).sqrt();
            let a_k = Complex::from_polar(half_amp, phase);
            let w = std::f64::consts::TAU * f;
            let v_k = a_k / Complex::new(0.0, w);
            let x_k = -a_k / (w * w);
            acc[k] = a_k;
            acc[n - k] = a_k.conj();
            vel[k] = v_k;
            vel[n - k] = v_k.conj();
            dis[k] = x_k;
            dis[n - k] = x_k.conj();
        }
        ifft.process(&mut acc);
        ifft.process(&mut vel);
        ifft.process(&mut dis);
        let c = axis.index();
        for (m, s) in samples.iter_mut().enumerate() {
            s.acceleration_m_s2[c] = acc[m].re;
            s.velocity_m_s[c] = vel[m].re;
            s.displacement_m[c] = dis[m].re;
        }
    }
    SampledRecord::new(1.0 / sample_rate_hz, samples)
        .ok_or_else(|| FieldError::new("sample_rate_hz", "must be finite and > 0").into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_log_interpolation_closed_form() {
        // 3 dB/octave rise from 0.001 at 10 Hz: G doubles per octave, so G(40) = 0.004.
        let bp = [(10.0, 0.001), (40.0, 0.004), (100.0, 0.004)];
        assert!((psd_at(&bp, 20.0) - 0.002).abs() < 1e-12);
        assert!((psd_at(&bp, 70.0) - 0.004).abs() < 1e-12);
        assert_eq!(psd_at(&bp, 5.0), 0.0);
        assert_eq!(psd_at(&bp, 101.0), 0.0);
        // integral: slope 1 segment G = 1e-4 f -> 1e-4 (40²-10²)/2 = 0.075; flat 0.004*60 = 0.24
        let ms = psd_mean_square(&bp, 0.0, 1e9);
        assert!((ms - (0.075 + 0.24)).abs() < 1e-12);
        // slope -1 segment: G = 0.01/f on [1, 10] -> 0.01 ln 10
        let inv = [(1.0, 0.01), (10.0, 0.001)];
        assert!((psd_mean_square(&inv, 0.0, 1e9) - 0.01 * 10f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn bad_breakpoints_name_the_pair() {
        let err = synthesize_random(
            &[Axis::X],
            &[(10.0, 0.01), (10.0, 0.02)],
            1.0,
            1024.0,
            1,
            1.0,
        )
        .unwrap_err();
        assert!(err.to_string().contains("psd_breakpoints[1].frequency_hz"));
        let err = synthesize_random(
            &[Axis::X],
            &[(10.0, 0.01), (600.0, 0.02)],
            1.0,
            1024.0,
            1,
            1.0,
        )
        .unwrap_err();
        assert!(err.to_string().contains("sample_rate_hz"));
    }
}
