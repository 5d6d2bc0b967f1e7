//! §2 The axis state diagram: states, notes 1–6, state changes in the cycle a command is
//! accepted (§11a items 1–6).

use super::*;

#[test]
fn s11a_01_fresh_axis_is_disabled_and_rejects_moves() {
    let mut r = Rig::new(1);
    r.step();
    assert_eq!(r.st(0).state, AxisState::Disabled);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(10.0, 100.0))),
        ErrorId::AXIS_CANNOT_BE_STARTED
    );
    r.run(0.05);
    assert_eq!(r.st(0).set_position, 0.0);
    assert_eq!(r.plants[0].pos, 0.0);
}

#[test]
fn s11a_02_power_enable_goes_to_standstill_with_status_or_errorstop_with_error() {
    let mut r = Rig::new(1);
    let p = r.ok(0, power_with_override(100.0));
    assert!(r.out(p).busy && !r.out(p).status);
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
    assert!(r.out(p).status && r.out(p).busy && r.out(p).active);
    assert!(r.st(0).power_status);

    // With a drive fault pending: ErrorStop.
    let mut r = Rig::new(1);
    r.plants[0].fault = true;
    r.ok(0, power_with_override(100.0));
    r.step();
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    assert_eq!(r.st(0).error_id, ErrorId::DRIVE_FAULT.0);
}

#[test]
fn s11a_03_power_off_from_motion_disables_and_aborts() {
    let mut r = Rig::new(1);
    power(&mut r);
    let m = r.ok(0, velocity(100.0, Direction::Positive));
    r.run(0.1);
    r.ok(
        0,
        CommandKind::Power {
            enable: false,
            enable_positive: false,
            enable_negative: false,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        },
    );
    assert_eq!(r.st(0).state, AxisState::Disabled);
    assert!(r.out(m).command_aborted);
    r.step();
    assert!(!r.sp[0].enable);
}

#[test]
fn s11a_04_errorstop_rejects_everything_until_reset() {
    let mut r = Rig::new(1);
    let p = power(&mut r);
    r.plants[0].fault = true;
    r.plants[0].fault_code = 7;
    r.step();
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    for k in [
        CommandKind::MoveAbsolute(mv(1.0, 10.0)),
        CommandKind::Home {
            position: None,
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
        CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: MoveOptions::default(),
        },
    ] {
        assert_eq!(r.rejected(0, k), ErrorId::AXIS_CANNOT_BE_STARTED);
    }
    // Reset with power still enabled → Standstill (note 4) once the drive recovers.
    r.ok(0, CommandKind::Reset);
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
    assert!(r.out(p).status);
    // Reset with power off → Disabled (note 3).
    r.plants[0].fault = true;
    r.step();
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    r.ok(
        0,
        CommandKind::Power {
            enable: false,
            enable_positive: false,
            enable_negative: false,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        },
    );
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    r.ok(0, CommandKind::Reset);
    assert_eq!(r.st(0).state, AxisState::Disabled);
}

#[test]
fn s11a_05_state_changes_in_the_cycle_the_command_is_accepted() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    assert_eq!(r.st(0).state, AxisState::DiscreteMotion);
    r.ok(0, velocity(10.0, Direction::Positive));
    assert_eq!(r.st(0).state, AxisState::ContinuousMotion);
    r.ok(
        0,
        CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: MoveOptions::default(),
        },
    );
    assert_eq!(r.st(0).state, AxisState::Stopping);
}

#[test]
fn s11a_06_parameter_writes_do_not_change_the_state() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(
        0,
        CommandKind::WriteParameter {
            number: 1026,
            value: 0.05,
        },
    );
    assert_eq!(r.st(0).state, AxisState::Standstill);
    r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    r.ok(
        0,
        CommandKind::WriteParameter {
            number: 1026,
            value: 0.02,
        },
    );
    assert_eq!(r.st(0).state, AxisState::DiscreteMotion);
}

/// A bus that loses its drive (lost frames, working counters, a SubDevice out of OP) stops the
/// axis into ErrorStop with 0x70A0 on the error ramp — the drive is still enabled and follows
/// what reaches it, so the set velocity falls continuously instead of the power being cut — and
/// a reset clears it only once the bus has the drive again (decision 104).
#[test]
fn a_bus_error_stops_on_the_ramp_into_errorstop_and_reset_needs_the_bus_back() {
    let mut r = Rig::new(1);
    let p = power(&mut r);
    r.ok(0, velocity(100.0, Direction::Positive));
    r.run(0.2);
    let v0 = r.st(0).set_velocity;
    assert!(v0 > 99.0, "{v0}");
    r.plants[0].bus_error = true;
    r.step();
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    assert_eq!(r.st(0).error_id, ErrorId::BUS_ERROR.0);
    assert!(!r.st(0).drive_fault, "not a drive fault");
    assert!(r.sp[0].enable, "the drive stays enabled for the ramp");
    let mut last = r.st(0).set_velocity;
    assert!(last > 0.0 && last < v0, "the ramp starts: {last}");
    let mut cycles = 0;
    while r.st(0).set_velocity > 0.0 {
        r.step();
        let v = r.st(0).set_velocity;
        assert!(v <= last, "never faster again: {v} after {last}");
        last = v;
        cycles += 1;
        assert!(cycles < 10_000, "stands");
    }
    assert!(cycles > 5, "a ramp, not a cut: {cycles} cycles");
    // Reset while the bus still lacks the drive: the power status is false, so the axis is
    // Disabled (PLCopen's reset without power), and MC_Power, still enabled, waits for the drive.
    r.ok(0, CommandKind::Reset);
    r.run(0.05);
    assert_eq!(r.st(0).state, AxisState::Disabled);
    assert!(!r.st(0).power_status);
    assert!(r.out(p).busy && !r.out(p).status && !r.out(p).error);
    // The bus has the drive again: MC_Power's enable brings the axis up where it stands.
    r.plants[0].bus_error = false;
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
    assert!(r.out(p).status);
    // A power-on while the bus lacks the drive waits for it instead of failing at once.
    let mut r = Rig::new(1);
    r.plants[0].bus_error = true;
    let p = r.ok(0, power_with_override(100.0));
    r.run(0.1);
    assert_eq!(r.st(0).state, AxisState::Disabled);
    assert!(r.out(p).busy && !r.out(p).error);
    r.plants[0].bus_error = false;
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
}
