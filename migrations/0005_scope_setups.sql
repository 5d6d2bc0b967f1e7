-- Saved scope setups (the UI issue): what to record and how to show it, by name, so that an
-- engineer finds the tuning setup of yesterday on another PC.
CREATE TABLE scope_setups (
    name       TEXT PRIMARY KEY,
    body       TEXT NOT NULL,
    updated_at TEXT NOT NULL
);
