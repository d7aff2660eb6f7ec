-- A running simulation's records stored in chunks as the run goes, so that a checkpoint stays
-- small (see migrations/sqlite/0010_job_record_chunks.sql). Deleted when the job ends.

CREATE TABLE job_record_chunks (
    job_id   UUID   NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
    seq      BIGINT NOT NULL,
    attempt  BIGINT NOT NULL,
    data     BYTEA  NOT NULL,
    PRIMARY KEY (job_id, seq)
);

CREATE FUNCTION job_record_chunks_end() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    DELETE FROM job_record_chunks WHERE job_id = NEW.id;
    RETURN NULL;
END
$$;

CREATE TRIGGER job_record_chunks_end AFTER UPDATE OF status ON jobs
    FOR EACH ROW WHEN (NEW.status IN ('succeeded', 'failed', 'cancelled'))
    EXECUTE FUNCTION job_record_chunks_end();
