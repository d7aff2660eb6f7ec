//! One effect's predictions tabulated over its magnitude, interpolated between the simulated
//! magnitudes, and the table's roughness (how far each point lies from what its neighbours
//! interpolate).

use super::prediction::TestPredictions;
use crate::gap::effects::EffectInfo;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One effect tabulated over its magnitude.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EffectTable {
    /// The library entry (serialized as its name).
    #[serde(with = "library_entry")]
    pub info: &'static EffectInfo,
    /// Magnitudes, ascending; contains 0.
    pub magnitudes: Vec<f64>,
    /// Predictions at each magnitude.
    pub predictions: Vec<TestPredictions>,
    /// True when the table comes from simulations (interpolated between grid points).
    pub simulated: bool,
    /// Values of the effect's other parameters this table was made at (by name); a parameter
    /// not listed is at its library default. Tables of one effect that differ here are the
    /// variants the diagnosis profiles its secondary parameters over.
    #[serde(default)]
    pub parameters: BTreeMap<String, f64>,
}

impl EffectTable {
    /// How far each grid point on either side of 0 lies from what its neighbours interpolate
    /// (leave-one-out), relative, RMS over tests, increments and interior points, per quantity
    /// label (`mass cube`, `response y`, ...). It measures both the interpolation error and the
    /// window-to-window spread of a regime the effect brings (a cube tumbling in 3D under
    /// cross-axis drive wears differently at each magnitude); the diagnosis adds it to the
    /// model's uncertainty wherever the effect is on.
    pub fn roughness(&self) -> BTreeMap<String, f64> {
        let mut sums: BTreeMap<String, (f64, usize)> = BTreeMap::new();
        let n = self.magnitudes.len();
        for i in 1..n.saturating_sub(1) {
            let (a, m, b) = (
                self.magnitudes[i - 1],
                self.magnitudes[i],
                self.magnitudes[i + 1],
            );
            // Interior points of one side only (0 is the nominal, not interpolated).
            if m == 0.0 || (a < 0.0) != (b < 0.0) && a != 0.0 && b != 0.0 {
                continue;
            }
            let without = EffectTable {
                info: self.info,
                magnitudes: self
                    .magnitudes
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| *k != i)
                    .map(|(_, x)| *x)
                    .collect(),
                predictions: self
                    .predictions
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| *k != i)
                    .map(|(_, x)| x.clone())
                    .collect(),
                simulated: self.simulated,
                parameters: self.parameters.clone(),
            };
            let guess = without.at(m);
            for (t_actual, t_guess) in self.predictions[i].iter().zip(&guess) {
                for (p_actual, p_guess) in t_actual.iter().zip(t_guess) {
                    let labels = p_actual.labels();
                    for ((x, y), label) in p_actual.flat().iter().zip(p_guess.flat()).zip(labels) {
                        let scale = x.abs().max(y.abs());
                        if scale > 0.0 {
                            let e = sums.entry(label).or_insert((0.0, 0));
                            e.0 += ((x - y) / scale).powi(2);
                            e.1 += 1;
                        }
                    }
                }
            }
        }
        sums.into_iter()
            .map(|(k, (s, c))| (k, (s / c.max(1) as f64).sqrt()))
            .collect()
    }

    /// Prediction at magnitude `m` (clamped to the table), exact at table points. Between
    /// them each quantity's change from the nominal, `Δ(m) = q(m) - q(0)`, is interpolated as a
    /// power law (linear in log |Δ| against log |m|) where both neighbours change it the same
    /// way, linearly otherwise; below the first grid point on either side `Δ = Δ₁ (m/m₁)^k`,
    /// `k` from the first two grid points (clamped to 0.5-4, 1 without a second point). Power
    /// laws are what the effects give at small magnitude: a cross-axis share s puts s² of the
    /// drive's mean square on the other axes; a mount of period P amplifies by 1/(1 - (fP)²).
    pub fn at(&self, m: f64) -> TestPredictions {
        let n = self.magnitudes.len();
        let m = m.clamp(self.magnitudes[0], self.magnitudes[n - 1]);
        if let Some(i) = self.magnitudes.iter().position(|g| *g == m) {
            return self.predictions[i].clone();
        }
        let Some(zero) = self.magnitudes.iter().position(|g| *g == 0.0) else {
            return self.predictions[0].clone();
        };
        // Grid points on m's side of 0, nearest 0 first: (|magnitude|, index).
        let side: Vec<(f64, usize)> = if m > 0.0 {
            (zero + 1..n).map(|i| (self.magnitudes[i], i)).collect()
        } else {
            (0..zero).rev().map(|i| (-self.magnitudes[i], i)).collect()
        };
        let x = m.abs();
        let j = side
            .iter()
            .position(|(g, _)| x < *g)
            .unwrap_or(side.len() - 1);
        let interp = |q: &[f64]| -> f64 {
            // q[0]: nominal; q[1..]: the side's points in order.
            let d = |k: usize| q[k + 1] - q[0];
            let same = |a: f64, b: f64| a != 0.0 && b != 0.0 && a.signum() == b.signum();
            let delta = if j == 0 {
                let k = if side.len() > 1 && same(d(0), d(1)) {
                    ((d(1) / d(0)).ln() / (side[1].0 / side[0].0).ln()).clamp(0.5, 4.0)
                } else {
                    1.0
                };
                d(0) * (x / side[0].0).powf(k)
            } else {
                let (ga, gb) = (side[j - 1].0, side[j].0);
                let (da, db) = (d(j - 1), d(j));
                if same(da, db) {
                    let t = (x / ga).ln() / (gb / ga).ln();
                    da.signum() * ((1.0 - t) * da.abs().ln() + t * db.abs().ln()).exp()
                } else {
                    da + (db - da) * (x - ga) / (gb - ga)
                }
            };
            let v = q[0] + delta;
            if q.iter().all(|x| *x >= 0.0) {
                v.max(0.0)
            } else {
                v
            }
        };
        let nominal = &self.predictions[zero];
        nominal
            .iter()
            .enumerate()
            .map(|(ti, t)| {
                t.iter()
                    .enumerate()
                    .map(|(k, p0)| {
                        let mut columns: Vec<Vec<f64>> = vec![p0.flat()];
                        for (_, i) in &side {
                            columns.push(self.predictions[*i][ti][k].flat());
                        }
                        let values: Vec<f64> = (0..columns[0].len())
                            .map(|q| {
                                let row: Vec<f64> = columns.iter().map(|c| c[q]).collect();
                                interp(&row)
                            })
                            .collect();
                        p0.with_flat(&values)
                    })
                    .collect()
            })
            .collect()
    }
}

impl EffectTable {
    /// The value of parameter `name` in this table (its library default when not listed).
    pub fn parameter(&self, name: &str) -> f64 {
        self.parameters.get(name).copied().unwrap_or_else(|| {
            self.info
                .parameters
                .iter()
                .find(|p| p.name == name)
                .map_or(f64::NAN, |p| p.default)
        })
    }

    /// The table's magnitude bound on `m`'s side of 0 (the magnitude parameter's max, or its
    /// min for negative magnitudes).
    pub fn bound_for(&self, m: f64) -> f64 {
        let p = &self.info.parameters[0];
        if m < 0.0 {
            p.min
        } else {
            p.max
        }
    }
}

/// A dynamics effect and a wear-law effect together, exactly: the wear law evaluated on the
/// dynamics effect's own simulated tracks (never a product of the two effects' ratios).
/// `slices[j]` is the dynamics table (its magnitudes) with the wear law at
/// `wear_magnitudes[j]`; between slices the prediction is linear in the wear magnitude (exact
/// for a wear term linear in its magnitude, which the emulator checks when it builds the
/// table; otherwise it keeps more slices).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PairTable {
    /// Index of the dynamics effect's table in the emulator.
    pub dynamics: usize,
    /// Index of the wear-law effect's table in the emulator.
    pub wear: usize,
    /// Wear-law magnitudes of the slices, ascending, from 0.
    pub wear_magnitudes: Vec<f64>,
    /// The dynamics effect over its magnitudes, one table per wear magnitude.
    pub slices: Vec<EffectTable>,
}

impl PairTable {
    /// Prediction with the dynamics effect at `dynamics` and the wear law at `wear` (clamped
    /// to the slices' range).
    pub fn at(&self, dynamics: f64, wear: f64) -> TestPredictions {
        let w = &self.wear_magnitudes;
        let n = w.len();
        if n == 0 {
            return Vec::new();
        }
        let x = wear.clamp(w[0], w[n - 1]);
        if let Some(j) = w.iter().position(|v| *v == x) {
            return self.slices[j].at(dynamics);
        }
        let j = w.partition_point(|v| *v <= x).clamp(1, n - 1);
        let t = (x - w[j - 1]) / (w[j] - w[j - 1]);
        let a = self.slices[j - 1].at(dynamics);
        let b = self.slices[j].at(dynamics);
        a.iter()
            .zip(&b)
            .map(|(ta, tb)| {
                ta.iter()
                    .zip(tb)
                    .map(|(pa, pb)| pa.zip(pb, |u, v| u + t * (v - u)))
                    .collect()
            })
            .collect()
    }
}

/// Serializes a library entry as its name.
mod library_entry {
    use crate::gap::effects::{info, EffectInfo};
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(e: &&'static EffectInfo, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(e.name)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<&'static EffectInfo, D::Error> {
        let name = String::deserialize(d)?;
        info(&name).ok_or_else(|| serde::de::Error::custom(format!("unknown effect `{name}`")))
    }
}
