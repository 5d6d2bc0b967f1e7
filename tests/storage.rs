//! A full disk (issue "Security and reliability"): motiond runs with its files limited in size
//! (RLIMIT_FSIZE, SIGXFSZ ignored, so that writes fail with EFBIG as on a full disk). No write
//! may be acknowledged that is not there after a restart, and API, kernel and database agree
//! after the failure.

mod common;

use std::process::Command;

use common::*;
use serde_json::json;

#[tokio::test(flavor = "multi_thread")]
async fn after_a_failed_commit_no_write_is_acknowledged_that_is_lost() {
    let dir = temp_dir();
    let db = dir.join("full.db");
    let db = db.to_str().unwrap();
    // The demo machine needs about 200 KB; the limit is reached after some dozens of writes.
    let s = start_in_sh(db, r#"ulimit -f 1400; trap "" XFSZ; exec "$0" "$@""#);
    let path = "/api/v1/axes/x/parameters/AxisVeloMax";
    let mut last_ok = None;
    let mut first_failure = None;
    for i in 0..400 {
        let v = 500.0 + i as f64;
        let r = put(&s, path, json!({"value": v, "persistent": true})).await;
        match r.status {
            // A write may succeed again after a failure (SQLite reuses WAL space it already
            // has); what is acknowledged must be there after the restart.
            200 => last_ok = Some(v),
            503 => {
                assert_eq!(r.json["code"], "storage_unavailable", "{}", r.text);
                first_failure.get_or_insert(i);
                // Not stored, not in force: the API shows the last acknowledged value.
                let p = get(&s, path).await;
                assert_eq!(p.json["value"].as_f64(), last_ok, "{}", p.text);
            }
            other => panic!("write {i}: {other} {}", r.text),
        }
        if first_failure.is_some_and(|f| i > f + 20) {
            break;
        }
    }
    let failed_at = first_failure.expect("the size limit was reached");
    let last_ok = last_ok.expect("some writes were stored first");
    // Other writes: acknowledged only if stored.
    let table =
        json!({"name": "t", "table_type": "non_equidistant", "rows": [[0.0, 0.0], [1.0, 1.0]]});
    let created = post(&s, "/api/v1/cam-tables", table.clone()).await.status;
    assert!(created == 201 || created == 503, "{created}");
    s.stop();

    let s = Server::start_with(db, &[]);
    let p = get(&s, path).await;
    assert_eq!(
        p.json["value"].as_f64(),
        Some(last_ok),
        "after {failed_at} writes: {}",
        p.text
    );
    let tables = get(&s, "/api/v1/cam-tables")
        .await
        .json
        .as_array()
        .unwrap()
        .len();
    assert_eq!(
        tables,
        usize::from(created == 201),
        "the table is there exactly if it was acknowledged"
    );
    // With room again, writes are stored.
    assert_eq!(
        put(&s, path, json!({"value": 777.0, "persistent": true}))
            .await
            .status,
        200
    );
    s.stop();
    let s = Server::start_with(db, &[]);
    assert_eq!(get(&s, path).await.json["value"].as_f64(), Some(777.0));
}

/// Starts motiond on `db` with SIGXFSZ ignored (a write beyond the file size limit fails with
/// EFBIG, as on a full disk, instead of killing the process).
fn start_ignoring_xfsz(db: &str) -> Server {
    start_in_sh(db, r#"trap "" XFSZ; exec "$0" "$@""#)
}

/// Starts motiond on `db` through `sh -c script` (which ends with `exec "$0" "$@"`).
fn start_in_sh(db: &str, script: &str) -> Server {
    let mut cmd = Command::new("sh");
    cmd.args([
        "-c",
        script,
        env!("CARGO_BIN_EXE_motiond"),
        "serve",
        "--listen",
        "127.0.0.1:0",
        "--db",
        db,
    ]);
    Server::spawn(cmd)
}

/// The disk is full from now on for the running motiond: its file size limit drops to 0, so
/// that every write of the database fails — appends and rewrites of pages it has alike
/// (util-linux `prlimit` on the running process). `false` when it cannot be done here.
fn fill_the_disk(s: &Server) -> bool {
    let pid = s.child.id().to_string();
    match Command::new("prlimit")
        .args(["--pid", &pid, "--fsize=0:0"])
        .output()
    {
        Ok(o) if o.status.success() => true,
        Ok(o) => {
            cannot_run(
                "storage::a_stop_acts_on_a_full_disk_past_the_reserved_ids",
                &format!("prlimit: {}", String::from_utf8_lossy(&o.stderr)),
            );
            false
        }
        Err(e) => {
            cannot_run(
                "storage::a_stop_acts_on_a_full_disk_past_the_reserved_ids",
                &format!("prlimit (util-linux): {e}"),
            );
            false
        }
    }
}

/// A stop is never refused (decision 116): with the disk full and the block of reserved command
/// ids used up, motion commands are 503 `storage_unavailable` — and stop, halt and power-off
/// still act, also as the first commands after a start on the full disk.
#[tokio::test(flavor = "multi_thread")]
async fn a_stop_acts_on_a_full_disk_past_the_reserved_ids() {
    let dir = temp_dir();
    let db = dir.join("full.db");
    let db = db.to_str().unwrap();
    let s = start_ignoring_xfsz(db);
    power_on(&s, "spindle").await;
    let m = post(
        &s,
        "/api/v1/axes/spindle/move-velocity",
        json!({"velocity": 100.0}),
    )
    .await;
    assert_eq!(m.status, 202, "{}", m.text);
    if !fill_the_disk(&s) {
        return;
    }
    let r = put(
        &s,
        "/api/v1/axes/x/parameters/AxisVeloMax",
        json!({"value": 700.0, "persistent": true}),
    )
    .await;
    assert_problem(&r, 503, "storage_unavailable");
    // Use up the block of reserved ids: commands that the axis refuses (y is disabled) take an
    // id each without moving anything. Eight at a time; the first 503 is the end of the block.
    let client = reqwest::Client::new();
    let url = s.url("/api/v1/axes/y/move-relative");
    let mut refused = None;
    'outer: for round in 0..2000 {
        let mut tasks = Vec::new();
        for _ in 0..8 {
            let (client, url) = (client.clone(), url.clone());
            tasks.push(tokio::spawn(async move {
                resp_of(
                    client
                        .post(url)
                        .json(&json!({"distance": 1.0, "velocity": 1.0}))
                        .send()
                        .await
                        .unwrap(),
                )
                .await
            }));
        }
        for t in tasks {
            let r = t.await.unwrap();
            match r.status {
                409 => {}
                503 => {
                    refused = Some((round, r));
                    break 'outer;
                }
                other => panic!("{other} {}", r.text),
            }
        }
    }
    let (round, r) = refused.expect("the reserved ids were used up");
    assert_eq!(r.json["code"], "storage_unavailable", "{}", r.text);
    assert!(round > 100, "the block lasted {round} rounds only");
    // The spindle still turns; a move is refused, the stop acts.
    let st = status(&s, "spindle").await["status"].clone();
    assert!(st["actual_velocity"].as_f64().unwrap() > 50.0, "{st}");
    let r = post(
        &s,
        "/api/v1/axes/spindle/move-velocity",
        json!({"velocity": 50.0}),
    )
    .await;
    assert_problem(&r, 503, "storage_unavailable");
    let r = post(
        &s,
        "/api/v1/axes/spindle/stop?wait=true&timeout_ms=20000",
        json!({}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["state"], "done", "{}", r.text);
    let st = status(&s, "spindle").await["status"].clone();
    assert_eq!(st["set_velocity"].as_f64(), Some(0.0), "{st}");
    assert_eq!(st["state"], "stopping", "{st}");
    // Halt and power-off act too.
    let r = post(&s, "/api/v1/axes/spindle/halt", json!({})).await;
    assert_ne!(r.status, 503, "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/spindle/power?wait=true",
        json!({"enable": false}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(status(&s, "spindle").await["status"]["state"], "disabled");
    // The audit rows that could not be stored are counted.
    let m = reqwest::get(s.url("/metrics"))
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    assert!(
        m.lines()
            .any(|l| l.starts_with("motiond_audit_dropped") && !l.ends_with(" 0")),
        "{m}"
    );
    s.stop();

    // The first commands after a start on the full disk: no id can be reserved.
    let s = start_ignoring_xfsz(db);
    assert!(fill_the_disk(&s));
    let r = post(&s, "/api/v1/axes/x/power", json!({})).await;
    assert_problem(&r, 503, "storage_unavailable");
    // x stands disabled: the stop reaches the axis (which refuses it in that state), not 503.
    let r = post(&s, "/api/v1/axes/x/stop", json!({})).await;
    assert_problem(&r, 409, "axis_cannot_be_started");
    let r = post(&s, "/api/v1/axes/x/power", json!({"enable": false})).await;
    assert_eq!(r.status, 202, "{}", r.text);
    s.stop();
}
