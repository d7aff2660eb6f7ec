-- Issue 17: mid-run checkpoints (see migrations/sqlite/0007_job_checkpoints.sql). One
-- checkpoint per job, stored by a worker at shutdown while it holds the lease; deleted when
-- the job ends.

CREATE TABLE job_checkpoints (
    job_id       UUID             PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
    attempt      BIGINT           NOT NULL,
    simulated_s  DOUBLE PRECISION NOT NULL,
    end_s        DOUBLE PRECISION NOT NULL,
    created_ms   BIGINT           NOT NULL,
    data         BYTEA            NOT NULL
);

CREATE FUNCTION job_checkpoints_end() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    DELETE FROM job_checkpoints WHERE job_id = NEW.id;
    RETURN NULL;
END
$$;

CREATE TRIGGER job_checkpoints_end AFTER UPDATE OF status ON jobs
    FOR EACH ROW WHEN (NEW.status IN ('succeeded', 'failed', 'cancelled'))
    EXECUTE FUNCTION job_checkpoints_end();

ALTER TABLE job_attempts ADD COLUMN checkpoint_s DOUBLE PRECISION;
