//! Websocket `/api/v1/ws`: JSON-RPC 2.0 — subscriptions with deltas, and commands.
//!
//! Each connection is one task. Snapshots are taken from the latest status at the tick a
//! subscription is due (a socket woken at most [`LATE_TICKS`] late sends that tick's), so a
//! slow client simply skips intermediate snapshots; command notices come from a bounded
//! broadcast channel (a lagging client is told how many it missed). Replies to commands are produced by spawned tasks through a bounded channel.
//! Nothing here can block another client or the cycle thread.

use std::net::SocketAddr;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use axum::extract::ws::{Message, Utf8Bytes, WebSocket, WebSocketUpgrade};
use axum::extract::{ConnectInfo, State};
use axum::http::HeaderMap;
use axum::response::Response;
use serde::Serialize;
use serde_json::{Map, Value, json};
use tokio::sync::{broadcast, mpsc};
use tokio::time::Instant;
use utoipa::ToSchema;

use super::blocks;
use crate::app::AppState;
use crate::auth::Role;
use crate::blocks::torque::{ExtSetPointFeedBody, FeedResult};
use crate::error::AppError;
use crate::model::*;
use crate::service::commands;

/// Highest subscription rate.
pub const MAX_RATE_HZ: f64 = 100.0;
/// Lowest subscription rate (one update every 10 s).
pub const MIN_RATE_HZ: f64 = 0.1;
/// A send that takes longer than this (the client does not read) stops the socket's ticks from
/// holding a virtual clock.
const SLOW_SEND: std::time::Duration = std::time::Duration::from_millis(100);
/// Commands, keepalives and releases of one socket whose responses are still outstanding: a
/// client that sends faster than it reads is refused instead of queued without bound.
pub const MAX_IN_FLIGHT: usize = 32;
/// Seconds without anything from the client before the server pings it, and again before it
/// closes a socket whose client did not answer (`--ws-ping-s`).
pub const DEFAULT_PING_S: f64 = 30.0;
/// The close code for a client that did not answer a ping (private range: an HTTP 408 in
/// websocket terms).
pub const PING_TIMEOUT_CLOSE: u16 = 4408;
/// The close code for a message over [`MAX_MESSAGE`] (RFC 6455: message too big).
pub const MESSAGE_TOO_BIG_CLOSE: u16 = 1009;
/// The longest message a client may send.
pub const MAX_MESSAGE: usize = 256 * 1024;

/// How the server watches idle sockets.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Silence from the client (no message, no Pong) after which it is pinged, and then the time
    /// it has to send anything before the socket is closed.
    pub ping_after: Duration,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            ping_after: Duration::from_secs_f64(DEFAULT_PING_S),
        }
    }
}
use crate::app::feed::{Asked, TICK};
use motion::AxisSlot;

// ---------------------------------------------------------------------------------------------
// The messages, as types: the session serialises these, and `super::asyncapi` describes the
// socket with their schemas (and the command bodies'), so that the AsyncAPI document cannot
// drift from what is sent.

/// `subscribe` params.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"topic": "axes/x/status", "rate_hz": 25.0}))]
pub struct SubscribeParams {
    /// `axes/{axis}/status` (axis id or name), `groups/{group}/status` (group id or name),
    /// `commands` or `system`.
    pub topic: String,
    /// Updates per second, 0.1–100 (more is capped); default 10. Not used by `commands`
    /// (every change is sent).
    #[schema(minimum = 0.1)]
    pub rate_hz: Option<f64>,
}

/// `subscribe` result.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"topic": "axes/x/status", "rate_hz": 25.0}))]
pub struct SubscribeResult {
    /// The topic as given.
    pub topic: String,
    /// The rate in effect (capped at 100).
    pub rate_hz: f64,
}

/// `unsubscribe` params. The result is `true` if there was such a subscription.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"topic": "axes/x/status"}))]
pub struct UnsubscribeParams {
    /// The topic as subscribed.
    pub topic: String,
}

/// `keepalive` (renew a jog's dead-man) and `release` (falling edge of Execute/Enable) params.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"command": 42}))]
pub struct CommandRef {
    /// Command id.
    pub command: u64,
}

/// `keepalive` / `release` result.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"command": 42, "cycle": 1873}))]
pub struct ControlResult {
    pub command: u64,
    /// The kernel cycle it took effect in.
    pub cycle: u64,
}

/// `update` notification params: a subscription's data, stamped with the kernel cycle.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"topic": "axes/x/status", "cycle": 2009, "full": false,
    "data": {"set_position": 64.111, "actual_position": 64.109}}))]
pub struct UpdateParams {
    pub topic: String,
    pub cycle: u64,
    /// `true`: `data` is the whole object (the first update of a subscription, and after the
    /// axis was replaced); `false`: only the fields that changed since the previous update (a
    /// field that is no longer there is `null`, as in a JSON merge patch).
    pub full: bool,
    /// `axes/{axis}/status`: a `LiveStatus`; `system`: a `SystemResource` (whole or in part).
    #[schema(value_type = Object)]
    pub data: Map<String, Value>,
}

/// `commands_lagged` notification params: the socket fell behind the command notices.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"missed": 12}))]
pub struct CommandsLagged {
    /// How many `command_event`s it missed.
    pub missed: u64,
}

/// Why the server ended a subscription.
#[derive(Clone, Copy, Debug, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum EndReason {
    /// The axis was deleted, or an import left no axis with its id.
    AxisRemoved,
}

/// `subscription_ended` notification params.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"topic": "axes/y/status", "reason": "axis_removed"}))]
pub struct SubscriptionEnded {
    pub topic: String,
    pub reason: EndReason,
}

/// A JSON-RPC error object.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"code": -32602, "message": "velocity: must be > 0", "data": {
    "type": "urn:motiond:problem:validation_failed", "title": "Invalid request", "status": 422,
    "detail": "velocity: must be > 0", "code": "validation_failed",
    "errors": [{"field": "velocity", "message": "must be > 0"}]}}))]
pub struct RpcError {
    /// -32700 parse error, -32600 invalid request, -32601 method not found, -32602 invalid
    /// params (a 400/422 of the REST API), -32000 any other refusal (409, 404, 503 …).
    pub code: i64,
    pub message: String,
    /// The REST API's problem for the same refusal (`code`, `error_id`, `errors[].field`), or
    /// `{"code": "too_many_in_flight"}`.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<Object>)]
    pub data: Option<Value>,
}

#[utoipa::path(get, path = "/api/v1/ws", tag = "system", summary = "Websocket: JSON-RPC 2.0 subscriptions and commands",
    description = "Requests: `subscribe` {topic, rate_hz} with topic `axes/{axis}/status`, `commands` or `system` \
(0.1–100 Hz, more is capped; default 10) — an axis topic follows its axis (by id) when an import moves it and \
ends with a `subscription_ended` {topic, reason} notification when the axis is removed; `unsubscribe` {topic}; every command endpoint by its name (`power`, \
`move-absolute`, `jog` …) with params = the REST body plus `axis` (and optional `wait`, `timeout_ms`), a group's blocks \
(`enable`, `move-path`, `release-blocker` …) with `group` instead of `axis`; \
`keepalive` / `release` {command}. Notifications: `update` {topic, cycle, full, data} — first the full object, \
then only changed fields; `command_event` {cycle, command, axis, name, state, final, outputs}. A jog's dead-man is \
the client's to renew whatever the transport (`keepalive` within its `deadman_timeout`): an open socket alone does \
not keep a jog going, so a frozen client stops it too. A jog sent over the socket is also released when the socket \
closes. At most 32 requests per socket may await their responses; more are refused (`too_many_in_flight`). \
A request without an id is a notification: carried out, never answered. A client may send a JSON-RPC 2.0 batch \
(an array of requests): each is started in order (a command does not wait for the one before it to end) and \
the batch is answered with one array of the responses, once every one of them is in (nothing for a batch of notifications; an empty array is an invalid request). \
The server sends one message per tick (5 ms grid): when several notifications are due together (the updates of \
several subscriptions), they come as one JSON-RPC 2.0 batch, a JSON array of the notifications. \
Every message is described by the AsyncAPI 3 document at `/asyncapi.json`. The server pings a socket it has \
heard nothing from for 30 s (`--ws-ping-s`) and closes it (code 4408) when nothing arrives within as long again. \
A message over 256 KiB closes the socket with code 1009 (message too big).",
    params(super::WsQuery),
    responses((status = 101, description = "Switching protocols"), super::errors::WebsocketErrors))]
pub async fn upgrade(
    ws: WebSocketUpgrade,
    State(s): State<Arc<AppState>>,
    ConnectInfo(addr): ConnectInfo<SocketAddr>,
    headers: HeaderMap,
    settings: Settings,
    identity: Option<crate::auth::Principal>,
    client_id: Option<String>,
) -> Response {
    let client = ClientInfo {
        addr: addr.to_string(),
        // A browser cannot set headers on a websocket: `?client_id=` names it instead.
        // Non-ASCII names arrive as UTF-8 bytes: decoded, never dropped (as for REST).
        id: headers
            .get("x-client-id")
            .map(|v| String::from_utf8_lossy(v.as_bytes()).into_owned())
            .or(client_id)
            .map(|s| s.chars().take(128).collect()),
        via: "websocket",
        principal: identity.as_ref().map(|p| p.label()),
        identity,
    };
    // Clients send little (requests of at most 256 KiB): a small read chunk, because the read
    // buffer is zeroed to its size on every read.
    // A frame of up to 1 MiB is read whole, so that one over the message limit is answered
    // with the 1009 close frame after it (an unread rest would make the close a reset).
    ws.max_message_size(MAX_MESSAGE)
        .max_frame_size(1024 * 1024)
        .read_buffer_size(4 * 1024)
        .on_upgrade(move |socket| session(s, socket, client, settings))
}

impl<S: Send + Sync> axum::extract::FromRequestParts<S> for Settings {
    type Rejection = std::convert::Infallible;

    async fn from_request_parts(
        parts: &mut axum::http::request::Parts,
        _: &S,
    ) -> Result<Self, Self::Rejection> {
        Ok(parts
            .extensions
            .get::<Settings>()
            .copied()
            .unwrap_or_default())
    }
}

enum Topic {
    /// Followed by the axis id: an import or a re-created axis may move it to another slot.
    Axis {
        id: i64,
        slot: u16,
        name: String,
    },
    Commands,
    System,
    /// A group's status (`groups/{group}/status`), followed by the group id. Made per
    /// subscriber from the snapshot, as the system topic (16 groups at most, few watchers).
    Group {
        id: i64,
    },
}

struct Sub {
    key: String,
    /// `key` as a JSON string (written into every update); one allocation for every socket
    /// with this topic ([`crate::app::feed::Feed::topic`]).
    key_json: Arc<str>,
    topic: Topic,
    /// The rate, in feed ticks; due on the ticks that are multiples of it (the same ticks in
    /// every socket, so that subscribers share the feed's deltas).
    every: u64,
    due: u64,
    /// The system topic: the object last sent (its delta is made here).
    last: Option<crate::app::StatusJson>,
    /// An axis topic: the version (status cycle) last sent; the feed makes its delta.
    seen: Option<u64>,
}

impl Sub {
    /// Sent at `tick`: due next on its rate's grid (a socket that fell behind skips what it
    /// missed).
    fn sent_at(&mut self, tick: u64) {
        self.due = (tick / self.every + 1) * self.every;
    }
}

fn rpc_result(id: &Value, result: Value) -> String {
    json!({"jsonrpc": "2.0", "id": id, "result": result}).to_string()
}

fn rpc_error(id: &Value, code: i64, message: &str, data: Option<Value>) -> String {
    let error = RpcError {
        code,
        message: message.to_owned(),
        data,
    };
    json!({"jsonrpc": "2.0", "id": id, "error": error}).to_string()
}

/// The `axis` of a method's params (an id or a name), taken out of them.
fn take_axis(params: &mut Map<String, Value>) -> Option<String> {
    match params.remove("axis") {
        Some(Value::String(a)) => Some(a),
        Some(Value::Number(n)) => Some(n.to_string()),
        _ => None,
    }
}

/// The `group` of a group block's params (an id or a name), taken out of them.
fn take_group(params: &mut Map<String, Value>) -> Option<String> {
    match params.remove("group") {
        Some(Value::String(g)) => Some(g),
        Some(Value::Number(n)) => Some(n.to_string()),
        _ => None,
    }
}

/// A block method addresses a group when its params name one (`group`), else an axis: the
/// same name (`halt`, `stop`, `reset`, `set-override`) is a block of both.
fn target_kind(params: &Map<String, Value>) -> blocks::At {
    if params.contains_key("group") {
        blocks::At::Groups
    } else {
        blocks::At::Axes
    }
}

fn api_error(id: &Value, e: AppError) -> String {
    let code = match e.status().as_u16() {
        422 | 400 => -32602,
        _ => -32000,
    };
    rpc_error(
        id,
        code,
        &e.to_string(),
        serde_json::to_value(e.problem()).ok(),
    )
}

fn notify(method: &str, params: impl Serialize) -> String {
    json!({"jsonrpc": "2.0", "method": method, "params": params}).to_string()
}

async fn session(s: Arc<AppState>, mut socket: WebSocket, client: ClientInfo, settings: Settings) {
    let mut subs: Vec<Sub> = Vec::new();
    let mut notices: Option<broadcast::Receiver<Arc<crate::app::CommandNotice>>> = None;
    let (out_tx, mut out_rx) = mpsc::channel::<String>(64);
    let jogs: Arc<Mutex<Vec<u64>>> = Arc::default();
    let in_flight = Arc::new(tokio::sync::Semaphore::new(MAX_IN_FLIGHT));
    // Idle watch: a Ping after `ping_after` without anything from the client, then the socket
    // is closed if nothing arrives within `ping_after` (a dead peer or a frozen client).
    let mut heard = Instant::now();
    let mut pinged: Option<Instant> = None;
    // The registry as this socket last checked its subscriptions against it.
    let mut seen_writes = u64::MAX;
    // The size of the last tick's message (the next one is usually alike).
    let mut last_len = 256;
    let mut due_hold: Option<(u64, crate::clock::Hold)> = None;
    // Its last send went out within `SLOW_SEND` (only then are its ticks held).
    let mut keeping_up = true;
    loop {
        let idle_deadline = match pinged {
            None => heard + settings.ping_after,
            Some(at) => at + settings.ping_after,
        };
        // The socket sleeps until its next subscription is due (not every tick of the grid).
        let next_due = subs
            .iter()
            .filter(|x| !matches!(x.topic, Topic::Commands))
            .map(|x| x.due)
            .min();
        // The hold on the next tick is kept across wake-ups for other reasons (in virtual time
        // the clock waits at it until this socket has taken the tick's statuses).
        if due_hold.as_ref().map(|(t, _)| *t) != next_due {
            due_hold = next_due.map(|t| (t, s.feed.at(t, keeping_up)));
        }
        let due = async {
            match &due_hold {
                Some((_, h)) => h.wait().await,
                None => std::future::pending().await,
            }
        };
        // A tick's message (shared with other sockets: no copy).
        let mut tick_out: Option<Utf8Bytes> = None;
        let outgoing: Vec<String> = tokio::select! {
            msg = socket.recv() => {
                if matches!(msg, Some(Ok(_))) {
                    (heard, pinged) = (Instant::now(), None);
                }
                match msg {
                    Some(Ok(Message::Text(t))) => match batch_of(t.as_str()) {
                        None => handle(&s, &mut subs, &mut notices, &client, &out_tx, &jogs, &in_flight, t.as_str()).into_iter().collect(),
                        Some(Err(e)) => vec![e],
                        Some(Ok(calls)) => {
                            // A JSON-RPC 2.0 batch: every call handled in order, the answers
                            // (those that come later too) sent as one array once all are in;
                            // nothing when all were notifications.
                            let (batch_tx, mut batch_rx) = mpsc::channel::<String>(calls.len().max(1));
                            let mut answers: Vec<String> = calls
                                .iter()
                                .filter_map(|c| handle(&s, &mut subs, &mut notices, &client, &batch_tx, &jogs, &in_flight, &c.to_string()))
                                .collect();
                            drop(batch_tx);
                            let out = out_tx.clone();
                            tokio::spawn(async move {
                                while let Some(a) = batch_rx.recv().await {
                                    answers.push(a);
                                }
                                if !answers.is_empty() {
                                    let _ = out.send(format!("[{}]", answers.join(","))).await;
                                }
                            });
                            vec![]
                        }
                    },
                    Some(Ok(Message::Binary(_))) => vec![rpc_error(&Value::Null, -32600, "binary messages are not supported", None)],
                    Some(Ok(_)) => vec![],
                    Some(Err(e)) => {
                        // A message over the limit is answered with a close frame that says so
                        // (1009), not a silently dropped connection.
                        let too_big = e
                            .into_inner()
                            .downcast::<tungstenite::Error>()
                            .is_ok_and(|e| matches!(*e, tungstenite::Error::Capacity(_)));
                        if too_big {
                            let close = axum::extract::ws::CloseFrame {
                                code: MESSAGE_TOO_BIG_CLOSE,
                                reason: format!("message too big: at most {} KiB", MAX_MESSAGE / 1024).into(),
                            };
                            let _ = socket.send(Message::Close(Some(close))).await;
                        }
                        break;
                    }
                    None => break,
                }
            },
            _ = tokio::time::sleep_until(idle_deadline) => {
                // A client that does not read can block these sends: no tick of it is held
                // meanwhile (held again from the next turn).
                due_hold = None;
                if pinged.is_some() {
                    let close = axum::extract::ws::CloseFrame {
                        code: PING_TIMEOUT_CLOSE,
                        reason: "no answer to ping".into(),
                    };
                    let _ = socket.send(Message::Close(Some(close))).await;
                    break;
                }
                pinged = Some(Instant::now());
                if socket.send(Message::Ping(Default::default())).await.is_err() {
                    break;
                }
                vec![]
            },
            Some(m) = out_rx.recv() => vec![m],
            n = async { match notices.as_mut() { Some(rx) => rx.recv().await, None => std::future::pending().await } } => match n {
                Ok(n) => vec![notify("command_event", &*n)],
                Err(broadcast::error::RecvError::Lagged(k)) => vec![notify("commands_lagged", CommandsLagged { missed: k })],
                Err(broadcast::error::RecvError::Closed) => vec![],
            },
            _ = due => {
                // Socket jogs are not renewed here: only the client's keepalives renew them,
                // so a client whose script hangs with the socket open still stops the axis.
                let tick = sending_tick(s.feed.tick_now(), &subs);
                let m = tick_message(&s, &mut subs, &mut seen_writes, tick, last_len);
                // The next tick is held before this one is let go (the clock never slips
                // past it while this socket sends).
                let next = subs
                    .iter()
                    .filter(|x| !matches!(x.topic, Topic::Commands))
                    .map(|x| x.due)
                    .min();
                due_hold = next.map(|t| (t, s.feed.at(t, keeping_up)));
                last_len = m.as_ref().map_or(last_len, |m| m.len() + 64);
                tick_out = m;
                vec![]
            }
        };
        for m in outgoing
            .into_iter()
            .map(Utf8Bytes::from)
            .chain(tick_out.take())
        {
            let send = socket.send(Message::Text(m));
            tokio::pin!(send);
            let sent = tokio::select! {
                // The send first: one that completes at once (the usual case) never registers
                // its timer in the runtime's wheel (issue 27: fewer timers per tick).
                biased;
                r = &mut send => r,
                _ = tokio::time::sleep(SLOW_SEND) => {
                    // A client that does not read holds no virtual clock: its ticks are no
                    // longer held (it gets the newest state when it reads again).
                    keeping_up = false;
                    due_hold = None;
                    send.await
                }
            };
            if sent.is_err() {
                break;
            }
            keeping_up = true;
        }
    }
    // The socket is gone: release its jogs (a jog held on a socket stops when it closes).
    let held: Vec<u64> = std::mem::take(&mut *jogs.lock().unwrap());
    for id in held {
        if commands::get(&s, id).is_some_and(|c| !c.is_final) {
            let _ = commands::release(&s, id, &client).await;
        }
    }
}

/// Follows axis subscriptions to the slot their axis is in now; ends those whose axis is gone.
fn follow_axes(s: &AppState, subs: &mut Vec<Sub>, out: &mut Batch) {
    let reg = s.registry.read().unwrap();
    subs.retain_mut(|sub| {
        let Topic::Axis { id, slot, name } = &mut sub.topic else {
            return true;
        };
        match reg.axes.get(id) {
            None => {
                out.push(&notify(
                    "subscription_ended",
                    SubscriptionEnded {
                        topic: sub.key.clone(),
                        reason: EndReason::AxisRemoved,
                    },
                ));
                false
            }
            Some(e) => {
                if e.slot != *slot || e.name != *name {
                    // Another axis object now: start again with a full object.
                    (*slot, *name) = (e.slot, e.name.clone());
                    sub.seen = None;
                }
                true
            }
        }
    });
}

/// The notifications of one tick, written into one message: one alone as itself, several as
/// a JSON-RPC batch (an array).
struct Batch {
    buf: String,
    n: usize,
}

impl Batch {
    fn with_capacity(n: usize) -> Self {
        Batch {
            buf: String::with_capacity(n),
            n: 0,
        }
    }

    /// Starts the next notification (its text is written into `buf` after this).
    fn next(&mut self) -> &mut String {
        self.buf.push(if self.n == 0 { '[' } else { ',' });
        self.n += 1;
        &mut self.buf
    }

    fn push(&mut self, m: &str) {
        self.next().push_str(m);
    }

    fn finish(mut self) -> Option<String> {
        match self.n {
            0 => None,
            1 => {
                self.buf.remove(0);
                Some(self.buf)
            }
            _ => {
                self.buf.push(']');
                Some(self.buf)
            }
        }
    }
}

/// How many ticks late a socket may wake and still send the tick it was due at.
const LATE_TICKS: u64 = 3;

/// The tick a socket woken for its next due subscription sends: that tick when it woke at most
/// [`LATE_TICKS`] (15 ms) late (the versions and the message made for it, most often by the
/// sockets that were on time, are taken instead of new ones made for this socket alone), else
/// the tick now (a socket further behind gets the newest state). Decision 179.
fn sending_tick(now: u64, subs: &[Sub]) -> u64 {
    let due = subs
        .iter()
        .filter(|x| !matches!(x.topic, Topic::Commands))
        .map(|x| x.due)
        .min();
    match due {
        // (Woken before it, as the old rule did: the due tick.)
        Some(due) if now <= due + LATE_TICKS => due,
        _ => now,
    }
}

/// This socket's updates at `tick` as one message (`None`: nothing to send). A socket whose
/// due subscriptions are all axis topics asks the feed first for the message another socket
/// made for the same at this tick, and leaves its own there for the sockets after it: sockets
/// that subscribe alike and keep up share one message per tick (issue 27).
fn tick_message(
    s: &AppState,
    subs: &mut Vec<Sub>,
    seen_writes: &mut u64,
    tick: u64,
    capacity: usize,
) -> Option<Utf8Bytes> {
    let mut out = Batch::with_capacity(capacity);
    let writes = s.registry_writes();
    if writes != *seen_writes
        && subs
            .iter()
            .any(|x| tick >= x.due && matches!(x.topic, Topic::Axis { .. }))
    {
        // Only after the registry changed: axes moved to other slots, were renamed or removed.
        *seen_writes = writes;
        follow_axes(s, subs, &mut out);
    }
    // A group's or the system's update is this socket's own (its delta against what this
    // socket was sent); so is a message that tells of a subscription ended.
    // A tick with no axis topic due has nothing to share.
    let shareable = out.n == 0
        && subs
            .iter()
            .filter(|x| tick >= x.due)
            .all(|x| matches!(x.topic, Topic::Axis { .. } | Topic::Commands))
        && asked(subs, tick).next().is_some();
    if shareable {
        let same = |theirs: &[Asked]| {
            let mut mine = asked(subs, tick);
            theirs.iter().all(|t| {
                mine.next().is_some_and(|(slot, seen, key)| {
                    // Topics are shared: the same topic is most often the same text.
                    slot == t.0 && seen == t.1 && (Arc::ptr_eq(key, &t.2) || key == &t.2)
                })
            }) && mine.next().is_none()
        };
        if let Some(batch) = s.feed.shared(tick, same) {
            let mut seen = batch.seen.iter();
            for sub in subs.iter_mut().filter(|x| tick >= x.due) {
                sub.sent_at(tick);
                if let Topic::Axis { .. } = sub.topic {
                    sub.seen = seen.next().copied().flatten();
                }
            }
            return batch.message.clone();
        }
    }
    let mine: Option<Vec<Asked>> = shareable.then(|| {
        asked(subs, tick)
            .map(|(slot, seen, key)| (slot, seen, key.clone()))
            .collect()
    });
    // The subscriptions in `mine`, to read their versions after the updates.
    let due_axes: Vec<usize> = (0..subs.len())
        .filter(|&i| tick >= subs[i].due && matches!(subs[i].topic, Topic::Axis { .. }))
        .collect();
    updates(s, subs, tick, &mut out);
    s.feed.made_one();
    let message = out.finish().map(Utf8Bytes::from);
    if let Some(asked) = mine {
        let seen = due_axes.iter().map(|&i| subs[i].seen).collect();
        let batch = crate::app::feed::SharedBatch {
            asked,
            seen,
            message: message.clone(),
        };
        s.feed.share(tick, batch);
    }
    message
}

/// The axis subscriptions due at `tick`: slot, version last sent, topic as JSON.
fn asked(subs: &[Sub], tick: u64) -> impl Iterator<Item = (AxisSlot, Option<u64>, &Arc<str>)> {
    subs.iter()
        .filter(move |x| tick >= x.due)
        .filter_map(|x| match x.topic {
            Topic::Axis { slot, .. } => Some((slot, x.seen, &x.key_json)),
            _ => None,
        })
}

fn updates(s: &AppState, subs: &mut [Sub], tick: u64, out: &mut Batch) {
    // The axes' versions first: a second socket making its own message at this tick (on the
    // other worker) makes them from the other end, so the two share the work instead of one
    // waiting on the other axis by axis.
    let slots = subs
        .iter()
        .filter(|x| tick >= x.due)
        .filter_map(|x| match x.topic {
            Topic::Axis { slot, .. } => Some(slot),
            _ => None,
        });
    if s.feed.maker(tick) % 2 == 1 {
        slots.rev().for_each(|slot| s.feed.prepare(s, slot, tick));
    } else {
        slots.for_each(|slot| s.feed.prepare(s, slot, tick));
    }
    for sub in subs.iter_mut().filter(|x| tick >= x.due) {
        sub.sent_at(tick);
        match &sub.topic {
            Topic::Commands => {}
            Topic::Axis { slot, .. } => {
                let Some(p) = s.feed.piece(s, *slot, tick, sub.seen) else {
                    continue;
                };
                sub.seen = Some(p.version);
                if let Some(data) = p.data {
                    write_update(out.next(), &sub.key_json, p.cycle, p.full, &data);
                }
            }
            Topic::Group { id } => {
                // A deleted group (or one not in the cycle) sends nothing.
                let Ok(st) = crate::service::groups::status(s, &id.to_string()) else {
                    continue;
                };
                object_update(sub, st.cycle, &st, out);
            }
            Topic::System => {
                let sys = super::system::system_resource(s);
                object_update(sub, sys.cycle, &sys, out);
            }
        }
    }
}

/// An object topic's update (system, a group): made for this subscriber from the object and
/// the one it was last sent — the whole object first, then the changed fields, nothing when
/// none changed.
fn object_update(sub: &mut Sub, cycle: u64, object: &impl Serialize, out: &mut Batch) {
    let Ok(Value::Object(map)) = serde_json::to_value(object) else {
        return;
    };
    let data = match &sub.last {
        None => map.clone(),
        Some(last) => crate::app::feed::delta(last, &map),
    };
    let full = sub.last.is_none();
    sub.last = Some(Arc::new(map));
    if full || !data.is_empty() {
        out.push(&notify(
            "update",
            UpdateParams {
                topic: sub.key.clone(),
                cycle,
                full,
                data,
            },
        ));
    }
}

/// An `update` notification (as `UpdateParams` serialises) from the feed's ready JSON.
#[cfg(test)]
fn update_message(topic_json: &str, cycle: u64, full: bool, data: &str) -> String {
    let mut m = String::new();
    write_update(&mut m, topic_json, cycle, full, data);
    m
}

/// Writes an `update` notification into `m`.
fn write_update(m: &mut String, topic_json: &str, cycle: u64, full: bool, data: &str) {
    use std::fmt::Write;
    const HEAD: &str = r#"{"jsonrpc":"2.0","method":"update","params":{"topic":"#;
    m.push_str(HEAD);
    m.push_str(topic_json);
    m.push_str(r#","cycle":"#);
    let _ = write!(m, "{cycle}");
    m.push_str(if full {
        r#","full":true,"data":"#
    } else {
        r#","full":false,"data":"#
    });
    m.push_str(data);
    m.push_str("}}");
}

/// A message that is a JSON-RPC batch (an array): its calls, or the error to answer (an empty
/// array is an invalid request, an array that does not parse a parse error). `None`: not a
/// batch.
fn batch_of(text: &str) -> Option<Result<Vec<Value>, String>> {
    if !text.trim_start().starts_with('[') {
        return None;
    }
    Some(match serde_json::from_str::<Value>(text) {
        Ok(Value::Array(calls)) if !calls.is_empty() => Ok(calls),
        Ok(_) => Err(rpc_error(
            &Value::Null,
            -32600,
            "invalid request: an empty batch",
            None,
        )),
        Err(e) => Err(rpc_error(
            &Value::Null,
            -32700,
            &format!("parse error: {e}"),
            None,
        )),
    })
}

#[allow(
    clippy::too_many_arguments,
    reason = "one socket's whole state, borrowed apart"
)]
fn handle(
    s: &Arc<AppState>,
    subs: &mut Vec<Sub>,
    notices: &mut Option<broadcast::Receiver<Arc<crate::app::CommandNotice>>>,
    client: &ClientInfo,
    out_tx: &mpsc::Sender<String>,
    jogs: &Arc<Mutex<Vec<u64>>>,
    in_flight: &Arc<tokio::sync::Semaphore>,
    text: &str,
) -> Option<String> {
    let req: Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(e) => {
            return Some(rpc_error(
                &Value::Null,
                -32700,
                &format!("parse error: {e}"),
                None,
            ));
        }
    };
    let id = req.get("id").cloned().unwrap_or(Value::Null);
    let Some(method) = req
        .get("method")
        .and_then(|m| m.as_str())
        .filter(|_| req.get("jsonrpc") == Some(&json!("2.0")))
    else {
        return Some(rpc_error(
            &id,
            -32600,
            "invalid request: need jsonrpc \"2.0\" and a method",
            None,
        ));
    };
    let mut params = match req.get("params") {
        None => Map::new(),
        Some(Value::Object(m)) => m.clone(),
        Some(_) => return Some(rpc_error(&id, -32602, "params must be an object", None)),
    };
    let method = method.to_string();
    // A JSON-RPC notification (no id) is carried out but never answered.
    let notification = req.get("id").is_none();
    // (a closure, so that its early error returns are silenced for notifications too)
    #[allow(
        clippy::redundant_closure_call,
        reason = "the closure scopes the early returns"
    )]
    let need = match method.as_str() {
        "subscribe" | "unsubscribe" => Role::Viewer,
        "keepalive" | "release" | "update-inputs" | "ext-setpoint-gen-feed" => Role::Operator,
        name => blocks::find(target_kind(&params), name).map_or(Role::Viewer, |b| b.role),
    };
    if let Err(e) = may(s, client, need) {
        return Some(api_error(&id, e)).filter(|_| !notification);
    }
    let reply = (|| match method.as_str() {
        "subscribe" => {
            let Some(key) = params
                .get("topic")
                .and_then(|t| t.as_str())
                .map(String::from)
            else {
                return Some(rpc_error(&id, -32602, "topic is required", None));
            };
            let rate = match params.get("rate_hz") {
                None => 10.0,
                Some(v) => match v.as_f64() {
                    Some(r) if r >= MIN_RATE_HZ && r.is_finite() => r.min(MAX_RATE_HZ),
                    _ => {
                        let msg = format!(
                            "rate_hz must be a number ≥ {MIN_RATE_HZ} (more than {MAX_RATE_HZ} is capped)"
                        );
                        return Some(rpc_error(&id, -32602, &msg, None));
                    }
                },
            };
            let topic = if key == "commands" {
                *notices = Some(s.notices.subscribe());
                Topic::Commands
            } else if key == "system" {
                Topic::System
            } else if let Some(axis) = key
                .strip_prefix("axes/")
                .and_then(|r| r.strip_suffix("/status"))
            {
                let reg = s.registry.read().unwrap();
                match reg.find(axis) {
                    Some(e) => Topic::Axis {
                        id: e.id,
                        slot: e.slot,
                        name: e.name.clone(),
                    },
                    None => {
                        return Some(rpc_error(&id, -32602, &format!("no axis '{axis}'"), None));
                    }
                }
            } else if let Some(group) = key
                .strip_prefix("groups/")
                .and_then(|r| r.strip_suffix("/status"))
            {
                let reg = s.registry.read().unwrap();
                match reg.find_group(group) {
                    Some(g) => Topic::Group { id: g.id },
                    None => {
                        return Some(rpc_error(&id, -32602, &format!("no group '{group}'"), None));
                    }
                }
            } else {
                return Some(rpc_error(
                    &id,
                    -32602,
                    "unknown topic (axes/{axis}/status, groups/{group}/status, commands, system)",
                    None,
                ));
            };
            let canonical = match &topic {
                Topic::Axis { name, .. } => format!("axes/{name}/status"),
                _ => key.clone(),
            };
            subs.retain(|x| x.key != canonical && x.key != key);
            let every = (1.0 / (rate * TICK.as_secs_f64())).round().max(1.0) as u64;
            subs.push(Sub {
                key_json: s
                    .feed
                    .topic(&serde_json::to_string(&key).unwrap_or_default()),
                key: key.clone(),
                topic,
                every,
                due: 0,
                last: None,
                seen: None,
            });
            let result = SubscribeResult {
                topic: key,
                rate_hz: rate,
            };
            Some(rpc_result(&id, json!(result)))
        }
        "unsubscribe" => {
            let key = params
                .get("topic")
                .and_then(|t| t.as_str())
                .unwrap_or_default()
                .to_string();
            let before = subs.len();
            subs.retain(|x| x.key != key);
            if key == "commands" {
                *notices = None;
            }
            Some(rpc_result(
                &id,
                json!(before != subs.len() || key == "commands"),
            ))
        }
        "keepalive" | "release" => {
            let Some(cmd) = params.get("command").and_then(|c| c.as_u64()) else {
                return Some(rpc_error(&id, -32602, "command (id) is required", None));
            };
            let s = s.clone();
            let client = client.clone();
            answer_later(in_flight, out_tx, &id, notification, async move {
                let cycle = if method == "keepalive" {
                    commands::keepalive(&s, cmd).await
                } else {
                    commands::release(&s, cmd, &client).await
                }?;
                Ok(json!(ControlResult {
                    command: cmd,
                    cycle
                }))
            })
        }
        "update-inputs" => {
            let Some(cmd) = params.remove("command").and_then(|c| c.as_u64()) else {
                return Some(rpc_error(&id, -32602, "command (id) is required", None));
            };
            let body: super::commands::InputsBody = match super::from_value(Value::Object(params)) {
                Ok((b, _)) => b,
                Err(e) => return Some(api_error(&id, e)),
            };
            let s = s.clone();
            let client = client.clone();
            answer_later(in_flight, out_tx, &id, notification, async move {
                let c = super::commands::take_inputs(&s, cmd, &body, &client).await?;
                Ok(json!(c))
            })
        }
        "ext-setpoint-gen-feed" => {
            let Some(axis) = take_axis(&mut params) else {
                return Some(rpc_error(&id, -32602, "axis is required", None));
            };
            let body: ExtSetPointFeedBody = match super::from_value(Value::Object(params)) {
                Ok((b, _)) => b,
                Err(e) => return Some(api_error(&id, e)),
            };
            let s = s.clone();
            let client = client.clone();
            answer_later(in_flight, out_tx, &id, notification, async move {
                let cycle =
                    commands::ext_feed(&s, &axis, &body, ExtSetPointFeedBody::to_kind, &client)
                        .await?;
                Ok(json!(FeedResult { cycle }))
            })
        }
        name if super::reads::READS.iter().any(|r| r.name == name) => {
            let Some(axis) = take_axis(&mut params) else {
                return Some(rpc_error(&id, -32602, "axis is required", None));
            };
            let r = super::reads::dispatch(s, name, &axis, Value::Object(params))
                .expect("a read of the list");
            Some(match r {
                Ok(v) => rpc_result(&id, v),
                Err(e) => api_error(&id, e),
            })
        }
        name => {
            let at = target_kind(&params);
            let Some(block) = blocks::find(at, name) else {
                return Some(rpc_error(
                    &id,
                    -32601,
                    &format!("method not found: {name}"),
                    None,
                ));
            };
            let target = match at {
                blocks::At::Axes => take_axis(&mut params),
                blocks::At::Groups => take_group(&mut params),
            };
            let Some(axis) = target else {
                return Some(rpc_error(&id, -32602, "axis is required", None));
            };
            // The REST query's rules (`?wait=true&timeout_ms=N`), from the params.
            let query: Map<String, Value> = ["wait", "timeout_ms"]
                .into_iter()
                .filter_map(|k| params.remove(k).map(|v| (k.to_owned(), v)))
                .collect();
            let query: super::WaitQuery = match serde_json::from_value(Value::Object(query)) {
                Ok(q) => q,
                Err(e) => {
                    return Some(rpc_error(
                        &id,
                        -32602,
                        &format!("wait/timeout_ms: {e}"),
                        None,
                    ));
                }
            };
            let wait = match commands::wait_duration(query.wait, query.timeout_ms) {
                Ok(w) => w,
                Err(e) => return Some(api_error(&id, e)),
            };
            let permit = match in_flight.clone().try_acquire_owned() {
                Ok(p) => p,
                Err(_) => return Some(too_many_in_flight(&id)),
            };
            let s = s.clone();
            let out = out_tx.clone();
            let client = client.clone();
            let jogs = jogs.clone();
            tokio::spawn(async move {
                let raw = Value::Object(params);
                let r = blocks::dispatch(&s, (at, block.name), &axis, raw, client, wait)
                    .await
                    .expect("a block of the catalogue");
                let msg = match r {
                    Ok(v) => {
                        if block.keepalive {
                            let mut held = jogs.lock().unwrap();
                            held.retain(|id| commands::get(&s, *id).is_some_and(|c| !c.is_final));
                            held.push(v.id);
                        }
                        rpc_result(&id, serde_json::to_value(v).unwrap_or_default())
                    }
                    Err(e) => api_error(&id, e),
                };
                if !notification {
                    let _ = out.send(msg).await;
                }
                drop(permit);
            });
            None
        }
    })();
    reply.filter(|_| !notification)
}

/// Whether the socket's client may still do what needs `need`: its session or token is checked
/// again at every request (it may have been logged out, revoked or given another role since
/// the socket opened), and a socket opened before the first user existed gets nothing more.
fn may(s: &AppState, client: &ClientInfo, need: Role) -> Result<(), AppError> {
    match &client.identity {
        Some(p) => {
            let now = s.auth.recheck(p)?;
            if now.role < need {
                return Err(crate::auth::forbidden(&now, need));
            }
            Ok(())
        }
        None if s.auth.enabled() => Err(AppError::new(
            axum::http::StatusCode::UNAUTHORIZED,
            "unauthenticated",
            "Authentication required",
            "authentication was enabled after this socket opened: reconnect with a session or token",
        )),
        None => Ok(()),
    }
}

/// Runs a request's work off the session's loop (at most `MAX_IN_FLIGHT` at once) and
/// answers with its result or its problem, unless the request was a notification.
fn answer_later(
    in_flight: &Arc<tokio::sync::Semaphore>,
    out_tx: &mpsc::Sender<String>,
    id: &Value,
    notification: bool,
    work: impl std::future::Future<Output = Result<Value, AppError>> + Send + 'static,
) -> Option<String> {
    let Ok(permit) = in_flight.clone().try_acquire_owned() else {
        return Some(too_many_in_flight(id));
    };
    let (out, id) = (out_tx.clone(), id.clone());
    tokio::spawn(async move {
        let r = work.await;
        if !notification {
            let msg = match r {
                Ok(v) => rpc_result(&id, v),
                Err(e) => api_error(&id, e),
            };
            let _ = out.send(msg).await;
        }
        drop(permit);
    });
    None
}

fn too_many_in_flight(id: &Value) -> String {
    rpc_error(
        id,
        -32000,
        &format!("too many requests in flight ({MAX_IN_FLIGHT}): read their responses first"),
        Some(json!({"code": "too_many_in_flight"})),
    )
}

/// A websocket session without a socket, for `motiond scenario run`: the same methods, with the
/// same rules (jogs held by it, released when it ends), called one at a time.
pub struct LocalSession {
    s: Arc<AppState>,
    subs: Vec<Sub>,
    notices: Option<broadcast::Receiver<Arc<crate::app::CommandNotice>>>,
    client: ClientInfo,
    out_tx: mpsc::Sender<String>,
    out_rx: mpsc::Receiver<String>,
    jogs: Arc<Mutex<Vec<u64>>>,
    in_flight: Arc<tokio::sync::Semaphore>,
    next_id: u64,
}

impl LocalSession {
    pub fn new(s: Arc<AppState>, client: ClientInfo) -> Self {
        let (out_tx, out_rx) = mpsc::channel(64);
        LocalSession {
            s,
            subs: Vec::new(),
            notices: None,
            client,
            out_tx,
            out_rx,
            jogs: Arc::default(),
            in_flight: Arc::new(tokio::sync::Semaphore::new(MAX_IN_FLIGHT)),
            next_id: 1,
        }
    }

    /// Calls `method` and waits for its answer (the JSON-RPC response object).
    pub async fn call(&mut self, method: &str, params: Value) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        let text =
            json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}).to_string();
        let mut answer = handle(
            &self.s,
            &mut self.subs,
            &mut self.notices,
            &self.client,
            &self.out_tx,
            &self.jogs,
            &self.in_flight,
            &text,
        );
        loop {
            if let Some(a) = answer.take() {
                let v: Value = serde_json::from_str(&a).unwrap_or(Value::Null);
                if v["id"] == id {
                    return v;
                }
            }
            match self.out_rx.recv().await {
                Some(a) => answer = Some(a),
                None => return Value::Null,
            }
        }
    }

    /// Ends the session as a closed socket does: its jogs are released.
    pub async fn close(self) {
        let held: Vec<u64> = std::mem::take(&mut *self.jogs.lock().unwrap());
        for id in held {
            if commands::get(&self.s, id).is_some_and(|c| !c.is_final) {
                let _ = commands::release(&self.s, id, &self.client).await;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A socket woken at most three ticks late sends the tick it was due at; later, the tick now.
    #[test]
    fn a_late_socket_sends_its_due_tick_when_at_most_three_ticks_late() {
        let sub = |every: u64, due: u64, topic: Topic| Sub {
            key: String::new(),
            key_json: Arc::from(""),
            topic,
            every,
            due,
            last: None,
            seen: None,
        };
        let axis = || Topic::Axis {
            id: 1,
            slot: 0,
            name: "x".into(),
        };
        // 50 Hz (every 4th tick), due at 40: woken at 40 to 43 it sends 40.
        let subs = [sub(4, 40, axis()), sub(1, 0, Topic::Commands)];
        for now in 40..=43 {
            assert_eq!(sending_tick(now, &subs), 40, "woken at {now}");
        }
        // Further behind: the tick now (the newest state), also at a slow rate.
        assert_eq!(sending_tick(44, &subs), 44);
        assert_eq!(sending_tick(1900, &[sub(2000, 0, axis())]), 1900);
        // The earliest due subscription counts.
        let mixed = [sub(20, 60, Topic::System), sub(2, 42, axis())];
        assert_eq!(sending_tick(45, &mixed), 42);
        assert_eq!(sending_tick(46, &mixed), 46);
        // Woken before it: the due tick.
        assert_eq!(sending_tick(39, &subs), 40);
        assert_eq!(sending_tick(43, &[]), 43);
    }

    /// The update written from the feed's ready JSON is the `UpdateParams` notification the
    /// AsyncAPI document describes (the same JSON value; members in another order).
    #[test]
    fn an_update_from_the_feed_is_the_described_notification() {
        let mut data = Map::new();
        data.insert("set_position".into(), json!(12.5));
        data.insert("state".into(), json!("discrete_motion"));
        for (topic, full) in [("axes/x/status", false), ("axes/\"q\"/status", true)] {
            let typed = notify(
                "update",
                UpdateParams {
                    topic: topic.into(),
                    cycle: 4711,
                    full,
                    data: data.clone(),
                },
            );
            let fast = update_message(
                &serde_json::to_string(topic).unwrap(),
                4711,
                full,
                &serde_json::to_string(&data).unwrap(),
            );
            let parse = |t: &str| serde_json::from_str::<Value>(t).unwrap();
            assert_eq!(parse(&fast), parse(&typed), "{fast}");
        }
    }
}
