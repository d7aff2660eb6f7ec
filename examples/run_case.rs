use railwear::models::case::{load_case, run_case};
use railwear::pipeline::RunControl;
use std::path::Path;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut case = load_case(Path::new(&args[1])).expect("case");
    if let Some(d) = args.get(2) {
        case.simulation.duration_s = d.parse().unwrap();
    }
    if let Some(s) = args.get(3) {
        case.simulation.settle_s = s.parse().unwrap();
    }
    if let Some(r) = args.get(4) {
        case.simulation.rel_tolerance = r.parse().unwrap();
    }
    if let Some(a) = args.get(5) {
        case.simulation.abs_tolerance_m = a.parse().unwrap();
    }
    match run_case(&case, Path::new("configs"), &RunControl::silent()) {
        Ok((r, _o)) => {
            println!(
                "wall {:.2}s rtf {:.3} stats {:?}",
                r.wall_s,
                (case.simulation.settle_s + case.simulation.duration_s) / r.wall_s,
                r.integrator
            );
            println!(
                "mean N {:.4} N, mean N*v {:.5} W",
                r.mean_normal_force_n, r.mean_friction_power_w
            );
            for c in &r.contacts {
                println!(
                    "{} rate {:.5} mg/h (a {:.5}) above-cutoff {:.3} peakN {:.1} peakP {:.3e}",
                    c.name,
                    c.mass_rate_mg_per_h,
                    c.mass_rate_a_mg_per_h,
                    c.work_share_above_cutoff,
                    c.peak_normal_force_n,
                    c.wear.peak_pressure_pa
                );
            }
        }
        Err(e) => println!("error: {e}"),
    }
}
