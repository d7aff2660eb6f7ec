//! analysis
pub mod spectra;
pub mod svg;
pub mod vdv;
