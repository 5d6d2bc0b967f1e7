//! `/metrics` in the OpenMetrics text format, made with `prometheus-client` over the figures the
//! cycle thread keeps in atomics (`stats.rs`), the axes' statuses and the process's own
//! figures from `/proc`, read at scrape time; and the counters of submitted commands, by
//! function block and verdict, counted where commands are submitted.

use std::sync::atomic::Ordering::Relaxed;

use prometheus_client::collector::Collector;
use prometheus_client::encoding::{DescriptorEncoder, EncodeLabelSet, EncodeLabelValue};
use prometheus_client::metrics::MetricType;
use prometheus_client::metrics::counter::Counter;
use prometheus_client::metrics::family::Family;
use prometheus_client::metrics::info::Info;
use prometheus_client::registry::{Registry, Unit};

use crate::stats::Histogram;

/// How the service answered a submitted command.
#[derive(Clone, Copy, Debug, Hash, PartialEq, Eq, EncodeLabelValue)]
#[allow(
    non_camel_case_types,
    reason = "the variants are the label values as exported"
)]
pub enum Verdict {
    /// Taken by the kernel (202).
    accepted,
    /// Refused by the kernel with its ErrorID (409 and the like).
    rejected,
    /// Refused before the kernel: a body that does not check (422), an unknown axis.
    invalid,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct CommandLabels {
    /// The function block (the endpoint's and the websocket method's name).
    pub block: &'static str,
    pub verdict: Verdict,
}

/// The counters the service keeps (everything else is read at scrape time).
#[derive(Default)]
pub struct Metrics {
    commands: Family<CommandLabels, Counter>,
}

impl Metrics {
    pub fn command(&self, block: &'static str, verdict: Verdict) {
        self.commands
            .get_or_create(&CommandLabels { block, verdict })
            .inc();
    }
}

/// Histogram bounds (ns) for `/metrics`: powers of two from 2 µs to 1 ms with half steps from
/// 4 µs, then a few up to 1 s — 22 bounds, each an exact bound of the cycle thread's fine
/// histogram (so nothing is interpolated). `?buckets=fine` gives all of its 400 bounds.
const BOUNDS_NS: [u64; 22] = [
    1 << 11,
    1 << 12,
    3 << 11,
    1 << 13,
    3 << 12,
    1 << 14,
    3 << 13,
    1 << 15,
    3 << 14,
    1 << 16,
    3 << 15,
    1 << 17,
    3 << 16,
    1 << 18,
    3 << 17,
    1 << 19,
    3 << 18,
    1 << 20,
    1 << 21,
    1 << 23,
    1 << 25,
    1 << 30,
];

/// A histogram as read at a scrape: sum (s), count and per-bucket counts at upper bounds (s).
#[derive(Debug)]
struct Hist {
    sum: f64,
    count: u64,
    buckets: Vec<(f64, u64)>,
}

fn read_hist(h: &Histogram, fine: bool) -> Hist {
    let (fine_bounds, counts) = (Histogram::bounds_ns(), h.counts());
    let count: u64 = counts.iter().sum();
    let buckets = if fine {
        fine_bounds
            .zip(counts.iter())
            .map(|(b, &c)| (b as f64 / 1e9, c))
            .chain(std::iter::once((f64::INFINITY, 0)))
            .collect()
    } else {
        let mut out: Vec<(f64, u64)> = BOUNDS_NS
            .iter()
            .map(|&b| (b as f64 / 1e9, 0))
            .chain(std::iter::once((f64::INFINITY, 0)))
            .collect();
        for (b, &c) in fine_bounds.zip(counts.iter()) {
            // Each fine bucket lies wholly under one coarse bound.
            let j = BOUNDS_NS.partition_point(|&x| x < b);
            out[j].1 += c;
        }
        out
    };
    Hist {
        sum: h.sum_ns() as f64 / 1e9,
        count,
        buckets,
    }
}

#[derive(Debug)]
pub struct AxisFigures {
    pub name: String,
    pub state: u8,
    pub error_id: u32,
    pub following_error: f64,
    pub following_error_peak: f64,
}

/// The process's figures from `/proc/self` (Linux).
#[derive(Debug, Default)]
struct Process {
    cpu_seconds: f64,
    resident_bytes: u64,
    virtual_bytes: u64,
    threads: u64,
    start_time_seconds: f64,
    open_fds: u64,
    max_fds: u64,
}

fn read_process() -> Option<Process> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name in parentheses (which may hold spaces).
    let f: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    let num = |i: usize| f.get(i).and_then(|v| v.parse::<u64>().ok());
    // SAFETY: sysconf only reads configuration values.
    let (ticks, page) = unsafe {
        (
            libc::sysconf(libc::_SC_CLK_TCK) as f64,
            libc::sysconf(libc::_SC_PAGESIZE) as u64,
        )
    };
    let boot = std::fs::read_to_string("/proc/stat")
        .ok()?
        .lines()
        .find_map(|l| l.strip_prefix("btime ")?.trim().parse::<f64>().ok())?;
    let max_fds = std::fs::read_to_string("/proc/self/limits")
        .ok()
        .and_then(|l| {
            l.lines()
                .find(|l| l.starts_with("Max open files"))
                .and_then(|l| l.split_whitespace().nth(3)?.parse().ok())
        })
        .unwrap_or(0);
    Some(Process {
        // utime, stime: fields 14, 15 of stat (11, 12 after the name); threads 20, start 22,
        // vsize 23, rss 24 (pages).
        cpu_seconds: (num(11)? + num(12)?) as f64 / ticks,
        threads: num(17)?,
        start_time_seconds: boot + num(19)? as f64 / ticks,
        virtual_bytes: num(20)?,
        resident_bytes: num(21)? * page,
        open_fds: std::fs::read_dir("/proc/self/fd").map_or(0, |d| d.count() as u64),
        max_fds,
    })
}

/// Everything read at one scrape.
#[derive(Debug)]
struct Scrape {
    histograms: Vec<(&'static str, &'static str, Hist)>,
    counters: Vec<(&'static str, &'static str, u64)>,
    gauges: Vec<(&'static str, &'static str, Option<Unit>, f64)>,
    axes: Vec<AxisFigures>,
    process: Option<Process>,
}

fn gauge(
    enc: &mut DescriptorEncoder,
    name: &str,
    help: &str,
    unit: Option<&Unit>,
    v: f64,
) -> Result<(), std::fmt::Error> {
    enc.encode_descriptor(name, help, unit, MetricType::Gauge)?
        .encode_gauge(&v)
}

fn counter(
    enc: &mut DescriptorEncoder,
    name: &str,
    help: &str,
    unit: Option<&Unit>,
    v: &impl prometheus_client::encoding::EncodeCounterValue,
) -> Result<(), std::fmt::Error> {
    enc.encode_descriptor(name, help, unit, MetricType::Counter)?
        .encode_counter::<prometheus_client::encoding::NoLabelSet, _, f64>(v, None)
}

impl Collector for Scrape {
    fn encode(&self, mut enc: DescriptorEncoder) -> Result<(), std::fmt::Error> {
        for (name, help, h) in &self.histograms {
            enc.encode_descriptor(name, help, Some(&Unit::Seconds), MetricType::Histogram)?
                .encode_histogram::<prometheus_client::encoding::NoLabelSet>(
                    h.sum, h.count, &h.buckets, None,
                )?;
        }
        for (name, help, v) in &self.counters {
            counter(&mut enc, name, help, None, v)?;
        }
        for (name, help, unit, v) in &self.gauges {
            gauge(&mut enc, name, help, unit.as_ref(), *v)?;
        }
        type Of = fn(&AxisFigures) -> f64;
        let per_axis: [(&str, &str, Option<Unit>, Of); 4] = [
            (
                "motiond_axis_state",
                "PLCopen state: 0 disabled, 1 standstill, 2 homing, 3 discrete motion, 4 continuous motion, 5 synchronized motion, 6 stopping, 7 error stop",
                None,
                |a| a.state as f64,
            ),
            (
                "motiond_axis_error_id",
                "The axis's ErrorID (0: none)",
                None,
                |a| a.error_id as f64,
            ),
            (
                "motiond_axis_following_error",
                "Set minus actual position, in axis units",
                None,
                |a| a.following_error,
            ),
            (
                "motiond_axis_following_error_peak",
                "Largest following error magnitude since the peak was last reset, in axis units",
                None,
                |a| a.following_error_peak,
            ),
        ];
        for (name, help, unit, of) in per_axis {
            let mut m = enc.encode_descriptor(name, help, unit.as_ref(), MetricType::Gauge)?;
            for a in &self.axes {
                m.encode_family(&[("axis", a.name.as_str())])?
                    .encode_gauge(&of(a))?;
            }
        }
        if let Some(p) = &self.process {
            counter(
                &mut enc,
                "process_cpu",
                "User and system CPU time spent",
                Some(&Unit::Seconds),
                &p.cpu_seconds,
            )?;
            for (name, help, unit, v) in [
                (
                    "process_resident_memory",
                    "Resident memory size",
                    Some(Unit::Bytes),
                    p.resident_bytes as f64,
                ),
                (
                    "process_virtual_memory",
                    "Virtual memory size",
                    Some(Unit::Bytes),
                    p.virtual_bytes as f64,
                ),
                (
                    "process_start_time",
                    "Start time since the Unix epoch",
                    Some(Unit::Seconds),
                    p.start_time_seconds,
                ),
                ("process_threads", "OS threads", None, p.threads as f64),
                (
                    "process_open_fds",
                    "Open file descriptors",
                    None,
                    p.open_fds as f64,
                ),
                (
                    "process_max_fds",
                    "Limit of open file descriptors",
                    None,
                    p.max_fds as f64,
                ),
            ] {
                gauge(&mut enc, name, help, unit.as_ref(), v)?;
            }
        }
        Ok(())
    }
}

/// What a scrape reads of the running server, gathered by its caller (the service layer reads
/// the registry and the snapshot; this module only encodes).
pub struct Sources<'a> {
    pub stats: &'a crate::stats::CycleStats,
    /// Every configured axis that has a status, sorted by name.
    pub axes: Vec<AxisFigures>,
    pub ethercat: Option<&'a ethercat::bus::BusStatus>,
    pub audit_dropped: u64,
    pub cycle_time_s: f64,
    pub sched_fifo: bool,
    pub metrics: &'a Metrics,
    /// Websocket ticks whose axis updates a socket made itself, and took from another's.
    pub ws_messages: (u64, u64),
}

/// The whole `/metrics` text; `fine`: every bucket of the cycle timing histograms (for
/// windowed quantiles in benchmarks) instead of the ~20 of a normal scrape.
pub fn render(s: Sources<'_>, fine: bool) -> String {
    let st = s.stats;
    let axes = s.axes;
    let axes_configured = axes.len() as f64;
    let mut bus_counters = Vec::new();
    let mut bus_gauges = Vec::new();
    if let Some(b) = s.ethercat {
        bus_counters = vec![
            (
                "motiond_bus_frames",
                "EtherCAT cyclic frames sent",
                b.frames.load(Relaxed),
            ),
            (
                "motiond_bus_lost_frames",
                "EtherCAT cyclic frames not answered in time",
                b.lost_frames.load(Relaxed),
            ),
            (
                "motiond_bus_working_counter_errors",
                "EtherCAT cyclic frames with a wrong working counter",
                b.working_counter_errors.load(Relaxed),
            ),
            (
                "motiond_bus_faults",
                "Times the EtherCAT bus stopped its axes (lost frames or working counters in a row)",
                b.faults.load(Relaxed),
            ),
        ];
        bus_gauges = vec![
            (
                "motiond_bus_faulted",
                "The EtherCAT bus stopped its axes (lost frames or working counters in a row): 1, else 0",
                None,
                b.faulted.load(Relaxed) as u8 as f64,
            ),
            (
                "motiond_bus_subdevices_not_op",
                "EtherCAT SubDevices not in OP",
                None,
                b.al_states.iter().filter(|a| a.load(Relaxed) != 8).count() as f64,
            ),
            (
                "motiond_bus_dc_cycle_offset",
                "Where in its SYNC0 period the latest frame reached the DC reference clock",
                Some(Unit::Seconds),
                b.dc_cycle_offset.load(Relaxed) as f64 * 1e-9,
            ),
        ];
    }
    let scrape = Scrape {
        histograms: vec![
            (
                "motiond_cycle_wakeup_latency",
                "Wake-up time of the cycle thread minus its deadline",
                read_hist(&st.wakeup_latency, fine),
            ),
            (
                "motiond_cycle_compute",
                "Work per cycle",
                read_hist(&st.compute, fine),
            ),
            (
                "motiond_cycle_period",
                "Time between consecutive wake-ups of the cycle thread",
                read_hist(&st.period, fine),
            ),
        ],
        counters: vec![
            ("motiond_cycles", "Cycles run", st.cycles.load(Relaxed)),
            (
                "motiond_cycle_overruns",
                "Deadlines missed",
                st.overruns.load(Relaxed),
            ),
            (
                "motiond_cycle_requests",
                "Requests taken by the cycle thread (commands, configuration, scope, …)",
                st.commands_drained.load(Relaxed),
            ),
            (
                "motiond_events_dropped",
                "Command events lost (event ring full)",
                st.events_dropped.load(Relaxed),
            ),
            (
                "motiond_scope_frames_dropped",
                "Scope frames lost (scope ring full)",
                st.scope_frames_dropped.load(Relaxed),
            ),
            (
                "motiond_audit_dropped",
                "Audit entries lost (queue full or write failed)",
                s.audit_dropped,
            ),
            (
                "motiond_requests_expired",
                "Requests dropped undone after their requester had answered 503",
                st.requests_expired.load(Relaxed),
            ),
            (
                "motiond_ws_messages_made",
                "Websocket ticks whose axis updates a socket made itself",
                s.ws_messages.0,
            ),
            (
                "motiond_ws_messages_shared",
                "Websocket ticks whose axis updates a socket took from another socket that asked the same",
                s.ws_messages.1,
            ),
        ]
        .into_iter()
        .chain(bus_counters)
        .collect(),
        gauges: vec![
            (
                "motiond_cycle_time",
                "Configured cycle time",
                Some(Unit::Seconds),
                s.cycle_time_s,
            ),
            ("motiond_axes", "Configured axes", None, axes_configured),
            (
                "motiond_realtime_granted",
                "SCHED_FIFO granted (1) or not (0)",
                None,
                s.sched_fifo as u8 as f64,
            ),
        ]
        .into_iter()
        .chain(bus_gauges)
        .collect(),
        axes,
        process: read_process(),
    };
    let mut registry = Registry::default();
    registry.register(
        "motiond_build",
        "The running build",
        Info::new([("version", env!("CARGO_PKG_VERSION"))]),
    );
    registry.register(
        "motiond_commands",
        "Motion commands submitted, by function block and verdict",
        s.metrics.commands.clone(),
    );
    registry.register_collector(Box::new(scrape));
    let mut out = String::with_capacity(8 * 1024);
    let _ = prometheus_client::encoding::text::encode(&mut out, &registry);
    out
}

/// The Prometheus text format 0.0.4 (what `promtool check metrics` and clients that do not ask
/// for OpenMetrics read) of an OpenMetrics text: a counter's family is named with its
/// `_total`, an info is a gauge named `…_info` with the value 1, and there are no `# UNIT` or
/// `# EOF` lines.
pub fn to_prometheus_text(openmetrics: &str) -> String {
    let mut renamed: std::collections::HashMap<&str, (String, &str)> = Default::default();
    for line in openmetrics.lines() {
        if let Some(rest) = line.strip_prefix("# TYPE ") {
            match rest.rsplit_once(' ') {
                Some((name, "counter")) => {
                    renamed.insert(name, (format!("{name}_total"), "counter"));
                }
                Some((name, "info")) => {
                    renamed.insert(name, (format!("{name}_info"), "gauge"));
                }
                _ => {}
            }
        }
    }
    let mut out = String::with_capacity(openmetrics.len());
    for line in openmetrics.lines() {
        if line.starts_with("# UNIT ") || line == "# EOF" {
            continue;
        }
        let family = |prefix: &str| {
            let rest = line.strip_prefix(prefix)?;
            let (name, tail) = rest.split_once(' ').unwrap_or((rest, ""));
            renamed.get(name).map(|r| (r, tail))
        };
        if let Some(((name, _), help)) = family("# HELP ") {
            out.push_str(&format!("# HELP {name} {help}"));
        } else if let Some(((name, kind), _)) = family("# TYPE ") {
            out.push_str(&format!("# TYPE {name} {kind}"));
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}
