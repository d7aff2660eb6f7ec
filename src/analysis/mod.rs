//! analysis

pub mod penalization;
pub mod rattle_space;
