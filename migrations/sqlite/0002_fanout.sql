-- Fan-out (issue 6): a sweep creates child jobs (parent_id, child_index) and waits for them in
-- status 'waiting'; the parent keeps counts of how its children ended. job_attempts logs every
-- attempt (who claimed it, how it ended), written in the same transactions as the job row.
--
-- SQLite cannot alter a CHECK constraint, so `jobs` is rebuilt: copied aside, dropped,
-- re-created with the new columns and the wider status check, copied back. Foreign keys of
-- job_track_blocks, job_plots and penalization_curves name `jobs`, so they point at the new
-- table; deferring them to commit lets the rows be absent between the drop and the copy back.

PRAGMA defer_foreign_keys = ON;

CREATE TABLE jobs_copy AS SELECT * FROM jobs;
DROP TABLE jobs;

CREATE TABLE jobs (
    seq                 INTEGER PRIMARY KEY AUTOINCREMENT, -- submission order, list cursor
    id                  TEXT    NOT NULL UNIQUE,           -- UUID
    kind                TEXT    NOT NULL,
    status              TEXT    NOT NULL CHECK (status IN ('queued','running','waiting','succeeded','failed','cancelled')),
    params              TEXT    NOT NULL,                  -- exactly as submitted
    seed                INTEGER NOT NULL,                  -- u64 stored as its i64 bit pattern
    code_version        TEXT    NOT NULL,
    submitted_by        TEXT    NOT NULL,
    idempotency_key     TEXT    UNIQUE,
    request_sha256      TEXT,
    curve_key           TEXT,                              -- sweeps: profile/environment/law
    attempt             INTEGER NOT NULL DEFAULT 0,        -- fencing token
    lease_owner         TEXT,
    lease_expires_ms    INTEGER,
    cancel_requested    INTEGER NOT NULL DEFAULT 0,
    created_ms          INTEGER NOT NULL,
    started_ms          INTEGER,                           -- first attempt
    attempt_started_ms  INTEGER,                           -- current attempt (ETA)
    finished_ms         INTEGER,
    progress_simulated_s REAL,
    progress_end_s      REAL,
    progress_fraction   REAL,
    progress_eta_s      REAL,
    result              TEXT,
    error               TEXT,
    track_samples       INTEGER NOT NULL DEFAULT 0,
    parent_id           TEXT REFERENCES jobs (id),          -- child jobs: the job that fanned out
    child_index         INTEGER,                            -- child jobs: index among siblings
    children_total      INTEGER NOT NULL DEFAULT 0,         -- parents: children created
    children_succeeded  INTEGER NOT NULL DEFAULT 0,
    children_failed     INTEGER NOT NULL DEFAULT 0,
    children_cancelled  INTEGER NOT NULL DEFAULT 0,
    CHECK ((parent_id IS NULL) = (child_index IS NULL))
);

INSERT INTO jobs (seq, id, kind, status, params, seed, code_version, submitted_by,
    idempotency_key, request_sha256, curve_key, attempt, lease_owner, lease_expires_ms,
    cancel_requested, created_ms, started_ms, attempt_started_ms, finished_ms,
    progress_simulated_s, progress_end_s, progress_fraction, progress_eta_s, result, error,
    track_samples)
SELECT seq, id, kind, status, params, seed, code_version, submitted_by,
    idempotency_key, request_sha256, curve_key, attempt, lease_owner, lease_expires_ms,
    cancel_requested, created_ms, started_ms, attempt_started_ms, finished_ms,
    progress_simulated_s, progress_end_s, progress_fraction, progress_eta_s, result, error,
    track_samples
FROM jobs_copy ORDER BY seq;
DROP TABLE jobs_copy;

CREATE INDEX jobs_by_status ON jobs (status, seq);
CREATE INDEX jobs_by_curve ON jobs (curve_key, status);
-- One child per (parent, index): a fan-out cannot create a point twice.
CREATE UNIQUE INDEX jobs_children ON jobs (parent_id, child_index);

CREATE TABLE job_attempts (
    job_id      TEXT    NOT NULL REFERENCES jobs (id),
    attempt     INTEGER NOT NULL,
    worker      TEXT    NOT NULL,
    started_ms  INTEGER NOT NULL,
    ended_ms    INTEGER,
    -- running | succeeded | failed | cancelled | fanned_out | lost (lease expired)
    outcome     TEXT    NOT NULL CHECK (outcome IN ('running','succeeded','failed','cancelled','fanned_out','lost')),
    PRIMARY KEY (job_id, attempt)
);
