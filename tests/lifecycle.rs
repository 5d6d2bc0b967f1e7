//! The appliance's life across processes: options in either place on the command line, the
//! start-up log, and a configuration carried from one machine to a fresh one.

mod common;

use common::*;
use serde_json::json;

/// `motiond --opts serve` and `motiond serve --opts` mean the same; the log says where it
/// listens, which database, the cycle time and what real-time scheduling was granted.
#[tokio::test(flavor = "multi_thread")]
async fn options_before_serve_count_and_the_start_up_log_says_what_runs() {
    let mut cmd = bin();
    cmd.args([
        "--no-demo",
        "--cycle-us",
        "2000",
        "--db",
        ":memory:",
        "serve",
    ])
    .args(["--listen", "127.0.0.1:0"]);
    let s = Server::spawn(cmd);
    assert_eq!(get(&s, "/api/v1/axes").await.json, json!([]));
    assert_eq!(get(&s, "/api/v1/system").await.json["cycle_time"], 0.002);
    let log = s.log.lock().unwrap().join("\n");
    for expected in [
        "listening on http://127.0.0.1:",
        "database :memory: (in memory",
        "cycle thread: 2000 µs cycle; SCHED_FIFO",
    ] {
        assert!(log.contains(expected), "no «{expected}» in the log:\n{log}");
    }
    assert!(
        !log.contains("WAL"),
        "an in-memory database has no WAL:\n{log}"
    );
}

/// Export on one machine, import on a fresh one (another database): the same document comes
/// back, persistent parameters included, and it survives that machine's restart.
#[tokio::test(flavor = "multi_thread")]
async fn a_configuration_exported_from_one_machine_imports_into_a_fresh_one() {
    let a = Server::start();
    let r = put(
        &a,
        "/api/v1/axes/x/parameters/AxisVeloMax",
        json!({"value": 750.0, "persistent": true}),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let exported = get(&a, "/api/v1/config").await;
    assert_eq!(exported.status, 200);
    a.stop();

    let dir = temp_dir();
    let db = dir.join("fresh.db");
    let db = db.to_str().unwrap();
    let b = Server::start_with(db, &["--no-demo"]);
    assert_eq!(get(&b, "/api/v1/axes").await.json, json!([]));
    let r = put(&b, "/api/v1/config", exported.json.clone()).await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(get(&b, "/api/v1/config").await.text, exported.text);
    b.stop();

    let b = Server::start_with(db, &["--no-demo"]);
    assert_eq!(get(&b, "/api/v1/config").await.text, exported.text);
    let p = get(&b, "/api/v1/axes/x/parameters/AxisVeloMax").await;
    assert_eq!(p.json["value"], 750.0, "{}", p.text);
}

/// Command ids never repeat across a crash, and acknowledged commands keep their audit row: an id acknowledged before `kill -9` is never handed
/// out again, even when its audit row had not been written yet (the reserved mark is stored
/// before a command above it is acknowledged).
#[tokio::test(flavor = "multi_thread")]
async fn command_ids_never_repeat_after_a_crash() {
    let dir = temp_dir();
    let db = dir.join("ids.db");
    let db = db.to_str().unwrap();
    let s = Server::start_with(db, &[]);
    let mut acknowledged = Vec::new();
    for _ in 0..5 {
        let r = post(&s, "/api/v1/axes/x/power", json!({})).await;
        assert_eq!(r.status, 202, "{}", r.text);
        acknowledged.push(r.json["id"].as_u64().unwrap());
    }
    s.stop(); // SIGKILL, right after the last acknowledgement
    let s = Server::start_with(db, &[]);
    // Every acknowledged command has its submission row (stored before the 202; its outcome,
    // `accepted`, follows in the batched writer and may be lost with the process).
    let audit = get(&s, "/api/v1/audit?limit=1000").await;
    for id in &acknowledged {
        assert!(
            audit
                .json
                .as_array()
                .unwrap()
                .iter()
                .any(|e| e["command_id"] == *id
                    && (e["outcome"] == "accepted" || e["outcome"] == "submitted")),
            "no audit row for acknowledged command {id}"
        );
    }
    let r = post(&s, "/api/v1/axes/x/power", json!({})).await;
    assert_eq!(r.status, 202, "{}", r.text);
    let new = r.json["id"].as_u64().unwrap();
    assert!(
        acknowledged.iter().all(|&id| new > id),
        "{new} after {acknowledged:?}"
    );
}
