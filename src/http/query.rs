//! Unknown query parameters are refused on every route (issue 29: `GET /v1/jobs?foo=1` used
//! to answer 200 while a typo such as `?stauts=failed` silently listed every job).
//!
//! The parameters a route takes are the ones its OpenAPI operation documents (`params(...)`
//! in its `utoipa::path`), so a parameter added to a handler and to its documentation is
//! accepted with no second list to keep; routes outside the document (the dashboard, the
//! docs page) take none. The check runs before the handler, on the matched route.

use super::openapi::ApiDoc;
use super::problem::Problem;
use axum::extract::{MatchedPath, Request};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use std::collections::HashMap;
use std::sync::OnceLock;
use utoipa::openapi::path::{Operation, ParameterIn};
use utoipa::OpenApi;

/// (method, route template) -> the query parameters its operation documents.
type Allowed = HashMap<(String, String), Vec<String>>;

fn query_names(operation: &Operation) -> Vec<String> {
    operation
        .parameters
        .iter()
        .flatten()
        .filter(|p| matches!(p.parameter_in, ParameterIn::Query))
        .map(|p| p.name.clone())
        .collect()
}

/// The documented query parameters of every operation, read once from [`ApiDoc`].
fn allowed() -> &'static Allowed {
    static ALLOWED: OnceLock<Allowed> = OnceLock::new();
    ALLOWED.get_or_init(|| {
        let doc = ApiDoc::openapi();
        let mut map = Allowed::new();
        for (path, item) in doc.paths.paths {
            for (method, operation) in [
                ("GET", &item.get),
                ("HEAD", &item.get),
                ("POST", &item.post),
                ("PUT", &item.put),
                ("DELETE", &item.delete),
                ("PATCH", &item.patch),
            ] {
                if let Some(operation) = operation {
                    map.insert((method.to_string(), path.clone()), query_names(operation));
                }
            }
        }
        map
    })
}

/// The query parameters `method` on the route `template` takes (none for an undocumented
/// route).
pub fn documented_query_parameters(method: &str, template: &str) -> &'static [String] {
    allowed()
        .get(&(method.to_string(), template.to_string()))
        .map_or(&[], Vec::as_slice)
}

/// The first key of `query` (`a=1&b=2`, percent-encoded) that `known` does not hold.
fn first_unknown(query: &str, known: &[String]) -> Option<String> {
    form_urlencoded::parse(query.as_bytes())
        .map(|(key, _)| key.into_owned())
        .find(|key| !known.iter().any(|k| k == key))
}

/// Middleware: 400 problem naming the first query parameter the matched route does not take.
pub async fn refuse_unknown_query_parameters(request: Request, next: Next) -> Response {
    if let Some(query) = request.uri().query() {
        let template = request
            .extensions()
            .get::<MatchedPath>()
            .map(|p| p.as_str().to_string());
        // A method the document does not list on a documented route is the router's to
        // answer (405 Method Not Allowed), whatever its query.
        let undeclared_method = template.as_deref().is_some_and(|t| {
            !allowed().contains_key(&(request.method().as_str().to_string(), t.to_string()))
                && allowed().keys().any(|(_, path)| path == t)
        });
        if let Some(template) = template.filter(|_| !undeclared_method) {
            let known = documented_query_parameters(request.method().as_str(), &template);
            if let Some(key) = first_unknown(query, known) {
                let rule = if known.is_empty() {
                    "is not a parameter of this resource (it takes no query parameters)".into()
                } else {
                    format!(
                        "is not a parameter of this resource (known: {})",
                        known.join(", ")
                    )
                };
                return Problem::bad_parameter(key, rule).into_response();
            }
        }
    }
    next.run(request).await
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_parameters_of_a_route_are_its_only_ones() {
        let list = documented_query_parameters("GET", "/v1/jobs");
        for name in ["status", "parent", "top_level"] {
            assert!(list.iter().any(|k| k == name), "{name} in {list:?}");
        }
        assert_eq!(
            first_unknown("status=failed&foo=1", list).as_deref(),
            Some("foo")
        );
        assert_eq!(first_unknown("status=failed&top_level=true", list), None);
        // Percent-encoded keys are decoded before they are compared.
        assert_eq!(first_unknown("st%61tus=failed", list), None);
        assert_eq!(first_unknown("f%6Fo=1", list).as_deref(), Some("foo"));
        // An undocumented route takes none.
        assert!(documented_query_parameters("GET", "/").is_empty());
    }
}
