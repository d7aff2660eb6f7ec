//! The initial-state spread of two dynamics effects together: what a joint point's
//! settle-shifted twin adds to the model's uncertainty (docs/results/diagnosis.md, "Two dynamics
//! effects together").
//!
//! The noise model takes the spread of a window's wear over initial states from the
//! nominal's settle-shift run, and an effect's own spread from its table's roughness. Two
//! effects together can make the motion depend on the state it enters the excitation in where
//! neither alone does (bench 2035: friction drift 0.48 with a cross-axis drive, test A's
//! increments moving by -46 % and +144 % between two settles, every mass of the drift alone
//! unchanged). Each joint point simulated twice, [`super::emulator::SETTLE_SHIFT_S`] apart,
//! measures that spread; the pair carries it wherever both members are on.

use super::emulator::Emulator;
use super::noise::{Observation, Quantity};
use std::collections::BTreeMap;

/// One joint point with its settle-shifted twin: its tables, each magnitude over its bound,
/// and per observation the pooled relative variance and the squared difference of the two
/// runs.
pub(super) struct JointSpread {
    tables: [usize; 2],
    units: [f64; 2],
    rel_var: Vec<f64>,
    abs_var: Vec<f64>,
}

/// The spread of every joint point that has a twin. Per test, the two runs' relative
/// differences are pooled (RMS) over the test's increments and components for masses, and
/// over its increments for each accelerometer quantity: two runs are one draw each, so one
/// observation's difference alone would be a variance estimate on one degree of freedom,
/// zero wherever the two draws happen to agree. Each observation's own squared difference is
/// kept too: a relative variance is applied to the prediction, and where the prediction is
/// the smaller of two draws far apart (bench 2035: test A's second-increment response y, a
/// mean square of 290 m²/s⁴ at one settle and 4921 at the other) the pooled relative spread
/// of a few tens of per cent would still leave the other draw many deviations away.
pub(super) fn joint_spreads(emulator: &Emulator, obs: &[Observation]) -> Vec<JointSpread> {
    let kind = |o: &Observation| match &o.quantity {
        Quantity::Mass(_) => (o.test, "mass".to_string()),
        q => (o.test, q.label()),
    };
    emulator
        .joints
        .iter()
        .filter_map(|j| {
            let shifted = j.initial_state.as_ref()?;
            // Each observation's two draws, taken once.
            let draws: Vec<(f64, f64)> = obs
                .iter()
                .map(|o| (o.predicted(&j.predictions), o.predicted(shifted)))
                .collect();
            let mut pooled: BTreeMap<(usize, String), (f64, usize)> = BTreeMap::new();
            for (o, &(x, y)) in obs.iter().zip(&draws) {
                let scale = x.abs().max(y.abs());
                if scale > 0.0 && scale.is_finite() {
                    let e = pooled.entry(kind(o)).or_insert((0.0, 0));
                    e.0 += ((x - y) / scale).powi(2);
                    e.1 += 1;
                }
            }
            let rel_var = obs
                .iter()
                .map(|o| pooled.get(&kind(o)).map_or(0.0, |(s, n)| s / *n as f64))
                .collect();
            let abs_var = draws
                .iter()
                .map(|(x, y)| {
                    let d = x - y;
                    if d.is_finite() {
                        d * d
                    } else {
                        0.0
                    }
                })
                .collect();
            let [a, b] = j.tables;
            Some(JointSpread {
                tables: j.tables,
                units: [
                    emulator.unit(a, j.magnitudes[0]),
                    emulator.unit(b, j.magnitudes[1]),
                ],
                rel_var,
                abs_var,
            })
        })
        .collect()
}

/// The joint points of tables `a` at `ma` and `b` at `mb`, weighted as the interaction is (one
/// at a joint point, inverse squared distance in magnitude over bound otherwise), each faded
/// by the product of the magnitudes over the point's (capped at 1), so that the spread
/// vanishes as either member goes off and the pair becomes a single, whose own spread its
/// table's roughness carries. They depend on the pair's magnitudes only, so a likelihood
/// evaluation takes them once for all its observations ([`PairSpread::rel_var`]).
pub(super) struct PairSpread<'s> {
    /// (joint point, fade, squared distance); at a joint point itself only that point, with
    /// distance 1.
    points: Vec<(&'s JointSpread, f64, f64)>,
    /// Sum of the points' inverse squared distances (1 at a joint point itself).
    total: f64,
}

/// [`PairSpread`] of tables `a` at `ma` and `b` at `mb` (no point when either is off).
pub(super) fn pair_spread<'s>(
    spreads: &'s [JointSpread],
    emulator: &Emulator,
    (a, ma): (usize, f64),
    (b, mb): (usize, f64),
) -> PairSpread<'s> {
    if ma == 0.0 || mb == 0.0 {
        return PairSpread {
            points: Vec::new(),
            total: 1.0,
        };
    }
    let (u, v) = (emulator.unit(a, ma), emulator.unit(b, mb));
    // (point, fade, squared distance) of each joint point of the two tables.
    let near: Vec<(&JointSpread, f64, f64)> = spreads
        .iter()
        .filter_map(|s| {
            let [x, y] = if s.tables == [a, b] {
                s.units
            } else if s.tables == [b, a] {
                [s.units[1], s.units[0]]
            } else {
                return None;
            };
            let fade = (u * v / (x * y)).abs().min(1.0);
            Some((s, fade, (u - x).powi(2) + (v - y).powi(2)))
        })
        .collect();
    if let Some(&(s, fade, _)) = near.iter().find(|(_, _, d)| *d < 1e-24) {
        return PairSpread {
            points: vec![(s, fade, 1.0)],
            total: 1.0,
        };
    }
    let total: f64 = near.iter().map(|(_, _, d)| 1.0 / d).sum();
    PairSpread {
        points: near,
        total,
    }
}

impl PairSpread<'_> {
    /// The relative variance (of the prediction `mu`) the pair adds to observation `i`: at
    /// each joint point the larger of its pooled relative variance and its own squared
    /// difference over `mu²`, faded and weighted.
    pub(super) fn rel_var(&self, i: usize, mu: f64) -> f64 {
        self.points
            .iter()
            .map(|(s, fade, d)| {
                let own = if mu != 0.0 {
                    s.abs_var[i] / (mu * mu)
                } else {
                    0.0
                };
                fade * s.rel_var[i].max(own) / d / self.total
            })
            .sum()
    }
}
