//! Adapter to the MC_AxisParameter table of `backend/motion`.
//!
//! STAND-IN until `motion::params` has the full table (`PARAMETERS`, `ParameterInfo`,
//! `ParamValue`, `lookup`, `AxisParameters::{get, read, set, validate}`): the functions here
//! have the signatures of that API and cover the parameters of the seed `AxisParameters`, so
//! the switch is replacing this module's body by re-exports and method calls.

use motion::{AxisParameters, AxisStatus, ErrorId};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// Value of a parameter: a number (LREAL, DWORD …) or a boolean.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(untagged)]
pub enum ParamValue {
    Bool(bool),
    Number(f64),
}

impl ParamValue {
    pub fn as_f64(self) -> f64 {
        match self {
            ParamValue::Bool(b) => b as u8 as f64,
            ParamValue::Number(n) => n,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum ParamType {
    Bool,
    Lreal,
    Dword,
}

/// Descriptor of one MC_AxisParameter entry.
#[derive(Clone, Copy, Debug)]
pub struct ParameterInfo {
    pub number: u16,
    pub name: &'static str,
    pub ty: ParamType,
    pub unit: &'static str,
    pub group: &'static str,
    pub read_only: bool,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub help: &'static str,
}

/// A configuration that fails validation.
#[derive(Clone, Debug)]
pub struct ParamIssue {
    pub number: u16,
    pub error: ErrorId,
    pub message: String,
}

macro_rules! table {
    ($( $num:literal $name:literal $ty:ident $unit:literal $group:literal $ro:literal $min:expr, $max:expr, $help:literal; )*) => {
        pub static PARAMETERS: &[ParameterInfo] = &[ $( ParameterInfo {
            number: $num, name: $name, ty: ParamType::$ty, unit: $unit, group: $group,
            read_only: $ro, min: $min, max: $max, help: $help,
        }, )* ];
    };
}

const P: Option<f64> = Some(0.0);
const N: Option<f64> = None;

table! {
    1 "CommandedPosition" Lreal "u" "status" true N, N, "commanded (set) position";
    10 "ActualVelocity" Lreal "u/s" "status" true N, N, "actual velocity";
    11 "CommandedVelocity" Lreal "u/s" "status" true N, N, "commanded velocity";
    1000 "AxisId" Lreal "" "axis" true N, N, "axis id";
    1001 "AxisVeloManSlow" Lreal "u/s" "axis" false P, N, "manual (jog) velocity slow";
    1002 "AxisVeloManFast" Lreal "u/s" "axis" false P, N, "manual (jog) velocity fast";
    1003 "AxisVeloMax" Lreal "u/s" "axis" false P, N, "maximum permitted axis velocity";
    1004 "AxisAcc" Lreal "u/s²" "axis" false P, N, "default acceleration";
    1005 "AxisDec" Lreal "u/s²" "axis" false P, N, "default deceleration";
    1006 "AxisJerk" Lreal "u/s³" "axis" false P, N, "default jerk";
    1012 "AxisCalibrationVelocityForward" Lreal "u/s" "axis" false P, N, "homing: velocity towards the cam";
    1013 "AxisCalibrationVelocityBackward" Lreal "u/s" "axis" false P, N, "homing: velocity off the cam";
    1014 "AxisJogIncrementForward" Lreal "u" "axis" false P, N, "jog increment forward";
    1015 "AxisJogIncrementBackward" Lreal "u" "axis" false P, N, "jog increment backward";
    1016 "AxisEnMinSoftPosLimit" Bool "" "encoder" false N, N, "enable minimum software end position";
    1017 "AxisMinSoftPosLimit" Lreal "u" "encoder" false N, N, "minimum software end position";
    1018 "AxisEnMaxSoftPosLimit" Bool "" "encoder" false N, N, "enable maximum software end position";
    1019 "AxisMaxSoftPosLimit" Lreal "u" "encoder" false N, N, "maximum software end position";
    1020 "AxisEnPositionLagMonitoring" Bool "" "controller" false N, N, "enable following-error monitoring";
    1021 "AxisMaxPosLagValue" Lreal "u" "controller" false P, N, "maximum following error";
    1022 "AxisMaxPosLagFilterTime" Lreal "s" "controller" false P, N, "following-error filter time";
    1023 "AxisEnPositionRangeMonitoring" Bool "" "axis" false N, N, "enable position range monitoring";
    1024 "AxisPositionRangeWindow" Lreal "u" "axis" false P, N, "position range window";
    1025 "AxisEnTargetPositionMonitoring" Bool "" "axis" false N, N, "enable target position monitoring";
    1026 "AxisTargetPositionWindow" Lreal "u" "axis" false P, N, "target position window";
    1027 "AxisTargetPositionMonitoringTime" Lreal "s" "axis" false P, N, "dwell time in the target window";
    1028 "AxisEnInTargetTimeout" Bool "" "axis" false N, N, "enable in-target timeout";
    1029 "AxisInTargetTimeout" Lreal "s" "axis" false P, N, "in-target timeout";
    1044 "AxisEncoderModuloValue" Lreal "u" "encoder" false P, N, "modulo period";
    1045 "AxisModuloToleranceWindow" Lreal "u" "encoder" false P, N, "modulo tolerance window";
    1050 "AxisCycleTime" Lreal "s" "axis" true N, N, "axis cycle time";
    1052 "AxisFastAcc" Lreal "u/s²" "axis" false P, N, "fast-stop acceleration";
    1053 "AxisFastDec" Lreal "u/s²" "axis" false P, N, "fast-stop deceleration";
    1054 "AxisFastJerk" Lreal "u/s³" "axis" false P, N, "fast-stop jerk";
    1057 "AxisMaximumAcceleration" Lreal "u/s²" "axis" false P, N, "maximum acceleration";
    1058 "AxisMaximumDeceleration" Lreal "u/s²" "axis" false P, N, "maximum deceleration";
    1064 "AxisCoupleSlaveToActualValues" Bool "" "axis" false N, N, "couple slave to master actual values";
    1065 "AxisAllowMotionCmdToSlaveAxis" Bool "" "axis" false N, N, "allow motion commands to a coupled slave";
}

pub fn by_number(number: u16) -> Option<&'static ParameterInfo> {
    PARAMETERS.iter().find(|p| p.number == number)
}

pub fn by_name(name: &str) -> Option<&'static ParameterInfo> {
    PARAMETERS
        .iter()
        .find(|p| p.name.eq_ignore_ascii_case(name))
}

/// A parameter by number ("1003") or name ("AxisVeloMax").
pub fn lookup(key: &str) -> Option<&'static ParameterInfo> {
    match key.parse::<u16>() {
        Ok(n) => by_number(n),
        Err(_) => by_name(key),
    }
}

macro_rules! fields {
    ($p:ident, $n:ident, $v:ident; num: $($nn:literal => $nf:ident),*; bool: $($bn:literal => $bf:ident),*) => {
        match ($n, $v) {
            $( ($nn, Access::Get) => Ok(ParamValue::Number($p.$nf)), )*
            $( ($bn, Access::Get) => Ok(ParamValue::Bool($p.$bf)), )*
            $( ($nn, Access::Set(ParamValue::Number(x))) => { $p.$nf = x; Ok(ParamValue::Number(x)) } )*
            $( ($bn, Access::Set(ParamValue::Bool(x))) => { $p.$bf = x; Ok(ParamValue::Bool(x)) } )*
            $( ($bn, Access::Set(ParamValue::Number(x))) if x == 0.0 || x == 1.0 => { $p.$bf = x == 1.0; Ok(ParamValue::Bool(x == 1.0)) } )*
            (_, Access::Set(_)) if by_number($n).is_some() => Err(ErrorId::COMMAND_NOT_PERMITTED),
            _ => Err(ErrorId::PARAMETER_UNKNOWN),
        }
    };
}

enum Access {
    Get,
    Set(ParamValue),
}

fn access(p: &mut AxisParameters, number: u16, a: Access) -> Result<ParamValue, ErrorId> {
    fields!(p, number, a;
        num: 1000 => axis_id, 1001 => axis_velo_man_slow, 1002 => axis_velo_man_fast, 1003 => axis_velo_max,
            1004 => axis_acc, 1005 => axis_dec, 1006 => axis_jerk, 1012 => axis_calibration_velocity_forward,
            1013 => axis_calibration_velocity_backward, 1014 => axis_jog_increment_forward,
            1015 => axis_jog_increment_backward, 1017 => axis_min_soft_pos_limit, 1019 => axis_max_soft_pos_limit,
            1021 => axis_max_pos_lag_value, 1022 => axis_max_pos_lag_filter_time, 1024 => axis_position_range_window,
            1026 => axis_target_position_window, 1027 => axis_target_position_monitoring_time,
            1029 => axis_in_target_timeout, 1044 => axis_encoder_modulo_value, 1045 => axis_modulo_tolerance_window,
            1050 => axis_cycle_time, 1052 => axis_fast_acc, 1053 => axis_fast_dec, 1054 => axis_fast_jerk,
            1057 => axis_maximum_acceleration, 1058 => axis_maximum_deceleration;
        bool: 1016 => axis_en_min_soft_pos_limit, 1018 => axis_en_max_soft_pos_limit,
            1020 => axis_en_position_lag_monitoring, 1023 => axis_en_position_range_monitoring,
            1025 => axis_en_target_position_monitoring, 1028 => axis_en_in_target_timeout,
            1064 => axis_couple_slave_to_actual_values, 1065 => axis_allow_motion_cmd_to_slave_axis)
}

/// `AxisParameters::get`: the stored value (status entries are not stored: see [`read`]).
pub fn get(p: &AxisParameters, number: u16) -> Result<ParamValue, ErrorId> {
    access(&mut p.clone(), number, Access::Get)
}

/// `AxisParameters::read`: stored value or, for read-only status entries, the live value.
pub fn read(p: &AxisParameters, number: u16, status: &AxisStatus) -> Result<ParamValue, ErrorId> {
    match number {
        1 => Ok(ParamValue::Number(status.set_position)),
        10 => Ok(ParamValue::Number(status.actual_velocity)),
        11 => Ok(ParamValue::Number(status.set_velocity)),
        _ => get(p, number),
    }
}

/// `AxisParameters::set`: type and range checked write of a writable parameter.
pub fn set(p: &mut AxisParameters, number: u16, value: ParamValue) -> Result<(), ErrorId> {
    let info = by_number(number).ok_or(ErrorId::PARAMETER_UNKNOWN)?;
    if info.read_only {
        return Err(ErrorId::PARAMETER_READ_ONLY);
    }
    if let ParamValue::Number(x) = value {
        if !x.is_finite() || info.min.is_some_and(|m| x < m) || info.max.is_some_and(|m| x > m) {
            return Err(ErrorId::PARAMETER_OUT_OF_RANGE);
        }
    }
    access(p, number, Access::Set(value)).map(|_| ())
}

/// Writes a value the kernel reported (bools as 0/1), bypassing checks.
pub fn set_raw(p: &mut AxisParameters, number: u16, value: f64) {
    let v = match by_number(number).map(|i| i.ty) {
        Some(ParamType::Bool) => ParamValue::Bool(value != 0.0),
        _ => ParamValue::Number(value),
    };
    let _ = access(p, number, Access::Set(v));
}

/// `AxisParameters::validate`: consistency of the whole set.
pub fn validate(p: &AxisParameters) -> Result<(), ParamIssue> {
    let issue = |number, message: &str| {
        Err(ParamIssue {
            number,
            error: ErrorId::PARAMETER_OUT_OF_RANGE,
            message: message.into(),
        })
    };
    if !(p.axis_velo_max > 0.0) {
        return issue(1003, "AxisVeloMax must be > 0");
    }
    for (n, v) in [(1004, p.axis_acc), (1005, p.axis_dec), (1006, p.axis_jerk)] {
        if !(v > 0.0) || !v.is_finite() {
            return issue(n, "default dynamics must be > 0");
        }
    }
    if p.axis_velo_man_slow > p.axis_velo_max || p.axis_velo_man_fast > p.axis_velo_max {
        return issue(1002, "manual velocities must not exceed AxisVeloMax");
    }
    if p.axis_en_min_soft_pos_limit
        && p.axis_en_max_soft_pos_limit
        && p.axis_min_soft_pos_limit >= p.axis_max_soft_pos_limit
    {
        return issue(
            1017,
            "AxisMinSoftPosLimit must be below AxisMaxSoftPosLimit",
        );
    }
    if !(p.axis_encoder_modulo_value > 0.0) {
        return issue(1044, "modulo period must be > 0");
    }
    Ok(())
}
