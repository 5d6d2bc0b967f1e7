//! The cycle thread's work (drain requests, step, publish, scope samples) allocates nothing and
//! frees nothing, including while commands, axis hand-overs and scope configurations arrive.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Arc;

use drives::{DriveConfig, SimBus, SimFault};
use motion::{
    Axis, AxisConfig, AxisParameters, Command, CommandKind, DriveFeedback, DriveSetpoint,
    Positioning, Target,
};
use server::cycle::{CycleThread, MAX_AXES, Request, Shared, Snapshot};
use server::scope::{ScopeConfig, ScopeSignal};

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if COUNTING.with(|c| c.get()) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        if COUNTING.with(|c| c.get()) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        if COUNTING.with(|c| c.get()) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

fn counted<R>(f: impl FnOnce() -> R) -> (R, usize) {
    COUNT.with(|c| c.set(0));
    COUNTING.with(|c| c.set(true));
    let r = f();
    COUNTING.with(|c| c.set(false));
    (r, COUNT.with(|c| c.get()))
}

#[test]
fn a_cycle_allocates_nothing() {
    let ct = 0.001;
    let shared = Arc::new(Shared::new(1_000_000));
    let (input, mut output) = triple_buffer::triple_buffer(&Snapshot::default());
    let mut cycle = CycleThread::new(ct, Box::new(SimBus::new(MAX_AXES)), shared.clone(), input);
    let mut fb = vec![DriveFeedback::default(); MAX_AXES];
    let mut sp = vec![DriveSetpoint::default(); MAX_AXES];
    let axis = || {
        Axis::new(
            AxisConfig {
                modulo: false,
                parameters: AxisParameters::default(),
                compensation_table: None,
                drive_executed: false,
            },
            ct,
        )
    };
    let drive = || DriveConfig::default().build(ct);
    for slot in 0..3u16 {
        assert!(
            shared
                .push(Request::InsertAxis {
                    ticket: slot as u64,
                    slot,
                    axis: axis(),
                    drive: drive(),
                    require_disabled: false
                })
                .is_ok()
        );
    }
    let mut total = 0;
    let mut id = 100;
    let mut frames = Vec::with_capacity(4096);
    let scope = |generation: u64, signals: &[(u16, ScopeSignal)]| {
        let mut config = ScopeConfig {
            generation,
            ..Default::default()
        };
        for (c, s) in config.channels.iter_mut().zip(signals) {
            *c = Some(*s);
        }
        Request::ScopeConfig {
            ticket: 1000 + generation,
            config,
        }
    };
    for i in 0..3000u64 {
        // Commands arrive now and then: power, moves back and forth, a replacement axis.
        match i {
            5 => {
                for slot in 0..3u16 {
                    id += 1;
                    let kind = CommandKind::Power {
                        enable: true,
                        enable_positive: true,
                        enable_negative: true,
                        override_percent: 100.0,
                        buffer_mode: motion::BufferMode::Aborting,
                    };
                    assert!(
                        shared
                            .push(Request::Command(Command {
                                id,
                                target: Target::Axis(slot),
                                kind
                            }))
                            .is_ok()
                    );
                }
            }
            i if i > 100 && i % 250 == 0 => {
                id += 1;
                let p = Positioning {
                    position: (i % 500) as f64,
                    velocity: 300.0,
                    dynamics: Default::default(),
                    buffer_mode: Default::default(),
                    options: Default::default(),
                };
                assert!(
                    shared
                        // (expiring, as the server sends them: the expiry check is in the cycle too)
                        .push_expiring(
                            Request::Command(Command {
                                id,
                                target: Target::Axis(0),
                                kind: CommandKind::MoveAbsolute(p)
                            }),
                            std::time::Duration::from_secs(60)
                        )
                        .is_ok()
                );
            }
            1500 => {
                assert!(
                    shared
                        .push(Request::InsertAxis {
                            ticket: 9,
                            slot: 2,
                            axis: axis(),
                            drive: drive(),
                            require_disabled: false
                        })
                        .is_ok()
                );
            }
            2000 | 2100 | 2200 => {
                let fault = match i {
                    2000 => SimFault::Load { force: 1.0 },
                    2100 => SimFault::DriveFault { code: 0 },
                    _ => SimFault::Clear,
                };
                assert!(
                    shared
                        .push(Request::InjectFault {
                            ticket: i,
                            slot: 1,
                            fault
                        })
                        .is_ok()
                );
            }
            // The scope samples from cycle 300 on, changes its channels at 1200, stops at 2600.
            300 => assert!(
                shared
                    .push(scope(
                        1,
                        &[(0, ScopeSignal::SetPosition), (0, ScopeSignal::SetVelocity)]
                    ))
                    .is_ok()
            ),
            1200 => assert!(
                shared
                    .push(scope(
                        2,
                        &[
                            (0, ScopeSignal::SetPosition),
                            (1, ScopeSignal::FollowingError),
                            (7, ScopeSignal::ActualPosition)
                        ]
                    ))
                    .is_ok()
            ),
            2600 => assert!(shared.push(scope(3, &[])).is_ok()),
            _ => {}
        }
        let ((), n) = counted(|| cycle.one_cycle(&mut fb, &mut sp));
        while let Some(f) = shared.scope_frames.pop() {
            // The frame is the status the snapshot of that cycle publishes.
            let snap = output.read();
            assert_eq!(f.cycle, snap.cycle);
            assert_eq!(f.values[0], snap.axes[0].unwrap().set_position);
            frames.push(f);
        }
        total += n;
        // The async side drains (and frees) outside the counted region.
        while let Some(r) = shared.replies.pop() {
            assert!(r.result.is_ok(), "request {} refused: {r:?}", r.ticket);
        }
        while shared.events.pop().is_some() {}
        while shared.garbage.pop().is_some() {}
    }
    assert_eq!(total, 0, "the cycle allocated or freed {total} times");
    // One frame per cycle while the scope sampled (cycles 301 … 2600), none after.
    assert_eq!(frames.len(), 2300);
    assert!(frames.windows(2).all(|w| w[1].cycle == w[0].cycle + 1));
    assert_eq!((frames[0].cycle, frames[0].generation), (301, 1));
    let switch = frames.iter().position(|f| f.generation == 2).unwrap();
    assert_eq!(frames[switch].cycle, 1201);
    let f = frames[switch];
    assert!(f.values[1].is_finite() && f.values[2].is_nan() && f.values[3].is_nan());
    assert!(
        frames[..switch]
            .iter()
            .all(|f| f.values[1].is_finite() && f.values[2].is_nan())
    );
    assert!(frames.iter().any(|f| f.values[0] != 0.0));
    assert_eq!(
        shared
            .stats
            .scope_frames_dropped
            .load(std::sync::atomic::Ordering::Relaxed),
        0
    );
    let snap = output.read();
    assert_eq!(snap.cycle, 3000);
    // The injected drive fault reached axis 1 (and stays, no reset was sent).
    let a1 = snap.axes[1].unwrap();
    assert_eq!(a1.error_id, motion::ErrorId::DRIVE_FAULT.0, "{a1:?}");
    assert!(
        snap.axes[0].unwrap().set_position != 0.0,
        "axis 0 never moved: {:?}",
        snap.axes[0]
    );
}
