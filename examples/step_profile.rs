//! Development helper: where the integrator's steps, rejections and right-hand sides go on a
//! case, binned by the largest contact normal force at the end of each step
//! (`cargo run --release --example step_profile configs/rattle-box-c.toml 2 0.5`).
use railwear::models::case::{build, integrator_settings, load_case};
use railwear::physics::integrator::Integrator;
use std::path::Path;
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        return Err("usage: step_profile <config> [duration_s settle_s]".into());
    };
    let mut case = load_case(Path::new(path))?;
    let arg = |i: usize| args.get(i).and_then(|s| s.parse::<f64>().ok());
    case.simulation.duration_s = arg(2).unwrap_or(1.0);
    case.simulation.settle_s = arg(3).unwrap_or(0.5);
    let m = build(&case, Path::new("configs"))?;
    let sys = &m.system;
    let settings = integrator_settings(&case)?;
    let mut integ = Integrator::new(sys, settings);
    integ.diagnose = true;
    let mut ws = sys.workspace();
    ws.keep_tracks = true; // as simulate() does: the step's tracks come with its last evaluation
    let mut y = m.initial_state.clone();
    let mut t = 0.0;
    // bins: 0 free, 1 N<1, 2 1..100, 3 >=100
    let mut steps = [0u64; 4];
    let mut rhs = [0u64; 4];
    let mut rej = [0u64; 4];
    let mut simt = [0f64; 4];
    let mut hhist = [0u64; 12];
    let mut prev = integ.stats;
    let mut prev_bin = 0usize;
    let mut impacts = 0u64;
    let start = std::time::Instant::now();
    while t < m.end_time_s {
        let t0 = t;
        t = integ
            .advance(sys, &mut ws, t, &mut y, m.end_time_s)
            .expect("advance");
        let ntr = ws.tracks.len();
        let maxn = ws
            .tracks
            .iter()
            .map(|tr| tr.normal_force)
            .fold(-1.0, f64::max);
        let bin = if ntr == 0 {
            0
        } else if maxn < 1.0 {
            1
        } else if maxn < 100.0 {
            2
        } else {
            3
        };
        // attribute work to the max of the bin before and after
        let b = bin.max(prev_bin);
        if bin == 3 && prev_bin < 3 && t0 >= m.excitation_start_s {
            impacts += 1;
        }
        prev_bin = bin;
        if t0 >= m.excitation_start_s {
            let s = integ.stats;
            steps[b] += 1;
            rhs[b] += s.rhs_evals - prev.rhs_evals;
            rej[b] += s.rejected - prev.rejected;
            simt[b] += t - t0;
            let lh = (-(t - t0).log10()).floor() as usize;
            hhist[lh.min(11)] += 1;
        }
        prev = integ.stats;
    }
    println!(
        "wall {:.2}s stats {:?}",
        start.elapsed().as_secs_f64(),
        integ.stats
    );
    for (i, name) in ["free", "N<1", "1..100", ">=100"].iter().enumerate() {
        println!(
            "{name:>8}: steps {:>7} rej {:>7} rhs {:>8} simtime {:.4}s",
            steps[i], rej[i], rhs[i], simt[i]
        );
    }
    // Counted over the whole run, settle included.
    let d = integ.diagnostics;
    println!("rejections by what the contacts did within the attempt (whole run):");
    for (name, row) in ["Newton failures", "error test"]
        .iter()
        .zip(d.rejections_by_event)
    {
        println!(
            "{name:>16}: onset {} separation {} clamp switch {} same contact set {}",
            row[0], row[1], row[2], row[3]
        );
    }
    println!("attempts by step size and the state kind limiting the error (whole run):");
    for (i, row) in d.limiting_kind.iter().enumerate() {
        if row.iter().any(|&c| c > 0) {
            println!(
                "h in [1e-{}, 1e-{}): position {} rotation {} velocity {} angular velocity {}",
                i + 1,
                i,
                row[0],
                row[1],
                row[2],
                row[3]
            );
        }
    }
    println!("impacts (entries into N >= 100 N): {impacts}");
    for (i, c) in hhist.iter().enumerate() {
        println!("h in [1e-{}, 1e-{}): {}", i + 1, i, c);
    }
    Ok(())
}
