//! The drive-side blocks: the external setpoint generator (MC_ExtSetPointGenEnable/Disable and its
//! feed, MC_ExtSetPointGenFeed), MC_TorqueControl, MC_WriteDriveOperationMode,
//! MC_SelectControlLoop.

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
            ext_setpoint_gen_enable: "ext-setpoint-gen-enable" at axes, ExtSetPointGenEnableBody, ExtSetPointGenEnableBody::to_kind, Operator, Done, [],
                "MC_ExtSetPointGenEnable: the axis takes its setpoints from samples fed to ext-setpoint-gen-feed (extrapolated between feeds; a stalled stream stops a moving axis in ErrorStop)";
            ext_setpoint_gen_disable: "ext-setpoint-gen-disable" at axes, EmptyBody, |_, _, _| Ok(CommandKind::ExtSetPointGenDisable), Operator, Done, [lease_free],
                "MC_ExtSetPointGenDisable: the axis no longer takes samples (one moving by them stops on its ramp)";
            torque_control: "torque-control" at axes, TorqueControlBody, TorqueControlBody::to_kind, Operator, InTorque, [],
                "MC_TorqueControl: the drive in torque mode with a ramped torque, the velocity kept within limits (wait returns at in_torque); MC_Halt, MC_Stop or a move returns to position control";
            write_drive_operation_mode: "write-drive-operation-mode" at axes, WriteDriveOperationModeBody, WriteDriveOperationModeBody::to_kind, Operator, Done, [],
                "MC_WriteDriveOperationMode: the drive's position-based mode (configured, position, velocity), at rest; Done once the drive reports it";
            select_control_loop: "select-control-loop" at axes, SelectControlLoopBody, SelectControlLoopBody::to_kind, Operator, Done, [],
                "MC_SelectControlLoop: an axis has the one control loop of its drive (index 0)";
        }
    };
}
pub(crate) use entries;

/// `E_PositionType` of MC_ExtSetPointGenEnable's monitored position.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum PositionType {
    #[default]
    Absolute,
    /// Relative to the set position at the enable.
    Relative,
}

/// MC_ExtSetPointGenEnable (§4.4.1): from now on the axis takes its setpoints from samples a
/// client feeds (`POST /axes/{axis}/ext-setpoint-gen-feed`, or the websocket method of that
/// name — at up to the cycle rate; a sample is extrapolated with its velocity and
/// acceleration until the next arrives). The first sample must be where the axis stands.
/// A stream that pauses longer than `feed_timeout` while it moves the axis stops it in
/// ErrorStop (0x70B7); a sample that jumps or exceeds the maximum velocity stops it (0x70B6),
/// as does one heading into an enabled software limit (0x7003). Enabled at standstill.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"position": 250.0, "feed_timeout": 0.05}))]
pub struct ExtSetPointGenEnableBody {
    /// Monitored for InTargetPosition (the axis does not go there by itself); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub position: Option<f64>,
    #[serde(default)]
    pub position_type: PositionType,
    /// Seconds without a sample after which a moving axis stops (default 0.05).
    #[serde(default = "default_feed_timeout")]
    #[schema(exclusive_minimum = 0, maximum = 10, default = 0.05)]
    pub feed_timeout: f64,
}

fn default_feed_timeout() -> f64 {
    motion::DEFAULT_EXT_FEED_TIMEOUT
}

/// MC_ExtSetPointGenFeed (§4.4.3): the sample for now. Not a command: it is applied in the
/// next cycle (or refused) and answered with that cycle.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"position": 12.5, "velocity": 40.0, "acceleration": 0.0, "direction": 1}))]
pub struct ExtSetPointFeedBody {
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub position: f64,
    /// Units/s, within AxisVeloMax.
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub velocity: f64,
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub acceleration: f64,
    /// −1, 0 or +1 (standstill); absent: the velocity's sign.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = -1, maximum = 1)]
    pub direction: Option<i8>,
}

/// The answer to a fed sample: the kernel cycle it takes effect in.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"cycle": 1873}))]
pub struct FeedResult {
    pub cycle: u64,
}

/// MC_TorqueControl (§5.7.1): the drive switched to torque mode (CST) with a torque ramped at
/// `torque_ramp`; the load's velocity is kept within the limits by the drive. Busy until
/// MC_Halt, MC_Stop or another motion command takes the axis back to position control (from
/// where it is, at its speed). BufferMode Aborting only: a further torque-control is the
/// manual's ContinuousUpdate (it takes over from the running setpoint; `relative` adds to
/// its target). `?wait=true` answers at InTorque (`in_torque`: the torque built up, no
/// velocity limit active).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"torque": 35.0, "torque_ramp": 10.0, "velocity_limit_high": 400.0, "velocity_limit_low": -500.0}))]
pub struct TorqueControlBody {
    /// Percent of rated torque (relative: the change); positive drives the positive way.
    #[schema(minimum = -1000, maximum = 1000)]
    pub torque: f64,
    /// Rate of change of the torque setpoint, percent/s (> 0).
    #[schema(exclusive_minimum = 0, maximum = 1e9)]
    pub torque_ramp: f64,
    #[serde(default)]
    pub relative: bool,
    /// The velocity (units/s) the drive keeps the load below; within ±AxisVeloMax, ≥ low.
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub velocity_limit_high: f64,
    /// The velocity (units/s) the drive keeps the load above.
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub velocity_limit_low: f64,
    /// `Options.ManualTorqueStartValue`: start the ramp here (percent) instead of at the
    /// drive's actual torque.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = -1000, maximum = 1000)]
    pub manual_start_torque: Option<f64>,
}

/// MC_WriteDriveOperationMode (§4.5.1): the drive's position-based operation mode, at rest;
/// Done once the drive reports it (409 drive_mode_not_reached after 0.5 s). `torque` is
/// MC_TorqueControl's (409 invalid_mode here), so a drive is never left in torque mode
/// without a torque under control.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"drive_operation_mode": "position"}))]
pub struct WriteDriveOperationModeBody {
    /// `configured` (DriveOperationMode_Default: the drive's configured mode), `position`
    /// (Pos1, CSP), `velocity` (Velo1, CSV).
    pub drive_operation_mode: motion::DriveMode,
}

/// `E_SelectControlLoopType` (§6.10): only the standard switch is usable (as in TwinCAT).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum SelectControlLoopType {
    #[default]
    Standard,
}

/// MC_SelectControlLoop (§4.5.7): an axis has the one control loop of its drive, index 0;
/// another index is a 409 control_loop_unknown.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"encoder_index": 0}))]
pub struct SelectControlLoopBody {
    /// The control loop's index (0..9).
    #[schema(minimum = 0, maximum = 9)]
    pub encoder_index: u16,
    #[serde(default)]
    pub select_type: SelectControlLoopType,
}

impl ExtSetPointGenEnableBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if let Some(p) = self.position {
            c.finite("position", p);
        }
        if !(self.feed_timeout.is_finite() && self.feed_timeout > 0.0 && self.feed_timeout <= 10.0)
        {
            c.fail("feed_timeout", "must be above 0 and at most 10 s");
        }
        c.done(CommandKind::ExtSetPointGenEnable {
            target: self.position,
            relative: self.position_type == PositionType::Relative,
            timeout: self.feed_timeout,
        })
    }
}

impl ExtSetPointFeedBody {
    /// MC_ExtSetPointGenFeed's sample, checked (its velocity within the axis's AxisVeloMax).
    pub fn to_kind(&self, _: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let vmax = axis.params.axis_velo_max;
        let body = self;
        let mut c = Check::default();
        c.finite("position", body.position);
        c.finite("acceleration", body.acceleration);
        if !(body.velocity.is_finite() && body.velocity.abs() <= vmax) {
            c.fail("velocity", &format!("must be within ±{vmax} (AxisVeloMax)"));
        }
        let sign = |v: f64| {
            if v > 0.0 {
                1
            } else if v < 0.0 {
                -1
            } else {
                0
            }
        };
        let direction = body.direction.unwrap_or(sign(body.velocity));
        if ![-1, 0, 1].contains(&direction) {
            c.fail("direction", "must be -1, 0 or 1");
        } else if direction != sign(body.velocity) && body.velocity != 0.0 {
            c.fail("direction", "must be the velocity's sign");
        } else if direction == 0 && body.velocity != 0.0 {
            c.fail("direction", "0 means standstill: the velocity must be 0");
        }
        c.done(CommandKind::ExtSetPointGenFeed {
            position: body.position,
            velocity: body.velocity,
            acceleration: body.acceleration,
            direction,
        })
    }
}

impl TorqueControlBody {
    pub fn to_kind(&self, _: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let bounded = |x: f64, m: f64| x.is_finite() && x.abs() <= m;
        if !bounded(self.torque, 1000.0) {
            c.fail("torque", "must be from -1000 to 1000 %");
        }
        c.positive("torque_ramp", self.torque_ramp);
        let vmax = axis.params.axis_velo_max;
        for (field, v) in [
            ("velocity_limit_high", self.velocity_limit_high),
            ("velocity_limit_low", self.velocity_limit_low),
        ] {
            if !bounded(v, vmax) {
                c.fail(field, &format!("must be within ±{vmax} (AxisVeloMax)"));
            }
        }
        if self.velocity_limit_low > self.velocity_limit_high {
            c.fail("velocity_limit_low", "must not exceed velocity_limit_high");
        }
        if let Some(t) = self.manual_start_torque {
            if !bounded(t, 1000.0) {
                c.fail("manual_start_torque", "must be from -1000 to 1000 %");
            }
        }
        c.done(CommandKind::TorqueControl(motion::TorqueControl {
            torque: self.torque,
            torque_ramp: self.torque_ramp,
            relative: self.relative,
            velocity_limit_high: self.velocity_limit_high,
            velocity_limit_low: self.velocity_limit_low,
            manual_start: self.manual_start_torque,
        }))
    }
}

impl WriteDriveOperationModeBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        Ok(CommandKind::WriteDriveOperationMode {
            mode: self.drive_operation_mode,
        })
    }
}

impl SelectControlLoopBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if self.encoder_index > 9 {
            c.fail("encoder_index", "must be from 0 to 9");
        }
        c.done(CommandKind::SelectControlLoop {
            index: self.encoder_index,
        })
    }
}
