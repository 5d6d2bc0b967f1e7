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
pub mod auth;
pub mod bus;
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
pub mod tls;
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
    /// Manage users in the database given with `--db` (while no motiond runs on it; use the
    /// API's `/api/v1/users` otherwise). The first user turns authentication on.
    User {
        #[command(subcommand)]
        action: UserCmd,
    },
    /// Manage API tokens for machines in the database given with `--db`.
    Token {
        #[command(subcommand)]
        action: TokenCmd,
    },
    /// Serve an emulated EtherCAT segment of CiA-402 servo drives on a network interface (a
    /// raw socket; `CAP_NET_RAW`), for trying `--bus ethercat` without hardware: one end of a
    /// veth pair here, `motiond --bus ethercat --interface` on the other. Runs until stopped.
    EmulateSegment {
        /// The interface to answer frames on.
        #[arg(long = "on", value_name = "IFACE")]
        on: String,
        /// Drives on the segment (1–16).
        #[arg(long, default_value_t = bus::EMULATED_DRIVES, value_parser = clap::value_parser!(u32).range(1..=16))]
        drives: u32,
        /// Drives like many not written by motiond's authors: no touch probe (0x60B8–0x60BB)
        /// and no digital inputs (0x60FD) in the dictionary; any mapping write is taken and
        /// the mapping checked only at PRE-OP → SAFE-OP (AL status code 0x001D/0x001E).
        #[arg(long)]
        strict_drives: bool,
        /// One answer in 100 comes this many ms after its frame (a link slow now and then:
        /// more than the PDU timeout, and motiond counts late replies and drops them).
        #[arg(long, value_name = "MS", value_parser = clap::value_parser!(u32).range(1..=1000))]
        late_reply_ms: Option<u32>,
    },
}

#[derive(Subcommand, Debug)]
pub enum UserCmd {
    /// Add a user; the password is read from standard input (one line; asked for without
    /// echo on a terminal).
    Add {
        name: String,
        /// Make the user an admin (the first user must be one).
        #[arg(long, conflicts_with = "role")]
        admin: bool,
        /// viewer, operator, engineer or admin.
        #[arg(long, value_parser = parse_role)]
        role: Option<auth::Role>,
    },
    /// List the users and their roles.
    List,
    /// Set a user's password (read from standard input); ends its sessions.
    Passwd { name: String },
    /// Delete a user (never the last admin).
    Delete { name: String },
}

#[derive(Subcommand, Debug)]
pub enum TokenCmd {
    /// Create an API token and print it (the only time it is shown).
    Add {
        name: String,
        /// viewer, operator, engineer or admin.
        #[arg(long, value_parser = parse_role)]
        role: auth::Role,
        /// Days until it expires; never when left out.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=3650))]
        expires_in_days: Option<u32>,
    },
    /// List the tokens (never their secrets).
    List,
    /// Revoke a token by name.
    Revoke { name: String },
}

fn parse_role(s: &str) -> Result<auth::Role, String> {
    auth::Role::parse(s).ok_or_else(|| format!("{s:?} is not viewer, operator, engineer or admin"))
}

/// The options of `serve`. Global, so that `motiond --db m.db serve` and
/// `motiond serve --db m.db` mean the same (a systemd unit may write either).
#[derive(clap::Args, Debug, Clone)]
pub struct ServeArgs {
    /// Address to listen on: an IP address or `localhost` (bound to its loopback address), and a
    /// port. A non-loopback address (`0.0.0.0:8443`) needs authentication (a user must exist)
    /// and is served over TLS only.
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
    /// One holder commands motion at a time (`POST /api/v1/control`); `false` lets every
    /// operator command at any time (single-client plants, tests).
    #[arg(long, global = true, value_name = "BOOL", default_value_t = true, action = clap::ArgAction::Set)]
    pub control_lease: bool,
    /// Hours a browser session lasts from its login (1–720).
    #[arg(long, global = true, value_name = "HOURS", default_value_t = 12, value_parser = clap::value_parser!(u32).range(1..=720))]
    pub session_hours: u32,
    /// Serve HTTPS with this certificate chain (PEM); with `--tls-key`.
    #[arg(long, global = true, value_name = "PEM", requires = "tls_key")]
    pub tls_cert: Option<std::path::PathBuf>,
    /// The private key of `--tls-cert` (PEM).
    #[arg(long, global = true, value_name = "PEM", requires = "tls_cert")]
    pub tls_key: Option<std::path::PathBuf>,
    /// Serve HTTPS also on a loopback address; without `--tls-cert`, with a self-signed
    /// certificate made on first start and kept beside the database (its fingerprint is logged).
    /// A non-loopback `--listen` implies it.
    #[arg(long, global = true)]
    pub tls: bool,
    /// Do not create the demo axes on a new database.
    #[arg(long, global = true)]
    pub no_demo: bool,
    /// The drive bus: `simulated` drives (the default), `ethercat` (CiA-402 drives on
    /// `--interface`; needs `CAP_NET_RAW`), or `emulated` (an emulated EtherCAT segment of
    /// CiA-402 drives in this process: EtherCAT without hardware).
    #[arg(long, global = true, value_enum, default_value = "simulated")]
    pub bus: bus::BusKind,
    /// The network interface of the EtherCAT segment (`--bus ethercat`).
    #[arg(long, global = true, value_name = "IFACE")]
    pub interface: Option<String>,
    /// `--bus emulated` with drives like many not written by motiond's authors: no touch probe
    /// (0x60B8–0x60BB) and no digital inputs (0x60FD), the mapping checked only at SAFE-OP
    /// (as `emulate-segment --strict-drives`).
    #[arg(long = "emulated-strict-drives", global = true)]
    pub emulated_strict_drives: bool,
    /// Lost frames or wrong working counters in a row after which every axis of the EtherCAT
    /// bus stops into ErrorStop (1–1000).
    #[arg(long = "bus-max-errors", global = true, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub bus_max_errors: u32,
    /// How long an EtherCAT frame may take to come back before it is sent again (twice) and
    /// then counted as lost, in ms (1–1000) [default: four cycles, at least 10 ms].
    #[arg(long = "bus-timeout-ms", global = true, value_name = "MS", value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub bus_timeout_ms: Option<u32>,
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
            jog_deadman_max: 1.0,
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
        position_compensation_table: None,
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
                jog_deadman_max: 1.0,
            },
            parameters: BTreeMap::new(),
            drive: DriveConfig::default(),
            position_compensation_table: None,
        },
    ]
}

/// The demo machine on the emulated EtherCAT segment: each axis's drive is the emulated
/// CiA-402 servo at its position (1 µm per increment on the linear axes, 0.01° on the spindle).
fn on_emulated_drives(axes: &mut [AxisConfigDto]) {
    for (i, a) in axes.iter_mut().enumerate() {
        a.drive = DriveConfig::Cia402(drives::cia402::Cia402Config::csp(
            i as u16,
            if a.modulo.is_some() { 100.0 } else { 1000.0 },
        ));
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
    let db = store::open(&args.db).await?;
    if args.db == ":memory:" {
        tracing::info!("database :memory: (in memory: nothing is kept after exit)");
    } else {
        tracing::info!("database {} (WAL, synchronous=FULL)", args.db);
    }

    let cycle_time = args.cycle_us as f64 * 1e-6;
    // The bus first: an EtherCAT segment is brought up to OP before the cycle starts.
    let (bus, bus_handle) = {
        let (kind, iface, strict) = (
            args.bus,
            args.interface.clone(),
            args.emulated_strict_drives,
        );
        let (cycle, max, timeout) = (
            std::time::Duration::from_micros(args.cycle_us as u64),
            args.bus_max_errors,
            args.bus_timeout_ms
                .map(|ms| std::time::Duration::from_millis(ms as u64)),
        );
        tokio::task::spawn_blocking(move || {
            bus::start(
                kind,
                iface.as_deref(),
                strict,
                cycle,
                max,
                timeout,
                cycle::MAX_AXES,
            )
        })
        .await
        .map_err(|e| format!("the bus start-up failed: {e}"))?
        .map_err(|e| format!("the {} bus did not come up: {e}", args.bus.name()))?
    };
    let shared = Arc::new(cycle::Shared::new(args.cycle_us as u64 * 1000));
    let (input, output) = triple_buffer::triple_buffer(&cycle::Snapshot::default());
    let (grant_tx, grant_rx) = std::sync::mpsc::channel();
    let thread_shared = shared.clone();
    let cycle_thread = std::thread::Builder::new()
        .name("motiond-cycle".into())
        .spawn(move || {
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
        bus: bus_handle,
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
    let remote = !args.listen.ip().is_loopback();
    let tls_on = remote || args.tls || args.tls_cert.is_some();
    let auth = Arc::new(
        auth::Auth::load(
            db.clone(),
            std::time::Duration::from_secs(args.session_hours as u64 * 3600),
            tls_on,
        )
        .await?,
    );
    first_admin_from_env(&auth).await?;
    if remote && !auth.enabled() {
        return Err(format!(
            "refusing to listen on {}: a non-loopback address needs authentication, and no user exists; \
             create an admin first (`motiond --db {} user add --admin NAME`, password on stdin, or \
             MOTIOND_ADMIN_USER and MOTIOND_ADMIN_PASSWORD on first start)",
            args.listen, args.db
        ));
    }
    if auth.enabled() {
        tracing::info!(
            "authentication on: {} users; browser sessions last {} h",
            auth.users().len(),
            args.session_hours
        );
    } else {
        tracing::info!("authentication off (no user exists): every local client may act");
    }
    let tls = if tls_on {
        Some(tls::acceptor(&args)?)
    } else {
        None
    };
    let (state, audit_rx) = AppState::new(
        shared.clone(),
        output,
        db.clone(),
        first_id,
        info,
        auth,
        args.control_lease,
    );
    tokio::spawn(app::pump(state.clone()));
    let audit_task = tokio::spawn(app::audit_writer(
        db.clone(),
        audit_rx,
        state.audit_dropped.clone(),
    ));

    load_axes(&state, args.no_demo).await?;
    if let Some(notice) = api::bus::idle_drives_notice(&state) {
        tracing::warn!("{notice}");
    }
    let cams = service::cams::load(&state).await?;
    if cams > 0 {
        tracing::info!("{cams} cam tables loaded");
    }

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
    shared
        .shutdown
        .store(true, std::sync::atomic::Ordering::Relaxed);
    let _ = cycle_thread.join();
    drop(state);
    audit_task.abort();
    db.close().await;
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

/// The first admin, on a database without users, from `MOTIOND_ADMIN_USER` and
/// `MOTIOND_ADMIN_PASSWORD` (for images and unattended installs; ignored once a user exists).
async fn first_admin_from_env(auth: &auth::Auth) -> Result<(), String> {
    let (Ok(name), Ok(password)) = (
        std::env::var("MOTIOND_ADMIN_USER"),
        std::env::var("MOTIOND_ADMIN_PASSWORD"),
    ) else {
        return Ok(());
    };
    if auth.enabled() {
        return Ok(());
    }
    let audit = store::AuditEntry {
        at: store::now_rfc3339(),
        client_id: Some("environment".into()),
        action: "user.create".into(),
        target: Some(name.clone()),
        outcome: Some("committed".into()),
        ..Default::default()
    };
    auth.add_user(&name, auth::Role::Admin, &password, audit)
        .await
        .map_err(|e| format!("MOTIOND_ADMIN_USER: {}", e.problem().detail))?;
    tracing::info!("created the admin {name} from MOTIOND_ADMIN_USER; authentication is on");
    Ok(())
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
            let mut demo = demo_axes();
            if state.info.bus.kind == bus::BusKind::Emulated {
                on_emulated_drives(&mut demo);
            }
            for config in demo {
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
