//! Reports: what a finished run is handed back as. A finished case run packaged into its
//! outcome (summary JSON, track samples, SVG plots: [`case`]), the plots of a case and of a
//! penalization curve ([`plots`]), and the figures they and the diagnosis draw with plotters
//! ([`figure`]).

pub mod case;
pub mod figure;
pub mod plots;

pub use case::{package, package_run};
pub use plots::{case_plots, curve_plot};
