-- railwear schema (PostgreSQL), the same tables as migrations/sqlite with native types.
-- Times are Unix milliseconds (BIGINT). JSON is stored as TEXT exactly as serde_json wrote it,
-- so floats round-trip bit for bit and both engines return identical documents.

CREATE TABLE jobs (
    seq                  BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY, -- submission order, list cursor
    id                   UUID    NOT NULL UNIQUE,
    kind                 TEXT    NOT NULL,
    status               TEXT    NOT NULL CHECK (status IN ('queued','running','succeeded','failed','cancelled')),
    params               TEXT    NOT NULL,                  -- exactly as submitted
    seed                 BIGINT  NOT NULL,                  -- u64 stored as its i64 bit pattern
    code_version         TEXT    NOT NULL,
    submitted_by         TEXT    NOT NULL,
    idempotency_key      TEXT    UNIQUE,
    request_sha256       TEXT,
    curve_key            TEXT,                              -- sweeps: profile/environment/law
    attempt              BIGINT  NOT NULL DEFAULT 0,        -- fencing token
    lease_owner          TEXT,
    lease_expires_ms     BIGINT,
    cancel_requested     BOOLEAN NOT NULL DEFAULT FALSE,
    created_ms           BIGINT  NOT NULL,
    started_ms           BIGINT,                            -- first attempt
    attempt_started_ms   BIGINT,                            -- current attempt (ETA)
    finished_ms          BIGINT,
    progress_simulated_s DOUBLE PRECISION,
    progress_end_s       DOUBLE PRECISION,
    progress_fraction    DOUBLE PRECISION,
    progress_eta_s       DOUBLE PRECISION,
    result               TEXT,
    error                TEXT,
    track_samples        BIGINT  NOT NULL DEFAULT 0
);
CREATE INDEX jobs_by_status ON jobs (status, seq);
CREATE INDEX jobs_by_curve ON jobs (curve_key, status);
-- Claims scan only the queued jobs in submission order.
CREATE INDEX jobs_queued ON jobs (seq) WHERE status = 'queued';
-- The re-queue sweep looks only at running jobs.
CREATE INDEX jobs_running_lease ON jobs (lease_expires_ms) WHERE status = 'running';

-- Contact tracks as deflate-compressed column blocks (store/tracks.rs).
CREATE TABLE job_track_blocks (
    job_id      UUID             NOT NULL REFERENCES jobs (id),
    block       BIGINT           NOT NULL,
    samples     BIGINT           NOT NULL,
    t_start_s   DOUBLE PRECISION NOT NULL,
    t_end_s     DOUBLE PRECISION NOT NULL,
    data        BYTEA            NOT NULL,
    PRIMARY KEY (job_id, block)
);

CREATE TABLE job_plots (
    job_id  UUID NOT NULL REFERENCES jobs (id),
    name    TEXT NOT NULL,
    svg     TEXT NOT NULL,
    PRIMARY KEY (job_id, name)
);

CREATE TABLE rails (
    seq         BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    serial      TEXT   NOT NULL UNIQUE,
    created_ms  BIGINT NOT NULL
);

CREATE TABLE rail_measurements (
    seq           BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    id            UUID             NOT NULL UNIQUE,
    serial        TEXT             NOT NULL REFERENCES rails (serial),
    dimensions_mm TEXT             NOT NULL,
    measured_by   TEXT             NOT NULL,
    measured_at   TEXT             NOT NULL,
    location      TEXT             NOT NULL,
    rattle_space  DOUBLE PRECISION NOT NULL,
    recorded_by   TEXT             NOT NULL,
    recorded_ms   BIGINT           NOT NULL
);
CREATE INDEX rail_measurements_by_serial ON rail_measurements (serial, seq);

-- Penalization curves from sweep jobs; the newest sweep for a key wins.
CREATE TABLE penalization_curves (
    curve_key   TEXT   PRIMARY KEY,
    job_id      UUID   NOT NULL REFERENCES jobs (id),
    curve       TEXT   NOT NULL,
    created_ms  BIGINT NOT NULL
);

CREATE TABLE api_tokens (
    id            UUID   PRIMARY KEY,
    name          TEXT   NOT NULL,
    role          TEXT   NOT NULL CHECK (role IN ('planner','engineer','admin')),
    token_sha256  TEXT   NOT NULL UNIQUE,
    created_ms    BIGINT NOT NULL,
    revoked_ms    BIGINT
);
