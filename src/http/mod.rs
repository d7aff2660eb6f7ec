//! The HTTP API (axum): `/v1/jobs`, `/v1/rails`, `/v1/tokens`, health, metrics, OpenAPI,
//! dashboard. Each module exposes its own `router()`; shared state is [`AppState`].

pub mod auth;
pub mod campaigns;
pub mod connection;
pub mod curves;
pub mod jobs;
pub mod openapi;
pub mod ops;
pub mod pagination;
pub mod problem;
pub mod query;
pub mod rails;
pub mod server;
pub mod tokens;

use crate::config::{Role, ServiceConfig};
use crate::jobs::{CaseRunner, CurveDefaults, Jobs};
use crate::store::{self, Store, StoreError};
use axum::extract::DefaultBodyLimit;
use axum::http::StatusCode;
use axum::{middleware, Extension, Router};
use problem::Problem;
use std::collections::HashMap;
use std::net::SocketAddr;
use std::ops::Deref;
use std::sync::Arc;
use tower_http::trace::TraceLayer;

/// What every handler shares.
pub struct AppContext {
    pub jobs: Arc<Jobs>,
    pub store: Arc<dyn Store>,
    pub config: ServiceConfig,
    /// SHA-256 of each configured token -> (name, role).
    pub config_tokens: HashMap<String, (String, Role)>,
}

/// Cheap-to-clone handle on the [`AppContext`].
#[derive(Clone)]
pub struct AppState(pub Arc<AppContext>);

impl Deref for AppState {
    type Target = AppContext;
    fn deref(&self) -> &AppContext {
        &self.0
    }
}

/// The complete router with body limits, problem+json fallbacks and request tracing. Every
/// route takes bodies up to `body_limit_bytes`, except the campaign upload, which takes up to
/// `campaign_body_limit_bytes` (accelerometer samples inline). The limits apply when a
/// handler reads the body, which each does after checking the caller's role, so a caller
/// without the role gets 403 whatever the body's size (issue 29); no layer refuses a body by
/// its `Content-Length` before that. A refused body is read to its end (within bounds) before
/// the 413 or 415 goes out, so a client that sends before it listens still hears the refusal
/// ([`problem::json_body_bytes`]). Query parameters a route does not document are refused
/// before its handler runs ([`query`]).
pub fn app(state: AppState) -> Router {
    let limit = state.config.body_limit_bytes;
    let campaign_limit = state.config.campaign_body_limit_bytes;
    let general = Router::new()
        .merge(jobs::router())
        .merge(rails::router())
        .merge(curves::router())
        .merge(tokens::router())
        .merge(ops::router())
        .merge(openapi::router());
    let general = with_body_limit(general, limit);
    let campaigns = with_body_limit(campaigns::router(), campaign_limit);
    Router::new()
        .merge(general)
        .merge(campaigns)
        .fallback(|| async { Problem::not_found("no such resource") })
        .method_not_allowed_fallback(|| async {
            Problem::new(
                StatusCode::METHOD_NOT_ALLOWED,
                "method-not-allowed",
                "Method not allowed",
                "this resource does not support that method",
            )
        })
        .route_layer(middleware::from_fn(query::refuse_unknown_query_parameters))
        .layer(middleware::from_fn_with_state(state.clone(), http_metrics))
        .layer(middleware::map_response(problem::problem_for_bare_errors))
        .layer(middleware::from_fn(ops::security_headers))
        .layer(TraceLayer::new_for_http())
        .with_state(state)
}

/// `router`'s body limit, `limit` bytes: for the JSON readers ([`problem::RouteBodyLimit`],
/// which drain a refused body) and for any axum extractor (`DefaultBodyLimit`).
fn with_body_limit(router: Router<AppState>, limit: usize) -> Router<AppState> {
    router
        .layer(DefaultBodyLimit::max(limit))
        .layer(Extension(problem::RouteBodyLimit(limit)))
}

/// Counts each request and its latency per method and matched route (`/metrics`).
async fn http_metrics(
    axum::extract::State(state): axum::extract::State<AppState>,
    request: axum::extract::Request,
    next: middleware::Next,
) -> axum::response::Response {
    let method = request.method().as_str().to_string();
    let route = request
        .extensions()
        .get::<axum::extract::MatchedPath>()
        .map_or_else(|| "unmatched".to_string(), |p| p.as_str().to_string());
    let started = std::time::Instant::now();
    let response = next.run(request).await;
    state.jobs.metrics.http_request(
        &method,
        &route,
        response.status().as_u16(),
        started.elapsed().as_secs_f64(),
    );
    response
}

/// Why the service could not start.
#[derive(Debug, thiserror::Error)]
pub enum StartError {
    #[error(transparent)]
    Store(#[from] StoreError),
    #[error("cannot listen on {addr}")]
    Bind {
        addr: String,
        source: std::io::Error,
    },
}

/// A running service (API and, unless disabled, the embedded workers).
pub struct RunningService {
    /// Bound address (useful with port 0).
    pub addr: SocketAddr,
    pub state: AppState,
    shutdown: tokio::sync::oneshot::Sender<()>,
    server: tokio::task::JoinHandle<std::io::Result<()>>,
    workers: Vec<tokio::task::JoinHandle<()>>,
}

impl RunningService {
    /// Clean shutdown: stop accepting requests and finish in-flight ones, while the workers
    /// stop taking jobs and give running ones back to the queue within `shutdown_grace_s`
    /// ([`Jobs::shutdown`]).
    pub async fn stop(self) {
        let _ = self.shutdown.send(());
        self.state.jobs.shutdown(self.workers).await;
        let _ = self.server.await;
    }

    /// Stop as a crash would leave things: the workers are dropped mid-attempt, their jobs
    /// stay running until their leases expire (tests of lease recovery).
    pub async fn abandon(self) {
        for worker in self.workers {
            worker.abort();
        }
        let _ = self.shutdown.send(());
        let _ = self.server.await;
    }
}

/// Open the store, start `config.worker_count()` workers (if `workers`), bind and serve.
pub async fn start(
    config: ServiceConfig,
    runner: Arc<dyn CaseRunner>,
    workers: bool,
) -> Result<RunningService, StartError> {
    let store = store::open(&config.database_url).await?;
    let settings = config.worker_settings();
    let curve_defaults = CurveDefaults {
        vehicle_profile: config.report.vehicle_profile.clone(),
        environment: config.report.environment.clone(),
        wear_law: config.report.wear_law.clone(),
    };
    let jobs = Jobs::new(Arc::clone(&store), runner, settings, curve_defaults);
    let config_tokens = config
        .tokens
        .iter()
        .map(|t| (auth::token_sha256(&t.token), (t.name.clone(), t.role)))
        .collect();
    let listener = tokio::net::TcpListener::bind(&config.listen)
        .await
        .map_err(|source| StartError::Bind {
            addr: config.listen.clone(),
            source,
        })?;
    let addr = listener.local_addr().map_err(|source| StartError::Bind {
        addr: config.listen.clone(),
        source,
    })?;
    let worker_handles = if workers {
        let count = config.worker_count();
        // Jobs left running by dead processes of this host go back to the queue at once.
        jobs.release_dead_leases().await?;
        tracing::info!(count, host = %jobs.host.host, pid = jobs.host.pid, "starting workers");
        jobs.spawn_workers(count, &jobs.worker_prefix())
    } else {
        Vec::new()
    };
    let state = AppState(Arc::new(AppContext {
        jobs,
        store,
        config,
        config_tokens,
    }));
    let router = app(state.clone());
    let limits = server::Limits {
        header_read_timeout: std::time::Duration::from_secs_f64(state.config.header_read_timeout_s),
        body_read_timeout: std::time::Duration::from_secs_f64(state.config.body_read_timeout_s),
        max_connections: state.config.max_connections,
        max_connections_per_peer: state.config.max_connections_per_peer,
    };
    let (shutdown, on_shutdown) = tokio::sync::oneshot::channel::<()>();
    let server = tokio::spawn(server::serve(listener, router, limits, async move {
        let _ = on_shutdown.await;
    }));
    Ok(RunningService {
        addr,
        state,
        shutdown,
        server,
        workers: worker_handles,
    })
}
