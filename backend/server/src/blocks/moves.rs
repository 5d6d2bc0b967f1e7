//! The positioning blocks (MC_MoveAbsolute, MC_MoveRelative, MC_MoveAdditive, MC_MoveModulo,
//! MC_MoveVelocity, MC_MoveContinuousAbsolute/Relative) and the blocks that end motion (MC_Halt,
//! MC_Stop).

use motion::{BufferMode, CommandKind, Direction, MoveOptions, Positioning};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::*;
use crate::app::{AxisEntry, Registry};
use crate::error::AppResult;
use crate::model::*;

/// The family's catalogue entries (the form: `crate::blocks`).
macro_rules! entries {
    ($catalogue:ident) => {
        $catalogue! {
            move_absolute: "move-absolute" at axes, MoveBody, MoveBody::absolute, Operator, Done, [],
                "MC_MoveAbsolute";
            move_relative: "move-relative" at axes, MoveRelativeBody, MoveRelativeBody::relative, Operator, Done, [],
                "MC_MoveRelative: move `distance` from the set position";
            move_additive: "move-additive" at axes, MoveRelativeBody, MoveRelativeBody::additive, Operator, Done, [],
                "MC_MoveAdditive: add `distance` to the running target";
            move_modulo: "move-modulo" at axes, MoveModuloBody, MoveModuloBody::modulo, Operator, Done, [],
                "MC_MoveModulo (modulo axes)";
            move_velocity: "move-velocity" at axes, MoveVelocityBody, MoveVelocityBody::to_kind, Operator, InVelocity, [],
                "MC_MoveVelocity (wait returns at in_velocity)";
            move_continuous_absolute: "move-continuous-absolute" at axes, MoveContinuousBody, MoveContinuousBody::to_kind, Operator, InEndVelocity, [],
                "MC_MoveContinuousAbsolute (wait returns at in_end_velocity)";
            move_continuous_relative: "move-continuous-relative" at axes, MoveContinuousRelativeBody, MoveContinuousRelativeBody::to_kind, Operator, InEndVelocity, [],
                "MC_MoveContinuousRelative (wait returns at in_end_velocity)";
            halt: "halt" at axes, HaltBody, HaltBody::to_kind, Operator, Done, [lease_free],
                "MC_Halt";
            stop: "stop" at axes, StopBody, StopBody::to_kind, Operator, Done, [lease_free],
                "MC_Stop: stops and locks the axis until released with DELETE /commands/{id}";
        }
    };
}
pub(crate) use entries;

/// MC_MoveAbsolute: a target position.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"position": 250.0, "velocity": 200.0}))]
pub struct MoveBody {
    /// Target position.
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub position: f64,
    /// > 0, units/s.
    #[schema(exclusive_minimum = 0)]
    pub velocity: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub jerk: f64,
    #[serde(default)]
    pub buffer_mode: BufferMode,
    #[serde(default)]
    pub options: MoveOptions,
}

/// MC_MoveModulo: a target within one turn, reached in a direction.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"position": 90.0, "velocity": 360.0, "direction": "shortest_way"}))]
pub struct MoveModuloBody {
    /// Modulo target (≥ 0; a target of a full turn or more adds turns).
    #[schema(minimum = 0, maximum = 1e12)]
    pub position: f64,
    /// > 0, units/s.
    #[schema(exclusive_minimum = 0)]
    pub velocity: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub jerk: f64,
    #[serde(default)]
    pub buffer_mode: BufferMode,
    #[serde(default)]
    pub options: MoveOptions,
    /// Default `positive`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<Direction>,
}

/// MC_MoveRelative / MC_MoveAdditive: a distance (PLCopen's `Distance`), from the set position
/// (relative) or added to the running target (additive).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"distance": 50.0, "velocity": 200.0}))]
pub struct MoveRelativeBody {
    /// Signed distance, units.
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub distance: f64,
    /// > 0, units/s.
    #[schema(exclusive_minimum = 0)]
    pub velocity: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub jerk: f64,
    #[serde(default)]
    pub buffer_mode: BufferMode,
    #[serde(default)]
    pub options: MoveOptions,
}

/// MC_MoveContinuousRelative: a distance, then `end_velocity`.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"distance": 100.0, "velocity": 200.0, "end_velocity": 50.0}))]
pub struct MoveContinuousRelativeBody {
    /// Signed distance, units.
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub distance: f64,
    #[schema(exclusive_minimum = 0)]
    pub velocity: f64,
    /// Velocity kept after the target (signed).
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub end_velocity: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub jerk: f64,
    #[serde(default)]
    pub buffer_mode: BufferMode,
    #[serde(default)]
    pub options: MoveOptions,
}

/// MC_MoveContinuousAbsolute: a target position, then `end_velocity`.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"position": 500.0, "velocity": 200.0, "end_velocity": 50.0}))]
pub struct MoveContinuousBody {
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub position: f64,
    #[schema(exclusive_minimum = 0)]
    pub velocity: f64,
    /// Velocity kept after the target (signed).
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub end_velocity: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub jerk: f64,
    #[serde(default)]
    pub buffer_mode: BufferMode,
    #[serde(default)]
    pub options: MoveOptions,
}

/// MC_MoveVelocity.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"velocity": 100.0, "direction": "positive"}))]
pub struct MoveVelocityBody {
    #[schema(exclusive_minimum = 0)]
    pub velocity: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub jerk: f64,
    #[serde(default)]
    pub direction: Direction,
    #[serde(default)]
    pub buffer_mode: BufferMode,
    #[serde(default)]
    pub options: MoveOptions,
}

/// MC_Halt.
#[derive(Clone, Debug, Default, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"deceleration": 1000.0}))]
pub struct HaltBody {
    /// 0 = that of the running job.
    #[serde(default)]
    #[schema(default = 0.0)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(default = 0.0)]
    #[schema(minimum = 0)]
    pub jerk: f64,
    /// Default `aborting`.
    #[serde(default)]
    pub buffer_mode: BufferMode,
    /// Default: none set.
    #[serde(default)]
    pub options: MoveOptions,
}

/// MC_Stop.
#[derive(Clone, Debug, Default, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"deceleration": 5000.0, "jerk": 50000.0}))]
pub struct StopBody {
    #[serde(default)]
    #[schema(default = 0.0)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(default = 0.0)]
    #[schema(minimum = 0)]
    pub jerk: f64,
    /// Default: none set.
    #[serde(default)]
    pub options: MoveOptions,
}

/// The inputs every positioning block shares, checked, as the kernel's `Positioning`
/// (`field`: the body's name of the target or distance; the kernel calls both `position`).
fn positioning(
    c: &mut Check,
    (field, position): (&str, f64),
    velocity: f64,
    (acceleration, deceleration, jerk): (f64, f64, f64),
    buffer_mode: motion::BufferMode,
    options: motion::MoveOptions,
) -> Positioning {
    c.finite(field, position);
    c.positive("velocity", velocity);
    c.non_negative("acceleration", acceleration);
    c.non_negative("deceleration", deceleration);
    c.non_negative("jerk", jerk);
    c.options(&options);
    Positioning {
        position,
        velocity,
        dynamics: dynamics(acceleration, deceleration, jerk),
        buffer_mode,
        options,
    }
}

/// `positioning` for the bodies of the positioning blocks; `$target` is the body's name of its
/// target or distance.
macro_rules! positioning_inputs {
    ($($body:ty => $target:ident),+ $(,)?) => {$(
        impl $body {
            fn positioning(&self, c: &mut Check) -> Positioning {
                positioning(
                    c,
                    (stringify!($target), self.$target),
                    self.velocity,
                    (self.acceleration, self.deceleration, self.jerk),
                    self.buffer_mode,
                    self.options,
                )
            }
        }
    )+};
}

positioning_inputs! {
    MoveBody => position,
    MoveModuloBody => position,
    MoveRelativeBody => distance,
    MoveContinuousBody => position,
    MoveContinuousRelativeBody => distance,
}

impl MoveBody {
    /// MC_MoveAbsolute.
    pub fn absolute(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let p = self.positioning(&mut c);
        c.done(CommandKind::MoveAbsolute(p))
    }
}

impl MoveModuloBody {
    /// MC_MoveModulo: only on a modulo axis, with a target within one turn's range.
    pub fn modulo(&self, _: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let p = self.positioning(&mut c);
        if axis.config.modulo.is_none() {
            c.fail("axis", "move-modulo needs a modulo axis");
        }
        if self.position < 0.0 {
            c.fail("position", "a modulo target must be ≥ 0");
        }
        c.done(CommandKind::MoveModulo {
            move_: p,
            direction: self.direction.unwrap_or(Direction::Positive),
        })
    }
}

impl MoveRelativeBody {
    /// MC_MoveRelative: `distance` from the set position.
    pub fn relative(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let p = self.positioning(&mut c);
        c.done(CommandKind::MoveRelative(p))
    }

    /// MC_MoveAdditive: `distance` added to the running target.
    pub fn additive(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let p = self.positioning(&mut c);
        c.done(CommandKind::MoveAdditive(p))
    }
}

impl MoveContinuousRelativeBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let move_ = self.positioning(&mut c);
        c.finite("end_velocity", self.end_velocity);
        c.done(CommandKind::MoveContinuousRelative {
            move_,
            end_velocity: self.end_velocity,
        })
    }
}

impl MoveContinuousBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let move_ = self.positioning(&mut c);
        c.finite("end_velocity", self.end_velocity);
        c.done(CommandKind::MoveContinuousAbsolute {
            move_,
            end_velocity: self.end_velocity,
        })
    }
}

impl MoveVelocityBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.positive("velocity", self.velocity);
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.options(&self.options);
        c.done(CommandKind::MoveVelocity {
            velocity: self.velocity,
            dynamics: dynamics(self.acceleration, self.deceleration, self.jerk),
            direction: self.direction,
            buffer_mode: self.buffer_mode,
            options: self.options,
        })
    }
}

impl HaltBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.options(&self.options);
        c.done(CommandKind::Halt {
            deceleration: self.deceleration,
            jerk: self.jerk,
            buffer_mode: self.buffer_mode,
            options: self.options,
        })
    }
}

impl StopBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.options(&self.options);
        c.done(CommandKind::Stop {
            deceleration: self.deceleration,
            jerk: self.jerk,
            options: self.options,
        })
    }
}
