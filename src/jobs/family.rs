//! A fanned-out job's progress from its children's (issue 29: a sweep showed `fraction` 0 and
//! no `eta_s` while its points ran, because the stored progress of a parent counts only the
//! children that succeeded). Read when a parent is shown, not stored: the children's own
//! heartbeats keep it current.
//!
//! The ETA counts whole points, not simulated time: a point's wall time also holds what its
//! fraction does not see (the claim, the model's build, the cheap settle that runs its
//! fraction ahead, storing the result), which made the sweep's ETA start about a third low
//! when it extrapolated the mean fraction. Once a point has finished, the measured duration
//! of finished points is the estimate of every point's.

use super::{JobProgress, JobRecord, JobStatus};
use crate::store::{JobFilter, PageRequest, Store, StoreError};

/// Most children read per page (a sweep has at most `pipeline::limits::MAX_SWEEP_RUNS`).
const PAGE: i64 = 100;

/// The progress of a parent with `total` children from the children's records at `now_ms`:
/// the fraction is the mean over all children (a succeeded child counts 1, a running one its
/// own fraction, a queued one 0), the simulated times are the children's sums (a child not yet
/// started counts the mean end time of those that did). The ETA is [`points_eta_s`]; before
/// any point has a measured duration, each running point's duration is extrapolated from its
/// own fraction.
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
    // A point whose fraction reads 1 may still be storing its result: while one runs, the ETA
    // is the points'.
    let eta_s = started_ms
        .and_then(|_| points_eta_s(children, total, now_ms))
        .or((fraction >= 1.0).then_some(0.0));
    Some(JobProgress {
        simulated_time_s: simulated,
        end_time_s,
        fraction,
        eta_s,
    })
}

/// Time until the last of `total` points is done, s, with the points still to run shared by
/// the points running now (the workers' number): `(Σ max(D - age_i, 0) + queued · D) /
/// running`, where `D` is the mean wall time of the points that succeeded (claim to finish),
/// or, before any has, the mean of the running points' own extrapolations `age_i /
/// fraction_i`. None when nothing runs or nothing can be measured yet.
pub fn points_eta_s(children: &[JobRecord], total: usize, now_ms: i64) -> Option<f64> {
    let seconds = |ms: i64| ms.max(0) as f64 / 1000.0;
    let mut finished = Vec::new();
    let mut running = Vec::new();
    for child in children {
        match (child.status, child.started_ms, child.finished_ms) {
            (JobStatus::Succeeded, Some(start), Some(end)) => finished.push(seconds(end - start)),
            (JobStatus::Succeeded, ..) => finished.push(f64::NAN),
            (JobStatus::Running, Some(start), _) => running.push((
                seconds(now_ms - start),
                child.progress.map_or(0.0, |p| p.fraction),
            )),
            _ => {}
        }
    }
    if running.is_empty() {
        return None;
    }
    let measured: Vec<f64> = finished.iter().copied().filter(|d| d.is_finite()).collect();
    let per_point = if measured.is_empty() {
        let extrapolated: Vec<f64> = running
            .iter()
            .filter(|(_, f)| f.is_finite() && *f > 0.0)
            .map(|(age, f)| age / f.min(1.0))
            .collect();
        if extrapolated.is_empty() {
            return None;
        }
        extrapolated.iter().sum::<f64>() / extrapolated.len() as f64
    } else {
        measured.iter().sum::<f64>() / measured.len() as f64
    };
    let queued = total.saturating_sub(finished.len() + running.len()) as f64;
    let left: f64 = running
        .iter()
        .map(|(age, _)| (per_point - age).max(0.0))
        .sum();
    Some((left + queued * per_point) / running.len() as f64)
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

    /// A child claimed at `started_s` (and finished at `finished_s`), s on the test's clock.
    fn timed(
        status: JobStatus,
        fraction: f64,
        started_s: i64,
        finished_s: Option<i64>,
    ) -> JobRecord {
        JobRecord {
            started_ms: Some(started_s * 1000),
            finished_ms: finished_s.map(|s| s * 1000),
            ..child(status, Some(fraction))
        }
    }

    #[test]
    fn a_parent_counts_its_running_children_by_their_fraction() {
        // Four points: one done (claimed at 1 s, done at 41 s), two half way since 41 s, one
        // queued. Fraction (1 + 0.5 + 0.5 + 0) / 4 = 0.5.
        let children = [
            timed(JobStatus::Succeeded, 1.0, 1, Some(41)),
            timed(JobStatus::Running, 0.5, 41, None),
            timed(JobStatus::Running, 0.5, 41, None),
            child(JobStatus::Queued, None),
        ];
        let p = parent_progress(&children, 4, Some(1_000), 61_000).unwrap();
        assert!((p.fraction - 0.5).abs() < 1e-12);
        // A point takes 40 s: the running two need 20 s more, then the queued one 40 s on one
        // of the two workers: (20 + 20 + 40) / 2 = 40 s.
        assert!((p.eta_s.unwrap() - 40.0).abs() < 1e-9, "{p:?}");
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

    #[test]
    fn the_eta_of_points_with_unseen_overhead_is_the_closed_form() {
        // Six points on two workers in waves of two; each point takes 10 s of wall time of
        // which its fraction sees 7 s (a cheap settle and the storing of its result are not
        // in it): fraction = min(age / 7, 1). The sweep ends at 30 s, so at time t the
        // answer is 30 - t.
        let fraction = |age: i64| (age as f64 / 7.0).min(1.0);
        let at = |t: i64| {
            let mut children = Vec::new();
            for wave in 0..3 {
                let start = 10 * wave;
                for _ in 0..2 {
                    children.push(if t >= start + 10 {
                        timed(JobStatus::Succeeded, 1.0, start, Some(start + 10))
                    } else if t >= start {
                        timed(JobStatus::Running, fraction(t - start), start, None)
                    } else {
                        child(JobStatus::Queued, None)
                    });
                }
            }
            parent_progress(&children, 6, Some(0), t * 1000).unwrap()
        };
        for t in [12, 15, 18, 21, 25, 29] {
            let eta = at(t).eta_s.unwrap();
            assert!(
                (eta - (30 - t) as f64).abs() < 1e-9,
                "at {t} s: ETA {eta} s"
            );
        }
        // Before any point has finished the points' own rates are all there is: at 5 s the
        // running pair reads 5/7 done, so a point seems to take 7 s, and the ETA is 16 s where
        // 25 s remain; the mean-fraction extrapolation gave the same.
        let early = at(5);
        assert!((early.eta_s.unwrap() - 16.0).abs() < 1e-9, "{early:?}");
        let old = 5.0 * (1.0 - early.fraction) / early.fraction;
        assert!((old - 16.0).abs() < 1e-9);
        // At 15 s the mean-fraction extrapolation said 11.25 s where 15 s remain (a quarter
        // low); the measured durations give 15 s.
        let mid = at(15);
        let old = 15.0 * (1.0 - mid.fraction) / mid.fraction;
        assert!((old - 11.25).abs() < 1e-9, "{old}");
    }
}
