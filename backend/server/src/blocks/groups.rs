//! The blocks of an axis group (TwinCAT TF5420, Tc3_McCoordinatedMotion): the administrative
//! ones (MC_AddAxisToGroup … MC_GroupSetOverride), the stops (MC_GroupHalt, MC_GroupStop),
//! MC_ReleaseBlocker, and MC_MovePath with its table built from the Preparation blocks' inputs
//! (linear, circular, blocker, dwell entries). Each entry is checked here with the kernel's
//! own rules (`PathTable::check`), so that a bad entry is a 422 naming `entries[i].field`
//! before anything reaches the cycle thread.

use motion::group::{
    EntryMotion, GroupRole, MAX_PATH_ENTRIES, PathEntry, PathTable, PathValue, TransitionMode,
};
use motion::path::{CircMode, CircPathChoice, MAX_PATH_DIMS, PathPoint};
use motion::{BufferMode, CommandKind, ConveyorTracking, TrackingBehavior};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::Check;
use crate::app::{GroupEntry, Registry};
use crate::error::{AppError, AppResult, FieldError};
use crate::model::GroupOrder;

/// The family's catalogue entries (the form: `crate::blocks`).
macro_rules! entries {
    ($catalogue:ident) => {
        $catalogue! {
            group_add_axis: "add-axis" at groups, GroupAddAxisBody, GroupAddAxisBody::to_order, Operator, Done, [],
                "MC_AddAxisToGroup: an axis takes a role (only while the group is disabled)";
            group_remove_axis: "remove-axis" at groups, GroupRemoveAxisBody, GroupRemoveAxisBody::to_order, Operator, Done, [],
                "MC_RemoveAxisFromGroup: the axis of a role leaves (Done also when there is none)";
            group_ungroup_all: "ungroup-all" at groups, EmptyBody, |_, _, _| Ok(GroupOrder::Command(CommandKind::UngroupAllAxes)), Operator, Done, [lease_free],
                "MC_UngroupAllAxes: every axis leaves and the group is disabled";
            group_enable: "enable" at groups, EmptyBody, |_, _, _| Ok(GroupOrder::Command(CommandKind::GroupEnable)), Operator, Done, [],
                "MC_GroupEnable: with all its axes, the group goes to standby (not_ready until every axis is powered)";
            group_disable: "disable" at groups, EmptyBody, |_, _, _| Ok(GroupOrder::Command(CommandKind::GroupDisable)), Operator, Done, [lease_free],
                "MC_GroupDisable: disabled at once (a moving group stops abruptly: halt or stop first)";
            group_reset: "reset" at groups, EmptyBody, |_, _, _| Ok(GroupOrder::Command(CommandKind::GroupReset)), Operator, Done, [],
                "MC_GroupReset: clear the errors of the group and its axes";
            group_set_override: "set-override" at groups, GroupSetOverrideBody, GroupSetOverrideBody::to_order, Operator, Done, [],
                "MC_GroupSetOverride: the path velocity factor, clamped to 0…1, ramped over the override ramp time";
            group_halt: "halt" at groups, GroupStopBody, GroupStopBody::to_halt, Operator, Done, [lease_free],
                "MC_GroupHalt: stop on the path without a lock; flushes the queued entries";
            group_stop: "stop" at groups, GroupStopBody, GroupStopBody::to_stop, Operator, Done, [lease_free],
                "MC_GroupStop: stop on the path and lock the group until released (DELETE /commands/{id})";
            group_release_blocker: "release-blocker" at groups, ReleaseBlockerBody, ReleaseBlockerBody::to_order, Operator, Done, [],
                "MC_ReleaseBlocker: let the path go on past a blocker";
            group_move_path: "move-path" at groups, MovePathBody, MovePathBody::to_order, Operator, Done, [],
                "MC_MovePath: run a path of linear, circular, blocker, dwell and coordinate-transform entries";
            group_set_coordinate_transform: "set-coordinate-transform" at groups, SetCoordinateTransformBody, SetCoordinateTransformBody::to_order, Operator, Done, [],
                "MC_SetCoordinateTransform: later MovePaths are read in this frame (a halt or stop clears it; it detaches from a tracked conveyor: active while the tracking brakes to rest)";
            group_track_conveyor_belt: "track-conveyor-belt" at groups, TrackConveyorBeltBody, TrackConveyorBeltBody::to_order, Operator, InSync, [],
                "MC_TrackConveyorBelt: follow a conveyor axis; later MovePaths are read relative to the detected object (no Done: in_sync, until another frame, tracking, halt or stop)";
        }
    };
}
pub(crate) use entries;

/// MC_AddAxisToGroup.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"role": "x", "axis": "x"}))]
pub struct GroupAddAxisBody {
    /// `IdentInGroup`: a role of the group's convention or addax1..n.
    pub role: GroupRole,
    /// The axis: its id (all digits) or its name.
    #[schema(min_length = 1, max_length = 64)]
    pub axis: String,
}

impl GroupAddAxisBody {
    pub fn to_order(&self, reg: &Registry, _: &GroupEntry) -> AppResult<GroupOrder> {
        let axis = reg
            .find(&self.axis)
            .ok_or_else(|| AppError::field("axis", &format!("no axis '{}'", self.axis)))?;
        Ok(GroupOrder::Command(CommandKind::AddAxisToGroup {
            axis: axis.slot,
            role: self.role,
        }))
    }
}

/// MC_RemoveAxisFromGroup.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"role": "y"}))]
pub struct GroupRemoveAxisBody {
    pub role: GroupRole,
}

impl GroupRemoveAxisBody {
    pub fn to_order(&self, _: &Registry, _: &GroupEntry) -> AppResult<GroupOrder> {
        Ok(GroupOrder::Command(CommandKind::RemoveAxisFromGroup {
            role: self.role,
        }))
    }
}

/// MC_GroupSetOverride.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"factor": 0.5}))]
pub struct GroupSetOverrideBody {
    /// `VelFactor`: 0 (0 %) … 1 (100 %); a value outside is clamped, never refused.
    pub factor: f64,
}

impl GroupSetOverrideBody {
    pub fn to_order(&self, _: &Registry, _: &GroupEntry) -> AppResult<GroupOrder> {
        Ok(GroupOrder::Command(CommandKind::GroupSetOverride {
            factor: self.factor.clamp(0.0, 1.0),
        }))
    }
}

/// `MC_DEFAULT`, `MC_MAXIMUM`, `MC_IGNORE` (TF5420 §2.4, §5.16).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum SpecialValue {
    /// The group's default dynamics.
    Default,
    /// The group's maximum dynamics.
    Maximum,
    /// No limit (the jerk of a halt or stop only).
    Ignore,
}

/// A path dynamics input: a number (path units/s, /s², /s³), or `"default"`, `"maximum"`
/// (and `"ignore"` for the jerk of a halt or stop).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(untagged)]
#[schema(example = json!(200.0))]
pub enum PathValueDto {
    Number(f64),
    Special(SpecialValue),
}

impl Default for PathValueDto {
    fn default() -> Self {
        PathValueDto::Special(SpecialValue::Default)
    }
}

impl PathValueDto {
    fn kernel(self) -> PathValue {
        match self {
            PathValueDto::Number(x) => PathValue::Value(x),
            PathValueDto::Special(SpecialValue::Default) => PathValue::Default,
            PathValueDto::Special(SpecialValue::Maximum) => PathValue::Maximum,
            PathValueDto::Special(SpecialValue::Ignore) => PathValue::Ignore,
        }
    }
}

/// MC_GroupHalt, MC_GroupStop.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"deceleration": 2000.0, "jerk": "default"}))]
pub struct GroupStopBody {
    /// ≥ 1, `"default"` (default) or `"maximum"`.
    #[serde(default)]
    pub deceleration: PathValueDto,
    /// ≥ 100, `"default"` (default), `"maximum"` or `"ignore"` (no jerk limit).
    #[serde(default)]
    pub jerk: PathValueDto,
}

impl GroupStopBody {
    fn values(&self) -> AppResult<(PathValue, PathValue)> {
        let mut c = Check::default();
        match self.deceleration {
            PathValueDto::Number(d) if !(d.is_finite() && d >= 1.0) => {
                c.fail("deceleration", "must be ≥ 1, \"default\" or \"maximum\"")
            }
            PathValueDto::Special(SpecialValue::Ignore) => {
                c.fail("deceleration", "must be ≥ 1, \"default\" or \"maximum\"")
            }
            _ => {}
        }
        if let PathValueDto::Number(j) = self.jerk {
            if !(j.is_finite() && j >= 100.0) {
                c.fail(
                    "jerk",
                    "must be ≥ 100, \"default\", \"maximum\" or \"ignore\"",
                );
            }
        }
        c.done((self.deceleration.kernel(), self.jerk.kernel()))
    }
    pub fn to_halt(&self, _: &Registry, _: &GroupEntry) -> AppResult<GroupOrder> {
        let (deceleration, jerk) = self.values()?;
        Ok(GroupOrder::Command(CommandKind::GroupHalt {
            deceleration,
            jerk,
        }))
    }
    pub fn to_stop(&self, _: &Registry, _: &GroupEntry) -> AppResult<GroupOrder> {
        let (deceleration, jerk) = self.values()?;
        Ok(GroupOrder::Command(CommandKind::GroupStop {
            deceleration,
            jerk,
        }))
    }
}

/// MC_ReleaseBlocker.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"blocker_id": 7}))]
pub struct ReleaseBlockerBody {
    /// The blocker's id (> 0).
    #[schema(value_type = i64, minimum = 1, maximum = 4294967295_u64)]
    pub blocker_id: u32,
}

impl ReleaseBlockerBody {
    pub fn to_order(&self, _: &Registry, _: &GroupEntry) -> AppResult<GroupOrder> {
        if self.blocker_id == 0 {
            return Err(coded(
                "blocker_id".into(),
                motion::ErrorId::BLOCKER_ID_INVALID,
            ));
        }
        Ok(GroupOrder::Command(CommandKind::ReleaseBlocker {
            blocker_id: self.blocker_id,
        }))
    }
}

/// `MC_TRANSITION_MODE` (only `none`, `corner_distance` and `corner_distance_advanced` are
/// supported by the CM group; the others are refused with transition_mode_invalid).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum TransitionModeDto {
    /// No blending: the path stops at the corner.
    #[default]
    None,
    /// A tolerance sphere of radius `transition_parameters[0]` around the corner.
    CornerDistance,
    /// `transition_parameters` = [r_in on the previous segment, r_out on this one].
    CornerDistanceAdvanced,
    StartVelocity,
    ConstantVelocity,
    MaxCornerDeviation,
}

impl TransitionModeDto {
    fn kernel(self) -> TransitionMode {
        match self {
            TransitionModeDto::None => TransitionMode::None,
            TransitionModeDto::CornerDistance => TransitionMode::CornerDistance,
            TransitionModeDto::CornerDistanceAdvanced => TransitionMode::CornerDistanceAdvanced,
            TransitionModeDto::StartVelocity => TransitionMode::StartVelocity,
            TransitionModeDto::ConstantVelocity => TransitionMode::ConstantVelocity,
            TransitionModeDto::MaxCornerDeviation => TransitionMode::MaxCornerDeviation,
        }
    }
}

/// One row of the path table, by `type`: `linear` (MC_MoveLinearAbsolutePreparation),
/// `circular` (MC_MoveCircularAbsolutePreparation), `blocker` (MC_BlockerPreparation: the path
/// holds there until MC_ReleaseBlocker), `dwell` (MC_DwellTimePreparation).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
#[schema(example = json!({"type": "linear", "position": [100.0, 0.0], "velocity": 200.0}))]
pub enum PathEntryDto {
    /// MC_MoveLinearAbsolutePreparation.
    Linear {
        /// The target in the group's axis order (the convention's axes, then addax1..n): as many
        /// values as the group has axes.
        #[schema(min_items = 1, max_items = 12)]
        position: Vec<f64>,
        /// Maximum path velocity of the segment: > 0 or `"maximum"` (mandatory).
        velocity: PathValueDto,
        /// ≥ 1, `"default"` (default) or `"maximum"`.
        #[serde(default)]
        acceleration: PathValueDto,
        /// ≥ 1, `"default"` (default) or `"maximum"`.
        #[serde(default)]
        deceleration: PathValueDto,
        /// ≥ 100, `"default"` (default) or `"maximum"`.
        #[serde(default)]
        jerk: PathValueDto,
        /// How the entry joins the one before (TF5420 §7.3); default `aborting` as the manual's
        /// (legal only on the first entry of a path: later entries need `buffered` or
        /// `blending_previous`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        buffer_mode: Option<BufferMode>,
        /// Blending at the start of this entry (default `none`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        transition_mode: Option<TransitionModeDto>,
        /// TransitionParameter[1..]: 1 for corner_distance, 2 for corner_distance_advanced.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        #[schema(max_items = 2)]
        transition_parameters: Vec<f64>,
        /// Echoed in the group status while the entry runs.
        #[serde(default)]
        #[schema(default = 0, value_type = i64, minimum = 0, maximum = 4294967295_u64)]
        invoke_id: u32,
    },
    /// MC_MoveCircularAbsolutePreparation.
    Circular {
        /// What `aux_point` is: a point on the arc (`border`), its centre (`center`), or the normal
        /// of its plane whose length is the radius (`radius`).
        circ_mode: CircMode,
        /// X, Y, Z of the auxiliary point.
        #[schema(min_items = 3, max_items = 3)]
        aux_point: Vec<f64>,
        /// The end in the group's axis order (as many values as the group has axes).
        #[schema(min_items = 1, max_items = 12)]
        end_point: Vec<f64>,
        /// Which arc (ignored for `border`; default `counter_clockwise`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        path_choice: Option<CircPathChoice>,
        /// Maximum path velocity of the segment: > 0 or `"maximum"` (mandatory).
        velocity: PathValueDto,
        #[serde(default)]
        acceleration: PathValueDto,
        #[serde(default)]
        deceleration: PathValueDto,
        #[serde(default)]
        jerk: PathValueDto,
        /// As for a linear entry (default `aborting`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        buffer_mode: Option<BufferMode>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        transition_mode: Option<TransitionModeDto>,
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        #[schema(max_items = 2)]
        transition_parameters: Vec<f64>,
        #[serde(default)]
        #[schema(default = 0, value_type = i64, minimum = 0, maximum = 4294967295_u64)]
        invoke_id: u32,
    },
    /// MC_BlockerPreparation.
    Blocker {
        /// > 0.
        #[schema(value_type = i64, minimum = 1, maximum = 4294967295_u64)]
        blocker_id: u32,
        /// `buffered` (default) or, as the first entry, `aborting`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        buffer_mode: Option<BufferMode>,
        #[serde(default)]
        #[schema(default = 0, value_type = i64, minimum = 0, maximum = 4294967295_u64)]
        invoke_id: u32,
    },
    /// MC_DwellTimePreparation: the path stands still for `time`.
    Dwell {
        /// Seconds, ≥ 0 (0 still forces an exact stop).
        time: f64,
        /// `buffered` (default) or, as the first entry, `aborting`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        buffer_mode: Option<BufferMode>,
        #[serde(default)]
        #[schema(default = 0, value_type = i64, minimum = 0, maximum = 4294967295_u64)]
        invoke_id: u32,
    },
    /// MC_SetCoordinateTransformPreparation: the entries after it are read in this frame.
    CoordinateTransform {
        /// Shift of the frame's origin, X, Y, Z.
        #[schema(min_items = 3, max_items = 3)]
        translation: Vec<f64>,
        /// Rotations in degrees, DIN 9300 Z″Y′X: [about X, about Y, about Z].
        #[schema(min_items = 3, max_items = 3)]
        rotation: Vec<f64>,
    },
}

/// A frame's shift and rotations: three finite numbers each.
fn check_frame(c: &mut Check, translation: &[f64], rotation: &[f64]) {
    for (name, v) in [("translation", translation), ("rotation", rotation)] {
        if v.len() != 3 {
            c.fail(name, "X, Y and Z: three numbers");
        }
        for (j, x) in v.iter().enumerate() {
            c.finite(&format!("{name}[{j}]"), *x);
        }
    }
}

/// Three numbers as a kernel vector (`None`: not three).
fn xyz(v: &[f64]) -> Option<[f64; 3]> {
    v.try_into().ok()
}

/// MC_SetCoordinateTransform: later MovePaths are read in this frame.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"translation": [100.0, 50.0, 0.0], "rotation": [0.0, 0.0, 90.0]}))]
pub struct SetCoordinateTransformBody {
    /// Shift of the frame's origin, X, Y, Z.
    #[schema(min_items = 3, max_items = 3)]
    pub translation: Vec<f64>,
    /// Rotations in degrees, DIN 9300 Z″Y′X: [about X, about Y, about Z].
    #[schema(min_items = 3, max_items = 3)]
    pub rotation: Vec<f64>,
}

impl SetCoordinateTransformBody {
    pub fn to_order(&self, _: &Registry, group: &GroupEntry) -> AppResult<GroupOrder> {
        let mut c = Check::default();
        check_frame(&mut c, &self.translation, &self.rotation);
        c.done(())?;
        let transform = motion::group::CoordTransform {
            translation: xyz(&self.translation).unwrap_or_default(),
            rotation: xyz(&self.rotation).unwrap_or_default(),
        };
        // An XY group's frames stay in its plane (decision 135).
        transform
            .check(group.config.convention.planar())
            .map_err(|f| {
                AppError::field(
                    f,
                    "an XY group's frame turns only about Z and does not shift in Z",
                )
            })?;
        Ok(GroupOrder::Command(CommandKind::SetCoordinateTransform {
            transform,
        }))
    }
}

/// MC_TrackConveyorBelt: the conveyor frame (its X the conveying direction), the object
/// detected on it with the conveyor position latched at that moment, and the
/// synchronisation's dynamics (not capped by the axes' maxima, TF5420 §4.1).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"conveyor": "belt", "translation": [0.0, 100.0, 0.0], "rotation": [0.0, 0.0, 0.0],
    "initial_object_position": [30.0, 0.0], "master_ref_position": 1250.0, "velocity": 200.0,
    "acceleration": 1000.0, "deceleration": 1000.0, "jerk": 10000.0,
    "tracking_behavior": "dyn_limited", "sync_tolerance": 0.01}))]
pub struct TrackConveyorBeltBody {
    /// The conveyor axis (the master): its id (all digits) or its name; not an axis of the
    /// group.
    #[schema(min_length = 1, max_length = 64)]
    pub conveyor: String,
    /// The conveyor frame's origin in machine coordinates, X, Y, Z (default 0).
    #[serde(default = "zero3")]
    #[schema(min_items = 3, max_items = 3)]
    pub translation: Vec<f64>,
    /// Its rotations in degrees, DIN 9300 Z″Y′X: [about X, about Y, about Z] (default 0).
    #[serde(default = "zero3")]
    #[schema(min_items = 3, max_items = 3)]
    pub rotation: Vec<f64>,
    /// `InitialObjectPos`: where the object was detected, in the conveyor frame (1 to 3
    /// numbers: X along the belt, then Y, Z; missing ones are 0).
    #[schema(min_items = 1, max_items = 3)]
    pub initial_object_position: Vec<f64>,
    /// `MasterRefPos`: the conveyor's position latched when the object was detected.
    pub master_ref_position: f64,
    /// Synchronisation velocity (> the conveyor's velocity), acceleration (≥ 1),
    /// deceleration (≥ 1), jerk (≥ 100): numbers, `"default"` (the group's default
    /// dynamics) or `"maximum"`.
    #[serde(default)]
    pub velocity: PathValueDto,
    #[serde(default)]
    pub acceleration: PathValueDto,
    #[serde(default)]
    pub deceleration: PathValueDto,
    #[serde(default)]
    pub jerk: PathValueDto,
    /// `dyn_limited` (default): InSync may fall when the conveyor jolts; `stay_in_sync`.
    #[serde(default)]
    pub tracking_behavior: TrackingBehavior,
    /// Synchronization Tolerance Distance (> 0, default 0.01 path units).
    #[serde(default = "default_sync_tolerance")]
    #[schema(exclusive_minimum = 0.0)]
    pub sync_tolerance: f64,
}

fn zero3() -> Vec<f64> {
    vec![0.0; 3]
}

fn default_sync_tolerance() -> f64 {
    0.01
}

impl TrackConveyorBeltBody {
    pub fn to_order(&self, reg: &Registry, group: &GroupEntry) -> AppResult<GroupOrder> {
        let mut c = Check::default();
        let conveyor = reg.find(&self.conveyor);
        if conveyor.is_none() {
            c.fail("conveyor", &format!("no axis '{}'", self.conveyor));
        }
        check_frame(&mut c, &self.translation, &self.rotation);
        if self.initial_object_position.is_empty() || self.initial_object_position.len() > 3 {
            c.fail("initial_object_position", "1 to 3 numbers: X, Y, Z");
        }
        for (j, x) in self.initial_object_position.iter().enumerate() {
            c.finite(&format!("initial_object_position[{j}]"), *x);
        }
        c.finite("master_ref_position", self.master_ref_position);
        for (name, v, min) in [
            ("velocity", self.velocity, f64::MIN_POSITIVE),
            ("acceleration", self.acceleration, 1.0),
            ("deceleration", self.deceleration, 1.0),
            ("jerk", self.jerk, 100.0),
        ] {
            match v {
                PathValueDto::Number(x) if !(x.is_finite() && x >= min) => c.fail(
                    name,
                    &format!("must be ≥ {min}, \"default\" or \"maximum\""),
                ),
                PathValueDto::Special(SpecialValue::Ignore) => {
                    c.fail(name, "must be a number, \"default\" or \"maximum\"")
                }
                _ => {}
            }
        }
        if !(self.sync_tolerance.is_finite() && self.sync_tolerance > 0.0) {
            c.fail("sync_tolerance", "must be > 0");
        }
        c.done(())?;
        let mut object = [0.0; 3];
        object[..self.initial_object_position.len()].copy_from_slice(&self.initial_object_position);
        let transform = motion::group::CoordTransform {
            translation: xyz(&self.translation).unwrap_or_default(),
            rotation: xyz(&self.rotation).unwrap_or_default(),
        };
        let planar = group.config.convention.planar();
        transform.check(planar).map_err(|f| {
            AppError::field(
                f,
                "an XY group's conveyor lies in its plane: it turns only about Z and does not shift in Z",
            )
        })?;
        if planar && object[2] != 0.0 {
            return Err(AppError::field(
                "initial_object_position[2]",
                "an XY group's object lies in its plane (Z = 0)",
            ));
        }
        Ok(GroupOrder::Command(CommandKind::TrackConveyorBelt(
            ConveyorTracking {
                conveyor: conveyor.map(|a| a.slot).unwrap_or_default(),
                transform,
                initial_object_position: object,
                master_ref_position: self.master_ref_position,
                velocity: self.velocity.kernel(),
                acceleration: self.acceleration.kernel(),
                deceleration: self.deceleration.kernel(),
                jerk: self.jerk.kernel(),
                behavior: self.tracking_behavior,
                sync_tolerance: self.sync_tolerance,
            },
        )))
    }
}

/// MC_MovePath with its table.
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"entries": [
    {"type": "linear", "position": [100.0, 0.0], "velocity": 200.0},
    {"type": "circular", "circ_mode": "center", "aux_point": [100.0, 50.0, 0.0], "end_point": [150.0, 50.0],
        "path_choice": "counter_clockwise", "velocity": 200.0, "buffer_mode": "buffered"},
    {"type": "linear", "position": [150.0, 150.0], "velocity": 200.0, "buffer_mode": "blending_previous",
        "transition_mode": "corner_distance", "transition_parameters": [5.0]},
    {"type": "linear", "position": [0.0, 150.0], "velocity": 200.0, "buffer_mode": "blending_previous",
        "transition_mode": "corner_distance", "transition_parameters": [5.0]}
]}))]
pub struct MovePathBody {
    /// 1 to 256 entries (TwinCAT's table holds 30; decision 123).
    #[schema(min_items = 1, max_items = 256)]
    pub entries: Vec<PathEntryDto>,
}

/// A 422 with the rule's own code, on one field.
fn coded(field: String, id: motion::ErrorId) -> AppError {
    AppError::InvalidCoded {
        errors: vec![FieldError {
            message: format!("{} (0x{:04X}): {}", id.code(), id.0, id.text()),
            field,
        }],
        id,
    }
}

/// A vector of the group's axis order as a path point (count = its length); `None` if longer
/// than a point holds.
fn point(v: &[f64]) -> Option<(PathPoint, u8)> {
    if v.len() > MAX_PATH_DIMS {
        return None;
    }
    let mut p = [0.0; MAX_PATH_DIMS];
    p[..v.len()].copy_from_slice(v);
    Some((p, v.len() as u8))
}

/// The motion inputs of a linear or circular entry (`[velocity, acceleration, deceleration,
/// jerk]` and the buffer and transition inputs) with the manual's defaults.
fn motion(
    [velocity, acceleration, deceleration, jerk]: [PathValueDto; 4],
    buffer_mode: Option<BufferMode>,
    transition_mode: Option<TransitionModeDto>,
    params: &[f64],
) -> Option<EntryMotion> {
    if params.len() > 2 {
        return None;
    }
    let mut transition_parameters = [0.0; 2];
    transition_parameters[..params.len()].copy_from_slice(params);
    Some(EntryMotion {
        velocity: velocity.kernel(),
        acceleration: acceleration.kernel(),
        deceleration: deceleration.kernel(),
        jerk: jerk.kernel(),
        // The manual's default for the linear and circular Preparation blocks.
        buffer_mode: buffer_mode.unwrap_or(BufferMode::Aborting),
        transition_mode: transition_mode.unwrap_or_default().kernel(),
        transition_parameters,
        transition_parameter_count: params.len() as u8,
    })
}

impl MovePathBody {
    /// The kernel's table, checked entry by entry with the kernel's rules for this group's
    /// axis count.
    pub fn to_table(&self, axes: usize, planar: bool) -> AppResult<PathTable> {
        if self.entries.is_empty() || self.entries.len() > MAX_PATH_ENTRIES {
            return Err(coded("entries".into(), motion::ErrorId::PATH_TOO_LONG));
        }
        let mut entries = Vec::with_capacity(self.entries.len());
        for (i, e) in self.entries.iter().enumerate() {
            let field = |name: &str| format!("entries[{i}].{name}");
            let count = |name: &str| coded(field(name), motion::ErrorId::POSITION_COUNT_INVALID);
            let too_many_params = || {
                coded(
                    field("transition_parameters"),
                    motion::ErrorId::TRANSITION_MODE_INVALID,
                )
            };
            entries.push(match e {
                PathEntryDto::Linear {
                    position,
                    velocity,
                    acceleration,
                    deceleration,
                    jerk,
                    buffer_mode,
                    transition_mode,
                    transition_parameters,
                    invoke_id,
                } => {
                    let (position, count_) = point(position).ok_or_else(|| count("position"))?;
                    PathEntry::Linear {
                        position,
                        count: count_,
                        motion: motion(
                            [*velocity, *acceleration, *deceleration, *jerk],
                            *buffer_mode,
                            *transition_mode,
                            transition_parameters,
                        )
                        .ok_or_else(too_many_params)?,
                        invoke_id: *invoke_id,
                    }
                }
                PathEntryDto::Circular {
                    circ_mode,
                    aux_point,
                    end_point,
                    path_choice,
                    velocity,
                    acceleration,
                    deceleration,
                    jerk,
                    buffer_mode,
                    transition_mode,
                    transition_parameters,
                    invoke_id,
                } => {
                    let (end_point, count_) = point(end_point).ok_or_else(|| count("end_point"))?;
                    let aux: [f64; 3] = aux_point.as_slice().try_into().map_err(|_| {
                        AppError::field(&field("aux_point"), "X, Y and Z: three numbers")
                    })?;
                    PathEntry::Circular {
                        mode: *circ_mode,
                        aux,
                        end_point,
                        count: count_,
                        path_choice: path_choice.unwrap_or_default(),
                        motion: motion(
                            [*velocity, *acceleration, *deceleration, *jerk],
                            *buffer_mode,
                            *transition_mode,
                            transition_parameters,
                        )
                        .ok_or_else(too_many_params)?,
                        invoke_id: *invoke_id,
                    }
                }
                PathEntryDto::Blocker {
                    blocker_id,
                    buffer_mode,
                    invoke_id,
                } => PathEntry::Blocker {
                    blocker_id: *blocker_id,
                    buffer_mode: buffer_mode.unwrap_or(BufferMode::Buffered),
                    invoke_id: *invoke_id,
                },
                PathEntryDto::Dwell {
                    time,
                    buffer_mode,
                    invoke_id,
                } => PathEntry::Dwell {
                    time: *time,
                    buffer_mode: buffer_mode.unwrap_or(BufferMode::Buffered),
                    invoke_id: *invoke_id,
                },
                PathEntryDto::CoordinateTransform {
                    translation,
                    rotation,
                } => {
                    let three = |name: &str, v: &[f64]| {
                        xyz(v).ok_or_else(|| {
                            AppError::field(&field(name), "X, Y and Z: three numbers")
                        })
                    };
                    PathEntry::CoordinateTransform {
                        transform: motion::group::CoordTransform {
                            translation: three("translation", translation)?,
                            rotation: three("rotation", rotation)?,
                        },
                    }
                }
            });
        }
        // Beyond ±1e12 an f64 position has no useful resolution and lengths could overflow to
        // infinity inside the planner: refused here, as for an axis's positions.
        let mut c = Check::default();
        for (i, e) in self.entries.iter().enumerate() {
            let field = |name: &str, j: usize| format!("entries[{i}].{name}[{j}]");
            let vectors: [(&str, &[f64]); 4] = match e {
                PathEntryDto::Linear {
                    position,
                    transition_parameters,
                    ..
                } => [
                    ("position", position),
                    ("transition_parameters", transition_parameters),
                    ("", &[]),
                    ("", &[]),
                ],
                PathEntryDto::Circular {
                    aux_point,
                    end_point,
                    transition_parameters,
                    ..
                } => [
                    ("aux_point", aux_point),
                    ("end_point", end_point),
                    ("transition_parameters", transition_parameters),
                    ("", &[]),
                ],
                PathEntryDto::Dwell { time, .. } => {
                    if *time > crate::model::MAX_MAGNITUDE {
                        c.fail(&format!("entries[{i}].time"), "at most 1e12 s");
                    }
                    [("", &[]), ("", &[]), ("", &[]), ("", &[])]
                }
                PathEntryDto::Blocker { .. } => [("", &[]), ("", &[]), ("", &[]), ("", &[])],
                PathEntryDto::CoordinateTransform {
                    translation,
                    rotation,
                } => [
                    ("translation", translation),
                    ("rotation", rotation),
                    ("", &[]),
                    ("", &[]),
                ],
            };
            for (name, v) in vectors {
                for (j, x) in v.iter().enumerate() {
                    c.finite(&field(name, j), *x);
                }
            }
        }
        c.done(())?;
        let table = PathTable { entries };
        table
            .check(axes, planar)
            .map_err(|(i, f, id)| coded(format!("entries[{i}].{f}"), id))?;
        Ok(table)
    }

    pub fn to_order(&self, _: &Registry, group: &GroupEntry) -> AppResult<GroupOrder> {
        let table = self.to_table(group.config.axis_count(), group.config.convention.planar())?;
        Ok(GroupOrder::Path(Box::new(table)))
    }
}
