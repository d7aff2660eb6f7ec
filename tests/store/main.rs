//! The store test binary: `Store` implementations called directly (SQLite and PostgreSQL), the
//! fan-out bookkeeping and the worker leases over a store. One module per concern.

#[path = "../support/mod.rs"]
mod support;

mod postgres_store;
mod postgres_store_script;
mod store_fanout;
mod store_fanout_migration;
mod worker_leases;
