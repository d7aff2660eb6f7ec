//! Planner journey over HTTP (curl): measured dimensions -> rattle space at once (eq. 6.1-6.3),
//! a report that says which sweep to run, then K_SL and penalized life once the sweep's curve
//! exists (eq. 6.4); rejected measurements are 4xx problems that store nothing.
//! Sweeps here are the counting test runner's fixed curve: rail wear 2.0, 1.5, 1.0 mg/h at
//! k_rs 0.7684 (loose), 0.7990 (design), 0.8317 (tight).

mod service_support;

use railwear::analysis::rattle_space::LauncherDimensions;
use serde_json::json;
use service_support::runner::{start, test_config};
use service_support::{curl, wait_for, TempDir, ENGINEER, PLANNER};
use std::time::Duration;

fn measurement(dims: LauncherDimensions) -> String {
    json!({
        "dimensions_mm": dims,
        "measured_by": "J. Doe",
        "measured_at": "2024-05-01T08:30:00Z",
        "location": "Depot 7",
    })
    .to_string()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn measurement_report_and_penalized_life() {
    let dir = TempDir::new("rails");
    let service = start(test_config(&dir.db_url()), true).await;
    let base = format!("http://{}", service.addr);
    tokio::task::spawn_blocking(move || {
        let post = |serial: &str, body: &str| {
            curl(
                "POST",
                &format!("{base}/v1/rails/{serial}/measurements"),
                Some(PLANNER),
                &[],
                Some(body),
            )
        };
        let report = |serial: &str| {
            let r = curl(
                "GET",
                &format!("{base}/v1/rails/{serial}/report"),
                Some(PLANNER),
                &[],
                None,
            );
            assert_eq!(r.status, 200, "{}", r.body);
            r.json()
        };

        // Rattle space at once: the design rail is the thesis' 0.7990 (6.4.2).
        let r = post("R-100", &measurement(LauncherDimensions::design()));
        assert_eq!(r.status, 201, "{}", r.body);
        let k_rs = r.json()["rattle_space"].as_f64().unwrap();
        assert!((k_rs - 0.7990).abs() < 5e-5, "k_rs {k_rs}");

        // No curve yet: the report names the sweep to run.
        let rep = report("R-100");
        assert!(rep["service_life"].is_null());
        assert_eq!(
            rep["missing_curve"]["curve_key"],
            "ah64/clean/modified-archard"
        );
        assert_eq!(rep["missing_curve"]["suggested_job"]["kind"], "sweep");

        // An engineer queues that sweep: the report says it is under way.
        let sweep = r#"{"kind":"sweep","params":{"steps":20,"step_ms":100}}"#;
        let r = curl(
            "POST",
            &format!("{base}/v1/jobs"),
            Some(ENGINEER),
            &[],
            Some(sweep),
        );
        assert_eq!(r.status, 201, "{}", r.body);
        let sweep_id = r.json()["id"].as_str().unwrap().to_string();
        let rep = report("R-100");
        assert_eq!(rep["missing_curve"]["sweep_job_id"], sweep_id.as_str());
        assert!(rep["missing_curve"]["suggested_job"].is_null());

        wait_for(Duration::from_secs(30), "sweep success", || {
            let j = curl(
                "GET",
                &format!("{base}/v1/jobs/{sweep_id}"),
                Some(ENGINEER),
                &[],
                None,
            )
            .json();
            (j["status"] == "succeeded").then_some(())
        });

        // At the design point K_SL = 1 (eq. 6.4), so the penalized life is the design life.
        let rep = report("R-100");
        let life = &rep["service_life"];
        assert_eq!(life["k_sl"], 1.0, "{rep}");
        assert_eq!(life["penalized_life_h"], 1000.0);
        assert_eq!(rep["curve_job_id"], sweep_id.as_str());
        assert_eq!(rep["k_sl_curve"].as_array().unwrap().len(), 3);

        // A loose rail (k_rs 0.7684) wears 2.0 instead of 1.5 mg/h: K_SL = 1.5 / 2.0 = 0.75,
        // bands 0.675 and 0.6; with 400 h design life, 300 h.
        let r = post("R-100", &measurement(LauncherDimensions::loose()));
        assert_eq!(r.status, 201);
        let r = curl(
            "GET",
            &format!("{base}/v1/rails/R-100/report?design_life_h=400"),
            Some(PLANNER),
            &[],
            None,
        );
        let life = r.json()["service_life"].clone();
        let close = |v: &serde_json::Value, x: f64| (v.as_f64().unwrap() - x).abs() < 1e-9;
        assert!(close(&life["k_sl"], 0.75), "{life}");
        assert!(close(&life["k_sl_band_90"], 0.675), "{life}");
        assert!(close(&life["k_sl_band_80"], 0.6), "{life}");
        assert!(close(&life["penalized_life_h"], 300.0), "{life}");
        // A tight rail wears less, but K_SL never exceeds 1.
        post("R-200", &measurement(LauncherDimensions::tight()));
        assert_eq!(report("R-200")["service_life"]["k_sl"], 1.0);

        // History, newest first.
        let h = curl(
            "GET",
            &format!("{base}/v1/rails/R-100/measurements"),
            Some(PLANNER),
            &[],
            None,
        )
        .json();
        let items = h["items"].as_array().unwrap();
        assert_eq!(items.len(), 2);
        assert!(
            items[0]["rattle_space"].as_f64().unwrap() < items[1]["rattle_space"].as_f64().unwrap()
        );
        assert_eq!(items[0]["measured_by"], "J. Doe");
    })
    .await
    .unwrap();
    service.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_measurements_are_422_naming_the_field_and_store_nothing() {
    let dir = TempDir::new("badrail");
    let service = start(test_config(&dir.db_url()), false).await;
    let base = format!("http://{}", service.addr);
    tokio::task::spawn_blocking(move || {
        let url = format!("{base}/v1/rails/R-1/measurements");
        assert_eq!(
            curl(
                "POST",
                &url,
                Some(PLANNER),
                &[],
                Some(&measurement(LauncherDimensions::design()))
            )
            .status,
            201
        );
        let history = || curl("GET", &url, Some(PLANNER), &[], None).body;
        let before = history();

        let with = |f: &dyn Fn(&mut serde_json::Value)| {
            let mut v: serde_json::Value =
                serde_json::from_str(&measurement(LauncherDimensions::design())).unwrap();
            f(&mut v);
            v.to_string()
        };
        let cases: Vec<(String, &str)> = vec![
            (
                with(&|v| v["dimensions_mm"]["a_shoe_mm"] = json!(-38.1)),
                "dimensions_mm.a_shoe_mm",
            ),
            (
                with(&|v| v["dimensions_mm"]["n_rail_mm"] = json!("ten")),
                "dimensions_mm.n_rail_mm",
            ),
            // A unit mistake: inches instead of mm.
            (
                with(&|v| v["dimensions_mm"]["a_shoe_mm"] = json!(1.5)),
                "dimensions_mm.a_shoe_mm",
            ),
            (
                with(&|v| {
                    v["dimensions_mm"]
                        .as_object_mut()
                        .unwrap()
                        .remove("q_rail_mm");
                }),
                "dimensions_mm",
            ),
            (
                with(&|v| v["measured_at"] = json!("yesterday")),
                "measured_at",
            ),
            (with(&|v| v["measured_by"] = json!("  ")), "measured_by"),
            (with(&|v| v["location"] = json!("")), "location"),
            // Issue 17: days that do not exist, dates in the future.
            (
                with(&|v| v["measured_at"] = json!("2024-02-30")),
                "measured_at",
            ),
            (
                with(&|v| v["measured_at"] = json!("9999-12-31")),
                "measured_at",
            ),
            // Issue 17: the shoe head narrower than the rail slot (the missile falls out).
            (
                with(&|v| v["dimensions_mm"]["a_shoe_mm"] = json!(10.0)),
                "dimensions_mm.a_shoe_mm",
            ),
            // Issue 17: a 170 mm slot (and head) is not this rail class.
            (
                with(&|v| {
                    v["dimensions_mm"]["b_rail_mm"] = json!(170.0);
                    v["dimensions_mm"]["a_shoe_mm"] = json!(175.0);
                }),
                "dimensions_mm",
            ),
            // Issue 17: dimensions as an undocumented positional array of 14 numbers.
            (
                with(&|v| {
                    let d = LauncherDimensions::design();
                    v["dimensions_mm"] = json!([
                        d.a_shoe_mm,
                        d.f_shoe_mm,
                        d.g_shoe_mm,
                        d.h_shoe_mm,
                        d.i_shoe_mm,
                        d.j_shoe_mm,
                        d.k_shoe_mm,
                        d.l_shoe_mm,
                        d.m_shoe_mm,
                        d.n_shoe_mm,
                        d.o_shoe_mm,
                        d.b_rail_mm,
                        d.n_rail_mm,
                        d.q_rail_mm
                    ]);
                }),
                "dimensions_mm",
            ),
        ];
        for (body, field) in cases {
            let p = curl("POST", &url, Some(PLANNER), &[], Some(&body)).problem(422);
            assert!(
                p["field"].as_str().unwrap().starts_with(field),
                "expected field {field}, got {p}"
            );
        }
        let body = measurement(LauncherDimensions::design());
        curl(
            "POST",
            &format!("{base}/v1/rails/bad%20serial/measurements"),
            Some(PLANNER),
            &[],
            Some(&body),
        )
        .problem(400);
        // Issue 17: "." and ".." (and anything not starting with a letter or digit) are not
        // serials: a URL path resolves them away, so their report URL was unreachable.
        for serial in ["%2E", "%2E%2E", ".hidden", "-R1"] {
            let p = curl(
                "POST",
                &format!("{base}/v1/rails/{serial}/measurements"),
                Some(PLANNER),
                &[],
                Some(&body),
            )
            .problem(400);
            assert_eq!(p["field"], "serial", "{serial}: {p}");
        }
        let p = curl(
            "POST",
            &url,
            Some(PLANNER),
            &[],
            Some(&with(&|v| v["dimensions_mm"] = json!([38.1, 16.23]))),
        )
        .problem(422);
        assert!(p["detail"].as_str().unwrap().contains("positional"), "{p}");
        curl("POST", &url, Some(ENGINEER), &[], Some(&body)).problem(403);
        curl("POST", &url, None, &[], Some(&body)).problem(401);
        curl(
            "GET",
            &format!("{base}/v1/rails/R-404/report"),
            Some(PLANNER),
            &[],
            None,
        )
        .problem(404);
        assert_eq!(
            before,
            history(),
            "a rejected measurement changed stored data"
        );
        let rails = curl("GET", &format!("{base}/v1/rails"), Some(PLANNER), &[], None).json();
        assert_eq!(rails["items"].as_array().unwrap().len(), 1);
    })
    .await
    .unwrap();
    service.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_report_uses_the_latest_measured_at_not_the_last_recorded() {
    let dir = TempDir::new("latest");
    let service = start(test_config(&dir.db_url()), false).await;
    let base = format!("http://{}", service.addr);
    tokio::task::spawn_blocking(move || {
        let url = format!("{base}/v1/rails/R-7/measurements");
        let post = |dims: LauncherDimensions, measured_at: &str| {
            let mut v: serde_json::Value = serde_json::from_str(&measurement(dims)).unwrap();
            v["measured_at"] = json!(measured_at);
            let r = curl("POST", &url, Some(PLANNER), &[], Some(&v.to_string()));
            assert_eq!(r.status, 201, "{}", r.body);
            r.json()
        };
        let current = post(LauncherDimensions::loose(), "2024-05-01T08:30:00Z");
        // A 2019 paper reading back-filled afterwards: recorded last, measured first.
        let old = post(LauncherDimensions::design(), "2019-03-04");
        let report = curl(
            "GET",
            &format!("{base}/v1/rails/R-7/report"),
            Some(PLANNER),
            &[],
            None,
        );
        assert_eq!(report.status, 200, "{}", report.body);
        let report = report.json();
        assert_eq!(report["measurement"]["id"], current["id"], "{report}");
        assert_eq!(report["rattle_space"], current["rattle_space"]);
        // History shows both times for each measurement.
        let history = curl("GET", &url, Some(PLANNER), &[], None).json();
        let items = history["items"].as_array().unwrap();
        assert_eq!(items.len(), 2);
        for item in items {
            assert!(item["measured_at"].is_string() && item["recorded_at"].is_string());
        }
        assert!(items.iter().any(|i| i["id"] == old["id"]));
    })
    .await
    .unwrap();
    service.stop().await;
}
