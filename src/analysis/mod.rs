//! Analysis: spectra, vibration dose value, calibration fits, rattle space, service-life
//! penalization, SVG plots.

pub mod calibration;
pub mod penalization;
pub mod rattle_space;
pub mod spectra;
pub mod svg;
pub mod vdv;
