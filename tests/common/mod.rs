//! Starts the real `motiond` binary on a free port with its own database.
#![allow(dead_code, reason = "each test binary uses part of the fixtures")]

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use serde_json::{Value, json};

pub struct Server {
    pub child: Child,
    pub base: String,
    pub addr: String,
    pub log: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
}

static N: AtomicUsize = AtomicUsize::new(0);

/// A fresh directory for one test's database files.
pub fn temp_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "motiond-test-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::SeqCst)
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_motiond"))
}

impl Server {
    /// Starts motiond with `--db db` (`:memory:` by default) on 127.0.0.1:0 and waits until it listens.
    pub fn start_with(db: &str, extra: &[&str]) -> Server {
        let mut cmd = bin();
        cmd.args(["serve", "--listen", "127.0.0.1:0", "--db", db])
            .args(extra);
        Self::spawn(cmd)
    }

    /// Starts a prepared command that runs motiond (which must listen on a free port).
    pub fn spawn(mut cmd: Command) -> Server {
        cmd.stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .env("NO_COLOR", "1");
        let mut child = cmd.spawn().expect("motiond starts");
        let stdout = child.stdout.take().unwrap();
        let stderr = child.stderr.take().unwrap();
        let log = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let (tx, rx) = mpsc::channel();
        let l = log.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                // Logged before the address is handed over: a test that reads the log once
                // motiond listens finds everything up to that line.
                l.lock().unwrap().push(line.clone());
                if let Some(i) = line.find("listening on http") {
                    // http://ADDR or https://ADDR
                    let rest = &line[i + "listening on ".len()..];
                    let url = rest.split_whitespace().next().unwrap_or_default();
                    let (scheme, addr) = url.split_once("://").unwrap_or(("http", url));
                    let _ = tx.send((scheme.to_string(), addr.to_string()));
                }
            }
        });
        let l = log.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                l.lock().unwrap().push(line);
            }
        });
        let (scheme, addr) = match rx.recv_timeout(Duration::from_secs(60)) {
            Ok(a) => a,
            Err(_) => {
                let _ = child.kill();
                panic!("motiond did not start:\n{}", log.lock().unwrap().join("\n"));
            }
        };
        Server {
            child,
            base: format!("{scheme}://{addr}"),
            addr,
            log,
        }
    }

    pub fn start() -> Server {
        Self::start_with(":memory:", &[])
    }

    pub fn url(&self, path: &str) -> String {
        format!("{}{}", self.base, path)
    }

    pub fn stop(mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub struct Resp {
    pub status: u16,
    pub content_type: String,
    pub location: Option<String>,
    pub text: String,
    pub json: Value,
}

impl Resp {
    /// The status and the JSON path of the first field a 422 names.
    pub fn field_error(&self) -> (u16, Option<&str>) {
        (self.status, self.json["errors"][0]["field"].as_str())
    }
}

/// Sends a request as a well-behaved client does: a POST, PUT or DELETE is declared JSON, also
/// without a body (motiond answers 415 otherwise).
pub async fn req(method: reqwest::Method, url: &str, body: Option<Value>) -> Resp {
    let client = reqwest::Client::new();
    let changes = !matches!(method, reqwest::Method::GET | reqwest::Method::HEAD);
    let mut r = client
        .request(method, url)
        .header("x-client-id", "integration-test");
    if changes {
        r = r.header("content-type", "application/json");
    }
    if let Some(b) = body {
        r = r.body(b.to_string());
    }
    resp_of(r.send().await.expect("request sent")).await
}

/// A response with its body read, for `assert_problem`.
pub async fn resp_of(resp: reqwest::Response) -> Resp {
    let status = resp.status().as_u16();
    let content_type = resp
        .headers()
        .get("content-type")
        .and_then(|v| v.to_str().ok())
        .unwrap_or_default()
        .to_string();
    let location = resp
        .headers()
        .get("location")
        .and_then(|v| v.to_str().ok())
        .map(String::from);
    let text = resp.text().await.unwrap_or_default();
    let json = serde_json::from_str(&text).unwrap_or(Value::Null);
    Resp {
        status,
        content_type,
        location,
        text,
        json,
    }
}

pub async fn get(s: &Server, path: &str) -> Resp {
    req(reqwest::Method::GET, &s.url(path), None).await
}
pub async fn post(s: &Server, path: &str, body: Value) -> Resp {
    req(reqwest::Method::POST, &s.url(path), Some(body)).await
}
pub async fn put(s: &Server, path: &str, body: Value) -> Resp {
    req(reqwest::Method::PUT, &s.url(path), Some(body)).await
}
pub async fn delete(s: &Server, path: &str) -> Resp {
    req(reqwest::Method::DELETE, &s.url(path), None).await
}

/// Enables an axis and waits until it is ready; returns the power command.
pub async fn power_on(s: &Server, axis: &str) -> Value {
    let r = post(
        s,
        &format!("/api/v1/axes/{axis}/power?wait=true&timeout_ms=5000"),
        json!({"enable": true}),
    )
    .await;
    assert_eq!(r.status, 202, "power on {axis}: {}", r.text);
    assert_eq!(
        r.json["outputs"]["status"], true,
        "power status of {axis}: {}",
        r.text
    );
    r.json
}

pub async fn status(s: &Server, axis: &str) -> Value {
    let r = get(s, &format!("/api/v1/axes/{axis}/status")).await;
    assert_eq!(r.status, 200, "{}", r.text);
    r.json
}

/// Polls a command until it is final (or panics after `secs`).
pub async fn until_final(s: &Server, id: u64, secs: u64) -> Value {
    let deadline = std::time::Instant::now() + Duration::from_secs(secs);
    loop {
        let r = get(s, &format!("/api/v1/commands/{id}")).await;
        assert_eq!(r.status, 200, "{}", r.text);
        if r.json["final"] == true {
            return r.json;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "command {id} not final: {}",
            r.text
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

pub fn assert_problem(r: &Resp, status: u16, code: &str) {
    assert_eq!(r.status, status, "{}", r.text);
    assert_eq!(r.content_type, "application/problem+json", "{}", r.text);
    assert_eq!(r.json["status"], status, "{}", r.text);
    assert_eq!(r.json["code"], code, "{}", r.text);
    assert!(
        r.json["type"].is_string() && r.json["title"].is_string() && r.json["detail"].is_string(),
        "{}",
        r.text
    );
}

/// A test that cannot run on this machine (no privileges, no tool): under CI (`CI` set and not
/// `false`/`0`) it fails; elsewhere it says SKIPPED on stdout (shown by `--nocapture`) and adds
/// a line to `MOTIOND_SKIPPED_LOG` (test-all's summary lists them), then the caller returns.
pub fn cannot_run(test: &str, why: &str) {
    if std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0") {
        panic!("{test} cannot run here and CI is set: {why}");
    }
    println!("SKIPPED {test}: {why}");
    eprintln!("SKIPPED {test}: {why}");
    if let Ok(path) = std::env::var("MOTIOND_SKIPPED_LOG") {
        use std::io::Write;
        if let Ok(mut f) = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
        {
            let _ = writeln!(f, "{test}: {why}");
        }
    }
}

pub type WsStream =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

/// A websocket session on `/api/v1/ws` (no Origin: a tool, not a page).
pub async fn ws_connect(s: &Server) -> WsStream {
    tokio_tungstenite::connect_async(format!("ws://{}/api/v1/ws", s.addr))
        .await
        .expect("websocket connects")
        .0
}

/// A JSON-RPC request and its answer (the message with its id; notifications in between are
/// skipped).
pub async fn call(ws: &mut WsStream, id: u64, method: &str, params: Value) -> Value {
    use futures_util::{SinkExt, StreamExt};
    use tokio_tungstenite::tungstenite::Message;
    let m = json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params});
    ws.send(Message::Text(m.to_string().into())).await.unwrap();
    loop {
        let msg = tokio::time::timeout(Duration::from_secs(20), ws.next())
            .await
            .expect("an answer within 20 s")
            .expect("the socket stays open")
            .unwrap();
        if let Message::Text(t) = msg {
            let v: Value = serde_json::from_str(&t).unwrap();
            if v["id"] == id {
                return v;
            }
        }
    }
}
