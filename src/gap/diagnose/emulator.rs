//! The model's predictions for a campaign's tests, nominal and under each library effect,
//! tabulated over the effect's magnitude so that fitting never waits for a simulation.
//!
//! Over 700 lines for now: the nominal tables, the effects' grids, their secondary-parameter
//! variants and the exact pair tables share one simulation plan and cache; the variants and
//! pairs are the part to move out next (issue 30's data walk).
//!
//! - Nominal: every test simulated through the rig's own segment path
//!   ([`crate::gap::rig`], no scatter, no noise), once at the configured tolerance and once at
//!   half of it (the numerical uncertainty), and once with the friction coefficients raised by
//!   [`FRICTION_STEP`] (the parameter uncertainty of Table 5.2's fit, by sensitivity), and once
//!   entering the excitation [`SETTLE_SHIFT_S`] later (the spread of a window's wear over
//!   initial states).
//! - Wear-law effects: evaluated exactly on the nominal windows' tracks at every magnitude of a
//!   fine table (no simulation).
//! - Dynamics effects: simulated at a grid of magnitudes (0, and the bound halved repeatedly);
//!   between grid points the prediction is interpolated, log-linearly in each quantity. The
//!   interpolation is an approximation of the simulator: its error is of the order of the
//!   chaotic spread the tolerance-halving run measures, which the diagnosis already carries.
//! - A dynamics effect with a wear-law effect: exact once the diagnosis has built their
//!   [`PairTable`] (the wear law on the dynamics effect's own simulated tracks).
//! - Two effects together otherwise: the product of their ratios to the nominal (exact when
//!   they act independently, an approximation otherwise; stated in the report).
//! - Variants: an effect tabulated again at other values of its secondary parameters
//!   ([`EffectTable::parameters`]), for the diagnosis to profile them.

use super::measured::{measure, MeasuredValue};
pub use super::prediction::{mean_square, Prediction, TestPredictions};
pub use super::table::{EffectTable, PairTable};
use crate::gap::effects::{Acts, Effect, EffectInfo, ParameterInfo, LIBRARY};
use crate::gap::rig::{simulate_test, ModelIncrement, RigOptions};
use crate::gap::tracks::WearTerm;
use crate::gap::window::{WindowCache, WindowOptions};
use crate::gap::{Campaign, GapError};
use crate::models::spec::CaseSpec;
use crate::pipeline::RunControl;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Raise of mu_s and mu_d for the friction sensitivity run: Table 5.2 gives mu to three or four
/// digits from a fit to torque records (thesis 4.4-4.5); 0.01 is taken as one standard
/// uncertainty (estimate).
pub const FRICTION_STEP: f64 = 0.01;

/// Extra settle of the initial-state run, s: the body enters the excitation from another
/// state. A window's wear depends on where the rattle starts (the motion may settle on one of
/// several periodic or chaotic regimes), which a tolerance-halving run started from the same
/// state does not show; the spread between the two runs is part of the numerical uncertainty.
pub const SETTLE_SHIFT_S: f64 = 0.2;

/// How the emulator simulates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EmulatorOptions {
    /// Simulated excitation per increment, s.
    pub window_s: f64,
    /// Settle before it, s.
    pub settle_s: f64,
    /// Rate of the predicted acceleration records, Hz.
    pub accelerometer_rate_hz: f64,
    /// Grid points of each dynamics effect on the positive side of 0 (the bound, halved
    /// `grid_points - 1` times); negative bounds get the bound and its half.
    pub grid_points: usize,
    /// Library effects considered (None: every effect that applies to the campaign's models).
    pub effects: Option<Vec<String>>,
    /// Worker threads for the simulations.
    pub threads: usize,
}

impl Default for EmulatorOptions {
    fn default() -> Self {
        Self {
            window_s: 2.0,
            settle_s: 0.3,
            accelerometer_rate_hz: 2000.0,
            grid_points: 5,
            effects: None,
            threads: 2,
        }
    }
}

/// The nominal model and the tabulated effects of one campaign's tests.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Emulator {
    /// Nominal predictions.
    pub nominal: TestPredictions,
    /// Nominal at half the tolerances.
    pub halving: TestPredictions,
    /// Nominal with mu_s and mu_d raised by [`FRICTION_STEP`].
    pub friction_step: TestPredictions,
    /// Nominal entering the excitation [`SETTLE_SHIFT_S`] later (another initial state).
    pub initial_state: TestPredictions,
    /// Per test and increment: the nominal's friction work by contact-pressure band and by
    /// slip-speed band, J (see [`PRESSURE_BANDS`], [`SLIP_BANDS`]).
    pub bands: Vec<Vec<Bands>>,
    /// Nominal response records per test (first increment), for spectra: (rate Hz, samples).
    pub response_records: Vec<(f64, Vec<[f64; 3]>)>,
    /// The same from the tolerance-halving run.
    pub halving_response_records: Vec<(f64, Vec<[f64; 3]>)>,
    /// Tabulated effects (an effect may have several tables: variants at other values of
    /// its secondary parameters).
    pub effects: Vec<EffectTable>,
    /// Exact dynamics + wear-law pairs built so far.
    #[serde(default)]
    pub pairs: Vec<PairTable>,
    /// Two dynamics effects simulated together at the magnitudes a pair's fits landed on.
    #[serde(default)]
    pub joints: Vec<JointPoint>,
    /// Secondary values the campaign's data measure (`measured`): tables that contradict
    /// them are left out of every family.
    #[serde(default)]
    pub measured: Vec<MeasuredValue>,
    /// Windows simulated to build it.
    pub simulations: usize,
    /// Options used.
    pub options: EmulatorOptions,
}

/// Two dynamics effects simulated together: `tables` (emulator table indices) at
/// `magnitudes`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct JointPoint {
    /// The two tables.
    pub tables: [usize; 2],
    /// Their magnitudes.
    pub magnitudes: [f64; 2],
    /// The simulated predictions.
    pub predictions: TestPredictions,
    /// The same two effects entering the excitation [`SETTLE_SHIFT_S`] later: the spread of
    /// a window's wear over initial states with both on (docs/diagnosis.md, "Two dynamics
    /// effects together"). Two effects together may make the motion depend on the state it
    /// starts from where neither alone does; None in an emulator saved before it was kept.
    #[serde(default)]
    pub initial_state: Option<TestPredictions>,
}

/// Friction work of one increment's window by band, J.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Bands {
    /// By contact pressure (see [`PRESSURE_BANDS`]).
    pub pressure: Vec<f64>,
    /// By slip speed (see [`SLIP_BANDS`]).
    pub slip: Vec<f64>,
    /// Work by kind and the wear mechanisms' drivers per contact (the energy budget).
    #[serde(default)]
    pub work: super::budget::IncrementWork,
}

/// Contact-pressure bands relative to the yield strength Sy: below 0.1 Sy, 0.1-1 Sy, 1-2 Sy
/// (plastic, below the eq. 3.11 cutoff), above 2 Sy (no wear in the thesis' law).
pub const PRESSURE_BANDS: [&str; 4] = [
    "< 0.1 Sy",
    "0.1-1 Sy",
    "1-2 Sy (below cutoff)",
    "> 2 Sy (cutoff)",
];
/// Slip-speed bands: below 1 mm/s (stuck), 1-6.5 mm/s (up to Table 5.2's stiction speed),
/// 6.5-100 mm/s, above 100 mm/s.
pub const SLIP_BANDS: [&str; 4] = ["< 1 mm/s", "1-6.5 mm/s", "6.5-100 mm/s", "> 100 mm/s"];

fn band_of(x: f64, edges: &[f64]) -> usize {
    edges.iter().take_while(|e| x >= **e).count()
}

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

fn effect_at(info: &EffectInfo, magnitude: f64) -> Effect {
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

/// A task's simulated increments.
type TaskResult = Result<Vec<ModelIncrement>, GapError>;

/// One simulation task: (what, effects, tolerance scale, friction step, test).
struct Task {
    slot: usize,
    test: usize,
    effects: Vec<Effect>,
    tolerance_scale: f64,
    friction_step: f64,
    settle_shift_s: f64,
}

/// One simulation slot: the effects on, the tolerance scale, the friction step and the settle
/// shift of its run of every test.
type Slot = (Vec<Effect>, f64, f64, f64);

/// Every test's case and the number of increments simulated for it.
fn plan(campaign: &Campaign, configs_dir: &Path) -> Result<(Vec<CaseSpec>, Vec<usize>), GapError> {
    let cases: Vec<CaseSpec> = campaign
        .tests
        .iter()
        .enumerate()
        .map(|(ti, t)| t.case(ti, configs_dir))
        .collect::<Result<_, _>>()?;
    let increments: Vec<usize> = campaign
        .tests
        .iter()
        .map(|t| {
            t.specimens
                .iter()
                .map(|s| s.increments.len())
                .max()
                .unwrap_or(0)
        })
        .collect();
    Ok((cases, increments))
}

/// Simulates every test under every slot on `options.threads` threads; returns the increments
/// `[slot][test]`. `progress(done, total)` is called after every test simulated, counting from
/// `done_before` of `total`.
#[allow(clippy::too_many_arguments)]
fn simulate_slots(
    slots: &[Slot],
    campaign: &Campaign,
    (cases, increments): (&[CaseSpec], &[usize]),
    configs_dir: &Path,
    options: &EmulatorOptions,
    control: &RunControl,
    cache: &WindowCache,
    progress: &(dyn Fn(usize, usize) + Sync),
    (done_before, total): (usize, usize),
) -> Result<Vec<Vec<Vec<ModelIncrement>>>, GapError> {
    let tasks: Vec<Task> = slots
        .iter()
        .enumerate()
        .flat_map(|(slot, (effects, tol, fr, settle))| {
            (0..campaign.tests.len()).map(move |test| Task {
                slot,
                test,
                effects: effects.clone(),
                tolerance_scale: *tol,
                friction_step: *fr,
                settle_shift_s: *settle,
            })
        })
        .collect();
    let results: Mutex<Vec<Option<TaskResult>>> =
        Mutex::new((0..tasks.len()).map(|_| None).collect());
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(done_before);
    std::thread::scope(|scope| {
        for _ in 0..options.threads.max(1) {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(task) = tasks.get(i) else { break };
                if control.is_cancelled() {
                    break;
                }
                let r = run_task(
                    task,
                    campaign,
                    cases,
                    configs_dir,
                    options,
                    increments,
                    control,
                    cache,
                );
                if let Ok(mut v) = results.lock() {
                    v[i] = Some(r);
                }
                progress(done.fetch_add(1, Ordering::SeqCst) + 1, total);
            });
        }
    });
    if control.is_cancelled() {
        return Err(GapError::Simulation {
            what: "diagnosis".into(),
            message: "cancelled".into(),
        });
    }
    let mut results = results.into_inner().map_err(|_| GapError::Simulation {
        what: "diagnosis".into(),
        message: "a simulation thread panicked".into(),
    })?;
    let mut by_slot: Vec<Vec<Vec<ModelIncrement>>> = (0..slots.len()).map(|_| Vec::new()).collect();
    for (i, task) in tasks.iter().enumerate() {
        let r = results[i].take().ok_or_else(|| GapError::Simulation {
            what: format!("test {}", campaign.tests[task.test].id),
            message: "not simulated".into(),
        })??;
        debug_assert_eq!(by_slot[task.slot].len(), task.test);
        by_slot[task.slot].push(r);
    }
    Ok(by_slot)
}

/// Predictions `[test][increment]` of one slot's simulated increments.
fn predictions_of(slot: &[Vec<ModelIncrement>]) -> TestPredictions {
    slot.iter()
        .map(|t| t.iter().map(Prediction::from_increment).collect())
        .collect()
}

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
                            work: super::budget::IncrementWork::of(&inc.segments)?,
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

    /// Predictions with the effects `(table index, magnitude)`: one effect from its table;
    /// two or more as the nominal times each one's ratio to the nominal.
    pub fn predict(&self, effects: &[(usize, f64)]) -> TestPredictions {
        match effects {
            [] => self.nominal.clone(),
            [(e, m)] => self.effects[*e].at(*m),
            // A member at 0 is the other alone, exactly.
            [(_, z), one] | [one, (_, z)] if *z == 0.0 => self.effects[one.0].at(one.1),
            [(a, ma), (b, mb)] if self.pair(*a, *b).is_some() => {
                let p = &self.pairs[self.pair(*a, *b).unwrap_or_default()];
                if p.dynamics == *a {
                    p.at(*ma, *mb)
                } else {
                    p.at(*mb, *ma)
                }
            }
            [(a, ma), (b, mb)] if self.has_joint(*a, *b) => self.interacting(*a, *ma, *b, *mb),
            many => self.product(many),
        }
    }

    /// Magnitude `m` of table `t` over the table's bound on its side of 0.
    pub fn unit(&self, t: usize, m: f64) -> f64 {
        m / self.effects[t].bound_for(m).abs().max(1e-300)
    }

    /// Whether tables `a` and `b` were simulated together anywhere.
    fn has_joint(&self, a: usize, b: usize) -> bool {
        self.joints
            .iter()
            .any(|j| j.tables == [a, b] || j.tables == [b, a])
    }

    /// Tables `a` at `ma` and `b` at `mb` together: the product of their ratios times an
    /// interaction the joint simulations measure (docs/diagnosis.md, "Two dynamics effects
    /// together"). With `u`, `v` each magnitude over its bound, the interaction of a quantity
    /// is `exp(u v h(u, v))` (a product that is 0 at the joint points: `+ u v h`), where
    /// `h_i = ln(joint_i / product_i) / (u_i v_i)` at each joint point is interpolated by
    /// inverse squared distance in `(u, v)`. So it is exact at every joint point, vanishes
    /// where either member is off (the product is exact there), and is smooth in both
    /// magnitudes: a fit moving between joint points sees no jump.
    fn interacting(&self, a: usize, ma: f64, b: usize, mb: f64) -> TestPredictions {
        let (u, v) = (self.unit(a, ma), self.unit(b, mb));
        // (u_i, v_i, joint, product) at each joint point of the two tables, in (a, b) order.
        let points: Vec<(f64, f64, &TestPredictions, TestPredictions)> = self
            .joints
            .iter()
            .filter_map(|j| {
                let (x, y) = if j.tables == [a, b] {
                    (j.magnitudes[0], j.magnitudes[1])
                } else if j.tables == [b, a] {
                    (j.magnitudes[1], j.magnitudes[0])
                } else {
                    return None;
                };
                let (ui, vi) = (self.unit(a, x), self.unit(b, y));
                (ui * vi != 0.0).then(|| (ui, vi, &j.predictions, self.product(&[(a, x), (b, y)])))
            })
            .collect();
        let mut out = self.product(&[(a, ma), (b, mb)]);
        // Weights: one at a joint point (exact there), inverse squared distance otherwise.
        let d2: Vec<f64> = points
            .iter()
            .map(|(ui, vi, _, _)| (u - ui).powi(2) + (v - vi).powi(2))
            .collect();
        let weights: Vec<f64> = match d2.iter().position(|d| *d < 1e-24) {
            Some(k) => (0..d2.len()).map(|i| f64::from(u8::from(i == k))).collect(),
            None => d2.iter().map(|d| 1.0 / d).collect(),
        };
        let total: f64 = weights.iter().sum();
        if points.is_empty() || !(total > 0.0) {
            return out;
        }
        let uv = u * v;
        for (ti, t) in out.iter_mut().enumerate() {
            for (k, q) in t.iter_mut().enumerate() {
                let at = |i: usize| (&points[i].2[ti][k], &points[i].3[ti][k]);
                // Multiplicative where every joint point and its product are positive.
                let mut h_log = q.zip(q, |_, _| 0.0);
                let mut h_add = h_log.clone();
                let mut positive = q.zip(q, |x, _| if x > 0.0 { 1.0 } else { 0.0 });
                for (i, (ui, vi, _, _)) in points.iter().enumerate() {
                    let (joint, base) = at(i);
                    let w = weights[i] / total / (ui * vi);
                    let log = joint.zip(base, |j, p| {
                        if j > 0.0 && p > 0.0 {
                            (j / p).ln()
                        } else {
                            f64::NAN
                        }
                    });
                    positive = positive.zip(&log, |s, l| if l.is_nan() { 0.0 } else { s });
                    h_log = h_log.zip(&log, |h, l| if l.is_nan() { h } else { h + w * l });
                    h_add = h_add.zip(&joint.zip(base, |j, p| j - p), |h, d| h + w * d);
                }
                let scaled = q.zip(&h_log, |x, h| x * (uv * h).exp());
                let added = q.zip(&h_add, |x, h| x + uv * h);
                let mixed = scaled.zip(&positive, |x, s| if s > 0.0 { x } else { f64::NAN });
                *q = mixed.zip(&added, |x, a| if x.is_nan() { a } else { x });
            }
        }
        out
    }

    /// The nominal times each effect's ratio to the nominal.
    fn product(&self, effects: &[(usize, f64)]) -> TestPredictions {
        let mut out = self.nominal.clone();
        for (e, m) in effects {
            let p = self.effects[*e].at(*m);
            for (ti, t) in out.iter_mut().enumerate() {
                for (k, q) in t.iter_mut().enumerate() {
                    let nom = &self.nominal[ti][k];
                    let ratio = nom.zip(&p[ti][k], |n, x| if n > 0.0 { x / n } else { f64::NAN });
                    let delta = nom.zip(&p[ti][k], |n, x| x - n);
                    *q = q.zip(&ratio, |a, r| a * r);
                    // Where the nominal is 0, add the effect's own amount.
                    let fixed = q.zip(&delta, |a, d| if a.is_nan() { d } else { a });
                    *q = fixed;
                }
            }
        }
        out
    }
}

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

    /// Whether a joint point of tables `a` and `b` (either order) is held within relative
    /// distance `tolerance` of magnitudes `ma` and `mb` (0: at exactly them).
    pub fn joint_near(&self, [(a, ma), (b, mb)]: [(usize, f64); 2], tolerance: f64) -> bool {
        let near = |x: f64, y: f64| (x - y).abs() <= tolerance * y.abs();
        self.joints.iter().any(|j| {
            (j.tables == [a, b] && near(j.magnitudes[0], ma) && near(j.magnitudes[1], mb))
                || (j.tables == [b, a] && near(j.magnitudes[1], ma) && near(j.magnitudes[0], mb))
        })
    }

    /// Every table of the effect of table `t` (its library defaults and its variants), in
    /// table order; when a measurement of the effect's secondary values is held and some
    /// table agrees with it, only the tables that agree (`measured`).
    pub fn family(&self, t: usize) -> Vec<usize> {
        let name = self.effects[t].info.name;
        let all: Vec<usize> = (0..self.effects.len())
            .filter(|&i| self.effects[i].info.name == name)
            .collect();
        let agreeing: Vec<usize> = all
            .iter()
            .copied()
            .filter(|&i| self.agrees_with_measurements(i))
            .collect();
        if agreeing.is_empty() {
            all
        } else {
            agreeing
        }
    }

    /// Index of the exact pair table of tables `a` and `b` (either order), if built.
    pub fn pair(&self, a: usize, b: usize) -> Option<usize> {
        self.pairs
            .iter()
            .position(|p| (p.dynamics, p.wear) == (a, b) || (p.dynamics, p.wear) == (b, a))
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

#[allow(clippy::too_many_arguments)]
fn run_task(
    task: &Task,
    campaign: &Campaign,
    cases: &[CaseSpec],
    configs_dir: &Path,
    options: &EmulatorOptions,
    increments: &[usize],
    control: &RunControl,
    cache: &WindowCache,
) -> Result<Vec<ModelIncrement>, GapError> {
    let rig = RigOptions {
        effects: task.effects.clone(),
        window_s: options.window_s,
        settle_s: options.settle_s + task.settle_shift_s,
        accelerometer_rate_hz: Some(options.accelerometer_rate_hz),
        ..RigOptions::default()
    };
    let window = WindowOptions {
        window_s: options.window_s,
        settle_s: options.settle_s + task.settle_shift_s,
        accelerometer_rate_hz: Some(options.accelerometer_rate_hz),
        tolerance_scale: task.tolerance_scale,
    };
    let mut case = cases[task.test].clone();
    if task.friction_step != 0.0 {
        if let Some(rb) = case.rattle_box.as_mut() {
            rb.friction.mu_static += task.friction_step;
            rb.friction.mu_dynamic += task.friction_step;
        }
        if let Some(l) = case.launcher.as_mut() {
            l.friction.mu_static += task.friction_step;
            l.friction.mu_dynamic += task.friction_step;
        }
    }
    simulate_test(
        task.test,
        campaign,
        Some(&case),
        configs_dir,
        &rig,
        &window,
        increments[task.test],
        control,
        cache,
    )
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

impl Emulator {
    /// The measurement of `effect`'s `parameter`, if the campaign's data gave one.
    pub fn measured_value(&self, effect: &str, parameter: &str) -> Option<&MeasuredValue> {
        self.measured
            .iter()
            .find(|m| m.effect == effect && m.parameter == parameter)
    }

    /// The secondary parameters of `info` that no measurement fixes (a fit's to choose).
    pub fn unmeasured_secondaries(&self, info: &'static EffectInfo) -> Vec<&'static ParameterInfo> {
        info.parameters[1..]
            .iter()
            .filter(|p| self.measured_value(info.name, p.name).is_none())
            .collect()
    }

    /// Secondary parameters of table `t` off their defaults that no measurement fixes (the
    /// fit chose them).
    pub fn fitted_secondaries(&self, t: usize) -> usize {
        let table = &self.effects[t];
        table
            .parameters
            .keys()
            .filter(|p| self.measured_value(table.info.name, p).is_none())
            .count()
    }

    /// The campaign's measurements taken (`measure`), and for each a variant of its effect at
    /// the measured value on the default table's grid when no table agrees with it yet. A
    /// measurement whose effect is not tabulated is dropped.
    pub fn take_measurements(
        &mut self,
        campaign: &Campaign,
        configs_dir: &Path,
        control: &RunControl,
        cache: &WindowCache,
    ) -> Result<(), GapError> {
        let measured = measure(campaign, configs_dir)?;
        self.measured.clear();
        for mv in measured {
            let Some(default) = (0..self.effects.len()).find(|&t| {
                self.effects[t].info.name == mv.effect && self.effects[t].parameters.is_empty()
            }) else {
                continue;
            };
            tracing::info!(
                effect = %mv.effect, parameter = %mv.parameter, value = mv.value, sd = mv.sd,
                "measured from the campaign's records"
            );
            let (value, parameter) = (mv.value, mv.parameter.clone());
            self.measured.push(mv);
            if !self
                .family(default)
                .iter()
                .any(|&t| self.agrees_with_measurements(t))
            {
                let grid: Vec<f64> = self.effects[default]
                    .magnitudes
                    .iter()
                    .copied()
                    .filter(|m| *m != 0.0)
                    .collect();
                self.add_variant(
                    campaign,
                    configs_dir,
                    default,
                    BTreeMap::from([(parameter, value)]),
                    &grid,
                    control,
                    cache,
                )?;
            }
        }
        Ok(())
    }

    /// Whether table `t`'s secondary values agree with every measurement of its effect.
    pub fn agrees_with_measurements(&self, t: usize) -> bool {
        let table = &self.effects[t];
        self.measured
            .iter()
            .filter(|m| m.effect == table.info.name)
            .all(|m| m.agrees(table.parameter(&m.parameter)))
    }
}
