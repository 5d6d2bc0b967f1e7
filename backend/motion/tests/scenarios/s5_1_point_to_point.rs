//! §5.1 Point-to-point motion: MoveAbsolute/Relative/Additive, MoveModulo, MoveVelocity,
//! MoveContinuous*, MC_Halt, MC_Stop (§11a items 17, 18, 20–24).

use super::*;

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
fn s11a_17_move_additive_after_an_endless_motion_starts_from_the_set_position() {
    let mut r = Rig::new(1);
    r.power_on(0);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 300.0)));
    r.until(3.0, |r| r.out(a).done);
    r.ok(0, velocity(100.0, Direction::Positive));
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
    assert!((-1000.0 - 1e-6..-900.0).contains(&amin), "{amin}");
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
fn s11a_20_move_velocity_in_velocity_and_stays_busy() {
    let mut r = Rig::new(1);
    power(&mut r);
    let v = r.ok(0, velocity(120.0, Direction::Negative));
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
            acceleration_factor: 1.0,
            jerk_factor: 1.0,
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
            clear_position_offset: false,
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
    r.ok(0, velocity(200.0, Direction::Positive));
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
        ("move velocity", velocity(300.0, Direction::Positive)),
        (
            "move velocity negative",
            velocity(300.0, Direction::Negative),
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
    r.ok(0, velocity(200.0, Direction::Positive));
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
    let a = r.ok(0, velocity(100.0, Direction::Positive));
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

#[test]
fn a_stop_whose_position_window_times_out_ends_with_the_error_and_unlocks() {
    let mut p = params();
    p.axis_in_target_timeout = 0.2;
    p.axis_en_position_lag_monitoring = false;
    let mut r = Rig::with(vec![(false, p)]);
    r.power_on(0);
    r.ok(0, velocity(100.0, Direction::Positive));
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
