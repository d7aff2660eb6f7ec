//! Development helper for behaviour-preserving refactors (issue 18): prints a SHA-256 of four
//! runs, so the same command before and after a change shows whether any result moved.
//!
//! - rattle box C, 2 s: summary JSON, tracks CSV and SVG plots;
//! - launcher-design, 2 s: the same;
//! - `railwear validate` (fast anchors): every anchor's measured value, bit for bit;
//! - a 3-point tolerance sweep of 0.5 s per point, one seed: the sweep summary JSON.
//!
//! Usage: `cargo run --release --example refactor_hashes [configs-dir]`
use railwear::pipeline::{simulate_job, sweep_job, CaseOutcome, RunControl};
use sha2::{Digest, Sha256};
use std::path::Path;

fn hex(digest: impl AsRef<[u8]>) -> String {
    digest.as_ref().iter().map(|b| format!("{b:02x}")).collect()
}

fn outcome_hash(o: &CaseOutcome) -> String {
    let mut h = Sha256::new();
    h.update(o.summary.to_string());
    for s in &o.tracks {
        h.update(s.csv_line());
    }
    for (name, svg) in &o.plots {
        h.update(name);
        h.update(svg);
    }
    hex(h.finalize())
}

fn main() -> anyhow::Result<()> {
    let configs = std::env::args().nth(1).unwrap_or_else(|| "configs".into());
    let configs = Path::new(&configs);
    let control = RunControl::silent();
    for config in ["rattle-box-c", "launcher-design"] {
        let params = serde_json::json!({
            "config": config,
            "overrides": {"simulation": {"duration_s": 2.0}},
            "seed": 7
        });
        let o = simulate_job(&params, configs, &control)?;
        println!(
            "{config:<16} {}  ({} track samples)",
            outcome_hash(&o),
            o.tracks.len()
        );
    }
    let mut h = Sha256::new();
    for a in railwear::validation::run_all(false, configs) {
        h.update(format!("{}={:e};", a.name, a.measured));
    }
    println!("{:<16} {}", "validate", hex(h.finalize()));
    let params = serde_json::json!({
        "points": 3,
        "seeds": 1,
        "overrides": {"simulation": {"duration_s": 0.5}},
        "seed": 11
    });
    let (summary, _) = sweep_job(&params, configs, &control)?;
    println!(
        "{:<16} {}",
        "sweep",
        hex(Sha256::digest(summary.to_string()))
    );
    Ok(())
}
