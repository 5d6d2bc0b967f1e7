//! MC_PhasingAbsolute, MC_PhasingRelative, MC_HaltPhasing: a phase shift of a coupled slave
//! against its master.

use motion::CommandKind;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::*;
use crate::app::{AxisEntry, Registry};
use crate::error::AppResult;

/// The family's catalogue entries (the form: `crate::blocks`).
macro_rules! entries {
    ($catalogue:ident) => {
        $catalogue! {
            phasing_absolute: "phasing-absolute" at axes, PhasingBody, PhasingBody::absolute, Operator, Done, [],
                "MC_PhasingAbsolute: establish a phase shift of this coupled slave against its master by a jerk-limited superimposed motion (409 phasing_not_coupled unless coupled to that master by gear-in, a cam, or gear-in-multi-master with advanced slave dynamics in possync1/2)";
            phasing_relative: "phasing-relative" at axes, PhasingBody, PhasingBody::relative, Operator, Done, [],
                "MC_PhasingRelative: change the phase shift of this coupled slave by phase_shift (covered so far: status covered_phase_shift)";
            halt_phasing: "halt-phasing" at axes, HaltPhasingBody, HaltPhasingBody::to_kind, Operator, Done, [lease_free],
                "MC_HaltPhasing: bring the phase motion to rest (aborts the running phasing; the shift stays where it stops)";
        }
    };
}
pub(crate) use entries;

/// MC_PhasingAbsolute / MC_PhasingRelative (§5.6.2, §5.6.3): a phase shift of this slave
/// against its master made by a jerk-limited superimposed motion (the slave coupled by
/// gear-in, a cam, or gear-in-multi-master with advanced slave dynamics in possync1/2 — not
/// gear-in-dyn). BufferMode is Aborting only: a new phasing command
/// takes over from the running one's velocity, which is also how ContinuousUpdate is
/// served. The shift reached is the status's `absolute_phase_shift` / `covered_phase_shift`.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"master": "x", "phase_shift": 10.0, "velocity": 20.0}))]
pub struct PhasingBody {
    /// Master axis id or name: the master the slave is coupled to.
    pub master: String,
    /// Absolute: the shift to establish; relative: the change of the shift (slave units).
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub phase_shift: f64,
    /// Maximum velocity of the phase motion, ≥ 0.01 units/s.
    #[schema(minimum = 0.01)]
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
}

/// MC_HaltPhasing (§5.6.1): bring the phase motion to rest (0 = the axis's default
/// deceleration and jerk); the shift stays where the phase stops.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"master": "x", "deceleration": 500.0}))]
pub struct HaltPhasingBody {
    /// Master axis id or name: the master the slave is coupled to.
    pub master: String,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub jerk: f64,
}

impl PhasingBody {
    fn to_phasing(
        &self,
        reg: &Registry,
        axis: &AxisEntry,
        kind: motion::PhasingKind,
    ) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        c.finite("phase_shift", self.phase_shift);
        if !(self.velocity.is_finite() && self.velocity >= 0.01) {
            c.fail("velocity", "must be ≥ 0.01");
        }
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.done(CommandKind::Phasing {
            master,
            motion: motion::PhasingMotion {
                kind,
                phase_shift: self.phase_shift,
                velocity: self.velocity,
                acceleration: self.acceleration,
                deceleration: self.deceleration,
                jerk: self.jerk,
            },
        })
    }
    pub fn absolute(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        self.to_phasing(reg, axis, motion::PhasingKind::Absolute)
    }
    pub fn relative(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        self.to_phasing(reg, axis, motion::PhasingKind::Relative)
    }
}

impl HaltPhasingBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.done(CommandKind::Phasing {
            master,
            motion: motion::PhasingMotion {
                kind: motion::PhasingKind::Halt,
                phase_shift: 0.0,
                velocity: 0.0,
                acceleration: 0.0,
                deceleration: self.deceleration,
                jerk: self.jerk,
            },
        })
    }
}
