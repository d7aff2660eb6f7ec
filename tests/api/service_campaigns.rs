//! Test-engineer journey over HTTP, issue 14 item 5: a campaign uploaded as JSON is
//! validated against the service's configs, stored, listed and served back unchanged; a
//! broken campaign is a 422 naming the field (down to the sample row) and stores nothing;
//! only test engineers and admins upload, every role reads.

use crate::helpers::{Api, Reply, TestApp};
use crate::support::runner::{start, test_config};
use crate::support::{temp_dir, ADMIN, ENGINEER, PLANNER, TEST_ENGINEER};
use railwear::gap::Campaign;
use serde_json::{json, Value};
use std::path::Path;

fn thesis_json() -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("campaigns/thesis-rattle-box.toml");
    let campaign = Campaign::load(&path).expect("the thesis campaign loads");
    serde_json::to_value(&campaign).expect("serializes")
}

/// `n` samples at `rate_hz` of a 20 Hz tone on x, as `[time_s, a_x, a_y, a_z]`.
fn samples(n: usize, rate_hz: f64) -> Value {
    let rows: Vec<Value> = (0..n)
        .map(|i| {
            let t = i as f64 / rate_hz;
            let a = 147.1 * (2.0 * std::f64::consts::PI * 20.0 * t).sin();
            json!([t, a, 0.01 * a, -0.002 * a])
        })
        .collect();
    Value::Array(rows)
}

/// The thesis campaign with input and response records (2000 samples each at 1 kHz) on case
/// C's specimen: well over the 64 KiB general body limit of the test service.
fn with_records() -> Value {
    let mut c = thesis_json();
    c["name"] = json!("rattle-box-with-accelerometers");
    c["tests"][2]["specimens"][0]["accelerometers"] = json!([
        {"increment": 1, "location": "input", "sample_rate_hz": 1000.0,
         "sensor_noise_m_s2": 0.05, "samples": samples(2000, 1000.0)},
        {"increment": 2, "location": "response", "sample_rate_hz": 1000.0,
         "sensor_noise_m_s2": 0.05, "csv": "c1-inc2-response.csv",
         "samples": samples(2000, 1000.0)},
    ]);
    c
}

/// The campaign routes of one service.
struct Campaigns(Api);

impl Campaigns {
    fn post(&self, token: Option<&str>, body: &str) -> Reply {
        self.0.post("/v1/campaigns", token, body)
    }

    fn get(&self, token: Option<&str>, path: &str) -> Reply {
        self.0.get(path, token)
    }

    /// Every stored campaign (all pages), as the planner sees them.
    fn list_all(&self) -> Vec<Value> {
        let mut out = Vec::new();
        let mut cursor: Option<String> = None;
        loop {
            let path = match &cursor {
                None => "/v1/campaigns?limit=2".to_string(),
                Some(c) => format!("/v1/campaigns?limit=2&cursor={c}"),
            };
            let r = self.get(Some(PLANNER), &path);
            assert_eq!(r.status, 200, "{}", r.body);
            let page = r.json();
            out.extend(page["items"].as_array().expect("items").iter().cloned());
            match page["next_cursor"].as_str() {
                Some(c) => cursor = Some(c.to_string()),
                None => return out,
            }
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn campaigns_round_trip_and_list() {
    let dir = temp_dir("campaigns");
    let service = start(test_config(&dir.db_url()), false).await;
    let api = Campaigns(Api::new(&format!("http://{}", service.addr)));
    tokio::task::spawn_blocking(move || {
        // The thesis campaign goes in and comes back unchanged.
        let thesis = thesis_json();
        let r = api.post(Some(TEST_ENGINEER), &thesis.to_string());
        assert_eq!(r.status, 201, "{}", r.body);
        let created = r.json();
        let location = r.header("location").expect("Location").to_string();
        assert_eq!(
            location,
            format!("/v1/campaigns/{}", created["id"].as_str().unwrap())
        );
        assert_eq!(created["links"]["self"], location.as_str());
        assert_eq!(created["name"], "thesis-rattle-box");
        assert_eq!(created["created_by"], "lab");
        assert_eq!(
            created["counts"],
            json!({"tests": 4, "specimens": 4, "increments": 8, "accelerometer_records": 0})
        );
        for token in [PLANNER, ENGINEER, TEST_ENGINEER, ADMIN] {
            let got = api.get(Some(token), &location);
            assert_eq!(got.status, 200, "{}", got.body);
            assert_eq!(got.header("content-type"), Some("application/json"));
            assert_eq!(got.json(), thesis, "the stored campaign is what was sent");
            assert_eq!(
                got.header("etag"),
                Some(format!("\"{}\"", created["content_sha256"].as_str().unwrap()).as_str())
            );
            assert_eq!(
                got.body.len() as i64,
                created["content_bytes"].as_i64().unwrap()
            );
        }
        // The text served parses back to the same campaign.
        let got = api.get(Some(PLANNER), &location);
        assert_eq!(
            Campaign::from_json_str(&got.body).expect("parses"),
            serde_json::from_value::<Campaign>(thesis.clone()).expect("parses")
        );

        // The same content again (pretty-printed this time) is not stored twice.
        let pretty = serde_json::to_string_pretty(&thesis).unwrap();
        let r = api.post(Some(TEST_ENGINEER), &pretty);
        assert_eq!(r.status, 200, "{}", r.body);
        assert_eq!(r.json()["id"], created["id"]);
        assert_eq!(r.header("content-location"), Some(location.as_str()));

        // A campaign with accelerometer records: far over the general 64 KiB body limit,
        // within the campaign route's own; an admin may upload too.
        let records = with_records();
        let body = records.to_string();
        assert!(body.len() > 64 * 1024, "{} bytes", body.len());
        let r = api.post(Some(ADMIN), &body);
        assert_eq!(r.status, 201, "{}", r.body);
        let second = r.json();
        assert_eq!(second["counts"]["accelerometer_records"], 2);
        assert_eq!(second["created_by"], "root");
        let got = api.get(Some(ENGINEER), second["links"]["self"].as_str().unwrap());
        assert_eq!(got.status, 200);
        assert_eq!(got.json(), records);

        // Newest first, summaries only, paginated.
        let list = api.list_all();
        assert_eq!(list.len(), 2);
        assert_eq!(list[0]["id"], second["id"]);
        assert_eq!(list[1]["id"], created["id"]);
        assert!(list
            .iter()
            .all(|c| c.get("tests").is_none() && c["counts"].is_object()));
        let r = api.get(Some(PLANNER), "/v1/campaigns?limit=1");
        let page = r.json();
        assert_eq!(page["items"].as_array().unwrap().len(), 1);
        assert!(page["next_cursor"].is_string());
        api.get(Some(PLANNER), "/v1/campaigns?limit=0").problem(400);

        // Unknown and malformed ids.
        let p = api
            .get(
                Some(PLANNER),
                "/v1/campaigns/00000000-0000-4000-8000-000000000000",
            )
            .problem(404);
        assert!(p["detail"].as_str().unwrap().contains("00000000"));
        let p = api
            .get(Some(PLANNER), "/v1/campaigns/not-a-uuid")
            .problem(400);
        assert_eq!(p["field"], "id");
    })
    .await
    .unwrap();
    service.stop().await;
}

/// Each bad campaign: how to break the thesis campaign (with records) and the field the 422
/// must name.
fn bad_campaigns() -> Vec<(&'static str, Value, String)> {
    let base = with_records();
    let rec = "tests[2].specimens[0].accelerometers[0]";
    let mut out = Vec::new();

    let mut c = base.clone();
    c["tests"][1]["config"] = json!("rattle-box-z");
    out.push(("unknown config", c, "tests[1].config".to_string()));

    let mut c = base.clone();
    c["tests"][3]["specimens"][0]["increments"][2]["mass_loss_mg"]["cube"] = json!(-0.05);
    out.push((
        "negative mass",
        c,
        "tests[3].specimens[0].increments[2].mass_loss_mg.cube".to_string(),
    ));

    let mut c = base.clone();
    // Row 1500 goes back in time.
    c["tests"][2]["specimens"][0]["accelerometers"][0]["samples"][1500][0] = json!(1.2);
    out.push(("time not increasing", c, format!("{rec}.samples[1500]")));

    let mut c = base.clone();
    // Samples 1 ms apart declared at 500 Hz: the first step is off.
    c["tests"][2]["specimens"][0]["accelerometers"][0]["sample_rate_hz"] = json!(500.0);
    out.push(("sample rate mismatch", c, format!("{rec}.samples[1]")));

    let mut c = base.clone();
    // Row 7 has three columns instead of four.
    c["tests"][2]["specimens"][0]["accelerometers"][0]["samples"][7] = json!([0.007, 1.0, 2.0]);
    out.push(("three columns", c, format!("{rec}.samples[7]")));

    let mut c = base.clone();
    c["tests"][2]["specimens"][0]["accelerometers"][1]["samples"][3] =
        json!([0.003, 1.0, 2.0, 3.0, 4.0]);
    out.push((
        "five columns",
        c,
        "tests[2].specimens[0].accelerometers[1].samples[3]".to_string(),
    ));

    let mut c = base.clone();
    c["tests"][0]["specimens"][0]["weight_g"] = json!(12.0);
    out.push((
        "unknown key",
        c,
        "tests[0].specimens[0].weight_g".to_string(),
    ));

    let mut c = base;
    c["format_version"] = json!(2);
    out.push(("format version", c, "format_version".to_string()));
    out
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_campaigns_name_field_and_row_and_store_nothing() {
    let dir = temp_dir("campaigns-bad");
    let mut config = test_config(&dir.db_url());
    config.campaign_body_limit_bytes = 1024 * 1024;
    let service = start(config, false).await;
    let api = Campaigns(Api::new(&format!("http://{}", service.addr)));
    tokio::task::spawn_blocking(move || {
        let r = api.post(Some(TEST_ENGINEER), &thesis_json().to_string());
        assert_eq!(r.status, 201, "{}", r.body);
        let before = api.list_all();
        assert_eq!(before.len(), 1);

        for (what, campaign, field) in bad_campaigns() {
            let p = api
                .post(Some(TEST_ENGINEER), &campaign.to_string())
                .problem(422);
            assert_eq!(p["field"], field.as_str(), "{what}: {p}");
            let detail = p["detail"].as_str().unwrap();
            assert!(detail.contains(&field), "{what}: {detail}");
        }
        // What the rules say, in words.
        let cases = bad_campaigns();
        let detail = |i: usize| {
            api.post(Some(TEST_ENGINEER), &cases[i].1.to_string())
                .problem(422)["detail"]
                .as_str()
                .unwrap()
                .to_string()
        };
        assert!(
            detail(0).contains("unknown config `rattle-box-z`"),
            "{}",
            detail(0)
        );
        assert!(detail(1).contains(">= 0 mg"), "{}", detail(1));
        assert!(
            detail(2).contains("time must increase strictly"),
            "{}",
            detail(2)
        );
        assert!(detail(3).contains("sample_rate_hz 500"), "{}", detail(3));
        assert!(detail(4).contains("length 3"), "{}", detail(4));

        // Malformed JSON, a non-JSON body, an empty object, a body over the campaign limit.
        let p = api.post(Some(TEST_ENGINEER), "{\"name\": ").problem(400);
        assert_eq!(p["type"], "urn:railwear:problem:malformed-json");
        let r = api.0.request(
            "POST",
            "/v1/campaigns",
            Some(TEST_ENGINEER),
            &[("Content-Type", "text/csv")],
            Some("time_s,a_x_m_s2\n"),
        );
        r.problem(415);
        let p = api.post(Some(TEST_ENGINEER), "{}").problem(422);
        assert_eq!(p["field"], "campaign");
        let mut huge = with_records();
        huge["tests"][2]["specimens"][0]["accelerometers"][0]["samples"] = samples(150_000, 1000.0);
        let huge = huge.to_string();
        // Several times the limit: the client is still sending when the server has seen
        // enough, and must still hear the 413 (the server drains the rest first).
        assert!(huge.len() > 3 * 1024 * 1024, "{}", huge.len());
        api.post(Some(TEST_ENGINEER), &huge).problem(413);

        assert_eq!(api.list_all(), before, "refused uploads store nothing");
    })
    .await
    .unwrap();
    service.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn only_test_engineers_and_admins_upload() {
    let app = TestApp::spawn_idle().await;
    let api = Campaigns(app.api.clone());
    tokio::task::spawn_blocking(move || {
        let good = thesis_json().to_string();
        // The role is checked before the body is read: a planner gets 403 whatever it sends.
        for body in [good.as_str(), "not json at all", "{}"] {
            for token in [PLANNER, ENGINEER] {
                let p = api.post(Some(token), body).problem(403);
                assert!(p["detail"].as_str().unwrap().contains("campaigns"), "{p}");
            }
        }
        // No token, or an unknown one: 401 on every route.
        api.post(None, &good).problem(401);
        api.post(Some("unknown-token-0123456789abcdef"), &good)
            .problem(401);
        api.get(None, "/v1/campaigns").problem(401);
        api.get(None, "/v1/campaigns/00000000-0000-4000-8000-000000000000")
            .problem(401);
        assert!(api.list_all().is_empty());
        let r = api.post(Some(TEST_ENGINEER), &good);
        assert_eq!(r.status, 201, "{}", r.body);
    })
    .await
    .unwrap();
    app.stop().await;
}
