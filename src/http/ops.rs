//! Operational endpoints (no token): health, readiness, metrics, the interactive API page and
//! the dashboard (the OpenAPI document is served by `openapi`).

use super::problem::Problem;
use super::AppState;
use axum::extract::State;
use axum::http::{header, StatusCode};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::get;
use axum::Router;

pub fn router() -> Router<AppState> {
    Router::new()
        .route("/", get(dashboard))
        .route(
            "/dashboard.js",
            get(|| asset(JAVASCRIPT, include_str!("dashboard.js"))),
        )
        .route(
            "/dashboard.css",
            get(|| asset(CSS, include_str!("dashboard.css"))),
        )
        .route("/docs", get(docs))
        .route(
            "/docs.js",
            get(|| asset(JAVASCRIPT, include_str!("docs.js"))),
        )
        .route("/docs.css", get(|| asset(CSS, include_str!("docs.css"))))
        .route("/healthz", get(healthz))
        .route("/readyz", get(readyz))
        .route("/metrics", get(metrics))
}

const JAVASCRIPT: &str = "text/javascript; charset=utf-8";
const CSS: &str = "text/css; charset=utf-8";

/// A static script or style sheet of the pages (kept out of the HTML, so the pages run under
/// a content security policy without inline script or style).
async fn asset(content_type: &'static str, body: &'static str) -> Response {
    ([(header::CONTENT_TYPE, content_type)], body).into_response()
}

/// The policy every answer carries: scripts, styles, images and requests from this origin
/// only (figures are shown as `blob:` images), no inline script or style, no plugins, no
/// framing, no form posts elsewhere.
pub const CONTENT_SECURITY_POLICY: &str = "default-src 'none'; script-src 'self'; \
    style-src 'self'; img-src 'self' blob: data:; connect-src 'self'; base-uri 'none'; \
    form-action 'none'; frame-ancestors 'none'";

/// Middleware: the browser hardening headers on every answer (issue 29): the policy above,
/// `X-Frame-Options: DENY` (no clickjacking through frames), `X-Content-Type-Options:
/// nosniff` (an SVG figure or a JSON body is never run as something else) and
/// `Referrer-Policy: no-referrer` (a job id in a URL does not leak to other sites).
pub async fn security_headers(
    request: axum::extract::Request,
    next: axum::middleware::Next,
) -> Response {
    let mut response = next.run(request).await;
    let headers = response.headers_mut();
    for (name, value) in [
        (header::CONTENT_SECURITY_POLICY, CONTENT_SECURITY_POLICY),
        (header::X_FRAME_OPTIONS, "DENY"),
        (header::X_CONTENT_TYPE_OPTIONS, "nosniff"),
        (header::REFERRER_POLICY, "no-referrer"),
    ] {
        headers.insert(name, axum::http::HeaderValue::from_static(value));
    }
    response
}

async fn dashboard() -> Html<&'static str> {
    Html(include_str!("dashboard.html"))
}

async fn docs() -> Html<&'static str> {
    Html(include_str!("docs.html"))
}

/// Liveness: the process answers.
#[utoipa::path(get, path = "/healthz", tag = "ops", responses((status = 200, description = "alive", body = String)))]
pub async fn healthz() -> &'static str {
    "ok"
}

/// Readiness: the database answers.
#[utoipa::path(get, path = "/readyz", tag = "ops", responses(
    (status = 200, description = "ready", body = String),
    (status = 503, body = Problem, content_type = "application/problem+json")))]
pub async fn readyz(State(state): State<AppState>) -> Response {
    match state.store.ping().await {
        Ok(()) => "ready".into_response(),
        Err(e) => {
            tracing::warn!(error = %e, "readiness check failed");
            Problem::new(
                StatusCode::SERVICE_UNAVAILABLE,
                "not-ready",
                "Not ready",
                "the database does not answer",
            )
            .into_response()
        }
    }
}

/// Prometheus metrics: queue depth, job durations, simulated seconds per second.
#[utoipa::path(get, path = "/metrics", tag = "ops", responses((status = 200, description = "OpenMetrics text format (version 1.0.0), as Prometheus scrapes it", body = String, content_type = "application/openmetrics-text")))]
pub async fn metrics(State(state): State<AppState>) -> Result<Response, Problem> {
    let counts = state.store.job_counts().await?;
    let text = state.jobs.metrics.render(&counts);
    Ok((
        [(header::CONTENT_TYPE, crate::jobs::metrics::CONTENT_TYPE)],
        text,
    )
        .into_response())
}
