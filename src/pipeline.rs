//! The one narrow interface between the service (jobs) and the simulation library.
//!
//! A job hands a case configuration (JSON, the same schema as the TOML files in `configs/`)
//! and a [`RunControl`]; it gets back a [`CaseOutcome`] or a [`RunError`].

use crate::physics::track::TrackSample;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Progress of a running simulation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    /// Simulated time reached, s.
    pub simulated_time_s: f64,
    /// Simulated time at which the run ends, s.
    pub end_time_s: f64,
    /// Fraction done in [0, 1].
    pub fraction: f64,
}

/// Cancellation flag and progress sink handed to a run.
#[derive(Clone)]
pub struct RunControl {
    /// Set to true to stop the run; it returns [`RunError::Cancelled`] within a second.
    pub cancel: Arc<AtomicBool>,
    /// Called from the simulation thread, at most a few times per second.
    pub progress: Arc<dyn Fn(Progress) + Send + Sync>,
}

impl RunControl {
    /// A control that is never cancelled and drops progress.
    pub fn silent() -> Self {
        Self {
            cancel: Arc::new(AtomicBool::new(false)),
            progress: Arc::new(|_| {}),
        }
    }

    /// True once cancellation was requested.
    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

/// What a finished case produces.
#[derive(Debug, Clone)]
pub struct CaseOutcome {
    /// Summary: wear per contact and body (mg, mg/h), above-cutoff work share, pressure PDFs,
    /// spectra, settings used. JSON object.
    pub summary: serde_json::Value,
    /// Recorded contact-track samples (may be many).
    pub tracks: Vec<TrackSample>,
    /// Named SVG plots: (file name, SVG text).
    pub plots: Vec<(String, String)>,
}

/// Why a run did not produce an outcome.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The configuration broke a rule; `field` is a dotted path into the config.
    #[error("invalid configuration: field `{field}` {rule}")]
    InvalidConfig { field: String, rule: String },
    /// The simulation diverged; the message names time, body, contact and energy.
    #[error("simulation diverged: {0}")]
    Diverged(String),
    /// Cancelled through [`RunControl::cancel`].
    #[error("cancelled")]
    Cancelled,
}
