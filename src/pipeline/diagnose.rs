//! Diagnose jobs: the params of a diagnosis of a stored campaign (its id, the SHA-256 of its
//! content and the client's options), parsed and bounded once into [`DiagnosePlan`]. The
//! options' bounds ([`check_window_s`], [`check_settle_s`], [`check_grid_points`]) are the
//! ones the CLI's diagnosis and the virtual rig apply too.

use super::{limits, RunError};
use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};

/// Params a client may give a diagnosis (`POST /v1/campaigns/{id}/diagnoses`).
pub const DIAGNOSE_CLIENT_KEYS: &[&str] =
    &["window_s", "settle_s", "grid_points", "effects", "seed"];

/// Params of a stored `diagnose` job: the client's plus the campaign's id and the SHA-256 of
/// its content, which the service adds at submission.
pub const DIAGNOSE_KEYS: &[&str] = &[
    "campaign_id",
    "campaign_sha256",
    "window_s",
    "settle_s",
    "grid_points",
    "effects",
    "seed",
];

/// A `diagnose` job, parsed and checked: the stored campaign it reads (by id, pinned by the
/// SHA-256 of its content) and the options the client set (absent ones keep the diagnosis'
/// defaults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiagnosePlan {
    /// The campaign's id.
    pub campaign_id: uuid::Uuid,
    /// SHA-256 of the campaign's stored canonical JSON, lower-case hex.
    pub campaign_sha256: String,
    /// Simulated excitation per increment, s ([`check_window_s`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window_s: Option<f64>,
    /// Settle time before each window, s ([`check_settle_s`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_s: Option<f64>,
    /// Grid points per effect parameter ([`check_grid_points`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid_points: Option<usize>,
    /// Library effects to consider (all when absent); at least one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effects: Option<Vec<String>>,
}

/// `window_s` within [`limits::WINDOW_S_RANGE`].
pub fn check_window_s(window_s: f64) -> Result<(), FieldError> {
    let (lo, hi) = limits::WINDOW_S_RANGE;
    if window_s.is_finite() && (lo..=hi).contains(&window_s) {
        Ok(())
    } else {
        Err(FieldError::new(
            "window_s",
            format!("must lie in [{lo}, {hi}] s"),
        ))
    }
}

/// `settle_s` within [0, [`limits::MAX_SETTLE_S`]].
pub fn check_settle_s(settle_s: f64) -> Result<(), FieldError> {
    if settle_s.is_finite() && (0.0..=limits::MAX_SETTLE_S).contains(&settle_s) {
        Ok(())
    } else {
        Err(FieldError::new(
            "settle_s",
            format!("must lie in [0, {}] s", limits::MAX_SETTLE_S),
        ))
    }
}

/// `grid_points` within [`limits::GRID_POINTS`].
pub fn check_grid_points(grid_points: usize) -> Result<(), FieldError> {
    if limits::GRID_POINTS.contains(&grid_points) {
        Ok(())
    } else {
        Err(FieldError::new(
            "grid_points",
            format!("must lie in {}", grid_points_range()),
        ))
    }
}

/// [`limits::GRID_POINTS`] as a rule shows it: `2..=12`.
fn grid_points_range() -> String {
    format!(
        "{}..={}",
        limits::GRID_POINTS.start(),
        limits::GRID_POINTS.end()
    )
}

/// Lower-case hex of a SHA-256: 64 digits.
fn is_sha256(s: &str) -> bool {
    s.len() == 64 && s.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'))
}

impl DiagnosePlan {
    /// Parses a `diagnose` job's params ([`DIAGNOSE_KEYS`]); `effects` must name effects of
    /// `library` (the gap library's names). Errors name the params field.
    pub fn from_params(params: &serde_json::Value, library: &[&str]) -> Result<Self, RunError> {
        let known = DIAGNOSE_CLIENT_KEYS.join(", ");
        let map = params
            .as_object()
            .ok_or_else(|| FieldError::new("params", "must be a JSON object"))?;
        if let Some(key) = map.keys().find(|k| !DIAGNOSE_KEYS.contains(&k.as_str())) {
            return Err(
                FieldError::new(key, format!("is not a known parameter (known: {known})")).into(),
            );
        }
        let submit_here = "is required (submit through POST /v1/campaigns/{id}/diagnoses)";
        let campaign_id = map
            .get("campaign_id")
            .ok_or_else(|| FieldError::new("campaign_id", submit_here))?
            .as_str()
            .and_then(|s| uuid::Uuid::parse_str(s).ok())
            .ok_or_else(|| FieldError::new("campaign_id", "must be a campaign's UUID"))?;
        let campaign_sha256 = map
            .get("campaign_sha256")
            .ok_or_else(|| FieldError::new("campaign_sha256", submit_here))?
            .as_str()
            .filter(|s| is_sha256(s))
            .ok_or_else(|| FieldError::new("campaign_sha256", "must be 64 lower-case hex digits"))?
            .to_string();
        let seconds = |name: &str| -> Result<Option<f64>, FieldError> {
            map.get(name)
                .map(|value| {
                    value
                        .as_f64()
                        .ok_or_else(|| FieldError::new(name, "must be a number of seconds"))
                })
                .transpose()
        };
        let window_s = seconds("window_s")?;
        let settle_s = seconds("settle_s")?;
        let grid_points = map
            .get("grid_points")
            .map(|value| {
                value
                    .as_u64()
                    .map(|n| usize::try_from(n).unwrap_or(usize::MAX))
                    .ok_or_else(|| {
                        FieldError::new(
                            "grid_points",
                            format!("must be an integer in {}", grid_points_range()),
                        )
                    })
            })
            .transpose()?;
        let effects = map
            .get("effects")
            .map(|value| parse_effects(value, library))
            .transpose()?;
        window_s.map(check_window_s).transpose()?;
        settle_s.map(check_settle_s).transpose()?;
        grid_points.map(check_grid_points).transpose()?;
        Ok(Self {
            campaign_id,
            campaign_sha256,
            window_s,
            settle_s,
            grid_points,
            effects,
        })
    }
}

/// A non-empty list of names of `library` effects.
fn parse_effects(value: &serde_json::Value, library: &[&str]) -> Result<Vec<String>, FieldError> {
    let names: Vec<String> = serde_json::from_value(value.clone())
        .map_err(|_| FieldError::new("effects", "must be a list of effect names"))?;
    if names.is_empty() {
        return Err(FieldError::new("effects", "must name at least one effect"));
    }
    for (i, name) in names.iter().enumerate() {
        if let Some(first) = names[..i].iter().position(|n| n == name) {
            return Err(FieldError::new(
                format!("effects[{i}]"),
                format!("`{name}` is already effects[{first}]: name each effect once"),
            ));
        }
        if !library.contains(&name.as_str()) {
            return Err(FieldError::new(
                format!("effects[{i}]"),
                format!(
                    "`{name}` is not a library effect (known: {})",
                    library.join(", ")
                ),
            ));
        }
    }
    Ok(names)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn params(options: serde_json::Value) -> serde_json::Value {
        let mut p = json!({
            "campaign_id": "6f1c1c64-0f4e-4d57-9a53-0d7c2b3a1e10",
            "campaign_sha256": "a".repeat(64),
        });
        super::super::merge_json(&mut p, &options);
        p
    }

    #[test]
    fn options_are_bounded_once_naming_the_field() {
        let library = ["third_body", "misalignment"];
        let ok = DiagnosePlan::from_params(
            &params(json!({"window_s": 0.1, "grid_points": 2, "effects": ["third_body"]})),
            &library,
        )
        .unwrap();
        assert_eq!(ok.window_s, Some(0.1));
        assert_eq!(ok.grid_points, Some(2));
        for (bad, field) in [
            (json!({"window_s": 0}), "window_s"),
            (json!({"window_s": 0.04}), "window_s"),
            (json!({"window_s": 601}), "window_s"),
            (json!({"settle_s": -1.0}), "settle_s"),
            (json!({"grid_points": 13}), "grid_points"),
            (json!({"grid_points": 2.5}), "grid_points"),
            (json!({"effects": []}), "effects"),
            (json!({"effects": ["third_body", "gremlins"]}), "effects[1]"),
            (
                json!({"effects": ["third_body", "third_body"]}),
                "effects[1]",
            ),
            (json!({"colour": "red"}), "colour"),
        ] {
            let Err(RunError::InvalidConfig { field: got, .. }) =
                DiagnosePlan::from_params(&params(bad.clone()), &library)
            else {
                panic!("{bad} is refused");
            };
            assert_eq!(got, field, "{bad}");
        }
    }

    #[test]
    fn a_plan_round_trips_through_its_json() {
        let plan = DiagnosePlan::from_params(
            &params(json!({"window_s": 0.1, "settle_s": 0.02})),
            &["third_body"],
        )
        .unwrap();
        let json = super::super::plan_to_json(&plan).unwrap();
        assert_eq!(
            super::super::plan_from_json::<DiagnosePlan>(&json, "diagnose").unwrap(),
            plan
        );
    }
}
