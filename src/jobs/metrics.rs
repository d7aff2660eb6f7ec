//! Prometheus metrics of the job system, rendered as text exposition format by `/metrics`.

use super::model::{JobKind, JobStatus};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::sync::Mutex;
use std::time::Instant;
use uuid::Uuid;

/// Upper bounds of the job-duration histogram buckets, s.
const DURATION_BUCKETS_S: [f64; 10] = [0.1, 0.5, 1.0, 5.0, 10.0, 30.0, 60.0, 300.0, 900.0, 3600.0];

#[derive(Default)]
struct Histogram {
    counts: [u64; DURATION_BUCKETS_S.len()],
    count: u64,
    sum_s: f64,
}

#[derive(Default)]
struct Inner {
    durations: HashMap<(&'static str, &'static str), Histogram>,
    simulated_s_total: f64,
    /// Running attempts in this process: (start, simulated seconds reached).
    running: HashMap<Uuid, (Instant, f64)>,
}

/// Counters and gauges of this process.
#[derive(Default)]
pub struct Metrics {
    inner: Mutex<Inner>,
}

impl Metrics {
    fn with<R>(&self, f: impl FnOnce(&mut Inner) -> R) -> R {
        let mut guard = match self.inner.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        f(&mut guard)
    }

    /// An attempt started in this process.
    pub fn attempt_started(&self, id: Uuid) {
        self.with(|m| {
            m.running.insert(id, (Instant::now(), 0.0));
        });
    }

    /// Progress of a running attempt: simulated time reached, s.
    pub fn attempt_progress(&self, id: Uuid, simulated_time_s: f64) {
        self.with(|m| {
            if let Some(entry) = m.running.get_mut(&id) {
                if simulated_time_s.is_finite() && simulated_time_s > entry.1 {
                    m.simulated_s_total += simulated_time_s - entry.1;
                    entry.1 = simulated_time_s;
                }
            }
        });
    }

    /// An attempt ended with `status`.
    pub fn attempt_finished(&self, id: Uuid, kind: JobKind, status: JobStatus) {
        self.with(|m| {
            if let Some((start, _)) = m.running.remove(&id) {
                let seconds = start.elapsed().as_secs_f64();
                let h = m
                    .durations
                    .entry((kind.as_str(), status.as_str()))
                    .or_default();
                for (slot, bound) in h.counts.iter_mut().zip(DURATION_BUCKETS_S) {
                    if seconds <= bound {
                        *slot += 1;
                    }
                }
                h.count += 1;
                h.sum_s += seconds;
            }
        });
    }

    /// Prometheus text with the given job counts per status (queue depth from the store).
    pub fn render(&self, counts: &[(JobStatus, i64)]) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "# HELP railwear_jobs Jobs in the store by status (queue depth = queued)."
        );
        let _ = writeln!(out, "# TYPE railwear_jobs gauge");
        for (status, n) in counts {
            let _ = writeln!(out, "railwear_jobs{{status=\"{}\"}} {n}", status.as_str());
        }
        let queued = counts
            .iter()
            .find(|(s, _)| *s == JobStatus::Queued)
            .map_or(0, |(_, n)| *n);
        let _ = writeln!(
            out,
            "# HELP railwear_queue_depth Jobs waiting for a worker."
        );
        let _ = writeln!(out, "# TYPE railwear_queue_depth gauge");
        let _ = writeln!(out, "railwear_queue_depth {queued}");
        self.with(|m| {
            let _ = writeln!(
                out,
                "# HELP railwear_job_duration_seconds Wall time of finished attempts in this process."
            );
            let _ = writeln!(out, "# TYPE railwear_job_duration_seconds histogram");
            let mut keys: Vec<_> = m.durations.keys().copied().collect();
            keys.sort();
            for key in keys {
                let Some(h) = m.durations.get(&key) else {
                    continue;
                };
                let labels = format!("kind=\"{}\",status=\"{}\"", key.0, key.1);
                for (count, bound) in h.counts.iter().zip(DURATION_BUCKETS_S) {
                    let _ = writeln!(
                        out,
                        "railwear_job_duration_seconds_bucket{{{labels},le=\"{bound}\"}} {count}"
                    );
                }
                let _ = writeln!(
                    out,
                    "railwear_job_duration_seconds_bucket{{{labels},le=\"+Inf\"}} {}",
                    h.count
                );
                let _ = writeln!(out, "railwear_job_duration_seconds_sum{{{labels}}} {}", h.sum_s);
                let _ = writeln!(out, "railwear_job_duration_seconds_count{{{labels}}} {}", h.count);
            }
            let _ = writeln!(
                out,
                "# HELP railwear_simulated_seconds_total Simulated time advanced by this process, s."
            );
            let _ = writeln!(out, "# TYPE railwear_simulated_seconds_total counter");
            let _ = writeln!(out, "railwear_simulated_seconds_total {}", m.simulated_s_total);
            let rate: f64 = m
                .running
                .values()
                .map(|(start, sim)| {
                    let wall = start.elapsed().as_secs_f64();
                    if wall > 0.0 {
                        sim / wall
                    } else {
                        0.0
                    }
                })
                .sum();
            let _ = writeln!(
                out,
                "# HELP railwear_simulated_seconds_per_second Simulated seconds per wall second, summed over running attempts."
            );
            let _ = writeln!(out, "# TYPE railwear_simulated_seconds_per_second gauge");
            let _ = writeln!(out, "railwear_simulated_seconds_per_second {rate}");
            let _ = writeln!(out, "# HELP railwear_running_attempts Attempts running in this process.");
            let _ = writeln!(out, "# TYPE railwear_running_attempts gauge");
            let _ = writeln!(out, "railwear_running_attempts {}", m.running.len());
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn histogram_counts_cumulatively() {
        let metrics = Metrics::default();
        let id = Uuid::new_v4();
        metrics.attempt_started(id);
        metrics.attempt_progress(id, 2.0);
        metrics.attempt_progress(id, 1.0); // progress never goes back
        metrics.attempt_finished(id, JobKind::Simulate, JobStatus::Succeeded);
        let text = metrics.render(&[(JobStatus::Queued, 4)]);
        assert!(text.contains("railwear_queue_depth 4"));
        assert!(text.contains("railwear_simulated_seconds_total 2"));
        assert!(text.contains(
            "railwear_job_duration_seconds_bucket{kind=\"simulate\",status=\"succeeded\",le=\"3600\"} 1"
        ));
        assert!(text.contains(
            "railwear_job_duration_seconds_count{kind=\"simulate\",status=\"succeeded\"} 1"
        ));
        assert!(text.contains("railwear_running_attempts 0"));
    }
}
