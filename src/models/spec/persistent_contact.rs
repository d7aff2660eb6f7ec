//! Chapter 4: the persistent contact fixture.

use crate::field_error::FieldError;
use crate::models::spec::{
    finite, non_negative, path, positive, validate_friction, validate_material, ContactSpec,
};
use crate::parameters::{Bounded, FieldPath};
use crate::physics::friction::{in_mm_per_s, FrictionParams};
use crate::wear::material::Material;
use serde::{Deserialize, Serialize};

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

/// The persistent-contact block runs in no job (it is not a dynamic case), so only what it
/// shares with the dynamic models is bounded: its material, contact, friction and the
/// oscillation's frequency.
impl Bounded for PersistentContactSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.child("material", &self.material)?;
        if let PrescribedRotation::Oscillating { frequency_hz, .. } = self.rotation {
            at.field("rotation", |at| {
                at.number("frequency_hz", frequency_hz, &super::FREQUENCY)
            })?;
        }
        at.child("contact", &self.contact)?;
        at.child("friction", &self.friction)
    }
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

    fn validate(&self, prefix: &str) -> Result<(), FieldError> {
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
                    return Err(FieldError::new(
                        path(prefix, "rate_deg_per_s"),
                        "must not be zero",
                    ));
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
    pub material: Material,
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
    #[serde(with = "in_mm_per_s")]
    pub friction: FrictionParams,
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
    pub fn validate(&self, prefix: &str) -> Result<(), FieldError> {
        validate_material(&self.material, &path(prefix, "material"))?;
        if self.pad_count == 0 {
            return Err(FieldError::new(
                path(prefix, "pad_count"),
                "must be >= 1 (thesis: 3)",
            ));
        }
        for s in self.pad_size_m {
            if !(s.is_finite() && s > 2.0 * self.pad_edge_radius_m) {
                return Err(FieldError::new(
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
        validate_friction(&self.friction, &path(prefix, "friction"))?;
        let half_diag = 0.5 * self.pad_size_m[0].hypot(self.pad_size_m[2]);
        if self.mean_radius_m + half_diag > 0.5 * self.coupon_side_m {
            return Err(FieldError::new(
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
                return Err(FieldError::new(
                    path(prefix, "mean_radius_m"),
                    "pads at this radius would overlap each other",
                ));
            }
        }
        Ok(())
    }
}
