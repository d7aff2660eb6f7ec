-- Issue 17: clean shutdown and dead-worker leases.
--
-- A claim records where its worker runs: host name, process id and the process instance (a
-- random id per process start). At start-up a worker process releases at once the running
-- jobs of processes of its own host that no longer exist (their attempt is logged `lost`),
-- instead of leaving them for the lease to expire.
--
-- An attempt a worker gives back on SIGTERM (the job goes back to the queue at once, to be
-- resumed by the next worker) is logged `released`. SQLite cannot alter a CHECK constraint,
-- so job_attempts is rebuilt (nothing references it).

ALTER TABLE jobs ADD COLUMN lease_host TEXT;
ALTER TABLE jobs ADD COLUMN lease_pid INTEGER;
ALTER TABLE jobs ADD COLUMN lease_instance TEXT;
CREATE INDEX jobs_running_host ON jobs (lease_host, status);

CREATE TABLE job_attempts_new (
    job_id      TEXT    NOT NULL REFERENCES jobs (id),
    attempt     INTEGER NOT NULL,
    worker      TEXT    NOT NULL,
    started_ms  INTEGER NOT NULL,
    ended_ms    INTEGER,
    -- running | succeeded | failed | cancelled | fanned_out | lost (lease expired or its
    -- process found dead) | released (given back at shutdown)
    outcome     TEXT    NOT NULL CHECK (outcome IN ('running','succeeded','failed','cancelled','fanned_out','lost','released')),
    PRIMARY KEY (job_id, attempt)
);
INSERT INTO job_attempts_new (job_id, attempt, worker, started_ms, ended_ms, outcome)
SELECT job_id, attempt, worker, started_ms, ended_ms, outcome FROM job_attempts;
DROP TABLE job_attempts;
ALTER TABLE job_attempts_new RENAME TO job_attempts;
