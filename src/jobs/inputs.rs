//! What a job reads from the store when it runs instead of carrying it in its params: a
//! diagnosis names its campaign by id and pins the content by its SHA-256 (a campaign is up to
//! 32 MiB; copying it into every job's params would store it again per job).
//!
//! The runner says what a job reads ([`super::CaseRunner::stored_inputs`]); the worker reads
//! it once per attempt, asynchronously, before the computation starts on its blocking thread,
//! and hands it over as [`JobInputs`].

use crate::field_error::FieldError;
use crate::pipeline::RunError;
use crate::store::Store;
use sha2::{Digest, Sha256};
use uuid::Uuid;

/// A stored input a job reads when it runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StoredInput {
    /// Campaign `id`, whose stored canonical JSON must have SHA-256 `sha256` (lower-case hex).
    Campaign { id: Uuid, sha256: String },
}

/// The stored inputs read for one attempt.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct JobInputs {
    /// The canonical JSON of the job's campaign, checked against its SHA-256.
    pub campaign: Option<String>,
}

impl JobInputs {
    /// Reads `wanted` from `store`. Errors name `campaign_id` (gone, or unreadable) or
    /// `campaign_sha256` (other content).
    pub async fn read(store: &dyn Store, wanted: &[StoredInput]) -> Result<Self, RunError> {
        let mut inputs = Self::default();
        for input in wanted {
            match input {
                StoredInput::Campaign { id, sha256 } => {
                    inputs.campaign = Some(read_campaign(store, *id, sha256).await?);
                }
            }
        }
        Ok(inputs)
    }
}

/// The canonical JSON of campaign `id`, checked against `sha256`.
async fn read_campaign(store: &dyn Store, id: Uuid, sha256: &str) -> Result<String, RunError> {
    let record = store
        .get_campaign(id)
        .await
        .map_err(|e| FieldError::new("campaign_id", format!("could not be read: {e}")))?
        .ok_or_else(|| {
            FieldError::new(
                "campaign_id",
                format!(
                    "names campaign {id}, which is no longer stored: upload it again and start \
                     a new diagnosis"
                ),
            )
        })?;
    let found = super::hex(&Sha256::digest(record.content.as_bytes()));
    if found != sha256 {
        return Err(FieldError::new(
            "campaign_sha256",
            format!(
                "is {sha256}, but campaign {id} as stored has SHA-256 {found}: its content is \
                 not the content this diagnosis was submitted for"
            ),
        )
        .into());
    }
    Ok(record.content)
}
