//! End-to-end tests of the `motiond` binary over HTTP (issue 3, "How we will know").

mod common;

use std::time::Duration;

use common::*;
use serde_json::{Value, json};

const AXIS_CANNOT_BE_STARTED: u64 = 0x4B01;
const DEADMAN_TIMEOUT: u64 = 0x7061;

#[tokio::test(flavor = "multi_thread")]
async fn demo_axes_exist() {
    let s = Server::start();
    let r = get(&s, "/api/v1/axes").await;
    assert_eq!(r.status, 200);
    let axes = r.json.as_array().unwrap();
    let names: Vec<&str> = axes
        .iter()
        .map(|a| a["config"]["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["x", "y", "spindle"]);
    let x = &axes[0]["config"];
    assert_eq!(x["unit"], "mm");
    assert_eq!(x["soft_limits"], json!({"min": 0.0, "max": 1000.0}));
    assert_eq!(axes[2]["config"]["modulo"]["period"], 360.0);
    assert_eq!(axes[0]["state"], "disabled");
    // by id and by name
    let id = axes[1]["id"].as_i64().unwrap();
    assert_eq!(
        get(&s, &format!("/api/v1/axes/{id}")).await.json["config"]["name"],
        "y"
    );
    assert_eq!(
        get(&s, "/api/v1/axes/spindle").await.json["id"],
        axes[2]["id"]
    );
    assert_problem(&get(&s, "/api/v1/axes/nope").await, 404, "axis_not_found");
    let st = status(&s, "x").await;
    assert_eq!(st["status"]["state"], "disabled");
    assert!(st["cycle"].as_u64().unwrap() > 0);
}

#[tokio::test(flavor = "multi_thread")]
async fn no_demo_gives_an_empty_machine() {
    let s = Server::start_with(":memory:", &["--no-demo", "--cycle-us", "2000"]);
    assert_eq!(get(&s, "/api/v1/axes").await.json, json!([]));
    assert_eq!(get(&s, "/api/v1/system").await.json["cycle_time"], 0.002);
}

#[tokio::test(flavor = "multi_thread")]
async fn power_and_move_absolute_with_wait_reaches_the_target() {
    let s = Server::start();
    power_on(&s, "x").await;
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true&timeout_ms=20000",
        json!({"position": 120.0, "velocity": 300.0}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let loc = r.location.clone().expect("Location header");
    assert_eq!(loc, format!("/api/v1/commands/{}", r.json["id"]));
    assert_eq!(r.json["state"], "done", "{}", r.text);
    assert_eq!(r.json["final"], true);
    assert_eq!(r.json["outputs"]["done"], true);
    let window = get(&s, "/api/v1/axes/x/parameters/AxisTargetPositionWindow")
        .await
        .json["value"]
        .as_f64()
        .unwrap();
    let st = status(&s, "x").await;
    let actual = st["status"]["actual_position"].as_f64().unwrap();
    assert!(
        (actual - 120.0).abs() <= window,
        "actual {actual} not within {window} of 120"
    );
    assert_eq!(st["status"]["state"], "standstill");
    // A timeout alone means wait (decision 94); wait=false with it does not wait.
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?timeout_ms=20000",
        json!({"position": 130.0, "velocity": 300.0}),
    )
    .await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=false&timeout_ms=20000",
        json!({"position": 120.0, "velocity": 300.0}),
    )
    .await;
    assert_eq!(r.json["final"], false, "{}", r.text);
    until_final(&s, r.json["id"].as_u64().unwrap(), 20).await;
    // the resource is kept and listed
    let c = get(&s, &loc).await;
    assert_eq!(c.json["state"], "done");
    let list = get(&s, "/api/v1/commands?axis=x&state=done").await;
    assert!(
        list.json
            .as_array()
            .unwrap()
            .iter()
            .any(|c| c["id"] == r.json["id"]),
        "{}",
        list.text
    );
}

#[tokio::test(flavor = "multi_thread")]
async fn move_on_a_disabled_axis_is_409_with_the_plcopen_error_id() {
    let s = Server::start();
    let r = post(
        &s,
        "/api/v1/axes/y/move-absolute",
        json!({"position": 10.0, "velocity": 10.0}),
    )
    .await;
    assert_problem(&r, 409, "axis_cannot_be_started");
    assert_eq!(r.json["error_id"].as_u64(), Some(AXIS_CANNOT_BE_STARTED));
    // a rejected command leaves no resource
    assert_eq!(get(&s, "/api/v1/commands?axis=y").await.json, json!([]));
}

#[tokio::test(flavor = "multi_thread")]
async fn invalid_requests_are_problems_and_keep_no_command() {
    let s = Server::start();
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute",
        json!({"position": 10.0, "velocity": -5.0}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(r.json["errors"][0]["field"], "velocity");
    // a timeout beyond 10 minutes (a timeout alone means wait=true)
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?timeout_ms=600001",
        json!({"position": 10.0, "velocity": 5.0}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(r.json["errors"][0]["field"], "timeout_ms", "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute",
        json!({"position": "far", "velocity": 5.0}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute",
        json!({"position": 1.0, "velocity": 5.0, "speed": 3}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    assert!(
        r.json["detail"].as_str().unwrap().contains("speed"),
        "{}",
        r.text
    );
    let r = post(&s, "/api/v1/axes/x/move-absolute", json!({"velocity": 5.0})).await;
    assert_problem(&r, 422, "validation_failed");
    let r = req(
        reqwest::Method::POST,
        &s.url("/api/v1/axes/x/move-absolute"),
        None,
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    let client = reqwest::Client::new();
    let raw = client
        .post(s.url("/api/v1/axes/x/move-absolute"))
        .header("content-type", "application/json")
        .body("{\"position\": 1,")
        .send()
        .await
        .unwrap();
    assert_eq!(raw.status().as_u16(), 400);
    assert_eq!(raw.headers()["content-type"], "application/problem+json");
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=maybe",
        json!({"position": 1.0, "velocity": 5.0}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    let r = post(&s, "/api/v1/axes/x/jog", json!({"deadman_timeout": 0.0})).await;
    assert_problem(&r, 422, "validation_failed");
    let r = post(
        &s,
        "/api/v1/axes/x/gear-in",
        json!({"master": "nobody", "ratio_numerator": 1.0, "ratio_denominator": 1}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    let r = post(
        &s,
        "/api/v1/axes/z/move-absolute",
        json!({"position": 1.0, "velocity": 5.0}),
    )
    .await;
    assert_problem(&r, 404, "axis_not_found");
    assert_problem(
        &get(&s, "/api/v1/commands/12345").await,
        404,
        "command_not_found",
    );
    assert_problem(
        &get(&s, "/api/v1/nothing-here").await,
        404,
        "route_not_found",
    );
    assert_eq!(get(&s, "/api/v1/commands").await.json, json!([]));
    // the server is still fine
    assert_eq!(get(&s, "/api/v1/system").await.status, 200);
}

/// A 422 names the JSON path of the field at fault: nested, in an array, unknown, missing or of
/// the wrong type; relative moves take a `distance` and refuse the old `position` by name. None of
/// the refused requests leaves anything behind.
#[tokio::test(flavor = "multi_thread")]
async fn validation_errors_name_the_json_path_of_the_field() {
    let s = Server::start();
    let axes_before = get(&s, "/api/v1/axes").await.json;
    let field_of = |r: &Resp| {
        r.json["errors"][0]["field"]
            .as_str()
            .unwrap_or_default()
            .to_owned()
    };
    let cases = [
        (
            "/api/v1/axes/x/move-absolute",
            json!({"position": 1.0, "velocity": 5.0, "options": {"blending_position": "far"}}),
            "options.blending_position",
            "invalid type",
        ),
        (
            "/api/v1/axes/x/move-absolute",
            json!({"position": 1.0, "velocity": 5.0, "options": {"blend": 3.0}}),
            "options.blend",
            "unknown field",
        ),
        (
            "/api/v1/axes/x/move-absolute",
            json!({"position": 1.0, "velocity": 5.0, "speed": 3}),
            "speed",
            "unknown field",
        ),
        (
            "/api/v1/axes/x/move-absolute",
            json!({"position": 1.0, "velocity": "fast"}),
            "velocity",
            "invalid type",
        ),
        (
            "/api/v1/axes/x/move-absolute",
            json!({"position": 1.0}),
            "velocity",
            "missing field",
        ),
        (
            "/api/v1/axes/x/move-absolute",
            json!({"position": 1.0, "velocity": 5.0, "buffer_mode": "later"}),
            "buffer_mode",
            "unknown variant",
        ),
        (
            "/api/v1/axes/x/home",
            json!({"options": {"search_velocity": true}}),
            "options.search_velocity",
            "invalid type",
        ),
        (
            "/api/v1/scope/recordings",
            json!({"channels": [{"axis": "x", "signal": "set_position"}, {"axis": "y", "signal": "set_position"},
                                {"axis": true, "signal": "set_position"}], "duration_s": 1.0}),
            "channels[2].axis",
            "did not match",
        ),
        (
            "/api/v1/scope/recordings",
            json!({"channels": [{"axis": "x", "signal": "set_position"}, {"axis": "y"}], "duration_s": 1.0}),
            "channels[1].signal",
            "missing field",
        ),
        (
            "/api/v1/axes",
            json!({"name": "z", "unit": "mm", "dynamics": {"max_velocity": 100.0, "acceleration": 1000.0,
                   "deceleration": 1000.0, "jerk": "high", "jog_velocity_slow": 5.0, "jog_velocity_fast": 50.0}}),
            "dynamics.jerk",
            "invalid type",
        ),
        (
            "/api/v1/axes/x/move-relative",
            json!({"position": 5.0, "velocity": 5.0}),
            "position",
            "renamed to `distance`",
        ),
        (
            "/api/v1/axes/x/move-additive",
            json!({"position": 5.0, "velocity": 5.0}),
            "position",
            "renamed to `distance`",
        ),
        (
            "/api/v1/axes/x/move-continuous-relative",
            json!({"position": 5.0, "velocity": 5.0, "end_velocity": 1.0}),
            "position",
            "renamed to `distance`",
        ),
        (
            "/api/v1/axes/x/move-relative",
            json!({"velocity": 5.0}),
            "distance",
            "missing field",
        ),
    ];
    for (path, body, field, message) in cases {
        let r = post(&s, path, body.clone()).await;
        assert_problem(&r, 422, "validation_failed");
        assert_eq!(field_of(&r), field, "{path} {body}: {}", r.text);
        let m = r.json["errors"][0]["message"].as_str().unwrap_or_default();
        assert!(m.contains(message), "{path} {body}: {}", r.text);
    }
    // A parameter write's value of the wrong type, with PUT.
    let r = put(
        &s,
        "/api/v1/axes/x/parameters/AxisVeloMax",
        json!({"value": [1]}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(field_of(&r), "value", "{}", r.text);
    // Nothing was done.
    assert_eq!(get(&s, "/api/v1/commands").await.json, json!([]));
    assert_eq!(get(&s, "/api/v1/scope/recordings").await.json, json!([]));
    assert_eq!(get(&s, "/api/v1/axes").await.json, axes_before);
    // The new names work.
    power_on(&s, "x").await;
    let r = post(
        &s,
        "/api/v1/axes/x/move-relative?wait=true",
        json!({"distance": 7.5, "velocity": 50.0}),
    )
    .await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    assert_eq!(r.json["parameters"]["distance"], 7.5, "{}", r.text);
    let st = status(&s, "x").await;
    assert!(
        (st["status"]["set_position"].as_f64().unwrap() - 7.5).abs() < 1e-9,
        "{st}"
    );
}

#[tokio::test(flavor = "multi_thread")]
async fn stop_locks_the_axis_until_released() {
    let s = Server::start();
    power_on(&s, "y").await;
    let mv = post(
        &s,
        "/api/v1/axes/y/move-velocity",
        json!({"velocity": 50.0}),
    )
    .await;
    assert_eq!(mv.status, 202, "{}", mv.text);
    let stop = post(
        &s,
        "/api/v1/axes/y/stop?wait=true&timeout_ms=10000",
        json!({}),
    )
    .await;
    assert_eq!(stop.status, 202, "{}", stop.text);
    assert_eq!(stop.json["outputs"]["done"], true, "{}", stop.text);
    assert_eq!(
        stop.json["outputs"]["busy"], true,
        "a stop holds the lock: {}",
        stop.text
    );
    let mv_after = get(&s, &format!("/api/v1/commands/{}", mv.json["id"])).await;
    assert_eq!(mv_after.json["state"], "aborted", "{}", mv_after.text);
    assert_eq!(
        status(&s, "y").await["status"]["motion_commands_locked"],
        true
    );
    let r = post(
        &s,
        "/api/v1/axes/y/move-relative",
        json!({"distance": 5.0, "velocity": 10.0}),
    )
    .await;
    assert_problem(&r, 409, "axis_cannot_be_started");
    assert_eq!(r.json["error_id"].as_u64(), Some(AXIS_CANNOT_BE_STARTED));
    let rel = delete(&s, &format!("/api/v1/commands/{}", stop.json["id"])).await;
    assert_eq!(rel.status, 200, "{}", rel.text);
    let stop_final = until_final(&s, stop.json["id"].as_u64().unwrap(), 5).await;
    assert_eq!(stop_final["outputs"]["busy"], false);
    let r = post(
        &s,
        "/api/v1/axes/y/move-relative?wait=true",
        json!({"distance": 5.0, "velocity": 10.0}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["state"], "done", "{}", r.text);
}

/// Issue 3: "a jog whose keepalives stop halts within dead-man time + one cycle". Without
/// keepalives the dead-man counts from the cycle the jog took effect in (its first event); the
/// kernel reports the expiry in the cycle it fires (in_velocity falls, warning 0x7061) and ends
/// the command with error 0x7061 once the axis is at rest.
/// A client may not choose a long dead-man: each axis has the engineer's maximum
/// (`dynamics.jog_deadman_max`, default 1 s), so a never-renewed jog runs at most that long.
#[tokio::test]
async fn a_jog_dead_man_is_bounded_by_the_axis_maximum() {
    let s = Server::start();
    power_on(&s, "y").await;
    let r = post(&s, "/api/v1/axes/y/jog", json!({"deadman_timeout": 10.0})).await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(r.field_error(), (422, Some("deadman_timeout")));
    assert!(r.text.contains("jog_deadman_max"), "{}", r.text);
    let st = status(&s, "y").await;
    assert_eq!(st["status"]["state"], "standstill", "nothing moved: {st}");
    // The engineer raises it (on a disabled axis); then 5 s is taken, 6 s still refused.
    let r = post(
        &s,
        "/api/v1/axes/y/power?wait=true",
        json!({"enable": false}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let mut config = get(&s, "/api/v1/axes/y").await.json["config"].clone();
    assert_eq!(config["dynamics"]["jog_deadman_max"], 1.0);
    config["dynamics"]["jog_deadman_max"] = json!(5.0);
    let r = put(&s, "/api/v1/axes/y", config.clone()).await;
    assert_eq!(r.status, 200, "{}", r.text);
    config["dynamics"]["jog_deadman_max"] = json!(11.0);
    let r = put(&s, "/api/v1/axes/y", config).await;
    assert_eq!(r.field_error(), (422, Some("dynamics.jog_deadman_max")));
    power_on(&s, "y").await;
    let r = post(&s, "/api/v1/axes/y/jog", json!({"deadman_timeout": 6.0})).await;
    assert_eq!(r.field_error(), (422, Some("deadman_timeout")));
    let r = post(&s, "/api/v1/axes/y/jog", json!({"deadman_timeout": 5.0})).await;
    assert_eq!(r.status, 202, "{}", r.text);
    let id = r.json["id"].as_u64().unwrap();
    assert_eq!(
        delete(&s, &format!("/api/v1/commands/{id}")).await.status,
        200
    );
    s.stop();
}

#[tokio::test(flavor = "multi_thread")]
async fn a_jog_without_keepalive_is_stopped_by_its_deadman() {
    let s = Server::start();
    power_on(&s, "y").await;
    let deadman: f64 = 0.2; // s; cycle 1 ms
    let deadman_cycles = (deadman / 0.001).round() as u64;
    let jog = post(
        &s,
        "/api/v1/axes/y/jog",
        json!({"direction": "forward", "mode": "standard_fast", "deadman_timeout": deadman}),
    )
    .await;
    assert_eq!(jog.status, 202, "{}", jog.text);
    let id = jog.json["id"].as_u64().unwrap();
    let fin = until_final(&s, id, 10).await;
    assert_eq!(fin["state"], "error", "{fin}");
    assert_eq!(fin["error_code"], "deadman_timeout", "{fin}");
    assert_eq!(
        fin["outputs"]["error_id"].as_u64(),
        Some(DEADMAN_TIMEOUT),
        "{fin}"
    );
    let events = fin["events"].as_array().unwrap();
    let start = events[0]["cycle"].as_u64().unwrap();
    assert_eq!(fin["accepted_cycle"].as_u64(), Some(start), "{fin}");
    let fired = events
        .iter()
        .position(|e| e["outputs"]["warning_id"].as_u64() == Some(DEADMAN_TIMEOUT))
        .unwrap_or_else(|| panic!("no dead-man event: {fin}"));
    let f = &events[fired]["outputs"];
    assert_eq!(f["warning"], true, "{fin}");
    assert_eq!(f["in_velocity"], false, "{fin}");
    assert_eq!(f["busy"], true, "{fin}");
    assert_eq!(f["error"], false, "{fin}");
    assert_eq!(
        events[fired - 1]["outputs"]["in_velocity"],
        true,
        "the jog never reached its velocity before the dead-man: {fin}"
    );
    let fired_cycle = events[fired]["cycle"].as_u64().unwrap();
    assert!(
        fired_cycle - start <= deadman_cycles + 1,
        "dead-man fired at cycle {fired_cycle}, {} cycles after the jog took effect (limit {}): {fin}",
        fired_cycle - start,
        deadman_cycles + 1
    );
    assert!(
        fired_cycle - start + 1 >= deadman_cycles,
        "dead-man fired early, {} cycles after the jog took effect: {fin}",
        fired_cycle - start
    );
    let end = fin["last_cycle"].as_u64().unwrap();
    assert!(
        end > fired_cycle,
        "ended in the cycle the dead-man fired: {fin}"
    );
    let st = until_status(&s, "y", 5, |st| st["state"] == "standstill").await;
    assert_eq!(st["moving"], false, "{st}");
}

#[tokio::test(flavor = "multi_thread")]
async fn a_jog_with_keepalives_keeps_running_until_released() {
    let s = Server::start();
    power_on(&s, "y").await;
    let jog = post(
        &s,
        "/api/v1/axes/y/jog",
        json!({"direction": "backward", "deadman_timeout": 0.5}),
    )
    .await;
    assert_eq!(jog.status, 202, "{}", jog.text);
    let id = jog.json["id"].as_u64().unwrap();
    for _ in 0..25 {
        let k = post(&s, &format!("/api/v1/commands/{id}/keepalive"), json!({})).await;
        assert_eq!(k.status, 204, "{}", k.text);
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let c = get(&s, &format!("/api/v1/commands/{id}")).await;
    assert_eq!(c.json["final"], false, "renewed jog stopped: {}", c.text);
    assert!(
        status(&s, "y").await["status"]["actual_position"]
            .as_f64()
            .unwrap()
            < 0.0
    );
    assert_eq!(
        delete(&s, &format!("/api/v1/commands/{id}")).await.status,
        200
    );
    let fin = until_final(&s, id, 10).await;
    assert_eq!(fin["outputs"]["error"], false, "{fin}");
}

#[tokio::test(flavor = "multi_thread")]
async fn persistent_parameters_survive_a_restart_and_others_do_not() {
    let dir = temp_dir();
    let db = dir.join("m.db");
    let db = db.to_str().unwrap();
    let s = Server::start_with(db, &[]);
    let r = put(
        &s,
        "/api/v1/axes/x/parameters/AxisVeloMax",
        json!({"value": 800.0, "persistent": true}),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["value"], 800.0);
    assert_eq!(r.json["persistent_value"], 800.0);
    let r = put(
        &s,
        "/api/v1/axes/y/parameters/1004",
        json!({"value": 3000.0}),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(
        get(&s, "/api/v1/axes/y/parameters/AxisAcc").await.json["value"],
        3000.0
    );
    let r = put(
        &s,
        "/api/v1/axes/y/parameters/AxisAcc",
        json!({"value": -1.0}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    let r = put(
        &s,
        "/api/v1/axes/y/parameters/AxisAcc",
        json!({"value": true}),
    )
    .await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_problem(
        &put(
            &s,
            "/api/v1/axes/y/parameters/NoSuchThing",
            json!({"value": 1.0}),
        )
        .await,
        404,
        "parameter_not_found",
    );
    let list = get(&s, "/api/v1/axes/x/parameters").await;
    assert!(
        list.json
            .as_array()
            .unwrap()
            .iter()
            .any(|p| p["number"] == 1003 && p["value"] == 800.0)
    );
    s.stop(); // SIGKILL: what was reported as written must be on disk

    let s = Server::start_with(db, &[]);
    assert!(
        !s.log.lock().unwrap().iter().any(|l| l.contains("demo")),
        "demo created again"
    );
    let v = get(&s, "/api/v1/axes/x/parameters/AxisVeloMax").await;
    assert_eq!(v.json["value"], 800.0, "{}", v.text);
    assert_eq!(v.json["persistent_value"], 800.0);
    assert_eq!(
        get(&s, "/api/v1/axes/y/parameters/AxisAcc").await.json["value"],
        2500.0
    );
    // A save that does not set AxisVeloMax anew keeps its persistent value (and the axis);
    // one that does gives it up, and says so first.
    let mut cfg = get(&s, "/api/v1/axes/x").await.json["config"].clone();
    cfg["dynamics"]["jog_velocity_slow"] = json!(20.0);
    let r = put(&s, "/api/v1/axes/x", cfg.clone()).await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(
        r.json["change"]["persistent_discarded"],
        json!([]),
        "{}",
        r.text
    );
    let v = get(&s, "/api/v1/axes/x/parameters/AxisVeloMax").await;
    assert_eq!(v.json["value"], 800.0, "{}", v.text);
    assert_eq!(v.json["persistent_value"], 800.0, "{}", v.text);
    assert_eq!(v.json["configured_value"], 500.0, "{}", v.text);
    cfg["dynamics"]["max_velocity"] = json!(500.0 + 1.0);
    let dry = put(&s, "/api/v1/axes/x?dry_run=true", cfg.clone()).await;
    assert_eq!(
        dry.json["change"]["persistent_discarded"][0]["name"], "AxisVeloMax",
        "{}",
        dry.text
    );
    assert_eq!(dry.json["change"]["persistent_discarded"][0]["new"], 800.0);
    let r = put(&s, "/api/v1/axes/x", cfg).await;
    assert_eq!(r.status, 200, "{}", r.text);
    let v = get(&s, "/api/v1/axes/x/parameters/AxisVeloMax").await;
    assert_eq!(v.json["value"], 501.0, "{}", v.text);
    assert!(v.json.get("persistent_value").is_none());
    s.stop();
    let s = Server::start_with(db, &[]);
    assert_eq!(
        get(&s, "/api/v1/axes/x/parameters/AxisVeloMax").await.json["value"],
        501.0
    );
    drop(s);
    let _ = std::fs::remove_dir_all(dir);
}

#[tokio::test(flavor = "multi_thread")]
async fn export_import_round_trips() {
    let s = Server::start();
    assert_eq!(
        put(
            &s,
            "/api/v1/axes/spindle/parameters/AxisVeloManFast",
            json!({"value": 360.0, "persistent": true})
        )
        .await
        .status,
        200
    );
    let a = get(&s, "/api/v1/config").await;
    assert_eq!(a.status, 200);
    assert_eq!(
        a.json["axes"][2]["persistent_parameters"],
        json!({"AxisVeloManFast": 360.0})
    );
    let r = put(&s, "/api/v1/config", a.json.clone()).await;
    assert_eq!(r.status, 200, "{}", r.text);
    let b = get(&s, "/api/v1/config").await;
    assert_eq!(a.text, b.text, "export → import → export differs");
    assert_eq!(
        get(&s, "/api/v1/axes/spindle/parameters/AxisVeloManFast")
            .await
            .json["value"],
        360.0
    );

    // an invalid document changes nothing
    let mut bad = a.json.clone();
    bad["axes"][1]["config"]["name"] = json!("x");
    bad["axes"][0]["config"]["dynamics"]["jerk"] = json!(0.0);
    let r = put(&s, "/api/v1/config", bad).await;
    assert_problem(&r, 422, "validation_failed");
    assert!(
        r.json["errors"].as_array().unwrap().len() >= 2,
        "{}",
        r.text
    );
    assert_eq!(get(&s, "/api/v1/config").await.text, a.text);

    // a different document replaces the machine
    let mut two = a.json.clone();
    two["axes"].as_array_mut().unwrap().truncate(1);
    two["axes"][0]["config"]["name"] = json!("portal");
    // The demo group xy has x and y as members: a machine without them has no group.
    two["groups"] = json!([]);
    let r = put(&s, "/api/v1/config", two).await;
    assert_eq!(r.status, 200, "{}", r.text);
    let axes = get(&s, "/api/v1/axes").await.json;
    assert_eq!(axes.as_array().unwrap().len(), 1);
    assert_eq!(axes[0]["config"]["name"], "portal");

    // not while an axis is enabled
    power_on(&s, "portal").await;
    let r = put(&s, "/api/v1/config", a.json.clone()).await;
    assert_problem(&r, 409, "axis_not_disabled");
}

#[tokio::test(flavor = "multi_thread")]
async fn axis_crud_with_validation_and_enabled_axes_protected() {
    let s = Server::start();
    let cfg = json!({"name": "z", "unit": "mm", "soft_limits": {"min": -10.0, "max": 200.0},
        "dynamics": {"max_velocity": 100.0, "acceleration": 1000.0, "deceleration": 1000.0, "jerk": 10000.0,
                     "jog_velocity_slow": 5.0, "jog_velocity_fast": 50.0}});
    let r = post(&s, "/api/v1/axes", cfg.clone()).await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(
        r.location.as_deref(),
        Some(format!("/api/v1/axes/{}", r.json["id"]).as_str())
    );
    assert_problem(
        &post(&s, "/api/v1/axes", cfg.clone()).await,
        409,
        "axis_name_taken",
    );
    let mut bad = cfg.clone();
    bad["name"] = json!("1bad name");
    bad["unit"] = json!("furlong");
    bad["modulo"] = json!({"period": -1.0});
    bad["dynamics"]["jog_velocity_fast"] = json!(500.0);
    bad["drive"] = json!({"dead_time": 5.0});
    let r = post(&s, "/api/v1/axes", bad).await;
    assert_problem(&r, 422, "validation_failed");
    let fields: Vec<&str> = r.json["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["field"].as_str().unwrap())
        .collect();
    for f in [
        "name",
        "unit",
        "modulo.period",
        "dynamics.jog_velocity_fast",
    ] {
        assert!(fields.contains(&f), "{f} not reported: {fields:?}");
    }
    assert!(fields.iter().any(|f| f.starts_with("drive.")), "{fields:?}");
    // A wrong type inside the drive is named by its path, with or without the drive's kind;
    // an unknown kind is refused (only `simulated` exists).
    for drive in [
        json!({"kind": "simulated", "dead_time": "x"}),
        json!({"dead_time": "x", "kind": "simulated"}),
        json!({"dead_time": "x"}),
    ] {
        let mut bad = cfg.clone();
        bad["drive"] = drive;
        let r = post(&s, "/api/v1/axes", bad).await;
        assert_problem(&r, 422, "validation_failed");
        assert_eq!(
            r.json["errors"][0]["field"], "drive.dead_time",
            "{}",
            r.json
        );
    }
    let mut bad = cfg.clone();
    bad["drive"] = json!({"kind": "servo"});
    let r = post(&s, "/api/v1/axes", bad).await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(r.json["errors"][0]["field"], "drive.kind", "{}", r.json);
    // A CiA-402 drive names what it lacks; and needs an EtherCAT bus (this one is simulated).
    let mut bad = cfg.clone();
    bad["drive"] = json!({"kind": "cia402"});
    let r = post(&s, "/api/v1/axes", bad.clone()).await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(
        r.json["errors"][0]["field"], "drive.subdevice",
        "{}",
        r.json
    );
    bad["drive"] = json!({"kind": "cia402", "subdevice": 0, "increments_per_unit": 1000.0});
    bad["name"] = json!("servo");
    let r = post(&s, "/api/v1/axes", bad).await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(r.json["errors"][0]["field"], "drive.kind", "{}", r.json);
    let mut unknown = cfg.clone();
    unknown["colour"] = json!("red");
    assert_problem(
        &post(&s, "/api/v1/axes", unknown).await,
        422,
        "validation_failed",
    );
    assert_eq!(
        get(&s, "/api/v1/axes").await.json.as_array().unwrap().len(),
        4
    );

    power_on(&s, "z").await;
    // What can be written online is, on the running axis (no rebuild); a new unit re-creates
    // the axis, which must be disabled for it.
    let mut faster = cfg.clone();
    faster["dynamics"]["max_velocity"] = json!(150.0);
    let r = put(&s, "/api/v1/axes/z", faster.clone()).await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["change"]["rebuild"], false, "{}", r.text);
    assert_eq!(r.json["change"]["parameters"][0]["name"], "AxisVeloMax");
    assert_eq!(status(&s, "z").await["status"]["state"], "standstill");
    let mut changed = faster.clone();
    changed["unit"] = json!("m");
    let r = put(&s, "/api/v1/axes/z?dry_run=true", changed.clone()).await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["change"]["rebuild"], true, "{}", r.text);
    assert_eq!(r.json["change"]["rebuild_reasons"][0], "unit changed");
    assert_eq!(r.json["change"]["dry_run"], true);
    assert_eq!(get(&s, "/api/v1/axes/z").await.json["config"]["unit"], "mm");
    assert_problem(
        &put(&s, "/api/v1/axes/z", changed.clone()).await,
        409,
        "axis_not_disabled",
    );
    assert_problem(
        &delete(&s, "/api/v1/axes/z").await,
        409,
        "axis_not_disabled",
    );
    let off = post(
        &s,
        "/api/v1/axes/z/power?wait=true",
        json!({"enable": false}),
    )
    .await;
    assert_eq!(off.status, 202, "{}", off.text);
    let deadline = std::time::Instant::now() + Duration::from_secs(5);
    while status(&s, "z").await["status"]["state"] != "disabled" {
        assert!(std::time::Instant::now() < deadline);
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let r = put(&s, "/api/v1/axes/z", changed).await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["change"]["rebuild"], true, "{}", r.text);
    assert_eq!(r.json["config"]["unit"], "m");
    assert_eq!(r.json["config"]["dynamics"]["max_velocity"], 150.0);
    assert_eq!(
        get(&s, "/api/v1/axes/z/parameters/1003").await.json["value"],
        150.0
    );
    assert_eq!(delete(&s, "/api/v1/axes/z").await.status, 204);
    assert_problem(&get(&s, "/api/v1/axes/z").await, 404, "axis_not_found");
}

#[tokio::test(flavor = "multi_thread")]
async fn system_and_metrics_report_cycle_timing() {
    let s = Server::start();
    // At least 100 cycles (counted, not waited for: a loaded machine stretches time).
    let deadline = std::time::Instant::now() + Duration::from_secs(30);
    let r = loop {
        let r = get(&s, "/api/v1/system").await;
        if r.json["timing"]["cycles"].as_u64().unwrap_or(0) > 100 {
            break r;
        }
        assert!(std::time::Instant::now() < deadline, "{}", r.text);
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    assert_eq!(r.status, 200);
    assert_eq!(r.json["cycle_time"], 0.001);
    assert!(
        r.json["timing"]["cycles"].as_u64().unwrap() > 100,
        "{}",
        r.text
    );
    assert!(
        r.json["timing"]["wakeup_latency"]["count"]
            .as_u64()
            .unwrap()
            > 100
    );
    assert!(r.json["realtime"]["sched_fifo"].is_boolean());
    let m = get(&s, "/metrics").await;
    assert_eq!(m.status, 200);
    assert!(m.content_type.starts_with("text/plain"));
    for name in [
        "motiond_cycle_wakeup_latency_seconds_bucket",
        "motiond_cycle_compute_seconds_count",
        "motiond_cycle_overruns_total",
        "motiond_cycles_total",
    ] {
        assert!(m.text.contains(name), "{name} missing");
    }
    let docs = get(&s, "/docs/").await;
    assert_eq!(docs.status, 200);
    assert!(docs.text.contains("swagger"), "{}", docs.text);
}

#[tokio::test(flavor = "multi_thread")]
async fn start_up_refuses_what_it_cannot_do_safely() {
    let out = bin()
        .args(["--listen", "0.0.0.0:0", "--db", ":memory:"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(text.contains("authentication"), "{text}");

    let out = bin()
        .args(["--cycle-us", "100", "--db", ":memory:"])
        .output()
        .unwrap();
    assert!(!out.status.success());

    let dir = temp_dir();
    let corrupt = dir.join("corrupt.db");
    std::fs::write(&corrupt, vec![0x42u8; 8192]).unwrap();
    let out = bin()
        .args(["--listen", "127.0.0.1:0", "--db", corrupt.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(text.contains("corrupt.db"), "{text}");

    let db = dir.join("locked.db");
    let first = Server::start_with(db.to_str().unwrap(), &[]);
    let out = bin()
        .args(["--listen", "127.0.0.1:0", "--db", db.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(text.contains("locked"), "{text}");
    drop(first);
    let _ = std::fs::remove_dir_all(dir);
}

#[tokio::test(flavor = "multi_thread")]
async fn openapi_json_is_current() {
    let out = bin().arg("openapi").output().unwrap();
    assert!(out.status.success());
    let generated = String::from_utf8(out.stdout).unwrap();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/openapi/openapi.json");
    if std::env::var_os("UPDATE_OPENAPI").is_some() {
        std::fs::write(path, &generated).unwrap();
    }
    let stored = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        stored == generated,
        "openapi/openapi.json is stale: regenerate with `cargo run -- openapi > openapi/openapi.json` (or UPDATE_OPENAPI=1 cargo test --test api openapi)"
    );
    let doc: Value = serde_json::from_str(&generated).unwrap();
    // Every $ref resolves (the frontend generates its API types from this document).
    let mut all = Vec::new();
    refs(&doc, &mut all);
    for r in all {
        let (kind, name) = r
            .strip_prefix("#/components/")
            .and_then(|r| r.split_once('/'))
            .filter(|(kind, _)| ["schemas", "responses"].contains(kind))
            .unwrap_or_else(|| panic!("unexpected $ref {r}"));
        assert!(
            doc["components"][kind].get(name).is_some(),
            "$ref {r} does not resolve"
        );
    }
    check_examples(&doc);
    check_generator_friendly(&doc, "#");
    let paths = doc["paths"].as_object().unwrap();
    for p in [
        "/api/v1/axes",
        "/api/v1/axes/{axis}/move-absolute",
        "/api/v1/axes/{axis}/gear-out",
        "/api/v1/axes/{axis}/gear-in-dyn",
        "/api/v1/axes/{axis}/move-superimposed",
        "/api/v1/axes/{axis}/abort-superposition",
        "/api/v1/axes/{axis}/simulation/fault",
        "/api/v1/audit",
        "/api/v1/commands/{id}/keepalive",
        "/api/v1/config",
        "/metrics",
        "/api/v1/ws",
        "/api/v1/scope/recordings",
        "/api/v1/scope/recordings/{id}",
        "/api/v1/axes/{axis}/status/following-error-peak/reset",
        "/api/v1/cam-tables",
        "/api/v1/cam-tables/{table}",
        "/api/v1/cam-tables/{table}/characteristics",
        "/api/v1/cam-tables/{table}/slave-dynamics",
        "/api/v1/cam-tables/{table}/master-position",
        "/api/v1/cam-tables/{table}/values",
        "/api/v1/axes/{axis}/cam-in",
        "/api/v1/axes/{axis}/cam-out",
        "/api/v1/axes/{axis}/cam-scaling",
        "/api/v1/cam-tables/{table}/online-change-mode",
        "/api/v1/cam-tables/{table}/points",
        "/api/v1/cam-tables/{table}/points/{point}",
        "/api/v1/axes/{axis}/cam-in-v2",
        "/api/v1/axes/{axis}/cam-add",
        "/api/v1/axes/{axis}/cam-exchange",
        "/api/v1/axes/{axis}/cam-remove",
        "/api/v1/axes/{axis}/cam-scaling-v2",
        "/api/v1/axes/{axis}/cam-info",
        "/api/v1/auth/session",
        "/api/v1/auth/login",
        "/api/v1/auth/logout",
        "/api/v1/auth/password",
        "/api/v1/users",
        "/api/v1/users/{name}",
        "/api/v1/tokens",
        "/api/v1/tokens/{id}",
        "/api/v1/control",
        "/api/v1/scope/setups",
        "/api/v1/scope/setups/{name}",
        "/api/v1/bus/reset",
        "/api/v1/groups",
        "/api/v1/groups/{group}",
        "/api/v1/groups/{group}/status",
        "/api/v1/groups/{group}/read-error",
        "/api/v1/groups/{group}/read-blocker-status",
        "/api/v1/groups/{group}/move-path",
        "/api/v1/groups/{group}/set-coordinate-transform",
        "/api/v1/commands/{id}/inputs",
    ] {
        assert!(paths.contains_key(p), "{p} not documented");
    }
    // 93 before the groups: 5 resource paths and 12 blocks; 1 for ContinuousUpdate.
    assert_eq!(paths.len(), 115, "{:?}", paths.keys().collect::<Vec<_>>());
    let s = Server::start();
    assert_eq!(get(&s, "/openapi.json").await.json, doc);
}

/// Every `$ref` in `v`.
fn refs<'a>(v: &'a Value, out: &mut Vec<&'a str>) {
    match v {
        Value::Object(m) => {
            if let Some(Value::String(r)) = m.get("$ref") {
                out.push(r);
            }
            m.values().for_each(|v| refs(v, out));
        }
        Value::Array(a) => a.iter().for_each(|v| refs(v, out)),
        _ => {}
    }
}

/// The websocket's AsyncAPI document is the binary's and is served; every `$ref` resolves, and it
/// has an operation for every request and notification, the command methods' params being their
/// REST bodies (same properties and required ones) with `axis`, `wait` and `timeout_ms`.
#[tokio::test(flavor = "multi_thread")]
async fn asyncapi_json_is_current() {
    let out = bin().arg("asyncapi").output().unwrap();
    assert!(out.status.success());
    let generated = String::from_utf8(out.stdout).unwrap();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/openapi/asyncapi.json");
    if std::env::var_os("UPDATE_OPENAPI").is_some() {
        std::fs::write(path, &generated).unwrap();
    }
    let stored = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        stored == generated,
        "openapi/asyncapi.json is stale: regenerate with `cargo run -- asyncapi > openapi/asyncapi.json` (or UPDATE_OPENAPI=1 cargo test --test api asyncapi)"
    );
    let doc: Value = serde_json::from_str(&generated).unwrap();
    assert_eq!(doc["asyncapi"], "3.0.0");
    let mut all = Vec::new();
    refs(&doc, &mut all);
    for r in all {
        let pointer = r
            .strip_prefix('#')
            .unwrap_or_else(|| panic!("external $ref {r}"));
        assert!(doc.pointer(pointer).is_some(), "$ref {r} does not resolve");
    }
    // Every operation by its JSON-RPC method (`title`).
    let ops: std::collections::BTreeMap<&str, &Value> = doc["operations"]
        .as_object()
        .unwrap()
        .values()
        .map(|o| (o["title"].as_str().unwrap(), o))
        .collect();
    for m in [
        "subscribe",
        "unsubscribe",
        "keepalive",
        "release",
        "update-inputs",
    ] {
        assert_eq!(ops[m]["action"], "receive", "{m}");
        assert_eq!(
            ops[m]["reply"]["messages"].as_array().unwrap().len(),
            2,
            "{m}"
        );
    }
    for m in [
        "update",
        "command_event",
        "commands_lagged",
        "subscription_ended",
    ] {
        assert_eq!(
            ops.get(m).map(|o| &o["action"]),
            Some(&json!("send")),
            "{m}"
        );
    }
    // The command methods are the REST command endpoints, their params the REST bodies.
    let openapi: Value = serde_json::from_str(
        &String::from_utf8(bin().arg("openapi").output().unwrap().stdout).unwrap(),
    )
    .unwrap();
    let schemas = &doc["components"]["schemas"];
    let mut commands = 0;
    for (p, item) in openapi["paths"].as_object().unwrap() {
        let Some(method) = p.strip_prefix("/api/v1/axes/{axis}/") else {
            continue;
        };
        if item["post"]["tags"][0] != "commands" {
            continue;
        }
        commands += 1;
        let op = ops
            .get(method)
            .unwrap_or_else(|| panic!("no websocket method {method}"));
        let key = op["messages"][0]["$ref"]
            .as_str()
            .unwrap()
            .rsplit('/')
            .next()
            .unwrap();
        let params = &doc["components"]["messages"][key]["payload"]["properties"]["params"];
        let body_ref = item["post"]["requestBody"]["content"]["application/json"]["schema"]["$ref"]
            .as_str()
            .unwrap();
        let body = &schemas[body_ref.rsplit('/').next().unwrap()];
        let names = |s: &Value| {
            let mut v: Vec<String> = s["properties"]
                .as_object()
                .map_or(vec![], |m| m.keys().cloned().collect());
            v.sort();
            v
        };
        let mut expected = names(body);
        expected.extend(["axis".to_string(), "timeout_ms".into(), "wait".into()]);
        expected.sort();
        assert_eq!(names(params), expected, "{method}");
        let mut required: Vec<Value> = body["required"].as_array().cloned().unwrap_or_default();
        required.insert(0, json!("axis"));
        assert_eq!(params["required"], Value::Array(required), "{method}");
        let reply = ops[method]["reply"]["messages"][0]["$ref"]
            .as_str()
            .unwrap();
        let reply = &doc["components"]["messages"][reply.rsplit('/').next().unwrap()];
        assert_eq!(
            reply["payload"]["properties"]["result"]["$ref"],
            "#/components/schemas/CommandResource",
            "{method}"
        );
    }
    assert_eq!(commands, 44);
    let s = Server::start();
    let served = get(&s, "/asyncapi.json").await;
    assert_eq!(served.status, 200);
    assert_eq!(served.content_type, "application/json");
    assert_eq!(served.json, doc);
}

/// What client generators refuse (openapi-python-client drops every schema and operation that
/// uses one): a one-element `oneOf` (utoipa's way of giving a `$ref` a default) and an object or
/// array `default` beside a `$ref`. `tests/client/check.sh` runs the generators themselves.
fn check_generator_friendly(v: &Value, at: &str) {
    match v {
        Value::Object(m) => {
            if let Some(Value::Array(items)) = m.get("oneOf") {
                assert!(items.len() > 1, "{at}: a oneOf of one schema");
            }
            let has_ref = m.contains_key("$ref")
                || m.get("oneOf")
                    .and_then(Value::as_array)
                    .is_some_and(|items| items.iter().any(|i| i.get("$ref").is_some()));
            if has_ref {
                assert!(
                    !m.get("default")
                        .is_some_and(|d| d.is_object() || d.is_array()),
                    "{at}: an object default beside a $ref"
                );
            }
            for (k, v) in m {
                // Examples are values, not schemas.
                if k != "example" && k != "examples" {
                    check_generator_friendly(v, &format!("{at}/{k}"));
                }
            }
        }
        Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                check_generator_friendly(v, &format!("{at}/{i}"));
            }
        }
        _ => {}
    }
}

/// A full disk at run time: the write that does not fit is a 503 and leaves nothing behind;
/// every write that was reported as done is there after a restart.
#[tokio::test(flavor = "multi_thread")]
async fn a_full_disk_is_a_503_and_never_a_lost_write() {
    let dir = temp_dir();
    let db = dir.join("full.db");
    let db = db.to_str().unwrap().to_string();
    // Create the database first, then restart with a file-size limit just above its size.
    drop(Server::start_with(&db, &[]));
    let size = |p: &str| std::fs::metadata(p).map_or(0, |m| m.len());
    let limit_kb = (size(&db) + size(&format!("{db}-wal"))) / 1024 + 96;
    let script = format!("ulimit -f {limit_kb}; exec \"$0\" \"$@\"");
    let mut cmd = std::process::Command::new("bash");
    cmd.args([
        "-c",
        &script,
        env!("CARGO_BIN_EXE_motiond"),
        "--listen",
        "127.0.0.1:0",
        "--db",
        &db,
    ]);
    let s = Server::spawn(cmd);
    let mut created = Vec::new();
    let mut failure = None;
    for i in 0..60 {
        let name = format!("filler{i}");
        let cfg = json!({"name": name, "unit": "mm",
            "dynamics": {"max_velocity": 100.0, "acceleration": 1000.0, "deceleration": 1000.0, "jerk": 10000.0,
                         "jog_velocity_slow": 5.0, "jog_velocity_fast": 50.0}});
        let r = post(&s, "/api/v1/axes", cfg).await;
        match r.status {
            201 => created.push(name),
            _ => {
                failure = Some((name, r));
                break;
            }
        }
    }
    let (failed_name, r) = failure.expect("the file-size limit was never reached");
    assert_problem(&r, 503, "storage_unavailable");
    assert!(!created.is_empty(), "the limit left no room at all");
    let names = |axes: &Value| {
        axes.as_array()
            .unwrap()
            .iter()
            .map(|a| a["config"]["name"].as_str().unwrap().to_string())
            .collect::<Vec<_>>()
    };
    let live = names(&get(&s, "/api/v1/axes").await.json);
    assert!(
        !live.contains(&failed_name),
        "{failed_name} half-created: {live:?}"
    );
    assert_eq!(
        get(&s, "/api/v1/system").await.status,
        200,
        "server unwell after the full disk"
    );
    s.stop();
    let s = Server::start_with(&db, &[]);
    let after = names(&get(&s, "/api/v1/axes").await.json);
    assert_eq!(
        after, live,
        "what the server showed differs from what was stored"
    );
    for n in &created {
        assert!(after.contains(n), "{n} was reported created but is lost");
    }
    drop(s);
    let _ = std::fs::remove_dir_all(dir);
}

/// Polls an axis's status until `f` holds (or panics after `secs` with the last status).
async fn until_status(s: &Server, axis: &str, secs: u64, f: impl Fn(&Value) -> bool) -> Value {
    let deadline = std::time::Instant::now() + Duration::from_secs(secs);
    loop {
        let st = status(s, axis).await["status"].clone();
        if f(&st) {
            return st;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "{axis}: condition not reached: {st}"
        );
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn a_superposition_on_a_moving_axis_completes_and_the_axis_ends_its_distance_ahead() {
    const AXIS_NOT_MOVING: u64 = 0x4B03;
    let s = Server::start();
    power_on(&s, "x").await;
    let sp = json!({"distance": 10.0, "velocity_diff": 50.0, "velocity_process": 200.0, "length": 200.0});
    // Nothing to superimpose on at standstill.
    let r = post(&s, "/api/v1/axes/x/move-superimposed", sp.clone()).await;
    assert_problem(&r, 409, "axis_not_moving");
    assert_eq!(r.json["error_id"].as_u64(), Some(AXIS_NOT_MOVING));
    for (field, value) in [
        ("velocity_diff", json!(0.0)),
        ("velocity_process", json!(-1.0)),
        ("length", json!(0.0)),
        ("acceleration", json!(-5.0)),
        ("deceleration", json!(-5.0)),
    ] {
        let mut bad = sp.clone();
        bad[field] = value;
        let r = post(&s, "/api/v1/axes/x/move-superimposed", bad).await;
        assert_problem(&r, 422, "validation_failed");
        assert_eq!(r.json["errors"][0]["field"], field, "{}", r.text);
    }
    let mut missing = sp.clone();
    missing.as_object_mut().unwrap().remove("length");
    assert_problem(
        &post(&s, "/api/v1/axes/x/move-superimposed", missing).await,
        422,
        "validation_failed",
    );

    let mv = post(
        &s,
        "/api/v1/axes/x/move-absolute",
        json!({"position": 600.0, "velocity": 200.0}),
    )
    .await;
    assert_eq!(mv.status, 202, "{}", mv.text);
    until_status(&s, "x", 10, |st| {
        st["set_velocity"].as_f64().unwrap() > 150.0
    })
    .await;
    let r = post(&s, "/api/v1/axes/x/move-superimposed", sp.clone()).await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["command"], "move-superimposed");
    let id = r.json["id"].as_u64().unwrap();
    // While it runs the axis reports it (compensating, part of the distance applied).
    let st = until_status(&s, "x", 10, |st| {
        st["compensating"] == true && st["superimposed_distance"].as_f64().unwrap() > 0.0
    })
    .await;
    assert!(
        st["superimposed_distance"].as_f64().unwrap() <= 10.0,
        "{st}"
    );
    let fin = until_final(&s, id, 20).await;
    assert_eq!(fin["state"], "done", "{fin}");
    assert_eq!(fin["outputs"]["warning"], false, "{fin}");
    let mv_fin = until_final(&s, mv.json["id"].as_u64().unwrap(), 20).await;
    assert_eq!(mv_fin["state"], "done", "{mv_fin}");
    let st = until_status(&s, "x", 5, |st| st["state"] == "standstill").await;
    assert_eq!(st["compensating"], false, "{st}");
    let set = st["set_position"].as_f64().unwrap();
    let actual = st["actual_position"].as_f64().unwrap();
    assert!(
        (set - 610.0).abs() < 1e-6,
        "set position {set}, not 600 + 10"
    );
    assert!((actual - 610.0).abs() <= 0.01, "actual position {actual}");

    // abort-superposition ends a running one; what it applied stays.
    let mv = post(
        &s,
        "/api/v1/axes/x/move-velocity",
        json!({"velocity": 100.0, "direction": "negative"}),
    )
    .await;
    assert_eq!(mv.status, 202, "{}", mv.text);
    until_status(&s, "x", 10, |st| {
        st["set_velocity"].as_f64().unwrap() < -50.0
    })
    .await;
    let long = json!({"distance": -50.0, "velocity_diff": 20.0, "velocity_process": 100.0, "length": 400.0});
    let r = post(&s, "/api/v1/axes/x/move-superimposed", long).await;
    assert_eq!(r.status, 202, "{}", r.text);
    let id = r.json["id"].as_u64().unwrap();
    until_status(&s, "x", 10, |st| st["compensating"] == true).await;
    let a = post(
        &s,
        "/api/v1/axes/x/abort-superposition?wait=true",
        json!({}),
    )
    .await;
    assert_eq!(a.status, 202, "{}", a.text);
    assert_eq!(a.json["state"], "done", "{}", a.text);
    let fin = until_final(&s, id, 5).await;
    assert_eq!(fin["state"], "aborted", "{fin}");
    let st = until_status(&s, "x", 5, |st| st["compensating"] == false).await;
    assert_eq!(st["state"], "continuous_motion", "{st}");
}

#[tokio::test(flavor = "multi_thread")]
async fn gear_in_dyn_couples_y_to_x_and_a_second_call_changes_the_ratio() {
    let s = Server::start();
    power_on(&s, "x").await;
    power_on(&s, "y").await;
    for (body, field) in [
        (json!({"master": "nobody", "gear_ratio": 1.0}), "master"),
        (json!({"master": "y", "gear_ratio": 1.0}), "master"),
        (
            json!({"master": "x", "gear_ratio": 1.0, "acceleration": -1.0}),
            "acceleration",
        ),
    ] {
        let r = post(&s, "/api/v1/axes/y/gear-in-dyn", body).await;
        assert_problem(&r, 422, "validation_failed");
        assert_eq!(r.json["errors"][0]["field"], field, "{}", r.text);
    }
    let x_id = get(&s, "/api/v1/axes/x").await.json["id"].clone();
    // The master by id works as well as by name.
    let g1 = post(
        &s,
        "/api/v1/axes/y/gear-in-dyn?wait=true",
        json!({"master": x_id.to_string(), "gear_ratio": 1.0}),
    )
    .await;
    assert_eq!(g1.status, 202, "{}", g1.text);
    assert_eq!(g1.json["outputs"]["in_gear"], true, "{}", g1.text);
    assert_eq!(g1.json["final"], false, "an enabled gear-in-dyn stays busy");
    let st = status(&s, "y").await["status"].clone();
    assert_eq!(st["state"], "synchronized_motion", "{st}");
    // The master by its name (a kernel slot means nothing to a client).
    assert_eq!(st["master"], "x", "{st}");

    let mv = post(
        &s,
        "/api/v1/axes/x/move-velocity?wait=true",
        json!({"velocity": 100.0}),
    )
    .await;
    assert_eq!(mv.json["outputs"]["in_velocity"], true, "{}", mv.text);
    let st = until_status(&s, "y", 10, |st| {
        (st["set_velocity"].as_f64().unwrap() - 100.0).abs() < 1e-6
    })
    .await;
    assert_eq!(st["gear_ratio"], 1.0);

    // A second gear-in-dyn to the same master while the first is enabled: a new ratio.
    let g2 = post(
        &s,
        "/api/v1/axes/y/gear-in-dyn?wait=true",
        json!({"master": "x", "gear_ratio": 2.0}),
    )
    .await;
    assert_eq!(g2.status, 202, "{}", g2.text);
    assert_eq!(g2.json["outputs"]["in_gear"], true, "{}", g2.text);
    let first = get(&s, &format!("/api/v1/commands/{}", g1.json["id"])).await;
    assert_eq!(first.json["state"], "done", "{}", first.text);
    assert_eq!(first.json["final"], true, "{}", first.text);
    // (polled: the status snapshot of the cycle that reported in_gear may not be out yet)
    let st = until_status(&s, "y", 5, |st| st["gear_ratio"] == 2.0).await;
    assert!(
        (st["set_velocity"].as_f64().unwrap() - 200.0).abs() < 1e-6,
        "{st}"
    );

    // Enable FALSE: the command ends, the slave stays coupled at the ratio it has.
    let rel = delete(&s, &format!("/api/v1/commands/{}", g2.json["id"])).await;
    assert_eq!(rel.status, 200, "{}", rel.text);
    let fin = until_final(&s, g2.json["id"].as_u64().unwrap(), 5).await;
    assert_eq!(fin["state"], "done", "{fin}");
    assert_eq!(fin["outputs"]["in_gear"], true, "{fin}");
    let st = status(&s, "y").await["status"].clone();
    assert_eq!(st["state"], "synchronized_motion", "{st}");
    assert_eq!(st["gear_ratio"], 2.0, "{st}");
    let out = post(&s, "/api/v1/axes/y/gear-out?wait=true", json!({})).await;
    assert_eq!(out.json["state"], "done", "{}", out.text);
    until_status(&s, "y", 5, |st| st["coupled"] == false).await;
}

#[tokio::test(flavor = "multi_thread")]
async fn an_injected_drive_fault_stops_the_axis_until_cleared_and_reset() {
    const DRIVE_FAULT: u64 = 0x7010;
    let s = Server::start();
    power_on(&s, "x").await;
    power_on(&s, "y").await;
    let fault = "/api/v1/axes/x/simulation/fault";
    for bad in [
        json!({"kind": "meltdown"}),
        json!({"kind": "load"}),
        json!({"kind": "drive_fault", "code": -1}),
        json!({"kind": "limit_switch", "positive": true}),
        json!({"kind": "clear", "now": true}),
    ] {
        assert_problem(&post(&s, fault, bad).await, 422, "validation_failed");
    }
    assert_problem(
        &post(
            &s,
            "/api/v1/axes/nope/simulation/fault",
            json!({"kind": "clear"}),
        )
        .await,
        404,
        "axis_not_found",
    );
    assert_eq!(status(&s, "x").await["status"]["state"], "standstill");

    let r = post(&s, fault, json!({"kind": "drive_fault", "code": 0x2310})).await;
    assert_eq!(r.status, 204, "{}", r.text);
    assert!(r.text.is_empty(), "{}", r.text);
    let st = until_status(&s, "x", 5, |st| st["state"] == "error_stop").await;
    assert_eq!(st["error_id"].as_u64(), Some(DRIVE_FAULT), "{st}");
    assert_eq!(st["drive_fault"], true, "{st}");
    let r = post(
        &s,
        "/api/v1/axes/x/move-relative",
        json!({"distance": 5.0, "velocity": 10.0}),
    )
    .await;
    assert_problem(&r, 409, "axis_cannot_be_started");

    let r = post(&s, fault, json!({"kind": "clear"})).await;
    assert_eq!(r.status, 204, "{}", r.text);
    let r = post(&s, "/api/v1/axes/x/reset?wait=true", json!({})).await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    let st = until_status(&s, "x", 5, |st| st["state"] == "standstill").await;
    assert_eq!(st["error_id"], 0, "{st}");
    assert_eq!(st["drive_fault"], false, "{st}");
    let r = post(
        &s,
        "/api/v1/axes/x/move-relative?wait=true",
        json!({"distance": 5.0, "velocity": 10.0}),
    )
    .await;
    assert_eq!(
        r.json["state"], "done",
        "the axis does not move again: {}",
        r.text
    );

    // A load force gives a following error of force / load_stiffness (1000 by default).
    let r = post(
        &s,
        "/api/v1/axes/y/simulation/fault",
        json!({"kind": "load", "force": 5.0}),
    )
    .await;
    assert_eq!(r.status, 204, "{}", r.text);
    until_status(&s, "y", 5, |st| {
        (st["following_error"].as_f64().unwrap() - 0.005).abs() < 1e-5
    })
    .await;
    let r = post(
        &s,
        "/api/v1/axes/y/simulation/fault",
        json!({"kind": "clear"}),
    )
    .await;
    assert_eq!(r.status, 204, "{}", r.text);
    until_status(&s, "y", 5, |st| {
        st["following_error"].as_f64().unwrap().abs() < 1e-5
    })
    .await;

    // Every injection is audited with its client.
    let entries = until_audit(&s, "", |e| {
        e.iter()
            .filter(|e| e["action"] == "simulation.fault")
            .count()
            >= 4
    })
    .await;
    let injected = entries
        .iter()
        .find(|e| e["action"] == "simulation.fault" && e["detail"]["kind"] == "drive_fault")
        .expect("drive fault audited");
    assert_eq!(injected["target"], "x", "{injected}");
    assert_eq!(injected["detail"]["code"], 0x2310, "{injected}");
    assert_eq!(injected["client_id"], "integration-test", "{injected}");
    assert_eq!(injected["outcome"], "applied", "{injected}");
}

/// Polls `GET /audit?limit=1000{query}` until `f` holds for the entries.
async fn until_audit(s: &Server, query: &str, f: impl Fn(&[Value]) -> bool) -> Vec<Value> {
    let deadline = std::time::Instant::now() + Duration::from_secs(10);
    loop {
        let r = get(s, &format!("/api/v1/audit?limit=1000{query}")).await;
        assert_eq!(r.status, 200, "{}", r.text);
        let entries = r.json.as_array().unwrap().clone();
        if f(&entries) {
            return entries;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "audit log incomplete: {}",
            r.text
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn the_audit_log_shows_changes_and_motion_commands_with_their_client() {
    let s = Server::start();
    let r = get(&s, "/api/v1/audit").await;
    assert_eq!(r.status, 200, "{}", r.text);
    let demo: Vec<&Value> = r
        .json
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["action"] == "axis.create")
        .collect();
    assert_eq!(demo.len(), 3, "{}", r.text);
    assert!(demo.iter().all(|e| e["client_id"] == "demo"), "{}", r.text);
    let since = r.json[0]["id"].as_i64().unwrap();

    let p = put(
        &s,
        "/api/v1/axes/y/parameters/AxisAcc",
        json!({"value": 3000.0}),
    )
    .await;
    assert_eq!(p.status, 200, "{}", p.text);
    let power = power_on(&s, "y").await;
    let mv = post(
        &s,
        "/api/v1/axes/y/move-relative?wait=true",
        json!({"distance": 2.0, "velocity": 20.0}),
    )
    .await;
    assert_eq!(mv.json["state"], "done", "{}", mv.text);
    let query = format!("&since_id={since}");
    let entries = until_audit(&s, &query, |e| {
        e.iter()
            .any(|e| e["action"] == "command.final" && e["command_id"] == mv.json["id"])
    })
    .await;
    let ids: Vec<i64> = entries.iter().map(|e| e["id"].as_i64().unwrap()).collect();
    assert!(ids.iter().all(|id| *id > since), "{ids:?}");
    assert!(
        ids.windows(2).all(|w| w[0] > w[1]),
        "not newest first: {ids:?}"
    );
    let find = |action: &str| {
        entries
            .iter()
            .find(|e| e["action"] == action)
            .unwrap_or_else(|| panic!("no {action}: {entries:?}"))
    };
    for e in &entries {
        assert_eq!(e["client_id"], "integration-test", "{e}");
        assert!(
            e["client_addr"].as_str().unwrap().starts_with("127.0.0.1:"),
            "{e}"
        );
    }
    let w = find("parameter.write");
    assert_eq!(w["target"], "y", "{w}");
    assert_eq!(w["detail"]["parameter"], 1004, "{w}");
    assert_eq!(w["detail"]["value"], 3000.0, "{w}");
    assert_eq!(w["outcome"], "committed", "{w}");
    let c = find("command.power");
    assert_eq!(c["command_id"], power["id"], "{c}");
    assert_eq!(c["target"], "y", "{c}");
    assert_eq!(c["outcome"], "accepted", "{c}");
    let m = find("command.move-relative");
    assert_eq!(m["detail"]["distance"], 2.0, "{m}");
    // Its end comes after its submission.
    let fin = entries
        .iter()
        .find(|e| e["action"] == "command.final" && e["command_id"] == mv.json["id"])
        .unwrap();
    assert_eq!(fin["outcome"], "done", "{fin}");
    assert!(fin["id"].as_i64() > m["id"].as_i64(), "{fin} {m}");

    let one = get(&s, "/api/v1/audit?limit=1").await;
    assert_eq!(one.json.as_array().unwrap().len(), 1, "{}", one.text);
    assert!(
        one.json[0]["id"].as_i64().unwrap() >= ids[0],
        "{}",
        one.text
    );
    for q in ["limit=0", "limit=1001", "since=3", "limit=many"] {
        assert_problem(
            &get(&s, &format!("/api/v1/audit?{q}")).await,
            422,
            "validation_failed",
        );
    }
}

/// The following-error peak hold is kept by the kernel every cycle: after a move the held
/// peaks are larger than the following error at rest, and a reset restarts them from there.
#[tokio::test(flavor = "multi_thread")]
async fn the_following_error_peak_hold_is_kept_every_cycle_and_resets() {
    let s = Server::start();
    power_on(&s, "x").await;
    let st = status(&s, "x").await["status"].clone();
    assert_eq!(st["master"], Value::Null, "{st}");
    let mv = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true",
        json!({"position": 300.0, "velocity": 500.0}),
    )
    .await;
    assert_eq!(mv.json["state"], "done", "{}", mv.text);
    let st = status(&s, "x").await["status"].clone();
    let f = |k: &str| st[k].as_f64().unwrap_or_else(|| panic!("{k}: {st}"));
    let (min, max, now) = (
        f("following_error_min"),
        f("following_error_max"),
        f("following_error"),
    );
    assert!(max > 1e-3 && min < -1e-3, "the move lagged both ways: {st}");
    assert!(min <= now && now <= max, "{st}");
    assert!(
        now.abs() < 0.5 * max,
        "at rest the lag is below its peak: {st}"
    );

    let r = post(
        &s,
        "/api/v1/axes/x/status/following-error-peak/reset",
        json!({}),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let from = r.json["cycle"].as_u64().unwrap();
    let after = loop {
        let v = status(&s, "x").await;
        if v["cycle"].as_u64().unwrap() >= from {
            break v["status"].clone();
        }
    };
    let g = |k: &str| after[k].as_f64().unwrap();
    assert!(
        g("following_error_max") - g("following_error_min") < 1e-3,
        "{after}"
    );
    assert!(g("following_error_max") < max, "{after}");
    assert_eq!(
        after["set_position"], 300.0,
        "the reset moves nothing: {after}"
    );
    assert_eq!(after["state"], "standstill", "{after}");
    let r = post(
        &s,
        "/api/v1/axes/nobody/status/following-error-peak/reset",
        json!({}),
    )
    .await;
    assert_problem(&r, 404, "axis_not_found");
}

/// The examples of the OpenAPI document (called by `openapi_json_is_current`). The rules:
///
/// - Every request body and every response with content has an example: on the media type
///   (`example` or `examples`), or on its schema (through `$ref`, or on the items of an array).
/// - A problem+json response has its own example(s) (the generic `Problem` example does not
///   say which error it is), each with the response's `status` and a `code` the server emits:
///   a string literal in backend/server/src (outside api/errors.rs, which builds the examples),
///   `<what>_not_found` of an `ApiError::not_found("<what>", …)`, or a kernel code listed in
///   docs/errors.md.
/// - Every component schema has an example, except plain string enums: their `enum` already
///   lists every value an example could show.
/// - Every example conforms to its schema (types, enum values, required properties, no
///   properties the schema does not have), so that examples cannot drift from the types.
fn check_examples(doc: &Value) {
    let schemas = doc["components"]["schemas"].as_object().unwrap();
    let mut missing = Vec::new();
    let mut wrong = Vec::new();
    for (name, schema) in schemas {
        let plain_enum = schema["type"] == "string" && schema.get("enum").is_some();
        match schema.get("example") {
            Some(example) => {
                if let Err(e) = conforms(doc, schema, example, name, true) {
                    wrong.push(format!("schema {name}: {e}"));
                }
            }
            None if plain_enum => {}
            None => missing.push(format!("schema {name}")),
        }
    }
    let emitted = emitted_codes();
    for (path, ops) in doc["paths"].as_object().unwrap() {
        for (method, op) in ops.as_object().unwrap() {
            let op_name = format!("{} {path}", method.to_uppercase());
            let mut bodies: Vec<(String, Option<u64>, &Value)> = Vec::new();
            for (ct, media) in op["requestBody"]["content"]
                .as_object()
                .into_iter()
                .flatten()
            {
                bodies.push((format!("{op_name} request {ct}"), None, media));
            }
            for (status, r) in op["responses"].as_object().unwrap() {
                let r = match r["$ref"].as_str() {
                    Some(name) => {
                        &doc["components"]["responses"]
                            [name.trim_start_matches("#/components/responses/")]
                    }
                    None => r,
                };
                for (ct, media) in r["content"].as_object().into_iter().flatten() {
                    let status = status.parse::<u64>().ok();
                    bodies.push((
                        format!("{op_name} {} {ct}", status.unwrap_or(0)),
                        status,
                        media,
                    ));
                }
            }
            for (what, status, media) in bodies {
                let own: Vec<&Value> = media
                    .get("example")
                    .into_iter()
                    .chain(
                        media["examples"]
                            .as_object()
                            .into_iter()
                            .flat_map(|m| m.values().map(|e| &e["value"])),
                    )
                    .collect();
                let schema = &media["schema"];
                for example in &own {
                    if let Err(e) = conforms(doc, schema, example, &what, true) {
                        wrong.push(format!("{what}: {e}"));
                    }
                }
                if what.ends_with("application/problem+json") {
                    if own.is_empty() {
                        missing.push(what.clone());
                    }
                    for example in own {
                        if example["status"].as_u64() != status {
                            wrong.push(format!("{what}: example has status {}", example["status"]));
                        }
                        let code = example["code"].as_str().unwrap_or_default();
                        if !emitted(code) {
                            wrong.push(format!("{what}: the server never emits code '{code}'"));
                        }
                    }
                } else if own.is_empty() && !schema_has_example(doc, schema) {
                    missing.push(what);
                }
            }
        }
    }
    assert!(
        missing.is_empty() && wrong.is_empty(),
        "OpenAPI examples (see check_examples for the rules)\nmissing:\n{}\nwrong:\n{}",
        missing.join("\n"),
        wrong.join("\n")
    );
}

fn resolve<'a>(doc: &'a Value, schema: &'a Value) -> &'a Value {
    match schema["$ref"].as_str() {
        Some(r) => {
            let name = r.trim_start_matches("#/components/schemas/");
            resolve(doc, &doc["components"]["schemas"][name])
        }
        None => schema,
    }
}

fn schema_has_example(doc: &Value, schema: &Value) -> bool {
    let s = resolve(doc, schema);
    s.get("example").is_some()
        || (s["type"] == "array" && s.get("items").is_some_and(|i| schema_has_example(doc, i)))
}

/// The property names an object of `schema` may have; `None` when it may have any.
fn property_names(doc: &Value, schema: &Value) -> Option<Vec<String>> {
    let s = resolve(doc, schema);
    if s.get("additionalProperties").is_some_and(|a| a != false) {
        return None;
    }
    let mut names: Vec<String> = s["properties"]
        .as_object()
        .map(|m| m.keys().cloned().collect())
        .unwrap_or_default();
    let parts = s["allOf"].as_array();
    for part in parts.into_iter().flatten() {
        names.extend(property_names(doc, part)?);
    }
    if names.is_empty() && parts.is_none() {
        return None;
    }
    Some(names)
}

/// Checks `v` against `schema` as far as the document uses JSON Schema: `$ref`, `allOf`,
/// `oneOf`, `type` (also lists with "null"), `enum`, `required`, `properties`, `items`.
/// `closed`: properties the schema does not name are an error (off for the parts of an
/// `allOf`, which is checked as a whole).
fn conforms(doc: &Value, schema: &Value, v: &Value, at: &str, closed: bool) -> Result<(), String> {
    let s = resolve(doc, schema);
    for part in s["allOf"].as_array().into_iter().flatten() {
        conforms(doc, part, v, at, false)?;
    }
    if let Some(variants) = s["oneOf"].as_array() {
        let errors: Vec<String> = variants
            .iter()
            .filter_map(|variant| conforms(doc, variant, v, at, true).err())
            .collect();
        if errors.len() == variants.len() {
            return Err(format!(
                "{at}: {v} is none of oneOf ({})",
                errors.join("; ")
            ));
        }
    }
    let types: Vec<&str> = match &s["type"] {
        Value::String(t) => vec![t.as_str()],
        Value::Array(ts) => ts.iter().filter_map(Value::as_str).collect(),
        _ => Vec::new(),
    };
    let type_ok = |t: &str| match t {
        "null" => v.is_null(),
        "boolean" => v.is_boolean(),
        "string" => v.is_string(),
        "integer" => v.is_i64() || v.is_u64(),
        "number" => v.is_number(),
        "array" => v.is_array(),
        "object" => v.is_object(),
        _ => true,
    };
    if !types.is_empty() && !types.iter().any(|t| type_ok(t)) {
        return Err(format!("{at}: {v} is not of type {}", s["type"]));
    }
    if let Some(values) = s["enum"].as_array() {
        if !values.contains(v) {
            return Err(format!("{at}: {v} is not one of {}", s["enum"]));
        }
    }
    if let Some(object) = v.as_object() {
        for required in s["required"].as_array().into_iter().flatten() {
            let required = required.as_str().unwrap();
            if !object.contains_key(required) {
                return Err(format!("{at}: `{required}` is missing"));
            }
        }
        let names = if closed { property_names(doc, s) } else { None };
        for (key, value) in object {
            if let Some(p) = s["properties"].get(key) {
                conforms(doc, p, value, &format!("{at}.{key}"), true)?;
            } else if names.as_ref().is_some_and(|n| !n.contains(key)) {
                return Err(format!("{at}: the schema has no property `{key}`"));
            }
        }
    }
    if let (Some(items), Some(array)) = (s.get("items"), v.as_array()) {
        for (i, item) in array.iter().enumerate() {
            conforms(doc, items, item, &format!("{at}[{i}]"), true)?;
        }
    }
    Ok(())
}

/// Whether the server can send a problem with this `code` (see `check_examples`).
fn emitted_codes() -> impl Fn(&str) -> bool {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut source = String::new();
    let mut dirs = vec![root.join("backend/server/src")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs")
                && !path.ends_with("api/errors.rs")
            {
                source += &std::fs::read_to_string(&path).unwrap();
            }
        }
    }
    let kernel = std::fs::read_to_string(root.join("docs/errors.md")).unwrap();
    move |code: &str| {
        !code.is_empty()
            && (source.contains(&format!("\"{code}\""))
                || code
                    .strip_suffix("_not_found")
                    .is_some_and(|what| source.contains(&format!("not_found(\"{what}\"")))
                || kernel.contains(&format!("`{code}`")))
    }
}

/// What axum answers by itself is problem+json too: a method the route does not take is a 405
/// `method_not_allowed` that keeps its `Allow` header, a path that is not UTF-8 a 400. (The
/// requests are declared JSON: the request checks come before routing, so without it an
/// `/api` PATCH or DELETE would be a 415.)
#[tokio::test(flavor = "multi_thread")]
async fn a_method_a_route_does_not_take_is_a_405_problem_with_allow() {
    let s = Server::start();
    let client = reqwest::Client::new();
    for (method, path, allow) in [
        (reqwest::Method::GET, "/api/v1/axes/x/power", "POST"),
        (
            reqwest::Method::PATCH,
            "/api/v1/axes/x",
            "GET,HEAD,PUT,DELETE",
        ),
        (reqwest::Method::DELETE, "/api/v1/commands", "GET,HEAD"),
        (reqwest::Method::POST, "/metrics", "GET,HEAD"),
    ] {
        let resp = client
            .request(method.clone(), s.url(path))
            .header("content-type", "application/json")
            .send()
            .await
            .unwrap();
        let allow_header = resp.headers()["allow"].to_str().unwrap().to_owned();
        let r = resp_of(resp).await;
        assert_problem(&r, 405, "method_not_allowed");
        assert_eq!(allow_header, allow, "{method} {path}");
        assert!(
            r.json["detail"].as_str().unwrap().contains(method.as_str()),
            "{}",
            r.json
        );
    }
    assert_problem(&get(&s, "/api/v1/axes/%FF").await, 400, "bad_request");
    // The server is still fine and nothing was done.
    assert_eq!(get(&s, "/api/v1/commands").await.json, json!([]));
}

/// A body over the 2 MiB limit is a 413 problem (not a 400 malformed_json) and leaves no
/// command; one just under the limit is read.
#[tokio::test(flavor = "multi_thread")]
async fn a_body_over_the_limit_is_a_413_problem() {
    let s = Server::start();
    let client = reqwest::Client::new();
    let padded = |len: usize| {
        let body = r#"{"position": 10.0, "velocity": 5.0}"#;
        format!("{body}{}", " ".repeat(len - body.len()))
    };
    let send = |path: &'static str, method: reqwest::Method, body: String| {
        let request = client
            .request(method, s.url(path))
            .header("content-type", "application/json")
            .body(body);
        async move { resp_of(request.send().await.unwrap()).await }
    };
    let over = 2 * 1024 * 1024 + 1;
    let r = send(
        "/api/v1/axes/x/move-absolute",
        reqwest::Method::POST,
        padded(over),
    )
    .await;
    assert_problem(&r, 413, "payload_too_large");
    assert!(
        r.json["detail"].as_str().unwrap().contains("2097152"),
        "{}",
        r.json
    );
    // Cam tables and the configuration document (which carries them) take up to 64 MiB: just
    // over 2 MiB is read (and refused for what it says), just over 64 MiB is a 413 naming it.
    // (Only just over: a body far beyond what the server reads is cut off by its close, and
    // the client may see the reset before the response.)
    let r = send("/api/v1/config", reqwest::Method::PUT, padded(over + 1)).await;
    assert_problem(&r, 422, "validation_failed");
    let big = 64 * 1024 * 1024 + 1;
    let r = send("/api/v1/cam-tables", reqwest::Method::POST, padded(big)).await;
    assert_problem(&r, 413, "payload_too_large");
    assert!(
        r.json["detail"].as_str().unwrap().contains("67108864"),
        "{}",
        r.json
    );
    assert_eq!(get(&s, "/api/v1/cam-tables").await.json, json!([]));
    assert_eq!(get(&s, "/api/v1/commands").await.json, json!([]));
    // Just under the limit the body is read: the move is refused by the disabled axis.
    let r = send(
        "/api/v1/axes/x/move-absolute",
        reqwest::Method::POST,
        padded(over - 1),
    )
    .await;
    assert_problem(&r, 409, "axis_cannot_be_started");
}

/// `/api/v1/ws` without a websocket handshake: 426 `websocket_upgrade_required` with the
/// `Upgrade` header for a plain GET, 400 for a malformed handshake; a real one still connects.
#[tokio::test(flavor = "multi_thread")]
async fn a_plain_get_on_the_websocket_is_a_426_problem() {
    let s = Server::start();
    let resp = reqwest::get(s.url("/api/v1/ws")).await.unwrap();
    assert_eq!(resp.headers()["upgrade"], "websocket");
    assert_eq!(resp.headers()["sec-websocket-version"], "13");
    assert_problem(&resp_of(resp).await, 426, "websocket_upgrade_required");
    let resp = reqwest::Client::new()
        .get(s.url("/api/v1/ws"))
        .header("connection", "upgrade")
        .header("upgrade", "websocket")
        .header("sec-websocket-version", "13")
        .send()
        .await
        .unwrap();
    assert_problem(&resp_of(resp).await, 400, "websocket_handshake_invalid");
    let (mut socket, response) =
        tokio_tungstenite::connect_async(format!("ws://{}/api/v1/ws", s.addr))
            .await
            .expect("a websocket handshake still connects");
    assert_eq!(response.status().as_u16(), 101);
    socket.close(None).await.unwrap();
}

/// `GET /audit` pages back with `before_id` (the smallest id of the previous page) and forward
/// with `since_id`; negative ids are a 422 at their parameter.
#[tokio::test(flavor = "multi_thread")]
async fn the_audit_log_pages_back_and_forth() {
    let s = Server::start();
    for v in 0..12 {
        let r = put(
            &s,
            "/api/v1/axes/x/parameters/AxisVeloMax",
            json!({"value": 500.0 + v as f64, "persistent": true}),
        )
        .await;
        assert_eq!(r.status, 200, "{}", r.text);
    }
    let ids = |r: &Resp| -> Vec<i64> {
        r.json
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["id"].as_i64().unwrap())
            .collect()
    };
    let all = ids(&get(&s, "/api/v1/audit?limit=1000").await);
    assert!(
        all.len() >= 12 && all.windows(2).all(|w| w[0] > w[1]),
        "{all:?}"
    );
    let mut paged = Vec::new();
    let mut before = None::<i64>;
    loop {
        let path = match before {
            None => "/api/v1/audit?limit=5".to_string(),
            Some(b) => format!("/api/v1/audit?limit=5&before_id={b}"),
        };
        let page = ids(&get(&s, &path).await);
        if page.is_empty() {
            break;
        }
        before = page.last().copied();
        paged.extend(page);
    }
    assert_eq!(
        paged, all,
        "paging back gives every entry once, newest first"
    );
    let newer = ids(&get(&s, &format!("/api/v1/audit?since_id={}", all[3])).await);
    assert_eq!(newer, all[..3]);
    // A client name that is not ASCII is kept.
    let r = reqwest::Client::new()
        .put(s.url("/api/v1/axes/x/parameters/AxisVeloMax"))
        .header("content-type", "application/json")
        .header(
            "x-client-id",
            reqwest::header::HeaderValue::from_bytes("Presse-Süd".as_bytes()).unwrap(),
        )
        .body(json!({"value": 600.0, "persistent": true}).to_string())
        .send()
        .await
        .unwrap();
    assert_eq!(r.status().as_u16(), 200);
    let newest = get(&s, "/api/v1/audit?limit=1").await;
    assert_eq!(newest.json[0]["client_id"], "Presse-Süd", "{}", newest.text);
    for q in ["since_id=-1", "before_id=0"] {
        let r = get(&s, &format!("/api/v1/audit?{q}")).await;
        assert_eq!(r.status, 422, "{q}: {}", r.text);
    }
}

/// `/metrics` (issue 13): ~20 buckets per timing histogram (all of them with `buckets=fine`),
/// `motiond_build_info`, process figures, per-axis gauges, and submitted commands counted by
/// block and verdict; the classic text format is well formed (every sample belongs to the family
/// its `# TYPE` names, counters end in `_total`, buckets rise to `+Inf` = `_count`), small, and
/// OpenMetrics is served to whoever asks for it.
#[tokio::test(flavor = "multi_thread")]
async fn metrics_count_commands_and_describe_axes_and_process() {
    let s = Server::start();
    power_on(&s, "x").await;
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute",
        json!({"position": 5000.0, "velocity": 10.0}),
    )
    .await;
    assert_eq!(r.status, 409, "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute",
        json!({"position": 5.0, "velocity": -1.0}),
    )
    .await;
    assert_eq!(r.status, 422, "{}", r.text);
    let m = get(&s, "/metrics").await;
    assert_eq!(m.status, 200);
    assert!(
        m.content_type.starts_with("text/plain; version=0.0.4"),
        "{}",
        m.content_type
    );
    let t = &m.text;
    assert!(t.len() < 10_000, "{} bytes", t.len());
    for line in [
        "motiond_commands_total{block=\"power\",verdict=\"accepted\"} 1",
        "motiond_commands_total{block=\"move-absolute\",verdict=\"rejected\"} 1",
        "motiond_commands_total{block=\"move-absolute\",verdict=\"invalid\"} 1",
        "motiond_axis_state{axis=\"x\"} 1",
        "motiond_axis_error_id{axis=\"y\"} 0",
    ] {
        assert!(
            t.lines().any(|l| l.starts_with(line)),
            "{line} missing:\n{t}"
        );
    }
    for name in [
        "motiond_build_info{version=",
        "process_resident_memory_bytes ",
        "process_cpu_seconds_total ",
        "process_open_fds ",
        "motiond_axis_following_error_peak{axis=\"x\"}",
        "motiond_cycle_requests_total ",
    ] {
        assert!(t.contains(name), "{name} missing");
    }
    // Well formed: each sample's family is the last `# TYPE`.
    let mut family = String::new();
    let mut kind = String::new();
    let mut buckets: Vec<(String, u64)> = Vec::new();
    let mut count = None;
    let mut histograms = 0;
    let mut end_of = |family: &str, buckets: &mut Vec<(String, u64)>, count: &mut Option<u64>| {
        if let Some(n) = count.take() {
            assert_eq!(
                buckets.last().map(|b| (b.0.as_str(), b.1)),
                Some(("+Inf", n)),
                "{family}"
            );
            assert!(
                (18..=26).contains(&buckets.len()),
                "{family}: {} buckets",
                buckets.len()
            );
            histograms += 1;
        }
        buckets.clear();
    };
    for line in t.lines() {
        if let Some(rest) = line.strip_prefix("# TYPE ") {
            end_of(&family, &mut buckets, &mut count);
            let (f, k) = rest.split_once(' ').unwrap();
            (family, kind) = (f.to_string(), k.to_string());
            assert!(kind != "counter" || family.ends_with("_total"), "{line}");
            continue;
        }
        if line.starts_with('#') {
            assert!(line.starts_with("# HELP "), "{line}");
            continue;
        }
        let name = line.split(['{', ' ']).next().unwrap();
        if kind == "histogram" {
            let suffix = name
                .strip_prefix(family.as_str())
                .unwrap_or_else(|| panic!("{line} not in {family}"));
            assert!(["_bucket", "_sum", "_count"].contains(&suffix), "{line}");
            let v = line.rsplit(' ').next().unwrap();
            if suffix == "_bucket" {
                let le = line
                    .split("le=\"")
                    .nth(1)
                    .unwrap()
                    .split('"')
                    .next()
                    .unwrap();
                buckets.push((le.to_string(), v.parse().unwrap()));
                assert!(
                    buckets.windows(2).all(|w| w[0].1 <= w[1].1),
                    "{family}: not cumulative"
                );
            } else if suffix == "_count" {
                count = Some(v.parse().unwrap());
            }
        } else {
            assert_eq!(name, family, "{line}");
        }
    }
    end_of(&family, &mut buckets, &mut count);
    assert_eq!(histograms, 3);
    let fine = get(&s, "/metrics?buckets=fine").await;
    let n = fine
        .text
        .lines()
        .filter(|l| l.starts_with("motiond_cycle_compute_seconds_bucket"))
        .count();
    assert!(n > 300, "{n} fine buckets");
    let r = get(&s, "/metrics?buckets=coarse").await;
    assert_eq!(r.status, 422, "{}", r.text);
    let om = reqwest::Client::new()
        .get(s.url("/metrics"))
        .header(
            "accept",
            "application/openmetrics-text;version=1.0.0,text/plain;q=0.5",
        )
        .send()
        .await
        .unwrap();
    assert!(
        om.headers()["content-type"]
            .to_str()
            .unwrap()
            .starts_with("application/openmetrics-text")
    );
    assert!(om.text().await.unwrap().ends_with("# EOF\n"));
}

/// `?wait=true` says how the wait ended (issue 28, defect 2): a power on an axis in
/// error_stop cannot reach Status before a reset — the answer comes at once with
/// `wait.reached: false`, the reason, the axis state and its error — and a wait that reaches
/// its milestone says so.
#[tokio::test(flavor = "multi_thread")]
async fn a_wait_says_why_it_ended_early() {
    let s = Server::start();
    let r = post(&s, "/api/v1/axes/x/power?wait=true", json!({})).await;
    assert_eq!(r.json["wait"]["reached"], true, "{}", r.text);
    assert_eq!(r.json["wait"]["milestone"], "status", "{}", r.text);
    assert!(r.json["wait"]["reason"].is_null(), "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/x/simulation/fault",
        json!({"kind": "drive_fault", "code": 8976}),
    )
    .await;
    assert_eq!(r.status, 204, "{}", r.text);
    until_status(&s, "x", 20, |st| st["state"] == "error_stop").await;
    let r = post(
        &s,
        "/api/v1/axes/x/power?wait=true&timeout_ms=30000",
        json!({}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["state"], "active", "{}", r.text);
    assert_eq!(r.json["outputs"]["status"], false, "{}", r.text);
    let w = &r.json["wait"];
    assert_eq!(w["reached"], false, "{}", r.text);
    assert_eq!(w["reason"], "axis_error_stop", "{}", r.text);
    assert_eq!(w["axis_state"], "error_stop", "{}", r.text);
    assert_eq!(w["axis_error_id"], 0x7010, "{}", r.text);
    assert_eq!(w["axis_error_code"], "drive_fault", "{}", r.text);
    // A wait that runs out says `timeout`: a long move waited for 50 ms.
    let r = post(&s, "/api/v1/axes/y/power?wait=true", json!({})).await;
    assert_eq!(r.json["wait"]["reached"], true, "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/y/move-absolute?wait=true&timeout_ms=50",
        json!({"position": 900.0, "velocity": 10.0}),
    )
    .await;
    assert_eq!(r.json["wait"]["reached"], false, "{}", r.text);
    assert_eq!(r.json["wait"]["reason"], "timeout", "{}", r.text);
    assert_eq!(r.json["wait"]["milestone"], "done", "{}", r.text);
    // Without wait there is no `wait`.
    let r = post(&s, "/api/v1/axes/y/halt", json!({})).await;
    assert!(r.json.get("wait").is_none(), "{}", r.text);
    s.stop();
}

/// A command the axis refuses names what is in the way and what to do (issue 28, defect 3).
#[tokio::test(flavor = "multi_thread")]
async fn refusals_say_what_is_in_the_way() {
    let s = Server::start();
    let mv = json!({"position": 10.0, "velocity": 100.0});
    let r = post(&s, "/api/v1/axes/x/move-absolute", mv.clone()).await;
    assert_problem(&r, 409, "axis_cannot_be_started");
    let d = r.json["detail"].as_str().unwrap();
    assert!(d.contains("disabled") && d.contains("power"), "{d}");
    power_on(&s, "x").await;
    // A target beyond a software limit: the limit is named, not the (irrelevant) state.
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute",
        json!({"position": 2000.0, "velocity": 100.0}),
    )
    .await;
    assert_problem(&r, 409, "target_above_soft_limit");
    let d = r.json["detail"].as_str().unwrap();
    assert!(
        d.contains("SWLimitPos (#1019) is 1000") && !d.contains("standstill"),
        "{d}"
    );
    let stop = post(&s, "/api/v1/axes/x/stop?wait=true", json!({})).await;
    assert_eq!(stop.json["state"], "done", "{}", stop.text);
    let id = stop.json["id"].as_u64().unwrap();
    let r = post(&s, "/api/v1/axes/x/move-absolute", mv.clone()).await;
    assert_problem(&r, 409, "axis_cannot_be_started");
    let d = r.json["detail"].as_str().unwrap();
    assert!(
        d.contains(&format!("MC_Stop (command {id})"))
            && d.contains(&format!("DELETE /api/v1/commands/{id}")),
        "{d}"
    );
    let r = post(
        &s,
        "/api/v1/axes/x/simulation/fault",
        json!({"kind": "drive_fault", "code": 8976}),
    )
    .await;
    assert_eq!(r.status, 204);
    until_status(&s, "x", 20, |st| st["state"] == "error_stop").await;
    let r = post(&s, "/api/v1/axes/x/move-absolute", mv.clone()).await;
    let d = r.json["detail"].as_str().unwrap();
    assert!(
        d.contains("error_stop with 0x7010 drive_fault") && d.contains("reset"),
        "{d}"
    );
    // A cam that would make the slave jump says where the slave must be.
    let table = json!({"name": "lift", "table_type": "motion_function", "points": [
        {"point_index": 1, "function_type": "polynom5", "point_type": "rest", "master_pos": 0, "slave_pos": 10},
        {"point_index": 2, "function_type": "polynom5", "point_type": "rest", "master_pos": 200, "slave_pos": 100}]});
    assert_eq!(post(&s, "/api/v1/cam-tables", table).await.status, 201);
    power_on(&s, "y").await;
    power_on(&s, "spindle").await;
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in",
        json!({"master": "spindle", "cam_table": "lift"}),
    )
    .await;
    assert_problem(&r, 409, "cam_slave_would_jump");
    let d = r.json["detail"].as_str().unwrap();
    assert!(
        d.contains("puts the slave at 10 ") && d.contains("the slave is at 0"),
        "{d}"
    );
    // A cam table id out of 1..255 carries its number (docs/errors.md 0x4B32).
    for id in [0, 256] {
        let r = post(
            &s,
            "/api/v1/cam-tables",
            json!({"name": format!("t{id}"), "id": id, "table_type": "non_equidistant", "rows": [[0.0, 0.0], [1.0, 1.0]]}),
        )
        .await;
        assert_problem(&r, 422, "validation_failed");
        assert_eq!(r.json["error_id"], 0x4B32, "{}", r.text);
    }
    s.stop();
}
