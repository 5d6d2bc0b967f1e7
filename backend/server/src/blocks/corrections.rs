//! Position corrections: MC_PositionCorrectionLimiter, MC_BacklashCompensation,
//! MC_TableBasedPositionCompensation (Enable-type: active until released).

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
            position_correction_limiter: "position-correction-limiter" at axes, PositionCorrectionLimiterBody, PositionCorrectionLimiterBody::to_kind, Operator, Active, [],
                "MC_PositionCorrectionLimiter: a correction added to the actual position and taken off the drive's setpoint, reached at once, as fast as an acceleration allows, or over a travel; active until DELETE /commands/{id}";
            backlash_compensation: "backlash-compensation" at axes, BacklashCompensationBody, BacklashCompensationBody::to_kind, Operator, Active, [],
                "MC_BacklashCompensation: apply the backlash while travelling in the compensating direction, at most at `ramp`; active until DELETE /commands/{id} (disable_mode hold or reset)";
            table_based_position_compensation: "table-based-position-compensation" at axes, TableCompensationBody, TableCompensationBody::to_kind, Operator, Active, [],
                "MC_TableBasedPositionCompensation: apply the axis's position compensation table at the set position, at most at `ramp`; active until DELETE /commands/{id}";
        }
    };
}
pub(crate) use entries;

/// MC_PositionCorrectionLimiter (§4.5.5, Enable-type): a correction added to the actual
/// position and taken off the drive's setpoint, reached as `mode` says; active until released
/// with DELETE /commands/{id} (the correction then stays where it is). A further one takes
/// over from the correction reached. Needs AxisEnablePosCorrection (#1046), else 409
/// invalid_mode. The status's `position_correction` shows it and `limiter_limiting`.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"value": 0.05, "mode": "fast", "acceleration": 1000.0}))]
pub struct PositionCorrectionLimiterBody {
    /// The correction (axis units).
    #[schema(minimum = -1e9, maximum = 1e9)]
    pub value: f64,
    /// `unlimited` (default: at once), `fast` (at most acceleration × cycle time² per cycle),
    /// `full_length` (spread over correction_length of travel).
    #[serde(default)]
    pub mode: motion::PositionCorrectionMode,
    /// fast: units/s² (0 = no limitation).
    #[serde(default)]
    #[schema(minimum = 0)]
    pub acceleration: f64,
    /// full_length: the travel a change is spread over (> 0).
    #[serde(default)]
    #[schema(minimum = 0)]
    pub correction_length: f64,
}

/// MC_BacklashCompensation (§4.5.2, appendix §7, Enable-type): the backlash is applied while
/// the axis travels in the compensating direction — negative (reference on the left flank,
/// default) or positive — changing at most `ramp` units/s; active until released with DELETE
/// /commands/{id} (`disable_mode` hold keeps the correction, reset returns it to 0 at once).
/// Needs AxisEnablePosCorrection (#1046). CurrentBacklash is the status's
/// `position_correction.backlash`.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"backlash": 0.02, "ramp": 1.0}))]
pub struct BacklashCompensationBody {
    /// Signed backlash (positive: encoder on the motor; negative: encoder with play); absent
    /// = the axis's AxisBacklash (#1036).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = -1e6, maximum = 1e6)]
    pub backlash: Option<f64>,
    /// false: compensated while travelling negative (left flank); true: while positive.
    #[serde(default)]
    pub compensate_in_positive_direction: bool,
    /// The velocity (units/s, > 0) with which the compensation is applied.
    #[schema(exclusive_minimum = 0)]
    pub ramp: f64,
    #[serde(default)]
    pub disable_mode: motion::DisableMode,
}

/// MC_TableBasedPositionCompensation (§4.5.12, Enable-type): the compensation of the axis's
/// `position_compensation_table` at the set position, changing at most `ramp` units/s; active
/// until released with DELETE /commands/{id}. Needs AxisEnablePosCorrection (#1046) and a
/// table (409 compensation_table_missing). CurrentCorrection is the status's
/// `position_correction.table`.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"ramp": 1.0}))]
pub struct TableCompensationBody {
    /// The velocity (units/s, > 0) with which the compensation is applied.
    #[schema(exclusive_minimum = 0)]
    pub ramp: f64,
    #[serde(default)]
    pub disable_mode: motion::DisableMode,
}

impl PositionCorrectionLimiterBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if !(self.value.is_finite() && self.value.abs() <= 1e9) {
            c.fail("value", "must be a number from -1e9 to 1e9");
        }
        c.non_negative("acceleration", self.acceleration);
        if self.mode == motion::PositionCorrectionMode::FullLength {
            c.positive("correction_length", self.correction_length);
        } else {
            c.non_negative("correction_length", self.correction_length);
        }
        c.done(CommandKind::PositionCorrectionLimiter {
            value: self.value,
            mode: self.mode,
            acceleration: self.acceleration,
            correction_length: self.correction_length,
        })
    }
}

impl BacklashCompensationBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if let Some(b) = self.backlash {
            if !(b.is_finite() && b.abs() <= 1e6) {
                c.fail("backlash", "must be a number from -1e6 to 1e6");
            }
        }
        c.positive("ramp", self.ramp);
        c.done(CommandKind::BacklashCompensation {
            backlash: self.backlash,
            compensate_in_positive_direction: self.compensate_in_positive_direction,
            ramp: self.ramp,
            disable_mode: self.disable_mode,
        })
    }
}

impl TableCompensationBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.positive("ramp", self.ramp);
        c.done(CommandKind::TableBasedPositionCompensation {
            ramp: self.ramp,
            disable_mode: self.disable_mode,
        })
    }
}
