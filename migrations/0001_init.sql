-- motiond store: axis configurations, the persistent parameter overlay, the audit log.
CREATE TABLE axes (
    id          INTEGER PRIMARY KEY,
    name        TEXT    NOT NULL UNIQUE,
    config      TEXT    NOT NULL,          -- AxisConfigDto as canonical JSON
    created_at  TEXT    NOT NULL,
    updated_at  TEXT    NOT NULL
);

-- MC_WriteParameterPersistent: re-applied at every start, dropped when the axis is replaced.
CREATE TABLE persistent_parameters (
    axis_id     INTEGER NOT NULL REFERENCES axes(id) ON DELETE CASCADE,
    number      INTEGER NOT NULL,
    value       TEXT    NOT NULL,          -- JSON number or boolean
    updated_at  TEXT    NOT NULL,
    PRIMARY KEY (axis_id, number)
);

-- Every change and every motion command: when, from whom, what, and how it ended.
CREATE TABLE audit_log (
    id          INTEGER PRIMARY KEY AUTOINCREMENT,
    at          TEXT    NOT NULL,
    client_addr TEXT,
    client_id   TEXT,
    action      TEXT    NOT NULL,          -- e.g. axis.create, parameter.write, command
    target      TEXT,                      -- axis name, command id …
    command_id  INTEGER,
    detail      TEXT    NOT NULL,          -- JSON
    outcome     TEXT                       -- accepted, rejected:<code>, done, error:<code> …
);
CREATE INDEX audit_log_command ON audit_log(command_id);

CREATE TABLE meta (
    key   TEXT PRIMARY KEY,
    value TEXT NOT NULL
);
