//! Observations of a campaign and the uncertainty of each about a prediction.
//!
//! `u² = (s²/n + v_model) μ² + v_fixed + v_floor`, where
//! - `s` is the relative repeatability of one specimen's reading (specimen scatter and
//!   measurement noise together), pooled over every group of repeats; without repeats an
//!   assumed value (stated in the report);
//! - `n` is the number of specimens averaged;
//! - `v_model` is the model's relative variance: numerical (the pooled relative differences of
//!   the tolerance-halving and initial-state runs, squared) plus parameters (the wear coefficient's relative
//!   uncertainty for masses; the friction sensitivity run's relative change for both; twice
//!   the accelerometer calibration uncertainty for mean squares);
//! - `v_fixed` is the reading's own absolute variance: the scale's quantisation `res²/12`, or the
//!   variance of a mean square estimated from `N` samples with sensor noise `σ`
//!   (`(4 m σ² + 2 σ⁴) / N`);
//! - `v_floor` keeps `u > 0` where a prediction and its reading are both exactly 0.

use super::emulator::{mean_square, Emulator, TestPredictions};
use super::DiagnoseOptions;
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

/// The model's relative variance of one observation (docs/diagnosis.md, "Uncertainty"): the
/// numerical spread squared, plus the friction sensitivity squared, plus for masses the wear
/// coefficient's relative uncertainty squared, for mean squares twice the accelerometer
/// calibration uncertainty squared (a sensitivity off by a factor 1 + e scales a mean square by
/// (1 + e)^2, about 1 + 2e).
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
        Quantity::Accel(..) => {
            numerical + friction + (2.0 * options.accelerometer_calibration_rel).powi(2)
        }
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

    /// Standard uncertainty of observation `o` about the prediction `mu`.
    pub fn u(&self, o: &Observation, mu: f64) -> f64 {
        let s = if o.quantity.is_mass() {
            self.mass_rel
        } else {
            self.accel_rel
        };
        let rel = s * s / o.specimens as f64 + o.model_rel_var;
        (rel * mu * mu + o.fixed_var + o.floor_var).sqrt()
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
    fn mean_squares_carry_twice_the_calibration_uncertainty_masses_the_wear_coefficient() {
        let options = DiagnoseOptions::default();
        let accel = Quantity::Accel(AccelLocation::Response, 1);
        let mass = Quantity::Mass("cube".into());
        // Nothing but the calibration: a 2 % sensitivity is a 4 % mean square, variance 0.0016.
        assert!((model_rel_var(&accel, 0.0, 0.0, &options) - 0.0016).abs() < 1e-15);
        // The wear coefficient's 10 % (an estimate, Table 4.3 has none) enters masses only.
        assert!((model_rel_var(&mass, 0.0, 0.0, &options) - 0.01).abs() < 1e-15);
        // Independent terms add in variance: 3-4-5.
        let five = model_rel_var(
            &accel,
            0.03,
            0.0,
            &DiagnoseOptions {
                accelerometer_calibration_rel: 0.02,
                ..options.clone()
            },
        );
        assert!((five - 0.0025).abs() < 1e-15, "{five}");
    }
}
