//! Queue semantics over HTTP against an in-process service whose computations are the
//! counting test runner: idempotency, cancellation, results and track export, recovery of a job
//! whose worker died, rejected inputs leaving stored data unchanged.

use crate::helpers::{Api, TestApp};
use crate::support::runner::{sample, start, test_config};
use crate::support::{temp_dir, ENGINEER, PLANNER};
use railwear::jobs::JobStatus;
use serde_json::json;
use std::time::{Duration, Instant};

fn job_count(api: &Api) -> usize {
    let r = api.get("/v1/jobs?limit=100", Some(ENGINEER));
    r.json()["items"].as_array().map_or(0, Vec::len)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn idempotency_key_gives_one_job() {
    let app = TestApp::spawn_idle().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let body = r#"{"kind":"simulate","params":{"steps":1,"seed":7}}"#;
        let key = [("Idempotency-Key", "order-42")];
        let first = api.request("POST", "/v1/jobs", Some(ENGINEER), &key, Some(body));
        assert_eq!(first.status, 201, "{}", first.body);
        // Same body with keys in another order and other whitespace is the same request.
        let same = r#"{ "params": {"seed": 7, "steps": 1}, "kind": "simulate" }"#;
        let second = api.request("POST", "/v1/jobs", Some(ENGINEER), &key, Some(same));
        assert_eq!(second.status, 200, "{}", second.body);
        assert_eq!(second.header("idempotent-replayed"), Some("true"));
        assert_eq!(first.json()["id"], second.json()["id"]);
        assert_eq!(job_count(&api), 1);

        let other = r#"{"kind":"simulate","params":{"steps":2,"seed":7}}"#;
        let conflict = api.request("POST", "/v1/jobs", Some(ENGINEER), &key, Some(other));
        let p = conflict.problem(422);
        assert_eq!(p["field"], "Idempotency-Key");
        assert_eq!(job_count(&api), 1);

        // Without a key every POST is a new job.
        let third = api.post("/v1/jobs", Some(ENGINEER), body);
        assert_eq!(third.status, 201);
        assert_eq!(job_count(&api), 2);
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
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cancel_stops_a_running_job_within_a_second() {
    let app = TestApp::spawn().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // 600 steps of 50 ms = 30 s if not cancelled.
        let body = r#"{"kind":"simulate","params":{"steps":600,"step_ms":50}}"#;
        let id = api.submit_job(body);
        api.wait_job_until(&id, "progress", Duration::from_secs(10), |j| {
            j.status == JobStatus::Running && j.progress.is_some_and(|p| p.fraction > 0.0)
        });
        let progress = api.job(&id).progress.expect("a running job's progress");
        assert!(progress.simulated_time_s > 0.0);
        assert!(progress.eta_s.expect("an ETA") > 0.0);

        let asked = Instant::now();
        let r = api.cancel_job(&id);
        assert_eq!(r.status, 202, "{}", r.body);
        api.wait_job(&id, JobStatus::Cancelled, Duration::from_secs(5));
        let took = asked.elapsed();
        assert!(took < Duration::from_millis(1500), "cancel took {took:?}");
        // Cancelled jobs have no results.
        let r = api.get(&format!("/v1/jobs/{id}/result"), Some(ENGINEER));
        r.problem(409);

        // A queued job (no free worker is needed) is cancelled at once.
        let r = api.cancel_job(&id);
        assert_eq!(r.json()["status"], "cancelled");
    })
    .await
    .unwrap();
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn results_and_tracks_export_with_downsampling() {
    let app = TestApp::spawn().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let body =
            r#"{"kind":"simulate","params":{"steps":3,"step_ms":10,"samples":2500,"seed":99}}"#;
        let id = api.submit_job(body);
        let job = api.wait_job(&id, JobStatus::Succeeded, Duration::from_secs(20));
        assert_eq!(job.track_samples, 2500);
        assert_eq!(job.progress.map(|p| p.fraction), Some(1.0));

        let result = api.get(&format!("/v1/jobs/{id}/result"), Some(ENGINEER));
        assert_eq!(result.status, 200);
        let result = result.json();
        assert_eq!(result["summary"]["seed"], 99);
        assert_eq!(result["plots"][0]["name"], "force.svg");
        let svg = api.get(&format!("/v1/jobs/{id}/plots/force.svg"), Some(ENGINEER));
        assert_eq!(svg.header("content-type"), Some("image/svg+xml"));

        let csv = api.get(&format!("/v1/jobs/{id}/tracks?format=csv"), Some(ENGINEER));
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

        let every = api.get(
            &format!("/v1/jobs/{id}/tracks?format=csv&every=10"),
            Some(ENGINEER),
        );
        assert_eq!(every.body.lines().count(), 1 + 250);
        let json = api.get(
            &format!("/v1/jobs/{id}/tracks?format=json&every=1000"),
            Some(ENGINEER),
        );
        let samples = json.json();
        let samples = samples.as_array().unwrap();
        assert_eq!(samples.len(), 3); // samples 0, 1000, 2000
        assert_eq!(samples[2]["time_s"], sample(99, 2000).time_s);

        // Rejected export parameters.
        api.get_problem(
            &format!("/v1/jobs/{id}/tracks?every=0"),
            Some(ENGINEER),
            400,
        );
        api.get_problem(
            &format!("/v1/jobs/{id}/tracks?format=xml"),
            Some(ENGINEER),
            400,
        );

        // The dashboard lists it (served without token; data needs one).
        let page = api.get("/", None);
        assert!(page.body.contains("railwear dashboard"));
        let metrics = api.get("/metrics", None);
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
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn job_of_a_dead_worker_is_rerun_once_with_the_same_result() {
    let dir = temp_dir("lease");
    let config = test_config(&dir.db_url());
    // Reference: an uninterrupted run of seed 5.
    let reference = start(config.clone(), true).await;
    let api = Api::new(&format!("http://{}", reference.addr));
    let body = r#"{"kind":"simulate","params":{"steps":5,"step_ms":10,"samples":300,"seed":5}}"#;
    let expected = tokio::task::spawn_blocking({
        let api = api.clone();
        move || {
            let id = api.submit_job(body);
            api.wait_job(&id, JobStatus::Succeeded, Duration::from_secs(20));
            let csv = api.get(&format!("/v1/jobs/{id}/tracks"), Some(ENGINEER));
            let result = api.get(&format!("/v1/jobs/{id}/result"), Some(ENGINEER));
            (csv.body, result.json()["summary"].clone())
        }
    })
    .await
    .unwrap();
    reference.stop().await;

    // A service without workers queues the job; a "worker" claims it and dies (never
    // heartbeats, never finishes).
    let api_only = start(config.clone(), false).await;
    let api = Api::new(&format!("http://{}", api_only.addr));
    let id = tokio::task::spawn_blocking({
        let api = api.clone();
        move || api.submit_job(body)
    })
    .await
    .unwrap();
    let store = api_only.state.store.clone();
    let now = railwear::store::clock::now_ms();
    let claimed = store.claim_job("doomed", now, 500).await.unwrap().unwrap();
    assert_eq!(claimed.attempt, 1);
    api_only.stop().await;

    // A service with workers picks it up once the lease expired and finishes it.
    let service = start(config, true).await;
    let api = Api::new(&format!("http://{}", service.addr));
    let (csv, summary, attempt) = tokio::task::spawn_blocking({
        let api = api.clone();
        let id = id.clone();
        move || {
            let job = api.wait_job(&id, JobStatus::Succeeded, Duration::from_secs(20));
            let csv = api.get(&format!("/v1/jobs/{id}/tracks"), Some(ENGINEER));
            let result = api.get(&format!("/v1/jobs/{id}/result"), Some(ENGINEER));
            (csv.body, result.json()["summary"].clone(), job.attempt)
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
    let app = TestApp::spawn_idle().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let ok = r#"{"kind":"simulate","params":{"steps":1}}"#;
        assert_eq!(api.post("/v1/jobs", Some(ENGINEER), ok).status, 201);
        let before = api.get("/v1/jobs?limit=100", Some(ENGINEER)).body;

        let big = format!(
            r#"{{"kind":"simulate","params":{{"pad":"{}"}}}}"#,
            "x".repeat(100_000)
        );
        let (unknown, unknown_cancel) = (
            format!("/v1/jobs/{}", uuid::Uuid::new_v4()),
            format!("/v1/jobs/{}/cancel", uuid::Uuid::new_v4()),
        );
        let wrong = Some("wrong-token-0000000000000");
        let (eng, plain) = (Some(ENGINEER), &[("Content-Type", "text/plain")][..]);
        // (case, method, path, token, headers, body, status, what the problem names)
        let cases: [Rejected; 22] = [
            (
                "no token",
                "POST",
                "/v1/jobs",
                None,
                &[],
                Some(ok),
                401,
                Names::Nothing,
            ),
            (
                "wrong token",
                "POST",
                "/v1/jobs",
                wrong,
                &[],
                Some(ok),
                401,
                Names::Header("www-authenticate"),
            ),
            (
                "planner submits",
                "POST",
                "/v1/jobs",
                Some(PLANNER),
                &[],
                Some(ok),
                403,
                Names::Nothing,
            ),
            (
                "engineer lists tokens",
                "GET",
                "/v1/tokens",
                eng,
                &[],
                None,
                403,
                Names::Nothing,
            ),
            (
                "not JSON",
                "POST",
                "/v1/jobs",
                eng,
                &[],
                Some("{not json"),
                400,
                Names::Nothing,
            ),
            (
                "text/plain",
                "POST",
                "/v1/jobs",
                eng,
                plain,
                Some(ok),
                415,
                Names::Nothing,
            ),
            (
                "unknown kind",
                "POST",
                "/v1/jobs",
                eng,
                &[],
                Some(r#"{"kind":"dance","params":{}}"#),
                422,
                Names::Field("kind"),
            ),
            (
                "no params",
                "POST",
                "/v1/jobs",
                eng,
                &[],
                Some(r#"{"kind":"simulate"}"#),
                422,
                Names::Detail("params"),
            ),
            (
                "params an array",
                "POST",
                "/v1/jobs",
                eng,
                &[],
                Some(r#"{"kind":"simulate","params":[]}"#),
                422,
                Names::Field("params"),
            ),
            (
                "negative seed",
                "POST",
                "/v1/jobs",
                eng,
                &[],
                Some(r#"{"kind":"simulate","params":{"seed":-1}}"#),
                422,
                Names::Field("params.seed"),
            ),
            (
                "steps a string",
                "POST",
                "/v1/jobs",
                eng,
                &[],
                Some(r#"{"kind":"simulate","params":{"steps":"x"}}"#),
                422,
                Names::Field("params.steps"),
            ),
            (
                "unknown member",
                "POST",
                "/v1/jobs",
                eng,
                &[],
                Some(r#"{"kind":"simulate","params":{},"extra":1}"#),
                422,
                Names::Detail("extra"),
            ),
            (
                "body over the limit",
                "POST",
                "/v1/jobs",
                eng,
                &[],
                Some(&big),
                413,
                Names::Nothing,
            ),
            (
                "limit 0",
                "GET",
                "/v1/jobs?limit=0",
                eng,
                &[],
                None,
                400,
                Names::Nothing,
            ),
            (
                "limit not a number",
                "GET",
                "/v1/jobs?limit=abc",
                eng,
                &[],
                None,
                400,
                Names::Nothing,
            ),
            (
                "bad cursor",
                "GET",
                "/v1/jobs?cursor=zzz",
                eng,
                &[],
                None,
                400,
                Names::Nothing,
            ),
            (
                "unknown status",
                "GET",
                "/v1/jobs?status=lost",
                eng,
                &[],
                None,
                400,
                Names::Nothing,
            ),
            (
                "id not a uuid",
                "GET",
                "/v1/jobs/not-a-uuid",
                eng,
                &[],
                None,
                400,
                Names::Nothing,
            ),
            (
                "unknown job",
                "GET",
                &unknown,
                eng,
                &[],
                None,
                404,
                Names::Nothing,
            ),
            (
                "cancel an unknown job",
                "POST",
                &unknown_cancel,
                eng,
                &[],
                None,
                404,
                Names::Nothing,
            ),
            (
                "DELETE the collection",
                "DELETE",
                "/v1/jobs",
                eng,
                &[],
                None,
                405,
                Names::Nothing,
            ),
            (
                "unknown route",
                "GET",
                "/v1/nothing",
                eng,
                &[],
                None,
                404,
                Names::Nothing,
            ),
        ];
        for (case, method, path, token, headers, body, status, names) in cases {
            let r = api.request(method, path, token, headers, body);
            assert_eq!(r.status, status, "{case}: {}", r.body);
            let p = r.problem(status);
            match names {
                Names::Nothing => {}
                Names::Field(field) => assert_eq!(p["field"], field, "{case}"),
                Names::Detail(word) => {
                    assert!(p["detail"].as_str().unwrap().contains(word), "{case}: {p}")
                }
                Names::Header(name) => assert!(r.header(name).is_some(), "{case}"),
            }
        }

        let after = api.get("/v1/jobs?limit=100", Some(ENGINEER)).body;
        assert_eq!(before, after, "a rejected request changed stored jobs");
    })
    .await
    .unwrap();
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn pagination_walks_every_job_once() {
    let app = TestApp::spawn_idle().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        for _ in 0..7 {
            api.submit_job(r#"{"kind":"calibrate","params":{}}"#);
        }
        let mut seen = Vec::new();
        let mut cursor: Option<String> = None;
        loop {
            let path = match &cursor {
                Some(c) => format!("/v1/jobs?limit=3&cursor={c}"),
                None => "/v1/jobs?limit=3".to_string(),
            };
            let page = api.get(&path, Some(PLANNER)).json();
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
    app.stop().await;
}

/// A rejected request: (case, method, path, token, headers, body, status, what the problem
/// names).
type Rejected<'a> = (
    &'a str,
    &'a str,
    &'a str,
    Option<&'a str>,
    &'a [(&'a str, &'a str)],
    Option<&'a str>,
    u16,
    Names,
);

/// What a rejected request's problem must name besides its status.
#[derive(Clone, Copy)]
enum Names {
    Nothing,
    /// `field` equal to this.
    Field(&'static str),
    /// `detail` containing this.
    Detail(&'static str),
    /// This response header present.
    Header(&'static str),
}
