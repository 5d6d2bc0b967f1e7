//! §4.4 The external setpoint generator: MC_ExtSetPointGenEnable / Disable and the samples a
//! client feeds (MC_ExtSetPointGenFeed), cycle by cycle — followed exactly, extrapolated when
//! the client feeds more slowly than the cycle, and what a stalled or broken stream does.

use super::*;

fn enable(target: Option<f64>, timeout: f64) -> CommandKind {
    CommandKind::ExtSetPointGenEnable {
        target,
        relative: false,
        timeout,
    }
}

fn feed(position: f64, velocity: f64) -> CommandKind {
    CommandKind::ExtSetPointGenFeed {
        position,
        velocity,
        acceleration: 0.0,
        direction: if velocity > 0.0 {
            1
        } else if velocity < 0.0 {
            -1
        } else {
            0
        },
    }
}

/// §4.4.1/§4.4.3: after the enable (Done, `Enabled` in the status) the axis takes the fed
/// samples as its setpoints; a sample fed every 10 cycles is extrapolated with its velocity
/// in between, so a client streaming a ramp at 100 Hz moves the axis smoothly along it;
/// the target position is monitored (InTargetPosition once there), the axis does not go there
/// by itself. MC_ExtSetPointGenDisable at rest ends it.
#[test]
fn s4_4_fed_samples_are_the_setpoints_and_are_extrapolated_between_feeds() {
    let mut r = Rig::new(1);
    power(&mut r);
    let e = r.ok(0, enable(Some(20.0), 0.05));
    assert!(r.out(e).done && r.st(0).ext_setpoint_gen_enabled);
    assert_eq!(
        r.st(0).state,
        AxisState::Standstill,
        "nothing moves by itself"
    );
    r.run(0.1);
    assert_eq!(r.st(0).set_position, 0.0);
    // 40 u/s for 0.5 s, fed every 10 ms.
    for k in 0..50 {
        let t = k as f64 * 0.01;
        r.ok(0, feed(40.0 * t, 40.0));
        for i in 0..10 {
            r.step();
            // The sample is the next cycle's setpoint; later ones extrapolate it.
            let now = t + i as f64 * DT;
            assert!(
                (r.st(0).set_position - 40.0 * now).abs() < 1e-9,
                "cycle {i} after feed {k}: {}",
                r.st(0).set_position
            );
            assert_eq!(r.st(0).state, AxisState::ContinuousMotion);
        }
    }
    r.ok(0, feed(20.0, 0.0));
    r.run(0.04);
    assert_eq!(r.st(0).set_position, 20.0);
    r.run(0.2);
    assert!(r.st(0).in_target_position);
    assert_eq!(r.st(0).target_position, 20.0);
    r.ok(0, CommandKind::ExtSetPointGenDisable);
    r.until(1.0, |r| r.st(0).state == AxisState::Standstill);
    assert!(!r.st(0).ext_setpoint_gen_enabled);
    assert_eq!(
        r.rejected(0, feed(20.0, 0.0)),
        ErrorId::EXT_SETPOINT_GEN_NOT_ENABLED
    );
}

/// §4.4 (what the manual leaves open): a stream that pauses longer than its timeout stops the
/// axis in ErrorStop (0x70B7) on the fast ramp from where the stream left it, never by running
/// on; a sample that would make the axis jump or exceed its maximum velocity stops it with
/// 0x70B6; one beyond an enabled software limit with 0x7003 — the set position stays inside.
/// The generator is off after such a stop.
#[test]
fn s4_4_a_stalled_or_broken_stream_stops_the_axis() {
    let mut r = Rig::with(vec![(false, params_with_soft_limits(-1000.0, 30.0))]);
    power(&mut r);
    r.ok(0, enable(None, 0.05));
    r.ok(0, feed(0.0, 100.0));
    let cycles = r.until(1.0, |r| r.st(0).error_id != 0);
    assert_eq!(r.st(0).error_id, ErrorId::EXT_SETPOINT_STALLED.0);
    // Extrapolated for 50 ms, then stopping: 5 units, no more than the ramp adds.
    assert!((50..=52).contains(&cycles), "{cycles}");
    r.until(1.0, |r| r.st(0).set_velocity == 0.0);
    assert!(r.st(0).set_position < 5.0 + 100.0 * 100.0 / (2.0 * 1000.0) + 1e-6);

    let mut r = Rig::with(vec![(false, params_with_soft_limits(-1000.0, 30.0))]);
    power(&mut r);
    r.ok(0, enable(None, 0.05));
    assert_eq!(
        r.rejected(0, feed(5.0, 0.0)),
        ErrorId::EXT_SETPOINT_INVALID,
        "the first sample is where the axis stands"
    );
    assert_eq!(
        r.rejected(0, feed(0.0, 600.0)),
        ErrorId::PARAMETER_NOT_CORRECT,
        "beyond the maximum velocity"
    );
    r.ok(0, feed(0.0, 10.0));
    r.run(0.005);
    r.ok(0, feed(3.0, 10.0));
    r.step();
    assert_eq!(r.st(0).error_id, ErrorId::EXT_SETPOINT_INVALID.0, "a jump");
    r.until(1.0, |r| r.st(0).set_velocity == 0.0);

    let mut r = Rig::with(vec![(false, params_with_soft_limits(-1000.0, 30.0))]);
    power(&mut r);
    r.ok(0, enable(None, 0.05));
    let mut pos = 0.0;
    let mut k = 0;
    while r.st(0).error_id == 0 {
        r.ok(0, feed(pos, 200.0));
        r.step();
        pos += 200.0 * DT;
        k += 1;
        assert!(k < 1000);
    }
    assert_eq!(r.st(0).error_id, ErrorId::SOFT_LIMIT_REACHED.0);
    r.until(2.0, |r| r.st(0).set_velocity == 0.0);
}

/// §4.4.1: motion commands to an axis the generator moves need #1066
/// AxisAllowMotionCmdToExtSetAxis (else 0x70B9); MC_Halt and MC_Stop are never refused and
/// stop it on their ramp.
#[test]
fn s4_4_motion_commands_need_1066_but_a_stop_never_does() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(0, enable(None, 0.5));
    r.ok(0, feed(0.0, 50.0));
    r.run(0.1);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(100.0, 100.0))),
        ErrorId::EXT_SETPOINT_AXIS_COMMAND_NOT_ALLOWED
    );
    let h = r.ok(0, halt());
    r.until(1.0, |r| r.out(h).done);
    assert_eq!(r.st(0).state, AxisState::Standstill);
    r.ok(
        0,
        CommandKind::WriteParameter {
            number: 1066,
            value: 1.0,
        },
    );
    let at = r.st(0).set_position;
    r.ok(0, feed(at, 50.0));
    r.run(0.1);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 100.0)));
    r.until(3.0, |r| r.out(m).done);
    assert_eq!(r.st(0).set_position, 0.0);
}

/// A relative MC_SetPosition while the generator moves the axis would shift the axis under
/// the client's samples (the drive would jump back to them): refused, as a superposition is.
#[test]
fn s4_4_no_set_position_or_superposition_under_a_stream() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(0, enable(None, 0.5));
    r.ok(0, feed(0.0, 50.0));
    r.run(0.05);
    assert_eq!(
        r.rejected(
            0,
            CommandKind::SetPosition {
                position: 0.3,
                relative: true,
                clear_position_lag: false,
                clear_position_offset: false
            }
        ),
        ErrorId::AXIS_CANNOT_BE_STARTED
    );
    assert_eq!(
        r.rejected(
            0,
            CommandKind::MoveSuperImposed(Superposition {
                distance: 1.0,
                velocity_diff: 10.0,
                velocity_process: 50.0,
                length: 100.0,
                ..Superposition::default()
            })
        ),
        ErrorId::AXIS_CANNOT_BE_STARTED
    );
}
