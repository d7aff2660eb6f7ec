//! Persistent contact fixture (thesis chapter 4): three pads on a rotating upper fixture pressed
//! on a coupon, for the friction (eq. 4.1-4.4) and wear-law (eq. 4.16-4.18) tests. What it is
//! ([`PersistentContactSpec`], the case file's `[persistent_contact]` table) is in
//! `models/spec/persistent_contact.rs`.
//!
//! It is not built as a dynamic case in this build: its data go through `railwear calibrate`
//! (the calibrate jobs of `pipeline::calibrate` and the fits of `analysis::calibration`), so
//! [`build`] refuses it, naming the `model` field.

#[cfg(test)]
mod tests;

pub use super::spec::persistent_contact::{PersistentContactSpec, PrescribedRotation};

use super::outcome::RunError;
use super::run::BuiltModel;
use crate::field_error::FieldError;

/// The fixture as a dynamic model: refused (see the module notes), with the field `model`.
pub fn build(_spec: &PersistentContactSpec) -> Result<BuiltModel, RunError> {
    Err(FieldError::new(
        "model",
        "the persistent-contact fixture runs through `railwear calibrate`, not as a dynamic case in this build",
    ).into())
}
