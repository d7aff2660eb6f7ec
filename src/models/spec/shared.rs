//! Specs shared by every model: material, contact and friction (ADAMS units), rounded boxes, the simulation settings.

use super::{finite3, non_negative, path, positive};
use crate::field_error::FieldError;
use crate::physics::friction::FrictionParams;
use crate::physics::impact::ImpactParams;
use crate::physics::step::StepKind;
use crate::wear::material::Material;
use serde::{Deserialize, Serialize};

/// ADAMS IMPACT contact parameters in ADAMS units (N, mm, s), eq. 2.1-2.3.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Stiffness k, N/mm^e. Tables 4.1, 5.2, 6.2: 1000.
    pub stiffness_n_per_mm_e: f64,
    /// Force exponent e, dimensionless (>= 1). Tables 4.1, 5.2, 6.2: 2.0.
    pub exponent: f64,
    /// Maximum damping c_max, N·s/mm. Tables 4.1, 5.2, 6.2: 500.
    pub damping_ns_per_mm: f64,
    /// Penetration d at which full damping is reached, mm. Tables 4.1, 5.2, 6.2: 0.01.
    pub penetration_depth_mm: f64,
    /// Damping ramp shape: `cycloidal` (eq. 2.4, default) or `cubic` (ADAMS STEP).
    #[serde(default)]
    pub step: StepKind,
}

impl ContactSpec {
    /// Thesis Table 4.1 / 5.2 / 6.2 default contact: k 1000 N/mm², e 2, c 500 N·s/mm, d 0.01 mm.
    pub const fn thesis_default() -> Self {
        Self {
            stiffness_n_per_mm_e: crate::thesis::IMPACT_STIFFNESS_N_PER_MM_E,
            exponent: crate::thesis::IMPACT_EXPONENT,
            damping_ns_per_mm: crate::thesis::IMPACT_DAMPING_NS_PER_MM,
            penetration_depth_mm: crate::thesis::IMPACT_PENETRATION_DEPTH_MM,
            step: StepKind::Cycloidal,
        }
    }

    /// Converts to SI [`ImpactParams`] (N/m^e, N·s/m, m).
    pub fn to_impact_params(&self) -> ImpactParams {
        let mut p = ImpactParams::from_adams_units(
            self.stiffness_n_per_mm_e,
            self.exponent,
            self.damping_ns_per_mm,
            self.penetration_depth_mm,
        );
        p.step = self.step;
        p
    }

    /// Field rules (k > 0, e >= 1, c >= 0, d > 0), reported under `prefix`.
    pub fn validate(&self, prefix: &str) -> Result<(), FieldError> {
        positive(prefix, "stiffness_n_per_mm_e", self.stiffness_n_per_mm_e)?;
        if !(self.exponent.is_finite() && self.exponent >= 1.0) {
            return Err(FieldError::new(
                path(prefix, "exponent"),
                format!("must be a finite number >= 1, got {}", self.exponent),
            ));
        }
        non_negative(prefix, "damping_ns_per_mm", self.damping_ns_per_mm)?;
        positive(prefix, "penetration_depth_mm", self.penetration_depth_mm)?;
        Ok(())
    }
}

/// A case's friction (the one [`FrictionParams`] type, written in mm/s in case files through
/// [`in_mm_per_s`](crate::physics::friction::in_mm_per_s)), checked with its own rules and
/// reported at `prefix` (e.g. `rattle_box.friction.mu_dynamic`).
pub fn validate_friction(friction: &FrictionParams, prefix: &str) -> Result<(), FieldError> {
    friction.validate().map_err(|e| e.at(prefix))
}

/// The material of a case's contacting parts: the one [`Material`] type, checked with its own
/// rules and reported at `prefix` (e.g. `rattle_box.material.poisson_ratio`).
pub fn validate_material(material: &Material, prefix: &str) -> Result<(), FieldError> {
    material
        .validate()
        .map_err(|crate::wear::WearError::Invalid(e)| e.at(prefix))
}

/// A box with rounded edges and corners (a convex contact piece, SPEC 2), given by its centre
/// in a stated frame, its outer half extents (including the roundover) along that frame's axes,
/// and its edge radius.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoundedBoxSpec {
    /// Centre, m, in the frame named where the box is used.
    pub centre_m: [f64; 3],
    /// Outer half extents along x, y, z, m (> edge radius).
    pub half_extents_m: [f64; 3],
    /// Edge and corner roundover radius, m (>= 0; thesis 5.4 and 6.5: small but not zero).
    pub edge_radius_m: f64,
}

impl RoundedBoxSpec {
    /// Field rules: finite centre, half extents > edge radius >= 0.
    pub fn validate(&self, prefix: &str) -> Result<(), FieldError> {
        finite3(prefix, "centre_m", self.centre_m)?;
        non_negative(prefix, "edge_radius_m", self.edge_radius_m)?;
        for h in self.half_extents_m {
            if !(h.is_finite() && h > self.edge_radius_m) {
                return Err(FieldError::new(
                    path(prefix, "half_extents_m"),
                    format!(
                        "each half extent must be finite and larger than edge_radius_m = {}, got {:?}",
                        self.edge_radius_m, self.half_extents_m
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Lowest y of the box, m (frame of the box).
    pub fn min_y_m(&self) -> f64 {
        self.centre_m[1] - self.half_extents_m[1]
    }

    /// Highest y of the box, m.
    pub fn max_y_m(&self) -> f64 {
        self.centre_m[1] + self.half_extents_m[1]
    }
}

/// A bounded planar face (a rectangle) of a kinematic body, derived from a spec.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanarFace {
    /// Name, e.g. `lip_top_left`.
    pub name: String,
    /// Centre of the rectangle, m, in the body frame.
    pub centre_m: [f64; 3],
    /// Unit outward normal (pointing out of the material, into the free space), body frame.
    pub normal: [f64; 3],
    /// Unit in-plane direction of the first half size, body frame.
    pub tangent: [f64; 3],
    /// Half size along `tangent`, m.
    pub half_length_m: f64,
    /// Half size along `normal x tangent`, m.
    pub half_width_m: f64,
}

/// Run-control settings shared by all models.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// Settle time with no excitation before the input starts, s (thesis 6.6.1: 2 s). Wear is
    /// not counted during the settle.
    #[serde(default = "default_settle_s")]
    pub settle_s: f64,
    /// Excited (recorded) duration after the settle, s.
    pub duration_s: f64,
    /// Integrator name (lower case; default `trbdf2`, a stiff L-stable method, SPEC 2).
    #[serde(default = "default_integrator")]
    pub integrator: String,
    /// Newton matrix of the implicit integrators: `contact_aware` (default; contacts
    /// linearised at every Newton iterate) or `finite_difference` (whole Jacobian by finite
    /// differences, reused across steps). Both solve the same equations to the same tolerance.
    #[serde(default)]
    pub newton_jacobian: crate::physics::integrator::NewtonJacobian,
    /// Contact patches (overlap centroid and area) of the contact-aware Newton: `per_step`
    /// (default; computed at each step's start, the penetration exact at every iterate) or
    /// `per_iterate` (computed at every Newton iterate).
    #[serde(default)]
    pub contact_patches: crate::physics::integrator::ContactPatches,
    /// Relative local error tolerance, dimensionless (0 < tol < 1).
    #[serde(default = "default_rel_tolerance")]
    pub rel_tolerance: f64,
    /// Absolute local error tolerance on positions, m (velocities are scaled by the integrator).
    #[serde(default = "default_abs_tolerance_m")]
    pub abs_tolerance_m: f64,
    /// Seed of every random draw in the case (random excitation), for determinism.
    #[serde(default)]
    pub seed: u64,
    /// Output (track sample) interval, s.
    #[serde(default = "default_record_interval_s")]
    pub record_interval_s: f64,
    /// Relative tolerance on each step's dissipated and drive work, dimensionless (the energy
    /// account's quadrature, docs/reference/models.md "Energy account"): each step's quadrature error
    /// within this share of its work plus a step's work at the run's mean power. Default 10 ×
    /// `rel_tolerance` (1e-3): the account closes within 0.5 % of the throughput
    /// (docs/journal/performance.md, twenty-first pass). 0 switches the check off (the account is
    /// still kept, by the same quadrature, and may not close).
    #[serde(default)]
    pub energy_rel_tolerance: Option<f64>,
    /// Which state entries the implicit integrators' local error test weighs: `full` (default;
    /// positions, rotations, velocities, angular velocities) or `positions` (poses only, the
    /// analogue of ADAMS WSTIFF-I3: velocities in conditional accuracy). The energy account's
    /// work test (`energy_rel_tolerance`) applies in both. docs/journal/performance.md, seventh pass.
    #[serde(default)]
    pub error_control: crate::physics::integrator::ErrorControl,
    /// Contact points per box edge (docs/reference/models.md "Contact formulation"): each face of a
    /// rounded box is resolved by `n × n` points whose stiffness shares sum to the thesis' face
    /// law. Default 5 (25 per face); more points resolve rocking and edge contacts more finely
    /// at a proportional cost in contact evaluation; range 2 (corners only) to 33.
    #[serde(default = "default_contact_points_per_edge")]
    pub contact_points_per_edge: usize,
    /// How rounded boxes' faces are resolved (docs/reference/models.md "Exact face contact"): `lattice`
    /// (`contact_points_per_edge` points per edge) or `exact` (each face integrated over its
    /// pressed polygon, exact for the IMPACT force, torque and stored energy at an integer
    /// exponent; `contact_points_per_edge` then unused by boxes). Absent: the model's own
    /// default, `exact` for launchers (the lattice is not converged there) and `lattice` for
    /// rattle boxes (converged at 3 points per edge, about a third of the exact contact's
    /// cost); docs/journal/performance.md, eighteenth pass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub face_contact: Option<crate::physics::contact::FaceContact>,
}

fn default_contact_points_per_edge() -> usize {
    crate::geometry::DEFAULT_POINTS_PER_EDGE
}

fn default_settle_s() -> f64 {
    2.0
}
fn default_integrator() -> String {
    "trbdf2".to_string()
}
fn default_rel_tolerance() -> f64 {
    1.0e-4
}
fn default_abs_tolerance_m() -> f64 {
    1.0e-9
}
fn default_record_interval_s() -> f64 {
    1.0e-4
}

impl SimulationSpec {
    /// Field rules: settle >= 0, duration > 0, tolerances in range, record interval in
    /// (0, duration], integrator a non-empty lower-case identifier.
    pub fn validate(&self, prefix: &str) -> Result<(), FieldError> {
        non_negative(prefix, "settle_s", self.settle_s)?;
        positive(prefix, "duration_s", self.duration_s)?;
        if !(self.rel_tolerance.is_finite() && self.rel_tolerance > 0.0 && self.rel_tolerance < 1.0)
        {
            return Err(FieldError::new(
                path(prefix, "rel_tolerance"),
                format!("must lie in (0, 1), got {}", self.rel_tolerance),
            ));
        }
        positive(prefix, "abs_tolerance_m", self.abs_tolerance_m)?;
        positive(prefix, "record_interval_s", self.record_interval_s)?;
        if let Some(e) = self.energy_rel_tolerance {
            if !(e.is_finite() && (0.0..1.0).contains(&e)) {
                return Err(FieldError::new(
                    path(prefix, "energy_rel_tolerance"),
                    format!("must lie in [0, 1), got {e}"),
                ));
            }
        }
        let (lo, hi) = crate::geometry::lattice::POINTS_PER_EDGE_RANGE;
        if !(lo..=hi).contains(&self.contact_points_per_edge) {
            return Err(FieldError::new(
                path(prefix, "contact_points_per_edge"),
                format!(
                    "must lie in [{lo}, {hi}], got {}",
                    self.contact_points_per_edge
                ),
            ));
        }
        if self.record_interval_s > self.duration_s {
            return Err(FieldError::new(
                path(prefix, "record_interval_s"),
                "must not exceed duration_s",
            ));
        }
        let ok = !self.integrator.is_empty()
            && self
                .integrator
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_' || c == '-');
        if !ok {
            return Err(FieldError::new(
                path(prefix, "integrator"),
                format!(
                    "must be a lower-case name such as \"trbdf2\", got {:?}",
                    self.integrator
                ),
            ));
        }
        Ok(())
    }
}
