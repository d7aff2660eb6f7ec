-- Issue 17: mid-run checkpoints. A worker stopping at SIGTERM asks its running simulation for
-- a checkpoint (the complete run state at an accepted step), stores it here while it still
-- holds the lease, and releases the job; the next attempt resumes from it to the result of an
-- uninterrupted run. One checkpoint per job (the latest); it is deleted when the job ends.

CREATE TABLE job_checkpoints (
    job_id       TEXT    PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
    attempt      INTEGER NOT NULL,  -- the attempt that stored it
    simulated_s  REAL    NOT NULL,  -- simulated time of the checkpoint, s
    end_s        REAL    NOT NULL,  -- end of the run it belongs to, s
    created_ms   INTEGER NOT NULL,
    data         BLOB    NOT NULL   -- models::checkpoint encoding (zlib of bincode)
);

-- A job that ends (succeeded, failed, cancelled) has no use for its checkpoint, whichever
-- path ended it (finish, cancel, lost leases beyond max_attempts, a failed parent).
CREATE TRIGGER job_checkpoints_end AFTER UPDATE OF status ON jobs
WHEN NEW.status IN ('succeeded', 'failed', 'cancelled')
BEGIN
    DELETE FROM job_checkpoints WHERE job_id = NEW.id;
END;

-- The simulated time of the checkpoint a released attempt stored.
ALTER TABLE job_attempts ADD COLUMN checkpoint_s REAL;
