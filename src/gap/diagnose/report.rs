//! The diagnosis report (`railwear diagnose --json`, the diagnose job's result): verdict, the
//! chosen effect and how far it closes the gap, the ranking, where the residuals lie, the
//! nominal fit, the noise model, how the predictions were made and the held-out predictions.

use super::{location, noise};
use serde::{Deserialize, Serialize};

/// The verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The nominal model agrees with the measurements within their uncertainty.
    NoGap,
    /// An effect (or a pair) explains the gap on held-out tests: it passes the explaining
    /// rule, shrinks the held-out error, is fitted inside its bounds and predicts every
    /// held-out group within its noise (Holm-adjusted).
    Explained,
    /// An effect (or a pair) passes the explaining rule but is fitted at its physical bound,
    /// shrinks the held-out error by less than [`super::MIN_EXPLAINED_SHRINK`] or leaves a
    /// held-out group it does not predict within its noise: named, with what it leaves and the
    /// groups it cannot predict ([`Report::partly_explained`]).
    PartlyExplained,
    /// There is a gap and no effect of the library explains it.
    NotExplained,
}

/// A fitted or fixed parameter of the chosen effect.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedParameter {
    /// Effect.
    pub effect: String,
    /// Parameter name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Value the predictions use (fitted on all tests, measured, or the library default when
    /// not fitted). Not a measurement of the parameter unless `identified`.
    pub value: f64,
    /// 95 % profile-likelihood interval (fitted parameters), clipped to the bounds.
    pub interval: Option<[f64; 2]>,
    /// Physical bounds.
    pub bounds: [f64; 2],
    /// True when fitted; false when held at the library default or measured.
    pub fitted: bool,
    /// Where a measured value comes from (the campaign's data measure it before any fit; its
    /// interval is the measurement's 95 %).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measured_from: Option<String>,
    /// The data identify it: measured, or fitted with a 95 % interval spanning less than
    /// [`UNIDENTIFIED_SHARE`](super::identification::UNIDENTIFIED_SHARE) of its physical
    /// range. False when held at the library default or when the interval spans (nearly) the
    /// whole range: `value` is then the search's choice, not the data's.
    #[serde(default = "identified_by_default")]
    pub identified: bool,
    /// The physical bounds its 95 % interval reaches (`min`, `max`): the data would take it
    /// there or beyond.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bounds_reached: Vec<String>,
}

fn identified_by_default() -> bool {
    true
}

impl FittedParameter {
    /// `effect.name`.
    pub fn label(&self) -> String {
        format!("{}.{}", self.effect, self.name)
    }

    /// The parameter as the text summary gives it: its value and interval when identified;
    /// otherwise no value, only the interval that says the data do not measure it.
    pub fn describe(&self) -> String {
        let reached = if self.bounds_reached.is_empty() {
            String::new()
        } else {
            format!(
                "; its interval reaches the physical {} bound",
                self.bounds_reached.join(" and ")
            )
        };
        match (self.identified, self.fitted, self.interval, &self.measured_from) {
            (true, _, Some([lo, hi]), Some(source)) => format!(
                "{} = {:.4e} {} (measured by {source}: 95 % interval [{lo:.4e}, {hi:.4e}])",
                self.label(),
                self.value,
                self.unit
            ),
            (true, true, Some([lo, hi]), None) => format!(
                "{} = {:.4e} {} (95 % interval [{lo:.4e}, {hi:.4e}]; bounds [{}, {}]{reached})",
                self.label(),
                self.value,
                self.unit,
                self.bounds[0],
                self.bounds[1]
            ),
            (false, true, Some([lo, hi]), _) => format!(
                "{}: not identified by the data (95 % interval [{lo:.4e}, {hi:.4e}] {} spans its physical range [{}, {}])",
                self.label(),
                self.unit,
                self.bounds[0],
                self.bounds[1]
            ),
            _ => format!(
                "{}: held at the library default {:.4e} {} (not fitted)",
                self.label(),
                self.value,
                self.unit
            ),
        }
    }
}

/// The chosen effect and how far it closes the gap.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BestEffect {
    /// Effect name, or `a+b` for a pair.
    pub name: String,
    /// Parameters.
    pub parameters: Vec<FittedParameter>,
    /// Held-out RMS standardized error of the nominal model.
    pub held_out_error_before: f64,
    /// Held-out RMS standardized error with the effect.
    pub held_out_error_after: f64,
    /// 1 - after / before.
    pub shrink: f64,
    /// 90 % bootstrap interval of the shrink (over held-out groups).
    pub shrink_interval: [f64; 2],
    /// Lack-of-fit p-value of the residuals left with the effect (full-data fit).
    pub residual_p_value: f64,
    /// Held-out RMS standardized error per held-out group, before and after.
    pub per_group: Vec<GroupError>,
}

/// Held-out error of one held-out group.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupError {
    /// Group (test id, or increment).
    pub group: String,
    /// Nominal model.
    pub before: f64,
    /// With the effect.
    pub after: f64,
    /// Holm-adjusted p-value of the group's held-out chi-square with the effect (across the
    /// held-out groups).
    #[serde(default)]
    pub p_adjusted: f64,
    /// The largest held-out error the rule accepts for the group (Holm's first step, at the
    /// report's `alpha`, on the group's degrees of freedom).
    #[serde(default)]
    pub bound: f64,
    /// Predicted within its noise: Holm-adjusted p-value at least `alpha`.
    #[serde(default = "predicted_by_default")]
    pub predicted: bool,
}

fn predicted_by_default() -> bool {
    true
}

/// One candidate in the ranking.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RankEntry {
    /// Effect name, `a+b` for a pair, `none` for the nominal model.
    pub name: String,
    /// Fitted magnitudes (full data), in the order of the names.
    pub magnitudes: Vec<f64>,
    /// Each member's secondary parameters where its fit took a variant table (other values
    /// than the library defaults), in the order of the names; empty maps for the defaults.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub secondary: Vec<std::collections::BTreeMap<String, f64>>,
    /// Parameters fitted.
    pub parameters: usize,
    /// Held-out log-likelihood (sum over held-out groups).
    pub held_out_log_likelihood: f64,
    /// Gain over the nominal model's held-out log-likelihood.
    pub held_out_gain: f64,
    /// 90 % bootstrap interval of the gain (held-out groups resampled, the resamples of
    /// `p_first`).
    #[serde(default)]
    pub held_out_gain_interval: [f64; 2],
    /// Held-out RMS standardized error.
    pub held_out_error: f64,
    /// AICc of the full-data fit.
    pub aicc: f64,
    /// BIC of the full-data fit.
    pub bic: f64,
    /// Lack-of-fit p-value of the full-data fit.
    pub residual_p_value: f64,
    /// Bootstrap probability of ranking first (among candidates and the nominal).
    pub p_first: f64,
    /// Share of the nominal model's excess chi-square (chi2 - dof) the full-data fit removes.
    pub explained_share: f64,
    /// Explains the gap: gain > MIN_HELD_OUT_GAIN, residual p-value >= alpha and at least
    /// [`MIN_EXPLAINED_SHARE`](super::MIN_EXPLAINED_SHARE) of the excess removed.
    pub explains: bool,
    /// Where the campaign's records bound a magnitude and the masses alone would fit one
    /// outside that band: the value refused and why (the candidate is judged within the band).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refused_by_records: Option<String>,
}

/// Fit of the nominal model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NominalFit {
    /// Weighted sum of squared standardized residuals.
    pub chi2: f64,
    /// Degrees of freedom (weighted observation count).
    pub dof: f64,
    /// Lack-of-fit p-value.
    pub p_value: f64,
    /// Held-out log-likelihood (no parameter: the plain log-likelihood).
    pub held_out_log_likelihood: f64,
    /// RMS standardized error.
    pub held_out_error: f64,
}

/// How the predictions were made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EmulatorReport {
    /// Simulated excitation per increment, s.
    pub window_s: f64,
    /// Settle, s.
    pub settle_s: f64,
    /// Windows simulated.
    pub simulations: usize,
    /// Dynamics-effect grid points (positive side).
    pub grid_points: usize,
    /// Approximations, in words.
    pub approximations: Vec<String>,
}

/// The diagnosis report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Campaign name.
    pub campaign: String,
    /// Verdict.
    pub verdict: Verdict,
    /// One sentence.
    pub summary: String,
    /// The effect (or pair) chosen, when explained.
    pub best_effect: Option<BestEffect>,
    /// Other explaining candidates that cannot be told apart from the best.
    pub indistinguishable: Vec<String>,
    /// Single effects, best held-out log-likelihood first.
    pub ranking: Vec<RankEntry>,
    /// Pairs tried (when no single effect explains).
    pub pairs: Vec<RankEntry>,
    /// Where the nominal model misses.
    #[serde(rename = "where")]
    pub location: location::Where,
    /// Nominal fit.
    pub nominal: NominalFit,
    /// Uncertainty model.
    pub noise: noise::NoiseReport,
    /// Hold-out scheme.
    pub held_out: String,
    /// Multiple-comparison correction.
    pub multiple_comparisons: String,
    /// Significance level.
    pub alpha: f64,
    /// Predictions.
    pub emulator: EmulatorReport,
    /// Held-out predictions of every measured mass: the nominal model's and the verdict's
    /// effect or pair's (the best-ranked single's when none is named), fitted without the
    /// observation's group, with an interval (what the model, given the other tests, says
    /// this test should have lost).
    #[serde(default)]
    pub held_out_predictions: Vec<HeldOutPrediction>,
    /// Why the verdict is `partly_explained`: the leading candidate, what it leaves, the test
    /// it cannot predict (None for the other verdicts).
    #[serde(default)]
    pub partly_explained: Option<PartlyExplained>,
    /// The campaign tests whose repetition would let held-out data confirm the leading
    /// candidate (held out by test only): the tests it cannot predict held out, furthest
    /// above its bound first. The next tests start with their repeats
    /// (docs/results/diagnosis.md, "The next test").
    #[serde(default)]
    pub to_repeat: Vec<String>,
    /// The campaign test that carries 90 % or more of what the leading candidate explains
    /// (held out by test only): held out, nothing else informs it, so the campaign cannot
    /// confirm the candidate until a second test carries it (docs/results/diagnosis.md, "Seen
    /// in one test"). None when no one test carries it.
    #[serde(default)]
    pub carried_by: Option<String>,
    /// The tests that would best confirm the leading candidate or separate it from its
    /// rivals: the repeats of `to_repeat` first, then cheapest decisive first
    /// (docs/results/diagnosis.md, "The next test"); empty when the verdict is `no_gap` or
    /// `explained` without indistinguishable candidates.
    #[serde(default)]
    pub next_tests: Vec<ProposedTest>,
    /// railwear version.
    pub code_version: String,
}

/// A candidate that passes the explaining rule but does not carry the gap on held-out data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartlyExplained {
    /// The leading candidate (effect, or `a+b`).
    pub candidate: String,
    /// Why it is not `explained`, in words (fitted at its bound, held-out shrink under 20 %).
    pub reasons: Vec<String>,
    /// Parameters fitted at a physical bound (`effect.parameter`).
    pub at_bound: Vec<String>,
    /// Held-out RMS standardized error before (nominal) and after.
    pub held_out_error: [f64; 2],
    /// Held-out shrink.
    pub shrink: f64,
    /// What it leaves: the full-data fit's chi-square, its degrees of freedom and lack-of-fit
    /// p-value.
    pub chi2_left: f64,
    /// Degrees of freedom of `chi2_left`.
    pub dof: f64,
    /// Lack-of-fit p-value of what it leaves.
    pub residual_p_value: f64,
    /// The held-out groups it does not predict within their noise (Holm-adjusted p below
    /// `alpha`), with their errors and bounds.
    #[serde(default)]
    pub unpredicted: Vec<GroupError>,
    /// The held-out group it predicts worst: the unpredicted group furthest above its bound,
    /// or, when every group is predicted, the one with the largest held-out error.
    pub cannot_predict: String,
    /// That group's held-out RMS standardized error, nominal and with the candidate.
    pub cannot_predict_error: [f64; 2],
}

impl PartlyExplained {
    /// The report's one-sentence summary.
    pub fn sentence(&self) -> String {
        format!(
            "partly explained by {} ({}): held-out error {:.2} -> {:.2} (shrink {:.0} %); it leaves chi2 {:.1} on {:.1} dof (p = {:.2e}) and cannot predict {} (held-out error {:.2} -> {:.2})",
            self.candidate,
            self.reasons.join("; "),
            self.held_out_error[0],
            self.held_out_error[1],
            100.0 * self.shrink,
            self.chi2_left,
            self.dof,
            self.residual_p_value,
            self.cannot_predict,
            self.cannot_predict_error[0],
            self.cannot_predict_error[1],
        )
    }
}

/// One measured mass and what the model predicts for it when its group is held out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HeldOutPrediction {
    /// Held-out group (test or increment).
    pub group: String,
    /// Test id.
    pub test: String,
    /// Increment, from 1.
    pub increment: usize,
    /// Quantity (`mass cube`).
    pub quantity: String,
    /// Specimens' mean, mg.
    pub measured_mg: f64,
    /// Its standard uncertainty about the nominal prediction, mg.
    pub uncertainty_mg: f64,
    /// Nominal model, mg.
    pub nominal_mg: f64,
    /// The verdict's effect or pair (`a+b`; the best-ranked single when none is named),
    /// fitted on the other groups.
    pub effect: String,
    /// Its (first member's) magnitude fitted without this group.
    pub magnitude: f64,
    /// Every member's magnitude fitted without this group, in the order of the names.
    #[serde(default)]
    pub magnitudes: Vec<f64>,
    /// The prediction with it, mg.
    pub with_effect_mg: f64,
    /// 95 % interval of the prediction: plus or minus 1.96 standard uncertainties of the
    /// observation about it, mg.
    #[serde(default)]
    pub interval_mg: [f64; 2],
}

/// A test the diagnosis proposes to run next.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProposedTest {
    /// The campaign test entry (specimens with empty increments): what the rig runs and the
    /// campaign appends.
    pub test: crate::gap::campaign::CampaignTest,
    /// Case (config and rattle space).
    pub case: String,
    /// What it changes from the campaign, in words.
    pub change: String,
    /// The campaign test it repeats as it was run (its case, drive, increments, specimens and
    /// records), when it is proposed to confirm the leading candidate where held-out data
    /// cannot (`Report::to_repeat`); None for a test chosen by its separation.
    #[serde(default)]
    pub repeats_test: Option<String>,
    /// The campaign test that alone carries the leading candidate (`Report::carried_by`, or a
    /// test of `to_repeat`) when this test, of another case or drive, is proposed to carry it
    /// too: then each of the two is predicted held out from the other.
    #[serde(default)]
    pub second_to: Option<String>,
    /// Axis of the drive tone (`x`, `y`, `z`), when the drive is one sine tone.
    pub drive_axis: Option<String>,
    /// Peak level of the tone, g.
    pub level_g: Option<f64>,
    /// Frequency of the tone, Hz.
    pub frequency_hz: Option<f64>,
    /// Increments per specimen.
    pub increments: usize,
    /// Excited duration of each increment, s.
    pub increment_duration_s: f64,
    /// Specimens.
    pub repeats: usize,
    /// Input and response accelerometer records asked for.
    pub accelerometers: bool,
    /// Test hours: increments x length x repeats.
    pub cost_h: f64,
    /// The leading candidate, then the rivals it is told from.
    pub separates: Vec<String>,
    /// The smallest expected log-likelihood ratio between the leading candidate and a rival,
    /// nats.
    pub separation_nats: f64,
    /// The ratio exceeds ln 20 against every rival.
    pub decisive: bool,
    /// Per rival: the expected log-likelihood ratio.
    pub rivals: Vec<RivalSeparation>,
    /// What each candidate predicts the test reads.
    pub predictions: Vec<CandidateReading>,
    /// What each outcome would decide, in words.
    pub decides: Vec<String>,
}

/// How well a proposed test tells the leading candidate from one rival.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RivalSeparation {
    /// The rival (`none`: the nominal model).
    pub candidate: String,
    /// Expected log-likelihood ratio, nats.
    pub expected_log_lr: f64,
    /// Above ln 20.
    pub decisive: bool,
}

/// A candidate's prediction of a proposed test: the first weighed component's mass per
/// increment with its 95 % interval (the mean of the repeats).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateReading {
    /// Candidate (`none`: the nominal model).
    pub candidate: String,
    /// Quantity (`mass cube`).
    pub quantity: String,
    /// Per increment, mg.
    pub mass_mg: Vec<f64>,
    /// 95 % interval per increment, mg: plus or minus 1.96 standard uncertainties of the
    /// reading (scatter of the repeats' mean, the simulator's numerical and parameter
    /// uncertainty, quantisation).
    pub interval_mg: Vec<[f64; 2]>,
}
