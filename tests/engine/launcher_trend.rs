//! Issue 3 item 6: under the AH-64 transverse profile looser rails wear the rail faster
//! (thesis 6.6), and the penalization K_SL (eq. 6.4) is 1 at design, below 1 when looser,
//! never above 1.

use railwear::analysis::penalization::{PenalizationCurve, SweepPoint};
use railwear::models::case::load_case;
use railwear::pipeline::{run_case, RunControl};
use std::path::Path;

fn rail_rate(variant: &str) -> (f64, f64) {
    let configs = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/configs"));
    let mut case = load_case(&configs.join(format!("launcher-{variant}.toml"))).expect("loads");
    case.simulation.settle_s = 1.0;
    case.simulation.duration_s = 2.0;
    case.simulation.record_interval_s = 2.0;
    let k = case
        .launcher
        .as_ref()
        .and_then(|l| l.rattle_space().ok())
        .expect("k_rs");
    let (report, _) = run_case(&case, configs, &RunControl::silent()).expect("runs");
    let rail = report
        .bodies
        .iter()
        .find(|b| b.name == "rail")
        .expect("rail body");
    (k, rail.mass_rate_mg_per_h)
}

#[test]
fn looser_rails_wear_faster_and_k_sl_penalizes_them() {
    let [tight, design, loose] = std::thread::scope(|s| {
        let h: Vec<_> = ["tight", "design", "loose"]
            .iter()
            .map(|v| s.spawn(move || rail_rate(v)))
            .collect();
        let mut out = h.into_iter().map(|j| j.join().expect("run"));
        [
            out.next().expect("t"),
            out.next().expect("d"),
            out.next().expect("l"),
        ]
    });
    assert!(
        tight.1 < design.1 && design.1 < loose.1,
        "rail wear tight {tight:?} design {design:?} loose {loose:?}"
    );
    let points: Vec<SweepPoint> = [tight, design, loose]
        .iter()
        .map(|&(k, r)| SweepPoint {
            offset_mm: None,
            rattle_space: k,
            rail_wear_rate_mg_per_h: r,
        })
        .collect();
    let curve = PenalizationCurve::new(&points, design.0).expect("curve");
    assert!((curve.k_sl(design.0).expect("design") - 1.0).abs() < 1e-12);
    assert!(curve.k_sl(loose.0).expect("loose") < 1.0);
    assert!((curve.k_sl(tight.0).expect("tight") - 1.0).abs() < 1e-12);
}
