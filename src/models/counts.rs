//! Test-only counts of case validations ([`super::spec::CaseSpec::validate`]), model builds and
//! campaign validations on this thread, so a test can check that a job attempt validates and
//! builds its case once and that a diagnosis does not validate its stored campaign again.
//! Thread-local: the tests of one process run side by side on their own threads.

use std::cell::Cell;

thread_local! {
    static VALIDATIONS: Cell<u32> = const { Cell::new(0) };
    static BUILDS: Cell<u32> = const { Cell::new(0) };
    static CAMPAIGN_VALIDATIONS: Cell<u32> = const { Cell::new(0) };
}

/// One `CaseSpec::validate` ran on this thread.
pub(crate) fn validated() {
    VALIDATIONS.with(|c| c.set(c.get() + 1));
}

/// One model was built on this thread.
pub(crate) fn built() {
    BUILDS.with(|c| c.set(c.get() + 1));
}

/// (validations, builds) on this thread since the last [`take`], and zero them.
pub(crate) fn take() -> (u32, u32) {
    (
        VALIDATIONS.with(|c| c.replace(0)),
        BUILDS.with(|c| c.replace(0)),
    )
}

/// One campaign was validated against the configs on this thread.
pub(crate) fn campaign_validated() {
    CAMPAIGN_VALIDATIONS.with(|c| c.set(c.get() + 1));
}

/// Campaign validations on this thread since the last call, and zero them.
pub(crate) fn take_campaign_validations() -> u32 {
    CAMPAIGN_VALIDATIONS.with(|c| c.replace(0))
}
