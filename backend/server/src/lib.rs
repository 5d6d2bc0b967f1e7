//! motiond, the appliance: the cycle thread, the REST + websocket API and the SQLite store.
//!
//! Map: [`cycle`] (the real-time thread and its queues), [`app`] (the async side's state and
//! the pump between the two), [`api`] (HTTP and websocket; [`api::blocks`] makes the blocks'
//! endpoints), [`blocks`] (the function blocks by family: bodies, checks, conversions,
//! catalogue entries), [`service`] (the rules of each request), [`store`] (SQLite), [`error`]
//! (`AppError`, `FieldError`), [`model`] (DTOs, the command resource), [`sim`] / [`params`]
//! (adapters to `drives` and `motion::params`), [`cli`] (the command line).
//!
//! Every function block an axis takes is a catalogue entry of its family; the REST endpoint,
//! the websocket method and the OpenAPI operation all come from it:
//!
//! ```
//! use server::api::blocks::{self, Role};
//!
//! let block = blocks::find(blocks::At::Axes, "move-absolute").expect("MC_MoveAbsolute is in the catalogue");
//! assert_eq!(block.path, "/api/v1/axes/{axis}/move-absolute");
//! assert_eq!(block.role, Role::Operator);
//!
//! // The OpenAPI document served at /openapi.json has its operation, body and all.
//! let doc: serde_json::Value = serde_json::from_str(&server::api::openapi_json()).unwrap();
//! let op = &doc["paths"][block.path]["post"];
//! assert_eq!(op["summary"], block.summary);
//! assert_eq!(op["x-motiond-block"]["milestone"], "done");
//! ```

pub mod api;
pub mod app;
pub mod auth;
pub mod blocks;
pub mod bus;
pub mod cli;
pub mod clock;
pub mod cycle;
pub mod error;
pub mod metrics;
pub mod model;
pub mod params;
pub mod scenario;
pub mod scope;
pub mod service;
pub mod sim;
pub mod startup;
pub mod stats;
pub mod store;
pub mod tls;

pub use cli::{Cli, Cmd, ServeArgs, TokenCmd, UserCmd};

use std::sync::Arc;

use clap::Parser;

/// Entry point of the `motiond` binary.
pub fn run() {
    let cli = Cli::parse();
    let args = match cli.command {
        Some(Cmd::Openapi) => {
            print!("{}", api::openapi_json());
            return;
        }
        Some(Cmd::Asyncapi) => {
            print!("{}", api::asyncapi::asyncapi_json());
            return;
        }
        Some(Cmd::Scenario { action }) => {
            return match action {
                cli::ScenarioCmd::Schema => print!("{}", scenario::schema_json()),
                cli::ScenarioCmd::Run { files, csv } => {
                    // Only what goes wrong: the report is the scenario's.
                    tracing_subscriber::fmt()
                        .with_target(false)
                        .with_max_level(tracing::Level::ERROR)
                        .init();
                    exit_with(scenario::run_files(&files, csv.as_deref()))
                }
            };
        }
        Some(Cmd::User { action }) => {
            return exit_with(admin_command(&cli.serve, Admin::User(action)));
        }
        Some(Cmd::Token { action }) => {
            return exit_with(admin_command(&cli.serve, Admin::Token(action)));
        }
        Some(Cmd::EmulateSegment {
            on,
            drives,
            strict_drives,
            late_reply_ms,
        }) => {
            return exit_with(bus::serve_emulated_segment(
                &on,
                drives,
                strict_drives,
                late_reply_ms,
            ));
        }
        Some(Cmd::Serve) | None => cli.serve,
    };
    tracing_subscriber::fmt()
        .with_target(false)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stdout()))
        .with_max_level(tracing::Level::INFO)
        .init();
    if let Err(e) = serve(args) {
        tracing::error!("{e}");
        eprintln!("motiond: {e}");
        std::process::exit(1);
    }
}

fn exit_with(r: Result<(), String>) {
    if let Err(e) = r {
        eprintln!("motiond: {e}");
        std::process::exit(1);
    }
}

enum Admin {
    User(UserCmd),
    Token(TokenCmd),
}

/// Reads a password: a line of standard input, without echo when it is a terminal.
fn read_password(prompt: &str) -> Result<String, String> {
    use std::io::{BufRead, IsTerminal, Write};
    let stdin = std::io::stdin();
    let tty = stdin.is_terminal();
    // SAFETY: termios of fd 0, restored below.
    let mut old: libc::termios = unsafe { std::mem::zeroed() };
    if tty {
        eprint!("{prompt}: ");
        let _ = std::io::stderr().flush();
        unsafe {
            if libc::tcgetattr(0, &mut old) == 0 {
                let mut quiet = old;
                quiet.c_lflag &= !libc::ECHO;
                libc::tcsetattr(0, libc::TCSANOW, &quiet);
            }
        }
    }
    let mut line = String::new();
    let r = stdin.lock().read_line(&mut line);
    if tty {
        unsafe { libc::tcsetattr(0, libc::TCSANOW, &old) };
        eprintln!();
    }
    r.map_err(|e| format!("cannot read the password: {e}"))?;
    let pw = line.trim_end_matches(['\n', '\r']).to_owned();
    if pw.is_empty() {
        return Err("no password given on standard input".into());
    }
    Ok(pw)
}

/// `motiond user …` / `motiond token …` on the database of `--db`.
fn admin_command(args: &ServeArgs, cmd: Admin) -> Result<(), String> {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| e.to_string())?;
    rt.block_on(async {
        let db = store::open(&args.db).await.map_err(|e| {
            if e.contains("locked") {
                format!("{e}\n(is motiond running on {}? stop it, or use the API: /api/v1/users, /api/v1/tokens)", args.db)
            } else {
                e
            }
        })?;
        let auth = auth::Auth::load(db.clone(), std::time::Duration::from_secs(3600), false).await?;
        let audit = |action: &str, target: &str| store::AuditEntry {
            at: store::now_rfc3339(),
            client_id: Some("cli".into()),
            action: action.into(),
            target: Some(target.into()),
            outcome: Some("committed".into()),
            ..Default::default()
        };
        let e = |e: error::AppError| e.problem().detail;
        match cmd {
            Admin::User(UserCmd::Add { name, admin, role }) => {
                let role = if admin { auth::Role::Admin } else { role.unwrap_or(auth::Role::Viewer) };
                let pw = read_password(&format!("password for {name}"))?;
                auth.add_user(&name, role, &pw, audit("user.create", &name)).await.map_err(e)?;
                println!("user {name} ({}) added; authentication is on", role.as_str());
            }
            Admin::User(UserCmd::List) => {
                for u in auth.users() {
                    println!("{}\t{}\t{}", u.name, u.role.as_str(), u.created_at);
                }
            }
            Admin::User(UserCmd::Passwd { name }) => {
                let pw = read_password(&format!("new password for {name}"))?;
                auth.update_user(&name, None, Some(&pw), None, audit("user.password", &name)).await.map_err(e)?;
                println!("password of {name} set; its sessions ended");
            }
            Admin::User(UserCmd::Delete { name }) => {
                auth.delete_user(&name, audit("user.delete", &name)).await.map_err(e)?;
                println!("user {name} deleted");
            }
            Admin::Token(TokenCmd::Add { name, role, expires_in_days }) => {
                let t = auth
                    .add_token(&name, role, expires_in_days, "cli", audit("token.create", &name))
                    .await
                    .map_err(e)?;
                eprintln!("token {name} ({}) created; it is shown once:", role.as_str());
                println!("{}", t.token);
            }
            Admin::Token(TokenCmd::List) => {
                for t in auth.tokens() {
                    println!(
                        "{}\t{}\t{}\tcreated {}\tlast used {}\t{}",
                        t.id,
                        t.name,
                        t.role.as_str(),
                        t.created_at,
                        t.last_used_at.as_deref().unwrap_or("never"),
                        t.revoked_at.map_or("active".into(), |r| format!("revoked {r}"))
                    );
                }
            }
            Admin::Token(TokenCmd::Revoke { name }) => {
                let Some(t) = auth.tokens().into_iter().find(|t| t.name == name) else {
                    return Err(format!("no token {name}"));
                };
                auth.revoke_token(t.id, audit("token.revoke", &name)).await.map_err(e)?;
                println!("token {name} revoked");
            }
        }
        db.close().await;
        Ok(())
    })
}

fn serve(args: ServeArgs) -> Result<(), String> {
    // A file-size limit must fail the write (SQLite reports it, the request gets 503), not
    // kill the process.
    // SAFETY: setting a signal disposition to SIG_IGN before any thread is started.
    unsafe { libc::signal(libc::SIGXFSZ, libc::SIG_IGN) };
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .thread_name("motiond-async")
        .enable_all()
        .build()
        .map_err(|e| format!("cannot start the async runtime: {e}"))?;
    rt.block_on(serve_async(args))
}

async fn serve_async(args: ServeArgs) -> Result<(), String> {
    let machine = startup::start_machine(&args).await?;
    let (state, remote) = (machine.state.clone(), machine.remote);
    let tls = if machine.tls_on {
        Some(tls::acceptor(&args)?)
    } else {
        None
    };
    let listener = tokio::net::TcpListener::bind(args.listen)
        .await
        .map_err(|e| format!("cannot listen on {}: {e}", args.listen))?;
    let local = listener.local_addr().map_err(|e| e.to_string())?;
    let scheme = if tls.is_some() { "https" } else { "http" };
    tracing::info!("listening on {scheme}://{local} (UI /, API /api/v1, docs /docs)");
    let mut public_names = args.public_names.clone();
    if remote && !args.listen.ip().is_unspecified() {
        // Clients that use the address itself are served; names must be given.
        public_names.push(api::guard::parse_public_name(
            &args.listen.ip().to_string(),
        )?);
    }
    if remote && args.public_names.is_empty() {
        tracing::warn!(
            "listening on {} without --public-name: browsers and clients must use a name this server \
             serves in Host (others get 421); give the machine's name with --public-name",
            args.listen
        );
    }
    let guard = api::guard::Guard {
        public_names,
        allowed_origins: args.allowed_origins.clone(),
    };
    if !guard.public_names.is_empty() {
        tracing::info!("also serving the names {}", guard.public_names.join(", "));
    }
    if !guard.allowed_origins.is_empty() {
        tracing::info!(
            "pages of {} may change things here",
            guard.allowed_origins.join(", ")
        );
    }
    let ws = api::ws::Settings {
        ping_after: std::time::Duration::from_secs_f64(args.ws_ping_s),
    };
    let read_timeout = std::time::Duration::from_secs_f64(args.read_timeout_s);
    let app = api::router(state.clone(), Arc::new(guard), ws)
        // A body announced but not sent holds nothing for long (Content-Length: 10 GB and 14 bytes).
        .layer(tower_http::timeout::RequestBodyTimeoutLayer::new(
            read_timeout,
        ));
    let (stopping_tx, stopping) = tokio::sync::watch::channel(false);
    tokio::spawn(async move {
        shutdown_signal().await;
        let _ = stopping_tx.send(true);
    });
    let max = args.max_connections as usize;
    let permits = Arc::new(tokio::sync::Semaphore::new(max));
    accept_loop(listener, app, permits.clone(), read_timeout, stopping, tls).await;
    // The connections end gracefully; open websockets would hold them forever: 2 s at most.
    if tokio::time::timeout(
        std::time::Duration::from_secs(2),
        permits.acquire_many(max as u32),
    )
    .await
    .is_err()
    {
        tracing::warn!("closing the connections still open");
    }
    tracing::info!("shutting down");
    drop(state);
    machine.shut_down().await;
    Ok(())
}

/// How long a connection must have been idle before a new client may close it to make room.
const IDLE_BEFORE_CLOSED: std::time::Duration = std::time::Duration::from_secs(1);

/// An open connection as the accept loop knows it: whether a request of it is being served,
/// when it last did something, and how to close it.
struct OpenConn {
    /// Requests being served (0: reading headers, or idle between requests).
    busy: std::sync::atomic::AtomicUsize,
    /// Opened, or its last request answered (for the oldest idle one to go first).
    last_active: std::sync::Mutex<std::time::Instant>,
    /// Chosen to make room (not chosen again while it closes).
    closing: std::sync::atomic::AtomicBool,
    close: tokio::sync::Notify,
}

/// The open connections (by a running number), for making room under a flood.
#[derive(Default)]
struct OpenConns {
    next: std::sync::atomic::AtomicU64,
    map: std::sync::Mutex<std::collections::HashMap<u64, Arc<OpenConn>>>,
}

impl OpenConns {
    fn open(self: &Arc<Self>) -> (u64, Arc<OpenConn>) {
        let id = self.next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let c = Arc::new(OpenConn {
            busy: Default::default(),
            last_active: std::sync::Mutex::new(std::time::Instant::now()),
            closing: Default::default(),
            close: tokio::sync::Notify::new(),
        });
        self.map.lock().unwrap().insert(id, c.clone());
        (id, c)
    }

    /// Closes the connection that has been idle longest (no request in service: a client
    /// sending headers slowly, or a keep-alive connection between requests) — one idle for
    /// [`IDLE_BEFORE_CLOSED`] at least, so that a burst of new clients do not close each
    /// other before they could send a request. `false` when there is none.
    fn close_oldest_idle(&self) -> bool {
        let map = self.map.lock().unwrap();
        let now = std::time::Instant::now();
        let oldest = map
            .values()
            .filter(|c| {
                c.busy.load(std::sync::atomic::Ordering::Relaxed) == 0
                    && !c.closing.load(std::sync::atomic::Ordering::Relaxed)
                    && now.duration_since(*c.last_active.lock().unwrap()) >= IDLE_BEFORE_CLOSED
            })
            .min_by_key(|c| *c.last_active.lock().unwrap());
        match oldest {
            Some(c) => {
                c.closing.store(true, std::sync::atomic::Ordering::Relaxed);
                // Stored if the connection's task is not waiting yet: it closes when it does.
                c.close.notify_one();
                true
            }
            None => false,
        }
    }
}

/// Serves connections until shutdown: at most `max` at once. One more makes room by closing
/// the connection idle longest (for a second at least) — one that has not finished sending a
/// request's headers, or a keep-alive connection between requests — so that a flood of
/// half-sent requests cannot lock a real client out (decision 69); when there is none, one
/// more is answered 503 (`Retry-After: 1`) and closed. A client that takes longer than `read_timeout` to send a
/// request's headers or the next request is disconnected. The client's address reaches the
/// handlers as axum's `ConnectInfo`.
async fn accept_loop(
    listener: tokio::net::TcpListener,
    app: axum::Router,
    permits: Arc<tokio::sync::Semaphore>,
    read_timeout: std::time::Duration,
    mut stopping: tokio::sync::watch::Receiver<bool>,
    tls: Option<tokio_rustls::TlsAcceptor>,
) {
    use hyper_util::rt::TokioIo;
    use std::sync::atomic::Ordering::Relaxed;
    use tokio::io::AsyncWriteExt;
    let max = permits.available_permits();
    let conns = Arc::new(OpenConns::default());
    loop {
        let (mut stream, addr) = tokio::select! {
            r = listener.accept() => match r {
                Ok(x) => x,
                Err(e) => {
                    // Out of file descriptors and the like: wait a moment instead of spinning.
                    tracing::warn!("accept failed: {e}");
                    tokio::time::sleep(std::time::Duration::from_millis(50)).await;
                    continue;
                }
            },
            _ = async { let _ = stopping.wait_for(|s| *s).await; } => return,
        };
        let permit = match permits.clone().try_acquire_owned() {
            Ok(p) => Some(p),
            // Full: the connection idle longest gives its place (its task ends at once and
            // gives the permit back).
            Err(_) if conns.close_oldest_idle() => tokio::time::timeout(
                std::time::Duration::from_secs(1),
                permits.clone().acquire_owned(),
            )
            .await
            .ok()
            .and_then(Result::ok),
            Err(_) => None,
        };
        let Some(permit) = permit else {
            tokio::spawn(async move {
                let body = format!(
                    r#"{{"type":"urn:motiond:problem:too_many_connections","title":"Service unavailable","status":503,"detail":"motiond serves at most {max} connections at once, none of them idle for a second; try again","code":"too_many_connections"}}"#
                );
                let head = format!(
                    "HTTP/1.1 503 Service Unavailable\r\ncontent-type: application/problem+json\r\ncontent-length: {}\r\nretry-after: 1\r\nconnection: close\r\n\r\n",
                    body.len()
                );
                let _ = stream.write_all(head.as_bytes()).await;
                let _ = stream.write_all(body.as_bytes()).await;
                let _ = stream.shutdown().await;
            });
            continue;
        };
        let (conn_id, conn) = conns.open();
        let served = conn.clone();
        let app = app.clone();
        let svc = tower::service_fn(move |mut r: hyper::Request<hyper::body::Incoming>| {
            r.extensions_mut().insert(axum::extract::ConnectInfo(addr));
            let (app, conn) = (app.clone(), served.clone());
            async move {
                conn.busy.fetch_add(1, Relaxed);
                let answer = tower::ServiceExt::oneshot(app, r).await;
                *conn.last_active.lock().unwrap() = std::time::Instant::now();
                conn.busy.fetch_sub(1, Relaxed);
                answer
            }
        });
        let stop = stopping.clone();
        let tls = tls.clone();
        let conns = conns.clone();
        tokio::spawn(async move {
            let _permit = permit;
            let serve = async {
                match tls {
                    None => serve_connection(TokioIo::new(stream), svc, read_timeout, stop).await,
                    Some(acceptor) => {
                        // The handshake is bounded like a request's headers.
                        match tokio::time::timeout(read_timeout, acceptor.accept(stream)).await {
                            Ok(Ok(s)) => {
                                serve_connection(TokioIo::new(s), svc, read_timeout, stop).await
                            }
                            Ok(Err(e)) => tracing::debug!("TLS handshake with {addr} failed: {e}"),
                            Err(_) => tracing::debug!("TLS handshake with {addr} timed out"),
                        }
                    }
                }
            };
            let mut serve = std::pin::pin!(serve);
            loop {
                tokio::select! {
                    _ = &mut serve => break,
                    // Closed to make room — never while one of its requests is served (it
                    // may have started one since it was chosen).
                    _ = conn.close.notified() => {
                        if conn.busy.load(Relaxed) == 0 {
                            break;
                        }
                        // It took a request meanwhile: it may be chosen again once idle.
                        conn.closing.store(false, Relaxed);
                    }
                }
            }
            conns.map.lock().unwrap().remove(&conn_id);
        });
    }
}

/// One HTTP/1.1 connection (plain or TLS) until it ends or motiond stops.
async fn serve_connection<I, S>(
    io: I,
    svc: S,
    read_timeout: std::time::Duration,
    mut stop: tokio::sync::watch::Receiver<bool>,
) where
    I: hyper::rt::Read + hyper::rt::Write + Unpin + Send + 'static,
    S: tower::Service<
            hyper::Request<hyper::body::Incoming>,
            Response = axum::response::Response,
            Error = std::convert::Infallible,
        > + Clone
        + Send
        + 'static,
    S::Future: Send + 'static,
{
    use hyper_util::rt::TokioTimer;
    let mut http = hyper::server::conn::http1::Builder::new();
    // Requests beyond the guard's limits (api/guard.rs) are refused there with a
    // problem; hyper's buffer bounds what is read at all.
    http.timer(TokioTimer::new())
        .header_read_timeout(read_timeout)
        .max_buf_size(64 * 1024);
    let conn = http
        .serve_connection(io, hyper_util::service::TowerToHyperService::new(svc))
        .with_upgrades();
    let mut conn = std::pin::pin!(conn);
    tokio::select! {
        _ = conn.as_mut() => {}
        _ = async { let _ = stop.wait_for(|s| *s).await; } => {
            conn.as_mut().graceful_shutdown();
            let _ = conn.await;
        }
    }
}

async fn shutdown_signal() {
    let ctrl_c = tokio::signal::ctrl_c();
    let mut term = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
        .expect("SIGTERM handler");
    tokio::select! {
        _ = ctrl_c => {},
        _ = term.recv() => {},
    }
}
