//! SVG plots of a diagnosis report: residuals by group with the flag threshold, the effect
//! ranking, the held-out error before and after the chosen effect per held-out group, and the
//! energy budget. Horizontal labelled bars drawn by [`crate::report::figure::BarChart`]
//! (plotters); the report's numbers are in its JSON.

use super::report::{Report, Verdict};
use crate::report::figure::{AxisSpec, Bar, BarChart};

/// A bar chart with an axis of `scale` (its label `axis`).
fn bar_chart(
    title: &str,
    axis: AxisSpec,
    bars: Vec<Bar>,
    guides: &[f64],
    legend: Option<(&str, &str)>,
) -> String {
    BarChart {
        title: title.to_string(),
        axis,
        bars,
        guides: guides.to_vec(),
        legend: legend.map(|(a, b)| (a.to_string(), b.to_string())),
    }
    .to_svg()
}

/// The verdict in words, as a reader says it.
fn verdict_words(verdict: Verdict) -> &'static str {
    match verdict {
        Verdict::NoGap => "no gap",
        Verdict::Explained => "explained",
        Verdict::PartlyExplained => "partly explained",
        Verdict::NotExplained => "not explained",
    }
}

/// The title's note on the parameters the data do not identify (none: empty).
fn not_identified(b: &super::report::BestEffect) -> String {
    let names: Vec<String> = b
        .parameters
        .iter()
        .filter(|p| p.fitted && !p.identified)
        .map(|p| p.label())
        .collect();
    if names.is_empty() {
        String::new()
    } else {
        format!("; not identified by the data: {}", names.join(", "))
    }
}

/// The report's plots: (file name, SVG text).
pub fn plots(report: &Report) -> Vec<(String, String)> {
    let residual_bars: Vec<Bar> = report
        .location
        .groups
        .iter()
        .map(|g| Bar {
            label: format!("{}: {}", g.by, g.label),
            value: g.z,
            second: None,
            // A bias score is standardized: its standard uncertainty is 1.
            whisker: g.z.is_finite().then_some([g.z - 1.0, g.z + 1.0]),
            note: format!("adjusted p {:.2}", g.p_adjusted),
            highlight: g.flagged,
        })
        .collect();
    let residuals = bar_chart(
        &format!(
            "{}: where the nominal model misses (red: flagged, Holm 5 %)",
            report.campaign
        ),
        AxisSpec::auto(
            "bias score z (measured above the model: > 0; whiskers: +-1, its standard uncertainty); dashed: |z| = 2",
        ),
        residual_bars,
        &[-2.0, 2.0],
        None,
    );
    let rank_bars: Vec<Bar> = report
        .ranking
        .iter()
        .chain(&report.pairs)
        .map(|r| Bar {
            label: r.name.clone(),
            value: r.held_out_gain,
            second: None,
            whisker: Some(r.held_out_gain_interval),
            note: format!(
                "P(first) {:.2}, lack-of-fit p {:.2}",
                r.p_first, r.residual_p_value
            ),
            highlight: r.explains,
        })
        .collect();
    let ranking = bar_chart(
        &format!(
            "{}: effects ranked by held-out log-likelihood gain (red: explains)",
            report.campaign
        ),
        AxisSpec::auto(
            "held-out log-likelihood gain over the nominal model (whiskers: 90 % bootstrap interval); dashed: the explaining threshold",
        ),
        rank_bars,
        &[super::MIN_HELD_OUT_GAIN],
        None,
    );
    let before_after = match &report.best_effect {
        Some(b) => bar_chart(
            &format!(
                "{}: held-out RMS standardized error, nominal vs {} (shrink {:.0} %; red: a group it does not predict within its bound){}",
                report.campaign,
                b.name,
                100.0 * b.shrink,
                not_identified(b)
            ),
            AxisSpec::auto("held-out RMS standardized error per held-out group"),
            b.per_group
                .iter()
                .map(|g| Bar {
                    label: g.group.clone(),
                    value: g.before,
                    second: Some(g.after),
                    whisker: None,
                    note: format!(
                        "{:.2} -> {:.2} (bound {:.2}{})",
                        g.before,
                        g.after,
                        g.bound,
                        if g.predicted { "" } else { ", not predicted" }
                    ),
                    highlight: !g.predicted,
                })
                .collect(),
            &[1.0],
            Some(("nominal", b.name.as_str())),
        ),
        None => bar_chart(
            &format!(
                "{}: no effect chosen (verdict: {})",
                report.campaign,
                verdict_words(report.verdict)
            ),
            AxisSpec::auto("held-out RMS standardized error of the nominal model"),
            vec![Bar {
                label: "nominal".into(),
                value: report.nominal.held_out_error,
                second: None,
                whisker: None,
                note: format!("{:.2}", report.nominal.held_out_error),
                highlight: false,
            }],
            &[1.0],
            None,
        ),
    };
    let mut out = vec![
        ("residuals.svg".into(), residuals),
        ("ranking.svg".into(), ranking),
        ("before_after.svg".into(), before_after),
    ];
    out.extend(energy_budget_plot(report).map(|svg| ("energy_budget.svg".to_string(), svg)));
    out
}

/// The energy budget: per test, component and mechanism, how many decades the coefficient
/// needed for the measured wear lies above the top of its literature range (red: within the
/// range). None without a budget.
fn energy_budget_plot(report: &Report) -> Option<String> {
    let budget = &report.location.energy_budget;
    let bars: Vec<Bar> = budget
        .tests
        .iter()
        .flat_map(|t| {
            t.needed.iter().filter_map(move |n| {
                let v = n.value?;
                Some(Bar {
                    label: format!("{} {}: {}", t.test, n.component, n.mechanism),
                    value: (v / n.range[1]).log10(),
                    second: None,
                    whisker: None,
                    note: format!("{v:.2e} {}", n.unit),
                    highlight: n.verdict == "within",
                })
            })
        })
        .collect();
    if bars.is_empty() {
        return None;
    }
    let low = budget
        .tests
        .iter()
        .flat_map(|t| &t.needed)
        .map(|n| (n.range[0] / n.range[1]).log10())
        .fold(0.0f64, f64::min);
    // The values are decades already: a linear axis of them is the log axis of the coefficient.
    Some(bar_chart(
        &format!(
            "{}: coefficient each wear mechanism needs for the measured wear (red: within its literature range)",
            report.campaign
        ),
        AxisSpec::linear(
            "decades above the top of the mechanism's literature range (dashed: the top, and the widest range's bottom)",
        ),
        bars,
        &[low],
        None,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verdicts_read_as_words() {
        for verdict in [
            Verdict::NoGap,
            Verdict::Explained,
            Verdict::PartlyExplained,
            Verdict::NotExplained,
        ] {
            let words = verdict_words(verdict);
            assert!(
                words.chars().all(|c| c.is_ascii_lowercase() || c == ' '),
                "{words}"
            );
        }
        assert_eq!(verdict_words(Verdict::NotExplained), "not explained");
    }
}
