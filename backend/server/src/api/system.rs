//! `GET /system`, `/metrics`.

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
    /// `simulated`, `emulated` (an emulated EtherCAT segment) or `ethercat`; details in
    /// `GET /api/v1/bus`.
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
        drive_bus: s.info.bus.kind.name(),
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

/// `/metrics` query.
#[derive(Debug, Default, serde::Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct MetricsQuery {
    /// `fine`: every bucket (≈6 % steps, 400 bounds) of the cycle timing histograms, for
    /// windowed quantiles between two scrapes; default: 22 bounds from 2 µs to 1 s.
    #[serde(default)]
    #[param(inline)]
    pub buckets: Option<MetricsBuckets>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum MetricsBuckets {
    Fine,
}

#[utoipa::path(get, path = "/metrics", tag = "system", summary = "Metrics for Prometheus",
    description = "OpenMetrics text when the request accepts `application/openmetrics-text` (as Prometheus does), \
else the Prometheus text format 0.0.4. Cycle timing histograms, cycle and service counters, submitted commands by function block and \
verdict (`motiond_commands_total{block, verdict}`), per-axis gauges (state, error id, following error and its peak), \
`motiond_build_info` and the process's figures (`process_*`).",
    params(MetricsQuery),
    responses((status = 200, description = "Metrics", content_type = "text/plain", body = String,
        example = "# HELP motiond_cycle_compute_seconds Work per cycle\n# TYPE motiond_cycle_compute_seconds histogram\n\
motiond_cycle_compute_seconds_sum 0.0522\nmotiond_cycle_compute_seconds_count 5750\n\
motiond_cycle_compute_seconds_bucket{le=\"0.000002048\"} 2871\n…\nmotiond_cycle_compute_seconds_bucket{le=\"+Inf\"} 5750\n\
# HELP motiond_commands_total Motion commands submitted, by function block and verdict\n# TYPE motiond_commands_total counter\n\
motiond_commands_total{block=\"move-absolute\",verdict=\"accepted\"} 12\n…\n"), super::errors::MetricsErrors))]
pub async fn metrics(
    State(s): State<Arc<AppState>>,
    headers: axum::http::HeaderMap,
    super::Q(q): super::Q<MetricsQuery>,
) -> impl IntoResponse {
    let out = crate::service::metrics::text(&s, q.buckets == Some(MetricsBuckets::Fine));
    // OpenMetrics for those that ask for it (Prometheus does), else the classic text format.
    let openmetrics = headers
        .get_all(header::ACCEPT)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .any(|v| v.contains("application/openmetrics-text"));
    if openmetrics {
        (
            [(
                header::CONTENT_TYPE,
                "application/openmetrics-text; version=1.0.0; charset=utf-8",
            )],
            out,
        )
    } else {
        (
            [(
                header::CONTENT_TYPE,
                "text/plain; version=0.0.4; charset=utf-8",
            )],
            crate::metrics::to_prometheus_text(&out),
        )
    }
}
