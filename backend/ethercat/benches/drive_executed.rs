//! The cycle of 64 axes whose drives run the profile against 64 host-side (CSP) axes, doing
//! the same moves: motiond's part of a cycle — the kernel's step and the CiA-402 layer's
//! outputs and feedback for every axis — timed alone; the emulated drives (one per axis,
//! wired directly, no segment) are stepped between the timed parts, untimed.
//!
//!     cargo bench -p ethercat --bench drive_executed
//!
//! Cases: `host_csp` (positioning back and forth, motiond's planner), `drive_pp` (the same
//! moves as profile-position set points), `drive_pv` (MoveVelocity in profile velocity,
//! holding), `*_standing` (enabled, no job). One step of 64 axes; ÷ 64 per axis.
//!
//! Group `cycle_64_axes_segment`: the same cases on an emulated EtherCAT segment of 64
//! drives (DC, SYNC0, the full mapping: four LRWs and a frame of state checks per cycle), through `EthercatBus` as
//! the cycle thread runs it, paced at 1 ms. Timed: the kernel's step and the bus exchange,
//! which includes the frames' round trips through the TX/RX thread and the emulated
//! segment's answer (the emulator's work is in it, the same for every case).

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use drives::DriveBus;
use drives::DriveConfig;
use drives::cia402::{Cia402Config, Cia402Drive, ProfileSide, RxPdo, TxPdo};
use ethercat::bus::{BusOptions, EthercatBus, Link};
use ethercat::emu::drive::{Cia402Emu, Plant};
use ethercat::emu::sii::Identity;
use motion::*;

#[path = "../tests/common/mod.rs"]
mod common;

const DT: f64 = 0.001;
const AXES: usize = 64;

#[derive(Clone, Copy, PartialEq)]
enum Load {
    Positioning,
    Velocity,
    Standing,
}

/// How the drives are reached: emulated drives wired directly (motiond's part timed alone),
/// or an emulated segment through the EtherCAT bus (the whole exchange timed).
enum Wiring {
    Direct {
        cia: Vec<Cia402Drive>,
        emu: Vec<Cia402Emu>,
    },
    Segment(Box<EthercatBus>),
}

struct Machine {
    k: Kernel,
    wiring: Wiring,
    tx: Vec<TxPdo>,
    rx: Vec<RxPdo>,
    fb: Vec<DriveFeedback>,
    sp: Vec<DriveSetpoint>,
    events: Vec<CommandEvent>,
    next_id: CommandId,
    load: Load,
    next_tick: Instant,
    /// Motion commands given after the first (an axis stood again: its move was Done), the
    /// cycles and the kernel's share of the timed part: printed after each case.
    moves: u64,
    cycles: u64,
    kernel: Duration,
    /// Each timed cycle's duration (ns), for the median and the 99th percentile.
    samples: Vec<u32>,
}

fn dynamics() -> Dynamics {
    Dynamics {
        acceleration: 2000.0,
        deceleration: 2000.0,
        jerk: 0.0,
    }
}

impl Machine {
    fn new(drive_executed: bool, load: Load, segment: bool) -> Machine {
        let id = Identity {
            vendor_id: 1,
            product_code: 2,
            revision: 3,
            serial: 4,
            name: "bench".into(),
        };
        let profile = if drive_executed {
            ProfileSide::Drive
        } else {
            ProfileSide::Host
        };
        let mut k = Kernel::new(DT, AXES);
        for i in 0..AXES {
            let config = AxisConfig {
                parameters: AxisParameters {
                    axis_max_pos_lag_value: 1e6,
                    ..AxisParameters::default()
                },
                drive_executed,
                ..AxisConfig::default()
            };
            k.insert_axis(i as u16, Axis::new(config, DT)).unwrap();
        }
        let config = |i: usize| Cia402Config {
            profile,
            ..Cia402Config::csp(i as u16, 1000.0)
        };
        let wiring = if segment {
            let mut bus = EthercatBus::start(
                Link::Emulated(common::servos(AXES as u32, true)),
                &BusOptions::new(Duration::from_secs_f64(DT)),
                AXES,
            )
            .expect("bring-up of 64 emulated drives");
            for i in 0..AXES {
                let drive = DriveConfig::Cia402(config(i)).build(DT);
                assert!(bus.attach(i, drive).is_ok_and(|old| old.is_none()));
            }
            Wiring::Segment(Box::new(bus))
        } else {
            Wiring::Direct {
                cia: (0..AXES).map(|i| Cia402Drive::new(config(i))).collect(),
                emu: (0..AXES)
                    .map(|_| Cia402Emu::new(&id, Plant::default()))
                    .collect(),
            }
        };
        let mut m = Machine {
            k,
            wiring,
            tx: vec![TxPdo::default(); AXES],
            rx: vec![RxPdo::default(); AXES],
            fb: vec![DriveFeedback::default(); AXES],
            sp: vec![DriveSetpoint::default(); AXES],
            events: Vec::with_capacity(4096),
            next_id: 1,
            load,
            next_tick: Instant::now(),
            moves: 0,
            cycles: 0,
            kernel: Duration::ZERO,
            samples: Vec::with_capacity(1 << 16),
        };
        for i in 0..AXES {
            m.submit(
                i,
                CommandKind::Power {
                    enable: true,
                    enable_positive: true,
                    enable_negative: true,
                    override_percent: 100.0,
                    buffer_mode: BufferMode::Aborting,
                },
            );
        }
        let mut untimed = Duration::ZERO;
        for _ in 0..2000 {
            m.cycle(&mut untimed);
            if (0..AXES).all(|i| m.k.status(i as u16).unwrap().state == AxisState::Standstill) {
                break;
            }
        }
        assert!(
            (0..AXES).all(|i| m.k.status(i as u16).unwrap().state == AxisState::Standstill),
            "every axis enabled"
        );
        m
    }

    fn submit(&mut self, axis: usize, kind: CommandKind) {
        let id = self.next_id;
        self.next_id += 1;
        let v = self.k.submit(
            Command {
                id,
                target: Target::Axis(axis as u16),
                kind,
            },
            &mut self.events,
        );
        assert_eq!(v, Verdict::Accepted);
    }

    /// A new command for every axis that stands (moves back and forth; a velocity once).
    fn command(&mut self) {
        for i in 0..AXES {
            let st = self.k.status(i as u16).unwrap();
            if st.state != AxisState::Standstill {
                continue;
            }
            let kind = match self.load {
                Load::Standing => continue,
                Load::Positioning => CommandKind::MoveAbsolute(Positioning {
                    position: if st.actual_position < 50.0 {
                        100.0
                    } else {
                        0.0
                    },
                    velocity: 200.0,
                    dynamics: dynamics(),
                    buffer_mode: BufferMode::Aborting,
                    options: MoveOptions::default(),
                }),
                Load::Velocity => CommandKind::MoveVelocity {
                    velocity: 50.0,
                    dynamics: dynamics(),
                    direction: Direction::Positive,
                    buffer_mode: BufferMode::Aborting,
                    options: MoveOptions::default(),
                },
            };
            self.submit(i, kind);
            self.moves += 1;
        }
    }

    /// One cycle; the timed part (see the module's doc) added to `timed`. On the segment,
    /// each cycle first waits for its 1 ms tick, untimed.
    fn cycle(&mut self, timed: &mut Duration) {
        match &mut self.wiring {
            Wiring::Direct { cia, emu } => {
                let t0 = Instant::now();
                for ((fb, d), tx) in self.fb.iter_mut().zip(cia.iter_mut()).zip(&self.tx) {
                    *fb = d.feedback(tx);
                }
                let t1 = Instant::now();
                self.k.step(&self.fb, &mut self.sp, &mut self.events);
                self.kernel += t1.elapsed();
                for ((rx, d), sp) in self.rx.iter_mut().zip(cia.iter_mut()).zip(&self.sp) {
                    *rx = d.outputs(sp);
                }
                *timed += t0.elapsed();
                self.cycles += 1;
                black_box(&self.rx);
                for ((tx, e), rx) in self.tx.iter_mut().zip(emu.iter_mut()).zip(&self.rx) {
                    *tx = e.exchange_direct(rx, DT);
                }
            }
            Wiring::Segment(bus) => {
                let tick = Duration::from_secs_f64(DT);
                let now = Instant::now();
                let next = self.next_tick.max(now);
                std::thread::sleep(next - now);
                self.next_tick = next + tick;
                let t0 = Instant::now();
                self.k.step(&self.fb, &mut self.sp, &mut self.events);
                let t1 = Instant::now();
                bus.exchange(&self.sp, &mut self.fb);
                let took = t0.elapsed();
                *timed += took;
                self.kernel += t1 - t0;
                self.cycles += 1;
                self.samples.push(took.as_nanos() as u32);
            }
        }
        self.events.clear();
    }
}

/// Pins the calling thread to the last CPU, where motiond's cycle thread runs (the EtherCAT
/// TX/RX thread pins itself to the one before).
fn pin_like_the_cycle_thread() {
    // SAFETY: plain libc calls on the current thread with valid arguments.
    unsafe {
        let ncpu = libc::sysconf(libc::_SC_NPROCESSORS_ONLN).max(1) as usize;
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(ncpu - 1, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
    }
}

fn bench(c: &mut Criterion) {
    pin_like_the_cycle_thread();
    cases(c, "cycle_64_axes", false);
    cases(c, "cycle_64_axes_segment", true);
}

fn cases(c: &mut Criterion, group: &str, segment: bool) {
    let mut g = c.benchmark_group(group);
    for (name, drive_executed, load) in [
        ("host_csp", false, Load::Positioning),
        ("drive_pp", true, Load::Positioning),
        ("drive_pv", true, Load::Velocity),
        ("host_standing", false, Load::Standing),
        ("drive_standing", true, Load::Standing),
    ] {
        let mut m = Machine::new(drive_executed, load, segment);
        let (moves, cycles, kernel) = (m.moves, m.cycles, m.kernel);
        m.samples.clear();
        g.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let mut timed = Duration::ZERO;
                for _ in 0..iters {
                    m.command();
                    m.cycle(&mut timed);
                }
                timed
            })
        });
        // The moves ran (an axis that stood again was Done and took the next; velocity: one
        // each), and the kernel's step as a share of the timed part.
        let cycles = m.cycles - cycles;
        if cycles == 0 {
            continue; // filtered out
        }
        let per_cycle = (m.kernel - kernel).as_secs_f64() * 1e6 / cycles as f64;
        let mut t = std::mem::take(&mut m.samples);
        t.sort_unstable();
        let at = |q: f64| {
            t.get((q * t.len() as f64) as usize)
                .map_or(0.0, |&ns| ns as f64 / 1e3)
        };
        eprintln!(
            "{group}/{name}: {} moves in {cycles} cycles, kernel step {per_cycle:.1} µs{}",
            m.moves - moves,
            if t.is_empty() {
                String::new()
            } else {
                format!(", cycle median {:.0} µs, p99 {:.0} µs", at(0.5), at(0.99))
            }
        );
        // (`cargo test` runs each case once: too short for a move to end.)
        if load == Load::Positioning && cycles >= 1000 {
            assert!(
                m.moves - moves > AXES as u64,
                "the axes move back and forth"
            );
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
