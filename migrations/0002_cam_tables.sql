-- Cam tables (TwinCAT NC Camming): position tables and motion functions, by id (MC_CAM_ID,
-- 1..255) and unique name. A PUT bumps the version. Couplings are not stored: they end with
-- the process.
CREATE TABLE cam_tables (
    id            INTEGER PRIMARY KEY CHECK (id BETWEEN 1 AND 255),
    name          TEXT    NOT NULL UNIQUE,
    version       INTEGER NOT NULL,
    table_type    TEXT    NOT NULL,          -- equidistant, non_equidistant, motion_function
    periodic      INTEGER NOT NULL,          -- 0 or 1
    interpolation TEXT    NOT NULL,          -- linear, spline, sliding_spline
    row_count     INTEGER NOT NULL,
    rows          BLOB,                      -- position tables: [master, slave] pairs as little-endian f64
    points        TEXT,                      -- motion functions: the points as JSON
    created_at    TEXT    NOT NULL,
    updated_at    TEXT    NOT NULL
);
