//! models

pub mod specs;
