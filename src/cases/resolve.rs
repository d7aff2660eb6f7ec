//! A case's one parser: a reference config or an inline case object, with overrides and a seed
//! merged in, to a validated [`CaseSpec`] (unknown keys, the physical bounds of
//! [`super::bounds`], the run-control limits of [`super::limits`], the model's own rules) and
//! the model built once to prove it builds. Used by every job kind, the CLI, the campaigns and
//! the virtual rig.

use super::{limits, merge_json, RunError};
use crate::field_error::FieldError;
use crate::models::case::read_case;
use crate::models::run::BuiltModel;
use crate::models::spec::CaseSpec;
use std::path::Path;

/// True when the dotted `path` (`simulation.duration_s`) is set in `value`.
fn sets_path(value: &serde_json::Value, path: &str) -> bool {
    let mut v = value;
    for part in path.split('.') {
        match v.get(part) {
            Some(next) => v = next,
            None => return false,
        }
    }
    true
}

/// Where a case field's value came from, as a params path: the overrides when they set it (or
/// a parent of it), otherwise the config.
fn locate(case_field: &str, overrides: Option<&serde_json::Value>) -> String {
    let field = case_field.trim_matches('.');
    if field.is_empty() || field == "toml" {
        return "config".into();
    }
    if let Some(over) = overrides {
        let parts: Vec<&str> = field.split('.').collect();
        for n in (1..=parts.len()).rev() {
            if sets_path(over, &parts[..n].join(".")) {
                return format!("overrides.{field}");
            }
        }
    }
    format!("config.{field}")
}

/// Checks the run-control bounds of [`limits`]; the error's field is a case path.
fn check_simulation_bounds(case: &CaseSpec) -> Result<(), FieldError> {
    let s = &case.simulation;
    let bad = |field: &str, rule: String| Err(FieldError::new(field, rule).at("simulation"));
    if !(s.duration_s.is_finite()
        && s.duration_s >= limits::MIN_RECORD_INTERVAL_S
        && s.duration_s <= limits::MAX_DURATION_S)
    {
        return bad(
            "duration_s",
            format!(
                "must be > 0 (at least one record interval, {:e} s) and <= {} s (24 h of \
                 simulated time), got {}",
                limits::MIN_RECORD_INTERVAL_S,
                limits::MAX_DURATION_S,
                s.duration_s
            ),
        );
    }
    if !(s.settle_s.is_finite() && s.settle_s >= 0.0 && s.settle_s <= limits::MAX_SETTLE_S) {
        return bad(
            "settle_s",
            format!(
                "must be >= 0 and <= {} s (past the contact creep time constant), got {}",
                limits::MAX_SETTLE_S,
                s.settle_s
            ),
        );
    }
    let (lo, hi) = limits::REL_TOLERANCE_RANGE;
    if !(s.rel_tolerance >= lo && s.rel_tolerance <= hi) {
        return bad(
            "rel_tolerance",
            format!("must lie in [{lo:e}, {hi}], got {}", s.rel_tolerance),
        );
    }
    let (lo, hi) = limits::ABS_TOLERANCE_M_RANGE;
    if !(s.abs_tolerance_m >= lo && s.abs_tolerance_m <= hi) {
        return bad(
            "abs_tolerance_m",
            format!("must lie in [{lo:e}, {hi:e}] m, got {}", s.abs_tolerance_m),
        );
    }
    let dt = s.record_interval_s;
    if !(dt.is_finite() && dt >= limits::MIN_RECORD_INTERVAL_S && dt <= s.duration_s) {
        return bad(
            "record_interval_s",
            format!(
                "must lie in [{:e} s, duration_s], got {dt}",
                limits::MIN_RECORD_INTERVAL_S
            ),
        );
    }
    let points = (s.settle_s + s.duration_s) / dt;
    if points > limits::MAX_RECORDED_POINTS {
        return bad(
            "record_interval_s",
            format!(
                "records {points:.3e} time points over settle_s + duration_s; at most {:e} \
                 are kept in memory: raise record_interval_s or shorten the run",
                limits::MAX_RECORDED_POINTS
            ),
        );
    }
    Ok(())
}

/// Checks every number and text of the case against [`super::bounds`], including the
/// excitation a profile name stands for.
fn check_physical_bounds(case: &CaseSpec, configs_dir: &Path) -> Result<(), RunError> {
    let profile = matches!(
        case.excitation.kind(),
        crate::models::spec::Excitation::Profile(_)
    );
    let resolved = if profile {
        let spec = crate::models::case::resolve_excitation(case, configs_dir)?;
        Some(
            serde_json::to_value(&spec)
                .map_err(|e| FieldError::new("excitation", e.to_string()))?,
        )
    } else {
        None
    };
    super::bounds::check_case(case, resolved.as_ref())?;
    Ok(())
}

/// Where a case comes from: a reference config by name (`configs/<name>.toml`) or a whole case
/// object (the schema of those files, as JSON).
#[derive(Debug, Clone, Copy)]
pub enum CaseSource<'a> {
    /// A reference config's name.
    Reference(&'a str),
    /// A case object.
    Inline(&'a serde_json::Value),
}

/// A case from its `source` with `overrides` deep-merged into it (e.g.
/// `{"simulation": {"duration_s": 0.5}}`; must be an object) and `seed` as its
/// `simulation.seed`. `adjust` edits the typed case before it is checked (a sweep sets its
/// excitation, a campaign test its rattle space and drive). The case is checked completely:
/// unknown keys anywhere, the model's own rules (validated once, overrides merged), the
/// bounds of [`limits`] and [`super::bounds`], and the model is built once (excitation,
/// geometry, integrator), so an accepted job does not fail on its configuration later.
/// Errors name the path as job params would (`config`, `config.<path>` or
/// `overrides.<path>`).
pub fn resolve_config(
    source: CaseSource<'_>,
    overrides: Option<&serde_json::Value>,
    seed: Option<u64>,
    configs_dir: &Path,
    adjust: impl FnOnce(&mut CaseSpec) -> Result<(), RunError>,
) -> Result<CaseSpec, RunError> {
    resolve_model(source, overrides, seed, configs_dir, adjust).map(|(case, _)| case)
}

/// [`resolve_config`] with the model it built, for a caller that reads the model (a campaign
/// checks its measurements against the model's bodies) without building it again.
pub fn resolve_model(
    source: CaseSource<'_>,
    overrides: Option<&serde_json::Value>,
    seed: Option<u64>,
    configs_dir: &Path,
    adjust: impl FnOnce(&mut CaseSpec) -> Result<(), RunError>,
) -> Result<(CaseSpec, BuiltModel), RunError> {
    let mut value = match source {
        CaseSource::Reference(name) => {
            let path = crate::models::reference::reference_config_path(configs_dir, name)
                .map_err(|e| FieldError::new("config", e.to_string()))?;
            // Validated once below, with the overrides merged in.
            let case = read_case(&path)?;
            serde_json::to_value(&case).map_err(|e| FieldError::new("config", e.to_string()))?
        }
        CaseSource::Inline(case) => case.clone(),
    };
    if let Some(over) = overrides {
        if !over.is_object() {
            return Err(FieldError::new("overrides", "must be an object").into());
        }
        merge_json(&mut value, over);
    }
    if let Some(seed) = seed {
        merge_json(
            &mut value,
            &serde_json::json!({"simulation": {"seed": seed}}),
        );
    }
    // Bounds on the JSON first: a value of the wrong type or out of range is named at its
    // own path, also inside tables serde reads whole (the tagged wear law).
    super::bounds::check_value(&value, "")
        .map_err(|e| RunError::from(FieldError::new(locate(&e.field, overrides), e.rule)))?;
    let mut case: CaseSpec = serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        FieldError::new(locate(&path, overrides), e.into_inner().to_string())
    })?;
    adjust(&mut case)?;
    let relocate = |e: RunError| match e {
        RunError::InvalidConfig { field, rule } => RunError::InvalidConfig {
            field: locate(&field, overrides),
            rule,
        },
        other => other,
    };
    // The bounds first: a value out of its physical range is named itself, not through a
    // rule between two fields that it happens to break as well (a cube of 1e308 m is too
    // large, not a tube too small).
    check_simulation_bounds(&case).map_err(|e| relocate(e.into()))?;
    check_physical_bounds(&case, configs_dir).map_err(relocate)?;
    case.validate().map_err(|e| relocate(e.into()))?;
    crate::models::case::run_options(&case).map_err(relocate)?;
    // Validated above (and not changed since): build without validating again.
    let model = crate::models::case::build_validated(&case, configs_dir).map_err(relocate)?;
    Ok((case, model))
}
