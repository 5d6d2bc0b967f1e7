//! The pump: moves what the cycle thread produced (verdicts, command events, scope frames,
//! garbage) to where it is awaited; and the audit writer.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::time::Duration;

use sqlx::SqlitePool;

use tokio::sync::mpsc;

use super::AppState;
use super::commands::{apply_event, final_audit};
use crate::cycle::Request;
use crate::store::{self, AuditOp};

impl AppState {
    /// Moves whatever the cycle thread produced to where it is awaited. Runs every ms.
    pub fn drain(&self) {
        // Every event of this cycle and before is in the ring now, and its snapshot published
        // (stored with Release after both): once they are applied below, the clock may say the
        // cycle is reached.
        let cycle = self
            .shared
            .published_cycle
            .load(std::sync::atomic::Ordering::Acquire);
        // Replies are taken first but completed only after the events: the cycle thread pushes
        // a submit's events before its reply, so a handler woken by its reply sees them.
        let mut replies = Vec::new();
        while let Some(r) = self.shared.replies.pop() {
            replies.push(r);
        }
        let mut notices = Vec::new();
        {
            let mut store = self.commands.lock().unwrap();
            while let Some(ev) = self.shared.events.pop() {
                let Some(n) = apply_event(&mut store, &ev) else {
                    continue;
                };
                if n.is_final {
                    if let Some(r) = store.map.get_mut(&n.command) {
                        let entry = final_audit(&n, &r.client);
                        if r.accepted {
                            // Queued before the store shows the command final (`try_send`,
                            // no wait): a reader of the log who saw it end finds its row.
                            self.audit(entry);
                        } else {
                            // Ended before its verdict was handled: `submit` writes this entry
                            // after the one of the submission.
                            r.final_audit = Some(entry);
                        }
                    }
                }
                notices.push(n);
            }
        }
        {
            let mut scope = self.scope.lock().unwrap();
            scope.feed(std::iter::from_fn(|| self.shared.scope_frames.pop()));
            if let Some(config) = scope.take_dirty() {
                // Nobody waits for this reply (ticket 0); a full queue is retried next time.
                let req = Request::ScopeConfig { ticket: 0, config };
                if self.shared.push(req).is_err() {
                    scope.handover_failed();
                }
            }
        }
        for n in notices {
            let _ = self.notices.send(Arc::new(n));
        }
        for r in replies {
            if let Some(tx) = self.pending.lock().unwrap().remove(&r.ticket) {
                let _ = tx.send(r);
            }
        }
        while let Some(g) = self.shared.garbage.pop() {
            drop(g);
        }
        self.drains
            .fetch_add(1, std::sync::atomic::Ordering::AcqRel);
        self.clock.reached(cycle);
        // A virtual clock waiting for room in the rings goes on now.
        self.shared.clock.nudge();
    }
}

/// Drains the cycle thread's queues when it says it produced something, and every
/// millisecond besides (scope frames and garbage come without a wake-up).
pub async fn pump(state: Arc<AppState>) {
    let mut tick = tokio::time::interval(Duration::from_millis(1));
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let fd = state.shared.wake.listener().expect("the pump's eventfd");
    // SAFETY: `fd` is an open descriptor the AsyncFd owns until it is dropped.
    let wake = unsafe {
        tokio::io::unix::AsyncFd::register_with_interest(fd, tokio::io::Interest::READABLE)
    }
    .map_err(|e| e.to_string())
    .expect("the pump's eventfd registered");
    // Ends with its machine (`motiond scenario run` starts one machine after the other).
    while !state
        .shared
        .shutdown
        .load(std::sync::atomic::Ordering::Relaxed)
    {
        tokio::select! {
            _ = tick.tick() => {}
            r = wake.readable() => {
                if let Ok(mut ready) = r {
                    // Read (and so reset) the counter; then wait for the next write.
                    let mut n = [0u8; 8];
                    // SAFETY: reads 8 bytes into a valid buffer from our own descriptor.
                    unsafe {
                        libc::read(
                            std::os::fd::AsRawFd::as_raw_fd(wake.get_ref()),
                            n.as_mut_ptr().cast(),
                            8,
                        )
                    };
                    ready.clear_ready();
                }
            }
        }
        state.drain();
    }
}

/// Waits until the audit writer has written (or given up as lost) what was queued before, at
/// most `bound` (a database held by a long transaction must not hold the caller longer).
pub async fn audit_flushed(queue: &mpsc::Sender<AuditOp>, bound: Duration) {
    let (done, written) = tokio::sync::oneshot::channel();
    let _ = tokio::time::timeout(bound, async {
        if queue.send(AuditOp::Flush(done)).await.is_ok() {
            let _ = written.await;
        }
    })
    .await;
}

/// Writes queued audit entries in batches, one transaction per batch. A batch that cannot be
/// written (database locked past its busy timeout, disk full) is tried again a few times; what
/// is still not written is logged and counted in `lost` (`audit_dropped` in /system, /metrics).
pub async fn audit_writer(db: SqlitePool, mut rx: mpsc::Receiver<AuditOp>, lost: Arc<AtomicU64>) {
    const TRIES: u32 = 3;
    let mut batch = Vec::with_capacity(256);
    while rx.recv_many(&mut batch, 256).await > 0 {
        // Flushes are not entries: not written, not counted as lost.
        let entries = batch
            .iter()
            .filter(|op| !matches!(op, AuditOp::Flush(_)))
            .count();
        // (A batch of flushes only opens no transaction.)
        let tries = if entries == 0 { 0 } else { TRIES };
        for attempt in 1..=tries {
            let result = async {
                let mut tx = db.begin().await?;
                for op in &batch {
                    match op {
                        AuditOp::Row(e) => store::audit(&mut *tx, e).await?,
                        AuditOp::Outcome(id, o) => store::audit_outcome(&mut *tx, *id, o).await?,
                        AuditOp::Flush(_) => {}
                    }
                }
                tx.commit().await
            }
            .await;
            match result {
                Ok(()) => break,
                Err(e) if attempt == TRIES => {
                    tracing::error!("audit log: {entries} entries not written: {e}");
                    lost.fetch_add(entries as u64, Relaxed);
                }
                Err(_) => tokio::time::sleep(Duration::from_millis(200)).await,
            }
        }
        for op in batch.drain(..) {
            if let AuditOp::Flush(done) = op {
                let _ = done.send(());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every row queued before the flush is in the log when it returns, also when they took
    /// more than one batch.
    #[tokio::test(flavor = "current_thread")]
    async fn a_flush_returns_when_the_rows_queued_before_it_are_written() {
        let db = store::open(":memory:").await.unwrap();
        let (queue, rx) = mpsc::channel(1024);
        for n in 0..300 {
            let row = store::AuditEntry {
                action: format!("parameter.write.{n}"),
                ..Default::default()
            };
            queue.send(AuditOp::Row(row)).await.unwrap();
        }
        tokio::spawn(audit_writer(db.clone(), rx, Default::default()));
        audit_flushed(&queue, Duration::from_secs(60)).await;
        let rows = store::read_audit(&db, 1000, 0, i64::MAX).await.unwrap();
        assert_eq!(rows.len(), 300);
        assert_eq!(rows[0].entry.action, "parameter.write.299");
    }
}
