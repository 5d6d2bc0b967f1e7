//! Axis groups (TwinCAT TF5420 CM group) as the API shows them: the configuration resource
//! and the live status (`NcToPlc` of the group, MC_GroupReadStatus).

use std::collections::BTreeMap;

use motion::group::{AxesConvention, GroupConfig, GroupRole, GroupState, PathDynamics};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// One member of a group's configuration: the axis that takes a role (`IDENT_IN_GROUP_REF`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"role": "x", "axis": "x"}))]
pub struct GroupMemberBody {
    pub role: GroupRole,
    /// The axis: its id (all digits) or its name.
    #[schema(min_length = 1, max_length = 64, example = "x")]
    pub axis: String,
}

/// A group's configuration (`POST /groups`, `PUT /groups/{group}`; the configuration
/// document's `groups[]`). Every field but `name` has a default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"name": "xy", "convention": "xy", "axes": [{"role": "x", "axis": "x"}, {"role": "y", "axis": "y"}]}))]
pub struct GroupBody {
    /// 1..16 (`POST`: the lowest free one when left out; `PUT`: the group's own). The kernel's
    /// group slot is id − 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = 1, maximum = 16)]
    pub id: Option<i64>,
    /// Unique name: a letter or `_`, then letters, digits, `_` or `-` (at most 64).
    #[schema(pattern = "^[A-Za-z_][A-Za-z0-9_-]{0,63}$")]
    pub name: String,
    /// Spatial Axes Convention (default `xy`).
    #[serde(default)]
    pub convention: AxesConvention,
    /// Additional Axes Count, 0..8 (ADDAX1..n; default 0).
    #[serde(default)]
    #[schema(minimum = 0, maximum = 8, default = 0)]
    pub additional_axes: u8,
    /// The axes added (MC_AddAxisToGroup) whenever the group is put in force (created,
    /// replaced, motiond started): each role of the convention and ADDAX1..n at most once,
    /// each axis in at most one group. Default none.
    #[serde(default)]
    #[schema(max_items = 12)]
    pub axes: Vec<GroupMemberBody>,
    /// What `"default"` means in a path entry, halt or stop (default v 100, a/d 1000, j 10000).
    #[serde(default = "default_dynamics")]
    pub default_dynamics: PathDynamics,
    /// What `"maximum"` means, and the cap of every commanded path value (default v 1000,
    /// a/d 10000, j 1e6).
    #[serde(default = "maximum_dynamics")]
    pub maximum_dynamics: PathDynamics,
    /// Time Override Ramp Time (s), 0..10 (default 0.1).
    #[serde(default = "override_ramp_time")]
    #[schema(minimum = 0, maximum = 10, default = 0.1)]
    pub override_ramp_time: f64,
}

fn default_dynamics() -> PathDynamics {
    GroupConfig::default().default_dynamics
}

fn maximum_dynamics() -> PathDynamics {
    GroupConfig::default().maximum_dynamics
}

fn override_ramp_time() -> f64 {
    GroupConfig::default().override_ramp_time
}

impl GroupBody {
    /// The kernel's configuration (validated by `GroupConfig::validate`).
    pub fn config(&self) -> GroupConfig {
        GroupConfig {
            convention: self.convention,
            additional_axes: self.additional_axes,
            default_dynamics: self.default_dynamics,
            maximum_dynamics: self.maximum_dynamics,
            override_ramp_time: self.override_ramp_time,
        }
    }
}

/// A configured member as the API shows it.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"role": "x", "axis": "x", "axis_id": 1}))]
pub struct GroupMemberResource {
    pub role: GroupRole,
    pub axis: String,
    pub axis_id: i64,
}

/// A group: its configuration and, while it is in the cycle, its live status.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"id": 1, "name": "xy", "convention": "xy", "additional_axes": 0,
    "axes": [{"role": "x", "axis": "x", "axis_id": 1}, {"role": "y", "axis": "y", "axis_id": 2}],
    "default_dynamics": {"velocity": 100.0, "acceleration": 1000.0, "deceleration": 1000.0, "jerk": 10000.0},
    "maximum_dynamics": {"velocity": 500.0, "acceleration": 2500.0, "deceleration": 2500.0, "jerk": 25000.0},
    "override_ramp_time": 0.1, "updated_at": "2026-11-27T19:00:25.160Z",
    "status": {"cycle": 1200, "state": "disabled", "enable_requested": false, "error_id": 0,
        "members": {"x": "x", "y": "y"}, "axes_count": 2, "all_axes_standing": true, "override_factor": 1.0,
        "actual_override": 1.0, "path_velocity": 0.0, "path_acceleration": 0.0, "path_position": 0.0,
        "entry_index": 0, "invoke_id": 0, "in_blending_segment": false, "remaining_distance": 0.0,
        "remaining_time": 0.0, "blocked": false, "blocker_id": 0, "queued_entries": 0,
        "position": {"x": 0.0, "y": 0.0}, "actual_position": {"x": 0.0, "y": 0.0},
        "frame": {"translation": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 0.0]}, "prepared_paths": 0,
        "tracking_velocity": 0.0}}))]
pub struct GroupResource {
    pub id: i64,
    pub name: String,
    pub convention: AxesConvention,
    pub additional_axes: u8,
    pub axes: Vec<GroupMemberResource>,
    pub default_dynamics: PathDynamics,
    pub maximum_dynamics: PathDynamics,
    pub override_ramp_time: f64,
    pub updated_at: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub status: Option<GroupStatusDto>,
}

/// A group's live status (TF5420 `NcToPlc`, MC_GroupReadStatus, MC_GroupReadError,
/// MC_GroupReadBlockerStatus), as of `cycle`.
#[derive(Clone, Debug, Default, Serialize, ToSchema)]
#[schema(example = json!({"cycle": 1200, "state": "standby", "enable_requested": true, "error_id": 0,
    "members": {"x": "x", "y": "y"}, "axes_count": 2, "all_axes_standing": true, "override_factor": 1.0,
    "actual_override": 1.0, "path_velocity": 0.0, "path_acceleration": 0.0, "path_position": 0.0,
    "entry_index": 0, "invoke_id": 0, "in_blending_segment": false, "remaining_distance": 0.0,
    "remaining_time": 0.0, "blocked": false, "blocker_id": 0, "queued_entries": 0,
    "position": {"x": 0.0, "y": 0.0}, "actual_position": {"x": 0.0, "y": 0.0},
        "frame": {"translation": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 0.0]}, "prepared_paths": 0,
        "tracking_velocity": 0.0}))]
pub struct GroupStatusDto {
    pub cycle: u64,
    /// MC_GROUP_STATE (error_stop with `enable_requested` false is GroupErrorDisabled).
    pub state: GroupState,
    /// `Flags.IsEnableRequested`.
    pub enable_requested: bool,
    /// `GroupErrorId` (0: none).
    pub error_id: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_code: Option<&'static str>,
    /// The member axis of each role (its name), as the group has them now.
    pub members: BTreeMap<String, String>,
    /// `GroupAxesCount`.
    pub axes_count: u8,
    /// `AllAxesStanding`: every member at v = 0 and a = 0.
    pub all_axes_standing: bool,
    /// Override asked for (MC_GroupSetOverride's VelFactor, clamped) and in effect
    /// (`ActOverrideFactor`), 0..1.
    pub override_factor: f64,
    pub actual_override: f64,
    /// `PathVelo` (path units/s) and the path acceleration.
    pub path_velocity: f64,
    pub path_acceleration: f64,
    /// Path length travelled since the group last stood idle.
    pub path_position: f64,
    /// The MovePath command running (absent: none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command: Option<u64>,
    /// Its entry (index in its table) and that entry's `InvokeId`.
    pub entry_index: u32,
    pub invoke_id: u32,
    /// `IsInBlendingSegment`.
    pub in_blending_segment: bool,
    /// `RemainingCartesianDistanceActiveJob` and `RemainingTimeActiveJob` (s).
    pub remaining_distance: f64,
    pub remaining_time: f64,
    /// MC_GroupReadBlockerStatus: `Blocked` and `BlockerId`.
    pub blocked: bool,
    pub blocker_id: u32,
    /// Entries queued (the running one included).
    pub queued_entries: u32,
    /// The group's set point of each role of its configuration.
    pub position: BTreeMap<String, f64>,
    /// The member axes' actual positions (their drives' feedback) by role, of the same cycle.
    pub actual_position: BTreeMap<String, f64>,
    /// The coordinate frame later MovePaths are read in (MC_SetCoordinateTransform or a
    /// table's frame entry; a halt or stop clears it).
    pub frame: FrameDto,
    /// MovePaths whose entries were built off the cycle thread and taken as built (the
    /// others were built in the cycle: an aborting path while moving, a queue that changed).
    pub prepared_paths: u64,
    /// MC_TrackConveyorBelt: the conveyor the group follows (absent: none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tracking: Option<TrackingStatusDto>,
    /// The set point's velocity along conveyors (a tracking still braking to rest included).
    pub tracking_velocity: f64,
}

/// The conveyor tracking of a group (MC_TrackConveyorBelt's outputs, `NcToPlc`).
#[derive(Clone, Debug, Default, Serialize, ToSchema)]
#[schema(example = json!({"conveyor": "belt", "command": 57, "in_sync": true, "conveyor_error": false,
    "remaining_distance_to_sync": 0.0, "remaining_time_to_sync": 0.0}))]
pub struct TrackingStatusDto {
    /// The conveyor axis's name.
    pub conveyor: String,
    /// The MC_TrackConveyorBelt command.
    pub command: u64,
    /// `InSync`.
    pub in_sync: bool,
    /// The conveyor is in error or gone: the path goes on, the client decides (TF5420 §4.1).
    pub conveyor_error: bool,
    /// `RemainingCartesianTimeToSync` (despite its name a distance) and
    /// `RemainingTimeToSync` (s).
    pub remaining_distance_to_sync: f64,
    pub remaining_time_to_sync: f64,
}

/// A coordinate frame: a shift and DIN 9300 Z″Y′X rotations in degrees.
#[derive(Clone, Copy, Debug, Default, Serialize, ToSchema)]
#[schema(example = json!({"translation": [100.0, 50.0, 0.0], "rotation": [0.0, 0.0, 90.0]}))]
pub struct FrameDto {
    pub translation: [f64; 3],
    /// [about X, about Y, about Z] in degrees.
    pub rotation: [f64; 3],
}

/// A role as JSON names it (`x`, `addax1` …).
pub fn role_name(r: GroupRole) -> String {
    serde_json::to_value(r)
        .ok()
        .and_then(|v| v.as_str().map(str::to_owned))
        .unwrap_or_default()
}

/// MC_GroupReadError.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"group": "xy", "cycle": 1200, "valid": true, "error": false, "error_id": 0}))]
pub struct GroupErrorRead {
    pub group: String,
    pub cycle: u64,
    /// `Valid`: the outputs are valid (the group is in the cycle).
    pub valid: bool,
    /// Whether the group has an error (`GroupErrorId` ≠ 0).
    pub error: bool,
    /// `GroupErrorId`.
    pub error_id: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_code: Option<&'static str>,
}

/// MC_GroupReadBlockerStatus.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"group": "xy", "cycle": 1200, "valid": true, "blocked": true, "blocker_id": 7}))]
pub struct GroupBlockerRead {
    pub group: String,
    pub cycle: u64,
    /// `Valid` (a CM group in the cycle).
    pub valid: bool,
    /// `Blocked`: a blocker holds the path.
    pub blocked: bool,
    /// `BlockerId` (0: none).
    pub blocker_id: u32,
}

/// What a group block's body becomes: a kernel command, or MC_MovePath's table (handed to the
/// cycle thread as a box and freed off it).
pub enum GroupOrder {
    Command(motion::CommandKind),
    Path(Box<motion::group::PathTable>),
}

/// One member of an analysed path: its axis's set values over the run.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"role": "x", "axis": "x", "position": [0.0, 0.5, 100.0],
    "velocity": [0.0, 40.0, 0.0], "acceleration": [0.0, 4000.0, 0.0],
    "max_velocity": 200.0, "max_acceleration": 5000.0}))]
pub struct PlannedAxisDto {
    pub role: GroupRole,
    /// The axis of the role (its name).
    pub axis: String,
    /// Set position, velocity and acceleration at each sample's `t`.
    pub position: Vec<f64>,
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
    /// The largest |velocity| and |acceleration| over the whole run (every cycle, not only the
    /// samples).
    pub max_velocity: f64,
    pub max_acceleration: f64,
}

/// What a path table will do, planned by the group's own planner in virtual time (ideal
/// drives, override 100 %, blockers released as they are reached): sample columns of equal
/// length, and what the run comes to. Nothing was stored or moved.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"group": "xy", "cycle_time": 0.001, "start": {"x": 0.0, "y": 0.0},
    "duration": 1.62, "length": 278.54, "truncated": false,
    "t": [0.001, 0.81, 1.62], "path_position": [0.0001, 150.0, 278.54],
    "path_velocity": [0.2, 200.0, 0.0], "path_acceleration": [200.0, 0.0, 0.0],
    "entry": [0, 1, 2], "in_blend": [false, false, false],
    "axes": [{"role": "x", "axis": "x", "position": [0.0001, 140.0, 150.0], "velocity": [0.2, 80.0, 0.0],
        "acceleration": [200.0, 0.0, 0.0], "max_velocity": 200.0, "max_acceleration": 2000.0},
      {"role": "y", "axis": "y", "position": [0.0, 20.0, 150.0], "velocity": [0.0, 180.0, 0.0],
        "acceleration": [0.0, 0.0, 0.0], "max_velocity": 200.0, "max_acceleration": 2000.0}]}))]
pub struct PathAnalysisResource {
    /// The group's name.
    pub group: String,
    /// The cycle the run was planned in (s).
    pub cycle_time: f64,
    /// Where the run started, per role.
    pub start: BTreeMap<String, f64>,
    /// Time until the last entry is done (s; the time analysed when `truncated`).
    pub duration: f64,
    /// The path length travelled.
    pub length: f64,
    /// The path did not end within `max_seconds`.
    pub truncated: bool,
    /// Time of each sample since the start (s).
    pub t: Vec<f64>,
    /// Path position, velocity and acceleration at each sample.
    pub path_position: Vec<f64>,
    pub path_velocity: Vec<f64>,
    pub path_acceleration: Vec<f64>,
    /// The entry running (index in `entries`) and whether a corner blend runs.
    pub entry: Vec<u32>,
    pub in_blend: Vec<bool>,
    /// The members in the group's axis order.
    pub axes: Vec<PlannedAxisDto>,
}
