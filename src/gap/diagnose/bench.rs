//! The blind check of the diagnosis (`railwear diagnose-bench`): campaigns drawn from the
//! virtual rig on one skeleton (controls, each library effect from barely to clearly
//! detectable with its secondary parameters drawn uniformly within their bounds, pairs of a
//! dynamics effect with a wear-law effect and of two dynamics effects, the rig-only effects,
//! two noise levels), each diagnosed without its truth, then scored against the truth.
//!
//! Over 700 lines for now: drawing the scenarios (singles, pairs, secondary parameters) and
//! scoring them (top-1, pairs, wrong names) are one table; the drawing is the part to move out
//! next.
//!
//! A **wrong name** is a confident name that is not the truth: an `explained` verdict naming
//! an effect the rig did not inject (any name, for a control or a rig-only effect). A pair is
//! **both named** when the verdict is `explained` and names exactly its two effects.
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
//! **Pairs.** A pair is detectable when each member is, given the other: the pair's
//! noise-free readings differ from those of the other member alone by more than twice the
//! uncertainty, *at every magnitude and secondary value of the other member*. The bench
//! searches the other member's values that come closest (its magnitude over eight fractions
//! of its bound and three golden-section steps; then each secondary parameter over five values
//! within its bounds, each with the magnitude over the eight fractions again) and scores the
//! member against that. A member
//! that the other, at other values, stands in for within the noise is not seen by any
//! diagnosis: a friction drift at 0.045 with the default slip scale fits a drift of 0.18 over
//! 997 m with a 6 ms fixture compliance within the noise (bench seed 2045). The older measure,
//! the other member at its drawn values only, is reported beside it
//! (`pairs_detectable_at_drawn`).
//!
//! **Carried by one test.** The diagnosis confirms an effect on held-out tests
//! (leave-one-test-out), so an effect whose readings differ detectably in one test alone has
//! nothing to be fitted on when that test is held out. A proxy: an effect spread thinly over
//! several tests, detectable in none alone, counts as carried by fewer than two. The bench counts the tests in which an
//! effect is detectable on their own observations (`detectable_tests`; a pair: the fewest over
//! the pair and each member given the other). Top-1 and both-named are reported over every
//! detectable campaign and over those two or more tests carry; for the singles one test
//! carries, the share whose leading candidate (`explained` or `partly_explained`) is right.
//!
//! **The truth's own fit** ([`truth_fit`](super::truth_fit)). After each diagnosis, the
//! injected effects are simulated in the emulator at their drawn values (a pair together) and
//! scored on the campaign as any candidate is: its lack-of-fit p-value and AICc. A truth that
//! does not fit says the emulator's model of it (its window, settle and uncertainty) cannot
//! match this campaign, and no search could name it; a pair whose truth a member alone beats
//! by AICc (as the diagnosis fitted that member) is not identifiable from the campaign. The
//! pairs left, whose truth fits and beats each member alone, are scored apart
//! (`identifiable_pairs`): there a miss is the search's.
//!
//! The emulator only reads the tests' configurations, never their measurements, so one
//! emulator built on the skeleton serves every campaign drawn on it.

use super::emulator::{effect_with, Emulator, EmulatorOptions};
use super::noise::{gaussian, observations, NoiseModel, Observation, Term};
use super::truth_fit::{truth_fit, TruthFit};
use super::{diagnose_refining, stats, DiagnoseOptions, Report, Simulating, Verdict};
use crate::gap::effects::{Acts, Effect, EffectInfo, LIBRARY};
use crate::gap::rig::{run_cached, RigOptions, Truth};
use crate::gap::rig_effects::{HiddenEffect, RIG_ONLY};
use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use crate::pipeline::RunControl;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
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
    /// Share of the campaigns drawn with accelerometer records (the rest weigh only).
    pub records_share: f64,
    /// Sensor noise, RMS m/s².
    pub sensor_noise_m_s2: f64,
    /// Magnitudes drawn, as fractions of each effect's bound.
    pub fractions: Vec<f64>,
    /// Pairs drawn per noise level of each kind (dynamics + wear law, dynamics + dynamics).
    pub pairs_per_kind: usize,
    /// Keep only the campaigns whose truth names this effect (alone or in a pair), `control`,
    /// or `pairs` (every pair): a focused study. Each kept campaign has the seed, records and draw it has in
    /// the full bench. None: every campaign.
    pub truth_filter: Option<String>,
    /// Write each campaign's diagnosis report here, as `<rig seed>.json` (with its truth beside
    /// it): what a confusion row hides.
    pub reports_dir: Option<std::path::PathBuf>,
    /// Keep only the campaigns with these rig seeds (empty: all): one campaign re-run as the
    /// full bench draws it.
    pub only_seeds: Vec<u64>,
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
            records_share: 0.5,
            sensor_noise_m_s2: 0.5,
            fractions: vec![0.07, 0.3, 0.8],
            pairs_per_kind: 4,
            truth_filter: None,
            reports_dir: None,
            only_seeds: Vec::new(),
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
    /// `control`, a library effect's name, `a+b` for a pair (library order) or a rig-only
    /// effect's name.
    pub truth: String,
    /// In the library.
    pub in_library: bool,
    /// Magnitude (of the first effect).
    pub magnitude: f64,
    /// The library effects injected, every parameter given (secondary ones drawn).
    #[serde(default)]
    pub effects: Vec<Effect>,
    /// Relative measurement noise.
    pub noise_rel: f64,
    /// Rig seed.
    pub seed: u64,
    /// Whether the rig writes the input and response accelerometer records (drawn: a real
    /// campaign may weigh only).
    #[serde(default = "records_by_default")]
    pub accelerometers: bool,
}

fn records_by_default() -> bool {
    true
}

/// One campaign's outcome.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// What the rig did.
    pub scenario: Scenario,
    /// Detectability score (see the module documentation).
    pub detectability: f64,
    /// Detectable (score > 2; a pair: each member's score given the other at its closest
    /// magnitude, `member_distinguishable`, > 2 too).
    pub detectable: bool,
    /// A pair's members' detectability, each given the other at its drawn magnitude.
    #[serde(default)]
    pub member_detectability: Vec<f64>,
    /// A pair's members' detectability, each given the other at the magnitude that brings the
    /// other alone closest to the pair's readings (its drawn secondary values kept): a member
    /// the other can stand in for, at some magnitude, is not seen (module `bench`, "Pairs").
    #[serde(default)]
    pub member_distinguishable: Vec<f64>,
    /// Detectable at the drawn magnitudes (the older measure, `member_detectability` over 2).
    #[serde(default)]
    pub detectable_at_drawn: bool,
    /// Tests in which the effect is detectable on their own observations (a pair: the
    /// fewest over the pair against the control and each member given the other). Held-out
    /// tests can confirm an effect only when at least two tests carry it.
    #[serde(default)]
    pub detectable_tests: usize,
    /// Verdict.
    pub verdict: Verdict,
    /// Best effect's name, if any.
    pub chosen: Option<String>,
    /// Shrink of the held-out error, if explained.
    pub shrink: Option<f64>,
    /// Fitted magnitude, if one effect.
    pub fitted_magnitude: Option<f64>,
    /// Every parameter of the named effect(s): value, interval, fitted or held at default.
    #[serde(default)]
    pub fitted: Vec<FittedValue>,
    /// Lack-of-fit p-value of the nominal model.
    pub nominal_p_value: f64,
    /// Groups flagged in `where`.
    pub flagged: Vec<String>,
    /// The truth simulated in the emulator at its drawn values and scored on the campaign
    /// (library effects only): whether the library's model of the truth itself fits within
    /// the noise ([`truth_fit`]).
    #[serde(default)]
    pub truth_fit: Option<TruthFit>,
    /// A pair: the lowest AICc the diagnosis found for either member alone. The pair is
    /// identifiable from the campaign only when its truth fits and beats this: otherwise the
    /// data prefer one member alone, whatever the search.
    #[serde(default)]
    pub best_member_aicc: Option<f64>,
}

/// One parameter of a named effect.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedValue {
    /// `effect.parameter`.
    pub name: String,
    /// Value.
    pub value: f64,
    /// 95 % interval, when fitted.
    pub interval: Option<[f64; 2]>,
    /// Fitted (false: held at the library default).
    pub fitted: bool,
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
    /// Detectable in-library single effects detectable in two or more tests on their own
    /// (held-out tests can confirm them).
    #[serde(default)]
    pub confirmable_in_library: usize,
    /// Of those, the share whose best effect is the true one.
    #[serde(default)]
    pub top1_confirmable: f64,
    /// Detectable in-library single effects detectable in fewer than two tests on their own.
    #[serde(default)]
    pub one_test_singles: usize,
    /// Of those, the share whose leading candidate (`explained` or `partly_explained`) is the
    /// true effect.
    #[serde(default)]
    pub one_test_led_right: f64,
    /// Detectable pairs.
    #[serde(default)]
    pub detectable_pairs: usize,
    /// Detectable pairs detectable in two or more tests on their own (each member given the
    /// other).
    #[serde(default)]
    pub confirmable_pairs: usize,
    /// Of those, the share `explained` by exactly their two effects.
    #[serde(default)]
    pub confirmable_pairs_both_named: f64,
    /// Of those, the share `explained` by exactly their two effects.
    #[serde(default)]
    pub pairs_both_named: f64,
    /// Pairs detectable with each member given the other at its drawn magnitude (the older
    /// measure: it counts a member that the other, at another magnitude, stands in for).
    #[serde(default)]
    pub pairs_detectable_at_drawn: usize,
    /// Of those, the share `explained` by exactly their two effects.
    #[serde(default)]
    pub pairs_at_drawn_both_named: f64,
    /// Detectable pairs whose truth, simulated in the emulator at its drawn values, passes
    /// the lack-of-fit test (`Outcome::truth_fit`): the pairs a search could name.
    #[serde(default)]
    pub pairs_truth_fits: usize,
    /// Detectable pairs the campaign identifies: the truth fits and its AICc beats each
    /// member alone as the diagnosis fitted it (`Outcome::best_member_aicc`).
    #[serde(default)]
    pub identifiable_pairs: usize,
    /// Of those, the share `explained` by exactly their two effects.
    #[serde(default)]
    pub identifiable_pairs_both_named: f64,
    /// Detectable single effects whose truth passes the lack-of-fit test.
    #[serde(default)]
    pub singles_truth_fits: usize,
    /// Campaigns `explained` by an effect that is not (part of) the truth.
    #[serde(default)]
    pub wrong_names: usize,
    /// Their share of every campaign.
    #[serde(default)]
    pub wrong_name_rate: f64,
    /// Campaigns reported `partly_explained`.
    #[serde(default)]
    pub partly_explained: usize,
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
    /// Fitted parameters with a 95 % interval, of the campaigns named right: the magnitudes
    /// and secondary values the diagnosis fitted (measured ones included).
    #[serde(default)]
    pub intervals_checked: usize,
    /// Of those, the share whose interval holds the drawn value (`interval_hits`).
    #[serde(default)]
    pub interval_coverage: f64,
    /// The magnitudes alone: checked and the share held.
    #[serde(default)]
    pub magnitude_intervals_checked: usize,
    /// Of those, the share whose interval holds the drawn magnitude.
    #[serde(default)]
    pub magnitude_interval_coverage: f64,
    /// Undetectable in-library campaigns reported no_gap (share).
    pub undetectable_no_gap: f64,
    /// Detectable single effects drawn without accelerometer records.
    #[serde(default)]
    pub detectable_weighed_only: usize,
    /// Of those, the share whose best effect is the true one.
    #[serde(default)]
    pub top1_weighed_only: f64,
    /// Truth -> answer -> count.
    pub confusion: BTreeMap<String, BTreeMap<String, usize>>,
    /// Every outcome.
    pub outcomes: Vec<Outcome>,
}

/// Secondary parameters of `info` drawn uniformly within their bounds.
fn draw_secondary(info: &EffectInfo, rng: &mut ChaCha20Rng) -> BTreeMap<String, f64> {
    info.parameters[1..]
        .iter()
        .map(|p| (p.name.to_string(), rng.gen_range(p.min..=p.max)))
        .collect()
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
    // Secondary parameters and pairs from their own stream.
    let mut draw = ChaCha20Rng::seed_from_u64(o.seed);
    draw.set_stream(2);
    type Drawn = (String, bool, Vec<Effect>, f64, f64);
    let mut list: Vec<Drawn> = Vec::new();
    let library_effect = |info: &EffectInfo, f: f64, rng: &mut ChaCha20Rng| {
        effect_with(info, f * info.parameters[0].max, &draw_secondary(info, rng))
    };
    let dynamics: Vec<&EffectInfo> = lib
        .iter()
        .copied()
        .filter(|e| e.acts == Acts::Dynamics)
        .collect();
    let wear: Vec<&EffectInfo> = lib
        .iter()
        .copied()
        .filter(|e| e.acts == Acts::WearLaw)
        .collect();
    for &noise in &o.noise_levels {
        for _ in 0..6 {
            list.push(("control".to_string(), true, Vec::new(), 0.0, noise));
        }
        for info in &lib {
            for f in &o.fractions {
                let e = library_effect(info, *f, &mut draw);
                list.push((
                    info.name.to_string(),
                    true,
                    vec![e],
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
                    Vec::new(),
                    f * info.parameters[0].max,
                    noise,
                ));
            }
        }
        // Pairs: a dynamics effect with a wear-law effect, and two dynamics effects.
        for kind in 0..2 {
            for _ in 0..o.pairs_per_kind {
                let Some(a) = dynamics.choose(&mut draw).copied() else {
                    continue;
                };
                let pool: Vec<&EffectInfo> = if kind == 0 {
                    wear.clone()
                } else {
                    dynamics
                        .iter()
                        .copied()
                        .filter(|d| d.name != a.name)
                        .collect()
                };
                let Some(b) = pool.choose(&mut draw).copied() else {
                    continue;
                };
                let (fa, fb) = (
                    *o.fractions.choose(&mut draw).unwrap_or(&0.3),
                    *o.fractions.choose(&mut draw).unwrap_or(&0.3),
                );
                let mut members = vec![
                    library_effect(a, fa, &mut draw),
                    library_effect(b, fb, &mut draw),
                ];
                let rank = |e: &Effect| LIBRARY.iter().position(|l| l.name == e.name);
                members.sort_by_key(rank);
                let name = members
                    .iter()
                    .map(|e| e.name.as_str())
                    .collect::<Vec<_>>()
                    .join("+");
                let m = members[0].magnitude();
                list.push((name, true, members, m, noise));
            }
        }
    }
    let mut rng = ChaCha20Rng::seed_from_u64(o.seed);
    list.shuffle(&mut rng);
    // Accelerometer records drawn per campaign after the order (so the order is the one
    // earlier benches drew): about half the campaigns weigh only.
    let mut records = ChaCha20Rng::seed_from_u64(o.seed ^ 0xacce1);
    let named = |truth: &str| {
        o.truth_filter.as_deref().is_none_or(|f| match f {
            "pairs" => truth.contains('+'),
            _ => truth.split('+').any(|t| t == f),
        })
    };
    Ok(list
        .into_iter()
        .enumerate()
        .map(
            |(i, (truth, in_library, effects, magnitude, noise_rel))| Scenario {
                truth,
                in_library,
                magnitude,
                effects,
                noise_rel,
                seed: o.seed.wrapping_mul(1000).wrapping_add(i as u64),
                accelerometers: records.gen_bool(o.records_share),
            },
        )
        .filter(|s| named(&s.truth))
        .filter(|s| o.only_seeds.is_empty() || o.only_seeds.contains(&s.seed))
        .take(o.campaigns)
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
        accelerometer_rate_hz: s.accelerometers.then_some(o.accelerometer_rate_hz),
        sensor_noise_m_s2: if noisy { o.sensor_noise_m_s2 } else { 0.0 },
        calibration_rel: if noisy {
            o.diagnose.accelerometer_calibration_rel
        } else {
            0.0
        },
        ..RigOptions::default()
    };
    if s.truth != "control" {
        if s.in_library {
            r.effects = s.effects.clone();
        } else {
            r.hidden.push(HiddenEffect::parse(&format!(
                "{}={}",
                s.truth, s.magnitude
            ))?);
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
    detectability_in(effect, control, noise, noisy, |_| true)
}

/// Fractions of a magnitude's bound the search for the closest stand-in starts from.
const STAND_IN_FRACTIONS: [f64; 8] = [0.01, 0.03, 0.07, 0.15, 0.3, 0.5, 0.75, 1.0];

/// Values of each secondary parameter the search for the closest stand-in tries (the
/// profile's spacing, bounds included).
const STAND_IN_SECONDARY_VALUES: usize = 5;

/// Readings of the effect alone at a magnitude and secondary values.
type AloneAt<'a> = dyn Fn(f64, &BTreeMap<String, f64>) -> Result<Vec<Observation>, GapError> + 'a;

/// The closest stand-in found so far: magnitude, secondary values, readings, score.
type StandIn = (f64, BTreeMap<String, f64>, Vec<Observation>, f64);

/// Scores the effect alone at a magnitude and secondary values, keeping the closest.
type TryAt<'a> = dyn Fn(f64, &BTreeMap<String, f64>, &mut StandIn) -> Result<f64, GapError> + 'a;

/// The effect `other` alone at the magnitude and secondary values whose noise-free readings
/// come closest to a pair's (`score`, smaller is closer). Coordinate search from the drawn
/// values (`at_drawn`, their readings and score): the magnitude over [`STAND_IN_FRACTIONS`]
/// of its bound on the drawn magnitude's side and three golden-section steps between the best
/// one's neighbours; then, while the stand-in is still told apart (score > 2), each secondary
/// parameter over [`STAND_IN_SECONDARY_VALUES`] values within its bounds, each with the
/// magnitude over the same fractions, and the golden-section steps at the value that came
/// closest. Returns the closest readings and their score.
fn closest_alone(
    other: &Effect,
    alone_at: &AloneAt,
    score: &dyn Fn(&[Observation]) -> f64,
    at_drawn: (Vec<Observation>, f64),
) -> Result<(Vec<Observation>, f64), GapError> {
    let info = other.info()?;
    let drawn = other.magnitude();
    let bound = if drawn < 0.0 {
        info.parameters[0].min
    } else {
        info.parameters[0].max
    };
    let secondary: BTreeMap<String, f64> = other
        .parameters
        .iter()
        .filter(|(k, _)| k.as_str() != info.parameters[0].name)
        .map(|(k, v)| (k.clone(), *v))
        .collect();
    let mut best: StandIn = (drawn, secondary, at_drawn.0, at_drawn.1);
    let mut tried: Vec<(f64, f64)> = vec![(drawn, best.3)];
    let try_at =
        |m: f64, sec: &BTreeMap<String, f64>, best: &mut StandIn| -> Result<f64, GapError> {
            let obs = alone_at(m, sec)?;
            let d = score(&obs);
            if d < best.3 {
                *best = (m, sec.clone(), obs, d);
            }
            Ok(d)
        };
    // The magnitude over the fractions of its bound at secondary values `sec`: (magnitude,
    // score) each.
    let sweep =
        |sec: &BTreeMap<String, f64>, best: &mut StandIn| -> Result<Vec<(f64, f64)>, GapError> {
            let mut tried = Vec::new();
            for f in STAND_IN_FRACTIONS {
                tried.push((f * bound, try_at(f * bound, sec, best)?));
            }
            Ok(tried)
        };
    let drawn_secondary = best.1.clone();
    tried.extend(sweep(&drawn_secondary, &mut best)?);
    golden_steps(&mut tried, &mut best, &try_at)?;
    for p in &info.parameters[1..] {
        if best.3 <= 2.0 {
            break;
        }
        // Each value with the magnitude searched over the same fractions: a secondary value
        // and the magnitude trade off (a friction drift's slip scale and its size), so a
        // value judged at another value's best magnitude would look worse than it is.
        let drawn_value = best.1.get(p.name).copied();
        let mut by_value: Vec<(f64, Vec<(f64, f64)>)> = Vec::new();
        for v in super::secondary_values::profile_values(p, STAND_IN_SECONDARY_VALUES) {
            if Some(v) == drawn_value {
                continue;
            }
            let mut sec = best.1.clone();
            sec.insert(p.name.to_string(), v);
            by_value.push((v, sweep(&sec, &mut best)?));
        }
        // The golden-section steps at the value that came closest, if it moved.
        if best.1.get(p.name).copied() != drawn_value {
            let chosen = best.1.get(p.name).copied();
            if let Some((_, tried)) = by_value.iter_mut().find(|(v, _)| Some(*v) == chosen) {
                golden_steps(tried, &mut best, &try_at)?;
            }
        }
    }
    Ok((best.2, best.3))
}

/// Three golden-section steps of the magnitude at the best stand-in's secondary values,
/// into the wider side of the best of `tried` (magnitude, score).
fn golden_steps(
    tried: &mut Vec<(f64, f64)>,
    best: &mut StandIn,
    try_at: &TryAt,
) -> Result<(), GapError> {
    for _ in 0..3 {
        tried.sort_by(|a, b| a.0.total_cmp(&b.0));
        let Some(i) = tried
            .iter()
            .enumerate()
            .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
            .map(|(i, _)| i)
        else {
            break;
        };
        let lo = tried[i.saturating_sub(1)].0;
        let hi = tried[(i + 1).min(tried.len() - 1)].0;
        let m = tried[i].0;
        let next = if hi - m > m - lo {
            m + 0.381_966 * (hi - m)
        } else {
            m - 0.381_966 * (m - lo)
        };
        if tried.iter().any(|t| t.0 == next) {
            break;
        }
        let sec = best.1.clone();
        let d = try_at(next, &sec, best)?;
        tried.push((next, d));
    }
    Ok(())
}

/// Tests (indices below `tests`) in which the effect is detectable on that test's
/// observations alone ([`detectability`] over them > 2).
fn detectable_tests(
    effect: &[Observation],
    control: &[Observation],
    noise: &NoiseModel,
    noisy: &[Observation],
    tests: usize,
) -> usize {
    (0..tests)
        .filter(|&t| detectability_in(effect, control, noise, noisy, |o| o.test == t) > 2.0)
        .count()
}

/// [`detectability`] over the observations `keep` selects.
fn detectability_in(
    effect: &[Observation],
    control: &[Observation],
    noise: &NoiseModel,
    noisy: &[Observation],
    keep: impl Fn(&Observation) -> bool,
) -> f64 {
    let terms = effect
        .iter()
        .zip(control)
        .zip(noisy)
        .filter(|(_, o)| keep(o))
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
        effects: Vec::new(),
        noise_rel: 0.0,
        seed: 0,
        accelerometers: true,
    };
    // The control's readings with and without accelerometer records (a campaign is compared
    // with the control taken as it was).
    let mut control_obs_by_records = Vec::new();
    for accelerometers in [false, true] {
        let scenario = Scenario {
            accelerometers,
            ..control_scenario.clone()
        };
        let (clean_control, _) = run_cached(
            skeleton,
            configs_dir,
            &rig_options(&scenario, o, false)?,
            control,
            &cache,
        )?;
        control_obs_by_records.push(observations(&clean_control));
    }
    let mut outcomes = Vec::new();
    for (i, s) in list.iter().enumerate() {
        progress(format!(
            "campaign {}/{}: rig ({} {:.4}, noise {}, {})",
            i + 1,
            list.len(),
            s.truth,
            s.magnitude,
            s.noise_rel,
            if s.accelerometers {
                "with accelerometers"
            } else {
                "weighed only"
            }
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
        let mut member_detectability = Vec::new();
        let mut member_distinguishable = Vec::new();
        let control_obs = &control_obs_by_records[usize::from(s.accelerometers)];
        let tests = skeleton.tests.len();
        let mut in_tests = 0;
        let det = if s.truth == "control" {
            0.0
        } else {
            let mut noisy_obs = observations(&noisy);
            let noise = NoiseModel::estimate(&noisy, &mut noisy_obs, &emulator, &o.diagnose);
            let clean_obs = observations(&clean);
            in_tests = detectable_tests(&clean_obs, control_obs, &noise, &noisy_obs, tests);
            if s.effects.len() == 2 {
                // Each member given the other: the pair against the other member alone, at its
                // drawn magnitude, then at the magnitude that comes closest.
                for drop in 0..2 {
                    let other = &s.effects[1 - drop];
                    let alone_at = |m: f64,
                                    secondary: &BTreeMap<String, f64>|
                     -> Result<Vec<Observation>, GapError> {
                        let info = other.info()?;
                        let one = Scenario {
                            effects: vec![effect_with(info, m, secondary)],
                            ..s.clone()
                        };
                        let (alone, _) = run_cached(
                            skeleton,
                            configs_dir,
                            &rig_options(&one, o, false)?,
                            control,
                            &cache,
                        )?;
                        Ok(observations(&alone))
                    };
                    let score = |alone: &[Observation]| {
                        detectability(&clean_obs, alone, &noise, &noisy_obs)
                    };
                    let drawn = alone_at(other.magnitude(), &other.parameters)?;
                    let at_drawn = score(&drawn);
                    member_detectability.push(at_drawn);
                    let (closest, d) = if at_drawn > 2.0 {
                        closest_alone(other, &alone_at, &score, (drawn, at_drawn))?
                    } else {
                        (drawn, at_drawn)
                    };
                    member_distinguishable.push(d);
                    in_tests = in_tests.min(detectable_tests(
                        &clean_obs, &closest, &noise, &noisy_obs, tests,
                    ));
                }
            }
            detectability(&clean_obs, control_obs, &noise, &noisy_obs)
        };
        let detectable_at_drawn = det > 2.0 && member_detectability.iter().all(|d| *d > 2.0);
        let detectable = det > 2.0 && member_distinguishable.iter().all(|d| *d > 2.0);
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
        // On the campaign's refined copy, after its diagnosis (not counted in `refinements`):
        // the truth's own fit.
        let sim = Simulating {
            campaign: &noisy,
            options: &o.diagnose,
            configs_dir,
            control,
            cache: &cache,
        };
        let truth = truth_fit(sim, &mut refined, &s.effects)?;
        let truth_p = truth
            .as_ref()
            .map_or_else(|| "n/a".to_string(), |t| format!("{:.2e}", t.p_value));
        if let Some(dir) = &o.reports_dir {
            write_report(dir, s, &report)?;
        }
        let chosen = report.best_effect.as_ref().map(|b| b.name.clone());
        outcomes.push(Outcome {
            scenario: s.clone(),
            detectability: det,
            detectable,
            member_detectability,
            member_distinguishable,
            detectable_at_drawn,
            detectable_tests: in_tests,
            verdict: report.verdict,
            shrink: report.best_effect.as_ref().map(|b| b.shrink),
            fitted_magnitude: report
                .best_effect
                .as_ref()
                .filter(|b| !b.name.contains('+'))
                .and_then(|b| b.parameters.first().map(|p| p.value)),
            fitted: report
                .best_effect
                .as_ref()
                .map(|b| {
                    b.parameters
                        .iter()
                        .map(|p| FittedValue {
                            name: format!("{}.{}", p.effect, p.name),
                            value: p.value,
                            interval: p.interval,
                            fitted: p.fitted,
                        })
                        .collect()
                })
                .unwrap_or_default(),
            chosen,
            nominal_p_value: report.nominal.p_value,
            flagged: report
                .location
                .groups
                .iter()
                .filter(|g| g.flagged)
                .map(|g| format!("{}: {} (z {:+.1})", g.by, g.label, g.z))
                .collect(),
            truth_fit: truth,
            best_member_aicc: (s.effects.len() == 2)
                .then(|| {
                    report
                        .ranking
                        .iter()
                        .filter(|r| s.effects.iter().any(|e| e.name == r.name))
                        .map(|r| r.aicc)
                        .min_by(f64::total_cmp)
                })
                .flatten(),
        });
        let last = outcomes.last().map(|x| (x.verdict, x.chosen.clone()));
        progress(format!(
            "  -> {:?} {:?} (detectability {det:.1}, {refinements} refinement windows; the truth's own lack-of-fit p {truth_p})",
            last.as_ref().map(|l| l.0),
            last.and_then(|l| l.1)
        ));
    }
    Ok(score(outcomes))
}

/// Writes `report` and its scenario as `<dir>/<rig seed>.json`.
fn write_report(dir: &Path, s: &Scenario, report: &Report) -> Result<(), GapError> {
    let path = dir.join(format!("{}.json", s.seed));
    let write_error = |x: String| GapError::Write {
        path: path.display().to_string(),
        message: x,
    };
    std::fs::create_dir_all(dir).map_err(|x| write_error(x.to_string()))?;
    let text =
        serde_json::to_string_pretty(&serde_json::json!({ "scenario": s, "report": report }))
            .map_err(|x| write_error(x.to_string()))?;
    std::fs::write(&path, text).map_err(|x| write_error(x.to_string()))
}

fn answer(o: &Outcome) -> String {
    match o.verdict {
        Verdict::NoGap => "no_gap".into(),
        Verdict::NotExplained => "not_explained".into(),
        Verdict::Explained => o.chosen.clone().unwrap_or_else(|| "?".into()),
        Verdict::PartlyExplained => {
            format!("partly: {}", o.chosen.clone().unwrap_or_else(|| "?".into()))
        }
    }
}

fn share(k: usize, n: usize) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        k as f64 / n as f64
    }
}

/// The effect names of a truth or an answer (`a+b` split; none for a control).
fn names(text: &str) -> Vec<&str> {
    if text == "control" {
        Vec::new()
    } else {
        text.split('+').collect()
    }
}

/// Explained by exactly the truth's effects.
fn named_right(o: &Outcome) -> bool {
    let (mut truth, mut chosen) = (
        names(&o.scenario.truth),
        names(o.chosen.as_deref().unwrap_or("")),
    );
    truth.sort_unstable();
    chosen.sort_unstable();
    o.verdict == Verdict::Explained && o.scenario.in_library && truth == chosen
}

/// Every fitted parameter of `o` with an interval whose effect the rig injected: (is it the
/// effect's magnitude, does the interval hold the drawn value). The check the issue asks of
/// every effect ("the diagnosis recovers its magnitude within the reported interval"), on
/// campaigns drawn unlike the bench's defaults.
fn interval_hits(o: &Outcome) -> Vec<(bool, bool)> {
    o.fitted
        .iter()
        .filter(|f| f.fitted)
        .filter_map(|f| {
            let [lo, hi] = f.interval?;
            let (effect, parameter) = f.name.split_once('.')?;
            let drawn = o.scenario.effects.iter().find(|e| e.name == effect)?;
            let info = crate::gap::effects::info(effect)?;
            let value = *drawn.parameters.get(parameter)?;
            let magnitude = info.parameters.first().is_some_and(|p| p.name == parameter);
            Some((magnitude, holds([lo, hi], value)))
        })
        .collect()
}

/// Whether `[lo, hi]` holds `value`, to round-off: the diagnosis' candidate magnitudes are
/// computed between grid points (0.01875 + 3/5 of 0.00375 = 0.020999999999999998) and the
/// rig draws the value as written (0.021), so an endpoint within 1e-9 of the value,
/// relative, holds it.
fn holds([lo, hi]: [f64; 2], value: f64) -> bool {
    let tol = 1e-9 * lo.abs().max(hi.abs()).max(value.abs());
    lo - tol <= value && value <= hi + tol
}

/// Two or more tests carry the effect, so held-out tests can confirm it.
fn confirmable(o: &Outcome) -> bool {
    o.detectable && o.detectable_tests >= 2
}

/// The leading candidate (`explained` or `partly_explained`) is exactly the truth.
fn led_right(o: &Outcome) -> bool {
    let led = o.verdict == Verdict::Explained || o.verdict == Verdict::PartlyExplained;
    led && o.chosen.as_deref() == Some(o.scenario.truth.as_str())
}

/// A confident name that is not the truth: explained by an effect the rig did not inject.
fn truth_fits(o: &Outcome) -> bool {
    o.truth_fit.as_ref().is_some_and(|t| t.fits)
}

/// A pair whose truth fits and beats each member alone by AICc.
fn identifiable(o: &Outcome) -> bool {
    o.truth_fit
        .as_ref()
        .zip(o.best_member_aicc)
        .is_some_and(|(t, single)| t.fits && t.aicc < single)
}

fn named_wrong(o: &Outcome) -> bool {
    if o.verdict != Verdict::Explained {
        return false;
    }
    let truth = if o.scenario.in_library {
        names(&o.scenario.truth)
    } else {
        Vec::new()
    };
    names(o.chosen.as_deref().unwrap_or("?"))
        .iter()
        .any(|n| !truth.contains(n))
}

/// Scores outcomes.
pub fn score(outcomes: Vec<Outcome>) -> Scores {
    let lib: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.scenario.in_library && o.scenario.truth != "control")
        .collect();
    let singles: Vec<&&Outcome> = lib
        .iter()
        .filter(|o| !o.scenario.truth.contains('+'))
        .collect();
    let det_lib: Vec<&&&Outcome> = singles.iter().filter(|o| o.detectable).collect();
    let right: Vec<&&&&Outcome> = det_lib.iter().filter(|o| named_right(o)).collect();
    let weighed_only: Vec<&&&&Outcome> = det_lib
        .iter()
        .filter(|o| !o.scenario.accelerometers)
        .collect();
    let weighed_only_right = weighed_only.iter().filter(|o| named_right(o)).count();
    let det_pairs: Vec<&&Outcome> = lib
        .iter()
        .filter(|o| o.scenario.truth.contains('+') && o.detectable)
        .collect();
    let pairs_right = det_pairs.iter().filter(|o| named_right(o)).count();
    let drawn_pairs: Vec<&&Outcome> = lib
        .iter()
        .filter(|o| o.scenario.truth.contains('+') && o.detectable_at_drawn)
        .collect();
    let conf_pairs: Vec<&&&Outcome> = det_pairs.iter().filter(|o| confirmable(o)).collect();
    let identifiable: Vec<&&&Outcome> = det_pairs.iter().filter(|o| identifiable(o)).collect();
    let conf: Vec<&&&&Outcome> = det_lib.iter().filter(|o| confirmable(o)).collect();
    let one_test: Vec<&&&&Outcome> = det_lib.iter().filter(|o| !confirmable(o)).collect();
    let undet: Vec<&&&Outcome> = singles.iter().filter(|o| !o.detectable).collect();
    let controls: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.scenario.truth == "control")
        .collect();
    let rig_only: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| !o.scenario.in_library && o.detectable)
        .collect();
    let wrong = outcomes.iter().filter(|o| named_wrong(o)).count();
    let mut confusion: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
    for o in &outcomes {
        let row = if o.scenario.truth == "control" || confirmable(o) {
            o.scenario.truth.clone()
        } else if o.detectable {
            format!("{} (one test)", o.scenario.truth)
        } else {
            format!("{} (undetectable)", o.scenario.truth)
        };
        *confusion
            .entry(row)
            .or_default()
            .entry(answer(o))
            .or_insert(0) += 1;
    }
    let shrinks: Vec<f64> = right
        .iter()
        .map(|o| ****o)
        .chain(det_pairs.iter().map(|o| **o).filter(|o| named_right(o)))
        .filter_map(|o| o.shrink)
        .collect();
    let hits: Vec<(bool, bool)> = outcomes
        .iter()
        .filter(|o| named_right(o))
        .flat_map(interval_hits)
        .collect();
    let magnitude_hits: Vec<bool> = hits.iter().filter(|h| h.0).map(|h| h.1).collect();
    Scores {
        campaigns: outcomes.len(),
        detectable_in_library: det_lib.len(),
        top1: share(right.len(), det_lib.len()),
        confirmable_in_library: conf.len(),
        top1_confirmable: share(conf.iter().filter(|o| named_right(o)).count(), conf.len()),
        one_test_singles: one_test.len(),
        one_test_led_right: share(
            one_test.iter().filter(|o| led_right(o)).count(),
            one_test.len(),
        ),
        detectable_pairs: det_pairs.len(),
        confirmable_pairs: conf_pairs.len(),
        confirmable_pairs_both_named: share(
            conf_pairs.iter().filter(|o| named_right(o)).count(),
            conf_pairs.len(),
        ),
        pairs_both_named: share(pairs_right, det_pairs.len()),
        pairs_detectable_at_drawn: drawn_pairs.len(),
        pairs_at_drawn_both_named: share(
            drawn_pairs.iter().filter(|o| named_right(o)).count(),
            drawn_pairs.len(),
        ),
        pairs_truth_fits: det_pairs.iter().filter(|o| truth_fits(o)).count(),
        identifiable_pairs: identifiable.len(),
        identifiable_pairs_both_named: share(
            identifiable.iter().filter(|o| named_right(o)).count(),
            identifiable.len(),
        ),
        singles_truth_fits: det_lib.iter().filter(|o| truth_fits(o)).count(),
        wrong_names: wrong,
        wrong_name_rate: share(wrong, outcomes.len()),
        partly_explained: outcomes
            .iter()
            .filter(|o| o.verdict == Verdict::PartlyExplained)
            .count(),
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
        intervals_checked: hits.len(),
        interval_coverage: share(hits.iter().filter(|h| h.1).count(), hits.len()),
        magnitude_intervals_checked: magnitude_hits.len(),
        magnitude_interval_coverage: share(
            magnitude_hits.iter().filter(|h| **h).count(),
            magnitude_hits.len(),
        ),
        undetectable_no_gap: share(
            undet.iter().filter(|o| o.verdict == Verdict::NoGap).count(),
            undet.len(),
        ),
        detectable_weighed_only: weighed_only.len(),
        top1_weighed_only: share(weighed_only_right, weighed_only.len()),
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
            "| top-1 on detectable single effects ({}) | {} | >= 85 % |\n",
            self.detectable_in_library,
            pct(self.top1)
        ));
        s.push_str(&format!(
            "| of them detectable in two or more tests on their own, which held-out tests can confirm ({}) | {} | >= 85 % |\n",
            self.confirmable_in_library,
            pct(self.top1_confirmable)
        ));
        s.push_str(&format!(
            "| of them detectable in fewer than two tests on their own: leading candidate right ({}) | {} | |\n",
            self.one_test_singles,
            pct(self.one_test_led_right)
        ));
        s.push_str(&format!(
            "| of them weighed only, without accelerometer records ({}) | {} | |\n",
            self.detectable_weighed_only,
            pct(self.top1_weighed_only)
        ));
        s.push_str(&format!(
            "| detectable pairs explained by both members ({}) | {} | >= 60 % |\n",
            self.detectable_pairs,
            pct(self.pairs_both_named)
        ));
        s.push_str(&format!(
            "| of them detectable in two or more tests on their own ({}) | {} | >= 60 % |\n",
            self.confirmable_pairs,
            pct(self.confirmable_pairs_both_named)
        ));
        s.push_str(&format!(
            "| detectable singles / pairs whose truth, simulated in the emulator, passes the lack-of-fit test | {} of {} / {} of {} | |\n",
            self.singles_truth_fits,
            self.detectable_in_library,
            self.pairs_truth_fits,
            self.detectable_pairs
        ));
        s.push_str(&format!(
            "| of them identifiable: the truth fits and beats each member alone by AICc ({}) | {} | |\n",
            self.identifiable_pairs,
            pct(self.identifiable_pairs_both_named)
        ));
        s.push_str(&format!(
            "| pairs detectable at the drawn magnitudes, explained by both members ({}) | {} | |\n",
            self.pairs_detectable_at_drawn,
            pct(self.pairs_at_drawn_both_named)
        ));
        s.push_str(&format!(
            "| wrong names: explained by an effect not injected ({} of {}) | {} | <= 5 % |\n",
            self.wrong_names,
            self.campaigns,
            pct(self.wrong_name_rate)
        ));
        s.push_str(&format!(
            "| partly_explained (not counted as named) | {} | |\n",
            self.partly_explained
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
            "| median held-out shrink where the right effect (or pair) was found | {} | >= 50 % |\n",
            pct(self.median_shrink)
        ));
        s.push_str(&format!(
            "| 95 % intervals of the fitted parameters holding the drawn value, where named right ({}; magnitudes {}) | {} (magnitudes {}) | 95 % |\n",
            self.intervals_checked,
            self.magnitude_intervals_checked,
            pct(self.interval_coverage),
            pct(self.magnitude_interval_coverage)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A friction drift's mass readings after slip distances `l` (m): `delta (1 - e^(-l/s))`.
    fn drift_readings(delta: f64, slip_scale: f64) -> Vec<Observation> {
        [20.0_f64, 200.0, 2000.0]
            .iter()
            .enumerate()
            .map(|(i, l)| Observation {
                test: i,
                increment: 0,
                quantity: super::super::noise::Quantity::Mass("shoe".into()),
                value: delta * (1.0 - (-l / slip_scale).exp()),
                specimens: 1,
                spread: None,
                weight: 1.0,
                fixed_var: 0.0,
                floor_var: 0.0,
                model_rel_var: 0.0,
            })
            .collect()
    }

    #[test]
    fn the_closest_stand_in_is_searched_over_secondary_values_too() {
        // A pair's readings that a friction drift of 0.042 over a 100 m slip scale reproduces
        // exactly (both on the search's grids: 0.07 of the 0.6 bound, the middle of five
        // log-spaced scales over [1, 10⁴] m); the drift was drawn at 0.18 over 997 m. At the
        // drawn scale no magnitude comes within the noise (σ = 10⁻³), at 100 m one does.
        let info = crate::gap::effects::info("friction_drift").expect("in the library");
        let drawn = effect_with(
            info,
            0.18,
            &BTreeMap::from([("slip_scale_m".into(), 997.0)]),
        );
        let target = drift_readings(0.042, 100.0);
        let score = |obs: &[Observation]| {
            let n = obs.len() as f64;
            (obs.iter()
                .zip(&target)
                .map(|(a, b)| ((a.value - b.value) / 1e-3).powi(2))
                .sum::<f64>()
                / n)
                .sqrt()
        };
        let alone_at = |m: f64, sec: &BTreeMap<String, f64>| {
            Ok(drift_readings(
                m,
                sec.get("slip_scale_m").copied().unwrap_or(100.0),
            ))
        };
        let at_drawn = drift_readings(0.18, 997.0);
        let d0 = score(&at_drawn);
        let (_, d) = closest_alone(&drawn, &alone_at, &score, (at_drawn, d0)).expect("searched");
        assert!(d0 > 2.0, "drawn values told apart: {d0}");
        let best_at_drawn_scale = STAND_IN_FRACTIONS
            .iter()
            .map(|f| score(&drift_readings(f * 0.6, 997.0)))
            .fold(f64::INFINITY, f64::min);
        assert!(best_at_drawn_scale > 2.0, "{best_at_drawn_scale}");
        assert!(
            d < 2.0,
            "a stand-in within the noise (0.042 over 100 m) is found: score {d}"
        );
    }

    fn outcome(truth: &str, in_library: bool, verdict: Verdict, chosen: Option<&str>) -> Outcome {
        Outcome {
            scenario: Scenario {
                truth: truth.into(),
                in_library,
                magnitude: 1.0,
                effects: Vec::new(),
                noise_rel: 0.03,
                seed: 0,
                accelerometers: true,
            },
            detectability: 10.0,
            detectable: true,
            member_detectability: Vec::new(),
            member_distinguishable: Vec::new(),
            detectable_at_drawn: true,
            detectable_tests: 4,
            verdict,
            chosen: chosen.map(str::to_string),
            shrink: chosen.map(|_| 0.9),
            fitted_magnitude: None,
            fitted: Vec::new(),
            nominal_p_value: 0.0,
            flagged: Vec::new(),
            truth_fit: None,
            best_member_aicc: None,
        }
    }

    /// A pair is both named whatever the order of its names; naming one member is neither
    /// both named nor wrong; naming an effect the rig did not inject is wrong, and so is any
    /// name for a control or a rig-only effect; `partly_explained` is never a confident name.
    #[test]
    fn pairs_and_wrong_names_are_scored_by_the_truth() {
        let s = score(vec![
            outcome(
                "third_body+cross_axis",
                true,
                Verdict::Explained,
                Some("cross_axis+third_body"),
            ),
            outcome(
                "third_body+cross_axis",
                true,
                Verdict::Explained,
                Some("cross_axis"),
            ),
            outcome(
                "cross_axis",
                true,
                Verdict::Explained,
                Some("fixture_compliance"),
            ),
            outcome("cross_axis", true, Verdict::Explained, Some("cross_axis")),
            outcome(
                "work_hardening",
                false,
                Verdict::Explained,
                Some("friction_drift"),
            ),
            outcome(
                "control",
                true,
                Verdict::PartlyExplained,
                Some("sharp_edges"),
            ),
        ]);
        assert_eq!(s.detectable_pairs, 2);
        assert_eq!(s.pairs_both_named, 0.5);
        assert_eq!(s.detectable_in_library, 2);
        assert_eq!(s.top1, 0.5);
        assert_eq!(s.wrong_names, 2);
        assert_eq!(s.partly_explained, 1);
        assert_eq!(s.controls_clean, 0.0);
    }

    /// A pair counts as identifiable only when its truth fits and beats each member alone by
    /// AICc: a truth that does not fit, or that a member alone beats, no search can name.
    #[test]
    fn a_pair_is_identifiable_when_its_truth_fits_and_beats_each_member_alone() {
        let with = |fits: bool, truth_aicc: f64, member_aicc: f64, chosen: &str| Outcome {
            truth_fit: Some(TruthFit {
                chi2: 0.0,
                dof: 84.0,
                parameters: 4,
                p_value: if fits { 0.5 } else { 1e-30 },
                nll: 0.0,
                aicc: truth_aicc,
                fits,
                by_group: Vec::new(),
                worst: Vec::new(),
            }),
            best_member_aicc: Some(member_aicc),
            ..outcome(
                "friction_drift+cross_axis",
                true,
                Verdict::Explained,
                Some(chosen),
            )
        };
        let s = score(vec![
            with(true, 500.0, 640.0, "friction_drift+cross_axis"),
            with(true, 500.0, 640.0, "cross_axis"),
            with(false, 500.0, 640.0, "cross_axis"),
            with(true, 650.0, 640.0, "cross_axis"),
        ]);
        assert_eq!(s.detectable_pairs, 4);
        assert_eq!(s.pairs_truth_fits, 3);
        assert_eq!(s.identifiable_pairs, 2);
        assert_eq!(s.identifiable_pairs_both_named, 0.5);
    }

    /// Interval coverage counts the fitted parameters of the campaigns named right, against
    /// the values the rig drew: a magnitude and a slip scale whose intervals hold the drawn
    /// ones, a magnitude whose interval misses it; parameters held at their default and
    /// campaigns not named right are not counted.
    #[test]
    fn intervals_are_scored_against_the_drawn_values() {
        let drift = |delta: f64, slip: f64| Effect {
            name: "friction_drift".into(),
            parameters: BTreeMap::from([
                ("delta_mu".to_string(), delta),
                ("slip_scale_m".to_string(), slip),
            ]),
        };
        let fitted = |name: &str, lo: f64, hi: f64, fitted: bool| FittedValue {
            name: format!("friction_drift.{name}"),
            value: 0.5 * (lo + hi),
            interval: Some([lo, hi]),
            fitted,
        };
        let named = |delta: f64, verdict| {
            let mut o = outcome("friction_drift", true, verdict, Some("friction_drift"));
            o.scenario.effects = vec![drift(delta, 7143.0)];
            o.fitted = vec![
                fitted("delta_mu", 0.4838, 0.4886, true),
                fitted("slip_scale_m", 3162.0, 7499.0, true),
            ];
            o
        };
        let mut held = named(0.485, Verdict::Explained);
        held.fitted.push(fitted("slip_scale_m", 0.0, 1.0, false));
        let s = score(vec![
            held,
            named(0.48, Verdict::Explained),
            named(0.48, Verdict::NotExplained),
        ]);
        assert_eq!(s.intervals_checked, 4);
        assert_eq!(s.interval_coverage, 0.75);
        assert_eq!(s.magnitude_intervals_checked, 2);
        assert_eq!(s.magnitude_interval_coverage, 0.5);
        // An endpoint one rounding step from the drawn value holds it; a real miss does not.
        let step = 0.01875 + (0.0225 - 0.01875) * 3.0 / 5.0;
        assert!(step < 0.021);
        assert!(holds([0.020574, step], 0.021));
        assert!(holds([0.021 + (0.021 - step), 0.0216], 0.021));
        assert!(!holds([0.02061, 0.020724], 0.021));
        assert!(!holds([0.0201, 0.0209999], 0.021));
    }

    /// A single effect one test alone carries counts apart: in the top-1 over every detectable
    /// single, not in the top-1 over those two or more tests carry, and its leading candidate
    /// is scored whether the verdict is `explained` or `partly_explained`.
    #[test]
    fn an_effect_one_test_carries_is_scored_apart() {
        let one_test = |verdict, chosen| Outcome {
            detectable_tests: 1,
            ..outcome("friction_drift", true, verdict, chosen)
        };
        let s = score(vec![
            outcome("cross_axis", true, Verdict::Explained, Some("cross_axis")),
            one_test(Verdict::PartlyExplained, Some("friction_drift")),
            one_test(Verdict::PartlyExplained, Some("fixture_compliance")),
        ]);
        assert_eq!(s.detectable_in_library, 3);
        assert_eq!(s.top1, 1.0 / 3.0);
        assert_eq!(s.confirmable_in_library, 1);
        assert_eq!(s.top1_confirmable, 1.0);
        assert_eq!(s.one_test_singles, 2);
        assert_eq!(s.one_test_led_right, 0.5);
    }
}
