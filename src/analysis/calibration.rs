//! Calibration of the friction law and of the wear law K(sigma) from persistent-contact fixture
//! records (thesis chapter 4): eq. 4.1-4.4 for friction, eq. 4.16-4.18 for wear.

use crate::field_error::FieldError;
use crate::physics::friction::FrictionParams;
use crate::physics::step::StepKind;
use crate::wear::WearLaw;
use nalgebra::{Matrix4, Vector4};
use serde::{Deserialize, Serialize};

/// Errors of the calibration fits: each names the field (a path such as `records[3].time_s`
/// for a record's field, relative to the function's arguments) and the rule.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    /// An input value broke a rule.
    #[error(transparent)]
    Invalid(#[from] FieldError),
    /// The fit could not be carried out.
    #[error("fit failed: {0}")]
    Fit(&'static str),
}

impl CalibrationError {
    /// As a field error placed under `prefix` (the path of the fit's data, e.g. `friction`):
    /// a broken rule keeps its field (`friction.records[3].time_s`), a failed fit names
    /// `prefix` itself.
    pub fn at(self, prefix: &str) -> FieldError {
        match self {
            CalibrationError::Invalid(e) => e.at(prefix),
            fit @ CalibrationError::Fit(_) => FieldError::new(prefix, fit.to_string()),
        }
    }
}

/// `records[index].field`: the path of a field of the record at `index`.
fn record_field(index: usize, field: &str) -> String {
    format!("records[{index}].{field}")
}

/// One row of a friction test record (thesis 4.3.1: angle, angular velocity, vertical force,
/// torque and time).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TorqueRecord {
    /// Time, s.
    pub time_s: f64,
    /// Fixture angle theta, rad.
    pub angle_rad: f64,
    /// Angular velocity theta-dot, rad/s.
    pub angular_velocity_rad_s: f64,
    /// Normal load on the three pads together, N (eq. 4.2 uses it per pad: F_fric = N mu).
    pub normal_load_n: f64,
    /// Input torque T_in, N·m (eq. 4.1).
    pub input_torque_n_m: f64,
}

/// The rotating fixture (thesis 4.3): inertia and pad radius.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Fixture {
    /// Polar moment of inertia J of the rotating part, kg·m² (eq. 4.1).
    pub polar_inertia_kg_m2: f64,
    /// Radius r_avg from the axis to the pad centroids, m (eq. 4.1, 4.4).
    pub mean_radius_m: f64,
}

/// One instantaneous friction estimate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FrictionSample {
    /// Slip speed |theta-dot| r_avg, m/s (eq. 4.4).
    pub slip_speed_m_s: f64,
    /// mu (eq. 4.3), signed so that it opposes slip: mu(|v|) for the law's magnitude.
    pub coefficient: f64,
}

/// Eq. 4.3-4.4 on every record: `mu = (T_in - J theta-ddot) / (3 r_avg N)` at
/// `v = |theta-dot| r_avg`, with theta-ddot from central differences of theta-dot
/// (one-sided at the ends). The sign of theta-dot is folded in so mu is a magnitude.
pub fn friction_samples(
    records: &[TorqueRecord],
    fixture: &Fixture,
) -> Result<Vec<FrictionSample>, CalibrationError> {
    let j = fixture.polar_inertia_kg_m2;
    let r = fixture.mean_radius_m;
    if !(j.is_finite() && j >= 0.0) {
        return Err(FieldError::new(
            "fixture.polar_inertia_kg_m2",
            "must be a finite number >= 0",
        )
        .into());
    }
    if !(r.is_finite() && r > 0.0) {
        return Err(FieldError::new("fixture.mean_radius_m", "must be a finite number > 0").into());
    }
    if records.len() < 3 {
        return Err(FieldError::new("records", "need at least 3 torque records").into());
    }
    for (i, rec) in records.iter().enumerate() {
        if !rec.time_s.is_finite() || (i > 0 && rec.time_s <= records[i - 1].time_s) {
            return Err(FieldError::new(
                record_field(i, "time_s"),
                "must be finite and strictly increasing",
            )
            .into());
        }
        if !rec.angular_velocity_rad_s.is_finite() {
            return Err(FieldError::new(
                record_field(i, "angular_velocity_rad_s"),
                "must be finite",
            )
            .into());
        }
        if !(rec.normal_load_n.is_finite() && rec.normal_load_n > 0.0) {
            return Err(FieldError::new(
                record_field(i, "normal_load_n"),
                "must be a finite number > 0",
            )
            .into());
        }
        if !rec.input_torque_n_m.is_finite() {
            return Err(
                FieldError::new(record_field(i, "input_torque_n_m"), "must be finite").into(),
            );
        }
    }
    let n = records.len();
    let accel = |i: usize| -> f64 {
        let (a, b) = if i == 0 {
            (0, 1)
        } else if i == n - 1 {
            (n - 2, n - 1)
        } else {
            (i - 1, i + 1)
        };
        (records[b].angular_velocity_rad_s - records[a].angular_velocity_rad_s)
            / (records[b].time_s - records[a].time_s)
    };
    Ok(records
        .iter()
        .enumerate()
        .map(|(i, rec)| {
            let mu = (rec.input_torque_n_m - j * accel(i)) / (3.0 * r * rec.normal_load_n);
            let sign = if rec.angular_velocity_rad_s < 0.0 {
                -1.0
            } else {
                1.0
            };
            FrictionSample {
                slip_speed_m_s: rec.angular_velocity_rad_s.abs() * r,
                coefficient: sign * mu,
            }
        })
        .collect())
}

/// Result of the friction fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FrictionFit {
    /// Fitted eq. 4.5 parameters (SI speeds).
    pub params: FrictionParams,
    /// RMS of mu residuals.
    pub rms_residual: f64,
    /// Levenberg-Marquardt iterations used.
    pub iterations: usize,
}

/// Parameter vector used by the fit: (mu_s, mu_d, ln v_s, ln(v_d - v_s)) keeps 0 < v_s < v_d.
fn unpack(p: &Vector4<f64>, step: StepKind) -> FrictionParams {
    let vs = p[2].exp();
    FrictionParams {
        mu_static: p[0],
        mu_dynamic: p[1],
        stiction_transition_speed: vs,
        friction_transition_speed: vs + p[3].exp(),
        step,
    }
}

fn friction_cost(samples: &[FrictionSample], f: &FrictionParams) -> f64 {
    samples
        .iter()
        .map(|s| (f.coefficient(s.slip_speed_m_s) - s.coefficient).powi(2))
        .sum()
}

/// Starting point from the data: mu_d = median mu of the fastest quarter, mu_s and v_s from
/// the speed bin with the largest median mu, v_d = 2 v_s.
fn friction_initial_guess(samples: &[FrictionSample]) -> Option<Vector4<f64>> {
    let mut sorted: Vec<FrictionSample> = samples.to_vec();
    sorted.sort_by(|a, b| a.slip_speed_m_s.total_cmp(&b.slip_speed_m_s));
    let median = |xs: &mut Vec<f64>| -> f64 {
        xs.sort_by(f64::total_cmp);
        xs[xs.len() / 2]
    };
    let n = sorted.len();
    let mut fast: Vec<f64> = sorted[3 * n / 4..].iter().map(|s| s.coefficient).collect();
    let mu_d = median(&mut fast);
    let bins = 40.min(n / 5).max(1);
    let (mut best_mu, mut best_v) = (f64::NEG_INFINITY, 0.0);
    for b in 0..bins {
        let chunk = &sorted[b * n / bins..(b + 1) * n / bins];
        if chunk.is_empty() {
            continue;
        }
        let mut mus: Vec<f64> = chunk.iter().map(|s| s.coefficient).collect();
        let m = median(&mut mus);
        if m > best_mu {
            best_mu = m;
            best_v = chunk[chunk.len() / 2].slip_speed_m_s;
        }
    }
    let vs = best_v.max(1e-6);
    Some(Vector4::new(best_mu, mu_d, vs.ln(), vs.ln()))
}

/// Fits mu_s, mu_d, v_s, v_d of [`FrictionParams::coefficient`] (eq. 4.5) to friction samples
/// by Levenberg-Marquardt with a central-difference Jacobian. `step` is the smooth step used.
pub fn fit_friction(
    samples: &[FrictionSample],
    step: StepKind,
) -> Result<FrictionFit, CalibrationError> {
    if samples.len() < 8 {
        return Err(FieldError::new("samples", "need at least 8 friction samples").into());
    }
    for (i, s) in samples.iter().enumerate() {
        if !(s.slip_speed_m_s.is_finite() && s.slip_speed_m_s >= 0.0 && s.coefficient.is_finite()) {
            return Err(FieldError::new(
                format!("samples[{i}]"),
                "speed must be finite >= 0 and mu finite",
            )
            .into());
        }
    }
    let mut p = friction_initial_guess(samples).ok_or(CalibrationError::Fit("no initial guess"))?;
    let mut cost = friction_cost(samples, &unpack(&p, step));
    let mut lambda = 1e-3;
    let mut iterations = 0;
    for it in 0..200 {
        iterations = it + 1;
        // Jacobian of the model at every sample, column by column.
        let mut jtj = Matrix4::<f64>::zeros();
        let mut jtr = Vector4::<f64>::zeros();
        let base = unpack(&p, step);
        let h = [1e-5, 1e-5, 1e-4, 1e-4];
        let plus: Vec<FrictionParams> = (0..4)
            .map(|k| {
                let mut q = p;
                q[k] += h[k];
                unpack(&q, step)
            })
            .collect();
        let minus: Vec<FrictionParams> = (0..4)
            .map(|k| {
                let mut q = p;
                q[k] -= h[k];
                unpack(&q, step)
            })
            .collect();
        for s in samples {
            let v = s.slip_speed_m_s;
            let r = base.coefficient(v) - s.coefficient;
            let jrow = Vector4::from_fn(|k, _| {
                (plus[k].coefficient(v) - minus[k].coefficient(v)) / (2.0 * h[k])
            });
            jtj += jrow * jrow.transpose();
            jtr += jrow * r;
        }
        let mut improved = false;
        while lambda < 1e10 {
            let mut a = jtj;
            for k in 0..4 {
                a[(k, k)] += lambda * jtj[(k, k)].max(1e-12);
            }
            let Some(delta) = a.lu().solve(&(-jtr)) else {
                lambda *= 10.0;
                continue;
            };
            let q = p + delta;
            let c = friction_cost(samples, &unpack(&q, step));
            if c.is_finite() && c < cost {
                let rel = (cost - c) / cost.max(f64::MIN_POSITIVE);
                p = q;
                cost = c;
                lambda = (lambda * 0.3).max(1e-12);
                improved = true;
                if rel < 1e-12 {
                    lambda = f64::INFINITY; // converged
                }
                break;
            }
            lambda *= 10.0;
        }
        if !improved || lambda.is_infinite() {
            break;
        }
    }
    let params = unpack(&p, step);
    params
        .validate()
        .map_err(|_| CalibrationError::Fit("fitted friction parameters are not physical"))?;
    Ok(FrictionFit {
        params,
        rms_residual: (cost / samples.len() as f64).sqrt(),
        iterations,
    })
}

/// One wear test on the fixture (thesis 4.4): constant load, measured wear mass.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WearTestRecord {
    /// Normal load N, N (eq. 4.16).
    pub normal_load_n: f64,
    /// Mean contact pressure sigma = N / A, Pa (K is a function of it, eq. 3.11).
    pub contact_pressure_pa: f64,
    /// Sliding distance s = r_avg ∫ theta-dot dt, m (eq. 4.18); see [`sliding_distance_m`].
    pub sliding_distance_m: f64,
    /// Measured wear mass M_wear, kg (eq. 4.17).
    pub wear_mass_kg: f64,
}

/// Sliding distance from the swept angle ∫ theta-dot dt (rad) at radius r_avg (m), m.
pub fn sliding_distance_m(mean_radius_m: f64, swept_angle_rad: f64) -> f64 {
    mean_radius_m * swept_angle_rad.abs()
}

/// Dimensional lumped wear coefficient K = (M_wear / rho) / (N s), m²/N (eq. 4.16-4.18).
pub fn lumped_wear_coefficient(
    record: &WearTestRecord,
    density_kg_m3: f64,
) -> Result<f64, CalibrationError> {
    if !(density_kg_m3.is_finite() && density_kg_m3 > 0.0) {
        return Err(FieldError::new("density_kg_m3", "must be a finite number > 0").into());
    }
    check_wear_record(record).map_err(|e| e.at("record"))?;
    Ok(record.wear_mass_kg / density_kg_m3 / (record.normal_load_n * record.sliding_distance_m))
}

/// The rules of one wear test record; the field is named bare (the caller places it).
fn check_wear_record(r: &WearTestRecord) -> Result<(), FieldError> {
    if !(r.normal_load_n.is_finite() && r.normal_load_n > 0.0) {
        return Err(FieldError::new(
            "normal_load_n",
            "must be a finite number > 0",
        ));
    }
    if !(r.contact_pressure_pa.is_finite() && r.contact_pressure_pa > 0.0) {
        return Err(FieldError::new(
            "contact_pressure_pa",
            "must be a finite number > 0",
        ));
    }
    if !(r.sliding_distance_m.is_finite() && r.sliding_distance_m > 0.0) {
        return Err(FieldError::new(
            "sliding_distance_m",
            "must be a finite number > 0",
        ));
    }
    if !(r.wear_mass_kg.is_finite() && r.wear_mass_kg >= 0.0) {
        return Err(FieldError::new(
            "wear_mass_kg",
            "must be a finite number >= 0",
        ));
    }
    Ok(())
}

/// Result of the K(sigma) fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WearLawFit {
    /// The fitted modified law (eq. 3.11) with the cutoff passed in.
    pub law: WearLaw,
    /// RMS of (K_fit - K_i)/K_i over the tests.
    pub rms_relative_residual: f64,
}

/// For a fixed exponent b = 1/C2, the weighted linear least squares for (C1, C3) with weights
/// 1/K_i²; returns (C1, C3, cost).
fn wear_linear_solve(points: &[(f64, f64)], b: f64) -> Option<(f64, f64, f64)> {
    let (mut s11, mut s12, mut s22, mut t1, mut t2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &(sigma, k) in points {
        let w = 1.0 / (k * k);
        let x = sigma.powf(b);
        s11 += w * x * x;
        s12 += w * x;
        s22 += w;
        t1 += w * x * k;
        t2 += w * k;
    }
    let det = s11 * s22 - s12 * s12;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let c1 = (t1 * s22 - s12 * t2) / det;
    let c3 = (s11 * t2 - s12 * t1) / det;
    let cost = points
        .iter()
        .map(|&(sigma, k)| ((c1 * sigma.powf(b) + c3 - k) / k).powi(2))
        .sum();
    Some((c1, c3, cost))
}

/// Fits `K(sigma) = C1 sigma^(1/C2) + C3` (eq. 3.10) to the lumped coefficients of the tests
/// (eq. 4.18) by relative least squares: exact linear solve for (C1, C3) at each exponent,
/// grid then golden-section search over ln(1/C2) in [ln 0.005, ln 2] (C2 from 0.5 to 200).
pub fn fit_wear_law(
    records: &[WearTestRecord],
    density_kg_m3: f64,
    cutoff_pressure_pa: f64,
) -> Result<WearLawFit, CalibrationError> {
    if cutoff_pressure_pa.is_nan() || cutoff_pressure_pa <= 0.0 {
        return Err(FieldError::new("cutoff_pressure_pa", "must be > 0 Pa").into());
    }
    let mut points = Vec::with_capacity(records.len());
    for (i, r) in records.iter().enumerate() {
        check_wear_record(r).map_err(|e| e.at(&format!("records[{i}]")))?;
        let k = lumped_wear_coefficient(r, density_kg_m3)?;
        if k <= 0.0 {
            return Err(FieldError::new(
                record_field(i, "wear_mass_kg"),
                "must be > 0 for the relative fit",
            )
            .into());
        }
        points.push((r.contact_pressure_pa, k));
    }
    let mut pressures: Vec<f64> = points.iter().map(|p| p.0).collect();
    pressures.sort_by(f64::total_cmp);
    pressures.dedup();
    if pressures.len() < 3 {
        return Err(
            FieldError::new("records", "need at least 3 distinct contact pressures").into(),
        );
    }
    let cost_at = |lb: f64| wear_linear_solve(&points, lb.exp()).map_or(f64::INFINITY, |s| s.2);
    let (lo, hi) = (0.005f64.ln(), 2.0f64.ln());
    let grid = 400;
    let mut best = (f64::INFINITY, lo);
    for g in 0..=grid {
        let lb = lo + (hi - lo) * g as f64 / grid as f64;
        let c = cost_at(lb);
        if c < best.0 {
            best = (c, lb);
        }
    }
    let step = (hi - lo) / grid as f64;
    let (mut a, mut b) = ((best.1 - step).max(lo), (best.1 + step).min(hi));
    let gr = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..100 {
        let x1 = b - gr * (b - a);
        let x2 = a + gr * (b - a);
        if cost_at(x1) < cost_at(x2) {
            b = x2;
        } else {
            a = x1;
        }
    }
    let lb = 0.5 * (a + b);
    let (c1, c3, cost) =
        wear_linear_solve(&points, lb.exp()).ok_or(CalibrationError::Fit("singular wear fit"))?;
    Ok(WearLawFit {
        law: WearLaw::Modified {
            c1,
            c2: 1.0 / lb.exp(),
            c3,
            cutoff_pressure_pa,
        },
        rms_relative_residual: (cost / points.len() as f64).sqrt(),
    })
}

/// Synthetic torque records of the thesis' friction rig (eq. 4.1), for anchors and tests: a
/// fixture of polar inertia 0.02 kg m² and mean radius 20 mm under 300 N, driven at
/// theta-dot = 1.5 sin(2 pi 0.1 t) rad/s (slip up to 30 mm/s both ways), 20 s at 1 kHz, with
/// the torque of `truth` times (1 + `noise` g), g standard normal (Box-Muller on ChaCha8 seeded
/// with `seed`).
pub fn synthetic_torque_records(
    truth: &FrictionParams,
    noise: f64,
    seed: u64,
) -> (Fixture, Vec<TorqueRecord>) {
    use rand::SeedableRng;
    let fixture = Fixture {
        polar_inertia_kg_m2: 0.02,
        mean_radius_m: 0.02,
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let w = 2.0 * std::f64::consts::PI * 0.1;
    let records = (0..20_000)
        .map(|i| {
            let t = i as f64 * 1e-3;
            let thd = 1.5 * (w * t).sin();
            let thdd = 1.5 * w * (w * t).cos();
            let v = thd * fixture.mean_radius_m;
            let mu = truth.coefficient(v.abs()) * v.signum();
            let torque =
                fixture.polar_inertia_kg_m2 * thdd + 3.0 * fixture.mean_radius_m * 300.0 * mu;
            let gauss = crate::sampling::standard_normal(&mut rng);
            TorqueRecord {
                time_s: t,
                angle_rad: -1.5 / w * (w * t).cos(),
                angular_velocity_rad_s: thd,
                normal_load_n: 300.0,
                input_torque_n_m: torque * (1.0 + noise * gauss),
            }
        })
        .collect();
    (fixture, records)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// Table 4.2 (6.46 mm/s as printed there).
    fn table_4_2() -> FrictionParams {
        FrictionParams {
            mu_static: 0.1799,
            mu_dynamic: 0.166,
            stiction_transition_speed: 6.46e-3,
            friction_transition_speed: 12.0e-3,
            step: StepKind::Cycloidal,
        }
    }

    #[test]
    fn friction_parameters_recovered_from_noisy_torque() {
        // Fixture: J = 0.02 kg m², r_avg = 20 mm, N = 300 N; theta-dot = 1.5 sin(2 pi 0.1 t)
        // rad/s (slip up to 30 mm/s both ways), 20 s at 1 kHz; torque from eq. 4.1 with 2 %
        // multiplicative Gaussian noise.
        let truth = table_4_2();
        let (fixture, records) = synthetic_torque_records(&truth, 0.02, 42);
        let samples = friction_samples(&records, &fixture).unwrap();
        let fit = fit_friction(&samples, StepKind::Cycloidal).unwrap();
        let p = fit.params;
        let rel = |a: f64, b: f64| (a - b).abs() / b;
        println!("{p:?} rms {} iters {}", fit.rms_residual, fit.iterations);
        assert!(rel(p.mu_static, 0.1799) < 0.03, "{p:?}");
        assert!(rel(p.mu_dynamic, 0.166) < 0.03, "{p:?}");
        assert!(rel(p.stiction_transition_speed, 6.46e-3) < 0.10, "{p:?}");
        assert!(rel(p.friction_transition_speed, 12.0e-3) < 0.10, "{p:?}");
        // The residual is the injected noise (2 % of mu ~ 0.0035), not model error.
        assert!(fit.rms_residual < 0.02 * 0.18 * 1.2);
    }

    #[test]
    fn eq_4_3_on_a_hand_case() {
        // J = 1, r = 0.1, N = 10, theta-dot rising 0, 1, 2 rad/s over 1 s steps (accel 1),
        // T = 1.6 N m: mu = (1.6 - 1*1) / (3*0.1*10) = 0.2 at v = 0.1 m/s.
        let fx = Fixture {
            polar_inertia_kg_m2: 1.0,
            mean_radius_m: 0.1,
        };
        let rec = |t: f64, thd: f64| TorqueRecord {
            time_s: t,
            angle_rad: 0.0,
            angular_velocity_rad_s: thd,
            normal_load_n: 10.0,
            input_torque_n_m: 1.6,
        };
        let s = friction_samples(&[rec(0.0, 0.0), rec(1.0, 1.0), rec(2.0, 2.0)], &fx).unwrap();
        assert!((s[1].coefficient - 0.2).abs() < 1e-12);
        assert!((s[1].slip_speed_m_s - 0.1).abs() < 1e-12);
        let bad = friction_samples(&[rec(0.0, 0.0), rec(0.0, 1.0), rec(2.0, 2.0)], &fx);
        assert_eq!(
            bad,
            Err(FieldError::new(
                "records[1].time_s",
                "must be finite and strictly increasing"
            )
            .into())
        );
    }

    /// Wear tests at the given pressures: pad area 1 cm², 100 m of sliding, mass from Table 4.3.
    fn wear_records(
        pressures: &[f64],
        repeats: usize,
        noise: f64,
        seed: u64,
    ) -> Vec<WearTestRecord> {
        let law = WearLaw::table_4_3();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut out = Vec::new();
        for &sigma in pressures {
            for _ in 0..repeats {
                let n = sigma * 1e-4;
                let k = law.coefficient_m2_per_n(sigma).unwrap_or(0.0);
                let mass = 2810.0
                    * k
                    * n
                    * 100.0
                    * (1.0 + noise * crate::sampling::standard_normal(&mut rng));
                out.push(WearTestRecord {
                    normal_load_n: n,
                    contact_pressure_pa: sigma,
                    sliding_distance_m: 100.0,
                    wear_mass_kg: mass,
                });
            }
        }
        out
    }

    const PRESSURES: [f64; 5] = [0.2e6, 0.5e6, 1.0e6, 2.0e6, 5.0e6];

    #[test]
    fn eq_4_18_by_hand() {
        // 2.81 mg of 7075 is 1e-9 m³; over 10 N * 100 m gives K = 1e-12 m²/N.
        let r = WearTestRecord {
            normal_load_n: 10.0,
            contact_pressure_pa: 1e6,
            sliding_distance_m: sliding_distance_m(0.02, 5000.0),
            wear_mass_kg: 2.81e-6,
        };
        assert!((lumped_wear_coefficient(&r, 2810.0).unwrap() - 1e-12).abs() < 1e-24);
    }

    #[test]
    fn wear_law_recovered_exactly_from_clean_records() {
        let fit = fit_wear_law(&wear_records(&PRESSURES, 1, 0.0, 1), 2810.0, 870e6).unwrap();
        let WearLaw::Modified { c1, c2, c3, .. } = fit.law else {
            unreachable!()
        };
        assert!((c2 - 6.3197).abs() / 6.3197 < 1e-3, "{c2}");
        assert!((c1 - 2.3685e-15).abs() / 2.3685e-15 < 1e-3, "{c1}");
        assert!((c3 + 9.5089e-16).abs() / 9.5089e-16 < 1e-2, "{c3}");
    }

    #[test]
    fn wear_law_k_within_5_percent_from_noisy_records() {
        // Five loads, three repeats each, 2 % Gaussian scatter on the wear mass.
        let fit = fit_wear_law(&wear_records(&PRESSURES, 3, 0.02, 7), 2810.0, 870e6).unwrap();
        let truth = WearLaw::table_4_3();
        for i in 0..=50 {
            let sigma = 0.2e6 * 25f64.powf(i as f64 / 50.0);
            let k_fit = fit.law.coefficient_m2_per_n(sigma).unwrap_or(0.0);
            let k_true = truth.coefficient_m2_per_n(sigma).unwrap_or(1.0);
            assert!(
                (k_fit - k_true).abs() / k_true < 0.05,
                "sigma {sigma}: {k_fit} vs {k_true}"
            );
        }
    }

    #[test]
    fn too_few_pressures_is_an_error() {
        let r = wear_records(&[1e6, 2e6], 3, 0.0, 1);
        assert_eq!(
            fit_wear_law(&r, 2810.0, 870e6),
            Err(FieldError::new("records", "need at least 3 distinct contact pressures").into())
        );
    }
}
