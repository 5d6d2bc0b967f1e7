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

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use drives::cia402::{Cia402Config, Cia402Drive, ProfileSide, RxPdo, TxPdo};
use ethercat::emu::drive::{Cia402Emu, Plant};
use ethercat::emu::sii::Identity;
use motion::*;

const DT: f64 = 0.001;
const AXES: usize = 64;

#[derive(Clone, Copy, PartialEq)]
enum Load {
    Positioning,
    Velocity,
    Standing,
}

struct Machine {
    k: Kernel,
    cia: Vec<Cia402Drive>,
    emu: Vec<Cia402Emu>,
    tx: Vec<TxPdo>,
    rx: Vec<RxPdo>,
    fb: Vec<DriveFeedback>,
    sp: Vec<DriveSetpoint>,
    events: Vec<CommandEvent>,
    next_id: CommandId,
    load: Load,
}

fn dynamics() -> Dynamics {
    Dynamics {
        acceleration: 2000.0,
        deceleration: 2000.0,
        jerk: 0.0,
    }
}

impl Machine {
    fn new(drive_executed: bool, load: Load) -> Machine {
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
        let mut m = Machine {
            k,
            cia: (0..AXES)
                .map(|i| {
                    Cia402Drive::new(Cia402Config {
                        profile,
                        ..Cia402Config::csp(i as u16, 1000.0)
                    })
                })
                .collect(),
            emu: (0..AXES)
                .map(|_| Cia402Emu::new(&id, Plant::default()))
                .collect(),
            tx: vec![TxPdo::default(); AXES],
            rx: vec![RxPdo::default(); AXES],
            fb: vec![DriveFeedback::default(); AXES],
            sp: vec![DriveSetpoint::default(); AXES],
            events: Vec::with_capacity(4096),
            next_id: 1,
            load,
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
        for _ in 0..200 {
            m.cycle(&mut untimed);
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
        }
    }

    /// One cycle; motiond's part added to `timed`.
    fn cycle(&mut self, timed: &mut Duration) {
        let t0 = Instant::now();
        for i in 0..AXES {
            self.fb[i] = self.cia[i].feedback(&self.tx[i]);
        }
        self.k.step(&self.fb, &mut self.sp, &mut self.events);
        for i in 0..AXES {
            self.rx[i] = self.cia[i].outputs(&self.sp[i]);
        }
        *timed += t0.elapsed();
        black_box(&self.rx);
        for i in 0..AXES {
            self.tx[i] = self.emu[i].exchange_direct(&self.rx[i], DT);
        }
        self.events.clear();
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("cycle_64_axes");
    for (name, drive_executed, load) in [
        ("host_csp", false, Load::Positioning),
        ("drive_pp", true, Load::Positioning),
        ("drive_pv", true, Load::Velocity),
        ("host_standing", false, Load::Standing),
        ("drive_standing", true, Load::Standing),
    ] {
        let mut m = Machine::new(drive_executed, load);
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
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
