//! The engine's run hooks: a cancellation flag and a progress sink the caller hands to
//! [`simulate`](super::simulate::simulate) (the engine owns its hooks, as rapier's pipeline
//! does; the service passes them in through `pipeline`).

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
    /// Set to true to stop the run; it returns a cancellation error within a second.
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
