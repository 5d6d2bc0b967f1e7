//! The cycle thread (DESIGN §2): owns the kernel and the drive bus; talks to the async side
//! only through bounded lock-free queues and a triple buffer.
//!
//! Inside the loop there is no allocation, no lock, no logging and no syscall except the
//! timer (`clock_nanosleep` / `clock_gettime`). Axes are built off the thread and handed in as
//! boxes; whatever they replace is handed back through `garbage` to be freed off the thread.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering::Relaxed};

use crossbeam_queue::ArrayQueue;
use motion::group::{Group, GroupId, GroupStatus, MAX_GROUPS, PathTable};
use motion::{
    Axis, AxisSlot, AxisStatus, Command, CommandEvent, CommandId, DriveFeedback, DriveSetpoint,
    ErrorId, EventSink, Kernel, Verdict,
};

use drives::{BusError, Drive, DriveBus, SimFault};

use crate::scope::{SCOPE_RING, ScopeConfig, ScopeFrame};
use crate::stats::CycleStats;

/// Number of axis slots (fixed so that the cycle never allocates).
pub const MAX_AXES: usize = 64;
const COMMAND_QUEUE: usize = 1024;
const REPLY_QUEUE: usize = 2048;
const EVENT_RING: usize = 1 << 16;
/// Commands taken from the queue per cycle at most, so a burst cannot overrun a cycle.
const DRAIN_PER_CYCLE: usize = 64;

/// What the async side asks of the cycle thread.
pub enum Request {
    Command(Command),
    /// Put an axis (and its drive) into a slot; with `require_disabled`, only if the axis
    /// there now is disabled (else the new boxes come back as garbage and the reply is an error).
    InsertAxis {
        ticket: u64,
        slot: AxisSlot,
        axis: Box<Axis>,
        drive: Drive,
        require_disabled: bool,
    },
    RemoveAxis {
        ticket: u64,
        slot: AxisSlot,
        require_disabled: bool,
    },
    /// Inject a fault or disturbance into the simulated drive of a slot (the simulated bus
    /// only). It acts on the drive's step in this cycle's exchange; the kernel reads it in
    /// the next cycle.
    InjectFault {
        ticket: u64,
        slot: AxisSlot,
        fault: SimFault,
    },
    /// Restart the following-error peak hold of a slot (the online tab's reset).
    ResetFollowingErrorPeak {
        ticket: u64,
        slot: AxisSlot,
    },
    /// Put a built cam under its table id (refused while the table is in use: a coupled
    /// table is never swapped under its slave).
    InsertCam {
        ticket: u64,
        id: u32,
        cam: Arc<motion::cam::Cam>,
    },
    /// Take a cam out (refused while in use).
    RemoveCam {
        ticket: u64,
        id: u32,
    },
    /// New data for a table (online change when coupled: see `Kernel::change_cam`).
    ChangeCam {
        ticket: u64,
        id: u32,
        cam: Arc<motion::cam::Cam>,
        change: motion::cam::OnlineChange,
    },
    /// Whether new data for a table would be taken now (no earlier change on its way).
    ProbeCamChange {
        ticket: u64,
        id: u32,
    },
    /// DELETEQUEUEDDATA: written data not yet in effect stays out of the slaves.
    DropCamData {
        ticket: u64,
        id: u32,
    },
    /// Put a built group into its slot (refused while the group there is enabled or in
    /// error: a configuration changes only on a disabled group).
    InsertGroup {
        ticket: u64,
        id: GroupId,
        group: Box<Group>,
    },
    /// Take a group out; with `require_disabled`, only while it is disabled (not enabled, not
    /// in error).
    RemoveGroup {
        ticket: u64,
        id: GroupId,
        require_disabled: bool,
    },
    /// MC_MovePath: a table built and checked off the thread; it comes back as garbage after
    /// the verdict (the group copies what it accepts into its own queue).
    MovePath {
        command: CommandId,
        group: GroupId,
        table: Box<PathTable>,
        /// Its items built off the thread (`motion::group::prepare_path`), taken when the
        /// group still joins them where they were built from; built here otherwise.
        prepared: Option<Box<motion::group::PreparedPath>>,
    },
    /// What the scope samples from the cycle this is drained in (see `scope.rs`).
    ScopeConfig {
        ticket: u64,
        config: ScopeConfig,
    },
}

/// The cycle thread's answer to a request (`ticket` = command id for commands).
#[derive(Clone, Copy, Debug)]
pub struct Reply {
    pub ticket: u64,
    /// The cycle the request takes effect in: the step that follows the drain. The kernel
    /// stamps the events of an accepted command's submit with this number too, and the
    /// snapshot of that step carries it.
    pub cycle: u64,
    pub result: Result<(), ErrorId>,
    /// What a refused command needed (the kernel's hint), for the answer's `detail`.
    pub hint: Option<motion::RefusalHint>,
}

pub enum Garbage {
    Axis(#[allow(dead_code, reason = "held only to be dropped off the cycle thread")] Box<Axis>),
    Drive(#[allow(dead_code, reason = "held only to be dropped off the cycle thread")] Drive),
    Cam(
        #[allow(dead_code, reason = "held only to be dropped off the cycle thread")]
        Arc<motion::cam::Cam>,
    ),
    Group(#[allow(dead_code, reason = "held only to be dropped off the cycle thread")] Box<Group>),
    Path(
        #[allow(dead_code, reason = "held only to be dropped off the cycle thread")] Box<PathTable>,
    ),
    Prepared(
        #[allow(dead_code, reason = "held only to be dropped off the cycle thread")]
        Box<motion::group::PreparedPath>,
    ),
}

/// Status of every slot at the end of one cycle.
#[derive(Clone)]
pub struct Snapshot {
    pub cycle: u64,
    pub axes: [Option<AxisStatus>; MAX_AXES],
    /// The groups' status (TF5420 `NcToPlc` of each group), by group slot.
    pub groups: [Option<GroupStatus>; MAX_GROUPS],
    /// The `Axis::status_seq` each slot's status was copied at: a slot whose axis has the
    /// same count now gets only its cycle counter written (this buffer is reused every
    /// third publication, so it keeps its own record).
    copied_at: [u64; MAX_AXES],
}

impl Default for Snapshot {
    fn default() -> Self {
        Snapshot {
            cycle: 0,
            axes: [None; MAX_AXES],
            groups: [None; MAX_GROUPS],
            copied_at: [u64::MAX; MAX_AXES],
        }
    }
}

/// A request in the queue to the cycle thread, with the moment its requester stops waiting.
pub struct Queued {
    pub request: Request,
    /// `CLOCK_MONOTONIC` nanoseconds after which the request is dropped undone (its requester
    /// has answered 503 by then, so it must not act later); 0 = never.
    pub expires_ns: u64,
}

/// The queues and counters shared by both sides.
pub struct Shared {
    requests: ArrayQueue<Queued>,
    pub replies: ArrayQueue<Reply>,
    pub events: ArrayQueue<CommandEvent>,
    pub garbage: ArrayQueue<Garbage>,
    /// One frame per cycle while the scope samples something; a full ring drops the frame
    /// (counted in `stats.scope_frames_dropped`).
    pub scope_frames: ArrayQueue<ScopeFrame>,
    pub stats: CycleStats,
    pub cycle: AtomicU64,
    /// The newest cycle whose snapshot is published (every cycle in real time; in virtual
    /// time at least every cycle the clock stops at). Stored after `cycle`.
    pub published_cycle: AtomicU64,
    pub shutdown: AtomicBool,
    pub period_ns: u64,
    /// Written by the cycle thread when it produced verdicts or events: the pump drains at
    /// once.
    pub wake: Wake,
    /// Virtual time (`--clock virtual|fast`): when the cycle thread may step.
    pub clock: ClockLink,
}

/// What the cycle thread runs on in virtual time (issue 26): it steps while its cycle is below
/// `limit` and no watched command has stopped it; between steps it takes requests as they come
/// (they apply at the next cycle) and parks. The async side (`crate::clock::Clock`) sets the
/// limit and unparks it. In real time none of this is read.
pub struct ClockLink {
    pub virtual_time: bool,
    /// `--clock fast=FACTOR`: wall nanoseconds per cycle (0: as fast as the machine can).
    pub pace_ns: u64,
    /// The cycle thread steps while its cycle is below this.
    pub limit: AtomicU64,
    /// A command whose events stop the clock after the cycle that produced them (0: none) …
    pub watch: AtomicU64,
    /// … and the cycle it stopped after (0: not stopped); cleared by the async side.
    pub watch_stop: AtomicU64,
    /// The cycle thread is deciding on or running a cycle (an advance that ends waits for it:
    /// the clock then stands where the answer says).
    pub stepping: AtomicBool,
    thread: std::sync::OnceLock<std::thread::Thread>,
}

impl ClockLink {
    fn new(virtual_time: bool, pace_ns: u64) -> Self {
        ClockLink {
            virtual_time,
            pace_ns,
            limit: AtomicU64::new(if virtual_time { 0 } else { u64::MAX }),
            watch: AtomicU64::new(0),
            watch_stop: AtomicU64::new(0),
            stepping: AtomicBool::new(false),
            thread: std::sync::OnceLock::new(),
        }
    }

    /// Wakes a parked cycle thread (virtual time; nothing in real time).
    pub fn nudge(&self) {
        if self.virtual_time {
            if let Some(t) = self.thread.get() {
                t.unpark();
            }
        }
    }
}

/// The cycle thread's wake-up of the pump: an eventfd. Signalling is one `write(2)` — no lock,
/// no allocation (a `tokio::sync::Notify` takes its waiters' mutex when the pump waits, and
/// the cycle thread must never wait on a lock the async side holds).
pub struct Wake {
    fd: std::os::fd::OwnedFd,
}

impl Wake {
    fn new() -> Self {
        // SAFETY: eventfd returns a new descriptor or -1.
        let fd = unsafe { libc::eventfd(0, libc::EFD_NONBLOCK | libc::EFD_CLOEXEC) };
        assert!(fd >= 0, "eventfd: {}", std::io::Error::last_os_error());
        // SAFETY: fd is a fresh descriptor that nothing else owns.
        Wake {
            fd: unsafe { std::os::fd::FromRawFd::from_raw_fd(fd) },
        }
    }

    /// Wakes the pump (cycle thread): adds 1 to the counter; never blocks (a full counter,
    /// 2^64 − 2 unread wake-ups, is already a wake-up).
    pub fn signal(&self) {
        let one: u64 = 1;
        // SAFETY: writes 8 bytes from a valid u64 to our own descriptor.
        unsafe {
            libc::write(
                std::os::fd::AsRawFd::as_raw_fd(&self.fd),
                (&one as *const u64).cast(),
                8,
            )
        };
    }

    /// The descriptor the pump waits on (a duplicate, for tokio's `AsyncFd`).
    pub fn listener(&self) -> std::io::Result<std::os::fd::OwnedFd> {
        self.fd.try_clone()
    }
}

impl Shared {
    pub fn new(period_ns: u64) -> Self {
        Self::with_clock(period_ns, false, 0)
    }

    /// `virtual_time`: cycles only when the async side lets them (`ClockLink`), each `pace_ns`
    /// of wall time apart at least.
    pub fn with_clock(period_ns: u64, virtual_time: bool, pace_ns: u64) -> Self {
        Shared {
            clock: ClockLink::new(virtual_time, pace_ns),
            requests: ArrayQueue::new(COMMAND_QUEUE),
            replies: ArrayQueue::new(REPLY_QUEUE),
            events: ArrayQueue::new(EVENT_RING),
            garbage: ArrayQueue::new(4 * MAX_AXES + COMMAND_QUEUE),
            scope_frames: ArrayQueue::new(SCOPE_RING),
            stats: CycleStats::default(),
            wake: Wake::new(),
            cycle: AtomicU64::new(0),
            published_cycle: AtomicU64::new(0),
            shutdown: AtomicBool::new(false),
            period_ns,
        }
    }

    /// Queues a request that never expires (nobody waits for it, or a test steps the cycle).
    #[allow(
        clippy::result_large_err,
        reason = "a full queue hands the request back as it was; boxing it would allocate per command"
    )]
    pub fn push(&self, request: Request) -> Result<(), Request> {
        self.enqueue(request, 0)
    }

    /// Queues a request that is dropped undone unless the cycle thread takes it within `ttl`.
    #[allow(
        clippy::result_large_err,
        reason = "a full queue hands the request back as it was; boxing it would allocate per command"
    )]
    pub fn push_expiring(&self, request: Request, ttl: std::time::Duration) -> Result<(), Request> {
        self.enqueue(request, now_ns() + ttl.as_nanos() as u64)
    }

    #[allow(
        clippy::result_large_err,
        reason = "a full queue hands the request back as it was; boxing it would allocate per command"
    )]
    fn enqueue(&self, request: Request, expires_ns: u64) -> Result<(), Request> {
        self.requests
            .push(Queued {
                request,
                expires_ns,
            })
            .map_err(|q| q.request)?;
        // A stopped virtual clock takes requests as they come.
        self.clock.nudge();
        Ok(())
    }
}

/// What real-time facilities the OS granted.
#[derive(Clone, Debug, Default, serde::Serialize, utoipa::ToSchema)]
pub struct RealtimeGrant {
    pub sched_fifo: bool,
    pub mlockall: bool,
    /// CPU the cycle thread is pinned to, if pinning was granted.
    pub pinned_cpu: Option<usize>,
    /// `/dev/cpu_dma_latency` held at 0 (no deep C-states that slow wake-ups).
    pub cpu_dma_latency_zero: bool,
    /// Why something was refused (empty when all was granted).
    pub notes: Vec<String>,
}

struct RingSink<'a> {
    q: &'a ArrayQueue<CommandEvent>,
    dropped: u64,
    pushed: u64,
    /// The command watched by a virtual clock's advance (0: none), and whether it had events.
    watch: u64,
    watched: bool,
}

impl EventSink for RingSink<'_> {
    fn push(&mut self, event: CommandEvent) {
        self.watched |= self.watch != 0 && event.command == self.watch;
        if self.q.push(event).is_err() {
            self.dropped += 1;
        } else {
            self.pushed += 1;
        }
    }
}

pub fn now_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: valid pointer to a timespec; CLOCK_MONOTONIC always exists on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

fn sleep_until(deadline_ns: u64) {
    let ts = libc::timespec {
        tv_sec: (deadline_ns / 1_000_000_000) as libc::time_t,
        tv_nsec: (deadline_ns % 1_000_000_000) as libc::c_long,
    };
    // SAFETY: valid timespec; an EINTR just makes us retry until the deadline has passed.
    while unsafe {
        libc::clock_nanosleep(
            libc::CLOCK_MONOTONIC,
            libc::TIMER_ABSTIME,
            &ts,
            std::ptr::null_mut(),
        )
    } == libc::EINTR
    {}
}

/// Linux's `MCL_ONFAULT` (x86, ARM; not in the libc crate for glibc): lock pages as they are
/// faulted in. An older kernel refuses it (EINVAL) and the plain mlockall is used.
const MCL_ONFAULT: libc::c_int = 4;

/// Reads one byte of every page of the process's executable mappings (the binary's and the
/// libraries' code), so that no code path of the cycle faults in later.
fn prefault_code() {
    let Ok(maps) = std::fs::read_to_string("/proc/self/maps") else {
        return;
    };
    for line in maps.lines() {
        let mut f = line.split_whitespace();
        let (Some(range), Some(perms)) = (f.next(), f.next()) else {
            continue;
        };
        if !perms.starts_with("r-x") {
            continue;
        }
        let Some((a, b)) = range.split_once('-') else {
            continue;
        };
        let (Ok(a), Ok(b)) = (usize::from_str_radix(a, 16), usize::from_str_radix(b, 16)) else {
            continue;
        };
        for page in (a..b).step_by(4096) {
            // SAFETY: the page is mapped readable (r-x) for the life of the process.
            unsafe { std::ptr::read_volatile(page as *const u8) };
        }
    }
}

/// Touches the first 256 KiB of the calling thread's stack (far more than the cycle uses).
#[inline(never)]
fn prefault_stack() {
    let mut stack = [0u8; 256 * 1024];
    std::hint::black_box(&mut stack);
}

/// Tries SCHED_FIFO, mlockall and pinning for the calling thread (done once, before the loop).
pub fn request_realtime(priority: i32) -> RealtimeGrant {
    let mut g = RealtimeGrant::default();
    // SAFETY: plain libc calls on the current thread with valid arguments.
    unsafe {
        let param = libc::sched_param {
            sched_priority: priority,
        };
        if libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) == 0 {
            g.sched_fifo = true;
        } else {
            g.notes.push(format!(
                "SCHED_FIFO refused: {}",
                std::io::Error::last_os_error()
            ));
        }
        // What the cycle runs is made resident first (every page of the code, this thread's
        // stack), then locked with what is resident and whatever is touched from now on
        // (MCL_ONFAULT) — not every page mapped: the embedded API-docs bundle (≈10 MB of the
        // binary) and the untouched parts of the other threads' 2 MB stacks stay out of
        // memory (decision 78).
        prefault_code();
        prefault_stack();
        if libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE | MCL_ONFAULT) == 0
            || libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) == 0
        {
            g.mlockall = true;
        } else {
            g.notes.push(format!(
                "mlockall refused: {}",
                std::io::Error::last_os_error()
            ));
        }
        // As cyclictest does: keep the CPUs out of deep idle states for the process's life.
        match std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/cpu_dma_latency")
        {
            Ok(mut f) => {
                use std::io::Write;
                if f.write_all(&0i32.to_ne_bytes()).is_ok() {
                    g.cpu_dma_latency_zero = true;
                    std::mem::forget(f); // the request holds while the file is open
                }
            }
            Err(e) => g.notes.push(format!("/dev/cpu_dma_latency not set: {e}")),
        }
        let ncpu = libc::sysconf(libc::_SC_NPROCESSORS_ONLN).max(1) as usize;
        // The last CPU: the async runtime's threads are not pinned and prefer the others.
        let cpu = ncpu - 1;
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        if ncpu > 1 && libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) == 0
        {
            g.pinned_cpu = Some(cpu);
        } else if ncpu > 1 {
            g.notes.push(format!(
                "pinning refused: {}",
                std::io::Error::last_os_error()
            ));
        } else {
            g.notes.push("pinning skipped: one CPU".into());
        }
    }
    g
}

/// The state the cycle thread owns.
pub struct CycleThread {
    pub kernel: Kernel,
    /// The process image exchange with every slot's drive (the simulated bus today).
    pub bus: Box<dyn DriveBus>,
    pub shared: Arc<Shared>,
    pub snapshot: triple_buffer::Input<Snapshot>,
    /// What the scope samples (nothing by default: no frames are pushed then).
    pub scope: ScopeConfig,
    /// The snapshot's slots that have ever held an axis are `..published` (only they are
    /// written each cycle: a slot emptied later is cleared in every buffer of the triple).
    published: usize,
    /// The same for the group slots.
    groups_published: usize,
    /// Virtual time: the snapshot is published only at a stop, for a watched event, while
    /// the scope samples, and at least every millisecond of wall time (copying 64 statuses
    /// every cycle was a quarter of a 64-axis cycle).
    lazy_publish: bool,
    /// This cycle is published (virtual time: the last before a stop, or a millisecond
    /// since the last).
    publish_next: bool,
    /// The last cycle was not published.
    unpublished: bool,
    /// The watched command had events from a request taken while the clock stood.
    watched_pending: bool,
}

impl CycleThread {
    /// `bus` must have [`MAX_AXES`] slots.
    pub fn new(
        cycle_time_s: f64,
        bus: Box<dyn DriveBus>,
        shared: Arc<Shared>,
        snapshot: triple_buffer::Input<Snapshot>,
    ) -> Self {
        assert_eq!(bus.slots(), MAX_AXES, "one bus slot per axis slot");
        CycleThread {
            kernel: Kernel::new(cycle_time_s, MAX_AXES),
            bus,
            shared,
            snapshot,
            scope: ScopeConfig::default(),
            published: 0,
            groups_published: 0,
            lazy_publish: false,
            publish_next: false,
            unpublished: false,
            watched_pending: false,
        }
    }

    /// Runs until `shared.shutdown` is set.
    pub fn run(mut self) {
        let shared = self.shared.clone();
        let period = shared.period_ns;
        let mut feedback = vec![DriveFeedback::default(); MAX_AXES];
        let mut setpoints = vec![DriveSetpoint::default(); MAX_AXES];
        let mut deadline = now_ns() + period;
        let mut last_wake = 0u64;
        while !shared.shutdown.load(Relaxed) {
            sleep_until(deadline);
            let woke = now_ns();
            let stats = &shared.stats;
            stats.wakeup_latency.record(woke.saturating_sub(deadline));
            if last_wake != 0 {
                stats.period.record(woke - last_wake);
            }
            last_wake = woke;

            self.one_cycle(&mut feedback, &mut setpoints);

            let end = now_ns();
            stats.compute.record(end - woke);
            stats.cycles.fetch_add(1, Relaxed);
            deadline += period;
            // Follow a bus clock (EtherCAT DC): one exchange per SYNC0 period.
            if let Some(e) = self.bus.sync_error_ns() {
                deadline = deadline.saturating_add_signed(drives::sync_correction_ns(e, period));
            }
            if end >= deadline {
                // Late: skip the deadlines already passed (keeping the grid) and count them.
                let missed = (end - deadline) / period + 1;
                deadline += missed * period;
                stats.overruns.fetch_add(missed, Relaxed);
            }
        }
    }

    /// Runs in virtual time until `shared.shutdown` is set: a cycle whenever the clock allows
    /// one (`ClockLink`), as fast as the machine can or `pace_ns` apart; requests taken as they
    /// come while it is stopped. The rings to the async side are never overrun: the thread
    /// waits for the pump instead (time does not pass meanwhile).
    pub fn run_virtual(mut self) {
        let shared = self.shared.clone();
        let link = &shared.clock;
        let _ = link.thread.set(std::thread::current());
        let mut feedback = vec![DriveFeedback::default(); MAX_AXES];
        let mut setpoints = vec![DriveSetpoint::default(); MAX_AXES];
        let mut next = now_ns();
        let idle = std::time::Duration::from_millis(50);
        self.lazy_publish = true;
        let mut last_publish = 0u64;
        use std::sync::atomic::Ordering::SeqCst;
        while !shared.shutdown.load(Relaxed) {
            // Announced before the limit is read (both SeqCst): a limit lowered by the async
            // side is either seen here or waited for there (`Clock::stand`).
            link.stepping.store(true, SeqCst);
            let may_step = self.kernel.cycle() < link.limit.load(SeqCst)
                && link.watch_stop.load(std::sync::atomic::Ordering::Acquire) == 0;
            let backlog = shared.events.len() > EVENT_RING / 2
                || shared.scope_frames.len() > SCOPE_RING / 2
                || shared.replies.len() > REPLY_QUEUE / 2;
            if !may_step || backlog {
                link.stepping.store(false, SeqCst);
                if self.unpublished {
                    // Stopped where it was not published (the limit came nearer meanwhile):
                    // whoever looks at this cycle sees it.
                    let cycle = self.kernel.cycle();
                    self.publish_snapshot(cycle);
                    shared.published_cycle.store(cycle, SeqCst);
                    shared.wake.signal();
                }
                // With the rings to the async side half full, not even the replies are made
                // until the pump has taken what waits (a reply beyond the queue would be lost).
                if !backlog {
                    self.requests_and_cycle(&mut feedback, &mut setpoints, false);
                }
                if backlog {
                    shared.wake.signal();
                    std::thread::park_timeout(std::time::Duration::from_micros(200));
                } else if shared.requests.is_empty() {
                    std::thread::park_timeout(idle);
                }
                continue;
            }
            if link.pace_ns > 0 {
                sleep_until(next);
                next = next.max(now_ns().saturating_sub(link.pace_ns)) + link.pace_ns;
            }
            let start = now_ns();
            self.publish_next = self.kernel.cycle() + 1 >= link.limit.load(SeqCst)
                || start.saturating_sub(last_publish) >= 1_000_000;
            if self.publish_next {
                last_publish = start;
            }
            self.one_cycle(&mut feedback, &mut setpoints);
            link.stepping.store(false, SeqCst);
            shared.stats.compute.record(now_ns() - start);
            shared.stats.cycles.fetch_add(1, Relaxed);
            let cycle = self.kernel.cycle();
            if link.watch_stop.load(Relaxed) != 0 || cycle >= link.limit.load(Relaxed) {
                // Stopped: the async side looks at this cycle now.
                shared.wake.signal();
            }
        }
    }

    /// One cycle without the timing: commands, kernel step on the feedback of the last
    /// exchange, bus exchange (setpoints out, feedback in for the next cycle), publish.
    pub fn one_cycle(&mut self, feedback: &mut [DriveFeedback], setpoints: &mut [DriveSetpoint]) {
        self.requests_and_cycle(feedback, setpoints, true);
    }

    /// The requests waiting (at most [`DRAIN_PER_CYCLE`] when `step`, else all of them), then
    /// with `step` the cycle: kernel step, bus exchange, publish. Without `step` (a stopped
    /// virtual clock) the requests apply at the next cycle, as they would in real time.
    fn requests_and_cycle(
        &mut self,
        feedback: &mut [DriveFeedback],
        setpoints: &mut [DriveSetpoint],
        step: bool,
    ) {
        // Its own handle (an uncontended count): the sink holds the event ring through the
        // cycle while the cycle publishes through `&mut self`.
        let handle = self.shared.clone();
        let shared = &*handle;
        let mut sink = RingSink {
            q: &shared.events,
            dropped: 0,
            pushed: 0,
            watch: shared.clock.watch.load(Relaxed),
            watched: false,
        };
        let mut drained = 0;
        let most = if step { DRAIN_PER_CYCLE } else { usize::MAX };
        // Read once per cycle, and only when something waits (a vDSO call, no syscall).
        let mut now = 0;
        while drained < most {
            let Some(Queued {
                request: req,
                expires_ns,
            }) = shared.requests.pop()
            else {
                break;
            };
            drained += 1;
            if expires_ns != 0 {
                if now == 0 {
                    now = now_ns();
                }
                if now > expires_ns {
                    // Its requester has given up (503): acting now would be a command nobody
                    // tracks. Boxes go back to be freed off the thread; no reply is awaited.
                    shared.stats.requests_expired.fetch_add(1, Relaxed);
                    match req {
                        Request::InsertAxis { axis, drive, .. } => {
                            let _ = shared.garbage.push(Garbage::Axis(axis));
                            let _ = shared.garbage.push(Garbage::Drive(drive));
                        }
                        Request::InsertCam { cam, .. } | Request::ChangeCam { cam, .. } => {
                            let _ = shared.garbage.push(Garbage::Cam(cam));
                        }
                        Request::InsertGroup { group, .. } => {
                            let _ = shared.garbage.push(Garbage::Group(group));
                        }
                        Request::MovePath {
                            table, prepared, ..
                        } => {
                            let _ = shared.garbage.push(Garbage::Path(table));
                            if let Some(p) = prepared {
                                let _ = shared.garbage.push(Garbage::Prepared(p));
                            }
                        }
                        _ => {}
                    }
                    continue;
                }
            }
            let cycle = self.kernel.cycle() + 1;
            let reply = match req {
                Request::Command(cmd) => {
                    // A hint the step left (a queued cam change's jump check) is not this
                    // command's.
                    if let motion::Target::Axis(slot) = cmd.target {
                        if let Some(a) = self.kernel.axis(slot) {
                            a.take_refusal_hint();
                        }
                    }
                    let result = match self.kernel.submit(cmd, &mut sink) {
                        Verdict::Accepted => Ok(()),
                        Verdict::Rejected(e) => Err(e),
                    };
                    // Taken also after an acceptance, so that no stale hint stays behind.
                    let hint = match cmd.target {
                        motion::Target::Axis(slot) => {
                            self.kernel.axis(slot).and_then(|a| a.take_refusal_hint())
                        }
                        motion::Target::Group(_) => None,
                    };
                    Reply {
                        hint: hint.filter(|_| result.is_err()),
                        ticket: cmd.id,
                        cycle,
                        result,
                    }
                }
                Request::InsertAxis {
                    ticket,
                    slot,
                    axis,
                    drive,
                    require_disabled,
                } => {
                    if require_disabled && !self.kernel.is_disabled(slot) {
                        self.discard(Garbage::Axis(axis));
                        self.discard(Garbage::Drive(drive));
                        Reply {
                            hint: None,
                            ticket,
                            cycle,
                            result: Err(ErrorId::AXIS_CANNOT_BE_STARTED),
                        }
                    } else {
                        match self.kernel.insert_axis(slot, axis) {
                            Ok(old) => {
                                self.published = self.published.max(slot as usize + 1);
                                if let Some(old) = old {
                                    self.discard(Garbage::Axis(old));
                                }
                                let result = match self.bus.attach(slot as usize, drive) {
                                    Ok(old) => {
                                        if let Some(old) = old {
                                            self.discard(Garbage::Drive(old));
                                        }
                                        Ok(())
                                    }
                                    Err(drive) => {
                                        self.discard(Garbage::Drive(drive));
                                        Err(ErrorId::AXIS_UNKNOWN)
                                    }
                                };
                                Reply {
                                    hint: None,
                                    ticket,
                                    cycle,
                                    result,
                                }
                            }
                            Err(axis) => {
                                self.discard(Garbage::Axis(axis));
                                self.discard(Garbage::Drive(drive));
                                Reply {
                                    hint: None,
                                    ticket,
                                    cycle,
                                    result: Err(ErrorId::AXIS_UNKNOWN),
                                }
                            }
                        }
                    }
                }
                Request::RemoveAxis {
                    ticket,
                    slot,
                    require_disabled,
                } => {
                    if require_disabled && !self.kernel.is_disabled(slot) {
                        Reply {
                            hint: None,
                            ticket,
                            cycle,
                            result: Err(ErrorId::AXIS_CANNOT_BE_STARTED),
                        }
                    } else {
                        if let Some(old) = self.kernel.remove_axis(slot) {
                            self.discard(Garbage::Axis(old));
                        }
                        if let Some(old) = self.bus.detach(slot as usize) {
                            self.discard(Garbage::Drive(old));
                        }
                        Reply {
                            hint: None,
                            ticket,
                            cycle,
                            result: Ok(()),
                        }
                    }
                }
                Request::InjectFault {
                    ticket,
                    slot,
                    fault,
                } => {
                    // A mark is given where the axis reads it (after homing, a set position, a
                    // correction …); the simulated load carries it in the drive's coordinates.
                    let fault = match (fault, self.kernel.axis(slot)) {
                        (SimFault::ProbeMark { position: Some(p) }, Some(a)) => {
                            SimFault::ProbeMark {
                                position: Some(a.drive_position_of(p)),
                            }
                        }
                        (f, _) => f,
                    };
                    // The simulated drives' own door (an emulated drive's is the emulator's,
                    // reached without the cycle thread: `BusHandle::inject_emulated`).
                    let result = match self.bus.simulated().map(|b| b.inject(slot as usize, fault))
                    {
                        Some(Ok(())) => Ok(()),
                        Some(Err(BusError::NoDrive)) => Err(ErrorId::AXIS_UNKNOWN),
                        Some(Err(BusError::Unsupported)) | None => {
                            Err(ErrorId::COMMAND_NOT_PERMITTED)
                        }
                    };
                    Reply {
                        hint: None,
                        ticket,
                        cycle,
                        result,
                    }
                }
                Request::ResetFollowingErrorPeak { ticket, slot } => Reply {
                    hint: None,
                    ticket,
                    cycle,
                    result: match self.kernel.reset_following_error_peak(slot) {
                        true => Ok(()),
                        false => Err(ErrorId::AXIS_UNKNOWN),
                    },
                },
                Request::InsertCam { ticket, id, cam } => {
                    let result = match self.kernel.insert_cam(id, cam) {
                        Ok(old) => {
                            if let Some(old) = old {
                                self.discard(Garbage::Cam(old));
                            }
                            Ok(())
                        }
                        Err(cam) => {
                            self.discard(Garbage::Cam(cam));
                            Err(ErrorId::CAM_TABLE_IN_USE)
                        }
                    };
                    Reply {
                        hint: None,
                        ticket,
                        cycle,
                        result,
                    }
                }
                Request::RemoveCam { ticket, id } => {
                    let result = self.kernel.remove_cam(id).map(|old| {
                        if let Some(old) = old {
                            self.discard(Garbage::Cam(old));
                        }
                    });
                    Reply {
                        hint: None,
                        ticket,
                        cycle,
                        result,
                    }
                }
                Request::ChangeCam {
                    ticket,
                    id,
                    cam,
                    change,
                } => {
                    let result = self.kernel.change_cam(id, cam, change).map_err(|cam| {
                        self.discard(Garbage::Cam(cam));
                        ErrorId::CAM_TABLE_IN_USE
                    });
                    Reply {
                        hint: None,
                        ticket,
                        cycle,
                        result,
                    }
                }
                Request::ProbeCamChange { ticket, id } => Reply {
                    hint: None,
                    ticket,
                    cycle,
                    result: if self.kernel.cam_change_pending(id) {
                        Err(ErrorId::CAM_TABLE_IN_USE)
                    } else {
                        Ok(())
                    },
                },
                Request::DropCamData { ticket, id } => {
                    self.kernel.drop_cam_data(id);
                    Reply {
                        hint: None,
                        ticket,
                        cycle,
                        result: Ok(()),
                    }
                }
                Request::InsertGroup { ticket, id, group } => {
                    let result = match self.kernel.insert_group(id, group) {
                        Ok(old) => {
                            self.groups_published = self.groups_published.max(id as usize + 1);
                            if let Some(old) = old {
                                self.discard(Garbage::Group(old));
                            }
                            Ok(())
                        }
                        Err(group) => {
                            self.discard(Garbage::Group(group));
                            Err(ErrorId::GROUP_STATE_INVALID)
                        }
                    };
                    Reply {
                        hint: None,
                        ticket,
                        cycle,
                        result,
                    }
                }
                Request::RemoveGroup {
                    ticket,
                    id,
                    require_disabled,
                } => {
                    let enabled = self.kernel.group(id).is_some_and(|g| {
                        g.status().enable_requested
                            || g.state() == motion::group::GroupState::ErrorStop
                    });
                    let result = if require_disabled && enabled {
                        Err(ErrorId::GROUP_STATE_INVALID)
                    } else {
                        if let Some(old) = self.kernel.remove_group(id, &mut sink) {
                            self.discard(Garbage::Group(old));
                        }
                        Ok(())
                    };
                    Reply {
                        hint: None,
                        ticket,
                        cycle,
                        result,
                    }
                }
                Request::MovePath {
                    command,
                    group,
                    table,
                    prepared,
                } => {
                    let verdict = self.kernel.submit_prepared_path(
                        command,
                        group,
                        &table,
                        prepared.as_deref(),
                        &mut sink,
                    );
                    let result = match verdict {
                        Verdict::Accepted => Ok(()),
                        Verdict::Rejected(e) => Err(e),
                    };
                    self.discard(Garbage::Path(table));
                    if let Some(p) = prepared {
                        self.discard(Garbage::Prepared(p));
                    }
                    Reply {
                        hint: None,
                        ticket: command,
                        cycle,
                        result,
                    }
                }
                Request::ScopeConfig { ticket, config } => {
                    self.scope = config;
                    Reply {
                        hint: None,
                        ticket,
                        cycle,
                        result: Ok(()),
                    }
                }
            };
            // The async side waits on every ticket; the reply queue is larger than the request
            // queue, so this only fails if the async side has stopped draining.
            let _ = shared.replies.push(reply);
        }
        shared
            .stats
            .commands_drained
            .fetch_add(drained as u64, Relaxed);
        if !step {
            // A request that ends the watched command (a move aborting it) while the clock
            // stands: its events are the next cycle's, so the clock stops after that one.
            self.watched_pending |= sink.watched;
            if sink.dropped > 0 {
                shared.stats.events_dropped.fetch_add(sink.dropped, Relaxed);
            }
            if drained > 0 || sink.pushed > 0 {
                shared.wake.signal();
            }
            return;
        }

        self.kernel.step(feedback, setpoints, &mut sink);
        while let Some(cam) = self.kernel.take_retired_cam() {
            self.discard(Garbage::Cam(cam));
        }
        // Setpoints out, the drives' answers in: read by the next cycle's step.
        self.bus.exchange(setpoints, feedback);
        if sink.dropped > 0 {
            shared.stats.events_dropped.fetch_add(sink.dropped, Relaxed);
        }

        let cycle = self.kernel.cycle();
        // Virtual time publishes only where someone looks (see `run_virtual`); a scope samples
        // from the snapshot, so it has one every cycle.
        let watched = sink.watched || std::mem::take(&mut self.watched_pending);
        let publish = !self.lazy_publish || self.publish_next || watched || self.scope.is_active();
        if publish {
            self.publish_snapshot(cycle);
        } else {
            self.unpublished = true;
        }
        if watched {
            // Before the cycle is stored: whoever reads this cycle sees that it stopped there.
            shared
                .clock
                .watch_stop
                .store(cycle, std::sync::atomic::Ordering::Release);
        }
        // Release: whoever reads this cycle finds its events in the ring (the pump, the clock).
        shared
            .cycle
            .store(cycle, std::sync::atomic::Ordering::Release);
        if publish {
            shared
                .published_cycle
                .store(cycle, std::sync::atomic::Ordering::Release);
        }
        // A verdict or an output change waits on the async side: wake the pump now rather
        // than at its next millisecond (one wake-up; nothing when the cycle produced nothing).
        if drained > 0 || sink.pushed > 0 {
            shared.wake.signal();
        }
    }

    /// Writes every slot's status into the snapshot, samples the scope from it, publishes it.
    fn publish_snapshot(&mut self, cycle: u64) {
        let snap = self.snapshot.input_buffer_mut();
        snap.cycle = cycle;
        // Only the slots in use, each status copied once into its place (not the whole array
        // of 64 through a temporary every cycle: that copy was a quarter of an idle cycle),
        // and only when it changed since this buffer last held it: an axis at rest changes
        // its cycle counter only.
        let slots = snap.axes[..self.published].iter_mut();
        for ((i, s), at) in slots.enumerate().zip(snap.copied_at.iter_mut()) {
            match (self.kernel.axis(i as AxisSlot), s.as_mut()) {
                (Some(a), Some(dst)) if *at == a.status_seq() => {
                    dst.nc_cycle_counter = a.nc_cycle_counter();
                }
                (Some(a), _) => {
                    *s = Some(a.status());
                    *at = a.status_seq();
                }
                (None, _) => {
                    *s = None;
                    *at = u64::MAX;
                }
            }
        }
        for (i, s) in snap.groups[..self.groups_published].iter_mut().enumerate() {
            match (self.kernel.group(i as GroupId), s.as_mut()) {
                (Some(g), Some(dst)) => *dst = *g.status(),
                (Some(g), None) => *s = Some(*g.status()),
                (None, _) => *s = None,
            }
        }
        if self.scope.is_active() {
            let frame = ScopeFrame::sample(cycle, &self.scope, &snap.axes, &snap.groups);
            if self.shared.scope_frames.push(frame).is_err() {
                self.shared.stats.scope_frames_dropped.fetch_add(1, Relaxed);
            }
        }
        self.snapshot.publish();
        self.unpublished = false;
    }

    fn discard(&self, g: Garbage) {
        if let Err(g) = self.shared.garbage.push(g) {
            // Never free on the cycle thread: leak instead (cannot happen with the sizes above).
            std::mem::forget(g);
        }
    }
}
