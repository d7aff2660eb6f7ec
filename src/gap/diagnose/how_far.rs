//! How far the chosen effect closes the gap: held-out error before and after with the shrink
//! and its bootstrap interval, the fitted magnitude with its profile-likelihood interval, and
//! every measured mass's held-out prediction.

use super::candidate::Candidate;
use super::emulator;
use super::fit_problem::FitProblem;
use super::identification;
use super::noise;
use super::options::{MIN_EXPLAINED_SHRINK, PROFILE_95};
use super::report::{BestEffect, FittedParameter, GroupError, HeldOutPrediction, PartlyExplained};
use super::stats;
use crate::gap::Campaign;

/// Every measured mass with the nominal prediction and `c`'s prediction at the magnitudes
/// fitted without the mass's group, with its 95 % interval: the prediction plus or minus 1.96
/// times the observation's standard uncertainty about it (measurement and specimen scatter,
/// the simulator's numerical and parameter uncertainty; the spread of the fold's fitted
/// magnitudes is not in it).
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
            let with_effect = o.predicted(&folds[g]);
            let u = problem.noise.u_marginal(o, with_effect);
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
                magnitudes: c.fold_specs[g].iter().map(|s| s.1).collect(),
                with_effect_mg: with_effect,
                interval_mg: [with_effect - 1.96 * u, with_effect + 1.96 * u],
            }
        })
        .collect()
}

/// The physical bounds a fitted parameter's interval reaches, as the report names them.
fn reached(p: &crate::gap::effects::ParameterInfo, interval: [f64; 2]) -> Vec<String> {
    identification::bounds_reached(p, interval)
        .into_iter()
        .map(str::to_string)
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
        let started = std::time::Instant::now();
        let profile = Profile::of(problem, &c.spec, i);
        tracing::debug!(
            effect = info.name,
            points = profile.tables.iter().map(|(_, r)| r.len()).sum::<usize>(),
            seconds = started.elapsed().as_secs_f64(),
            "likelihood profile for the intervals"
        );
        let interval = profile.magnitude_interval(problem);
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
                    // Fitted within what the records allow (`FitProblem::candidates`).
                    measured_from: problem.emulator.magnitude_measurement(t).map(|mv| {
                        let [lo, hi] = mv.band.unwrap_or([mv.value, mv.value]);
                        format!("{}; fitted within [{lo:.4}, {hi:.4}]", mv.source)
                    }),
                    identified: identification::identified(p, interval),
                    bounds_reached: reached(p, interval),
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
                    identified: true,
                    bounds_reached: Vec::new(),
                });
                continue;
            }
            let profiled = profile.secondary_interval(problem, value, p.name);
            parameters.push(FittedParameter {
                effect: info.name.to_string(),
                name: p.name.to_string(),
                unit: p.unit.to_string(),
                value,
                interval: profiled,
                bounds: [p.min, p.max],
                fitted: profiled.is_some(),
                measured_from: None,
                identified: profiled.is_some_and(|iv| identification::identified(p, iv)),
                bounds_reached: profiled.map(|iv| reached(p, iv)).unwrap_or_default(),
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
        per_group: c
            .group_tests()
            .iter()
            .enumerate()
            .map(|(g, t)| GroupError {
                group: problem.group_labels[g].clone(),
                before: (nominal.held_r2[g] / nominal.held_w[g].max(1e-300)).sqrt(),
                after: t.error,
                p_adjusted: t.p_adjusted,
                bound: t.bound,
                predicted: !t.fails(c.alpha),
            })
            .collect(),
    }
}

/// Member `i`'s likelihood profile over its family's tables: each table's candidate
/// magnitudes ([`FitProblem::candidates`]) with their negative log-likelihoods on all the
/// data. For a pair, the other member is profiled out at each point: its best over the tables
/// the pair's fit may take beside this one ([`FitProblem::pair_combinations`]), each at 0 and
/// its grid magnitudes, then at the candidates around the best of those. So a pair member's
/// intervals are not conditional on where the search left its partner: a drift's magnitude
/// and a cross-axis share that trade off widen each other's intervals, as a magnitude and its
/// own slip scale do.
struct Profile {
    /// The member's fitted `(table, magnitude)`.
    fit: (usize, f64),
    /// `(table, [(magnitude, nll)])`, in family order.
    tables: Vec<(usize, Vec<(f64, f64)>)>,
    /// The negative log-likelihood at the reported fit: a magnitude's interval is drawn
    /// around it (so a fit the search left short of the profile's lowest point keeps the
    /// points better than it inside).
    at_fit: f64,
    /// The lowest negative log-likelihood in the profile: a secondary value's interval is
    /// drawn around it.
    floor: f64,
}

impl Profile {
    fn of(problem: &FitProblem, spec: &[(usize, f64)], i: usize) -> Self {
        // The table combinations the pair's fit may take (none for a single).
        let allowed: Vec<(usize, usize)> = match spec {
            [(a, _), (b, _)] => std::iter::once((*a, *b))
                .chain(problem.pair_combinations(*a, *b))
                .collect(),
            _ => Vec::new(),
        };
        let partners = |ti: usize| -> Vec<usize> {
            allowed
                .iter()
                .filter_map(|&(ta, tb)| match i {
                    0 if ta == ti => Some(tb),
                    1 if tb == ti => Some(ta),
                    _ => None,
                })
                .collect()
        };
        let nll_at = |ti: usize, m: f64, partner: Option<(usize, f64)>| {
            let mut s = spec.to_vec();
            s[i] = (ti, m);
            if let Some(p) = partner {
                s[1 - i] = p;
            }
            problem.nll_of(&s, |_| true)
        };
        let coarse = |tj: usize| {
            std::iter::once(0.0)
                .chain(problem.emulator.effects[tj].magnitudes.iter().copied())
                .collect()
        };
        let near = |tj: usize, y: f64| problem.candidates_near(tj, y);
        let space = PartnerSpace {
            tables: &partners,
            coarse: &coarse,
            near: &near,
        };
        let family = &problem.families[problem.family_of(spec[i].0)];
        let tables = profile_rows(
            family,
            &|t| problem.candidates(t),
            (spec.len() == 2).then_some(&space),
            &nll_at,
        );
        let at_fit = problem.nll_of(spec, |_| true);
        let floor = tables
            .iter()
            .flat_map(|(_, row)| row.iter().map(|v| v.1))
            .fold(f64::INFINITY, f64::min);
        Profile {
            fit: spec[i],
            tables,
            at_fit,
            floor,
        }
    }

    /// A table's best `(magnitude, nll)` over its row.
    fn best_of(row: &[(f64, f64)]) -> Option<(f64, f64)> {
        row.iter().copied().min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// 95 % profile-likelihood interval of the member's magnitude: every magnitude of any of
    /// its family's tables within [`PROFILE_95`] of the fit (the secondary values and a
    /// pair's partner profiled out), and the magnitude each table fits best where the table's
    /// secondary values all lie within their (grid-widened) intervals, so the magnitude's
    /// interval is the projection of the same region the secondary values' intervals span. A
    /// slip scale and a magnitude that trade off along a ridge otherwise give a magnitude
    /// interval conditional on the grid's tables inside the threshold, while the secondary
    /// value's interval reaches the neighbouring grid values beyond it (2035: a drift of 0.48
    /// drawn at 7143 m, fitted 0.485 at 5623 m with a slip-scale interval of 3162-7499 m and a
    /// magnitude interval of 0.4838-0.4886). Widened to the neighbouring candidates.
    fn magnitude_interval(&self, problem: &FitProblem) -> [f64; 2] {
        let (fitted_table, best) = self.fit;
        let cands: Vec<f64> = self
            .tables
            .iter()
            .flat_map(|(_, row)| row.iter().map(|v| v.0))
            .collect();
        let mut inside: Vec<f64> = self
            .tables
            .iter()
            .flat_map(|(_, row)| row.iter())
            .filter(|v| v.1 <= self.at_fit + PROFILE_95)
            .map(|v| v.0)
            .collect();
        let names: std::collections::BTreeSet<&String> = self
            .tables
            .iter()
            .flat_map(|(t, _)| problem.emulator.effects[*t].parameters.keys())
            .collect();
        let intervals: Vec<(&String, [f64; 2])> = names
            .into_iter()
            .filter_map(|n| {
                let chosen = problem.emulator.effects[fitted_table].parameter(n);
                Some((n, self.secondary_interval(problem, chosen, n)?))
            })
            .collect();
        if !intervals.is_empty() {
            inside.extend(
                self.tables
                    .iter()
                    .filter(|(t, _)| {
                        let table = &problem.emulator.effects[*t];
                        intervals.iter().all(|(n, [lo, hi])| {
                            let v = table.parameter(n);
                            *lo <= v && v <= *hi
                        })
                    })
                    .filter_map(|(t, row)| {
                        let m = ridge_point(Self::best_of(row)?.0, best)?;
                        tracing::debug!(table = t, magnitude = m, "ridge point");
                        Some(m)
                    }),
            );
        }
        let lo = inside.iter().copied().fold(best, f64::min);
        let hi = inside.iter().copied().fold(best, f64::max);
        widen_to_grid(&cands, [lo, hi])
    }

    /// 95 % profile-likelihood interval of secondary parameter `name` over the values the
    /// family's tables hold (each value at its best magnitude, a pair's partner profiled out),
    /// the values within [`PROFILE_95`] of the floor spanned, with `chosen` (the fit's value)
    /// always inside. None when the family holds no variant in that parameter (it was not
    /// fitted). Its resolution is the profile's grid.
    fn secondary_interval(
        &self,
        problem: &FitProblem,
        chosen: f64,
        name: &str,
    ) -> Option<[f64; 2]> {
        let effects = &problem.emulator.effects;
        if !self
            .tables
            .iter()
            .any(|(t, _)| effects[*t].parameters.contains_key(name))
        {
            return None;
        }
        let by_value: Vec<(f64, f64)> = self
            .tables
            .iter()
            .map(|(t, row)| {
                let nll = Self::best_of(row).map_or(f64::INFINITY, |b| b.1);
                (effects[*t].parameter(name), nll)
            })
            .collect();
        let inside = by_value
            .iter()
            .filter(|(_, n)| *n <= self.floor + PROFILE_95)
            .map(|(v, _)| *v);
        let lo = inside.clone().fold(chosen, f64::min);
        let hi = inside.fold(chosen, f64::max);
        let grid: Vec<f64> = by_value.iter().map(|v| v.0).collect();
        Some(widen_to_grid(&grid, [lo, hi]))
    }
}

/// A table's best magnitude `m` as a point of the ridge a fitted magnitude `fit` trades off
/// along: only where the effect is on, on the fit's side of 0. A table of the grid-widened
/// secondary interval that fits best with the effect off (a poor neighbour, where the data
/// would rather have none of it) is not a point of the ridge: taking its 0 would put "no
/// effect" inside the magnitude's interval, against the likelihood-ratio test that chose the
/// effect (1039: a drift interval reaching 0 beside a pair that beats the cross-axis drive
/// alone by 63 units of log-likelihood).
fn ridge_point(m: f64, fit: f64) -> Option<f64> {
    (m != 0.0 && m.signum() == fit.signum()).then_some(m)
}

/// Where a pair member's partner is profiled out: the partner's tables the pair's fit may take
/// beside a table of the member, each table's coarse magnitudes (0, the member alone, and its
/// grid), and the candidates around a coarse best.
struct PartnerSpace<'a> {
    tables: &'a dyn Fn(usize) -> Vec<usize>,
    coarse: &'a dyn Fn(usize) -> Vec<f64>,
    near: &'a dyn Fn(usize, f64) -> Vec<f64>,
}

/// A profile's rows: for each table of `family`, each of its `candidates` with `nll(table,
/// magnitude, partner)`, the partner (with `partner`) at its best over its tables beside this
/// one, coarse then refined around each table's coarse best; without a partner table beside
/// it (or without `partner`), the fit's own partner (`None`).
fn profile_rows(
    family: &[usize],
    candidates: &dyn Fn(usize) -> Vec<f64>,
    partner: Option<&PartnerSpace>,
    nll: &dyn Fn(usize, f64, Option<(usize, f64)>) -> f64,
) -> Vec<(usize, Vec<(f64, f64)>)> {
    let profiled = |ti: usize, m: f64, beside: &[usize], space: &PartnerSpace| {
        let mut best = f64::INFINITY;
        for &tj in beside {
            let coarse = (space.coarse)(tj)
                .into_iter()
                .map(|y| (y, nll(ti, m, Some((tj, y)))))
                .min_by(|x, y| x.1.total_cmp(&y.1));
            let Some((y0, n0)) = coarse else { continue };
            let fine = (space.near)(tj, y0)
                .into_iter()
                .map(|y| nll(ti, m, Some((tj, y))))
                .fold(n0, f64::min);
            best = best.min(fine);
        }
        best
    };
    family
        .iter()
        .map(|&ti| {
            let beside = partner.map(|p| ((p.tables)(ti), p));
            let row = candidates(ti)
                .into_iter()
                .map(|m| match &beside {
                    Some((tables, space)) if !tables.is_empty() => {
                        (m, profiled(ti, m, tables, space))
                    }
                    _ => (m, nll(ti, m, None)),
                })
                .collect();
            (ti, row)
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
    let unpredicted: Vec<GroupError> = b
        .per_group
        .iter()
        .filter(|g| !g.predicted)
        .cloned()
        .collect();
    for g in &unpredicted {
        reasons.push(format!(
            "{} not predicted held out: error {:.2} > {:.2} (Holm-adjusted p = {:.1e})",
            g.group, g.after, g.bound, g.p_adjusted
        ));
    }
    if reasons.is_empty() {
        return None;
    }
    let worst = unpredicted
        .iter()
        .max_by(|x, y| (x.after / x.bound).total_cmp(&(y.after / y.bound)))
        .or_else(|| {
            b.per_group
                .iter()
                .max_by(|x, y| x.after.total_cmp(&y.after))
        })?
        .clone();
    Some(PartlyExplained {
        candidate: b.name.clone(),
        reasons,
        at_bound,
        held_out_error: [b.held_out_error_before, b.held_out_error_after],
        shrink: b.shrink,
        chi2_left: c.chi2,
        dof: c.dof,
        residual_p_value: c.residual_p,
        unpredicted,
        cannot_predict: worst.group.clone(),
        cannot_predict_error: [worst.before, worst.after],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Magnitudes `0, step, ..., 1`.
    fn steps(step: f64) -> Vec<f64> {
        (0..=(1.0 / step).round() as usize)
            .map(|k| k as f64 * step)
            .collect()
    }

    /// The 95 % interval of a profile's rows: the magnitudes within [`PROFILE_95`] of the
    /// lowest.
    fn interval(rows: &[(usize, Vec<(f64, f64)>)]) -> [f64; 2] {
        let all: Vec<(f64, f64)> = rows.iter().flat_map(|(_, r)| r.iter().copied()).collect();
        let floor = all.iter().map(|v| v.1).fold(f64::INFINITY, f64::min);
        let inside = all
            .iter()
            .filter(|v| v.1 <= floor + PROFILE_95)
            .map(|v| v.0);
        [
            inside.clone().fold(f64::INFINITY, f64::min),
            inside.fold(f64::NEG_INFINITY, f64::max),
        ]
    }

    /// Two Gaussian constraints on a pair's magnitudes `a` and `b`: a sharp one on `a + b`
    /// (sd `s1`) and a loose one on `a - b` (sd `s2`), both centred on `a = b = 0.3`. With `b`
    /// held at 0.3 the 95 % interval of `a` is `0.3 ± sqrt(2 PROFILE_95 / (1/s1² + 1/s2²))`;
    /// with `b` profiled out, the profile is `(2a - 0.6)² / (2 (s1² + s2²))`, so the interval
    /// is `0.3 ± sqrt(2 PROFILE_95 (s1² + s2²)) / 2`: ten times wider here. The rows must give
    /// both to within the candidates' spacing.
    #[test]
    fn a_pair_members_profile_takes_its_partner_out_as_the_closed_form_says() {
        let (s1, s2) = (0.02, 0.2);
        let nll = |_: usize, a: f64, partner: Option<(usize, f64)>| {
            let b = partner.map_or(0.3, |p| p.1);
            let (u, v) = ((a + b - 0.6) / s1, (a - b) / s2);
            0.5 * (u * u + v * v)
        };
        let fine = steps(0.002);
        let candidates = |_: usize| fine.clone();
        let held = profile_rows(&[0], &candidates, None, &nll);
        let half = (2.0 * PROFILE_95 / (1.0 / (s1 * s1) + 1.0 / (s2 * s2))).sqrt();
        let [lo, hi] = interval(&held);
        assert!((lo - (0.3 - half)).abs() <= 0.002, "{lo} {half}");
        assert!((hi - (0.3 + half)).abs() <= 0.002, "{hi} {half}");

        let partners = |_: usize| vec![1];
        let coarse = |_: usize| steps(0.1);
        let near = |_: usize, y: f64| {
            steps(0.002)
                .into_iter()
                .filter(|c| (c - y).abs() <= 0.1 + 1e-12)
                .collect()
        };
        let space = PartnerSpace {
            tables: &partners,
            coarse: &coarse,
            near: &near,
        };
        let profiled = profile_rows(&[0], &candidates, Some(&space), &nll);
        let half = (2.0 * PROFILE_95 * (s1 * s1 + s2 * s2)).sqrt() / 2.0;
        let [lo, hi] = interval(&profiled);
        assert!((lo - (0.3 - half)).abs() <= 0.004, "{lo} {half}");
        assert!((hi - (0.3 + half)).abs() <= 0.004, "{hi} {half}");
        // Profiling never raises a point's negative log-likelihood (the partner's held value
        // is among those it tries).
        for ((_, p), (_, h)) in profiled.iter().zip(&held) {
            for (x, y) in p.iter().zip(h) {
                assert!(x.1 <= y.1 + 1e-12, "{x:?} {y:?}");
            }
        }
    }

    #[test]
    fn the_effect_off_is_not_a_ridge_point() {
        assert_eq!(ridge_point(0.0, 0.18), None);
        assert_eq!(ridge_point(-0.01, 0.18), None);
        assert_eq!(ridge_point(0.6, 0.18), Some(0.6));
        assert_eq!(ridge_point(-0.05, -0.02), Some(-0.05));
    }

    /// A member table without a partner table beside it keeps the fit's own partner.
    #[test]
    fn a_table_without_a_partner_beside_it_keeps_the_fits_partner() {
        let nll = |t: usize, a: f64, partner: Option<(usize, f64)>| {
            a + t as f64 + partner.map_or(100.0, |p| p.1)
        };
        let partners = |t: usize| if t == 0 { vec![7] } else { Vec::new() };
        let coarse = |_: usize| vec![0.0, 1.0];
        let near = |_: usize, y: f64| vec![y];
        let space = PartnerSpace {
            tables: &partners,
            coarse: &coarse,
            near: &near,
        };
        let rows = profile_rows(&[0, 1], &|_| vec![0.5], Some(&space), &nll);
        assert_eq!(rows, vec![(0, vec![(0.5, 0.5)]), (1, vec![(0.5, 101.5)])]);
    }
}
