//! motiond's own TX/RX loop: ethercrab's `PduTx`/`PduRx` driven on a thread of their own,
//! over a raw socket (a network interface) or the emulated segment in this process. It
//! replaces ethercrab's `tx_rx_task`, which ends with an error at the first reply it cannot
//! place (a late reply, the second answer to a frame sent again with the same PDU index —
//! ethercrab issue #293) and leaves the bus dead. Here such a reply is counted and dropped:
//!
//! - `late`: a reply to a PDU index that is not waiting for one, arriving a PDU timeout or
//!   more after the index was sent (its frame was answered by a retry's reply, or given up);
//! - `duplicate`: the same, sooner (the segment answered twice);
//! - `malformed`: an EtherCAT frame that does not parse.
//!
//! Only the socket failing ends the loop (or [`LinkState::kill`], for tests): the reason is
//! kept, the thread waits, and [`LinkState::request_restart`] opens the link again with the
//! same `PduTx`/`PduRx` (nothing is lost: the frames in flight time out and are freed).
//!
//! The thread asks for SCHED_FIFO (one below the cycle thread) and is pinned to the CPU before
//! the cycle thread's (the cycle thread takes the last one) when there are two or more.

use std::collections::VecDeque;
use std::os::fd::OwnedFd;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering::Relaxed};
use std::sync::{Arc, Mutex};
use std::task::{Wake, Waker};
use std::time::{Duration, Instant};

use ethercrab::error::{Error, PduError};
use ethercrab::{PduRx, PduTx, ReceiveAction};

use crate::emu::Segment;
use crate::raw::{self, EventFd};

/// How long the TX/RX thread looks for the next frame without sleeping after the last one
/// went out or came back, and the cycle thread for a reply before it parks (see
/// [`block_on_spinning`]). A frame's round trip through the emulated segment, or on the wire
/// for a few drives, is well within it; a segment of 64 drives sends five frames a cycle.
pub const SPIN: Duration = Duration::from_micros(100);

/// `block_on` for the cycle thread's exchange: while the future waits for a reply it polls
/// again as soon as it is woken, spinning (yielding) for up to [`SPIN`] before it parks. A
/// parked thread is woken from the TX/RX thread's CPU by an interrupt that costs tens of
/// microseconds per frame on a virtual machine — five frames a cycle for 64 drives (decision
/// 170). `spin`: whether spinning can help, i.e. the TX/RX thread runs on another CPU (see
/// [`LinkState::runs_apart_from_caller`]); on the same CPU a spinning real-time thread would
/// only keep the reply from being made.
pub fn block_on_spinning<F: std::future::Future>(f: F, spin: bool) -> F::Output {
    use std::sync::atomic::Ordering::{Acquire, Release};
    use std::task::{Context, Poll};
    thread_local! {
        // Made once per thread: the cycle's exchange allocates nothing.
        static WAKER: (Arc<SpinFlag>, Waker) = {
            let flag = Arc::new(SpinFlag {
                woken: AtomicBool::new(false),
                thread: std::thread::current(),
            });
            (flag.clone(), Waker::from(flag))
        };
    }
    WAKER.with(|(flag, waker)| {
        let mut cx = Context::from_waker(waker);
        let mut f = std::pin::pin!(f);
        let mut spin = spin;
        loop {
            if let Poll::Ready(v) = f.as_mut().poll(&mut cx) {
                return v;
            }
            let since = Instant::now();
            let spinning = spin && CYCLE_SPIN.allows();
            while !flag.woken.swap(false, Acquire) {
                if !spinning || since.elapsed() >= SPIN {
                    // A wake between the check and the park leaves its token: park returns.
                    std::thread::park();
                    flag.woken.store(false, Release);
                    // A wake that came while spinning left a token too, and this park may
                    // have returned on it: no second spin in this exchange.
                    spin = false;
                    break;
                }
                std::thread::yield_now();
            }
            if spinning {
                CYCLE_SPIN.spend(since.elapsed().min(SPIN));
            }
        }
    })
}

/// The waker of [`block_on_spinning`]: a flag the spinning thread watches, and an unpark for
/// when it stopped spinning.
struct SpinFlag {
    woken: AtomicBool,
    thread: std::thread::Thread,
}

impl Wake for SpinFlag {
    fn wake(self: Arc<Self>) {
        self.wake_by_ref();
    }
    fn wake_by_ref(self: &Arc<Self>) {
        self.woken.store(true, std::sync::atomic::Ordering::Release);
        // Only a token when the thread is not parked: no system call then.
        self.thread.unpark();
    }
}

/// The SCHED_FIFO priority of the TX/RX thread: just below the cycle thread's 80, so that a
/// busy cycle is not preempted by it on a shared CPU, and above everything else.
pub const TXRX_PRIORITY: i32 = 79;

/// What the loop shares: counters, whether it runs, why it stopped; and the switches to stop
/// and restart it.
pub struct LinkState {
    pub sent: AtomicU64,
    pub received: AtomicU64,
    pub late: AtomicU64,
    pub duplicate: AtomicU64,
    pub malformed: AtomicU64,
    /// Times the loop was started again after it stopped.
    pub restarts: AtomicU64,
    alive: AtomicBool,
    restart: AtomicBool,
    kill: AtomicBool,
    fault: Mutex<Option<String>>,
    /// What the thread got: SCHED_FIFO and the CPU, or why not.
    realtime: Mutex<String>,
    /// The CPU the thread runs on when it got both SCHED_FIFO and its CPU, else -1.
    pinned_cpu: std::sync::atomic::AtomicI32,
    wake: EventFd,
}

impl LinkState {
    fn new() -> std::io::Result<LinkState> {
        Ok(LinkState {
            sent: AtomicU64::new(0),
            received: AtomicU64::new(0),
            late: AtomicU64::new(0),
            duplicate: AtomicU64::new(0),
            malformed: AtomicU64::new(0),
            restarts: AtomicU64::new(0),
            alive: AtomicBool::new(false),
            restart: AtomicBool::new(false),
            kill: AtomicBool::new(false),
            fault: Mutex::new(None),
            realtime: Mutex::new(String::new()),
            pinned_cpu: std::sync::atomic::AtomicI32::new(-1),
            wake: EventFd::new()?,
        })
    }
    /// The loop runs (frames can flow).
    pub fn alive(&self) -> bool {
        self.alive.load(Relaxed)
    }
    /// Why the loop stopped (`None` while it runs).
    pub fn fault(&self) -> Option<String> {
        self.fault.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
    /// Whether this thread never runs on the TX/RX thread's CPU (its affinity excludes it),
    /// and that thread has its CPU at real-time priority: then waiting for a frame by
    /// spinning saves the cross-CPU wake-up. Checked once per thread and CPU.
    pub fn runs_apart_from_caller(&self) -> bool {
        thread_local! {
            static APART: std::cell::Cell<Option<(i32, bool)>> = const { std::cell::Cell::new(None) };
        }
        let cpu = self.pinned_cpu.load(Relaxed);
        if cpu < 0 {
            return false;
        }
        if let Some((c, apart)) = APART.get()
            && c == cpu
        {
            return apart;
        }
        // SAFETY: reads this thread's affinity into a zeroed set of the right size.
        let apart = unsafe {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) == 0
                && !libc::CPU_ISSET(cpu as usize, &set)
        };
        APART.set(Some((cpu, apart)));
        apart
    }

    pub fn realtime(&self) -> String {
        self.realtime
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }
    /// Asks a stopped loop to open its link again (no allocation: the cycle thread calls it
    /// on MC_Reset). Nothing when it runs.
    pub fn request_restart(&self) {
        if !self.alive() {
            self.restart.store(true, Relaxed);
            self.wake.notify();
        }
    }
    /// Stops the loop as a failing socket would (fault injection).
    pub fn kill(&self) {
        self.kill.store(true, Relaxed);
        self.wake.notify();
    }
    fn set_fault(&self, why: Option<String>) {
        *self.fault.lock().unwrap_or_else(|e| e.into_inner()) = why;
    }
}

/// Where the loop's frames go.
pub trait Wire: Send {
    fn send(&mut self, frame: &[u8]) -> std::io::Result<()>;
    /// Waits up to `timeout` (or until `wake`) for a frame; `Some(len)` when one is in `buf`.
    fn recv(
        &mut self,
        buf: &mut [u8],
        wake: &EventFd,
        timeout: Duration,
    ) -> std::io::Result<Option<usize>>;
}

/// A network interface.
pub struct RawWire(OwnedFd);

impl RawWire {
    pub fn open(interface: &str) -> std::io::Result<RawWire> {
        raw::open(interface).map(RawWire)
    }
}

impl Wire for RawWire {
    fn send(&mut self, frame: &[u8]) -> std::io::Result<()> {
        raw::send(&self.0, frame)
    }
    fn recv(
        &mut self,
        buf: &mut [u8],
        wake: &EventFd,
        timeout: Duration,
    ) -> std::io::Result<Option<usize>> {
        if let Some(n) = raw::try_recv(&self.0, buf)? {
            return Ok(Some(n));
        }
        if raw::wait(Some(&self.0), wake, timeout)? {
            raw::try_recv(&self.0, buf)
        } else {
            Ok(None)
        }
    }
}

/// The emulated segment in this process: each frame passes through it at once; its answers
/// come back as its reply faults say (late, twice).
pub struct SegmentWire {
    segment: Arc<Mutex<Segment>>,
    answers: VecDeque<(Instant, Vec<u8>)>,
}

impl SegmentWire {
    pub fn new(segment: Arc<Mutex<Segment>>) -> SegmentWire {
        SegmentWire {
            segment,
            answers: VecDeque::new(),
        }
    }
}

impl Wire for SegmentWire {
    fn send(&mut self, frame: &[u8]) -> std::io::Result<()> {
        let mut seg = self.segment.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(answer) = seg.process(frame) {
            let (delay, copies) = seg.reply_plan();
            let due = Instant::now() + delay;
            for _ in 1..copies {
                self.answers.push_back((due, answer.clone()));
            }
            self.answers.push_back((due, answer));
        }
        Ok(())
    }
    fn recv(
        &mut self,
        buf: &mut [u8],
        wake: &EventFd,
        timeout: Duration,
    ) -> std::io::Result<Option<usize>> {
        let now = Instant::now();
        // The earliest due answer (late ones are behind prompt ones in the queue).
        let next = self
            .answers
            .iter()
            .enumerate()
            .min_by_key(|(_, (due, _))| *due)
            .map(|(i, (due, _))| (i, *due));
        match next {
            Some((i, due)) if due <= now => {
                let (_, a) = self.answers.remove(i).expect("found");
                let n = a.len().min(buf.len());
                buf[..n].copy_from_slice(&a[..n]);
                Ok(Some(n))
            }
            Some((_, due)) => {
                raw::wait(None, wake, timeout.min(due - now))?;
                Ok(None)
            }
            None => {
                raw::wait(None, wake, timeout)?;
                Ok(None)
            }
        }
    }
}

struct EventWaker(Arc<LinkState>);

impl Wake for EventWaker {
    fn wake(self: Arc<Self>) {
        self.0.wake.notify();
    }
    fn wake_by_ref(self: &Arc<Self>) {
        self.0.wake.notify();
    }
}

/// Whether a frame is (part of) a cycle's exchange: its first datagram reads or writes the
/// process image (LRD, LWR, LRW) or is the DC time's FRMW that precedes it.
fn carries_process_data(frame: &[u8]) -> bool {
    matches!(frame.get(16), Some(0x0A..=0x0C | 0x0E))
}

/// How much real-time threads may spin: a quarter of every 10 ms at most, for all threads
/// that share the budget together (the cycle thread has one, every segment's TX/RX thread
/// shares another: they would share a CPU). Linux stops real-time threads that ran 95 % of a
/// second for the rest of it (50 ms, longer than a frame may take), and the other threads on
/// the CPU need it too: a cycle whose exchange fills it (a short cycle, many drives) sleeps
/// between frames again.
struct SpinBudget {
    /// Start of the current window and time spun in it, in ns since the first use.
    window: AtomicU64,
    spent: AtomicU64,
}

static CYCLE_SPIN: SpinBudget = SpinBudget::new();
static TXRX_SPIN: SpinBudget = SpinBudget::new();

impl SpinBudget {
    const WINDOW_NS: u64 = 10_000_000;
    const SHARE_NS: u64 = 2_500_000;
    const fn new() -> SpinBudget {
        SpinBudget {
            window: AtomicU64::new(0),
            spent: AtomicU64::new(0),
        }
    }
    fn now_ns() -> u64 {
        static EPOCH: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
        EPOCH.get_or_init(Instant::now).elapsed().as_nanos() as u64
    }
    fn allows(&self) -> bool {
        let now = Self::now_ns();
        let w = self.window.load(Relaxed);
        if now.saturating_sub(w) >= Self::WINDOW_NS
            && self
                .window
                .compare_exchange(w, now, Relaxed, Relaxed)
                .is_ok()
        {
            self.spent.store(0, Relaxed);
        }
        self.spent.load(Relaxed) < Self::SHARE_NS
    }
    fn spend(&self, d: Duration) {
        self.spent.fetch_add(d.as_nanos() as u64, Relaxed);
    }
}

/// The PDU index of a frame's first datagram (Ethernet 14 bytes, EtherCAT header 2, then the
/// datagram's command and index).
fn first_pdu_index(frame: &[u8]) -> Option<u8> {
    frame.get(17).copied()
}

/// Runs the loop until ethercrab says exit (`Ok`) or the link fails (`Err`: why).
fn run(
    tx: &mut PduTx<'static>,
    rx: &mut PduRx<'static>,
    wire: &mut dyn Wire,
    st: &Arc<LinkState>,
    pdu_timeout: Duration,
) -> Result<(), String> {
    let waker = Waker::from(Arc::new(EventWaker(st.clone())));
    let mut buf = vec![0u8; 2048];
    // Per PDU index: when it was first sent, and whether its reply came.
    let mut sent_at = [None::<Instant>; 256];
    let mut answered = [false; 256];
    // The last process-data frame sent or received: the cycle's exchange is under way.
    let mut last_traffic = Instant::now()
        .checked_sub(SPIN)
        .unwrap_or_else(Instant::now);
    // Spinning helps only a TX/RX thread that has its own CPU at real-time priority.
    let may_spin = st.pinned_cpu.load(Relaxed) >= 0;
    loop {
        if st.kill.swap(false, Relaxed) {
            return Err("the TX/RX loop was stopped (injected fault)".into());
        }
        tx.replace_waker(&waker);
        if tx.should_exit() {
            return Ok(());
        }
        while let Some(frame) = tx.next_sendable_frame() {
            let mut failed = None;
            let mut pd = false;
            let r = frame.send_blocking(|bytes| {
                pd = carries_process_data(bytes);
                if let Some(i) = first_pdu_index(bytes) {
                    let i = usize::from(i);
                    // A retry keeps its index and its first send time.
                    if answered[i] || sent_at[i].is_none() {
                        sent_at[i] = Some(Instant::now());
                    }
                    answered[i] = false;
                }
                match wire.send(bytes) {
                    Ok(()) => Ok(bytes.len()),
                    Err(e) => {
                        failed = Some(e);
                        Err(Error::SendFrame)
                    }
                }
            });
            if r.is_err() {
                return Err(match failed {
                    Some(e) => format!("sending a frame failed: {e}"),
                    None => "sending a frame failed".into(),
                });
            }
            st.sent.fetch_add(1, Relaxed);
            if pd {
                last_traffic = Instant::now();
            }
        }
        // Right after a frame went out or came back the next one follows within
        // microseconds (the cycle's next chunk of process image, its reply): look for it
        // without sleeping for a while, as a sleeping thread is woken by another CPU only
        // after tens of microseconds on a virtual machine.
        let wait = if may_spin && last_traffic.elapsed() < SPIN && TXRX_SPIN.allows() {
            Duration::ZERO
        } else {
            Duration::from_millis(50)
        };
        let looked = Instant::now();
        let n = match wire.recv(&mut buf, &st.wake, wait) {
            Ok(Some(n)) => n,
            Ok(None) => {
                if wait.is_zero() {
                    // Yield, not spin: another thread of the same SCHED_FIFO priority on this
                    // CPU (another segment's loop) must not wait for this one's window to end.
                    std::thread::yield_now();
                    TXRX_SPIN.spend(looked.elapsed());
                }
                continue;
            }
            Err(e) => return Err(format!("receiving failed: {e}")),
        };
        if carries_process_data(&buf[..n]) {
            last_traffic = Instant::now();
        }
        let frame = &buf[..n];
        let index = first_pdu_index(frame).map(usize::from);
        match rx.receive_frame(frame) {
            Ok(ReceiveAction::Processed) => {
                st.received.fetch_add(1, Relaxed);
                if let Some(i) = index {
                    answered[i] = true;
                }
            }
            Ok(ReceiveAction::Ignored) => {}
            // No frame waits for this index (given up, or already answered), or its frame
            // is not waiting for a reply now (answered; about to be sent again).
            Err(Error::Pdu(PduError::InvalidIndex(_) | PduError::Decode)) => {
                let late = index
                    .and_then(|i| sent_at[i])
                    .is_none_or(|t| t.elapsed() >= pdu_timeout);
                if late {
                    st.late.fetch_add(1, Relaxed);
                } else {
                    st.duplicate.fetch_add(1, Relaxed);
                }
            }
            Err(_) => {
                st.malformed.fetch_add(1, Relaxed);
            }
        }
    }
}

/// Tries SCHED_FIFO and pinning for the calling thread; what it got, in words.
/// What it got, in words; whether it got all it asked for; the CPU it is pinned to when it
/// also runs at real-time priority.
fn request_realtime() -> (String, bool, Option<usize>) {
    let mut notes = Vec::new();
    let mut granted = true;
    let mut pinned = None;
    // SAFETY: plain libc calls on the current thread with valid arguments.
    unsafe {
        let param = libc::sched_param {
            sched_priority: TXRX_PRIORITY,
        };
        if libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) == 0 {
            notes.push(format!("SCHED_FIFO {TXRX_PRIORITY}"));
        } else {
            granted = false;
            notes.push(format!(
                "SCHED_FIFO refused ({})",
                std::io::Error::last_os_error()
            ));
        }
        let ncpu = libc::sysconf(libc::_SC_NPROCESSORS_ONLN).max(1) as usize;
        if ncpu > 1 {
            // The cycle thread takes the last CPU; this one the CPU before it.
            let cpu = ncpu - 2;
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            libc::CPU_SET(cpu, &mut set);
            if libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) == 0 {
                notes.push(format!("pinned to CPU {cpu}"));
                pinned = Some(cpu);
            } else {
                granted = false;
                notes.push(format!(
                    "pinning refused ({})",
                    std::io::Error::last_os_error()
                ));
            }
        } else {
            notes.push("not pinned (one CPU)".into());
        }
    }
    (notes.join(", "), granted, pinned.filter(|_| granted))
}

/// Opens the link again after it failed.
pub type Opener = Box<dyn FnMut() -> std::io::Result<Box<dyn Wire>> + Send>;

/// Starts the TX/RX thread on `wire` (already open: a failure to open is the caller's error);
/// `reopen` opens the link again on a restart.
pub fn spawn(
    mut tx: PduTx<'static>,
    mut rx: PduRx<'static>,
    wire: Box<dyn Wire>,
    mut reopen: Opener,
    pdu_timeout: Duration,
) -> std::io::Result<Arc<LinkState>> {
    let st = Arc::new(LinkState::new()?);
    st.alive.store(true, Relaxed);
    let state = st.clone();
    std::thread::Builder::new()
        .name("ecat-txrx".into())
        .spawn(move || {
            let st = state;
            let (rt, granted, pinned) = request_realtime();
            st.pinned_cpu
                .store(pinned.map_or(-1, |c| c as i32), Relaxed);
            if !granted {
                tracing::warn!("EtherCAT TX/RX thread: {rt}; it runs at normal priority");
            }
            *st.realtime.lock().unwrap_or_else(|e| e.into_inner()) = rt;
            let mut wire = Some(wire);
            loop {
                if let Some(mut w) = wire.take() {
                    st.set_fault(None);
                    st.alive.store(true, Relaxed);
                    let r = run(&mut tx, &mut rx, &mut *w, &st, pdu_timeout);
                    st.alive.store(false, Relaxed);
                    match r {
                        Ok(()) => return,
                        Err(why) => {
                            tracing::error!(
                                "EtherCAT TX/RX loop stopped: {why}; the bus is faulted until a reset (MC_Reset or POST /api/v1/bus/reset)"
                            );
                            st.set_fault(Some(why));
                        }
                    }
                }
                // Stopped: wait for a restart (or for ethercrab to say exit).
                while !st.restart.swap(false, Relaxed) {
                    if tx.should_exit() {
                        return;
                    }
                    let _ = raw::wait(None, &st.wake, Duration::from_millis(100));
                }
                st.restarts.fetch_add(1, Relaxed);
                match reopen() {
                    Ok(w) => {
                        tracing::info!("EtherCAT TX/RX loop started again");
                        wire = Some(w);
                    }
                    Err(e) => {
                        let why = format!("the link could not be opened again: {e}");
                        tracing::error!("EtherCAT TX/RX loop: {why}");
                        st.set_fault(Some(why));
                    }
                }
            }
        })?;
    Ok(st)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::task::{Context, Poll};

    /// A reply another thread gives after `delay`, waking whoever waits for it.
    struct Reply(Arc<Mutex<(Option<u32>, Option<Waker>)>>);

    impl std::future::Future for Reply {
        type Output = u32;
        fn poll(self: std::pin::Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<u32> {
            let mut g = self.0.lock().unwrap();
            match g.0 {
                Some(v) => Poll::Ready(v),
                None => {
                    g.1 = Some(cx.waker().clone());
                    Poll::Pending
                }
            }
        }
    }

    #[test]
    fn the_exchange_sees_its_reply_whether_it_spins_or_has_parked() {
        // Within the spin, well after it (parked), and several in a row on one thread (the
        // thread's waker is reused: a stale wake of one exchange must not lose the next).
        for (delay, spin) in [
            (0, true),
            (20, true),
            (500, true),
            (20_000, true),
            (0, true),
            (300, false),
            (0, false),
            (20_000, false),
        ] {
            let shared = Arc::new(Mutex::new((None, None::<Waker>)));
            let replier = shared.clone();
            let t = std::thread::spawn(move || {
                std::thread::sleep(Duration::from_micros(delay));
                let mut g = replier.lock().unwrap();
                g.0 = Some(delay as u32);
                if let Some(w) = g.1.take() {
                    w.wake();
                }
            });
            assert_eq!(block_on_spinning(Reply(shared), spin), delay as u32);
            t.join().unwrap();
        }
    }
}
