//! The blind check of the diagnosis (`railwear diagnose-bench`): campaigns drawn from the
//! virtual rig on one skeleton (controls, each library effect from barely to clearly
//! detectable, the rig-only effects, two noise levels), each diagnosed without its truth, then
//! scored against the truth.
//!
//! **Detectable.** An effect is detectable in a campaign when its noise-free readings (the rig
//! with noise, scatter and sensor noise off) differ from the control's noise-free readings by
//! more than twice the uncertainty the campaign's data carry, RMS over the observations:
//! `sqrt(d' Σ⁻¹ d / n) > 2` with `d = y_effect - y_control` and `Σ` the noise model estimated
//! from the noisy campaign itself at the control's readings (repeats, quantisation, sensor
//! noise, the simulator's numerical and parameter uncertainty, and each accelerometer channel's
//! calibration as one shared scale: an effect that only rescales a channel by about the
//! calibration's uncertainty is not detectable). Only detectable in-library effects count in the top-1 score;
//! undetectable ones are reported apart (the right answer for them is `no_gap`).
//!
//! The emulator only reads the tests' configurations, never their measurements, so one
//! emulator built on the skeleton serves every campaign drawn on it.

use super::emulator::{Emulator, EmulatorOptions};
use super::noise::{gaussian, observations, NoiseModel, Observation, Term};
use super::{diagnose_refining, stats, DiagnoseOptions, Report, Verdict};
use crate::gap::effects::{Effect, LIBRARY};
use crate::gap::rig::{run_cached, RigOptions, Truth};
use crate::gap::rig_effects::{HiddenEffect, RIG_ONLY};
use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use crate::pipeline::RunControl;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha20Rng;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// How the bench draws and diagnoses.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchOptions {
    /// Campaigns to draw.
    pub campaigns: usize,
    /// Seed of the draw (scenario order and every rig seed).
    pub seed: u64,
    /// Rig window per increment, s.
    pub rig_window_s: f64,
    /// Rig settle, s (different from the diagnosis': the diagnosis does not simulate the rig's
    /// exact windows).
    pub rig_settle_s: f64,
    /// Relative measurement noise levels drawn.
    pub noise_levels: Vec<f64>,
    /// Specimen scatter (log-normal sigma).
    pub scatter_rel: f64,
    /// Accelerometer rate, Hz.
    pub accelerometer_rate_hz: f64,
    /// Sensor noise, RMS m/s².
    pub sensor_noise_m_s2: f64,
    /// Magnitudes drawn, as fractions of each effect's bound.
    pub fractions: Vec<f64>,
    /// Diagnosis options.
    pub diagnose: DiagnoseOptions,
}

impl Default for BenchOptions {
    fn default() -> Self {
        Self {
            campaigns: 60,
            seed: 1,
            rig_window_s: 0.5,
            rig_settle_s: 0.5,
            noise_levels: vec![0.03, 0.10],
            scatter_rel: 0.05,
            accelerometer_rate_hz: 2000.0,
            sensor_noise_m_s2: 0.5,
            fractions: vec![0.07, 0.3, 0.8],
            diagnose: DiagnoseOptions {
                emulator: EmulatorOptions {
                    window_s: 0.5,
                    settle_s: 0.3,
                    ..EmulatorOptions::default()
                },
                ..DiagnoseOptions::default()
            },
        }
    }
}

/// What the rig put in one campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scenario {
    /// `control`, a library effect's name or a rig-only effect's name.
    pub truth: String,
    /// In the library.
    pub in_library: bool,
    /// Magnitude.
    pub magnitude: f64,
    /// Relative measurement noise.
    pub noise_rel: f64,
    /// Rig seed.
    pub seed: u64,
}

/// One campaign's outcome.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// What the rig did.
    pub scenario: Scenario,
    /// Detectability score (see the module documentation).
    pub detectability: f64,
    /// Detectable (score > 2).
    pub detectable: bool,
    /// Verdict.
    pub verdict: Verdict,
    /// Best effect's name, if any.
    pub chosen: Option<String>,
    /// Shrink of the held-out error, if explained.
    pub shrink: Option<f64>,
    /// Fitted magnitude, if one effect.
    pub fitted_magnitude: Option<f64>,
    /// Lack-of-fit p-value of the nominal model.
    pub nominal_p_value: f64,
    /// Groups flagged in `where`.
    pub flagged: Vec<String>,
}

/// The bench's scores.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// Campaigns diagnosed.
    pub campaigns: usize,
    /// Detectable in-library campaigns.
    pub detectable_in_library: usize,
    /// Of those, the share whose best effect is the true one.
    pub top1: f64,
    /// Controls.
    pub controls: usize,
    /// Share of controls reported no_gap.
    pub controls_clean: f64,
    /// Detectable rig-only campaigns.
    pub detectable_rig_only: usize,
    /// Share of those reported not_explained.
    pub rig_only_flagged: f64,
    /// Median held-out shrink where the right effect was found.
    pub median_shrink: f64,
    /// Undetectable in-library campaigns reported no_gap (share).
    pub undetectable_no_gap: f64,
    /// Truth -> answer -> count.
    pub confusion: BTreeMap<String, BTreeMap<String, usize>>,
    /// Every outcome.
    pub outcomes: Vec<Outcome>,
}

fn scenarios(
    base: &Campaign,
    configs_dir: &Path,
    o: &BenchOptions,
) -> Result<Vec<Scenario>, GapError> {
    let cases: Vec<_> = base
        .tests
        .iter()
        .enumerate()
        .map(|(ti, t)| t.case(ti, configs_dir))
        .collect::<Result<_, _>>()?;
    let lib = super::emulator::applicable(&cases, None)?;
    let mut list = Vec::new();
    for &noise in &o.noise_levels {
        for _ in 0..6 {
            list.push(("control".to_string(), true, 0.0, noise));
        }
        for info in &lib {
            for f in &o.fractions {
                list.push((
                    info.name.to_string(),
                    true,
                    f * info.parameters[0].max,
                    noise,
                ));
            }
        }
        for info in RIG_ONLY {
            for f in &o.fractions {
                list.push((
                    info.name.to_string(),
                    false,
                    f * info.parameters[0].max,
                    noise,
                ));
            }
        }
    }
    let mut rng = ChaCha20Rng::seed_from_u64(o.seed);
    list.shuffle(&mut rng);
    Ok(list
        .into_iter()
        .take(o.campaigns)
        .enumerate()
        .map(|(i, (truth, in_library, magnitude, noise_rel))| Scenario {
            truth,
            in_library,
            magnitude,
            noise_rel,
            seed: o.seed.wrapping_mul(1000).wrapping_add(i as u64),
        })
        .collect())
}

fn rig_options(s: &Scenario, o: &BenchOptions, noisy: bool) -> Result<RigOptions, GapError> {
    let mut r = RigOptions {
        noise_rel: if noisy { s.noise_rel } else { 0.0 },
        scatter_rel: if noisy { o.scatter_rel } else { 0.0 },
        seed: s.seed,
        window_s: o.rig_window_s,
        settle_s: o.rig_settle_s,
        segments_per_increment: 1,
        accelerometer_rate_hz: Some(o.accelerometer_rate_hz),
        sensor_noise_m_s2: if noisy { o.sensor_noise_m_s2 } else { 0.0 },
        calibration_rel: if noisy {
            o.diagnose.accelerometer_calibration_rel
        } else {
            0.0
        },
        ..RigOptions::default()
    };
    if s.truth != "control" {
        let text = format!("{}={}", s.truth, s.magnitude);
        if s.in_library {
            r.effects.push(Effect::parse(&text)?);
        } else {
            r.hidden.push(HiddenEffect::parse(&text)?);
        }
    }
    Ok(r)
}

/// Noise-free readings' distance from the control's, in units of the uncertainty the noisy
/// campaign's data carry (its noise model, estimated from its repeats, with each channel's
/// shared calibration scale), RMS: `sqrt(Mahalanobis² / n)`.
fn detectability(
    effect: &[Observation],
    control: &[Observation],
    noise: &NoiseModel,
    noisy: &[Observation],
) -> f64 {
    let terms = effect
        .iter()
        .zip(control)
        .zip(noisy)
        .map(|((e, c), o)| (noise.term(o, c.value, 0.0), e.value - c.value))
        .filter(|(t, _)| t.var > 0.0)
        .map(|(t, d)| Term { residual: d, ..t });
    let t = gaussian(terms, noise.scale_var);
    if t.w > 0.0 {
        (t.r2 / t.w).sqrt()
    } else {
        0.0
    }
}

/// Runs the bench. `progress(message)` reports each step.
pub fn run(
    skeleton: &Campaign,
    configs_dir: &Path,
    o: &BenchOptions,
    control: &RunControl,
    emulator_file: Option<&Path>,
    progress: &(dyn Fn(String) + Sync),
) -> Result<Scores, GapError> {
    skeleton.validate(configs_dir)?;
    let cache = WindowCache::new();
    let key = Emulator::key(skeleton, &o.diagnose.emulator);
    let saved = emulator_file
        .and_then(|p| std::fs::read_to_string(p).ok())
        .and_then(|text| {
            serde_json::from_str::<(String, Emulator)>(&text)
                .ok()
                .filter(|(k, _)| *k == key)
        });
    let emulator = match saved {
        Some((_, e)) => {
            progress("emulator loaded (same tests, options and code version)".into());
            e
        }
        None => {
            progress("building the emulator on the skeleton".into());
            let e = Emulator::build(
                skeleton,
                configs_dir,
                &o.diagnose.emulator,
                control,
                &cache,
                &|d, t| {
                    if d == t || d % 10 == 0 {
                        progress(format!("emulator: {d}/{t} test simulations"));
                    }
                },
            )?;
            if let Some(p) = emulator_file {
                let text = serde_json::to_string(&(&key, &e))
                    .map_err(|x| GapError::field("emulator", x.to_string()))?;
                std::fs::write(p, text).map_err(|x| GapError::Write {
                    path: p.display().to_string(),
                    message: x.to_string(),
                })?;
            }
            e
        }
    };
    let list = scenarios(skeleton, configs_dir, o)?;
    let control_scenario = Scenario {
        truth: "control".into(),
        in_library: true,
        magnitude: 0.0,
        noise_rel: 0.0,
        seed: 0,
    };
    let (clean_control, _) = run_cached(
        skeleton,
        configs_dir,
        &rig_options(&control_scenario, o, false)?,
        control,
        &cache,
    )?;
    let control_obs = observations(&clean_control);
    let mut outcomes = Vec::new();
    for (i, s) in list.iter().enumerate() {
        progress(format!(
            "campaign {}/{}: rig ({} {:.4}, noise {})",
            i + 1,
            list.len(),
            s.truth,
            s.magnitude,
            s.noise_rel
        ));
        let (noisy, _truth): (Campaign, Truth) = run_cached(
            skeleton,
            configs_dir,
            &rig_options(s, o, true)?,
            control,
            &cache,
        )?;
        let (clean, _) = run_cached(
            skeleton,
            configs_dir,
            &rig_options(s, o, false)?,
            control,
            &cache,
        )?;
        let det = if s.truth == "control" {
            0.0
        } else {
            let mut noisy_obs = observations(&noisy);
            let noise = NoiseModel::estimate(&noisy, &mut noisy_obs, &emulator, &o.diagnose);
            detectability(&observations(&clean), &control_obs, &noise, &noisy_obs)
        };
        // Each campaign refines its own copy, so its diagnosis is the one it would get alone.
        let mut refined = emulator.clone();
        let report: Report = diagnose_refining(
            &noisy,
            &mut refined,
            &o.diagnose,
            configs_dir,
            control,
            &cache,
            &|_, _| {},
        )?;
        let refinements = refined.simulations - emulator.simulations;
        let chosen = report.best_effect.as_ref().map(|b| b.name.clone());
        outcomes.push(Outcome {
            scenario: s.clone(),
            detectability: det,
            detectable: det > 2.0,
            verdict: report.verdict,
            shrink: report.best_effect.as_ref().map(|b| b.shrink),
            fitted_magnitude: report
                .best_effect
                .as_ref()
                .filter(|b| !b.name.contains('+'))
                .and_then(|b| b.parameters.first().map(|p| p.value)),
            chosen,
            nominal_p_value: report.nominal.p_value,
            flagged: report
                .location
                .groups
                .iter()
                .filter(|g| g.flagged)
                .map(|g| format!("{}: {} (z {:+.1})", g.by, g.label, g.z))
                .collect(),
        });
        let last = outcomes.last().map(|x| (x.verdict, x.chosen.clone()));
        progress(format!(
            "  -> {:?} {:?} (detectability {det:.1}, {refinements} refinement windows)",
            last.as_ref().map(|l| l.0),
            last.and_then(|l| l.1)
        ));
    }
    Ok(score(outcomes))
}

fn answer(o: &Outcome) -> String {
    match o.verdict {
        Verdict::NoGap => "no_gap".into(),
        Verdict::NotExplained => "not_explained".into(),
        Verdict::Explained => o.chosen.clone().unwrap_or_else(|| "?".into()),
    }
}

fn share(k: usize, n: usize) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        k as f64 / n as f64
    }
}

/// Scores outcomes.
pub fn score(outcomes: Vec<Outcome>) -> Scores {
    let lib: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.scenario.in_library && o.scenario.truth != "control")
        .collect();
    let det_lib: Vec<&&Outcome> = lib.iter().filter(|o| o.detectable).collect();
    let right: Vec<&&&Outcome> = det_lib
        .iter()
        .filter(|o| {
            o.verdict == Verdict::Explained && o.chosen.as_deref() == Some(&o.scenario.truth)
        })
        .collect();
    let undet: Vec<&&Outcome> = lib.iter().filter(|o| !o.detectable).collect();
    let controls: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.scenario.truth == "control")
        .collect();
    let rig_only: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| !o.scenario.in_library && o.detectable)
        .collect();
    let mut confusion: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
    for o in &outcomes {
        let row = if o.scenario.truth == "control" || o.detectable {
            o.scenario.truth.clone()
        } else {
            format!("{} (undetectable)", o.scenario.truth)
        };
        *confusion
            .entry(row)
            .or_default()
            .entry(answer(o))
            .or_insert(0) += 1;
    }
    let shrinks: Vec<f64> = right.iter().filter_map(|o| o.shrink).collect();
    Scores {
        campaigns: outcomes.len(),
        detectable_in_library: det_lib.len(),
        top1: share(right.len(), det_lib.len()),
        controls: controls.len(),
        controls_clean: share(
            controls
                .iter()
                .filter(|o| o.verdict == Verdict::NoGap)
                .count(),
            controls.len(),
        ),
        detectable_rig_only: rig_only.len(),
        rig_only_flagged: share(
            rig_only
                .iter()
                .filter(|o| o.verdict == Verdict::NotExplained)
                .count(),
            rig_only.len(),
        ),
        median_shrink: if shrinks.is_empty() {
            f64::NAN
        } else {
            stats::median(&shrinks)
        },
        undetectable_no_gap: share(
            undet.iter().filter(|o| o.verdict == Verdict::NoGap).count(),
            undet.len(),
        ),
        confusion,
        outcomes,
    }
}

impl Scores {
    /// The printed tables.
    pub fn table(&self) -> String {
        let pct = |x: f64| {
            if x.is_nan() {
                "n/a".to_string()
            } else {
                format!("{:.0} %", 100.0 * x)
            }
        };
        let mut s = String::new();
        s.push_str("| score | value | target |\n|---|---|---|\n");
        s.push_str(&format!("| campaigns | {} | >= 60 |\n", self.campaigns));
        s.push_str(&format!(
            "| top-1 on detectable in-library effects ({}) | {} | >= 85 % |\n",
            self.detectable_in_library,
            pct(self.top1)
        ));
        s.push_str(&format!(
            "| controls reported no_gap ({}) | {} | >= 90 % |\n",
            self.controls,
            pct(self.controls_clean)
        ));
        s.push_str(&format!(
            "| detectable rig-only effects reported not_explained ({}) | {} | >= 70 % |\n",
            self.detectable_rig_only,
            pct(self.rig_only_flagged)
        ));
        s.push_str(&format!(
            "| median held-out shrink where the right effect was found | {} | >= 50 % |\n",
            pct(self.median_shrink)
        ));
        s.push_str(&format!(
            "| undetectable in-library effects reported no_gap | {} | (right answer) |\n\n",
            pct(self.undetectable_no_gap)
        ));
        let mut cols: Vec<String> = vec!["no_gap".into()];
        cols.extend(LIBRARY.iter().map(|e| e.name.to_string()));
        for row in self.confusion.values() {
            for k in row.keys() {
                if !cols.contains(k) && k != "not_explained" {
                    cols.push(k.clone());
                }
            }
        }
        cols.push("not_explained".into());
        s.push_str("Confusion (rows: truth; columns: answer)\n\n| truth |");
        for c in &cols {
            s.push_str(&format!(" {c} |"));
        }
        s.push_str("\n|---|");
        for _ in &cols {
            s.push_str("---|");
        }
        s.push('\n');
        for (truth, row) in &self.confusion {
            s.push_str(&format!("| {truth} |"));
            for c in &cols {
                s.push_str(&format!(" {} |", row.get(c).copied().unwrap_or(0)));
            }
            s.push('\n');
        }
        s
    }
}
