//! Gear couplings: MC_GearIn, MC_GearInDyn, MC_GearInMultiMaster, MC_GearOut; and the phase
//! shift of a coupled slave against its master: MC_PhasingAbsolute, MC_PhasingRelative,
//! MC_HaltPhasing.

use motion::CommandKind;
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
            gear_in: "gear-in" at axes, GearInBody, GearInBody::to_kind, Operator, InGear, [],
                "MC_GearIn: couple to a master (wait returns at in_gear)";
            gear_in_dyn: "gear-in-dyn" at axes, GearInDynBody, GearInDynBody::to_kind, Operator, InGear, [],
                "MC_GearInDyn: couple with a ratio that may change while enabled (a further gear-in-dyn to the same master changes it; wait returns at in_gear); DELETE /commands/{id} = Enable FALSE (ratio frozen, still coupled)";
            gear_in_multi_master: "gear-in-multi-master" at axes, GearInMultiMasterBody, GearInMultiMasterBody::to_kind, Operator, InGear, [],
                "MC_GearInMultiMaster: follow the sum of up to four masters times their ratios (ratios changeable while enabled; wait returns at in_gear); DELETE /commands/{id} = Enable FALSE (ratios frozen, still coupled)";
            gear_out: "gear-out" at axes, EmptyBody, |_, _, _| Ok(CommandKind::GearOut), Operator, Done, [],
                "MC_GearOut";
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

/// MC_GearIn.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"master": "x", "ratio_numerator": 1.0, "ratio_denominator": 1}))]
pub struct GearInBody {
    /// Master axis id or name.
    pub master: String,
    #[schema(schema_with = nonzero_number)]
    pub ratio_numerator: f64,
    #[schema(minimum = 1, maximum = 65535)]
    pub ratio_denominator: u16,
}

/// One master of MC_GearInMultiMaster and its ratio.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[schema(example = json!({"master": "x", "gear_ratio": 1.0}))]
#[serde(deny_unknown_fields)]
pub struct MasterRatio {
    /// Master axis id or name.
    pub master: String,
    /// GearRatio of this master (changeable while enabled).
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub gear_ratio: f64,
}

/// MC_GearInMultiMaster (§5.5.4, Enable-type): the slave follows Σ gear_ratio_i × master_i's
/// travel; stays active until released with `DELETE /commands/{id}` (the ratios freeze, the
/// slave stays coupled). A further gear-in-multi-master to the same masters while enabled
/// changes the ratios (limited by `acceleration` without advanced slave dynamics).
/// Without `advanced_slave_dynamics` the masters and the slave must stand when it couples
/// (409 master_moving); with it the slave synchronises within its acceleration, deceleration
/// and jerk, `sync_mode` saying which position differences it makes up.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"masters": [{"master": "x", "gear_ratio": 1.0}, {"master": "spindle", "gear_ratio": 0.1}],
    "advanced_slave_dynamics": true, "sync_mode": "possync2", "acceleration": 1000.0}))]
pub struct GearInMultiMasterBody {
    /// Master1…Master4 in order, 1 to 4 of them.
    #[schema(min_items = 1, max_items = 4)]
    pub masters: Vec<MasterRatio>,
    /// ≥ 0, 0 = the axis default.
    #[serde(default)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
    /// With advanced slave dynamics; ≥ 0, 0 = the axis default.
    #[serde(default)]
    #[schema(minimum = 0)]
    pub deceleration: f64,
    #[serde(default)]
    #[schema(minimum = 0)]
    pub jerk: f64,
    #[serde(default)]
    pub advanced_slave_dynamics: bool,
    #[serde(default)]
    pub sync_mode: motion::MultiMasterSyncMode,
}

/// MC_GearInDyn (Enable-type): stays active until released with `DELETE /commands/{id}`
/// (Enable FALSE: the ratio freezes, the slave stays coupled). A further gear-in-dyn to the
/// same master while this one is enabled takes over and changes the ratio.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"master": "x", "gear_ratio": 1.5, "acceleration": 500.0}))]
pub struct GearInDynBody {
    /// Master axis id or name.
    pub master: String,
    /// Slave travel per master travel (signed).
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub gear_ratio: f64,
    /// Slave acceleration that a ratio change may cause at the master's maximum velocity,
    /// units/s² (0 = the slave's AxisAcc #1004).
    #[serde(default)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
}

impl GearInBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        c.scaling("ratio_numerator", self.ratio_numerator);
        if self.ratio_denominator == 0 {
            c.fail("ratio_denominator", "must be ≥ 1");
        }
        c.done(CommandKind::GearIn {
            master,
            ratio_numerator: self.ratio_numerator,
            ratio_denominator: self.ratio_denominator,
        })
    }
}

impl GearInMultiMasterBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if self.masters.is_empty() || self.masters.len() > 4 {
            c.fail("masters", "must name 1 to 4 masters");
        }
        let mut masters = [None; 4];
        let mut ratios = [0.0; 4];
        for (i, m) in self.masters.iter().take(4).enumerate() {
            let mut one = Check::default();
            let slot = master_slot(&mut one, reg, axis, &m.master);
            for e in one.0 {
                c.fail(&format!("masters[{i}].{}", e.field), &e.message);
            }
            if masters[..i].contains(&Some(slot)) {
                c.fail(&format!("masters[{i}].master"), "names a master twice");
            }
            masters[i] = Some(slot);
            if !(m.gear_ratio.is_finite() && m.gear_ratio.abs() <= MAX_MAGNITUDE) {
                c.fail(
                    &format!("masters[{i}].gear_ratio"),
                    "must be a number from -1e12 to 1e12",
                );
            }
            ratios[i] = m.gear_ratio;
        }
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.done(CommandKind::GearInMultiMaster(motion::GearInMultiMaster {
            masters,
            ratios,
            acceleration: self.acceleration,
            deceleration: self.deceleration,
            jerk: self.jerk,
            advanced_slave_dynamics: self.advanced_slave_dynamics,
            sync_mode: self.sync_mode,
        }))
    }
}

impl GearInDynBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        c.finite("gear_ratio", self.gear_ratio);
        c.non_negative("acceleration", self.acceleration);
        c.done(CommandKind::GearInDyn {
            master,
            gear_ratio: self.gear_ratio,
            acceleration: self.acceleration,
        })
    }
}

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
