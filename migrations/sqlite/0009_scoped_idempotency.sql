-- Idempotency keys are scoped to the submitter and the route (jobs::scoped_idempotency_key):
-- the same key from two tokens makes two resources. Keys stored before are scoped the same
-- way, so a retry of an earlier submission still finds its job. 0x1f separates the parts.

UPDATE jobs
SET idempotency_key = submitted_by || char(31)
    || CASE WHEN kind = 'diagnose' THEN 'diagnoses' ELSE 'jobs' END
    || char(31) || idempotency_key
WHERE idempotency_key IS NOT NULL;
