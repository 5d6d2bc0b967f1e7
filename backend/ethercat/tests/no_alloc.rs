//! `EthercatBus::exchange` runs on the real-time cycle thread and must not allocate: a counting
//! global allocator watches that thread through cycles of enabling, moving and faults (the
//! emulator's own thread allocates; it is not counted). One test in this file, so no other
//! test thread can be counted by mistake.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::time::Duration;

use drives::cia402::Cia402Config;
use drives::{DriveBus, DriveConfig};
use ethercat::bus::{BusOptions, EthercatBus, Link};
use motion::{DriveFeedback, DriveSetpoint};

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn note() {
    let _ = COUNTING.try_with(|c| {
        if c.get() {
            let _ = ALLOCATIONS.try_with(|a| a.set(a.get() + 1));
        }
    });
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn the_exchange_does_not_allocate() {
    let seg = common::servos(1, true);
    let cycle = Duration::from_millis(1);
    let mut bus = EthercatBus::start(Link::Emulated(seg.clone()), &BusOptions::new(cycle), 2)
        .expect("bring-up");
    let cfg = DriveConfig::Cia402(Cia402Config::csp(0, 1000.0));
    assert!(bus.attach(0, cfg.build(0.001)).unwrap().is_none());
    let mut sp = vec![
        DriveSetpoint {
            enable: true,
            ..DriveSetpoint::default()
        },
        DriveSetpoint::default(),
    ];
    let mut fb = vec![DriveFeedback::default(); 2];
    // The counter itself works.
    COUNTING.with(|c| c.set(true));
    drop(std::hint::black_box(vec![1u8; 16]));
    COUNTING.with(|c| c.set(false));
    assert!(ALLOCATIONS.with(Cell::get) > 0);
    ALLOCATIONS.with(|a| a.set(0));
    // Warm up (first polls of lazily made statics), then count.
    for _ in 0..50 {
        bus.exchange(&sp, &mut fb);
        std::thread::sleep(cycle);
    }
    COUNTING.with(|c| c.set(true));
    for k in 0..2000 {
        sp[0].position = k as f64 * 0.0005;
        sp[0].fault_reset = k % 500 == 0;
        bus.exchange(&sp, &mut fb);
        let _ = bus.sync_error_ns();
        COUNTING.with(|c| c.set(false));
        std::thread::sleep(cycle);
        COUNTING.with(|c| c.set(true));
    }
    COUNTING.with(|c| c.set(false));
    assert!(fb[0].enabled, "{:?}", fb[0]);
    assert_eq!(
        ALLOCATIONS.with(Cell::get),
        0,
        "allocations on the cycle thread"
    );
}
