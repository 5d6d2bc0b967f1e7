//! §5.7.1 MC_TorqueControl and §4.5.1 MC_Read/WriteDriveOperationMode, §4.5.7
//! MC_SelectControlLoop, cycle by cycle against the rig's plant (in torque mode a load that
//! accelerates with the torque against friction, its velocity held within the limits).

use super::*;

fn torque(torque: f64, ramp: f64, high: f64, low: f64) -> CommandKind {
    CommandKind::TorqueControl(TorqueControl {
        torque,
        torque_ramp: ramp,
        relative: false,
        velocity_limit_high: high,
        velocity_limit_low: low,
        manual_start: None,
    })
}

/// §5.7.1: the drive goes to torque mode (CST) and the torque setpoint ramps at TorqueRamp
/// from the torque the drive applied; InTorque once it stands at the setpoint with no
/// velocity limit active; the velocity stays within VelocityLimitHigh/Low, and while the
/// drive holds it there InTorque falls; the axis is in Continuous Motion with its position
/// loop open and the set position following the actual one.
#[test]
fn s5_7_1_torque_ramps_and_the_velocity_is_limited() {
    let mut r = Rig::new(1);
    power(&mut r);
    let t = r.ok(0, torque(20.0, 100.0, 400.0, -400.0));
    assert!(r.out(t).busy && r.out(t).active);
    assert_eq!(r.st(0).state, AxisState::ContinuousMotion);
    let mut last = 0.0;
    let mut cycles = 0;
    r.until(1.0, |r| {
        cycles += 1;
        let st = r.st(0);
        assert!(st.set_torque - last <= 100.0 * DT + 1e-9, "ramp exceeded");
        assert!(!st.control_loop_closed);
        assert!((st.set_position - st.actual_position).abs() < 1e-9);
        last = st.set_torque;
        r.out(t).in_torque
    });
    // 20 % at 100 %/s: 200 cycles (and the drive in torque mode).
    assert!((199..=202).contains(&cycles), "{cycles}");
    assert_eq!(r.sp[0].mode, DriveMode::Torque);
    assert_eq!(r.st(0).drive_operation_mode, DriveMode::Torque);
    // (20 − 1 friction) % × 100 u/s² per %: from 180 u/s to the limit of 400 in 0.12 s.
    let v = r.st(0).actual_velocity;
    assert!(v > 150.0 && v < 200.0, "{v}");
    r.until(1.0, |r| r.st(0).torque_velocity_limited);
    assert!(!r.out(t).in_torque, "a velocity limit is active");
    r.run(0.2);
    assert!((r.st(0).actual_velocity - 400.0).abs() < 1e-6);
    assert!(r.out(t).busy);
}

/// §5.7.1: MC_Halt and MC_Stop bring the axis back to position control — from where it is and
/// as fast as it goes, braking on their ramp — and the drive back to its position mode; a
/// new MC_TorqueControl while one runs takes over from its setpoint (Relative adds to it).
#[test]
fn s5_7_1_halt_and_stop_return_to_position_control() {
    let mut r = Rig::new(1);
    power(&mut r);
    let t = r.ok(0, torque(30.0, 1000.0, 40.0, -40.0));
    r.until(1.0, |r| r.st(0).torque_velocity_limited);
    let rel = r.ok(
        0,
        CommandKind::TorqueControl(TorqueControl {
            torque: -10.0,
            relative: true,
            ..match torque(0.0, 1000.0, 40.0, -40.0) {
                CommandKind::TorqueControl(tc) => tc,
                _ => unreachable!(),
            }
        }),
    );
    assert!(r.out(t).command_aborted);
    let cycles = r.until(1.0, |r| r.st(0).set_torque == 20.0);
    assert!(cycles <= 11, "30 → 20 at 1000 %/s: {cycles} cycles");
    let v = r.st(0).actual_velocity;
    let h = r.ok(0, halt());
    assert!(r.out(rel).command_aborted);
    assert_eq!(r.st(0).state, AxisState::DiscreteMotion);
    r.step();
    assert_ne!(r.sp[0].mode, DriveMode::Torque);
    assert!(r.st(0).control_loop_closed);
    assert!(
        (r.st(0).set_velocity - v).abs() < 2000.0 * DT + 1.0,
        "taken over at speed"
    );
    r.until(2.0, |r| r.out(h).done);
    assert_eq!(r.st(0).state, AxisState::Standstill);

    let t = r.ok(0, torque(-30.0, 1000.0, 40.0, -40.0));
    r.run(0.3);
    let s = r.ok(
        0,
        CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: MoveOptions::default(),
        },
    );
    assert!(r.out(t).command_aborted);
    r.until(2.0, |r| r.out(s).done);
    assert_ne!(r.sp[0].mode, DriveMode::Torque);
}

/// Torque control keeps within the software limits: with the limit ahead closer than the
/// axis can brake (from its velocity and the acceleration the torque gives it), it stops with
/// 0x7003 instead of running past it — harder, as an axis error, where its ramp would not end
/// inside.
#[test]
fn s5_7_torque_control_stops_before_a_software_limit() {
    let mut r = Rig::with(vec![(false, params_with_soft_limits(-1000.0, 30.0))]);
    power(&mut r);
    let t = r.ok(0, torque(50.0, 1000.0, 200.0, -200.0));
    r.until(3.0, |r| !r.out(t).busy);
    assert_eq!(r.out(t).error_id, ErrorId::SOFT_LIMIT_REACHED.0);
    // At this acceleration (5000 u/s² against a deceleration of 1000) the stop's own ramp
    // would not end inside: it stops harder, as an axis error.
    r.until(2.0, |r| {
        r.st(0).set_velocity == 0.0 && r.st(0).actual_velocity == 0.0
    });
    assert!(
        r.st(0).set_position <= 30.0 + 1e-9,
        "{}",
        r.st(0).set_position
    );
}

/// §4.5.1 MC_WriteDriveOperationMode: a position-based mode at rest, Done once the drive
/// reports it (the rig's plant reports its configured mode: Position or Configured are
/// reached, Velocity is not → 0x70B4 after 0.5 s); torque is refused (MC_TorqueControl's);
/// in motion refused. §4.5.7 MC_SelectControlLoop: loop 0 only.
#[test]
fn s4_5_1_write_drive_operation_mode_and_select_control_loop() {
    let mut r = Rig::new(1);
    power(&mut r);
    assert_eq!(
        r.rejected(
            0,
            CommandKind::WriteDriveOperationMode {
                mode: DriveMode::Torque
            }
        ),
        ErrorId::INVALID_MODE
    );
    let w = r.ok(
        0,
        CommandKind::WriteDriveOperationMode {
            mode: DriveMode::Position,
        },
    );
    r.step();
    assert!(r.out(w).done);
    assert_eq!(r.sp[0].mode, DriveMode::Position);
    let w = r.ok(
        0,
        CommandKind::WriteDriveOperationMode {
            mode: DriveMode::Velocity,
        },
    );
    let cycles = r.until(1.0, |r| !r.out(w).busy);
    assert_eq!(r.out(w).error_id, ErrorId::DRIVE_MODE_NOT_REACHED.0);
    assert!((499..=502).contains(&cycles), "{cycles}");
    r.ok(0, velocity(10.0, Direction::Positive));
    assert_eq!(
        r.rejected(
            0,
            CommandKind::WriteDriveOperationMode {
                mode: DriveMode::Configured
            }
        ),
        ErrorId::AXIS_CANNOT_BE_STARTED
    );
    r.ok(0, CommandKind::SelectControlLoop { index: 0 });
    assert_eq!(
        r.rejected(0, CommandKind::SelectControlLoop { index: 1 }),
        ErrorId::CONTROL_LOOP_UNKNOWN
    );
}

/// §5.7.1's danger note: a drive that stays in torque mode after torque control ends (here
/// one that ignores the request to go back to position mode) puts the axis in ErrorStop with
/// 0x70B4 once the timeout (0.5 s) has passed, instead of being taken as position-controlled.
#[test]
fn s5_7_1_a_drive_left_in_torque_mode_is_an_axis_error() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.plants[0].stays_in_torque = true;
    let t = r.ok(0, torque(2.0, 1000.0, 20.0, -20.0));
    r.until(1.0, |r| r.out(t).in_torque);
    r.ok(0, halt());
    let cycles = r.until(2.0, |r| r.st(0).state == AxisState::ErrorStop);
    assert_eq!(r.st(0).error_id, ErrorId::DRIVE_MODE_NOT_REACHED.0);
    assert!((500..=503).contains(&cycles), "{cycles}");
}
