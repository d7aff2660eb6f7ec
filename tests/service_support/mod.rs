//! Shared helpers for the service integration tests: a curl-driven HTTP client, the real binary
//! on a free port with a fresh SQLite database, and an in-process service with a test runner.
#![allow(dead_code)]

pub mod runner;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

pub const ADMIN: &str = "admin-token-0123456789abcdef";
pub const ENGINEER: &str = "engineer-token-0123456789abcdef";
pub const PLANNER: &str = "planner-token-0123456789abcdef";
pub const TEST_ENGINEER: &str = "test-engineer-token-0123456789abcdef";

/// `RAILWEAR_TOKENS` value for the four test tokens.
pub fn tokens_env() -> String {
    format!(
        "root:admin:{ADMIN},eng:engineer:{ENGINEER},plan:planner:{PLANNER},\
         lab:test-engineer:{TEST_ENGINEER}"
    )
}

/// A fresh directory under the system temp dir, removed on drop.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> Self {
        let dir = std::env::temp_dir().join(format!(
            "railwear-{tag}-{}-{}",
            std::process::id(),
            uuid::Uuid::new_v4().simple()
        ));
        std::fs::create_dir_all(&dir).expect("temp dir");
        TempDir(dir)
    }
    pub fn db_url(&self) -> String {
        format!("sqlite://{}?mode=rwc", self.0.join("railwear.db").display())
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// One HTTP response as seen by curl.
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

/// Run curl: `method url`, optional bearer token, extra headers, optional body (sent as JSON
/// unless a Content-Type header is given).
pub fn curl(
    method: &str,
    url: &str,
    token: Option<&str>,
    headers: &[(&str, &str)],
    body: Option<&str>,
) -> Reply {
    let mut cmd = Command::new("curl");
    cmd.args(["-sS", "-i", "--max-time", "60", "-X", method, url]);
    if let Some(token) = token {
        cmd.arg("-H").arg(format!("Authorization: Bearer {token}"));
    }
    let mut has_type = false;
    for (k, v) in headers {
        has_type |= k.eq_ignore_ascii_case("content-type");
        cmd.arg("-H").arg(format!("{k}: {v}"));
    }
    if body.is_some() {
        if !has_type {
            cmd.args(["-H", "Content-Type: application/json"]);
        }
        cmd.args(["-H", "Expect:"]);
        cmd.arg("--data-binary").arg("@-");
        cmd.stdin(Stdio::piped());
    }
    cmd.stdout(Stdio::piped()).stderr(Stdio::piped());
    let mut child = cmd.spawn().expect("curl must be installed");
    if let Some(body) = body {
        use std::io::Write;
        let mut stdin = child.stdin.take().expect("stdin");
        let _ = stdin.write_all(body.as_bytes());
    }
    let out = child.wait_with_output().expect("curl ran");
    assert!(
        out.status.success(),
        "curl {method} {url} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let (head, body) = text.split_once("\r\n\r\n").unwrap_or((&text, ""));
    let mut lines = head.lines();
    let status = lines
        .next()
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let headers = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
        .collect();
    Reply {
        status,
        headers,
        body: body.to_string(),
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

/// The real `railwear serve` binary on a free port.
pub struct Binary {
    pub child: Child,
    pub base: String,
}

impl Binary {
    /// Start `railwear serve` with a fresh or given database and extra env vars.
    pub fn start(db_url: &str, extra_env: &[(&str, &str)]) -> Binary {
        Self::start_with_args(db_url, extra_env, &[])
    }

    /// [`Binary::start`] with more `serve` arguments (e.g. `--no-workers`).
    pub fn start_with_args(db_url: &str, extra_env: &[(&str, &str)], args: &[&str]) -> Binary {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_railwear"));
        cmd.current_dir(root)
            .args(["serve", "--listen", "127.0.0.1:0"])
            .args(args)
            .env("DATABASE_URL", db_url)
            .env("RAILWEAR_TOKENS", tokens_env())
            .env("RAILWEAR_CONFIGS_DIR", root.join("configs"))
            .env("RUST_LOG", "warn")
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit());
        for (k, v) in extra_env {
            cmd.env(k, v);
        }
        let mut child = cmd.spawn().expect("start railwear");
        let stdout = child.stdout.take().expect("stdout");
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if let Some(addr) = line.strip_prefix("listening on ") {
                    let _ = tx.send(addr.to_string());
                }
            }
        });
        let base = rx
            .recv_timeout(Duration::from_secs(60))
            .expect("server printed its address");
        Binary { child, base }
    }

    pub fn url(&self, path: &str) -> String {
        format!("{}{path}", self.base)
    }

    /// SIGKILL: no shutdown code runs.
    pub fn kill9(mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for Binary {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `GET {base}{path}` as the engineer; asserts 200 and returns the JSON body.
/// Uploads the campaign manifest `toml` (no CSV records) as a test engineer; the stored
/// campaign's id.
pub fn upload_campaign(base: &str, toml: &str) -> String {
    let campaign = railwear::gap::Campaign::from_toml_str(toml, Path::new(".")).expect("campaign");
    let body = serde_json::to_string(&campaign).expect("campaign JSON");
    let r = curl(
        "POST",
        &format!("{base}/v1/campaigns"),
        Some(TEST_ENGINEER),
        &[],
        Some(&body),
    );
    assert_eq!(r.status, 201, "{}", r.body);
    r.json()["id"].as_str().expect("campaign id").to_string()
}

pub fn get_json(base: &str, path: &str) -> serde_json::Value {
    let r = curl("GET", &format!("{base}{path}"), Some(ENGINEER), &[], None);
    assert_eq!(r.status, 200, "{path}: {}", r.body);
    r.json()
}

/// The job record `GET /v1/jobs/{id}` as the engineer.
pub fn get_job(base: &str, id: &str) -> serde_json::Value {
    get_json(base, &format!("/v1/jobs/{id}"))
}

/// `POST /v1/jobs` with `body` as the engineer; asserts 201 and returns the new job's id.
pub fn submit_job(base: &str, body: &str) -> String {
    let r = curl(
        "POST",
        &format!("{base}/v1/jobs"),
        Some(ENGINEER),
        &[],
        Some(body),
    );
    assert_eq!(r.status, 201, "{}", r.body);
    r.json()["id"].as_str().expect("job id").to_string()
}
