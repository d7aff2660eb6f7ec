//! `railwear run`'s case file, read by the parser the service runs on a job's inline config.

use anyhow::{Context, Result};
use std::path::Path;

/// The case in `config_file` with `--duration` and `--settle` applied, checked by the parser
/// the service runs on a job's inline config (`pipeline::resolve_config`: the model's rules,
/// the bounds of every field, the model built once), so the command line refuses what the API
/// refuses, naming the same field: `rattle_box.friction.mu_dynamic` (the path in the file) here
/// is `params.config.rattle_box.friction.mu_dynamic` there, with the same rule.
pub(super) fn checked_case(
    config_file: &Path,
    duration: Option<f64>,
    settle: Option<f64>,
    configs_dir: &Path,
) -> Result<crate::models::spec::CaseSpec> {
    let text = std::fs::read_to_string(config_file)
        .with_context(|| format!("cannot read the case file {}", config_file.display()))?;
    let table: toml::Value = toml::from_str(&text)
        .with_context(|| format!("{} is not valid TOML", config_file.display()))?;
    let config = serde_json::to_value(&table)
        .with_context(|| format!("{} cannot be read as a case", config_file.display()))?;
    let mut simulation = serde_json::Map::new();
    if let Some(d) = duration {
        simulation.insert("duration_s".into(), d.into());
    }
    if let Some(s) = settle {
        simulation.insert("settle_s".into(), s.into());
    }
    let overrides = serde_json::json!({ "simulation": simulation });
    crate::pipeline::resolve_config(
        crate::pipeline::CaseSource::Inline(&config),
        Some(&overrides),
        None,
        configs_dir,
        |_| Ok(()),
    )
    .map_err(|e| match e {
        crate::pipeline::RunError::InvalidConfig { field, rule } => {
            let field = match field.as_str() {
                "overrides.simulation.duration_s" => "--duration".to_string(),
                "overrides.simulation.settle_s" => "--settle".to_string(),
                _ => field
                    .strip_prefix("config.")
                    .map_or(field.clone(), str::to_string),
            };
            anyhow::anyhow!("{}: `{field}` {rule}", config_file.display())
        }
        other => {
            anyhow::Error::new(other).context(format!("{} cannot be run", config_file.display()))
        }
    })
}
