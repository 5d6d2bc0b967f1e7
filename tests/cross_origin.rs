//! The browser's attack surface (docs/security.md), against the real binary: every trick a
//! web page of another site can play — simple cross-site requests (text/plain, form-encoded,
//! bodyless), a foreign or null Origin, Sec-Fetch-Site cross-site/same-site, DNS rebinding
//! (a foreign Host), the websocket from another origin — and JSON bodies that are not objects
//! are refused with their problem, and leave the machine exactly as it was. Same-origin
//! requests, requests without Origin (curl, an MES), `--allow-origin` and `--public-name` work.

mod common;

use std::time::Duration;

use common::*;
use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio_tungstenite::tungstenite::{self, Message, client::IntoClientRequest, http};

const JSON: (&str, &str) = ("content-type", "application/json");
const EVIL: (&str, &str) = ("origin", "http://evil.example");

/// A request with exactly these headers (no Content-Type unless given) and this body.
async fn send(s: &Server, method: &str, path: &str, headers: &[(&str, &str)], body: &str) -> Resp {
    let mut r = reqwest::Client::new().request(method.parse().unwrap(), s.url(path));
    for (k, v) in headers {
        r = r.header(*k, *v);
    }
    if !body.is_empty() {
        r = r.body(body.to_owned());
    }
    resp_of(r.send().await.expect("request sent")).await
}

/// Everything a refused request must leave as it was: each axis's state and position, the
/// configuration with its persistent parameters, y's parameters, the commands, the audit log
/// and the scope recordings.
async fn machine(s: &Server) -> Value {
    let mut axes = serde_json::Map::new();
    for axis in ["x", "y", "spindle"] {
        let st = &status(s, axis).await["status"];
        let keep = [
            "state",
            "power_status",
            "set_position",
            "has_job",
            "active_command",
        ];
        let st: serde_json::Map<String, Value> = keep
            .iter()
            .map(|k| (k.to_string(), st[k].clone()))
            .collect();
        axes.insert(axis.into(), st.into());
    }
    let mut m = json!({ "axes": axes });
    for (key, path) in [
        ("config", "/api/v1/config"),
        ("y_parameters", "/api/v1/axes/y/parameters"),
        ("commands", "/api/v1/commands"),
        ("audit", "/api/v1/audit?limit=1000"),
        ("recordings", "/api/v1/scope/recordings"),
        ("group", "/api/v1/groups/xy/status"),
    ] {
        let r = get(s, path).await;
        assert_eq!(r.status, 200, "{path}: {}", r.text);
        m[key] = r.json;
    }
    // The group's status is stamped with its cycle: what it says is compared, not when.
    if let Some(g) = m["group"].as_object_mut() {
        g.remove("cycle");
    }
    m
}

/// The state of a fresh demo machine: nothing powered, nothing commanded, only the demo's
/// axis creations in the audit log.
fn assert_untouched(m: &Value) {
    for (axis, st) in m["axes"].as_object().unwrap() {
        assert_eq!(st["power_status"], false, "{axis} powered: {st}");
        assert_eq!(st["state"], "disabled", "{axis}: {st}");
        assert_eq!(st["set_position"], 0.0, "{axis} moved: {st}");
    }
    assert_eq!(m["commands"], json!([]), "a command exists");
    assert_eq!(m["recordings"], json!([]), "a recording exists");
    assert_eq!(
        m["group"]["state"], "disabled",
        "the demo group: {}",
        m["group"]
    );
    assert_eq!(
        m["group"]["queued_entries"], 0,
        "the demo group: {}",
        m["group"]
    );
    for row in m["audit"].as_array().unwrap() {
        // The demo machine's axes and its group xy.
        assert!(
            row["action"] == "axis.create" || row["action"] == "group.create",
            "audited: {row}"
        );
        assert_eq!(row["client_id"], "demo", "audited: {row}");
    }
    let velo_max = m["y_parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "AxisVeloMax")
        .unwrap();
    assert_eq!(velo_max["value"], 500.0, "{velo_max}");
}

/// (method, path, headers, body, status, code)
type Case<'a> = (
    &'a str,
    &'a str,
    Vec<(&'a str, &'a str)>,
    &'a str,
    u16,
    &'a str,
);

#[tokio::test(flavor = "multi_thread")]
async fn simple_and_cross_site_requests_are_refused_and_change_nothing() {
    let s = Server::start();
    let before = machine(&s).await;
    assert_untouched(&before);
    let own = format!("http://{}", s.addr);
    let velocity = r#"{"velocity": 50}"#;
    let power = r#"{"enable": true}"#;
    #[rustfmt::skip]
    let cases: Vec<Case> = vec![
        // "Simple" requests a page may send anywhere without a preflight: not JSON → 415.
        ("POST", "/api/v1/axes/y/move-velocity", vec![("content-type", "text/plain")], velocity, 415, "unsupported_media_type"),
        ("POST", "/api/v1/axes/y/move-velocity", vec![("content-type", "text/plain;charset=UTF-8")], velocity, 415, "unsupported_media_type"),
        ("POST", "/api/v1/axes/y/power", vec![("content-type", "application/x-www-form-urlencoded")], "enable=true", 415, "unsupported_media_type"),
        ("POST", "/api/v1/axes/y/power", vec![("content-type", "multipart/form-data; boundary=x")], "--x--", 415, "unsupported_media_type"),
        ("POST", "/api/v1/axes/y/power", vec![], "", 415, "unsupported_media_type"),
        ("POST", "/api/v1/axes/y/power", vec![], power, 415, "unsupported_media_type"),
        ("PUT", "/api/v1/axes/y/parameters/AxisVeloMax", vec![("content-type", "text/plain")], r#"{"value": 50}"#, 415, "unsupported_media_type"),
        ("DELETE", "/api/v1/axes/spindle", vec![], "", 415, "unsupported_media_type"),
        ("PUT", "/api/v1/config", vec![("content-type", "text/plain")], r#"{"version": 1, "axes": []}"#, 415, "unsupported_media_type"),
        ("POST", "/api/v1/axes/y/simulation/fault", vec![], r#"{"kind": "drive_fault", "code": 1}"#, 415, "unsupported_media_type"),
        // From another origin: 403 first, JSON or not.
        ("POST", "/api/v1/axes/y/move-velocity", vec![EVIL, ("content-type", "text/plain")], velocity, 403, "cross_origin_forbidden"),
        ("POST", "/api/v1/axes/y/power", vec![EVIL, JSON], power, 403, "cross_origin_forbidden"),
        ("POST", "/api/v1/axes/y/power", vec![("origin", "null"), JSON], power, 403, "cross_origin_forbidden"),
        ("POST", "/api/v1/axes/y/power", vec![("origin", "http://127.0.0.1:1"), JSON], power, 403, "cross_origin_forbidden"),
        ("POST", "/api/v1/axes/y/power", vec![("sec-fetch-site", "cross-site"), JSON], power, 403, "cross_origin_forbidden"),
        ("POST", "/api/v1/axes/y/power", vec![("sec-fetch-site", "same-site"), JSON], power, 403, "cross_origin_forbidden"),
        ("POST", "/api/v1/axes/y/power", vec![("origin", &own), ("sec-fetch-site", "cross-site"), JSON], power, 403, "cross_origin_forbidden"),
        ("PUT", "/api/v1/axes/y/parameters/AxisVeloMax", vec![EVIL, JSON], r#"{"value": 50, "persistent": true}"#, 403, "cross_origin_forbidden"),
        ("DELETE", "/api/v1/axes/spindle", vec![EVIL, JSON], "", 403, "cross_origin_forbidden"),
        ("POST", "/api/v1/scope/recordings", vec![EVIL, JSON], r#"{"channels": [{"axis": "x", "signal": "set_position"}], "duration_s": 1}"#, 403, "cross_origin_forbidden"),
        // Before routing: a path or method that does not exist tells a foreign page nothing.
        ("POST", "/api/v1/no-such-thing", vec![EVIL, JSON], "{}", 403, "cross_origin_forbidden"),
    ];
    for (method, path, headers, body, status, code) in cases {
        let r = send(&s, method, path, &headers, body).await;
        let what = format!("{method} {path} {headers:?} {body}");
        assert_eq!(r.status, status, "{what}: {}", r.text);
        assert_problem(&r, status, code);
        assert_eq!(machine(&s).await, before, "{what} changed something");
    }
    assert_untouched(&machine(&s).await);
}

#[tokio::test(flavor = "multi_thread")]
async fn same_origin_requests_and_requests_without_origin_still_work() {
    let s = Server::start();
    let port = s.addr.rsplit_once(':').unwrap().1;
    let own = format!("http://{}", s.addr);
    let localhost = format!("localhost:{port}");
    let localhost_origin = format!("http://localhost:{port}");
    let accepted: Vec<(&str, Vec<(&str, &str)>)> = vec![
        ("x", vec![JSON]),
        (
            "y",
            vec![("origin", &own), ("sec-fetch-site", "same-origin"), JSON],
        ),
        (
            "spindle",
            vec![
                ("sec-fetch-site", "none"),
                ("content-type", "application/json; charset=utf-8"),
            ],
        ),
        (
            "y",
            vec![("host", &localhost), ("origin", &localhost_origin), JSON],
        ),
    ];
    for (axis, headers) in accepted {
        let path = format!("/api/v1/axes/{axis}/power");
        let r = send(&s, "POST", &path, &headers, "").await;
        assert_eq!(r.status, 202, "{headers:?}: {}", r.text);
        assert_eq!(r.json["axis"], axis, "{}", r.text);
    }
    let id = get(&s, "/api/v1/commands?axis=x").await.json[0]["id"].clone();
    let r = send(
        &s,
        "DELETE",
        &format!("/api/v1/commands/{id}"),
        &[("origin", &own), JSON],
        "",
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    // Reading needs no Content-Type and is not Origin-checked (the browser keeps the answer
    // from a foreign page: motiond sends no CORS headers).
    let r = send(&s, "GET", "/api/v1/axes", &[EVIL], "").await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert!(!r.text.is_empty());
    let raw = reqwest::Client::new()
        .get(s.url("/api/v1/axes"))
        .header("origin", "http://evil.example")
        .send()
        .await
        .unwrap();
    assert!(raw.headers().get("access-control-allow-origin").is_none());
}

#[tokio::test(flavor = "multi_thread")]
async fn a_foreign_host_is_misdirected_everywhere_and_changes_nothing() {
    let s = Server::start();
    let before = machine(&s).await;
    let port = s.addr.rsplit_once(':').unwrap().1;
    let attacker = format!("attacker.example:{port}");
    let attacker_origin = format!("http://{attacker}");
    let rebound = [("host", attacker.as_str())];
    for path in [
        "/api/v1/axes",
        "/api/v1/axes/y/status",
        "/",
        "/index.html",
        "/openapi.json",
        "/docs/",
        "/metrics",
        "/api/v1/nothing",
    ] {
        let r = send(&s, "GET", path, &rebound, "").await;
        assert_problem(&r, 421, "misdirected_request");
    }
    // A rebound page is same-origin with itself: Host is what refuses it.
    let rebound_page = [
        ("host", attacker.as_str()),
        ("origin", attacker_origin.as_str()),
        ("sec-fetch-site", "same-origin"),
        JSON,
    ];
    for (method, path, body) in [
        ("POST", "/api/v1/axes/y/power", r#"{"enable": true}"#),
        (
            "POST",
            "/api/v1/axes/y/move-velocity",
            r#"{"velocity": 50}"#,
        ),
        (
            "PUT",
            "/api/v1/axes/y/parameters/AxisVeloMax",
            r#"{"value": 50}"#,
        ),
        ("DELETE", "/api/v1/axes/spindle", ""),
    ] {
        let r = send(&s, method, path, &rebound_page, body).await;
        assert_problem(&r, 421, "misdirected_request");
        let r = send(
            &s,
            method,
            path,
            &[("host", "attacker.example"), JSON],
            body,
        )
        .await;
        assert_problem(&r, 421, "misdirected_request");
    }
    // The websocket too, before the handshake.
    let err = ws_refused(&s, &[("host", &attacker), ("origin", &attacker_origin)]).await;
    assert_eq!(err, (421, "misdirected_request".into()));
    assert_eq!(machine(&s).await, before);
    assert_untouched(&before);
    // No Host at all (HTTP/1.0): served, no browser sends such a request.
    let mut tcp = tokio::net::TcpStream::connect(&s.addr).await.unwrap();
    tcp.write_all(b"GET /api/v1/axes HTTP/1.0\r\n\r\n")
        .await
        .unwrap();
    let mut answer = String::new();
    tcp.read_to_string(&mut answer).await.unwrap();
    assert!(answer.starts_with("HTTP/1.0 200"), "{answer}");
    // Loopback names and addresses with any port are this server.
    for host in [
        format!("localhost:{port}"),
        "localhost".into(),
        format!("ui.localhost:{port}"),
        format!("127.0.0.2:{port}"),
        format!("[::1]:{port}"),
        "127.0.0.1".into(),
    ] {
        let r = send(&s, "GET", "/api/v1/axes", &[("host", &host)], "").await;
        assert_eq!(r.status, 200, "{host}: {}", r.text);
    }
}

/// Opens the websocket with these headers; `Err((status, code))` when it is refused.
async fn ws_connect(s: &Server, headers: &[(&str, &str)]) -> Result<Ws, (u16, String)> {
    let mut request = format!("ws://{}/api/v1/ws", s.addr)
        .into_client_request()
        .unwrap();
    for (k, v) in headers {
        request.headers_mut().insert(
            http::HeaderName::from_bytes(k.as_bytes()).unwrap(),
            http::HeaderValue::from_str(v).unwrap(),
        );
    }
    match tokio_tungstenite::connect_async(request).await {
        Ok((ws, response)) => {
            assert_eq!(response.status().as_u16(), 101);
            Ok(ws)
        }
        Err(tungstenite::Error::Http(response)) => {
            let body = response.body().as_deref().unwrap_or_default();
            let problem: Value = serde_json::from_slice(body).unwrap_or(Value::Null);
            assert_eq!(
                response.headers()["content-type"],
                "application/problem+json"
            );
            assert_eq!(problem["status"], response.status().as_u16(), "{problem}");
            let code = problem["code"].as_str().unwrap_or_default().to_owned();
            Err((response.status().as_u16(), code))
        }
        Err(e) => panic!("websocket: {e}"),
    }
}

async fn ws_refused(s: &Server, headers: &[(&str, &str)]) -> (u16, String) {
    match ws_connect(s, headers).await {
        Ok(_) => panic!("the websocket opened with {headers:?}"),
        Err(e) => e,
    }
}

type Ws =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

/// A JSON-RPC call: its response (notifications in between are skipped).
async fn call(ws: &mut Ws, id: u64, method: &str, params: Value) -> Value {
    let m = json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params});
    ws.send(Message::Text(m.to_string().into())).await.unwrap();
    loop {
        let next = tokio::time::timeout(Duration::from_secs(20), ws.next()).await;
        if let Ok(Some(Ok(Message::Text(t)))) = next {
            let v: Value = serde_json::from_str(&t).unwrap();
            if v["id"] == id {
                return v;
            }
        } else {
            assert!(next.is_ok(), "no response to {method}");
        }
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn the_websocket_refuses_foreign_origins_before_the_handshake() {
    let s = Server::start();
    let before = machine(&s).await;
    let own = format!("http://{}", s.addr);
    for headers in [
        vec![EVIL],
        vec![("origin", "null")],
        vec![("origin", "http://localhost:1")],
        vec![("sec-fetch-site", "cross-site")],
        vec![("origin", own.as_str()), ("sec-fetch-site", "same-site")],
    ] {
        let err = ws_refused(&s, &headers).await;
        assert_eq!(err, (403, "cross_origin_forbidden".into()), "{headers:?}");
    }
    // A plain GET (no upgrade) is no handshake, whoever sends it.
    let r = send(&s, "GET", "/api/v1/ws", &[EVIL], "").await;
    assert_problem(&r, 426, "websocket_upgrade_required");
    assert_eq!(machine(&s).await, before);
    assert_untouched(&before);
    // The server's own pages, and clients without Origin, connect and command.
    for (id, headers) in [
        (
            1,
            vec![("origin", own.as_str()), ("sec-fetch-site", "same-origin")],
        ),
        (2, vec![]),
    ] {
        let mut ws = ws_connect(&s, &headers).await.expect("connects");
        let r = call(&mut ws, id, "power", json!({"axis": "y", "wait": true})).await;
        assert_eq!(r["result"]["outputs"]["status"], true, "{r}");
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn allowed_origins_and_public_names_are_served() {
    let s = Server::start_with(
        ":memory:",
        &[
            "--allow-origin",
            "http://localhost:5173/",
            "--allow-origin",
            "https://hmi.example",
            "--public-name",
            "machine.example",
        ],
    );
    let before = machine(&s).await;
    let port = s.addr.rsplit_once(':').unwrap().1;
    // Allowed origins still need JSON, and only the allowed ones pass.
    let vite = ("origin", "http://localhost:5173");
    let r = send(
        &s,
        "POST",
        "/api/v1/axes/y/power",
        &[vite, ("content-type", "text/plain")],
        "{}",
    )
    .await;
    assert_problem(&r, 415, "unsupported_media_type");
    for origin in [
        "http://localhost:5174",
        "https://localhost:5173",
        "http://hmi.example",
        "http://machine.example",
    ] {
        let r = send(
            &s,
            "POST",
            "/api/v1/axes/y/power",
            &[("origin", origin), JSON],
            "{}",
        )
        .await;
        assert_problem(&r, 403, "cross_origin_forbidden");
    }
    let machine_host = format!("machine.example:{port}");
    let r = send(&s, "GET", "/api/v1/axes", &[("host", "other.example")], "").await;
    assert_problem(&r, 421, "misdirected_request");
    let err = ws_refused(&s, &[EVIL]).await;
    assert_eq!(err, (403, "cross_origin_forbidden".into()));
    assert_eq!(machine(&s).await, before);
    // An allowed origin may act even when the browser calls it same-site (another port).
    let r = send(
        &s,
        "POST",
        "/api/v1/axes/y/power",
        &[vite, ("sec-fetch-site", "same-site"), JSON],
        "{}",
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let r = send(
        &s,
        "POST",
        "/api/v1/axes/x/power",
        &[
            ("origin", "https://hmi.example"),
            ("sec-fetch-site", "cross-site"),
            JSON,
        ],
        "{}",
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    // A public name is served, and a page of it is same-origin.
    let r = send(&s, "GET", "/api/v1/axes", &[("host", &machine_host)], "").await;
    assert_eq!(r.status, 200, "{}", r.text);
    let machine_origin = format!("http://{machine_host}");
    let r = send(
        &s,
        "POST",
        "/api/v1/axes/spindle/power",
        &[("host", &machine_host), ("origin", &machine_origin), JSON],
        "{}",
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let mut ws = ws_connect(&s, &[vite])
        .await
        .expect("an allowed origin connects");
    let r = call(&mut ws, 1, "subscribe", json!({"topic": "system"})).await;
    assert_eq!(r["result"]["topic"], "system", "{r}");
    // The same names without the options: refused.
    let plain = Server::start();
    let r = send(&plain, "POST", "/api/v1/axes/y/power", &[vite, JSON], "{}").await;
    assert_problem(&r, 403, "cross_origin_forbidden");
    let r = send(
        &plain,
        "GET",
        "/api/v1/axes",
        &[("host", &machine_host)],
        "",
    )
    .await;
    assert_problem(&r, 421, "misdirected_request");
}

#[tokio::test(flavor = "multi_thread")]
async fn json_bodies_must_be_objects() {
    let s = Server::start();
    let before = machine(&s).await;
    for (method, path) in [
        ("POST", "/api/v1/axes/y/move-absolute"),
        ("POST", "/api/v1/axes/y/power"),
        ("POST", "/api/v1/axes/y/jog"),
        ("POST", "/api/v1/axes/y/stop"),
        ("POST", "/api/v1/axes/y/reset"),
        ("PUT", "/api/v1/axes/y/parameters/AxisVeloMax"),
        ("POST", "/api/v1/axes"),
        ("PUT", "/api/v1/axes/y"),
        ("PUT", "/api/v1/config"),
        ("POST", "/api/v1/axes/y/simulation/fault"),
        ("POST", "/api/v1/scope/recordings"),
    ] {
        for body in [
            "[300,150]",
            "[]",
            "[600]",
            "[600, true]",
            "null",
            "5",
            "\"x\"",
            "true",
        ] {
            let r = send(&s, method, path, &[JSON], body).await;
            assert_problem(&r, 422, "validation_failed");
            assert_eq!(r.json["errors"][0]["field"], "body", "{}", r.text);
            assert!(r.text.contains("must be a JSON object"), "{}", r.text);
        }
    }
    // Over the websocket: params must be an object too.
    let mut ws = ws_connect(&s, &[]).await.unwrap();
    for (id, method) in [(1, "power"), (2, "move-absolute"), (3, "jog")] {
        let r = call(&mut ws, id, method, json!(["y", 300, 150])).await;
        assert_eq!(r["error"]["code"], -32602, "{r}");
        assert!(r["result"].is_null(), "{r}");
    }
    assert_eq!(machine(&s).await, before);
    assert_untouched(&before);
    // The parameter handler survived (it used to panic on an array): the server still answers,
    // and an empty body is still `{}`.
    let r = send(
        &s,
        "PUT",
        "/api/v1/axes/y/parameters/AxisVeloMax",
        &[JSON],
        r#"{"value": 600}"#,
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["value"], 600.0, "{}", r.text);
    let r = send(&s, "POST", "/api/v1/axes/y/power", &[JSON], "").await;
    assert_eq!(r.status, 202, "{}", r.text);
}

#[tokio::test(flavor = "multi_thread")]
async fn listen_takes_localhost_and_the_options_are_checked() {
    for listen in ["localhost:0", "LOCALHOST:0", "127.0.0.2:0"] {
        let mut cmd = bin();
        cmd.args(["serve", "--listen", listen, "--db", ":memory:", "--no-demo"]);
        let s = Server::spawn(cmd);
        assert!(s.addr.starts_with("127.0.0."), "{listen} → {}", s.addr);
        let port = s.addr.rsplit_once(':').unwrap().1;
        let r = send(
            &s,
            "GET",
            "/api/v1/system",
            &[("host", &format!("localhost:{port}"))],
            "",
        )
        .await;
        assert_eq!(r.status, 200, "{}", r.text);
        // (`listen` is the address as given, resolved: the port is still 0.)
        let listen = r.json["listen"].as_str().unwrap();
        assert!(
            listen.starts_with("127.0.0.") && listen.ends_with(":0"),
            "{listen}"
        );
    }
    for bad in [
        ["--listen", "attacker.example:0"],
        ["--listen", "localhost"],
        ["--allow-origin", "null"],
        ["--allow-origin", "*"],
        ["--allow-origin", "localhost:5173"],
        ["--allow-origin", "http://localhost:5173/ui"],
        ["--public-name", "http://machine.example"],
        ["--public-name", "machine.example:8080"],
    ] {
        let out = bin().args(bad).args(["--db", ":memory:"]).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
        let text = String::from_utf8_lossy(&out.stderr);
        assert!(text.contains(bad[0]), "{bad:?}: {text}");
    }
}
