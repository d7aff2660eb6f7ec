//! contact_models
