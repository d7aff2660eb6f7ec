//! What railwear's tests and its benchmark program share, kept out of the `railwear` library
//! that users build: an HTTP client of the service on `reqwest` ([`http`]), the real `railwear`
//! binary spawned on a free port ([`server`]), a throwaway PostgreSQL database ([`postgres`]),
//! a temporary directory removed on drop ([`tempdir`]) and the check that a figure's text lies
//! inside its picture ([`svg`]).
//!
//! A dev-dependency of `railwear` (its integration tests) and a dependency of `railwear-bench`;
//! it depends on no part of `railwear`, so the library is built once for both.

pub mod http;
pub mod postgres;
pub mod server;
pub mod svg;
pub mod tempdir;

pub use http::{Client, ClientError, Request, Response};
pub use postgres::ThrowawayDb;
pub use server::{serve_command, ServerProcess, SpawnError};
pub use tempdir::TempDir;
