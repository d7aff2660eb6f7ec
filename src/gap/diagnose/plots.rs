//! SVG plots of a diagnosis report: residuals by group with the flag threshold, the effect
//! ranking, and the held-out error before and after the chosen effect per held-out group.
//! Horizontal labelled bars, drawn without dependencies (the report's numbers are in its JSON).

use super::Report;
use crate::report::svg::escape;
use std::fmt::Write;

/// One bar.
struct Bar {
    label: String,
    value: f64,
    /// Second value drawn as a thinner bar below (before/after plots).
    second: Option<f64>,
    /// Interval drawn as a whisker across the bar (uncertainty of the value).
    whisker: Option<[f64; 2]>,
    note: String,
    highlight: bool,
}

/// Estimated width of one label character, px (0.55 em of the 12 px sans-serif labels).
const LABEL_CHAR_PX: f64 = 6.6;

fn bar_chart(
    title: &str,
    axis: &str,
    bars: &[Bar],
    guides: &[f64],
    legend: Option<(&str, &str)>,
) -> String {
    let row = 22.0;
    // Labels are right-aligned against the bars: the margin holds the longest one at about
    // 0.55 em a character (12 px sans-serif), so none is cut off at the left edge.
    let longest = bars
        .iter()
        .map(|b| b.label.chars().count())
        .max()
        .unwrap_or(0);
    let left = (16.0 + LABEL_CHAR_PX * longest as f64).max(120.0);
    let plot_w = 430.0;
    let width = left + plot_w + 140.0;
    let top = 50.0;
    let height = top + row * bars.len().max(1) as f64 + 60.0;
    let values = bars
        .iter()
        .flat_map(|b| {
            std::iter::once(b.value)
                .chain(b.second)
                .chain(b.whisker.into_iter().flatten())
        })
        .chain(guides.iter().copied())
        .chain([0.0])
        .filter(|v| v.is_finite());
    let (mut lo, mut hi) = values.fold((0.0f64, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
    if hi - lo <= 0.0 {
        hi = lo + 1.0;
    }
    let pad = 0.05 * (hi - lo);
    lo -= pad;
    hi += pad;
    let x = |v: f64| left + (v.clamp(lo, hi) - lo) / (hi - lo) * plot_w;
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="12">"#
    );
    let _ = write!(
        s,
        r#"<rect width="100%" height="100%" fill="white"/><text x="{}" y="24" font-size="15" text-anchor="middle">{}</text>"#,
        width / 2.0,
        escape(title)
    );
    let bottom = top + row * bars.len() as f64;
    for g in guides.iter().chain([&0.0]) {
        let dash = if *g == 0.0 {
            ""
        } else {
            r#" stroke-dasharray="4 3""#
        };
        let _ = write!(
            s,
            r##"<line x1="{0:.1}" y1="{1}" x2="{0:.1}" y2="{2}" stroke="#888"{dash}/>"##,
            x(*g),
            top - 6.0,
            bottom + 4.0
        );
    }
    for (i, b) in bars.iter().enumerate() {
        let y = top + row * i as f64;
        let colour = if b.highlight { "#c0392b" } else { "#2c7fb8" };
        let _ = write!(
            s,
            r#"<text x="{}" y="{}" text-anchor="end">{}</text>"#,
            left - 8.0,
            y + 14.0,
            escape(&b.label)
        );
        let (x0, x1) = (x(0.0).min(x(b.value)), x(0.0).max(x(b.value)));
        let h = if b.second.is_some() { 8.0 } else { 14.0 };
        if b.value.is_finite() {
            let _ = write!(
                s,
                r#"<rect x="{x0:.1}" y="{:.1}" width="{:.1}" height="{h}" fill="{colour}"/>"#,
                y + 3.0,
                (x1 - x0).max(0.5)
            );
        }
        if let Some(v) = b.second.filter(|v| v.is_finite()) {
            let (a0, a1) = (x(0.0).min(x(v)), x(0.0).max(x(v)));
            let _ = write!(
                s,
                r##"<rect x="{a0:.1}" y="{:.1}" width="{:.1}" height="8" fill="#27ae60"/>"##,
                y + 12.0,
                (a1 - a0).max(0.5)
            );
        }
        if let Some([w0, w1]) = b.whisker.filter(|w| w.iter().all(|v| v.is_finite())) {
            let (a, c, mid) = (x(w0), x(w1), y + 10.0);
            let _ = write!(
                s,
                r##"<path d="M{a:.1} {:.1}V{:.1}M{a:.1} {mid:.1}H{c:.1}M{c:.1} {:.1}V{:.1}" stroke="#222" fill="none"/>"##,
                mid - 4.0,
                mid + 4.0,
                mid - 4.0,
                mid + 4.0
            );
        }
        let _ = write!(
            s,
            r#"<text x="{}" y="{}">{}</text>"#,
            left + plot_w + 8.0,
            y + 14.0,
            escape(&b.note)
        );
    }
    // Axis ticks.
    for k in 0..=4 {
        let v = lo + (hi - lo) * k as f64 / 4.0;
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{}" text-anchor="middle">{:.3}</text>"#,
            x(v),
            bottom + 20.0,
            v
        );
    }
    let _ = write!(
        s,
        r#"<text x="{:.1}" y="{}" text-anchor="middle">{}</text>"#,
        left + plot_w / 2.0,
        bottom + 40.0,
        escape(axis)
    );
    if let Some((a, b)) = legend {
        let _ = write!(
            s,
            r##"<rect x="{0}" y="32" width="10" height="8" fill="#2c7fb8"/><text x="{1}" y="40">{2}</text><rect x="{3}" y="32" width="10" height="8" fill="#27ae60"/><text x="{4}" y="40">{5}</text>"##,
            left,
            left + 14.0,
            escape(a),
            left + 200.0,
            left + 214.0,
            escape(b)
        );
    }
    s.push_str("</svg>\n");
    s
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
            note: format!("p_adj {:.2}", g.p_adjusted),
            highlight: g.flagged,
        })
        .collect();
    let residuals = bar_chart(
        &format!(
            "{}: where the nominal model misses (red: flagged, Holm 5 %)",
            report.campaign
        ),
        "bias score z (measured above the model: > 0; whiskers: +-1, its standard uncertainty); dashed: |z| = 2",
        &residual_bars,
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
        "held-out log-likelihood gain over the nominal model (whiskers: 90 % bootstrap interval); dashed: the explaining threshold",
        &rank_bars,
        &[super::MIN_HELD_OUT_GAIN],
        None,
    );
    let before_after = match &report.best_effect {
        Some(b) => bar_chart(
            &format!(
                "{}: held-out RMS standardized error, nominal vs {} (shrink {:.0} %)",
                report.campaign,
                b.name,
                100.0 * b.shrink
            ),
            "held-out RMS standardized error per held-out group",
            &b.per_group
                .iter()
                .map(|g| Bar {
                    label: g.group.clone(),
                    value: g.before,
                    second: Some(g.after),
                    whisker: None,
                    note: format!("{:.2} -> {:.2}", g.before, g.after),
                    highlight: false,
                })
                .collect::<Vec<_>>(),
            &[1.0],
            Some(("nominal", b.name.as_str())),
        ),
        None => bar_chart(
            &format!(
                "{}: no effect chosen ({:?})",
                report.campaign, report.verdict
            ),
            "held-out RMS standardized error of the nominal model",
            &[Bar {
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
    Some(bar_chart(
        &format!(
            "{}: coefficient each wear mechanism needs for the measured wear (red: within its literature range)",
            report.campaign
        ),
        "decades above the top of the mechanism's literature range (dashed: the top, and the widest range's bottom)",
        &bars,
        &[low],
        None,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bar(label: &str) -> Bar {
        Bar {
            label: label.into(),
            value: 1.0,
            second: None,
            whisker: None,
            note: String::new(),
            highlight: false,
        }
    }

    /// The x of every label's right end, and the SVG's width.
    fn label_ends(svg: &str) -> (Vec<f64>, f64) {
        let number = |s: &str, key: &str| -> Option<f64> {
            let at = s.find(key)? + key.len();
            s[at..].split('"').next()?.parse().ok()
        };
        let ends = svg
            .split("<text ")
            .filter(|t| t.contains(r#"text-anchor="end""#))
            .filter_map(|t| number(t, "x=\""))
            .collect();
        (ends, number(svg, "width=\"").unwrap_or(f64::NAN))
    }

    #[test]
    fn the_longest_label_fits_left_of_the_bars() {
        let long = "pressure_band: 0.1-0.5 Sy and below the cutoff, case A, increment 3";
        let svg = bar_chart("t", "x", &[bar("short"), bar(long)], &[], None);
        let (ends, width) = label_ends(&svg);
        assert_eq!(ends.len(), 2, "{svg}");
        // 0.55 em a character at 12 px: the label's start stays inside the picture.
        for end in ends {
            assert!(
                end - 0.55 * 12.0 * long.chars().count() as f64 >= 0.0,
                "{end}"
            );
        }
        // The plot keeps its width whatever the labels: 430 px of bars, 140 px of notes.
        let short = bar_chart("t", "x", &[bar("a")], &[], None);
        let (_, short_width) = label_ends(&short);
        assert!(width > short_width);
        assert_eq!(short_width, 120.0 + 430.0 + 140.0);
    }

    /// A whisker spans its interval on the bar's axis: from 1 to 3 on an axis from 0 to 3
    /// (padded 5 %), its ends lie at 1/3 and all of the axis.
    #[test]
    fn a_whisker_spans_its_interval() {
        let mut b = bar("gain");
        b.value = 2.0;
        b.whisker = Some([1.0, 3.0]);
        let svg = bar_chart("t", "x", &[b], &[], None);
        let path = svg.split("<path d=\"M").nth(1).expect("a whisker path");
        let xs: Vec<f64> = path
            .split(['M', 'H', 'V', ' ', '"'])
            .take(8)
            .filter_map(|t| t.parse().ok())
            .collect();
        let left = (16.0 + LABEL_CHAR_PX * 4.0f64).max(120.0);
        let (lo, hi) = (-0.15, 3.15);
        let at = |v: f64| left + (v - lo) / (hi - lo) * 430.0;
        assert!((xs[0] - at(1.0)).abs() < 0.06, "{xs:?} vs {}", at(1.0));
        assert!(
            xs.iter().any(|x| (x - at(3.0)).abs() < 0.06),
            "{xs:?} vs {}",
            at(3.0)
        );
    }
}
