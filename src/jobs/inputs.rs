//! What a job reads from the store when it runs instead of carrying it in its params: a
//! diagnosis names its campaign by id and pins the content by its SHA-256 (a campaign is up to
//! 32 MiB; copying it into every job's params would store it again per job).
//!
//! Runners run on tokio's blocking threads; the store is async, so a read here blocks the
//! calling thread on the runtime the worker runs in.

use crate::field_error::FieldError;
use crate::models::outcome::RunError;
use crate::store::Store;
use sha2::{Digest, Sha256};
use std::sync::{Arc, OnceLock};
use uuid::Uuid;

/// The store a runner's jobs read their inputs from. Empty until [`StoredInputs::bind`]
/// (`Jobs::new` binds the queue's store); a job that needs it then fails, saying so.
#[derive(Default)]
pub struct StoredInputs {
    store: OnceLock<Arc<dyn Store>>,
}

impl std::fmt::Debug for StoredInputs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StoredInputs")
            .field("bound", &self.store.get().is_some())
            .finish()
    }
}

impl StoredInputs {
    /// Read inputs from `store` from now on (the first binding stays).
    pub fn bind(&self, store: Arc<dyn Store>) {
        let _ = self.store.set(store);
    }

    /// The canonical JSON of campaign `id`, checked against `sha256` (lower-case hex). Errors
    /// name `campaign_id` (gone, or no store) or `campaign_sha256` (other content). Must be
    /// called on a thread that may block (not inside an async task) of a tokio runtime.
    pub fn campaign(&self, id: Uuid, sha256: &str) -> Result<String, RunError> {
        let store = self.store.get().ok_or_else(|| {
            FieldError::new(
                "campaign_id",
                "cannot be read: this runner has no store (diagnoses run in the service's \
                 workers)",
            )
        })?;
        let runtime = tokio::runtime::Handle::try_current().map_err(|_| {
            FieldError::new(
                "campaign_id",
                "cannot be read: no async runtime to read the store with",
            )
        })?;
        let record = runtime
            .block_on(store.get_campaign(id))
            .map_err(|e| FieldError::new("campaign_id", format!("could not be read: {e}")))?
            .ok_or_else(|| {
                FieldError::new(
                    "campaign_id",
                    format!(
                        "names campaign {id}, which is no longer stored: upload it again and \
                         start a new diagnosis"
                    ),
                )
            })?;
        let found = super::hex(&Sha256::digest(record.content.as_bytes()));
        if found != sha256 {
            return Err(FieldError::new(
                "campaign_sha256",
                format!(
                    "is {sha256}, but campaign {id} as stored has SHA-256 {found}: its content \
                     is not the content this diagnosis was submitted for"
                ),
            )
            .into());
        }
        Ok(record.content)
    }
}
