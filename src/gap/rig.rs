//! The virtual shaker rig (issue 14 item 4): a campaign skeleton in, a campaign out whose
//! measurements come from the model plus hidden effects, specimen scatter and measurement
//! noise; the truth goes to a separate file.
//!
//! For each test the rig simulates every segment of every increment once (each increment is
//! cut into `segments_per_increment` segments; dynamics effects see the specimen's state at
//! each segment: test time at its middle, slip distance at its start), keeps the contact
//! tracks of the simulated window (`window_s` of excitation after `settle_s`) and integrates the
//! wear over them with the wear-law effects. The window stands for the segment's test time:
//! wear and slip distance scale by `segment duration / window_s`. The simulation is
//! deterministic, so all specimens of a test share it; they differ by scatter and noise:
//!
//! - specimen scatter: the wear of a specimen is multiplied by `exp(scatter_rel z - scatter_rel²/2)`
//!   (log-normal, mean 1), one `z ~ N(0, 1)` per specimen;
//! - measurement: each weighed mass is `m (1 + noise_rel z)`, clamped at 0 and rounded to the
//!   test's scale resolution;
//! - accelerometers (if asked): the window's input (tube / rail) and response (free body)
//!   acceleration at `accelerometer_rate_hz`, times the sensor's sensitivity error, plus
//!   N(0, sensor_noise²) per axis and sample. One sensor per location and axis serves the whole
//!   campaign: its sensitivity is `1 + calibration_rel z`, one `z ~ N(0, 1)` per channel.
//!
//! All draws come from one ChaCha20 stream seeded by `seed`, in a fixed order that does not
//! depend on the effects: the same seed gives the same campaign, and an effect at magnitude 0
//! gives the control's campaign bit for bit. The sensitivities come from a second stream on the
//! same seed, so a campaign drawn without calibration error is the one drawn before they
//! existed.

use super::accel::{AccelLocation, AccelRecord};
use super::campaign::{Campaign, Increment, Specimen};
use super::effects::{Effect, SpecimenState, LIBRARY};
use super::rig_effects::{HiddenEffect, RIG_ONLY};
use super::tracks::{SlipHistory, WearTerm};
use super::window::{WindowCache, WindowOptions, WindowRun};
use super::GapError;
use crate::models::spec::CaseSpec;
use crate::physics::control::RunControl;
use crate::sampling::standard_normal;
use crate::units::S_PER_H;
use rand::SeedableRng;
use rand_chacha::ChaCha20Rng;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

/// How the rig runs.
#[derive(Debug, Clone, PartialEq)]
pub struct RigOptions {
    /// Library effects (hidden from the output campaign).
    pub effects: Vec<Effect>,
    /// Rig-only effects.
    pub hidden: Vec<HiddenEffect>,
    /// Relative measurement noise of each weighed mass (standard deviation / mass), >= 0.
    pub noise_rel: f64,
    /// Specimen-to-specimen scatter of the wear (log-normal sigma), >= 0.
    pub scatter_rel: f64,
    /// Seed of every random draw.
    pub seed: u64,
    /// Simulated excitation per segment, s.
    pub window_s: f64,
    /// Settle time before each segment's excitation, s.
    pub settle_s: f64,
    /// Segments each increment is cut into (dynamics effects update between them), >= 1.
    pub segments_per_increment: usize,
    /// Write input and response accelerometer records at this rate, Hz (None: no records).
    pub accelerometer_rate_hz: Option<f64>,
    /// Sensor noise of the written records, RMS m/s².
    pub sensor_noise_m_s2: f64,
    /// Relative error of each accelerometer's sensitivity (1 sigma; a mean square carries
    /// about twice it), >= 0.
    pub calibration_rel: f64,
}

impl Default for RigOptions {
    fn default() -> Self {
        Self {
            effects: Vec::new(),
            hidden: Vec::new(),
            noise_rel: 0.0,
            scatter_rel: 0.0,
            seed: 0,
            window_s: 2.0,
            settle_s: 0.5,
            segments_per_increment: 1,
            accelerometer_rate_hz: None,
            sensor_noise_m_s2: 0.0,
            calibration_rel: 0.0,
        }
    }
}

/// Parses `--effect` arguments: `none` (a control) or `name=magnitude[,param=value...]` of
/// the library or of the rig-only effects.
pub fn parse_effects(args: &[String]) -> Result<(Vec<Effect>, Vec<HiddenEffect>), GapError> {
    let mut effects = Vec::new();
    let mut hidden = Vec::new();
    for a in args {
        let a = a.trim();
        if a == "none" {
            continue;
        }
        let name = a.split(['=', ',']).next().unwrap_or_default();
        if RIG_ONLY.iter().any(|e| e.name == name) {
            hidden.push(HiddenEffect::parse(a)?);
        } else if LIBRARY.iter().any(|e| e.name == name) {
            effects.push(Effect::parse(a)?);
        } else {
            let known: Vec<&str> = LIBRARY.iter().chain(RIG_ONLY).map(|e| e.name).collect();
            return Err(GapError::field(
                "effect",
                format!(
                    "unknown effect `{name}` (known: none, {})",
                    known.join(", ")
                ),
            ));
        }
    }
    Ok((effects, hidden))
}

/// One effect in the truth file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthEffect {
    /// Name.
    pub name: String,
    /// True when the diagnosis' library has it.
    pub in_library: bool,
    /// Parameters by name.
    pub parameters: BTreeMap<String, f64>,
}

/// What the rig put into a campaign (never shown to the diagnosis).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Truth {
    /// Base campaign name.
    pub base: String,
    /// Effects (empty: a control).
    pub effects: Vec<TruthEffect>,
    /// Relative measurement noise.
    pub noise_rel: f64,
    /// Specimen scatter (log-normal sigma).
    pub scatter_rel: f64,
    /// Seed.
    pub seed: u64,
    /// Simulated window per segment, s.
    pub window_s: f64,
    /// Settle per segment, s.
    pub settle_s: f64,
    /// Segments per increment.
    pub segments_per_increment: usize,
    /// Accelerometer rate, Hz.
    pub accelerometer_rate_hz: Option<f64>,
    /// Sensor noise, RMS m/s².
    pub sensor_noise_m_s2: f64,
    /// Relative sensitivity error drawn per accelerometer (1 sigma).
    #[serde(default)]
    pub calibration_rel: f64,
    /// Sensitivity of each accelerometer: input x, y, z, then response x, y, z (1 = exact).
    #[serde(default)]
    pub accelerometer_sensitivity: Vec<f64>,
    /// Per test: the model's masses before scatter and noise.
    pub tests: Vec<TruthTest>,
    /// railwear version.
    pub code_version: String,
}

/// Truth of one test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthTest {
    /// Test id.
    pub id: String,
    /// Model mass loss per increment and component (with the effects, before scatter and
    /// noise), mg.
    pub model_mass_loss_mg: Vec<BTreeMap<String, f64>>,
    /// Slip distance accumulated by the end of each increment, m.
    pub slip_distance_m: Vec<f64>,
    /// Scatter factor of each specimen.
    pub specimen_factors: BTreeMap<String, f64>,
}

/// One increment of a test as the model gives it (no scatter, no noise).
pub(crate) struct ModelIncrement {
    /// Mass lost per body, mg.
    pub(crate) mass_mg: BTreeMap<String, f64>,
    /// Input acceleration of the first segment's window, m/s².
    pub(crate) input: Vec<[f64; 3]>,
    /// Response acceleration of the first segment's window, m/s².
    pub(crate) response: Vec<[f64; 3]>,
    /// Each segment's window and where it sits in the test (wear-law terms re-evaluate them).
    pub(crate) segments: Vec<(Arc<WindowRun>, SlipHistory)>,
    /// Slip distance accumulated by the end of the increment, m.
    pub(crate) slip_end_m: f64,
}

fn check_options(o: &RigOptions) -> Result<(), GapError> {
    let rule = GapError::require;
    rule(
        "noise",
        o.noise_rel.is_finite() && (0.0..=1.0).contains(&o.noise_rel),
        "must lie in [0, 1]",
    )?;
    rule(
        "scatter",
        o.scatter_rel.is_finite() && (0.0..=2.0).contains(&o.scatter_rel),
        "must lie in [0, 2]",
    )?;
    // A diagnosis' window and settle bounds: the rig makes the campaigns a diagnosis reads.
    crate::cases::check_window_s(o.window_s)?;
    crate::cases::check_settle_s(o.settle_s)?;
    rule(
        "segments_per_increment",
        (1..=100).contains(&o.segments_per_increment),
        "must lie in 1..=100",
    )?;
    rule(
        "sensor_noise_m_s2",
        o.sensor_noise_m_s2.is_finite() && o.sensor_noise_m_s2 >= 0.0,
        "must be a finite number >= 0",
    )?;
    rule(
        "calibration_rel",
        o.calibration_rel.is_finite() && (0.0..=0.2).contains(&o.calibration_rel),
        "must lie in [0, 0.2]",
    )?;
    if let Some(r) = o.accelerometer_rate_hz {
        rule(
            "accelerometer_rate_hz",
            r.is_finite() && r > 0.0 && r <= 1.0e5,
            "must lie in (0, 1e5] Hz",
        )?;
    }
    Ok(())
}

/// Runs the rig on `base` (its measurements are ignored) and returns the campaign and the
/// truth.
pub fn run(
    base: &Campaign,
    configs_dir: &Path,
    options: &RigOptions,
    control: &RunControl,
) -> Result<(Campaign, Truth), GapError> {
    run_cached(base, configs_dir, options, control, &WindowCache::new())
}

/// [`run`] with simulations remembered in `cache` (deterministic: a cached window is the one
/// the rig would simulate), for callers that draw many campaigns on one skeleton.
pub fn run_cached(
    base: &Campaign,
    configs_dir: &Path,
    options: &RigOptions,
    control: &RunControl,
    cache: &WindowCache,
) -> Result<(Campaign, Truth), GapError> {
    check_options(options)?;
    base.validate(configs_dir)?;
    let mut rng = ChaCha20Rng::seed_from_u64(options.seed);
    // Sensitivities: input x, y, z, response x, y, z, from their own stream.
    let mut cal_rng = ChaCha20Rng::seed_from_u64(options.seed);
    cal_rng.set_stream(1);
    let sensitivity: Vec<f64> = (0..6)
        .map(|_| 1.0 + options.calibration_rel * standard_normal(&mut cal_rng))
        .collect();
    let mut out = base.clone();
    out.name = format!("{}-rig", base.name);
    out.description = format!("Virtual rig campaign on the tests of `{}`", base.name);
    out.source = Some("railwear rig (virtual shaker rig)".into());
    let mut truth_tests = Vec::new();
    for (ti, test) in base.tests.iter().enumerate() {
        let increments = test
            .specimens
            .iter()
            .map(|s| s.increments.len())
            .max()
            .unwrap_or(0);
        let window = WindowOptions {
            window_s: options.window_s,
            settle_s: options.settle_s,
            accelerometer_rate_hz: options.accelerometer_rate_hz,
            tolerance_scale: 1.0,
        };
        let model = simulate_test(
            ti,
            base,
            None,
            configs_dir,
            options,
            &window,
            increments,
            control,
            cache,
        )?;
        let slip: Vec<f64> = model.iter().map(|m| m.slip_end_m).collect();
        let mut factors = BTreeMap::new();
        let out_test = &mut out.tests[ti];
        for spec in out_test.specimens.iter_mut() {
            let factor = (options.scatter_rel * standard_normal(&mut rng)
                - 0.5 * options.scatter_rel.powi(2))
            .exp();
            factors.insert(spec.id.clone(), factor);
            let n = spec.increments.len();
            let mut new_spec = Specimen {
                id: spec.id.clone(),
                increments: Vec::with_capacity(n),
                accelerometers: Vec::new(),
            };
            for m in model.iter().take(n) {
                let mut inc = Increment::default();
                for comp in &test.components {
                    let true_mg = m.mass_mg.get(comp).copied().unwrap_or(0.0) * factor;
                    let noisy =
                        (true_mg * (1.0 + options.noise_rel * standard_normal(&mut rng))).max(0.0);
                    inc.mass_loss_mg
                        .insert(comp.clone(), quantize(noisy, test.scale_resolution_mg));
                }
                new_spec.increments.push(inc);
            }
            if let Some(rate) = options.accelerometer_rate_hz {
                for (k, m) in model.iter().take(n).enumerate() {
                    for (location, series, gain) in [
                        (AccelLocation::Input, &m.input, &sensitivity[..3]),
                        (AccelLocation::Response, &m.response, &sensitivity[3..]),
                    ] {
                        let samples = series
                            .iter()
                            .enumerate()
                            .map(|(i, a)| {
                                let mut s = [i as f64 / rate, a[0], a[1], a[2]];
                                for (x, g) in s.iter_mut().skip(1).zip(gain) {
                                    *x = *x * g
                                        + options.sensor_noise_m_s2 * standard_normal(&mut rng);
                                }
                                s
                            })
                            .collect();
                        new_spec.accelerometers.push(AccelRecord {
                            increment: k + 1,
                            location,
                            sample_rate_hz: rate,
                            sensor_noise_m_s2: options.sensor_noise_m_s2,
                            csv: None,
                            samples,
                        });
                    }
                }
            }
            *spec = new_spec;
        }
        truth_tests.push(TruthTest {
            id: test.id.clone(),
            model_mass_loss_mg: model.iter().map(|m| m.mass_mg.clone()).collect(),
            slip_distance_m: slip,
            specimen_factors: factors,
        });
    }
    let truth = Truth {
        base: base.name.clone(),
        effects: options
            .effects
            .iter()
            .map(|e| TruthEffect {
                name: e.name.clone(),
                in_library: true,
                parameters: e.parameters.clone(),
            })
            .chain(options.hidden.iter().map(|e| TruthEffect {
                name: e.name().to_string(),
                in_library: false,
                parameters: e.parameters(),
            }))
            .collect(),
        noise_rel: options.noise_rel,
        scatter_rel: options.scatter_rel,
        seed: options.seed,
        window_s: options.window_s,
        settle_s: options.settle_s,
        segments_per_increment: options.segments_per_increment,
        accelerometer_rate_hz: options.accelerometer_rate_hz,
        sensor_noise_m_s2: options.sensor_noise_m_s2,
        calibration_rel: options.calibration_rel,
        accelerometer_sensitivity: sensitivity,
        tests: truth_tests,
        code_version: crate::models::case::code_version().to_string(),
    };
    Ok((out, truth))
}

/// `x` rounded to a multiple of `resolution`, printed cleanly (to 1e-9 mg).
fn quantize(x: f64, resolution: f64) -> f64 {
    ((x / resolution).round() * resolution * 1e9).round() / 1e9
}

/// Simulates the increments of test `ti` (shared by its specimens): model masses per
/// increment and the slip distance at the end of each. Segments whose case is the same as an
/// earlier one (every segment of a test without dynamics effects of time or slip) come from
/// `cache`.
///
/// `case` replaces the test's own case (already resolved) when given; `window` says how each
/// window is simulated (the rig: its window, settle and accelerometer rate at the configured
/// tolerance).
#[allow(clippy::too_many_arguments)]
pub(crate) fn simulate_test(
    ti: usize,
    base: &Campaign,
    case: Option<&CaseSpec>,
    configs_dir: &Path,
    o: &RigOptions,
    window: &WindowOptions,
    increments: usize,
    control: &RunControl,
    cache: &WindowCache,
) -> Result<Vec<ModelIncrement>, GapError> {
    let test = &base.tests[ti];
    let case0 = match case {
        Some(c) => c.clone(),
        None => test.case(ti, configs_dir)?,
    };
    let segment_s = test.increment_duration_s / o.segments_per_increment as f64;
    let mut slip = 0.0;
    let mut out = Vec::with_capacity(increments);
    for k in 0..increments {
        let mut inc = ModelIncrement {
            mass_mg: BTreeMap::new(),
            input: Vec::new(),
            response: Vec::new(),
            segments: Vec::new(),
            slip_end_m: 0.0,
        };
        for j in 0..o.segments_per_increment {
            let what = format!("test {} increment {} segment {}", test.id, k + 1, j + 1);
            let start_s = k as f64 * test.increment_duration_s + j as f64 * segment_s;
            let state = SpecimenState {
                elapsed_h: (start_s + 0.5 * segment_s) / S_PER_H,
                slip_distance_m: slip,
            };
            let mut case = case0.clone();
            for e in &o.effects {
                e.apply(&mut case, &state, configs_dir)?;
            }
            let run = cache.get_or_run(&case, configs_dir, window, &what, control)?;
            let scale = segment_s / run.window_s;
            let mut boxed: Vec<Box<dyn WearTerm>> = Vec::new();
            for e in o.effects.iter().filter(|e| e.magnitude() != 0.0) {
                boxed.extend(e.wear_term(run.hardness_pa)?);
            }
            boxed.extend(
                o.hidden
                    .iter()
                    .filter(|h| h.magnitude() != 0.0)
                    .map(|h| h.wear_term()),
            );
            let terms: Vec<&dyn WearTerm> = boxed.iter().map(|b| b.as_ref()).collect();
            let history = SlipHistory {
                slip_start_m: slip,
                time_scale: scale,
            };
            for (body, mg) in run.masses_mg(&terms, history)? {
                *inc.mass_mg.entry(body).or_insert(0.0) += mg;
            }
            slip += run.slip_distance_m() * scale;
            if j == 0 {
                inc.input = run.input.clone();
                inc.response = run.response.clone();
            }
            inc.segments.push((run, history));
        }
        inc.slip_end_m = slip;
        out.push(inc);
    }
    Ok(out)
}
