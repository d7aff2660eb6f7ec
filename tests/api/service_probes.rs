//! The probes of the hostile pass that found the service's open ends (a service that holds on
//! an open network, and numbers that mean what their names say), repeated on every CI run.
//! Each probe holds in one of these tests; those already written elsewhere are not repeated:
//!
//! - Slow clients: partial heads closed within the configured timeout and the per-peer cap
//!   answering 429, a body shorter than its Content-Length answered 408
//!   (`service_hostile.rs`).
//! - Idempotency keys: two tokens with one key get two jobs; two `Idempotency-Key` headers
//!   are refused (`service_hostile.rs`).
//! - SIGTERM late in a long run: the checkpoint is written within the grace and the next
//!   worker resumes from it to the uninterrupted result (`service_shutdown.rs`, stopped past
//!   80 %; `tests/engine/checkpoint_resume.rs` for the checkpoint's bounded size).
//! - Names: `summary.mean_friction_power_w` is the energy account's friction power, and
//!   `mean_normal_slip_power_w` the normal-load-times-slip integral it read before (here).
//! - Nonsense: control characters, `design_life_h = 1e308`, a repeated query key
//!   (`service_hostile.rs`); a request's `kind` of the wrong type and a diagnosis naming an
//!   effect twice (here); a curve from short points published only with `force`
//!   (`service_rails.rs`).
//! - Smaller: a job's stored params submitted again (`service_jobs.rs`); a sweep naming a
//!   cancelled diagnosis is told it will not finish (here).

use crate::helpers::{Runner, TestApp};
use crate::support::{ENGINEER, TEST_ENGINEER};
use serde_json::{json, Value};

/// The smallest campaign that runs a real diagnosis (tests/fixtures, shared).
const CAMPAIGN: &str = include_str!("../fixtures/small-campaign.toml");

fn relative_gap(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_friction_power_a_summary_reports_is_the_energy_accounts() {
    let app = TestApp::spawn_with(Runner::Library, true, |_| {}).await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // No settle, and a run shorter than the drive's 0.15 s ramp-in (three cycles of
        // 20 Hz): its rates are taken over the whole excited window, which is the whole run,
        // so the window's friction work is the energy account's whole friction work. (A run
        // past its ramp takes its rates after it: tests/engine/rattle_box.rs checks those
        // against the difference of two runs' totals.)
        let body = json!({"kind": "simulate", "params": {"config": "rattle-box-c", "seed": 3,
            "overrides": {"simulation": {"settle_s": 0.0, "duration_s": 0.12}}}});
        let id = api.submit_job(&body.to_string());
        api.wait_job(
            &id,
            railwear::jobs::JobStatus::Succeeded,
            std::time::Duration::from_secs(120),
        );
        let summary = api.get_json(&format!("/v1/jobs/{id}/result"))["summary"].clone();
        let window_s = summary["window_s"].as_f64().expect("window_s");
        assert!((window_s - 0.12).abs() < 1e-12, "{window_s}");
        let rate_window = &summary["rate_window"];
        assert_eq!(rate_window["after_ramp"], json!(false), "{rate_window}");
        assert_eq!(
            rate_window["length_s"].as_f64(),
            Some(window_s),
            "{rate_window}"
        );
        let account: &Vec<Value> = summary["energy"]["contacts"].as_array().expect("account");
        let contacts = summary["contacts"].as_array().expect("contacts");
        assert_eq!(contacts.len(), account.len());
        let mut total_j = 0.0;
        for (c, a) in contacts.iter().zip(account) {
            assert_eq!(c["name"], a["name"]);
            let friction_j = a["friction_j"].as_f64().expect("friction_j");
            total_j += friction_j;
            let power = c["mean_friction_power_w"].as_f64().expect("power");
            assert!(
                relative_gap(power * window_s, friction_j) <= 1e-6,
                "{}: {power} W over {window_s} s against {friction_j} J",
                c["name"]
            );
            // What the wear law integrates, N |v_slip|, bounds friction's power from above
            // by the friction coefficient: friction dissipates mu N |v_slip| at most, mu < 1.
            let normal_slip = c["mean_normal_slip_power_w"].as_f64().expect("normal slip");
            assert!(
                power <= normal_slip,
                "{}: {power} > {normal_slip}",
                c["name"]
            );
        }
        assert!(total_j > 0.0, "friction dissipated nothing");
        let power = summary["mean_friction_power_w"]
            .as_f64()
            .expect("total power");
        assert!(
            relative_gap(power * window_s, total_j) <= 1e-6,
            "{power} W, {total_j} J"
        );
    })
    .await
    .unwrap();
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn nonsense_the_hostile_pass_found_is_refused_naming_the_field() {
    // No workers: the diagnosis below stays queued until it is cancelled.
    let app = TestApp::spawn_with(Runner::Library, false, |_| {}).await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // A request's kind of the wrong type names `kind`.
        let r = api.post("/v1/jobs", Some(ENGINEER), r#"{"kind":1}"#);
        assert!(r.status == 400 || r.status == 422, "{}", r.body);
        assert_eq!(r.json()["field"], "kind", "{}", r.body);

        // A diagnosis naming an effect twice.
        let campaign = api.upload_campaign(CAMPAIGN);
        let url = format!("/v1/campaigns/{campaign}/diagnoses");
        let twice = json!({"window_s": 0.1, "effects": ["third_body", "third_body"]});
        let p = api
            .post(&url, Some(TEST_ENGINEER), &twice.to_string())
            .problem(422);
        assert_eq!(p["field"], "effects[1]", "{p}");

        // A sweep naming a cancelled diagnosis is told it will not finish, not to wait.
        let r = api.post(&url, Some(TEST_ENGINEER), r#"{"window_s": 0.1}"#);
        assert_eq!(r.status, 201, "{}", r.body);
        let diagnosis = r.json()["id"].as_str().unwrap().to_string();
        let r = api.post_empty(&format!("/v1/jobs/{diagnosis}/cancel"), Some(TEST_ENGINEER));
        assert!(r.status == 202 || r.status == 200, "{}", r.body);
        api.wait_job(
            &diagnosis,
            railwear::jobs::JobStatus::Cancelled,
            std::time::Duration::from_secs(30),
        );
        let sweep = json!({"kind": "sweep", "params": {"points": 2,
            "wear_law": {"diagnosis": diagnosis}}});
        let p = api
            .post("/v1/jobs", Some(ENGINEER), &sweep.to_string())
            .problem(422);
        assert_eq!(p["field"], "params.wear_law.diagnosis", "{p}");
        let detail = p["detail"].as_str().unwrap_or_default();
        assert!(detail.contains("will not finish"), "{p}");
        assert!(!detail.contains("wait until"), "{p}");
    })
    .await
    .unwrap();
    app.stop().await;
}
