//! The HTTP layer's one error type: RFC 9457 problem details (`application/problem+json`) with
//! the offending `field` for validation errors. Internal causes are logged, never sent.

use axum::body::Bytes;
use axum::extract::{FromRequest, Request};
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use serde::de::DeserializeOwned;
use serde::Serialize;
use utoipa::ToSchema;

/// Problem details (RFC 9457) as sent to clients.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct Problem {
    /// URI naming the problem type, e.g. `urn:railwear:problem:invalid-field`.
    #[serde(rename = "type")]
    pub problem_type: String,
    /// Short summary of the problem type.
    pub title: String,
    /// HTTP status code.
    pub status: u16,
    /// What went wrong in this request, in words.
    pub detail: String,
    /// Dotted path of the request field at fault (validation errors only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub field: Option<String>,
}

impl Problem {
    /// A problem of type `urn:railwear:problem:<slug>`.
    pub fn new(status: StatusCode, slug: &str, title: &str, detail: impl Into<String>) -> Self {
        Self {
            problem_type: format!("urn:railwear:problem:{slug}"),
            title: title.to_string(),
            status: status.as_u16(),
            detail: detail.into(),
            field: None,
        }
    }

    /// 422: `field` breaks `rule`.
    pub fn invalid_field(field: impl Into<String>, rule: impl std::fmt::Display) -> Self {
        let field = field.into();
        let mut p = Self::new(
            StatusCode::UNPROCESSABLE_ENTITY,
            "invalid-field",
            "Invalid field",
            format!("`{field}` {rule}"),
        );
        p.field = Some(field);
        p
    }

    /// 400: a query or path parameter is malformed.
    pub fn bad_parameter(field: impl Into<String>, rule: impl std::fmt::Display) -> Self {
        let field = field.into();
        let mut p = Self::new(
            StatusCode::BAD_REQUEST,
            "bad-parameter",
            "Bad parameter",
            format!("`{field}` {rule}"),
        );
        p.field = Some(field);
        p
    }

    pub fn not_found(what: impl Into<String>) -> Self {
        Self::new(StatusCode::NOT_FOUND, "not-found", "Not found", what)
    }

    pub fn conflict(slug: &str, title: &str, detail: impl Into<String>) -> Self {
        Self::new(StatusCode::CONFLICT, slug, title, detail)
    }

    pub fn unauthorized(detail: impl Into<String>) -> Self {
        Self::new(
            StatusCode::UNAUTHORIZED,
            "unauthorized",
            "Missing or invalid token",
            detail,
        )
    }

    pub fn forbidden(detail: impl Into<String>) -> Self {
        Self::new(
            StatusCode::FORBIDDEN,
            "forbidden",
            "Role not allowed",
            detail,
        )
    }

    /// 500 with a generic message; `cause` goes to the log only.
    pub fn internal(cause: &dyn std::fmt::Display) -> Self {
        tracing::error!(error = %cause, "internal error");
        Self::new(
            StatusCode::INTERNAL_SERVER_ERROR,
            "internal",
            "Internal error",
            "the server failed to handle the request; see its log",
        )
    }

    fn status_code(&self) -> StatusCode {
        StatusCode::from_u16(self.status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR)
    }
}

/// A field that breaks a rule, anywhere below the HTTP edge, is a 422 naming it.
impl From<crate::field_error::FieldError> for Problem {
    fn from(e: crate::field_error::FieldError) -> Self {
        Self::invalid_field(e.field, e.rule)
    }
}

impl IntoResponse for Problem {
    fn into_response(self) -> Response {
        let status = self.status_code();
        let body = serde_json::to_vec(&self).unwrap_or_default();
        let mut response = (status, body).into_response();
        response.headers_mut().insert(
            header::CONTENT_TYPE,
            HeaderValue::from_static("application/problem+json"),
        );
        if status == StatusCode::UNAUTHORIZED {
            response.headers_mut().insert(
                header::WWW_AUTHENTICATE,
                HeaderValue::from_static("Bearer realm=\"railwear\""),
            );
        }
        response
    }
}

impl From<crate::store::StoreError> for Problem {
    fn from(e: crate::store::StoreError) -> Self {
        Problem::internal(&e)
    }
}

/// JSON body extractor whose rejections are problems naming the field (via
/// `serde_path_to_error`), including 413 for bodies over the limit and 415 for non-JSON.
pub struct ApiJson<T>(pub T);

impl<S, T> FromRequest<S> for ApiJson<T>
where
    S: Send + Sync,
    T: DeserializeOwned,
{
    type Rejection = Problem;

    async fn from_request(req: Request, _state: &S) -> Result<Self, Self::Rejection> {
        let bytes = json_body_bytes(req).await?;
        let mut deserializer = serde_json::Deserializer::from_slice(&bytes);
        match serde_path_to_error::deserialize(&mut deserializer) {
            Ok(value) => {
                if deserializer.end().is_err() {
                    return Err(Problem::new(
                        StatusCode::BAD_REQUEST,
                        "malformed-json",
                        "Malformed JSON",
                        "trailing characters after the JSON value",
                    ));
                }
                Ok(ApiJson(value))
            }
            Err(err) => {
                let path = err.path().to_string();
                let inner = err.into_inner();
                // A number past a double's range (1e400) is well-formed JSON that no field
                // can hold: a 422 naming the field, like any other value out of bounds.
                if inner.is_syntax() && inner.to_string().starts_with("number out of range") {
                    let field = if path == "." {
                        "body".to_string()
                    } else {
                        path
                    };
                    return Err(Problem::invalid_field(
                        field,
                        "is a number beyond the range of a double (about 1.8e308)",
                    ));
                }
                if inner.is_syntax() || inner.is_eof() {
                    Err(Problem::new(
                        StatusCode::BAD_REQUEST,
                        "malformed-json",
                        "Malformed JSON",
                        inner.to_string(),
                    ))
                } else {
                    let field = if path == "." {
                        "body".to_string()
                    } else {
                        path
                    };
                    Err(Problem::invalid_field(field, inner))
                }
            }
        }
    }
}

/// The body limit of the route a request is on (`body_limit_bytes` or
/// `campaign_body_limit_bytes`), set by the router as a request extension; the JSON body readers
/// take it from there.
#[derive(Debug, Clone, Copy)]
pub struct RouteBodyLimit(pub usize);

/// How much of a refused body (over the limit, or not JSON) is still read and thrown away, and
/// for how long, before the refusal is sent. A client that sends its whole body before reading
/// the answer (no `Expect: 100-continue`) would otherwise have its connection closed, and often
/// reset, in mid-send, and lose the 413 or 415 (a server's "lingering close"). Past either bound
/// the connection is closed as before.
const REFUSED_BODY_DISCARD_BYTES: usize = 64 * 1024 * 1024;
const REFUSED_BODY_DISCARD_TIME: std::time::Duration = std::time::Duration::from_secs(10);

/// Read and drop what is left of a refused body, within the bounds above.
async fn discard_refused_body(mut body: axum::body::Body) {
    use http_body_util::BodyExt;
    let drain = async {
        let mut discarded = 0usize;
        while let Some(Ok(frame)) = body.frame().await {
            if let Some(data) = frame.data_ref() {
                discarded += data.len();
                if discarded > REFUSED_BODY_DISCARD_BYTES {
                    break;
                }
            }
        }
    };
    // Past the time bound the body is dropped unread: the connection closes, as it would have.
    let _ = tokio::time::timeout(REFUSED_BODY_DISCARD_TIME, drain).await;
}

/// The 413 for a body over a limit, `detail` saying which.
fn body_too_large(detail: impl Into<String>) -> Problem {
    Problem::new(
        StatusCode::PAYLOAD_TOO_LARGE,
        "body-too-large",
        "Request body too large",
        detail,
    )
}

/// [`body_too_large`] for a route's limit of `limit` bytes.
fn over_route_limit(limit: usize) -> Problem {
    body_too_large(format!(
        "the request body exceeds this route's limit of {limit} bytes"
    ))
}

/// The bytes of a body sent as JSON (`application/json` or `*+json`, else 415), 413 when over
/// the route's limit ([`RouteBodyLimit`]; 2 MiB where no route set one). Not parsed. A refused
/// body is read to its end (within bounds) before the refusal goes out, so the client hears it.
pub async fn json_body_bytes(req: Request) -> Result<Bytes, Problem> {
    use http_body_util::BodyExt;
    let is_json = req
        .headers()
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .map(|v| {
            let mime = v.split(';').next().unwrap_or("").trim();
            mime == "application/json" || mime.ends_with("+json")
        })
        .unwrap_or(false);
    let limit = req
        .extensions()
        .get::<RouteBodyLimit>()
        .map_or(DEFAULT_BODY_LIMIT_BYTES, |l| l.0);
    let declared = req
        .headers()
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.trim().parse::<u64>().ok());
    let mut body = req.into_body();
    if !is_json {
        discard_refused_body(body).await;
        return Err(Problem::new(
            StatusCode::UNSUPPORTED_MEDIA_TYPE,
            "unsupported-media-type",
            "Unsupported media type",
            "send the body as Content-Type: application/json",
        ));
    }
    if declared.is_some_and(|n| n > limit as u64) {
        discard_refused_body(body).await;
        return Err(over_route_limit(limit));
    }
    let mut bytes = Vec::new();
    while let Some(frame) = body.frame().await {
        let frame = frame.map_err(|e| unreadable_body(&e))?;
        if let Some(data) = frame.data_ref() {
            if bytes.len() + data.len() > limit {
                discard_refused_body(body).await;
                return Err(over_route_limit(limit));
            }
            bytes.extend_from_slice(data);
        }
    }
    Ok(Bytes::from(bytes))
}

/// The error a request body yields once its deadline has passed (`super::server`'s body
/// deadline, `body_read_timeout_s` from the head's arrival).
#[derive(Debug, thiserror::Error)]
#[error("the request body did not arrive within body_read_timeout_s ({0:?})")]
pub struct BodyDeadlinePassed(pub std::time::Duration);

/// The problem for a body that broke off: 408 when its deadline passed ([`BodyDeadlinePassed`]:
/// the client sent less than it announced, or too slowly), 400 otherwise.
pub fn unreadable_body(e: &axum::Error) -> Problem {
    use std::error::Error as _;
    let mut source: Option<&(dyn std::error::Error + 'static)> = e.source();
    while let Some(cause) = source {
        if let Some(passed) = cause.downcast_ref::<BodyDeadlinePassed>() {
            return Problem::new(
                StatusCode::REQUEST_TIMEOUT,
                "body-timeout",
                "Request body timed out",
                format!(
                    "the request body did not arrive within {} s (body_read_timeout_s): send                      the whole body, and exactly the Content-Length announced",
                    passed.0.as_secs_f64()
                ),
            );
        }
        source = cause.source();
    }
    Problem::new(
        StatusCode::BAD_REQUEST,
        "bad-body",
        "Unreadable body",
        format!("the request body could not be read: {e}"),
    )
}

/// The body limit of a route that did not set one: axum's default.
const DEFAULT_BODY_LIMIT_BYTES: usize = 2 * 1024 * 1024;

/// 400 when `bytes` is not one well-formed JSON value (syntax, truncation, trailing text);
/// checked without building the value.
pub fn check_json_syntax(bytes: &[u8]) -> Result<(), Problem> {
    let mut deserializer = serde_json::Deserializer::from_slice(bytes);
    let parsed = <serde::de::IgnoredAny as serde::Deserialize>::deserialize(&mut deserializer)
        .and_then(|_| deserializer.end());
    parsed.map_err(|e| {
        Problem::new(
            StatusCode::BAD_REQUEST,
            "malformed-json",
            "Malformed JSON",
            e.to_string(),
        )
    })
}

/// Read a JSON body with [`ApiJson`]'s rules after the handler has checked the caller's role,
/// so a caller without the role gets 403 whatever the body holds.
pub async fn read_json<T: DeserializeOwned>(request: Request) -> Result<T, Problem> {
    let ApiJson(value) = ApiJson::<T>::from_request(request, &()).await?;
    Ok(value)
}

/// Turn every error answer without a problem body (axum's own rejections: a path with invalid
/// percent-encoding, a query with a repeated key, tower-http's length check, ...) into
/// problem+json, keeping its status and its text as `detail`.
pub async fn problem_for_bare_errors(response: Response) -> Response {
    let is_problem = response
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|v| v.as_bytes() == b"application/problem+json");
    let status = response.status();
    if is_problem || !(status.is_client_error() || status.is_server_error()) {
        return response;
    }
    if status == StatusCode::PAYLOAD_TOO_LARGE {
        return body_too_large("the request body exceeds the server's limit (body_limit_bytes)")
            .into_response();
    }
    let text = match axum::body::to_bytes(response.into_body(), 16 * 1024).await {
        Ok(bytes) => String::from_utf8_lossy(&bytes).trim().to_string(),
        Err(_) => String::new(),
    };
    bare_error_problem(status, &text).into_response()
}

/// The problem for an error answer whose body was `text` (plain text from axum).
pub fn bare_error_problem(status: StatusCode, text: &str) -> Problem {
    let detail = if text.is_empty() {
        status
            .canonical_reason()
            .unwrap_or("request refused")
            .to_string()
    } else {
        text.to_string()
    };
    // serde_urlencoded names a repeated or unknown query key in backticks.
    let named = |marker: &str| {
        text.split_once(marker)
            .and_then(|(_, rest)| rest.split_once('`'))
            .map(|(name, _)| name.to_string())
    };
    if status == StatusCode::BAD_REQUEST {
        if let Some(field) = named("duplicate field `") {
            return Problem::bad_parameter(field, "must be given once");
        }
        if let Some(field) = named("unknown field `") {
            return Problem::bad_parameter(field, "is not a parameter of this resource");
        }
        let (slug, title) = if text.contains("query string") {
            ("bad-query", "Malformed query string")
        } else if text.contains("URL") || text.contains("path") {
            ("bad-path", "Malformed path")
        } else {
            ("bad-request", "Bad request")
        };
        return Problem::new(status, slug, title, detail);
    }
    let title = status.canonical_reason().unwrap_or("Error");
    let slug = title.to_ascii_lowercase().replace(' ', "-");
    Problem::new(status, &slug, title, detail)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bare_query_and_path_errors_become_problems_naming_the_key() {
        let p = bare_error_problem(
            StatusCode::BAD_REQUEST,
            "Failed to deserialize query string: duplicate field `limit`",
        );
        assert_eq!(p.status, 400);
        assert_eq!(p.field.as_deref(), Some("limit"));
        let p = bare_error_problem(
            StatusCode::BAD_REQUEST,
            "Invalid URL: Cannot parse `%FF` to a `String`",
        );
        assert_eq!(p.problem_type, "urn:railwear:problem:bad-path");
        let p = bare_error_problem(StatusCode::BAD_GATEWAY, "");
        assert_eq!(p.status, 502);
        assert!(!p.detail.is_empty());
    }
}
