//! The three thesis models (persistent-contact fixture, rattle box, launcher): build a
//! multibody system from a config and run it with wear post-processing.

pub mod motion;
pub mod run;
pub mod specs;
