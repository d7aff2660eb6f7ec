//! Cross-cutting checks of the excitation module against closed forms and the target PSD.

use super::profile::{ah64_transverse_representative, rattle_box_20hz_15g};
use super::*;
use crate::analysis::spectra::{amplitude_spectrum, welch_psd, Window};
use crate::units::STANDARD_GRAVITY;
use std::f64::consts::TAU;

const AH64_PSD: [(f64, f64); 3] = [(5.0, 0.0005), (10.0, 0.001), (500.0, 0.001)];

#[test]
fn welch_psd_of_synthesis_matches_target_within_1_db() {
    // 128 s at 2048 Hz; Welch with 2048-sample segments (1 Hz bins, 255 segments). Each bin's
    // estimate scatters by about 1/sqrt(255 * 0.9) = 6.6 %; averaging 4 adjacent bins (4 Hz
    // bands from 7 to 499 Hz, away from the 5 Hz band edge where the Hann main lobe sees the
    // empty band below) gives about 3.5 %, so 1 dB (-21 %/+26 %) is a 6 sigma bound.
    let fs = 2048.0;
    let rec = synthesize_random(&[Axis::X], &AH64_PSD, 128.0, fs, 514, 4.0).unwrap();
    let accel_g: Vec<f64> = rec
        .samples()
        .iter()
        .map(|s| s.acceleration_m_s2[0] / STANDARD_GRAVITY)
        .collect();
    let psd = welch_psd(&accel_g, fs, 2048).unwrap();
    let mut worst_db: f64 = 0.0;
    let mut band_lo = 7.0;
    while band_lo < 496.0 {
        let estimate = psd.band_mean(band_lo, band_lo + 4.0).unwrap();
        let target = (0..4)
            .map(|i| psd_at(&AH64_PSD, band_lo + i as f64))
            .sum::<f64>()
            / 4.0;
        let db = 10.0 * (estimate / target).log10();
        worst_db = worst_db.max(db.abs());
        band_lo += 4.0;
    }
    eprintln!("welch worst band error {worst_db} dB");
    assert!(worst_db < 1.0, "worst band error {worst_db} dB");
    // Outside the band the PSD is empty (below 4 Hz and above 520 Hz, clear of leakage).
    assert!(psd.band_mean(520.0, 1000.0).unwrap() < 1e-6 * 0.001);
}

#[test]
fn synthesis_mean_square_equals_psd_integral() {
    // Line amplitudes are deterministic, so the record's mean square is the Riemann sum of the
    // PSD on the 1/T grid: within 1 % of the closed-form integral (here 0.49375 g²).
    let rec = synthesize_random(&[Axis::Y], &AH64_PSD, 32.0, 2048.0, 1, 4.0).unwrap();
    let n = rec.samples().len() as f64;
    let mean_square = rec
        .samples()
        .iter()
        .map(|s| (s.acceleration_m_s2[1] / STANDARD_GRAVITY).powi(2))
        .sum::<f64>()
        / n;
    let target = psd_mean_square(&AH64_PSD, 0.0, 1e9);
    // 5-10 Hz: G = 1e-4 f (3 dB/octave) gives 1e-4 (10² - 5²)/2; 10-500 Hz flat.
    assert!((target - (1e-4 * (100.0 - 25.0) / 2.0 + 0.001 * 490.0)).abs() < 1e-12);
    eprintln!("mean square {mean_square} g² vs {target}");
    assert!(
        (mean_square / target - 1.0).abs() < 0.01,
        "{mean_square} vs {target}"
    );
    // No drift: displacement and velocity have zero mean over the period.
    let mean_x = rec
        .samples()
        .iter()
        .map(|s| s.displacement_m[1])
        .sum::<f64>()
        / n;
    let mean_v = rec.samples().iter().map(|s| s.velocity_m_s[1]).sum::<f64>() / n;
    assert!(mean_x.abs() < 1e-12 && mean_v.abs() < 1e-12);
    // Other axes untouched.
    assert!(rec.samples().iter().all(|s| s.acceleration_m_s2[0] == 0.0));
}

#[test]
fn same_seed_same_record_other_seed_differs() {
    let a = synthesize_random(&[Axis::X, Axis::Z], &AH64_PSD, 4.0, 2048.0, 42, 4.0).unwrap();
    let b = synthesize_random(&[Axis::X, Axis::Z], &AH64_PSD, 4.0, 2048.0, 42, 4.0).unwrap();
    let c = synthesize_random(&[Axis::X, Axis::Z], &AH64_PSD, 4.0, 2048.0, 43, 4.0).unwrap();
    assert_eq!(a, b);
    assert!(a
        .samples()
        .iter()
        .zip(c.samples())
        .any(|(p, q)| p.acceleration_m_s2[0] != q.acceleration_m_s2[0]));
    // Independent phases per axis: x and z differ.
    assert!(a
        .samples()
        .iter()
        .any(|s| s.acceleration_m_s2[0] != s.acceleration_m_s2[2]));
}

/// Acceleration (axis x) of `motion` sampled at `fs` over one window of `n` samples starting at
/// excitation time `tau0_s`.
fn sample_x(motion: &BaseMotion, tau0_s: f64, fs: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|m| motion.acceleration(motion.settle_s() + tau0_s + m as f64 / fs)[0])
        .collect()
}

#[test]
fn tones_have_their_amplitude() {
    // AH-64 tones on bins: a 50 s record has 0.02 Hz lines and 4.86 Hz = line 243. Over one
    // whole period after the ramp the spectrum at a tone bin is the tone plus the random line
    // there, whose amplitude sqrt(2 G df) is known exactly, so
    // | |X| - A | <= 1 % A + sqrt(2 G df).
    let fs = 2048.0;
    let duration = 50.0;
    let ExcitationSpec::SineOnRandom { tones, .. } = ah64_transverse_representative() else {
        unreachable!("the AH-64 profile is sine-on-random")
    };
    let spec = ExcitationSpec::SineOnRandom {
        axes: vec![Axis::X],
        tones: tones.clone(),
        psd_breakpoints: AH64_PSD.to_vec(),
        duration_s: duration,
        sample_rate_hz: fs,
        seed: 9,
        low_cutoff_hz: 4.0,
        settle_s: 2.0,
        ramp: RampSpec::Cycles(3.0),
    };
    let motion = BaseMotion::from_spec(&spec).unwrap();
    let n = (duration * fs) as usize;
    let spectrum =
        amplitude_spectrum(&sample_x(&motion, duration, fs, n), fs, Window::Rectangular).unwrap();
    for tone in &tones {
        let k = (tone.frequency_hz * duration).round() as usize;
        let amp = tone.amplitude_g * STANDARD_GRAVITY;
        let line =
            (2.0 * psd_at(&AH64_PSD, tone.frequency_hz) / duration).sqrt() * STANDARD_GRAVITY;
        let err = (spectrum.amplitude[k] - amp).abs();
        assert!(
            err <= 0.01 * amp + line,
            "{} Hz: {err} vs {amp}",
            tone.frequency_hz
        );
    }
    // Tones clear of the random band must be exact to 1 %.
    let spec = ExcitationSpec::SineOnRandom {
        axes: vec![Axis::X],
        tones: vec![
            Tone {
                axis: Axis::X,
                frequency_hz: 5.0,
                amplitude_g: 0.3,
                phase_deg: 40.0,
            },
            Tone {
                axis: Axis::X,
                frequency_hz: 20.0,
                amplitude_g: 2.0,
                phase_deg: -10.0,
            },
        ],
        psd_breakpoints: vec![(100.0, 0.01), (400.0, 0.01)],
        duration_s: 8.0,
        sample_rate_hz: fs,
        seed: 3,
        low_cutoff_hz: 50.0,
        settle_s: 0.5,
        ramp: RampSpec::Seconds(1.0),
    };
    let motion = BaseMotion::from_spec(&spec).unwrap();
    let spectrum = amplitude_spectrum(
        &sample_x(&motion, 8.0, fs, 8 * 2048),
        fs,
        Window::Rectangular,
    )
    .unwrap();
    for (f, g) in [(5.0, 0.3), (20.0, 2.0)] {
        let k = (f * 8.0) as usize;
        let amp = g * STANDARD_GRAVITY;
        assert!((spectrum.amplitude[k] - amp).abs() < 0.01 * amp);
    }
}

/// v = dx/dt and a = dv/dt by central differences at times spread over settle, ramp and
/// steady state.
fn assert_consistent(motion: &BaseMotion, t_end: f64, scale_v: f64, scale_a: f64) {
    let h = 1e-6;
    for k in 0..400 {
        let t = t_end * k as f64 / 400.0 + 1.234e-4;
        let s = motion.state(t);
        let p = motion.state(t + h);
        let m = motion.state(t - h);
        for c in 0..3 {
            let dx = (p.displacement_m[c] - m.displacement_m[c]) / (2.0 * h);
            let dv = (p.velocity_m_s[c] - m.velocity_m_s[c]) / (2.0 * h);
            assert!(
                (dx - s.velocity_m_s[c]).abs() < 1e-6 * scale_v,
                "v at t={t}"
            );
            assert!(
                (dv - s.acceleration_m_s2[c]).abs() < 1e-5 * scale_a,
                "a at t={t}"
            );
        }
    }
}

#[test]
fn sine_motion_is_analytic_after_the_ramp() {
    let motion = BaseMotion::from_spec(&rattle_box_20hz_15g()).unwrap();
    let w = TAU * 20.0;
    let amp = 15.0 * STANDARD_GRAVITY;
    assert_eq!(motion.settle_s(), 2.0);
    assert!((motion.ramp_s() - 0.15).abs() < 1e-15);
    // Nothing during the settle phase, and a smooth start: x, v, a -> 0 at its end.
    assert_eq!(motion.state(1.0).displacement_m, nalgebra::Vector3::zeros());
    let start = motion.state(2.0 + 1e-6);
    assert!(start.displacement_m.norm() < 1e-12);
    assert!(start.velocity_m_s.norm() < 1e-9);
    assert!(start.acceleration_m_s2.norm() < 1e-3);
    // After the ramp: a = -w² x, peak 15 g, only on x.
    let mut peak: f64 = 0.0;
    for k in 0..5000 {
        let t = 2.15 + k as f64 * 1.0e-5 * 7.0;
        let s = motion.state(t);
        assert!((s.acceleration_m_s2[0] + w * w * s.displacement_m[0]).abs() < 1e-9 * amp);
        assert!(s.acceleration_m_s2[1] == 0.0 && s.acceleration_m_s2[2] == 0.0);
        peak = peak.max(s.acceleration_m_s2[0].abs());
    }
    assert!((peak / amp - 1.0).abs() < 1e-3);
    assert_consistent(&motion, 2.5, amp / w, amp);
}

#[test]
fn sine_on_random_motion_is_consistent() {
    let mut spec = ah64_transverse_representative();
    if let ExcitationSpec::SineOnRandom { duration_s, .. } = &mut spec {
        *duration_s = 2.0;
    }
    let motion = BaseMotion::from_spec(&spec).unwrap();
    assert!((motion.record_period_s().unwrap() - 2.0).abs() < 1e-12);
    // 3 cycles of the lowest frequency, the 4.86 Hz tone (below the 5 Hz PSD start).
    assert!((motion.ramp_s() - 3.0 / 4.86).abs() < 1e-12);
    // scale: a few g, velocities of order 0.1 m/s
    assert_consistent(&motion, 5.0, 0.1, 30.0);
}

#[test]
fn measured_motion_ramps_out_and_stops() {
    let rows: Vec<[f64; 4]> = (0..4000)
        .map(|m| {
            let t = m as f64 / 1000.0;
            [t, 0.0, (TAU * 12.0 * t).sin(), 0.0]
        })
        .collect();
    let spec = ExcitationSpec::Measured {
        csv_path: None,
        samples: Some(rows),
        units: AccelUnit::G,
        highpass_hz: 2.0,
        settle_s: 1.0,
        ramp: RampSpec::Seconds(0.5),
    };
    let motion = BaseMotion::from_spec(&spec).unwrap();
    assert!((motion.end_time_s().unwrap() - 4.999).abs() < 1e-9);
    assert!(motion.record_period_s().is_none());
    assert_eq!(motion.state(5.2).displacement_m, nalgebra::Vector3::zeros());
    let near_end = motion.state(4.999 - 1e-6);
    assert!(near_end.velocity_m_s.norm() < 1e-6);
    // Mid-record the y acceleration is the 1 g, 12 Hz input.
    let t = 3.0;
    let a = motion.acceleration(t)[1];
    let expected = STANDARD_GRAVITY * (TAU * 12.0 * (t - 1.0)).sin();
    assert!(
        (a - expected).abs() < 0.01 * STANDARD_GRAVITY,
        "{a} vs {expected}"
    );
    assert_consistent(&motion, 6.0, 0.2, STANDARD_GRAVITY);
}

#[test]
fn spec_errors_name_fields() {
    let err = BaseMotion::from_spec(&ExcitationSpec::Sine {
        tones: vec![],
        settle_s: 2.0,
        ramp: RampSpec::default(),
    })
    .unwrap_err();
    assert!(err.to_string().contains("`tones`"));
    let err = BaseMotion::from_spec(&ExcitationSpec::Sine {
        tones: vec![Tone {
            axis: Axis::X,
            frequency_hz: 20.0,
            amplitude_g: 1.0,
            phase_deg: 0.0,
        }],
        settle_s: -1.0,
        ramp: RampSpec::default(),
    })
    .unwrap_err();
    assert!(err.to_string().contains("settle_s"));
    let err = BaseMotion::from_spec(&ExcitationSpec::Measured {
        csv_path: None,
        samples: None,
        units: AccelUnit::G,
        highpass_hz: 2.0,
        settle_s: 2.0,
        ramp: RampSpec::default(),
    })
    .unwrap_err();
    assert!(err.to_string().contains("csv_path"));
    let err = BaseMotion::from_spec(&ExcitationSpec::Measured {
        csv_path: Some("/nonexistent/railwear.csv".into()),
        samples: None,
        units: AccelUnit::G,
        highpass_hz: 2.0,
        settle_s: 2.0,
        ramp: RampSpec::default(),
    })
    .unwrap_err();
    assert!(err.to_string().contains("/nonexistent/railwear.csv"));
}
