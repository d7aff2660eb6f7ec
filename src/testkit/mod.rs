//! Test and bench support, not part of the service: one small async HTTP/1.1 client
//! ([`http`]), the real `railwear` binary spawned on a free port ([`server`]), a throwaway
//! PostgreSQL database ([`postgres`]) and a temporary directory removed on drop ([`tempdir`]).
//! The integration tests (`tests/`) and `railwear-bench` both use it, so neither keeps a copy.
//!
//! It depends on no other room of the crate (tokio, sqlx and uuid only).

pub mod http;
pub mod postgres;
pub mod server;
pub mod tempdir;

pub use http::{Client, ClientError, Conn, Request, Response};
pub use postgres::ThrowawayDb;
pub use server::{serve_command, ServerProcess, SpawnError};
pub use tempdir::TempDir;
