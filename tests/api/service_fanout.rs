//! Fan-out through the embedded workers on SQLite (the same code path as `railwear worker`
//! processes on PostgreSQL), over HTTP, with the counting test runner: a sweep becomes child
//! jobs listed under `?parent=`, its progress is the mean of its children's, its result is
//! assembled once from the children's results in index order; a failing child fails the sweep
//! naming it and cancels the rest; cancelling the sweep cancels its children.

use crate::helpers::{wait_for, Runner, TestApp};
use crate::support::runner::sample;
use crate::support::ENGINEER;
use railwear::http::jobs::JobView;
use railwear::jobs::{ChildCounts, JobKind, JobStatus};
use railwear::store::AttemptOutcome;
use std::time::Duration;

fn count(jobs: &[JobView], status: JobStatus) -> i64 {
    jobs.iter().filter(|j| j.status == status).count() as i64
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_sweep_fans_out_to_child_jobs_and_is_assembled_once() {
    let app = TestApp::spawn_with(Runner::Counting, true, |config| {
        config.workers = 3;
    })
    .await;
    let store = app.service.state.store.clone();
    let api = app.api.clone();
    let (id, child_ids) = tokio::task::spawn_blocking(move || {
        let body = r#"{"kind":"sweep","params":{"children":6,"steps":3,"step_ms":20,"seed":42}}"#;
        let id = api.submit_job(body);
        let done = api.wait_job(&id, JobStatus::Succeeded, Duration::from_secs(30));
        assert_eq!(
            done.children,
            Some(ChildCounts {
                total: 6,
                succeeded: 6,
                failed: 0,
                cancelled: 0
            })
        );
        assert_eq!(done.progress.map(|p| p.fraction), Some(1.0));
        assert_eq!(done.parent_id, None);
        assert_eq!(
            done.links.children,
            Some(format!("/v1/jobs?parent={id}&limit=100"))
        );

        let kids = api.children(&id);
        assert_eq!(kids.len(), 6);
        let mut indices: Vec<i64> = kids.iter().filter_map(|c| c.child_index).collect();
        indices.sort_unstable();
        assert_eq!(indices, [0, 1, 2, 3, 4, 5]);
        for c in &kids {
            assert_eq!(c.kind, JobKind::SweepPoint);
            assert_eq!(c.status, JobStatus::Succeeded);
            assert_eq!(c.parent_id.map(|p| p.to_string()), Some(id.clone()));
            assert_eq!(c.seed, 42);
            assert_eq!(c.children, None);
        }
        // Submitted jobs only: the children stay out of the top-level list.
        let top = api.get_json("/v1/jobs?top_level=true")["items"].clone();
        assert_eq!(top.as_array().map(Vec::len), Some(1));
        assert_eq!(top[0]["id"], id.as_str());

        // The assembled result lists the children's results in index order; each is the
        // runner's value for the sweep's seed and that point, so the seed reached every child.
        let result = api.get_json(&format!("/v1/jobs/{id}/result"));
        let points = result["summary"]["points"].as_array().unwrap().clone();
        assert_eq!(points.len(), 6);
        for (i, p) in points.iter().enumerate() {
            assert_eq!(p["point"], i);
            assert_eq!(
                p["value"].as_f64().unwrap().to_bits(),
                sample(42, i as u64).normal_force_n.to_bits()
            );
        }
        assert_eq!(result["plots"][0]["name"], "penalization.svg");
        // The attempt log over HTTP: fanned out once, assembled once, both ended.
        let log = api.get_json(&format!("/v1/jobs/{id}/attempts"));
        let outcomes: Vec<&str> = log
            .as_array()
            .map(|rows| rows.iter().filter_map(|a| a["outcome"].as_str()).collect())
            .unwrap_or_default();
        assert_eq!(outcomes, ["fanned_out", "succeeded"], "{log}");
        assert_eq!(log[0]["attempt"], 1);
        assert_eq!(log[1]["attempt"], 2);
        assert!(log[1]["ended_at"].is_string(), "{log}");
        assert_eq!(done.links.attempts, format!("/v1/jobs/{id}/attempts"));
        let missing = api.get(
            &format!("/v1/jobs/{}/attempts", uuid::Uuid::new_v4()),
            Some(ENGINEER),
        );
        assert_eq!(missing.status, 404, "{}", missing.body);
        let malformed = api.get("/v1/jobs/not-a-uuid/attempts", Some(ENGINEER));
        assert_eq!(malformed.status, 400, "{}", malformed.body);
        assert!(malformed.body.contains("id"), "{}", malformed.body);
        let child_ids: Vec<uuid::Uuid> = kids.iter().map(|c| c.id).collect();
        (id.parse::<uuid::Uuid>().unwrap(), child_ids)
    })
    .await
    .unwrap();
    // The attempt log: fanned out once, assembled once; every child ran once.
    let outcomes = |a: Vec<railwear::store::AttemptRecord>| -> Vec<AttemptOutcome> {
        a.iter().map(|a| a.outcome).collect()
    };
    assert_eq!(
        outcomes(store.attempts(id).await.unwrap()),
        [AttemptOutcome::FannedOut, AttemptOutcome::Succeeded]
    );
    for child in child_ids {
        assert_eq!(
            outcomes(store.attempts(child).await.unwrap()),
            [AttemptOutcome::Succeeded]
        );
    }
    let job = store.get_job(id).await.unwrap().unwrap();
    let curve = railwear::store::latest_curve(store.as_ref(), job.curve_key.as_deref().unwrap())
        .await
        .unwrap()
        .unwrap();
    assert_eq!(curve.job_id, id);
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_failing_child_fails_the_sweep_naming_it_and_cancels_the_rest() {
    let app = TestApp::spawn().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let body = r#"{"kind":"sweep","params":{"children":6,"steps":5,"step_ms":40,"fail_point":0,"seed":1}}"#;
        let id = api.submit_job(body);
        let failed = api.wait_job_until(&id, "sweep failure", Duration::from_secs(30), |j| {
            assert_ne!(j.status, JobStatus::Succeeded, "{j:?}");
            j.status == JobStatus::Failed
        });
        let kids = wait_for(Duration::from_secs(30), "children ended", || {
            let kids = api.children(&id);
            (count(&kids, JobStatus::Queued) + count(&kids, JobStatus::Running) == 0)
                .then_some(kids)
        });
        let first = kids
            .iter()
            .find(|c| c.child_index == Some(0))
            .expect("child 0");
        assert_eq!(first.status, JobStatus::Failed);
        assert_eq!(
            first.error.as_deref(),
            Some("simulation diverged: point 0 diverged on purpose")
        );
        assert_eq!(
            failed.error,
            Some(format!(
                "child 0 (job {}) failed: simulation diverged: point 0 diverged on purpose",
                first.id
            ))
        );
        // The others either finished before they heard or were cancelled.
        assert_eq!(count(&kids, JobStatus::Failed), 1);
        assert_eq!(
            count(&kids, JobStatus::Succeeded) + count(&kids, JobStatus::Cancelled),
            5
        );
        assert!(
            count(&kids, JobStatus::Cancelled) >= 3,
            "queued children were not cancelled"
        );
        let parent = api.job(&id);
        assert_eq!(parent.status, JobStatus::Failed);
        assert_eq!(
            parent.children,
            Some(ChildCounts {
                total: 6,
                succeeded: count(&kids, JobStatus::Succeeded),
                failed: 1,
                cancelled: count(&kids, JobStatus::Cancelled),
            })
        );
        let r = api.get(&format!("/v1/jobs/{id}/result"), Some(ENGINEER));
        r.problem(409);
    })
    .await
    .unwrap();
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cancelling_a_sweep_cancels_its_queued_and_running_children() {
    let app = TestApp::spawn().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // 600 steps of 50 ms = 30 s per child if not cancelled.
        let body = r#"{"kind":"sweep","params":{"children":5,"steps":600,"step_ms":50}}"#;
        let id = api.submit_job(body);
        wait_for(Duration::from_secs(20), "two running children", || {
            let kids = api.children(&id);
            (kids.len() == 5 && count(&kids, JobStatus::Running) == 2).then_some(())
        });
        // Issue 29: while its points run, the sweep shows their combined progress (the mean
        // of their fractions) and an ETA, not 0 until the first point succeeds.
        let waiting = api.wait_job_until(
            &id,
            "progress of running children",
            Duration::from_secs(20),
            |j| j.progress.is_some_and(|p| p.fraction > 0.0),
        );
        assert_eq!(waiting.status, JobStatus::Waiting);
        assert_eq!(waiting.worker, None);
        // Two of five points run and none is done: the fraction is below 2/5.
        let progress = waiting.progress.expect("progress");
        assert!(
            progress.fraction > 0.0 && progress.fraction < 0.4,
            "{waiting:?}"
        );
        assert!(progress.eta_s.is_some_and(|e| e > 0.0), "{waiting:?}");
        let r = api.cancel_job(&id);
        assert_eq!(r.status, 202, "{}", r.body);
        assert_eq!(r.json()["status"], "cancelled");
        // The running children stop at once: the cancel reaches them in this process.
        let kids = wait_for(Duration::from_secs(5), "children cancelled", || {
            let kids = api.children(&id);
            (count(&kids, JobStatus::Cancelled) == 5).then_some(kids)
        });
        assert!(kids.iter().all(|c| c.cancel_requested));
        let parent = api.job(&id);
        assert_eq!(parent.status, JobStatus::Cancelled);
        assert_eq!(parent.children.map(|c| c.cancelled), Some(5));
    })
    .await
    .unwrap();
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sweep_points_cannot_be_submitted_and_bad_filters_are_refused() {
    let app = TestApp::spawn_idle().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let r = api.post(
            "/v1/jobs",
            Some(ENGINEER),
            r#"{"kind":"sweep_point","params":{"point":0}}"#,
        );
        assert_eq!(r.problem(422)["field"], "kind");
        for (query, field) in [
            ("parent=7", "parent"),
            ("top_level=yes", "top_level"),
            ("status=done", "status"),
        ] {
            let r = api.get(&format!("/v1/jobs?{query}"), Some(ENGINEER));
            assert_eq!(r.problem(400)["field"], field, "{query}");
        }
    })
    .await
    .unwrap();
    app.stop().await;
}

/// The value of the Prometheus sample `name{labels}` in `text`, if present.
fn sample_value(text: &str, series: &str) -> Option<f64> {
    text.lines()
        .find_map(|l| l.strip_prefix(series))
        .and_then(|rest| rest.trim().parse().ok())
}

/// Issue 17: the sweep duration histogram counts whole sweeps, from the first claim through the
/// children to the assembly (the assembly alone takes milliseconds), also when a child's
/// failure ends the sweep; each sweep once.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_sweep_duration_histogram_counts_whole_sweeps() {
    let app = TestApp::spawn_with(Runner::Counting, true, |config| {
        config.workers = 2;
    })
    .await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // 4 children of 5 x 60 ms on 2 workers: at least 0.6 s of wall time.
        let body = r#"{"kind":"sweep","params":{"children":4,"steps":5,"step_ms":60,"seed":3}}"#;
        let id = api.submit_job(body);
        let failing =
            r#"{"kind":"sweep","params":{"children":3,"steps":5,"step_ms":60,"fail_point":1}}"#;
        let failed_id = api.submit_job(failing);
        for (job, status) in [(&id, JobStatus::Succeeded), (&failed_id, JobStatus::Failed)] {
            api.wait_job(job, status, Duration::from_secs(30));
        }
        let job = api.job(&id);
        let whole_s = (chrono_ms(&job.finished_at) - chrono_ms(&job.started_at)) / 1000.0;
        assert!(whole_s >= 0.6, "{job:?}");
        let text = api.get("/metrics", None).body;
        let sum = sample_value(
            &text,
            "railwear_job_duration_seconds_sum{kind=\"sweep\",status=\"succeeded\"}",
        )
        .unwrap_or_else(|| panic!("{text}"));
        assert!(
            sum >= 0.6 && (sum - whole_s).abs() < 0.1,
            "sum {sum}, whole {whole_s}"
        );
        assert_eq!(
            sample_value(
                &text,
                "railwear_job_duration_seconds_count{kind=\"sweep\",status=\"succeeded\"}"
            ),
            Some(1.0)
        );
        // The failed sweep ended in its child's finish: counted once, with its whole time.
        assert_eq!(
            sample_value(
                &text,
                "railwear_job_duration_seconds_count{kind=\"sweep\",status=\"failed\"}"
            ),
            Some(1.0),
            "{text}"
        );
        let failed_sum = sample_value(
            &text,
            "railwear_job_duration_seconds_sum{kind=\"sweep\",status=\"failed\"}",
        )
        .unwrap();
        assert!(failed_sum >= 0.25, "{failed_sum}");
    })
    .await
    .unwrap();
    app.stop().await;
}

/// Unix ms of an RFC 3339 time as the API writes it (`2024-05-01T08:30:00.123Z`).
fn chrono_ms(time: &Option<String>) -> f64 {
    let text = time.as_deref().expect("a time");
    let ms = railwear::store::clock::parse_iso8601_ms(text).expect("RFC 3339");
    ms as f64
}
