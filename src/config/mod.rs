//! Typed settings of the service: built-in defaults, then `configs/service.toml`, then the
//! environment. The reference model configs in `configs/` are found by
//! [`crate::models::reference`]; the token roles are the store's ([`crate::store::Role`]).

pub mod service;

// Former paths, kept for callers outside the library.
pub use crate::models::reference::{reference_config_names, reference_config_path, ReferenceError};
pub use service::{ConfigError, Role, ServiceConfig, TokenSetting};
