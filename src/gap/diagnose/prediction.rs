//! The model's prediction of one increment of one test (masses, input and response mean
//! squares), the unit the emulator tabulates and the diagnosis compares with a measurement.

use crate::gap::rig::ModelIncrement;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The model's prediction of one increment of one test.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Prediction {
    /// Mass lost per body, mg.
    pub mass_mg: BTreeMap<String, f64>,
    /// Mean-square input acceleration per axis, m²/s⁴.
    pub input_ms: [f64; 3],
    /// Mean-square response acceleration per axis, m²/s⁴.
    pub response_ms: [f64; 3],
}

impl Prediction {
    pub(super) fn from_increment(m: &ModelIncrement) -> Self {
        Self {
            mass_mg: m.mass_mg.clone(),
            input_ms: mean_square(&m.input),
            response_ms: mean_square(&m.response),
        }
    }

    /// Every quantity in a fixed order: masses by body name, input, response.
    pub fn flat(&self) -> Vec<f64> {
        self.mass_mg
            .values()
            .copied()
            .chain(self.input_ms)
            .chain(self.response_ms)
            .collect()
    }

    /// Labels of [`Prediction::flat`]'s quantities (`mass cube`, `input x`, `response z`).
    pub fn labels(&self) -> Vec<String> {
        self.mass_mg
            .keys()
            .map(|k| format!("mass {k}"))
            .chain(["x", "y", "z"].iter().map(|a| format!("input {a}")))
            .chain(["x", "y", "z"].iter().map(|a| format!("response {a}")))
            .collect()
    }

    /// The same structure with the quantities of [`Prediction::flat`] replaced by `v`.
    pub fn with_flat(&self, v: &[f64]) -> Self {
        let mut out = self.clone();
        let nm = out.mass_mg.len();
        for (slot, x) in out.mass_mg.values_mut().zip(v) {
            *slot = *x;
        }
        for i in 0..3 {
            out.input_ms[i] = v.get(nm + i).copied().unwrap_or(f64::NAN);
            out.response_ms[i] = v.get(nm + 3 + i).copied().unwrap_or(f64::NAN);
        }
        out
    }

    /// Applies `f(self, other)` to every quantity.
    pub(super) fn zip(&self, other: &Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let mut out = self.clone();
        for (k, v) in out.mass_mg.iter_mut() {
            *v = f(*v, other.mass_mg.get(k).copied().unwrap_or(0.0));
        }
        for i in 0..3 {
            out.input_ms[i] = f(self.input_ms[i], other.input_ms[i]);
            out.response_ms[i] = f(self.response_ms[i], other.response_ms[i]);
        }
        out
    }
}

/// Mean square per axis of an acceleration record, m²/s⁴ (mean removed).
pub fn mean_square(a: &[[f64; 3]]) -> [f64; 3] {
    let mut out = [0.0; 3];
    if a.is_empty() {
        return out;
    }
    let n = a.len() as f64;
    for (axis, o) in out.iter_mut().enumerate() {
        let mean = a.iter().map(|s| s[axis]).sum::<f64>() / n;
        *o = a.iter().map(|s| (s[axis] - mean).powi(2)).sum::<f64>() / n;
    }
    out
}

/// Predictions `[test][increment]`.
pub type TestPredictions = Vec<Vec<Prediction>>;
