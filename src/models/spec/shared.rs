//! Specs shared by every model: material, contact and friction (ADAMS units), rounded boxes, the simulation settings.

use super::{finite3, non_negative, path, positive, EDGE_RADIUS, LENGTH, POSITION};
use crate::field_error::FieldError;
use crate::parameters::{Bound, Bounded, FieldPath};
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

/// IMPACT stiffness k, N/mm^e.
const CONTACT_STIFFNESS: Bound = Bound::new(
    1.0e-3,
    1.0e8,
    "N/mm^e",
    "IMPACT stiffness from 1e-3 to 1e8 N/mm^e: the thesis uses 1e3-1e4; stiffer laws put \
     contact time constants below 1 ns",
);
/// IMPACT force exponent e.
const CONTACT_EXPONENT: Bound = Bound::new(
    1.0,
    4.0,
    "",
    "force exponents of contact laws lie between 1 (flat punch) and about 3 (rough surfaces, \
     Kogut-Etsion fits); Hertz gives 1.5, the thesis 2; at 4 the force at the 0.01 mm damping \
     depth is 1e-8 of the linear law's",
);
/// IMPACT maximum damping, N·s/mm.
const CONTACT_DAMPING: Bound = Bound::new(
    0.0,
    1.0e5,
    "N·s/mm",
    "up to 200 times the thesis' 500 N·s/mm; more makes every impact plastic",
);
/// IMPACT full-damping penetration, mm.
const CONTACT_PENETRATION: Bound = Bound::new(
    0.0,
    1.0,
    "mm",
    "full damping within 1 mm of penetration (thesis: 0.01 mm); deeper than the tight rail's \
     whole clearance is no ramp",
)
.open_min();

impl Bounded for ContactSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number(
            "stiffness_n_per_mm_e",
            self.stiffness_n_per_mm_e,
            &CONTACT_STIFFNESS,
        )?;
        at.number("exponent", self.exponent, &CONTACT_EXPONENT)?;
        at.number(
            "damping_ns_per_mm",
            self.damping_ns_per_mm,
            &CONTACT_DAMPING,
        )?;
        at.number(
            "penetration_depth_mm",
            self.penetration_depth_mm,
            &CONTACT_PENETRATION,
        )
    }
}

/// Friction coefficients (eq. 4.5, Tables 4.2, 5.2, 6.1).
const MU: Bound = Bound::new(
    0.0,
    2.0,
    "",
    "friction coefficients of dry engineering pairs lie below 1.3 (clean aluminium); 2 bounds \
     every real pair, Table 5.2 gives 0.18",
);
/// Friction transition speeds, mm/s (as case files write them).
const TRANSITION_SPEED: Bound = Bound::new(
    1.0e-3,
    1.0e3,
    "mm/s",
    "friction transition speeds from 1 µm/s to 1 m/s (Table 5.2: 6.46 and 12 mm/s); above \
     1 m/s every slip of a rattle is stiction",
);

/// A case's friction, at the names and units case files write (the speeds in mm/s).
impl Bounded for FrictionParams {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number("mu_static", self.mu_static, &MU)?;
        at.number("mu_dynamic", self.mu_dynamic, &MU)?;
        at.number(
            "stiction_transition_speed_mm_per_s",
            crate::units::to_mm(self.stiction_transition_speed),
            &TRANSITION_SPEED,
        )?;
        at.number(
            "friction_transition_speed_mm_per_s",
            crate::units::to_mm(self.friction_transition_speed),
            &TRANSITION_SPEED,
        )
    }
}

/// Material density range, kg/m³: from polymers to the densest metals (osmium 22 590). A
/// wear calibration's density is held to it too.
pub const DENSITY_KG_M3_RANGE: (f64, f64) = (500.0, 25_000.0);
const DENSITY: Bound = Bound::new(
    DENSITY_KG_M3_RANGE.0,
    DENSITY_KG_M3_RANGE.1,
    "kg/m³",
    "from polymers to the densest metals (osmium 22 590 kg/m³)",
);
const YIELD_STRENGTH: Bound = Bound::new(
    1.0e6,
    1.0e10,
    "Pa",
    "from soft polymers (1 MPa) to above the strongest steels (maraging 2.5 GPa)",
);
const YOUNGS_MODULUS: Bound = Bound::new(
    1.0e7,
    1.2e12,
    "Pa",
    "from elastomers (10 MPa) to diamond (1.2 TPa)",
);
const POISSON_RATIO: Bound = Bound::new(
    -1.0,
    0.5,
    "",
    "an isotropic solid is stable only for -1 < ν <= 0.5",
)
.open_min();
const BRINELL_HARDNESS: Bound = Bound::new(
    1.0,
    1000.0,
    "HB",
    "from lead (about 5 HB) to above hardened tool steel (about 700 HB)",
);

/// The material of a case's contacting parts (`wear::material::Material`).
impl Bounded for Material {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number("density_kg_per_m3", self.density_kg_per_m3, &DENSITY)?;
        at.number("yield_strength_pa", self.yield_strength_pa, &YIELD_STRENGTH)?;
        at.number("youngs_modulus_pa", self.youngs_modulus_pa, &YOUNGS_MODULUS)?;
        at.number("poisson_ratio", self.poisson_ratio, &POISSON_RATIO)?;
        at.number("brinell_hardness", self.brinell_hardness, &BRINELL_HARDNESS)
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

impl Bounded for RoundedBoxSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.numbers("centre_m", &self.centre_m, &POSITION)?;
        at.numbers("half_extents_m", &self.half_extents_m, &LENGTH)?;
        at.number("edge_radius_m", self.edge_radius_m, &EDGE_RADIUS)
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

/// Longest excited duration of a job, s: 24 h of simulated time. The thesis' longest run is
/// the 12 h launcher validation (6.7); beyond a day a run is a typing error (1e308 s was
/// once accepted and grew memory without end).
pub const MAX_DURATION_S: f64 = 86_400.0;
/// Longest settle phase, s: ten minutes, well past the tens-of-seconds creep time constant
/// of a body resting on a face (SPEC 8); the thesis settles for 2 s (6.6.1).
pub const MAX_SETTLE_S: f64 = 600.0;
/// Shortest track-record interval, s: 1 us resolves a 500 Hz excitation 2000 times over;
/// finer only multiplies stored samples.
pub const MIN_RECORD_INTERVAL_S: f64 = 1.0e-6;
/// Relative error tolerance range: looser than 10 % is no error control; tighter than
/// 1e-10 is below what double precision holds over a run.
pub const REL_TOLERANCE_RANGE: (f64, f64) = (1.0e-10, 0.1);
/// Absolute position tolerance range, m: coarser than 0.1 mm does not resolve the 0.2 mm
/// clearance of the tight rail; finer than 1e-15 m is below double precision on metres.
pub const ABS_TOLERANCE_M_RANGE: (f64, f64) = (1.0e-15, 1.0e-4);
/// Largest seed, 2^53 - 1: every seed a JSON reader parses into a double (JavaScript, jq)
/// is then exact, so a run can be reproduced from what a dashboard shows.
pub const MAX_SEED: u64 = (1 << 53) - 1;

/// A settle phase, s (the case's and a base motion's).
pub(in crate::models) const SETTLE: Bound = Bound::new(
    0.0,
    MAX_SETTLE_S,
    "s",
    "a settle of up to ten minutes, past the contact creep time constant (thesis: 2 s)",
);
/// An excited duration, s (the case's and a synthesised random record's).
pub(in crate::models) const DURATION: Bound = Bound::new(
    MIN_RECORD_INTERVAL_S,
    MAX_DURATION_S,
    "s",
    "from one record interval (1 µs) to 24 h of simulated time (thesis: 12 h at most); also \
     the length of a synthesised random record",
);
/// A seed (the case's and a random base motion's).
pub(in crate::models) const SEED: Bound = Bound::new(
    0.0,
    MAX_SEED as f64,
    "",
    "seeds below 2^53 read back exactly from JSON (see limits::MAX_SEED)",
);
const REL_TOLERANCE: Bound = Bound::new(
    REL_TOLERANCE_RANGE.0,
    REL_TOLERANCE_RANGE.1,
    "",
    "looser than 10 % is no error control; tighter than 1e-10 is below double precision",
);
const ABS_TOLERANCE: Bound = Bound::new(
    ABS_TOLERANCE_M_RANGE.0,
    ABS_TOLERANCE_M_RANGE.1,
    "m",
    "coarser than 0.1 mm misses the tight rail's 0.2 mm clearance; finer than 1e-15 m is below \
     double precision on metres",
);
const RECORD_INTERVAL: Bound = Bound::new(
    MIN_RECORD_INTERVAL_S,
    MAX_DURATION_S,
    "s",
    "1 µs resolves a 500 Hz excitation 2000 times over",
);
const ENERGY_REL_TOLERANCE: Bound = Bound::new(
    0.0,
    0.5,
    "",
    "above 50 % the energy account's quadrature error is as large as the work it checks; 0 \
     switches the check off",
);
const POINTS_PER_EDGE: Bound = Bound::new(
    crate::geometry::lattice::POINTS_PER_EDGE_RANGE.0 as f64,
    crate::geometry::lattice::POINTS_PER_EDGE_RANGE.1 as f64,
    "",
    "2 points per edge are the corners; beyond 33 the cost grows with no change in the \
     resolved face law",
);

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

impl Bounded for SimulationSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number("settle_s", self.settle_s, &SETTLE)?;
        at.number("duration_s", self.duration_s, &DURATION)?;
        at.text("integrator", &self.integrator, super::MAX_TEXT_CHARS, false)?;
        at.number("rel_tolerance", self.rel_tolerance, &REL_TOLERANCE)?;
        at.number("abs_tolerance_m", self.abs_tolerance_m, &ABS_TOLERANCE)?;
        at.number("seed", self.seed as f64, &SEED)?;
        at.number(
            "record_interval_s",
            self.record_interval_s,
            &RECORD_INTERVAL,
        )?;
        at.optional(
            "energy_rel_tolerance",
            self.energy_rel_tolerance,
            &ENERGY_REL_TOLERANCE,
        )?;
        at.number(
            "contact_points_per_edge",
            self.contact_points_per_edge as f64,
            &POINTS_PER_EDGE,
        )
    }
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
