//! How far apart two candidates' predictions of a proposed test lie under the noise its
//! readings would carry: the expected log-likelihood ratio between them.
//!
//! For two Gaussians of the same covariance `Σ` and means `μ_a`, `μ_b`, the Kullback-Leibler
//! divergence is `½ Δᵀ Σ⁻¹ Δ` with `Δ = μ_a - μ_b`, the same both ways: the log-likelihood
//! ratio a test's readings are expected to give the true candidate over the other. `Σ` is the
//! campaign's noise model (`noise`) evaluated at the two predictions' mean, with two shared
//! scales written as in the diagnosis' likelihood ([`noise::gaussian`]):
//!
//! - **specimen scatter**: a specimen's wear is off by one factor over all its increments and
//!   components, so a test's masses share one scale of variance `s²/n` (`s` the campaign's
//!   relative repeatability of one reading, `n` the repeats): more increments on the same
//!   specimens do not tell a constant factor from scatter, more repeats do. The whole
//!   repeatability is taken as scatter (the conservative reading: it could be part measurement
//!   noise, independent per increment);
//! - **calibration**: a channel's mean squares share one scale of variance `(2 e_cal)²`.
//!
//! The rest is independent per reading, as in the diagnosis: the simulator's numerical and
//! parameter variance (`v_model μ²`), the scale's quantisation `res²/12/n`, and for mean squares
//! the record's repeatability and the sensor noise `(4 μ σ² + 2 σ⁴)/N/n`.

use super::super::noise::{self, Term, CHANNELS};
use super::super::prediction::Prediction;

/// The noise a proposed test's readings would carry (from the campaign's noise model).
#[derive(Debug, Clone, PartialEq)]
pub struct TestNoise {
    /// Relative repeatability of one specimen's mass reading (1 sigma).
    pub mass_rel: f64,
    /// The model's relative variance of a mass (numerical, wear coefficient, friction).
    pub mass_model_rel_var: f64,
    /// Scale resolution, mg.
    pub resolution_mg: f64,
    /// Relative repeatability of one record's mean square.
    pub accel_rel: f64,
    /// The model's relative variance of a mean square per channel (input x, y, z, response
    /// x, y, z).
    pub accel_model_rel_var: [f64; CHANNELS],
    /// Variance of a channel's shared calibration scale, `(2 e_cal)²`.
    pub calibration_var: f64,
    /// Sensor noise, RMS m/s².
    pub sensor_noise_m_s2: f64,
    /// Samples per record.
    pub samples: usize,
}

/// What one proposed test reads: its increments (a prefix of the predictions), its weighed
/// components, its repeats and whether it records input and response accelerations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Readings<'a> {
    /// Increments read.
    pub increments: usize,
    /// Weighed components.
    pub components: &'a [String],
    /// Specimens (repeats).
    pub repeats: usize,
    /// Input and response records on.
    pub accelerometers: bool,
}

/// The expected log-likelihood ratio, nats, between candidates predicting `a` and `b` (per
/// increment) on a test read as `r` (module documentation).
pub fn expected_log_lr(a: &[Prediction], b: &[Prediction], r: Readings, noise: &TestNoise) -> f64 {
    let n = r.repeats.max(1) as f64;
    let increments = r.increments.min(a.len()).min(b.len());
    let weight = 1.0 / r.components.len().max(1) as f64;
    let mut masses = Vec::new();
    let mut accels = Vec::new();
    for k in 0..increments {
        for c in r.components {
            let (ya, yb) = (mass(&a[k], c), mass(&b[k], c));
            let mu = 0.5 * (ya + yb);
            let var = noise.mass_model_rel_var * mu * mu
                + noise.resolution_mg.powi(2) / 12.0 / n
                + (1e-3 * noise.resolution_mg).powi(2);
            masses.push(Term {
                weight,
                residual: ya - yb,
                var,
                predicted: mu,
                channel: Some(0),
            });
        }
        if !r.accelerometers {
            continue;
        }
        let pairs = a[k]
            .input_ms
            .iter()
            .chain(&a[k].response_ms)
            .zip(b[k].input_ms.iter().chain(&b[k].response_ms));
        for (channel, (&ya, &yb)) in pairs.enumerate() {
            let mu = 0.5 * (ya + yb);
            let s2 = noise.sensor_noise_m_s2.powi(2);
            let sensor = (4.0 * mu.max(0.0) * s2 + 2.0 * s2 * s2) / noise.samples.max(1) as f64 / n;
            let var = (noise.accel_rel.powi(2) / n + noise.accel_model_rel_var[channel]) * mu * mu
                + sensor
                + (1e-6 * mu).powi(2).max(1e-30);
            accels.push(Term {
                weight: 1.0,
                residual: ya - yb,
                var,
                predicted: mu,
                channel: Some(channel),
            });
        }
    }
    let scatter = noise::gaussian(masses, noise.mass_rel.powi(2) / n).r2;
    let records = noise::gaussian(accels, noise.calibration_var).r2;
    0.5 * (scatter + records)
}

fn mass(p: &Prediction, component: &str) -> f64 {
    p.mass_mg.get(component).copied().unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(mg: f64) -> Prediction {
        Prediction {
            mass_mg: [("cube".to_string(), mg)].into(),
            input_ms: [1.0, 0.0, 0.0],
            response_ms: [1.0, 0.0, 0.0],
        }
    }

    fn quiet() -> TestNoise {
        TestNoise {
            mass_rel: 0.0,
            mass_model_rel_var: 0.0,
            resolution_mg: 1e-9,
            accel_rel: 0.0,
            accel_model_rel_var: [0.0; CHANNELS],
            calibration_var: 0.0,
            sensor_noise_m_s2: 0.0,
            samples: 1000,
        }
    }

    #[test]
    fn one_reading_separates_by_half_its_squared_standardized_distance() {
        // Independent noise only: 10 % of the mean prediction 1.5 mg, readings 1 and 2 mg apart
        // by 1 mg: ½ (1 / 0.15)² = 22.2 nats.
        let noise = TestNoise {
            mass_model_rel_var: 0.01,
            ..quiet()
        };
        let components = ["cube".to_string()];
        let r = Readings {
            increments: 1,
            components: &components,
            repeats: 1,
            accelerometers: false,
        };
        let got = expected_log_lr(&[cube(1.0)], &[cube(2.0)], r, &noise);
        let want = 0.5 / (0.15f64 * 0.15);
        assert!((got - want).abs() < 1e-6 * want, "{got} vs {want}");
        // Symmetric: the same whichever candidate is true.
        let back = expected_log_lr(&[cube(2.0)], &[cube(1.0)], r, &noise);
        assert!((back - got).abs() < 1e-12);
        // The same predictions separate nothing.
        assert!(expected_log_lr(&[cube(1.0)], &[cube(1.0)], r, &noise).abs() < 1e-12);
    }

    #[test]
    fn a_constant_factor_is_told_from_scatter_by_repeats_not_by_increments() {
        // Candidate a predicts (1 + e) times b in every increment; the only noise is the
        // specimen scatter s on the mean of n specimens (shared by the increments) and an
        // independent variance d per reading. Closed form for K equal readings μ:
        // r2 = e² / (d / (K μ²) + s² / n), so the ratio tends to e² n / s² / 2 however many
        // increments, and grows with the repeats.
        let (e, s, d_rel) = (0.2, 0.3, 0.01);
        let noise = TestNoise {
            mass_rel: s,
            mass_model_rel_var: d_rel,
            ..quiet()
        };
        let components = ["cube".to_string()];
        let a: Vec<Prediction> = (0..50).map(|_| cube(1.0 + e)).collect();
        let b: Vec<Prediction> = (0..50).map(|_| cube(1.0)).collect();
        let mu = 1.0 + 0.5 * e;
        for (increments, repeats) in [(1, 1), (3, 1), (50, 1), (3, 3), (50, 9)] {
            let r = Readings {
                increments,
                components: &components,
                repeats,
                accelerometers: false,
            };
            let got = expected_log_lr(&a, &b, r, &noise);
            let d = d_rel * mu * mu;
            let r2 = (e * e) / (d / (increments as f64 * mu * mu) + s * s / repeats as f64);
            // The residual is e mg against readings of μ mg.
            let want = 0.5 * r2 / (mu * mu);
            assert!(
                (got - want).abs() < 1e-6 * want,
                "K {increments} n {repeats}: {got} vs {want}"
            );
        }
        let r = |increments, repeats| Readings {
            increments,
            components: &components,
            repeats,
            accelerometers: false,
        };
        let limit = 0.5 * e * e / (s * s) / (mu * mu);
        assert!(expected_log_lr(&a, &b, r(50, 1), &noise) < limit);
        assert!(expected_log_lr(&a, &b, r(50, 9), &noise) > 8.0 * limit);
    }

    #[test]
    fn records_add_what_the_masses_cannot_show() {
        // Equal masses, response mean squares 1 and 4 (m/s²)²: only the records separate, by
        // ½ Δ² / σ² with the sensor's variance of a mean square (4 μ σ² + 2 σ⁴) / N.
        let noise = TestNoise {
            sensor_noise_m_s2: 0.5,
            samples: 100,
            ..quiet()
        };
        let components = ["cube".to_string()];
        let mut a = cube(1.0);
        let mut b = cube(1.0);
        a.response_ms = [0.0, 1.0, 0.0];
        b.response_ms = [0.0, 4.0, 0.0];
        let r = |accelerometers| Readings {
            increments: 1,
            components: &components,
            repeats: 1,
            accelerometers,
        };
        assert!(expected_log_lr(&[a.clone()], &[b.clone()], r(false), &noise) < 1e-9);
        let got = expected_log_lr(&[a], &[b], r(true), &noise);
        let (mu, s2) = (2.5, 0.25);
        let var = (4.0 * mu * s2 + 2.0 * s2 * s2) / 100.0 + (1e-6 * mu * 1e-6 * mu);
        let want = 0.5 * 9.0 / var;
        assert!((got - want).abs() < 1e-6 * want, "{got} vs {want}");
    }
}
