//! The three thesis models (persistent-contact fixture, rattle box, launcher): build a
//! multibody system from a config and run it with wear post-processing.

pub mod case;
pub mod case_run;
pub mod checkpoint;
#[cfg(test)]
pub(crate) mod counts;
pub mod launcher;
pub mod motion;
pub mod outcome;
pub mod persistent_contact;
pub mod rattle_box;
pub mod reference;
pub mod run;
pub mod spec;
#[cfg(test)]
mod system_tests;
