-- Coordinated-motion groups (TwinCAT TF5420 CM group): by id (1..16, the kernel's group slot
-- + 1) and unique name. `config` is the group's configuration as JSON (convention, additional
-- axes, dynamics, override ramp time, and its members as role and axis id). Runtime
-- membership changes (add-axis, remove-axis blocks) and the enable state are not stored:
-- after a start the group is disabled with its configured members.
CREATE TABLE axis_groups (
    id         INTEGER PRIMARY KEY CHECK (id BETWEEN 1 AND 16),
    name       TEXT    NOT NULL UNIQUE,
    config     TEXT    NOT NULL,
    created_at TEXT    NOT NULL,
    updated_at TEXT    NOT NULL
);
