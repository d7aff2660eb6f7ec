//! The OpenAPI document, generated from the handlers' annotations. `api/openapi.json` is a copy
//! kept in sync by a test (`railwear openapi > api/openapi.json` regenerates it).

use super::{campaigns, curves, jobs, ops, pagination, problem, rails, tokens, AppState};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use utoipa::openapi::security::{HttpAuthScheme, HttpBuilder, SecurityScheme};
use utoipa::{Modify, OpenApi};

struct BearerAuth;

impl Modify for BearerAuth {
    fn modify(&self, openapi: &mut utoipa::openapi::OpenApi) {
        let components = openapi.components.get_or_insert_with(Default::default);
        components.add_security_scheme(
            "bearer",
            SecurityScheme::Http(HttpBuilder::new().scheme(HttpAuthScheme::Bearer).build()),
        );
    }
}

/// The error answers every operation can give, added where an operation does not document
/// them itself, so the document lists every status the service sends (a property-based run
/// checks it, `tests/api_schemathesis.rs`): 401 on every operation with a token, 403 on
/// writes and on token listing (the role is checked before anything else), 400 on every
/// operation (a malformed or unknown parameter; every route refuses undocumented query
/// parameters), and on operations with a
/// body 400 (malformed JSON), 413 (too large), 415 (not JSON) and 422 (a rule broken).
struct CommonErrors;

impl CommonErrors {
    fn problem(description: &str) -> utoipa::openapi::RefOr<utoipa::openapi::Response> {
        use utoipa::openapi::{ContentBuilder, Ref, ResponseBuilder};
        ResponseBuilder::new()
            .description(description)
            .content(
                "application/problem+json",
                ContentBuilder::new()
                    .schema(Some(Ref::from_schema_name("Problem")))
                    .build(),
            )
            .build()
            .into()
    }

    fn add(operation: &mut utoipa::openapi::path::Operation, path: &str, write: bool) {
        let secured = operation.security.as_ref().is_some_and(|s| !s.is_empty());
        let has_params =
            operation.parameters.as_ref().is_some_and(|p| !p.is_empty()) || path.contains('{');
        let mut wanted: Vec<(&str, &str)> = Vec::new();
        if secured {
            wanted.push(("401", "Missing, unknown or revoked token"));
            if write || path.starts_with("/v1/tokens") {
                wanted.push(("403", "The token's role may not do this"));
            }
        }
        if path.contains('{') {
            wanted.push(("404", "No such resource"));
        }
        // Every route refuses query parameters it does not document (`http::query`), so
        // every operation can answer 400.
        wanted.push((
            "400",
            match (has_params, operation.request_body.is_some()) {
                (true, _) => {
                    "Malformed, unknown or repeated path or query parameter; `field` names it"
                }
                (false, true) => {
                    "Malformed JSON body, or a query parameter this operation does not take \
                     (`field` names it)"
                }
                (false, false) => {
                    "A query parameter this operation does not take; `field` names it"
                }
            },
        ));
        if operation.request_body.is_some() {
            wanted.push(("400", "Malformed JSON body"));
            wanted.push(("413", "Request body over the route's limit"));
            wanted.push(("415", "Body not sent as application/json"));
            wanted.push(("422", "A field breaks a rule; `field` names it"));
        }
        for (status, description) in wanted {
            operation
                .responses
                .responses
                .entry(status.to_string())
                .or_insert_with(|| Self::problem(description));
        }
    }
}

impl Modify for CommonErrors {
    fn modify(&self, openapi: &mut utoipa::openapi::OpenApi) {
        for (path, item) in openapi.paths.paths.iter_mut() {
            for (operation, write) in [
                (&mut item.get, false),
                (&mut item.head, false),
                (&mut item.post, true),
                (&mut item.put, true),
                (&mut item.patch, true),
                (&mut item.delete, true),
            ] {
                if let Some(operation) = operation.as_mut() {
                    Self::add(operation, path, write);
                }
            }
        }
    }
}

/// OpenAPI links from what creates a resource to what reads it (a job's id to its status,
/// attempts, result and cancel; a campaign's id to its JSON; a rail's serial to the rail, its
/// history and report; a token's id to its revocation), so clients and the property-based run
/// can follow them.
struct Links;

impl Links {
    /// (path, method, status, link name, target operation id, target parameter, expression).
    const LINKS: &'static [(
        &'static str,
        &'static str,
        &'static str,
        &'static str,
        &'static str,
        &'static str,
        &'static str,
    )] = &[
        (
            "/v1/jobs",
            "post",
            "201",
            "GetJob",
            "get_job",
            "id",
            "$response.body#/id",
        ),
        (
            "/v1/jobs",
            "post",
            "201",
            "GetAttempts",
            "get_attempts",
            "id",
            "$response.body#/id",
        ),
        (
            "/v1/jobs",
            "post",
            "201",
            "GetResult",
            "get_result",
            "id",
            "$response.body#/id",
        ),
        (
            "/v1/jobs",
            "post",
            "201",
            "CancelJob",
            "cancel_job",
            "id",
            "$response.body#/id",
        ),
        (
            "/v1/campaigns",
            "post",
            "201",
            "GetCampaign",
            "get_campaign",
            "id",
            "$response.body#/id",
        ),
        (
            "/v1/rails/{serial}/measurements",
            "post",
            "201",
            "GetRail",
            "get_rail",
            "serial",
            "$request.path.serial",
        ),
        (
            "/v1/rails/{serial}/measurements",
            "post",
            "201",
            "ListMeasurements",
            "list_measurements",
            "serial",
            "$request.path.serial",
        ),
        (
            "/v1/rails/{serial}/measurements",
            "post",
            "201",
            "GetReport",
            "get_report",
            "serial",
            "$request.path.serial",
        ),
        (
            "/v1/tokens",
            "post",
            "201",
            "RevokeToken",
            "revoke_token",
            "id",
            "$response.body#/id",
        ),
    ];
}

impl Modify for Links {
    fn modify(&self, openapi: &mut utoipa::openapi::OpenApi) {
        use utoipa::openapi::link::LinkBuilder;
        use utoipa::openapi::RefOr;
        for (path, method, status, name, target, parameter, expression) in Self::LINKS {
            let Some(item) = openapi.paths.paths.get_mut(*path) else {
                continue;
            };
            let operation = match *method {
                "post" => item.post.as_mut(),
                _ => item.get.as_mut(),
            };
            let Some(RefOr::T(response)) =
                operation.and_then(|op| op.responses.responses.get_mut(*status))
            else {
                continue;
            };
            response.links.insert(
                name.to_string(),
                RefOr::T(
                    LinkBuilder::new()
                        .operation_id(*target)
                        .parameter(*parameter, *expression)
                        .build(),
                ),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn links_name_their_target_operation_as_openapi_spells_it() {
        let doc: serde_json::Value =
            serde_json::from_str(&super::openapi_json()).expect("the document is JSON");
        let link = &doc["paths"]["/v1/jobs"]["post"]["responses"]["201"]["links"]["GetJob"];
        assert_eq!(link["operationId"], "get_job", "{link}");
        assert_eq!(link["parameters"]["id"], "$response.body#/id");
        assert!(!super::openapi_json().contains("\"operation_id\""));
    }
}

#[derive(OpenApi)]
#[openapi(
    info(
        title = "railwear",
        description = "Launcher-rail and missile-shoe wear prediction: jobs (simulate, sweep, calibrate, diagnose), rail measurements and service-life reports. Errors are application/problem+json. Send `Authorization: Bearer <token>`; roles: planner (rails), engineer (jobs, curves), test_engineer (test campaigns and their diagnoses), admin (tokens, and everything)."
    ),
    paths(
        jobs::submit_job, jobs::list_jobs, jobs::get_job, jobs::get_attempts, jobs::cancel_job,
        jobs::get_result,
        jobs::get_tracks, jobs::get_plot,
        rails::post_measurement, rails::list_rails, rails::get_rail, rails::list_measurements,
        rails::get_report,
        curves::list_curves, curves::get_curve, curves::publish_curve,
        campaigns::upload_campaign, campaigns::list_campaigns, campaigns::get_campaign,
        campaigns::submit_diagnosis,
        tokens::create_token, tokens::list_tokens, tokens::revoke_token, tokens::whoami,
        ops::healthz, ops::readyz, ops::metrics, openapi,
    ),
    components(schemas(
        problem::Problem,
        jobs::JobRequest, jobs::JobView, jobs::JobLinks, jobs::JobResultView, jobs::PlotLink,
        jobs::AttemptView,
        pagination::PageView<jobs::JobView>, pagination::PageView<rails::RailView>,
        pagination::PageView<rails::MeasurementView>,
        crate::jobs::JobKind, crate::jobs::JobStatus, crate::jobs::JobProgress,
        rails::CurvePointView, crate::analysis::rattle_space::LauncherDimensions,
        rails::MeasurementRequest, rails::MeasurementView, rails::RailView, rails::ReportView,
        rails::ServiceLife, rails::MissingCurve, rails::ServiceLifeInterval, rails::ReportCurve,
        curves::CurveView, curves::FidelityView, curves::CurveLinks, curves::PublishRequest,
        pagination::PageView<curves::CurveView>,
        campaigns::CampaignView, campaigns::CampaignCountsView, campaigns::CampaignLinks,
        campaigns::DiagnosisRequest,
        campaigns::CampaignDocument, campaigns::CampaignTestDocument, campaigns::DriveDocument,
        campaigns::SpecimenDocument, campaigns::IncrementDocument,
        campaigns::AccelRecordDocument, campaigns::AccelLocationDocument,
        pagination::PageView<campaigns::CampaignView>,
        tokens::TokenRequest, tokens::TokenView, tokens::CreatedToken, tokens::WhoAmI,
        tokens::Permissions,
        crate::store::Role,
    )),
    modifiers(&BearerAuth, &CommonErrors, &Links),
    tags(
        (name = "jobs", description = "Simulation, sweep and calibration jobs (engineer)"),
        (name = "rails", description = "Rail registry, measurements and service-life reports (planner)"),
        (name = "curves", description = "Penalization curve versions; publishing one makes reports use it (engineer)"),
        (name = "campaigns", description = "Test campaigns: measured wear and accelerometer records of physical tests (upload: test_engineer; read: every role)"),
        (name = "tokens", description = "API tokens (admin)"),
        (name = "ops", description = "Health, readiness, metrics, this document"),
    )
)]
pub struct ApiDoc;

/// The OpenAPI document as pretty JSON with a trailing newline (the exact text of
/// `api/openapi.json`).
/// Serves the document (no token).
pub fn router() -> Router<AppState> {
    Router::new().route("/v1/openapi.json", get(openapi))
}

/// This API's OpenAPI 3.1 document.
#[utoipa::path(get, path = "/v1/openapi.json", tag = "ops", responses((status = 200, description = "OpenAPI document", content_type = "application/json")))]
pub async fn openapi() -> Response {
    ([(header::CONTENT_TYPE, "application/json")], openapi_json()).into_response()
}

/// The document as pretty JSON text.
pub fn openapi_json() -> String {
    let mut doc = ApiDoc::openapi();
    doc.info.version = env!("CARGO_PKG_VERSION").to_string();
    let text = doc
        .to_pretty_json()
        .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"));
    // utoipa 5.5 writes a Link Object's fields in snake case; OpenAPI spells them
    // `operationId` (no other key of this document is `operation_id`).
    let mut text = text.replace("\"operation_id\": ", "\"operationId\": ");
    text.push('\n');
    text
}
