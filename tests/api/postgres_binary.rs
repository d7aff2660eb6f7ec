//! The real binary on PostgreSQL: `railwear serve --no-workers` (API only) and separate
//! `railwear worker --database-url ...` processes share one fresh database. A job submitted over
//! HTTP is run by a worker process; a worker killed with SIGKILL mid-job loses its lease and
//! another worker process finishes the job.

use crate::helpers::{wait_for, Api};
use crate::support::{tokens_env, ENGINEER};
use railwear::jobs::{ChildCounts, JobStatus};
use railwear_testkit::ServerProcess;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// A `railwear` process (testkit), killed (SIGKILL) and reaped on drop.
type Proc = ServerProcess;

/// Start `railwear <args>` and wait for a stdout line starting with `ready_prefix`.
fn spawn(args: &[&str], db_url: &str, env: &[(&str, &str)], ready_prefix: &str) -> Proc {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_railwear"));
    cmd.current_dir(root)
        .args(args)
        .env("DATABASE_URL", db_url)
        .env("RAILWEAR_TOKENS", tokens_env())
        .env("RAILWEAR_CONFIGS_DIR", root.join("configs"))
        .env("RUST_LOG", "warn")
        .envs(env.iter().copied());
    ServerProcess::spawn_ready(cmd, ready_prefix, Duration::from_secs(60))
        .unwrap_or_else(|e| panic!("railwear {args:?}: {e}"))
}

/// `railwear serve --no-workers` and a client of it.
fn serve(db_url: &str, env: &[(&str, &str)]) -> (Proc, Api) {
    let server = spawn(
        &["serve", "--no-workers", "--listen", "127.0.0.1:0"],
        db_url,
        env,
        "listening on ",
    );
    let api = Api::new(&server.base_url());
    (server, api)
}

fn worker(db_url: &str, env: &[(&str, &str)]) -> Proc {
    // The URL comes from the flag: DATABASE_URL is pointed elsewhere to prove the flag wins.
    spawn(
        &["worker", "--database-url", db_url, "--workers", "1"],
        "sqlite://not-used-by-the-worker.db?mode=ro",
        env,
        "workers started: ",
    )
}

/// A very short simulate job of rattle-box case C.
const SHORT: &str = r#"{"kind":"simulate","params":{"config":"rattle-box-c","seed":5,"overrides":{"simulation":{"settle_s":0.05,"duration_s":0.05,"record_interval_s":0.01}}}}"#;

#[test]
fn api_without_workers_and_a_worker_process_complete_a_job() {
    let rt = tokio::runtime::Runtime::new().expect("runtime");
    let Some(db) = rt.block_on(async { crate::support::postgres::create("bin").await }) else {
        return;
    };
    let (_server, api) = serve(&db.url, &[]);
    let id = api.submit_job(SHORT);
    // The API runs no workers: the job stays queued.
    std::thread::sleep(Duration::from_millis(1500));
    assert_eq!(api.job(&id).status, JobStatus::Queued);

    let _worker = worker(&db.url, &[]);
    let done = api.wait_job(&id, JobStatus::Succeeded, Duration::from_secs(300));
    assert_eq!(done.attempt, 1);
    assert!(done.track_samples > 0);
    let result = api.get(&format!("/v1/jobs/{id}/result"), Some(ENGINEER));
    assert_eq!(result.status, 200, "{}", result.body);
    assert!(result.json()["summary"].is_object());
    // Tracks written by the worker process are served by the API process, one CSV row each.
    let csv = api.get(&format!("/v1/jobs/{id}/tracks?format=csv"), Some(ENGINEER));
    assert_eq!(csv.status, 200);
    let lines: Vec<&str> = csv.body.lines().collect();
    assert_eq!(lines[0], railwear::physics::track::TrackSample::CSV_HEADER);
    assert_eq!(lines.len() as i64, 1 + done.track_samples);
    drop(rt);
}

#[test]
fn a_worker_killed_mid_job_loses_its_lease_and_another_worker_finishes() {
    let rt = tokio::runtime::Runtime::new().expect("runtime");
    let Some(db) = rt.block_on(async { crate::support::postgres::create("kill").await }) else {
        return;
    };
    let env = [("RAILWEAR_LEASE_S", "2"), ("RAILWEAR_HEARTBEAT_S", "0.5")];
    let (_server, api) = serve(&db.url, &env);
    // Long enough to be caught running (cancelled at the end, so its length costs nothing).
    let long = r#"{"kind":"simulate","params":{"config":"rattle-box-c","seed":9,"overrides":{"simulation":{"duration_s":600}}}}"#;
    let id = api.submit_job(long);
    let first = worker(&db.url, &env);
    let running = api.wait_job(&id, JobStatus::Running, Duration::from_secs(60));
    assert_eq!(running.attempt, 1);
    drop(first); // SIGKILL: no shutdown code runs, the lease is left to expire

    let _second = worker(&db.url, &env);
    let retaken = api.wait_job_until(&id, "attempt 2", Duration::from_secs(60), |j| {
        j.status == JobStatus::Running && j.attempt == 2
    });
    assert_eq!(
        retaken.error.as_deref(),
        Some("attempt 1 lost its worker (lease expired)"),
        "{retaken:?}"
    );
    // The new owner heartbeats: its cancel request reaches it through the database.
    api.cancel_job(&id);
    let cancelled = api.wait_job(&id, JobStatus::Cancelled, Duration::from_secs(30));
    assert_eq!(cancelled.attempt, 2);
    drop(rt);
}

/// Issue 6, item 1: one API process and three worker processes on PostgreSQL run a 12-point
/// sweep fanned out into 12 child jobs; one worker is killed (SIGKILL) while it holds a child.
/// Every child ends with exactly one succeeded attempt (the killed one is logged lost and its
/// child re-run elsewhere), the sweep is fanned out once and assembled once, and its result
/// equals bit for bit both the same sweep run by a single `railwear serve` process on SQLite
/// (fanned out to its embedded workers) and the sequential in-process `pipeline::sweep_job`.
#[test]
fn a_sweep_fanned_out_to_three_worker_processes_survives_a_killed_worker() {
    use railwear::store::AttemptOutcome;
    let rt = tokio::runtime::Runtime::new().expect("runtime");
    let Some(db) = rt.block_on(async { crate::support::postgres::create("fanout").await }) else {
        return;
    };
    let env = [("RAILWEAR_LEASE_S", "2"), ("RAILWEAR_HEARTBEAT_S", "0.5")];
    let (_server, api) = serve(&db.url, &env);
    let mut workers: Vec<Option<Proc>> = (0..3).map(|_| Some(worker(&db.url, &env))).collect();

    // Short points (under a second each in the test profile).
    let params = serde_json::json!({
        "config": "launcher-design",
        "points": 12,
        "seeds": 1,
        "seed": 2024,
        "overrides": {"simulation": {"settle_s": 0.2, "duration_s": 0.3, "record_interval_s": 0.01}},
    });
    // The single-process reference, computed here while the workers run.
    let reference = {
        let params = params.clone();
        std::thread::spawn(move || {
            let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
            railwear::pipeline::sweep_job(
                &params,
                &configs,
                &railwear::pipeline::RunControl::silent(),
            )
            .expect("sequential sweep")
        })
    };
    let body = serde_json::json!({"kind": "sweep", "params": params}).to_string();
    let id = api.submit_job(&body);
    // The same sweep in one process on SQLite.
    let sqlite_dir = crate::support::temp_dir("fanout-sqlite");
    let single = crate::helpers::Binary::start(&sqlite_dir.db_url(), &[("RAILWEAR_WORKERS", "2")]);
    let single_id = single.submit_job(&body);

    // SIGKILL the worker process that holds a running child.
    let victim_worker = wait_for(Duration::from_secs(120), "a running child", || {
        api.children(&id)
            .into_iter()
            .find(|c| c.status == JobStatus::Running)
            .and_then(|c| c.worker)
    });
    // Worker names are `<host>-<pid>-<n>`.
    let pid: u32 = victim_worker
        .rsplit('-')
        .nth(1)
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("no pid in worker name {victim_worker}"));
    let slot = workers
        .iter()
        .position(|w| w.as_ref().is_some_and(|p| p.id() == pid))
        .unwrap_or_else(|| panic!("worker {victim_worker} is not one of ours"));
    drop(workers[slot].take());

    let done = api.wait_job(&id, JobStatus::Succeeded, Duration::from_secs(300));
    assert_eq!(
        done.children,
        Some(ChildCounts {
            total: 12,
            succeeded: 12,
            failed: 0,
            cancelled: 0
        })
    );
    let kids = api.children(&id);
    assert_eq!(kids.len(), 12);
    assert!(
        kids.iter().all(|c| c.status == JobStatus::Succeeded),
        "{kids:?}"
    );

    let store = rt
        .block_on(railwear::store::open(&db.url))
        .expect("open the test database");
    let id: uuid::Uuid = id.parse().expect("uuid");
    let children = rt.block_on(store.children(id)).expect("children");
    assert_eq!(
        children.iter().map(|c| c.index).collect::<Vec<_>>(),
        (0..12).collect::<Vec<i64>>()
    );
    // Exactly one succeeded attempt per child; every other attempt was lost (fenced out).
    let mut lost = Vec::new();
    for child in &children {
        let attempts = rt.block_on(store.attempts(child.id)).expect("attempts");
        let succeeded: Vec<_> = attempts
            .iter()
            .filter(|a| a.outcome == AttemptOutcome::Succeeded)
            .collect();
        assert_eq!(succeeded.len(), 1, "child {}: {attempts:?}", child.index);
        assert_eq!(succeeded[0].attempt, attempts.len() as i64);
        for a in &attempts[..attempts.len() - 1] {
            assert_eq!(a.outcome, AttemptOutcome::Lost, "{attempts:?}");
            lost.push((child.id, a.worker.clone()));
        }
        assert_ne!(succeeded[0].worker, victim_worker);
    }
    // The child the killed worker held, and only that, was run twice (if the worker had just
    // moved on from the child seen running, the child it moved on to).
    assert_eq!(lost.len(), 1, "{lost:?}");
    assert_eq!(lost[0].1, victim_worker);
    // The same log over HTTP: the re-run child shows the killed worker's lost attempt, then
    // the success by another worker.
    let rerun = api.get_json(&format!("/v1/jobs/{}/attempts", lost[0].0));
    let rows = rerun.as_array().expect("an array of attempts");
    let outcomes: Vec<&str> = rows.iter().filter_map(|a| a["outcome"].as_str()).collect();
    assert_eq!(outcomes, ["lost", "succeeded"], "{rerun}");
    assert_eq!(rows[0]["attempt"], 1);
    assert_eq!(rows[0]["worker"], victim_worker.as_str());
    assert_eq!(rows[1]["attempt"], 2);
    assert_ne!(rows[1]["worker"], victim_worker.as_str());
    assert!(rows[1]["ended_at"].is_string(), "{rerun}");
    // Fanned out once, assembled once.
    let parent_attempts = rt.block_on(store.attempts(id)).expect("attempts");
    assert_eq!(
        parent_attempts
            .iter()
            .map(|a| a.outcome)
            .collect::<Vec<_>>(),
        [AttemptOutcome::FannedOut, AttemptOutcome::Succeeded]
    );

    // The assembled result and the stored curve equal the sequential single-process sweep, and
    // the single-process SQLite service's result.
    let (summary, outcome) = reference.join().expect("reference sweep");
    let job = rt.block_on(store.get_job(id)).expect("job").expect("job");
    let single_done = single.wait_job(&single_id, JobStatus::Succeeded, Duration::from_secs(300));
    assert_eq!(single_done.children.map(|c| c.succeeded), Some(12));
    let single_result = single.get(&format!("/v1/jobs/{single_id}/result"), Some(ENGINEER));
    assert_eq!(single_result.status, 200, "{}", single_result.body);
    assert_eq!(job.result, Some(single_result.json()["summary"].clone()));
    single.kill9();
    let assembled: railwear::pipeline::SweepOutcome =
        serde_json::from_value(job.result.clone().expect("result")).expect("sweep outcome");
    assert_eq!(
        assembled.design_rattle_space.to_bits(),
        outcome.design_rattle_space.to_bits()
    );
    assert_eq!(assembled.points.len(), 12);
    for (a, b) in assembled.points.iter().zip(&outcome.points) {
        assert_eq!(a.offset_mm.map(f64::to_bits), b.offset_mm.map(f64::to_bits));
        assert_eq!(a.rattle_space.to_bits(), b.rattle_space.to_bits());
        assert_eq!(
            a.rail_wear_rate_mg_per_h.to_bits(),
            b.rail_wear_rate_mg_per_h.to_bits(),
            "offset {:?} mm",
            b.offset_mm
        );
    }
    assert_eq!(job.result, Some(summary));
    let curve = rt
        .block_on(railwear::store::latest_curve(
            store.as_ref(),
            job.curve_key.as_deref().expect("curve key"),
        ))
        .expect("curve")
        .expect("curve stored");
    assert_eq!(curve.job_id, id);
    let plan = railwear::pipeline::SweepPlan::from_params(
        &params,
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs"),
    )
    .expect("plan");
    let expected = railwear::jobs::runner::sweep_output(&plan, &params, &outcome).expect("curve");
    assert_eq!(
        Some(curve.curve),
        expected
            .penalization
            .map(|c| serde_json::to_value(c).expect("curve json"))
    );
    drop(store);
    drop(rt);
}

/// Issue 17 on PostgreSQL: SIGTERM to a `railwear worker` running a 600 s simulation makes it
/// exit within its grace and give the job back at once (attempt `released`); a worker started
/// next takes it as attempt 2 without waiting for the 60 s lease.
#[test]
fn sigterm_to_a_worker_process_gives_its_job_back_at_once() {
    let rt = tokio::runtime::Runtime::new().expect("runtime");
    let Some(db) = rt.block_on(async { crate::support::postgres::create("sigterm").await }) else {
        return;
    };
    let env = [
        ("RAILWEAR_LEASE_S", "60"),
        ("RAILWEAR_SHUTDOWN_GRACE_S", "2"),
    ];
    let (_server, api) = serve(&db.url, &env);
    let long = r#"{"kind":"simulate","params":{"config":"rattle-box-c","seed":9,"overrides":{"simulation":{"duration_s":600}}}}"#;
    let id = api.submit_job(long);
    let mut first = worker(&db.url, &env);
    api.wait_job(&id, JobStatus::Running, Duration::from_secs(60));
    let asked = std::time::Instant::now();
    let status = std::process::Command::new("kill")
        .args(["-TERM", &first.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success());
    let exit = loop {
        if let Some(exit) = first.child_mut().try_wait().expect("try_wait") {
            break exit;
        }
        assert!(asked.elapsed() < Duration::from_secs(20), "no exit");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(exit.success(), "{exit}");
    assert!(
        asked.elapsed() < Duration::from_secs(2 + 3),
        "{:?}",
        asked.elapsed()
    );
    let j = api.job(&id);
    assert_eq!(j.status, JobStatus::Queued, "{j:?}");
    let log = api.get_json(&format!("/v1/jobs/{id}/attempts"));
    assert_eq!(log[0]["outcome"], "released", "{log}");

    let _second = worker(&db.url, &env);
    let retaken = api.wait_job(&id, JobStatus::Running, Duration::from_secs(10));
    assert_eq!(retaken.attempt, 2);
    api.cancel_job(&id);
    api.wait_job(&id, JobStatus::Cancelled, Duration::from_secs(30));
    drop(rt);
}
