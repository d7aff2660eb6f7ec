//! The verdict on one way of holding data out: the candidates ranked, the one named (or the
//! pair, or the member pairs share), `explained`, `partly_explained`, `not_explained` or
//! `no_gap`, and the report; and the campaign judged again by increment when one test carries
//! the leading effect.

use super::candidate::Candidate;
use super::emulator::Emulator;
use super::fit_problem::{held_out_by_test, FitProblem, Model};
use super::how_far::{best_effect, held_out_predictions, partly_explained};
use super::one_group::{carried_by_one_group, one_group_single, seen_in_one_group, OneGroup};
use super::options::{DiagnoseOptions, MIN_HELD_OUT_GAIN};
use super::report::{
    BestEffect, EmulatorReport, GroupError, NominalFit, PartlyExplained, RankEntry, Report, Verdict,
};
use super::{location, stats};
use crate::gap::{Campaign, GapError};

/// The member every pair of `within` (the chosen pair first, then the explaining pairs the
/// report lists as indistinguishable from it) shares, when there are two or more and they
/// share only that one: which partner goes with it, the data do not say (seed 1043 of the
/// bench: a cross-axis share fitted beside severe wear, beside a fixture compliance and beside
/// wear above the cutoff, held-out errors 1.244, 1.235 and 743, the last first in a tenth of
/// the bootstrap resamples). Returns the member's family.
pub(super) fn shared_member(pairs: &[Candidate], within: &[usize]) -> Option<usize> {
    let (&first, rest) = within.split_first()?;
    let shared: Vec<usize> = pairs[first]
        .families
        .iter()
        .copied()
        .filter(|f| rest.iter().all(|&i| pairs[i].families.contains(f)))
        .collect();
    match shared[..] {
        [f] if !rest.is_empty() => Some(f),
        _ => None,
    }
}

/// A campaign with nothing measured (a skeleton for the rig) cannot be diagnosed.
pub(super) fn no_measurement() -> GapError {
    GapError::field(
        "tests",
        "the campaign has no measurement to diagnose (every mass_loss_mg is empty)",
    )
}

/// The diagnosis on an emulator already built for `campaign` (the bench reuses one emulator
/// for many campaigns drawn on the same tests).
pub fn diagnose_with(
    campaign: &Campaign,
    emulator: &Emulator,
    options: &DiagnoseOptions,
) -> Result<Report, GapError> {
    let problem = FitProblem::new(campaign, emulator, options);
    if problem.obs.is_empty() {
        return Err(no_measurement());
    }
    let (report, carried) = judge(campaign, emulator, options, &problem, None);
    let Some(carried) = carried.filter(|_| held_out_by_test(campaign)) else {
        return Ok(report);
    };
    // Held out by test, an effect one test carries has nothing to be fitted on when that test
    // is left out. Its increments can still judge it (as in a campaign of fewer than three
    // tests): fitted on the other increments of every test, it must predict the one left out.
    // What that confirms holds within the one test only, so it names a leading candidate
    // (`partly_explained`), never more.
    let scope = format!(
        "confirmed by increment within one test only: held out by test, {carried} and leaves nothing to fit it on"
    );
    let by_increment = FitProblem::with_folds(campaign, emulator, options, false);
    if by_increment.groups < 2 {
        return Ok(report);
    }
    let (mut within, _) = judge(campaign, emulator, options, &by_increment, Some(&scope));
    tracing::debug!(verdict = ?within.verdict, summary = %within.summary, "judged again by increment");
    // Confirmed by increment means every increment predicted held out; one it does not
    // predict confirms nothing, and the report held out by test stands (it names the test
    // that carries the effect).
    let confirmed = within.verdict == Verdict::PartlyExplained
        && within
            .partly_explained
            .as_ref()
            .is_none_or(|p| p.unpredicted.is_empty());
    if !confirmed {
        return Ok(report);
    }
    within.held_out = format!("leave-one-increment-out, as {carried}");
    // Increments name no test to repeat; the tests held out by test could not confirm are
    // still the ones to repeat.
    within.to_repeat = report.to_repeat;
    within.carried_by = report.carried_by;
    Ok(within)
}

/// The verdict on one way of holding data out, and, when one held-out group carries what the
/// leading single explains (so the held-out fits cannot confirm it), which group and how much.
/// `scope`, when given, is a reason every named candidate explains only partly.
pub(super) fn judge(
    campaign: &Campaign,
    emulator: &Emulator,
    options: &DiagnoseOptions,
    problem: &FitProblem,
    scope: Option<&str>,
) -> (Report, Option<String>) {
    let alpha = options.alpha;
    let nominal = problem.evaluate(Model::Nominal, alpha);
    let nominal_score = problem.totals(&[], &|_| true);
    let (chi2, dof) = (nominal_score.r2, nominal_score.w);
    let nominal_p = stats::lack_of_fit_p(chi2, dof, 0.0);
    let location = location::locate(campaign, problem);
    let any_flag = location.any_flagged();

    let singles: Vec<Candidate> = (0..problem.families.len())
        .map(|f| problem.evaluate(Model::Single(f), alpha))
        .collect();
    let mut order: Vec<usize> = (0..singles.len()).collect();
    order.sort_by(|a, b| singles[*b].held_ll().total_cmp(&singles[*a].held_ll()));

    let no_gap = nominal_p >= alpha && !any_flag;
    let mut pairs: Vec<Candidate> = Vec::new();
    let explaining_singles: Vec<usize> = order
        .iter()
        .copied()
        .filter(|&i| singles[i].explains(&nominal))
        .collect();
    // A single that explains only partly (fitted at a bound, or a small held-out shrink)
    // leaves room for a second effect: the pairs are tried then too.
    let clean_single = singles
        .iter()
        .any(|c| c.explains_cleanly(&nominal, emulator));
    if !no_gap && !clean_single {
        pairs = problem
            .pair_models(&singles, &nominal)
            .into_iter()
            .map(|m| problem.evaluate(m, alpha))
            .collect();
        pairs.sort_by(|a, b| b.held_ll().total_cmp(&a.held_ll()));
    }

    // Bootstrap over held-out groups: P(first) among the nominal, singles and pairs.
    let all: Vec<&Candidate> = std::iter::once(&nominal)
        .chain(singles.iter())
        .chain(pairs.iter())
        .collect();
    let resamples = stats::bootstrap_indices(problem.groups, options.bootstrap_rounds, 0x5eed);
    let mut firsts = vec![0usize; all.len()];
    for idx in &resamples {
        let best = all
            .iter()
            .enumerate()
            .map(|(i, c)| (i, -idx.iter().map(|g| c.held_nll[*g]).sum::<f64>()))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(0, |(i, _)| i);
        firsts[best] += 1;
    }
    let p_first = |i: usize| firsts[i] as f64 / resamples.len().max(1) as f64;
    let gain_interval = |c: &Candidate| -> [f64; 2] {
        let gains: Vec<f64> = resamples
            .iter()
            .map(|idx| {
                idx.iter()
                    .map(|g| nominal.held_nll[*g] - c.held_nll[*g])
                    .sum()
            })
            .collect();
        [stats::quantile(&gains, 0.05), stats::quantile(&gains, 0.95)]
    };
    let entry = |c: &Candidate, i: usize| RankEntry {
        name: problem.name_of(&c.families),
        magnitudes: c.magnitudes(),
        secondary: {
            let values: Vec<_> = c
                .spec
                .iter()
                .map(|(t, _)| problem.emulator.effects[*t].parameters.clone())
                .collect();
            if values.iter().all(|v| v.is_empty()) {
                Vec::new()
            } else {
                values
            }
        },
        parameters: c.k.round() as usize,
        held_out_log_likelihood: c.held_ll(),
        held_out_gain: c.held_ll() - nominal.held_ll(),
        held_out_gain_interval: gain_interval(c),
        held_out_error: c.held_error(),
        aicc: c.aicc,
        bic: c.bic,
        residual_p_value: c.residual_p,
        p_first: p_first(i),
        explained_share: c.explained_share(&nominal),
        explains: c.explains(&nominal),
        refused_by_records: problem.refused_by_records(&c.spec),
    };
    let ranking: Vec<RankEntry> = order.iter().map(|&i| entry(&singles[i], 1 + i)).collect();
    let pair_entries: Vec<RankEntry> = pairs
        .iter()
        .enumerate()
        .map(|(j, c)| entry(c, 1 + singles.len() + j))
        .collect();

    // Why a pair's member is named alone (set where the pairs share one member only).
    let mut unidentified: Option<String> = None;
    let chosen: Option<(&Candidate, Vec<String>)> = if no_gap {
        None
    } else if let Some(&first) = explaining_singles.first().filter(|&&first| {
        // A pair that explains cleanly and beats the partial single held out is named
        // instead.
        clean_single
            || !pairs.iter().any(|p| {
                p.explains_cleanly(&nominal, emulator)
                    && p.held_ll() - singles[first].held_ll() > MIN_HELD_OUT_GAIN
            })
    }) {
        // When the held-out error the first leaves hardly shrinks because one group carries
        // what it explains, no held-out fit predicts that group and the held-out likelihood
        // ranks the explaining singles by how they mispredict it: they are ranked by their
        // full-data AICc instead (docs/results/diagnosis.md, "Seen in one test").
        let c = &singles[first];
        let best =
            if c.only_partly(&nominal, emulator) && carried_by_one_group(problem, c).is_some() {
                explaining_singles
                    .iter()
                    .copied()
                    .min_by(|a, b| singles[*a].aicc.total_cmp(&singles[*b].aicc))
                    .unwrap_or(first)
            } else {
                first
            };
        let b = &singles[best];
        let others = explaining_singles
            .iter()
            .filter(|&&i| i != best)
            .filter(|&&i| {
                b.held_ll() - singles[i].held_ll() < MIN_HELD_OUT_GAIN || p_first(1 + i) >= 0.1
            })
            .map(|&i| problem.name_of(&singles[i].families))
            .collect();
        Some((b, others))
    } else {
        // Beside a partial single, only the pairs that explain cleanly.
        let explaining: Vec<usize> = (0..pairs.len())
            .filter(|&j| pairs[j].explains(&nominal))
            .filter(|&j| explaining_singles.is_empty() || !pairs[j].only_partly(&nominal, emulator))
            .collect();
        // The first, and those it cannot be told from held out.
        let within: Vec<usize> = explaining
            .first()
            .map(|&j| {
                std::iter::once(j)
                    .chain(explaining[1..].iter().copied().filter(|&i| {
                        pairs[j].held_ll() - pairs[i].held_ll() < MIN_HELD_OUT_GAIN
                            || p_first(1 + singles.len() + i) >= 0.1
                    }))
                    .collect()
            })
            .unwrap_or_default();
        let names: Vec<String> = within
            .iter()
            .map(|&i| problem.name_of(&pairs[i].families))
            .collect();
        if let Some(f) = shared_member(&pairs, &within) {
            // The pairs agree on one member only: the data name that member, not its
            // partner.
            unidentified = Some(format!(
                "its partner is not identified: {} are indistinguishable held out",
                names.join(", ")
            ));
            Some((&singles[f], names))
        } else {
            within
                .first()
                .map(|&j| (&pairs[j], names.into_iter().skip(1).collect()))
        }
    };

    let best_effect = chosen
        .as_ref()
        .map(|(c, _)| best_effect(problem, c, &nominal, &resamples));
    // A candidate whose magnitude's 95 % interval holds 0 is not named: the data do not tell
    // it from no effect, so what it removes of the gap is not its doing.
    let absent = best_effect.as_ref().and_then(zero_in_magnitude_interval);
    let (chosen, best_effect) = match absent {
        Some(_) => (None, None),
        None => (chosen, best_effect),
    };
    let chosen_candidate: Option<&Candidate> = chosen.as_ref().map(|(c, _)| *c);
    // What the verdict predicts for each withheld group: the named effect's or pair's fits
    // without that group; with nothing named, the best-ranked single's.
    let held_out_predictions = chosen_candidate
        .or_else(|| order.first().map(|&i| &singles[i]))
        .map(|c| held_out_predictions(campaign, problem, c))
        .unwrap_or_default();
    let partly = chosen
        .as_ref()
        .zip(best_effect.as_ref())
        .and_then(|((c, others), b)| {
            // Candidates that predict the withheld data alike: the data do not tell them
            // apart, so none of them is named `explained` (a pair member named because its
            // partner is not identified says so already).
            let alike = (unidentified.is_none() && !others.is_empty()).then(|| {
                format!(
                    "indistinguishable held out from {}: the data do not tell them apart",
                    others.join(", ")
                )
            });
            let also: Vec<&str> = unidentified
                .iter()
                .chain(alike.iter())
                .map(String::as_str)
                .chain(scope)
                .collect();
            partly_explained(problem, c, b, (!also.is_empty()).then(|| also.join("; ")))
        });
    let verdict = if no_gap {
        Verdict::NoGap
    } else if partly.is_some() {
        Verdict::PartlyExplained
    } else if chosen.is_some() {
        Verdict::Explained
    } else {
        Verdict::NotExplained
    };
    // The candidate the summary reports as carried by one group: the chosen one when it
    // explains only partly, the best single that fits within the noise when none explains.
    let one_group: Option<OneGroup> = match verdict {
        Verdict::PartlyExplained => chosen_candidate
            .and_then(|c| carried_by_one_group(problem, c).map(|(g, share)| (c, g, share))),
        Verdict::NotExplained => one_group_single(problem, &singles, &nominal, alpha),
        _ => None,
    };
    // A pair member named because its partner is not identified was confirmed by the pairs
    // held out as they are; only a single's one-group share asks for another way to hold out.
    let carried = one_group
        .filter(|_| verdict == Verdict::NotExplained || unidentified.is_none())
        .map(|(c, g, share)| {
            format!(
                "{} carries {:.0} % of what {} explains",
                problem.group_labels[g],
                100.0 * share,
                problem.name_of(&c.families)
            )
        });
    let to_repeat = tests_to_repeat(campaign, problem, partly.as_ref());
    // Held out by test, the group labels are the tests' ids.
    let carried_by = one_group
        .filter(|_| problem.by_test())
        .map(|(_, g, _)| problem.group_labels[g].clone());
    let indistinguishable = chosen.map(|(_, o)| o).unwrap_or_default();
    let summary = match verdict {
        Verdict::NoGap => format!(
            "no gap: the nominal model fits within the uncertainty (chi2 {chi2:.1} on {dof:.1} dof, p = {nominal_p:.3}; no group flagged)"
        ),
        Verdict::Explained => {
            let b = best_effect.as_ref();
            format!(
                "explained by {}: held-out error {:.2} -> {:.2} (shrink {:.0} %)",
                b.map_or("?", |b| b.name.as_str()),
                b.map_or(f64::NAN, |b| b.held_out_error_before),
                b.map_or(f64::NAN, |b| b.held_out_error_after),
                b.map_or(f64::NAN, |b| 100.0 * b.shrink),
            )
        }
        Verdict::PartlyExplained => {
            let mut text = partly
                .as_ref()
                .map_or_else(String::new, PartlyExplained::sentence);
            if let Some((_, g, share)) = one_group {
                text.push_str(&format!(
                    "; {} carries {:.0} % of what it explains, so held out it has nothing to be fitted on: more tests like {} could confirm it",
                    problem.group_labels[g],
                    100.0 * share,
                    problem.group_labels[g],
                ));
            }
            text
        }
        Verdict::NotExplained => {
            let mut text = format!(
                "not explained: a gap (p = {nominal_p:.2e}) that no effect of the library (nor pair) fits on held-out data with residuals consistent with noise"
            );
            if let Some(seen) = one_group {
                text.push_str("; ");
                text.push_str(&seen_in_one_group(problem, seen));
            }
            if let Some(absent) = &absent {
                text.push_str("; ");
                text.push_str(absent);
            }
            text
        }
    };
    let summary = summary + &parameter_notes(best_effect.as_ref());
    let report = Report {
        campaign: campaign.name.clone(),
        verdict,
        summary,
        best_effect,
        indistinguishable,
        ranking,
        pairs: pair_entries,
        location,
        nominal: NominalFit {
            chi2,
            dof,
            p_value: nominal_p,
            held_out_log_likelihood: nominal.held_ll(),
            held_out_error: nominal.held_error(),
        },
        noise: problem.noise.report(),
        held_out: problem.held_out.clone(),
        multiple_comparisons: format!("Holm step-down over every group of `where` (family-wise error rate 0.05); over the held-out groups' errors with the named candidate (family-wise error rate alpha = {alpha})"),
        alpha,
        emulator: EmulatorReport {
            window_s: emulator.options.window_s,
            settle_s: emulator.options.settle_s,
            simulations: emulator.simulations,
            grid_points: emulator.options.grid_points,
            approximations: vec![
                "each increment is represented by one simulated window (wear scaled by increment / window); dynamics effects of time or slip see the state at the increment's middle".into(),
                "dynamics effects are simulated on a grid of magnitudes and interpolated log-linearly between grid points".into(),
                "a dynamics effect with a wear-law effect is exact once refined (the wear law on the dynamics effect's own tracks); two dynamics effects combine as the product of their ratios to the nominal times an interaction the joint simulations measure (exact at each joint point, interpolated between them, none where either is off)".into(),
                "secondary parameters are fitted only for the leading effects that leave lack-of-fit (profiled over a few values within their bounds); otherwise they are held at the library defaults".into(),
                "specimen scatter is common to a specimen's increments; that correlation is not modelled".into(),
            ],
        },
        held_out_predictions,
        partly_explained: partly,
        to_repeat,
        carried_by,
        next_tests: Vec::new(),
        code_version: crate::models::case::code_version().to_string(),
    };
    (report, carried)
}

/// Why a candidate is not named although it passes the explaining rules: a member's magnitude
/// whose 95 % interval holds 0, the effect off (`cross_axis fits at share 6e-6, 95 % interval
/// [0, 0.00975] holding 0: ...`). A dynamics effect fitted at a vanishing magnitude changes the
/// simulated windows only as any perturbation of a chaotic rattle does (bench campaigns 1001
/// and 3030: a rig-only surface oxide and work hardening, each named cross_axis at a share of
/// 6e-6 whose drive the records could not see); that is the simulator's window-to-window
/// spread, not the effect.
fn zero_in_magnitude_interval(b: &BestEffect) -> Option<String> {
    let held: Vec<String> = b
        .parameters
        .iter()
        .filter(|p| {
            crate::gap::effects::info(&p.effect)
                .is_some_and(|info| info.parameters[0].name == p.name)
        })
        .filter_map(|p| {
            let [lo, hi] = p.interval?;
            (lo <= 0.0 && 0.0 <= hi).then(|| {
                format!(
                    "{}.{} = {:.3e} {}, 95 % interval [{lo:.3e}, {hi:.3e}] holds 0",
                    p.effect, p.name, p.value, p.unit
                )
            })
        })
        .collect();
    (!held.is_empty()).then(|| {
        format!(
            "{} fits only where the data do not tell it from no effect ({}): what it removes of the gap is not its doing, and it is not named",
            b.name,
            held.join("; ")
        )
    })
}

/// What the summary adds on the named candidate's parameters: those the data do not identify
/// (no value given for them) and those whose interval reaches a physical bound.
fn parameter_notes(best: Option<&BestEffect>) -> String {
    let Some(b) = best else {
        return String::new();
    };
    let unidentified: Vec<String> = b
        .parameters
        .iter()
        .filter(|p| p.fitted && !p.identified)
        .map(|p| p.label())
        .collect();
    let at_bound: Vec<String> = b
        .parameters
        .iter()
        .filter(|p| p.identified && !p.bounds_reached.is_empty())
        .map(|p| format!("{} ({})", p.label(), p.bounds_reached.join(", ")))
        .collect();
    let mut out = String::new();
    if !unidentified.is_empty() {
        out.push_str(&format!(
            "; not identified by the data: {}",
            unidentified.join(", ")
        ));
    }
    if !at_bound.is_empty() {
        out.push_str(&format!(
            "; 95 % interval reaching a physical bound: {}",
            at_bound.join(", ")
        ));
    }
    out
}

/// The nominal model and every single effect evaluated, when the nominal model shows a gap
/// (None otherwise).
pub(super) fn singles_if_gap(
    campaign: &Campaign,
    problem: &FitProblem,
    options: &DiagnoseOptions,
) -> Option<(Candidate, Vec<Candidate>)> {
    if problem.obs.is_empty() {
        return None;
    }
    let nominal = problem.evaluate(Model::Nominal, options.alpha);
    let nominal_p = stats::lack_of_fit_p(nominal.chi2, nominal.dof, 0.0);
    if nominal_p >= options.alpha && !location::locate(campaign, problem).any_flagged() {
        return None;
    }
    let singles = (0..problem.families.len())
        .map(|f| problem.evaluate(Model::Single(f), options.alpha))
        .collect();
    Some((nominal, singles))
}

/// [`singles_if_gap`] when no single effect explains cleanly (None otherwise): where the
/// refinement's secondary and pair steps start (a single that explains only partly leaves
/// room for them).
pub(super) fn singles_unexplained(
    campaign: &Campaign,
    problem: &FitProblem,
    options: &DiagnoseOptions,
    emulator: &Emulator,
) -> Option<(Candidate, Vec<Candidate>)> {
    let (nominal, singles) = singles_if_gap(campaign, problem, options)?;
    let clean = singles
        .iter()
        .any(|c| c.explains_cleanly(&nominal, emulator));
    (!clean).then_some((nominal, singles))
}

/// The campaign tests whose repeats would let held-out data confirm the leading candidate
/// (`Report::to_repeat`), held out by test only: the tests it cannot predict held out, the
/// furthest above its bound first. A test is its own group when held out by test; an
/// increment group names no test to repeat. A test that carries what a candidate explains
/// while every test is predicted is not among them: a test that carries the effect in
/// another case or drive confirms it as well and tells more (the separating tests).
fn tests_to_repeat(
    campaign: &Campaign,
    problem: &FitProblem,
    partly: Option<&PartlyExplained>,
) -> Vec<String> {
    if !problem.by_test() {
        return Vec::new();
    }
    let is_test = |label: &str| campaign.tests.iter().any(|t| t.id == label);
    let mut unpredicted: Vec<&GroupError> = partly
        .map(|p| p.unpredicted.iter().filter(|g| is_test(&g.group)).collect())
        .unwrap_or_default();
    unpredicted.sort_by(|a, b| (b.after / b.bound).total_cmp(&(a.after / a.bound)));
    unpredicted.iter().map(|g| g.group.clone()).collect()
}

#[cfg(test)]
mod shared_member_tests {
    use super::*;
    use crate::gap::diagnose::report::FittedParameter;

    fn parameter(effect: &str, name: &str, value: f64, interval: [f64; 2]) -> FittedParameter {
        FittedParameter {
            effect: effect.into(),
            name: name.into(),
            unit: "1".into(),
            value,
            interval: Some(interval),
            bounds: [interval[0].min(0.0), interval[1].max(1.0)],
            fitted: true,
            measured_from: None,
            identified: true,
            bounds_reached: Vec::new(),
        }
    }

    fn best(name: &str, parameters: Vec<FittedParameter>) -> BestEffect {
        BestEffect {
            name: name.into(),
            parameters,
            held_out_error_before: 2.9,
            held_out_error_after: 1.2,
            shrink: 0.59,
            shrink_interval: [0.5, 0.6],
            residual_p_value: 0.1,
            per_group: Vec::new(),
        }
    }

    /// Bench campaigns 1001 and 3030: a rig-only effect named cross_axis at a share of 6e-6
    /// whose interval [0, 0.00975] holds the effect off. A magnitude interval that holds 0
    /// keeps the candidate from being named; a secondary parameter's interval holding 0 (a
    /// phase over the whole circle) does not, nor a magnitude clear of 0; a pair is held back
    /// by either member.
    #[test]
    fn a_magnitude_whose_interval_holds_zero_is_not_named() {
        let phase = parameter("cross_axis", "phase_deg", 0.0, [-180.0, 180.0]);
        let vanishing = best(
            "cross_axis",
            vec![
                parameter("cross_axis", "share", 6e-6, [0.0, 0.00975]),
                phase.clone(),
            ],
        );
        let why = zero_in_magnitude_interval(&vanishing).expect("held back");
        assert!(why.contains("cross_axis.share"), "{why}");
        assert!(!why.contains("phase_deg"), "{why}");
        let clear = best(
            "cross_axis",
            vec![parameter("cross_axis", "share", 0.072, [0.06, 0.09]), phase],
        );
        assert_eq!(zero_in_magnitude_interval(&clear), None);
        // A friction drift may be negative: an interval across 0 holds it too.
        let drift = parameter("friction_drift", "delta_mu", 0.01, [-0.02, 0.04]);
        let pair = best(
            "friction_drift+cross_axis",
            vec![drift, parameter("cross_axis", "share", 0.072, [0.06, 0.09])],
        );
        let why = zero_in_magnitude_interval(&pair).expect("held back");
        assert!(why.contains("friction_drift.delta_mu"), "{why}");
    }

    /// A pair of families `a`, `b` with held-out log-likelihood `ll` (one group).
    fn pair(a: usize, b: usize, ll: f64) -> Candidate {
        Candidate {
            families: vec![a, b],
            spec: Vec::new(),
            fold_specs: Vec::new(),
            held_nll: vec![-ll],
            held_r2: vec![0.0],
            held_r2_spread: vec![0.0],
            held_w: vec![1.0],
            aicc: 0.0,
            bic: 0.0,
            residual_p: 1.0,
            chi2: 0.0,
            dof: 1.0,
            k: 2.0,
            alpha: 0.05,
        }
    }

    #[test]
    fn indistinguishable_pairs_sharing_one_member_name_that_member() {
        // Seed 1043's shape: cross-axis (0) beside severe wear (1) and beside fixture
        // compliance (2).
        let pairs = [pair(0, 1, -10.0), pair(2, 0, -10.5), pair(3, 4, -13.5)];
        assert_eq!(shared_member(&pairs, &[0, 1]), Some(0));
        // The chosen pair alone: its partner is not in doubt.
        assert_eq!(shared_member(&pairs, &[0]), None);
        assert_eq!(shared_member(&pairs, &[]), None);
        // Indistinguishable pairs that share no member stay as they are.
        assert_eq!(shared_member(&pairs, &[0, 2]), None);
        // Three that share one member; one that does not breaks it.
        let three = [pair(0, 1, -10.0), pair(2, 0, -10.5), pair(0, 5, -11.0)];
        assert_eq!(shared_member(&three, &[0, 1, 2]), Some(0));
        let broken = [pair(0, 1, -10.0), pair(2, 0, -10.5), pair(1, 2, -11.0)];
        assert_eq!(shared_member(&broken, &[0, 1, 2]), None);
    }
}
