//! Power spectral density (Welch) and amplitude spectrum, for comparing simulated and measured
//! accelerations in the frequency domain (thesis 6.6 figures) and checking synthesised profiles.

use crate::field_error::FieldError;
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

/// Errors from spectral estimation; each names the argument and the rule broken.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpectraError {
    /// An argument breaks a rule.
    #[error("spectrum argument `{}`: {}", .0.field, .0.rule)]
    InvalidInput(#[from] FieldError),
}

/// One-sided power spectral density.
#[derive(Debug, Clone, PartialEq)]
pub struct Psd {
    /// Bin frequencies, Hz, from 0 to the Nyquist frequency.
    pub frequency_hz: Vec<f64>,
    /// Density, (signal unit)² / Hz, one-sided (integral over 0..Nyquist = variance).
    pub density: Vec<f64>,
}

impl Psd {
    /// Bin spacing, Hz.
    pub fn resolution_hz(&self) -> f64 {
        if self.frequency_hz.len() < 2 {
            0.0
        } else {
            self.frequency_hz[1] - self.frequency_hz[0]
        }
    }

    /// Mean square of the signal from the PSD (rectangle rule over all bins), (signal unit)².
    pub fn mean_square(&self) -> f64 {
        self.density.iter().sum::<f64>() * self.resolution_hz()
    }

    /// Mean density over the bins with `f_lo_hz <= f < f_hi_hz`; `None` if no bin falls inside.
    pub fn band_mean(&self, f_lo_hz: f64, f_hi_hz: f64) -> Option<f64> {
        let (sum, count) = self
            .frequency_hz
            .iter()
            .zip(&self.density)
            .filter(|(f, _)| **f >= f_lo_hz && **f < f_hi_hz)
            .fold((0.0, 0usize), |(s, c), (_, d)| (s + d, c + 1));
        (count > 0).then(|| sum / count as f64)
    }
}

/// Single-sided peak-amplitude spectrum.
#[derive(Debug, Clone, PartialEq)]
pub struct AmplitudeSpectrum {
    /// Bin frequencies, Hz, from 0 to the Nyquist frequency.
    pub frequency_hz: Vec<f64>,
    /// Peak amplitude of the sinusoid at each bin, signal unit (DC bin: the mean).
    pub amplitude: Vec<f64>,
}

/// Window applied before an FFT.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Window {
    /// No window: exact amplitude for a tone on a bin, strong leakage otherwise.
    Rectangular,
    /// Periodic Hann window: low leakage, amplitude error up to 15 % (-1.42 dB) between bins.
    Hann,
}

/// The window's `n` weights (Hann: periodic, `0.5 (1 - cos(2π i / n))`).
pub fn window_values(window: Window, n: usize) -> Vec<f64> {
    match window {
        Window::Rectangular => vec![1.0; n],
        Window::Hann => (0..n)
            .map(|i| 0.5 * (1.0 - (std::f64::consts::TAU * i as f64 / n as f64).cos()))
            .collect(),
    }
}

fn check_signal(signal: &[f64], sample_rate_hz: f64) -> Result<(), SpectraError> {
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(FieldError::new(
            "sample_rate_hz",
            format!("must be finite and > 0, got {sample_rate_hz}"),
        )
        .into());
    }
    if let Some(i) = signal.iter().position(|v| !v.is_finite()) {
        return Err(FieldError::new("signal", format!("sample {i} is not finite")).into());
    }
    Ok(())
}

/// Welch PSD: Hann-windowed segments of `segment_len` samples with 50 % overlap, each segment's
/// mean removed, periodograms averaged, one-sided density scaling `2 |X_k|² / (fs sum w²)`
/// (DC and Nyquist bins not doubled). Samples after the last whole segment are ignored.
pub fn welch_psd(
    signal: &[f64],
    sample_rate_hz: f64,
    segment_len: usize,
) -> Result<Psd, SpectraError> {
    check_signal(signal, sample_rate_hz)?;
    if segment_len < 4 {
        return Err(FieldError::new(
            "segment_len",
            format!("must be at least 4, got {segment_len}"),
        )
        .into());
    }
    if segment_len > signal.len() {
        return Err(FieldError::new(
            "segment_len",
            format!("{segment_len} exceeds the signal length {}", signal.len()),
        )
        .into());
    }
    let window = window_values(Window::Hann, segment_len);
    let window_power: f64 = window.iter().map(|w| w * w).sum();
    let step = segment_len / 2;
    let segments = (signal.len() - segment_len) / step + 1;
    let bins = segment_len / 2 + 1;
    let fft = FftPlanner::<f64>::new().plan_fft_forward(segment_len);
    let mut buffer = vec![Complex::new(0.0, 0.0); segment_len];
    let mut density = vec![0.0; bins];
    for s in 0..segments {
        let segment = &signal[s * step..s * step + segment_len];
        let mean = segment.iter().sum::<f64>() / segment_len as f64;
        for ((b, x), w) in buffer.iter_mut().zip(segment).zip(&window) {
            *b = Complex::new((x - mean) * w, 0.0);
        }
        fft.process(&mut buffer);
        for (k, d) in density.iter_mut().enumerate() {
            *d += buffer[k].norm_sqr();
        }
    }
    let scale = 1.0 / (sample_rate_hz * window_power * segments as f64);
    for (k, d) in density.iter_mut().enumerate() {
        let one_sided = if k == 0 || 2 * k == segment_len {
            1.0
        } else {
            2.0
        };
        *d *= scale * one_sided;
    }
    let df = sample_rate_hz / segment_len as f64;
    Ok(Psd {
        frequency_hz: (0..bins).map(|k| k as f64 * df).collect(),
        density,
    })
}

/// Peak-amplitude spectrum of the whole signal with one FFT: `2 |X_k| / sum w` (DC and Nyquist
/// `|X_k| / sum w`). A tone exactly on a bin reads its amplitude exactly with `Rectangular`.
pub fn amplitude_spectrum(
    signal: &[f64],
    sample_rate_hz: f64,
    window: Window,
) -> Result<AmplitudeSpectrum, SpectraError> {
    check_signal(signal, sample_rate_hz)?;
    let n = signal.len();
    if n < 2 {
        return Err(FieldError::new("signal", "needs at least 2 samples").into());
    }
    let w = window_values(window, n);
    let gain: f64 = w.iter().sum();
    let mut buffer: Vec<Complex<f64>> = signal
        .iter()
        .zip(&w)
        .map(|(x, w)| Complex::new(x * w, 0.0))
        .collect();
    FftPlanner::<f64>::new()
        .plan_fft_forward(n)
        .process(&mut buffer);
    let bins = n / 2 + 1;
    let df = sample_rate_hz / n as f64;
    Ok(AmplitudeSpectrum {
        frequency_hz: (0..bins).map(|k| k as f64 * df).collect(),
        amplitude: (0..bins)
            .map(|k| {
                let factor = if k == 0 || 2 * k == n { 1.0 } else { 2.0 };
                factor * buffer[k].norm() / gain
            })
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha20Rng;
    use std::f64::consts::TAU;

    #[test]
    fn parseval_white_noise() {
        // Integral of the Welch PSD equals the variance; 2^18 samples, 1024-sample segments
        // (511 segments) keep the estimator's scatter near 0.3 %, bound 1 %.
        let mut rng = ChaCha20Rng::seed_from_u64(7);
        let signal: Vec<f64> = (0..1 << 18).map(|_| rng.gen::<f64>() - 0.5 + 3.0).collect();
        let mean = signal.iter().sum::<f64>() / signal.len() as f64;
        let var = signal.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / signal.len() as f64;
        let psd = welch_psd(&signal, 1000.0, 1024).unwrap();
        assert!((psd.mean_square() / var - 1.0).abs() < 0.01);
        // White: uniform(-0.5, 0.5) has variance 1/12 spread over 500 Hz.
        let level = psd.band_mean(50.0, 450.0).unwrap();
        assert!((level / (1.0 / 12.0 / 500.0) - 1.0).abs() < 0.02);
    }

    #[test]
    fn parseval_and_amplitude_of_a_tone() {
        // 5 Hz resolution at 1024 Hz / 4096 samples; 123.75 Hz lies between bins.
        let fs = 1024.0;
        let amp = 2.5;
        let tone: Vec<f64> = (0..4096)
            .map(|i| amp * (TAU * 123.75 * i as f64 / fs + 0.4).sin())
            .collect();
        let psd = welch_psd(&tone, fs, 256).unwrap();
        assert!((psd.mean_square() / (amp * amp / 2.0) - 1.0).abs() < 0.01);
        // On a bin (128 Hz = bin 512 of 4096 at 1024 Hz) the rectangular spectrum is exact.
        let on_bin: Vec<f64> = (0..4096)
            .map(|i| amp * (TAU * 128.0 * i as f64 / fs + 0.4).sin())
            .collect();
        let spec = amplitude_spectrum(&on_bin, fs, Window::Rectangular).unwrap();
        assert!((spec.frequency_hz[512] - 128.0).abs() < 1e-12);
        assert!((spec.amplitude[512] - amp).abs() < 1e-9);
        let hann = amplitude_spectrum(&on_bin, fs, Window::Hann).unwrap();
        assert!((hann.amplitude[512] - amp).abs() < 1e-9);
    }

    #[test]
    fn bad_arguments_are_named() {
        let err = welch_psd(&[0.0; 10], 100.0, 64).unwrap_err();
        assert!(err.to_string().contains("segment_len"));
        let err = welch_psd(&[0.0, f64::NAN, 0.0, 0.0], 100.0, 4).unwrap_err();
        assert!(err.to_string().contains("sample 1"));
    }
}
