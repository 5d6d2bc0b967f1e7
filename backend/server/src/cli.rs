//! The command line: `motiond [serve]` and its options, and the administrative subcommands.

use std::net::SocketAddr;

use clap::{Parser, Subcommand};

use crate::{api, auth, bus};

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
    /// Acceptance tests of machine sequences as data, run in virtual time.
    Scenario {
        #[command(subcommand)]
        action: ScenarioCmd,
    },
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
        /// Drives on the segment (1–64).
        #[arg(long, default_value_t = bus::EMULATED_DRIVES, value_parser = clap::value_parser!(u32).range(1..=64))]
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
pub enum ScenarioCmd {
    /// Run scenario files, each on a fresh machine in virtual time (an in-memory database);
    /// exits 1 at the first failed expectation, with what, where, expected and got.
    Run {
        /// Scenario files (JSON, `motiond scenario schema`).
        #[arg(required = true)]
        files: Vec<std::path::PathBuf>,
        /// Write each scenario's scope recording as CSV: to this file (one scenario) or into
        /// this directory (several: FILE.csv each).
        #[arg(long, value_name = "PATH")]
        csv: Option<std::path::PathBuf>,
    },
    /// Print the JSON Schema of a scenario file.
    Schema,
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
    /// The number of drives on `--bus emulated`'s segment (4–64): the demo's axes use the
    /// first four, the others wait for axes configured on them (`drive.subdevice`).
    #[arg(long = "emulated-drives", global = true, value_name = "N", default_value_t = bus::EMULATED_DRIVES, value_parser = clap::value_parser!(u32).range(4..=64))]
    pub emulated_drives: u32,
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
    /// The clock the cycle runs on: `real` (the default: one cycle per cycle time), `virtual`
    /// (cycles advance only when a client asks: `POST /api/v1/clock/advance`) or `fast` /
    /// `fast=FACTOR` (continuously, as fast as the machine can or at FACTOR × real time).
    /// Virtual time needs the simulated bus.
    #[arg(long, global = true, value_name = "MODE", default_value = "real", value_parser = crate::clock::parse_mode)]
    pub clock: crate::clock::Mode,
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
