//! `MC_AxisParameter` (spec §6.11.8): the complete parameter list of an axis.
//!
//! * [`PARAMETERS`] describes every entry of the list in number order: PLCopen 1…17,
//!   Beckhoff 1000…1102, status 2000…2003, gear ratio 3000, NC task cycle times 4000/4001.
//!   Each [`ParameterInfo`] carries the exact TwinCAT name, the value type, unit, UI group,
//!   the validation range and a short help text.
//! * [`AxisParameters`] holds one field per *storage slot*. Entries that share an ADS index
//!   offset in TwinCAT (e.g. `SWLimitPos` #2 and `AxisMaxSoftPosLimit` #1019) are aliases of
//!   one slot: writing either changes both. Field names are the snake_case of the canonical
//!   1000-series name.
//! * Status entries (1, 10, 11, 2000–2003) have no storage; [`AxisParameters::read`] takes
//!   them from the [`AxisStatus`]. The gear ratio (3000) has a slot that only the kernel
//!   writes ([`AxisParameters::set_raw`]) and is read from the status as well.
//!
//! Decisions the manual leaves open (spec §12 item 12):
//!
//! * **Read-only for users**: the status entries, 3000 `AxisGearRatio` (a live value set by the
//!   coupling), 1000 `AxisId` and the cycle times 1050/4000/4001 (all assigned by the system,
//!   which writes them with [`AxisParameters::set_raw`]). Every other entry may be written at
//!   runtime and persistently; whether a write waits for standstill is the kernel's business.
//! * **Types**: BOOL entries take JSON `true`/`false` only, LREAL and DWORD entries a number;
//!   a DWORD must be integral. A wrong type is 0x4B05 (`COMMAND_NOT_PERMITTED`), as TwinCAT
//!   reports an unsuitable parameter type.
//! * **Ranges** (not given by the manual) are in the table: dynamics strictly positive, windows
//!   and times ≥ 0 (times in seconds), enumerated codes restricted to their known values,
//!   every number finite. Relations between entries are checked by
//!   [`AxisParameters::validate`] (see there), not by a single [`AxisParameters::set`].
//! * **Encoder scaling**: the effective factor is numerator / denominator (TwinCAT 3).
//!   Writing `AxisEncoderScalingFactor` (#1040) sets numerator = factor and denominator = 1;
//!   writing the numerator (#1055) or the denominator (#1056) recomputes the factor.
//! * **Units**: positions in axis units `u`, velocities `u/s`, accelerations `u/s²`, jerks
//!   `u/s³`, times in seconds; [`Unit::text`] renders them for a concrete axis unit.

use core::fmt;

use serde::{Deserialize, Serialize};

use crate::error::ErrorId;
use crate::status::AxisStatus;

// ---------------------------------------------------------------------------------------------
// Descriptor types
// ---------------------------------------------------------------------------------------------

/// Value type of a parameter as the manual gives it (BOOL, LREAL or DWORD).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ParamType {
    /// BOOL: written with MC_WriteBoolParameter, JSON `true`/`false`.
    #[serde(rename = "bool")]
    Bool,
    /// LREAL: a finite floating-point number.
    #[serde(rename = "lreal")]
    Real,
    /// DWORD: an integer 0…4294967295, transported as a number.
    #[serde(rename = "dword")]
    DWord,
}

/// UI group of a parameter (no meaning for the kernel).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ParamGroup {
    /// Live values taken from the axis status (read-only).
    Status,
    /// Velocity limit, default and fast-stop dynamics, override behaviour.
    Dynamics,
    /// Jog (manual motion) velocities and increments.
    Manual,
    /// Software end positions.
    Limits,
    /// Following-error, target, range and motion monitoring, error reaction.
    Monitoring,
    /// Referencing (MC_Home) parameters.
    Homing,
    /// Encoder scaling, modulo, filters, position correction.
    Encoder,
    /// Drive output scaling, limits and delays.
    Drive,
    /// Position controller.
    Controller,
    /// Gearing / slave axes.
    Coupling,
    /// Identification, cycle times and NC-internal settings.
    System,
}

impl ParamGroup {
    /// Every group in display order.
    pub const ALL: &'static [ParamGroup] = &[
        ParamGroup::Status,
        ParamGroup::Dynamics,
        ParamGroup::Manual,
        ParamGroup::Limits,
        ParamGroup::Monitoring,
        ParamGroup::Homing,
        ParamGroup::Encoder,
        ParamGroup::Drive,
        ParamGroup::Controller,
        ParamGroup::Coupling,
        ParamGroup::System,
    ];

    /// The snake_case key (as serialized).
    pub fn key(self) -> &'static str {
        match self {
            ParamGroup::Status => "status",
            ParamGroup::Dynamics => "dynamics",
            ParamGroup::Manual => "manual",
            ParamGroup::Limits => "limits",
            ParamGroup::Monitoring => "monitoring",
            ParamGroup::Homing => "homing",
            ParamGroup::Encoder => "encoder",
            ParamGroup::Drive => "drive",
            ParamGroup::Controller => "controller",
            ParamGroup::Coupling => "coupling",
            ParamGroup::System => "system",
        }
    }

    /// English heading for a UI.
    pub fn label(self) -> &'static str {
        match self {
            ParamGroup::Status => "Status",
            ParamGroup::Dynamics => "Dynamics",
            ParamGroup::Manual => "Manual motion",
            ParamGroup::Limits => "Software limits",
            ParamGroup::Monitoring => "Monitoring",
            ParamGroup::Homing => "Homing",
            ParamGroup::Encoder => "Encoder",
            ParamGroup::Drive => "Drive",
            ParamGroup::Controller => "Controller",
            ParamGroup::Coupling => "Coupling",
            ParamGroup::System => "System",
        }
    }
}

/// Physical unit of a parameter, relative to the axis unit `u` (mm, °, …).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Unit {
    /// No unit (switches).
    None,
    /// Axis units: `u`.
    Position,
    /// `u/s`.
    Velocity,
    /// `u/s²`.
    Acceleration,
    /// `u/s³`.
    Jerk,
    /// Seconds.
    Seconds,
    /// A dimensionless factor or ratio (1.0 = 100 %).
    Factor,
    /// Percent (100 = full weight).
    Percent,
    /// A gain in 1/s (velocity per position error).
    PerSecond,
    /// Axis units per encoder increment: `u/inc`.
    PositionPerIncrement,
    /// Encoder increments (masks, counter widths).
    Increments,
    /// A plain integer count (e.g. a filter order).
    Count,
    /// An identifier or an enumerated selector: integral, no unit.
    Code,
}

impl Unit {
    /// The unit text for an axis whose position unit is `axis_unit`
    /// (`Unit::Acceleration.text("mm") == "mm/s²"`); empty for unitless values.
    pub fn text(self, axis_unit: &str) -> String {
        match self {
            Unit::Position => axis_unit.to_string(),
            Unit::Velocity => format!("{axis_unit}/s"),
            Unit::Acceleration => format!("{axis_unit}/s²"),
            Unit::Jerk => format!("{axis_unit}/s³"),
            Unit::PositionPerIncrement => format!("{axis_unit}/inc"),
            other => other.generic().to_string(),
        }
    }

    /// The unit text with the placeholder `u` for the axis unit (`"u/s²"`).
    pub fn generic(self) -> &'static str {
        match self {
            Unit::None | Unit::Factor | Unit::Count | Unit::Code => "",
            Unit::Position => "u",
            Unit::Velocity => "u/s",
            Unit::Acceleration => "u/s²",
            Unit::Jerk => "u/s³",
            Unit::Seconds => "s",
            Unit::Percent => "%",
            Unit::PerSecond => "1/s",
            Unit::PositionPerIncrement => "u/inc",
            Unit::Increments => "inc",
        }
    }

    /// Values of this unit must be whole numbers.
    pub fn is_integral(self) -> bool {
        matches!(self, Unit::Count | Unit::Code | Unit::Increments)
    }
}

/// Descriptor of one `MC_AxisParameter` entry.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ParameterInfo {
    /// The `MC_AxisParameter` number (e.g. 1003).
    pub number: u16,
    /// The exact TwinCAT name (e.g. `AxisVeloMax`).
    pub name: &'static str,
    #[serde(rename = "type")]
    pub ty: ParamType,
    pub unit: Unit,
    pub group: ParamGroup,
    /// Users cannot write it (status entries, 3000, 1000, cycle times).
    pub read_only: bool,
    /// Number of the canonical entry whose field holds the value; equal to `number` for a
    /// canonical entry, another number for an alias, 0 for a status entry (no storage).
    pub storage: u16,
    /// Lowest valid value (−∞ when unbounded; serialized as `null` then). 0 for BOOL.
    #[cfg_attr(feature = "schema", schema(value_type = Option<f64>))]
    pub min: f64,
    /// Highest valid value (+∞ when unbounded; serialized as `null` then). 1 for BOOL.
    #[cfg_attr(feature = "schema", schema(value_type = Option<f64>))]
    pub max: f64,
    /// `min` itself is not valid: the value must be strictly greater (`> 0`).
    pub min_exclusive: bool,
    /// The TwinCAT ADS index offset (informative; the high word selects axis/encoder/
    /// controller/drive).
    pub ads_index_offset: &'static str,
    /// What the parameter does and when motiond uses it.
    pub help: &'static str,
}

impl ParameterInfo {
    /// A status entry: no storage, the value comes from the axis status.
    pub fn is_status(&self) -> bool {
        self.storage == 0
    }

    /// Another name for a canonical entry's storage.
    pub fn is_alias(&self) -> bool {
        self.storage != 0 && self.storage != self.number
    }

    /// The entry whose field holds this value (itself when canonical; `None` for status).
    pub fn canonical(&self) -> Option<&'static ParameterInfo> {
        if self.is_status() {
            None
        } else {
            by_number(self.storage)
        }
    }

    /// Every other entry sharing this entry's storage.
    pub fn aliases(&self) -> impl Iterator<Item = &'static ParameterInfo> + 'static {
        let (storage, number) = (self.storage, self.number);
        PARAMETERS
            .iter()
            .filter(move |p| storage != 0 && p.storage == storage && p.number != number)
    }

    /// Finite lower bound, for display (`None` when unbounded).
    pub fn min_value(&self) -> Option<f64> {
        self.min.is_finite().then_some(self.min)
    }

    /// Finite upper bound, for display (`None` when unbounded).
    pub fn max_value(&self) -> Option<f64> {
        self.max.is_finite().then_some(self.max)
    }

    /// Values must be whole numbers (DWORD, or an LREAL that carries a code or count).
    pub fn is_integral(&self) -> bool {
        self.ty == ParamType::DWord || self.unit.is_integral()
    }

    /// Checks the type and range of a value for this entry (not whether it is read-only):
    /// wrong type or a fractional DWORD → `COMMAND_NOT_PERMITTED`; NaN, ±∞ or outside the
    /// range → `PARAMETER_OUT_OF_RANGE`.
    pub fn check(&self, value: ParamValue) -> Result<(), ErrorId> {
        match (self.ty, value) {
            (ParamType::Bool, ParamValue::Bool(_)) => Ok(()),
            (ParamType::Bool, ParamValue::Number(_)) | (_, ParamValue::Bool(_)) => {
                Err(ErrorId::COMMAND_NOT_PERMITTED)
            }
            (ParamType::DWord, ParamValue::Number(x)) if x.is_finite() && x.fract() != 0.0 => {
                Err(ErrorId::COMMAND_NOT_PERMITTED)
            }
            (_, ParamValue::Number(x)) => {
                if self.in_range(x) {
                    Ok(())
                } else {
                    Err(ErrorId::PARAMETER_OUT_OF_RANGE)
                }
            }
        }
    }

    /// A number lies in this entry's range (finite, integral where required, within bounds).
    pub fn in_range(&self, x: f64) -> bool {
        let above_min = if self.min_exclusive {
            x > self.min
        } else {
            x >= self.min
        };
        x.is_finite() && above_min && x <= self.max && (!self.is_integral() || x.fract() == 0.0)
    }

    // Builders used by the table (const).
    const fn alias(self, number: u16, name: &'static str, help: &'static str) -> ParameterInfo {
        ParameterInfo {
            number,
            name,
            help,
            storage: self.number,
            ..self
        }
    }
    const fn ro(self) -> ParameterInfo {
        ParameterInfo {
            read_only: true,
            ..self
        }
    }
}

/// A parameter value: JSON `true`/`false` for BOOL entries, a number otherwise.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParamValue {
    Bool(bool),
    Number(f64),
}

impl ParamValue {
    /// The value as the kernel transports it (BOOL as 0/1).
    pub fn as_f64(self) -> f64 {
        match self {
            ParamValue::Bool(b) => {
                if b {
                    1.0
                } else {
                    0.0
                }
            }
            ParamValue::Number(x) => x,
        }
    }

    pub fn as_bool(self) -> Option<bool> {
        match self {
            ParamValue::Bool(b) => Some(b),
            ParamValue::Number(_) => None,
        }
    }

    pub fn as_number(self) -> Option<f64> {
        match self {
            ParamValue::Number(x) => Some(x),
            ParamValue::Bool(_) => None,
        }
    }
}

impl From<bool> for ParamValue {
    fn from(b: bool) -> Self {
        ParamValue::Bool(b)
    }
}

impl From<f64> for ParamValue {
    fn from(x: f64) -> Self {
        ParamValue::Number(x)
    }
}

impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamValue::Bool(b) => write!(f, "{b}"),
            ParamValue::Number(x) => write!(f, "{x}"),
        }
    }
}

/// Why a parameter set is not valid: the first entry found wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParamIssue {
    /// The entry to correct (canonical number).
    pub number: u16,
    pub error: ErrorId,
    /// English explanation naming the entries involved.
    pub message: String,
}

impl fmt::Display for ParamIssue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = by_number(self.number).map_or("?", |i| i.name);
        write!(
            f,
            "#{} {}: {} ({})",
            self.number, name, self.message, self.error
        )
    }
}

impl std::error::Error for ParamIssue {}

// ---------------------------------------------------------------------------------------------
// The table
// ---------------------------------------------------------------------------------------------

const INF: f64 = f64::INFINITY;
const DWORD_MAX: f64 = u32::MAX as f64;

#[allow(
    clippy::too_many_arguments,
    reason = "one row of the parameter table, its columns in order (a const fn: no builder)"
)]
const fn entry(
    number: u16,
    name: &'static str,
    ty: ParamType,
    unit: Unit,
    group: ParamGroup,
    min: f64,
    max: f64,
    min_exclusive: bool,
    ads_index_offset: &'static str,
    help: &'static str,
) -> ParameterInfo {
    ParameterInfo {
        number,
        name,
        ty,
        unit,
        group,
        read_only: false,
        storage: number,
        min,
        max,
        min_exclusive,
        ads_index_offset,
        help,
    }
}

/// LREAL with an inclusive range.
#[allow(
    clippy::too_many_arguments,
    reason = "one row of the parameter table, its columns in order (a const fn: no builder)"
)]
const fn real(
    n: u16,
    name: &'static str,
    unit: Unit,
    group: ParamGroup,
    min: f64,
    max: f64,
    ads: &'static str,
    help: &'static str,
) -> ParameterInfo {
    entry(
        n,
        name,
        ParamType::Real,
        unit,
        group,
        min,
        max,
        false,
        ads,
        help,
    )
}

/// LREAL strictly greater than 0.
const fn positive(
    n: u16,
    name: &'static str,
    unit: Unit,
    group: ParamGroup,
    ads: &'static str,
    help: &'static str,
) -> ParameterInfo {
    entry(
        n,
        name,
        ParamType::Real,
        unit,
        group,
        0.0,
        INF,
        true,
        ads,
        help,
    )
}

/// LREAL ≥ 0.
const fn non_negative(
    n: u16,
    name: &'static str,
    unit: Unit,
    group: ParamGroup,
    ads: &'static str,
    help: &'static str,
) -> ParameterInfo {
    real(n, name, unit, group, 0.0, INF, ads, help)
}

/// Any finite LREAL.
const fn any(
    n: u16,
    name: &'static str,
    unit: Unit,
    group: ParamGroup,
    ads: &'static str,
    help: &'static str,
) -> ParameterInfo {
    real(n, name, unit, group, -INF, INF, ads, help)
}

const fn boolean(
    n: u16,
    name: &'static str,
    group: ParamGroup,
    ads: &'static str,
    help: &'static str,
) -> ParameterInfo {
    entry(
        n,
        name,
        ParamType::Bool,
        Unit::None,
        group,
        0.0,
        1.0,
        false,
        ads,
        help,
    )
}

#[allow(
    clippy::too_many_arguments,
    reason = "one row of the parameter table, its columns in order (a const fn: no builder)"
)]
const fn dword(
    n: u16,
    name: &'static str,
    unit: Unit,
    group: ParamGroup,
    min: f64,
    max: f64,
    ads: &'static str,
    help: &'static str,
) -> ParameterInfo {
    entry(
        n,
        name,
        ParamType::DWord,
        unit,
        group,
        min,
        max,
        false,
        ads,
        help,
    )
}

/// A read-only status entry without storage.
const fn status(
    n: u16,
    name: &'static str,
    unit: Unit,
    ads: &'static str,
    help: &'static str,
) -> ParameterInfo {
    ParameterInfo {
        storage: 0,
        read_only: true,
        ..any(n, name, unit, ParamGroup::Status, ads, help)
    }
}

use ParamGroup as G;

// Canonical entries that have aliases (the aliases are derived from them).
const AXIS_VELO_MAN_SLOW: ParameterInfo = positive(
    1001,
    "AxisVeloManSlow",
    Unit::Velocity,
    G::Manual,
    "0x00000008",
    "Velocity of MC_Jog in MC_JOGMODE_STANDARD_SLOW; the jog then uses the axis default dynamics. Must not exceed AxisVeloMax.",
);
const AXIS_VELO_MAN_FAST: ParameterInfo = positive(
    1002,
    "AxisVeloManFast",
    Unit::Velocity,
    G::Manual,
    "0x00000009",
    "Velocity of MC_Jog in MC_JOGMODE_STANDARD_FAST; the jog then uses the axis default dynamics. Must not exceed AxisVeloMax.",
);
const AXIS_VELO_MAX: ParameterInfo = positive(
    1003,
    "AxisVeloMax",
    Unit::Velocity,
    G::Dynamics,
    "0x00000027",
    "Highest velocity the axis may be commanded to. Jog, homing and rapid traverse velocities must stay at or below it.",
);
const AXIS_ACC: ParameterInfo = positive(
    1004,
    "AxisAcc",
    Unit::Acceleration,
    G::Dynamics,
    "0x00000101",
    "Default acceleration: used whenever a motion command passes Acceleration = 0, and by jogs. Must not exceed AxisMaximumAcceleration.",
);
const AXIS_DEC: ParameterInfo = positive(
    1005,
    "AxisDec",
    Unit::Acceleration,
    G::Dynamics,
    "0x00000102",
    "Default deceleration: used whenever a motion command passes Deceleration = 0, and by jogs. Must not exceed AxisMaximumDeceleration.",
);
const AXIS_JERK: ParameterInfo = positive(
    1006,
    "AxisJerk",
    Unit::Jerk,
    G::Dynamics,
    "0x00000103",
    "Default jerk: used whenever a motion command passes Jerk = 0, and by jogs.",
);
const AXIS_EN_MIN_SOFT_POS_LIMIT: ParameterInfo = boolean(
    1016,
    "AxisEnMinSoftPosLimit",
    G::Limits,
    "0x0001000B",
    "Switches on the negative software end position: targets below AxisMinSoftPosLimit are refused and endless motion stops there.",
);
const AXIS_MIN_SOFT_POS_LIMIT: ParameterInfo = any(
    1017,
    "AxisMinSoftPosLimit",
    Unit::Position,
    G::Limits,
    "0x0001000D",
    "Negative software end position, effective while AxisEnMinSoftPosLimit is on. Must lie below AxisMaxSoftPosLimit when both limits are on.",
);
const AXIS_EN_MAX_SOFT_POS_LIMIT: ParameterInfo = boolean(
    1018,
    "AxisEnMaxSoftPosLimit",
    G::Limits,
    "0x0001000C",
    "Switches on the positive software end position: targets above AxisMaxSoftPosLimit are refused and endless motion stops there.",
);
const AXIS_MAX_SOFT_POS_LIMIT: ParameterInfo = any(
    1019,
    "AxisMaxSoftPosLimit",
    Unit::Position,
    G::Limits,
    "0x0001000E",
    "Positive software end position, effective while AxisEnMaxSoftPosLimit is on. Must lie above AxisMinSoftPosLimit when both limits are on.",
);
const AXIS_EN_POSITION_LAG_MONITORING: ParameterInfo = boolean(
    1020,
    "AxisEnPositionLagMonitoring",
    G::Monitoring,
    "0x00020010",
    "Switches on following-error monitoring: a lag above AxisMaxPosLagValue for longer than AxisMaxPosLagFilterTime puts the axis into ErrorStop (0x4550).",
);
const AXIS_MAX_POS_LAG_VALUE: ParameterInfo = non_negative(
    1021,
    "AxisMaxPosLagValue",
    Unit::Position,
    G::Monitoring,
    "0x00020012",
    "Largest permitted difference between set and actual position while following-error monitoring is on.",
);

/// Every `MC_AxisParameter` entry, in number order.
#[rustfmt::skip]
pub static PARAMETERS: &[ParameterInfo] = &[
    // --- PLCopen 1…17 ---
    status(1, "CommandedPosition", Unit::Position, "NcToPlc.SetPos", "The commanded (set) position of the axis. Read-only, taken from the live status."),
    AXIS_MAX_SOFT_POS_LIMIT.alias(2, "SWLimitPos", "PLCopen name of AxisMaxSoftPosLimit (#1019): the positive software end position."),
    AXIS_MIN_SOFT_POS_LIMIT.alias(3, "SWLimitNeg", "PLCopen name of AxisMinSoftPosLimit (#1017): the negative software end position."),
    AXIS_EN_MAX_SOFT_POS_LIMIT.alias(4, "EnableLimitPos", "PLCopen name of AxisEnMaxSoftPosLimit (#1018): switches the positive software end position on."),
    AXIS_EN_MIN_SOFT_POS_LIMIT.alias(5, "EnableLimitNeg", "PLCopen name of AxisEnMinSoftPosLimit (#1016): switches the negative software end position on."),
    AXIS_EN_POSITION_LAG_MONITORING.alias(6, "EnablePosLagMonitoring", "PLCopen name of AxisEnPositionLagMonitoring (#1020): switches following-error monitoring on."),
    AXIS_MAX_POS_LAG_VALUE.alias(7, "MaxPositionLag", "PLCopen name of AxisMaxPosLagValue (#1021): the largest permitted following error."),
    AXIS_VELO_MAX.alias(8, "MaxVelocitySystem", "PLCopen name of AxisVeloMax (#1003): the highest permitted axis velocity."),
    AXIS_VELO_MAX.alias(9, "MaxVelocityAppl", "PLCopen name of AxisVeloMax (#1003): the highest permitted axis velocity."),
    status(10, "ActualVelocity", Unit::Velocity, "NcToPlc.ActVelo", "The measured velocity of the axis. Read-only, taken from the live status."),
    status(11, "CommandedVelocity", Unit::Velocity, "NcToPlc.SetVelo", "The commanded (set) velocity of the axis. Read-only, taken from the live status."),
    AXIS_ACC.alias(12, "MaxAccelerationSystem", "PLCopen name mapped onto the default acceleration AxisAcc (#1004), not onto the acceleration limit (#1057)."),
    AXIS_ACC.alias(13, "MaxAccelerationAppl", "PLCopen name mapped onto the default acceleration AxisAcc (#1004), not onto the acceleration limit (#1057)."),
    AXIS_DEC.alias(14, "MaxDecelerationSystem", "PLCopen name mapped onto the default deceleration AxisDec (#1005), not onto the deceleration limit (#1058)."),
    AXIS_DEC.alias(15, "MaxDecelerationAppl", "PLCopen name mapped onto the default deceleration AxisDec (#1005), not onto the deceleration limit (#1058)."),
    AXIS_JERK.alias(16, "MaxJerkSystem", "PLCopen name mapped onto the default jerk AxisJerk (#1006)."),
    AXIS_JERK.alias(17, "MaxJerkAppl", "PLCopen name mapped onto the default jerk AxisJerk (#1006)."),
    // --- Beckhoff 1000…1102 ---
    real(1000, "AxisId", Unit::Code, G::System, 0.0, DWORD_MAX, "0x00000001", "Identifier of the axis, assigned by the system when the axis is created. Read-only for users.").ro(),
    AXIS_VELO_MAN_SLOW,
    AXIS_VELO_MAN_FAST,
    AXIS_VELO_MAX,
    AXIS_ACC,
    AXIS_DEC,
    AXIS_JERK,
    AXIS_JERK.alias(1007, "MaxJerk", "Second name of AxisJerk (#1006), the default jerk."),
    AXIS_VELO_MAX.alias(1008, "AxisMaxVelocity", "Second name of AxisVeloMax (#1003), the highest permitted axis velocity."),
    positive(1009, "AxisRapidTraverseVelocity", Unit::Velocity, G::Dynamics, "0x0000000A", "Rapid traverse velocity (the fast speed of two-speed axes, G0 of path programs). Stored for completeness; must not exceed AxisVeloMax."),
    AXIS_VELO_MAN_FAST.alias(1010, "AxisManualVelocityFast", "Second name of AxisVeloManFast (#1002), the fast jog velocity."),
    AXIS_VELO_MAN_SLOW.alias(1011, "AxisManualVelocitySlow", "Second name of AxisVeloManSlow (#1001), the slow jog velocity."),
    positive(1012, "AxisCalibrationVelocityForward", Unit::Velocity, G::Homing, "0x00000006", "Homing velocity while searching the reference cam. Must not exceed AxisVeloMax."),
    positive(1013, "AxisCalibrationVelocityBackward", Unit::Velocity, G::Homing, "0x00000007", "Homing velocity while leaving the cam towards the sync pulse (latch). Must not exceed AxisVeloMax."),
    positive(1014, "AxisJogIncrementForward", Unit::Position, G::Manual, "0x00000018", "Step width offered for inching in the positive direction (a configuration value; MC_Jog itself takes the step from its Position input)."),
    positive(1015, "AxisJogIncrementBackward", Unit::Position, G::Manual, "0x00000019", "Step width offered for inching in the negative direction (a configuration value; MC_Jog itself takes the step from its Position input)."),
    AXIS_EN_MIN_SOFT_POS_LIMIT,
    AXIS_MIN_SOFT_POS_LIMIT,
    AXIS_EN_MAX_SOFT_POS_LIMIT,
    AXIS_MAX_SOFT_POS_LIMIT,
    AXIS_EN_POSITION_LAG_MONITORING,
    AXIS_MAX_POS_LAG_VALUE,
    non_negative(1022, "AxisMaxPosLagFilterTime", Unit::Seconds, G::Monitoring, "0x00020013", "How long the following error may stay above AxisMaxPosLagValue before the axis errors; 0 errors at once."),
    boolean(1023, "AxisEnPositionRangeMonitoring", G::Monitoring, "0x0000000F", "Switches on position range monitoring (InPositionArea). With target monitoring off, positioning commands report Done once the axis is inside the range window."),
    non_negative(1024, "AxisPositionRangeWindow", Unit::Position, G::Monitoring, "0x00000010", "Half width of the window around the target in which InPositionArea is TRUE."),
    boolean(1025, "AxisEnTargetPositionMonitoring", G::Monitoring, "0x00000015", "Switches on target position monitoring (InTargetPosition): positioning commands report Done only after the axis has stayed inside the target window for the monitoring time."),
    non_negative(1026, "AxisTargetPositionWindow", Unit::Position, G::Monitoring, "0x00000016", "Half width of the window around the target that counts as 'in target'."),
    non_negative(1027, "AxisTargetPositionMonitoringTime", Unit::Seconds, G::Monitoring, "0x00000017", "How long the axis must stay inside the target window before InTargetPosition becomes TRUE."),
    boolean(1028, "AxisEnInTargetTimeout", G::Monitoring, "0x00000029", "Switches on the in-target timeout: if the target window is not reached within AxisInTargetTimeout after the end of positioning, the command fails with 0x4B07."),
    non_negative(1029, "AxisInTargetTimeout", Unit::Seconds, G::Monitoring, "0x0000002A", "Time allowed after the end of positioning for reaching the target window."),
    boolean(1030, "AxisEnMotionMonitoring", G::Monitoring, "0x00000011", "Switches on physical motion monitoring (the axis must actually move while it is commanded to)."),
    non_negative(1031, "AxisMotionMonitoringWindow", Unit::Position, G::Monitoring, "0x00000028", "Distance the axis must cover within AxisMotionMonitoringTime while motion monitoring is on."),
    non_negative(1032, "AxisMotionMonitoringTime", Unit::Seconds, G::Monitoring, "0x00000012", "Time window of the motion monitoring."),
    non_negative(1033, "AxisDelayTimeVeloPosition", Unit::Seconds, G::Controller, "0x00000104", "Dead time between velocity and position setpoint, used to align velocity feed-forward with the position loop. Stored; no effect on simulated axes."),
    boolean(1034, "AxisEnLoopingDistance", G::Dynamics, "0x00000013", "Switches on the looping distance of two-speed axes (always approach the target from one side). Stored for completeness."),
    non_negative(1035, "AxisLoopingDistance", Unit::Position, G::Dynamics, "0x00000014", "Looping distance of two-speed axes. Stored for completeness."),
    any(1036, "AxisBacklash", Unit::Position, G::Encoder, "0x0000002C", "Signed backlash of the mechanics; the value backlash compensation uses when no explicit value is given."),
    boolean(1037, "AxisEnDataPersistence", G::System, "0x00000030", "Keep the axis position across a restart (retain of position data)."),
    positive(1038, "AxisRefVeloOnRefOutput", Unit::Velocity, G::Drive, "0x00030101", "Drive scaling: the velocity reached at the reference output ratio (AxisRefVeloOutputRatio)."),
    real(1039, "AxisOverrideType", Unit::Code, G::Dynamics, 1.0, 4.0, "0x00000105", "What the velocity override refers to: 1 reduced, 2 original (legacy), 3 reduced (iterated), 4 original (iterated). 'Reduced' scales the profile's reachable peak velocity, 'original' the commanded velocity."),
    positive(1040, "AxisEncoderScalingFactor", Unit::PositionPerIncrement, G::Encoder, "0x00010006", "Axis units per encoder increment. Writing it sets the numerator to this value and the denominator to 1."),
    any(1041, "AxisEncoderOffset", Unit::Position, G::Encoder, "0x00010007", "Offset added to the scaled encoder position."),
    boolean(1042, "AxisEncoderDirectionInverse", G::Encoder, "0x00010008", "Inverts the counting direction of the encoder."),
    dword(1043, "AxisEncoderMask", Unit::Increments, G::Encoder, 0.0, DWORD_MAX, "0x00010015", "Largest encoder count before the counter wraps (counter width as a mask, 0xFFFFFFFF = 32 bit)."),
    positive(1044, "AxisEncoderModuloValue", Unit::Position, G::Encoder, "0x00010009", "Modulo period (e.g. 360): MC_MoveModulo and the modulo status positions wrap at this value."),
    non_negative(1045, "AxisModuloToleranceWindow", Unit::Position, G::Encoder, "0x0001001B", "Half width of the window around the modulo set position within which MC_MoveModulo treats the target as already reached (no extra turn). Must be below half the modulo period."),
    boolean(1046, "AxisEnablePosCorrection", G::Encoder, "0x00010016", "Allows position correction (prerequisite for backlash and table compensation and the correction limiter)."),
    non_negative(1047, "AxisPosCorrectionFilterTime", Unit::Seconds, G::Encoder, "0x00010017", "Filter time with which a position correction is applied."),
    real(1048, "AxisUnitInterpretation", Unit::Code, G::System, 0.0, DWORD_MAX, "0x00000026", "How the axis unit is interpreted for display (a code). Stored for completeness."),
    boolean(1049, "AxisMotorDirectionInverse", G::Drive, "0x00030006", "Inverts the direction of the drive output (motor turns the other way for the same setpoint)."),
    real(1050, "AxisCycleTime", Unit::Seconds, G::System, 0.0, 1.0, "0x00000004", "Cycle time of the motion kernel for this axis, set by the system. Read-only for users.").excl().ro(),
    dword(1051, "AxisFastStopSignalType", Unit::Code, G::Dynamics, 0.0, DWORD_MAX, "0x0000001E", "Selects the input signal that triggers a fast stop (0 = none). Stored for completeness."),
    positive(1052, "AxisFastAcc", Unit::Acceleration, G::Dynamics, "0x0000010A", "Acceleration of the fast (emergency) stop ramp."),
    positive(1053, "AxisFastDec", Unit::Acceleration, G::Dynamics, "0x0000010B", "Deceleration of the fast (emergency) stop ramp, for stops the axis makes on its own (axis errors, lost enables)."),
    positive(1054, "AxisFastJerk", Unit::Jerk, G::Dynamics, "0x0000010C", "Jerk of the fast (emergency) stop ramp."),
    positive(1055, "AxisEncoderScalingNumerator", Unit::PositionPerIncrement, G::Encoder, "0x00010023", "Numerator of the encoder scaling; the effective factor (#1040) is numerator / denominator."),
    positive(1056, "AxisEncoderScalingDenominator", Unit::Factor, G::Encoder, "0x00010024", "Denominator of the encoder scaling; the effective factor (#1040) is numerator / denominator."),
    positive(1057, "AxisMaximumAcceleration", Unit::Acceleration, G::Dynamics, "0x000000F1", "Upper limit for any acceleration a command may request; AxisAcc must not exceed it."),
    positive(1058, "AxisMaximumDeceleration", Unit::Acceleration, G::Dynamics, "0x000000F2", "Upper limit for any deceleration a command may request; AxisDec must not exceed it."),
    non_negative(1059, "AxisVeloJumpFactor", Unit::Factor, G::System, "0x00000106", "Permitted velocity jump at path segment transitions (NC interpolation). Stored for completeness."),
    non_negative(1060, "AxisToleranceBallAuxAxis", Unit::Position, G::System, "0x00000108", "Tolerance ball of an auxiliary axis in path interpolation. Stored for completeness."),
    non_negative(1061, "AxisMaxPositionDeviationAuxAxis", Unit::Position, G::System, "0x00000109", "Largest position deviation of an auxiliary axis in path interpolation. Stored for completeness."),
    dword(1062, "AxisErrorPropagationMode", Unit::Code, G::Monitoring, 0.0, 1.0, "0x0000001A", "Error reaction: 0 = the axis error takes effect immediately, 1 = it is delayed by AxisErrorPropagationDelay (a pre-warning meanwhile)."),
    non_negative(1063, "AxisErrorPropagationDelay", Unit::Seconds, G::Monitoring, "0x0000001B", "Delay of the error reaction when AxisErrorPropagationMode is 1."),
    boolean(1064, "AxisCoupleSlaveToActualValues", G::Coupling, "0x0000001C", "A slave follows its master's actual values instead of its set values."),
    boolean(1065, "AxisAllowMotionCmdToSlaveAxis", G::Coupling, "0x00000020", "Allows motion commands to a coupled slave: the command decouples the slave and runs (Aborting only); otherwise it is refused."),
    boolean(1066, "AxisAllowMotionCmdToExtSetAxis", G::Coupling, "0x00000021", "Allows motion commands to an axis fed by the external setpoint generator."),
    dword(1067, "AxisEncoderSubMask", Unit::Increments, G::Encoder, 0.0, DWORD_MAX, "0x00010108", "Mask of the increments within one encoder period, used to detect a software sync pulse when homing."),
    dword(1068, "AxisEncoderReferenceSystem", Unit::Code, G::Encoder, 0.0, 2.0, "0x00010019", "Encoder reference system: 0 incremental, 1 absolute, 2 absolute modulo."),
    non_negative(1069, "AxisEncoderPositionFilterPT1", Unit::Seconds, G::Encoder, "0x00010010", "PT1 filter time of the actual position (0 = unfiltered)."),
    non_negative(1070, "AxisEncoderVelocityFilterPT1", Unit::Seconds, G::Encoder, "0x00010011", "PT1 filter time of the actual velocity (0 = unfiltered)."),
    non_negative(1071, "AxisEncoderAccelerationFilterPT1", Unit::Seconds, G::Encoder, "0x00010012", "PT1 filter time of the actual acceleration (0 = unfiltered)."),
    dword(1072, "AxisEncoderMode", Unit::Code, G::Encoder, 0.0, DWORD_MAX, "0x0001000A", "Encoder evaluation mode (which actual values are derived). Stored for completeness."),
    boolean(1073, "AxisEncoderHomingInvDirCamSearch", G::Homing, "0x00010101", "Homing searches the reference cam in the negative instead of the positive direction."),
    boolean(1074, "AxisEncoderHomingInvDirSyncSearch", G::Homing, "0x00010102", "Homing searches the sync pulse moving in the opposite direction to the default (off the cam in positive direction)."),
    any(1075, "AxisEncoderHomingCalibValue", Unit::Position, G::Homing, "0x00010103", "Reference position set at the end of homing when MC_Home is given DEFAULT_HOME_POSITION (no explicit position)."),
    dword(1076, "AxisEncoderReferenceMode", Unit::Code, G::Homing, 0.0, 7.0, "0x00010107", "Signal used to find the sync point when homing (E_EncoderReferenceMode): 0 default, 1 PLC cam, 2 hardware sync, 3/4 hardware latch rising/falling, 5 software sync, 6/7 drive latch rising/falling."),
    real(1077, "AxisRefVeloOutputRatio", Unit::Factor, G::Drive, 0.0, 1.0, "0x00030102", "Drive scaling: the output ratio (1.0 = full output) at which AxisRefVeloOnRefOutput is reached.").excl(),
    positive(1078, "AxisDrivePositionOutputScaling", Unit::Factor, G::Drive, "0x00030109", "Factor applied to the position setpoint sent to the drive."),
    positive(1079, "AxisDriveVelocityOutputScaling", Unit::Factor, G::Drive, "0x00030105", "Factor applied to the velocity setpoint sent to the drive."),
    non_negative(1080, "AxisDriveVelocityOutputDelay", Unit::Seconds, G::Drive, "0x0003010D", "Delay of the velocity setpoint relative to the position setpoint at the drive output."),
    real(1081, "AxisDriveMinOutputLimitation", Unit::Factor, G::Drive, -1.0, 1.0, "0x0003000B", "Lowest drive output as a fraction of full scale (−1.0 = −100 %). Must lie below AxisDriveMaxOutputLimitation."),
    real(1082, "AxisDriveMaxOutputLimitation", Unit::Factor, G::Drive, -1.0, 1.0, "0x0003000C", "Highest drive output as a fraction of full scale (1.0 = 100 %). Must lie above AxisDriveMinOutputLimitation."),
    positive(1083, "AxisTorqueInputScaling", Unit::Factor, G::Drive, "0x00030031", "Factor applied to the actual torque read from the drive."),
    non_negative(1084, "AxisTorqueInputFilterPT1", Unit::Seconds, G::Drive, "0x00030032", "PT1 filter time of the actual torque (0 = unfiltered)."),
    non_negative(1085, "AxisTorqueDerivationInputFilterPT1", Unit::Seconds, G::Drive, "0x00030033", "PT1 filter time of the derivative of the actual torque (0 = unfiltered)."),
    positive(1086, "AxisTorqueOutputScaling", Unit::Factor, G::Drive, "0x0003010B", "Factor applied to the torque setpoint sent to the drive (torque control)."),
    non_negative(1087, "AxisTorqueOutputDelay", Unit::Seconds, G::Drive, "0x0003010F", "Delay of the torque setpoint at the drive output."),
    positive(1088, "AxisAccelerationOutputScaling", Unit::Factor, G::Drive, "0x0003010A", "Factor applied to the acceleration (feed-forward) setpoint sent to the drive."),
    non_negative(1089, "AxisAccelerationOutputDelay", Unit::Seconds, G::Drive, "0x0003010E", "Delay of the acceleration setpoint at the drive output."),
    dword(1090, "AxisDrivePosOutputSmoothFilterType", Unit::Code, G::Drive, 0.0, DWORD_MAX, "0x00030110", "Type of the smoothing filter on the position setpoint (0 = off)."),
    non_negative(1091, "AxisDrivePosOutputSmoothFilterTime", Unit::Seconds, G::Drive, "0x00030111", "Time constant of the position setpoint smoothing filter."),
    dword(1092, "AxisDrivePosOutputSmoothFilterOrder", Unit::Count, G::Drive, 0.0, DWORD_MAX, "0x00030112", "Order of the position setpoint smoothing filter."),
    dword(1093, "AxisDriveMode", Unit::Code, G::Drive, 0.0, DWORD_MAX, "0x0003000A", "Drive mode code. Stored for completeness; the operating mode of a CiA-402 drive is chosen by the drive layer."),
    real(1094, "AxisDriftCompensationOffset", Unit::Factor, G::Drive, -1.0, 1.0, "0x00030104", "Constant offset added to the drive output to compensate drift (fraction of full scale)."),
    non_negative(1095, "AxisPositionControlKv", Unit::PerSecond, G::Controller, "0x00020102", "Proportional gain Kv of the position controller (velocity per unit of following error)."),
    real(1096, "AxisCtrlVelocityPreCtrlWeight", Unit::Percent, G::Controller, 0.0, 100.0, "0x0002000B", "Weight of the velocity feed-forward in percent (100 = full feed-forward)."),
    dword(1097, "AxisControllerMode", Unit::Code, G::Controller, 0.0, DWORD_MAX, "0x0002000A", "Controller mode code. Stored for completeness."),
    boolean(1098, "AxisCtrlAutoOffset", G::Controller, "0x00020110", "Switches on automatic offset compensation of the controller output at standstill."),
    non_negative(1099, "AxisCtrlAutoOffsetTimer", Unit::Seconds, G::Controller, "0x00020115", "Time at standstill after which the automatic offset compensation acts."),
    real(1100, "AxisCtrlAutoOffsetLimit", Unit::Factor, G::Controller, 0.0, 1.0, "0x00020114", "Largest offset the automatic compensation may apply (fraction of full output)."),
    non_negative(1101, "AxisSlaveCouplingControlKcp", Unit::PerSecond, G::Controller, "0x0002010F", "Gain Kcp of the slave coupling controller that corrects a slave's position difference to its master (0 = off)."),
    real(1102, "AxisCtrlOutputLimit", Unit::Factor, G::Controller, 0.0, 1.0, "0x00020100", "Limit of the position controller output as a fraction of the reference velocity."),
    // --- status 2000…2003 (index group 0x4100 + ID) ---
    status(2000, "AxisTargetPosition", Unit::Position, "0x00000013", "Target position of the running job (the set position when none). Read-only."),
    status(2001, "AxisRemainingTimeToGo", Unit::Seconds, "0x00000014", "Time the running positioning job still needs. Read-only."),
    status(2002, "AxisRemainingDistanceToGo", Unit::Position, "0x00000022, 0x00000042", "Distance the running positioning job still has to travel. Read-only."),
    status(2003, "AxisMcSetPositionOffset", Unit::Position, "0x00n10017", "Offset accumulated by MC_SetPosition since the last homing. Read-only."),
    // --- functions 3000 ---
    any(3000, "AxisGearRatio", Unit::Factor, G::Coupling, "read 0x00000022 (IG 0x4100+ID), write 0x00000042 (IG 0x4200+ID)", "Gear ratio of a coupled slave, read from the live status. Changed only by the coupling commands (MC_GearIn, MC_GearInDyn), so read-only here.").ro(),
    // --- NC task 4000/4001 ---
    real(4000, "NcSafCycleTime", Unit::Seconds, G::System, 0.0, 1.0, "0x00000010", "Cycle time of the setpoint execution (SAF) task; in motiond the real-time cycle. Set by the system, read-only.").excl().ro(),
    real(4001, "NcSvbCycleTime", Unit::Seconds, G::System, 0.0, 1.0, "0x00000012", "Cycle time of the setpoint preparation (SVB) task; motiond has no separate SVB task and reports its real-time cycle. Set by the system, read-only.").excl().ro(),
];

impl ParameterInfo {
    const fn excl(self) -> ParameterInfo {
        ParameterInfo {
            min_exclusive: true,
            ..self
        }
    }
}

/// The entry with this number.
pub fn by_number(number: u16) -> Option<&'static ParameterInfo> {
    PARAMETERS
        .binary_search_by_key(&number, |p| p.number)
        .ok()
        .map(|i| &PARAMETERS[i])
}

/// The entry with this name (ASCII case-insensitive).
pub fn by_name(name: &str) -> Option<&'static ParameterInfo> {
    PARAMETERS
        .iter()
        .find(|p| p.name.eq_ignore_ascii_case(name))
}

/// An entry by decimal number (`"1003"`) or name (`"AxisVeloMax"`, any case).
pub fn lookup(key: &str) -> Option<&'static ParameterInfo> {
    let key = key.trim();
    match key.parse::<u16>() {
        Ok(n) => by_number(n),
        Err(_) => by_name(key),
    }
}

// ---------------------------------------------------------------------------------------------
// Storage
// ---------------------------------------------------------------------------------------------

macro_rules! storage {
    (@ty bool) => { bool };
    (@ty real) => { f64 };
    (@ty dword) => { u32 };
    (@get bool, $e:expr) => { ParamValue::Bool($e) };
    (@get real, $e:expr) => { ParamValue::Number($e) };
    (@get dword, $e:expr) => { ParamValue::Number($e as f64) };
    (@put bool, $place:expr, $v:expr) => { $place = $v != 0.0 && !$v.is_nan() };
    (@put real, $place:expr, $v:expr) => { $place = $v };
    // `as` saturates and maps NaN to 0: never panics.
    (@put dword, $place:expr, $v:expr) => { $place = $v.round() as u32 };
    ($( $(#[$doc:meta])* $num:literal $field:ident : $kind:ident = $default:expr; )*) => {
        /// Storage of one axis's parameters: one field per storage slot of `MC_AxisParameter`.
        ///
        /// Field names are the snake_case of the canonical (1000-series) Beckhoff name; aliases
        /// share a field (see [`PARAMETERS`]). The defaults describe a linear axis in mm.
        /// Write through [`AxisParameters::set`] (users) or [`AxisParameters::set_raw`] (kernel,
        /// system); a direct field write must keep [`AxisParameters::validate`] happy.
        #[derive(Clone, Debug, PartialEq)]
        pub struct AxisParameters {
            $( $(#[$doc])* pub $field: storage!(@ty $kind), )*
        }

        impl Default for AxisParameters {
            fn default() -> Self {
                AxisParameters { $( $field: $default, )* }
            }
        }

        impl AxisParameters {
            /// Value of a storage slot (canonical number), `None` when there is no such slot.
            fn slot(&self, storage: u16) -> Option<ParamValue> {
                match storage {
                    $( $num => Some(storage!(@get $kind, self.$field)), )*
                    _ => None,
                }
            }

            /// Stores a raw value into a slot without checks.
            fn put_slot(&mut self, storage: u16, v: f64) {
                match storage {
                    $( $num => { storage!(@put $kind, self.$field, v); } )*
                    _ => {}
                }
            }

            /// Canonical numbers of every storage slot, in number order.
            #[cfg(test)]
            const SLOTS: &'static [u16] = &[$( $num ),*];
        }
    };
}

storage! {
    /// #1000 AxisId: assigned by the system (read-only for users). Default 0 = not assigned.
    1000 axis_id: real = 0.0;
    /// #1001 AxisVeloManSlow ≡ #1011: slow jog velocity. Default 10 mm/s.
    1001 axis_velo_man_slow: real = 10.0;
    /// #1002 AxisVeloManFast ≡ #1010: fast jog velocity. Default 50 mm/s.
    1002 axis_velo_man_fast: real = 50.0;
    /// #1003 AxisVeloMax ≡ #8, #9, #1008: maximum velocity. Default 500 mm/s.
    1003 axis_velo_max: real = 500.0;
    /// #1004 AxisAcc ≡ #12, #13: default acceleration. Default 2500 mm/s².
    1004 axis_acc: real = 2500.0;
    /// #1005 AxisDec ≡ #14, #15: default deceleration. Default 2500 mm/s².
    1005 axis_dec: real = 2500.0;
    /// #1006 AxisJerk ≡ #16, #17, #1007: default jerk. Default 25000 mm/s³.
    1006 axis_jerk: real = 25000.0;
    /// #1009 AxisRapidTraverseVelocity. Default 500 mm/s (= AxisVeloMax).
    1009 axis_rapid_traverse_velocity: real = 500.0;
    /// #1012 AxisCalibrationVelocityForward: cam search velocity. Default 30 mm/s.
    1012 axis_calibration_velocity_forward: real = 30.0;
    /// #1013 AxisCalibrationVelocityBackward: sync search velocity. Default 5 mm/s.
    1013 axis_calibration_velocity_backward: real = 5.0;
    /// #1014 AxisJogIncrementForward. Default 1 mm.
    1014 axis_jog_increment_forward: real = 1.0;
    /// #1015 AxisJogIncrementBackward. Default 1 mm.
    1015 axis_jog_increment_backward: real = 1.0;
    /// #1016 AxisEnMinSoftPosLimit ≡ #5. Default off.
    1016 axis_en_min_soft_pos_limit: bool = false;
    /// #1017 AxisMinSoftPosLimit ≡ #3. Default 0 mm.
    1017 axis_min_soft_pos_limit: real = 0.0;
    /// #1018 AxisEnMaxSoftPosLimit ≡ #4. Default off.
    1018 axis_en_max_soft_pos_limit: bool = false;
    /// #1019 AxisMaxSoftPosLimit ≡ #2. Default 0 mm.
    1019 axis_max_soft_pos_limit: real = 0.0;
    /// #1020 AxisEnPositionLagMonitoring ≡ #6. Default on.
    1020 axis_en_position_lag_monitoring: bool = true;
    /// #1021 AxisMaxPosLagValue ≡ #7. Default 5 mm.
    1021 axis_max_pos_lag_value: real = 5.0;
    /// #1022 AxisMaxPosLagFilterTime. Default 0.02 s.
    1022 axis_max_pos_lag_filter_time: real = 0.02;
    /// #1023 AxisEnPositionRangeMonitoring. Default on.
    1023 axis_en_position_range_monitoring: bool = true;
    /// #1024 AxisPositionRangeWindow. Default 5 mm.
    1024 axis_position_range_window: real = 5.0;
    /// #1025 AxisEnTargetPositionMonitoring. Default on.
    1025 axis_en_target_position_monitoring: bool = true;
    /// #1026 AxisTargetPositionWindow. Default 0.02 mm.
    1026 axis_target_position_window: real = 0.02;
    /// #1027 AxisTargetPositionMonitoringTime. Default 0.02 s.
    1027 axis_target_position_monitoring_time: real = 0.02;
    /// #1028 AxisEnInTargetTimeout. Default on.
    1028 axis_en_in_target_timeout: bool = true;
    /// #1029 AxisInTargetTimeout. Default 5 s.
    1029 axis_in_target_timeout: real = 5.0;
    /// #1030 AxisEnMotionMonitoring. Default off.
    1030 axis_en_motion_monitoring: bool = false;
    /// #1031 AxisMotionMonitoringWindow. Default 0.1 mm.
    1031 axis_motion_monitoring_window: real = 0.1;
    /// #1032 AxisMotionMonitoringTime. Default 0.5 s.
    1032 axis_motion_monitoring_time: real = 0.5;
    /// #1033 AxisDelayTimeVeloPosition. Default 0 s.
    1033 axis_delay_time_velo_position: real = 0.0;
    /// #1034 AxisEnLoopingDistance. Default off.
    1034 axis_en_looping_distance: bool = false;
    /// #1035 AxisLoopingDistance. Default 0 mm.
    1035 axis_looping_distance: real = 0.0;
    /// #1036 AxisBacklash (signed). Default 0 mm.
    1036 axis_backlash: real = 0.0;
    /// #1037 AxisEnDataPersistence. Default off.
    1037 axis_en_data_persistence: bool = false;
    /// #1038 AxisRefVeloOnRefOutput. Default 500 mm/s.
    1038 axis_ref_velo_on_ref_output: real = 500.0;
    /// #1039 AxisOverrideType (1…4). Default 3 = reduced (iterated).
    1039 axis_override_type: real = 3.0;
    /// #1040 AxisEncoderScalingFactor; always numerator / denominator. Default 1 mm/inc
    /// (neutral: the drive layer does its own scaling unless configured).
    1040 axis_encoder_scaling_factor: real = 1.0;
    /// #1041 AxisEncoderOffset. Default 0 mm.
    1041 axis_encoder_offset: real = 0.0;
    /// #1042 AxisEncoderDirectionInverse. Default off.
    1042 axis_encoder_direction_inverse: bool = false;
    /// #1043 AxisEncoderMask. Default 0xFFFFFFFF (32-bit counter).
    1043 axis_encoder_mask: dword = u32::MAX;
    /// #1044 AxisEncoderModuloValue: modulo period. Default 360.
    1044 axis_encoder_modulo_value: real = 360.0;
    /// #1045 AxisModuloToleranceWindow. Default 1.
    1045 axis_modulo_tolerance_window: real = 1.0;
    /// #1046 AxisEnablePosCorrection. Default off.
    1046 axis_enable_pos_correction: bool = false;
    /// #1047 AxisPosCorrectionFilterTime. Default 0 s.
    1047 axis_pos_correction_filter_time: real = 0.0;
    /// #1048 AxisUnitInterpretation (code). Default 0.
    1048 axis_unit_interpretation: real = 0.0;
    /// #1049 AxisMotorDirectionInverse. Default off.
    1049 axis_motor_direction_inverse: bool = false;
    /// #1050 AxisCycleTime: set by the system (read-only for users). Default 0.001 s.
    1050 axis_cycle_time: real = 0.001;
    /// #1051 AxisFastStopSignalType. Default 0 = none.
    1051 axis_fast_stop_signal_type: dword = 0;
    /// #1052 AxisFastAcc. Default 10000 mm/s².
    1052 axis_fast_acc: real = 10000.0;
    /// #1053 AxisFastDec. Default 10000 mm/s².
    1053 axis_fast_dec: real = 10000.0;
    /// #1054 AxisFastJerk. Default 100000 mm/s³.
    1054 axis_fast_jerk: real = 100000.0;
    /// #1055 AxisEncoderScalingNumerator. Default 1.
    1055 axis_encoder_scaling_numerator: real = 1.0;
    /// #1056 AxisEncoderScalingDenominator. Default 1.
    1056 axis_encoder_scaling_denominator: real = 1.0;
    /// #1057 AxisMaximumAcceleration. Default 10000 mm/s².
    1057 axis_maximum_acceleration: real = 10000.0;
    /// #1058 AxisMaximumDeceleration. Default 10000 mm/s².
    1058 axis_maximum_deceleration: real = 10000.0;
    /// #1059 AxisVeloJumpFactor. Default 0.
    1059 axis_velo_jump_factor: real = 0.0;
    /// #1060 AxisToleranceBallAuxAxis. Default 0 mm.
    1060 axis_tolerance_ball_aux_axis: real = 0.0;
    /// #1061 AxisMaxPositionDeviationAuxAxis. Default 0 mm.
    1061 axis_max_position_deviation_aux_axis: real = 0.0;
    /// #1062 AxisErrorPropagationMode (0 immediate, 1 delayed). Default 0.
    1062 axis_error_propagation_mode: dword = 0;
    /// #1063 AxisErrorPropagationDelay. Default 0 s.
    1063 axis_error_propagation_delay: real = 0.0;
    /// #1064 AxisCoupleSlaveToActualValues. Default off.
    1064 axis_couple_slave_to_actual_values: bool = false;
    /// #1065 AxisAllowMotionCmdToSlaveAxis. Default off.
    1065 axis_allow_motion_cmd_to_slave_axis: bool = false;
    /// #1066 AxisAllowMotionCmdToExtSetAxis. Default off.
    1066 axis_allow_motion_cmd_to_ext_set_axis: bool = false;
    /// #1067 AxisEncoderSubMask. Default 0x0000FFFF.
    1067 axis_encoder_sub_mask: dword = 0x0000_FFFF;
    /// #1068 AxisEncoderReferenceSystem (0 incremental, 1 absolute, 2 absolute modulo). Default 0.
    1068 axis_encoder_reference_system: dword = 0;
    /// #1069 AxisEncoderPositionFilterPT1. Default 0 s.
    1069 axis_encoder_position_filter_pt1: real = 0.0;
    /// #1070 AxisEncoderVelocityFilterPT1. Default 0 s.
    1070 axis_encoder_velocity_filter_pt1: real = 0.0;
    /// #1071 AxisEncoderAccelerationFilterPT1. Default 0 s.
    1071 axis_encoder_acceleration_filter_pt1: real = 0.0;
    /// #1072 AxisEncoderMode (code). Default 0.
    1072 axis_encoder_mode: dword = 0;
    /// #1073 AxisEncoderHomingInvDirCamSearch. Default off.
    1073 axis_encoder_homing_inv_dir_cam_search: bool = false;
    /// #1074 AxisEncoderHomingInvDirSyncSearch. Default off.
    1074 axis_encoder_homing_inv_dir_sync_search: bool = false;
    /// #1075 AxisEncoderHomingCalibValue. Default 0 mm.
    1075 axis_encoder_homing_calib_value: real = 0.0;
    /// #1076 AxisEncoderReferenceMode (E_EncoderReferenceMode 0…7). Default 0.
    1076 axis_encoder_reference_mode: dword = 0;
    /// #1077 AxisRefVeloOutputRatio. Default 1.0.
    1077 axis_ref_velo_output_ratio: real = 1.0;
    /// #1078 AxisDrivePositionOutputScaling. Default 1.0.
    1078 axis_drive_position_output_scaling: real = 1.0;
    /// #1079 AxisDriveVelocityOutputScaling. Default 1.0.
    1079 axis_drive_velocity_output_scaling: real = 1.0;
    /// #1080 AxisDriveVelocityOutputDelay. Default 0 s.
    1080 axis_drive_velocity_output_delay: real = 0.0;
    /// #1081 AxisDriveMinOutputLimitation. Default −1.0.
    1081 axis_drive_min_output_limitation: real = -1.0;
    /// #1082 AxisDriveMaxOutputLimitation. Default 1.0.
    1082 axis_drive_max_output_limitation: real = 1.0;
    /// #1083 AxisTorqueInputScaling. Default 1.0.
    1083 axis_torque_input_scaling: real = 1.0;
    /// #1084 AxisTorqueInputFilterPT1. Default 0 s.
    1084 axis_torque_input_filter_pt1: real = 0.0;
    /// #1085 AxisTorqueDerivationInputFilterPT1. Default 0 s.
    1085 axis_torque_derivation_input_filter_pt1: real = 0.0;
    /// #1086 AxisTorqueOutputScaling. Default 1.0.
    1086 axis_torque_output_scaling: real = 1.0;
    /// #1087 AxisTorqueOutputDelay. Default 0 s.
    1087 axis_torque_output_delay: real = 0.0;
    /// #1088 AxisAccelerationOutputScaling. Default 1.0.
    1088 axis_acceleration_output_scaling: real = 1.0;
    /// #1089 AxisAccelerationOutputDelay. Default 0 s.
    1089 axis_acceleration_output_delay: real = 0.0;
    /// #1090 AxisDrivePosOutputSmoothFilterType. Default 0 = off.
    1090 axis_drive_pos_output_smooth_filter_type: dword = 0;
    /// #1091 AxisDrivePosOutputSmoothFilterTime. Default 0 s.
    1091 axis_drive_pos_output_smooth_filter_time: real = 0.0;
    /// #1092 AxisDrivePosOutputSmoothFilterOrder. Default 1.
    1092 axis_drive_pos_output_smooth_filter_order: dword = 1;
    /// #1093 AxisDriveMode (code). Default 0.
    1093 axis_drive_mode: dword = 0;
    /// #1094 AxisDriftCompensationOffset. Default 0.
    1094 axis_drift_compensation_offset: real = 0.0;
    /// #1095 AxisPositionControlKv. Default 1.0 1/s.
    1095 axis_position_control_kv: real = 1.0;
    /// #1096 AxisCtrlVelocityPreCtrlWeight. Default 100 %.
    1096 axis_ctrl_velocity_pre_ctrl_weight: real = 100.0;
    /// #1097 AxisControllerMode (code). Default 0.
    1097 axis_controller_mode: dword = 0;
    /// #1098 AxisCtrlAutoOffset. Default off.
    1098 axis_ctrl_auto_offset: bool = false;
    /// #1099 AxisCtrlAutoOffsetTimer. Default 0 s.
    1099 axis_ctrl_auto_offset_timer: real = 0.0;
    /// #1100 AxisCtrlAutoOffsetLimit. Default 0.
    1100 axis_ctrl_auto_offset_limit: real = 0.0;
    /// #1101 AxisSlaveCouplingControlKcp. Default 0 = off.
    1101 axis_slave_coupling_control_kcp: real = 0.0;
    /// #1102 AxisCtrlOutputLimit. Default 0.5.
    1102 axis_ctrl_output_limit: real = 0.5;
    /// #3000 AxisGearRatio: the live gear ratio, written only by the kernel (`set_raw`); users
    /// cannot `set` it and [`AxisParameters::read`] serves it from `AxisStatus::gear_ratio`.
    /// Default 1.0.
    3000 axis_gear_ratio: real = 1.0;
    /// #4000 NcSafCycleTime: set by the system (read-only for users). Default 0.001 s.
    4000 nc_saf_cycle_time: real = 0.001;
    /// #4001 NcSvbCycleTime: set by the system (read-only for users). Default 0.001 s.
    4001 nc_svb_cycle_time: real = 0.001;
}

const SCALING_FACTOR: u16 = 1040;
const SCALING_NUMERATOR: u16 = 1055;
const SCALING_DENOMINATOR: u16 = 1056;

impl AxisParameters {
    /// The stored value of an entry (aliases read their canonical field).
    ///
    /// Unknown numbers and status entries (1, 10, 11, 2000–2003: no storage) give
    /// `PARAMETER_UNKNOWN`; use [`AxisParameters::read`] for those.
    pub fn get(&self, number: u16) -> Result<ParamValue, ErrorId> {
        let info = by_number(number).ok_or(ErrorId::PARAMETER_UNKNOWN)?;
        self.slot(info.storage).ok_or(ErrorId::PARAMETER_UNKNOWN)
    }

    /// What MC_ReadParameter / MC_ReadBoolParameter report: the stored value, or the live
    /// value for status entries (1 set position, 10 actual velocity, 11 set velocity,
    /// 2000 target, 2001 remaining time, 2002 remaining distance, 2003 MC_SetPosition offset)
    /// and for 3000 (gear ratio). Unknown numbers give `PARAMETER_UNKNOWN`.
    pub fn read(&self, number: u16, status: &AxisStatus) -> Result<ParamValue, ErrorId> {
        let live = match number {
            1 => status.set_position,
            10 => status.actual_velocity,
            11 => status.set_velocity,
            2000 => status.target_position,
            2001 => status.remaining_time,
            2002 => status.remaining_distance,
            2003 => status.set_position_offset,
            3000 => status.gear_ratio,
            _ => return self.get(number),
        };
        Ok(ParamValue::Number(live))
    }

    /// MC_WriteParameter / MC_WriteBoolParameter: checked write of one entry.
    ///
    /// Errors: unknown number → `PARAMETER_UNKNOWN`; read-only entry → `PARAMETER_READ_ONLY`;
    /// BOOL for a number, number for a BOOL, fractional DWORD → `COMMAND_NOT_PERMITTED`
    /// (0x4B05); NaN, ±∞ or outside the entry's range → `PARAMETER_OUT_OF_RANGE`. A failed
    /// write changes nothing. Writing an alias writes the shared field. Relations to other
    /// entries are not checked here: see [`AxisParameters::validate`] and
    /// [`AxisParameters::set_consistent`].
    pub fn set(&mut self, number: u16, value: ParamValue) -> Result<(), ErrorId> {
        let info = by_number(number).ok_or(ErrorId::PARAMETER_UNKNOWN)?;
        if info.read_only {
            return Err(ErrorId::PARAMETER_READ_ONLY);
        }
        info.check(value)?;
        let x = value.as_f64();
        if let Some(factor) = self.derived_scaling_factor(info.storage, x) {
            if !self.info_of(SCALING_FACTOR).in_range(factor) {
                return Err(ErrorId::PARAMETER_OUT_OF_RANGE);
            }
        }
        self.apply(info.storage, x);
        Ok(())
    }

    /// [`AxisParameters::set`] that also keeps the whole set consistent: the write is refused
    /// (and nothing changes) when [`AxisParameters::validate`] would fail afterwards. Use it
    /// for runtime writes on a live axis; the set must have been valid before.
    pub fn set_consistent(&mut self, number: u16, value: ParamValue) -> Result<(), ParamIssue> {
        let mut next = self.clone();
        next.set(number, value).map_err(|error| ParamIssue {
            number,
            error,
            message: error.text().to_string(),
        })?;
        next.validate()?;
        *self = next;
        Ok(())
    }

    /// Unchecked write for the kernel and the system (after validation, or for read-only
    /// entries such as the cycle times and the gear ratio). BOOL entries take 0/1 (any
    /// non-zero is TRUE), DWORD entries are rounded and saturated into 0…u32::MAX.
    /// Status and unknown numbers are ignored. Never panics.
    pub fn set_raw(&mut self, number: u16, value: f64) {
        if let Some(info) = by_number(number) {
            self.apply(info.storage, value);
        }
    }

    /// Checks the whole set: every stored value in its entry's range, and
    ///
    /// * AxisMinSoftPosLimit < AxisMaxSoftPosLimit when both limits are enabled;
    /// * AxisAcc ≤ AxisMaximumAcceleration and AxisDec ≤ AxisMaximumDeceleration;
    /// * jog (manual), calibration and rapid traverse velocities ≤ AxisVeloMax;
    /// * AxisModuloToleranceWindow < AxisEncoderModuloValue / 2;
    /// * AxisDriveMinOutputLimitation < AxisDriveMaxOutputLimitation;
    /// * AxisEncoderScalingFactor = numerator / denominator.
    ///
    /// Returns the first problem found (all are `PARAMETER_OUT_OF_RANGE`).
    pub fn validate(&self) -> Result<(), ParamIssue> {
        match self.problem() {
            None => Ok(()),
            Some(Problem::Range(info, value)) => Err(issue(
                info.number,
                format!(
                    "{} = {} is outside its range {}",
                    info.name,
                    value,
                    range_text(info)
                ),
            )),
            Some(Problem::AboveVeloMax(number)) => {
                let name = self.info_of(number).name;
                Err(issue(number, format!("{name} must not exceed AxisVeloMax")))
            }
            Some(Problem::Relation(number, message)) => Err(issue(number, message.into())),
        }
    }

    /// The first problem [`AxisParameters::validate`] reports, found without allocating (the
    /// kernel checks writes in the cycle thread).
    fn problem(&self) -> Option<Problem> {
        for info in PARAMETERS.iter().filter(|p| p.storage == p.number) {
            let Some(value) = self.slot(info.number) else {
                continue;
            };
            if info.check(value).is_err() {
                return Some(Problem::Range(info, value));
            }
        }
        if self.axis_en_min_soft_pos_limit
            && self.axis_en_max_soft_pos_limit
            && self.axis_min_soft_pos_limit >= self.axis_max_soft_pos_limit
        {
            return Some(Problem::Relation(
                1017,
                "AxisMinSoftPosLimit must be below AxisMaxSoftPosLimit while both limits are enabled",
            ));
        }
        if self.axis_acc > self.axis_maximum_acceleration {
            return Some(Problem::Relation(
                1004,
                "AxisAcc must not exceed AxisMaximumAcceleration",
            ));
        }
        if self.axis_dec > self.axis_maximum_deceleration {
            return Some(Problem::Relation(
                1005,
                "AxisDec must not exceed AxisMaximumDeceleration",
            ));
        }
        for (number, v) in [
            (1001, self.axis_velo_man_slow),
            (1002, self.axis_velo_man_fast),
            (1009, self.axis_rapid_traverse_velocity),
            (1012, self.axis_calibration_velocity_forward),
            (1013, self.axis_calibration_velocity_backward),
        ] {
            if v > self.axis_velo_max {
                return Some(Problem::AboveVeloMax(number));
            }
        }
        if self.axis_modulo_tolerance_window >= self.axis_encoder_modulo_value / 2.0 {
            return Some(Problem::Relation(
                1045,
                "AxisModuloToleranceWindow must be below half of AxisEncoderModuloValue",
            ));
        }
        if self.axis_drive_min_output_limitation >= self.axis_drive_max_output_limitation {
            return Some(Problem::Relation(
                1081,
                "AxisDriveMinOutputLimitation must be below AxisDriveMaxOutputLimitation",
            ));
        }
        if self.axis_encoder_scaling_factor
            != self.axis_encoder_scaling_numerator / self.axis_encoder_scaling_denominator
        {
            return Some(Problem::Relation(
                1040,
                "AxisEncoderScalingFactor must equal AxisEncoderScalingNumerator / AxisEncoderScalingDenominator",
            ));
        }
        None
    }

    /// MC_WriteParameter / MC_WriteBoolParameter as the kernel receives them: the value as a
    /// number, a BOOL as 0 or 1. The kernel checks every write itself (whoever submits it)
    /// with the same table as [`AxisParameters::set`]: unknown number → `PARAMETER_UNKNOWN`;
    /// read-only entry (status entries, 1000, 1050, 3000, 4000, 4001) → `PARAMETER_READ_ONLY`;
    /// a BOOL other than 0/1, NaN, ±∞ or a value outside the range → `PARAMETER_OUT_OF_RANGE`;
    /// a fractional DWORD → `COMMAND_NOT_PERMITTED`. A set that was consistent must stay so
    /// ([`AxisParameters::validate`]; else `PARAMETER_OUT_OF_RANGE`). A refused write changes
    /// nothing. Allocates nothing.
    pub fn write(&mut self, number: u16, value: f64) -> Result<(), ErrorId> {
        let info = by_number(number).ok_or(ErrorId::PARAMETER_UNKNOWN)?;
        if info.read_only {
            return Err(ErrorId::PARAMETER_READ_ONLY);
        }
        let value = match info.ty {
            ParamType::Bool if value == 0.0 => ParamValue::Bool(false),
            ParamType::Bool if value == 1.0 => ParamValue::Bool(true),
            ParamType::Bool => return Err(ErrorId::PARAMETER_OUT_OF_RANGE),
            _ => ParamValue::Number(value),
        };
        let mut next = self.clone();
        next.set(number, value)?;
        if next.problem().is_some() && self.problem().is_none() {
            return Err(ErrorId::PARAMETER_OUT_OF_RANGE);
        }
        *self = next;
        Ok(())
    }

    /// Every storage entry (canonical entries, including the read-only 1000, 1050, 3000,
    /// 4000, 4001) with its stored value, in number order. Aliases and status entries are
    /// left out.
    pub fn entries(&self) -> impl Iterator<Item = (&'static ParameterInfo, ParamValue)> + '_ {
        PARAMETERS
            .iter()
            .filter(|p| p.storage == p.number)
            .filter_map(move |p| self.slot(p.number).map(|v| (p, v)))
    }

    fn info_of(&self, number: u16) -> &'static ParameterInfo {
        // Only called with numbers from this module's table.
        by_number(number).unwrap_or(&PARAMETERS[0])
    }

    /// The scaling factor that writing `x` into slot `storage` implies, if it is a scaling
    /// numerator or denominator.
    fn derived_scaling_factor(&self, storage: u16, x: f64) -> Option<f64> {
        match storage {
            SCALING_NUMERATOR => Some(x / self.axis_encoder_scaling_denominator),
            SCALING_DENOMINATOR => Some(self.axis_encoder_scaling_numerator / x),
            _ => None,
        }
    }

    /// Stores `x` into a slot, keeping the encoder scaling triple coupled.
    fn apply(&mut self, storage: u16, x: f64) {
        match storage {
            SCALING_FACTOR => {
                self.axis_encoder_scaling_factor = x;
                self.axis_encoder_scaling_numerator = x;
                self.axis_encoder_scaling_denominator = 1.0;
            }
            SCALING_NUMERATOR | SCALING_DENOMINATOR => {
                self.put_slot(storage, x);
                self.axis_encoder_scaling_factor =
                    self.axis_encoder_scaling_numerator / self.axis_encoder_scaling_denominator;
            }
            _ => self.put_slot(storage, x),
        }
    }
}

/// What [`AxisParameters::validate`] found wrong first.
#[derive(Clone, Copy, Debug)]
enum Problem {
    /// A stored value outside its entry's range.
    Range(&'static ParameterInfo, ParamValue),
    /// A velocity (its number) above AxisVeloMax.
    AboveVeloMax(u16),
    /// Another relation between entries: the entry to correct and why.
    Relation(u16, &'static str),
}

fn issue(number: u16, message: String) -> ParamIssue {
    ParamIssue {
        number,
        error: ErrorId::PARAMETER_OUT_OF_RANGE,
        message,
    }
}

fn range_text(info: &ParameterInfo) -> String {
    let lo = if info.min.is_finite() {
        format!(
            "{}{}",
            if info.min_exclusive { "> " } else { "≥ " },
            info.min
        )
    } else {
        String::new()
    };
    let hi = if info.max.is_finite() {
        format!("≤ {}", info.max)
    } else {
        String::new()
    };
    let integral = if info.is_integral() { ", integral" } else { "" };
    match (lo.is_empty(), hi.is_empty()) {
        (true, true) => format!("(finite{integral})"),
        (false, true) => format!("({lo}{integral})"),
        (true, false) => format!("({hi}{integral})"),
        (false, false) => format!("({lo}, {hi}{integral})"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_storage_entry_has_a_field_of_its_type() {
        for info in PARAMETERS {
            if info.is_status() {
                assert!(
                    AxisParameters::default().slot(info.number).is_none(),
                    "{} has storage",
                    info.name
                );
                continue;
            }
            let v = AxisParameters::default()
                .slot(info.storage)
                .unwrap_or_else(|| panic!("{} has no field", info.name));
            assert_eq!(
                matches!(v, ParamValue::Bool(_)),
                info.ty == ParamType::Bool,
                "{}",
                info.name
            );
        }
        let canonical: Vec<u16> = PARAMETERS
            .iter()
            .filter(|p| p.storage == p.number)
            .map(|p| p.number)
            .collect();
        assert_eq!(canonical, AxisParameters::SLOTS);
    }

    #[test]
    fn aliases_point_at_canonical_entries_with_the_same_shape() {
        for info in PARAMETERS.iter().filter(|p| p.is_alias()) {
            let c = info.canonical().unwrap();
            assert_eq!(c.storage, c.number, "{} points at an alias", info.name);
            assert_eq!(
                (c.ty, c.unit, c.group, c.read_only, c.ads_index_offset),
                (
                    info.ty,
                    info.unit,
                    info.group,
                    info.read_only,
                    info.ads_index_offset
                )
            );
            assert_eq!(
                (c.min.to_bits(), c.max.to_bits(), c.min_exclusive),
                (info.min.to_bits(), info.max.to_bits(), info.min_exclusive)
            );
        }
    }

    #[test]
    fn set_raw_never_panics_on_garbage() {
        let mut p = AxisParameters::default();
        for info in PARAMETERS {
            for x in [
                f64::NAN,
                f64::INFINITY,
                f64::NEG_INFINITY,
                -1.0,
                1e300,
                -0.0,
                0.5,
            ] {
                p.set_raw(info.number, x);
            }
        }
        p.set_raw(0, 1.0);
        p.set_raw(65535, 1.0);
        assert_eq!(p.axis_encoder_mask, 1); // the last write, 0.5, rounds to 1
        p.set_raw(1043, f64::NAN);
        assert_eq!(p.axis_encoder_mask, 0);
        p.set_raw(1043, 1e300);
        assert_eq!(p.axis_encoder_mask, u32::MAX);
        p.set_raw(1020, f64::NAN);
        assert!(!p.axis_en_position_lag_monitoring);
    }
}
