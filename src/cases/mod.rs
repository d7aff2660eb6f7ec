//! The validated case, below everything that reads one: its one parser from a reference config
//! or an inline case object with overrides and a seed ([`resolve_config`], [`resolve_model`]),
//! the physical range of every case field ([`bounds`]) and the limits on run control and job
//! options ([`limits`]), a case run to its packaged outcome ([`run_case`]), and a wear law
//! carried from a diagnosis to a sweep ([`DiagnosedWearLaw`]).
//!
//! It stands below `validation`, `gap` and `pipeline`, which all read cases: `pipeline` parses
//! each job kind's params with it (and re-exports it for the service), the campaigns and the
//! virtual rig resolve their tests' cases with it. Not to be confused with
//! [`crate::models::case`], which builds a model from a case already validated here.

pub mod bounds;
mod diagnosed_wear;
pub mod limits;
mod resolve;
mod run;

pub use diagnosed_wear::{DiagnosedWearLaw, SweepWearLaw};
pub use limits::{check_grid_points, check_settle_s, check_window_s};
pub use resolve::{resolve_config, resolve_model, CaseSource};
pub use run::{run_case, run_case_from};

pub use crate::models::outcome::{CaseOutcome, RunError, SavedRun};
pub use crate::physics::control::{Progress, RecordChunk, RecordSink, RunControl};

/// Deep-merges `patch` into `base` (objects merge key by key; anything else replaces).
pub fn merge_json(base: &mut serde_json::Value, patch: &serde_json::Value) {
    match (base, patch) {
        (serde_json::Value::Object(b), serde_json::Value::Object(p)) => {
            for (k, v) in p {
                merge_json(b.entry(k.clone()).or_insert(serde_json::Value::Null), v);
            }
        }
        (b, p) => *b = p.clone(),
    }
}
