-- Issue 14 item 5: test campaigns stored and served (POST/GET /v1/campaigns), uploaded by the
-- new token role `test_engineer`.
--
-- A campaign is kept as its canonical JSON (gap::campaign::Campaign serialized by serde_json,
-- samples inline), exactly the text GET /v1/campaigns/{id} answers with, with the SHA-256 of
-- that text (the same content is stored once: a repeated upload returns the stored record) and
-- the counts a list shows without reading the content.

CREATE TABLE campaigns (
    seq                   INTEGER PRIMARY KEY AUTOINCREMENT, -- upload order, list cursor
    id                    TEXT    NOT NULL UNIQUE,           -- UUID
    name                  TEXT    NOT NULL,                  -- the campaign's `name`
    created_by            TEXT    NOT NULL,                  -- token name of the uploader
    created_ms            INTEGER NOT NULL,
    content               TEXT    NOT NULL,                  -- canonical JSON
    content_sha256        TEXT    NOT NULL UNIQUE,           -- of `content`, lower-case hex
    content_bytes         INTEGER NOT NULL,
    tests                 INTEGER NOT NULL,
    specimens             INTEGER NOT NULL,
    increments            INTEGER NOT NULL,
    accelerometer_records INTEGER NOT NULL
);

-- The token role check gains `test_engineer`. SQLite cannot alter a CHECK constraint, so the
-- table is rebuilt (nothing references it).
CREATE TABLE api_tokens_new (
    id            TEXT    PRIMARY KEY,
    name          TEXT    NOT NULL,
    role          TEXT    NOT NULL CHECK (role IN ('planner','engineer','test_engineer','admin')),
    token_sha256  TEXT    NOT NULL UNIQUE,
    created_ms    INTEGER NOT NULL,
    revoked_ms    INTEGER
);
INSERT INTO api_tokens_new (id, name, role, token_sha256, created_ms, revoked_ms)
SELECT id, name, role, token_sha256, created_ms, revoked_ms FROM api_tokens;
DROP TABLE api_tokens;
ALTER TABLE api_tokens_new RENAME TO api_tokens;
