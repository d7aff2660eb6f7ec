//! A fresh directory under the system temp dir, removed on drop.

use std::path::{Path, PathBuf};

/// `railwear-<tag>-<pid>-<uuid>` under the system temp dir; removed (with its contents) on drop.
/// The uuid makes it unique among the tests running as threads of one process.
#[derive(Debug)]
pub struct TempDir(PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> std::io::Result<Self> {
        let dir = std::env::temp_dir().join(format!(
            "railwear-{tag}-{}-{}",
            std::process::id(),
            uuid::Uuid::new_v4().simple()
        ));
        std::fs::create_dir_all(&dir)?;
        Ok(TempDir(dir))
    }

    pub fn path(&self) -> &Path {
        &self.0
    }

    /// URL of a SQLite database file `railwear.db` in this directory (created on first open).
    pub fn db_url(&self) -> String {
        format!("sqlite://{}?mode=rwc", self.0.join("railwear.db").display())
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
