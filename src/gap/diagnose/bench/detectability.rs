//! How detectable an effect is in a campaign (module `bench`, "Detectable", "Pairs",
//! "Carried by one test"): its noise-free readings against the control's, a pair's member
//! against the other member at the values that stand in for it best, and the tests that carry it.

use crate::gap::diagnose::noise::{gaussian, NoiseModel, Observation, Term};
use crate::gap::diagnose::secondary_values::profile_values;
use crate::gap::effects::Effect;
use crate::gap::GapError;
use std::collections::BTreeMap;

/// Noise-free readings' distance from the control's, in units of the uncertainty the noisy
/// campaign's data carry (its noise model, estimated from its repeats, with each channel's
/// shared calibration scale), RMS: `sqrt(Mahalanobis² / n)`.
pub(super) fn detectability(
    effect: &[Observation],
    control: &[Observation],
    noise: &NoiseModel,
    noisy: &[Observation],
) -> f64 {
    detectability_in(effect, control, noise, noisy, |_| true)
}

/// Fractions of a magnitude's bound the search for the closest stand-in starts from.
const STAND_IN_FRACTIONS: [f64; 8] = [0.01, 0.03, 0.07, 0.15, 0.3, 0.5, 0.75, 1.0];

/// Values of each secondary parameter the search for the closest stand-in tries (the
/// profile's spacing, bounds included).
const STAND_IN_SECONDARY_VALUES: usize = 5;

/// Readings of the effect alone at a magnitude and secondary values.
type AloneAt<'a> = dyn Fn(f64, &BTreeMap<String, f64>) -> Result<Vec<Observation>, GapError> + 'a;

/// The closest stand-in found so far: magnitude, secondary values, readings, score.
type StandIn = (f64, BTreeMap<String, f64>, Vec<Observation>, f64);

/// Scores the effect alone at a magnitude and secondary values, keeping the closest.
type TryAt<'a> = dyn Fn(f64, &BTreeMap<String, f64>, &mut StandIn) -> Result<f64, GapError> + 'a;

/// The effect `other` alone at the magnitude and secondary values whose noise-free readings
/// come closest to a pair's (`score`, smaller is closer). Coordinate search from the drawn
/// values (`at_drawn`, their readings and score): the magnitude over [`STAND_IN_FRACTIONS`]
/// of its bound on the drawn magnitude's side and three golden-section steps between the best
/// one's neighbours; then, while the stand-in is still told apart (score > 2), each secondary
/// parameter over [`STAND_IN_SECONDARY_VALUES`] values within its bounds, each with the
/// magnitude over the same fractions, and the golden-section steps at the value that came
/// closest. Returns the closest readings and their score.
pub(super) fn closest_alone(
    other: &Effect,
    alone_at: &AloneAt,
    score: &dyn Fn(&[Observation]) -> f64,
    at_drawn: (Vec<Observation>, f64),
) -> Result<(Vec<Observation>, f64), GapError> {
    let info = other.info()?;
    let drawn = other.magnitude();
    let bound = if drawn < 0.0 {
        info.parameters[0].min
    } else {
        info.parameters[0].max
    };
    let secondary: BTreeMap<String, f64> = other
        .parameters
        .iter()
        .filter(|(k, _)| k.as_str() != info.parameters[0].name)
        .map(|(k, v)| (k.clone(), *v))
        .collect();
    let mut best: StandIn = (drawn, secondary, at_drawn.0, at_drawn.1);
    let mut tried: Vec<(f64, f64)> = vec![(drawn, best.3)];
    let try_at =
        |m: f64, sec: &BTreeMap<String, f64>, best: &mut StandIn| -> Result<f64, GapError> {
            let obs = alone_at(m, sec)?;
            let d = score(&obs);
            if d < best.3 {
                *best = (m, sec.clone(), obs, d);
            }
            Ok(d)
        };
    // The magnitude over the fractions of its bound at secondary values `sec`: (magnitude,
    // score) each.
    let sweep =
        |sec: &BTreeMap<String, f64>, best: &mut StandIn| -> Result<Vec<(f64, f64)>, GapError> {
            let mut tried = Vec::new();
            for f in STAND_IN_FRACTIONS {
                tried.push((f * bound, try_at(f * bound, sec, best)?));
            }
            Ok(tried)
        };
    let drawn_secondary = best.1.clone();
    tried.extend(sweep(&drawn_secondary, &mut best)?);
    golden_steps(&mut tried, &mut best, &try_at)?;
    for p in &info.parameters[1..] {
        if best.3 <= 2.0 {
            break;
        }
        // Each value with the magnitude searched over the same fractions: a secondary value
        // and the magnitude trade off (a friction drift's slip scale and its size), so a
        // value judged at another value's best magnitude would look worse than it is.
        let drawn_value = best.1.get(p.name).copied();
        let mut by_value: Vec<(f64, Vec<(f64, f64)>)> = Vec::new();
        for v in profile_values(p, STAND_IN_SECONDARY_VALUES) {
            if Some(v) == drawn_value {
                continue;
            }
            let mut sec = best.1.clone();
            sec.insert(p.name.to_string(), v);
            by_value.push((v, sweep(&sec, &mut best)?));
        }
        // The golden-section steps at the value that came closest, if it moved.
        if best.1.get(p.name).copied() != drawn_value {
            let chosen = best.1.get(p.name).copied();
            if let Some((_, tried)) = by_value.iter_mut().find(|(v, _)| Some(*v) == chosen) {
                golden_steps(tried, &mut best, &try_at)?;
            }
        }
    }
    Ok((best.2, best.3))
}

/// Three golden-section steps of the magnitude at the best stand-in's secondary values,
/// into the wider side of the best of `tried` (magnitude, score).
pub(super) fn golden_steps(
    tried: &mut Vec<(f64, f64)>,
    best: &mut StandIn,
    try_at: &TryAt,
) -> Result<(), GapError> {
    for _ in 0..3 {
        tried.sort_by(|a, b| a.0.total_cmp(&b.0));
        let Some(i) = tried
            .iter()
            .enumerate()
            .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
            .map(|(i, _)| i)
        else {
            break;
        };
        let lo = tried[i.saturating_sub(1)].0;
        let hi = tried[(i + 1).min(tried.len() - 1)].0;
        let m = tried[i].0;
        let next = if hi - m > m - lo {
            m + 0.381_966 * (hi - m)
        } else {
            m - 0.381_966 * (m - lo)
        };
        if tried.iter().any(|t| t.0 == next) {
            break;
        }
        let sec = best.1.clone();
        let d = try_at(next, &sec, best)?;
        tried.push((next, d));
    }
    Ok(())
}

/// Tests (indices below `tests`) in which the effect is detectable on that test's
/// observations alone ([`detectability`] over them > 2).
pub(super) fn detectable_tests(
    effect: &[Observation],
    control: &[Observation],
    noise: &NoiseModel,
    noisy: &[Observation],
    tests: usize,
) -> usize {
    (0..tests)
        .filter(|&t| detectability_in(effect, control, noise, noisy, |o| o.test == t) > 2.0)
        .count()
}

/// [`detectability`] over the observations `keep` selects.
pub(super) fn detectability_in(
    effect: &[Observation],
    control: &[Observation],
    noise: &NoiseModel,
    noisy: &[Observation],
    keep: impl Fn(&Observation) -> bool,
) -> f64 {
    let terms = effect
        .iter()
        .zip(control)
        .zip(noisy)
        .filter(|(_, o)| keep(o))
        .map(|((e, c), o)| (noise.term(o, c.value, 0.0), e.value - c.value))
        .filter(|(t, _)| t.var > 0.0)
        .map(|(t, d)| Term { residual: d, ..t });
    let t = gaussian(terms, noise.scale_var);
    if t.w > 0.0 {
        (t.r2 / t.w).sqrt()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gap::diagnose::emulator::effect_with;

    /// A friction drift's mass readings after slip distances `l` (m): `delta (1 - e^(-l/s))`.
    fn drift_readings(delta: f64, slip_scale: f64) -> Vec<Observation> {
        [20.0_f64, 200.0, 2000.0]
            .iter()
            .enumerate()
            .map(|(i, l)| Observation {
                test: i,
                increment: 0,
                quantity: crate::gap::diagnose::noise::Quantity::Mass("shoe".into()),
                value: delta * (1.0 - (-l / slip_scale).exp()),
                specimens: 1,
                spread: None,
                weight: 1.0,
                fixed_var: 0.0,
                floor_var: 0.0,
                model_rel_var: 0.0,
            })
            .collect()
    }

    #[test]
    fn the_closest_stand_in_is_searched_over_secondary_values_too() {
        // A pair's readings that a friction drift of 0.042 over a 100 m slip scale reproduces
        // exactly (both on the search's grids: 0.07 of the 0.6 bound, the middle of five
        // log-spaced scales over [1, 10⁴] m); the drift was drawn at 0.18 over 997 m. At the
        // drawn scale no magnitude comes within the noise (σ = 10⁻³), at 100 m one does.
        let info = crate::gap::effects::info("friction_drift").expect("in the library");
        let drawn = effect_with(
            info,
            0.18,
            &BTreeMap::from([("slip_scale_m".into(), 997.0)]),
        );
        let target = drift_readings(0.042, 100.0);
        let score = |obs: &[Observation]| {
            let n = obs.len() as f64;
            (obs.iter()
                .zip(&target)
                .map(|(a, b)| ((a.value - b.value) / 1e-3).powi(2))
                .sum::<f64>()
                / n)
                .sqrt()
        };
        let alone_at = |m: f64, sec: &BTreeMap<String, f64>| {
            Ok(drift_readings(
                m,
                sec.get("slip_scale_m").copied().unwrap_or(100.0),
            ))
        };
        let at_drawn = drift_readings(0.18, 997.0);
        let d0 = score(&at_drawn);
        let (_, d) = closest_alone(&drawn, &alone_at, &score, (at_drawn, d0)).expect("searched");
        assert!(d0 > 2.0, "drawn values told apart: {d0}");
        let best_at_drawn_scale = STAND_IN_FRACTIONS
            .iter()
            .map(|f| score(&drift_readings(f * 0.6, 997.0)))
            .fold(f64::INFINITY, f64::min);
        assert!(best_at_drawn_scale > 2.0, "{best_at_drawn_scale}");
        assert!(
            d < 2.0,
            "a stand-in within the noise (0.042 over 100 m) is found: score {d}"
        );
    }
}
