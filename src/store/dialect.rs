//! What differs between the two engines, as data the shared code ([`super::portable`],
//! [`super::bookkeeping`]) reads: how a writing transaction begins and what it locks, and the
//! few statements the dialects spell differently. Everything else is one statement text for
//! both (`$N` placeholders, which sqlx's SQLite driver accepts too).
//!
//! The statements here differ because PostgreSQL must know the type of a parameter that is
//! only compared with NULL (`$1::BIGINT IS NULL`), which SQLite cannot spell (no `::`), and
//! because the engines sort text differently (PostgreSQL's `COLLATE "C"` is SQLite's default
//! byte order).

/// One engine's dialect; implemented by `sqlx::Sqlite` (`sqlite.rs`) and `sqlx::Postgres`
/// (`postgres.rs`).
pub(crate) trait Dialect: sqlx::Database {
    /// How a transaction that writes begins (`None`: the engine's plain `BEGIN`). SQLite's
    /// `BEGIN IMMEDIATE` takes the write lock up front, so two writers queue instead of
    /// deadlocking on a lock upgrade, and the counts a transaction reads are final.
    const BEGIN_WRITE: Option<&'static str>;
    /// Appended to the select of a row the transaction then writes (PostgreSQL's row lock).
    const FOR_UPDATE: &'static str;
    /// Lock the parent of child job `$1`, first in every transaction that writes a child and
    /// its parent (PostgreSQL: serializes the parent's counting and fixes the lock order, so
    /// concurrent finishes, cancels and re-queues cannot deadlock). `None`: one writer.
    const LOCK_PARENT: Option<&'static str>;
    /// Serialize the publishes of curve key `$1` (the comparison and the switch are one step).
    const LOCK_CURVE_KEY: Option<&'static str>;

    /// After `SELECT <job columns> FROM jobs`: `$1` status, `$2` parent, `$3` top level only,
    /// `$4` after seq, `$5` limit (each page's cursor and limit are its last two parameters).
    const JOBS_PAGE: &'static str;
    /// Renew lease `$1` id, `$2` attempt, until `$3 + $4`; progress `$5`..`$8` (kept when
    /// NULL); returns `cancel_requested`.
    const HEARTBEAT: &'static str;
    /// Rails with their measurement counts: `$1` after seq, `$2` limit.
    const RAILS_PAGE: &'static str;
    /// Measurements of serial `$1`: `$2` after seq, `$3` limit.
    const MEASUREMENTS_PAGE: &'static str;
    /// After the curve select: `$1` key, `$2` after id, `$3` limit.
    const CURVES_PAGE: &'static str;
    /// After `SELECT <campaign summary> FROM campaigns`: `$1` after seq, `$2` limit.
    const CAMPAIGNS_PAGE: &'static str;
    /// A job's plot names in byte order: `$1` job.
    const PLOT_NAMES: &'static str;
    /// All tokens by creation time, then id text in byte order.
    const TOKENS: &'static str;
}
