//! Physical bounds on every number a case can carry (no silent nonsense), checked on the typed
//! case.
//!
//! A case passes these and then its model's own rules (`models::spec`: positive sizes, unit
//! axes, the cube fits the tube): each number lies in a range with a physical reason, so a
//! typing error (a friction coefficient of 1e6, an amplitude of 1e308 g) is refused at submit
//! with a 422 naming the field instead of running into NaN. Each range is a [`Bound`] declared
//! beside the field it bounds, in the file of its spec struct (`models/spec/`), and each struct
//! checks its own fields and calls its children ([`Bounded::check_bounds`]) at their path
//! ([`FieldPath`]): one mechanism, the one the named parameters of `crate::parameters` carry too.
//! The case's own checks run on the [`CaseSpec`] as typed; the motion an excitation profile
//! stands for is checked as it is resolved, under `excitation`.

use crate::excitation::ExcitationSpec;
use crate::field_error::FieldError;
use crate::models::spec::CaseSpec;
pub use crate::models::spec::{
    MAX_DESCRIPTION_CHARS, MAX_PSD_BREAKPOINTS, MAX_TEXT_CHARS, MAX_TONES,
    MAX_WEAR_COEFFICIENT_M2_PER_N,
};
pub use crate::parameters::{Bound, Bounded, FieldPath};

/// Checks every number of `case` against its bound, its texts against the length limits, the
/// excitation's list lengths and the wear law's peak coefficient, at `at` (a
/// [`FieldPath::recording`] one lists what it checked). `resolved_excitation` is the motion a
/// profile name stands for (its fields are reported under `excitation`). Errors name the case
/// path (`rattle_box.friction.mu_static`).
pub fn check_case_at(
    case: &CaseSpec,
    resolved_excitation: Option<&ExcitationSpec>,
    at: &mut FieldPath,
) -> Result<(), FieldError> {
    case.check_bounds(at)?;
    match resolved_excitation {
        Some(motion) => at.child("excitation", motion),
        None => Ok(()),
    }
}

/// [`check_case_at`] at the case's root.
pub fn check_case(
    case: &CaseSpec,
    resolved_excitation: Option<&ExcitationSpec>,
) -> Result<(), FieldError> {
    check_case_at(case, resolved_excitation, &mut FieldPath::new(""))
}
