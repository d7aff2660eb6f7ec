//! Prometheus metrics of the job system, rendered as text exposition format by `/metrics`.

use super::model::{JobKind, JobStatus};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::sync::Mutex;
use std::time::Instant;
use uuid::Uuid;

/// Upper bounds of the job-duration histogram buckets, s.
const DURATION_BUCKETS_S: [f64; 10] = [0.1, 0.5, 1.0, 5.0, 10.0, 30.0, 60.0, 300.0, 900.0, 3600.0];

/// Upper bounds of the HTTP request-latency histogram buckets, s.
const HTTP_BUCKETS_S: [f64; 12] = [
    0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 10.0,
];

/// A cumulative histogram over the bucket bounds `N` of its kind.
struct Histogram<const N: usize> {
    counts: [u64; N],
    count: u64,
    sum_s: f64,
}

impl<const N: usize> Default for Histogram<N> {
    fn default() -> Self {
        Self {
            counts: [0; N],
            count: 0,
            sum_s: 0.0,
        }
    }
}

impl<const N: usize> Histogram<N> {
    fn observe(&mut self, bounds: &[f64; N], seconds: f64) {
        for (slot, bound) in self.counts.iter_mut().zip(bounds) {
            if seconds <= *bound {
                *slot += 1;
            }
        }
        self.count += 1;
        self.sum_s += seconds;
    }
}

/// A labelled histogram metric: HELP, TYPE and each label set's series, label sets sorted.
fn histogram<K: Ord + std::hash::Hash, const N: usize>(
    out: &mut String,
    name: &str,
    help: &str,
    bounds: &[f64; N],
    series: &HashMap<K, Histogram<N>>,
    labels: impl Fn(&K) -> String,
) {
    let _ = writeln!(out, "# HELP {name} {help}");
    let _ = writeln!(out, "# TYPE {name} histogram");
    let mut keys: Vec<&K> = series.keys().collect();
    keys.sort();
    for key in keys {
        let h = &series[key];
        histogram_series(
            out,
            name,
            &labels(key),
            h.counts.iter().copied().zip(bounds.iter().copied()),
            h.count,
            h.sum_s,
        );
    }
}

/// One unlabelled metric: its HELP and TYPE lines and its value.
fn scalar(out: &mut String, name: &str, kind: &str, help: &str, value: impl std::fmt::Display) {
    let _ = writeln!(out, "# HELP {name} {help}");
    let _ = writeln!(out, "# TYPE {name} {kind}");
    let _ = writeln!(out, "{name} {value}");
}

/// One labelled series of a histogram: its cumulative buckets (`le` = each bound, then
/// `+Inf`), sum and count.
fn histogram_series(
    out: &mut String,
    name: &str,
    labels: &str,
    buckets: impl Iterator<Item = (u64, f64)>,
    count: u64,
    sum_s: f64,
) {
    for (n, bound) in buckets {
        let _ = writeln!(out, "{name}_bucket{{{labels},le=\"{bound}\"}} {n}");
    }
    let _ = writeln!(out, "{name}_bucket{{{labels},le=\"+Inf\"}} {count}");
    let _ = writeln!(out, "{name}_sum{{{labels}}} {}", num(sum_s));
    let _ = writeln!(out, "{name}_count{{{labels}}} {count}");
}

/// A number as Prometheus text, never `-0` (an empty float sum is -0.0 in Rust).
fn num(x: f64) -> f64 {
    x + 0.0
}

#[derive(Default)]
struct Inner {
    durations: HashMap<(&'static str, &'static str), Histogram<{ DURATION_BUCKETS_S.len() }>>,
    /// HTTP requests by (method, route template): latency histogram.
    http_latency: HashMap<(String, String), Histogram<{ HTTP_BUCKETS_S.len() }>>,
    /// HTTP requests by (method, route template, status code).
    http_requests: HashMap<(String, String, u16), u64>,
    simulated_s_total: f64,
    /// Running attempts in this process: (start, simulated seconds reached, simulated seconds
    /// it resumed from).
    running: HashMap<Uuid, (Instant, f64, f64)>,
    /// Attempts given back at shutdown, without and with a checkpoint.
    released: [u64; 2],
    /// Simulated time kept by the checkpoints of released attempts, s.
    checkpointed_s_total: f64,
    /// Attempts that resumed from a stored checkpoint.
    resumed: u64,
}

impl Inner {
    /// One job (or attempt) of `kind` that ended with `status` after `seconds`.
    fn observe(&mut self, kind: JobKind, status: JobStatus, seconds: f64) {
        self.durations
            .entry((kind.as_str(), status.as_str()))
            .or_default()
            .observe(&DURATION_BUCKETS_S, seconds);
    }
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
            m.running.insert(id, (Instant::now(), 0.0, 0.0));
        });
    }

    /// A running attempt resumes from a checkpoint at `simulated_time_s`: the time before it
    /// was simulated by an earlier attempt and is not counted again.
    pub fn attempt_resumed(&self, id: Uuid, simulated_time_s: f64) {
        self.with(|m| {
            if let Some(entry) = m.running.get_mut(&id) {
                if simulated_time_s.is_finite() {
                    entry.1 = entry.1.max(simulated_time_s);
                    entry.2 = simulated_time_s;
                }
                m.resumed += 1;
            }
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

    /// An attempt ended with `status`: its wall time goes to the duration histogram.
    pub fn attempt_finished(&self, id: Uuid, kind: JobKind, status: JobStatus) {
        self.with(|m| {
            if let Some((start, _, _)) = m.running.remove(&id) {
                m.observe(kind, status, start.elapsed().as_secs_f64());
            }
        });
    }

    /// An attempt was given back at shutdown (with a checkpoint at `checkpoint_s` simulated
    /// seconds, if it stored one): no longer running here, not a finished job.
    pub fn attempt_released(&self, id: Uuid, checkpoint_s: Option<f64>) {
        self.with(|m| {
            let resumed_from = m.running.remove(&id).map_or(0.0, |r| r.2);
            m.released[usize::from(checkpoint_s.is_some())] += 1;
            if let Some(t) = checkpoint_s.filter(|t| t.is_finite()) {
                m.checkpointed_s_total += (t - resumed_from).max(0.0);
            }
        });
    }

    /// The attempt that ended a fanned-out job (a sweep's assembly) ended with `status`; the
    /// job took `whole_s` from its first claim (fan-out, children, assembly), which is what the
    /// duration histogram counts for it, not the assembly alone.
    pub fn fanned_out_job_finished(
        &self,
        id: Uuid,
        kind: JobKind,
        status: JobStatus,
        whole_s: f64,
    ) {
        self.with(|m| {
            m.running.remove(&id);
            m.observe(kind, status, whole_s.max(0.0));
        });
    }

    /// A fanned-out job ended without an attempt of its own (a child's failure failed it),
    /// `whole_s` after its first claim.
    pub fn job_ended(&self, kind: JobKind, status: JobStatus, whole_s: f64) {
        self.with(|m| m.observe(kind, status, whole_s.max(0.0)));
    }

    /// One HTTP request answered: `route` is the matched route template (`/v1/jobs/{id}`), or
    /// `unmatched`, so the label set stays bounded.
    pub fn http_request(&self, method: &str, route: &str, status: u16, seconds: f64) {
        self.with(|m| {
            *m.http_requests
                .entry((method.to_string(), route.to_string(), status))
                .or_default() += 1;
            m.http_latency
                .entry((method.to_string(), route.to_string()))
                .or_default()
                .observe(&HTTP_BUCKETS_S, seconds);
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
        scalar(
            &mut out,
            "railwear_queue_depth",
            "gauge",
            "Jobs waiting for a worker.",
            queued,
        );
        self.with(|m| {
            histogram(
                &mut out,
                "railwear_job_duration_seconds",
                "Wall time of jobs ended by this process: an attempt's, or for a job that fanned out (a sweep) the whole job's, from its first claim through its children to its assembly.",
                &DURATION_BUCKETS_S,
                &m.durations,
                |(kind, status)| format!("kind=\"{kind}\",status=\"{status}\""),
            );
            scalar(
                &mut out,
                "railwear_simulated_seconds_total",
                "counter",
                "Simulated time advanced by this process, s.",
                num(m.simulated_s_total),
            );
            let rate = m.running.values().fold(0.0, |acc, (start, sim, from)| {
                let wall = start.elapsed().as_secs_f64();
                if wall > 0.0 {
                    acc + (sim - from) / wall
                } else {
                    acc
                }
            });
            scalar(
                &mut out,
                "railwear_simulated_seconds_per_second",
                "gauge",
                "Simulated seconds per wall second, summed over running attempts.",
                num(rate),
            );
            scalar(
                &mut out,
                "railwear_running_attempts",
                "gauge",
                "Attempts running in this process.",
                m.running.len(),
            );
            let _ = writeln!(
                out,
                "# HELP railwear_attempts_released_total Attempts this process gave back at shutdown, by whether they stored a checkpoint."
            );
            let _ = writeln!(out, "# TYPE railwear_attempts_released_total counter");
            for (i, label) in ["false", "true"].iter().enumerate() {
                let _ = writeln!(
                    out,
                    "railwear_attempts_released_total{{checkpoint=\"{label}\"}} {}",
                    m.released[i]
                );
            }
            scalar(
                &mut out,
                "railwear_checkpointed_simulated_seconds_total",
                "counter",
                "Simulated time the checkpoints of released attempts kept (not simulated again by the next attempt), s.",
                num(m.checkpointed_s_total),
            );
            scalar(
                &mut out,
                "railwear_attempts_resumed_total",
                "counter",
                "Attempts this process started from a stored checkpoint.",
                m.resumed,
            );
            let _ = writeln!(
                out,
                "# HELP railwear_http_requests_total HTTP requests answered by this process, by method, route and status."
            );
            let _ = writeln!(out, "# TYPE railwear_http_requests_total counter");
            let mut keys: Vec<_> = m.http_requests.keys().cloned().collect();
            keys.sort();
            for key in keys {
                let n = m.http_requests.get(&key).copied().unwrap_or(0);
                let _ = writeln!(
                    out,
                    "railwear_http_requests_total{{method=\"{}\",route=\"{}\",status=\"{}\"}} {n}",
                    key.0, key.1, key.2
                );
            }
            histogram(
                &mut out,
                "railwear_http_request_duration_seconds",
                "Latency of HTTP requests answered by this process, by method and route.",
                &HTTP_BUCKETS_S,
                &m.http_latency,
                |(method, route)| format!("method=\"{method}\",route=\"{route}\""),
            );
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

    #[test]
    fn a_fanned_out_job_counts_whole() {
        let metrics = Metrics::default();
        let id = Uuid::new_v4();
        metrics.attempt_started(id);
        metrics.fanned_out_job_finished(id, JobKind::Sweep, JobStatus::Succeeded, 42.0);
        metrics.job_ended(JobKind::Sweep, JobStatus::Failed, 7.5);
        let text = metrics.render(&[]);
        assert!(text
            .contains("railwear_job_duration_seconds_sum{kind=\"sweep\",status=\"succeeded\"} 42"));
        assert!(text.contains(
            "railwear_job_duration_seconds_bucket{kind=\"sweep\",status=\"succeeded\",le=\"30\"} 0"
        ));
        assert!(text
            .contains("railwear_job_duration_seconds_count{kind=\"sweep\",status=\"failed\"} 1"));
        assert!(text.contains("railwear_running_attempts 0"));
    }

    #[test]
    fn idle_metrics_never_print_negative_zero() {
        let text = Metrics::default().render(&[]);
        assert!(
            text.contains("railwear_simulated_seconds_per_second 0\n"),
            "{text}"
        );
        assert!(!text.contains("-0"), "{text}");
    }

    #[test]
    fn http_requests_are_counted_per_route_with_a_latency_histogram() {
        let metrics = Metrics::default();
        metrics.http_request("GET", "/v1/jobs/{id}", 200, 0.003);
        metrics.http_request("GET", "/v1/jobs/{id}", 404, 0.2);
        let text = metrics.render(&[]);
        assert!(text.contains(
            "railwear_http_requests_total{method=\"GET\",route=\"/v1/jobs/{id}\",status=\"200\"} 1"
        ));
        assert!(text.contains(
            "railwear_http_request_duration_seconds_bucket{method=\"GET\",route=\"/v1/jobs/{id}\",le=\"0.005\"} 1"
        ));
        assert!(text.contains(
            "railwear_http_request_duration_seconds_count{method=\"GET\",route=\"/v1/jobs/{id}\"} 2"
        ));
    }
}
