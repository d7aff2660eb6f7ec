//! A diagnosis' fitted wear mechanism carried to a sweep (`wear_law = {diagnosis = <id>}`):
//! which reports can be carried, and the record the sweep stores
//! ([`crate::pipeline::DiagnosedWearLaw`]).
//!
//! Only what the sweep's runs can reproduce is carried, so the curve is the diagnosis' model:
//! - the verdict must be `explained` or `partly_explained` (a `partly_explained` record keeps
//!   its verdict, and the curve's provenance shows it);
//! - the named effect must be a single wear-law effect: a dynamics effect changes the rig, not
//!   the wear law, and a pair would need both;
//! - `severe_wear` and `local_pressure` act on the contact points' own pressures, which the
//!   diagnosis records and a sweep's run does not: refused rather than silently lumped;
//! - `coating_breakthrough` is carried past breakthrough (distance 0): a sweep point lasts
//!   seconds, the service life thousands of hours, so the curve gives the bare wear rate a
//!   worn-through coating leaves, and the record says so.

use super::report::{Report, Verdict};
use crate::cases::DiagnosedWearLaw;
use crate::field_error::FieldError;
use crate::gap::effects::{info, Acts};

/// The record a sweep stores for diagnosis `id` whose job result is `result` (the report's
/// JSON). Errors name `wear_law.diagnosis` and say why the report cannot be carried.
pub fn carried_wear_law(
    id: uuid::Uuid,
    result: &serde_json::Value,
) -> Result<DiagnosedWearLaw, FieldError> {
    let refuse = |rule: String| FieldError::new("wear_law.diagnosis", rule);
    let report: Report = serde_json::from_value(result.clone()).map_err(|e| {
        refuse(format!(
            "diagnosis {id}'s report could not be read ({e}); run the diagnosis again"
        ))
    })?;
    let verdict = match report.verdict {
        Verdict::Explained => "explained",
        Verdict::PartlyExplained => "partly_explained",
        Verdict::NoGap => {
            return Err(refuse(format!(
                "diagnosis {id} found no gap: the config's own wear law is what it supports"
            )))
        }
        Verdict::NotExplained => {
            return Err(refuse(format!(
                "diagnosis {id} explained nothing (not_explained): it fitted no mechanism to \
                 carry"
            )))
        }
    };
    let best = report
        .best_effect
        .as_ref()
        .ok_or_else(|| refuse(format!("diagnosis {id} names no effect")))?;
    if best.name.contains('+') {
        return Err(refuse(format!(
            "diagnosis {id} named the pair `{}`; a sweep carries one wear mechanism, and a \
             dynamics effect changes the rig, not the wear law",
            best.name
        )));
    }
    let effect = info(&best.name).ok_or_else(|| {
        refuse(format!(
            "names `{}`, not an effect of this library",
            best.name
        ))
    })?;
    if effect.acts != Acts::WearLaw {
        return Err(refuse(format!(
            "diagnosis {id} named `{}`, a dynamics effect (it changes the rig or its drive, not \
             the wear law): nothing to carry to a launcher's wear",
            best.name
        )));
    }
    if matches!(best.name.as_str(), "severe_wear" | "local_pressure") {
        return Err(refuse(format!(
            "`{}` acts on the contact points' own pressures, which the diagnosis records and a \
             sweep's run does not",
            best.name
        )));
    }
    let mut parameters: std::collections::BTreeMap<String, f64> = best
        .parameters
        .iter()
        .filter(|p| p.effect == best.name)
        .map(|p| (p.name.clone(), p.value))
        .collect();
    let mut note = String::new();
    if best.name == "coating_breakthrough" {
        let distance = parameters.insert("breakthrough_slip_m".into(), 0.0);
        note = format!(
            "breakthrough distance {} m set to 0: the curve is the wear rate past breakthrough",
            distance.map_or("(default)".to_string(), |d| format!("{d}"))
        );
    }
    Ok(DiagnosedWearLaw {
        diagnosis: id,
        effect: best.name.clone(),
        parameters,
        verdict: verdict.to_string(),
        note,
    })
}
