//! Slow anchors of `railwear validate --slow`: whole-model runs.

use crate::models::case::{load_case, run_case};
use crate::pipeline::RunControl;
use crate::validation::Anchor;
use std::path::Path;

/// Thesis Table 5.4 (ADAMS) rattle-box wear rates, mg/h.
pub const TABLE_5_4_ADAMS_MG_PER_H: [(&str, f64); 4] =
    [("a", 1.7124), ("b", 3.2622), ("c", 1.7278), ("d", 0.5910)];

/// Runs the slow anchors.
pub fn run(configs_dir: &Path) -> Vec<Anchor> {
    let mut out = Vec::new();
    // Convergence of the friction power on rattle box C (issue 2 item 5).
    let fp = |scale: f64| -> f64 {
        let path = configs_dir.join("rattle-box-c.toml");
        let Ok(mut case) = load_case(&path) else {
            return f64::NAN;
        };
        case.simulation.settle_s = 0.5;
        case.simulation.duration_s = 16.0;
        case.simulation.rel_tolerance *= scale;
        case.simulation.abs_tolerance_m *= scale;
        case.simulation.record_interval_s = 0.01;
        match run_case(&case, configs_dir, &RunControl::silent()) {
            Ok((r, _)) => r.mean_friction_power_w,
            Err(_) => f64::NAN,
        }
    };
    let p1 = fp(1.0);
    let p2 = fp(0.5);
    out.push(Anchor {
        name: "rattle box C: friction power change when halving tolerances".into(),
        source: "issue 2 convergence criterion (< 2 %)".into(),
        unit: "relative".into(),
        expected: 0.0,
        measured: ((p2 - p1) / p1).abs(),
        tolerance: 0.02,
        pass: ((p2 - p1) / p1).abs() < 0.02,
    });
    out
}
