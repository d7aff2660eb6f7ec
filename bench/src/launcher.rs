//! `launcher` and `launcher-mem`: real-time factor and memory of the launcher.

use super::*;

pub(crate) fn launcher_case(configs_dir: &Path, settle: f64, window: f64) -> Result<CaseSpec> {
    let mut case = load_case(&configs_dir.join("launcher-design.toml"))?;
    case.simulation.settle_s = settle;
    case.simulation.duration_s = window;
    case.simulation.record_interval_s = case.simulation.record_interval_s.min(window);
    Ok(case)
}

/// VmHWM (peak resident set) and VmRSS of this process, kB.
pub(crate) fn vm_kb(key: &str) -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    s.lines()
        .find(|l| l.starts_with(key))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
}

/// Wall time against simulated duration (issue 16: 10, 30, 60, 120 s within 10 % of
/// proportional): launcher-design with the default engine and tracks recorded at the case's
/// rate, each duration one run after a 1 s settle.
pub(crate) fn launcher_linearity(
    configs_dir: &Path,
    settle: f64,
    durations: &[f64],
) -> Result<Table> {
    let mut t = Table::new(
        "Launcher cost against duration (launcher-design, default engine, tracks recorded)",
        &[
            ("simulated_s", "simulated s (settle + window)"),
            ("cpu_s", "CPU s"),
            ("wall_s", "wall s"),
            ("cpu_per_simulated_s", "CPU s per simulated s"),
            ("vs_shortest", "per simulated s / shortest run"),
            ("real_time_factor_cpu", "real-time factor (CPU)"),
            ("accepted", "accepted"),
            ("accepted_per_simulated_s", "accepted steps per simulated s"),
            ("cpu_us_per_step", "CPU µs per accepted step"),
            ("track_samples", "track samples"),
        ],
    );
    let mut first: Option<f64> = None;
    for &d in durations {
        eprintln!("launcher: linearity run, window {d} s ...");
        let case = launcher_case(configs_dir, settle, d)?;
        let cpu0 = super::convergence::thread_cpu_s();
        let (report, outcome) = run_case(&case, configs_dir, &RunControl::silent())
            .map_err(|e| anyhow!("launcher run: {e}"))?;
        let cpu = super::convergence::thread_cpu_s()
            .zip(cpu0)
            .map(|(b, a)| b - a)
            .unwrap_or(report.wall_s);
        let simulated = settle + d;
        let per = cpu / simulated;
        let base = *first.get_or_insert(per);
        t.row(vec![
            Cell::Num(simulated),
            Cell::Num(cpu),
            Cell::Num(report.wall_s),
            Cell::Num(per),
            Cell::Num(per / base),
            Cell::Num(simulated / cpu.max(1e-9)),
            Cell::Int(report.integrator.accepted),
            Cell::Num(report.integrator.accepted as f64 / simulated),
            Cell::Num(1e6 * cpu / (report.integrator.accepted as f64).max(1.0)),
            Cell::Int(outcome.tracks.len() as u64),
        ]);
    }
    t.note(
        "CPU s = this thread's user + system time of the run (simulation, wear, track recording); \
         the target is every row's per-second cost within 10 % of the others. The cost per accepted \
         step separates the engine (is each step's cost constant?) from the physics (does the \
         motion need as many steps per second early in a run as later?)",
    );
    t.note(machine_note());
    Ok(t)
}

pub(crate) fn launcher(
    configs_dir: &Path,
    settle: f64,
    window: f64,
    mem_window: f64,
    no_mem: bool,
    default_only: bool,
) -> Result<Vec<Table>> {
    if !(settle >= 0.0 && window > 0.0 && mem_window > 0.0) {
        bail!("--settle must be >= 0 and --window, --mem-window > 0");
    }
    let mut t = Table::new(
        "Launcher reference run (launcher-design, AH-64 transverse profile)",
        &[
            ("run", "run"),
            ("simulated_s", "simulated s"),
            ("tolerance", "tolerance"),
            ("real_time_factor", "real-time factor"),
            ("steps_per_s", "steps/s"),
            ("accepted", "accepted"),
            ("rejected", "rejected"),
            ("track_samples", "track samples stored"),
            ("peak_rss_mb", "peak RSS MB"),
            ("rail_wear_mg_per_h", "rail wear mg/h"),
        ],
    );
    let case = launcher_case(configs_dir, settle, window)?;
    let options = run_options(&case)?;
    // Every engine variant (the default first) for the same-run comparison.
    let variants = if default_only {
        1
    } else {
        ENGINE_VARIANTS.len()
    };
    for engine in ENGINE_VARIANTS.into_iter().take(variants) {
        let mut variant = case.clone();
        variant.simulation.newton_jacobian = engine.newton;
        variant.simulation.contact_patches = engine.patches;
        eprintln!("launcher: timed run ({}) ...", engine.name);
        let (report, outcome) = run_case(&variant, configs_dir, &RunControl::silent())
            .map_err(|e| anyhow!("launcher run: {e}"))?;
        let simulated = settle + window;
        let wall = report.wall_s.max(1e-9);
        let rail = rail_wear_mg_per_h(&report);
        let newton_name = engine.name;
        t.row(vec![
            Cell::text(format!(
                "timed: settle {settle} s + window {window} s, {newton_name}"
            )),
            Cell::Num(simulated),
            Cell::text(tolerance_text(&options.integrator.tolerances)),
            Cell::Num(simulated / wall),
            Cell::Num(report.integrator.accepted as f64 / wall),
            Cell::Int(report.integrator.accepted),
            Cell::Int(report.integrator.rejected),
            Cell::Int(outcome.tracks.len() as u64),
            Cell::opt(vm_kb("VmHWM:").map(|k| k as f64 / 1024.0)),
            Cell::opt(rail),
        ]);
    }
    if !no_mem {
        eprintln!("launcher: memory run (settle {settle} s + window {mem_window} s) in a child process ...");
        let exe = std::env::current_exe().context("locating railwear-bench")?;
        let out = std::process::Command::new(exe)
            .arg("--configs-dir")
            .arg(configs_dir)
            .args([
                "launcher-mem",
                "--settle",
                &settle.to_string(),
                "--window",
                &mem_window.to_string(),
            ])
            .stderr(std::process::Stdio::inherit())
            .output()
            .context("running the memory child")?;
        let line = String::from_utf8_lossy(&out.stdout);
        let v: Value = parse_json_lines(&line)
            .into_iter()
            .next()
            .ok_or_else(|| anyhow!("memory child printed no result ({})", out.status))?;
        let f = |k: &str| v.get(k).and_then(Value::as_f64);
        let sim = f("simulated_s").unwrap_or(f64::NAN);
        let label = if (sim - 60.0).abs() < 1e-9 {
            format!(
                "memory: 60 s run (settle {settle} s + window {mem_window} s), all tracks stored"
            )
        } else {
            format!(
                "memory: SHORTENED to {sim} s (settle {settle} s + window {mem_window} s; the target is a 60 s run), all tracks stored"
            )
        };
        t.row(vec![
            Cell::text(label),
            Cell::Num(sim),
            Cell::text(tolerance_text(&options.integrator.tolerances)),
            Cell::opt(f("real_time_factor")),
            Cell::opt(f("steps_per_s")),
            Cell::Int(f("accepted").unwrap_or(0.0) as u64),
            Cell::Int(f("rejected").unwrap_or(0.0) as u64),
            Cell::Int(f("track_samples").unwrap_or(0.0) as u64),
            Cell::opt(f("vm_hwm_kb").map(|k| k / 1024.0)),
            Cell::opt(f("rail_wear_mg_per_h")),
        ]);
        if let (Some(b), Some(h)) = (f("baseline_hwm_kb"), f("vm_hwm_kb")) {
            t.note(format!(
                "memory run: peak RSS (VmHWM of a fresh child process) {:.1} MB; {:.1} MB before the run \
                 (binary, configs); track sample = {} bytes in memory, recorded every {} s per active track; \
                 the run as the service does it (run_case: report plus packaged outcome; the track samples are held once, in the outcome)",
                h / 1024.0,
                b / 1024.0,
                f("track_sample_bytes").unwrap_or(f64::NAN),
                case.simulation.record_interval_s
            ));
            if let (Some(n), Some(bytes)) = (f("track_samples"), f("track_sample_bytes")) {
                if sim < 60.0 && mem_window > 0.0 {
                    // Samples accrue over the window only (recording starts with the excitation).
                    let n60 = n * (60.0 - settle).max(0.0) / mem_window;
                    let est_mb = h / 1024.0 + (n60 - n) * bytes / 1048576.0;
                    t.note(format!(
                        "ESTIMATE, not measured: at this run's rate a 60 s run stores about {n60:.0}                          track samples; with one copy of {bytes} bytes each the peak would be about                          {est_mb:.0} MB (plus up to 2x Vec growth slack on the track buffers)"
                    ));
                }
            }
        }
    }
    t.note(
        "real-time factor = (settle + window) / wall of the simulation loop (track recording \
         included, as configured); one thread",
    );
    t.note(machine_note());
    Ok(vec![t])
}

/// Wear rate of the launcher's rail body, mg/h.
pub(crate) fn rail_wear_mg_per_h(report: &RunReport) -> Option<f64> {
    report
        .bodies
        .iter()
        .find(|b| b.name == "rail")
        .map(|b| b.mass_rate_mg_per_h)
}

pub(crate) fn launcher_mem(configs_dir: &Path, settle: f64, window: f64) -> Result<()> {
    let baseline = vm_kb("VmHWM:");
    let case = launcher_case(configs_dir, settle, window)?;
    let (report, outcome) = run_case(&case, configs_dir, &RunControl::silent())
        .map_err(|e| anyhow!("launcher memory run: {e}"))?;
    let hwm = vm_kb("VmHWM:");
    let simulated = settle + window;
    let wall = report.wall_s.max(1e-9);
    let rail = rail_wear_mg_per_h(&report);
    println!(
        "{}",
        json!({
            "simulated_s": simulated,
            "wall_s": report.wall_s,
            "real_time_factor": simulated / wall,
            "steps_per_s": report.integrator.accepted as f64 / wall,
            "accepted": report.integrator.accepted,
            "rejected": report.integrator.rejected,
            "track_samples": outcome.tracks.len(),
            "track_sample_bytes": std::mem::size_of::<railwear::physics::track::TrackSample>(),
            "vm_hwm_kb": hwm,
            "baseline_hwm_kb": baseline,
            "rail_wear_mg_per_h": rail,
        })
    );
    Ok(())
}
