//! Two dynamics effects together (`Emulator::predict` with joint points): checked against a
//! closed form on hand-made tables.

use super::emulator::{Emulator, EmulatorOptions, JointPoint};
use super::prediction::{Prediction, TestPredictions};
use super::table::EffectTable;
use crate::gap::effects::{info, EffectInfo};
use std::collections::BTreeMap;

fn one(mass: f64, response: f64) -> TestPredictions {
    vec![vec![Prediction {
        mass_mg: BTreeMap::from([("cube".to_string(), mass)]),
        input_ms: [1.0, 0.0, 0.0],
        response_ms: [response, 0.0, 0.0],
    }]]
}

fn table(info: &'static EffectInfo, magnitudes: &[f64], f: impl Fn(f64) -> f64) -> EffectTable {
    EffectTable {
        info,
        magnitudes: magnitudes.to_vec(),
        predictions: magnitudes.iter().map(|&m| one(f(m), 2.0 * f(m))).collect(),
        simulated: true,
        parameters: BTreeMap::new(),
    }
}

/// Friction drift (bound 0.6, -0.1 below 0) and a cross-axis share (bound 0.3), each a known
/// function of its magnitude, and joint points whose interaction is `exp(c u v)` with `u`,
/// `v` the magnitudes over their bounds.
fn emulator(c: f64, joints: &[(f64, f64)]) -> Emulator {
    let (fd, ca) = (
        info("friction_drift").expect("in the library"),
        info("cross_axis").expect("in the library"),
    );
    let a = table(fd, &[-0.1, 0.0, 0.15, 0.3, 0.6], |m| 1.0 + 2.0 * m);
    let b = table(ca, &[0.0, 0.075, 0.15, 0.3], |m| 1.0 + 5.0 * m);
    let mut e = Emulator {
        nominal: one(1.0, 2.0),
        halving: one(1.0, 2.0),
        friction_step: one(1.0, 2.0),
        initial_state: one(1.0, 2.0),
        bands: Vec::new(),
        response_records: Vec::new(),
        halving_response_records: Vec::new(),
        effects: vec![a, b],
        pairs: Vec::new(),
        joints: Vec::new(),
        measured: Vec::new(),
        simulations: 0,
        options: EmulatorOptions::default(),
    };
    for &(x, y) in joints {
        let product = product(&e, x, y);
        let (u, v) = (x / if x < 0.0 { 0.1 } else { 0.6 }, y / 0.3);
        let k = (c * u * v).exp();
        e.joints.push(JointPoint {
            tables: [0, 1],
            magnitudes: [x, y],
            predictions: one(product.0 * k, product.1 * k),
            initial_state: None,
        });
    }
    e
}

/// The product of the two effects' ratios to the nominal (mass, response), from each alone.
fn product(e: &Emulator, x: f64, y: f64) -> (f64, f64) {
    let (a, b) = (&e.predict(&[(0, x)])[0][0], &e.predict(&[(1, y)])[0][0]);
    (
        a.mass_mg["cube"] * b.mass_mg["cube"],
        a.response_ms[0] * b.response_ms[0] / 2.0,
    )
}

fn mass(e: &Emulator, x: f64, y: f64) -> f64 {
    e.predict(&[(0, x), (1, y)])[0][0].mass_mg["cube"]
}

#[test]
fn joint_points_are_exact_and_an_interaction_of_the_modelled_form_is_reproduced_everywhere() {
    let c = 0.4;
    let e = emulator(c, &[(0.3, 0.15), (0.6, 0.075), (-0.1, 0.3)]);
    for x in [-0.1, -0.05, 0.05, 0.2, 0.3, 0.45, 0.6] {
        for y in [0.02, 0.075, 0.1, 0.15, 0.3] {
            let (u, v) = (x / if x < 0.0 { 0.1 } else { 0.6 }, y / 0.3);
            let want = product(&e, x, y).0 * (c * u * v).exp();
            let got = mass(&e, x, y);
            assert!((got / want - 1.0).abs() < 1e-12, "{x} {y}: {got} vs {want}");
        }
    }
    // A member off: the other alone, exactly.
    assert_eq!(
        mass(&e, 0.3, 0.0),
        e.predict(&[(0, 0.3)])[0][0].mass_mg["cube"]
    );
}

#[test]
fn between_joint_points_the_interaction_is_continuous_and_exact_at_each() {
    // An interaction that is not of the modelled form: each joint point its own factor.
    let mut e = emulator(0.0, &[(0.15, 0.075), (0.6, 0.3)]);
    let lifted = 1.3 * product(&e, 0.15, 0.075).0;
    e.joints[0].predictions[0][0]
        .mass_mg
        .insert("cube".into(), lifted);
    for j in &e.joints {
        let (x, y) = (j.magnitudes[0], j.magnitudes[1]);
        assert_eq!(mass(&e, x, y), j.predictions[0][0].mass_mg["cube"]);
    }
    // Approaching a joint point, the prediction tends to the point's value.
    let at = mass(&e, 0.15, 0.075);
    let near = mass(&e, 0.15 + 1e-7, 0.075 - 1e-7);
    assert!((near / at - 1.0).abs() < 1e-5, "{near} vs {at}");
    // Along a line between the two points, no step larger than the line's step allows.
    let mut last = mass(&e, 0.15, 0.075);
    for i in 1..=200 {
        let t = f64::from(i) / 200.0;
        let m = mass(&e, 0.15 + t * 0.45, 0.075 + t * 0.225);
        assert!((m / last - 1.0).abs() < 0.02, "step at {t}: {last} -> {m}");
        last = m;
    }
}
