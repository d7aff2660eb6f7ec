-- A running simulation's growing records (track samples, response, finished parts' reports)
-- stored in chunks as the run goes (models::run's record chunks), so that the checkpoint a
-- worker stores at shutdown holds only the run's state and the records since the last chunk:
-- its size and write time stay bounded however long the run. A checkpoint names how many
-- chunks it follows and their chained SHA-256; resuming reads them back. Chunks are written by
-- the attempt holding the running lease (a later attempt rewrites a chunk of the same number
-- with the same bytes: chunk boundaries follow sample counts); deleted when the job ends.

CREATE TABLE job_record_chunks (
    job_id   TEXT    NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
    seq      INTEGER NOT NULL,  -- position in the run's chunks, from 0
    attempt  INTEGER NOT NULL,  -- the attempt that wrote it
    data     BLOB    NOT NULL,  -- zlib of bincode (models::run::records)
    PRIMARY KEY (job_id, seq)
);

CREATE TRIGGER job_record_chunks_end AFTER UPDATE OF status ON jobs
WHEN NEW.status IN ('succeeded', 'failed', 'cancelled')
BEGIN
    DELETE FROM job_record_chunks WHERE job_id = NEW.id;
END;
