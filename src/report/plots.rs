//! The plots of a finished case (wear versus time, contact-pressure PDFs, response PSD) and of
//! a service-life penalization curve (thesis Figure 6.68), drawn with [`super::figure`].

use super::figure::{spans_decades, AxisSpec, Plot, Series};
use crate::analysis::penalization::PenalizationCurve;
use crate::models::run::RunReport;
use crate::models::spec::{CaseSpec, ModelSpecRef};

/// The named SVG plots of a finished case: (file name, SVG text).
pub fn case_plots(
    case: &CaseSpec,
    r: &RunReport,
    psd: Option<&crate::analysis::spectra::Psd>,
) -> Vec<(String, String)> {
    let mut out = Vec::new();
    // Wear versus time per contact, mg.
    // The rattle box and the launcher are one material (7075-T73 unless the config says
    // otherwise); the persistent-contact case has no dynamic run.
    let material = match case.model_spec() {
        Ok(ModelSpecRef::RattleBox(s)) => s.material,
        Ok(ModelSpecRef::Launcher(s)) => s.material,
        _ => crate::wear::material::Material::default(),
    };
    let density = material.density_kg_per_m3;
    let wear_series: Vec<Series> = r
        .contacts
        .iter()
        .enumerate()
        .map(|(ci, c)| {
            let pts: Vec<(f64, f64)> = r
                .wear_history
                .iter()
                .map(|(t, v)| (*t, v.get(ci).copied().unwrap_or(0.0) * density * 1e6))
                .collect();
            Series::line(&c.name, pts)
        })
        .collect();
    // The contacts' wear is compared at the end of the run: where their final masses span
    // more than two decades the axis is logarithmic, down to three decades below the least.
    let finals: Vec<f64> = wear_series
        .iter()
        .filter_map(|s| s.points.last().map(|p| p.1))
        .filter(|m| m.is_finite() && *m > 0.0)
        .collect();
    let wear_axis = if spans_decades(finals.iter().copied()) {
        let least = finals.iter().copied().fold(f64::INFINITY, f64::min);
        let most = finals.iter().copied().fold(0.0, f64::max);
        AxisSpec::log("wear mass (mg)").with_range(
            10f64.powf(least.log10().floor() - 3.0),
            10f64.powf(most.log10().ceil()),
        )
    } else {
        AxisSpec::linear("wear mass (mg)")
    };
    let mut wear_plot = Plot::new(
        format!("{}: wear versus time", case.name),
        AxisSpec::linear("time (s)"),
        wear_axis,
    );
    for series in wear_series {
        wear_plot = wear_plot.with_series(series);
    }
    out.push(("wear_vs_time.svg".to_string(), wear_plot.to_svg()));
    // Contact-pressure PDF per contact with S_y and the cutoff marked.
    for c in &r.contacts {
        let dens = c.wear.pressure_histogram.time_density_per_pa();
        let nonzero: Vec<(f64, f64)> = dens.into_iter().filter(|(_, d)| *d > 0.0).collect();
        if nonzero.is_empty() {
            continue;
        }
        let edges: Vec<f64> = (0..=c.wear.pressure_histogram.len())
            .map(|i| c.wear.pressure_histogram.edge_pa(i) / 1e6)
            .collect();
        let values: Vec<f64> = c
            .wear
            .pressure_histogram
            .time_density_per_pa()
            .iter()
            .map(|(_, d)| d * 1e6)
            .collect();
        let mut p = Plot::new(
            format!("{}: contact-pressure PDF, {}", case.name, c.name),
            AxisSpec::log("contact pressure (MPa)"),
            AxisSpec::auto("time density (1/MPa)"),
        )
        .with_series(Series::histogram("time share", &edges, &values));
        p = p.with_marker(material.yield_strength_pa / 1e6, "yield strength Sy");
        if let Some(cut) = c.wear.cutoff_pressure_pa {
            p = p.with_marker(cut / 1e6, "wear-law cutoff");
        }
        out.push((format!("pressure_pdf_{}.svg", c.name), p.to_svg()));
    }
    if let Some(psd) = psd {
        let pts: Vec<(f64, f64)> = psd
            .frequency_hz
            .iter()
            .zip(&psd.density)
            .filter(|(f, d)| **f > 0.0 && **d > 0.0)
            .map(|(f, d)| (*f, *d))
            .collect();
        if !pts.is_empty() {
            let p = Plot::new(
                format!("{}: response acceleration PSD (x)", case.name),
                AxisSpec::log("frequency (Hz)"),
                AxisSpec::log("PSD ((m/s²)²/Hz)"),
            )
            .with_series(Series::line("x", pts));
            out.push(("response_psd.svg".to_string(), p.to_svg()));
        }
    }
    out
}

/// K_SL versus rattle space with the 0.9 and 0.8 bands (thesis Figure 6.68).
pub fn curve_plot(curve: &PenalizationCurve) -> String {
    let (lo, hi) = curve.range();
    let n = 60;
    let mut k_sl = Vec::new();
    let mut b90 = Vec::new();
    let mut b80 = Vec::new();
    for i in 0..=n {
        let k = lo + (hi - lo) * i as f64 / n as f64;
        if let Ok(f) = curve.factors(k) {
            k_sl.push((k, f.k_sl));
            b90.push((k, f.k_sl_conservative_90));
            b80.push((k, f.k_sl_conservative_80));
        }
    }
    Plot::new(
        "Service-life penalization (eq. 6.4)",
        AxisSpec::linear("rattle space k_rs"),
        AxisSpec::linear("K_SL"),
    )
    .with_series(Series::line("K_SL", k_sl))
    .with_series(Series::line("0.9 K_SL", b90))
    .with_series(Series::line("0.8 K_SL", b80))
    .to_svg()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::penalization::SweepPoint;
    use railwear_testkit::svg::texts_outside_view_box;

    #[test]
    fn the_penalization_curve_fits_its_picture() {
        let point = |rattle_space, rate| SweepPoint {
            offset_mm: None,
            rattle_space,
            rail_wear_rate_mg_per_h: rate,
        };
        let curve = PenalizationCurve::new(
            &[point(0.8317, 1.0), point(0.7684, 4.0), point(0.7990, 2.0)],
            0.7990,
        )
        .expect("curve");
        let svg = curve_plot(&curve);
        let outside = texts_outside_view_box(&svg);
        assert!(outside.is_empty(), "{outside:#?}");
        assert!(svg.contains("0.9 K_SL") && svg.contains("rattle space k_rs"));
    }
}
