//! The README's three journeys, run verbatim: the fenced bash blocks marked
//! `<!-- journey: NAME -->` (setup, planner, engineer, test-engineer) are taken from README.md as
//! they stand and run in that order by bash against the real `railwear serve` on a fresh SQLite
//! database. Two things differ from a user's shell, both outside the blocks: `cargo run ... --
//! ARGS` runs the test's own `railwear` binary (a shell function, so no nested cargo), and the
//! service reads a copy of `configs/` whose cases settle 0.05 s and run 0.1 s (every number a
//! journey sends itself, such as the simulate job's 2 s, is kept), so the sweeps finish in a
//! test's time. The journeys need `bash`, `curl` and `python3`; the test says so and skips when
//! one is missing, unless `RAILWEAR_REQUIRE_JOURNEYS` is set (CI sets it).

use crate::helpers::Api;
use crate::support::{temp_dir, tokens_env, ENGINEER, PLANNER, TEST_ENGINEER};
use railwear_testkit::{self as testkit, ServerProcess};
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// The journeys in the order they run; the first defines the helpers the others use.
const JOURNEYS: &[&str] = &["setup", "planner", "engineer", "test-engineer"];

/// The fenced block after `<!-- journey: NAME -->` in `readme`.
fn journey_block(readme: &str, name: &str) -> Option<String> {
    let marker = format!("<!-- journey: {name} -->");
    let after = &readme[readme.find(&marker)? + marker.len()..];
    let body = after.trim_start().strip_prefix("```bash\n")?;
    let end = body.find("\n```")?;
    Some(body[..end].to_string())
}

fn have(tool: &str) -> bool {
    Command::new(tool)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// `configs/` copied to `to` with every case's `settle_s` and `duration_s` cut short.
fn short_configs(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("configs dir");
    for entry in std::fs::read_dir(from).expect("configs").flatten() {
        let path = entry.path();
        let target = to.join(entry.file_name());
        if path.is_dir() {
            short_configs(&path, &target);
            continue;
        }
        let text = std::fs::read_to_string(&path).expect("config");
        let is_case = path.parent() == Some(from)
            && path.extension().is_some_and(|e| e == "toml")
            && entry.file_name() != "service.toml"
            && from.file_name().is_some_and(|n| n == "configs");
        let text = if is_case {
            text.lines()
                .map(|line| {
                    if line.starts_with("settle_s =") {
                        "settle_s = 0.05".to_string()
                    } else if line.starts_with("duration_s =") {
                        "duration_s = 0.1".to_string()
                    } else {
                        line.to_string()
                    }
                })
                .collect::<Vec<_>>()
                .join("\n")
        } else {
            text
        };
        std::fs::write(&target, text).expect("write config");
    }
}

#[test]
fn the_readme_journeys_run_verbatim_on_a_fresh_database() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let blocks: Vec<String> = JOURNEYS
        .iter()
        .map(|name| {
            journey_block(&readme, name)
                .unwrap_or_else(|| panic!("README.md has no block marked `journey: {name}`"))
        })
        .collect();
    let missing: Vec<&str> = ["bash", "curl", "python3"]
        .into_iter()
        .filter(|tool| !have(tool))
        .collect();
    if !missing.is_empty() {
        assert!(
            std::env::var_os("RAILWEAR_REQUIRE_JOURNEYS").is_none(),
            "RAILWEAR_REQUIRE_JOURNEYS is set but {missing:?} not found"
        );
        eprintln!("skipping the README journeys: {missing:?} not found");
        return;
    }

    let dir = temp_dir("journeys");
    let configs = dir.path().join("configs");
    short_configs(&root.join("configs"), &configs);
    std::fs::create_dir_all(dir.path().join("campaigns")).expect("campaigns dir");
    for entry in std::fs::read_dir(root.join("campaigns"))
        .expect("campaigns")
        .flatten()
    {
        std::fs::copy(
            entry.path(),
            dir.path().join("campaigns").join(entry.file_name()),
        )
        .expect("copy campaign");
    }
    let bin = Path::new(env!("CARGO_BIN_EXE_railwear"));
    let mut serve = testkit::serve_command(bin, &dir.db_url(), &tokens_env(), &configs);
    serve.current_dir(dir.path());
    let server = ServerProcess::spawn(serve, Duration::from_secs(60)).expect("start railwear");
    let base = server.base_url();

    // `cargo run [options] -- ARGS` in the blocks runs this binary with ARGS.
    let shim = format!(
        "set -eo pipefail\n\
         cargo() {{ while [ $# -gt 0 ] && [ \"$1\" != -- ]; do shift; done; shift; \"{}\" \"$@\"; }}\n",
        bin.display()
    );
    let script = format!("{shim}{}\n", blocks.join("\n"));
    let output = Command::new("timeout")
        .args(["1500", "bash", "-c", &script])
        .current_dir(dir.path())
        .env("RW", &base)
        .env("DATABASE_URL", dir.db_url())
        .env("RAILWEAR_CONFIGS_DIR", &configs)
        .env("RUST_LOG", "warn")
        .output()
        .expect("run bash");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "the README journeys failed ({}):\nstdout:\n{stdout}\nstderr:\n{stderr}",
        output.status
    );
    // Every job a journey waited for succeeded: the planner's sweep, the engineer's simulation
    // and sweep, the test engineer's diagnosis.
    let ended: Vec<&str> = stdout
        .lines()
        .filter(|l| ["succeeded", "failed", "cancelled"].contains(&l.trim()))
        .collect();
    assert_eq!(
        ended, ["succeeded"; 4],
        "the journeys' jobs:\nstdout:\n{stdout}\nstderr:\n{stderr}"
    );

    // What the journeys promise, read back by the test's own tokens.
    let api = Api::new(&base);
    let report = api.get("/v1/rails/R-1042/report", Some(PLANNER)).json();
    let k_sl = report["service_life"]["k_sl"].as_f64();
    assert!(
        k_sl.is_some_and(|k| k > 0.0 && k <= 1.0),
        "the planner's report has no K_SL in (0, 1]: {report}"
    );
    assert!(
        report["service_life"]["interval"].is_object(),
        "a three-seed curve gives an interval: {report}"
    );
    let curves = api
        .get(
            "/v1/curves?curve_key=ah64/clean/modified-archard",
            Some(ENGINEER),
        )
        .json();
    let versions = curves["items"].as_array().map_or(0, Vec::len);
    assert_eq!(
        versions, 2,
        "the planner's and the engineer's curves: {curves}"
    );
    assert_eq!(
        report["curve"]["version"], 2,
        "the engineer's seven-point curve is the published one: {report}"
    );
    let jobs = api
        .get("/v1/jobs?top_level=true", Some(TEST_ENGINEER))
        .json();
    let kinds: Vec<&str> = jobs["items"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|j| j["kind"].as_str())
        .collect();
    assert_eq!(kinds, ["diagnose", "sweep", "simulate", "sweep"], "{jobs}");
}

#[test]
fn journey_blocks_are_found_as_written() {
    let readme = "text\n<!-- journey: a -->\n```bash\necho 1\necho 2\n```\n\
                  <!-- journey: b -->\n\n```bash\nx=$(y)\n```\n";
    assert_eq!(
        journey_block(readme, "a").as_deref(),
        Some("echo 1\necho 2")
    );
    assert_eq!(journey_block(readme, "b").as_deref(), Some("x=$(y)"));
    assert_eq!(journey_block(readme, "c"), None);
}
