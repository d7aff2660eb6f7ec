//! Calibrate jobs: friction and wear-law data sets, parsed and checked, and the fits.

use super::{check_keys, limits, parse_seed, RunError, CALIBRATE_KEYS};
use crate::analysis::calibration::{Fixture, TorqueRecord, WearTestRecord};
use crate::field_error::FieldError;
use crate::parameters::{Bound, Bounded, FieldPath};
use serde::{Deserialize, Serialize};

/// Friction data of a calibrate job (thesis 4.3): the fixture and its torque records.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionData {
    pub fixture: Fixture,
    pub records: Vec<TorqueRecord>,
}

/// Wear-law data of a calibrate job (thesis 4.4): material density, cutoff and wear tests.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WearLawData {
    /// kg/m³ (default 2810, 7075-T73), within [`limits::DENSITY_KG_M3_RANGE`].
    pub density_kg_m3: f64,
    /// Pa (default 870e6, 2 S_y of 7075-T73), in (0, [`limits::MAX_CUTOFF_PRESSURE_PA`]].
    pub cutoff_pressure_pa: f64,
    pub records: Vec<WearTestRecord>,
}

const POLAR_INERTIA: Bound = Bound::new(
    1.0e-9,
    1.0e3,
    "kg·m²",
    "a fixture's rotating parts, from a 1 g cup to a 1 t turntable",
);
const MEAN_RADIUS: Bound = Bound::new(1.0e-5, 10.0, "m", "contact radii from 10 µm to 10 m");
const TIME: Bound = Bound::new(
    0.0,
    limits::MAX_DURATION_S,
    "s",
    "a test record within 24 h",
);
const ANGLE: Bound = Bound::new(-1.0e7, 1.0e7, "rad", "1.6 million turns: a day at 20 rev/s");
const ANGULAR_VELOCITY: Bound = Bound::new(
    -1.0e4,
    1.0e4,
    "rad/s",
    "up to 95 000 rpm, past any friction rig's spindle",
);
const NORMAL_LOAD: Bound = Bound::new(
    0.0,
    1.0e6,
    "N",
    "a compressive load up to 1 MN, a large press",
);
const INPUT_TORQUE: Bound = Bound::new(
    -1.0e5,
    1.0e5,
    "N·m",
    "torques up to 100 kN·m, past any friction rig's drive",
);
const CONTACT_PRESSURE: Bound = Bound::new(
    0.0,
    limits::MAX_CUTOFF_PRESSURE_PA,
    "Pa",
    "compressive pressures up to 10 GPa, above any engineering alloy's hardness",
);
const SLIDING_DISTANCE: Bound = Bound::new(0.0, 1.0e7, "m", "up to 10 000 km of sliding");
const WEAR_MASS: Bound = Bound::new(0.0, 1.0, "kg", "wear of a test specimen, up to 1 kg");

/// The rotating-cup fixture of the friction test (thesis 4.3).
impl Bounded for Fixture {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number(
            "polar_inertia_kg_m2",
            self.polar_inertia_kg_m2,
            &POLAR_INERTIA,
        )?;
        at.number("mean_radius_m", self.mean_radius_m, &MEAN_RADIUS)
    }
}

/// One torque record of the friction test.
impl Bounded for TorqueRecord {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number("time_s", self.time_s, &TIME)?;
        at.number("angle_rad", self.angle_rad, &ANGLE)?;
        at.number(
            "angular_velocity_rad_s",
            self.angular_velocity_rad_s,
            &ANGULAR_VELOCITY,
        )?;
        at.number("normal_load_n", self.normal_load_n, &NORMAL_LOAD)?;
        at.number("input_torque_n_m", self.input_torque_n_m, &INPUT_TORQUE)
    }
}

/// One wear test's record (thesis 4.4).
impl Bounded for WearTestRecord {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number("normal_load_n", self.normal_load_n, &NORMAL_LOAD)?;
        at.number(
            "contact_pressure_pa",
            self.contact_pressure_pa,
            &CONTACT_PRESSURE,
        )?;
        at.number(
            "sliding_distance_m",
            self.sliding_distance_m,
            &SLIDING_DISTANCE,
        )?;
        at.number("wear_mass_kg", self.wear_mass_kg, &WEAR_MASS)
    }
}

/// Each record inside its bounds, named `field[i].<name>`.
fn check_records<T: Bounded>(records: &[T], field: &str) -> Result<(), FieldError> {
    let mut at = FieldPath::new(field);
    records
        .iter()
        .enumerate()
        .try_for_each(|(i, record)| at.item(i, |at| record.check_bounds(at)))
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
        Self::parse_seeded(params, None)
    }

    /// [`CalibrateParams::parse`] for a job whose seed the caller has parsed already
    /// (`job_seed`: the params' own `seed`, or the one drawn for a job that names none), so
    /// the params' `seed` is not read again (a calibration draws nothing from it). Without
    /// one, the params' `seed` is checked here.
    pub fn parse_seeded(
        params: &serde_json::Value,
        job_seed: Option<u64>,
    ) -> Result<Self, RunError> {
        use crate::analysis::calibration as cal;
        let map = check_keys(params, "params", CALIBRATE_KEYS)?;
        if let (None, Some(seed)) = (job_seed, map.get("seed")) {
            parse_seed(seed)?;
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
                fixture.check_bounds(&mut FieldPath::new("friction.fixture"))?;
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
                check_records(&records, "friction.records")?;
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
                let records: Vec<WearTestRecord> = parse_records(
                    w.get("records"),
                    "wear_law.records",
                    &[
                        "normal_load_n",
                        "contact_pressure_pa",
                        "sliding_distance_m",
                        "wear_mass_kg",
                    ],
                )?;
                check_records(&records, "wear_law.records")?;
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
