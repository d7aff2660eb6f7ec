//! What a model run reports: wear and loading per contact and per body over the excitation
//! window, the window's mean powers, the integrator's counters, the recorded tracks and
//! response, and the energy account.

use crate::physics::energy::EnergyAudit;
use crate::physics::integrator::IntegratorStats;
use crate::physics::track::TrackSample;
use crate::wear::integrate::WearTotals;
use serde::{Deserialize, Serialize};

/// Wear and loading of one contact: totals over the excitation window, rates and means over
/// the rate window ([`super::RateWindow`]: after the excitation's ramp-in).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ContactReport {
    /// Contact name.
    pub name: String,
    /// Body carrying the convex pieces.
    pub body_a: String,
    /// Body carrying the faces.
    pub body_b: String,
    /// Wear totals (volume, work, work above the cutoff, pressure histogram).
    pub wear: WearTotals,
    /// Share of the normal-load-times-slip work (what the wear law integrates) done above the
    /// wear law's cutoff (thesis 5.5), 0..1.
    pub work_share_above_cutoff: f64,
    /// Wear mass charged to body a, mg.
    pub mass_a_mg: f64,
    /// Wear mass charged to body b, mg.
    pub mass_b_mg: f64,
    /// Total wear-mass rate of the contact over the rate window, mg/h.
    pub mass_rate_mg_per_h: f64,
    /// Wear-mass rate charged to body a, mg/h.
    pub mass_rate_a_mg_per_h: f64,
    /// Wear-mass rate charged to body b, mg/h.
    pub mass_rate_b_mg_per_h: f64,
    /// Time-averaged normal force over the rate window, N.
    pub mean_normal_force_n: f64,
    /// Time-averaged normal-load-times-slip power Σ N |v_slip| over the rate window, W: what the
    /// Archard law integrates (wear volume = K/H × this work). Not a dissipated power: friction
    /// dissipates μ times it where the contact slides.
    pub mean_normal_slip_power_w: f64,
    /// Time-averaged power dissipated by friction over the rate window, W: the energy account's
    /// friction work over the rate window divided by its length.
    pub mean_friction_power_w: f64,
    /// Work dissipated by friction over the excitation window, J (the energy account's).
    pub friction_work_j: f64,
    /// Largest normal force seen, N.
    pub peak_normal_force_n: f64,
}

/// Wear charged to one body, summed over its contacts.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BodyReport {
    /// Body name.
    pub name: String,
    /// Wear mass, mg.
    pub mass_mg: f64,
    /// Wear-mass rate over the rate window, mg/h.
    pub mass_rate_mg_per_h: f64,
}

/// Everything a run produces (serializable: a partitioned run's checkpoint keeps the reports
/// of its finished parts).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunReport {
    /// Per contact.
    pub contacts: Vec<ContactReport>,
    /// Per body.
    pub bodies: Vec<BodyReport>,
    /// Length of the excitation window (settle's end to the run's end), s: the totals (wear
    /// mass, friction work) are over it.
    pub window_s: f64,
    /// Where the rates (mean force and powers, wear-mass rates) are taken: from the end of the
    /// excitation's ramp-in to the run's end.
    pub rate_window: super::RateWindow,
    /// Time-averaged total normal force over the rate window, N.
    pub mean_normal_force_n: f64,
    /// Time-averaged total normal-load-times-slip power Σ N |v_slip| over the rate window, W (what
    /// the wear law integrates).
    pub mean_normal_slip_power_w: f64,
    /// Time-averaged total power dissipated by friction over the rate window, W (the energy
    /// account's friction work over the rate window / its length).
    pub mean_friction_power_w: f64,
    /// Integrator counters.
    pub integrator: IntegratorStats,
    /// Wall-clock time, s.
    pub wall_s: f64,
    /// Recorded track samples.
    pub tracks: Vec<TrackSample>,
    /// Response-body acceleration, world frame, sampled uniformly over the window, m/s².
    pub response_acceleration: Vec<[f64; 3]>,
    /// Sample rate of `response_acceleration`, Hz.
    pub response_rate_hz: f64,
    /// Base (drive) acceleration at the same instants, m/s².
    pub base_acceleration: Vec<[f64; 3]>,
    /// Cumulative wear volume per contact versus time: (time s, volume m³ per contact).
    pub wear_history: Vec<(f64, Vec<f64>)>,
    /// The run's energy account (settle and excitation).
    pub energy: Option<EnergyAudit>,
    /// Simulated time of the checkpoint the run resumed from, s (None: it ran from t = 0).
    /// Set by `models::case_run::run_case_model`; not part of the results.
    #[serde(default)]
    pub resumed_from_s: Option<f64>,
}
