//! The async side's shared state: axis registry, command tracking, the pump that drains the
//! cycle thread's queues, the audit writer.

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::sync::{Arc, Mutex, RwLock};
use std::time::{Duration, Instant};

use motion::{
    Axis, AxisConfig, AxisParameters, AxisSlot, AxisStatus, Command, CommandEvent, CommandId,
    CommandKind, ErrorId, FbOutputs,
};
use serde::Serialize;
use sqlx::SqlitePool;
use tokio::sync::{broadcast, mpsc, oneshot};

use crate::cycle::{MAX_AXES, RealtimeGrant, Reply, Request, Shared, Snapshot};
use crate::error::{ApiError, ApiResult};
use crate::model::{AxisConfigDto, ClientInfo, CommandEventDto, CommandResource, CommandState};
use crate::params::{self, ParamValue};
use crate::scope::{NewRecording, Recordings, ScopeBusy, ScopeRecording};
use crate::sim::FieldError;
use crate::store::{self, AuditEntry};
use drives::{Drive, DriveConfig};

/// How many commands `GET /commands` remembers.
pub const HISTORY: usize = 2000;
const EVENTS_PER_COMMAND: usize = 64;
/// How long the async side waits for the cycle thread's verdict.
const VERDICT_TIMEOUT: Duration = Duration::from_secs(2);
/// How long a request may wait in the queue before the cycle thread drops it undone: shorter
/// than `VERDICT_TIMEOUT` by far more than the pump's period, so that a verdict the cycle thread
/// gives always reaches its waiting requester.
const REQUEST_TTL: Duration = Duration::from_millis(1500);

pub struct AxisEntry {
    pub id: i64,
    pub name: String,
    pub slot: AxisSlot,
    pub config: AxisConfigDto,
    /// Mirror of the parameters active in the kernel (base + persistent + runtime writes).
    pub params: AxisParameters,
    /// The persistent overlay.
    pub persistent: BTreeMap<u16, ParamValue>,
}

#[derive(Default)]
pub struct Registry {
    pub axes: BTreeMap<i64, AxisEntry>,
}

impl Registry {
    /// By id (all digits) or by name.
    pub fn find(&self, key: &str) -> Option<&AxisEntry> {
        match key.parse::<i64>() {
            Ok(id) => self.axes.get(&id),
            Err(_) => self.axes.values().find(|a| a.name == key),
        }
    }
    pub fn find_mut(&mut self, key: &str) -> Option<&mut AxisEntry> {
        match key.parse::<i64>() {
            Ok(id) => self.axes.get_mut(&id),
            Err(_) => self.axes.values_mut().find(|a| a.name == key),
        }
    }
    pub fn by_slot(&self, slot: AxisSlot) -> Option<&AxisEntry> {
        self.axes.values().find(|a| a.slot == slot)
    }
    pub fn free_slot(&self) -> Option<AxisSlot> {
        (0..MAX_AXES as AxisSlot).find(|s| self.axes.values().all(|a| a.slot != *s))
    }
}

pub struct CommandRecord {
    pub id: CommandId,
    pub axis_id: i64,
    pub axis_name: String,
    pub slot: AxisSlot,
    pub name: &'static str,
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
}

impl CommandRecord {
    pub fn is_final(&self) -> bool {
        !self.outputs.busy && !self.events.is_empty()
    }
    pub fn view(&self) -> CommandResource {
        let o = &self.outputs;
        CommandResource {
            id: self.id,
            axis: self.axis_name.clone(),
            axis_id: self.axis_id,
            command: self.name,
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
        }
    }
}

#[derive(Default)]
pub struct CommandStore {
    pub map: HashMap<CommandId, CommandRecord>,
    pub order: VecDeque<CommandId>,
}

impl CommandStore {
    fn insert(&mut self, r: CommandRecord) {
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
    fn remove(&mut self, id: CommandId) {
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
    pub name: &'static str,
    pub cycle: u64,
    pub state: CommandState,
    #[serde(rename = "final")]
    pub is_final: bool,
    pub outputs: FbOutputs,
}

pub struct SystemInfo {
    pub version: &'static str,
    pub cycle_time_s: f64,
    pub listen: String,
    pub db: String,
    pub realtime: RealtimeGrant,
    pub started: Instant,
    /// Where the commissioning UI's built files are (`--ui-dir`).
    pub ui_dir: std::path::PathBuf,
}

/// A status as a JSON object, shared by every websocket subscriber of that cycle.
pub type StatusJson = Arc<serde_json::Map<String, serde_json::Value>>;

pub struct AppState {
    pub shared: Arc<Shared>,
    snapshot: Mutex<triple_buffer::Output<Snapshot>>,
    /// Per slot: the status of the latest cycle already turned into JSON.
    status_json: Mutex<Vec<Option<(u64, StatusJson)>>>,
    pub registry: RwLock<Registry>,
    /// Serialises configuration changes (axes, parameters, import).
    pub config_lock: tokio::sync::Mutex<()>,
    pub commands: Mutex<CommandStore>,
    pending: Mutex<HashMap<u64, oneshot::Sender<Reply>>>,
    pub notices: broadcast::Sender<Arc<CommandNotice>>,
    next_id: AtomicU64,
    pub db: SqlitePool,
    audit_tx: mpsc::Sender<AuditEntry>,
    /// Audit rows lost (queue full, or not written after retries); shared with the writer.
    pub audit_dropped: Arc<AtomicU64>,
    pub info: SystemInfo,
    /// Scope recordings and the channel layout the cycle thread samples.
    pub scope: Mutex<Recordings>,
}

impl AppState {
    pub fn new(
        shared: Arc<Shared>,
        snapshot: triple_buffer::Output<Snapshot>,
        db: SqlitePool,
        first_command_id: u64,
        info: SystemInfo,
    ) -> (Arc<AppState>, mpsc::Receiver<AuditEntry>) {
        let (audit_tx, audit_rx) = mpsc::channel(8192);
        let scope = Mutex::new(Recordings::new(info.cycle_time_s, shared.period_ns));
        let state = AppState {
            scope,
            shared,
            snapshot: Mutex::new(snapshot),
            status_json: Mutex::new(vec![None; MAX_AXES]),
            registry: RwLock::new(Registry::default()),
            config_lock: tokio::sync::Mutex::new(()),
            commands: Mutex::new(CommandStore::default()),
            pending: Mutex::new(HashMap::new()),
            notices: broadcast::channel(4096).0,
            next_id: AtomicU64::new(first_command_id.max(1)),
            db,
            audit_tx,
            audit_dropped: Arc::new(AtomicU64::new(0)),
            info,
        };
        (Arc::new(state), audit_rx)
    }

    pub fn next_id(&self) -> u64 {
        self.next_id.fetch_add(1, Relaxed)
    }

    /// The latest published snapshot: its cycle and the status of one slot.
    pub fn status(&self, slot: AxisSlot) -> (u64, Option<AxisStatus>) {
        let mut out = self.snapshot.lock().unwrap();
        let s = out.read();
        (s.cycle, s.axes.get(slot as usize).copied().flatten())
    }

    /// The slot and name of an axis given by id or name (404 when there is none).
    pub fn axis_slot(&self, key: &str) -> ApiResult<(AxisSlot, String)> {
        let reg = self.registry.read().unwrap();
        let e = reg
            .find(key)
            .ok_or_else(|| ApiError::not_found("axis", key))?;
        Ok((e.slot, e.name.clone()))
    }

    /// A kernel status as the API shows it: the master named by its axis, not its slot.
    pub fn status_view(&self, status: AxisStatus) -> crate::model::LiveStatus {
        let master = status.master.and_then(|slot| {
            let reg = self.registry.read().unwrap();
            reg.by_slot(slot).map(|e| e.name.clone())
        });
        crate::model::LiveStatus { status, master }
    }

    /// The latest status of a slot as JSON, serialised once per cycle whoever asks.
    pub fn status_json(&self, slot: AxisSlot) -> Option<(u64, StatusJson)> {
        let (cycle, status) = self.status(slot);
        let status = status?;
        let mut cache = self.status_json.lock().unwrap();
        let entry = cache.get_mut(slot as usize)?;
        if let Some((c, j)) = entry {
            if *c == cycle {
                return Some((cycle, j.clone()));
            }
        }
        let view = self.status_view(status);
        let serde_json::Value::Object(map) = serde_json::to_value(view).ok()? else {
            return None;
        };
        let j = Arc::new(map);
        *entry = Some((cycle, j.clone()));
        Some((cycle, j))
    }

    pub fn with_snapshot<R>(&self, f: impl FnOnce(&Snapshot) -> R) -> R {
        let mut out = self.snapshot.lock().unwrap();
        f(out.read())
    }

    /// Moves whatever the cycle thread produced to where it is awaited. Runs every ms.
    pub fn drain(&self) {
        // Replies are taken first but completed only after the events: the cycle thread pushes
        // a submit's events before its reply, so a handler woken by its reply sees them.
        let mut replies = Vec::new();
        while let Some(r) = self.shared.replies.pop() {
            replies.push(r);
        }
        let mut notices = Vec::new();
        let mut audits = Vec::new();
        {
            let mut store = self.commands.lock().unwrap();
            while let Some(ev) = self.shared.events.pop() {
                let Some(n) = apply_event(&mut store, &ev) else {
                    continue;
                };
                if n.is_final {
                    if let Some(r) = store.map.get_mut(&n.command) {
                        let entry = final_audit(&n, &r.client);
                        if r.accepted {
                            audits.push(entry);
                        } else {
                            // Ended before its verdict was handled: `submit` writes this entry
                            // after the one of the submission.
                            r.final_audit = Some(entry);
                        }
                    }
                }
                notices.push(n);
            }
        }
        for e in audits {
            self.audit(e);
        }
        {
            let mut scope = self.scope.lock().unwrap();
            scope.feed(std::iter::from_fn(|| self.shared.scope_frames.pop()));
            if let Some(config) = scope.take_dirty() {
                // Nobody waits for this reply (ticket 0); a full queue is retried next time.
                let req = Request::ScopeConfig { ticket: 0, config };
                if self.shared.push(req).is_err() {
                    scope.handover_failed();
                }
            }
        }
        for n in notices {
            let _ = self.notices.send(Arc::new(n));
        }
        for r in replies {
            if let Some(tx) = self.pending.lock().unwrap().remove(&r.ticket) {
                let _ = tx.send(r);
            }
        }
        while let Some(g) = self.shared.garbage.pop() {
            drop(g);
        }
    }

    /// Queues an audit entry for the batching writer (motion commands are not delayed by the
    /// disk; configuration changes write their audit row in their own transaction instead).
    pub fn audit(&self, e: AuditEntry) {
        if self.audit_tx.try_send(e).is_err() {
            self.audit_dropped.fetch_add(1, Relaxed);
        }
    }

    async fn request(&self, ticket: u64, req: Request) -> ApiResult<Reply> {
        let (tx, rx) = oneshot::channel();
        self.pending.lock().unwrap().insert(ticket, tx);
        // Expires well before we stop waiting: a request we answer 503 for never acts later.
        if self.shared.push_expiring(req, REQUEST_TTL).is_err() {
            self.pending.lock().unwrap().remove(&ticket);
            return Err(ApiError::unavailable(
                "command_queue_full",
                "the command queue to the cycle thread is full; try again",
            ));
        }
        match tokio::time::timeout(VERDICT_TIMEOUT, rx).await {
            Ok(Ok(r)) => Ok(r),
            _ => {
                self.pending.lock().unwrap().remove(&ticket);
                Err(ApiError::unavailable(
                    "cycle_unavailable",
                    "the cycle thread did not answer",
                ))
            }
        }
    }

    /// Creates a scope recording: allocates its channels, hands the new sampling configuration
    /// to the cycle thread and waits until it is in effect (the recording's first cycle).
    pub async fn create_recording(&self, r: NewRecording) -> ApiResult<ScopeRecording> {
        let ticket = self.next_id();
        let (tx, rx) = oneshot::channel();
        let id = {
            let mut scope = self.scope.lock().unwrap();
            let (id, config) = scope.create(r).map_err(|e| match e {
                ScopeBusy::Channels { in_use, needed } => ApiError::conflict(
                    "scope_channels_busy",
                    format!(
                        "the scope samples at most {} signals at once: {in_use} are in use by \
                         active recordings and this one needs {needed} more; cancel one or \
                         wait until it is done",
                        crate::scope::SCOPE_CHANNELS
                    ),
                ),
                ScopeBusy::Recordings => ApiError::conflict(
                    "scope_busy",
                    format!(
                        "too many active recordings (at most {} recordings and {} values are \
                         kept); cancel one or wait until it is done",
                        crate::scope::MAX_RECORDINGS,
                        crate::scope::MAX_VALUES
                    ),
                ),
            })?;
            // Pushed under the scope lock so that configurations reach the cycle thread in the
            // order of their generations.
            self.pending.lock().unwrap().insert(ticket, tx);
            if self
                .shared
                .push(Request::ScopeConfig { ticket, config })
                .is_err()
            {
                self.pending.lock().unwrap().remove(&ticket);
                scope.abandon(id);
                return Err(ApiError::unavailable(
                    "command_queue_full",
                    "the command queue to the cycle thread is full; try again",
                ));
            }
            id
        };
        match tokio::time::timeout(VERDICT_TIMEOUT, rx).await {
            Ok(Ok(reply)) => {
                let mut scope = self.scope.lock().unwrap();
                scope.started(id, reply.cycle);
                scope.get(id, false).ok_or_else(|| {
                    ApiError::unavailable("scope_unavailable", "the recording was evicted")
                })
            }
            _ => {
                self.pending.lock().unwrap().remove(&ticket);
                self.scope.lock().unwrap().abandon(id);
                Err(ApiError::unavailable(
                    "cycle_unavailable",
                    "the cycle thread did not answer",
                ))
            }
        }
    }

    /// Sends a kernel command and waits for its verdict (not tracked as a command resource).
    pub async fn kernel_command(
        &self,
        slot: AxisSlot,
        kind: CommandKind,
    ) -> ApiResult<Result<u64, ErrorId>> {
        let id = self.next_id();
        let r = self
            .request(
                id,
                Request::Command(Command {
                    id,
                    axis: slot,
                    kind,
                }),
            )
            .await?;
        Ok(r.result.map(|_| r.cycle))
    }

    /// Hands a ready axis to the cycle thread.
    pub async fn install_axis(
        &self,
        slot: AxisSlot,
        axis: Box<Axis>,
        drive: Drive,
        require_disabled: bool,
    ) -> ApiResult<Result<(), ErrorId>> {
        let ticket = self.next_id();
        let r = self
            .request(
                ticket,
                Request::InsertAxis {
                    ticket,
                    slot,
                    axis,
                    drive,
                    require_disabled,
                },
            )
            .await?;
        Ok(r.result)
    }

    pub async fn uninstall_axis(
        &self,
        slot: AxisSlot,
        require_disabled: bool,
    ) -> ApiResult<Result<(), ErrorId>> {
        let ticket = self.next_id();
        let r = self
            .request(
                ticket,
                Request::RemoveAxis {
                    ticket,
                    slot,
                    require_disabled,
                },
            )
            .await?;
        if r.result.is_ok() {
            // The pump hands the smaller sampling configuration over.
            self.scope.lock().unwrap().axis_removed(slot);
        }
        Ok(r.result)
    }

    /// Releases a command (the falling edge of Execute/Enable) and audits it.
    pub async fn release(
        &self,
        slot: AxisSlot,
        id: CommandId,
        client: &ClientInfo,
    ) -> ApiResult<Result<u64, ErrorId>> {
        let result = self
            .kernel_command(slot, CommandKind::Release { target: id })
            .await?;
        self.audit(AuditEntry {
            at: store::now_rfc3339(),
            client_addr: (!client.addr.is_empty()).then(|| client.addr.clone()),
            client_id: client.id.clone(),
            action: "command.release".into(),
            target: Some(id.to_string()),
            command_id: Some(id),
            detail: serde_json::json!({"via": client.via}).to_string(),
            outcome: Some(match result {
                Ok(_) => "accepted".into(),
                Err(e) => format!("rejected:{}", e.code()),
            }),
        });
        Ok(result)
    }

    /// Hands a fault or disturbance to the simulated drive of a slot.
    pub async fn inject_fault(
        &self,
        slot: AxisSlot,
        fault: crate::sim::SimFault,
    ) -> ApiResult<Result<u64, ErrorId>> {
        self.ticketed(|ticket| Request::InjectFault {
            ticket,
            slot,
            fault,
        })
        .await
    }

    /// Restarts the following-error peak hold of a slot; the cycle it counts from.
    pub async fn reset_following_error_peak(
        &self,
        slot: AxisSlot,
    ) -> ApiResult<Result<u64, ErrorId>> {
        self.ticketed(|ticket| Request::ResetFollowingErrorPeak { ticket, slot })
            .await
    }

    /// A request that only needs its verdict and the cycle it takes effect in.
    async fn ticketed(&self, make: impl FnOnce(u64) -> Request) -> ApiResult<Result<u64, ErrorId>> {
        let ticket = self.next_id();
        let r = self.request(ticket, make(ticket)).await?;
        Ok(r.result.map(|_| r.cycle))
    }

    /// Builds the kernel's axis and drive for a configuration plus its persistent overlay.
    pub fn build_axis(
        &self,
        id: i64,
        config: &AxisConfigDto,
        persistent: &BTreeMap<u16, ParamValue>,
    ) -> Result<(AxisParameters, Box<Axis>, Drive), Vec<FieldError>> {
        let ct = self.info.cycle_time_s;
        let mut p = config.to_parameters(id, ct)?;
        for (n, v) in persistent {
            if let Err(e) = params::set(&mut p, *n, *v) {
                tracing::warn!(
                    "axis {}: persistent parameter {n} not applied: {}",
                    config.name,
                    e.text()
                );
            }
        }
        let axis = Axis::new(
            AxisConfig {
                modulo: config.modulo.is_some(),
                parameters: p.clone(),
            },
            ct,
        );
        let drive = DriveConfig::Simulated(config.drive.clone()).build(ct);
        Ok((p, axis, drive))
    }

    /// Submits a tracked command (REST or websocket). Returns its id once accepted.
    pub async fn submit(
        &self,
        axis_key: &str,
        name: &'static str,
        parameters: serde_json::Value,
        client: ClientInfo,
        build: impl FnOnce(&Registry, &AxisEntry) -> ApiResult<CommandKind>,
    ) -> ApiResult<CommandId> {
        let (slot, axis_id, axis_name, kind) = {
            let reg = self.registry.read().unwrap();
            let e = reg
                .find(axis_key)
                .ok_or_else(|| ApiError::not_found("axis", axis_key))?;
            (e.slot, e.id, e.name.clone(), build(&reg, e)?)
        };
        let id = self.next_id();
        let submitted_at = store::now_rfc3339();
        let audit = AuditEntry {
            at: submitted_at.clone(),
            client_addr: Some(client.addr.clone()),
            client_id: client.id.clone(),
            action: format!("command.{name}"),
            target: Some(axis_name.clone()),
            command_id: Some(id),
            detail: parameters.to_string(),
            outcome: None,
        };
        self.commands.lock().unwrap().insert(CommandRecord {
            id,
            axis_id,
            axis_name,
            slot,
            name,
            parameters,
            client,
            submitted_at,
            accepted: false,
            accepted_cycle: 0,
            outputs: FbOutputs::default(),
            last_cycle: 0,
            finished_at: None,
            events: VecDeque::new(),
            final_audit: None,
        });
        let reply = match self
            .request(
                id,
                Request::Command(Command {
                    id,
                    axis: slot,
                    kind,
                }),
            )
            .await
        {
            Ok(r) => r,
            Err(e) => {
                self.commands.lock().unwrap().remove(id);
                return Err(e);
            }
        };
        match reply.result {
            Ok(()) => {
                let final_audit = self
                    .commands
                    .lock()
                    .unwrap()
                    .map
                    .get_mut(&id)
                    .and_then(|r| {
                        r.accepted = true;
                        r.accepted_cycle = reply.cycle;
                        if r.finished_at.is_none() && r.is_final() {
                            r.finished_at = Some(store::now_rfc3339());
                        }
                        r.final_audit.take()
                    });
                self.audit(AuditEntry {
                    outcome: Some("accepted".into()),
                    ..audit
                });
                if let Some(e) = final_audit {
                    self.audit(e);
                }
                Ok(id)
            }
            Err(e) => {
                self.commands.lock().unwrap().remove(id);
                self.audit(AuditEntry {
                    outcome: Some(format!("rejected:{}", e.code())),
                    ..audit
                });
                Err(ApiError::rejected(e))
            }
        }
    }

    pub fn command(&self, id: CommandId) -> Option<CommandResource> {
        self.commands
            .lock()
            .unwrap()
            .map
            .get(&id)
            .filter(|r| r.accepted)
            .map(|r| r.view())
    }

    /// Waits until the command is final or reaches its milestone, or the timeout.
    pub async fn wait(&self, id: CommandId, timeout: Duration) -> Option<CommandResource> {
        let deadline = tokio::time::Instant::now() + timeout;
        let mut rx = self.notices.subscribe();
        loop {
            let v = self.command(id)?;
            if v.is_final || milestone(&v) {
                return Some(v);
            }
            match tokio::time::timeout_at(deadline, rx.recv()).await {
                Err(_) => return self.command(id),
                Ok(Err(broadcast::error::RecvError::Closed)) => return self.command(id),
                Ok(_) => {}
            }
        }
    }
}

/// The audit entry of a command that has ended, naming the client as its submission does.
fn final_audit(n: &CommandNotice, client: &ClientInfo) -> AuditEntry {
    AuditEntry {
        at: store::now_rfc3339(),
        client_addr: (!client.addr.is_empty()).then(|| client.addr.clone()),
        client_id: client.id.clone(),
        action: "command.final".into(),
        target: Some(n.axis.clone()),
        command_id: Some(n.command),
        detail: serde_json::to_string(n).unwrap_or_default(),
        outcome: Some(match n.state {
            CommandState::Error => format!("error:{}", ErrorId(n.outputs.error_id).code()),
            s => serde_json::to_value(s)
                .ok()
                .and_then(|v| v.as_str().map(String::from))
                .unwrap_or_default(),
        }),
    }
}

/// The point where a `?wait=true` request returns for commands that stay busy.
fn milestone(v: &CommandResource) -> bool {
    let o = &v.outputs;
    o.done
        || o.error
        || o.command_aborted
        || o.in_velocity
        || o.in_gear
        || o.in_end_velocity
        || (v.command == "power" && o.status)
}

fn apply_event(store: &mut CommandStore, ev: &CommandEvent) -> Option<CommandNotice> {
    let r = store.map.get_mut(&ev.command)?;
    r.outputs = ev.outputs;
    r.last_cycle = ev.cycle;
    if r.events.len() == EVENTS_PER_COMMAND {
        r.events.pop_front();
    }
    r.events.push_back(CommandEventDto {
        cycle: ev.cycle,
        outputs: ev.outputs,
    });
    if r.is_final() && r.finished_at.is_none() {
        r.finished_at = Some(store::now_rfc3339());
    }
    Some(CommandNotice {
        command: r.id,
        axis: r.axis_name.clone(),
        name: r.name,
        cycle: ev.cycle,
        state: CommandState::of(&ev.outputs),
        is_final: !ev.outputs.busy,
        outputs: ev.outputs,
    })
}

/// Drains the cycle thread's queues every millisecond.
pub async fn pump(state: Arc<AppState>) {
    let mut tick = tokio::time::interval(Duration::from_millis(1));
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    loop {
        tick.tick().await;
        state.drain();
    }
}

/// Writes queued audit entries in batches, one transaction per batch. A batch that cannot be
/// written (database locked past its busy timeout, disk full) is tried again a few times; what
/// is still not written is logged and counted in `lost` (`audit_dropped` in /system, /metrics).
pub async fn audit_writer(
    db: SqlitePool,
    mut rx: mpsc::Receiver<AuditEntry>,
    lost: Arc<AtomicU64>,
) {
    const TRIES: u32 = 3;
    let mut batch = Vec::with_capacity(256);
    while rx.recv_many(&mut batch, 256).await > 0 {
        for attempt in 1..=TRIES {
            let result = async {
                let mut tx = db.begin().await?;
                for e in &batch {
                    store::audit(&mut *tx, e).await?;
                }
                tx.commit().await
            }
            .await;
            match result {
                Ok(()) => break,
                Err(e) if attempt == TRIES => {
                    tracing::error!("audit log: {} entries not written: {e}", batch.len());
                    lost.fetch_add(batch.len() as u64, Relaxed);
                }
                Err(_) => tokio::time::sleep(Duration::from_millis(200)).await,
            }
        }
        batch.clear();
    }
}
