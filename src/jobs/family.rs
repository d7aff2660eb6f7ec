//! A fanned-out job's progress from its children's (issue 29: a sweep showed `fraction` 0 and
//! no `eta_s` while its points ran, because the stored progress of a parent counts only the
//! children that succeeded). Read when a parent is shown, not stored: the children's own
//! heartbeats keep it current.

use super::{JobProgress, JobRecord, JobStatus};
use crate::store::{JobFilter, PageRequest, Store, StoreError};

/// Most children read per page (a sweep has at most `pipeline::limits::MAX_SWEEP_RUNS`).
const PAGE: i64 = 100;

/// The progress of a parent with `total` children from the children's records: the fraction
/// is the mean over all children (a succeeded child counts 1, a running one its own fraction,
/// a queued one 0), the simulated times are the children's sums (a child not yet started
/// counts the mean end time of those that did), and the ETA extrapolates the rate since
/// `started_ms` (the parent's fan-out).
pub fn parent_progress(
    children: &[JobRecord],
    total: usize,
    started_ms: Option<i64>,
    now_ms: i64,
) -> Option<JobProgress> {
    if total == 0 {
        return None;
    }
    let mut done = 0.0;
    let mut simulated = 0.0;
    let mut ends = Vec::new();
    for child in children {
        let fraction = match child.status {
            JobStatus::Succeeded => 1.0,
            _ => child.progress.map_or(0.0, |p| p.fraction).clamp(0.0, 1.0),
        };
        done += if fraction.is_finite() { fraction } else { 0.0 };
        if let Some(p) = child.progress {
            if p.simulated_time_s.is_finite() && p.end_time_s.is_finite() {
                simulated += p.simulated_time_s;
                ends.push(p.end_time_s);
            }
        }
    }
    let fraction = (done / total as f64).clamp(0.0, 1.0);
    let mean_end = if ends.is_empty() {
        0.0
    } else {
        ends.iter().sum::<f64>() / ends.len() as f64
    };
    let end_time_s = ends.iter().sum::<f64>() + mean_end * (total - ends.len()) as f64;
    let elapsed_s = started_ms.map(|s| (now_ms - s).max(0) as f64 / 1000.0);
    let eta_s = match elapsed_s {
        Some(e) if fraction > 0.0 && fraction < 1.0 => Some(e * (1.0 - fraction) / fraction),
        Some(_) if fraction >= 1.0 => Some(0.0),
        _ => None,
    };
    Some(JobProgress {
        simulated_time_s: simulated,
        end_time_s,
        fraction,
        eta_s,
    })
}

/// The live progress of `job` if it is a parent waiting for its children (else `None`: its
/// own stored progress stands).
pub async fn live_parent_progress(
    store: &dyn Store,
    job: &JobRecord,
    now_ms: i64,
) -> Result<Option<JobProgress>, StoreError> {
    let Some(counts) = job.children else {
        return Ok(None);
    };
    if job.status != JobStatus::Waiting || counts.total <= 0 {
        return Ok(None);
    }
    let mut children = Vec::new();
    let mut after_seq = None;
    loop {
        let page = store
            .list_jobs(
                PageRequest {
                    limit: PAGE,
                    after_seq,
                },
                JobFilter {
                    status: None,
                    parent: Some(job.id),
                    top_level: false,
                },
            )
            .await?;
        let last = page.items.last().map(|j| j.seq);
        let full = page.items.len() as i64 == PAGE;
        children.extend(page.items);
        match last {
            Some(seq) if full && children.len() < counts.total as usize => after_seq = Some(seq),
            _ => break,
        }
    }
    Ok(parent_progress(
        &children,
        counts.total as usize,
        job.started_ms,
        now_ms,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn child(status: JobStatus, fraction: Option<f64>) -> JobRecord {
        JobRecord {
            id: uuid::Uuid::new_v4(),
            seq: 0,
            kind: super::super::JobKind::SweepPoint,
            status,
            params: serde_json::json!({}),
            seed: 0,
            code_version: String::new(),
            submitted_by: "t".into(),
            attempt: 0,
            cancel_requested: false,
            created_ms: 0,
            started_ms: None,
            finished_ms: None,
            progress: fraction.map(|f| JobProgress {
                simulated_time_s: 10.0 * f,
                end_time_s: 10.0,
                fraction: f,
                eta_s: None,
            }),
            result: None,
            error: None,
            track_samples: 0,
            curve_key: None,
            lease_owner: None,
            parent: None,
            children: None,
        }
    }

    #[test]
    fn a_parent_counts_its_running_children_by_their_fraction() {
        // Four points: one done, two half way, one queued: (1 + 0.5 + 0.5 + 0) / 4 = 0.5;
        // after 60 s at that rate, 60 s remain.
        let children = [
            child(JobStatus::Succeeded, Some(1.0)),
            child(JobStatus::Running, Some(0.5)),
            child(JobStatus::Running, Some(0.5)),
            child(JobStatus::Queued, None),
        ];
        let p = parent_progress(&children, 4, Some(1_000), 61_000).unwrap();
        assert!((p.fraction - 0.5).abs() < 1e-12);
        assert!((p.eta_s.unwrap() - 60.0).abs() < 1e-9);
        // Simulated time: 10 + 5 + 5 of 4 x 10 s.
        assert!((p.simulated_time_s - 20.0).abs() < 1e-12);
        assert!((p.end_time_s - 40.0).abs() < 1e-12);
        // Nothing started yet: fraction 0, no ETA.
        let idle = [
            child(JobStatus::Queued, None),
            child(JobStatus::Queued, None),
        ];
        let p = parent_progress(&idle, 2, Some(0), 5_000).unwrap();
        assert_eq!((p.fraction, p.eta_s), (0.0, None));
    }
}
