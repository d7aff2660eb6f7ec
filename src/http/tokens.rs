//! `/v1/tokens` (admin): create, list and revoke API tokens.

use super::auth::{generate_token, token_sha256, Area, Caller};
use super::problem::{read_json, Problem};
use super::AppState;
use crate::store::Role;
use crate::store::{clock, TokenRecord};
use axum::extract::{Path, State};
use axum::http::{Method, StatusCode};
use axum::routing::{delete, get};
use axum::{Json, Router};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;
use uuid::Uuid;

pub fn router() -> Router<AppState> {
    Router::new()
        .route("/v1/tokens", get(list_tokens).post(create_token))
        .route("/v1/tokens/{id}", delete(revoke_token))
        .route("/v1/whoami", get(whoami))
}

/// The caller's token: its name, role and what the role may do (so a client such as the
/// dashboard shows only the actions it may take).
#[derive(Debug, Serialize, ToSchema)]
pub struct WhoAmI {
    /// Token name.
    pub name: String,
    pub role: Role,
    pub may: Permissions,
}

/// What a role may do besides reading (every role reads rails, jobs, curves and campaigns).
#[derive(Debug, Serialize, ToSchema)]
pub struct Permissions {
    /// `POST /v1/jobs` (simulate, sweep, calibrate), cancel jobs.
    pub submit_jobs: bool,
    /// Record rail measurements.
    pub record_measurements: bool,
    /// Publish penalization curves.
    pub publish_curves: bool,
    /// `POST /v1/campaigns`.
    pub upload_campaigns: bool,
    /// `POST /v1/campaigns/{id}/diagnoses`.
    pub diagnose: bool,
    /// Create, list and revoke tokens.
    pub manage_tokens: bool,
}

/// Who the token is and what its role may do (every valid token).
#[utoipa::path(
    get, path = "/v1/whoami", tag = "tokens",
    responses(
        (status = 200, description = "The token's name, role and permissions", body = WhoAmI),
        (status = 401, body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn whoami(caller: Caller) -> Json<WhoAmI> {
    let post = Method::POST;
    Json(WhoAmI {
        may: Permissions {
            submit_jobs: caller.allowed(Area::Jobs, &post),
            record_measurements: caller.allowed(Area::Rails, &post),
            publish_curves: caller.allowed(Area::Curves, &post),
            upload_campaigns: caller.allowed(Area::Campaigns, &post),
            diagnose: caller.may_diagnose(),
            manage_tokens: caller.allowed(Area::Tokens, &post),
        },
        name: caller.name,
        role: caller.role,
    })
}

/// A token to create.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TokenRequest {
    /// Who will hold the token (1-100 characters, not only spaces).
    #[schema(min_length = 1, max_length = 100, pattern = "\\S")]
    pub name: String,
    pub role: Role,
}

/// A stored token (without its secret).
#[derive(Debug, Serialize, ToSchema)]
pub struct TokenView {
    pub id: Uuid,
    pub name: String,
    pub role: Role,
    pub created_at: String,
    pub revoked: bool,
}

/// A created token: the secret is shown this once.
#[derive(Debug, Serialize, ToSchema)]
pub struct CreatedToken {
    #[serde(flatten)]
    pub info: TokenView,
    /// Send as `Authorization: Bearer <token>`. Not retrievable later.
    pub token: String,
}

impl From<TokenRecord> for TokenView {
    fn from(t: TokenRecord) -> Self {
        TokenView {
            id: t.id,
            name: t.name,
            role: t.role,
            created_at: clock::rfc3339(t.created_ms),
            revoked: t.revoked,
        }
    }
}

/// Create a token (admin).
#[utoipa::path(
    post, path = "/v1/tokens", tag = "tokens",
    request_body = TokenRequest,
    responses(
        (status = 201, body = CreatedToken),
        (status = 403, body = Problem, content_type = "application/problem+json"),
        (status = 422, body = Problem, content_type = "application/problem+json"),
    ),
    security(("bearer" = []))
)]
pub async fn create_token(
    State(state): State<AppState>,
    caller: Caller,
    body: axum::extract::Request,
) -> Result<(StatusCode, Json<CreatedToken>), Problem> {
    caller.require(Area::Tokens, &Method::POST)?;
    let request: TokenRequest = read_json(body).await?;
    let name = request.name.trim();
    if name.is_empty() || name.chars().count() > 100 {
        return Err(Problem::invalid_field(
            "name",
            "must be 1 to 100 characters",
        ));
    }
    if name.chars().any(char::is_control) {
        return Err(Problem::invalid_field(
            "name",
            "must not contain control characters",
        ));
    }
    let token = generate_token();
    let record = state
        .store
        .create_token(name, request.role, &token_sha256(&token), clock::now_ms())
        .await?;
    Ok((
        StatusCode::CREATED,
        Json(CreatedToken {
            info: record.into(),
            token,
        }),
    ))
}

/// List tokens (admin). Tokens from the settings file are not listed.
#[utoipa::path(
    get, path = "/v1/tokens", tag = "tokens",
    responses((status = 200, body = Vec<TokenView>), (status = 403, body = Problem, content_type = "application/problem+json")),
    security(("bearer" = []))
)]
pub async fn list_tokens(
    State(state): State<AppState>,
    caller: Caller,
) -> Result<Json<Vec<TokenView>>, Problem> {
    caller.require(Area::Tokens, &Method::GET)?;
    let tokens = state.store.list_tokens().await?;
    Ok(Json(tokens.into_iter().map(TokenView::from).collect()))
}

/// Revoke a token (admin).
#[utoipa::path(
    delete, path = "/v1/tokens/{id}", tag = "tokens",
    params(("id" = Uuid, Path)),
    responses((status = 204), (status = 404, body = Problem, content_type = "application/problem+json")),
    security(("bearer" = []))
)]
pub async fn revoke_token(
    State(state): State<AppState>,
    caller: Caller,
    Path(id): Path<String>,
) -> Result<StatusCode, Problem> {
    caller.require(Area::Tokens, &Method::DELETE)?;
    let id = Uuid::parse_str(&id).map_err(|_| Problem::bad_parameter("id", "must be a UUID"))?;
    if state.store.revoke_token(id, clock::now_ms()).await? {
        Ok(StatusCode::NO_CONTENT)
    } else {
        Err(Problem::not_found(format!("no active token {id}")))
    }
}
