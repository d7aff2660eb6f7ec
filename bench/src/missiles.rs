//! `missiles`: cost per missile of a launcher carrying 1, 2 and 4 missiles (launcher-design,
//! launcher-m299-2, launcher-m299-4), each missile with its own latch and contacts, all rails
//! driven by the one launcher motion. The library integrates each independent missile with its
//! own integrator (`physics::partition`); with `--monolithic` the same systems are also
//! integrated as one system with one integrator, for comparison.

use super::convergence::thread_cpu_s;
use super::*;
use railwear::physics::partition::independent_parts;

fn missile_case(configs_dir: &Path, name: &str, settle: f64, window: f64) -> Result<CaseSpec> {
    let mut case = load_case(&configs_dir.join(format!("{name}.toml")))?;
    case.simulation.settle_s = settle;
    case.simulation.duration_s = window;
    case.simulation.record_interval_s = case.simulation.record_interval_s.min(window);
    Ok(case)
}

pub(crate) fn missiles(
    configs_dir: &Path,
    settle: f64,
    window: f64,
    monolithic: bool,
) -> Result<Vec<Table>> {
    if !(settle >= 0.0 && window > 0.0) {
        bail!("--settle must be >= 0 and --window > 0");
    }
    let mut t = Table::new(
        "Launcher with 1, 2 and 4 missiles (AH-64 transverse profile, tracks recorded)",
        &[
            ("config", "config"),
            ("missiles", "missiles"),
            ("integration", "integration"),
            ("accepted", "accepted"),
            ("rhs", "right-hand sides"),
            ("cpu_s", "CPU s"),
            ("cpu_per_missile_s", "CPU s per missile"),
            ("per_missile_vs_one", "per missile / 1 missile"),
            ("real_time_factor_cpu", "real-time factor (CPU)"),
            ("rail_wear", "rail wear per missile mg/h (mean)"),
        ],
    );
    let mut one: Option<f64> = None;
    let mut one_mono: Option<f64> = None;
    let simulated = settle + window;
    for name in ["launcher-design", "launcher-m299-2", "launcher-m299-4"] {
        let case = missile_case(configs_dir, name, settle, window)?;
        let n = match case.model_spec() {
            Ok(railwear::models::spec::ModelSpecRef::Launcher(s)) => s.stations.len(),
            _ => bail!("{name} is not a launcher case"),
        };
        eprintln!("missiles: {name} ({n} missiles), one integrator per missile ...");
        let cpu0 = thread_cpu_s();
        let (report, _) = run_case(&case, configs_dir, &RunControl::silent())
            .map_err(|e| anyhow!("{name}: {e}"))?;
        let cpu = thread_cpu_s()
            .zip(cpu0)
            .map(|(b, a)| b - a)
            .unwrap_or(report.wall_s);
        let per = cpu / n as f64;
        let base = *one.get_or_insert(per);
        let rail_wear: f64 = report
            .bodies
            .iter()
            .filter(|b| b.name == "rail" || b.name.starts_with("rail#"))
            .map(|b| b.mass_rate_mg_per_h)
            .sum::<f64>()
            / n as f64;
        t.row(vec![
            Cell::text(name),
            Cell::Int(n as u64),
            Cell::text("one integrator per missile (default)"),
            Cell::Int(report.integrator.accepted),
            Cell::Int(report.integrator.rhs_evals),
            Cell::Num(cpu),
            Cell::Num(per),
            Cell::Num(per / base),
            Cell::Num(simulated / cpu.max(1e-9)),
            Cell::Num(rail_wear),
        ]);
        if monolithic {
            eprintln!("missiles: {name} ({n} missiles), one integrator for all ...");
            let model = build(&case, configs_dir)?;
            let options = run_options(&case)?;
            let parts = independent_parts(&model.system).len();
            let mut y = model.initial_state.clone();
            let cpu0 = thread_cpu_s();
            let stats = simulate(
                &model.system,
                &mut y,
                0.0,
                model.end_time_s,
                options.integrator,
                options.limits,
                &RunControl::silent(),
                &mut |_| {},
            )
            .map_err(|e| anyhow!("{name} monolithic: {e}"))?;
            let cpu = thread_cpu_s()
                .zip(cpu0)
                .map(|(b, a)| b - a)
                .unwrap_or(stats.wall_s);
            let per = cpu / n as f64;
            let base = *one_mono.get_or_insert(per);
            t.row(vec![
                Cell::text(name),
                Cell::Int(n as u64),
                Cell::text(format!(
                    "one integrator for all {parts} independent parts (no wear, no tracks)"
                )),
                Cell::Int(stats.integrator.accepted),
                Cell::Int(stats.integrator.rhs_evals),
                Cell::Num(cpu),
                Cell::Num(per),
                Cell::Num(per / base),
                Cell::Num(simulated / cpu.max(1e-9)),
                Cell::text("-"),
            ]);
        }
    }
    t.note(format!(
        "settle {settle} s + window {window} s; CPU s = this thread's user + system time (10 ms \
         ticks); the target is per missile / 1 missile within 1.15 (issue 16)"
    ));
    t.note(
        "the stations are translated copies of launcher-design's rail driven by one translating \
         launcher motion: the missiles see the same excitation and differ only by rounding, \
         which the chaotic impacts amplify",
    );
    t.note(machine_note());
    Ok(vec![t])
}
