//! Scope recordings over HTTP against the real binary (issue 4, "Scope").

mod common;

use std::time::Duration;

use common::*;
use serde_json::{Value, json};

const RECORDINGS: &str = "/api/v1/scope/recordings";

/// Polls a recording until it is no longer armed or recording.
async fn until_final(s: &Server, id: u64) -> Value {
    let deadline = std::time::Instant::now() + Duration::from_secs(20);
    loop {
        let r = get(s, &format!("{RECORDINGS}/{id}")).await;
        assert_eq!(r.status, 200, "{}", r.text);
        let state = r.json["state"].as_str().unwrap().to_string();
        if state != "armed" && state != "recording" {
            return r.json;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "recording {id} not final: {}",
            r.text
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[tokio::test(flavor = "multi_thread")]
async fn a_recording_of_a_move_has_one_sample_per_cycle_from_start_to_target() {
    let s = Server::start();
    power_on(&s, "x").await;
    let cycle = get(&s, "/api/v1/system").await.json["cycle_time"]
        .as_f64()
        .unwrap();
    let start = status(&s, "x").await["status"]["set_position"]
        .as_f64()
        .unwrap();
    let x_id = get(&s, "/api/v1/axes/x").await.json["id"].as_i64().unwrap();
    // The axis by name and by id.
    let r = post(
        &s,
        RECORDINGS,
        json!({"channels": [{"axis": "x", "signal": "set_position"},
                            {"axis": x_id, "signal": "set_velocity"}],
               "duration_s": 0.5, "trigger": null}),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let id = r.json["id"].as_u64().unwrap();
    assert_eq!(r.location.as_deref(), Some(&*format!("{RECORDINGS}/{id}")));
    assert_eq!(r.json["state"], "recording");
    assert_eq!(r.json["cycle_time_s"].as_f64(), Some(cycle));
    let samples = (0.5 / cycle).round() as usize;
    assert_eq!(r.json["samples"].as_u64(), Some(samples as u64));
    assert!(r.json["start_cycle"].as_u64().unwrap() > 0);
    assert_eq!(r.json["trigger_cycle"], Value::Null);
    assert!(r.json["created_at"].is_string());
    assert!(r.json.get("data").is_none());
    assert_eq!(
        r.json["channels"],
        json!([{"axis": "x", "axis_id": x_id, "signal": "set_position", "unit": "mm"},
               {"axis": "x", "axis_id": x_id, "signal": "set_velocity", "unit": "mm/s"}])
    );

    // 30 mm at 200 mm/s with the demo's dynamics takes ≈ 0.33 s: it fits in the window.
    let target = start + 30.0;
    let m = post(
        &s,
        "/api/v1/axes/x/move-absolute",
        json!({"position": target, "velocity": 200.0}),
    )
    .await;
    assert_eq!(m.status, 202, "{}", m.text);

    let rec = until_final(&s, id).await;
    assert_eq!(rec["state"], "done", "{rec}");
    assert_eq!(rec["samples_recorded"].as_u64(), Some(samples as u64));
    let t = floats(&rec["t"]);
    let data = rec["data"].as_array().unwrap();
    assert_eq!(data.len(), 2);
    let pos = floats(&data[0]);
    let vel = floats(&data[1]);
    assert_eq!(t.len(), samples);
    assert_eq!(pos.len(), samples);
    assert_eq!(vel.len(), samples);
    assert_eq!(t[0], 0.0);
    assert!((t[samples - 1] - (samples - 1) as f64 * cycle).abs() < 1e-12);
    assert!(t.windows(2).all(|w| (w[1] - w[0] - cycle).abs() < 1e-12));
    assert_eq!(pos[0], start, "first sample = start position");
    assert_eq!(pos[samples - 1], target, "last sample = target");
    assert!(
        vel.iter().all(|v| v.abs() <= 200.0 + 1e-9),
        "velocity above the commanded 200"
    );
    assert!(vel.iter().any(|v| *v > 100.0), "the move was not recorded");
    // The position never jumps by more than the velocity allows in a cycle.
    assert!(
        pos.windows(2)
            .all(|w| (w[1] - w[0]).abs() <= 200.0 * cycle + 1e-9)
    );

    // Listed, newest first, without data.
    let list = get(&s, RECORDINGS).await;
    assert_eq!(list.status, 200);
    assert_eq!(list.json[0]["id"].as_u64(), Some(id));
    assert!(list.json[0].get("data").is_none());
}

#[tokio::test(flavor = "multi_thread")]
async fn a_triggered_recording_puts_the_crossing_at_t_zero_after_its_pre_trigger_history() {
    let s = Server::start();
    power_on(&s, "x").await;
    let cycle = get(&s, "/api/v1/system").await.json["cycle_time"]
        .as_f64()
        .unwrap();
    let start = status(&s, "x").await["status"]["set_position"]
        .as_f64()
        .unwrap();
    let level = start + 10.0;
    let r = post(
        &s,
        RECORDINGS,
        json!({"channels": [{"axis": "x", "signal": "set_position"},
                            {"axis": "x", "signal": "following_error"}],
               "duration_s": 0.5,
               "trigger": {"channel": 0, "level": level, "edge": "rising", "pre_trigger_s": 0.1}}),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let id = r.json["id"].as_u64().unwrap();
    assert_eq!(r.json["state"], "armed");
    let pre = (0.1 / cycle).round() as usize;
    assert_eq!(r.json["pre_trigger_samples"].as_u64(), Some(pre as u64));
    // The trigger looks for crossings once the pre-trigger history is full: wait for the
    // cycles (not for time, which a loaded machine stretches).
    let armed_at = get(&s, "/api/v1/system").await.json["cycle"]
        .as_u64()
        .unwrap();
    let deadline = std::time::Instant::now() + Duration::from_secs(30);
    while get(&s, "/api/v1/system").await.json["cycle"]
        .as_u64()
        .unwrap()
        < armed_at + pre as u64 + 10
    {
        assert!(
            std::time::Instant::now() < deadline,
            "the cycle does not advance"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let armed = get(&s, &format!("{RECORDINGS}/{id}")).await;
    assert_eq!(armed.json["state"], "armed", "{}", armed.text);
    let m = post(
        &s,
        "/api/v1/axes/x/move-absolute",
        json!({"position": start + 30.0, "velocity": 200.0}),
    )
    .await;
    assert_eq!(m.status, 202, "{}", m.text);

    let rec = until_final(&s, id).await;
    assert_eq!(rec["state"], "done", "{rec}");
    let samples = (0.5 / cycle).round() as usize;
    let t = floats(&rec["t"]);
    let pos = floats(&rec["data"][0]);
    assert_eq!(t.len(), samples);
    assert_eq!(pos.len(), samples);
    assert_eq!(t[0], -0.1);
    assert_eq!(t[pre], 0.0);
    assert!(
        pos[pre] >= level && pos[pre - 1] < level,
        "t = 0 must be the first sample ≥ {level}: {} then {}",
        pos[pre - 1],
        pos[pre]
    );
    assert!(pos[..pre].iter().all(|p| *p < level));
    let trigger = rec["trigger_cycle"].as_u64().unwrap();
    assert_eq!(
        rec["start_cycle"].as_u64().unwrap(),
        trigger - pre as u64,
        "{rec}"
    );
    assert_eq!(rec["trigger"]["edge"], "rising");

    // CSV: header and one row per sample; by query and by Accept.
    let csv = get(&s, &format!("{RECORDINGS}/{id}?format=csv")).await;
    assert_eq!(csv.status, 200, "{}", csv.text);
    assert!(
        csv.content_type.starts_with("text/csv"),
        "{}",
        csv.content_type
    );
    let lines: Vec<&str> = csv.text.lines().collect();
    assert_eq!(lines[0], "t,x.set_position,x.following_error");
    assert_eq!(lines.len(), 1 + samples);
    let row: Vec<f64> = lines[1 + pre]
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(row[0], 0.0);
    assert_eq!(row[1], pos[pre]);
    let client = reqwest::Client::new();
    let by_accept = client
        .get(s.url(&format!("{RECORDINGS}/{id}")))
        .header("accept", "text/csv")
        .send()
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    assert_eq!(by_accept, csv.text);
}

#[tokio::test(flavor = "multi_thread")]
async fn invalid_recordings_are_422_naming_the_field() {
    let s = Server::start();
    let ch = |axis: &str, signal: &str| json!({"axis": axis, "signal": signal});
    let cases = [
        (json!({"channels": [], "duration_s": 1.0}), "channels"),
        (
            json!({"channels": vec![ch("x", "set_position"); 9], "duration_s": 1.0}),
            "channels",
        ),
        (
            json!({"channels": [ch("x", "set_position"), ch("x", "jerk")], "duration_s": 1.0}),
            "channels[1].signal",
        ),
        (
            json!({"channels": [ch("z", "set_position")], "duration_s": 1.0}),
            "channels[0].axis",
        ),
        (
            json!({"channels": [ch("x", "set_position")], "duration_s": 0.0}),
            "duration_s",
        ),
        (
            json!({"channels": [ch("x", "set_position")], "duration_s": -1.0}),
            "duration_s",
        ),
        (
            json!({"channels": [ch("x", "set_position")], "duration_s": 1e6}),
            "duration_s",
        ),
        (
            json!({"channels": [ch("x", "set_position")], "duration_s": 1.0,
                   "trigger": {"channel": 1, "level": 1.0}}),
            "trigger.channel",
        ),
        (
            json!({"channels": [ch("x", "set_position")], "duration_s": 1.0,
                   "trigger": {"channel": 0, "level": 1.0, "edge": "up"}}),
            "trigger.edge",
        ),
        (
            json!({"channels": [ch("x", "set_position")], "duration_s": 1.0,
                   "trigger": {"channel": 0, "level": 1.0, "pre_trigger_s": 1.5}}),
            "trigger.pre_trigger_s",
        ),
        (
            json!({"channels": [ch("x", "set_position")], "duration_s": 1.0,
                   "trigger": {"channel": 0, "level": 1.0, "pre_trigger_s": -0.1}}),
            "trigger.pre_trigger_s",
        ),
        (
            json!({"channels": [ch("x", "set_position")], "duration_s": 1.0, "rate": 2}),
            "rate",
        ),
        (json!({"duration_s": 1.0}), "channels"),
    ];
    for (body, field) in cases {
        let r = post(&s, RECORDINGS, body.clone()).await;
        assert_problem(&r, 422, "validation_failed");
        assert_eq!(r.json["errors"][0]["field"], field, "{body}: {}", r.text);
    }
    // Nothing was kept.
    assert_eq!(get(&s, RECORDINGS).await.json, json!([]));
    assert_problem(
        &get(&s, &format!("{RECORDINGS}/1?format=xml")).await,
        422,
        "validation_failed",
    );
    assert_problem(
        &get(&s, &format!("{RECORDINGS}/99")).await,
        404,
        "recording_not_found",
    );
}

#[tokio::test(flavor = "multi_thread")]
async fn delete_cancels_an_armed_recording_then_deletes_it() {
    let s = Server::start();
    let r = post(
        &s,
        RECORDINGS,
        json!({"channels": [{"axis": "y", "signal": "actual_velocity"}], "duration_s": 1.0,
               "trigger": {"channel": 0, "level": 1e9, "edge": "either", "pre_trigger_s": 0.5}}),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let id = r.json["id"].as_u64().unwrap();
    let url = format!("{RECORDINGS}/{id}");
    assert_problem(
        &get(&s, &format!("{url}?format=csv")).await,
        409,
        "recording_not_done",
    );
    let d = delete(&s, &url).await;
    assert_eq!(d.status, 200, "{}", d.text);
    assert_eq!(d.json["state"], "cancelled");
    let g = get(&s, &url).await;
    assert_eq!(g.json["state"], "cancelled");
    assert!(g.json.get("data").is_none());
    let d = delete(&s, &url).await;
    assert_eq!(d.status, 204, "{}", d.text);
    assert_problem(&get(&s, &url).await, 404, "recording_not_found");
    assert_problem(&delete(&s, &url).await, 404, "recording_not_found");
    assert_eq!(get(&s, RECORDINGS).await.json, json!([]));
}

#[tokio::test(flavor = "multi_thread")]
async fn at_most_eight_signals_are_sampled_at_once() {
    let s = Server::start();
    let all = [
        "set_position",
        "actual_position",
        "set_velocity",
        "actual_velocity",
        "set_acceleration",
        "following_error",
    ];
    let armed = |channels: Vec<Value>| {
        json!({"channels": channels, "duration_s": 1.0,
               "trigger": {"channel": 0, "level": 1e9}})
    };
    let six: Vec<Value> = all
        .iter()
        .map(|sig| json!({"axis": "x", "signal": sig}))
        .collect();
    let a = post(&s, RECORDINGS, armed(six.clone())).await;
    assert_eq!(a.status, 201, "{}", a.text);
    // The same signals again are shared; two more fit, a third does not.
    assert_eq!(post(&s, RECORDINGS, armed(six)).await.status, 201);
    let two: Vec<Value> = all[..2]
        .iter()
        .map(|sig| json!({"axis": "y", "signal": sig}))
        .collect();
    assert_eq!(post(&s, RECORDINGS, armed(two)).await.status, 201);
    let r = post(
        &s,
        RECORDINGS,
        armed(vec![json!({"axis": "spindle", "signal": "set_position"})]),
    )
    .await;
    assert_problem(&r, 409, "scope_channels_busy");
}

/// The actual acceleration is recorded too: the actual velocity differentiated per cycle.
#[tokio::test(flavor = "multi_thread")]
async fn the_actual_acceleration_is_the_recorded_actual_velocity_differentiated() {
    let s = Server::start();
    power_on(&s, "x").await;
    let cycle = get(&s, "/api/v1/system").await.json["cycle_time"]
        .as_f64()
        .unwrap();
    let r = post(
        &s,
        RECORDINGS,
        json!({"channels": [{"axis": "x", "signal": "actual_velocity"},
                            {"axis": "x", "signal": "actual_acceleration"}],
               "duration_s": 0.4}),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["channels"][1]["unit"], "mm/s²", "{}", r.text);
    let id = r.json["id"].as_u64().unwrap();
    let m = post(
        &s,
        "/api/v1/axes/x/move-relative",
        json!({"distance": 40.0, "velocity": 300.0}),
    )
    .await;
    assert_eq!(m.status, 202, "{}", m.text);
    let rec = until_final(&s, id).await;
    assert_eq!(rec["state"], "done", "{rec}");
    let v = floats(&rec["data"][0]);
    let a = floats(&rec["data"][1]);
    for k in 1..v.len() {
        let expected = (v[k] - v[k - 1]) / cycle;
        assert!(
            (a[k] - expected).abs() < 1e-6,
            "sample {k}: {} vs {expected}",
            a[k]
        );
    }
    assert!(
        a.iter().any(|x| *x > 500.0),
        "the move's acceleration was recorded"
    );
}

/// Saved scope setups: stored by name across restarts, checked as a recording request is,
/// audited.
#[tokio::test(flavor = "multi_thread")]
async fn scope_setups_are_saved_by_name_and_survive_a_restart() {
    let dir = temp_dir();
    let db = dir.join("m.db");
    let db = db.to_str().unwrap();
    let s = Server::start_with(db, &[]);
    let setup = json!({
        "recording": {"channels": [{"axis": "x", "signal": "set_velocity"}, {"axis": "x", "signal": "following_error"}],
                      "duration_s": 2.0, "trigger": {"channel": 0, "level": 10.0, "edge": "rising", "pre_trigger_s": 0.2}},
        "view": {"charts": [[0], [1]], "rolling": false}
    });
    let r = put(&s, "/api/v1/scope/setups/x-velocity-loop", setup.clone()).await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["view"]["charts"], json!([[0], [1]]));
    let mut changed = setup.clone();
    changed["recording"]["duration_s"] = json!(3.0);
    let r = put(&s, "/api/v1/scope/setups/x-velocity-loop", changed).await;
    assert_eq!(r.status, 200, "{}", r.text);
    let mut bad = setup.clone();
    bad["recording"]["channels"][0]["axis"] = json!("z");
    let r = put(&s, "/api/v1/scope/setups/other", bad).await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(
        r.json["errors"][0]["field"], "recording.channels[0].axis",
        "{}",
        r.text
    );
    let r = put(&s, "/api/v1/scope/setups/1bad", setup.clone()).await;
    assert_problem(&r, 422, "validation_failed");
    s.stop();

    let s = Server::start_with(db, &[]);
    let list = get(&s, "/api/v1/scope/setups").await;
    assert_eq!(list.json.as_array().unwrap().len(), 1, "{}", list.text);
    let r = get(&s, "/api/v1/scope/setups/x-velocity-loop").await;
    assert_eq!(r.json["recording"]["duration_s"], 3.0, "{}", r.text);
    // What it records can be started as it is.
    let rec = post(&s, "/api/v1/scope/recordings", r.json["recording"].clone()).await;
    assert_eq!(rec.status, 201, "{}", rec.text);
    assert_eq!(
        delete(&s, "/api/v1/scope/setups/x-velocity-loop")
            .await
            .status,
        204
    );
    assert_problem(
        &get(&s, "/api/v1/scope/setups/x-velocity-loop").await,
        404,
        "scope_setup_not_found",
    );
    let audit = get(&s, "/api/v1/audit?limit=10").await;
    let actions: Vec<_> = audit
        .json
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["action"].clone())
        .collect();
    assert!(
        actions.contains(&json!("scope_setup.put"))
            && actions.contains(&json!("scope_setup.delete")),
        "{actions:?}"
    );
    s.stop();
}

/// A group's signals (TF5420 §9: path velocity, path position, entry index) beside an axis's:
/// a recording triggered by the group's path velocity holds the path from rest to rest, its
/// velocity within the commanded one, the entry index counting through the table; a group
/// signal on an axis (and the other way round) is a 422 naming the field.
#[tokio::test(flavor = "multi_thread")]
async fn a_group_s_path_signals_are_recorded_beside_its_axes() {
    let s = Server::start();
    power_on(&s, "x").await;
    power_on(&s, "y").await;
    let r = post(&s, "/api/v1/groups/xy/enable?wait=true", json!({})).await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    let r = post(
        &s,
        RECORDINGS,
        json!({"channels": [{"axis": "x", "signal": "path_velocity"}], "duration_s": 0.5}),
    )
    .await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(
        r.json["errors"][0]["field"], "channels[0].signal",
        "{}",
        r.text
    );
    let r = post(
        &s,
        RECORDINGS,
        json!({"channels": [{"group": "xy", "signal": "set_position"}], "duration_s": 0.5}),
    )
    .await;
    assert_eq!(r.status, 422, "{}", r.text);
    let r = post(
        &s,
        RECORDINGS,
        json!({"channels": [{"group": "nope", "signal": "path_velocity"}], "duration_s": 0.5}),
    )
    .await;
    assert_eq!(
        r.json["errors"][0]["field"], "channels[0].group",
        "{}",
        r.text
    );

    let r = post(
        &s,
        RECORDINGS,
        json!({"channels": [{"group": "xy", "signal": "path_velocity"},
                            {"group": "xy", "signal": "path_position"},
                            {"group": "xy", "signal": "entry_index"},
                            {"axis": "y", "signal": "set_position"}],
               "duration_s": 2.0,
               "trigger": {"channel": 0, "level": 0.001, "edge": "rising", "pre_trigger_s": 0.01}}),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["channels"][0]["group"], "xy", "{}", r.text);
    assert_eq!(r.json["channels"][0]["unit"], "mm/s", "{}", r.text);
    assert!(r.json["channels"][0].get("axis").is_none(), "{}", r.text);
    let id = r.json["id"].as_u64().unwrap();
    let r = post(
        &s,
        "/api/v1/groups/xy/move-path?wait=true",
        json!({"entries": [
            {"type": "linear", "position": [50.0, 0.0], "velocity": 200.0},
            {"type": "linear", "position": [50.0, 50.0], "velocity": 200.0, "buffer_mode": "buffered"}]}),
    )
    .await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    let rec = until_final(&s, id).await;
    assert_eq!(rec["state"], "done", "{rec}");
    let v = floats(&rec["data"][0]);
    let pos = floats(&rec["data"][1]);
    let entry = floats(&rec["data"][2]);
    let y = floats(&rec["data"][3]);
    assert!(v.iter().all(|v| *v >= 0.0 && *v <= 200.0 + 1e-9), "{v:?}");
    assert!(v.iter().any(|v| *v > 100.0), "it ran");
    // 100 mm of path from rest to rest within the recording, never backwards (the path
    // position starts again at 0 once the group stands idle), the second entry after the
    // first.
    let end = pos.iter().cloned().fold(0.0, f64::max);
    assert!((end - 100.0).abs() < 1e-6, "{end}");
    let last = pos.iter().rposition(|p| *p == end).unwrap();
    assert!(
        pos[..=last].windows(2).all(|w| w[1] >= w[0] - 1e-9),
        "never backwards: {pos:?}"
    );
    assert!(entry.contains(&0.0) && entry.contains(&1.0), "{entry:?}");
    assert!((y.last().unwrap() - 50.0).abs() < 1e-6);
    // The CSV names the group's columns.
    let csv = get(&s, &format!("{RECORDINGS}/{id}?format=csv")).await;
    assert!(
        csv.text
            .starts_with("t,xy.path_velocity,xy.path_position,xy.entry_index,y.set_position"),
        "{}",
        csv.text
    );
}
