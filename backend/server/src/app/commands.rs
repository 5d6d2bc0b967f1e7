//! The command history: each tracked command's record, its events and its end, as the pump
//! applies the cycle thread's events.

use std::collections::{HashMap, VecDeque};

use motion::{BlockResult, CommandEvent, CommandId, ErrorId, FbOutputs, Target};
use serde::Serialize;

use crate::model::{Block, ProbeResult};
use crate::model::{ClientInfo, CommandEventDto, CommandResource, CommandState};
use crate::store::{self, AuditEntry};

/// How many commands `GET /commands` remembers.
pub const HISTORY: usize = 2000;
const EVENTS_PER_COMMAND: usize = 64;

pub struct CommandRecord {
    pub id: CommandId,
    pub axis_id: i64,
    pub axis_name: String,
    /// What it addresses (its axis; `axis_id`/`axis_name` are that axis as the API shows it).
    pub target: Target,
    /// A group's command: the group's id and name (`axis_id` 0, `axis_name` empty).
    pub group: Option<(i64, String)>,
    /// Its catalogue entry (name, milestone, flags).
    pub block: &'static Block,
    /// An MC_Stop: it holds its axis locked until released.
    pub locks_axis: bool,
    /// An MC_Reset: what leaves error_stop (a wait for it does not end there).
    pub resets_axis: bool,
    pub parameters: serde_json::Value,
    pub client: ClientInfo,
    pub submitted_at: String,
    pub accepted: bool,
    pub accepted_cycle: u64,
    pub outputs: FbOutputs,
    pub last_cycle: u64,
    pub finished_at: Option<String>,
    pub events: VecDeque<CommandEventDto>,
    /// The audit entry of its end, when it ended before its acceptance was recorded.
    pub final_audit: Option<AuditEntry>,
    /// What the block ended Done with (MC_TouchProbe's `MC_TouchProbeRecordedData`), from its
    /// Done event.
    pub result: Option<BlockResult>,
}

impl CommandRecord {
    pub fn is_final(&self) -> bool {
        !self.outputs.busy && !self.events.is_empty()
    }
    pub fn view(&self) -> CommandResource {
        let o = &self.outputs;
        CommandResource {
            id: self.id,
            axis: self.group.is_none().then(|| self.axis_name.clone()),
            axis_id: self.group.is_none().then_some(self.axis_id),
            group: self.group.as_ref().map(|g| g.1.clone()),
            group_id: self.group.as_ref().map(|g| g.0),
            command: self.block.name,
            parameters: self.parameters.clone(),
            state: CommandState::of(o),
            is_final: self.is_final(),
            outputs: *o,
            error_code: (o.error_id != 0).then(|| ErrorId(o.error_id).code()),
            accepted_cycle: self.accepted_cycle,
            last_cycle: self.last_cycle,
            submitted_at: self.submitted_at.clone(),
            finished_at: self.finished_at.clone(),
            client: self.client.clone(),
            events: self.events.iter().copied().collect(),
            result: self.result.map(|BlockResult::Probe(p)| ProbeResult {
                recorded_position: p.recorded_position,
                absolute_position: p.absolute_position,
                modulo_position: p.modulo_position,
                counter: p.counter,
            }),
            wait: None,
        }
    }
}

#[derive(Default)]
pub struct CommandStore {
    pub map: HashMap<CommandId, CommandRecord>,
    pub order: VecDeque<CommandId>,
}

impl CommandStore {
    pub(crate) fn insert(&mut self, r: CommandRecord) {
        while self.map.len() >= HISTORY {
            // Forget the oldest finished command (or the oldest at all if none has finished).
            let pos = self
                .order
                .iter()
                .position(|id| self.map.get(id).is_none_or(|r| r.is_final()))
                .unwrap_or(0);
            if let Some(id) = self.order.remove(pos) {
                self.map.remove(&id);
            } else {
                break;
            }
        }
        self.order.push_back(r.id);
        self.map.insert(r.id, r);
    }
    pub(crate) fn remove(&mut self, id: CommandId) {
        if self.map.remove(&id).is_some() {
            self.order.retain(|x| *x != id);
        }
    }
}

/// A change of a command's outputs, for websocket subscribers and waiters (the websocket's
/// `command_event` notification).
#[derive(Clone, Debug, Serialize, utoipa::ToSchema)]
pub struct CommandNotice {
    pub command: CommandId,
    pub axis: String,
    /// The group a group's command addresses (`axis` is empty then).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
    pub name: &'static str,
    pub cycle: u64,
    pub state: CommandState,
    #[serde(rename = "final")]
    pub is_final: bool,
    pub outputs: FbOutputs,
}

/// The audit entry of a command that has ended, naming the client as its submission does.
pub(super) fn final_audit(n: &CommandNotice, client: &ClientInfo) -> AuditEntry {
    AuditEntry {
        at: store::cycle_rfc3339(n.cycle),
        client_addr: (!client.addr.is_empty()).then(|| client.addr.clone()),
        client_id: client.id.clone(),
        principal: client.principal.clone(),
        action: "command.final".into(),
        target: Some(n.group.clone().unwrap_or_else(|| n.axis.clone())),
        command_id: Some(n.command),
        detail: serde_json::to_string(n).unwrap_or_default(),
        outcome: Some(match n.state {
            CommandState::Error => format!("error:{}", ErrorId(n.outputs.error_id).code()),
            s => serde_json::to_value(s)
                .ok()
                .and_then(|v| v.as_str().map(String::from))
                .unwrap_or_default(),
        }),
        idempotency_key: None,
    }
}

pub(super) fn apply_event(store: &mut CommandStore, ev: &CommandEvent) -> Option<CommandNotice> {
    let r = store.map.get_mut(&ev.command)?;
    r.outputs = ev.outputs;
    r.last_cycle = ev.cycle;
    if r.block.has_result && ev.result.is_some() {
        r.result = ev.result;
    }
    if r.events.len() == EVENTS_PER_COMMAND {
        r.events.pop_front();
    }
    r.events.push_back(CommandEventDto {
        cycle: ev.cycle,
        outputs: ev.outputs,
    });
    if r.is_final() && r.finished_at.is_none() {
        r.finished_at = Some(store::cycle_rfc3339(ev.cycle));
    }
    Some(CommandNotice {
        command: r.id,
        axis: r.axis_name.clone(),
        group: r.group.as_ref().map(|g| g.1.clone()),
        name: r.block.name,
        cycle: ev.cycle,
        state: CommandState::of(&ev.outputs),
        is_final: !ev.outputs.busy,
        outputs: ev.outputs,
    })
}
