//! Where the nominal model misses: standardized residuals grouped by test, quantity
//! (component or accelerometer axis), increment, contact-pressure band, slip-speed band and
//! 1/3-octave band of the response spectrum, each group tested for a bias and all tests
//! corrected together by Holm's method.
//!
//! A group's score is `z = Σ w r / sqrt(Var Σ w r)`, standard normal when the model is right.
//! The residuals are independent but for the mean squares of one channel, which share its
//! calibration scale: with `a = 2 e_cal μ / u` the correlation of two of them is `a_i a_j`, so
//! `Var Σ w r = Σ w² + Σ_channels ((Σ w a)² - Σ w² a²)`. A calibration error alone therefore
//! moves a channel's score by about its own number of sigmas, not by that times `sqrt(n)`. The
//! frequency bands' log ratios carry the calibration's `(2 e_cal)²` in their variance. Pressure and slip bands are not measured: a band's score combines
//! the tests' mass scores weighted by the share of each test's friction work (the model's) in
//! that band, so a band lights up when the tests whose work falls there are the ones that miss.

use super::emulator::{PRESSURE_BANDS, SLIP_BANDS};
use super::fit_problem::FitProblem;
use super::noise::{Quantity, CHANNELS};
use super::stats;
use crate::analysis::spectra::welch_psd;
use crate::gap::accel::AccelLocation;
use crate::gap::Campaign;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};

/// Family-wise error rate of the flags.
pub const FLAG_LEVEL: f64 = 0.05;

/// Smallest work share (summed over tests) a pressure or slip band needs to be scored.
pub const MIN_BAND_SHARE: f64 = 0.05;

/// One group of residuals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Group {
    /// Grouping: `test`, `config`, `rattle_space`, `drive` (tests sharing that attribute,
    /// where it takes several values), `quantity`, `increment`, `pressure_band`, `slip_band`,
    /// `frequency_band`.
    pub by: String,
    /// Label, e.g. `C (k_rs 0.64, 15 g at 20 Hz)`.
    pub label: String,
    /// Weighted number of observations.
    pub observations: f64,
    /// Weighted mean standardized residual (measured above the model: positive). For
    /// frequency bands: measured / model, dB.
    pub mean_residual: f64,
    /// Bias score.
    pub z: f64,
    /// Two-sided p-value.
    pub p_value: f64,
    /// Holm-adjusted p-value.
    pub p_adjusted: f64,
    /// Adjusted p-value below 0.05.
    pub flagged: bool,
}

/// One observation's residual.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Residual {
    /// Test id.
    pub test: String,
    /// Increment, 1-based.
    pub increment: usize,
    /// Quantity (`mass cube`, `response z`, ...); masses in mg, mean squares in m²/s⁴.
    pub quantity: String,
    /// Mean reading.
    pub measured: f64,
    /// Nominal prediction.
    pub predicted: f64,
    /// Standard uncertainty.
    pub u: f64,
    /// (measured - predicted) / u.
    pub residual: f64,
}

/// Where the nominal model misses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Where {
    /// Groups, in the order test, quantity, increment, pressure band, slip band, frequency band.
    pub groups: Vec<Group>,
    /// Every observation.
    pub residuals: Vec<Residual>,
    /// Work by kind per test and contact, and the coefficient each wear mechanism would need
    /// for the measured wear (`budget`).
    #[serde(default)]
    pub energy_budget: super::budget::EnergyBudget,
}

impl Where {
    /// True when any group is flagged.
    pub fn any_flagged(&self) -> bool {
        self.groups.iter().any(|g| g.flagged)
    }
}

struct Acc {
    sum_wr: f64,
    sum_w2: f64,
    sum_w: f64,
    /// Per calibration channel: Σ w a and Σ w² a².
    sum_wa: [f64; CHANNELS],
    sum_w2a2: [f64; CHANNELS],
}

/// A residual's share of its channel's calibration scale: the channel and `a`.
type Shared = Option<(usize, f64)>;

impl Acc {
    fn new() -> Self {
        Self {
            sum_wr: 0.0,
            sum_w2: 0.0,
            sum_w: 0.0,
            sum_wa: [0.0; CHANNELS],
            sum_w2a2: [0.0; CHANNELS],
        }
    }

    fn push(&mut self, w: f64, r: f64, shared: Shared) {
        self.sum_wr += w * r;
        self.sum_w2 += w * w;
        self.sum_w += w;
        if let Some((c, a)) = shared {
            self.sum_wa[c] += w * a;
            self.sum_w2a2[c] += w * w * a * a;
        }
    }

    /// Variance of `Σ w r` when the model is right.
    fn var(&self) -> f64 {
        let shared: f64 = (0..CHANNELS)
            .map(|c| self.sum_wa[c].powi(2) - self.sum_w2a2[c])
            .sum();
        self.sum_w2 + shared.max(0.0)
    }

    fn z(&self) -> f64 {
        self.sum_wr / self.var().sqrt()
    }

    fn group(&self, by: &str, label: String) -> Option<Group> {
        (self.sum_w > 0.0).then(|| {
            let z = self.z();
            Group {
                by: by.into(),
                label,
                observations: self.sum_w,
                mean_residual: self.sum_wr / self.sum_w,
                z,
                p_value: stats::normal_two_sided(z),
                p_adjusted: 1.0,
                flagged: false,
            }
        })
    }
}

/// The configuration attributes a test shares with others: `config`, `rattle_space`, `drive`.
fn configuration_keys(t: &crate::gap::campaign::CampaignTest) -> Vec<(&'static str, String)> {
    let mut keys = vec![("config", t.config.clone())];
    if let Some(k) = t.rattle_space {
        keys.push(("rattle_space", format!("k_rs {k}")));
    }
    if let Some(d) = &t.drive {
        if let (Some(g), Some(f)) = (d.level_g, d.frequency_hz) {
            keys.push(("drive", format!("{g} g at {f} Hz")));
        } else if let Some(p) = &d.profile {
            keys.push(("drive", p.clone()));
        }
    }
    keys
}

fn test_label(campaign: &Campaign, ti: usize) -> String {
    let t = &campaign.tests[ti];
    let parts: Vec<String> = configuration_keys(t).into_iter().map(|(_, v)| v).collect();
    format!("{} ({})", t.id, parts.join(", "))
}

/// The residual breakdown of the nominal model.
pub(super) fn locate(campaign: &Campaign, problem: &FitProblem) -> Where {
    let em = problem.emulator;
    let nominal = &em.nominal;
    let ntests = campaign.tests.len();
    let mut residuals = Vec::with_capacity(problem.obs.len());
    let mut by_test: Vec<Acc> = (0..ntests).map(|_| Acc::new()).collect();
    let mut mass_by_test: Vec<Acc> = (0..ntests).map(|_| Acc::new()).collect();
    let mut by_quantity: Vec<(String, Acc)> = Vec::new();
    let mut by_increment: Vec<Acc> = Vec::new();
    let configuration: Vec<Vec<(&str, String)>> =
        campaign.tests.iter().map(configuration_keys).collect();
    let mut by_configuration: BTreeMap<(&str, String), (Acc, BTreeSet<usize>)> = BTreeMap::new();
    for o in &problem.obs {
        let mu = o.predicted(nominal);
        let u = problem.noise.u_marginal(o, mu);
        let r = (o.value - mu) / u;
        let shared: Shared = o
            .quantity
            .channel()
            .map(|c| (c, problem.noise.scale_var.sqrt() * mu / u));
        residuals.push(Residual {
            test: campaign.tests[o.test].id.clone(),
            increment: o.increment + 1,
            quantity: o.quantity.label(),
            measured: o.value,
            predicted: mu,
            u,
            residual: r,
        });
        by_test[o.test].push(o.weight, r, shared);
        if matches!(o.quantity, Quantity::Mass(_)) {
            mass_by_test[o.test].push(o.weight, r, shared);
        }
        let label = o.quantity.label();
        match by_quantity.iter_mut().find(|(l, _)| *l == label) {
            Some((_, a)) => a.push(o.weight, r, shared),
            None => {
                let mut a = Acc::new();
                a.push(o.weight, r, shared);
                by_quantity.push((label, a));
            }
        }
        while by_increment.len() <= o.increment {
            by_increment.push(Acc::new());
        }
        by_increment[o.increment].push(o.weight, r, shared);
        for (by, value) in &configuration[o.test] {
            let (acc, tests) = by_configuration
                .entry((by, value.clone()))
                .or_insert_with(|| (Acc::new(), BTreeSet::new()));
            acc.push(o.weight, r, shared);
            tests.insert(o.test);
        }
    }
    let mut groups: Vec<Group> = Vec::new();
    for (ti, a) in by_test.iter().enumerate() {
        groups.extend(a.group("test", test_label(campaign, ti)));
    }
    // Configuration: the tests that share a config, a rattle space or a drive, pooled. Only a
    // value two or more tests share, in a campaign where that attribute takes more than one
    // value, says more than the test groups or the whole campaign.
    for ((by, value), (a, tests)) in &by_configuration {
        let values = by_configuration.keys().filter(|(b, _)| b == by).count();
        if tests.len() >= 2 && values >= 2 {
            groups.extend(a.group(by, format!("{value} ({} tests)", tests.len())));
        }
    }
    for (label, a) in &by_quantity {
        groups.extend(a.group("quantity", label.clone()));
    }
    for (k, a) in by_increment.iter().enumerate() {
        groups.extend(a.group("increment", format!("increment {}", k + 1)));
    }
    // Bands: tests' mass scores weighted by their work share in the band.
    let test_z: Vec<Option<f64>> = mass_by_test
        .iter()
        .map(|a| (a.sum_w > 0.0).then(|| a.z()))
        .collect();
    for (by, names, pick) in [
        ("pressure_band", &PRESSURE_BANDS[..], 0usize),
        ("slip_band", &SLIP_BANDS[..], 1usize),
    ] {
        for (b, name) in names.iter().enumerate() {
            let mut num = 0.0;
            let mut den = 0.0;
            let mut share_sum = 0.0;
            for ti in 0..ntests {
                let Some(z) = test_z[ti] else { continue };
                let (mut in_band, mut total) = (0.0, 0.0);
                for inc in &em.bands[ti] {
                    let v = if pick == 0 { &inc.pressure } else { &inc.slip };
                    in_band += v[b];
                    total += v.iter().sum::<f64>();
                }
                if total <= 0.0 {
                    continue;
                }
                let a = in_band / total;
                num += a * z;
                den += a * a;
                share_sum += a;
            }
            // A band holding less than 5 % of one test's work says nothing.
            if den > 0.0 && share_sum >= MIN_BAND_SHARE {
                let z = num / den.sqrt();
                groups.push(Group {
                    by: by.into(),
                    label: format!("{name} (work share summed over tests {share_sum:.2})"),
                    observations: share_sum,
                    mean_residual: num / share_sum.max(1e-300),
                    z,
                    p_value: stats::normal_two_sided(z),
                    p_adjusted: 1.0,
                    flagged: false,
                });
            }
        }
    }
    groups.extend(frequency_bands(campaign, problem));
    let p: Vec<f64> = groups.iter().map(|g| g.p_value).collect();
    for (g, adj) in groups.iter_mut().zip(stats::holm(&p)) {
        g.p_adjusted = adj;
        g.flagged = adj < FLAG_LEVEL;
    }
    let energy_budget = energy_budget_of(campaign, em, &residuals);
    Where {
        groups,
        residuals,
        energy_budget,
    }
}

/// The energy budget of the nominal model's windows against the measured masses (summed over
/// each test's weighed increments).
fn energy_budget_of(
    campaign: &Campaign,
    em: &super::emulator::Emulator,
    residuals: &[Residual],
) -> super::budget::EnergyBudget {
    let mut measured: BTreeMap<(String, String), f64> = BTreeMap::new();
    for r in residuals {
        if let Some(component) = r.quantity.strip_prefix("mass ") {
            *measured
                .entry((r.test.clone(), component.to_string()))
                .or_insert(0.0) += r.measured;
        }
    }
    let tests: Vec<_> = campaign
        .tests
        .iter()
        .zip(&em.bands)
        .map(|(t, incs)| {
            let hours = t.increment_duration_s * incs.len() as f64 / 3600.0;
            (
                t.id.clone(),
                hours,
                incs.iter().map(|b| b.work.clone()).collect(),
            )
        })
        .collect();
    super::budget::energy_budget(&tests, &measured)
}

/// 1/3-octave band centres from 10 Hz to 500 Hz (base-2 series, IEC 61260 nominal spacing).
pub fn third_octave_centres() -> Vec<f64> {
    (0..=16).map(|k| 10.0 * 2f64.powf(k as f64 / 3.0)).collect()
}

/// Welch PSD of the summed axes: (psd, segments).
fn total_psd(samples: &[[f64; 3]], rate: f64) -> Option<(crate::analysis::spectra::Psd, usize)> {
    let n = samples.len();
    let mut seg = 16usize;
    while seg * 2 <= n / 2 && seg < 2048 {
        seg *= 2;
    }
    if seg > n || n < 32 {
        return None;
    }
    let mut total: Option<crate::analysis::spectra::Psd> = None;
    for axis in 0..3 {
        let s: Vec<f64> = samples.iter().map(|a| a[axis]).collect();
        let p = welch_psd(&s, rate, seg).ok()?;
        total = Some(match total {
            None => p,
            Some(mut t) => {
                for (d, x) in t.density.iter_mut().zip(&p.density) {
                    *d += x;
                }
                t
            }
        });
    }
    let segments = (n - seg) / (seg / 2) + 1;
    total.map(|t| (t, segments))
}

fn frequency_bands(campaign: &Campaign, problem: &FitProblem) -> Vec<Group> {
    let em = problem.emulator;
    let mut out = Vec::new();
    for (ti, test) in campaign.tests.iter().enumerate() {
        let records: Vec<_> = test
            .specimens
            .iter()
            .flat_map(|s| s.accelerometers.iter())
            .filter(|r| r.location == AccelLocation::Response)
            .collect();
        if records.is_empty() {
            continue;
        }
        let (rate_p, model) = &em.response_records[ti];
        let Some((psd_p, seg_p)) = total_psd(model, *rate_p) else {
            continue;
        };
        let (rate_h, half) = &em.halving_response_records[ti];
        let psd_h = total_psd(half, *rate_h).map(|(p, _)| p);
        // Measured: the records' PSDs averaged, sensor noise floor (white, 3 axes) removed.
        let mut measured: Vec<(crate::analysis::spectra::Psd, usize, f64)> = Vec::new();
        for r in &records {
            let xyz: Vec<[f64; 3]> = r.samples.iter().map(|s| [s[1], s[2], s[3]]).collect();
            if let Some((p, segs)) = total_psd(&xyz, r.sample_rate_hz) {
                let floor = 3.0 * 2.0 * r.sensor_noise_m_s2.powi(2) / r.sample_rate_hz;
                measured.push((p, segs, floor));
            }
        }
        if measured.is_empty() {
            continue;
        }
        for fc in third_octave_centres() {
            let (lo, hi) = (fc * 2f64.powf(-1.0 / 6.0), fc * 2f64.powf(1.0 / 6.0));
            let nyquist = measured
                .iter()
                .map(|(p, _, _)| p.frequency_hz.last().copied().unwrap_or(0.0))
                .fold(f64::INFINITY, f64::min)
                .min(*rate_p / 2.0);
            if hi > nyquist {
                continue;
            }
            let Some(pm) = psd_p.band_mean(lo, hi) else {
                continue;
            };
            let bins_p = psd_p
                .frequency_hz
                .iter()
                .filter(|f| **f >= lo && **f < hi)
                .count();
            let mut sum = 0.0;
            let mut raw = 0.0;
            let mut dof_m = 0.0;
            let mut ok = true;
            for (p, segs, floor) in &measured {
                match p.band_mean(lo, hi) {
                    Some(v) => {
                        sum += v - floor;
                        raw += v;
                        let bins = p
                            .frequency_hz
                            .iter()
                            .filter(|f| **f >= lo && **f < hi)
                            .count();
                        dof_m += 2.0 * (*segs * bins) as f64;
                    }
                    None => ok = false,
                }
            }
            // Bands where the sensor noise is as strong as the signal measure nothing.
            if !ok || pm <= 0.0 || sum <= 0.5 * raw {
                continue;
            }
            let mean_m = sum / measured.len() as f64;
            // The estimate's relative error is the raw PSD's, scaled by raw / (raw - floor).
            let noise_gain = raw / sum;
            let dof_p = 2.0 * (seg_p * bins_p) as f64;
            let log_ratio = (mean_m / pm).ln();
            // Numerical: the band's log change in the tolerance-halving run.
            let num = psd_h
                .as_ref()
                .and_then(|p| p.band_mean(lo, hi))
                .filter(|h| *h > 0.0)
                .map_or(0.0, |h| (pm / h).ln());
            let sd = (2.0 / dof_m * noise_gain * noise_gain
                + 2.0 / dof_p
                + num * num
                + problem.noise.scale_var)
                .sqrt();
            let z = log_ratio / sd;
            out.push(Group {
                by: "frequency_band".into(),
                label: format!("{} response {:.1} Hz (1/3 octave)", test.id, fc),
                observations: measured.len() as f64,
                mean_residual: 10.0 * log_ratio / std::f64::consts::LN_10,
                z,
                p_value: stats::normal_two_sided(z),
                p_adjusted: 1.0,
                flagged: false,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shared_calibration_error_moves_a_channel_by_its_own_sigmas_not_root_n_times_more() {
        // Eight mean squares of one channel whose uncertainty is all calibration (a = 1), each
        // read two sigmas high: one 2-sigma calibration error, z = 16 / sqrt(8 + 64 - 8) = 2.
        let mut shared = Acc::new();
        let mut independent = Acc::new();
        for _ in 0..8 {
            shared.push(1.0, 2.0, Some((4, 1.0)));
            independent.push(1.0, 2.0, None);
        }
        assert!((shared.z() - 2.0).abs() < 1e-12, "{}", shared.z());
        // Independent residuals add up: 16 / sqrt(8).
        assert!((independent.z() - 16.0 / 8f64.sqrt()).abs() < 1e-12);
        // Two channels are independent of each other: 4 + 4 readings, each channel's sum has
        // variance 4 + 16 - 4 = 16, together 32.
        let mut two = Acc::new();
        for c in [1, 4] {
            for _ in 0..4 {
                two.push(1.0, 1.0, Some((c, 1.0)));
            }
        }
        assert!((two.var() - 32.0).abs() < 1e-12, "{}", two.var());
    }
}
