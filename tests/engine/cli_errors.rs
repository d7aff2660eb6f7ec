//! A failed CLI command prints one line, `error: ` and the chain of causes naming the field and
//! the rule, and exits with status 1: never a stack backtrace, even with `RUST_BACKTRACE=1`
//! set (as it is on the development machines).

use std::path::PathBuf;
use std::process::{Command, Output};

fn railwear(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_railwear"))
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .env("RUST_LIB_BACKTRACE", "1")
        .output()
        .expect("railwear runs")
}

fn assert_one_line_error(out: &Output, names: &[&str]) {
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("error: "), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(!err.to_lowercase().contains("backtrace"), "{err}");
    for name in names {
        assert!(err.contains(name), "{name} missing from: {err}");
    }
}

#[test]
fn a_missing_case_file_is_one_line_naming_the_file() {
    let out = railwear(&[
        "run",
        "/nonexistent/railwear-case.toml",
        "--duration",
        "0.1",
    ]);
    assert_one_line_error(
        &out,
        &[
            "cannot read the case file",
            "/nonexistent/railwear-case.toml",
        ],
    );
}

#[test]
fn a_profile_missing_from_the_configs_directory_names_the_field_and_the_flag() {
    // A configs directory holding the launcher's case but not its profiles/.
    let dir: PathBuf =
        std::env::temp_dir().join(format!("railwear-cli-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let case = dir.join("launcher-design.toml");
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    std::fs::copy(manifest.join("configs/launcher-design.toml"), &case).unwrap();
    let out = railwear(&[
        "run",
        case.to_str().unwrap(),
        "--configs-dir",
        dir.to_str().unwrap(),
        "--duration",
        "0.1",
    ]);
    std::fs::remove_dir_all(&dir).ok();
    assert_one_line_error(&out, &["`excitation.profile`", "--configs-dir", "profiles"]);
}

#[test]
fn the_cli_refuses_what_the_api_refuses_with_the_same_field_and_rule() {
    // The service checks a job's inline config with pipeline::resolve_case; `railwear run`
    // must refuse the same file for the same reason (it once ran mu_dynamic = 1e6 to the end).
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(manifest.join("configs/rattle-box-c.toml")).unwrap();
    let bad: String = text
        .lines()
        .map(|l| {
            if l.trim_start().starts_with("mu_dynamic") {
                "mu_dynamic = 1e6".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let path = std::env::temp_dir().join(format!("railwear-cli-bad-{}.toml", std::process::id()));
    std::fs::write(&path, &bad).unwrap();
    let out = railwear(&["run", path.to_str().unwrap(), "--duration", "0.01"]);
    std::fs::remove_file(&path).ok();
    // What the service answers to the same case sent inline as a simulate job's config.
    let table: toml::Value = toml::from_str(&bad).unwrap();
    let params = serde_json::json!({"config": serde_json::to_value(&table).unwrap()});
    let configs = manifest.join("configs");
    let api = railwear::pipeline::resolve_case(&params, &configs, |_| Ok(()));
    let Err(railwear::pipeline::RunError::InvalidConfig { field, rule }) = api else {
        panic!("the service's parser accepted mu_dynamic = 1e6");
    };
    assert_eq!(field, "config.rattle_box.friction.mu_dynamic");
    assert_one_line_error(&out, &["`rattle_box.friction.mu_dynamic`", &rule]);
    // And a duration past the service's bound names the flag with the service's rule.
    let out = railwear(&["run", "configs/rattle-box-c.toml", "--duration", "1e9"]);
    assert_one_line_error(&out, &["`--duration`", "24 h"]);
}
