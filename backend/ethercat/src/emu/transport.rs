//! How frames reach the emulated segment: in-process through ethercrab's `PduTx`/`PduRx` (a
//! thread that takes each sendable frame, passes it through the segment and hands the answer
//! back), or on a raw socket (a veth pair in tests: the MainDevice's own `tx_rx_task` path).

use std::sync::{Arc, Mutex};
use std::task::Poll;
use std::thread::JoinHandle;

use ethercrab::{PduRx, PduTx};

use super::Segment;

/// Serves the MainDevice's frames from `segment` on a thread of its own until the MainDevice
/// is dropped (the PDU loop says exit).
pub fn spawn_in_process(
    mut tx: PduTx<'static>,
    mut rx: PduRx<'static>,
    segment: Arc<Mutex<Segment>>,
) -> std::io::Result<JoinHandle<()>> {
    std::thread::Builder::new()
        .name("ecat-emu".into())
        .spawn(move || {
            futures_lite::future::block_on(std::future::poll_fn(|cx| {
                tx.replace_waker(cx.waker());
                while let Some(frame) = tx.next_sendable_frame() {
                    let mut answer = None;
                    let sent = frame.send_blocking(|bytes| {
                        answer = segment
                            .lock()
                            .unwrap_or_else(|e| e.into_inner())
                            .process(bytes);
                        Ok(bytes.len())
                    });
                    if sent.is_err() {
                        continue;
                    }
                    // A lost frame is simply not answered: the MainDevice's PDU timeout sees it.
                    if let Some(answer) = answer {
                        let _ = rx.receive_frame(&answer);
                    }
                }
                if tx.should_exit() {
                    Poll::Ready(())
                } else {
                    Poll::Pending
                }
            }));
        })
}

/// Serves the segment on a raw `AF_PACKET` socket bound to `interface` (one end of a veth
/// pair whose other end the MainDevice uses), until `stop` is set; the segment's reply faults
/// (late, duplicate answers) apply. The socket is opened
/// before this returns, in the caller's network namespace.
#[cfg(target_os = "linux")]
pub fn serve_raw_socket(
    interface: &str,
    segment: Arc<Mutex<Segment>>,
    stop: Arc<std::sync::atomic::AtomicBool>,
) -> std::io::Result<JoinHandle<()>> {
    let fd = crate::raw::open(interface)?;
    std::thread::Builder::new()
        .name("ecat-emu-raw".into())
        .spawn(move || {
            let mut buf = vec![0u8; 2048];
            // Answers held back by the reply faults: (due, frame).
            let mut later: Vec<(std::time::Instant, Vec<u8>)> = Vec::new();
            let idle = crate::raw::EventFd::new().ok();
            while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                let now = std::time::Instant::now();
                later.retain(|(due, answer)| {
                    let keep = *due > now;
                    if !keep {
                        let _ = crate::raw::send(&fd, answer);
                    }
                    keep
                });
                let wait = later
                    .iter()
                    .map(|(due, _)| due.saturating_duration_since(now))
                    .min()
                    .unwrap_or(std::time::Duration::from_millis(50));
                if let Some(idle) = &idle {
                    if !crate::raw::wait(Some(&fd), idle, wait).unwrap_or(false) {
                        continue;
                    }
                }
                let Some(n) = crate::raw::recv(&fd, &mut buf) else {
                    continue;
                };
                let frame = &buf[..n];
                // Our own answers (the locally administered source bit) pass by as well.
                if n < 14 || frame[6] & 0x02 != 0 {
                    continue;
                }
                let mut seg = segment.lock().unwrap_or_else(|e| e.into_inner());
                if let Some(answer) = seg.process(frame) {
                    let (delay, copies) = seg.reply_plan();
                    for _ in 0..copies {
                        if delay.is_zero() {
                            let _ = crate::raw::send(&fd, &answer);
                        } else {
                            later.push((std::time::Instant::now() + delay, answer.clone()));
                        }
                    }
                }
            }
        })
}
