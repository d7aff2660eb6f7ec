//! A sweep's wear law taken from a gap diagnosis (issue 26, "carried to the planner"):
//! `wear_law = {diagnosis = "<job id>"}`.
//!
//! The service resolves the diagnosis when the sweep is submitted (`jobs::Jobs::submit`, from
//! the stored report through `gap::diagnose::carry`) and stores the resolved form, so the
//! sweep, its point jobs and its curve's provenance all read one record: which diagnosis,
//! which effect, its fitted parameters in the library's units, and the verdict they came with.
//! The plan turns that record into the case's `wear.mechanism` with the launcher's own
//! hardness (the dimensionless coefficients are properties of the material pair; K = k/H).

use crate::field_error::FieldError;
use crate::wear::mechanism::{WearEffect, WearMechanism};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A wear mechanism a gap diagnosis fitted, as a sweep carries it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiagnosedWearLaw {
    /// Id of the diagnose job whose report gave the mechanism.
    pub diagnosis: uuid::Uuid,
    /// The wear-law effect it named (`impact_wear`, `third_body`, ...).
    pub effect: String,
    /// Its parameters in the effect library's names and units (fitted, or the library default
    /// where the diagnosis held them).
    pub parameters: BTreeMap<String, f64>,
    /// The diagnosis' verdict (`explained` or `partly_explained`).
    pub verdict: String,
    /// What the carrying changed and why (e.g. a coating's breakthrough distance set to 0:
    /// the curve is the wear rate past breakthrough), empty when nothing.
    #[serde(default)]
    pub note: String,
}

impl DiagnosedWearLaw {
    /// The wear-law name of the sweep's curve (its key's last part): `diagnosis-<id>`.
    pub fn curve_name(&self) -> String {
        format!("diagnosis-{}", self.diagnosis)
    }

    /// The mechanism for a case whose softer body has indentation hardness `hardness_pa`.
    pub fn mechanism(&self, hardness_pa: f64) -> Result<WearMechanism, FieldError> {
        let mechanism = WearEffect::from_values(&self.effect, &self.parameters)
            .map_err(|e| e.at("wear_law.parameters"))?
            .ok_or_else(|| {
                FieldError::new(
                    "wear_law.effect",
                    format!("`{}` is not a wear-law effect", self.effect),
                )
            })?
            .mechanism(hardness_pa);
        mechanism
            .validate()
            .map_err(|crate::wear::WearError::Invalid(e)| {
                FieldError::new(format!("wear_law.parameters.{}", e.field), e.rule)
            })?;
        Ok(mechanism)
    }
}

/// What a sweep's `wear_law` param holds: a law's name, or a diagnosis' mechanism.
#[derive(Debug, Clone, PartialEq)]
pub enum SweepWearLaw {
    /// A wear-law name (`modified-archard`, `archard`, `legacy-appendix`).
    Named(String),
    /// A mechanism a diagnosis fitted (resolved by the service at submission).
    Diagnosed(DiagnosedWearLaw),
}

impl SweepWearLaw {
    /// Reads `params.wear_law` (absent: `default`). An object is the resolved form; the bare
    /// `{"diagnosis": "<id>"}` a client sends is resolved by the service before this runs.
    pub fn from_param(
        value: Option<&serde_json::Value>,
        default: &str,
    ) -> Result<Self, FieldError> {
        match value {
            None => Ok(Self::Named(default.to_string())),
            Some(serde_json::Value::String(s)) => Ok(Self::Named(s.clone())),
            Some(serde_json::Value::Object(map)) => {
                if map.len() == 1 && map.contains_key("diagnosis") {
                    return Err(FieldError::new(
                        "wear_law.diagnosis",
                        "is resolved by the service when the sweep is submitted (POST \
                         /v1/jobs); this runner cannot read stored diagnoses",
                    ));
                }
                serde_json::from_value(serde_json::Value::Object(map.clone()))
                    .map(Self::Diagnosed)
                    .map_err(|e| {
                        FieldError::new("wear_law", format!("is not a resolved diagnosis: {e}"))
                    })
            }
            Some(_) => Err(FieldError::new(
                "wear_law",
                "must be a wear-law name or {\"diagnosis\": \"<diagnose job id>\"}",
            )),
        }
    }

    /// The wear-law part of the curve key.
    pub fn curve_name(&self) -> String {
        match self {
            Self::Named(name) => name.clone(),
            Self::Diagnosed(d) => d.curve_name(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wear::mechanism::ImpactWear;

    fn impact(k: f64) -> DiagnosedWearLaw {
        DiagnosedWearLaw {
            diagnosis: uuid::Uuid::nil(),
            effect: "impact_wear".into(),
            parameters: [
                ("k_energy_m3_per_j".to_string(), k),
                ("min_normal_speed_m_s".to_string(), 0.0),
            ]
            .into_iter()
            .collect(),
            verdict: "explained".into(),
            note: String::new(),
        }
    }

    #[test]
    fn a_diagnosed_impact_wear_becomes_the_mechanism() {
        let m = impact(2.5e-13).mechanism(1.32e9).unwrap();
        assert_eq!(
            m,
            WearMechanism::ImpactWear(ImpactWear {
                k_energy_m3_per_j: 2.5e-13,
                min_normal_speed_m_s: 0.0
            })
        );
        assert_eq!(
            impact(1.0).curve_name(),
            "diagnosis-00000000-0000-0000-0000-000000000000"
        );
    }

    #[test]
    fn a_dimensionless_coefficient_is_divided_by_the_hardness() {
        let d = DiagnosedWearLaw {
            effect: "third_body".into(),
            parameters: [
                ("k_abrasive".to_string(), 1.0e-4),
                ("min_pressure_pa".to_string(), 0.0),
                ("min_slip_m_s".to_string(), 0.0),
            ]
            .into_iter()
            .collect(),
            ..impact(0.0)
        };
        match d.mechanism(2.0e9).unwrap() {
            WearMechanism::ThirdBody(t) => assert_eq!(t.k_add_m2_per_n, 5.0e-14),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn bad_records_name_the_field() {
        let mut d = impact(1e-13);
        d.parameters.remove("min_normal_speed_m_s");
        let e = d.mechanism(1e9).unwrap_err();
        assert_eq!(e.field, "wear_law.parameters.min_normal_speed_m_s");
        let e = impact(-1.0).mechanism(1e9).unwrap_err();
        assert_eq!(e.field, "wear_law.parameters.k_energy_m3_per_j");
        let mut d = impact(1e-13);
        d.effect = "cross_axis".into();
        assert_eq!(d.mechanism(1e9).unwrap_err().field, "wear_law.effect");
        let bare = serde_json::json!({"diagnosis": uuid::Uuid::nil()});
        let e = SweepWearLaw::from_param(Some(&bare), "x").unwrap_err();
        assert_eq!(e.field, "wear_law.diagnosis");
        let e = SweepWearLaw::from_param(Some(&serde_json::json!(3)), "x").unwrap_err();
        assert_eq!(e.field, "wear_law");
    }
}
