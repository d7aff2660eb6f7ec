//! Quasistatic sphere-on-flat contact models of thesis 2.3.1 (Hertz, fully plastic,
//! Jackson-Green, Kogut-Etsion) and their least-squares fits to the IMPACT spring `k w^e`.
//!
//! They choose IMPACT stiffness and exponent from material data ([`impact_fit()`], the
//! `railwear contact-fit` command, and the Table 2.1/2.2 anchors of `railwear validate`); they
//! are not used inside the time integration itself.

pub mod fit;
pub mod impact_fit;
pub mod quasistatic;

pub use fit::{
    fit_model, fit_power_law, static_penetration, table_2_1_parameters, FitSpace, ImpactFitRow,
    PowerLawFit,
};
pub use impact_fit::{impact_fit, FitRange, ImpactFit, ImpactFitSpec};
pub use quasistatic::{QuasistaticModel, SphereOnFlat};

use crate::field_error::FieldError;

/// Errors of the contact-model library; each names the field and the rule.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContactModelError {
    /// A parameter broke a rule.
    #[error("invalid {}: {}", .0.field, .0.rule)]
    Invalid(#[from] FieldError),
    /// The fit did not converge or the data could not be fitted.
    #[error("fit failed: {0}")]
    Fit(&'static str),
}
