//! The clock motiond runs on (`--clock`, issue 26). In real time (the default) the cycle thread
//! keeps its deadlines on `CLOCK_MONOTONIC` and everything else reads the wall clock. In
//! virtual time the cycle thread steps only when this clock lets it (`cycle::ClockLink`):
//! `virtual` when a client advances it (`POST /api/v1/clock/advance`), `fast` continuously (as
//! fast as the machine can, or at a factor of real time). Time is then cycles × cycle time, and
//! everything on the async side that is time reads it here: command and audit timestamps
//! (virtual time 0 is the Unix epoch), `?wait=true`'s timeout, the control lease, the
//! websocket's subscription rates. The kernel's own timers (dead-man, in-target, homing, the
//! external stream's stall) count cycles and need nothing.
//!
//! **Holds.** Something on the async side that must act at an exact virtual time takes a
//! [`Hold`] at that cycle: the cycle thread does not step past a held cycle until the hold is
//! dropped, so the holder sees the machine exactly as it was then (a websocket tick, a wait's
//! timeout). A hold is registered when it is made, not when it is first awaited.

use std::collections::BTreeMap;
use std::sync::atomic::Ordering::{Acquire, Release};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::cycle::Shared;

/// `--clock`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mode {
    /// Wall-clock time: the cycle thread keeps its period.
    Real,
    /// Cycles advance when a client asks.
    Virtual,
    /// Cycles run continuously: as fast as the machine can (`None`), or at this factor of real
    /// time.
    Fast(Option<f64>),
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Real => "real",
            Mode::Virtual => "virtual",
            Mode::Fast(_) => "fast",
        }
    }

    pub fn is_virtual(self) -> bool {
        self != Mode::Real
    }
}

/// `--clock real|virtual|fast|fast=FACTOR` (FACTOR 0.01–10000).
pub fn parse_mode(s: &str) -> Result<Mode, String> {
    match s {
        "real" => Ok(Mode::Real),
        "virtual" => Ok(Mode::Virtual),
        "fast" => Ok(Mode::Fast(None)),
        _ => match s.strip_prefix("fast=").map(str::parse::<f64>) {
            Some(Ok(f)) if (0.01..=10_000.0).contains(&f) => Ok(Mode::Fast(Some(f))),
            _ => Err(format!(
                "{s:?} is not real, virtual, fast or fast=FACTOR (a factor of real time from 0.01 to 10000)"
            )),
        },
    }
}

struct Held {
    /// The cycle the clock may run to (the advance's end; `u64::MAX` in fast mode).
    target: u64,
    /// Held cycles and how many holds each has.
    holds: BTreeMap<u64, usize>,
    /// An advance is running (one at a time).
    advancing: bool,
}

pub struct Clock {
    pub mode: Mode,
    pub period_ns: u64,
    shared: Arc<Shared>,
    /// Real time: when the clock started (the feed's ticks count from here).
    start: tokio::time::Instant,
    held: Mutex<Held>,
    /// The newest cycle whose events the pump has applied (virtual time).
    reached: tokio::sync::watch::Sender<u64>,
}

impl Clock {
    pub fn new(mode: Mode, shared: Arc<Shared>) -> Arc<Clock> {
        let period_ns = shared.period_ns;
        if mode.is_virtual() {
            let cycles = shared.clone();
            crate::store::use_virtual_time(Box::new(move || cycles.cycle.load(Acquire)), period_ns);
        }
        let clock = Arc::new(Clock {
            mode,
            period_ns,
            start: tokio::time::Instant::now(),
            held: Mutex::new(Held {
                target: if matches!(mode, Mode::Fast(_)) {
                    u64::MAX
                } else {
                    0
                },
                holds: BTreeMap::new(),
                advancing: false,
            }),
            reached: tokio::sync::watch::channel(0).0,
            shared,
        });
        clock.update_limit(&clock.held.lock().unwrap());
        clock
    }

    /// The cycle count (the cycle thread's last completed cycle).
    pub fn cycle(&self) -> u64 {
        self.shared.cycle.load(Acquire)
    }

    /// Time since the clock started: wall time, or cycles × cycle time.
    pub fn now(&self) -> Duration {
        if self.mode.is_virtual() {
            Duration::from_nanos(self.cycle() * self.period_ns)
        } else {
            self.start.elapsed()
        }
    }

    /// The first cycle at or after clock time `t`.
    pub fn cycle_at(&self, t: Duration) -> u64 {
        (t.as_nanos() as u64).div_ceil(self.period_ns)
    }

    /// The pump has applied every event up to `cycle` (virtual time: holds and advances at or
    /// before it may look now).
    pub fn reached(&self, cycle: u64) {
        if self.mode.is_virtual() {
            self.reached.send_if_modified(|c| {
                let newer = cycle > *c;
                *c = (*c).max(cycle);
                newer
            });
        }
    }

    /// Holds the clock at clock time `t` (see the module docs); in real time a plain deadline.
    pub fn hold_until(self: &Arc<Self>, t: Duration) -> Hold {
        if !self.mode.is_virtual() {
            return Hold {
                clock: self.clone(),
                at: Until::Real(self.start + t),
            };
        }
        self.hold_cycle(self.cycle_at(t))
    }

    /// Clock time `t` without holding the clock there (its [`Hold::wait`] wakes once the clock
    /// has passed it).
    pub fn wake_at(self: &Arc<Self>, t: Duration) -> Hold {
        let at = if self.mode.is_virtual() {
            Until::Passing(self.cycle_at(t))
        } else {
            Until::Real(self.start + t)
        };
        Hold {
            clock: self.clone(),
            at,
        }
    }

    /// Holds the clock `d` from now.
    pub fn hold_after(self: &Arc<Self>, d: Duration) -> Hold {
        self.hold_until(self.now() + d)
    }

    /// Holds the clock at `cycle` (virtual time).
    pub fn hold_cycle(self: &Arc<Self>, cycle: u64) -> Hold {
        let mut h = self.held.lock().unwrap();
        *h.holds.entry(cycle).or_default() += 1;
        self.update_limit(&h);
        Hold {
            clock: self.clone(),
            at: Until::Cycle(cycle),
        }
    }

    fn release(&self, cycle: u64) {
        let mut h = self.held.lock().unwrap();
        if let Some(n) = h.holds.get_mut(&cycle) {
            *n -= 1;
            if *n == 0 {
                h.holds.remove(&cycle);
            }
        }
        self.update_limit(&h);
    }

    /// The cycle thread may step up to the advance's end or the first hold after now.
    fn update_limit(&self, h: &Held) {
        if !self.mode.is_virtual() {
            return;
        }
        let now = self.cycle();
        // A hold at the cycle the clock is at keeps it there; one already passed is nothing.
        let first_hold = h.holds.range(now..).next().map(|(c, _)| *c);
        let limit = first_hold.map_or(h.target, |c| c.min(h.target));
        self.shared
            .clock
            .limit
            .store(limit, std::sync::atomic::Ordering::SeqCst);
        self.shared.clock.nudge();
    }

    /// Stops the clock now: once this returns the cycle thread steps no further (a cycle it
    /// had begun has ended).
    fn stand(&self, h: &mut Held) {
        h.target = 0;
        self.update_limit(h);
        while self
            .shared
            .clock
            .stepping
            .load(std::sync::atomic::Ordering::SeqCst)
        {
            // A cycle takes microseconds.
            std::hint::spin_loop();
        }
    }

    /// Waits until the pump has applied the events of `cycle`.
    async fn until_reached(&self, cycle: u64) {
        let mut rx = self.reached.subscribe();
        let _ = rx.wait_for(|c| *c >= cycle).await;
    }

    /// Starts an advance to `target` (virtual mode only); `None` while another one runs.
    pub fn begin_advance(self: &Arc<Self>, cycles: u64, watch: u64) -> Option<Advance> {
        let mut h = self.held.lock().unwrap();
        if h.advancing || self.mode != Mode::Virtual {
            return None;
        }
        h.advancing = true;
        let from = self.cycle();
        h.target = from.saturating_add(cycles);
        self.shared.clock.watch.store(watch, Release);
        self.shared.clock.watch_stop.store(0, Release);
        self.update_limit(&h);
        Some(Advance {
            clock: self.clone(),
            from,
            target: h.target,
        })
    }

    pub fn advancing(&self) -> bool {
        self.held.lock().unwrap().advancing
    }
}

enum Until {
    Real(tokio::time::Instant),
    /// Held at this cycle.
    Cycle(u64),
    /// Not held: a wake-up once the clock has reached it.
    Passing(u64),
}

/// A point in clock time that the clock does not pass while this is held (virtual time).
pub struct Hold {
    clock: Arc<Clock>,
    at: Until,
}

impl Hold {
    /// Returns once the clock is there (in virtual time: stopped there, its events applied).
    pub async fn wait(&self) {
        match self.at {
            Until::Real(t) => tokio::time::sleep_until(t).await,
            Until::Cycle(c) | Until::Passing(c) => self.clock.until_reached(c).await,
        }
    }
}

impl Drop for Hold {
    fn drop(&mut self) {
        if let Until::Cycle(c) = self.at {
            self.clock.release(c);
        }
    }
}

/// A running advance; dropping it (the client went away) stops the clock where it is.
pub struct Advance {
    clock: Arc<Clock>,
    pub from: u64,
    pub target: u64,
}

/// Where an advance stopped.
pub enum Stopped {
    /// At its end.
    Target,
    /// After a cycle with events of the watched command.
    Watched(u64),
}

impl Advance {
    /// Runs the clock until the advance's end or an event of the watched command (the cycle
    /// thread stops after that cycle; [`Advance::resume`] goes on).
    pub async fn run(&self) -> Stopped {
        let link = &self.clock.shared.clock;
        let mut rx = self.clock.reached.subscribe();
        loop {
            // `reached` first: the cycle thread stores `watch_stop` before the cycle it stopped
            // after is published (and so before the pump can report it), so a stop is never
            // missed between the two reads.
            let reached = *rx.borrow_and_update();
            let stop = link.watch_stop.load(Acquire);
            if stop != 0 && reached >= stop {
                return Stopped::Watched(stop);
            }
            if reached >= self.target {
                return Stopped::Target;
            }
            if rx.changed().await.is_err() {
                return Stopped::Target;
            }
        }
    }

    /// Goes on after a watched command's events.
    pub fn resume(&self) {
        let link = &self.clock.shared.clock;
        link.watch_stop.store(0, Release);
        link.nudge();
    }
}

impl Drop for Advance {
    fn drop(&mut self) {
        let mut h = self.clock.held.lock().unwrap();
        h.advancing = false;
        // Ended early (a milestone, a client gone): the clock stays where it is.
        self.clock.stand(&mut h);
        let link = &self.clock.shared.clock;
        link.watch.store(0, Release);
        link.watch_stop.store(0, Release);
    }
}
