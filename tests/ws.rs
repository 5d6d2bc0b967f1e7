//! End-to-end tests of the websocket `/api/v1/ws` (JSON-RPC 2.0).

mod common;

use std::time::Duration;

use common::*;
use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use tokio_tungstenite::tungstenite::Message;

type Stream =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

/// A socket and the JSON-RPC messages of a batch (a JSON array) not read yet.
struct Ws {
    stream: Stream,
    queue: std::collections::VecDeque<Value>,
    /// Batches received (messages that were JSON arrays).
    batches: usize,
}

impl std::ops::Deref for Ws {
    type Target = Stream;
    fn deref(&self) -> &Stream {
        &self.stream
    }
}

impl std::ops::DerefMut for Ws {
    fn deref_mut(&mut self) -> &mut Stream {
        &mut self.stream
    }
}

async fn connect(s: &Server) -> Ws {
    let (stream, _) = tokio_tungstenite::connect_async(format!("ws://{}/api/v1/ws", s.addr))
        .await
        .expect("websocket connects");
    Ws {
        stream,
        queue: Default::default(),
        batches: 0,
    }
}

async fn send(ws: &mut Ws, id: u64, method: &str, params: Value) {
    let m = json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params});
    ws.send(Message::Text(m.to_string().into())).await.unwrap();
}

/// Next JSON-RPC message (one of a batch in turn), or None after `timeout`.
async fn next(ws: &mut Ws, timeout: Duration) -> Option<Value> {
    loop {
        if let Some(m) = ws.queue.pop_front() {
            return Some(m);
        }
        match tokio::time::timeout(timeout, ws.stream.next()).await {
            Ok(Some(Ok(Message::Text(t)))) => match serde_json::from_str(&t).unwrap() {
                Value::Array(batch) => {
                    assert!(batch.len() > 1, "a batch of one: {t}");
                    ws.batches += 1;
                    ws.queue.extend(batch);
                }
                m => return Some(m),
            },
            Ok(Some(Ok(_))) => continue,
            _ => return None,
        }
    }
}

/// Reads until the response with `id` arrives; returns it and everything else seen.
async fn response(ws: &mut Ws, id: u64) -> (Value, Vec<Value>) {
    let mut other = Vec::new();
    loop {
        let m = next(ws, Duration::from_secs(20)).await.expect("response");
        if m["id"] == id {
            return (m, other);
        }
        other.push(m);
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn subscriber_sees_deltas_during_a_move_with_increasing_cycle_stamps() {
    let s = Server::start();
    let mut ws = connect(&s).await;
    send(&mut ws, 1, "power", json!({"axis": "x", "wait": true})).await;
    let (r, _) = response(&mut ws, 1).await;
    assert_eq!(r["result"]["outputs"]["status"], true, "{r}");
    send(
        &mut ws,
        2,
        "subscribe",
        json!({"topic": "axes/x/status", "rate_hz": 50}),
    )
    .await;
    // The first (full) update may come before these replies: keep what came.
    let (r, mut early) = response(&mut ws, 2).await;
    assert_eq!(r["result"]["rate_hz"], 50.0, "{r}");
    send(&mut ws, 3, "subscribe", json!({"topic": "commands"})).await;
    early.extend(response(&mut ws, 3).await.1);
    send(
        &mut ws,
        4,
        "move-absolute",
        json!({"axis": "x", "position": 300.0, "velocity": 400.0}),
    )
    .await;

    let mut updates: Vec<Value> = early
        .into_iter()
        .filter(|m| m["method"] == "update")
        .map(|m| m["params"].clone())
        .collect();
    let mut events = Vec::new();
    let mut move_id = None;
    let deadline = tokio::time::Instant::now() + Duration::from_secs(20);
    while tokio::time::Instant::now() < deadline {
        let Some(m) = next(&mut ws, Duration::from_secs(5)).await else {
            break;
        };
        if m["id"] == 4 {
            assert!(m["error"].is_null(), "{m}");
            move_id = Some(m["result"]["id"].clone());
        } else if m["method"] == "update" {
            updates.push(m["params"].clone());
        } else if m["method"] == "command_event" {
            let done =
                m["params"]["final"] == true && Some(&m["params"]["command"]) == move_id.as_ref();
            events.push(m["params"].clone());
            if done {
                break;
            }
        }
    }
    assert!(move_id.is_some(), "no response to move-absolute");
    assert!(
        events
            .iter()
            .any(|e| Some(&e["command"]) == move_id.as_ref() && e["state"] == "done"),
        "no done event: {events:?}"
    );
    assert!(updates.len() >= 5, "too few updates: {}", updates.len());
    assert_eq!(updates[0]["full"], true);
    let full_keys = updates[0]["data"].as_object().unwrap().len();
    assert!(full_keys > 20, "first update is not the full status");
    let deltas: Vec<&Value> = updates[1..].iter().collect();
    assert!(deltas.iter().all(|u| u["full"] == false));
    assert!(
        deltas
            .iter()
            .all(|u| u["data"].as_object().unwrap().len() < full_keys),
        "a delta carried every field"
    );
    assert!(
        deltas
            .iter()
            .any(|u| u["data"].get("set_position").is_some()),
        "no position delta"
    );
    let cycles: Vec<u64> = updates
        .iter()
        .map(|u| u["cycle"].as_u64().unwrap())
        .collect();
    assert!(
        cycles.windows(2).all(|w| w[0] < w[1]),
        "cycle stamps not increasing: {cycles:?}"
    );
    let ev_cycles: Vec<u64> = events
        .iter()
        .filter(|e| Some(&e["command"]) == move_id.as_ref())
        .map(|e| e["cycle"].as_u64().unwrap())
        .collect();
    assert!(ev_cycles.windows(2).all(|w| w[0] <= w[1]), "{ev_cycles:?}");
}

#[tokio::test(flavor = "multi_thread")]
async fn rpc_errors_and_unsubscribe() {
    let s = Server::start();
    let mut ws = connect(&s).await;
    ws.send(Message::Text("{not json".into())).await.unwrap();
    let m = next(&mut ws, Duration::from_secs(5)).await.unwrap();
    assert_eq!(m["error"]["code"], -32700);
    send(&mut ws, 1, "teleport", json!({})).await;
    assert_eq!(response(&mut ws, 1).await.0["error"]["code"], -32601);
    send(
        &mut ws,
        2,
        "move-absolute",
        json!({"axis": "x", "position": 1.0, "velocity": -1.0}),
    )
    .await;
    let (r, _) = response(&mut ws, 2).await;
    assert_eq!(r["error"]["code"], -32602, "{r}");
    assert_eq!(r["error"]["data"]["status"], 422);
    send(
        &mut ws,
        3,
        "move-absolute",
        json!({"axis": "x", "position": 1.0, "velocity": 1.0}),
    )
    .await;
    let (r, _) = response(&mut ws, 3).await;
    assert_eq!(r["error"]["data"]["error_id"], 0x4B01, "{r}");
    // The newer function blocks are methods too, validated like their REST endpoints.
    send(
        &mut ws,
        30,
        "move-superimposed",
        json!({"axis": "x", "distance": 1.0, "velocity_diff": 0.0, "velocity_process": 10.0, "length": 10.0}),
    )
    .await;
    let (r, _) = response(&mut ws, 30).await;
    assert_eq!(
        r["error"]["data"]["errors"][0]["field"], "velocity_diff",
        "{r}"
    );
    send(
        &mut ws,
        31,
        "gear-in-dyn",
        json!({"axis": "y", "master": "nobody", "gear_ratio": 1.0}),
    )
    .await;
    let (r, _) = response(&mut ws, 31).await;
    assert_eq!(r["error"]["data"]["errors"][0]["field"], "master", "{r}");
    send(&mut ws, 32, "abort-superposition", json!({"axis": "x"})).await;
    let (r, _) = response(&mut ws, 32).await;
    assert_eq!(r["result"]["command"], "abort-superposition", "{r}");
    send(
        &mut ws,
        4,
        "subscribe",
        json!({"topic": "axes/nope/status"}),
    )
    .await;
    assert_eq!(response(&mut ws, 4).await.0["error"]["code"], -32602);
    send(
        &mut ws,
        5,
        "subscribe",
        json!({"topic": "system", "rate_hz": 1000}),
    )
    .await;
    let (r, mut seen) = response(&mut ws, 5).await;
    assert_eq!(r["result"]["rate_hz"], 100.0, "rate not capped: {r}");
    // A rate too small to schedule is refused; the session goes on. (The system topic's
    // notifications may arrive between these answers: they are kept, in order.)
    for (k, rate) in [(50u64, json!(1e-300)), (51, json!(0)), (52, json!("fast"))] {
        send(
            &mut ws,
            k,
            "subscribe",
            json!({"topic": "commands", "rate_hz": rate}),
        )
        .await;
        let (r, other) = response(&mut ws, k).await;
        assert_eq!(r["error"]["code"], -32602, "{r}");
        seen.extend(other);
    }
    // The first notification of a subscription is the full object, whenever it came.
    let first = match seen.into_iter().find(|m| m["params"]["topic"] == "system") {
        Some(m) => m,
        None => next(&mut ws, Duration::from_secs(5)).await.unwrap(),
    };
    assert_eq!(first["params"]["topic"], "system");
    assert_eq!(first["params"]["full"], true);
    // wait must be a boolean, and timeout_ms at most 600000.
    for (k, extra) in [
        (40u64, json!({"wait": "yes"})),
        (41, json!({"timeout_ms": 600001})),
        (42, json!({"wait": true, "timeout_ms": -5})),
    ] {
        let mut p = json!({"axis": "x", "position": 1.0, "velocity": 1.0});
        p.as_object_mut()
            .unwrap()
            .extend(extra.as_object().unwrap().clone());
        send(&mut ws, k, "move-absolute", p).await;
        let (r, _) = response(&mut ws, k).await;
        assert_eq!(r["error"]["code"], -32602, "{r}");
    }
    // A notification (no id) is carried out but not answered: the next answer is id 43's.
    let m = json!({"jsonrpc": "2.0", "method": "unsubscribe", "params": {"topic": "commands"}});
    ws.send(Message::Text(m.to_string().into())).await.unwrap();
    let m = json!({"jsonrpc": "2.0", "method": "move-absolute", "params": {"axis": "x"}});
    ws.send(Message::Text(m.to_string().into())).await.unwrap();
    send(&mut ws, 43, "unsubscribe", json!({"topic": "nothing"})).await;
    let m = loop {
        let m = next(&mut ws, Duration::from_secs(5)).await.unwrap();
        if m.get("id").is_some() {
            break m;
        }
    };
    assert_eq!(m["id"], 43, "a notification was answered: {m}");
    send(&mut ws, 6, "unsubscribe", json!({"topic": "system"})).await;
    response(&mut ws, 6).await;
    // after the unsubscribe reply no system update arrives any more
    assert!(next(&mut ws, Duration::from_millis(300)).await.is_none());
}

async fn socket_jog(ws: &mut Ws, rpc: u64, deadman: f64) -> u64 {
    let params = json!({"axis": "y", "direction": "forward", "deadman_timeout": deadman});
    send(ws, rpc, "jog", params).await;
    let (r, _) = response(ws, rpc).await;
    assert!(r["error"].is_null(), "{r}");
    r["result"]["id"].as_u64().unwrap()
}

/// A socket jog runs while the client renews it (keepalives on the socket), stops by its
/// dead-man when the client falls silent with the socket still open (a frozen page), and is
/// released at once when the socket closes.
#[tokio::test(flavor = "multi_thread")]
async fn a_socket_jog_runs_while_renewed_stops_when_its_client_falls_silent_and_is_released_on_close()
 {
    const DEADMAN_TIMEOUT: u64 = 0x7061;
    let s = Server::start();
    power_on(&s, "y").await;
    // Renewed every 100 ms for 3 s (three dead-man times of 1 s): still running. (A machine
    // stalled for the whole second would stop it — as it should.)
    let mut ws = connect(&s).await;
    let id = socket_jog(&mut ws, 1, 1.0).await;
    for k in 0..30u64 {
        send(&mut ws, 10 + k, "keepalive", json!({"command": id})).await;
        let (r, _) = response(&mut ws, 10 + k).await;
        assert!(r["error"].is_null(), "{r}");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    let c = get(&s, &format!("/api/v1/commands/{id}")).await;
    assert_eq!(
        c.json["final"], false,
        "renewed socket jog stopped: {}",
        c.text
    );
    assert_eq!(c.json["outputs"]["warning_id"], 0, "{}", c.text);

    // Silent with the socket open: the dead-man stops it, the socket does not renew it.
    let fin = until_final(&s, id, 10).await;
    assert_eq!(fin["state"], "error", "{fin}");
    assert_eq!(
        fin["outputs"]["error_id"].as_u64(),
        Some(DEADMAN_TIMEOUT),
        "{fin}"
    );
    let t0 = std::time::Instant::now();
    while status(&s, "y").await["status"]["moving"] != false {
        assert!(t0.elapsed() < Duration::from_secs(10), "y still moving");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }

    // A jog whose socket closes is released: done, not a dead-man error (a dead-man of 5 s
    // leaves the server ample time to see the close on a busy machine).
    let mut config = get(&s, "/api/v1/axes/y").await.json["config"].clone();
    config["dynamics"]["jog_deadman_max"] = json!(5.0);
    let r = put(&s, "/api/v1/axes/y", config).await;
    assert_eq!(r.json["change"]["rebuild"], false, "{}", r.text);
    let id = socket_jog(&mut ws, 2, 5.0).await;
    send(&mut ws, 50, "keepalive", json!({"command": id})).await;
    response(&mut ws, 50).await;
    drop(ws);
    let fin = until_final(&s, id, 10).await;
    assert_eq!(fin["state"], "done", "{fin}");
}

/// Issue 3: "a jog whose keepalives stop halts within dead-man time + one cycle". Keepalives
/// sent over the socket answer with the cycle they take effect in; the kernel reports the
/// dead-man expiry (warning 0x7061, in_velocity false) as a command event in the cycle it fires.
#[tokio::test(flavor = "multi_thread")]
async fn a_jog_whose_keepalives_stop_halts_within_deadman_plus_one_cycle() {
    const DEADMAN_TIMEOUT: u64 = 0x7061;
    let s = Server::start();
    power_on(&s, "y").await;
    let mut ws = connect(&s).await;
    send(&mut ws, 1, "subscribe", json!({"topic": "commands"})).await;
    response(&mut ws, 1).await;
    let deadman: f64 = 0.3;
    let deadman_cycles = (deadman / 0.001).round() as u64;
    // A REST jog renewed over the socket: only the keepalives below renew it.
    let jog = post(
        &s,
        "/api/v1/axes/y/jog",
        json!({"direction": "forward", "mode": "standard_fast", "deadman_timeout": deadman}),
    )
    .await;
    assert_eq!(jog.status, 202, "{}", jog.text);
    let id = jog.json["id"].as_u64().unwrap();
    let accepted = jog.json["accepted_cycle"].as_u64().unwrap();
    let mut seen = Vec::new();
    let mut keepalives = Vec::new();
    for k in 0..5u64 {
        send(&mut ws, 10 + k, "keepalive", json!({"command": id})).await;
        let (r, other) = response(&mut ws, 10 + k).await;
        seen.extend(other);
        assert!(r["error"].is_null(), "{r}");
        assert_eq!(r["result"]["command"], id, "{r}");
        keepalives.push(r["result"]["cycle"].as_u64().unwrap());
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert!(keepalives.windows(2).all(|w| w[0] < w[1]), "{keepalives:?}");
    // Command events of the jog until it is final.
    let mut events: Vec<Value> = seen
        .into_iter()
        .filter(|m| m["method"] == "command_event" && m["params"]["command"] == id)
        .map(|m| m["params"].clone())
        .collect();
    while !events.iter().any(|e| e["final"] == true) {
        let m = next(&mut ws, Duration::from_secs(10))
            .await
            .expect("the jog ends");
        assert_ne!(m["method"], "commands_lagged", "{m}");
        if m["method"] == "command_event" && m["params"]["command"] == id {
            events.push(m["params"].clone());
        }
    }
    let fired = events
        .iter()
        .find(|e| e["outputs"]["warning_id"].as_u64() == Some(DEADMAN_TIMEOUT))
        .unwrap_or_else(|| panic!("no dead-man event: {events:?}"));
    assert_eq!(fired["outputs"]["in_velocity"], false, "{fired}");
    assert_eq!(fired["final"], false, "{fired}");
    let fired_cycle = fired["cycle"].as_u64().unwrap();
    // The keepalives that took effect before the dead-man fired (on a very slow machine a late
    // one may arrive after it; it no longer matters then).
    let last = *keepalives
        .iter()
        .filter(|c| **c < fired_cycle)
        .max()
        .unwrap_or_else(|| panic!("no keepalive before the dead-man: {keepalives:?} {fired}"));
    assert!(
        fired_cycle - last <= deadman_cycles + 1,
        "dead-man fired {} cycles after the last keepalive (limit {}): {keepalives:?} {events:?}",
        fired_cycle - last,
        deadman_cycles + 1
    );
    assert!(
        fired_cycle - last + 1 >= deadman_cycles,
        "dead-man fired early, {} cycles after the last keepalive: {keepalives:?} {events:?}",
        fired_cycle - last
    );
    assert!(
        fired_cycle > accepted + deadman_cycles + 1,
        "the keepalives did not extend the jog: accepted {accepted}, fired {fired_cycle}"
    );
    let fin = events.last().unwrap();
    assert_eq!(fin["state"], "error", "{fin}");
    assert_eq!(
        fin["outputs"]["error_id"].as_u64(),
        Some(DEADMAN_TIMEOUT),
        "{fin}"
    );
    assert!(fin["cycle"].as_u64().unwrap() > fired_cycle, "{fin}");
    assert_eq!(status(&s, "y").await["status"]["moving"], false);
}

/// An axis subscription follows its axis; when the axis is deleted the subscription ends with
/// a notification instead of going silent (or streaming whatever takes the slot next).
#[tokio::test(flavor = "multi_thread")]
async fn an_axis_subscription_ends_when_its_axis_is_deleted() {
    let s = Server::start();
    let mut ws = connect(&s).await;
    send(
        &mut ws,
        1,
        "subscribe",
        json!({"topic": "axes/y/status", "rate_hz": 50}),
    )
    .await;
    // The first (full) update may come before the reply.
    let early = response(&mut ws, 1).await.1;
    let first = match early.into_iter().next() {
        Some(m) => m,
        None => next(&mut ws, Duration::from_secs(5)).await.unwrap(),
    };
    assert_eq!(first["params"]["full"], true, "{first}");
    let r = delete(&s, "/api/v1/axes/y").await;
    assert_eq!(r.status, 204, "{}", r.text);
    let ended = loop {
        let m = next(&mut ws, Duration::from_secs(5))
            .await
            .expect("subscription_ended");
        if m["method"] == "subscription_ended" {
            break m;
        }
        assert_eq!(m["params"]["topic"], "axes/y/status", "{m}");
    };
    assert_eq!(ended["params"]["topic"], "axes/y/status", "{ended}");
    assert_eq!(ended["params"]["reason"], "axis_removed", "{ended}");
    // nothing more for it
    assert!(next(&mut ws, Duration::from_millis(300)).await.is_none());
}

/// Command params are read like REST bodies: an invalid one is -32602 whose `data` is the 422
/// problem, naming the JSON path of the field; relative moves take a `distance`.
#[tokio::test(flavor = "multi_thread")]
async fn command_params_errors_name_the_json_path_and_relative_moves_take_a_distance() {
    let s = Server::start();
    let mut ws = connect(&s).await;
    let cases = [
        (
            "move-absolute",
            json!({"axis": "x", "position": 1.0, "velocity": 5.0, "options": {"blending_position": "far"}}),
            "options.blending_position",
        ),
        (
            "move-absolute",
            json!({"axis": "x", "position": 1.0, "velocity": 5.0, "options": {"blend": 1}}),
            "options.blend",
        ),
        (
            "move-absolute",
            json!({"axis": "x", "position": 1.0}),
            "velocity",
        ),
        (
            "move-absolute",
            json!({"axis": "x", "position": [1.0], "velocity": 5.0}),
            "position",
        ),
        (
            "move-relative",
            json!({"axis": "x", "position": 1.0, "velocity": 5.0}),
            "position",
        ),
        (
            "move-continuous-relative",
            json!({"axis": "x", "position": 1.0, "velocity": 5.0, "end_velocity": 0.0}),
            "position",
        ),
    ];
    for (k, (method, params, field)) in cases.into_iter().enumerate() {
        let id = 100 + k as u64;
        send(&mut ws, id, method, params.clone()).await;
        let (r, _) = response(&mut ws, id).await;
        assert_eq!(r["error"]["code"], -32602, "{params}: {r}");
        assert_eq!(
            r["error"]["data"]["errors"][0]["field"], field,
            "{params}: {r}"
        );
    }
    assert_eq!(get(&s, "/api/v1/commands").await.json, json!([]));
    send(&mut ws, 1, "power", json!({"axis": "x", "wait": true})).await;
    assert_eq!(
        response(&mut ws, 1).await.0["result"]["outputs"]["status"],
        true
    );
    send(
        &mut ws,
        2,
        "move-relative",
        json!({"axis": "x", "distance": 4.0, "velocity": 50.0, "wait": true}),
    )
    .await;
    let (r, _) = response(&mut ws, 2).await;
    assert_eq!(r["result"]["state"], "done", "{r}");
    let st = status(&s, "x").await;
    assert!(
        (st["status"]["set_position"].as_f64().unwrap() - 4.0).abs() < 1e-9,
        "{st}"
    );
}

/// A raw websocket client (handshake and unmasked server frames by hand), so that nothing answers
/// a Ping behind the test's back.
async fn raw_ws(s: &Server) -> tokio::net::TcpStream {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let mut tcp = tokio::net::TcpStream::connect(&s.addr).await.unwrap();
    let req = format!(
        "GET /api/v1/ws HTTP/1.1\r\nHost: {}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n",
        s.addr
    );
    tcp.write_all(req.as_bytes()).await.unwrap();
    let mut head = Vec::new();
    while !head.ends_with(b"\r\n\r\n") {
        head.push(tcp.read_u8().await.unwrap());
    }
    let head = String::from_utf8_lossy(&head);
    assert!(head.starts_with("HTTP/1.1 101"), "{head}");
    tcp
}

/// The next frame from the server: (opcode, payload), or None at end of stream.
async fn raw_frame(tcp: &mut tokio::net::TcpStream) -> Option<(u8, Vec<u8>)> {
    use tokio::io::AsyncReadExt;
    let b0 = tcp.read_u8().await.ok()?;
    let b1 = tcp.read_u8().await.ok()?;
    let len = match b1 & 0x7f {
        126 => tcp.read_u16().await.ok()? as usize,
        127 => tcp.read_u64().await.ok()? as usize,
        n => n as usize,
    };
    let mut payload = vec![0; len];
    tcp.read_exact(&mut payload).await.ok()?;
    Some((b0 & 0x0f, payload))
}

/// The server pings a socket it has heard nothing from for `--ws-ping-s`, and closes it (4408)
/// when the client does not answer within as long again. No sleeps: the test waits for the
/// frames themselves (a generous bound only against a hang).
#[tokio::test(flavor = "multi_thread")]
async fn an_idle_socket_is_pinged_and_closed_when_its_client_does_not_answer() {
    let s = Server::start_with(":memory:", &["--ws-ping-s", "0.3"]);
    let mut tcp = raw_ws(&s).await;
    let frames = async {
        let mut seen = Vec::new();
        while let Some(f) = raw_frame(&mut tcp).await {
            seen.push(f);
        }
        seen
    };
    let seen = tokio::time::timeout(Duration::from_secs(20), frames)
        .await
        .expect("the server closes a socket that does not answer its ping");
    let ops: Vec<u8> = seen.iter().map(|f| f.0).collect();
    assert_eq!(ops, vec![0x9, 0x8], "a ping, then a close: {seen:?}");
    let close = &seen[1].1;
    assert_eq!(u16::from_be_bytes([close[0], close[1]]), 4408, "{seen:?}");
}

/// A client that answers the ping (tungstenite sends the Pong) keeps its socket: the server
/// pings it again after the next idle period instead of closing it.
#[tokio::test(flavor = "multi_thread")]
async fn a_client_that_answers_pings_keeps_its_socket() {
    let s = Server::start_with(":memory:", &["--ws-ping-s", "0.3"]);
    let mut ws = connect(&s).await;
    let mut pings = 0;
    let run = async {
        while pings < 3 {
            match ws.next().await {
                Some(Ok(Message::Ping(_))) => {
                    pings += 1;
                    // Sends the Pong tungstenite has queued.
                    ws.flush().await.unwrap();
                }
                Some(Ok(Message::Close(c))) => panic!("closed after {pings} pings: {c:?}"),
                Some(Ok(_)) => {}
                other => panic!("socket ended after {pings} pings: {other:?}"),
            }
        }
    };
    tokio::time::timeout(Duration::from_secs(20), run)
        .await
        .expect("three pings");
    // And it still works.
    send(&mut ws, 1, "unsubscribe", json!({"topic": "system"})).await;
    assert_eq!(response(&mut ws, 1).await.0["result"], false);
}

/// A socket subscribed to several axes gets one message per tick: the updates due together
/// come as one JSON-RPC batch (an array), each a delta of its own topic; two sockets on the
/// same axis at the same rate get the same updates.
#[tokio::test(flavor = "multi_thread")]
async fn updates_due_together_come_as_one_batch() {
    let s = Server::start();
    let mut a = connect(&s).await;
    let mut b = connect(&s).await;
    power_x_and_y(&mut a).await;
    for (id, topic) in [(1, "axes/x/status"), (2, "axes/y/status")] {
        send(
            &mut a,
            id,
            "subscribe",
            json!({"topic": topic, "rate_hz": 50}),
        )
        .await;
        response(&mut a, id).await;
    }
    send(
        &mut b,
        1,
        "subscribe",
        json!({"topic": "axes/x/status", "rate_hz": 50}),
    )
    .await;
    response(&mut b, 1).await;
    move_x_and_y(&mut a).await;
    // Read a second of updates on both sockets.
    let (mut on_a, mut on_b) = (Vec::new(), Vec::new());
    for (ws, seen) in [(&mut a, &mut on_a), (&mut b, &mut on_b)] {
        let end = tokio::time::Instant::now() + Duration::from_secs(1);
        while tokio::time::Instant::now() < end {
            match next(ws, Duration::from_secs(5)).await {
                Some(m) if m["method"] == "update" => seen.push(m["params"].clone()),
                Some(_) => {}
                None => break,
            }
        }
    }
    assert!(a.batches > 0, "no batch on a socket with two moving axes");
    assert_eq!(b.batches, 0, "a socket with one subscription got a batch");
    for topic in ["axes/x/status", "axes/y/status"] {
        let moving = on_a
            .iter()
            .filter(|u| u["topic"] == topic && u["data"]["set_position"].is_number())
            .count();
        assert!(moving > 5, "{topic}: {moving} position updates");
    }
    // x's status as each socket has it, by cycle (its members as last sent, from the updates
    // read here): the same on both sockets in every cycle both were sent, member by member.
    // (The deltas themselves may differ: a socket that skipped a version gets the delta from
    // the version it has; and the full objects came before the reading began.)
    let (xa, xb) = (
        states(&on_a, "axes/x/status"),
        states(&on_b, "axes/x/status"),
    );
    let mut same = 0;
    for (cycle, sb) in &xb {
        if let Some(sa) = xa.get(cycle) {
            for (k, vb) in sb {
                if let Some(va) = sa.get(k) {
                    assert_eq!(va, vb, "x's {k} at cycle {cycle}");
                }
            }
            assert!(sa.contains_key("set_position") && sb.contains_key("set_position"));
            same += 1;
        }
    }
    assert!(same > 0, "no common cycle between the two sockets");
    for ws in [&mut a, &mut b] {
        send(ws, 99, "stop", json!({"axis": "x"})).await;
    }
}

/// An axis topic's status as a socket has it after each cycle it was sent: the members last
/// sent (from `updates`, whole from a full one on).
fn states(
    updates: &[Value],
    topic: &str,
) -> std::collections::BTreeMap<u64, serde_json::Map<String, Value>> {
    let mut state = serde_json::Map::new();
    let mut by_cycle = std::collections::BTreeMap::new();
    for u in updates.iter().filter(|u| u["topic"] == topic) {
        if u["full"] == true {
            state.clear();
        }
        for (k, v) in u["data"].as_object().expect("an object") {
            state.insert(k.clone(), v.clone());
        }
        by_cycle.insert(u["cycle"].as_u64().expect("a cycle"), state.clone());
    }
    by_cycle
}

/// Powers x and y through `ws`.
async fn power_x_and_y(ws: &mut Ws) {
    for (i, axis) in ["x", "y"].iter().enumerate() {
        let id = 10 + i as u64;
        send(ws, id, "power", json!({"axis": axis, "wait": true})).await;
        let (r, _) = response(ws, id).await;
        assert_eq!(r["result"]["outputs"]["status"], true, "{r}");
    }
}

/// Starts x and y at 20 units/s through `ws`.
async fn move_x_and_y(ws: &mut Ws) {
    for (id, axis) in [(20, "x"), (21, "y")] {
        send(
            ws,
            id,
            "move-velocity",
            json!({"axis": axis, "velocity": 20.0}),
        )
        .await;
        let (r, _) = response(ws, id).await;
        assert!(r["error"].is_null(), "{r}");
    }
}

/// Issue 27: sockets that subscribe alike take one message per tick, made once (`/metrics`
/// counts the ones taken from another socket's), and what they have of an axis is what a
/// socket that subscribed otherwise (and made its own messages) has, cycle by cycle.
#[tokio::test(flavor = "multi_thread")]
async fn sockets_that_subscribe_alike_share_a_tick_s_message() {
    let s = Server::start();
    let (mut a, mut b, mut c) = (connect(&s).await, connect(&s).await, connect(&s).await);
    power_x_and_y(&mut a).await;
    // a and b alike (x, then y); c the other way round.
    for (ws, topics) in [
        (&mut a, ["axes/x/status", "axes/y/status"]),
        (&mut b, ["axes/x/status", "axes/y/status"]),
        (&mut c, ["axes/y/status", "axes/x/status"]),
    ] {
        for (id, topic) in [1, 2].into_iter().zip(topics) {
            send(ws, id, "subscribe", json!({"topic": topic, "rate_hz": 50})).await;
            response(ws, id).await;
        }
    }
    move_x_and_y(&mut a).await;
    let shared = || async {
        let m = get(&s, "/metrics").await;
        let line = m
            .text
            .lines()
            .find(|l| l.starts_with("motiond_ws_messages_shared_total "))
            .unwrap_or_else(|| panic!("no shared count: {}", m.text));
        line.rsplit(' ').next().unwrap().parse::<f64>().unwrap()
    };
    // What a and b have of each axis is what c has, member by member, in every cycle both
    // were sent (asserted); whether each shares a moving cycle with c for both axes.
    let same_as_c = |got: &[Vec<Value>; 3]| {
        let mut all = true;
        for topic in ["axes/x/status", "axes/y/status"] {
            let theirs = states(&got[2], topic);
            for (socket, updates) in got[..2].iter().enumerate() {
                let mut common = 0;
                for (cycle, m) in &states(updates, topic) {
                    if let Some(t) = theirs.get(cycle) {
                        for (k, v) in m.iter().filter(|(k, _)| t.contains_key(*k)) {
                            assert_eq!(v, &t[k], "{topic}'s {k} at {cycle}: {socket} and c differ");
                        }
                        common += usize::from(
                            m.contains_key("set_position") && t.contains_key("set_position"),
                        );
                    }
                }
                all &= common > 0;
            }
        }
        all
    };
    // Read the three sockets in turn until some message was shared (alike sockets that keep
    // up share from their second tick on; a busy machine may take longer).
    let mut got: [Vec<Value>; 3] = Default::default();
    let deadline = tokio::time::Instant::now() + Duration::from_secs(60);
    loop {
        for (ws, seen) in [&mut a, &mut b, &mut c].into_iter().zip(got.iter_mut()) {
            let end = tokio::time::Instant::now() + Duration::from_millis(300);
            while tokio::time::Instant::now() < end {
                match next(ws, Duration::from_secs(5)).await {
                    Some(m) if m["method"] == "update" => seen.push(m["params"].clone()),
                    Some(_) => {}
                    None => break,
                }
            }
        }
        // Until something was shared and each of a, b has cycles in common with c for
        // both axes (busy machines take longer; the deadline is far).
        if shared().await > 0.0 && same_as_c(&got) {
            break;
        }
        assert!(
            tokio::time::Instant::now() < deadline,
            "nothing shared, or no cycle in common, in 60 s"
        );
    }
    for ws in [&mut a, &mut b, &mut c] {
        send(ws, 99, "stop", json!({"axis": "x"})).await;
    }
}

/// A message over 256 KiB closes the socket with code 1009 (message too big), not silently.
#[tokio::test(flavor = "multi_thread")]
async fn an_oversize_message_closes_the_socket_with_1009() {
    let s = Server::start();
    let mut ws = connect(&s).await;
    let big = format!(
        r#"{{"jsonrpc":"2.0","id":1,"method":"subscribe","params":{{"topic":"{}"}}}}"#,
        "x".repeat(300 * 1024)
    );
    ws.send(Message::Text(big.into())).await.unwrap();
    let close = loop {
        match tokio::time::timeout(Duration::from_secs(20), ws.stream.next()).await {
            Ok(Some(Ok(Message::Close(c)))) => break c,
            Ok(Some(Ok(_))) => continue,
            other => panic!("no close frame: {other:?}"),
        }
    };
    let c = close.expect("a close frame with a code");
    assert_eq!(u16::from(c.code), 1009, "{c:?}");
    assert!(c.reason.contains("256 KiB"), "{c:?}");
}

/// A socket names its client by `X-Client-Id` (kept when not ASCII) or, from a browser that
/// cannot set headers, by `?client_id=`; its commands carry the name.
#[tokio::test(flavor = "multi_thread")]
async fn a_socket_names_its_client_by_header_or_query() {
    use tokio_tungstenite::tungstenite::client::IntoClientRequest;
    let s = Server::start();
    let mut req = format!("ws://{}/api/v1/ws", s.addr)
        .into_client_request()
        .unwrap();
    req.headers_mut().insert(
        "x-client-id",
        tokio_tungstenite::tungstenite::http::HeaderValue::from_bytes("Presse-Süd".as_bytes())
            .unwrap(),
    );
    let url = format!("ws://{}/api/v1/ws?client_id=panel-2", s.addr);
    for (req, name) in [
        (req, "Presse-Süd"),
        (url.into_client_request().unwrap(), "panel-2"),
    ] {
        let (stream, _) = tokio_tungstenite::connect_async(req).await.unwrap();
        let mut ws = Ws {
            stream,
            queue: Default::default(),
            batches: 0,
        };
        send(
            &mut ws,
            1,
            "set-override",
            json!({"axis": "x", "velocity_factor": 1.0}),
        )
        .await;
        let (r, _) = response(&mut ws, 1).await;
        assert_eq!(r["result"]["client"]["id"], name, "{r}");
        assert_eq!(r["result"]["client"]["via"], "websocket", "{r}");
    }
    s.stop();
}

/// Reads raw text messages until one parses to a JSON array; it and the messages before it.
async fn next_raw(ws: &mut Ws) -> Value {
    loop {
        match tokio::time::timeout(Duration::from_secs(20), ws.stream.next()).await {
            Ok(Some(Ok(Message::Text(t)))) => return serde_json::from_str(&t).unwrap(),
            Ok(Some(Ok(_))) => continue,
            other => panic!("no message: {other:?}"),
        }
    }
}

/// A client's JSON-RPC 2.0 batch (issue 28): each call started in order (a command does not
/// wait for the one before it) and answered with one array of the responses once all are in
/// (a waited command's answer too); a call without an id is
/// not answered; an empty batch is an invalid request; a batch of notifications alone gets
/// no answer (the next message is the answer to the next request).
#[tokio::test(flavor = "multi_thread")]
async fn a_batch_of_requests_gets_one_array_of_responses() {
    let s = Server::start();
    let mut ws = connect(&s).await;
    let batch = json!([
        {"jsonrpc": "2.0", "id": 1, "method": "power", "params": {"axis": "x", "wait": true}},
        {"jsonrpc": "2.0", "method": "power", "params": {"axis": "y"}},
        {"jsonrpc": "2.0", "id": 3, "method": "read-drive-operation-mode", "params": {"axis": "spindle"}},
        {"jsonrpc": "2.0", "id": 4, "method": "no-such-method", "params": {}},
        7
    ]);
    ws.send(Message::Text(batch.to_string().into()))
        .await
        .unwrap();
    let answer = next_raw(&mut ws).await;
    let answers = answer
        .as_array()
        .unwrap_or_else(|| panic!("an array: {answer}"));
    assert_eq!(answers.len(), 4, "{answer}");
    let by_id = |id: Value| {
        answers
            .iter()
            .find(|a| a["id"] == id)
            .cloned()
            .unwrap_or_else(|| panic!("{id}: {answer}"))
    };
    assert_eq!(
        by_id(json!(1))["result"]["outputs"]["status"],
        true,
        "{answer}"
    );
    assert!(by_id(json!(3))["result"].is_object(), "{answer}");
    assert_eq!(by_id(json!(4))["error"]["code"], -32601, "{answer}");
    assert_eq!(by_id(Value::Null)["error"]["code"], -32600, "{answer}");
    // The notification was carried out.
    let deadline = std::time::Instant::now() + Duration::from_secs(20);
    while status(&s, "y").await["status"]["state"] != "standstill" {
        assert!(std::time::Instant::now() < deadline, "y was not enabled");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    // An empty batch.
    ws.send(Message::Text("[]".into())).await.unwrap();
    let e = next_raw(&mut ws).await;
    assert_eq!(e["error"]["code"], -32600, "{e}");
    // Notifications alone: no answer — the next message answers the next request.
    let only = json!([{"jsonrpc": "2.0", "method": "reset", "params": {"axis": "x"}}]);
    ws.send(Message::Text(only.to_string().into()))
        .await
        .unwrap();
    send(&mut ws, 9, "reset", json!({"axis": "y"})).await;
    let m = next_raw(&mut ws).await;
    assert_eq!(m["id"], 9, "{m}");
    s.stop();
}
