//! Physical bounds over HTTP, against an in-process service with the production runner and no
//! workers (nothing runs): every numeric field of a case out of its physical bounds is a 422
//! naming it and stores nothing; unknown query parameters are refused on every route; the role
//! comes before the body's size; whoever started a job may cancel it.

use crate::helpers::{Api, Runner, TestApp};
use crate::support::{ENGINEER, PLANNER, TEST_ENGINEER};
use railwear::pipeline::bounds::{check_case_at, FieldPath};
use serde_json::{json, Value};

/// The smallest campaign that runs a real diagnosis (tests/fixtures, shared).
const CAMPAIGN: &str = include_str!("../fixtures/small-campaign.toml");

fn stored_jobs(api: &Api) -> usize {
    let r = api.get("/v1/jobs?limit=100", Some(ENGINEER));
    assert_eq!(r.status, 200, "{}", r.body);
    r.json()["items"].as_array().map_or(0, Vec::len)
}

/// Rattle box C as an inline config, as the service would load it, and the typed case.
fn rattle_box_c() -> (Value, railwear::models::spec::CaseSpec) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/rattle-box-c.toml");
    let case = railwear::models::case::load_case(&path).unwrap();
    (serde_json::to_value(&case).unwrap(), case)
}

/// The path of every number in `value` (`a.b[2].c`).
fn number_paths(value: &Value, path: String, out: &mut Vec<String>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                let sub = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                number_paths(v, sub, out);
            }
        }
        Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                number_paths(v, format!("{path}[{i}]"), out);
            }
        }
        Value::Number(_) => out.push(path),
        _ => {}
    }
}

/// `a.b[2].c` as a JSON pointer.
fn pointer(path: &str) -> String {
    path.split('.')
        .flat_map(|part| part.split('['))
        .map(|s| format!("/{}", s.trim_end_matches(']')))
        .collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_numeric_field_out_of_bounds_is_422_naming_it() {
    let app = TestApp::spawn_with(Runner::Library, false, |_| {}).await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let (case, typed) = rattle_box_c();
        // The table is generated from the case's own fields, with the bound the typed checker
        // holds each to.
        let mut at = FieldPath::recording("");
        check_case_at(&typed, None, &mut at).unwrap();
        let mut paths = Vec::new();
        number_paths(&case, String::new(), &mut paths);
        let leaves: Vec<_> = paths
            .into_iter()
            .map(|path| {
                let bound = at
                    .checked()
                    .iter()
                    .find(|(p, _)| *p == path)
                    .map(|(_, b)| *b)
                    .unwrap_or_else(|| panic!("{path} has no bound"));
                (path, bound)
            })
            .collect();
        assert!(leaves.len() >= 25, "{} numeric fields", leaves.len());
        let mut refused = 0;
        for (path, bound) in &leaves {
            // -1, 0, 1e308 where the bound excludes them; NaN as a string and a number past
            // a double's range (1e400), which no field admits.
            let mut bodies: Vec<String> = [-1.0, 0.0, 1e308]
                .into_iter()
                .filter(|v| !bound.admits(*v))
                .map(|v| json!(v).to_string())
                .collect();
            bodies.push("\"NaN\"".into());
            bodies.push("1e400".into());
            for bad in bodies {
                let mut edited = case.clone();
                *edited.pointer_mut(&pointer(path)).unwrap() = json!("__BAD__");
                let body = json!({"kind": "simulate", "params": {"config": edited}})
                    .to_string()
                    .replace("\"__BAD__\"", &bad);
                let p = api.post_job(&body).problem(422);
                let want = format!("params.config.{path}");
                let whole = want.split('[').next().unwrap().to_string();
                let field = p["field"].as_str().unwrap_or_default();
                assert!(
                    field == want || field == whole,
                    "{path} = {bad}: named `{field}`: {p}"
                );
                refused += 1;
            }
        }
        assert!(refused >= 3 * leaves.len(), "{refused}");
        // The reproduction: an amplitude of 1e308 g in the overrides.
        let p = api
            .post_job(
                &json!({"kind": "simulate", "params": {"config": "rattle-box-c", "overrides":
                    {"excitation": {"tones": [{"axis": "x", "frequency_hz": 20.0,
                    "amplitude_g": 1e308}]}}}})
                .to_string(),
            )
            .problem(422);
        assert_eq!(
            p["field"], "params.overrides.excitation.tones[0].amplitude_g",
            "{p}"
        );
        assert_eq!(stored_jobs(&api), 0, "a refusal stores nothing");
    })
    .await
    .unwrap();
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn unknown_query_parameters_roles_and_cancellation() {
    let app = TestApp::spawn_with(Runner::Library, false, |_| {}).await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // Unknown query parameters are refused on every route, naming the key.
        for (path, token) in [
            ("/v1/jobs?foo=1", Some(ENGINEER)),
            ("/v1/jobs?status=queued&stauts=failed", Some(ENGINEER)),
            ("/v1/rails?foo=", Some(PLANNER)),
            ("/v1/curves?foo=1", Some(PLANNER)),
            ("/v1/campaigns?foo=1", Some(PLANNER)),
            ("/v1/whoami?foo=1", Some(PLANNER)),
            ("/healthz?foo=1", None),
            ("/v1/openapi.json?foo=1", None),
            ("/?foo=1", None),
        ] {
            let p = api.get(path, token).problem(400);
            let want = if path.contains("stauts") {
                "stauts"
            } else {
                "foo"
            };
            assert_eq!(p["field"], want, "{path}: {p}");
        }
        // A method the document does not list on a documented route is 405, whatever its
        // query (the router's answer, not a parameter error).
        let r = api.request(
            "TRACE",
            "/v1/curves?curve_key=x&limit=1",
            Some(PLANNER),
            &[],
            None,
        );
        assert_eq!(r.status, 405, "{}", r.body);
        // Documented ones still work.
        assert_eq!(
            api.get(
                "/v1/jobs?status=queued&top_level=true&limit=5",
                Some(ENGINEER)
            )
            .status,
            200
        );

        // The role comes before the body: a planner's 10 MB job is 403, not 413.
        let big = format!(
            "{{\"kind\": \"simulate\", \"params\": {{\"config\": \"{}\"}}}}",
            "x".repeat(10 << 20)
        );
        // (On a raw connection: the server answers before reading the body.)
        api.wire("POST", "/v1/jobs", Some(PLANNER), &big)
            .problem(403);
        // An engineer's is 413 (the limit still holds).
        api.wire("POST", "/v1/jobs", Some(ENGINEER), &big)
            .problem(413);

        // Whoever started a job may cancel it: a test engineer their diagnosis.
        let id = api.upload_campaign(CAMPAIGN);
        let r = api.post(
            &format!("/v1/campaigns/{id}/diagnoses"),
            Some(TEST_ENGINEER),
            &json!({"window_s": 0.1, "settle_s": 0.02, "grid_points": 2,
                "effects": ["third_body"]})
            .to_string(),
        );
        assert_eq!(r.status, 201, "{}", r.body);
        let diagnosis = r.json()["id"].as_str().unwrap().to_string();
        // A planner, who did not start it, may not.
        api.post_empty(&format!("/v1/jobs/{diagnosis}/cancel"), Some(PLANNER))
            .problem(403);
        let r = api.post_empty(&format!("/v1/jobs/{diagnosis}/cancel"), Some(TEST_ENGINEER));
        assert_eq!(r.status, 202, "{}", r.body);
        assert_eq!(r.json()["status"], "cancelled", "{}", r.body);
        // A test engineer may not cancel a job an engineer started.
        let job = api.submit_job(
            &json!({"kind": "simulate", "params": {"config": "rattle-box-c",
                "overrides": {"simulation": {"duration_s": 0.05}}}})
            .to_string(),
        );
        api.post_empty(&format!("/v1/jobs/{job}/cancel"), Some(TEST_ENGINEER))
            .problem(403);
    })
    .await
    .unwrap();
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_request_head_hyper_refuses_is_answered_as_problem_json() {
    use std::io::{Read, Write};
    let app = TestApp::spawn_with(Runner::Library, false, |_| {}).await;
    let addr = app.api.base.trim_start_matches("http://").to_string();
    tokio::task::spawn_blocking(move || {
        // A control character (0x01) in Idempotency-Key: hyper refuses the head itself.
        let mut stream = std::net::TcpStream::connect(&addr).unwrap();
        stream
            .write_all(
                format!(
                    "POST /v1/jobs HTTP/1.1\r\nHost: {addr}\r\nAuthorization: Bearer {ENGINEER}\r\n\
                     Idempotency-Key: order\x0142\r\nContent-Type: application/json\r\n\
                     Content-Length: 2\r\n\r\n{{}}"
                )
                .as_bytes(),
            )
            .unwrap();
        let mut reply = String::new();
        stream.read_to_string(&mut reply).unwrap();
        let (head, body) = reply.split_once("\r\n\r\n").unwrap();
        assert!(head.starts_with("HTTP/1.1 400"), "{reply}");
        assert!(
            head.to_ascii_lowercase()
                .contains("content-type: application/problem+json"),
            "{reply}"
        );
        let p: Value = serde_json::from_str(body).unwrap();
        assert_eq!(p["status"], 400, "{p}");
        assert!(
            p["detail"].as_str().unwrap().contains("control character"),
            "{p}"
        );
    })
    .await
    .unwrap();
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn campaign_masses_and_names_are_bounded() {
    let app = TestApp::spawn_with(Runner::Library, false, |_| {}).await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let campaign =
            railwear::gap::Campaign::from_toml_str(CAMPAIGN, std::path::Path::new(".")).unwrap();
        let good = serde_json::to_value(&campaign).unwrap();
        let upload = |v: &Value| api.post("/v1/campaigns", Some(TEST_ENGINEER), &v.to_string());
        let mass = "/tests/0/specimens/0/increments/0/mass_loss_mg/cube";
        let mass_field = "tests[0].specimens[0].increments[0].mass_loss_mg.cube";
        // 1e308 mg; and 50 g from a cube of 2810 kg/m³ x (25.4 mm)³ = 46.05 g.
        for bad in [1e308, 50_000.0] {
            let mut v = good.clone();
            *v.pointer_mut(mass).unwrap() = json!(bad);
            let p = upload(&v).problem(422);
            assert_eq!(p["field"], mass_field, "{p}");
        }
        let mut v = good.clone();
        v["name"] = json!("x".repeat(10_000));
        assert_eq!(upload(&v).problem(422)["field"], "name");
        let r = api.get("/v1/campaigns", Some(TEST_ENGINEER)).json();
        assert_eq!(
            r["items"].as_array().map(Vec::len),
            Some(0),
            "nothing stored"
        );
        // Two tests may each have a specimen `s1`: a specimen is known by test and id.
        let mut v = good.clone();
        v["tests"][0]["specimens"][0]["id"] = json!("s1");
        v["tests"][1]["specimens"][0]["id"] = json!("s1");
        assert_eq!(upload(&v).status, 201);
    })
    .await
    .unwrap();
    app.stop().await;
}
