//! The bench's scores against the truth (module `bench`): top-1, both-named pairs, wrong
//! names, controls, rig-only effects, interval coverage.

use super::coverage::{coverage_by_parameter, interval_hits};
use super::Outcome;
use crate::gap::diagnose::{stats, Verdict};
use crate::gap::effects::LIBRARY;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The bench's scores.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// Campaigns diagnosed.
    pub campaigns: usize,
    /// Detectable in-library campaigns.
    pub detectable_in_library: usize,
    /// Of those, the share whose best effect is the true one.
    pub top1: f64,
    /// Detectable in-library single effects detectable in two or more tests on their own
    /// (held-out tests can confirm them).
    #[serde(default)]
    pub confirmable_in_library: usize,
    /// Of those, the share whose best effect is the true one.
    #[serde(default)]
    pub top1_confirmable: f64,
    /// Detectable in-library single effects detectable in fewer than two tests on their own.
    #[serde(default)]
    pub one_test_singles: usize,
    /// Of those, the share whose leading candidate (`explained` or `partly_explained`) is the
    /// true effect.
    #[serde(default)]
    pub one_test_led_right: f64,
    /// Detectable pairs.
    #[serde(default)]
    pub detectable_pairs: usize,
    /// Detectable pairs detectable in two or more tests on their own (each member given the
    /// other).
    #[serde(default)]
    pub confirmable_pairs: usize,
    /// Of those, the share `explained` by exactly their two effects.
    #[serde(default)]
    pub confirmable_pairs_both_named: f64,
    /// Of those, the share `explained` by exactly their two effects.
    #[serde(default)]
    pub pairs_both_named: f64,
    /// Pairs detectable with each member given the other at its drawn magnitude (the older
    /// measure: it counts a member that the other, at another magnitude, stands in for).
    #[serde(default)]
    pub pairs_detectable_at_drawn: usize,
    /// Of those, the share `explained` by exactly their two effects.
    #[serde(default)]
    pub pairs_at_drawn_both_named: f64,
    /// Detectable pairs whose truth, simulated in the emulator at its drawn values, passes
    /// the lack-of-fit test (`Outcome::truth_fit`): the pairs a search could name.
    #[serde(default)]
    pub pairs_truth_fits: usize,
    /// Detectable pairs the campaign identifies: the truth fits and its AICc beats each
    /// member alone as the diagnosis fitted it (`Outcome::best_member_aicc`).
    #[serde(default)]
    pub identifiable_pairs: usize,
    /// Of those, the share `explained` by exactly their two effects.
    #[serde(default)]
    pub identifiable_pairs_both_named: f64,
    /// Detectable single effects whose truth passes the lack-of-fit test.
    #[serde(default)]
    pub singles_truth_fits: usize,
    /// Campaigns `explained` by an effect that is not (part of) the truth.
    #[serde(default)]
    pub wrong_names: usize,
    /// Their share of every campaign.
    #[serde(default)]
    pub wrong_name_rate: f64,
    /// Campaigns reported `partly_explained`.
    #[serde(default)]
    pub partly_explained: usize,
    /// Controls.
    pub controls: usize,
    /// Share of controls reported no_gap.
    pub controls_clean: f64,
    /// Detectable rig-only campaigns.
    pub detectable_rig_only: usize,
    /// Share of those reported not_explained.
    pub rig_only_flagged: f64,
    /// Median held-out shrink where the right effect was found.
    pub median_shrink: f64,
    /// Fitted parameters with a 95 % interval, of the campaigns named right: the magnitudes
    /// and secondary values the diagnosis fitted (measured ones included).
    #[serde(default)]
    pub intervals_checked: usize,
    /// Of those, the share whose interval holds the drawn value (`interval_hits`).
    #[serde(default)]
    pub interval_coverage: f64,
    /// The magnitudes alone: checked and the share held.
    #[serde(default)]
    pub magnitude_intervals_checked: usize,
    /// Of those, the share whose interval holds the drawn magnitude.
    #[serde(default)]
    pub magnitude_interval_coverage: f64,
    /// 95 % interval coverage per parameter (`effect.parameter`, and the rows `magnitudes` and
    /// `secondary parameters`) over the campaigns whose leading candidate (`explained` or
    /// `partly_explained`) is exactly the truth: [intervals checked, holding the drawn value,
    /// reported identified].
    #[serde(default)]
    pub coverage_by_parameter: BTreeMap<String, [usize; 3]>,
    /// Undetectable in-library campaigns reported no_gap (share).
    pub undetectable_no_gap: f64,
    /// Detectable single effects drawn without accelerometer records.
    #[serde(default)]
    pub detectable_weighed_only: usize,
    /// Of those, the share whose best effect is the true one.
    #[serde(default)]
    pub top1_weighed_only: f64,
    /// The confirm mode's scores (`diagnose-bench --confirm`; None otherwise).
    #[serde(default)]
    pub next_test: Option<super::confirm::ConfirmScores>,
    /// Truth -> answer -> count.
    pub confusion: BTreeMap<String, BTreeMap<String, usize>>,
    /// Every outcome.
    pub outcomes: Vec<Outcome>,
}

fn answer(o: &Outcome) -> String {
    match o.verdict {
        Verdict::NoGap => "no_gap".into(),
        Verdict::NotExplained => "not_explained".into(),
        Verdict::Explained => o.chosen.clone().unwrap_or_else(|| "?".into()),
        Verdict::PartlyExplained => {
            format!("partly: {}", o.chosen.clone().unwrap_or_else(|| "?".into()))
        }
    }
}

fn share(k: usize, n: usize) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        k as f64 / n as f64
    }
}

/// The effect names of a truth or an answer (`a+b` split; none for a control).
fn names(text: &str) -> Vec<&str> {
    if text == "control" {
        Vec::new()
    } else {
        text.split('+').collect()
    }
}

/// Explained by exactly the truth's effects.
fn named_right(o: &Outcome) -> bool {
    let (mut truth, mut chosen) = (
        names(&o.scenario.truth),
        names(o.chosen.as_deref().unwrap_or("")),
    );
    truth.sort_unstable();
    chosen.sort_unstable();
    o.verdict == Verdict::Explained && o.scenario.in_library && truth == chosen
}

/// Two or more tests carry the effect, so held-out tests can confirm it.
fn confirmable(o: &Outcome) -> bool {
    o.detectable && o.detectable_tests >= 2
}

/// The leading candidate (`explained` or `partly_explained`) is exactly the truth.
fn led_right(o: &Outcome) -> bool {
    let led = o.verdict == Verdict::Explained || o.verdict == Verdict::PartlyExplained;
    led && o.chosen.as_deref() == Some(o.scenario.truth.as_str())
}

/// A confident name that is not the truth: explained by an effect the rig did not inject.
fn named_wrong(o: &Outcome) -> bool {
    if o.verdict != Verdict::Explained {
        return false;
    }
    let truth = if o.scenario.in_library {
        names(&o.scenario.truth)
    } else {
        Vec::new()
    };
    names(o.chosen.as_deref().unwrap_or("?"))
        .iter()
        .any(|n| !truth.contains(n))
}

/// Scores outcomes.
pub fn score(outcomes: Vec<Outcome>) -> Scores {
    let lib: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.scenario.in_library && o.scenario.truth != "control")
        .collect();
    let singles: Vec<&&Outcome> = lib
        .iter()
        .filter(|o| !o.scenario.truth.contains('+'))
        .collect();
    let det_lib: Vec<&&&Outcome> = singles.iter().filter(|o| o.detectable).collect();
    let right: Vec<&&&&Outcome> = det_lib.iter().filter(|o| named_right(o)).collect();
    let weighed_only: Vec<&&&&Outcome> = det_lib
        .iter()
        .filter(|o| !o.scenario.accelerometers)
        .collect();
    let weighed_only_right = weighed_only.iter().filter(|o| named_right(o)).count();
    let det_pairs: Vec<&&Outcome> = lib
        .iter()
        .filter(|o| o.scenario.truth.contains('+') && o.detectable)
        .collect();
    let pairs_right = det_pairs.iter().filter(|o| named_right(o)).count();
    let drawn_pairs: Vec<&&Outcome> = lib
        .iter()
        .filter(|o| o.scenario.truth.contains('+') && o.detectable_at_drawn)
        .collect();
    let conf_pairs: Vec<&&&Outcome> = det_pairs.iter().filter(|o| confirmable(o)).collect();
    let identifiable: Vec<&&&Outcome> =
        det_pairs.iter().filter(|o| o.pair_identifiable()).collect();
    let conf: Vec<&&&&Outcome> = det_lib.iter().filter(|o| confirmable(o)).collect();
    let one_test: Vec<&&&&Outcome> = det_lib.iter().filter(|o| !confirmable(o)).collect();
    let undet: Vec<&&&Outcome> = singles.iter().filter(|o| !o.detectable).collect();
    let controls: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.scenario.truth == "control")
        .collect();
    let rig_only: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| !o.scenario.in_library && o.detectable)
        .collect();
    let wrong = outcomes.iter().filter(|o| named_wrong(o)).count();
    let mut confusion: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
    for o in &outcomes {
        let row = if o.scenario.truth == "control" || confirmable(o) {
            o.scenario.truth.clone()
        } else if o.detectable {
            format!("{} (one test)", o.scenario.truth)
        } else {
            format!("{} (undetectable)", o.scenario.truth)
        };
        *confusion
            .entry(row)
            .or_default()
            .entry(answer(o))
            .or_insert(0) += 1;
    }
    let shrinks: Vec<f64> = right
        .iter()
        .map(|o| ****o)
        .chain(det_pairs.iter().map(|o| **o).filter(|o| named_right(o)))
        .filter_map(|o| o.shrink)
        .collect();
    let hits: Vec<(bool, bool)> = outcomes
        .iter()
        .filter(|o| named_right(o))
        .flat_map(interval_hits)
        .collect();
    let magnitude_hits: Vec<bool> = hits.iter().filter(|h| h.0).map(|h| h.1).collect();
    Scores {
        campaigns: outcomes.len(),
        detectable_in_library: det_lib.len(),
        top1: share(right.len(), det_lib.len()),
        confirmable_in_library: conf.len(),
        top1_confirmable: share(conf.iter().filter(|o| named_right(o)).count(), conf.len()),
        one_test_singles: one_test.len(),
        one_test_led_right: share(
            one_test.iter().filter(|o| led_right(o)).count(),
            one_test.len(),
        ),
        detectable_pairs: det_pairs.len(),
        confirmable_pairs: conf_pairs.len(),
        confirmable_pairs_both_named: share(
            conf_pairs.iter().filter(|o| named_right(o)).count(),
            conf_pairs.len(),
        ),
        pairs_both_named: share(pairs_right, det_pairs.len()),
        pairs_detectable_at_drawn: drawn_pairs.len(),
        pairs_at_drawn_both_named: share(
            drawn_pairs.iter().filter(|o| named_right(o)).count(),
            drawn_pairs.len(),
        ),
        pairs_truth_fits: det_pairs.iter().filter(|o| o.truth_fits()).count(),
        identifiable_pairs: identifiable.len(),
        identifiable_pairs_both_named: share(
            identifiable.iter().filter(|o| named_right(o)).count(),
            identifiable.len(),
        ),
        singles_truth_fits: det_lib.iter().filter(|o| o.truth_fits()).count(),
        wrong_names: wrong,
        wrong_name_rate: share(wrong, outcomes.len()),
        partly_explained: outcomes
            .iter()
            .filter(|o| o.verdict == Verdict::PartlyExplained)
            .count(),
        controls: controls.len(),
        controls_clean: share(
            controls
                .iter()
                .filter(|o| o.verdict == Verdict::NoGap)
                .count(),
            controls.len(),
        ),
        detectable_rig_only: rig_only.len(),
        rig_only_flagged: share(
            rig_only
                .iter()
                .filter(|o| o.verdict == Verdict::NotExplained)
                .count(),
            rig_only.len(),
        ),
        median_shrink: if shrinks.is_empty() {
            f64::NAN
        } else {
            stats::median(&shrinks)
        },
        intervals_checked: hits.len(),
        interval_coverage: share(hits.iter().filter(|h| h.1).count(), hits.len()),
        magnitude_intervals_checked: magnitude_hits.len(),
        magnitude_interval_coverage: share(
            magnitude_hits.iter().filter(|h| **h).count(),
            magnitude_hits.len(),
        ),
        coverage_by_parameter: coverage_by_parameter(outcomes.iter().filter(|o| led_right(o))),
        undetectable_no_gap: share(
            undet.iter().filter(|o| o.verdict == Verdict::NoGap).count(),
            undet.len(),
        ),
        detectable_weighed_only: weighed_only.len(),
        top1_weighed_only: share(weighed_only_right, weighed_only.len()),
        next_test: super::confirm::score(&outcomes),
        confusion,
        outcomes,
    }
}

impl Scores {
    /// The printed tables.
    pub fn table(&self) -> String {
        let pct = |x: f64| {
            if x.is_nan() {
                "n/a".to_string()
            } else {
                format!("{:.0} %", 100.0 * x)
            }
        };
        let mut s = String::new();
        s.push_str("| score | value | target |\n|---|---|---|\n");
        s.push_str(&format!("| campaigns | {} | >= 60 |\n", self.campaigns));
        s.push_str(&format!(
            "| top-1 on detectable single effects ({}) | {} | >= 85 % |\n",
            self.detectable_in_library,
            pct(self.top1)
        ));
        s.push_str(&format!(
            "| of them detectable in two or more tests on their own, which held-out tests can confirm ({}) | {} | >= 85 % |\n",
            self.confirmable_in_library,
            pct(self.top1_confirmable)
        ));
        s.push_str(&format!(
            "| of them detectable in fewer than two tests on their own: leading candidate right ({}) | {} | |\n",
            self.one_test_singles,
            pct(self.one_test_led_right)
        ));
        s.push_str(&format!(
            "| of them weighed only, without accelerometer records ({}) | {} | |\n",
            self.detectable_weighed_only,
            pct(self.top1_weighed_only)
        ));
        s.push_str(&format!(
            "| detectable pairs explained by both members ({}) | {} | >= 60 % |\n",
            self.detectable_pairs,
            pct(self.pairs_both_named)
        ));
        s.push_str(&format!(
            "| of them detectable in two or more tests on their own ({}) | {} | >= 60 % |\n",
            self.confirmable_pairs,
            pct(self.confirmable_pairs_both_named)
        ));
        s.push_str(&format!(
            "| detectable singles / pairs whose truth, simulated in the emulator, passes the lack-of-fit test | {} of {} / {} of {} | |\n",
            self.singles_truth_fits,
            self.detectable_in_library,
            self.pairs_truth_fits,
            self.detectable_pairs
        ));
        s.push_str(&format!(
            "| of them identifiable: the truth fits and beats each member alone by AICc ({}) | {} | |\n",
            self.identifiable_pairs,
            pct(self.identifiable_pairs_both_named)
        ));
        s.push_str(&format!(
            "| pairs detectable at the drawn magnitudes, explained by both members ({}) | {} | |\n",
            self.pairs_detectable_at_drawn,
            pct(self.pairs_at_drawn_both_named)
        ));
        s.push_str(&format!(
            "| wrong names: explained by an effect not injected ({} of {}) | {} | <= 5 % |\n",
            self.wrong_names,
            self.campaigns,
            pct(self.wrong_name_rate)
        ));
        s.push_str(&format!(
            "| partly_explained (not counted as named) | {} | |\n",
            self.partly_explained
        ));
        s.push_str(&format!(
            "| controls reported no_gap ({}) | {} | >= 90 % |\n",
            self.controls,
            pct(self.controls_clean)
        ));
        s.push_str(&format!(
            "| detectable rig-only effects reported not_explained ({}) | {} | >= 70 % |\n",
            self.detectable_rig_only,
            pct(self.rig_only_flagged)
        ));
        s.push_str(&format!(
            "| median held-out shrink where the right effect (or pair) was found | {} | >= 50 % |\n",
            pct(self.median_shrink)
        ));
        s.push_str(&format!(
            "| 95 % intervals of the fitted parameters holding the drawn value, where named right ({}; magnitudes {}) | {} (magnitudes {}) | 95 % |\n",
            self.intervals_checked,
            self.magnitude_intervals_checked,
            pct(self.interval_coverage),
            pct(self.magnitude_interval_coverage)
        ));
        s.push_str(&format!(
            "| undetectable in-library effects reported no_gap | {} | (right answer) |\n\n",
            pct(self.undetectable_no_gap)
        ));
        if !self.coverage_by_parameter.is_empty() {
            s.push_str("95 % interval coverage per parameter, where the leading candidate is the truth (explained or partly_explained):\n\n| parameter | intervals | holding the drawn value | reported identified |\n|---|---|---|---|\n");
            for (name, [n, held, identified]) in &self.coverage_by_parameter {
                s.push_str(&format!(
                    "| {name} | {n} | {} | {} |\n",
                    pct(share(*held, *n)),
                    pct(share(*identified, *n))
                ));
            }
            s.push('\n');
        }
        if let Some(c) = &self.next_test {
            s.push_str("Confirm by next test:\n\n| score | value | target |\n|---|---|---|\n");
            s.push_str(&c.rows());
            s.push('\n');
        }
        let mut cols: Vec<String> = vec!["no_gap".into()];
        cols.extend(LIBRARY.iter().map(|e| e.name.to_string()));
        for row in self.confusion.values() {
            for k in row.keys() {
                if !cols.contains(k) && k != "not_explained" {
                    cols.push(k.clone());
                }
            }
        }
        cols.push("not_explained".into());
        s.push_str("Confusion (rows: truth; columns: answer)\n\n| truth |");
        for c in &cols {
            s.push_str(&format!(" {c} |"));
        }
        s.push_str("\n|---|");
        for _ in &cols {
            s.push_str("---|");
        }
        s.push('\n');
        for (truth, row) in &self.confusion {
            s.push_str(&format!("| {truth} |"));
            for c in &cols {
                s.push_str(&format!(" {} |", row.get(c).copied().unwrap_or(0)));
            }
            s.push('\n');
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::super::coverage::holds;
    use super::super::test_outcome::outcome;
    use super::super::FittedValue;
    use super::*;
    use crate::gap::diagnose::truth_fit::TruthFit;
    use crate::gap::effects::Effect;

    /// A pair is both named whatever the order of its names; naming one member is neither
    /// both named nor wrong; naming an effect the rig did not inject is wrong, and so is any
    /// name for a control or a rig-only effect; `partly_explained` is never a confident name.
    #[test]
    fn pairs_and_wrong_names_are_scored_by_the_truth() {
        let s = score(vec![
            outcome(
                "third_body+cross_axis",
                true,
                Verdict::Explained,
                Some("cross_axis+third_body"),
            ),
            outcome(
                "third_body+cross_axis",
                true,
                Verdict::Explained,
                Some("cross_axis"),
            ),
            outcome(
                "cross_axis",
                true,
                Verdict::Explained,
                Some("fixture_compliance"),
            ),
            outcome("cross_axis", true, Verdict::Explained, Some("cross_axis")),
            outcome(
                "work_hardening",
                false,
                Verdict::Explained,
                Some("friction_drift"),
            ),
            outcome(
                "control",
                true,
                Verdict::PartlyExplained,
                Some("sharp_edges"),
            ),
        ]);
        assert_eq!(s.detectable_pairs, 2);
        assert_eq!(s.pairs_both_named, 0.5);
        assert_eq!(s.detectable_in_library, 2);
        assert_eq!(s.top1, 0.5);
        assert_eq!(s.wrong_names, 2);
        assert_eq!(s.partly_explained, 1);
        assert_eq!(s.controls_clean, 0.0);
    }

    /// A pair counts as identifiable only when its truth fits and beats each member alone by
    /// AICc: a truth that does not fit, or that a member alone beats, no search can name.
    #[test]
    fn a_pair_is_identifiable_when_its_truth_fits_and_beats_each_member_alone() {
        let with = |fits: bool, truth_aicc: f64, member_aicc: f64, chosen: &str| Outcome {
            truth_fit: Some(TruthFit {
                chi2: 0.0,
                dof: 84.0,
                parameters: 4,
                p_value: if fits { 0.5 } else { 1e-30 },
                nll: 0.0,
                aicc: truth_aicc,
                fits,
                by_group: Vec::new(),
                worst: Vec::new(),
            }),
            best_member_aicc: Some(member_aicc),
            ..outcome(
                "friction_drift+cross_axis",
                true,
                Verdict::Explained,
                Some(chosen),
            )
        };
        let s = score(vec![
            with(true, 500.0, 640.0, "friction_drift+cross_axis"),
            with(true, 500.0, 640.0, "cross_axis"),
            with(false, 500.0, 640.0, "cross_axis"),
            with(true, 650.0, 640.0, "cross_axis"),
        ]);
        assert_eq!(s.detectable_pairs, 4);
        assert_eq!(s.pairs_truth_fits, 3);
        assert_eq!(s.identifiable_pairs, 2);
        assert_eq!(s.identifiable_pairs_both_named, 0.5);
    }

    /// Interval coverage counts the fitted parameters of the campaigns named right, against
    /// the values the rig drew: a magnitude and a slip scale whose intervals hold the drawn
    /// ones, a magnitude whose interval misses it; parameters held at their default and
    /// campaigns not named right are not counted.
    #[test]
    fn intervals_are_scored_against_the_drawn_values() {
        let drift = |delta: f64, slip: f64| Effect {
            name: "friction_drift".into(),
            parameters: BTreeMap::from([
                ("delta_mu".to_string(), delta),
                ("slip_scale_m".to_string(), slip),
            ]),
        };
        let fitted = |name: &str, lo: f64, hi: f64, fitted: bool| FittedValue {
            name: format!("friction_drift.{name}"),
            value: 0.5 * (lo + hi),
            interval: Some([lo, hi]),
            fitted,
            identified: true,
        };
        let named = |delta: f64, verdict| {
            let mut o = outcome("friction_drift", true, verdict, Some("friction_drift"));
            o.scenario.effects = vec![drift(delta, 7143.0)];
            o.fitted = vec![
                fitted("delta_mu", 0.4838, 0.4886, true),
                fitted("slip_scale_m", 3162.0, 7499.0, true),
            ];
            o
        };
        let mut held = named(0.485, Verdict::Explained);
        held.fitted.push(fitted("slip_scale_m", 0.0, 1.0, false));
        let s = score(vec![
            held,
            named(0.48, Verdict::Explained),
            named(0.48, Verdict::NotExplained),
        ]);
        assert_eq!(s.intervals_checked, 4);
        assert_eq!(s.interval_coverage, 0.75);
        assert_eq!(s.magnitude_intervals_checked, 2);
        assert_eq!(s.magnitude_interval_coverage, 0.5);
        // Per parameter, over the campaigns led right (the not_explained one is left out):
        // [checked, held, identified].
        let row = |n: &str| s.coverage_by_parameter[n];
        assert_eq!(row("friction_drift.delta_mu"), [2, 1, 2]);
        assert_eq!(row("friction_drift.slip_scale_m"), [2, 2, 2]);
        assert_eq!(row("magnitudes"), [2, 1, 2]);
        assert_eq!(row("secondary parameters"), [2, 2, 2]);
        // An endpoint one rounding step from the drawn value holds it; a real miss does not.
        let step = 0.01875 + (0.0225 - 0.01875) * 3.0 / 5.0;
        assert!(step < 0.021);
        assert!(holds([0.020574, step], 0.021));
        assert!(holds([0.021 + (0.021 - step), 0.0216], 0.021));
        assert!(!holds([0.02061, 0.020724], 0.021));
        assert!(!holds([0.0201, 0.0209999], 0.021));
    }

    /// A single effect one test alone carries counts apart: in the top-1 over every detectable
    /// single, not in the top-1 over those two or more tests carry, and its leading candidate
    /// is scored whether the verdict is `explained` or `partly_explained`.
    #[test]
    fn an_effect_one_test_carries_is_scored_apart() {
        let one_test = |verdict, chosen| Outcome {
            detectable_tests: 1,
            ..outcome("friction_drift", true, verdict, chosen)
        };
        let s = score(vec![
            outcome("cross_axis", true, Verdict::Explained, Some("cross_axis")),
            one_test(Verdict::PartlyExplained, Some("friction_drift")),
            one_test(Verdict::PartlyExplained, Some("fixture_compliance")),
        ]);
        assert_eq!(s.detectable_in_library, 3);
        assert_eq!(s.top1, 1.0 / 3.0);
        assert_eq!(s.confirmable_in_library, 1);
        assert_eq!(s.top1_confirmable, 1.0);
        assert_eq!(s.one_test_singles, 2);
        assert_eq!(s.one_test_led_right, 0.5);
    }
}
