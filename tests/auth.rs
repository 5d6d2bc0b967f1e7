//! Users, roles, tokens, sessions, the control of the machine and remote access (TLS), against
//! the real binary (docs/security.md). The role matrix walks every operation of the server's
//! own OpenAPI document: each is refused without credentials and with every role below the
//! one it declares, and nothing refused acts.

mod common;

use std::process::Stdio;
use std::time::{Duration, Instant};

use common::*;
use serde_json::{Value, json};

const ADMIN: (&str, &str) = ("anna", "secret-pass-1");

/// motiond with authentication on (the first admin from the environment).
fn start_with_auth(db: &str, extra: &[&str]) -> Server {
    let mut cmd = bin();
    cmd.args(["serve", "--listen", "127.0.0.1:0", "--db", db])
        .args(extra)
        .env("MOTIOND_ADMIN_USER", ADMIN.0)
        .env("MOTIOND_ADMIN_PASSWORD", ADMIN.1);
    Server::spawn(cmd)
}

/// A request with a bearer token or a session cookie, declared JSON when it changes something.
async fn call(
    s: &Server,
    method: &str,
    path: &str,
    cred: Option<&str>,
    client_id: &str,
    body: Option<Value>,
) -> Resp {
    let method: reqwest::Method = method.parse().unwrap();
    let mut r = reqwest::Client::new()
        .request(method.clone(), s.url(path))
        .header("x-client-id", client_id);
    if !matches!(method, reqwest::Method::GET | reqwest::Method::HEAD) {
        r = r.header("content-type", "application/json");
    }
    match cred {
        Some(c) if c.starts_with("motiond_session=") => r = r.header("cookie", c),
        Some(t) => r = r.header("authorization", format!("Bearer {t}")),
        None => {}
    }
    if let Some(b) = body {
        r = r.body(b.to_string());
    }
    resp_of(r.send().await.expect("request sent")).await
}

/// Logs in; the `Cookie` header value of the session.
async fn login(s: &Server, name: &str, password: &str) -> String {
    let r = reqwest::Client::new()
        .post(s.url("/api/v1/auth/login"))
        .header("content-type", "application/json")
        .body(json!({"name": name, "password": password}).to_string())
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200);
    let cookie = r
        .headers()
        .get("set-cookie")
        .expect("a session cookie")
        .to_str()
        .unwrap()
        .to_owned();
    for flag in ["HttpOnly", "SameSite=Strict", "Path=/"] {
        assert!(cookie.contains(flag), "{cookie}");
    }
    assert!(!cookie.contains("Secure"), "plain HTTP: {cookie}");
    cookie.split(';').next().unwrap().to_owned()
}

async fn token(s: &Server, admin: &str, name: &str, role: &str) -> String {
    let r = call(
        s,
        "POST",
        "/api/v1/tokens",
        Some(admin),
        "t",
        Some(json!({"name": name, "role": role})),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["role"], role);
    r.json["token"].as_str().unwrap().to_owned()
}

const ROLES: [&str; 4] = ["viewer", "operator", "engineer", "admin"];

fn rank(role: &str) -> usize {
    ROLES.iter().position(|r| *r == role).unwrap()
}

fn concrete(path: &str) -> String {
    path.replace("{axis}", "x")
        .replace("{id}", "1")
        .replace("{name}", "anna")
        .replace("{parameter}", "AxisVeloMax")
        .replace("{table}", "1")
        .replace("{point}", "1")
}

#[tokio::test]
async fn every_operation_is_refused_below_its_role_and_nothing_refused_acts() {
    let s = start_with_auth(":memory:", &[]);
    let admin = login(&s, ADMIN.0, ADMIN.1).await;
    let mut creds = Vec::new();
    for role in ROLES {
        creds.push((role, token(&s, &admin, &format!("t-{role}"), role).await));
    }
    let doc = get(&s, "/openapi.json").await.json;
    let mut checked = 0;
    for (path, item) in doc["paths"].as_object().unwrap() {
        for (method, op) in item.as_object().unwrap() {
            let need = op["x-motiond-role"].as_str();
            let Some(need) = need.or(op["x-motiond-block"]["role"].as_str()) else {
                // Public: only the login, logout and session query.
                assert!(
                    path.starts_with("/api/v1/auth/") && path != "/api/v1/auth/password",
                    "{method} {path} declares no role"
                );
                continue;
            };
            assert!(
                op["security"].as_array().is_some_and(|s| !s.is_empty()),
                "{method} {path} lists no security"
            );
            for status in ["401", "403"] {
                assert!(
                    op["responses"][status].is_object(),
                    "{method} {path}: no {status}"
                );
            }
            let url = concrete(path);
            let m = method.to_uppercase();
            let r = call(&s, &m, &url, None, "matrix", Some(json!({}))).await;
            assert_problem(&r, 401, "unauthenticated");
            for (role, cred) in &creds {
                if rank(role) >= rank(need) {
                    continue;
                }
                let r = call(&s, &m, &url, Some(cred), "matrix", Some(json!({}))).await;
                assert_problem(&r, 403, "role_insufficient");
                assert!(
                    r.json["detail"].as_str().unwrap().contains(need),
                    "{}",
                    r.text
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 80, "only {checked} refusals checked");
    // Nothing refused acted: no command, x still disabled at 0, the users and tokens as made.
    let commands = call(&s, "GET", "/api/v1/commands", Some(&admin), "m", None).await;
    assert_eq!(
        commands.json.as_array().map(Vec::len),
        Some(0),
        "{}",
        commands.text
    );
    let st = call(
        &s,
        "GET",
        "/api/v1/axes/x/status",
        Some(&creds[0].1),
        "m",
        None,
    )
    .await;
    assert_eq!(st.json["status"]["state"], "disabled", "{}", st.text);
    let users = call(&s, "GET", "/api/v1/users", Some(&admin), "m", None).await;
    assert_eq!(users.json.as_array().unwrap().len(), 1);
    let tokens = call(&s, "GET", "/api/v1/tokens", Some(&admin), "m", None).await;
    assert!(
        tokens
            .json
            .as_array()
            .unwrap()
            .iter()
            .all(|t| t["revoked_at"].is_null())
    );

    // Each role can do its own class of things.
    let (viewer, operator, engineer) = (&creds[0].1, &creds[1].1, &creds[2].1);
    for path in [
        "/api/v1/axes",
        "/api/v1/axes/x/status",
        "/api/v1/system",
        "/metrics",
    ] {
        let r = call(&s, "GET", path, Some(viewer), "m", None).await;
        assert_eq!(r.status, 200, "{path}: {}", r.text);
    }
    let r = call(
        &s,
        "POST",
        "/api/v1/axes/x/power?wait=true",
        Some(operator),
        "m",
        Some(json!({})),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["client"]["principal"], "token:t-operator");
    let r = call(
        &s,
        "PUT",
        "/api/v1/axes/y/parameters/AxisVeloMax",
        Some(engineer),
        "m",
        Some(json!({"value": 600})),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let r = call(
        &s,
        "GET",
        "/api/v1/audit?limit=1000",
        Some(engineer),
        "m",
        None,
    )
    .await;
    let rows = r.json.as_array().unwrap();
    let by = |action: &str| {
        rows.iter()
            .find(|row| row["action"] == action)
            .map(|row| row["principal"].clone())
    };
    assert_eq!(by("command.power"), Some(json!("token:t-operator")));
    assert_eq!(by("parameter.write"), Some(json!("token:t-engineer")));
    assert_eq!(by("token.create"), Some(json!("user:anna")));
    s.stop();
}

#[tokio::test]
async fn sessions_end_with_logout_and_tokens_with_revocation_and_both_survive_a_restart() {
    let dir = temp_dir();
    let db = dir.join("m.db");
    let db = db.to_str().unwrap();
    let s = start_with_auth(db, &[]);
    let r = get(&s, "/api/v1/auth/session").await;
    assert_eq!(r.json["auth_enabled"], true);
    assert!(r.json["principal"].is_null());
    // Wrong passwords: 401, and the fifth in a row locks the name (429) even for the right one.
    for _ in 0..5 {
        let r = call(
            &s,
            "POST",
            "/api/v1/auth/login",
            None,
            "c",
            Some(json!({"name": "anna", "password": "wrong-password"})),
        )
        .await;
        assert_problem(&r, 401, "invalid_credentials");
    }
    let r = call(
        &s,
        "POST",
        "/api/v1/auth/login",
        None,
        "c",
        Some(json!({"name": "anna", "password": ADMIN.1})),
    )
    .await;
    assert_problem(&r, 429, "too_many_login_attempts");
    s.stop();

    // After a restart (the lock is in memory) the admin logs in; the session and a token live on.
    let s = start_with_auth(db, &[]);
    let cookie = login(&s, ADMIN.0, ADMIN.1).await;
    let me = call(&s, "GET", "/api/v1/auth/session", Some(&cookie), "c", None).await;
    assert_eq!(me.json["principal"], "user:anna");
    assert_eq!(me.json["role"], "admin");
    let t = token(&s, &cookie, "mes", "operator").await;
    assert!(t.starts_with("mtk_"));
    s.stop();
    let s = start_with_auth(db, &[]);
    let r = call(&s, "GET", "/api/v1/axes", Some(&cookie), "c", None).await;
    assert_eq!(r.status, 200, "the session outlives a restart: {}", r.text);
    let r = call(&s, "GET", "/api/v1/axes", Some(&t), "c", None).await;
    assert_eq!(r.status, 200, "{}", r.text);
    // Only the hashes are stored: neither secret is in the database file.
    s.stop();
    let bytes = std::fs::read(db).unwrap();
    let wal = std::fs::read(format!("{db}-wal")).unwrap_or_default();
    for secret in [&t, cookie.trim_start_matches("motiond_session=")] {
        let found = |hay: &[u8]| hay.windows(secret.len()).any(|w| w == secret.as_bytes());
        assert!(
            !found(&bytes) && !found(&wal),
            "a secret is stored in clear"
        );
    }
    let s = start_with_auth(db, &[]);
    // Revoked: refused at once, and listed as revoked.
    let tokens = call(&s, "GET", "/api/v1/tokens", Some(&cookie), "c", None).await;
    let id = tokens.json[0]["id"].as_i64().unwrap();
    let r = call(
        &s,
        "DELETE",
        &format!("/api/v1/tokens/{id}"),
        Some(&cookie),
        "c",
        None,
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert!(r.json["revoked_at"].is_string());
    let r = call(&s, "GET", "/api/v1/axes", Some(&t), "c", None).await;
    assert_problem(&r, 401, "invalid_credentials");
    // Logged out: the cookie is cleared and the session is refused.
    let r = reqwest::Client::new()
        .post(s.url("/api/v1/auth/logout"))
        .header("content-type", "application/json")
        .header("cookie", &cookie)
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 204);
    assert!(
        r.headers()["set-cookie"]
            .to_str()
            .unwrap()
            .contains("Max-Age=0")
    );
    let r = call(&s, "GET", "/api/v1/axes", Some(&cookie), "c", None).await;
    assert_problem(&r, 401, "unauthenticated");
    // The last admin cannot be deleted or demoted.
    let cookie = login(&s, ADMIN.0, ADMIN.1).await;
    let r = call(&s, "DELETE", "/api/v1/users/anna", Some(&cookie), "c", None).await;
    assert_problem(&r, 409, "last_admin");
    let r = call(
        &s,
        "PUT",
        "/api/v1/users/anna",
        Some(&cookie),
        "c",
        Some(json!({"role": "viewer"})),
    )
    .await;
    assert_problem(&r, 409, "last_admin");
    s.stop();
}

#[tokio::test]
async fn the_cli_adds_the_first_admin_and_makes_tokens() {
    let dir = temp_dir();
    let db = dir.join("m.db");
    let db = db.to_str().unwrap();
    let run = |args: &[&str], stdin: &str| {
        use std::io::Write;
        let mut c = bin()
            .args(["--db", db])
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        c.stdin.take().unwrap().write_all(stdin.as_bytes()).unwrap();
        c.wait_with_output().unwrap()
    };
    // The first user must be an admin.
    let o = run(
        &["user", "add", "bert", "--role", "operator"],
        "bert-password\n",
    );
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("admin"));
    let o = run(&["user", "add", "--admin", "anna"], "secret-pass-1\n");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(&["token", "add", "mes", "--role", "operator"], "");
    assert!(o.status.success());
    let t = String::from_utf8(o.stdout).unwrap().trim().to_owned();
    assert!(t.starts_with("mtk_"), "{t}");
    let s = Server::start_with(db, &[]);
    let r = get(&s, "/api/v1/axes").await;
    assert_problem(&r, 401, "unauthenticated");
    let r = call(&s, "GET", "/api/v1/axes", Some(&t), "c", None).await;
    assert_eq!(r.status, 200);
    login(&s, "anna", "secret-pass-1").await;
    s.stop();
}

#[tokio::test]
async fn one_holder_commands_motion_and_a_stop_is_never_refused() {
    let s = start_with_auth(":memory:", &[]);
    let admin = login(&s, ADMIN.0, ADMIN.1).await;
    let mes = token(&s, &admin, "mes", "operator").await;
    let op = token(&s, &admin, "panel", "operator").await;
    let r = call(
        &s,
        "POST",
        "/api/v1/axes/y/power?wait=true",
        Some(&op),
        "panel",
        Some(json!({})),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    // Nobody holds control: anyone may command.
    let r = call(&s, "GET", "/api/v1/control", Some(&op), "panel", None).await;
    assert!(r.json["holder"].is_null() && r.json["lease_enabled"] == true);
    let r = call(
        &s,
        "POST",
        "/api/v1/control",
        Some(&mes),
        "line-3",
        Some(json!({"lease_ms": 60000})),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["yours"], true);
    assert_eq!(r.json["holder"]["principal"], "token:mes");
    // The same token from another client id is another client.
    for (cred, id) in [(&op, "panel"), (&mes, "other")] {
        let r = call(
            &s,
            "POST",
            "/api/v1/axes/y/move-velocity",
            Some(cred),
            id,
            Some(json!({"velocity": 20})),
        )
        .await;
        assert_problem(&r, 409, "control_held");
        assert!(
            r.json["detail"]
                .as_str()
                .unwrap()
                .contains("token:mes (client line-3)")
        );
    }
    let st = call(&s, "GET", "/api/v1/axes/y/status", Some(&op), "panel", None).await;
    assert_eq!(
        st.json["status"]["state"], "standstill",
        "nothing moved: {}",
        st.text
    );
    // The holder moves; another client's stop, halt and power-off are accepted.
    let passes = [
        (&mes, "line-3", "move-velocity", json!({"velocity": 20})),
        (&op, "panel", "halt", json!({})),
        (&op, "panel", "stop?wait=true", json!({})),
        (&op, "panel", "power", json!({"enable": false})),
    ];
    for (cred, id, block, body) in passes {
        let path = format!("/api/v1/axes/y/{block}");
        let r = call(&s, "POST", &path, Some(cred), id, Some(body)).await;
        assert_eq!(r.status, 202, "{block}: {}", r.text);
    }
    // An operator cannot take over; an admin can; the holder then may not command.
    let r = call(
        &s,
        "POST",
        "/api/v1/control",
        Some(&op),
        "panel",
        Some(json!({"take_over": true})),
    )
    .await;
    assert_problem(&r, 403, "role_insufficient");
    let r = call(
        &s,
        "POST",
        "/api/v1/control",
        Some(&admin),
        "ui",
        Some(json!({"take_over": true, "lease_ms": 500})),
    )
    .await;
    assert_eq!(r.json["holder"]["principal"], "user:anna", "{}", r.text);
    let r = call(
        &s,
        "POST",
        "/api/v1/axes/y/reset",
        Some(&mes),
        "line-3",
        Some(json!({})),
    )
    .await;
    assert_problem(&r, 409, "control_held");
    // A lease that is not renewed ends by itself (polled, at most 10 s).
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let r = call(&s, "GET", "/api/v1/control", Some(&op), "panel", None).await;
        if r.json["holder"].is_null() {
            break;
        }
        assert!(Instant::now() < deadline, "lease never ended: {}", r.text);
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let r = call(
        &s,
        "POST",
        "/api/v1/axes/y/reset",
        Some(&mes),
        "line-3",
        Some(json!({})),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let audit = call(&s, "GET", "/api/v1/audit", Some(&admin), "ui", None).await;
    let takes: Vec<_> = audit
        .json
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["action"] == "control.take")
        .map(|r| (r["principal"].clone(), r["outcome"].clone()))
        .collect();
    assert!(
        takes.contains(&(json!("user:anna"), json!("accepted"))),
        "{takes:?}"
    );
    assert!(
        takes.contains(&(json!("token:panel"), json!("rejected:role_insufficient"))),
        "{takes:?}"
    );
    s.stop();

    // Switched off: nobody can hold it.
    let s = Server::start_with(":memory:", &["--control-lease", "false"]);
    let r = post(&s, "/api/v1/control", json!({})).await;
    assert_problem(&r, 409, "control_lease_disabled");
    s.stop();
}

#[tokio::test]
async fn a_socket_needs_credentials_and_its_role() {
    use futures_util::{SinkExt, StreamExt};
    use tokio_tungstenite::tungstenite::{Message, client::IntoClientRequest};
    let s = start_with_auth(":memory:", &[]);
    let admin = login(&s, ADMIN.0, ADMIN.1).await;
    let viewer = token(&s, &admin, "dash", "viewer").await;
    let ws_url = format!("ws://{}/api/v1/ws", s.addr);
    let err = tokio_tungstenite::connect_async(ws_url.as_str())
        .await
        .unwrap_err();
    match err {
        tokio_tungstenite::tungstenite::Error::Http(r) => assert_eq!(r.status(), 401),
        e => panic!("{e}"),
    }
    let mut req = ws_url.as_str().into_client_request().unwrap();
    req.headers_mut()
        .insert("authorization", format!("Bearer {viewer}").parse().unwrap());
    let (mut ws, _) = tokio_tungstenite::connect_async(req).await.unwrap();
    let mut ask = async |msg: Value| -> Value {
        ws.send(Message::Text(msg.to_string().into()))
            .await
            .unwrap();
        loop {
            let m = ws.next().await.unwrap().unwrap();
            let Message::Text(t) = m else { continue };
            let v: Value = serde_json::from_str(&t).unwrap();
            if v["id"] == msg["id"] {
                return v;
            }
        }
    };
    let r = ask(
        json!({"jsonrpc": "2.0", "id": 1, "method": "subscribe", "params": {"topic": "system"}}),
    )
    .await;
    assert!(r["result"].is_object(), "{r}");
    let r =
        ask(json!({"jsonrpc": "2.0", "id": 2, "method": "power", "params": {"axis": "x"}})).await;
    assert_eq!(r["error"]["data"]["code"], "role_insufficient", "{r}");
    // Revoked while the socket is open: its next request is refused.
    let tokens = call(&s, "GET", "/api/v1/tokens", Some(&admin), "c", None).await;
    let id = tokens.json[0]["id"].as_i64().unwrap();
    call(
        &s,
        "DELETE",
        &format!("/api/v1/tokens/{id}"),
        Some(&admin),
        "c",
        None,
    )
    .await;
    let r = ask(
        json!({"jsonrpc": "2.0", "id": 3, "method": "subscribe", "params": {"topic": "system"}}),
    )
    .await;
    assert_eq!(r["error"]["data"]["code"], "invalid_credentials", "{r}");
    s.stop();
}

#[tokio::test]
async fn remote_listening_needs_a_user_and_serves_only_tls() {
    // No user: refused at start.
    let dir = temp_dir();
    let db = dir.join("m.db");
    let db = db.to_str().unwrap();
    let o = bin()
        .args(["serve", "--listen", "0.0.0.0:0", "--db", db])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs authentication"));
    // With the first admin: HTTPS with a self-signed certificate, its fingerprint logged.
    let mut cmd = bin();
    cmd.args([
        "serve",
        "--listen",
        "0.0.0.0:0",
        "--db",
        db,
        "--public-name",
        "machine.example",
    ])
    .env("MOTIOND_ADMIN_USER", ADMIN.0)
    .env("MOTIOND_ADMIN_PASSWORD", ADMIN.1);
    let s = Server::spawn(cmd);
    let log = s.log.lock().unwrap().join("\n");
    assert!(log.contains("listening on https://"), "{log}");
    let fp = log
        .split("SHA-256 fingerprint ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .expect("the fingerprint is logged")
        .to_owned();
    let port = s.addr.rsplit(':').next().unwrap().to_owned();
    let addr = format!("127.0.0.1:{port}");
    // Plain HTTP gets no answer.
    let plain = reqwest::Client::new()
        .get(format!("http://{addr}/api/v1/auth/session"))
        .timeout(Duration::from_secs(10))
        .send()
        .await;
    assert!(plain.is_err() || plain.unwrap().status() == 400);
    // Over TLS: the certificate is the logged one, a session cookie is Secure.
    let body = json!({"name": ADMIN.0, "password": ADMIN.1}).to_string();
    let (cert, head) = tls_request(
        &addr,
        &format!(
            "POST /api/v1/auth/login HTTP/1.1\r\nHost: machine.example\r\ncontent-type: application/json\r\n\
             content-length: {}\r\nconnection: close\r\n\r\n{body}",
            body.len()
        ),
    )
    .await;
    let got = cert
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect::<Vec<_>>()
        .join(":");
    assert_eq!(got, fp);
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    assert!(head.to_lowercase().contains("; secure"), "{head}");
    // The certificate is kept: the same fingerprint after a restart.
    s.stop();
    let s = Server::start_with(db, &["--tls"]);
    let log = s.log.lock().unwrap().join("\n");
    assert!(log.contains(&fp), "{log}");
    s.stop();
    // A name it does not carry (issue 28, defect 8): renewed, said in the log, and the new
    // certificate is valid for the new name (and the earlier ones); a name given twice is one.
    let s = Server::start_with(
        db,
        &[
            "--tls",
            "--public-name",
            "cell-7.example",
            "--public-name",
            "machine.example",
            "--public-name",
            "cell-7.example",
        ],
    );
    let log = s.log.lock().unwrap().join("\n");
    assert!(!log.contains(&fp), "renewed: {log}");
    assert!(log.contains("does not name cell-7.example"), "{log}");
    let made = log
        .lines()
        .find(|l| l.contains("made a self-signed TLS certificate for"))
        .unwrap_or_default()
        .to_owned();
    assert_eq!(made.matches("cell-7.example").count(), 1, "{made}");
    assert!(made.contains("machine.example"), "{made}");
    let fp2 = log
        .split("SHA-256 fingerprint ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .unwrap()
        .to_owned();
    s.stop();
    // The same names again: kept.
    let s = Server::start_with(db, &["--tls", "--public-name", "cell-7.example"]);
    let log = s.log.lock().unwrap().join("\n");
    assert!(log.contains(&fp2), "{log}");
    assert!(!log.contains("making a new one"), "{log}");
    s.stop();
}

/// One request over TLS accepting any certificate (the test pins the fingerprint itself):
/// the SHA-256 of the server's certificate and the response head.
async fn tls_request(addr: &str, request: &str) -> (Vec<u8>, String) {
    use std::sync::Arc;
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    use tokio_rustls::rustls::{self, client::danger, pki_types};

    #[derive(Debug)]
    struct Any(Arc<rustls::crypto::CryptoProvider>);
    impl danger::ServerCertVerifier for Any {
        fn verify_server_cert(
            &self,
            _: &pki_types::CertificateDer<'_>,
            _: &[pki_types::CertificateDer<'_>],
            _: &pki_types::ServerName<'_>,
            _: &[u8],
            _: pki_types::UnixTime,
        ) -> Result<danger::ServerCertVerified, rustls::Error> {
            Ok(danger::ServerCertVerified::assertion())
        }
        fn verify_tls12_signature(
            &self,
            m: &[u8],
            c: &pki_types::CertificateDer<'_>,
            d: &rustls::DigitallySignedStruct,
        ) -> Result<danger::HandshakeSignatureValid, rustls::Error> {
            rustls::crypto::verify_tls12_signature(
                m,
                c,
                d,
                &self.0.signature_verification_algorithms,
            )
        }
        fn verify_tls13_signature(
            &self,
            m: &[u8],
            c: &pki_types::CertificateDer<'_>,
            d: &rustls::DigitallySignedStruct,
        ) -> Result<danger::HandshakeSignatureValid, rustls::Error> {
            rustls::crypto::verify_tls13_signature(
                m,
                c,
                d,
                &self.0.signature_verification_algorithms,
            )
        }
        fn supported_verify_schemes(&self) -> Vec<rustls::SignatureScheme> {
            self.0.signature_verification_algorithms.supported_schemes()
        }
    }
    let provider = Arc::new(rustls::crypto::ring::default_provider());
    let config = rustls::ClientConfig::builder_with_provider(provider.clone())
        .with_safe_default_protocol_versions()
        .unwrap()
        .dangerous()
        .with_custom_certificate_verifier(Arc::new(Any(provider)))
        .with_no_client_auth();
    let connector = tokio_rustls::TlsConnector::from(Arc::new(config));
    let tcp = tokio::net::TcpStream::connect(addr).await.unwrap();
    let name = pki_types::ServerName::try_from("machine.example").unwrap();
    let mut tls = connector.connect(name, tcp).await.expect("TLS handshake");
    let cert = tls.get_ref().1.peer_certificates().unwrap()[0].to_vec();
    let digest = ring::digest::digest(&ring::digest::SHA256, &cert)
        .as_ref()
        .to_vec();
    tls.write_all(request.as_bytes()).await.unwrap();
    let mut out = Vec::new();
    let _ = tls.read_to_end(&mut out).await;
    let text = String::from_utf8_lossy(&out).into_owned();
    (digest, text)
}

/// A token made while authentication was off (no user: anyone on loopback could make it) ends
/// when the first user turns authentication on (decision 118): afterwards it is a 401, it is
/// listed as revoked, and the audit log says why. Tokens made after that are kept.
#[tokio::test(flavor = "multi_thread")]
async fn tokens_made_in_open_mode_end_when_authentication_turns_on() {
    let s = Server::start();
    let r = call(
        &s,
        "POST",
        "/api/v1/tokens",
        None,
        "c",
        Some(json!({"name": "made-anonymously", "role": "admin"})),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let open = r.json["token"].as_str().unwrap().to_owned();
    let r = call(&s, "GET", "/api/v1/axes", Some(&open), "c", None).await;
    assert_eq!(r.status, 200, "{}", r.text);
    // The first user, an admin (authentication on from now).
    let r = call(
        &s,
        "POST",
        "/api/v1/users",
        None,
        "c",
        Some(json!({"name": "anna", "role": "admin", "password": "secret-pass-1"})),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let r = call(&s, "GET", "/api/v1/axes", Some(&open), "c", None).await;
    assert_eq!(r.status, 401, "the open-mode token ends: {}", r.text);
    let r = call(
        &s,
        "POST",
        "/api/v1/axes/x/power",
        Some(&open),
        "c",
        Some(json!({})),
    )
    .await;
    assert_eq!(r.status, 401, "{}", r.text);
    let cookie = login(&s, "anna", "secret-pass-1").await;
    let tokens = call(&s, "GET", "/api/v1/tokens", Some(&cookie), "c", None).await;
    let t = tokens
        .json
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["name"] == "made-anonymously")
        .cloned()
        .unwrap();
    assert!(t["revoked_at"].is_string(), "{t}");
    let audit = call(
        &s,
        "GET",
        "/api/v1/audit?limit=20",
        Some(&cookie),
        "c",
        None,
    )
    .await;
    assert!(
        audit.text.contains("authentication turned on") && audit.text.contains("made-anonymously"),
        "{}",
        audit.text
    );
    // A token the admin makes now is kept, also when a second user is added.
    let kept = token(&s, &cookie, "line-3", "operator").await;
    let r = call(
        &s,
        "POST",
        "/api/v1/users",
        Some(&cookie),
        "c",
        Some(json!({"name": "ben", "role": "viewer", "password": "secret-pass-2"})),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let r = call(&s, "GET", "/api/v1/axes", Some(&kept), "c", None).await;
    assert_eq!(r.status, 200, "{}", r.text);
    s.stop();
}
