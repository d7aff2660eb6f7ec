//! `railwear diagnose-bench`: the blind bench's run and its scores, and scoring the outcomes
//! of earlier runs together (`--rescore`).

use crate::pipeline::RunControl;
use anyhow::{Context, Result};
use std::path::Path;

/// `railwear diagnose-bench`: prints the scores and the confusion table; with `rescore` files,
/// scores their outcomes together instead ([`rescore_bench`]).
pub fn diagnose_bench(
    skeleton: &Path,
    options: &crate::gap::diagnose::bench::BenchOptions,
    out: Option<&Path>,
    emulator_file: Option<&Path>,
    rescore: &[std::path::PathBuf],
    configs_dir: &Path,
) -> Result<()> {
    if !rescore.is_empty() {
        return rescore_bench(rescore, out);
    }
    use crate::gap::Campaign;
    let campaign =
        Campaign::load(skeleton).map_err(|e| anyhow::anyhow!("{}: {e}", skeleton.display()))?;
    let started = std::time::Instant::now();
    let scores = crate::gap::diagnose::bench::run(
        &campaign,
        configs_dir,
        options,
        &RunControl::silent(),
        emulator_file,
        &|m| eprintln!("[{:>6.0} s] {m}", started.elapsed().as_secs_f64()),
        &|outcomes| {
            // The finished campaigns' scores after each one, so a run stopped part way keeps them.
            if let Some(path) = out {
                let partial = crate::gap::diagnose::bench::score(outcomes.to_vec());
                if let Err(e) = write_scores(&partial, path) {
                    tracing::warn!(error = %format!("{e:#}"), "diagnose-bench: partial --out not written");
                }
            }
        },
    )?;
    println!(
        "diagnose-bench: {} campaigns on {} (seed {}, window {} s), {:.0} s\n",
        scores.campaigns,
        skeleton.display(),
        options.seed,
        options.rig_window_s,
        started.elapsed().as_secs_f64()
    );
    print_and_write(&scores, out)
}

/// `railwear diagnose-bench --rescore`: the outcomes of earlier runs' `--out` files scored
/// together (each campaign once: a campaign in two files is an error, not counted twice).
pub fn rescore_bench(files: &[std::path::PathBuf], out: Option<&Path>) -> Result<()> {
    use crate::gap::diagnose::bench::{score, Outcome};
    /// The part of a `--out` file read back: its scores are recomputed (a share over no
    /// campaign was written as `null`).
    #[derive(serde::Deserialize)]
    struct OutFile {
        outcomes: Vec<Outcome>,
    }
    let mut outcomes = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for path in files {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        let scores: OutFile = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a diagnose-bench --out file", path.display()))?;
        for o in scores.outcomes {
            if !seen.insert(o.scenario.seed) {
                anyhow::bail!(
                    "{}: campaign {} is already in an earlier file",
                    path.display(),
                    o.scenario.seed
                );
            }
            outcomes.push(o);
        }
    }
    let scores = score(outcomes);
    println!(
        "diagnose-bench: {} campaigns from {} files\n",
        scores.campaigns,
        files.len()
    );
    print_and_write(&scores, out)
}

/// The scores' table on stdout, and the scores with every outcome as JSON in `out` if given.
fn print_and_write(scores: &crate::gap::diagnose::bench::Scores, out: Option<&Path>) -> Result<()> {
    println!("{}", scores.table());
    match out {
        Some(path) => write_scores(scores, path),
        None => Ok(()),
    }
}

/// The scores with every outcome as JSON in `path`, replaced whole (written beside it, then
/// renamed, so a run stopped while writing leaves the previous file).
fn write_scores(scores: &crate::gap::diagnose::bench::Scores, path: &Path) -> Result<()> {
    let partial = path.with_extension("json.part");
    std::fs::write(&partial, serde_json::to_string_pretty(scores)?)
        .with_context(|| format!("writing {}", partial.display()))?;
    std::fs::rename(&partial, path).with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rescore_refuses_a_file_that_is_not_a_bench_output_and_names_it() {
        let dir = std::env::temp_dir().join(format!("railwear-rescore-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let empty = dir.join("empty.json");
        let scores = crate::gap::diagnose::bench::score(Vec::new());
        std::fs::write(&empty, serde_json::to_string(&scores).unwrap()).unwrap();
        let other = dir.join("other.json");
        std::fs::write(&other, "{\"verdict\": \"no_gap\"}").unwrap();
        let out = dir.join("merged.json");
        rescore_bench(&[empty.clone(), empty.clone()], Some(&out)).unwrap();
        let merged: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        assert_eq!(merged["campaigns"], 0);
        let e = rescore_bench(&[empty, other.clone()], None).unwrap_err();
        assert!(format!("{e:#}").contains("other.json"), "{e:#}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
