//! One kernel cycle for 1, 8 and 64 axes under mixed load: a quarter positioning back and
//! forth, a quarter velocity moves re-planned every cycle by an override ramp, a quarter
//! gear slaves of moving masters, a quarter jogging. Figures: docs/benchmarks.md.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use motion::*;

struct Machine {
    k: Kernel,
    fb: Vec<DriveFeedback>,
    sp: Vec<DriveSetpoint>,
    events: Vec<CommandEvent>,
    n: usize,
    next_id: u64,
    cycle: u64,
}

fn mv(position: f64) -> Positioning {
    Positioning {
        position,
        velocity: 400.0,
        dynamics: Dynamics::default(),
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    }
}

impl Machine {
    fn new(n: usize) -> Machine {
        let mut k = Kernel::new(0.001, n);
        for i in 0..n {
            let p = AxisParameters {
                axis_max_pos_lag_value: 1e6,
                ..AxisParameters::default()
            };
            k.insert_axis(
                i as u16,
                Axis::new(
                    AxisConfig {
                        modulo: false,
                        parameters: p,
                        compensation_table: None,
                        drive_executed: false,
                    },
                    0.001,
                ),
            )
            .unwrap();
        }
        let mut m = Machine {
            k,
            fb: vec![DriveFeedback::default(); n],
            sp: vec![DriveSetpoint::default(); n],
            events: Vec::with_capacity(1 << 16),
            n,
            next_id: 0,
            cycle: 0,
        };
        for a in 0..n as u16 {
            m.submit(
                a,
                CommandKind::Power {
                    enable: true,
                    enable_positive: true,
                    enable_negative: true,
                    override_percent: 100.0,
                    buffer_mode: BufferMode::Aborting,
                },
            );
        }
        for _ in 0..10 {
            m.cycle_once();
        }
        for a in 0..n {
            let axis = a as u16;
            match a % 4 {
                0 => m.submit(axis, CommandKind::MoveAbsolute(mv(200.0))),
                1 => m.submit(
                    axis,
                    CommandKind::MoveVelocity {
                        velocity: 300.0,
                        dynamics: Dynamics::default(),
                        direction: Direction::Positive,
                        buffer_mode: BufferMode::Aborting,
                        options: MoveOptions::default(),
                    },
                ),
                2 => m.submit(
                    axis,
                    CommandKind::GearIn {
                        master: (a - 2) as u16,
                        ratio_numerator: 0.5,
                        ratio_denominator: 1,
                    },
                ),
                _ => m.submit(
                    axis,
                    CommandKind::Jog {
                        mode: JogMode::Continuous,
                        forward: true,
                        position: 0.0,
                        velocity: 50.0,
                        dynamics: Dynamics::default(),
                        deadman: 0.0,
                    },
                ),
            };
        }
        m
    }

    fn submit(&mut self, axis: u16, kind: CommandKind) -> Verdict {
        self.next_id += 1;
        self.k.submit(
            Command {
                id: self.next_id,
                target: Target::Axis(axis),
                kind,
            },
            &mut self.events,
        )
    }

    fn cycle_once(&mut self) {
        self.cycle += 1;
        // Load: re-plan the velocity axes every cycle, restart finished moves.
        let o = 60.0 + 40.0 * ((self.cycle as f64) * 0.003).sin();
        for a in 0..self.n {
            let axis = a as u16;
            match a % 4 {
                1 => {
                    self.submit(
                        axis,
                        CommandKind::Power {
                            enable: true,
                            enable_positive: true,
                            enable_negative: true,
                            override_percent: o,
                            buffer_mode: BufferMode::Aborting,
                        },
                    );
                }
                0 if !self.k.status(axis).unwrap().has_job => {
                    let to = if self.k.status(axis).unwrap().set_position > 100.0 {
                        0.0
                    } else {
                        200.0
                    };
                    self.submit(axis, CommandKind::MoveAbsolute(mv(to)));
                }
                _ => {}
            }
        }
        self.k.step(&self.fb, &mut self.sp, &mut self.events);
        for (s, f) in self.sp.iter().zip(self.fb.iter_mut()) {
            f.ready = true;
            f.enabled = s.enable;
            f.actual_position = s.position;
            f.actual_velocity = s.velocity;
        }
        if self.events.len() > 60000 {
            self.events.clear();
        }
    }
}

fn cycle(c: &mut Criterion) {
    let mut g = c.benchmark_group("cycle_mixed_load");
    for n in [1usize, 8, 64] {
        // With one axis it is a positioning axis moving back and forth.
        let mut m = Machine::new(n);
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| m.cycle_once())
        });
    }
    g.finish();
    // The step alone, without the benchmark's own command traffic, at 64 axes.
    let mut m = Machine::new(64);
    c.bench_function("step_only_64_axes", |b| {
        b.iter(|| {
            m.k.step(&m.fb, &mut m.sp, &mut m.events);
            if m.events.len() > 60000 {
                m.events.clear();
            }
        })
    });
}

/// 64 powered axes at rest with no command traffic of the benchmark's own (`n` = 0), their
/// parameters as `tune` leaves them, the kernel's cam tables put in by `cams`.
fn powered_64(tune: impl Fn(&mut AxisParameters), cams: impl FnOnce(&mut Kernel)) -> Machine {
    let mut m = Machine::new(1);
    let n = 64;
    let mut k = Kernel::new(0.001, n);
    for i in 0..n {
        let mut p = AxisParameters {
            axis_max_pos_lag_value: 1e6,
            axis_velo_max: 1e6,
            ..AxisParameters::default()
        };
        tune(&mut p);
        k.insert_axis(
            i as u16,
            Axis::new(
                AxisConfig {
                    modulo: false,
                    parameters: p,
                    compensation_table: None,
                    drive_executed: false,
                },
                0.001,
            ),
        )
        .unwrap();
    }
    cams(&mut k);
    m.k = k;
    m.fb = vec![DriveFeedback::default(); n];
    m.sp = vec![DriveSetpoint::default(); n];
    m.n = 0; // no command traffic in cycle_once
    for a in 0..n as u16 {
        m.submit(
            a,
            CommandKind::Power {
                enable: true,
                enable_positive: true,
                enable_negative: true,
                override_percent: 100.0,
                buffer_mode: BufferMode::Aborting,
            },
        );
    }
    for _ in 0..10 {
        m.cycle_once();
    }
    m
}

/// One master at constant velocity and 63 cam slaves: odd ones through a periodic 20-segment
/// motion function, even ones through a periodic 100 000-row spline table.
fn cam_machine() -> Machine {
    use motion::cam::*;
    use std::sync::Arc;
    let n = 64;
    let laws = [
        MotionFunctionType::Polynom5,
        MotionFunctionType::Bestehorn,
        MotionFunctionType::ModSinuslinie,
        MotionFunctionType::Polynom7,
    ];
    let points: Vec<_> = (0..=20u32)
        .map(|i| MotionFunctionPoint {
            point_index: i + 1,
            function_type: laws[i as usize % laws.len()],
            point_type: MotionPointType::Rest,
            rel_index_next_point: 1,
            master_pos: i as f64 * 18.0,
            slave_pos: if i % 2 == 0 { 0.0 } else { 50.0 },
            slave_velo: 0.0,
            slave_acc: 0.0,
            slave_jerk: 0.0,
        })
        .collect();
    let mut mf = CamTableData::motion_function(points);
    mf.periodic = true;
    let rows: Vec<[f64; 2]> = (0..100_000)
        .map(|i| {
            [
                i as f64 * 0.0036,
                (i as f64 * 0.0036).to_radians().sin() * 50.0,
            ]
        })
        .collect();
    let mut table = CamTableData::positions(rows, false);
    table.periodic = true;
    table.interpolation = InterpolationType::Spline;
    let mut m = powered_64(
        |_| {},
        |k| {
            k.insert_cam(1, Arc::new(Cam::build(&mf).unwrap())).unwrap();
            k.insert_cam(2, Arc::new(Cam::build(&table).unwrap()))
                .unwrap();
        },
    );
    for a in 1..n as u16 {
        let v = m.submit(
            a,
            CommandKind::CamIn(CamIn {
                master: 0,
                cam_table: 1 + (a as u32 % 2),
                master_offset: 0.0,
                slave_offset: 0.0,
                master_scaling: 1.0,
                slave_scaling: 1.0,
                start_mode: StartMode::Absolute,
                activation_mode: CamActivationMode::Instantaneous,
                activation_position: 0.0,
                master_scaling_mode: CamScalingMode::UserDefined,
                slave_scaling_mode: CamScalingMode::UserDefined,
                interpolation: None,
                ramp_in: Default::default(),
            }),
        );
        assert_eq!(v, Verdict::Accepted);
    }
    m.submit(
        0,
        CommandKind::MoveVelocity {
            velocity: 300.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    m
}

fn cams(c: &mut Criterion) {
    let mut m = cam_machine();
    c.bench_function("step_64_axes_63_cam_slaves", |b| {
        b.iter(|| {
            m.k.step(&m.fb, &mut m.sp, &mut m.events);
            for (s, f) in m.sp.iter().zip(m.fb.iter_mut()) {
                f.ready = true;
                f.enabled = s.enable;
                f.actual_position = s.position;
                f.actual_velocity = s.velocity;
            }
            if m.events.len() > 60000 {
                m.events.clear();
            }
        })
    });
    assert!(m.k.status(1).unwrap().coupled && m.k.status(2).unwrap().coupled);
}

/// 64 axes with the single-axis blocks of issue 9 running, in groups of four: a velocity
/// axis with the position-correction limiter and backlash compensation, a second velocity
/// axis, a multi-master slave of both with AdvancedSlaveDynamics in POSSYNC2 (replanned every
/// cycle), and a gear slave of the first being phased.
fn issue9_machine() -> Machine {
    let n = 64;
    let mut m = powered_64(|p| p.axis_enable_pos_correction = true, |_| {});
    let velocity = |v: f64| CommandKind::MoveVelocity {
        velocity: v,
        dynamics: Dynamics::default(),
        direction: Direction::Positive,
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    };
    for g in (0..n as u16).step_by(4) {
        let accepted = [
            m.submit(
                g + 2,
                CommandKind::GearInMultiMaster(GearInMultiMaster {
                    masters: [Some(g), Some(g + 1), None, None],
                    ratios: [0.5, 0.25, 0.0, 0.0],
                    acceleration: 1000.0,
                    deceleration: 1000.0,
                    jerk: 10_000.0,
                    advanced_slave_dynamics: true,
                    sync_mode: MultiMasterSyncMode::Possync2,
                }),
            ),
            m.submit(
                g + 3,
                CommandKind::GearIn {
                    master: g,
                    ratio_numerator: 1.0,
                    ratio_denominator: 1,
                },
            ),
            m.submit(g, velocity(300.0)),
            m.submit(g + 1, velocity(100.0)),
            m.submit(
                g,
                CommandKind::PositionCorrectionLimiter {
                    value: 1e6,
                    mode: PositionCorrectionMode::Fast,
                    acceleration: 1000.0,
                    correction_length: 0.0,
                },
            ),
            m.submit(
                g,
                CommandKind::BacklashCompensation {
                    backlash: Some(0.1),
                    compensate_in_positive_direction: true,
                    ramp: 1.0,
                    disable_mode: DisableMode::Hold,
                },
            ),
            m.submit(
                g + 3,
                CommandKind::Phasing {
                    master: g,
                    motion: PhasingMotion {
                        kind: PhasingKind::Absolute,
                        phase_shift: 1e6,
                        velocity: 10.0,
                        acceleration: 0.0,
                        deceleration: 0.0,
                        jerk: 0.0,
                    },
                },
            ),
        ];
        assert!(
            accepted.iter().all(|v| *v == Verdict::Accepted),
            "{accepted:?}"
        );
    }
    for _ in 0..100 {
        m.cycle_once();
    }
    m
}

fn issue9(c: &mut Criterion) {
    let mut m = issue9_machine();
    c.bench_function("step_64_axes_issue9_blocks", |b| b.iter(|| m.cycle_once()));
    let st = m.k.status(2).unwrap();
    assert!(st.coupled && st.gear_ratios[1] == 0.25);
    assert!(m.k.status(3).unwrap().phasing_active);
    assert!(m.k.status(0).unwrap().position_correction.limiter_limiting);
}

criterion_group!(benches, cycle, cams, issue9);
criterion_main!(benches);
