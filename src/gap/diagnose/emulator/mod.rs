//! The model's predictions for a campaign's tests, nominal and under each library effect,
//! tabulated over the effect's magnitude so that fitting never waits for a simulation.
//!
//! Its rooms: [`grids`] (which effects apply and the magnitudes they are tabulated at),
//! [`slots`] (the simulation plan: one slot per effect set and test), `build` (the nominal and
//! the grids), [`lookup`] (a prediction at any magnitudes), `extend` (refinement, variants,
//! joint points and exact pairs added later) and `measurements` (what the data measure).
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

mod build;
mod extend;
pub mod grids;
pub mod lookup;
mod measurements;
pub mod slots;

pub use super::prediction::{mean_square, Prediction, TestPredictions};
pub use super::table::{EffectTable, PairTable};
pub use grids::{applicable, dynamics_grid, effect_with, wear_grid};

use super::measured::MeasuredValue;
use serde::{Deserialize, Serialize};

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
    /// a window's wear over initial states with both on (docs/results/diagnosis.md, "Two dynamics
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

pub(super) fn band_of(x: f64, edges: &[f64]) -> usize {
    edges.iter().take_while(|e| x >= **e).count()
}
