//! Prometheus metrics of the job system and the HTTP layer, served by `/metrics` in the
//! OpenMetrics text format ([`CONTENT_TYPE`]).
//!
//! The metric types, the registry and the exposition are `prometheus-client`'s (the Prometheus
//! project's Rust client); this module only says what is counted and when. What the store knows
//! (jobs per status) and what is true at scrape time (running attempts, their rate) is read at
//! [`Metrics::render`]; everything else accumulates in the registry's metrics as it happens.

use super::model::{JobKind, JobStatus};
use prometheus_client::encoding::text::{encode_eof, encode_registry};
use prometheus_client::encoding::EncodeLabelSet;
use prometheus_client::metrics::counter::Counter;
use prometheus_client::metrics::family::Family;
use prometheus_client::metrics::gauge::Gauge;
use prometheus_client::metrics::histogram::Histogram;
use prometheus_client::registry::{Registry, Unit};
use std::collections::HashMap;
use std::sync::atomic::AtomicU64;
use std::sync::Mutex;
use std::time::Instant;
use uuid::Uuid;

/// The media type of [`Metrics::render`]'s text (OpenMetrics 1.0, which Prometheus scrapes).
pub const CONTENT_TYPE: &str = "application/openmetrics-text; version=1.0.0; charset=utf-8";

/// Upper bounds of the job-duration histogram buckets, s.
const DURATION_BUCKETS_S: [f64; 10] = [0.1, 0.5, 1.0, 5.0, 10.0, 30.0, 60.0, 300.0, 900.0, 3600.0];

/// Upper bounds of the HTTP request-latency histogram buckets, s.
const HTTP_BUCKETS_S: [f64; 12] = [
    0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 10.0,
];

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct JobLabels {
    kind: &'static str,
    status: &'static str,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct StatusLabels {
    status: &'static str,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct CheckpointLabels {
    checkpoint: bool,
}

/// An HTTP request's method and matched route template (`/v1/jobs/{id}`, or `unmatched`), so
/// the label set stays bounded.
#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct RouteLabels {
    method: String,
    route: String,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct RouteStatusLabels {
    method: String,
    route: String,
    status: u16,
}

type HistogramFamily<L> = Family<L, Histogram, fn() -> Histogram>;
type FloatCounter = Counter<f64, AtomicU64>;
type FloatGauge = Gauge<f64, AtomicU64>;

fn duration_histogram() -> Histogram {
    Histogram::new(DURATION_BUCKETS_S)
}

fn http_histogram() -> Histogram {
    Histogram::new(HTTP_BUCKETS_S)
}

/// A running attempt in this process.
#[derive(Clone, Copy)]
struct Running {
    started: Instant,
    /// Simulated time reached, s.
    simulated_s: f64,
    /// Simulated time it resumed from (a checkpoint of an earlier attempt), s.
    resumed_from_s: f64,
}

/// Counters, gauges and histograms of this process.
pub struct Metrics {
    /// The metrics that accumulate, registered once; encoded after the scrape-time gauges.
    registry: Registry,
    job_duration: HistogramFamily<JobLabels>,
    simulated: FloatCounter,
    released: Family<CheckpointLabels, Counter>,
    checkpointed: FloatCounter,
    resumed: Counter,
    http_requests: Family<RouteStatusLabels, Counter>,
    http_latency: HistogramFamily<RouteLabels>,
    /// Attempts running here: what the rate gauge and the progress accounting read.
    running: Mutex<HashMap<Uuid, Running>>,
}

impl Default for Metrics {
    fn default() -> Self {
        let job_duration: HistogramFamily<JobLabels> =
            Family::new_with_constructor(duration_histogram);
        let simulated = FloatCounter::default();
        let released = Family::<CheckpointLabels, Counter>::default();
        let checkpointed = FloatCounter::default();
        let resumed = Counter::default();
        let http_requests = Family::<RouteStatusLabels, Counter>::default();
        let http_latency: HistogramFamily<RouteLabels> =
            Family::new_with_constructor(http_histogram);
        // Both label values of the released counter exist from the start (0 until counted).
        for checkpoint in [false, true] {
            drop(released.get_or_create(&CheckpointLabels { checkpoint }));
        }

        let mut registry = Registry::default();
        registry.register_with_unit(
            "railwear_job_duration",
            "Wall time of jobs ended by this process: an attempt's, or for a job that fanned out (a sweep) the whole job's, from its first claim through its children to its assembly",
            Unit::Seconds,
            job_duration.clone(),
        );
        registry.register_with_unit(
            "railwear_simulated",
            "Simulated time advanced by this process",
            Unit::Seconds,
            simulated.clone(),
        );
        registry.register(
            "railwear_attempts_released",
            "Attempts this process gave back at shutdown, by whether they stored a checkpoint",
            released.clone(),
        );
        registry.register_with_unit(
            "railwear_checkpointed_simulated",
            "Simulated time the checkpoints of released attempts kept (not simulated again by the next attempt)",
            Unit::Seconds,
            checkpointed.clone(),
        );
        registry.register(
            "railwear_attempts_resumed",
            "Attempts this process started from a stored checkpoint",
            resumed.clone(),
        );
        registry.register(
            "railwear_http_requests",
            "HTTP requests answered by this process, by method, route and status",
            http_requests.clone(),
        );
        registry.register_with_unit(
            "railwear_http_request_duration",
            "Latency of HTTP requests answered by this process, by method and route",
            Unit::Seconds,
            http_latency.clone(),
        );
        Metrics {
            registry,
            job_duration,
            simulated,
            released,
            checkpointed,
            resumed,
            http_requests,
            http_latency,
            running: Mutex::new(HashMap::new()),
        }
    }
}

impl Metrics {
    fn running<R>(&self, f: impl FnOnce(&mut HashMap<Uuid, Running>) -> R) -> R {
        let mut guard = match self.running.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        f(&mut guard)
    }

    /// One job (or attempt) of `kind` that ended with `status` after `seconds` of wall time.
    fn observe(&self, kind: JobKind, status: JobStatus, seconds: f64) {
        self.job_duration
            .get_or_create(&JobLabels {
                kind: kind.as_str(),
                status: status.as_str(),
            })
            .observe(seconds);
    }

    /// An attempt started in this process.
    pub fn attempt_started(&self, id: Uuid) {
        self.running(|running| {
            running.insert(
                id,
                Running {
                    started: Instant::now(),
                    simulated_s: 0.0,
                    resumed_from_s: 0.0,
                },
            );
        });
    }

    /// A running attempt resumes from a checkpoint at `simulated_time_s`: the time before it
    /// was simulated by an earlier attempt and is not counted again.
    pub fn attempt_resumed(&self, id: Uuid, simulated_time_s: f64) {
        self.running(|running| {
            if let Some(entry) = running.get_mut(&id) {
                if simulated_time_s.is_finite() {
                    entry.simulated_s = entry.simulated_s.max(simulated_time_s);
                    entry.resumed_from_s = simulated_time_s;
                }
                self.resumed.inc();
            }
        });
    }

    /// Progress of a running attempt: simulated time reached, s.
    pub fn attempt_progress(&self, id: Uuid, simulated_time_s: f64) {
        self.running(|running| {
            if let Some(entry) = running.get_mut(&id) {
                if simulated_time_s.is_finite() && simulated_time_s > entry.simulated_s {
                    self.simulated.inc_by(simulated_time_s - entry.simulated_s);
                    entry.simulated_s = simulated_time_s;
                }
            }
        });
    }

    /// An attempt ended with `status`: its wall time goes to the duration histogram.
    pub fn attempt_finished(&self, id: Uuid, kind: JobKind, status: JobStatus) {
        if let Some(run) = self.running(|running| running.remove(&id)) {
            self.observe(kind, status, run.started.elapsed().as_secs_f64());
        }
    }

    /// An attempt was given back at shutdown (with a checkpoint at `checkpoint_s` simulated
    /// seconds, if it stored one): no longer running here, not a finished job.
    pub fn attempt_released(&self, id: Uuid, checkpoint_s: Option<f64>) {
        let resumed_from = self
            .running(|running| running.remove(&id))
            .map_or(0.0, |run| run.resumed_from_s);
        self.released
            .get_or_create(&CheckpointLabels {
                checkpoint: checkpoint_s.is_some(),
            })
            .inc();
        if let Some(t) = checkpoint_s.filter(|t| t.is_finite()) {
            let kept = t - resumed_from;
            if kept > 0.0 {
                self.checkpointed.inc_by(kept);
            }
        }
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
        self.running(|running| running.remove(&id));
        self.observe(kind, status, whole_s.max(0.0));
    }

    /// A fanned-out job ended without an attempt of its own (a child's failure failed it),
    /// `whole_s` after its first claim.
    pub fn job_ended(&self, kind: JobKind, status: JobStatus, whole_s: f64) {
        self.observe(kind, status, whole_s.max(0.0));
    }

    /// One HTTP request answered: `route` is the matched route template (`/v1/jobs/{id}`), or
    /// `unmatched`, so the label set stays bounded.
    pub fn http_request(&self, method: &str, route: &str, status: u16, seconds: f64) {
        self.http_requests
            .get_or_create(&RouteStatusLabels {
                method: method.to_string(),
                route: route.to_string(),
                status,
            })
            .inc();
        self.http_latency
            .get_or_create(&RouteLabels {
                method: method.to_string(),
                route: route.to_string(),
            })
            .observe(seconds);
    }

    /// The OpenMetrics text ([`CONTENT_TYPE`]) with the given job counts per status (queue
    /// depth from the store).
    pub fn render(&self, counts: &[(JobStatus, i64)]) -> String {
        // What is true now: the store's counts and the attempts running at this moment.
        let mut now = Registry::default();
        let jobs = Family::<StatusLabels, Gauge>::default();
        for (status, n) in counts {
            jobs.get_or_create(&StatusLabels {
                status: status.as_str(),
            })
            .set(*n);
        }
        now.register(
            "railwear_jobs",
            "Jobs in the store by status (queue depth = queued)",
            jobs,
        );
        let queued = counts
            .iter()
            .find(|(s, _)| *s == JobStatus::Queued)
            .map_or(0, |(_, n)| *n);
        let queue_depth = Gauge::<i64>::default();
        queue_depth.set(queued);
        now.register(
            "railwear_queue_depth",
            "Jobs waiting for a worker",
            queue_depth,
        );
        let (rate, running) = self.running(|running| {
            let rate = running.values().fold(0.0, |acc, run| {
                let wall = run.started.elapsed().as_secs_f64();
                if wall > 0.0 {
                    acc + (run.simulated_s - run.resumed_from_s) / wall
                } else {
                    acc
                }
            });
            (rate, running.len())
        });
        let rate_gauge = FloatGauge::default();
        // `+ 0.0`: an empty sum is -0.0, which is not a number Prometheus users expect to see.
        rate_gauge.set(rate + 0.0);
        now.register(
            "railwear_simulated_seconds_per_second",
            "Simulated seconds per wall second, summed over running attempts",
            rate_gauge,
        );
        let running_gauge = Gauge::<i64>::default();
        running_gauge.set(i64::try_from(running).unwrap_or(i64::MAX));
        now.register(
            "railwear_running_attempts",
            "Attempts running in this process",
            running_gauge,
        );

        let mut out = String::new();
        // Writing to a String cannot fail.
        let _ = encode_registry(&mut out, &now)
            .and_then(|()| encode_registry(&mut out, &self.registry))
            .and_then(|()| encode_eof(&mut out));
        out
    }
}

#[cfg(test)]
mod tests {
    //! The text as `prometheus-client` writes it; tests/api/service_metrics.rs reads a live
    //! `/metrics` with the Prometheus project's OpenMetrics parser.
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
        assert!(text.ends_with("# EOF\n"), "{text}");
        for line in [
            "railwear_queue_depth 4\n",
            "railwear_jobs{status=\"queued\"} 4\n",
            "railwear_simulated_seconds_total 2.0\n",
            "railwear_job_duration_seconds_bucket{le=\"3600.0\",kind=\"simulate\",status=\"succeeded\"} 1\n",
            "railwear_job_duration_seconds_bucket{le=\"+Inf\",kind=\"simulate\",status=\"succeeded\"} 1\n",
            "railwear_job_duration_seconds_count{kind=\"simulate\",status=\"succeeded\"} 1\n",
            "railwear_running_attempts 0\n",
            "# UNIT railwear_job_duration_seconds seconds\n",
        ] {
            assert!(text.contains(line), "{line} in {text}");
        }
    }

    #[test]
    fn a_fanned_out_job_counts_whole() {
        let metrics = Metrics::default();
        let id = Uuid::new_v4();
        metrics.attempt_started(id);
        metrics.fanned_out_job_finished(id, JobKind::Sweep, JobStatus::Succeeded, 42.0);
        metrics.job_ended(JobKind::Sweep, JobStatus::Failed, 7.5);
        let text = metrics.render(&[]);
        for line in [
            "railwear_job_duration_seconds_sum{kind=\"sweep\",status=\"succeeded\"} 42.0\n",
            "railwear_job_duration_seconds_bucket{le=\"30.0\",kind=\"sweep\",status=\"succeeded\"} 0\n",
            "railwear_job_duration_seconds_bucket{le=\"60.0\",kind=\"sweep\",status=\"succeeded\"} 1\n",
            "railwear_job_duration_seconds_count{kind=\"sweep\",status=\"failed\"} 1\n",
            "railwear_running_attempts 0\n",
        ] {
            assert!(text.contains(line), "{line} in {text}");
        }
    }

    #[test]
    fn idle_metrics_never_print_negative_zero() {
        let text = Metrics::default().render(&[]);
        assert!(
            text.contains("railwear_simulated_seconds_per_second 0.0\n"),
            "{text}"
        );
        assert!(!text.contains(" -0"), "{text}");
        assert!(
            text.contains("railwear_attempts_released_total{checkpoint=\"false\"} 0\n"),
            "{text}"
        );
    }

    #[test]
    fn released_and_resumed_attempts_are_counted() {
        let metrics = Metrics::default();
        let id = Uuid::new_v4();
        metrics.attempt_started(id);
        metrics.attempt_resumed(id, 1.5);
        metrics.attempt_progress(id, 4.0);
        metrics.attempt_released(id, Some(3.5));
        let text = metrics.render(&[]);
        for line in [
            "railwear_attempts_resumed_total 1\n",
            "railwear_attempts_released_total{checkpoint=\"true\"} 1\n",
            // The checkpoint kept the 3.5 - 1.5 s that the earlier attempt had not kept.
            "railwear_checkpointed_simulated_seconds_total 2.0\n",
            // Resumed at 1.5 s: only the 2.5 s simulated here count.
            "railwear_simulated_seconds_total 2.5\n",
        ] {
            assert!(text.contains(line), "{line} in {text}");
        }
    }

    #[test]
    fn http_requests_are_counted_per_route_with_a_latency_histogram() {
        let metrics = Metrics::default();
        metrics.http_request("GET", "/v1/jobs/{id}", 200, 0.003);
        metrics.http_request("GET", "/v1/jobs/{id}", 404, 0.2);
        let text = metrics.render(&[]);
        for line in [
            "railwear_http_requests_total{method=\"GET\",route=\"/v1/jobs/{id}\",status=\"200\"} 1\n",
            "railwear_http_request_duration_seconds_bucket{le=\"0.005\",method=\"GET\",route=\"/v1/jobs/{id}\"} 1\n",
            "railwear_http_request_duration_seconds_count{method=\"GET\",route=\"/v1/jobs/{id}\"} 2\n",
        ] {
            assert!(text.contains(line), "{line} in {text}");
        }
    }
}
