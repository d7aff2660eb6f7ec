//! What the three models ARE: typed, documented, validated specifications read from the case
//! files in `configs/` (thesis chapters 4, 5 and 6). How they move is built elsewhere from these.
//!
//! Conventions (SPEC 1, thesis 6.2.2): SI unless a field name says otherwise (`_mm`, `_deg`,
//! `_n_per_mm_e`); y is vertical (up, towards the vehicle), gravity is standard gravity along -y;
//! for the launcher the rail frame has its origin at the rail's centre of mass, z longitudinal
//! (firing direction), x transverse. Contact and friction parameters are written in the thesis'
//! ADAMS units (N, mm, s) and converted with [`ContactSpec::to_impact_params`] and
//! [`FrictionSpec::to_friction_params`]. Values the thesis does not give are engineering
//! estimates, flagged `estimate` in `docs/models.md`.

use crate::analysis::rattle_space::{self, LauncherDimensions, RattleSpaceError};
use crate::physics::friction::FrictionParams;
use crate::physics::impact::ImpactParams;
use crate::physics::step::StepKind;
use crate::units;
use serde::{Deserialize, Serialize};

/// A specification that breaks a rule. `field` is the dotted path of the offending field as it
/// appears in the case file (e.g. `launcher.rail.lip_thickness_m`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid `{field}`: {rule}")]
pub struct SpecError {
    /// Dotted path of the field in the case file.
    pub field: String,
    /// The rule broken, in words, with the value where useful.
    pub rule: String,
}

fn err(field: impl Into<String>, rule: impl Into<String>) -> SpecError {
    SpecError {
        field: field.into(),
        rule: rule.into(),
    }
}

fn path(prefix: &str, name: &str) -> String {
    if prefix.is_empty() {
        name.to_string()
    } else {
        format!("{prefix}.{name}")
    }
}

fn finite(prefix: &str, name: &str, v: f64) -> Result<(), SpecError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(err(
            path(prefix, name),
            format!("must be a finite number, got {v}"),
        ))
    }
}

fn positive(prefix: &str, name: &str, v: f64) -> Result<(), SpecError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(err(
            path(prefix, name),
            format!("must be a finite number > 0, got {v}"),
        ))
    }
}

fn non_negative(prefix: &str, name: &str, v: f64) -> Result<(), SpecError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(err(
            path(prefix, name),
            format!("must be a finite number >= 0, got {v}"),
        ))
    }
}

fn finite3(prefix: &str, name: &str, v: [f64; 3]) -> Result<(), SpecError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(err(
            path(prefix, name),
            format!("all components must be finite, got {v:?}"),
        ))
    }
}

fn unit3(prefix: &str, name: &str, v: [f64; 3]) -> Result<(), SpecError> {
    finite3(prefix, name, v)?;
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if (n - 1.0).abs() > 1e-6 {
        return Err(err(
            path(prefix, name),
            format!("must be a unit vector, |v| = {n}"),
        ));
    }
    Ok(())
}

/// Principal moments must be > 0 and satisfy the triangle inequality (a real rigid body).
fn inertia3(prefix: &str, name: &str, i: [f64; 3]) -> Result<(), SpecError> {
    if !i.iter().all(|x| x.is_finite() && *x > 0.0) {
        return Err(err(
            path(prefix, name),
            format!("all moments must be finite and > 0, got {i:?}"),
        ));
    }
    let tol = 1e-12 * (i[0] + i[1] + i[2]);
    if i[0] + i[1] < i[2] - tol || i[1] + i[2] < i[0] - tol || i[0] + i[2] < i[1] - tol {
        return Err(err(
            path(prefix, name),
            format!(
                "principal moments {i:?} break the triangle inequality (no real body has them)"
            ),
        ));
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Shared pieces
// ---------------------------------------------------------------------------------------------

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
            stiffness_n_per_mm_e: 1000.0,
            exponent: 2.0,
            damping_ns_per_mm: 500.0,
            penetration_depth_mm: 0.01,
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
    pub fn validate(&self, prefix: &str) -> Result<(), SpecError> {
        positive(prefix, "stiffness_n_per_mm_e", self.stiffness_n_per_mm_e)?;
        if !(self.exponent.is_finite() && self.exponent >= 1.0) {
            return Err(err(
                path(prefix, "exponent"),
                format!("must be a finite number >= 1, got {}", self.exponent),
            ));
        }
        non_negative(prefix, "damping_ns_per_mm", self.damping_ns_per_mm)?;
        positive(prefix, "penetration_depth_mm", self.penetration_depth_mm)?;
        Ok(())
    }
}

/// ADAMS Coulomb friction (eq. 4.5) with speeds in mm/s, as the thesis tables print them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSpec {
    /// Static coefficient mu_s. Tables 4.2, 5.2, 6.1: 0.1799.
    pub mu_static: f64,
    /// Dynamic coefficient mu_d. Tables 4.2, 5.2, 6.1: 0.1660.
    pub mu_dynamic: f64,
    /// Stiction transition speed v_s, mm/s. Tables 5.2, 6.1: 6.4634 (Table 4.2 rounds to 6.46).
    pub stiction_transition_speed_mm_per_s: f64,
    /// Friction transition speed v_d, mm/s (> v_s). Tables 4.2, 5.2, 6.1: 12.0.
    pub friction_transition_speed_mm_per_s: f64,
    /// Transition shape: `cycloidal` (eq. 4.6, default) or `cubic`.
    #[serde(default)]
    pub step: StepKind,
}

impl FrictionSpec {
    /// Thesis Table 5.2 / 6.1 (dry anodized 7075 on 7075).
    pub const fn thesis_default() -> Self {
        Self {
            mu_static: 0.1799,
            mu_dynamic: 0.1660,
            stiction_transition_speed_mm_per_s: 6.4634,
            friction_transition_speed_mm_per_s: 12.0,
            step: StepKind::Cycloidal,
        }
    }

    /// Converts to SI [`FrictionParams`] (speeds in m/s).
    pub fn to_friction_params(&self) -> FrictionParams {
        FrictionParams {
            mu_static: self.mu_static,
            mu_dynamic: self.mu_dynamic,
            stiction_transition_speed: units::mm(self.stiction_transition_speed_mm_per_s),
            friction_transition_speed: units::mm(self.friction_transition_speed_mm_per_s),
            step: self.step,
        }
    }

    /// Field rules of [`FrictionParams::validate`], reported with this struct's field names.
    pub fn validate(&self, prefix: &str) -> Result<(), SpecError> {
        non_negative(prefix, "mu_static", self.mu_static)?;
        non_negative(prefix, "mu_dynamic", self.mu_dynamic)?;
        positive(
            prefix,
            "stiction_transition_speed_mm_per_s",
            self.stiction_transition_speed_mm_per_s,
        )?;
        finite(
            prefix,
            "friction_transition_speed_mm_per_s",
            self.friction_transition_speed_mm_per_s,
        )?;
        if self.friction_transition_speed_mm_per_s <= self.stiction_transition_speed_mm_per_s {
            return Err(err(
                path(prefix, "friction_transition_speed_mm_per_s"),
                "must be greater than stiction_transition_speed_mm_per_s",
            ));
        }
        Ok(())
    }
}

/// Bulk material of the contacting parts. Default 7075-T73, anodized (thesis 4.2.1, SPEC 3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Density, kg/m³. 7075-T73: 2810.
    pub density_kg_per_m3: f64,
    /// Yield strength S_y, Pa. 7075-T73: 435 MPa (the wear-law cutoff is 2 S_y, eq. 3.11).
    pub yield_strength_pa: f64,
    /// Young's modulus E, Pa. 7075-T73: 72 GPa.
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio. 7075-T73: 0.33.
    pub poisson_ratio: f64,
    /// Brinell hardness, HB. 7075-T73: 135 (used to split wear between bodies).
    pub brinell_hardness: f64,
}

impl Default for MaterialSpec {
    /// 7075-T73, from the one source of the thesis' material
    /// ([`Material::aluminium_7075_t73`](crate::wear::material::Material::aluminium_7075_t73)).
    fn default() -> Self {
        let m = crate::wear::material::Material::aluminium_7075_t73();
        Self {
            density_kg_per_m3: m.density_kg_m3,
            yield_strength_pa: m.yield_strength_pa,
            youngs_modulus_pa: m.youngs_modulus_pa,
            poisson_ratio: m.poisson_ratio,
            brinell_hardness: m.brinell_hardness_hb,
        }
    }
}

impl MaterialSpec {
    /// Field rules: all > 0, Poisson's ratio in (-1, 0.5).
    pub fn validate(&self, prefix: &str) -> Result<(), SpecError> {
        positive(prefix, "density_kg_per_m3", self.density_kg_per_m3)?;
        positive(prefix, "yield_strength_pa", self.yield_strength_pa)?;
        positive(prefix, "youngs_modulus_pa", self.youngs_modulus_pa)?;
        positive(prefix, "brinell_hardness", self.brinell_hardness)?;
        if !(self.poisson_ratio.is_finite()
            && self.poisson_ratio > -1.0
            && self.poisson_ratio < 0.5)
        {
            return Err(err(
                path(prefix, "poisson_ratio"),
                format!("must lie in (-1, 0.5), got {}", self.poisson_ratio),
            ));
        }
        Ok(())
    }
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
    pub fn validate(&self, prefix: &str) -> Result<(), SpecError> {
        finite3(prefix, "centre_m", self.centre_m)?;
        non_negative(prefix, "edge_radius_m", self.edge_radius_m)?;
        for h in self.half_extents_m {
            if !(h.is_finite() && h > self.edge_radius_m) {
                return Err(err(
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
    /// account's quadrature, docs/models.md "Energy account"). Default 10 × `rel_tolerance`
    /// (1e-3): the account closes within 0.5 % of the dissipated work; on the rattle box it
    /// costs 2.2x the steps of no work control (docs/performance.md). 0 switches the check
    /// off (the account is still kept, by the same quadrature, and may not close).
    #[serde(default)]
    pub energy_rel_tolerance: Option<f64>,
    /// Contact points per box edge (docs/models.md "Contact formulation"): each face of a
    /// rounded box is resolved by `n × n` points whose stiffness shares sum to the thesis' face
    /// law. Default 5 (25 per face); more points resolve rocking and edge contacts more finely
    /// at a proportional cost in contact evaluation; range 2 (corners only) to 33.
    #[serde(default = "default_contact_points_per_edge")]
    pub contact_points_per_edge: usize,
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
    pub fn validate(&self, prefix: &str) -> Result<(), SpecError> {
        non_negative(prefix, "settle_s", self.settle_s)?;
        positive(prefix, "duration_s", self.duration_s)?;
        if !(self.rel_tolerance.is_finite() && self.rel_tolerance > 0.0 && self.rel_tolerance < 1.0)
        {
            return Err(err(
                path(prefix, "rel_tolerance"),
                format!("must lie in (0, 1), got {}", self.rel_tolerance),
            ));
        }
        positive(prefix, "abs_tolerance_m", self.abs_tolerance_m)?;
        positive(prefix, "record_interval_s", self.record_interval_s)?;
        if let Some(e) = self.energy_rel_tolerance {
            if !(e.is_finite() && (0.0..1.0).contains(&e)) {
                return Err(err(
                    path(prefix, "energy_rel_tolerance"),
                    format!("must lie in [0, 1), got {e}"),
                ));
            }
        }
        let (lo, hi) = crate::geometry::lattice::POINTS_PER_EDGE_RANGE;
        if !(lo..=hi).contains(&self.contact_points_per_edge) {
            return Err(err(
                path(prefix, "contact_points_per_edge"),
                format!(
                    "must lie in [{lo}, {hi}], got {}",
                    self.contact_points_per_edge
                ),
            ));
        }
        if self.record_interval_s > self.duration_s {
            return Err(err(
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
            return Err(err(
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

// ---------------------------------------------------------------------------------------------
// Chapter 4: persistent contact fixture
// ---------------------------------------------------------------------------------------------

/// Prescribed rotation of the upper fixture about the vertical axis (thesis 4.3: "an angular
/// motion was imposed on the cylindrical joint", by an equation or a spline of test data).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum PrescribedRotation {
    /// `theta(t) = amplitude sin(2 pi f t)`: oscillatory persistent contact (thesis 4.2).
    Oscillating {
        /// Angle amplitude, degrees.
        amplitude_deg: f64,
        /// Frequency, Hz.
        frequency_hz: f64,
    },
    /// `theta(t) = rate t`: continuous rotation.
    ConstantRate {
        /// Angular rate, degrees per second.
        rate_deg_per_s: f64,
    },
}

impl PrescribedRotation {
    /// Peak angular speed, rad/s.
    pub fn peak_rate_rad_per_s(&self) -> f64 {
        match *self {
            Self::Oscillating {
                amplitude_deg,
                frequency_hz,
            } => amplitude_deg.to_radians() * 2.0 * std::f64::consts::PI * frequency_hz,
            Self::ConstantRate { rate_deg_per_s } => rate_deg_per_s.abs().to_radians(),
        }
    }

    fn validate(&self, prefix: &str) -> Result<(), SpecError> {
        match *self {
            Self::Oscillating {
                amplitude_deg,
                frequency_hz,
            } => {
                positive(prefix, "amplitude_deg", amplitude_deg)?;
                positive(prefix, "frequency_hz", frequency_hz)
            }
            Self::ConstantRate { rate_deg_per_s } => {
                finite(prefix, "rate_deg_per_s", rate_deg_per_s)?;
                if rate_deg_per_s == 0.0 {
                    return Err(err(path(prefix, "rate_deg_per_s"), "must not be zero"));
                }
                Ok(())
            }
        }
    }
}

/// Persistent contact fixture, thesis chapter 4 (Figures 4.2-4.5): three 7075 pads (upper
/// samples) locked to an upper fixture that has a cylindrical joint to ground about the vertical
/// (y) axis, pressed by a constant vertical load on a square 7075 coupon (lower sample) locked to
/// the ground-fixed cup; the fixture's rotation is prescribed. Pads sit at 120° spacing at radius
/// `mean_radius_m`. Used for eq. 4.1-4.4 (friction) and eq. 4.16-4.18 (K(sigma)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PersistentContactSpec {
    /// Pad and coupon material (thesis 4.2.1: 7075, anodized MIL-A-8625 Type II Class 1).
    #[serde(default)]
    pub material: MaterialSpec,
    /// Number of pads (thesis 4.2: 3).
    pub pad_count: u32,
    /// Pad size, m: radial (x), height (y), tangential (z). Estimate (not in the thesis).
    pub pad_size_m: [f64; 3],
    /// Pad edge roundover, m. Estimate.
    pub pad_edge_radius_m: f64,
    /// r_avg: radius from the rotation axis to the pad centroids, m (eq. 4.1, 4.4, 4.11).
    /// Estimate.
    pub mean_radius_m: f64,
    /// Side of the square coupon (lower sample), m. Estimate.
    pub coupon_side_m: f64,
    /// Coupon thickness, m. Estimate.
    pub coupon_thickness_m: f64,
    /// Mass of the moving upper fixture with its pads, kg. Estimate.
    pub upper_fixture_mass_kg: f64,
    /// J: polar moment of inertia of the moving fixture about the rotation axis, kg·m²
    /// (eq. 4.1, 4.3). Estimate.
    pub polar_inertia_kg_m2: f64,
    /// Constant vertical test load N pressing the pads on the coupon, N (thesis 4.3). Estimate.
    pub normal_load_n: f64,
    /// Prescribed rotation of the upper fixture.
    pub rotation: PrescribedRotation,
    /// Pad-coupon contact, Table 4.1.
    pub contact: ContactSpec,
    /// Friction, Table 4.2.
    pub friction: FrictionSpec,
}

impl PersistentContactSpec {
    /// Nominal contact pressure `N / (pad_count * pad face area)`, Pa (the sigma of K(sigma),
    /// eq. 4.7, for flat pads carrying equal shares, thesis Figure 4.6).
    pub fn nominal_pressure_pa(&self) -> f64 {
        self.normal_load_n / (self.pad_count as f64 * self.pad_size_m[0] * self.pad_size_m[2])
    }

    /// Peak bulk slip speed `thetadot_max r_avg`, m/s (eq. 4.4).
    pub fn peak_slip_speed_m_per_s(&self) -> f64 {
        self.rotation.peak_rate_rad_per_s() * self.mean_radius_m
    }

    /// Mass of one pad, kg (density x volume).
    pub fn pad_mass_kg(&self) -> f64 {
        self.material.density_kg_per_m3 * self.pad_size_m.iter().product::<f64>()
    }

    /// Field rules, plus: pads stay on the coupon at every angle (`r_avg` + pad half diagonal
    /// <= half coupon side) and do not overlap each other.
    pub fn validate(&self, prefix: &str) -> Result<(), SpecError> {
        self.material.validate(&path(prefix, "material"))?;
        if self.pad_count == 0 {
            return Err(err(path(prefix, "pad_count"), "must be >= 1 (thesis: 3)"));
        }
        for s in self.pad_size_m {
            if !(s.is_finite() && s > 2.0 * self.pad_edge_radius_m) {
                return Err(err(
                    path(prefix, "pad_size_m"),
                    "each size must be finite and larger than twice pad_edge_radius_m",
                ));
            }
        }
        non_negative(prefix, "pad_edge_radius_m", self.pad_edge_radius_m)?;
        positive(prefix, "mean_radius_m", self.mean_radius_m)?;
        positive(prefix, "coupon_side_m", self.coupon_side_m)?;
        positive(prefix, "coupon_thickness_m", self.coupon_thickness_m)?;
        positive(prefix, "upper_fixture_mass_kg", self.upper_fixture_mass_kg)?;
        positive(prefix, "polar_inertia_kg_m2", self.polar_inertia_kg_m2)?;
        positive(prefix, "normal_load_n", self.normal_load_n)?;
        self.rotation.validate(&path(prefix, "rotation"))?;
        self.contact.validate(&path(prefix, "contact"))?;
        self.friction.validate(&path(prefix, "friction"))?;
        let half_diag = 0.5 * self.pad_size_m[0].hypot(self.pad_size_m[2]);
        if self.mean_radius_m + half_diag > 0.5 * self.coupon_side_m {
            return Err(err(
                path(prefix, "coupon_side_m"),
                format!(
                    "pads would run off the coupon: mean_radius_m + pad half diagonal = {} m > \
                     half the coupon side",
                    self.mean_radius_m + half_diag
                ),
            ));
        }
        if self.pad_count > 1 {
            let spacing =
                2.0 * self.mean_radius_m * (std::f64::consts::PI / self.pad_count as f64).sin();
            if spacing < 2.0 * half_diag {
                return Err(err(
                    path(prefix, "mean_radius_m"),
                    "pads at this radius would overlap each other",
                ));
            }
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// Chapter 5: rattle box
// ---------------------------------------------------------------------------------------------

/// Table 5.1 enclosure (tube inner) sides, inches, for cases A-D (1 in cube).
pub const TABLE_5_1_TUBE_SIDES_IN: [(&str, f64); 4] =
    [("A", 2.0), ("B", 1.5), ("C", 1.25), ("D", 1.125)];

/// Rattle box, thesis chapter 5 (Figures 5.1-5.4): an aluminium cube free inside a long square
/// tube with capped ends; the tube is driven (kinematic) by the shaker. Frame: tube axis along z,
/// y vertical (gravity -y), x transverse (the excitation axis of Figures 5.1-5.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RattleBoxSpec {
    /// Table 5.1 case letter (`A`..`D`), or another label for a custom enclosure.
    pub case: String,
    /// Cube and tube material (thesis 5.3.1: anodized aluminium, as chapter 4).
    #[serde(default)]
    pub material: MaterialSpec,
    /// Cube side, m (thesis 5.3.2: 1 in = 0.0254 m).
    pub cube_side_m: f64,
    /// Cube mass, kg. Omitted: density x side³ (the thesis matches the real fixture's mass but
    /// does not state it; 7075 at 2810 kg/m³ gives 46.05 g).
    #[serde(default)]
    pub cube_mass_kg: Option<f64>,
    /// Tube inner side, m (Table 5.1: 2.0, 1.5, 1.25, 1.125 in).
    pub tube_inner_side_m: f64,
    /// Tube inner length between the end caps, m. Estimate ("very long", thesis 5.2).
    pub tube_length_m: f64,
    /// Whether the tube ends are capped (thesis 5.3.1: yes), i.e. two end faces are contacts.
    #[serde(default = "default_true")]
    pub end_caps: bool,
    /// Edge roundover of cube and tube, m (thesis 5.4: 0.02 in = 0.508 mm).
    pub edge_radius_m: f64,
    /// Cube-tube contact, Table 5.2.
    pub contact: ContactSpec,
    /// Cube-tube friction, Table 5.2.
    pub friction: FrictionSpec,
}

fn default_true() -> bool {
    true
}

impl RattleBoxSpec {
    /// Cube mass, kg: the given value, else density x side³.
    pub fn cube_mass_kg(&self) -> f64 {
        self.cube_mass_kg
            .unwrap_or(self.material.density_kg_per_m3 * self.cube_side_m.powi(3))
    }

    /// Cube principal moment of inertia about its centre, kg·m²: `m a² / 6` (solid cube; the
    /// roundover changes it by under 1 %).
    pub fn cube_inertia_kg_m2(&self) -> f64 {
        self.cube_mass_kg() * self.cube_side_m * self.cube_side_m / 6.0
    }

    /// Rattle space, eq. 5.1-5.2.
    pub fn rattle_space(&self) -> Result<f64, RattleSpaceError> {
        rattle_space::rattle_space_square(self.cube_side_m, self.tube_inner_side_m)
    }

    /// Field rules, plus: the cube fits the tube (in section and length), the roundover is
    /// smaller than half the cube side, and a Table 5.1 letter uses Table 5.1's tube side.
    pub fn validate(&self, prefix: &str) -> Result<(), SpecError> {
        self.material.validate(&path(prefix, "material"))?;
        positive(prefix, "cube_side_m", self.cube_side_m)?;
        if let Some(m) = self.cube_mass_kg {
            positive(prefix, "cube_mass_kg", m)?;
        }
        positive(prefix, "tube_inner_side_m", self.tube_inner_side_m)?;
        positive(prefix, "tube_length_m", self.tube_length_m)?;
        non_negative(prefix, "edge_radius_m", self.edge_radius_m)?;
        if self.edge_radius_m >= 0.5 * self.cube_side_m {
            return Err(err(
                path(prefix, "edge_radius_m"),
                "must be smaller than half the cube side",
            ));
        }
        if self.tube_inner_side_m < self.cube_side_m {
            return Err(err(
                path(prefix, "tube_inner_side_m"),
                format!(
                    "interference: tube inner side {} m is smaller than the cube side {} m",
                    self.tube_inner_side_m, self.cube_side_m
                ),
            ));
        }
        if self.tube_length_m < self.cube_side_m {
            return Err(err(
                path(prefix, "tube_length_m"),
                "must be at least the cube side",
            ));
        }
        if let Some((_, side_in)) = TABLE_5_1_TUBE_SIDES_IN
            .iter()
            .find(|(c, _)| *c == self.case)
        {
            if (self.tube_inner_side_m - units::inch(*side_in)).abs() > 1e-6 {
                return Err(err(
                    path(prefix, "tube_inner_side_m"),
                    format!(
                        "case {} of Table 5.1 has a {side_in} in ({} m) tube; use another case \
                         label for a custom enclosure",
                        self.case,
                        units::inch(*side_in)
                    ),
                ));
            }
        }
        self.contact.validate(&path(prefix, "contact"))?;
        self.friction.validate(&path(prefix, "friction"))?;
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// Chapter 6: launcher
// ---------------------------------------------------------------------------------------------

/// Rail extrusion layout (kinematic body, driven at its centre of mass, thesis 6.5). The channel
/// cross-section comes from [`LauncherDimensions`]; this places it in the rail frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RailSpec {
    /// Length of the channel along z, m. Estimate.
    pub channel_length_m: f64,
    /// z of the channel's mid-length in the rail frame, m. Estimate.
    pub channel_centre_z_m: f64,
    /// y of the lip top faces (the chamber floor the shoe heads rest on), m. Estimate.
    pub lip_top_y_m: f64,
    /// Lip thickness (slot depth), m; the rail's bottom face is at `lip_top_y_m` minus this.
    /// Must be smaller than the shoes' neck height. Estimate.
    pub lip_thickness_m: f64,
    /// Half width of the rail's bottom face (from the channel centreline to the outer edge), m.
    /// Estimate.
    pub bottom_half_width_m: f64,
}

/// The missile body (rigid, carrying the shoes and the front bearing pad). Missile frame: origin
/// at its centre of mass, axes parallel to the rail frame at assembly (z along the missile axis).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissileSpec {
    /// Mass, kg. SPEC 4: about 45 kg (Hellfire class; not given in the thesis).
    pub mass_kg: f64,
    /// Body length, m. SPEC 4: 1.63 m.
    pub length_m: f64,
    /// Body diameter, m. SPEC 4: 0.178 m.
    pub diameter_m: f64,
    /// Principal moments (x, y, z) about the centre of mass, kg·m². Omitted: a solid cylinder of
    /// the given mass, length and diameter (estimate; the thesis gives no inertia).
    #[serde(default)]
    pub inertia_kg_m2: Option<[f64; 3]>,
    /// z of the missile's centre of mass in the rail frame at assembly, m. Estimate. (x is 0;
    /// y follows from the rear shoe resting on the lips, [`LauncherSpec::missile_com_in_rail_m`].)
    pub com_z_in_rail_m: f64,
}

impl MissileSpec {
    /// Principal moments, kg·m²: the given ones or a solid cylinder's
    /// (`I_xx = I_yy = m (3 r² + L²) / 12`, `I_zz = m r² / 2`).
    pub fn inertia_kg_m2(&self) -> [f64; 3] {
        self.inertia_kg_m2.unwrap_or_else(|| {
            let r = 0.5 * self.diameter_m;
            let transverse = self.mass_kg * (3.0 * r * r + self.length_m * self.length_m) / 12.0;
            [transverse, transverse, 0.5 * self.mass_kg * r * r]
        })
    }
}

/// A shoe (mid or rear), rigidly fastened to the missile (thesis 6.5: locked joints). Its T-head
/// and neck cross-sections come from [`LauncherDimensions`]; this places it on the missile.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShoeSpec {
    /// Centre of the head's underside (the face that rests on the rail lips), m, missile frame.
    pub head_base_in_missile_m: [f64; 3],
    /// Shoe length along z, m. Estimate.
    pub length_m: f64,
    /// Edge roundover, m (thesis 6.5: "a small roundover specified in the design"). Estimate.
    pub edge_radius_m: f64,
    /// Extra contact piece, missile frame: the mid shoe's front protrusion that enlarges the
    /// latch interface (thesis 6.2.3). None for the rear shoe.
    #[serde(default)]
    pub protrusion: Option<RoundedBoxSpec>,
}

impl ShoeSpec {
    /// The T-head as a rounded box in the missile frame: width `A`, thickness `K`, this length.
    pub fn head_box(&self, d: &LauncherDimensions) -> RoundedBoxSpec {
        let t = units::mm(d.k_shoe_mm);
        let b = self.head_base_in_missile_m;
        RoundedBoxSpec {
            centre_m: [b[0], b[1] + 0.5 * t, b[2]],
            half_extents_m: [0.5 * units::mm(d.a_shoe_mm), 0.5 * t, 0.5 * self.length_m],
            edge_radius_m: self.edge_radius_m,
        }
    }

    /// The neck as a rounded box in the missile frame: width `mean(N, O)`, height
    /// `mean(F-G, H-I, J-K, L-M)`, below the head.
    pub fn neck_box(&self, d: &LauncherDimensions) -> RoundedBoxSpec {
        let h = units::mm(d.mean_neck_height_mm());
        let b = self.head_base_in_missile_m;
        RoundedBoxSpec {
            centre_m: [b[0], b[1] - 0.5 * h, b[2]],
            half_extents_m: [
                0.5 * units::mm(d.mean_neck_width_mm()),
                0.5 * h,
                0.5 * self.length_m,
            ],
            edge_radius_m: self.edge_radius_m,
        }
    }

    /// Centre of the head's top face, missile frame, m (where the leaf spring bears).
    pub fn head_top_in_missile_m(&self, d: &LauncherDimensions) -> [f64; 3] {
        let b = self.head_base_in_missile_m;
        [b[0], b[1] + units::mm(d.k_shoe_mm), b[2]]
    }
}

/// Joint of the latch on the rail.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LatchJoint {
    /// Rotation about and translation along the hinge axis (thesis 6.5).
    Cylindrical,
    /// Rotation only (translation locked): for builders that prefer to bound the axial slide.
    Revolute,
}

/// The latch rocker (thesis 6.2.3, Figures 6.9-6.10): pivots on the rail, its tooth bears on the
/// mid shoe's front to retain the missile longitudinally, and rests on the rail lips (the
/// latch-rail contact stops its rotation). Latch frame: origin at its centre of mass, axes
/// parallel to the rail frame at assembly.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatchSpec {
    /// Mass, kg. Estimate.
    pub mass_kg: f64,
    /// Principal moments about the centre of mass along the latch frame axes, kg·m². Estimate.
    pub inertia_kg_m2: [f64; 3],
    /// Centre of mass in the rail frame at assembly, m. Estimate.
    pub com_in_rail_m: [f64; 3],
    /// A point on the hinge axis, rail frame, m. Estimate.
    pub hinge_point_in_rail_m: [f64; 3],
    /// Hinge axis direction (unit), rail frame. Transverse (x) by the latch's function.
    pub hinge_axis: [f64; 3],
    /// Joint type (thesis 6.5: cylindrical).
    pub joint: LatchJoint,
    /// The tooth (contact piece bearing on the mid shoe and on the rail), latch frame.
    pub tooth: RoundedBoxSpec,
}

impl LatchSpec {
    /// Tooth centre in the rail frame at assembly, m.
    pub fn tooth_centre_in_rail_m(&self) -> [f64; 3] {
        add3(self.com_in_rail_m, self.tooth.centre_m)
    }
}

fn add3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn dist3(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The latch coil springs (two concentric springs, thesis 6.2.3, modelled as one two-point coil
/// spring, thesis 6.5). Compression spring: the force pushes the two points apart,
/// `F = preload + k (L_installed - L) - c dL/dt`, with `L_installed` the distance at assembly.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoilSpringSpec {
    /// Combined stiffness k, N/m. Estimate.
    pub stiffness_n_per_m: f64,
    /// Damping c, N·s/m. Estimate.
    pub damping_ns_per_m: f64,
    /// Force at the installed length, N (> 0: compressed at assembly). Estimate.
    pub preload_n: f64,
    /// Attachment on the rail (latch cover), rail frame, m. Estimate.
    pub point_on_rail_m: [f64; 3],
    /// Attachment on the latch, latch frame, m. Estimate.
    pub point_on_latch_m: [f64; 3],
}

/// A constant point force on the missile (a double-barrel spring, thesis 6.5: "modeled as
/// constant point forces because of the small displacements").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantForceSpec {
    /// Label, e.g. `double_barrel_left`.
    pub name: String,
    /// Force magnitude, N. Estimate.
    pub force_n: f64,
    /// Point of application on the mid shoe, missile frame, m. Estimate.
    pub point_in_missile_m: [f64; 3],
    /// Direction (unit), fixed in the rail frame: +z, opposite the latch (thesis 6.2.3).
    pub direction_in_rail: [f64; 3],
}

/// The rear leaf spring (thesis 6.2.3, 6.5): fixed to the rail above the rear shoe, it presses
/// the shoe head down onto the lips. Modelled as a vertical one-sided point force with a smooth
/// engagement: with `c` the compression (shoe head top above the spring's free tip),
/// `F_y = -STEP(c, 0, 0, s, 1) (preload + k c)` on the shoe for `c > 0`, zero otherwise, `s` the
/// engagement smoothing. The free tip hangs `reach_below_roof_m` below the chamber roof, so the
/// static engagement depends on the rail's vertical clearance: it may not engage when static for
/// a loose rail (thesis 6.3.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeafSpringSpec {
    /// Stiffness k, N/m. Estimate.
    pub stiffness_n_per_m: f64,
    /// Force at first touch (c = 0+), N. Estimate.
    pub preload_n: f64,
    /// How far the free tip hangs below the chamber roof, m. Estimate.
    pub reach_below_roof_m: f64,
    /// z of the spring tip in the rail frame, m (over the rear shoe at assembly). Estimate.
    pub z_in_rail_m: f64,
    /// Engagement smoothing s (smooth-step width), m. Estimate.
    pub engagement_smoothing_m: f64,
    /// Step shape for the engagement (default cycloidal, eq. 2.4).
    #[serde(default)]
    pub step: StepKind,
}

/// The five solid-solid contacts of thesis 6.5 (numbered 1-5 as in Figures 6.59-6.62, 6.65-6.66).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LauncherContacts {
    /// Contact 1: missile front (front bearing pad) - rail. Table 6.2 default.
    pub missile_rail: ContactSpec,
    /// Contact 2: latch - rail. Stiffer than default (thesis 6.5.2, 6.6.3; value estimate).
    pub latch_rail: ContactSpec,
    /// Contact 3: mid shoe - rail. Table 6.2 default.
    pub mid_shoe_rail: ContactSpec,
    /// Contact 4: mid shoe - latch. Stiffer than default (thesis 6.5.2, 6.6.3; value estimate).
    pub mid_shoe_latch: ContactSpec,
    /// Contact 5: rear shoe - rail. Table 6.2 default.
    pub rear_shoe_rail: ContactSpec,
}

/// The Hellfire-class launcher of thesis chapter 6: kinematic rail, missile with mid and rear
/// shoes and a front bearing pad, latch on a cylindrical joint with its coil spring, two
/// double-barrel springs, the rear leaf spring, five contacts (Table 6.2) and friction (Table
/// 6.1). `dimensions` sets the channel and shoe cross-sections, so the tight, design and loose
/// variants (eq. 6.1-6.3) change the clearances.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LauncherSpec {
    /// Rail and shoe material (anodized 7075, thesis 4.2.1).
    #[serde(default)]
    pub material: MaterialSpec,
    /// Rear shoe and rail cross-section dimensions (eq. 6.1-6.2), mm.
    pub dimensions: LauncherDimensions,
    /// Rail layout.
    pub rail: RailSpec,
    /// Missile body.
    pub missile: MissileSpec,
    /// Mid shoe (latch side).
    pub mid_shoe: ShoeSpec,
    /// Rear shoe.
    pub rear_shoe: ShoeSpec,
    /// Missile front bearing pad (contact 1, the "front shoe (missile)" of Figure 6.59): where the
    /// missile's forward body meets the rail's bottom face, missile frame. Estimate.
    pub front_pad: RoundedBoxSpec,
    /// Latch rocker.
    pub latch: LatchSpec,
    /// Latch coil spring.
    pub latch_spring: CoilSpringSpec,
    /// The two double-barrel springs on the mid shoe.
    pub double_barrel_springs: Vec<ConstantForceSpec>,
    /// Rear leaf spring.
    pub rear_leaf_spring: LeafSpringSpec,
    /// Contact parameters (Table 6.2).
    pub contacts: LauncherContacts,
    /// Friction for all contacts (Table 6.1).
    pub friction: FrictionSpec,
}

impl LauncherSpec {
    /// Rattle space of the rail, eq. 6.1-6.3.
    pub fn rattle_space(&self) -> Result<f64, RattleSpaceError> {
        self.dimensions.rattle_space()
    }

    /// y of the chamber roof over the centreline, rail frame, m: lip top + mean(N_rail, Q_rail).
    pub fn chamber_roof_y_m(&self) -> f64 {
        self.rail.lip_top_y_m + units::mm(self.dimensions.mean_chamber_height_mm())
    }

    /// Missile centre of mass in the rail frame at assembly, m: the rear shoe's head rests on the
    /// lips (zero penetration), x = 0.
    pub fn missile_com_in_rail_m(&self) -> [f64; 3] {
        [
            -self.rear_shoe.head_base_in_missile_m[0],
            self.rail.lip_top_y_m - self.rear_shoe.head_base_in_missile_m[1],
            self.missile.com_z_in_rail_m,
        ]
    }

    /// Missile-frame point expressed in the rail frame at assembly, m.
    pub fn missile_to_rail_m(&self, p: [f64; 3]) -> [f64; 3] {
        add3(self.missile_com_in_rail_m(), p)
    }

    /// Leaf spring free tip, rail frame, m.
    pub fn leaf_spring_tip_in_rail_m(&self) -> [f64; 3] {
        [
            0.0,
            self.chamber_roof_y_m() - self.rear_leaf_spring.reach_below_roof_m,
            self.rear_leaf_spring.z_in_rail_m,
        ]
    }

    /// Leaf spring compression at assembly, m (> 0 engaged, < 0 a gap: not engaged when static).
    pub fn leaf_spring_static_compression_m(&self) -> f64 {
        let top = self.missile_to_rail_m(self.rear_shoe.head_top_in_missile_m(&self.dimensions));
        top[1] - self.leaf_spring_tip_in_rail_m()[1]
    }

    /// Latch spring length at assembly, m.
    pub fn latch_spring_installed_length_m(&self) -> f64 {
        dist3(
            self.latch_spring.point_on_rail_m,
            add3(self.latch.com_in_rail_m, self.latch_spring.point_on_latch_m),
        )
    }

    /// The channel faces the shoes, latch tooth and front pad can touch, rail frame (from
    /// `dimensions` and `rail`): lip tops (floor, +y), roof halves (-y, heights N_rail left and
    /// Q_rail right), chamber walls (width `B + A - mean(N, O)`, eq. 6.1), slot walls (width B)
    /// and the rail's bottom face (-y). Left is -x.
    pub fn rail_faces(&self) -> Vec<PlanarFace> {
        let d = &self.dimensions;
        let r = &self.rail;
        let half_b = 0.5 * units::mm(d.b_rail_mm);
        let half_w = 0.5 * units::mm(d.chamber_width_mm());
        let y0 = r.lip_top_y_m;
        let (hl, hr) = (units::mm(d.n_rail_mm), units::mm(d.q_rail_mm));
        let yb = y0 - r.lip_thickness_m;
        let zc = r.channel_centre_z_m;
        let hz = 0.5 * r.channel_length_m;
        let ez = [0.0, 0.0, 1.0];
        // Each face: tangent along z (half length = half the channel), width across.
        let face = |name: &str, centre: [f64; 3], normal: [f64; 3], half_width: f64| PlanarFace {
            name: name.to_string(),
            centre_m: centre,
            normal,
            tangent: ez,
            half_length_m: hz,
            half_width_m: half_width,
        };
        let lip_half = 0.5 * (half_w - half_b);
        let bottom_half = 0.5 * (r.bottom_half_width_m - half_b);
        vec![
            face(
                "lip_top_left",
                [-(half_b + lip_half), y0, zc],
                [0.0, 1.0, 0.0],
                lip_half,
            ),
            face(
                "lip_top_right",
                [half_b + lip_half, y0, zc],
                [0.0, 1.0, 0.0],
                lip_half,
            ),
            face(
                "roof_left",
                [-0.5 * half_w, y0 + hl, zc],
                [0.0, -1.0, 0.0],
                0.5 * half_w,
            ),
            face(
                "roof_right",
                [0.5 * half_w, y0 + hr, zc],
                [0.0, -1.0, 0.0],
                0.5 * half_w,
            ),
            face(
                "chamber_wall_left",
                [-half_w, y0 + 0.5 * hl, zc],
                [1.0, 0.0, 0.0],
                0.5 * hl,
            ),
            face(
                "chamber_wall_right",
                [half_w, y0 + 0.5 * hr, zc],
                [-1.0, 0.0, 0.0],
                0.5 * hr,
            ),
            face(
                "slot_wall_left",
                [-half_b, y0 - 0.5 * r.lip_thickness_m, zc],
                [1.0, 0.0, 0.0],
                0.5 * r.lip_thickness_m,
            ),
            face(
                "slot_wall_right",
                [half_b, y0 - 0.5 * r.lip_thickness_m, zc],
                [-1.0, 0.0, 0.0],
                0.5 * r.lip_thickness_m,
            ),
            face(
                "bottom_left",
                [-(half_b + bottom_half), yb, zc],
                [0.0, -1.0, 0.0],
                bottom_half,
            ),
            face(
                "bottom_right",
                [half_b + bottom_half, yb, zc],
                [0.0, -1.0, 0.0],
                bottom_half,
            ),
        ]
    }

    /// Field rules and assembly checks: dimensions (eq. 6.1-6.2 rules), positive masses and
    /// stiffnesses, real inertias, unit axes, exactly two double-barrel springs pushing +z, both
    /// shoes seated at the same height, shoes and pad inside the channel length, lips thinner
    /// than the neck, front pad clear of the rail bottom, latch tooth not below the lip tops.
    pub fn validate(&self, prefix: &str) -> Result<(), SpecError> {
        let p = |name: &str| path(prefix, name);
        self.material.validate(&p("material"))?;
        self.dimensions.validate().map_err(
            |RattleSpaceError::InvalidDimension { field, rule }| {
                err(path(&p("dimensions"), field), rule)
            },
        )?;
        // Rail
        let rp = p("rail");
        positive(&rp, "channel_length_m", self.rail.channel_length_m)?;
        finite(&rp, "channel_centre_z_m", self.rail.channel_centre_z_m)?;
        finite(&rp, "lip_top_y_m", self.rail.lip_top_y_m)?;
        positive(&rp, "lip_thickness_m", self.rail.lip_thickness_m)?;
        let neck_h = units::mm(self.dimensions.mean_neck_height_mm());
        if self.rail.lip_thickness_m >= neck_h {
            return Err(err(
                path(&rp, "lip_thickness_m"),
                format!("must be smaller than the shoes' mean neck height {neck_h} m"),
            ));
        }
        let half_w = 0.5 * units::mm(self.dimensions.chamber_width_mm());
        if !(self.rail.bottom_half_width_m.is_finite() && self.rail.bottom_half_width_m > half_w) {
            return Err(err(
                path(&rp, "bottom_half_width_m"),
                format!("must exceed the chamber half width {half_w} m"),
            ));
        }
        // Missile
        let mp = p("missile");
        positive(&mp, "mass_kg", self.missile.mass_kg)?;
        positive(&mp, "length_m", self.missile.length_m)?;
        positive(&mp, "diameter_m", self.missile.diameter_m)?;
        inertia3(&mp, "inertia_kg_m2", self.missile.inertia_kg_m2())?;
        finite(&mp, "com_z_in_rail_m", self.missile.com_z_in_rail_m)?;
        // Shoes and pad
        let (z_lo, z_hi) = (
            self.rail.channel_centre_z_m - 0.5 * self.rail.channel_length_m,
            self.rail.channel_centre_z_m + 0.5 * self.rail.channel_length_m,
        );
        for (name, shoe) in [("mid_shoe", &self.mid_shoe), ("rear_shoe", &self.rear_shoe)] {
            let sp = p(name);
            finite3(&sp, "head_base_in_missile_m", shoe.head_base_in_missile_m)?;
            positive(&sp, "length_m", shoe.length_m)?;
            non_negative(&sp, "edge_radius_m", shoe.edge_radius_m)?;
            let head = shoe.head_box(&self.dimensions);
            let neck = shoe.neck_box(&self.dimensions);
            if head
                .half_extents_m
                .iter()
                .chain(neck.half_extents_m.iter())
                .any(|h| *h <= shoe.edge_radius_m)
            {
                return Err(err(
                    path(&sp, "edge_radius_m"),
                    "must be smaller than every half size of the head and neck",
                ));
            }
            if let Some(pr) = &shoe.protrusion {
                pr.validate(&path(&sp, "protrusion"))?;
                if pr.min_y_m() < shoe.head_base_in_missile_m[1] {
                    return Err(err(
                        path(&sp, "protrusion"),
                        "reaches below the head base: it would intersect the rail lips at assembly",
                    ));
                }
            }
            let zc = self.missile_to_rail_m(shoe.head_base_in_missile_m)[2];
            if zc - 0.5 * shoe.length_m < z_lo || zc + 0.5 * shoe.length_m > z_hi {
                return Err(err(
                    path(&sp, "head_base_in_missile_m"),
                    "the shoe lies outside the rail channel's length",
                ));
            }
        }
        if (self.mid_shoe.head_base_in_missile_m[1] - self.rear_shoe.head_base_in_missile_m[1])
            .abs()
            > 1e-6
            || (self.mid_shoe.head_base_in_missile_m[0] - self.rear_shoe.head_base_in_missile_m[0])
                .abs()
                > 1e-6
        {
            return Err(err(
                p("mid_shoe.head_base_in_missile_m"),
                "x and y must equal the rear shoe's: both heads ride on the same lips",
            ));
        }
        let fp = p("front_pad");
        self.front_pad.validate(&fp)?;
        let pad_top =
            self.missile_to_rail_m(self.front_pad.centre_m)[1] + self.front_pad.half_extents_m[1];
        let bottom = self.rail.lip_top_y_m - self.rail.lip_thickness_m;
        if pad_top > bottom {
            return Err(err(
                path(&fp, "centre_m"),
                format!("the pad top ({pad_top} m) is above the rail bottom face ({bottom} m): interference at assembly"),
            ));
        }
        let pz = self.missile_to_rail_m(self.front_pad.centre_m)[2];
        if pz - self.front_pad.half_extents_m[2] < z_lo
            || pz + self.front_pad.half_extents_m[2] > z_hi
        {
            return Err(err(
                path(&fp, "centre_m"),
                "the pad lies outside the rail channel's length",
            ));
        }
        // Latch
        let lp = p("latch");
        positive(&lp, "mass_kg", self.latch.mass_kg)?;
        inertia3(&lp, "inertia_kg_m2", self.latch.inertia_kg_m2)?;
        finite3(&lp, "com_in_rail_m", self.latch.com_in_rail_m)?;
        finite3(
            &lp,
            "hinge_point_in_rail_m",
            self.latch.hinge_point_in_rail_m,
        )?;
        unit3(&lp, "hinge_axis", self.latch.hinge_axis)?;
        self.latch.tooth.validate(&path(&lp, "tooth"))?;
        let tooth_bottom =
            self.latch.tooth_centre_in_rail_m()[1] - self.latch.tooth.half_extents_m[1];
        if tooth_bottom < self.rail.lip_top_y_m - 1e-9 {
            return Err(err(
                path(&lp, "tooth"),
                format!("the tooth bottom ({tooth_bottom} m) is below the lip tops: interference at assembly"),
            ));
        }
        // Springs
        let sp = p("latch_spring");
        positive(
            &sp,
            "stiffness_n_per_m",
            self.latch_spring.stiffness_n_per_m,
        )?;
        non_negative(&sp, "damping_ns_per_m", self.latch_spring.damping_ns_per_m)?;
        non_negative(&sp, "preload_n", self.latch_spring.preload_n)?;
        finite3(&sp, "point_on_rail_m", self.latch_spring.point_on_rail_m)?;
        finite3(&sp, "point_on_latch_m", self.latch_spring.point_on_latch_m)?;
        if self.latch_spring_installed_length_m() <= 0.0 {
            return Err(err(
                path(&sp, "point_on_rail_m"),
                "the two attachment points coincide at assembly",
            ));
        }
        if self.double_barrel_springs.len() != 2 {
            return Err(err(
                p("double_barrel_springs"),
                format!(
                    "there are two double-barrel springs (thesis 6.5), got {}",
                    self.double_barrel_springs.len()
                ),
            ));
        }
        for (i, f) in self.double_barrel_springs.iter().enumerate() {
            let fp = p(&format!("double_barrel_springs[{i}]"));
            positive(&fp, "force_n", f.force_n)?;
            finite3(&fp, "point_in_missile_m", f.point_in_missile_m)?;
            unit3(&fp, "direction_in_rail", f.direction_in_rail)?;
            if f.direction_in_rail[2] <= 0.0 {
                return Err(err(
                    path(&fp, "direction_in_rail"),
                    "must push forward (+z), opposite the latch (thesis 6.2.3)",
                ));
            }
        }
        let lf = p("rear_leaf_spring");
        positive(
            &lf,
            "stiffness_n_per_m",
            self.rear_leaf_spring.stiffness_n_per_m,
        )?;
        non_negative(&lf, "preload_n", self.rear_leaf_spring.preload_n)?;
        non_negative(
            &lf,
            "reach_below_roof_m",
            self.rear_leaf_spring.reach_below_roof_m,
        )?;
        finite(&lf, "z_in_rail_m", self.rear_leaf_spring.z_in_rail_m)?;
        positive(
            &lf,
            "engagement_smoothing_m",
            self.rear_leaf_spring.engagement_smoothing_m,
        )?;
        // Contacts and friction
        let cp = p("contacts");
        let c = &self.contacts;
        c.missile_rail.validate(&path(&cp, "missile_rail"))?;
        c.latch_rail.validate(&path(&cp, "latch_rail"))?;
        c.mid_shoe_rail.validate(&path(&cp, "mid_shoe_rail"))?;
        c.mid_shoe_latch.validate(&path(&cp, "mid_shoe_latch"))?;
        c.rear_shoe_rail.validate(&path(&cp, "rear_shoe_rail"))?;
        self.friction.validate(&p("friction"))?;
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// Case files
// ---------------------------------------------------------------------------------------------

/// Which model a case file describes (its top-level `model` key).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// Thesis chapter 4; model table `[persistent_contact]`.
    PersistentContact,
    /// Thesis chapter 5; model table `[rattle_box]`.
    RattleBox,
    /// Thesis chapter 6; model table `[launcher]`.
    Launcher,
}

/// The model table of a case, by kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModelSpecRef<'a> {
    /// Chapter 4.
    PersistentContact(&'a PersistentContactSpec),
    /// Chapter 5.
    RattleBox(&'a RattleBoxSpec),
    /// Chapter 6.
    Launcher(&'a LauncherSpec),
}

/// One case file (`configs/*.toml`): model kind, name, description, run control, the model's own
/// table and the excitation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseSpec {
    /// Model kind; the table of the same name must be present and no other model table.
    pub model: ModelKind,
    /// Short identifier, e.g. `rattle-box-c`.
    pub name: String,
    /// One-line description with the thesis source.
    pub description: String,
    /// Run control.
    pub simulation: SimulationSpec,
    /// Chapter 4 model table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub persistent_contact: Option<PersistentContactSpec>,
    /// Chapter 5 model table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rattle_box: Option<RattleBoxSpec>,
    /// Chapter 6 model table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub launcher: Option<LauncherSpec>,
    /// Base excitation, kept untyped here (its schema belongs to `crate::excitation`).
    pub excitation: serde_json::Value,
    /// Wear law and the split of wear volume between the bodies of a contact.
    #[serde(default)]
    pub wear: WearSpec,
}

/// The `[wear]` table: wear law (default thesis Table 4.3 with the eq. 3.11 cutoff 2 S_y) and
/// how each contact's volume is split between its two bodies (default inverse hardness).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WearSpec {
    /// Wear law (tagged by `kind`: `archard`, `modified`, `legacy_appendix`).
    #[serde(default = "crate::wear::law::WearLaw::table_4_3")]
    pub law: crate::wear::law::WearLaw,
    /// Volume split between the two bodies of each contact.
    #[serde(default)]
    pub volume_split: crate::wear::allocation::VolumeSplit,
}

impl Default for WearSpec {
    fn default() -> Self {
        Self {
            law: crate::wear::law::WearLaw::table_4_3(),
            volume_split: crate::wear::allocation::VolumeSplit::default(),
        }
    }
}

impl CaseSpec {
    /// Parses a TOML case file (unknown keys are errors) and validates it.
    pub fn from_toml_str(text: &str) -> Result<Self, SpecError> {
        let case: Self = toml::from_str(text).map_err(|e| err("toml", e.to_string()))?;
        case.validate()?;
        Ok(case)
    }

    /// The model table matching `model`.
    pub fn model_spec(&self) -> Result<ModelSpecRef<'_>, SpecError> {
        let missing = |t: &str| err(t, format!("model = {:?} needs a [{t}] table", self.model));
        match self.model {
            ModelKind::PersistentContact => self
                .persistent_contact
                .as_ref()
                .map(ModelSpecRef::PersistentContact)
                .ok_or_else(|| missing("persistent_contact")),
            ModelKind::RattleBox => self
                .rattle_box
                .as_ref()
                .map(ModelSpecRef::RattleBox)
                .ok_or_else(|| missing("rattle_box")),
            ModelKind::Launcher => self
                .launcher
                .as_ref()
                .map(ModelSpecRef::Launcher)
                .ok_or_else(|| missing("launcher")),
        }
    }

    /// Validates the whole case: name, the one matching model table, run control, and that the
    /// excitation is a table with a `kind`.
    pub fn validate(&self) -> Result<(), SpecError> {
        if self.name.trim().is_empty() {
            return Err(err("name", "must not be empty"));
        }
        let extra = [
            (
                "persistent_contact",
                self.persistent_contact.is_some(),
                ModelKind::PersistentContact,
            ),
            (
                "rattle_box",
                self.rattle_box.is_some(),
                ModelKind::RattleBox,
            ),
            ("launcher", self.launcher.is_some(), ModelKind::Launcher),
        ]
        .into_iter()
        .find(|(_, present, kind)| *present && *kind != self.model);
        if let Some((table, _, _)) = extra {
            return Err(err(
                table,
                format!("table present but model = {:?}", self.model),
            ));
        }
        self.simulation.validate("simulation")?;
        match self.model_spec()? {
            ModelSpecRef::PersistentContact(s) => s.validate("persistent_contact")?,
            ModelSpecRef::RattleBox(s) => s.validate("rattle_box")?,
            ModelSpecRef::Launcher(s) => s.validate("launcher")?,
        }
        match self.excitation.get("kind").and_then(|k| k.as_str()) {
            Some(k) if !k.is_empty() => Ok(()),
            _ => Err(err(
                "excitation.kind",
                "the excitation table needs a `kind` string",
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn configs_dir() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("configs")
    }

    fn load(name: &str) -> CaseSpec {
        let text = std::fs::read_to_string(configs_dir().join(name)).unwrap();
        CaseSpec::from_toml_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"))
    }

    fn round_to(x: f64, decimals: i32) -> f64 {
        let s = 10f64.powi(decimals);
        (x * s).round() / s
    }

    #[test]
    fn every_case_file_parses_and_validates() {
        let mut count = 0;
        for entry in std::fs::read_dir(configs_dir()).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().and_then(|e| e.to_str()) != Some("toml") {
                continue; // also skips the profiles/ directory
            }
            if path.file_name().and_then(|n| n.to_str()) == Some("service.toml") {
                continue; // service settings, not a case
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let case = CaseSpec::from_toml_str(&text)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert_eq!(
                path.file_stem().and_then(|s| s.to_str()),
                Some(case.name.as_str()),
                "file name and `name` should agree"
            );
            count += 1;
        }
        assert!(
            count >= 8,
            "expected the 8 shipped case files, found {count}"
        );
    }

    #[test]
    fn rattle_box_cases_match_table_5_1_and_5_2() {
        for (file, k) in [
            ("rattle-box-a.toml", 0.25),
            ("rattle-box-b.toml", 0.44),
            ("rattle-box-c.toml", 0.64),
            ("rattle-box-d.toml", 0.79),
        ] {
            let case = load(file);
            let Ok(ModelSpecRef::RattleBox(rb)) = case.model_spec() else {
                panic!("{file} is not a rattle box");
            };
            assert_eq!(round_to(rb.rattle_space().unwrap(), 2), k, "{file}");
            // 7075 cube, 1 in: 2810 kg/m³ x 16.387 cm³ = 46.05 g (thesis fixture about 46 g).
            assert!(
                (rb.cube_mass_kg() - 0.04605).abs() < 5e-6,
                "{}",
                rb.cube_mass_kg()
            );
            // Table 5.2 in SI: k 1e9 N/m², c 5e5 N·s/m, v_s 6.4634 mm/s.
            let ip = rb.contact.to_impact_params();
            assert!((ip.stiffness - 1.0e9).abs() < 1.0);
            assert!((ip.max_damping - 5.0e5).abs() < 1e-6);
            assert!((ip.full_damping_depth - 1.0e-5).abs() < 1e-15);
            let fp = rb.friction.to_friction_params();
            assert!((fp.stiction_transition_speed - 6.4634e-3).abs() < 1e-12);
            assert!((fp.friction_transition_speed - 12.0e-3).abs() < 1e-12);
            assert!((rb.edge_radius_m - 0.02 * 0.0254).abs() < 1e-12);
            assert_eq!(
                case.excitation["tones"][0]["frequency_hz"].as_f64(),
                Some(20.0)
            );
            assert_eq!(
                case.excitation["tones"][0]["amplitude_g"].as_f64(),
                Some(15.0)
            );
        }
    }

    fn launcher(file: &str) -> LauncherSpec {
        match load(file).model_spec() {
            Ok(ModelSpecRef::Launcher(l)) => l.clone(),
            other => panic!("{file}: {other:?}"),
        }
    }

    #[test]
    fn launcher_variants_have_the_thesis_rattle_spaces() {
        for (file, k) in [
            ("launcher-tight.toml", 0.8317),
            ("launcher-design.toml", 0.7990),
            ("launcher-loose.toml", 0.7684),
        ] {
            let l = launcher(file);
            assert_eq!(round_to(l.rattle_space().unwrap(), 4), k, "{file}");
        }
        // The config files carry the same numbers as the named sets in code.
        assert_eq!(
            launcher("launcher-design.toml").dimensions,
            LauncherDimensions::design()
        );
        let tight = launcher("launcher-tight.toml").dimensions;
        assert!((tight.b_rail_mm - LauncherDimensions::tight().b_rail_mm).abs() < 1e-9);
    }

    #[test]
    fn leaf_spring_engages_except_on_the_loose_rail() {
        // Design: vertical clearance 0.60 mm, tip reach 0.80 mm -> 0.20 mm compression.
        let d = launcher("launcher-design.toml");
        assert!((d.leaf_spring_static_compression_m() - 0.20e-3).abs() < 1e-9);
        // Tight: clearance 0.60 - 2 x 0.201 = 0.198 mm -> 0.602 mm compression.
        let t = launcher("launcher-tight.toml");
        assert!((t.leaf_spring_static_compression_m() - 0.602e-3).abs() < 1e-9);
        // Loose: clearance 0.60 + 2 x 0.1955 = 0.991 mm -> a 0.191 mm gap (thesis 6.3.1).
        let l = launcher("launcher-loose.toml");
        assert!((l.leaf_spring_static_compression_m() + 0.191e-3).abs() < 1e-9);
    }

    #[test]
    fn rail_faces_follow_the_dimensions() {
        let l = launcher("launcher-design.toml");
        let faces = l.rail_faces();
        assert_eq!(faces.len(), 10);
        let get = |n: &str| faces.iter().find(|f| f.name == n).unwrap().clone();
        // Chamber wall at x = (B + A - N)/2 = (10.23 + 38.10 - 9.53)/2 mm = 19.40 mm.
        assert!((get("chamber_wall_right").centre_m[0] - 19.40e-3).abs() < 1e-12);
        // Slot wall at B/2 = 5.115 mm; roof at lip top + 10.13 mm.
        assert!((get("slot_wall_left").centre_m[0] + 5.115e-3).abs() < 1e-12);
        assert!((get("roof_left").centre_m[1] - (-0.030 + 10.13e-3)).abs() < 1e-12);
        for f in &faces {
            let n = f.normal;
            assert!((n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-12);
            assert!(f.half_width_m > 0.0 && f.half_length_m > 0.0, "{}", f.name);
        }
        // The rear shoe head sits on the lips at assembly, inside the chamber.
        let head = l.rear_shoe.head_box(&l.dimensions);
        let centre = l.missile_to_rail_m(head.centre_m);
        assert!((centre[1] - head.half_extents_m[1] - l.rail.lip_top_y_m).abs() < 1e-12);
        assert!(head.half_extents_m[0] < get("chamber_wall_right").centre_m[0]);
        // Loose rail: wider slot and chamber.
        let loose = launcher("launcher-loose.toml").rail_faces();
        let wall = loose.iter().find(|f| f.name == "slot_wall_right").unwrap();
        assert!(wall.centre_m[0] > get("slot_wall_right").centre_m[0]);
    }

    #[test]
    fn missile_inertia_defaults_to_a_solid_cylinder() {
        let l = launcher("launcher-design.toml");
        let i = l.missile.inertia_kg_m2();
        let (m, r, len) = (45.0, 0.089, 1.63);
        assert!((i[0] - m * (3.0 * r * r + len * len) / 12.0).abs() < 1e-12);
        assert!((i[2] - 0.5 * m * r * r).abs() < 1e-12);
    }

    #[test]
    fn latch_spring_and_contacts() {
        let l = launcher("launcher-design.toml");
        assert!((l.latch_spring_installed_length_m() - 0.030).abs() < 1e-12);
        let def = l.contacts.rear_shoe_rail;
        assert_eq!(def, ContactSpec::thesis_default());
        assert!(l.contacts.mid_shoe_latch.stiffness_n_per_mm_e > def.stiffness_n_per_mm_e);
        assert!(l.contacts.latch_rail.stiffness_n_per_mm_e > def.stiffness_n_per_mm_e);
        // The latch tooth's rear face touches the mid shoe protrusion's front face at assembly.
        let tooth = l.latch.tooth_centre_in_rail_m();
        let pr = l.mid_shoe.protrusion.unwrap();
        let front = l.missile_to_rail_m(pr.centre_m)[2] + pr.half_extents_m[2];
        assert!((tooth[2] - l.latch.tooth.half_extents_m[2] - front).abs() < 1e-12);
    }

    #[test]
    fn persistent_contact_derived_quantities() {
        let case = load("persistent-contact.toml");
        let Ok(ModelSpecRef::PersistentContact(p)) = case.model_spec() else {
            panic!("not a persistent contact case");
        };
        // 50 N over 3 pads of 6.35 mm x 6.35 mm.
        let expected = 50.0 / (3.0 * 0.00635 * 0.00635);
        assert!((p.nominal_pressure_pa() - expected).abs() < 1e-6);
        // eq. 4.4: peak slip = 30 deg x 2 pi x 1 Hz x 20 mm.
        let v = 30f64.to_radians() * 2.0 * std::f64::consts::PI * 0.020;
        assert!((p.peak_slip_speed_m_per_s() - v).abs() < 1e-12);
        assert_eq!(p.contact, ContactSpec::thesis_default());
    }

    #[test]
    fn validation_names_fields() {
        let text = std::fs::read_to_string(configs_dir().join("launcher-design.toml")).unwrap();
        let field_of = |from: &str, to: &str| {
            assert!(text.contains(from), "{from}");
            CaseSpec::from_toml_str(&text.replacen(from, to, 1))
                .unwrap_err()
                .field
        };
        assert_eq!(
            field_of("b_rail_mm = 10.23", "b_rail_mm = 9.0"),
            "launcher.dimensions.n_shoe_mm"
        );
        assert_eq!(
            field_of("a_shoe_mm = 38.1", "a_shoe_mm = 1.5"),
            "launcher.dimensions.a_shoe_mm"
        );
        assert_eq!(
            field_of("mass_kg = 45.0", "mass_kg = -45.0"),
            "launcher.missile.mass_kg"
        );
        assert_eq!(
            field_of(
                "hinge_axis = [1.0, 0.0, 0.0]",
                "hinge_axis = [1.0, 1.0, 0.0]"
            ),
            "launcher.latch.hinge_axis"
        );
        assert_eq!(
            field_of(
                "stiffness_n_per_mm_e = 10000.0",
                "stiffness_n_per_mm_e = 0.0"
            ),
            "launcher.contacts.latch_rail.stiffness_n_per_mm_e"
        );
        assert_eq!(
            field_of("lip_thickness_m = 0.005", "lip_thickness_m = 0.008"),
            "launcher.rail.lip_thickness_m"
        );
        assert_eq!(
            field_of("duration_s = 10.0", "duration_s = 0.0"),
            "simulation.duration_s"
        );
        // Unknown keys are rejected (deny_unknown_fields), reported as a TOML error.
        assert_eq!(
            field_of("mass_kg = 45.0", "mass_kg = 45.0\nmass_lb = 99.0"),
            "toml"
        );
        // The wrong model table.
        assert_eq!(
            field_of("model = \"launcher\"", "model = \"rattle_box\""),
            "launcher"
        );

        let pc = std::fs::read_to_string(configs_dir().join("persistent-contact.toml")).unwrap();
        let e = CaseSpec::from_toml_str(&pc.replacen(
            "frequency_hz = 1.0",
            "frequency_hz = 1.0\nphase_deg = 3.0",
            1,
        ))
        .unwrap_err();
        assert_eq!(e.field, "toml");
        let e =
            CaseSpec::from_toml_str(&pc.replace("mean_radius_m = 0.020", "mean_radius_m = 0.024"))
                .unwrap_err();
        assert_eq!(e.field, "persistent_contact.coupon_side_m");

        let rb = std::fs::read_to_string(configs_dir().join("rattle-box-c.toml")).unwrap();
        let e = CaseSpec::from_toml_str(
            &rb.replace("tube_inner_side_m = 0.031750", "tube_inner_side_m = 0.0200"),
        )
        .unwrap_err();
        assert_eq!(e.field, "rattle_box.tube_inner_side_m");
        let e = CaseSpec::from_toml_str(&rb.replace("mu_dynamic = 0.1660", "mu_dynamic = -0.1"))
            .unwrap_err();
        assert_eq!(e.field, "rattle_box.friction.mu_dynamic");
    }

    #[test]
    fn toml_round_trip() {
        let case = load("launcher-loose.toml");
        let text = toml::to_string(&case).unwrap();
        let back = CaseSpec::from_toml_str(&text).unwrap();
        assert_eq!(back, case);
    }
}
