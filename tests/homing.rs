//! The demo machine homes (cam 20–25 mm, index pulse every 10 mm), and a homing search that
//! misses the cam ends on a hardware limit switch in ErrorStop with homing_failed instead of
//! running on.

mod common;

use common::*;
use serde_json::json;

const HOMING_FAILED: u64 = 0x7030;
const LIMIT_SWITCH: u64 = 0x7012;

#[tokio::test(flavor = "multi_thread")]
async fn the_demo_x_homes_from_its_start_position() {
    let s = Server::start();
    let x = get(&s, "/api/v1/axes/x").await;
    assert_eq!(
        x.json["config"]["drive"]["limit_switches"],
        json!({"negative": -5.0, "positive": 1005.0, "fault_on_hit": false})
    );
    power_on(&s, "x").await;
    // The README's command.
    let r = post(
        &s,
        "/api/v1/axes/x/home?wait=true&timeout_ms=20000",
        json!({}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["state"], "done", "{}", r.text);
    let st = status(&s, "x").await["status"].clone();
    assert_eq!(st["homed"], true, "{st}");
    assert_eq!(st["state"], "standstill", "{st}");
    // The reference (calibration value 0) is set at the index pulse; the stop after it
    // overshoots by a fraction of a millimetre.
    let p = st["set_position"].as_f64().unwrap();
    assert!(p.abs() < 1.0, "{st}");
    // Homed, x moves as before.
    let m = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true&timeout_ms=20000",
        json!({"position": 100.0, "velocity": 300.0}),
    )
    .await;
    assert_eq!(m.json["state"], "done", "{}", m.text);
}

#[tokio::test(flavor = "multi_thread")]
async fn a_homing_search_past_the_cam_fails_at_the_limit_switch_which_then_blocks_motion_into_it() {
    let s = Server::start();
    power_on(&s, "y").await;
    let m = post(
        &s,
        "/api/v1/axes/y/move-absolute?wait=true&timeout_ms=20000",
        json!({"position": 600.0, "velocity": 500.0}),
    )
    .await;
    assert_eq!(m.json["state"], "done", "{}", m.text);
    // The cam (20–25) is behind; the search runs forward into the switch at 1005.
    let r = post(
        &s,
        "/api/v1/axes/y/home?wait=true&timeout_ms=20000",
        json!({"options": {"search_velocity": 300.0}}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["state"], "error", "{}", r.text);
    assert_eq!(r.json["error_code"], "homing_failed", "{}", r.text);
    assert_eq!(r.json["outputs"]["error_id"].as_u64(), Some(HOMING_FAILED));
    // On the switch (an end of travel): ErrorStop with why homing failed, until a reset.
    let st = until(&s, "y", "error_stop").await;
    assert_eq!(st["homed"], false, "{st}");
    assert_eq!(st["error_id"].as_u64(), Some(HOMING_FAILED), "{st}");
    assert!(st["actual_position"].as_f64().unwrap() >= 1005.0, "{st}");
    let r = post(&s, "/api/v1/axes/y/reset?wait=true", json!({})).await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
    until(&s, "y", "standstill").await;
    // On the switch: no motion further into it, motion away from it is fine.
    let r = post(
        &s,
        "/api/v1/axes/y/move-velocity",
        json!({"velocity": 50.0}),
    )
    .await;
    assert_problem(&r, 409, "limit_switch");
    assert_eq!(r.json["error_id"].as_u64(), Some(LIMIT_SWITCH));
    let r = post(
        &s,
        "/api/v1/axes/y/move-relative?wait=true&timeout_ms=20000",
        json!({"distance": -100.0, "velocity": 200.0}),
    )
    .await;
    assert_eq!(r.json["state"], "done", "{}", r.text);
}

/// Polls the status until the axis is in `state` and at rest (at most 10 s).
async fn until(s: &Server, axis: &str, state: &str) -> serde_json::Value {
    for _ in 0..500 {
        let st = status(s, axis).await["status"].clone();
        if st["state"] == state && st["moving"] == false {
            return st;
        }
        tokio::time::sleep(std::time::Duration::from_millis(20)).await;
    }
    panic!("{axis} did not come to rest in {state}");
}
