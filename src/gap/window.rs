//! One simulated excitation window of a campaign test, shared by the virtual rig and the
//! diagnosis: the case is built and run once, its contact tracks kept, and the wear of any
//! wear-law terms integrated over them afterwards (never re-simulating).
//!
//! A window stands for a stretch of test time (a segment of an increment); the masses scale
//! by `segment / window` ([`SlipHistory::time_scale`]). Runs are deterministic, so a
//! [`WindowCache`] keyed by the case (its JSON form) and the window options returns the same
//! run for the same inputs: the rig simulates an increment whose case did not change since the
//! previous one only once, and a diagnosis reuses the rig-free simulations of its emulator.

use super::tracks::{SlipHistory, TrackRecord, WearTerm};
use super::GapError;
use crate::models::spec::{CaseSpec, ModelSpecRef};
use crate::physics::control::RunControl;
use crate::units::MG_PER_KG;
use crate::wear::allocation::VolumeSplit;
use crate::wear::law::WearLaw;
use crate::wear::material::Material;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::sync::{Arc, Mutex};

/// How a window is simulated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowOptions {
    /// Simulated excitation, s.
    pub window_s: f64,
    /// Settle before the excitation, s.
    pub settle_s: f64,
    /// Rate of the input and response acceleration records, Hz (None: the run's default).
    pub accelerometer_rate_hz: Option<f64>,
    /// Scales the case's relative and absolute tolerances (1 = as configured; 0.5 = the
    /// tolerance-halving run of the numerical uncertainty).
    pub tolerance_scale: f64,
}

impl Default for WindowOptions {
    fn default() -> Self {
        Self {
            window_s: 2.0,
            settle_s: 0.5,
            accelerometer_rate_hz: None,
            tolerance_scale: 1.0,
        }
    }
}

/// Bodies and materials of one contact, to charge its wear volume.
#[derive(Debug, Clone)]
struct ContactBodies {
    name: String,
    body_a: String,
    body_b: String,
    material_a: Material,
    material_b: Material,
}

/// A simulated window: tracks, accelerations and what is needed to turn wear volume into
/// component masses.
#[derive(Debug, Clone)]
pub struct WindowRun {
    /// Contact tracks at every accepted step of the excitation.
    pub record: TrackRecord,
    /// Excitation simulated, s.
    pub window_s: f64,
    /// Wear law of the case.
    pub law: WearLaw,
    /// Indentation hardness of the softer surface, Pa (for wear-law terms).
    pub hardness_pa: f64,
    /// Yield strength of the contact material, Pa (pressure bands of the diagnosis).
    pub yield_strength_pa: f64,
    /// Input (base) acceleration, m/s², at `accel_rate_hz`.
    pub input: Vec<[f64; 3]>,
    /// Response (free body) acceleration, m/s², at `accel_rate_hz`.
    pub response: Vec<[f64; 3]>,
    /// Rate of `input` and `response`, Hz.
    pub accel_rate_hz: f64,
    split: VolumeSplit,
    contacts: Vec<ContactBodies>,
}

impl WindowRun {
    /// Mass lost per body over the test time the window stands for (`history.time_scale`
    /// windows), mg, with the wear-law `terms` applied in order.
    pub fn masses_mg(
        &self,
        terms: &[&dyn WearTerm],
        history: SlipHistory,
    ) -> Result<BTreeMap<String, f64>, GapError> {
        let volumes = self.record.wear_volumes_m3(&self.law, terms, history)?;
        let mut out = BTreeMap::new();
        for (v, c) in volumes.iter().zip(&self.contacts) {
            let (wa, wb) = self
                .split
                .split(v * history.time_scale, &c.material_a, &c.material_b)
                .map_err(|e| GapError::field("wear", e.to_string()))?;
            *out.entry(c.body_a.clone()).or_insert(0.0) += wa.mass_kg * MG_PER_KG;
            *out.entry(c.body_b.clone()).or_insert(0.0) += wb.mass_kg * MG_PER_KG;
        }
        Ok(out)
    }

    /// Contact names, in model order.
    pub fn contact_names(&self) -> Vec<String> {
        self.contacts.iter().map(|c| c.name.clone()).collect()
    }

    /// Per contact: the mass charged to each of its bodies per m³ worn there, mg/m³ (the
    /// case's volume split and the bodies' densities; linear in the volume).
    pub fn charge_mg_per_m3(&self) -> Result<Vec<BTreeMap<String, f64>>, GapError> {
        const UNIT_M3: f64 = 1e-9;
        self.contacts
            .iter()
            .map(|c| {
                let (wa, wb) = self
                    .split
                    .split(UNIT_M3, &c.material_a, &c.material_b)
                    .map_err(|e| GapError::field("wear", e.to_string()))?;
                let mut out = BTreeMap::new();
                *out.entry(c.body_a.clone()).or_insert(0.0) += wa.mass_kg * MG_PER_KG / UNIT_M3;
                *out.entry(c.body_b.clone()).or_insert(0.0) += wb.mass_kg * MG_PER_KG / UNIT_M3;
                Ok(out)
            })
            .collect()
    }

    /// Slip distance over the window, m (see [`TrackRecord::slip_distance_m`]).
    pub fn slip_distance_m(&self) -> f64 {
        self.record.slip_distance_m()
    }
}

/// Simulates `case` for one window.
pub fn simulate_window(
    case: &CaseSpec,
    configs_dir: &Path,
    options: &WindowOptions,
    what: &str,
    control: &RunControl,
) -> Result<WindowRun, GapError> {
    let sim_err = |m: String| GapError::Simulation {
        what: what.to_string(),
        message: m,
    };
    let mut case = case.clone();
    case.simulation.duration_s = options.window_s;
    case.simulation.settle_s = options.settle_s;
    case.simulation.record_interval_s = options.window_s;
    if options.tolerance_scale != 1.0 {
        case.simulation.rel_tolerance *= options.tolerance_scale;
        case.simulation.abs_tolerance_m *= options.tolerance_scale;
    }
    let model =
        crate::models::case::build(&case, configs_dir).map_err(|e| sim_err(e.to_string()))?;
    let mut run_options =
        crate::models::case::run_options(&case).map_err(|e| sim_err(e.to_string()))?;
    run_options.record_interval_s = -1.0;
    if let Some(rate) = options.accelerometer_rate_hz {
        run_options.response_rate_hz = rate;
    }
    let material = match case.model_spec() {
        Ok(ModelSpecRef::RattleBox(s)) => s.material,
        Ok(ModelSpecRef::Launcher(s)) => s.material,
        _ => Material::default(),
    };
    let mut record = TrackRecord::new(model.system.contacts.len())
        .with_yield_strength(material.yield_strength_pa);
    let mut ws = model.system.workspace();
    let mut scratch = Vec::new();
    tracing::debug!(%what, "simulating a window");
    let report = crate::models::run::run_model_observed(&model, &run_options, control, &mut |v| {
        record.push_view_with_points(v, &mut ws, &mut scratch)
    })
    .map_err(|e| sim_err(e.to_string()))?;
    let contacts = model
        .system
        .contacts
        .iter()
        .zip(&model.contact_materials)
        .map(|(c, (ma, mb))| ContactBodies {
            name: c.name.clone(),
            body_a: model.system.bodies[c.body_a].name.clone(),
            body_b: model.system.bodies[c.body_b].name.clone(),
            material_a: *ma,
            material_b: *mb,
        })
        .collect();
    Ok(WindowRun {
        record,
        window_s: model.end_time_s - model.excitation_start_s,
        law: case.wear.law,
        hardness_pa: material.hardness_pa(),
        yield_strength_pa: material.yield_strength_pa,
        input: report.base_acceleration,
        response: report.response_acceleration,
        accel_rate_hz: report.response_rate_hz,
        split: case.wear.volume_split,
        contacts,
    })
}

/// Deterministic runs remembered by case and options; safe to share between threads.
#[derive(Default)]
pub struct WindowCache {
    runs: Mutex<HashMap<String, Arc<WindowRun>>>,
}

impl WindowCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of distinct runs held.
    pub fn len(&self) -> usize {
        self.runs.lock().map_or(0, |m| m.len())
    }

    /// True when nothing is held.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The run of `case` with `options`: remembered, or simulated and remembered.
    pub fn get_or_run(
        &self,
        case: &CaseSpec,
        configs_dir: &Path,
        options: &WindowOptions,
        what: &str,
        control: &RunControl,
    ) -> Result<Arc<WindowRun>, GapError> {
        let key = format!(
            "{}|{:?}",
            serde_json::to_string(case).map_err(|e| GapError::field("case", e.to_string()))?,
            options
        );
        if let Some(run) = self.runs.lock().ok().and_then(|m| m.get(&key).cloned()) {
            return Ok(run);
        }
        let run = Arc::new(simulate_window(case, configs_dir, options, what, control)?);
        if let Ok(mut m) = self.runs.lock() {
            m.insert(key, run.clone());
        }
        Ok(run)
    }
}
