//! How far the chosen effect closes the gap: held-out error before and after with the shrink
//! and its bootstrap interval, the fitted magnitude with its profile-likelihood interval, and
//! every measured mass's held-out prediction.

use super::*;

/// Every measured mass with the nominal prediction and `c`'s prediction at the magnitude
/// fitted without the mass's group.
pub(super) fn held_out_predictions(
    campaign: &Campaign,
    problem: &FitProblem,
    c: &Candidate,
) -> Vec<HeldOutPrediction> {
    let nominal = problem.emulator.predict(&[]);
    let folds: Vec<emulator::TestPredictions> = c
        .fold_specs
        .iter()
        .map(|spec| problem.emulator.predict(spec))
        .collect();
    problem
        .obs
        .iter()
        .enumerate()
        .filter(|(_, o)| matches!(o.quantity, noise::Quantity::Mass(_)))
        .map(|(i, o)| {
            let g = problem.group[i];
            let mu = o.predicted(&nominal);
            HeldOutPrediction {
                group: problem.group_labels[g].clone(),
                test: campaign.tests[o.test].id.clone(),
                increment: o.increment + 1,
                quantity: o.quantity.label(),
                measured_mg: o.value,
                uncertainty_mg: problem.noise.u_marginal(o, mu),
                nominal_mg: mu,
                effect: problem.name_of(&c.families),
                magnitude: c.fold_specs[g].first().map_or(0.0, |s| s.1),
                with_effect_mg: o.predicted(&folds[g]),
            }
        })
        .collect()
}

pub(super) fn best_effect(
    problem: &FitProblem,
    c: &Candidate,
    nominal: &Candidate,
    resamples: &[Vec<usize>],
) -> BestEffect {
    let before = nominal.held_error();
    let after = c.held_error();
    let shrinks: Vec<f64> = resamples
        .iter()
        .map(|idx| {
            let rb: f64 = idx.iter().map(|g| nominal.held_r2[*g]).sum();
            let ra: f64 = idx.iter().map(|g| c.held_r2[*g]).sum();
            if rb > 0.0 {
                1.0 - (ra / rb).sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let mut parameters = Vec::new();
    for (i, &(t, m)) in c.spec.iter().enumerate() {
        let table = &problem.emulator.effects[t];
        let info = table.info;
        let family = problem.family_of(t);
        let interval = profile_interval(problem, &c.spec, i);
        for (pi, p) in info.parameters.iter().enumerate() {
            if pi == 0 {
                parameters.push(FittedParameter {
                    effect: info.name.to_string(),
                    name: p.name.to_string(),
                    unit: p.unit.to_string(),
                    value: m,
                    interval: Some(interval),
                    bounds: [p.min, p.max],
                    fitted: true,
                    measured_from: None,
                });
                continue;
            }
            let value = table.parameter(p.name);
            if let Some(mv) = problem
                .emulator
                .measured_value(info.name, p.name)
                .filter(|mv| mv.agrees(value))
            {
                parameters.push(FittedParameter {
                    effect: info.name.to_string(),
                    name: p.name.to_string(),
                    unit: p.unit.to_string(),
                    value,
                    interval: Some([mv.value - 1.96 * mv.sd, mv.value + 1.96 * mv.sd]),
                    bounds: [p.min, p.max],
                    fitted: false,
                    measured_from: Some(mv.source.clone()),
                });
                continue;
            }
            let profiled = secondary_interval(problem, family, &c.spec, i, p.name);
            parameters.push(FittedParameter {
                effect: info.name.to_string(),
                name: p.name.to_string(),
                unit: p.unit.to_string(),
                value,
                interval: profiled,
                bounds: [p.min, p.max],
                fitted: profiled.is_some(),
                measured_from: None,
            });
        }
    }
    BestEffect {
        name: problem.name_of(&c.families),
        parameters,
        held_out_error_before: before,
        held_out_error_after: after,
        shrink: if before > 0.0 {
            1.0 - after / before
        } else {
            0.0
        },
        shrink_interval: [
            stats::quantile(&shrinks, 0.05),
            stats::quantile(&shrinks, 0.95),
        ],
        residual_p_value: c.residual_p,
        per_group: (0..problem.groups)
            .map(|g| GroupError {
                group: problem.group_labels[g].clone(),
                before: (nominal.held_r2[g] / nominal.held_w[g].max(1e-300)).sqrt(),
                after: (c.held_r2[g] / c.held_w[g].max(1e-300)).sqrt(),
            })
            .collect(),
    }
}

/// 95 % profile-likelihood interval of member `i`'s magnitude around the full-data optimum
/// `spec` (the other member, for a pair, held at its fitted magnitude: a conditional interval).
/// The member's secondary values are profiled out: each magnitude takes the best of its
/// family's tables (the variants the diagnosis simulated), so a slip scale and a magnitude
/// that trade off along a ridge widen the interval rather than pin it to the chosen variant.
fn profile_interval(problem: &FitProblem, spec: &[(usize, f64)], i: usize) -> [f64; 2] {
    let (t, best) = spec[i];
    let tables = &problem.families[problem.family_of(t)];
    let nll = |table: usize, m: f64| {
        let mut s = spec.to_vec();
        s[i] = (table, m);
        problem.nll_of(&s, |_| true)
    };
    let floor = nll(t, best);
    let mut cands: Vec<f64> = Vec::new();
    let mut inside: Vec<f64> = Vec::new();
    for &table in tables {
        for m in problem.candidates(table) {
            cands.push(m);
            if nll(table, m) <= floor + PROFILE_95 {
                inside.push(m);
            }
        }
    }
    inside.extend(ridge_magnitudes(problem, spec, i));
    let lo = inside.iter().copied().fold(best, f64::min);
    let hi = inside.iter().copied().fold(best, f64::max);
    widen_to_grid(&cands, [lo, hi])
}

/// The magnitude each of member `i`'s family tables fits best, for the tables whose secondary
/// values all lie within their (grid-widened) intervals: the magnitude's interval is the
/// projection of the same region the secondary values' intervals span. A slip scale and a
/// magnitude that trade off along a ridge otherwise give a magnitude interval conditional on
/// the grid's tables inside the threshold, while the secondary value's interval reaches the
/// neighbouring grid values beyond it (2035: a drift of 0.48 drawn at 7143 m, fitted 0.485
/// at 5623 m with a slip-scale interval of 3162-7499 m and a magnitude interval of
/// 0.4838-0.4886). Empty for a family without variants.
fn ridge_magnitudes(problem: &FitProblem, spec: &[(usize, f64)], i: usize) -> Vec<f64> {
    let family = problem.family_of(spec[i].0);
    let tables = &problem.families[family];
    let names: std::collections::BTreeSet<&String> = tables
        .iter()
        .flat_map(|t| problem.emulator.effects[*t].parameters.keys())
        .collect();
    let intervals: Vec<(&String, [f64; 2])> = names
        .into_iter()
        .filter_map(|n| Some((n, secondary_interval(problem, family, spec, i, n)?)))
        .collect();
    if intervals.is_empty() {
        return Vec::new();
    }
    tables
        .iter()
        .filter(|t| {
            let table = &problem.emulator.effects[**t];
            intervals.iter().all(|(n, [lo, hi])| {
                let v = table.parameter(n);
                *lo <= v && v <= *hi
            })
        })
        .filter_map(|&t| {
            problem
                .candidates(t)
                .into_iter()
                .map(|m| {
                    let mut s = spec.to_vec();
                    s[i] = (t, m);
                    (m, problem.nll_of(&s, |_| true))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(m, _)| m)
        })
        .collect()
}

/// `[lo, hi]` widened to the neighbouring grid values outside it (the profile's edge lies
/// somewhere between the last value inside and the first outside: the conservative side).
fn widen_to_grid(grid: &[f64], [lo, hi]: [f64; 2]) -> [f64; 2] {
    let below = grid
        .iter()
        .copied()
        .filter(|v| *v < lo)
        .fold(f64::NAN, f64::max);
    let above = grid
        .iter()
        .copied()
        .filter(|v| *v > hi)
        .fold(f64::NAN, f64::min);
    [
        if below.is_nan() { lo } else { below },
        if above.is_nan() { hi } else { above },
    ]
}

/// 95 % profile-likelihood interval of secondary parameter `name` of member `i`, over the
/// values its family's tables hold (each value at its best magnitude, the other member held):
/// the values within [`PROFILE_95`] of the best, spanned. None when the family holds no
/// variant in that parameter (it was not fitted). Its resolution is the profile's grid.
fn secondary_interval(
    problem: &FitProblem,
    family: usize,
    spec: &[(usize, f64)],
    i: usize,
    name: &str,
) -> Option<[f64; 2]> {
    let tables = &problem.families[family];
    if !tables
        .iter()
        .any(|t| problem.emulator.effects[*t].parameters.contains_key(name))
    {
        return None;
    }
    let chosen = problem.emulator.effects[spec[i].0].parameter(name);
    let mut by_value: Vec<(f64, f64)> = Vec::new();
    for &t in tables {
        let mut best = f64::INFINITY;
        for m in problem.candidates(t) {
            let mut s = spec.to_vec();
            s[i] = (t, m);
            best = best.min(problem.nll_of(&s, |_| true));
        }
        by_value.push((problem.emulator.effects[t].parameter(name), best));
    }
    let floor = by_value.iter().map(|v| v.1).fold(f64::INFINITY, f64::min);
    let inside = by_value
        .iter()
        .filter(|(_, n)| *n <= floor + PROFILE_95)
        .map(|(v, _)| *v);
    let lo = inside.clone().fold(chosen, f64::min);
    let hi = inside.fold(chosen, f64::max);
    let grid: Vec<f64> = by_value.iter().map(|v| v.0).collect();
    Some(widen_to_grid(&grid, [lo, hi]))
}

/// Why a chosen candidate only partly explains the gap: a magnitude fitted at its physical
/// bound, a held-out shrink under [`MIN_EXPLAINED_SHRINK`], or `also` (a reason the caller
/// found: a pair's partner not identified). None when none holds.
pub(super) fn partly_explained(
    problem: &FitProblem,
    c: &Candidate,
    b: &BestEffect,
    also: Option<String>,
) -> Option<PartlyExplained> {
    let mut reasons: Vec<String> = also.into_iter().collect();
    let mut at_bound = Vec::new();
    for &(t, m) in &c.spec {
        let table = &problem.emulator.effects[t];
        let bound = table.bound_for(m);
        if m != 0.0 && (m - bound).abs() <= 1e-9 * bound.abs() {
            let p = &table.info.parameters[0];
            at_bound.push(format!("{}.{}", table.info.name, p.name));
            reasons.push(format!(
                "{} fitted at its bound {} {}",
                p.name, bound, p.unit
            ));
        }
    }
    if !(b.shrink >= MIN_EXPLAINED_SHRINK) {
        reasons.push(format!(
            "held-out shrink {:.0} % < {:.0} %",
            100.0 * b.shrink,
            100.0 * MIN_EXPLAINED_SHRINK
        ));
    }
    if reasons.is_empty() {
        return None;
    }
    let worst = b
        .per_group
        .iter()
        .max_by(|x, y| x.after.total_cmp(&y.after))?;
    Some(PartlyExplained {
        candidate: b.name.clone(),
        reasons,
        at_bound,
        held_out_error: [b.held_out_error_before, b.held_out_error_after],
        shrink: b.shrink,
        chi2_left: c.chi2,
        dof: c.dof,
        residual_p_value: c.residual_p,
        cannot_predict: worst.group.clone(),
        cannot_predict_error: [worst.before, worst.after],
    })
}
