//! The async side's shared state ([`AppState`]): the axis registry, the command history, the
//! link to the cycle thread, the pump that drains its queues and the audit writer. The rules
//! (what a request may do, transactions) are the service layer's (`crate::service`); this is
//! the machinery they use.

mod commands;
pub mod control;
pub mod feed;
pub mod idempotency;
mod link;
pub mod members;
mod pump;
mod registry;

pub use commands::{CommandNotice, CommandRecord, CommandStore, HISTORY};
pub use pump::{audit_writer, pump};
pub use registry::{AxisEntry, CamEntry, GroupEntry, Registry};

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::sync::{Arc, Mutex, RwLock};
use std::time::Instant;

use motion::{AxisSlot, AxisStatus};
use sqlx::SqlitePool;
use tokio::sync::{broadcast, mpsc, oneshot};

use crate::cycle::{MAX_AXES, RealtimeGrant, Reply, Shared, Snapshot};
use crate::error::{AppError, AppResult};
use crate::scope::Recordings;
use crate::store::AuditEntry;

pub struct SystemInfo {
    pub version: &'static str,
    pub cycle_time_s: f64,
    pub listen: String,
    pub db: String,
    pub realtime: RealtimeGrant,
    pub started: Instant,
    /// Where the commissioning UI's built files are (`--ui-dir`).
    pub ui_dir: std::path::PathBuf,
    /// The drive bus (`--bus`).
    pub bus: crate::bus::BusHandle,
}

/// A prepared MovePath, or why the table does not build (entry index, field, error).
pub type PreparedOrWhy = (
    Option<Box<motion::group::PreparedPath>>,
    Option<(usize, &'static str, motion::ErrorId)>,
);

/// A status as a JSON object, shared by every websocket subscriber of that cycle.
pub type StatusJson = Arc<serde_json::Map<String, serde_json::Value>>;

pub struct AppState {
    pub shared: Arc<Shared>,
    snapshot: Mutex<triple_buffer::Output<Snapshot>>,
    /// The websocket status feed (each axis's JSON and deltas made once for every subscriber).
    pub feed: feed::Feed,
    /// Counters for `/metrics` (the rest is read at scrape time).
    pub metrics: crate::metrics::Metrics,
    /// Bumped whenever the registry is written (sockets re-check their subscriptions then).
    registry_writes: AtomicU64,
    /// Recent `Idempotency-Key`s of motion commands and their answers.
    pub idempotency: idempotency::Keys,
    pub registry: RwLock<Registry>,
    /// Serialises configuration changes (axes, parameters, import).
    pub config_lock: tokio::sync::Mutex<()>,
    pub commands: Mutex<CommandStore>,
    pending: Mutex<HashMap<u64, oneshot::Sender<Reply>>>,
    pub notices: broadcast::Sender<Arc<CommandNotice>>,
    next_id: AtomicU64,
    /// Ids up to this are persisted as reserved (see `reserve_id`).
    ids_reserved: AtomicU64,
    reserve_lock: tokio::sync::Mutex<()>,
    pub db: SqlitePool,
    audit_tx: mpsc::Sender<crate::store::AuditOp>,
    /// Audit rows lost (queue full, or not written after retries); shared with the writer.
    pub audit_dropped: Arc<AtomicU64>,
    pub info: SystemInfo,
    /// Scope recordings and the channel layout the cycle thread samples.
    pub scope: Mutex<Recordings>,
    /// Users, sessions, tokens.
    pub auth: Arc<crate::auth::Auth>,
    /// Who holds control of the machine.
    pub control: control::Control,
    /// Real or virtual time (`--clock`): what every timer on this side reads.
    pub clock: Arc<crate::clock::Clock>,
    /// Passes of `drain` completed: a pass that begins after a snapshot was read has applied
    /// every command event of that snapshot's cycle (the cycle thread pushes them first).
    pub drains: AtomicU64,
}

impl AppState {
    #[allow(
        clippy::too_many_arguments,
        reason = "each is a separate part made at start-up; a struct of them would only rename them"
    )]
    pub fn new(
        shared: Arc<Shared>,
        snapshot: triple_buffer::Output<Snapshot>,
        db: SqlitePool,
        first_command_id: u64,
        info: SystemInfo,
        auth: Arc<crate::auth::Auth>,
        control_lease: bool,
        clock: Arc<crate::clock::Clock>,
    ) -> (Arc<AppState>, mpsc::Receiver<crate::store::AuditOp>) {
        let (audit_tx, audit_rx) = mpsc::channel(8192);
        let scope = Mutex::new(Recordings::new(info.cycle_time_s, shared.period_ns));
        let state = AppState {
            scope,
            shared,
            snapshot: Mutex::new(snapshot),
            feed: feed::Feed::new(MAX_AXES, clock.clone()),
            metrics: Default::default(),
            registry_writes: AtomicU64::new(0),
            idempotency: Default::default(),
            registry: RwLock::new(Registry::default()),
            config_lock: tokio::sync::Mutex::new(()),
            commands: Mutex::new(CommandStore::default()),
            pending: Mutex::new(HashMap::new()),
            notices: broadcast::channel(4096).0,
            next_id: AtomicU64::new(first_command_id.max(1)),
            ids_reserved: AtomicU64::new(0),
            reserve_lock: tokio::sync::Mutex::new(()),
            db,
            drains: AtomicU64::new(0),
            audit_tx,
            audit_dropped: Arc::new(AtomicU64::new(0)),
            info,
            auth,
            control: control::Control::new(control_lease, clock.clone()),
            clock,
        };
        (Arc::new(state), audit_rx)
    }

    pub fn next_id(&self) -> u64 {
        self.next_id.fetch_add(1, Relaxed)
    }

    /// Makes sure `id` cannot be handed out again after a crash: the reserved mark is moved
    /// ahead (by a block, so that most commands wait for nothing) and stored before the
    /// command can act or be acknowledged. 503 when the database does not take it.
    pub async fn reserve_id(&self, id: u64) -> crate::error::AppResult<()> {
        const BLOCK: u64 = 10_000;
        if id <= self.ids_reserved.load(Relaxed) {
            return Ok(());
        }
        let _g = self.reserve_lock.lock().await;
        if id <= self.ids_reserved.load(Relaxed) {
            return Ok(());
        }
        let up_to = id + BLOCK;
        crate::store::reserve_command_ids(&self.db, up_to).await?;
        self.ids_reserved.store(up_to, Relaxed);
        Ok(())
    }

    /// The latest published snapshot: its cycle and the status of one slot.
    pub fn status(&self, slot: AxisSlot) -> (u64, Option<AxisStatus>) {
        let mut out = self.snapshot.lock().unwrap();
        let s = out.read();
        (s.cycle, s.axes.get(slot as usize).copied().flatten())
    }

    /// The latest published snapshot: its cycle and the status of one group slot.
    pub fn group_status(
        &self,
        slot: motion::group::GroupId,
    ) -> (u64, Option<motion::group::GroupStatus>) {
        let (cycle, st, _) = self.group_status_and_actuals(slot);
        (cycle, st)
    }

    /// A group's status with its members' actual positions (by role dimension; NaN where a
    /// role has no axis), both of the same cycle.
    pub fn group_status_and_actuals(
        &self,
        slot: motion::group::GroupId,
    ) -> (
        u64,
        Option<motion::group::GroupStatus>,
        [f64; motion::path::MAX_PATH_DIMS],
    ) {
        let mut out = self.snapshot.lock().unwrap();
        let s = out.read();
        let st = s.groups.get(slot as usize).copied().flatten();
        let mut actual = [f64::NAN; motion::path::MAX_PATH_DIMS];
        if let Some(g) = &st {
            for (a, m) in actual.iter_mut().zip(g.members) {
                if let Some(Some(axis)) = m.and_then(|m| s.axes.get(m as usize)) {
                    *a = axis.actual_position;
                }
            }
        }
        (s.cycle, st, actual)
    }

    /// A MovePath's items built here, off the cycle thread, from the group's queue end in the
    /// latest snapshot, its configuration and the members' parameters as mirrored. The
    /// cycle thread takes them only if that is still what the group joins (else it builds
    /// them itself), so a stale snapshot costs time, never a wrong path. A table that does
    /// not build gives the failing entry, for the refusal to name it.
    pub fn prepare_path(
        &self,
        slot: motion::group::GroupId,
        table: &motion::group::PathTable,
    ) -> PreparedOrWhy {
        let (_, Some(st)) = self.group_status(slot) else {
            return (None, None);
        };
        let reg = self.registry.read().unwrap();
        let Some(entry) = reg.groups.values().find(|e| e.slot == slot) else {
            return (None, None);
        };
        let mut limits = [None; motion::path::MAX_PATH_DIMS];
        for (d, m) in st.members.iter().enumerate() {
            if let Some(a) = m.and_then(|m| reg.axes.values().find(|a| a.slot == m)) {
                limits[d] = Some(motion::group::AxisLimits::of(&a.params));
            }
        }
        let ctx = motion::group::PathContext {
            config: entry.config,
            frame: st.frame,
            limits,
            cycle_time: self.info.cycle_time_s,
        };
        drop(reg);
        match motion::group::prepare_path(&ctx, table, st.queue_end) {
            Ok(p) => (Some(Box::new(p)), None),
            Err(why) => (None, Some(why)),
        }
    }

    /// The slot and name of an axis given by id or name (404 when there is none).
    pub fn axis_slot(&self, key: &str) -> AppResult<(AxisSlot, String)> {
        let reg = self.registry.read().unwrap();
        let e = reg
            .find(key)
            .ok_or_else(|| AppError::not_found("axis", key))?;
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

    /// The registry to change (counted, see [`AppState::registry_writes`]).
    pub fn registry_write(&self) -> std::sync::RwLockWriteGuard<'_, Registry> {
        self.registry_writes.fetch_add(1, Relaxed);
        self.registry.write().unwrap()
    }

    /// How often the registry has been written: unchanged, every axis is where it was.
    pub fn registry_writes(&self) -> u64 {
        self.registry_writes.load(Relaxed)
    }

    pub fn with_snapshot<R>(&self, f: impl FnOnce(&Snapshot) -> R) -> R {
        let mut out = self.snapshot.lock().unwrap();
        f(out.read())
    }

    /// Queues an audit entry for the batching writer (motion commands are not delayed by the
    /// disk; configuration changes write their audit row in their own transaction instead).
    pub fn audit(&self, e: AuditEntry) {
        self.audit_op(crate::store::AuditOp::Row(e));
    }

    /// Queues the outcome of a command whose row was stored as `submitted`.
    pub fn audit_outcome(&self, command_id: u64, outcome: String) {
        self.audit_op(crate::store::AuditOp::Outcome(command_id, outcome));
    }

    /// Under `--clock virtual`: waits until the audit rows queued so far are written, so that a row
    /// written directly after this (a command's, a configuration's) comes after them in the
    /// log, as in the order of the requests (decision 161). Nothing in real time.
    pub async fn audit_barrier(&self) {
        // Only where runs are reproducible: a `fast` clock runs on while a request would wait.
        if self.clock.mode != crate::clock::Mode::Virtual {
            return;
        }
        self.audit_written().await;
    }

    /// Waits until the audit rows queued before this call are written (or given up as lost),
    /// at most 2 s: a reader of the log then finds the entry of every change and command
    /// acknowledged before its request (decision 178).
    pub async fn audit_written(&self) {
        pump::audit_flushed(&self.audit_tx, std::time::Duration::from_secs(2)).await;
    }

    fn audit_op(&self, op: crate::store::AuditOp) {
        if self.audit_tx.try_send(op).is_err() {
            self.audit_dropped.fetch_add(1, Relaxed);
        }
    }
}
