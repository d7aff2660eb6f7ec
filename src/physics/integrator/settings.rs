//! What the integrator is asked to do (method, tolerances, Newton matrix, contact patches),
//! what it counts, and why it may stop.

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
/// `abs + rel * |y|` with the absolute part chosen by the component's physical kind. When the
/// system names a carrier (the kinematic body carrying the excitation:
/// [`MultibodySystem::with_carrier`](crate::physics::system::MultibodySystem::with_carrier)),
/// `y` in the relative part is each body's position and velocity relative to the carrier's
/// rigid motion, so a shaking rail does not loosen the tolerance on what slides on it; Newton's
/// convergence test keeps the world-frame weights. The local error norm is the largest over the
/// dynamic bodies of each body's root mean square, so every body is resolved on its own.
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
    /// step's work plus the work of a step as long at the run's mean power so far
    /// ([`WorkThroughput`](super::WorkThroughput); + [`ENERGY_ABS_TOLERANCE_J`]). Default 1e-3
    /// (cases: 10 × `rel_tolerance`), so the account closes to well within 0.5 % of the
    /// throughput; 0 switches the check off.
    #[serde(default = "default_energy_rel")]
    pub energy_rel: f64,
    /// Which state entries the implicit methods' local error test weighs (the energy account's
    /// work test is separate, [`Self::energy_rel`]). Default [`ErrorControl::Full`].
    #[serde(default)]
    pub error_control: ErrorControl,
}

/// Which entries of the state the local error test of the implicit methods (TR-BDF2, SDIRK2)
/// weighs. Newton's convergence test always weighs every entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ErrorControl {
    /// Every entry: positions, quaternions, velocities and angular velocities (default).
    #[default]
    Full,
    /// Positions and quaternions only, the analogue of ADAMS' WSTIFF-I3 (thesis 2.4): the
    /// velocities are solved to Newton's tolerance at every stage but their local error is not
    /// tested ("conditional accuracy in velocity"); a velocity error shows up in the next
    /// steps' positions, which are tested. The stiff IMPACT damping transients (m/c ~ 1e-7 s)
    /// are then damped by the L-stable method instead of resolved where they move no pose.
    Positions,
}

impl ErrorControl {
    /// Name as in the case files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Full => "full",
            Self::Positions => "positions",
        }
    }
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
            error_control: ErrorControl::Full,
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
            error_control: self.error_control,
        }
    }
}

/// How the implicit methods build the Newton matrix `I - h d J`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NewtonJacobian {
    /// `J` split into a contact-free part (finite differences of the right-hand side without
    /// contacts, no geometry) and the contacts' part, linearised analytically at every Newton
    /// iterate ([`MultibodySystem::contact_jacobian`](crate::physics::system::MultibodySystem::contact_jacobian)): the matrix follows each contact as it
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
