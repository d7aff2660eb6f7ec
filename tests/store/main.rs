//! The store test binary: `Store` implementations called directly (SQLite and PostgreSQL), the
//! fan-out bookkeeping and the worker leases over a store. One module per concern.

#[path = "../support/mod.rs"]
mod support;

mod postgres_store;
mod store_fanout;
mod worker_leases;
