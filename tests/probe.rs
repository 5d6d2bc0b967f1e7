//! MC_TouchProbe / MC_AbortTrigger over HTTP with the simulated drive's probe input: a mark on
//! the load (`probe_mark`) or the input forced (`probe_input`), the recorded position in the
//! command's `result` and the axis status.

mod common;

use common::*;
use serde_json::json;

/// The probe command once its result is there (read from the status of the cycle that
/// recorded it).
async fn with_result(s: &Server, id: u64) -> serde_json::Value {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    loop {
        let c = get(s, &format!("/api/v1/commands/{id}")).await.json;
        if c["result"].is_object() {
            return c;
        }
        assert!(std::time::Instant::now() < deadline, "no result: {c}");
        tokio::time::sleep(std::time::Duration::from_millis(20)).await;
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn a_touch_probe_records_where_the_load_passed_the_mark() {
    let s = Server::start();
    power_on(&s, "x").await;
    let r = post(
        &s,
        "/api/v1/axes/x/simulation/fault",
        json!({"kind": "probe_mark", "position": 123.456}),
    )
    .await;
    assert_eq!(r.status, 204, "{}", r.text);
    let p = post(
        &s,
        "/api/v1/axes/x/touch-probe",
        json!({"signal": "input1", "edge": "rising", "window_only": true, "first_position": 100.0, "last_position": 150.0}),
    )
    .await;
    assert_eq!(p.status, 202, "{}", p.text);
    assert_eq!(p.json["state"], "busy", "{}", p.text);
    let id = p.json["id"].as_u64().unwrap();
    assert_eq!(status(&s, "x").await["status"]["probe"]["armed"], true);
    // A second probe cycle while one runs is refused.
    let r = post(&s, "/api/v1/axes/x/touch-probe", json!({})).await;
    assert_problem(&r, 409, "touch_probe_busy");
    let m = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true&timeout_ms=20000",
        json!({"position": 200.0, "velocity": 300.0}),
    )
    .await;
    assert_eq!(m.json["state"], "done", "{}", m.text);
    let fin = until_final(&s, id, 10).await;
    assert_eq!(fin["state"], "done", "{fin}");
    // The result is read from the status of the cycle that recorded it.
    let fin = with_result(&s, id).await;
    assert_eq!(fin["result"]["recorded_position"], 123.456, "{fin}");
    assert_eq!(fin["result"]["counter"], 1);
    let st = status(&s, "x").await;
    assert_eq!(st["status"]["probe"]["recorded_position"], 123.456, "{st}");
    assert_eq!(st["status"]["probe"]["command"], id);
    assert_eq!(st["status"]["probe"]["armed"], false);
    s.stop();
}

#[tokio::test(flavor = "multi_thread")]
async fn a_forced_input_edge_latches_where_the_axis_stands_and_abort_trigger_cancels() {
    let s = Server::start();
    power_on(&s, "y").await;
    let p = post(&s, "/api/v1/axes/y/touch-probe", json!({"edge": "falling"})).await;
    let id = p.json["id"].as_u64().unwrap();
    // Rising first (not the wanted edge), then falling: recorded at the standing position 0.
    for active in [true, false] {
        let r = post(
            &s,
            "/api/v1/axes/y/simulation/fault",
            json!({"kind": "probe_input", "active": active}),
        )
        .await;
        assert_eq!(r.status, 204, "{}", r.text);
    }
    let fin = until_final(&s, id, 10).await;
    assert_eq!(fin["state"], "done", "{fin}");
    // Cancelled before the trigger: CommandAborted, and the abort itself is done.
    let p = post(
        &s,
        "/api/v1/axes/y/touch-probe",
        json!({"signal": "reference_cam"}),
    )
    .await;
    let id = p.json["id"].as_u64().unwrap();
    let a = post(&s, "/api/v1/axes/y/abort-trigger?wait=true", json!({})).await;
    assert_eq!(a.json["state"], "done", "{}", a.text);
    let fin = until_final(&s, id, 10).await;
    assert_eq!(fin["state"], "aborted", "{fin}");
    // The index pulse has no falling edge to latch.
    let r = post(
        &s,
        "/api/v1/axes/y/touch-probe",
        json!({"signal": "index_pulse", "edge": "falling"}),
    )
    .await;
    assert_eq!(r.field_error(), (422, Some("edge")));
    s.stop();
}

/// MC_CalcDynamicsByRampTime (§4.5.3) as a function endpoint: the manual's 50 % example gives
/// t1 = t2 = t/3; stiffness 1 is refused with 0x4B06.
#[tokio::test(flavor = "multi_thread")]
async fn calc_dynamics_by_ramp_time_gives_the_ramp_of_the_manual() {
    let s = Server::start();
    let r = get(
        &s,
        "/api/v1/functions/calc-dynamics-by-ramp-time?velocity=300&ramp_time=0.3&stiffness=0.5",
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let t1 = r.json["jerk_time"].as_f64().unwrap();
    assert!((t1 - 0.1).abs() < 1e-12, "{}", r.text);
    let a = r.json["acceleration"].as_f64().unwrap();
    assert!((a - 1500.0).abs() < 1e-9, "{}", r.text);
    assert_eq!(r.json["deceleration"], r.json["acceleration"]);
    let r = get(
        &s,
        "/api/v1/functions/calc-dynamics-by-ramp-time?velocity=300&ramp_time=0.3&stiffness=1",
    )
    .await;
    assert_problem(&r, 422, "validation_failed");
    assert_eq!(r.json["error_id"], 0x4B06);
    assert_eq!(r.json["errors"][0]["field"], "stiffness");
    s.stop();
}

/// A mark is given where the axis reads it: after homing moved the reference (the README's
/// order: home, then probe), the probe records the mark at the position given, not at the
/// drive's raw coordinate of it (issue 28, defect 1).
#[tokio::test(flavor = "multi_thread")]
async fn a_mark_after_homing_is_recorded_where_it_was_given() {
    let s = Server::start();
    power_on(&s, "x").await;
    let h = post(
        &s,
        "/api/v1/axes/x/home?wait=true&timeout_ms=20000",
        json!({}),
    )
    .await;
    assert_eq!(h.json["state"], "done", "{}", h.text);
    let st = status(&s, "x").await;
    assert_eq!(st["status"]["homed"], true, "{st}");
    let r = post(
        &s,
        "/api/v1/axes/x/simulation/fault",
        json!({"kind": "probe_mark", "position": 123.456}),
    )
    .await;
    assert_eq!(r.status, 204, "{}", r.text);
    let p = post(
        &s,
        "/api/v1/axes/x/touch-probe",
        json!({"signal": "input1", "edge": "rising"}),
    )
    .await;
    assert_eq!(p.status, 202, "{}", p.text);
    let id = p.json["id"].as_u64().unwrap();
    let m = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true&timeout_ms=20000",
        json!({"position": 200.0, "velocity": 300.0}),
    )
    .await;
    assert_eq!(m.json["state"], "done", "{}", m.text);
    let fin = until_final(&s, id, 10).await;
    assert_eq!(fin["state"], "done", "the probe saw the mark: {fin}");
    let fin = with_result(&s, id).await;
    let recorded = fin["result"]["recorded_position"].as_f64().unwrap();
    assert!((recorded - 123.456).abs() < 1e-6, "{fin}");
    s.stop();
}
