//! One candidate's numbers (held out per group, full-data fit, criteria) and the rules that
//! say whether it explains the gap, cleanly or only partly.

use super::emulator::Emulator;
use super::options::{MIN_EXPLAINED_SHARE, MIN_EXPLAINED_SHRINK, MIN_HELD_OUT_GAIN};
use super::stats;

/// Whether one held-out group is predicted within its noise (docs/results/diagnosis.md, "Every
/// withheld group predicted").
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct GroupTest {
    /// Held-out RMS standardized error of the group.
    pub(super) error: f64,
    /// Upper-tail p-value of its held-out chi-square on its degrees of freedom.
    pub(super) p: f64,
    /// `p` adjusted by Holm's method across the held-out groups.
    pub(super) p_adjusted: f64,
    /// The largest RMS error Holm's first step accepts for the group: `sqrt(x / w)` with `x`
    /// the chi-square quantile at `alpha / groups` on its degrees of freedom.
    pub(super) bound: f64,
}

impl GroupTest {
    /// Not predicted within its noise: Holm-adjusted p below `alpha`.
    pub(super) fn fails(&self, alpha: f64) -> bool {
        self.p_adjusted < alpha
    }
}

/// Each held-out group's test: its held-out chi-square `r2[g]` (the group given the training
/// groups, calibration scales integrated out) is a chi-square on its weighted observation
/// count `w[g]` when the candidate holds, so its upper tail is the group's p-value; the
/// p-values are adjusted across groups by Holm's step-down method (family-wise error rate
/// `alpha`).
pub(super) fn group_tests(r2: &[f64], w: &[f64], alpha: f64) -> Vec<GroupTest> {
    let dof = |g: usize| w[g].round().max(1.0) as usize;
    let p: Vec<f64> = (0..r2.len())
        .map(|g| stats::chi2_sf(r2[g], dof(g)))
        .collect();
    let adjusted = stats::holm(&p);
    let level = alpha / r2.len().max(1) as f64;
    (0..r2.len())
        .map(|g| GroupTest {
            error: (r2[g] / w[g].max(1e-300)).sqrt(),
            p: p[g],
            p_adjusted: adjusted[g],
            bound: (stats::chi2_isf(level, dof(g)) / w[g].max(1e-300)).sqrt(),
        })
        .collect()
}

/// One candidate's numbers.
#[derive(Debug, Clone)]
pub(super) struct Candidate {
    /// Effects (family indices), for its name.
    pub(super) families: Vec<usize>,
    /// Full-data fit: (table, magnitude) per effect.
    pub(super) spec: Vec<(usize, f64)>,
    /// The fit on each training fold (the held-out predictions use them).
    pub(super) fold_specs: Vec<Vec<(usize, f64)>>,
    pub(super) held_nll: Vec<f64>,
    pub(super) held_r2: Vec<f64>,
    /// Per group, the held-out chi-square at the training fold's fit that predicts the group
    /// best among those the training groups do not refuse (within [`PROFILE_95`](super::options::PROFILE_95) of the
    /// fold's best: other values of parameters the training data leave open); `held_r2` at
    /// most. What the group test uses: a prediction carries the spread of what the data
    /// do not identify.
    pub(super) held_r2_spread: Vec<f64>,
    pub(super) held_w: Vec<f64>,
    pub(super) aicc: f64,
    pub(super) bic: f64,
    pub(super) residual_p: f64,
    pub(super) chi2: f64,
    pub(super) dof: f64,
    /// Parameters fitted (full data).
    pub(super) k: f64,
    pub(super) alpha: f64,
}

impl Candidate {
    pub(super) fn held_ll(&self) -> f64 {
        -self.held_nll.iter().sum::<f64>()
    }

    pub(super) fn held_error(&self) -> f64 {
        (self.held_r2.iter().sum::<f64>() / self.held_w.iter().sum::<f64>().max(1e-300)).sqrt()
    }

    pub(super) fn magnitudes(&self) -> Vec<f64> {
        self.spec.iter().map(|s| s.1).collect()
    }

    /// The table of a single effect's full-data fit.
    pub(super) fn table(&self) -> usize {
        self.spec.first().map_or(0, |s| s.0)
    }

    pub(super) fn explained_share(&self, nominal: &Candidate) -> f64 {
        let excess = nominal.chi2 - nominal.dof;
        if excess > 0.0 {
            (nominal.chi2 - self.chi2) / excess
        } else {
            0.0
        }
    }

    /// Each held-out group's test of being predicted within its noise ([`group_tests`]), on
    /// the training fold's fits within [`PROFILE_95`](super::options::PROFILE_95) of its best (`held_r2_spread`).
    pub(super) fn group_tests(&self) -> Vec<GroupTest> {
        group_tests(&self.held_r2_spread, &self.held_w, self.alpha)
    }

    /// The held-out groups it does not predict within their noise.
    pub(super) fn unpredicted_groups(&self) -> Vec<usize> {
        let tests = self.group_tests();
        (0..tests.len())
            .filter(|&g| tests[g].fails(self.alpha))
            .collect()
    }

    /// Explains, but fitted at a magnitude bound, with a held-out shrink under
    /// [`MIN_EXPLAINED_SHRINK`], or leaving a held-out group it does not predict within its
    /// noise (what `partly_explained` reports).
    pub(super) fn only_partly(&self, nominal: &Candidate, emulator: &Emulator) -> bool {
        let at_bound = self.spec.iter().any(|&(t, m)| {
            let b = emulator.effects[t].bound_for(m);
            m != 0.0 && (m - b).abs() <= 1e-9 * b.abs()
        });
        let before = nominal.held_error();
        let shrink = if before > 0.0 {
            1.0 - self.held_error() / before
        } else {
            0.0
        };
        at_bound || !(shrink >= MIN_EXPLAINED_SHRINK) || !self.unpredicted_groups().is_empty()
    }

    pub(super) fn explains(&self, nominal: &Candidate) -> bool {
        self.held_ll() - nominal.held_ll() > MIN_HELD_OUT_GAIN
            && self.residual_p >= self.alpha
            && self.explained_share(nominal) >= MIN_EXPLAINED_SHARE
    }

    /// Explains, and not only partly: what lets a single stand without pairs or profiles.
    pub(super) fn explains_cleanly(&self, nominal: &Candidate, emulator: &Emulator) -> bool {
        self.explains(nominal) && !self.only_partly(nominal, emulator)
    }
}

/// Requests `(table, magnitude)` of a candidate's simulated tables at its full-data and every
/// fold's fitted magnitudes.
pub(super) fn requests_of(emulator: &Emulator, c: &Candidate) -> Vec<(usize, f64)> {
    std::iter::once(&c.spec)
        .chain(c.fold_specs.iter())
        .flat_map(|s| s.iter().copied())
        .filter(|(t, m)| *m != 0.0 && emulator.effects[*t].simulated)
        .collect()
}
