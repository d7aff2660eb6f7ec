//! Wear (thesis chapter 3): wear laws, the per-track streaming integrator, the pressure
//! histogram behind Figure 6.65, and the split of a contact's wear volume between its bodies.
//!
//! Data flow: the engine pushes each contact track's samples into a [`WearAccumulator`] as it
//! integrates (no track storage needed), `finish()` gives [`WearTotals`], a contact's totals are
//! the [`WearTotals::merge`] of its tracks, and [`VolumeSplit`] turns a contact volume into
//! per-body volume and mass.

pub mod allocation;
pub mod integrate;
pub mod law;
pub mod material;
pub mod mechanism;
pub mod pressure_pdf;

pub use allocation::{mass_rate_mg_per_h, volume_rate_m3_per_h, BodyWear, VolumeSplit};
pub use integrate::{WearAccumulator, WearTotals};
pub use law::{Quadrature, WearLaw};
pub use material::Material;
pub use mechanism::{WearMechanism, WearSample, WearTerm};
pub use pressure_pdf::PressureHistogram;

use crate::field_error::FieldError;

/// Errors of the wear module: each names the offending field and the rule it broke.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WearError {
    /// A parameter or sample value broke a rule.
    /// (The field is a parameter's name or a sample column.)
    #[error("invalid {}: {}", .0.field, .0.rule)]
    Invalid(#[from] FieldError),
}
