-- Issue 17: a rail's report uses the measurement with the latest measured_at, not the last one
-- recorded. measured_ms is measured_at as Unix milliseconds (a date alone is midnight UTC),
-- written by the service at insert. Existing rows are back-filled from measured_at where it
-- reads as a timestamp, else from the time they were recorded (a row at a time, so one
-- unreadable value cannot stop the migration).
ALTER TABLE rail_measurements ADD COLUMN measured_ms BIGINT NOT NULL DEFAULT 0;
DO $$
DECLARE
    r RECORD;
BEGIN
    FOR r IN SELECT seq, measured_at, recorded_ms FROM rail_measurements LOOP
        BEGIN
            UPDATE rail_measurements
            SET measured_ms = (EXTRACT(EPOCH FROM (
                CASE WHEN length(r.measured_at) = 10 THEN r.measured_at || 'T00:00:00Z'
                     ELSE r.measured_at END)::timestamptz) * 1000)::BIGINT
            WHERE seq = r.seq;
        EXCEPTION WHEN others THEN
            UPDATE rail_measurements SET measured_ms = r.recorded_ms WHERE seq = r.seq;
        END;
    END LOOP;
END $$;
CREATE INDEX rail_measurements_by_measured ON rail_measurements (serial, measured_ms, seq);
