//! The real `railwear` binary on a free port with a fresh SQLite database, driven with the test client.

use crate::helpers::{wait_for, Binary};
use crate::support::{temp_dir, ADMIN, ENGINEER, PLANNER};
use railwear::jobs::JobStatus;
use std::process::Command;
use std::time::Duration;

#[test]
fn serves_health_metrics_docs_and_enforces_tokens() {
    let dir = temp_dir("bin");
    let server = Binary::start(&dir.db_url(), &[]);
    assert_eq!(server.get("/healthz", None).body, "ok");
    assert_eq!(server.get("/readyz", None).body, "ready");
    let metrics = server.get("/metrics", None);
    assert!(metrics.body.contains("railwear_queue_depth 0"));
    assert!(metrics
        .body
        .contains("railwear_simulated_seconds_per_second"));
    let docs = server.get("/docs", None);
    assert!(docs.body.contains("/v1/openapi.json"));
    let doc = server.get("/v1/openapi.json", None);
    assert_eq!(doc.body, railwear::http::openapi::openapi_json());

    server.get_problem("/v1/jobs", None, 401);
    server.get_problem("/v1/tokens", Some(PLANNER), 403);
    // An admin creates a planner token over HTTP; it works, and is refused once revoked.
    let created = server.post(
        "/v1/tokens",
        Some(ADMIN),
        r#"{"name":"depot-7","role":"planner"}"#,
    );
    assert_eq!(created.status, 201, "{}", created.body);
    let created = created.json();
    let token = created["token"].as_str().unwrap().to_string();
    assert_eq!(server.get("/v1/rails", Some(&token)).status, 200);
    server
        .post("/v1/jobs", Some(&token), r#"{"kind":"sweep","params":{}}"#)
        .problem(403);
    let id = created["id"].as_str().unwrap();
    assert_eq!(
        server
            .delete(&format!("/v1/tokens/{id}"), Some(ADMIN))
            .status,
        204
    );
    server.get_problem("/v1/rails", Some(&token), 401);
}

#[test]
fn unknown_or_unsafe_config_names_are_422_and_store_nothing() {
    let dir = temp_dir("names");
    let server = Binary::start(&dir.db_url(), &[]);
    for name in ["../../etc/passwd", "no-such-model", ""] {
        let body = serde_json::json!({"kind": "simulate", "params": {"config": name}}).to_string();
        let p = server.post("/v1/jobs", Some(ENGINEER), &body).problem(422);
        assert_eq!(p["field"], "params.config");
    }
    let p = server
        .post(
            "/v1/jobs",
            Some(ENGINEER),
            r#"{"kind":"simulate","params":{"config":7}}"#,
        )
        .problem(422);
    assert_eq!(p["field"], "params.config");
    let list = server.get("/v1/jobs", Some(ENGINEER)).json();
    assert_eq!(list["items"].as_array().unwrap().len(), 0);
}

#[test]
fn token_create_command_makes_a_working_token() {
    let dir = temp_dir("cli");
    let out = Command::new(env!("CARGO_BIN_EXE_railwear"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["token", "create", "--role", "engineer", "--name", "ci"])
        .env("DATABASE_URL", dir.db_url())
        .output()
        .expect("run railwear token create");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let token = String::from_utf8_lossy(&out.stdout).trim().to_string();
    assert!(token.starts_with("rw_"));
    let bad = Command::new(env!("CARGO_BIN_EXE_railwear"))
        .args(["token", "create", "--role", "pilot"])
        .env("DATABASE_URL", dir.db_url())
        .output()
        .unwrap();
    assert!(!bad.status.success());

    let server = Binary::start(&dir.db_url(), &[]);
    let r = server.get("/v1/jobs", Some(&token));
    assert_eq!(r.status, 200, "{}", r.body);
}

/// Request body of a short simulate job of rattle-box case C.
const SHORT_SIMULATE: &str = r#"{"kind":"simulate","params":{"config":"rattle-box-c","seed":11,"overrides":{"simulation":{"settle_s":0.5,"duration_s":0.5}}}}"#;

#[test]
fn simulate_job_succeeds_with_results_and_tracks_csv() {
    let dir = temp_dir("sim");
    let server = Binary::start(&dir.db_url(), &[]);
    let id = server.submit_job(SHORT_SIMULATE);
    let job = server.wait_job(&id, JobStatus::Succeeded, Duration::from_secs(300));
    assert!(job.track_samples > 0);
    let result = server.get(&format!("/v1/jobs/{id}/result"), Some(ENGINEER));
    assert_eq!(result.status, 200);
    assert!(result.json()["summary"].is_object());
    let csv = server.get(&format!("/v1/jobs/{id}/tracks?format=csv"), Some(ENGINEER));
    let lines: Vec<&str> = csv.body.lines().collect();
    assert_eq!(lines[0], railwear::physics::track::TrackSample::CSV_HEADER);
    assert_eq!(lines.len() as i64, 1 + job.track_samples);
}

#[test]
fn sigkill_mid_job_then_restart_completes_once_with_the_same_result() {
    // Reference: uninterrupted run of the same seed.
    let ref_dir = temp_dir("ref");
    let reference = Binary::start(&ref_dir.db_url(), &[]);
    let ref_id = reference.submit_job(SHORT_SIMULATE);
    reference.wait_job(&ref_id, JobStatus::Succeeded, Duration::from_secs(300));
    let ref_csv = reference
        .get(&format!("/v1/jobs/{ref_id}/tracks"), Some(ENGINEER))
        .body;
    let ref_result = reference
        .get(&format!("/v1/jobs/{ref_id}/result"), Some(ENGINEER))
        .json();
    drop(reference);

    let dir = temp_dir("crash");
    let env = [("RAILWEAR_LEASE_S", "2"), ("RAILWEAR_HEARTBEAT_S", "0.5")];
    let server = Binary::start(&dir.db_url(), &env);
    let id = server.submit_job(SHORT_SIMULATE);
    server.wait_job(&id, JobStatus::Running, Duration::from_secs(60));
    server.kill9();

    let server = Binary::start(&dir.db_url(), &env);
    let job = server.wait_job(&id, JobStatus::Succeeded, Duration::from_secs(300));
    assert_eq!(job.attempt, 2, "exactly one re-run");
    let csv = server
        .get(&format!("/v1/jobs/{id}/tracks"), Some(ENGINEER))
        .body;
    let result = server
        .get(&format!("/v1/jobs/{id}/result"), Some(ENGINEER))
        .json();
    assert_eq!(csv, ref_csv);
    assert_eq!(result["summary"], ref_result["summary"]);
    let list = server.get("/v1/jobs", Some(ENGINEER)).json();
    assert_eq!(list["items"].as_array().unwrap().len(), 1);
}

#[test]
fn cancel_a_running_simulation() {
    let dir = temp_dir("bincancel");
    let server = Binary::start(&dir.db_url(), &[]);
    let long = r#"{"kind":"simulate","params":{"config":"rattle-box-c","seed":3,"overrides":{"simulation":{"duration_s":600}}}}"#;
    let id = server.submit_job(long);
    server.wait_job(&id, JobStatus::Running, Duration::from_secs(60));
    let asked = std::time::Instant::now();
    server.cancel_job(&id);
    server.wait_job(&id, JobStatus::Cancelled, Duration::from_secs(5));
    assert!(asked.elapsed() < Duration::from_millis(1500));
}

/// SIGTERM to `server`; returns how long it took to exit (panics after 30 s).
fn sigterm(server: &mut Binary) -> Duration {
    let asked = std::time::Instant::now();
    let status = Command::new("kill")
        .args(["-TERM", &server.process.id().to_string()])
        .status()
        .expect("run kill");
    assert!(status.success());
    loop {
        if let Some(exit) = server.process.child_mut().try_wait().expect("try_wait") {
            assert!(exit.success(), "exit status {exit}");
            eprintln!("exited {:?} after SIGTERM", asked.elapsed());
            return asked.elapsed();
        }
        assert!(
            asked.elapsed() < Duration::from_secs(30),
            "no exit after SIGTERM"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn attempt_outcomes(server: &Binary, id: &str) -> Vec<String> {
    let r = server.get(&format!("/v1/jobs/{id}/attempts"), Some(ENGINEER));
    assert_eq!(r.status, 200, "{}", r.body);
    r.json()
        .as_array()
        .expect("attempts")
        .iter()
        .map(|a| a["outcome"].as_str().unwrap_or("?").to_string())
        .collect()
}

/// Issue 17: SIGTERM with a 600 s simulation running: the process exits within the grace, the
/// job is queued again at once (not left running on a dead worker for the lease), its attempt
/// logged `released`.
#[test]
fn sigterm_gives_a_running_simulation_back_and_exits_within_the_grace() {
    let dir = temp_dir("sigterm");
    let env = [
        ("RAILWEAR_SHUTDOWN_GRACE_S", "2"),
        ("RAILWEAR_LEASE_S", "60"),
        ("RAILWEAR_WORKERS", "1"),
    ];
    let mut server = Binary::start(&dir.db_url(), &env);
    let long = r#"{"kind":"simulate","params":{"config":"rattle-box-c","seed":3,"overrides":{"simulation":{"duration_s":600}}}}"#;
    let id = server.submit_job(long);
    server.wait_job(&id, JobStatus::Running, Duration::from_secs(60));
    let took = sigterm(&mut server);
    assert!(took < Duration::from_secs(2 + 3), "exit took {took:?}");
    drop(server);

    // An API-only process reads the store: queued at once, the attempt released.
    let api = Binary::start_with_args(&dir.db_url(), &env, &["--no-workers"]);
    let j = api.job(&id);
    assert_eq!(j.status, JobStatus::Queued, "{j:?}");
    assert_eq!(j.worker, None);
    assert_eq!(attempt_outcomes(&api, &id), ["released"]);
    // The simulation stopped with a checkpoint, stored before the release.
    let attempts = api
        .get(&format!("/v1/jobs/{id}/attempts"), Some(ENGINEER))
        .json();
    let checkpoint_s = attempts[0]["checkpoint_s"].as_f64();
    assert!(
        checkpoint_s.is_some_and(|t| (0.0..602.0).contains(&t)),
        "{attempts}"
    );
    assert_eq!(
        j.progress.map(|p| p.simulated_time_s),
        checkpoint_s,
        "{j:?}"
    );
}

/// Issue 17: SIGTERM in the middle of a real sweep (one worker, three points), then a
/// restart: the points finished before the shutdown are kept (the sweep-level checkpoint), the
/// point that was running is given back (with its mid-run checkpoint, from which the next
/// worker resumes it, or, without one, to be re-run from its start with its seed), and the
/// sweep's result equals bit for bit the sequential uninterrupted sweep.
#[test]
fn sigterm_mid_sweep_then_restart_gives_the_uninterrupted_result() {
    let params = serde_json::json!({
        "config": "launcher-design",
        "points": 3,
        "seeds": 1,
        "seed": 31,
        "overrides": {"simulation": {"settle_s": 0.2, "duration_s": 0.3, "record_interval_s": 0.01}},
    });
    let reference = {
        let params = params.clone();
        std::thread::spawn(move || {
            let configs = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
            railwear::pipeline::sweep_job(
                &params,
                &configs,
                &railwear::pipeline::RunControl::silent(),
            )
            .expect("sequential sweep")
            .0
        })
    };
    let dir = temp_dir("sigterm-sweep");
    let env = [
        ("RAILWEAR_SHUTDOWN_GRACE_S", "5"),
        ("RAILWEAR_LEASE_S", "60"),
        ("RAILWEAR_WORKERS", "1"),
    ];
    let mut server = Binary::start(&dir.db_url(), &env);
    let body = serde_json::json!({"kind": "sweep", "params": params}).to_string();
    let id = server.submit_job(&body);
    // Stop while one point is done and another runs.
    let done_before: Vec<String> = wait_for(Duration::from_secs(300), "a point done", || {
        let kids = server.children(&id);
        let done: Vec<String> = kids
            .iter()
            .filter(|c| c.status == JobStatus::Succeeded)
            .map(|c| c.id.to_string())
            .collect();
        let running = kids.iter().any(|c| c.status == JobStatus::Running);
        (!done.is_empty() && running).then_some(done)
    });
    let took = sigterm(&mut server);
    assert!(took < Duration::from_secs(5 + 3), "exit took {took:?}");
    drop(server);

    let server = Binary::start(&dir.db_url(), &env);
    let done = server.wait_job(&id, JobStatus::Succeeded, Duration::from_secs(300));
    assert_eq!(done.children.map(|c| c.succeeded), Some(3));
    let result = server
        .get(&format!("/v1/jobs/{id}/result"), Some(ENGINEER))
        .json();
    assert_eq!(
        result["summary"],
        reference.join().expect("reference"),
        "bit for bit the uninterrupted sweep"
    );
    let mut released = 0;
    for kid in server.children(&id) {
        let kid_id = kid.id.to_string();
        let log = attempt_outcomes(&server, &kid_id);
        if done_before.contains(&kid_id) {
            assert_eq!(log, ["succeeded"], "kept, not re-run");
        }
        released += log.iter().filter(|o| *o == "released").count();
        assert_eq!(log.last().map(String::as_str), Some("succeeded"));
    }
    assert!(released >= 1, "the running point was given back");
}

/// Issue 17: after a crash (SIGKILL) the restarted service, on the same host, re-queues the
/// dead process's running job at once instead of after the 60 s lease.
#[test]
fn a_restarted_service_releases_its_dead_predecessors_job_at_once() {
    let dir = temp_dir("restart");
    let env = [("RAILWEAR_LEASE_S", "60"), ("RAILWEAR_WORKERS", "1")];
    let server = Binary::start(&dir.db_url(), &env);
    let long = r#"{"kind":"simulate","params":{"config":"rattle-box-c","seed":4,"overrides":{"simulation":{"duration_s":600}}}}"#;
    let id = server.submit_job(long);
    server.wait_job(&id, JobStatus::Running, Duration::from_secs(60));
    server.kill9();

    let restarted = std::time::Instant::now();
    let server = Binary::start(&dir.db_url(), &env);
    let j = server.wait_job_until(&id, "attempt 2 running", Duration::from_secs(10), |j| {
        j.status == JobStatus::Running && j.attempt == 2
    });
    assert!(restarted.elapsed() < Duration::from_secs(15));
    assert_eq!(attempt_outcomes(&server, &id), ["lost", "running"], "{j:?}");
    server.cancel_job(&id);
}
