//! The API tests' house: [`TestApp`] (the service in this process on port 0 with a fresh SQLite
//! file), [`Binary`] (the real `railwear serve`), and [`Api`], the typed client both hand out.
//! Built on the `railwear-testkit` crate (the HTTP client on reqwest, the process spawner),
//! which the bench shares.
//!
//! The client methods block: the tests drive the service from plain threads (`#[test]`
//! functions and `spawn_blocking` closures beside an in-process service on the test's runtime).
//! Each call runs a fresh testkit client (a connection per request, none kept) on a one-request
//! runtime of its own thread, so it works from any thread, inside a runtime or not, and never
//! leaves an idle connection for a graceful shutdown to wait on.

use crate::support::runner::{start, start_library, test_config};
use crate::support::{temp_dir, tokens_env, TempDir, ENGINEER, PLANNER, TEST_ENGINEER};
use railwear::config::ServiceConfig;
use railwear::http::jobs::JobView;
use railwear::http::RunningService;
use railwear::jobs::JobStatus;
use railwear_testkit::{self as testkit, Client, ClientError, Request, ServerProcess};
use std::path::Path;
use std::time::{Duration, Instant};

/// One HTTP response with its body as text.
#[derive(Debug)]
pub struct Reply {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: String,
}

impl Reply {
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_str(&self.body).unwrap_or_else(|e| panic!("not JSON ({e}): {}", self.body))
    }
    /// Assert a problem+json with this status; returns the problem.
    pub fn problem(&self, status: u16) -> serde_json::Value {
        assert_eq!(self.status, status, "body: {}", self.body);
        assert_eq!(
            self.header("content-type"),
            Some("application/problem+json"),
            "body: {}",
            self.body
        );
        let p = self.json();
        assert_eq!(p["status"], status);
        assert!(p["type"].as_str().is_some_and(|t| !t.is_empty()));
        assert!(p["title"].as_str().is_some_and(|t| !t.is_empty()));
        assert!(p["detail"].as_str().is_some_and(|t| !t.is_empty()));
        p
    }
}

/// Poll `f` every 100 ms until it returns Some, or panic after `timeout`.
pub fn wait_for<T>(timeout: Duration, what: &str, mut f: impl FnMut() -> Option<T>) -> T {
    let start = Instant::now();
    loop {
        if let Some(v) = f() {
            return v;
        }
        assert!(start.elapsed() < timeout, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// A typed client of one service (`base` = `http://host:port`).
#[derive(Debug, Clone)]
pub struct Api {
    pub base: String,
}

impl Api {
    pub fn new(base: &str) -> Api {
        Api {
            base: base.trim_end_matches('/').to_string(),
        }
    }

    /// `{base}{path}`.
    pub fn url(&self, path: &str) -> String {
        format!("{}{path}", self.base)
    }

    /// Any request: `method path`, optional bearer token, extra headers, optional body (sent as
    /// JSON unless a Content-Type header is given). For malformed bodies, odd headers and
    /// content types; the typed methods below cover the rest.
    pub fn request(
        &self,
        method: &str,
        path: &str,
        token: Option<&str>,
        headers: &[(&str, &str)],
        body: Option<&str>,
    ) -> Reply {
        self.try_request(method, path, token, headers, body)
            .unwrap_or_else(|e| panic!("{method} {} failed: {e}", self.url(path)))
    }

    /// [`Api::request`] that returns a connection failure instead of panicking (a server
    /// that may not listen yet).
    pub fn try_request(
        &self,
        method: &str,
        path: &str,
        token: Option<&str>,
        headers: &[(&str, &str)],
        body: Option<&str>,
    ) -> Result<Reply, ClientError> {
        let mut request = Request::new(method, path);
        if let Some(token) = token {
            request = request.bearer(token);
        }
        for (k, v) in headers {
            request = request.header(k, v);
        }
        if let Some(body) = body {
            request = request.json(body);
        }
        let base = self.base.clone();
        // A thread of its own with a one-request runtime: callable from any thread.
        let response = std::thread::spawn(move || {
            let rt = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .expect("client runtime");
            rt.block_on(async { Client::new(&base)?.send(&request).await })
        })
        .join()
        .expect("client thread")?;
        Ok(Reply {
            status: response.status,
            body: response.text(),
            headers: response.headers,
        })
    }

    /// `method path` with a JSON body exactly as written, on a raw connection: for the probes
    /// a conforming client will not send as is (see `wire.rs`).
    pub fn wire(&self, method: &str, path: &str, token: Option<&str>, body: &str) -> Reply {
        crate::wire::send(&self.base, method, path, token, body)
    }

    pub fn get(&self, path: &str, token: Option<&str>) -> Reply {
        self.request("GET", path, token, &[], None)
    }

    /// `POST path` with a JSON body.
    pub fn post(&self, path: &str, token: Option<&str>, body: &str) -> Reply {
        self.request("POST", path, token, &[], Some(body))
    }

    /// `POST path` without a body.
    pub fn post_empty(&self, path: &str, token: Option<&str>) -> Reply {
        self.request("POST", path, token, &[], None)
    }

    pub fn delete(&self, path: &str, token: Option<&str>) -> Reply {
        self.request("DELETE", path, token, &[], None)
    }

    /// `GET path` as `token`; asserts the problem+json `status` and returns the problem.
    pub fn get_problem(&self, path: &str, token: Option<&str>, status: u16) -> serde_json::Value {
        self.get(path, token).problem(status)
    }

    /// `GET path` as the engineer; asserts 200 and returns the JSON body.
    pub fn get_json(&self, path: &str) -> serde_json::Value {
        let r = self.get(path, Some(ENGINEER));
        assert_eq!(r.status, 200, "{path}: {}", r.body);
        r.json()
    }

    /// `POST /v1/jobs` with `body` as the engineer (the raw reply).
    pub fn post_job(&self, body: &str) -> Reply {
        self.post("/v1/jobs", Some(ENGINEER), body)
    }

    /// `POST /v1/jobs` with `body` as the engineer; asserts 201 and returns the new job's id.
    pub fn submit_job(&self, body: &str) -> String {
        let r = self.post_job(body);
        assert_eq!(r.status, 201, "{}", r.body);
        r.json()["id"].as_str().expect("job id").to_string()
    }

    /// The job record `GET /v1/jobs/{id}` as the engineer, typed.
    pub fn job(&self, id: &str) -> JobView {
        let j = self.get_json(&format!("/v1/jobs/{id}"));
        serde_json::from_value(j.clone()).unwrap_or_else(|e| panic!("not a job ({e}): {j}"))
    }

    /// Polls the job until `done` holds for its record; the record (panics on timeout).
    pub fn wait_job_until(
        &self,
        id: &str,
        what: &str,
        timeout: Duration,
        mut done: impl FnMut(&JobView) -> bool,
    ) -> JobView {
        wait_for(timeout, what, || Some(self.job(id)).filter(|j| done(j)))
    }

    /// Polls the job until its status is `status` (panics if it fails first, or on timeout).
    pub fn wait_job(&self, id: &str, status: JobStatus, timeout: Duration) -> JobView {
        self.wait_job_until(id, status.as_str(), timeout, |j| {
            assert!(
                j.status != JobStatus::Failed || status == JobStatus::Failed,
                "job failed: {j:?}"
            );
            j.status == status
        })
    }

    /// The child jobs of `id` (`GET /v1/jobs?parent={id}`, one page of 100).
    pub fn children(&self, id: &str) -> Vec<JobView> {
        let page = self.get_json(&format!("/v1/jobs?parent={id}&limit=100"));
        serde_json::from_value(page["items"].clone())
            .unwrap_or_else(|e| panic!("not a page of jobs ({e}): {page}"))
    }

    /// `POST /v1/jobs/{id}/cancel` as the engineer.
    pub fn cancel_job(&self, id: &str) -> Reply {
        self.post_empty(&format!("/v1/jobs/{id}/cancel"), Some(ENGINEER))
    }

    /// `POST /v1/rails/{serial}/measurements` with `body` as the planner.
    pub fn post_rail(&self, serial: &str, body: &str) -> Reply {
        self.post(
            &format!("/v1/rails/{serial}/measurements"),
            Some(PLANNER),
            body,
        )
    }

    /// `GET /v1/rails/{serial}/report` as the planner.
    pub fn rail_report(&self, serial: &str) -> Reply {
        self.get(&format!("/v1/rails/{serial}/report"), Some(PLANNER))
    }

    /// Uploads the campaign manifest `toml` (no CSV records) as a test engineer; the stored
    /// campaign's id.
    pub fn upload_campaign(&self, toml: &str) -> String {
        let campaign =
            railwear::gap::Campaign::from_toml_str(toml, Path::new(".")).expect("campaign");
        let body = serde_json::to_string(&campaign).expect("campaign JSON");
        let r = self.post("/v1/campaigns", Some(TEST_ENGINEER), &body);
        assert_eq!(r.status, 201, "{}", r.body);
        r.json()["id"].as_str().expect("campaign id").to_string()
    }
}

/// Which computations the in-process service runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Runner {
    /// The counting test double (`support::runner::CountingRunner`).
    Counting,
    /// The production runner on the shipped `configs/`.
    Library,
}

/// The service in this process on port 0 with a fresh SQLite file (or the database its config
/// names), and an [`Api`] to it (`app.job(..)` etc. through `Deref`).
pub struct TestApp {
    pub api: Api,
    pub service: RunningService,
    /// Holds the SQLite file; removed when the app drops.
    dir: TempDir,
}

impl std::ops::Deref for TestApp {
    type Target = Api;
    fn deref(&self) -> &Api {
        &self.api
    }
}

impl TestApp {
    /// The counting runner with workers.
    pub async fn spawn() -> TestApp {
        Self::spawn_with(Runner::Counting, true, |_| {}).await
    }

    /// The counting runner without workers (jobs stay queued).
    pub async fn spawn_idle() -> TestApp {
        Self::spawn_with(Runner::Counting, false, |_| {}).await
    }

    /// `runner`, with or without workers, the test config changed by `tweak` (e.g. another
    /// `database_url`, a smaller body limit).
    pub async fn spawn_with(
        runner: Runner,
        workers: bool,
        tweak: impl FnOnce(&mut ServiceConfig),
    ) -> TestApp {
        let dir = temp_dir("app");
        let mut config = test_config(&dir.db_url());
        tweak(&mut config);
        let service = match runner {
            Runner::Counting => start(config, workers).await,
            Runner::Library => start_library(config, workers).await,
        };
        TestApp {
            api: Api::new(&format!("http://{}", service.addr)),
            service,
            dir,
        }
    }

    /// Clean shutdown ([`RunningService::stop`]); the database goes with the app.
    /// Stops the service; the returned guard keeps its database file until it drops, for a
    /// test that reads the store after the shutdown.
    pub async fn stop(self) -> TempDir {
        self.service.stop().await;
        self.dir
    }
}

/// The real `railwear serve` binary on a free port (killed on drop).
pub struct Binary {
    pub process: ServerProcess,
    pub api: Api,
    pub base: String,
}

impl std::ops::Deref for Binary {
    type Target = Api;
    fn deref(&self) -> &Api {
        &self.api
    }
}

impl Binary {
    /// Start `railwear serve` on the database `db_url` with extra env vars.
    pub fn start(db_url: &str, extra_env: &[(&str, &str)]) -> Binary {
        Self::start_with_args(db_url, extra_env, &[])
    }

    /// [`Binary::start`] with more `serve` arguments (e.g. `--no-workers`).
    pub fn start_with_args(db_url: &str, extra_env: &[(&str, &str)], args: &[&str]) -> Binary {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut cmd = testkit::serve_command(
            Path::new(env!("CARGO_BIN_EXE_railwear")),
            db_url,
            &tokens_env(),
            &root.join("configs"),
        );
        cmd.current_dir(root)
            .args(args)
            .envs(extra_env.iter().copied());
        let process = ServerProcess::spawn(cmd, Duration::from_secs(60)).expect("start railwear");
        let base = process.base_url();
        Binary {
            api: Api::new(&base),
            base,
            process,
        }
    }

    /// SIGKILL: no shutdown code runs.
    pub fn kill9(self) {
        self.process.kill();
    }
}
