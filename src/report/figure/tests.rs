//! The figures render inside their pictures, with round ticks and log axes over decades.

use super::axis::{resolve, AxisCoord};
use super::*;
use railwear_testkit::svg::{text_boxes, texts_outside_view_box};

/// Every text inside the picture; every number among the texts round (at most two
/// significant digits: 1-2-5 steps, whole decades).
fn check(svg: &str) {
    let outside = texts_outside_view_box(svg);
    assert!(outside.is_empty(), "{outside:#?}\n{svg}");
    for t in text_boxes(svg) {
        if let Ok(v) = t.text.parse::<f64>() {
            let digits = format!("{:e}", v.abs());
            let mantissa = digits.split('e').next().unwrap_or("");
            assert!(
                mantissa.replace('.', "").len() <= 2,
                "tick {} is not round",
                t.text
            );
        }
    }
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
}

/// The tick labels of an SVG (texts that are numbers).
fn ticks(svg: &str) -> Vec<f64> {
    text_boxes(svg)
        .iter()
        .filter_map(|t| t.text.parse().ok())
        .collect()
}

#[test]
fn tick_labels_are_compact_and_round() {
    assert_eq!(format_tick(0.30000000000000004), "0.3");
    assert_eq!(format_tick(2.5e-6), "2.5e-6");
    assert_eq!(format_tick(1e6), "1e6");
    assert_eq!(format_tick(1000.0000000000001), "1000");
    assert_eq!(format_tick(-40.0), "-40");
    let axis = AxisCoord::fit(&AxisSpec::linear("x"), &[-495.141, 2217.135]);
    assert_eq!(axis.ticks, [-1000.0, 0.0, 1000.0, 2000.0, 3000.0]);
    assert_eq!((axis.from, axis.to), (-1000.0, 3000.0));
}

#[test]
fn auto_takes_a_log_axis_over_two_decades() {
    assert_eq!(resolve(Scale::Auto, &[1.0, 50.0]), Scale::Linear);
    assert_eq!(resolve(Scale::Auto, &[1e2, 1e8]), Scale::Log10);
    assert_eq!(
        resolve(Scale::Auto, &[-5e6, 150.0, 5e7]),
        Scale::SymLog10 {
            linear_within: 100.0
        }
    );
    let axis = AxisCoord::fit(&AxisSpec::auto("gain"), &[-5e6, 150.0, 5e7]);
    assert!(
        axis.ticks.contains(&0.0) && axis.ticks.contains(&1e6),
        "{:?}",
        axis.ticks
    );
    assert_eq!((axis.from, axis.to), (-1e7, 1e8));
    let log = AxisCoord::fit(&AxisSpec::auto("gain"), &[120.0, 3e4, 2e8]);
    assert_eq!((log.from, log.to), (100.0, 1e9));
}

#[test]
fn line_histogram_and_markers_fit_the_picture() {
    // A pressure PDF: log pressure, densities over decades (log), markers near the right edge.
    let edges: Vec<f64> = (0..=40)
        .map(|i| 10f64.powf(-1.0 + 0.1 * f64::from(i)))
        .collect();
    let values: Vec<f64> = (0..40).map(|i| 10f64.powf(-0.15 * f64::from(i))).collect();
    let pdf = Plot::new(
        "launcher-design: contact-pressure PDF, front shoe upper flange against the rail",
        AxisSpec::log("contact pressure (MPa)"),
        AxisSpec::auto("time density (1/MPa)"),
    )
    .with_series(Series::histogram("time share", &edges, &values))
    .with_marker(435.0, "yield strength Sy")
    .with_marker(870.0, "wear-law cutoff")
    .to_svg();
    check(&pdf);
    assert!(ticks(&pdf).contains(&1000.0), "{pdf}");
    assert!(pdf.contains("yield strength Sy") && pdf.contains("wear-law cutoff"));

    // Wear versus time: three contacts, a scatter, a line broken at a NaN.
    let wear = Plot::new(
        "rattle-box-c: wear versus time",
        AxisSpec::linear("time (s)"),
        AxisSpec::linear("wear mass (mg)"),
    )
    .with_series(Series::line(
        "box_floor",
        vec![
            (0.0, 0.0),
            (1.0, 0.2),
            (f64::NAN, 1.0),
            (2.0, 0.45),
            (3.0, 0.61),
        ],
    ))
    .with_series(Series::line(
        "a contact with a long name",
        vec![(0.0, 0.0), (3.0, 0.07)],
    ))
    .with_series(Series::scatter("samples", vec![(0.5, 0.1), (2.5, 0.5)]))
    .to_svg();
    check(&wear);
    // The first series' line is broken at its NaN: two runs, and its legend entry.
    let first_colour = wear
        .matches("<polyline")
        .count()
        .min(wear.matches(r##"stroke="#1F77B4""##).count());
    assert_eq!(first_colour, 3, "{wear}");

    // An empty plot still draws its frame.
    check(&Plot::new("", AxisSpec::linear("x"), AxisSpec::log("y")).to_svg());
}

fn bar(label: &str, value: f64) -> Bar {
    Bar {
        label: label.into(),
        value,
        second: None,
        whisker: None,
        note: String::new(),
        highlight: false,
    }
}

#[test]
fn bar_charts_fit_the_picture_and_take_log_axes_over_decades() {
    // A ranking whose gains span 1e2 to 1e8 and go negative, long labels and notes.
    let bars: Vec<Bar> = [
        ("third_body", 5.07e7),
        ("wear_above_cutoff", 2.3e5),
        (
            "pressure_band: 0.1-0.5 Sy and below the cutoff, case A",
            150.0,
        ),
        ("cross_axis", -5.07e6),
    ]
    .iter()
    .map(|(name, gain)| Bar {
        whisker: Some([gain * 0.5, gain * 1.5]),
        note: "P(first) 0.97, lack-of-fit p 0.01".into(),
        highlight: *gain > 1e7,
        ..bar(name, *gain)
    })
    .collect();
    let ranking = BarChart {
        title: "thesis-rattle-box: effects ranked by held-out log-likelihood gain (red: explains)"
            .into(),
        axis: AxisSpec::auto(
            "held-out log-likelihood gain over the nominal model (whiskers: 90 % bootstrap \
             interval); dashed: the explaining threshold",
        ),
        bars,
        guides: vec![2.0],
        legend: None,
    }
    .to_svg();
    check(&ranking);
    let t = ticks(&ranking);
    assert!(
        t.contains(&0.0) && t.contains(&1e6) && t.contains(&-1e6),
        "{t:?}"
    );
    assert!(ranking.contains("lack-of-fit p 0.01"));

    // Before and after, with its legend; residuals on a linear axis.
    let before_after = BarChart {
        title: "c: held-out RMS standardized error, nominal vs third_body (shrink 80 %)".into(),
        axis: AxisSpec::auto("held-out RMS standardized error per held-out group"),
        bars: vec![Bar {
            second: Some(1.2),
            note: "801.44 -> 1.20".into(),
            ..bar("test 3", 801.44)
        }],
        guides: vec![1.0],
        legend: Some(("nominal".into(), "third_body".into())),
    }
    .to_svg();
    check(&before_after);
    assert!(ticks(&before_after).contains(&1000.0));
    let residuals = BarChart {
        title: "c: where the nominal model misses".into(),
        axis: AxisSpec::auto("bias score z"),
        bars: vec![
            Bar {
                whisker: Some([-2.2, -0.2]),
                ..bar("test: 1", -1.2)
            },
            bar("test: 2", 3.5),
        ],
        guides: vec![-2.0, 2.0],
        legend: None,
    }
    .to_svg();
    check(&residuals);
    assert_eq!(ticks(&residuals), [-4.0, -2.0, 0.0, 2.0, 4.0]);
}
