//! The API's data types (DTOs) besides the blocks' bodies (those are their families',
//! `crate::blocks`). Kernel enums and structs are reused, not mirrored.

pub mod command;
pub mod demo;
pub mod group;

pub use command::*;
pub use group::*;

use std::collections::BTreeMap;

use motion::{AxisParameters, AxisState, Dynamics};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::error::FieldError;
use crate::params::{self, ParamValue};
use crate::scope::{ScopeSignal, TriggerEdge};
use drives::DriveConfig;

/// Modulo (rotary) axis: positions wrap at `period`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"period": 360.0}))]
pub struct ModuloConfig {
    /// Modulo period in axis units (#1044), e.g. 360.
    #[schema(example = 360.0)]
    #[schema(exclusive_minimum = 0)]
    pub period: f64,
}

/// Software end positions (#1016–#1019); both are enabled when present.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"min": 0.0, "max": 1000.0}))]
pub struct SoftLimits {
    #[schema(example = 0.0)]
    pub min: f64,
    #[schema(example = 1000.0)]
    pub max: f64,
}

/// Default dynamics of the axis (used when a command passes 0).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"max_velocity": 500.0, "acceleration": 2500.0, "deceleration": 2500.0, "jerk": 25000.0,
                          "jog_velocity_slow": 10.0, "jog_velocity_fast": 100.0}))]
pub struct AxisDynamics {
    /// #1003 AxisVeloMax, units/s.
    #[schema(example = 500.0)]
    #[schema(exclusive_minimum = 0)]
    pub max_velocity: f64,
    /// #1004 AxisAcc, units/s².
    #[schema(example = 2500.0)]
    #[schema(exclusive_minimum = 0)]
    pub acceleration: f64,
    /// #1005 AxisDec, units/s².
    #[schema(example = 2500.0)]
    #[schema(exclusive_minimum = 0)]
    pub deceleration: f64,
    /// #1006 AxisJerk, units/s³.
    #[schema(example = 25000.0)]
    #[schema(exclusive_minimum = 0)]
    pub jerk: f64,
    /// #1001 AxisVeloManSlow, units/s.
    #[schema(example = 10.0)]
    #[schema(exclusive_minimum = 0)]
    pub jog_velocity_slow: f64,
    /// #1002 AxisVeloManFast, units/s.
    #[schema(example = 100.0)]
    #[schema(exclusive_minimum = 0)]
    pub jog_velocity_fast: f64,
    /// The longest dead-man a jog on this axis may ask for (`deadman_timeout`), in s
    /// (0.05–10, default 1): what a client that vanishes mid-jog can cost, set by the engineer.
    #[serde(default = "default_jog_deadman_max")]
    #[schema(default = 1.0, example = 1.0, minimum = 0.05, maximum = 10.0)]
    pub jog_deadman_max: f64,
}

fn default_jog_deadman_max() -> f64 {
    1.0
}

/// The configuration of one axis (its base parameter set).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "name": "x", "unit": "mm", "soft_limits": {"min": 0.0, "max": 1000.0},
    "dynamics": {"max_velocity": 500.0, "acceleration": 2500.0, "deceleration": 2500.0, "jerk": 25000.0,
                 "jog_velocity_slow": 10.0, "jog_velocity_fast": 100.0},
    "parameters": {"AxisTargetPositionWindow": 0.01}, "drive": {}
}))]
pub struct AxisConfigDto {
    /// Unique name: a letter or `_`, then letters, digits, `_` or `-` (at most 64).
    #[schema(pattern = "^[A-Za-z_][A-Za-z0-9_-]{0,63}$")]
    pub name: String,
    /// Engineering unit of positions (mm, m, um, deg, rad, rev, in, inc).
    #[schema(pattern = "^(mm|m|um|deg|rad|rev|in|inc)$")]
    pub unit: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modulo: Option<ModuloConfig>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub soft_limits: Option<SoftLimits>,
    pub dynamics: AxisDynamics,
    /// Further base values of MC_AxisParameter entries, by name (or number).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    #[schema(value_type = BTreeMap<String, ParamValue>)]
    pub parameters: BTreeMap<String, ParamValue>,
    /// The axis's drive: `kind` (default `simulated`) and that drive's fields.
    #[serde(default)]
    pub drive: DriveConfig,
    /// The table MC_TableBasedPositionCompensation applies (§4.5.12): equidistant
    /// compensation values from min_position to max_position. Changing it re-creates the axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position_compensation_table: Option<motion::CompensationTable>,
}

pub const UNITS: &[&str] = &["mm", "m", "um", "deg", "rad", "rev", "in", "inc"];

fn finite_positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

impl AxisConfigDto {
    /// Checks everything and builds the kernel's parameter set.
    pub fn to_parameters(
        &self,
        axis_id: i64,
        cycle_time: f64,
    ) -> Result<AxisParameters, Vec<FieldError>> {
        let mut errs = Vec::new();
        let mut err = |field: &str, message: &str| {
            errs.push(FieldError {
                field: field.into(),
                message: message.into(),
            })
        };
        let n = &self.name;
        if !valid_name(n) {
            err(
                "name",
                "must start with a letter or '_' and contain only letters, digits, '_' or '-' (at most 64)",
            );
        }
        if !UNITS.contains(&self.unit.as_str()) {
            err("unit", &format!("must be one of {}", UNITS.join(", ")));
        }
        if let Some(m) = &self.modulo {
            if !finite_positive(m.period) {
                err("modulo.period", "must be a finite number > 0");
            }
        }
        if let Some(l) = &self.soft_limits {
            if !l.min.is_finite() || !l.max.is_finite() {
                err("soft_limits", "limits must be finite numbers");
            } else if l.min >= l.max {
                err("soft_limits.min", "must be below soft_limits.max");
            }
            if self.modulo.is_some() {
                err("soft_limits", "a modulo axis has no software end positions");
            }
        }
        let d = &self.dynamics;
        for (f, v) in [
            ("dynamics.max_velocity", d.max_velocity),
            ("dynamics.acceleration", d.acceleration),
            ("dynamics.deceleration", d.deceleration),
            ("dynamics.jerk", d.jerk),
            ("dynamics.jog_velocity_slow", d.jog_velocity_slow),
            ("dynamics.jog_velocity_fast", d.jog_velocity_fast),
        ] {
            if !finite_positive(v) {
                err(f, "must be a finite number > 0");
            }
        }
        if d.jog_velocity_slow > d.max_velocity {
            err("dynamics.jog_velocity_slow", "must not exceed max_velocity");
        }
        if d.jog_velocity_fast > d.max_velocity {
            err("dynamics.jog_velocity_fast", "must not exceed max_velocity");
        }
        if !(d.jog_deadman_max.is_finite() && (0.05..=10.0).contains(&d.jog_deadman_max)) {
            err("dynamics.jog_deadman_max", "must be between 0.05 and 10 s");
        }
        if let Some(t) = &self.position_compensation_table {
            if let Err((field, message)) = t.validate() {
                err(&format!("position_compensation_table.{field}"), message);
            }
        }
        if let Err(fe) = self.drive.validate() {
            for e in fe {
                errs.push(FieldError {
                    field: format!("drive.{}", e.field),
                    message: e.message,
                });
            }
        }
        let mut p = AxisParameters::default();
        params::assign_system(&mut p, axis_id, cycle_time);
        p.axis_velo_max = d.max_velocity;
        p.axis_acc = d.acceleration;
        p.axis_dec = d.deceleration;
        p.axis_jerk = d.jerk;
        p.axis_velo_man_slow = d.jog_velocity_slow;
        p.axis_velo_man_fast = d.jog_velocity_fast;
        p.axis_maximum_acceleration = p.axis_maximum_acceleration.max(d.acceleration);
        p.axis_maximum_deceleration = p.axis_maximum_deceleration.max(d.deceleration);
        p.axis_fast_dec = p.axis_fast_dec.max(d.deceleration);
        p.axis_fast_acc = p.axis_fast_acc.max(d.acceleration);
        p.axis_fast_jerk = p.axis_fast_jerk.max(d.jerk);
        // Defaults above the axis's maximum velocity would make a small axis invalid.
        for n in [1009u16, 1012, 1013] {
            if p.get(n).is_ok_and(|v| v.as_f64() > d.max_velocity) {
                p.set_raw(n, d.max_velocity);
            }
        }
        if let Some(m) = &self.modulo {
            p.axis_encoder_modulo_value = m.period;
            p.axis_modulo_tolerance_window = p.axis_modulo_tolerance_window.min(m.period / 4.0);
        }
        if let Some(l) = &self.soft_limits {
            p.axis_en_min_soft_pos_limit = true;
            p.axis_en_max_soft_pos_limit = true;
            p.axis_min_soft_pos_limit = l.min;
            p.axis_max_soft_pos_limit = l.max;
        }
        for (key, value) in &self.parameters {
            let field = format!("parameters.{key}");
            match params::lookup(key) {
                None => errs.push(FieldError {
                    field,
                    message: "unknown parameter".into(),
                }),
                Some(info) => {
                    if let Err(e) = params::set(&mut p, info.number, *value) {
                        errs.push(FieldError {
                            field,
                            message: e.text().into(),
                        });
                    }
                }
            }
        }
        if errs.is_empty() {
            if let Err(issue) = params::validate(&p) {
                let name = params::by_number(issue.number).map_or("?", |i| i.name);
                errs.push(FieldError {
                    field: format!("parameters.{name}"),
                    message: issue.message,
                });
            }
        }
        if errs.is_empty() { Ok(p) } else { Err(errs) }
    }
}

/// An axis as the API shows it.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = examples::axis_resource)]
pub struct AxisResource {
    #[schema(example = 1)]
    pub id: i64,
    /// Kernel slot (diagnostics).
    pub slot: u16,
    pub state: AxisState,
    pub config: AxisConfigDto,
    /// What a `PUT` of the configuration changed (or, with `?dry_run=true`, would change).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub change: Option<ConfigChange>,
}

/// `PUT /axes/{axis}?dry_run=true`.
#[derive(Debug, Default, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct ReplaceQuery {
    /// Only say what the save would change (`change`), and change nothing.
    #[serde(default)]
    pub dry_run: bool,
}

/// What saving a new configuration of an axis does.
#[derive(Clone, Debug, Default, Serialize, ToSchema)]
#[schema(example = json!({"dry_run": true, "rebuild": false, "rebuild_reasons": [],
    "parameters": [{"name": "AxisVeloManSlow", "number": 1001, "configured": 10.0, "online": 10.0, "new": 20.0}],
    "persistent_discarded": []}))]
pub struct ConfigChange {
    /// Nothing was changed: this is what the save would do.
    pub dry_run: bool,
    /// The axis is (or would be) re-created from the configuration: it must be disabled, and
    /// its position (0 afterwards), homed state and online values are lost; persistent values
    /// of parameters the save does not change are kept. Without a rebuild the changed
    /// parameters are written online (MC_WriteParameter) and nothing else is touched.
    pub rebuild: bool,
    /// Why a rebuild is needed (the fields that cannot change online).
    pub rebuild_reasons: Vec<String>,
    /// The parameters whose configured value changes.
    pub parameters: Vec<ParameterChange>,
    /// Persistent values given up because the save sets their parameter anew.
    pub persistent_discarded: Vec<ParameterChange>,
}

/// One parameter a configuration save changes.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"name": "AxisVeloMax", "number": 1003, "configured": 500.0, "online": 650.0, "new": 700.0}))]
pub struct ParameterChange {
    #[schema(example = "AxisVeloMax")]
    pub name: &'static str,
    #[schema(example = 1003)]
    pub number: u16,
    /// The value of the configuration before the save.
    pub configured: ParamValue,
    /// The value in force before the save (an online or persistent write may differ).
    pub online: ParamValue,
    /// The value after the save (for a discarded persistent value: the persistent value).
    pub new: ParamValue,
}

/// The whole configuration (`GET/PUT /config`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = examples::config_document)]
pub struct ConfigDocument {
    /// Format version (1).
    #[schema(example = 1)]
    #[schema(minimum = 1, maximum = 1)]
    pub version: u32,
    pub axes: Vec<ConfigAxis>,
    /// The cam tables with their ids. An import without this field leaves the stored cam
    /// tables as they are; with it (also `[]`) they are replaced.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cam_tables: Option<Vec<CamTableBody>>,
    /// The axis groups with their ids. An import without this field leaves the stored groups
    /// as they are (their members must then be among the imported axes); with it (also `[]`)
    /// they are replaced.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(max_items = 16)]
    pub groups: Option<Vec<GroupBody>>,
    /// The drive bus the machine runs on (`--bus`, `--interface`, `--bus-max-errors` at start).
    /// Exported as it runs; an import that names another bus kind is refused (start motiond
    /// with that bus first), the interface and error limit are information only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bus: Option<BusSettings>,
}

/// The drive bus of a configuration document.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"kind": "ethercat", "interface": "enp2s0", "max_errors_in_row": 3}))]
pub struct BusSettings {
    pub kind: crate::bus::BusKind,
    /// The network interface (`ethercat`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(max_length = 64)]
    pub interface: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = 1, maximum = 1000)]
    pub max_errors_in_row: Option<u32>,
}

/// One axis of the configuration document.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = examples::config_axis)]
pub struct ConfigAxis {
    #[schema(minimum = 1)]
    pub id: i64,
    pub config: AxisConfigDto,
    /// The persistent parameter overlay, by parameter name.
    #[serde(default)]
    #[schema(value_type = BTreeMap<String, ParamValue>)]
    pub persistent_parameters: BTreeMap<String, ParamValue>,
}

/// One MC_AxisParameter entry with its value on an axis.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "number": 1096, "name": "AxisCtrlVelocityPreCtrlWeight", "type": "lreal", "unit": "percent",
    "group": "controller", "read_only": false, "storage": 1096, "min": 0.0, "max": 100.0, "min_exclusive": false,
    "ads_index_offset": "0x0002000B", "help": "Weight of the velocity feed-forward in percent (100 = full feed-forward).",
    "unit_text": "%", "value": 90.0, "persistent_value": 90.0, "configured_value": 100.0
}))]
pub struct ParameterResource {
    #[serde(flatten)]
    pub info: params::ParameterInfo,
    /// The unit for this axis (e.g. `mm/s²`).
    #[schema(example = "mm/s")]
    pub unit_text: String,
    /// The value in force (online).
    pub value: ParamValue,
    /// The value of the persistent overlay, when there is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub persistent_value: Option<ParamValue>,
    /// The value of the axis's configuration (the start-up value before the persistent
    /// overlay); absent for status entries.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub configured_value: Option<ParamValue>,
}

/// `PUT /axes/{axis}/parameters/{parameter}`.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"value": 800.0, "persistent": true}))]
pub struct ParameterWrite {
    pub value: ParamValue,
    /// MC_WriteParameterPersistent: kept across restarts until the axis is replaced.
    #[serde(default)]
    pub persistent: bool,
}

/// MC_ReadDriveOperationMode (§4.5.1): the mode the drive reports (CiA-402 0x6061).
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"drive_operation_mode": "position", "code": 4, "cycle": 52000}))]
pub struct DriveOperationModeResource {
    /// `position` (CSP), `velocity` (CSV), `torque` (CST), `configured` (a drive that does
    /// not say: its configured position-based mode).
    pub drive_operation_mode: motion::DriveMode,
    /// The `E_DriveOperationMode` number (0 default, 1 torque, 2 velo1, 4 pos1).
    pub code: i32,
    pub cycle: u64,
}

/// An encoder count for MC_ConvertIncPosToPos.
#[derive(Debug, Deserialize, utoipa::IntoParams, ToSchema)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct IncPosQuery {
    /// The encoder count (UDINT, masked by AxisEncoderMask #1043).
    #[param(value_type = i64, minimum = 0, maximum = 4294967295_u64)]
    #[schema(value_type = i64, minimum = 0, maximum = 4294967295_u64)]
    pub inc_pos: u32,
}

/// A position for MC_ConvertPosToIncPos.
#[derive(Debug, Deserialize, utoipa::IntoParams, ToSchema)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct PositionQuery {
    /// Axis position (in the actual position's coordinates).
    #[param(minimum = -1e12, maximum = 1e12)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub position: f64,
}

/// MC_ConvertIncPosToPos / MC_ConvertPosToIncPos: a position and its encoder count, from the
/// status of `cycle` (the encoder count and actual position of that cycle).
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"position": 100.01, "inc_pos": 100010, "cycle": 52000,
    "encoder_count": 100000, "actual_position": 100.0, "encoder_scaling_factor": 0.001}))]
pub struct PositionConversion {
    pub position: f64,
    /// A UDINT (0 … 4294967295).
    #[schema(value_type = i64, minimum = 0, maximum = 4294967295_u64)]
    pub inc_pos: u32,
    pub cycle: u64,
    /// The count and actual position the conversion counted from.
    #[schema(value_type = i64, minimum = 0, maximum = 4294967295_u64)]
    pub encoder_count: u32,
    pub actual_position: f64,
    pub encoder_scaling_factor: f64,
}

/// MC_ReadAxisComponents (§4.2.3, ST_AxisComponents): the encoder, controller and drive of
/// an axis. motiond gives each axis one of each, numbered with the axis id.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"encoder_ids": [1], "controller_ids": [1], "drive_ids": [1],
    "encoder": {"id": 1, "kind": "drive_feedback", "scaling_factor": 1.0, "mask": 4294967295_u64},
    "controller": {"id": 1, "kind": "in_drive"},
    "drive": {"id": 1, "kind": "simulated", "subdevice": null, "operation_mode": "csp"},
    "active_control_loop": 0}))]
pub struct AxisComponents {
    /// `EncoderIDs`, `ControllerIDs`, `DriveIDs` (one each).
    pub encoder_ids: Vec<i64>,
    pub controller_ids: Vec<i64>,
    pub drive_ids: Vec<i64>,
    pub encoder: EncoderComponent,
    pub controller: ControllerComponent,
    pub drive: DriveComponent,
    /// The control loop in use (MC_SelectControlLoop's EncoderIndex; an axis has one, 0).
    pub active_control_loop: u16,
}

/// The encoder of an axis: the drive's position feedback.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"id": 1, "kind": "drive_feedback", "scaling_factor": 1.0, "mask": 4294967295_u64}))]
pub struct EncoderComponent {
    pub id: i64,
    /// `drive_feedback`: the drive's own position is the encoder.
    pub kind: String,
    /// AxisEncoderScalingFactor (#1040), units per increment.
    pub scaling_factor: f64,
    /// AxisEncoderMask (#1043).
    #[schema(value_type = i64, minimum = 0, maximum = 4294967295_u64)]
    pub mask: u32,
}

/// The position controller of an axis.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"id": 1, "kind": "in_drive"}))]
pub struct ControllerComponent {
    pub id: i64,
    /// `in_drive` (CSP, the simulated drive: the drive closes the position loop) or `motiond`
    /// (CSV, CST: motiond closes it).
    pub kind: String,
}

/// The drive of an axis.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"id": 1, "kind": "cia402", "subdevice": 0, "operation_mode": "csp"}))]
pub struct DriveComponent {
    pub id: i64,
    /// `simulated` or `cia402`.
    pub kind: String,
    /// The EtherCAT SubDevice position of a CiA-402 drive.
    pub subdevice: Option<u16>,
    /// The configured operation mode (`csp`, `csv`, `cst`).
    pub operation_mode: String,
}

/// MC_Reset, MC_GearOut, MC_AbortSuperposition (no inputs; an empty body is read as `{}`).
#[derive(Clone, Debug, Default, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({}))]
pub struct EmptyBody {}

pub fn dynamics(acceleration: f64, deceleration: f64, jerk: f64) -> Dynamics {
    Dynamics {
        acceleration,
        deceleration,
        jerk,
    }
}

/// The live status of an axis: the kernel's status plus what only the server can name.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = examples::live_status)]
pub struct LiveStatus {
    #[serde(flatten)]
    pub status: motion::AxisStatus,
    /// The master axis (name) while the axis is coupled as a gear slave.
    #[schema(example = "x")]
    pub master: Option<String>,
}

/// Examples of the OpenAPI document that are built rather than written out: the demo machine's
/// axes as `demo::axes` makes them (what a new motiond answers), and the status example
/// of `motion::AxisStatus`, which `LiveStatus` extends.
pub(crate) mod examples {
    use serde_json::{Value, json};
    use utoipa::PartialSchema;
    use utoipa::openapi::RefOr;
    use utoipa::openapi::schema::Schema;

    /// The example of a schema (null when it has none).
    fn example_of<T: PartialSchema>() -> Value {
        match T::schema() {
            RefOr::T(Schema::Object(o)) => o.example.unwrap_or_default(),
            _ => Value::Null,
        }
    }

    /// The axis `x` of the demo machine, enabled.
    pub fn axis_resource() -> Value {
        json!({"id": 1, "slot": 0, "state": "standstill", "config": crate::model::demo::axes()[0]})
    }

    /// `x` with a persistent AxisVeloMax.
    pub fn config_axis() -> Value {
        json!({"id": 1, "config": crate::model::demo::axes()[0], "persistent_parameters": {"AxisVeloMax": 400.0}})
    }

    /// The demo machine (x with a persistent AxisVeloMax).
    pub fn config_document() -> Value {
        let axes: Vec<Value> = crate::model::demo::axes()
            .into_iter()
            .enumerate()
            .map(|(i, config)| match i {
                0 => config_axis(),
                _ => json!({"id": i + 1, "config": config, "persistent_parameters": {}}),
            })
            .collect();
        json!({"version": 1, "axes": axes, "bus": {"kind": "simulated"}})
    }

    /// `x` moving (the kernel's status example), not coupled.
    pub fn live_status() -> Value {
        let mut v = example_of::<motion::AxisStatus>();
        v["master"] = Value::Null;
        v
    }
}

/// Live status of an axis.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"axis": "x", "axis_id": 1, "cycle": 2009, "unit": "mm",
                          "status": crate::model::examples::live_status()}))]
pub struct StatusResource {
    pub axis: String,
    pub axis_id: i64,
    /// The cycle the snapshot was taken in.
    pub cycle: u64,
    pub unit: String,
    pub status: LiveStatus,
}

/// When the following-error peak hold counts from.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"axis": "x", "cycle": 120345}))]
pub struct PeakResetResource {
    pub axis: String,
    /// The first cycle of the new peak hold.
    pub cycle: u64,
}

// --- Scope recording requests -------------------------------------------------------------

/// An axis by id (number or digits) or by name.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(untagged)]
pub enum AxisKey {
    Id(i64),
    Name(String),
}

impl AxisKey {
    pub fn key(&self) -> String {
        match self {
            AxisKey::Id(i) => i.to_string(),
            AxisKey::Name(s) => s.clone(),
        }
    }
}

/// One signal of one axis, or of one group (`group` instead of `axis`, with `path_position`,
/// `path_velocity`, `path_acceleration` or `entry_index`).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"axis": "x", "signal": "set_position"}))]
pub struct ChannelRequest {
    /// Axis id or name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<String>, example = "x")]
    pub axis: Option<AxisKey>,
    /// Group id or name (for a group's signal).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<String>, example = "xy")]
    pub group: Option<AxisKey>,
    #[schema(value_type = ScopeSignal)]
    pub signal: String,
}

/// Start the recording when `channels[channel]` crosses `level` in the direction of `edge`.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"channel": 0, "level": 100.0, "edge": "rising", "pre_trigger_s": 0.002}))]
pub struct TriggerRequest {
    /// Index into `channels`.
    #[schema(value_type = usize)]
    pub channel: i64,
    pub level: f64,
    /// `rising` (previous < level ≤ sample, the default), `falling` (previous > level ≥
    /// sample) or `either`.
    #[serde(default = "rising")]
    #[schema(value_type = TriggerEdge)]
    pub edge: String,
    /// History before the trigger sample (s, 0 … duration_s, default 0).
    #[serde(default)]
    #[schema(minimum = 0)]
    pub pre_trigger_s: f64,
}

fn rising() -> String {
    "rising".into()
}

/// `POST /scope/recordings`.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "channels": [{"axis": "x", "signal": "set_position"}, {"axis": "x", "signal": "set_velocity"}],
    "duration_s": 2.0,
    "trigger": {"channel": 0, "level": 100.0, "edge": "rising", "pre_trigger_s": 0.2}
}))]
pub struct RecordingRequest {
    /// 1 to 8 signals.
    #[schema(min_items = 1, max_items = 8)]
    pub channels: Vec<ChannelRequest>,
    /// Length of the recording (s): round(duration_s / cycle time) samples, at most 600 000.
    #[schema(exclusive_minimum = 0)]
    pub duration_s: f64,
    /// `null` (or absent): record from the next cycle on.
    #[serde(default)]
    pub trigger: Option<TriggerRequest>,
}

/// A name of an axis or a cam table: a letter or `_`, then letters, digits, `_` or `-` (at most
/// 64). Never all digits, so that a path segment is an id or a name, never both.
pub fn valid_name(n: &str) -> bool {
    !n.is_empty()
        && n.len() <= 64
        && n.chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && n.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// A saved scope setup (`PUT /scope/setups/{name}`): what to record and how the UI shows it.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "recording": {"channels": [{"axis": "x", "signal": "set_velocity"}, {"axis": "x", "signal": "following_error"}],
                  "duration_s": 2.0, "trigger": {"channel": 0, "level": 10.0, "edge": "rising", "pre_trigger_s": 0.2}},
    "view": {"charts": [[0], [1]], "rolling": false}
}))]
pub struct ScopeSetup {
    /// What `POST /scope/recordings` is sent when the setup is started (checked like it).
    pub recording: RecordingRequest,
    /// How the client shows it (charts, colours, rolling mode …): kept as given, at most 64 KiB.
    #[serde(default)]
    #[schema(value_type = Object)]
    pub view: serde_json::Map<String, serde_json::Value>,
}

/// A stored scope setup.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"name": "x-velocity-loop", "updated_at": "2026-11-25T15:00:00.000Z",
    "recording": {"channels": [{"axis": "x", "signal": "set_velocity"}], "duration_s": 2.0}, "view": {}}))]
pub struct ScopeSetupResource {
    pub name: String,
    pub updated_at: String,
    pub recording: RecordingRequest,
    #[schema(value_type = Object)]
    pub view: serde_json::Map<String, serde_json::Value>,
}

/// A cam table as sent: `POST /cam-tables` creates it, `PUT /cam-tables/{table}` replaces it;
/// also an entry of the configuration document. Position tables have `rows`, motion functions
/// `points`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "name": "knife", "table_type": "motion_function", "periodic": true,
    "points": [
        {"point_index": 1, "function_type": "polynom1", "point_type": "velocity", "master_pos": 0.0, "slave_pos": 0.0, "slave_velo": 1.0},
        {"point_index": 2, "function_type": "polynom5_mm", "point_type": "velocity", "master_pos": 30.0, "slave_pos": 30.0, "slave_velo": 1.0},
        {"point_index": 3, "function_type": "polynom1", "point_type": "velocity", "master_pos": 330.0, "slave_pos": 330.0, "slave_velo": 1.0},
        {"point_index": 4, "function_type": "polynom1", "point_type": "velocity", "master_pos": 360.0, "slave_pos": 360.0, "slave_velo": 1.0}
    ]
}))]
pub struct CamTableBody {
    /// MC_CAM_ID, 1..255 (`POST`: the lowest free one when left out; `PUT`: the table's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = 1, maximum = 255)]
    pub id: Option<u32>,
    /// Unique name: a letter or `_`, then letters, digits, `_` or `-` (at most 64).
    #[schema(pattern = "^[A-Za-z_][A-Za-z0-9_-]{0,63}$")]
    pub name: String,
    pub table_type: motion::cam::TableType,
    /// Repeats cyclically; the stroke (last minus first slave position) is added per cycle.
    #[serde(default)]
    pub periodic: bool,
    /// How a position table is interpolated (ignored for motion functions).
    #[serde(default)]
    pub interpolation: motion::cam::InterpolationType,
    /// Position tables: `[master, slave]` rows, masters strictly rising.
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        deserialize_with = "cam_rows"
    )]
    #[schema(schema_with = cam_rows_schema, example = json!([[0.0, 0.0], [180.0, 100.0], [360.0, 0.0]]))]
    pub rows: Vec<[f64; 2]>,
    /// Motion functions: `MC_MotionFunctionPoint`s, indices from 1 without gaps.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<motion::cam::MotionFunctionPoint>,
}

impl CamTableBody {
    pub fn data(&self) -> motion::cam::CamTableData {
        motion::cam::CamTableData {
            table_type: self.table_type,
            periodic: self.periodic,
            interpolation: self.interpolation,
            rows: self.rows.clone(),
            points: self.points.clone(),
        }
    }
}

/// A stored cam table: what it is and its range (`GET /cam-tables/{table}` adds its rows or
/// points).
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "id": 1, "name": "p5", "version": 1, "table_type": "motion_function", "periodic": false,
    "interpolation": "linear", "row_count": 2, "master_start": 0.0, "master_end": 200.0,
    "slave_start": 0.0, "slave_end": 100.0, "master_period": 200.0, "slave_stroke": 100.0,
    "updated_at": "2026-11-25T11:10:20.502Z"
}))]
pub struct CamTableResource {
    pub id: u32,
    pub name: String,
    /// Rises by 1 with every `PUT`.
    pub version: i64,
    pub table_type: motion::cam::TableType,
    pub periodic: bool,
    pub interpolation: motion::cam::InterpolationType,
    /// Number of rows or points.
    pub row_count: usize,
    /// Raw master position of the first and the last row or point.
    pub master_start: f64,
    pub master_end: f64,
    /// Raw slave position of the first and the last row or point.
    pub slave_start: f64,
    pub slave_end: f64,
    /// Raw master period (last minus first master position).
    pub master_period: f64,
    /// Raw slave stroke (last minus first slave position).
    pub slave_stroke: f64,
    pub updated_at: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<Vec<Vec<f64>>>)]
    pub rows: Option<Vec<[f64; 2]>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<motion::cam::MotionFunctionPoint>>,
}

/// MC_ReadCamTableSlaveDynamics: raw slave values at a raw master position. As in TwinCAT, a
/// motion function gives position, velocity and acceleration, an equidistant table position
/// and velocity, a non-equidistant one the position only (the others 0).
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"master_position": 50.0, "slave_position": 10.3515625,
    "slave_velocity": 0.52734375, "slave_acceleration": 0.0140625}))]
pub struct SlaveDynamicsResource {
    pub master_position: f64,
    pub slave_position: f64,
    pub slave_velocity: f64,
    pub slave_acceleration: f64,
}

/// MC_ReadCamTableMasterPosition: the nearest solutions at or below and at or above the start.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "master_low": {"valid": false, "master_axis_position": 0.0, "master_cam_position": 0.0, "slave_offset": 0.0},
    "master_high": {"valid": true, "master_axis_position": 100.0, "master_cam_position": 100.0, "slave_offset": 0.0}
}))]
pub struct MasterPositionResource {
    pub master_low: motion::cam::CamMasterData,
    pub master_high: motion::cam::CamMasterData,
}

/// What the cam editor plots while a table is edited (`POST /cam-analysis`): the table's
/// range, its values over one cycle, its characteristic values and where boundary conditions
/// are not met. Nothing is stored.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "master_start": 0.0, "master_end": 360.0, "slave_start": 0.0, "slave_end": 0.0,
    "values": {"columns": ["master", "position", "velocity", "acceleration", "jerk"],
               "rows": [[0.0, 0.0, 0.0, 0.0, 0.0], [360.0, 0.0, 0.0, 0.0, 0.0]]},
    "characteristics": {"master_velo_nom": 1.0, "master_pos_start": 0.0, "slave_pos_start": 0.0,
        "slave_velo_start": 0.0, "slave_acc_start": 0.0, "slave_jerk_start": 0.0,
        "master_pos_end": 360.0, "slave_pos_end": 0.0, "slave_velo_end": 0.0, "slave_acc_end": 0.0,
        "slave_jerk_end": 0.0, "m_pos_at_s_pos_min": 0.0, "slave_pos_min": 0.0,
        "m_pos_at_s_velo_min": 270.0, "slave_velo_min": -1.04, "m_pos_at_s_acc_min": 90.0,
        "slave_acc_min": -0.011, "s_velo_at_s_acc_min": 0.0, "m_pos_at_s_jerk_min": 45.0,
        "slave_jerk_min": -0.0002, "slave_dyn_mom_min": -0.008, "m_pos_at_s_pos_max": 180.0,
        "slave_pos_max": 100.0, "m_pos_at_s_velo_max": 90.0, "slave_velo_max": 1.04,
        "m_pos_at_s_acc_max": 0.0, "slave_acc_max": 0.011, "s_velo_at_s_acc_max": 0.0,
        "m_pos_at_s_jerk_max": 0.0, "slave_jerk_max": 0.0002, "slave_dyn_mom_max": 0.008,
        "slave_velo_mean": 0.56, "slave_acc_eff": 0.007},
    "discontinuities": [{"index": 1, "master": 180.0, "quantity": "velocity", "before": 0.0,
        "after": 1.0, "wrap": false}]
}))]
pub struct CamAnalysisResource {
    /// Raw master position of the first and the last row or point.
    pub master_start: f64,
    pub master_end: f64,
    /// Raw slave position there.
    pub slave_start: f64,
    pub slave_end: f64,
    /// `samples` rows from `master_start` to `master_end` (both included): master, position,
    /// velocity, acceleration, jerk (per raw master unit).
    pub values: CamValuesResource,
    pub characteristics: motion::cam::Characteristics,
    /// Where a law's boundary conditions are not met: the slave's position, velocity or
    /// acceleration jumps where two laws meet or where a periodic table wraps. Warnings: the
    /// table is valid and can be stored; a slave coupled through it will jump there.
    pub discontinuities: Vec<motion::cam::Discontinuity>,
}

/// MC_ReadMotionFunctionValues: one row per sample, columns as named.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"columns": ["master", "position", "velocity"], "rows": [[0.0, 0.0, 0.0], [50.0, 10.3515625, 0.52734375]]}))]
pub struct CamValuesResource {
    /// `master`, then the selected values in the order position, velocity, acceleration, jerk.
    pub columns: Vec<&'static str>,
    pub rows: Vec<Vec<f64>>,
}

/// Position-table rows: each exactly `[master, slave]`; a row of another length is a 422 at
/// `rows[i]` (serde's fixed-size arrays would call it malformed JSON).
fn cam_rows<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
    struct Row([f64; 2]);
    impl<'de> Deserialize<'de> for Row {
        fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Row, D::Error> {
            struct V;
            impl<'de> serde::de::Visitor<'de> for V {
                type Value = Row;
                fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                    f.write_str("a row [master, slave] of two numbers")
                }
                fn visit_seq<A: serde::de::SeqAccess<'de>>(
                    self,
                    mut a: A,
                ) -> Result<Row, A::Error> {
                    use serde::de::Error;
                    let wrong = |n: usize| {
                        A::Error::invalid_length(n, &"a row [master, slave] of two numbers")
                    };
                    let m: f64 = a.next_element()?.ok_or_else(|| wrong(0))?;
                    let s: f64 = a.next_element()?.ok_or_else(|| wrong(1))?;
                    let mut n = 2;
                    while a.next_element::<serde::de::IgnoredAny>()?.is_some() {
                        n += 1;
                    }
                    if n != 2 {
                        return Err(wrong(n));
                    }
                    Ok(Row([m, s]))
                }
            }
            d.deserialize_seq(V)
        }
    }
    let rows: Vec<Row> = Deserialize::deserialize(d)?;
    Ok(rows.into_iter().map(|r| r.0).collect())
}

/// The largest magnitude of a position, distance, offset or end velocity a request may give.
pub const MAX_MAGNITUDE: f64 = 1e12;
/// The smallest magnitude of a scaling or gear ratio (dividing by less would overflow).
pub const MIN_SCALING: f64 = 1e-9;

/// A scaling or gear ratio: not 0, magnitude from [`MIN_SCALING`] to [`MAX_MAGNITUDE`].
pub fn valid_scaling(v: f64) -> bool {
    v.is_finite() && (MIN_SCALING..=MAX_MAGNITUDE).contains(&v.abs())
}

/// A number other than 0 (a gear ratio's numerator, a cam scaling) of a magnitude from 1e-9
/// to 1e12: `anyOf` a positive and a negative range.
pub fn nonzero_number() -> utoipa::openapi::schema::Schema {
    use utoipa::openapi::schema::{AnyOfBuilder, ObjectBuilder, Type};
    AnyOfBuilder::new()
        .item(
            ObjectBuilder::new()
                .schema_type(Type::Number)
                .minimum(Some(MIN_SCALING))
                .maximum(Some(MAX_MAGNITUDE)),
        )
        .item(
            ObjectBuilder::new()
                .schema_type(Type::Number)
                .minimum(Some(-MAX_MAGNITUDE))
                .maximum(Some(-MIN_SCALING)),
        )
        .description(Some(
            "a number other than 0, from 1e-9 to 1e12 in magnitude",
        ))
        .into()
}

/// A position table's rows: `[master, slave]` pairs.
fn cam_rows_schema() -> utoipa::openapi::schema::Schema {
    use utoipa::openapi::schema::{ArrayBuilder, ObjectBuilder, Type};
    ArrayBuilder::new()
        .items(
            ArrayBuilder::new()
                .items(ObjectBuilder::new().schema_type(Type::Number))
                .min_items(Some(2))
                .max_items(Some(2)),
        )
        .description(Some("[master, slave] pairs, masters rising strictly"))
        .into()
}
