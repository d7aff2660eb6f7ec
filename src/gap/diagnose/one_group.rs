//! An effect one held-out group carries: held out, it has nothing to be fitted on, so the
//! campaign cannot confirm it (docs/results/diagnosis.md, "Seen in one test").

use super::candidate::Candidate;
use super::fit_problem::FitProblem;

/// Share of a candidate's full-data chi-square reduction that one group must carry for the
/// effect to count as seen in that group alone.
pub(super) const ONE_GROUP_SHARE: f64 = 0.9;

/// For a `not_explained` verdict, the sentence on [`one_group_single`]'s effect: it is seen in
/// one group alone, so leaving the group out leaves nothing to fit it on; the campaign cannot
/// confirm it, and more tests like that group could.
pub(super) fn seen_in_one_group(problem: &FitProblem, (c, g, share): OneGroup) -> String {
    format!(
        "{} fits every observation within the noise (lack-of-fit p = {:.2}), but {} carries {:.0} % of what it explains, so held out it has nothing to be fitted on: this campaign cannot confirm it; more tests like {} could",
        problem.name_of(&c.families),
        c.residual_p,
        problem.group_labels[g],
        100.0 * share,
        problem.group_labels[g],
    )
}

/// A candidate, the held-out group that carries what it explains, and that group's share.
pub(super) type OneGroup<'c> = (&'c Candidate, usize, f64);

/// The best single (by full-data chi-square) that fits every observation within the noise
/// (lack-of-fit p >= `alpha`) but does not explain held out, if one held-out group carries at
/// least [`ONE_GROUP_SHARE`] of its chi-square reduction.
pub(super) fn one_group_single<'c>(
    problem: &FitProblem,
    singles: &'c [Candidate],
    nominal: &Candidate,
    alpha: f64,
) -> Option<OneGroup<'c>> {
    let c = singles
        .iter()
        .filter(|c| c.residual_p >= alpha && !c.explains(nominal))
        .min_by(|a, b| a.chi2.total_cmp(&b.chi2))?;
    carried_by_one_group(problem, c).map(|(g, share)| (c, g, share))
}

/// The held-out group that carries at least [`ONE_GROUP_SHARE`] of candidate `c`'s full-data
/// chi-square reduction, with its share; None when no group does.
pub(super) fn carried_by_one_group(problem: &FitProblem, c: &Candidate) -> Option<(usize, f64)> {
    let reduction = |g: usize| {
        let only = |h: usize| h == g;
        problem.totals(&[], &only).r2 - problem.totals(&c.spec, &only).r2
    };
    let per_group: Vec<f64> = (0..problem.groups).map(reduction).collect();
    let total: f64 = per_group.iter().sum();
    let (g, top) = per_group
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    (total > 0.0 && top >= ONE_GROUP_SHARE * total).then_some((g, top / total))
}
