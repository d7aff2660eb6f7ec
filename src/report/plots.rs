//! The plots of a finished case (wear versus time, contact-pressure PDFs, response PSD) and of
//! a service-life penalization curve (thesis Figure 6.68), drawn with [`super::svg`].

use super::svg::{AxisSpec, Plot, Series};
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
    let mut wear_plot = Plot::new(
        format!("{}: wear versus time", case.name),
        AxisSpec::linear("time (s)"),
        AxisSpec::linear("wear mass (mg)"),
    );
    for (ci, c) in r.contacts.iter().enumerate() {
        let pts: Vec<(f64, f64)> = r
            .wear_history
            .iter()
            .map(|(t, v)| (*t, v.get(ci).copied().unwrap_or(0.0) * density * 1e6))
            .collect();
        wear_plot = wear_plot.with_series(Series::line(&c.name, pts));
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
            AxisSpec::linear("time density (1/MPa)"),
        )
        .with_series(Series::histogram("time share", &edges, &values));
        p = p.with_marker(material.yield_strength_pa / 1e6, "Sy");
        if let Some(cut) = c.wear.cutoff_pressure_pa {
            p = p.with_marker(cut / 1e6, "cutoff");
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
