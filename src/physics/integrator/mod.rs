//! Time integrators with error control for the stiff contact problem.
//!
//! The IMPACT damping of thesis Tables 4.1/5.2/6.2 (500 N·s/mm on a 46 g cube) gives time
//! constants near 1e-7 s, so explicit methods crawl. Three methods are available so they can be
//! compared as in thesis Table 2.3 (the benchmark prints their VDV, eq. 2.51):
//!
//! - [`IntegratorKind::Trbdf2`] (default): TR-BDF2 as an L-stable ESDIRK (trapezoidal stage
//!   then BDF2 stage, Hosea & Shampine 1996) with its third-order companion for the error
//!   estimate. One-step (no history to corrupt at contact events, the weakness of GSTIFF that
//!   made ADAMS add WSTIFF), both implicit stages share one Newton matrix `I - h d J`.
//! - [`IntegratorKind::Sdirk2`]: Alexander's two-stage L-stable SDIRK, order 2, with a
//!   filtered first-order error estimate. Cheaper per step, more steps.
//! - [`IntegratorKind::Dopri5`]: explicit Dormand-Prince 5(4). Not stiff-capable; the reference
//!   for smooth problems (torque-free body, undamped Hertz bounce).
//!
//! Newton matrix ([`NewtonJacobian`]): by default contact-aware, i.e. a finite-difference
//! Jacobian of the contact-free right-hand side (refreshed every 20 steps or after a Newton
//! failure) plus every active contact's analytic linearisation at each Newton iterate, so the
//! matrix follows contacts that open, clamp or stick inside a step; the LU is kept while the
//! matrix barely moves, and Newton stops on Hairer-Wanner's contraction estimate. The
//! alternative reuses a finite-difference Jacobian of the whole right-hand side across steps
//! and refreshes it only when convergence slows. Either way the Newton systems are solved by
//! eliminating the pose entries ([`super::newton_matrix`]).
//!
//! Contact patches ([`ContactPatches`]): with the contact-aware Newton the overlap volumes and
//! centroids are computed once per step, at the accepted state that starts it; the Newton
//! iterates compute every penetration exactly (support function) and hold each centroid on its
//! piece, which is what the contact-aware matrix assumes anyway.
//!
//! Files: `settings.rs` (method, tolerances, Newton and patch choices, counters, errors),
//! `dirk.rs` (TR-BDF2 and SDIRK2 as tableaus, their predictors, and the stage loop both run
//! on), `methods.rs` (Dopri5's tableau and attempt, the energy account's stage quadrature),
//! `newton.rs` (the stage equations' Newton iteration), `jacobian.rs` (Newton matrix:
//! finite-difference and contact-aware parts, factorisation), `diagnostics.rs` (where the steps
//! go), `checkpoint.rs` (what carries over between steps, for a run's checkpoint),
//! `step_control.rs` (error norms and step-size factors); this file holds the integrator's
//! state and the step loop.

// Stage updates index several parallel state arrays at once; index loops read clearest.
#![allow(clippy::needless_range_loop)]

mod checkpoint;
mod diagnostics;
mod dirk;
mod jacobian;
mod methods;
mod newton;
mod settings;
mod step_control;

pub use checkpoint::{IntegratorState, RestoreError};
pub use diagnostics::{StepDiagnostics, STEP_DECADES};
pub use settings::{
    ContactPatches, ErrorControl, IntegratorError, IntegratorKind, IntegratorSettings,
    IntegratorStats, NewtonJacobian, Tolerances, ENERGY_ABS_TOLERANCE_J,
};

use super::body::{BodyKind, BODY_STATE_LEN};
use super::contact::{GeometryMode, JacobianScope};
use super::newton_matrix::NewtonLu;
use super::system::{MultibodySystem, Workspace};
use diagnostics::{contact_change, contact_set_into};
use step_control::{
    rejected_step_factor, step_exponent_and_growth, CONTACT_AWARE_NEWTON_CUT,
    HOLD_STEPS_AFTER_NEWTON_FAILURE,
};

/// A Newton failure with a Jacobian at most this many steps old is blamed on the step size
/// (an impact or a stick-slip reversal inside the step), not on the Jacobian: the step is cut
/// without refreshing it (measured alone on rattle box C: -50 % Jacobians, -20 % rejections).
const YOUNG_JACOBIAN_STEPS: u32 = 2;

/// Contact-aware Newton keeps its LU while every entry of the Newton matrix moved by less than
/// this fraction of its size since the factorisation.
const LU_REUSE_CHANGE: f64 = 0.05;

/// Contact-aware Newton stops when the estimated distance to the solution, in units of the
/// local error tolerance, is below this (Hairer-Wanner II IV.8 use 0.01-0.1).
const NEWTON_KAPPA: f64 = 0.03;

/// Integrator state and scratch memory (allocated once per run).
pub struct Integrator {
    settings: IntegratorSettings,
    n: usize,
    abs_tol: Vec<f64>,
    /// The carrier's rigid motion as a state at the step's start and at the attempt's end
    /// ([`MultibodySystem::carrier_entries`]), taken out of the state before the local error
    /// test applies the relative tolerance; empty when the system has no carrier.
    carrier_start: Vec<f64>,
    carrier_end: Vec<f64>,
    /// Body owning each state entry.
    column_body: Vec<usize>,
    /// Entries the implicit methods' local error test weighs (all, or the poses only:
    /// [`ErrorControl`]).
    error_entries: Vec<usize>,
    h: f64,
    k: [Vec<f64>; 7],
    fsal_valid: bool,
    z: Vec<f64>,
    rhs: Vec<f64>,
    ynew: Vec<f64>,
    err: Vec<f64>,
    fz: Vec<f64>,
    tmp: Vec<f64>,
    /// Jacobian df/dy, column-major `n × n` (contact-aware: its contact-free part).
    jac: Vec<f64>,
    /// Contact-aware Newton: `jac` plus the contacts' Jacobian at the current iterate.
    newton_jac: Vec<f64>,
    /// Contact-aware Newton: the LU holds `I - h d jac` (no contact term). After each
    /// iterate's factorisation this is true exactly when no contact was active at the iterate;
    /// otherwise `newton_jac` is the Jacobian there.
    lu_contact_free: bool,
    /// Contact-aware Newton: the `J` the LU was made from.
    lu_jac: Vec<f64>,
    /// Contraction estimate θ/(1-θ) of the last Newton solve.
    newton_eta: f64,
    /// The last Newton solve stopped after an update: `fz` is not f at the accepted point.
    newton_z_is_new: bool,
    /// That update (`z` minus the iterate `fz` was evaluated at), when `newton_z_is_new`.
    last_dz: Vec<f64>,
    jac_fresh: bool,
    jac_age: u32,
    /// Perturbed state and derivative for the finite differences (no allocation per call).
    jac_y: Vec<f64>,
    jac_f: Vec<f64>,
    lu: NewtonLu,
    lu_valid: bool,
    /// What the LU was factored for: the step `h` (finite-difference Newton) or `h d`
    /// (contact-aware Newton, which factors per stage).
    lu_h: f64,
    last_update: f64,
    /// Counters.
    pub stats: IntegratorStats,
    /// Count [`Self::diagnostics`] (off by default: costs a sort per step and a `log10` per
    /// attempt). Rejections are classified only when the workspace keeps its tracks.
    pub diagnose: bool,
    /// Where the steps go (development diagnostics, when `diagnose`).
    pub diagnostics: StepDiagnostics,
    /// Kind of each state entry (0 position, 1 rotation, 2 velocity, 3 angular velocity):
    /// velocity columns of the Jacobian keep all poses; the diagnostics name the limiting kind.
    state_kind: Vec<u8>,
    /// Contact sets at the step start and at the attempt's end (diagnostics; reused buffers).
    start_contacts: Vec<(u32, u32, bool)>,
    end_contacts: Vec<(u32, u32, bool)>,
    /// The last attempt was rejected (caps the next growth factor at 1).
    after_reject: bool,
    /// Accepted steps left whose growth is capped after a Newton failure.
    hold_steps: u32,
    /// f at the start of the last accepted step and that step's size (stage predictors).
    k_prev: Vec<f64>,
    prev_h: f64,
    /// Power terms at the last attempt's interior stage (TR-BDF2: t + γh), for the energy
    /// account's quadrature ([`Integrator::interior_stage`]).
    stage: Option<InteriorStage>,
    /// Power terms at the start of the current step (the accepted state).
    power_start: super::system::PowerBalance,
    /// The energy account's throughput over the accepted steps (the work test's floor).
    work_throughput: WorkThroughput,
    /// The last attempt's work quadrature, J (added to `work_throughput` if it is accepted).
    attempt_work_j: f64,
}

/// The energy account's throughput over the accepted steps so far: the work test's per-time
/// floor ([`Tolerances::energy_rel`]).
///
/// The account is judged against the run's throughput (docs/reference/models.md "Energy account"), so
/// a step's allowance is `energy_rel` of its own work plus that of a step of the same size at
/// the run's mean power: the allowances sum to at most `2 energy_rel` of the throughput, and a
/// step that does little work (a light slide, a cube in flight) is no longer held to a
/// relative accuracy on it that the account cannot see.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WorkThroughput {
    /// `Σ h Σ_i w_i |P_i|` over the accepted steps (dissipated and drive power), J.
    pub work_j: f64,
    /// `Σ h` over the same steps, s.
    pub time_s: f64,
}

impl WorkThroughput {
    /// Adds one accepted step of size `h` (s) and work quadrature `work_j` (J).
    pub fn add(&mut self, work_j: f64, h: f64) {
        self.work_j += work_j;
        self.time_s += h;
    }

    /// The throughput's mean power, W (0 before the first step).
    pub fn mean_power_w(&self) -> f64 {
        if self.time_s > 0.0 {
            self.work_j / self.time_s
        } else {
            0.0
        }
    }
}

/// The power terms at a step's interior stage and the method's quadrature weights: the
/// energy account integrates each power as `h (w0 P(t) + w1 P(stage) + w2 P(t + h))`, the
/// weights with which the method advanced the state itself (TR-BDF2: `(√2/4, √2/4, 1 − √2/2)`),
/// so the works follow the same quadrature as the momenta.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct InteriorStage {
    /// Weights of the start, the stage and the end (sum 1).
    pub weights: [f64; 3],
    /// Power terms at the stage (its last Newton iterate).
    pub power: super::system::PowerBalance,
    /// Contact damping and friction power per contact at the stage, W.
    pub contacts: Vec<[f64; 2]>,
}

struct Attempt {
    err_norm: f64,
    newton_failed: bool,
}

impl Integrator {
    /// Prepares an integrator for `system`.
    pub fn new(system: &MultibodySystem, settings: IntegratorSettings) -> Self {
        let n = system.state_len();
        let tol = settings.tolerances;
        let kinds = system.state_kinds();
        let mut column_body = vec![0; n];
        for (i, b) in system.bodies.iter().enumerate() {
            if let BodyKind::Dynamic { offset } = b.kind {
                for c in column_body.iter_mut().skip(offset).take(BODY_STATE_LEN) {
                    *c = i;
                }
            }
        }
        let abs_tol = kinds
            .iter()
            .map(|&k| match k {
                0 => tol.abs_position_m,
                1 => tol.abs_rotation,
                2 => tol.abs_velocity_m_s,
                _ => tol.abs_angular_velocity_rad_s,
            })
            .collect();
        let error_entries = (0..n)
            .filter(|&i| match tol.error_control {
                ErrorControl::Full => true,
                ErrorControl::Positions => kinds[i] <= 1,
            })
            .collect();
        let v = || vec![0.0; n];
        let carrier_len = if system.carrier().is_some() { n } else { 0 };
        Self {
            settings,
            n,
            abs_tol,
            carrier_start: vec![0.0; carrier_len],
            carrier_end: vec![0.0; carrier_len],
            column_body,
            error_entries,
            h: settings.initial_step_s,
            k: [v(), v(), v(), v(), v(), v(), v()],
            fsal_valid: false,
            z: v(),
            rhs: v(),
            ynew: v(),
            err: v(),
            fz: v(),
            tmp: v(),
            jac: vec![0.0; n * n],
            newton_jac: vec![0.0; n * n],
            lu_contact_free: false,
            lu_jac: vec![0.0; n * n],
            newton_eta: 1.0,
            newton_z_is_new: false,
            last_dz: v(),
            jac_fresh: false,
            jac_age: u32::MAX,
            jac_y: v(),
            jac_f: v(),
            lu: NewtonLu::new(n / BODY_STATE_LEN),
            lu_valid: false,
            lu_h: 0.0,
            last_update: f64::INFINITY,
            stats: IntegratorStats::default(),
            diagnose: false,
            diagnostics: StepDiagnostics::default(),
            state_kind: kinds,
            start_contacts: Vec::new(),
            end_contacts: Vec::new(),
            after_reject: false,
            hold_steps: 0,
            k_prev: v(),
            prev_h: 0.0,
            stage: None,
            power_start: Default::default(),
            work_throughput: WorkThroughput::default(),
            attempt_work_j: 0.0,
        }
    }

    /// The interior stage of the last accepted TR-BDF2 step (None for the other methods, whose
    /// works the account integrates by the trapezoid rule).
    pub fn interior_stage(&self) -> Option<&InteriorStage> {
        self.stage.as_ref()
    }

    /// Newton's last update `Δz` of the last accepted step when the step's tracks and power
    /// terms are those of the iterate before it, `z − Δz` (`Integrator::start_from_last_iterate`),
    /// and `None` when they are at the accepted state.
    pub fn last_newton_update(&self) -> Option<&[f64]> {
        (self.contact_aware() && self.newton_z_is_new).then_some(self.last_dz.as_slice())
    }

    /// `f` at the next step's start and at the last evaluated Newton iterate (tests).
    #[cfg(test)]
    pub(crate) fn start_and_iterate_derivatives(&self) -> (&[f64], &[f64]) {
        (&self.k[0], &self.fz)
    }

    /// Step size the next attempt will use, s.
    pub fn step_size(&self) -> f64 {
        self.h
    }

    /// Forgets derivative history (call after the state was changed from outside).
    pub fn reset(&mut self) {
        self.fsal_valid = false;
        self.prev_h = 0.0;
        self.jac_age = u32::MAX;
    }

    fn rhs(&mut self, sys: &MultibodySystem, ws: &mut Workspace, t: f64, y: &[f64], out_k: usize) {
        let mut out = std::mem::take(&mut self.k[out_k]);
        sys.derivative(t, y, &mut out, ws);
        self.k[out_k] = out;
        self.stats.rhs_evals += 1;
    }

    /// f at the start of a step into `k[0]`; with frozen contact patches it records every
    /// overlap for the step's Newton iterates.
    fn step_start_rhs(&mut self, sys: &MultibodySystem, ws: &mut Workspace, t: f64, y: &[f64]) {
        if self.frozen_patches() {
            ws.geometry.set_mode(GeometryMode::Refresh);
            self.rhs(sys, ws, t, y, 0);
            ws.geometry.set_mode(GeometryMode::Compute);
        } else {
            self.rhs(sys, ws, t, y, 0);
        }
        self.power_start = ws.power;
    }

    fn frozen_patches(&self) -> bool {
        self.contact_aware() && self.settings.patches == ContactPatches::PerStep
    }

    /// The next step's start from Newton's last iterate `z_p` (the accepted `z = z_p + Δz` of
    /// the contact-aware Newton, or `z_p` itself when Newton stopped on its residual): `f(z) = f(z_p) +
    /// J(z_p) Δz + O(|Δz|²)` with the Jacobian that Newton assembled at `z_p`, the power terms
    /// (energy account) and the tracks (wear) of `z_p`, and with frozen patches the overlaps
    /// refreshed at `z` ([`MultibodySystem::refresh_patches`]). `Δz` is Newton's last update,
    /// so the tracks and powers lie within it of the accepted state; the derivative, which the
    /// next step's stages integrate, is off by its square. This replaces an evaluation of every
    /// contact at the accepted state (docs/journal/performance.md, twenty-third pass).
    fn start_from_last_iterate(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t_new: f64,
        y: &[f64],
    ) {
        let n = self.n;
        self.k[0].copy_from_slice(&self.fz);
        if self.newton_z_is_new {
            // The LU of the last iterate is contact-free exactly when no contact was active
            // there (`factorize_at_iterate`); otherwise `newton_jac` was assembled there.
            let jac = if self.lu_contact_free {
                &self.jac
            } else {
                &self.newton_jac
            };
            for (column, &d) in jac.chunks_exact(n).zip(&self.last_dz) {
                if d != 0.0 {
                    for (k, &j) in self.k[0].iter_mut().zip(column) {
                        *k += j * d;
                    }
                }
            }
        }
        sys.rescale_quaternion_rates(&self.ynew, &mut self.k[0]);
        self.power_start = ws.power;
        if self.frozen_patches() {
            sys.refresh_patches(t_new, y, ws);
        }
    }

    fn contact_aware(&self) -> bool {
        self.settings.newton == NewtonJacobian::ContactAware
            && self.settings.kind != IntegratorKind::Dopri5
    }

    /// Takes one accepted step from `t` (not beyond `t_end`), updating `y` in place.
    /// Returns the new time.
    pub fn advance(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &mut [f64],
        t_end: f64,
    ) -> Result<f64, IntegratorError> {
        if !self.fsal_valid {
            self.step_start_rhs(sys, ws, t, y);
            self.fsal_valid = true;
            if let Some(i) = self.k[0].iter().position(|v| !v.is_finite()) {
                return Err(IntegratorError::NonFinite { t, index: i });
            }
        }
        if !self.carrier_start.is_empty() {
            sys.carrier_entries(t, y, ws, &mut self.carrier_start);
        }
        let (order_exp, facmax) = step_exponent_and_growth(self.settings.kind);
        let classify = self.diagnose && ws.keep_tracks;
        if classify {
            contact_set_into(&ws.tracks, &mut self.start_contacts);
        }
        loop {
            let remaining = t_end - t;
            let mut h = self.h.min(self.settings.max_step_s);
            let last = h >= remaining * (1.0 - 1e-12);
            if last {
                h = remaining;
            }
            if h < self.settings.min_step_s {
                return Err(IntegratorError::StepSizeUnderflow { t, h });
            }
            let attempt = match self.settings.kind {
                IntegratorKind::Trbdf2 => self.attempt_dirk(&dirk::TRBDF2, sys, ws, t, y, h)?,
                IntegratorKind::Sdirk2 => self.attempt_dirk(&dirk::SDIRK2, sys, ws, t, y, h)?,
                IntegratorKind::Dopri5 => self.attempt_dopri5(sys, ws, t, y, h),
            };
            let passed = attempt.err_norm.is_finite() && attempt.err_norm <= 1.0;
            let rejected = attempt.newton_failed || !passed;
            if rejected && classify {
                contact_set_into(&ws.tracks, &mut self.end_contacts);
                let change = contact_change(&self.start_contacts, &self.end_contacts);
                let test = usize::from(!attempt.newton_failed);
                self.diagnostics.rejections_by_event[test][change] += 1;
            }
            if attempt.newton_failed {
                self.stats.rejected += 1;
                self.stats.newton_failures += 1;
                self.after_reject = true;
                if self.contact_aware() {
                    // The contacts' part of the matrix was current at every iterate: the
                    // step is too long for the contact event inside it. The contact-free
                    // part is refreshed too when it is not young.
                    if !(self.jac_fresh || self.jac_age <= YOUNG_JACOBIAN_STEPS) {
                        self.compute_jacobian(sys, ws, t, y);
                    }
                    self.h = h * CONTACT_AWARE_NEWTON_CUT;
                    self.hold_steps = HOLD_STEPS_AFTER_NEWTON_FAILURE;
                } else if self.jac_fresh || self.jac_age <= YOUNG_JACOBIAN_STEPS {
                    self.h = h * 0.25;
                } else {
                    // Retry the same step with a fresh Jacobian first.
                    self.jac_age = u32::MAX;
                    self.compute_jacobian(sys, ws, t, y);
                }
                continue;
            }
            let err = attempt.err_norm;
            if err.is_finite() && err <= 1.0 {
                let t_new = if last { t_end } else { t + h };
                y.copy_from_slice(&self.ynew);
                sys.normalize(y);
                self.stats.accepted += 1;
                self.work_throughput.add(self.attempt_work_j, h);
                // Explicit FSAL reuses the last stage. The implicit methods need f itself at
                // the new point, not the stage derivative (z - rhs)/(h d), which carries the
                // Newton error divided by h d and would poison the next step after a tiny
                // step. The contact-aware Newton has it from its last iterate
                // ([`Integrator::start_from_last_iterate`]); the finite-difference Newton
                // evaluates it when the accepted z moved after its last evaluation.
                // Renormalising the quaternions changes no force (frames are built from
                // normalised quaternions) and scales q' = q ⊗ ω/2 by 1/|q|, applied here.
                std::mem::swap(&mut self.k_prev, &mut self.k[0]);
                self.prev_h = h;
                match self.settings.kind {
                    IntegratorKind::Dopri5 => self.k.swap(0, 6),
                    _ if self.newton_z_is_new && !self.contact_aware() => {
                        self.step_start_rhs(sys, ws, t_new, y)
                    }
                    _ => self.start_from_last_iterate(sys, ws, t_new, y),
                }
                self.jac_fresh = false;
                self.jac_age = self.jac_age.saturating_add(1);
                let fac = self.accepted_step_factor(err, order_exp, facmax);
                // Hold the step (and the LU) when the change would be small.
                if !(1.0..1.2).contains(&fac) && !last {
                    self.h = h * fac;
                } else if !last {
                    self.h = h;
                }
                if let Some(i) = y.iter().position(|v| !v.is_finite()) {
                    return Err(IntegratorError::NonFinite { t: t_new, index: i });
                }
                return Ok(t_new);
            }
            self.stats.rejected += 1;
            self.after_reject = true;
            self.h = h * rejected_step_factor(err, order_exp);
        }
    }
}
