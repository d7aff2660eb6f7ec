-- railwear schema (SQLite). Times are Unix milliseconds. JSON is stored as TEXT.

CREATE TABLE jobs (
    seq                 INTEGER PRIMARY KEY AUTOINCREMENT, -- submission order, list cursor
    id                  TEXT    NOT NULL UNIQUE,           -- UUID
    kind                TEXT    NOT NULL,
    status              TEXT    NOT NULL CHECK (status IN ('queued','running','succeeded','failed','cancelled')),
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
    track_samples       INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX jobs_by_status ON jobs (status, seq);
CREATE INDEX jobs_by_curve ON jobs (curve_key, status);

-- Contact tracks as deflate-compressed column blocks (store/tracks.rs).
CREATE TABLE job_track_blocks (
    job_id      TEXT    NOT NULL REFERENCES jobs (id),
    block       INTEGER NOT NULL,
    samples     INTEGER NOT NULL,
    t_start_s   REAL    NOT NULL,
    t_end_s     REAL    NOT NULL,
    data        BLOB    NOT NULL,
    PRIMARY KEY (job_id, block)
);

CREATE TABLE job_plots (
    job_id  TEXT NOT NULL REFERENCES jobs (id),
    name    TEXT NOT NULL,
    svg     TEXT NOT NULL,
    PRIMARY KEY (job_id, name)
);

CREATE TABLE rails (
    seq         INTEGER PRIMARY KEY AUTOINCREMENT,
    serial      TEXT    NOT NULL UNIQUE,
    created_ms  INTEGER NOT NULL
);

CREATE TABLE rail_measurements (
    seq           INTEGER PRIMARY KEY AUTOINCREMENT,
    id            TEXT    NOT NULL UNIQUE,
    serial        TEXT    NOT NULL REFERENCES rails (serial),
    dimensions_mm TEXT    NOT NULL,
    measured_by   TEXT    NOT NULL,
    measured_at   TEXT    NOT NULL,
    location      TEXT    NOT NULL,
    rattle_space  REAL    NOT NULL,
    recorded_by   TEXT    NOT NULL,
    recorded_ms   INTEGER NOT NULL
);
CREATE INDEX rail_measurements_by_serial ON rail_measurements (serial, seq);

-- Penalization curves from sweep jobs; the newest sweep for a key wins.
CREATE TABLE penalization_curves (
    curve_key   TEXT    PRIMARY KEY,
    job_id      TEXT    NOT NULL REFERENCES jobs (id),
    curve       TEXT    NOT NULL,
    created_ms  INTEGER NOT NULL
);

CREATE TABLE api_tokens (
    id            TEXT    PRIMARY KEY,
    name          TEXT    NOT NULL,
    role          TEXT    NOT NULL CHECK (role IN ('planner','engineer','admin')),
    token_sha256  TEXT    NOT NULL UNIQUE,
    created_ms    INTEGER NOT NULL,
    revoked_ms    INTEGER
);
