//! The run loop: advances a system with an integrator, hands every accepted step to an
//! observer, reports progress, honours cancellation and turns any breakdown into a
//! [`SimError::Diverged`] diagnostic naming time, body, contact and energy. Asked for a
//! checkpoint ([`RunControl::request_checkpoint`]) it stops at the next accepted step with
//! the run's state ([`EngineCheckpoint`]); [`simulate_from`] continues from it to the same
//! result bit for bit.

use super::body::BodyKind;
use super::contact::{GeometryCache, TrackState};
use super::control::{Progress, RunControl};
use super::energy::{EnergyAudit, EnergyMeter};
use super::integrator::{
    Integrator, IntegratorError, IntegratorSettings, IntegratorState, IntegratorStats,
    InteriorStage,
};
use super::system::{MultibodySystem, PowerBalance, Workspace};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Limits beyond which a run is declared diverged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DivergenceLimits {
    /// Largest admissible penetration of any track, m (rigid-body contact assumes small
    /// penetrations; default 2 mm).
    pub max_penetration_m: f64,
    /// Largest admissible speed of any dynamic body relative to the world, m/s (default 100).
    pub max_speed_m_s: f64,
}

impl Default for DivergenceLimits {
    fn default() -> Self {
        Self {
            max_penetration_m: 2e-3,
            max_speed_m_s: 100.0,
        }
    }
}

/// What an observer sees after each accepted step.
pub struct StepView<'a> {
    /// Start of the step, s.
    pub t_prev: f64,
    /// End of the step, s.
    pub t: f64,
    /// State at `t`.
    pub state: &'a [f64],
    /// Active contact tracks at `t`.
    pub tracks: &'a [TrackState],
    /// Stored energy and power terms at `t` (the drive's power among them).
    pub power: PowerBalance,
    /// The energy account's friction work per contact from the start of the run to `t`, J.
    pub friction_work_j: &'a [f64],
    /// The system.
    pub system: &'a MultibodySystem,
}

/// Why a run stopped early.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// Numerical or physical breakdown.
    #[error("diverged at t = {time_s:.6} s: {reason} (body `{body}`, contact `{contact}`, mechanical energy {energy_j:.4e} J)")]
    Diverged {
        /// Simulated time, s.
        time_s: f64,
        /// Body most involved.
        body: String,
        /// Contact most involved ("none" if no contact was active).
        contact: String,
        /// Mechanical energy of the last good state, J.
        energy_j: f64,
        /// What happened.
        reason: String,
    },
    /// Stopped through the run control.
    #[error("cancelled at t = {time_s:.6} s")]
    Cancelled {
        /// Simulated time reached, s.
        time_s: f64,
    },
    /// Stopped at an accepted step because a checkpoint was requested: the state to resume
    /// from with [`simulate_from`].
    #[error("checkpointed at t = {:.6} s", .0.time_s)]
    Checkpointed(Box<EngineCheckpoint>),
    /// The checkpoint given to [`simulate_from`] does not belong to this system or span.
    #[error("checkpoint does not fit the run: {0}")]
    BadCheckpoint(String),
}

/// The run loop's state at an accepted-step boundary: time, state vector, the integrator's
/// carried state ([`IntegratorState`]), the contact overlaps kept for the next step (their
/// reuse depends on when each was computed) and the energy account so far. The system itself
/// is rebuilt from the case.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EngineCheckpoint {
    /// Simulated time of the boundary, s.
    pub time_s: f64,
    /// Start of the run, s.
    pub start_time_s: f64,
    /// End of the run, s.
    pub end_time_s: f64,
    /// State at `time_s`.
    pub state: Vec<f64>,
    /// Integrator state.
    pub integrator: IntegratorState,
    /// Contact overlaps kept on their pieces for the next step.
    pub geometry: GeometryCache,
    /// Energy account so far.
    pub energy: EnergyMeter,
    /// Wall-clock time spent before the checkpoint, s.
    pub wall_s: f64,
}

/// Summary of a finished run.
#[derive(Debug, Clone, Default)]
pub struct RunStats {
    /// Integrator counters.
    pub integrator: IntegratorStats,
    /// Wall-clock time spent, s.
    pub wall_s: f64,
    /// The run's energy account.
    pub energy: Option<EnergyAudit>,
}

/// Integrates `system` from `t0` to `t_end`, updating `y` in place.
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    system: &MultibodySystem,
    y: &mut [f64],
    t0: f64,
    t_end: f64,
    settings: IntegratorSettings,
    limits: DivergenceLimits,
    control: &RunControl,
    observer: &mut dyn FnMut(&StepView),
) -> Result<RunStats, SimError> {
    simulate_from(
        system, y, t0, t_end, settings, limits, control, observer, None,
    )
}

/// [`simulate`], or with `resume` its continuation from a checkpoint of the same system,
/// span and settings: the observer then sees the steps after the checkpoint, and the result
/// (states, steps, counters, energy account) is that of the uninterrupted run bit for bit.
#[allow(clippy::too_many_arguments)]
pub fn simulate_from(
    system: &MultibodySystem,
    y: &mut [f64],
    t0: f64,
    t_end: f64,
    settings: IntegratorSettings,
    limits: DivergenceLimits,
    control: &RunControl,
    observer: &mut dyn FnMut(&StepView),
    resume: Option<EngineCheckpoint>,
) -> Result<RunStats, SimError> {
    let start = Instant::now();
    let mut integ = Integrator::new(system, settings);
    let mut ws = system.workspace();
    // The integrator's last derivative evaluation of each step is at the accepted state: its
    // tracks are those of the step, with no second overlap computation.
    ws.keep_tracks = true;
    let mut tracks: Vec<TrackState> = Vec::with_capacity(16);
    let mut t = t0;
    let mut last_progress = Instant::now();
    let mut meter = EnergyMeter::new(system.contacts.iter().map(|c| c.name.clone()).collect());
    let mut wall_before = 0.0;
    if let Some(cp) = resume {
        if cp.state.len() != y.len() || cp.start_time_s != t0 || cp.end_time_s != t_end {
            return Err(SimError::BadCheckpoint(format!(
                "{} state entries over [{}, {}] s, the run has {} over [{t0}, {t_end}] s",
                cp.state.len(),
                cp.start_time_s,
                cp.end_time_s,
                y.len()
            )));
        }
        if !(t0..=t_end).contains(&cp.time_s) {
            return Err(SimError::BadCheckpoint(format!(
                "time {} s outside the run",
                cp.time_s
            )));
        }
        integ
            .restore_state(cp.integrator)
            .map_err(|e| SimError::BadCheckpoint(e.to_string()))?;
        y.copy_from_slice(&cp.state);
        t = cp.time_s;
        ws.geometry = cp.geometry;
        meter = cp.energy;
        wall_before = cp.wall_s;
        (control.progress)(Progress {
            simulated_time_s: t,
            end_time_s: t_end,
            fraction: ((t - t0) / (t_end - t0)).clamp(0.0, 1.0),
        });
    } else {
        // One evaluation at the start: its tracks, stored energy and powers open the account.
        let mut dy = vec![0.0; y.len()];
        system.derivative(t, y, &mut dy, &mut ws);
        std::mem::swap(&mut tracks, &mut ws.tracks);
        record_energy(system, &mut meter, t, y, &mut ws, &tracks, None);
        observer(&StepView {
            t_prev: t,
            t,
            state: y,
            tracks: &tracks,
            power: ws.power,
            friction_work_j: meter.friction_work_j(),
            system,
        });
    }
    let mut last_good = y.to_vec();
    while t < t_end {
        if control.is_cancelled() {
            if control.checkpoint_requested() {
                return Err(SimError::Checkpointed(Box::new(EngineCheckpoint {
                    time_s: t,
                    start_time_s: t0,
                    end_time_s: t_end,
                    state: y.to_vec(),
                    integrator: integ.save_state(),
                    geometry: ws.geometry.clone(),
                    energy: meter,
                    wall_s: wall_before + start.elapsed().as_secs_f64(),
                })));
            }
            return Err(SimError::Cancelled { time_s: t });
        }
        let t_prev = t;
        match integ.advance(system, &mut ws, t, y, t_end) {
            Ok(t_new) => t = t_new,
            Err(e) => {
                y.copy_from_slice(&last_good);
                return Err(diagnose(system, t, y, &mut ws, &e.to_string(), Some(&e)));
            }
        }
        std::mem::swap(&mut tracks, &mut ws.tracks);
        record_energy(
            system,
            &mut meter,
            t,
            y,
            &mut ws,
            &tracks,
            integ.interior_stage(),
        );
        if let Some(tr) = tracks
            .iter()
            .find(|tr| tr.penetration > limits.max_penetration_m)
        {
            let c = &system.contacts[tr.contact as usize];
            let reason = format!(
                "penetration {:.4} mm exceeds the bound {:.4} mm",
                tr.penetration * 1e3,
                limits.max_penetration_m * 1e3
            );
            let energy = system.energy(t_prev, &last_good, &mut ws).total();
            return Err(SimError::Diverged {
                time_s: t,
                body: system.bodies[c.body_a].name.clone(),
                contact: c.name.clone(),
                energy_j: energy,
                reason,
            });
        }
        system.frames(t, y, &mut ws);
        for (i, b) in system.bodies.iter().enumerate() {
            if matches!(b.kind, BodyKind::Dynamic { .. })
                && ws.frames[i].velocity.norm() > limits.max_speed_m_s
            {
                let reason = format!(
                    "body speed {:.3e} m/s exceeds the bound {} m/s",
                    ws.frames[i].velocity.norm(),
                    limits.max_speed_m_s
                );
                let mut d = diagnose(system, t, y, &mut ws, &reason, None);
                if let SimError::Diverged { body, .. } = &mut d {
                    *body = b.name.clone();
                }
                return Err(d);
            }
        }
        observer(&StepView {
            t_prev,
            t,
            state: y,
            tracks: &tracks,
            power: ws.power,
            friction_work_j: meter.friction_work_j(),
            system,
        });
        last_good.copy_from_slice(y);
        if last_progress.elapsed() >= control.progress_interval {
            last_progress = Instant::now();
            (control.progress)(Progress {
                simulated_time_s: t,
                end_time_s: t_end,
                fraction: ((t - t0) / (t_end - t0)).clamp(0.0, 1.0),
            });
        }
    }
    (control.progress)(Progress {
        simulated_time_s: t,
        end_time_s: t_end,
        fraction: 1.0,
    });
    Ok(RunStats {
        integrator: integ.stats,
        wall_s: wall_before + start.elapsed().as_secs_f64(),
        energy: Some(meter.audit()),
    })
}

/// Adds the accepted state `(t, y)` to the energy account; `ws` holds its last derivative
/// evaluation (stored energy and power terms).
fn record_energy(
    system: &MultibodySystem,
    meter: &mut EnergyMeter,
    t: f64,
    y: &[f64],
    ws: &mut Workspace,
    tracks: &[TrackState],
    stage: Option<&InteriorStage>,
) {
    let power = ws.power;
    let motion = system.motion_energy(t, y, ws);
    meter.record(
        t,
        motion.kinetic + motion.gravitational + power.elastic_energy,
        &power,
        tracks,
        stage,
    );
}

fn collect_tracks(
    system: &MultibodySystem,
    t: f64,
    y: &[f64],
    ws: &mut Workspace,
    out: &mut Vec<TrackState>,
) {
    out.clear();
    system.tracks(t, y, ws, &mut |tr| out.push(*tr));
}

/// Builds a divergence diagnostic from the last good state: the contact carrying the largest
/// normal force (if any) and the body with the largest kinetic energy.
fn diagnose(
    system: &MultibodySystem,
    t: f64,
    y: &[f64],
    ws: &mut Workspace,
    reason: &str,
    _err: Option<&IntegratorError>,
) -> SimError {
    let mut tracks = Vec::new();
    collect_tracks(system, t, y, ws, &mut tracks);
    let worst = tracks
        .iter()
        .max_by(|a, b| a.normal_force.total_cmp(&b.normal_force));
    let (contact, contact_body) = match worst {
        Some(tr) => {
            let c = &system.contacts[tr.contact as usize];
            (
                format!(
                    "{} (track {}, N = {:.4e} N, w = {:.4e} m)",
                    c.name, tr.track, tr.normal_force, tr.penetration
                ),
                Some(system.bodies[c.body_a].name.clone()),
            )
        }
        None => ("none".to_string(), None),
    };
    let energy = system.energy(t, y, ws);
    system.frames(t, y, ws);
    let body = contact_body.unwrap_or_else(|| {
        system
            .bodies
            .iter()
            .enumerate()
            .filter(|(_, b)| matches!(b.kind, BodyKind::Dynamic { .. }))
            .max_by(|(i, a), (j, b)| {
                let ea = a.mass.mass * ws.frames[*i].velocity.norm_squared();
                let eb = b.mass.mass * ws.frames[*j].velocity.norm_squared();
                ea.total_cmp(&eb)
            })
            .map(|(_, b)| b.name.clone())
            .unwrap_or_else(|| "none".to_string())
    });
    SimError::Diverged {
        time_s: t,
        body,
        contact,
        energy_j: energy.total(),
        reason: reason.to_string(),
    }
}
