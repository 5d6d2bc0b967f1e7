//! An axis whose drive runs the profile, cycle by cycle in virtual time: the kernel, the
//! CiA-402 layer and the emulated drive wired directly (one cycle of bus latency, no segment).
//! Done only when the drive reports the target reached; the set-point handshake; halt and stop
//! through the halt bit; MoveVelocity's InVelocity from the drive; homing in the drive; the
//! blocks Drive Motion Control does not have refused; MC2's drive-based homing on a host-side
//! axis, then a CSP move without a jump.

use drives::cia402::{Cia402Config, Cia402Drive, ProfileSide, TxPdo};
use ethercat::emu::drive::{Cia402Emu, Plant};
use ethercat::emu::sii::Identity;
use motion::*;

const DT: f64 = 0.001;

struct Machine {
    k: Kernel,
    cia: Cia402Drive,
    emu: Cia402Emu,
    tx: TxPdo,
    sp: [DriveSetpoint; 1],
    fb: DriveFeedback,
    events: Vec<CommandEvent>,
    next_id: CommandId,
    cycle: u64,
    /// The drive's answers still on their way (a bus that answers `latency` cycles late).
    in_flight: std::collections::VecDeque<TxPdo>,
    latency: usize,
}

impl Machine {
    /// `soft_max`: the enabled positive software limit.
    fn new(drive_executed: bool, soft_max: f64) -> Machine {
        let mut k = Kernel::new(DT, 1);
        let p = AxisParameters {
            axis_en_max_soft_pos_limit: true,
            axis_max_soft_pos_limit: soft_max,
            ..Default::default()
        };
        k.insert_axis(
            0,
            Axis::new(
                AxisConfig {
                    parameters: p,
                    drive_executed,
                    ..AxisConfig::default()
                },
                DT,
            ),
        )
        .unwrap();
        let id = Identity {
            vendor_id: 1,
            product_code: 2,
            revision: 3,
            serial: 4,
            name: "drive".into(),
        };
        let plant = Plant {
            limit_negative: Some(-45_000.0),
            limit_positive: Some(450_000.0),
            ..Plant::default()
        };
        let profile = if drive_executed {
            ProfileSide::Drive
        } else {
            ProfileSide::Host
        };
        Machine {
            k,
            cia: Cia402Drive::new(Cia402Config {
                profile,
                ..Cia402Config::csp(0, 1000.0)
            }),
            emu: Cia402Emu::new(&id, plant),
            tx: TxPdo::default(),
            sp: [DriveSetpoint::default()],
            fb: DriveFeedback::default(),
            events: Vec::new(),
            next_id: 1,
            cycle: 0,
            in_flight: std::collections::VecDeque::new(),
            latency: 0,
        }
    }

    fn cmd(&mut self, kind: CommandKind) -> (CommandId, Verdict) {
        let id = self.next_id;
        self.next_id += 1;
        let v = self.k.submit(
            Command {
                id,
                target: Target::Axis(0),
                kind,
            },
            &mut self.events,
        );
        (id, v)
    }

    fn ok(&mut self, kind: CommandKind) -> CommandId {
        let (id, v) = self.cmd(kind);
        assert_eq!(v, Verdict::Accepted, "{kind:?}");
        id
    }

    fn refused(&mut self, kind: CommandKind) -> ErrorId {
        match self.cmd(kind).1 {
            Verdict::Rejected(e) => e,
            v => panic!("{kind:?} accepted: {v:?}"),
        }
    }

    /// One cycle: the drive's last answer → the kernel → the drive.
    fn step(&mut self) {
        self.fb = self.cia.feedback(&self.tx);
        self.k.step(&[self.fb], &mut self.sp, &mut self.events);
        let rx = self.cia.outputs(&self.sp[0]);
        let answer = self.emu.exchange_direct(&rx, DT);
        self.in_flight.push_back(answer);
        while self.in_flight.len() > self.latency {
            self.tx = self.in_flight.pop_front().expect("one at least");
        }
        self.cycle += 1;
    }

    fn out(&self, id: CommandId) -> FbOutputs {
        self.events
            .iter()
            .rev()
            .find(|e| e.command == id)
            .map(|e| e.outputs)
            .unwrap_or_default()
    }

    fn st(&self) -> AxisStatus {
        self.k.status(0).unwrap()
    }

    /// Steps until `f` holds; the number of cycles it took.
    fn until(&mut self, seconds: f64, f: impl Fn(&Machine) -> bool) -> usize {
        for n in 0..(seconds / DT) as usize {
            if f(self) {
                return n;
            }
            self.step();
        }
        panic!("not reached within {seconds} s: {:?}", self.st());
    }

    fn power(&mut self) {
        self.ok(CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        });
        self.until(1.0, |m| m.st().state == AxisState::Standstill);
    }
}

fn mv(position: f64, velocity: f64) -> Positioning {
    Positioning {
        position,
        velocity,
        dynamics: Dynamics {
            acceleration: 1000.0,
            deceleration: 1000.0,
            jerk: 0.0,
        },
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    }
}

#[test]
fn a_move_is_done_when_the_drive_reports_its_target_reached() {
    let mut m = Machine::new(true, 400.0);
    m.power();
    // The drive is switched to profile position at rest.
    m.until(0.1, |m| m.fb.profile.mode == ProfileMode::Position);
    let id = m.ok(CommandKind::MoveAbsolute(mv(50.0, 100.0)));
    assert_eq!(m.st().state, AxisState::DiscreteMotion);
    let cycles = m.until(3.0, |m| m.out(id).done);
    assert!(cycles > 500, "0.55 s of motion at least: {cycles}");
    let st = m.st();
    assert!((st.actual_position - 50.0).abs() <= 0.011, "{st:?}");
    assert_eq!(st.state, AxisState::Standstill);
    assert!(m.fb.profile.target_reached);
    assert_eq!(m.emu.od.i32(0x607A, 0), 50_000, "the target in increments");
    assert_eq!(m.emu.od.u32(0x6081, 0), 100_000, "the profile velocity");
    assert_eq!(m.emu.od.u32(0x6083, 0), 1_000_000);
}

#[test]
fn the_set_point_handshake_and_done_cycle_by_cycle() {
    let mut m = Machine::new(true, 400.0);
    m.power();
    m.until(0.1, |m| m.fb.profile.mode == ProfileMode::Position);
    let id = m.ok(CommandKind::MoveRelative(mv(20.0, 50.0)));
    let mut sent = false;
    let mut acked = false;
    let mut done_cycle = None;
    for _ in 0..3000 {
        m.step();
        let cw = m.emu.od.u16(0x6040, 0);
        let bit4 = cw & (1 << 4) != 0;
        if bit4 {
            sent = true;
            assert!(!acked, "bit 4 again after the acknowledge");
        }
        if sent && m.fb.profile.acknowledge {
            acked = true;
        }
        let out = m.out(id);
        assert!(!(out.done && out.busy), "exclusive outputs");
        if out.done {
            assert!(acked, "done only after the acknowledge");
            assert!(m.fb.profile.target_reached, "done with the drive's bit 10");
            done_cycle = Some(m.cycle);
            break;
        }
        assert!(out.busy && out.active, "{out:?}");
    }
    assert!(done_cycle.is_some());
    assert!((m.st().actual_position - 20.0).abs() <= 0.011);
}

#[test]
fn halt_brakes_in_the_drive_and_a_new_move_runs_after_it() {
    let mut m = Machine::new(true, 400.0);
    m.power();
    m.until(0.1, |m| m.fb.profile.mode == ProfileMode::Position);
    let id = m.ok(CommandKind::MoveAbsolute(mv(200.0, 100.0)));
    m.until(1.0, |m| m.st().actual_position > 50.0);
    let halt = m.ok(CommandKind::Halt {
        deceleration: 500.0,
        jerk: 0.0,
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    });
    assert!(m.out(id).command_aborted);
    m.step();
    assert_ne!(m.emu.od.u16(0x6040, 0) & (1 << 8), 0, "halt bit");
    let cycles = m.until(1.0, |m| m.out(halt).done);
    // 100 mm/s at 500 mm/s² (the halt's deceleration, never weaker than the move's 1000:
    // 1000 is taken) — at most 0.2 s plus the answer.
    assert!(cycles < 250, "{cycles}");
    let stood = m.st().actual_position;
    assert!(stood < 200.0 && stood > 50.0, "{stood}");
    let id = m.ok(CommandKind::MoveAbsolute(mv(100.0, 100.0)));
    m.until(3.0, |m| m.out(id).done);
    assert!((m.st().actual_position - 100.0).abs() <= 0.011);
}

/// MC_MoveVelocity, aborting, with the same acceleration and deceleration.
fn velocity(velocity: f64, ramp: f64, direction: Direction) -> CommandKind {
    CommandKind::MoveVelocity {
        velocity,
        dynamics: Dynamics {
            acceleration: ramp,
            deceleration: ramp,
            jerk: 0.0,
        },
        direction,
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    }
}

#[test]
fn move_velocity_is_in_velocity_when_the_drive_says_so_and_stop_locks() {
    let mut m = Machine::new(true, 400.0);
    m.power();
    let id = m.ok(velocity(20.0, 200.0, Direction::Negative));
    m.until(2.0, |m| m.out(id).in_velocity);
    assert_eq!(m.fb.profile.mode, ProfileMode::Velocity);
    assert!((m.st().actual_velocity + 20.0).abs() <= 0.2, "{:?}", m.st());
    assert_eq!(m.st().state, AxisState::ContinuousMotion);
    let stop = m.ok(CommandKind::Stop {
        deceleration: 0.0,
        jerk: 0.0,
        options: MoveOptions::default(),
    });
    assert!(m.out(id).command_aborted);
    m.until(1.0, |m| m.out(stop).done);
    assert_eq!(m.st().state, AxisState::Stopping, "locked until released");
    // Done when the drive says it stands (within its velocity window 0x606D, 1 mm/s here).
    assert!(
        m.st().actual_velocity.abs() <= 1.0,
        "{:?}",
        m.st().actual_velocity
    );
    m.until(0.1, |m| m.st().actual_velocity.abs() < 0.01);
    let e = m.refused(CommandKind::MoveAbsolute(mv(0.0, 10.0)));
    assert_eq!(e, ErrorId::AXIS_CANNOT_BE_STARTED);
    m.ok(CommandKind::Release { target: stop });
    m.until(0.1, |m| m.st().state == AxisState::Standstill);
    // A positioning move after velocity: the drive switches back to profile position at rest.
    let id = m.ok(CommandKind::MoveAbsolute(mv(0.0, 50.0)));
    m.until(3.0, |m| m.out(id).done);
    assert!(m.st().actual_position.abs() <= 0.011);
}

#[test]
fn velocity_stops_before_an_enabled_soft_limit() {
    let mut m = Machine::new(true, 400.0);
    m.power();
    let id = m.ok(velocity(100.0, 1000.0, Direction::Positive));
    m.until(6.0, |m| m.out(id).error);
    assert_eq!(ErrorId(m.out(id).error_id), ErrorId::SOFT_LIMIT_REACHED);
    m.until(1.0, |m| m.st().state == AxisState::Standstill);
    for _ in 0..100 {
        m.step();
    }
    assert!(m.st().actual_position <= 400.0, "{:?}", m.st());
    assert!(m.st().actual_position > 390.0, "{:?}", m.st());
}

/// A drive that still creeps out of the limits after homing onto a limit (what a drive
/// reports while it settles) heads nowhere: a move back into the limits starts. It was an
/// axis error (soft_limit_reached) whenever the move came within the creep, so a move after
/// homing onto the limit failed at random over the emulated segment (decision 172).
#[test]
fn a_move_off_a_limit_starts_while_the_drive_settles_onto_it() {
    let mut k = Kernel::new(DT, 1);
    let p = AxisParameters {
        axis_en_min_soft_pos_limit: true,
        axis_min_soft_pos_limit: 0.0,
        ..Default::default()
    };
    let config = AxisConfig {
        parameters: p,
        drive_executed: true,
        ..AxisConfig::default()
    };
    k.insert_axis(0, Axis::new(config, DT)).unwrap();
    // A thousandth of a unit per second outwards, a ten-thousandth of a micrometre away.
    let fb = [DriveFeedback {
        ready: true,
        enabled: true,
        actual_position: 1e-7,
        actual_velocity: -1e-3,
        ..DriveFeedback::default()
    }];
    let (mut sp, mut events) = ([DriveSetpoint::default()], Vec::new());
    let submit = |k: &mut Kernel, id, kind, events: &mut Vec<CommandEvent>| {
        let c = Command {
            id,
            target: Target::Axis(0),
            kind,
        };
        assert_eq!(k.submit(c, events), Verdict::Accepted);
    };
    let power = CommandKind::Power {
        enable: true,
        enable_positive: true,
        enable_negative: true,
        override_percent: 100.0,
        buffer_mode: BufferMode::Aborting,
    };
    submit(&mut k, 1, power, &mut events);
    for _ in 0..5 {
        k.step(&fb, &mut sp, &mut events);
    }
    assert_eq!(k.status(0).unwrap().state, AxisState::Standstill);
    submit(
        &mut k,
        2,
        CommandKind::MoveAbsolute(mv(120.0, 100.0)),
        &mut events,
    );
    for _ in 0..5 {
        k.step(&fb, &mut sp, &mut events);
    }
    let st = k.status(0).unwrap();
    assert_eq!(st.state, AxisState::DiscreteMotion, "{st:?}");
    assert!(
        events.iter().all(|e| !e.outputs.error),
        "{:?}",
        events.iter().find(|e| e.outputs.error)
    );
}

/// Endless motion commanded within the standstill band is still watched: a crawl stops at
/// the soft limit (the band is only for jobs that end by themselves, decision 172).
#[test]
fn a_crawl_stops_at_an_enabled_soft_limit() {
    let mut m = Machine::new(true, 0.05);
    m.power();
    let id = m.ok(velocity(0.04, 1000.0, Direction::Positive));
    m.until(3.0, |m| m.out(id).error);
    assert_eq!(ErrorId(m.out(id).error_id), ErrorId::SOFT_LIMIT_REACHED);
    m.until(1.0, |m| m.st().state == AxisState::Standstill);
    for _ in 0..100 {
        m.step();
    }
    assert!(m.st().actual_position <= 0.05, "{:?}", m.st());
    assert!(m.st().actual_position > 0.04, "{:?}", m.st());
}

#[test]
fn the_blocks_and_inputs_drive_motion_control_lacks_are_refused() {
    let mut m = Machine::new(true, 400.0);
    m.power();
    for kind in [
        CommandKind::MoveAdditive(mv(1.0, 1.0)),
        CommandKind::MoveContinuousAbsolute {
            move_: mv(1.0, 1.0),
            end_velocity: 1.0,
        },
        CommandKind::GearOut,
        CommandKind::ExtSetPointGenDisable,
        CommandKind::SetOverride {
            velocity_factor: 0.5,
            acceleration_factor: 1.0,
            jerk_factor: 1.0,
        },
        CommandKind::Jog {
            mode: JogMode::Inching,
            forward: true,
            position: 1.0,
            velocity: 1.0,
            dynamics: Dynamics::default(),
            deadman: 0.0,
        },
    ] {
        assert_eq!(
            m.refused(kind),
            ErrorId::NOT_ON_DRIVE_EXECUTED_AXIS,
            "{kind:?}"
        );
    }
    let jerk = Positioning {
        dynamics: Dynamics {
            jerk: 1000.0,
            ..Dynamics::default()
        },
        ..mv(1.0, 1.0)
    };
    let buffered = Positioning {
        buffer_mode: BufferMode::Buffered,
        ..mv(1.0, 1.0)
    };
    for kind in [
        CommandKind::MoveAbsolute(jerk),
        CommandKind::MoveRelative(buffered),
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 50.0,
            buffer_mode: BufferMode::Aborting,
        },
    ] {
        assert_eq!(
            m.refused(kind),
            ErrorId::INPUT_NOT_ON_DRIVE_EXECUTED_AXIS,
            "{kind:?}"
        );
    }
    // Nothing moved.
    for _ in 0..50 {
        m.step();
    }
    assert_eq!(m.st().state, AxisState::Standstill);
    assert!(m.st().actual_position.abs() < 1e-9);
}

#[test]
fn homing_runs_in_the_drive_and_the_axis_reads_the_reference_there() {
    let mut m = Machine::new(true, 1000.0);
    m.emu.od.set(0x6098, 0, &[1]);
    m.power();
    let id = m.ok(CommandKind::Home {
        position: Some(-5.0),
        mode: HomingMode::Default,
        options: HomingOptions::default(),
    });
    assert_eq!(m.st().state, AxisState::Homing);
    m.until(1.0, |m| m.fb.profile.mode == ProfileMode::Homing);
    m.until(10.0, |m| m.out(id).done || m.out(id).error);
    assert!(m.out(id).done, "{:?}", m.out(id));
    let st = m.st();
    assert!(st.homed);
    assert_eq!(st.state, AxisState::Standstill);
    assert!((st.actual_position + 5.0).abs() < 1e-3, "{st:?}");
    // On the plant: method 1 found the index pulse at −40 000 increments.
    assert!((m.emu.plant_position() + 40_000.0).abs() <= 1.0);
    // A homing error in the drive (method 34 runs into the positive switch at 450 mm on the
    // plant from 445 mm, 480 mm in the axis's coordinates now) ends the command with it.
    let id = m.ok(CommandKind::MoveAbsolute(mv(480.0, 100.0)));
    m.until(10.0, |m| m.out(id).done);
    m.emu.od.set(0x6098, 0, &[34]);
    let id = m.ok(CommandKind::Home {
        position: None,
        mode: HomingMode::Default,
        options: HomingOptions::default(),
    });
    m.until(10.0, |m| m.out(id).error || m.out(id).done);
    assert_eq!(ErrorId(m.out(id).error_id), ErrorId::DRIVE_HOMING_ERROR);
    assert!(!m.st().homed);
}

#[test]
fn drive_based_homing_on_a_host_axis_returns_to_csp_without_a_jump() {
    let mut m = Machine::new(false, 400.0);
    m.emu.od.set(0x6098, 0, &[34]);
    m.power();
    let id = m.ok(CommandKind::MoveAbsolute(mv(3.0, 50.0)));
    m.until(2.0, |m| m.out(id).done);
    let id = m.ok(CommandKind::Home {
        position: Some(100.0),
        mode: HomingMode::DriveBased,
        options: HomingOptions::default(),
    });
    m.until(1.0, |m| m.fb.profile.mode == ProfileMode::Homing);
    m.until(10.0, |m| m.out(id).done || m.out(id).error);
    assert!(m.out(id).done, "{:?}", m.out(id));
    assert!(
        (m.emu.plant_position() - 10_000.0).abs() <= 1.0,
        "index at 10 mm"
    );
    assert!((m.st().actual_position - 100.0).abs() < 1e-3);
    // The drive's position jumped where it homed: no following error for it (the lag is the
    // drive's own while it runs the profile).
    let st = m.st();
    assert!(
        st.following_error_max < 0.1 && st.following_error_min > -0.1,
        "{} {}",
        st.following_error_min,
        st.following_error_max
    );
    // Back in CSP: the set position is the actual one, no jump while the mode changes.
    let mut last = m.st().actual_position;
    for _ in 0..100 {
        m.step();
        let p = m.st().actual_position;
        assert!((p - last).abs() < 1e-3, "{last} → {p}");
        last = p;
    }
    assert_eq!(m.emu.od.i8(0x6061, 0), 8);
    let id = m.ok(CommandKind::MoveRelative(mv(5.0, 50.0)));
    let mut last_set = m.st().set_position;
    for _ in 0..2000 {
        m.step();
        let s = m.st().set_position;
        assert!(
            (s - last_set).abs() <= 50.0 * DT * 1.01,
            "set jumped {last_set} → {s}"
        );
        last_set = s;
        if m.out(id).done {
            break;
        }
    }
    assert!(m.out(id).done);
    assert!((m.st().actual_position - 105.0).abs() < 0.01);
}

#[test]
fn the_drives_following_error_is_an_axis_error_and_reset_recovers() {
    let mut m = Machine::new(true, 1000.0);
    // A lag window of 10 increments (10 µm): the drive's position loop lags more at speed.
    m.emu.od.set(0x6065, 0, &10u32.to_le_bytes());
    m.power();
    let id = m.ok(CommandKind::MoveAbsolute(mv(100.0, 100.0)));
    m.until(2.0, |m| m.out(id).error);
    assert_eq!(ErrorId(m.out(id).error_id), ErrorId::FOLLOWING_ERROR);
    assert_eq!(m.st().state, AxisState::ErrorStop);
    // The error stop brakes in the drive (halt bit) to a standstill.
    m.until(1.0, |m| {
        m.st().actual_velocity.abs() < 1e-3 && m.fb.profile.target_reached
    });
    assert_ne!(m.emu.od.u16(0x6040, 0) & (1 << 8), 0, "halt bit");
    // It stays halted: the drive's set point (100 mm) must not resume.
    let stood = m.st().actual_position;
    for _ in 0..300 {
        m.step();
        assert!(
            (m.st().actual_position - stood).abs() < 1e-3,
            "moved after the stop"
        );
    }
    m.emu.od.set(0x6065, 0, &100_000u32.to_le_bytes());
    let r = m.ok(CommandKind::Reset);
    m.until(1.0, |m| m.out(r).done);
    m.until(0.5, |m| m.st().state == AxisState::Standstill);
    let id = m.ok(CommandKind::MoveAbsolute(mv(10.0, 50.0)));
    m.until(3.0, |m| m.out(id).done);
    assert!((m.st().actual_position - 10.0).abs() <= 0.011);
}

#[test]
fn move_modulo_takes_its_start_types_on_a_drive_executed_axis() {
    let mut m = Machine::new(true, 1000.0);
    m.power();
    let id = m.ok(CommandKind::MoveAbsolute(mv(90.0, 200.0)));
    m.until(3.0, |m| m.out(id).done);
    // From 90 positive to 0: 360; there negative to 0: no motion; negative to 270: 270;
    // shortest way to 0: 360; negative to 360 (≥ one period: a full turn back): 0.
    for (target, direction, end) in [
        (0.0, Direction::Positive, 360.0),
        (0.0, Direction::Negative, 360.0),
        (270.0, Direction::Negative, 270.0),
        (0.0, Direction::ShortestWay, 360.0),
        (360.0, Direction::Negative, 0.0),
    ] {
        let id = m.ok(CommandKind::MoveModulo {
            move_: mv(target, 200.0),
            direction,
        });
        m.until(10.0, |m| m.out(id).done || m.out(id).error);
        assert!(m.out(id).done, "{:?}", m.out(id));
        assert!(
            (m.st().actual_position - end).abs() <= 0.011,
            "{target} {direction:?}: {} ≠ {end}",
            m.st().actual_position
        );
    }
}

/// DMC's MoveVelocity with ContinuousUpdate: new inputs while it runs, taken at once, on an
/// axis whose drive runs the profile and on a host-side one alike; without it, or on another
/// block, an update is refused.
#[test]
fn move_velocity_with_continuous_update_takes_new_inputs_while_it_runs() {
    for drive_executed in [true, false] {
        let mut m = Machine::new(drive_executed, 1e6);
        m.power();
        let velocity = |v: f64, update: bool| CommandKind::MoveVelocity {
            velocity: v,
            dynamics: Dynamics {
                acceleration: 200.0,
                deceleration: 200.0,
                jerk: 0.0,
            },
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions {
                continuous_update: update,
                ..MoveOptions::default()
            },
        };
        let id = m.ok(velocity(20.0, true));
        m.until(2.0, |m| m.out(id).in_velocity);
        let update = |v: f64| CommandKind::UpdateInputs {
            target: id,
            velocity: v,
            dynamics: Dynamics {
                acceleration: 400.0,
                deceleration: 400.0,
                jerk: 0.0,
            },
        };
        let u = m.ok(update(40.0));
        assert!(m.out(u).done);
        m.step();
        m.until(0.2, |m| !m.out(id).in_velocity);
        m.until(2.0, |m| m.out(id).in_velocity);
        assert!(
            (m.st().actual_velocity - 40.0).abs() <= 0.4,
            "{drive_executed}: {:?}",
            m.st().actual_velocity
        );
        assert!(
            m.out(id).busy && m.out(id).active,
            "the same command runs on"
        );
        assert_eq!(m.refused(update(-1.0)), ErrorId::PARAMETER_NOT_CORRECT);
        // Without ContinuousUpdate the inputs are the ones of the rising edge.
        let plain = m.ok(velocity(10.0, false));
        assert!(m.out(id).command_aborted);
        let e = m.refused(CommandKind::UpdateInputs {
            target: plain,
            velocity: 30.0,
            dynamics: Dynamics::default(),
        });
        assert_eq!(e, ErrorId::COMMAND_NOT_PERMITTED);
        let e = m.refused(CommandKind::MoveAbsolute(Positioning {
            options: MoveOptions {
                continuous_update: true,
                ..MoveOptions::default()
            },
            ..mv(0.0, 10.0)
        }));
        assert_eq!(e, ErrorId::COMMAND_NOT_PERMITTED);
    }
}

/// MC_TouchProbe on an axis whose drive runs the profile: the drive's latch (0x60B8 on the
/// index pulse) records where a profile-position move passes the pulse.
#[test]
fn touch_probe_latches_in_the_drive_during_a_profile_move() {
    let mut m = Machine::new(true, 1000.0);
    m.power();
    let probe = m.ok(CommandKind::TouchProbe(TouchProbe {
        source: LatchSource::IndexPulse,
        window_only: false,
        first_position: 0.0,
        last_position: 0.0,
        modulo_positions: false,
    }));
    let id = m.ok(CommandKind::MoveAbsolute(mv(15.0, 50.0)));
    m.until(3.0, |m| m.out(probe).done || m.out(probe).error);
    assert!(m.out(probe).done, "{:?}", m.out(probe));
    // The index pulse every 10 mm: the first one passed is at 10 mm.
    assert!(
        (m.st().probe.recorded_position - 10.0).abs() < 1e-3,
        "{:?}",
        m.st().probe
    );
    m.until(3.0, |m| m.out(id).done);
}

/// The set-point handshake on a bus that answers late (2 more cycles): a move replacing one
/// whose acknowledge is still on its way is not lost (the drive must see bit 4 low before a
/// new rising edge), and the axis ends on the new target.
#[test]
fn a_move_replacing_an_unacknowledged_one_is_not_lost_on_a_late_bus() {
    let mut m = Machine::new(true, 1000.0);
    m.latency = 2;
    m.power();
    m.until(0.1, |m| m.fb.profile.mode == ProfileMode::Position);
    for _ in 0..10 {
        m.step();
    }
    let a = m.ok(CommandKind::MoveAbsolute(mv(50.0, 100.0)));
    // Until A's set point is sent (bit 4 high), then B at once.
    m.until(0.1, |m| m.emu.od.u16(0x6040, 0) & (1 << 4) != 0);
    let b = m.ok(CommandKind::MoveAbsolute(mv(-20.0, 100.0)));
    assert!(m.out(a).command_aborted);
    m.until(5.0, |m| m.out(b).done || m.out(b).error);
    assert!(m.out(b).done, "{:?}", m.out(b));
    assert!(
        (m.st().actual_position + 20.0).abs() <= 0.011,
        "{:?}",
        m.st().actual_position
    );
    assert_eq!(m.emu.od.i32(0x607A, 0), -20_000);
}

/// A move that reverses an endless motion heading for a software limit, with a deceleration
/// too weak to stop before it: the drive first brakes the motion it runs (never weaker than
/// that motion's deceleration), and the axis never passes the limit.
#[test]
fn reversing_a_velocity_with_a_weak_deceleration_stays_within_the_soft_limit() {
    let mut m = Machine::new(true, 400.0);
    m.power();
    let v = m.ok(velocity(100.0, 1000.0, Direction::Positive));
    m.until(5.0, |m| m.st().actual_position > 380.0);
    let weak = Positioning {
        dynamics: Dynamics {
            acceleration: 10.0,
            deceleration: 10.0,
            jerk: 0.0,
        },
        ..mv(0.0, 100.0)
    };
    let id = m.ok(CommandKind::MoveAbsolute(weak));
    assert!(m.out(v).command_aborted);
    let mut highest: f64 = 0.0;
    for _ in 0..3000 {
        m.step();
        highest = highest.max(m.st().actual_position);
        if m.st().actual_velocity < -1.0 || m.out(id).error {
            break;
        }
    }
    assert!(highest <= 400.0, "passed the limit: {highest}");
}

/// A stop during drive-based homing on a host-side axis: the drive brakes by itself in its
/// homing mode, and the axis goes back to CSP only once it stands — no hard stop, no lurch.
#[test]
fn a_stop_during_drive_based_homing_brakes_in_the_drive_then_returns_to_csp() {
    let mut m = Machine::new(false, 1000.0);
    m.emu.od.set(0x6098, 0, &[34]);
    m.emu.od.set(0x6099, 2, &100_000u32.to_le_bytes());
    m.power();
    let home = m.ok(CommandKind::Home {
        position: None,
        mode: HomingMode::DriveBased,
        options: HomingOptions::default(),
    });
    m.until(1.0, |m| m.st().actual_velocity > 50.0);
    let stop = m.ok(CommandKind::Stop {
        deceleration: 500.0,
        jerk: 0.0,
        options: MoveOptions::default(),
    });
    assert!(m.out(home).command_aborted);
    let mut last_v = m.st().actual_velocity;
    for _ in 0..2000 {
        m.step();
        let v = m.st().actual_velocity;
        // The homing acceleration 0x609A (1 000 mm/s² by default) per cycle at most.
        assert!(
            (v - last_v).abs() <= 1000.0 * DT * 1.5 + 0.2,
            "{last_v} → {v}"
        );
        last_v = v;
        if m.out(stop).done {
            break;
        }
    }
    assert!(m.out(stop).done, "{:?}", m.out(stop));
    m.ok(CommandKind::Release { target: stop });
    m.until(0.1, |m| m.st().state == AxisState::Standstill);
    assert_eq!(m.emu.od.i8(0x6061, 0), 8, "CSP again");
    assert!(!m.st().homed);
    let at = m.st().actual_position;
    let id = m.ok(CommandKind::MoveRelative(mv(1.0, 20.0)));
    m.until(2.0, |m| m.out(id).done);
    assert!((m.st().actual_position - at - 1.0).abs() < 0.01);
}
