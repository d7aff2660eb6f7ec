//! `sweep-procs`: a fanned-out sweep on PostgreSQL with 1 and 2 worker processes.

use super::*;

/// CPU time of this process's reaped children (user + system), s, from /proc/self/stat
/// (`cutime`, `cstime` in USER_HZ ticks, 100 per second on Linux).
pub(crate) fn reaped_children_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name `(...)`: state is field 3, cutime 16, cstime 17.
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<f64>().ok();
    Some((ticks(13)? + ticks(14)?) / 100.0)
}

/// Worker processes, killed (SIGKILL) and reaped on drop.
pub(crate) struct Workers(Vec<std::process::Child>);

impl Drop for Workers {
    fn drop(&mut self) {
        for child in &mut self.0 {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

pub(crate) fn sweep_procs(
    configs_dir: &Path,
    bin: &Path,
    admin_url: &str,
    points: u64,
    settle: f64,
    window: f64,
) -> Result<Vec<Table>> {
    if !(settle >= 0.0 && window > 0.0 && (2..=50).contains(&points)) {
        bail!("--settle >= 0, --window > 0, --points in 2..=50");
    }
    if !bin.exists() {
        bail!(
            "{} not found: build it first (cargo build --release)",
            bin.display()
        );
    }
    let configs_abs = std::fs::canonicalize(configs_dir).unwrap_or(configs_dir.to_path_buf());
    let params = json!({
        "config": "launcher-design",
        "points": points,
        "seed": 6,
        "overrides": {"simulation": {
            "settle_s": settle,
            "duration_s": window,
            "record_interval_s": window.min(5e-4),
        }},
    });
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()?;
    // A database created beside the admin connection's, dropped at the end (testkit).
    let db = rt
        .block_on(railwear_testkit::ThrowawayDb::create(
            admin_url,
            "railwear_bench",
        ))
        .with_context(|| format!("creating a database through {admin_url}"))?;
    let store = rt.block_on(railwear::store::open(&db.url))?;
    // Submissions go through the job system as an API process would (no workers here).
    let jobs = railwear::jobs::Jobs::new(
        Arc::clone(&store),
        Arc::new(railwear::jobs::LibraryRunner::new(configs_abs.clone())),
        railwear::jobs::WorkerSettings {
            lease: Duration::from_secs(15),
            heartbeat: Duration::from_secs(1),
            poll: Duration::from_millis(100),
            max_attempts: 3,
            track_block_samples: 4096,
            record_chunk_samples: 8192,
            shutdown_grace: Duration::from_secs(5),
        },
        railwear::jobs::CurveDefaults {
            vehicle_profile: "ah64".into(),
            environment: railwear::pipeline::DEFAULT_ENVIRONMENT.into(),
            wear_law: "modified-archard".into(),
        },
    );
    let mut t = Table::new(
        format!(
            "Fanned-out sweep on PostgreSQL ({points}-point sweep job of launcher-design, settle {settle} s + window {window} s per point, one `railwear worker --workers 1` per process)"
        ),
        &[
            ("worker_processes", "worker processes"),
            ("points", "sweep points"),
            ("runs", "child jobs (points x seeds)"),
            ("wall_s", "wall s"),
            ("simulations_per_min", "simulations/min"),
            ("ratio", "ratio to 1 process"),
            ("cores_used", "worker CPU s / wall s"),
            ("points_per_process", "points run per process"),
        ],
    );
    let mut base: Option<f64> = None;
    let mut summaries = Vec::new();
    for procs in [1usize, 2] {
        eprintln!("sweep-procs: {procs} worker process(es) ...");
        let submitted = rt.block_on(jobs.submit(
            railwear::jobs::JobKind::Sweep,
            params.clone(),
            "bench",
            None,
        ));
        let id = match submitted {
            Ok(railwear::store::Submitted::Created(job)) => job.id,
            Ok(other) => bail!("unexpected submission answer {other:?}"),
            Err(e) => bail!("submission refused: {e}"),
        };
        let cpu_before = reaped_children_cpu_s();
        let start = Instant::now();
        let mut workers = Workers(Vec::new());
        for _ in 0..procs {
            let child = std::process::Command::new(bin)
                .args(["worker", "--database-url", &db.url, "--workers", "1"])
                .env("RAILWEAR_CONFIGS_DIR", &configs_abs)
                .env("RUST_LOG", "warn")
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::inherit())
                .spawn()
                .with_context(|| format!("starting {}", bin.display()))?;
            workers.0.push(child);
        }
        let job = loop {
            std::thread::sleep(Duration::from_millis(100));
            let job = rt
                .block_on(store.get_job(id))?
                .ok_or_else(|| anyhow!("job {id} vanished"))?;
            if job.status.is_terminal() {
                break job;
            }
            if start.elapsed() > Duration::from_secs(3600) {
                bail!("sweep {id} not done within an hour");
            }
        };
        let wall = start.elapsed().as_secs_f64();
        drop(workers);
        let cores_used = match (cpu_before, reaped_children_cpu_s()) {
            (Some(a), Some(b)) => Some((b - a) / wall),
            _ => None,
        };
        // Which process ran each point (the succeeded attempt's lease owner, `<host>-<pid>-0`).
        let mut per_worker: std::collections::BTreeMap<String, u64> = Default::default();
        for child in rt.block_on(store.children(id))? {
            for a in rt.block_on(store.attempts(child.id))? {
                if a.outcome == railwear::store::AttemptOutcome::Succeeded {
                    *per_worker.entry(a.worker).or_default() += 1;
                }
            }
        }
        let spread = per_worker
            .values()
            .map(u64::to_string)
            .collect::<Vec<_>>()
            .join(" + ");
        if job.status != railwear::jobs::JobStatus::Succeeded {
            bail!(
                "sweep {id} ended {}: {}",
                job.status.as_str(),
                job.error.unwrap_or_default()
            );
        }
        summaries.push(job.result);
        // Each point runs once per seed: the child jobs are the simulations.
        let runs: u64 = per_worker.values().sum();
        let per_min = runs as f64 / wall * 60.0;
        let ratio = base.map(|b| per_min / b).unwrap_or(1.0);
        base.get_or_insert(per_min);
        t.row(vec![
            Cell::Int(procs as u64),
            Cell::Int(points),
            Cell::Int(runs),
            Cell::Num(wall),
            Cell::Num(per_min),
            Cell::Num(ratio),
            Cell::opt(cores_used),
            Cell::text(spread),
        ]);
    }
    t.note(format!(
        "wall: from starting the worker processes to the sweep's assembled result (fan-out, \
         its child jobs, assembly); the two runs' results are {}",
        if summaries.windows(2).all(|w| w[0] == w[1]) {
            "identical"
        } else {
            "DIFFERENT"
        }
    ));
    t.note(
        "2 processes can reach 2x only with 2 idle cores: `worker CPU s / wall s` is how many \
         cores the worker processes got (the rest went to other load on the machine)",
    );
    t.note(machine_note());
    drop(store);
    drop(jobs);
    drop(rt);
    drop(db);
    Ok(vec![t])
}
