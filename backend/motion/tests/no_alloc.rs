//! `Kernel::step` (and submitting commands that re-plan) allocates nothing: a counting global
//! allocator watches the cycles of steady motion, re-planning every cycle, and coupling.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use motion::*;

struct Counting;

thread_local! {
    static COUNT: Cell<u64> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        COUNT.with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        COUNT.with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static A: Counting = Counting;

fn allocations() -> u64 {
    COUNT.with(|c| c.get())
}

/// An ideal drive: actual = last setpoint.
fn exchange(sp: &[DriveSetpoint], fb: &mut [DriveFeedback]) {
    for (s, f) in sp.iter().zip(fb.iter_mut()) {
        f.ready = true;
        f.enabled = s.enable;
        f.actual_velocity = (s.position - f.actual_position) / 0.001;
        f.actual_position = s.position;
    }
}

#[test]
fn step_and_replanning_allocate_nothing() {
    const N: usize = 8;
    let mut k = Kernel::new(0.001, N);
    for i in 0..N {
        let p = AxisParameters {
            axis_max_pos_lag_value: 100.0,
            ..AxisParameters::default()
        };
        k.insert_axis(
            i as u16,
            Axis::new(
                AxisConfig {
                    modulo: i % 2 == 1,
                    parameters: p,
                    compensation_table: None,
                    drive_executed: false,
                },
                0.001,
            ),
        )
        .unwrap();
    }
    let mut fb = vec![DriveFeedback::default(); N];
    let mut sp = vec![DriveSetpoint::default(); N];
    let mut events: Vec<CommandEvent> = Vec::with_capacity(4096);
    let mut id = 0;
    let mut submit =
        |k: &mut Kernel, events: &mut Vec<CommandEvent>, axis: u16, kind: CommandKind| {
            id += 1;
            assert_eq!(
                k.submit(
                    Command {
                        id,
                        target: Target::Axis(axis),
                        kind,
                    },
                    events
                ),
                Verdict::Accepted,
                "{kind:?}"
            );
        };
    for a in 0..N as u16 {
        submit(
            &mut k,
            &mut events,
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
    for _ in 0..20 {
        k.step(&fb, &mut sp, &mut events);
        exchange(&sp, &mut fb);
    }
    events.clear();
    // The counter sees allocations (so the zero below means something).
    let probe = allocations();
    drop(std::hint::black_box(vec![1u8; 16]));
    assert_eq!(allocations(), probe + 1);
    // Warm-up is over: from here on nothing may allocate.
    let before = allocations();
    let mv = |p: f64| Positioning {
        position: p,
        velocity: 200.0,
        dynamics: Dynamics::default(),
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    };
    submit(
        &mut k,
        &mut events,
        1,
        CommandKind::GearIn {
            master: 0,
            ratio_numerator: 2.0,
            ratio_denominator: 1,
        },
    );
    submit(&mut k, &mut events, 0, CommandKind::MoveAbsolute(mv(300.0)));
    submit(
        &mut k,
        &mut events,
        2,
        CommandKind::MoveVelocity {
            velocity: 100.0,
            dynamics: Dynamics::default(),
            direction: Direction::Negative,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    submit(&mut k, &mut events, 3, CommandKind::MoveAbsolute(mv(100.0)));
    submit(
        &mut k,
        &mut events,
        3,
        CommandKind::MoveAbsolute(Positioning {
            buffer_mode: BufferMode::BlendingHigh,
            ..mv(200.0)
        }),
    );
    submit(
        &mut k,
        &mut events,
        4,
        CommandKind::Jog {
            mode: JogMode::Continuous,
            forward: true,
            position: 0.0,
            velocity: 50.0,
            dynamics: Dynamics::default(),
            deadman: 0.5,
        },
    );
    // Parameter writes are checked in the cycle thread as well: accepted or refused (here a
    // relation broken), nothing allocates.
    submit(
        &mut k,
        &mut events,
        6,
        CommandKind::WriteParameter {
            number: 1026,
            value: 0.05,
        },
    );
    for (number, value) in [(1003, 1.0), (1003, f64::NAN), (9999, 1.0), (1050, 0.002)] {
        let kind = CommandKind::WriteParameter { number, value };
        let cmd = Command {
            id: 100_000,
            target: Target::Axis(6),
            kind,
        };
        assert_ne!(k.submit(cmd, &mut events), Verdict::Accepted, "{kind:?}");
    }
    for c in 0..2000 {
        // Re-planning every cycle on axis 5 (override changes), keepalives on the jog.
        let o = 50.0 + 50.0 * ((c as f64) * 0.01).sin().abs();
        submit(
            &mut k,
            &mut events,
            5,
            CommandKind::Power {
                enable: true,
                enable_positive: true,
                enable_negative: true,
                override_percent: o,
                buffer_mode: BufferMode::Aborting,
            },
        );
        if c == 0 {
            submit(
                &mut k,
                &mut events,
                5,
                CommandKind::MoveVelocity {
                    velocity: 150.0,
                    dynamics: Dynamics::default(),
                    direction: Direction::Positive,
                    buffer_mode: BufferMode::Aborting,
                    options: MoveOptions::default(),
                },
            );
        }
        if c % 100 == 0 {
            submit(
                &mut k,
                &mut events,
                4,
                CommandKind::Keepalive { target: 14 },
            );
        }
        k.step(&fb, &mut sp, &mut events);
        exchange(&sp, &mut fb);
        if events.len() > 3000 {
            events.clear();
        }
    }
    let after = allocations();
    assert_eq!(
        after - before,
        0,
        "the kernel allocated {} times",
        after - before
    );
    // And the motion really happened.
    assert!(k.status(0).unwrap().set_position > 299.0);
    assert!(
        (k.status(1).unwrap().set_position - 2.0 * k.status(0).unwrap().set_position).abs() < 1e-6
    );
    assert!(k.status(2).unwrap().set_position < -100.0);
}

/// Evaluating a built cam — a motion function of every kind of law and a large spline
/// table, periodic — allocates nothing (it runs in the cycle).
#[test]
fn evaluating_a_cam_allocates_nothing() {
    use motion::cam::*;
    let point = |i: u32, law, x: f64, y: f64| MotionFunctionPoint {
        point_index: i,
        function_type: law,
        point_type: MotionPointType::Motion,
        rel_index_next_point: 1,
        master_pos: x,
        slave_pos: y,
        slave_velo: 0.0,
        slave_acc: 0.0,
        slave_jerk: 0.0,
    };
    use MotionFunctionType::*;
    let laws = [
        Polynom5,
        Bestehorn,
        ModSinuslinie,
        BeschlTrapez,
        HarmonicKombiRt,
        HarmonicKombiTr,
        Polynom7Mm,
        Polynom1,
    ];
    let mut points: Vec<_> = laws
        .iter()
        .enumerate()
        .map(|(i, &l)| point(i as u32 + 1, l, i as f64 * 10.0, (i % 2) as f64 * 5.0))
        .collect();
    points.push(point(
        laws.len() as u32 + 1,
        Polynom1,
        laws.len() as f64 * 10.0,
        0.0,
    ));
    let mut mf = CamTableData::motion_function(points);
    mf.periodic = true;
    let rows: Vec<[f64; 2]> = (0..10_000)
        .map(|i| [i as f64, (i as f64 * 0.01).sin()])
        .collect();
    let mut table = CamTableData::positions(rows, false);
    table.periodic = true;
    table.interpolation = InterpolationType::Spline;
    let cams = [Cam::build(&mf).unwrap(), Cam::build(&table).unwrap()];
    let before = allocations();
    let mut sum = 0.0;
    for cam in &cams {
        for i in 0..20_000 {
            let v = cam.eval(i as f64 * 0.731 - 3000.0);
            sum += v.position + v.velocity + v.acceleration + v.jerk;
        }
    }
    assert!(sum.is_finite());
    assert_eq!(allocations() - before, 0, "cam evaluation allocated");
}

/// A group running blended paths — committing a prepared path, following lines, arcs and
/// blends, an override change, a halt on the path and a path built in the cycle after it —
/// allocates nothing in the cycle (the tables and the prepared paths are built before).
/// A kernel of `n` axes (a generous lag limit: the exchange below is ideal anyway) and group 0
/// of `convention`, not yet populated.
fn group_kernel(n: usize, convention: motion::group::AxesConvention) -> Kernel {
    use motion::group::*;
    let mut k = Kernel::new(0.001, n);
    for i in 0..n {
        let config = AxisConfig {
            modulo: false,
            parameters: AxisParameters {
                axis_max_pos_lag_value: 100.0,
                ..AxisParameters::default()
            },
            compensation_table: None,
            drive_executed: false,
        };
        k.insert_axis(i as u16, Axis::new(config, 0.001)).unwrap();
    }
    let config = GroupConfig {
        convention,
        ..GroupConfig::default()
    };
    k.insert_group(0, Group::new(config, 0.001)).unwrap();
    k
}

#[test]
fn a_group_on_a_blended_path_allocates_nothing() {
    use motion::group::*;
    use motion::path::{CircMode, CircPathChoice, MAX_PATH_DIMS};
    const N: usize = 3;
    let mut k = group_kernel(N, AxesConvention::Xyz);
    let mut events: Vec<CommandEvent> = Vec::with_capacity(1 << 16);
    let mut id = 0;
    let mut cmd = |k: &mut Kernel, target: Target, kind: CommandKind, e: &mut Vec<CommandEvent>| {
        id += 1;
        k.submit(Command { id, target, kind }, e)
    };
    for a in 0..N as u16 {
        let power = CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        };
        cmd(&mut k, Target::Axis(a), power, &mut events);
        let role = [GroupRole::X, GroupRole::Y, GroupRole::Z][a as usize];
        cmd(
            &mut k,
            Target::Group(0),
            CommandKind::AddAxisToGroup { axis: a, role },
            &mut events,
        );
    }
    cmd(
        &mut k,
        Target::Group(0),
        CommandKind::GroupEnable,
        &mut events,
    );
    let mut sp = vec![DriveSetpoint::default(); N];
    let mut fb = vec![DriveFeedback::default(); N];
    for _ in 0..20 {
        exchange(&sp, &mut fb);
        k.step(&fb, &mut sp, &mut events);
    }
    assert_eq!(k.group_status(0).unwrap().state, GroupState::Standby);
    let motion_of = |first: bool| EntryMotion {
        velocity: PathValue::Value(300.0),
        acceleration: PathValue::Default,
        deceleration: PathValue::Default,
        jerk: PathValue::Default,
        buffer_mode: if first {
            BufferMode::Buffered
        } else {
            BufferMode::BlendingPrevious
        },
        transition_mode: if first {
            TransitionMode::None
        } else {
            TransitionMode::CornerDistance
        },
        transition_parameters: [5.0, 0.0],
        transition_parameter_count: if first { 0 } else { 1 },
    };
    let p = |x: f64, y: f64, z: f64| {
        let mut v = [0.0; MAX_PATH_DIMS];
        v[..3].copy_from_slice(&[x, y, z]);
        v
    };
    let table = PathTable {
        entries: vec![
            PathEntry::Linear {
                position: p(100.0, 0.0, 0.0),
                count: 3,
                motion: motion_of(true),
                invoke_id: 1,
            },
            PathEntry::Circular {
                mode: CircMode::Center,
                aux: [100.0, 50.0, 0.0],
                end_point: p(150.0, 50.0, 0.0),
                count: 3,
                path_choice: CircPathChoice::CounterClockwise,
                motion: motion_of(false),
                invoke_id: 2,
            },
            PathEntry::Linear {
                position: p(150.0, 150.0, 20.0),
                count: 3,
                motion: motion_of(false),
                invoke_id: 3,
            },
            PathEntry::Linear {
                position: p(0.0, 0.0, 0.0),
                count: 3,
                motion: motion_of(false),
                invoke_id: 4,
            },
        ],
    };
    let ctx = k.path_context(0).unwrap();
    let prepared = prepare_path(&ctx, &table, k.group_status(0).unwrap().queue_end).unwrap();
    let before = allocations();
    let verdict = k.submit_prepared_path(1000, 0, &table, Some(&prepared), &mut events);
    assert_eq!(verdict, Verdict::Accepted);
    for c in 0..3000 {
        if c == 500 {
            cmd(
                &mut k,
                Target::Group(0),
                CommandKind::GroupSetOverride { factor: 0.5 },
                &mut events,
            );
        }
        if c == 1500 {
            let halt = CommandKind::GroupHalt {
                deceleration: PathValue::Default,
                jerk: PathValue::Default,
            };
            cmd(&mut k, Target::Group(0), halt, &mut events);
            // A path during the halt's ramp: built in the cycle from where the halt stops.
            assert_eq!(
                k.submit_path(1001, 0, &table, &mut events),
                Verdict::Accepted
            );
        }
        exchange(&sp, &mut fb);
        k.step(&fb, &mut sp, &mut events);
    }
    assert_eq!(allocations() - before, 0, "the group's cycles allocated");
    assert!(k.group(0).unwrap().prepared_paths_taken() == 1);
    assert!(
        events
            .iter()
            .any(|e| e.command == 1000 && e.outputs.command_aborted)
    );
}

/// MC_TrackConveyorBelt in the cycle: the chase, InSync, a conveyor that speeds up (a plan
/// per cycle), a second tracking across the first (one brakes while the other chases), a
/// frame that detaches and a halt — no allocation.
#[test]
fn a_group_tracking_conveyors_allocates_nothing() {
    use motion::group::*;
    const N: usize = 4;
    let mut k = group_kernel(N, AxesConvention::Xy);
    let mut events: Vec<CommandEvent> = Vec::with_capacity(1 << 16);
    let mut id = 0;
    let mut cmd = |k: &mut Kernel, target: Target, kind: CommandKind, e: &mut Vec<CommandEvent>| {
        id += 1;
        k.submit(Command { id, target, kind }, e)
    };
    for a in 0..N as u16 {
        let power = CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        };
        cmd(&mut k, Target::Axis(a), power, &mut events);
    }
    for (a, role) in [(0, GroupRole::X), (1, GroupRole::Y)] {
        let add = CommandKind::AddAxisToGroup { axis: a, role };
        cmd(&mut k, Target::Group(0), add, &mut events);
    }
    cmd(
        &mut k,
        Target::Group(0),
        CommandKind::GroupEnable,
        &mut events,
    );
    let belt = |v: f64| CommandKind::MoveVelocity {
        velocity: v,
        dynamics: Dynamics::default(),
        direction: Direction::Positive,
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    };
    cmd(&mut k, Target::Axis(2), belt(50.0), &mut events);
    cmd(&mut k, Target::Axis(3), belt(30.0), &mut events);
    let mut sp = vec![DriveSetpoint::default(); N];
    let mut fb = vec![DriveFeedback::default(); N];
    for _ in 0..1000 {
        exchange(&sp, &mut fb);
        k.step(&fb, &mut sp, &mut events);
    }
    let track = |conveyor: u16, turn: f64| {
        CommandKind::TrackConveyorBelt(ConveyorTracking {
            conveyor,
            transform: CoordTransform {
                translation: [0.0, 100.0, 0.0],
                rotation: [0.0, 0.0, turn],
            },
            initial_object_position: [30.0, 0.0, 0.0],
            master_ref_position: 0.0,
            velocity: PathValue::Value(200.0),
            acceleration: PathValue::Value(1000.0),
            deceleration: PathValue::Value(1000.0),
            jerk: PathValue::Value(10000.0),
            behavior: TrackingBehavior::DynLimited,
            sync_tolerance: 0.01,
        })
    };
    let before = allocations();
    assert_eq!(
        cmd(&mut k, Target::Group(0), track(2, 0.0), &mut events),
        Verdict::Accepted
    );
    for c in 0..4000 {
        match c {
            800 => {
                cmd(&mut k, Target::Axis(2), belt(80.0), &mut events);
            }
            1600 => {
                let v = cmd(&mut k, Target::Group(0), track(3, 90.0), &mut events);
                assert_eq!(v, Verdict::Accepted);
            }
            2400 => {
                let frame = CommandKind::SetCoordinateTransform {
                    transform: CoordTransform::default(),
                };
                cmd(&mut k, Target::Group(0), frame, &mut events);
                cmd(&mut k, Target::Group(0), track(2, 0.0), &mut events);
            }
            3200 => {
                let halt = CommandKind::GroupHalt {
                    deceleration: PathValue::Default,
                    jerk: PathValue::Default,
                };
                cmd(&mut k, Target::Group(0), halt, &mut events);
            }
            _ => {}
        }
        exchange(&sp, &mut fb);
        k.step(&fb, &mut sp, &mut events);
    }
    assert_eq!(allocations() - before, 0, "the tracking's cycles allocated");
    assert!(events.iter().any(|e| e.outputs.in_sync), "it synchronised");
    assert_eq!(k.group_status(0).unwrap().state, GroupState::Standby);
}
