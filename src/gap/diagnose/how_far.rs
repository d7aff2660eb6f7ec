//! How far the chosen effect closes the gap: held-out error before and after with the shrink
//! and its bootstrap interval, the fitted magnitude with its profile-likelihood interval, and
//! every measured mass's held-out prediction.

use super::*;

/// Every measured mass with the nominal prediction and `c`'s prediction at the magnitude
/// fitted without the mass's group.
pub(super) fn held_out_predictions(
    campaign: &Campaign,
    problem: &Problem,
    c: &Candidate,
) -> Vec<HeldOutPrediction> {
    let nominal = problem.emulator.predict(&[]);
    let folds: Vec<emulator::TestPredictions> = c
        .fold_magnitudes
        .iter()
        .map(|m| {
            let spec: Vec<(usize, f64)> =
                c.effects.iter().copied().zip(m.iter().copied()).collect();
            problem.emulator.predict(&spec)
        })
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
                effect: problem.name_of(&c.effects),
                magnitude: c.fold_magnitudes[g].first().copied().unwrap_or(0.0),
                with_effect_mg: o.predicted(&folds[g]),
            }
        })
        .collect()
}

pub(super) fn best_effect(
    problem: &Problem,
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
    for (&e, &m) in c.effects.iter().zip(&c.magnitudes) {
        let info = problem.emulator.effects[e].info;
        let interval = (c.effects.len() == 1).then(|| profile_interval(problem, e, m));
        for (pi, p) in info.parameters.iter().enumerate() {
            parameters.push(FittedParameter {
                effect: info.name.to_string(),
                name: p.name.to_string(),
                unit: p.unit.to_string(),
                value: if pi == 0 { m } else { p.default },
                interval: if pi == 0 { interval } else { None },
                bounds: [p.min, p.max],
                fitted: pi == 0,
            });
        }
    }
    BestEffect {
        name: problem.name_of(&c.effects),
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

/// 95 % profile-likelihood interval of one effect's magnitude around its full-data optimum.
fn profile_interval(problem: &Problem, e: usize, best: f64) -> [f64; 2] {
    let nll = |m: f64| problem.nll_of(&[(e, m)], |_| true);
    let floor = nll(best);
    let cands = problem.candidates(e);
    let inside: Vec<f64> = cands
        .into_iter()
        .filter(|m| nll(*m) <= floor + PROFILE_95)
        .collect();
    let lo = inside.iter().copied().fold(best, f64::min);
    let hi = inside.iter().copied().fold(best, f64::max);
    [lo, hi]
}
