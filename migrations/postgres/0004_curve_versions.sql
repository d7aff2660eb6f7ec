-- Issue 17: penalization curves are versioned records with provenance (see
-- migrations/sqlite/0004_curve_versions.sql for the design). Curves stored before become
-- version 1 of their key, published, with the sweep job's params and seed as provenance, one
-- seed per point and the duration per point unknown (NULL).

CREATE TABLE curve_versions (
    id                   BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    curve_key            TEXT    NOT NULL,
    version              BIGINT  NOT NULL,
    job_id               UUID    NOT NULL REFERENCES jobs (id),
    curve                TEXT    NOT NULL,
    provenance           TEXT    NOT NULL,
    points               BIGINT  NOT NULL,
    duration_per_point_s DOUBLE PRECISION,
    seeds                BIGINT  NOT NULL,
    created_by           TEXT    NOT NULL,
    code_version         TEXT    NOT NULL,
    created_ms           BIGINT  NOT NULL,
    UNIQUE (curve_key, version)
);
CREATE INDEX curve_versions_by_key ON curve_versions (curve_key, id);

CREATE TABLE published_curves (
    curve_key     TEXT    PRIMARY KEY,
    curve_id      BIGINT  NOT NULL REFERENCES curve_versions (id),
    published_by  TEXT    NOT NULL,
    published_ms  BIGINT  NOT NULL
);

INSERT INTO curve_versions (curve_key, version, job_id, curve, provenance, points,
    duration_per_point_s, seeds, created_by, code_version, created_ms)
SELECT c.curve_key, 1, c.job_id, c.curve,
    json_build_object(
        'migrated', 'stored before curve versions (issue 17); duration per point not recorded',
        'params', j.params::json,
        'seeds', json_build_array(j.seed))::text,
    COALESCE(json_array_length(c.curve::json -> 'points'), 0),
    NULL, 1, j.submitted_by, j.code_version, c.created_ms
FROM penalization_curves c JOIN jobs j ON j.id = c.job_id
ORDER BY c.created_ms, c.curve_key;

INSERT INTO published_curves (curve_key, curve_id, published_by, published_ms)
SELECT curve_key, id, 'migration', created_ms FROM curve_versions;

DROP TABLE penalization_curves;
