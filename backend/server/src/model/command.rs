//! A command as the API shows it (the command resource, its state, events, result and the wait
//! that answered it), where it came from, and a catalogue entry as data ([`Block`]).

use motion::FbOutputs;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::auth::Role;

/// A command's life as the API shows it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum CommandState {
    Busy,
    Active,
    Done,
    Aborted,
    Error,
}

impl CommandState {
    pub fn of(o: &FbOutputs) -> Self {
        if o.error {
            CommandState::Error
        } else if o.command_aborted {
            CommandState::Aborted
        } else if o.done || !o.busy {
            CommandState::Done
        } else if o.active {
            CommandState::Active
        } else {
            CommandState::Busy
        }
    }
}

/// A change of a command's outputs.
#[derive(Clone, Copy, Debug, Serialize, ToSchema)]
#[schema(example = json!({"cycle": 1200, "outputs": {"busy": true, "active": true, "done": false, "command_aborted": false,
    "error": false, "error_id": 0, "in_velocity": false, "in_gear": false, "in_sync": false, "in_end_velocity": false, "in_torque": false, "status": false,
    "warning": false, "warning_id": 0}}))]
pub struct CommandEventDto {
    /// The kernel cycle it happened in.
    pub cycle: u64,
    pub outputs: FbOutputs,
}

/// `MC_TouchProbeRecordedData` of a done probe cycle.
#[derive(Clone, Copy, Debug, Serialize, ToSchema)]
#[schema(example = json!({"recorded_position": 5.0, "absolute_position": 365.0, "modulo_position": 5.0, "counter": 1}))]
pub struct ProbeResult {
    /// Absolute or modulo, as the probe cycle asked (`modulo_positions`).
    pub recorded_position: f64,
    pub absolute_position: f64,
    pub modulo_position: f64,
    /// Edges recorded on the axis so far (this one included).
    pub counter: u32,
}

/// Where a command came from.
#[derive(Clone, Debug, Default, Serialize, ToSchema)]
#[schema(example = json!({"addr": "127.0.0.1:50312", "id": "line-3-mes", "via": "rest"}))]
pub struct ClientInfo {
    /// Remote address.
    pub addr: String,
    /// The `X-Client-Id` header, if sent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
    /// `rest` or `websocket`.
    pub via: &'static str,
    /// `user:NAME` or `token:NAME`, when authentication is enabled.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub principal: Option<String>,
    /// Who it is (role, credential), when authentication is enabled.
    #[serde(skip)]
    #[schema(ignore)]
    pub identity: Option<crate::auth::Principal>,
}

impl ClientInfo {
    /// The client as the holder of the machine's control knows it: its principal and its
    /// `X-Client-Id` (`None` when it has neither).
    pub fn control_key(&self) -> Option<String> {
        match (&self.principal, &self.id) {
            (None, None) => None,
            (p, id) => Some(format!(
                "{}/{}",
                p.as_deref().unwrap_or(""),
                id.as_deref().unwrap_or("")
            )),
        }
    }
}

#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "id": 42, "axis": "x", "axis_id": 1, "command": "move-absolute",
    "parameters": {"position": 100.0, "velocity": 200.0},
    "state": "done", "final": true,
    "outputs": {"busy": false, "active": false, "done": true, "command_aborted": false, "error": false,
                "error_id": 0, "in_velocity": false, "in_gear": false, "in_sync": false, "in_end_velocity": false, "in_torque": false, "status": false,
                "warning": false, "warning_id": 0},
    "accepted_cycle": 1200, "last_cycle": 1873,
    "submitted_at": "2025-01-01T12:00:00.000Z", "finished_at": "2025-01-01T12:00:00.673Z",
    "client": {"addr": "127.0.0.1:50312", "via": "rest"},
    "events": [{"cycle": 1200, "outputs": {"busy": true, "active": true, "done": false, "command_aborted": false,
                "error": false, "error_id": 0, "in_velocity": false, "in_gear": false, "in_sync": false, "in_end_velocity": false, "in_torque": false, "status": false,
                "warning": false, "warning_id": 0}}]
}))]
pub struct CommandResource {
    pub id: u64,
    /// The axis it addresses (absent for a group's command: see `group`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_id: Option<i64>,
    /// The axis group it addresses (a group's block).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub group_id: Option<i64>,
    /// kebab-case command name (the REST endpoint).
    pub command: &'static str,
    /// The request body as given.
    #[schema(value_type = Object)]
    pub parameters: serde_json::Value,
    pub state: CommandState,
    /// Busy has fallen: the outputs no longer change.
    #[serde(rename = "final")]
    pub is_final: bool,
    pub outputs: FbOutputs,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_code: Option<&'static str>,
    /// The cycle the command took effect in (the cycle of its first event).
    pub accepted_cycle: u64,
    /// The cycle of its latest output change.
    pub last_cycle: u64,
    pub submitted_at: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finished_at: Option<String>,
    pub client: ClientInfo,
    /// Output changes in order (the most recent 64).
    pub events: Vec<CommandEventDto>,
    /// What a done `touch-probe` recorded (MC_TouchProbe's RecordedPosition and
    /// RecordedData); absent for other blocks and before it is done.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub result: Option<ProbeResult>,
    /// With `?wait=true`: whether the answer comes at the milestone, and if not why — the
    /// command may still be busy (a power waiting on an axis in error_stop, a move still
    /// running at the timeout). Absent without `wait`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wait: Option<WaitOutcome>,
}

/// Where a `?wait=true` request answers for a command that stays busy (besides its end:
/// Done, Error or CommandAborted): the output that says the block has arrived (PLCopen's
/// InVelocity, InGear, InEndVelocity; a power's Status). Each catalogue entry names its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum Milestone {
    /// Only its end (Done, Error, CommandAborted).
    Done,
    InVelocity,
    InGear,
    /// MC_CamIn: coupled and the cam active.
    InSync,
    InEndVelocity,
    /// MC_Power's Status: the axis is enabled.
    Status,
    /// An Enable-type block is active (a compensation applied from now on).
    Active,
    /// MC_TorqueControl: the torque built up, no velocity limit active.
    InTorque,
}

impl Milestone {
    /// Whether outputs `o` are at this milestone or the command's end.
    pub fn reached(self, o: &FbOutputs) -> bool {
        let arrived = match self {
            Milestone::Done => false,
            Milestone::InVelocity => o.in_velocity,
            Milestone::InGear => o.in_gear,
            Milestone::InSync => o.in_sync,
            Milestone::InEndVelocity => o.in_end_velocity,
            Milestone::Status => o.status,
            Milestone::Active => o.active,
            Milestone::InTorque => o.in_torque,
        };
        o.done || o.error || o.command_aborted || arrived
    }
}

/// How a `?wait=true` ended.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"milestone": "status", "reached": false, "reason": "axis_error_stop",
    "axis_state": "error_stop", "axis_error_id": 28688, "axis_error_code": "drive_fault"}))]
pub struct WaitOutcome {
    /// The output waited for besides the command's end (`done`: only the end).
    pub milestone: Milestone,
    /// The command reached its milestone or its end (done, error or aborted: see `state`).
    pub reached: bool,
    /// Why not: `timeout` (still on its way at `timeout_ms`), `axis_error_stop` (the axis is
    /// in error_stop: nothing reaches the milestone before a reset), `axis_disabled`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<&'static str>,
    /// The axis's state when the answer was made.
    pub axis_state: motion::AxisState,
    /// The axis's error (0: none) and its code.
    pub axis_error_id: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_error_code: Option<&'static str>,
}

/// A catalogue entry as data: what the server knows of a block besides its body. The entries
/// are the block families' (`crate::blocks`); `crate::api::blocks` makes their endpoints.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Block {
    /// The endpoint's last segment and the websocket method.
    pub name: &'static str,
    /// What it addresses (an axis or a group): the same name may be a block of each.
    pub at: At,
    /// The REST path: the entry's route prefix (`/api/v1/axes/{axis}/`: the block addresses an
    /// axis) and its name.
    pub path: &'static str,
    /// The schema name of its body (REST body = websocket params without `axis`).
    pub body: &'static str,
    pub role: Role,
    pub milestone: Milestone,
    pub summary: &'static str,
    /// Done with a result (MC_TouchProbe's recorded data), shown as the command's `result`.
    pub has_result: bool,
    /// Runs only while renewed (MC_Jog's dead-man): a websocket that sent it holds it and
    /// releases it when it closes.
    pub keepalive: bool,
    /// Accepted from a client that does not hold the control while another does: it ends
    /// motion or moves nothing (MC_Stop, MC_Halt, MC_TouchProbe …; MC_Power's disabling is
    /// recognised by its command, `service::control::stops_motion`).
    pub lease_free: bool,
}

/// The kind of target a block addresses (the catalogue entry's route prefix).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum At {
    /// `/api/v1/axes/{axis}/…`; the websocket method's `axis`.
    Axes,
    /// `/api/v1/groups/{group}/…`; the websocket method's `group`.
    Groups,
}

impl Block {
    /// An entry without flags (the catalogue sets the ones an entry names).
    pub const PLAIN: Block = Block {
        name: "",
        at: At::Axes,
        path: "",
        body: "",
        role: Role::Operator,
        milestone: Milestone::Done,
        summary: "",
        has_result: false,
        keepalive: false,
        lease_free: false,
    };
}
