-- Issue 30: a job's typed plan, parsed and checked once at submission, stored as its canonical
-- JSON (a simulate job's complete case, seed included) and run by the worker as it is. NULL
-- for kinds without one and for jobs queued before plans were stored (planned from params).

ALTER TABLE jobs ADD COLUMN plan TEXT;
