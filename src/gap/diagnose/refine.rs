//! Adaptive refinement of the emulator at what the contending candidates' fits land on
//! (docs/results/diagnosis.md, "Adaptive refinement", "Secondary parameters", "Exact pairs"):
//!
//! 1. the dynamics tables of the best single effects, at their fitted magnitudes;
//! 2. when no single effect explains and the leading ones leave lack-of-fit, their secondary
//!    parameters: each profiled over a few values within its bounds (a variant table per
//!    value, simulated near the fitted magnitude), then the best value's neighbours, then the
//!    chosen variant refined at its fitted magnitudes; when a single explains cleanly, its
//!    own secondary parameters the same way, so its intervals are not conditional on the
//!    library defaults;
//! 3. when still no single effect explains cleanly (only partly, or not at all), the pairs
//!    of the best singles: a dynamics effect with a wear-law effect made exact
//!    ([`Emulator::add_pair`]), and every dynamics member refined at the magnitudes the
//!    pair's fits land on (module `pair_search`).

use super::candidate::{requests_of, Candidate};
use super::fit_problem::{FitProblem, Model};
use super::options::{DiagnoseOptions, Simulating, REFINE_CONTENDERS, SECONDARY_CONTENDERS};
use super::pair_search;
use super::report::Report;
use super::secondary_values::{
    midpoints_beside, profile_values, threshold_midpoints_beside, threshold_values,
};
use super::verdict::{diagnose_with, singles_if_gap};
use crate::gap::diagnose::emulator::Emulator;
use crate::gap::effects::{Acts, ParameterInfo};
use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use crate::physics::control::RunControl;
use std::collections::BTreeMap;
use std::path::Path;

/// The diagnosis after adaptive refinement of the emulator (module documentation): the
/// verdict rests on the simulator at the fitted magnitudes and secondary values rather than
/// on interpolation. Nothing is refined when the nominal model shows no gap.
pub fn diagnose_refining(
    campaign: &Campaign,
    emulator: &mut Emulator,
    options: &DiagnoseOptions,
    configs_dir: &Path,
    control: &RunControl,
    cache: &WindowCache,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Report, GapError> {
    // `progress` counts the test simulations of every round: a round's are added to those
    // done before it, so the count never goes back (the total grows by what a round adds).
    let mut done_before = 0;
    if options.refine_rounds > 0 {
        emulator.take_measurements(
            campaign,
            configs_dir,
            control,
            cache,
            options.accelerometer_calibration_rel,
        )?;
    }
    for _ in 0..options.refine_rounds {
        let requests = refinement_requests(campaign, emulator, options);
        if requests.is_empty() {
            break;
        }
        let offset = done_before;
        let cumulative = |done: usize, total: usize| progress(offset + done, offset + total);
        let added = emulator.refine(
            campaign,
            configs_dir,
            &requests,
            control,
            cache,
            &cumulative,
        )?;
        done_before = offset + added * campaign.tests.len();
        if added == 0 {
            break;
        }
    }
    if options.refine_rounds > 0 {
        let sim = Simulating {
            campaign,
            options,
            configs_dir,
            control,
            cache,
        };
        secondary(sim, emulator)?;
        pair_search::exact_pairs(sim, emulator)?;
    }
    diagnose_with(campaign, emulator, options)
}

/// Magnitudes the next refinement round simulates: for the [`REFINE_CONTENDERS`] simulated
/// effects whose held-out fit beats the nominal, the full-data and every training fold's
/// fitted magnitude. Empty when the nominal model shows no gap.
fn refinement_requests(
    campaign: &Campaign,
    emulator: &Emulator,
    options: &DiagnoseOptions,
) -> Vec<(usize, f64)> {
    let problem = FitProblem::new(campaign, emulator, options);
    let Some((nominal, singles)) = singles_if_gap(campaign, &problem, options) else {
        return Vec::new();
    };
    let mut contenders: Vec<&Candidate> = singles
        .iter()
        .filter(|c| emulator.effects[c.table()].simulated)
        .filter(|c| c.held_ll() > nominal.held_ll())
        .collect();
    contenders.sort_by(|a, b| b.held_ll().total_cmp(&a.held_ll()));
    contenders
        .iter()
        .take(REFINE_CONTENDERS)
        .flat_map(|c| requests_of(emulator, c))
        .collect()
}

/// Step 2: when no single effect explains, the [`SECONDARY_CONTENDERS`] best singles that
/// beat the nominal held out but leave lack-of-fit get their secondary parameters profiled
/// (variant tables), then the chosen variant is refined at its fitted magnitudes. Every
/// wear-law effect with a secondary parameter is profiled as well (no simulation needed).
fn secondary(sim: Simulating, emulator: &mut Emulator) -> Result<(), GapError> {
    let (campaign, options, configs_dir, control, cache) = sim.parts();
    // (default table, fitted magnitude at the defaults) of each effect to profile.
    let leaders: Vec<(usize, f64)> = {
        let problem = FitProblem::new(campaign, emulator, options);
        let Some((nominal, singles)) = singles_if_gap(campaign, &problem, options) else {
            return Ok(());
        };
        let clean: Vec<&Candidate> = singles
            .iter()
            .filter(|c| c.explains_cleanly(&nominal, emulator))
            .collect();
        if !clean.is_empty() {
            // A single explains at the library defaults of its other parameters. Its
            // magnitude's interval would be conditional on those defaults, which the data were
            // never asked about (a cross-axis share fitted at phase 0 for a drive at -62°
            // misses the drawn share by 20 % with an interval 0.4 % wide): its secondary
            // values are profiled too, so the report's intervals span them.
            clean
                .iter()
                .filter(|c| emulator.effects[c.table()].info.parameters.len() > 1)
                .filter(|c| c.spec.first().is_some_and(|s| s.1 != 0.0))
                .map(|c| (problem.families[c.families[0]][0], c.spec[0].1))
                .collect()
        } else {
            let mut order: Vec<&Candidate> = singles
                .iter()
                .filter(|c| c.held_ll() > nominal.held_ll())
                .filter(|c| c.residual_p < options.alpha || c.only_partly(&nominal, emulator))
                .filter(|c| emulator.effects[c.table()].info.parameters.len() > 1)
                .filter(|c| c.spec.first().is_some_and(|s| s.1 != 0.0))
                .collect();
            order.sort_by(|a, b| b.held_ll().total_cmp(&a.held_ll()));
            // The best by held-out likelihood, and every single that explains only partly: when
            // one test carries what they explain, the held-out likelihood does not rank them
            // (docs/results/diagnosis.md, "Seen in one test").
            let mut leaders: Vec<(usize, f64)> = order
                .iter()
                .take(SECONDARY_CONTENDERS)
                .chain(
                    order
                        .iter()
                        .skip(SECONDARY_CONTENDERS)
                        .filter(|c| c.explains(&nominal)),
                )
                .map(|c| (problem.families[c.families[0]][0], c.spec[0].1))
                .collect();
            // Every wear-law effect with a secondary parameter is profiled too, whatever its
            // default's fit: a threshold (a breakthrough distance, a pressure ratio) can put the
            // whole effect outside the campaign at its default and inside at another value, and
            // its variants cost no simulation (they are evaluated on the recorded windows).
            for family in &problem.families {
                let default_table = family[0];
                let info = emulator.effects[default_table].info;
                let listed = leaders.iter().any(|l| l.0 == default_table);
                if info.acts == Acts::WearLaw && info.parameters.len() > 1 && !listed {
                    leaders.push((default_table, 0.0));
                }
            }
            leaders
        }
    };
    for (default_table, m) in &leaders {
        profile_secondary(sim, emulator, *default_table, *m)?;
    }
    if leaders.is_empty() {
        return Ok(());
    }
    // The chosen variants at their fitted magnitudes.
    let requests: Vec<(usize, f64)> = {
        let problem = FitProblem::new(campaign, emulator, options);
        leaders
            .iter()
            .map(|(t, _)| problem.family_of(*t))
            .flat_map(|f| requests_of(emulator, &problem.evaluate(Model::Single(f), options.alpha)))
            .collect()
    };
    emulator.refine(campaign, configs_dir, &requests, control, cache, &|_, _| {})?;
    Ok(())
}

/// Profiles each secondary parameter of the effect of `default_table` (fitted magnitude `m`
/// at the defaults): variants at [`profile_values`], then at the midpoints between the best
/// value and its neighbours (once for a dynamics effect, four times for a wear law); with two
/// or more secondary parameters, a variant at every best value together.
fn profile_secondary(
    sim: Simulating,
    emulator: &mut Emulator,
    default_table: usize,
    m: f64,
) -> Result<(), GapError> {
    let (campaign, _, configs_dir, control, cache) = sim.parts();
    let info = emulator.effects[default_table].info;
    let magnitudes: Vec<f64> = match info.acts {
        Acts::WearLaw => Vec::new(),
        // The default table's grid on the fitted magnitude's side, and the fitted magnitude:
        // another secondary value may move the magnitude that fits.
        Acts::Dynamics => emulator.effects[default_table]
            .magnitudes
            .iter()
            .copied()
            .filter(|g| *g != 0.0 && (*g < 0.0) == (m < 0.0))
            .filter(|g| g.abs() >= 0.1 * m.abs())
            .chain([m])
            .collect(),
    };
    // A wear-law variant costs no simulation, and a threshold (where the extra wear starts)
    // moves the fit sharply: nine first values and four bisections towards the best, against
    // five and one for a simulated dynamics variant.
    let (first, bisections) = match info.acts {
        Acts::WearLaw => (9, 4),
        Acts::Dynamics => (5, 1),
    };
    let mut bests: BTreeMap<String, f64> = BTreeMap::new();
    let secondaries = emulator.unmeasured_secondaries(info);
    // A wear law with two thresholds (third body's pressure and slip speed) can hide behind
    // either: one profiled with the other at its default finds nothing when both must be
    // lowered. A second pass profiles each with the others at their bests from the first.
    let passes = if info.acts == Acts::WearLaw && secondaries.len() > 1 {
        2
    } else {
        1
    };
    for pass in 0..passes {
        for &p in &secondaries {
            let others: BTreeMap<String, f64> = if pass == 0 {
                BTreeMap::new()
            } else {
                bests
                    .iter()
                    .filter(|(n, v)| {
                        n.as_str() != p.name
                            && info
                                .parameters
                                .iter()
                                .any(|q| q.name == *n && q.default != **v)
                    })
                    .map(|(n, v)| (n.clone(), *v))
                    .collect()
            };
            let best = profile_one(
                sim,
                emulator,
                default_table,
                (p, others),
                &magnitudes,
                (first, bisections),
            )?;
            bests.insert(p.name.to_string(), best);
        }
    }
    let non_default: BTreeMap<String, f64> = bests
        .into_iter()
        .filter(|(n, v)| {
            info.parameters
                .iter()
                .find(|p| p.name == n)
                .is_some_and(|p| p.default != *v)
        })
        .collect();
    if non_default.len() > 1 {
        emulator.add_variant(
            campaign,
            configs_dir,
            default_table,
            non_default,
            &magnitudes,
            control,
            cache,
        )?;
    }
    Ok(())
}

/// One secondary parameter `p` of the effect of `default_table` profiled with the other
/// secondary values `others` held: variants at its first values, then `bisections` passes
/// midway to the best value's neighbours; its best value. A wear law's threshold from 0 is
/// profiled over its whole range on a log scale ([`threshold_values`]).
fn profile_one(
    sim: Simulating,
    emulator: &mut Emulator,
    default_table: usize,
    (p, others): (&ParameterInfo, BTreeMap<String, f64>),
    magnitudes: &[f64],
    (first, bisections): (usize, usize),
) -> Result<f64, GapError> {
    let (campaign, options, configs_dir, control, cache) = sim.parts();
    let wear_law = emulator.effects[default_table].info.acts == Acts::WearLaw;
    let mut values = if wear_law {
        threshold_values(p, first)
    } else {
        profile_values(p, first)
    };
    let mut tables = Vec::new();
    let add = |emulator: &mut Emulator, v: f64| {
        let mut values = others.clone();
        values.insert(p.name.to_string(), v);
        emulator.add_variant(
            campaign,
            configs_dir,
            default_table,
            values,
            magnitudes,
            control,
            cache,
        )
    };
    for &v in &values {
        tables.push(add(emulator, v)?);
    }
    let mut best = best_value(campaign, emulator, options, &tables, p.name);
    // Further passes: midway to the best value's neighbours among the values tried.
    for _ in 0..bisections {
        values.sort_by(f64::total_cmp);
        let Some(i) = values.iter().position(|v| *v == best) else {
            break;
        };
        let more = if wear_law {
            threshold_midpoints_beside(p, &values, i)
        } else {
            midpoints_beside(p, &values, i)
        };
        for v in more {
            tables.push(add(emulator, v)?);
            values.push(v);
        }
        best = best_value(campaign, emulator, options, &tables, p.name);
    }
    Ok(best)
}

/// The value of parameter `name` among `tables` whose best full-data fit is best.
fn best_value(
    campaign: &Campaign,
    emulator: &Emulator,
    options: &DiagnoseOptions,
    tables: &[usize],
    name: &str,
) -> f64 {
    let problem = FitProblem::new(campaign, emulator, options);
    tables
        .iter()
        .map(|&t| (t, problem.fit_table(t, &|_| true).1))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(f64::NAN, |(t, _)| emulator.effects[t].parameter(name))
}
