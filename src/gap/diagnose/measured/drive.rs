//! What input accelerometer records measure of the drive's amplitudes (docs/results/diagnosis.md,
//! "Measured secondary values"): the drive the tube (rail) received, against the drive the
//! campaign commanded.
//!
//! - **Cross-axis share.** At each drive tone, the motion of each other axis relative to the
//!   drive axis: `s² = (|P_c|² - 2 σ_c²) / |P_d|²` (the noise's mean contribution `2 σ_c²`
//!   removed, so a record without cross motion reads 0, not the noise floor), combined over
//!   records, tones and axes. The share the records allow is the 3σ band of the mean, widened by
//!   the two channels' calibration (`√2` times the relative calibration error, 3σ). A
//!   `cross_axis` candidate is held to it: one that needs a cross-axis drive the records do not
//!   show is refused.
//! - **Mount transmissibility.** On the drive axis, the steady amplitude (the record's trailing
//!   whole cycles, after any ramp-in) over the commanded one: the gain `|T(f)|` of a compliant
//!   fixture at each drive frequency, with the drive channel's calibration error as its floor.
//!   The `(natural period, damping)` pairs of `fixture_compliance` whose `|T|` matches every
//!   measured gain within 3σ bound the period (and the damping, where the gains constrain it: a
//!   drive far below the mount's resonance sees `|T| ≈ 1/(1 - r²)` whatever the damping). A gain
//!   no mount within the library's bounds gives leaves only the rigid mount (period 0).
//!
//! Only the drive of a sine excitation is read (its tones and levels are known); the damping is
//! reported as measured only when the records exclude part of its range.

use super::{phasor, phasor_sd, MeasuredValue, MIN_SNR};
use crate::excitation::Tone;
use crate::gap::effects::{self, transmissibility};
use crate::units::STANDARD_GRAVITY;
use std::f64::consts::PI;

/// Fewest steady whole cycles of the drive tone a gain reading needs.
pub const MIN_STEADY_CYCLES: usize = 2;

/// Relative spread of the steady cycles' amplitudes tolerated besides their noise (a smooth
/// ramp-in's last cycle within 0.5 % of the level counts as steady).
const STEADY_REL: f64 = 0.005;

/// Steps of the `(period, damping)` scan that bounds the fixture's parameters.
const PERIOD_STEPS: usize = 801;
const DAMPING_STEPS: usize = 117;

/// A value with its standard deviation.
type Reading = (f64, f64);

/// Gain readings at one drive frequency: `(frequency Hz, gain, sd)`.
type GainReading = (f64, f64, f64);

/// What one input record reads of the drive: cross-axis `s²` readings and drive-axis gains.
#[derive(Debug, Default)]
pub(super) struct DriveReadings {
    pub share2: Vec<Reading>,
    pub gains: Vec<GainReading>,
}

impl DriveReadings {
    pub(super) fn extend(&mut self, other: DriveReadings) {
        self.share2.extend(other.share2);
        self.gains.extend(other.gains);
    }
}

/// The drive readings of one record `[t, ax, ay, az]` under the commanded `tones`.
pub(super) fn record_drive(samples: &[[f64; 4]], tones: &[Tone]) -> DriveReadings {
    let mut out = DriveReadings::default();
    if samples.len() < 16 {
        return out;
    }
    let t: Vec<f64> = samples.iter().map(|s| s[0] - samples[0][0]).collect();
    let span = t.last().copied().unwrap_or(0.0);
    let dt = span / (t.len() - 1).max(1) as f64;
    let h = crate::analysis::spectra::window_values(
        crate::analysis::spectra::Window::Hann,
        samples.len(),
    );
    let freqs: Vec<f64> = tones.iter().map(|x| x.frequency_hz).collect();
    let cols: Vec<Vec<f64>> = (1..4)
        .map(|col| {
            let mean = samples.iter().map(|s| s[col]).sum::<f64>() / samples.len() as f64;
            samples.iter().map(|s| s[col] - mean).collect()
        })
        .collect();
    let fits: Vec<Vec<(f64, f64)>> = cols
        .iter()
        .map(|x| freqs.iter().map(|&f| phasor(&t, x, &h, f)).collect())
        .collect();
    let noise: Vec<f64> = cols
        .iter()
        .zip(&fits)
        .map(|(x, fit)| phasor_sd(&t, x, &h, &freqs, fit))
        .collect();
    for (k, tone) in tones.iter().enumerate() {
        let shared = tones
            .iter()
            .any(|o| o.axis != tone.axis && (o.frequency_hz - tone.frequency_hz).abs() < 1e-9);
        if shared || tone.frequency_hz * span < 2.0 || 2.0 * tone.frequency_hz * dt >= 1.0 {
            continue;
        }
        let d = tone.axis.index();
        let md = fits[d][k].0.hypot(fits[d][k].1);
        if md < MIN_SNR * noise[d] {
            continue;
        }
        for c in (0..3).filter(|&c| c != d) {
            let mc = fits[c][k].0.hypot(fits[c][k].1);
            let s2 = (mc * mc - 2.0 * noise[c] * noise[c]) / (md * md);
            // |P_c|² has sd 2 |P_c| σ (signal) plus 2 σ² (noise alone); the drive's own noise
            // enters through md² at 2 σ_d / md relative.
            let sd = (2.0 * mc * noise[c] + 2.0 * noise[c] * noise[c]) / (md * md)
                + s2.abs() * 2.0 * noise[d] / md;
            out.share2.push((s2, sd));
        }
        // The gain: only a drive axis with this one tone (a cycle projection would mix two).
        let alone = tones
            .iter()
            .filter(|o| o.axis == tone.axis && o.amplitude_g > 0.0)
            .count()
            == 1;
        if alone && tone.amplitude_g > 0.0 {
            if let Some((a, sd)) = steady_amplitude(&t, &cols[d], tone.frequency_hz) {
                let commanded = tone.amplitude_g * STANDARD_GRAVITY;
                out.gains
                    .push((tone.frequency_hz, a / commanded, sd / commanded));
            }
        }
    }
    out
}

/// Amplitude of the `f` Hz tone in `x` over the record's trailing steady whole cycles (from
/// the end back while each cycle's amplitude agrees with the mean of those after it) and its
/// standard deviation; None with fewer than [`MIN_STEADY_CYCLES`] cycles. Each cycle is the
/// last `round(1 / (f dt))` samples before the next, fitted by least squares with a constant,
/// a cosine and a sine (exact for a pure tone whatever the sample count).
fn steady_amplitude(t: &[f64], x: &[f64], f: f64) -> Option<Reading> {
    let n = t.len();
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    let per = (1.0 / (f * dt)).round() as usize;
    if per < 8 {
        return None;
    }
    let cycles = n / per;
    if cycles < MIN_STEADY_CYCLES {
        return None;
    }
    let w = 2.0 * PI * f;
    let mut amps = Vec::with_capacity(cycles);
    let mut resid = (0.0, 0usize);
    for j in 0..cycles {
        let idx = n - (j + 1) * per..n - j * per;
        let (re, im, c0) = fit_tone(&t[idx.clone()], &x[idx.clone()], w)?;
        for i in idx {
            let r = x[i] - c0 - re * (w * t[i]).cos() - im * (w * t[i]).sin();
            resid.0 += r * r;
            resid.1 += 1;
        }
        amps.push(re.hypot(im));
    }
    let sigma = (resid.0 / resid.1.saturating_sub(3 * cycles).max(1) as f64).sqrt();
    // One cycle's amplitude deviation: the noise's projection on the tone, sqrt(2/n) sigma.
    let cycle_sd = sigma * (2.0 / per as f64).sqrt();
    let mut kept = 1;
    let mut sum = amps[0];
    while kept < amps.len() {
        let mean = sum / kept as f64;
        if (amps[kept] - mean).abs() > (3.0 * cycle_sd).max(STEADY_REL * mean) {
            break;
        }
        sum += amps[kept];
        kept += 1;
    }
    if kept < MIN_STEADY_CYCLES {
        return None;
    }
    Some((sum / kept as f64, cycle_sd / (kept as f64).sqrt()))
}

/// Least-squares `x ≈ c0 + a cos ωt + b sin ωt` over the samples: `(a, b, c0)`; None when the
/// normal equations are singular.
fn fit_tone(t: &[f64], x: &[f64], w: f64) -> Option<(f64, f64, f64)> {
    // Normal equations of the basis [cos, sin, 1], solved by Cramer's rule.
    let mut m = [[0.0; 3]; 3];
    let mut v = [0.0; 3];
    for (ti, xi) in t.iter().zip(x) {
        let b = [(w * ti).cos(), (w * ti).sin(), 1.0];
        for r in 0..3 {
            v[r] += b[r] * xi;
            for c in 0..3 {
                m[r][c] += b[r] * b[c];
            }
        }
    }
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    if d.abs() < 1e-12 * (t.len() as f64).powi(3) {
        return None;
    }
    let mut out = [0.0; 3];
    for (k, o) in out.iter_mut().enumerate() {
        let mut mk = m;
        for r in 0..3 {
            mk[r][k] = v[r];
        }
        *o = det(&mk) / d;
    }
    Some((out[0], out[1], out[2]))
}

/// The cross-axis share the readings allow, as a measured band (None without readings).
pub(super) fn share_value(
    readings: &[Reading],
    calibration_rel: f64,
    records: usize,
) -> Option<MeasuredValue> {
    let (mean, sd) = weighted_mean(readings)?;
    let cal = 2f64.sqrt() * calibration_rel;
    let band = |k: f64| {
        let lo = (mean - k * sd).max(0.0).sqrt() * (1.0 - k * cal).max(0.0);
        let hi = (mean + k * sd).max(0.0).sqrt() * (1.0 + k * cal);
        [lo, hi]
    };
    let info = effects::info("cross_axis")?;
    band_value(
        "cross_axis",
        info.parameters[0].name,
        band(1.96),
        band(3.0),
        format!(
            "input accelerometer records ({records} records, {} readings: cross-axis motion over the drive at each tone)",
            readings.len()
        ),
    )
}

/// The fixture compliance's period (and damping, where constrained) the drive-axis gains
/// allow (empty without gains).
pub(super) fn fixture_values(
    gains: &[GainReading],
    calibration_rel: f64,
    records: usize,
) -> Vec<MeasuredValue> {
    let Some(info) = effects::info("fixture_compliance") else {
        return Vec::new();
    };
    let (period, damping) = (&info.parameters[0], &info.parameters[1]);
    // Per frequency: the mean gain and its relative deviation, the calibration its floor.
    let mut freqs: Vec<f64> = gains.iter().map(|g| g.0).collect();
    freqs.sort_by(f64::total_cmp);
    freqs.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    let measured: Vec<(f64, f64, f64)> = freqs
        .iter()
        .filter_map(|&f| {
            let at: Vec<Reading> = gains
                .iter()
                .filter(|g| (g.0 - f).abs() < 1e-9)
                .map(|g| (g.1, g.2))
                .collect();
            let (g, sd) = weighted_mean(&at)?;
            (g > 0.0).then(|| (f, g, (sd / g).hypot(calibration_rel)))
        })
        .collect();
    if measured.is_empty() {
        return Vec::new();
    }
    let consistent = |k: f64, p_ms: f64, zeta: f64| {
        measured.iter().all(|&(f, g, rel)| {
            let tg = transmissibility(f, p_ms * 1e-3, zeta).0;
            (tg.ln() - g.ln()).abs() <= k * rel
        })
    };
    let band = |k: f64| -> ([f64; 2], [f64; 2]) {
        let (mut p, mut z) = (
            [f64::INFINITY, f64::NEG_INFINITY],
            [f64::INFINITY, f64::NEG_INFINITY],
        );
        for i in 0..PERIOD_STEPS {
            let pm = period.min + (period.max - period.min) * i as f64 / (PERIOD_STEPS - 1) as f64;
            for j in 0..DAMPING_STEPS {
                let zeta = damping.min
                    + (damping.max - damping.min) * j as f64 / (DAMPING_STEPS - 1) as f64;
                if consistent(k, pm, zeta) {
                    p = [p[0].min(pm), p[1].max(pm)];
                    z = [z[0].min(zeta), z[1].max(zeta)];
                }
            }
        }
        // No mount within the bounds matches: only the rigid mount (period 0) is left.
        if p[0] > p[1] {
            ([0.0, 0.0], [damping.min, damping.max])
        } else {
            (p, z)
        }
    };
    let ((p95, z95), (p3, z3)) = (band(1.96), band(3.0));
    let source = format!(
        "input accelerometer records ({records} records: drive-axis gain {} against the commanded level)",
        measured
            .iter()
            .map(|(f, g, rel)| format!("{g:.4} ± {:.4} at {f} Hz", g * rel))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut out: Vec<MeasuredValue> = band_value(info.name, period.name, p95, p3, source.clone())
        .into_iter()
        .collect();
    // The damping only where the gains exclude at least a tenth of its range.
    if z3[1] - z3[0] < 0.9 * (damping.max - damping.min) {
        out.extend(band_value(info.name, damping.name, z95, z3, source));
    }
    out
}

/// A measured band: `value` its 95 % band's middle, `sd` the half-width over 1.96, `band` the
/// 3σ values a table or fit must keep to.
fn band_value(
    effect: &str,
    parameter: &str,
    b95: [f64; 2],
    b3: [f64; 2],
    source: String,
) -> Option<MeasuredValue> {
    if !(b3[0].is_finite() && b3[1].is_finite()) {
        return None;
    }
    let value = 0.5 * (b95[0] + b95[1]);
    let sd = 0.5 * (b95[1] - b95[0]) / 1.96;
    Some(MeasuredValue {
        effect: effect.into(),
        parameter: parameter.into(),
        value,
        sd,
        tolerance: (b3[1] - value).max(value - b3[0]),
        source,
        band: Some([b3[0].min(b95[0]), b3[1].max(b95[1])]),
    })
}

/// Inverse-variance mean of `readings` and its deviation, inflated by the readings' scatter
/// when they disagree beyond their stated deviations (Birge ratio above 1).
fn weighted_mean(readings: &[Reading]) -> Option<Reading> {
    if readings.is_empty() {
        return None;
    }
    let w: Vec<f64> = readings
        .iter()
        .map(|r| 1.0 / (r.1 * r.1).max(1e-300))
        .collect();
    let sw: f64 = w.iter().sum();
    let mean = readings.iter().zip(&w).map(|(r, w)| r.0 * w).sum::<f64>() / sw;
    let sd = sw.sqrt().recip();
    let n = readings.len();
    let birge = if n > 1 {
        let chi2: f64 = readings
            .iter()
            .zip(&w)
            .map(|(r, w)| w * (r.0 - mean).powi(2))
            .sum();
        (chi2 / (n - 1) as f64).sqrt().max(1.0)
    } else {
        1.0
    };
    Some((mean, sd * birge))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::excitation::Axis;

    /// A 0.5 s record at 2 kHz of a 15 g, 20 Hz drive on y through a mount of `period_ms` and
    /// `zeta` (its closed-form gain), ramped in over 3 cycles (raised cosine), with `share` of
    /// it on x and z 40° later, white noise of `noise` m/s² per axis (fixed-seed generator).
    fn record(period_ms: f64, zeta: f64, share: f64, noise: f64, seed: u64) -> Vec<[f64; 4]> {
        let gain = transmissibility(20.0, period_ms * 1e-3, zeta).0;
        let amplitude = 15.0 * STANDARD_GRAVITY * gain;
        super::super::tests::synthetic_record(amplitude, 0.4, share, 40.0, 0.15, noise, seed)
    }

    fn tones() -> Vec<Tone> {
        vec![Tone {
            axis: Axis::Y,
            frequency_hz: 20.0,
            amplitude_g: 15.0,
            phase_deg: 0.0,
        }]
    }

    #[test]
    fn the_steady_gain_is_the_mounts_transmissibility_after_the_ramp() {
        // Noise-free: the trailing cycles give |T| (1/(1 - r²) nearly, r = 0.3: 1.0985 at
        // zeta 0.1) to 1e-6, the ramp's cycles left out.
        let d = record_drive(&record(15.0, 0.1, 0.0, 0.0, 1), &tones());
        let expected = transmissibility(20.0, 0.015, 0.1).0;
        assert!((expected - 1.0985).abs() < 1e-3, "{expected}");
        assert_eq!(d.gains.len(), 1);
        assert!((d.gains[0].1 - expected).abs() < 1e-6, "{:?}", d.gains);
        // With noise: within 4 stated deviations on each of 50 records.
        for seed in 0..50 {
            let d = record_drive(&record(15.0, 0.1, 0.0, 0.5, seed), &tones());
            let (_, g, sd) = d.gains[0];
            assert!((g - expected).abs() < 4.0 * sd, "{g} ± {sd} for {expected}");
        }
    }

    #[test]
    fn the_gain_bounds_the_period_and_contains_the_drawn_one() {
        // 15 ms / damping 0.1 at a 2 % calibration: the 95 % interval holds 15 ms, and the
        // 3σ band excludes 20 ms (|T| 1.19: ln ratio 0.080, four deviations of 0.02) and the
        // rigid mount (ln 1.0985 = 0.094). Below resonance the damping barely moves |T|
        // (1.0953 at 0.3): it is not measured.
        let d = record_drive(&record(15.0, 0.1, 0.0, 0.5, 3), &tones());
        let m = fixture_values(&d.gains, 0.02, 1);
        assert_eq!(m.len(), 1, "{m:?}");
        let p = &m[0];
        assert_eq!(p.parameter, "natural_period_ms");
        let (lo, hi) = (p.value - 1.96 * p.sd, p.value + 1.96 * p.sd);
        assert!(lo < 15.0 && 15.0 < hi, "[{lo}, {hi}]");
        let [b0, b1] = p.band.unwrap();
        assert!(b0 > 0.0 && b1 < 20.0, "{:?}", p.band);
        assert!(!p.agrees(20.0) && !p.agrees(0.0) && p.agrees(15.0));
    }

    #[test]
    fn a_gain_of_one_leaves_a_stiff_mount_and_a_gain_no_mount_gives_leaves_only_the_rigid_one() {
        // Rigid: |T| = 1 within 2 %: periods up to r² ≈ 1 - 1/1.062 at 3σ, r 0.24, about 12 ms.
        let m = fixture_values(&[(20.0, 1.0, 1e-4)], 0.02, 1);
        let [b0, b1] = m[0].band.unwrap();
        assert!(b0 == 0.0 && (11.0..12.5).contains(&b1), "[{b0}, {b1}]");
        // |T| = 0.8 at 20 Hz needs r > sqrt(2), a period above 70 ms: none within [0, 20].
        let m = fixture_values(&[(20.0, 0.8, 1e-4)], 0.02, 1);
        assert_eq!(m[0].band, Some([0.0, 0.0]));
    }

    #[test]
    fn the_share_is_read_without_the_noise_floor_and_no_cross_motion_bounds_it_near_zero() {
        // No cross motion: the share's band stays below 0.002 (noise 0.5 m/s² against a
        // 161 m/s² drive), so a cross-axis drive of 0.01 or more contradicts the records.
        let mut r = DriveReadings::default();
        for seed in 0..4 {
            r.extend(record_drive(&record(0.0, 0.05, 0.0, 0.5, seed), &tones()));
        }
        let m = share_value(&r.share2, 0.02, 4).unwrap();
        let [lo, hi] = m.band.unwrap();
        assert!(lo == 0.0 && hi < 0.002, "{m:?}");
        assert!(!m.agrees(0.01));
        // A share of 0.24: read within its calibration (3 x √2 x 2 %, 8.5 %).
        let mut r = DriveReadings::default();
        r.extend(record_drive(&record(0.0, 0.05, 0.24, 0.5, 9), &tones()));
        let m = share_value(&r.share2, 0.02, 1).unwrap();
        assert!(m.agrees(0.24) && !m.agrees(0.2) && !m.agrees(0.28), "{m:?}");
    }
}
