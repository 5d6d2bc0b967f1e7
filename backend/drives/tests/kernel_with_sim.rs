//! The kernel against the real simulated servo drive (default PT2 plant with dead time): the
//! behaviour that depends on a lagging drive — target window and done, the referencing
//! sequence against the cam and index pulse with a real latch, following-error and drive
//! faults — works end to end, cycle by cycle in virtual time.

use drives::sim::{SimDrive, SimDriveConfig, SimFault};
use motion::*;

const DT: f64 = 0.001;

struct Machine {
    k: Kernel,
    drive: SimDrive,
    sp: [DriveSetpoint; 1],
    events: Vec<CommandEvent>,
    next_id: CommandId,
}

impl Machine {
    fn new(config: SimDriveConfig) -> Machine {
        let mut k = Kernel::new(DT, 1);
        let p = AxisParameters {
            axis_target_position_window: 0.02,
            axis_target_position_monitoring_time: 0.01,
            ..Default::default()
        };
        k.insert_axis(
            0,
            Axis::new(
                AxisConfig {
                    modulo: false,
                    parameters: p,
                    compensation_table: None,
                    drive_executed: false,
                },
                DT,
            ),
        )
        .unwrap();
        Machine {
            k,
            drive: SimDrive::new(config, DT),
            sp: [DriveSetpoint::default()],
            events: Vec::new(),
            next_id: 1,
        }
    }

    fn cmd(&mut self, kind: CommandKind) -> (CommandId, Verdict) {
        let id = self.next_id;
        self.next_id += 1;
        (
            id,
            self.k.submit(
                Command {
                    id,
                    target: Target::Axis(0),
                    kind,
                },
                &mut self.events,
            ),
        )
    }

    fn ok(&mut self, kind: CommandKind) -> CommandId {
        let (id, v) = self.cmd(kind);
        assert_eq!(v, Verdict::Accepted, "{kind:?}");
        id
    }

    fn step(&mut self) {
        let fb = [self.drive.feedback()];
        self.k.step(&fb, &mut self.sp, &mut self.events);
        self.drive.apply(&self.sp[0]);
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

    fn until(&mut self, seconds: f64, f: impl Fn(&Machine) -> bool) {
        for _ in 0..(seconds / DT) as usize {
            if f(self) {
                return;
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
            buffer_mode: motion::BufferMode::Aborting,
        });
        self.until(0.5, |m| m.st().state == AxisState::Standstill);
    }
}

fn mv(position: f64, velocity: f64) -> Positioning {
    Positioning {
        position,
        velocity,
        dynamics: Dynamics::default(),
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    }
}

#[test]
fn move_is_done_only_when_the_lagging_drive_is_in_the_target_window() {
    let mut m = Machine::new(SimDriveConfig::default());
    m.power();
    let a = m.ok(CommandKind::MoveAbsolute(mv(200.0, 500.0)));
    let max_lag = std::cell::Cell::new(0.0f64);
    let ended_at = std::cell::Cell::new(None);
    m.until(3.0, |m| {
        let s = m.st();
        max_lag.set(max_lag.get().max(s.following_error.abs()));
        if ended_at.get().is_none() && !s.moving && s.set_position == 200.0 {
            ended_at.set(Some(m.k.cycle()));
        }
        m.out(a).done
    });
    let s = m.st();
    assert!((s.actual_position - 200.0).abs() <= 0.02, "{s:?}");
    assert_eq!(s.state, AxisState::Standstill);
    // The drive lags (PT2 + dead time) but follows within a fraction of a millimetre …
    assert!(
        max_lag.get() > 1e-4 && max_lag.get() < 0.5,
        "max lag {}",
        max_lag.get()
    );
    // … and Done waited for the window dwell (10 ms; the cycle the setpoint arrives in counts
    // as its first) after the setpoint had arrived.
    let dwell = m.k.cycle() - ended_at.get().unwrap();
    assert!(dwell >= 9, "done {dwell} cycles after the setpoint stopped");
}

#[test]
fn referencing_sequence_latches_the_index_pulse_of_the_simulated_encoder() {
    // Default sim drive: cam 20–25, index pulse every 10. From 0 the search runs positive
    // onto the cam, stops, leaves it positive (an undefined SyncDirection is positive,
    // ST_HomingOptions); after the falling edge (at 25) the next index pulse is at 30: that
    // drive position becomes the reference 100.
    let mut m = Machine::new(SimDriveConfig::default());
    m.power();
    let h = m.ok(CommandKind::Home {
        position: Some(100.0),
        mode: HomingMode::Default,
        options: HomingOptions::default(),
    });
    m.until(20.0, |m| !m.out(h).busy);
    assert!(m.out(h).done, "{:?}", m.out(h));
    for _ in 0..50 {
        m.step();
    }
    let s = m.st();
    assert!(s.homed);
    let drive_pos = m.drive.feedback().actual_position;
    assert!(
        (s.actual_position - (100.0 + (drive_pos - 30.0))).abs() < 1e-6,
        "axis {} drive {}",
        s.actual_position,
        drive_pos
    );
}

#[test]
fn a_load_the_drive_cannot_hold_trips_following_error_monitoring() {
    let mut m = Machine::new(SimDriveConfig::default());
    m.power();
    let a = m.ok(CommandKind::MoveVelocity {
        velocity: 50.0,
        dynamics: Dynamics::default(),
        direction: Direction::Positive,
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    });
    m.until(1.0, |m| m.out(a).in_velocity);
    // Default max lag 5 mm, stiffness 1000: a force of 8000 gives 8 mm of lag.
    m.drive.inject(SimFault::Load { force: 8000.0 });
    m.until(1.0, |m| m.st().state == AxisState::ErrorStop);
    assert_eq!(m.st().error_id, ErrorId::FOLLOWING_ERROR.0);
    assert_eq!(m.out(a).error_id, ErrorId::FOLLOWING_ERROR.0);
    m.drive.inject(SimFault::Load { force: 0.0 });
    // The axis brakes on its fast-stop ramp with the drive still enabled (TwinCAT would
    // switch it off and let the load coast).
    m.until(1.0, |m| {
        assert!(m.st().power_status, "drive disabled while braking");
        !m.st().moving
    });
    assert!(m.st().power_status);
    m.ok(CommandKind::Reset);
    m.until(0.5, |m| m.st().state == AxisState::Standstill);
}

#[test]
fn a_drive_fault_is_an_axis_error_until_cleared_and_reset() {
    let mut m = Machine::new(SimDriveConfig::default());
    m.power();
    m.drive.inject(SimFault::DriveFault { code: 0x2310 });
    m.until(0.1, |m| m.st().state == AxisState::ErrorStop);
    assert_eq!(m.st().error_id, ErrorId::DRIVE_FAULT.0);
    assert!(m.st().drive_fault);
    // While the cause persists, a reset does not bring the axis back.
    m.ok(CommandKind::Reset);
    m.until(0.1, |m| m.st().state == AxisState::ErrorStop);
    for _ in 0..50 {
        m.step();
    }
    assert_eq!(m.st().state, AxisState::ErrorStop);
    m.drive.inject(SimFault::Clear);
    m.ok(CommandKind::Reset);
    m.until(0.5, |m| m.st().state == AxisState::Standstill);
}
