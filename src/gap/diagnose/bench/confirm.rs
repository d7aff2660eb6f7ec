//! The loop closed on the bench (`diagnose-bench --confirm`): a campaign whose answer is
//! `partly_explained` or `not_explained` while its in-library truth is detectable (a pair only
//! where identifiable, `eligible`) gets its top proposed next test run by the rig under the
//! same hidden truth; the test is appended and the campaign diagnosed again on an emulator
//! built for the longer campaign. **Confirmed** is `explained` with the right name (a pair:
//! both members) after that one test; **wrong** is `explained` naming an effect the rig did not
//! inject.

use super::scenarios::rig_options;
use super::{BenchOptions, Outcome, Scenario};
use crate::cases::RunControl;
use crate::gap::campaign::Campaign;
use crate::gap::diagnose::emulator::Emulator;
use crate::gap::diagnose::{diagnose_refining, propose_next_tests, Report, Simulating, Verdict};
use crate::gap::rig::run_cached;
use crate::gap::window::WindowCache;
use crate::gap::GapError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Offset of the proposed test's rig seed from the campaign's: its scatter and noise are drawn
/// apart from the campaign's own.
const SEED_OFFSET: u64 = 1_000_003;

/// What one proposed next test did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NextTestOutcome {
    /// The test run (`next-1: rattle-box-b, ...; 1 x 8.0 h x 3`), or why none was.
    pub test: String,
    /// Its test hours.
    pub cost_h: f64,
    /// Its expected separation, nats.
    pub separation_nats: f64,
    /// The verdict with it appended.
    pub verdict: Verdict,
    /// The effect named then.
    pub chosen: Option<String>,
    /// `explained` with the right name.
    pub confirmed: bool,
    /// Lack-of-fit p-value of the truth itself, simulated in the emulator at its drawn
    /// values, on the campaign with the test appended: below the diagnosis' alpha, no
    /// diagnosis through this emulator could confirm it (None where the truth is not fitted).
    #[serde(default)]
    pub truth_p_after: Option<f64>,
}

/// The confirm mode's scores.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConfirmScores {
    /// Campaigns partly or not explained with a detectable in-library truth (a pair only
    /// when identifiable).
    pub eligible: usize,
    /// Of those, a next test proposed and run.
    pub run: usize,
    /// Of those eligible, confirmed after it.
    pub confirmed: usize,
    /// Explained naming an effect the rig did not inject after it (one member of an injected
    /// pair named alone is incomplete, not wrong).
    pub wrong_after: usize,
    /// Of those eligible, the ones whose truth, simulated in the emulator at its drawn values,
    /// fits the campaign within its noise (`Outcome::truth_fit`): the ones any diagnosis
    /// through this emulator could confirm (a pair's eligibility already asks it).
    #[serde(default)]
    pub truth_fits: usize,
    /// Of those, confirmed after the next test.
    #[serde(default)]
    pub truth_fits_confirmed: usize,
}

impl ConfirmScores {
    /// The table rows.
    pub fn rows(&self) -> String {
        let pct = |n: usize| {
            if self.eligible == 0 {
                "n/a".to_string()
            } else {
                format!("{:.0} %", 100.0 * n as f64 / self.eligible as f64)
            }
        };
        let fits = if self.truth_fits == 0 {
            "n/a".to_string()
        } else {
            format!(
                "{:.0} %",
                100.0 * self.truth_fits_confirmed as f64 / self.truth_fits as f64
            )
        };
        format!(
            "| confirmed (explained, right name) after one proposed next test ({} partly or not explained, detectable, pairs identifiable; {} with a test proposed) | {} | >= 80 % |\n| of them, those whose truth the emulator fits within the noise ({}) | {} | |\n| wrong names after the next test | {} | <= 5 % |\n",
            self.eligible,
            self.run,
            pct(self.confirmed),
            self.truth_fits,
            fits,
            pct(self.wrong_after)
        )
    }
}

/// Whether a campaign's outcome asks for the confirm step: partly or not explained with a
/// detectable in-library truth, a pair only where the data can name both members (the bench
/// scores pairs over identifiable ones; one whose member alone fits better by AICc cannot be
/// confirmed as a pair by one more test of the same kind).
pub(super) fn eligible(o: &Outcome) -> bool {
    o.scenario.in_library
        && o.scenario.truth != "control"
        && o.detectable
        && (!o.scenario.truth.contains('+') || o.pair_identifiable())
        && matches!(o.verdict, Verdict::PartlyExplained | Verdict::NotExplained)
}

/// The confirm mode's scores over `outcomes` (None when no campaign ran it).
pub(super) fn score(outcomes: &[Outcome]) -> Option<ConfirmScores> {
    if !outcomes.iter().any(|o| o.next_test.is_some()) {
        return None;
    }
    let eligible: Vec<&Outcome> = outcomes.iter().filter(|o| eligible(o)).collect();
    let ran: Vec<(&Outcome, &NextTestOutcome)> = eligible
        .iter()
        .filter_map(|o| o.next_test.as_ref().map(|n| (*o, n)))
        .collect();
    Some(ConfirmScores {
        eligible: eligible.len(),
        run: ran.iter().filter(|(_, n)| n.cost_h > 0.0).count(),
        confirmed: ran.iter().filter(|(_, n)| n.confirmed).count(),
        wrong_after: ran
            .iter()
            .filter(|(o, n)| named_wrong_after(&o.scenario.truth, n))
            .count(),
        truth_fits: eligible.iter().filter(|o| o.truth_fits()).count(),
        truth_fits_confirmed: ran
            .iter()
            .filter(|(o, n)| n.confirmed && o.truth_fits())
            .count(),
    })
}

/// `explained` after the next test naming an effect the rig did not inject: the bench's own
/// rule for a wrong name ("wrong names" in its scores). One member of an injected pair named
/// alone is incomplete, not wrong: it is counted neither confirmed nor wrong.
fn named_wrong_after(truth: &str, n: &NextTestOutcome) -> bool {
    n.verdict == Verdict::Explained
        && n.chosen.as_deref().is_some_and(|c| {
            c.split('+')
                .any(|name| !truth.split('+').any(|t| t == name))
        })
}

/// Same effects, in any order: `a+b` and `b+a` name one pair.
fn same_name(a: &str, b: &str) -> bool {
    fn sorted(s: &str) -> Vec<&str> {
        let mut v: Vec<&str> = s.split('+').collect();
        v.sort_unstable();
        v
    }
    sorted(a) == sorted(b)
}

/// The confirm step of one campaign: its top proposed next test run by the rig under the
/// truth of `s`, appended to `noisy`, diagnosed again; with the report after it (None when
/// no test was proposed).
#[allow(clippy::too_many_arguments)]
pub(super) fn confirm(
    skeleton: &Campaign,
    noisy: &Campaign,
    report: &Report,
    s: &Scenario,
    o: &BenchOptions,
    configs_dir: &Path,
    control: &RunControl,
    cache: &WindowCache,
) -> Result<(NextTestOutcome, Option<Report>), GapError> {
    let sim = Simulating {
        campaign: noisy,
        options: &o.diagnose,
        configs_dir,
        control,
        cache,
    };
    let proposed = propose_next_tests(noisy, report, sim)?;
    let Some(top) = proposed.first() else {
        let none = NextTestOutcome {
            test: "none proposed".into(),
            cost_h: 0.0,
            separation_nats: 0.0,
            verdict: report.verdict,
            chosen: report.best_effect.as_ref().map(|b| b.name.clone()),
            confirmed: false,
            truth_p_after: None,
        };
        return Ok((none, None));
    };
    let one = Campaign {
        tests: vec![top.test.clone()],
        ..skeleton.clone()
    };
    let scenario = Scenario {
        accelerometers: top.accelerometers,
        ..s.clone()
    };
    let mut rig = rig_options(&scenario, o, true)?;
    rig.seed = s.seed.wrapping_add(SEED_OFFSET);
    let (ran, _) = run_cached(&one, configs_dir, &rig, control, cache)?;
    let mut extended = noisy.clone();
    extended.tests.extend(ran.tests);
    let mut emulator = Emulator::build(
        &extended,
        configs_dir,
        &o.diagnose.emulator,
        control,
        cache,
        &|_, _| {},
    )?;
    let after = diagnose_refining(
        &extended,
        &mut emulator,
        &o.diagnose,
        configs_dir,
        control,
        cache,
        &|_, _| {},
    )?;
    let chosen = after.best_effect.as_ref().map(|b| b.name.clone());
    let sim = Simulating {
        campaign: &extended,
        options: &o.diagnose,
        configs_dir,
        control,
        cache,
    };
    let truth_p_after = crate::gap::diagnose::truth_fit::truth_fit(sim, &mut emulator, &s.effects)?
        .map(|t| t.p_value);
    let outcome = NextTestOutcome {
        test: format!(
            "{}: {}; {} x {:.1} h x {}",
            top.test.id,
            top.change,
            top.increments,
            top.increment_duration_s / crate::units::S_PER_H,
            top.repeats
        ),
        cost_h: top.cost_h,
        separation_nats: top.separation_nats,
        verdict: after.verdict,
        confirmed: after.verdict == Verdict::Explained
            && chosen.as_deref().is_some_and(|c| same_name(c, &s.truth)),
        chosen,
        truth_p_after,
    };
    Ok((outcome, Some(after)))
}

#[cfg(test)]
mod tests {
    use super::super::test_outcome::outcome;
    use super::{eligible, named_wrong_after, same_name, score, NextTestOutcome, Outcome, Verdict};
    use crate::gap::diagnose::truth_fit::TruthFit;

    /// The confirm step asks for a partly or not explained campaign with a detectable truth,
    /// a pair only when the data can name both members (the rule the pair scores use).
    #[test]
    fn the_confirm_step_takes_pairs_only_where_identifiable() {
        let pair = |truth_aicc: f64, member_aicc: f64| Outcome {
            truth_fit: Some(TruthFit {
                chi2: 0.0,
                dof: 84.0,
                parameters: 4,
                p_value: 0.5,
                nll: 0.0,
                aicc: truth_aicc,
                fits: true,
                by_group: Vec::new(),
                worst: Vec::new(),
            }),
            best_member_aicc: Some(member_aicc),
            ..outcome(
                "fixture_compliance+cross_axis",
                true,
                Verdict::PartlyExplained,
                Some("cross_axis"),
            )
        };
        assert!(eligible(&pair(-40.0, -31.0)));
        // The member alone fits better: no test of the same kind names both.
        assert!(!eligible(&pair(-31.2, -38.2)));
        let single = |verdict| outcome("cross_axis", true, verdict, Some("cross_axis"));
        assert!(eligible(&single(Verdict::PartlyExplained)));
        assert!(eligible(&single(Verdict::NotExplained)));
        assert!(!eligible(&single(Verdict::Explained)));
        assert!(!eligible(&outcome(
            "surface_oxide",
            false,
            Verdict::NotExplained,
            None
        )));
    }

    #[test]
    fn a_wrong_name_is_one_the_rig_did_not_inject() {
        let after = |verdict: Verdict, chosen: Option<&str>| NextTestOutcome {
            test: "next-1".into(),
            cost_h: 8.0,
            separation_nats: 5.0,
            verdict,
            chosen: chosen.map(str::to_string),
            confirmed: false,
            truth_p_after: None,
        };
        let truth = "fixture_compliance+cross_axis";
        // One member of the injected pair: incomplete, not wrong.
        assert!(!named_wrong_after(
            truth,
            &after(Verdict::Explained, Some("cross_axis"))
        ));
        // An effect the rig did not inject.
        assert!(named_wrong_after(
            truth,
            &after(Verdict::Explained, Some("third_body"))
        ));
        assert!(named_wrong_after(
            truth,
            &after(Verdict::Explained, Some("cross_axis+severe_wear"))
        ));
        // Only `explained` names anything.
        assert!(!named_wrong_after(
            truth,
            &after(Verdict::PartlyExplained, Some("third_body"))
        ));
        assert!(!named_wrong_after(
            "cross_axis",
            &after(Verdict::NotExplained, None)
        ));
    }

    /// The confirm score counts apart the campaigns whose truth the emulator itself fits: a
    /// truth it cannot reproduce no next test can confirm.
    #[test]
    fn the_confirm_score_counts_apart_the_truths_the_emulator_fits() {
        let fit = |fits: bool| TruthFit {
            chi2: 0.0,
            dof: 84.0,
            parameters: 1,
            p_value: if fits { 0.5 } else { 3e-22 },
            nll: 0.0,
            aicc: 0.0,
            fits,
            by_group: Vec::new(),
            worst: Vec::new(),
        };
        let ran = |fits: bool, confirmed: bool| Outcome {
            truth_fit: Some(fit(fits)),
            next_test: Some(NextTestOutcome {
                test: "next-1".into(),
                cost_h: 8.0,
                separation_nats: 5.0,
                verdict: if confirmed {
                    Verdict::Explained
                } else {
                    Verdict::NotExplained
                },
                chosen: confirmed.then(|| "friction_drift".to_string()),
                confirmed,
                truth_p_after: None,
            }),
            ..outcome(
                "friction_drift",
                true,
                Verdict::PartlyExplained,
                Some("friction_drift"),
            )
        };
        let scores = score(&[ran(true, true), ran(true, false), ran(false, false)]).unwrap();
        assert_eq!((scores.eligible, scores.run, scores.confirmed), (3, 3, 1));
        assert_eq!((scores.truth_fits, scores.truth_fits_confirmed), (2, 1));
        assert!(scores.rows().contains("(2) | 50 %"), "{}", scores.rows());
    }

    #[test]
    fn a_pair_is_one_name_in_either_order() {
        assert!(same_name(
            "cross_axis+severe_wear",
            "severe_wear+cross_axis"
        ));
        assert!(same_name("third_body", "third_body"));
        assert!(!same_name("cross_axis+severe_wear", "cross_axis"));
        assert!(!same_name("third_body", "impact_wear"));
    }
}
