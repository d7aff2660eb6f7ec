//! The fit problem of one diagnosis: the observations, their noise model and held-out groups,
//! the emulator's tables by effect, and each candidate's fit (a single effect over its
//! family's tables, a pair over its members' tables) and evaluation (held out per group, full
//! data, criteria).

use super::candidate::Candidate;
use super::emulator::{self, Emulator};
use super::noise::{self, NoiseModel, Observation, Totals};
use super::options::{DiagnoseOptions, PROFILE_95};
use super::{joint_spread, stats};
use crate::gap::Campaign;

/// The data, noise model and folds of one diagnosis.
pub struct FitProblem<'a> {
    pub(super) obs: Vec<Observation>,
    pub(super) noise: NoiseModel,
    pub(super) emulator: &'a Emulator,
    /// Group (fold) of each observation.
    pub(super) group: Vec<usize>,
    pub(super) groups: usize,
    pub(super) group_labels: Vec<String>,
    pub(super) held_out: String,
    /// Per effect table, per observation: the table's relative roughness², added to the
    /// model's variance wherever the effect is on.
    pub(super) roughness: Vec<Vec<f64>>,
    /// The emulator's tables by effect: the first is the effect at its library defaults, the
    /// others its variants at other values of its secondary parameters.
    pub(super) families: Vec<Vec<usize>>,
    /// The initial-state spread of each joint point of two dynamics effects, added to a pair's
    /// variance where both are on.
    pub(super) joint_spreads: Vec<joint_spread::JointSpread>,
}

/// What a candidate fits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Model {
    /// Nothing: the nominal model.
    Nominal,
    /// One effect (family index): its magnitude, and its secondary parameters over the
    /// family's variant tables.
    Single(usize),
    /// Two effects on fixed tables (table indices): both magnitudes.
    Pair(usize, usize),
}

/// The hold-out scheme by test, as reports name it.
const LEAVE_ONE_TEST_OUT: &str = "leave-one-test-out";

impl<'a> FitProblem<'a> {
    /// Held out by test: each group is one test, labelled by its id.
    pub(super) fn by_test(&self) -> bool {
        self.held_out == LEAVE_ONE_TEST_OUT
    }

    pub(super) fn new(
        campaign: &Campaign,
        emulator: &'a Emulator,
        options: &DiagnoseOptions,
    ) -> Self {
        Self::with_folds(campaign, emulator, options, held_out_by_test(campaign))
    }

    /// The problem held out by test (`by_test`) or by increment.
    pub(super) fn with_folds(
        campaign: &Campaign,
        emulator: &'a Emulator,
        options: &DiagnoseOptions,
        by_test: bool,
    ) -> Self {
        let mut obs = noise::observations(campaign);
        let noise = NoiseModel::estimate(campaign, &mut obs, emulator, options);
        let (group, groups, group_labels, held_out) = if by_test {
            (
                obs.iter().map(|o| o.test).collect(),
                campaign.tests.len(),
                campaign.tests.iter().map(|t| t.id.clone()).collect(),
                LEAVE_ONE_TEST_OUT.to_string(),
            )
        } else {
            let n = obs.iter().map(|o| o.increment + 1).max().unwrap_or(1);
            (
                obs.iter().map(|o| o.increment).collect(),
                n,
                (1..=n).map(|k| format!("increment {k}")).collect(),
                if held_out_by_test(campaign) {
                    "leave-one-increment-out".to_string()
                } else {
                    "leave-one-increment-out (fewer than 3 tests)".to_string()
                },
            )
        };
        // A variant (the effect at other secondary values, a few magnitudes) carries its
        // effect's roughness from the default table's full grid.
        let roughness = emulator
            .effects
            .iter()
            .map(|t| {
                let source = emulator
                    .effects
                    .iter()
                    .find(|d| d.info.name == t.info.name && d.parameters.is_empty())
                    .unwrap_or(t);
                let r = source.roughness();
                obs.iter()
                    .map(|o| r.get(&o.quantity.label()).copied().unwrap_or(0.0).powi(2))
                    .collect()
            })
            .collect();
        // One family per effect, from its first table, in the order effects first appear.
        let families: Vec<Vec<usize>> = (0..emulator.effects.len())
            .map(|i| emulator.family(i))
            .enumerate()
            .filter(|(i, f)| f[0] == *i)
            .map(|(_, f)| f)
            .collect();
        let joint_spreads = joint_spread::joint_spreads(emulator, &obs);
        Self {
            obs,
            noise,
            emulator,
            joint_spreads,
            roughness,
            group,
            groups,
            group_labels,
            held_out,
            families,
        }
    }

    /// Likelihood of `spec`'s predictions (effect table, magnitude) over the observations of
    /// the groups `mask` keeps, each channel's calibration scale integrated out
    /// ([`noise::gaussian`]).
    pub(super) fn totals(&self, spec: &[(usize, f64)], mask: &dyn Fn(usize) -> bool) -> Totals {
        self.totals_of(&self.emulator.predict(spec), spec, mask)
    }

    pub(super) fn totals_of(
        &self,
        p: &emulator::TestPredictions,
        spec: &[(usize, f64)],
        mask: &dyn Fn(usize) -> bool,
    ) -> Totals {
        let terms = self.terms_of(p, spec, mask).map(|(_, t)| t);
        noise::gaussian(terms, self.noise.scale_var)
    }

    /// Each kept observation's index and likelihood term under `spec`'s predictions `p`.
    pub(super) fn terms_of<'b>(
        &'b self,
        p: &'b emulator::TestPredictions,
        spec: &'b [(usize, f64)],
        mask: &'b dyn Fn(usize) -> bool,
    ) -> impl Iterator<Item = (usize, noise::Term)> + 'b {
        // Two effects: their joint points' initial-state spread, weighted once for every
        // observation.
        let pair = match spec {
            [a, b] => Some(joint_spread::pair_spread(
                &self.joint_spreads,
                self.emulator,
                *a,
                *b,
            )),
            _ => None,
        };
        self.obs
            .iter()
            .enumerate()
            .filter(|(i, _)| mask(self.group[*i]))
            .map(move |(i, o)| {
                let mut extra: f64 = spec
                    .iter()
                    .filter(|(_, m)| *m != 0.0)
                    .map(|(e, _)| self.roughness[*e][i])
                    .sum();
                let mu = o.predicted(p);
                if let Some(pair) = &pair {
                    extra += pair.rel_var(i, mu);
                }
                (i, self.noise.term(o, mu, extra))
            })
    }

    pub(super) fn nll_of(&self, spec: &[(usize, f64)], mask: impl Fn(usize) -> bool) -> f64 {
        self.totals(spec, &mask).nll
    }

    /// Magnitudes to try for table `e`: the table's points and four between each pair; where
    /// the campaign's records bound the effect's magnitude
    /// ([`Emulator::magnitude_measurement`]), only those within the band, and the band's ends.
    pub(super) fn candidates(&self, e: usize) -> Vec<f64> {
        let all = self.candidates_unbounded(e);
        let Some([lo, hi]) = self.emulator.magnitude_measurement(e).and_then(|m| m.band) else {
            return all;
        };
        let (first, last) = (all[0], all[all.len() - 1]);
        let mut out: Vec<f64> = all.into_iter().filter(|m| lo <= *m && *m <= hi).collect();
        out.extend([lo, hi].into_iter().filter(|m| first <= *m && *m <= last));
        out.sort_by(f64::total_cmp);
        out.dedup();
        if out.is_empty() {
            // A band outside the table's range: the table's end nearest to it.
            out.push(if hi < first { first } else { last });
        }
        out
    }

    /// [`FitProblem::candidates`] without the records' bound: what the masses alone would
    /// choose from.
    pub(super) fn candidates_unbounded(&self, e: usize) -> Vec<f64> {
        let m = &self.emulator.effects[e].magnitudes;
        let mut out = Vec::with_capacity(m.len() * 5);
        for w in m.windows(2) {
            for k in 0..5 {
                out.push(w[0] + (w[1] - w[0]) * k as f64 / 5.0);
            }
        }
        out.extend(m.last());
        out
    }

    /// [`FitProblem::candidates`] of table `e` between the table points either side of its
    /// point `x`.
    pub(super) fn candidates_near(&self, e: usize, x: f64) -> Vec<f64> {
        let m = &self.emulator.effects[e].magnitudes;
        let i = m.partition_point(|v| *v < x);
        let lo = m[i.saturating_sub(1)];
        let hi = m[(i + 1).min(m.len() - 1)];
        self.candidates(e)
            .into_iter()
            .filter(|c| *c >= lo && *c <= hi)
            .collect()
    }

    /// Why the records refuse what the masses alone would fit, if they do: for each member of
    /// `spec` (full-data fit) whose magnitude the records bound, the best magnitude over the
    /// unbounded candidates (the other members held) when it lies outside the band and fits
    /// the data better by more than [`PROFILE_95`].
    pub(super) fn refused_by_records(&self, spec: &[(usize, f64)]) -> Option<String> {
        let all = |_: usize| true;
        let at_fit = self.nll_of(spec, all);
        let reasons: Vec<String> = (0..spec.len())
            .filter_map(|i| {
                let (t, _) = spec[i];
                let mv = self.emulator.magnitude_measurement(t)?;
                let [lo, hi] = mv.band?;
                let mut trial = spec.to_vec();
                let (m, nll) = self
                    .candidates_unbounded(t)
                    .into_iter()
                    .map(|m| {
                        trial[i].1 = m;
                        (m, self.nll_of(&trial, all))
                    })
                    .min_by(|a, b| a.1.total_cmp(&b.1))?;
                (!(lo..=hi).contains(&m) && nll < at_fit - PROFILE_95).then(|| {
                    format!(
                        "{}.{} = {m:.4} (what the masses alone fit) is refused: {} allow [{lo:.4}, {hi:.4}]",
                        mv.effect, mv.parameter, mv.source
                    )
                })
            })
            .collect();
        (!reasons.is_empty()).then(|| reasons.join("; "))
    }

    /// The family (effect) of table `t`.
    pub(super) fn family_of(&self, t: usize) -> usize {
        self.families
            .iter()
            .position(|f| f.contains(&t))
            .unwrap_or(0)
    }

    /// Best magnitude of table `t` alone on the groups `mask` keeps (a grid search over the
    /// table refined five-fold): (magnitude, negative log-likelihood).
    pub(super) fn fit_table(&self, t: usize, mask: &dyn Fn(usize) -> bool) -> (f64, f64) {
        let mut best = (0.0, f64::INFINITY);
        for m in self.candidates(t) {
            let nll = self.nll_of(&[(t, m)], mask);
            if nll < best.1 {
                best = (m, nll);
            }
        }
        best
    }

    /// Best `(table, magnitude)` of `model` on the groups `mask` keeps, and its negative
    /// log-likelihood.
    ///
    /// - One effect: its magnitude over its default table; a variant table (other values of
    ///   its secondary parameters) is taken only when it beats the default's best by more than
    ///   [`PROFILE_95`] (a likelihood-ratio test at 95 %), so noise does not buy parameters.
    /// - Two effects: every magnitude of each alone (the singles' own candidates, so a pair
    ///   never fits the training data worse than either member), then both over the tables'
    ///   points, refined five-fold around the best; both are taken only when they beat the
    ///   better member alone by more than [`PROFILE_95`].
    pub(super) fn fit(&self, model: Model, mask: &dyn Fn(usize) -> bool) -> Fit {
        chosen(&self.fits(model, mask))
    }

    /// Every fit [`FitProblem::fit`] chooses among on the groups `mask` keeps, the library
    /// defaults' (or the tables the singles chose) first: one per table of the model's
    /// secondary values, each at its best magnitudes.
    pub(super) fn fits(&self, model: Model, mask: &dyn Fn(usize) -> bool) -> Vec<Fit> {
        match model {
            Model::Nominal => vec![(Vec::new(), self.nll_of(&[], mask))],
            Model::Single(f) => self.families[f]
                .iter()
                .map(|&t| {
                    let (m, n) = self.fit_table(t, mask);
                    (vec![(t, m)], n)
                })
                .collect(),
            Model::Pair(a, b) => {
                // The tables the singles chose first; another combination of the two
                // effects' tables (their secondary values profiled with the other member on)
                // only when it beats them by more than [`PROFILE_95`], as for a single.
                std::iter::once(self.fit_pair_tables(a, b, mask))
                    .chain(
                        self.pair_combinations(a, b)
                            .into_iter()
                            .map(|(ta, tb)| self.fit_pair_tables(ta, tb, mask)),
                    )
                    .collect()
            }
        }
    }

    /// Candidate evaluated: held-out per group, full-data fit, criteria.
    pub(super) fn evaluate(&self, model: Model, alpha: f64) -> Candidate {
        let mut held_nll = Vec::with_capacity(self.groups);
        let mut held_r2 = Vec::with_capacity(self.groups);
        let mut held_w = Vec::with_capacity(self.groups);
        let mut held_r2_spread = Vec::with_capacity(self.groups);
        let mut fold_specs = Vec::with_capacity(self.groups);
        for g in 0..self.groups {
            let fits = self.fits(model, &|h| h != g);
            let floor = fits.iter().map(|f| f.1).fold(f64::INFINITY, f64::min);
            let (spec, _) = chosen(&fits);
            // Held out: the joint likelihood less the training groups' alone, i.e. group `g`
            // given the training groups (their calibration scales carried over).
            let held_of = |spec: &[(usize, f64)]| {
                let p = self.emulator.predict(spec);
                self.totals_of(&p, spec, &|_| true) - self.totals_of(&p, spec, &|h| h != g)
            };
            let held = held_of(&spec);
            // The prediction carries the spread of what the training groups leave open: the
            // group's chi-square at the fit, among those the training groups do not refuse
            // (within PROFILE_95 of their best), that predicts it best.
            let spread = fits
                .iter()
                .filter(|f| f.1 <= floor + PROFILE_95 && f.0 != spec)
                .map(|f| held_of(&f.0).r2)
                .fold(held.r2, f64::min);
            held_nll.push(held.nll);
            held_r2.push(held.r2);
            held_r2_spread.push(spread);
            held_w.push(held.w);
            fold_specs.push(spec);
        }
        let (spec, nll_full) = self.fit(model, &|_| true);
        let full = self.totals(&spec, &|_| true);
        // Parameters fitted: each magnitude, and the secondary parameters of a variant that
        // the data do not measure.
        let k = spec
            .iter()
            .map(|(t, _)| 1 + self.emulator.fitted_secondaries(*t))
            .sum::<usize>() as f64;
        let n = full.w;
        let chi2 = full.r2;
        let residual_p = stats::lack_of_fit_p(chi2, n, k);
        let families = match model {
            Model::Nominal => Vec::new(),
            Model::Single(f) => vec![f],
            Model::Pair(a, b) => vec![self.family_of(a), self.family_of(b)],
        };
        Candidate {
            families,
            spec,
            fold_specs,
            held_nll,
            held_r2,
            held_r2_spread,
            held_w,
            aicc: stats::aicc(k, nll_full, n),
            bic: k * n.max(1.0).ln() + 2.0 * nll_full,
            residual_p,
            chi2,
            dof: n,
            k,
            alpha,
        }
    }

    /// Name of an effect (family) list: `a+b`, `none` when empty.
    pub(super) fn name_of(&self, families: &[usize]) -> String {
        if families.is_empty() {
            return "none".into();
        }
        families
            .iter()
            .map(|f| self.emulator.effects[self.families[*f][0]].info.name)
            .collect::<Vec<_>>()
            .join("+")
    }
}

/// A fit `(spec, negative log-likelihood)`.
pub(super) type Fit = (Vec<(usize, f64)>, f64);

/// The fit [`FitProblem::fit`] takes among `fits` ([`FitProblem::fits`]: the defaults' first):
/// [`unless_beaten`].
fn chosen(fits: &[Fit]) -> Fit {
    match fits.split_first() {
        Some((first, others)) => unless_beaten(first.clone(), others.iter().cloned()),
        None => (Vec::new(), f64::INFINITY),
    }
}

/// `first` (the library defaults, or the tables the singles chose), unless the best of
/// `others` (other secondary values) beats it by more than [`PROFILE_95`]: a likelihood-ratio
/// test at 95 %, so noise does not buy parameters. The first of equal bests is kept.
pub(super) fn unless_beaten(first: Fit, others: impl Iterator<Item = Fit>) -> Fit {
    let best = others.fold((Vec::new(), f64::INFINITY), |best, fit| {
        if fit.1 < best.1 {
            fit
        } else {
            best
        }
    });
    if best.1 < first.1 - PROFILE_95 {
        best
    } else {
        first
    }
}

/// Whether the campaign's default held-out groups are its tests (three or more of them) rather
/// than its increments.
pub(super) fn held_out_by_test(campaign: &Campaign) -> bool {
    campaign.tests.len() >= 3
}
