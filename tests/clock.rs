//! Virtual time over HTTP and the websocket (issue 26): `--clock virtual` stands until a client
//! advances it, every timer follows it, and two runs of the same requests give the same answers.

mod common;

use std::time::Duration;

use common::*;
use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use tokio_tungstenite::tungstenite::Message;

fn virtual_server() -> Server {
    Server::start_with(
        ":memory:",
        &["--clock", "virtual", "--control-lease", "true"],
    )
}

async fn clock(s: &Server) -> Value {
    let r = get(s, "/api/v1/clock").await;
    assert_eq!(r.status, 200, "{}", r.text);
    r.json
}

async fn advance(s: &Server, body: Value) -> Value {
    let r = post(s, "/api/v1/clock/advance", body).await;
    assert_eq!(r.status, 200, "{}", r.text);
    r.json
}

/// Sends a block without waiting; the command's id.
async fn command(s: &Server, axis: &str, block: &str, body: Value) -> u64 {
    let r = post(s, &format!("/api/v1/axes/{axis}/{block}"), body).await;
    assert_eq!(r.status, 202, "{block}: {}", r.text);
    r.json["id"].as_u64().unwrap()
}

/// Enables `axis` in virtual time: the power command, then the clock run until its Status.
async fn power(s: &Server, axis: &str) -> u64 {
    let id = command(s, axis, "power", json!({})).await;
    let a = advance(s, json!({"until": {"command": id}, "max_seconds": 5})).await;
    assert_eq!(a["until"]["reached"], true, "{a}");
    id
}

const MOVE: &str =
    r#"{"position": 100, "velocity": 50, "acceleration": 500, "deceleration": 500, "jerk": 5000}"#;

#[tokio::test(flavor = "multi_thread")]
async fn the_virtual_clock_stands_until_advanced_and_requests_apply_at_the_next_cycle() {
    let s = virtual_server();
    let c = clock(&s).await;
    assert_eq!(c["mode"], "virtual", "{c}");
    assert_eq!(c["cycle"], 0, "{c}");
    // Nothing runs by itself: the power command is accepted for cycle 1 and stays busy.
    let id = command(&s, "x", "power", json!({})).await;
    let cmd = get(&s, &format!("/api/v1/commands/{id}")).await.json;
    assert_eq!(cmd["accepted_cycle"], 1, "{cmd}");
    assert_eq!(cmd["submitted_at"], "1970-01-01T00:00:00.000Z", "{cmd}");
    assert_eq!(clock(&s).await["cycle"], 0);
    assert_eq!(status(&s, "x").await["status"]["state"], "disabled");

    let a = advance(&s, json!({"cycles": 250})).await;
    assert_eq!(
        (a["from_cycle"].as_u64(), a["cycles"].as_u64()),
        (Some(0), Some(250)),
        "{a}"
    );
    assert_eq!(a["clock"]["cycle"], 250, "{a}");
    assert_eq!(a["clock"]["time_s"], 0.25, "{a}");
    assert_eq!(a["clock"]["advancing"], false, "{a}");
    let st = status(&s, "x").await;
    assert_eq!(st["cycle"], 250, "{st}");
    assert_eq!(st["status"]["state"], "standstill", "{st}");
    // Seconds round up to whole cycles.
    let a = advance(&s, json!({"seconds": 0.0105})).await;
    assert_eq!(a["cycles"], 11, "{a}");
    assert_eq!(clock(&s).await["cycle"], 261);
}

#[tokio::test(flavor = "multi_thread")]
async fn an_advance_until_a_milestone_stops_at_exactly_its_cycle() {
    let s = virtual_server();
    power(&s, "x").await;
    let id = command(
        &s,
        "x",
        "move-absolute",
        serde_json::from_str(MOVE).unwrap(),
    )
    .await;
    let a = advance(&s, json!({"until": {"command": id}, "max_seconds": 30})).await;
    let cmd = &a["until"]["command"];
    assert_eq!(a["until"]["reached"], true, "{a}");
    assert_eq!(a["until"]["milestone"], "done", "{a}");
    assert_eq!(cmd["state"], "done", "{a}");
    // The clock stands at the cycle of Done: the status there is the target, the set velocity 0.
    assert_eq!(a["clock"]["cycle"], cmd["last_cycle"], "{a}");
    let st = status(&s, "x").await;
    assert_eq!(st["cycle"], cmd["last_cycle"], "{st}");
    assert_eq!(st["status"]["set_position"], 100.0, "{st}");

    // A velocity move's milestone is InVelocity: the clock stops when it is reached, the axis
    // is at its velocity at that cycle and was not one cycle before.
    let id = command(
        &s,
        "x",
        "move-velocity",
        json!({"velocity": 20, "direction": "negative",
        "acceleration": 500, "deceleration": 500, "jerk": 5000}),
    )
    .await;
    let a = advance(&s, json!({"until": {"command": id}, "max_cycles": 10000})).await;
    assert_eq!(a["until"]["milestone"], "in_velocity", "{a}");
    assert_eq!(a["until"]["command"]["outputs"]["in_velocity"], true, "{a}");
    let events = a["until"]["command"]["events"].as_array().unwrap();
    let first_in_velocity = events
        .iter()
        .find(|e| e["outputs"]["in_velocity"] == true)
        .unwrap();
    assert_eq!(first_in_velocity["cycle"], a["clock"]["cycle"], "{a}");
    assert_eq!(status(&s, "x").await["status"]["set_velocity"], -20.0);

    // A bound that comes first: not reached, the clock at the bound.
    let id = command(&s, "x", "halt", json!({"deceleration": 10, "jerk": 100})).await;
    let a = advance(&s, json!({"until": {"command": id}, "max_cycles": 7})).await;
    assert_eq!(a["until"]["reached"], false, "{a}");
    assert_eq!(a["cycles"], 7, "{a}");
}

#[tokio::test(flavor = "multi_thread")]
async fn a_wait_times_out_after_its_virtual_time_not_its_wall_time() {
    let s = virtual_server();
    power(&s, "x").await;
    let url = s.url("/api/v1/axes/x/move-absolute?wait=true&timeout_ms=300");
    let waiting = tokio::spawn(async move {
        req(
            reqwest::Method::POST,
            &url,
            Some(serde_json::from_str(MOVE).unwrap()),
        )
        .await
    });
    // Longer than its timeout in wall time: still waiting while the clock stands.
    let early = tokio::time::timeout(Duration::from_millis(600), async {
        loop {
            if waiting.is_finished() {
                break;
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    })
    .await;
    assert!(early.is_err(), "a ?wait=true answered before the clock ran");
    let from = clock(&s).await["cycle"].as_u64().unwrap();
    // The advance runs past the timeout: the answer is made at the timeout's cycle.
    let a = advance(&s, json!({"seconds": 1})).await;
    assert_eq!(a["cycles"], 1000, "{a}");
    let r = waiting.await.unwrap();
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["wait"]["reached"], false, "{}", r.text);
    assert_eq!(r.json["wait"]["reason"], "timeout", "{}", r.text);
    assert_eq!(
        r.json["wait"]["axis_state"], "discrete_motion",
        "{}",
        r.text
    );
    // The move (about 2.2 s) is still on its way at 1 s.
    assert_eq!(r.json["state"], "active", "{}", r.text);
    assert!(from < 300, "{from}");
}

#[tokio::test(flavor = "multi_thread")]
async fn a_jog_stops_after_exactly_its_dead_man_time_of_virtual_time_however_slowly_the_clock_runs()
{
    let s = virtual_server();
    power(&s, "x").await;
    let id = command(
        &s,
        "x",
        "jog",
        json!({"direction": "forward", "mode": "standard_slow",
        "deadman_timeout": 0.2}),
    )
    .await;
    let accepted = get(&s, &format!("/api/v1/commands/{id}")).await.json["accepted_cycle"]
        .as_u64()
        .unwrap();
    // 150 ms of virtual time in three steps, each a wall-clock age apart (longer than the
    // dead-man itself): the jog runs on, since virtual time is what counts.
    for _ in 0..3 {
        advance(&s, json!({"cycles": 50})).await;
        tokio::time::sleep(Duration::from_millis(300)).await;
    }
    let st = status(&s, "x").await;
    assert_eq!(st["status"]["state"], "continuous_motion", "{st}");
    // Not renewed: the dead-man fires in the jog's 200th cycle (200 ms of virtual time, its
    // first cycle counted) and the axis brakes; the error ends the jog once it stands.
    let a = advance(
        &s,
        json!({"until": {"command": id, "milestone": "done"}, "max_seconds": 5}),
    )
    .await;
    let cmd = &a["until"]["command"];
    assert_eq!(cmd["outputs"]["error_id"], 0x7061, "{a}");
    let fired = cmd["events"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["outputs"]["warning_id"] == 0x7061)
        .unwrap()["cycle"]
        .as_u64()
        .unwrap();
    assert_eq!(fired, accepted + 199, "{a}");
}

#[tokio::test(flavor = "multi_thread")]
async fn the_control_lease_ends_after_its_virtual_time() {
    let s = virtual_server();
    let r = post(&s, "/api/v1/control", json!({"lease_ms": 1000})).await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(
        r.json["holder"]["since"], "1970-01-01T00:00:00.000Z",
        "{}",
        r.text
    );
    tokio::time::sleep(Duration::from_millis(1100)).await;
    // A wall-clock second later it is held still, for the whole lease.
    let c = get(&s, "/api/v1/control").await.json;
    assert_eq!(c["holder"]["expires_in_ms"], 1000, "{c}");
    advance(&s, json!({"cycles": 999})).await;
    let c = get(&s, "/api/v1/control").await.json;
    assert_eq!(c["holder"]["expires_in_ms"], 1, "{c}");
    advance(&s, json!({"cycles": 1})).await;
    let c = get(&s, "/api/v1/control").await.json;
    assert!(c["holder"].is_null(), "{c}");
}

type Ws =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

async fn rpc(ws: &mut Ws, id: u64, method: &str, params: Value) -> Vec<Value> {
    let m = json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params});
    ws.send(Message::Text(m.to_string().into())).await.unwrap();
    let mut seen = Vec::new();
    loop {
        let m = next_message(ws).await.expect("a response");
        let done = m.iter().any(|m| m["id"] == id);
        seen.extend(m);
        if done {
            return seen;
        }
    }
}

/// The messages of the next frame (a batch is several).
async fn next_message(ws: &mut Ws) -> Option<Vec<Value>> {
    loop {
        match tokio::time::timeout(Duration::from_secs(20), ws.next()).await {
            Ok(Some(Ok(Message::Text(t)))) => {
                return Some(match serde_json::from_str(&t).unwrap() {
                    Value::Array(b) => b,
                    m => vec![m],
                });
            }
            Ok(Some(Ok(_))) => continue,
            _ => return None,
        }
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn a_subscription_at_50_hz_gets_one_update_per_20_ms_of_virtual_time() {
    let s = virtual_server();
    power(&s, "x").await;
    let (mut ws, _) = tokio_tungstenite::connect_async(format!("ws://{}/api/v1/ws", s.addr))
        .await
        .unwrap();
    let mut seen = rpc(
        &mut ws,
        1,
        "subscribe",
        json!({"topic": "axes/x/status", "rate_hz": 50}),
    )
    .await;
    // A slow move: the set position changes every cycle, so every tick has something to send.
    command(
        &s,
        "x",
        "move-velocity",
        json!({"velocity": 5, "acceleration": 500,
        "deceleration": 500, "jerk": 5000}),
    )
    .await;
    let from = clock(&s).await["cycle"].as_u64().unwrap();
    let a = advance(&s, json!({"seconds": 1})).await;
    let to = a["clock"]["cycle"].as_u64().unwrap();
    // Every tick up to the advance's end was held: the last one is within 20 ms of it.
    while !seen.iter().any(|m| {
        m["method"] == "update" && m["params"]["cycle"].as_u64().is_some_and(|c| c + 20 > to)
    }) {
        seen.extend(
            next_message(&mut ws)
                .await
                .expect("the update at the last tick"),
        );
    }
    let cycles: Vec<u64> = seen
        .iter()
        .filter(|m| m["method"] == "update")
        .filter_map(|m| m["params"]["cycle"].as_u64())
        .filter(|c| *c > from && *c <= to)
        .collect();
    assert_eq!(cycles.len(), 50, "{cycles:?}");
    assert!(cycles.windows(2).all(|w| w[1] - w[0] == 20), "{cycles:?}");
}

/// One run of a short sequence: a move recorded by the scope, a fault, a reset.
async fn sequence(s: &Server) -> (String, Vec<Value>, Value, Vec<Value>) {
    power(s, "x").await;
    let r = post(
        s,
        "/api/v1/scope/recordings",
        json!({"channels": [
        {"axis": "x", "signal": "set_position"}, {"axis": "x", "signal": "actual_position"},
        {"axis": "x", "signal": "following_error"}], "duration_s": 1.5, "trigger": null}),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let rec = r.json["id"].as_u64().unwrap();
    let id = command(s, "x", "move-absolute", serde_json::from_str(MOVE).unwrap()).await;
    advance(s, json!({"seconds": 0.7})).await;
    let r = post(
        s,
        "/api/v1/axes/x/simulation/fault",
        json!({"kind": "drive_fault", "code": 8976}),
    )
    .await;
    assert_eq!(r.status, 204, "{}", r.text);
    advance(s, json!({"until": {"command": id}, "max_seconds": 5})).await;
    post(
        s,
        "/api/v1/axes/x/simulation/fault",
        json!({"kind": "clear"}),
    )
    .await;
    let reset = command(s, "x", "reset", json!({})).await;
    advance(s, json!({"until": {"command": reset}, "max_seconds": 5})).await;
    advance(s, json!({"seconds": 1})).await;
    let r = get(s, &format!("/api/v1/scope/recordings/{rec}?format=csv")).await;
    assert_eq!(r.status, 200, "{}", r.text);
    let mut commands = get(s, "/api/v1/commands")
        .await
        .json
        .as_array()
        .unwrap()
        .clone();
    // Who sent them differs (the client's port); what they did may not.
    for c in &mut commands {
        c.as_object_mut().unwrap().remove("client");
    }
    // The audit log is written behind: read once the last advance (the fifth) is in.
    let deadline = std::time::Instant::now() + Duration::from_secs(20);
    let audit: Vec<Value> = loop {
        let rows = get(s, "/api/v1/audit?limit=100").await.json;
        let rows = rows.as_array().expect("audit rows");
        if rows
            .iter()
            .filter(|e| e["action"] == "clock.advance")
            .count()
            == 5
        {
            break rows
                .iter()
                .map(|e| {
                    json!([
                        e["at"],
                        e["action"],
                        e["target"],
                        e["command_id"],
                        e["outcome"]
                    ])
                })
                .collect();
        }
        assert!(std::time::Instant::now() < deadline, "audit: {rows:?}");
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    (r.text, commands, status(s, "x").await, audit)
}

#[tokio::test(flavor = "multi_thread")]
async fn two_runs_of_the_same_requests_give_identical_scope_data_commands_and_audit() {
    let (a, b) = (virtual_server(), virtual_server());
    let (ra, rb) = tokio::join!(sequence(&a), sequence(&b));
    assert!(ra.0.lines().count() > 1500, "{}", &ra.0[..200]);
    assert_eq!(ra.0, rb.0, "scope CSV");
    assert_eq!(ra.1.len(), 3, "{:?}", ra.1);
    assert_eq!(ra.1, rb.1, "commands");
    assert_eq!(ra.2, rb.2, "status");
    assert!(!ra.3.is_empty());
    let differ: Vec<_> = ra.3.iter().zip(&rb.3).filter(|(a, b)| a != b).collect();
    assert!(
        differ.is_empty() && ra.3.len() == rb.3.len(),
        "audit differs: {differ:?}"
    );
    // The drive fault stopped the move: the run is not a trivial one.
    assert!(
        ra.1.iter()
            .any(|c| c["command"] == "move-absolute" && c["state"] != "done"),
        "{:?}",
        ra.1
    );
}

#[tokio::test(flavor = "multi_thread")]
async fn advances_are_refused_on_a_clock_that_is_not_virtual_and_bad_ones_change_nothing() {
    let real = Server::start();
    let r = post(&real, "/api/v1/clock/advance", json!({"cycles": 10})).await;
    assert_problem(&r, 409, "clock_not_virtual");
    assert_eq!(clock(&real).await["mode"], "real");

    let s = virtual_server();
    for bad in [
        json!({}),
        json!({"cycles": 0}),
        json!({"cycles": 10, "seconds": 1}),
        json!({"seconds": -1}),
        json!({"cycles": 10, "max_cycles": 5}),
        json!({"until": {"command": 1}}),
        json!({"until": {"command": 1}, "max_cycles": 5, "max_seconds": 1}),
    ] {
        let r = post(&s, "/api/v1/clock/advance", bad.clone()).await;
        assert_eq!(r.status, 422, "{bad}: {}", r.text);
    }
    let r = post(
        &s,
        "/api/v1/clock/advance",
        json!({"until": {"command": 999}, "max_cycles": 5}),
    )
    .await;
    assert_problem(&r, 404, "command_not_found");
    assert_eq!(clock(&s).await["cycle"], 0);
}

#[test]
fn virtual_time_needs_the_simulated_bus() {
    let out = bin()
        .args([
            "--db",
            ":memory:",
            "--clock",
            "virtual",
            "--bus",
            "emulated",
            "--listen",
            "127.0.0.1:0",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("needs the simulated bus"), "{err}");
}

#[tokio::test(flavor = "multi_thread")]
async fn a_fast_clock_runs_by_itself_and_waits_follow_it() {
    let s = Server::start_with(":memory:", &["--clock", "fast"]);
    let r = post(
        &s,
        "/api/v1/axes/x/power?wait=true&timeout_ms=5000",
        json!({}),
    )
    .await;
    assert_eq!(r.json["outputs"]["status"], true, "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true&timeout_ms=30000",
        serde_json::from_str(MOVE).unwrap(),
    )
    .await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    let c = clock(&s).await;
    assert_eq!(c["mode"], "fast", "{c}");
    assert!(c["cycle"].as_u64().unwrap() >= 2000, "{c}");
    let r = post(&s, "/api/v1/clock/advance", json!({"cycles": 10})).await;
    assert_problem(&r, 409, "clock_not_virtual");
}

/// Polls the clock until an advance runs (`true`) or none does.
async fn until_advancing(s: &Server, running: bool) {
    let deadline = std::time::Instant::now() + Duration::from_secs(20);
    while clock(s).await["advancing"] != running {
        assert!(
            std::time::Instant::now() < deadline,
            "advancing never became {running}"
        );
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn one_advance_at_a_time_and_a_client_that_goes_away_stops_the_clock_where_it_is() {
    let s = virtual_server();
    power(&s, "x").await;
    let id = command(&s, "x", "move-velocity", json!({"velocity": 5})).await;
    // Until a velocity move's end: only the bound ends this advance (an hour of virtual time).
    let url = s.url("/api/v1/clock/advance");
    let long = tokio::spawn(async move {
        req(
            reqwest::Method::POST,
            &url,
            Some(json!({"until": {"command": id, "milestone": "done"}, "max_seconds": 3600})),
        )
        .await
    });
    until_advancing(&s, true).await;
    let r = post(&s, "/api/v1/clock/advance", json!({"cycles": 10})).await;
    assert_problem(&r, 409, "clock_busy");
    // The client goes away: the clock stops, the move stays as it is.
    long.abort();
    until_advancing(&s, false).await;
    let stood = clock(&s).await["cycle"].as_u64().unwrap();
    assert!(stood < 3_600_000, "{stood}");
    tokio::time::sleep(Duration::from_millis(200)).await;
    assert_eq!(clock(&s).await["cycle"], stood);
    let a = advance(&s, json!({"cycles": 1})).await;
    assert_eq!(a["clock"]["cycle"], stood + 1, "{a}");
}
