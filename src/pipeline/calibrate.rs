//! Calibrate jobs: friction and wear-law data sets, parsed and checked, and the fits.

use super::{check_keys, limits, parse_seed, RunError, CALIBRATE_KEYS};
use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};

/// Friction data of a calibrate job (thesis 4.3): the fixture and its torque records.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionData {
    pub fixture: crate::analysis::calibration::Fixture,
    pub records: Vec<crate::analysis::calibration::TorqueRecord>,
}

/// Wear-law data of a calibrate job (thesis 4.4): material density, cutoff and wear tests.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WearLawData {
    /// kg/m³ (default 2810, 7075-T73), within [`limits::DENSITY_KG_M3_RANGE`].
    pub density_kg_m3: f64,
    /// Pa (default 870e6, 2 S_y of 7075-T73), in (0, [`limits::MAX_CUTOFF_PRESSURE_PA`]].
    pub cutoff_pressure_pa: f64,
    pub records: Vec<crate::analysis::calibration::WearTestRecord>,
}

/// A calibrate job's params, parsed and checked ([`CALIBRATE_KEYS`]): the plan a calibrate
/// job stores at submission as its canonical JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrateParams {
    pub friction: Option<FrictionData>,
    pub wear_law: Option<WearLawData>,
}

/// Typed records at `field` (an array of objects with exactly `keys`), 1 to
/// [`limits::MAX_CALIBRATION_RECORDS`] of them.
fn parse_records<T: serde::de::DeserializeOwned>(
    value: Option<&serde_json::Value>,
    field: &str,
    keys: &[&str],
) -> Result<Vec<T>, RunError> {
    let items = value
        .ok_or_else(|| FieldError::new(field, "is required (an array of records)"))?
        .as_array()
        .ok_or_else(|| FieldError::new(field, "must be an array of records"))?;
    if items.is_empty() || items.len() > limits::MAX_CALIBRATION_RECORDS {
        return Err(FieldError::new(
            field,
            format!(
                "must hold 1 to {} records, got {}",
                limits::MAX_CALIBRATION_RECORDS,
                items.len()
            ),
        )
        .into());
    }
    items
        .iter()
        .enumerate()
        .map(|(i, item)| {
            let at = format!("{field}[{i}]");
            check_keys(item, &at, keys)?;
            serde_json::from_value(item.clone())
                .map_err(|e| FieldError::new(&at, e.to_string()).into())
        })
        .collect()
}

/// A number at `field` in `[lo, hi]`, or `default` when absent.
fn bounded_number(
    map: &serde_json::Map<String, serde_json::Value>,
    name: &str,
    field: &str,
    default: f64,
    (lo, hi): (f64, f64),
    why: &str,
) -> Result<f64, RunError> {
    match map.get(name) {
        None => Ok(default),
        Some(v) => v.as_f64().filter(|x| *x >= lo && *x <= hi).ok_or_else(|| {
            FieldError::new(field, format!("must be a number in [{lo}, {hi}] ({why})")).into()
        }),
    }
}

impl CalibrateParams {
    /// `{"friction": {"fixture": {...}, "records": [...]}}` and/or `{"wear_law":
    /// {"density_kg_m3": .., "cutoff_pressure_pa": .., "records": [...]}}`; unknown keys at
    /// any level are refused, numbers bounded ([`limits`]), friction records checked as the
    /// fit reads them (eq. 4.1-4.4) and at least 8 of them (the fit's minimum).
    pub fn parse(params: &serde_json::Value) -> Result<Self, RunError> {
        use crate::analysis::calibration as cal;
        let map = check_keys(params, "params", CALIBRATE_KEYS)?;
        if let Some(seed) = map.get("seed") {
            parse_seed(seed)?;
        }
        for key in ["friction", "wear_law"] {
            if let Some(data) = map.get(key) {
                super::bounds::check_calibration_value(data, key)?;
            }
        }
        let friction = match map.get("friction") {
            None => None,
            Some(f) => {
                let f = check_keys(f, "friction", &["fixture", "records"])?;
                let fixture_value = f
                    .get("fixture")
                    .ok_or_else(|| FieldError::new("friction.fixture", "is required"))?;
                check_keys(
                    fixture_value,
                    "friction.fixture",
                    &["polar_inertia_kg_m2", "mean_radius_m"],
                )?;
                let fixture: cal::Fixture = serde_json::from_value(fixture_value.clone())
                    .map_err(|e| FieldError::new("friction.fixture", e.to_string()))?;
                let records: Vec<cal::TorqueRecord> = parse_records(
                    f.get("records"),
                    "friction.records",
                    &[
                        "time_s",
                        "angle_rad",
                        "angular_velocity_rad_s",
                        "normal_load_n",
                        "input_torque_n_m",
                    ],
                )?;
                if records.len() < 8 {
                    return Err(FieldError::new(
                        "friction.records",
                        "need at least 8 records (the friction fit's minimum)",
                    )
                    .into());
                }
                cal::friction_samples(&records, &fixture).map_err(|e| e.at("friction"))?;
                Some(FrictionData { fixture, records })
            }
        };
        let wear_law = match map.get("wear_law") {
            None => None,
            Some(w) => {
                let w = check_keys(
                    w,
                    "wear_law",
                    &["density_kg_m3", "cutoff_pressure_pa", "records"],
                )?;
                let density_kg_m3 = bounded_number(
                    w,
                    "density_kg_m3",
                    "wear_law.density_kg_m3",
                    crate::wear::material::Material::aluminium_7075_t73().density_kg_per_m3,
                    limits::DENSITY_KG_M3_RANGE,
                    "kg/m³, polymers to the densest metals",
                )?;
                let cutoff_pressure_pa = bounded_number(
                    w,
                    "cutoff_pressure_pa",
                    "wear_law.cutoff_pressure_pa",
                    2.0 * crate::wear::material::Material::aluminium_7075_t73().yield_strength_pa,
                    (1.0, limits::MAX_CUTOFF_PRESSURE_PA),
                    "Pa, up to 10 GPa, above any engineering alloy's hardness",
                )?;
                let records = parse_records(
                    w.get("records"),
                    "wear_law.records",
                    &[
                        "normal_load_n",
                        "contact_pressure_pa",
                        "sliding_distance_m",
                        "wear_mass_kg",
                    ],
                )?;
                Some(WearLawData {
                    density_kg_m3,
                    cutoff_pressure_pa,
                    records,
                })
            }
        };
        if friction.is_none() && wear_law.is_none() {
            return Err(FieldError::new(
                "params",
                "give `friction` and/or `wear_law` calibration data",
            )
            .into());
        }
        Ok(Self { friction, wear_law })
    }
}

/// A calibrate job (thesis 4.3-4.4): [`CalibrateParams::parse`], then [`run_calibration`].
pub fn calibrate(params: &serde_json::Value) -> Result<serde_json::Value, RunError> {
    run_calibration(&CalibrateParams::parse(params)?)
}

/// Fits eq. 4.5 to torque records (eq. 4.1-4.4) and/or K(sigma) to wear tests (eq.
/// 4.16-4.18).
pub fn run_calibration(params: &CalibrateParams) -> Result<serde_json::Value, RunError> {
    use crate::analysis::calibration as cal;
    let mut out = serde_json::Map::new();
    if let Some(f) = &params.friction {
        let samples =
            cal::friction_samples(&f.records, &f.fixture).map_err(|e| e.at("friction"))?;
        let fit = cal::fit_friction(&samples, crate::physics::step::StepKind::Cycloidal)
            .map_err(|e| e.at("friction"))?;
        out.insert(
            "friction".into(),
            serde_json::to_value(fit).map_err(|e| FieldError::new("friction", e.to_string()))?,
        );
    }
    if let Some(w) = &params.wear_law {
        let fit = cal::fit_wear_law(&w.records, w.density_kg_m3, w.cutoff_pressure_pa)
            .map_err(|e| e.at("wear_law"))?;
        out.insert(
            "wear_law".into(),
            serde_json::to_value(fit).map_err(|e| FieldError::new("wear_law", e.to_string()))?,
        );
    }
    Ok(serde_json::Value::Object(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eight torque records, the fourth going back in time.
    fn friction_params() -> serde_json::Value {
        let records: Vec<_> = (0..8)
            .map(|i| {
                let t = if i == 3 { 1.0 } else { i as f64 };
                serde_json::json!({"time_s": t, "angle_rad": 0.0, "angular_velocity_rad_s": 1.0,
                    "normal_load_n": 10.0, "input_torque_n_m": 0.5})
            })
            .collect();
        serde_json::json!({"friction": {
            "fixture": {"polar_inertia_kg_m2": 1.0, "mean_radius_m": 0.1},
            "records": records}})
    }

    #[test]
    fn a_record_error_names_the_record_and_its_field() {
        let Err(RunError::InvalidConfig { field, rule }) =
            CalibrateParams::parse(&friction_params())
        else {
            panic!("a record going back in time is refused");
        };
        assert_eq!(field, "friction.records[3].time_s");
        assert_eq!(rule, "must be finite and strictly increasing");
    }
}
