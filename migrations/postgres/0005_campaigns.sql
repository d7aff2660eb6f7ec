-- Issue 14 item 5: test campaigns stored and served, uploaded by the new token role
-- `test_engineer` (see migrations/sqlite/0005_campaigns.sql for the design). The canonical
-- JSON is TEXT exactly as serde_json wrote it, so both engines serve identical documents.

CREATE TABLE campaigns (
    seq                   BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY, -- upload order, list cursor
    id                    UUID    NOT NULL UNIQUE,
    name                  TEXT    NOT NULL,
    created_by            TEXT    NOT NULL,
    created_ms            BIGINT  NOT NULL,
    content               TEXT    NOT NULL,
    content_sha256        TEXT    NOT NULL UNIQUE,
    content_bytes         BIGINT  NOT NULL,
    tests                 BIGINT  NOT NULL,
    specimens             BIGINT  NOT NULL,
    increments            BIGINT  NOT NULL,
    accelerometer_records BIGINT  NOT NULL
);

ALTER TABLE api_tokens DROP CONSTRAINT api_tokens_role_check;
ALTER TABLE api_tokens ADD CONSTRAINT api_tokens_role_check
    CHECK (role IN ('planner','engineer','test_engineer','admin'));
