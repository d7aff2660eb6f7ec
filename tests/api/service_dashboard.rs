//! The dashboard in headless Chromium (driven through chromedriver's WebDriver HTTP API with
//! the test client): the page lists a submitted job and shows it reach success, then shows a rail report;
//! a test engineer starts a diagnosis of a stored campaign from the page and sees its report
//! (verdict, ranking, figures) as the API gives it. Every browser test fails on a console
//! error the page did not expect (the browser's log, read through chromedriver). Skipped with
//! a message when Chromium is absent, unless RAILWEAR_REQUIRE_BROWSER is set (`.ci/run` sets
//! it and installs the browser).
//!
//! Over 700 lines: the WebDriver harness (sessions, console log, downloads) and each role's
//! journey through the page share one file, as every journey needs the harness and nothing
//! else does.

use crate::helpers::{wait_for, Api, Runner, TestApp};
use crate::support::{ENGINEER, PLANNER, TEST_ENGINEER};
use railwear::jobs::JobStatus;
use serde_json::{json, Value};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

fn find(program: &str) -> Option<String> {
    let out = Command::new("sh")
        .args(["-c", &format!("command -v {program}")])
        .output()
        .ok()?;
    let path = String::from_utf8_lossy(&out.stdout).trim().to_string();
    (out.status.success() && !path.is_empty()).then_some(path)
}

struct Driver {
    child: Child,
    /// chromedriver's WebDriver HTTP API.
    api: Api,
    session: String,
    /// Where the browser saves downloads (removed with the driver).
    downloads: std::path::PathBuf,
}

impl Driver {
    fn start(chromium: &str, chromedriver: &str) -> Driver {
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .expect("free port")
            .port();
        let child = Command::new(chromedriver)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("start chromedriver");
        let downloads =
            std::env::temp_dir().join(format!("railwear-downloads-{}-{port}", std::process::id()));
        std::fs::create_dir_all(&downloads).expect("download directory");
        let mut driver = Driver {
            child,
            api: Api::new(&format!("http://127.0.0.1:{port}")),
            session: String::new(),
            downloads,
        };
        wait_for(Duration::from_secs(30), "chromedriver", || {
            let out = driver
                .api
                .try_request("GET", "/status", None, &[], None)
                .ok()?;
            let status: Value = serde_json::from_str(&out.body).ok()?;
            (status["value"]["ready"] == true).then_some(())
        });
        let capabilities = json!({"capabilities": {"alwaysMatch": {
            "goog:loggingPrefs": {"browser": "ALL"},
            "goog:chromeOptions": {
            "binary": chromium,
            "prefs": {
                "download.default_directory": driver.downloads.to_string_lossy(),
                "download.prompt_for_download": false
            },
            "args": ["--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--disable-background-networking", "--no-first-run"]
        }}}});
        let session = driver.call("POST", "/session", Some(capabilities));
        driver.session = session["sessionId"]
            .as_str()
            .unwrap_or_else(|| panic!("no session: {session}"))
            .to_string();
        driver
    }

    fn call(&self, method: &str, path: &str, body: Option<Value>) -> Value {
        let body = body.map(|b| b.to_string());
        let r = self.api.request(method, path, None, &[], body.as_deref());
        let v: Value = serde_json::from_str(&r.body).unwrap_or(Value::Null);
        v["value"].clone()
    }

    fn goto(&self, url: &str) {
        self.call(
            "POST",
            &format!("/session/{}/url", self.session),
            Some(json!({ "url": url })),
        );
    }

    fn script(&self, script: &str) -> Value {
        self.call(
            "POST",
            &format!("/session/{}/execute/sync", self.session),
            Some(json!({ "script": script, "args": [] })),
        )
    }

    /// Chooses a file in a file input, as a user picking it would (WebDriver's send keys).
    fn choose_file(&self, css: &str, path: &std::path::Path) {
        let element = self.call(
            "POST",
            &format!("/session/{}/element", self.session),
            Some(json!({ "using": "css selector", "value": css })),
        );
        let key = "element-6066-11e4-a52e-4f735466cecf";
        let id = element[key]
            .as_str()
            .unwrap_or_else(|| panic!("no {css}: {element}"));
        self.call(
            "POST",
            &format!("/session/{}/element/{id}/value", self.session),
            Some(json!({ "text": path.to_string_lossy() })),
        );
    }

    /// The text of a file the browser downloaded, once it is complete.
    fn downloaded(&self, name: &str) -> String {
        let path = self.downloads.join(name);
        wait_for(Duration::from_secs(30), "the download", || {
            std::fs::read_to_string(&path).ok()
        })
    }

    /// The browser's console and network log since the last call (chromedriver drains it).
    fn log(&self) -> Vec<Value> {
        let entries = self.call(
            "POST",
            &format!("/session/{}/se/log", self.session),
            Some(json!({ "type": "browser" })),
        );
        entries.as_array().cloned().unwrap_or_default()
    }

    /// Fails on any error or warning in the log since the last call except those naming one
    /// of `expected` (each must then appear as often as listed), and on Chromium's note about
    /// a password field outside a form.
    fn assert_console_clean(&self, expected: &[&str]) {
        let log = self.log();
        let mut seen = vec![0usize; expected.len()];
        let mut unexpected = Vec::new();
        for entry in &log {
            let message = entry["message"].as_str().unwrap_or_default();
            let level = entry["level"].as_str().unwrap_or_default();
            if message.contains("not contained in a form") {
                unexpected.push(entry.clone());
                continue;
            }
            if level != "SEVERE" && level != "WARNING" {
                continue;
            }
            match expected.iter().position(|e| message.contains(e)) {
                Some(i) => seen[i] += 1,
                None => unexpected.push(entry.clone()),
            }
        }
        assert!(unexpected.is_empty(), "console errors: {unexpected:?}");
        let counts: Vec<(&str, usize)> = expected.iter().copied().zip(seen).collect();
        for (message, count) in &counts {
            assert_eq!(*count, 1, "{message} seen {count} times: {log:?}");
        }
    }

    /// Requests the page made to the API so far (the browser's resource timing entries).
    fn api_requests(&self) -> u64 {
        self.script(
            "return performance.getEntriesByType('resource')\
             .filter(e => new URL(e.name).pathname.startsWith('/v1/')).length;",
        )
        .as_u64()
        .unwrap_or(0)
    }

    /// Signs in through the page's form, as a user pressing "Use token" would.
    fn sign_in(&self, token: &str) {
        fill(self, "token", token);
        self.script("document.getElementById('token-form').requestSubmit(); return null;");
    }

    /// Waits until the page says who is signed in, and returns what it says.
    fn signed_in(&self, role: &str) -> String {
        wait_for(Duration::from_secs(30), "who is signed in", || {
            self.script(
                "const w = document.getElementById('whoami'); \
                 return w.dataset.role ? w.textContent : null;",
            )
            .as_str()
            .filter(|t| t.ends_with(&format!("({role})")))
            .map(str::to_string)
        })
    }

    /// Asserts the page made no API request for `seconds` (its polling stopped).
    fn assert_quiet(&self, seconds: u64) {
        let before = self.api_requests();
        std::thread::sleep(Duration::from_secs(seconds));
        assert_eq!(self.api_requests(), before, "the page kept polling");
    }
}

/// The 422 Chromium logs for the diagnosis request the test makes with a refused option.
const REFUSED_OPTIONS: &str =
    "/diagnoses - Failed to load resource: the server responded with a status of 422";

/// The 401 Chromium logs for a refused token's `/v1/whoami` (the one request it makes).
const REFUSED_WHOAMI: &str =
    "/v1/whoami - Failed to load resource: the server responded with a status of 401";

impl Drop for Driver {
    fn drop(&mut self) {
        if !self.session.is_empty() {
            let _ = self.call("DELETE", &format!("/session/{}", self.session), None);
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.downloads);
    }
}

/// Chromium and chromedriver, or `None` (the test skips) when they are not installed and
/// RAILWEAR_REQUIRE_BROWSER is not set.
fn browser() -> Option<(String, String)> {
    let chromium = find("chromium").or_else(|| find("chromium-browser"));
    let chromedriver = find("chromedriver");
    let (Some(chromium), Some(chromedriver)) = (chromium, chromedriver) else {
        assert!(
            std::env::var_os("RAILWEAR_REQUIRE_BROWSER").is_none(),
            "RAILWEAR_REQUIRE_BROWSER is set but chromium/chromedriver are missing"
        );
        eprintln!("SKIPPED dashboard test: chromium and chromedriver are not installed (apt-get install chromium chromium-driver)");
        return None;
    };
    Some((chromium, chromedriver))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn dashboard_shows_a_job_reach_success() {
    let Some((chromium, chromedriver)) = browser() else {
        return;
    };
    let app = TestApp::spawn().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // The page is open before the job is submitted (a browser can take seconds to start on
        // a loaded machine), and the job runs 40 steps of 100 ms: several of the page's 1 s
        // polls see it queued or running before it succeeds.
        let driver = Driver::start(&chromium, &chromedriver);
        driver.goto(&api.url(&format!("/#token={ENGINEER}")));
        // Defect 7: who is signed in, with which role.
        let who = driver.signed_in("engineer");
        assert!(who.starts_with("signed in as "), "{who}");
        let body = r#"{"kind":"simulate","params":{"steps":60,"step_ms":100,"samples":50}}"#;
        let id = api.submit_job(body);
        let row_status = format!(
            "const r = document.getElementById('job-{id}'); return r ? r.dataset.status : null;"
        );
        let first = wait_for(Duration::from_secs(30), "job row", || {
            driver.script(&row_status).as_str().map(str::to_string)
        });
        assert!(
            first == "queued" || first == "running",
            "page should list the job before it finishes, saw {first}"
        );
        // The full id is in the row, and a text selection of it survives the page's polls
        // while the job's progress changes under it.
        let id_cell = format!("document.querySelector('#job-{id} code.id')");
        assert_eq!(driver.script(&format!("return {id_cell}.textContent;")), id);
        wait_for(Duration::from_secs(30), "the job running", || {
            (driver.script(&row_status) == "running").then_some(())
        });
        driver.script(&format!(
            "const range = document.createRange(); range.selectNodeContents({id_cell}); \
             const s = window.getSelection(); s.removeAllRanges(); s.addRange(range); return null;"
        ));
        std::thread::sleep(Duration::from_millis(2500));
        assert_eq!(
            driver.script("return window.getSelection().toString();"),
            id,
            "the selection survived 2.5 s of polls"
        );
        driver.script("window.getSelection().removeAllRanges(); return null;");
        wait_for(Duration::from_secs(60), "success on the page", || {
            (driver.script(&row_status) == "succeeded").then_some(())
        });
        let cell = driver.script(&format!(
            "return document.querySelector('#job-{id} .status').textContent;"
        ));
        assert_eq!(cell, "succeeded");
        // Times carry their zone.
        let created = driver.script(&format!(
            "return document.querySelector('#job-{id}').children[4].textContent;"
        ));
        assert!(created.as_str().unwrap().ends_with(" UTC"), "{created}");
        let links = driver.script(&format!(
            "return document.querySelector('#job-{id}').textContent;"
        ));
        assert!(
            links.as_str().unwrap().ends_with("pagedownload tracks (CSV)"),
            "{links}"
        );
        // Defect 2: progress reads 100 % only once the job ended (a diagnosis' simulations
        // can all be done while it still writes its report).
        assert_eq!(
            driver.script("return percentDone({status: 'running', progress: {fraction: 1.0}});"),
            99
        );
        assert_eq!(
            driver.script("return percentDone({status: 'succeeded', progress: {fraction: 1.0}});"),
            100
        );
        // The job's page, by its URL: parameters as a table, attempts, its figures and the
        // tracks as a CSV download.
        driver.script(&format!(
            "document.querySelector('#job-{id} a.job-page').click(); return null;"
        ));
        let page = format!(
            "const p = document.querySelector('#job-page > div'); \
             return p && p.dataset.job === '{id}' && p.querySelector('.plots, h3') ? p.dataset.status : null;"
        );
        wait_for(Duration::from_secs(10), "the job page", || {
            (driver.script(&page) == "succeeded").then_some(())
        });
        assert_eq!(driver.script("return location.hash;"), format!("#/jobs/{id}"));
        let params = driver.script(
            "return Object.fromEntries([...document.querySelectorAll('#job-params tr')]\
             .map(r => [r.children[0].textContent, r.children[1].textContent]));",
        );
        assert_eq!(params["steps"], "60");
        assert_eq!(params["samples"], "50");
        let facts = driver.script(
            "return Object.fromEntries([...document.querySelectorAll('#job-facts tr')]\
             .map(r => [r.children[0].textContent, r.children[1].textContent]));",
        );
        assert_eq!(facts["Attempts"], "1");
        assert_eq!(facts["Submitted by"], "eng");
        assert!(facts["Finished"].as_str().unwrap().ends_with(" UTC"), "{facts}");
        assert_eq!(
            driver.script("return document.querySelectorAll('#job-attempts tbody tr').length;"),
            1
        );
        let result = api.get(&format!("/v1/jobs/{id}/result"), Some(ENGINEER)).json();
        let names: Vec<Value> = result["plots"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["name"].clone())
            .collect();
        assert!(!names.is_empty(), "{result}");
        let figures = wait_for(Duration::from_secs(10), "the figures", || {
            let v = driver.script(
                "const imgs = [...document.querySelectorAll('#job-page img[data-plot]')]; \
                 return imgs.length > 0 && imgs.every(i => i.complete) ? imgs.map(i => i.dataset.plot) : null;",
            );
            (!v.is_null()).then_some(v)
        });
        assert_eq!(figures, Value::Array(names));
        driver.script(
            "[...document.querySelectorAll('#job-page a')]\
             .find(a => a.textContent.startsWith('download tracks')).click(); return null;",
        );
        let downloaded = driver.downloaded(&format!("railwear-{id}-tracks.csv"));
        let csv = api.get(&format!("/v1/jobs/{id}/tracks?format=csv"), Some(ENGINEER));
        assert_eq!(csv.status, 200);
        assert_eq!(downloaded, csv.body);
        assert_eq!(csv.body.lines().count(), 51, "a header and the 50 samples");
        // The engineer submits a job through the page and lands on its page, which follows
        // it to success.
        driver.goto(&api.url("/#/jobs"));
        fill(&driver, "submit-kind", "simulate");
        fill(
            &driver,
            "submit-params",
            r#"{"steps": 5, "step_ms": 20, "samples": 10}"#,
        );
        driver.script("document.getElementById('submit-job').requestSubmit(); return null;");
        let second = wait_for(Duration::from_secs(30), "the new job's page", || {
            driver
                .script("return location.hash;")
                .as_str()
                .and_then(|h| h.strip_prefix("#/jobs/"))
                .filter(|h| *h != id)
                .map(str::to_string)
        });
        let page_of = |job: &str| {
            format!(
                "const p = document.querySelector('#job-page > div'); \
                 return p && p.dataset.job === '{job}' ? p.dataset.status : null;"
            )
        };
        wait_for(Duration::from_secs(30), "the new job succeeded", || {
            (driver.script(&page_of(&second)) == "succeeded").then_some(())
        });
        let submitted = api.get(&format!("/v1/jobs/{second}"), Some(ENGINEER)).json();
        assert_eq!(submitted["params"]["steps"], 5, "{submitted}");
        assert_eq!(submitted["submitted_by"], "eng");
        driver.goto(&api.url(&format!("/#/jobs/{id}")));
        wait_for(Duration::from_secs(30), "the first job's page", || {
            (driver.script(&page) == "succeeded").then_some(())
        });
        // Issue 29: the page ran above under its policy, which allows no inline script. The
        // token is in this tab's sessionStorage, not localStorage nor the address bar, and
        // signing out forgets it.
        assert_eq!(
            driver.script("return sessionStorage.getItem('railwear-token');"),
            ENGINEER
        );
        assert!(driver
            .script("return localStorage.getItem('railwear-token');")
            .is_null());
        let address = driver.script("return location.href;");
        assert!(!address.as_str().unwrap().contains(ENGINEER), "{address}");
        driver.assert_console_clean(&[]);

        // Defect 4: signing out clears everything, stays signed out and stops polling.
        driver.script("document.getElementById('sign-out').click(); return null;");
        assert!(driver
            .script("return sessionStorage.getItem('railwear-token');")
            .is_null());
        assert_eq!(
            driver.script("return document.getElementById('token').value;"),
            ""
        );
        driver.assert_quiet(3);
        let cleared = "return [document.querySelectorAll('#jobs tr').length, \
             document.getElementById('whoami').textContent, \
             document.getElementById('job-page').textContent, \
             document.getElementById('error').textContent];";
        assert_eq!(driver.script(cleared), json!([0, "", "", "signed out"]));

        // Defect 6: a wrong token after a right one clears what the first user saw and stops
        // polling after its single 401.
        driver.sign_in(ENGINEER);
        driver.signed_in("engineer");
        wait_for(Duration::from_secs(30), "the job page again", || {
            (driver.script(&page) == "succeeded").then_some(())
        });
        driver.sign_in("not-a-token");
        let refused = wait_for(Duration::from_secs(30), "the refusal", || {
            driver
                .script("return document.getElementById('error').textContent;")
                .as_str()
                .filter(|t| t.starts_with("token refused"))
                .map(str::to_string)
        });
        assert!(refused.contains("401"), "{refused}");
        driver.assert_quiet(3);
        assert_eq!(
            driver.script(cleared),
            json!([0, "", "", refused]),
            "nothing of the engineer's stays"
        );
        driver.assert_console_clean(&[REFUSED_WHOAMI]);
    })
    .await
    .unwrap();
    app.stop().await;
}

/// Issue 26 item 7: a planner reads a rail's report with the K_SL under a second stored curve
/// beside the published one, and the page shows what the API returns.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn dashboard_compares_a_rails_life_under_two_curves() {
    use crate::service_rails::{measurement, publish, run_sweep};
    let Some((chromium, chromedriver)) = browser() else {
        return;
    };
    let app = TestApp::spawn().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let dims = railwear::analysis::rattle_space::LauncherDimensions::design()
            .with_material_condition(0.1);
        let r = api.post_rail("R-9", &measurement(dims));
        assert_eq!(r.status, 201, "{}", r.body);
        // Two curves of the test runner: three seeds (published) and one seed.
        let sweep = |seeds: u32| {
            format!(
                r#"{{"kind":"sweep","params":{{"steps":1,"step_ms":1,"rattle_space_range":{{"min":0.76,"max":0.84}},"points":3,"seeds":{seeds},"duration_s":1}}}}"#
            )
        };
        run_sweep(&api, &sweep(3));
        let first = api.get("/v1/curves", Some(PLANNER)).json()["items"][0]["id"]
            .as_i64()
            .unwrap();
        assert_eq!(publish(&api, first, None).status, 200);
        run_sweep(&api, &sweep(1));
        let second = api.get("/v1/curves", Some(PLANNER)).json()["items"][0]["id"]
            .as_i64()
            .unwrap();
        assert_ne!(first, second);
        let expected = api
            .get(&format!("/v1/rails/R-9/report?compare={second}"), Some(PLANNER))
            .json();
        let k_sl = expected["comparison"]["k_sl"].as_f64().expect("a K_SL");

        let driver = Driver::start(&chromium, &chromedriver);
        driver.goto(&api.url(&format!("/#token={PLANNER}")));
        // A planner starts on the rails: the list links each rail's page.
        driver.signed_in("planner");
        wait_for(Duration::from_secs(30), "the rail listed", || {
            (driver.script("return document.querySelector('#rail-row-R-9 a') !== null;") == true)
                .then_some(())
        });
        assert_eq!(driver.script("return document.getElementById('view-rails').hidden;"), false);
        fill(&driver, "serial", "R-9");
        fill(&driver, "compare", &second.to_string());
        driver.script("document.getElementById('load-report').click(); return null;");
        let shown = wait_for(Duration::from_secs(30), "the comparison", || {
            driver
                .script(
                    "const c = document.getElementById('report-comparison'); \
                     return c ? c.textContent : null;",
                )
                .as_str()
                .map(str::to_string)
        });
        assert!(
            shown.contains(&format!("Under curve {second}"))
                && shown.contains(&format!("K_SL = {k_sl:.3}")),
            "{shown} (API: {k_sl})"
        );
        // The compared curve has one seed per point against three: the page warns.
        let warning = driver.script(
            "const w = document.getElementById('report-fidelity-warning'); \
             return w ? w.textContent : null;",
        );
        assert!(
            warning
                .as_str()
                .is_some_and(|w| w.contains("(1 seed per point against 3)")),
            "{warning}"
        );
        // The figure: a marker per swept point, the rail with its interval, the compared K_SL,
        // and a legend naming each.
        let figure = driver.script(
            "const f = document.getElementById('curve-plot'); \
             return [f.querySelectorAll('circle.point').length, \
                     f.querySelectorAll('circle.rail, line.interval, path.compared').length, \
                     [...f.querySelectorAll('text.legend-entry')].map(t => t.textContent)];",
        );
        assert_eq!(
            figure[0],
            expected["k_sl_curve"].as_array().unwrap().len(),
            "{figure}"
        );
        assert_eq!(figure[1], 3, "{figure}");
        assert_eq!(
            figure[2].as_array().unwrap().last().unwrap(),
            &json!(format!("K_SL under curve {second}"))
        );
        // The curve the report used and the interval over its seeds, as the API gives them.
        let curve = driver.script("return document.getElementById('report-curve').textContent;");
        let used = &expected["service_life"];
        assert_eq!(expected["curve"]["id"], first);
        assert!(
            curve
                .as_str()
                .unwrap()
                .starts_with(&format!("Curve used: {first} (")),
            "{curve}"
        );
        let interval =
            driver.script("return document.getElementById('report-interval').textContent;");
        let interval = interval.as_str().unwrap();
        let band = &used["interval"];
        let low = band["k_sl_low"].as_f64().expect("three seeds give an interval");
        let high = band["k_sl_high"].as_f64().unwrap();
        assert!(
            interval.starts_with("90 % interval over 3 seeds")
                && interval.contains(&format!("K_SL {low:.4} to {high:.4}"))
                && interval.ends_with(used["uncertainty"].as_str().unwrap()),
            "{interval} (API: {used})"
        );
        assert_eq!(
            driver.script("return location.hash;"),
            format!("#/rails/R-9?compare={second}")
        );
        assert_eq!(
            driver.script("return document.querySelectorAll('#measurements tr').length;"),
            1,
            "the measurement history"
        );
        // The planner records a second measurement through the page: the history shows both.
        let second_dims = railwear::analysis::rattle_space::LauncherDimensions::design()
            .with_material_condition(0.1);
        fill(&driver, "m-by", "A. Roe");
        fill(&driver, "m-at", "2024-06-01T08:30:00Z");
        fill(&driver, "m-location", "Depot 7");
        fill(
            &driver,
            "m-dimensions",
            &serde_json::to_string(&second_dims).unwrap(),
        );
        driver.script("document.getElementById('record-measurement').requestSubmit(); return null;");
        wait_for(Duration::from_secs(30), "two measurements", || {
            (driver.script("return document.querySelectorAll('#measurements tr').length;") == 2)
                .then_some(())
        });
        assert_eq!(
            driver.script("return document.getElementById('m-error').textContent;"),
            ""
        );
        let rail = api.get("/v1/rails/R-9", Some(PLANNER)).json();
        assert_eq!(rail["measurements"], 2, "{rail}");
        // The page's URL opens the same report in a fresh load.
        driver.goto("about:blank");
        driver.goto(&api.url(&format!("/#/rails/R-9?compare={second}")));
        let again = wait_for(Duration::from_secs(30), "the bookmarked report", || {
            driver
                .script(
                    "const c = document.getElementById('report-comparison'); \
                     return c ? c.textContent : null;",
                )
                .as_str()
                .map(str::to_string)
        });
        assert!(again.starts_with(&format!("Under curve {second}")), "{again}");
        // The curves, each with its fidelity and the sweep that made it.
        driver.goto("about:blank");
        driver.goto(&api.url("/#/curves"));
        let curves = api.get("/v1/curves", Some(PLANNER)).json();
        for curve in curves["items"].as_array().unwrap() {
            let id = curve["id"].as_i64().unwrap();
            let seeds = curve["fidelity"]["seeds"].as_i64().unwrap();
            let fidelity = wait_for(Duration::from_secs(30), "the curve listed", || {
                driver
                    .script(&format!(
                        "const r = document.getElementById('curve-{id}'); \
                         return r ? r.querySelector('.fidelity').textContent : null;"
                    ))
                    .as_str()
                    .map(str::to_string)
            });
            let f = &curve["fidelity"];
            let duration = match f["duration_per_point_s"].as_f64() {
                Some(d) => format!("{d} s per point"),
                None => "duration not recorded".to_string(),
            };
            let expected = format!(
                "{} points, {duration}, {seeds} seed{}",
                f["points"],
                if seeds == 1 { "" } else { "s" }
            );
            assert_eq!(fidelity, expected);
        }
        driver.assert_console_clean(&[]);
    })
    .await
    .unwrap();
    app.stop().await;
}

/// The smallest campaign that runs a real diagnosis (shared with tests/service_diagnose.rs).
const CAMPAIGN: &str = include_str!("../fixtures/small-campaign.toml");

/// Sets an input's value through the page (as typing would).
fn fill(driver: &Driver, id: &str, value: &str) {
    driver.script(&format!(
        "document.getElementById({}).value = {}; return null;",
        json!(id),
        json!(value)
    ));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn dashboard_starts_a_diagnosis_and_shows_its_report() {
    let Some((chromium, chromedriver)) = browser() else {
        return;
    };
    let app = TestApp::spawn_with(Runner::Library, true, |_| {}).await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let campaign_id = api.upload_campaign(CAMPAIGN);
        let driver = Driver::start(&chromium, &chromedriver);
        let row = format!("document.getElementById('campaign-{campaign_id}')");
        let buttons = format!("{row}.querySelectorAll('button.start-diagnosis').length");

        // A planner sees the campaign but no way to start a diagnosis (the API would say 403).
        driver.goto(&api.url(&format!("/#token={PLANNER}")));
        wait_for(Duration::from_secs(30), "the campaign listed", || {
            (driver.script(&format!("return {row} !== null;")) == true).then_some(())
        });
        assert_eq!(driver.script(&format!("return {buttons};")), 0);
        assert_eq!(
            driver.script("return document.getElementById('diagnose-options').hidden;"),
            true
        );

        // A test engineer does.
        // A fresh load (the dashboard takes no query parameters, so a blank page in between
        // makes the navigation more than a change of fragment).
        driver.goto("about:blank");
        driver.goto(&api.url(&format!("/#token={TEST_ENGINEER}")));
        wait_for(Duration::from_secs(30), "the start button", || {
            (driver.script(&format!("return {row} !== null && {buttons} === 1;")) == true)
                .then_some(())
        });
        let start = format!("{row}.querySelector('button.start-diagnosis').click(); return null;");
        let error = "return document.getElementById('diagnose-error').textContent;";

        // A refused request shows the problem's detail, naming the field.
        fill(&driver, "opt-window", "0");
        driver.script(&start);
        let shown = wait_for(Duration::from_secs(30), "the 422 detail", || {
            driver
                .script(error)
                .as_str()
                .filter(|t| !t.is_empty())
                .map(str::to_string)
        });
        assert!(shown.starts_with("Error: 422: `window_s`"), "{shown}");

        // Short windows and one effect: a real diagnosis that finishes in seconds. Defect 5:
        // a double click starts one job, the button waiting for the service's answer.
        fill(&driver, "opt-window", "0.1");
        fill(&driver, "opt-settle", "0.02");
        fill(&driver, "opt-grid", "2");
        fill(&driver, "opt-effects", "third_body, wear_above_cutoff");
        let disabled = driver.script(&format!(
            "const b = {row}.querySelector('button.start-diagnosis'); b.click(); b.click(); \
             return {row}.querySelector('button.start-diagnosis').disabled;"
        ));
        assert_eq!(disabled, true, "the button waits for the answer");
        let job = wait_for(Duration::from_secs(30), "the diagnosis listed", || {
            driver
                .script("return document.getElementById('diagnosis').dataset.job || null;")
                .as_str()
                .map(str::to_string)
        });
        assert_eq!(driver.script(error), "", "the new request succeeded");
        let listed = format!("return document.getElementById('diagnosis-{job}') !== null;");
        wait_for(Duration::from_secs(30), "the job row", || {
            (driver.script(&listed) == true).then_some(())
        });
        // Defect 1: the panel says what the row says until the report shows.
        let both = format!(
            "return [document.getElementById('diagnosis-{job}').dataset.status, \
             document.getElementById('diagnosis').dataset.status, \
             document.getElementById('diagnosis').dataset.verdict || null];"
        );
        let mut statuses = Vec::new();
        let verdict = wait_for(Duration::from_secs(600), "the report on the page", || {
            let seen = driver.script(&both);
            let (row_says, panel_says) = (seen[0].clone(), seen[1].clone());
            if row_says != "succeeded" {
                assert_eq!(panel_says, row_says, "the panel follows the row");
            }
            statuses.push(row_says);
            seen[2].as_str().map(str::to_string)
        });
        // (A diagnosis this small can go from queued to succeeded between two polls.)
        assert_eq!(statuses.last(), Some(&json!("succeeded")), "{statuses:?}");
        let jobs = api.get("/v1/jobs?limit=100", Some(TEST_ENGINEER)).json();
        let diagnoses = jobs["items"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|j| j["kind"] == "diagnose")
            .count();
        assert_eq!(diagnoses, 1, "one job for the double click");

        // The page shows what the API returns.
        let r = api.get(&format!("/v1/jobs/{job}/result"), Some(TEST_ENGINEER));
        assert_eq!(r.status, 200, "{}", r.body);
        let result = r.json();
        assert_eq!(result["kind"], "diagnose");
        let report = &result["summary"];
        assert_eq!(verdict, report["verdict"].as_str().unwrap());
        assert_eq!(
            driver.script("return document.querySelector('#diagnosis .verdict').textContent;"),
            report["verdict"]
        );
        let candidates: Vec<Value> = report["ranking"]
            .as_array()
            .unwrap()
            .iter()
            .chain(report["pairs"].as_array().unwrap())
            .map(|e| e["name"].clone())
            .collect();
        assert!(candidates.contains(&json!("third_body")), "{report}");
        let rows = driver.script(
            "return [...document.querySelectorAll('#diagnosis-ranking tbody tr')]\
             .map(r => r.dataset.effect);",
        );
        assert_eq!(rows, Value::Array(candidates));
        let marked = driver.script(
            "return [...document.querySelectorAll('#diagnosis-ranking tr.indistinguishable')]\
             .map(r => r.dataset.effect);",
        );
        assert_eq!(marked, report["indistinguishable"]);
        let flagged = report["where"]["groups"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|g| g["flagged"] == true)
            .count();
        let flagged_rows = driver.script(
            "const t = document.getElementById('diagnosis-where'); \
             return t ? t.querySelectorAll('tbody tr').length : 0;",
        );
        assert_eq!(flagged_rows, flagged);
        // Issue 26: the energy budget, one row per test and contact, one per test, component
        // and mechanism.
        let budget = &report["where"]["energy_budget"]["tests"];
        let contacts: usize = budget
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["contacts"].as_array().unwrap().len())
            .sum();
        let needed: usize = budget
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["needed"].as_array().unwrap().len())
            .sum();
        assert!(contacts > 0 && needed > 0, "{budget}");
        let rows = |id: &str| {
            driver.script(&format!(
                "const t = document.getElementById('{id}'); \
                 return t ? t.querySelectorAll('tbody tr').length : 0;"
            ))
        };
        assert_eq!(rows("diagnosis-budget"), contacts);
        assert_eq!(rows("diagnosis-budget-needed"), needed);

        // The four figures, each decoded by the browser as an image.
        let mut names: Vec<&str> = result["plots"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["name"].as_str().unwrap())
            .collect();
        names.sort_unstable();
        assert_eq!(
            names,
            [
                "before_after.svg",
                "energy_budget.svg",
                "ranking.svg",
                "residuals.svg"
            ]
        );
        let decoded = wait_for(Duration::from_secs(30), "the figures decoded", || {
            let v = driver.script(
                "const imgs = [...document.querySelectorAll('#diagnosis img[data-plot]')]; \
                 return imgs.every(i => i.complete && i.naturalWidth > 0) \
                 ? imgs.map(i => i.dataset.plot) : null;",
            );
            (!v.is_null()).then_some(v)
        });
        // Each beside the table it illustrates: how far (after the fitted parameters), which
        // (after the ranking), where (after the flagged groups, after the energy budget).
        assert_eq!(
            decoded,
            json!([
                "before_after.svg",
                "ranking.svg",
                "residuals.svg",
                "energy_budget.svg"
            ])
        );
        // A reason beside every "no" in the Explains column.
        let explains = driver.script(
            "return [...document.querySelectorAll('#diagnosis-ranking tbody tr')]\
             .map(r => r.children[8].textContent);",
        );
        let entries: Vec<&Value> = report["ranking"]
            .as_array()
            .unwrap()
            .iter()
            .chain(report["pairs"].as_array().unwrap())
            .collect();
        for (cell, entry) in explains.as_array().unwrap().iter().zip(&entries) {
            let cell = cell.as_str().unwrap();
            if entry["explains"] == true {
                assert_eq!(cell, "yes");
            } else {
                assert!(cell.starts_with("no: "), "{cell} for {entry}");
            }
        }
        // The per-test held-out predictions, one row each.
        let predictions = report["held_out_predictions"]
            .as_array()
            .map_or(0, |p| p.len());
        let shown = driver.script(
            "const t = document.getElementById('diagnosis-predictions'); \
             return t ? t.querySelectorAll('tbody tr').length : 0;",
        );
        assert_eq!(shown, predictions);
        // Each table says which interval level it shows.
        let caption = driver
            .script("return document.querySelector('#diagnosis-ranking caption').textContent;");
        assert!(caption.as_str().unwrap().contains("90 %"), "{caption}");
        driver.assert_console_clean(&[REFUSED_OPTIONS]);

        // Defect 3: sign out, sign in, open the same report: it shows again.
        driver.script("document.getElementById('sign-out').click(); return null;");
        assert_eq!(
            driver.script("return document.getElementById('diagnosis').textContent;"),
            ""
        );
        driver.sign_in(TEST_ENGINEER);
        driver.signed_in("test_engineer");
        let report_link = format!(
            "const a = document.querySelector('#diagnosis-{job} a'); \
             if (!a) {{ return false; }} a.click(); return true;"
        );
        wait_for(Duration::from_secs(30), "the report link again", || {
            (driver.script(&report_link) == true).then_some(())
        });
        let again = wait_for(Duration::from_secs(30), "the report again", || {
            driver
                .script("return document.getElementById('diagnosis').dataset.verdict || null;")
                .as_str()
                .map(str::to_string)
        });
        assert_eq!(again, verdict);
        driver.assert_console_clean(&[]);
    })
    .await
    .unwrap();
    app.stop().await;
}

/// Defect 8: a diagnosis older than the latest hundred submitted jobs stays listed; defect 5:
/// a queued job is cancelled from the page. No worker runs, so every job stays queued.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn dashboard_lists_old_diagnoses_and_cancels_a_job() {
    let Some((chromium, chromedriver)) = browser() else {
        return;
    };
    let app = TestApp::spawn_idle().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // The test engineer uploads the campaign through the page.
        let driver = Driver::start(&chromium, &chromedriver);
        driver.goto(&api.url(&format!("/#token={TEST_ENGINEER}")));
        driver.signed_in("test_engineer");
        let campaign = railwear::gap::Campaign::from_toml_str(CAMPAIGN, std::path::Path::new("."))
            .expect("campaign");
        let file = driver.downloads.join("campaign.json");
        std::fs::write(&file, serde_json::to_string(&campaign).unwrap()).expect("campaign file");
        driver.choose_file("#campaign-file", &file);
        driver.script("document.getElementById('upload-campaign').requestSubmit(); return null;");
        let stored = wait_for(Duration::from_secs(30), "the campaign stored", || {
            let list = api.get("/v1/campaigns", Some(TEST_ENGINEER)).json();
            list["items"][0]["id"].as_str().map(str::to_string)
        });
        let listed = format!("return document.getElementById('campaign-{stored}') !== null;");
        wait_for(Duration::from_secs(30), "the campaign listed", || {
            (driver.script(&listed) == true).then_some(())
        });
        assert_eq!(
            driver.script("return document.getElementById('upload-error').textContent;"),
            ""
        );
        let campaign_id = stored;
        let r = api.post(
            &format!("/v1/campaigns/{campaign_id}/diagnoses"),
            Some(TEST_ENGINEER),
            "{}",
        );
        assert_eq!(r.status, 201, "{}", r.body);
        let old = r.json()["id"].as_str().expect("job id").to_string();
        // More newer jobs than one page of the job list holds (100).
        let newer: Vec<String> = (0..101)
            .map(|_| api.submit_job(r#"{"kind":"simulate","params":{"steps":1}}"#))
            .collect();
        let listed = api
            .get("/v1/jobs?limit=100&top_level=true", Some(ENGINEER))
            .json();
        assert!(
            listed["items"]
                .as_array()
                .unwrap()
                .iter()
                .all(|j| j["id"] != json!(old)),
            "the diagnosis is off the first page"
        );

        driver.goto("about:blank");
        driver.goto(&api.url("/#/campaigns"));
        driver.signed_in("test_engineer");
        let row = format!("return document.getElementById('diagnosis-{old}') !== null;");
        wait_for(Duration::from_secs(30), "the old diagnosis listed", || {
            (driver.script(&row) == true).then_some(())
        });

        // The test engineer cancels it from its row; the engineer cancels a simulate job.
        driver.script(&format!(
            "document.querySelector('#diagnosis-{old} button.cancel-job').click(); return null;"
        ));
        wait_for(Duration::from_secs(30), "the diagnosis cancelled", || {
            (api.job(&old).status == JobStatus::Cancelled).then_some(())
        });
        driver.goto("about:blank");
        driver.goto(&api.url(&format!("/#token={ENGINEER}")));
        driver.signed_in("engineer");
        let last = newer.last().expect("a job");
        let button = format!(
            "const b = document.querySelector('#job-{last} button.cancel-job'); \
             if (!b) {{ return false; }} b.click(); return true;"
        );
        wait_for(Duration::from_secs(30), "the cancel button", || {
            (driver.script(&button) == true).then_some(())
        });
        wait_for(Duration::from_secs(30), "the job cancelled", || {
            (api.job(last).status == JobStatus::Cancelled).then_some(())
        });
        let shown = format!("return document.querySelector('#job-{last} .status').textContent;");
        wait_for(Duration::from_secs(30), "the row cancelled", || {
            (driver.script(&shown) == "cancelled").then_some(())
        });
        // Filters by kind and paging: the old diagnosis is on the second page of 100.
        driver.goto(&api.url("/#/jobs?kind=diagnose"));
        let rows = "return [...document.querySelectorAll('#jobs tr')].map(r => r.id);";
        wait_for(Duration::from_secs(30), "the older page offered", || {
            (driver.script("return document.getElementById('jobs-older').disabled;") == false)
                .then_some(())
        });
        assert_eq!(
            driver.script(rows),
            json!([]),
            "no diagnosis among the newest 100"
        );
        driver.script("document.getElementById('jobs-older').click(); return null;");
        wait_for(Duration::from_secs(30), "the diagnosis on page 2", || {
            (driver.script(rows) == json!([format!("job-{old}")])).then_some(())
        });
        assert_eq!(
            driver.script("return document.getElementById('jobs-page').textContent;"),
            "page 2"
        );
        driver.assert_console_clean(&[]);
    })
    .await
    .unwrap();
    app.stop().await;
}

/// Issue 29: the pages and every answer carry the browser hardening headers, and the pages
/// hold no inline script or style (their policy would block it).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn pages_carry_a_strict_policy_and_no_inline_script() {
    let app = TestApp::spawn().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        for path in ["/", "/docs", "/dashboard.js", "/v1/jobs"] {
            let r = api.get(path, Some(ENGINEER));
            let csp = r.header("content-security-policy").unwrap_or_default();
            for directive in [
                "default-src 'none'",
                "script-src 'self'",
                "style-src 'self'",
                "frame-ancestors 'none'",
            ] {
                assert!(csp.contains(directive), "{path}: {csp}");
            }
            assert!(!csp.contains("unsafe-inline"), "{path}: {csp}");
            assert_eq!(r.header("x-frame-options"), Some("DENY"), "{path}");
            assert_eq!(
                r.header("x-content-type-options"),
                Some("nosniff"),
                "{path}"
            );
            assert_eq!(r.header("referrer-policy"), Some("no-referrer"), "{path}");
        }
        for page in ["/", "/docs"] {
            let html = api.get(page, None).body;
            assert!(!html.contains("<script>"), "{page} has an inline script");
            assert!(!html.contains("<style"), "{page} has an inline style sheet");
            assert!(!html.contains(" onclick="), "{page} has an inline handler");
        }
        let js = api.get("/dashboard.js", None);
        assert!(js
            .header("content-type")
            .unwrap_or_default()
            .starts_with("text/javascript"));
        assert!(
            !js.body.contains("localStorage.setItem"),
            "the token stays out of localStorage"
        );
    })
    .await
    .unwrap();
    app.stop().await;
}
