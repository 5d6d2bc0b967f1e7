//! MC_Power, MC_Reset, MC_SetPosition, MC_SetEncoderScalingFactor, MC_SetOverride,
//! MC_OverrideFilter: the axis's enable, its error reset, its position and its scale, its
//! overrides.

use motion::{BufferMode, CommandKind};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::*;
use crate::app::{AxisEntry, Registry};
use crate::error::AppResult;

/// The family's catalogue entries (the form: `crate::blocks`).
macro_rules! entries {
    ($catalogue:ident) => {
        $catalogue! {
            power: "power" at axes, PowerBody, PowerBody::to_kind, Operator, Status, [],
                "MC_Power: enable (stays active until released with DELETE /commands/{id} or a power with enable=false)";
            reset: "reset" at axes, EmptyBody, |_, _, _| Ok(CommandKind::Reset), Operator, Done, [],
                "MC_Reset: clear an axis error";
            set_position: "set-position" at axes, SetPositionBody, SetPositionBody::to_kind, Operator, Done, [],
                "MC_SetPosition";
            set_encoder_scaling_factor: "set-encoder-scaling-factor" at axes, SetEncoderScalingFactorBody, SetEncoderScalingFactorBody::to_kind, Operator, Done, [],
                "MC_SetEncoderScalingFactor: the encoder's units per increment; absolute (the position jumps, at standstill only) or relative (no jump, also in motion)";
            set_override: "set-override" at axes, SetOverrideBody, SetOverrideBody::to_kind, Operator, Done, [],
                "MC_SetOverride: velocity factor at once; acceleration and jerk factors for the motion commands that follow";
            override_filter: "override-filter" at axes, OverrideFilterBody, OverrideFilterBody::to_kind, Operator, Done, [],
                "MC_OverrideFilter: a raw override value (digits) clamped, quantised and applied as the power override after its recovery time (0 % and 100 % at once)";
        }
    };
}
pub(crate) use entries;

/// MC_Power.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(default, deny_unknown_fields)]
#[schema(example = json!({"enable": true}))]
pub struct PowerBody {
    pub enable: bool,
    pub enable_positive: bool,
    pub enable_negative: bool,
    /// Velocity override in percent (0–100).
    #[schema(minimum = 0, maximum = 100)]
    pub override_percent: f64,
    /// How removing the enable (enable=false, or DELETE of the enabling command) acts:
    /// `aborting` (default) disables at once; any other mode waits until the axis no longer
    /// executes a job (§4.1.1), the command staying busy until then.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub buffer_mode: Option<BufferMode>,
}

impl Default for PowerBody {
    fn default() -> Self {
        PowerBody {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
            buffer_mode: None,
        }
    }
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// MC_SetPosition.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"position": 0.0}))]
pub struct SetPositionBody {
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub position: f64,
    #[serde(default, skip_serializing_if = "is_false")]
    pub relative: bool,
    #[serde(default, skip_serializing_if = "is_false")]
    pub clear_position_lag: bool,
    /// Undo the offset earlier set-positions accumulated (`status.set_position_offset`),
    /// back to the referenced coordinates; `position` and `relative` are then not used.
    #[serde(default, skip_serializing_if = "is_false")]
    pub clear_position_offset: bool,
}

/// MC_SetOverride.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"velocity_factor": 0.5}))]
pub struct SetOverrideBody {
    /// 0.0–1.0: scales the velocity of every motion at once (with MC_Power's override).
    #[schema(minimum = 0, maximum = 1)]
    pub velocity_factor: f64,
    /// (0, 1], default 1: scales acceleration and deceleration of motion commands started
    /// after it (not MC_Halt or MC_Stop).
    #[serde(default = "one")]
    #[schema(exclusive_minimum = 0, maximum = 1, default = 1.0)]
    pub acceleration_factor: f64,
    /// (0, 1], default 1: scales the jerk of motion commands started after it.
    #[serde(default = "one")]
    #[schema(exclusive_minimum = 0, maximum = 1, default = 1.0)]
    pub jerk_factor: f64,
}

/// MC_OverrideFilter (§4.5.4): a raw override (e.g. an analog potentiometer in digits) clamped
/// to the thresholds and quantised into `steps`, applied as the axis's MC_Power override
/// (`power_override_percent`). After each change of the filtered value a new one waits until
/// `recovery_time` has passed — and is then applied without being sent again — except 0 % and
/// 100 %, which act at once.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"raw": 16384}))]
pub struct OverrideFilterBody {
    /// OverrideValueRaw, digits.
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub raw: f64,
    /// LowerOverrideThreshold (default 0).
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12, default = 0.0)]
    pub lower_threshold: f64,
    /// UpperOverrideThreshold (default 32767), above lower_threshold.
    #[serde(default = "default_upper_threshold")]
    #[schema(minimum = -1e12, maximum = 1e12, default = 32767.0)]
    pub upper_threshold: f64,
    /// OverrideSteps (default 200 = 0.5 %), 2 to 1 000 000.
    #[serde(default = "default_override_steps")]
    #[schema(minimum = 2, maximum = 1000000, default = 200)]
    pub steps: u32,
    /// OverrideRecoveryTime in seconds (default 0.15).
    #[serde(default = "default_recovery_time")]
    #[schema(minimum = 0, maximum = 3600, default = 0.15)]
    pub recovery_time: f64,
}

fn default_upper_threshold() -> f64 {
    32767.0
}

fn default_override_steps() -> u32 {
    200
}

fn default_recovery_time() -> f64 {
    0.15
}

impl PowerBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if !(self.override_percent.is_finite() && (0.0..=100.0).contains(&self.override_percent)) {
            c.fail("override_percent", "must be between 0 and 100");
        }
        c.done(CommandKind::Power {
            enable: self.enable,
            enable_positive: self.enable_positive,
            enable_negative: self.enable_negative,
            override_percent: self.override_percent,
            buffer_mode: self.buffer_mode.unwrap_or_default(),
        })
    }
}

impl SetPositionBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.finite("position", self.position);
        c.done(CommandKind::SetPosition {
            position: self.position,
            relative: self.relative,
            clear_position_lag: self.clear_position_lag,
            clear_position_offset: self.clear_position_offset,
        })
    }
}

impl SetOverrideBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if !(self.velocity_factor.is_finite() && (0.0..=1.0).contains(&self.velocity_factor)) {
            c.fail("velocity_factor", "must be between 0 and 1");
        }
        for (field, f) in [
            ("acceleration_factor", self.acceleration_factor),
            ("jerk_factor", self.jerk_factor),
        ] {
            if !(f.is_finite() && f > 0.0 && f <= 1.0) {
                c.fail(field, "must be above 0 and at most 1");
            }
        }
        c.done(CommandKind::SetOverride {
            velocity_factor: self.velocity_factor,
            acceleration_factor: self.acceleration_factor,
            jerk_factor: self.jerk_factor,
        })
    }
}

impl OverrideFilterBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.finite("raw", self.raw);
        c.finite("lower_threshold", self.lower_threshold);
        c.finite("upper_threshold", self.upper_threshold);
        if self.upper_threshold <= self.lower_threshold {
            c.fail("upper_threshold", "must be above lower_threshold");
        }
        if !(2..=1_000_000).contains(&self.steps) {
            c.fail("steps", "must be from 2 to 1000000");
        }
        if !(self.recovery_time.is_finite() && (0.0..=3600.0).contains(&self.recovery_time)) {
            c.fail("recovery_time", "must be between 0 and 3600 s");
        }
        c.done(CommandKind::OverrideFilter {
            raw: self.raw,
            lower_threshold: self.lower_threshold,
            upper_threshold: self.upper_threshold,
            steps: self.steps,
            recovery_time: self.recovery_time,
        })
    }
}

/// `E_SetScalingFactorMode` (§6.11.6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum EncoderScalingMode {
    /// The position is the count × the new factor: it jumps (at standstill only; the set
    /// position goes along, nothing moves).
    #[default]
    Absolute,
    /// The offset takes up the change: no jump, also in motion (as long as the drive's
    /// velocity steps by no more than the axis's acceleration in one cycle).
    Relative,
}

/// MC_SetEncoderScalingFactor (§4.5.9): the encoder's units per increment (#1040). The axis's
/// drive is its encoder, so its setpoints are scaled alike and the position loop stays closed.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"scaling_factor": 0.001, "mode": "relative"}))]
pub struct SetEncoderScalingFactorBody {
    /// Units per encoder increment (> 0).
    #[schema(minimum = 1e-12, maximum = 1e12)]
    pub scaling_factor: f64,
    #[serde(default)]
    pub mode: EncoderScalingMode,
}

impl SetEncoderScalingFactorBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if !(self.scaling_factor.is_finite() && (1e-12..=1e12).contains(&self.scaling_factor)) {
            c.fail("scaling_factor", "must be a number from 1e-12 to 1e12");
        }
        c.done(CommandKind::SetEncoderScalingFactor {
            factor: self.scaling_factor,
            relative: self.mode == EncoderScalingMode::Relative,
        })
    }
}
