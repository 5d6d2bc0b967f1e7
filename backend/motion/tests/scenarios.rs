//! Scenario tests in virtual time. Test names carry the spec §11a item they cover
//! (`s11a_NN_…`); every cycle of every test also runs the rig's invariant checks. Item 32
//! (parameters by number, aliases) is in `tests/params.rs`; item 33 (persistent writes survive
//! a restart) has no kernel meaning — persistence is the server's.

mod rig;

use motion::*;
use rig::*;

fn power(r: &mut Rig) -> CommandId {
    r.power_on(0)
}

// ---------------------------------------------------------------- state machine & power

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
    let p = r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
        },
    );
    assert!(r.out(p).busy && !r.out(p).status);
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
    assert!(r.out(p).status && r.out(p).busy && r.out(p).active);
    assert!(r.st(0).power_status);

    // With a drive fault pending: ErrorStop.
    let mut r = Rig::new(1);
    r.plants[0].fault = true;
    r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
        },
    );
    r.step();
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    assert_eq!(r.st(0).error_id, ErrorId::DRIVE_FAULT.0);
}

#[test]
fn s11a_03_power_off_from_motion_disables_and_aborts() {
    let mut r = Rig::new(1);
    power(&mut r);
    let m = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 100.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(0.1);
    r.ok(
        0,
        CommandKind::Power {
            enable: false,
            enable_positive: false,
            enable_negative: false,
            override_percent: 100.0,
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
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 10.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
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

/// MC_WriteParameter is checked by the kernel with the parameter table (params.rs), whoever
/// submits it: unknown and read-only numbers, NaN, ±∞, values out of range, a BOOL other than
/// 0/1, a fractional DWORD, and a write that breaks the relations of a consistent set are
/// refused with their error numbers and change nothing (the rig checks that a rejected
/// command changes nothing and emits nothing).
#[test]
fn write_parameter_is_validated_by_the_kernel() {
    let mut r = Rig::new(1);
    power(&mut r);
    let before = r.k.parameters(0).unwrap().clone();
    let write = |number: u16, value: f64| CommandKind::WriteParameter { number, value };
    for (number, value, error) in [
        (999, 1.0, ErrorId::PARAMETER_UNKNOWN),
        (5000, 1.0, ErrorId::PARAMETER_UNKNOWN),
        (1, 5.0, ErrorId::PARAMETER_READ_ONLY),
        (2000, 5.0, ErrorId::PARAMETER_READ_ONLY),
        (1000, 7.0, ErrorId::PARAMETER_READ_ONLY),
        (1050, 0.002, ErrorId::PARAMETER_READ_ONLY),
        (4000, 0.002, ErrorId::PARAMETER_READ_ONLY),
        (1003, f64::NAN, ErrorId::PARAMETER_OUT_OF_RANGE),
        (1003, f64::INFINITY, ErrorId::PARAMETER_OUT_OF_RANGE),
        (1003, 0.0, ErrorId::PARAMETER_OUT_OF_RANGE),
        (1003, -500.0, ErrorId::PARAMETER_OUT_OF_RANGE),
        (1026, -0.1, ErrorId::PARAMETER_OUT_OF_RANGE),
        (1018, 0.5, ErrorId::PARAMETER_OUT_OF_RANGE),
        (1018, f64::NAN, ErrorId::PARAMETER_OUT_OF_RANGE),
        (1062, 2.0, ErrorId::PARAMETER_OUT_OF_RANGE),
        (1062, 0.5, ErrorId::COMMAND_NOT_PERMITTED),
        // Relations: AxisAcc above AxisMaximumAcceleration (5000), a jog velocity above
        // AxisVeloMax (500), the soft limits crossed while both are enabled.
        (1004, 6000.0, ErrorId::PARAMETER_OUT_OF_RANGE),
        (1001, 600.0, ErrorId::PARAMETER_OUT_OF_RANGE),
        (1003, 1.0, ErrorId::PARAMETER_OUT_OF_RANGE),
    ] {
        assert_eq!(
            r.rejected(0, write(number, value)),
            error,
            "#{number} = {value}"
        );
        assert_eq!(r.k.parameters(0).unwrap(), &before, "#{number} = {value}");
    }
    // 3000 (AxisGearRatio) is read-only (MC_GearInDyn changes a ratio, acceleration-limited).
    assert_eq!(
        r.rejected(0, write(3000, 2.0)),
        ErrorId::PARAMETER_READ_ONLY
    );
    // Valid writes, BOOL as 0/1, aliases (#2 = #1019) share their storage.
    // AxisVeloMax below the rapid traverse velocity (500) breaks a relation: lower that first.
    assert_eq!(
        r.rejected(0, write(1003, 400.0)),
        ErrorId::PARAMETER_OUT_OF_RANGE
    );
    r.ok(0, write(1009, 300.0));
    r.ok(0, write(1003, 400.0));
    r.ok(0, write(1018, 1.0));
    r.ok(0, write(2, 50.0));
    let p = r.k.parameters(0).unwrap();
    assert_eq!(p.axis_velo_max, 400.0);
    assert!(p.axis_en_max_soft_pos_limit);
    assert_eq!(p.axis_max_soft_pos_limit, 50.0);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(60.0, 100.0))),
        ErrorId::TARGET_ABOVE_SOFT_LIMIT
    );
    r.ok(0, write(1016, 1.0));
    r.ok(0, write(1017, -50.0));
    assert_eq!(
        r.rejected(0, write(1017, 50.0)),
        ErrorId::PARAMETER_OUT_OF_RANGE,
        "min limit not below max"
    );
}

// ---------------------------------------------------------------- FB protocol

#[test]
fn s11a_07_busy_with_acceptance_and_exactly_one_outcome() {
    let mut r = Rig::new(1);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(20.0, 200.0)));
    assert!(r.out(a).busy && r.out(a).active);
    r.until(1.0, |r| !r.out(a).busy);
    let o = r.out(a);
    assert!(o.done && !o.error && !o.command_aborted);
}

#[test]
fn s11a_08_09_inputs_latched_a_new_command_is_a_new_instance() {
    // Over the API a second POST is a second FB instance; the first one's target is latched.
    let mut r = Rig::new(1);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(20.0, 200.0)));
    r.run(0.05);
    let b = r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(30.0, 200.0, BufferMode::Buffered)),
    );
    r.until(2.0, |r| r.out(b).done);
    assert!(r.out(a).done);
    assert!((r.st(0).set_position - 30.0).abs() < 1e-9);
}

#[test]
fn s11a_10_interrupted_move_reports_aborted_never_done() {
    let mut r = Rig::new(1);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 200.0)));
    r.run(0.1);
    let b = r.ok(0, CommandKind::MoveAbsolute(mv(-10.0, 200.0)));
    let o = r.out(a);
    assert!(o.command_aborted && !o.done && !o.busy && !o.active);
    r.until(3.0, |r| r.out(b).done);
    assert!(!r.out(a).done);
    assert!((r.st(0).set_position + 10.0).abs() < 1e-9);
}

#[test]
fn s11a_11_parameter_errors_are_fb_errors_axis_errors_need_reset() {
    let mut r = Rig::new(1);
    power(&mut r);
    // FB error: rejected, axis unaffected.
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(10.0, -1.0))),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(r.st(0).state, AxisState::Standstill);
    r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    // Axis error: following error → ErrorStop until reset.
    r.run(0.02);
    r.plants[0].load_lag = 5.0;
    r.run(0.05);
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    assert_eq!(r.st(0).error_id, ErrorId::FOLLOWING_ERROR.0);
    r.plants[0].load_lag = 0.0;
    r.ok(0, CommandKind::Reset);
    r.step();
    assert_eq!(r.st(0).state, AxisState::Standstill);
}

// ---------------------------------------------------------------- buffering

#[test]
fn s11a_12_buffered_successor_starts_from_standstill() {
    let mut r = Rig::new(1);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    let b = r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(20.0, 100.0, BufferMode::Buffered)),
    );
    assert!(r.out(b).busy && !r.out(b).active);
    r.until(2.0, |r| r.out(a).done);
    // The predecessor was Done (target window) before the successor became active; at that
    // moment the axis was at rest at P1.
    let h = &r.history[0];
    let i = h
        .iter()
        .position(|s| (s.target_position - 20.0).abs() < 1e-12)
        .unwrap();
    assert!(h[i - 1].set_velocity.abs() < 1e-9 && (h[i - 1].set_position - 10.0).abs() < 1e-9);
    r.until(2.0, |r| r.out(b).done);
}

fn blend_velocity_at_p1(mode: BufferMode, v1: f64, v2: f64) -> f64 {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(0, CommandKind::MoveAbsolute(mv(100.0, v1)));
    r.run(0.01);
    let b = r.ok(0, CommandKind::MoveAbsolute(mvb(200.0, v2, mode)));
    r.until(5.0, |r| r.out(b).done);
    // Velocity when passing P1.
    let h = &r.history[0];
    let i = h.iter().position(|s| s.set_position >= 100.0).unwrap();
    h[i].set_velocity
}

#[test]
fn s11a_12_blending_modes_pass_p1_at_the_specified_velocity() {
    // v1 < v2
    let (v1, v2) = (100.0, 300.0);
    let near = |a: f64, b: f64| (a - b).abs() < 2.0; // within a cycle of acceleration
    assert!(near(
        blend_velocity_at_p1(BufferMode::BlendingLow, v1, v2),
        v1
    ));
    assert!(near(
        blend_velocity_at_p1(BufferMode::BlendingPrevious, v1, v2),
        v1
    ));
    assert!(near(
        blend_velocity_at_p1(BufferMode::BlendingNext, v1, v2),
        v2
    ));
    assert!(near(
        blend_velocity_at_p1(BufferMode::BlendingHigh, v1, v2),
        v2
    ));
    // v2 < v1
    let (v1, v2) = (300.0, 100.0);
    assert!(near(
        blend_velocity_at_p1(BufferMode::BlendingLow, v1, v2),
        v2
    ));
    assert!(near(
        blend_velocity_at_p1(BufferMode::BlendingPrevious, v1, v2),
        v1
    ));
    assert!(near(
        blend_velocity_at_p1(BufferMode::BlendingNext, v1, v2),
        v2
    ));
    assert!(near(
        blend_velocity_at_p1(BufferMode::BlendingHigh, v1, v2),
        v1
    ));
    // Buffered passes at rest.
    assert!(blend_velocity_at_p1(BufferMode::Buffered, v1, v2).abs() < 1e-9);
}

#[test]
fn s11a_13_second_buffered_command_is_buffer_full_aborting_still_wins() {
    let mut r = Rig::new(1);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(50.0, 100.0)));
    let b = r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(60.0, 100.0, BufferMode::Buffered)),
    );
    assert_eq!(
        r.rejected(
            0,
            CommandKind::MoveAbsolute(mvb(70.0, 100.0, BufferMode::BlendingLow))
        ),
        ErrorId::BUFFER_FULL
    );
    let c = r.ok(0, CommandKind::MoveAbsolute(mv(5.0, 100.0)));
    assert!(r.out(a).command_aborted && r.out(b).command_aborted);
    r.until(3.0, |r| r.out(c).done);
}

#[test]
fn s11a_14_buffered_command_after_endless_motion_acts_at_once() {
    let mut r = Rig::new(1);
    power(&mut r);
    let v = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 50.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(0.2);
    let b = r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(100.0, 100.0, BufferMode::Buffered)),
    );
    assert!(r.out(v).command_aborted);
    assert!(r.out(b).active);
}

#[test]
fn s11a_15_blending_position_rules() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 100.0)));
    r.run(0.05);
    let mut m = mvb(150.0, 100.0, BufferMode::BlendingLow);
    m.options.blending_position = Some(120.0);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(m)),
        ErrorId::BLENDING_POSITION_INVALID
    );
    // Already passed → acts like Aborting.
    let pos = r.st(0).set_position;
    m.options.blending_position = Some(pos - 1.0);
    let b = r.ok(0, CommandKind::MoveAbsolute(m));
    assert!(r.out(b).active);
}

#[test]
fn s11a_16_slave_motion_commands_decouple_only_when_allowed_and_aborting() {
    let mut p = params();
    p.axis_allow_motion_cmd_to_slave_axis = true;
    let mut r = Rig::with(vec![(false, params()), (false, params()), (false, p)]);
    r.power_on(0);
    r.power_on(1);
    r.power_on(2);
    r.ok(
        1,
        CommandKind::GearIn {
            master: 0,
            ratio_numerator: 1.0,
            ratio_denominator: 1,
        },
    );
    r.ok(
        2,
        CommandKind::GearIn {
            master: 0,
            ratio_numerator: 1.0,
            ratio_denominator: 1,
        },
    );
    assert_eq!(
        r.rejected(1, CommandKind::MoveAbsolute(mv(10.0, 10.0))),
        ErrorId::SLAVE_COMMAND_NOT_ALLOWED
    );
    assert_eq!(
        r.rejected(
            2,
            CommandKind::MoveAbsolute(mvb(10.0, 10.0, BufferMode::Buffered))
        ),
        ErrorId::INVALID_MODE
    );
    let m = r.ok(2, CommandKind::MoveAbsolute(mv(10.0, 10.0)));
    assert_eq!(r.st(2).state, AxisState::DiscreteMotion);
    assert!(!r.st(2).coupled);
    r.until(3.0, |r| r.out(m).done);
}

// ---------------------------------------------------------------- moves

#[test]
fn s11a_17_relative_from_set_additive_from_last_target() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 100.0)));
    r.until(3.0, |r| r.st(0).set_position > 40.0);
    let s = r.st(0).set_position;
    let a = r.ok(0, CommandKind::MoveAdditive(mv(50.0, 100.0)));
    assert!((r.st(0).target_position - 150.0).abs() < 1e-9);
    r.until(5.0, |r| r.out(a).done);
    let rel = r.ok(0, CommandKind::MoveRelative(mv(-20.0, 100.0)));
    assert!((r.st(0).target_position - 130.0).abs() < 1e-9);
    r.until(5.0, |r| r.out(rel).done);
    assert!(s < 100.0);
}

#[test]
fn s11a_18_zero_dynamics_use_axis_defaults_velocity_must_be_positive() {
    let mut r = Rig::new(1);
    power(&mut r);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(10.0, 0.0))),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(10.0, f64::NAN))),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 500.0)));
    r.until(3.0, |r| r.out(a).done);
    let h = &r.history[0];
    let amax = h.iter().map(|s| s.set_acceleration).fold(0.0, f64::max);
    let amin = h.iter().map(|s| s.set_acceleration).fold(0.0, f64::min);
    // Defaults: acc 2000, dec 1000 (rig params).
    assert!(amax <= 2000.0 + 1e-6 && amax > 1900.0, "{amax}");
    assert!(amin >= -1000.0 - 1e-6 && amin < -900.0, "{amin}");
}

#[test]
fn s11a_19_done_waits_for_the_target_window_unless_ignored() {
    let mut r = Rig::new(1);
    r.plants[0].tau = 0.01; // a lagging drive
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    r.until(2.0, |r| !r.st(0).moving && r.st(0).set_position == 10.0);
    assert!(
        !r.out(a).done,
        "done before the actual position is in the window"
    );
    r.until(1.0, |r| r.out(a).done);
    assert!((r.plants[0].pos - 10.0).abs() <= 0.01);

    let mut m = mv(20.0, 100.0);
    m.options.ignore_position_monitoring = true;
    let b = r.ok(0, CommandKind::MoveAbsolute(m));
    r.until(2.0, |r| r.st(0).set_position == 20.0);
    r.step();
    assert!(r.out(b).done);
    assert!((r.plants[0].pos - 20.0).abs() > 0.01);
}

#[test]
fn in_target_timeout_reports_0x4b07() {
    let mut p = params();
    p.axis_in_target_timeout = 0.05;
    p.axis_en_position_lag_monitoring = false;
    let mut r = Rig::with(vec![(false, p)]);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    r.plants[0].load_lag = 0.5;
    r.until(3.0, |r| !r.out(a).busy);
    assert_eq!(r.out(a).error_id, ErrorId::IN_TARGET_TIMEOUT.0);
}

#[test]
fn s11a_20_move_velocity_in_velocity_and_stays_busy() {
    let mut r = Rig::new(1);
    power(&mut r);
    let v = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 120.0,
            dynamics: Dynamics::default(),
            direction: Direction::Negative,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.until(1.0, |r| r.out(v).in_velocity);
    assert!((r.st(0).set_velocity + 120.0).abs() < 1e-9);
    r.run(0.5);
    let o = r.out(v);
    assert!(o.busy && o.active && o.in_velocity && !o.done);
    // Override change: in_velocity drops, re-plans without a jump, comes back.
    r.ok(
        0,
        CommandKind::SetOverride {
            velocity_factor: 0.5,
        },
    );
    r.step();
    assert!(!r.out(v).in_velocity);
    r.until(1.0, |r| r.out(v).in_velocity);
    assert!((r.st(0).set_velocity + 60.0).abs() < 1e-9);
}

/// §11a #20: a superposition on a MoveVelocity keeps InVelocity TRUE in every cycle (the
/// commanded velocity of the main motion is unchanged; the setpoint carries the extra).
#[test]
fn s11a_20_superposition_keeps_in_velocity_of_a_move_velocity() {
    let mut r = Rig::new(1);
    r.bounds[0].jerk = 1e9; // the superposition profile is C² but not jerk-limited
    power(&mut r);
    let v = r.ok(0, velocity(120.0, Direction::Positive));
    r.until(1.0, |r| r.out(v).in_velocity);
    let s = r.ok(
        0,
        CommandKind::MoveSuperImposed(Superposition {
            mode: SuperpositionMode::VeloReductionAdditiveMotion,
            distance: 30.0,
            velocity_diff: 100.0,
            velocity_process: 120.0,
            length: 200.0,
            ..Default::default()
        }),
    );
    let mut faster = false;
    while r.out(s).busy {
        r.step();
        let o = r.out(v);
        assert!(o.busy && o.active && o.in_velocity, "{o:?}");
        faster |= r.st(0).set_velocity > 120.0 + 1.0;
    }
    assert!(r.out(s).done && faster, "the superposition ran");
    r.run(0.1);
    assert!(r.out(v).in_velocity);
    assert!((r.st(0).set_velocity - 120.0).abs() < 1e-9);
}

#[test]
fn s11a_21_move_continuous_reaches_target_then_keeps_end_velocity() {
    let mut r = Rig::new(1);
    power(&mut r);
    let c = r.ok(
        0,
        CommandKind::MoveContinuousAbsolute {
            move_: mv(100.0, 200.0),
            end_velocity: 50.0,
        },
    );
    assert_eq!(r.st(0).state, AxisState::ContinuousMotion);
    r.until(3.0, |r| r.out(c).in_end_velocity);
    assert!((r.st(0).set_position - 100.0).abs() < 0.1);
    r.run(0.5);
    assert!((r.st(0).set_velocity - 50.0).abs() < 1e-9);
    assert!(r.out(c).busy && r.out(c).in_end_velocity);
}

#[test]
fn s11a_22_move_modulo_from_standstill_uses_the_table_algorithm() {
    let mut p = params();
    p.axis_modulo_tolerance_window = 1.0;
    let mut r = Rig::with(vec![(true, p)]);
    power(&mut r);
    r.ok(
        0,
        CommandKind::SetPosition {
            position: 90.9,
            relative: false,
            clear_position_lag: true,
        },
    );
    let m = r.ok(
        0,
        CommandKind::MoveModulo {
            move_: mv(450.0, 300.0),
            direction: Direction::Positive,
        },
    );
    assert!((r.st(0).target_position - 450.0).abs() < 1e-9);
    r.until(5.0, |r| r.out(m).done);
    assert!((r.st(0).modulo_set_position - 90.0).abs() < 1e-9);
    assert_eq!(r.st(0).modulo_set_turns, 1);
    assert_eq!(
        r.rejected(
            0,
            CommandKind::MoveModulo {
                move_: mv(400.0, 100.0),
                direction: Direction::ShortestWay
            }
        ),
        ErrorId::INVALID_MODE
    );
    assert_eq!(
        r.rejected(
            0,
            CommandKind::MoveModulo {
                move_: mv(-1.0, 100.0),
                direction: Direction::Positive
            }
        ),
        ErrorId::PARAMETER_NOT_CORRECT
    );
}

#[test]
fn move_modulo_from_motion_keeps_direction_and_ignores_extra_turns() {
    let mut r = Rig::with(vec![(true, params())]);
    power(&mut r);
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 200.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(0.5);
    let m = r.ok(
        0,
        CommandKind::MoveModulo {
            move_: mv(370.0, 200.0),
            direction: Direction::Positive,
        },
    );
    let start = r.st(0).set_position;
    r.until(5.0, |r| r.out(m).done);
    let s = r.st(0);
    assert!((s.modulo_set_position - 10.0).abs() < 1e-9);
    assert!(s.set_position > start && s.set_position - start < 360.0 + 100.0);
    assert!(
        r.history[0].iter().all(|h| h.set_velocity >= -1e-9),
        "reversed"
    );
}

/// Behind endless motion a Buffered MoveModulo acts at once on the moving axis (§3.8): it must
/// run exactly as an Aborting one issued in the same cycle — from-motion rules, extra turns
/// ignored, no reversal, the target past the braking distance.
#[test]
fn buffered_move_modulo_behind_endless_motion_resolves_from_motion_like_aborting() {
    let endless: [(&str, CommandKind); 4] = [
        (
            "move velocity",
            CommandKind::MoveVelocity {
                velocity: 300.0,
                dynamics: Dynamics::default(),
                direction: Direction::Positive,
                buffer_mode: BufferMode::Aborting,
                options: MoveOptions::default(),
            },
        ),
        (
            "move velocity negative",
            CommandKind::MoveVelocity {
                velocity: 300.0,
                dynamics: Dynamics::default(),
                direction: Direction::Negative,
                buffer_mode: BufferMode::Aborting,
                options: MoveOptions::default(),
            },
        ),
        (
            "continuous jog",
            CommandKind::Jog {
                mode: JogMode::Continuous,
                forward: true,
                position: 0.0,
                velocity: 300.0,
                dynamics: Dynamics::default(),
                deadman: 0.0,
            },
        ),
        (
            "move continuous at its end velocity",
            CommandKind::MoveContinuousRelative {
                move_: mv(100.0, 300.0),
                end_velocity: 250.0,
            },
        ),
    ];
    for (name, start) in endless {
        let run = |buffer_mode: BufferMode| {
            let mut r = Rig::with(vec![(true, params())]);
            r.power_on(0);
            r.ok(0, start);
            r.run(0.8);
            let v0 = r.st(0).set_velocity;
            let (p0, a0) = (r.st(0).set_position, r.st(0).set_acceleration);
            assert!(v0.abs() > 200.0, "{name}: moving");
            let direction = if v0 > 0.0 {
                Direction::Positive
            } else {
                Direction::Negative
            };
            // Two extra turns asked: ignored from motion.
            let m = r.ok(
                0,
                CommandKind::MoveModulo {
                    move_: mvb(720.0 + 100.0, 200.0, buffer_mode),
                    direction,
                },
            );
            assert!(r.out(m).active, "{name}: acts at once");
            let target = r.st(0).target_position;
            r.until(5.0, |r| !r.out(m).busy);
            assert!(r.out(m).done, "{name} {buffer_mode:?}: {:?}", r.out(m));
            (r, m, v0, p0, a0, target)
        };
        let (a, _, v0, p0, a0, target) = run(BufferMode::Aborting);
        let (b, _, _, _, _, target_b) = run(BufferMode::Buffered);
        assert_eq!(target, target_b, "{name}: same target");
        assert_eq!(
            a.history[0], b.history[0],
            "{name}: Buffered and Aborting move alike in every cycle"
        );
        // From-motion rules: never reversed, no extra turns, not before the brake point.
        let dir = v0.signum();
        assert!(
            b.history[0]
                .iter()
                .rev()
                .take(4000)
                .all(|h| h.set_velocity * dir >= -1e-9),
            "{name}: reversed"
        );
        let brake = params().axis_dec;
        let min_travel = v0 * v0 / (2.0 * brake) * 0.9 * dir.abs();
        let travel = (target - p0) * dir;
        assert!(
            travel >= min_travel && travel < min_travel / 0.9 + 360.0 + 1e-9,
            "{name}: travel {travel} from {p0} (v {v0}, a {a0})"
        );
        assert!(
            (target.rem_euclid(360.0) - 100.0).abs() < 1e-9,
            "{name}: modulo target {target}"
        );
    }
}

#[test]
fn s11a_23_halt_has_no_lock_and_never_weaker_dynamics() {
    let mut r = Rig::new(1);
    power(&mut r);
    let mut m = mv(400.0, 400.0);
    m.dynamics.deceleration = 3000.0;
    r.ok(0, CommandKind::MoveAbsolute(m));
    r.run(0.3);
    // Weaker deceleration asked: the move's 3000 is used.
    let h = r.ok(
        0,
        CommandKind::Halt {
            deceleration: 100.0,
            jerk: 0.0,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    assert_eq!(r.st(0).state, AxisState::DiscreteMotion);
    r.run(0.05);
    let amin = r.history[0]
        .iter()
        .rev()
        .take(50)
        .map(|s| s.set_acceleration)
        .fold(0.0, f64::min);
    assert!(amin < -1000.0, "halt used a weaker deceleration: {amin}");
    // No lock: a new move during the ramp is accepted.
    let b = r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 100.0)));
    assert!(r.out(h).command_aborted);
    r.until(10.0, |r| r.out(b).done);
}

#[test]
fn s11a_24_stop_locks_until_released_done_while_busy() {
    let mut r = Rig::new(1);
    power(&mut r);
    let a = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 100.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(0.2);
    let s = r.ok(
        0,
        CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: MoveOptions::default(),
        },
    );
    assert!(r.out(a).command_aborted);
    assert_eq!(r.st(0).state, AxisState::Stopping);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(0.0, 10.0))),
        ErrorId::AXIS_CANNOT_BE_STARTED
    );
    r.until(2.0, |r| r.out(s).done);
    let o = r.out(s);
    assert!(o.done && o.busy && o.active, "{o:?}");
    assert_eq!(r.st(0).state, AxisState::Stopping);
    assert!(r.st(0).motion_commands_locked);
    r.run(0.1);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(0.0, 10.0))),
        ErrorId::AXIS_CANNOT_BE_STARTED
    );
    r.ok(0, CommandKind::Release { target: s });
    assert_eq!(r.st(0).state, AxisState::Standstill);
    assert!(!r.out(s).busy && r.out(s).done);
    r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 10.0)));

    // MC_Reset also removes the lock.
    let s2 = r.ok(
        0,
        CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: MoveOptions::default(),
        },
    );
    r.until(2.0, |r| r.out(s2).done);
    r.ok(0, CommandKind::Reset);
    r.step();
    assert_eq!(r.st(0).state, AxisState::Standstill);
}

// ---------------------------------------------------------------- homing, jog, gearing

/// MC_SetPosition relative +5: the MC_SetPosition offset (#2003) is 5.
fn set_position_offset_5(r: &mut Rig) {
    r.ok(
        0,
        CommandKind::SetPosition {
            position: 5.0,
            relative: true,
            clear_position_lag: false,
        },
    );
    assert_eq!(r.st(0).set_position_offset, 5.0);
}

#[test]
fn s11a_25_home_direct_force_reset_calibration() {
    let mut r = Rig::new(1);
    power(&mut r);
    set_position_offset_5(&mut r);
    r.ok(
        0,
        CommandKind::Home {
            position: Some(42.0),
            mode: HomingMode::Direct,
            options: HomingOptions::default(),
        },
    );
    assert!(r.st(0).homed);
    assert!((r.st(0).set_position - 42.0).abs() < 1e-9);
    assert_eq!(r.st(0).set_position_offset, 0.0);
    r.run(0.01);
    assert_eq!(r.plants[0].pos, 0.0, "direct homing moved the axis");
    r.ok(
        0,
        CommandKind::Home {
            position: None,
            mode: HomingMode::ResetCalibration,
            options: HomingOptions::default(),
        },
    );
    assert!(!r.st(0).homed);
    r.ok(
        0,
        CommandKind::Home {
            position: None,
            mode: HomingMode::ForceCalibration,
            options: HomingOptions::default(),
        },
    );
    assert!(r.st(0).homed);
    assert!((r.st(0).set_position - 42.0).abs() < 1e-9);
}

/// MC_Home with the referencing sequence (#1076) to `position`; returns when it has ended.
fn home_by_sequence(r: &mut Rig, position: f64) -> CommandId {
    let h = r.ok(
        0,
        CommandKind::Home {
            position: Some(position),
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    r.until(20.0, |r| !r.out(h).busy);
    h
}

/// §11a #25 for the referencing sequence (not only MC_Direct): homing clears the
/// MC_SetPosition offset.
#[test]
fn s11a_25_a_homing_sequence_clears_the_set_position_offset() {
    let mut r = Rig::new(1);
    r.plants[0].cam = Some((50.0, 55.0));
    r.plants[0].index_period = Some(8.0);
    power(&mut r);
    set_position_offset_5(&mut r);
    let h = home_by_sequence(&mut r, 100.0);
    assert!(r.out(h).done && r.st(0).homed);
    assert_eq!(r.st(0).set_position_offset, 0.0);
}

#[test]
fn homing_sequence_cam_then_index_pulse_references_exactly() {
    let mut r = Rig::new(1);
    r.plants[0].cam = Some((50.0, 55.0));
    r.plants[0].index_period = Some(8.0); // pulses at …, 40, 48, 56 …
    power(&mut r);
    let h = r.ok(
        0,
        CommandKind::Home {
            position: Some(100.0),
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    assert_eq!(r.st(0).state, AxisState::Homing);
    let mut phases = vec![];
    r.until(20.0, |r| {
        let p = r.st(0).homing_phase;
        if phases.last() != Some(&p) {
            phases.push(p);
        }
        !r.out(h).busy
    });
    assert!(r.out(h).done, "{:?}", r.out(h));
    r.run(0.01); // the drive follows the last setpoint
    use HomingPhase::*;
    assert_eq!(
        phases,
        vec![
            SearchCam,
            StopOnCam,
            LeaveCam,
            WaitCamFallingEdge,
            WaitLatch,
            SetPosition,
            Idle
        ]
    );
    // ST_HomingOptions: an undefined SyncDirection is positive, so the cam is left forwards
    // (falling edge at 55) and the first index pulse is at 56: the drive position 56 is now
    // the reference 100.
    let s = r.st(0);
    assert!(s.homed && s.state == AxisState::Standstill);
    assert!(
        (s.actual_position - (100.0 + (r.plants[0].pos - 56.0))).abs() < 1e-9,
        "{s:?} plant {}",
        r.plants[0].pos
    );
}

/// A homing run that reaches a limit switch before the cam says so (0x7030, cam not found)
/// and stops on the switch in ErrorStop: an axis on an end of travel is never a silent
/// Standstill.
#[test]
fn homing_fails_cleanly_when_the_cam_is_never_found() {
    let mut r = Rig::new(1);
    power(&mut r);
    let h = r.ok(
        0,
        CommandKind::Home {
            position: None,
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    r.run(0.5);
    r.plants[0].limit_positive = true;
    r.until(2.0, |r| !r.out(h).busy);
    assert_eq!(r.out(h).error_id, ErrorId::HOMING_FAILED.0);
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    assert_eq!(r.st(0).error_id, ErrorId::HOMING_FAILED.0);
    assert!(!r.st(0).homed);
    r.until(1.0, |r| !r.st(0).moving);
    r.plants[0].limit_positive = false;
    r.ok(0, CommandKind::Reset);
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
}

#[test]
fn s11a_26_jog_modes() {
    let mut p = params();
    p.axis_velo_man_slow = 7.0;
    p.axis_velo_man_fast = 70.0;
    let mut r = Rig::with(vec![(false, p)]);
    power(&mut r);
    let jog = |mode, forward, position| CommandKind::Jog {
        mode,
        forward,
        position,
        velocity: 33.0,
        dynamics: Dynamics::default(),
        deadman: 0.0,
    };
    let j = r.ok(0, jog(JogMode::StandardSlow, true, 0.0));
    r.run(0.5);
    assert!((r.st(0).set_velocity - 7.0).abs() < 1e-9);
    r.ok(0, CommandKind::Release { target: j });
    r.until(1.0, |r| r.out(j).done);
    let j = r.ok(0, jog(JogMode::StandardFast, false, 0.0));
    r.run(0.5);
    assert!((r.st(0).set_velocity + 70.0).abs() < 1e-9);
    r.ok(0, CommandKind::Release { target: j });
    r.until(1.0, |r| r.out(j).done);
    let j = r.ok(0, jog(JogMode::Continuous, true, 0.0));
    r.run(0.5);
    assert!((r.st(0).set_velocity - 33.0).abs() < 1e-9);
    r.ok(0, CommandKind::Release { target: j });
    r.until(1.0, |r| r.out(j).done);
    let s = r.st(0).set_position;
    let j = r.ok(0, jog(JogMode::Inching, true, 2.5));
    r.until(2.0, |r| r.out(j).done);
    assert!((r.st(0).set_position - (s + 2.5)).abs() < 1e-9);
    let j = r.ok(0, jog(JogMode::InchingModulo, true, 2.0));
    r.until(2.0, |r| r.out(j).done);
    let p = r.st(0).set_position;
    assert!((p / 2.0 - (p / 2.0).round()).abs() < 1e-9 && p > s + 2.5);
}

/// INCHING_MODULO stops on multiples of the step in modulo coordinates: on a 360° axis with
/// a 50° step the stops are 0, 50 … 350 in every turn (the step after 350 is 0 of the next
/// turn), backwards too — they do not drift by 40° a turn.
#[test]
fn inching_modulo_snaps_in_modulo_coordinates_without_drift_per_turn() {
    let mut r = Rig::with(vec![(true, params())]);
    r.power_on(0);
    let inch = |forward| CommandKind::Jog {
        mode: JogMode::InchingModulo,
        forward,
        position: 50.0,
        velocity: 300.0,
        dynamics: Dynamics::default(),
        deadman: 0.0,
    };
    let stops = |r: &mut Rig, forward: bool, n: usize| -> Vec<(f64, i64)> {
        (0..n)
            .map(|_| {
                let j = r.ok(0, inch(forward));
                r.until(3.0, |r| !r.out(j).busy);
                assert!(r.out(j).done);
                let s = r.st(0);
                (s.modulo_set_position, s.modulo_set_turns)
            })
            .collect()
    };
    let forward = stops(&mut r, true, 18);
    let expected: Vec<(f64, i64)> = (1..=18)
        .map(|k| {
            let (turn, i) = (k / 8, k % 8);
            ((i * 50) as f64, turn)
        })
        .collect();
    for (got, want) in forward.iter().zip(&expected) {
        assert!(
            (got.0 - want.0).abs() < 1e-9 && got.1 == want.1,
            "{forward:?}"
        );
    }
    // 18 steps forward end on 100° of turn 2; 5 back: 50, 0, then 350, 300, 250 of turn 1.
    let backward = stops(&mut r, false, 5);
    let want = [(50.0, 2), (0.0, 2), (350.0, 1), (300.0, 1), (250.0, 1)];
    for (got, want) in backward.iter().zip(&want) {
        assert!(
            (got.0 - want.0).abs() < 1e-9 && got.1 == want.1,
            "{backward:?}"
        );
    }
    // Not a modulo axis: multiples of the absolute position.
    let mut r = Rig::new(1);
    r.power_on(0);
    let linear = stops(&mut r, true, 9);
    assert!((linear[8].0 - 450.0).abs() < 1e-9, "{linear:?}");
}

#[test]
fn jog_dead_man_stops_the_axis_when_not_renewed() {
    let mut r = Rig::new(1);
    power(&mut r);
    let j = r.ok(
        0,
        CommandKind::Jog {
            mode: JogMode::Continuous,
            forward: true,
            position: 0.0,
            velocity: 50.0,
            dynamics: Dynamics::default(),
            deadman: 0.2,
        },
    );
    for _ in 0..5 {
        r.run(0.1);
        r.ok(0, CommandKind::Keepalive { target: j });
    }
    assert!(r.st(0).set_velocity > 49.0);
    // The last keepalive takes effect in cycle c0; the dead-man fires exactly 200 cycles
    // (0.2 s) later, reports it at once and starts braking in that cycle.
    let c0 = r.k.cycle() + 1;
    r.until(1.0, |r| r.out(j).warning);
    let fired = r
        .events
        .iter()
        .find(|e| e.command == j && e.outputs.warning)
        .unwrap()
        .cycle;
    assert_eq!(
        fired - c0,
        199,
        "fired {} cycles after the keepalive",
        fired - c0
    );
    assert_eq!(r.out(j).warning_id, ErrorId::DEADMAN_TIMEOUT.0);
    assert!(!r.out(j).in_velocity && r.st(0).decelerating);
    r.until(1.0, |r| !r.out(j).busy);
    assert_eq!(r.out(j).error_id, ErrorId::DEADMAN_TIMEOUT.0);
}

#[test]
fn s11a_27_gear_ratio_forms_give_identical_slaves_denominator_zero_rejected() {
    let mut r = Rig::new(3);
    for a in 0..3 {
        r.power_on(a);
    }
    assert_eq!(
        r.rejected(
            1,
            CommandKind::GearIn {
                master: 0,
                ratio_numerator: 1.0,
                ratio_denominator: 0
            }
        ),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    let g1 = r.ok(
        1,
        CommandKind::GearIn {
            master: 0,
            ratio_numerator: 1.0,
            ratio_denominator: 4,
        },
    );
    let g2 = r.ok(
        2,
        CommandKind::GearIn {
            master: 0,
            ratio_numerator: 0.25,
            ratio_denominator: 1,
        },
    );
    assert!(r.out(g1).in_gear && r.out(g2).in_gear);
    assert_eq!(r.st(1).state, AxisState::SynchronizedMotion);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 200.0)));
    r.until(3.0, |r| r.out(m).done);
    assert!((r.st(1).set_position - 25.0).abs() < 1e-9);
    assert_eq!(r.st(1).set_position, r.st(2).set_position);
    // Negative numerator.
    let mut r = Rig::new(2);
    r.power_on(0);
    r.power_on(1);
    r.ok(
        1,
        CommandKind::GearIn {
            master: 0,
            ratio_numerator: -2.0,
            ratio_denominator: 1,
        },
    );
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    r.until(3.0, |r| r.out(m).done);
    assert!((r.st(1).set_position + 20.0).abs() < 1e-9);
}

#[test]
fn s11a_28_gear_out_in_motion_keeps_constant_velocity() {
    let mut r = Rig::new(2);
    r.power_on(0);
    r.power_on(1);
    let g = r.ok(
        1,
        CommandKind::GearIn {
            master: 0,
            ratio_numerator: 2.0,
            ratio_denominator: 1,
        },
    );
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 50.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(1.0);
    assert!((r.st(1).set_velocity - 100.0).abs() < 1e-6);
    // MC_GearIn ended with InGear once coupled; GearOut has nothing to abort.
    assert!(r.out(g).in_gear && r.out(g).done && !r.out(g).busy);
    r.ok(1, CommandKind::GearOut);
    assert!(!r.out(g).command_aborted);
    assert_eq!(r.st(1).state, AxisState::ContinuousMotion);
    r.ok(
        0,
        CommandKind::Halt {
            deceleration: 0.0,
            jerk: 0.0,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(1.0);
    assert!(
        (r.st(1).set_velocity - 100.0).abs() < 1e-6,
        "{}",
        r.st(1).set_velocity
    );
    assert!(r.st(0).set_velocity.abs() < 1e-9);
}

#[test]
fn s11a_34_override_range() {
    let mut r = Rig::new(1);
    assert_eq!(
        r.rejected(
            0,
            CommandKind::Power {
                enable: true,
                enable_positive: true,
                enable_negative: true,
                override_percent: 100.5
            }
        ),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(
        r.rejected(
            0,
            CommandKind::Power {
                enable: true,
                enable_positive: true,
                enable_negative: true,
                override_percent: -0.1
            }
        ),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    power(&mut r);
    r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 50.0,
        },
    );
    let v = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 100.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.until(1.0, |r| r.out(v).in_velocity);
    assert!((r.st(0).set_velocity - 50.0).abs() < 1e-9);
    // Override 0 stops the axis without aborting the command.
    r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 0.0,
        },
    );
    r.run(1.0);
    assert!(r.st(0).set_velocity.abs() < 1e-9);
    assert!(r.out(v).busy && !r.out(v).command_aborted);
}

// ---------------------------------------------------------------- monitoring

#[test]
fn soft_limits_reject_targets_and_stop_endless_motion_at_the_limit() {
    let mut p = params();
    p.axis_en_max_soft_pos_limit = true;
    p.axis_max_soft_pos_limit = 100.0;
    p.axis_en_min_soft_pos_limit = true;
    p.axis_min_soft_pos_limit = -10.0;
    let mut r = Rig::with(vec![(false, p)]);
    power(&mut r);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(100.5, 10.0))),
        ErrorId::TARGET_ABOVE_SOFT_LIMIT
    );
    assert_eq!(
        r.rejected(0, CommandKind::MoveRelative(mv(-11.0, 10.0))),
        ErrorId::TARGET_BELOW_SOFT_LIMIT
    );
    let v = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 300.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.until(3.0, |r| !r.out(v).busy);
    assert_eq!(r.out(v).error_id, ErrorId::SOFT_LIMIT_REACHED.0);
    r.until(3.0, |r| r.st(0).state == AxisState::Standstill);
    let s = r.st(0);
    assert!(
        s.set_position <= 100.0 + 1e-9 && s.set_position > 99.0,
        "{}",
        s.set_position
    );
    assert!(r.history[0].iter().all(|h| h.set_position <= 100.0 + 1e-9));
}

/// A coupled slave cannot brake for its own soft limit: crossing it decouples the slave and
/// stops it on the fast-stop ramp in ErrorStop with 0x7003; the master runs on.
#[test]
fn a_gear_slave_crossing_a_soft_limit_decouples_and_stops_fast_in_error_stop() {
    for (dyn_coupling, dir) in [(true, Direction::Positive), (false, Direction::Negative)] {
        let p = params_with_soft_limits(-100.0, 100.0);
        let mut r = Rig::with(vec![(false, params()), (false, p.clone())]);
        r.power_on(0);
        r.power_on(1);
        let g = if dyn_coupling {
            r.ok(
                1,
                CommandKind::GearInDyn {
                    master: 0,
                    gear_ratio: 2.0,
                    acceleration: 0.0,
                },
            )
        } else {
            r.ok(
                1,
                CommandKind::GearIn {
                    master: 0,
                    ratio_numerator: 2.0,
                    ratio_denominator: 1,
                },
            )
        };
        r.ok(0, velocity(100.0, dir));
        let limit: f64 = if dir == Direction::Positive {
            100.0
        } else {
            -100.0
        };
        let s = limit.signum();
        // Cycle by cycle: coupled up to the cycle whose setpoint crosses the limit.
        let mut prev = r.st(1);
        loop {
            r.step();
            let now = r.st(1);
            if now.state != AxisState::SynchronizedMotion {
                assert!(prev.set_position * s <= 100.0, "{prev:?}");
                assert!(
                    now.set_position * s > 100.0,
                    "stopped before crossing: {now:?}"
                );
                break;
            }
            assert!(
                now.set_position * s <= 100.0,
                "crossed while coupled: {now:?}"
            );
            prev = now;
        }
        let st = r.st(1);
        assert_eq!(st.state, AxisState::ErrorStop);
        assert_eq!(st.error_id, ErrorId::SOFT_LIMIT_REACHED.0);
        assert!(!st.coupled && st.master.is_none());
        if dyn_coupling {
            let o = r.out(g);
            assert!(o.error && !o.busy, "{o:?}");
            assert_eq!(o.error_id, ErrorId::SOFT_LIMIT_REACHED.0);
        } else {
            assert!(r.out(g).done, "MC_GearIn ended when it coupled");
        }
        let from = r.history[1].len();
        r.until(1.0, |r| !r.st(1).moving);
        // Fast-stop ramp: stronger than the axis deceleration, within the fast one.
        let peak = r.history[1][from..]
            .iter()
            .map(|h| h.set_acceleration.abs())
            .fold(0.0, f64::max);
        assert!(
            peak > p.axis_dec && peak <= p.axis_fast_dec + 1e-9,
            "{peak}"
        );
        let over = (r.st(1).set_position - limit) * s;
        let v = 200.0;
        assert!(
            over > 0.0
                && over < v * v / (2.0 * p.axis_fast_dec) + v * p.axis_fast_dec / p.axis_fast_jerk,
            "stopped {over} beyond the limit"
        );
        assert_eq!(r.st(1).state, AxisState::ErrorStop);
        // The master is not affected.
        assert_eq!(r.st(0).state, AxisState::ContinuousMotion);
        assert!((r.st(0).set_velocity.abs() - 100.0).abs() < 1e-9);
        // After MC_Reset the slave may move back inside its limits.
        r.ok(1, CommandKind::Reset);
        r.until(0.1, |r| r.st(1).state == AxisState::Standstill);
        let m = r.ok(1, CommandKind::MoveAbsolute(mv(0.0, 100.0)));
        r.until(5.0, |r| !r.out(m).busy);
        assert!(r.out(m).done);
    }
}

#[test]
fn feed_enable_missing_rejects_and_stops() {
    let mut r = Rig::new(1);
    r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: false,
            override_percent: 100.0,
        },
    );
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(-5.0, 10.0))),
        ErrorId::FEED_ENABLE_MISSING
    );
    let v = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 100.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(0.3);
    r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: false,
            enable_negative: false,
            override_percent: 100.0,
        },
    );
    r.step();
    assert_eq!(r.out(v).error_id, ErrorId::FEED_ENABLE_MISSING.0);
    r.until(2.0, |r| r.st(0).state == AxisState::Standstill);
}

#[test]
fn set_position_during_motion_shifts_coordinates_not_the_motion() {
    let mut r = Rig::new(1);
    power(&mut r);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 100.0)));
    r.run(0.3);
    assert_eq!(
        r.rejected(
            0,
            CommandKind::SetPosition {
                position: 0.0,
                relative: false,
                clear_position_lag: false
            }
        ),
        ErrorId::AXIS_CANNOT_BE_STARTED
    );
    r.ok(
        0,
        CommandKind::SetPosition {
            position: 1000.0,
            relative: true,
            clear_position_lag: false,
        },
    );
    r.until(5.0, |r| r.out(m).done);
    assert!((r.st(0).set_position - 1100.0).abs() < 1e-9);
    assert!((r.plants[0].pos - 100.0).abs() < 0.01);
}

/// The rig holds a move started from rest to its own dynamics in every cycle (not only to the
/// axis envelope): velocity × override, acceleration, deceleration, jerk — and it reaches them.
#[test]
fn the_rig_holds_a_move_from_rest_to_its_own_dynamics() {
    let mut r = Rig::new(1);
    r.power_on_with_override(0, 50.0);
    let mut m = mv(100.0, 300.0);
    m.dynamics = Dynamics {
        acceleration: 800.0,
        deceleration: 400.0,
        jerk: 9000.0,
    };
    let a = r.ok(0, CommandKind::MoveAbsolute(m));
    let t = r.from_rest[0].expect("checked");
    assert_eq!(
        (t.velocity, t.acceleration, t.deceleration, t.jerk),
        (150.0, 800.0, 400.0, 9000.0)
    );
    let from = r.history[0].len();
    let cycles = r.from_rest_cycles;
    r.until(3.0, |r| !r.out(a).busy);
    assert!(r.from_rest_cycles - cycles > 500);
    let h = &r.history[0][from..];
    let peak = |f: fn(&AxisStatus) -> f64| h.iter().map(f).fold(0.0, f64::max);
    assert!(peak(|s| s.set_velocity) > 149.9);
    assert!(peak(|s| s.set_acceleration) > 799.0);
    assert!(peak(|s| -s.set_acceleration) > 399.0);
    // A command on the axis ends the check.
    let v = r.ok(0, velocity(100.0, Direction::Positive));
    assert_eq!(r.from_rest[0].map(|t| t.command), Some(v));
    r.ok(
        0,
        CommandKind::SetOverride {
            velocity_factor: 0.5,
        },
    );
    assert!(r.from_rest[0].is_none());
}

#[test]
#[should_panic(expected = "above the command's acceleration")]
fn the_rig_catches_a_move_from_rest_above_its_own_acceleration() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 300.0)));
    // As if the command had asked for less than the axis default (2000) it runs with.
    r.from_rest[0].as_mut().unwrap().acceleration = 1900.0;
    r.run(1.0);
}

#[test]
fn jerk_and_acceleration_limits_hold_for_an_aborting_reversal() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.bounds[0].acceleration = 2000.0;
    r.bounds[0].jerk = 20000.0;
    r.ok(0, CommandKind::MoveAbsolute(mv(300.0, 500.0)));
    r.run(0.25);
    let b = r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 500.0)));
    r.until(5.0, |r| r.out(b).done);
}

#[test]
fn coupling_loops_and_self_coupling_are_rejected_master_loss_is_an_error() {
    let mut r = Rig::new(3);
    for a in 0..3 {
        r.power_on(a);
    }
    assert_eq!(
        r.rejected(
            0,
            CommandKind::GearIn {
                master: 0,
                ratio_numerator: 1.0,
                ratio_denominator: 1
            }
        ),
        ErrorId::MASTER_INVALID
    );
    assert_eq!(
        r.rejected(
            0,
            CommandKind::GearIn {
                master: 9,
                ratio_numerator: 1.0,
                ratio_denominator: 1
            }
        ),
        ErrorId::MASTER_INVALID
    );
    r.ok(
        1,
        CommandKind::GearIn {
            master: 0,
            ratio_numerator: 1.0,
            ratio_denominator: 1,
        },
    );
    r.ok(
        2,
        CommandKind::GearIn {
            master: 1,
            ratio_numerator: 1.0,
            ratio_denominator: 1,
        },
    );
    assert_eq!(
        r.rejected(
            0,
            CommandKind::GearIn {
                master: 2,
                ratio_numerator: 1.0,
                ratio_denominator: 1
            }
        ),
        ErrorId::MASTER_INVALID
    );
    // A chain follows in one cycle (masters are stepped first).
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 10.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(0.2);
    assert_eq!(r.st(2).set_position, r.st(0).set_position);
    // The master faults: its slaves go to ErrorStop with master_lost.
    r.plants[0].fault = true;
    r.run(0.01);
    assert_eq!(r.st(1).state, AxisState::ErrorStop);
    assert_eq!(r.st(1).error_id, ErrorId::MASTER_LOST.0);
}

#[test]
fn velocity_never_exceeds_commanded_velocity_times_override_in_any_cycle() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 50.0,
        },
    );
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(300.0, 200.0)));
    r.until(10.0, |r| {
        let v = r.st(0).set_velocity.abs();
        assert!(v <= 100.0 + 1e-9, "{v} > 200 × 50 %");
        !r.out(a).busy
    });
    // Second run: override changed mid-move.
    let b = r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 200.0)));
    r.run(0.5);
    r.ok(
        0,
        CommandKind::SetOverride {
            velocity_factor: 0.4,
        },
    );
    let v_before = r.st(0).set_velocity.abs();
    r.step();
    assert!(
        (r.st(0).set_velocity.abs() - v_before).abs() < 1000.0 * DT + 1e-9,
        "velocity jumped on override"
    );
    r.run(0.3);
    r.until(10.0, |r| {
        assert!(r.st(0).set_velocity.abs() <= 40.0 + 1e-9);
        !r.out(b).busy
    });
    assert!(r.out(b).done);
}

// ---------------------------------------------------------------- GearInDyn, superposition

#[test]
fn s11a_29_gear_in_dyn_release_freezes_ratio_gear_out_while_enabled_recouples() {
    let mut r = Rig::new(2);
    r.power_on(0);
    r.power_on(1);
    r.bounds[1].jerk = 1e9; // ratio ramps are acceleration-limited, not jerk-limited
    let g = r.ok(
        1,
        CommandKind::GearInDyn {
            master: 0,
            gear_ratio: 1.0,
            acceleration: 0.0,
        },
    );
    assert!(r.out(g).in_gear && r.out(g).busy);
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 100.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(0.5);
    assert!((r.st(1).set_velocity - 100.0).abs() < 1e-6);
    // A new ratio while enabled: ramps (acceleration-limited), in_gear when reached.
    let g2 = r.ok(
        1,
        CommandKind::GearInDyn {
            master: 0,
            gear_ratio: 1.5,
            acceleration: 500.0,
        },
    );
    assert!(r.out(g).done && !r.out(g).busy);
    assert!(!r.out(g2).in_gear);
    let mut amax: f64 = 0.0;
    r.until(2.0, |r| {
        amax = amax.max(r.st(1).set_acceleration.abs());
        r.out(g2).in_gear
    });
    assert!((r.st(1).set_velocity - 150.0).abs() < 1e-6);
    // 500 at the master's maximum velocity (500): 100 at its actual 100 mm/s.
    assert!(amax <= 500.0 * 100.0 / 500.0 + 1e-6, "{amax}");
    // GearOut while enabled: decoupled for an instant, recoupled.
    let o = r.ok(1, CommandKind::GearOut);
    assert!(r.out(o).done);
    assert_eq!(r.st(1).state, AxisState::SynchronizedMotion);
    r.run(0.1);
    assert!((r.st(1).set_velocity - 150.0).abs() < 1e-6);
    // Enable FALSE: command ends, ratio frozen, still coupled.
    r.ok(1, CommandKind::Release { target: g2 });
    let o2 = r.out(g2);
    assert!(!o2.busy && o2.done && o2.in_gear);
    r.run(0.2);
    assert_eq!(r.st(1).state, AxisState::SynchronizedMotion);
    assert!((r.st(1).gear_ratio - 1.5).abs() < 1e-12);
    // Now GearOut really decouples.
    r.ok(1, CommandKind::GearOut);
    assert_eq!(r.st(1).state, AxisState::ContinuousMotion);
}

fn conveyor(velocity: f64) -> Rig {
    let mut p = params();
    p.axis_velo_max = 1500.0;
    let mut r = Rig::with(vec![(false, p)]);
    r.bounds[0].jerk = 1e9; // the superposition profile is C² but not jerk-limited
    r.power_on(0);
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(1.0);
    r
}

#[test]
fn s11a_30_superposition_conveyor_example_and_infeasible_warning() {
    // Spec §5.2.2 example 1: gap 1800 → 1500 mm, 300 mm to make up within 1000 mm of belt,
    // speed reserve 500 mm/s, velocity reduction, limited motion.
    let mut r = conveyor(500.0);
    let start = r.st(0).set_position;
    let sp = Superposition {
        mode: SuperpositionMode::VeloReductionLimitedMotion,
        distance: 300.0,
        velocity_diff: 500.0,
        acceleration: 0.0,
        deceleration: 0.0,
        velocity_process: 500.0,
        length: 1000.0,
        abort_option: SuperpositionAbortOption::AbortAtStandstill,
    };
    let s = r.ok(0, CommandKind::MoveSuperImposed(sp));
    assert!(r.st(0).compensating);
    // While it runs, the axis is 300 mm ahead of the conveyor at the end, within 1000 mm.
    let t0 = r.k.cycle();
    r.until(5.0, |r| !r.out(s).busy);
    let o = r.out(s);
    assert!(o.done && !o.warning, "{o:?}");
    let travelled = r.st(0).set_position - start;
    let base = 500.0 * (r.k.cycle() - t0) as f64 * DT;
    assert!(
        (travelled - base - 300.0).abs() < 1.0,
        "ahead by {}",
        travelled - base
    );
    assert!(travelled <= 1000.0 + 1.0, "used {travelled} mm");
    assert!(
        r.history[0]
            .iter()
            .all(|h| h.set_velocity <= 500.0 + 500.0 + 1e-6)
    );
    assert_eq!(r.st(0).state, AxisState::ContinuousMotion);
    assert!((r.st(0).set_velocity - 500.0).abs() < 1e-9);

    // Infeasible: the same distance within 400 mm → warning 0x4243, less distance.
    let mut r = conveyor(500.0);
    let start = r.st(0).set_position;
    let s = r.ok(
        0,
        CommandKind::MoveSuperImposed(Superposition {
            length: 400.0,
            ..sp
        }),
    );
    assert!(r.out(s).warning);
    assert_eq!(r.out(s).warning_id, ErrorId::SUPERPOSITION_INCOMPLETE.0);
    let t0 = r.k.cycle();
    r.until(5.0, |r| !r.out(s).busy);
    assert!(r.out(s).done && r.out(s).warning);
    let ahead = r.st(0).set_position - start - 500.0 * (r.k.cycle() - t0) as f64 * DT;
    assert!(ahead < 300.0 - 1.0 && ahead > 0.0, "{ahead}");
}

/// MC_MoveSuperImposed: 50 more over 400 of main travel at 200 (velocity reduction, additive).
fn superimpose_50_over_400(abort_option: SuperpositionAbortOption) -> CommandKind {
    CommandKind::MoveSuperImposed(Superposition {
        mode: SuperpositionMode::VeloReductionAdditiveMotion,
        distance: 50.0,
        velocity_diff: 200.0,
        velocity_process: 200.0,
        length: 400.0,
        abort_option,
        ..Default::default()
    })
}

/// What happens to the main motion in one row of the superposition abort table (spec §6.13).
#[derive(Clone, Copy, Debug, PartialEq)]
enum MainMotion {
    /// Row 1: override 0 %.
    OverrideZero,
    /// Row 2: a temporary standstill (a gear slave whose master halts and starts again).
    TemporaryStandstill,
    /// Row 3: the main motion reverses.
    Reversal,
    /// Row 4: the axis reaches its target.
    ReachedTarget,
    /// Row 4: the axis is stopped (MC_Halt).
    Stopped,
    /// Row 5: MC_Reset.
    Reset,
    /// Row 5: MC_Power Enable FALSE.
    PowerOff,
    /// Row 6: a slave is decoupled (MC_GearOut).
    Decoupled,
}

/// §11a #31: every row × column of the superposition abort table (spec §6.13): whether the
/// superposition is aborted, and when it continues, that it completes once the main motion
/// goes on.
#[test]
fn s11a_31_superposition_abort_table_every_row_and_column() {
    use MainMotion::*;
    use SuperpositionAbortOption::*;
    // (row event, aborted with AbortAtStandstill, ResumeAfterStandstill, ResumeAfterMotionStop)
    let table = [
        (OverrideZero, [false, false, false]),
        (TemporaryStandstill, [true, false, false]),
        (Reversal, [true, false, false]),
        (ReachedTarget, [true, true, false]),
        (Stopped, [true, true, false]),
        (Reset, [true, true, true]),
        (PowerOff, [true, true, true]),
        (Decoupled, [true, true, true]),
    ];
    for (event, aborted) in table {
        for (option, aborted) in [
            AbortAtStandstill,
            ResumeAfterStandstill,
            ResumeAfterMotionStop,
        ]
        .into_iter()
        .zip(aborted)
        {
            let what = format!("{event:?} / {option:?}");
            // The superposed axis (a slave of axis 0 for the coupling rows) runs at 200.
            let slave = matches!(event, TemporaryStandstill | Decoupled);
            let mut p = params();
            p.axis_velo_max = 1500.0;
            let mut r = Rig::with(vec![(false, p.clone()), (false, p)]);
            r.bounds[1].jerk = 1e9; // the superposition profile is C² but not jerk-limited
            r.power_on(0);
            r.power_on(1);
            if slave {
                r.ok(
                    1,
                    CommandKind::GearIn {
                        master: 0,
                        ratio_numerator: 1.0,
                        ratio_denominator: 1,
                    },
                );
                r.ok(0, velocity(200.0, Direction::Positive));
            } else if event == ReachedTarget {
                r.ok(1, CommandKind::MoveAbsolute(mv(200.0, 200.0)));
            } else {
                r.ok(1, velocity(200.0, Direction::Positive));
            }
            r.run(0.5);
            let s = r.ok(1, superimpose_50_over_400(option));
            r.run(0.2);
            assert!(r.out(s).busy, "{what}: running before the event");
            match event {
                OverrideZero => {
                    r.ok(
                        1,
                        CommandKind::SetOverride {
                            velocity_factor: 0.0,
                        },
                    );
                }
                TemporaryStandstill => {
                    r.ok(0, halt());
                }
                Reversal => {
                    r.ok(1, velocity(200.0, Direction::Negative));
                }
                ReachedTarget => {}
                Stopped => {
                    r.ok(1, halt());
                }
                Reset => {
                    r.ok(1, CommandKind::Reset);
                }
                PowerOff => {
                    r.ok(1, power_off());
                }
                Decoupled => {
                    r.ok(1, CommandKind::GearOut);
                }
            }
            // Long enough for the main motion to stand still, reverse or reach its target.
            r.run(1.0);
            let o = r.out(s);
            if aborted {
                assert!(o.command_aborted && !o.busy, "{what}: {o:?}");
                continue;
            }
            assert!(o.busy && !o.command_aborted, "{what}: {o:?}");
            // The main motion goes on: the superposition completes.
            match event {
                OverrideZero => {
                    r.ok(
                        1,
                        CommandKind::SetOverride {
                            velocity_factor: 1.0,
                        },
                    );
                }
                TemporaryStandstill => {
                    r.ok(0, velocity(200.0, Direction::Positive));
                }
                ReachedTarget | Stopped => {
                    r.ok(1, velocity(200.0, Direction::Positive));
                }
                _ => {}
            }
            r.until(10.0, |r| !r.out(s).busy);
            let o = r.out(s);
            assert!(o.done && !o.warning, "{what}: {o:?}");
        }
    }
}

#[test]
fn s11a_31_superposition_abort_options() {
    let sp = |abort_option| Superposition {
        mode: SuperpositionMode::VeloReductionAdditiveMotion,
        distance: 50.0,
        velocity_diff: 200.0,
        acceleration: 0.0,
        deceleration: 0.0,
        velocity_process: 200.0,
        length: 400.0,
        abort_option,
    };
    use SuperpositionAbortOption::*;
    // Row 1: override 0 → continues (all options).
    for opt in [
        AbortAtStandstill,
        ResumeAfterStandstill,
        ResumeAfterMotionStop,
    ] {
        let mut r = conveyor(200.0);
        let s = r.ok(0, CommandKind::MoveSuperImposed(sp(opt)));
        r.run(0.2);
        r.ok(
            0,
            CommandKind::SetOverride {
                velocity_factor: 0.0,
            },
        );
        r.run(2.0);
        assert!(r.out(s).busy, "{opt:?}: aborted by override 0");
        r.ok(
            0,
            CommandKind::SetOverride {
                velocity_factor: 1.0,
            },
        );
        r.until(5.0, |r| !r.out(s).busy);
        assert!(r.out(s).done, "{opt:?}");
    }
    // Row 2/4: the main motion stops (halt) → abort unless ResumeAfterMotionStop.
    for (opt, survives) in [
        (AbortAtStandstill, false),
        (ResumeAfterStandstill, false),
        (ResumeAfterMotionStop, true),
    ] {
        let mut r = conveyor(200.0);
        let s = r.ok(0, CommandKind::MoveSuperImposed(sp(opt)));
        r.run(0.2);
        r.ok(
            0,
            CommandKind::Halt {
                deceleration: 0.0,
                jerk: 0.0,
                buffer_mode: BufferMode::Aborting,
                options: MoveOptions::default(),
            },
        );
        r.run(1.0);
        assert_eq!(r.out(s).busy, survives, "{opt:?}");
        assert_eq!(r.out(s).command_aborted, !survives, "{opt:?}");
        if survives {
            // Resumes with the next motion and completes.
            r.ok(
                0,
                CommandKind::MoveVelocity {
                    velocity: 200.0,
                    dynamics: Dynamics::default(),
                    direction: Direction::Positive,
                    buffer_mode: BufferMode::Aborting,
                    options: MoveOptions::default(),
                },
            );
            r.until(5.0, |r| !r.out(s).busy);
            assert!(r.out(s).done);
        }
    }
    // Row 3: reversal of the main motion → abort only with AbortAtStandstill.
    for (opt, survives) in [(AbortAtStandstill, false), (ResumeAfterStandstill, true)] {
        let mut r = conveyor(200.0);
        let s = r.ok(0, CommandKind::MoveSuperImposed(sp(opt)));
        r.run(0.1);
        r.ok(
            0,
            CommandKind::MoveVelocity {
                velocity: 200.0,
                dynamics: Dynamics::default(),
                direction: Direction::Negative,
                buffer_mode: BufferMode::Aborting,
                options: MoveOptions::default(),
            },
        );
        r.run(0.6);
        assert_eq!(r.out(s).command_aborted, !survives, "{opt:?}");
    }
    // Row 5: reset / enable off → abort (all).
    let mut r = conveyor(200.0);
    let s = r.ok(0, CommandKind::MoveSuperImposed(sp(ResumeAfterMotionStop)));
    r.run(0.1);
    r.ok(
        0,
        CommandKind::Power {
            enable: false,
            enable_positive: false,
            enable_negative: false,
            override_percent: 100.0,
        },
    );
    assert!(r.out(s).command_aborted);
    // At standstill it is rejected (nothing to superimpose on).
    let mut r = Rig::new(1);
    r.power_on(0);
    assert_eq!(
        r.rejected(0, CommandKind::MoveSuperImposed(sp(AbortAtStandstill))),
        ErrorId::AXIS_NOT_MOVING
    );
}

/// The largest velocity change of a cycle beyond what its accelerations allow (a velocity
/// step; the superposition is acceleration- but not jerk-limited, so the rig's jerk bound is
/// lifted in these tests and cannot see one).
fn max_velocity_step(history: &[AxisStatus]) -> f64 {
    history
        .windows(2)
        .map(|w| {
            let dv = (w[1].set_velocity - w[0].set_velocity).abs();
            let a = w[0].set_acceleration.abs().max(w[1].set_acceleration.abs());
            (dv - a * DT).max(0.0)
        })
        .fold(0.0, f64::max)
}

/// An aborted superposition hands the velocity it was adding to the main motion, which is
/// re-planned from there: no velocity step (it was a step of what the superposition added).
#[test]
fn an_aborted_superposition_leaves_no_velocity_step() {
    use SuperpositionAbortOption::*;
    let halt = halt();
    for (option, then) in [
        (AbortAtStandstill, halt),
        (ResumeAfterStandstill, halt),
        (AbortAtStandstill, velocity(200.0, Direction::Negative)),
        (AbortAtStandstill, CommandKind::AbortSuperposition),
    ] {
        let mut r = conveyor(200.0);
        let s = r.ok(0, superimpose_50_over_400(option));
        r.run(0.2);
        assert!(r.st(0).set_velocity > 201.0, "adding velocity");
        r.ok(0, then);
        r.until(1.0, |r| !r.out(s).busy);
        assert!(r.out(s).command_aborted, "{option:?} {then:?}");
        r.run(0.5);
        let step = max_velocity_step(&r.history[0]);
        assert!(step < 0.1, "{option:?} {then:?}: velocity step {step}");
    }
}

#[test]
fn superposition_shifts_the_target_of_the_running_move() {
    let mut r = Rig::new(1);
    r.bounds[0].jerk = 1e9;
    r.power_on(0);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(400.0, 200.0)));
    r.run(0.5);
    let s = r.ok(
        0,
        CommandKind::MoveSuperImposed(Superposition {
            mode: SuperpositionMode::LengthReductionAdditiveMotion,
            distance: 20.0,
            velocity_diff: 100.0,
            acceleration: 0.0,
            deceleration: 0.0,
            velocity_process: 200.0,
            length: 200.0,
            abort_option: SuperpositionAbortOption::AbortAtStandstill,
        }),
    );
    r.until(5.0, |r| !r.out(m).busy);
    assert!(r.out(s).done);
    assert!(r.out(m).done);
    assert!(
        (r.st(0).set_position - 420.0).abs() < 1e-9,
        "{}",
        r.st(0).set_position
    );
}

/// Decision: a superposition never moves the target of the running move beyond an enabled
/// soft limit. It is limited (done as far as the limit allows, Warning 0x4243), not refused.
#[test]
fn superposition_is_limited_to_keep_the_target_within_the_soft_limits() {
    // A positive distance gets ahead in the direction of travel, towards the limit there.
    for target in [400.0f64, -400.0] {
        let distance = 20.0;
        let mut r = Rig::with(vec![(false, params_with_soft_limits(-410.0, 410.0))]);
        r.bounds[0].jerk = 1e9; // the superposition profile is C² but not jerk-limited
        r.power_on(0);
        let m = r.ok(0, CommandKind::MoveAbsolute(mv(target, 200.0)));
        r.run(0.5);
        let sp = Superposition {
            mode: SuperpositionMode::LengthReductionAdditiveMotion,
            distance,
            velocity_diff: 100.0,
            velocity_process: 200.0,
            length: 200.0,
            abort_option: SuperpositionAbortOption::AbortAtStandstill,
            ..Default::default()
        };
        let s = r.ok(0, CommandKind::MoveSuperImposed(sp));
        let o = r.out(s);
        assert!(o.busy && o.warning, "{o:?}");
        assert_eq!(o.warning_id, ErrorId::SUPERPOSITION_INCOMPLETE.0);
        let limit = 410.0 * target.signum();
        assert_eq!(r.st(0).target_position, target, "shifts as it goes");
        r.until(5.0, |r| !r.out(m).busy);
        assert!(r.out(m).done);
        let o = r.out(s);
        assert!(o.done && o.warning, "done as far as possible: {o:?}");
        assert!((r.st(0).set_position - limit).abs() < 1e-9, "{:?}", r.st(0));
        assert!(r.history[0].iter().all(
            |h| h.set_position.abs() <= 410.0 + 1e-9 && h.target_position.abs() <= 410.0 + 1e-9
        ));
        // Away from the limit, or within it, the distance is done in full.
        let m = r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 200.0)));
        r.run(0.5);
        let s = r.ok(
            0,
            CommandKind::MoveSuperImposed(Superposition {
                distance: -distance,
                ..sp
            }),
        );
        assert!(!r.out(s).warning);
        r.until(5.0, |r| !r.out(m).busy);
        assert!(r.out(s).done && !r.out(s).warning, "{:?}", r.out(s));
        // Falling back on the way to 0: the target moves back, away from 0.
        assert!((r.st(0).set_position - distance * target.signum()).abs() < 1e-9);
    }
}

/// Endless motion under a superposition stops for the soft limit: the superposition ends
/// (abort table row 4: the main motion is stopped) and hands its velocity to the stop; one
/// that resumes after a motion stop is held at the limit. Either way the limit holds.
#[test]
fn superposition_on_endless_motion_never_carries_it_past_a_soft_limit() {
    use SuperpositionAbortOption::*;
    for option in [
        AbortAtStandstill,
        ResumeAfterStandstill,
        ResumeAfterMotionStop,
    ] {
        let mut p = params();
        p.axis_en_max_soft_pos_limit = true;
        p.axis_max_soft_pos_limit = 300.0;
        let mut r = Rig::with(vec![(false, p)]);
        r.bounds[0].jerk = 1e9;
        r.power_on(0);
        let v = r.ok(0, velocity(200.0, Direction::Positive));
        r.until(3.0, |r| r.st(0).set_position > 200.0);
        let s = r.ok(
            0,
            CommandKind::MoveSuperImposed(Superposition {
                mode: SuperpositionMode::VeloReductionAdditiveMotion,
                distance: 100.0,
                velocity_diff: 100.0,
                velocity_process: 200.0,
                length: 300.0,
                abort_option: option,
                ..Default::default()
            }),
        );
        r.until(3.0, |r| !r.out(v).busy);
        assert_eq!(r.out(v).error_id, ErrorId::SOFT_LIMIT_REACHED.0);
        r.until(3.0, |r| r.st(0).state == AxisState::Standstill);
        let o = r.out(s);
        if option == ResumeAfterMotionStop {
            // It would resume, but what it still has to do lies beyond the limit.
            assert!(o.done && o.warning, "{option:?}: {o:?}");
            assert_eq!(o.warning_id, ErrorId::SUPERPOSITION_INCOMPLETE.0);
        } else {
            assert!(o.command_aborted, "{option:?}: {o:?}");
        }
        assert!(
            r.history[0].iter().all(|h| h.set_position <= 300.0 + 1e-9),
            "{option:?}: past the limit"
        );
        assert!(r.st(0).set_position > 290.0, "{option:?}: {:?}", r.st(0));
        let step = max_velocity_step(&r.history[0]);
        assert!(step < 0.1, "{option:?}: velocity step {step}");
    }
}

/// A superposition that resumes with the next motion is held within the soft limits by that
/// motion's target too: it does what still fits, with the warning.
#[test]
fn a_resumed_superposition_is_limited_by_the_next_moves_target() {
    let mut p = params();
    p.axis_en_max_soft_pos_limit = true;
    p.axis_max_soft_pos_limit = 410.0;
    let mut r = Rig::with(vec![(false, p)]);
    r.bounds[0].jerk = 1e9;
    r.power_on(0);
    r.ok(0, velocity(200.0, Direction::Positive));
    r.run(0.5);
    let s = r.ok(
        0,
        CommandKind::MoveSuperImposed(Superposition {
            mode: SuperpositionMode::VeloReductionAdditiveMotion,
            distance: 40.0,
            velocity_diff: 100.0,
            velocity_process: 200.0,
            length: 400.0,
            abort_option: SuperpositionAbortOption::ResumeAfterMotionStop,
            ..Default::default()
        }),
    );
    r.run(0.3);
    let applied = r.st(0).superimposed_distance;
    assert!(applied > 0.0 && applied < 20.0, "{applied}");
    // A move to 400 leaves room for 10 more: less than the superposition still has to do.
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(400.0, 200.0)));
    r.until(5.0, |r| !r.out(m).busy);
    assert!(r.out(m).done);
    let o = r.out(s);
    assert!(
        o.busy && o.warning,
        "resumes after the motion stop, reduced: {o:?}"
    );
    assert!(r.st(0).set_position <= 410.0 + 1e-9, "{:?}", r.st(0));
    // It completes (what is left of it) with the next motion.
    r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 200.0)));
    r.until(5.0, |r| !r.out(s).busy);
    let o = r.out(s);
    assert!(o.done && o.warning, "{o:?}");
    assert!(r.history[0].iter().all(|h| h.set_position <= 410.0 + 1e-9));
    let step = max_velocity_step(&r.history[0]);
    assert!(step < 0.1, "velocity step {step}");
}

#[test]
fn superposition_across_a_blend_handoff_stays_continuous() {
    // Found by the property test: a blending successor must plan from the main motion alone,
    // not from the main motion minus the superposition twice.
    let mut r = Rig::new(1);
    r.bounds[0].jerk = 1e12;
    r.bounds[0].acceleration *= 2.0;
    r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 65.0,
        },
    );
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
    r.ok(0, CommandKind::MoveRelative(mv(173.0, 467.0)));
    let b = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 1.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::BlendingPrevious,
            options: MoveOptions::default(),
        },
    );
    r.run(0.078);
    r.ok(
        0,
        CommandKind::MoveSuperImposed(Superposition {
            mode: SuperpositionMode::LengthReductionAdditiveMotion,
            distance: -77.0,
            velocity_diff: 215.0,
            acceleration: 0.0,
            deceleration: 0.0,
            velocity_process: 1.0,
            length: 788.0,
            abort_option: SuperpositionAbortOption::AbortAtStandstill,
        }),
    );
    r.until(3.0, |r| r.out(b).active);
    r.run(0.5);
}

#[test]
fn hardware_limit_switch_stops_fast_and_blocks_that_direction_only() {
    let mut r = Rig::new(1);
    r.power_on(0);
    let v = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 200.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(0.5);
    r.plants[0].limit_positive = true;
    r.step();
    r.step();
    // An end of travel is an axis error: ErrorStop with the switch's error, not a standstill
    // that a client could mistake for a finished move.
    assert_eq!(r.out(v).error_id, ErrorId::LIMIT_SWITCH.0);
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    assert_eq!(r.st(0).error_id, ErrorId::LIMIT_SWITCH.0);
    r.until(1.0, |r| !r.st(0).moving);
    let reset = r.ok(0, CommandKind::Reset);
    assert!(r.out(reset).done);
    assert_eq!(r.st(0).state, AxisState::Standstill);
    // Braked with the fast-stop deceleration (5000), not the axis default (1000).
    let amin = r.history[0]
        .iter()
        .map(|s| s.set_acceleration)
        .fold(0.0, f64::min);
    assert!(amin < -1000.0 - 1.0, "{amin}");
    // Moving further into the switch is refused; moving off it is fine.
    assert_eq!(
        r.rejected(0, CommandKind::MoveRelative(mv(1.0, 10.0))),
        ErrorId::LIMIT_SWITCH
    );
    let back = r.ok(0, CommandKind::MoveRelative(mv(-5.0, 10.0)));
    r.until(2.0, |r| r.out(back).done);
}

#[test]
fn homing_reference_modes_plc_cam_and_drive_latch_on_the_cam_edge() {
    // PLC cam (#1076 = 1): the reference is the falling edge of the cam seen by the kernel.
    let mut p = params();
    p.axis_encoder_reference_mode = 1;
    let mut r = Rig::with(vec![(false, p)]);
    r.plants[0].cam = Some((50.0, 55.0));
    r.power_on(0);
    let h = home_by_sequence(&mut r, 0.0);
    assert!(r.out(h).done);
    r.run(0.01);
    // Leaving the cam forwards (the default sync direction), its falling edge is at 55
    // (within one cycle of travel at the sync velocity 5 mm/s, the resolution of a PLC cam).
    let zero_at_drive = r.plants[0].pos - r.st(0).actual_position;
    assert!(
        (zero_at_drive - 55.0).abs() <= 5.0 * DT + 1e-9,
        "{zero_at_drive}"
    );

    // Hardware latch on the rising cam edge (#1076 = 3), found while searching: exact.
    let mut p = params();
    p.axis_encoder_reference_mode = 3;
    let mut r = Rig::with(vec![(false, p)]);
    r.plants[0].cam = Some((50.0, 55.0));
    r.power_on(0);
    let h = home_by_sequence(&mut r, 7.0);
    assert!(r.out(h).done);
    r.run(0.01);
    let at = r.plants[0].pos - (r.st(0).actual_position - 7.0);
    assert!((at - 50.0).abs() < 1e-9, "{at}");
}

/// Spec §5.3.1: with the cam already active at the start, homing begins at phase 3 (leave
/// the cam) — also in the drive-latch modes (#1076 = 3, 4, 6, 7), which leave the cam against
/// the search direction and search it again: they latch the same cam edge as a search from
/// outside (rising: the cam's start 50, falling: its end 55, searching positive).
#[test]
fn homing_with_the_cam_active_at_the_start_begins_by_leaving_the_cam_in_every_mode() {
    use ReferenceMode::*;
    for (mode, edge) in [
        (HardwareLatchPos, Some(50.0)),
        (HardwareLatchNeg, Some(55.0)),
        (SoftDriveLatchPos, Some(50.0)),
        (SoftDriveLatchNeg, Some(55.0)),
        (PlcCam, None),
        (HardwareSync, None),
    ] {
        let mut references = vec![];
        for start in [0.0, 52.0] {
            let mut r = Rig::new(1);
            r.plants[0].cam = Some((50.0, 55.0));
            r.plants[0].index_period = Some(8.0);
            r.plants[0].pos = start;
            r.power_on(0);
            let h = r.ok(
                0,
                CommandKind::Home {
                    position: Some(7.0),
                    mode: HomingMode::Default,
                    options: HomingOptions {
                        reference_mode: Some(mode),
                        ..HomingOptions::default()
                    },
                },
            );
            let mut phases = vec![r.st(0).homing_phase];
            r.until(20.0, |r| {
                let p = r.st(0).homing_phase;
                if phases.last() != Some(&p) {
                    phases.push(p);
                }
                !r.out(h).busy
            });
            assert!(r.out(h).done, "{mode:?} from {start}: {:?}", r.out(h));
            if start == 52.0 {
                assert_eq!(phases[0], HomingPhase::LeaveCam, "{mode:?}: {phases:?}");
            } else {
                assert_eq!(phases[0], HomingPhase::SearchCam, "{mode:?}: {phases:?}");
            }
            r.run(0.01);
            // Where the drive position that became 7 lies.
            references.push(r.plants[0].pos - (r.st(0).actual_position - 7.0));
        }
        if let Some(edge) = edge {
            for at in &references {
                assert!((at - edge).abs() < 1e-9, "{mode:?}: {references:?}");
            }
        } else {
            // The same reference (cam left backwards; PLC cam to within one cycle of travel).
            assert!(
                (references[0] - references[1]).abs() <= 5.0 * DT + 1e-9,
                "{mode:?}: {references:?}"
            );
        }
    }
}

#[test]
fn gear_coupling_to_the_masters_actual_values_with_parameter_1064() {
    let mut ps = params();
    ps.axis_couple_slave_to_actual_values = true;
    let mut pm = params();
    pm.axis_max_pos_lag_value = 10.0;
    let mut r = Rig::with(vec![(false, pm), (false, ps)]);
    r.plants[0].tau = 0.02; // the master lags behind its setpoint (2 mm at 100 mm/s)
    r.power_on(0);
    r.power_on(1);
    r.ok(
        1,
        CommandKind::GearIn {
            master: 0,
            ratio_numerator: 1.0,
            ratio_denominator: 1,
        },
    );
    r.bounds[1].jerk = 1e12; // an actual value is not jerk-limited
    r.bounds[1].acceleration = 1e12;
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 100.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(0.3);
    let (m, s) = (r.st(0), r.st(1));
    // The slave follows the master's actual position (one cycle late), not its setpoint.
    assert!(
        (s.set_position - m.actual_position).abs() < 0.2,
        "{} vs {}",
        s.set_position,
        m.actual_position
    );
    assert!(
        (s.set_position - m.set_position).abs() > 1.0,
        "follows the set value"
    );
}

// ---------------------------------------------------------------- review regressions

#[test]
fn a_second_homing_run_never_uses_a_latch_left_from_an_aborted_one() {
    let mut r = Rig::new(1);
    r.plants[0].cam = Some((50.0, 55.0));
    r.plants[0].index_period = Some(8.0);
    r.power_on(0);
    let h = r.ok(
        0,
        CommandKind::Home {
            position: Some(100.0),
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    r.until(20.0, |r| r.st(0).homing_phase == HomingPhase::WaitLatch);
    r.run(0.1); // latch armed; the next pulse (56) is not reached yet
    let s = r.ok(
        0,
        CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: MoveOptions::default(),
        },
    );
    assert!(r.out(h).command_aborted);
    r.until(2.0, |r| r.out(s).done);
    r.ok(0, CommandKind::Release { target: s });
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(200.0, 300.0)));
    r.until(5.0, |r| r.out(m).done);
    r.plants[0].cam = Some((250.0, 255.0));
    let h2 = r.ok(
        0,
        CommandKind::Home {
            position: Some(100.0),
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    r.until(30.0, |r| !r.out(h2).busy);
    assert!(r.out(h2).done);
    r.run(0.01);
    // Referenced to the pulse at 256 (above the new cam), not the stale one at 56.
    let zero = r.plants[0].pos - (r.st(0).actual_position - 100.0);
    assert!((zero - 256.0).abs() < 1e-9, "{zero}");
}

#[test]
fn a_stop_whose_position_window_times_out_ends_with_the_error_and_unlocks() {
    let mut p = params();
    p.axis_in_target_timeout = 0.2;
    p.axis_en_position_lag_monitoring = false;
    let mut r = Rig::with(vec![(false, p)]);
    r.power_on(0);
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 100.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(0.3);
    r.plants[0].load_lag = 0.5;
    let s = r.ok(
        0,
        CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: MoveOptions {
                enable_stop_position_monitoring: true,
                ..MoveOptions::default()
            },
        },
    );
    r.until(3.0, |r| !r.out(s).busy);
    assert_eq!(r.out(s).error_id, ErrorId::IN_TARGET_TIMEOUT.0);
    assert_eq!(r.st(0).state, AxisState::Standstill);
    assert!(!r.st(0).motion_commands_locked);
}

#[test]
fn s11a_15_a_valid_blending_position_is_where_the_successor_takes_over() {
    let mut r = Rig::new(1);
    r.power_on(0);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 100.0)));
    let mut m = mvb(200.0, 100.0, BufferMode::BlendingNext);
    m.options.blending_position = Some(50.0);
    let b = r.ok(0, CommandKind::MoveAbsolute(m));
    assert!(!r.out(b).active);
    r.until(3.0, |r| r.out(b).active);
    let p = r.st(0).set_position;
    assert!((50.0..51.0).contains(&p), "took over at {p}");
    assert!(r.out(a).command_aborted);
    // Behind an endless motion a blending position buffers too.
    let v = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 50.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    let here = r.st(0).set_position;
    let mut m = mvb(here + 100.0, 50.0, BufferMode::BlendingLow);
    m.options.blending_position = Some(here + 20.0);
    let c = r.ok(0, CommandKind::MoveAbsolute(m));
    assert!(r.out(v).busy && !r.out(c).active);
    r.until(3.0, |r| r.out(c).active);
    assert!(r.st(0).set_position >= here + 20.0);
    r.until(5.0, |r| r.out(c).done);
}

#[test]
fn halt_buffered_with_blending_previous_starts_its_ramp_at_the_original_target() {
    let mut r = Rig::new(1);
    r.power_on(0);
    r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 100.0)));
    let h = r.ok(
        0,
        CommandKind::Halt {
            deceleration: 0.0,
            jerk: 0.0,
            buffer_mode: BufferMode::BlendingPrevious,
            options: MoveOptions::default(),
        },
    );
    r.until(5.0, |r| r.out(h).done);
    let h_ = &r.history[0];
    let at_target = h_.iter().find(|s| s.set_position >= 100.0).unwrap();
    assert!(
        at_target.set_velocity > 90.0,
        "passed the target at {}",
        at_target.set_velocity
    );
    assert!(
        r.st(0).set_position > 100.0 + 1.0,
        "stopped at {}",
        r.st(0).set_position
    );
}

#[test]
fn override_applies_to_a_move_with_a_pending_blend() {
    let mut r = Rig::new(1);
    r.power_on(0);
    r.ok(0, CommandKind::MoveAbsolute(mv(300.0, 200.0)));
    r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(400.0, 200.0, BufferMode::BlendingPrevious)),
    );
    r.run(0.5);
    r.ok(
        0,
        CommandKind::SetOverride {
            velocity_factor: 0.1,
        },
    );
    r.run(1.0);
    assert!(
        r.st(0).set_velocity <= 20.0 + 1e-9,
        "{}",
        r.st(0).set_velocity
    );
}

#[test]
fn s11a_17_move_additive_after_an_endless_motion_starts_from_the_set_position() {
    let mut r = Rig::new(1);
    r.power_on(0);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 300.0)));
    r.until(3.0, |r| r.out(a).done);
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 100.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(1.0);
    let h = r.ok(
        0,
        CommandKind::Halt {
            deceleration: 0.0,
            jerk: 0.0,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.until(3.0, |r| r.out(h).done);
    let s = r.st(0).set_position;
    r.ok(0, CommandKind::MoveAdditive(mv(50.0, 100.0)));
    assert!((r.st(0).target_position - (s + 50.0)).abs() < 1e-9);
}

#[test]
fn move_modulo_shortest_way_while_the_last_move_settles_is_a_start_from_standstill() {
    let mut p = params();
    p.axis_target_position_monitoring_time = 0.5; // a long settling phase
    let mut r = Rig::with(vec![(true, p)]);
    r.power_on(0);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    r.until(3.0, |r| !r.st(0).moving && r.st(0).set_position == 10.0);
    assert!(r.out(a).busy, "still settling");
    r.ok(
        0,
        CommandKind::MoveModulo {
            move_: mv(350.0, 100.0),
            direction: Direction::ShortestWay,
        },
    );
    assert!(
        (r.st(0).target_position + 10.0).abs() < 1e-9,
        "{}",
        r.st(0).target_position
    );
}

#[test]
fn move_modulo_from_motion_refuses_reversal_and_respects_soft_limits() {
    let mut p = params();
    p.axis_en_max_soft_pos_limit = true;
    p.axis_max_soft_pos_limit = 400.0;
    let mut r = Rig::with(vec![(true, p)]);
    r.power_on(0);
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 200.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.until(3.0, |r| r.st(0).set_position > 300.0);
    assert_eq!(
        r.rejected(
            0,
            CommandKind::MoveModulo {
                move_: mv(350.0, 200.0),
                direction: Direction::Negative
            }
        ),
        ErrorId::INVALID_MODE
    );
    // 350 lies within the braking distance: the next 350 is 710, beyond the limit 400.
    let m = r.ok(
        0,
        CommandKind::MoveModulo {
            move_: mv(310.0, 200.0),
            direction: Direction::Positive,
        },
    );
    r.until(3.0, |r| !r.out(m).busy);
    assert_eq!(r.out(m).error_id, ErrorId::TARGET_ABOVE_SOFT_LIMIT.0);
    r.until(3.0, |r| r.st(0).state == AxisState::Standstill);
    assert!(r.st(0).set_position <= 400.0);
}

#[test]
fn set_position_with_clear_lag_during_motion_clears_it_for_good() {
    let mut p = params();
    p.axis_en_position_lag_monitoring = false;
    let mut r = Rig::with(vec![(false, p)]);
    r.power_on(0);
    r.plants[0].tau = 0.05; // a drive that lags (2.5 mm at 50 mm/s)
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 50.0)));
    r.run(0.5);
    let before = r.st(0);
    assert!(before.following_error > 1.0);
    r.ok(
        0,
        CommandKind::SetPosition {
            position: 0.0,
            relative: true,
            clear_position_lag: true,
        },
    );
    let after = r.st(0);
    assert_eq!(after.set_position, after.actual_position);
    r.step();
    // The motion continues from the actual position (the next sample does not bring the old
    // set position back).
    let s = r.st(0);
    assert!(
        (s.set_position - after.actual_position).abs() < 0.2,
        "{} vs {}",
        s.set_position,
        after.actual_position
    );
    r.until(5.0, |r| !r.out(m).busy);
    assert!(r.out(m).done);
}

#[test]
fn homing_stops_at_a_limit_switch_in_any_phase() {
    let mut r = Rig::new(1);
    r.plants[0].cam = Some((10.0, 15.0)); // a cam, but no index pulse ever comes
    r.power_on(0);
    let h = r.ok(
        0,
        CommandKind::Home {
            position: None,
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    r.until(20.0, |r| r.st(0).homing_phase == HomingPhase::WaitLatch);
    r.run(0.5);
    r.plants[0].limit_positive = true;
    r.until(3.0, |r| !r.out(h).busy);
    // The cam was found, the sync pulse was not: the error says which.
    assert_eq!(r.out(h).error_id, ErrorId::HOMING_SYNC_NOT_FOUND.0);
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
}

#[test]
fn reset_during_the_error_stop_ramp_waits_for_standstill() {
    let mut r = Rig::new(1);
    r.power_on(0);
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 400.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(1.0);
    r.plants[0].load_lag = 5.0;
    r.until(1.0, |r| r.st(0).state == AxisState::ErrorStop);
    r.plants[0].load_lag = 0.0;
    assert!(r.st(0).moving);
    let reset = r.ok(0, CommandKind::Reset);
    assert!(r.out(reset).busy);
    // The rig checks every cycle that the velocity does not jump.
    r.until(2.0, |r| !r.out(reset).busy);
    assert!(r.out(reset).done);
    assert_eq!(r.st(0).state, AxisState::Standstill);
}

#[test]
fn repeated_fault_and_reset_rounds_can_always_be_re_enabled() {
    let mut r = Rig::new(1);
    r.plants[0].enable_delay_cycles = 300; // a slow drive (0.3 s)
    r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
        },
    );
    for _ in 0..5 {
        r.until(1.0, |r| r.st(0).state == AxisState::Standstill);
        r.plants[0].fault = true;
        r.until(0.1, |r| r.st(0).state == AxisState::ErrorStop);
        r.plants[0].fault = false;
        r.ok(0, CommandKind::Reset);
    }
}

#[test]
fn move_continuous_with_end_velocity_zero_stays_busy_at_the_target() {
    let mut r = Rig::new(1);
    r.power_on(0);
    let c = r.ok(
        0,
        CommandKind::MoveContinuousAbsolute {
            move_: mv(50.0, 100.0),
            end_velocity: 0.0,
        },
    );
    r.until(3.0, |r| r.out(c).in_end_velocity);
    r.run(0.5);
    let o = r.out(c);
    assert!(o.busy && o.in_end_velocity && !o.done);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 100.0)));
    let o = r.out(c);
    assert!(o.command_aborted && !o.in_end_velocity, "{o:?}");
    r.until(3.0, |r| r.out(m).done);
}

/// A drive-latch homing run (#1076 = 3, 4, 6, 7) started off the cam never travels against
/// the search direction, so a blocked direction there (negative limit switch) does not refuse
/// it; a mode with a sync phase does travel it and is refused, and so is a drive-latch run that
/// starts on the cam (it leaves the cam backwards first).
#[test]
fn homing_is_refused_only_for_a_direction_the_run_will_travel() {
    use ReferenceMode::*;
    let home = |r: &mut Rig, mode: ReferenceMode, sync_direction: Option<Direction>| {
        r.cmd(
            0,
            CommandKind::Home {
                position: Some(0.0),
                mode: HomingMode::Default,
                options: HomingOptions {
                    reference_mode: Some(mode),
                    sync_direction,
                    ..HomingOptions::default()
                },
            },
        )
    };
    let neg = Some(Direction::Negative);
    for (mode, start, sync, accepted) in [
        (HardwareLatchPos, 0.0, None, true),
        (SoftDriveLatchNeg, 0.0, None, true),
        (HardwareLatchPos, 52.0, None, false),
        (HardwareSync, 0.0, neg, false),
        // The default sync direction is positive (ST_HomingOptions): never travels negative.
        (HardwareSync, 0.0, None, true),
    ] {
        let mut r = Rig::new(1);
        r.plants[0].cam = Some((50.0, 55.0));
        r.plants[0].index_period = Some(8.0);
        r.plants[0].pos = start;
        r.power_on(0);
        r.plants[0].limit_negative = true;
        r.run(0.01);
        let (id, verdict) = home(&mut r, mode, sync);
        assert_eq!(
            verdict == Verdict::Accepted,
            accepted,
            "{mode:?} from {start}: {verdict:?}"
        );
        if accepted {
            r.until(20.0, |r| !r.out(id).busy);
            assert!(r.out(id).done, "{mode:?}: {:?}", r.out(id));
        }
    }
}
