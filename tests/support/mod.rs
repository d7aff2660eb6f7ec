//! Shared by the api and store test binaries: the four test tokens, temporary directories, a
//! throwaway PostgreSQL database ([`postgres`]) and the counting test runner ([`runner`]).
//! The HTTP side (client, real binary, `TestApp`) is in `tests/api/helpers.rs`; the pieces the
//! bench uses too live in the `railwear-testkit` crate (testkit/), a dev-dependency.
#![allow(dead_code)]

pub mod postgres;
pub mod runner;

pub use railwear_testkit::TempDir;

pub const ADMIN: &str = "admin-token-0123456789abcdef";
pub const ENGINEER: &str = "engineer-token-0123456789abcdef";
pub const PLANNER: &str = "planner-token-0123456789abcdef";
pub const TEST_ENGINEER: &str = "test-engineer-token-0123456789abcdef";

/// `RAILWEAR_TOKENS` value for the four test tokens.
pub fn tokens_env() -> String {
    format!(
        "root:admin:{ADMIN},eng:engineer:{ENGINEER},plan:planner:{PLANNER},\
         lab:test-engineer:{TEST_ENGINEER}"
    )
}

/// A fresh directory `railwear-<tag>-<pid>-<uuid>` under the system temp dir, removed on drop.
pub fn temp_dir(tag: &str) -> TempDir {
    TempDir::new(tag).expect("temp dir")
}
