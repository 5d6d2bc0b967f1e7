//! MC_Jog: motion while renewed (its dead-man), in either direction, continuous or by a step.

use motion::{CommandKind, JogMode};
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
            jog: "jog" at axes, JogBody, JogBody::to_kind, Operator, InVelocity, [keepalive],
                "MC_Jog: runs while renewed with POST /commands/{id}/keepalive within deadman_timeout; DELETE releases";
        }
    };
}
pub(crate) use entries;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum JogDirection {
    #[default]
    Forward,
    Backward,
}

/// MC_Jog: a press of JogForward / JogBackwards; held by keepalives (dead-man).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"direction": "forward", "mode": "standard_slow", "deadman_timeout": 0.5}))]
pub struct JogBody {
    /// Default `forward`.
    #[serde(default)]
    pub direction: JogDirection,
    /// Default `standard_slow`.
    #[serde(default)]
    pub mode: JogMode,
    /// Inching distance (inching modes).
    #[serde(default)]
    #[schema(default = 0.0)]
    #[schema(minimum = 0)]
    pub position: f64,
    /// Continuous mode velocity.
    #[serde(default)]
    #[schema(default = 0.0)]
    #[schema(minimum = 0)]
    pub velocity: f64,
    #[serde(default)]
    #[schema(default = 0.0)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
    #[serde(default)]
    #[schema(default = 0.0)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(default = 0.0)]
    #[schema(minimum = 0)]
    pub jerk: f64,
    /// Seconds without keepalive after which the jog stops (0.05 s up to the axis's
    /// `dynamics.jog_deadman_max`, at most 10; default 0.5).
    #[serde(default = "default_deadman_timeout")]
    #[schema(default = 0.5)]
    #[schema(minimum = 0.05, maximum = 10)]
    pub deadman_timeout: f64,
}

fn default_deadman_timeout() -> f64 {
    0.5
}

impl Default for JogBody {
    fn default() -> Self {
        JogBody {
            direction: JogDirection::Forward,
            mode: JogMode::StandardSlow,
            position: 0.0,
            velocity: 0.0,
            acceleration: 0.0,
            deceleration: 0.0,
            jerk: 0.0,
            deadman_timeout: default_deadman_timeout(),
        }
    }
}

impl JogBody {
    pub fn to_kind(&self, _: &Registry, e: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        // Bounded by the engineer's maximum for this axis: a client that vanishes mid-jog
        // costs at most that long at jog speed.
        let max = e.config.dynamics.jog_deadman_max;
        if !(self.deadman_timeout.is_finite() && (0.05..=max).contains(&self.deadman_timeout)) {
            c.fail(
                "deadman_timeout",
                &format!("must be between 0.05 and {max} s (the axis's dynamics.jog_deadman_max)"),
            );
        }
        c.non_negative("velocity", self.velocity);
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.non_negative("position", self.position);
        match self.mode {
            JogMode::Continuous if self.velocity <= 0.0 => {
                c.fail("velocity", "continuous jog needs a velocity > 0")
            }
            JogMode::Inching | JogMode::InchingModulo if self.position <= 0.0 => {
                c.fail("position", "inching needs a distance > 0")
            }
            _ => {}
        }
        c.done(CommandKind::Jog {
            mode: self.mode,
            forward: self.direction == JogDirection::Forward,
            position: self.position,
            velocity: self.velocity,
            dynamics: dynamics(self.acceleration, self.deceleration, self.jerk),
            deadman: self.deadman_timeout,
        })
    }
}
