//! motiond, the appliance: the cycle thread, the REST + websocket API and the SQLite store.
//!
//! Map: [`cycle`] (the real-time thread and its queues), [`app`] (the async side's state and
//! the pump between the two), [`api`] (HTTP and websocket; [`api::blocks`] is the catalogue of
//! function blocks), [`service`] (the rules of each request), [`store`] (SQLite), [`error`]
//! (`AppError`), [`model`] (DTOs), [`sim`] / [`params`] (adapters to `drives` and
//! `motion::params`).
//!
//! Every function block an axis takes is a catalogue entry; the REST endpoint, the websocket
//! method and the OpenAPI operation all come from it:
//!
//! ```
//! use server::api::blocks::{self, Role};
//!
//! let block = blocks::find("move-absolute").expect("MC_MoveAbsolute is in the catalogue");
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
pub mod cycle;
pub mod error;
pub mod metrics;
pub mod model;
pub mod params;
pub mod scope;
pub mod service;
pub mod sim;
pub mod stats;
pub mod store;
pub mod ui;

use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Instant;

use clap::{Parser, Subcommand};

use crate::app::{AppState, AxisEntry, SystemInfo};
use crate::model::{AxisConfigDto, AxisDynamics, ModuloConfig, SoftLimits};
use crate::params::ParamValue;
use crate::sim::{LimitSwitches, SimDriveConfig};
use drives::DriveConfig;

#[derive(Parser, Debug)]
#[command(
    name = "motiond",
    version,
    about = "Motion controller appliance: PLCopen axes over REST and websocket"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Cmd>,
    #[command(flatten)]
    pub serve: ServeArgs,
}

#[derive(Subcommand, Debug)]
pub enum Cmd {
    /// Run the appliance (the default). Its options may stand before or after `serve`.
    Serve,
    /// Print the OpenAPI document (what `openapi/openapi.json` must contain).
    Openapi,
    /// Print the websocket's AsyncAPI document (what `openapi/asyncapi.json` must contain).
    Asyncapi,
}

/// The options of `serve`. Global, so that `motiond --db m.db serve` and
/// `motiond serve --db m.db` mean the same (a systemd unit may write either).
#[derive(clap::Args, Debug, Clone)]
pub struct ServeArgs {
    /// Address to listen on: an IP address or `localhost` (bound to its loopback address), and a
    /// port. Only loopback addresses are allowed until authentication exists.
    #[arg(long, global = true, default_value = "127.0.0.1:8080", value_parser = parse_listen)]
    pub listen: SocketAddr,
    /// A host name (or address) motiond answers to besides loopback names and addresses, e.g.
    /// the name a reverse proxy forwards; any other `Host` is refused with 421 (DNS
    /// rebinding). Repeatable.
    #[arg(long = "public-name", global = true, value_name = "NAME", value_parser = api::guard::parse_public_name)]
    pub public_names: Vec<String>,
    /// A foreign web origin (`http://localhost:5173`) whose pages may change things here
    /// (commands, parameters, configuration, the websocket); other origins are refused with
    /// 403. Repeatable.
    #[arg(long = "allow-origin", global = true, value_name = "ORIGIN", value_parser = api::guard::parse_allow_origin)]
    pub allowed_origins: Vec<String>,
    /// SQLite database file (`:memory:` for a throw-away one).
    #[arg(long, global = true, default_value = "./motiond.db")]
    pub db: String,
    /// Cycle time in microseconds.
    #[arg(long, global = true, default_value_t = 1000, value_parser = clap::value_parser!(u32).range(250..=10_000))]
    pub cycle_us: u32,
    /// Seconds without anything from a websocket client before it is pinged, and then before
    /// its socket is closed if it does not answer (0.05–3600).
    #[arg(long = "ws-ping-s", global = true, value_name = "SECONDS", default_value_t = api::ws::DEFAULT_PING_S, value_parser = parse_ping)]
    pub ws_ping_s: f64,
    /// Seconds a client may take to send a request's headers, or its body, or to send the next
    /// request on an idle connection, before the connection is closed (1–600).
    #[arg(long = "read-timeout-s", global = true, value_name = "SECONDS", default_value_t = 30.0, value_parser = parse_read_timeout)]
    pub read_timeout_s: f64,
    /// Open HTTP connections at most (websockets included); one more is answered 503 and
    /// closed (8–100000).
    #[arg(long = "max-connections", global = true, value_name = "N", default_value_t = 512, value_parser = clap::value_parser!(u32).range(8..=100_000))]
    pub max_connections: u32,
    /// Do not create the demo axes on a new database.
    #[arg(long, global = true)]
    pub no_demo: bool,
    /// The built commissioning UI, served at `/` [default: `frontend/dist` in the current
    /// directory, else the one of the source tree motiond was built from].
    #[arg(long, global = true, value_name = "PATH")]
    pub ui_dir: Option<std::path::PathBuf>,
}

/// `--listen`: `IP:PORT`, `[IPv6]:PORT` or `localhost:PORT` (resolved, its loopback address
/// taken, IPv4 first).
fn parse_listen(s: &str) -> Result<SocketAddr, String> {
    if let Ok(a) = s.parse() {
        return Ok(a);
    }
    let bad = || format!("{s:?} is not IP:PORT or localhost:PORT");
    let (host, port) = s.rsplit_once(':').ok_or_else(bad)?;
    let port: u16 = port.parse().map_err(|_| bad())?;
    if !host.eq_ignore_ascii_case("localhost") {
        return Err(bad());
    }
    let mut addrs: Vec<SocketAddr> = std::net::ToSocketAddrs::to_socket_addrs(&(host, port))
        .map_err(|e| format!("cannot resolve {host}: {e}"))?
        .filter(|a| a.ip().is_loopback())
        .collect();
    addrs.sort_by_key(|a| !a.is_ipv4());
    addrs
        .first()
        .copied()
        .ok_or_else(|| format!("{host} does not resolve to a loopback address"))
}

/// `--ws-ping-s`: 0.05–3600 seconds.
fn parse_read_timeout(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (1.0..=600.0).contains(&v) => Ok(v),
        _ => Err(format!("{s:?} is not a number of seconds from 1 to 600")),
    }
}

fn parse_ping(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (0.05..=3600.0).contains(&v) => Ok(v),
        _ => Err(format!(
            "{s:?} is not a number of seconds from 0.05 to 3600"
        )),
    }
}

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

/// The demo machine: two linear axes with limit switches just outside their travel (so that a
/// homing search that misses the cam ends with homing_failed at a switch instead of running
/// forever; the switches only report, they do not fault the drive) and a rotary spindle.
pub fn demo_axes() -> Vec<AxisConfigDto> {
    let linear = |name: &str, limits: Option<SoftLimits>, switches: (f64, f64)| AxisConfigDto {
        name: name.into(),
        unit: "mm".into(),
        modulo: None,
        soft_limits: limits,
        dynamics: AxisDynamics {
            max_velocity: 500.0,
            acceleration: 2500.0,
            deceleration: 2500.0,
            jerk: 25000.0,
            jog_velocity_slow: 10.0,
            jog_velocity_fast: 100.0,
        },
        parameters: BTreeMap::from([(
            "AxisTargetPositionWindow".to_string(),
            ParamValue::Number(0.01),
        )]),
        drive: DriveConfig::Simulated(SimDriveConfig {
            limit_switches: LimitSwitches {
                negative: Some(switches.0),
                positive: Some(switches.1),
                fault_on_hit: false,
            },
            ..SimDriveConfig::default()
        }),
    };
    vec![
        // Travel 0–1000 mm (software limits), switches 5 mm beyond.
        linear(
            "x",
            Some(SoftLimits {
                min: 0.0,
                max: 1000.0,
            }),
            (-5.0, 1005.0),
        ),
        // No software limits; travel ±1000 mm between the switches.
        linear("y", None, (-1005.0, 1005.0)),
        AxisConfigDto {
            name: "spindle".into(),
            unit: "deg".into(),
            modulo: Some(ModuloConfig { period: 360.0 }),
            soft_limits: None,
            dynamics: AxisDynamics {
                max_velocity: 3600.0,
                acceleration: 18000.0,
                deceleration: 18000.0,
                jerk: 180000.0,
                jog_velocity_slow: 90.0,
                jog_velocity_fast: 720.0,
            },
            parameters: BTreeMap::new(),
            drive: DriveConfig::default(),
        },
    ]
}

fn serve(args: ServeArgs) -> Result<(), String> {
    if !args.listen.ip().is_loopback() {
        return Err(format!(
            "refusing to listen on {}: binding a non-loopback address requires authentication, which motiond \
             does not implement yet (DESIGN §6); use a loopback address such as 127.0.0.1:8080 \
             (and a reverse proxy with authentication for remote access)",
            args.listen
        ));
    }
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
    let db = store::open(&args.db).await?;
    if args.db == ":memory:" {
        tracing::info!("database :memory: (in memory: nothing is kept after exit)");
    } else {
        tracing::info!("database {} (WAL, synchronous=FULL)", args.db);
    }

    let cycle_time = args.cycle_us as f64 * 1e-6;
    let shared = Arc::new(cycle::Shared::new(args.cycle_us as u64 * 1000));
    let (input, output) = triple_buffer::triple_buffer(&cycle::Snapshot::default());
    let (grant_tx, grant_rx) = std::sync::mpsc::channel();
    let thread_shared = shared.clone();
    let cycle_thread = std::thread::Builder::new()
        .name("motiond-cycle".into())
        .spawn(move || {
            let bus = Box::new(drives::SimBus::new(cycle::MAX_AXES));
            let ct = cycle::CycleThread::new(cycle_time, bus, thread_shared, input);
            let _ = grant_tx.send(cycle::request_realtime(80));
            ct.run();
        })
        .map_err(|e| format!("cannot start the cycle thread: {e}"))?;
    let realtime = grant_rx
        .recv()
        .map_err(|_| "the cycle thread died at start-up".to_string())?;
    tracing::info!(
        "cycle thread: {} µs cycle; SCHED_FIFO {}, mlockall {}, pinned to {}",
        args.cycle_us,
        if realtime.sched_fifo {
            "granted"
        } else {
            "NOT granted"
        },
        if realtime.mlockall {
            "granted"
        } else {
            "NOT granted"
        },
        realtime
            .pinned_cpu
            .map_or("no CPU (not granted)".to_string(), |c| format!("CPU {c}"))
    );
    for n in &realtime.notes {
        tracing::warn!("real-time: {n} (running without it)");
    }

    // Above every id an earlier run may have acknowledged: those in the audit log and the
    // reserved mark (an acknowledged command whose audit row died with the process is below it).
    let first_id = store::max_command_id(&db)
        .await
        .map_err(|e| format!("cannot read the audit log: {e}"))?
        .max(
            store::command_ids_reserved(&db)
                .await
                .map_err(|e| format!("cannot read the database: {e}"))?,
        )
        + 1;
    let info = SystemInfo {
        version: env!("CARGO_PKG_VERSION"),
        cycle_time_s: cycle_time,
        listen: args.listen.to_string(),
        db: args.db.clone(),
        realtime,
        started: Instant::now(),
        ui_dir: ui::resolve_dir(args.ui_dir.as_deref()),
    };
    if ui::is_built(&info.ui_dir) {
        let dir = info.ui_dir.canonicalize();
        tracing::info!(
            "commissioning UI: {}",
            dir.as_deref().unwrap_or(&info.ui_dir).display()
        );
    } else {
        tracing::warn!(
            "commissioning UI not built (no index.html in {}): / shows how to build it \
             (`{}`, or start motiond with ./scripts/run.sh)",
            info.ui_dir.display(),
            ui::BUILD_COMMAND
        );
    }
    let (state, audit_rx) = AppState::new(shared.clone(), output, db.clone(), first_id, info);
    tokio::spawn(app::pump(state.clone()));
    let audit_task = tokio::spawn(app::audit_writer(
        db.clone(),
        audit_rx,
        state.audit_dropped.clone(),
    ));

    load_axes(&state, args.no_demo).await?;
    let cams = service::cams::load(&state).await?;
    if cams > 0 {
        tracing::info!("{cams} cam tables loaded");
    }

    let listener = tokio::net::TcpListener::bind(args.listen)
        .await
        .map_err(|e| format!("cannot listen on {}: {e}", args.listen))?;
    let local = listener.local_addr().map_err(|e| e.to_string())?;
    tracing::info!("listening on http://{local} (UI /, API /api/v1, docs /docs)");
    let guard = api::guard::Guard {
        public_names: args.public_names.clone(),
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
    accept_loop(listener, app, permits.clone(), read_timeout, stopping).await;
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
    shared
        .shutdown
        .store(true, std::sync::atomic::Ordering::Relaxed);
    let _ = cycle_thread.join();
    drop(state);
    audit_task.abort();
    db.close().await;
    Ok(())
}

/// Serves connections until shutdown: at most `max` at once (one more is answered 503 and
/// closed, so that a flood of idle connections cannot make motiond answer nobody), each closed
/// when a client takes longer than `read_timeout` to send a request's headers or the next
/// request. The client's address reaches the handlers as axum's `ConnectInfo`.
async fn accept_loop(
    listener: tokio::net::TcpListener,
    app: axum::Router,
    permits: Arc<tokio::sync::Semaphore>,
    read_timeout: std::time::Duration,
    mut stopping: tokio::sync::watch::Receiver<bool>,
) {
    use hyper_util::rt::{TokioIo, TokioTimer};
    use tokio::io::AsyncWriteExt;
    let max = permits.available_permits();
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
        let Ok(permit) = permits.clone().try_acquire_owned() else {
            tokio::spawn(async move {
                let body = format!(
                    r#"{{"type":"urn:motiond:problem:too_many_connections","title":"Service unavailable","status":503,"detail":"motiond serves at most {max} connections at once; try again","code":"too_many_connections"}}"#
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
        let svc = tower::ServiceExt::map_request(
            app.clone(),
            move |mut r: hyper::Request<hyper::body::Incoming>| {
                r.extensions_mut().insert(axum::extract::ConnectInfo(addr));
                r
            },
        );
        let mut stop = stopping.clone();
        tokio::spawn(async move {
            let _permit = permit;
            let mut http = hyper::server::conn::http1::Builder::new();
            // Requests beyond the guard's limits (api/guard.rs) are refused there with a
            // problem; hyper's buffer bounds what is read at all.
            http.timer(TokioTimer::new())
                .header_read_timeout(read_timeout)
                .max_buf_size(64 * 1024);
            let conn = http
                .serve_connection(
                    TokioIo::new(stream),
                    hyper_util::service::TowerToHyperService::new(svc),
                )
                .with_upgrades();
            let mut conn = std::pin::pin!(conn);
            tokio::select! {
                _ = conn.as_mut() => {}
                _ = async { let _ = stop.wait_for(|s| *s).await; } => {
                    conn.as_mut().graceful_shutdown();
                    let _ = conn.await;
                }
            }
        });
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

/// Loads the stored axes into the kernel, or creates the demo on a new database.
async fn load_axes(state: &Arc<AppState>, no_demo: bool) -> Result<(), String> {
    let db = &state.db;
    let stored = store::load_axes(db)
        .await
        .map_err(|e| format!("cannot read axes: {e}"))?;
    let initialised = store::meta(db, "initialised")
        .await
        .map_err(|e| e.to_string())?
        .is_some();
    if !initialised {
        store::mark_initialised(db)
            .await
            .map_err(|e| format!("cannot write the database: {e}"))?;
        if stored.is_empty() && !no_demo {
            for config in demo_axes() {
                let name = config.name.clone();
                let audit = store::AuditEntry {
                    at: store::now_rfc3339(),
                    action: "axis.create".into(),
                    target: Some(name.clone()),
                    client_id: Some("demo".into()),
                    ..Default::default()
                };
                service::axes::create(state, config, None, audit)
                    .await
                    .map_err(|e| format!("cannot create demo axis {name}: {}", e))?;
            }
            tracing::info!(
                "new database: created the demo axes x, y (linear, mm) and spindle (modulo 360°)"
            );
            return Ok(());
        }
    }
    let mut persistent: BTreeMap<i64, BTreeMap<u16, ParamValue>> = BTreeMap::new();
    for (axis, number, value) in store::load_persistent(db)
        .await
        .map_err(|e| e.to_string())?
    {
        match serde_json::from_str(&value) {
            Ok(v) => {
                persistent.entry(axis).or_default().insert(number, v);
            }
            Err(e) => tracing::warn!(
                "axis {axis}: persistent parameter {number} unreadable ({e}); ignored"
            ),
        }
    }
    for (slot, a) in stored.into_iter().enumerate() {
        let config: AxisConfigDto = serde_json::from_str(&a.config)
            .map_err(|e| format!("axis {} in the database is unreadable: {e}", a.name))?;
        let overlay = persistent.remove(&a.id).unwrap_or_default();
        let (p, axis, drive) = state
            .build_axis(a.id, &config, &overlay)
            .map_err(|e| format!("axis {} in the database is invalid: {e:?}", a.name))?;
        let slot = slot as u16;
        state
            .install_axis(slot, axis, drive, false)
            .await
            .map_err(|e| format!("cannot install axis {}: {e}", a.name))?;
        state.registry_write().axes.insert(
            a.id,
            AxisEntry {
                id: a.id,
                name: a.name,
                slot,
                config,
                params: p,
                persistent: overlay,
            },
        );
    }
    let n = state.registry.read().unwrap().axes.len();
    tracing::info!("{n} axes loaded from the database");
    Ok(())
}
