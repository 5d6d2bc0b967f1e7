//! MC_MoveSuperImposed and MC_AbortSuperposition: a relative motion laid over the running one.

use motion::{CommandKind, Superposition, SuperpositionAbortOption, SuperpositionMode};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::*;
use crate::app::{AxisEntry, Registry};
use crate::error::AppResult;

/// The family's catalogue entries (the form: `crate::blocks`).
macro_rules! entries {
    ($catalogue:ident) => {
        $catalogue! {
            move_superimposed: "move-superimposed" at axes, MoveSuperImposedBody, MoveSuperImposedBody::to_kind, Operator, Done, [],
                "MC_MoveSuperImposed: lay a relative distance over the running motion (409 axis_not_moving at standstill; warning 0x4243 when it can only be done in part)";
            abort_superposition: "abort-superposition" at axes, EmptyBody, |_, _, _| Ok(CommandKind::AbortSuperposition), Operator, Done, [],
                "MC_AbortSuperposition: end a running superposition (what it applied so far stays)";
        }
    };
}
pub(crate) use entries;

/// MC_MoveSuperImposed: a relative motion laid over the running one.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"distance": 10.0, "velocity_diff": 50.0, "velocity_process": 200.0, "length": 200.0}))]
pub struct MoveSuperImposedBody {
    /// What `length` refers to and what is minimised.
    #[serde(default)]
    pub mode: SuperpositionMode,
    /// Distance to make up (> 0: get ahead, < 0: fall back), units.
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub distance: f64,
    /// Largest velocity difference to the main motion (> 0), units/s.
    #[schema(exclusive_minimum = 0)]
    pub velocity_diff: f64,
    /// 0 = the axis default.
    #[serde(default)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
    /// 0 = the axis default.
    #[serde(default)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    /// Mean velocity of the main motion while the superposition runs (> 0), units/s.
    #[schema(exclusive_minimum = 0)]
    pub velocity_process: f64,
    /// Travel available for the superposition (> 0), units; see `mode`.
    #[schema(exclusive_minimum = 0)]
    pub length: f64,
    #[serde(default)]
    pub abort_option: SuperpositionAbortOption,
}

impl MoveSuperImposedBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.finite("distance", self.distance);
        c.positive("velocity_diff", self.velocity_diff);
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.positive("velocity_process", self.velocity_process);
        c.positive("length", self.length);
        c.done(CommandKind::MoveSuperImposed(Superposition {
            mode: self.mode,
            distance: self.distance,
            velocity_diff: self.velocity_diff,
            acceleration: self.acceleration,
            deceleration: self.deceleration,
            velocity_process: self.velocity_process,
            length: self.length,
            abort_option: self.abort_option,
        }))
    }
}
