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
