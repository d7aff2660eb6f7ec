//! Queue semantics over HTTP (curl) against an in-process service whose computations are the
//! counting test runner: idempotency, cancellation, results and track export, recovery of a job
//! whose worker died, rejected inputs leaving stored data unchanged.

use crate::helpers::{curl, get_job, submit_job, wait_for};
use crate::support::runner::{sample, start, test_config};
use crate::support::{temp_dir, ENGINEER, PLANNER};
use serde_json::json;
use std::time::{Duration, Instant};

fn job_count(base: &str) -> usize {
    let r = curl(
        "GET",
        &format!("{base}/v1/jobs?limit=100"),
        Some(ENGINEER),
        &[],
        None,
    );
    r.json()["items"].as_array().map_or(0, Vec::len)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn idempotency_key_gives_one_job() {
    let dir = temp_dir("idem");
    let service = start(test_config(&dir.db_url()), false).await;
    let base = format!("http://{}", service.addr);
    tokio::task::spawn_blocking(move || {
        let body = r#"{"kind":"simulate","params":{"steps":1,"seed":7}}"#;
        let key = [("Idempotency-Key", "order-42")];
        let first = curl(
            "POST",
            &format!("{base}/v1/jobs"),
            Some(ENGINEER),
            &key,
            Some(body),
        );
        assert_eq!(first.status, 201, "{}", first.body);
        // Same body with keys in another order and other whitespace is the same request.
        let same = r#"{ "params": {"seed": 7, "steps": 1}, "kind": "simulate" }"#;
        let second = curl(
            "POST",
            &format!("{base}/v1/jobs"),
            Some(ENGINEER),
            &key,
            Some(same),
        );
        assert_eq!(second.status, 200, "{}", second.body);
        assert_eq!(second.header("idempotent-replayed"), Some("true"));
        assert_eq!(first.json()["id"], second.json()["id"]);
        assert_eq!(job_count(&base), 1);

        let other = r#"{"kind":"simulate","params":{"steps":2,"seed":7}}"#;
        let conflict = curl(
            "POST",
            &format!("{base}/v1/jobs"),
            Some(ENGINEER),
            &key,
            Some(other),
        );
        let p = conflict.problem(422);
        assert_eq!(p["field"], "Idempotency-Key");
        assert_eq!(job_count(&base), 1);

        // Without a key every POST is a new job.
        let third = curl(
            "POST",
            &format!("{base}/v1/jobs"),
            Some(ENGINEER),
            &[],
            Some(body),
        );
        assert_eq!(third.status, 201);
        assert_eq!(job_count(&base), 2);
        // The job keeps the exact params, the seed and the code version.
        let job = third.json();
        assert_eq!(job["params"], json!({"steps": 1, "seed": 7}));
        assert_eq!(job["seed"], 7);
        assert!(job["code_version"]
            .as_str()
            .unwrap()
            .starts_with(env!("CARGO_PKG_VERSION")));
    })
    .await
    .unwrap();
    service.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cancel_stops_a_running_job_within_a_second() {
    let dir = temp_dir("cancel");
    let service = start(test_config(&dir.db_url()), true).await;
    let base = format!("http://{}", service.addr);
    tokio::task::spawn_blocking(move || {
        // 600 steps of 50 ms = 30 s if not cancelled.
        let body = r#"{"kind":"simulate","params":{"steps":600,"step_ms":50}}"#;
        let id = submit_job(&base, body);
        wait_for(Duration::from_secs(10), "progress", || {
            let j = get_job(&base, &id);
            (j["status"] == "running" && j["progress"]["fraction"].as_f64().unwrap_or(0.0) > 0.0)
                .then_some(())
        });
        let job = get_job(&base, &id);
        assert!(job["progress"]["simulated_time_s"].as_f64().unwrap() > 0.0);
        assert!(job["progress"]["eta_s"].as_f64().unwrap() > 0.0);

        let asked = Instant::now();
        let r = curl(
            "POST",
            &format!("{base}/v1/jobs/{id}/cancel"),
            Some(ENGINEER),
            &[],
            None,
        );
        assert_eq!(r.status, 202, "{}", r.body);
        wait_for(Duration::from_secs(5), "cancelled", || {
            (get_job(&base, &id)["status"] == "cancelled").then_some(())
        });
        let took = asked.elapsed();
        assert!(took < Duration::from_millis(1500), "cancel took {took:?}");
        // Cancelled jobs have no results.
        let r = curl(
            "GET",
            &format!("{base}/v1/jobs/{id}/result"),
            Some(ENGINEER),
            &[],
            None,
        );
        r.problem(409);

        // A queued job (no free worker is needed) is cancelled at once.
        let r = curl(
            "POST",
            &format!("{base}/v1/jobs/{id}/cancel"),
            Some(ENGINEER),
            &[],
            None,
        );
        assert_eq!(r.json()["status"], "cancelled");
    })
    .await
    .unwrap();
    service.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn results_and_tracks_export_with_downsampling() {
    let dir = temp_dir("tracks");
    let service = start(test_config(&dir.db_url()), true).await;
    let base = format!("http://{}", service.addr);
    tokio::task::spawn_blocking(move || {
        let body =
            r#"{"kind":"simulate","params":{"steps":3,"step_ms":10,"samples":2500,"seed":99}}"#;
        let id = submit_job(&base, body);
        wait_for(Duration::from_secs(20), "success", || {
            (get_job(&base, &id)["status"] == "succeeded").then_some(())
        });
        let job = get_job(&base, &id);
        assert_eq!(job["track_samples"], 2500);
        assert_eq!(job["progress"]["fraction"], 1.0);

        let result = curl(
            "GET",
            &format!("{base}/v1/jobs/{id}/result"),
            Some(ENGINEER),
            &[],
            None,
        );
        assert_eq!(result.status, 200);
        let result = result.json();
        assert_eq!(result["summary"]["seed"], 99);
        assert_eq!(result["plots"][0]["name"], "force.svg");
        let svg = curl(
            "GET",
            &format!("{base}/v1/jobs/{id}/plots/force.svg"),
            Some(ENGINEER),
            &[],
            None,
        );
        assert_eq!(svg.header("content-type"), Some("image/svg+xml"));

        let csv = curl(
            "GET",
            &format!("{base}/v1/jobs/{id}/tracks?format=csv"),
            Some(ENGINEER),
            &[],
            None,
        );
        assert_eq!(csv.status, 200);
        let lines: Vec<&str> = csv.body.lines().collect();
        assert_eq!(lines[0], railwear::physics::track::TrackSample::CSV_HEADER);
        assert_eq!(lines.len(), 2501);
        // Every stored value comes back exactly (the runner's samples are reproducible).
        for (i, line) in lines[1..].iter().enumerate().step_by(97) {
            let expected = sample(99, i as u64);
            let fields: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
            assert_eq!(fields[0], expected.time_s);
            assert_eq!(fields[3], expected.normal_force_n);
            assert_eq!(fields[11], expected.pressure_pa);
        }

        let every = curl(
            "GET",
            &format!("{base}/v1/jobs/{id}/tracks?format=csv&every=10"),
            Some(ENGINEER),
            &[],
            None,
        );
        assert_eq!(every.body.lines().count(), 1 + 250);
        let json = curl(
            "GET",
            &format!("{base}/v1/jobs/{id}/tracks?format=json&every=1000"),
            Some(ENGINEER),
            &[],
            None,
        );
        let samples = json.json();
        let samples = samples.as_array().unwrap();
        assert_eq!(samples.len(), 3); // samples 0, 1000, 2000
        assert_eq!(samples[2]["time_s"], sample(99, 2000).time_s);

        // Rejected export parameters.
        curl(
            "GET",
            &format!("{base}/v1/jobs/{id}/tracks?every=0"),
            Some(ENGINEER),
            &[],
            None,
        )
        .problem(400);
        curl(
            "GET",
            &format!("{base}/v1/jobs/{id}/tracks?format=xml"),
            Some(ENGINEER),
            &[],
            None,
        )
        .problem(400);

        // The dashboard lists it (served without token; data needs one).
        let page = curl("GET", &format!("{base}/"), None, &[], None);
        assert!(page.body.contains("railwear dashboard"));
        let metrics = curl("GET", &format!("{base}/metrics"), None, &[], None);
        assert!(
            metrics
                .body
                .contains("railwear_jobs{status=\"succeeded\"} 1"),
            "{}",
            metrics.body
        );
        assert!(metrics.body.contains("railwear_queue_depth 0"));
    })
    .await
    .unwrap();
    service.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn job_of_a_dead_worker_is_rerun_once_with_the_same_result() {
    let dir = temp_dir("lease");
    let config = test_config(&dir.db_url());
    // Reference: an uninterrupted run of seed 5.
    let reference = start(config.clone(), true).await;
    let base = format!("http://{}", reference.addr);
    let body = r#"{"kind":"simulate","params":{"steps":5,"step_ms":10,"samples":300,"seed":5}}"#;
    let expected = tokio::task::spawn_blocking({
        let base = base.clone();
        move || {
            let id = submit_job(&base, body);
            wait_for(Duration::from_secs(20), "reference", || {
                (get_job(&base, &id)["status"] == "succeeded").then_some(())
            });
            let csv = curl(
                "GET",
                &format!("{base}/v1/jobs/{id}/tracks"),
                Some(ENGINEER),
                &[],
                None,
            );
            let result = curl(
                "GET",
                &format!("{base}/v1/jobs/{id}/result"),
                Some(ENGINEER),
                &[],
                None,
            );
            (csv.body, result.json()["summary"].clone())
        }
    })
    .await
    .unwrap();
    reference.stop().await;

    // A service without workers queues the job; a "worker" claims it and dies (never
    // heartbeats, never finishes).
    let api = start(config.clone(), false).await;
    let base = format!("http://{}", api.addr);
    let id = tokio::task::spawn_blocking({
        let base = base.clone();
        move || submit_job(&base, body)
    })
    .await
    .unwrap();
    let store = api.state.store.clone();
    let now = railwear::store::clock::now_ms();
    let claimed = store.claim_job("doomed", now, 500).await.unwrap().unwrap();
    assert_eq!(claimed.attempt, 1);
    api.stop().await;

    // A service with workers picks it up once the lease expired and finishes it.
    let service = start(config, true).await;
    let base = format!("http://{}", service.addr);
    let (csv, summary, attempt) = tokio::task::spawn_blocking({
        let base = base.clone();
        let id = id.clone();
        move || {
            let job = wait_for(Duration::from_secs(20), "recovered", || {
                let j = get_job(&base, &id);
                (j["status"] == "succeeded").then_some(j)
            });
            let csv = curl(
                "GET",
                &format!("{base}/v1/jobs/{id}/tracks"),
                Some(ENGINEER),
                &[],
                None,
            );
            let result = curl(
                "GET",
                &format!("{base}/v1/jobs/{id}/result"),
                Some(ENGINEER),
                &[],
                None,
            );
            (
                csv.body,
                result.json()["summary"].clone(),
                job["attempt"].clone(),
            )
        }
    })
    .await
    .unwrap();
    assert_eq!(attempt, 2);
    assert_eq!(csv, expected.0);
    assert_eq!(summary, expected.1);
    // The dead attempt cannot overwrite the finished one (fenced by attempt).
    let stale = store
        .finish_job(
            claimed.id,
            1,
            railwear::store::Finish::Failed("late".into()),
            railwear::store::clock::now_ms(),
        )
        .await
        .unwrap();
    assert!(!stale);
    let job = store.get_job(claimed.id).await.unwrap().unwrap();
    assert_eq!(job.status, railwear::jobs::JobStatus::Succeeded);
    service.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn rejected_inputs_are_problems_and_change_nothing() {
    let dir = temp_dir("reject");
    let service = start(test_config(&dir.db_url()), false).await;
    let base = format!("http://{}", service.addr);
    tokio::task::spawn_blocking(move || {
        let jobs = format!("{base}/v1/jobs");
        let ok = r#"{"kind":"simulate","params":{"steps":1}}"#;
        assert_eq!(
            curl("POST", &jobs, Some(ENGINEER), &[], Some(ok)).status,
            201
        );
        let before = curl(
            "GET",
            &format!("{jobs}?limit=100"),
            Some(ENGINEER),
            &[],
            None,
        )
        .body;

        curl("POST", &jobs, None, &[], Some(ok)).problem(401);
        let r = curl(
            "POST",
            &jobs,
            Some("wrong-token-0000000000000"),
            &[],
            Some(ok),
        );
        r.problem(401);
        assert!(r.header("www-authenticate").is_some());
        curl("POST", &jobs, Some(PLANNER), &[], Some(ok)).problem(403);
        curl(
            "GET",
            &format!("{base}/v1/tokens"),
            Some(ENGINEER),
            &[],
            None,
        )
        .problem(403);
        curl("POST", &jobs, Some(ENGINEER), &[], Some("{not json")).problem(400);
        curl(
            "POST",
            &jobs,
            Some(ENGINEER),
            &[("Content-Type", "text/plain")],
            Some(ok),
        )
        .problem(415);
        let p = curl(
            "POST",
            &jobs,
            Some(ENGINEER),
            &[],
            Some(r#"{"kind":"dance","params":{}}"#),
        )
        .problem(422);
        assert_eq!(p["field"], "kind");
        let p = curl(
            "POST",
            &jobs,
            Some(ENGINEER),
            &[],
            Some(r#"{"kind":"simulate"}"#),
        )
        .problem(422);
        assert!(p["detail"].as_str().unwrap().contains("params"));
        let p = curl(
            "POST",
            &jobs,
            Some(ENGINEER),
            &[],
            Some(r#"{"kind":"simulate","params":[]}"#),
        )
        .problem(422);
        assert_eq!(p["field"], "params");
        let p = curl(
            "POST",
            &jobs,
            Some(ENGINEER),
            &[],
            Some(r#"{"kind":"simulate","params":{"seed":-1}}"#),
        )
        .problem(422);
        assert_eq!(p["field"], "params.seed");
        let p = curl(
            "POST",
            &jobs,
            Some(ENGINEER),
            &[],
            Some(r#"{"kind":"simulate","params":{"steps":"x"}}"#),
        )
        .problem(422);
        assert_eq!(p["field"], "params.steps");
        let p = curl(
            "POST",
            &jobs,
            Some(ENGINEER),
            &[],
            Some(r#"{"kind":"simulate","params":{},"extra":1}"#),
        )
        .problem(422);
        assert!(p["detail"].as_str().unwrap().contains("extra"));
        let big = format!(
            r#"{{"kind":"simulate","params":{{"pad":"{}"}}}}"#,
            "x".repeat(100_000)
        );
        curl("POST", &jobs, Some(ENGINEER), &[], Some(&big)).problem(413);
        curl("GET", &format!("{jobs}?limit=0"), Some(ENGINEER), &[], None).problem(400);
        curl(
            "GET",
            &format!("{jobs}?limit=abc"),
            Some(ENGINEER),
            &[],
            None,
        )
        .problem(400);
        curl(
            "GET",
            &format!("{jobs}?cursor=zzz"),
            Some(ENGINEER),
            &[],
            None,
        )
        .problem(400);
        curl(
            "GET",
            &format!("{jobs}?status=lost"),
            Some(ENGINEER),
            &[],
            None,
        )
        .problem(400);
        curl(
            "GET",
            &format!("{jobs}/not-a-uuid"),
            Some(ENGINEER),
            &[],
            None,
        )
        .problem(400);
        curl(
            "GET",
            &format!("{jobs}/{}", uuid::Uuid::new_v4()),
            Some(ENGINEER),
            &[],
            None,
        )
        .problem(404);
        curl(
            "POST",
            &format!("{jobs}/{}/cancel", uuid::Uuid::new_v4()),
            Some(ENGINEER),
            &[],
            None,
        )
        .problem(404);
        curl("DELETE", &jobs, Some(ENGINEER), &[], None).problem(405);
        curl(
            "GET",
            &format!("{base}/v1/nothing"),
            Some(ENGINEER),
            &[],
            None,
        )
        .problem(404);

        let after = curl(
            "GET",
            &format!("{jobs}?limit=100"),
            Some(ENGINEER),
            &[],
            None,
        )
        .body;
        assert_eq!(before, after, "a rejected request changed stored jobs");
    })
    .await
    .unwrap();
    service.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn pagination_walks_every_job_once() {
    let dir = temp_dir("page");
    let service = start(test_config(&dir.db_url()), false).await;
    let base = format!("http://{}", service.addr);
    tokio::task::spawn_blocking(move || {
        for _ in 0..7 {
            submit_job(&base, r#"{"kind":"calibrate","params":{}}"#);
        }
        let mut seen = Vec::new();
        let mut cursor: Option<String> = None;
        loop {
            let url = match &cursor {
                Some(c) => format!("{base}/v1/jobs?limit=3&cursor={c}"),
                None => format!("{base}/v1/jobs?limit=3"),
            };
            let page = curl("GET", &url, Some(PLANNER), &[], None).json();
            for item in page["items"].as_array().unwrap() {
                seen.push(item["id"].as_str().unwrap().to_string());
            }
            match page["next_cursor"].as_str() {
                Some(c) => cursor = Some(c.to_string()),
                None => break,
            }
        }
        assert_eq!(seen.len(), 7);
        let mut unique = seen.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), 7);
    })
    .await
    .unwrap();
    service.stop().await;
}
