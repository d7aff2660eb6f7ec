//! Issue 17 over HTTP against an in-process service with the production runner
//! (`LibraryRunner`, the shipped `configs/`) and no workers, so nothing runs: job parameters
//! are checked completely at submission (422 problem+json naming the field, nothing stored),
//! authorization comes before body parsing, every error is problem+json, drawn seeds are
//! below 2^53, and /metrics counts HTTP requests per route and never prints -0. A job's
//! stored params, read back, are a request that submits the same job again (a sweep's
//! diagnosed wear-law record included, refused naming the field once altered).

use crate::helpers::{Api, Runner, TestApp};
use crate::support::{ENGINEER, PLANNER, TEST_ENGINEER};
use serde_json::json;

fn stored_jobs(api: &Api) -> usize {
    let r = api.get("/v1/jobs?limit=100", Some(ENGINEER));
    assert_eq!(r.status, 200, "{}", r.body);
    r.json()["items"].as_array().map_or(0, Vec::len)
}

/// A short simulate request on rattle-box-c with `simulation` overrides merged in.
fn simulate_with(simulation: serde_json::Value) -> String {
    let mut sim = json!({"settle_s": 0.05, "duration_s": 0.05, "record_interval_s": 0.01});
    if let (Some(base), Some(extra)) = (sim.as_object_mut(), simulation.as_object()) {
        for (k, v) in extra {
            base.insert(k.clone(), v.clone());
        }
    }
    json!({"kind": "simulate", "params": {"config": "rattle-box-c", "seed": 1,
        "overrides": {"simulation": sim}}})
    .to_string()
}

/// A calibrate request whose eight torque records go back in time at the fourth.
fn calibrate_back_in_time() -> String {
    let records: Vec<_> = (0..8)
        .map(|i| {
            let t = if i == 3 { 1.0 } else { f64::from(i) };
            json!({"time_s": t, "angle_rad": 0.0, "angular_velocity_rad_s": 1.0,
                "normal_load_n": 10.0, "input_torque_n_m": 0.5})
        })
        .collect();
    json!({"kind": "calibrate", "params": {"friction": {
        "fixture": {"polar_inertia_kg_m2": 1.0, "mean_radius_m": 0.1},
        "records": records}}})
    .to_string()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn invalid_job_parameters_are_422_naming_the_field_and_store_nothing() {
    let app = TestApp::spawn_with(Runner::Library, false, |_| {}).await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let jobs = "/v1/jobs";
        let sim = |s: serde_json::Value| simulate_with(s);
        let raw = |s: &str| s.to_string();
        let duration = "params.overrides.simulation.duration_s";
        // (case, body, field the 422 names, a word its detail must contain)
        let cases: Vec<(&str, String, &str, Option<&str>)> = vec![
            // Durations: not positive, absurd (1e308 once ran with eta 1.8e307 s).
            ("negative duration", sim(json!({"duration_s": -1.0})), duration, None),
            ("zero duration", sim(json!({"duration_s": 0.0})), duration, None),
            ("absurd duration", sim(json!({"duration_s": 1e308})), duration, None),
            ("duration over a day", sim(json!({"duration_s": 86_401.0})), duration, None),
            ("settle over a day", sim(json!({"settle_s": 1e6})), "params.overrides.simulation.settle_s", None),
            ("loose tolerance", sim(json!({"rel_tolerance": 0.5})), "params.overrides.simulation.rel_tolerance", None),
            ("metre tolerance", sim(json!({"abs_tolerance_m": 1.0})), "params.overrides.simulation.abs_tolerance_m", None),
            ("nanosecond records", sim(json!({"record_interval_s": 1e-9})), "params.overrides.simulation.record_interval_s", None),
            // 24 h at the default 0.1 ms interval records far more than memory holds.
            (
                "24 h of default records",
                json!({"kind": "simulate", "params": {"config": "rattle-box-c",
                    "overrides": {"simulation": {"duration_s": 86_400.0}}}})
                .to_string(),
                "params.overrides.simulation.record_interval_s",
                None,
            ),
            // A typo in an override key, overrides that are not an object, unknown params.
            ("override typo", sim(json!({"durationn_s": 1.0})), "params.overrides.simulation.durationn_s", Some("durationn_s")),
            ("overrides an array", raw(r#"{"kind":"simulate","params":{"config":"rattle-box-c","overrides":[1,2]}}"#), "params.overrides", None),
            ("params typo", raw(r#"{"kind":"simulate","params":{"confg":"rattle-box-c"}}"#), "params.confg", None),
            ("no config", raw(r#"{"kind":"simulate","params":{"seed":3}}"#), "params.config", None),
            // Names the configs that exist (not the server's path to them).
            ("config not a model", raw(r#"{"kind":"simulate","params":{"config":"service"}}"#), "params.config", Some("rattle-box-c")),
            ("unknown config", raw(r#"{"kind":"simulate","params":{"config":"no-such-case"}}"#), "params.config", None),
            ("seed 2^53", raw(r#"{"kind":"simulate","params":{"config":"rattle-box-c","seed":9007199254740992}}"#), "params.seed", None),
            // Sweeps: point counts, launcher-only, labels that must select something real.
            ("one point", raw(r#"{"kind":"sweep","params":{"points":1}}"#), "params.points", None),
            ("500 points", raw(r#"{"kind":"sweep","params":{"points":500}}"#), "params.points", None),
            ("sweep of a rattle box", raw(r#"{"kind":"sweep","params":{"config":"rattle-box-c"}}"#), "params.config", None),
            ("unknown vehicle", raw(r#"{"kind":"sweep","params":{"vehicle_profile":"uh60"}}"#), "params.vehicle_profile", Some("ah64")),
            ("unknown wear law", raw(r#"{"kind":"sweep","params":{"wear_law":"totally-made-up"}}"#), "params.wear_law", None),
            // `archard` is a real law but needs its coefficient: the default config has none.
            ("archard without coefficient", raw(r#"{"kind":"sweep","params":{"wear_law":"archard"}}"#), "params.wear_law", None),
            ("unknown environment", raw(r#"{"kind":"sweep","params":{"environment":"desert-sand"}}"#), "params.environment", None),
            ("point on a sweep", raw(r#"{"kind":"sweep","params":{"point":0}}"#), "params.point", None),
            ("sweep negative duration", raw(r#"{"kind":"sweep","params":{"overrides":{"simulation":{"duration_s":-2}}}}"#), duration, None),
            // Calibration data: required, typed, no unknown keys.
            ("no calibration data", raw(r#"{"kind":"calibrate","params":{}}"#), "params", None),
            ("calibration typo", raw(r#"{"kind":"calibrate","params":{"wear_law":{"records":[],"densty":1}}}"#), "params.wear_law.densty", None),
            ("absurd density", raw(r#"{"kind":"calibrate","params":{"wear_law":{"density_kg_m3":1e9,"records":[]}}}"#), "params.wear_law.density_kg_m3", None),
            // A record breaking the fit's rule is named by its index and field (the detail no
            // longer reads `invalid time_s (record 3)` under `params.friction.records`).
            ("record back in time", calibrate_back_in_time(), "params.friction.records[3].time_s", Some("strictly increasing")),
        ];
        for (case, body, field, word) in &cases {
            let p = api.post(jobs, Some(ENGINEER), body).problem(422);
            assert_eq!(p["field"], *field, "{case}: {body}: {p}");
            if let Some(word) = word {
                assert!(p["detail"].as_str().unwrap().contains(word), "{case}: {p}");
            }
        }
        // A config that is an object: the field is under params.config.
        let p = api
            .post(
                jobs,
                Some(ENGINEER),
                r#"{"kind":"simulate","params":{"config":{"garbage":true}}}"#,
            )
            .problem(422);
        assert!(
            p["field"].as_str().unwrap().starts_with("params.config"),
            "{p}"
        );

        assert_eq!(stored_jobs(&api), 0, "a rejected job stores nothing");

        // What is valid is accepted: the sweep's curve selectors are stored with it.
        let r = api.post(jobs, Some(ENGINEER), &simulate_with(json!({})));
        assert_eq!(r.status, 201, "{}", r.body);
        let r = api.post(
            jobs,
            Some(ENGINEER),
            r#"{"kind":"sweep","params":{"points":3}}"#,
        );
        assert_eq!(r.status, 201, "{}", r.body);
        let sweep = r.json();
        assert_eq!(sweep["curve_key"], "ah64/clean/modified-archard");
        assert_eq!(sweep["params"]["vehicle_profile"], "ah64");
        // Drawn seeds are below 2^53: JSON readers that use doubles read them exactly.
        let seed = sweep["seed"].as_u64().expect("seed");
        assert!(seed < 1 << 53, "{seed}");
        assert_eq!(stored_jobs(&api), 2);
    })
    .await
    .unwrap();
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn drawn_seeds_are_below_two_to_the_53() {
    for _ in 0..1000 {
        assert!(railwear::jobs::draw_seed() < 1 << 53);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn roles_are_checked_before_the_body_and_every_error_is_a_problem() {
    let app = TestApp::spawn_with(Runner::Library, false, |_| {}).await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let jobs = "/v1/jobs";
        // A planner may not submit jobs, whatever the body holds.
        api.post(jobs, Some(PLANNER), "{not json").problem(403);
        api.request(
            "POST",
            jobs,
            Some(PLANNER),
            &[("Content-Type", "text/plain")],
            Some("x"),
        )
        .problem(403);
        // An engineer may not record measurements, whatever the body holds.
        api.post("/v1/rails/R-1/measurements", Some(ENGINEER), "[1,2")
            .problem(403);
        // A repeated query key and invalid percent-encoding answer problem+json.
        let p = api
            .get(&format!("{jobs}?limit=1&limit=2"), Some(ENGINEER))
            .problem(400);
        assert_eq!(p["field"], "limit", "{p}");
        api.get_problem("/v1/rails/%FF%FE/report", Some(PLANNER), 400);
        api.get_problem("/v1/jobs/%FF", Some(ENGINEER), 400);

        // /metrics: never -0, and HTTP requests per route with a latency histogram.
        let r = api.get("/metrics", None);
        assert_eq!(r.status, 200);
        assert!(!r.body.contains(" -0"), "{}", r.body);
        assert!(
            r.body.contains(
                "railwear_http_requests_total{method=\"POST\",route=\"/v1/jobs\",status=\"403\"} 2"
            ),
            "{}",
            r.body
        );
        assert!(
            r.body.contains(
                "railwear_http_request_duration_seconds_count{method=\"GET\",route=\"/v1/jobs\"} 1"
            ),
            "{}",
            r.body
        );
    })
    .await
    .unwrap();
    app.stop().await;
}

/// The smallest campaign that runs a real diagnosis (tests/fixtures, shared).
const CAMPAIGN: &str = include_str!("../fixtures/small-campaign.toml");

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_jobs_stored_params_submit_the_same_job_again() {
    let app = TestApp::spawn_with(Runner::Library, true, |_| {}).await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // A diagnosis whose wear-law effect a sweep carries: the fixture's masses twenty times
        // over, a gap impact wear explains.
        let mut text = CAMPAIGN.to_string();
        for (measured, scaled) in [
            ("0.004", "0.08"),
            ("0.005", "0.1"),
            ("0.002", "0.04"),
            ("0.003", "0.06"),
        ] {
            text = text.replace(&format!("cube = {measured} "), &format!("cube = {scaled} "));
        }
        let campaign = api.upload_campaign(&text);
        let r = api.post(
            &format!("/v1/campaigns/{campaign}/diagnoses"),
            Some(TEST_ENGINEER),
            r#"{"window_s": 0.1, "settle_s": 0.02, "grid_points": 2, "effects": ["impact_wear"]}"#,
        );
        assert_eq!(r.status, 201, "{}", r.body);
        let diagnosis = r.json()["id"].as_str().unwrap().to_string();
        api.wait_job(
            &diagnosis,
            railwear::jobs::JobStatus::Succeeded,
            std::time::Duration::from_secs(300),
        );

        let submit =
            |body: &serde_json::Value| api.post("/v1/jobs", Some(ENGINEER), &body.to_string());
        let sweep = json!({"kind": "sweep", "params": {"points": 2,
            "wear_law": {"diagnosis": diagnosis},
            "overrides": {"simulation": {"duration_s": 0.05, "settle_s": 0.01}}}});
        for first in [
            json!({"kind": "simulate", "params": {"config": "rattle-box-c",
                "overrides": {"simulation": {"settle_s": 0.01, "duration_s": 0.01}}}}),
            sweep,
        ] {
            let r = submit(&first);
            assert_eq!(r.status, 201, "{}", r.body);
            let job = r.json();
            let id = job["id"].as_str().unwrap();
            api.cancel_job(id);
            // GET the job, POST its kind and params back: a new job with the same params.
            let stored = api.get_json(&format!("/v1/jobs/{id}"));
            let again = json!({"kind": stored["kind"], "params": stored["params"]});
            let r = submit(&again);
            assert_eq!(r.status, 201, "resubmitting {again}: {}", r.body);
            let second = r.json();
            assert_ne!(second["id"], stored["id"]);
            assert_eq!(second["params"], stored["params"], "{second}");
            api.cancel_job(second["id"].as_str().unwrap());
            if stored["kind"] != "sweep" {
                continue;
            }
            // The stored diagnosed wear law is the diagnosis' record: altered, it is refused
            // naming the field that differs.
            let law = &stored["params"]["wear_law"];
            assert_eq!(law["diagnosis"], diagnosis.as_str(), "{stored}");
            let name = law["parameters"]
                .as_object()
                .and_then(|p| p.keys().next().cloned())
                .expect("the record has parameters");
            let mut altered = again.clone();
            let value = &mut altered["params"]["wear_law"]["parameters"][&name];
            *value = json!(value.as_f64().unwrap() * 2.0 + 1.0);
            let p = submit(&altered).problem(422);
            assert_eq!(
                p["field"],
                format!("params.wear_law.parameters.{name}"),
                "{p}"
            );
            let mut altered = again.clone();
            altered["params"]["wear_law"]["effect"] = json!("third_body");
            let p = submit(&altered).problem(422);
            assert_eq!(p["field"], "params.wear_law.effect", "{p}");
        }
    })
    .await
    .unwrap();
    app.stop().await;
}
