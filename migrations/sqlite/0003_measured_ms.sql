-- Issue 17: a rail's report uses the measurement with the latest measured_at, not the last one
-- recorded. measured_ms is measured_at as Unix milliseconds (a date alone is midnight UTC),
-- written by the service at insert. Existing rows are back-filled from measured_at where
-- SQLite's date functions read it, else from the time they were recorded.
ALTER TABLE rail_measurements ADD COLUMN measured_ms INTEGER NOT NULL DEFAULT 0;
UPDATE rail_measurements
SET measured_ms = COALESCE(
    CAST(ROUND((julianday(measured_at) - 2440587.5) * 86400000.0) AS INTEGER),
    recorded_ms);
CREATE INDEX rail_measurements_by_measured ON rail_measurements (serial, measured_ms, seq);
