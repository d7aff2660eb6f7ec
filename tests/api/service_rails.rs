//! Planner journey over HTTP: measured dimensions -> rattle space at once (eq. 6.1-6.3),
//! a report that says which sweep to run, then K_SL and penalized life once the sweep's curve
//! exists (eq. 6.4); rejected measurements are 4xx problems that store nothing.
//! Sweeps here are the counting test runner's fixed curve: rail wear 2.0, 1.5, 1.0 mg/h at
//! k_rs 0.7684 (loose), 0.7990 (design), 0.8317 (tight).

use crate::helpers::{wait_for, Api, TestApp};
use crate::support::runner::{start, test_config};
use crate::support::{temp_dir, ENGINEER, PLANNER};
use railwear::analysis::rattle_space::LauncherDimensions;
use serde_json::json;
use std::time::Duration;

pub(crate) fn measurement(dims: LauncherDimensions) -> String {
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
    let app = TestApp::spawn().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let post = |serial: &str, body: &str| api.post_rail(serial, body);
        let report = |serial: &str| {
            let r = api.rail_report(serial);
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
        let r = api.post("/v1/jobs", Some(ENGINEER), sweep);
        assert_eq!(r.status, 201, "{}", r.body);
        let sweep_id = r.json()["id"].as_str().unwrap().to_string();
        let rep = report("R-100");
        assert_eq!(rep["missing_curve"]["sweep_job_id"], sweep_id.as_str());
        assert!(rep["missing_curve"]["suggested_job"].is_null());

        wait_for(Duration::from_secs(30), "sweep success", || {
            let j = api
                .get(&format!("/v1/jobs/{sweep_id}"), Some(ENGINEER))
                .json();
            (j["status"] == "succeeded").then_some(())
        });

        // The sweep stored a curve version, but reports use it only once an engineer publishes
        // it: until then the report names the version to publish.
        let rep = report("R-100");
        assert!(rep["service_life"].is_null(), "{rep}");
        let curve_id = rep["missing_curve"]["unpublished_curve_id"]
            .as_i64()
            .expect("the unpublished version is named");
        let r = api.post_empty(&format!("/v1/curves/{curve_id}/publish"), Some(PLANNER));
        r.problem(403);
        let r = api.post_empty(&format!("/v1/curves/{curve_id}/publish"), Some(ENGINEER));
        assert_eq!(r.status, 200, "{}", r.body);

        // At the design point K_SL = 1 (eq. 6.4), so the penalized life is the design life.
        let rep = report("R-100");
        let life = &rep["service_life"];
        assert_eq!(life["k_sl"], 1.0, "{rep}");
        assert_eq!(life["penalized_life_h"], 1000.0);
        assert_eq!(rep["curve_job_id"], sweep_id.as_str());
        assert_eq!(rep["curve"]["id"], curve_id);
        assert_eq!(rep["curve"]["version"], 1);
        assert_eq!(rep["curve"]["fidelity"]["points"], 3);
        assert_eq!(rep["k_sl_curve"].as_array().unwrap().len(), 3);

        // A loose rail (k_rs 0.7684) wears 2.0 instead of 1.5 mg/h: K_SL = 1.5 / 2.0 = 0.75,
        // bands 0.675 and 0.6; with 400 h design life, 300 h.
        let r = post("R-100", &measurement(LauncherDimensions::loose()));
        assert_eq!(r.status, 201);
        let r = api.get("/v1/rails/R-100/report?design_life_h=400", Some(PLANNER));
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
        let h = api
            .get("/v1/rails/R-100/measurements", Some(PLANNER))
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
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_measurements_are_422_naming_the_field_and_store_nothing() {
    let app = TestApp::spawn_idle().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let url = "/v1/rails/R-1/measurements";
        assert_eq!(
            api.post(
                url,
                Some(PLANNER),
                &measurement(LauncherDimensions::design())
            )
            .status,
            201
        );
        let history = || api.get(url, Some(PLANNER)).body;
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
            let p = api.post(url, Some(PLANNER), &body).problem(422);
            assert!(
                p["field"].as_str().unwrap().starts_with(field),
                "expected field {field}, got {p}"
            );
        }
        let body = measurement(LauncherDimensions::design());
        api.post("/v1/rails/bad%20serial/measurements", Some(PLANNER), &body)
            .problem(400);
        // Issue 17: "." and ".." (and anything not starting with a letter or digit) are not
        // serials: a URL path resolves them away, so their report URL was unreachable.
        // (On a raw connection: a conforming client resolves `%2E` segments away.)
        for serial in ["%2E", "%2E%2E", ".hidden", "-R1"] {
            let p = api
                .wire(
                    "POST",
                    &format!("/v1/rails/{serial}/measurements"),
                    Some(PLANNER),
                    &body,
                )
                .problem(400);
            assert_eq!(p["field"], "serial", "{serial}: {p}");
        }
        let p = api
            .post(
                url,
                Some(PLANNER),
                &with(&|v| v["dimensions_mm"] = json!([38.1, 16.23])),
            )
            .problem(422);
        assert!(p["detail"].as_str().unwrap().contains("positional"), "{p}");
        api.post(url, Some(ENGINEER), &body).problem(403);
        api.post(url, None, &body).problem(401);
        api.rail_report("R-404").problem(404);
        assert_eq!(
            before,
            history(),
            "a rejected measurement changed stored data"
        );
        let rails = api.get("/v1/rails", Some(PLANNER)).json();
        assert_eq!(rails["items"].as_array().unwrap().len(), 1);
    })
    .await
    .unwrap();
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_report_uses_the_latest_measured_at_not_the_last_recorded() {
    let dir = temp_dir("latest");
    let service = start(test_config(&dir.db_url()), false).await;
    let api = Api::new(&format!("http://{}", service.addr));
    tokio::task::spawn_blocking(move || {
        let url = "/v1/rails/R-7/measurements";
        let post = |dims: LauncherDimensions, measured_at: &str| {
            let mut v: serde_json::Value = serde_json::from_str(&measurement(dims)).unwrap();
            v["measured_at"] = json!(measured_at);
            let r = api.post(url, Some(PLANNER), &v.to_string());
            assert_eq!(r.status, 201, "{}", r.body);
            r.json()
        };
        let current = post(LauncherDimensions::loose(), "2024-05-01T08:30:00Z");
        // A 2019 paper reading back-filled afterwards: recorded last, measured first.
        let old = post(LauncherDimensions::design(), "2019-03-04");
        let report = api.rail_report("R-7");
        assert_eq!(report.status, 200, "{}", report.body);
        let report = report.json();
        assert_eq!(report["measurement"]["id"], current["id"], "{report}");
        assert_eq!(report["rattle_space"], current["rattle_space"]);
        // History shows both times for each measurement.
        let history = api.get(url, Some(PLANNER)).json();
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

fn report_of(api: &Api, serial: &str) -> serde_json::Value {
    let r = api.rail_report(serial);
    assert_eq!(r.status, 200, "{}", r.body);
    r.json()
}

pub(crate) fn run_sweep(api: &Api, body: &str) -> String {
    let r = api.post("/v1/jobs", Some(ENGINEER), body);
    assert_eq!(r.status, 201, "{}", r.body);
    let id = r.json()["id"].as_str().unwrap().to_string();
    wait_for(Duration::from_secs(30), "sweep success", || {
        let j = api.get(&format!("/v1/jobs/{id}"), Some(ENGINEER)).json();
        assert_ne!(j["status"], "failed", "{j}");
        (j["status"] == "succeeded").then_some(())
    });
    id
}

pub(crate) fn publish(api: &Api, id: i64, body: Option<&str>) -> crate::helpers::Reply {
    api.request(
        "POST",
        &format!("/v1/curves/{id}/publish"),
        Some(ENGINEER),
        &[],
        body,
    )
}

/// Issue 17 item 2: rails outside the swept range (k_rs 0.643, looser; 0.861, tighter than
/// the design family reaches) get a suggested sweep whose range covers them (before: the same
/// default sweep forever); running and publishing it gives them a service life.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_rail_outside_every_curve_gets_a_sweep_that_covers_it() {
    let dir = temp_dir("rails-range");
    let service = start(test_config(&dir.db_url()), true).await;
    let api = Api::new(&format!("http://{}", service.addr));
    tokio::task::spawn_blocking(move || {
        let post = |serial: &str, dims: LauncherDimensions| {
            let r = api.post_rail(serial, &measurement(dims));
            assert_eq!(r.status, 201, "{}", r.body);
            r.json()["rattle_space"].as_f64().unwrap()
        };
        // A loose rail (material condition +1.075 mm) and a tight one whose head nearly fills the
        // chamber (not a uniform offset of the design rail).
        let loose = post(
            "R-LOOSE",
            LauncherDimensions::design().with_material_condition(1.075),
        );
        assert!((loose - 0.643).abs() < 0.003, "{loose}");
        let mut tight_dims = LauncherDimensions::design().with_material_condition(-0.28);
        tight_dims.f_shoe_mm -= 1.0;
        tight_dims.h_shoe_mm -= 1.0;
        tight_dims.j_shoe_mm -= 1.0;
        tight_dims.l_shoe_mm -= 1.0;
        let tight = post("R-TIGHT", tight_dims);
        assert!(tight > 0.855, "{tight}");
        let design_k = LauncherDimensions::design().rattle_space().unwrap();

        // The default sweep's curve, published, covers neither.
        let id = run_sweep(&api, r#"{"kind":"sweep","params":{"steps":1,"step_ms":1}}"#);
        let rep = report_of(&api, "R-LOOSE");
        // Stored but not published, and it would not cover the rail anyway.
        assert!(
            rep["missing_curve"]["unpublished_curve_id"].is_null(),
            "{rep}"
        );
        let list = api.get("/v1/curves", Some(ENGINEER)).json();
        let v1 = list["items"][0]["id"].as_i64().unwrap();
        assert_eq!(publish(&api, v1, None).status, 200);
        for (serial, k) in [("R-LOOSE", loose), ("R-TIGHT", tight)] {
            let rep = report_of(&api, serial);
            assert!(rep["service_life"].is_null(), "{rep}");
            // The published curve (the default sweep's, then the loose rail's) is named.
            assert!(rep["curve"]["id"].is_i64(), "{rep}");
            if serial == "R-LOOSE" {
                assert_eq!(rep["curve"]["job_id"], id.as_str());
            }
            let job = &rep["missing_curve"]["suggested_job"];
            assert_eq!(job["kind"], "sweep", "{rep}");
            let params = &job["params"];
            // The suggestion covers the rail and the design point, and is a sweep the service
            // plans as such.
            let range = railwear::pipeline::SweepRange::from_params(params)
                .unwrap_or_else(|e| panic!("{e}: {params}"));
            let (lo, hi) = range.rattle_space_bounds();
            assert!(lo <= k && k <= hi, "{serial}: {k} not in [{lo}, {hi}]");
            assert!(lo <= design_k && design_k <= hi);
            if serial == "R-TIGHT" {
                // The design family stops at zero vertical clearance (k_rs 0.848): the sweep
                // runs around the rail's own dimensions.
                assert!(params["base_dimensions_mm"].is_object(), "{params}");
            }
            // Run it (the counting runner's closed-form curve over the planned points), then
            // the report names it as the version to publish.
            let sweep = run_sweep(&api, &job.to_string());
            let rep = report_of(&api, serial);
            let v = rep["missing_curve"]["unpublished_curve_id"]
                .as_i64()
                .unwrap_or_else(|| panic!("{rep}"));
            let r = publish(&api, v, None);
            assert_eq!(r.status, 200, "{}", r.body);
            let rep = report_of(&api, serial);
            let life = &rep["service_life"];
            assert!(life["k_sl"].as_f64().is_some(), "{rep}");
            assert_eq!(rep["curve"]["id"], v);
            assert_eq!(rep["curve"]["job_id"], sweep.as_str());
        }
    })
    .await
    .unwrap();
    service.stop().await;
}

/// Issue 17 item 4: a new sweep does not replace the curve planners read; publishing a
/// lower-fidelity version over a higher one needs `force` (409 naming the field otherwise);
/// the report names the curve, its fidelity, and carries K_SL's interval over seeds.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn curves_are_published_explicitly_with_fidelity_and_an_interval() {
    let app = TestApp::spawn().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let dims = LauncherDimensions::design().with_material_condition(0.1);
        let r = api.post_rail("R-7", &measurement(dims));
        assert_eq!(r.status, 201, "{}", r.body);
        let k = r.json()["rattle_space"].as_f64().unwrap();
        let kd = LauncherDimensions::design().rattle_space().unwrap();

        // Production curve: 5 points, 3 seeds, 10 s per point; published.
        run_sweep(
            &api,
            r#"{"kind":"sweep","params":{"steps":1,"step_ms":1,"rattle_space_range":{"min":0.76,"max":0.84},"points":5,"seeds":3,"duration_s":10}}"#,
        );
        let list = api.get("/v1/curves", Some(PLANNER)).json();
        let v1 = &list["items"][0];
        assert_eq!(v1["version"], 1);
        assert_eq!(v1["published"], false);
        assert_eq!(v1["created_by"], "eng");
        assert!(v1["code_version"].as_str().is_some_and(|v| !v.is_empty()));
        assert_eq!(v1["fidelity"]["seeds"], 3);
        let v1 = v1["id"].as_i64().unwrap();
        assert_eq!(publish(&api, v1, Some(r#"{"force":false}"#)).status, 200);
        let rep = report_of(&api, "R-7");
        let life = rep["service_life"].clone();
        assert_eq!(rep["curve"]["id"], v1);
        assert_eq!(rep["curve"]["fidelity"]["points"], 5);
        assert_eq!(rep["curve"]["fidelity"]["seeds"], 3);
        assert_eq!(rep["curve"]["fidelity"]["duration_per_point_s"], 10.0);
        assert_eq!(rep["curve"]["published_by"], "eng");

        // K_SL's 90 % interval against the closed form: seed j's log ratio is
        // -(8 + 0.5 j)(kd - k), so over 3 seeds the mean is -8.5 (kd - k), the standard
        // deviation 0.5 (kd - k), and the half width t(0.95; 2) 0.5 (kd - k) / sqrt(3).
        let d = kd - k;
        let half = 2.919986 * 0.5 * d / 3f64.sqrt();
        let close = |v: &serde_json::Value, x: f64| (v.as_f64().unwrap() - x).abs() < 1e-6;
        assert!(close(&life["k_sl"], (-8.5 * d).exp()), "{life}");
        let i = &life["interval"];
        assert_eq!(i["confidence"], 0.9);
        assert_eq!(i["seeds"], 3);
        assert!(close(&i["k_sl_low"], (-8.5 * d - half).exp()), "{i}");
        assert!(close(&i["k_sl_high"], (-8.5 * d + half).exp()), "{i}");
        assert!(close(&i["penalized_life_low_h"], 1000.0 * (-8.5 * d - half).exp()));
        assert!(close(&i["penalized_life_high_h"], 1000.0 * (-8.5 * d + half).exp()));

        // A 2-point, 1-seed, 0.3 s trial sweep stores version 2 and changes nothing planners
        // read.
        run_sweep(
            &api,
            r#"{"kind":"sweep","params":{"steps":1,"step_ms":1,"rattle_space_range":{"min":0.78,"max":0.82},"points":2,"seeds":1,"duration_s":0.3}}"#,
        );
        let rep = report_of(&api, "R-7");
        assert_eq!(rep["curve"]["id"], v1);
        assert_eq!(rep["service_life"], life);
        let list = api.get("/v1/curves?curve_key=ah64/clean/modified-archard", Some(ENGINEER))
        .json();
        let v2 = &list["items"][0];
        assert_eq!((v2["version"].as_i64(), v2["published"].as_bool()), (Some(2), Some(false)));
        let v2 = v2["id"].as_i64().unwrap();
        // Issue 26 item 7: the report compares K_SL under another stored curve, here the
        // 1-seed trial (unpublished): seed 0's log ratio is -8 (kd - k), so K_SL = e^(-8 d),
        // and its ratio to the published curve's e^(-8.5 d) is e^(0.5 d).
        let r = api.get(
            &format!("/v1/rails/R-7/report?compare={v2}"),
            Some(PLANNER),
        );
        assert_eq!(r.status, 200, "{}", r.body);
        let rep = r.json();
        assert_eq!(rep["service_life"], life, "the report's own curve is unchanged");
        let c = &rep["comparison"];
        assert_eq!(c["curve_id"], v2);
        assert_eq!(c["published"], false);
        assert!(close(&c["k_sl"], (-8.0 * d).exp()), "{c}");
        assert!(close(&c["penalized_life_h"], 1000.0 * (-8.0 * d).exp()), "{c}");
        assert!(close(&c["k_sl_ratio"], (0.5 * d).exp()), "{c}");
        // A curve id that is not stored is a 422 naming `compare`; a malformed one a 400.
        let p = api
            .get("/v1/rails/R-7/report?compare=999999", Some(PLANNER))
            .problem(422);
        assert_eq!(p["field"], "compare");
        let p = api
            .get("/v1/rails/R-7/report?compare=abc", Some(PLANNER))
            .problem(400);
        assert_eq!(p["field"], "compare");
        // Publishing it over the 5-point curve is refused without force.
        let p = publish(&api, v2, None).problem(409);
        assert_eq!(p["field"], "force");
        assert!(p["detail"].as_str().unwrap().contains("2 points < 5"), "{p}");
        assert_eq!(report_of(&api, "R-7")["curve"]["id"], v1);
        // Unknown keys and bad ids are refused naming the field.
        // JSON `null` (the document allows it: the body is optional) is no force either.
        let p = publish(&api, v2, Some("null")).problem(409);
        assert_eq!(p["field"], "force");
        let p = publish(&api, v2, Some(r#"{"forse":true}"#)).problem(422);
        assert!(p["detail"].as_str().unwrap().contains("forse"), "{p}");
        publish(&api, 0, None).problem(400);
        publish(&api, 999_999, None).problem(404);
        // With force it is published; the report says so and has no interval (one seed).
        let r = publish(&api, v2, Some(r#"{"force":true}"#));
        assert_eq!(r.status, 200, "{}", r.body);
        let rep = report_of(&api, "R-7");
        assert_eq!(rep["curve"]["id"], v2);
        assert_eq!(rep["curve"]["fidelity"]["seeds"], 1);
        assert!(rep["service_life"]["interval"].is_null(), "{rep}");
        assert!(rep["service_life"]["uncertainty"]
            .as_str()
            .unwrap()
            .contains("one seed"));
        let one = api.get(&format!("/v1/curves/{v1}"), Some(PLANNER)).json();
        assert_eq!(one["published"], false);
        assert_eq!(one["provenance"]["created_by"], "eng");
    })
    .await
    .unwrap();
    app.stop().await;
}

/// Issue 17: a report query naming a vehicle profile, environment or wear law no sweep can run
/// is a 422 naming the parameter (it would stay at missing_curve forever); a malformed design
/// life or an unknown or repeated parameter is a 400 naming it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn report_labels_must_name_what_a_sweep_runs() {
    let app = TestApp::spawn_idle().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let r = api.post_rail("R-7", &measurement(LauncherDimensions::design()));
        assert_eq!(r.status, 201, "{}", r.body);
        let get = |query: &str| api.get(&format!("/v1/rails/R-7/report?{query}"), Some(PLANNER));
        for (query, field, words) in [
            (
                "vehicle_profile=uh60",
                "vehicle_profile",
                "`uh60` is not a vehicle profile",
            ),
            ("environment=sand", "environment", "`sand` is not modelled"),
            (
                "wear_law=totally-made-up",
                "wear_law",
                "`totally-made-up` is not a wear law",
            ),
            (
                "environment=clean&wear_law=Archard",
                "wear_law",
                "(known: modified-archard",
            ),
        ] {
            let p = get(query).problem(422);
            assert_eq!(p["field"], field, "{query}: {p}");
            assert!(
                p["detail"].as_str().unwrap().contains(words),
                "{query}: {p}"
            );
        }
        for (query, field) in [
            ("design_life_h=abc", "design_life_h"),
            ("design_life_h=-5", "design_life_h"),
            ("vehicle_profil=ah64", "vehicle_profil"),
            ("wear_law=archard&wear_law=archard", "wear_law"),
        ] {
            let p = get(query).problem(400);
            assert_eq!(p["field"], field, "{query}: {p}");
        }
        // Known labels, by alias or by profile file name, give a report (no curve yet).
        for query in [
            "vehicle_profile=ah64&environment=clean&wear_law=archard",
            "vehicle_profile=ah64-transverse",
            "design_life_h=400",
        ] {
            let r = get(query);
            assert_eq!(r.status, 200, "{query}: {}", r.body);
            assert!(r.json()["missing_curve"].is_object());
        }
        assert_eq!(
            get("vehicle_profile=ah64-transverse").json()["curve_key"],
            "ah64-transverse/clean/modified-archard"
        );
    })
    .await
    .unwrap();
    app.stop().await;
}
