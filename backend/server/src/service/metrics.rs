//! What a `/metrics` scrape reads of the running server (the registry, the latest snapshot, the
//! cycle thread's and the bus's counters), handed to `crate::metrics` to encode.

use std::sync::atomic::Ordering::Relaxed;

use crate::app::AppState;
use crate::metrics::{self, AxisFigures, Sources};

/// The whole `/metrics` text (see [`metrics::render`]).
pub fn text(s: &AppState, fine: bool) -> String {
    let axes = {
        let reg = s.registry.read().unwrap();
        let mut axes: Vec<AxisFigures> = reg
            .axes
            .values()
            .filter_map(|e| {
                let status = s.status(e.slot).1?;
                Some(AxisFigures {
                    name: e.name.clone(),
                    state: status.state as u8,
                    error_id: status.error_id,
                    following_error: status.following_error,
                    following_error_peak: status
                        .following_error_min
                        .abs()
                        .max(status.following_error_max.abs()),
                })
            })
            .collect();
        axes.sort_by(|a, b| a.name.cmp(&b.name));
        axes
    };
    let sources = Sources {
        stats: &s.shared.stats,
        axes,
        ethercat: s.info.bus.ethercat.as_ref().map(|(b, _)| &**b),
        audit_dropped: s.audit_dropped.load(Relaxed),
        cycle_time_s: s.info.cycle_time_s,
        sched_fifo: s.info.realtime.sched_fifo,
        metrics: &s.metrics,
        ws_messages: s.feed.messages(),
    };
    metrics::render(sources, fine)
}
