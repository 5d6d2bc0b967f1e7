//! Cam couplings (TwinCAT NC Camming): MC_CamIn, MC_CamOut, the multi-cam blocks (MC_CamIn_V2,
//! MC_CamAdd, MC_CamExchange, MC_CamRemove, MC_CamScaling_V2) and MC_CamScaling.

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
            cam_in: "cam-in" at axes, CamInBody, CamInBody::to_kind, Operator, InSync, [],
                "MC_CamIn: couple to a master through a cam table, or switch the cam of a coupled slave (active while it waits for its activation; wait returns at in_sync; 409 cam_slave_would_jump unless the slave stands where the cam puts it)";
            cam_out: "cam-out" at axes, EmptyBody, |_, _, _| Ok(CommandKind::CamOut), Operator, Done, [],
                "MC_CamOut: decouple a cam slave; it keeps its velocity";
            cam_in_v2: "cam-in-v2" at axes, CamInV2Body, CamInV2Body::to_kind, Operator, InSync, [],
                "MC_CamIn_V2: multi-cam — couple with one cam, then add, exchange or remove superimposed cams (operation); not with cam-in on one slave";
            cam_add: "cam-add" at axes, CamAddBody, CamAddBody::to_kind, Operator, InSync, [],
                "MC_CamAdd: superimpose a cam on a multi-cam slave (relative slave: its share starts from 0)";
            cam_exchange: "cam-exchange" at axes, CamExchangeBody, CamExchangeBody::to_kind, Operator, InSync, [],
                "MC_CamExchange: replace one cam of a multi-cam slave (slave auto_offset: no jump)";
            cam_remove: "cam-remove" at axes, CamRemoveBody, CamRemoveBody::to_kind, Operator, Done, [],
                "MC_CamRemove: take a cam off a multi-cam slave (its position stays; Done once removed)";
            cam_scaling_v2: "cam-scaling-v2" at axes, CamScalingV2Body, CamScalingV2Body::to_kind, Operator, Done, [],
                "MC_CamScaling_V2: new offsets and scalings of one cam of a multi-cam slave";
            cam_scaling: "cam-scaling" at axes, CamScalingBody, CamScalingBody::to_kind, Operator, Done, [],
                "MC_CamScaling: new offsets and scalings of the cam coupling (auto_offset: no position jump)";
        }
    };
}
pub(crate) use entries;

/// How a coupling interpolates a position table (`ST_CamInOptions.InterpolationType`): the
/// document's view of `InterpolationType` without `4point`, which is no longer supported.
#[derive(Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
#[allow(
    dead_code,
    reason = "the document's view of the kernel's enum, never built"
)]
pub enum CouplingInterpolation {
    Linear,
    Spline,
    SlidingSpline,
}

/// MC_CamIn: couple this axis (the slave) to `master` through a cam table, or — on a slave
/// already coupled to that master through a cam — switch to another cam. The slave must stand
/// where the cam puts it (`GET /cam-tables/{table}/slave-dynamics`), or use a relative start
/// mode or slave autooffset: a cam that would make it jump is refused (0x7084).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"master": "x", "cam_table": "knife", "start_mode": "absolute", "activation_mode": "instantaneous"}))]
pub struct CamInBody {
    /// Master axis id or name.
    pub master: String,
    /// Cam table id (1..255) or name.
    pub cam_table: String,
    /// Added to the master position before scaling (spec §1.5). Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub master_offset: f64,
    /// Added to the scaled slave cam position. Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub slave_offset: f64,
    /// Default 1 (not 0).
    #[serde(default = "one")]
    #[schema(default = 1.0)]
    #[schema(schema_with = nonzero_number)]
    pub master_scaling: f64,
    /// Default 1 (not 0).
    #[serde(default = "one")]
    #[schema(default = 1.0)]
    #[schema(schema_with = nonzero_number)]
    pub slave_scaling: f64,
    /// Default `absolute`.
    #[serde(default)]
    pub start_mode: motion::cam::StartMode,
    /// Default `instantaneous`.
    #[serde(default)]
    pub activation_mode: motion::cam::CamActivationMode,
    /// For the position modes: master axis position, or raw cam position for
    /// `at_master_cam_pos`. Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub activation_position: f64,
    /// Default `user_defined`.
    #[serde(default)]
    pub master_scaling_mode: motion::cam::CamScalingMode,
    /// Default `user_defined`.
    #[serde(default)]
    pub slave_scaling_mode: motion::cam::CamScalingMode,
    /// `ST_CamInOptions.InterpolationType`: how this coupling interpolates a position table.
    /// Default: the table's own `interpolation`. Motion functions ignore it (their laws decide).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<CouplingInterpolation>)]
    pub interpolation: Option<motion::cam::InterpolationType>,
    /// With a `ramp_in*` start mode: how the slave catches up with the cam (the limits of its
    /// deviation from the cam; `velocity` required, the others 0 = the axis defaults).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ramp_in: Option<motion::cam::RampIn>,
}

/// MC_CamScaling: new offsets and scalings of the cam coupling (the raw table stays).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"slave_scaling": 2.0, "slave_scaling_mode": "auto_offset", "master_scaling_mode": "off"}))]
pub struct CamScalingBody {
    /// Default `instantaneous` (also `at_master_cam_pos`, `at_master_axis_pos…`, `next_cycle`,
    /// `off`).
    #[serde(default)]
    pub activation_mode: motion::cam::CamActivationMode,
    /// Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub activation_position: f64,
    /// Default `user_defined`.
    #[serde(default)]
    pub master_scaling_mode: motion::cam::CamScalingMode,
    /// Default `user_defined`.
    #[serde(default)]
    pub slave_scaling_mode: motion::cam::CamScalingMode,
    /// Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub master_offset: f64,
    /// Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub slave_offset: f64,
    /// Default 1.
    #[serde(default = "one")]
    #[schema(default = 1.0)]
    #[schema(schema_with = nonzero_number)]
    pub master_scaling: f64,
    /// Default 1.
    #[serde(default = "one")]
    #[schema(default = 1.0)]
    #[schema(schema_with = nonzero_number)]
    pub slave_scaling: f64,
}

/// MC_CamIn_V2: couple with one cam, then add, exchange or remove superimposed cams
/// (`operation`). Not to be mixed with cam-in on one slave.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"master": "x", "cam_table": "knife", "operation": "additive"}))]
pub struct CamInV2Body {
    /// Master axis id or name.
    pub master: String,
    /// Cam table id (1..255) or name.
    pub cam_table: String,
    /// Default `instantaneous`.
    #[serde(default)]
    pub activation_mode: motion::cam::CamActivationMode,
    /// Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub activation_position: f64,
    /// This cam's offsets and scalings (default: absolute, no offset, scaling 1).
    #[serde(default)]
    pub scaling: motion::cam::CamScalingData,
    /// Default `default` (= additive: the first call couples).
    #[serde(default)]
    pub operation: motion::cam::CamOperationMode,
    /// For `exchange`: the cam to replace (id or name; may be left out when the slave has one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_cam_table: Option<String>,
    /// `ST_CamInOptions.InterpolationType`: how this coupling interpolates a position table.
    /// Default: the table's own `interpolation`. Motion functions ignore it (their laws decide).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<CouplingInterpolation>)]
    pub interpolation: Option<motion::cam::InterpolationType>,
}

/// MC_CamAdd: superimpose a cam on a multi-cam slave (the first one couples).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"master": "x", "cam_table": "correction", "scaling": {"slave_relative": true}}))]
pub struct CamAddBody {
    /// Master axis id or name.
    pub master: String,
    /// Cam table id (1..255) or name.
    pub cam_table: String,
    /// Default `instantaneous`.
    #[serde(default)]
    pub activation_mode: motion::cam::CamActivationMode,
    /// Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub activation_position: f64,
    /// Default: absolute, no offset, scaling 1.
    #[serde(default)]
    pub scaling: motion::cam::CamScalingData,
    /// `ST_CamInOptions.InterpolationType`: how this coupling interpolates a position table.
    /// Default: the table's own `interpolation`. Motion functions ignore it (their laws decide).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<CouplingInterpolation>)]
    pub interpolation: Option<motion::cam::InterpolationType>,
}

/// MC_CamExchange: replace one cam of a multi-cam slave.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"master": "x", "cam_table": "knife_long", "reference_cam_table": "knife", "scaling": {"slave_scaling_mode": "auto_offset"}}))]
pub struct CamExchangeBody {
    /// Master axis id or name.
    pub master: String,
    /// The new cam (id or name).
    pub cam_table: String,
    /// The cam it replaces (id or name; may be left out when the slave has one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_cam_table: Option<String>,
    /// Default `instantaneous`.
    #[serde(default)]
    pub activation_mode: motion::cam::CamActivationMode,
    /// Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub activation_position: f64,
    /// Default: absolute, no offset, scaling 1.
    #[serde(default)]
    pub scaling: motion::cam::CamScalingData,
    /// `ST_CamInOptions.InterpolationType`: how this coupling interpolates a position table.
    /// Default: the table's own `interpolation`. Motion functions ignore it (their laws decide).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<CouplingInterpolation>)]
    pub interpolation: Option<motion::cam::InterpolationType>,
}

/// MC_CamRemove: take one cam off a multi-cam slave (Done once removed; the last one is
/// removed by cam-out).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"master": "x", "cam_table": "correction"}))]
pub struct CamRemoveBody {
    /// Master axis id or name.
    pub master: String,
    /// The cam to remove (id or name).
    pub cam_table: String,
    /// Default `instantaneous`.
    #[serde(default)]
    pub activation_mode: motion::cam::CamActivationMode,
    /// Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub activation_position: f64,
}

/// MC_CamScaling_V2: new offsets and scalings of one cam of the slave.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"cam_table": "correction", "scaling": {"slave_scaling": 0.5, "master_scaling_mode": "off"}}))]
pub struct CamScalingV2Body {
    /// The cam to scale (id or name; may be left out when the slave has one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cam_table: Option<String>,
    /// Default `instantaneous`.
    #[serde(default)]
    pub activation_mode: motion::cam::CamActivationMode,
    /// Default 0.
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub activation_position: f64,
    /// Default: absolute, no offset, scaling 1.
    #[serde(default)]
    pub scaling: motion::cam::CamScalingData,
}

/// A cam table by id or name, as the kernel knows it (its id).
fn cam_table_id(c: &mut Check, reg: &Registry, key: &str) -> u32 {
    match reg.find_cam(key) {
        Some(t) => t.id,
        None => {
            c.fail("cam_table", "no such cam table");
            0
        }
    }
}

impl CamInBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        let cam_table = cam_table_id(&mut c, reg, &self.cam_table);
        c.cam_coupling(
            [
                self.master_offset,
                self.slave_offset,
                self.activation_position,
            ],
            [self.master_scaling, self.slave_scaling],
        );
        c.interpolation(self.interpolation);
        let ramp_in = self.ramp_in.unwrap_or_default();
        if self.start_mode.ramp_in() {
            if !(ramp_in.velocity > 0.0 && ramp_in.velocity.is_finite()) {
                c.fail(
                    "ramp_in.velocity",
                    "a ramp-in start mode needs its velocity (> 0)",
                );
            }
            for (field, v) in [
                ("ramp_in.acceleration", ramp_in.acceleration),
                ("ramp_in.deceleration", ramp_in.deceleration),
                ("ramp_in.jerk", ramp_in.jerk),
            ] {
                if !(v >= 0.0 && v.is_finite()) {
                    c.fail(field, "must be a finite number ≥ 0 (0: the axis default)");
                }
            }
        } else if self.ramp_in.is_some() {
            c.fail("ramp_in", "only with a ramp_in start mode");
        }
        c.done(CommandKind::CamIn(motion::cam::CamIn {
            master,
            cam_table,
            master_offset: self.master_offset,
            slave_offset: self.slave_offset,
            master_scaling: self.master_scaling,
            slave_scaling: self.slave_scaling,
            start_mode: self.start_mode,
            activation_mode: self.activation_mode,
            activation_position: self.activation_position,
            master_scaling_mode: self.master_scaling_mode,
            slave_scaling_mode: self.slave_scaling_mode,
            interpolation: self.interpolation,
            ramp_in,
        }))
    }
}

/// A multi-cam operation (MC_CamIn_V2 and its convenience blocks).
#[allow(
    clippy::too_many_arguments,
    reason = "MC_CamIn_V2's inputs, as the block has them"
)]
fn cam_in_v2(
    reg: &Registry,
    axis: &AxisEntry,
    master: &str,
    cam_table: &str,
    reference: Option<&str>,
    activation: (motion::cam::CamActivationMode, f64),
    scaling: motion::cam::CamScalingData,
    operation: motion::cam::CamOperationMode,
    interpolation: Option<motion::cam::InterpolationType>,
) -> AppResult<CommandKind> {
    let mut c = Check::default();
    let master = master_slot(&mut c, reg, axis, master);
    let cam_table = cam_table_id(&mut c, reg, cam_table);
    let reference_cam_table = match reference {
        None => 0,
        Some(r) => match reg.find_cam(r) {
            Some(t) => t.id,
            None => {
                c.fail("reference_cam_table", "no such cam table");
                0
            }
        },
    };
    c.cam_coupling(
        [scaling.master_offset, scaling.slave_offset, activation.1],
        [scaling.master_scaling, scaling.slave_scaling],
    );
    c.interpolation(interpolation);
    c.done(CommandKind::CamInV2(motion::cam::CamInV2 {
        master,
        cam_table,
        activation_mode: activation.0,
        activation_position: activation.1,
        scaling,
        operation,
        reference_cam_table,
        interpolation,
    }))
}

impl CamInV2Body {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        cam_in_v2(
            reg,
            axis,
            &self.master,
            &self.cam_table,
            self.reference_cam_table.as_deref(),
            (self.activation_mode, self.activation_position),
            self.scaling,
            self.operation,
            self.interpolation,
        )
    }
}

impl CamAddBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        cam_in_v2(
            reg,
            axis,
            &self.master,
            &self.cam_table,
            None,
            (self.activation_mode, self.activation_position),
            self.scaling,
            motion::cam::CamOperationMode::Additive,
            self.interpolation,
        )
    }
}

impl CamExchangeBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        cam_in_v2(
            reg,
            axis,
            &self.master,
            &self.cam_table,
            self.reference_cam_table.as_deref(),
            (self.activation_mode, self.activation_position),
            self.scaling,
            motion::cam::CamOperationMode::Exchange,
            self.interpolation,
        )
    }
}

impl CamRemoveBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        cam_in_v2(
            reg,
            axis,
            &self.master,
            &self.cam_table,
            None,
            (self.activation_mode, self.activation_position),
            motion::cam::CamScalingData::default(),
            motion::cam::CamOperationMode::Remove,
            None,
        )
    }
}

impl CamScalingV2Body {
    pub fn to_kind(&self, reg: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let cam_table = match self.cam_table.as_deref() {
            None => 0,
            Some(t) => cam_table_id(&mut c, reg, t),
        };
        let d = self.scaling;
        c.cam_coupling(
            [d.master_offset, d.slave_offset, self.activation_position],
            [d.master_scaling, d.slave_scaling],
        );
        c.done(CommandKind::CamScalingV2(motion::cam::CamScalingV2 {
            cam_table,
            activation_mode: self.activation_mode,
            activation_position: self.activation_position,
            scaling: d,
        }))
    }
}

impl CamScalingBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.cam_coupling(
            [
                self.master_offset,
                self.slave_offset,
                self.activation_position,
            ],
            [self.master_scaling, self.slave_scaling],
        );
        c.done(CommandKind::CamScaling(motion::cam::CamScaling {
            activation_mode: self.activation_mode,
            activation_position: self.activation_position,
            master_scaling_mode: self.master_scaling_mode,
            slave_scaling_mode: self.slave_scaling_mode,
            master_offset: self.master_offset,
            slave_offset: self.slave_offset,
            master_scaling: self.master_scaling,
            slave_scaling: self.slave_scaling,
        }))
    }
}
