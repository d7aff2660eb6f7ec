//! Reference model configurations shipped in `configs/` (rattle-box cases, launcher, fixture),
//! looked up by name so a job can say `"config": "rattle-box-c"`.

use std::path::{Path, PathBuf};

/// Why a reference config name could not be resolved.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    /// Names are file stems: letters, digits, `-` and `_` only (no paths).
    #[error("config name `{0}` must use only letters, digits, '-' and '_'")]
    BadName(String),
    /// No `<name>.toml` in the configs directory (`service` is the service's settings, not a
    /// model). Names what the directory holds; the directory itself only when it holds none
    /// (a misconfigured server), so a client is not told the server's paths.
    #[error("no reference config named `{name}` (known: {})", if known.is_empty() { format!("none in {}: is the configs directory right? set RAILWEAR_CONFIGS_DIR or --configs-dir", dir.display()) } else { known.join(", ") })]
    Unknown {
        name: String,
        dir: PathBuf,
        known: Vec<String>,
    },
}

/// Stem of the service settings file that shares the configs directory (`service.toml`): not
/// a model config.
pub const SERVICE_SETTINGS_STEM: &str = "service";

/// Path of the reference config `name` (`<dir>/<name>.toml`), refusing anything that is not a
/// plain file stem so a request cannot read outside the directory.
pub fn reference_config_path(dir: &Path, name: &str) -> Result<PathBuf, ReferenceError> {
    let plain = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    if !plain {
        return Err(ReferenceError::BadName(name.to_string()));
    }
    let path = dir.join(format!("{name}.toml"));
    if name != SERVICE_SETTINGS_STEM && path.is_file() {
        Ok(path)
    } else {
        Err(ReferenceError::Unknown {
            name: name.to_string(),
            dir: dir.to_path_buf(),
            known: reference_config_names(dir),
        })
    }
}

/// Names (file stems) of the reference configs in `dir`, sorted; `service.toml` is excluded
/// because it configures the service, not a model.
pub fn reference_config_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|entry| {
            let path = entry.path();
            if path.extension().and_then(|e| e.to_str()) != Some("toml") {
                return None;
            }
            let stem = path.file_stem()?.to_str()?.to_string();
            (stem != SERVICE_SETTINGS_STEM).then_some(stem)
        })
        .collect();
    names.sort();
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn path_traversal_is_refused() {
        let dir = Path::new(".");
        assert!(matches!(
            reference_config_path(dir, "../etc/passwd"),
            Err(ReferenceError::BadName(_))
        ));
        assert!(matches!(
            reference_config_path(dir, ""),
            Err(ReferenceError::BadName(_))
        ));
        assert!(matches!(
            reference_config_path(dir, "no-such-config"),
            Err(ReferenceError::Unknown { .. })
        ));
    }

    #[test]
    fn service_settings_are_not_a_model_and_only_an_empty_directory_is_named() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
        assert!(dir.join("service.toml").is_file());
        let err = reference_config_path(&dir, "service").unwrap_err();
        assert!(matches!(err, ReferenceError::Unknown { .. }));
        let text = err.to_string();
        // A client is told what exists, not where the server keeps it.
        assert!(!text.contains(&dir.display().to_string()), "{text}");
        assert!(text.contains("rattle-box-c"), "{text}");
        let empty = std::env::temp_dir().join(format!("railwear-noconfigs-{}", std::process::id()));
        let text = reference_config_path(&empty, "rattle-box-c")
            .unwrap_err()
            .to_string();
        assert!(text.contains(&empty.display().to_string()), "{text}");
        assert!(text.contains("RAILWEAR_CONFIGS_DIR"), "{text}");
    }
}
