//! `GET /system`, `/metrics`.

use std::fmt::Write;
use std::sync::Arc;
use std::sync::atomic::Ordering::Relaxed;

use axum::Json;
use axum::extract::State;
use axum::http::header;
use axum::response::IntoResponse;
use serde::Serialize;
use utoipa::ToSchema;

use crate::app::AppState;
use crate::cycle::RealtimeGrant;
use crate::stats::Summary;

/// Timing of the cycle thread, measured by itself.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!(timing_example()))]
pub struct Timing {
    /// Wake-up time minus the deadline.
    pub wakeup_latency: Summary,
    /// Work per cycle (drives, commands, kernel, snapshot).
    pub compute: Summary,
    /// Time between consecutive wake-ups.
    pub period: Summary,
    pub cycles: u64,
    /// Deadlines missed because a cycle's work ended late.
    pub overruns: u64,
    /// Command events lost because the event ring was full.
    pub events_dropped: u64,
    /// Audit entries lost: the audit queue was full or writing them failed (disk full,
    /// database locked); each one is also logged.
    pub audit_dropped: u64,
    /// Requests the cycle thread dropped undone because their requester had already answered
    /// 503 (the cycle thread took longer than that to drain them).
    pub requests_expired: u64,
    /// Scope frames lost because the scope ring was full (the recordings running then failed).
    pub scope_frames_dropped: u64,
}

/// What `GET /system` reports.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "version": "0.1.0", "cycle_time": 0.001, "cycle": 5750, "uptime_s": 5.76, "listen": "127.0.0.1:8080",
    "database": "motiond.db", "axes": 3, "drive_bus": "simulated",
    "realtime": {"sched_fifo": true, "mlockall": true, "pinned_cpu": 1, "cpu_dma_latency_zero": true, "notes": []},
    "timing": timing_example()
}))]
pub struct SystemResource {
    #[schema(example = "0.1.0")]
    pub version: &'static str,
    /// Kernel cycle time in seconds.
    #[schema(example = 0.001)]
    pub cycle_time: f64,
    /// The latest cycle.
    pub cycle: u64,
    pub uptime_s: f64,
    pub listen: String,
    pub database: String,
    pub axes: usize,
    /// `simulated` (EtherCAT later).
    pub drive_bus: &'static str,
    pub realtime: RealtimeGrant,
    pub timing: Timing,
}

fn timing_example() -> serde_json::Value {
    serde_json::json!({
        "wakeup_latency": {"count": 5750, "mean_us": 23.6, "p50_us": 16.4, "p90_us": 26.6, "p99_us": 94.2,
                           "p999_us": 852.0, "max_us": 8172.8},
        "compute": {"count": 5750, "mean_us": 9.1, "p50_us": 6.4, "p90_us": 14.3, "p99_us": 32.8,
                    "p999_us": 51.2, "max_us": 64.7},
        "period": {"count": 5749, "mean_us": 1002.4, "p50_us": 1015.8, "p90_us": 1015.8, "p99_us": 1114.1,
                   "p999_us": 1769.5, "max_us": 9157.2},
        "cycles": 5750, "overruns": 14, "events_dropped": 0, "audit_dropped": 0, "requests_expired": 0,
        "scope_frames_dropped": 0
    })
}

pub fn system_resource(s: &AppState) -> SystemResource {
    let st = &s.shared.stats;
    SystemResource {
        version: s.info.version,
        cycle_time: s.info.cycle_time_s,
        cycle: s.shared.cycle.load(Relaxed),
        uptime_s: s.info.started.elapsed().as_secs_f64(),
        listen: s.info.listen.clone(),
        database: s.info.db.clone(),
        axes: s.registry.read().unwrap().axes.len(),
        drive_bus: "simulated",
        realtime: s.info.realtime.clone(),
        timing: Timing {
            wakeup_latency: st.wakeup_latency.summary(),
            compute: st.compute.summary(),
            period: st.period.summary(),
            cycles: st.cycles.load(Relaxed),
            overruns: st.overruns.load(Relaxed),
            events_dropped: st.events_dropped.load(Relaxed),
            audit_dropped: s.audit_dropped.load(Relaxed),
            requests_expired: st.requests_expired.load(Relaxed),
            scope_frames_dropped: st.scope_frames_dropped.load(Relaxed),
        },
    }
}

#[utoipa::path(get, path = "/api/v1/system", tag = "system", summary = "Version, cycle time, real-time grant and timing statistics",
    responses((status = 200, description = "System information", body = SystemResource)))]
pub async fn system(State(s): State<Arc<AppState>>) -> Json<SystemResource> {
    Json(system_resource(&s))
}

#[utoipa::path(get, path = "/metrics", tag = "system", summary = "Prometheus metrics (text format 0.0.4)",
    responses((status = 200, description = "Metrics", content_type = "text/plain", body = String,
        example = "# HELP motiond_cycle_compute_seconds Work per cycle.\n# TYPE motiond_cycle_compute_seconds histogram\n\
motiond_cycle_compute_seconds_bucket{le=\"6.4e-6\"} 2871\n…\nmotiond_cycle_compute_seconds_bucket{le=\"+Inf\"} 5750\n\
motiond_cycle_compute_seconds_sum 0.0522\nmotiond_cycle_compute_seconds_count 5750\n\
# HELP motiond_cycles_total Cycles run.\n# TYPE motiond_cycles_total counter\nmotiond_cycles_total 5750\n\
# HELP motiond_cycle_overruns_total Deadlines missed.\n# TYPE motiond_cycle_overruns_total counter\nmotiond_cycle_overruns_total 14\n\
# HELP motiond_axes Configured axes.\n# TYPE motiond_axes gauge\nmotiond_axes 3\n")))]
pub async fn metrics(State(s): State<Arc<AppState>>) -> impl IntoResponse {
    let st = &s.shared.stats;
    let mut out = String::with_capacity(16 * 1024);
    st.wakeup_latency.prometheus(
        "motiond_cycle_wakeup_latency_seconds",
        "Wake-up time of the cycle thread minus its deadline.",
        &mut out,
    );
    st.compute
        .prometheus("motiond_cycle_compute_seconds", "Work per cycle.", &mut out);
    st.period.prometheus(
        "motiond_cycle_period_seconds",
        "Time between consecutive wake-ups of the cycle thread.",
        &mut out,
    );
    let counters = [
        (
            "motiond_cycles_total",
            "Cycles run.",
            st.cycles.load(Relaxed),
        ),
        (
            "motiond_cycle_overruns_total",
            "Deadlines missed.",
            st.overruns.load(Relaxed),
        ),
        (
            "motiond_events_dropped_total",
            "Command events lost (event ring full).",
            st.events_dropped.load(Relaxed),
        ),
        (
            "motiond_commands_total",
            "Requests taken by the cycle thread.",
            st.commands_drained.load(Relaxed),
        ),
        (
            "motiond_scope_frames_dropped_total",
            "Scope frames lost (scope ring full).",
            st.scope_frames_dropped.load(Relaxed),
        ),
        (
            "motiond_audit_dropped_total",
            "Audit entries lost (queue full or write failed).",
            s.audit_dropped.load(Relaxed),
        ),
        (
            "motiond_requests_expired_total",
            "Requests dropped undone after their requester had answered 503.",
            st.requests_expired.load(Relaxed),
        ),
    ];
    for (name, help, v) in counters {
        let _ = writeln!(
            out,
            "# HELP {name} {help}\n# TYPE {name} counter\n{name} {v}"
        );
    }
    let _ = writeln!(
        out,
        "# HELP motiond_cycle_time_seconds Configured cycle time.\n# TYPE motiond_cycle_time_seconds gauge\nmotiond_cycle_time_seconds {}",
        s.info.cycle_time_s
    );
    let _ = writeln!(
        out,
        "# HELP motiond_axes Configured axes.\n# TYPE motiond_axes gauge\nmotiond_axes {}",
        s.registry.read().unwrap().axes.len()
    );
    let _ = writeln!(
        out,
        "# HELP motiond_realtime_granted SCHED_FIFO granted (1) or not (0).\n# TYPE motiond_realtime_granted gauge\nmotiond_realtime_granted {}",
        s.info.realtime.sched_fifo as u8
    );
    ([(header::CONTENT_TYPE, "text/plain; version=0.0.4")], out)
}
