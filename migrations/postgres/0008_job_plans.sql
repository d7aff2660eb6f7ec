-- Issue 30: a job's typed plan (see migrations/sqlite/0008_job_plans.sql). NULL for kinds
-- without one and for jobs queued before plans were stored.

ALTER TABLE jobs ADD COLUMN plan TEXT;
