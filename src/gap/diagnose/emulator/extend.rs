//! The emulator extended after it is built: dynamics tables refined at fitted magnitudes,
//! two dynamics effects simulated together (joint points), secondary-parameter variants and
//! exact dynamics + wear-law pair tables.

use super::grids::{effect_with, wear_grid};
use super::slots::{plan, predictions_of, simulate_slots, Slot};
use super::{EffectTable, Emulator, JointPoint, PairTable, TestPredictions, SETTLE_SHIFT_S};
use crate::cases::RunControl;
use crate::gap::effects::{Acts, Effect};
use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use std::collections::BTreeMap;
use std::path::Path;

impl Emulator {
    /// Adds simulated points to dynamics-effect tables: each request `(table index, magnitude)`
    /// whose magnitude the table does not hold yet is simulated for every test (the same
    /// segment path, tolerance and initial state as the grid) and inserted in order. Wear-law
    /// tables are exact at every magnitude already and are left alone. Returns how many points
    /// were added; `progress(done, total)` counts this refinement's test simulations.
    ///
    /// This is the adaptive refinement of the diagnosis: where a fit lands between grid points
    /// of a rough table, the simulator itself replaces the interpolation there.
    pub fn refine(
        &mut self,
        campaign: &Campaign,
        configs_dir: &Path,
        requests: &[(usize, f64)],
        control: &RunControl,
        cache: &WindowCache,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<usize, GapError> {
        let mut targets: Vec<(usize, f64)> = Vec::new();
        for &(e, m) in requests {
            let Some(t) = self.effects.get(e) else {
                continue;
            };
            let inside = m >= t.magnitudes[0] && m <= t.magnitudes[t.magnitudes.len() - 1];
            if !t.simulated
                || !m.is_finite()
                || !inside
                || t.magnitudes.contains(&m)
                || targets.contains(&(e, m))
            {
                continue;
            }
            targets.push((e, m));
        }
        if targets.is_empty() {
            return Ok(0);
        }
        let sets = targets
            .iter()
            .map(|&(e, m)| {
                let t = &self.effects[e];
                vec![effect_with(t.info, m, &t.parameters)]
            })
            .collect();
        let predictions =
            self.simulate_sets(campaign, configs_dir, sets, control, cache, progress)?;
        for (&(e, m), p) in targets.iter().zip(predictions) {
            let t = &mut self.effects[e];
            let at = t.magnitudes.partition_point(|x| *x < m);
            t.magnitudes.insert(at, m);
            t.predictions.insert(at, p);
        }
        // Exact pairs on a refined dynamics table follow it.
        let stale: Vec<(usize, usize)> = self
            .pairs
            .iter()
            .filter(|p| targets.iter().any(|(e, _)| *e == p.dynamics))
            .map(|p| (p.dynamics, p.wear))
            .collect();
        for (d, w) in stale {
            self.add_pair(campaign, configs_dir, d, w, control, cache)?;
        }
        Ok(targets.len())
    }

    /// Simulates dynamics tables `a` and `b` together at `ma` and `mb` (held already: nothing
    /// done). Returns whether a point was added.
    #[allow(clippy::too_many_arguments)]
    pub fn add_joint(
        &mut self,
        campaign: &Campaign,
        configs_dir: &Path,
        (a, ma): (usize, f64),
        (b, mb): (usize, f64),
        control: &RunControl,
        cache: &WindowCache,
    ) -> Result<bool, GapError> {
        if ma == 0.0 || mb == 0.0 || !ma.is_finite() || !mb.is_finite() {
            return Ok(false);
        }
        if self.joint_near([(a, ma), (b, mb)], 0.0) {
            return Ok(false);
        }
        let (ta, tb) = (&self.effects[a], &self.effects[b]);
        let set = vec![
            effect_with(ta.info, ma, &ta.parameters),
            effect_with(tb.info, mb, &tb.parameters),
        ];
        let slots = vec![
            (set.clone(), 1.0, 0.0, 0.0),
            (set, 1.0, 0.0, SETTLE_SHIFT_S),
        ];
        let mut p = self
            .run_slots(campaign, configs_dir, slots, control, cache, &|_, _| {})?
            .into_iter();
        let predictions = p.next().unwrap_or_default();
        self.joints.push(JointPoint {
            tables: [a, b],
            magnitudes: [ma, mb],
            predictions,
            initial_state: p.next(),
        });
        Ok(true)
    }

    /// Predictions `[set][test][increment]` of every test with each set of effects on,
    /// through the same segment path, tolerance and initial state as the grid (windows already
    /// simulated come from `cache`; wear-law effects are evaluated on the windows' tracks).
    fn simulate_sets(
        &mut self,
        campaign: &Campaign,
        configs_dir: &Path,
        sets: Vec<Vec<Effect>>,
        control: &RunControl,
        cache: &WindowCache,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Vec<TestPredictions>, GapError> {
        let slots: Vec<Slot> = sets.into_iter().map(|e| (e, 1.0, 0.0, 0.0)).collect();
        self.run_slots(campaign, configs_dir, slots, control, cache, progress)
    }

    /// [`Self::simulate_sets`] with each slot's tolerance scale, friction step and settle shift
    /// given.
    fn run_slots(
        &mut self,
        campaign: &Campaign,
        configs_dir: &Path,
        slots: Vec<Slot>,
        control: &RunControl,
        cache: &WindowCache,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Vec<TestPredictions>, GapError> {
        let (cases, increments) = plan(campaign, configs_dir)?;
        let before = cache.len();
        let total = slots.len() * campaign.tests.len();
        let by_slot = simulate_slots(
            &slots,
            campaign,
            (&cases, &increments),
            configs_dir,
            &self.options,
            control,
            cache,
            progress,
            (0, total),
        )?;
        self.simulations += cache.len() - before;
        Ok(by_slot.iter().map(|s| predictions_of(s)).collect())
    }

    /// Adds a variant of table `of`: the same effect with its secondary parameters at
    /// `secondary` (those not listed at the library defaults), simulated at `magnitudes`
    /// (dynamics; 0 is the nominal and is always included) or evaluated exactly on the nominal
    /// windows' tracks at the wear-law grid (wear law; `magnitudes` ignored). Returns the new
    /// table's index; an identical variant already held is returned instead.
    #[allow(clippy::too_many_arguments)]
    pub fn add_variant(
        &mut self,
        campaign: &Campaign,
        configs_dir: &Path,
        of: usize,
        secondary: BTreeMap<String, f64>,
        magnitudes: &[f64],
        control: &RunControl,
        cache: &WindowCache,
    ) -> Result<usize, GapError> {
        let info = self.effects[of].info;
        if let Some(i) = self
            .effects
            .iter()
            .position(|t| t.info.name == info.name && t.parameters == secondary)
        {
            return Ok(i);
        }
        let mut grid: Vec<f64> = match info.acts {
            Acts::WearLaw => wear_grid(info),
            Acts::Dynamics => magnitudes
                .iter()
                .copied()
                .filter(|m| m.is_finite())
                .chain([0.0])
                .collect(),
        };
        grid.sort_by(f64::total_cmp);
        grid.dedup();
        let sets: Vec<Vec<Effect>> = grid
            .iter()
            .map(|&m| {
                if m == 0.0 {
                    Vec::new()
                } else {
                    vec![effect_with(info, m, &secondary)]
                }
            })
            .collect();
        let predictions =
            self.simulate_sets(campaign, configs_dir, sets, control, cache, &|_, _| {})?;
        self.effects.push(EffectTable {
            info,
            magnitudes: grid,
            predictions,
            simulated: info.acts == Acts::Dynamics,
            parameters: secondary,
        });
        Ok(self.effects.len() - 1)
    }

    /// Builds (or rebuilds) the exact pair of dynamics table `dynamics` and wear-law table
    /// `wear`: the wear law at its bound evaluated on the dynamics effect's own windows at
    /// every magnitude of its table (the windows come from `cache`, or are simulated again).
    /// The prediction is linear in the wear magnitude when the wear term is (checked at an
    /// eighth of the bound on the dynamics effect's first simulated magnitude, to 1e-9
    /// relative); otherwise slices at nine magnitudes of the wear-law grid are kept. Returns
    /// the pair table's index.
    pub fn add_pair(
        &mut self,
        campaign: &Campaign,
        configs_dir: &Path,
        dynamics: usize,
        wear: usize,
        control: &RunControl,
        cache: &WindowCache,
    ) -> Result<usize, GapError> {
        let (d, w) = (self.effects[dynamics].clone(), self.effects[wear].clone());
        if d.info.acts != Acts::Dynamics || w.info.acts != Acts::WearLaw {
            return Err(GapError::field(
                "effects",
                format!(
                    "an exact pair is a dynamics effect and a wear-law effect, not `{}` and `{}`",
                    d.info.name, w.info.name
                ),
            ));
        }
        let slice_at = |this: &mut Self, wm: f64| -> Result<EffectTable, GapError> {
            let sets = d
                .magnitudes
                .iter()
                .map(|&m| {
                    let mut set = Vec::new();
                    if m != 0.0 {
                        set.push(effect_with(d.info, m, &d.parameters));
                    }
                    if wm != 0.0 {
                        set.push(effect_with(w.info, wm, &w.parameters));
                    }
                    set
                })
                .collect();
            let predictions =
                this.simulate_sets(campaign, configs_dir, sets, control, cache, &|_, _| {})?;
            Ok(EffectTable {
                predictions,
                ..d.clone()
            })
        };
        let max = w.info.parameters[0].max;
        let top = slice_at(self, max)?;
        // Linearity check on the first simulated magnitude.
        let probe = d.magnitudes.iter().position(|m| *m != 0.0).unwrap_or(0);
        let eighth = {
            let m = d.magnitudes[probe];
            let mut set = vec![effect_with(w.info, max / 8.0, &w.parameters)];
            if m != 0.0 {
                set.push(effect_with(d.info, m, &d.parameters));
            }
            self.simulate_sets(campaign, configs_dir, vec![set], control, cache, &|_, _| {})?
        };
        let linear = eighth.first().is_some_and(|e| {
            e.iter().enumerate().all(|(ti, t)| {
                t.iter().enumerate().all(|(k, p)| {
                    let a = d.predictions[probe][ti][k].flat();
                    let b = top.predictions[probe][ti][k].flat();
                    p.flat().iter().zip(a.iter().zip(&b)).all(|(x, (u, v))| {
                        let lin = u + (v - u) / 8.0;
                        (x - lin).abs() <= 1e-9 * x.abs().max(lin.abs()).max(1e-300)
                    })
                })
            })
        });
        let (wear_magnitudes, slices) = if linear {
            (vec![0.0, max], vec![d.clone(), top])
        } else {
            let grid = wear_grid(w.info);
            let mut ms: Vec<f64> = grid.iter().copied().skip(1).step_by(4).collect();
            ms.retain(|m| *m != max);
            let mut slices = vec![d.clone()];
            let mut mags = vec![0.0];
            for m in ms {
                slices.push(slice_at(self, m)?);
                mags.push(m);
            }
            slices.push(top);
            mags.push(max);
            (mags, slices)
        };
        let table = PairTable {
            dynamics,
            wear,
            wear_magnitudes,
            slices,
        };
        if let Some(i) = self.pair(dynamics, wear) {
            self.pairs[i] = table;
            Ok(i)
        } else {
            self.pairs.push(table);
            Ok(self.pairs.len() - 1)
        }
    }
}
