//! Observations of a campaign and the uncertainty of each about a prediction.
//!
//! Each observation has an independent variance
//! `u² = (s²/n + v_model) μ² + v_fixed + v_floor`, where
//! - `s` is the relative repeatability of one specimen's reading (specimen scatter and
//!   measurement noise together), pooled over every group of repeats; without repeats an
//!   assumed value (stated in the report);
//! - `n` is the number of specimens averaged;
//! - `v_model` is the model's relative variance: numerical (the pooled relative differences of
//!   the tolerance-halving and initial-state runs, squared) plus parameters (the wear
//!   coefficient's relative uncertainty for masses; the friction sensitivity run's relative
//!   change for both);
//! - `v_fixed` is the reading's own absolute variance: the scale's quantisation `res²/12`, or the
//!   variance of a mean square estimated from `N` samples with sensor noise `σ`
//!   (`(4 m σ² + 2 σ⁴) / N`);
//! - `v_floor` keeps `u > 0` where a prediction and its reading are both exactly 0.
//!
//! **Calibration is shared, not independent.** An accelerometer whose sensitivity is off by a
//! factor `1 + e` scales every mean square it records by `(1 + e)² ≈ 1 + 2e`. The campaign's
//! mean squares of one location and axis (a *channel*) therefore share one unknown scale
//! `c ~ N(1, (2 e_cal)²)`: the readings of a channel are `y = c μ + ε`, and with `c`
//! integrated out their covariance is `D + (2 e_cal)² μ μᵀ` (`D` the independent variances
//! above). [`gaussian`] evaluates that likelihood exactly with the Sherman-Morrison identity;
//! held out, a test's readings are judged conditional on the training tests' (their joint
//! likelihood less the training tests' alone), so the scale the training tests show is used and
//! only what changes between tests counts as a gap. A single reading's marginal uncertainty
//! ([`NoiseModel::u_marginal`]) is `sqrt(u² + (2 e_cal μ)²)`.

use super::emulator::{mean_square, Emulator, TestPredictions};
use super::options::DiagnoseOptions;
use crate::gap::accel::AccelLocation;
use crate::gap::Campaign;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// What an observation measures.
#[derive(Debug, Clone, PartialEq)]
pub enum Quantity {
    /// Mass loss of a weighed component, mg.
    Mass(String),
    /// Mean-square acceleration at a location along an axis (0 x, 1 y, 2 z), m²/s⁴.
    Accel(AccelLocation, usize),
}

impl Quantity {
    /// Label, e.g. `mass cube` or `response y`.
    pub fn label(&self) -> String {
        match self {
            Self::Mass(c) => format!("mass {c}"),
            Self::Accel(l, a) => format!("{} {}", l.as_str(), ["x", "y", "z"][*a]),
        }
    }

    fn is_mass(&self) -> bool {
        matches!(self, Self::Mass(_))
    }

    /// Calibration channel of a mean square (0..[`CHANNELS`]: location and axis); None for a
    /// mass.
    pub fn channel(&self) -> Option<usize> {
        match self {
            Self::Mass(_) => None,
            Self::Accel(AccelLocation::Input, a) => Some(*a),
            Self::Accel(AccelLocation::Response, a) => Some(3 + *a),
        }
    }
}

/// Calibration channels: two locations times three axes.
pub const CHANNELS: usize = 6;

/// One observation's term of the Gaussian likelihood.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Term {
    /// Weight (composite likelihood; 1 for mean squares).
    pub weight: f64,
    /// Residual `y - μ`.
    pub residual: f64,
    /// Independent variance `u²`.
    pub var: f64,
    /// Prediction `μ` (the shared scale acts on it).
    pub predicted: f64,
    /// Calibration channel (None: no shared scale).
    pub channel: Option<usize>,
}

/// Totals of a Gaussian likelihood.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Totals {
    /// Negative log-likelihood (the constant `n/2 ln 2π` left out).
    pub nll: f64,
    /// Squared Mahalanobis distance of the residuals (a chi-square with `w` degrees of freedom
    /// when the model holds).
    pub r2: f64,
    /// Weighted observation count.
    pub w: f64,
}

impl std::ops::Sub for Totals {
    type Output = Totals;
    fn sub(self, o: Totals) -> Totals {
        Totals {
            nll: self.nll - o.nll,
            r2: (self.r2 - o.r2).max(0.0),
            w: self.w - o.w,
        }
    }
}

/// Negative log-likelihood and Mahalanobis distance of `terms`: independent Gaussians, except
/// that the terms of one channel share a scale of variance `scale_var` on their predictions
/// (covariance `D + scale_var μ μᵀ` per channel). Sherman-Morrison: with `a = Σ μ²/d` and
/// `b = Σ μ r/d` over a channel, the quadratic form loses `scale_var b² / (1 + scale_var a)`
/// and the log-determinant gains `ln(1 + scale_var a)`.
pub fn gaussian(terms: impl IntoIterator<Item = Term>, scale_var: f64) -> Totals {
    let mut t = Totals::default();
    let mut a = [0.0; CHANNELS];
    let mut b = [0.0; CHANNELS];
    for x in terms {
        let q = x.weight * x.residual * x.residual / x.var;
        t.nll += 0.5 * q + 0.5 * x.weight * x.var.ln();
        t.r2 += q;
        t.w += x.weight;
        if let Some(c) = x.channel {
            a[c] += x.weight * x.predicted * x.predicted / x.var;
            b[c] += x.weight * x.predicted * x.residual / x.var;
        }
    }
    if scale_var > 0.0 {
        for c in 0..CHANNELS {
            let den = 1.0 + scale_var * a[c];
            let drop = scale_var * b[c] * b[c] / den;
            t.nll += -0.5 * drop + 0.5 * den.ln();
            t.r2 -= drop;
        }
    }
    t
}

/// One observation: a mean over the specimens of a test at one increment.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    /// Test index.
    pub test: usize,
    /// Increment index (0-based).
    pub increment: usize,
    /// Quantity.
    pub quantity: Quantity,
    /// Mean reading.
    pub value: f64,
    /// Specimens averaged.
    pub specimens: usize,
    /// Sample variance of the specimens' readings (None with one specimen).
    pub spread: Option<f64>,
    /// Weight in the likelihood (1 / weighed components for masses, 1 otherwise).
    pub weight: f64,
    /// Absolute variance of the mean reading (quantisation, sensor noise).
    pub fixed_var: f64,
    /// Floor variance.
    pub floor_var: f64,
    /// Relative variance of the model (numerical + parameters), set by the noise model.
    pub model_rel_var: f64,
}

impl Observation {
    /// The prediction of this observation.
    pub fn predicted(&self, p: &TestPredictions) -> f64 {
        let Some(pred) = p.get(self.test).and_then(|t| t.get(self.increment)) else {
            return f64::NAN;
        };
        match &self.quantity {
            Quantity::Mass(c) => pred.mass_mg.get(c).copied().unwrap_or(0.0),
            Quantity::Accel(AccelLocation::Input, a) => pred.input_ms[*a],
            Quantity::Accel(AccelLocation::Response, a) => pred.response_ms[*a],
        }
    }
}

/// The campaign's observations, in test, increment, quantity order.
pub fn observations(campaign: &Campaign) -> Vec<Observation> {
    let mut out = Vec::new();
    for (ti, test) in campaign.tests.iter().enumerate() {
        let n_inc = test
            .specimens
            .iter()
            .map(|s| s.increments.len())
            .max()
            .unwrap_or(0);
        let weighed = test.components.len().max(1) as f64;
        let res = test.scale_resolution_mg;
        for k in 0..n_inc {
            for c in &test.components {
                let values: Vec<f64> = test
                    .specimens
                    .iter()
                    .filter_map(|s| s.increments.get(k))
                    .filter_map(|inc| inc.mass_loss_mg.get(c).copied())
                    .collect();
                if let Some(o) = mean_obs(ti, k, Quantity::Mass(c.clone()), &values) {
                    let n = o.specimens as f64;
                    out.push(Observation {
                        weight: 1.0 / weighed,
                        fixed_var: res * res / 12.0 / n,
                        floor_var: (1e-3 * res).powi(2),
                        ..o
                    });
                }
            }
            for location in [AccelLocation::Input, AccelLocation::Response] {
                let records: Vec<_> = test
                    .specimens
                    .iter()
                    .flat_map(|s| s.accelerometers.iter())
                    .filter(|r| r.increment == k + 1 && r.location == location)
                    .collect();
                if records.is_empty() {
                    continue;
                }
                // Each record's mean squares (mean removed), once: (per axis, samples, σ²).
                let stats: Vec<([f64; 3], usize, f64)> = records
                    .iter()
                    .map(|r| {
                        let xyz: Vec<[f64; 3]> =
                            r.samples.iter().map(|s| [s[1], s[2], s[3]]).collect();
                        (mean_square(&xyz), xyz.len(), r.sensor_noise_m_s2.powi(2))
                    })
                    .collect();
                let scale = stats
                    .iter()
                    .flat_map(|(ms, _, _)| ms.iter().copied())
                    .fold(0.0, f64::max);
                for axis in 0..3 {
                    let mut values = Vec::new();
                    let mut fixed = 0.0;
                    for (ms, len, s2) in &stats {
                        let m = (ms[axis] - s2).max(0.0);
                        values.push(ms[axis] - s2);
                        fixed += (4.0 * m * s2 + 2.0 * s2 * s2) / (*len).max(1) as f64;
                    }
                    if let Some(o) = mean_obs(ti, k, Quantity::Accel(location, axis), &values) {
                        let n = o.specimens as f64;
                        out.push(Observation {
                            fixed_var: fixed / (n * n),
                            floor_var: (1e-6 * scale).powi(2).max(1e-30),
                            ..o
                        });
                    }
                }
            }
        }
    }
    out
}

fn mean_obs(
    test: usize,
    increment: usize,
    quantity: Quantity,
    values: &[f64],
) -> Option<Observation> {
    if values.is_empty() {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let spread = (values.len() >= 2)
        .then(|| values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0));
    Some(Observation {
        test,
        increment,
        quantity,
        value: mean,
        specimens: values.len(),
        spread,
        weight: 1.0,
        fixed_var: 0.0,
        floor_var: 0.0,
        model_rel_var: 0.0,
    })
}

/// The uncertainty model of one campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseModel {
    /// Relative repeatability of one specimen's mass reading.
    pub mass_rel: f64,
    /// Relative repeatability of one record's mean square.
    pub accel_rel: f64,
    /// Variance of a channel's shared mean-square scale, `(2 e_cal)²`.
    pub scale_var: f64,
    report: NoiseReport,
}

/// The uncertainty model, as reported.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseReport {
    /// Relative repeatability of one specimen's mass reading (scatter and noise), 1 sigma.
    pub mass_repeatability_rel: f64,
    /// Where it comes from: `repeats (N groups)` or `assumed (no repeats)`.
    pub mass_repeatability_source: String,
    /// Relative repeatability of one record's mean-square acceleration.
    pub accel_repeatability_rel: f64,
    /// Numerical relative uncertainty of masses (tolerance halving and initial state, pooled
    /// RMS).
    pub numerical_mass_rel: f64,
    /// Numerical relative uncertainty of mean squares by quantity (tolerance halving).
    pub numerical_accel_rel: BTreeMap<String, f64>,
    /// Relative uncertainty of the wear coefficient K.
    pub k_rel_uncertainty: f64,
    /// Relative calibration uncertainty of the accelerometers' sensitivity.
    pub accelerometer_calibration_rel: f64,
    /// Friction step of the sensitivity run (mu_s and mu_d).
    pub friction_step: f64,
    /// RMS relative change of masses in the friction sensitivity run.
    pub friction_mass_rel: f64,
}

/// The model's independent relative variance of one observation (docs/results/diagnosis.md,
/// "Uncertainty"): the numerical spread squared, plus the friction sensitivity squared, plus for
/// masses the wear coefficient's relative uncertainty squared. The accelerometer calibration is
/// not here: it is one scale per channel ([`gaussian`]).
fn model_rel_var(
    quantity: &Quantity,
    numerical_rel: f64,
    friction_rel: f64,
    options: &DiagnoseOptions,
) -> f64 {
    let numerical = numerical_rel.powi(2);
    let friction = friction_rel * friction_rel;
    match quantity {
        Quantity::Mass(_) => numerical + options.k_rel_uncertainty.powi(2) + friction,
        Quantity::Accel(..) => numerical + friction,
    }
}

fn rel_diff(a: f64, b: f64) -> Option<f64> {
    let m = a.abs().max(b.abs());
    (m > 0.0).then(|| (a - b).abs() / m)
}

fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        0.0
    } else {
        (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
    }
}

impl NoiseModel {
    /// Estimates the model from the repeats and the emulator's halving and sensitivity runs,
    /// and sets each observation's model variance.
    pub fn estimate(
        campaign: &Campaign,
        obs: &mut [Observation],
        emulator: &Emulator,
        options: &DiagnoseOptions,
    ) -> Self {
        // Repeatability: pooled relative variance of groups of repeats, quantisation or sensor
        // variance removed, groups whose mean is too small to tell skipped.
        let pooled = |is_mass: bool| -> Option<(f64, usize)> {
            let mut sum = 0.0;
            let mut dof = 0usize;
            let mut groups = 0usize;
            for o in obs.iter().filter(|o| o.quantity.is_mass() == is_mass) {
                let Some(s2) = o.spread else { continue };
                let n = o.specimens as f64;
                let per_reading_fixed = o.fixed_var * n;
                if o.value.abs() <= 0.0 || o.value * o.value < 400.0 * per_reading_fixed {
                    continue;
                }
                let rel = ((s2 - per_reading_fixed) / (o.value * o.value)).max(0.0);
                sum += rel * (o.specimens - 1) as f64;
                dof += o.specimens - 1;
                groups += 1;
            }
            (dof > 0).then(|| ((sum / dof as f64).sqrt(), groups))
        };
        let (mass_rel, source) = match pooled(true) {
            Some((s, g)) => (s, format!("repeats ({g} groups)")),
            None => (
                options.assumed_scatter_rel,
                "assumed (no repeats to estimate it from)".to_string(),
            ),
        };
        let accel_rel = pooled(false).map_or(0.0, |(s, _)| s);

        // Numerical: tolerance halving; parameters: friction step and K.
        let mut num_mass = Vec::new();
        let mut fr_mass = Vec::new();
        let mut num_accel: BTreeMap<String, Vec<f64>> = BTreeMap::new();
        for (ti, t) in emulator.nominal.iter().enumerate() {
            for (k, p) in t.iter().enumerate() {
                let f = &emulator.friction_step[ti][k];
                for c in &campaign.tests[ti].components {
                    let a = p.mass_mg.get(c).copied().unwrap_or(0.0);
                    fr_mass.extend(rel_diff(a, f.mass_mg.get(c).copied().unwrap_or(0.0)));
                }
                for h in [&emulator.halving[ti][k], &emulator.initial_state[ti][k]] {
                    for c in &campaign.tests[ti].components {
                        let a = p.mass_mg.get(c).copied().unwrap_or(0.0);
                        num_mass.extend(rel_diff(a, h.mass_mg.get(c).copied().unwrap_or(0.0)));
                    }
                    for axis in 0..3 {
                        for (loc, x, y) in [
                            (AccelLocation::Input, p.input_ms[axis], h.input_ms[axis]),
                            (
                                AccelLocation::Response,
                                p.response_ms[axis],
                                h.response_ms[axis],
                            ),
                        ] {
                            if let Some(d) = rel_diff(x, y) {
                                num_accel
                                    .entry(Quantity::Accel(loc, axis).label())
                                    .or_default()
                                    .push(d);
                            }
                        }
                    }
                }
            }
        }
        let numerical_mass_rel = rms(&num_mass);
        let numerical_accel_rel: BTreeMap<String, f64> =
            num_accel.iter().map(|(k, v)| (k.clone(), rms(v))).collect();
        let friction_mass_rel = rms(&fr_mass);
        for o in obs.iter_mut() {
            let nominal = o.predicted(&emulator.nominal);
            let fr = rel_diff(nominal, o.predicted(&emulator.friction_step)).unwrap_or(0.0);
            let numerical = match &o.quantity {
                Quantity::Mass(_) => numerical_mass_rel,
                q => numerical_accel_rel.get(&q.label()).copied().unwrap_or(0.0),
            };
            o.model_rel_var = model_rel_var(&o.quantity, numerical, fr, options);
        }
        Self {
            mass_rel,
            accel_rel,
            scale_var: (2.0 * options.accelerometer_calibration_rel).powi(2),
            report: NoiseReport {
                mass_repeatability_rel: mass_rel,
                mass_repeatability_source: source,
                accel_repeatability_rel: accel_rel,
                numerical_mass_rel,
                numerical_accel_rel,
                k_rel_uncertainty: options.k_rel_uncertainty,
                accelerometer_calibration_rel: options.accelerometer_calibration_rel,
                friction_step: super::emulator::FRICTION_STEP,
                friction_mass_rel,
            },
        }
    }

    /// Independent standard uncertainty of observation `o` about the prediction `mu` (the
    /// channel's shared calibration scale not included).
    pub fn u(&self, o: &Observation, mu: f64) -> f64 {
        let s = if o.quantity.is_mass() {
            self.mass_rel
        } else {
            self.accel_rel
        };
        let rel = s * s / o.specimens as f64 + o.model_rel_var;
        (rel * mu * mu + o.fixed_var + o.floor_var).sqrt()
    }

    /// Marginal standard uncertainty of `o` read alone: [`Self::u`] with the calibration.
    pub fn u_marginal(&self, o: &Observation, mu: f64) -> f64 {
        let cal = if o.quantity.channel().is_some() {
            self.scale_var * mu * mu
        } else {
            0.0
        };
        (self.u(o, mu).powi(2) + cal).sqrt()
    }

    /// The likelihood term of `o` about the prediction `mu`, with `extra_rel_var` added to its
    /// independent relative variance.
    pub fn term(&self, o: &Observation, mu: f64, extra_rel_var: f64) -> Term {
        Term {
            weight: o.weight,
            residual: o.value - mu,
            var: self.u(o, mu).powi(2) + extra_rel_var * mu * mu,
            predicted: mu,
            channel: o.quantity.channel(),
        }
    }

    /// As reported.
    pub fn report(&self) -> NoiseReport {
        self.report.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn independent_variances_add_calibration_is_left_to_the_channel_scale() {
        let options = DiagnoseOptions::default();
        let accel = Quantity::Accel(AccelLocation::Response, 1);
        let mass = Quantity::Mass("cube".into());
        // The calibration is not an independent variance any more: nothing else, nothing.
        assert_eq!(model_rel_var(&accel, 0.0, 0.0, &options), 0.0);
        // The wear coefficient's 10 % (an estimate, Table 4.3 has none) enters masses only.
        assert!((model_rel_var(&mass, 0.0, 0.0, &options) - 0.01).abs() < 1e-15);
        // Independent terms add in variance: 3-4-5.
        let five = model_rel_var(&accel, 0.03, 0.04, &options);
        assert!((five - 0.0025).abs() < 1e-15, "{five}");
        assert_eq!(mass.channel(), None);
        assert_eq!(Quantity::Accel(AccelLocation::Input, 2).channel(), Some(2));
        assert_eq!(accel.channel(), Some(4));
    }

    fn terms() -> Vec<Term> {
        // Two readings on channel 1, three on channel 4, one mass of weight 1/2.
        let raw = [
            (1.0, 0.3, 0.04, 2.0, Some(1)),
            (1.0, -0.1, 0.09, 1.5, Some(1)),
            (1.0, 0.5, 0.25, 4.0, Some(4)),
            (1.0, 0.2, 0.16, 3.0, Some(4)),
            (1.0, 0.6, 0.36, 5.0, Some(4)),
            (0.5, 0.7, 0.49, 9.0, None),
        ];
        raw.iter()
            .map(|&(weight, residual, var, predicted, channel)| Term {
                weight,
                residual,
                var,
                predicted,
                channel,
            })
            .collect()
    }

    /// The same likelihood written densely: covariance `D + s μμᵀ` within each channel.
    fn dense(terms: &[Term], s: f64) -> (f64, f64) {
        let n = terms.len();
        let cov = nalgebra::DMatrix::from_fn(n, n, |i, j| {
            let (a, b) = (terms[i], terms[j]);
            let shared = match (a.channel, b.channel) {
                (Some(x), Some(y)) if x == y => s * a.predicted * b.predicted,
                _ => 0.0,
            };
            shared + if i == j { a.var } else { 0.0 }
        });
        // A weight scales a term's information; the one weighted term is alone (no channel,
        // last), so its Cholesky diagonal is its own standard deviation.
        let r = nalgebra::DVector::from_fn(n, |i, _| terms[i].residual * terms[i].weight.sqrt());
        let inv = cov.clone().try_inverse().expect("positive definite");
        let q = (r.transpose() * &inv * &r)[(0, 0)];
        let logdet: f64 = cov
            .cholesky()
            .expect("positive definite")
            .l()
            .diagonal()
            .iter()
            .zip(terms)
            .map(|(d, t)| 2.0 * d.ln() * t.weight)
            .sum();
        (0.5 * q + 0.5 * logdet, q)
    }

    #[test]
    fn the_shared_scale_likelihood_is_the_dense_gaussian() {
        let t = terms();
        for s in [0.0, 0.0016, 0.05, 3.0] {
            let got = gaussian(t.iter().copied(), s);
            let (nll, q) = dense(&t, s);
            assert!((got.nll - nll).abs() < 1e-12, "s {s}: {} vs {nll}", got.nll);
            assert!((got.r2 - q).abs() < 1e-12, "s {s}: {} vs {q}", got.r2);
            assert!((got.w - 5.5).abs() < 1e-15);
        }
    }

    #[test]
    fn a_vague_scale_removes_the_best_fitting_scale_of_each_channel() {
        // Readings exactly 1.08 times the prediction: the residuals are all scale, and a
        // scale with a vague prior leaves nothing of them (least squares through the origin).
        let t: Vec<Term> = [2.0, 3.0, 5.0]
            .iter()
            .map(|&mu: &f64| Term {
                weight: 1.0,
                residual: 0.08 * mu,
                var: 0.01 * mu * mu,
                predicted: mu,
                channel: Some(0),
            })
            .collect();
        let independent = gaussian(t.iter().copied(), 0.0).r2;
        // Independent: three readings, each 0.8 sigma off (8 % against 10 %).
        assert!((independent - 3.0 * 0.64).abs() < 1e-9, "{independent}");
        assert!(gaussian(t.iter().copied(), 1e9).r2 < 1e-6);
        // A 4 % prior on an 8 % offset: the offset is 2 prior sigmas, and with the readings'
        // own 10 % per reading (3 readings: 5.8 % on their mean) the Mahalanobis distance is
        // 0.08² / (0.0016 + 0.01 / 3) = 1.30, closed form.
        let q = gaussian(t.iter().copied(), 0.0016).r2;
        let expected = 0.0064 / (0.0016 + 0.01 / 3.0);
        assert!((q - expected).abs() < 1e-9, "{q} vs {expected}");
    }

    #[test]
    fn held_out_readings_are_judged_given_the_training_readings() {
        // The chain rule: the joint likelihood less the training one is the conditional
        // Gaussian of the held-out readings, written densely.
        let t = terms();
        let s = 0.05;
        let (train, held): (Vec<Term>, Vec<Term>) = (
            t[..2].iter().chain(&t[3..5]).copied().collect(),
            vec![t[2], t[5]],
        );
        let all: Vec<Term> = train.iter().chain(&held).copied().collect();
        let cond = gaussian(all.iter().copied(), s) - gaussian(train.iter().copied(), s);
        // Dense conditional of the channel-4 reading t[2] given the channel-4 training readings.
        let ch: Vec<Term> = vec![t[3], t[4]];
        let cov_tt = nalgebra::DMatrix::from_fn(2, 2, |i, j| {
            s * ch[i].predicted * ch[j].predicted + if i == j { ch[i].var } else { 0.0 }
        });
        let cov_ht = nalgebra::DVector::from_fn(2, |i, _| s * t[2].predicted * ch[i].predicted);
        let r_t = nalgebra::DVector::from_fn(2, |i, _| ch[i].residual);
        let inv = cov_tt.try_inverse().expect("positive definite");
        let mean = (cov_ht.transpose() * &inv * &r_t)[(0, 0)];
        let var =
            t[2].var + s * t[2].predicted.powi(2) - (cov_ht.transpose() * &inv * &cov_ht)[(0, 0)];
        let q2 = (t[2].residual - mean).powi(2) / var;
        // The mass is independent of everything: its own term, weighted.
        let q5 = t[5].weight * t[5].residual.powi(2) / t[5].var;
        assert!(
            (cond.r2 - (q2 + q5)).abs() < 1e-12,
            "{} vs {}",
            cond.r2,
            q2 + q5
        );
        let nll = 0.5 * q2 + 0.5 * var.ln() + 0.5 * q5 + 0.5 * t[5].weight * t[5].var.ln();
        assert!((cond.nll - nll).abs() < 1e-12, "{} vs {nll}", cond.nll);
    }
}
