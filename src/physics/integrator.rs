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

// Stage updates index several parallel state arrays at once; index loops read clearest.
#![allow(clippy::needless_range_loop)]

use super::body::{BodyKind, BODY_STATE_LEN};
use super::contact::{GeometryMode, TrackState};
use super::newton_matrix::NewtonLu;
use super::system::{MultibodySystem, Workspace};
use serde::{Deserialize, Serialize};

/// Which integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorKind {
    /// TR-BDF2 ESDIRK, L-stable, order 2 (default).
    #[default]
    Trbdf2,
    /// Two-stage L-stable SDIRK, order 2.
    Sdirk2,
    /// Explicit Dormand-Prince 5(4).
    Dopri5,
}

impl IntegratorKind {
    /// All kinds, for comparison tables.
    pub const ALL: [IntegratorKind; 3] = [Self::Trbdf2, Self::Sdirk2, Self::Dopri5];

    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Trbdf2 => "trbdf2",
            Self::Sdirk2 => "sdirk2",
            Self::Dopri5 => "dopri5",
        }
    }
}

/// Error-control settings. The local error of each component is weighted by
/// `abs + rel * |y|` with the absolute part chosen by the component's physical kind.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tolerances {
    /// Relative tolerance (dimensionless). Default 1e-4.
    pub rel: f64,
    /// Absolute tolerance on positions, m. Default 1e-8 m (penetrations are ~1e-5 m).
    pub abs_position_m: f64,
    /// Absolute tolerance on quaternion components (≈ rad/2). Default 1e-7.
    pub abs_rotation: f64,
    /// Absolute tolerance on velocities, m/s. Default 1e-5 m/s.
    pub abs_velocity_m_s: f64,
    /// Absolute tolerance on angular velocities, rad/s. Default 1e-3 rad/s.
    pub abs_angular_velocity_rad_s: f64,
    /// Relative tolerance on each step's dissipated and drive work (TR-BDF2), dimensionless:
    /// the energy account's works are quadratures of the power terms like the state's own
    /// (the integrator's weights at the step's start, stage and end), and a step is accepted
    /// only if the embedded estimate of that quadrature's error is within this share of the
    /// step's work (+ [`ENERGY_ABS_TOLERANCE_J`]). Default 1e-3 (cases: 10 × `rel_tolerance`),
    /// so the account closes to well within 0.5 % of the dissipated work; 0 switches the check
    /// off.
    #[serde(default = "default_energy_rel")]
    pub energy_rel: f64,
}

/// Absolute floor of the per-step work tolerance, J (a picojoule per step needs no resolving).
pub const ENERGY_ABS_TOLERANCE_J: f64 = 1e-12;

fn default_energy_rel() -> f64 {
    1e-3
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            rel: 1e-4,
            abs_position_m: 1e-8,
            abs_rotation: 1e-7,
            abs_velocity_m_s: 1e-5,
            abs_angular_velocity_rad_s: 1e-3,
            energy_rel: default_energy_rel(),
        }
    }
}

impl Tolerances {
    /// All tolerances multiplied by `factor` (convergence studies halve them).
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            rel: self.rel * factor,
            abs_position_m: self.abs_position_m * factor,
            abs_rotation: self.abs_rotation * factor,
            abs_velocity_m_s: self.abs_velocity_m_s * factor,
            abs_angular_velocity_rad_s: self.abs_angular_velocity_rad_s * factor,
            energy_rel: self.energy_rel * factor,
        }
    }
}

/// How the implicit methods build the Newton matrix `I - h d J`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NewtonJacobian {
    /// `J` split into a contact-free part (finite differences of the right-hand side without
    /// contacts, no geometry) and the contacts' part, linearised analytically at every Newton
    /// iterate ([`MultibodySystem::contact_jacobian`]): the matrix follows each contact as it
    /// opens, closes, clamps or sticks inside the step (default).
    #[default]
    ContactAware,
    /// `J` by finite differences of the whole right-hand side, reused across steps
    /// (simplified Newton) and refreshed when Newton fails or slows.
    FiniteDifference,
}

/// How often the implicit methods compute the contact patches (overlap volume, area and
/// centroid) while solving one step.
///
/// The normal force depends only on the penetration of the deepest point and its rate, which
/// the support function gives exactly at every Newton iterate in both modes. The patch (where
/// the force acts and the slip is measured, and the area for the wear) is the expensive part of
/// a right-hand side: 55-65 % of it on the reference cases.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactPatches {
    /// Computed once per step, at the step's start (the accepted state, so the tracks and wear
    /// use exact patches); the Newton iterates of the step hold each patch's centroid fixed on
    /// its piece and compute the penetration afresh. A piece that starts touching inside the
    /// step gets its patch computed there. The contact-aware Newton's matrix already holds the
    /// centroid fixed. Default with the contact-aware Newton (the finite-difference Newton
    /// always computes every patch).
    #[default]
    PerStep,
    /// Computed at every evaluation (the Newton iterates too).
    PerIterate,
}

/// Integrator settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IntegratorSettings {
    /// Method.
    pub kind: IntegratorKind,
    /// Newton matrix of the implicit methods.
    #[serde(default)]
    pub newton: NewtonJacobian,
    /// Contact patches per step or per Newton iterate (contact-aware Newton only).
    #[serde(default)]
    pub patches: ContactPatches,
    /// Error tolerances.
    pub tolerances: Tolerances,
    /// First step tried, s.
    pub initial_step_s: f64,
    /// Largest step, s (also bounds how far excitation detail can be skipped).
    pub max_step_s: f64,
    /// Smallest step before giving up (divergence), s.
    pub min_step_s: f64,
}

impl Default for IntegratorSettings {
    fn default() -> Self {
        Self {
            kind: IntegratorKind::Trbdf2,
            newton: NewtonJacobian::default(),
            patches: ContactPatches::default(),
            tolerances: Tolerances::default(),
            initial_step_s: 1e-6,
            max_step_s: 1e-3,
            min_step_s: 1e-15,
        }
    }
}

/// Counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct IntegratorStats {
    /// Accepted steps.
    pub accepted: u64,
    /// Rejected steps (error or Newton failure).
    pub rejected: u64,
    /// Of the rejected steps, those whose Newton iteration failed.
    #[serde(default)]
    pub newton_failures: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Jacobian evaluations.
    pub jacobians: u64,
    /// LU factorisations.
    pub factorizations: u64,
    /// Right-hand sides without contacts (contact-free Jacobian part; no geometry).
    #[serde(default)]
    pub contact_free_rhs_evals: u64,
}

/// Where the steps go (development diagnostics, printed by `examples/step_profile`; not part
/// of a run's results), settle included. The limiting kinds are counted for the implicit
/// methods; rejections for every method.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepDiagnostics {
    /// Attempts that reached the error test, by step-size decade (`[k]` holds
    /// `1e-(k+1) <= h < 1e-k` s, the last entry everything shorter) and by the kind of state
    /// entry with the largest weighted error: 0 position, 1 rotation (quaternion),
    /// 2 velocity, 3 angular velocity.
    pub limiting_kind: [[u64; 4]; STEP_DECADES],
    /// Rejected attempts, `[0]` Newton failures and `[1]` error-test failures, by what the
    /// contacts did between the step start and the attempt's last evaluation: 0 a contact
    /// patch appeared (onset), 1 one vanished (separation), 2 a patch's IMPACT force switched
    /// between clamped at zero and positive, 3 none of these (same contact set).
    pub rejections_by_event: [[u64; 4]; 2],
}

/// Step-size decades in [`StepDiagnostics::limiting_kind`].
pub const STEP_DECADES: usize = 12;

/// Contact set of a track list: (contact, track, force > 0), sorted.
fn contact_set_into(tracks: &[TrackState], out: &mut Vec<(u32, u32, bool)>) {
    out.clear();
    out.extend(
        tracks
            .iter()
            .map(|t| (t.contact, t.track, t.normal_force > 0.0)),
    );
    out.sort_unstable_by_key(|&(c, k, _)| (c, k));
}

/// What changed from contact set `a` to `b`: 0 onset, 1 separation, 2 clamp switch, 3 nothing.
fn contact_change(a: &[(u32, u32, bool)], b: &[(u32, u32, bool)]) -> usize {
    let find = |set: &[(u32, u32, bool)], x: &(u32, u32, bool)| {
        set.binary_search_by_key(&(x.0, x.1), |&(c, k, _)| (c, k))
            .ok()
    };
    if b.iter().any(|x| find(a, x).is_none()) {
        0
    } else if a.iter().any(|x| find(b, x).is_none()) {
        1
    } else if a.iter().any(|x| find(b, x).is_some_and(|i| b[i].2 != x.2)) {
        2
    } else {
        3
    }
}

/// Why the integrator could not advance.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntegratorError {
    /// The step size fell below `min_step_s`.
    #[error("step size {h:e} s fell below the minimum at t = {t} s")]
    StepSizeUnderflow { t: f64, h: f64 },
    /// The state or its derivative became NaN or infinite.
    #[error("non-finite state at t = {t} s (state entry {index})")]
    NonFinite { t: f64, index: usize },
    /// The Newton matrix was singular.
    #[error("singular Newton matrix at t = {t} s")]
    Singular { t: f64 },
}

// TR-BDF2 coefficients (ESDIRK form).
const SQRT2: f64 = std::f64::consts::SQRT_2;
const TRB_GAMMA: f64 = 2.0 - SQRT2;
const TRB_D: f64 = 1.0 - SQRT2 / 2.0;
const TRB_W: f64 = SQRT2 / 4.0;
/// Stage-3 predictor weight of k1: the quadratic with slope k0 at t and k1 at t + γh reaches
/// `y + h ((1 - 1/(2γ)) k0 + 1/(2γ) k1)` at t + h (measured on the 2 s windows: -14 % / -10 %
/// right-hand sides on rattle box C / launcher against `y + h k1`).
const STAGE3_K1: f64 = 1.0 / (2.0 * TRB_GAMMA);
// SDIRK2 (Alexander 1977).
const SD_GAMMA: f64 = 1.0 - 1.0 / SQRT2;
/// A Newton failure with a Jacobian at most this many steps old is blamed on the step size
/// (an impact or a stick-slip reversal inside the step), not on the Jacobian: the step is cut
/// without refreshing it (measured alone on rattle box C: -50 % Jacobians, -20 % rejections).
const YOUNG_JACOBIAN_STEPS: u32 = 2;

/// Contact-aware Newton: a failed Newton iteration halves the step, and the next
/// `HOLD_STEPS_AFTER_NEWTON_FAILURE` accepted steps grow by at most `HELD_GROWTH` each, so the
/// step creeps back instead of jumping straight into the next contact event (measured on the
/// 2 s windows of rattle box C and the launcher: 0.25 without the hold 84 479 launcher
/// right-hand sides, 0.5 with a 20-step hold at 1.2 74 064, 7 868 -> 3 756 rejections).
const CONTACT_AWARE_NEWTON_CUT: f64 = 0.5;
const HOLD_STEPS_AFTER_NEWTON_FAILURE: u32 = 20;
const HELD_GROWTH: f64 = 1.2;

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
    /// Body owning each state entry.
    column_body: Vec<usize>,
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
    /// Contact-aware Newton: the LU holds `I - h d jac` (no contact term).
    lu_contact_free: bool,
    /// Contact-aware Newton: the `J` the LU was made from.
    lu_jac: Vec<f64>,
    /// Contraction estimate θ/(1-θ) of the last Newton solve.
    newton_eta: f64,
    /// The last Newton solve stopped after an update: `fz` is not f at the accepted point.
    newton_z_is_new: bool,
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
}

/// The power terms at a step's interior stage and the method's quadrature weights: the
/// energy account integrates each power as `h (w0 P(t) + w1 P(stage) + w2 P(t + h))`, the
/// weights with which the method advanced the state itself (TR-BDF2: `(√2/4, √2/4, 1 − √2/2)`),
/// so the works follow the same quadrature as the momenta.
#[derive(Debug, Clone, Default)]
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
        let v = || vec![0.0; n];
        Self {
            settings,
            n,
            abs_tol,
            column_body,
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
        }
    }

    /// The interior stage of the last accepted TR-BDF2 step (None for the other methods, whose
    /// works the account integrates by the trapezoid rule).
    pub fn interior_stage(&self) -> Option<&InteriorStage> {
        self.stage.as_ref()
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

    /// Entry `i` of `e` in units of its tolerance between states `y0` and `y1`.
    #[inline]
    fn weighted_entry(&self, i: usize, e: &[f64], y0: &[f64], y1: &[f64]) -> f64 {
        let rel = self.settings.tolerances.rel;
        e[i] / (self.abs_tol[i] + rel * y0[i].abs().max(y1[i].abs()))
    }

    fn weighted_norm(&self, e: &[f64], y0: &[f64], y1: &[f64]) -> f64 {
        let mut s = 0.0;
        for i in 0..self.n {
            let r = self.weighted_entry(i, e, y0, y1);
            s += r * r;
        }
        (s / self.n.max(1) as f64).sqrt()
    }

    /// The error norm of an implicit attempt of size `h`; with `diagnose`, counted by the kind
    /// of the entry that limits it.
    fn error_norm(&mut self, e: &[f64], y0: &[f64], h: f64) -> f64 {
        let norm = self.weighted_norm(e, y0, &self.ynew);
        if !self.diagnose {
            return norm;
        }
        // The first entry of largest weighted size.
        let mut worst = (0.0, 0);
        for i in 0..self.n {
            let r = self.weighted_entry(i, e, y0, &self.ynew).abs();
            if r > worst.0 {
                worst = (r, i);
            }
        }
        if let Some(&kind) = self.state_kind.get(worst.1) {
            let decade = (-h.log10()).floor().clamp(0.0, (STEP_DECADES - 1) as f64) as usize;
            self.diagnostics.limiting_kind[decade][usize::from(kind.min(3))] += 1;
        }
        norm
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

    fn contact_aware(&self) -> bool {
        self.settings.newton == NewtonJacobian::ContactAware
            && self.settings.kind != IntegratorKind::Dopri5
    }

    fn compute_jacobian(&mut self, sys: &MultibodySystem, ws: &mut Workspace, t: f64, y: &[f64]) {
        if self.contact_aware() {
            self.compute_contact_free_jacobian(sys, ws, t, y);
        } else {
            self.compute_full_jacobian(sys, ws, t, y);
        }
        self.stats.jacobians += 1;
        self.jac_fresh = true;
        self.jac_age = 0;
        self.lu_valid = false;
    }

    /// Forward differences of the right-hand side without contacts: rigid-body kinematics,
    /// gyroscopic terms and force elements (no overlap geometry, a small fraction of a full
    /// right-hand side each).
    fn compute_contact_free_jacobian(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
    ) {
        let n = self.n;
        ws.skip_contacts = true;
        let mut reference = std::mem::take(&mut self.tmp);
        sys.derivative(t, y, &mut reference, ws);
        self.jac_y.copy_from_slice(y);
        for j in 0..n {
            self.difference_column(sys, ws, t, y, j, &reference);
        }
        self.tmp = reference;
        ws.skip_contacts = false;
        self.stats.contact_free_rhs_evals += n as u64 + 1;
    }

    fn compute_full_jacobian(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
    ) {
        // Forward differences around (t, y); f(t, y) is k[0] (valid: FSAL). A velocity column
        // leaves every pose unchanged and a pose column moves one body: contacts whose poses
        // are unchanged replay the geometry (bit-identical forces, no overlap computation).
        let n = self.n;
        self.jac_y.copy_from_slice(y);
        let reference = std::mem::take(&mut self.k[0]);
        // Velocity columns first: the first records the geometry at the unperturbed poses.
        let mut recorded = false;
        // Velocity entries (kinds 2 and 3): their columns keep all poses.
        let kind = std::mem::take(&mut self.state_kind);
        let velocity_column = |j: usize| kind[j] >= 2;
        let velocity_first = (0..n)
            .filter(|&j| velocity_column(j))
            .chain((0..n).filter(|&j| !velocity_column(j)));
        for j in velocity_first {
            let mode = if !velocity_column(j) {
                if recorded {
                    GeometryMode::ReplayExcept(self.column_body[j])
                } else {
                    GeometryMode::Compute
                }
            } else if recorded {
                GeometryMode::Replay
            } else {
                recorded = true;
                GeometryMode::Record
            };
            ws.geometry.set_mode(mode);
            self.difference_column(sys, ws, t, y, j, &reference);
            self.stats.rhs_evals += 1;
        }
        self.state_kind = kind;
        self.k[0] = reference;
        ws.geometry.set_mode(GeometryMode::Compute);
    }

    /// Column `j` of `jac` by a forward difference of the derivative around `(t, y)`, whose
    /// value there is `reference`; `jac_y` holds `y` on entry and on return.
    fn difference_column(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        j: usize,
        reference: &[f64],
    ) {
        let n = self.n;
        let scale = self.abs_tol[j] * 1e3;
        let delta = 1.5e-8 * y[j].abs().max(scale);
        self.jac_y[j] = y[j] + delta;
        sys.derivative(t, &self.jac_y, &mut self.jac_f, ws);
        let col = &mut self.jac[j * n..(j + 1) * n];
        for i in 0..n {
            col[i] = (self.jac_f[i] - reference[i]) / delta;
        }
        self.jac_y[j] = y[j];
    }

    /// Contact-aware Newton: factors `I - h d (J_free + J_contacts(z))` with the contacts'
    /// Jacobian of the derivative just evaluated at the iterate `z` (`ws.linearize` set).
    /// Without active tracks the contact-free matrix is kept while `h d` is unchanged.
    fn factorize_at_iterate(
        &mut self,
        sys: &MultibodySystem,
        ws: &Workspace,
        hd: f64,
        t: f64,
    ) -> bool {
        if ws.linearizations.is_empty() {
            if self.lu_valid && self.lu_contact_free && self.lu_h == hd {
                return true;
            }
            self.lu_contact_free = true;
            self.lu_h = hd;
            self.stats.factorizations += 1;
            self.lu_valid = self.lu.factor_newton(&self.jac, hd);
            return self.lu_valid;
        }
        self.newton_jac.copy_from_slice(&self.jac);
        sys.contact_jacobian(&self.z, ws, &mut self.newton_jac);
        if self.lu_valid && !self.lu_contact_free && self.lu_h == hd {
            // Keep the factorisation while no entry of I - h d J moved by more than
            // LU_REUSE_CHANGE of its size (persistent contact; Newton still contracts).
            let close = self
                .newton_jac
                .iter()
                .zip(&self.lu_jac)
                .all(|(&a, &b)| hd * (a - b).abs() <= LU_REUSE_CHANGE * (1.0 + hd * b.abs()));
            if close {
                return true;
            }
        }
        self.lu_jac.copy_from_slice(&self.newton_jac);
        self.lu_h = hd;
        self.lu_contact_free = false;
        self.stats.factorizations += 1;
        self.lu_valid = self.lu.factor_newton(&self.newton_jac, hd);
        if !self.lu_valid {
            tracing::debug!(t, "singular contact-aware Newton matrix");
        }
        self.lu_valid
    }

    fn factorize(&mut self, h: f64, diag: f64, t: f64) -> Result<(), IntegratorError> {
        if !self.lu.factor_newton(&self.jac, h * diag) {
            self.lu_valid = false;
            return Err(IntegratorError::Singular { t });
        }
        self.lu_valid = true;
        self.lu_h = h;
        self.stats.factorizations += 1;
        Ok(())
    }

    fn solve_in_place(&mut self, v: &mut [f64]) {
        if self.lu_valid {
            self.lu.solve(v);
        }
    }

    /// Solves `z - h*d*f(ts, z) = rhs` by simplified Newton starting from `self.z`;
    /// stores f(ts, z) in k[out_k]. Returns false when Newton does not converge.
    fn newton(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        ts: f64,
        hd: f64,
        y0: &[f64],
        out_k: usize,
    ) -> bool {
        self.last_update = f64::INFINITY;
        let mut prev = f64::INFINITY;
        let contact_aware = self.contact_aware();
        let frozen = self.frozen_patches();
        self.newton_z_is_new = false;
        for iter in 0..10 {
            let mut fz = std::mem::take(&mut self.fz);
            ws.linearize = contact_aware;
            if frozen {
                ws.geometry.set_mode(GeometryMode::Frozen);
            }
            sys.derivative(ts, &self.z, &mut fz, ws);
            ws.geometry.set_mode(GeometryMode::Compute);
            ws.linearize = false;
            self.stats.rhs_evals += 1;
            for i in 0..self.n {
                self.tmp[i] = -(self.z[i] - hd * fz[i] - self.rhs[i]);
            }
            self.fz = fz;
            // The residual itself must be within tolerance once the updates have converged:
            // a stale Jacobian can make updates small while the equation is far from solved.
            let residual = self.weighted_norm(&self.tmp, y0, &self.z);
            if !residual.is_finite() {
                return false;
            }
            if iter > 0 && residual < 0.1 {
                let theta = if prev.is_finite() {
                    self.last_update / prev
                } else {
                    1.0
                };
                if theta < 0.9 || self.last_update < 1e-3 {
                    for i in 0..self.n {
                        self.k[out_k][i] = (self.z[i] - self.rhs[i]) / hd;
                    }
                    if iter > 3 {
                        self.jac_age = u32::MAX; // slow: refresh next step
                    }
                    return true;
                }
            }
            if contact_aware && !self.factorize_at_iterate(sys, ws, hd, ts) {
                return false;
            }
            let mut dz = std::mem::take(&mut self.tmp);
            self.solve_in_place(&mut dz);
            for i in 0..self.n {
                self.z[i] += dz[i];
            }
            let norm = self.weighted_norm(&dz, y0, &self.z);
            self.tmp = dz;
            if !norm.is_finite() {
                return false;
            }
            if contact_aware {
                // Hairer-Wanner II IV.8: with contraction θ the distance of the new iterate
                // to the solution is at most θ/(1-θ) times the update; at the first iteration
                // θ comes from the previous solve.
                let eta = if iter == 0 {
                    self.newton_eta.max(1e-2).powf(0.8)
                } else {
                    let theta = norm / self.last_update;
                    if theta >= 0.99 {
                        return false;
                    }
                    theta / (1.0 - theta)
                };
                if iter > 0 {
                    self.newton_eta = eta;
                }
                if eta * norm <= NEWTON_KAPPA {
                    for i in 0..self.n {
                        self.k[out_k][i] = (self.z[i] - self.rhs[i]) / hd;
                    }
                    self.newton_z_is_new = true;
                    return true;
                }
            }
            if iter > 1 && norm > 0.9 * self.last_update {
                return false;
            }
            prev = self.last_update;
            self.last_update = norm;
        }
        false
    }

    fn ensure_newton_matrix(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        h: f64,
        diag: f64,
    ) -> Result<(), IntegratorError> {
        if self.jac_age > 20 {
            self.compute_jacobian(sys, ws, t, y);
        }
        if self.contact_aware() {
            // Factored at every Newton iterate (`factorize_at_iterate`).
            return Ok(());
        }
        if !self.lu_valid || self.lu_h != h {
            self.factorize(h, diag, t)?;
        }
        Ok(())
    }

    fn attempt_trbdf2(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Result<Attempt, IntegratorError> {
        self.ensure_newton_matrix(sys, ws, t, y, h, TRB_D)?;
        let n = self.n;
        let hd = h * TRB_D;
        // Stage 2 (trapezoidal to t + γh).
        // Predictor: Taylor to second order, f' from the last two step starts (first order on
        // the first step). Only Newton's starting point: the stage solves the same equation.
        let gh = TRB_GAMMA * h;
        let curvature = if self.prev_h > 0.0 {
            0.5 * gh * gh / self.prev_h
        } else {
            0.0
        };
        for i in 0..n {
            self.rhs[i] = y[i] + hd * self.k[0][i];
            self.z[i] = y[i] + gh * self.k[0][i] + curvature * (self.k[0][i] - self.k_prev[i]);
        }
        if !self.newton(sys, ws, t + TRB_GAMMA * h, hd, y, 1) {
            return Ok(Attempt {
                err_norm: f64::INFINITY,
                newton_failed: true,
            });
        }
        self.capture_stage(sys, ws);
        // Stage 3 (BDF2 to t + h).
        for i in 0..n {
            self.rhs[i] = y[i] + h * TRB_W * (self.k[0][i] + self.k[1][i]);
            // Predictor: the quadratic through y with slopes k0 at t and k1 at t + γh.
            self.z[i] = y[i] + h * ((1.0 - STAGE3_K1) * self.k[0][i] + STAGE3_K1 * self.k[1][i]);
        }
        if !self.newton(sys, ws, t + h, hd, y, 2) {
            return Ok(Attempt {
                err_norm: f64::INFINITY,
                newton_failed: true,
            });
        }
        let b1 = (1.0 - TRB_W) / 3.0;
        let b2 = (3.0 * TRB_W + 1.0) / 3.0;
        let b3 = TRB_D / 3.0;
        for i in 0..n {
            self.ynew[i] = self.z[i];
            self.err[i] = h
                * ((TRB_W - b1) * self.k[0][i]
                    + (TRB_W - b2) * self.k[1][i]
                    + (TRB_D - b3) * self.k[2][i]);
        }
        let mut e = std::mem::take(&mut self.err);
        self.solve_in_place(&mut e);
        let norm = self.error_norm(&e, y, h);
        self.err = e;
        let energy = self.energy_error_norm(ws, h, [TRB_W - b1, TRB_W - b2, TRB_D - b3]);
        Ok(Attempt {
            err_norm: norm.max(energy),
            newton_failed: false,
        })
    }

    /// The energy account's quadrature error on this attempt over its tolerance
    /// ([`Tolerances::energy_rel`]): the embedded estimate `h Σ (w_i − b_i) P_i` of the
    /// dissipated and the drive power against the step's work. `ws.power` holds the attempt's
    /// last evaluation (its end).
    fn energy_error_norm(&self, ws: &Workspace, h: f64, err_weights: [f64; 3]) -> f64 {
        let rel = self.settings.tolerances.energy_rel;
        let Some(stage) = self.stage.as_ref().filter(|_| rel > 0.0) else {
            return 0.0;
        };
        let p = [self.power_start, stage.power, ws.power];
        let [w0, w1, w2] = stage.weights;
        let mut err = 0.0;
        let mut work = 0.0;
        for term in [
            |q: &super::system::PowerBalance| q.dissipation(),
            |q: &super::system::PowerBalance| q.drive,
        ] {
            let v = [term(&p[0]), term(&p[1]), term(&p[2])];
            err +=
                (h * (err_weights[0] * v[0] + err_weights[1] * v[1] + err_weights[2] * v[2])).abs();
            work += h * (w0 * v[0].abs() + w1 * v[1].abs() + w2 * v[2].abs());
        }
        err / (rel * work + ENERGY_ABS_TOLERANCE_J)
    }

    /// Keeps the power terms of the stage just solved (the workspace holds its last Newton
    /// iterate's evaluation).
    fn capture_stage(&mut self, sys: &MultibodySystem, ws: &Workspace) {
        let stage = self.stage.get_or_insert_with(InteriorStage::default);
        stage.weights = [TRB_W, TRB_W, TRB_D];
        stage.power = ws.power;
        stage.contacts.clear();
        stage.contacts.resize(sys.contacts.len(), [0.0; 2]);
        for tr in &ws.tracks {
            if let Some(c) = stage.contacts.get_mut(tr.contact as usize) {
                c[0] += tr.damping_power;
                c[1] += tr.friction_power;
            }
        }
    }

    fn attempt_sdirk2(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Result<Attempt, IntegratorError> {
        self.ensure_newton_matrix(sys, ws, t, y, h, SD_GAMMA)?;
        let n = self.n;
        let hg = h * SD_GAMMA;
        for i in 0..n {
            self.rhs[i] = y[i];
            self.z[i] = y[i] + hg * self.k[0][i];
        }
        if !self.newton(sys, ws, t + hg, hg, y, 1) {
            return Ok(Attempt {
                err_norm: f64::INFINITY,
                newton_failed: true,
            });
        }
        for i in 0..n {
            self.rhs[i] = y[i] + h * (1.0 - SD_GAMMA) * self.k[1][i];
            self.z[i] = y[i] + h * self.k[1][i];
        }
        if !self.newton(sys, ws, t + h, hg, y, 2) {
            return Ok(Attempt {
                err_norm: f64::INFINITY,
                newton_failed: true,
            });
        }
        for i in 0..n {
            self.ynew[i] = self.z[i];
            self.err[i] = hg * (self.k[2][i] - self.k[1][i]);
        }
        let mut e = std::mem::take(&mut self.err);
        self.solve_in_place(&mut e);
        let norm = self.error_norm(&e, y, h);
        self.err = e;
        Ok(Attempt {
            err_norm: norm,
            newton_failed: false,
        })
    }

    fn attempt_dopri5(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Attempt {
        const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
        const A: [[f64; 6]; 7] = [
            [0.0; 6],
            [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
            [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
            [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
            [
                19372.0 / 6561.0,
                -25360.0 / 2187.0,
                64448.0 / 6561.0,
                -212.0 / 729.0,
                0.0,
                0.0,
            ],
            [
                9017.0 / 3168.0,
                -355.0 / 33.0,
                46732.0 / 5247.0,
                49.0 / 176.0,
                -5103.0 / 18656.0,
                0.0,
            ],
            [
                35.0 / 384.0,
                0.0,
                500.0 / 1113.0,
                125.0 / 192.0,
                -2187.0 / 6784.0,
                11.0 / 84.0,
            ],
        ];
        const E: [f64; 7] = [
            71.0 / 57600.0,
            0.0,
            -71.0 / 16695.0,
            71.0 / 1920.0,
            -17253.0 / 339200.0,
            22.0 / 525.0,
            -1.0 / 40.0,
        ];
        let n = self.n;
        for s in 1..7 {
            for i in 0..n {
                let mut acc = y[i];
                for (j, a) in A[s].iter().enumerate().take(s) {
                    acc += h * a * self.k[j][i];
                }
                self.z[i] = acc;
            }
            let z = std::mem::take(&mut self.z);
            self.rhs(sys, ws, t + C[s] * h, &z, s);
            self.z = z;
        }
        for i in 0..n {
            self.ynew[i] = self.z[i];
            let mut e = 0.0;
            for (j, ej) in E.iter().enumerate() {
                e += ej * self.k[j][i];
            }
            self.err[i] = h * e;
        }
        let norm = self.weighted_norm(&self.err, y, &self.ynew);
        Attempt {
            err_norm: norm,
            newton_failed: false,
        }
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
        let (order_exp, facmax) = match self.settings.kind {
            IntegratorKind::Trbdf2 => (1.0 / 3.0, 4.0),
            IntegratorKind::Sdirk2 => (0.5, 4.0),
            IntegratorKind::Dopri5 => (0.2, 5.0),
        };
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
                IntegratorKind::Trbdf2 => self.attempt_trbdf2(sys, ws, t, y, h)?,
                IntegratorKind::Sdirk2 => self.attempt_sdirk2(sys, ws, t, y, h)?,
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
                // Explicit FSAL reuses the last stage. The implicit methods need f itself at
                // the new point, not the stage derivative (z - rhs)/(h d), which carries the
                // Newton error divided by h d and would poison the next step after a tiny
                // step. The last Newton iteration evaluated f exactly there (the accepted z is
                // the iterate whose residual passed); renormalising the quaternions changes no
                // force (frames are built from normalised quaternions) and scales q' = q ⊗ ω/2
                // by 1/|q|, applied here.
                std::mem::swap(&mut self.k_prev, &mut self.k[0]);
                self.prev_h = h;
                match self.settings.kind {
                    IntegratorKind::Dopri5 => self.k.swap(0, 6),
                    _ if self.newton_z_is_new || self.frozen_patches() => {
                        self.step_start_rhs(sys, ws, t_new, y)
                    }
                    _ => {
                        self.k[0].copy_from_slice(&self.fz);
                        sys.rescale_quaternion_rates(&self.ynew, &mut self.k[0]);
                        // The last Newton evaluation was at the accepted state.
                        self.power_start = ws.power;
                    }
                }
                self.jac_fresh = false;
                self.jac_age = self.jac_age.saturating_add(1);
                // No growth right after a rejection (Hairer-Wanner II IV.8): growing back
                // at once re-triggers the same failure (measured: -40 % rejections).
                let fmax = if self.after_reject {
                    1.0
                } else if self.hold_steps > 0 {
                    HELD_GROWTH
                } else {
                    facmax
                };
                self.hold_steps = self.hold_steps.saturating_sub(1);
                self.after_reject = false;
                let fac = if err == 0.0 {
                    fmax
                } else {
                    (0.9 * err.powf(-order_exp)).clamp(0.2, fmax)
                };
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
            let fac = if err.is_finite() {
                (0.9 * err.powf(-order_exp)).clamp(0.1, 0.9)
            } else {
                0.1
            };
            self.h = h * fac;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::contact_change;

    #[test]
    fn contact_changes_are_classified_onset_first() {
        let a = [(0, 1, true), (2, 0, false)];
        assert_eq!(contact_change(&a, &a), 3);
        assert_eq!(
            contact_change(&a, &[(0, 1, true), (1, 0, true), (2, 0, false)]),
            0
        );
        assert_eq!(contact_change(&a, &[(0, 1, true)]), 1);
        assert_eq!(contact_change(&a, &[(0, 1, true), (2, 0, true)]), 2);
        // A patch replaced by another is an onset (the new one) before a separation.
        assert_eq!(contact_change(&a, &[(0, 1, true), (3, 0, true)]), 0);
        assert_eq!(contact_change(&[], &[]), 3);
    }
}
