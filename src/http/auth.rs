//! Bearer-token access with roles. Tokens come from the settings or from the database
//! (`railwear token create`, `POST /v1/tokens`); only their SHA-256 is compared or stored.

use super::problem::Problem;
use super::AppState;
use crate::store::Role;
use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use axum::http::{header, Method};
use sha2::{Digest, Sha256};

/// SHA-256 of a token, lower-case hex (what is stored and looked up).
pub fn token_sha256(token: &str) -> String {
    crate::jobs::hex(&Sha256::digest(token.as_bytes()))
}

/// A fresh random token: `rw_` and 64 hex digits (256 bits from the OS generator via UUID v4).
pub fn generate_token() -> String {
    format!(
        "rw_{}{}",
        uuid::Uuid::new_v4().simple(),
        uuid::Uuid::new_v4().simple()
    )
}

/// What a request wants to touch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Area {
    /// Rails, measurements, reports.
    Rails,
    /// Simulation, sweep and calibration jobs.
    Jobs,
    /// API tokens.
    Tokens,
    /// Penalization curve versions (publishing is an engineer's decision).
    Curves,
    /// Test campaigns: measured data of physical tests (uploading is a test engineer's).
    Campaigns,
}

/// The authenticated caller.
#[derive(Debug, Clone)]
pub struct Caller {
    pub name: String,
    pub role: Role,
}

impl Caller {
    /// Role policy: planners write rails, engineers write jobs and curves, test engineers
    /// write campaigns, admins everything; every role may read rails, jobs, curves and
    /// campaigns (a planner sees whether the sweep a report needs is running). Measured data
    /// is written only by those who measure it: engineers, who tune and run the model, do not
    /// upload campaigns, as they do not record rail measurements (docs/reference/campaigns.md).
    pub fn allowed(&self, area: Area, method: &Method) -> bool {
        let read = method == Method::GET || method == Method::HEAD;
        match (self.role, area) {
            (Role::Admin, _) => true,
            (_, Area::Tokens) => false,
            (_, Area::Rails | Area::Jobs | Area::Curves | Area::Campaigns) if read => true,
            (Role::Planner, Area::Rails) => true,
            (Role::Engineer, Area::Jobs | Area::Curves) => true,
            (Role::TestEngineer, Area::Campaigns) => true,
            _ => false,
        }
    }

    /// May start a diagnosis of a stored campaign: those who upload campaigns (test
    /// engineers) and those who run jobs (engineers), and admins.
    pub fn may_diagnose(&self) -> bool {
        self.allowed(Area::Campaigns, &Method::POST) || self.allowed(Area::Jobs, &Method::POST)
    }

    /// 403 unless [`Caller::allowed`].
    pub fn require(&self, area: Area, method: &Method) -> Result<(), Problem> {
        if self.allowed(area, method) {
            Ok(())
        } else {
            Err(Problem::forbidden(format!(
                "role `{}` may not {method} {}",
                self.role.as_str(),
                match area {
                    Area::Rails => "rails",
                    Area::Jobs => "jobs",
                    Area::Tokens => "tokens",
                    Area::Curves => "curves",
                    Area::Campaigns => "campaigns",
                }
            )))
        }
    }
}

impl FromRequestParts<AppState> for Caller {
    type Rejection = Problem;

    async fn from_request_parts(parts: &mut Parts, state: &AppState) -> Result<Self, Problem> {
        let header_value = parts
            .headers
            .get(header::AUTHORIZATION)
            .ok_or_else(|| Problem::unauthorized("send `Authorization: Bearer <token>`"))?;
        let token = header_value
            .to_str()
            .ok()
            .and_then(|v| v.strip_prefix("Bearer "))
            .map(str::trim)
            .filter(|t| !t.is_empty())
            .ok_or_else(|| {
                Problem::unauthorized("the Authorization header must be `Bearer <token>`")
            })?;
        let sha = token_sha256(token);
        if let Some((name, role)) = state.config_tokens.get(&sha) {
            return Ok(Caller {
                name: name.clone(),
                role: *role,
            });
        }
        match state.store.find_token(&sha).await? {
            Some(record) => Ok(Caller {
                name: record.name,
                role: record.role,
            }),
            None => Err(Problem::unauthorized("unknown or revoked token")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn role_policy() {
        let caller = |role| Caller {
            name: "t".into(),
            role,
        };
        let (get, post) = (Method::GET, Method::POST);
        assert!(caller(Role::Planner).allowed(Area::Rails, &post));
        assert!(!caller(Role::Planner).allowed(Area::Jobs, &post));
        assert!(caller(Role::Planner).allowed(Area::Jobs, &get));
        assert!(caller(Role::Engineer).allowed(Area::Jobs, &post));
        assert!(!caller(Role::Engineer).allowed(Area::Rails, &post));
        assert!(!caller(Role::Engineer).allowed(Area::Tokens, &get));
        assert!(caller(Role::Admin).allowed(Area::Tokens, &post));
        // Campaigns: uploaded by test engineers (and admins), read by every role.
        assert!(caller(Role::TestEngineer).allowed(Area::Campaigns, &post));
        assert!(caller(Role::Admin).allowed(Area::Campaigns, &post));
        assert!(!caller(Role::Planner).allowed(Area::Campaigns, &post));
        assert!(!caller(Role::Engineer).allowed(Area::Campaigns, &post));
        for role in [Role::Planner, Role::Engineer, Role::TestEngineer] {
            assert!(caller(role).allowed(Area::Campaigns, &get));
        }
        assert!(!caller(Role::TestEngineer).allowed(Area::Jobs, &post));
        assert!(!caller(Role::TestEngineer).allowed(Area::Rails, &post));
        assert!(!caller(Role::TestEngineer).allowed(Area::Tokens, &get));
    }

    #[test]
    fn sha256_of_known_text() {
        // FIPS 180-2 test vector for "abc".
        assert_eq!(
            token_sha256("abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        assert_ne!(generate_token(), generate_token());
        assert_eq!(generate_token().len(), 67);
    }
}
