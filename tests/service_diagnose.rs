//! Diagnosis over HTTP (issue 15 item 4): a test engineer uploads a small campaign, posts a
//! diagnosis, follows the job to the end and reads the report and its SVG figures; planners
//! may not diagnose; bad params are 422s naming the field; an unknown campaign is a 404.

mod service_support;

use railwear::gap::Campaign;
use railwear::jobs::LibraryRunner;
use serde_json::{json, Value};
use service_support::runner::test_config;
use service_support::{curl, TempDir, PLANNER, TEST_ENGINEER};
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

const CAMPAIGN: &str = r#"
format_version = 1
name = "small-diagnosis-http"
[[tests]]
id = "C"
config = "rattle-box-c"
increment_duration_s = 5400.0
scale_resolution_mg = 0.0001
components = ["cube"]
[[tests.specimens]]
id = "C-1"
increments = [{ mass_loss_mg = { cube = 0.004 } }, { mass_loss_mg = { cube = 0.005 } }]
[[tests]]
id = "D"
config = "rattle-box-d"
increment_duration_s = 5400.0
scale_resolution_mg = 0.0001
components = ["cube"]
[[tests.specimens]]
id = "D-1"
increments = [{ mass_loss_mg = { cube = 0.002 } }, { mass_loss_mg = { cube = 0.003 } }]
"#;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_test_engineer_diagnoses_a_campaign_over_http() {
    let dir = TempDir::new("diagnose");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let service = railwear::http::start(
        test_config(&dir.db_url()),
        Arc::new(LibraryRunner {
            configs_dir: root.join("configs"),
        }),
        true,
    )
    .await
    .expect("service starts");
    let base = format!("http://{}", service.addr);
    tokio::task::spawn_blocking(move || {
        let campaign = Campaign::from_toml_str(CAMPAIGN, Path::new(".")).expect("campaign");
        let body = serde_json::to_string(&campaign).unwrap();
        let r = curl(
            "POST",
            &format!("{base}/v1/campaigns"),
            Some(TEST_ENGINEER),
            &[],
            Some(&body),
        );
        assert_eq!(r.status, 201, "{}", r.body);
        let id = r.json()["id"].as_str().unwrap().to_string();
        let url = format!("{base}/v1/campaigns/{id}/diagnoses");
        let post = |token: &str, body: &Value| {
            curl("POST", &url, Some(token), &[], Some(&body.to_string()))
        };

        // Who and what is refused.
        let good =
            json!({"window_s": 0.1, "settle_s": 0.02, "grid_points": 2, "effects": ["third_body"]});
        post(PLANNER, &good).problem(403);
        for (bad, field) in [
            (json!({"window_s": 0}), "window_s"),
            (json!({"effects": ["third_body", "gremlins"]}), "effects[1]"),
            (json!({"colour": "red"}), "colour"),
            (json!({"campaign": {}}), "campaign"),
            (json!({"grid_points": 20}), "grid_points"),
        ] {
            let p = post(TEST_ENGINEER, &bad).problem(422);
            assert_eq!(p["field"], field, "{p}");
        }
        let unknown = format!("{base}/v1/campaigns/{}/diagnoses", uuid::Uuid::new_v4());
        curl(
            "POST",
            &unknown,
            Some(TEST_ENGINEER),
            &[],
            Some(&good.to_string()),
        )
        .problem(404);

        // The diagnosis runs as a job.
        let r = post(TEST_ENGINEER, &good);
        assert_eq!(r.status, 201, "{}", r.body);
        let job = r.json();
        assert_eq!(job["kind"], "diagnose");
        assert_eq!(job["params"]["campaign_id"], id.as_str());
        assert!(
            job["params"].get("campaign").is_none(),
            "the view leaves the content out"
        );
        let job_url = format!("{base}/v1/jobs/{}", job["id"].as_str().unwrap());
        let deadline = Instant::now() + Duration::from_secs(300);
        let done = loop {
            let j = curl("GET", &job_url, Some(PLANNER), &[], None).json();
            match j["status"].as_str().unwrap() {
                "succeeded" => break j,
                "failed" | "cancelled" => panic!("diagnosis ended: {j}"),
                _ => {}
            }
            assert!(Instant::now() < deadline, "diagnosis did not finish: {j}");
            std::thread::sleep(Duration::from_millis(200));
        };
        assert_eq!(done["progress"]["fraction"], 1.0, "{done}");

        let r = curl(
            "GET",
            &format!("{job_url}/result"),
            Some(TEST_ENGINEER),
            &[],
            None,
        );
        assert_eq!(r.status, 200, "{}", r.body);
        let result = r.json();
        let report = &result["summary"];
        let verdict = report["verdict"].as_str().unwrap();
        assert!(
            ["no_gap", "explained", "not_explained"].contains(&verdict),
            "{verdict}"
        );
        assert!(report["ranking"]
            .as_array()
            .unwrap()
            .iter()
            .any(|e| e["name"] == "third_body"));
        assert!(!report["where"]["groups"].as_array().unwrap().is_empty());
        let plots = result["plots"].as_array().unwrap();
        assert!(!plots.is_empty(), "{result}");
        let r = curl(
            "GET",
            &format!("{base}{}", plots[0]["url"].as_str().unwrap()),
            Some(TEST_ENGINEER),
            &[],
            None,
        );
        assert_eq!(r.status, 200);
        assert_eq!(r.header("content-type"), Some("image/svg+xml"));
        assert!(r.body.contains("<svg"));
    })
    .await
    .unwrap();
    service.stop().await;
}
