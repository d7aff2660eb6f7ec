-- Fan-out (issue 6): a sweep creates child jobs (parent_id, child_index) and waits for them in
-- status 'waiting'; the parent keeps counts of how its children ended. job_attempts logs every
-- attempt (who claimed it, how it ended), written in the same transactions as the job row.

ALTER TABLE jobs DROP CONSTRAINT jobs_status_check;
ALTER TABLE jobs ADD CONSTRAINT jobs_status_check
    CHECK (status IN ('queued','running','waiting','succeeded','failed','cancelled'));

ALTER TABLE jobs
    ADD COLUMN parent_id          UUID REFERENCES jobs (id), -- child jobs: the job that fanned out
    ADD COLUMN child_index        BIGINT,                    -- child jobs: index among siblings
    ADD COLUMN children_total     BIGINT NOT NULL DEFAULT 0, -- parents: children created
    ADD COLUMN children_succeeded BIGINT NOT NULL DEFAULT 0,
    ADD COLUMN children_failed    BIGINT NOT NULL DEFAULT 0,
    ADD COLUMN children_cancelled BIGINT NOT NULL DEFAULT 0,
    ADD CONSTRAINT jobs_child_has_index CHECK ((parent_id IS NULL) = (child_index IS NULL));

-- One child per (parent, index): a fan-out cannot create a point twice.
CREATE UNIQUE INDEX jobs_children ON jobs (parent_id, child_index);

CREATE TABLE job_attempts (
    job_id      UUID   NOT NULL REFERENCES jobs (id),
    attempt     BIGINT NOT NULL,
    worker      TEXT   NOT NULL,
    started_ms  BIGINT NOT NULL,
    ended_ms    BIGINT,
    -- running | succeeded | failed | cancelled | fanned_out | lost (lease expired)
    outcome     TEXT   NOT NULL CHECK (outcome IN ('running','succeeded','failed','cancelled','fanned_out','lost')),
    PRIMARY KEY (job_id, attempt)
);
