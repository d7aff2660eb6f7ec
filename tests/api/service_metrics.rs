//! `/metrics` read as Prometheus reads it: the live exposition of a service that ran a job and
//! answered requests goes through the Prometheus project's own OpenMetrics parser
//! (`prometheus_client.openmetrics.parser`, Python), which refuses a malformed exposition (a
//! missing `# EOF`, a counter without `_total`, unescaped labels, buckets out of order); the
//! test then checks the parsed families, their types and their values.
//!
//! The parser's Python is `RAILWEAR_METRICS_PYTHON`, else `python3` if it has
//! `prometheus_client`. When neither does the test prints that it skipped, unless
//! `RAILWEAR_REQUIRE_METRICS_PARSER=1` (set by `.ci/run`, which installs it): then it fails.

use crate::helpers::TestApp;
use railwear::jobs::JobStatus;
use serde_json::Value;
use std::io::Write;
use std::process::{Command, Stdio};
use std::time::Duration;

/// Reads OpenMetrics text on stdin; prints its families as JSON.
const PARSE: &str = r#"
import json, sys
from prometheus_client.openmetrics.parser import text_string_to_metric_families
families = [
    {"name": f.name, "type": f.type, "unit": f.unit,
     "samples": [{"name": s.name, "labels": s.labels, "value": s.value} for s in f.samples]}
    for f in text_string_to_metric_families(sys.stdin.read())
]
print(json.dumps(families))
"#;

fn has_parser(python: &str) -> bool {
    Command::new(python)
        .args(["-c", "import prometheus_client.openmetrics.parser"])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// A Python with `prometheus_client`, if any.
fn python() -> Option<String> {
    if let Ok(python) = std::env::var("RAILWEAR_METRICS_PYTHON") {
        if !python.is_empty() {
            return Some(python);
        }
    }
    has_parser("python3").then(|| "python3".to_string())
}

/// The families of `text` as the parser reads them (panics with its error if it refuses).
fn parse(python: &str, text: &str) -> Vec<Value> {
    let mut child = Command::new(python)
        .args(["-c", PARSE])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {python}: {e}"));
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(text.as_bytes())
        .expect("write the exposition");
    let out = child.wait_with_output().expect("parser output");
    assert!(
        out.status.success(),
        "the OpenMetrics parser refused /metrics:\n{}\n--- exposition ---\n{text}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("parser JSON")
}

fn family<'a>(families: &'a [Value], name: &str) -> &'a Value {
    families
        .iter()
        .find(|f| f["name"] == name)
        .unwrap_or_else(|| panic!("no family {name} in {families:?}"))
}

/// The value of the sample `name` of `family` whose labels include `labels`.
fn value(family: &Value, name: &str, labels: &[(&str, &str)]) -> f64 {
    family["samples"]
        .as_array()
        .into_iter()
        .flatten()
        .find(|s| s["name"] == name && labels.iter().all(|(k, v)| s["labels"][*k] == *v))
        .and_then(|s| s["value"].as_f64())
        .unwrap_or_else(|| panic!("no sample {name} {labels:?} in {family}"))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn metrics_parse_as_openmetrics_with_their_names_types_and_values() {
    let required = std::env::var("RAILWEAR_REQUIRE_METRICS_PARSER").as_deref() == Ok("1");
    let Some(python) = python() else {
        assert!(
            !required,
            "no Python with prometheus_client (RAILWEAR_REQUIRE_METRICS_PARSER=1): run .ci/run, \
             which installs it, or set RAILWEAR_METRICS_PYTHON"
        );
        eprintln!("skipped: no Python with prometheus_client (set RAILWEAR_METRICS_PYTHON)");
        return;
    };
    let app = TestApp::spawn().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let id = api.submit_job(r#"{"kind":"simulate","params":{"steps":3}}"#);
        api.wait_job(&id, JobStatus::Succeeded, Duration::from_secs(30));
        api.get_problem("/v1/jobs", None, 401);

        let r = api.get("/metrics", None);
        assert_eq!(r.status, 200, "{}", r.body);
        assert_eq!(
            r.header("content-type"),
            Some(railwear::jobs::metrics::CONTENT_TYPE)
        );
        let families = parse(&python, &r.body);

        let jobs = family(&families, "railwear_jobs");
        assert_eq!(jobs["type"], "gauge");
        assert_eq!(
            value(jobs, "railwear_jobs", &[("status", "succeeded")]),
            1.0
        );
        let depth = family(&families, "railwear_queue_depth");
        assert_eq!(value(depth, "railwear_queue_depth", &[]), 0.0);

        let duration = family(&families, "railwear_job_duration_seconds");
        assert_eq!(
            (&duration["type"], &duration["unit"]),
            (&Value::from("histogram"), &Value::from("seconds"))
        );
        let job = [("kind", "simulate"), ("status", "succeeded")];
        assert_eq!(
            value(duration, "railwear_job_duration_seconds_count", &job),
            1.0
        );
        let mut bucket = job.to_vec();
        bucket.push(("le", "+Inf"));
        assert_eq!(
            value(duration, "railwear_job_duration_seconds_bucket", &bucket),
            1.0
        );

        let requests = family(&families, "railwear_http_requests");
        assert_eq!(requests["type"], "counter");
        let refused = [("method", "GET"), ("route", "/v1/jobs"), ("status", "401")];
        assert_eq!(
            value(requests, "railwear_http_requests_total", &refused),
            1.0
        );
        let job_route = [
            ("method", "GET"),
            ("route", "/v1/jobs/{id}"),
            ("status", "200"),
        ];
        assert!(value(requests, "railwear_http_requests_total", &job_route) >= 1.0);
        let latency = family(&families, "railwear_http_request_duration_seconds");
        assert_eq!(latency["type"], "histogram");
        assert!(
            value(
                latency,
                "railwear_http_request_duration_seconds_count",
                &[("method", "POST"), ("route", "/v1/jobs")]
            ) >= 1.0
        );

        for (name, kind) in [
            ("railwear_simulated_seconds", "counter"),
            ("railwear_simulated_seconds_per_second", "gauge"),
            ("railwear_running_attempts", "gauge"),
            ("railwear_attempts_released", "counter"),
            ("railwear_checkpointed_simulated_seconds", "counter"),
            ("railwear_attempts_resumed", "counter"),
        ] {
            assert_eq!(family(&families, name)["type"], kind, "{name}");
        }
    })
    .await
    .unwrap();
    app.stop().await;
}
