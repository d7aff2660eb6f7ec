//! The dashboard in headless Chromium (driven through chromedriver's WebDriver HTTP API with
//! curl): the page lists a submitted job and shows it reach success, then shows a rail report.
//! Skipped with a message when Chromium is absent, unless RAILWEAR_REQUIRE_BROWSER is set
//! (`.ci/run` sets it and installs the browser).

mod service_support;

use serde_json::{json, Value};
use service_support::runner::{start, test_config};
use service_support::{curl, submit_job, wait_for, TempDir, ENGINEER};
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
    base: String,
    session: String,
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
        let base = format!("http://127.0.0.1:{port}");
        let mut driver = Driver {
            child,
            base,
            session: String::new(),
        };
        wait_for(Duration::from_secs(30), "chromedriver", || {
            let out = Command::new("curl")
                .args(["-s", &format!("{}/status", driver.base)])
                .output()
                .ok()?;
            let status: Value = serde_json::from_slice(&out.stdout).ok()?;
            (status["value"]["ready"] == true).then_some(())
        });
        let capabilities = json!({"capabilities": {"alwaysMatch": {"goog:chromeOptions": {
            "binary": chromium,
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
        let r = curl(
            method,
            &format!("{}{path}", self.base),
            None,
            &[],
            body.as_deref(),
        );
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
}

impl Drop for Driver {
    fn drop(&mut self) {
        if !self.session.is_empty() {
            let _ = self.call("DELETE", &format!("/session/{}", self.session), None);
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn dashboard_shows_a_job_reach_success() {
    let chromium = find("chromium").or_else(|| find("chromium-browser"));
    let chromedriver = find("chromedriver");
    let (Some(chromium), Some(chromedriver)) = (chromium, chromedriver) else {
        assert!(
            std::env::var_os("RAILWEAR_REQUIRE_BROWSER").is_none(),
            "RAILWEAR_REQUIRE_BROWSER is set but chromium/chromedriver are missing"
        );
        eprintln!("SKIPPED dashboard test: chromium and chromedriver are not installed (apt-get install chromium chromium-driver)");
        return;
    };
    let dir = TempDir::new("dash");
    let service = start(test_config(&dir.db_url()), true).await;
    let base = format!("http://{}", service.addr);
    tokio::task::spawn_blocking(move || {
        // 40 steps of 100 ms: long enough to be seen queued/running before it succeeds.
        let body = r#"{"kind":"simulate","params":{"steps":40,"step_ms":100,"samples":50}}"#;
        let id = submit_job(&base, body);

        let driver = Driver::start(&chromium, &chromedriver);
        driver.goto(&format!("{base}/#token={ENGINEER}"));
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
        wait_for(Duration::from_secs(60), "success on the page", || {
            (driver.script(&row_status) == "succeeded").then_some(())
        });
        let cell = driver.script(&format!(
            "return document.querySelector('#job-{id} .status').textContent;"
        ));
        assert_eq!(cell, "succeeded");
        let links = driver.script(&format!(
            "return document.querySelector('#job-{id}').textContent;"
        ));
        assert!(links.as_str().unwrap().contains("result"), "{links}");
        // The result link loads the job's summary into the page.
        driver.script(&format!(
            "document.querySelector('#job-{id} a').click(); return null;"
        ));
        wait_for(Duration::from_secs(10), "result shown", || {
            let text = driver.script("return document.getElementById('result').textContent;");
            text.as_str()
                .filter(|t| t.contains("force_sum_n"))
                .map(|_| ())
        });
    })
    .await
    .unwrap();
    service.stop().await;
}
