//! Start-up: the machine without its listener (database, bus, cycle thread, the async side's
//! state, the stored axes, cam tables and groups), for `serve` and `motiond scenario run`.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

use crate::app::{AppState, AxisEntry, SystemInfo};
use crate::cli::ServeArgs;
use crate::params::ParamValue;
use crate::{api, app, auth, bus, clock, cycle, model, service, store};

/// The machine without its listener: the database, the bus, the cycle thread, the async side's
/// state with its pump and audit writer, the axes, cam tables and groups loaded. `serve` adds
/// the HTTP listener; `motiond scenario run` calls the router in-process.
pub struct Machine {
    pub state: Arc<AppState>,
    shared: Arc<cycle::Shared>,
    cycle_thread: std::thread::JoinHandle<()>,
    audit_task: tokio::task::JoinHandle<()>,
    db: sqlx::SqlitePool,
    /// Served over TLS (a non-loopback address, or asked for).
    pub tls_on: bool,
    /// `--listen` is not a loopback address.
    pub remote: bool,
}

impl Machine {
    /// Stops the cycle thread, lets the audit writer go and closes the database.
    pub async fn shut_down(self) {
        self.shared
            .shutdown
            .store(true, std::sync::atomic::Ordering::Relaxed);
        let _ = self.cycle_thread.join();
        drop(self.state);
        self.audit_task.abort();
        self.db.close().await;
    }
}

pub async fn start_machine(args: &ServeArgs) -> Result<Machine, String> {
    if args.clock.is_virtual() && args.bus != bus::BusKind::Simulated {
        // Real drives (and the emulated segment's frames) run on their own time.
        return Err(format!(
            "--clock {} needs the simulated bus: drives on EtherCAT run in real time (use --bus simulated)",
            args.clock.name()
        ));
    }
    let db = store::open(&args.db).await?;
    if args.db == ":memory:" {
        tracing::info!("database :memory: (in memory: nothing is kept after exit)");
    } else {
        tracing::info!("database {} (WAL, synchronous=FULL)", args.db);
    }

    let cycle_time = args.cycle_us as f64 * 1e-6;
    // The bus first: an EtherCAT segment is brought up to OP before the cycle starts.
    let (bus, bus_handle) = {
        let (kind, iface, emulation) = (
            args.bus,
            args.interface.clone(),
            bus::Emulation {
                drives: args.emulated_drives,
                strict: args.emulated_strict_drives,
            },
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
                emulation,
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
    let period_ns = args.cycle_us as u64 * 1000;
    let pace_ns = match args.clock {
        clock::Mode::Fast(Some(factor)) => (period_ns as f64 / factor) as u64,
        _ => 0,
    };
    let shared = Arc::new(cycle::Shared::with_clock(
        period_ns,
        args.clock.is_virtual(),
        pace_ns,
    ));
    let (input, output) = triple_buffer::triple_buffer(&cycle::Snapshot::default());
    let (grant_tx, grant_rx) = std::sync::mpsc::channel();
    let thread_shared = shared.clone();
    let virtual_time = args.clock.is_virtual();
    let cycle_thread = std::thread::Builder::new()
        .name("motiond-cycle".into())
        .spawn(move || {
            let ct = cycle::CycleThread::new(cycle_time, bus, thread_shared, input);
            if virtual_time {
                // Nothing waits for a deadline: no real-time priority (a thread running
                // cycles back to back at SCHED_FIFO would starve the API).
                let _ = grant_tx.send(cycle::RealtimeGrant {
                    notes: vec!["virtual time: no real-time scheduling asked for".into()],
                    ..Default::default()
                });
                ct.run_virtual();
            } else {
                let _ = grant_tx.send(cycle::request_realtime(80));
                ct.run();
            }
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
        ui_dir: api::ui::resolve_dir(args.ui_dir.as_deref()),
        bus: bus_handle,
    };
    if api::ui::is_built(&info.ui_dir) {
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
            api::ui::BUILD_COMMAND
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
    let (state, audit_rx) = AppState::new(
        shared.clone(),
        output,
        db.clone(),
        first_id,
        info,
        auth,
        args.control_lease,
        clock::Clock::new(args.clock, shared.clone()),
    );
    if args.clock.is_virtual() {
        tracing::info!(
            "clock: {} (virtual time: {}; timestamps count from 1970-01-01T00:00:00Z)",
            args.clock.name(),
            match args.clock {
                clock::Mode::Fast(Some(f)) => format!("{f} × real time"),
                clock::Mode::Fast(None) => "as fast as the machine can".into(),
                _ => "cycles advance on POST /api/v1/clock/advance".into(),
            }
        );
    }
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
    let groups = service::groups::load(&state).await?;
    if groups > 0 {
        tracing::info!("{groups} axis groups loaded (disabled)");
    }

    Ok(Machine {
        state,
        shared,
        cycle_thread,
        audit_task,
        db,
        tls_on,
        remote,
    })
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
            let mut demo = model::demo::axes();
            if state.info.bus.kind == bus::BusKind::Emulated {
                model::demo::on_emulated_drives(&mut demo);
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
            service::groups::create_demo(state)
                .await
                .map_err(|e| format!("cannot create the demo group xy: {e}"))?;
            tracing::info!(
                "new database: created the demo axes x, y (linear, mm) and spindle (modulo 360°), \
                 and the group xy of x and y (disabled){}",
                if state.info.bus.kind == bus::BusKind::Emulated {
                    "; on the emulated segment also feeder, whose drive runs the profile"
                } else {
                    ""
                }
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
        let config: model::AxisConfigDto = serde_json::from_str(&a.config)
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
