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
/// pair whose other end the MainDevice uses), until `stop` is set. The socket is opened
/// before this returns, in the caller's network namespace.
#[cfg(target_os = "linux")]
pub fn serve_raw_socket(
    interface: &str,
    segment: Arc<Mutex<Segment>>,
    stop: Arc<std::sync::atomic::AtomicBool>,
) -> std::io::Result<JoinHandle<()>> {
    let fd = raw::open(interface)?;
    std::thread::Builder::new()
        .name("ecat-emu-raw".into())
        .spawn(move || {
            let mut buf = vec![0u8; 2048];
            while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                let Some(n) = raw::recv(&fd, &mut buf) else {
                    continue;
                };
                let frame = &buf[..n];
                // Our own answers (the locally administered source bit) pass by as well.
                if n < 14 || frame[6] & 0x02 != 0 {
                    continue;
                }
                let answer = segment
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .process(frame);
                if let Some(answer) = answer {
                    raw::send(&fd, &answer);
                }
            }
        })
}

#[cfg(target_os = "linux")]
mod raw {
    use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};

    const ETH_P_ECAT: u16 = super::super::ETHERTYPE;

    pub fn open(interface: &str) -> std::io::Result<OwnedFd> {
        let name = std::ffi::CString::new(interface)
            .map_err(|_| std::io::Error::from(std::io::ErrorKind::InvalidInput))?;
        // SAFETY: plain libc calls on values we own; the fd is wrapped at once.
        unsafe {
            let index = libc::if_nametoindex(name.as_ptr());
            if index == 0 {
                return Err(std::io::Error::last_os_error());
            }
            let fd = libc::socket(
                libc::AF_PACKET,
                libc::SOCK_RAW,
                i32::from(ETH_P_ECAT.to_be()),
            );
            if fd < 0 {
                return Err(std::io::Error::last_os_error());
            }
            let fd = OwnedFd::from_raw_fd(fd);
            let mut addr: libc::sockaddr_ll = std::mem::zeroed();
            addr.sll_family = libc::AF_PACKET as u16;
            addr.sll_protocol = ETH_P_ECAT.to_be();
            addr.sll_ifindex = index as i32;
            if libc::bind(
                fd.as_raw_fd(),
                &addr as *const libc::sockaddr_ll as *const libc::sockaddr,
                std::mem::size_of::<libc::sockaddr_ll>() as u32,
            ) < 0
            {
                return Err(std::io::Error::last_os_error());
            }
            // Wake up now and then to see whether to stop.
            let tv = libc::timeval {
                tv_sec: 0,
                tv_usec: 50_000,
            };
            libc::setsockopt(
                fd.as_raw_fd(),
                libc::SOL_SOCKET,
                libc::SO_RCVTIMEO,
                &tv as *const libc::timeval as *const libc::c_void,
                std::mem::size_of::<libc::timeval>() as u32,
            );
            Ok(fd)
        }
    }

    pub fn recv(fd: &OwnedFd, buf: &mut [u8]) -> Option<usize> {
        // SAFETY: the buffer is ours and as long as we say.
        let n = unsafe { libc::recv(fd.as_raw_fd(), buf.as_mut_ptr().cast(), buf.len(), 0) };
        (n > 0).then_some(n as usize)
    }

    pub fn send(fd: &OwnedFd, frame: &[u8]) {
        // SAFETY: as above; a frame that cannot be sent is a lost frame.
        unsafe {
            libc::send(fd.as_raw_fd(), frame.as_ptr().cast(), frame.len(), 0);
        }
    }
}
