//! `railwear plan-test`: the next tests of a diagnosed campaign, planned again from its stored
//! report, printed with what each would decide and as campaign test entries ready to append;
//! and the "Next tests" section `railwear diagnose` prints.

use crate::gap::campaign::{Campaign, CampaignTest};
use crate::gap::diagnose::{DiagnoseOptions, ProposedTest, Report, Simulating};
use crate::pipeline::RunControl;
use anyhow::{Context, Result};
use std::path::PathBuf;

/// `railwear plan-test`'s arguments.
#[derive(Debug, Clone, clap::Args)]
pub struct PlanTestArgs {
    /// Campaign manifest (TOML, CSV files beside it).
    pub campaign: PathBuf,
    /// The campaign's report.json from `railwear diagnose` (its window is reused).
    #[arg(long)]
    pub report: PathBuf,
    /// Print the proposed tests' JSON instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Directory of reference configs and profiles.
    #[arg(long, env = "RAILWEAR_CONFIGS_DIR", default_value = "configs")]
    pub configs_dir: PathBuf,
}

/// `railwear plan-test <campaign> --report <report.json>`: the campaign's next tests planned
/// again from its stored report at the report's window (`railwear diagnose` prints them as it
/// diagnoses). Prints the tests and their TOML entries, or their JSON with `--json`.
pub fn plan_test(args: &PlanTestArgs) -> Result<()> {
    let (file, report_file, json, configs_dir) = (
        args.campaign.as_path(),
        args.report.as_path(),
        args.json,
        args.configs_dir.as_path(),
    );
    let campaign = Campaign::load(file)
        .and_then(|c| c.validate(configs_dir).map(|()| c))
        .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    let path = report_file;
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let report: Report = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a diagnosis report", path.display()))?;
    if report.campaign != campaign.name {
        anyhow::bail!(
            "{}: the report is of campaign `{}`, not `{}`",
            path.display(),
            report.campaign,
            campaign.name
        );
    }
    let mut options = DiagnoseOptions::default();
    options.emulator.window_s = report.emulator.window_s;
    options.emulator.settle_s = report.emulator.settle_s;
    crate::gap::diagnose::check_options(&options)?;
    let cache = crate::gap::window::WindowCache::new();
    let sim = Simulating {
        campaign: &campaign,
        options: &options,
        configs_dir,
        control: &RunControl::silent(),
        cache: &cache,
    };
    let tests = crate::gap::diagnose::propose_next_tests(&campaign, &report, sim)?;
    if json {
        println!("{}", serde_json::to_string_pretty(&tests)?);
        return Ok(());
    }
    println!("{}: {}", report.campaign, report.summary);
    println!("{}", next_tests_text(&tests));
    if !tests.is_empty() {
        println!("\ncampaign entries (append to the manifest, run, fill in the masses):\n");
        for t in &tests {
            println!("{}", test_toml(&t.test)?);
        }
    }
    Ok(())
}

/// The "Next tests" section of a text summary.
pub(crate) fn next_tests_text(tests: &[ProposedTest]) -> String {
    let Some(first) = tests.first() else {
        return "next tests: none (nothing left to separate)".to_string();
    };
    let repeated: Vec<&str> = tests
        .iter()
        .filter_map(|t| t.repeats_test.as_deref())
        .collect();
    let mut repeats = if repeated.is_empty() {
        String::new()
    } else {
        format!(
            "repeats of {} (held out, {} cannot be confirmed without them), then ",
            repeated.join(", "),
            first.separates[0]
        )
    };
    if let Some(alone) = first.second_to.as_deref() {
        repeats = format!(
            "{} a second test that carries {} (test {alone} alone carries it), then {repeats}",
            first.test.id, first.separates[0]
        );
    }
    if !repeats.is_empty() {
        repeats = format!("first {repeats}");
    }
    let mut out = format!(
        "next tests ({repeats}to tell {} from {}; decisive: expected log-likelihood ratio above ln 20 against each):",
        first.separates[0],
        first.separates[1..].join(", ")
    );
    for t in tests {
        out.push_str(&format!(
            "\n  {:<8} {}; {} x {:.1} h x {} specimen(s), records {}; {:.1} test hours; {:.1} nats ({})",
            t.test.id,
            t.change,
            t.increments,
            t.increment_duration_s / crate::units::S_PER_H,
            t.repeats,
            if t.accelerometers { "on" } else { "off" },
            t.cost_h,
            t.separation_nats,
            if t.decisive { "decisive" } else { "not decisive" }
        ));
        for d in &t.decides {
            out.push_str(&format!("\n           {d}"));
        }
    }
    out
}

/// A test entry as the manifest's TOML (`[[tests]]` and its specimens).
fn test_toml(test: &CampaignTest) -> Result<String> {
    #[derive(serde::Serialize)]
    struct Entry<'a> {
        tests: [&'a CampaignTest; 1],
    }
    toml::to_string(&Entry { tests: [test] }).context("writing the test entry as TOML")
}
