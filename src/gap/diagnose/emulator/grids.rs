//! Which library effects apply to a campaign's cases and the magnitudes each is tabulated
//! at: a fine table for a wear law (exact, no simulation), a grid halving the bound for a
//! dynamics effect; and an effect at a magnitude with its secondary values.

use crate::gap::effects::{Effect, EffectInfo, LIBRARY};
use crate::gap::GapError;
use crate::models::spec::CaseSpec;
use std::collections::BTreeMap;

/// The effects of the library that apply to every test of `cases`, filtered by `only`.
pub fn applicable(
    cases: &[CaseSpec],
    only: Option<&[String]>,
) -> Result<Vec<&'static EffectInfo>, GapError> {
    if let Some(names) = only {
        for n in names {
            if !LIBRARY.iter().any(|e| e.name == n) {
                let known: Vec<&str> = LIBRARY.iter().map(|e| e.name).collect();
                return Err(GapError::field(
                    "effects",
                    format!("unknown effect `{n}` (known: {})", known.join(", ")),
                ));
            }
        }
    }
    Ok(LIBRARY
        .iter()
        .filter(|e| cases.iter().all(|c| e.models.contains(&c.model)))
        .filter(|e| only.is_none_or(|o| o.iter().any(|n| n == e.name)))
        .collect())
}

/// Magnitudes a dynamics effect is simulated at.
pub fn dynamics_grid(info: &EffectInfo, points: usize) -> Vec<f64> {
    let p = &info.parameters[0];
    let mut g = vec![0.0];
    if p.min < 0.0 {
        g.push(p.min);
        g.push(0.5 * p.min);
    }
    let mut v = p.max;
    for _ in 0..points.max(1) {
        g.push(v);
        v *= 0.5;
    }
    g.sort_by(f64::total_cmp);
    g.dedup();
    g
}

/// Magnitudes a wear-law effect is evaluated at: 0 and a log-spaced table from 1e-4 of the
/// bound to the bound (8 per decade).
pub fn wear_grid(info: &EffectInfo) -> Vec<f64> {
    let max = info.parameters[0].max;
    let mut g = vec![0.0];
    for k in 0..=32 {
        g.push(max * 10f64.powf(-4.0 + k as f64 / 8.0));
    }
    g
}

pub(super) fn effect_at(info: &EffectInfo, magnitude: f64) -> Effect {
    effect_with(info, magnitude, &BTreeMap::new())
}

/// The effect at `magnitude` with its other parameters from `secondary` (library defaults for
/// those not listed).
pub fn effect_with(info: &EffectInfo, magnitude: f64, secondary: &BTreeMap<String, f64>) -> Effect {
    let mut parameters: BTreeMap<String, f64> = info
        .parameters
        .iter()
        .map(|p| {
            let v = secondary.get(p.name).copied().unwrap_or(p.default);
            (p.name.to_string(), v)
        })
        .collect();
    parameters.insert(info.parameters[0].name.to_string(), magnitude);
    Effect {
        name: info.name.to_string(),
        parameters,
    }
}
