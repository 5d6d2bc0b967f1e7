//! The function blocks an axis takes as commands, by family: each family's module holds its
//! bodies (the REST body, the websocket params), their checks, their conversion to the kernel's
//! `CommandKind` and its catalogue entries (`entries!`, from which `crate::api::blocks` makes
//! the endpoints). Adding a block is its entry, its body and its conversion in its family's
//! file — and its behaviour in the kernel.
//!
//! An entry (`entries!`, handed to `crate::api::blocks`, which makes each one's REST handler,
//! route, OpenAPI operation and websocket method): `fn: "name" at prefix, Body, conversion,
//! Role, Milestone, [flags], "summary";` — `at axes`: the route prefix `/api/v1/axes/{axis}/`,
//! the body converted with the axis (`fn(&Body, &Registry, &AxisEntry) -> CommandKind`);
//! `at groups`: `/api/v1/groups/{group}/`, converted with the group (`… &GroupEntry) ->
//! GroupOrder`, a command or a path table);
//! the flags are `model::Block`'s (`has_result`, `keepalive`, `lease_free`).
//!
//! Bodies: fields follow the FB inputs; 0 dynamics = axis default. Bodies whose every field may
//! be left out name their defaults field by field (not with a container `#[serde(default)]`):
//! utoipa would write a nested struct's default as an object `default` beside a one-element
//! `oneOf`, which client generators refuse. Scalars keep a documented `default`; enums and
//! objects say theirs in the description.

pub mod admin;
pub mod cams;
pub mod corrections;
pub mod coupling;
pub mod groups;
pub mod homing;
pub mod jog;
pub mod moves;
pub mod probe;
pub mod superposition;
pub mod torque;

use ::motion::AxisSlot;

use crate::app::{AxisEntry, Registry};
use crate::error::{AppError, AppResult, FieldError};

/// Collects invalid fields of a command body.
#[derive(Default)]
pub struct Check(Vec<FieldError>);

impl Check {
    fn fail(&mut self, field: &str, message: &str) {
        self.0.push(FieldError {
            field: field.into(),
            message: message.into(),
        });
    }
    /// A position, distance, offset or end velocity: within ±1e12 (beyond it an f64 position
    /// has no useful resolution, and sums of such inputs could overflow to infinity).
    fn finite(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v.abs() <= crate::model::MAX_MAGNITUDE) {
            self.fail(field, "must be a number from -1e12 to 1e12");
        }
    }
    fn scaling(&mut self, field: &str, v: f64) {
        if !crate::model::valid_scaling(v) {
            self.fail(
                field,
                "must be a number other than 0, from 1e-9 to 1e12 in magnitude",
            );
        }
    }
    fn positive(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(field, "must be > 0");
        }
    }
    fn non_negative(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v >= 0.0) {
            self.fail(field, "must be ≥ 0 (0 = axis default)");
        }
    }
    /// A cam block's offsets and activation position (finite) and scalings (finite, not 0).
    /// A coupling's own interpolation of a position table (4POINT is no longer supported).
    fn interpolation(&mut self, i: Option<motion::cam::InterpolationType>) {
        if i == Some(motion::cam::InterpolationType::FourPoint) {
            self.fail(
                "interpolation",
                "4-point interpolation is no longer supported (as in TwinCAT); use linear, spline or sliding_spline",
            );
        }
    }
    fn cam_coupling(&mut self, [mo, so, position]: [f64; 3], [ms, ss]: [f64; 2]) {
        self.finite("master_offset", mo);
        self.finite("slave_offset", so);
        self.finite("activation_position", position);
        self.scaling("master_scaling", ms);
        self.scaling("slave_scaling", ss);
    }
    fn options(&mut self, o: &motion::MoveOptions) {
        if let Some(b) = o.blending_position {
            self.finite("options.blending_position", b);
        }
    }
    fn done<T>(self, t: T) -> AppResult<T> {
        if self.0.is_empty() {
            Ok(t)
        } else {
            Err(AppError::invalid(self.0))
        }
    }
}

/// The master of a coupling: an axis other than the slave.
fn master_slot(c: &mut Check, reg: &Registry, axis: &AxisEntry, master: &str) -> AxisSlot {
    match reg.find(master) {
        None => {
            c.fail("master", "no such axis");
            0
        }
        Some(m) if m.id == axis.id => {
            c.fail("master", "an axis cannot be its own master");
            0
        }
        Some(m) => m.slot,
    }
}

fn one() -> f64 {
    1.0
}
