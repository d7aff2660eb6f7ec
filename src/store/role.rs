//! The access role a token carries: stored with every token row, checked by the HTTP layer,
//! named in the service settings.

use serde::{Deserialize, Serialize};

/// Access role carried by an API token.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Maintenance planner: registers rails, posts measurements, reads reports.
    Planner,
    /// Engineer: submits, watches, cancels simulation/sweep/calibration jobs.
    Engineer,
    /// Test engineer: uploads test campaigns (measured wear and accelerometer records of
    /// physical tests, issue 14). `test-engineer` is accepted on the command line and in
    /// `RAILWEAR_TOKENS`.
    #[serde(rename = "test_engineer")]
    TestEngineer,
    /// Administrator: manages tokens; may also do what planners and engineers do.
    Admin,
}

impl Role {
    /// Lower-case name as used in config, CLI and API.
    pub fn as_str(self) -> &'static str {
        match self {
            Role::Planner => "planner",
            Role::Engineer => "engineer",
            Role::TestEngineer => "test_engineer",
            Role::Admin => "admin",
        }
    }

    /// Parse a lower-case role name (`test-engineer` is read as `test_engineer`).
    pub fn parse(text: &str) -> Option<Role> {
        match text {
            "planner" => Some(Role::Planner),
            "engineer" => Some(Role::Engineer),
            "test_engineer" | "test-engineer" => Some(Role::TestEngineer),
            "admin" => Some(Role::Admin),
            _ => None,
        }
    }
}
