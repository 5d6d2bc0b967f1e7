//! The CiA-402 drive adapter against a model of a CiA-402 device (the state machine of
//! statusword/controlword and an ideal CSP/CSV follower): enable and disable sequences, fault
//! and fault reset, scaling and the 32-bit position counter, mode checks, switches, touch
//! probe, and the kernel moving an axis through it — cycle by cycle, no network.

use drives::cia402::{
    Cia402Config, Cia402Drive, Cia402Mode, Cia402State, RxPdo, TxPdo, controlword,
};
use motion::*;

const DT: f64 = 0.001;

/// A CiA-402 device as the standard describes it, answering one cycle after the command.
#[derive(Clone, Debug)]
struct Device {
    state: Cia402State,
    position: i32,
    velocity: i32,
    mode_display: i8,
    error_code: u16,
    last_controlword: u16,
    digital_inputs: u32,
    /// A fault waiting to be raised at the next cycle.
    pending_fault: Option<u16>,
    fraction: f64,
    tp_status: u16,
    tp_pos: i32,
    tp_neg: i32,
    /// The index pulse every this many increments (for the probe).
    index_period: i64,
    /// 0x6077: in CST the target torque it was given.
    torque: i16,
}

impl Device {
    fn new(position: i32) -> Device {
        Device {
            state: Cia402State::NotReadyToSwitchOn,
            position,
            velocity: 0,
            mode_display: 0,
            error_code: 0,
            last_controlword: 0,
            digital_inputs: 0,
            pending_fault: None,
            fraction: 0.0,
            tp_status: 0,
            tp_pos: 0,
            tp_neg: 0,
            index_period: 10_000,
            torque: 0,
        }
    }

    fn statusword(&self) -> u16 {
        use Cia402State::*;
        match self.state {
            NotReadyToSwitchOn => 0x00,
            SwitchOnDisabled => 0x40,
            ReadyToSwitchOn => 0x21,
            SwitchedOn => 0x23,
            OperationEnabled => 0x27 | 0x1000,
            QuickStopActive => 0x07,
            FaultReactionActive => 0x0F,
            Fault => 0x08,
        }
    }

    fn tx(&self) -> TxPdo {
        TxPdo {
            statusword: self.statusword(),
            position_actual: self.position,
            velocity_actual: self.velocity,
            mode_display: self.mode_display,
            torque_actual: self.torque,
            error_code: self.error_code,
            digital_inputs: self.digital_inputs,
            touch_probe_status: self.tp_status,
            touch_probe_pos_edge: self.tp_pos,
            touch_probe_neg_edge: self.tp_neg,
        }
    }

    /// One cycle: the outputs arrive, the device reacts.
    fn apply(&mut self, rx: &RxPdo) {
        use Cia402State::*;
        let cw = rx.controlword;
        let rising_reset = cw & 0x80 != 0 && self.last_controlword & 0x80 == 0;
        self.last_controlword = cw;
        self.mode_display = rx.mode;
        if let Some(code) = self.pending_fault.take() {
            self.state = Fault;
            self.error_code = code;
            return;
        }
        self.state = match self.state {
            NotReadyToSwitchOn => SwitchOnDisabled,
            Fault | FaultReactionActive => {
                if rising_reset {
                    self.error_code = 0;
                    SwitchOnDisabled
                } else {
                    self.state
                }
            }
            s => {
                let disable_voltage = cw & 0x02 == 0;
                let quick_stop = cw & 0x06 == 0x02;
                let shutdown = cw & 0x87 == 0x06;
                let switch_on = cw & 0x8F == 0x07;
                let enable = cw & 0x8F == 0x0F;
                match s {
                    SwitchOnDisabled if shutdown => ReadyToSwitchOn,
                    ReadyToSwitchOn if switch_on => SwitchedOn,
                    ReadyToSwitchOn if disable_voltage => SwitchOnDisabled,
                    SwitchedOn if enable => OperationEnabled,
                    SwitchedOn if shutdown => ReadyToSwitchOn,
                    SwitchedOn if disable_voltage => SwitchOnDisabled,
                    OperationEnabled if quick_stop => QuickStopActive,
                    OperationEnabled if shutdown => ReadyToSwitchOn,
                    OperationEnabled if switch_on => SwitchedOn,
                    OperationEnabled if disable_voltage => SwitchOnDisabled,
                    QuickStopActive if disable_voltage => SwitchOnDisabled,
                    s => s,
                }
            }
        };
        let before = self.position;
        if self.state == OperationEnabled {
            match rx.mode {
                8 => {
                    let step = rx.target_position.wrapping_sub(self.position) as i64;
                    self.velocity = (step * 1000).clamp(i32::MIN as i64, i32::MAX as i64) as i32;
                    self.position = rx.target_position;
                }
                9 => {
                    // Integrates the velocity with the fraction of an increment carried on.
                    self.velocity = rx.target_velocity;
                    self.fraction += rx.target_velocity as f64 * DT;
                    let whole = self.fraction.trunc();
                    self.fraction -= whole;
                    self.position = self.position.wrapping_add(whole as i32);
                }
                10 => self.torque = rx.target_torque,
                _ => {}
            }
        } else {
            self.velocity = 0;
        }
        // Touch probe 1: armed by a rising enable bit, stores the first edge.
        if rx.touch_probe_function & 1 == 0 {
            self.tp_status = 0;
        } else if self.tp_status & 1 == 0 {
            self.tp_status = 1;
        } else if self.tp_status & 0b110 == 0
            && rx.touch_probe_function & (1 << 2) != 0
            && rx.touch_probe_function & (1 << 4) != 0
        {
            // The index pulse between the last position and this one.
            let (a, b) = (before as i64, self.position as i64);
            let (lo, hi) = (a.min(b), a.max(b));
            let k = (lo + 1).div_euclid(self.index_period) * self.index_period;
            let k = if k < lo + 1 { k + self.index_period } else { k };
            if k <= hi && a != b {
                self.tp_status |= 0b10;
                self.tp_pos = k as i32;
            }
        }
    }
}

fn config() -> Cia402Config {
    Cia402Config::csp(0, 1000.0)
}

fn enable() -> DriveSetpoint {
    DriveSetpoint {
        enable: true,
        ..DriveSetpoint::default()
    }
}

/// One cycle as a bus runs it: the kernel's setpoint out, the device's answer back in.
fn cycle(drive: &mut Cia402Drive, device: &mut Device, sp: &DriveSetpoint) -> DriveFeedback {
    let rx = drive.outputs(sp);
    device.apply(&rx);
    drive.feedback(&device.tx())
}

#[test]
fn mc_power_walks_the_state_machine_to_operation_enabled_and_back() {
    let mut device = Device::new(123_456);
    let mut drive = Cia402Drive::new(config());
    let fb = drive.feedback(&device.tx());
    assert!(!fb.ready && !fb.enabled, "not ready to switch on: {fb:?}");
    assert_eq!(fb.actual_position, 123.456);
    // Disabled: the drive is asked for nothing, and to stay where it is.
    let rx = drive.outputs(&DriveSetpoint::default());
    assert_eq!(rx.controlword, controlword::DISABLE_VOLTAGE);
    assert_eq!(rx.target_position, 123_456);
    assert_eq!(rx.mode, 8);
    let mut seen = Vec::new();
    let mut enabled_at = None;
    for k in 0..10 {
        let sp = DriveSetpoint {
            position: 0.0, // a stale setpoint must not make it jump
            ..enable()
        };
        let rx = drive.outputs(&sp);
        seen.push(rx.controlword);
        assert_eq!(
            rx.target_position, 123_456,
            "cycle {k}: the drive must stay"
        );
        device.apply(&rx);
        let fb = drive.feedback(&device.tx());
        if fb.enabled {
            enabled_at = Some(k);
            break;
        }
    }
    // Disable voltage (not ready yet) → shutdown → switch on → enable operation.
    assert_eq!(seen, [0x00, 0x06, 0x07, 0x0F]);
    assert_eq!(enabled_at, Some(3));
    assert_eq!(device.state, Cia402State::OperationEnabled);
    // Enabled, it follows the setpoint in increments.
    let fb = cycle(
        &mut drive,
        &mut device,
        &DriveSetpoint {
            position: 123.5,
            ..enable()
        },
    );
    assert_eq!(device.position, 123_500);
    assert_eq!(fb.actual_position, 123.5);
    // MC_Power off: shutdown, the power stage goes off (ready to switch on).
    let fb = cycle(&mut drive, &mut device, &DriveSetpoint::default());
    assert_eq!(device.last_controlword, controlword::SHUTDOWN);
    assert_eq!(device.state, Cia402State::ReadyToSwitchOn);
    assert!(fb.ready && !fb.enabled);
}

#[test]
fn a_drive_fault_reports_its_error_code_until_a_reset_edge() {
    let mut device = Device::new(0);
    let mut drive = Cia402Drive::new(config());
    drive.feedback(&device.tx());
    for _ in 0..5 {
        cycle(&mut drive, &mut device, &enable());
    }
    assert_eq!(device.state, Cia402State::OperationEnabled);
    device.pending_fault = Some(0x2310);
    let fb = cycle(&mut drive, &mut device, &enable());
    assert!(fb.fault && !fb.ready && !fb.enabled, "{fb:?}");
    assert_eq!(fb.fault_code, 0x2310);
    // No reset asked: the fault stays, whatever MC_Power wants.
    for _ in 0..3 {
        let fb = cycle(&mut drive, &mut device, &enable());
        assert!(fb.fault);
        assert_eq!(device.last_controlword, controlword::DISABLE_VOLTAGE);
    }
    // The kernel's fault-reset edge: controlword bit 7 rises, the device clears.
    let fb = cycle(
        &mut drive,
        &mut device,
        &DriveSetpoint {
            fault_reset: true,
            ..DriveSetpoint::default()
        },
    );
    assert_eq!(device.last_controlword, controlword::FAULT_RESET);
    assert!(!fb.fault && fb.ready && fb.fault_code == 0, "{fb:?}");
    // And it can be enabled again.
    let mut enabled = false;
    for _ in 0..5 {
        enabled = cycle(&mut drive, &mut device, &enable()).enabled;
    }
    assert!(enabled);
}

#[test]
fn the_position_counter_is_unwrapped_across_its_32_bit_range() {
    let mut device = Device::new(i32::MAX - 5_000);
    let mut drive = Cia402Drive::new(config());
    drive.feedback(&device.tx());
    for _ in 0..5 {
        cycle(&mut drive, &mut device, &enable());
    }
    let start = (i32::MAX - 5_000) as f64 / 1000.0;
    let mut last = start;
    // 20 mm forward in 1 mm steps: the device's counter wraps to negative on the way.
    for k in 1..=20 {
        let fb = cycle(
            &mut drive,
            &mut device,
            &DriveSetpoint {
                position: start + k as f64,
                ..enable()
            },
        );
        assert!(
            (fb.actual_position - (start + k as f64)).abs() < 1e-6,
            "{fb:?}"
        );
        assert!(fb.actual_position > last);
        last = fb.actual_position;
    }
    assert!(device.position < 0, "the device's counter wrapped");
}

#[test]
fn a_drive_in_another_mode_is_not_taken_as_following() {
    let mut device = Device::new(1_000);
    let mut drive = Cia402Drive::new(config());
    drive.feedback(&device.tx());
    for _ in 0..5 {
        let here = DriveSetpoint {
            position: 1.0,
            ..enable()
        };
        cycle(&mut drive, &mut device, &here);
    }
    assert_eq!(device.position, 1_000);
    // The drive reports CST (10), e.g. left so after torque mode: a mode we run drives in,
    // so it counts as enabled (a mode switch is on the fly), but until it is back in CSP it
    // is held where it is, and CSP is asked for again.
    device.mode_display = 10;
    let fb = drive.feedback(&device.tx());
    assert!(fb.enabled, "{fb:?}");
    assert_eq!(fb.mode, DriveMode::Torque);
    let rx = drive.outputs(&DriveSetpoint {
        position: 50.0,
        ..enable()
    });
    assert_eq!(rx.target_position, 1_000, "held where it is");
    assert_eq!(rx.target_torque, 0);
    assert_eq!(rx.mode, 8, "CSP asked for again");
    // A mode the drive is never run in (velocity mode, 2) is not taken as enabled.
    device.mode_display = 2;
    assert!(!drive.feedback(&device.tx()).enabled);
}

/// MC_TorqueControl on a CiA-402 drive: CST (10) is asked for; while the drive still shows
/// CSP it is held (torque 0); in CST the target torque is the setpoint in per mille; beyond
/// the high velocity limit the velocity loop's torque towards the limit takes over and the
/// feedback says the velocity is limited; 0x6077 is the actual torque. MC_WriteDriveOperation-
/// Mode Velo1 asks for CSV (9).
#[test]
fn torque_control_runs_the_drive_in_cst_within_its_velocity_limits() {
    let mut device = Device::new(0);
    let mut drive = Cia402Drive::new(Cia402Config {
        velocity_gain: 10.0,
        ..config()
    });
    drive.feedback(&device.tx());
    for _ in 0..5 {
        cycle(&mut drive, &mut device, &enable());
    }
    assert_eq!(device.mode_display, 8);
    let torque = DriveSetpoint {
        mode: DriveMode::Torque,
        torque: 12.5,
        velocity_limit_high: 100.0,
        velocity_limit_low: -100.0,
        ..enable()
    };
    let rx = drive.outputs(&torque);
    assert_eq!(
        (rx.mode, rx.target_torque),
        (10, 0),
        "held until the drive shows CST"
    );
    device.apply(&rx);
    let fb = drive.feedback(&device.tx());
    assert!(fb.enabled && fb.mode == DriveMode::Torque, "{fb:?}");
    let rx = drive.outputs(&torque);
    assert_eq!(rx.target_torque, 125);
    device.apply(&rx);
    assert_eq!(drive.feedback(&device.tx()).actual_torque, 12.5);
    // 110 mm/s against a limit of 100: 10 × (100 − 110) = −100 ‰ instead of 125.
    device.velocity = 110_000;
    drive.feedback(&device.tx());
    let rx = drive.outputs(&torque);
    assert_eq!(rx.target_torque, -100);
    device.apply(&rx);
    assert!(drive.feedback(&device.tx()).velocity_limited);
    let rx = drive.outputs(&DriveSetpoint {
        mode: DriveMode::Velocity,
        ..enable()
    });
    assert_eq!(rx.mode, 9);
}

#[test]
fn csv_closes_the_position_loop_on_our_side() {
    let mut device = Device::new(0);
    let mut drive = Cia402Drive::new(Cia402Config {
        mode: Cia402Mode::Csv,
        position_gain: 100.0,
        ..config()
    });
    drive.feedback(&device.tx());
    for _ in 0..5 {
        cycle(&mut drive, &mut device, &enable());
    }
    assert_eq!(device.mode_display, 9);
    let rx = drive.outputs(&DriveSetpoint {
        position: 1.0,
        velocity: 20.0,
        ..enable()
    });
    // 20 mm/s feed-forward + 100/s × 1 mm lag = 120 mm/s = 120 000 increments/s.
    assert_eq!(rx.target_velocity, 120_000);
    for _ in 0..500 {
        cycle(
            &mut drive,
            &mut device,
            &DriveSetpoint {
                position: 1.0,
                ..enable()
            },
        );
    }
    assert!((device.position - 1_000).abs() <= 1, "{}", device.position);
}

#[test]
fn switches_and_the_touch_probe_reach_the_kernel() {
    let mut device = Device::new(0);
    let mut drive = Cia402Drive::new(config());
    device.digital_inputs = 0b101; // negative limit and home switch
    let fb = drive.feedback(&device.tx());
    assert!(fb.limit_negative && fb.reference_cam && !fb.limit_positive);
    device.digital_inputs = 0b010;
    let fb = drive.feedback(&device.tx());
    assert!(fb.limit_positive && !fb.reference_cam && !fb.limit_negative);
    device.digital_inputs = 0;
    for _ in 0..5 {
        cycle(&mut drive, &mut device, &enable());
    }
    // Arm the probe on the index pulse (every 10 000 increments = 10 mm) and move past one.
    let armed = DriveSetpoint {
        latch_enable: true,
        latch_source: LatchSource::IndexPulse,
        ..enable()
    };
    assert_eq!(drive.outputs(&armed).touch_probe_function, 0b1_0101);
    let mut latched = None;
    for k in 1..=150 {
        let fb = cycle(
            &mut drive,
            &mut device,
            &DriveSetpoint {
                position: k as f64 * 0.1,
                ..armed
            },
        );
        if fb.latch_valid {
            latched = Some(fb.latch_position);
            break;
        }
    }
    assert_eq!(latched, Some(10.0));
    // Disarmed: nothing latched.
    let fb = cycle(&mut drive, &mut device, &enable());
    assert!(!fb.latch_valid);
    let rising = DriveSetpoint {
        latch_source: LatchSource::CamRising,
        ..armed
    };
    assert_eq!(drive.outputs(&rising).touch_probe_function, 0b1_0001);
    let falling = DriveSetpoint {
        latch_source: LatchSource::CamFalling,
        ..armed
    };
    assert_eq!(drive.outputs(&falling).touch_probe_function, 0b10_0001);
}

#[test]
fn the_kernel_powers_and_moves_an_axis_through_the_cia402_drive() {
    let mut k = Kernel::new(DT, 1);
    k.insert_axis(
        0,
        Axis::new(
            AxisConfig {
                modulo: false,
                parameters: AxisParameters::default(),
                compensation_table: None,
                drive_executed: false,
            },
            DT,
        ),
    )
    .unwrap();
    let mut device = Device::new(-42_000);
    let mut drive = Cia402Drive::new(config());
    let mut events = Vec::new();
    let mut sp = [DriveSetpoint::default()];
    let mut fb = [drive.feedback(&device.tx())];
    let mut step = |k: &mut Kernel, events: &mut Vec<CommandEvent>| {
        k.step(&fb, &mut sp, events);
        let rx = drive.outputs(&sp[0]);
        device.apply(&rx);
        fb[0] = drive.feedback(&device.tx());
    };
    let power = Command {
        id: 1,
        target: Target::Axis(0),
        kind: CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
            buffer_mode: motion::BufferMode::Aborting,
        },
    };
    assert_eq!(k.submit(power, &mut events), Verdict::Accepted);
    for _ in 0..50 {
        step(&mut k, &mut events);
    }
    let s = k.status(0).unwrap();
    assert_eq!(s.state, AxisState::Standstill, "{s:?}");
    assert_eq!(s.actual_position, -42.0);
    let mv = Command {
        id: 2,
        target: Target::Axis(0),
        kind: CommandKind::MoveAbsolute(Positioning {
            position: 10.0,
            velocity: 100.0,
            dynamics: Dynamics::default(),
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        }),
    };
    assert_eq!(k.submit(mv, &mut events), Verdict::Accepted);
    let mut done = false;
    for _ in 0..5000 {
        step(&mut k, &mut events);
        if events.iter().any(|e| e.command == 2 && e.outputs.done) {
            done = true;
            break;
        }
    }
    assert!(done, "{:?}", k.status(0));
    assert_eq!(device.position, 10_000);
    assert_eq!(k.status(0).unwrap().actual_position, 10.0);
}

/// A drive samples the controlword at its SYNC0: MC_Reset's one-cycle edge is held as a fault
/// reset (bit 7) for some cycles while the drive still reports the fault, then released (a
/// later reset makes a new rising edge); it ends as soon as the drive leaves the fault.
#[test]
fn a_fault_reset_is_held_until_the_drive_leaves_the_fault() {
    let mut drive = Cia402Drive::new(config());
    // The drive reports a fault (statusword 0x0008).
    drive.feedback(&TxPdo {
        statusword: 0x0008,
        error_code: 0x2310,
        mode_display: 8,
        ..TxPdo::default()
    });
    let reset = DriveSetpoint {
        fault_reset: true,
        ..DriveSetpoint::default()
    };
    assert_eq!(drive.outputs(&reset).controlword, controlword::FAULT_RESET);
    let held = (0..40)
        .take_while(|_| {
            drive.outputs(&DriveSetpoint::default()).controlword == controlword::FAULT_RESET
        })
        .count();
    assert!((8..=20).contains(&held), "held {held} more cycles");
    assert_eq!(
        drive.outputs(&DriveSetpoint::default()).controlword,
        controlword::DISABLE_VOLTAGE,
        "then released"
    );
    // A new reset; the drive leaves the fault at once: the hold ends with it.
    assert_eq!(drive.outputs(&reset).controlword, controlword::FAULT_RESET);
    drive.feedback(&TxPdo {
        statusword: 0x0040,
        mode_display: 8,
        ..TxPdo::default()
    });
    assert_eq!(
        drive.outputs(&DriveSetpoint::default()).controlword,
        controlword::DISABLE_VOLTAGE
    );
    drive.feedback(&TxPdo {
        statusword: 0x0008,
        mode_display: 8,
        ..TxPdo::default()
    });
    assert_eq!(
        drive.outputs(&DriveSetpoint::default()).controlword,
        controlword::DISABLE_VOLTAGE,
        "a new fault needs a new reset"
    );
}
