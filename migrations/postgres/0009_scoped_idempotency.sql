-- Idempotency keys are scoped to the submitter and the route (see
-- migrations/sqlite/0009_scoped_idempotency.sql).

UPDATE jobs
SET idempotency_key = submitted_by || chr(31)
    || CASE WHEN kind = 'diagnose' THEN 'diagnoses' ELSE 'jobs' END
    || chr(31) || idempotency_key
WHERE idempotency_key IS NOT NULL;
