//! The emulator built for a campaign: the nominal (and its tolerance-halving, friction-step and
//! initial-state runs) and every applicable effect's table; and the key a saved one is
//! reused under.

use super::grids::{applicable, dynamics_grid, effect_at, wear_grid};
use super::slots::{plan, predictions_of, simulate_slots, Slot};
use super::{
    band_of, Bands, EffectTable, Emulator, EmulatorOptions, FRICTION_STEP, PRESSURE_BANDS,
    SETTLE_SHIFT_S, SLIP_BANDS,
};
use crate::cases::RunControl;
use crate::gap::diagnose::budget::IncrementWork;
use crate::gap::effects::Acts;
use crate::gap::rig::ModelIncrement;
use crate::gap::tracks::WearTerm;
use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use std::collections::BTreeMap;
use std::path::Path;

impl Emulator {
    /// Simulates and tabulates. `progress(done, total)` is called after every test simulated.
    pub fn build(
        campaign: &Campaign,
        configs_dir: &Path,
        options: &EmulatorOptions,
        control: &RunControl,
        cache: &WindowCache,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Self, GapError> {
        let (cases, increments) = plan(campaign, configs_dir)?;
        let infos = applicable(&cases, options.effects.as_deref())?;
        // Slots: 0 nominal, 1 halving, 2 friction step, 3 initial state, then (dynamics
        // effect, magnitude).
        let mut slots: Vec<Slot> = vec![
            (vec![], 1.0, 0.0, 0.0),
            (vec![], 0.5, 0.0, 0.0),
            (vec![], 1.0, FRICTION_STEP, 0.0),
            (vec![], 1.0, 0.0, SETTLE_SHIFT_S),
        ];
        let mut dyn_slots: Vec<(usize, Vec<usize>)> = Vec::new();
        for (ei, info) in infos.iter().enumerate() {
            if info.acts != Acts::Dynamics {
                continue;
            }
            let mut ids = Vec::new();
            for m in dynamics_grid(info, options.grid_points) {
                if m == 0.0 {
                    ids.push(0);
                } else {
                    ids.push(slots.len());
                    slots.push((vec![effect_at(info, m)], 1.0, 0.0, 0.0));
                }
            }
            dyn_slots.push((ei, ids));
        }
        let before = cache.len();
        let total = slots.len() * campaign.tests.len();
        let by_slot = simulate_slots(
            &slots,
            campaign,
            (&cases, &increments),
            configs_dir,
            options,
            control,
            cache,
            progress,
            (0, total),
        )?;
        let ntests = campaign.tests.len();
        let preds = |slot: &Vec<Vec<ModelIncrement>>| predictions_of(slot);
        let nominal = preds(&by_slot[0]);
        let mut effects = Vec::new();
        let mut dyn_iter = dyn_slots.iter();
        for info in &infos {
            match info.acts {
                Acts::Dynamics => {
                    let Some((_, ids)) = dyn_iter.next() else {
                        continue;
                    };
                    effects.push(EffectTable {
                        info,
                        magnitudes: dynamics_grid(info, options.grid_points),
                        predictions: ids.iter().map(|&s| preds(&by_slot[s])).collect(),
                        simulated: true,
                        parameters: BTreeMap::new(),
                    });
                }
                Acts::WearLaw => {
                    let magnitudes = wear_grid(info);
                    let mut predictions = Vec::with_capacity(magnitudes.len());
                    for &m in &magnitudes {
                        let e = effect_at(info, m);
                        let mut table = nominal.clone();
                        for (ti, t) in by_slot[0].iter().enumerate() {
                            for (k, inc) in t.iter().enumerate() {
                                let mut mass: BTreeMap<String, f64> = BTreeMap::new();
                                for (run, history) in &inc.segments {
                                    let term = e.wear_term(run.hardness_pa)?;
                                    let terms: Vec<&dyn WearTerm> =
                                        term.as_deref().filter(|_| m != 0.0).into_iter().collect();
                                    for (b, v) in run.masses_mg(&terms, *history)? {
                                        *mass.entry(b).or_insert(0.0) += v;
                                    }
                                }
                                table[ti][k].mass_mg = mass;
                            }
                        }
                        predictions.push(table);
                    }
                    effects.push(EffectTable {
                        info,
                        magnitudes,
                        predictions,
                        simulated: false,
                        parameters: BTreeMap::new(),
                    });
                }
            }
        }
        let bands = by_slot[0]
            .iter()
            .map(|t| {
                t.iter()
                    .map(|inc| -> Result<Bands, GapError> {
                        let mut b = Bands {
                            pressure: vec![0.0; PRESSURE_BANDS.len()],
                            slip: vec![0.0; SLIP_BANDS.len()],
                            work: IncrementWork::of(&inc.segments)?,
                        };
                        for (run, h) in &inc.segments {
                            let sy = run.yield_strength_pa;
                            let edges = [0.1 * sy, sy, 2.0 * sy];
                            let p = run.record.work_by_bin(4, |p, _| Some(band_of(p, &edges)));
                            let s = run
                                .record
                                .work_by_bin(4, |_, v| Some(band_of(v, &[1e-3, 6.5e-3, 0.1])));
                            for i in 0..4 {
                                b.pressure[i] += p[i] * h.time_scale;
                                b.slip[i] += s[i] * h.time_scale;
                            }
                        }
                        Ok(b)
                    })
                    .collect::<Result<Vec<_>, _>>()
            })
            .collect::<Result<Vec<_>, _>>()?;
        let records = |slot: &Vec<Vec<ModelIncrement>>| -> Vec<(f64, Vec<[f64; 3]>)> {
            slot.iter()
                .map(|t| {
                    let rate = options.accelerometer_rate_hz;
                    (
                        rate,
                        t.first()
                            .map(|inc| inc.response.clone())
                            .unwrap_or_default(),
                    )
                })
                .collect()
        };
        let response_records = records(&by_slot[0]);
        let halving_response_records = records(&by_slot[1]);
        debug_assert_eq!(nominal.len(), ntests);
        Ok(Self {
            halving: preds(&by_slot[1]),
            friction_step: preds(&by_slot[2]),
            initial_state: preds(&by_slot[3]),
            nominal,
            bands,
            response_records,
            halving_response_records,
            effects,
            pairs: Vec::new(),
            joints: Vec::new(),
            measured: Vec::new(),
            simulations: cache.len() - before,
            options: options.clone(),
        })
    }
}

impl Emulator {
    /// A key of what the emulator depends on: the tests' configurations (never their
    /// measurements), the options and the code version. Saved emulators are reused only
    /// under the same key.
    pub fn key(campaign: &Campaign, options: &EmulatorOptions) -> String {
        use sha2::{Digest, Sha256};
        let tests: Vec<serde_json::Value> = campaign
            .tests
            .iter()
            .map(|t| {
                serde_json::json!({
                    "config": t.config, "overrides": t.overrides, "rattle_space": t.rattle_space,
                    "drive": t.drive, "increment_duration_s": t.increment_duration_s,
                    "increments": t.specimens.iter().map(|s| s.increments.len()).max(),
                })
            })
            .collect();
        let text = serde_json::json!({
            "tests": tests,
            "options": options,
            "code": crate::models::case::code_version(),
        })
        .to_string();
        format!("{:x}", Sha256::digest(text.as_bytes()))
    }
}
