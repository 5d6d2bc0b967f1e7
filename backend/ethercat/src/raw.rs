//! A raw `AF_PACKET` socket for EtherCAT frames (Ethernet type 0x88A4) on one interface, and
//! an eventfd to wake a thread that waits on it: what motiond's own TX/RX loop and the
//! emulated segment's raw-socket server use.
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};

const ETH_P_ECAT: u16 = crate::emu::ETHERTYPE;

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

/// Sends one frame; an error is the socket's.
pub fn send(fd: &OwnedFd, frame: &[u8]) -> std::io::Result<()> {
    // SAFETY: the frame is ours and as long as we say.
    let n = unsafe { libc::send(fd.as_raw_fd(), frame.as_ptr().cast(), frame.len(), 0) };
    if n < 0 {
        Err(std::io::Error::last_os_error())
    } else if n as usize != frame.len() {
        Err(std::io::Error::other(format!(
            "sent {n} of {} bytes",
            frame.len()
        )))
    } else {
        Ok(())
    }
}

/// Receives one frame if one is there (never blocks).
pub fn try_recv(fd: &OwnedFd, buf: &mut [u8]) -> std::io::Result<Option<usize>> {
    // SAFETY: the buffer is ours and as long as we say.
    let n = unsafe {
        libc::recv(
            fd.as_raw_fd(),
            buf.as_mut_ptr().cast(),
            buf.len(),
            libc::MSG_DONTWAIT,
        )
    };
    if n >= 0 {
        return Ok(Some(n as usize));
    }
    let e = std::io::Error::last_os_error();
    match e.kind() {
        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::Interrupted => Ok(None),
        _ => Err(e),
    }
}

/// An eventfd: one thread waits on it (with a socket, [`wait`]), any other wakes it.
pub struct EventFd(OwnedFd);

impl EventFd {
    pub fn new() -> std::io::Result<EventFd> {
        // SAFETY: a plain libc call; the fd is wrapped at once.
        let fd = unsafe { libc::eventfd(0, libc::EFD_NONBLOCK | libc::EFD_CLOEXEC) };
        if fd < 0 {
            return Err(std::io::Error::last_os_error());
        }
        // SAFETY: a fresh fd we own.
        Ok(EventFd(unsafe { OwnedFd::from_raw_fd(fd) }))
    }
    /// Wakes the waiter (one write, no allocation: the cycle thread calls it).
    pub fn notify(&self) {
        let one = 1u64.to_ne_bytes();
        // SAFETY: 8 bytes of ours.
        unsafe { libc::write(self.0.as_raw_fd(), one.as_ptr().cast(), 8) };
    }
    fn drain(&self) {
        let mut v = [0u8; 8];
        // SAFETY: 8 bytes of ours; non-blocking.
        unsafe { libc::read(self.0.as_raw_fd(), v.as_mut_ptr().cast(), 8) };
    }
}

/// Waits until `socket` (if any) is readable, `wake` was notified, or `timeout` passed;
/// whether the socket is readable. A notification is consumed.
pub fn wait(
    socket: Option<&OwnedFd>,
    wake: &EventFd,
    timeout: std::time::Duration,
) -> std::io::Result<bool> {
    let mut fds = [
        libc::pollfd {
            fd: wake.0.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        },
        libc::pollfd {
            fd: socket.map_or(-1, |s| s.as_raw_fd()),
            events: libc::POLLIN,
            revents: 0,
        },
    ];
    // Rounded up: a wait of 0.3 ms must not become a poll that returns at once (a busy loop
    // until the time has passed).
    let ms = timeout.as_nanos().div_ceil(1_000_000).min(i32::MAX as u128) as i32;
    // SAFETY: two pollfds of ours.
    let n = unsafe { libc::poll(fds.as_mut_ptr(), 2, ms) };
    if n < 0 {
        let e = std::io::Error::last_os_error();
        return if e.kind() == std::io::ErrorKind::Interrupted {
            Ok(false)
        } else {
            Err(e)
        };
    }
    if fds[0].revents != 0 {
        wake.drain();
    }
    if fds[1].revents & (libc::POLLERR | libc::POLLHUP | libc::POLLNVAL) != 0 {
        return Err(std::io::Error::other(format!(
            "the socket reports {}",
            if fds[1].revents & libc::POLLNVAL != 0 {
                "an invalid descriptor"
            } else {
                "an error or hang-up"
            }
        )));
    }
    Ok(fds[1].revents & libc::POLLIN != 0)
}
