//! The API test binary: the service over HTTP, in process ([`helpers::TestApp`]) or as the real
//! `railwear` binary, on SQLite or PostgreSQL. One module per concern.

#[path = "../support/mod.rs"]
mod support;

mod helpers;

mod api_schemathesis;
mod postgres_binary;
mod readme_journeys;
mod service_binary;
mod service_bounds;
mod service_campaigns;
mod service_dashboard;
mod service_diagnose;
mod service_fanout;
mod service_hostile;
mod service_jobs;
mod service_metrics;
mod service_openapi;
mod service_probes;
mod service_queue;
mod service_rails;
mod service_shutdown;
mod wire;
