-- Issue 17: clean shutdown and dead-worker leases (see migrations/sqlite/0006_worker_leases.sql).
-- A claim records host name, process id and process instance of its worker; an attempt given
-- back at shutdown is logged `released`.

ALTER TABLE jobs
    ADD COLUMN lease_host     TEXT,
    ADD COLUMN lease_pid      BIGINT,
    ADD COLUMN lease_instance TEXT;
CREATE INDEX jobs_running_host ON jobs (lease_host) WHERE status = 'running';

ALTER TABLE job_attempts DROP CONSTRAINT job_attempts_outcome_check;
ALTER TABLE job_attempts ADD CONSTRAINT job_attempts_outcome_check
    CHECK (outcome IN ('running','succeeded','failed','cancelled','fanned_out','lost','released'));
