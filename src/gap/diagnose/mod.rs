//! Gap diagnosis (SPEC 7, issue 15): where the sim-to-real gap of a test campaign lies, which
//! effect of the library causes it, and how far it shrinks once that effect is added, judged on
//! held-out tests.
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
//!
//! The rooms: [`options`] (the options and the constants of the rules), `fit_problem` (the
//! data, noise model and folds, and each candidate's fit), `candidate` (one candidate's
//! numbers and the explaining rule), `verdict` (the verdict from the candidates), `one_group`
//! (an effect one held-out group carries), `how_far`, `pairs` and `pair_search`, `refine`
//! (adaptive refinement) and `run` (the whole diagnosis from a campaign); the [`emulator`],
//! the [`next_test`] planner (the tests that would separate the leading candidates) and the
//! `bench` are rooms of their own.

pub mod bench;
pub mod budget;
mod candidate;
pub mod carry;
pub mod emulator;
mod fit_problem;
mod how_far;
pub mod identification;
#[cfg(test)]
mod interaction_tests;
mod joint_spread;
pub mod location;
pub mod measured;
pub mod next_test;
pub mod noise;
mod one_group;
pub mod options;
mod pair_search;
mod pairs;
pub mod plots;
pub mod prediction;
mod refine;
mod report;
mod run;
mod secondary_values;
pub mod stats;
pub mod table;
pub mod truth_fit;
mod verdict;

pub use fit_problem::FitProblem;
pub use next_test::propose as propose_next_tests;
pub use options::{
    check_effects, check_options, DiagnoseOptions, Simulating, MIN_EXPLAINED_SHARE,
    MIN_EXPLAINED_SHRINK, MIN_HELD_OUT_GAIN, PROFILE_95, REFINE_CONTENDERS, REFINE_ROUNDS,
    SECONDARY_CONTENDERS,
};
pub use refine::diagnose_refining;
pub use report::*;
pub use run::diagnose;
pub use verdict::diagnose_with;
