//! Axis groups (TwinCAT TF5420 CM group) over HTTP and the websocket against the real binary:
//! the demo group `xy`, a path with a line, an arc and a blended corner run with `?wait=true`,
//! invalid entries refused field by field and changing nothing, a blocker released over the
//! websocket, a stop held until released, the configuration kept across a kill -9.

mod common;

use std::time::Duration;

use common::*;
use futures_util::StreamExt;
use serde_json::{Value, json};
use tokio_tungstenite::tungstenite::Message;

/// The README tour's path: a line, a quarter arc (centre mode) and two corners blended with a
/// 5 mm tolerance sphere; it ends at (0, 150).
fn tour_path() -> Value {
    json!({"entries": [
        {"type": "linear", "position": [100.0, 0.0], "velocity": 200.0},
        {"type": "circular", "circ_mode": "center", "aux_point": [100.0, 50.0, 0.0], "end_point": [150.0, 50.0],
            "velocity": 200.0, "buffer_mode": "buffered"},
        {"type": "linear", "position": [150.0, 150.0], "velocity": 200.0, "buffer_mode": "blending_previous",
            "transition_mode": "corner_distance", "transition_parameters": [5.0]},
        {"type": "linear", "position": [0.0, 150.0], "velocity": 200.0, "buffer_mode": "blending_previous",
            "transition_mode": "corner_distance", "transition_parameters": [5.0], "invoke_id": 4}
    ]})
}

async fn group_status(s: &Server) -> Value {
    let r = get(s, "/api/v1/groups/xy/status").await;
    assert_eq!(r.status, 200, "{}", r.text);
    r.json
}

/// Polls the group's status until `f` holds (or panics after 20 s): the status is what the
/// cycle thread published, there is no event to wait on for a state.
async fn until_group(s: &Server, what: &str, f: impl Fn(&Value) -> bool) -> Value {
    let deadline = std::time::Instant::now() + Duration::from_secs(20);
    loop {
        let st = group_status(s).await;
        if f(&st) {
            return st;
        }
        assert!(std::time::Instant::now() < deadline, "{what}: {st}");
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
}

async fn enable_xy(s: &Server) {
    power_on(s, "x").await;
    power_on(s, "y").await;
    let r = post(s, "/api/v1/groups/xy/enable?wait=true", json!({})).await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["state"], "done", "{}", r.text);
    assert_eq!(r.json["group"], "xy");
    until_group(s, "standby", |st| st["state"] == "standby").await;
}

fn near(v: &Value, want: f64) -> bool {
    (v.as_f64().unwrap_or(f64::NAN) - want).abs() < 1e-6
}

#[tokio::test(flavor = "multi_thread")]
async fn a_group_runs_a_path_refuses_what_is_wrong_and_keeps_its_configuration_across_a_kill() {
    let dir = temp_dir();
    let db = dir.join("g.db");
    let db = db.to_str().unwrap();
    let s = Server::start_with(db, &[]);

    // The demo machine's group: disabled, x and y in their roles.
    let g = get(&s, "/api/v1/groups/xy").await;
    assert_eq!(g.status, 200, "{}", g.text);
    assert_eq!(g.json["id"], 1);
    assert_eq!(
        g.json["axes"],
        json!([{"role": "x", "axis": "x", "axis_id": 1}, {"role": "y", "axis": "y", "axis_id": 2}])
    );
    assert_eq!(g.json["status"]["state"], "disabled");
    assert_eq!(
        get(&s, "/api/v1/groups/1").await.json["name"],
        "xy",
        "by id or name"
    );

    // A group of its own, validated field by field.
    let r = post(
        &s,
        "/api/v1/groups",
        json!({"name": "spin", "axes": [{"role": "x", "axis": "x"}]}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(
        r.json["errors"][0]["field"], "axes[0].axis",
        "x is xy's: {}",
        r.text
    );
    let r = post(
        &s,
        "/api/v1/groups",
        json!({"name": "spin", "axes": [{"role": "z", "axis": "spindle"}]}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(r.json["errors"][0]["field"], "axes[0].role", "{}", r.text);
    let r = post(&s, "/api/v1/groups", json!({"name": "spin",
        "default_dynamics": {"velocity": 2000.0, "acceleration": 1000.0, "deceleration": 1000.0, "jerk": 10000.0}})).await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(
        r.json["errors"][0]["field"], "default_dynamics.velocity",
        "{}",
        r.text
    );
    assert_eq!(r.json["error_id"], 0x8140, "{}", r.text);
    let r = post(
        &s,
        "/api/v1/groups",
        json!({"name": "spin", "convention": "xyzc", "additional_axes": 1,
        "axes": [{"role": "addax1", "axis": "spindle"}]}),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.location.as_deref(), Some("/api/v1/groups/2"));
    assert_eq!(
        r.json["status"]["members"],
        json!({"addax1": "spindle"}),
        "{}",
        r.text
    );
    // 16 group slots: the 17th is refused.
    for i in 3..=16 {
        let r = post(&s, "/api/v1/groups", json!({"name": format!("g{i}")})).await;
        assert_eq!(r.status, 201, "{}", r.text);
    }
    assert_problem(
        &post(&s, "/api/v1/groups", json!({"name": "g17"})).await,
        409,
        "no_free_group_slot",
    );
    for i in 3..=16 {
        assert_eq!(
            delete(&s, &format!("/api/v1/groups/g{i}")).await.status,
            204
        );
    }

    enable_xy(&s).await;

    // Configuration changes only on a disabled group.
    let g = get(&s, "/api/v1/groups/xy").await.json;
    let mut body =
        json!({"name": "xy", "axes": [{"role": "x", "axis": "x"}, {"role": "y", "axis": "y"}]});
    body["default_dynamics"] = g["default_dynamics"].clone();
    body["maximum_dynamics"] = g["maximum_dynamics"].clone();
    assert_problem(
        &put(&s, "/api/v1/groups/xy", body.clone()).await,
        409,
        "group_state_invalid",
    );
    assert_problem(
        &delete(&s, "/api/v1/groups/xy").await,
        409,
        "group_state_invalid",
    );
    // Nor does an axis leave an enabled group by being deleted.
    assert_problem(
        &delete(&s, "/api/v1/axes/y").await,
        409,
        "group_state_invalid",
    );
    // A member of an enabled group takes no single-axis motion (TF5420 §1.5).
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute",
        json!({"position": 10.0, "velocity": 10.0}),
    )
    .await;
    assert_problem(&r, 409, "axis_in_group");
    assert_eq!(r.json["error_id"], 0x8145);

    // Invalid entries: each a 422 naming the entry's field and the rule, and nothing changes.
    let commands_before = get(&s, "/api/v1/commands?limit=2000")
        .await
        .json
        .as_array()
        .unwrap()
        .len();
    let line = |p: [f64; 2]| json!({"type": "linear", "position": p, "velocity": 100.0});
    let mut blended = line([20.0, 20.0]);
    blended["buffer_mode"] = json!("buffered");
    blended["transition_mode"] = json!("corner_distance");
    blended["transition_parameters"] = json!([2.0]);
    let mut second_aborting = line([20.0, 20.0]);
    second_aborting["buffer_mode"] = json!("aborting");
    let cases = [
        (
            json!([{"type": "linear", "position": [1.0, 2.0, 3.0], "velocity": 100.0}]),
            "entries[0].position",
            "position_count_invalid",
        ),
        (
            json!([{"type": "linear", "position": [1.0, 2.0], "velocity": 0.0}]),
            "entries[0].velocity",
            "path_dynamics_invalid",
        ),
        (
            json!([{"type": "linear", "position": [1.0, 2.0], "velocity": "default"}]),
            "entries[0].velocity",
            "path_dynamics_invalid",
        ),
        (
            json!([line([10.0, 0.0]), second_aborting]),
            "entries[1].buffer_mode",
            "buffer_mode_invalid",
        ),
        (
            json!([line([10.0, 0.0]), blended]),
            "entries[1].transition_mode",
            "transition_mode_invalid",
        ),
        (
            json!([{"type": "blocker", "blocker_id": 0}]),
            "entries[0].blocker_id",
            "blocker_id_invalid",
        ),
        (
            json!([{"type": "dwell", "time": -1.0}]),
            "entries[0].time",
            "dwell_time_invalid",
        ),
        (
            json!([{"type": "linear", "position": [1.0, 2.0], "velocity": 100.0, "transition_mode": "start_velocity"}]),
            "entries[0].transition_mode",
            "transition_mode_invalid",
        ),
    ];
    for (entries, field, code) in cases {
        let r = post(
            &s,
            "/api/v1/groups/xy/move-path",
            json!({"entries": entries}),
        )
        .await;
        assert_problem(&r, 422, code);
        assert_eq!(r.json["errors"][0]["field"], field, "{}", r.text);
    }
    let r = post(&s, "/api/v1/groups/xy/move-path", json!({"entries": [{"type": "linear", "position": [1.0, 2.0], "velocity": 100.0, "speed": 1}]})).await;
    assert_problem(&r, 422, "validation_failed");
    let r = post(
        &s,
        "/api/v1/groups/xy/move-path",
        json!({"entries": [{"type": "linear", "position": [1e13, 2.0], "velocity": 100.0}]}),
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(
        r.json["errors"][0]["field"], "entries[0].position[0]",
        "{}",
        r.text
    );
    // Three points on a line are no arc: the kernel's verdict, with its code.
    let r = post(
        &s,
        "/api/v1/groups/xy/move-path",
        json!({"entries": [{"type": "circular", "circ_mode": "border",
        "aux_point": [5.0, 0.0, 0.0], "end_point": [10.0, 0.0], "velocity": 100.0}]}),
    )
    .await;
    assert_problem(&r, 422, "circle_invalid");
    let st = group_status(&s).await;
    assert_eq!(st["state"], "standby", "{st}");
    assert_eq!(st["queued_entries"], 0, "{st}");
    assert_eq!(st["position"], json!({"x": 0.0, "y": 0.0}), "{st}");
    let commands_after = get(&s, "/api/v1/commands?limit=2000")
        .await
        .json
        .as_array()
        .unwrap()
        .len();
    assert_eq!(
        commands_before, commands_after,
        "no command resource for a refused request"
    );

    // The tour's path, waited for: done, and the axes stand at its end.
    let r = post(
        &s,
        "/api/v1/groups/xy/move-path?wait=true&timeout_ms=30000",
        tour_path(),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["state"], "done", "{}", r.text);
    assert_eq!(r.json["wait"]["reached"], true, "{}", r.text);
    assert!(r.json["outputs"]["done"] == true && r.json["outputs"]["error"] == false);
    let x = status(&s, "x").await;
    let y = status(&s, "y").await;
    assert!(near(&x["status"]["set_position"], 0.0), "{x}");
    assert!(near(&y["status"]["set_position"], 150.0), "{y}");
    let st = until_group(&s, "standby after the path", |st| st["state"] == "standby").await;
    assert!(near(&st["position"]["y"], 150.0), "{st}");
    // Its entries were built off the cycle thread and taken as built (decision 133).
    assert_eq!(st["prepared_paths"], 1, "{st}");

    // A frame for later paths: (10, 0) in a frame turned by 90° about Z and shifted by
    // (20, 30) is (20, 40).
    let r = post(
        &s,
        "/api/v1/groups/xy/set-coordinate-transform?wait=true",
        json!({"translation": [20.0, 30.0, 0.0], "rotation": [0.0, 0.0, 90.0]}),
    )
    .await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    let r = post(
        &s,
        "/api/v1/groups/xy/set-coordinate-transform",
        json!({"translation": [0.0, 0.0, 0.0], "rotation": [10.0, 0.0, 0.0]}),
    )
    .await;
    assert_eq!(r.status, 422, "an XY group turns only about Z: {}", r.text);
    let r = post(
        &s,
        "/api/v1/groups/xy/move-path?wait=true&timeout_ms=30000",
        json!({"entries": [{"type": "linear", "position": [10.0, 0.0], "velocity": 200.0}]}),
    )
    .await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    let st = until_group(&s, "standby after the framed path", |st| {
        st["state"] == "standby"
    })
    .await;
    assert!(
        near(&st["position"]["x"], 20.0) && near(&st["position"]["y"], 40.0),
        "{st}"
    );
    assert_eq!(st["frame"]["rotation"], json!([0.0, 0.0, 90.0]), "{st}");

    // Halt with ?wait=true at standstill is done at once; disabled again, a PUT takes.
    let r = post(
        &s,
        "/api/v1/groups/xy/halt?wait=true",
        json!({"deceleration": "maximum", "jerk": "ignore"}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let r = post(&s, "/api/v1/groups/xy/disable?wait=true", json!({})).await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    until_group(&s, "disabled", |st| st["state"] == "disabled").await;
    body["override_ramp_time"] = json!(0.25);
    let r = put(&s, "/api/v1/groups/xy", body).await;
    assert_eq!(r.status, 200, "{}", r.text);

    // kill -9: the configuration is in the database.
    s.stop();
    let s = Server::start_with(db, &[]);
    let g = get(&s, "/api/v1/groups/xy").await;
    assert_eq!(g.status, 200, "{}", g.text);
    assert_eq!(g.json["override_ramp_time"], 0.25, "{}", g.text);
    assert_eq!(g.json["status"]["state"], "disabled", "{}", g.text);
    assert_eq!(
        g.json["status"]["members"],
        json!({"x": "x", "y": "y"}),
        "{}",
        g.text
    );
    let spin = get(&s, "/api/v1/groups/spin").await;
    assert_eq!(
        spin.json["axes"],
        json!([{"role": "addax1", "axis": "spindle", "axis_id": 3}]),
        "{}",
        spin.text
    );
    assert_eq!(
        get(&s, "/api/v1/groups")
            .await
            .json
            .as_array()
            .unwrap()
            .len(),
        2
    );
    // A deleted axis leaves its (disabled) group's configuration and membership.
    assert_eq!(delete(&s, "/api/v1/axes/spindle").await.status, 204);
    let spin = get(&s, "/api/v1/groups/spin").await.json;
    assert_eq!(spin["axes"], json!([]), "{spin}");
    assert_eq!(spin["status"]["members"], json!({}), "{spin}");
    // And it is in the configuration document.
    let doc = get(&s, "/api/v1/config").await;
    assert_eq!(doc.json["groups"][0]["name"], "xy", "{}", doc.text);
    // An import replaces the groups with the document's, members checked against its axes.
    let mut bad = doc.json.clone();
    bad["groups"][0]["axes"][0]["axis"] = json!("nope");
    let r = put(&s, "/api/v1/config", bad).await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(
        r.json["errors"][0]["field"], "groups[0].axes[0].axis",
        "{}",
        r.text
    );
    let mut one = doc.json.clone();
    one["groups"].as_array_mut().unwrap().truncate(1);
    let r = put(&s, "/api/v1/config", one).await;
    assert_eq!(r.status, 200, "{}", r.text);
    let all = get(&s, "/api/v1/groups").await.json;
    assert_eq!(all.as_array().unwrap().len(), 1, "{all}");
    assert_eq!(
        all[0]["status"]["members"],
        json!({"x": "x", "y": "y"}),
        "{all}"
    );
    enable_xy(&s).await;
    assert_problem(
        &put(&s, "/api/v1/config", doc.json.clone()).await,
        409,
        "group_state_invalid",
    );
    s.stop();
    let _ = std::fs::remove_dir_all(dir);
}

#[tokio::test(flavor = "multi_thread")]
async fn a_blocker_is_released_and_a_stop_held_over_the_websocket() {
    let s = Server::start();
    enable_xy(&s).await;
    let mut ws = ws_connect(&s).await;

    // The group's status as a subscription: the full object first.
    let r = call(
        &mut ws,
        9,
        "subscribe",
        json!({"topic": "groups/xy/status", "rate_hz": 50}),
    )
    .await;
    assert_eq!(r["result"]["topic"], "groups/xy/status", "{r}");
    loop {
        let msg = tokio::time::timeout(Duration::from_secs(20), ws.next())
            .await
            .expect("an update")
            .unwrap()
            .unwrap();
        let Message::Text(t) = msg else { continue };
        let v: Value = serde_json::from_str(&t).unwrap();
        if v["method"] == "update" && v["params"]["topic"] == "groups/xy/status" {
            assert_eq!(v["params"]["full"], true, "{v}");
            assert_eq!(v["params"]["data"]["state"], "standby", "{v}");
            break;
        }
    }
    let r = call(
        &mut ws,
        10,
        "unsubscribe",
        json!({"topic": "groups/xy/status"}),
    )
    .await;
    assert_eq!(r["result"], true, "{r}");

    // A path that holds at blocker 7 between two lines.
    let r = call(&mut ws, 1, "move-path", json!({"group": "xy", "entries": [
        {"type": "linear", "position": [50.0, 0.0], "velocity": 200.0},
        {"type": "blocker", "blocker_id": 7},
        {"type": "linear", "position": [50.0, 50.0], "velocity": 200.0, "buffer_mode": "buffered"}
    ]})).await;
    let path = r["result"]["id"].as_u64().unwrap_or_else(|| panic!("{r}"));
    assert_eq!(r["result"]["group"], "xy", "{r}");
    let st = until_group(&s, "held at blocker 7", |st| st["blocked"] == true).await;
    assert_eq!(st["blocker_id"], 7, "{st}");
    assert_eq!(st["state"], "moving", "a held path is moving (TF5420 §4.3)");
    assert!(
        near(&st["position"]["x"], 50.0) && near(&st["position"]["y"], 0.0),
        "{st}"
    );
    let b = get(&s, "/api/v1/groups/xy/read-blocker-status").await;
    assert_eq!(b.json["blocked"], true, "{}", b.text);
    assert_eq!(b.json["blocker_id"], 7, "{}", b.text);
    // The same names as the axis's blocks: `group` in the params says whose.
    let r = call(
        &mut ws,
        2,
        "release-blocker",
        json!({"group": "xy", "blocker_id": 7, "wait": true}),
    )
    .await;
    assert_eq!(r["result"]["state"], "done", "{r}");
    let done = until_final(&s, path, 20).await;
    assert_eq!(done["state"], "done", "{done}");
    assert!(near(&status(&s, "y").await["status"]["set_position"], 50.0));

    // MC_GroupStop: done at standstill, the group locked in stopping until released.
    let r = call(&mut ws, 3, "stop", json!({"group": "xy", "wait": true})).await;
    let stop = r["result"]["id"].as_u64().unwrap_or_else(|| panic!("{r}"));
    assert_eq!(r["result"]["outputs"]["done"], true, "{r}");
    assert_eq!(r["result"]["outputs"]["busy"], true, "held: {r}");
    assert_eq!(group_status(&s).await["state"], "stopping");
    let r = post(
        &s,
        "/api/v1/groups/xy/move-path",
        json!({"entries": [
        {"type": "linear", "position": [0.0, 0.0], "velocity": 100.0}]}),
    )
    .await;
    assert_problem(&r, 409, "group_state_invalid");
    let r = call(&mut ws, 4, "release", json!({"command": stop})).await;
    assert!(r["result"]["cycle"].is_u64(), "{r}");
    until_group(&s, "standby after the release", |st| {
        st["state"] == "standby"
    })
    .await;
    let r = post(
        &s,
        "/api/v1/groups/xy/move-path?wait=true",
        json!({"entries": [
        {"type": "linear", "position": [0.0, 0.0], "velocity": 100.0}]}),
    )
    .await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
}

/// MC_TrackConveyorBelt over HTTP: the spindle serves as the conveyor (an ordinary axis in
/// move-velocity). `?wait=true` answers at InSync with the command still active (it has no
/// Done); refusals change nothing; a static frame detaches, Done once the tracking stands.
#[tokio::test(flavor = "multi_thread")]
async fn a_group_tracks_a_conveyor_until_a_frame_detaches_it() {
    let s = Server::start();
    enable_xy(&s).await;
    power_on(&s, "spindle").await;
    let r = post(
        &s,
        "/api/v1/axes/spindle/move-velocity?wait=true&timeout_ms=5000",
        json!({"velocity": 20.0}),
    )
    .await;
    assert_eq!(r.json["outputs"]["in_velocity"], true, "{}", r.text);
    let body = |conveyor: &str, velocity: f64| {
        json!({"conveyor": conveyor, "translation": [0.0, 50.0, 0.0],
            "initial_object_position": [10.0], "master_ref_position": 0.0,
            "velocity": velocity, "acceleration": 500.0, "deceleration": 500.0, "jerk": 5000.0})
    };
    // Refused, changing nothing: a member as conveyor, a velocity not above the conveyor's,
    // an object outside an XY group's plane.
    let r = post(
        &s,
        "/api/v1/groups/xy/track-conveyor-belt",
        body("x", 100.0),
    )
    .await;
    assert_problem(&r, 409, "conveyor_invalid");
    let r = post(
        &s,
        "/api/v1/groups/xy/track-conveyor-belt",
        body("spindle", 15.0),
    )
    .await;
    assert_problem(&r, 409, "tracking_dynamics_invalid");
    let mut bad = body("spindle", 100.0);
    bad["initial_object_position"] = json!([10.0, 0.0, 5.0]);
    let r = post(&s, "/api/v1/groups/xy/track-conveyor-belt", bad).await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert!(r.text.contains("initial_object_position[2]"), "{}", r.text);
    assert_eq!(group_status(&s).await["state"], "standby");

    let r = post(
        &s,
        "/api/v1/groups/xy/track-conveyor-belt?wait=true&timeout_ms=10000",
        body("spindle", 100.0),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["outputs"]["in_sync"], true, "{}", r.text);
    assert_eq!(r.json["outputs"]["busy"], true, "no Done: {}", r.text);
    let track = r.json["id"].as_u64().unwrap();
    let st = group_status(&s).await;
    assert_eq!(st["state"], "moving", "{st}");
    assert_eq!(st["tracking"]["conveyor"], "spindle", "{st}");
    assert_eq!(st["tracking"]["command"], track, "{st}");
    // The frame of later paths is the object's.
    assert_eq!(st["frame"]["translation"][1], 50.0, "{st}");

    let r = post(
        &s,
        "/api/v1/groups/xy/set-coordinate-transform?wait=true&timeout_ms=10000",
        json!({"translation": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 0.0]}),
    )
    .await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    let r = get(&s, &format!("/api/v1/commands/{track}")).await;
    assert_eq!(r.json["state"], "aborted", "{}", r.text);
    let st = until_group(&s, "standby after detaching", |st| st["state"] == "standby").await;
    assert!(st.get("tracking").is_none(), "{st}");
    assert_eq!(st["tracking_velocity"], 0.0, "{st}");
    // The members' actual positions beside the set point (the drives' feedback, same cycle).
    for role in ["x", "y"] {
        let (set, actual) = (&st["position"][role], &st["actual_position"][role]);
        assert!(
            (set.as_f64().unwrap() - actual.as_f64().unwrap()).abs() < 0.05,
            "{role}: {st}"
        );
    }

    // The group's commands, by group: each names its group and no axis.
    let r = get(&s, "/api/v1/commands?group=xy").await;
    assert_eq!(r.status, 200, "{}", r.text);
    let list = r.json.as_array().unwrap();
    assert!(list.iter().any(|c| c["id"] == track), "{}", r.text);
    assert!(
        list.iter()
            .all(|c| c["group"] == "xy" && c.get("axis").is_none()),
        "{}",
        r.text
    );
    let r = get(&s, "/api/v1/commands?axis=spindle").await;
    assert!(
        r.json
            .as_array()
            .unwrap()
            .iter()
            .all(|c| c["axis"] == "spindle" && c.get("group").is_none()),
        "{}",
        r.text
    );
    let r = get(&s, "/api/v1/commands?group=gantry").await;
    assert_problem(&r, 404, "group_not_found");
}

/// The §8.3 example's arcs N20 and N30 (both counter-clockwise, as the manual's prose has
/// them), from N10's end (200, 0): two quarter arcs of radius 100 in the XY plane.
fn worked_arcs(n20: &str) -> Value {
    json!([
        {"type": "circular", "circ_mode": "center", "aux_point": [200.0, -100.0, 0.0], "end_point": [300.0, -100.0],
            "path_choice": n20, "velocity": 1000.0, "invoke_id": 20},
        {"type": "circular", "circ_mode": "center", "aux_point": [400.0, -100.0, 0.0], "end_point": [400.0, -200.0],
            "path_choice": "counter_clockwise", "velocity": 1000.0, "buffer_mode": "buffered", "invoke_id": 30}
    ])
}

#[tokio::test(flavor = "multi_thread")]
async fn a_path_is_analysed_by_the_groups_planner_without_storing_or_moving_anything() {
    let s = Server::start();
    enable_xy(&s).await;
    let before = group_status(&s).await;
    let commands_before = get(&s, "/api/v1/commands?limit=2000").await.json;

    // §8.3: two quarter arcs of π·100/2 ≈ 157.08 each.
    let r = post(
        &s,
        "/api/v1/path-analysis",
        json!({"group": "xy", "start": {"x": 200.0, "y": 0.0}, "entries": worked_arcs("counter_clockwise")}),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let a = &r.json;
    let quarter = std::f64::consts::PI * 100.0 / 2.0;
    assert!(
        (a["length"].as_f64().unwrap() - 2.0 * quarter).abs() < 1e-6,
        "{}",
        a["length"]
    );
    assert_eq!(a["truncated"], false);
    assert_eq!(a["group"], "xy");
    assert_eq!(a["start"], json!({"x": 200.0, "y": 0.0}));
    let t = a["t"].as_array().unwrap();
    assert!(t.len() > 100 && t.len() <= 2000, "{}", t.len());
    for column in [
        "path_position",
        "path_velocity",
        "path_acceleration",
        "entry",
        "in_blend",
    ] {
        assert_eq!(a[column].as_array().unwrap().len(), t.len(), "{column}");
    }
    assert!(near(t.last().unwrap(), a["duration"].as_f64().unwrap()));
    assert_eq!(a["entry"][0], 0);
    assert_eq!(a["entry"][t.len() - 1], 1, "the last entry at the end");
    let axes = a["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 2);
    assert_eq!(
        (&axes[0]["role"], &axes[0]["axis"]),
        (&json!("x"), &json!("x"))
    );
    assert_eq!(
        (&axes[1]["role"], &axes[1]["axis"]),
        (&json!("y"), &json!("y"))
    );
    assert!(near(
        axes[0]["position"].as_array().unwrap().last().unwrap(),
        400.0
    ));
    assert!(near(
        axes[1]["position"].as_array().unwrap().last().unwrap(),
        -200.0
    ));
    // Halfway along N20 (45°): x = 200 + 100·sin 45°, y = −100 + 100·cos 45°, turning clockwise
    // seen from +Z (the manual's normal is −Z).
    let i = a["path_position"]
        .as_array()
        .unwrap()
        .iter()
        .position(|p| p.as_f64().unwrap() >= quarter / 2.0)
        .unwrap();
    let (x, y) = (
        axes[0]["position"][i].as_f64().unwrap(),
        axes[1]["position"][i].as_f64().unwrap(),
    );
    let h = 100.0 * std::f64::consts::FRAC_1_SQRT_2;
    assert!(
        (x - 200.0 - h).abs() < 2.0 && (y + 100.0 - h).abs() < 2.0,
        "({x}, {y})"
    );
    // Every axis within its limits (the demo's 500 mm/s, 2500 mm/s²).
    for ax in axes {
        assert!(
            ax["max_velocity"].as_f64().unwrap() <= 500.0 * (1.0 + 1e-9),
            "{ax}"
        );
        assert!(
            ax["max_acceleration"].as_f64().unwrap() <= 2500.0 * (1.0 + 1e-9),
            "{ax}"
        );
        assert_eq!(ax["velocity"].as_array().unwrap().len(), t.len());
    }
    // Clockwise on N20 (the manual's code line) is the long way round: 270° + 90°.
    let r = post(
        &s,
        "/api/v1/path-analysis",
        json!({"group": "xy", "start": {"x": 200.0, "y": 0.0}, "entries": worked_arcs("clockwise"), "max_samples": 50}),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert!((r.json["length"].as_f64().unwrap() - 4.0 * quarter).abs() < 1e-6);
    assert!(r.json["t"].as_array().unwrap().len() <= 50);

    // The tour from where the group stands (0, 0): its corners blended, a little shorter than
    // programmed; a run longer than asked for is truncated.
    let r = post(
        &s,
        "/api/v1/path-analysis",
        json!({"group": "1", "entries": tour_path()["entries"]}),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["start"], json!({"x": 0.0, "y": 0.0}));
    let programmed = 100.0 + std::f64::consts::PI * 50.0 / 2.0 + 100.0 + 150.0;
    let length = r.json["length"].as_f64().unwrap();
    assert!(
        length < programmed - 0.1 && length > programmed - 10.0,
        "{length}"
    );
    assert!(
        r.json["in_blend"]
            .as_array()
            .unwrap()
            .iter()
            .any(|b| b == true)
    );
    let r = post(
        &s,
        "/api/v1/path-analysis",
        json!({"group": "xy", "entries": tour_path()["entries"], "max_seconds": 0.5}),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["truncated"], true);
    let d = r.json["duration"].as_f64().unwrap();
    assert!((0.5..0.51).contains(&d), "{d}");

    // Refusals name the entry and field with the rule's code, as move-path's do.
    let mut bad = worked_arcs("counter_clockwise");
    // (N20 ends at (300, −100): three points on a line are no arc)
    bad[1] = json!({"type": "circular", "circ_mode": "border", "aux_point": [350.0, -100.0, 0.0],
        "end_point": [400.0, -100.0], "velocity": 100.0, "buffer_mode": "buffered"});
    let r = post(
        &s,
        "/api/v1/path-analysis",
        json!({"group": "xy", "start": {"x": 200.0, "y": 0.0}, "entries": bad}),
    )
    .await;
    assert_problem(&r, 422, "circle_invalid");
    assert_eq!(
        r.json["errors"][0]["field"], "entries[1].aux_point",
        "{}",
        r.text
    );
    let mut bad = worked_arcs("counter_clockwise");
    bad[1]["buffer_mode"] = json!("aborting");
    let r = post(
        &s,
        "/api/v1/path-analysis",
        json!({"group": "xy", "entries": bad}),
    )
    .await;
    assert_problem(&r, 422, "buffer_mode_invalid");
    assert_eq!(
        r.json["errors"][0]["field"], "entries[1].buffer_mode",
        "{}",
        r.text
    );
    // x's soft limits are 0…1000: a path to x = −50 is refused at its entry (a preview names
    // the row where move-path answers 409).
    let line = |x: f64| json!({"type": "linear", "position": [x, 0.0], "velocity": 100.0, "buffer_mode": "buffered"});
    let r = post(
        &s,
        "/api/v1/path-analysis",
        json!({"group": "xy", "entries": [line(50.0), line(-50.0)]}),
    )
    .await;
    assert_problem(&r, 422, "path_beyond_soft_limit");
    assert_eq!(
        r.json["errors"][0]["field"], "entries[1].position",
        "{}",
        r.text
    );
    for (body, field) in [
        (json!({"group": "gantry", "entries": [line(1.0)]}), "group"),
        (
            json!({"group": "xy", "start": {"z": 1.0}, "entries": [line(1.0)]}),
            "start.z",
        ),
        (
            json!({"group": "xy", "entries": [line(1.0)], "max_samples": 1}),
            "max_samples",
        ),
        (
            json!({"group": "xy", "entries": [line(1.0)], "max_seconds": 0.0}),
            "max_seconds",
        ),
        (json!({"group": "xy", "entries": []}), "entries"),
    ] {
        let r = post(&s, "/api/v1/path-analysis", body).await;
        assert_eq!(r.status, 422, "{}", r.text);
        assert_eq!(r.json["errors"][0]["field"], field, "{}", r.text);
    }

    // Nothing stored, nothing moved: the group's status and the command list as they were.
    let after = group_status(&s).await;
    for k in [
        "state",
        "position",
        "queued_entries",
        "path_position",
        "command",
    ] {
        assert_eq!(after[k], before[k], "{k}");
    }
    assert_eq!(
        get(&s, "/api/v1/commands?limit=2000").await.json,
        commands_before
    );
}
