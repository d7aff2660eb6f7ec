//! Development helper: runs a case with overrides and prints per-track friction-power shares.
use railwear::models::case::load_case;
use railwear::pipeline::{run_case, RunControl};
use std::collections::BTreeMap;
use std::path::Path;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: run_case <config> [duration settle rel abs]");
        return;
    };
    let Ok(mut case) = load_case(Path::new(path)) else {
        eprintln!("bad case");
        return;
    };
    let arg = |i: usize| args.get(i).and_then(|s| s.parse::<f64>().ok());
    if let Some(d) = arg(2) {
        case.simulation.duration_s = d;
    }
    if let Some(s) = arg(3) {
        case.simulation.settle_s = s;
    }
    if let Some(r) = arg(4) {
        case.simulation.rel_tolerance = r;
    }
    if let Some(a) = arg(5) {
        case.simulation.abs_tolerance_m = a;
    }
    case.simulation.record_interval_s = 1e-9;
    match run_case(&case, Path::new("configs"), &RunControl::silent()) {
        Ok((r, o)) => {
            let sim = case.simulation.settle_s + case.simulation.duration_s;
            println!(
                "wall {:.2}s rtf {:.3} stats {:?}",
                r.wall_s,
                sim / r.wall_s,
                r.integrator
            );
            println!(
                "mean N {:.4} N, mean N*v {:.5} W",
                r.mean_normal_force_n, r.mean_normal_slip_power_w
            );
            for c in &r.contacts {
                println!(
                    "{} rate {:.5} mg/h above-cutoff {:.3} peakN {:.1}",
                    c.name, c.mass_rate_mg_per_h, c.work_share_above_cutoff, c.peak_normal_force_n
                );
            }
            // Friction-power share by track and by normal-force band.
            let mut prev: BTreeMap<(u32, u32), (f64, f64)> = BTreeMap::new();
            let mut by_track: BTreeMap<u32, f64> = BTreeMap::new();
            let mut by_band = [0.0f64; 4];
            for s in &o.tracks {
                let p = s.normal_force_n * s.slip_speed_m_s;
                if let Some((t0, p0)) = prev.insert((s.contact, s.track), (s.time_s, p)) {
                    let dt = s.time_s - t0;
                    if dt < 1e-3 {
                        let e = 0.5 * dt * (p + p0);
                        *by_track.entry(s.track).or_default() += e;
                        let band = if s.normal_force_n < 1.0 {
                            0
                        } else if s.normal_force_n < 10.0 {
                            1
                        } else if s.normal_force_n < 100.0 {
                            2
                        } else {
                            3
                        };
                        by_band[band] += e;
                    }
                }
            }
            let w = r.window_s;
            for (t, e) in &by_track {
                println!("track {t}: {:.4} W", e / w);
            }
            println!(
                "by N band <1, <10, <100, >=100 N: {:?} W",
                by_band.map(|e| e / w)
            );
        }
        Err(e) => println!("error: {e}"),
    }
}
