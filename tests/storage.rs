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
    let mut cmd = Command::new("sh");
    cmd.args([
        "-c",
        r#"ulimit -f 1400; trap "" XFSZ; exec "$0" "$@""#,
        env!("CARGO_BIN_EXE_motiond"),
        "serve",
        "--listen",
        "127.0.0.1:0",
        "--db",
        db,
    ]);
    let s = Server::spawn(cmd);
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
