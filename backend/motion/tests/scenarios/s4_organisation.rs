//! §4 Organisation FBs: MC_Power (override), MC_Reset, MC_SetPosition, MC_WriteParameter
//! (§11a item 34).

use super::*;

#[test]
fn s11a_34_override_range() {
    let mut r = Rig::new(1);
    assert_eq!(
        r.rejected(0, power_with_override(100.5)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(
        r.rejected(0, power_with_override(-0.1)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    power(&mut r);
    r.ok(0, power_with_override(50.0));
    let v = r.ok(0, velocity(100.0, Direction::Positive));
    r.until(1.0, |r| r.out(v).in_velocity);
    assert!((r.st(0).set_velocity - 50.0).abs() < 1e-9);
    // Override 0 stops the axis without aborting the command; the change drops InVelocity
    // in the next cycle (the velocity is re-planned, no longer reached).
    r.ok(0, power_with_override(0.0));
    r.step();
    assert!(!r.out(v).in_velocity && r.out(v).busy);
    r.run(1.0);
    assert!(r.st(0).set_velocity.abs() < 1e-9);
    assert!(r.out(v).busy && !r.out(v).command_aborted);
}

#[test]
fn velocity_never_exceeds_commanded_velocity_times_override_in_any_cycle() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(0, power_with_override(50.0));
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
            acceleration_factor: 1.0,
            jerk_factor: 1.0,
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
                clear_position_lag: false,
                clear_position_offset: false,
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
            clear_position_offset: false,
        },
    );
    r.until(5.0, |r| r.out(m).done);
    assert!((r.st(0).set_position - 1100.0).abs() < 1e-9);
    assert!((r.plants[0].pos - 100.0).abs() < 0.01);
}

/// §4.1.3 Options.ClearPositionOffset: "deletes the accumulated offset created by
/// MC_SetPosition calls and returns the axis to the originally referenced coordinate system
/// (the Position input is then irrelevant)"; the following error is kept.
#[test]
fn s4_1_3_clear_position_offset_returns_to_the_referenced_coordinates() {
    let mut r = Rig::new(1);
    power(&mut r);
    let set = |position: f64, relative: bool, clear: bool| CommandKind::SetPosition {
        position,
        relative,
        clear_position_lag: false,
        clear_position_offset: clear,
    };
    r.ok(0, set(5.0, true, false));
    r.ok(0, set(100.0, false, false));
    r.run(0.01);
    assert!((r.st(0).set_position_offset - 100.0).abs() < 1e-9);
    assert!((r.st(0).actual_position - 100.0).abs() < 1e-9);
    let lag = r.st(0).following_error;
    r.ok(0, set(12345.0, false, true));
    r.run(0.01);
    assert_eq!(r.st(0).set_position_offset, 0.0);
    assert!(
        r.st(0).actual_position.abs() < 1e-9,
        "{:?}",
        r.st(0).actual_position
    );
    assert!(
        (r.st(0).following_error - lag).abs() < 1e-9,
        "the lag is kept"
    );
}

/// Decision 95: MC_SetPosition never makes coordinates beyond ±1e15 (or infinite): relative
/// shifts of 1e300, repeated, once made a spindle's positions infinite.
#[test]
fn set_position_refuses_coordinates_beyond_what_a_position_resolves() {
    let mut r = Rig::new(1);
    let set = |position: f64, relative: bool| CommandKind::SetPosition {
        position,
        relative,
        clear_position_lag: false,
        clear_position_offset: false,
    };
    r.ok(0, set(9e14, true));
    assert_eq!(
        r.rejected(0, set(2e14, true)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(
        r.rejected(0, set(1e300, false)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    r.run(0.01);
    assert!(
        (r.st(0).set_position - 9e14).abs() < 1.0,
        "unchanged by the refusals"
    );
    assert!(r.st(0).actual_position.is_finite());
    r.ok(0, set(-1e15, false));
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
            clear_position_offset: false,
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
fn reset_during_the_error_stop_ramp_waits_for_standstill() {
    let mut r = Rig::new(1);
    r.power_on(0);
    r.ok(0, velocity(400.0, Direction::Positive));
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
    r.ok(0, power_with_override(100.0));
    for _ in 0..5 {
        r.until(1.0, |r| r.st(0).state == AxisState::Standstill);
        r.plants[0].fault = true;
        r.until(0.1, |r| r.st(0).state == AxisState::ErrorStop);
        r.plants[0].fault = false;
        r.ok(0, CommandKind::Reset);
    }
}

/// MC_Power with both feed enables (a buffered disable keeps them: the move it waits for
/// may go on).
fn power_buffered(enable: bool, buffer_mode: BufferMode) -> CommandKind {
    CommandKind::Power {
        enable,
        enable_positive: true,
        enable_negative: true,
        override_percent: 100.0,
        buffer_mode,
    }
}

/// §4.1.1 MC_Power BufferMode, evaluated when the enable is removed: a buffered disable waits
/// until the axis no longer executes a job — the move runs to its target and ends Done, the
/// disabling command stays busy with the axis enabled every cycle until then, and the axis
/// is Disabled in the cycle the move ended. Aborting disables at once (the move aborted).
#[test]
fn s4_1_1_power_buffer_mode_disables_once_the_job_has_ended() {
    let mut r = Rig::new(1);
    power(&mut r);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(50.0, 100.0)));
    r.run(0.1);
    let off = r.ok(0, power_buffered(false, BufferMode::Buffered));
    let mut cycles = 0;
    while r.out(m).busy {
        assert_eq!(r.st(0).state, AxisState::DiscreteMotion);
        assert!(r.st(0).power_status);
        assert!(r.out(off).busy && r.out(off).status && !r.out(off).done);
        r.step();
        cycles += 1;
        assert!(cycles < 5000, "the move never ended");
    }
    assert!(r.out(m).done && !r.out(m).command_aborted);
    assert!((r.st(0).set_position - 50.0).abs() < 1e-9);
    // The disable takes effect in the cycle the move ended.
    assert_eq!(r.st(0).state, AxisState::Disabled);
    assert!(r.out(off).done && !r.out(off).busy);

    // Aborting (the default): at once, the running move aborted.
    power(&mut r);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 100.0)));
    r.run(0.1);
    r.ok(0, power_buffered(false, BufferMode::Aborting));
    assert!(r.out(m).command_aborted);
    assert_eq!(r.st(0).state, AxisState::Disabled);
}

/// §4.1.1: the BufferMode of the enabling MC_Power applies when its Enable falls (the release
/// of the command). At standstill a buffered disable acts at once; a newer enabling power
/// cancels a disable still waiting.
#[test]
fn s4_1_1_power_release_with_buffer_mode_waits_and_a_new_enable_cancels_it() {
    let mut r = Rig::new(1);
    let on = r.ok(0, power_buffered(true, BufferMode::Buffered));
    r.until(1.0, |r| r.st(0).state == AxisState::Standstill);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(20.0, 100.0)));
    r.run(0.05);
    r.ok(0, CommandKind::Release { target: on });
    r.step();
    assert_eq!(r.st(0).state, AxisState::DiscreteMotion);
    assert!(r.out(on).busy);
    r.until(5.0, |r| !r.out(m).busy);
    assert!(r.out(m).done);
    assert_eq!(r.st(0).state, AxisState::Disabled);
    assert!(!r.out(on).busy);

    // At standstill the buffered release disables in the same submit.
    let on = r.ok(0, power_buffered(true, BufferMode::Buffered));
    r.until(1.0, |r| r.st(0).state == AxisState::Standstill);
    r.ok(0, CommandKind::Release { target: on });
    assert_eq!(r.st(0).state, AxisState::Disabled);

    // A disable waiting for the move is cancelled by a new enable: the move ends, the axis
    // stays enabled.
    power(&mut r);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 100.0)));
    r.run(0.05);
    let off = r.ok(0, power_buffered(false, BufferMode::Buffered));
    let on = r.ok(0, power_buffered(true, BufferMode::Aborting));
    assert!(r.out(off).command_aborted);
    r.until(5.0, |r| !r.out(m).busy);
    assert!(r.out(m).done);
    r.run(0.1);
    assert_eq!(r.st(0).state, AxisState::Standstill);
    assert!(r.out(on).busy && r.out(on).status);
}

/// §4.2.8 MC_ReadStatus / §6.11.13 ST_AxisStatus: the StateDWord flags cycle by cycle —
/// Operational and ControlLoopClosed with the enable, NotMoving against Moving, NewTarget-
/// Position while an Aborting move replaced a running one, HasBeenStopped after MC_Stop until
/// the next motion command, PTPmode off while coupled, the cycle counter of every step, and
/// the OpModes from the parameters.
#[test]
fn s4_2_8_extended_status_flags_follow_the_axis_in_every_cycle() {
    let mut r = Rig::new(2);
    let st = r.st(0);
    assert!(!st.operational && !st.control_loop_closed && st.not_moving && st.ptp_mode);
    assert!(st.op_modes.position_lag_monitoring && !st.op_modes.position_correction);
    power(&mut r);
    assert!(r.st(0).operational && r.st(0).control_loop_closed);
    let c0 = r.st(0).nc_cycle_counter;
    r.step();
    assert_eq!(r.st(0).nc_cycle_counter, c0 + 1);

    let a = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 100.0)));
    r.run(0.2);
    assert!(
        !r.st(0).new_target_position,
        "the first move started from rest"
    );
    r.ok(0, CommandKind::MoveAbsolute(mv(50.0, 100.0)));
    assert!(r.out(a).command_aborted);
    let mut was_new = false;
    r.until(5.0, |r| {
        let s = r.st(0);
        assert_eq!(s.not_moving, !s.moving);
        assert_eq!(s.homing_busy, s.state == AxisState::Homing);
        was_new |= s.new_target_position;
        s.state == AxisState::Standstill
    });
    assert!(was_new, "NewTargetPosition while the replacing move ran");
    assert!(!r.st(0).new_target_position && !r.st(0).has_been_stopped);

    r.ok(0, velocity(50.0, Direction::Positive));
    r.run(0.2);
    let stop = r.ok(
        0,
        CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: MoveOptions::default(),
        },
    );
    assert!(r.st(0).has_been_stopped);
    r.until(2.0, |r| r.out(stop).done);
    r.ok(0, CommandKind::Release { target: stop });
    r.step();
    assert!(
        r.st(0).has_been_stopped,
        "stays until the next motion command"
    );
    r.ok(0, CommandKind::MoveRelative(mv(1.0, 10.0)));
    assert!(!r.st(0).has_been_stopped);

    // A coupled slave is not in PTP mode.
    r.power_on(1);
    r.until(2.0, |r| {
        r.st(1).state == AxisState::Standstill && r.st(0).state == AxisState::Standstill
    });
    r.ok(1, gear_in(0, 1.0, 1));
    r.step();
    assert!(r.st(1).coupled && !r.st(1).ptp_mode);

    // OpModes follow the parameters written online.
    r.ok(
        0,
        CommandKind::WriteParameter {
            number: 1046,
            value: 1.0,
        },
    );
    assert!(r.st(0).op_modes.position_correction);
}

fn set_override(velocity_factor: f64, acceleration_factor: f64, jerk_factor: f64) -> CommandKind {
    CommandKind::SetOverride {
        velocity_factor,
        acceleration_factor,
        jerk_factor,
    }
}

/// §4.5.10 MC_SetOverride: AccFactor and JerkFactor (0 < f ≤ 1) scale the acceleration,
/// deceleration and jerk of the motion commands started after them — a move's |a| reaches
/// half the axis's acceleration and no more in any cycle; MC_Halt keeps its full
/// deceleration; factors outside (0, 1] are refused.
#[test]
fn s4_5_10_set_override_factors_scale_the_dynamics_of_new_moves() {
    let mut r = Rig::new(1);
    power(&mut r);
    for (v, a, j) in [
        (1.1, 1.0, 1.0),
        (1.0, 0.0, 1.0),
        (1.0, 1.0, 1.5),
        (1.0, f64::NAN, 1.0),
    ] {
        assert_eq!(
            r.rejected(0, set_override(v, a, j)),
            ErrorId::PARAMETER_NOT_CORRECT
        );
    }
    r.ok(0, set_override(1.0, 0.5, 0.5));
    let acc = r.k.parameters(0).unwrap().axis_acc;
    let jerk = r.k.parameters(0).unwrap().axis_jerk;
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(200.0, 400.0)));
    let mut peak: f64 = 0.0;
    let mut last_a = 0.0;
    r.until(5.0, |r| {
        let a = r.st(0).set_acceleration;
        assert!(a.abs() <= 0.5 * acc + 1e-6, "|a| {a} above half of {acc}");
        assert!(
            ((a - last_a) / DT).abs() <= 0.5 * jerk + 1e-3,
            "jerk above half"
        );
        last_a = a;
        peak = peak.max(a.abs());
        r.out(m).done
    });
    assert!(peak > 0.49 * acc, "the halved acceleration is used: {peak}");
    // A halt brakes with its own deceleration, unscaled.
    r.ok(0, velocity(300.0, Direction::Negative));
    r.run(1.0);
    r.ok(
        0,
        CommandKind::Halt {
            deceleration: 1000.0,
            jerk: 0.0,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    let mut peak: f64 = 0.0;
    r.until(2.0, |r| {
        peak = peak.max(r.st(0).set_acceleration.abs());
        r.st(0).state == AxisState::Standstill
    });
    assert!(peak > 900.0, "halt braked with {peak}, not its 1000");
}

fn filter(raw: f64, recovery_time: f64) -> CommandKind {
    CommandKind::OverrideFilter {
        raw,
        lower_threshold: 0.0,
        upper_threshold: 32767.0,
        steps: 200,
        recovery_time,
    }
}

/// §4.5.4 MC_OverrideFilter: the raw value becomes a quantised override (MC_Power's, the
/// PlcToNc.Override it is made for); after each change a new value waits for the recovery
/// time — then it is applied without being sent again — except 0 % and 100 %, which act at
/// once; steps ≤ 1 or lower ≥ upper are refused (0x4B06).
#[test]
fn s4_5_4_override_filter_quantises_and_waits_for_its_recovery_time() {
    let mut r = Rig::new(1);
    power(&mut r);
    assert_eq!(
        r.rejected(
            0,
            CommandKind::OverrideFilter {
                raw: 1.0,
                lower_threshold: 5.0,
                upper_threshold: 5.0,
                steps: 200,
                recovery_time: 0.15
            }
        ),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    r.ok(0, filter(16383.5, 0.15));
    assert_eq!(r.st(0).power_override_percent, 50.0);
    r.run(0.05);
    r.ok(0, filter(8191.75, 0.15));
    assert_eq!(
        r.st(0).power_override_percent,
        50.0,
        "waits for the quiet time"
    );
    let mut cycles = 0;
    r.until(1.0, |r| {
        cycles += 1;
        r.st(0).power_override_percent == 25.0
    });
    // 150 ms after the change to 50 %, of which 50 ms had passed: exactly 100 steps (the
    // condition is asked before each step, so 101 asks), counted while the standing axis
    // rests too.
    assert_eq!(cycles, 101);
    // 0 % acts at once, and so does 100 % right after it.
    r.ok(0, filter(10.0, 0.15));
    assert_eq!(r.st(0).power_override_percent, 0.0);
    r.ok(0, filter(40000.0, 0.15));
    assert_eq!(r.st(0).power_override_percent, 100.0);
}

fn encoder_scaling(factor: f64, relative: bool) -> CommandKind {
    CommandKind::SetEncoderScalingFactor { factor, relative }
}

/// §4.5.9 MC_SetEncoderScalingFactor: absolute mode makes the position jump with the new
/// factor and is allowed at standstill only — the set position goes along, so nothing moves;
/// relative mode moves no position, also in motion (within one cycle's acceleration of the
/// drive's velocity step, else 0x70B2); the drive then travels in the new scale; #1040 reads
/// the new factor, and writing it is the absolute mode.
#[test]
fn s4_5_9_encoder_scaling_absolute_jumps_at_rest_relative_never() {
    let mut r = Rig::new(1);
    power(&mut r);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 200.0)));
    r.until(3.0, |r| r.out(m).done);
    let drive_before = r.sp[0].position;
    r.ok(0, encoder_scaling(2.0, false));
    let st = r.st(0);
    assert!(
        (st.actual_position - 200.0).abs() < 1e-9,
        "{}",
        st.actual_position
    );
    assert!((st.set_position - 200.0).abs() < 1e-9);
    assert_eq!(st.encoder_scaling_factor, 2.0);
    r.run(0.1);
    assert!(
        (r.sp[0].position - drive_before).abs() < 1e-9,
        "the drive did not move"
    );
    assert!(r.st(0).following_error.abs() < 1e-9);
    // 100 axis units further is 50 drive units now.
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(300.0, 200.0)));
    r.until(3.0, |r| r.out(m).done);
    assert!((r.sp[0].position - (drive_before + 50.0)).abs() < 1e-9);

    // In motion: absolute refused, a large relative change refused, a small one smooth.
    r.ok(0, velocity(50.0, Direction::Negative));
    r.run(0.5);
    assert_eq!(
        r.rejected(0, encoder_scaling(2.5, false)),
        ErrorId::AXIS_CANNOT_BE_STARTED
    );
    assert_eq!(
        r.rejected(0, encoder_scaling(4.0, true)),
        ErrorId::ENCODER_SCALING_STEP_TOO_LARGE
    );
    let before = r.st(0).actual_position;
    r.ok(0, encoder_scaling(2.02, true));
    assert!((r.st(0).actual_position - before).abs() < 1e-9, "no jump");
    let mut last = r.st(0).actual_position;
    for _ in 0..100 {
        r.step();
        let a = r.st(0).actual_position;
        assert!(
            (a - last + 50.0 * DT).abs() < 0.01,
            "actual steps by {}",
            a - last
        );
        assert!(r.st(0).following_error.abs() < 0.01);
        last = a;
    }
    r.ok(0, halt());
    r.until(2.0, |r| r.st(0).state == AxisState::Standstill);
    // Writing #1040 at standstill is the absolute mode.
    // Absolute counts from zero again: the drive's position × the new factor (what the
    // relative change put into the offset goes).
    let drive = r.sp[0].position;
    r.ok(
        0,
        CommandKind::WriteParameter {
            number: 1040,
            value: 1.01,
        },
    );
    assert!(
        (r.st(0).actual_position - drive * 1.01).abs() < 1e-5,
        "{} vs {} ({:?})",
        r.st(0).actual_position,
        drive * 1.01,
        r.k.parameters(0).unwrap().axis_encoder_scaling_factor
    );
    assert_eq!(r.st(0).encoder_scaling_factor, 1.01);
    assert_eq!(
        r.rejected(0, encoder_scaling(0.0, true)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
}
