//! Reports: what a finished run is handed back as. A case run packaged into its outcome
//! (summary JSON, track samples, SVG plots: [`case`]), the plots of a case and of a
//! penalization curve ([`plots`]), and the dependency-free SVG writer they use ([`svg`]).

pub mod case;
pub mod plots;
pub mod svg;

pub use case::{package, run_case, run_case_from};
pub use plots::{case_plots, curve_plot};
