//! Test bed of the sim-to-real gap diagnosis (SPEC 7, issue 14): measured test campaigns in,
//! a library of candidate unmodelled effects, and a virtual shaker rig that writes campaigns
//! whose cause is known but withheld.
//!
//! - [`campaign`]: the campaign format (TOML manifest + CSV files beside it, or the same content
//!   as JSON), its parser and its validation (errors name the field and the CSV row).
//! - [`accel`]: accelerometer records (CSV `time_s,a_x_m_s2,a_y_m_s2,a_z_m_s2`).
//! - [`tracks`]: contact tracks kept per integrator step, and the wear integral over them with
//!   optional wear-law terms (so wear-law effects never re-simulate).
//! - [`effects`]: the effect library shared by the rig and the diagnosis.
//! - [`rig`] and [`rig_effects`]: the virtual rig and the effects only the rig knows.
//! - [`window`]: one simulated excitation window, shared (and cached) by the rig and the
//!   diagnosis.
//! - [`diagnose`]: the gap diagnosis (where, which effect, how far) and its blind bench.

pub mod accel;
pub mod campaign;
pub mod diagnose;
mod drive_edits;
mod dynamics_effects;
pub mod effects;
mod manifest;
pub mod point_pressure;
pub mod rig;
pub mod rig_effects;
pub mod track_point;
pub mod tracks;
pub mod window;

pub use campaign::Campaign;
pub use effects::Effect;

/// Errors of the gap test bed. Each names the campaign field (dotted path, e.g.
/// `tests[2].specimens[0].increments[1].mass_loss_mg.cube`) and, for CSV files, the 1-based
/// row (the header is row 1) and the column.
#[derive(Debug, thiserror::Error)]
pub enum GapError {
    /// A field breaks a rule.
    #[error("field `{field}`: {rule}")]
    Field {
        /// Dotted field path.
        field: String,
        /// The rule broken.
        rule: String,
    },
    /// A cell or row of a CSV file breaks a rule.
    #[error("field `{field}`: {file} row {row}, column `{column}`: {rule}")]
    Csv {
        /// Field of the manifest that names the file.
        field: String,
        /// File name as given in the manifest.
        file: String,
        /// 1-based row (line) number; the header is row 1.
        row: usize,
        /// Column name.
        column: String,
        /// The rule broken.
        rule: String,
    },
    /// A simulation the rig ran failed.
    #[error("simulation of {what}: {message}")]
    Simulation {
        /// Test, specimen and increment.
        what: String,
        /// What failed.
        message: String,
    },
    /// Writing output failed.
    #[error("writing {path}: {message}")]
    Write {
        /// File path.
        path: String,
        /// Cause.
        message: String,
    },
}

/// A field error of the campaign (the variant keeps its named fields, which callers and tests
/// match).
impl From<crate::field_error::FieldError> for GapError {
    fn from(e: crate::field_error::FieldError) -> Self {
        Self::field(e.field, e.rule)
    }
}

impl GapError {
    /// A field error.
    pub fn field(field: impl Into<String>, rule: impl Into<String>) -> Self {
        Self::Field {
            field: field.into(),
            rule: rule.into(),
        }
    }

    /// `Ok` when `ok` holds, otherwise a field error naming `field` and `rule`.
    pub fn require(field: &str, ok: bool, rule: &str) -> Result<(), Self> {
        if ok {
            Ok(())
        } else {
            Err(Self::field(field, rule))
        }
    }

    /// The field at fault (for problem+json `field`), if any.
    pub fn field_path(&self) -> Option<&str> {
        match self {
            Self::Field { field, .. } | Self::Csv { field, .. } => Some(field),
            _ => None,
        }
    }
}
