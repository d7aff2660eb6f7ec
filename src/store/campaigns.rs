//! Stored test campaigns (issue 14 item 5): what [`super::Store::insert_campaign`] takes and the
//! records the campaign methods return.

use uuid::Uuid;

/// How much a campaign holds (what a list shows without reading the content).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, sqlx::FromRow)]
pub struct CampaignCounts {
    pub tests: i64,
    /// Specimens (repeats) over all tests.
    pub specimens: i64,
    /// Increments over all specimens.
    pub increments: i64,
    /// Accelerometer records over all specimens.
    pub accelerometer_records: i64,
}

/// A validated test campaign to store (issue 14): its canonical JSON text (samples inline),
/// what `GET /v1/campaigns/{id}` answers with.
#[derive(Debug, Clone, PartialEq)]
pub struct NewCampaign {
    pub id: Uuid,
    /// The campaign's `name`.
    pub name: String,
    /// Token name of the uploader.
    pub created_by: String,
    pub created_ms: i64,
    /// Canonical JSON (`gap::Campaign` as serde_json writes it).
    pub content: String,
    /// SHA-256 of `content`, lower-case hex. The same content is stored once.
    pub content_sha256: String,
    pub counts: CampaignCounts,
}

/// A stored campaign without its content.
#[derive(Debug, Clone, PartialEq)]
pub struct CampaignSummary {
    pub id: Uuid,
    /// Upload order (list cursor).
    pub seq: i64,
    pub name: String,
    pub created_by: String,
    pub created_ms: i64,
    pub content_sha256: String,
    /// Length of the canonical JSON, bytes.
    pub content_bytes: i64,
    pub counts: CampaignCounts,
}

/// A stored campaign with its canonical JSON text.
#[derive(Debug, Clone, PartialEq)]
pub struct CampaignRecord {
    pub summary: CampaignSummary,
    pub content: String,
}

/// What [`Store::insert_campaign`](super::Store::insert_campaign) did.
#[derive(Debug, Clone, PartialEq)]
pub enum CampaignInsert {
    /// A new record.
    Created(CampaignSummary),
    /// A campaign with the same content (SHA-256) was already stored: that one, unchanged.
    Existing(CampaignSummary),
}
