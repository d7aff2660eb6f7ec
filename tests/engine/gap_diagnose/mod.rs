//! Gap diagnosis (issue 15), the method on a model with a known answer: a hand-built
//! emulator whose effects change the predictions in known, different patterns (uniform per
//! test, growing over increments, lifting the off-axis response), measurements drawn from one
//! of them with known scatter. The diagnosis must report no_gap for the control, name the true
//! effect with an interval that holds the true magnitude, and refuse (not_explained) a pattern
//! no effect can make. Secondary parameters (a cross-axis phase) are fitted over variant tables
//! and reported with an interval; an effect fitted at its bound is `partly_explained`; a pair
//! never scores worse held out than its better member. The simulator path is in
//! `gap_diagnose_simulated.rs`.
//!
//! This file holds the hand-built emulator and campaign; `verdicts` the verdicts on single
//! effects, calibration and pooling; `secondary` secondary parameters, identification, bounds
//! and pairs.

mod records;
mod secondary;
mod verdicts;

use railwear::gap::accel::AccelLocation;
use railwear::gap::campaign::{Campaign, Increment, Specimen};
use railwear::gap::diagnose::emulator::{
    Bands, EffectTable, Emulator, EmulatorOptions, JointPoint, Prediction, TestPredictions,
};
use railwear::gap::diagnose::measured::MeasuredValue;
use railwear::gap::diagnose::{diagnose_with, DiagnoseOptions, Verdict};
use railwear::gap::effects;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha20Rng;
use std::collections::BTreeMap;

const TESTS: usize = 5;
const INCREMENTS: usize = 3;
/// Nominal mass per increment of each test, mg.
const NOMINAL_MG: [f64; TESTS] = [1.0, 0.6, 0.35, 0.2, 0.1];
/// How strongly third-body abrasion acts on each test (its work at pressure and slip).
const ABRASION_SHARE: [f64; TESTS] = [1.0, 0.9, 0.6, 0.3, 0.1];
/// How strongly cross-axis drive acts on each test's wear.
const CROSS_SHARE: [f64; TESTS] = [0.1, 0.3, 0.6, 1.0, 1.5];
const DRIVE_MS: f64 = 1.0e4;

/// The truth of the hand-built model: prediction of test `t`, increment `k` with relative
/// magnitudes (share of each effect's bound) of third-body, clearance growth and cross-axis.
fn truth(t: usize, k: usize, third: f64, growth: f64, cross: f64) -> Prediction {
    let m = NOMINAL_MG[t]
        * (1.0 + 3.0 * third * ABRASION_SHARE[t])
        * (1.0 + 2.0 * growth * (k as f64 + 0.5) / INCREMENTS as f64)
        * (1.0 + 1.5 * cross * CROSS_SHARE[t]);
    Prediction {
        mass_mg: BTreeMap::from([("cube".to_string(), m)]),
        input_ms: [DRIVE_MS, DRIVE_MS * cross * cross, DRIVE_MS * cross * cross],
        response_ms: [
            0.5 * DRIVE_MS,
            0.01 * DRIVE_MS + 0.4 * DRIVE_MS * cross * cross,
            0.01 * DRIVE_MS + 0.4 * DRIVE_MS * cross * cross,
        ],
    }
}

fn table(name: &str, which: usize, points: usize) -> EffectTable {
    let info = effects::info(name).unwrap();
    let max = info.parameters[0].max;
    let magnitudes: Vec<f64> = (0..points)
        .map(|i| max * i as f64 / (points - 1) as f64)
        .collect();
    let predictions = magnitudes
        .iter()
        .map(|m| {
            let f = m / max;
            let mut r = [0.0; 3];
            r[which] = f;
            (0..TESTS)
                .map(|t| {
                    (0..INCREMENTS)
                        .map(|k| truth(t, k, r[0], r[1], r[2]))
                        .collect()
                })
                .collect()
        })
        .collect();
    EffectTable {
        info,
        magnitudes,
        predictions,
        simulated: which != 0,
        parameters: BTreeMap::new(),
    }
}

fn emulator() -> Emulator {
    let nominal: TestPredictions = (0..TESTS)
        .map(|t| {
            (0..INCREMENTS)
                .map(|k| truth(t, k, 0.0, 0.0, 0.0))
                .collect()
        })
        .collect();
    Emulator {
        halving: nominal.clone(),
        friction_step: nominal.clone(),
        initial_state: nominal.clone(),
        bands: vec![
            vec![
                Bands {
                    pressure: vec![1.0, 0.0, 0.0, 0.0],
                    slip: vec![0.0, 0.0, 1.0, 0.0],
                    work: Default::default(),
                };
                INCREMENTS
            ];
            TESTS
        ],
        response_records: vec![(1000.0, Vec::new()); TESTS],
        halving_response_records: vec![(1000.0, Vec::new()); TESTS],
        nominal,
        effects: vec![
            table("third_body", 0, 41),
            table("clearance_growth", 1, 41),
            table("cross_axis", 2, 41),
        ],
        pairs: Vec::new(),
        joints: Vec::new(),
        measured: Vec::new(),
        simulations: 0,
        options: EmulatorOptions::default(),
    }
}

/// A campaign whose three specimens per test read `f(t, k)` with 5 % scatter and a
/// 1 µg scale; accelerometer mean squares carried as a 1 s record at 1 kHz whose samples
/// have exactly that mean square (a square wave of the right amplitude).
fn campaign(f: impl Fn(usize, usize) -> Prediction, seed: u64) -> Campaign {
    let mut rng = ChaCha20Rng::seed_from_u64(seed);
    let mut normal = move || {
        let u1: f64 = 1.0 - rng.gen::<f64>();
        let u2: f64 = rng.gen::<f64>();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let mut tests = Vec::new();
    for t in 0..TESTS {
        let mut specimens = Vec::new();
        for s in 0..3 {
            let mut increments = Vec::new();
            let mut accelerometers = Vec::new();
            for k in 0..INCREMENTS {
                let p = f(t, k);
                let m = p.mass_mg["cube"] * (1.0 + 0.05 * normal());
                increments.push(Increment {
                    mass_loss_mg: BTreeMap::from([("cube".into(), (m * 1000.0).round() / 1000.0)]),
                });
                for (location, ms) in [("input", p.input_ms), ("response", p.response_ms)] {
                    let samples: Vec<[f64; 4]> = (0..1000)
                        .map(|i| {
                            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                            [
                                i as f64 / 1000.0,
                                sign * ms[0].sqrt(),
                                sign * ms[1].sqrt(),
                                sign * ms[2].sqrt(),
                            ]
                        })
                        .collect();
                    accelerometers.push(
                        serde_json::from_value(serde_json::json!({
                            "increment": k + 1,
                            "location": location,
                            "sample_rate_hz": 1000.0,
                            "sensor_noise_m_s2": 0.0,
                            "samples": samples,
                        }))
                        .unwrap(),
                    );
                }
            }
            specimens.push(Specimen {
                id: format!("T{t}-{s}"),
                increments,
                accelerometers,
            });
        }
        tests.push(
            serde_json::from_value(serde_json::json!({
                "id": format!("T{t}"),
                "config": "rattle-box-c",
                "increment_duration_s": 5400.0,
                "scale_resolution_mg": 0.001,
                "components": ["cube"],
                "specimens": specimens,
            }))
            .unwrap(),
        );
    }
    Campaign {
        format_version: 1,
        name: format!("synthetic-{seed}"),
        description: String::new(),
        source: None,
        tests,
    }
}

fn options() -> DiagnoseOptions {
    DiagnoseOptions {
        k_rel_uncertainty: 0.0,
        bootstrap_rounds: 200,
        ..DiagnoseOptions::default()
    }
}
