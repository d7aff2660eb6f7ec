//! Secondary values the data measure before any fit (docs/results/diagnosis.md, "Measured secondary
//! values"): a campaign's input accelerometer records (on the driven tube or rail) carry the
//! drive itself, so a cross-axis drive's phase is read from them, not profiled.
//!
//! At each drive tone's frequency, each record's phasor on each axis is taken (a Hann-window
//! projection, the window of `analysis::spectra`); the cross-axis phase is `arg(P_cross / P_drive)` on each other axis that
//! moves (the phasor at least [`MIN_SNR`] times its noise), with the noise from the record's
//! residual after the tones are taken out. The phases of every record, tone and cross axis
//! are combined by a weighted circular mean. When they disagree beyond their noise (and
//! [`CHANNEL_PHASE_DEG`]), one phase does not describe the drive and nothing is measured.
//!
//! Why it is exact for the library's effect: `cross_axis` repeats each tone on the other axes
//! at `share` times its amplitude and `phase_deg` later, and the tube is driven rigidly, so
//! the input records see that relative phase. A compliant fixture (`fixture_compliance`)
//! shifts every axis' tone by the same transmissibility phase and leaves the relative phase.

mod drive;

use crate::analysis::spectra::{window_values, Window};
use crate::excitation::{ExcitationSpec, Tone};
use crate::gap::accel::AccelLocation;
use crate::gap::{Campaign, GapError};
use drive::{fixture_values, record_drive, share_value, DriveReadings};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::path::Path;

/// Fewest noise standard deviations a cross axis' phasor must reach to carry a phase.
pub const MIN_SNR: f64 = 10.0;

/// Phase match between a triaxial accelerometer's channels, degrees: the measurement's
/// systematic floor (data sheets give 1-2° at tens of Hz; the records' own noise is far
/// smaller at these amplitudes).
pub const CHANNEL_PHASE_DEG: f64 = 2.0;

/// A secondary parameter the data measure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeasuredValue {
    /// Library effect.
    pub effect: String,
    /// Its secondary parameter.
    pub parameter: String,
    /// Measured value, in the parameter's unit.
    pub value: f64,
    /// Standard deviation from the records' noise, in the parameter's unit.
    pub sd: f64,
    /// Tables whose value lies farther than this from `value` contradict the measurement:
    /// 3 standard deviations with the channel floor ([`CHANNEL_PHASE_DEG`]) added in
    /// quadrature.
    pub tolerance: f64,
    /// Where it comes from.
    pub source: String,
    /// For a magnitude or a ratio (not an angle): the values the records allow (3 standard
    /// deviations, calibration included), which a table's value or a fitted magnitude must keep
    /// to; None for an angle (`value` ± `tolerance`, modulo 360°).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub band: Option<[f64; 2]>,
}

impl MeasuredValue {
    /// Whether `v` agrees with the measurement (within `band` when given, else angles
    /// compared modulo 360°).
    pub fn agrees(&self, v: f64) -> bool {
        match self.band {
            Some([lo, hi]) => lo <= v && v <= hi,
            None => wrap_deg(v - self.value).abs() <= self.tolerance,
        }
    }
}

/// `d` wrapped into [-180°, 180°).
pub fn wrap_deg(d: f64) -> f64 {
    (d + 180.0).rem_euclid(360.0) - 180.0
}

/// One phase reading: degrees and its standard deviation.
type Reading = (f64, f64);

/// What `campaign`'s input records measure (empty without input records): the cross-axis
/// phase where the records show cross-axis motion, the cross-axis share the records allow, and
/// the fixture compliance's period (and damping, where constrained) from the drive-axis gain
/// (module `drive`); `calibration_rel` is each accelerometer's relative calibration
/// error (1σ). An error only when a test's case cannot be resolved.
pub fn measure(
    campaign: &Campaign,
    configs_dir: &Path,
    calibration_rel: f64,
) -> Result<Vec<MeasuredValue>, GapError> {
    let mut readings: Vec<Reading> = Vec::new();
    let mut drive = DriveReadings::default();
    let (mut records, mut drive_records) = (0, 0);
    for (ti, test) in campaign.tests.iter().enumerate() {
        let inputs: Vec<_> = test
            .specimens
            .iter()
            .flat_map(|s| s.accelerometers.iter())
            .filter(|r| r.location == AccelLocation::Input && r.samples.len() > 16)
            .collect();
        if inputs.is_empty() {
            continue;
        }
        let case = test.case(ti, configs_dir)?;
        let excitation = crate::models::case::resolve_excitation(&case, configs_dir)
            .map_err(|e| GapError::field(format!("tests[{ti}].config"), e.to_string()))?;
        let tones = match excitation {
            ExcitationSpec::Sine { tones, .. } | ExcitationSpec::SineOnRandom { tones, .. } => {
                tones
            }
            _ => continue,
        };
        for r in inputs {
            let before = readings.len();
            readings.extend(record_readings(&r.samples, &tones));
            records += usize::from(readings.len() > before);
            let d = record_drive(&r.samples, &tones);
            drive_records += usize::from(!d.share2.is_empty() || !d.gains.is_empty());
            drive.extend(d);
        }
    }
    let mut out: Vec<MeasuredValue> = combine(&readings)
        .map(|(value, sd)| MeasuredValue {
            effect: "cross_axis".into(),
            parameter: "phase_deg".into(),
            value,
            sd,
            tolerance: 3.0 * sd.hypot(CHANNEL_PHASE_DEG),
            source: format!(
                "input accelerometer records ({records} records, {} readings: drive tones x moving cross axes)",
                readings.len()
            ),
            band: None,
        })
        .into_iter()
        .collect();
    out.extend(share_value(&drive.share2, calibration_rel, drive_records));
    out.extend(fixture_values(&drive.gains, calibration_rel, drive_records));
    for m in &out {
        tracing::info!(
            effect = %m.effect, parameter = %m.parameter, value = m.value, band = ?m.band,
            "measured from the input records"
        );
    }
    Ok(out)
}

/// The cross-axis phase readings of one record `[t, ax, ay, az]` at each drive tone whose
/// frequency no other axis' tone shares.
fn record_readings(samples: &[[f64; 4]], tones: &[Tone]) -> Vec<Reading> {
    let t: Vec<f64> = samples.iter().map(|s| s[0] - samples[0][0]).collect();
    let span = t.last().copied().unwrap_or(0.0);
    let h = window_values(Window::Hann, samples.len());
    let mut out = Vec::new();
    // Each axis' samples less their mean, its phasor at every tone frequency, and the
    // phasor's noise from the residual after they are removed.
    let freqs: Vec<f64> = tones.iter().map(|x| x.frequency_hz).collect();
    let (mut fits, mut noise) = (Vec::with_capacity(3), Vec::with_capacity(3));
    for col in 1..4 {
        let mean = samples.iter().map(|s| s[col]).sum::<f64>() / samples.len() as f64;
        let x: Vec<f64> = samples.iter().map(|s| s[col] - mean).collect();
        let fit: Vec<(f64, f64)> = freqs.iter().map(|&f| phasor(&t, &x, &h, f)).collect();
        noise.push(phasor_sd(&t, &x, &h, &freqs, &fit));
        fits.push(fit);
    }
    for (k, tone) in tones.iter().enumerate() {
        // A frequency another axis' tone shares: the drive moves two axes there already.
        let shared = tones
            .iter()
            .any(|o| o.axis != tone.axis && (o.frequency_hz - tone.frequency_hz).abs() < 1e-9);
        // At least two cycles in the record for the projection to separate the tones, and
        // below the record's Nyquist frequency.
        let dt = span / (t.len() - 1).max(1) as f64;
        if shared || tone.frequency_hz * span < 2.0 || 2.0 * tone.frequency_hz * dt >= 1.0 {
            continue;
        }
        let d = tone.axis.index();
        let pd = fits[d][k];
        let md = pd.0.hypot(pd.1);
        if md < MIN_SNR * noise[d] {
            continue;
        }
        for c in (0..3).filter(|&c| c != d) {
            let pc = fits[c][k];
            let mc = pc.0.hypot(pc.1);
            if mc < MIN_SNR * noise[c] {
                continue;
            }
            let phase = (pc.1.atan2(pc.0) - pd.1.atan2(pd.0)).to_degrees();
            let sd = (noise[c] / mc).hypot(noise[d] / md).to_degrees();
            out.push((wrap_deg(phase), sd));
        }
    }
    out
}

/// Complex amplitude `(re, im)` of the zero-mean samples `x` at times `t` at `f` Hz:
/// `x(t) ≈ re cos ωt - im sin ωt` (a projection weighted by the window `h`), so its argument
/// is the tone's phase.
pub(super) fn phasor(t: &[f64], x: &[f64], h: &[f64], f: f64) -> (f64, f64) {
    let w = 2.0 * PI * f;
    let (mut re, mut im) = (0.0, 0.0);
    for ((ti, xi), hi) in t.iter().zip(x).zip(h) {
        re += hi * xi * (w * ti).cos();
        im -= hi * xi * (w * ti).sin();
    }
    let sw: f64 = h.iter().sum();
    (2.0 * re / sw, 2.0 * im / sw)
}

/// Standard deviation of one component of [`phasor`] from the residual after every tone
/// (`fits` at `freqs`) is removed: white noise of variance `s²` gives `s sqrt(2 Σ h²) / Σ h`
/// (each component takes half the noise power at the tone's frequency).
pub(super) fn phasor_sd(
    t: &[f64],
    x: &[f64],
    h: &[f64],
    freqs: &[f64],
    fits: &[(f64, f64)],
) -> f64 {
    let (mut r2, mut sh, mut sh2) = (0.0, 0.0, 0.0);
    for ((ti, xi), hi) in t.iter().zip(x).zip(h) {
        let model: f64 = freqs
            .iter()
            .zip(fits)
            .map(|(f, p)| {
                let w = 2.0 * PI * f * ti;
                p.0 * w.cos() - p.1 * w.sin()
            })
            .sum();
        let r = xi - model;
        r2 += hi * r * r;
        sh += hi;
        sh2 += hi * hi;
    }
    let s = (r2 / sh).sqrt();
    s * (2.0 * sh2).sqrt() / sh
}

/// Weighted circular mean of the readings and its standard deviation; None without readings
/// or when one reading lies more than 3 of its deviations (with the channel floor) from the
/// mean: one phase does not describe the drive.
fn combine(readings: &[Reading]) -> Option<(f64, f64)> {
    if readings.is_empty() {
        return None;
    }
    let (mut c, mut s, mut w) = (0.0, 0.0, 0.0);
    for &(p, sd) in readings {
        let wi = 1.0 / (sd * sd).max(1e-300);
        c += wi * p.to_radians().cos();
        s += wi * p.to_radians().sin();
        w += wi;
    }
    let mean = s.atan2(c).to_degrees();
    let agree = readings
        .iter()
        .all(|&(p, sd)| wrap_deg(p - mean).abs() <= 3.0 * sd.hypot(CHANNEL_PHASE_DEG));
    if !agree {
        tracing::info!(
            readings = readings.len(),
            "input records' cross-axis phases disagree beyond their noise: not measured"
        );
        return None;
    }
    Some((wrap_deg(mean), w.sqrt().recip()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::excitation::Axis;

    /// A record at 2 kHz, 1000 samples, of a 20 Hz drive on y of amplitude `amplitude` m/s²
    /// at phase `phase_rad`, with `share` of it on x and z `cross_deg` degrees later, the whole
    /// ramped in over `ramp_s` (raised cosine; 0: none), and white noise of `noise` m/s² on
    /// every axis (a fixed-seed generator). The drive tests (`drive.rs`) use it too.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn synthetic_record(
        amplitude: f64,
        phase_rad: f64,
        share: f64,
        cross_deg: f64,
        ramp_s: f64,
        noise: f64,
        seed: u64,
    ) -> Vec<[f64; 4]> {
        let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
        let mut gauss = move || {
            let mut u = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            let (a, b) = (u(), u());
            (-2.0 * a.ln()).sqrt() * (2.0 * PI * b).cos()
        };
        let (a, w) = (amplitude, 2.0 * PI * 20.0);
        (0..1000)
            .map(|i| {
                let t = i as f64 / 2000.0;
                let ramp = if t < ramp_s {
                    0.5 - 0.5 * (PI * t / ramp_s).cos()
                } else {
                    1.0
                };
                let cross = ramp * share * a * (w * t + phase_rad + cross_deg.to_radians()).sin();
                [
                    t,
                    cross + noise * gauss(),
                    ramp * a * (w * t + phase_rad).sin() + noise * gauss(),
                    cross + noise * gauss(),
                ]
            })
            .collect()
    }

    /// A record of a 20 Hz drive on y with a cross-axis share on x and z at `phase` degrees
    /// later, white noise of `noise` m/s² on every axis.
    fn record(phase: f64, share: f64, noise: f64, seed: u64) -> Vec<[f64; 4]> {
        synthetic_record(147.0, 0.3, share, phase, 0.0, noise, seed)
    }

    fn tones() -> Vec<Tone> {
        vec![Tone {
            axis: Axis::Y,
            frequency_hz: 20.0,
            amplitude_g: 15.0,
            phase_deg: 17.0,
        }]
    }

    #[test]
    fn a_cross_axis_phase_is_read_back_within_its_stated_deviation() {
        // 200 records at a noise that makes the deviation about a degree: the phase is
        // unbiased, and the stated deviation is the scatter's (a z-score's mean square near
        // 1, within what 200 draws allow: chi-square 200 dof, 99.9 % band 145-266).
        let (phase, share, noise) = (158.0, 0.021, 1.0);
        let mut z2 = 0.0;
        let mut n = 0;
        for seed in 0..100 {
            for (p, sd) in record_readings(&record(phase, share, noise, seed), &tones()) {
                z2 += (wrap_deg(p - phase) / sd).powi(2);
                n += 1;
            }
        }
        assert_eq!(n, 200, "both cross axes read on every record");
        assert!((145.0..266.0).contains(&z2), "sum of z² {z2} on {n}");
    }

    #[test]
    fn the_combined_phase_agrees_across_the_wrap_and_noise_free_records_are_exact() {
        for phase in [-179.0, -90.0, 0.0, 56.0, 179.5] {
            let readings = record_readings(&record(phase, 0.09, 1e-3, 1), &tones());
            let (v, sd) = combine(&readings).expect("readings agree");
            assert!(wrap_deg(v - phase).abs() < 1e-3, "{v} for {phase}");
            assert!(sd < 1e-3);
        }
    }

    #[test]
    fn no_cross_motion_measures_nothing_and_disagreeing_phases_measure_nothing() {
        assert!(record_readings(&record(40.0, 0.0, 0.05, 2), &tones()).is_empty());
        assert_eq!(combine(&[(10.0, 0.1), (40.0, 0.1)]), None);
        assert!(combine(&[(179.0, 0.1), (-179.0, 0.1)]).is_some());
    }
}
