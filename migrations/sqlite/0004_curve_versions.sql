-- Issue 17: penalization curves are versioned records with provenance. A sweep stores a new
-- version (curve_versions); reports use the version an engineer published (published_curves,
-- one per key). Fidelity columns (points, duration per point, seeds) let a publish compare a
-- version with the published one.
--
-- Curves stored before this migration (penalization_curves, one per key, the newest sweep)
-- become version 1 of their key, published (reports keep answering as before), with the
-- sweep job's params and seed as provenance, one seed per point and the duration per point
-- unknown (NULL: it was not recorded).

CREATE TABLE curve_versions (
    id                   INTEGER PRIMARY KEY AUTOINCREMENT,
    curve_key            TEXT    NOT NULL,
    version              INTEGER NOT NULL,
    job_id               TEXT    NOT NULL REFERENCES jobs (id),
    curve                TEXT    NOT NULL,           -- analysis::penalization::PenalizationCurve
    provenance           TEXT    NOT NULL,           -- JSON object
    points               INTEGER NOT NULL,
    duration_per_point_s REAL,                       -- NULL: not recorded (migrated)
    seeds                INTEGER NOT NULL,
    created_by           TEXT    NOT NULL,           -- token name of the sweep's submitter
    code_version         TEXT    NOT NULL,
    created_ms           INTEGER NOT NULL,
    UNIQUE (curve_key, version)
);
CREATE INDEX curve_versions_by_key ON curve_versions (curve_key, id);

CREATE TABLE published_curves (
    curve_key     TEXT    PRIMARY KEY,
    curve_id      INTEGER NOT NULL REFERENCES curve_versions (id),
    published_by  TEXT    NOT NULL,
    published_ms  INTEGER NOT NULL
);

INSERT INTO curve_versions (curve_key, version, job_id, curve, provenance, points,
    duration_per_point_s, seeds, created_by, code_version, created_ms)
SELECT c.curve_key, 1, c.job_id, c.curve,
    json_object(
        'migrated', 'stored before curve versions (issue 17); duration per point not recorded',
        'params', CASE WHEN json_valid(j.params) THEN json(j.params) ELSE j.params END,
        'seeds', json_array(j.seed)),
    CASE WHEN json_valid(c.curve) THEN COALESCE(json_array_length(c.curve, '$.points'), 0) ELSE 0 END,
    NULL, 1, j.submitted_by, j.code_version, c.created_ms
FROM penalization_curves c JOIN jobs j ON j.id = c.job_id
ORDER BY c.created_ms, c.curve_key;

INSERT INTO published_curves (curve_key, curve_id, published_by, published_ms)
SELECT curve_key, id, 'migration', created_ms FROM curve_versions;

DROP TABLE penalization_curves;
