//! End-to-end tests of the websocket `/api/v1/ws` (JSON-RPC 2.0).

mod common;

use std::time::Duration;

use common::*;
use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use tokio_tungstenite::tungstenite::Message;

type Ws =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

async fn connect(s: &Server) -> Ws {
    let (ws, _) = tokio_tungstenite::connect_async(format!("ws://{}/api/v1/ws", s.addr))
        .await
        .expect("websocket connects");
    ws
}

async fn send(ws: &mut Ws, id: u64, method: &str, params: Value) {
    let m = json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params});
    ws.send(Message::Text(m.to_string().into())).await.unwrap();
}

/// Next JSON message, or None after `timeout`.
async fn next(ws: &mut Ws, timeout: Duration) -> Option<Value> {
    loop {
        match tokio::time::timeout(timeout, ws.next()).await {
            Ok(Some(Ok(Message::Text(t)))) => return Some(serde_json::from_str(&t).unwrap()),
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
    let (r, _) = response(&mut ws, 2).await;
    assert_eq!(r["result"]["rate_hz"], 50.0, "{r}");
    send(&mut ws, 3, "subscribe", json!({"topic": "commands"})).await;
    response(&mut ws, 3).await;
    send(
        &mut ws,
        4,
        "move-absolute",
        json!({"axis": "x", "position": 300.0, "velocity": 400.0}),
    )
    .await;

    let mut updates = Vec::new();
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
    let (r, _) = response(&mut ws, 5).await;
    assert_eq!(r["result"]["rate_hz"], 100.0, "rate not capped: {r}");
    let first = next(&mut ws, Duration::from_secs(5)).await.unwrap();
    assert_eq!(first["params"]["topic"], "system");
    assert_eq!(first["params"]["full"], true);
    send(&mut ws, 6, "unsubscribe", json!({"topic": "system"})).await;
    response(&mut ws, 6).await;
    // after the unsubscribe reply no system update arrives any more
    assert!(next(&mut ws, Duration::from_millis(300)).await.is_none());
}

#[tokio::test(flavor = "multi_thread")]
async fn a_jog_sent_over_the_socket_is_held_while_open_and_released_when_it_closes() {
    let s = Server::start();
    power_on(&s, "y").await;
    let mut ws = connect(&s).await;
    send(
        &mut ws,
        1,
        "jog",
        json!({"axis": "y", "direction": "forward", "deadman_timeout": 0.3}),
    )
    .await;
    let (r, _) = response(&mut ws, 1).await;
    assert!(r["error"].is_null(), "{r}");
    let id = r["result"]["id"].as_u64().unwrap();
    tokio::time::sleep(Duration::from_millis(1200)).await;
    let c = get(&s, &format!("/api/v1/commands/{id}")).await;
    assert_eq!(
        c.json["final"], false,
        "jog on an open socket stopped: {}",
        c.text
    );
    drop(ws);
    let fin = until_final(&s, id, 10).await;
    assert_eq!(fin["state"], "done", "{fin}");
}
