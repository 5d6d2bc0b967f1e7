//! `feedback` and `apply` never allocate: a counting global allocator watches one thread
//! through every path of the drive (enable, motion, latch, faults, coasting, limit switches).
//! One test in this file, so no other test thread can be counted by mistake.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use drives::sim::{IndexPulse, LimitSwitches, PlantModel, SimDrive, SimDriveConfig, SimFault};
use motion::{DriveSetpoint, LatchSource};

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn note() {
    // `try_with`: the thread-locals may already be gone while a thread shuts down.
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

fn allocations_during(f: impl FnOnce()) -> u64 {
    ALLOCATIONS.with(|a| a.set(0));
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    ALLOCATIONS.with(|a| a.get())
}

#[test]
fn feedback_and_apply_do_not_allocate() {
    // The counter itself works.
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 16]))) > 0);

    let plants = [
        PlantModel::Ideal,
        PlantModel::Pt1 {
            time_constant: 0.004,
        },
        PlantModel::default(),
    ];
    for plant in plants {
        let config = SimDriveConfig {
            plant,
            dead_time: 0.0025,
            index_pulse: Some(IndexPulse {
                period: 3.0,
                offset: 0.5,
            }),
            limit_switches: LimitSwitches {
                negative: Some(-50.0),
                positive: Some(60.0),
                fault_on_hit: true,
            },
            ..SimDriveConfig::default()
        };
        let mut drive = SimDrive::new(config, 0.001);
        let n = allocations_during(|| {
            let mut sp = DriveSetpoint {
                enable: true,
                ..Default::default()
            };
            for k in 0..6000u32 {
                let fb = drive.feedback();
                let t = k as f64 * 0.001;
                sp.velocity = 40.0 * (t * 1.3).sin();
                sp.position = 40.0 / 1.3 * (1.0 - (t * 1.3).cos());
                sp.acceleration = 52.0 * (t * 1.3).cos();
                sp.latch_source = match (k / 500) % 3 {
                    0 => LatchSource::IndexPulse,
                    1 => LatchSource::CamRising,
                    _ => LatchSource::CamFalling,
                };
                sp.latch_enable = !(fb.latch_valid && k % 7 == 0);
                sp.fault_reset = fb.fault && k % 2 == 0;
                match k {
                    1000 => drive.inject(SimFault::Load { force: 300.0 }),
                    2000 => drive.inject(SimFault::DriveFault { code: 42 }),
                    2100 => drive.inject(SimFault::Clear),
                    3000 => drive.inject(SimFault::LimitSwitch {
                        positive: true,
                        active: true,
                    }),
                    3100 => drive.inject(SimFault::LimitSwitch {
                        positive: true,
                        active: false,
                    }),
                    _ => {}
                }
                sp.enable = !(4000..4100).contains(&k);
                drive.apply(&sp);
                if k == 5000 {
                    drive.set_actual_position(fb.actual_position);
                }
            }
        });
        assert_eq!(n, 0, "{plant:?}: allocations in the cycle");
    }
}
