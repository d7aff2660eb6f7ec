//! Gap diagnosis (SPEC 7, issue 15): where the sim-to-real gap of a test campaign lies, which
//! effect of the library causes it, and how far it shrinks once that effect is added, judged on
//! held-out tests.
//!
//! Over 700 lines for now: the problem, the candidates' fits and the verdict rules (with
//! partly_explained) read together; the pairs' fitting is in pairs.rs, and the single
//! candidates' fitting is the part to move out next.
//!
//! 1. **Observations.** Per test, increment and weighed component: the specimens' mean mass
//!    loss; per test, increment, accelerometer location and axis: the specimens' mean square
//!    acceleration less the sensor noise variance.
//! 2. **Uncertainty** `u` of each observation about a prediction `μ` ([`noise`]):
//!    measurement and specimen scatter from the repeats (pooled relative variance; an assumed
//!    value, stated, when there are none) and the scale's quantisation; numerical, from a
//!    tolerance-halving run; parameters, from the wear coefficient's relative uncertainty and a
//!    friction sensitivity run; the accelerometers' calibration as one unknown scale per
//!    channel (location and axis), integrated out ([`noise::gaussian`]). Components of one
//!    specimen share its scatter, so each of a test's `n` components enters the likelihood
//!    with weight `1/n` (a composite likelihood, conservative when they are fully correlated).
//! 3. **Where** ([`location`]): standardized residuals `(y - μ)/u` of the nominal model, grouped
//!    by test, component, increment, contact-pressure and slip-speed band (weighted by where the
//!    model's friction work falls) and 1/3-octave band of the response spectrum; p-values
//!    adjusted by Holm's method (family-wise error rate 5 %).
//! 4. **Which**: each effect's magnitude is fitted by maximum likelihood on the training tests
//!    and judged on the held-out test given the training tests (leave-one-test-out with three
//!    or more tests, otherwise leave-one-increment-out); AICc and BIC of the full-data fit; a bootstrap over the held-out
//!    groups gives the probability that each ranks first. An effect *explains* the gap when its
//!    held-out log-likelihood gain over the nominal exceeds [`MIN_HELD_OUT_GAIN`], it removes
//!    at least [`MIN_EXPLAINED_SHARE`] of the nominal's excess chi-square, and the residuals
//!    left after it pass the lack-of-fit test at `alpha`: the diagnosis never names the least
//!    bad effect. Pairs are tried when no single effect explains. When one test carries what
//!    the leading single explains, leave-one-test-out has nothing to fit it on; the campaign
//!    is then judged again leave-one-increment-out, and an effect that passes there is named
//!    `partly_explained` (confirmed within that test only).
//! 5. **How far**: held-out RMS standardized error before and after, the shrink and its
//!    bootstrap interval, and the fitted magnitude with its profile-likelihood interval.

pub mod bench;
pub mod budget;
pub mod carry;
pub mod emulator;
mod how_far;
#[cfg(test)]
mod interaction_tests;
mod joint_spread;
pub mod location;
pub mod measured;
pub mod noise;
mod pair_search;
mod pairs;
pub mod plots;
pub mod prediction;
mod refine;
mod report;
mod secondary_values;
pub mod stats;
pub mod table;
pub mod truth_fit;

use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use crate::pipeline::RunControl;
use emulator::{Emulator, EmulatorOptions};
use how_far::{best_effect, held_out_predictions, partly_explained};
use noise::{NoiseModel, Observation, Totals};
pub use refine::diagnose_refining;
pub use report::*;
use std::path::Path;

/// Held-out log-likelihood gain over the nominal model an effect must exceed to count as an
/// improvement beyond noise: a likelihood ratio of e² (about 7.4), the conventional "strong"
/// evidence threshold (Kass & Raftery 1995), on data the fit did not see.
pub const MIN_HELD_OUT_GAIN: f64 = 2.0;

/// Share of the nominal model's excess chi-square an explaining effect must remove: an effect
/// that passes the lack-of-fit test only because the gap was marginal, while accounting for
/// little of it, does not explain it.
pub const MIN_EXPLAINED_SHARE: f64 = 0.5;

/// Default rounds of adaptive refinement ([`DiagnoseOptions::refine_rounds`]).
pub const REFINE_ROUNDS: usize = 3;

/// Dynamics effects refined per round: those with the best held-out log-likelihood among the
/// ones that improve on the nominal.
pub const REFINE_CONTENDERS: usize = 3;

/// Held-out shrink below which a named effect only partly explains the gap
/// ([`Verdict::PartlyExplained`]): it fits the training tests but predicts the held-out ones
/// little better than the nominal model.
pub const MIN_EXPLAINED_SHRINK: f64 = 0.2;

/// Effects whose secondary parameters are fitted when they lead and leave lack-of-fit: three,
/// so a pair of the two that are not first (a friction drift beside a cross-axis drive whose
/// single fit a fixture compliance follows) has both members' variants to choose from.
pub const SECONDARY_CONTENDERS: usize = 3;

/// Profile-likelihood drop of a 95 % interval for one parameter (chi-square 1 dof: 3.84 / 2).
pub const PROFILE_95: f64 = 1.920_729_410_347_062;

/// What the refinement steps and the truth's own fit simulate with: the campaign, the
/// diagnosis' options, the reference configs, the run's control and the window cache.
#[derive(Clone, Copy)]
pub struct Simulating<'a> {
    /// The campaign diagnosed.
    pub campaign: &'a Campaign,
    /// The diagnosis' options.
    pub options: &'a DiagnoseOptions,
    /// Directory of reference configs and profiles.
    pub configs_dir: &'a Path,
    /// Cancellation and progress of the simulations.
    pub control: &'a RunControl,
    /// Windows simulated already.
    pub cache: &'a WindowCache,
}

impl<'a> Simulating<'a> {
    /// `(campaign, options, configs_dir, control, cache)`.
    pub fn parts(
        self,
    ) -> (
        &'a Campaign,
        &'a DiagnoseOptions,
        &'a Path,
        &'a RunControl,
        &'a WindowCache,
    ) {
        (
            self.campaign,
            self.options,
            self.configs_dir,
            self.control,
            self.cache,
        )
    }
}

/// How the diagnosis runs.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseOptions {
    /// Simulations.
    pub emulator: EmulatorOptions,
    /// Significance level of the lack-of-fit tests and flags.
    pub alpha: f64,
    /// Bootstrap rounds.
    pub bootstrap_rounds: usize,
    /// Relative specimen scatter assumed when the campaign has no repeats (1 sigma).
    pub assumed_scatter_rel: f64,
    /// Relative standard uncertainty of the wear coefficient K (parameter uncertainty).
    pub k_rel_uncertainty: f64,
    /// Relative calibration uncertainty of an accelerometer's sensitivity (a mean square
    /// carries twice it).
    pub accelerometer_calibration_rel: f64,
    /// Rounds of adaptive refinement: each round simulates the dynamics effects that improve
    /// the held-out fit at the magnitudes their fits land on (on all tests and on every
    /// training fold) where the table holds no simulation yet, then fits again. 0 keeps the
    /// grid alone.
    pub refine_rounds: usize,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self {
            emulator: EmulatorOptions::default(),
            alpha: 0.01,
            bootstrap_rounds: 500,
            assumed_scatter_rel: 0.3,
            k_rel_uncertainty: 0.1,
            accelerometer_calibration_rel: 0.02,
            refine_rounds: REFINE_ROUNDS,
        }
    }
}

/// The data, noise model and folds of one diagnosis.
pub struct FitProblem<'a> {
    obs: Vec<Observation>,
    noise: NoiseModel,
    emulator: &'a Emulator,
    /// Group (fold) of each observation.
    group: Vec<usize>,
    groups: usize,
    group_labels: Vec<String>,
    held_out: String,
    /// Per effect table, per observation: the table's relative roughness², added to the
    /// model's variance wherever the effect is on.
    roughness: Vec<Vec<f64>>,
    /// The emulator's tables by effect: the first is the effect at its library defaults, the
    /// others its variants at other values of its secondary parameters.
    families: Vec<Vec<usize>>,
    /// The initial-state spread of each joint point of two dynamics effects, added to a pair's
    /// variance where both are on.
    joint_spreads: Vec<joint_spread::JointSpread>,
}

/// What a candidate fits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Model {
    /// Nothing: the nominal model.
    Nominal,
    /// One effect (family index): its magnitude, and its secondary parameters over the
    /// family's variant tables.
    Single(usize),
    /// Two effects on fixed tables (table indices): both magnitudes.
    Pair(usize, usize),
}

impl<'a> FitProblem<'a> {
    fn new(campaign: &Campaign, emulator: &'a Emulator, options: &DiagnoseOptions) -> Self {
        Self::with_folds(campaign, emulator, options, held_out_by_test(campaign))
    }

    /// The problem held out by test (`by_test`) or by increment.
    fn with_folds(
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
                "leave-one-test-out".to_string(),
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
    fn totals(&self, spec: &[(usize, f64)], mask: &dyn Fn(usize) -> bool) -> Totals {
        self.totals_of(&self.emulator.predict(spec), spec, mask)
    }

    fn totals_of(
        &self,
        p: &emulator::TestPredictions,
        spec: &[(usize, f64)],
        mask: &dyn Fn(usize) -> bool,
    ) -> Totals {
        let terms = self.terms_of(p, spec, mask).map(|(_, t)| t);
        noise::gaussian(terms, self.noise.scale_var)
    }

    /// Each kept observation's index and likelihood term under `spec`'s predictions `p`.
    fn terms_of<'b>(
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

    fn nll_of(&self, spec: &[(usize, f64)], mask: impl Fn(usize) -> bool) -> f64 {
        self.totals(spec, &mask).nll
    }

    /// Magnitudes to try for table `e`: the table's points and four between each pair.
    fn candidates(&self, e: usize) -> Vec<f64> {
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
    fn candidates_near(&self, e: usize, x: f64) -> Vec<f64> {
        let m = &self.emulator.effects[e].magnitudes;
        let i = m.partition_point(|v| *v < x);
        let lo = m[i.saturating_sub(1)];
        let hi = m[(i + 1).min(m.len() - 1)];
        self.candidates(e)
            .into_iter()
            .filter(|c| *c >= lo && *c <= hi)
            .collect()
    }

    /// The family (effect) of table `t`.
    fn family_of(&self, t: usize) -> usize {
        self.families
            .iter()
            .position(|f| f.contains(&t))
            .unwrap_or(0)
    }

    /// Best magnitude of table `t` alone on the groups `mask` keeps (a grid search over the
    /// table refined five-fold): (magnitude, negative log-likelihood).
    fn fit_table(&self, t: usize, mask: &dyn Fn(usize) -> bool) -> (f64, f64) {
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
    fn fit(&self, model: Model, mask: &dyn Fn(usize) -> bool) -> Fit {
        match model {
            Model::Nominal => (Vec::new(), self.nll_of(&[], mask)),
            Model::Single(f) => {
                let tables = &self.families[f];
                let (m0, n0) = self.fit_table(tables[0], mask);
                let variants = tables[1..].iter().map(|&t| {
                    let (m, n) = self.fit_table(t, mask);
                    (vec![(t, m)], n)
                });
                unless_beaten((vec![(tables[0], m0)], n0), variants)
            }
            Model::Pair(a, b) => {
                // The tables the singles chose first; another combination of the two
                // effects' tables (their secondary values profiled with the other member on)
                // only when it beats them by more than [`PROFILE_95`], as for a single.
                let combinations = self
                    .pair_combinations(a, b)
                    .into_iter()
                    .map(|(ta, tb)| self.fit_pair_tables(ta, tb, mask));
                unless_beaten(self.fit_pair_tables(a, b, mask), combinations)
            }
        }
    }

    /// Candidate evaluated: held-out per group, full-data fit, criteria.
    fn evaluate(&self, model: Model, alpha: f64) -> Candidate {
        let mut held_nll = Vec::with_capacity(self.groups);
        let mut held_r2 = Vec::with_capacity(self.groups);
        let mut held_w = Vec::with_capacity(self.groups);
        let mut fold_specs = Vec::with_capacity(self.groups);
        for g in 0..self.groups {
            let (spec, _) = self.fit(model, &|h| h != g);
            // Held out: the joint likelihood less the training groups' alone, i.e. group `g`
            // given the training groups (their calibration scales carried over).
            let p = self.emulator.predict(&spec);
            let held =
                self.totals_of(&p, &spec, &|_| true) - self.totals_of(&p, &spec, &|h| h != g);
            held_nll.push(held.nll);
            held_r2.push(held.r2);
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
    fn name_of(&self, families: &[usize]) -> String {
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
type Fit = (Vec<(usize, f64)>, f64);

/// `first` (the library defaults, or the tables the singles chose), unless the best of
/// `others` (other secondary values) beats it by more than [`PROFILE_95`]: a likelihood-ratio
/// test at 95 %, so noise does not buy parameters. The first of equal bests is kept.
fn unless_beaten(first: Fit, others: impl Iterator<Item = Fit>) -> Fit {
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

/// The member every pair of `within` (the chosen pair first, then the explaining pairs the
/// report lists as indistinguishable from it) shares, when there are two or more and they
/// share only that one: which partner goes with it, the data do not say (seed 1043 of the
/// bench: a cross-axis share fitted beside severe wear, beside a fixture compliance and beside
/// wear above the cutoff, held-out errors 1.244, 1.235 and 743, the last first in a tenth of
/// the bootstrap resamples). Returns the member's family.
fn shared_member(pairs: &[Candidate], within: &[usize]) -> Option<usize> {
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

/// One candidate's numbers.
#[derive(Debug, Clone)]
struct Candidate {
    /// Effects (family indices), for its name.
    families: Vec<usize>,
    /// Full-data fit: (table, magnitude) per effect.
    spec: Vec<(usize, f64)>,
    /// The fit on each training fold (the held-out predictions use them).
    fold_specs: Vec<Vec<(usize, f64)>>,
    held_nll: Vec<f64>,
    held_r2: Vec<f64>,
    held_w: Vec<f64>,
    aicc: f64,
    bic: f64,
    residual_p: f64,
    chi2: f64,
    dof: f64,
    /// Parameters fitted (full data).
    k: f64,
    alpha: f64,
}

impl Candidate {
    fn held_ll(&self) -> f64 {
        -self.held_nll.iter().sum::<f64>()
    }

    fn held_error(&self) -> f64 {
        (self.held_r2.iter().sum::<f64>() / self.held_w.iter().sum::<f64>().max(1e-300)).sqrt()
    }

    fn magnitudes(&self) -> Vec<f64> {
        self.spec.iter().map(|s| s.1).collect()
    }

    /// The table of a single effect's full-data fit.
    fn table(&self) -> usize {
        self.spec.first().map_or(0, |s| s.0)
    }

    fn explained_share(&self, nominal: &Candidate) -> f64 {
        let excess = nominal.chi2 - nominal.dof;
        if excess > 0.0 {
            (nominal.chi2 - self.chi2) / excess
        } else {
            0.0
        }
    }

    /// Explains, but fitted at a magnitude bound or with a held-out shrink under
    /// [`MIN_EXPLAINED_SHRINK`] (what `partly_explained` reports).
    fn only_partly(&self, nominal: &Candidate, emulator: &Emulator) -> bool {
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
        at_bound || !(shrink >= MIN_EXPLAINED_SHRINK)
    }

    fn explains(&self, nominal: &Candidate) -> bool {
        self.held_ll() - nominal.held_ll() > MIN_HELD_OUT_GAIN
            && self.residual_p >= self.alpha
            && self.explained_share(nominal) >= MIN_EXPLAINED_SHARE
    }

    /// Explains, and not only partly: what lets a single stand without pairs or profiles.
    fn explains_cleanly(&self, nominal: &Candidate, emulator: &Emulator) -> bool {
        self.explains(nominal) && !self.only_partly(nominal, emulator)
    }
}

/// Runs the diagnosis: builds the emulator (simulations, reported through `progress(done,
/// total)`), then fits, ranks and locates. The campaign is taken as validated
/// ([`Campaign::validate`]): the service validates it once on upload, the CLI as it loads it.
pub fn diagnose(
    campaign: &Campaign,
    configs_dir: &Path,
    options: &DiagnoseOptions,
    control: &RunControl,
    cache: &WindowCache,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(Report, Emulator), GapError> {
    check_options(options)?;
    // Refused before anything is simulated.
    if noise::observations(campaign).is_empty() {
        return Err(no_measurement());
    }
    let built = std::sync::atomic::AtomicUsize::new(0);
    let mut emulator = Emulator::build(
        campaign,
        configs_dir,
        &options.emulator,
        control,
        cache,
        &|done, total| {
            built.fetch_max(done, std::sync::atomic::Ordering::SeqCst);
            progress(done, total)
        },
    )?;
    // Refinement's simulations count on from the emulator's, so progress never goes back.
    let offset = built.into_inner();
    let report = diagnose_refining(
        campaign,
        &mut emulator,
        options,
        configs_dir,
        control,
        cache,
        &|done, total| progress(offset + done, offset + total),
    )?;
    Ok((report, emulator))
}

/// The one set of rules for a diagnosis' options, for the CLI and the service alike; an error
/// names the option (`window_s`, `grid_points`, ...).
pub fn check_options(o: &DiagnoseOptions) -> Result<(), GapError> {
    let rule = GapError::require;
    rule(
        "alpha",
        o.alpha > 0.0 && o.alpha < 0.5,
        "must lie in (0, 0.5)",
    )?;
    rule(
        "bootstrap_rounds",
        (10..=100_000).contains(&o.bootstrap_rounds),
        "must lie in 10..=100000",
    )?;
    // The service's bounds (one set, with their reasons, in pipeline::limits).
    crate::pipeline::check_window_s(o.emulator.window_s)?;
    crate::pipeline::check_settle_s(o.emulator.settle_s)?;
    crate::pipeline::check_grid_points(o.emulator.grid_points)?;
    rule(
        "threads",
        (1..=64).contains(&o.emulator.threads),
        "must lie in 1..=64",
    )?;
    rule(
        "accelerometer_rate_hz",
        o.emulator.accelerometer_rate_hz.is_finite()
            && o.emulator.accelerometer_rate_hz >= 100.0
            && o.emulator.accelerometer_rate_hz <= 1e5,
        "must lie in [100, 1e5] Hz",
    )?;
    rule(
        "assumed_scatter_rel",
        o.assumed_scatter_rel.is_finite()
            && o.assumed_scatter_rel > 0.0
            && o.assumed_scatter_rel <= 2.0,
        "must lie in (0, 2]",
    )?;
    rule(
        "accelerometer_calibration_rel",
        o.accelerometer_calibration_rel.is_finite()
            && (0.0..=0.5).contains(&o.accelerometer_calibration_rel),
        "must lie in [0, 0.5]",
    )?;
    rule(
        "k_rel_uncertainty",
        o.k_rel_uncertainty.is_finite() && (0.0..=2.0).contains(&o.k_rel_uncertainty),
        "must lie in [0, 2]",
    )?;
    Ok(())
}

/// A campaign with nothing measured (a skeleton for the rig) cannot be diagnosed.
fn no_measurement() -> GapError {
    GapError::field(
        "tests",
        "the campaign has no measurement to diagnose (every mass_loss_mg is empty)",
    )
}

/// Whether the campaign's default held-out groups are its tests (three or more of them) rather
/// than its increments.
fn held_out_by_test(campaign: &Campaign) -> bool {
    campaign.tests.len() >= 3
}

/// Share of a candidate's full-data chi-square reduction that one group must carry for the
/// effect to count as seen in that group alone.
const ONE_GROUP_SHARE: f64 = 0.9;

/// For a `not_explained` verdict, the sentence on [`one_group_single`]'s effect: it is seen in
/// one group alone, so leaving the group out leaves nothing to fit it on; the campaign cannot
/// confirm it, and more tests like that group could.
fn seen_in_one_group(problem: &FitProblem, (c, g, share): OneGroup) -> String {
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
type OneGroup<'c> = (&'c Candidate, usize, f64);

/// The best single (by full-data chi-square) that fits every observation within the noise
/// (lack-of-fit p >= `alpha`) but does not explain held out, if one held-out group carries at
/// least [`ONE_GROUP_SHARE`] of its chi-square reduction.
fn one_group_single<'c>(
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
fn carried_by_one_group(problem: &FitProblem, c: &Candidate) -> Option<(usize, f64)> {
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
    if within.verdict != Verdict::PartlyExplained {
        return Ok(report);
    }
    within.held_out = format!("leave-one-increment-out, as {carried}");
    Ok(within)
}

/// The verdict on one way of holding data out, and, when one held-out group carries what the
/// leading single explains (so the held-out fits cannot confirm it), which group and how much.
/// `scope`, when given, is a reason every named candidate explains only partly.
fn judge(
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
    };
    let ranking: Vec<RankEntry> = order.iter().map(|&i| entry(&singles[i], 1 + i)).collect();
    let held_out_predictions = order
        .first()
        .map(|&i| held_out_predictions(campaign, problem, &singles[i]))
        .unwrap_or_default();
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
        // full-data AICc instead (docs/diagnosis.md, "Seen in one test").
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

    let chosen_candidate: Option<&Candidate> = chosen.as_ref().map(|(c, _)| *c);
    let best_effect = chosen
        .as_ref()
        .map(|(c, _)| best_effect(problem, c, &nominal, &resamples));
    let partly = chosen
        .as_ref()
        .zip(best_effect.as_ref())
        .and_then(|((c, _), b)| {
            let also: Vec<&str> = unidentified
                .iter()
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
            text
        }
    };
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
        multiple_comparisons: "Holm step-down over every group of `where` (family-wise error rate 0.05)".into(),
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
        code_version: crate::models::case::code_version().to_string(),
    };
    (report, carried)
}

/// The nominal model and every single effect evaluated, when the nominal model shows a gap
/// (None otherwise).
fn singles_if_gap(
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
fn singles_unexplained(
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

/// Requests `(table, magnitude)` of a candidate's simulated tables at its full-data and every
/// fold's fitted magnitudes.
fn requests_of(emulator: &Emulator, c: &Candidate) -> Vec<(usize, f64)> {
    std::iter::once(&c.spec)
        .chain(c.fold_specs.iter())
        .flat_map(|s| s.iter().copied())
        .filter(|(t, m)| *m != 0.0 && emulator.effects[*t].simulated)
        .collect()
}

#[cfg(test)]
mod option_tests {
    use super::*;

    #[test]
    fn options_outside_their_bounds_are_refused_naming_the_option() {
        assert!(check_options(&DiagnoseOptions::default()).is_ok());
        let mut o = DiagnoseOptions::default();
        o.emulator.window_s = 0.04;
        let e = check_options(&o).unwrap_err();
        assert_eq!(e.field_path(), Some("window_s"), "{e}");
        assert!(e.to_string().contains("[0.05, 600] s"), "{e}");
        let mut o = DiagnoseOptions::default();
        o.emulator.grid_points = 13;
        assert_eq!(
            check_options(&o).unwrap_err().field_path(),
            Some("grid_points")
        );
    }
}

#[cfg(test)]
mod shared_member_tests {
    use super::*;

    /// A pair of families `a`, `b` with held-out log-likelihood `ll` (one group).
    fn pair(a: usize, b: usize, ll: f64) -> Candidate {
        Candidate {
            families: vec![a, b],
            spec: Vec::new(),
            fold_specs: Vec::new(),
            held_nll: vec![-ll],
            held_r2: vec![0.0],
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
