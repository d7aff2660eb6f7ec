//! `load`: reports under GET load from HTTP/1.1 keep-alive clients, one connection per task.

use super::*;

use railwear_testkit::{Client, ClientError, Request, ServerProcess, TempDir};

/// One request as `token` on a kept connection (the testkit's client, on reqwest): status and
/// body.
async fn call(
    conn: &Client,
    method: &str,
    path: &str,
    token: &str,
    body: Option<&str>,
) -> std::result::Result<(u16, Vec<u8>), ClientError> {
    let mut request = Request::new(method, path).bearer(token);
    if let Some(body) = body {
        request = request.json(body);
    }
    let response = conn.send(&request).await?;
    Ok((response.status, response.body))
}

pub(crate) fn percentile(sorted: &[u64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i.min(sorted.len() - 1)] as f64
}

/// The server process and its database directory (the process is killed first on drop).
pub(crate) struct Server {
    pub(crate) process: ServerProcess,
    pub(crate) _dir: TempDir,
}

pub(crate) fn start_server(bin: &Path, configs_dir: &Path, tokens: &str) -> Result<Server> {
    if !bin.exists() {
        bail!(
            "{} not found: build it first (cargo build --release)",
            bin.display()
        );
    }
    let dir = TempDir::new("bench")?;
    let mut cmd = railwear_testkit::serve_command(bin, &dir.db_url(), tokens, configs_dir);
    cmd.args(["--workers", "2"]);
    let process = ServerProcess::spawn(cmd, Duration::from_secs(60))
        .with_context(|| format!("starting {}", bin.display()))?;
    Ok(Server { process, _dir: dir })
}

pub(crate) fn json_body(b: &[u8]) -> Value {
    serde_json::from_slice(b).unwrap_or(Value::Null)
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn load(
    configs_dir: &Path,
    bin: &Path,
    rails: usize,
    concurrency: usize,
    seconds: f64,
    curve: bool,
    client_threads: usize,
) -> Result<Vec<Table>> {
    if rails == 0
        || concurrency == 0
        || !(seconds.is_finite() && seconds > 0.0)
        || client_threads == 0
    {
        bail!("--rails, --concurrency, --client-threads >= 1 and --seconds > 0");
    }
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    let planner = format!("bench-planner-{stamp:x}");
    let engineer = format!("bench-engineer-{stamp:x}");
    let tokens = format!("bench-p:planner:{planner},bench-e:engineer:{engineer}");
    let configs_abs = std::fs::canonicalize(configs_dir).unwrap_or(configs_dir.to_path_buf());
    let server = start_server(bin, &configs_abs, &tokens)?;
    eprintln!("load: server at {}", server.process.addr());
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(client_threads)
        .enable_all()
        .build()?;
    let addr = server.process.addr().to_string();
    let result = rt.block_on(load_async(
        addr,
        planner,
        engineer,
        rails,
        concurrency,
        seconds,
        curve,
    ));
    drop(server);
    result
}

async fn load_async(
    addr: String,
    planner: String,
    engineer: String,
    rails: usize,
    concurrency: usize,
    seconds: f64,
    curve: bool,
) -> Result<Vec<Table>> {
    let mut notes = Vec::new();
    let conn = Client::keep_alive(&addr)?;
    // Optional short sweep so that reports compute K_SL from a stored curve.
    let mut curve_text = "none (reports answer `missing_curve`)".to_string();
    if curve {
        eprintln!("load: short sweep job for a penalization curve ...");
        let body = json!({"kind": "sweep", "params": {
            "config": "launcher-design", "points": 3,
            "overrides": {"simulation": {"settle_s": 0.1, "duration_s": 0.1, "record_interval_s": 0.01}}}})
        .to_string();
        let (st, b) = call(&conn, "POST", "/v1/jobs", &engineer, Some(&body)).await?;
        let id = json_body(&b)
            .get("id")
            .and_then(Value::as_str)
            .map(str::to_string);
        match id {
            Some(id) if st < 300 => {
                let t0 = Instant::now();
                loop {
                    tokio::time::sleep(Duration::from_millis(500)).await;
                    let (_, b) =
                        call(&conn, "GET", &format!("/v1/jobs/{id}"), &engineer, None).await?;
                    let status = json_body(&b)
                        .get("status")
                        .and_then(Value::as_str)
                        .unwrap_or("")
                        .to_string();
                    if status == "succeeded" {
                        curve_text = format!(
                            "3-point sweep job (0.1 s + 0.1 s per point) done in {:.0} s",
                            t0.elapsed().as_secs_f64()
                        );
                        break;
                    }
                    if status == "failed" || status == "cancelled" {
                        curve_text = format!("sweep job {status}; reports answer `missing_curve`");
                        break;
                    }
                    if t0.elapsed() > Duration::from_secs(600) {
                        curve_text =
                            "sweep job not done in 600 s; reports answer `missing_curve`".into();
                        break;
                    }
                }
            }
            _ => curve_text = format!("sweep submission answered {st}"),
        }
    }
    // Store the rails concurrently.
    eprintln!("load: storing {rails} rails ...");
    let offsets = railwear::pipeline::sweep_offsets_mm(11);
    let t_store = Instant::now();
    let next = Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let mut tasks = Vec::new();
    for _ in 0..concurrency.min(16) {
        let next = next.clone();
        let planner = planner.clone();
        let offsets = offsets.clone();
        // One client per task: its one kept connection.
        let c = Client::keep_alive(&addr)?;
        tasks.push(tokio::spawn(async move {
            let mut failures = 0usize;
            loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= rails {
                    break;
                }
                let dims = LauncherDimensions::design()
                    .with_material_condition(offsets[i % offsets.len()]);
                let body = json!({
                    "dimensions_mm": dims,
                    "measured_by": "railwear-bench",
                    "measured_at": "2024-05-01T08:30:00Z",
                    "location": "loopback",
                })
                .to_string();
                match call(
                    &c,
                    "POST",
                    &format!("/v1/rails/R-{i:05}/measurements"),
                    &planner,
                    Some(&body),
                )
                .await
                {
                    Ok((st, _)) if st < 300 => {}
                    _ => failures += 1,
                }
            }
            failures
        }));
    }
    let mut store_failures = 0;
    for t in tasks {
        store_failures += t.await.unwrap_or(0);
    }
    let store_s = t_store.elapsed().as_secs_f64();
    if store_failures > 0 {
        notes.push(format!("{store_failures} measurement POSTs failed"));
    }
    // Two long simulate jobs.
    let mut job_ids = Vec::new();
    for seed in [1, 2] {
        let body = json!({"kind": "simulate", "params": {"config": "rattle-box-c", "seed": seed,
            "overrides": {"simulation": {"settle_s": 1.0, "duration_s": 3600.0}}}})
        .to_string();
        let (st, b) = call(&conn, "POST", "/v1/jobs", &engineer, Some(&body)).await?;
        match json_body(&b).get("id").and_then(Value::as_str) {
            Some(id) if st < 300 => job_ids.push(id.to_string()),
            _ => notes.push(format!(
                "simulate submission answered {st}: {}",
                String::from_utf8_lossy(&b)
            )),
        }
    }
    // Wait until both run.
    let t_wait = Instant::now();
    let mut running = 0;
    while t_wait.elapsed() < Duration::from_secs(30) {
        running = 0;
        for id in &job_ids {
            let (_, b) = call(&conn, "GET", &format!("/v1/jobs/{id}"), &engineer, None).await?;
            if json_body(&b).get("status").and_then(Value::as_str) == Some("running") {
                running += 1;
            }
        }
        if running == job_ids.len() {
            break;
        }
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    // A sample report.
    let (st, b) = call(&conn, "GET", "/v1/rails/R-00000/report", &planner, None).await?;
    let sample = json_body(&b);
    let report_kind = if st != 200 {
        format!("status {st}")
    } else if sample.get("service_life").is_some_and(|v| !v.is_null()) {
        "K_SL and penalized life from the stored curve".to_string()
    } else {
        "rattle space + missing_curve".to_string()
    };
    // The GET load.
    eprintln!("load: {concurrency} tasks x {seconds} s of GET reports ...");
    let deadline = Instant::now() + Duration::from_secs_f64(seconds);
    let t_load = Instant::now();
    let mut tasks = Vec::new();
    for k in 0..concurrency {
        let planner = planner.clone();
        // One client per task: its one kept connection.
        let c = Client::keep_alive(&addr)?;
        tasks.push(tokio::spawn(async move {
            let mut lat_us: Vec<u64> = Vec::with_capacity(4096);
            let mut non_ok = 0usize;
            let mut errors = 0usize;
            let mut x: u64 = 0x9E37_79B9_7F4A_7C15 ^ (k as u64 + 1);
            while Instant::now() < deadline {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let i = (x % rails as u64) as usize;
                let t = Instant::now();
                match call(
                    &c,
                    "GET",
                    &format!("/v1/rails/R-{i:05}/report"),
                    &planner,
                    None,
                )
                .await
                {
                    Ok((200, _)) => lat_us.push(t.elapsed().as_micros() as u64),
                    Ok(_) => {
                        non_ok += 1;
                        lat_us.push(t.elapsed().as_micros() as u64);
                    }
                    Err(_) => errors += 1,
                }
            }
            (lat_us, non_ok, errors)
        }));
    }
    let mut lat = Vec::new();
    let mut non_ok = 0;
    let mut errors = 0;
    for t in tasks {
        if let Ok((l, n, e)) = t.await {
            lat.extend(l);
            non_ok += n;
            errors += e;
        }
    }
    let load_s = t_load.elapsed().as_secs_f64();
    lat.sort_unstable();
    // Still running? Then cancel.
    let mut still = 0;
    for id in &job_ids {
        let (_, b) = call(&conn, "GET", &format!("/v1/jobs/{id}"), &engineer, None).await?;
        if json_body(&b).get("status").and_then(Value::as_str) == Some("running") {
            still += 1;
        }
        let _ = call(
            &conn,
            "POST",
            &format!("/v1/jobs/{id}/cancel"),
            &engineer,
            None,
        )
        .await;
    }
    let mut t = Table::new(
        "Service load: GET /v1/rails/{serial}/report on loopback",
        &[
            ("rails", "rails stored"),
            ("store_posts_per_s", "store POSTs/s"),
            ("simulations_running", "simulations running (start/end)"),
            ("concurrency", "client tasks"),
            ("seconds", "load s"),
            ("gets", "GETs"),
            ("gets_per_s", "GETs/s"),
            ("p50_ms", "p50 ms"),
            ("p99_ms", "p99 ms"),
            ("non_200", "non-200"),
            ("errors", "I/O errors"),
        ],
    );
    t.row(vec![
        Cell::Int(rails as u64),
        Cell::Num(rails as f64 / store_s),
        Cell::text(format!("{running}/{still}")),
        Cell::Int(concurrency as u64),
        Cell::Num(load_s),
        Cell::Int(lat.len() as u64),
        Cell::Num(lat.len() as f64 / load_s),
        Cell::Num(percentile(&lat, 0.50) / 1000.0),
        Cell::Num(percentile(&lat, 0.99) / 1000.0),
        Cell::Int(non_ok as u64),
        Cell::Int(errors as u64),
    ]);
    t.note(format!(
        "server: target/release binary `railwear serve --workers 2`, fresh SQLite file, the two \
         simulations are rattle box C jobs (3600 s windows, cancelled after the load); report content: {report_kind}; curve: {curve_text}"
    ));
    t.note(
        "client: reqwest (HTTP/1.1 keep-alive) on tokio in this process, one connection per task, \
         random serials; client, server and both simulations share the same cores",
    );
    for n in notes {
        t.note(n);
    }
    t.note(machine_note());
    Ok(vec![t])
}
