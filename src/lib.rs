//! railwear: wear of missile-launcher rails and missile shoes in captive carry.
//!
//! The modules are floors that follow the data (see ARCHITECTURE.md, "Floors"): geometry ->
//! physics -> wear -> models -> report -> cases -> gap -> pipeline -> jobs -> http, each
//! importing only the floors below it.
//!
//! Units: SI inside the engine (m, kg, s, N, Pa). See [`units`] for the
//! conversions from the thesis' ADAMS units (mm, kg, s, N).

// `!(x > 0.0)` is used on purpose throughout input validation: it rejects NaN, which the
// "simplified" `x <= 0.0` would let through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Numerical kernels index several equally sized arrays in one loop; iterator zips would hide
// the algebra.
#![allow(clippy::needless_range_loop)]

pub mod analysis;
pub mod cases;
pub mod cli;
pub mod config;
pub mod contact_models;
pub mod excitation;
pub mod field_error;
/// The house rules (import floors, file length), checked on the source tree.
#[cfg(test)]
mod floors;
pub mod gap;
pub mod geometry;
pub mod http;
pub mod jobs;
pub mod models;
pub mod parameters;
pub mod physics;
pub mod pipeline;
pub mod report;
pub mod sampling;
pub mod service_life;
pub mod store;
#[doc(hidden)]
pub mod thesis;
pub mod units;
pub mod validation;
pub mod wear;
