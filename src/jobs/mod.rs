//! Job queue and embedded worker pool: submission with idempotency keys, claims with leases and
//! heartbeats, fenced completion, cancellation, progress. Computations run on tokio's blocking
//! threads through the [`CaseRunner`] interface.

mod checkpoints;
pub mod family;
pub mod host;
pub mod inputs;
pub mod metrics;
use crate::field_error::FieldError;
/// The job records live with the store that keeps them (`store::job_records`).
pub use crate::store::job_records as model;
pub mod runner;
#[cfg(test)]
mod runner_tests;
pub mod worker;

use crate::store::{clock, NewJob, Store, StoreError, Submitted, WorkerHost};
pub use metrics::Metrics;
pub use model::{ChildCounts, ChildOf, JobKind, JobProgress, JobRecord, JobStatus};
pub use runner::{
    CaseRunner, ChildJob, CurveInfo, FanOutPlan, JobInputs, JobOutput, LibraryRunner, StoredInput,
};
use sha2::{Digest, Sha256};
use std::collections::HashMap;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::sync::Notify;
use uuid::Uuid;

pub use crate::pipeline::code_version;

/// Key of a penalization curve: vehicle profile, environment and wear law.
pub fn curve_key(vehicle_profile: &str, environment: &str, wear_law: &str) -> String {
    format!("{vehicle_profile}/{environment}/{wear_law}")
}

/// Timing settings of the worker pool (from [`crate::config::ServiceConfig`]).
#[derive(Debug, Clone, Copy)]
pub struct WorkerSettings {
    pub lease: Duration,
    pub heartbeat: Duration,
    pub poll: Duration,
    pub max_attempts: u32,
    /// Samples per stored track block.
    pub track_block_samples: usize,
    /// Samples a running simulation gathers per stored record chunk
    /// ([`crate::pipeline::RecordSink::chunk_samples`]).
    pub record_chunk_samples: usize,
    /// At shutdown, how long a running attempt gets to stop before its job is given back.
    pub shutdown_grace: Duration,
}

/// Defaults for the curve key of a sweep whose params do not name all three parts.
#[derive(Debug, Clone)]
pub struct CurveDefaults {
    pub vehicle_profile: String,
    pub environment: String,
    pub wear_law: String,
}

/// A submission was refused.
#[derive(Debug, thiserror::Error)]
pub enum SubmitError {
    /// A parameter broke a rule (`field` is a dotted path in the request body).
    #[error(transparent)]
    Invalid(#[from] FieldError),
    #[error(transparent)]
    Store(#[from] StoreError),
}

/// The job system shared by the HTTP layer and the workers.
pub struct Jobs {
    pub store: Arc<dyn Store>,
    pub runner: Arc<dyn CaseRunner>,
    pub metrics: Arc<Metrics>,
    pub settings: WorkerSettings,
    pub curve_defaults: CurveDefaults,
    /// Wakes an idle worker when a job is submitted.
    wake: Notify,
    /// Cancel flags of attempts running in this process, so a cancel request reaches the
    /// computation at once instead of at the next heartbeat.
    running: Mutex<HashMap<Uuid, Arc<AtomicBool>>>,
    /// Host, pid and instance of this process, recorded with each claim.
    pub host: WorkerHost,
    /// True once shutdown began: workers take no more jobs and give running ones back.
    stopping: tokio::sync::watch::Sender<bool>,
}

impl Jobs {
    pub fn new(
        store: Arc<dyn Store>,
        runner: Arc<dyn CaseRunner>,
        settings: WorkerSettings,
        curve_defaults: CurveDefaults,
    ) -> Arc<Self> {
        Arc::new(Self {
            store,
            runner,
            metrics: Arc::new(Metrics::default()),
            settings,
            curve_defaults,
            wake: Notify::new(),
            running: Mutex::new(HashMap::new()),
            host: WorkerHost::current(),
            stopping: tokio::sync::watch::Sender::new(false),
        })
    }

    /// Prefix of this process's worker names: `<host>-<pid>` (workers are `<host>-<pid>-<n>`).
    pub fn worker_prefix(&self) -> String {
        format!("{}-{}", self.host.host, self.host.pid)
    }

    /// Give the jobs held by dead processes of this host back to the queue at once (their
    /// attempts logged `lost`; or failed after `max_attempts`, or cancelled if asked), instead
    /// of waiting for their leases to expire. Run at start-up, before the workers claim.
    /// Returns how many leases were ended.
    pub async fn release_dead_leases(&self) -> Result<u64, StoreError> {
        let leases = self.store.host_leases(&self.host.host).await?;
        let dead: Vec<(Uuid, i64)> = leases
            .iter()
            .filter(|lease| self.host.holder_is_dead(lease))
            .map(|lease| (lease.job, lease.attempt))
            .collect();
        if dead.is_empty() {
            return Ok(0);
        }
        let now = clock::now_ms();
        let ended = self.store.expire_leases(dead, now).await?;
        self.store
            .requeue_expired(now, i64::from(self.settings.max_attempts))
            .await?;
        tracing::info!(
            host = %self.host.host,
            jobs = ended,
            "released the leases of dead workers of this host"
        );
        self.wake.notify_waiters();
        Ok(ended)
    }

    /// A receiver that sees `true` once shutdown began.
    pub(crate) fn stopping(&self) -> tokio::sync::watch::Receiver<bool> {
        self.stopping.subscribe()
    }

    /// Clean shutdown of this process's workers: they take no more jobs; each running attempt
    /// is asked to stop at its next step boundary and its job is given back to the queue
    /// (`released`), at the latest `shutdown_grace` after this call. Returns once every worker
    /// has ended (workers still busy after the grace and a margin for the release's write are
    /// aborted).
    pub async fn shutdown(&self, mut workers: Vec<tokio::task::JoinHandle<()>>) {
        self.stopping.send_replace(true);
        let bound = self.settings.shutdown_grace + Duration::from_secs(3);
        let joined = tokio::time::timeout(bound, async {
            for worker in workers.iter_mut() {
                let _ = worker.await;
            }
        })
        .await;
        if joined.is_err() {
            tracing::warn!("workers still busy after the shutdown grace; stopping them");
        }
        for worker in workers {
            worker.abort();
        }
    }

    fn running_flags(&self) -> std::sync::MutexGuard<'_, HashMap<Uuid, Arc<AtomicBool>>> {
        match self.running.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        }
    }

    /// Queue a job. The same `idempotency_key` with the same kind and params returns the
    /// earlier job; with different ones it is a [`Submitted::KeyConflict`].
    pub async fn submit(
        &self,
        kind: JobKind,
        params: serde_json::Value,
        submitted_by: &str,
        idempotency_key: Option<String>,
    ) -> Result<Submitted, SubmitError> {
        if kind == JobKind::SweepPoint {
            return Err(SubmitError::Invalid(FieldError::new(
                "kind",
                "sweep_point jobs are created by sweep jobs (one per point); submit a sweep",
            )));
        }
        if kind == JobKind::Diagnose {
            return Err(SubmitError::Invalid(FieldError::new(
                "kind",
                "diagnose jobs are submitted for a stored campaign: POST \
                       /v1/campaigns/{id}/diagnoses",
            )));
        }
        self.submit_checked(kind, params, submitted_by, idempotency_key)
            .await
    }

    /// Queue a diagnosis of a stored campaign: `options` are the client's params (keys of
    /// [`crate::pipeline::DIAGNOSE_CLIENT_KEYS`]; others are refused, naming the key); the campaign's
    /// id and the SHA-256 of its content are stored with them, and the job reads the campaign
    /// from the store when it runs (so its result depends on its params and that content).
    /// Errors name the client's field (`window_s`, `effects[0]`, ...).
    pub async fn submit_diagnosis(
        &self,
        campaign_id: Uuid,
        campaign_sha256: &str,
        options: serde_json::Value,
        submitted_by: &str,
        idempotency_key: Option<String>,
    ) -> Result<Submitted, SubmitError> {
        let Some(map) = options.as_object() else {
            return Err(SubmitError::Invalid(FieldError::new(
                "body",
                "must be a JSON object",
            )));
        };
        if let Some(key) = map
            .keys()
            .find(|k| !crate::pipeline::DIAGNOSE_CLIENT_KEYS.contains(&k.as_str()))
        {
            return Err(SubmitError::Invalid(FieldError::new(
                key.clone(),
                format!(
                    "is not a known parameter (known: {})",
                    crate::pipeline::DIAGNOSE_CLIENT_KEYS.join(", ")
                ),
            )));
        }
        let mut params = map.clone();
        params.insert("campaign_id".into(), campaign_id.to_string().into());
        params.insert("campaign_sha256".into(), campaign_sha256.into());
        self.submit_checked(
            JobKind::Diagnose,
            serde_json::Value::Object(params),
            submitted_by,
            idempotency_key,
        )
        .await
        .map_err(|e| match e {
            SubmitError::Invalid(FieldError { field, rule }) => SubmitError::Invalid(FieldError {
                field: field
                    .strip_prefix("params.")
                    .map(str::to_string)
                    .unwrap_or(field),
                rule,
            }),
            other => other,
        })
    }

    /// A sweep's `wear_law = {"diagnosis": "<id>"}` becomes the diagnosis' fitted mechanism
    /// ([`crate::pipeline::DiagnosedWearLaw`], read from the stored report once, here), so the
    /// sweep, its points and its curve carry one record. The resolved record itself (what a
    /// stored sweep's params show, so that they can be submitted again) is accepted when it is
    /// the one the diagnosis gives; anything else is refused, naming the field that differs:
    /// the resolved form is the service's to write.
    async fn resolve_diagnosed_wear_law(
        &self,
        params: &mut serde_json::Value,
    ) -> Result<(), SubmitError> {
        let Some(serde_json::Value::Object(law)) = params.get("wear_law") else {
            return Ok(());
        };
        let invalid = |field: &str, rule: String| {
            SubmitError::Invalid(FieldError::new(format!("params.wear_law{field}"), rule))
        };
        // The resolved form, as read back from a stored sweep.
        let submitted_record = if law.len() > 1 || !law.contains_key("diagnosis") {
            let record: crate::pipeline::DiagnosedWearLaw =
                serde_json::from_value(serde_json::Value::Object(law.clone())).map_err(|e| {
                    invalid(
                        "",
                        format!(
                            "must be {{\"diagnosis\": \"<diagnose job id>\"}}, or the whole \
                             record a stored sweep shows for it (diagnosis, effect, parameters, \
                             verdict, note): {e}"
                        ),
                    )
                })?;
            Some(record)
        } else {
            None
        };
        let id = law
            .get("diagnosis")
            .and_then(|v| v.as_str())
            .and_then(|s| Uuid::parse_str(s).ok())
            .ok_or_else(|| invalid(".diagnosis", "must be a diagnose job's id (a UUID)".into()))?;
        let job = self
            .store
            .get_job(id)
            .await
            .map_err(SubmitError::Store)?
            .ok_or_else(|| invalid(".diagnosis", format!("names no job ({id})")))?;
        if job.kind != JobKind::Diagnose {
            return Err(invalid(
                ".diagnosis",
                format!("names a {} job, not a diagnosis", job.kind.as_str()),
            ));
        }
        let result = match (job.status, &job.result) {
            (JobStatus::Succeeded, Some(result)) => result,
            (status, _) => {
                let what_next = match status {
                    JobStatus::Queued | JobStatus::Running | JobStatus::Waiting => {
                        "wait until it has succeeded"
                    }
                    _ => "it will not finish: name a diagnosis that succeeded, or run one again",
                };
                return Err(invalid(
                    ".diagnosis",
                    format!(
                        "names diagnosis {id}, which is {}: {what_next}",
                        status.as_str()
                    ),
                ));
            }
        };
        let carried = crate::pipeline::carried_wear_law(id, result)
            .map_err(|e| SubmitError::Invalid(e.at("params")))?;
        if let Some(submitted) = submitted_record {
            if let Some(field) = differing_field(&submitted, &carried) {
                return Err(invalid(
                    &format!(".{field}"),
                    format!(
                        "differs from what diagnosis {id} gives: give only \
                         {{\"diagnosis\": \"{id}\"}}, or the record unchanged"
                    ),
                ));
            }
        }
        let value = serde_json::to_value(&carried).map_err(|e| invalid("", e.to_string()))?;
        if let Some(map) = params.as_object_mut() {
            map.insert("wear_law".into(), value);
        }
        Ok(())
    }

    async fn submit_checked(
        &self,
        kind: JobKind,
        params: serde_json::Value,
        submitted_by: &str,
        idempotency_key: Option<String>,
    ) -> Result<Submitted, SubmitError> {
        if !params.is_object() {
            return Err(SubmitError::Invalid(FieldError::new(
                "params",
                "must be a JSON object",
            )));
        }
        let seed = match params.get("seed") {
            None => draw_seed(),
            Some(value) => crate::pipeline::parse_seed(value).map_err(|_| {
                SubmitError::Invalid(FieldError::new(
                    "params.seed",
                    "must be an integer in [0, 2^53) (JavaScript reads larger integers \
                       inexactly)",
                ))
            })?,
        };
        // The request as submitted is what an Idempotency-Key is compared against.
        let canonical = serde_json::json!({ "kind": kind, "params": params }).to_string();
        // A sweep's curve selectors are stored with it, defaults filled in, so the curve key,
        // the submission check and the worker all read the same names.
        let mut params = params;
        if kind == JobKind::Sweep {
            if let Some(map) = params.as_object_mut() {
                let defaults = [
                    ("vehicle_profile", &self.curve_defaults.vehicle_profile),
                    ("environment", &self.curve_defaults.environment),
                    ("wear_law", &self.curve_defaults.wear_law),
                ];
                for (name, default) in defaults {
                    map.entry(name)
                        .or_insert_with(|| serde_json::Value::from(default.as_str()));
                }
            }
        }
        if kind == JobKind::Sweep {
            self.resolve_diagnosed_wear_law(&mut params).await?;
        }
        // The same parse the worker runs (one set of rules); it may build the model, so it
        // runs on a blocking thread. A kind with a typed plan gets it back (with the job's
        // seed), stored with the job and run by the worker as it is.
        let runner = Arc::clone(&self.runner);
        let check_params = params.clone();
        let checked =
            tokio::task::spawn_blocking(move || runner.submit_plan(&kind, &check_params, seed))
                .await
                .map_err(|e| {
                    SubmitError::Invalid(FieldError::new(
                        "params",
                        format!("could not be checked: {e}"),
                    ))
                })?;
        let plan = checked.map_err(|e| match e {
            crate::pipeline::RunError::InvalidConfig { field, rule } => {
                let e = FieldError::new(field, rule);
                SubmitError::Invalid(if e.field == "params" {
                    e
                } else {
                    e.at("params")
                })
            }
            other => SubmitError::Invalid(FieldError::new("params", other.to_string())),
        })?;
        let curve_key = (kind == JobKind::Sweep).then(|| {
            let part = |name: &str| {
                params
                    .get(name)
                    .and_then(|v| v.as_str())
                    .unwrap_or_default()
                    .to_string()
            };
            let wear_law = crate::pipeline::SweepWearLaw::from_param(params.get("wear_law"), "")
                .map(|law| law.curve_name())
                .unwrap_or_default();
            curve_key(&part("vehicle_profile"), &part("environment"), &wear_law)
        });
        let idempotency = idempotency_key.map(|key| {
            // serde_json maps are sorted, so this text is canonical for equal bodies.
            let sha = Sha256::digest(canonical.as_bytes());
            (scoped_idempotency_key(submitted_by, kind, &key), hex(&sha))
        });
        let submitted = self
            .store
            .submit_job(NewJob {
                id: Uuid::new_v4(),
                kind,
                params,
                plan,
                seed,
                code_version: code_version().to_string(),
                submitted_by: submitted_by.to_string(),
                idempotency,
                curve_key,
                created_ms: clock::now_ms(),
            })
            .await?;
        if matches!(submitted, Submitted::Created(_)) {
            self.wake.notify_one();
        }
        Ok(submitted)
    }

    /// Request cancellation: a queued job is cancelled at once; a running one here is told
    /// immediately (its computation stops within a second), elsewhere at its next heartbeat.
    /// Cancelling a job that fanned out cancels its children the same way.
    pub async fn cancel(&self, id: Uuid) -> Result<Option<JobRecord>, StoreError> {
        let record = self.store.request_cancel(id, clock::now_ms()).await?;
        let mut stop = vec![id];
        if record.as_ref().is_some_and(|r| r.children.is_some()) {
            stop.extend(self.store.children(id).await?.iter().map(|c| c.id));
        }
        let flags = self.running_flags();
        for job in stop {
            if let Some(flag) = flags.get(&job) {
                flag.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        }
        Ok(record)
    }
}

/// A seed drawn for a job that names none: 53 random bits, so it is below 2^53 and every
/// JSON reader (JavaScript, jq) reads it exactly.
pub fn draw_seed() -> u64 {
    // A v4 UUID's fixed version and variant bits sit in different halves: XOR-ing the halves
    // gives 64 uniformly random bits.
    let v = Uuid::new_v4().as_u128();
    ((v >> 64) as u64 ^ v as u64) & crate::pipeline::limits::MAX_SEED
}

/// The key an `Idempotency-Key` is stored under: scoped to the caller and the route, so two
/// tokens that pick the same key make two resources and never see each other's job. The unit
/// separator (0x1f) cannot occur in a key (visible ASCII and inner spaces) nor in a token name.
/// migrations/*/0009_scoped_idempotency.sql scopes the keys stored before this way.
pub(crate) fn scoped_idempotency_key(submitted_by: &str, kind: JobKind, key: &str) -> String {
    let route = if kind == JobKind::Diagnose {
        "diagnoses"
    } else {
        "jobs"
    };
    format!("{submitted_by}\u{1f}{route}\u{1f}{key}")
}

/// Lower-case hex of bytes.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The first field of a submitted diagnosed wear-law record that is not the diagnosis' own
/// (`parameters.<name>` for a parameter), or None when the records agree.
fn differing_field(
    submitted: &crate::pipeline::DiagnosedWearLaw,
    carried: &crate::pipeline::DiagnosedWearLaw,
) -> Option<String> {
    if submitted.effect != carried.effect {
        return Some("effect".into());
    }
    if submitted.verdict != carried.verdict {
        return Some("verdict".into());
    }
    if submitted.note != carried.note {
        return Some("note".into());
    }
    let names = submitted.parameters.keys().chain(carried.parameters.keys());
    for name in names {
        let (a, b) = (submitted.parameters.get(name), carried.parameters.get(name));
        if a.map(|v| v.to_bits()) != b.map(|v| v.to_bits()) {
            return Some(format!("parameters.{name}"));
        }
    }
    None
}
