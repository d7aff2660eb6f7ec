//! What the integrator carries from one accepted step to the next, for a run's checkpoint.
//!
//! Resuming must repeat the uninterrupted run bit for bit, so everything a later step reads
//! before writing is kept: the next step size and its growth limits, f at the step start
//! (FSAL), the previous step's start derivative and size (stage predictors), the Newton
//! matrix pieces with their age and the factorisation in use (the contact-aware Newton keeps
//! an LU while the matrix barely moves), Newton's contraction estimate, the power terms at the
//! step start (energy quadrature) and the counters. The other buffers (stage values, Newton
//! iterates, finite-difference columns, error vectors) are scratch that every attempt writes
//! before it reads them.

use super::*;
use serde::{Deserialize, Serialize};

/// The integrator's state at an accepted-step boundary (see the module doc).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct IntegratorState {
    /// Method the state belongs to.
    pub kind: IntegratorKind,
    h: f64,
    fsal_valid: bool,
    k0: Vec<f64>,
    k_prev: Vec<f64>,
    prev_h: f64,
    jac: Vec<f64>,
    lu_jac: Vec<f64>,
    lu_contact_free: bool,
    lu: NewtonLu,
    lu_valid: bool,
    lu_h: f64,
    newton_eta: f64,
    newton_z_is_new: bool,
    jac_fresh: bool,
    jac_age: u32,
    after_reject: bool,
    hold_steps: u32,
    stage: Option<InteriorStage>,
    power_start: super::super::system::PowerBalance,
    /// Absent in checkpoints written before the work test's per-time floor: no history.
    #[serde(default)]
    work_throughput: WorkThroughput,
    stats: IntegratorStats,
}

/// Why a saved integrator state does not fit an integrator.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RestoreError {
    /// Another method, or a system with another number of state entries.
    #[error("integrator state of {saved} ({saved_len} entries) does not fit {actual} ({actual_len} entries)")]
    Mismatch {
        saved: &'static str,
        saved_len: usize,
        actual: &'static str,
        actual_len: usize,
    },
}

impl Integrator {
    /// The state to resume from after the last accepted step.
    pub fn save_state(&self) -> IntegratorState {
        IntegratorState {
            kind: self.settings.kind,
            h: self.h,
            fsal_valid: self.fsal_valid,
            k0: self.k[0].clone(),
            k_prev: self.k_prev.clone(),
            prev_h: self.prev_h,
            jac: self.jac.clone(),
            lu_jac: self.lu_jac.clone(),
            lu_contact_free: self.lu_contact_free,
            lu: self.lu.clone(),
            lu_valid: self.lu_valid,
            lu_h: self.lu_h,
            newton_eta: self.newton_eta,
            newton_z_is_new: self.newton_z_is_new,
            jac_fresh: self.jac_fresh,
            jac_age: self.jac_age,
            after_reject: self.after_reject,
            hold_steps: self.hold_steps,
            stage: self.stage.clone(),
            power_start: self.power_start,
            work_throughput: self.work_throughput,
            stats: self.stats,
        }
    }

    /// Continues from `state` (saved by [`Self::save_state`] of an integrator with the same
    /// settings on the same system).
    pub fn restore_state(&mut self, state: IntegratorState) -> Result<(), RestoreError> {
        let n = self.n;
        let fits = state.kind == self.settings.kind
            && state.k0.len() == n
            && state.k_prev.len() == n
            && state.jac.len() == n * n
            && state.lu_jac.len() == n * n
            && state.lu.bodies() == n / BODY_STATE_LEN;
        if !fits {
            return Err(RestoreError::Mismatch {
                saved: state.kind.name(),
                saved_len: state.k0.len(),
                actual: self.settings.kind.name(),
                actual_len: n,
            });
        }
        self.h = state.h;
        self.fsal_valid = state.fsal_valid;
        self.k[0] = state.k0;
        self.k_prev = state.k_prev;
        self.prev_h = state.prev_h;
        self.jac = state.jac;
        self.lu_jac = state.lu_jac;
        self.lu_contact_free = state.lu_contact_free;
        self.lu = state.lu;
        self.lu_valid = state.lu_valid;
        self.lu_h = state.lu_h;
        self.newton_eta = state.newton_eta;
        self.newton_z_is_new = state.newton_z_is_new;
        self.jac_fresh = state.jac_fresh;
        self.jac_age = state.jac_age;
        self.after_reject = state.after_reject;
        self.hold_steps = state.hold_steps;
        self.stage = state.stage;
        self.power_start = state.power_start;
        self.work_throughput = state.work_throughput;
        self.stats = state.stats;
        Ok(())
    }
}
