//! analysis

pub mod calibration;
