//! Service settings, layered: built-in defaults, then `configs/service.toml` (every key is
//! documented there), then `RAILWEAR_*` environment variables (and `DATABASE_URL`).

use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub use crate::store::Role;

/// A token given in the configuration (in addition to tokens created with `railwear token create`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TokenSetting {
    /// Who holds the token (shown in logs and job records).
    pub name: String,
    /// What the token may do.
    pub role: Role,
    /// The secret itself (sent as `Authorization: Bearer <token>`).
    pub token: String,
}

/// Defaults a rail report uses when the request does not name them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReportSettings {
    /// Vehicle profile whose penalization curve applies (e.g. `ah64`).
    pub vehicle_profile: String,
    /// Environment label of the curve (e.g. `clean`, `sand`).
    pub environment: String,
    /// Wear law of the curve (`modified-archard` eq. 3.10-3.15, or `archard` eq. 3.8).
    pub wear_law: String,
    /// Design service life T_SL,design that K_SL scales (eq. 6.4), hours.
    pub design_life_h: f64,
}

impl Default for ReportSettings {
    fn default() -> Self {
        Self {
            vehicle_profile: "ah64".into(),
            environment: "clean".into(),
            wear_law: "modified-archard".into(),
            design_life_h: 1000.0,
        }
    }
}

/// Default largest campaign upload: 32 MiB. A sample `[time_s, a_x, a_y, a_z]` is about 80
/// bytes of JSON, so this holds about 400 000 samples: e.g. 20 records of 10 s at 2 kHz, or one
/// 200 s record at 2 kHz (the rattle box's 20 Hz tone sampled 100 times a period).
pub const DEFAULT_CAMPAIGN_BODY_LIMIT_BYTES: usize = 32 * 1024 * 1024;

/// All service settings. See `configs/service.toml` for the meaning of each key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ServiceConfig {
    /// Socket address to listen on; port 0 picks a free port (printed on start).
    pub listen: String,
    /// sqlx database URL: `sqlite://path?mode=rwc` (PostgreSQL follows, issue 6).
    pub database_url: String,
    /// Directory of reference model configs, looked up by name.
    pub configs_dir: PathBuf,
    /// Worker threads running simulations; 0 means one per CPU core.
    pub workers: usize,
    /// A running job's lease, s: if its worker stops heartbeating this long the job is re-queued.
    pub lease_s: f64,
    /// Heartbeat (and progress write) interval of a running job, s. Must be well below `lease_s`.
    pub heartbeat_s: f64,
    /// How often an idle worker looks for queued jobs, ms (a submission also wakes it at once).
    pub poll_interval_ms: u64,
    /// Attempts before a job whose worker keeps dying is failed.
    pub max_attempts: u32,
    /// On SIGTERM, how long a running attempt gets to stop at a step boundary before its job
    /// is given back to the queue anyway, s.
    pub shutdown_grace_s: f64,
    /// Largest accepted request body, bytes.
    pub body_limit_bytes: usize,
    /// Largest accepted campaign upload (`POST /v1/campaigns`, accelerometer samples inline),
    /// bytes.
    pub campaign_body_limit_bytes: usize,
    /// Time a client gets to send a request's head (request line and headers), s; past it the
    /// connection is closed. Also bounds how long an idle keep-alive connection is held.
    pub header_read_timeout_s: f64,
    /// Time a client gets to send a request's whole body once its head has arrived, s; past it
    /// the request is answered 408 and the connection closed.
    pub body_read_timeout_s: f64,
    /// Open connections held at once; one more is answered 503 and closed.
    pub max_connections: usize,
    /// Open connections held at once from one peer address; one more is answered 429 and closed.
    pub max_connections_per_peer: usize,
    /// Log format: `text` or `json`.
    pub log_format: String,
    /// Samples per stored contact-track block (each block is compressed on its own).
    pub track_block_samples: usize,
    /// Samples (track samples, or response samples) a running simulation gathers before it
    /// stores them as a record chunk: a shutdown checkpoint carries fewer than this many of
    /// each, so its size and write time stay bounded however long the run.
    pub checkpoint_chunk_samples: usize,
    /// Rail-report defaults.
    pub report: ReportSettings,
    /// Tokens accepted in addition to those stored in the database.
    pub tokens: Vec<TokenSetting>,
}

impl Default for ServiceConfig {
    fn default() -> Self {
        Self {
            listen: "127.0.0.1:8080".into(),
            database_url: "sqlite://railwear.db?mode=rwc".into(),
            configs_dir: PathBuf::from("configs"),
            workers: 0,
            lease_s: 15.0,
            heartbeat_s: 1.0,
            poll_interval_ms: 250,
            max_attempts: 3,
            shutdown_grace_s: 5.0,
            body_limit_bytes: 8 * 1024 * 1024,
            campaign_body_limit_bytes: DEFAULT_CAMPAIGN_BODY_LIMIT_BYTES,
            header_read_timeout_s: 10.0,
            body_read_timeout_s: 60.0,
            max_connections: 1024,
            max_connections_per_peer: 256,
            log_format: "text".into(),
            track_block_samples: 16_384,
            checkpoint_chunk_samples: 8_192,
            report: ReportSettings::default(),
            tokens: Vec::new(),
        }
    }
}

/// Why the settings could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The settings file could not be read.
    #[error("cannot read {path}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The settings file is not valid TOML for [`ServiceConfig`].
    #[error("{path} is not valid settings TOML")]
    Parse {
        path: PathBuf,
        source: Box<toml::de::Error>,
    },
    /// A setting (from file or environment) breaks a rule.
    #[error("setting `{}` {}", .0.field, .0.rule)]
    Invalid(#[from] FieldError),
}

impl ServiceConfig {
    /// Defaults, then the file at `path` (when `required` is false a missing file is fine),
    /// then the environment given by `env` (a lookup function, so tests need not mutate the
    /// process environment).
    pub fn load(
        path: &Path,
        required: bool,
        env: impl Fn(&str) -> Option<String>,
    ) -> Result<Self, ConfigError> {
        let mut config = match std::fs::read_to_string(path) {
            Ok(text) => toml::from_str(&text).map_err(|source| ConfigError::Parse {
                path: path.to_path_buf(),
                source: Box::new(source),
            })?,
            Err(source) if required || source.kind() != std::io::ErrorKind::NotFound => {
                return Err(ConfigError::Read {
                    path: path.to_path_buf(),
                    source,
                })
            }
            Err(_) => ServiceConfig::default(),
        };
        config.apply_env(env)?;
        config.validate()?;
        Ok(config)
    }

    /// Override settings from environment variables (`RAILWEAR_*`, `DATABASE_URL`).
    pub fn apply_env(&mut self, env: impl Fn(&str) -> Option<String>) -> Result<(), ConfigError> {
        fn num<T: std::str::FromStr>(field: &str, text: &str) -> Result<T, ConfigError> {
            text.trim()
                .parse()
                .map_err(|_| FieldError::new(field, "must be a number").into())
        }
        if let Some(v) = env("RAILWEAR_LISTEN") {
            self.listen = v;
        }
        if let Some(v) = env("DATABASE_URL") {
            self.database_url = v;
        }
        if let Some(v) = env("RAILWEAR_DATABASE_URL") {
            self.database_url = v;
        }
        if let Some(v) = env("RAILWEAR_CONFIGS_DIR") {
            self.configs_dir = PathBuf::from(v);
        }
        if let Some(v) = env("RAILWEAR_WORKERS") {
            self.workers = num("RAILWEAR_WORKERS", &v)?;
        }
        if let Some(v) = env("RAILWEAR_LEASE_S") {
            self.lease_s = num("RAILWEAR_LEASE_S", &v)?;
        }
        if let Some(v) = env("RAILWEAR_HEARTBEAT_S") {
            self.heartbeat_s = num("RAILWEAR_HEARTBEAT_S", &v)?;
        }
        if let Some(v) = env("RAILWEAR_POLL_INTERVAL_MS") {
            self.poll_interval_ms = num("RAILWEAR_POLL_INTERVAL_MS", &v)?;
        }
        if let Some(v) = env("RAILWEAR_MAX_ATTEMPTS") {
            self.max_attempts = num("RAILWEAR_MAX_ATTEMPTS", &v)?;
        }
        if let Some(v) = env("RAILWEAR_SHUTDOWN_GRACE_S") {
            self.shutdown_grace_s = num("RAILWEAR_SHUTDOWN_GRACE_S", &v)?;
        }
        if let Some(v) = env("RAILWEAR_BODY_LIMIT_BYTES") {
            self.body_limit_bytes = num("RAILWEAR_BODY_LIMIT_BYTES", &v)?;
        }
        if let Some(v) = env("RAILWEAR_CAMPAIGN_BODY_LIMIT_BYTES") {
            self.campaign_body_limit_bytes = num("RAILWEAR_CAMPAIGN_BODY_LIMIT_BYTES", &v)?;
        }
        if let Some(v) = env("RAILWEAR_HEADER_READ_TIMEOUT_S") {
            self.header_read_timeout_s = num("RAILWEAR_HEADER_READ_TIMEOUT_S", &v)?;
        }
        if let Some(v) = env("RAILWEAR_BODY_READ_TIMEOUT_S") {
            self.body_read_timeout_s = num("RAILWEAR_BODY_READ_TIMEOUT_S", &v)?;
        }
        if let Some(v) = env("RAILWEAR_MAX_CONNECTIONS") {
            self.max_connections = num("RAILWEAR_MAX_CONNECTIONS", &v)?;
        }
        if let Some(v) = env("RAILWEAR_MAX_CONNECTIONS_PER_PEER") {
            self.max_connections_per_peer = num("RAILWEAR_MAX_CONNECTIONS_PER_PEER", &v)?;
        }
        if let Some(v) = env("RAILWEAR_LOG_FORMAT") {
            self.log_format = v;
        }
        if let Some(v) = env("RAILWEAR_TOKENS") {
            // `name:role:token` entries separated by `,`.
            for entry in v.split(',').map(str::trim).filter(|e| !e.is_empty()) {
                let mut parts = entry.splitn(3, ':');
                let (Some(name), Some(role), Some(token)) =
                    (parts.next(), parts.next(), parts.next())
                else {
                    return Err(FieldError::new(
                        "RAILWEAR_TOKENS",
                        "entries must be name:role:token",
                    )
                    .into());
                };
                let role = Role::parse(role).ok_or_else(|| {
                    FieldError::new(
                        "RAILWEAR_TOKENS",
                        "role must be planner, engineer, test_engineer or admin",
                    )
                })?;
                self.tokens.push(TokenSetting {
                    name: name.to_string(),
                    role,
                    token: token.to_string(),
                });
            }
        }
        Ok(())
    }

    /// Check the rules every setting must follow.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !(self.lease_s.is_finite() && self.lease_s > 0.0) {
            return Err(FieldError::new("lease_s", "must be a positive number of seconds").into());
        }
        if !(self.heartbeat_s.is_finite() && self.heartbeat_s > 0.0) {
            return Err(
                FieldError::new("heartbeat_s", "must be a positive number of seconds").into(),
            );
        }
        if self.heartbeat_s * 2.0 > self.lease_s {
            return Err(FieldError::new("heartbeat_s", "must be at most half of lease_s").into());
        }
        if !(self.shutdown_grace_s.is_finite() && (0.0..=300.0).contains(&self.shutdown_grace_s)) {
            return Err(FieldError::new(
                "shutdown_grace_s",
                "must be a number of seconds in [0, 300]",
            )
            .into());
        }
        if self.max_attempts == 0 {
            return Err(FieldError::new("max_attempts", "must be at least 1").into());
        }
        if self.body_limit_bytes < 1024 {
            return Err(FieldError::new("body_limit_bytes", "must be at least 1024").into());
        }
        if self.campaign_body_limit_bytes < 1024 {
            return Err(
                FieldError::new("campaign_body_limit_bytes", "must be at least 1024").into(),
            );
        }
        for (field, seconds) in [
            ("header_read_timeout_s", self.header_read_timeout_s),
            ("body_read_timeout_s", self.body_read_timeout_s),
        ] {
            if !(seconds.is_finite() && (0.1..=3600.0).contains(&seconds)) {
                return Err(
                    FieldError::new(field, "must be a number of seconds in [0.1, 3600]").into(),
                );
            }
        }
        if self.max_connections == 0 {
            return Err(FieldError::new("max_connections", "must be at least 1").into());
        }
        if self.max_connections_per_peer == 0
            || self.max_connections_per_peer > self.max_connections
        {
            return Err(FieldError::new(
                "max_connections_per_peer",
                "must be at least 1 and at most max_connections",
            )
            .into());
        }
        if self.track_block_samples == 0 {
            return Err(FieldError::new("track_block_samples", "must be at least 1").into());
        }
        if self.checkpoint_chunk_samples == 0 {
            return Err(FieldError::new("checkpoint_chunk_samples", "must be at least 1").into());
        }
        if self.log_format != "text" && self.log_format != "json" {
            return Err(FieldError::new("log_format", "must be `text` or `json`").into());
        }
        if !(self.report.design_life_h.is_finite() && self.report.design_life_h > 0.0) {
            return Err(FieldError::new(
                "report.design_life_h",
                "must be a positive number of hours",
            )
            .into());
        }
        for (i, token) in self.tokens.iter().enumerate() {
            if token.token.len() < 16 {
                return Err(FieldError::new(
                    format!("tokens[{i}].token"),
                    "must be at least 16 characters",
                )
                .into());
            }
        }
        Ok(())
    }

    /// `database_url` without its password (`postgres://user:***@host/db`), for logs.
    pub fn redacted_database_url(&self) -> String {
        redact_url_password(&self.database_url)
    }

    /// `configs_dir` made absolute (against the working directory) so logs and errors name
    /// the directory actually searched.
    pub fn resolved_configs_dir(&self) -> PathBuf {
        let dir = if self.configs_dir.is_absolute() {
            self.configs_dir.clone()
        } else {
            std::env::current_dir()
                .map(|cwd| cwd.join(&self.configs_dir))
                .unwrap_or_else(|_| self.configs_dir.clone())
        };
        dir.canonicalize().unwrap_or(dir)
    }

    /// Worker-pool settings (lease, heartbeat, poll, attempts, track blocks, record chunks,
    /// shutdown grace).
    pub fn worker_settings(&self) -> crate::jobs::WorkerSettings {
        crate::jobs::WorkerSettings {
            lease: std::time::Duration::from_secs_f64(self.lease_s),
            heartbeat: std::time::Duration::from_secs_f64(self.heartbeat_s),
            poll: std::time::Duration::from_millis(self.poll_interval_ms.max(1)),
            max_attempts: self.max_attempts,
            track_block_samples: self.track_block_samples,
            record_chunk_samples: self.checkpoint_chunk_samples,
            shutdown_grace: std::time::Duration::from_secs_f64(self.shutdown_grace_s),
        }
    }

    /// Number of worker threads to run (`workers`, or one per core when 0).
    pub fn worker_count(&self) -> usize {
        if self.workers > 0 {
            self.workers
        } else {
            std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1)
        }
    }
}

/// A URL with the password of its userinfo replaced by `***` (no userinfo: unchanged).
pub fn redact_url_password(url: &str) -> String {
    let Some((scheme, rest)) = url.split_once("://") else {
        return url.to_string();
    };
    let authority_end = rest.find(['/', '?', '#']).unwrap_or(rest.len());
    let (authority, tail) = rest.split_at(authority_end);
    match authority.rsplit_once('@') {
        Some((userinfo, host)) => match userinfo.split_once(':') {
            Some((user, _password)) => format!("{scheme}://{user}:***@{host}{tail}"),
            None => url.to_string(),
        },
        None => url.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn environment_overrides_file() {
        let dir = std::env::temp_dir().join(format!("railwear-cfg-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("service.toml");
        std::fs::write(&path, "workers = 3\nlease_s = 20.0\n").unwrap();
        let env = |key: &str| match key {
            "RAILWEAR_WORKERS" => Some("5".to_string()),
            "RAILWEAR_TOKENS" => Some("ops:planner:0123456789abcdef0123".to_string()),
            _ => None,
        };
        let config = ServiceConfig::load(&path, true, env).unwrap();
        assert_eq!(config.workers, 5);
        assert_eq!(config.lease_s, 20.0);
        assert_eq!(config.tokens.len(), 1);
        assert_eq!(config.tokens[0].role, Role::Planner);
    }

    #[test]
    fn bad_settings_name_the_field() {
        let env = |key: &str| (key == "RAILWEAR_HEARTBEAT_S").then(|| "30".to_string());
        let err =
            ServiceConfig::load(Path::new("/nonexistent/service.toml"), false, env).unwrap_err();
        assert!(
            matches!(err, ConfigError::Invalid(FieldError { ref field, .. }) if field == "heartbeat_s")
        );
        let env = |key: &str| (key == "RAILWEAR_WORKERS").then(|| "many".to_string());
        let err =
            ServiceConfig::load(Path::new("/nonexistent/service.toml"), false, env).unwrap_err();
        assert!(
            matches!(err, ConfigError::Invalid(FieldError { ref field, .. }) if field == "RAILWEAR_WORKERS")
        );
    }

    #[test]
    fn shipped_service_toml_parses() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/service.toml");
        let config = ServiceConfig::load(&path, true, |_| None).unwrap();
        assert_eq!(config.database_url, "sqlite://railwear.db?mode=rwc");
    }

    #[test]
    fn database_url_passwords_are_not_logged() {
        assert_eq!(
            redact_url_password(
                "postgres://railwear:s3cr%40t@db-host:5432/railwear?sslmode=require"
            ),
            "postgres://railwear:***@db-host:5432/railwear?sslmode=require"
        );
        assert_eq!(
            redact_url_password("postgres://railwear@db-host/railwear"),
            "postgres://railwear@db-host/railwear"
        );
        assert_eq!(
            redact_url_password("sqlite://railwear.db?mode=rwc"),
            "sqlite://railwear.db?mode=rwc"
        );
    }
}
