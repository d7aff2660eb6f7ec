//! A case's one parser: a reference config or an inline case object, with overrides and a seed
//! merged in, to a validated [`CaseSpec`] (unknown keys, the physical bounds of
//! [`super::bounds`] on the typed case, the run-control limits of [`super::limits`], the
//! model's own rules) and the model built once to prove it builds. Used by every job kind, the
//! CLI, the campaigns and the virtual rig.

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

/// Checks the run-control limits between fields of [`limits`] (each field's own range is its
/// bound, checked with the others); the error's field is a case path.
fn check_simulation_bounds(case: &CaseSpec) -> Result<(), FieldError> {
    let s = &case.simulation;
    let bad = |field: &str, rule: String| Err(FieldError::new(field, rule).at("simulation"));
    let dt = s.record_interval_s;
    if dt > s.duration_s {
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

/// Checks every number and text of the typed case against its bound ([`super::bounds`]),
/// including the motion an excitation profile stands for.
fn check_physical_bounds(case: &CaseSpec, configs_dir: &Path) -> Result<(), RunError> {
    let resolved = match case.excitation.kind() {
        crate::models::spec::Excitation::Profile(_) => {
            Some(crate::models::case::resolve_excitation(case, configs_dir)?)
        }
        crate::models::spec::Excitation::Motion(_) => None,
    };
    super::bounds::check_case(case, resolved.as_ref())?;
    Ok(())
}

/// The path of the value a type error of serde's names, when serde read the table at `path`
/// whole (a tagged wear law, the excitation) and so reports the table: the first scalar below
/// it that is the value the `message` quotes (`invalid type: string "NaN", expected f64`).
/// Otherwise `path` itself.
fn value_path(case: &serde_json::Value, path: &str, message: &str) -> String {
    use serde::de::Unexpected;
    use serde_json::Value;
    fn go(value: &Value, path: &mut String, message: &str) -> bool {
        match value {
            Value::Object(map) => map.iter().any(|(k, v)| {
                let len = path.len();
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(k);
                let found = go(v, path, message);
                if !found {
                    path.truncate(len);
                }
                found
            }),
            Value::Array(items) => items.iter().enumerate().any(|(i, v)| {
                let len = path.len();
                path.push_str(&format!("[{i}]"));
                let found = go(v, path, message);
                if !found {
                    path.truncate(len);
                }
                found
            }),
            scalar => quotes(message, scalar),
        }
    }
    // The value a type error quotes (`floating point `1e+308``, `string "NaN"`, `boolean
    // `true``), numbers compared by value (serde_json prints them its own way).
    fn quotes(message: &str, scalar: &Value) -> bool {
        let Some(quoted) = ["invalid type: ", "invalid value: "]
            .iter()
            .find_map(|head| {
                let rest = &message[message.find(head)? + head.len()..];
                Some(rest.split(", expected").next().unwrap_or(rest))
            })
        else {
            return false;
        };
        match scalar {
            Value::Number(n) => {
                let kind = if n.is_f64() {
                    "floating point `"
                } else {
                    "integer `"
                };
                quoted
                    .strip_prefix(kind)
                    .and_then(|q| q.strip_suffix('`'))
                    .and_then(|q| q.parse::<f64>().ok())
                    .is_some_and(|q| n.as_f64() == Some(q))
            }
            Value::String(s) => quoted == Unexpected::Str(s).to_string(),
            Value::Bool(b) => quoted == Unexpected::Bool(*b).to_string(),
            _ => false,
        }
    }
    let path = path.trim_start_matches('.');
    let mut table = case;
    for part in path.split('.').filter(|p| !p.is_empty()) {
        let (key, indices) = part.split_once('[').unwrap_or((part, ""));
        let next = table.get(key).and_then(|v| {
            indices
                .split('[')
                .filter(|i| !i.is_empty())
                .try_fold(v, |v, i| {
                    v.get(i.trim_end_matches(']').parse::<usize>().ok()?)
                })
        });
        match next {
            Some(v) => table = v,
            None => return path.to_string(),
        }
    }
    let mut found = path.to_string();
    if (table.is_object() || table.is_array()) && go(table, &mut found, message) {
        return found;
    }
    path.to_string()
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
    // A value of the wrong type is named at its own path, also inside tables serde reads
    // whole (the tagged wear law, the excitation).
    let mut case: CaseSpec = serde_path_to_error::deserialize(&value).map_err(|e| {
        let rule = e.inner().to_string();
        let path = value_path(&value, &e.path().to_string(), &rule);
        FieldError::new(locate(&path, overrides), rule)
    })?;
    adjust(&mut case)?;
    let relocate = |e: RunError| match e {
        RunError::InvalidConfig { field, rule } => RunError::InvalidConfig {
            field: locate(&field, overrides),
            rule,
        },
        other => other,
    };
    // The bounds first, on the typed case: a value out of its physical range is named itself,
    // not through a rule between two fields that it happens to break as well (a cube of 1e308
    // m is too large, not a tube too small).
    check_physical_bounds(&case, configs_dir).map_err(relocate)?;
    check_simulation_bounds(&case).map_err(|e| relocate(e.into()))?;
    case.validate().map_err(|e| relocate(e.into()))?;
    crate::models::case::run_options(&case).map_err(relocate)?;
    // Validated above (and not changed since): build without validating again.
    let model = crate::models::case::build_validated(&case, configs_dir).map_err(relocate)?;
    Ok((case, model))
}
