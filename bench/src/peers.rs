//! `peers`: railwear beside MuJoCo and Drake on rattle box C (bench/peers).

use super::*;

/// railwear's extra rows beside the engine variants: the default engine at these factors on
/// the case tolerance, at `points_per_edge` contact points per box edge (None: the case's).
pub(crate) struct ExtraRuns {
    pub(crate) tolerance_factors: Vec<f64>,
    pub(crate) points_per_edge: Option<usize>,
    /// Timed runs of each railwear row; the fastest is reported, as the peers' timing keeps
    /// the best of its repeats (run_peers.sh gets the same count).
    pub(crate) repeats: usize,
}

pub(crate) fn peers(
    configs_dir: &Path,
    with_peers: bool,
    peers_json: Option<&Path>,
    settle: f64,
    window: f64,
    peer_args: &str,
    extra: &ExtraRuns,
) -> Result<Vec<Table>> {
    let points_per_edge = extra.points_per_edge;
    let repeats = extra.repeats.max(1);
    let mut peer_rows: Vec<Value> = Vec::new();
    let mut notes = Vec::new();
    if with_peers {
        let script = Path::new("bench/peers/run_peers.sh");
        let mut cmd = std::process::Command::new("bash");
        cmd.arg(script)
            .args([
                "--window",
                &window.to_string(),
                "--settle",
                &settle.to_string(),
                "--repeats",
                &repeats.to_string(),
            ])
            .args(peer_args.split_whitespace())
            .stderr(std::process::Stdio::inherit());
        eprintln!("peers: running {} (MuJoCo, Drake) ...", script.display());
        let out = cmd.output().context("running bench/peers/run_peers.sh")?;
        if !out.status.success() {
            notes.push(format!("run_peers.sh exited with {}", out.status));
        }
        peer_rows.extend(parse_json_lines(&String::from_utf8_lossy(&out.stdout)));
        notes.push(format!(
            "peers measured in this run by bench/peers/run_peers.sh --window {window} --settle {settle} --repeats {repeats} {peer_args}"
        ));
    } else if let Some(path) = peers_json {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        peer_rows.extend(parse_json_lines(&text));
        notes.push(format!(
            "peer rows read from {} (an earlier run), not measured in this run",
            path.display()
        ));
    } else {
        notes.push("no peer rows: pass --with-peers (or --peers-json FILE)".into());
    }
    // railwear in each engine variant (the default first), so the engine changes are measured
    // in the same run as the peers; then the default at each further tolerance factor and
    // point count (the converged settings of `convergence --ladder`).
    let mut ours_rows = Vec::new();
    let factors = extra
        .tolerance_factors
        .iter()
        .copied()
        .filter(|f| *f != 1.0 || points_per_edge.is_some());
    let runs: Vec<(&EngineVariant, f64)> = ENGINE_VARIANTS
        .iter()
        .map(|v| (v, 1.0))
        .chain(factors.map(|f| (&ENGINE_VARIANTS[0], f)))
        .collect();
    for (i, (variant, factor)) in runs.into_iter().enumerate() {
        // The engine variants run the case as it is; the extra rows at the asked points.
        let points = if i < ENGINE_VARIANTS.len() {
            None
        } else {
            points_per_edge
        };
        eprintln!(
            "peers: railwear rattle box C ({}, tolerance x {factor}, points per edge {points:?}) ...",
            variant.name
        );
        let (case, model, mut options) =
            rattle_box_c_points(configs_dir, settle, window, IntegratorKind::Trbdf2, points)?;
        let points = case.simulation.contact_points_per_edge;
        options.integrator.newton = variant.newton;
        options.integrator.patches = variant.patches;
        options.integrator.tolerances = options.integrator.tolerances.scaled(factor);
        // The same deterministic run `repeats` times: the results are the first run's, the
        // wall and CPU times the fastest (the peers' protocol: best of their repeats).
        let mut timed: Option<(RunReport, Option<f64>)> = None;
        for _ in 0..repeats {
            let cpu0 = thread_cpu_s();
            let run = run_model(&model, &options, &RunControl::silent())
                .map_err(|e| anyhow!("railwear rattle box C: {e}"))?;
            let cpu = thread_cpu_s().zip(cpu0).map(|(b, a)| b - a);
            timed = Some(match timed {
                None => (run, cpu),
                Some((mut first, best_cpu)) => {
                    if run.integrator.accepted != first.integrator.accepted {
                        return Err(anyhow!(
                            "railwear rattle box C: a repeat took {} accepted steps, the first {} \
                             (the run is meant to be deterministic)",
                            run.integrator.accepted,
                            first.integrator.accepted
                        ));
                    }
                    first.wall_s = first.wall_s.min(run.wall_s);
                    let cpu = match (best_cpu, cpu) {
                        (Some(a), Some(b)) => Some(a.min(b)),
                        (a, b) => a.or(b),
                    };
                    (first, cpu)
                }
            });
        }
        let (run, cpu) = timed.ok_or_else(|| anyhow!("railwear rattle box C: no run"))?;
        ours_rows.push((
            variant,
            (factor, points),
            model.end_time_s,
            options,
            run,
            cpu,
        ));
    }
    let rw_rtf = ours_rows[0].2 / ours_rows[0].4.wall_s.max(1e-9);
    // Per tolerance factor and point count of the default variant: ((factor, points), wall
    // RTF, CPU RTF).
    let ours_by_factor: Vec<((f64, usize), f64, Option<f64>)> = ours_rows
        .iter()
        .filter(|r| r.0.name == ENGINE_VARIANTS[0].name)
        .map(|(_, f, end, _, run, cpu)| {
            (
                *f,
                end / run.wall_s.max(1e-9),
                cpu.map(|c| end / c.max(1e-9)),
            )
        })
        .collect();
    let mut table = Table::new(
        format!("Rattle box case C side by side (settle {settle} s, window {window} s, one run, best of {repeats} timings)"),
        &[
            ("engine", "engine"),
            ("contact_law", "contact law"),
            ("step_or_tolerance", "step or tolerance"),
            ("real_time_factor", "real-time factor"),
            ("real_time_factor_cpu", "real-time factor (CPU time)"),
            ("steps_per_s", "steps/s"),
            ("mean_normal_force_n", "mean normal force N"),
            ("mean_normal_slip_power_w", "mean N·\\|v_slip\\| W"),
            ("ratio_vs_mujoco", "railwear RTF / this RTF"),
        ],
    );
    for (variant, settings, end_time_s, options, run, cpu) in &ours_rows {
        let rtf = end_time_s / run.wall_s.max(1e-9);
        let newton_name = variant.name;
        table.row(vec![
            Cell::text(format!("railwear {}", env!("CARGO_PKG_VERSION"))),
            Cell::text("IMPACT eq. 2.1-2.3, Table 5.2 (k 1000 N/mm², e 2, c_max 500 N·s/mm, d 0.01 mm); ADAMS friction eq. 4.5"),
            Cell::text(format!(
                "trbdf2 {}, {newton_name}, {} points per edge",
                tolerance_text(&options.integrator.tolerances),
                settings.1
            )),
            Cell::Num(rtf),
            Cell::opt(cpu.map(|c| end_time_s / c.max(1e-9))),
            Cell::Num(run.integrator.accepted as f64 / run.wall_s.max(1e-9)),
            Cell::Num(run.mean_normal_force_n),
            Cell::Num(run.mean_normal_slip_power_w),
            Cell::Num(rw_rtf / rtf),
        ]);
    }
    let mut mujoco_best: Option<f64> = None;
    let mut mujoco_converged: Option<f64> = None;
    let mut mujoco_converged_cpu: Option<f64> = None;
    for p in &peer_rows {
        let engine = p.get("engine").and_then(Value::as_str).unwrap_or("?");
        let status = p.get("status").and_then(Value::as_str);
        if let Some(st) = status {
            let reason = p.get("reason").and_then(Value::as_str).unwrap_or("");
            table.row(vec![
                Cell::text(engine),
                Cell::text(format!("{st}: {reason}")),
                Cell::text(
                    p.get("step_s")
                        .and_then(Value::as_f64)
                        .map(|s| format!("step {s:e} s"))
                        .unwrap_or_else(|| "-".into()),
                ),
                Cell::text("-"),
                Cell::text("-"),
                Cell::text("-"),
                Cell::text("-"),
                Cell::text("-"),
                Cell::text("-"),
            ]);
            continue;
        }
        let f = |k: &str| p.get(k).and_then(Value::as_f64);
        let version = p.get("version").and_then(Value::as_str).unwrap_or("");
        let drive = p.get("drive").and_then(Value::as_str).unwrap_or("");
        let mocap = drive.starts_with("mocap");
        let rtf = f("real_time_factor");
        if engine == "mujoco" && !mocap {
            if let Some(r) = rtf {
                mujoco_best = Some(mujoco_best.map_or(r, |b: f64| b.max(r)));
                // The step at which MuJoCo's friction power has converged (issue 5: 5e-5 s).
                if f("step_s").is_some_and(|s| (s - 5e-5).abs() < 1e-12) {
                    mujoco_converged = Some(r);
                    mujoco_converged_cpu = f("real_time_factor_cpu");
                }
            }
        }
        table.row(vec![
            Cell::text(format!(
                "{engine} {version}{}",
                if mocap { " (mocap drive)" } else { "" }
            )),
            Cell::text(p.get("contact_law").and_then(Value::as_str).unwrap_or("?")),
            Cell::text(
                f("step_s")
                    .map(|s| format!("step {s:e} s"))
                    .unwrap_or_else(|| "-".into()),
            ),
            Cell::opt(rtf),
            Cell::opt(f("real_time_factor_cpu")),
            Cell::opt(f("steps_per_s")),
            Cell::opt(f("mean_normal_force_n")),
            Cell::opt(f("mean_normal_slip_power_w")),
            Cell::opt(rtf.filter(|r| *r > 0.0).map(|r| rw_rtf / r)),
        ]);
    }
    for n in notes {
        table.note(n);
    }
    if let Some(m) = mujoco_converged {
        for ((factor, points), wall, cpu) in &ours_by_factor {
            let cpu_ratio = cpu
                .zip(mujoco_converged_cpu)
                .map_or("-".into(), |(a, b)| format!("{:.2}", a / b.max(1e-9)));
            table.note(format!(
                "railwear (case tolerance x {factor}, {points} points per edge) / MuJoCo at its converged 5e-5 s step, real-time factor: \
                 {:.2} wall, {cpu_ratio} CPU (issue 27 target >= 1 at the case's settings; \
                 `convergence --ladder` says which settings are converged)",
                wall / m
            ));
        }
    }
    if let Some(m) = mujoco_best {
        table.note(format!(
            "railwear / MuJoCo (fastest accelerating-frame row, the strictest reading) real-time factor: {:.2}",
            rw_rtf / m
        ));
    }
    table.note(
        "railwear solves the thesis' IMPACT law (near-plastic nanosecond impacts); MuJoCo and Drake \
         use their own softer contact tuned to near-zero rebound (bench/peers/README.md). The \
         rattle is chaotic: window means scatter 10-20 % between engines and settings",
    );
    table.note(format!(
        "railwear's wall time is the whole run (settle + window) in this process, one thread, no \
             track recording; the peers' is their compiled stepping loop (rollout / AdvanceTo); \
             each engine's time is the best of {repeats} runs"
    ));
    table.note(machine_note());
    Ok(vec![table])
}

pub(crate) fn parse_json_lines(text: &str) -> Vec<Value> {
    text.lines()
        .filter_map(|l| serde_json::from_str::<Value>(l.trim()).ok())
        .filter(|v| v.is_object())
        .collect()
}
