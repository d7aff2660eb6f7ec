//! Analysis: spectra, vibration dose value, calibration fits, rattle space, service-life
//! penalization. Plots are drawn by [`crate::report`].

pub mod calibration;
pub mod penalization;
pub mod rattle_space;
pub mod spectra;
pub mod vdv;
