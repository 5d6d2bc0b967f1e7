//! `Idempotency-Key` on motion commands (issue "Security and reliability"), against the real
//! binary: a retry gets the first answer and does not act twice — also after a restart —; the key
//! with another request, or while the first is still answered, is refused; a bad key is a 422.

mod common;

use common::*;
use serde_json::{Value, json};

/// POST with an `Idempotency-Key`; the response and whether it says it is a replay.
async fn post_keyed(s: &Server, path: &str, key: &str, body: Value) -> (Resp, bool) {
    post_keyed_as(s, None, path, key, body).await
}

/// The same with an `X-Client-Id` (another client, when given).
async fn post_keyed_as(
    s: &Server,
    client: Option<&str>,
    path: &str,
    key: &str,
    body: Value,
) -> (Resp, bool) {
    let mut req = reqwest::Client::new().post(s.url(path));
    if let Some(c) = client {
        req = req.header("x-client-id", c);
    }
    let r = req
        .header("content-type", "application/json")
        .header("idempotency-key", key)
        .body(body.to_string())
        .send()
        .await
        .expect("request sent");
    let replayed = r
        .headers()
        .get("idempotent-replayed")
        .is_some_and(|v| v == "true");
    (resp_of(r).await, replayed)
}

fn position(v: &Value) -> f64 {
    v["status"]["set_position"].as_f64().unwrap()
}

#[tokio::test(flavor = "multi_thread")]
async fn a_retried_command_acts_once() {
    let s = Server::start();
    power_on(&s, "x").await;
    let mv = json!({"distance": 10.0, "velocity": 100.0});
    let path = "/api/v1/axes/x/move-relative?wait=true";
    let (first, replayed) = post_keyed(&s, path, "mes-order-1", mv.clone()).await;
    assert_eq!(first.status, 202, "{}", first.text);
    assert!(!replayed);
    assert_eq!(first.json["state"], "done", "{}", first.text);
    assert_eq!(position(&status(&s, "x").await), 10.0);
    // The MES did not get the answer and sends it again: the same command, nothing moves.
    let (again, replayed) = post_keyed(&s, path, "mes-order-1", mv.clone()).await;
    assert_eq!(again.status, 202, "{}", again.text);
    assert!(replayed);
    assert_eq!(again.json["id"], first.json["id"]);
    assert_eq!(again.json["state"], "done");
    assert_eq!(position(&status(&s, "x").await), 10.0);
    // The same key with another request.
    let (other, _) = post_keyed(
        &s,
        path,
        "mes-order-1",
        json!({"distance": 20.0, "velocity": 100.0}),
    )
    .await;
    assert_eq!(
        (other.status, other.json["code"].as_str()),
        (409, Some("idempotency_key_reused")),
        "{}",
        other.text
    );
    // A refused command is refused again, not tried again.
    let far = json!({"position": 5000.0, "velocity": 100.0});
    let (no, _) = post_keyed(
        &s,
        "/api/v1/axes/x/move-absolute",
        "mes-order-2",
        far.clone(),
    )
    .await;
    assert_eq!(no.status, 409, "{}", no.text);
    let (no_again, _) = post_keyed(&s, "/api/v1/axes/x/move-absolute", "mes-order-2", far).await;
    assert_eq!(
        (no_again.status, &no_again.json["code"]),
        (409, &no.json["code"]),
        "{}",
        no_again.text
    );
    // A key is 1–255 visible ASCII characters.
    for bad in ["", "with space", &"k".repeat(256)] {
        let (r, _) = post_keyed(&s, path, bad, mv.clone()).await;
        assert_eq!(
            r.field_error(),
            (422, Some("Idempotency-Key")),
            "{bad:?}: {}",
            r.text
        );
    }
    // A body that does not check does nothing and keeps no key: the corrected retry acts.
    let (r, _) = post_keyed(
        &s,
        path,
        "mes-order-3",
        json!({"distance": 1.0, "velocity": -1.0}),
    )
    .await;
    assert_eq!(r.status, 422, "{}", r.text);
    let (r, replayed) = post_keyed(
        &s,
        path,
        "mes-order-3",
        json!({"distance": 1.0, "velocity": 10.0}),
    )
    .await;
    assert_eq!((r.status, replayed), (202, false), "{}", r.text);
    assert_eq!(position(&status(&s, "x").await), 11.0);
}

#[tokio::test(flavor = "multi_thread")]
async fn a_retry_while_the_first_is_answered_is_refused_and_after_a_restart_is_recognised() {
    let dir = temp_dir();
    let db = dir.join("idem.db");
    let db = db.to_str().unwrap();
    let s = Server::start_with(db, &[]);
    power_on(&s, "x").await;
    // A long move waited for: its request is still being answered.
    let url = s.url("/api/v1/axes/x/move-relative?wait=true&timeout_ms=60000");
    let long = tokio::spawn(async move {
        reqwest::Client::new()
            .post(url)
            .header("content-type", "application/json")
            .header("idempotency-key", "mes-long")
            .body(json!({"distance": 500.0, "velocity": 20.0}).to_string())
            .send()
            .await
            .map(|r| r.status().as_u16())
    });
    // Wait until the move runs.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(30);
    while status(&s, "x").await["status"]["state"] != "discrete_motion" {
        assert!(
            std::time::Instant::now() < deadline,
            "the move did not start"
        );
        tokio::time::sleep(std::time::Duration::from_millis(10)).await;
    }
    let (r, _) = post_keyed(
        &s,
        "/api/v1/axes/x/move-relative",
        "mes-long",
        json!({"distance": 500.0, "velocity": 20.0}),
    )
    .await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("idempotency_key_in_flight")),
        "{}",
        r.text
    );
    s.stop(); // SIGKILL while the move runs
    let _ = long.await;
    let s = Server::start_with(db, &[]);
    power_on(&s, "x").await;
    let before = position(&status(&s, "x").await);
    let (r, _) = post_keyed(
        &s,
        "/api/v1/axes/x/move-relative",
        "mes-long",
        json!({"distance": 500.0, "velocity": 20.0}),
    )
    .await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("idempotency_key_replayed")),
        "{}",
        r.text
    );
    assert!(
        r.json["detail"].as_str().unwrap().contains("command "),
        "{}",
        r.text
    );
    assert_eq!(status(&s, "x").await["status"]["state"], "standstill");
    assert_eq!(position(&status(&s, "x").await), before);
    // Another request under that key is still another request.
    let (r, _) = post_keyed(
        &s,
        "/api/v1/axes/x/move-relative",
        "mes-long",
        json!({"distance": 1.0, "velocity": 20.0}),
    )
    .await;
    assert_eq!(r.json["code"], "idempotency_key_reused", "{}", r.text);
}

/// An MES that gives up waiting (its connection closed mid-request) and retries later gets the
/// first command's answer: the first request is carried on to its answer without its client.
#[tokio::test(flavor = "multi_thread")]
async fn a_client_that_gave_up_waiting_gets_the_answer_on_retry() {
    let s = Server::start();
    power_on(&s, "x").await;
    let body = json!({"distance": 40.0, "velocity": 100.0});
    let gave_up = reqwest::Client::builder()
        .timeout(std::time::Duration::from_millis(50))
        .build()
        .unwrap()
        .post(s.url("/api/v1/axes/x/move-relative?wait=true&timeout_ms=60000"))
        .header("content-type", "application/json")
        .header("idempotency-key", "mes-gave-up")
        .body(body.to_string())
        .send()
        .await;
    assert!(
        gave_up.is_err(),
        "the move should outlast the client's 50 ms"
    );
    // The move runs to its end all the same.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(30);
    loop {
        let st = status(&s, "x").await;
        if st["status"]["state"] == "standstill" && position(&st) == 40.0 {
            break;
        }
        assert!(std::time::Instant::now() < deadline, "{st}");
        tokio::time::sleep(std::time::Duration::from_millis(20)).await;
    }
    // The retry: the first command, done; nothing moves again. (The first request's task may
    // still be finishing its answer: then the key is in flight for a moment.)
    let (r, replayed) = loop {
        let (r, replayed) = post_keyed(
            &s,
            "/api/v1/axes/x/move-relative",
            "mes-gave-up",
            body.clone(),
        )
        .await;
        if r.json["code"] != "idempotency_key_in_flight" {
            break (r, replayed);
        }
        assert!(std::time::Instant::now() < deadline, "{}", r.text);
        tokio::time::sleep(std::time::Duration::from_millis(20)).await;
    };
    assert_eq!((r.status, replayed), (202, true), "{}", r.text);
    assert_eq!(r.json["state"], "done", "{}", r.text);
    assert_eq!(position(&status(&s, "x").await), 40.0);
}

/// A key belongs to its sender (issue 28, defect 7): another client (another `X-Client-Id`, or
/// none) sending the same key and body gets a command of its own, not the first client's
/// answer; its own retry is a replay of its own command. Also after a restart.
#[tokio::test(flavor = "multi_thread")]
async fn keys_are_scoped_per_client() {
    let dir = temp_dir();
    let db = dir.join("keys.db");
    let db = db.to_str().unwrap();
    let s = Server::start_with(db, &[]);
    power_on(&s, "x").await;
    let mv = json!({"distance": 10.0, "velocity": 100.0});
    let path = "/api/v1/axes/x/move-relative?wait=true";
    let (a, replayed) = post_keyed_as(&s, Some("line-1"), path, "order-7", mv.clone()).await;
    assert_eq!(a.status, 202, "{}", a.text);
    assert!(!replayed);
    let (b, replayed) = post_keyed_as(&s, Some("line-2"), path, "order-7", mv.clone()).await;
    assert_eq!(b.status, 202, "{}", b.text);
    assert!(!replayed, "another client's key is another key: {}", b.text);
    assert_ne!(a.json["id"], b.json["id"]);
    let (c, replayed) = post_keyed_as(&s, None, path, "order-7", mv.clone()).await;
    assert_eq!(c.status, 202, "{}", c.text);
    assert!(!replayed);
    assert_eq!(position(&status(&s, "x").await), 30.0);
    // Each client's own retry is its own command again.
    let (b2, replayed) = post_keyed_as(&s, Some("line-2"), path, "order-7", mv.clone()).await;
    assert!(replayed, "{}", b2.text);
    assert_eq!(b2.json["id"], b.json["id"]);
    assert_eq!(position(&status(&s, "x").await), 30.0);
    s.stop();
    // After a restart: the stored key is found for its sender only.
    let s = Server::start_with(db, &[]);
    power_on(&s, "x").await;
    let (a3, _) = post_keyed_as(&s, Some("line-1"), path, "order-7", mv.clone()).await;
    assert_eq!(a3.json["code"], "idempotency_key_replayed", "{}", a3.text);
    let (d, replayed) = post_keyed_as(&s, Some("line-3"), path, "order-7", mv.clone()).await;
    assert_eq!(d.status, 202, "{}", d.text);
    assert!(!replayed);
    s.stop();
}
