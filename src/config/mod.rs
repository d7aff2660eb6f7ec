//! Typed settings: the service settings (file then environment) and the reference model configs
//! in `configs/`, available by name.

pub mod reference;
pub mod service;

pub use reference::{reference_config_names, reference_config_path, ReferenceError};
pub use service::{ConfigError, Role, ServiceConfig, TokenSetting};
