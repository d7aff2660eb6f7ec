//! The bench's run: one emulator on the skeleton, each campaign drawn by the rig, diagnosed
//! without its truth, its truth's own fit and detectability measured, then scored.

use super::confirm;
use super::detectability::{closest_alone, detectability, detectable_tests};
use super::scenarios::{rig_options, scenarios};
use super::scores::{score, Scores};
use super::{BenchOptions, FittedValue, Outcome, Scenario};
use crate::cases::RunControl;
use crate::gap::diagnose::emulator::{effect_with, Emulator};
use crate::gap::diagnose::noise::{observations, NoiseModel, Observation};
use crate::gap::diagnose::truth_fit::truth_fit;
use crate::gap::diagnose::{diagnose_refining, Report, Simulating};
use crate::gap::rig::{run_cached, Truth};
use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use std::collections::BTreeMap;
use std::path::Path;

/// Runs the bench. `progress(message)` reports each step; `done(outcomes)` is called with
/// every outcome so far after each campaign (so a long run's finished campaigns can be kept
/// before it ends).
pub fn run(
    skeleton: &Campaign,
    configs_dir: &Path,
    o: &BenchOptions,
    control: &RunControl,
    emulator_file: Option<&Path>,
    progress: &(dyn Fn(String) + Sync),
    done: &(dyn Fn(&[Outcome]) + Sync),
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
            write_report(dir, s, "", &report)?;
        }
        let chosen = report.best_effect.as_ref().map(|b| b.name.clone());
        let mut outcome = Outcome {
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
                            identified: p.identified,
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
            next_test: None,
        };
        if o.confirm && confirm::eligible(&outcome) {
            let (next, after) = confirm::confirm(
                skeleton,
                &noisy,
                &report,
                s,
                o,
                configs_dir,
                control,
                &cache,
            )?;
            if let (Some(dir), Some(after)) = (&o.reports_dir, &after) {
                write_report(dir, s, "-after", after)?;
            }
            progress(format!(
                "  next test {} -> {:?} {:?}{}; the truth's own lack-of-fit p with it {}",
                next.test,
                next.verdict,
                next.chosen,
                if next.confirmed { " (confirmed)" } else { "" },
                next.truth_p_after
                    .map_or_else(|| "n/a".to_string(), |p| format!("{p:.2e}"))
            ));
            outcome.next_test = Some(next);
        }
        outcomes.push(outcome);
        done(&outcomes);
        let last = outcomes.last().map(|x| (x.verdict, x.chosen.clone()));
        progress(format!(
            "  -> {:?} {:?} (detectability {det:.1}, {refinements} refinement windows; the truth's own lack-of-fit p {truth_p})",
            last.as_ref().map(|l| l.0),
            last.and_then(|l| l.1)
        ));
    }
    Ok(score(outcomes))
}

/// Writes `report` and its scenario as `<dir>/<rig seed><suffix>.json` (the confirm step's
/// report after its next test: suffix `-after`).
fn write_report(dir: &Path, s: &Scenario, suffix: &str, report: &Report) -> Result<(), GapError> {
    let path = dir.join(format!("{}{suffix}.json", s.seed));
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
